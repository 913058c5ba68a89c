r"""The robust certificate of the continuous loop over a box that includes the reaction delay θ_r.

With the command delayed by θ_r (issue 25) the margin of
:mod:`stringstab.certify.margin_reaction`

.. math::
    g_θ(ω) = τ^2ω^4 + (1 − k_a^2)ω^2 + c^2 − k_v^2 − 2(k_x + τcω^2)\cos θ_rω
             − 2(c − τk_x)ω \sin θ_rω + 2k_xk_a\cos δω − 2k_vk_aω \sin δω ,

c = k_v + T*k_x, has no closed-form minimum over a box of (τ, δ, T*, θ_r).  It is bounded
below over *cells* of the box by the mean-value form: with p_c the centre of a cell and r its
half-widths, g_θ(ω; p) ≥ g_θ(ω; p_c) − Σ_i L_i(ω) r_i where, term by term (trigonometric
factors bounded by 1 in magnitude, parameters at their worst over the cell),

* L_τ = 2τ_hi ω⁴ + 2c_max ω² + 2|k_x|ω  (∂g/∂τ = 2τω⁴ − 2cω² cos θ_rω + 2k_xω sin θ_rω),
* L_T = 2|k_x|(c_max + τ_hi ω² + ω)  (∂g/∂T* = 2ck_x − 2τk_xω² cos θ_rω − 2k_xω sin θ_rω),
* L_δ = |2k_xk_a|ω + |2k_vk_a|ω²,
* L_θ = 2|k_x|ω + 2e_max ω² + 2τ_hi c_max ω³  (e = c − τk_x, affine in T* − τ),

c_max and e_max the largest |c| and |e| over the cell.  The one branch and bound
(:mod:`stringstab.certify.branch_bound`) runs on each cell with the point value g_θ(ω; p_c)
(a real member: a value below −slack is a witness) and that lower bound, a curvature bound
uniform over the cell (:func:`stringstab.certify.margin_reaction.curvature_bound` with the
cell's largest coefficients, δ_hi and θ_hi) and the tail of the whole box
(:func:`stringstab.certify.margin_reaction.tail_bound` with τ_lo², the smallest c² − k_v²
and the largest amplitudes of the trigonometric terms).  Frequency intervals that the cell's
width leaves undecided (its cost Σ L_i r_i exceeds the curvature term) are handed back; the
cell is halved along its costliest parameter and its two halves resume on those intervals
only (everything else is already proven for the parent, so for them).

Internal stability over the box: :mod:`stringstab.certify.box_axis` (one member counted
stable, no member with a root on jℝ).  A triple left inconclusive is ``not_certified`` when
one of its members — a corner, or the cell centre where the margin came closest — is not
certified by its own point certificate (:mod:`stringstab.certify.reaction`, or
:mod:`stringstab.certify.continuous` at θ_r = 0): that member is the witness.

The way in, the result types and the verdicts are those of :mod:`stringstab.certify.robust`;
a box with θ_r = (0, 0) never comes here (:mod:`stringstab.certify.robust_continuous`).

References
----------
Issue 25 (item 4); IDL paper, Definition 1 (eq 10).  R. E. Moore, R. B. Kearfott, M. J. Cloud,
*Introduction to Interval Analysis*, SIAM (2009) (the mean-value form).
"""

from __future__ import annotations

import itertools

import numpy as np
import numpy.typing as npt

from ..params import Box, Params
from . import continuous, reaction
from . import margin_reaction as _mr
from .box_axis import axis_free
from .branch_bound import PENDING, branch_and_bound
from .quasipolynomial import count_unstable_roots
from .verdicts import CERTIFIED, INCONCLUSIVE, NOT_CERTIFIED, Check, Verdict

__all__ = ["STABILITY", "box_margin_tail", "cell_cost", "certify_box_reaction", "sampled_box_refusal",
           "stability_words"]

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.intp]

