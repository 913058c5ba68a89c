"""The robust certificate of the sampled-data loop over a box: the split form on grids of cells.

g_H of :func:`stringstab.certify.sampled_frequency.sampled_margin` has no closed-form minimum
over a box of τ, δ, T* and the predecessor's lag τ_p, but it splits
(:mod:`stringstab.certify.sampled_split`): g_H has the sign of F(θ; τ, T*) − G(θ; τ_p, δ), the
follower's factor against the predecessor's, and the maximum of G over a piece of the delay
is at one of its ends.  So the box is certified when, at every θ ∈ [0, π], min F over
(τ, T*) ≥ max G over τ_p and the ends of the delay (τ_p ranging over the τ box independently,
``heterogeneous=True``), or, with τ_p = τ, when that holds per τ.  The branch and bound of
:mod:`stringstab.certify.branch_bound` decides it on θ, bounding F below and G above over
grids of cells (2^ℓ cells of τ and of T*, and of τ_p, at level ℓ; derivative enclosures and
the mean-value form, :mod:`stringstab.certify.interval`); a frequency interval the cells'
width leaves undecided is handed back and its triple goes to the next, finer level.  The point
value at each θ is that of a real member (the cells' centres where F is smallest and G
largest), so a violation comes with its witness.  The delay enters as z^{−(m+1)} with
m = ⌊δ/H⌋: the δ interval is split at the multiples of H into pieces of fractional delay
ε ∈ [ε_lo, ε_hi] ⊂ [0, 1] (continuous at the joins: ε = 1 at m equals ε = 0 at m + 1).  Schur
stability over (τ, T*) is decided by a two-dimensional bisection on the interval-evaluated Schur
conditions (:func:`stringstab.certify.zoh.schur_terms` of
:func:`_delta_cells`).  A box left inconclusive is not certified when one
of its members — a corner, or the member where the search came closest — is not certified by
its own point certificate (:func:`stringstab.certify.sampled.check_members`): that member is
the witness.

The way in, the result types and the verdicts are those of :mod:`stringstab.certify.robust`.

References
----------
R. E. Moore, R. B. Kearfott, M. J. Cloud, *Introduction to Interval Analysis*, SIAM (2009).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ..params import Box
from .excess import EXCESS_SEARCH, searched_excess
from .interval_stack import StackedAD
from .robust_split import split_search
from .sampled import check_members
from .sampled_excess import peak_gain, violation_peak
from .sampled_frequency import margin_bound
from .sampled_split import delay_ends, follower_primitives
from .schur import SCHUR_RTOL
from .verdicts import CERTIFIED, INCONCLUSIVE, NOT_CERTIFIED, ROUNDOFF_SLACK
from .zoh import Coefficients, coefficients, schur_terms, split_delay

__all__ = ["certify_box_sampled"]

Array = npt.NDArray[np.float64]

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


def _delta_cells(kx: Array, kv: Array, *, H: float, tau: Array, headway: Array) -> list[StackedAD]:
    """δ0, δ1, δ2 of Δ(w) with derivative enclosures over cells of (τ, T*) alone.

    The characteristic polynomial depends on τ and T* only (not on δ, k_a or the
    predecessor's lag), so the Schur test over a box needs these three coefficients, not the
    whole :func:`cell_coefficients`; the numbers are the ones :func:`build` computes for
    them (the same operations; the derivatives along τ and T* of a cell of
    :func:`cell_coefficients` with ``tau_p=None``).

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
        [δ0, δ1, δ2], derivatives in the order (τ, T*) (the numbers of IntervalAD, in the
        stacked arrays of :mod:`stringstab.certify.interval_stack`).
    """
    q = follower_primitives(kx, kv, H=H, tau=tau, headway=headway)
    K_x, Cc, T, f1, p2, p3 = (q[k] for k in ("K_x", "Cc", "T", "f1", "p2", "p3"))
    Hs = float(H)
    d0 = K_x * (Hs * Hs) * f1
    d1 = Hs * (Cc * f1 + K_x * (T * p2 + (0.5 * Hs) * f1))
    d2 = f1 + Cc * T * p2 + K_x * T * T * p3
    return [d0, d1, d2]



def _schur_box(kx: Array, kv: Array, box: Box, H: float, max_depth: int = 14) -> tuple[
        npt.NDArray[np.bool_], npt.NDArray[np.bool_], Array, Array]:
    """Schur stability of Δ over (τ, T*) ∈ box by bisection: (sure, fail, witness τ, T*).

    A cell is Schur when every condition's lower bound (natural interval extension or
    mean-value form, whichever is larger) exceeds a relative 10⁻¹² band; a condition
    below −band at a cell's centre is a witness member that is not Schur.
    """
    n = kx.size
    fail = np.zeros(n, dtype=bool)
    undecided = np.zeros(n, dtype=bool)
    wt = np.full(n, np.nan)
    wh = np.full(n, np.nan)
    # k_x ≤ 0: δ0 = k_x H² φ1 ≤ 0, the first condition fails at every member (the bisection
    # would find it at the box's centre, its first cell: the same witness, without the work)
    neg = kx <= 0
    fail[neg] = True
    wt[neg] = np.array(box.tau, dtype=float)[None, :].mean(axis=1)[0]
    wh[neg] = np.array(box.headway, dtype=float)[None, :].mean(axis=1)[0]
    owner = np.flatnonzero(~neg)
    t = np.tile(np.array(box.tau, dtype=float), (owner.size, 1))
    h = np.tile(np.array(box.headway, dtype=float), (owner.size, 1))
    for depth in range(max_depth + 1):
        if owner.size == 0:
            break
        delta = _delta_cells(kx[owner], kv[owner], H=H, tau=t, headway=h)
        hw = np.stack([0.5 * (t[:, 1] - t[:, 0]), 0.5 * (h[:, 1] - h[:, 0])], axis=1)
        ok = np.ones(owner.size, dtype=bool)
        bad = np.zeros(owner.size, dtype=bool)
        term: Any
        for term in schur_terms(delta):
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


def _own_evidence(kx: Array, kv: Array, ka: Array, box: Box, H: float, rows: npt.NDArray[np.intp],
                  wit: dict[str, Array], delays: Array, heterogeneous: bool) -> dict[str, Array]:
    """The point certificate at members of each box of ``rows``: the corners and the witness.

    Returns, per row of ``rows``, whether some member is not certified by its own point
    certificate (:func:`stringstab.certify.sampled.check_members`) and that member (the one
    with the smallest g_H when there are several), its θ and g_H, and whether Δ is Schur
    there.
    """
    taus, heads = sorted(set(box.tau)), sorted(set(box.headway))
    taups = taus if heterogeneous else [None]
    corners = [(t, t if tp is None else tp, d, h) for t in taus for tp in taups
               for d in sorted(set(delays.tolist())) for h in heads]
    k = len(corners) + 1
    M = np.empty((rows.size, k, 4))
    M[:, :-1] = np.array(corners)
    M[:, -1] = np.stack([wit["t"][rows], wit["tp"][rows], wit["d"][rows], wit["h"][rows]], 1)
    ok = np.asarray(np.isfinite(M).all(axis=2))
    M = np.where(ok[:, :, None], M, M[:, :1])  # a missing witness: repeat a corner
    r = np.repeat(rows, k)
    v, g, th = check_members(kx[r], kv[r], ka[r], tau=M[..., 0].ravel(),
                             tau_prev=M[..., 1].ravel(), delta=M[..., 2].ravel(),
                             headway=M[..., 3].ravel(), H=H)
    bad = (v == NOT_CERTIFIED).reshape(rows.size, k)
    score = np.where(bad, np.nan_to_num(g.reshape(rows.size, k), nan=-np.inf), np.inf)
    j = score.argmin(axis=1)
    i = np.arange(rows.size)
    return {"bad": bad.any(axis=1), "t": M[i, j, 0], "tp": M[i, j, 1], "d": M[i, j, 2],
            "h": M[i, j, 3], "theta": th.reshape(rows.size, k)[i, j],
            "value": g.reshape(rows.size, k)[i, j]}


def certify_box_sampled(kx: Array, kv: Array, ka: Array, box: Box, H: float, *,
                        heterogeneous: bool, n_grid: int | None, max_rounds: int,
                        max_intervals: int, max_splits: int, max_cells: int) -> dict[str, Array]:
    """The robust certificate of the sampled loop over a box, for a chunk of gain triples.

    Schur stability over (τ, T*) by bisection, then the branch and bound of the split
    margin F − G ≥ 0 on [0, π] over ever finer grids of cells of (τ, T*) and τ_p, at the
    ends of the delay's pieces (module docstring); a box left inconclusive whose own member
    (a corner, or the member where the search came closest) is not certified by its point
    certificate is not certified, with that member as the witness.

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
        Refinement levels of the cells (each halves every cell), and cells per triple,
        before it is inconclusive.

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
    ends = delay_ends(*box.delta, H, pieces)
    grid = n_grid or (64 + 8 * max(p[0] for p in pieces))
    status = np.full(n, CERTIFIED, dtype=np.int8)
    status[~sure] = np.where(fail[~sure], NOT_CERTIFIED, INCONCLUSIVE)
    live = np.flatnonzero(~fail)  # an undecided Schur band still looks for a witness
    found = split_search(kx, kv, ka, box, H, live, pieces, heterogeneous=heterogeneous,
                          grid=grid, max_rounds=max_rounds, max_intervals=max_intervals,
                          max_splits=max_splits, max_cells=max_cells)
    code = found["code"]
    status[code == NOT_CERTIFIED] = NOT_CERTIFIED
    status[(code == INCONCLUSIVE) & (status != NOT_CERTIFIED)] = INCONCLUSIVE
    wit = {k: found[k] for k in ("theta", "t", "tp", "d", "h")}
    margin = np.full(n, np.inf)
    unstable = fail.copy()  # the witness member is not internally stable
    # a box its own members prove not string stable is not certified (issue 29, item 7)
    rows = np.flatnonzero(status == INCONCLUSIVE)
    if rows.size:
        delays = np.clip([(m + e) * H for m, e in ends] + list(box.delta), *box.delta)
        ev = _own_evidence(kx, kv, ka, box, H, rows, wit, delays, heterogeneous)
        r = rows[ev["bad"]]
        status[r] = NOT_CERTIFIED
        for key in ("t", "tp", "d", "h", "theta"):
            wit[key][r] = ev[key][ev["bad"]]
        margin[r] = ev["value"][ev["bad"]]
        unstable[r] = np.isnan(ev["theta"][ev["bad"]])
    # members and frequencies of the witnesses; the unstable member when Schur fails
    tau_w = np.where(fail, wt, wit["t"])
    taup_w = np.where(fail, wt, wit["tp"])
    h_w = np.where(fail, wh, wit["h"])
    d_w = np.where(fail, box.delta[0], wit["d"])
    theta = np.where(unstable, np.nan, wit["theta"])
    sup = np.where(status == CERTIFIED, 1.0, np.where(unstable, np.inf, np.nan))
    member = ~unstable & np.isfinite(tau_w)
    split = [split_delay(float(d), H) if ok else (0, 0.0) for d, ok in zip(d_w, member)]
    m_w = np.array([s[0] for s in split], dtype=float)
    e_w = np.array([s[1] for s in split])
    coeffs: dict[float, tuple[npt.NDArray[np.intp], Coefficients]] = {}
    # the witnesses' point coefficients in one call (elementwise: each row's numbers are the
    # ones a call on its own group of m computes), then taken per m
    every = np.flatnonzero(member)
    e_a, c_a = e_w[every], kv[every] + h_w[every] * kx[every]
    co_all = coefficients(kx[every], kv[every], ka[every], H=H,
                          tau=(tau_w[every], tau_w[every]),
                          tau_p=(taup_w[every], taup_w[every]), eps=(e_a, e_a), c=(c_a, c_a))
    for mm in np.unique(m_w[member]):
        at = np.flatnonzero(m_w[every] == mm)
        idx = every[at]
        co = co_all.take(at)
        coeffs[float(mm)] = (idx, co)
        fresh = ~np.isfinite(margin[idx])  # g_H at the witness (the evidence rows have it)
        g_w = margin_bound(theta[idx][:, None], co, np.full(idx.size, float(mm)))[0][:, 0]
        margin[idx] = np.where(fresh, g_w, margin[idx])
        need = np.isnan(sup[idx])
        if need.any():
            j = idx[need]
            ng = 65 + 8 * int(mm)
            th_grid = np.broadcast_to(np.linspace(0.0, np.pi, ng), (j.size, ng))
            sup[j], theta[j] = peak_gain(co.take(np.flatnonzero(need)), int(mm), ka[j],
                                         th_grid, theta[j])
    out = {"verdict": status, "stable": sure, "margin": margin, "theta": theta,
           "tau": tau_w, "tau_prev": taup_w, "delta": d_w, "headway": h_w,
           "n_evals": found["n_evals"], "sup_gain_excess": sup - 1.0}
    small = (status == NOT_CERTIFIED) & sure & member & (sup - 1.0 < EXCESS_SEARCH)
    for mm, (idx, co) in coeffs.items():
        sel = small[idx]
        if not sel.any():
            continue
        j = idx[sel]
        kappa = tau_w[j] * taup_w[j] / H**3
        e2, th = violation_peak(co.take(np.flatnonzero(sel)), int(mm), kappa,
                                np.stack([theta[j], wit["theta"][j]], 1))
        e1, take = searched_excess(e2, out["sup_gain_excess"][j])
        out["sup_gain_excess"][j] = np.where(take, e1, out["sup_gain_excess"][j])
        out["theta"][j] = np.where(take, th, out["theta"][j])
        sup[j] = np.where(take, 1.0 + e1, sup[j])
    out["omega"] = out["theta"] / H
    out["sup_gain"] = sup
    return out
