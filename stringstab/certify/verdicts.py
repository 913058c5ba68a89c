"""The verdicts of every certificate and the protocol of their results: one home.

Every certificate of the toolkit — continuous time (:mod:`stringstab.certify.continuous`), sampled
data (:mod:`stringstab.certify.sampled`) and robust over a parameter box (:mod:`stringstab.certify.robust`) —
answers with the same three verdicts, :data:`VERDICTS`, and returns its results in the same
shape:

* a *batch* (one array per field, one row per gain triple) that owns its columns
  (``columns()``, written by :func:`stringstab.io.write_results`), its rows (``records()``)
  and its totals (``summary()``: counts per verdict and the share of rows certified), and
* a *single* result (one triple; ``batch[i]``) whose ``as_dict()`` is that triple's row.

:class:`BatchResult` and :class:`SingleResult` implement this protocol once; :class:`Check`
is the verdict-only answer of the ``check`` functions (for inner loops such as gain repair).
This module imports NumPy and the writer's column helpers only (no SymPy), so every
certificate imports it at no cost.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..io import TableColumn, records_from_columns

__all__ = [
    "CERTIFIED",
    "INCONCLUSIVE",
    "NOT_CERTIFIED",
    "ROUNDOFF_SLACK",
    "ROW_COLUMNS",
    "VERDICTS",
    "BatchResult",
    "Check",
    "SingleResult",
    "Verdict",
    "chunks",
    "codes",
    "names",
    "num",
    "one_triple",
    "verdict_summary",
]

Array = npt.NDArray[np.float64]

class Verdict(str, enum.Enum):
    """The answer of every certificate: the one verdict vocabulary of the toolkit.

    A ``Verdict`` is a ``str`` (``Verdict.CERTIFIED == "certified"``), so it is written to
    JSON, CSV and tables as its value; arrays of verdicts hold its :attr:`code` (int8), the
    position in :data:`VERDICTS`.

    * ``certified`` — internally stable and ‖Γ‖_H∞ ≤ 1 with the exact delay, proven (IDL
      Definition 1, eq 10);
    * ``not_certified`` — proven not string stable (|Γ(jω)| > 1 at a frequency reported with
      the result) or not internally stable;
    * ``inconclusive`` — neither could be proven within the budget.
    """

    CERTIFIED = "certified"
    NOT_CERTIFIED = "not_certified"
    INCONCLUSIVE = "inconclusive"

    # written as the value, as enum.StrEnum (Python 3.11) does
    def __str__(self) -> str:
        return str.__str__(self)

    def __format__(self, format_spec: str) -> str:
        return str.__format__(str(self), format_spec)

    @property
    def words(self) -> str:
        """The verdict in words, for legends and class names (``"not certified"``)."""
        return self.value.replace("_", " ")

    @property
    def code(self) -> int:
        """The verdict's code: its position in :data:`VERDICTS` (0, 1 or 2)."""
        return VERDICTS.index(self)

    @classmethod
    def of_code(cls, code: int) -> Verdict:
        """The verdict of a code (0 certified, 1 not certified, 2 inconclusive).

        Parameters
        ----------
        code : int
            A verdict code.

        Returns
        -------
        Verdict
            ``VERDICTS[code]``.
        """
        if not 0 <= int(code) < len(VERDICTS):
            raise StringStabError(f"a verdict code is 0, 1 or 2; got {code!r}")
        return VERDICTS[int(code)]


#: The three verdicts in code order: 0 certified, 1 not certified, 2 inconclusive.
VERDICTS: tuple[Verdict, Verdict, Verdict] = (Verdict.CERTIFIED, Verdict.NOT_CERTIFIED,
                                              Verdict.INCONCLUSIVE)
#: The verdict codes of arrays of verdicts (:attr:`Verdict.code`).
CERTIFIED, NOT_CERTIFIED, INCONCLUSIVE = (v.code for v in VERDICTS)

#: Relative round-off slack of every certificate's comparisons: each bound on a margin is
#: widened by this factor times the sum of the absolute values of its terms (hundreds of ulps).
ROUNDOFF_SLACK = 1e-13

#: The first columns of every certificate's human table: the input row's time and vehicle
#: (when the input has them) and the gains.
ROW_COLUMNS: tuple[TableColumn, ...] = (
    TableColumn("t", "t"),
    TableColumn("vehicle", "vehicle"),
    TableColumn("k_x", "k_x"),
    TableColumn("k_v", "k_v"),
    TableColumn("k_a", "k_a"),
)


def names(codes: npt.ArrayLike) -> npt.NDArray[np.str_]:
    """Verdict codes (0, 1, 2) as their names.

    Parameters
    ----------
    codes : array_like of int
        Verdict codes: 0 certified, 1 not certified, 2 inconclusive.

    Returns
    -------
    ndarray of str
        The names from :data:`VERDICTS`, of the shape of ``codes``.

    Examples
    --------
    >>> names([0, 2]).tolist()
    ['certified', 'inconclusive']
    """
    return np.array(VERDICTS)[np.asarray(codes, dtype=np.intp)]