#: Relative widening of the computed mean-value costs (sums of positive terms).
_COST_WIDEN = 1.0 + 1e-12


def _worst(kx: Array, kv: Array, lo: Array, hi: Array) -> tuple[Array, Array]:
    """(c_max, e_max) over cells: the largest |k_v + T*k_x| and |k_v + (T* − τ)k_x|."""
    cmax = np.maximum(np.abs(kv + lo[2] * kx), np.abs(kv + hi[2] * kx))
    emax = np.maximum(np.abs(kv + (lo[2] - hi[0]) * kx), np.abs(kv + (hi[2] - lo[0]) * kx))
    return cmax, emax


def cell_cost(kx: Array, kv: Array, ka: Array, lo: Array, hi: Array) -> Array:
    """The coefficients of Σ_i L_i(ω) r_i as a polynomial in ω (module docstring): shape (5, m).

    Parameters
    ----------
    kx, kv, ka : ndarray, shape (m,)
        Gains of each cell's triple.
    lo, hi : ndarray, shape (4, m)
        The cells' ends, in the order τ, δ, T*, θ_r.

    Returns
    -------
    ndarray, shape (5, m)
        p_0 … p_4 with Σ_i L_i(ω) r_i = Σ_k p_k ω^k (each widened by 10⁻¹² relative), and
        g_θ(ω; p) ≥ g_θ(ω; p_c) − Σ_k p_k ω^k for every member p of the cell.

    Examples
    --------
    >>> lo = np.array([[0.1], [0.2], [1.1], [0.1]]); hi = np.array([[0.2], [0.2], [1.1], [0.3]])
    >>> P = cell_cost(np.array([1.0]), np.array([0.5]), np.array([0.2]), lo, hi)
    >>> w = 1.3; c = 0.5 + 1.1
    >>> m = lambda t, th: (t*t*w**4 + 0.96*w*w + c*c - 0.25 - 2*(1 + t*c*w*w)*np.cos(th*w)
    ...     - 2*(c - t)*w*np.sin(th*w) + 0.4*np.cos(0.2*w) - 0.2*w*np.sin(0.2*w))
    >>> low = m(0.15, 0.2) - sum(P[k, 0] * w**k for k in range(5))
    >>> bool(all(m(t, th) >= low for t in np.linspace(0.1, 0.2, 11) for th in np.linspace(0.1, 0.3, 11)))
    True
    """
    pc = 0.5 * (lo + hi)
    r = np.maximum(hi - pc, pc - lo)
    rt, rd, rh, rq = r
    cmax, emax = _worst(kx, kv, lo, hi)
    t_hi, ak = hi[0], np.abs(kx)
    cx, cv = np.abs(2.0 * kx * ka), np.abs(2.0 * kv * ka)
    P = np.stack([
        2.0 * rh * ak * cmax,
        2.0 * rt * ak + 2.0 * rh * ak + rd * cx + 2.0 * rq * ak,
        2.0 * rt * cmax + 2.0 * rh * ak * t_hi + rd * cv + 2.0 * rq * emax,
        2.0 * rq * t_hi * cmax,
        2.0 * rt * t_hi,
    ])
    return P * _COST_WIDEN


def _per_parameter_cost(w: Array, kx: Array, kv: Array, ka: Array, lo: Array,
                        hi: Array) -> Array:
    """L_i(ω) r_i for each parameter (shape (4, m)): which one to halve."""
    r = 0.5 * (hi - lo)
    cmax, emax = _worst(kx, kv, lo, hi)
    ak, t_hi = np.abs(kx), hi[0]
    return np.stack([
        r[0] * (2.0 * t_hi * w ** 4 + 2.0 * cmax * w * w + 2.0 * ak * w),
        r[1] * (np.abs(2.0 * kx * ka) * w + np.abs(2.0 * kv * ka) * w * w),
        r[2] * 2.0 * ak * (cmax + t_hi * w * w + w),
        r[3] * (2.0 * ak * w + 2.0 * emax * w * w + 2.0 * t_hi * cmax * w ** 3),
    ])


