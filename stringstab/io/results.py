"""Writing result tables: the one entry point of every command's results, in five formats.

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

This module holds the entry points and picks the renderer: the column model is
:mod:`~stringstab.io.columns`, the renderers :mod:`~stringstab.io.table` (``table``),
:mod:`~stringstab.io.text_formats` (``json``, ``csv``) and :mod:`~stringstab.io.binary_formats`
(``parquet``, ``npz``).  Every result type owns its columns (e.g.
:meth:`stringstab.certify.continuous.CertificateBatch.columns`); this module knows none of them.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..errors import StringStabError
from .binary_formats import npz_arrays, parquet_bytes
from .columns import Columns
from .outputs import atomic_path, atomic_write_bytes
from .table import TableColumn, render_table
from .text_formats import render_csv, render_json

__all__ = [
    "BINARY_FORMATS",
    "RESULT_FORMATS",
    "format_results",
    "write_results",
    "write_text",
]

#: Every format :func:`write_results` writes.
RESULT_FORMATS: tuple[str, ...] = ("table", "json", "csv", "parquet", "npz")
#: Formats that need a file (not a text stream).
BINARY_FORMATS: tuple[str, ...] = ("parquet", "npz")


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
    if fmt == "table":
        return render_table(columns, table, params=params, summary=summary)
    if fmt == "json":
        return render_json(columns, params, summary)
    return render_csv(columns, params)


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
    if fmt == "parquet":
        atomic_write_bytes(Path(dest), parquet_bytes(columns, params, summary),  # type: ignore[arg-type]
                           what=what)
        return
    if fmt == "npz":
        arrays = npz_arrays(columns, params, summary)
        with atomic_path(dest, what=what) as tmp:  # type: ignore[arg-type]
            np.savez(tmp, **arrays)  # type: ignore[arg-type]
        return
    text = format_results(columns, fmt, params=params, summary=summary, table=table)
    write_text(text, dest, what=what)  # type: ignore[arg-type]