def codes(verdict: npt.ArrayLike) -> npt.NDArray[np.int8]:
    """Verdict names as their codes (the inverse of :func:`names`).

    Parameters
    ----------
    verdict : array_like of str
        Verdict names (``"certified"``, ``"not_certified"``, ``"inconclusive"``).

    Returns
    -------
    ndarray of int8
        The codes (:attr:`Verdict.code`), of the shape of ``verdict``.

    Raises
    ------
    StringStabError
        If a name is not a verdict.

    Examples
    --------
    >>> codes(["inconclusive", "certified"]).tolist()
    [2, 0]
    """
    v = np.asarray(verdict)
    out = np.full(v.shape, -1, dtype=np.int8)
    for w in VERDICTS:
        out[v == w.value] = w.code
    if (out < 0).any():
        raise StringStabError(f"verdicts are {[w.value for w in VERDICTS]}; "
                              f"got {v[out < 0].ravel()[0]!r}")
    return out


def num(x: float) -> float | None:
    """``x`` as a float, or None when it is not finite (a JSON row's ``null``).

    Parameters
    ----------
    x : float
        Any real number.

    Returns
    -------
    float or None
        ``float(x)``, or None for NaN and ±inf.
    """
    return float(x) if math.isfinite(x) else None


def verdict_summary(verdict: npt.NDArray[np.str_]) -> dict[str, Any]:
    """``n``, the count of each verdict and ``certified_row_share`` = certified / n (a fraction).

    The share of *rows* certified: each row counts once, however long its gains were in force.
    It is not m_fss (IDL eq 27, the share of vehicle-moments, which weighs each gain by the
    time it was in force; ``stringstab simulate --gains-file``): the two coincide only for rows
    sampled at one uniform step (docs/conventions.md).

    Parameters
    ----------
    verdict : ndarray of str
        Verdict names (``"certified"``, ``"not_certified"``, ``"inconclusive"``).

    Returns
    -------
    dict
        ``n``, one count per verdict and ``certified_row_share`` (NaN when ``n`` is 0).

    Examples
    --------
    >>> verdict_summary(np.array(["certified", "inconclusive"]))
    {'n': 2, 'certified': 1, 'not_certified': 0, 'inconclusive': 1, 'certified_row_share': 0.5}
    """
    n = int(np.size(verdict))
    counts = {v.value: int(np.count_nonzero(verdict == v)) for v in VERDICTS}
    return {"n": n, **counts,
            "certified_row_share": counts[Verdict.CERTIFIED.value] / n if n else float("nan")}


def one_triple(fn: str, batch_fn: str, **gains: Any) -> None:
    """Refuse arrays where a single-triple function takes scalars.

    Parameters
    ----------
    fn : str
        Name of the single-triple function, for the message.
    batch_fn : str
        Name of the batch function to suggest instead.
    **gains : object
        The gains as passed (``k_x=..., k_v=..., k_a=...``); each must be a scalar.

    Raises
    ------
    StringStabError
        Naming the gain that is an array and the batch function to use instead.
    """
    for name, v in gains.items():
        if np.ndim(v) != 0:
            raise StringStabError(
                f"{fn} takes one triple; {name} has shape {np.shape(v)}; use {batch_fn}")


def chunks(n: int, chunk: int, *, progress: bool = False, desc: str = "certify") -> Iterable[slice]:
    """Consecutive slices of ``chunk`` rows covering ``range(n)`` (with their ``progress``).

    Parameters
    ----------
    n : int
        Number of rows.
    chunk : int
        Rows per slice (the last may be shorter).
    progress : bool
        Report the chunks done (:class:`stringstab.progress.Progress`: a bar on a terminal,
        plain lines otherwise).
    desc : str
        Label of the progress.

    Yields
    ------
    slice
        ``slice(s, min(s + chunk, n))`` for s = 0, chunk, 2·chunk, …
    """
    if not progress:
        for s0 in range(0, n, chunk):
            yield slice(s0, min(s0 + chunk, n))
        return
    from ..progress import Progress  # a bar on a terminal, plain lines otherwise

    with Progress(math.ceil(n / chunk), desc, unit="chunks") as bar:
        for s0 in range(0, n, chunk):
            yield slice(s0, min(s0 + chunk, n))
            bar.update(1)


class SingleResult:
    """The certificate of one gain triple: ``certified`` and ``as_dict()`` (its batch row).

    A subclass is a frozen dataclass with the fields of its batch class (scalars where the
    batch has arrays), named by ``BATCH``.
    """

    verdict: str
    BATCH: ClassVar[type[BatchResult]]

    @property
    def certified(self) -> bool:
        """True iff the verdict is ``"certified"``."""
        return self.verdict == Verdict.CERTIFIED

    def as_dict(self) -> dict[str, Any]:
        """The JSON row of this triple: the batch's columns, non-finite numbers as None."""
        return self.BATCH.of_single(self).records()[0]