def _tables(kx: Array, kv: Array, ka: Array, lo: Array, hi: Array) -> tuple[Array, Array, Array]:
    """Per cell: the centre's coefficient table, the largest coefficients, the cost polynomial."""
    pc = 0.5 * (lo + hi)
    Qc = _mr.coefficient_table(kx, kv, ka, pc[0], pc[1], pc[2], pc[3])
    cmax, emax = _worst(kx, kv, lo, hi)
    Qm = np.zeros_like(Qc)
    Qm[0], Qm[1] = hi[0] * hi[0], 1.0 - ka * ka
    Qm[3], Qm[4], Qm[5] = 2.0 * kx * ka, 2.0 * kv * ka, 2.0 * kx
    Qm[6], Qm[7] = 2.0 * hi[0] * cmax, 2.0 * emax
    Qm[2 * _mr.N_COEFFICIENTS], Qm[2 * _mr.N_COEFFICIENTS + 1] = hi[1], hi[3]
    return Qc, Qm, cell_cost(kx, kv, ka, lo, hi)


def box_margin_tail(kx: Array, kv: Array, ka: Array, box: Box) -> Array:
    """Ω with g_θ(ω; p) > 0 for every member p of the box and every ω > Ω (module docstring).

    Parameters
    ----------
    kx, kv, ka : ndarray, shape (n,)
        Gains.
    box : Box
        The box.

    Returns
    -------
    ndarray
        Ω, rad/s.
    """
    n = kx.size
    lo = np.array([b[0] for b in (box.tau, box.delta, box.headway, box.reaction_delay)])
    hi = np.array([b[1] for b in (box.tau, box.delta, box.headway, box.reaction_delay)])
    h_lo, h_hi = box.headway
    c_lo, c_hi = np.minimum(kv + h_lo * kx, kv + h_hi * kx), np.maximum(kv + h_lo * kx, kv + h_hi * kx)
    c2_min = np.where((c_lo <= 0) & (c_hi >= 0), 0.0, np.minimum(c_lo * c_lo, c_hi * c_hi))
    cmax, emax = _worst(kx, kv, lo[:, None], hi[:, None])
    Q = np.zeros((2 * _mr.N_COEFFICIENTS + 2, n))
    Q[0], Q[1], Q[2] = lo[0] * lo[0], 1.0 - ka * ka, c2_min - kv * kv
    Q[3], Q[4], Q[5] = 2.0 * kx * ka, 2.0 * kv * ka, 2.0 * kx
    Q[6], Q[7] = 2.0 * hi[0] * cmax, 2.0 * emax
    return _mr.tail_bound(Q)


