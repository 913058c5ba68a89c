"""Robust certificates against dense grids over the parameter box and direct evaluation.

Truth: the nominal certificates at every member of a grid over the box (each validated
against independent sweeps in test_certificate.py / test_sampled.py), Γ(jω) written
out here, the expm construction of tests/_sampled_truth.py and numpy.roots.
"""

import itertools
import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from stringstab.certify.api import Loop, certify, certify_batch, check
from stringstab.certify.frequency import margin_g
from stringstab.certify.robust_continuous import box_margin, robust_margin
from stringstab.errors import StringStabError
from stringstab.params import Box, as_interval, check_box, parse_interval
from tests._sampled_truth import pair_response, pair_roots

gain = st.floats(-2, 2, allow_nan=False)


def gamma(w, kx, kv, ka, tau, delta, headway):
    s = 1j * np.asarray(w, dtype=float)
    return (kx + kv * s + ka * s**2 * np.exp(-delta * s)) / (
        tau * s**3 + s**2 + (kv + headway * kx) * s + kx)


def grid(lo, hi, n):
    return np.unique(np.linspace(lo, hi, n))


# ---------------------------------------------------------------------------
# intervals and boxes
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("text, want", [("0.1:0.5", (0.1, 0.5)), ("0.2", (0.2, 0.2)),
                                        (" 0:0.3 ", (0.0, 0.3)), ("1e-1:2e-1", (0.1, 0.2))])
def test_parse_interval(text, want):
    assert parse_interval(text) == want


@pytest.mark.parametrize("text, msg", [("0.5:0.1", "lo <= hi"), ("a:b", "LO:HI"), ("", "LO:HI"),
                                       ("0.1:0.2:0.3", "LO:HI"), ("nan:1", "finite"),
                                       ("0.1:", "LO:HI"), ("0:inf", "finite")])
def test_parse_interval_rejects(text, msg):
    with pytest.raises(StringStabError, match=msg):
        parse_interval(text, "tau")


@pytest.mark.parametrize("kw, msg", [
    ({"tau": "0:0.5"}, "tau .* must stay > 0"), ({"tau": (-0.1, 0.2)}, "tau .* must stay > 0"),
    ({"delta": "-0.1:0.2"}, "delta .* >= 0"), ({"headway": (1.2, 1.0)}, "lo <= hi"),
    ({"headway": "-1:1"}, "headway .* >= 0"), ({"tau": (0.1, 0.2, 0.3)}, "pair"),
    ({"delta": float("nan")}, "finite"), ({"tau": "x"}, "LO:HI"),
])
def test_bad_box(kw, msg):
    p = {"tau": 0.1, "delta": 0.2, "headway": 1.1, **kw}
    with pytest.raises(StringStabError, match=msg):
        certify(1.0, 0.5, 0.2, **p)


@pytest.mark.parametrize("H", [0.0, -0.1, float("nan"), float("inf")])
def test_bad_sample_time(H):
    with pytest.raises(StringStabError, match="sample_time"):
        certify_batch([1.0], [0.5], [0.2], tau=(0.1, 0.2), delta=0.2, headway=1.1,
                      sample_time=H)


def test_box_helpers():
    assert as_interval([0.1, 0.2]) == (0.1, 0.2)
    b = check_box("0.1:0.3", 0.2, (1.0, 1.2))
    assert b == Box((0.1, 0.3), (0.2, 0.2), (1.0, 1.2)) and not b.is_point
    assert json.loads(json.dumps(b.as_dict())) == {"tau": [0.1, 0.3], "delta": [0.2, 0.2],
                                                   "headway": [1.0, 1.2]}


# ---------------------------------------------------------------------------
# continuous time: the per-frequency minimum over the box is exact
# ---------------------------------------------------------------------------
@given(kx=gain, kv=gain, ka=gain, w=st.floats(0.0, 12.0),
       t0=st.floats(0.05, 0.4), dt=st.floats(0.0, 0.3), d0=st.floats(0.0, 0.4),
       dd=st.floats(0.0, 0.4), h0=st.floats(0.3, 2.0), dh=st.floats(0.0, 0.6))
def test_robust_margin_is_the_minimum_over_the_box(kx, kv, ka, w, t0, dt, d0, dd, h0, dh):
    box = Box((t0, t0 + dt), (d0, d0 + dd), (h0, h0 + dh))
    G, t_, d_, h_, mag = box_margin(np.array(w), kx, kv, ka, box)
    assert robust_margin(w, kx, kv, ka, tau=box.tau, delta=box.delta, headway=box.headway) == G
    # attained at the reported member, which lies in the box
    assert box.tau[0] <= t_ <= box.tau[1] and box.delta[0] <= d_ <= box.delta[1]
    assert box.headway[0] <= h_ <= box.headway[1]
    assert_allclose(margin_g(w, kx, kv, ka, tau=t_, delta=d_, headway=h_), G, rtol=0,
                    atol=1e-12 * mag)
    # below every member of a dense grid
    T, D, Hh = np.meshgrid(grid(*box.tau, 7), grid(*box.delta, 25), grid(*box.headway, 7))
    g = margin_g(w, kx, kv, ka, tau=T, delta=D, headway=Hh)
    assert G <= g.min() + 1e-12 * mag


