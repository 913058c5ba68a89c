r"""Sound certificates of the multi-rate V2V loop: messages every N control steps, held.

The loop (docs/sampled.md, §9): every vehicle samples and commands every H seconds (zero-order
hold, lag τ); the predecessor's acceleration a_{i−1}(kH − δ) arrives by message every N steps
and is held in between.  The link u_{i−1} → u_i is N-periodic; string stability is its
ℓ2-induced gain ≤ 1, which equals sup_θ σ_max(G(e^{jθ})) of the link lifted over one message
period (:mod:`stringstab.certify.lifting`).

**The decision.**  ``certified`` means: the lifted A is Schur — iff the follower's Δ(z) is
(:mod:`stringstab.certify.lifting`; decided by :func:`stringstab.certify.schur.schur_bands`,
sound with a relative 10⁻¹² band) — and λ_min(M(θ)) ≥ 0 on [0, π], with M the tangency-free
margin matrix of :mod:`stringstab.certify.lifted_frequency` (a congruence of I − G*G for
θ ≠ 0), decided by the branch and bound of :mod:`stringstab.certify.branch_bound` with the
proven slack at points and the proven curvature bound between them.  Then
sup_θ σ_max(G(e^{jθ})) = σ_max(G(1)) = 1.  ``not_certified``: Δ not Schur (a root of modulus
≥ 1: ``spectral_radius``), or a θ with λ_min(M(θ)) < −slack — so σ_max(G(e^{jθ})) > 1 (for
θ = 0, on a neighbourhood of it, by continuity).  ``inconclusive``: neither within the budget
(a tangency, e.g. Ψ3 = 0, stays inconclusive).  The reported peak (``sup_gain``,
``peak_theta``) is located by a grid and a bisected bracket on σ_max(Ĝ)
(:mod:`stringstab.certify.lifted_peak`) and never enters a verdict.

**The fallback mode** (ACC: the message is not used, k_a = 0, optionally other gains) is an
LTI loop, the sampled certificate of (k_x, k_v, 0) (:mod:`stringstab.certify.sampled`),
reported beside (``fallback_verdict``, ``fallback_sup_gain``).  Switching between the two
modes and random message loss are **not** covered by either certificate (:data:`SCOPE`).

References
----------
docs/sampled.md §9; IDL paper, eqs 3-9 and eq 4.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt

from ..io import TableColumn
from ..params import Box, Params
from .branch_bound import Evaluate, branch_and_bound, verdict_codes
from .lifted_frequency import LOCAL, Prepared, curvature, evaluate, prepare
from .lifted_peak import lifted_peak
from .lifting import LiftedLink, lift
from .schur import schur_bands, spectral_radius_of
from .verdicts import (
    CERTIFIED,
    INCONCLUSIVE,
    NOT_CERTIFIED,
    ROW_COLUMNS,
    BatchResult,
    Check,
    SingleResult,
    chunks,
    names,
)
from .zoh import point_coefficients

__all__ = [
    "SCOPE",
    "TABLE_COLUMNS",
    "MultirateCertificate",
    "MultirateCertificateBatch",
    "MultirateCheck",
    "certify_kernel",
    "check_kernel",
    "decide",
    "decide_lifted",
]

Array = npt.NDArray[np.float64]

#: What the multi-rate certificate does not cover (written into every result's summary).
SCOPE = ("the loop with every message delivered, in one mode at a time: switching between "
         "the cooperative (CACC) and fallback (ACC) modes and random message loss are not covered")

#: Points evaluated at once (bounds the working memory: ~ (4 + J)² + 3N² complex numbers each).
_BATCH_POINTS = 4096
#: The curvature bound of an interval whose resolvent bound is not proven (never settles it).
_HUGE = 1e290
#: The largest initial grid of the second pass.
_MAX_GRID = 1024


def _default_grid(N: int) -> int:
    """Initial intervals on [0, π]."""
    return 32 + 2 * N


def _evaluator(pr: Prepared, items: npt.NDArray[np.intp], rho_max: Array,
               local: bool = True) -> Evaluate:
    """The branch and bound's :data:`~stringstab.certify.branch_bound.Evaluate` of λ_min(M_r(θ)).

    Item i of the branch and bound is row ``items[i]`` of ``pr``; the largest resolvent bound
    seen per item is kept in ``rho_max`` (to size the next grid).  Without ``local`` the
    points are evaluated without the local bounds (a violation can still be found; no
    interval is settled).
    """

    def evaluate_(idx: npt.NDArray[np.intp], X: Array) -> tuple[Array, Array, Array, Array]:
        k, p = X.shape
        lam = np.empty((k, p))
        slack = np.empty((k, p))
        loc = np.empty((k, p, len(LOCAL)))
        step = max(1, _BATCH_POINTS // p)
        for s in range(0, k, step):
            mg = evaluate(pr, items[idx[s:s + step]], X[s:s + step], local=local)
            lam[s:s + step], slack[s:s + step], loc[s:s + step] = mg.lam, mg.slack, mg.local
        np.maximum.at(rho_max, idx, loc[:, :, LOCAL.index("rho")].max(axis=1))
        K = curvature(loc[:, :-1], loc[:, 1:], X[:, 1:2] - X[:, :1])
        # an unproven bound (inf) as a finite huge one: the interval is split, never settled
        return lam, lam, slack, np.minimum(K, _HUGE)

    return evaluate_


def _grid_for(rho: Array, lo: int, hi: int) -> Array:
    """Initial intervals on [0, π] keeping (h/2)·ρ ≤ 1/4 (so the Neumann factor s ≤ 4/3): powers of 2."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        need = np.where(np.isfinite(rho), 2.0 * np.pi * rho, hi)
        k = np.ceil(np.log2(np.maximum(need, 1.0)))
    return np.asarray(np.clip(np.exp2(k), lo, hi).astype(np.int64))


