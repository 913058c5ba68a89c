"""A vectorised one-dimensional branch and bound deciding f_i ≥ 0 on [0, Ω_i] for every item i.

The one engine behind every certificate: continuous time (:mod:`stringstab.certify.continuous`),
sampled data (:mod:`stringstab.certify.sampled`) and robust (:mod:`stringstab.certify.robust`).
Each item i (a gain triple, or a gain triple and a cell of uncertain parameters) has a
function f_i on [0, Ω_i] that the caller can evaluate at any points, returning for each point

* a *point value* f_i(x) at one admissible parameter value (used to prove a violation:
  f_i(x) < −slack is a witness),
* a *lower bound* of f over the item's parameter cell at x (equal to the point value
  when the cell is a point), and
* a round-off *slack*,

and for each interval [l, r] between consecutive points a bound M ≥ |f''| over [l, r]
(and the cell).  Then on [l, r] of width h, for every parameter of the cell,

    f ≥ min(f_low(l), f_low(r)) − M h²/8 − max(slack(l), slack(r))

(the error bound of linear interpolation: f(x) ≥ the chord − M (x − l)(r − x)/2 and the
chord ≥ the smaller end value).  An interval whose bound is ≥ 0 is settled; the others
are split into 4 to 64 pieces (as many as the curvature bound says are needed) and
re-checked, all items at once, for up to ``max_rounds`` rounds.

Items end ``certified`` (every interval settled), ``violated`` (a point value below
−slack: a witness), ``inconclusive`` (too many undecided intervals, or rounds ran out)
or ``pending``: intervals the caller asked to ``hold`` (e.g. where the parameter cell,
not the frequency interval, is too wide) are returned for the caller to split the cell.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import numpy.typing as npt

from .verdicts import CERTIFIED, INCONCLUSIVE, NOT_CERTIFIED, VERDICTS

__all__ = [
    "PENDING",
    "BranchAndBound",
    "branch_and_bound",
    "verdict_codes",
    "zoom_max",
]

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.intp]

#: Item outcomes: certified, violated and inconclusive items carry the verdict codes
#: CERTIFIED, NOT_CERTIFIED and INCONCLUSIVE of :mod:`stringstab.certify.verdicts` (a violated
#: item is not certified); PENDING, the engine's own fourth outcome (intervals handed back), is
#: the first code after them.
PENDING = len(VERDICTS)

#: ``evaluate(idx, X)`` with X of shape (len(idx), k + 1), sorted along axis 1, returns
#: (point values, lower bounds, slacks) of shape (len(idx), k + 1) and curvature bounds
#: of shape (len(idx), k) for the k intervals between consecutive columns.
Evaluate = Callable[[Index, Array], tuple[Array, Array, Array, Array]]

#: ``hold(idx, L, R, low_gap, curv)`` → mask of undecided intervals to hand back to the
#: caller instead of refining them (``low_gap`` = point − lower bound at the worse end,
#: ``curv`` = M h²/8).
Hold = Callable[[Index, Array, Array, Array, Array], npt.NDArray[np.bool_]]


@dataclass
class BranchAndBound:
    """Outcome per item, and the intervals handed back (see the module docstring).

    Attributes
    ----------
    status : ndarray of int8
        :data:`~stringstab.certify.verdicts.CERTIFIED`, :data:`~stringstab.certify.verdicts.NOT_CERTIFIED`
        (violated), :data:`~stringstab.certify.verdicts.INCONCLUSIVE` or :data:`PENDING`.
    minimum : ndarray
        Smallest point value found (an upper bound on min f).
    argmin : ndarray
        Where it was found.
    n_evals : ndarray of int
        Points evaluated per item (the initial grid, then the new interior points of each
        split).
    grid_x, grid_f : ndarray
        The initial grid and the point values on it (for reporting, e.g. a peak search).
    pending_item, pending_lo, pending_hi : ndarray
        The held intervals (item index, ends).
    """

    status: npt.NDArray[np.int8]
    minimum: Array
    argmin: Array
    n_evals: npt.NDArray[np.int64]
    grid_x: Array
    grid_f: Array
    pending_item: Index
    pending_lo: Array
    pending_hi: Array


#: Empty hand-backs (read-only).
_NO_ITEMS = np.zeros(0, dtype=np.intp)
_NO_POINTS = np.zeros(0)
_NO_ITEMS.setflags(write=False)
_NO_POINTS.setflags(write=False)


def verdict_codes(status: npt.NDArray[np.int8]) -> npt.NDArray[np.int8]:
    """Item outcomes of :func:`branch_and_bound` as verdict codes 0, 1, 2.

    Certified 0, violated 1 (not certified), anything else 2 (inconclusive): the codes of
    :data:`stringstab.certify.verdicts.VERDICTS`.  Certified, violated and inconclusive items
    already carry these codes (CERTIFIED, NOT_CERTIFIED, INCONCLUSIVE); only PENDING is mapped
    (to inconclusive).

    Parameters
    ----------
    status : ndarray of int8
        Item outcomes of :func:`branch_and_bound` (CERTIFIED, NOT_CERTIFIED, INCONCLUSIVE, PENDING).

    Returns
    -------
    ndarray of int8
        A copy with PENDING replaced by INCONCLUSIVE: verdict codes 0, 1, 2.
    """
    v = np.array(status, dtype=np.int8)
    v[v == PENDING] = INCONCLUSIVE
    return v


@lru_cache(maxsize=64)
def _unit_grid(k: int) -> Array:
    """``np.linspace(0, 1, k + 1)``, kept (read-only): the same points at every call."""
    u = np.linspace(0.0, 1.0, k + 1)
    u.setflags(write=False)
    return u


def _lower(Glow: Array, E: Array, M: Array, X: Array) -> tuple[Array, Array, Array]:
    """(lower bound, end value − slack, M h²/8) on every interval; a row's grid is uniform."""
    h = X[:, 1:2] - X[:, :1]
    gap = np.minimum(Glow[:, :-1], Glow[:, 1:])
    gap -= np.maximum(E[:, :-1], E[:, 1:])
    curv = M * (h * h / 8.0)
    return gap - curv, gap, curv


