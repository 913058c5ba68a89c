"""The symbolic model against independent numerical truth."""

import control
import numpy as np
import pytest
import sympy as sp
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from stringstab.derive import symbolic as S
from stringstab.derive.printed import printed_psi

gain = st.floats(-2, 2, allow_nan=False)
lag = st.floats(0.05, 1.0)
delay = st.floats(0.0, 0.5)
hw = st.floats(0.3, 2.5)


def _numeric_N_D(w, kx, kv, ka, tau, delta, headway):
    """N(jω), D(jω) written directly from the model's ODEs (not from SymPy)."""
    s = 1j * w
    N = kx + kv * s + ka * s**2 * np.exp(-delta * s)
    D = tau * s**3 + s**2 + (kv + headway * kx) * s + kx
    return N, D


def test_state_space_matches_eq9():
    m = S.vehicle_model()
    assert m.M1 == sp.Matrix([[0, 1, -S.headway], [0, 0, -1], [0, 0, -1 / S.tau]])
    assert m.M2 == sp.Matrix([0, 0, 1 / S.tau])
    assert m.M3 == sp.Matrix([0, 1, 0])


@given(kx=gain, kv=gain, ka=gain, tau=lag, headway=hw)
def test_gamma_matches_python_control_ss2tf(kx, kv, ka, tau, headway):
    """Γ from SymPy equals python-control's ss2tf of the closed loop at δ = 0."""
    A = np.array([[0, 1, -headway], [0, 0, -1], [kx / tau, kv / tau, -1 / tau]])
    B = np.array([[0], [1], [ka / tau]])
    C = np.array([[0, 0, 1]])
    tf = control.ss2tf(control.ss(A, B, C, 0))
    g = S.gamma()
    subs = {S.k_x: kx, S.k_v: kv, S.k_a: ka, S.tau: tau, S.headway: headway, S.delta: 0}
    num = np.array([float(c) for c in sp.Poly(g.numerator.subs(subs), S.s).all_coeffs()])
    den = np.array([float(c) for c in sp.Poly(g.denominator.subs(subs), S.s).all_coeffs()])
    # python-control cancels common factors (e.g. zero gains), so compare responses
    for w in (0.05, 0.7, 3.0, 20.0):
        ours = np.polyval(num, 1j * w) / np.polyval(den, 1j * w)
        theirs = complex(tf(1j * w))
        assert_allclose(ours, theirs, rtol=1e-8, atol=1e-10)


@given(kx=gain, kv=gain, ka=gain, tau=lag, delta=delay, headway=hw, w=st.floats(0.01, 50))
def test_margin_exact_equals_numeric_abs2(kx, kv, ka, tau, delta, headway, w):
    f = sp.lambdify([*S.GAINS, *S.PARAMS, S.omega], S.margin_exact(), "numpy")
    N, D = _numeric_N_D(w, kx, kv, ka, tau, delta, headway)
    expect = abs(D) ** 2 - abs(N) ** 2
    scale = abs(D) ** 2 + abs(N) ** 2
    assert_allclose(f(kx, kv, ka, tau, delta, headway, w), expect, rtol=0, atol=1e-9 * scale + 1e-12)


@pytest.mark.parametrize(
    "params",
    [(1.0, 0.5, 0.2, 0.1, 0.2, 1.1), (0.4, -1.2, 1.5, 0.5, 0.3, 0.8), (-1.5, 2.0, -0.7, 0.2, 0.05, 1.6)],
)
def test_psi_coefficients_match_numeric_polyfit(params):
    """Ψ3, Ψ2, Ψ1 equal a least-squares fit of (|D|²−|N|²)/ω² in ω² on small ω."""
    kx, kv, ka, tau, delta, headway = params
    w = np.linspace(1e-3, 0.25, 400)
    N, D = _numeric_N_D(w, kx, kv, ka, tau, delta, headway)
    y = (np.abs(D) ** 2 - np.abs(N) ** 2) / w**2
    coef = np.polynomial.polynomial.polyfit(w**2, y, 5)  # c0 + c1 x + ...
    psi1, psi2, psi3, _ = S.lambdify_psi("derived")(*params)
    assert_allclose(coef[0], psi3, rtol=1e-7, atol=1e-9)
    assert_allclose(coef[1], psi2, rtol=1e-5, atol=1e-7)
    assert_allclose(coef[2], psi1, rtol=1e-3, atol=1e-5)


def test_printed_psi1_is_delay_order_3_truncation():
    psi1_3 = S.derived_psi(delay_order=3)[0]
    assert sp.expand(psi1_3 - printed_psi()[0]) == 0
    psi1 = S.derived_psi()[0]
    assert sp.expand(psi1 - psi1_3 - S.k_x * S.k_a * S.delta**4 / 12) == 0


