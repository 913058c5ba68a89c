"""The largest certified V2V message period of gain triples (``certify --max-message-period``).

**Definition.**  For a loop sampled every H seconds and a cap N_max (steps), the largest
certified message period of a triple is P* = N*·H with N* the largest N ≤ N_max such that
the loop is certified for *every* message period N'·H, N' = 1 … N (0 when not even N = 1,
messages every step, is certified).  Every period up to P* is then proven string stable —
the guarantee a designer needs when the radio may run slower than planned (a CAM rate
that drops from 10 Hz to 5 Hz) — while "the largest certified N" alone would not be: the
certified set of N need not be an interval (a lifted link can be certified at N = 4 and
not at N = 3, docs/sampled.md §9.6 reports how often this happens on the IDL range).  The
first N that fails is reported with its verdict (``not_certified``: a proven violation at
that period; ``inconclusive``: neither proven).

Each N is decided by the way in (:class:`stringstab.certify.api.Loop`: N = 1 by the sampled
certificate, N ≥ 2 by the multi-rate one), only for the triples still certified for every
smaller N.
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
from ..params import Box, Params
from .api import Loop, gains
from .multirate import SCOPE
from .verdicts import CERTIFIED, ROW_COLUMNS, BatchResult, SingleResult, codes, names

__all__ = ["DEFAULT_CAP", "MessagePeriod", "MessagePeriodBatch", "largest_message_period"]

Array = npt.NDArray[np.float64]

#: The default cap on the message period, s (2 Hz, the slowest rate issue 26 asks about).
DEFAULT_CAP = 0.5


@dataclass(frozen=True)
class MessagePeriod(SingleResult):
    """The largest certified message period of one triple (module docstring).

    Attributes
    ----------
    k_x, k_v, k_a : float
        The gains.
    params : Params
        τ, δ, T*.
    sample_time : float
        H, s.
    cap : float
        The largest message period examined, s (N_max·H).
    verdict : str
        ``"certified"`` for every message period up to the cap, else the verdict of the first
        period that is not certified.
    max_message_steps : int
        N* (0: not certified even with a message every step).
    max_message_period : float
        N*·H, s.
    first_failure_period : float
        (N* + 1)·H, s, or NaN when every period up to the cap is certified.
    """

    k_x: float
    k_v: float
    k_a: float
    params: Params
    sample_time: float
    cap: float
    verdict: str
    max_message_steps: int
    max_message_period: float
    first_failure_period: float


#: The columns of the human table.
TABLE_COLUMNS: list[TableColumn] = [
    *ROW_COLUMNS,
    TableColumn("max period[s]", "max_message_period", "%.4g"),
    TableColumn("N*", "max_message_steps", "%d"),
    TableColumn("first failure[s]", "first_failure_period", "%.4g", missing="-"),
    TableColumn("verdict", "verdict"),
]


@dataclass(frozen=True)
class MessagePeriodBatch(BatchResult):
    """Largest certified message periods of many triples (fields of :class:`MessagePeriod`)."""

    SINGLE: ClassVar[type[MessagePeriod]] = MessagePeriod
    SHARED: ClassVar[tuple[str, ...]] = ("params", "sample_time", "cap")
    TABLE: ClassVar[Sequence[TableColumn]] = TABLE_COLUMNS

    k_x: Array
    k_v: Array
    k_a: Array
    params: Params
    sample_time: float
    cap: float
    verdict: npt.NDArray[np.str_]
    max_message_steps: npt.NDArray[np.int64]
    max_message_period: Array
    first_failure_period: Array

    @property
    def stable(self) -> npt.NDArray[np.bool_]:  # type: ignore[override]
        """Certified for every message period up to the cap (the protocol's name)."""
        return self.certified

    def columns(self) -> dict[str, Any]:
        """The result columns, one row per triple, with the (point) box group.

        Returns
        -------
        dict
            Column name to ndarray.
        """
        n = len(self)
        return {"k_x": self.k_x, "k_v": self.k_v, "k_a": self.k_a, "verdict": self.verdict,
                "max_message_period": self.max_message_period,
                "max_message_steps": self.max_message_steps,
                "first_failure_period": self.first_failure_period,
                "sample_time": np.full(n, self.sample_time), "cap": np.full(n, self.cap),
                "box": Box.of(self.params).columns(n)}

    def summary_extra(self) -> dict[str, Any]:
        """The sample time, the cap, the (point) box and the scope."""
        return {"sample_time": self.sample_time, "cap": self.cap,
                "box": Box.of(self.params).as_dict(), "not_covered": SCOPE}


MessagePeriod.BATCH = MessagePeriodBatch


def largest_message_period(loop: Loop, k_x: npt.ArrayLike, k_v: npt.ArrayLike,
                           k_a: npt.ArrayLike, *, cap: float = DEFAULT_CAP) -> MessagePeriodBatch:
    """The largest certified message period of each triple, up to ``cap`` (module docstring).

    Parameters
    ----------
    loop : Loop
        A checked sampled loop (point parameters and a sample time H; no message period).
    k_x, k_v, k_a : array_like
        Gains, broadcast together and flattened (checked here).
    cap : float
        The largest message period examined, s (≥ H); N_max = ⌊cap/H⌋ (within 10⁻⁹ H).

    Returns
    -------
    MessagePeriodBatch

    Raises
    ------
    StringStabError
        For a loop that is not a sampled point loop, or a cap that is not a number ≥ H.

    Examples
    --------
    >>> b = largest_message_period(Loop.of(0.1, 0.2, 1.1, sample_time=0.1), [1.2], [0.5], [0.6],
    ...                            cap=0.5)
    >>> b.max_message_period.tolist(), b.verdict.tolist()
    ([0.2], ['not_certified'])
    """
    if loop.kind != "sampled" or not isinstance(loop.model, Params) or loop.sample_time is None:
        raise StringStabError("the largest certified message period is for the sampled loop at "
                              f"one τ, δ, T* (a sample time, no message period); got a {loop.kind} loop")
    H = loop.sample_time
    try:
        c = float(cap)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"the message-period cap must be a number of seconds >= the sample "
                              f"time {H:g} s; got {cap!r}") from e
    if not np.isfinite(c) or c < H * (1 - 1e-9):
        raise StringStabError(f"the message-period cap must be a number of seconds >= the sample "
                              f"time {H:g} s; got {cap!r}")
    n_max = int(np.floor(c / H + 1e-9))
    kx, kv, ka = gains(k_x, k_v, k_a)
    n = kx.size
    best = np.zeros(n, dtype=np.int64)
    verdict = np.full(n, CERTIFIED, dtype=np.int8)
    alive = np.arange(n)
    for N in range(1, n_max + 1):
        if not alive.size:
            break
        lp = dataclasses.replace(loop, message_steps=N if N > 1 else None)
        v = codes(lp.check(kx[alive], kv[alive], ka[alive]).verdict)
        ok = v == CERTIFIED
        best[alive[ok]] = N
        verdict[alive[~ok]] = v[~ok]
        alive = alive[ok]
    # N·H as written (0.3, not 0.30000000000000004): twelve digits of the product
    fail = np.where(verdict != CERTIFIED, np.round((best + 1) * H, 12), np.nan)
    return MessagePeriodBatch(kx, kv, ka, loop.model, H, round(n_max * H, 12), names(verdict),
                              best, np.round(best * H, 12), fail)
