"""Robust string-stability certificates over boxes of uncertain lag, delay and headway.

A gain triple is *robustly certified* for the box τ ∈ [τ_lo, τ_hi], δ ∈ [δ_lo, δ_hi],
T* ∈ [h_lo, h_hi] (any of them may be a point) when the certificate of
:mod:`stringstab.certify.continuous` (continuous time) or :mod:`stringstab.certify.sampled`
(sampled data, period H) holds for *every* member of the box.  Since a vehicle's transfer
function depends only on its own τ, δ, T* (and, sampled, its predecessor's lag), a
certificate over the box covers a heterogeneous platoon whose vehicles each lie in it:
every |Γ_i(jω)| ≤ 1, so the product along the platoon is ≤ 1 too.

This module holds the kernel the way in calls (:func:`certify_kernel`, through
:mod:`stringstab.certify.api`) and the result types; the certificates themselves are
:mod:`stringstab.certify.robust_continuous` (the exact minimum of g over the box at each ω,
:func:`robust_margin`) and :mod:`stringstab.certify.robust_sampled` (bisection of cells of
parameters, in the interval arithmetic of :mod:`stringstab.certify.interval`); a box with a
reaction delay θ_r ≠ (0, 0) goes to :mod:`stringstab.certify.robust_reaction` (continuous time
only; its results carry the witness member's θ_r, :class:`RobustReactionCertificateBatch`).

Verdicts: ``certified`` (proven for the whole box), ``not_certified`` (a member that is
not internally stable, or a member and a frequency with |Γ| > 1: the witness),
``inconclusive`` (neither within the budget).

References
----------
IDL paper, Definition 1 (eq 10) and eq 11 (derived form).
R. E. Moore, R. B. Kearfott, M. J. Cloud, *Introduction to Interval Analysis*, SIAM (2009).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..io import TableColumn
from ..params import Box
from .robust_continuous import certify_box_continuous
from .verdicts import (
    ROW_COLUMNS,
    BatchResult,
    Check,
    SingleResult,
    chunks,
    names,
)

__all__ = [
    "TABLE_COLUMNS",
    "RobustCertificate",
    "RobustCertificateBatch",
    "RobustReactionCertificate",
    "RobustReactionCertificateBatch",
    "certify_kernel",
    "check_of",
]

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class RobustCertificate(SingleResult):
    """The robust certificate of one gain triple over a parameter box.

    Attributes
    ----------
    k_x, k_v, k_a : float
        The gains.
    box : Box
        τ, δ, T* intervals.
    sample_time : float or None
        H for the sampled-data certificate; None for continuous time.
    heterogeneous : bool
        Sampled only: the predecessor's lag ranges over the τ box independently.
    stable : bool
        Every member is internally stable (Hurwitz / Schur), proven.
    verdict : str
        ``"certified"``, ``"not_certified"`` or ``"inconclusive"``.
    sup_gain : float
        1 when certified (every member's norm is exactly 1); otherwise |Γ| (or |H|) at
        the witness (a lower bound on the worst member's norm), ``inf`` when the witness
        is a member that is not internally stable.
    margin : float
        Smallest g (or g_H) found at a member (an upper bound on the box minimum).
    witness_tau, witness_tau_prev, witness_delta, witness_headway : float
        The member where it was found (or the unstable member); for a certified triple,
        the tightest member found.
    witness_omega, witness_theta : float
        Its frequency in rad/s (and in rad/sample when sampled; NaN otherwise).
    n_evals : int
        Evaluations used.
    sup_gain_excess : float
        ``sup_gain`` − 1 computed without cancellation: 0 when certified, > 0 when not
        certified and stable (also when ``sup_gain`` rounds to 1.0: the witness member's
        violation near ω → 0, the frequency then where it is attained), ``inf`` when the
        witness member is not internally stable.
    """

    k_x: float
    k_v: float
    k_a: float
    box: Box
    sample_time: float | None
    heterogeneous: bool
    stable: bool
    verdict: str
    sup_gain: float
    margin: float
    witness_tau: float
    witness_tau_prev: float
    witness_delta: float
    witness_headway: float
    witness_omega: float
    witness_theta: float
    n_evals: int = 0
    sup_gain_excess: float = float("nan")


#: The columns of the human table of robust certificates (``stringstab certify`` with an
#: interval).
TABLE_COLUMNS: list[TableColumn] = [
    *ROW_COLUMNS,
    TableColumn("stable", "stable"),
    TableColumn("verdict", "verdict"),
    TableColumn("sup gain at witness", "sup_gain", "%.6g", missing="inf"),
    TableColumn("sup gain-1", "sup_gain_excess", "%.3g", missing="inf"),
    TableColumn("ω[rad/s]", "witness.omega", "%.4g"),
    TableColumn("θ[rad/sample]", "witness.theta", "%.4g"),
    TableColumn("τ", "witness.tau", "%.4g"),
    TableColumn("τ_prev", "witness.tau_prev", "%.4g"),
    TableColumn("δ", "witness.delta", "%.4g"),
    TableColumn("T*", "witness.headway", "%.4g"),
    TableColumn("margin", "margin", "%.3g"),
]


@dataclass(frozen=True)
class RobustCertificateBatch(BatchResult):
    """Robust certificates of many triples, as arrays (fields of :class:`RobustCertificate`)."""

    SINGLE: ClassVar[type[RobustCertificate]] = RobustCertificate
    SHARED: ClassVar[tuple[str, ...]] = ("box", "sample_time", "heterogeneous")
    TABLE: ClassVar[Sequence[TableColumn]] = TABLE_COLUMNS

    k_x: Array
    k_v: Array
    k_a: Array
    box: Box
    sample_time: float | None
    heterogeneous: bool
    stable: npt.NDArray[np.bool_]
    verdict: npt.NDArray[np.str_]
    sup_gain: Array
    margin: Array
    witness_tau: Array
    witness_tau_prev: Array
    witness_delta: Array
    witness_headway: Array
    witness_omega: Array
    witness_theta: Array
    n_evals: npt.NDArray[np.int64]
    sup_gain_excess: Array


    def __getitem__(self, i: int) -> RobustCertificate:
        return super().__getitem__(i)  # type: ignore[no-any-return]

    def columns(self) -> dict[str, Any]:
        """The result columns, one row per triple, with the witness and box groups.

        The gains, ``stable`` (over the box), ``verdict``, ``sup_gain``, ``sup_gain_excess``
        and ``margin``; the ``witness`` group (``tau``, ``tau_prev``, ``delta``, ``headway``,
        ``omega``, ``theta``); then ``sample_time`` (NaN in continuous time),
        ``heterogeneous`` (sampled only) and the ``box`` group (``tau_lo``, ``tau_hi``, ...).

        Returns
        -------
        dict
            Column name to ndarray; ``witness`` and ``box`` map to dicts of ndarrays.

        Examples
        --------
        >>> from stringstab.certify.api import certify_batch
        >>> b = certify_batch([1.2], [0.5], [0.6], tau=(0.1, 0.3), delta=0.2, headway=1.1)
        >>> c = b.columns()
        >>> c["verdict"].tolist(), c["box"]["tau_hi"].tolist(), c["sample_time"].tolist()
        (['certified'], [0.3], [nan])
        """
        n = len(self)
        cols: dict[str, Any] = {
            "k_x": self.k_x, "k_v": self.k_v, "k_a": self.k_a, "stable": self.stable,
            "verdict": self.verdict, "sup_gain": self.sup_gain,
            "sup_gain_excess": self.sup_gain_excess, "margin": self.margin,
            "witness": {k: getattr(self, f"witness_{k}")
                        for k in ("tau", "tau_prev", "delta", "headway", "omega", "theta")},
            "sample_time": np.full(n, np.nan if self.sample_time is None else self.sample_time),
        }
        if self.sample_time is not None:
            cols["heterogeneous"] = np.full(n, self.heterogeneous)
        cols["box"] = self.box.columns(n)
        return cols

    def summary_extra(self) -> dict[str, Any]:
        """The sample time (None in continuous time), heterogeneity (sampled) and the box."""
        out: dict[str, Any] = {"sample_time": self.sample_time}
        if self.sample_time is not None:
            out["heterogeneous"] = self.heterogeneous
        return {**out, "box": self.box.as_dict()}


RobustCertificate.BATCH = RobustCertificateBatch


@dataclass(frozen=True)
class RobustReactionCertificate(RobustCertificate):
    """The robust certificate of one triple over a box that includes the reaction delay θ_r.

    The fields of :class:`RobustCertificate`, and the witness member's θ_r (issue 25, item 4).

    Attributes
    ----------
    witness_reaction_delay : float
        θ_r of the witness member, s.
    stability : str
        Internal stability over the box in three states: ``"stable"`` (proven: ``stable``),
        ``"unstable"`` (a member proven not) or ``"undecided"`` (the budget ran out)
        (:data:`stringstab.certify.robust_reaction.STABILITY`).
    """

    witness_reaction_delay: float = 0.0
    stability: str = "undecided"


#: The robust table with the witness member's θ_r.
REACTION_TABLE_COLUMNS: list[TableColumn] = [
    *(TableColumn("stability", "stability") if c.key == "stable" else c for c in TABLE_COLUMNS[:-1]),
    TableColumn("θ_r", "witness.reaction_delay", "%.4g"), TABLE_COLUMNS[-1],
]


@dataclass(frozen=True)
class RobustReactionCertificateBatch(RobustCertificateBatch):
    """Robust certificates over a box with θ_r: :class:`RobustCertificateBatch` plus θ_r."""

    SINGLE: ClassVar[type[RobustCertificate]] = RobustReactionCertificate
    TABLE: ClassVar[Sequence[TableColumn]] = REACTION_TABLE_COLUMNS

    witness_reaction_delay: Array = dataclasses.field(default_factory=lambda: np.zeros(0))
    stability: npt.NDArray[np.str_] = dataclasses.field(default_factory=lambda: np.zeros(0, str))

    def __getitem__(self, i: int) -> RobustReactionCertificate:
        return super().__getitem__(i)  # type: ignore[return-value]

    def columns(self) -> dict[str, Any]:
        """The columns of :meth:`RobustCertificateBatch.columns` with ``witness.reaction_delay``.

        Returns
        -------
        dict
            Column name to ndarray; ``witness`` and ``box`` map to dicts of ndarrays.
        """
        cols = super().columns()
        cols["witness"]["reaction_delay"] = self.witness_reaction_delay
        cols["stability"] = self.stability
        return cols


RobustReactionCertificate.BATCH = RobustReactionCertificateBatch


def certify_kernel(
    kx: Array, kv: Array, ka: Array, box: Box, H: float | None, *, heterogeneous: bool = True,
    chunk: int = 4096, n_grid: int | None = None, max_rounds: int = 30,
    max_intervals: int = 1024, max_splits: int = 48, max_cells: int = 4096,
    progress: bool = False,
) -> RobustCertificateBatch:
    """Certify gain triples for every τ, δ, T* in a box (module docstring).

    Inputs already checked by :func:`stringstab.certify.api.certify_batch` or
    :meth:`stringstab.certify.api.Loop.certify_batch` (the way in): nothing is validated
    again here.

    Parameters
    ----------
    kx, kv, ka : ndarray of float64
        The gains, finite, one-dimensional, of one length.
    box : Box
        The box of τ, δ, T* (checked on construction).
    H : float or None
        Sampling period H > 0 (s), or None for continuous time.
    heterogeneous : bool
        Sampled only: let the predecessor's lag range over the τ box independently of the
        follower's (a platoon of different vehicles); False ties it to τ.
    chunk : int
        Triples per vectorised chunk.
    n_grid, max_rounds, max_intervals : int
        Initial frequency intervals (default 64, or 64 + 8m sampled), refinement rounds per
        pass, and undecided intervals per item before it is inconclusive.
    max_splits, max_cells : int
        Sampled only: bisection passes of the parameter cells, and cells per triple,
        before the triple is inconclusive.
    progress : bool
        Show a tqdm progress bar over chunks.

    Returns
    -------
    RobustCertificateBatch
    """
    n = kx.size
    keys: tuple[str, ...] = ("verdict", "stable", "margin", "theta", "omega", "tau", "tau_prev",
                             "delta", "headway", "n_evals", "sup_gain", "sup_gain_excess")
    reacting = box.reaction_delay != (0.0, 0.0)
    if reacting:
        if H is not None:
            from .robust_reaction import sampled_box_refusal

            raise StringStabError(sampled_box_refusal(box, H))
        keys += ("reaction_delay", "stability")
    acc: dict[str, list[Array]] = {k: [] for k in keys}
    if H is not None:
        # the sampled loop's arithmetic is imported only when a sample time is given
        from .robust_sampled import certify_box_sampled
    for sl in chunks(n, chunk, progress=progress, desc="certify (robust)"):
        if reacting:  # θ_r over a box (issue 25): cells of the box, continuous time
            from .robust_reaction import certify_box_reaction

            r = certify_box_reaction(kx[sl], kv[sl], ka[sl], box, n_grid=n_grid or 64,
                                     max_rounds=max_rounds, max_intervals=max_intervals,
                                     max_splits=max_splits, max_cells=max_cells)
        elif H is None:
            r = certify_box_continuous(kx[sl], kv[sl], ka[sl], box, n_grid=n_grid or 64,
                                       max_rounds=max_rounds, max_intervals=max_intervals)
        else:
            r = certify_box_sampled(kx[sl], kv[sl], ka[sl], box, H, heterogeneous=heterogeneous,
                                    n_grid=n_grid, max_rounds=max_rounds,
                                    max_intervals=max_intervals, max_splits=max_splits,
                                    max_cells=max_cells)
        for k in keys:
            acc[k].append(np.asarray(r[k]))

    def cat(k: str, dtype: Any = float) -> Any:
        return np.concatenate(acc[k]).astype(dtype) if acc[k] else np.zeros(0, dtype=dtype)

    fields = dict(
        k_x=kx, k_v=kv, k_a=ka, box=box, sample_time=H, heterogeneous=bool(heterogeneous),
        stable=cat("stable", bool), verdict=names(cat("verdict", np.int8)),
        sup_gain=cat("sup_gain"), margin=cat("margin"), witness_tau=cat("tau"),
        witness_tau_prev=cat("tau_prev"), witness_delta=cat("delta"),
        witness_headway=cat("headway"), witness_omega=cat("omega"),
        witness_theta=cat("theta"), n_evals=cat("n_evals", np.int64),
        sup_gain_excess=cat("sup_gain_excess"),
    )
    if reacting:
        return RobustReactionCertificateBatch(**fields,
                                              witness_reaction_delay=cat("reaction_delay"),
                                              stability=cat("stability", str))
    return RobustCertificateBatch(**fields)


def check_of(b: RobustCertificateBatch) -> Check:
    """The verdict-only answer of a robust batch (what :func:`stringstab.certify.api.check` returns).

    Parameters
    ----------
    b : RobustCertificateBatch
        The robust certificates.

    Returns
    -------
    Check
        Verdict, stability, margin and witness (member and frequency) of each triple.
    """
    return Check(b.verdict, b.stable, b.margin, b.witness_omega, sample_time=b.sample_time,
                 witness_theta=None if b.sample_time is None else b.witness_theta,
                 witness_tau=b.witness_tau, witness_tau_prev=b.witness_tau_prev,
                 witness_delta=b.witness_delta, witness_headway=b.witness_headway)
