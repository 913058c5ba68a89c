"""Writing result tables: one vectorised writer for every command.

A result is a set of *ordered columns* — ``name → 1-D array``, with at most one level of
grouping (``"taylor_derived" → {"psi1": array, ...}``) — plus ``params`` (the settings of the
run) and a ``summary`` (totals).  :func:`format_results` and :func:`write_results` turn it into

``table``
    for people: chosen columns (:class:`TableColumn`) with units and rounding, the parameters
    in a ``#`` header line and the summary in ``#`` footer lines;
``json``
    ``{"params": .., "results": [one object per row, groups nested], "summary": ..}``, one
    result per line, non-finite numbers as ``null``;
``csv``
    one row per result, groups flattened with ``_`` (``taylor_derived_psi1``), the scalar
    parameters repeated as trailing columns, non-finite numbers as empty fields;
``parquet``
    the flattened columns with their NumPy types (``inf`` and ``nan`` kept), ``params`` and
    ``summary`` as JSON in the file's metadata (keys ``stringstab.params``,
    ``stringstab.summary``);
``npz``
    the flattened columns as arrays (:func:`numpy.savez`, ``inf``/``nan`` kept), ``params``
    and ``summary`` as JSON strings in the 0-d arrays ``_params`` and ``_summary``.

Numbers in ``csv`` and ``json`` are written in their shortest form that reads back to the same
double (``0.1``, ``1.0``); every cell is converted column by column in C (pyarrow), so writing
is not slower than computing.  pyarrow is imported only when one of these formats is written.

Every result type owns its columns (e.g.
:meth:`stringstab.certify.continuous.CertificateBatch.columns`); this module knows none of them.
"""

from __future__ import annotations

import io
import json
import os
import sys
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from .outputs import atomic_path, atomic_write_bytes
from .plain import to_plain

__all__ = [
    "BINARY_FORMATS",
    "RESULT_FORMATS",
    "Categorical",
    "TableColumn",
    "columns_from_records",
    "flatten_columns",
    "format_results",
    "records_from_columns",
    "render_table",
    "warm_up",
    "write_results",
    "write_text",
]

#: Every format :func:`write_results` writes.
RESULT_FORMATS: tuple[str, ...] = ("table", "json", "csv", "parquet", "npz")
#: Formats that need a file (not a text stream).
BINARY_FORMATS: tuple[str, ...] = ("parquet", "npz")

#: Columns: name -> 1-D array, or name -> {name -> 1-D array} (one level of grouping).
Columns = Mapping[str, Any]


@dataclass(frozen=True)
class TableColumn:
    """One column of the human table.

    Parameters
    ----------
    header : str
        Column title (may carry the unit, e.g. ``"ω_peak [rad/s]"``).
    key : str
        Column name; ``"group.name"`` for a grouped column.
    fmt : str
        printf-style format of numbers (``"%.6g"``, ``"%d"``); booleans print yes/no.
    missing : str
        Text of a missing value (NaN or None).

    Examples
    --------
    >>> TableColumn("k_x", "k_x").fmt
    '%.6g'
    """

    header: str
    key: str
    fmt: str = "%.6g"
    missing: str = "-"


# --------------------------------------------------------------------------- columns


@dataclass(frozen=True)
class Categorical:
    """A column of few distinct values, ``labels[codes]``, written without forming every cell.

    Grid coordinates, verdicts and type labels repeat a handful of values over many rows; the
    writer formats each label once and spreads it (a region map's CSV is 3× faster so).
    ``numpy.asarray(c)`` and :meth:`tolist` give the plain values.

    Examples
    --------
    >>> c = Categorical(np.array([1, 0, 1]), np.array(["no", "yes"]))
    >>> c.tolist(), len(c), c[1:].tolist()
    (['yes', 'no', 'yes'], 3, ['no', 'yes'])
    """

    codes: npt.NDArray[np.integer[Any]]
    labels: npt.NDArray[Any]

    def __len__(self) -> int:
        return int(np.shape(self.codes)[0])

    def __getitem__(self, rows: Any) -> Categorical:
        return Categorical(np.asarray(self.codes)[rows], self.labels)

    def __array__(self, dtype: Any = None, copy: Any = None) -> npt.NDArray[Any]:
        out = np.asarray(self.labels)[np.asarray(self.codes)]
        return out if dtype is None else out.astype(dtype)

    def tolist(self) -> list[Any]:
        """The values as a list."""
        return np.asarray(self).tolist()