def _margin_cells(kx: Array, kv: Array, ka: Array, box: Box, rows: Index, *, n_grid: int,
                  max_rounds: int, max_intervals: int, max_splits: int,
                  max_cells: int) -> dict[str, Array]:
    """g_θ ≥ 0 over the box for the triples ``rows``: cells bisected (module docstring)."""
    n = kx.size
    status = np.full(n, INCONCLUSIVE, dtype=np.int8)
    best = np.full(n, np.inf)
    best_w, best_p = np.full(n, np.nan), np.full((n, 4), np.nan)
    viol = np.zeros(n, dtype=bool)
    n_evals = np.zeros(n, dtype=np.int64)
    box_lo = np.array([b[0] for b in (box.tau, box.delta, box.headway, box.reaction_delay)])
    box_hi = np.array([b[1] for b in (box.tau, box.delta, box.headway, box.reaction_delay)])
    if rows.size == 0:
        return {"status": status, "margin": best, "omega": best_w, "member": best_p,
                "violated": viol, "n_evals": n_evals}
    Om = box_margin_tail(kx[rows], kv[rows], ka[rows], box)
    cell_row = rows.copy()
    lo = box_lo[:, None].repeat(rows.size, 1)
    hi = box_hi[:, None].repeat(rows.size, 1)
    intervals: tuple[Index, Array, Array] | None = None
    open_ = np.zeros(n, dtype=bool)
    open_[rows] = True
    for split in range(max_splits + 1):
        k3 = kx[cell_row], kv[cell_row], ka[cell_row]
        Qc, Qm, P = _tables(*k3, lo, hi)

        def evaluate(idx: Index, X: Array, Qc: Array = Qc, Qm: Array = Qm,
                     P: Array = P) -> tuple[Array, Array, Array, Array]:
            G, E = _mr.g_and_slack(X, Qc[:, idx, None])
            Pi = P[:, idx, None]
            cost = (((Pi[4] * X + Pi[3]) * X + Pi[2]) * X + Pi[1]) * X + Pi[0]
            return G, G - cost, E, _mr.curvature_bound(X[:, 1:], Qm[:, idx, None])

        def hold(idx: Index, L: Array, R: Array, low_gap: Array, curv: Array) -> npt.NDArray[np.bool_]:
            return np.asarray(low_gap > curv)

        if intervals is None:  # the first pass: one cell per triple, the whole box
            bb = branch_and_bound(cell_row.size, evaluate, right=Om, n_grid=n_grid,
                                  max_rounds=max_rounds, max_intervals=max_intervals, hold=hold)
        else:
            bb = branch_and_bound(cell_row.size, evaluate, intervals=intervals,
                                  max_rounds=max_rounds, max_intervals=max_intervals, hold=hold)
        n_evals += np.bincount(cell_row, weights=bb.n_evals, minlength=n).astype(np.int64)
        # the closest member met per triple (a cell centre) and its frequency
        order = np.argsort(bb.minimum)[::-1]
        better = bb.minimum[order] < best[cell_row[order]]
        sel = order[better]
        best[cell_row[sel]] = bb.minimum[sel]
        best_w[cell_row[sel]] = bb.argmin[sel]
        best_p[cell_row[sel]] = (0.5 * (lo + hi))[:, sel].T
        bad = bb.status == NOT_CERTIFIED
        if bad.any():  # a witness: the cell's centre violates |Γ| ≤ 1 at its argmin
            b = np.flatnonzero(bad)
            o = b[np.argsort(bb.minimum[b])[::-1]]
            viol[cell_row[o]] = True
            best[cell_row[o]] = bb.minimum[o]
            best_w[cell_row[o]] = bb.argmin[o]
            best_p[cell_row[o]] = (0.5 * (lo + hi))[:, o].T
        stuck = np.zeros(n, dtype=bool)
        stuck[cell_row[bb.status == INCONCLUSIVE]] = True
        open_ &= ~(viol | stuck)
        pend_cells = np.flatnonzero((bb.status == PENDING) & open_[cell_row])
        if pend_cells.size == 0:
            break
        counts = np.bincount(cell_row[pend_cells], minlength=n)
        over = 2 * counts > max_cells
        open_ &= ~over
        pend_cells = pend_cells[open_[cell_row[pend_cells]]]
        if pend_cells.size == 0:
            break
        if split == max_splits:
            open_[cell_row[pend_cells]] = False
            break
        # halve each pending cell along its costliest parameter (at its highest pending ω)
        keep = np.isin(bb.pending_item, pend_cells)
        pi, pl, ph = bb.pending_item[keep], bb.pending_lo[keep], bb.pending_hi[keep]
        w_top = np.zeros(cell_row.size)
        np.maximum.at(w_top, pi, ph)
        c = pend_cells
        cost = _per_parameter_cost(w_top[c], kx[cell_row[c]], kv[cell_row[c]], ka[cell_row[c]],
                                   lo[:, c], hi[:, c])
        dim = np.argmax(cost, axis=0)
        j = np.arange(c.size)
        mid = 0.5 * (lo[dim, c] + hi[dim, c])
        lo_a, hi_a, lo_b, hi_b = lo[:, c].copy(), hi[:, c].copy(), lo[:, c].copy(), hi[:, c].copy()
        hi_a[dim, j], lo_b[dim, j] = mid, mid
        new_of = np.full(cell_row.size, -1, dtype=np.intp)
        new_of[c] = j
        ci = new_of[pi]
        intervals = (np.concatenate([ci, ci + c.size]), np.concatenate([pl, pl]),
                     np.concatenate([ph, ph]))
        cell_row = np.concatenate([cell_row[c], cell_row[c]])
        lo = np.concatenate([lo_a, lo_b], axis=1)
        hi = np.concatenate([hi_a, hi_b], axis=1)
    # open triples have no cell left pending: every cell of theirs is certified
    status[rows] = INCONCLUSIVE
    status[open_] = CERTIFIED
    status[viol] = NOT_CERTIFIED
    return {"status": status, "margin": best, "omega": best_w, "member": best_p,
            "n_evals": n_evals}


