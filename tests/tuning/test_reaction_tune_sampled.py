"""The reaction delay θ_r on the gain repair of the sampled loop (issue 25): `tune --sample-time`.

Independent truths: the sampled margin with θ_r against 1 − |H(e^{jθ})|² from the resolvent of
the certificate's link (another computation: a linear solve, not determinants) and, as H → 0,
against the continuous margin g_θ(ω) of the issue's model written here in complex arithmetic;
the tuned gains against :func:`stringstab.certify` with ``sample_time`` and ``reaction_delay``
and against numpy's eigenvalues of the closed loop with a fine sweep of |H(e^{jθ})|.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import stringstab as ss
from stringstab.certify.lifting import lifted_response
from stringstab.certify.lifting_reaction import lift_reaction
from stringstab.cli import main
from stringstab.params import Params
from stringstab.tuning import project
from stringstab.tuning.constraints import LoopConstraints, Member, evaluate_forms
from stringstab.tuning.sampled_reaction_margin import (
    sampled_reaction_margin,
    stability_conditions,
)

pytest.importorskip("casadi")

#: τ, δ, T* of the sampled tests; H = 0.1 s, θ_r = 0.2 s (two whole steps) or 0.25 s (2.5)
P = {"tau": 0.5, "delta": 0.1, "headway": 1.5}
H = 0.1
#: not certified at θ_r = 0.2 s with H = 0.1 s (asserted below)
K0 = (0.5, 0.4, 0.0)


def _gain(K, p, th, tp=None):
    """|H(e^{jθ})| from the resolvent of the certificate's link (a linear solve)."""
    link = lift_reaction(*(np.array([k]) for k in K), p, H, 1, tp)
    return np.abs(lifted_response(link, th)[0, :, 0, 0])


@pytest.mark.parametrize("theta_r,tp", [(0.2, None), (0.25, 0.3), (0.05, 0.5)])
def test_the_margin_has_the_sign_of_one_minus_the_gain(theta_r, tp):
    p = Params(**P, reaction_delay=theta_r)
    th = np.linspace(0.01, np.pi, 80)
    rng = np.random.default_rng(3)
    for K in rng.uniform([0, 0, 0], [2, 3, 1], (6, 3)):
        g = sampled_reaction_margin(th, *K[:, None], p, H, tau_prev=tp)[0]
        one = 1.0 - _gain(K, p, th, tp) ** 2
        clear = np.abs(one) > 1e-9
        assert clear.sum() > 70
        assert np.array_equal(np.sign(g[clear]), np.sign(one[clear]))


def test_the_margin_is_a_quadratic_form_in_the_gains():
    loop = LoopConstraints(Params(**P, reaction_delay=0.25), H)
    m = Member(0.5, 0.3, 0.1, 1.5)
    rng = np.random.default_rng(5)
    for th in (0.0, 0.07, 0.6, 2.9):
        form = loop.margin_slot(m, th).form
        for K in rng.uniform(-2, 2, (4, 3)):
            got = float(evaluate_forms(form[None, :], K)[0])
            want = float(loop.margin(m, np.array([th]), K)[0])
            np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-9 * (1 + abs(want)))


def test_the_margin_tends_to_the_continuous_one_as_h_shrinks():
    """g_{H,θ_r}(ωH) → g_θ(ω)/(1 + τ²ω⁴), g_θ of Γ = e^{−θs}N/D (issue 25's model)."""
    K, theta, tau, delta, T = (0.3, 0.8, 0.2), 0.2, 0.3, 0.17, 1.2
    w = np.array([0.3, 1.0, 2.0])
    s = 1j * w
    n = K[0] + K[1] * s + K[2] * s**2 * np.exp(-delta * s)
    d = tau * s**3 + s**2 + np.exp(-theta * s) * ((K[0] * T + K[1]) * s + K[0])
    want = (abs(d) ** 2 - abs(n) ** 2) / w**2 / (1 + tau**2 * w**4)
    p = Params(tau, delta, T, reaction_delay=theta)
    gaps = [np.max(np.abs(sampled_reaction_margin(w * h, *np.array(K)[:, None], p, h)[0] - want))
            for h in (0.02, 0.01, 0.005)]
    # first order in H (the sampled loop's phase lag H/2), and small at H = 5 ms
    assert gaps[2] < 0.6 * gaps[1] and gaps[1] < 0.6 * gaps[0] and gaps[2] < 0.02, gaps


def test_the_stability_conditions_are_necessary():
    """A negative condition means a closed loop with an eigenvalue outside the unit circle."""
    p = Params(**P, reaction_delay=0.2)
    c = stability_conditions([0.3, -0.1], [0.5, 0.5], [0.0, 0.0], p, H)
    np.testing.assert_allclose(c[0], [0.3, -0.1], rtol=1e-7)
    rng = np.random.default_rng(11)
    # the z = −1 condition is weak with θ_r (1 − 1.7·10⁻⁴(k_x + k_v) here): wide gains
    K = np.concatenate([rng.uniform([-1, -5, -1], [3, 6, 1], (150, 3)),
                        rng.uniform(-1e4, 1e4, (150, 3))])
    c = stability_conditions(*K.T, p, H)
    A = lift_reaction(*K.T, p, H, 1).A.mid
    rho = np.abs(np.linalg.eigvals(A)).max(axis=1)  # numpy, on the whole link
    for i in range(2):
        bad = c[i] < -1e-9
        assert bad.sum() >= 5 and np.all(rho[bad] > 1 + 1e-9), i


def test_projection_certifies_the_sampled_loop_with_the_reaction_delay():
    kw = {**P, "sample_time": H}
    assert ss.certify(*K0, **kw, reaction_delay=0.2).verdict == "not_certified"
    r = project(K0, **kw, reaction_delay=0.2)
    assert r.status == "repaired" and r.certified, r.message
    # the NLP on the sampled θ_r forms found it (not the map fallback), near K0
    assert not r.details["fallback"] and 0 < r.distance < 0.3, r
    assert ss.certify(*r.k, **kw, reaction_delay=0.2).verdict == "certified"
    # independent: numpy's eigenvalues of the closed loop, and |H| ≤ 1 on a fine sweep
    p = Params(**P, reaction_delay=0.2)
    link = lift_reaction(*(np.array([k]) for k in r.k), p, H, 1)
    assert np.abs(np.linalg.eigvals(link.A.mid[0])).max() < 1
    assert _gain(r.k, p, np.linspace(1e-4, np.pi, 20_001)).max() <= 1 + 1e-9
    # and not certified in the sampled loop without θ_r? (the repair is not a no-op there)
    assert ss.certify(*r.k, **kw).verdict == "certified"


def test_cli_tune_sampled_with_reaction_delay(capsys):
    args = ["tune", "0.5,0.4,0", "--tau", "0.5", "--delta", "0.1", "--headway", "1.5",
            "--sample-time", "0.1", "--reaction-delay", "0.2", "--format", "json"]
    assert main(args) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["params"]["reaction_delay"] == 0.2 and doc["params"]["sample_time"] == 0.1
    row = doc["results"][0] if "results" in doc else doc["rows"][0]
    K = [row["k_x"], row["k_v"], row["k_a"]]
    assert row["certified"] is True and row["status"] == "repaired"
    assert ss.certify(*K, **P, sample_time=H, reaction_delay=0.2).verdict == "certified"
