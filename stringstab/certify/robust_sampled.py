"""The robust certificate of the sampled-data loop over a box: bisection of parameter cells.

g_H of :func:`stringstab.certify.sampled_frequency.sampled_margin` has no closed-form minimum over a
box of τ, δ, T* (and the predecessor's lag τ_p), so the branch and bound of
:mod:`stringstab.certify.branch_bound` also splits the parameters: each item is a cell
(τ, τ_p, ε, T* intervals) whose coefficients are enclosed with derivative enclosures
(:func:`stringstab.certify.zoh.cell_coefficients`, the arithmetic of
:mod:`stringstab.certify.interval`), and g_H is bounded below over it by the better of the
interval extension and the mean-value form
(:func:`stringstab.certify.sampled_frequency.margin_over_cells`); a frequency interval where
the cell's width, not the curvature, prevents a decision is handed back and the cell is
bisected along the parameter that widens the bound most.  The delay enters as z^{−(m+1)}
with m = ⌊δ/H⌋, so the δ interval is split at the multiples of H and each piece is a
fractional-delay interval ε ∈ [ε_lo, ε_hi] ⊂ [0, 1] (continuous at the joins: ε = 1 at m
equals ε = 0 at m + 1).  The predecessor's lag τ_p ranges over the τ box independently
(``heterogeneous=True``) or equals τ.  Schur stability over (τ, T*) is decided by a
two-dimensional bisection on the interval-evaluated Schur conditions
(:func:`stringstab.certify.schur.schur_terms`).

The way in, the result types and the verdicts are those of :mod:`stringstab.certify.robust`.

References
----------
R. E. Moore, R. B. Kearfott, M. J. Cloud, *Introduction to Interval Analysis*, SIAM (2009).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ..params import Box
from . import branch_bound
from .excess import EXCESS_SEARCH, searched_excess
from .sampled_excess import peak_gain, violation_peak
from .sampled_frequency import margin_curvature, margin_over_cells, margin_spread
from .schur import SCHUR_RTOL, schur_terms
from .verdicts import CERTIFIED, INCONCLUSIVE, NOT_CERTIFIED, ROUNDOFF_SLACK
from .zoh import Coefficients, cell_coefficients, coefficients, split_delay

__all__ = ["certify_box_sampled"]

Array = npt.NDArray[np.float64]


@dataclass
class _Cells:
    """Cells of parameters, one row each: the triple owning it, m and the (n, 2) bounds."""

    owner: npt.NDArray[np.intp]
    m: Array
    t: Array  # (n, 2) τ interval
    tp: Array  # (n, 2) τ_p interval
    e: Array  # (n, 2) ε interval
    h: Array  # (n, 2) T* interval

    def __len__(self) -> int:
        return int(self.owner.size)

    def take(self, idx: npt.NDArray[np.intp]) -> _Cells:
        """The cells ``idx``."""
        return _Cells(self.owner[idx], self.m[idx], self.t[idx], self.tp[idx], self.e[idx],
                      self.h[idx])

    @staticmethod
    def cat(parts: list[_Cells]) -> _Cells:
        """The cells of ``parts``, one after the other."""
        return _Cells(*(np.concatenate([getattr(p, f) for p in parts])
                        for f in ("owner", "m", "t", "tp", "e", "h")))


def _delay_pieces(d_lo: float, d_hi: float, H: float) -> list[tuple[int, float, float]]:
    """(m, ε_lo, ε_hi) pieces covering δ ∈ [d_lo, d_hi] (ends widened by a few ulps)."""
    m_lo, e_lo = split_delay(d_lo, H, whole=False)  # the box's ends exactly: it covers them
    if d_hi == d_lo:
        return [(m_lo, e_lo, e_lo)]
    m_hi, e_hi = split_delay(d_hi, H, whole=False)
    tol = 8.0 * np.finfo(float).eps * (m_hi + 1.0)
    out = []
    for mm in range(m_lo, m_hi + 1):
        lo = e_lo if mm == m_lo else 0.0
        hi = e_hi if mm == m_hi else 1.0
        if mm == m_hi and hi == 0.0 and mm > m_lo:
            continue  # δ_hi on a multiple of H: the previous piece's ε = 1
        out.append((mm, max(lo - tol, 0.0), min(hi + tol, 1.0)))
    return out


def _cell_coeffs(kx: Array, kv: Array, ka: Array, c: _Cells, H: float,
                 heterogeneous: bool) -> Coefficients:
    """The coefficients of each cell with derivative enclosures (its owner's gains)."""
    o = c.owner
    return cell_coefficients(kx[o], kv[o], ka[o], H=H, tau=c.t,
                             tau_p=c.tp if heterogeneous else None, eps=c.e, headway=c.h)


def _halfwidths(c: _Cells, heterogeneous: bool) -> Array:
    """Half-widths of the cells, (n, d), in the order of :func:`_dims`."""
    cols = [c.t] + ([c.tp] if heterogeneous else []) + [c.e, c.h]
    return np.stack([0.5 * (x[:, 1] - x[:, 0]) for x in cols], axis=1)


def _dims(heterogeneous: bool) -> list[str]:
    """The cell fields in the order of :func:`stringstab.certify.zoh.cell_coefficients`."""
    return ["t", "tp", "e", "h"] if heterogeneous else ["t", "e", "h"]


def _bisect(c: _Cells, dim: npt.NDArray[np.intp], heterogeneous: bool) -> tuple[_Cells, Array]:
    """Split cell j in half along dimension ``dim[j]``; returns the children and parents."""
    names = _dims(heterogeneous)
    lo, hi = c.take(np.arange(len(c))), c.take(np.arange(len(c)))
    for k, name in enumerate(names):
        sel = dim == k
        if not sel.any():
            continue
        x = getattr(c, name)
        mid = 0.5 * (x[sel, 0] + x[sel, 1])
        a, b = getattr(lo, name), getattr(hi, name)
        a[sel, 1] = mid
        b[sel, 0] = mid
    if not heterogeneous:
        lo.tp, hi.tp = lo.t.copy(), hi.t.copy()
    parent = np.concatenate([np.arange(len(c)), np.arange(len(c))])
    return _Cells.cat([lo, hi]), parent


def _schur_box(kx: Array, kv: Array, box: Box, H: float, max_depth: int = 14) -> tuple[
        npt.NDArray[np.bool_], npt.NDArray[np.bool_], Array, Array]:
    """Schur stability of Δ over (τ, T*) ∈ box by bisection: (sure, fail, witness τ, T*).

    A cell is Schur when every condition's lower bound (natural interval extension or
    mean-value form, whichever is larger) exceeds a relative 10⁻¹² band; a condition
    below −band at a cell's centre is a witness member that is not Schur.
    """
    n = kx.size
    owner = np.arange(n)
    t = np.tile(np.array(box.tau, dtype=float), (n, 1))
    h = np.tile(np.array(box.headway, dtype=float), (n, 1))
    fail = np.zeros(n, dtype=bool)
    undecided = np.zeros(n, dtype=bool)
    wt = np.full(n, np.nan)
    wh = np.full(n, np.nan)
    for depth in range(max_depth + 1):
        if owner.size == 0:
            break
        z2 = np.zeros((owner.size, 2))
        co = cell_coefficients(kx[owner], kv[owner], np.zeros(owner.size), H=H, tau=t,
                                tau_p=None, eps=z2, headway=h)
        hw = np.stack([0.5 * (t[:, 1] - t[:, 0]), np.zeros(owner.size),
                       0.5 * (h[:, 1] - h[:, 0])], axis=1)
        ok = np.ones(owner.size, dtype=bool)
        bad = np.zeros(owner.size, dtype=bool)
        term: Any
        for term in schur_terms(co.delta):
            spread = sum((np.maximum(np.abs(g.lo), np.abs(g.hi)) + ROUNDOFF_SLACK * g.mag)
                         * hw[:, i] for i, g in enumerate(term.g))
            low = np.maximum(term.r.lo, term.c.lo - spread)
            ok &= low > SCHUR_RTOL * term.r.mag
            bad |= term.c.lo <= -SCHUR_RTOL * term.c.mag
        if bad.any():
            b_own = owner[bad]
            new = ~fail[b_own]
            fail[b_own] = True
            wt[b_own[new]] = t[bad][new].mean(axis=1)
            wh[b_own[new]] = h[bad][new].mean(axis=1)
        rest = ~ok & ~fail[owner]
        if not rest.any():
            break
        if depth == max_depth:
            undecided[np.unique(owner[rest])] = True
            break
        owner, t, h = owner[rest], t[rest], h[rest]
        tm, hm = t.mean(axis=1), h.mean(axis=1)
        t_wide, h_wide = t[:, 1] > t[:, 0], h[:, 1] > h[:, 0]
        parts = []
        for tl, tr in ((t[:, 0], tm), (tm, t[:, 1])):
            for hl, hr in ((h[:, 0], hm), (hm, h[:, 1])):
                parts.append((np.stack([tl, tr], 1), np.stack([hl, hr], 1)))
        # keep a half only along a dimension that has width
        sel = [np.ones(owner.size, bool), h_wide, t_wide, t_wide & h_wide]
        owner = np.concatenate([owner[k] for k in sel])
        t = np.concatenate([p[0][k] for p, k in zip(parts, sel)])
        h = np.concatenate([p[1][k] for p, k in zip(parts, sel)])
    sure = ~fail & ~undecided
    return sure, fail, wt, wh


def certify_box_sampled(kx: Array, kv: Array, ka: Array, box: Box, H: float, *,
                        heterogeneous: bool, n_grid: int | None, max_rounds: int,
                        max_intervals: int, max_splits: int, max_cells: int) -> dict[str, Array]:
    """The robust certificate of the sampled loop over a box, for a chunk of gain triples.

    Schur stability over (τ, T*) by bisection, then the branch and bound of g_H ≥ 0 on
    [0, π] over cells of (τ, τ_p, ε, T*) (module docstring), bisecting a cell where its
    width, not the frequency interval, prevents a decision.

    Parameters
    ----------
    kx, kv, ka : ndarray, shape (n,)
        The gains (validated, finite).
    box : Box
        τ, δ, T* intervals (validated).
    H : float
        Sample time, s.
    heterogeneous : bool
        The predecessor's lag ranges over the τ box independently (else it equals τ).
    n_grid : int or None
        Initial frequency intervals (None: 64 + 8 m at the box's largest m).
    max_rounds, max_intervals : int
        Branch-and-bound budgets per pass.
    max_splits, max_cells : int
        Bisection passes of the cells, and cells per triple, before it is inconclusive.

    Returns
    -------
    dict of str to ndarray
        ``verdict`` (codes of :mod:`stringstab.certify.verdicts`), ``stable``, ``margin``,
        the witness member (``tau``, ``tau_prev``, ``delta``, ``headway``) and frequency
        (``theta``, ``omega``), ``n_evals``, ``sup_gain`` and ``sup_gain_excess``.
    """
    n = kx.size
    sure, fail, wt, wh = _schur_box(kx, kv, box, H)
    pieces = _delay_pieces(*box.delta, H)
    live0 = np.flatnonzero(~fail)  # an undecided Schur band still looks for a witness
    tau2 = np.array(box.tau, dtype=float)
    cells = _Cells.cat([
        _Cells(live0, np.full(live0.size, float(mm)), np.tile(tau2, (live0.size, 1)),
               np.tile(tau2, (live0.size, 1)), np.tile(np.array([e0, e1]), (live0.size, 1)),
               np.tile(np.array(box.headway, dtype=float), (live0.size, 1)))
        for mm, e0, e1 in pieces])
    grid = n_grid or (64 + 8 * max(p[0] for p in pieces))
    status = np.full(n, CERTIFIED, dtype=np.int8)
    status[~sure] = np.where(fail[~sure], NOT_CERTIFIED, INCONCLUSIVE)
    active = ~fail
    margin = np.full(n, np.inf)
    wit = {k: np.full(n, np.nan) for k in ("theta", "m", "t", "tp", "e", "h")}
    n_evals = np.zeros(n, dtype=np.int64)
    n_cells = np.bincount(cells.owner, minlength=n)
    intervals: tuple[npt.NDArray[np.intp], Array, Array] | None = None
    for split_round in range(max_splits + 1):
        if len(cells) == 0:
            break
        co = _cell_coeffs(kx, kv, ka, cells, H, heterogeneous)
        hw_c = _halfwidths(cells, heterogeneous)
        wide = ((cells.t[:, 1] > cells.t[:, 0]) | (cells.tp[:, 1] > cells.tp[:, 0])
                | (cells.e[:, 1] > cells.e[:, 0]) | (cells.h[:, 1] > cells.h[:, 0]))
        can_split = wide & (split_round < max_splits)
        m_c = cells.m

        def evaluate(idx: npt.NDArray[np.intp], X: Array, co: Any = co, hw_c: Array = hw_c,
                     m_c: Array = m_c) -> tuple[Array, Array, Array, Array]:
            sub = co.take(idx)
            G, low, E = margin_over_cells(X, sub, m_c[idx], hw_c[idx])
            M = margin_curvature(sub.map(lambda v: v.r), m_c[idx], X[:, :-1], X[:, 1:])
            return G, np.minimum(low, G), E, M

        def hold(idx: npt.NDArray[np.intp], L: Array, R: Array, low_gap: Array, curv: Array,
                 can_split: npt.NDArray[np.bool_] = can_split) -> npt.NDArray[np.bool_]:
            # the cell's width, not the frequency interval, prevents a decision: bisect it
            return np.asarray(can_split[idx] & (low_gap > curv))

        if intervals is None:
            bb = branch_bound.branch_and_bound(len(cells), evaluate,
                                               right=np.full(len(cells), np.pi), n_grid=grid,
                                               max_rounds=max_rounds,
                                               max_intervals=max_intervals, hold=hold)
        else:
            bb = branch_bound.branch_and_bound(len(cells), evaluate, intervals=intervals,
                                               max_rounds=max_rounds,
                                               max_intervals=max_intervals, hold=hold)
        np.add.at(n_evals, cells.owner, bb.n_evals)
        # the smallest point value per triple, and the member where it was found
        order = np.lexsort((bb.minimum, cells.owner))
        own, first = np.unique(cells.owner[order], return_index=True)
        best = order[first]
        upd = bb.minimum[best] < margin[own]
        o, b = own[upd], best[upd]
        margin[o] = bb.minimum[b]
        wit["theta"][o] = bb.argmin[b]
        wit["m"][o] = cells.m[b]
        for k in ("t", "tp", "e", "h"):
            wit[k][o] = getattr(cells, k)[b].mean(axis=1)
        viol = np.unique(cells.owner[bb.status == NOT_CERTIFIED])
        status[viol] = NOT_CERTIFIED
        active[viol] = False
        decided = (CERTIFIED, NOT_CERTIFIED, branch_bound.PENDING)
        inc = np.unique(cells.owner[np.isin(bb.status, decided, invert=True)])
        inc = inc[status[inc] != NOT_CERTIFIED]
        status[inc] = INCONCLUSIVE
        active[inc] = False
        # hand-backs: bisect their cells; each child inherits its parent's held intervals
        pi, pl, ph = bb.pending_item, bb.pending_lo, bb.pending_hi
        sel = active[cells.owner[pi]]
        pi, pl, ph = pi[sel], pl[sel], ph[sel]
        if pi.size == 0:
            break
        ucell, inv = np.unique(pi, return_inverse=True)
        # bisect each cell along the parameter that widens its bound most where it failed
        Xp = np.stack([pl, ph], axis=1)
        sp = margin_spread(Xp, co.take(pi), cells.m[pi], hw_c[pi]).max(axis=1)  # (k, d)
        worst_dim = np.zeros((ucell.size, sp.shape[1]))
        np.maximum.at(worst_dim, inv, sp)
        kids, parent = _bisect(cells.take(ucell), np.argmax(worst_dim, axis=1), heterogeneous)
        n_cells += np.bincount(kids.owner, minlength=n)
        over = active & (n_cells > max_cells)
        status[over] = INCONCLUSIVE
        active[over] = False
        # the held intervals of each parent, repeated for each of its children
        order = np.argsort(inv, kind="stable")
        starts = np.concatenate([[0], np.cumsum(np.bincount(inv, minlength=ucell.size))[:-1]])
        counts = np.bincount(inv, minlength=ucell.size)[parent]
        kid = np.repeat(np.arange(len(kids)), counts)
        offs = np.arange(kid.size) - np.repeat(np.cumsum(counts) - counts, counts)
        src = order[starts[parent][kid] + offs]
        live = active[kids.owner[kid]]
        cells = kids
        intervals = (kid[live].astype(np.intp), pl[src][live], ph[src][live])
    # members and frequencies of the witnesses; the unstable member when Schur fails
    tau_w = np.where(fail, wt, wit["t"])
    taup_w = np.where(fail, wt, wit["tp"])
    h_w = np.where(fail, wh, wit["h"])
    d_w = np.where(fail, box.delta[0], (wit["m"] + wit["e"]) * H)
    theta = np.where(fail, np.nan, wit["theta"])
    sup = np.where(status == CERTIFIED, 1.0, np.where(fail, np.inf, np.nan))
    need = np.isnan(sup) & np.isfinite(tau_w)
    for mm in np.unique(wit["m"][need]):
        idx = np.flatnonzero(need & (wit["m"] == mm))
        e_i = wit["e"][idx]
        cc = kv[idx] + h_w[idx] * kx[idx]
        co = coefficients(kx[idx], kv[idx], ka[idx], H=H, tau=(tau_w[idx], tau_w[idx]),
                          tau_p=(taup_w[idx], taup_w[idx]), eps=(e_i, e_i), c=(cc, cc))
        ng = 65 + 8 * int(mm)
        th_grid = np.broadcast_to(np.linspace(0.0, np.pi, ng), (idx.size, ng))
        sup[idx], theta[idx] = peak_gain(co, int(mm), ka[idx], th_grid, theta[idx])
    out = {"verdict": status, "stable": sure, "margin": margin, "theta": theta,
           "tau": tau_w, "tau_prev": taup_w, "delta": d_w, "headway": h_w,
           "n_evals": n_evals, "sup_gain_excess": sup - 1.0}
    small_ = (status == NOT_CERTIFIED) & sure & need & (sup - 1.0 < EXCESS_SEARCH)
    for mm in np.unique(wit["m"][small_]):
        idx = np.flatnonzero(small_ & (wit["m"] == mm))
        e_i = wit["e"][idx]
        cc = kv[idx] + h_w[idx] * kx[idx]
        co = coefficients(kx[idx], kv[idx], ka[idx], H=H, tau=(tau_w[idx], tau_w[idx]),
                          tau_p=(taup_w[idx], taup_w[idx]), eps=(e_i, e_i), c=(cc, cc))
        kappa = tau_w[idx] * taup_w[idx] / H**3
        e2, th = violation_peak(co, int(mm), kappa, np.stack([theta[idx], wit["theta"][idx]], 1))
        e1, take = searched_excess(e2, out["sup_gain_excess"][idx])
        out["sup_gain_excess"][idx] = np.where(take, e1, out["sup_gain_excess"][idx])
        out["theta"][idx] = np.where(take, th, out["theta"][idx])
        sup[idx] = np.where(take, 1.0 + e1, sup[idx])
    out["omega"] = out["theta"] / H
    out["sup_gain"] = sup
    return out
