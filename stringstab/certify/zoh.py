r"""The zero-order-hold discretisation of the loop: the coefficients of H(z) and of g_H.

Every vehicle samples synchronously with period H, holds its command over the period and
has the actuator lag τ; the delayed predecessor acceleration a_{i−1}(kH − δ) is exact for
any δ = (m + ε)H ≥ 0 (:func:`split_delay`).  The string transfer function from the
predecessor's acceleration samples to the follower's, derived symbolically by
:mod:`stringstab.derive.sampled_symbolic`, is in w = z − 1

.. math::
    H(z) = \frac{φ_1}{φ_{1p}}\,\frac{n(w) + z^{-(m+1)} k_a w^2 \ell(w)}{Δ(w)}

with Δ = w³ + δ2 w² + δ1 w + δ0, n = ν2 w² + ν1 w + ν0, ℓ = φ_{1p} + (1 − C) w and

    δ0 = k_x H² φ1,  δ1 = H(c φ1 + k_x(τ ψ2 + H φ1/2)),  δ2 = φ1 + c τ ψ2 + k_x τ² ψ3,
    ν0 = k_x H² φ1p, ν1 = H(k_v φ1p + k_x(τ_p ψ2p + H φ1p/2)), ν2 = k_v τ_p ψ2p + k_x τ_p² ψ3p,

c = k_v + T* k_x, φ1 = 1 − e^{−x}, ψ2 = x − φ1, ψ3 = x²/2 − ψ2 at x = H/τ (:func:`phi`; the
``p`` forms at H/τ_p, the predecessor's lag) and C = e^{−(1−ε)H/τ_p}.  Every coefficient
is a sum of terms of one order in H, so nothing cancels as H → 0.

With δ, ν and ℓ, :func:`build` computes the coefficients of the polynomials P, Y_r (degree
2) and Y_i (degree 1) in ρ = 4 sin²(θ/2) of the margin g_H (:class:`Coefficients`;
:mod:`stringstab.certify.sampled_frequency`); the constant terms of |Δ|² and |n|² cancel
*exactly* (φ1p δ0 = φ1 ν0: H(1) = 1), so the division by ρ is exact.

Everything is computed in the arithmetic of :mod:`stringstab.certify.interval`: at a point
(:func:`point_coefficients`: one gain triple per row), over a cell of parameters
(:func:`coefficients` with (lo, hi) pairs), or with derivative enclosures over cells of
(τ, τ_p, ε, T*) for the mean-value form (:func:`cell_coefficients`, for
:mod:`stringstab.certify.robust_sampled`).

References
----------
IDL paper, eqs 3-9 (model) and eq 4 (law); :mod:`stringstab.derive.sampled_symbolic`
(the same coefficients in SymPy; tests check one against the other).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import numpy.typing as npt

from ..params import Params, check_params, positive
from ..params import sample_time as _sample_time
from .interval import Interval, IntervalAD, Point, interval, poly_add, poly_scale
from .point_program import Program, record

__all__ = [
    "WHOLE_SAMPLE_RTOL",
    "Coefficients",
    "abs2_over_rho",
    "build",
    "cell_coefficients",
    "coefficients",
    "cross_terms",
    "exp_neg_ad",
    "loop_parameters",
    "parameter_primitives",
    "phi",
    "phi_ad",
    "phi_interval",
    "point_coefficients",
    "primitives",
    "ratio_ad",
    "schur_terms",
    "split_delay",
]

Array = npt.NDArray[np.float64]

# ---------------------------------------------------------------------------
# The ZOH integrals of a lag: φ1, ψ2, ψ3 without cancellation
# ---------------------------------------------------------------------------
_INV_FACT = [1.0 / math.factorial(k) for k in range(40)]


def phi(x: npt.ArrayLike) -> tuple[Array, Array, Array]:
    """(φ1, ψ2, ψ3) = (1 − e^{−x}, x − φ1, x²/2 − ψ2) for x ≥ 0, each to a few ulps.

    For x ≤ 1, ψ3 = Σ_{k≥3} (−1)^{k+1} x^k/k! (24 terms: truncation < 10⁻²⁸ relative),
    then ψ2 = x²/2 − ψ3 and φ1 = x − ψ2 (no cancellation: ψ3 ≤ x²/6, ψ2 ≤ x/2);
    for x > 1 the direct forms (cancellation ratio < 16).

    Parameters
    ----------
    x : array_like
        x = H/τ ≥ 0 (the sample time over the lag).

    Returns
    -------
    (ndarray, ndarray, ndarray)
        φ1, ψ2 and ψ3 at x.

    Examples
    --------
    >>> [round(float(v), 12) for v in phi(0.5)]
    [0.393469340287, 0.106530659713, 0.018469340287]
    """
    x = np.asarray(x, dtype=float)
    xs = np.minimum(x, 1.0)
    neg = -xs
    acc = np.zeros_like(xs)
    for k in range(26, 2, -1):  # Horner on x³ Σ (−x)^{k−3}/k! (in place: the same numbers)
        acc *= neg
        acc += _INV_FACT[k]
    p3s = acc * xs * xs * xs
    p2s = 0.5 * xs * xs - p3s
    p1s = xs - p2s
    if acc.ndim and bool(np.all(x <= 1.0)):  # every x on the series (H ≤ τ): no direct forms
        return p1s, p2s, p3s
    p1l = -np.expm1(-x)
    p2l = x - p1l
    p3l = 0.5 * x * x - p2l
    small = x <= 1.0
    return np.where(small, p1s, p1l), np.where(small, p2s, p2l), np.where(small, p3s, p3l)


def phi_interval(x_lo: Array, x_hi: Array) -> tuple[Interval, Interval, Interval]:
    """φ1, ψ2, ψ3 over x ∈ [x_lo, x_hi]: all three increase with x.

    Parameters
    ----------
    x_lo, x_hi : ndarray
        The ends of x = H/τ; the same array twice gives points.

    Returns
    -------
    (Interval, Interval, Interval)
        Enclosures of φ1, ψ2 and ψ3 over [x_lo, x_hi].
    """
    lo = phi(x_lo)
    if x_hi is x_lo:
        return tuple(Interval(v) for v in lo)  # type: ignore[return-value]
    hi = phi(x_hi)
    return tuple(Interval(a, b) for a, b in zip(lo, hi))  # type: ignore[return-value]


# ---------------------------------------------------------------------------
# Coefficients
# ---------------------------------------------------------------------------
@dataclass
class Coefficients:
    """w-form coefficients (δ, ν, ℓ) and the margin polynomials P, Y_r, Y_i in ρ.

    Each entry is an :class:`~stringstab.certify.interval.Interval` (points, or intervals
    over a cell) or an :class:`~stringstab.certify.interval.IntervalAD` over a cell, one
    row per gain triple or cell: ``delta`` = [δ0, δ1, δ2] (δ3 = 1), ``nu`` = [ν0, ν1, ν2],
    ``ell`` = [φ1p, 1 − C], ``phi1`` and ``phi1p`` (φ1 at H/τ and H/τ_p), and the margin
    polynomials ``P``, ``Yr``, ``Yi`` in ρ, constant term first (module docstring).
    """

    delta: list[Any]
    nu: list[Any]
    ell: list[Any]
    phi1: Any
    phi1p: Any
    P: list[Any]
    Yr: list[Any]
    Yi: list[Any]
    #: The Schur conditions of δ (:func:`schur_terms`), when computed
    #: with the coefficients (:func:`point_coefficients`); None otherwise (not kept by
    #: :meth:`map` and :meth:`take`).
    schur: list[Any] | None = None

    def map(self, f: Callable[[Any], Any]) -> Coefficients:
        """Every entry through ``f`` (e.g. the centre values ``lambda v: v.c`` of a cell)."""
        return Coefficients([f(v) for v in self.delta], [f(v) for v in self.nu],
                            [f(v) for v in self.ell], f(self.phi1), f(self.phi1p),
                            [f(v) for v in self.P], [f(v) for v in self.Yr],
                            [f(v) for v in self.Yi])

    def take(self, idx: npt.NDArray[np.intp]) -> Coefficients:
        """The rows ``idx`` of every entry (points stay points)."""
        return self.map(lambda v: v.take(idx))


# Re(w^j) = R_j(ρ), Im(w^j) = sin θ · T_j(ρ), and R_j/ρ (j ≥ 1), as ascending ρ-coefficients:
# w + w̄ = −ρ, w w̄ = ρ, so w^j + w̄^j follows s_j = −ρ s_{j−1} − ρ s_{j−2}.
_R = {0: [1.0], 1: [0.0, -0.5], 2: [0.0, -1.0, 0.5], 3: [0.0, 0.0, 1.5, -0.5]}
_T = {0: [0.0], 1: [1.0], 2: [0.0, -1.0], 3: [0.0, -1.0, 1.0]}


def _scaled(c: Any, coefs: list[float]) -> list[Any]:
    """c times each constant of ``coefs`` (None for a zero: adding it would change nothing)."""
    return [None if v == 0.0 else c * v for v in coefs]


def _filled(p: list[Any], like: Any) -> list[Any]:
    """``p`` with every missing (None) coefficient a zero constant shaped as ``like``."""
    return [like.const(0.0) if v is None else v for v in p]


def abs2_over_rho(p: list[Any]) -> list[Any]:
    """(|Σ p_k w^k|² − p_0²)/ρ on the unit circle, as a polynomial in ρ.

    |Σp_k w^k|² = Σ_k p_k² ρ^k + 2 Σ_{k<l} p_k p_l ρ^k R_{l−k}(ρ); every term but p_0²
    carries a factor ρ (R_j(0) = 0 for j ≥ 1), divided out exactly.

    Parameters
    ----------
    p : list of Interval or IntervalAD
        The coefficients p_0, p_1, ... of a polynomial in w = z − 1 (at least two).

    Returns
    -------
    list
        The coefficients in ρ = |w|² = 4 sin²(θ/2), constant term first, in the arithmetic
        of ``p``.
    """
    out: list[Any] = []
    for k in range(1, len(p)):
        out = poly_add(out, [None] * (k - 1) + [p[k] * p[k]])
    for k in range(len(p)):
        for l_ in range(k + 1, len(p)):
            r = _R[l_ - k]
            # ρ^k R_j / ρ = ρ^{k-1} R_j  (k ≥ 1) or R_j/ρ (k = 0: drop R_j's zero constant)
            rr = ([0.0] * (k - 1) + r) if k >= 1 else r[1:]
            out = poly_add(out, _scaled(2.0 * (p[k] * p[l_]), rr))
    return _filled(out, p[0])


def cross_terms(ell: list[Any], nu: list[Any]) -> tuple[list[Any], list[Any]]:
    """Y = ℓ(w)·conj(n(w)) = Y_r(ρ) + j sin θ · Y_i(ρ) on the unit circle.

    Parameters
    ----------
    ell, nu : list of Interval or IntervalAD
        The coefficients of ℓ(w) and n(w) in w = z − 1, constant term first.

    Returns
    -------
    (list, list)
        The coefficients of Y_r and Y_i in ρ = 4 sin²(θ/2), constant term first.
    """
    yr: list[Any] = []
    yi: list[Any] = []
    for a, la in enumerate(ell):
        for b, nb in enumerate(nu):
            c = la * nb
            lo_, d = min(a, b), abs(a - b)
            shift = [0.0] * lo_
            yr = poly_add(yr, _scaled(c, shift + _R[d]))
            if d:
                sgn = 1.0 if a > b else -1.0
                yi = poly_add(yi, _scaled(c, shift + [sgn * t for t in _T[d]]))
    return _filled(yr, ell[0]), _filled(yi, ell[0])


def primitives(
    kx: Array, kv: Array, ka: Array, *, H: float,
    tau: tuple[Array, Array], tau_p: tuple[Array, Array], eps: tuple[Array, Array],
    c: tuple[Array, Array],
) -> dict[str, Interval]:
    """The model quantities over a cell by interval arithmetic (a point when lo is hi).

    Parameters
    ----------
    kx, kv, ka : ndarray
        The gains, one per row.
    H : float
        Sample time, s.
    tau, tau_p, eps, c : (ndarray, ndarray)
        (lo, hi) of τ, τ_p, ε and c = k_v + T* k_x; pass the same array twice for a point
        (then every quantity is a point and the build takes the point path).

    Returns
    -------
    dict of str to Interval
        The gains, τ, τ_p, c, the lag integrals φ1, ψ2, ψ3 (and their ``p`` forms), ℓ1 and
        C − E_p, keyed as :func:`build` reads them.
    """
    T = interval(*tau)
    Tp = interval(*tau_p)
    # a point parameter gives one array for both ends, so that phi_interval returns points and
    # the whole build takes the point path of Interval (two arrays of equal values would be an interval)
    x_lo = H / tau[1]
    f1, p2, p3 = phi_interval(x_lo, x_lo if tau[0] is tau[1] else H / tau[0])
    xp_lo = H / tau_p[1]
    xp_hi = xp_lo if tau_p[0] is tau_p[1] else H / tau_p[0]
    f1p, p2p, p3p = phi_interval(xp_lo, xp_hi)
    point = tau_p[0] is tau_p[1] and eps[0] is eps[1]
    y_lo = (1.0 - eps[1]) * xp_lo
    y_hi = y_lo if point else (1.0 - eps[0]) * xp_hi
    ell1 = phi_interval(y_lo, y_hi)[0]
    ex = Interval(np.exp(-y_lo)) if point else Interval(np.exp(-y_hi), np.exp(-y_lo))
    ex_lo = eps[0] * xp_lo
    cm = ex * phi_interval(ex_lo, ex_lo if point else eps[1] * xp_hi)[0]
    return {"K_x": Interval(kx), "K_v": Interval(kv), "K_a": Interval(ka), "T": T, "Tp": Tp,
            "Cc": interval(*c),
            "f1": f1, "p2": p2, "p3": p3, "f1p": f1p, "p2p": p2p, "p3p": p3p,
            "ell1": ell1, "cm": cm}


def build(q: dict[str, Any], H: float) -> Coefficients:
    """δ, ν, ℓ and the margin polynomials from the primitives (any arithmetic type).

    Parameters
    ----------
    q : dict
        The primitives of :func:`primitives` (intervals) or of :func:`cell_coefficients`
        (derivative enclosures).
    H : float
        Sample time, s.

    Returns
    -------
    Coefficients
        In the arithmetic of ``q``.
    """
    K_x, K_v, K_a, T, Tp, Cc = (q[k] for k in ("K_x", "K_v", "K_a", "T", "Tp", "Cc"))
    f1, p2, p3, f1p, p2p, p3p = (q[k] for k in ("f1", "p2", "p3", "f1p", "p2p", "p3p"))
    ell1, cm = q["ell1"], q["cm"]
    Hs = float(H)
    d0 = K_x * (Hs * Hs) * f1
    d1 = Hs * (Cc * f1 + K_x * (T * p2 + (0.5 * Hs) * f1))
    d2 = f1 + Cc * T * p2 + K_x * T * T * p3
    n0 = K_x * (Hs * Hs) * f1p
    n1 = Hs * (K_v * f1p + K_x * (Tp * p2p + (0.5 * Hs) * f1p))
    n2 = K_v * Tp * p2p + K_x * Tp * Tp * p3p
    nu = [n0, n1, n2]
    ell = [f1p, ell1]
    # κ² = τ² τ_p² / H⁶ and the two prefactors κ φ1p (on Δ) and κ φ1 (on the numerator)
    kap = T * Tp * (1.0 / Hs**3)
    A = kap * f1p
    B = kap * f1
    A2, B2 = A * A, B * B
    Ad = abs2_over_rho([d0, d1, d2, d0.const(1.0)])
    An = abs2_over_rho(nu)
    # |ℓ|² = ℓ0² − ℓ1 (ℓ0 − ℓ1) ρ, with ℓ0 − ℓ1 = C − E_p = C (1 − e^{−εH/τ_p}) ≥ 0
    L = [f1p * f1p, -(ell1 * cm)]
    kaL = poly_scale(B2 * K_a * K_a, [d0.const(0.0), *L])
    P = poly_add(poly_add(poly_scale(A2, Ad), poly_scale(B2, An), -1.0), kaL, -1.0)
    yr, yi = cross_terms(ell, nu)
    k2 = 2.0 * (B2 * K_a)
    return Coefficients([d0, d1, d2], nu, ell, f1, f1p, P, poly_scale(k2, yr), poly_scale(k2, yi))


def schur_terms(delta: list[Any]) -> list[Any]:
    """The five quantities of :func:`stringstab.derive.sampled_symbolic.schur_conditions`.

    Decided by :func:`stringstab.certify.schur.schur_bands` (which re-exports this function);
    here, with the coefficients, so that :func:`point_coefficients` records them too.

    Δ is Schur iff each is > 0 (the bilinear conditions in the w-form).

    Parameters
    ----------
    delta : list
        δ0, δ1, δ2 of Δ(w), in any arithmetic of :mod:`stringstab.certify.interval`
        (points, intervals over cells, or derivative enclosures).

    Returns
    -------
    list
        b0, b1, b2, b3 and the Hurwitz determinant h2, in the arithmetic of ``delta``.
    """
    d0, d1, d2 = delta
    b0 = d0
    b1 = 2.0 * d1 - 3.0 * d0
    b2 = 3.0 * d0 - 4.0 * d1 + 4.0 * d2
    b3 = 8.0 - d0 + 2.0 * d1 - 4.0 * d2
    h2 = 8.0 * (d1 * d2 - d0 * d2 - d1 * d1 + 2.0 * (d0 * d1) - d0 * d0 - d0)
    return [b0, b1, b2, b3, h2]


def coefficients(
    kx: Array, kv: Array, ka: Array, *, H: float,
    tau: tuple[Array, Array], tau_p: tuple[Array, Array], eps: tuple[Array, Array],
    c: tuple[Array, Array],
) -> Coefficients:
    """All coefficients over a parameter cell (a point when every lo is its hi).

    Parameters
    ----------
    kx, kv, ka : ndarray
        The gains, one per row.
    H : float
        Sample time, s.
    tau, tau_p, eps, c : (ndarray, ndarray)
        (lo, hi) pairs of arrays of τ, τ_p, ε and c = k_v + T* k_x (the same array twice
        for a point).

    Returns
    -------
    Coefficients
        Of :class:`~stringstab.certify.interval.Interval` entries.
    """
    return build(primitives(kx, kv, ka, H=H, tau=tau, tau_p=tau_p, eps=eps, c=c), H)


# ---------------------------------------------------------------------------
# Parameter cells: the mean-value form
# ---------------------------------------------------------------------------
def ratio_ad(t: IntervalAD, H: float) -> IntervalAD:
    """x = H/t for t > 0 (a lag): decreasing, derivative −H/t² ∈ [−H/t_lo², −H/t_hi²].

    Parameters
    ----------
    t : IntervalAD
        A lag over the cells (τ or τ_p), s, > 0.
    H : float
        Sample time, s.

    Returns
    -------
    IntervalAD
        H/t with its derivative enclosures.
    """
    lo, hi = t.r.lo, t.r.hi
    dr = Interval(-H / (lo * lo), -H / (hi * hi))
    return IntervalAD(Interval(H / t.c.lo), Interval(H / hi, H / lo), tuple(dr * gi for gi in t.g))


def phi_ad(x: IntervalAD) -> tuple[IntervalAD, IntervalAD, IntervalAD]:
    """φ1, ψ2, ψ3 of x ≥ 0 (:func:`phi`): increasing, with φ1' = 1 − φ1, ψ2' = φ1, ψ3' = ψ2.

    Parameters
    ----------
    x : IntervalAD
        x ≥ 0 over the cells (e.g. H/τ of :func:`ratio_ad`).

    Returns
    -------
    (IntervalAD, IntervalAD, IntervalAD)
        φ1, ψ2 and ψ3 with their derivative enclosures.
    """
    c = tuple(Interval(v) for v in phi(x.c.lo))
    r = phi_interval(x.r.lo, x.r.hi)
    ders = (1.0 - r[0], r[0], r[1])
    return tuple(IntervalAD(ci, ri, tuple(dk * gi for gi in x.g))  # type: ignore[return-value]
                 for ci, ri, dk in zip(c, r, ders))


def exp_neg_ad(y: IntervalAD) -> IntervalAD:
    """e^{−y}: decreasing, derivative −e^{−y}.

    Parameters
    ----------
    y : IntervalAD
        The exponent over the cells.

    Returns
    -------
    IntervalAD
        e^{−y} with its derivative enclosures.
    """
    r = Interval(np.exp(-y.r.hi), np.exp(-y.r.lo))
    return IntervalAD(Interval(np.exp(-y.c.lo)), r, tuple(-(r * gi) for gi in y.g))


def cell_coefficients(
    kx: Array, kv: Array, ka: Array, *, H: float, tau: Array, tau_p: Array | None,
    eps: Array, headway: Array,
) -> Coefficients:
    """Coefficients with derivative enclosures over cells ((n, 2) bounds per parameter).

    The parameters are (τ, τ_p, ε, T*), or (τ, ε, T*) with τ_p = τ when ``tau_p`` is None.

    Parameters
    ----------
    kx, kv, ka : ndarray
        The gains, one per cell.
    H : float
        Sample time, s.
    tau, tau_p, eps, headway : ndarray, shape (n, 2)
        The cells' bounds of τ, τ_p (or None: τ_p = τ), ε and T*.

    Returns
    -------
    Coefficients
        Of :class:`~stringstab.certify.interval.IntervalAD` entries (derivatives in the
        order of the parameters above).
    """
    d = 3 if tau_p is None else 4
    T = IntervalAD.variable(tau[:, 0], tau[:, 1], 0, d)
    Tp = T if tau_p is None else IntervalAD.variable(tau_p[:, 0], tau_p[:, 1], 1, d)
    E = IntervalAD.variable(eps[:, 0], eps[:, 1], d - 2, d)
    Th = IntervalAD.variable(headway[:, 0], headway[:, 1], d - 1, d)
    K_x, K_v, K_a = T.const(kx), T.const(kv), T.const(ka)
    f1, p2, p3 = phi_ad(ratio_ad(T, H))
    xp = ratio_ad(Tp, H)
    f1p, p2p, p3p = phi_ad(xp)
    y = (1.0 - E) * xp
    cm = exp_neg_ad(y) * phi_ad(E * xp)[0]
    q = {"K_x": K_x, "K_v": K_v, "K_a": K_a, "T": T, "Tp": Tp, "Cc": K_v + Th * K_x,
         "f1": f1, "p2": p2, "p3": p3, "f1p": f1p, "p2p": p2p, "p3p": p3p,
         "ell1": phi_ad(y)[0], "cm": cm}
    return build(q, H)


# ---------------------------------------------------------------------------
# The delay in samples, the parameters and the point coefficients
# ---------------------------------------------------------------------------
#: A delay this close to a whole number of samples (relative to H) is that whole number.
WHOLE_SAMPLE_RTOL = 1e-9


def split_delay(delta: float, sample_time: float, *, whole: bool = True) -> tuple[int, float]:
    """δ = (m + ε) H with m an integer ≥ 0 and 0 ≤ ε < 1.

    A δ within :data:`WHOLE_SAMPLE_RTOL` of a sample of a whole number of samples is that
    whole number (ε = 0): ``0.3`` is not a multiple of ``0.1`` in binary floating point
    (``math.fmod(0.3, 0.1)`` is 0.0999...), but the delay meant, and the loop certified, is
    three samples, not two samples and 0.9999999999999998 of a third.  Otherwise the exact
    ``math.fmod`` gives m and ε.

    Parameters
    ----------
    delta, sample_time : float
        δ ≥ 0 and H > 0, s (not validated here).
    whole : bool
        Round a δ within :data:`WHOLE_SAMPLE_RTOL` H of a whole number of samples to it
        (default).  False: the exact split of the float δ (the robust certificate's box ends,
        which must cover every δ in the box).

    Returns
    -------
    (int, float)
        m and ε.

    Examples
    --------
    >>> split_delay(0.2, 0.1), split_delay(0.25, 0.1)[0], split_delay(0.0, 0.05)
    ((2, 0.0), 2, (0, 0.0))
    >>> split_delay(0.3, 0.1), split_delay(0.7, 0.1)
    ((3, 0.0), (7, 0.0))
    """
    n = round(delta / sample_time)
    if whole and abs(delta - n * sample_time) <= WHOLE_SAMPLE_RTOL * sample_time:
        return int(n), 0.0
    r = math.fmod(delta, sample_time)
    m = round((delta - r) / sample_time)
    return m, r / sample_time


def loop_parameters(tau: Any, delta: Any, headway: Any, sample_time: Any,
                    tau_prev: Any) -> tuple[Params, float, float]:
    """The sampled loop's parameters, validated.

    Parameters
    ----------
    tau, delta, headway : float
        Lag τ > 0, delay δ ≥ 0 and headway T* ≥ 0, s.
    sample_time : float
        H > 0, s.
    tau_prev : float or None
        The predecessor's lag τ_p > 0 (None: τ).

    Returns
    -------
    (Params, float, float)
        τ, δ, T*; H; τ_p.

    Raises
    ------
    StringStabError
        On a parameter out of range or not finite.
    """
    p = Params(*check_params(tau, delta, headway))
    H = _sample_time(sample_time)
    tp = p.tau if tau_prev is None else positive("tau_prev (predecessor's actuator lag)",
                                                  tau_prev, unit=" s")
    return p, H, tp


def point_coefficients(kx: Array, kv: Array, ka: Array, p: Params, H: float,
                       tp: float) -> tuple[Coefficients, int]:
    """The coefficients of each gain triple's loop (points) and the whole samples m of δ.

    Parameters
    ----------
    kx, kv, ka : ndarray
        The gains, one triple per row.
    p : Params
        τ, δ, T* (validated).
    H : float
        Sample time, s.
    tp : float
        The predecessor's lag τ_p, s.

    Returns
    -------
    (Coefficients, int)
        Point coefficients, and m of δ = (m + ε)H (:func:`split_delay`).
    """
    m, eps = split_delay(p.delta, H)
    n = kx.size
    # the parameters' quantities once per parameter set, on one element: each row's numbers
    # are those of the full arrays (the same operations on the same values, broadcast); the
    # build in the stacked point arithmetic (Point: the same numbers as Interval's points,
    # one array operation per step instead of two),
    # build recorded once per loop and replayed on the gains (point_program: every step the
    # same operation on the same operands, so the same bits)
    prog = _program(float(p.tau), float(tp), float(eps), float(H))
    c = kv + p.headway * kx
    X = np.stack((kx, kv, ka, c))
    rows = np.stack((X, np.abs(X)), axis=1)  # each input's rows (value, magnitude)
    regs = prog.run(list(rows))
    one = np.ones(n)

    def point(i: int) -> Point:
        return Point(regs[i]) if regs[i].shape[1:] == (n,) else Point(regs[i] * one)

    co = prog.outputs.map(point)
    co.schur = [point(i) for i in prog.schur]
    return co, m


@lru_cache(maxsize=64)
def _program(tau: float, tau_p: float, eps: float, H: float) -> Program:
    """:func:`build` and :func:`schur_terms` recorded at the loop (τ, τ_p, ε, H) (point_program)."""

    def build_and_terms(q: dict[str, Any]) -> tuple[Coefficients, list[Any]]:
        co = build(q, H)
        return co, schur_terms(co.delta)

    return record(build_and_terms, parameter_primitives(tau, tau_p, eps, H),
                  ("K_x", "K_v", "K_a", "Cc"))


@lru_cache(maxsize=64)
def parameter_primitives(tau: float, tau_p: float, eps: float, H: float) -> dict[str, Point]:
    """The parameter-only primitives of :func:`primitives` at one point (one element).

    Parameters
    ----------
    tau, tau_p, eps, H : float
        τ, τ_p, ε and H (s; ε of δ = (m + ε)H).

    Returns
    -------
    dict of str to Point
        Keyed as :func:`build` reads them (the gains' entries left out).
    """
    t, t_p, e, one = np.array([tau]), np.array([tau_p]), np.array([eps]), np.ones(1)
    q = primitives(one, one, one, H=H, tau=(t, t), tau_p=(t_p, t_p), eps=(e, e), c=(one, one))
    return {k: Point.of(v) for k, v in q.items() if k not in ("K_x", "K_v", "K_a", "Cc")}
