"""Vectorised numeric frequency response of Γ(jω) with the exact delay.

Direct NumPy evaluation of the derived transfer function (IDL eq 11, derived
form, see :func:`stringstab.symbolic.gamma`)

.. math::
    Γ(jω) = \\frac{k_x + k_v jω − k_a ω² e^{−jδω}}
                 {k_x − ω² + j ω (k_v + T^* k_x − τ ω²)}

and of the margin g(ω) = (|D(jω)|² − |N(jω)|²)/ω², whose sign decides
|Γ(jω)| ≤ 1.  Every function broadcasts over gains, parameters and ω.
The test-suite checks these against the SymPy derivation.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

__all__ = ["gain", "gain_squared", "gamma_jw", "margin_g", "margin_g_coefficients"]

ArrayLike = npt.ArrayLike
Array = npt.NDArray[np.float64]


def gamma_jw(
    omega: ArrayLike, k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> npt.NDArray[np.complex128]:
    """Γ(jω) with the exact delay e^{−jδω} (IDL eq 11, derived form).

    Examples
    --------
    >>> abs(gamma_jw(0.0, 1.0, 0.5, 0.2, tau=0.1, delta=0.2, headway=1.1))
    np.float64(1.0)
    """
    jw = 1j * np.asarray(omega, dtype=float)
    kx, kv, ka = (np.asarray(k, dtype=float) for k in (k_x, k_v, k_a))
    t, d, h = (np.asarray(p, dtype=float) for p in (tau, delta, headway))
    num = kx + kv * jw + ka * jw**2 * np.exp(-d * jw)
    den = t * jw**3 + jw**2 + (kv + h * kx) * jw + kx
    return np.asarray(num / den)


def gain(
    omega: ArrayLike, k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> Array:
    """|Γ(jω)|: the amplitude ratio of follower to predecessor acceleration at ω."""
    return np.abs(gamma_jw(omega, k_x, k_v, k_a, tau=tau, delta=delta, headway=headway))


def gain_squared(
    omega: ArrayLike, k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> Array:
    """|Γ(jω)|² = |N(jω)|²/|D(jω)|² in real arithmetic, ``inf`` where D(jω) = 0.

    About twice as fast as ``gain(...)**2`` (no complex exponential); used by
    the certificate's peak search.

    Examples
    --------
    >>> round(float(gain_squared(1.0, 0.9, -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1)), 6)
    0.684342
    """
    w = np.asarray(omega, dtype=float)
    kx, kv, ka = (np.asarray(k, dtype=float) for k in (k_x, k_v, k_a))
    t, d, h = (np.asarray(p, dtype=float) for p in (tau, delta, headway))
    w2 = w * w
    dw = d * w
    re_n = kx - ka * w2 * np.cos(dw)
    im_n = kv * w + ka * w2 * np.sin(dw)
    re_d = kx - w2
    im_d = w * (kv + h * kx - t * w2)
    num = re_n * re_n + im_n * im_n
    den = re_d * re_d + im_d * im_d
    with np.errstate(divide="ignore", invalid="ignore"):
        out = num / den
    return np.asarray(np.where(den > 0, out, np.inf))


def margin_g_coefficients(
    k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> tuple[Array, Array, Array, Array, Array]:
    """Coefficients of g(ω) = (|D(jω)|² − |N(jω)|²)/ω².

    g(ω) = τ² ω⁴ + a ω² + b + 2 k_x k_a cos(δω) − 2 k_v k_a ω sin(δω), with
    c = k_v + T* k_x, a = 1 − 2τc − k_a², b = c² − 2k_x − k_v².

    Returns
    -------
    tuple
        (τ², a, b, 2 k_x k_a, 2 k_v k_a).
    """
    c = np.add(k_v, np.multiply(headway, k_x))
    t2 = np.square(tau)
    a = 1.0 - 2.0 * np.multiply(tau, c) - np.square(k_a)
    b = np.square(c) - 2.0 * np.asarray(k_x) - np.square(k_v)
    return t2, a, b, 2.0 * np.multiply(k_x, k_a), 2.0 * np.multiply(k_v, k_a)


def margin_g(
    omega: ArrayLike, k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> Array:
    """g(ω) = (|D(jω)|² − |N(jω)|²)/ω², continuous at ω = 0 where g(0) = Ψ3.

    |Γ(jω)| ≤ 1 at ω > 0 iff g(ω) ≥ 0.

    Examples
    --------
    >>> float(margin_g(0.0, 1.0, 0.5, 0.2, tau=0.1, delta=0.2, headway=1.1))  # = Ψ3
    0.71
    """
    t2, a, b, cx, cv = margin_g_coefficients(k_x, k_v, k_a, tau=tau, delta=delta, headway=headway)
    w = np.asarray(omega, dtype=float)
    w2 = w * w
    dw = np.multiply(delta, w)
    return np.asarray(t2 * w2 * w2 + a * w2 + b + cx * np.cos(dw) - cv * w * np.sin(dw))