@pytest.mark.parametrize("box", [((0.1, 0.3), (0.1, 0.3), (1.1, 1.1)),
                                 ((0.1, 0.1), (0.0, 0.5), (0.8, 1.4)),
                                 ((0.05, 0.5), (0.2, 0.2), (1.0, 1.2))])
def test_continuous_robust_verdict_against_a_dense_grid(box):
    rng = np.random.default_rng(8)
    K = rng.uniform(-2, 2, (150, 3))
    K[:50, 0] = np.abs(K[:50, 0])  # more stable triples
    b = Loop(check_box(*box)).certify_batch(*K.T)  # a point box too
    members = list(itertools.product(grid(*box[0], 4), grid(*box[1], 4), grid(*box[2], 3)))
    verdicts = np.array([certify_batch(*K.T, tau=t, delta=d, headway=h).verdict
                         for t, d, h in members])
    for i in range(len(K)):
        if b.verdict[i] == "certified":
            assert np.all(verdicts[:, i] == "certified")
        elif b.verdict[i] == "not_certified":
            t, d, h = b.witness_tau[i], b.witness_delta[i], b.witness_headway[i]
            assert box[0][0] <= t <= box[0][1] and box[1][0] <= d <= box[1][1]
            assert box[2][0] <= h <= box[2][1]
            roots = np.roots([t, 1.0, K[i, 1] + h * K[i, 0], K[i, 0]])
            if np.all(roots.real < -1e-9):  # an internally stable witness: |Γ| > 1 there
                g = abs(gamma(b.witness_omega[i], *K[i], t, d, h))
                assert g > 1.0
                assert_allclose(b.sup_gain[i], g, rtol=1e-9)
            else:
                assert not b.stable[i] and b.sup_gain[i] == np.inf
        # a grid member that is clearly not certified makes the box not certified
        if np.any(verdicts[:, i] == "not_certified"):
            assert b.verdict[i] != "certified"


def test_point_box_equals_the_nominal_certificates():
    rng = np.random.default_rng(9)
    K = rng.uniform(-2, 2, (300, 3))
    r = Loop(check_box(0.1, 0.2, 1.1)).certify_batch(*K.T)  # the box of one member
    c = certify_batch(*K.T, tau=0.1, delta=0.2, headway=1.1)
    assert r.verdict.tolist() == c.verdict.tolist()
    rs = Loop(check_box(0.1, 0.25, 1.1), sample_time=0.1).certify_batch(*K[:60].T)
    cs = check(*K[:60].T, tau=0.1, delta=0.25, headway=1.1, sample_time=0.1)
    assert rs.verdict.tolist() == cs.verdict.tolist()


def test_hurwitz_worst_corner():
    # stable at (τ_lo, h_hi) but not at (τ_hi, h_lo): k_v + (T* − τ) k_x changes sign
    c = certify(1.0, 0.2, 0.0, tau=(0.1, 0.5), delta=0.2, headway=(0.2, 1.1))
    assert c.verdict == "not_certified" and not c.stable
    assert (c.witness_tau, c.witness_headway) == (0.5, 0.2)
    assert np.any(np.roots([0.5, 1.0, 0.2 + 0.2 * 1.0, 1.0]).real >= 0)


# ---------------------------------------------------------------------------
# sampled data
# ---------------------------------------------------------------------------
SAMPLED_K = [(1.2, 0.5, 0.6), (0.9, -0.5, 1.1), (1.5, 0.3, -0.1), (0.8, 1.2, 0.3)]


@pytest.mark.parametrize("heterogeneous", [True, False])
def test_sampled_robust_against_a_grid_of_members(heterogeneous):
    """δ ∈ [0.15, 0.25] crosses the multiple 0.2 of H = 0.1: both pieces are covered."""
    box = dict(tau=(0.1, 0.2), delta=(0.15, 0.25), headway=(1.0, 1.2))
    K = np.array(SAMPLED_K)
    b = certify_batch(*K.T, sample_time=0.1, heterogeneous=heterogeneous, **box)
    taus = grid(0.1, 0.2, 3)
    members = [(t, tp, d, h) for t in taus for tp in (taus if heterogeneous else [None])
               for d in grid(0.15, 0.25, 5) for h in grid(1.0, 1.2, 3)]
    for i, k in enumerate(K):
        if b.verdict[i] == "certified":
            for t, tp, d, h in members:
                v = check([k[0]], [k[1]], [k[2]], tau=t, delta=d, headway=h,
                          sample_time=0.1, tau_prev=tp).verdict[0]
                assert v == "certified", (k, t, tp, d, h)
        elif b.verdict[i] == "not_certified" and b.stable[i]:
            t, tp, d, h = (b.witness_tau[i], b.witness_tau_prev[i], b.witness_delta[i],
                           b.witness_headway[i])
            assert 0.1 <= t <= 0.2 and 0.1 <= tp <= 0.2 and 0.15 <= d <= 0.25 and 1.0 <= h <= 1.2
            if not heterogeneous:
                assert tp == t
            a = abs(pair_response(np.array([b.witness_theta[i]]), *k, t, d, h, 0.1, tau_prev=tp)[0])
            assert np.max(np.abs(pair_roots(k[0], k[1], t, h, 0.1))) < 1 and a > 1.0
            assert_allclose(b.sup_gain[i], a, rtol=1e-9)
            assert_allclose(b.witness_omega[i], b.witness_theta[i] / 0.1)
    assert b.verdict.tolist()[:2] == ["certified", "not_certified"]


