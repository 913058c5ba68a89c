r"""Vectorised numeric frequency response of Γ(jω) with the exact delay.

Direct NumPy evaluation of the derived transfer function (IDL eq 11, derived
form, see :func:`stringstab.derive.symbolic.gamma`)

.. math::
    Γ(jω) = \frac{k_x + k_v jω − k_a ω² e^{−jδω}}
                 {k_x − ω² + j ω (k_v + T^* k_x − τ ω²)}

from the real and imaginary parts of N(jω) and D(jω) generated from the SymPy
derivation (:mod:`stringstab.derive.generated`).  The margin g(ω) = (|D(jω)|² −
|N(jω)|²)/ω², whose sign decides |Γ(jω)| ≤ 1, lives in :mod:`stringstab.certify.margin`;
:func:`margin_g` and :func:`margin_g_coefficients` are kept here as its names in
the frequency-response API.  Every function broadcasts over gains, parameters and ω.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..derive import generated as _gen
from . import margin as _margin

__all__ = ["gain", "gain_squared", "gamma_jw", "margin_g", "margin_g_coefficients", "resonances"]

ArrayLike = npt.ArrayLike
Array = npt.NDArray[np.float64]


def gamma_jw(
    omega: ArrayLike, k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> npt.NDArray[np.complex128]:
    """Γ(jω) with the exact delay e^{−jδω} (IDL eq 11, derived form).

    Parameters
    ----------
    omega : array_like
        Angular frequency ω, rad/s.
    k_x, k_v, k_a : array_like
        Gains of eq 4 (broadcast together).
    tau, delta, headway : array_like
        Actuator lag τ, delay δ and desired headway T*, s.

    Returns
    -------
    ndarray of complex
        Γ(jω) = N(jω)/D(jω), broadcast over the inputs.

    Examples
    --------
    >>> abs(gamma_jw(0.0, 1.0, 0.5, 0.2, tau=0.1, delta=0.2, headway=1.1))
    np.float64(1.0)
    """
    re_n, im_n, re_d, im_d = _parts(omega, k_x, k_v, k_a, tau, delta, headway)
    return np.asarray((re_n + 1j * im_n) / (re_d + 1j * im_d))


def _parts(omega: ArrayLike, k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike, tau: ArrayLike,
           delta: ArrayLike, headway: ArrayLike) -> tuple[Array, Array, Array, Array]:
    w = np.asarray(omega, dtype=float)
    kx, kv, ka = (np.asarray(k, dtype=float) for k in (k_x, k_v, k_a))
    t, d, h = (np.asarray(p, dtype=float) for p in (tau, delta, headway))
    re_n, im_n, re_d, im_d = _gen.gamma_parts(w, kx, kv, ka, t, d, h)
    return re_n, im_n, re_d, im_d


def gain(
    omega: ArrayLike, k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> Array:
    """|Γ(jω)|: the amplitude ratio of follower to predecessor acceleration at ω.

    Parameters
    ----------
    omega : array_like
        Angular frequency ω, rad/s.
    k_x, k_v, k_a : array_like
        Gains of eq 4 (broadcast together).
    tau, delta, headway : array_like
        Actuator lag τ, delay δ and desired headway T*, s.

    Returns
    -------
    ndarray
        |Γ(jω)|, broadcast over the inputs.
    """
    return np.abs(gamma_jw(omega, k_x, k_v, k_a, tau=tau, delta=delta, headway=headway))


def gain_squared(
    omega: ArrayLike, k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> Array:
    """|Γ(jω)|² = |N(jω)|²/|D(jω)|² in real arithmetic, ``inf`` where D(jω) = 0.

    About twice as fast as ``gain(...)**2`` (no complex exponential); used by
    the certificate's peak search.

    Parameters
    ----------
    omega : array_like
        Angular frequency ω, rad/s.
    k_x, k_v, k_a : array_like
        Gains of IDL eq 4 (k_x in 1/s², k_v in 1/s, k_a dimensionless), broadcast together.
    tau, delta, headway : array_like
        Actuator lag τ, delay δ and desired headway T*, s.

    Returns
    -------
    ndarray
        |Γ(jω)|² of the derived Γ (IDL eq 11), broadcast over the inputs.

    Examples
    --------
    >>> round(float(gain_squared(1.0, 0.9, -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1)), 6)
    0.684342
    """
    re_n, im_n, re_d, im_d = _parts(omega, k_x, k_v, k_a, tau, delta, headway)
    num = re_n * re_n + im_n * im_n
    den = re_d * re_d + im_d * im_d
    with np.errstate(divide="ignore", invalid="ignore"):
        out = num / den
    return np.asarray(np.where(den > 0, out, np.inf))


def resonances(p0: ArrayLike, p1: ArrayLike, p2: ArrayLike) -> Array:
    """The frequencies where |D(jω)|² is stationary: where |Γ(jω)| peaks (reporting only).

    |D(jω)|² = p0 x³ + p1 x² + p2 x + p3 with x = ω² (its coefficients from
    :func:`stringstab.derive.generated.denominator_abs2_coefficients`), so its minimisers over
    ω > 0 are the positive roots x of d|D|²/dx = 3 p0 x² + 2 p1 x + p2: at most two, the
    resonance frequencies ω = √x near which |Γ(jω)| = |N|/|D| has its peaks.

    Parameters
    ----------
    p0, p1, p2 : array_like
        The three leading coefficients of |D(jω)|² in x = ω² (broadcast together).

    Returns
    -------
    ndarray, shape (..., 2)
        The two candidate frequencies, rad/s; 0 where a root is complex or not positive.

    Examples
    --------
    >>> resonances(1.0, -3.0, 0.0).tolist()  # d/dx = 3x² − 6x: x = 2 and x = 0
    [1.4142135623730951, 0.0]
    """
    qa, qb, qc = 3.0 * np.asarray(p0, float), 2.0 * np.asarray(p1, float), np.asarray(p2, float)
    disc = qb * qb - 4.0 * qa * qc
    sq = np.sqrt(np.maximum(disc, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.stack([np.where((disc >= 0) & (x > 0), np.sqrt(np.abs(x)), 0.0)
                         for x in ((-qb + sq) / (2.0 * qa), (-qb - sq) / (2.0 * qa))], axis=-1)


def margin_g_coefficients(
    k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> tuple[Array, Array, Array, Array, Array]:
    """Coefficients of g(ω) = (|D(jω)|² − |N(jω)|²)/ω² (:func:`stringstab.certify.margin.coefficients`).

    g(ω) = τ² ω⁴ + a ω² + b + 2 k_x k_a cos(δω) − 2 k_v k_a ω sin(δω), with
    c = k_v + T* k_x, a = 1 − 2τc − k_a², b = c² − 2k_x − k_v².

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains of IDL eq 4 (k_x in 1/s², k_v in 1/s, k_a dimensionless), broadcast together.
    tau, delta, headway : array_like
        Actuator lag τ, delay δ and desired headway T*, s.

    Returns
    -------
    tuple
        (τ², a, b, 2 k_x k_a, 2 k_v k_a).
    """
    return tuple(_margin.coefficients(k_x, k_v, k_a, tau=tau, delta=delta, headway=headway))  # type: ignore[return-value]


def margin_g(
    omega: ArrayLike, k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> Array:
    """g(ω) = (|D(jω)|² − |N(jω)|²)/ω², continuous at ω = 0 where g(0) = Ψ3 (:func:`stringstab.certify.margin.g`).

    |Γ(jω)| ≤ 1 at ω > 0 iff g(ω) ≥ 0.


    Parameters
    ----------
    omega : array_like
        Angular frequency ω, rad/s.
    k_x, k_v, k_a : array_like
        Gains of eq 4 (broadcast together).
    tau, delta, headway : array_like
        Actuator lag τ, delay δ and desired headway T*, s.

    Returns
    -------
    ndarray
        g(ω); ≥ 0 where |Γ(jω)| ≤ 1.

    Examples
    --------
    >>> float(margin_g(0.0, 1.0, 0.5, 0.2, tau=0.1, delta=0.2, headway=1.1))  # = Ψ3
    0.71
    """
    return _margin.g(omega, k_x, k_v, k_a, tau=tau, delta=delta, headway=headway)
