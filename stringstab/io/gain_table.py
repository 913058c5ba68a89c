"""The gain table and the checks every gain reader shares.

:class:`GainTable` holds gain triples K = [k_x, k_v, k_a] (IDL eq 4) read from one source, with
an optional time and vehicle per row; :func:`table_from_columns` builds it from the cells of a
text file, checking every cell (:func:`finite_number`), the columns (:func:`resolve_columns`,
with the close match of a misspelt name, :func:`suggest_name`) and the vehicle ids
(:func:`vehicle_ids`).  The readers of each format are :mod:`stringstab.io.gain_text` and
:mod:`stringstab.io.gain_arrays`; the one way in is :func:`stringstab.io.gains.read_gains`.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show

__all__ = [
    "GAIN_COLUMNS",
    "OPTIONAL_COLUMNS",
    "GainTable",
    "finite_number",
    "resolve_columns",
    "suggest_name",
    "table_from_columns",
    "vehicle_ids",
]

#: The three gain columns, in the order of K = [k_x, k_v, k_a] (IDL eq 4).
GAIN_COLUMNS: tuple[str, str, str] = ("k_x", "k_v", "k_a")
#: Optional columns of a gain time series: time in s and a vehicle id.
OPTIONAL_COLUMNS: tuple[str, str] = ("t", "vehicle")

Array = npt.NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class GainTable:
    """Gain triples read from one source, with an optional time and vehicle per row.

    Attributes
    ----------
    k_x, k_v, k_a : ndarray of float, shape (n,)
        The gains (finite).
    t : ndarray of float, shape (n,), or None
        Time stamps in s of a gain time series (finite), if given.
    vehicle : ndarray, shape (n,), or None
        Vehicle ids (integers, or strings when not all are integers), if given.
    source : str
        Where the gains came from (a file name or ``"<command line>"``).

    Examples
    --------
    >>> g = GainTable.from_triples([(0.9, -0.5, 1.1), (1.3, 0.0, 0.6)])
    >>> len(g), g.K.shape
    (2, (2, 3))
    >>> g.rows()[0]
    {'k_x': 0.9, 'k_v': -0.5, 'k_a': 1.1}
    """

    k_x: Array
    k_v: Array
    k_a: Array
    t: Array | None = None
    vehicle: npt.NDArray[Any] | None = None
    source: str = "<input>"
    ignored_columns: tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        n = len(self.k_x)
        for name in ("k_v", "k_a", "t", "vehicle"):
            a = getattr(self, name)
            if a is not None and len(a) != n:
                raise StringStabError(
                    f"{self.source}: {name} must have one entry per gain triple ({n}); "
                    f"found {len(a)}"
                )

    @classmethod
    def from_triples(
        cls, triples: Iterable[Sequence[float]], *, source: str = "<input>"
    ) -> GainTable:
        """Build a table from ``[(k_x, k_v, k_a), ...]``, checking each is finite."""
        rows = list(triples)
        if not rows:
            raise StringStabError(f"{source}: expected at least one gain triple; found none")
        K = np.empty((len(rows), 3))
        for i, r in enumerate(rows):
            if len(r) != 3:
                raise StringStabError(
                    f"{source}, triple {i + 1}: expected 3 gains k_x,k_v,k_a; found {len(r)}"
                )
            for j, v in enumerate(r):
                K[i, j] = finite_number(v, f"{source}, triple {i + 1}, {GAIN_COLUMNS[j]}")
        return cls(K[:, 0].copy(), K[:, 1].copy(), K[:, 2].copy(), source=source)

    def __len__(self) -> int:
        return len(self.k_x)

    @property
    def K(self) -> Array:
        """The gains as one ``(n, 3)`` array, columns k_x, k_v, k_a."""
        return np.column_stack([self.k_x, self.k_v, self.k_a])

    @property
    def columns(self) -> list[str]:
        """Names of the columns present, in the order of :meth:`rows`."""
        return [c for c in OPTIONAL_COLUMNS if getattr(self, c) is not None] + list(GAIN_COLUMNS)

    def meta(self, i: int) -> dict[str, Any]:
        """The optional ``t`` / ``vehicle`` of row ``i`` as plain Python values."""
        out: dict[str, Any] = {}
        if self.t is not None:
            out["t"] = float(self.t[i])
        if self.vehicle is not None:
            out["vehicle"] = self.vehicle[i].item()
        return out

    def meta_columns(self) -> dict[str, npt.NDArray[Any]]:
        """The optional ``t`` / ``vehicle`` columns present, to lead a result table.

        Examples
        --------
        >>> GainTable.from_triples([(1, 2, 3)]).meta_columns()
        {}
        """
        out: dict[str, npt.NDArray[Any]] = {}
        if self.t is not None:
            out["t"] = self.t
        if self.vehicle is not None:
            out["vehicle"] = self.vehicle
        return out

    def rows(self) -> list[dict[str, Any]]:
        """One plain dict per triple: ``t`` and ``vehicle`` when present, then the gains."""
        kx, kv, ka = self.k_x.tolist(), self.k_v.tolist(), self.k_a.tolist()
        return [
            {**self.meta(i), "k_x": kx[i], "k_v": kv[i], "k_a": ka[i]} for i in range(len(self))
        ]


def finite_number(value: Any, where: str) -> float:
    """A finite float from ``value``, or a one-line refusal naming ``where``.

    Parameters
    ----------
    value : Any
        A number or the text of one (spaces around it allowed).
    where : str
        What the value is, for the message (file, line, column).

    Returns
    -------
    float
        The value, finite.

    Raises
    ------
    StringStabError
        If the value is a boolean, None, empty, not a number, or not finite.
    """
    if isinstance(value, (bool, np.bool_)) or value is None:
        raise StringStabError(f"{where}: expected a finite number; found {show(value)}")
    if isinstance(value, str):
        text = value.strip()
        if not text:
            raise StringStabError(f"{where}: expected a finite number; found an empty field")
    else:
        text = value
    try:
        x = float(text)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"{where}: expected a finite number; found {show(value)}") from e
    if not math.isfinite(x):
        raise StringStabError(f"{where}: expected a finite number; found {show(value)}")
    return x


def suggest_name(name: str, candidates: Iterable[str]) -> str:
    """``"; is 'kv' a misspelling of 'k_v'?"`` for the closest candidate, or ``""``.

    Parameters
    ----------
    name : str
        The expected name.
    candidates : iterable of str
        The names found.

    Returns
    -------
    str
        The suggestion to end a message with, or ``""`` when no candidate is close.
    """
    close = difflib.get_close_matches(name, list(candidates), n=1, cutoff=0.6)
    return f"; is {show(close[0])} a misspelling of {show(name)}?" if close else ""


def resolve_columns(
    names: Sequence[str], source: str, what: str = "column"
) -> tuple[dict[str, int], tuple[str, ...]]:
    """Map the known column names to their index; refuse missing, misspelt or repeated ones.

    Parameters
    ----------
    names : sequence of str
        The column (or key, or array) names found, in order.
    source : str
        Where they were found, for the message.
    what : str
        What a name is called in the message: ``"column"``, ``"key"`` or ``"array"``.

    Returns
    -------
    index : dict of str to int
        The index of each of :data:`GAIN_COLUMNS` and of the :data:`OPTIONAL_COLUMNS` present.
    ignored : tuple of str
        The other names (ignored).

    Raises
    ------
    StringStabError
        If a gain column is missing (with the close match suggested), a name appears twice, or
        a name is a near miss of an optional column.
    """
    norm = [n.strip() for n in names]
    index: dict[str, int] = {}
    for i, n in enumerate(norm):
        key = n.lower()
        if key in (*GAIN_COLUMNS, *OPTIONAL_COLUMNS):
            if key in index:
                raise StringStabError(f"{source}: {what} {show(n)} appears twice; expected it once")
            index[key] = i
    unknown = [n for n in norm if n.lower() not in index]
    expected = ", ".join(GAIN_COLUMNS)
    for col in GAIN_COLUMNS:
        if col not in index:
            raise StringStabError(
                f"{source}: missing {what} {show(col)}; expected {what}s {expected} "
                f"(optional t, vehicle); found {', '.join(map(repr, norm)) or 'none'}"
                + suggest_name(col, unknown)
            )
    # An absent optional column with a near-miss present was most likely misspelt.
    for col in OPTIONAL_COLUMNS:
        if col in index:
            continue
        for n in unknown:
            if len(n) > 1 and difflib.SequenceMatcher(None, n.lower(), col).ratio() >= 0.8:
                raise StringStabError(
                    f"{source}: unknown {what} {show(n)}; is it a misspelling of {show(col)}? "
                    f"(expected {expected}, optional t, vehicle)"
                )
    return index, tuple(unknown)


def vehicle_ids(values: Sequence[Any]) -> npt.NDArray[Any]:
    """Vehicle ids as integers when every id is integral, else as strings.

    Parameters
    ----------
    values : sequence
        The ids read (numbers or text).

    Returns
    -------
    ndarray
        ``int64`` ids, or ``str`` ids (stripped).
    """
    ints: list[int] = []
    for v in values:
        if isinstance(v, (bool, np.bool_)):
            break
        if isinstance(v, (int, np.integer)):
            ints.append(int(v))
            continue
        if isinstance(v, str):
            try:
                ints.append(int(v.strip()))
                continue
            except ValueError:
                break
        if isinstance(v, (float, np.floating)) and math.isfinite(v) and float(v).is_integer():
            ints.append(int(v))
            continue
        break
    else:
        return np.asarray(ints, dtype=np.int64)
    return np.asarray([str(v).strip() for v in values], dtype=str)


def table_from_columns(
    cols: dict[str, list[Any]], source: str, where: Any, ignored: tuple[str, ...] = ()
) -> GainTable:
    """Check the numeric columns and build the table.

    Each column is converted at once; a column that does not convert to finite numbers is
    checked cell by cell to name the first bad cell: ``where(col, i)`` names cell ``i`` of
    column ``col`` in that message.

    Parameters
    ----------
    cols : dict of str to list
        The cells of each column present (:data:`GAIN_COLUMNS`, optional ``t``, ``vehicle``).
    source : str
        Where the gains came from.
    where : callable
        ``where(col, i)``: the place of cell ``i`` of column ``col``, for a message.
    ignored : tuple of str
        The names of the columns ignored.

    Returns
    -------
    GainTable
        The gains, checked finite.

    Raises
    ------
    StringStabError
        If there is no row, a cell is not a finite number, or a vehicle id is empty.
    """
    n = len(cols["k_x"])
    if n == 0:
        raise StringStabError(f"{source}: expected at least one row of gains; found none")
    num: dict[str, Array] = {}
    for col in (*GAIN_COLUMNS, "t"):
        if col not in cols:
            continue
        arr = _fast_numbers(cols[col])
        if arr is None:
            arr = np.empty(n)
            for i, v in enumerate(cols[col]):
                arr[i] = finite_number(v, where(col, i))
        num[col] = arr
    vehicle = None
    if "vehicle" in cols:
        for i, v in enumerate(cols["vehicle"]):
            if v is None or (isinstance(v, str) and not v.strip()):
                raise StringStabError(
                    f"{where('vehicle', i)}: expected a vehicle id; found {show(v)}"
                )
        vehicle = vehicle_ids(cols["vehicle"])
    return GainTable(
        num["k_x"], num["k_v"], num["k_a"], num.get("t"), vehicle, source=source,
        ignored_columns=ignored,
    )


def _fast_numbers(values: Sequence[Any]) -> Array | None:
    """``values`` (all str, or all int/float) as finite floats in one go; None if they are not."""
    kinds = set(map(type, values))
    if not (kinds == {str} or kinds <= {int, float}):
        return None  # booleans, None, mixed types: checked cell by cell
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        return None
    return arr if arr.ndim == 1 and bool(np.isfinite(arr).all()) else None
