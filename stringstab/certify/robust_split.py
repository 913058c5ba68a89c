"""The branch and bound of the split margin F − G ≥ 0 over cells refined where they limit it.

The robust certificate of the sampled loop over a box (:mod:`stringstab.certify.robust_sampled`)
asks, for each gain triple, whether F(θ; τ, T*) ≥ G(θ; τ_p, δ) for every member and every
θ ∈ [0, π] (:mod:`stringstab.certify.sampled_split`).  :func:`screen_members` first tries the
members made of the centres of 2 × 2 cells on the certificate's grid of θ: most triples that
are not certified violate there, and a violation at a member is a witness.  :func:`split_search`
then runs the branch and bound of :mod:`stringstab.certify.branch_bound` on θ with, at each θ,
the lower bound min F over the follower cells minus max G over the predecessor cells
(:mod:`stringstab.certify.sampled_split_cells`) — or, with τ_p = τ, per follower cell its F
minus the maximum of G over its own τ — and the point value of the member made of the
centres where F is smallest and G largest.  A frequency interval the cells' width, not its
own, leaves undecided is handed back; the cells whose bounds are in the looser half of the
gap at its midpoint are halved, and the triple goes on with its undecided intervals.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ..params import Box
from . import branch_bound
from .sampled_split import (
    delay_ends,
    follower_margins,
    follower_points,
    predecessor_margins,
    predecessor_points,
    split_curvature,
    vander,
)
from .sampled_split_cells import CellCache, FollowerCells, PredecessorCells
from .verdicts import CERTIFIED, INCONCLUSIVE, NOT_CERTIFIED

__all__ = ["screen_members", "split_search"]

Array = npt.NDArray[np.float64]

#: Cells per side of (τ, T*) (and of τ_p) the split search's bounds start from, and the
#: frequency intervals of its first pass on [0, π] (the screen of the cells' centres uses the
#: certificate's grid, 64 + 8m).
_FIRST_CELLS = 3
_BOUND_GRID = 32
#: A cell is halved when its bound lies in this (lower) share of the gap between the best
#: bound and the best centre value of its side, at the end of a held interval.
_LOOSE = 0.5


def _grid(lo: float, hi: float, k: int) -> Array:
    """k equal cells [e_i, e_{i+1}] of [lo, hi] as a (k, 2) array (one cell for a point)."""
    e = np.linspace(lo, hi, k + 1)
    return np.stack([e[:-1], e[1:]], axis=1)


def _csr(owner: npt.NDArray[np.intp], n: int) -> tuple[npt.NDArray[np.intp], npt.NDArray[np.intp]]:
    """(start, count) of each of n owners in an array sorted by owner."""
    count = np.bincount(owner, minlength=n)
    return np.cumsum(count) - count, count


def _pairs(start: npt.NDArray[np.intp], count: npt.NDArray[np.intp],
           rows: npt.NDArray[np.intp]) -> tuple[npt.NDArray[np.intp], npt.NDArray[np.intp],
                                                npt.NDArray[np.intp]]:
    """Every (row, cell) pair of the owners ``rows``: the pairs' rows and cells, and row starts."""
    cnt = count[rows]
    off = np.cumsum(cnt) - cnt
    pr = np.repeat(np.arange(rows.size), cnt)
    pc = np.repeat(start[rows] - off, cnt) + np.arange(pr.size)
    return pr, pc, off


def _first_min(v: Array, vmin: Array, pr: npt.NDArray[np.intp],
               off: npt.NDArray[np.intp]) -> npt.NDArray[np.intp]:
    """For each row, the first of its pairs whose value ``v`` is the row's minimum ``vmin``."""
    at = np.where(v == vmin[pr], np.arange(v.size), v.size)
    return np.asarray(np.minimum.reduceat(at, off))


def _among(values: npt.NDArray[np.intp], members: npt.NDArray[np.intp]) -> npt.NDArray[np.bool_]:
    """``np.isin(values, members)`` for indices ≥ 0, by a table (no sort)."""
    size = 1 + max(int(values.max(initial=-1)), int(members.max(initial=-1)))
    table = np.zeros(size, dtype=bool)
    table[members] = True
    return table[values]


