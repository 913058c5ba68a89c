"""Issue 29 item 7 (continuous part): rows on the Hurwitz boundary say what their evidence proves.

On k_v + (T* − τ)k_x = 0 the cubic has a pair of roots on the imaginary axis (within
round-off), so internal stability is undecided; a proven g(ω) < 0 still proves the row not
string stable (‖Γ‖∞ ≥ |Γ(jω)| > 1, or ∞).  The row is then ``not_certified`` with that witness,
``hurwitz`` and ``hurwitz_margin`` agree in sign, and ``sup_gain_excess`` is a number.
"""

from __future__ import annotations

import numpy as np
import pytest

import stringstab as ss
from stringstab.certify.criteria import hurwitz_bands

#: The case of issue 29: K on the boundary with τ = 1, δ = 1, T* = 3 (margin −15.2).
CASE = ((1.2845722957179961, -2.5691445914359923, -0.9094496121951097), dict(tau=1.0, delta=1.0, headway=3.0))


def _band_rows(n: int, seed: int):
    """Random triples on the boundary k_v = (τ − T*)k_x at random τ, δ, T*."""
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(n):
        tau, delta, headway = rng.uniform(0.05, 1), rng.uniform(0, 1), rng.uniform(0, 3)
        kx = rng.uniform(0.05, 2.5)
        rows.append(((kx, (tau - headway) * kx, rng.uniform(-2.5, 2.5)),
                     dict(tau=tau, delta=delta, headway=headway)))
    return rows


def _g_exact(w: float, K, tau: float, delta: float, headway: float) -> float:
    """(|D(jω)|² − |N(jω)|²)/ω² in extended precision, straight from Γ (no toolkit code)."""
    kx, kv, ka = (np.longdouble(k) for k in K)
    w = np.longdouble(w)
    c = kv + np.longdouble(headway) * kx
    dr, di = kx - w * w, w * (c - np.longdouble(tau) * w * w)
    dw = np.longdouble(delta) * w
    nr = kx - ka * w * w * np.cos(dw)
    ni = kv * w + ka * w * w * np.sin(dw)
    return float((dr * dr + di * di - nr * nr - ni * ni) / (w * w))


def test_the_issue_case_is_not_certified_with_its_witness():
    K, p = CASE
    c = ss.certify(*K, **p)
    assert c.verdict == "not_certified"
    assert c.hurwitz is False and c.hurwitz_margin <= 0
    assert c.margin < -15
    assert np.isfinite(c.sup_gain_excess) and c.sup_gain_excess > 0
    chk = ss.check([K[0]], [K[1]], [K[2]], **p)
    assert chk.verdict.tolist() == ["not_certified"]
    # the witness is a proven value: g at ω computed independently is below 0 by a wide margin
    w = float(chk.witness_omega[0])
    assert w > 0 and _g_exact(w, K, **p) == pytest.approx(float(chk.margin[0]), rel=1e-9)


def test_band_rows_with_a_negative_margin_are_not_certified_and_agree_in_sign():
    rows = _band_rows(150, seed=29)
    n_viol = 0
    for K, p in rows:
        sure, fail = hurwitz_bands([K[0]], [K[1]], tau=p["tau"], headway=p["headway"])
        c = ss.certify(*K, **p)
        chk = ss.check([K[0]], [K[1]], [K[2]], **p)
        assert chk.verdict[0] == c.verdict
        # hurwitz and hurwitz_margin agree in sign on every row (NaN: not shown)
        assert not (c.hurwitz and c.hurwitz_margin <= 0)
        assert not (not c.hurwitz and c.hurwitz_margin > 0)
        if not sure[0] and not fail[0]:
            if c.margin < -1e-9 * (1 + abs(c.margin)):
                n_viol += 1
                assert c.verdict == "not_certified"
                assert np.isfinite(c.sup_gain_excess) and c.sup_gain_excess > 0
                # soundness: the witness value is g(ω) < 0, checked in extended precision
                w = float(chk.witness_omega[0])
                assert _g_exact(max(w, 1e-9), K, **p) < 0
            else:
                assert c.verdict == "inconclusive"
    assert n_viol > 50  # the check above can fail: most band rows have g < 0 somewhere


def test_the_sign_agrees_on_random_rows_everywhere():
    K = np.random.default_rng(3).uniform(-2.5, 2.5, (4000, 3))
    K[:500, 1] = (0.3 - 1.1) * K[:500, 0]  # 500 on the boundary at τ = 0.3, T* = 1.1
    b = ss.certify_batch(*K.T, tau=0.3, delta=0.4, headway=1.1)
    hm = b.hurwitz_margin
    shown = np.isfinite(hm)
    assert np.all((hm[shown] > 0) == b.hurwitz[shown])
    assert shown.mean() > 0.99
