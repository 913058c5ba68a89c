"""Former home of gain-file reading and result writing (kept importable).

Reading gains lives in :mod:`stringstab.io.gains` and writing results in
:mod:`stringstab.io`; this module re-exports the reader and keeps the record-based
writer (``format_results(records, ...)``) of earlier versions, built on the columnar one.
New code should use :func:`stringstab.io.read_gains` and :func:`stringstab.io.write_results`.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import IO, Any

from . import io as _io
from .errors import StringStabError
from .io.gains import (
    GAIN_COLUMNS,
    INPUT_FORMATS,
    OPTIONAL_COLUMNS,
    GainTable,
    parse_triple,
    read_gains,
)
from .io.plain import to_plain

__all__ = [
    "FORMATS",
    "GAIN_COLUMNS",
    "INPUT_FORMATS",
    "OPTIONAL_COLUMNS",
    "GainTable",
    "format_results",
    "parse_triple",
    "read_gains",
    "write_results",
    "write_text",
]

#: Formats of the record-based :func:`format_results`.
FORMATS: tuple[str, str, str] = ("table", "json", "csv")


def format_results(
    records: Sequence[Mapping[str, Any]],
    fmt: str = "table",
    *,
    params: Mapping[str, Any] | None = None,
    summary: Mapping[str, Any] | None = None,
) -> str:
    """Render per-triple result records as a table, JSON or CSV text.

    The records (one dict per triple, one nesting level) are turned into columns
    (:func:`stringstab.io.columns_from_records`) and written by
    :func:`stringstab.io.format_results`; the table shows the certificate's columns
    (:data:`stringstab.certificate.TABLE_COLUMNS`).

    Parameters
    ----------
    records : sequence of mapping
        One dict per gain triple (values: numbers, strings, lists, or one level of dicts).
    fmt : {"table", "json", "csv"}
        Output format.
    params : mapping, optional
        Run parameters (τ, δ, T*, ...): a header line of the table, a ``"params"`` object
        in JSON, constant columns in CSV (unless a record already has that column).
    summary : mapping, optional
        Summary (e.g. :func:`stringstab.verdicts.verdict_summary`): lines under the table and
        a ``"summary"`` object in JSON; not written in CSV.

    Returns
    -------
    str
        The rendered text.

    Raises
    ------
    StringStabError
        If ``fmt`` is not one of :data:`FORMATS`.

    Examples
    --------
    >>> print(format_results([{"k_x": 1.0, "verdict": "certified"}], "csv",
    ...                      params={"tau": 0.1}), end="")
    k_x,verdict,tau
    1.0,certified,0.1
    """
    if fmt not in FORMATS:
        raise StringStabError(f"output format must be one of {', '.join(FORMATS)}; got {fmt!r}")
    table = None
    if fmt == "table":
        from .certificate import TABLE_COLUMNS

        table = TABLE_COLUMNS
    columns = _io.columns_from_records([to_plain(r) for r in records])
    return _io.format_results(columns, fmt, params=params, summary=summary, table=table)


def write_text(text: str, dest: str | os.PathLike[str] | IO[str]) -> None:
    """Write text to a path atomically (temporary file + rename) or to a text stream.

    Parameters
    ----------
    text : str
        The text to write.
    dest : str, path-like or text stream
        Destination file (replaced atomically) or an open text stream.

    Raises
    ------
    StringStabError
        When the file cannot be written.
    """
    try:
        _io.write_text(text, dest)
    except StringStabError as e:
        cause = e.__cause__
        reason = (getattr(cause, "strerror", None) or cause) if cause is not None else e
        raise StringStabError(f"{dest}: cannot write the output file ({reason})") from e


def write_results(
    records: Sequence[Mapping[str, Any]],
    dest: str | os.PathLike[str] | IO[str],
    fmt: str = "table",
    *,
    params: Mapping[str, Any] | None = None,
    summary: Mapping[str, Any] | None = None,
) -> None:
    """Write :func:`format_results` text to a path (atomically) or a text stream.

    Parameters
    ----------
    records : sequence of mapping
        One dict per gain triple (see :func:`format_results`).
    dest : str, path-like or text stream
        Destination file (replaced atomically) or an open text stream.
    fmt : {"table", "json", "csv"}
        Output format.
    params, summary : mapping, optional
        As for :func:`format_results`.

    Raises
    ------
    StringStabError
        On an unknown format or when the file cannot be written.
    """
    write_text(format_results(records, fmt, params=params, summary=summary), dest)
