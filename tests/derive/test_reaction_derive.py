"""The reaction-delay derivation (issue 25): SymPy against the hand formula, θ_r = 0, and the code.

* g_θ derived from the model equals the hand derivation of the brief (symbolically), and
  reduces to today's g at θ_r = 0, as Γ, D and Ψ do;
* every generated θ_r function equals SymPy's evaluation of the derived expression at random
  points (the committed file is checked against a fresh generation by ``test_margin.py``);
* the bounds the certificate rests on hold: M ≥ |g_θ''| and L ≥ |dD(jω)/dω| (SymPy's own
  derivatives on dense grids), g_θ > 0 beyond the tail bound, |Q| < |P| beyond Ω;
* the Taylor route's verdicts differ from the exact root count on the triples docs/theory.md
  names.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from numpy.testing import assert_allclose

from stringstab.certify import margin_reaction as mr
from stringstab.certify.quasipolynomial import count_unstable_roots, tail_frequency
from stringstab.certify.reaction import approximation_verdicts
from stringstab.derive import codegen_reaction as CR
from stringstab.derive import generated as gen
from stringstab.derive import reaction as R
from stringstab.derive import symbolic as S
from stringstab.params import Params

TH = R.reaction_delay
ARGS = [*S.GAINS, *S.PARAMS, TH]
RNG = np.random.default_rng(250)
N = 64
KX, KV, KA = RNG.uniform(-2.5, 2.5, (3, N))
TAU, DELTA, HEADWAY = RNG.uniform(0.05, 1.0, N), RNG.uniform(0.0, 1.0, N), RNG.uniform(0.0, 3.0, N)
THETA, OMEGA = RNG.uniform(0.0, 1.0, N), RNG.uniform(0.0, 10.0, N)
POINT = (KX, KV, KA, TAU, DELTA, HEADWAY, THETA)


def ref(exprs, *extra, point=POINT, omega=OMEGA):
    """SymPy's values of ``exprs`` at the random points (lambdify of the derivation itself)."""
    f = sp.lambdify([*ARGS, *extra], exprs, "numpy")
    vals = f(*point, *([omega] if extra else []))
    return [np.broadcast_to(np.asarray(v, dtype=float), (N,)) for v in vals]


def close(ours, theirs, rtol=1e-10):
    assert len(ours) == len(theirs)
    for o, t in zip(ours, theirs):
        o = np.broadcast_to(np.asarray(o, dtype=float), (N,))
        assert_allclose(o, t, rtol=rtol, atol=rtol * (1.0 + np.max(np.abs(t))))


def test_the_derived_margin_equals_the_hand_derivation():
    assert sp.expand(R.margin_reaction() - R.margin_reaction_hand()) == 0


def test_everything_reduces_to_todays_model_at_zero():
    g = R.gamma_reaction()
    g0 = S.gamma()
    zero = {TH: 0}
    assert sp.simplify(g.numerator.subs(zero) - g0.numerator) == 0
    assert sp.expand(g.denominator.subs(zero) - g0.denominator) == 0
    assert sp.expand(R.margin_reaction().subs(zero) - sp.expand(S.margin_exact() / S.omega**2)) == 0
    for a, b in zip(R.psi_reaction(), S.derived_psi()):
        assert sp.expand(a.subs(zero) - b) == 0


def test_the_denominator_is_a_retarded_quasi_polynomial():
    P, Q = R.denominator_parts()
    assert sp.expand(P - (S.tau * S.s**3 + S.s**2)) == 0
    assert sp.expand(Q - ((S.k_v + S.headway * S.k_x) * S.s + S.k_x)) == 0
    assert sp.degree(P, S.s) > sp.degree(Q, S.s)


def test_generated_margin_coefficients_reassemble_the_derived_margin():
    basis = CR.reaction_margin_basis()
    ours = gen.reaction_margin_coefficients(*POINT)
    close(ours, ref([basis[n] for n, *_ in CR.REACTION_MARGIN_BASIS]))
    # g from the coefficients at ω = the derived g
    gv = mr.g(OMEGA, KX, KV, KA, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA)
    close([gv], ref([R.margin_reaction()], S.omega), rtol=1e-9)


def test_generated_gamma_parts_denominator_and_psi():
    g = R.gamma_reaction()
    parts = [*R.at_jomega(g.numerator), *R.at_jomega(g.denominator)]
    close(gen.reaction_gamma_parts(OMEGA, *POINT), ref(parts, S.omega))
    re, im, scale = gen.reaction_denominator_parts(OMEGA, *POINT)
    close([re, im], ref(list(R.at_jomega(g.denominator)), S.omega))
    assert np.all(scale >= np.abs(re)) and np.all(scale >= np.abs(im))
    close(gen.psi_reaction(*POINT), ref(list(R.psi_reaction()[:3])))
    for kind, fn in (("taylor1", gen.reaction_taylor1_hurwitz), ("pade11", gen.reaction_pade11_hurwitz)):
        close(fn(*POINT), ref(R.approximate_hurwitz(kind)))