def test_heterogeneous_box_contains_the_homogeneous_one():
    K = np.array(SAMPLED_K)
    box = dict(tau=(0.1, 0.2), delta=0.2, headway=1.1, sample_time=0.1)
    het = certify_batch(*K.T, heterogeneous=True, **box)
    hom = certify_batch(*K.T, heterogeneous=False, **box)
    for a, b in zip(het.verdict, hom.verdict):
        if a == "certified":
            assert b != "not_certified"
        if b == "not_certified":
            assert a == "not_certified"


def test_sampled_robust_schur_over_the_box():
    # Schur at τ = 0.1 but not at τ = 0.6 (H = 0.1, T* = 0.3)
    kx, kv = 2.0, 0.3
    r = [np.max(np.abs(pair_roots(kx, kv, t, 0.3, 0.1))) for t in (0.1, 0.6)]
    assert r[0] < 1 < r[1]
    c = certify(kx, kv, 0.0, tau=(0.1, 0.6), delta=0.2, headway=0.3, sample_time=0.1)
    assert c.verdict == "not_certified" and not c.stable and c.sup_gain == np.inf
    assert np.max(np.abs(pair_roots(kx, kv, c.witness_tau, c.witness_headway, 0.1))) >= 1
    assert certify(kx, kv, 0.0, tau=0.1, delta=0.2, headway=0.3, sample_time=0.1).schur


def test_records_are_strict_json():
    b = certify_batch([1.2, 0.0], [0.5, 1.0], [0.6, 0.5], tau=(0.1, 0.2), delta=0.2,
                      headway=1.1)
    rows = json.loads(json.dumps(b.records()))
    assert rows[0]["verdict"] == "certified" and rows[1]["sup_gain"] is None
    assert set(rows[0]["witness"]) == {"tau", "tau_prev", "delta", "headway", "omega", "theta"}
    assert b.summary()["n"] == 2


def test_the_box_of_one_member_matches_the_nominal_certificate():
    c = Loop(check_box(0.1, 0.2, 1.1)).certify_batch(0.9, -0.5, 1.1)[0]  # the box of one member
    n = certify(0.9, -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1)
    assert c.verdict == n.verdict == "not_certified"
    assert_allclose(c.sup_gain, n.sup_gain, rtol=1e-6)
    with pytest.raises(StringStabError, match="one triple"):
        certify([1.0, 2.0], 0.5, 0.2, tau=(0.1, 0.2), delta=0.2, headway=1.1)


def test_continuous_box_sup_gain_is_the_witness_members_peak_on_a_fine_sweep():
    # sup|Γ| of a not-certified box is the peak of its witness member (reporting): the search
    # (a 129-point grid, the resonances, zoom) against a 40,001-point sweep of |Γ(jω)| on
    # [0, 60] rad/s, refined by a local 2,001-point sweep around the sweep's best (a coarser
    # search, e.g. without the zoom, fails it)
    rng = np.random.default_rng(31)
    K = rng.uniform(-2, 2, (400, 3))
    b = certify_batch(*K.T, tau=(0.1, 0.2), delta=(0.15, 0.25), headway=(1.0, 1.2))
    rows = np.flatnonzero((b.verdict == "not_certified") & b.stable)
    assert rows.size > 50
    w = np.linspace(0.0, 60.0, 40_001)
    for i in rows:
        t, d, h = b.witness_tau[i], b.witness_delta[i], b.witness_headway[i]
        g = np.abs(gamma(w, *K[i], t, d, h))
        j = int(np.argmax(g))
        fine = np.linspace(w[max(j - 1, 0)], w[min(j + 1, w.size - 1)], 2_001)
        truth = max(g[j], float(np.max(np.abs(gamma(fine, *K[i], t, d, h)))))
        assert b.sup_gain[i] >= truth * (1 - 1e-9), (i, b.sup_gain[i], truth)
        # and it is attained: |Γ| at the reported frequency (a sharper peak than the sweep's)
        assert_allclose(b.sup_gain[i], abs(gamma(b.witness_omega[i], *K[i], t, d, h)), rtol=1e-9)