def _point_check(kx: Array, kv: Array, ka: Array, p: Params) -> Check:
    """The point certificate of one member: exact in θ_r (θ_r = 0: today's kernel)."""
    if p.reaction_delay:
        return reaction.check_kernel(kx, kv, ka, p)
    return continuous.check_kernel(kx, kv, ka, p)


def _own_evidence(kx: Array, kv: Array, ka: Array, box: Box,
                  closest: Array) -> dict[str, Array]:
    """The point certificate at the corners of the box and at each row's closest member.

    Returns, per row, whether some member is not certified and that member (the one with
    the smallest margin when there are several): its parameters (shape (n, 4)), witness ω
    (NaN when it is not internally stable), margin and whether it is unstable.
    """
    n = kx.size
    ends = [sorted(set(iv)) for iv in (box.tau, box.delta, box.headway, box.reaction_delay)]
    corners = list(itertools.product(*ends))
    k = len(corners) + 1
    M = np.empty((n, k, 4))
    M[:, :-1] = np.array(corners)
    M[:, -1] = closest
    bad = np.zeros((n, k), dtype=bool)
    margin, omega, stable = np.full((n, k), np.inf), np.full((n, k), np.nan), np.ones((n, k), bool)

    def run(i: Index, j: int, p: Params) -> None:
        c = _point_check(kx[i], kv[i], ka[i], p)
        bad[i, j] = np.asarray(c.verdict) == Verdict.NOT_CERTIFIED.value
        margin[i, j], omega[i, j], stable[i, j] = c.margin, c.witness_omega, c.hurwitz

    for j, corner in enumerate(corners):
        run(np.arange(n), j, Params(*corner))
    for row in range(n):
        if np.all(np.isfinite(closest[row])):
            run(np.array([row]), k - 1, Params(*closest[row]))
    j = np.where(bad, margin, np.inf).argmin(axis=1)
    i = np.arange(n)
    unstable = ~stable[i, j]
    return {"bad": bad.any(axis=1), "member": M[i, j], "omega": np.where(unstable, np.nan, omega[i, j]),
            "margin": margin[i, j], "unstable": unstable}


#: Internal stability over the box, three states (``stability``): every member proven stable;
#: a member proven not (k_x ≤ 0, or roots in Re s ≥ 0 counted at the box's centre); neither
#: proven within the budget (the centre's count or the axis bisection of
#: :func:`stringstab.certify.box_axis.axis_free` ran out) — never drawn as "not internally
#: stable".
STABILITY = ("stable", "unstable", "undecided")