@dataclass(frozen=True)
class _Leaf:
    """A normalised column: values (kind b, i, f or U), and a mask of missing values.

    With ``codes``, ``base`` holds the distinct labels and the values are ``base[codes]``.
    """

    base: npt.NDArray[Any]
    mask: npt.NDArray[np.bool_] | None
    codes: npt.NDArray[np.intp] | None = None

    @property
    def values(self) -> npt.NDArray[Any]:
        return self.base if self.codes is None else self.base[self.codes]

    @property
    def n(self) -> int:
        return int((self.base if self.codes is None else self.codes).shape[0])

    @property
    def kind(self) -> str:
        return self.base.dtype.kind


def _leaf(name: str, values: Any) -> _Leaf:
    if isinstance(values, Categorical):
        codes = np.asarray(values.codes)
        labels = _leaf(name, values.labels)
        if codes.ndim != 1 or codes.dtype.kind not in "iu" or labels.mask is not None:
            raise StringStabError(
                f"result column {name!r}: a Categorical needs 1-D integer codes and labels "
                f"without missing values; got codes of shape {codes.shape}, dtype {codes.dtype}"
            )
        return _Leaf(labels.base, None, codes.astype(np.intp, copy=False))
    a = np.asarray(values)
    if a.ndim != 1:
        raise StringStabError(f"result column {name!r} must be one-dimensional; got shape {a.shape}")
    k = a.dtype.kind
    if k in "biuf":
        return _Leaf(a.astype(np.int64) if k == "u" else a, None)
    if k == "U":
        return _Leaf(a, None)
    if k == "S":
        return _Leaf(a.astype(str), None)
    if k != "O":
        raise StringStabError(f"result column {name!r}: unsupported dtype {a.dtype}")
    items = a.tolist()
    mask = np.fromiter((v is None for v in items), dtype=bool, count=len(items))
    present = [v for v in items if v is not None]
    if all(isinstance(v, (bool, np.bool_)) for v in present):
        vals: npt.NDArray[Any] = np.array([bool(v) if v is not None else False for v in items])
    elif all(isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_))
             for v in present):
        vals = np.array([int(v) if v is not None else 0 for v in items], dtype=np.int64)
    elif all(isinstance(v, (int, float, np.integer, np.floating))
             and not isinstance(v, (bool, np.bool_)) for v in present):
        vals = np.array([float(v) if v is not None else np.nan for v in items], dtype=np.float64)
    else:
        vals = np.array(["" if v is None else str(v) for v in items], dtype=str)
    return _Leaf(vals, mask if mask.any() else None)


def _normalise(columns: Columns) -> dict[str, _Leaf | dict[str, _Leaf]]:
    """Check the shape of every column and normalise their types."""
    out: dict[str, _Leaf | dict[str, _Leaf]] = {}
    n: int | None = None

    def check(name: str, leaf: _Leaf) -> _Leaf:
        nonlocal n
        if n is None:
            n = leaf.n
        elif leaf.n != n:
            raise StringStabError(
                f"result column {name!r} has {leaf.n} rows; expected {n} like the others"
            )
        return leaf

    for name, col in columns.items():
        if isinstance(col, Mapping):
            out[name] = {k: check(f"{name}.{k}", _leaf(f"{name}.{k}", v)) for k, v in col.items()}
        else:
            out[name] = check(name, _leaf(name, col))
    return out


def _n_rows(cols: Mapping[str, _Leaf | dict[str, _Leaf]]) -> int:
    for c in cols.values():
        if isinstance(c, dict):
            for leaf in c.values():
                return leaf.n
        else:
            return c.n
    return 0


