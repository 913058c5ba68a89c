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

This module is the one way in (:func:`read_gains`, :func:`parse_triple`); the table and the
checks every format shares live in :mod:`stringstab.io.gain_table`, the readers of the text
formats (CSV, JSON) in :mod:`stringstab.io.gain_text` and of the array formats (NPZ, Parquet)
in :mod:`stringstab.io.gain_arrays`.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import IO

from ..errors import StringStabError, show
from .gain_arrays import read_npz_gains, read_parquet_gains
from .gain_table import GAIN_COLUMNS, GainTable, finite_number
from .gain_text import read_csv_gains, read_json_gains
from .text_input import read_stream, read_text

__all__ = [
    "INPUT_FORMATS",
    "parse_triple",
    "read_gains",
]

#: Gain file formats, by file extension.
INPUT_FORMATS: dict[str, str] = {".csv": "csv", ".json": "json", ".npz": "npz",
                                 ".parquet": "parquet"}


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
    kx, kv, ka = (finite_number(p, f"{label}, {c}") for p, c in zip(parts, GAIN_COLUMNS))
    return kx, kv, ka


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
        return read_json_gains(text, name) if kind == "json" else read_csv_gains(text, name)

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
        return read_npz_gains(path, name)
    if kind == "parquet":
        return read_parquet_gains(path, name)
    text = read_text(path, label=name, expected=f"a {kind.upper()} gain file")
    return read_json_gains(text, name) if kind == "json" else read_csv_gains(text, name)
