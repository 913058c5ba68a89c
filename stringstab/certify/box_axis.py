r"""Internal stability over a box of τ, T*, θ_r: one stable member and no root on jℝ for any.

With a reaction delay θ_r the denominator of Γ is the retarded quasi-polynomial
(:mod:`stringstab.certify.quasipolynomial`)

.. math::
    D(s; p) = τs^3 + s^2 + e^{−θ_r s}(cs + k_x),\qquad c = k_v + T^*k_x,
    \qquad p = (τ, T^*, θ_r) ∈ B,

(δ does not enter D).  Every member of the box B is internally stable when

1. k_x > 0 (so D(0; p) = k_x ≠ 0 for every member),
2. one member p₀ ∈ B has no root in Re s ≥ 0 (the exact count of
   :func:`stringstab.certify.quasipolynomial.count_unstable_roots` is 0), and
3. no member has a root on the imaginary axis: |D(jω; p)| > 0 for every p ∈ B and ω > 0
   (conjugate symmetry covers ω < 0).

*Why* (docs/theory.md, "the reaction delay over a box"): for Re s ≥ 0, |e^{−θ_r s}| ≤ 1, so
|D(s; p)| ≥ τ_lo|s|³ − |s|² − c_max|s| − |k_x| > 0 once |s| ≥ R (one R for the whole box,
since τ ≥ τ_lo > 0).  The number N(p) of roots in the half disc {Re s ≥ 0, |s| < R} is the
winding number of D(·; p) along its boundary, which no root meets (none on jℝ by 3, none on
the arc by the choice of R).  That winding number is continuous in p (D is jointly continuous
in s and p and bounded away from 0 on the compact boundary × B), integer valued, and B is
connected: N is constant on B, and N(p₀) = 0 by 2.

Step 3 is proven by bisection of four-dimensional cells [ω_l, ω_h] × [τ] × [T*] × [θ_r]:
with m, p_c the centres and h, r the half-widths, the mean-value theorem term by term gives

.. math::
    |D(jω; p)| ≥ |D(jm; p_c)| − hL_ω − r_τ ω_h^3 − r_T|k_x|ω_h
                 − r_θ ω_h(|k_x| + c_{\max}ω_h) − E(m)

(|∂_τ D| = ω³, |∂_{T^*} D| = |k_x|ω, |∂_{θ_r} D| = ω|k_x + jcω|; L_ω = 3τ_hiω_h² + 2ω_h + c_max
+ θ_hi(c_max ω_h + |k_x|) bounds |∂_ω D| as in the point count; E the round-off bound of
:func:`stringstab.certify.quasipolynomial.denominator_at`).  A cell with a positive bound is
settled; the others are halved along the term that costs most.  Beyond Ω, the tail frequency
of the box's worst member (τ_lo and the largest |c|: the cubic of
:func:`stringstab.certify.quasipolynomial.tail_frequency` only grows with τ and shrinks with c²),
|P(jω)| > |Q(jω)| for every member, so D ≠ 0 there.

References
----------
Issue 25.  W. Michiels, S.-I. Niculescu, *Stability, Control, and Computation for Time-Delay
Systems*, 2nd ed., SIAM 2014, §1.2 (continuity of the roots of retarded quasi-polynomials).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..params import Box
from .quasipolynomial import denominator_at, tail_frequency

__all__ = ["AxisCheck", "axis_free", "box_tail"]

Array = npt.NDArray[np.float64]

#: Relative widening of the computed mean-value costs (they are sums of positive terms).
_COST_WIDEN = 1.0 + 1e-12


@dataclass
class AxisCheck:
    """Whether any member of a box has a root of D on jℝ, per triple.

    Attributes
    ----------
    free : ndarray of bool
        Proven: no member has a root on the imaginary axis (k_x > 0 was required).
    min_abs : ndarray
        The smallest |D(jω; p)| evaluated (the stated distance to the boundary).
    where : ndarray, shape (n, 4)
        (ω, τ, T*, θ_r) where it was met.
    n_evals : ndarray of int64
        Evaluations of D per triple.
    """

    free: npt.NDArray[np.bool_]
    min_abs: Array
    where: Array
    n_evals: npt.NDArray[np.int64]


def box_tail(kx: Array, kv: Array, box: Box) -> Array:
    """Ω with |Q(jω)| < |P(jω)| for every member of the box and every ω ≥ Ω.

    Parameters
    ----------
    kx, kv : ndarray
        Gains, k_x ≠ 0.
    box : Box
        τ, T*, θ_r intervals.

    Returns
    -------
    ndarray
        Ω, rad/s: the tail of the member (τ_lo, T* with the largest |c|) (module docstring).
    """
    h_lo, h_hi = box.headway
    h_worst = np.where(np.abs(kv + h_hi * kx) >= np.abs(kv + h_lo * kx), h_hi, h_lo)
    return tail_frequency(kx, kv, np.full(kx.size, box.tau[0]), h_worst)


def axis_free(kx: Array, kv: Array, box: Box, *, n_grid: int = 32, max_rounds: int = 60,
              max_cells: int = 8192) -> AxisCheck:
    """Prove |D(jω; p)| > 0 on (0, ∞) × box for each triple (step 3 of the module docstring).

    Parameters
    ----------
    kx, kv : ndarray, shape (n,)
        Gains, k_x > 0 (rows with k_x ≤ 0 are never free).
    box : Box
        τ, T*, θ_r intervals (δ is not used).
    n_grid : int
        Initial frequency intervals on [0, Ω].
    max_rounds : int
        Bisection rounds.
    max_cells : int
        Undecided cells per triple beyond which it is left unproven.

    Returns
    -------
    AxisCheck

    Examples
    --------
    >>> from stringstab.params import check_box
    >>> a = axis_free(np.array([1.0]), np.array([0.5]), check_box("0.1:0.2", 0.2, 1.1, "0.1:0.2"))
    >>> a.free.tolist()
    [True]
    """
    n = kx.size
    free = kx > 0
    failed = ~free
    min_abs, where = np.full(n, np.inf), np.full((n, 4), np.nan)
    n_evals = np.zeros(n, dtype=np.int64)
    live = np.flatnonzero(free)
    if live.size == 0:
        return AxisCheck(free & ~failed, min_abs, where, n_evals)
    Om = box_tail(kx[live], kv[live], box)
    u = np.linspace(0.0, 1.0, n_grid + 1)
    row = np.repeat(live, n_grid)
    wl = (Om[:, None] * u[None, :-1]).ravel()
    wh = (Om[:, None] * u[None, 1:]).ravel()
    # the parameter cells: rows 0-2 τ, T*, θ_r; lo and hi
    lo = np.array([box.tau[0], box.headway[0], box.reaction_delay[0]])[:, None].repeat(row.size, 1)
    hi = np.array([box.tau[1], box.headway[1], box.reaction_delay[1]])[:, None].repeat(row.size, 1)
    for rnd in range(max_rounds + 1):
        if row.size == 0:
            break
        k, v = kx[row], kv[row]
        pc = 0.5 * (lo + hi)
        r = np.maximum(hi - pc, pc - lo)
        m, h = 0.5 * (wl + wh), np.maximum(wh - 0.5 * (wl + wh), 0.5 * (wl + wh) - wl)
        D, E = denominator_at(m, k, v, pc[0], pc[1], pc[2])
        aD = np.abs(D)
        n_evals += np.bincount(row, minlength=n)
        order = np.argsort(aD)[::-1]  # the smallest last: it wins the scatter
        better = aD[order] < min_abs[row[order]]
        sel = order[better]
        min_abs[row[sel]] = aD[sel]
        where[row[sel]] = np.stack([m[sel], pc[0, sel], pc[1, sel], pc[2, sel]], axis=1)
        cmax = np.maximum(np.abs(v + lo[1] * k), np.abs(v + hi[1] * k))
        ak = np.abs(k)
        costs = np.stack([
            h * (3.0 * hi[0] * wh * wh + 2.0 * wh + cmax + hi[2] * (cmax * wh + ak)),
            r[0] * wh ** 3,
            r[1] * ak * wh,
            r[2] * wh * (ak + cmax * wh),
        ]) * _COST_WIDEN
        und = aD - costs.sum(axis=0) - E <= 0
        und &= ~failed[row]
        if not und.any():
            row = row[:0]
            break
        counts = np.bincount(row[und], minlength=n)
        over = counts > max_cells
        if rnd == max_rounds:
            over |= counts > 0
        failed |= over
        und &= ~over[row]
        row, wl, wh, lo, hi, costs = row[und], wl[und], wh[und], lo[:, und], hi[:, und], costs[:, und]
        dim = np.argmax(costs, axis=0)
        # halve each undecided cell along its costliest term
        row2 = np.concatenate([row, row])
        wl2, wh2 = np.concatenate([wl, wl]), np.concatenate([wh, wh])
        lo2, hi2 = np.concatenate([lo, lo], axis=1), np.concatenate([hi, hi], axis=1)
        j = np.arange(row.size)
        split_w = dim == 0
        mid_w = 0.5 * (wl + wh)
        wh2[:row.size] = np.where(split_w, mid_w, wh)
        wl2[row.size:] = np.where(split_w, mid_w, wl)
        for d in (1, 2, 3):
            s = j[dim == d]
            mid = 0.5 * (lo[d - 1, s] + hi[d - 1, s])
            hi2[d - 1, s] = mid
            lo2[d - 1, row.size + s] = mid
        row, wl, wh, lo, hi = row2, wl2, wh2, lo2, hi2
    if row.size:
        failed[np.unique(row)] = True
    return AxisCheck(free & ~failed, min_abs, where, n_evals)