@dataclass(frozen=True)
class Decision:
    """The verdicts of :func:`decide` and what the branch and bound found.

    Attributes
    ----------
    verdict : ndarray of int8
        Verdict codes.
    sure, fail : ndarray of bool
        Δ surely Schur; surely not Schur.
    margin, argmin : ndarray
        Smallest λ_min(M̂(θ)) found and where (θ, rad per message period); NaN when not Schur.
    n_evals : ndarray of int
        Points evaluated.
    grid : ndarray
        The initial grid on [0, π].
    link : LiftedLink
        The lifted link of every row.
    delta : list of ndarray
        δ0, δ1, δ2 of Δ(w) (spectral radius, reporting); empty with θ_r > 0.
    rho : ndarray or None
        With θ_r > 0: the spectral radius of the computed one-step follower block
        (reporting); None otherwise (computed from ``delta``).
    """

    verdict: npt.NDArray[np.int8]
    sure: npt.NDArray[np.bool_]
    fail: npt.NDArray[np.bool_]
    margin: Array
    argmin: Array
    n_evals: npt.NDArray[np.int64]
    grid: Array
    link: LiftedLink
    delta: list[Array]
    rho: Array | None = None


def decide(kx: Array, kv: Array, ka: Array, p: Params, H: float, N: int, *,
           n_grid: int | None = None, max_rounds: int = 30,
           max_intervals: int = 1024) -> Decision:
    """The sound decision for many gain triples (module docstring).

    Parameters
    ----------
    kx, kv, ka : ndarray
        The gains (checked), one triple per row.
    p : Params
        τ, δ, T*.
    H : float
        The control period, s.
    N : int
        Steps per message period (≥ 1; 1 is the sampled loop, computed the lifted way).
    n_grid, max_rounds, max_intervals : int
        Initial intervals on [0, π] (default 32 + 2N), refinement rounds, and the cap on
        undecided intervals per triple.

    Returns
    -------
    Decision
    """
    if p.reaction_delay:
        return _decide_reaction(kx, kv, ka, p, H, N, n_grid=n_grid, max_rounds=max_rounds,
                                max_intervals=max_intervals)
    co, _ = point_coefficients(kx, kv, ka, p, H, p.tau)
    sure, fail = schur_bands(co.delta)
    link = lift(kx, kv, ka, p, H, N)
    verdict, margin, argmin, n_evals, grid = decide_lifted(
        link, sure, fail, n_grid=n_grid or _default_grid(N), max_rounds=max_rounds,
        max_intervals=max_intervals)
    return Decision(verdict, sure, fail, margin, argmin, n_evals, grid, link,
                    [d.lo for d in co.delta])


