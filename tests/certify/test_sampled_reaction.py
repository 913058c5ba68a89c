"""The sampled certificate with a reaction delay θ_r > 0 (issue 25 item 3).

Independent truths: a hand-built transfer function for θ_r = qH (the command shifted by q
steps: the vehicle's P(z) times z^{−q}, from scipy's expm, not the certificate's closed forms),
numpy's eigenvalues for the Stein test, the continuous θ_r certificate as H → 0, and a tiny
seeded run of analysis/sampled_reaction_check.py (expm truth, input-output |H|, simulation).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

import stringstab as ss
from stringstab.certify.ball import Ball
from stringstab.certify.lifting import lifted_response
from stringstab.certify.lifting_reaction import follower_block, held_steps, lift_reaction
from stringstab.certify.stein import stein_schur
from stringstab.errors import StringStabError

SCRIPT = Path(__file__).resolve().parents[2] / "analysis" / "sampled_reaction_check.py"


def _vehicle(tau: float, H: float) -> tuple[np.ndarray, np.ndarray]:
    """Φ (3 × 3) and Γ (3) of one vehicle [p, v, a] over a held step, by expm."""
    M = np.zeros((4, 4))
    M[0, 1] = M[1, 2] = 1.0
    M[2, 2], M[2, 3] = -1.0 / tau, 1.0 / tau
    E = expm(M * H)
    return E[:3, :3], E[:3, 3]


def _shifted_H(k, tau, m, T, H, q, theta):
    """H(e^{jθ}) of the loop whose command is applied q whole steps late (δ = mH)."""
    Phi, G = _vehicle(tau, H)
    z = np.exp(1j * theta)
    X = np.array([np.linalg.solve(zz * np.eye(3) - Phi, G) for zz in z])  # P(z) without delay
    d = z ** (-q)
    Pp, Pv, Pa = X[:, 0] * d, X[:, 1] * d, X[:, 2] * d
    Q = Pa * z ** (-m)  # a_{i−1}(kH − mH)
    num = k[0] * Pp + k[1] * Pv + k[2] * Q
    return num / (1.0 + k[0] * (Pp + T * Pv) + k[1] * Pv)


@pytest.mark.parametrize("q, m", [(1, 0), (1, 2), (3, 1), (5, 4)])
def test_whole_steps_of_theta_are_a_shift_by_q_steps(q, m):
    tau, T, H = 0.3, 1.2, 0.1
    k = (0.4, 0.9, 0.3)
    p = ss.Params(tau, m * H, T, reaction_delay=q * H)
    assert held_steps(q * H, H) == (q, 0.0, q)
    link = lift_reaction(*(np.array([v]) for v in k), p, H, 1)
    th = np.linspace(0.01, np.pi, 37)
    got = lifted_response(link, th)[0, :, 0, 0]
    want = _shifted_H(k, tau, m, T, H, q, th)
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)


def test_a_fractional_theta_lies_between_its_whole_neighbours_at_low_frequency():
    # θ_r = (q + f)H: the two pieces weigh u_{k−q−1} by the fraction f of the step; at the
    # lowest frequencies |H| − 1 moves monotonically with θ_r between the whole-step loops
    tau, T, H, k = 0.3, 1.2, 0.1, (0.4, 0.9, 0.3)
    th = np.array([0.02])
    vals = []
    for theta in (0.1, 0.125, 0.15, 0.175, 0.2):
        link = lift_reaction(*(np.array([v]) for v in k), ss.Params(tau, 0.1, T, reaction_delay=theta), H, 1)
        vals.append(abs(lifted_response(link, th)[0, 0, 0, 0]))
    assert np.all(np.diff(vals) > 0) or np.all(np.diff(vals) < 0)
    np.testing.assert_allclose(vals[0], abs(_shifted_H(k, tau, 1, T, H, 1, th)[0]), rtol=1e-9)
    np.testing.assert_allclose(vals[-1], abs(_shifted_H(k, tau, 1, T, H, 2, th)[0]), rtol=1e-9)


def test_the_follower_block_has_the_loops_poles():
    # the closed loop's poles from the hand-built model: 1 + L(z) = 0 with the shifted P(z)
    tau, T, H, q = 0.3, 1.2, 0.1, 2
    k = (0.4, 0.9, 0.3)
    link = lift_reaction(*(np.array([v]) for v in k), ss.Params(tau, 0.0, T, reaction_delay=q * H), H, 1)
    Af = follower_block(link, q).mid[0]
    for lam in np.linalg.eigvals(Af):
        if abs(lam) < 1e-6:
            continue
        Phi, G = _vehicle(tau, H)
        P = np.linalg.solve(lam * np.eye(3) - Phi, G) * lam ** (-q)
        assert abs(1.0 + k[0] * (P[0] + T * P[1]) + k[1] * P[1]) < 1e-8


def test_stein_agrees_with_the_eigenvalues_away_from_the_circle():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(300, 5, 5)) * rng.uniform(0.1, 0.8, size=(300, 1, 1))
    rho = np.abs(np.linalg.eigvals(A)).max(axis=1)
    sure, fail = stein_schur(Ball.exact(A))
    assert not np.any(sure & fail)
    assert np.all(rho[sure] < 1.0) and np.all(rho[fail] > 1.0)
    far = np.abs(rho - 1.0) > 0.05
    assert np.all((sure | fail)[far])  # decided away from the boundary
    assert sure.sum() > 30 and fail.sum() > 30


@pytest.mark.parametrize("k", [(0.2, 0.6, 0.0), (2.0, 0.3, 0.0), (0.5, 0.1, 1.3)])
def test_small_sample_times_approach_the_continuous_theta_certificate(k):
    # far from the boundary: the H = 0.005 verdict equals the continuous one, and sup|H| is
    # close to sup|Γ| when not certified (H ≤ 0.002 is too costly for a test and can be left
    # inconclusive: docs/sampled.md §10.2)
    P = {"tau": 0.5, "delta": 0.01, "headway": 1.5, "reaction_delay": 0.02}
    c = ss.certify_batch(*([v] for v in k), **P)
    s = ss.certify_batch(*([v] for v in k), **P, sample_time=0.005)
    assert s.verdict[0] == c.verdict[0] != "inconclusive"
    if c.verdict[0] == "not_certified":
        np.testing.assert_allclose(s.sup_gain[0], c.sup_gain[0], rtol=5e-2)


def test_theta_zero_with_a_sample_time_is_todays_certificate():
    K = ([1.2, 0.3], [0.5, 0.9], [0.6, 0.2])
    a = ss.certify_batch(*K, tau=0.1, delta=0.2, headway=1.1, sample_time=0.1)
    b = ss.certify_batch(*K, tau=0.1, delta=0.2, headway=1.1, sample_time=0.1, reaction_delay=0.0)
    assert a.columns().keys() == b.columns().keys()
    for key, v in a.columns().items():
        if key != "box":
            np.testing.assert_array_equal(v, b.columns()[key])


def test_certify_and_check_agree_and_report_the_sampled_rows():
    K = ([0.2, 2.0], [0.6, 0.3], [0.0, 0.0])
    P = {"tau": 0.5, "delta": 0.0, "headway": 1.5, "reaction_delay": 0.15, "sample_time": 0.1}
    b = ss.certify_batch(*K, **P)
    c = ss.check(*K, **P)
    assert b.verdict.tolist() == c.verdict.tolist() == ["certified", "not_certified"]
    assert b.sup_gain[0] == 1.0 and b.sup_gain[1] > 1.0 and b.sup_gain_excess[1] > 0.0
    # the witness is a frequency of the hand-built loop where |H| > 1 (q = 1, f = 1/2: check
    # the peak against the whole-step neighbours' bracket of the gain)
    assert 0.0 < b.peak_theta[1] <= np.pi and b.schur.all()


@pytest.mark.parametrize("kw, says", [
    ({"reaction_delay": -0.1}, "reaction_delay"),
    ({"reaction_delay": float("nan")}, "reaction_delay"),
    ({"reaction_delay": 150.0}, "reaction_delay"),
    ({"reaction_delay": 25.0, "sample_time": 0.01}, "at most 2000 whole samples"),
])
def test_bad_theta_with_a_sample_time_is_one_line(kw, says):
    args = {"tau": 0.1, "delta": 0.2, "headway": 1.1, "sample_time": 0.01, **kw}
    with pytest.raises(StringStabError, match=says) as e:
        ss.certify_batch([1.0], [0.5], [0.2], **args)
    assert "\n" not in str(e.value)


@pytest.fixture(scope="module")
def chk():
    spec = importlib.util.spec_from_file_location("sampled_reaction_check", SCRIPT)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["sampled_reaction_check"] = mod
    spec.loader.exec_module(mod)
    return mod


def test_a_tiny_run_of_the_independent_check_finds_no_unsound_verdict(chk):
    rows, by_q = chk.run(30, 11, 0)
    assert rows["cases"] == 30 and rows["unsound"] == 0 and rows["wrong_not_certified"] == 0
    assert rows["certified"] + rows["not_certified"] + rows["inconclusive"] == 30
    assert sum(c[0] for c in by_q.values()) == 30


def test_the_checks_three_truths_agree_with_the_lifted_response(chk):
    # a stable, not string-stable loop with a fractional θ_r: the script's expm transfer, its
    # fine-step simulation and the certificate's lifted response give the same |H| at the peak
    tau, delta, T, H, theta = 0.4, 0.13, 0.8, 0.1, 0.15
    k = np.array([0.5, 0.4, 0.9])
    v = chk.Vehicle(tau, delta, H, theta)
    st, sup, where = chk.truth(v, k, T, 0.5)
    assert st and sup > 1.0
    link = lift_reaction(*(np.array([x]) for x in k), ss.Params(tau, delta, T, reaction_delay=theta), H, 1)
    np.testing.assert_allclose(abs(lifted_response(link, [where])[0, 0, 0, 0]), sup, rtol=1e-9)
    r = chk.simulate(tau, delta, T, H, theta, k, where, sub=50, periods=30)
    np.testing.assert_allclose(r, sup, rtol=2e-2)