def _flat(cols: Mapping[str, _Leaf | dict[str, _Leaf]], sep: str = "_") -> dict[str, _Leaf]:
    out: dict[str, _Leaf] = {}
    for name, c in cols.items():
        if isinstance(c, dict):
            for k, leaf in c.items():
                out[f"{name}{sep}{k}"] = leaf
        else:
            out[name] = c
    return out


def flatten_columns(columns: Columns, sep: str = "_") -> dict[str, npt.NDArray[Any]]:
    """Grouped columns as one flat mapping (``group_name``), in order.

    Missing values become NaN in float columns and ``""`` in string columns.

    Parameters
    ----------
    columns : mapping
        Ordered columns ``name → 1-D array`` (or ``name → {name → array}``), one length.
    sep : str, default "_"
        Joins a group's name and a column's name.

    Returns
    -------
    dict of str to ndarray
        The flat columns, groups expanded in place.

    Examples
    --------
    >>> flatten_columns({"k_x": [1.0], "taylor": {"verdict": ["stable"]}})
    {'k_x': array([1.]), 'taylor_verdict': array(['stable'], dtype='<U6')}
    """
    return {k: leaf.values for k, leaf in _flat(_normalise(columns), sep).items()}


def columns_from_records(records: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """Row records (dicts, one nesting level) as columns; keys missing in a record are None.

    Parameters
    ----------
    records : sequence of mapping
        One dict per row; a value that is a mapping is a group of columns.

    Returns
    -------
    dict
        Columns as lists (groups as dicts of lists), keys in order of first appearance.

    Examples
    --------
    >>> columns_from_records([{"a": 1.0, "g": {"x": "u"}}, {"a": None, "g": {"x": "v"}}])
    {'a': [1.0, None], 'g': {'x': ['u', 'v']}}
    """
    keys: dict[str, dict[str, None] | None] = {}
    for r in records:
        for k, v in r.items():
            if isinstance(v, Mapping):
                sub = keys.get(k)
                if sub is None:
                    sub = keys[k] = {}
                for kk in v:
                    sub.setdefault(str(kk), None)
            else:
                keys.setdefault(k, None)
    out: dict[str, Any] = {}
    for k, sub in keys.items():
        if sub is None:
            out[k] = [r.get(k) for r in records]
        else:
            out[k] = {kk: [(r.get(k) or {}).get(kk) for r in records] for kk in sub}
    return out


def records_from_columns(columns: Columns) -> list[dict[str, Any]]:
    """The rows of result columns as plain dicts (groups nested; NaN, inf and None as None).

    The inverse of :func:`columns_from_records`, and the rows of the ``json`` format.

    Parameters
    ----------
    columns : mapping
        Ordered columns ``name → 1-D array`` (or ``name → {name → array}``), one length.

    Returns
    -------
    list of dict
        One dict per row, values as plain Python values.

    Examples
    --------
    >>> records_from_columns({"a": np.array([1.0, np.inf]), "g": {"x": np.array([1, 2])}})
    [{'a': 1.0, 'g': {'x': 1}}, {'a': None, 'g': {'x': 2}}]
    """
    cols = _normalise(columns)

    def plain(leaf: _Leaf) -> list[Any]:
        vals = leaf.values.tolist()
        if leaf.kind == "f":
            vals = [v if v - v == 0.0 else None for v in vals]
        if leaf.mask is not None:
            for i in np.flatnonzero(leaf.mask).tolist():
                vals[i] = None
        return vals

    names: list[str] = []
    lists: list[Any] = []
    for name, c in cols.items():
        names.append(name)
        if isinstance(c, dict):
            keys = list(c)
            sub = [plain(leaf) for leaf in c.values()]
            lists.append([dict(zip(keys, row)) for row in zip(*sub)] if sub else [])
        else:
            lists.append(plain(c))
    return [dict(zip(names, row)) for row in zip(*lists)]


# --------------------------------------------------------------------------- cells (pyarrow)


def _pa() -> tuple[Any, Any]:
    try:
        import pyarrow as pa
        import pyarrow.compute as pc
    except ImportError as e:  # pragma: no cover - pyarrow is a dependency
        raise StringStabError(
            "writing json, csv or parquet needs pyarrow; install it with 'pip install pyarrow'"
        ) from e
    return pa, pc


def warm_up() -> None:
    """Import pyarrow and its compute and CSV modules (about 0.3 s) ahead of a large write,
    e.g. in a thread while the results are computed in worker processes."""
    _pa()
    import pyarrow.csv  # noqa: F401


def _mapped(values: npt.NDArray[Any], fn: Callable[[Any], str]) -> Any:
    """``fn`` applied to each distinct value, then spread to every row (few distinct values)."""
    pa, _ = _pa()
    uniq, inverse = np.unique(values, return_inverse=True)
    return pa.array([fn(u) for u in uniq.tolist()], type=pa.string()).take(
        pa.array(np.ravel(inverse))
    )


def _cells(leaf: _Leaf, style: str) -> Any:
    """The column as a pyarrow string array of CSV or JSON cells (null where missing)."""
    pa, pc = _pa()
    if leaf.codes is not None:  # each distinct label formatted once, then spread
        return _cells(_Leaf(leaf.base, None), style).take(pa.array(leaf.codes))
    v = leaf.values
    mask = leaf.mask
    k = leaf.kind
    if k == "f":
        bad = ~np.isfinite(v)
        if bad.any():
            mask = bad if mask is None else (mask | bad)
        s = pc.cast(pa.array(v, type=pa.float64()), pa.string())  # shortest round-trip digits
        # integral values keep a '.0', as Python writes them (1.0, not 1)
        whole = (np.abs(v) < 1e15) & (np.trunc(v) == v)
        if whole.any():
            as_int = pc.cast(pa.array(np.where(whole, v, 0.0).astype(np.int64)), pa.string())
            s = pc.if_else(pa.array(whole), pc.binary_join_element_wise(as_int, ".0", ""), s)
            negative_zero = whole & (v == 0.0) & np.signbit(v)
            if negative_zero.any():
                s = pc.if_else(pa.array(negative_zero), pa.scalar("-0.0", pa.string()), s)
    elif k == "i":
        s = pc.cast(pa.array(v, type=pa.int64()), pa.string())
    elif k == "b":
        t, f = ("true", "false") if style == "json" else ("True", "False")
        s = pa.array(np.where(v, t, f), type=pa.string())
    else:
        if style == "json":
            s = _mapped(v, lambda x: json.dumps(x, ensure_ascii=False))
        else:
            s = _mapped(v, _csv_quote)
    if mask is not None and mask.any():
        s = pc.if_else(pa.array(mask), pa.scalar(None, pa.string()), s)
    return s


def _filled(cells: Any, text: str) -> Any:
    """``cells`` with nulls replaced by ``text``."""
    _, pc = _pa()
    return pc.fill_null(cells, text) if cells.null_count else cells


def _csv_quote(x: str) -> str:
    if any(c in x for c in ',"\r\n') or x != x.strip():
        return '"' + x.replace('"', '""') + '"'
    return x


def _join_rows(rows: Any, sep: str) -> str:
    """The rows joined by ``sep``: each row gets ``sep`` appended in C, and the text is the
    array's character buffer read once, without the last ``sep`` (no list of rows, no second
    join, no copy to cut the end)."""
    pa, pc = _pa()
    if len(rows) == 0:
        return ""
    ended = pc.binary_join_element_wise(rows.cast(pa.large_string()),
                                        pa.scalar(sep, pa.large_string()),
                                        pa.scalar("", pa.large_string()))
    offsets = np.frombuffer(ended.buffers()[1], dtype=np.int64, count=len(ended) + 1,
                            offset=8 * ended.offset)
    data = ended.buffers()[2]
    end = int(offsets[-1]) - len(sep.encode("utf-8"))
    return data[int(offsets[0]):end].to_pybytes().decode("utf-8")


def _params_flat(params: Mapping[str, Any] | None) -> dict[str, Any]:
    """Scalar parameters (lists joined with ','), for CSV columns."""
    out: dict[str, Any] = {}
    for k, v in to_plain(dict(params or {})).items():
        if isinstance(v, Mapping):
            continue
        if isinstance(v, list):
            v = ",".join(_g(x) for x in v)
        out[k] = v
    return out


def _csv(cols: Mapping[str, _Leaf | dict[str, _Leaf]], params: Mapping[str, Any] | None) -> str:
    pa, pc = _pa()
    flat = _flat(cols)
    n = _n_rows(cols)
    extra = {k: v for k, v in _params_flat(params).items() if k not in flat}
    header = ",".join(_csv_quote(h) for h in [*flat, *extra])
    if n == 0:
        return header + "\n"
    pieces = [_filled(_cells(leaf, "csv"), "") for leaf in flat.values()]
    extra_cells = [_csv_cell(v) for v in extra.values()]
    pieces += [pa.repeat(pa.scalar(c, pa.string()), n) for c in extra_cells]
    # only text can carry quotes (numbers and booleans never do); a categorical's labels suffice
    quoted = any(c.startswith('"') for c in extra_cells) or any(
        any(_csv_quote(str(x)) != str(x) for x in leaf.base.tolist()) if leaf.codes is not None
        else pc.any(pc.starts_with(cells, '"')).as_py()
        for leaf, cells in zip(flat.values(), pieces) if leaf.kind not in "bif")
    if not quoted:
        # Arrow's CSV writer lays the (already formatted) cells out in C++, 3x faster than
        # joining them here; "none" because every cell is final text needing no quotes.
        import pyarrow.csv as pa_csv

        buf = io.BytesIO()
        table = pa.table({str(i): p for i, p in enumerate(pieces)})
        pa_csv.write_csv(table, buf, pa_csv.WriteOptions(include_header=False,
                                                         quoting_style="none"))
        return header + "\n" + buf.getvalue().decode("utf-8")
    rows = pc.binary_join_element_wise(*pieces, ",")  # some cells carry their own quotes
    return header + "\n" + _join_rows(rows, "\n") + "\n"


def _csv_cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return repr(v)
    return _csv_quote(str(v))


def _json_rows(cols: Mapping[str, _Leaf | dict[str, _Leaf]]) -> str:
    pa, pc = _pa()
    pieces: list[Any] = []
    lit: list[str] = ["{"]

    def key(name: str) -> str:
        return json.dumps(name, ensure_ascii=False) + ": "

    first = True
    for name, c in cols.items():
        lit.append(("" if first else ", ") + key(name))
        first = False
        if isinstance(c, dict):
            lit.append("{")
            for j, (k, leaf) in enumerate(c.items()):
                lit.append(("" if j == 0 else ", ") + key(k))
                pieces.append(pa.scalar("".join(lit), pa.string()))
                lit = []
                pieces.append(_filled(_cells(leaf, "json"), "null"))
            lit.append("}")
        else:
            pieces.append(pa.scalar("".join(lit), pa.string()))
            lit = []
            pieces.append(_filled(_cells(c, "json"), "null"))
    lit.append("}")
    pieces.append(pa.scalar("".join(lit), pa.string()))
    rows = pc.binary_join_element_wise(*pieces, "")
    return _join_rows(rows, ",\n  ")


def _json(cols: Mapping[str, _Leaf | dict[str, _Leaf]], params: Mapping[str, Any] | None,
          summary: Mapping[str, Any] | None) -> str:
    dump = json.JSONEncoder(ensure_ascii=False, allow_nan=False).encode
    parts: list[str] = ["{\n"]  # joined once at the end: the rows' text is copied once
    if params is not None:
        parts.append(f' "params": {dump(to_plain(params))},\n')
    if _n_rows(cols):
        parts += [' "results": [\n  ', _json_rows(cols), "\n ]"]
    else:
        parts.append(' "results": []')
    if summary is not None:
        parts.append(f',\n "summary": {dump(to_plain(summary))}')
    parts.append("\n}\n")
    return "".join(parts)


# --------------------------------------------------------------------------- the human table


def _g(v: Any) -> str:
    """A parameter or summary value as people read it (numbers with %g, booleans yes/no)."""
    if v is None:
        return "-"
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, float, np.integer, np.floating)):
        return format(v, "g")
    if isinstance(v, (list, tuple)):
        return ",".join(_g(x) for x in v)
    return str(v)