def _decide_reaction(kx: Array, kv: Array, ka: Array, p: Params, H: float, N: int, *,
                     n_grid: int | None, max_rounds: int, max_intervals: int) -> Decision:
    """:func:`decide` with θ_r > 0: the held-input lift (docs/sampled.md §10.5).

    Internal stability is decided on the one-step follower block A_f (3 + L states) by the
    Stein inertia theorem, as the sampled θ_r certificate does: the lifted state matrix is
    block triangular and its follower block is A_f^N (the message's hold enters through the
    predecessor's states only), so it is Schur iff A_f is.  The frequency half is
    :func:`decide_lifted` on the N-step lift.  At N = 1 this is
    :func:`stringstab.certify.sampled_reaction.decide`, operation for operation (with its
    grid).
    """
    from .lifting_reaction import follower_block, held_steps, lift_reaction
    from .stein import stein_schur

    _, _, L = held_steps(p.reaction_delay, H)
    one = lift_reaction(kx, kv, ka, p, H, 1)
    Af = follower_block(one, L)
    sure, fail = stein_schur(Af)
    link = one if N == 1 else lift_reaction(kx, kv, ka, p, H, N)
    verdict, margin, argmin, n_evals, grid = decide_lifted(
        link, sure, fail, n_grid=n_grid or _default_grid(N), max_rounds=max_rounds,
        max_intervals=max_intervals)
    with np.errstate(invalid="ignore"):
        rho = np.array([np.abs(np.linalg.eigvals(a)).max() if np.all(np.isfinite(a)) else np.nan
                        for a in Af.mid])
    return Decision(verdict, sure, fail, margin, argmin, n_evals, grid, link, [], rho)


def decide_lifted(link: LiftedLink, sure: npt.NDArray[np.bool_], fail: npt.NDArray[np.bool_], *,
                  n_grid: int, max_rounds: int = 30, max_intervals: int = 1024,
                  ) -> tuple[npt.NDArray[np.int8], Array, Array, npt.NDArray[np.int64], Array]:
    """The frequency half of :func:`decide` on a lifted link whose stability is decided.

    Parameters
    ----------
    link : LiftedLink
        The lifted link of n triples (any per-step model: :mod:`stringstab.certify.lifting`
        or :mod:`stringstab.certify.lifting_reaction`).
    sure, fail : ndarray of bool
        Its state matrix surely Schur; surely not.
    n_grid, max_rounds, max_intervals : int
        Initial intervals on [0, π], refinement rounds, cap on undecided intervals per triple.

    Returns
    -------
    (ndarray of int8, ndarray, ndarray, ndarray of int, ndarray)
        Verdict codes, the smallest λ_min(M̂(θ)) found and where (NaN when not surely
        Schur), points evaluated, and the initial grid (n, n_grid + 1).
    """
    n = sure.size
    verdict = np.where(fail, NOT_CERTIFIED, INCONCLUSIVE).astype(np.int8)
    margin = np.full(n, np.nan)
    argmin = np.zeros(n)
    n_evals = np.zeros(n, dtype=np.int64)
    ng = n_grid
    grid = np.broadcast_to(np.linspace(0.0, np.pi, ng + 1), (n, ng + 1))
    idx = np.flatnonzero(sure)
    if idx.size:
        pr = prepare(link.take(idx))
        # a first look at the points of a coarse grid finds most violations (no interval is
        # settled there); the rest are decided on a grid fine enough for the resolvent bounds
        # (grouped by size, powers of two)
        rho = np.zeros(idx.size)
        items = np.arange(idx.size)
        bb = branch_and_bound(idx.size, _evaluator(pr, items, rho, local=False),
                              right=np.full(idx.size, np.pi), n_grid=ng, max_rounds=0,
                              max_intervals=max_intervals, refine=pr.ok)
        v = verdict_codes(bb.status)
        mn, am, ne_ = bb.minimum, bb.argmin, bb.n_evals.copy()
        again = np.flatnonzero((v == INCONCLUSIVE) & pr.ok)
        sizes = _grid_for(rho[again], ng, _MAX_GRID)
        for g in np.unique(sizes):
            grp = again[sizes == g]
            b2 = branch_and_bound(grp.size, _evaluator(pr, grp, np.zeros(grp.size)),
                                  right=np.full(grp.size, np.pi), n_grid=int(g),
                                  max_rounds=max_rounds, max_intervals=max_intervals)
            v[grp] = verdict_codes(b2.status)
            better = b2.minimum < mn[grp]
            mn[grp] = np.where(better, b2.minimum, mn[grp])
            am[grp] = np.where(better, b2.argmin, am[grp])
            ne_[grp] += b2.n_evals
        v[~pr.ok & (v == CERTIFIED)] = INCONCLUSIVE
        verdict[idx], margin[idx], argmin[idx], n_evals[idx] = v, mn, am, ne_
    return verdict, margin, argmin, n_evals, grid


