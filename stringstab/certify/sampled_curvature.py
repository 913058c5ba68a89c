r"""The curvature bound of the sampled margin's branch and bound: M ≥ |g_H''| on [l, r].

The branch and bound of :mod:`stringstab.certify.sampled` (and of the robust sampled
certificate) bounds g_H on [l, r] of width h by min(g_H(l), g_H(r)) − M h²/8; this module
computes M from bounds on the coefficients of P, Y_r and Y_i in ρ = 4 sin²(θ/2)
(:mod:`stringstab.certify.sampled_frequency`), their ρ-derivatives at ρ(r), |sin θ| on [l, r]
and the factors m, m² of the oscillating terms (derivation in docs/sampled.md).  The
coefficients of P, Y_r and Y_i are stacked in one array (q, k, ...) so that each step is one
array operation for the three polynomials: :func:`point_stack` for point coefficients.
Re-exported by :mod:`stringstab.certify.sampled_frequency`.

References
----------
docs/sampled.md (the curvature bound); IDL paper, eqs 3-9 and 4 (the loop).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from .interval import Point
from .verdicts import ROUNDOFF_SLACK
from .zoh import Coefficients

__all__ = [
    "curvature_bound",
    "interval_terms",
    "margin_curvature",
    "point_curvature",
    "point_stack",
]

Array = npt.NDArray[np.float64]


def point_stack(co: Coefficients) -> Array | None:
    """P's, Y_r's and Y_i's coefficients as one array (3, k, 2, n), or None.

    For coefficients of :class:`~stringstab.certify.interval.Point` entries of one shape
    (:func:`~stringstab.certify.zoh.point_coefficients`): polynomial, coefficient (constant
    term first; Y_i, of degree 1, padded at the top with a zero), the rows (value,
    magnitude) and the n triples.

    Parameters
    ----------
    co : Coefficients
        The coefficients.

    Returns
    -------
    ndarray, shape (3, k, 2, n), or None
        The stack; None for entries other than points of one shape.
    """
    polys = (co.P, co.Yr, co.Yi)
    first = co.P[0]
    if type(first) is not Point or not all(type(q) is Point and q.s.shape == first.s.shape
                                           for p in polys for q in p):
        return None
    return _stacked(tuple([q.s for q in p] for p in polys), np.zeros_like(first.s))


def point_curvature(S: Array, m: Array, L: Array, R: Array,
                    ends: tuple[Array, Array] | None = None) -> Array:
    """:func:`margin_curvature` of stacked point coefficients (:func:`point_stack`).

    Parameters
    ----------
    S : ndarray, shape (3, k, 2, n)
        :func:`point_stack`.
    m : ndarray, shape (n,)
        Whole samples of delay.
    L, R : ndarray, shape (n, j)
        The intervals' ends, 0 ≤ L ≤ R ≤ π.
    ends : (ndarray, ndarray), optional
        :func:`interval_terms` of L and R, computed before.

    Returns
    -------
    ndarray, shape (n, j)
        The bound on each interval.
    """
    return _curvature(np.abs(S[:, :, 0]) + ROUNDOFF_SLACK * S[:, :, 1], m, L, R, ends)


# ---------------------------------------------------------------------------
# The curvature bound of the branch and bound
# ---------------------------------------------------------------------------
def _bounds_poly(a: Array, rho_r: Array) -> tuple[Array, Array, Array]:
    """(max|Q|, max|Q_ρ|, max|Q_ρρ|) over ρ ∈ [0, ρ_r] for Q whose |coefficients| are ≤ a.

    ``a`` has shape (q, k, n): q polynomials (e.g. P, Y_r, Y_i) of k coefficients each (a
    shorter one padded with zeros, which add +0 to each non-negative sum and change no bit),
    n rows; the results have shape (q,) + the rows' shape against ``rho_r``.
    """
    A0 = np.zeros_like(rho_r)
    A1 = np.zeros_like(rho_r)
    A2 = np.zeros_like(rho_r)
    for j in range(a.shape[1]):
        aj = a[:, j, :, None] if rho_r.ndim == 2 else a[:, j]
        A0 = A0 + aj * rho_r**j
        if j >= 1:
            A1 = A1 + j * aj * rho_r ** (j - 1)
        if j >= 2:
            A2 = A2 + j * (j - 1) * aj * rho_r ** (j - 2)
    return A0, A1, A2


def _stacked(polys: tuple[list[Any], ...], zero: Any) -> Array:
    """The coefficient lists as one array (q, k, ...), each padded with ``zero`` to length k."""
    k = max(1, *(len(p) for p in polys))
    return np.array([list(p) + [zero] * (k - len(p)) for p in polys])


def _magnitudes(co: Coefficients) -> Array:
    """max(|lo|, |hi|) + the round-off slack of P's, Y_r's and Y_i's coefficients, (3, k, n).

    Bounds on |coefficient| (of :class:`~stringstab.certify.interval.Point` entries:
    :func:`point_curvature`, where max(|lo|, |hi|) is |lo|).
    """
    polys = (co.P, co.Yr, co.Yi)
    a = tuple([np.maximum(np.abs(q.lo), np.abs(q.hi)) + ROUNDOFF_SLACK * q.mag for q in p]
              for p in polys)
    return _stacked(a, np.zeros_like(a[0][0]))


def margin_curvature(co: Coefficients, m: Array, L: Array, R: Array,
                     ends: tuple[Array, Array] | None = None) -> Array:
    """M ≥ |g_H''(θ)| on [L, R] (module docstring; derivation in docs/sampled.md).

    Parameters
    ----------
    co : Coefficients
        Of :class:`~stringstab.certify.interval.Interval` entries (points, or enclosures
        over cells), n rows.
    m : ndarray, shape (n,)
        Whole samples of delay.
    L, R : ndarray, shape (n, k)
        The intervals' ends, 0 ≤ L ≤ R ≤ π.
    ends : (ndarray, ndarray), optional
        :func:`interval_terms` of L and R, computed before; default: computed here.

    Returns
    -------
    ndarray, shape (n, k)
        The bound on each interval (:func:`curvature_bound` of the coefficients' magnitudes).
    """
    S = point_stack(co)
    if S is not None:
        return point_curvature(S, m, L, R, ends)
    return _curvature(_magnitudes(co), m, L, R, ends)


def curvature_bound(aP: list[Array], aYr: list[Array], aYi: list[Array], m: Array, L: Array,
                    R: Array) -> Array:
    """M ≥ |f''(θ)| on [L, R] for f = P(ρ) + cos(mθ)Y_r(ρ) + sin(mθ) sin θ Y_i(ρ).

    For every P, Y_r, Y_i whose coefficients (in ρ = 4 sin²(θ/2), constant term first) are
    bounded in absolute value by ``aP``, ``aYr``, ``aYi``: g_H of one triple or of every
    member of a cell (:func:`margin_curvature`), or the split form's F and G
    (:mod:`stringstab.certify.sampled_split`, with Y_r = Y_i = 0 for F).  Derivation in
    docs/sampled.md: bounds on P, Y_r, Y_i and their ρ-derivatives at ρ(R), |sin θ| on
    [L, R] and the factors m, m² of the oscillating terms.

    Parameters
    ----------
    aP, aYr, aYi : list of ndarray, shape (n,)
        Bounds on the absolute values of the coefficients (empty lists for none).
    m : ndarray, shape (n,)
        Whole samples of delay.
    L, R : ndarray, shape (n, k)
        The intervals' ends, 0 ≤ L ≤ R ≤ π.

    Returns
    -------
    ndarray, shape (n, k)
        The bound on each interval.
    """
    ref = next((x for p in (aP, aYr, aYi) for x in p), None)
    zero = np.zeros_like(ref) if ref is not None else np.zeros(R.shape[:1])
    return _curvature(_stacked((aP, aYr, aYi), zero), m, L, R)


def interval_terms(L: Array, R: Array) -> tuple[Array, Array]:
    """ρ(R) = 4 sin²(R/2) and S1 ≥ |sin θ| on [L, R]: what the curvature bound needs of the ends.

    Parameters
    ----------
    L, R : ndarray
        The intervals' ends, 0 ≤ L ≤ R ≤ π.

    Returns
    -------
    (ndarray, ndarray)
        ρ(R) and S1 (sin R up to π/2, sin L from π/2, else 1).
    """
    rho_r = 4.0 * np.sin(0.5 * R) ** 2
    S1 = np.where(R <= 0.5 * np.pi, np.sin(R), np.where(L >= 0.5 * np.pi, np.sin(L), 1.0))
    return rho_r, S1


def _curvature(a: Array, m: Array, L: Array, R: Array,
               ends: tuple[Array, Array] | None = None) -> Array:
    """:func:`curvature_bound` of the stacked bounds ``a`` (3, k, n) of P, Y_r and Y_i."""
    rho_r, S1 = interval_terms(L, R) if ends is None else ends
    mm = m[:, None] if (np.ndim(m) and R.ndim == 2) else m
    A0, A1, A2 = _bounds_poly(a, rho_r)
    D1 = 2.0 * S1 * A1
    D2 = 4.0 * S1 * S1 * A2 + 2.0 * A1
    p2, (r0, i0), (r1, i1), (r2, i2) = D2[0], A0[1:], D1[1:], D2[1:]
    f0 = S1
    f1 = mm * S1 + 1.0
    f2 = (mm * mm + 1.0) * S1 + 2.0 * mm
    return np.asarray(p2 + (mm * mm * r0 + 2.0 * mm * r1 + r2)
                      + (f2 * i0 + 2.0 * f1 * i1 + f0 * i2))