def branch_and_bound(
    n: int, evaluate: Evaluate, *, right: Array | None = None, n_grid: int = 64,
    intervals: tuple[Index, Array, Array] | None = None, max_rounds: int = 30,
    max_intervals: int = 1024, refine: npt.NDArray[np.bool_] | None = None,
    hold: Hold | None = None,
) -> BranchAndBound:
    """Decide f_i ≥ 0 on [0, right_i] (or on given intervals) for n items.

    Parameters
    ----------
    n : int
        Number of items.
    evaluate : callable
        See :data:`Evaluate`.
    right : ndarray, optional
        Right ends Ω_i of the domains [0, Ω_i] (with ``n_grid`` initial intervals each).
    n_grid : int
        Initial intervals per item.
    intervals : (item, lo, hi), optional
        Start from these intervals instead (each evaluated at its two ends).
    max_rounds, max_intervals : int
        Refinement rounds; undecided intervals per item beyond which the item is
        inconclusive.
    refine : bool array, optional
        Items to refine at all (others keep the verdict of the first evaluation).
    hold : callable, optional
        See :data:`Hold`.

    Returns
    -------
    BranchAndBound
    """
    n_evals = np.zeros(n, dtype=np.int64)
    violated = np.zeros(n, dtype=bool)
    inconclusive = np.zeros(n, dtype=bool)
    held: list[tuple[Index, Array, Array]] = []
    if intervals is not None or n == 0:  # (else the first pass sets them)
        minimum, argmin = np.full(n, np.inf), np.zeros(n)
    if intervals is None:
        if right is None:
            raise ValueError("branch_and_bound needs right or intervals")
        u = _unit_grid(n_grid)
        X = np.asarray(right, dtype=float)[:, None] * u[None, :]
        idx = np.arange(n)
    else:
        idx, lo, hi = intervals
        X = np.stack([lo, hi], axis=1)
    G, Glow, E, M = evaluate(idx, X) if idx.size else (X, X, X, X[:, 1:])
    grid_x, grid_f = (X, G) if intervals is None else (np.zeros((n, 0)), np.zeros((n, 0)))

    new_points = X.shape[1]  # the first evaluation: every point; later the interior ones
    first = intervals is None  # one row per item, in order: no scatter needed
    evaluated: list[tuple[Index, int]] = []  # (items, new points each), counted at the end
    while True:
        if first:
            n_evals += new_points
        else:
            evaluated.append((idx, new_points))
        if idx.size:
            j = np.argmin(G, axis=1)
            rows = np.arange(idx.size)
            gmin = G[rows, j]
            if first:
                minimum, argmin = gmin.copy(), X[rows, j]
            else:
                np.minimum.at(minimum, idx, gmin)
                better = gmin <= minimum[idx]
                argmin[idx[better]] = X[rows, j][better]
            viol = np.any(G < -E, axis=1)
            if viol.any():
                violated[np.unique(idx[viol])] = True
        low, gap, curv = _lower(Glow, E, M, X)
        und = low < 0
        und &= ~violated[idx][:, None]
        if refine is not None:  # the first pass only: later passes hold refined items alone
            off = ~refine[idx]
            if off.any():
                skip = und & off[:, None]
                if skip.any():  # undecided but not to be refined: never certified
                    inconclusive[np.unique(idx[np.nonzero(skip)[0]])] = True
                und &= ~off[:, None]
            refine = None
        ii, kk = np.nonzero(und)
        it, L, R = idx[ii], X[ii, kk], X[ii, kk + 1]
        gp, Mi = gap[ii, kk], M[ii, kk]
        if hold is not None and it.size:
            # how much the cell's width costs at the worse end: point − lower bound
            low_gap = np.maximum(G[ii, kk] - Glow[ii, kk], G[ii, kk + 1] - Glow[ii, kk + 1])
            hm = hold(it, L, R, low_gap, curv[ii, kk])
            if hm.any():
                held.append((it[hm], L[hm], R[hm]))
                keep = ~hm
                it, L, R, gp, Mi = it[keep], L[keep], R[keep], gp[keep], Mi[keep]
        if it.size == 0:
            break
        if max_rounds <= 0:
            inconclusive[np.unique(it)] = True
            break
        max_rounds -= 1
        counts = np.bincount(it, minlength=n)
        over = counts > max_intervals
        if over.any():
            inconclusive |= over
            keep = ~over[it]
            it, L, R, gp, Mi = it[keep], L[keep], R[keep], gp[keep], Mi[keep]
            if it.size == 0:
                break
        # enough pieces that M h²/8 ≤ gap/2 where the end values are clearly positive
        with np.errstate(divide="ignore", invalid="ignore"):
            need = np.where(gp > 0, (R - L) * np.sqrt(Mi / (4.0 * gp)), 4.0)
        split = int(min(max(4, 2 ** math.ceil(math.log2(max(float(np.max(need)), 1.0)))), 64))
        while split > 4 and it.size * split > 2_000_000:
            split //= 2
        v = _unit_grid(split)
        new_points = split - 1
        first = False
        idx = it
        X = L[:, None] + (R - L)[:, None] * v[None, :]
        G, Glow, E, M = evaluate(idx, X)

    if evaluated:
        n_evals += np.bincount(np.concatenate([i for i, _ in evaluated]),
                               weights=np.concatenate([np.full(i.size, k) for i, k in evaluated]),
                               minlength=n).astype(np.int64)
    status = np.full(n, CERTIFIED, dtype=np.int8)
    if held:
        pi = np.concatenate([h[0] for h in held])
        status[pi] = PENDING
        pl = np.concatenate([h[1] for h in held])
        ph = np.concatenate([h[2] for h in held])
        keep = ~violated[pi] & ~inconclusive[pi]
        pi, pl, ph = pi[keep], pl[keep], ph[keep]
    else:
        pi, pl, ph = _NO_ITEMS, _NO_POINTS, _NO_POINTS
    status[inconclusive] = INCONCLUSIVE
    status[violated] = NOT_CERTIFIED
    return BranchAndBound(status, minimum, argmin, n_evals, grid_x, grid_f, pi, pl, ph)