def _summary_value(v: Any) -> str:
    if isinstance(v, float):
        return format(v, ".4g")
    return _g(v) if isinstance(v, (bool, type(None))) else str(v)


def _table_cells(leaf: _Leaf, spec: TableColumn) -> list[str]:
    v = leaf.values
    k = leaf.kind
    if k == "b":
        cells = np.where(v, "yes", "no").tolist()
    elif k == "f":
        cells = list(map(spec.fmt.__mod__, v.tolist()))
        for i in np.flatnonzero(np.isnan(v)).tolist():
            cells[i] = spec.missing
    elif k == "i":
        fmt = spec.fmt.__mod__ if "d" in spec.fmt else str
        cells = list(map(fmt, v.tolist()))
    else:
        cells = v.tolist()
    if leaf.mask is not None:
        for i in np.flatnonzero(leaf.mask).tolist():
            cells[i] = spec.missing
    return cells


def _lookup(cols: Mapping[str, _Leaf | dict[str, _Leaf]], key: str) -> _Leaf | None:
    head, _, tail = key.partition(".")
    c = cols.get(head)
    if isinstance(c, dict):
        return c.get(tail) if tail else None
    return c if not tail else None


def _header_line(params: Mapping[str, Any]) -> str:
    return "# " + ", ".join(f"{k} = {_g(v)}" for k, v in to_plain(dict(params)).items())