# ---------------------------------------------------------------------------
# The verdicts alone
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class MultirateCheck(Check):
    """The multi-rate certificate's verdicts alone (:func:`check_kernel`).

    A :class:`~stringstab.certify.verdicts.Check` whose ``hurwitz`` is Schur stability of the
    lifted A (iff Δ(z) is Schur), ``margin`` the smallest λ_min(M(θ)) found,
    ``witness_theta`` in rad per message period and ``witness_omega`` = θ/(NH) rad/s; with
    ``message_period`` (s) and ``message_steps`` (N).
    """

    message_period: float | None = None
    message_steps: int | None = None


def check_kernel(kx: Array, kv: Array, ka: Array, p: Params, H: float, N: int, *,
                 n_grid: int | None = None, max_rounds: int = 30,
                 max_intervals: int = 1024) -> MultirateCheck:
    """The multi-rate verdicts alone (inputs checked by :func:`stringstab.certify.check`).

    Parameters
    ----------
    kx, kv, ka : ndarray of float64
        The gains, finite, one-dimensional, of one length.
    p : Params
        τ, δ, T*.
    H : float
        The control period, s.
    N : int
        Steps per message period.
    n_grid, max_rounds, max_intervals : int
        As for :func:`decide`.

    Returns
    -------
    MultirateCheck
    """
    d = decide(kx, kv, ka, p, H, N, n_grid=n_grid, max_rounds=max_rounds,
               max_intervals=max_intervals)
    return MultirateCheck(names(d.verdict), d.sure, d.margin, d.argmin / (N * H),
                          sample_time=H, witness_theta=d.argmin, message_period=N * H,
                          message_steps=N)


# ---------------------------------------------------------------------------
# The certificate and its result types
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class MultirateCertificate(SingleResult):
    """The multi-rate certificate of one gain triple.

    Attributes
    ----------
    k_x, k_v, k_a : float
        The gains.
    params : Params
        τ, δ, T*.
    sample_time : float
        H (control and radar period), s.
    message_period : float
        N·H, s.
    message_steps : int
        N.
    message_phase : int
        φ (recorded; the certificate holds for every phase).
    schur : bool
        The lifted A is Schur (Δ(z) is).
    spectral_radius : float
        max |root| of Δ(z) (the lifted A's is its N-th power, or e^{−NH/τ}).
    verdict : str
        ``"certified"``, ``"not_certified"`` or ``"inconclusive"``.
    sup_gain : float
        sup_θ σ_max(G(e^{jθ})) (the ℓ2-induced gain of the link) found, ``inf`` when not Schur.
    linf_gain : float
        The same regardless of stability.
    peak_theta, peak_omega : float
        Where: θ in rad per message period and θ/(NH) in rad/s.
    margin : float
        Smallest λ_min(M(θ)) found (≥ 0 everywhere iff σ_max ≤ 1).
    n_evals : int
        Points evaluated.
    fallback_k_x, fallback_k_v : float
        The fallback (ACC, k_a = 0) gains.
    fallback_verdict : str
        The sampled certificate of the fallback loop.
    fallback_sup_gain : float
        Its sup|H| (``inf`` when not Schur).
    """

    k_x: float
    k_v: float
    k_a: float
    params: Params
    sample_time: float
    message_period: float
    message_steps: int
    message_phase: int
    schur: bool
    spectral_radius: float
    verdict: str
    sup_gain: float
    linf_gain: float
    peak_theta: float
    peak_omega: float
    margin: float
    n_evals: int
    fallback_k_x: float
    fallback_k_v: float
    fallback_verdict: str
    fallback_sup_gain: float


