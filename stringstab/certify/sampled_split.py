r"""The split form of the sampled margin: the follower's factor against the predecessor's.

H(z) of :mod:`stringstab.certify.zoh` is a product of a factor of the follower's loop and a
factor of what it receives from its predecessor:

.. math::
    H(z) = \frac{φ_1}{Δ(w)}\;\cdot\;\frac{n(w) + z^{-(m+1)} k_a w^2 \ell(w)}{φ_{1p}},

the first factor depending on τ and T* only, the second on τ_p and δ only:
Δ depending on the follower's lag τ and headway T* (through c = k_v + T*k_x), n, ℓ and
φ1p on the predecessor's lag τ_p and the delay δ = (m + ε)H.  On the unit circle
(ρ = 4 sin²(θ/2)), with Δ̂ = Δ/(φ1H²) and N̂ = (n + z^{−(m+1)}k_a w²ℓ)/(φ1pH²) (both → the
continuous D(jω), N(jω) as H → 0, and Δ̂(0) = N̂(0) = k_x exactly),

.. math::
    g_H = \frac{(τ τ_p φ_1 φ_{1p})^2}{H^4}\,\bigl(F(θ; τ, T^*) - G(θ; τ_p, δ)\bigr),\qquad
    F = H^2\frac{|Δ̂|^2 - k_x^2}{ρ},\quad G = H^2\frac{|N̂|^2 - k_x^2}{ρ},

(:func:`follower_terms`, :func:`predecessor_terms`; the same w-form polynomials as
:func:`stringstab.certify.zoh.build`, the constant terms cancelling exactly so the division
by ρ is exact).  The factor is positive, so |H(e^{jθ})| ≤ 1 at a member iff F ≥ G there, and

* **separation**: when τ_p ranges over its interval independently of τ (a heterogeneous
  platoon), every member satisfies F ≥ G at θ iff min over (τ, T*) of F ≥ max over
  (τ_p, δ) of G — two problems in two parameters each instead of one in four; with
  τ_p = τ, the minimum over T* and the maximum over δ are taken per τ;
* **the delay at its ends**: for fixed θ, τ_p and m, N̂ is affine in C = e^{−(1−ε)H/τ_p}
  (ℓ = φ1p + (1 − C)w), so |N̂|² and G are convex in C, and C is monotone in ε: the maximum
  of G over a piece ε ∈ [ε_lo, ε_hi] of the delay is at one of its ends
  (:func:`delay_ends`).  The delay dimension is gone.

F depends on θ only through ρ; G = P_G(ρ) + cos(mθ)Y_r(ρ) + sin(mθ) sin θ Y_i(ρ).  Over a
cell of parameters, each coefficient is enclosed with derivative enclosures
(:class:`~stringstab.certify.interval.IntervalAD`), and :class:`SplitTerms` bounds F from below
and G from above at any θ by the better of the interval extension and the mean-value form.
The robust certificate over a box (:mod:`stringstab.certify.robust_sampled`) runs the branch
and bound of :mod:`stringstab.certify.branch_bound` on F − G over grids of such cells.

References
----------
:mod:`stringstab.certify.zoh` (the coefficients), :mod:`stringstab.certify.sampled_frequency`
(g_H).  R. E. Moore, R. B. Kearfott, M. J. Cloud, *Introduction to Interval Analysis*, SIAM
(2009), §6.4 (the mean-value form).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from .interval import IntervalAD, poly_add, poly_scale
from .interval_stack import StackedAD, exp_neg_stacked, phi_stacked, ratio_stacked
from .sampled_curvature import curvature_bound
from .verdicts import ROUNDOFF_SLACK
from .zoh import (
    abs2_over_rho,
    cross_terms,
    exp_neg_ad,
    phi_ad,
    primitives,
    ratio_ad,
    split_delay,
)

__all__ = [
    "delay_ends",
    "follower_margins",
    "follower_of",
    "follower_points",
    "follower_primitives",
    "follower_stacked",
    "follower_terms",
    "predecessor_margins",
    "predecessor_of",
    "predecessor_points",
    "predecessor_stacked",
    "predecessor_terms",
    "split_curvature",
    "vander",
]

Array = npt.NDArray[np.float64]


# ---------------------------------------------------------------------------
# The two factors' coefficients
# ---------------------------------------------------------------------------
def follower_of(q: dict[str, Any], H: float) -> list[Any]:
    """F = H²(|Δ̂|² − k_x²)/ρ as a polynomial in ρ, from the primitives (any arithmetic).

    Δ̂ = Δ/(φ1H²) in w = z − 1 has the coefficients k_x, (c + k_x(τψ2/φ1 + H/2))/H,
    (1 + (cτψ2 + k_xτ²ψ3)/φ1)/H² and 1/(φ1H²) (δ0, δ1, δ2, 1 of
    :func:`stringstab.certify.zoh.build` divided by φ1H²).

    Parameters
    ----------
    q : dict
        The primitives ``K_x``, ``Cc``, ``T``, ``f1``, ``p2``, ``p3`` of
        :func:`stringstab.certify.zoh.primitives` (points or intervals) or of
        :func:`follower_terms` (derivative enclosures).
    H : float
        Sample time, s.

    Returns
    -------
    list
        The three coefficients of F in ρ, constant term first, in the arithmetic of ``q``.
    """
    K_x, Cc, T, p2, p3 = q["K_x"], q["Cc"], q["T"], q["p2"], q["p3"]
    u = q["f1"].reciprocal()
    ih = 1.0 / H
    ih2 = ih * ih
    d1 = (Cc + K_x * (T * p2 * u + 0.5 * H)) * ih
    d2 = (1.0 + (Cc * T * p2 + K_x * T * T * p3) * u) * ih2
    return poly_scale(H * H, abs2_over_rho([K_x, d1, d2, u * ih2]))


def predecessor_of(q: dict[str, Any], H: float) -> tuple[list[Any], list[Any], list[Any]]:
    """G = H²(|N̂|² − k_x²)/ρ = P_G + cos(mθ)Y_r + sin(mθ) sin θ Y_i, from the primitives.

    N̂ = (n + z^{−(m+1)} k_a w² ℓ)/(φ1p H²): n/(φ1pH²) has the coefficients k_x,
    (k_v + k_x(τ_pψ2p/φ1p + H/2))/H and (k_vτ_pψ2p + k_xτ_p²ψ3p)/(φ1pH²), ℓ/(φ1pH²) the
    coefficients 1/H² and (1 − C)/(φ1pH²) (ν and ℓ of :func:`stringstab.certify.zoh.build`
    divided by φ1pH²).

    Parameters
    ----------
    q : dict
        The primitives ``K_x``, ``K_v``, ``K_a``, ``Tp``, ``f1p``, ``p2p``, ``p3p``,
        ``ell1`` (1 − C) and ``cm`` (C − E_p) of :func:`stringstab.certify.zoh.primitives`
        or of :func:`predecessor_terms`.
    H : float
        Sample time, s.

    Returns
    -------
    (list, list, list)
        The coefficients of P_G, Y_r and Y_i in ρ, constant term first.
    """
    K_x, K_v, K_a, Tp = q["K_x"], q["K_v"], q["K_a"], q["Tp"]
    p2p, p3p = q["p2p"], q["p3p"]
    up = q["f1p"].reciprocal()
    ih = 1.0 / H
    ih2 = ih * ih
    nu = [K_x, (K_v + K_x * (Tp * p2p * up + 0.5 * H)) * ih,
          (K_v * Tp * p2p + K_x * Tp * Tp * p3p) * up * ih2]
    l0 = Tp.const(ih2)
    l1 = q["ell1"] * up * ih2
    # |ℓ̂|² = ℓ̂0² − ℓ̂1(ℓ̂0 − ℓ̂1)ρ, with ℓ̂0 − ℓ̂1 = (C − E_p)/(φ1p H²): no cancellation
    ell2 = [l0.const(0.0), l0 * l0, -(l1 * (q["cm"] * up * ih2))]
    P = poly_scale(H * H, poly_add(abs2_over_rho(nu), poly_scale(K_a * K_a, ell2)))
    yr, yi = cross_terms([l0, l1], nu)
    k2 = (-2.0 * H * H) * K_a
    return P, poly_scale(k2, yr), poly_scale(k2, yi)


def follower_terms(kx: Array, kv: Array, *, H: float, tau: Array,
                   headway: Array) -> list[IntervalAD]:
    """F (:func:`follower_of`) with derivative enclosures over cells of (τ, T*).

    Parameters
    ----------
    kx, kv : ndarray
        The gains, one per cell.
    H : float
        Sample time, s.
    tau, headway : ndarray, shape (n, 2)
        The cells' bounds of τ and T*.

    Returns
    -------
    list of IntervalAD
        The three coefficients of F in ρ, constant term first; derivatives along (τ, T*).
    """
    T = IntervalAD.variable(tau[:, 0], tau[:, 1], 0, 2)
    Th = IntervalAD.variable(headway[:, 0], headway[:, 1], 1, 2)
    K_x, K_v = T.const(kx), T.const(kv)
    f1, p2, p3 = phi_ad(ratio_ad(T, H))
    return follower_of({"K_x": K_x, "Cc": K_v + Th * K_x, "T": T, "f1": f1, "p2": p2,
                        "p3": p3}, H)


def predecessor_terms(kx: Array, kv: Array, ka: Array, *, H: float, tau_p: Array,
                      eps: Array) -> tuple[list[IntervalAD], list[IntervalAD], list[IntervalAD]]:
    """G (:func:`predecessor_of`) with derivative enclosures over cells of τ_p, at ε.

    Parameters
    ----------
    kx, kv, ka : ndarray
        The gains, one per cell.
    H : float
        Sample time, s.
    tau_p : ndarray, shape (n, 2)
        The cells' bounds of the predecessor's lag τ_p.
    eps : ndarray, shape (n,)
        The fractional delay ε ∈ [0, 1] of each cell (one end of a piece of the delay).

    Returns
    -------
    (list, list, list) of IntervalAD
        The coefficients of P_G, Y_r and Y_i in ρ, constant term first; derivatives along τ_p.
    """
    Tp = IntervalAD.variable(tau_p[:, 0], tau_p[:, 1], 0, 1)
    xp = ratio_ad(Tp, H)
    f1p, p2p, p3p = phi_ad(xp)
    E = Tp.const(eps)
    y = (1.0 - E) * xp
    return predecessor_of({
        "K_x": Tp.const(kx), "K_v": Tp.const(kv), "K_a": Tp.const(ka), "Tp": Tp, "f1p": f1p,
        "p2p": p2p, "p3p": p3p, "ell1": phi_ad(y)[0],  # 1 − C
        "cm": exp_neg_ad(y) * phi_ad(E * xp)[0],  # C − E_p = C(1 − e^{−εH/τ_p}) ≥ 0
    }, H)


def follower_primitives(kx: Array, kv: Array, *, H: float, tau: Array,
                        headway: Array) -> dict[str, StackedAD]:
    """The primitives of F over cells of (τ, T*) in stacked arrays (:class:`StackedAD`).

    ``K_x``, ``Cc`` = K_v + T* K_x, ``T``, and φ1, ψ2, ψ3 of H/τ (``f1``, ``p2``, ``p3``):
    what :func:`follower_of` takes, and what the characteristic polynomial's δ0, δ1, δ2 are
    made of (:func:`stringstab.certify.robust_sampled`'s Schur box); derivatives along
    (τ, T*), the numbers of :func:`follower_terms`' IntervalAD arithmetic, bit for bit.

    Parameters
    ----------
    kx, kv : ndarray
        The gains, one per cell.
    H : float
        Sample time, s.
    tau, headway : ndarray, shape (n, 2)
        The cells' bounds of τ and T*.

    Returns
    -------
    dict of str to StackedAD
        ``K_x``, ``Cc``, ``T``, ``f1``, ``p2``, ``p3``.
    """
    T = StackedAD.variable(tau[:, 0], tau[:, 1], 0, 2)
    Th = StackedAD.variable(headway[:, 0], headway[:, 1], 1, 2)
    K_x, K_v = T.const(kx), T.const(kv)
    f1, p2, p3 = phi_stacked(ratio_stacked(T, H))[0]
    return {"K_x": K_x, "Cc": K_v + Th * K_x, "T": T, "f1": f1, "p2": p2, "p3": p3}


def follower_stacked(kx: Array, kv: Array, *, H: float, tau: Array,
                     headway: Array) -> list[StackedAD]:
    """:func:`follower_terms` in stacked arrays (:class:`StackedAD`): the same numbers, bit for bit.

    Parameters
    ----------
    kx, kv : ndarray
        The gains, one per cell.
    H : float
        Sample time, s.
    tau, headway : ndarray, shape (n, 2)
        The cells' bounds of τ and T*.

    Returns
    -------
    list of StackedAD
        The three coefficients of F in ρ (:func:`follower_of`); derivatives along (τ, T*).
    """
    return follower_of(follower_primitives(kx, kv, H=H, tau=tau, headway=headway), H)


def predecessor_stacked(kx: Array, kv: Array, ka: Array, *, H: float, tau_p: Array,
                        eps: Array) -> tuple[list[StackedAD], list[StackedAD], list[StackedAD]]:
    """:func:`predecessor_terms` in stacked arrays (:class:`StackedAD`), bit for bit.

    Parameters
    ----------
    kx, kv, ka : ndarray
        The gains, one per cell.
    H : float
        Sample time, s.
    tau_p : ndarray, shape (n, 2)
        The cells' bounds of τ_p.
    eps : ndarray, shape (n,)
        The fractional delay ε ∈ [0, 1] of each cell.

    Returns
    -------
    (list, list, list) of StackedAD
        The coefficients of P_G, Y_r and Y_i in ρ (:func:`predecessor_of`); along τ_p.
    """
    Tp = StackedAD.variable(tau_p[:, 0], tau_p[:, 1], 0, 1)
    xp = ratio_stacked(Tp, H)
    E = Tp.const(eps)
    y = (1.0 - E) * xp
    # φ of x_p, y and εx_p in one call (elementwise: the numbers of three calls)
    (f1p, p2p, p3p), (ell1, _, _), (phe, _, _) = phi_stacked(xp, y, E * xp)
    return predecessor_of({
        "K_x": Tp.const(kx), "K_v": Tp.const(kv), "K_a": Tp.const(ka), "Tp": Tp, "f1p": f1p,
        "p2p": p2p, "p3p": p3p, "ell1": ell1,  # 1 − C
        "cm": exp_neg_stacked(y) * phe,  # C − E_p
    }, H)


def _arrays(poly: list[Any], n: int) -> tuple[Array, Array]:
    """Point coefficients as arrays (n, 3): the values and their magnitudes (zero-padded)."""
    val, mag = np.zeros((n, 3)), np.zeros((n, 3))
    for j, v in enumerate(poly):
        val[:, j], mag[:, j] = v.lo, v.mag
    return val, mag


def follower_points(kx: Array, kv: Array, *, H: float, tau: Array,
                    headway: Array) -> tuple[Array, Array]:
    """F's coefficients at points (τ, T*), one per row, and their magnitudes.

    The point path of :func:`stringstab.certify.zoh.primitives` and :func:`follower_of`:
    what a screen of a box's members needs, without derivative enclosures.

    Parameters
    ----------
    kx, kv : ndarray, shape (n,)
        The gains, one per row.
    H : float
        Sample time, s.
    tau, headway : ndarray, shape (n,)
        The follower's τ and T* of each row.

    Returns
    -------
    (ndarray, ndarray)
        F's coefficients in ρ and their magnitudes, (n, 3) each.
    """
    c = kv + headway * kx
    q = primitives(kx, kv, kx, H=H, tau=(tau, tau), tau_p=(tau, tau), eps=(tau, tau), c=(c, c))
    return _arrays(follower_of(q, H), kx.size)


def predecessor_points(kx: Array, kv: Array, ka: Array, *, H: float, tau_p: Array,
                       eps: Array) -> tuple[Array, Array]:
    """P_G, Y_r, Y_i's coefficients at points (τ_p, ε), one per row, and their magnitudes.

    Parameters
    ----------
    kx, kv, ka : ndarray, shape (n,)
        The gains, one per row.
    H : float
        Sample time, s.
    tau_p, eps : ndarray, shape (n,)
        The predecessor's lag and the fractional delay of each row.

    Returns
    -------
    (ndarray, ndarray)
        The coefficients in ρ and their magnitudes, (n, 3, 3) each (polynomial, power).
    """
    q = primitives(kx, kv, ka, H=H, tau=(tau_p, tau_p), tau_p=(tau_p, tau_p), eps=(eps, eps),
                   c=(kv, kv))
    arrs = [_arrays(p, kx.size) for p in predecessor_of(q, H)]
    return np.stack([a[0] for a in arrs], axis=1), np.stack([a[1] for a in arrs], axis=1)


def delay_ends(d_lo: float, d_hi: float, H: float,
               pieces: list[tuple[int, float, float]]) -> list[tuple[int, float]]:
    """(m, ε) at the ends of the delay's pieces: where G is largest over δ (module docstring).

    The pieces (m, ε_lo, ε_hi) cover δ ∈ [d_lo, d_hi] (split at the multiples of H, ends
    widened by a few ulps: :mod:`stringstab.certify.robust_sampled`); a join of two pieces
    (ε = 1 at m, ε = 0 at m + 1: the same delay) is taken once, at m + 1.

    Parameters
    ----------
    d_lo, d_hi : float
        The delay interval, s.
    H : float
        Sample time, s.
    pieces : list of (int, float, float)
        (m, ε_lo, ε_hi) of each piece, in order.

    Returns
    -------
    list of (int, float)
        The ends (m, ε), in order of δ.

    Examples
    --------
    >>> delay_ends(0.15, 0.25, 0.1, [(1, 0.5, 1.0), (2, 0.0, 0.5)])
    [(1, 0.5), (2, 0.0), (2, 0.5)]
    """
    if d_hi == d_lo:
        return [split_delay(d_lo, H, whole=False)] if not pieces else [(pieces[0][0],
                                                                       pieces[0][1])]
    out: list[tuple[int, float]] = []
    for i, (m, e0, e1) in enumerate(pieces):
        if not out or out[-1] != (m, e0):
            out.append((m, e0))
        joined = i + 1 < len(pieces) and e1 == 1.0 and pieces[i + 1][1] == 0.0
        if not joined:
            out.append((m, e1))
    return out


# ---------------------------------------------------------------------------
# Bounds over cells at any θ
# ---------------------------------------------------------------------------
def vander(theta: Array) -> Array:
    """[1, ρ, ρ²] at θ (ρ = 4 sin²(θ/2)), shape (r, 3, k) for θ of shape (r, k).

    A polynomial of degree ≤ 2 in ρ with coefficients A (r, f, 3) is then ``A @ vander(θ)``,
    of shape (r, f, k): a0 + a1ρ + a2ρ², within a few ulps of (|a0| + |a1|ρ + |a2|ρ²)
    (ρ ≥ 0), as every evaluation the round-off slacks cover.

    Parameters
    ----------
    theta : ndarray, shape (r, k)
        Frequencies, rad/sample.

    Returns
    -------
    ndarray, shape (r, 3, k)
    """
    s = np.sin(0.5 * theta)
    rho = 4.0 * s * s
    return np.stack([np.ones_like(rho), rho, rho * rho], axis=1)


def follower_margins(F: Array, Fmag: Array, theta: Array) -> tuple[Array, Array]:
    """F at points (:func:`follower_points`) and its round-off slack, on one θ grid.

    Parameters
    ----------
    F, Fmag : ndarray, shape (..., 3)
        F's coefficients and magnitudes.
    theta : ndarray, shape (k,)
        Frequencies, rad/sample, shared by every point.

    Returns
    -------
    (ndarray, ndarray)
        F and its slack, of shape F.shape[:-1] + (k,).
    """
    Z = vander(theta[None, :])[0]  # (3, k)
    return F @ Z, ROUNDOFF_SLACK * (Fmag @ Z)


def predecessor_margins(G: Array, Gmag: Array, m: Array,
                        theta: Array) -> tuple[Array, Array]:
    """G at points (:func:`predecessor_points`) and its round-off slack, on one θ grid.

    Parameters
    ----------
    G, Gmag : ndarray, shape (..., 3, 3)
        P_G, Y_r, Y_i's coefficients and magnitudes.
    m : ndarray
        Whole samples of delay of each point (broadcast against G's ``...``).
    theta : ndarray, shape (k,)
        Frequencies, rad/sample, shared by every point.

    Returns
    -------
    (ndarray, ndarray)
        G and its slack, of shape G.shape[:-2] + (k,).
    """
    Z = vander(theta[None, :])[0]
    st = np.sin(theta)
    gv, gm = G @ Z, Gmag @ Z
    mm = np.asarray(m, dtype=float)
    ms, inv = np.unique(mm, return_inverse=True)  # cos mθ, sin mθ once per distinct m
    cm = np.cos(ms[:, None] * theta)[inv.reshape(mm.shape)]
    sm = (np.sin(ms[:, None] * theta) * st)[inv.reshape(mm.shape)]
    m1 = 1.0 + mm[..., None]
    g = gv[..., 0, :] + cm * gv[..., 1, :] + sm * gv[..., 2, :]
    gs = ROUNDOFF_SLACK * m1 * (gm[..., 0, :] + m1 * (gm[..., 1, :] + np.abs(st) * gm[..., 2, :]))
    return g, gs


def split_curvature(aF: Array, aG: Array, m: Array, L: Array, R: Array) -> Array:
    """M ≥ |(F − G)''| on [L, R] for every member, from each side's |coefficient| bounds.

    Parameters
    ----------
    aF : ndarray, shape (r, J)
        Bounds on |F's coefficients| over every follower cell of each row's item.
    aG : ndarray, shape (r, 3, J)
        Bounds on |P_G|, |Y_r|, |Y_i|'s coefficients over every predecessor cell.
    m : ndarray, shape (r,)
        The largest m of the predecessor cells (the bound increases with m).
    L, R : ndarray, shape (r, k)
        The intervals' ends, 0 ≤ L ≤ R ≤ π.

    Returns
    -------
    ndarray, shape (r, k)
        |F''| + |G''| bounded by :func:`stringstab.certify.sampled_curvature.curvature_bound`
        (F has no oscillating terms).
    """
    J = aF.shape[1]
    mF = curvature_bound([aF[:, j] for j in range(J)], [], [], np.zeros(aF.shape[0]), L, R)
    aP, aYr, aYi = ([aG[:, i, j] for j in range(J)] for i in range(3))
    mG = curvature_bound(aP, aYr, aYi, m, L, R)
    return np.asarray(mF + mG)