@dataclass
class _Split:
    """The cells of the split search: follower cells by item, predecessor cells by owner."""

    F: FollowerCells
    G: PredecessorCells

    def sort(self, heterogeneous: bool) -> _Split:
        """Cells sorted by owner (the predecessor cells follow their follower cell when tied)."""
        fo = np.argsort(self.F.owner, kind="stable")
        F = self.F.take(fo)
        if heterogeneous:
            return _Split(F, self.G.take(np.argsort(self.G.owner, kind="stable")))
        new = np.empty(fo.size, dtype=np.intp)
        new[fo] = np.arange(fo.size)  # follower cell renumbering
        G = self.G
        G.owner = new[G.owner]
        return _Split(F, G.take(np.argsort(G.owner, kind="stable")))


def _pred_of(F: FollowerCells, cells: npt.NDArray[np.intp], first: int, kx: Array, kv: Array,
             ka: Array, H: float, ends: list[tuple[int, float]],
             cache: CellCache | None = None) -> PredecessorCells:
    """τ_p = τ: the predecessor cells of the follower cells ``cells`` (numbered from ``first``)."""
    E = len(ends)
    own = np.repeat(np.arange(cells.size) + first, E)
    gains, tau_p = F.owner[np.repeat(cells, E)], np.repeat(F.tau[cells], E, axis=0)
    end = np.tile(np.arange(E), cells.size)
    if cache is not None:
        return cache.predecessor(own, gains, tau_p, end)
    return PredecessorCells.of(own, gains, kx, kv, ka, H=H, tau_p=tau_p, end=end, ends=ends)


