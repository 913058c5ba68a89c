r"""The sampled loop on the unit circle: H(e^{jθ}) and the margin g_H(θ), with its bounds.

On z = e^{jθ}, with ρ = |w|² = 4 sin²(θ/2) and w² = −ρz (w = z − 1), |H(e^{jθ})| ≤ 1 iff

.. math::
    g_H(θ) = \frac{τ^2 τ_p^2}{H^6}\,
             \frac{φ_{1p}^2|Δ|^2 - φ_1^2|n + z^{-(m+1)}k_a w^2\ell|^2}{ρ}
           = P(ρ) + \cos(mθ)\,Y_r(ρ) + \sin(mθ)\sin θ\,Y_i(ρ) \;\ge 0,

with the coefficients of :mod:`stringstab.certify.zoh`.  The normalisation makes
g_H(ωH) → g(ω) of :func:`stringstab.certify.frequency.margin_g` as H → 0.  This module
evaluates, from the coefficients:

* H(e^{jθ}) (:func:`response`; :func:`sampled_response` from the gains and parameters);
* g_H(θ), or a lower bound of it over a cell of parameters, with the round-off slack
  (:func:`margin_bound`; :func:`sampled_margin` from the gains and parameters);
* over cells with derivative enclosures, the better of the interval extension and the
  mean-value form (:func:`margin_over_cells`, :func:`margin_spread`);
* M ≥ |g_H''| on a frequency interval (:func:`margin_curvature`), from bounds on P, Y_r,
  Y_i and their ρ-derivatives at ρ(r), |sin θ| on [l, r] and the factors m, m² of the
  oscillating terms — what the branch and bound of
  :mod:`stringstab.certify.branch_bound` needs: g_H ≥ min(g_H(l), g_H(r)) − M h²/8 on
  [l, r] of width h.

References
----------
:mod:`stringstab.certify.zoh` (the coefficients); docs/sampled.md (the curvature bound).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from ..params import as_gains
from .interval import Interval
from .sampled_curvature import point_stack
from .verdicts import ROUNDOFF_SLACK
from .zoh import Coefficients, loop_parameters, point_coefficients

__all__ = [
    "circle_terms",
    "margin_bound",
    "margin_over_cells",
    "margin_spread",
    "point_margin",
    "response",
    "sampled_margin",
    "sampled_response",
]

Array = npt.NDArray[np.float64]


def _polyval(coefs: list[Array], rho: Array) -> Array:
    """Σ_j coefs[j] ρ^j by Horner's rule (broadcast), from 0: (0·ρ + c_d)ρ + ...

    The zero is a number: 0.0·ρ is the product of an array of zeros of the broadcast shape
    with ρ, element by element, and the first coefficient's sum gives the broadcast shape.
    """
    out: Any = np.float64(0.0)
    for c in reversed(coefs):
        out = out * rho + c
    return np.asarray(out)


def response(theta: Array, co: Coefficients, m: int, ka: Array) -> npt.NDArray[np.complex128]:
    """H(e^{jθ}) from point coefficients (module docstring of :mod:`~stringstab.certify.zoh`).

    Parameters
    ----------
    theta : ndarray
        θ, rad/sample, broadcast against the coefficients' rows.
    co : Coefficients
        Point coefficients.
    m : int
        Whole samples of delay.
    ka : ndarray
        k_a, broadcast as the coefficients.

    Returns
    -------
    ndarray of complex
        H(e^{jθ}); ``nan`` where Δ(e^{jθ}) = 0.
    """
    s2 = np.sin(0.5 * theta)
    w = 2j * s2 * np.exp(0.5j * theta)  # e^{jθ} − 1 without cancellation
    d0, d1, d2 = (x.lo for x in co.delta)
    n0, n1, n2 = (x.lo for x in co.nu)
    l0, l1 = (x.lo for x in co.ell)
    D = ((w + d2) * w + d1) * w + d0
    N = (n2 * w + n1) * w + n0 + np.exp(-1j * (m + 1) * theta) * ka * w * w * (l0 + l1 * w)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray(co.phi1.lo / co.phi1p.lo * N / D)


def _on_circle(theta: Any, k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any,
               sample_time: Any, tau_prev: Any) -> tuple[Array, Array, Coefficients, int,
                                                         tuple[int, ...]]:
    """Validated, broadcast and flattened θ and k_a, the coefficients, m and the shape."""
    p, H, tp = loop_parameters(tau, delta, headway, sample_time, tau_prev)
    th = np.asarray(theta, dtype=float)
    kx, kv, ka = as_gains(k_x, k_v, k_a)
    shape = np.broadcast_shapes(th.shape, kx.shape)
    kx, kv, ka, th = (np.broadcast_to(v, shape).ravel() for v in (kx, kv, ka, th))
    co, m = point_coefficients(kx, kv, ka, p, H, tp)
    return th, ka, co, m, shape


def sampled_response(
    theta: npt.ArrayLike, k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: float, delta: float, headway: float, sample_time: float,
    tau_prev: float | None = None,
) -> npt.NDArray[np.complex128]:
    """H(e^{jθ}): the sampled string transfer function on the unit circle.

    Parameters
    ----------
    theta : array_like
        Normalised frequency θ = ωH in rad per sample, broadcast against the gains.
    k_x, k_v, k_a : array_like
        Gains (broadcast together).
    tau, delta, headway : float
        Actuator lag τ > 0, delay δ ≥ 0 (any real: exact between samples), headway T* ≥ 0.
    sample_time : float
        Sampling period H > 0 of every vehicle (zero-order hold), s.
    tau_prev : float, optional
        The predecessor's actuator lag (default τ: a homogeneous platoon).

    Returns
    -------
    ndarray of complex
        ``nan`` where Δ(e^{jθ}) = 0.

    Examples
    --------
    >>> h = sampled_response([0.0, 0.3], 1.2, 0.5, 0.6, tau=0.1, delta=0.2, headway=1.1,
    ...                      sample_time=0.1)
    >>> np.round(np.abs(h), 6).tolist()
    [1.0, 0.760411]
    """
    th, ka, co, m, shape = _on_circle(theta, k_x, k_v, k_a, tau, delta, headway, sample_time,
                                      tau_prev)
    # H(1) = 1 whenever Δ(1) ≠ 0 (k_x ≠ 0); at k_x = 0 the w-form gives 0/0 = nan at θ = 0
    return response(th, co, m, ka).reshape(shape)


def circle_terms(theta: Array, m: Array | float) -> tuple[Array, Array, Array, Array]:
    """ρ = 4 sin²(θ/2), |sin θ|, cos(mθ) and sin(mθ) sin θ at θ: what :func:`margin_bound` needs.

    Parameters
    ----------
    theta : ndarray
        θ, rad/sample (shape (n, k) with m of shape (n,), or any shape with a number m).
    m : float or ndarray, shape (n,)
        Whole samples of delay.

    Returns
    -------
    (ndarray, ndarray, ndarray, ndarray)
        ρ, |sin θ|, cos(mθ), sin(mθ) sin θ.
    """
    rho = 4.0 * np.sin(0.5 * theta) ** 2
    st = np.sin(theta)
    mm = np.asarray(m, dtype=float)
    mcol = mm[:, None] if mm.ndim else mm
    return rho, np.abs(st), np.cos(mcol * theta), np.sin(mcol * theta) * st


def margin_bound(theta: Array, co: Coefficients, m: Array | int,
                 circle: tuple[Array, Array, Array, Array] | None = None) -> tuple[Array, Array]:
    """(lower bound of g_H over the coefficient cell, round-off slack) at θ.

    For point coefficients the lower bound is g_H itself.  The slack is
    :data:`~stringstab.certify.verdicts.ROUNDOFF_SLACK` (1 + m) times the magnitude of the
    terms (the same sum on the magnitude companions).

    Parameters
    ----------
    theta : ndarray
        θ, rad/sample: shape (n, k) with coefficients of n rows (broadcast as columns), or
        any shape with coefficients that broadcast against it.
    co : Coefficients
        Of :class:`~stringstab.certify.interval.Interval` entries.
    m : int or ndarray, shape (n,)
        Whole samples of delay.
    circle : tuple of ndarray, optional
        :func:`circle_terms` of θ and m, computed before (e.g. once for the branch and
        bound's initial grid, broadcast over the rows); default: computed here.

    Returns
    -------
    (ndarray, ndarray)
        The lower bound of g_H and the slack, of the shape of ``theta``.
    """
    rho, ast, cm, f = circle_terms(theta, m) if circle is None else circle
    mm = np.asarray(m, dtype=float)
    mcol = mm[:, None] if mm.ndim else mm
    S = point_stack(co) if np.ndim(theta) == 2 else None
    if S is not None:
        return point_margin(S, (rho, ast, cm, f), mcol)

    def col(x: Array) -> Array:
        return x[:, None] if np.ndim(x) and np.ndim(theta) == 2 else x

    P_lo = _polyval([col(c.lo) for c in co.P], rho)
    Yr_lo = _polyval([col(c.lo) for c in co.Yr], rho)
    Yi_lo = _polyval([col(c.lo) for c in co.Yi], rho)
    P_mag = _polyval([col(c.mag) for c in co.P], rho)
    Yr_mag = _polyval([col(c.mag) for c in co.Yr], rho)
    Yi_mag = _polyval([col(c.mag) for c in co.Yi], rho)
    mag = P_mag + (1.0 + mcol) * (Yr_mag + ast * Yi_mag)
    slack = ROUNDOFF_SLACK * (1.0 + mcol) * mag
    if all(c.point for c in (*co.P, *co.Yr, *co.Yi)):
        return P_lo + cm * Yr_lo + f * Yi_lo, slack
    Yr_hi = _polyval([col(c.hi) for c in co.Yr], rho)
    Yi_hi = _polyval([col(c.hi) for c in co.Yi], rho)
    low = (P_lo + np.where(cm >= 0, cm * Yr_lo, cm * Yr_hi)
           + np.where(f >= 0, f * Yi_lo, f * Yi_hi))
    return np.asarray(low), slack


def point_margin(S: Array, circle: tuple[Array, Array, Array, Array],
                 mcol: Array) -> tuple[Array, Array]:
    """g_H and its round-off slack from stacked point coefficients (:func:`margin_bound`'s point path).

    One Horner pass over the stack: every polynomial's values and magnitude companions, the
    same operations as polynomial by polynomial (a zero at the top adds +0 first: 0·ρ + 0 =
    +0, then +0·ρ + c is the same number as the first step 0·ρ + c of the shorter one).

    Parameters
    ----------
    S : ndarray, shape (3, k, 2, n)
        :func:`point_stack`.
    circle : tuple of ndarray
        :func:`circle_terms` at θ (shape (n, j), or (1, j) broadcast over the rows).
    mcol : ndarray, shape (n, 1)
        Whole samples of delay, as a column.

    Returns
    -------
    (ndarray, ndarray)
        g_H and the slack :data:`~stringstab.certify.verdicts.ROUNDOFF_SLACK` (1 + m) × the
        magnitude, shape (n, j).
    """
    rho, ast, cm, f = circle
    V = _polyval([S[:, j, :, :, None] for j in range(S.shape[1])], rho)
    (P_lo, P_mag), (Yr_lo, Yr_mag), (Yi_lo, Yi_mag) = V
    mag = P_mag + (1.0 + mcol) * (Yr_mag + ast * Yi_mag)
    slack = ROUNDOFF_SLACK * (1.0 + mcol) * mag
    return P_lo + cm * Yr_lo + f * Yi_lo, slack


def sampled_margin(
    theta: npt.ArrayLike, k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: float, delta: float, headway: float, sample_time: float,
    tau_prev: float | None = None,
) -> Array:
    """g_H(θ) = τ²τ_p²(|D|² − |N|²)/(H⁶ ρ): ≥ 0 iff |H(e^{jθ})| ≤ 1 (module docstring).

    Tends to the continuous margin g(ω) of :func:`stringstab.certify.frequency.margin_g` at
    θ = ωH as H → 0; at θ = 0 it is the sampled analogue of Ψ3
    (:func:`stringstab.derive.sampled_symbolic.dc_margin`).

    Parameters
    ----------
    theta, k_x, k_v, k_a, tau, delta, headway, sample_time, tau_prev
        As for :func:`sampled_response`.

    Returns
    -------
    ndarray
        g_H at each θ (broadcast shape).

    Examples
    --------
    >>> from stringstab.certify.frequency import margin_g
    >>> kw = dict(tau=0.1, delta=0.2, headway=1.1)
    >>> gc = margin_g(1.5, 1.2, 0.5, 0.6, **kw)
    >>> [round(float(sampled_margin(H * 1.5, 1.2, 0.5, 0.6, sample_time=H, **kw) - gc), 3)
    ...  for H in (0.1, 0.01, 0.001)]  # the gap shrinks like H
    [-2.117, -0.471, -0.052]
    """
    th, _, co, m, shape = _on_circle(theta, k_x, k_v, k_a, tau, delta, headway, sample_time,
                                     tau_prev)
    return np.asarray(margin_bound(th, co, m)[0]).reshape(shape)


# ---------------------------------------------------------------------------
# Bounds over cells of parameters: the mean-value form
# ---------------------------------------------------------------------------
def margin_over_cells(theta: Array, co: Coefficients, m: Array,
                      hw: Array) -> tuple[Array, Array, Array]:
    """(g_H at the cells' centres, a lower bound over the cells, slack) at θ (n, k).

    The lower bound is the larger of the natural interval extension and the mean-value
    form g(centre) − Σ_i max|∂g/∂p_i| · halfwidth_i.

    Parameters
    ----------
    theta : ndarray, shape (n, k)
        Frequencies, rad/sample, one row per cell.
    co : Coefficients
        Derivative enclosures over the cells (:func:`~stringstab.certify.zoh.cell_coefficients`).
    m : ndarray, shape (n,)
        Whole samples of delay of each cell.
    hw : ndarray, shape (n, d)
        Half-widths of the cells, per parameter.

    Returns
    -------
    (ndarray, ndarray, ndarray)
        g_H at the centres, the lower bound over the cells and the round-off slack.
    """
    G, E = margin_bound(theta, co.map(lambda v: v.c), m)
    low_r, E_r = margin_bound(theta, co.map(lambda v: v.r), m)
    spread = margin_spread(theta, co, m, hw).sum(axis=-1)
    return G, np.maximum(low_r, G - spread), np.maximum(E, E_r)


def _grad_getter(i: int) -> Callable[[Any], Interval]:
    """The enclosure of ∂/∂p_i of an entry."""

    def get(v: Any) -> Interval:
        return v.g[i]  # type: ignore[no-any-return]

    return get


def margin_spread(theta: Array, co: Coefficients, m: Array, hw: Array) -> Array:
    """max|∂g_H/∂p_i| × halfwidth_i at θ, per parameter i.

    Parameters
    ----------
    theta : ndarray, shape (n, k)
        Frequencies, rad/sample, one row per cell.
    co : Coefficients
        Derivative enclosures over the cells.
    m : ndarray, shape (n,)
        Whole samples of delay of each cell.
    hw : ndarray, shape (n, d)
        Half-widths of the cells, per parameter.

    Returns
    -------
    ndarray, shape θ.shape + (d,)
        The spread of g_H over each cell along each parameter (0 for a parameter of no
        width in every cell).
    """
    out = np.zeros((*np.shape(theta), hw.shape[1]))
    for i in range(hw.shape[1]):
        if not np.any(hw[:, i] > 0):
            continue
        gi = co.map(_grad_getter(i))
        lo, Ei = margin_bound(theta, gi, m)
        nlo, _ = margin_bound(theta, gi.map(lambda v: -v), m)
        out[..., i] = (np.maximum(-lo, -nlo) + Ei) * hw[:, i][:, None]
    return out