def _summary_lines(summary: Mapping[str, Any]) -> list[str]:
    flat = {k: v for k, v in summary.items() if not isinstance(v, Mapping)}
    lines = []
    if flat:
        lines.append("# " + ", ".join(f"{k} = {_summary_value(v)}" for k, v in flat.items()))
    for k, v in summary.items():
        if isinstance(v, Mapping):
            lines.append(f"# {k}: " + ", ".join(
                f"{kk} = {_summary_value(vv)}" for kk, vv in v.items()))
    return lines


def _table(cols: Mapping[str, _Leaf | dict[str, _Leaf]], spec: Sequence[TableColumn] | None,
           params: Mapping[str, Any] | None, summary: Mapping[str, Any] | None) -> str:
    if spec is None:
        chosen = [(TableColumn(name, name), leaf) for name, leaf in _flat(cols).items()]
    else:
        chosen = [(s, leaf) for s in spec if (leaf := _lookup(cols, s.key)) is not None]
    body = [_table_cells(leaf, s) for s, leaf in chosen]
    widths = [max([len(s.header), *map(len, c)]) for (s, _), c in zip(chosen, body)]
    lines: list[str] = []
    if params is not None:
        lines.append(_header_line(params))
    lines.append("  ".join(s.header.ljust(w) for (s, _), w in zip(chosen, widths)).rstrip())
    if body and body[0]:
        row = "  ".join(f"%-{w}s" for w in widths).__mod__
        lines.extend(r.rstrip() for r in map(row, zip(*body)))
    if summary is not None:
        lines.extend(_summary_lines(summary))
    return "\n".join(lines) + "\n"


