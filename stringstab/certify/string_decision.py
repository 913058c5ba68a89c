"""The branch and bound of the head-to-tail certificate on any string loop: :func:`decide`.

For strings of one length (the items of a :class:`~stringstab.certify.head_to_tail.StringLoop`:
the continuous loop :class:`~stringstab.certify.head_to_tail.ContinuousString` or the sampled
one :class:`~stringstab.certify.head_to_tail_sampled.SampledString`), the one branch and bound
(:mod:`stringstab.certify.branch_bound`) decides G ≥ 0 on each item's domain: the point values
of G and their round-off bound (:func:`~stringstab.certify.head_to_tail.point_margin`), and
M ≥ |G''| on each interval from jets (:func:`~stringstab.certify.head_to_tail.string_margin`
on :class:`~stringstab.certify.interval_jets.Jet`).  Items whose vehicles are not all surely
internally stable take the verdict of their stability (module docstring of
:mod:`stringstab.certify.head_to_tail`).  A witness at ω = 0 (G(0) < 0) is moved to the
largest ω = h 2^−k with G < −slack, so it names a frequency where the product exceeds 1; and
sup ∏|Γ_i| is searched from the grid and the witness (reporting only).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .branch_bound import BranchAndBound, branch_and_bound, verdict_codes, zoom_max
from .head_to_tail import Index, StringLoop, point_margin, string_margin
from .interval import Interval
from .interval_jets import Jet
from .verdicts import INCONCLUSIVE, NOT_CERTIFIED

__all__ = ["StringDecision", "decide"]

Array = npt.NDArray[np.float64]


@dataclass
class StringDecision:
    """The head-to-tail verdicts of many strings of one length (codes) and what was found.

    Attributes
    ----------
    verdict : ndarray of int8
        Verdict codes (:data:`stringstab.certify.verdicts.VERDICTS`).
    stable, unstable : ndarray of bool
        Every vehicle surely internally stable; some vehicle surely not.
    right : ndarray
        The domain's right end (Ω in rad/s, or π in rad/sample).
    minimum, argmin : ndarray
        The smallest normalised G found, and a witness of a violation (where G < −slack: at
        ω > 0 whenever one is found, also when the smallest G is at 0).
    sup_gain, peak : ndarray
        sup ∏|Γ_i| found and where (reporting only; ``inf`` when not internally stable).
    n_evals : ndarray of int
        Points evaluated per string.
    """

    verdict: npt.NDArray[np.int8]
    stable: npt.NDArray[np.bool_]
    unstable: npt.NDArray[np.bool_]
    right: Array
    minimum: Array
    argmin: Array
    sup_gain: Array
    peak: Array
    n_evals: npt.NDArray[np.int64]


def _evaluator(loop: StringLoop) -> Callable[[Index, Array], tuple[Array, Array, Array, Array]]:
    def evaluate(idx: Index, X: Array) -> tuple[Array, Array, Array, Array]:
        val, slack, _ = point_margin(loop.parts(idx, Interval(X)), loop.scale[:, idx][:, :, None])
        M = string_margin(loop.factors(idx, Jet.variable(X[:, :-1], X[:, 1:]))).bound2()
        ok = np.isfinite(val) & np.isfinite(slack)
        # an overflow or NaN is never a witness and never settles an interval
        point = np.where(ok, val, np.inf)
        low = np.where(ok, val, -np.inf)
        slack = np.where(ok, slack, np.inf)
        M = np.where(np.isfinite(M), M, np.inf)
        return point, low, slack, M

    return evaluate


def _gain_squared(loop: StringLoop, idx: Index, X: Array) -> Array:
    """∏ n_i/d_i = ∏ |Γ_i|² at the points X (rows: the items idx); NaN where a d_i = 0."""
    return point_margin(loop.parts(idx, Interval(X)), loop.scale[:, idx][:, :, None])[2]


def decide(loop: StringLoop, *, n_grid: int, max_rounds: int = 30,
           max_intervals: int = 4096, peaks: bool = True) -> StringDecision:
    """The head-to-tail verdict of every item of ``loop`` (module docstring).

    Parameters
    ----------
    loop : StringLoop
        The strings and their loop.
    n_grid : int
        Initial intervals on each item's domain.
    max_rounds, max_intervals : int
        Refinement rounds, and the undecided intervals per string beyond which it is
        inconclusive.
    peaks : bool
        Also search sup ∏|Γ_i| (reporting only); else ``sup_gain`` is 1 for certified strings
        and NaN for the others.

    Returns
    -------
    StringDecision
    """
    n = loop.arrays.count
    sure, fail = loop.stability()
    right = np.asarray(loop.right(), dtype=float)
    bb: BranchAndBound = branch_and_bound(n, _evaluator(loop), right=right, n_grid=n_grid,
                                          max_rounds=max_rounds, max_intervals=max_intervals,
                                          refine=~fail)
    v = verdict_codes(bb.status)
    argmin = bb.argmin.copy()
    at0 = np.flatnonzero((v == NOT_CERTIFIED) & (argmin == 0))
    if at0.size:  # G(0) < 0: a positive witness close to 0, where the product itself exceeds 1
        argmin[at0] = _positive_witness(loop, at0, right[at0] / n_grid)
    v[~sure] = np.where(fail[~sure], NOT_CERTIFIED, INCONCLUSIVE)
    sup = np.where(v == 0, 1.0, np.nan)
    peak = np.zeros(n)
    need = np.flatnonzero(v != 0)
    if peaks and need.size:
        sup[need], peak[need] = _peak(loop, need, bb.grid_x[need], argmin[need], right[need])
    sup = np.where(sure, sup, np.inf)
    return StringDecision(v, sure, fail, right, bb.minimum, argmin, sup, peak, bb.n_evals)


def _positive_witness(loop: StringLoop, idx: Index, h: Array) -> Array:
    """The largest of h·2^−k (k = 0..40) with G < −slack, per item (0 where none is found)."""
    X = h[:, None] * 2.0 ** -np.arange(41.0)[None, :]
    val, slack, _ = point_margin(loop.parts(idx, Interval(X)), loop.scale[:, idx][:, :, None])
    ok = val < -slack
    first = np.argmax(ok, axis=1)
    return np.where(ok.any(axis=1), X[np.arange(idx.size), first], 0.0)


def _peak(loop: StringLoop, idx: Index, W: Array, worst: Array,
          right: Array) -> tuple[Array, Array]:
    """sup ∏|Γ_i| on the grid and at the witness, refined locally (reporting only)."""
    Wall = np.concatenate([W, worst[:, None]], axis=1)
    G2 = _gain_squared(loop, idx, Wall)
    G2 = np.where(np.isnan(G2), np.inf, G2)
    j = np.argmax(G2, axis=1)
    rows = np.arange(idx.size)
    best, bw = zoom_max(lambda X: _gain_squared(loop, idx, X), Wall[rows, j], G2[rows, j],
                        right / max(W.shape[1] - 1, 1), lo=0.0, hi=float(right.max()))
    at_zero = ~(best > 1.0)  # Γ_i(0) = 1: the product reaches 1 at ω = 0
    return np.sqrt(np.where(at_zero, 1.0, best)), np.where(at_zero, 0.0, bw)
