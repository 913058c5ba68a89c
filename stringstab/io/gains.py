"""Reading gain triples K = [k_x, k_v, k_a]: one reader for every command.

``certify --file``, ``tune --file``, ``region --gains``, ``simulate --gains-file`` and
:meth:`stringstab.traffic.TimeVaryingLinearController.from_csv` all read gains here, so
they all accept the same inputs:

* a triple on the command line, ``"0.9,-0.5,1.1"`` (:func:`parse_triple`);
* a file (:func:`read_gains`):

  - **CSV** with a header naming the columns ``k_x, k_v, k_a`` and, for a gain
    time series from a policy rollout, ``t`` and optionally ``vehicle``; other
    columns are ignored.  A header-less CSV of exactly three numeric columns is
    read as ``k_x, k_v, k_a``.  Blank lines and lines starting with ``#`` are
    skipped; a UTF-8 byte-order mark is allowed.
  - **JSON**: a list of objects ``{"k_x": .., "k_v": .., "k_a": .., "t": ..,
    "vehicle": ..}`` or of triples ``[k_x, k_v, k_a]``, either bare or under a
    key ``"gains"`` (or ``"results"``, so the output of ``stringstab certify
    --format json`` reads back).
  - **NPZ** (:func:`numpy.savez`): arrays ``k_x, k_v, k_a`` (optional ``t``,
    ``vehicle``) of one length, or one ``(n, 3)`` array ``K``.
  - **Parquet**: columns ``k_x, k_v, k_a`` (optional ``t``, ``vehicle``), so the output of
    ``stringstab certify --format parquet`` reads back (needs pyarrow).

Bad input raises :class:`~stringstab.errors.StringStabError` with a one-line
message naming the file, the row or column, what was expected and what was
found; it never yields a partial table.

Numbers are converted a column at a time; only when that fails is the file read cell by
cell again to name the first bad cell, so large files are read quickly.
"""

from __future__ import annotations

import csv
import difflib
import json
import math
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show
from .text_input import read_stream, read_text

__all__ = [
    "GAIN_COLUMNS",
    "INPUT_FORMATS",
    "OPTIONAL_COLUMNS",
    "GainTable",
    "parse_triple",
    "read_gains",
]

#: The three gain columns, in the order of K = [k_x, k_v, k_a] (IDL eq 4).
GAIN_COLUMNS: tuple[str, str, str] = ("k_x", "k_v", "k_a")
#: Optional columns of a gain time series: time in s and a vehicle id.
OPTIONAL_COLUMNS: tuple[str, str] = ("t", "vehicle")
#: Gain file formats, by file extension.
INPUT_FORMATS: dict[str, str] = {".csv": "csv", ".json": "json", ".npz": "npz",
                                 ".parquet": "parquet"}

Array = npt.NDArray[np.float64]


# --------------------------------------------------------------------------- table


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
                K[i, j] = _number(v, f"{source}, triple {i + 1}, {GAIN_COLUMNS[j]}")
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


# --------------------------------------------------------------------------- parsing


def _number(value: Any, where: str) -> float:
    """A finite float from ``value``, or a StringStabError naming ``where``."""
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


def parse_triple(text: str, *, where: str | None = None) -> tuple[float, float, float]:
    """Parse ``"k_x,k_v,k_a"`` (three comma-separated finite numbers).

    Parameters
    ----------
    text : str
        For example ``"0.9,-0.5,1.1"``; spaces around the numbers are allowed.
    where : str, optional
        Prefix of error messages (default: the triple itself).

    Returns
    -------
    tuple of float
        ``(k_x, k_v, k_a)``.

    Raises
    ------
    StringStabError
        If there are not exactly three fields or one is not a finite number.

    Examples
    --------
    >>> parse_triple("0.9,-0.5,1.1")
    (0.9, -0.5, 1.1)
    >>> parse_triple("0.9,-0.5")
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: gain triple '0.9,-0.5': expected 3 comma-separated numbers k_x,k_v,k_a; found 2 fields
    """
    label = where or f"gain triple {show(text)}"
    parts = text.split(",")
    if len(parts) != 3:
        raise StringStabError(
            f"{label}: expected 3 comma-separated numbers k_x,k_v,k_a; found {len(parts)} field"
            + ("s" if len(parts) != 1 else "")
        )
    kx, kv, ka = (_number(p, f"{label}, {c}") for p, c in zip(parts, GAIN_COLUMNS))
    return kx, kv, ka