def render_table(
    columns: Columns,
    spec: Sequence[TableColumn] | None = None,
    *,
    params: Mapping[str, Any] | None = None,
    summary: Mapping[str, Any] | None = None,
) -> str:
    """The human table: aligned columns, parameters above, summary below.

    Parameters
    ----------
    columns : mapping
        The result columns.
    spec : sequence of TableColumn, optional
        Which columns to show, with headers and number formats (absent columns are skipped);
        default every column with ``%.6g`` numbers.
    params, summary : mapping, optional
        A ``# k = v, ...`` header line, and footer lines (a nested mapping gets its own line).

    Returns
    -------
    str
        The table's text, one line per row, ending in a newline.

    Examples
    --------
    >>> print(render_table({"k_x": [0.9, 1.3], "ok": [False, True]},
    ...                    [TableColumn("k_x", "k_x"), TableColumn("certified", "ok")],
    ...                    params={"tau": 0.1}, summary={"n": 2, "share": 0.5}), end="")
    # tau = 0.1
    k_x  certified
    0.9  no
    1.3  yes
    # n = 2, share = 0.5
    """
    return _table(_normalise(columns), spec, params, summary)


# --------------------------------------------------------------------------- binary formats


def _parquet_bytes(cols: Mapping[str, _Leaf | dict[str, _Leaf]], params: Mapping[str, Any] | None,
                   summary: Mapping[str, Any] | None) -> bytes:
    pa, _ = _pa()
    import pyarrow.parquet as pq

    arrays = {}
    for name, leaf in _flat(cols).items():
        mask = leaf.mask
        arrays[name] = pa.array(leaf.values, mask=mask) if mask is not None else pa.array(leaf.values)
    meta = {b"stringstab.params": json.dumps(to_plain(dict(params or {})), ensure_ascii=False),
            b"stringstab.summary": json.dumps(to_plain(dict(summary or {})), ensure_ascii=False)}
    table = pa.table(arrays).replace_schema_metadata(meta)
    buf = io.BytesIO()
    pq.write_table(table, buf)
    return buf.getvalue()


