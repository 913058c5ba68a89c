"""Internal stability of the sampled loop: whether Δ(z) is Schur.

The characteristic polynomial of the follower's sampled loop (:mod:`stringstab.certify.zoh`),
in w = z − 1, is Δ = w³ + δ2 w² + δ1 w + δ0; it depends on k_x, k_v, τ, T* and H only (not
on δ, k_a or the predecessor's lag; the delay adds m + 1 poles at z = 0).  Schur stability
(every root inside |z| < 1) is decided in this well-conditioned w-form by the bilinear
conditions of :func:`stringstab.derive.sampled_symbolic.schur_conditions`
(:func:`schur_terms`), with a relative band of :data:`SCHUR_RTOL` around the boundary left
undecided (:func:`schur_bands`).  The spectral radius and the pole angles (companion-matrix
eigenvalues) are for reporting only.

References
----------
IDL paper, eqs 3-9 (model); :mod:`stringstab.derive.sampled_symbolic` (the conditions).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ..params import Params, as_gains, check_params
from ..params import sample_time as _sample_time
from .interval import Interval, Point
from .zoh import phi, point_coefficients, schur_terms

__all__ = [
    "SCHUR_RTOL",
    "pole_angles",
    "poles",
    "schur",
    "schur_bands",
    "schur_margins",
    "spectral_radius",
    "spectral_radius_of",
]

Array = npt.NDArray[np.float64]

#: Relative band around the Schur boundary left undecided (per unit of each condition's
#: magnitude companion).
SCHUR_RTOL = 1e-12


def schur_bands(delta: list[Interval], terms: list[Interval] | None = None,
                ) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
    """(surely Schur, surely not Schur), with a band of :data:`SCHUR_RTOL` around the boundary.

    Parameters
    ----------
    delta : list of Interval
        δ0, δ1, δ2 of Δ(w) (points or intervals), one row per triple.
    terms : list of Interval, optional
        :func:`schur_terms` of ``delta``, computed before (``Coefficients.schur`` of
        :func:`stringstab.certify.zoh.point_coefficients`); default: computed here.

    Returns
    -------
    (ndarray of bool, ndarray of bool)
        Every condition above its band; some condition at or below minus its band (a root
        on |z| = 1 is not Schur).  Rows with neither are left undecided.
    """
    terms = schur_terms(delta) if terms is None else terms
    pts = [t for t in terms if type(t) is Point]
    if len(pts) == len(terms) and all(t.s.shape == pts[0].s.shape for t in pts):
        # stacked points: the five conditions' rows (value, magnitude) as one array, the
        # same comparisons
        s = np.stack([t.s for t in pts])
        band = SCHUR_RTOL * s[:, 1]
        return (np.asarray((s[:, 0] > band).all(axis=0)),
                np.asarray((s[:, 0] <= -band).any(axis=0)))
    sure = np.ones(np.shape(delta[0].lo), dtype=bool)
    fail = np.zeros_like(sure)
    for t in terms:
        band = SCHUR_RTOL * t.mag
        sure &= t.lo > band
        fail |= t.hi <= -band  # the boundary itself (a root on |z| = 1) is not Schur
    return sure, fail


def _loop_delta(k_x: Any, k_v: Any, tau: Any, headway: Any,
                sample_time: Any) -> tuple[list[Interval], tuple[int, ...]]:
    """δ0, δ1, δ2 of the follower's loop (flattened) and the gains' shape."""
    p = Params(*check_params(tau, 0.0, headway))
    H = _sample_time(sample_time)
    kx, kv, _ = as_gains(k_x, k_v, 0.0)
    shape = kx.shape
    kx, kv = kx.ravel(), kv.ravel()
    return point_coefficients(kx, kv, np.zeros_like(kx), p, H, p.tau)[0].delta, shape


def schur(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, *, tau: float, headway: float, sample_time: float,
) -> npt.NDArray[np.bool_]:
    """Internal stability of the sampled loop: whether Δ(z) is Schur (all roots inside |z| < 1).

    Decided by the bilinear conditions (:func:`stringstab.derive.sampled_symbolic.schur_conditions`)
    in the w-form; True only outside a relative 10⁻¹² band around the boundary.  Δ does not
    depend on δ, k_a or the predecessor's lag.

    Parameters
    ----------
    k_x, k_v : array_like
        Gains (broadcast together).
    tau, headway, sample_time : float
        τ > 0, T* ≥ 0, H > 0 (s).

    Returns
    -------
    ndarray of bool

    Raises
    ------
    StringStabError
        On parameters out of range or non-finite gains.

    Examples
    --------
    >>> schur([1.2, 1.2, -0.5], [0.5, 40.0, 1.0], tau=0.1, headway=1.1, sample_time=0.1).tolist()
    [True, False, False]
    """
    delta, shape = _loop_delta(k_x, k_v, tau, headway, sample_time)
    return schur_bands(delta)[0].reshape(shape)


def schur_margins(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, *, tau: float, headway: float, sample_time: float,
) -> Array:
    """The five Schur conditions of Δ(z), each divided by its leading order in H (> 0 iff Schur).

    The conditions of :func:`stringstab.derive.sampled_symbolic.schur_conditions` (b0, b1, b2, b3 and
    the Hurwitz determinant h2) divided by H²φ1, 2Hφ1, 4φ1, 8 and 8τx³ (x = H/τ, φ1 = 1 − e^{−x}),
    so that as H → 0 they tend to k_x, c = k_v + T*k_x, 1, 1 and k_v + (T* − τ)k_x: the
    continuous Hurwitz conditions and the same margins (the gain repair of
    :mod:`stringstab.tuning` asks each to be ≥ a margin).  Each is a polynomial of degree ≤ 2
    in the gains.

    Parameters
    ----------
    k_x, k_v : array_like
        Position gain k_x (1/s²) and velocity gain k_v (1/s), broadcast together.
    tau : float
        Actuator lag τ > 0, s.
    headway : float
        Desired time headway T* ≥ 0, s.
    sample_time : float
        Sampling period H > 0, s.

    Returns
    -------
    ndarray, shape (5,) + the gains' shape

    Examples
    --------
    >>> np.round(schur_margins(1.2, 0.5, tau=0.1, headway=1.1, sample_time=1e-4), 3).tolist()
    [1.2, 1.82, 1.0, 1.0, 1.7]
    """
    delta, shape = _loop_delta(k_x, k_v, tau, headway, sample_time)
    H = float(sample_time)
    x = H / float(tau)
    f1 = float(phi(x)[0])
    scale = np.array([H * H * f1, 2.0 * H * f1, 4.0 * f1, 8.0, 8.0 * float(tau) * x**3])
    terms = np.stack([t.lo for t in schur_terms(delta)])
    return np.asarray(terms / scale[:, None]).reshape((5, *shape))


def _z_coeffs(delta: list[Array]) -> tuple[Array, Array, Array]:
    """a2, a1, a0 of Δ(z) = z³ + a2 z² + a1 z + a0."""
    d0, d1, d2 = delta
    # Δ(z) = (z−1)³ + δ2 (z−1)² + δ1 (z−1) + δ0 = z³ + a2 z² + a1 z + a0
    return d2 - 3.0, 3.0 - 2.0 * d2 + d1, d2 - d1 + d0 - 1.0


def spectral_radius(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, *, tau: float, headway: float, sample_time: float,
) -> Array:
    """max |root| of Δ(z) (< 1 iff Schur), from companion-matrix eigenvalues.

    Raises :class:`~stringstab.errors.StringStabError` on bad input, as :func:`schur`.

    Parameters
    ----------
    k_x, k_v : array_like
        Position gain k_x (1/s²) and velocity gain k_v (1/s), broadcast together.
    tau : float
        Actuator lag τ > 0, s.
    headway : float
        Desired time headway T* ≥ 0, s.
    sample_time : float
        Sampling period H > 0, s.

    Returns
    -------
    ndarray
        The spectral radius max |z| over the three roots of Δ(z), of the gains' shape.

    Examples
    --------
    >>> float(np.round(spectral_radius(1.2, 0.5, tau=0.1, headway=1.1, sample_time=0.1), 4))
    0.8888
    """
    delta, shape = _loop_delta(k_x, k_v, tau, headway, sample_time)
    return spectral_radius_of([d.lo for d in delta]).reshape(shape)


def poles(delta: list[Array]) -> npt.NDArray[np.complex128]:
    """The roots of Δ(z), one row of three per triple (companion-matrix eigenvalues).

    Parameters
    ----------
    delta : list of ndarray
        δ0, δ1, δ2 of Δ(w) (point values), one row per triple.

    Returns
    -------
    ndarray of complex, shape (n, 3)
        The three roots of each row.
    """
    a2, a1, a0 = _z_coeffs(delta)
    n = a2.size
    if not n:
        return np.zeros((0, 3), dtype=complex)
    C = np.zeros((n, 3, 3))
    C[:, 0, :] = -np.stack([a2, a1, a0], axis=1)
    C[:, 1, 0] = 1.0
    C[:, 2, 1] = 1.0
    return np.asarray(np.linalg.eigvals(C), dtype=complex)


def spectral_radius_of(delta: list[Array]) -> Array:
    """max |root| of Δ(z) per row (< 1 iff Schur).

    Parameters
    ----------
    delta : list of ndarray
        δ0, δ1, δ2 of Δ(w) (point values), one row per triple.

    Returns
    -------
    ndarray
        The spectral radius of each row.
    """
    return np.asarray(np.abs(poles(delta)).max(axis=1) if delta[0].size else np.zeros(0))


def pole_angles(delta: list[Array]) -> Array:
    """|arg z| ∈ [0, π] of the roots of Δ(z): where a lightly damped pole makes |H| peak.

    Parameters
    ----------
    delta : list of ndarray
        δ0, δ1, δ2 of Δ(w) (point values), one row per triple.

    Returns
    -------
    ndarray, shape (n, 3)
        The angles of the three roots of each row, rad/sample.
    """
    return np.abs(np.angle(poles(delta)))