def test_psi_with_theta_is_the_low_frequency_series_of_the_margin():
    w = 1e-3
    p1, p2, p3 = gen.psi_reaction(*POINT)
    gv = mr.g(w, KX, KV, KA, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA)
    assert_allclose(gv, p3 + p2 * w**2 + p1 * w**4, rtol=0, atol=1e-9 * (1 + np.abs(p2).max()))


@pytest.mark.parametrize("i", range(12))
def test_the_curvature_bound_bounds_the_second_derivative(i):
    """M(r) ≥ |g_θ''| on [0, r]: SymPy's second derivative on a dense grid (independent)."""
    rng = np.random.default_rng(i)
    pt = (*rng.uniform(-2.5, 2.5, 3), rng.uniform(0.05, 1), rng.uniform(0, 1), rng.uniform(0, 3),
          rng.uniform(0, 2))
    r = rng.uniform(0.5, 30)
    d2 = sp.lambdify([S.omega, *ARGS], sp.diff(R.margin_reaction(), S.omega, 2), "numpy")
    w = np.linspace(0, r, 4001)
    Q = mr.coefficient_table(*(np.array([v]) for v in pt[:3]), *pt[3:])
    M = mr.curvature_bound(np.array([r]), Q)[0]
    assert np.max(np.abs(d2(w, *pt))) <= M


@pytest.mark.parametrize("i", range(12))
def test_the_slope_bound_bounds_the_derivative_of_d(i):
    rng = np.random.default_rng(100 + i)
    kx, kv, tau, headway, theta = (*rng.uniform(-2.5, 2.5, 2), rng.uniform(0.05, 1),
                                   rng.uniform(0, 3), rng.uniform(0, 2))
    r = rng.uniform(0.5, 20)
    w = np.linspace(0, r, 4001)
    c = kv + headway * kx
    # dD(jω)/dω of D = −ω² − jτω³ + e^{−jθω}(k_x + jcω), by hand (independent of the code)
    e = np.exp(-1j * theta * w)
    dD = -2 * w - 3j * tau * w**2 + e * (1j * c) - 1j * theta * e * (kx + 1j * c * w)
    L = gen.reaction_denominator_slope_bound(r, kx, kv, 0.0, tau, 0.0, headway, theta)
    assert np.max(np.abs(dD)) <= L


def test_the_tail_bounds_hold_on_a_long_grid():
    for i in range(20):
        rng = np.random.default_rng(200 + i)
        K = rng.uniform(-2.5, 2.5, 3)
        tau, delta, headway, theta = rng.uniform(0.05, 1), rng.uniform(0, 1), rng.uniform(0, 3), rng.uniform(0, 1)
        Q = mr.coefficient_table(*(np.array([k]) for k in K), tau, delta, headway, theta)
        W = mr.tail_bound(Q)[0]
        w = np.linspace(W, 40 * W + 40, 40_000)
        assert np.all(mr.g(w, *K, tau=tau, delta=delta, headway=headway, reaction_delay=theta) > 0)
        Om = tail_frequency(np.array([K[0]]), np.array([K[1]]), np.array([tau]), np.array([headway]))[0]
        c = K[1] + headway * K[0]
        w = np.linspace(Om, 40 * Om + 40, 40_000)
        assert np.all(w**4 + tau**2 * w**6 > c**2 * w**2 + K[0] ** 2)


#: (k_x, k_v, θ_r) at τ = 0.1 s, T* = 1.1 s: the Taylor route wrong, the exact root count right
#: (found by scanning [−2, 2]² on a 0.01 grid; docs/theory.md §6).
TAYLOR_WRONG = [
    # (k_x, k_v, θ_r, taylor1 says stable, pade11 says stable, roots in Re s > 0)
    (1.56, -1.03, 0.3, True, True, 2),
    (1.22, 1.23, 0.5, False, True, 2),
    (0.72, 1.48, 0.5, False, True, 0),
]


@pytest.mark.parametrize("kx, kv, theta, t1, p11, n_roots", TAYLOR_WRONG)
def test_the_taylor_route_is_wrong_where_docs_say(kx, kv, theta, t1, p11, n_roots):
    p = Params(0.1, 0.2, 1.1, reaction_delay=theta)
    v = approximation_verdicts(np.array([kx]), np.array([kv]), p)
    assert bool(v["taylor1"][0]) is t1 and bool(v["pade11"][0]) is p11
    rc = count_unstable_roots(np.array([kx]), np.array([kv]), 0.1, 1.1, theta)
    assert rc.unstable_roots.tolist() == [n_roots]
    stable = n_roots == 0
    assert t1 != stable or p11 != stable  # at least one of the two routes is wrong
