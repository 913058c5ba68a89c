"""Internal stability over a θ_r box in three states: stable, unstable, undecided (issue 25).

A box whose internal-stability bisection runs out of budget used to report ``stable=False``,
which region maps drew as "not internally stable".  It is now ``stability == "undecided"``,
and the maps draw it as "not certified" when the verdict is not certified.  Independent
truth for "unstable": a root count of a high-order Padé model of the centre member's
quasi-polynomial, written here (numpy's polynomial roots), and k_x ≤ 0 (D(0) = k_x).
"""

from __future__ import annotations

from math import factorial

import numpy as np
import pytest

import stringstab as ss
from stringstab.certify.robust_reaction import STABILITY, stability_words
from stringstab.regions import region_map
from stringstab.regions.result import load_npz

K = ([1.0, 0.5, 0.2, -0.3, 1.2], [0.5, 1.0, 0.6, 0.5, 0.5], [0.0, 0.0, 0.0, 0.0, 0.6])
BOX = {"tau": "0.4:0.5", "delta": 0.1, "headway": 1.5, "reaction_delay": "0.05:1.5"}


def _pade_unstable_roots(kx, kv, tau, T, theta, n=14):
    """Roots with Re s > 0 of (τs³ + s²)P(s) + (cs + k_x)P(−s), P the [n/n] Padé polynomial."""
    c = kv + T * kx
    a = [factorial(2 * n - k) * factorial(n) / (factorial(2 * n) * factorial(k) * factorial(n - k))
         * theta ** k for k in range(n + 1)]
    P = np.polynomial.Polynomial(a)
    Pm = np.polynomial.Polynomial([ak * (-1) ** k for k, ak in enumerate(a)])
    D = np.polynomial.Polynomial([0, 0, 1, tau]) * P + np.polynomial.Polynomial([kx, c]) * Pm
    return int(np.sum(D.roots().real > 1e-9))


@pytest.fixture(scope="module")
def tiny():
    """The robust θ_r certificate with a tiny budget."""
    return ss.certify_batch(*K, **BOX, max_intervals=16, max_rounds=4)


def test_three_states_with_a_tiny_budget(tiny):
    b = tiny
    assert b.stability.tolist() == ["unstable", "unstable", "undecided", "unstable", "unstable"]
    assert set(b.stability.tolist()) <= set(STABILITY)
    # "stable" is the first state only; undecided is never "stable"
    assert np.array_equal(b.stable, b.stability == "stable")
    # a triple whose stability is undecided is never certified
    assert not np.any((b.stability == "undecided") & (b.verdict == "certified"))
    assert b[2].stability == "undecided" and b.columns()["stability"].tolist()[2] == "undecided"
    assert "stability" in [c.header for c in b.table_columns()]


def test_unstable_is_true(tiny):
    for i in np.flatnonzero(tiny.stability == "unstable"):
        kx, kv = K[0][i], K[1][i]
        if kx <= 0:
            continue  # D(0) = k_x ≤ 0 and D(s) → +∞ on the real axis: a root in s ≥ 0
        assert _pade_unstable_roots(kx, kv, 0.45, 1.5, 0.775) > 0  # the box's centre
    assert _pade_unstable_roots(0.2, 0.6, 0.45, 1.5, 0.05) == 0  # the truth can say stable


NEAR = {"tau": "0.45:0.5", "delta": 0.1, "headway": 1.5, "reaction_delay": "0.05:0.35"}


def test_a_stable_box_out_of_budget_is_undecided_not_unstable():
    """k_x = 1, k_v = 0.5: every member stable (θ_r < 0.36 s, the Padé count), near the edge."""
    for tau in (0.45, 0.5):
        for th in (0.05, 0.2, 0.35):
            assert _pade_unstable_roots(1.0, 0.5, tau, 1.5, th) == 0
    assert _pade_unstable_roots(1.0, 0.5, 0.5, 1.5, 0.37) > 0  # the boundary is close
    small = ss.certify_batch([1.0], [0.5], [0.0], **NEAR, max_intervals=1, max_rounds=4)
    full = ss.certify_batch([1.0], [0.5], [0.0], **NEAR)
    assert small.stability.tolist() == ["undecided"] and not small.stable[0]
    assert full.stability.tolist() == ["stable"] and full.stable[0]
    assert small.verdict[0] == full.verdict[0] == "not_certified"  # |Γ| > 1 at a member


def test_stability_words():
    assert stability_words(np.array([True, False, False]),
                           np.array([False, True, False])).tolist() == list(STABILITY)


def test_region_maps_do_not_draw_undecided_as_not_internally_stable(tmp_path):
    m = region_map({"k_x": np.array([0.2, 0.5]), "k_v": np.array([0.6, 1.0]),
                    "k_a": np.array([0.0, 0.1])}, {}, **BOX)
    und = m.stability_undecided
    assert und is not None and und.any() and (~und).any()
    cls = m.classes("exact")
    v = m.verdict["exact"]
    assert np.all(cls[und & (v == 1)] == 1)  # not certified, not "not internally stable"
    assert np.all(cls[~und & ~m.hurwitz & (v == 1)] == 0)
    back = load_npz(m.save_npz(tmp_path / "m.npz"))
    assert back.stability_undecided is not None
    assert np.array_equal(back.stability_undecided, und)
    assert np.array_equal(back.classes("exact"), cls)
    s = m.slice("k_a", 0.0)
    assert s.stability_undecided is not None and s.stability_undecided.shape == s.shape