def _npz_arrays(cols: Mapping[str, _Leaf | dict[str, _Leaf]], params: Mapping[str, Any] | None,
                summary: Mapping[str, Any] | None) -> dict[str, npt.NDArray[Any]]:
    arrays: dict[str, npt.NDArray[Any]] = {}
    for name, leaf in _flat(cols).items():
        v = leaf.values
        if leaf.mask is not None and leaf.kind in "ib":
            v = np.where(leaf.mask, np.nan, v.astype(np.float64))
        elif leaf.mask is not None and leaf.kind == "f":
            v = np.where(leaf.mask, np.nan, v)
        arrays[name] = v
    arrays["_params"] = np.array(json.dumps(to_plain(dict(params or {})), ensure_ascii=False))
    arrays["_summary"] = np.array(json.dumps(to_plain(dict(summary or {})), ensure_ascii=False))
    return arrays


# --------------------------------------------------------------------------- entry points


def _check_format(fmt: str, formats: Iterable[str] = RESULT_FORMATS) -> None:
    formats = tuple(formats)
    if fmt not in formats:
        raise StringStabError(f"output format must be one of {', '.join(formats)}; got {fmt!r}")


def format_results(
    columns: Columns,
    fmt: str = "table",
    *,
    params: Mapping[str, Any] | None = None,
    summary: Mapping[str, Any] | None = None,
    table: Sequence[TableColumn] | None = None,
) -> str:
    """The result columns as ``table``, ``json`` or ``csv`` text (see the module docstring).

    Parameters
    ----------
    columns : mapping
        Ordered columns ``name → 1-D array`` (or ``name → {name → array}``), one length.
    fmt : {"table", "json", "csv"}, default "table"
        The text format (binary formats go through :func:`write_results`).
    params : mapping, optional
        Settings of the run: a ``#`` header line of the table, the ``params`` object of the JSON,
        the scalar ones repeated as trailing CSV columns.
    summary : mapping, optional
        Totals of the run: ``#`` footer lines of the table and the ``summary`` object of the
        JSON (not written in CSV).
    table : sequence of TableColumn, optional
        The columns of the human table (with units and rounding); default all columns.

    Returns
    -------
    str
        The text, newline-terminated.

    Raises
    ------
    StringStabError
        On an unknown format or ragged columns.

    Examples
    --------
    >>> print(format_results({"k_x": [1.0, 0.5], "verdict": ["certified", "not_certified"]},
    ...                      "csv", params={"tau": 0.1}), end="")
    k_x,verdict,tau
    1.0,certified,0.1
    0.5,not_certified,0.1
    >>> print(format_results({"k_x": [1.0], "sup": [float("inf")]}, "json"), end="")
    {
     "results": [
      {"k_x": 1.0, "sup": null}
     ]
    }
    """
    _check_format(fmt, ("table", "json", "csv"))
    cols = _normalise(columns)
    if fmt == "table":
        return _table(cols, table, params, summary)
    if fmt == "json":
        return _json(cols, params, summary)
    return _csv(cols, params)


