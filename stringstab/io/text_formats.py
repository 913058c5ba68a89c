"""The ``csv`` and ``json`` texts of a result, formatted column by column in C (pyarrow).

Numbers are written in their shortest form that reads back to the same double (``0.1``,
``1.0``); every cell is converted column by column by pyarrow, so writing is not slower than
computing.  pyarrow is imported only when one of these formats is written.  The columns come
in the model of :mod:`stringstab.io.columns`.
"""

from __future__ import annotations

import io
import json
from collections.abc import Callable, Mapping
from typing import Any, BinaryIO

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from .columns import Columns, Leaf, Normalised, flat_leaves, n_rows, normalise_columns
from .plain import to_plain
from .table import human_value

__all__ = ["render_csv", "render_json", "warm_up", "write_csv"]


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
    """Import pyarrow and its compute and CSV modules (about 0.3 s) ahead of a large write.

    E.g. in a thread while the results are computed in worker processes.
    """
    _pa()
    import pyarrow.csv  # noqa: F401


def _mapped(values: npt.NDArray[Any], fn: Callable[[Any], str]) -> Any:
    """``fn`` applied to each distinct value, then spread to every row (few distinct values)."""
    pa, _ = _pa()
    uniq, inverse = np.unique(values, return_inverse=True)
    return pa.array([fn(u) for u in uniq.tolist()], type=pa.string()).take(
        pa.array(np.ravel(inverse))
    )


def _float_cells(v: npt.NDArray[Any], mask: npt.NDArray[np.bool_] | None) -> Any:
    """Float cells: the shortest round-trip digits, ``.0`` on integral values, null where missing.

    A non-finite number is missing too.  The missing cells are nulls from the start (only the
    present numbers are formatted), and only the integral values are formatted a second time.
    """
    pa, pc = _pa()
    bad = ~np.isfinite(v)
    if bad.any():
        mask = bad if mask is None else (mask | bad)
    if mask is not None and not mask.any():
        mask = None
    s = pc.cast(pa.array(v, type=pa.float64(), mask=mask), pa.string())  # shortest round-trip
    # integral values keep a '.0', as Python writes them (1.0, not 1)
    whole = (np.abs(v) < 1e15) & (np.trunc(v) == v)
    if mask is not None:
        whole &= ~mask
    if whole.any():  # those cells only, formatted as integers, replace theirs
        w = np.asarray(v, dtype=np.float64)[whole]
        as_int = pc.binary_join_element_wise(
            pc.cast(pa.array(w.astype(np.int64)), pa.string()), ".0", "")
        negative_zero = (w == 0.0) & np.signbit(w)
        if negative_zero.any():
            as_int = pc.if_else(pa.array(negative_zero), pa.scalar("-0.0", pa.string()), as_int)
        s = pc.replace_with_mask(s, pa.array(whole), as_int)
    return s


def _cells(leaf: Leaf, style: str) -> Any:
    """The column as a pyarrow string array of CSV or JSON cells (null where missing)."""
    pa, pc = _pa()
    if leaf.codes is not None:  # each distinct label formatted once, then spread
        return _cells(Leaf(leaf.base, None), style).take(pa.array(leaf.codes))
    v = leaf.values
    mask = leaf.mask
    k = leaf.kind
    if k == "f":
        return _float_cells(v, mask)
    if k == "i":
        s = pc.cast(pa.array(v, type=pa.int64()), pa.string())
    elif k == "b":  # the two words, spread by the values (no string per row formed here)
        t, f = ("true", "false") if style == "json" else ("True", "False")
        s = pa.array([f, t], type=pa.string()).take(pa.array(np.asarray(v, dtype=np.int8)))
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
    """The rows joined by ``sep``, built in C from the array's character buffer.

    Each row gets ``sep`` appended in C, and the text is the array's character buffer read
    once, without the last ``sep`` (no list of rows, no second join, no copy to cut the end).
    """
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
            v = ",".join(human_value(x) for x in v)
        out[k] = v
    return out


def _csv_cells(columns: Columns, params: Mapping[str, Any] | None) -> tuple[str, list[Any], bool]:
    """(header, the cells column by column as pyarrow arrays, whether some carry quotes)."""
    cols = normalise_columns(columns)
    pa, pc = _pa()
    flat = flat_leaves(cols)
    n = n_rows(cols)
    extra = {k: v for k, v in _params_flat(params).items() if k not in flat}
    header = ",".join(_csv_quote(h) for h in [*flat, *extra])
    if n == 0:
        return header, [], False
    pieces = [_filled(_cells(leaf, "csv"), "") for leaf in flat.values()]
    extra_cells = [_csv_cell(v) for v in extra.values()]
    pieces += [pa.repeat(pa.scalar(c, pa.string()), n) for c in extra_cells]
    # only text can carry quotes (numbers and booleans never do); a categorical's labels suffice
    quoted = any(c.startswith('"') for c in extra_cells) or any(
        any(_csv_quote(str(x)) != str(x) for x in leaf.base.tolist()) if leaf.codes is not None
        else pc.any(pc.starts_with(cells, '"')).as_py()
        for leaf, cells in zip(flat.values(), pieces) if leaf.kind not in "bif")
    return header, pieces, quoted