#: The columns of the human table (``stringstab certify --message-period``).
TABLE_COLUMNS: list[TableColumn] = [
    *ROW_COLUMNS,
    TableColumn("schur", "schur"),
    TableColumn("ρ(Δ)", "spectral_radius", "%.4g"),
    TableColumn("verdict", "verdict"),
    TableColumn("sup σ(G)", "sup_gain", "%.6g", missing="inf"),
    TableColumn("ω_peak[rad/s]", "peak_omega", "%.4g"),
    TableColumn("θ_peak[rad/msg]", "peak_theta", "%.4g"),
    TableColumn("margin", "margin", "%.3g"),
    TableColumn("fallback", "fallback_verdict"),
    TableColumn("fallback sup|H|", "fallback_sup_gain", "%.6g", missing="inf"),
]


@dataclass(frozen=True)
class MultirateCertificateBatch(BatchResult):
    """Multi-rate certificates of many triples (fields of :class:`MultirateCertificate`)."""

    SINGLE: ClassVar[type[MultirateCertificate]] = MultirateCertificate
    SHARED: ClassVar[tuple[str, ...]] = ("params", "sample_time", "message_period",
                                         "message_steps", "message_phase")
    TABLE: ClassVar[Sequence[TableColumn]] = TABLE_COLUMNS

    k_x: Array
    k_v: Array
    k_a: Array
    params: Params
    sample_time: float
    message_period: float
    message_steps: int
    message_phase: int
    schur: npt.NDArray[np.bool_]
    spectral_radius: Array
    verdict: npt.NDArray[np.str_]
    sup_gain: Array
    linf_gain: Array
    peak_theta: Array
    peak_omega: Array
    margin: Array
    n_evals: npt.NDArray[np.int64]
    fallback_k_x: Array
    fallback_k_v: Array
    fallback_verdict: npt.NDArray[np.str_]
    fallback_sup_gain: Array

    def __getitem__(self, i: int) -> MultirateCertificate:
        return super().__getitem__(i)  # type: ignore[no-any-return]

    @property
    def stable(self) -> npt.NDArray[np.bool_]:  # type: ignore[override]
        """Internally stable (the lifted A Schur, surely): :attr:`schur`."""
        return self.schur

    @property
    def box(self) -> Box:
        """The parameters as a (point) box."""
        return Box.of(self.params)

    def columns(self) -> dict[str, Any]:
        """The result columns, one row per triple, with the (point) box group.

        Returns
        -------
        dict
            Column name to ndarray; ``box`` maps to a dict of ndarrays.

        Examples
        --------
        >>> from stringstab.params import Params
        >>> b = certify_kernel(np.array([1.2]), np.array([0.5]), np.array([0.6]),
        ...                    Params(0.1, 0.2, 1.1), 0.1, 2)
        >>> c = b.columns()
        >>> c["verdict"].tolist(), c["message_period"].tolist(), c["fallback_verdict"].tolist()
        (['certified'], [0.2], ['certified'])
        """
        n = len(self)
        return {
            "k_x": self.k_x, "k_v": self.k_v, "k_a": self.k_a, "schur": self.schur,
            "spectral_radius": self.spectral_radius, "verdict": self.verdict,
            "sup_gain": self.sup_gain, "linf_gain": self.linf_gain,
            "peak_omega": self.peak_omega, "peak_theta": self.peak_theta, "margin": self.margin,
            "fallback_k_x": self.fallback_k_x, "fallback_k_v": self.fallback_k_v,
            "fallback_verdict": self.fallback_verdict,
            "fallback_sup_gain": self.fallback_sup_gain,
            "sample_time": np.full(n, self.sample_time),
            "message_period": np.full(n, self.message_period),
            "message_steps": np.full(n, self.message_steps),
            "message_phase": np.full(n, self.message_phase),
            "box": self.box.columns(n),
        }

    def summary_extra(self) -> dict[str, Any]:
        """The sample time, the message schedule, the (point) box and the scope."""
        return {"sample_time": self.sample_time, "message_period": self.message_period,
                "message_steps": self.message_steps, "message_phase": self.message_phase,
                "box": self.box.as_dict(), "not_covered": SCOPE}


MultirateCertificate.BATCH = MultirateCertificateBatch


