"""The SymPy derivation of the sampled H(z) against independent numerical truth.

Truth: scipy's matrix exponential of the continuous state equations and a direct
z-domain solve (tests/_sampled_truth.py), and numpy.roots for Schur stability.
"""

import functools
import math

import numpy as np
import pytest
import sympy as sp
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.linalg import expm

from stringstab.certify import zoh as S
from stringstab.derive import sampled_symbolic as SS
from stringstab.derive import symbolic as C
from tests._sampled_truth import pair_response

gain = st.floats(-2, 2, allow_nan=False)
lag = st.floats(0.05, 0.6)
period = st.sampled_from([0.02, 0.05, 0.1, 0.2, 0.3])
delay = st.floats(0.0, 0.6)
hw = st.floats(0.3, 2.0)

ALL = [*C.GAINS, C.tau, C.delta, C.headway, SS.sample_time, SS.tau_prev, SS.epsilon]


@functools.cache
def _h_parts():
    tf = SS.sampled_transfer()
    return sp.lambdify([*ALL, SS.z, SS.m],
                       [tf.numerator_direct, tf.numerator_delayed, tf.denominator], "numpy")


@functools.cache
def _w_coefficients():
    c = SS.w_coefficients()
    return sp.lambdify(ALL, [c[k] for k in SS.W_COEFFICIENT_NAMES], "numpy")


def test_discretisation_equals_scipy_expm():
    Phi = SS.sampled_model().Phi
    A = np.array(SS.sampled_model().A.subs({C.tau: 0.3, SS.tau_prev: 0.2, C.headway: 1.4}),
                 dtype=float)
    num = np.array(Phi.subs({C.tau: 0.3, SS.tau_prev: 0.2, C.headway: 1.4,
                             SS.sample_time: 0.1}).evalf(), dtype=float)
    assert_allclose(num, expm(A * 0.1), rtol=1e-12, atol=1e-14)


@given(kx=gain, kv=gain, ka=gain, tau=lag, tp=lag, H=period, d=delay, h=hw)
def test_symbolic_H_equals_direct_construction(kx, kv, ka, tau, tp, H, d, h):
    m, eps = S.split_delay(d, H)
    f = _h_parts()
    th = np.array([1e-3, 0.2, 1.0, 2.5, 3.1])
    z = np.exp(1j * th)
    n0, n1, den = f(kx, kv, ka, tau, d, h, H, tp, eps, z, m)
    ours = (n0 + z ** (-(m + 1)) * n1) / den
    truth = pair_response(th, kx, kv, ka, tau, d, h, H, tau_prev=tp)
    # near a pole on the unit circle (k_x = 0 puts one at z = 1, so den(e^{jθ}) ~ θ² at
    # θ = 1e-3) both sides lose digits as ~1e-15/|den|: the tolerance says so, and stays 1e-8
    # wherever |den| > 1e-6
    rtol = 1e-8 + 1e-14 / np.abs(den)
    assert np.all(np.abs(ours - truth) <= rtol * np.abs(truth) + 1e-10), (ours, truth, den)


@given(kx=gain, kv=gain, ka=gain, tau=lag, tp=lag, H=period, d=delay, h=hw)
def test_numeric_w_coefficients_equal_the_derivation(kx, kv, ka, tau, tp, H, d, h):
    """The closed forms evaluated by stringstab.certify.zoh are the SymPy coefficients."""
    _, eps = S.split_delay(d, H)
    want = _w_coefficients()(kx, kv, ka, tau, d, h, H, tp, eps)
    one = np.ones(1)
    co = S.coefficients(kx * one, kv * one, ka * one, H=H, tau=(tau * one,) * 2,
                        tau_p=(tp * one,) * 2, eps=(eps * one,) * 2,
                        c=((kv + h * kx) * one,) * 2)
    got = [*(v.lo[0] for v in co.delta), 1.0, *(v.lo[0] for v in co.nu),
           *(v.lo[0] for v in co.ell)]
    # atol: the lambdified 1 − e^{−y} cancels for y ~ 1e-16 where ours does not
    for g_, w_ in zip(got, want):
        assert_allclose(g_, w_, rtol=1e-9, atol=1e-15)