def test_higher_delay_orders_converge_to_exact():
    exact = S.derived_psi()
    for order in (4, 5, 8):
        assert all(sp.expand(a - b) == 0 for a, b in zip(S.derived_psi(order), exact))


def test_omega0_coefficient_vanishes_and_odd_powers_absent():
    ser = sp.Poly(S.margin_series(10), S.omega)
    assert ser.coeff_monomial(1) == 0
    assert all(k % 2 == 0 for (k,) in ser.monoms())


def test_gradients_are_derivatives():
    _, psi2, psi3, _ = S.derived_psi()
    grads = S.gradients()
    for k, g2, g3 in zip(S.GAINS, grads["grad_psi2"], grads["grad_psi3"]):
        assert sp.expand(sp.diff(psi2, k) - g2) == 0
        assert sp.expand(sp.diff(psi3, k) - g3) == 0


@given(kx=gain, kv=gain, ka=gain, tau=lag, headway=hw)
def test_hurwitz_conditions_agree_with_numpy_roots(kx, kv, ka, tau, headway):
    conds = sp.lambdify([*S.GAINS, *S.PARAMS], S.hurwitz_conditions(), "numpy")
    vals = conds(kx, kv, ka, tau, 0.2, headway)
    roots = np.roots([tau, 1.0, kv + headway * kx, kx])
    margin = min(abs(v) for v in vals)
    if margin < 1e-9:  # on the boundary: a root on the imaginary axis
        return
    assert all(v > 0 for v in vals) == bool(np.all(roots.real < 0))


@given(coeffs=st.lists(st.floats(-5, 5), min_size=2, max_size=6), lead=st.floats(0.1, 5))
def test_routh_hurwitz_agrees_with_numpy_roots(coeffs, lead):
    x = sp.Symbol("x")
    c = [lead, *coeffs]
    poly = sp.Poly(sum(sp.Float(a) * x ** (len(c) - 1 - i) for i, a in enumerate(c)), x)
    dets = [float(d) for d in S.routh_hurwitz(poly)]
    roots = np.roots(c)
    if min(abs(d) for d in dets) < 1e-6 or np.min(np.abs(roots.real)) < 1e-6:
        return  # too close to the stability boundary for floating point
    assert all(d > 0 for d in dets) == bool(np.all(roots.real < 0))


def test_lambdify_broadcasts():
    f = S.lambdify_psi("printed")
    kx = np.linspace(-2, 2, 5)
    out = f(kx, 0.5, 0.2, 0.1, 0.2, 1.1)
    assert all(o.shape == (5,) for o in out)
    # printed Ψ3 by hand
    assert_allclose(out[2], kx * (kx * 1.1**2 + 2 * 0.5 * 1.1 + 2 * 0.2 - 2), rtol=1e-12)


def test_parse_substitutions_errors():
    from stringstab.errors import StringStabError

    with pytest.raises(StringStabError, match="unknown symbol 'foo'"):
        S.parse_substitutions("foo=1")
    with pytest.raises(StringStabError, match=r"tau .* must be > 0"):
        S.parse_substitutions("tau=-0.1")
    with pytest.raises(StringStabError, match="NAME=VALUE"):
        S.parse_substitutions("tau")
    with pytest.raises(StringStabError, match="finite number"):
        S.parse_substitutions("delta=abc")


@given(kx=gain, kv=gain, ka=gain, tau=lag, delta=delay, headway=hw, w=st.floats(0.01, 50))
def test_numeric_frequency_module_matches_sympy(kx, kv, ka, tau, delta, headway, w):
    """stringstab.certify.frequency (hand-vectorised) equals the SymPy derivation."""
    from stringstab.certify.frequency import gain_squared, gamma_jw, margin_g

    g = S.gamma()
    f = sp.lambdify([*S.GAINS, *S.PARAMS, S.s], g.expr, "numpy")
    assert_allclose(gamma_jw(w, kx, kv, ka, tau=tau, delta=delta, headway=headway),
                    f(kx, kv, ka, tau, delta, headway, 1j * w), rtol=1e-9, atol=1e-12)
    G2 = abs(f(kx, kv, ka, tau, delta, headway, 1j * w)) ** 2
    assert_allclose(gain_squared(w, kx, kv, ka, tau=tau, delta=delta, headway=headway), G2,
                    rtol=1e-9, atol=1e-12)
    F = sp.lambdify([*S.GAINS, *S.PARAMS, S.omega], S.margin_exact() / S.omega**2, "numpy")
    ref = F(kx, kv, ka, tau, delta, headway, w)
    assert_allclose(margin_g(w, kx, kv, ka, tau=tau, delta=delta, headway=headway), ref,
                    rtol=1e-9, atol=1e-9 * (1 + abs(ref)))