def sampled_box_refusal(box: Box, H: float) -> str:
    """The one line refusing a box with θ_r > 0 and a sample time (no sound certificate yet).

    Parameters
    ----------
    box : Box
        The box (θ_r not (0, 0)).
    H : float
        The sample time, s.

    Returns
    -------
    str

    Examples
    --------
    >>> from stringstab.params import check_box
    >>> print(sampled_box_refusal(check_box("0.1:0.2", 0.2, 1.1, 0.2), 0.1))
    θ_r > 0 over a parameter box is certified in continuous time only (the sampled-data loop has no sound θ_r box certificate yet); expected point values of tau, delta, headway and reaction_delay with sample_time=0.1 (each member certified on its own), or the box without sample_time; got tau=0.1:0.2, reaction_delay=0.2 with sample_time=0.1
    """
    def show(lo: float, hi: float) -> str:
        return f"{lo:g}" if lo == hi else f"{lo:g}:{hi:g}"

    parts = [f"{k}={show(*getattr(box, k))}" for k in ("tau", "delta", "headway")
             if getattr(box, k)[0] != getattr(box, k)[1]]
    parts.append(f"reaction_delay={show(*box.reaction_delay)}")
    return ("θ_r > 0 over a parameter box is certified in continuous time only (the sampled-data "
            "loop has no sound θ_r box certificate yet); expected point values of tau, delta, "
            f"headway and reaction_delay with sample_time={H!r} (each member certified on its "
            f"own), or the box without sample_time; got {', '.join(parts)} with sample_time={H!r}")


def stability_words(stable: npt.NDArray[np.bool_],
                    unstable: npt.NDArray[np.bool_]) -> npt.NDArray[np.str_]:
    """The three-state internal stability of :data:`STABILITY`, per triple.

    Parameters
    ----------
    stable, unstable : ndarray of bool
        Every member proven internally stable; a member proven not (never both).

    Returns
    -------
    ndarray of str

    Examples
    --------
    >>> stability_words(np.array([True, False, False]), np.array([False, True, False])).tolist()
    ['stable', 'unstable', 'undecided']
    """
    assert not np.any(stable & unstable), "a box both proven stable and proven not"
    return np.where(stable, STABILITY[0], np.where(unstable, STABILITY[1], STABILITY[2]))