def zoom_max(
    f: Callable[[Array], Array], x: Array, fx: Array, half: Array, *, lo: float = 0.0,
    hi: float = math.inf, rounds: int = 8,
) -> tuple[Array, Array]:
    """Refine the maximum of f near ``x`` (one per row): a 9-point grid, shrunk ×4 each round.

    For *reporting* a peak (sup |Γ| or sup |H| and where): it never certifies anything.
    ``f`` maps an (n, 9) array of points (clipped to [lo, hi]) to values (NaN counts as
    +inf, a pole on the axis); ``fx`` are the values at ``x`` and ``half`` the initial
    half-widths.  Returns the best values and their points.

    Parameters
    ----------
    f : callable
        Maps an (n, 9) array of points to an (n, 9) array of values.
    x : ndarray, shape (n,)
        Starting points (e.g. the best grid points).
    fx : ndarray, shape (n,)
        f at ``x``.
    half : ndarray, shape (n,)
        Initial half-widths of the search windows.
    lo, hi : float
        The points are clipped to [lo, hi].
    rounds : int
        Number of zoom rounds.

    Returns
    -------
    best : ndarray, shape (n,)
        The largest value found per row (never below ``fx``).
    bx : ndarray, shape (n,)
        Where it was found.

    Examples
    --------
    >>> v, x = zoom_max(lambda t: -(t - 0.3) ** 2, np.array([0.0]), np.array([-0.09]),
    ...                 np.array([0.5]))
    >>> round(float(x[0]), 6)
    0.3
    """
    rows = np.arange(x.size)
    best, bx = np.asarray(fx, dtype=float).copy(), np.asarray(x, dtype=float).copy()
    half = np.asarray(half, dtype=float)
    v = np.linspace(-1.0, 1.0, 9)
    for _ in range(rounds):
        X = np.clip(bx[:, None] + half[:, None] * v[None, :], lo, hi)
        F = f(X)
        F = np.where(np.isnan(F), np.inf, F)
        j = np.argmax(F, axis=1)
        fj = F[rows, j]
        upd = fj > best
        best = np.where(upd, fj, best)
        bx = np.where(upd, X[rows, j], bx)
        half = half / 4.0
    return best, bx