def test_delayed_path_carries_z_minus_1_squared_and_dc_gain_is_one():
    tf = SS.sampled_transfer()
    n1 = sp.factor(tf.numerator_delayed)
    assert sp.simplify(n1.subs(SS.z, 1)) == 0
    assert sp.simplify(sp.diff(n1, SS.z).subs(SS.z, 1)) == 0
    assert sp.simplify(tf.expr.subs(SS.z, 1)) == 1
    chi = SS.characteristic_polynomial()
    assert not chi.has(C.delta) and not chi.has(SS.tau_prev)
    # T* enters only through c = k_v + T* k_x, as in continuous time
    c = sp.Symbol("c")
    assert not sp.expand(chi.subs(C.k_v, c - C.headway * C.k_x)).has(C.headway)


def test_phi_functions_are_accurate_for_small_and_large_x():
    x = np.array([1e-8, 1e-4, 0.03, 0.5, 0.999, 1.0, 1.001, 3.0, 40.0])
    got = S.phi(x)
    for k, expr in enumerate(SS.phi_functions(sp.Symbol("x"))):
        for xi, gi in zip(x, got[k]):
            exact = float(sp.N(expr.subs(sp.Symbol("x"), sp.Rational(str(xi))), 40))
            assert_allclose(gi, exact, rtol=1e-14)


@given(coef=st.lists(st.floats(-3, 3, allow_nan=False), min_size=3, max_size=3))
def test_schur_conditions_agree_with_numpy_roots(coef):
    """Bilinear Schur conditions (SymPy) ⇔ all roots of the cubic inside the unit circle."""
    d2, d1, d0 = coef  # Δ(1 + w) = w³ + δ2 w² + δ1 w + δ0
    conds = SS.schur_conditions()
    sym = sp.symbols("delta0 delta1 delta2", real=True)
    vals = [float(cnd.subs(dict(zip(sym, (d0, d1, d2))))) for cnd in conds]
    # z-polynomial: (z − 1)³ + δ2 (z − 1)² + δ1 (z − 1) + δ0
    p = np.polyadd(np.polyadd(np.poly([1, 1, 1]), d2 * np.poly([1, 1])),
                   np.polyadd(d1 * np.poly([1]), [d0]))
    r = np.max(np.abs(np.roots(p)))
    if abs(r - 1) < 1e-9 or min(abs(v) for v in vals) < 1e-9:
        return  # on the boundary: either answer is within round-off
    assert all(v > 0 for v in vals) == (r < 1)


@pytest.mark.parametrize("tau, tp, H", [(0.1, 0.1, 0.1), (0.3, 0.3, 0.2), (0.1, 0.25, 0.1)])
def test_dc_margin_is_the_small_theta_behaviour(tau, tp, H):
    """c₂ θ² ≈ |D|² − |N|² at small θ, with |D|² from the direct construction's poles."""
    f = sp.lambdify(ALL, SS.dc_margin(), "numpy")
    rng = np.random.default_rng(4)
    for kx, kv, ka in rng.uniform(-2, 2, (6, 3)):
        c2 = f(kx, kv, ka, tau, 0.2, 1.1, H, tp, 0.0)
        th = 1e-4
        h = pair_response(np.array([th]), kx, kv, ka, tau, 0.2, 1.1, H, tau_prev=tp)[0]
        # |D(e^{jθ})|² with D = (1 − e^{−H/τ_p}) Δ(e^{jθ}), Δ monic with the closed-loop roots
        from tests._sampled_truth import pair_roots

        roots = pair_roots(kx, kv, tau, 1.1, H)
        D2 = (1 - math.exp(-H / tp)) ** 2 * abs(np.prod(np.exp(1j * th) - roots)) ** 2
        assert_allclose((1 - abs(h) ** 2) * D2 / th**2, c2, rtol=1e-4, atol=1e-9 * abs(D2) / th**2)
