"""The readers of the text gain formats: CSV and JSON (:mod:`stringstab.io.gains` describes them).

Both take the text already read (:func:`stringstab.io.gains.read_gains` reads files and
streams) and refuse bad input in one line naming the line, item or key.
"""

from __future__ import annotations

import csv
import json
from typing import Any

import numpy as np

from ..errors import StringStabError, show
from .gain_table import (
    GAIN_COLUMNS,
    GainTable,
    resolve_columns,
    suggest_name,
    table_from_columns,
    vehicle_ids,
)

__all__ = ["read_csv_gains", "read_json_gains"]


def read_csv_gains(text: str, source: str) -> GainTable:
    """Gain triples from the text of a CSV file (the module docstring of :mod:`stringstab.io.gains`).

    Parameters
    ----------
    text : str
        The file's text.
    source : str
        The file's name, for messages.

    Returns
    -------
    GainTable
        The gains, with ``t`` and ``vehicle`` when the file has them.

    Raises
    ------
    StringStabError
        On an empty file, another separator than the comma, a missing or misspelt column, a
        row of the wrong width or a field that is not a finite number (naming its line).
    """
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
        index, ignored = resolve_columns(header, source)
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
    return table_from_columns(
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
        out["vehicle"] = vehicle_ids(ids)
    return out


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def read_json_gains(text: str, source: str) -> GainTable:
    """Gain triples from the text of a JSON file (the module docstring of :mod:`stringstab.io.gains`).

    Parameters
    ----------
    text : str
        The file's text: a list of objects or of triples, bare or under ``"gains"`` or
        ``"results"``.
    source : str
        The file's name, for messages.

    Returns
    -------
    GainTable
        The gains, with ``t`` and ``vehicle`` when the objects have them.

    Raises
    ------
    StringStabError
        On empty or invalid JSON, another shape, missing or misspelt keys, items with other
        keys than the first, or a value that is not a finite number (naming the item).
    """
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
                + suggest_name("gains", map(str, doc))
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
        return table_from_columns(cols, source, lambda c, i: f"{prefix}{i}], {c}")
    first: list[str] | None = None
    cols = {}
    for i, it in enumerate(items):
        if not isinstance(it, dict):
            raise StringStabError(
                f"{prefix}{i}]: expected an object with keys k_x, k_v, k_a "
                f"(or a triple [k_x, k_v, k_a]); found {type(it).__name__} {show(it)}"
            )
        keys = list(map(str, it))
        index, _ = resolve_columns(keys, f"{prefix}{i}]", what="key")
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
    return table_from_columns(cols, source, lambda c, i: f"{prefix}{i}], key {show(c)}")