def _write_rows(pieces: list[Any], quoted: bool, sink: Any) -> None:
    """The rows of :func:`_csv_cells`' cells, each newline-terminated, as UTF-8 into ``sink``."""
    pa, pc = _pa()
    if not quoted:
        # Arrow's CSV writer lays the (already formatted) cells out in C++, 3x faster than
        # joining them here; "none" because every cell is final text needing no quotes.
        import pyarrow.csv as pa_csv

        table = pa.table({str(i): p for i, p in enumerate(pieces)})
        pa_csv.write_csv(table, sink, pa_csv.WriteOptions(include_header=False,
                                                          quoting_style="none"))
        return
    rows = pc.binary_join_element_wise(*pieces, ",")  # some cells carry their own quotes
    sink.write(_join_rows(rows, "\n").encode("utf-8") + b"\n")


def render_csv(columns: Columns, params: Mapping[str, Any] | None = None) -> str:
    """The ``csv`` text of result columns: one row per result, groups flattened with ``_``.

    The scalar parameters are repeated as trailing columns (lists joined with ``,``); numbers
    are written in their shortest round-trip form, a non-finite number as an empty field.
    :func:`write_csv` writes the same text, UTF-8 encoded, to a binary file.

    Parameters
    ----------
    columns : mapping
        Ordered columns ``name → 1-D array`` (or ``name → {name → array}``), one length.
    params : mapping, optional
        Settings of the run.

    Returns
    -------
    str
        The header and the rows, newline-terminated.

    Raises
    ------
    StringStabError
        On ragged or malformed columns.
    """
    header, pieces, quoted = _csv_cells(columns, params)
    if not pieces:
        return header + "\n"
    buf = io.BytesIO()
    _write_rows(pieces, quoted, buf)
    return header + "\n" + buf.getvalue().decode("utf-8")


def write_csv(columns: Columns, sink: BinaryIO, params: Mapping[str, Any] | None = None) -> None:
    """Write the text of :func:`render_csv`, UTF-8 encoded, to the binary file ``sink``.

    The same bytes as ``render_csv(columns, params).encode("utf-8")``, without forming the
    text: the rows go from Arrow's buffers to the file (a region map of 641,601 rows is a
    60 MB text, decoded, joined and encoded again otherwise).

    Parameters
    ----------
    columns : mapping
        Ordered columns ``name → 1-D array`` (or ``name → {name → array}``), one length.
    sink : binary file
        Open for writing (e.g. ``open(path, "wb")``); written from its position, not closed.
    params : mapping, optional
        Settings of the run.

    Raises
    ------
    StringStabError
        On ragged or malformed columns (nothing is written then).

    Examples
    --------
    >>> buf = io.BytesIO()
    >>> write_csv({"k_x": [1.0, 0.25], "ok": [True, False]}, buf, params={"tau": 0.1})
    >>> buf.getvalue() == render_csv({"k_x": [1.0, 0.25], "ok": [True, False]},
    ...                              {"tau": 0.1}).encode("utf-8")
    True
    """
    header, pieces, quoted = _csv_cells(columns, params)
    sink.write(header.encode("utf-8") + b"\n")
    if pieces:
        _write_rows(pieces, quoted, sink)


def _csv_cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return repr(v)
    return _csv_quote(str(v))


def _json_rows(cols: Normalised) -> str:
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


def render_json(columns: Columns, params: Mapping[str, Any] | None = None,
                summary: Mapping[str, Any] | None = None) -> str:
    """The ``json`` text of result columns: ``{"params", "results", "summary"}``.

    One result per line, groups nested, non-finite numbers as ``null``.

    Parameters
    ----------
    columns : mapping
        Ordered columns ``name → 1-D array`` (or ``name → {name → array}``), one length.
    params, summary : mapping, optional
        Settings and totals of the run (omitted when None).

    Returns
    -------
    str
        The JSON text, newline-terminated.

    Raises
    ------
    StringStabError
        On ragged or malformed columns.
    """
    cols = normalise_columns(columns)
    dump = json.JSONEncoder(ensure_ascii=False, allow_nan=False).encode
    parts: list[str] = ["{\n"]  # joined once at the end: the rows' text is copied once
    if params is not None:
        parts.append(f' "params": {dump(to_plain(params))},\n')
    if n_rows(cols):
        parts += [' "results": [\n  ', _json_rows(cols), "\n ]"]
    else:
        parts.append(' "results": []')
    if summary is not None:
        parts.append(f',\n "summary": {dump(to_plain(summary))}')
    parts.append("\n}\n")
    return "".join(parts)