def screen_members(kx: Array, kv: Array, ka: Array, H: float, box: Box,
                   ends: list[tuple[int, float]], e_delta: Array, grid: int,
                   heterogeneous: bool) -> tuple[npt.NDArray[np.bool_], Array, Array,
                                                 npt.NDArray[np.int64]]:
    """F − G at the members made of the centres of 2 × 2 cells, on a grid of [0, π].

    The members: (τ, T*) at the centres of the 2 × 2 cells of their box, τ_p at the centres
    of the 2 cells of its box (or τ_p = τ), δ at the ends of the delay's pieces; the value at
    θ is min F − max G over them (heterogeneous) or, with τ_p = τ, the worst τ of min over T*
    of F − max over the delay of G.  A value below −slack is a member with |H| > 1 there.

    Parameters
    ----------
    kx, kv, ka : ndarray, shape (n,)
        The gains (checked).
    H : float
        Sample time, s.
    box : Box
        τ, δ, T* intervals.
    ends : list of (int, float)
        The ends (m, ε) of the delay's pieces (:func:`~stringstab.certify.sampled_split.delay_ends`).
    e_delta : ndarray
        δ of each end, s (clipped to the box).
    grid : int
        Intervals of the uniform grid on [0, π].
    heterogeneous : bool
        τ_p ranges over the τ box independently (else τ_p = τ).

    Returns
    -------
    violated : ndarray of bool, shape (n,)
        Some member violates.
    best : ndarray, shape (n, 5)
        The member with the smallest value: θ, τ, T*, τ_p, δ.
    value : ndarray, shape (n,)
        That value of F − G.
    n_evals : ndarray of int, shape (n,)
        Evaluations (points × members).
    """
    n, E = kx.size, len(ends)
    (t_lo, t_hi), (h_lo, h_hi) = box.tau, box.headway
    t = _grid(t_lo, t_hi, 2 if t_hi > t_lo else 1).mean(axis=1)
    h = _grid(h_lo, h_hi, 2 if h_hi > h_lo else 1).mean(axis=1)
    nt, nh = t.size, h.size
    eps = np.array([e[1] for e in ends])
    m = np.array([float(e[0]) for e in ends])
    # follower points (τ_i, T*_j), τ-major; predecessor points (τ_p = τ_i, end e), τ-major
    ft, fh = np.repeat(t, nh), np.tile(h, nt)
    gt, ge, gm = np.repeat(t, E), np.tile(eps, nt), np.tile(m, nt)
    nf, ng = ft.size, gt.size
    X = np.linspace(0.0, np.pi, grid + 1)
    k = X.size
    viol = np.zeros(n, dtype=bool)
    val, wrow = np.full(n, np.inf), np.zeros((n, 5))
    # triples per chunk: one chunk for a few hundred (each chunk's point arithmetic is a few
    # hundred small-array operations whatever its size; the values are the same in any
    # chunking: elementwise, and one product per triple and member)
    step = max(1, 250_000 // ((nf + ng) * k))
    for s in range(0, n, step):
        q = np.arange(s, min(s + step, n))
        r = q.size
        fi, gi = np.repeat(q, nf), np.repeat(q, ng)
        Ff, Fm = follower_points(kx[fi], kv[fi], H=H, tau=np.tile(ft, r), headway=np.tile(fh, r))
        Gg, Gm = predecessor_points(kx[gi], kv[gi], ka[gi], H=H, tau_p=np.tile(gt, r),
                                    eps=np.tile(ge, r))
        f, fs = follower_margins(Ff.reshape(r, nf, 3), Fm.reshape(r, nf, 3), X)
        g, gs = predecessor_margins(Gg.reshape(r, ng, 3, 3), Gm.reshape(r, ng, 3, 3), gm, X)
        if heterogeneous:
            jf, jg = f.argmin(axis=1), g.argmax(axis=1)
            pv = f.min(axis=1) - g.max(axis=1)
        else:  # per τ: min over T* minus max over the delay's ends, then the worst τ
            f4, g4 = f.reshape(r, nt, nh, k), g.reshape(r, nt, E, k)
            col = f4.min(axis=2) - g4.max(axis=2)
            jt = col.argmin(axis=1)
            ri, ki = np.arange(r)[:, None], np.arange(k)[None, :]
            jf = jt * nh + f4.argmin(axis=2)[ri, jt, ki]
            jg = jt * E + g4.argmax(axis=2)[ri, jt, ki]
            pv = col.min(axis=1)
        sl = fs.max(axis=1) + gs.max(axis=1)
        viol[q] = (pv < -sl).any(axis=1)
        kk = pv.argmin(axis=1)
        rr = np.arange(r)
        val[q] = pv[rr, kk]
        jf, jg = jf[rr, kk], jg[rr, kk]
        wrow[q] = np.stack([X[kk], ft[jf], fh[jf], gt[jg], e_delta[jg % E]], axis=1)
    return viol, wrow, val, np.full(n, k * (nf + ng), dtype=np.int64)


def split_search(kx: Array, kv: Array, ka: Array, box: Box, H: float,
                 live: npt.NDArray[np.intp], pieces: list[tuple[int, float, float]], *,
                 heterogeneous: bool, grid: int, max_rounds: int, max_intervals: int,
                 max_splits: int, max_cells: int) -> dict[str, Array]:
    """The branch and bound of F − G ≥ 0 over cells refined where they limit the bound.

    :func:`screen_members` first; then, for the triples that pass it, 3 × 3 follower cells
    of (τ, T*) (one along a dimension of no width) and the 3 cells of τ_p at each end of a
    piece of the delay (with τ_p = τ, each follower cell has its own predecessor cells over
    its τ), and the branch and bound on θ (module docstring).  A frequency interval the cells'
    width, not its own, leaves undecided is handed back; the cells whose bounds are in the
    looser half of the gap at its midpoint are halved (follower cells along the parameter
    whose width costs the bound most there), and the triple goes on with its undecided
    intervals.

    Parameters
    ----------
    kx, kv, ka : ndarray, shape (n,)
        The gains (checked).
    box : Box
        τ, δ, T* intervals.
    H : float
        Sample time, s.
    live : ndarray of int
        The triples to search (those not surely unstable).
    pieces : list of (int, float, float)
        (m, ε_lo, ε_hi) of the delay's pieces.
    heterogeneous : bool
        τ_p ranges over the τ box independently (else τ_p = τ).
    grid : int
        Intervals of the screen's grid on [0, π].
    max_rounds, max_intervals : int
        Branch-and-bound budgets per pass.
    max_splits, max_cells : int
        Refinement passes, and cells per triple, before a triple is inconclusive.

    Returns
    -------
    dict of str to ndarray
        ``code`` (verdict codes; CERTIFIED for the triples not searched), ``value`` (the
        smallest F − G found), the member where it was found (``theta``, ``t``, ``tp``,
        ``d``, ``h``) and ``n_evals`` (evaluations of a cell or member at a frequency).
    """
    n = kx.size
    code = np.full(n, CERTIFIED, dtype=np.int8)
    best = np.full(n, np.inf)
    wit = {k: np.full(n, np.nan) for k in ("theta", "t", "tp", "d", "h")}
    n_evals = np.zeros(n, dtype=np.int64)
    ends = delay_ends(*box.delta, H, pieces)
    E = len(ends)
    e_delta = np.clip([(m + e) * H for m, e in ends], *box.delta)
    (t_lo, t_hi), (h_lo, h_hi) = box.tau, box.headway
    t_w, h_w = t_hi - t_lo, h_hi - h_lo
    items = np.asarray(live, dtype=np.intp)  # local item i is the triple items[i]
    ni = items.size
    if ni == 0:
        return {"code": code, "value": best, **wit, "n_evals": n_evals}
    gx, gv, ga = kx[items], kv[items], ka[items]
    cache = CellCache(gx, gv, ga, H, ends)
    def initial(own: npt.NDArray[np.intp], k: int) -> _Split:
        """k × k follower cells and k cells of τ_p per end of the delay, for the items ``own``."""
        nt, nh = (k if t_w > 0 else 1), (k if h_w > 0 else 1)
        tc, hc = _grid(t_lo, t_hi, nt), _grid(h_lo, h_hi, nh)
        F = FollowerCells.of(np.repeat(own, nt * nh), gx, gv, H=H,
                             tau=np.tile(np.repeat(tc, nh, axis=0), (own.size, 1)),
                             headway=np.tile(np.tile(hc, (nt, 1)), (own.size, 1)))
        if not heterogeneous:
            return _Split(F, _pred_of(F, np.arange(len(F)), 0, gx, gv, ga, H, ends))
        g_own = np.repeat(own, nt * E)
        return _Split(F, PredecessorCells.of(g_own, g_own, gx, gv, ga, H=H,
                                             tau_p=np.tile(np.repeat(tc, E, axis=0), (own.size, 1)),
                                             end=np.tile(np.arange(E), own.size * nt), ends=ends))

    # the members at the centres of 2 × 2 cells first, on the certificate's grid: most triples
    # that are not certified violate there (a witness), at a fraction of the bounds' cost
    viol, w0, v0, n0 = screen_members(gx, gv, ga, H, box, ends, e_delta, grid, heterogeneous)
    n_evals[items] += n0
    best[items] = v0
    for j, key in enumerate(("theta", "t", "h", "tp", "d")):
        wit[key][items] = w0[:, j]
    code[items[viol]] = NOT_CERTIFIED
    act = np.flatnonzero(~viol)  # the items of this pass (the branch and bound's items)
    # the bounds need finer cells than 2 × 2 to say anything: start from 3 × 3
    cells = initial(act, _FIRST_CELLS)
    intervals: tuple[npt.NDArray[np.intp], Array, Array] | None = None
    can_split = (t_w > 0) or (h_w > 0)
    for split_round in range(max_splits + 1):
        if act.size == 0:
            break
        F, G = cells.F, cells.G
        f_start, f_count = _csr(F.owner, ni)
        g_item = G.owner if heterogeneous else F.owner[G.owner]
        g_start, g_count = _csr(G.owner, ni if heterogeneous else len(F))
        # per item, the largest coefficients over its cells (curvature) and the largest m
        aF = np.zeros((ni, F.a.shape[1]))
        np.maximum.at(aF, F.owner, F.a)
        aG = np.zeros((ni, *G.a.shape[1:]))
        np.maximum.at(aG, g_item, G.a)
        mG = np.zeros(ni)
        np.maximum.at(mG, g_item, G.m)
        # and the largest magnitudes (the round-off slacks, per item rather than per cell)
        env = [np.zeros((ni, *x.shape[1:])) for x in (F.mag, F.gmag, G.mag, G.gmag)]
        for e_, own_, x in zip(env, (F.owner, F.owner, g_item, g_item),
                               (F.mag, F.gmag, G.mag, G.gmag)):
            np.maximum.at(e_, own_, x)
        refine = can_split and split_round < max_splits
        lbest = np.full(act.size, np.inf)
        lwit = np.full((act.size, 5), np.nan)  # θ, τ, T*, τ_p, δ

        def evaluate(idx: npt.NDArray[np.intp], X: Array, F: FollowerCells = F,
                     G: PredecessorCells = G, f_start: Any = f_start, f_count: Any = f_count,
                     g_start: Any = g_start, g_count: Any = g_count, aF: Array = aF,
                     aG: Array = aG, mG: Array = mG, lbest: Array = lbest,
                     lwit: Array = lwit, act: Any = act,
                     env: list[Array] = env) -> tuple[Array, Array, Array, Array]:
            it = act[idx]
            point, low, slack = (np.empty_like(X) for _ in range(3))
            wrow = np.empty((X.shape[0], 5))
            per = f_count[it] * (1 if heterogeneous else E) + (g_count[it] if heterogeneous
                                                                 else 0)
            cum = np.cumsum(per * X.shape[1])
            s = 0
            while s < X.shape[0]:
                e = int(np.searchsorted(cum, (cum[s - 1] if s else 0) + 60_000, "right"))
                e = max(e, s + 1)
                sl = slice(s, e)
                _evaluate_rows(it[sl], X[sl], F, G, f_start, f_count, g_start, g_count,
                               heterogeneous, E, e_delta, point[sl], low[sl], slack[sl],
                               wrow[sl], [x[it[sl]] for x in env] + [mG[it[sl]]])
                s = e
            v = point[np.arange(X.shape[0]), point.argmin(axis=1)]
            order = np.lexsort((v, idx))
            own, first = np.unique(idx[order], return_index=True)
            b = order[first]
            upd = v[b] < lbest[own]
            lbest[own[upd]] = v[b[upd]]
            lwit[own[upd]] = wrow[b[upd]]
            M = split_curvature(aF[it], aG[it], mG[it], X[:, :-1], X[:, 1:])
            return point, np.minimum(low, point), slack, M

        def hold(idx: npt.NDArray[np.intp], L: Array, R: Array, low_gap: Array, curv: Array,
                 refine: bool = refine) -> npt.NDArray[np.bool_]:
            # the cells' width, not the frequency interval, prevents a decision: refine them
            return np.asarray((low_gap > curv) & refine)

        if intervals is None:
            bb = branch_bound.branch_and_bound(act.size, evaluate, right=np.full(act.size, np.pi),
                                               n_grid=_BOUND_GRID, max_rounds=max_rounds,
                                               max_intervals=max_intervals, hold=hold)
        else:
            bb = branch_bound.branch_and_bound(act.size, evaluate, intervals=intervals,
                                               max_rounds=max_rounds,
                                               max_intervals=max_intervals, hold=hold)
        cells_now = f_count[act] * (1 + (0 if heterogeneous else E)) + (
            g_count[act] if heterogeneous else 0)
        n_evals[items[act]] += bb.n_evals * cells_now
        upd = lbest < best[items[act]]
        o = items[act[upd]]
        best[o] = lbest[upd]
        for j, key in enumerate(("theta", "t", "h", "tp", "d")):
            wit[key][o] = lwit[upd, j]
        code[items[act[bb.status == NOT_CERTIFIED]]] = NOT_CERTIFIED
        code[items[act[bb.status == INCONCLUSIVE]]] = INCONCLUSIVE
        pend = np.unique(bb.pending_item)
        if pend.size == 0:
            break
        cells, over = _refine(cells, act, bb, kx=gx, kv=gv, ka=ga, H=H, ends=ends,
                              heterogeneous=heterogeneous, widths=(t_w, h_w),
                              max_cells=max_cells, e_delta=e_delta, cache=cache)
        code[items[act[over]]] = INCONCLUSIVE
        keep = ~over[bb.pending_item]
        nxt = np.setdiff1d(pend, np.flatnonzero(over))
        intervals = (np.searchsorted(nxt, bb.pending_item[keep]).astype(np.intp),
                     bb.pending_lo[keep], bb.pending_hi[keep])
        act = act[nxt]
        if act.size == 0:
            break
        cells = _keep(cells, act, heterogeneous)
    return {"code": code, "value": best, **wit, "n_evals": n_evals}


def _trig(X: Array, rows: npt.NDArray[np.intp], m: Array) -> tuple[Array, Array]:
    """cos(mθ) and sin(mθ) sin θ for pairs (row of X, m), computed once per row and m."""
    ms, inv = np.unique(m, return_inverse=True)
    mX = ms[None, :, None] * X[:, None, :]  # (r, distinct m, k)
    return np.cos(mX)[rows, inv], (np.sin(mX) * np.sin(X)[:, None, :])[rows, inv]


def _evaluate_rows(it: npt.NDArray[np.intp], X: Array, F: FollowerCells, G: PredecessorCells,
                   f_start: Any, f_count: Any, g_start: Any, g_count: Any, heterogeneous: bool,
                   E: int, e_delta: Array, point: Array, low: Array, slack: Array,
                   wrow: Array, env: list[Array]) -> None:
    """Point values, lower bounds, slacks and the best members of rows of items ``it`` at X.

    ``env``: per row, the largest magnitudes over the item's cells (F's value and gradients,
    G's value and gradient) and the largest m: the round-off slacks, once per row.
    """
    pr, pc, off = _pairs(f_start, f_count, it)
    r, k = X.shape
    rr = np.arange(r)
    Z = vander(X)
    fs = FollowerCells.slacks(env[0], env[1], Z)
    gs = PredecessorCells.slacks(env[2], env[3], env[4], X, Z)
    FC, FL, FE = F.bounds(pc, Z[pr], slack=(fs[0][pr], fs[1][pr]))
    if heterogeneous:
        qr, qc, qoff = _pairs(g_start, g_count, it)
        GC, GU, GE = G.bounds(qc, X[qr], Z[qr], trig=_trig(X, qr, G.m[qc]),
                              slack=(gs[0][qr], gs[1][qr]))
        low[:] = np.minimum.reduceat(FL, off, axis=0) - np.maximum.reduceat(GU, qoff, axis=0)
        fmin = np.minimum.reduceat(FC, off, axis=0)
        gmax = np.maximum.reduceat(GC, qoff, axis=0)
        point[:] = fmin - gmax
        slack[:] = np.maximum.reduceat(FE, off, axis=0) + np.maximum.reduceat(GE, qoff, axis=0)
        kk = point.argmin(axis=1)
        jf = pc[_first_min(FC[np.arange(pc.size), kk[pr]], fmin[rr, kk], pr, off)]
        jg = qc[_first_min(-GC[np.arange(qc.size), kk[qr]], -gmax[rr, kk], qr, qoff)]
    else:  # each follower cell with the predecessor cells of its own τ
        gc = (g_start[pc][:, None] + np.arange(E)[None, :]).ravel()
        rows = np.repeat(pr, E)
        GC, GU, GE = (v.reshape(pc.size, E, k) for v in G.bounds(
            gc, X[rows], Z[rows], trig=_trig(X, rows, G.m[gc]),
            slack=(gs[0][rows], gs[1][rows])))
        low[:] = np.minimum.reduceat(FL - GU.max(axis=1), off, axis=0)
        gmax = GC.max(axis=1)
        pp = FC - gmax
        pmin = np.minimum.reduceat(pp, off, axis=0)
        point[:] = pmin
        slack[:] = np.maximum.reduceat(FE + GE.max(axis=1), off, axis=0)
        kk = point.argmin(axis=1)
        ap = np.arange(pc.size)
        j = _first_min(pp[ap, kk[pr]], pmin[rr, kk], pr, off)
        jf = pc[j]
        jg = gc.reshape(pc.size, E)[j, GC[j, :, kk].argmax(axis=1)]
    wrow[:, 0] = X[rr, kk]
    wrow[:, 1] = F.tau[jf].mean(axis=1)
    wrow[:, 2] = F.headway[jf].mean(axis=1)
    wrow[:, 3] = G.tau_p[jg].mean(axis=1)
    wrow[:, 4] = e_delta[G.end[jg]]


def _keep(cells: _Split, act: npt.NDArray[np.intp], heterogeneous: bool) -> _Split:
    """Only the cells of the items ``act`` (sorted by owner)."""
    fk = np.flatnonzero(_among(cells.F.owner, act))
    F = cells.F.take(fk)
    if heterogeneous:
        return _Split(F, cells.G.take(np.flatnonzero(_among(cells.G.owner, act))))
    new = np.full(len(cells.F), -1, dtype=np.intp)
    new[fk] = np.arange(fk.size)
    gk = np.flatnonzero(new[cells.G.owner] >= 0)
    G = cells.G.take(gk)
    G.owner = new[G.owner]
    return _Split(F, G)


def _refine(cells: _Split, act: npt.NDArray[np.intp], bb: Any, *, kx: Array, kv: Array,
            ka: Array, H: float, ends: list[tuple[int, float]], heterogeneous: bool,
            widths: tuple[float, float], max_cells: int, e_delta: Array,
            cache: CellCache) -> tuple[_Split, npt.NDArray[np.bool_]]:
    """Halve the cells whose bounds are in the looser half at the held intervals' midpoints.

    Returns the new cells and, per item of ``act``, whether it now has more than
    ``max_cells`` cells (it is then inconclusive).
    """
    F, G = cells.F, cells.G
    ni = int(max(F.owner.max(initial=-1), act.max(initial=-1))) + 1
    f_start, f_count = _csr(F.owner, ni)
    g_start, g_count = _csr(G.owner, ni if heterogeneous else len(F))
    # the cells' bounds at the held intervals' midpoints decide which cells to halve
    th = (0.5 * (bb.pending_lo + bb.pending_hi))[:, None]
    it = act[bb.pending_item]
    pr, pc, off = _pairs(f_start, f_count, it)
    Z = vander(th)
    nil = (0.0, 0.0)  # the round-off slacks do not enter which cells to halve
    FC, FL, _ = F.bounds(pc, Z[pr], slack=nil)  # type: ignore[arg-type]
    FC, FL = FC[:, 0], FL[:, 0]
    split_f = np.zeros(len(F), dtype=bool)
    split_g = np.zeros(len(G), dtype=bool)
    bad_pairs: Any = None
    if heterogeneous:
        qr, qc, qoff = _pairs(g_start, g_count, it)
        GC, GU, _ = G.bounds(qc, th[qr], Z[qr], slack=nil)  # type: ignore[arg-type]
        GC, GU = GC[:, 0], GU[:, 0]
        fmin, L = np.minimum.reduceat(FC, off), np.minimum.reduceat(FL, off)
        gmax, U = np.maximum.reduceat(GC, qoff), np.maximum.reduceat(GU, qoff)
        lf, lg = fmin - L, U - gmax
        tot = lf + lg
        bad_f = (FL < (L + _LOOSE * lf)[pr]) & (lf >= 0.3 * tot)[pr] & (lf > 0)[pr]
        bad_g = (GU > (U - _LOOSE * lg)[qr]) & (lg >= 0.3 * tot)[qr] & (lg > 0)[qr]
        split_f[pc[bad_f]] = True
        split_g[qc[bad_g]] = True
        bad_pairs = bad_f
    else:
        E = len(ends)
        gc = (g_start[pc][:, None] + np.arange(E)[None, :]).ravel()
        GC, GU, _ = G.bounds(gc, np.repeat(th[pr], E, axis=0), np.repeat(Z[pr], E, axis=0),
                             slack=nil)  # type: ignore[arg-type]
        GC, GU = GC.reshape(pc.size, E).max(axis=1), GU.reshape(pc.size, E).max(axis=1)
        pp, lp = FC - GC, FL - GU
        pmin, low = np.minimum.reduceat(pp, off), np.minimum.reduceat(lp, off)
        loose = pmin - low
        bad_pairs = (lp < (low + _LOOSE * loose)[pr]) & (loose > 0)[pr]
        split_f[pc[bad_pairs]] = True
    # follower cells: halve along the parameter whose width costs the bound most where it
    # was loose (the larger mean-value spread at the held points)
    bp = np.flatnonzero(bad_pairs)
    sp = F.spreads(pc[bp], Z[pr[bp]])[:, :, 0]  # (bad pairs, 2)
    cost = np.zeros((len(F), 2))
    np.maximum.at(cost, pc[bp], sp)
    wt, wh = F.tau[:, 1] - F.tau[:, 0], F.headway[:, 1] - F.headway[:, 0]
    along_t = (cost[:, 0] >= cost[:, 1]) & (wt > 0) | (wh <= 0)
    sf = np.flatnonzero(split_f & ((wt > 0) | (wh > 0)))
    tau_a, tau_b = F.tau[sf].copy(), F.tau[sf].copy()
    hd_a, hd_b = F.headway[sf].copy(), F.headway[sf].copy()
    at = along_t[sf]
    mid_t, mid_h = F.tau[sf].mean(axis=1), F.headway[sf].mean(axis=1)
    tau_a[at, 1] = tau_b[at, 0] = mid_t[at]
    hd_a[~at, 1] = hd_b[~at, 0] = mid_h[~at]
    keep_f = np.flatnonzero(~_among(np.arange(len(F)), sf))
    kids = cache.follower(np.concatenate([F.owner[sf], F.owner[sf]]),
                          np.concatenate([tau_a, tau_b]), np.concatenate([hd_a, hd_b]),
                          around=(F.owner[keep_f], F.tau[keep_f], F.headway[keep_f]))
    F2 = FollowerCells(*(np.concatenate([getattr(F, k)[keep_f], getattr(kids, k)])
                         for k in ("owner", "tau", "headway", "V", "a", "mag", "gmag")))
    if heterogeneous:
        sg = np.flatnonzero(split_g & (G.tau_p[:, 1] > G.tau_p[:, 0]))
        mid = G.tau_p[sg].mean(axis=1)
        ta, tb = G.tau_p[sg].copy(), G.tau_p[sg].copy()
        ta[:, 1] = tb[:, 0] = mid
        own = np.concatenate([G.owner[sg], G.owner[sg]])
        keep_g = np.flatnonzero(~_among(np.arange(len(G)), sg))
        gk = cache.predecessor(own, own, np.concatenate([ta, tb]),
                               np.concatenate([G.end[sg], G.end[sg]]),
                               around=(G.owner[keep_g], G.tau_p[keep_g], G.end[keep_g]))
        G2 = PredecessorCells(*(np.concatenate([getattr(G, k)[keep_g], getattr(gk, k)])
                                for k in ("owner", "tau_p", "end", "m", "V", "a", "mag", "gmag")))
    else:
        # the follower cells kept keep their predecessor cells; the new ones get their own
        new = np.full(len(F), -1, dtype=np.intp)
        new[keep_f] = np.arange(keep_f.size)
        gk_ = np.flatnonzero(new[G.owner] >= 0)
        Gk = G.take(gk_)
        Gk.owner = new[Gk.owner]
        Gn = _pred_of(F2, np.arange(keep_f.size, len(F2)), keep_f.size, kx, kv, ka, H, ends,
                      cache)
        Gn.owner = np.arange(keep_f.size, len(F2)).repeat(len(ends))
        G2 = PredecessorCells(*(np.concatenate([getattr(Gk, k), getattr(Gn, k)])
                                for k in ("owner", "tau_p", "end", "m", "V", "a", "mag", "gmag")))
    out = _Split(F2, G2).sort(heterogeneous)
    n_f = np.bincount(out.F.owner, minlength=ni)
    n_g = np.bincount(out.G.owner if heterogeneous else out.F.owner[out.G.owner], minlength=ni)
    over = (n_f + n_g)[act] > max_cells
    return out, over