class BatchResult:
    """Certificates of many triples, as arrays: the protocol every batch result follows.

    A subclass is a frozen dataclass whose fields are per-triple arrays, except those named in
    ``SHARED`` (the same for every triple: parameters, sample time, box); ``SINGLE`` is the
    class of one row and ``TABLE`` the columns of its human table.  It defines
    :meth:`columns`; the rows and the totals follow.
    """

    k_x: Array
    verdict: npt.NDArray[np.str_]
    #: Internal stability of each triple's loop (Hurwitz, Schur, or every member of a box).
    stable: npt.NDArray[np.bool_]
    SINGLE: ClassVar[type[Any]]
    SHARED: ClassVar[tuple[str, ...]] = ()
    #: The columns of the batch type's human table (:meth:`table_columns`).
    TABLE: ClassVar[Sequence[TableColumn]] = ()

    def __len__(self) -> int:
        return int(self.k_x.size)

    @property
    def certified(self) -> npt.NDArray[np.bool_]:
        """Boolean array: verdict == "certified"."""
        return np.asarray(self.verdict == Verdict.CERTIFIED)

    def __getitem__(self, i: int) -> Any:
        values = {}
        for f in dataclasses.fields(self.SINGLE):
            v = getattr(self, f.name)
            values[f.name] = v if f.name in self.SHARED else np.asarray(v)[i].item()
        return self.SINGLE(**values)

    @classmethod
    def table_columns(cls) -> list[TableColumn]:
        """The columns of this result's human table (``stringstab certify --format table``).

        Each batch type names its own (the continuous, sampled and robust certificates report
        different quantities), so a caller renders any result without asking which loop it
        came from: ``write_results(b.columns(), ..., table=b.table_columns())``.

        Returns
        -------
        list of TableColumn
            Header, key into :meth:`columns` and format of each column, in order
            (``cls.TABLE``).
        """
        if not cls.TABLE:
            raise NotImplementedError(f"{cls.__name__} names no table columns")
        return list(cls.TABLE)

    @classmethod
    def of_single(cls, row: Any) -> Any:
        """The batch of one row (so that a single result renders through :meth:`columns`).

        Parameters
        ----------
        row : SingleResult
            One triple's result, of class ``cls.SINGLE``.

        Returns
        -------
        BatchResult
            A batch of length 1 (fields in ``SHARED`` kept as they are).
        """
        values = {}
        for f in dataclasses.fields(cls):  # type: ignore[arg-type]
            v = getattr(row, f.name)
            values[f.name] = v if f.name in cls.SHARED else np.asarray([v])
        return cls(**values)

    def columns(self) -> dict[str, Any]:  # pragma: no cover - every subclass defines it
        """The result columns (groups as nested mappings), for :func:`stringstab.io.write_results`."""
        raise NotImplementedError

    def records(self) -> list[dict[str, Any]]:
        """One JSON row per triple (non-finite numbers are None)."""
        return records_from_columns(self.columns())

    def summary_extra(self) -> dict[str, Any]:
        """What the summary adds to the counts (the sample time and the box, for example)."""
        return {}

    def summary(self) -> dict[str, Any]:
        """Counts per verdict and ``certified_row_share``, the share of rows certified (a fraction)."""
        return {**verdict_summary(self.verdict), **self.summary_extra()}


@dataclass(frozen=True)
class Check:
    """Verdicts only, with the witness of each triple that is not certified.

    Returned by :func:`stringstab.certify.api.check` for every loop (continuous, sampled,
    robust); the sampled and robust forms fill the optional fields.

    Attributes
    ----------
    verdict : ndarray of str
        ``"certified"``, ``"not_certified"`` or ``"inconclusive"``.
    hurwitz : ndarray of bool
        Internally stable, surely (outside the 10⁻¹² boundary band): Γ Hurwitz, the sampled
        Δ(z) Schur, or every member of the box so.
    margin : ndarray
        Smallest margin found (g(ω), or g_H(θ) when sampled).
    witness_omega : ndarray
        Where it was found, rad/s: for an internally stable, not-certified triple a
        frequency with |Γ(jω)| > 1 (|H(e^{jωH})| > 1 when sampled).
    sample_time : float or None
        H, s, for the sampled loop.
    witness_theta : ndarray or None
        The same frequency in rad/sample (θ = ωH), when sampled.
    witness_tau, witness_tau_prev, witness_delta, witness_headway : ndarray or None
        For a box: the member where the margin was found (or an unstable member).
    """

    verdict: npt.NDArray[np.str_]
    hurwitz: npt.NDArray[np.bool_]
    margin: Array
    witness_omega: Array
    sample_time: float | None = None
    witness_theta: Array | None = None
    witness_tau: Array | None = None
    witness_tau_prev: Array | None = None
    witness_delta: Array | None = None
    witness_headway: Array | None = None

    @property
    def stable(self) -> npt.NDArray[np.bool_]:
        """Internally stable (the same as :attr:`hurwitz`, named for every loop)."""
        return self.hurwitz

    @property
    def certified(self) -> npt.NDArray[np.bool_]:
        """Boolean array: verdict == "certified"."""
        return np.asarray(self.verdict == Verdict.CERTIFIED)