def _suggest(name: str, candidates: Iterable[str]) -> str:
    """``"; is 'kv' a misspelling of 'k_v'?"`` for the closest candidate, or ``""``."""
    close = difflib.get_close_matches(name, list(candidates), n=1, cutoff=0.6)
    return f"; is {show(close[0])} a misspelling of {show(name)}?" if close else ""


def _resolve_columns(
    names: Sequence[str], source: str, what: str = "column"
) -> tuple[dict[str, int], tuple[str, ...]]:
    """Map known column names to their index; error on missing/misspelt/duplicate ones."""
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
                + _suggest(col, unknown)
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


def _vehicle_array(values: Sequence[Any]) -> npt.NDArray[Any]:
    """Integer ids when every id is integral, else strings."""
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


def _table(
    cols: dict[str, list[Any]], source: str, where: Any, ignored: tuple[str, ...] = ()
) -> GainTable:
    """Check the numeric columns and build the table.

    Each column is converted at once; a column that does not convert to finite numbers is
    checked cell by cell to name the first bad cell: ``where(col, i)`` names cell ``i`` of
    column ``col`` in that message.
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
                arr[i] = _number(v, where(col, i))
        num[col] = arr
    vehicle = None
    if "vehicle" in cols:
        for i, v in enumerate(cols["vehicle"]):
            if v is None or (isinstance(v, str) and not v.strip()):
                raise StringStabError(
                    f"{where('vehicle', i)}: expected a vehicle id; found {show(v)}"
                )
        vehicle = _vehicle_array(cols["vehicle"])
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


def _read_csv(text: str, source: str) -> GainTable:
    lines = [
        (lineno, ln) for lineno, ln in enumerate(text.splitlines(), start=1)
        if ln.strip() and not ln.lstrip().startswith("#")
    ]
    if not lines:
        raise StringStabError(
            f"{source}: empty file; expected a CSV header with columns k_x,k_v,k_a "
            "(optional t, vehicle) and at least one row"
        )

    def parse(rows: list[tuple[int, str]]) -> list[list[str]]:
        try:
            return list(csv.reader([ln for _, ln in rows], skipinitialspace=True))
        except csv.Error as e:
            raise StringStabError(f"{source}: not a readable CSV file ({e})") from e

    header = parse(lines[:1])[0]
    if len(header) == 1 and (sep := next((d for d in ";\t|" if d in header[0]), None)):
        raise StringStabError(
            f"{source}, line {lines[0][0]}: expected comma-separated columns; "
            f"found fields separated by {show(sep)}"
        )
    headerless = len(header) == 3 and all(_is_number(h) for h in header)
    if headerless:
        index = {c: j for j, c in enumerate(GAIN_COLUMNS)}
        ignored: tuple[str, ...] = ()
        body = lines
    else:
        if all(_is_number(h) for h in header):
            raise StringStabError(
                f"{source}, line {lines[0][0]}: expected a header naming the columns "
                f"(k_x,k_v,k_a, optional t, vehicle) or exactly 3 numeric columns; "
                f"found {len(header)} numbers"
            )
        index, ignored = _resolve_columns(header, source)
        body = lines[1:]
    if not body:
        raise StringStabError(
            f"{source}: no data rows after the header; expected at least one row of gains"
        )
    width = len(header)
    fast = _fast_csv([ln for _, ln in body], index, width)
    if fast is not None:
        return GainTable(fast["k_x"], fast["k_v"], fast["k_a"], fast.get("t"), fast.get("vehicle"),
                         source=source, ignored_columns=ignored)
    recs = parse(body)
    if any(len(rec) != width for rec in recs):
        k = next(k for k, r in enumerate(recs) if len(r) != width)
        raise StringStabError(
            f"{source}, line {body[k][0]}: expected {width} comma-separated fields "
            f"({','.join(h.strip() for h in header)}); found {len(recs[k])}"
        )
    fields = list(zip(*recs))
    cols: dict[str, list[Any]] = {c: list(fields[j]) for c, j in index.items()}
    return _table(
        cols, source, lambda c, i: f"{source}, line {body[i][0]}, column {show(c)}", ignored
    )


def _fast_csv(lines: list[str], index: dict[str, int], width: int) -> dict[str, Any] | None:
    """The columns of plain numeric CSV rows, parsed in C (numpy.loadtxt); None if not plain.

    Plain: no quotes, ``width`` fields on every row, finite numbers in the numeric columns and
    a non-empty vehicle id.  Anything else returns None and is read by the cell-by-cell path,
    which names the first bad cell.
    """
    if any('"' in ln or ln.count(",") != width - 1 for ln in lines):
        return None
    numeric = [c for c in index if c != "vehicle"]
    try:
        arr = np.loadtxt(lines, delimiter=",", usecols=[index[c] for c in numeric],
                         dtype=np.float64, comments=None, ndmin=2)
    except ValueError:
        return None
    if arr.shape != (len(lines), len(numeric)) or not np.isfinite(arr).all():
        return None
    out: dict[str, Any] = {c: np.ascontiguousarray(arr[:, j]) for j, c in enumerate(numeric)}
    if "vehicle" in index:
        j = index["vehicle"]
        ids = [ln.split(",")[j].strip() for ln in lines]
        if not all(ids):
            return None
        out["vehicle"] = _vehicle_array(ids)
    return out


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def _read_json(text: str, source: str) -> GainTable:
    if not text.strip():
        raise StringStabError(
            f"{source}: empty file; expected a JSON list of gain objects "
            '{"k_x": .., "k_v": .., "k_a": ..} or of [k_x, k_v, k_a] triples'
        )
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as e:
        raise StringStabError(
            f"{source}: not valid JSON (line {e.lineno}, column {e.colno}: {e.msg})"
        ) from e
    items: Any = doc
    key = ""
    if isinstance(doc, dict):
        keys = [k for k in ("gains", "results") if k in doc]
        if not keys:
            raise StringStabError(
                f"{source}: expected a JSON list of gains or an object with a key 'gains'; "
                f"found an object with keys {sorted(map(str, doc))}"
                + _suggest("gains", map(str, doc))
            )
        key = keys[0]
        items = doc[key]
    if not isinstance(items, list):
        raise StringStabError(
            f"{source}: expected a list of gains{f' under {show(key)}' if key else ''}; "
            f"found {type(items).__name__}"
        )
    if not items:
        raise StringStabError(f"{source}: expected at least one gain triple; found an empty list")
    prefix = f"{source}, {key + '[' if key else 'item ['}"
    if all(isinstance(it, list) for it in items):
        for i, it in enumerate(items):
            if len(it) != 3:
                raise StringStabError(
                    f"{prefix}{i}]: expected a triple [k_x, k_v, k_a]; found {len(it)} values"
                )
        cols: dict[str, list[Any]] = {c: [it[j] for it in items] for j, c in enumerate(GAIN_COLUMNS)}
        return _table(cols, source, lambda c, i: f"{prefix}{i}], {c}")
    first: list[str] | None = None
    cols = {}
    for i, it in enumerate(items):
        if not isinstance(it, dict):
            raise StringStabError(
                f"{prefix}{i}]: expected an object with keys k_x, k_v, k_a "
                f"(or a triple [k_x, k_v, k_a]); found {type(it).__name__} {show(it)}"
            )
        keys = list(map(str, it))
        index, _ = _resolve_columns(keys, f"{prefix}{i}]", what="key")
        if first is None:
            first = sorted(index)
            cols = {c: [] for c in first}
        elif sorted(index) != first:
            missing = sorted(set(first) - set(index))
            extra = sorted(set(index) - set(first))
            raise StringStabError(
                f"{prefix}{i}]: expected the same keys as item 0 ({', '.join(first)}); "
                + (f"missing {', '.join(missing)}" if missing else f"extra {', '.join(extra)}")
            )
        values = list(it.values())
        for c, j in index.items():
            cols[c].append(values[j])
    return _table(cols, source, lambda c, i: f"{prefix}{i}], key {show(c)}")


def _read_npz(path: Path, source: str) -> GainTable:
    import zipfile

    try:
        if not zipfile.is_zipfile(path):
            raise StringStabError(
                f"{source}: not an NPZ archive (numpy.savez); expected arrays k_x, k_v, k_a "
                "or K (n, 3)"
            )
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except StringStabError:
        raise
    except ValueError as e:
        raise StringStabError(
            f"{source}: not a readable NPZ of numeric arrays (object arrays are refused; {e})"
        ) from e
    except (OSError, EOFError, zipfile.BadZipFile) as e:
        raise StringStabError(f"{source}: not a readable NPZ file ({e})") from e
    if not arrays:
        raise StringStabError(
            f"{source}: empty NPZ; expected arrays k_x, k_v, k_a (optional t, vehicle) or K (n, 3)"
        )
    return _from_arrays(arrays, source)


def _read_parquet(path: Path, source: str) -> GainTable:
    try:
        import pyarrow.parquet as pq
    except ImportError as e:  # pragma: no cover - pyarrow is a dependency
        raise StringStabError(f"{source}: reading Parquet needs pyarrow (pip install pyarrow)") from e
    try:
        table = pq.read_table(path)
    except Exception as e:  # pyarrow raises its own ArrowInvalid / OSError types
        raise StringStabError(f"{source}: not a readable Parquet file; expected Parquet columns "
                              f"k_x, k_v, k_a [, t, vehicle] ({e})") from e
    arrays = {name: np.asarray(table.column(name).to_numpy(zero_copy_only=False))
              for name in table.column_names}
    if not arrays:
        raise StringStabError(
            f"{source}: no columns; expected columns k_x, k_v, k_a (optional t, vehicle)"
        )
    return _from_arrays(arrays, source)


def _from_arrays(arrays: dict[str, npt.NDArray[Any]], source: str) -> GainTable:
    """The gains from named arrays (NPZ arrays or Parquet columns)."""
    names = list(arrays)
    if "K" in arrays and not any(c in arrays for c in GAIN_COLUMNS):
        K = arrays["K"]
        if K.ndim != 2 or K.shape[1] != 3:
            raise StringStabError(
                f"{source}: array 'K' must have shape (n, 3) with columns k_x, k_v, k_a; "
                f"found shape {K.shape}"
            )
        cols: dict[str, Any] = {c: K[:, j] for j, c in enumerate(GAIN_COLUMNS)}
        for c in OPTIONAL_COLUMNS:
            if c in arrays:
                cols[c] = arrays[c]
        ignored = tuple(n for n in names if n not in ("K", *OPTIONAL_COLUMNS))
    else:
        cand = [n for n in names if n not in OPTIONAL_COLUMNS]
        if len(cand) == 1 and arrays[cand[0]].ndim == 2 and arrays[cand[0]].shape[1] == 3:
            raise StringStabError(
                f"{source}: expected arrays k_x, k_v, k_a (optional t, vehicle) or one (n, 3) "
                f"array K; found {', '.join(map(repr, names))} (name the (n, 3) array 'K')"
            )
        index, ignored = _resolve_columns(names, source, what="array")
        cols = {c: arrays[names[j]] for c, j in index.items()}
    n = len(cols["k_x"])
    for c, a in cols.items():
        if a.ndim != 1 or len(a) != n:
            raise StringStabError(
                f"{source}: array {show(c)} must be 1-D of length {n} (one entry per triple); "
                f"found shape {a.shape}"
            )
        if c != "vehicle" and not (np.issubdtype(a.dtype, np.number) and not np.iscomplexobj(a)):
            raise StringStabError(
                f"{source}: array {show(c)} must be real numbers; found dtype {a.dtype}"
            )
    # Fast vectorised check, then a precise message naming the first bad entry.
    for c in (*GAIN_COLUMNS, "t"):
        if c in cols:
            a = np.asarray(cols[c], dtype=np.float64)
            bad = np.flatnonzero(~np.isfinite(a))
            if bad.size:
                i = int(bad[0])
                raise StringStabError(
                    f"{source}: array {show(c)}, index {i}: expected a finite number; "
                    f"found {show(float(a[i]))}"
                )
            cols[c] = a
    vehicle = _vehicle_array(cols["vehicle"].tolist()) if "vehicle" in cols else None
    if n == 0:
        raise StringStabError(f"{source}: expected at least one gain triple; found none")
    return GainTable(
        cols["k_x"], cols["k_v"], cols["k_a"], cols.get("t"), vehicle, source=source,
        ignored_columns=ignored,
    )


def _read_stream(stream: IO[str], name: str) -> str:
    """All of a text stream (standard input: gzip by content, strict UTF-8), or a one-line refusal."""
    return read_stream(stream, label=name, expected="a CSV or JSON gain file")


def read_gains(source: str | os.PathLike[str] | IO[str], *, fmt: str | None = None) -> GainTable:
    r"""Read gain triples from a CSV, JSON, NPZ or Parquet file (see the module docstring).

    Parameters
    ----------
    source : path or text stream
        A file path; ``"-"`` or an open text stream reads CSV or JSON text
        (JSON when it starts with ``[`` or ``{``).
    fmt : {"csv", "json", "npz", "parquet"}, optional
        Override the format implied by the file extension.

    Returns
    -------
    GainTable
        The gains, with ``t`` and ``vehicle`` when the file has them.

    Raises
    ------
    StringStabError
        On a missing or unreadable file, an unsupported extension, an empty file,
        missing or misspelt columns (with the close match suggested), or a field
        that is not a finite number (naming its line and column).

    Examples
    --------
    >>> import io
    >>> g = read_gains(io.StringIO("t,k_x,k_v,k_a\n0.0,0.9,-0.5,1.1\n0.1,1.3,0,0.6\n"))
    >>> g.t.tolist(), g.k_x.tolist()
    ([0.0, 0.1], [0.9, 1.3])
    >>> read_gains(io.StringIO("t,k_x,kv,k_a\n0,1,1,1\n"))
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: <stream>: missing column 'k_v'; expected columns k_x, k_v, k_a (optional t, vehicle); found 't', 'k_x', 'kv', 'k_a'; is 'kv' a misspelling of 'k_v'?
    """
    if fmt is not None and fmt not in INPUT_FORMATS.values():
        raise StringStabError(
            f"gain file format must be csv, json or npz (or parquet); got {show(fmt)}"
        )
    if not isinstance(source, (str, os.PathLike)) or str(source) == "-":
        if isinstance(source, (str, os.PathLike)):
            import sys

            stream: IO[str] = sys.stdin
            name = "<stdin>"
        else:
            stream = source
            name = str(getattr(source, "name", "<stream>"))
            if not isinstance(name, str) or name.isdigit():
                name = "<stream>"
        if fmt in ("npz", "parquet"):
            raise StringStabError(
                f"{name}: {fmt.upper()} cannot be read from a text stream; give a path"
            )
        text = _read_stream(stream, name)
        if text.startswith("\ufeff"):
            text = text[1:]
        kind = fmt or ("json" if text.lstrip()[:1] in ("[", "{") else "csv")
        return _read_json(text, name) if kind == "json" else _read_csv(text, name)

    path = Path(source)
    name = str(source)
    kind_or_none = fmt or INPUT_FORMATS.get(path.suffix.lower())
    if kind_or_none is None:
        raise StringStabError(
            f"{name}: unsupported file extension {show(path.suffix or '(none)')}; "
            "expected .csv, .json or .npz (or .parquet)"
        )
    kind = kind_or_none
    if not path.exists():
        raise StringStabError(f"{name}: no such file; expected a readable {kind.upper()} file")
    if path.is_dir():
        raise StringStabError(f"{name}: is a directory; expected a {kind.upper()} file")
    try:
        with open(path, "rb"):
            pass
    except OSError as e:
        raise StringStabError(f"{name}: cannot read the file ({e.strerror or e})") from e
    if kind == "npz":
        return _read_npz(path, name)
    if kind == "parquet":
        return _read_parquet(path, name)
    text = read_text(path, label=name, expected=f"a {kind.upper()} gain file")
    return _read_json(text, name) if kind == "json" else _read_csv(text, name)
