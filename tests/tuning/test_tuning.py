"""Gain repair (stringstab.tuning): region growing (IDL §3.3) and the nearest-point projection.

Independent truth: every output reported certified is re-checked by a dense
frequency sweep of |Γ(jω)| (:func:`stringstab.certify.frequency.gain`) and by the
poles of Γ's denominator from ``numpy.roots`` — neither is used by the code
under test.  The region-growing cases are worked by hand from the closed-form
Ψ of a delay-free model (δ = 0, where Ψ1 = τ², Ψ2 = 1 − 2τ(k_v + T*k_x) − k_a²,
Ψ3 = k_x(T*²k_x + 2T*k_v + 2k_a − 2)).
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from stringstab.certify.api import certify, certify_batch
from stringstab.certify.frequency import gain
from stringstab.errors import StringStabError
from stringstab.plots import moves_projection, plot_moves
from stringstab.tuning import Projector, TuneResult, project, region_growing, tune

P = {"tau": 0.1, "delta": 0.2, "headway": 1.1}
# delay-free model of the hand-worked region-growing cases
P0 = {"tau": 0.1, "delta": 0.0, "headway": 1.5}


def sweep_ok(K, tau, delta, headway, n=200_000):
    """Independent check: Hurwitz by numpy.roots and max |Γ(jω)| ≤ 1 + 1e-9 on a dense grid.

    Beyond Ω, the largest root of ½τω³ − |k_a|ω² − (½|c| + |k_v|)ω − |k_x|
    (c = k_v + T*k_x), |Γ(jω)| ≤ (|k_x| + |k_v|ω + |k_a|ω²)/(ω(τω² − |c|)) ≤ ½.
    """
    kx, kv, ka = K
    c = kv + headway * kx
    poles = np.roots([tau, 1.0, c, kx])
    if not np.all(poles.real < 0):
        return False
    r = np.roots([0.5 * tau, -abs(ka), -(0.5 * abs(c) + abs(kv)), -abs(kx)])
    om = max(float(max(z.real for z in r if abs(z.imag) < 1e-9)), 1.0) * 1.01
    w = np.concatenate([np.geomspace(1e-6, 1.0, 20_000), np.linspace(0.0, om, n)])
    return bool(np.max(gain(w, kx, kv, ka, **{"tau": tau, "delta": delta, "headway": headway}))
                <= 1.0 + 1e-9)


def test_sweep_check_can_fail():
    # the paper's example: |Γ| peaks at 1.044 near ω = 1.70 rad/s; and a non-Hurwitz triple
    assert not sweep_ok((0.9, -0.5, 1.1), **P)
    assert not sweep_ok((-0.5, 1.0, 1.0), **P)
    assert sweep_ok((1.3, 0.0, 0.6), **P)


# ---------------------------------------------------------------------------
# Region growing, hand-worked (δ = 0, T* = 1.5, τ = 0.1, r0 = 0.1, grid = 1)
# ---------------------------------------------------------------------------
def test_region_growing_type_iii_first_region():
    # K0 = (0.5, 0.125, 0.125): Ψ3 = 0.5 (2.25·0.5 + 3·0.125 + 2·0.125 − 2) = 0.5·(−0.25) < 0,
    # type III.  One step of 0.1 raises the bracket by 0.225 (k_x), 0.3 (k_v) or 0.2 (k_a):
    # only k_v + 0.1 makes Ψ3 ≥ 0 (0.5·0.05), with Ψ2 = 1 − 0.2(0.225 + 0.75) − 0.125² > 0
    # (type I); every other accepted point of R1 is further away.
    r = region_growing((0.5, 0.125, 0.125), **P0, r0=0.1, grid=1)
    assert r.status == "repaired"
    assert r.iterations == 1
    assert r.details["type_in"] == "III" and r.details["type_out"] == "I"
    assert_allclose(r.k, (0.5, 0.225, 0.125), rtol=0, atol=1e-12)
    assert_allclose(r.distance, 0.1, rtol=1e-12)
    assert r.certified and sweep_ok(r.k, **P0)


def test_region_growing_grows_to_second_region():
    # K0 = (0.5, 0.015, 0.01): bracket = −0.81; R1 can raise it by at most
    # 0.225 + 0.3 + 0.2 = 0.725, so R1 fails.  In R2 (k_x, k_v ± 0.2, k_a ± 0.1 as printed)
    # the nearest point with 0.225 i + 0.3 j + 0.2 l ≥ 0.81 is (i, j, l) = (1, 2, 0),
    # |offset| = 0.1·√5, unique.
    r = region_growing((0.5, 0.015, 0.01), **P0, r0=0.1, grid=1)
    assert r.status == "repaired"
    assert r.iterations == 2
    assert_allclose(r.k, (0.6, 0.215, 0.01), rtol=0, atol=1e-12)
    assert_allclose(r.distance, 0.1 * math.sqrt(5), rtol=1e-12)
    assert r.certified and sweep_ok(r.k, **P0)
    # with a single region the paper's "No optimized solution found" outcome, K0 returned
    r1 = region_growing((0.5, 0.015, 0.01), **P0, r0=0.1, grid=1, max_iter=1)
    assert r1.status == "no_solution" and r1.iterations == 1
    assert r1.k == (0.5, 0.015, 0.01) and not r1.certified
    assert "No optimized solution found" in r1.message


def test_region_growing_type_iii_exclusion():
    # K0 = (−0.5, 0.725, 0.6): k_x < 0, bracket = +0.25, Ψ3 = −0.125 < 0 (type III).
    # The nearest accepted grid point, k_v − 0.1 (bracket −0.05, Ψ3 = +0.025), lies in the
    # excluded slice {k_x = k_x0, k_v ≤ k_v0, k_a ≤ k_a0}; so do (0,−1,−1).  Next nearest
    # (0.1·√2): (−1,−1,0) and (−1,0,−1), tie broken lexicographically → (−0.6, 0.625, 0.6).
    r = region_growing((-0.5, 0.725, 0.6), **P0, r0=0.1, grid=1)
    assert r.status == "moved_not_certified" and r.iterations == 1  # not "repaired": not certified
    assert_allclose(r.k, (-0.6, 0.625, 0.6), rtol=0, atol=1e-12)
    # not internally stable (k_x < 0): the paper's Taylor test accepts it, the certificate not
    assert not r.certified and not sweep_ok(r.k, **P0)
    # with the (non-paper) internal-stability requirement it moves to k_x > 0
    rh = region_growing((-0.5, 0.725, 0.6), **P0, r0=0.1, grid=1, check_hurwitz=True)
    assert rh.k[0] > 0
    assert rh.certified == sweep_ok(rh.k, **P0)


def test_region_growing_brute_force_agrees():
    # Independent enumeration of R1..R3 with the closed-form δ = 0 criteria.
    tau, T = P0["tau"], P0["headway"]
    K0 = np.array([0.7, -0.3, 0.21])

    def accepted(K):
        kx, kv, ka = K
        psi2 = 1 - 2 * tau * (kv + T * kx) - ka**2
        psi3 = kx * (T * T * kx + 2 * T * kv + 2 * ka - 2)
        lam = psi2**2 - 4 * tau**2 * psi3
        return psi3 >= 0 and (psi2 >= 0 or lam <= 0)

    best = None
    for k in range(1, 4):
        cands = []
        for i in range(-2 * k, 2 * k + 1):
            for j in range(-2 * k, 2 * k + 1):
                for m in range(-2, 3):
                    if k > 1 and max(abs(i), abs(j)) <= 2 * (k - 1):
                        continue
                    if k == 1 and i == 0 and j <= 0 and m <= 0:
                        continue  # type-III exclusion (K0 is type III)
                    K = K0 + 0.05 * np.array([i, j, m])
                    if accepted(K):
                        cands.append((round(float(np.linalg.norm(K - K0)), 12), i, j, m, K))
        if cands:
            best = (k, min(cands, key=lambda c: c[:4])[4])
            break
    assert best is not None
    r = region_growing(K0, **P0, r0=0.1, grid=2, max_iter=3)
    assert r.details["type_in"] == "III"
    assert r.iterations == best[0]
    assert_allclose(r.k, best[1], rtol=0, atol=1e-12)


def test_region_growing_taylor_stable_input_left_alone():
    # The printed Proposition 1 calls the paper-style example stable (type II): the paper's
    # method does not act; the exact certificate says it is not string stable.
    r = region_growing((0.9, -0.5, 1.1), **P, criterion="printed")
    assert r.status == "taylor_stable" and r.k == r.k_in and not r.certified
    assert r.verdict == "not_certified"


def test_region_growing_keeps_ka_within_r0_as_printed():
    r = region_growing((1.9, 1.9, 1.9), **P)
    assert abs(r.k[2] - 1.9) <= 0.1 + 1e-12
    rg = region_growing((1.9, 1.9, 1.9), **P, grow_ka=True, check_hurwitz=True)
    assert rg.status == "repaired" and abs(rg.k[2] - 1.9) > 0.1


# ---------------------------------------------------------------------------
# Unchanged when already certified
# ---------------------------------------------------------------------------
CERTIFIED = [(1.3, 0.0, 0.6), (1.5, 0.3, -0.1), (0.45, 0.6, 0.3)]


@pytest.mark.parametrize("K", CERTIFIED)
@pytest.mark.parametrize("method", ["region-growing", "projection"])
def test_certified_input_returned_unchanged(K, method):
    assert certify(*K, **P).certified
    r = tune(K, method, **P)
    assert r.status == "unchanged"
    assert r.k == tuple(float(v) for v in K) and r.k_in == r.k
    assert r.distance == 0.0 and r.iterations == 0 and r.certified and not r.changed
    assert "solve" not in r.message


def test_projector_unchanged_without_solve():
    pr = Projector(**P)
    r = pr((1.3, 0.0, 0.6))
    assert r.status == "unchanged" and r.details == {}


# ---------------------------------------------------------------------------
# Projection
# ---------------------------------------------------------------------------
REPAIR = [(0.9, -0.5, 1.1), (-0.5, 1.0, 1.0), (0.2, 0.7, 0.0), (1.9, 1.9, 1.9), (-1.9, -1.9, -1.9),
          (1.0, -1.2, 0.5)]


@pytest.mark.parametrize("predictor", [True, False])
@pytest.mark.parametrize("K", REPAIR)
def test_projection_output_passes_fine_sweep(K, predictor):
    r = project(K, **P, predictor=predictor)
    if not predictor:
        assert not r.details["predictor"]
    assert isinstance(r, TuneResult)
    assert r.status == "repaired" and r.certified and r.verdict == "certified"
    assert sweep_ok(r.k, **P)
    assert all(-2.0 <= v <= 2.0 for v in r.k)
    assert r.k[0] >= 1e-3 - 1e-9
    assert r.k[1] + (P["headway"] - P["tau"]) * r.k[0] >= 1e-3 - 1e-9
    assert_allclose(r.distance, np.linalg.norm(np.subtract(r.k, K)), rtol=1e-12)


@pytest.mark.parametrize("K", REPAIR + CERTIFIED)
def test_projection_reports_what_certify_reports(K):
    # the projection decides with check() and builds its report from it; the
    # verdict and sup |Γ| it reports must be those of the full certificate
    r = project(K, **P)
    c = certify(*r.k, **P)
    assert (r.verdict, r.certified) == (c.verdict, c.certified)
    assert r.sup_gain == c.sup_gain


def test_projection_one_solve_near_the_boundary():
    # the paper's example: the dip of the repaired gains (predicted from the
    # linearised constraint) is in the first frequency set, so one solve suffices
    r = project((0.9, -0.5, 1.1), **P)
    assert r.certified and r.iterations == 1 and sweep_ok(r.k, **P)


# near-boundary inputs (bench_tune.py's boundary set, seed 0) whose solution has a single
# active constraint: Ψ3 = g(0) ≥ ε, or the margin k_x ≥ m, or g ≥ ε at a dip ω > 0
PREDICTOR_CASES = [
    ((1.2793, 0.2508, -0.1154), "psi3"),
    ((0.7645, 0.8174, -0.3711), "psi3"),
    ((-0.0004, 0.7911, 0.2411), "k_x >= m"),
    ((0.9, -0.5, 1.1), "g >= eps at the dip"),
    ((0.8823, 1.3741, 0.7167), "g >= eps at the dip"),
    ((1.4466, 1.537, 0.7365), "g >= eps at the dip"),
]


@pytest.mark.parametrize("K, kind", PREDICTOR_CASES)
def test_projection_predictor_certified_and_as_near_as_ipopt(K, kind):
    # the Newton predictor (no IPOPT solve) returns a certified output that passes the
    # independent dense sweep and numpy.roots, at the distance of the IPOPT path
    r = project(K, **P)
    assert r.details["predictor"] and r.status == "repaired" and r.certified
    assert r.details["ipopt_iterations"] == 0 and r.iterations == 1
    assert len(r.details["active"]) == 1 and r.details["active"][0].startswith(kind)
    assert sweep_ok(r.k, **P)
    ref = project(K, **P, predictor=False)
    assert not ref.details["predictor"] and ref.certified
    if "dip" not in kind:
        # the same point; IPOPT (an interior-point method, tol 1e-8) stops up to ~2e-6 inside
        # an active margin, so it may be further, never nearer
        assert -2e-6 <= r.distance - ref.distance <= 1e-9
        assert_allclose(r.k, ref.k, rtol=0, atol=1e-5)
        return
    # at a dip ω* > 0 the predictor has g(ω*) = ε at the dip itself, IPOPT only on its
    # frequency grid (0.98, 1, 1.02 × the predicted dip): it may be nearer by up to ~1e-5,
    # never further by more than rounding; with ω* in IPOPT's set the two agree to ~1e-6
    assert -1e-9 <= r.distance - ref.distance <= 2e-5
    w_star = float(r.details["active"][0].rsplit("=", 1)[1])
    pr = Projector(**P, predictor=False)
    k0 = np.asarray(K, dtype=float)
    x, status, _ = pr._solve(k0, k0 + 0.5 * (np.asarray(r.k) - k0),
                             [*r.details["frequencies"], w_star])
    assert status == "Solve_Succeeded"
    assert_allclose(np.linalg.norm(x - k0), r.distance, rtol=0, atol=1e-6)
    assert_allclose(x, r.k, rtol=0, atol=1e-5)


@pytest.mark.parametrize("K", [(-1.9, -1.9, -1.9), (1.4296, -1.8657, 0.9186)])
def test_projection_predictor_hands_over_to_ipopt(K):
    # far from the certified set Newton's method does not find the active set: IPOPT
    # decides (the same result as without the predictor), certified and passing the sweep
    r = project(K, **P)
    assert not r.details["predictor"] and r.details["ipopt_iterations"] > 0
    assert r.certified and sweep_ok(r.k, **P)
    assert r.k == project(K, **P, predictor=False).k


@pytest.mark.parametrize("K", [(0.9, -0.5, 1.1), (0.2, 0.7, 0.0), (1.0, -1.2, 0.5)])
def test_projection_no_further_than_region_growing(K):
    rg = region_growing(K, **P)
    pj = project(K, **P)
    assert rg.status == "repaired" and rg.certified  # a fair comparison: both certified
    assert pj.distance <= rg.distance + 1e-9


def test_projection_hand_case_delay_free():
    # δ = 0: g(ω) = τ²ω⁴ + Ψ2 ω² + Ψ3 and Ψ2 > 0 near K0, so the only active constraint is
    # Ψ3 = k_x(T²k_x + 2T k_v + 2k_a − 2) ≥ ε.  Nearest point for K0 = (0.5, 0.125, 0.125):
    # to first order, move along ∇Ψ3 = (2T²k_x + 2Tk_v + 2k_a − 2, 2Tk_x, 2k_x).
    r = project((0.5, 0.125, 0.125), **P0)
    assert r.certified and sweep_ok(r.k, **P0)
    kx, kv, ka = r.k
    psi3 = kx * (2.25 * kx + 3 * kv + 2 * ka - 2)
    assert_allclose(psi3, 1e-4, rtol=1e-3)  # the constraint is active at ε
    grad = np.array([4.5 * kx + 3 * kv + 2 * ka - 2, 3 * kx, 2 * kx])
    move = np.subtract(r.k, (0.5, 0.125, 0.125))
    cos = move @ grad / (np.linalg.norm(move) * np.linalg.norm(grad))
    assert_allclose(cos, 1.0, atol=1e-6)  # KKT: the move is parallel to the gradient
    assert r.distance < region_growing((0.5, 0.125, 0.125), **P0, r0=0.1, grid=1).distance


def test_projection_weights():
    K = (0.9, -0.5, 1.1)
    heavy_ka = project(K, **P, weights=(1.0, 1.0, 100.0))
    assert heavy_ka.certified and sweep_ok(heavy_ka.k, **P)
    assert abs(heavy_ka.k[2] - 1.1) < abs(project(K, **P).k[2] - 1.1)


def test_projection_warm_start_and_fast_path():
    pr = Projector(**P)
    a = pr((0.9, -0.5, 1.1))
    hit = pr((0.9, -0.5, 1.1))
    assert hit.details.get("cache_hit") and hit.k == a.k and hit.certified
    near = pr((0.9, -0.49, 1.1))  # no warm start from the previous output by default
    assert near.details["start"] == "map" and near.certified and sweep_ok(near.k, **P)
    assert pr.stats["cache_hits"] == 1 and pr.stats["warm_starts"] == 0
    pw = Projector(**P, warm_from_previous=True)
    pw((0.9, -0.5, 1.1))
    near = pw((0.9, -0.49, 1.1))
    assert near.details["start"] == "previous" and near.certified and sweep_ok(near.k, **P)
    assert pw.stats["warm_starts"] == 1
    ws = project((0.9, -0.5, 1.1), **P, warm_start=a.k)
    assert ws.details["start"] == "warm_start" and ws.certified
    assert_allclose(ws.k, a.k, atol=1e-5)


@settings(max_examples=15, deadline=None)
@given(st.tuples(*[st.floats(-2.0, 2.0, allow_nan=False)] * 3))
def test_property_projection_certified_outputs_pass_sweep(K):
    r = project(K, **P)
    assert r.certified  # every input in the bounds is repairable
    assert sweep_ok(r.k, **P)
    if r.status == "unchanged":
        assert r.k == tuple(float(v) for v in K)


@settings(max_examples=15, deadline=None)
@given(st.tuples(st.floats(0.05, 2.0), st.floats(-1.0, 2.0), st.floats(-1.0, 1.5)))
def test_property_region_growing_certified_outputs_pass_sweep(K):
    r = region_growing(K, **P, r0=0.2, grid=1)
    if r.certified:
        assert sweep_ok(r.k, **P)
    b = certify_batch([r.k[0]], [r.k[1]], [r.k[2]], **P)
    assert bool(b.certified[0]) == r.certified


# ---------------------------------------------------------------------------
# Errors and plot
# ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: project((0.9, -0.5), **P), "three numbers"),
        (lambda: project((0.9, float("nan"), 1.0), **P), "k_v must be finite"),
        (lambda: project((0.9, -0.5, 1.1), **P, weights=(1, 0, 1)), "weights"),
        (lambda: project((0.9, -0.5, 1.1), **P, eps=0), "eps"),
        (lambda: project((0.9, -0.5, 1.1), tau=-1, delta=0.2, headway=1.1), "tau"),
        (lambda: region_growing((0.9, -0.5, 1.1), **P, r0=0), "r0"),
        (lambda: region_growing((0.9, -0.5, 1.1), **P, grid=0), "grid"),
        (lambda: region_growing((0.9, -0.5, 1.1), **P, bounds=(2, -2)), "bounds"),
        (lambda: region_growing((0.9, -0.5, 1.1), **P, criterion="exact"), "criterion"),
        (lambda: tune((0.9, -0.5, 1.1), "newton", **P), "method"),
    ],
)
def test_bad_input_raises(call, match):
    with pytest.raises(StringStabError, match=match):
        call()


def test_plot_moves():
    import matplotlib.pyplot as plt

    rs = [f((0.9, -0.5, 1.1), **P) for f in (region_growing, project)]
    out = plot_moves(rs, moves_projection(rs, **P, n=21))
    assert len(out["arrows"]) == 2
    assert out["ax"].get_xlabel() == "$k_x$ (s$^{-2}$)"  # the gain with its unit
    # the background is the region projected over the outputs' own k_a: each certified output
    # lies in a cell certified at some (or every) evaluated k_a
    img = out["region"].get_array()
    x0, x1, y0, y1 = out["region"].get_extent()
    for r in rs:
        if r.certified:
            i = int((r.k[1] - y0) / (y1 - y0) * img.shape[0])
            j = int((r.k[0] - x0) / (x1 - x0) * img.shape[1])
            near = img[max(i - 1, 0):i + 2, max(j - 1, 0):j + 2]
            assert near.max() >= 1  # class 'some' or 'every'
    plt.close(out["ax"].figure)


def test_hand_derivatives_of_g_match_sympy():
    """The predictor's g, ∇_K g, g_ω, ∇_K g_ω, g_ωω, ∇²_KK g (stringstab.tuning.margin_terms.newton_terms
    and its vectorised twin margin_terms.gradient) equal SymPy's derivatives of the derived margin
    (|D|² − |N|²)/ω² (stringstab.derive.symbolic)."""
    import sympy as sp

    from stringstab.derive import symbolic as S
    from stringstab.tuning import margin_terms

    g = S.margin_exact() / S.omega**2
    K = list(S.GAINS)
    exprs = [g, *[sp.diff(g, k) for k in K], sp.diff(g, S.omega),
             *[sp.diff(g, S.omega, k) for k in K], sp.diff(g, S.omega, 2),
             *[sp.diff(g, a, b) for a in K for b in K]]
    f = sp.lambdify([*S.GAINS, *S.PARAMS, S.omega], exprs, "numpy")
    rng = np.random.default_rng(3)
    for _ in range(20):
        k = rng.uniform(-2, 2, 3)
        tau, delta, headway = rng.uniform(0.05, 0.6), rng.uniform(0, 0.5), rng.uniform(0.3, 2)
        om = rng.uniform(0.05, 8)
        ref = np.array(f(*k, tau, delta, headway, om), dtype=float)
        val, gk, gw, gwk, gww, gkk = margin_terms.newton_terms(om, *k, tau, delta, headway)
        ours = np.concatenate([[val], gk, [gw], gwk, [gww], np.asarray(gkk).ravel()])
        assert_allclose(ours, ref, rtol=1e-9, atol=1e-9 * (1 + float(np.max(np.abs(ref)))))
        gv, gk2 = margin_terms.gradient(np.array([om]), k, tau=tau, delta=delta, headway=headway)  # vectorised twin
        assert_allclose(np.concatenate([gv, gk2[0]]), ref[:4], rtol=1e-9,
                        atol=1e-9 * (1 + float(np.max(np.abs(ref)))))
