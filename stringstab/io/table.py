"""The human table of a result: chosen columns with units and rounding, parameters and summary.

``table`` is the format for people: the columns named by :class:`TableColumn` (header with its
unit, printf format), the run's parameters in a ``#`` header line and its summary in ``#``
footer lines.  The columns come in the model of :mod:`stringstab.io.columns`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .columns import Columns, Leaf, Normalised, flat_leaves, normalise_columns
from .plain import to_plain

__all__ = ["TableColumn", "human_value", "render_table"]


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


def human_value(v: Any) -> str:
    """A parameter or summary value as people read it (numbers with %g, booleans yes/no).

    Parameters
    ----------
    v : object
        A number, boolean, None, string or a list of them.

    Returns
    -------
    str
        ``-`` for None, ``yes``/``no``, ``%g`` numbers, list items joined with ``,``.

    Examples
    --------
    >>> human_value(0.1), human_value(True), human_value([1, 2.5])
    ('0.1', 'yes', '1,2.5')
    """
    if v is None:
        return "-"
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, float, np.integer, np.floating)):
        return format(v, "g")
    if isinstance(v, (list, tuple)):
        return ",".join(human_value(x) for x in v)
    return str(v)


def _summary_value(v: Any) -> str:
    if isinstance(v, float):
        return format(v, ".4g")
    return human_value(v) if isinstance(v, (bool, type(None))) else str(v)


def _table_cells(leaf: Leaf, spec: TableColumn) -> list[str]:
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


def _lookup(cols: Normalised, key: str) -> Leaf | None:
    head, _, tail = key.partition(".")
    c = cols.get(head)
    if isinstance(c, dict):
        return c.get(tail) if tail else None
    return c if not tail else None


def _header_line(params: Mapping[str, Any]) -> str:
    return "# " + ", ".join(f"{k} = {human_value(v)}" for k, v in to_plain(dict(params)).items())


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


def _table(cols: Normalised, spec: Sequence[TableColumn] | None,
           params: Mapping[str, Any] | None, summary: Mapping[str, Any] | None) -> str:
    if spec is None:
        chosen = [(TableColumn(name, name), leaf) for name, leaf in flat_leaves(cols).items()]
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
    return _table(normalise_columns(columns), spec, params, summary)

