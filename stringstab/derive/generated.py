"""Numeric code generated from the symbolic derivation: DO NOT EDIT.

Written by ``python -m stringstab.derive.codegen`` from :mod:`stringstab.derive.symbolic` (and the
printed Ψ of :mod:`stringstab.derive.printed`); ``tests/derive/test_margin.py`` checks that this file
equals a fresh generation and agrees with SymPy.  Only arithmetic, ``abs`` and the
``cos``/``sin`` passed in are used, so every function evaluates NumPy arrays (the
default), Python floats (``cos=math.cos, sin=math.sin``) and CasADi symbols
(``cos=casadi.cos, sin=casadi.sin``) alike.  The public interface is
:mod:`stringstab.certify.margin` and :mod:`stringstab.certify.criteria`.
"""

from __future__ import annotations

from typing import Any

from numpy import cos as _np_cos
from numpy import sin as _np_sin

#: Names of the coefficients returned by :func:`margin_coefficients`.
MARGIN_COEFFICIENTS = ('t2', 'a', 'b', 'cx', 'cv')


def margin_coefficients(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """(t2, a, b, cx, cv) with g(ω) = t2 ω⁴ + a ω² + b + cx cos(δω) − cv ω sin(δω)."""
    _x0 = 2*k_v
    _x1 = 2*k_x
    _x2 = _x1*headway
    return (
        (tau*tau),
        1 - (k_a*k_a) - _x0*tau - _x2*tau,
        -_x1 + _x2*k_v + (k_x*k_x)*(headway*headway),
        _x1*k_a,
        _x0*k_a,
    )


def margin_coefficient_scales(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Σ |term| of each coefficient of :func:`margin_coefficients` (round-off scales)."""
    _x0 = 2*abs(k_x)
    return (
        (tau*tau),
        1 + (k_a*k_a) + 2*tau*abs(k_v) + _x0*headway*tau,
        _x0 + (k_x*k_x)*(headway*headway) + 2*headway*abs(k_v*k_x),
        2*abs(k_a*k_x),
        2*abs(k_a*k_v),
    )


def margin_from_coefficients(omega: Any, t2: Any, a: Any, b: Any, cx: Any, cv: Any, delta: Any, cos: Any = _np_cos, sin: Any = _np_sin) -> Any:
    """g(ω) from the coefficients of :func:`margin_coefficients`."""
    _q0 = (omega*omega)
    _x0 = delta*omega
    return b + _q0*a + cx*cos(_x0) + t2*(_q0*_q0) - cv*omega*sin(_x0)


def margin_and_scale(omega: Any, t2: Any, a: Any, b: Any, cx: Any, cv: Any, s_t2: Any, s_a: Any, s_b: Any, s_cx: Any, s_cv: Any, delta: Any, cos: Any = _np_cos, sin: Any = _np_sin) -> tuple[Any, ...]:
    """(g(ω), Σ |term of g(ω)| bound) from the coefficients and their scales."""
    _x0 = (omega*omega)
    _x1 = delta*omega
    _x2 = _x0*_x0
    return (
        b + _x0*a + _x2*t2 + cx*cos(_x1) - cv*omega*sin(_x1),
        s_b + s_cx + _x0*s_a + _x2*s_t2 + s_cv*omega,
    )


def margin_separable(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """(c, h2, h0, cx, cv) with g(ω) = (τω² − c)² + h2 ω² + h0 + cx cos(δω) − cv ω sin(δω)."""
    _x0 = 2*k_x
    return (
        k_v + k_x*headway,
        1 - (k_a*k_a),
        -_x0 - (k_v*k_v),
        _x0*k_a,
        2*k_a*k_v,
    )


def margin_separable_scales(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Σ |term| of each value of :func:`margin_separable` (round-off scales)."""
    _x0 = abs(k_x)
    return (
        _x0*headway + abs(k_v),
        1 + (k_a*k_a),
        (k_v*k_v) + 2*_x0,
        2*abs(k_a*k_x),
        2*abs(k_a*k_v),
    )


def margin_curvature_bound(r: Any, t2: Any, a: Any, b: Any, cx: Any, cv: Any, delta: Any) -> Any:
    """M ≥ |g''(ω)| for every ω in [0, r], from the coefficients."""
    _x0 = (delta*delta)
    _x1 = abs(cv)
    return 2*abs(a) + _x0*abs(cx) + 2*_x1*delta + 12*t2*(r*r) + _x0*_x1*r


def margin_g(omega: Any, k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, cos: Any = _np_cos, sin: Any = _np_sin) -> Any:
    """g(ω) = (|D(jω)|² − |N(jω)|²)/ω² (IDL eq 10, exact delay)."""
    _q0 = (omega*omega)
    _x0 = 2*k_v
    _x1 = 2*k_x
    _x2 = _x1*headway
    _x3 = delta*omega
    _c0 = (tau*tau)
    _c1 = 1 - (k_a*k_a) - _x0*tau - _x2*tau
    _c2 = -_x1 + _x2*k_v + (k_x*k_x)*(headway*headway)
    _c3 = _x1*k_a
    _c4 = _x0*k_a
    return _c2 + _q0*_c1 + _c0*(_q0*_q0) + _c3*cos(_x3) - _c4*omega*sin(_x3)


def margin_gradient(omega: Any, k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, cos: Any = _np_cos, sin: Any = _np_sin) -> tuple[Any, ...]:
    """(g, ∂g/∂k_x, ∂g/∂k_v, ∂g/∂k_a) at ω."""
    _x0 = 2*tau
    _x1 = 2*k_x
    _x2 = _x1*headway
    _x3 = (headway*headway)
    _x4 = 2*k_a
    _x5 = 2*k_v
    _x6 = (omega*omega)
    _x7 = delta*omega
    _x8 = cos(_x7)
    _x9 = omega*sin(_x7)
    _c0 = (tau*tau)
    _c1 = 1 - (k_a*k_a) - _x0*k_v - _x2*tau
    _c2 = -_x1 + _x2*k_v + _x3*(k_x*k_x)
    _c3 = _x1*k_a
    _c4 = _x4*k_v
    _c5 = -_x0*headway
    _c6 = -2 + _x1*_x3 + _x5*headway
    _c8 = -_x0
    _c10 = -_x4
    return (
        _c2 + _x6*_c1 + _x8*_c3 + _c0*(_x6*_x6) - _x9*_c4,
        _c6 + _x4*_x8 + _x6*_c5,
        _x2 + _x6*_c8 - _x4*_x9,
        _x1*_x8 + _x6*_c10 - _x5*_x9,
    )


def margin_newton(omega: Any, k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, cos: Any = _np_cos, sin: Any = _np_sin) -> tuple[Any, ...]:
    """(g, ∇_K g (3), ∂g/∂ω, ∇_K ∂g/∂ω (3), ∂²g/∂ω², ∇²_KK g (xx, xv, xa, vv, va, aa)) at ω."""
    _x0 = 2*tau
    _x1 = 2*k_x
    _x2 = _x1*headway
    _x3 = (headway*headway)
    _x4 = 2*k_a
    _x5 = 2*k_v
    _x6 = (omega*omega)
    _x7 = delta*omega
    _x8 = cos(_x7)
    _x10 = sin(_x7)
    _x11 = _x10*omega
    _x12 = -_x10 - _x7*_x8
    _x14 = _x10*delta
    _x15 = 2*omega
    _x16 = 2*_x8
    _x17 = (delta*delta)
    _c0 = (tau*tau)
    _c1 = 1 - (k_a*k_a) - _x0*k_v - _x2*tau
    _c2 = -_x1 + _x2*k_v + _x3*(k_x*k_x)
    _c3 = _x1*k_a
    _c4 = _x4*k_v
    _c5 = -_x0*headway
    _c6 = -2 + _x1*_x3 + _x5*headway
    _c8 = -_x0
    _c10 = -_x4
    _c13 = 2*_x3
    _c14 = 2*headway
    _x9 = _x8*_c3
    _x13 = 2*_c1
    return (
        _x9 + _c2 + _x6*_c1 + _c0*(_x6*_x6) - _x11*_c4,
        _c6 + _x4*_x8 + _x6*_c5,
        _x2 + _x6*_c8 - _x11*_x4,
        _x1*_x8 + _x6*_c10 - _x11*_x5,
        _x12*_c4 + _x13*omega - _x14*_c3 + 4*_x6*_c0*omega,
        _x15*_c5 - _x14*_x4,
        _x12*_x4 + _x15*_c8,
        _x12*_x5 + _x15*_c10 - _x1*_x14,
        _x13 + _c4*(_x11*_x17 - _x16*delta) - _x17*_x9 + 12*_x6*_c0,
        _c13,
        _c14,
        _x16,
        0,
        -2*_x11,
        -2*_x6,
    )


def psi_derived(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """(Ψ1, Ψ2, Ψ3), derived forms (IDL eqs 12-14)."""
    _q0 = (delta*delta)
    _x0 = k_a*k_x
    _x1 = 2*k_v
    _x2 = 2*k_x
    _x3 = _x2*headway
    return (
        (tau*tau) + _x0*(_q0*_q0)/12 + _q0*k_a*k_v*delta/3,
        1 - (k_a*k_a) - _q0*_x0 - _x1*tau - _x3*tau - _x1*k_a*delta,
        -_x2 + _x2*k_a + _x3*k_v + (k_x*k_x)*(headway*headway),
    )


def psi_printed(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """(Ψ1, Ψ2, Ψ3), printed forms (IDL eqs 12-14)."""
    _q0 = (delta*delta)
    _x0 = k_a*k_v
    _x1 = 2*k_x
    _x2 = k_v*headway
    return (
        (tau*tau) + _q0*_x0*delta/3,
        1 - (k_a*k_a) - _x1*tau - 2*_x0*delta - 2*_x2*tau + _q0*k_a*k_x,
        -_x1 + _x1*_x2 + _x1*k_a + (k_x*k_x)*(headway*headway),
    )


def _psi_poly_derived_k_x(k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Coefficients (highest power first) of Ψ1, Ψ2, Ψ3, Λ as polynomials in k_x, derived forms, flat."""
    _x0 = (delta*delta*delta*delta)
    _x1 = _x0*k_a
    _x2 = (tau*tau)
    _x3 = (delta*delta*delta)
    _x4 = _x3*k_v
    _x5 = _x4*k_a
    _x6 = (delta*delta)
    _x7 = _x6*k_a
    _x8 = 2*tau
    _x9 = (k_a*k_a)
    _x10 = 2*k_a
    _x11 = k_v*delta
    _x12 = (headway*headway)
    _x13 = k_v*headway
    _x14 = 2*_x1/3
    _x15 = 4*tau
    _x16 = _x15*headway
    _x17 = 8*_x2
    _x18 = _x9*k_a
    _x19 = _x15*k_v
    _x20 = (k_v*k_v)
    _x21 = _x20*k_a
    _x22 = 8*delta*tau
    _x23 = 4*_x20
    _x24 = 4*_x11
    return (
        _x1/12,
        _x2 + _x5/3,
        -_x7 - _x8*headway,
        1 - _x9 - _x10*_x11 - _x8*k_v,
        _x12,
        -2 + _x10 + 2*_x13,
        0,
        -_x1*_x12/3,
        _x14 + _x16*_x7 - _x13*_x14 - 4*_x12*_x5/3 + _x0*_x9/3,
        _x17 - _x16 - 2*_x7 + 8*_x5/3 + _x16*_x9 + _x19*_x7 - _x17*k_a + 2*_x18*_x6 + 4*_x4*_x9/3 + _x13*_x22*k_a - 8*_x21*_x3*headway/3,
        1 - _x19 - 2*_x9 + _x18*_x24 + _x19*_x9 + _x2*_x23 + _x21*_x22 + _x9*_x9 - _x24*k_a + _x23*_x6*_x9,
    )


_PSI_POLY_SIZES_DERIVED_K_X = (2, 2, 3, 4)


def _psi_poly_derived_k_v(k_x: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Coefficients (highest power first) of Ψ1, Ψ2, Ψ3, Λ as polynomials in k_v, derived forms, flat."""
    _x0 = (delta*delta*delta)
    _x1 = _x0*k_a
    _x2 = (tau*tau)
    _x3 = (delta*delta*delta*delta)
    _x4 = k_a*k_x
    _x5 = 2*tau
    _x6 = k_a*delta
    _x7 = (k_a*k_a)
    _x8 = (delta*delta)
    _x9 = _x4*_x8
    _x10 = k_x*headway
    _x11 = 2*k_x
    _x12 = (k_x*k_x)
    _x13 = (headway*headway)
    _x14 = _x12*_x13
    _x15 = _x11*k_a
    _x16 = 8*_x6*tau
    _x17 = 8*_x1/3
    _x18 = 4*tau
    _x19 = _x7*k_a
    _x20 = _x18*_x7
    _x21 = _x12*_x3
    _x22 = 2*_x21*k_a/3
    _x23 = 8*_x2
    return (
        _x1/3,
        _x2 + _x3*_x4/12,
        -_x5 - 2*_x6,
        1 - _x7 - _x9 - _x10*_x5,
        _x11*headway,
        _x14 + _x15 - _x11,
        _x16 + 4*_x2 - _x10*_x17 + 4*_x7*_x8,
        _x20 - _x18 - 4*_x6 + _x10*_x16 + _x17*k_x + _x18*_x9 - _x22*headway + 4*_x19*delta - 4*_x1*_x14/3 + 4*_x0*_x7*k_x/3,
        1 + _x22 - 2*_x7 + _x10*_x20 + _x23*k_x + _x7*_x7 - _x10*_x18 - _x15*_x8 - _x23*_x4 + _x21*_x7/3 + _x11*_x19*_x8 + _x12*_x18*_x8*k_a*headway - _x12*_x13*_x3*k_a*k_x/3,
    )


_PSI_POLY_SIZES_DERIVED_K_V = (2, 2, 2, 3)


def _psi_poly_derived_k_a(k_x: Any, k_v: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Coefficients (highest power first) of Ψ1, Ψ2, Ψ3, Λ as polynomials in k_a, derived forms, flat."""
    _x0 = (delta*delta*delta)
    _x1 = _x0*k_v
    _x2 = (delta*delta*delta*delta)
    _x3 = (tau*tau)
    _x4 = (delta*delta)
    _x5 = _x4*k_x
    _x6 = 2*k_v
    _x7 = 2*k_x
    _x8 = _x7*headway
    _x9 = (k_x*k_x)
    _x10 = (headway*headway)
    _x11 = _x10*_x9
    _x12 = 4*k_v
    _x13 = 2*_x5 + _x12*delta
    _x14 = _x12*tau
    _x15 = (k_v*k_v)
    _x16 = 4*_x15
    _x17 = _x2*_x9
    _x18 = k_x*headway
    _x19 = 4*_x18*tau
    _x20 = 8*_x3*k_x
    return (
        _x1/3 + _x2*k_x/12,
        _x3,
        -1,
        -_x5 - _x6*delta,
        1 - _x6*tau - _x8*tau,
        _x7,
        _x11 - _x7 + _x8*k_v,
        1,
        _x13,
        -2 + _x14 + _x19 + _x17/3 + _x16*_x4 + 4*_x1*k_x/3,
        -_x13 - _x20 - 4*_x1*_x11/3 + 2*_x2*_x9/3 + 8*_x15*delta*tau - 8*_x0*_x15*_x18/3 - 2*_x17*k_v*headway/3 + 8*_x0*k_v*k_x/3 + 4*_x4*_x9*headway*tau + 4*_x4*k_v*k_x*tau - _x10*_x2*_x9*k_x/3 + 8*k_v*k_x*delta*headway*tau,
        1 + _x20 - _x14 - _x19 + _x16*_x3,
    )


_PSI_POLY_SIZES_DERIVED_K_A = (2, 3, 2, 5)


def _psi_poly_printed_k_x(k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Coefficients (highest power first) of Ψ1, Ψ2, Ψ3, Λ as polynomials in k_x, printed forms, flat."""
    _x0 = (tau*tau)
    _x1 = (delta*delta*delta)
    _x2 = _x1*k_v
    _x3 = _x2*k_a
    _x4 = 2*tau
    _x5 = (delta*delta)
    _x6 = _x5*k_a
    _x7 = (k_a*k_a)
    _x8 = 2*k_a
    _x9 = k_v*delta
    _x10 = k_v*headway
    _x11 = (headway*headway)
    _x12 = 4*_x0*_x11
    _x13 = 4*tau
    _x14 = _x13*_x6
    _x15 = _x7*k_a
    _x16 = (k_v*k_v)
    _x17 = _x16*headway
    _x18 = 4*_x9
    return (
        _x0 + _x3/3,
        _x6 - _x4,
        1 - _x7 - _x10*_x4 - _x8*_x9,
        _x11,
        -2 + _x8 + 2*_x10,
        0,
        -_x12 - _x14 + 4*_x0 + _x7*(_x5*_x5) - 4*_x11*_x3/3,
        -_x13 + 8*_x0 - _x10*_x14 - 8*_x0*k_a - 2*_x15*_x5 + 2*_x5*k_a + 4*_x7*tau - 20*_x2*_x7/3 - 8*_x1*_x17*k_a/3 + 8*_x1*k_a*k_v/3 + 8*k_a*k_v*delta*tau,
        1 - 2*_x7 + _x12*_x16 + _x15*_x18 + _x7*_x7 - _x10*_x13 - _x18*k_a + _x10*_x13*_x7 + 4*_x16*_x5*_x7 + 8*_x17*k_a*delta*tau,
    )


_PSI_POLY_SIZES_PRINTED_K_X = (1, 2, 3, 3)


def _psi_poly_printed_k_v(k_x: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Coefficients (highest power first) of Ψ1, Ψ2, Ψ3, Λ as polynomials in k_v, printed forms, flat."""
    _x0 = (delta*delta*delta)
    _x1 = _x0*k_a
    _x2 = (tau*tau)
    _x3 = k_a*delta
    _x4 = headway*tau
    _x5 = (k_a*k_a)
    _x6 = 2*k_x
    _x7 = (delta*delta)
    _x8 = k_a*k_x
    _x9 = _x7*_x8
    _x10 = (k_x*k_x)
    _x11 = (headway*headway)
    _x12 = _x10*_x11
    _x13 = _x6*k_a
    _x14 = 4*_x5
    _x15 = 4*_x2
    _x16 = _x5*k_a
    _x17 = 4*_x4
    _x18 = k_x*tau
    _x19 = 8*_x2
    return (
        _x1/3,
        _x2,
        -2*_x3 - 2*_x4,
        1 + _x9 - _x5 - _x6*tau,
        _x6*headway,
        _x12 + _x13 - _x6,
        _x11*_x15 + _x14*_x7 + 8*_x3*_x4 - 8*_x1*k_x*headway/3,
        -_x17 - 4*_x3 - _x17*_x9 + 4*_x16*delta - 4*_x1*_x12/3 + 4*_x5*headway*tau - 20*_x0*_x5*k_x/3 + 8*_x0*k_a*k_x/3 + 8*k_a*k_x*delta*tau,
        1 - 4*_x18 - 2*_x5 + _x10*_x15 + _x13*_x7 + _x14*_x18 + _x19*k_x + _x5*_x5 - _x12*_x15 - _x19*_x8 + _x10*_x5*(_x7*_x7) - _x16*_x6*_x7 - 4*_x10*_x7*k_a*tau,
    )


_PSI_POLY_SIZES_PRINTED_K_V = (2, 2, 2, 3)


def _psi_poly_printed_k_a(k_x: Any, k_v: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Coefficients (highest power first) of Ψ1, Ψ2, Ψ3, Λ as polynomials in k_a, printed forms, flat."""
    _x0 = (delta*delta*delta)
    _x1 = _x0*k_v
    _x2 = (tau*tau)
    _x3 = (delta*delta)
    _x4 = _x3*k_x
    _x5 = k_v*delta
    _x6 = 2*k_x
    _x7 = k_v*headway
    _x8 = (k_x*k_x)
    _x9 = (headway*headway)
    _x10 = _x8*_x9
    _x11 = 4*_x5
    _x12 = 2*_x4
    _x13 = 4*tau
    _x14 = _x13*k_x
    _x15 = (k_v*k_v)
    _x16 = 4*_x15
    _x17 = _x13*_x7
    _x18 = 8*_x2*k_x
    _x19 = 4*_x2
    return (
        _x1/3,
        _x2,
        -1,
        _x4 - 2*_x5,
        1 - _x6*tau - 2*_x7*tau,
        _x6,
        _x10 - _x6 + _x6*_x7,
        1,
        _x11 - _x12,
        -2 + _x14 + _x17 + _x16*_x3 + _x8*(_x3*_x3) - 20*_x1*k_x/3,
        _x12 - _x11 - _x18 - _x17*_x4 - 4*_x1*_x10/3 - _x13*_x3*_x8 + 8*_x0*k_v*k_x/3 + 8*_x15*delta*headway*tau + 8*k_v*k_x*delta*tau - 8*_x0*_x15*k_x*headway/3,
        1 + _x18 - _x14 - _x17 + _x19*_x8 - _x10*_x19 + _x16*_x2*_x9,
    )


_PSI_POLY_SIZES_PRINTED_K_A = (2, 3, 2, 5)


def psi_polynomials(source: str, gain: str, **values: Any) -> tuple[tuple[Any, ...], ...]:
    """Ψ1, Ψ2, Ψ3 (IDL eqs 12-14) and Λ as polynomials in ``gain``, as coefficient tuples.

    Parameters
    ----------
    source : str
        ``"derived"`` (from the model) or ``"printed"`` (the paper's forms).
    gain : str
        The polynomial variable: ``"k_x"``, ``"k_v"`` or ``"k_a"``.
    **values : Any
        The other two gains and ``tau``, ``delta``, ``headway``, by name (numbers or
        broadcastable arrays).

    Returns
    -------
    tuple of tuple
        Four tuples (Ψ1, Ψ2, Ψ3, Λ), each the coefficients, highest power of
        ``gain`` first, evaluated at ``values``.
    """
    flat = _PSI_POLY[source, gain](**values)
    sizes = _PSI_POLY_SIZES[source, gain]
    out, i = [], 0
    for n in sizes:
        out.append(flat[i:i + n])
        i += n
    return tuple(out)


_PSI_POLY: dict[tuple[str, str], Any] = {("derived", "k_x"): _psi_poly_derived_k_x, ("derived", "k_v"): _psi_poly_derived_k_v, ("derived", "k_a"): _psi_poly_derived_k_a, ("printed", "k_x"): _psi_poly_printed_k_x, ("printed", "k_v"): _psi_poly_printed_k_v, ("printed", "k_a"): _psi_poly_printed_k_a}
_PSI_POLY_SIZES: dict[tuple[str, str], tuple[int, ...]] = {("derived", "k_x"): _PSI_POLY_SIZES_DERIVED_K_X, ("derived", "k_v"): _PSI_POLY_SIZES_DERIVED_K_V, ("derived", "k_a"): _PSI_POLY_SIZES_DERIVED_K_A, ("printed", "k_x"): _PSI_POLY_SIZES_PRINTED_K_X, ("printed", "k_v"): _PSI_POLY_SIZES_PRINTED_K_V, ("printed", "k_a"): _PSI_POLY_SIZES_PRINTED_K_A}


def hurwitz_conditions(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Internal-stability conditions of Γ: each must be > 0 (from symbolic.hurwitz_conditions)."""
    return (
        k_x,
        k_v + k_x*(headway - tau),
    )


def hurwitz_scales(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Σ |coefficient|·|gain| of each Hurwitz condition (the scale of a relative margin)."""
    _x0 = abs(k_x)
    return (
        _x0,
        _x0*abs(headway - tau) + abs(k_v),
    )


def hurwitz_gradients(tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """∇_K of each Hurwitz condition, flat (3 per condition; the conditions are linear in K)."""
    return (
        1,
        0,
        0,
        headway - tau,
        1,
        0,
    )


def gamma_parts(omega: Any, k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, cos: Any = _np_cos, sin: Any = _np_sin) -> tuple[Any, ...]:
    """(Re N(jω), Im N(jω), Re D(jω), Im D(jω)) of Γ = N/D (IDL eq 11, derived)."""
    _x0 = delta*omega
    _x1 = (omega*omega)
    _x2 = _x1*k_a
    _x3 = k_v*omega
    return (
        k_x - _x2*cos(_x0),
        _x3 + _x2*sin(_x0),
        k_x - _x1,
        _x3 + k_x*headway*omega - _x1*omega*tau,
    )


def denominator_coefficients(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Coefficients of D(s), highest power of s first."""
    return (
        tau,
        1,
        k_v + k_x*headway,
        k_x,
    )


#: How many of :func:`numerator_coefficients` belong to the delay-free part n0(s).
NUMERATOR_SPLIT = 2


def numerator_coefficients(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Coefficients of N(s) = n0(s) + n1(s)·e^(−δs), highest power of s first: 2 of n0, then 3 of n1."""
    return (
        k_v,
        k_x,
        k_a,
        0,
        0,
    )


def denominator_abs2_coefficients(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any) -> tuple[Any, ...]:
    """Coefficients of |D(jω)|² as a polynomial in x = ω², highest power first."""
    _x0 = 2*k_x
    _x1 = _x0*headway
    _x2 = (k_x*k_x)
    return (
        (tau*tau),
        1 - _x1*tau - 2*k_v*tau,
        (k_v*k_v) - _x0 + _x1*k_v + _x2*(headway*headway),
        _x2,
    )


#: Names of the coefficients returned by :func:`reaction_margin_coefficients`.
REACTION_MARGIN_COEFFICIENTS = ('t2', 'a', 'b', 'cx', 'cv', 'r0', 'r2', 'r1')


#: (name, trigonometric factor, power of ω) of each coefficient of g_θ.
REACTION_MARGIN_BASIS = (('t2', '1', 4), ('a', '1', 2), ('b', '1', 0), ('cx', 'cos_delta', 0), ('cv', 'sin_delta', 1), ('r0', 'cos_reaction', 0), ('r2', 'cos_reaction', 2), ('r1', 'sin_reaction', 1))


def reaction_margin_coefficients(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, reaction_delay: Any) -> tuple[Any, ...]:
    """(t2, a, b, cx, cv, r0, r2, r1) of g_θ(ω) = t2 ω⁴ + a ω² + b + cx cos δω − cv ω sin δω + r0 cos θ_rω + r2 ω² cos θ_rω + r1 ω sin θ_rω (issue 25)."""
    _x0 = 2*k_x
    _x1 = _x0*headway
    _x2 = 2*k_v
    return (
        (tau*tau),
        1 - (k_a*k_a),
        _x1*k_v + (k_x*k_x)*(headway*headway),
        _x0*k_a,
        _x2*k_a,
        -_x0,
        -_x1*tau - _x2*tau,
        -_x1 - _x2 + 2*k_x*tau,
    )


def reaction_margin_coefficient_scales(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, reaction_delay: Any) -> tuple[Any, ...]:
    """Σ |term| of each coefficient of :func:`reaction_margin_coefficients` (round-off scales)."""
    _x0 = 2*abs(k_x)
    _x1 = 2*abs(k_v)
    _x2 = _x0*headway
    return (
        (tau*tau),
        1 + (k_a*k_a),
        (k_x*k_x)*(headway*headway) + 2*headway*abs(k_v*k_x),
        2*abs(k_a*k_x),
        2*abs(k_a*k_v),
        _x0,
        _x1*tau + _x2*tau,
        _x1 + _x2 + _x0*tau,
    )


def reaction_margin_and_scale(omega: Any, t2: Any, a: Any, b: Any, cx: Any, cv: Any, r0: Any, r2: Any, r1: Any, s_t2: Any, s_a: Any, s_b: Any, s_cx: Any, s_cv: Any, s_r0: Any, s_r2: Any, s_r1: Any, delta: Any, reaction_delay: Any, cos: Any = _np_cos, sin: Any = _np_sin) -> tuple[Any, ...]:
    """(g_θ(ω), Σ |term of g_θ(ω)|·(1 + its angle)) from the coefficients and their scales."""
    _x0 = (omega*omega)
    _x1 = delta*omega
    _x2 = reaction_delay*omega
    _x3 = cos(_x2)
    _x4 = _x0*_x0
    _x5 = 1 + _x1
    _x6 = 1 + _x2
    return (
        b + _x0*a + _x3*r0 + _x4*t2 + cx*cos(_x1) + _x0*_x3*r2 + r1*omega*sin(_x2) - cv*omega*sin(_x1),
        s_b + _x0*s_a + _x4*s_t2 + _x5*s_cx + _x6*s_r0 + _x0*_x6*s_r2 + _x5*s_cv*omega + _x6*s_r1*omega,
    )


def reaction_margin_curvature_bound(r: Any, t2: Any, a: Any, b: Any, cx: Any, cv: Any, r0: Any, r2: Any, r1: Any, delta: Any, reaction_delay: Any) -> Any:
    """M ≥ |g_θ''(ω)| for every ω in [0, r], from the coefficients."""
    _x0 = abs(r2)
    _x1 = (reaction_delay*reaction_delay)
    _x2 = (delta*delta)
    _x3 = abs(r1)
    _x4 = abs(cv)
    _x5 = (r*r)
    return 2*_x0 + 2*abs(a) + _x1*abs(r0) + _x2*abs(cx) + 2*_x3*reaction_delay + 2*_x4*delta + 12*_x5*t2 + _x0*_x1*_x5 + _x1*_x3*r + _x2*_x4*r + 4*_x0*r*reaction_delay


def reaction_gamma_parts(omega: Any, k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, reaction_delay: Any, cos: Any = _np_cos, sin: Any = _np_sin) -> tuple[Any, ...]:
    """(Re N(jω), Im N(jω), Re D(jω), Im D(jω)) of Γ = N/D with the reaction delay."""
    _x0 = reaction_delay*omega
    _x1 = sin(_x0)
    _x2 = delta*omega
    _x3 = (omega*omega)
    _x4 = _x3*k_a
    _x5 = _x4*sin(_x2)
    _x6 = cos(_x0)
    _x7 = _x4*cos(_x2)
    _x8 = _x6*k_x
    _x9 = k_v*omega
    _x10 = _x8 + _x1*_x9
    _x11 = _x1*k_x
    _x12 = -_x11 + _x6*_x9
    _x13 = headway*omega
    return (
        _x10 + _x1*_x5 - _x6*_x7,
        _x12 + _x1*_x7 + _x5*_x6,
        _x10 - _x3 + _x11*_x13,
        _x12 + _x13*_x8 - _x3*omega*tau,
    )


def reaction_denominator_parts(omega: Any, k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, reaction_delay: Any, cos: Any = _np_cos, sin: Any = _np_sin) -> tuple[Any, ...]:
    """(Re D(jω), Im D(jω), S(ω)) of D = P + e^{−θ_r s}Q; S = Σ|p_k|ω^k + (1 + θ_rω)Σ|q_k|ω^k bounds the terms (and the angle's round-off)."""
    _x0 = (omega*omega)
    _x1 = reaction_delay*omega
    _x2 = cos(_x1)
    _x3 = _x2*k_x
    _x4 = sin(_x1)
    _x5 = k_v*omega
    _x6 = _x4*k_x
    _x7 = headway*omega
    _x8 = _x0*omega*tau
    _x9 = abs(k_x)
    return (
        _x3 - _x0 + _x4*_x5 + _x6*_x7,
        -_x6 - _x8 + _x2*_x5 + _x3*_x7,
        _x0 + _x8 + (1 + _x1)*(_x9 + omega*(_x9*headway + abs(k_v))),
    )


def reaction_denominator_slope_bound(r: Any, k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, reaction_delay: Any) -> Any:
    """L ≥ |d D(jω)/dω| for every ω in [0, r]: Σ k|p_k| r^{k−1} + Σ k|q_k| r^{k−1} + θ_r Σ |q_k| r^k."""
    _x0 = abs(k_x)
    _x1 = _x0*reaction_delay
    _x2 = abs(k_v)
    return _x1 + _x2 + 2*r + _x0*headway + 3*tau*(r*r) + _x1*r*headway + _x2*r*reaction_delay


#: How many of :func:`reaction_denominator_coefficients` belong to P(s).
REACTION_DENOMINATOR_SPLIT = 4


def reaction_denominator_coefficients(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, reaction_delay: Any) -> tuple[Any, ...]:
    """Coefficients of D = P + e^(−θ_r s)Q, highest power first: 4 of P, then 2 of Q."""
    return (
        tau,
        1,
        0,
        0,
        k_v + k_x*headway,
        k_x,
    )


def psi_reaction(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, reaction_delay: Any) -> tuple[Any, ...]:
    """(Ψ1, Ψ2, Ψ3) with the reaction delay: the ω⁴, ω², ω⁰ coefficients of g_θ (eqs 12-14)."""
    _q0 = (delta*delta)
    _x0 = k_x/12
    _x1 = (reaction_delay*reaction_delay*reaction_delay)/3
    _x2 = (reaction_delay*reaction_delay)
    _x3 = k_v*tau
    _x4 = _x1*k_x
    _x5 = headway*tau
    _x6 = 2*k_v
    _x7 = 2*k_x
    return (
        (tau*tau) + _x1*k_v + _x2*_x3 + _x4*headway - _x0*(_x2*_x2) - _x4*tau + _x0*k_a*(_q0*_q0) + _x2*_x5*k_x + _q0*k_a*k_v*delta/3,
        1 - (k_a*k_a) - 2*_x3 + _x2*k_x - _x5*_x7 - _x6*reaction_delay - _q0*k_a*k_x - _x6*k_a*delta - _x7*reaction_delay*headway + 2*k_x*reaction_delay*tau,
        -_x7 + _x7*k_a + (k_x*k_x)*(headway*headway) + _x7*k_v*headway,
    )


def reaction_taylor1_hurwitz(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, reaction_delay: Any) -> tuple[Any, ...]:
    """Hurwitz determinants of D with e^(−θ_r s) replaced by taylor1 (each > 0): the Taylor route's stability test, not a certificate."""
    _x0 = k_v*reaction_delay
    _x1 = k_x*headway
    _x2 = (k_x*k_x)
    _x3 = (reaction_delay*reaction_delay)
    _x4 = -k_v + k_x*reaction_delay + k_x*tau + reaction_delay*(k_v*k_v) - k_x*headway + 2*_x0*_x1 + _x2*reaction_delay*(headway*headway) - _x2*_x3*headway - _x3*k_v*k_x
    return (
        1 - _x0 - _x1*reaction_delay,
        -_x4,
        -_x4*k_x,
    )


def reaction_pade11_hurwitz(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any, reaction_delay: Any) -> tuple[Any, ...]:
    """Hurwitz determinants of D with e^(−θ_r s) replaced by pade11 (each > 0): the Taylor route's stability test, not a certificate."""
    _x0 = 4*tau
    _x1 = (reaction_delay*reaction_delay)
    _x2 = _x1*k_v
    _x3 = _x1*k_x
    _x4 = k_v*reaction_delay
    _x5 = k_x*headway
    _x6 = _x5*reaction_delay
    _x7 = 8*tau
    _x8 = (k_v*k_v)
    _x9 = 2*_x1
    _x10 = (k_x*k_x)
    _x11 = _x1*reaction_delay
    _x12 = _x10*_x11
    _x13 = _x10*(headway*headway)
    _x14 = _x7*reaction_delay
    _x15 = k_x*tau
    _x16 = -4*_x4 - 4*_x6 + 4*_x3 + _x12*tau + _x13*_x14 + _x13*_x9 + _x14*_x8 + _x8*_x9 - _x12*headway - _x5*_x7 - _x7*k_v - 6*_x15*_x2 + 4*_x2*_x5 + 8*k_x*(tau*tau) + 12*_x15*reaction_delay - _x11*k_v*k_x + 16*_x4*_x5*tau - 6*_x1*_x10*headway*tau
    return (
        tau + reaction_delay/2,
        reaction_delay/2 - _x2/4 + _x0/4 - _x0*_x4/4 - _x0*_x6/4 - _x3*headway/4 + _x3*tau/4,
        -_x16/8,
        -_x16*k_x/8,
    )
