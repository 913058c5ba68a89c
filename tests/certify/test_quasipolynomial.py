"""The exact root count of D(s) = τs³ + s² + e^{−θ_r s}(cs + k_x) against closed forms.

Independent truths:

* **the delay margin**: a Hurwitz cubic at θ_r = 0 keeps every root in Re s < 0 until the
  smallest θ* at which D(jω_c) = 0, ω_c the one positive root of |P(jω)|² = |Q(jω)|²
  (τ²x³ + x² − c²x − k_x² = 0, x = ω²) and θ* = (−arg(−P(jω_c)/Q(jω_c)) mod 2π)/ω_c; just
  beyond, a pair crosses into Re s > 0 (|P|² − |Q|² increases through ω_c²): N = 0 just
  below θ*, N = 2 just above;
* θ_r → 0: N is the number of roots of the cubic in Re s > 0 (``numpy.roots``);
* k_x < 0: a real root in (0, ∞) (the witness solves D(σ) = 0); k_x = 0: a root at 0.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from stringstab.certify.quasipolynomial import count_unstable_roots, real_root
from stringstab.certify.verdicts import CERTIFIED, INCONCLUSIVE, NOT_CERTIFIED


def _delay_margin(kx: float, c: float, tau: float) -> float:
    r = np.roots([tau * tau, 1.0, -c * c, -kx * kx])
    x = float(max(v.real for v in r if abs(v.imag) < 1e-12 and v.real > 0))
    w = math.sqrt(x)
    P = -w * w - 1j * tau * w**3
    Q = kx + 1j * c * w
    return ((-np.angle(-P / Q)) % (2 * math.pi)) / w  # e^{−jθω} = −P/Q


def _cases(n: int, seed: int):
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        kx, kv, tau, headway = rng.uniform(0.05, 3), rng.uniform(-1, 3), rng.uniform(0.05, 1), rng.uniform(0, 3)
        c = kv + headway * kx
        if kx > 0 and c - tau * kx > 0.05:  # Hurwitz at θ_r = 0 (k_v + (T* − τ)k_x > 0)
            out.append((kx, kv, tau, headway, _delay_margin(kx, c, tau)))
    return out


@pytest.mark.parametrize("rel", [1e-3, 1e-6])
def test_the_count_jumps_from_0_to_2_at_the_delay_margin(rel):
    cases = _cases(200, seed=11)
    kx, kv, tau, headway, th = (np.array(v) for v in zip(*cases))
    below = count_unstable_roots(kx, kv, tau, headway, th * (1 - rel))
    above = count_unstable_roots(kx, kv, tau, headway, th * (1 + rel))
    assert below.unstable_roots.tolist() == [0] * len(cases)
    assert below.status.tolist() == [CERTIFIED] * len(cases)
    assert above.unstable_roots.tolist() == [2] * len(cases)
    assert above.status.tolist() == [NOT_CERTIFIED] * len(cases)


def test_a_tiny_delay_counts_the_roots_of_the_cubic():
    rng = np.random.default_rng(5)
    kx, kv = rng.uniform(0.05, 2.5, 300), rng.uniform(-2.5, 2.5, 300)
    tau, headway = 0.2, 1.1
    rc = count_unstable_roots(kx, kv, tau, headway, 1e-9)
    c = kv + headway * kx
    want = [int(np.sum(np.roots([tau, 1.0, ci, k]).real > 0)) for ci, k in zip(c, kx)]
    clear = np.abs(c - tau * kx) > 1e-3  # away from the cubic's own boundary
    assert np.array_equal(rc.unstable_roots[clear], np.array(want)[clear])


def test_a_negative_k_x_has_a_real_root_and_a_zero_k_x_a_root_at_zero():
    kx = np.array([-1.0, -0.01, 0.0])
    kv, tau, headway, th = np.array([0.5, 2.0, 0.5]), 0.1, 1.1, 0.3
    rc = count_unstable_roots(kx, kv, tau, headway, th)
    assert rc.status.tolist() == [NOT_CERTIFIED] * 3
    s = real_root(kx[:2], kv[:2], np.full(2, tau), np.full(2, headway), np.full(2, th))
    c = kv[:2] + headway * kx[:2]
    D = tau * s**3 + s**2 + np.exp(-th * s) * (c * s + kx[:2])
    assert np.all(s > 0) and np.all(np.abs(D) < 1e-9)
    assert rc.unstable_roots[2] == -1 and rc.min_abs[2] == 0.0
    assert np.all(rc.unstable_roots[:2] % 2 == 1)  # a real root and conjugate pairs


def test_an_exhausted_budget_is_inconclusive_with_its_distance():
    kx, kv, tau, headway = 1.0, 0.5, 0.1, 1.1
    th = _delay_margin(kx, kv + headway * kx, tau)
    rc = count_unstable_roots(np.array([kx]), np.array([kv]), tau, headway, th * (1 + 1e-12),
                              max_rounds=3)
    assert rc.status.tolist() == [INCONCLUSIVE] and rc.unstable_roots.tolist() == [-1]
    # the stated distance: |D(jω)| near the crossing frequency is tiny
    assert rc.min_abs[0] < 1e-2 and np.isnan(rc.error[0])


def test_large_delays_are_counted_not_refused():
    th = np.array([2.0, 5.0, 20.0, 60.0])
    rc = count_unstable_roots(np.full(4, 1.0), np.full(4, 0.5), 0.1, 1.1, th)
    assert np.all(rc.unstable_roots >= 2)
    assert np.all(rc.status == NOT_CERTIFIED)
    assert np.all(rc.error < math.pi / 4)
