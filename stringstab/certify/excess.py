"""sup|Γ| − 1 of the continuous loop without cancellation, and where it is attained.

A not-certified row must report a number that agrees with its verdict (issue 21, item 5):
|Γ(jω)|² − 1 computed directly rounds to 0 when the violation is below double precision
(Ψ3 just below 0, where |Γ|² = 1 − (Ψ3/k_x²) ω² + O(ω⁴) exceeds 1 only near ω = 0, by as
little as 10⁻²⁰).  Written as −ω² g(ω)/|D(jω)|² with the margin g evaluated from its
coefficients (:mod:`stringstab.certify.margin`), it keeps its sign and digits.  Used by
:mod:`stringstab.certify.continuous` and, at the witness member, :mod:`stringstab.certify.robust`;
reporting only — no verdict depends on it.

References
----------
IDL paper, eqs 10-14 (Γ, Ψ3); :mod:`stringstab.certify.margin` (g).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ..derive import generated as _gen
from . import margin as _margin

__all__ = ["EXCESS_SEARCH", "excess_squared", "searched_excess", "violation_peak"]

#: Not-certified rows whose directly computed sup gain − 1 is below this get the
#: cancellation-free search (:func:`violation_peak` and its sampled twin); above it the
#: direct value keeps at least 12 correct digits, so the search would only cost time.
EXCESS_SEARCH = 1e-4

Array = npt.NDArray[np.float64]


def col(v: Array) -> Array:
    """A 1-D array as a column, to broadcast against a frequency grid.

    Parameters
    ----------
    v : ndarray, shape (n,)
        One value per row (a coefficient, a parameter).

    Returns
    -------
    ndarray, shape (n, 1)
        A view of ``v`` as a column.
    """
    return v[:, None]


def excess_squared(omega: npt.ArrayLike, kx: npt.ArrayLike, kv: npt.ArrayLike, ka: npt.ArrayLike,
                   tau: npt.ArrayLike, delta: npt.ArrayLike, headway: npt.ArrayLike) -> Array:
    r"""|Γ(jω)|² − 1 = −ω² g(ω)/|D(jω)|², without the cancellation of |N|²/|D|² − 1.

    g (:mod:`stringstab.certify.margin`) is evaluated from its coefficients, so an excess of 1e-20,
    which |Γ|² computed directly rounds to exactly 1, keeps its sign and its digits.  Near
    ω = 0, g(ω) = Ψ3 + g₂ω² + O(ω⁴) with g₂ = a − c_x δ²/2 − c_v δ and |D(0)|² = k_x², so

    .. math:: |Γ(jω)|^2 = 1 − \frac{Ψ_3}{k_x^2} ω^2 − \frac{g_2 k_x^2 − Ψ_3 d_1}{k_x^4} ω^4 + …

    (d₁ the ω² coefficient of |D|²): Ψ3 < 0 makes |Γ| > 1 on a neighbourhood of 0.

    Parameters
    ----------
    omega : array_like
        Frequencies in rad/s (broadcast against the gains).
    kx, kv, ka : array_like
        The gains.
    tau, delta, headway : float or array_like
        τ, δ, T* in s (broadcast against ω and the gains).

    Returns
    -------
    ndarray
        |Γ(jω)|² − 1 (``inf`` where D(jω) = 0).

    Examples
    --------
    >>> from stringstab.certify.frequency import gain_squared
    >>> float(excess_squared(0.0, 1.0, 0.5, 0.2, 0.1, 0.2, 1.1))
    0.0
    >>> bool(np.isclose(excess_squared(2.0, 0.9, -0.5, 1.1, 0.1, 0.2, 1.1),
    ...                 gain_squared(2.0, 0.9, -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1) - 1))
    True
    """
    w = np.asarray(omega, dtype=float)
    kx, kv, ka, tau, delta, headway = (np.asarray(k, dtype=float)
                                       for k in (kx, kv, ka, tau, delta, headway))
    co = _gen.margin_coefficients(kx, kv, ka, tau, delta, headway)
    gv = _margin.g_from_coefficients(w, co, delta)
    re_d = kx - w * w
    im_d = w * (kv + headway * kx - tau * w * w)
    d2 = re_d * re_d + im_d * im_d
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        out = -(w * w) * gv / d2
    return np.asarray(np.where(d2 > 0, out, np.inf))


def violation_peak(kx: Array, kv: Array, ka: Array, tau: Any, delta: Any, headway: Any,
                    Om: Array, cand: Array) -> tuple[Array, Array]:
    """max over ω of |Γ(jω)|² − 1 (:func:`excess_squared`) and where, for not-certified rows.

    Searched on a logarithmic grid from 10⁻¹² Ω to Ω (a violation from Ψ3 < 0 sits near
    ω = √(−Ψ3/(2g₂)), which can be 10⁻⁷ rad/s), at the candidates ``cand`` (the direct
    peak search's and the branch and bound's witness, where g < 0 was proven) and at that
    small-ω estimate, then refined on a log scale.  Reporting only: the verdict is the
    branch and bound's.

    Parameters
    ----------
    kx, kv, ka : ndarray, shape (n,)
        The gains.
    tau, delta, headway : float or ndarray of shape (n,)
        τ, δ, T* (s): shared, or one value per row (the robust certificate's witness members).
    Om : ndarray, shape (n,)
        The top of the grid (rad/s; at least 1).
    cand : ndarray, shape (n, k)
        Candidate frequencies (rad/s).

    Returns
    -------
    (ndarray, ndarray)
        max |Γ(jω)|² − 1 found and the ω where, per row.

    Examples
    --------
    >>> e2, w = violation_peak(np.array([0.9]), np.array([-0.5]), np.array([1.1]), 0.1, 0.2, 1.1,
    ...                        np.array([20.0]), np.array([[1.7]]))
    >>> round(float(np.sqrt(1 + e2[0]) - 1), 4), round(float(w[0]), 2)
    (0.0438, 1.7)
    """
    n = kx.size
    tau, delta, headway = (np.asarray(v, dtype=float) for v in (tau, delta, headway))
    prm = tuple(col(v) if v.ndim else v for v in (tau, delta, headway))
    rows = np.arange(n)
    Om = np.maximum(Om, 1.0)
    co = _gen.margin_coefficients(kx, kv, ka, tau, delta, headway)
    _t2, a, b, cx, cv = (np.broadcast_to(np.asarray(c, float), (n,)) for c in co)
    psi3, g2 = b + cx, a - cx * delta * delta / 2.0 - cv * delta
    with np.errstate(divide="ignore", invalid="ignore"):
        w_small = np.where((psi3 < 0) & (g2 > 0), np.sqrt(-psi3 / (2.0 * g2)), 0.0)
    u = np.linspace(-12.0, 0.0, 241)
    W = np.concatenate([col(Om) * 10.0 ** u[None, :], cand, col(w_small)], axis=1)
    E = excess_squared(W, col(kx), col(kv), col(ka), *prm)
    E = np.where(np.isnan(E) | (W <= 0), -np.inf, E)
    j = np.argmax(E, axis=1)
    best_w, best = W[rows, j], E[rows, j]
    step = np.full(n, 0.05)  # in log10(ω)
    v = np.linspace(-1.0, 1.0, 9)
    for _ in range(12):
        Wl = (best_w[:, None] * 10.0 ** (step[:, None] * v[None, :]))
        El = excess_squared(Wl, col(kx), col(kv), col(ka), *prm)
        El = np.where(np.isnan(El), -np.inf, El)
        k = np.argmax(El, axis=1)
        better = El[rows, k] > best
        best = np.where(better, El[rows, k], best)
        best_w = np.where(better, Wl[rows, k], best_w)
        step = step / 3.0
    return best, best_w


def searched_excess(e2: Array, direct: Array) -> tuple[Array, npt.NDArray[np.bool_]]:
    """sup gain − 1 from the searched sup gain² − 1, and where it replaces the direct value.

    The searches (:func:`violation_peak` and its sampled twin,
    :func:`stringstab.certify.sampled_excess.violation_peak`) include the direct peak among
    their candidates, so their value replaces the directly computed gain − 1 (whose last
    bits are round-off at this size) unless they found nothing above 1.  Shared by every
    certificate that reports ``sup_gain_excess``.

    Parameters
    ----------
    e2 : ndarray
        The largest |gain|² − 1 found by the search, per row.
    direct : ndarray
        The directly computed sup gain − 1 of the same rows.

    Returns
    -------
    (ndarray, ndarray of bool)
        e1 = e2 / (1 + √(1 + e2)) = sup gain − 1 without cancellation, and the rows where it
        replaces ``direct`` (e1 > 0 or e1 ≥ ``direct``).

    Examples
    --------
    >>> e1, take = searched_excess(np.array([1e-20, -1.0]), np.array([0.0, 0.0]))
    >>> e1.tolist(), take.tolist()
    ([5e-21, -0.5], [True, False])
    """
    e1 = e2 / (1.0 + np.sqrt(1.0 + np.maximum(e2, 0.0)))
    return e1, (e1 > 0) | (e1 >= direct)
