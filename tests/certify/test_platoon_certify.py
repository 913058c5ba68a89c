"""The head-to-tail certificate of heterogeneous strings (issue 27, item 1).

Independent truths: ∏|Γ_i(jω)| from the model's transfer function written out in complex
arithmetic on a fine grid and ``numpy.roots`` (``analysis/platoon_validate.py``, run here on a
small seeded set), the sampled loop's state-space construction with ``scipy.linalg.expm``
(``tests/_sampled_truth.py``), closed-form derivatives for the interval jets, dense sampling
for the ranges of cos and sin, and exact rational arithmetic for the round-off bound of G.
"""

from __future__ import annotations

import importlib.util
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from stringstab.certify.api import certify, certify_string
from stringstab.certify.head_to_tail import (
    ContinuousString,
    StringArrays,
    Vehicle,
    point_margin,
    square_sum,
    string_margin,
)
from stringstab.certify.head_to_tail_sampled import SampledString
from stringstab.certify.interval import Interval
from stringstab.certify.interval_jets import Enclosure, Jet, cos_range, jet_cos, jet_sin, sin_range
from stringstab.certify.string_decision import decide
from stringstab.errors import StringStabError
from stringstab.params import Params

ROOT = Path(__file__).resolve().parents[2]


def _load(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


VALIDATE = _load(ROOT / "analysis" / "platoon_validate.py", "platoon_validate")
TRUTH = _load(ROOT / "tests" / "_sampled_truth.py", "_sampled_truth_h2t")

ACC = {"k_x": 0.1, "k_v": 0.3, "k_a": 0.0, "tau": 0.5, "delta": 0.0, "headway": 1.5}
CAV = {"k_x": 0.5, "k_v": 1.0, "k_a": 0.6, "tau": 0.2, "delta": 0.2, "headway": 2.0}


# ----------------------------------------------------------------------------- jets
def test_trig_ranges_enclose_dense_samples():
    rng = np.random.default_rng(0)
    a = rng.uniform(-20, 20, 400)
    b = a + rng.exponential(1.5, 400)
    for rng_f, f in ((cos_range, np.cos), (sin_range, np.sin)):
        lo, hi = rng_f(a, b)
        x = a[:, None] + (b - a)[:, None] * np.linspace(0, 1, 2001)[None, :]
        v = f(x)
        assert np.all(lo <= v.min(axis=1)) and np.all(hi >= v.max(axis=1))
        # and tight: within the sampling error of the true range
        assert np.allclose(lo, v.min(axis=1), atol=1e-5) and np.allclose(hi, v.max(axis=1), atol=1e-5)


def test_jets_enclose_the_closed_form_derivatives():
    # f(x) = x² sin(3x) − cos(0.5x) x³:  f'' in closed form, sampled densely on each interval
    def f2(x):
        return (2 * np.sin(3 * x) + 12 * x * np.cos(3 * x) - 9 * x * x * np.sin(3 * x)
                - (6 * x * np.cos(0.5 * x) - 3 * x * x * np.sin(0.5 * x) - 0.25 * x ** 3 * np.cos(0.5 * x)))

    L = np.linspace(0.0, 9.0, 60)[:, None]
    R = L + 0.15
    x = Jet.variable(L, R)
    f = x * x * jet_sin(3.0 * x) - jet_cos(0.5 * x) * (x * x * x)
    M = f.bound2()
    xs = L + (R - L) * np.linspace(0, 1, 301)[None, :]
    true = np.abs(f2(xs)).max(axis=1, keepdims=True)
    assert np.all(M >= true)
    assert np.all(M <= true * 1.5 + 40.0)  # an enclosure, not a wild overestimate
    # the value and the first derivative enclose too
    vals = xs * xs * np.sin(3 * xs) - np.cos(0.5 * xs) * xs ** 3
    assert np.all(f.v.lo <= vals.min(axis=1, keepdims=True))
    assert np.all(f.v.hi >= vals.max(axis=1, keepdims=True))


def test_enclosures_round_outward():
    e = Enclosure(np.array([0.1])) * 3.0 + Enclosure(np.array([0.2]))
    exact = Fraction(0.1) * 3 + Fraction(0.2)
    assert Fraction(float(e.lo[0])) <= exact <= Fraction(float(e.hi[0]))
    assert float(e.hi[0] - e.lo[0]) < 1e-15


# ----------------------------------------------------------------------------- the margin
def _random_strings(n, L, seed):
    rng = np.random.default_rng(seed)
    return [[VALIDATE.random_vehicle(rng) for _ in range(L)] for _ in range(n)]


def test_the_telescoping_margin_is_the_product_identity():
    # ω² G = ∏ d_i − ∏ n_i (module docstring), checked with |N_i|², |D_i|² of the written-out model
    S = _random_strings(20, 5, 3)
    loop = ContinuousString(StringArrays.of(S))
    W = np.linspace(0.05, 3.0, 40)[None, :].repeat(20, axis=0)
    G, _, gain2 = point_margin(loop.parts(np.arange(20), Interval(W)), loop.scale[:, :, None])
    prod_d = np.ones_like(W)
    prod_n = np.ones_like(W)
    for i in range(5):
        for j, s in enumerate(S):
            v, p = s[i], s[i].params
            sj = 1j * W[j]
            n = np.abs(v.k_x + v.k_v * sj + v.k_a * sj * sj * np.exp(-p.delta * sj)) ** 2
            d = np.abs(p.tau * sj ** 3 + sj * sj + (v.k_v + p.headway * v.k_x) * sj + v.k_x) ** 2
            prod_n[j] *= n * loop.scale[i, j]
            prod_d[j] *= d * loop.scale[i, j]
    np.testing.assert_allclose(W * W * G, prod_d - prod_n, rtol=1e-9, atol=1e-12 * np.abs(prod_d).max())
    np.testing.assert_allclose(gain2, prod_n / prod_d, rtol=1e-10)


def test_string_margin_with_scalars():
    n, d = [0.5, 2.0, 1.0, 0.3], [1.0, 1.5, 3.0, 0.7]
    G = string_margin([(a, b, b - a) for a, b in zip(n, d)])  # at ω = 1
    assert G == pytest.approx(np.prod(d) - np.prod(n), rel=1e-14)


def test_the_round_off_bound_holds_against_exact_arithmetic():
    # the parts at points, carried to G in exact rational arithmetic: |G − G_exact| ≤ slack
    S = _random_strings(6, 4, 11)
    loop = ContinuousString(StringArrays.of(S))
    W = np.array([[0.0, 0.3, 1.7, 4.0]]).repeat(6, axis=0)
    parts = loop.parts(np.arange(6), Interval(W))
    G, E, _ = point_margin(parts, loop.scale[:, :, None])
    for j in range(6):
        for k in range(W.shape[1]):
            terms = []
            for i, p in enumerate(parts):
                c = Fraction(float(loop.scale[i, j]))
                n = c * (Fraction(float(p.re_n.lo[j, k])) ** 2 + Fraction(float(p.im_n.lo[j, k])) ** 2)
                d = c * (Fraction(float(p.re_d.lo[j, k])) ** 2 + Fraction(float(p.im_d.lo[j, k])) ** 2)
                terms.append((n, d, c * Fraction(float(p.g.lo[j, k]))))
            exact = string_margin(terms)  # of the computed parts: isolates the products' rounding
            assert abs(Fraction(float(G[j, k])) - exact) <= Fraction(float(E[j, k]))


def test_square_sum_relative_error_bounds_cancellation():
    re = Interval(np.array([1e-8]), None, np.array([1.0]))  # a part computed with cancellation
    im = Interval(np.array([0.0]), None, np.array([1.0]))
    v, r = square_sum(re, im)
    assert v[0] == pytest.approx(1e-16) and r[0] > 1e-6  # the relative error is large, and said so


# ----------------------------------------------------------------------------- verdicts
def test_random_strings_are_sound_against_the_fine_grid():
    res = VALIDATE.run(40, seed=5, sampled_share=0.25, near=0.2, chunk=40)
    counts = res["counts"]
    assert res["unsound"] == []
    verdicts = {k[1] for k in counts}
    assert {"certified", "not_certified"} <= verdicts  # the check could have failed either way
    assert sum(counts.values()) == 40


def test_a_one_vehicle_string_is_the_one_vehicle_certificate():
    rng = np.random.default_rng(7)
    S = [[VALIDATE.random_vehicle(rng)] for _ in range(60)]
    dec = decide(ContinuousString(StringArrays.of(S)), n_grid=64)
    for j, (v,) in enumerate(S):
        c = certify(v.k_x, v.k_v, v.k_a, tau=v.params.tau, delta=v.params.delta, headway=v.params.headway)
        if "inconclusive" not in (c.verdict, ("certified", "not_certified", "inconclusive")[dec.verdict[j]]):
            assert ("certified", "not_certified", "inconclusive")[dec.verdict[j]] == c.verdict


def test_the_sampled_factors_are_the_state_space_responses():
    S = _random_strings(8, 3, 21)
    lt = np.full(8, 0.4)
    loop = SampledString(StringArrays.of(S), 0.1, lt)
    th = np.linspace(0.01, np.pi, 25)
    parts = loop.parts(np.arange(8), Interval(th[None, :].repeat(8, axis=0)))
    _, _, gain2 = point_margin(parts, loop.scale[:, :, None])
    for j, s in enumerate(S):
        truth = VALIDATE.product_sampled(TRUTH, s, th, 0.4) ** 2
        np.testing.assert_allclose(gain2[j], truth, rtol=1e-8)


def test_certify_string_reports_each_vehicle_and_the_worst_substring():
    c = certify_string([ACC, ACC, CAV])
    assert [x.verdict for x in c.certificates] == ["not_certified", "not_certified", "certified"]
    sub = {(r.first, r.last): r.verdict for r in c.substrings}
    assert sub[(1, 2)] == "not_certified"  # two amplifying cars amplify
    w = c.worst_substring
    assert w is not None and w.verdict == "not_certified"
    assert w.length == max(r.length for r in c.substrings if r.verdict == "not_certified")
    # the JSON shape of ``stringstab platoon certify --format json``
    d = c.as_dict()
    assert set(d) == {"head_to_tail", "vehicles"}
    assert {"verdict", "sup_gain", "peak_omega", "worst_substring"} <= set(d["head_to_tail"])
    assert [v["position"] for v in d["vehicles"]] == [1, 2, 3]


def test_a_cav_behind_an_amplifying_car_can_certify_the_pair():
    c = certify_string([ACC, CAV])
    assert c.verdict == "certified" and c.sup_gain == 1.0
    grid = np.linspace(0, 10, 200_001)
    prod = VALIDATE.product_continuous([Vehicle(**{k: v for k, v in d.items() if k.startswith("k_")},
                                                params=Params(d["tau"], d["delta"], d["headway"]))
                                        for d in (ACC, CAV)], grid)
    assert prod.max() <= 1 + 1e-12
    assert certify(**{k: v for k, v in ACC.items() if k.startswith("k_")}, tau=0.5, delta=0.0,
                   headway=1.5).verdict == "not_certified"


def test_a_not_certified_string_has_a_witness_where_the_product_exceeds_one():
    c = certify_string([ACC, ACC])
    assert c.verdict == "not_certified" and c.sup_gain > 1
    v = Vehicle(0.1, 0.3, 0.0, Params(0.5, 0.0, 1.5))
    at = VALIDATE.product_continuous([v, v], np.array([c.witness_omega]))[0]
    assert at > 1.0
    assert c.sup_gain == pytest.approx(VALIDATE.product_continuous([v, v]).max(), rel=1e-6)


def test_an_unstable_vehicle_makes_the_string_not_certified():
    bad = dict(CAV, k_v=-2.0)
    c = certify_string([CAV, bad])
    assert c.verdict == "not_certified" and "not internally stable" in c.reason
    assert c.sup_gain == float("inf")


def test_sampled_strings_take_the_predecessors_lag():
    c = certify_string([ACC, CAV], sample_time=0.1, leader_tau=0.5)
    assert c.sample_time == 0.1 and c.leader_tau == 0.5
    assert c.certificates[1].tau_prev == 0.5  # the CAV follows the ACC car (τ = 0.5)


# ----------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("vehicles, match", [
    ([], "at least 2 vehicles"),
    ([ACC], "at least 2 vehicles"),
    ([ACC, {k: v for k, v in CAV.items() if k != "tau"}], "vehicle 2: missing tau"),
    ([ACC, dict(CAV, k_x=float("nan"))], "vehicle 2: k_x must be finite"),
    ([dict(ACC, tau=-0.5), CAV], "vehicle 1: tau .* must be a finite number > 0"),
    ([ACC, dict(CAV, headway=1e9)], "vehicle 2: .*far outside"),
    ([ACC, dict(CAV, reaction_delay=-0.3, name="cav")], r"vehicle 2 \(cav\): reaction_delay"),
    ("ACC", "sequence of vehicles"),
])
def test_bad_strings_are_refused_in_one_line(vehicles, match):
    with pytest.raises(StringStabError, match=match) as e:
        certify_string(vehicles)
    assert "\n" not in str(e.value)


def test_leader_tau_needs_a_sample_time():
    with pytest.raises(StringStabError, match="leader_tau"):
        certify_string([ACC, CAV], leader_tau=0.3)


def test_a_reaction_delay_per_vehicle():
    # θ_r enters each vehicle's own Γ_i (issue 25): the head-to-tail verdict follows the grid
    # of the written-out model, and the sampled loop refuses it in one line
    for theta, verdict in ((0.05, "certified"), (0.5, "not_certified")):
        vs = [ACC, dict(CAV, reaction_delay=theta)]
        c = certify_string(vs)
        assert c.verdict == verdict
        model = [Vehicle(d["k_x"], d["k_v"], d["k_a"],
                         Params(d["tau"], d["delta"], d["headway"], d.get("reaction_delay", 0.0)))
                 for d in vs]
        peak = VALIDATE.product_continuous(model).max()
        assert (peak <= 1 + 1e-9) == (verdict == "certified")
        assert c.certificates[1].params.reaction_delay == theta
    with pytest.raises(StringStabError, match="reaction delay"):
        certify_string([ACC, dict(CAV, reaction_delay=0.1)], sample_time=0.1)