def certify_box_reaction(kx: Array, kv: Array, ka: Array, box: Box, *, n_grid: int,
                         max_rounds: int, max_intervals: int, max_splits: int,
                         max_cells: int) -> dict[str, Array]:
    """The robust certificate of the continuous loop over a box with θ_r, for a chunk of triples.

    The root count at the box's centre, then g_θ ≥ 0 over cells of the box (module
    docstring), then internal stability of every member
    (:func:`stringstab.certify.box_axis.axis_free`), then the point certificate at members of
    the boxes left inconclusive.

    Parameters
    ----------
    kx, kv, ka : ndarray, shape (n,)
        The gains (validated, finite).
    box : Box
        τ, δ, T*, θ_r intervals (validated); θ_r not (0, 0).
    n_grid, max_rounds, max_intervals : int
        Branch-and-bound budgets: initial intervals, refinement rounds per pass, undecided
        intervals per cell.
    max_splits, max_cells : int
        Bisection passes of the cells, and pending cells per triple, before the triple is
        inconclusive.

    Returns
    -------
    dict of str to ndarray
        As :func:`stringstab.certify.robust_continuous.certify_box_continuous`, plus
        ``reaction_delay``: the witness member's θ_r, and ``stability``: the three-state
        internal stability of :data:`STABILITY` (``stable`` is its first state only).

    Examples
    --------
    >>> from stringstab.params import check_box
    >>> b = check_box("0.1:0.2", 0.2, 1.1, "0.05:0.1")
    >>> r = certify_box_reaction(np.array([1.2, 0.9]), np.array([0.5, -0.5]), np.array([0.6, 1.1]),
    ...                          b, n_grid=64, max_rounds=30, max_intervals=1024,
    ...                          max_splits=24, max_cells=4096)
    >>> r["verdict"].tolist()  # codes: 0 certified, 1 not certified
    [0, 1]
    """
    n = kx.size
    centre = box.centre()
    pos = kx > 0
    rc = count_unstable_roots(kx, kv, centre.tau, centre.headway, centre.reaction_delay,
                              max_rounds=max_rounds + 10, max_intervals=4 * max_intervals)
    unstable = ~pos | rc.unstable
    stable = np.zeros(n, dtype=bool)
    n_evals = rc.n_evals.copy()
    rows = np.flatnonzero(~unstable)
    mc = _margin_cells(kx, kv, ka, box, rows, n_grid=n_grid, max_rounds=max_rounds,
                       max_intervals=max_intervals, max_splits=max_splits, max_cells=max_cells)
    n_evals += mc["n_evals"]
    # every member stable (asked also where a member violates |Γ| ≤ 1: ``stable`` is an answer
    # of its own, the region maps' "not internally stable" class)
    cand = np.flatnonzero(pos & rc.stable)
    if cand.size:
        ax = axis_free(kx[cand], kv[cand], box, max_rounds=max_rounds + 30,
                       max_cells=4 * max_intervals)
        stable[cand] = ax.free
        n_evals[cand] += ax.n_evals
    v = np.full(n, INCONCLUSIVE, dtype=np.int8)
    v[stable & (mc["status"] == CERTIFIED)] = CERTIFIED
    v[unstable | (mc["status"] == NOT_CERTIFIED)] = NOT_CERTIFIED
    member, w, margin = mc["member"], mc["omega"], mc["margin"]
    c4 = np.array([centre.tau, centre.delta, centre.headway, centre.reaction_delay])
    member[unstable] = c4
    w[unstable] = np.nan
    margin[unstable] = np.nan
    unstable_w = unstable.copy()  # the witness member is not internally stable
    # a box its own members prove not certified (the sampled box's rule, issue 29)
    inc = np.flatnonzero(v == INCONCLUSIVE)
    if inc.size:
        ev = _own_evidence(kx[inc], kv[inc], ka[inc], box, member[inc])
        r, e = inc[ev["bad"]], ev["bad"]
        v[r] = NOT_CERTIFIED
        member[r], w[r], margin[r] = ev["member"][e], ev["omega"][e], ev["margin"][e]
        unstable_w[r] = ev["unstable"][e]
    sup = np.where(v == CERTIFIED, 1.0, np.inf)
    excess = np.where(v == CERTIFIED, 0.0, np.inf)
    rep = np.flatnonzero((v != CERTIFIED) & ~unstable_w & np.isfinite(w)
                         & np.all(np.isfinite(member), axis=1))
    for i in rep:  # |Γ| at the witness member: its largest excess near ω_w and on a log grid
        t, d, h, th = member[i]
        W = np.concatenate([[w[i]], w[i] * 10.0 ** np.linspace(-2.0, 0.5, 26),
                            10.0 ** np.linspace(-8.0, 1.0 + np.log10(max(w[i], 1.0)), 181)])
        W = W[W > 0] if w[i] > 0 else W[1:]
        e2 = reaction.excess_squared(W, kx[i:i + 1], kv[i:i + 1], ka[i:i + 1], t, d, h, th)
        e2 = np.where(np.isfinite(e2), e2, -np.inf)
        j = int(np.argmax(e2))
        if e2[j] > -1.0:
            sup[i] = np.sqrt(1.0 + e2[j])
            excess[i] = e2[j] / (1.0 + sup[i])
            if e2[j] > 0:  # the frequency where |Γ| > 1 is seen (also when ω_w = 0)
                w[i] = W[j]
    return {
        "verdict": v, "stable": stable, "stability": stability_words(stable, unstable),
        "margin": margin, "omega": w, "theta": np.full(n, np.nan),
        "tau": member[:, 0], "tau_prev": member[:, 0].copy(), "delta": member[:, 1],
        "headway": member[:, 2], "reaction_delay": member[:, 3], "n_evals": n_evals,
        "sup_gain": sup, "sup_gain_excess": excess,
    }