def write_text(text: str, dest: str | os.PathLike[str] | IO[str], *,
               what: str = "output file") -> None:
    """Write text to a path atomically (temporary file + rename) or to a text stream.

    A stream that cannot encode a character (an ASCII terminal and ``Γ``) gets ``?`` instead.

    Parameters
    ----------
    text : str
        The text written.
    dest : path or text stream
        A path is written as UTF-8 through a temporary file and renamed; a stream is written to
        (and not closed).
    what : str, default "output file"
        What the file is, as the first words of an error message.

    Raises
    ------
    StringStabError
        When the file cannot be written.
    """
    if isinstance(dest, (str, os.PathLike)):
        atomic_write_bytes(dest, text.encode("utf-8"), what=what)
        return
    try:
        dest.write(text)
    except UnicodeEncodeError:  # e.g. an ASCII terminal: Γ, ω, ‖ become '?'
        enc = getattr(dest, "encoding", None) or "ascii"
        dest.write(text.encode(enc, "replace").decode(enc))


def write_results(
    columns: Columns,
    dest: str | os.PathLike[str] | IO[str] | None,
    fmt: str = "table",
    *,
    params: Mapping[str, Any] | None = None,
    summary: Mapping[str, Any] | None = None,
    table: Sequence[TableColumn] | None = None,
    what: str = "output file",
) -> None:
    """Write result columns in any of :data:`RESULT_FORMATS` to a file (atomically) or a stream.

    Parameters
    ----------
    columns : mapping
        Ordered columns ``name → 1-D array`` (or ``name → {name → array}``), one length.
    dest : path, text stream or None
        A path is written through a temporary file and renamed (complete or absent);
        ``None`` is standard output.  ``parquet`` and ``npz`` need a path.
    fmt : str
        One of :data:`RESULT_FORMATS`.
    params, summary : mapping, optional
        Settings of the run and its totals.
    table : sequence of TableColumn, optional
        The columns of the human table.
    what : str
        How error messages name the destination (e.g. ``"--out"``).

    Raises
    ------
    StringStabError
        On an unknown format, ragged columns, a binary format to a stream, or a file that
        cannot be written.

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "r.npz"
    >>> write_results({"k_x": np.array([0.5, 1.0])}, p, "npz", params={"tau": 0.1})
    >>> with np.load(p) as z:
    ...     z["k_x"].tolist(), str(z["_params"])
    ([0.5, 1.0], '{"tau": 0.1}')
    """
    _check_format(fmt)
    if dest is None:
        dest = sys.stdout
    is_path = isinstance(dest, (str, os.PathLike))
    if fmt in BINARY_FORMATS and not is_path:
        raise StringStabError(f"the {fmt} format is binary: expected an output file (--out FILE)")
    cols = _normalise(columns)
    if fmt == "parquet":
        atomic_write_bytes(Path(dest), _parquet_bytes(cols, params, summary),  # type: ignore[arg-type]
                           what=what)
        return
    if fmt == "npz":
        arrays = _npz_arrays(cols, params, summary)
        with atomic_path(dest, what=what) as tmp:  # type: ignore[arg-type]
            np.savez(tmp, **arrays)  # type: ignore[arg-type]
        return
    if fmt == "table":
        text = _table(cols, table, params, summary)
    elif fmt == "json":
        text = _json(cols, params, summary)
    else:
        text = _csv(cols, params)
    write_text(text, dest, what=what)  # type: ignore[arg-type]
