"""The sampled link with a reaction delay θ_r derived in SymPy (issue 25, `derive --sample-time`).

Independent truth: the certificate's model (:mod:`stringstab.certify.lifting_reaction`, closed
forms of the held pieces, built without SymPy) — its frequency response G(e^{jθ}) from the
resolvent and numpy's eigenvalues of its follower block — against the derived H(z) (SymPy's
matrix exponential, adjugates and the modified z-transform) and χ_f(z); both sides of the
delayed sample's case (1 − ε ≤ f or not), f = 0 and f > 0, τ_p ≠ τ.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy as sp

from stringstab.certify.lifting import lifted_response
from stringstab.certify.lifting_reaction import follower_block, held_steps, lift_reaction
from stringstab.cli import main
from stringstab.derive import sampled_reaction as SR
from stringstab.derive.sampled_symbolic import epsilon, m, sample_time, tau_prev, z
from stringstab.derive.symbolic import SUBSTITUTABLE as S
from stringstab.params import Params

#: (τ, τ_p, δ, T*, H, θ_r, K): f = 0; f = 1/2 with 1 − ε ≤ f; f = 1/2 with 1 − ε > f and
#: q = 0; f = 3/5 with ε = 0
CASES = [
    (0.5, 0.5, 0.1, 1.5, 0.1, 0.2, (0.5, 0.4, 0.3)),
    (0.3, 0.4, 0.17, 1.2, 0.1, 0.25, (0.8, 0.6, 0.4)),
    (0.3, 0.4, 0.12, 1.2, 0.1, 0.05, (0.8, 0.6, 0.4)),
    (0.3, 0.2, 0.0, 1.0, 0.05, 0.13, (1.1, 0.6, -0.4)),
]
THETAS = np.array([0.02, 0.3, 1.0, 2.5, 3.1])


def _r(x):
    return sp.Rational(str(x))


def _derived(tau, tp, delta, T, H, th, K):
    q, f = SR.held_split(th, H)
    r = _r(delta) / _r(H)
    mi, er = int(sp.floor(r)), r - sp.floor(r)
    sub = {S["tau"]: _r(tau), tau_prev: _r(tp), S["headway"]: _r(T), sample_time: _r(H),
           S["k_x"]: _r(K[0]), S["k_v"]: _r(K[1]), S["k_a"]: _r(K[2]), epsilon: er, m: mi,
           S["delta"]: _r(delta)}
    return q, f, mi, SR.transfer_at(q, f, sub)


def _model(tau, tp, delta, T, H, th, K):
    p = Params(tau, delta, T, reaction_delay=th)
    return lift_reaction(*(np.array([k]) for k in K), p, H, 1, tp)


@pytest.mark.parametrize("case", CASES)
def test_derived_h_is_the_certificates_link(case):
    _, _, mi, d = _derived(*case)
    Hz = (d["numerator_direct"] + z ** (-(mi + 1)) * d["numerator_delayed"]) / d["denominator"]
    got = sp.lambdify(z, Hz, "numpy")(np.exp(1j * THETAS))
    want = lifted_response(_model(*case), THETAS)[0, :, 0, 0]
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    # H(1) = 1: a constant command propagates (the derivation's own DC gain)
    n1 = complex((d["numerator_direct"] + d["numerator_delayed"]).subs(z, 1).evalf(30))
    d1 = complex(d["denominator"].subs(z, 1).evalf(30))
    assert abs(n1 / d1 - 1) < 1e-20


@pytest.mark.parametrize("case", CASES)
def test_derived_characteristic_polynomial_is_the_follower_block(case):
    q, f, _, d = _derived(*case)
    L = held_steps(case[5], case[4])[2]
    assert (q, 1 if f else 0) == (held_steps(case[5], case[4])[0], L - q)
    c = np.array([complex(v) for v in sp.Poly(d["characteristic"], z).all_coeffs()])
    assert len(c) == 4 + L and abs(c[0] - 1) < 1e-14  # monic, degree 3 + L
    A = follower_block(_model(*case), L).mid[0]
    np.testing.assert_allclose(c, np.poly(np.linalg.eigvals(A)), atol=1e-12)


def test_the_delayed_sample_is_piecewise_without_delta():
    ca, c0, c1 = SR.sample_coefficients(SR.reaction_fraction, epsilon)
    assert isinstance(c0, sp.Piecewise) and isinstance(c1, sp.Piecewise)
    assert sp.simplify(ca - sp.exp(-(1 - epsilon) * sample_time / tau_prev)) == 0  # both cases
    # the two cases meet at (1 − ε) = f: the sample is continuous in δ
    fr = sp.Rational(3, 10)
    first = SR.sample_coefficients(fr, 1 - fr)
    after = [c.subs(SR.reaction_fraction, fr).subs(epsilon, 1 - fr - sp.Rational(1, 10**30))
             for c in (ca, c0, c1)]
    for a, b in zip(first, after):
        assert abs(complex((a - b).subs({sample_time: 0.1, tau_prev: 0.3}).evalf(40))) < 1e-25


def test_held_split_is_the_certificates():
    for th, H in ((0.3, 0.1), (0.25, 0.1), (0.05, 0.1), (0.13, 0.05), (0.7, 0.1), (1.0, 0.01)):
        q, f = SR.held_split(th, H)
        cq, cf, _ = held_steps(th, H)
        assert q == cq and abs(float(f) - cf) < 1e-9, (th, H)


def test_cli_derive_sampled_with_reaction_delay(capsys):
    tau, tp, delta, T, H, th, K = CASES[1]
    sub = f"tau={tau},tau_prev={tp},delta={delta},headway={T},k_x={K[0]},k_v={K[1]},k_a={K[2]}"
    assert main(["derive", "--sample-time", str(H), "--reaction-delay", str(th),
                 "--substitute", sub, "--format", "json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert (doc["q"], doc["f"], doc["L"], doc["m"]) == (2, "1/2", 3, 1)
    Hz = sp.sympify(doc["H"], locals={"z": z})
    got = sp.lambdify(z, Hz, "numpy")(np.exp(1j * THETAS))
    want = lifted_response(_model(*CASES[1]), THETAS)[0, :, 0, 0]
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)


def test_cli_derive_sampled_reaction_delay_zero_is_todays(capsys):
    args = ["derive", "--sample-time", "0.1", "--substitute", "tau=0.1,delta=0.2,headway=1.1",
            "--format", "json"]
    assert main(args) == 0
    a = capsys.readouterr().out
    assert main([*args, "--reaction-delay", "0"]) == 0
    assert capsys.readouterr().out == a


def test_cli_derive_sampled_reaction_delay_refusals(capsys):
    assert main(["derive", "--sample-time", "0.0005", "--reaction-delay", "1.5"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[-1].startswith("stringstab derive: error:") and "at most 2000" in err[-1]
    assert main(["derive", "--sample-time", "0.1", "--substitute", "reaction_delay=-1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "reaction_delay" in err and "-1" in err