def certify_kernel(
    kx: Array, kv: Array, ka: Array, p: Params, H: float, N: int, *, phase: int = 0,
    fallback: tuple[float, float] | None = None, chunk: int = 1024,
    n_grid: int | None = None, max_rounds: int = 30, max_intervals: int = 1024,
    progress: bool = False,
) -> MultirateCertificateBatch:
    """The multi-rate certificates of many triples (inputs checked by the way in).

    Parameters
    ----------
    kx, kv, ka : ndarray of float64
        The gains, finite, one-dimensional, of one length.
    p : Params
        τ, δ, T*.
    H : float
        The control period, s.
    N : int
        Steps per message period (≥ 1).
    phase : int
        The message phase φ (recorded).
    fallback : (float, float), optional
        The fallback (ACC) gains (k_x, k_v); default each triple's own with k_a = 0.
    chunk : int
        Triples per vectorised chunk.
    n_grid, max_rounds, max_intervals : int
        As for :func:`decide`.
    progress : bool
        Show a tqdm progress bar over chunks.

    Returns
    -------
    MultirateCertificateBatch
    """
    from .sampled import certify_kernel as sampled_kernel

    n = kx.size
    verdict = np.empty(n, dtype=np.int8)
    margin = np.empty(n)
    n_evals = np.empty(n, dtype=np.int64)
    sup = np.ones(n)
    peak = np.zeros(n)
    sure = np.empty(n, dtype=bool)
    rad = np.empty(n)
    for sl in chunks(n, chunk, progress=progress, desc="certify (multi-rate)"):
        d = decide(kx[sl], kv[sl], ka[sl], p, H, N, n_grid=n_grid, max_rounds=max_rounds,
                   max_intervals=max_intervals)
        verdict[sl], margin[sl], n_evals[sl], sure[sl] = d.verdict, d.margin, d.n_evals, d.sure
        rad[sl] = spectral_radius_of(d.delta) if d.rho is None else d.rho
        need = np.flatnonzero(d.verdict != CERTIFIED)
        if need.size:
            s_, w_ = lifted_peak(d.link.take(need), d.grid[need], d.argmin[need])
            sup[sl][need], peak[sl][need] = s_, w_
    fx = kx if fallback is None else np.full(n, float(fallback[0]))
    fv = kv if fallback is None else np.full(n, float(fallback[1]))
    if p.reaction_delay:  # the fallback loop has the same θ_r (docs/sampled.md §10.5)
        fb_verdict, fb_sup = _reaction_fallback(fx, fv, p, H)
    else:
        fb = sampled_kernel(fx, fv, np.zeros(n), p, H, p.tau, chunk=4096)
        fb_verdict, fb_sup = fb.verdict, fb.sup_gain
    return MultirateCertificateBatch(
        k_x=kx, k_v=kv, k_a=ka, params=p, sample_time=H, message_period=N * H,
        message_steps=N, message_phase=phase, schur=sure, spectral_radius=rad,
        verdict=names(verdict), sup_gain=np.where(sure, sup, np.inf), linf_gain=sup,
        peak_theta=peak, peak_omega=peak / (N * H), margin=margin, n_evals=n_evals,
        fallback_k_x=fx, fallback_k_v=fv, fallback_verdict=fb_verdict,
        fallback_sup_gain=fb_sup)


def _reaction_fallback(fx: Array, fv: Array, p: Params, H: float,
                       ) -> tuple[npt.NDArray[np.str_], Array]:
    """The fallback (ACC) loop with θ_r > 0: the sampled θ_r certificate's decision.

    :func:`decide` at N = 1 with the grid of :data:`stringstab.certify.sampled_reaction.GRID`
    (32) is that certificate's decision operation for operation; the peak (reporting) is
    located by :func:`stringstab.certify.lifted_peak.lifted_peak`.
    """
    d = decide(fx, fv, np.zeros(fx.size), p, H, 1, n_grid=32)
    sup = np.ones(fx.size)
    need = np.flatnonzero((d.verdict != CERTIFIED) & d.sure)
    if need.size:
        sup[need] = lifted_peak(d.link.take(need), d.grid[need], d.argmin[need])[0]
    return names(d.verdict), np.where(d.sure, sup, np.inf)
