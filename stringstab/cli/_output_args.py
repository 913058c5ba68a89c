"""The sub-commands' gain inputs and result outputs: ``--file``/triples, ``--out``, ``--format``."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import StringStabError, show
from ..io import (
    BINARY_FORMATS,
    RESULT_FORMATS,
    GainTable,
    check_output_file,
    parse_triple,
    read_gains,
)
from ..ranges import check_magnitude
from ._model_args import warn_beyond_sensible

__all__ = [
    "add_gain_arguments",
    "add_output_arguments",
    "check_output",
    "gains_from_args",
    "resolve_format",
]


def add_gain_arguments(p: argparse.ArgumentParser) -> None:
    """Positional ``K_X,K_V,K_A`` triples and ``--file F``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The command's parser (:func:`gains_from_args` reads the values).
    """
    p.add_argument("triples", nargs="*", metavar="K_X,K_V,K_A",
                   help="gain triples, e.g. 0.9,-0.5,1.1 (or use --file)")
    p.add_argument("--file", "-f", metavar="F",
                   help="read triples from a .csv, .json, .npz or .parquet file "
                        "('-' reads CSV/JSON from stdin)")


def add_output_arguments(p: argparse.ArgumentParser,
                         formats: tuple[str, ...] = RESULT_FORMATS) -> None:
    """``--format`` (default ``table``) and ``--out FILE`` of a command that writes results.

    The ``--format`` default is None, resolved later from ``--out``'s extension
    (:func:`check_output`).

    Parameters
    ----------
    p : argparse.ArgumentParser
        The command's parser.
    formats : tuple of str, default RESULT_FORMATS
        The formats ``--format`` accepts.
    """
    p.add_argument("--format", choices=formats, default=None,
                   help="output format (default: the --out file's extension, .json .csv "
                        ".parquet .npz, else table); parquet and npz need --out")
    p.add_argument("--out", "-o", metavar="FILE", help="write to FILE instead of standard output")


def check_output(args: Any) -> Path | None:
    """``--out`` checked before any work (see :func:`stringstab.io.check_output_file`).

    Returns the path, or None for standard output; a binary ``--format`` needs ``--out``.
    Resolves ``args.format`` (:func:`resolve_format`) first.

    Parameters
    ----------
    args : argparse.Namespace
        With ``format`` and ``out`` (:func:`add_output_arguments`); ``args.format`` is set to
        the resolved format.

    Returns
    -------
    Path or None
        The checked ``--out`` path, or None for standard output.

    Raises
    ------
    StringStabError
        A binary format without ``--out``, conflicting ``--format`` and extension, or an
        ``--out`` that cannot be written.
    """
    args.format = resolve_format(args.format, args.out, RESULT_FORMATS)
    if args.out is None:
        if args.format in BINARY_FORMATS:
            raise StringStabError(
                f"--format {args.format} writes a binary file; expected --out FILE, got none"
            )
        return None
    return check_output_file(args.out, what="--out")


#: The format a known ``--out`` extension names.
FORMAT_BY_EXTENSION: dict[str, str] = {
    ".json": "json", ".csv": "csv", ".parquet": "parquet", ".npz": "npz", ".txt": "table",
    ".tex": "latex",
}


def resolve_format(given: str | None, out: str | None, formats: tuple[str, ...],
                   default: str = "table") -> str:
    """The output format: ``--format`` if given, else the one ``--out``'s extension names.

    Parameters
    ----------
    given : str or None
        ``--format`` as given (None: not given).
    out : str or None
        ``--out``.
    formats : tuple of str
        The command's formats.
    default : str
        Without either.

    Returns
    -------
    str
        The format to write: ``given`` when set, else the one ``out``'s extension names,
        else ``default``.

    Raises
    ------
    StringStabError
        When ``--format`` and a known extension of ``--out`` name different formats.

    Examples
    --------
    >>> resolve_format(None, "v.json", ("table", "json")), resolve_format("csv", "v.dat", ("csv",))
    ('json', 'csv')
    >>> resolve_format("csv", "y.json", ("csv", "json"))
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: --format csv conflicts with --out y.json (a .json file is json); expected --format json, or an --out ending in the format's extension
    """
    ext = Path(out).suffix.lower() if out else ""
    by_ext = FORMAT_BY_EXTENSION.get(ext)
    by_ext = by_ext if by_ext in formats else None
    if given is None:
        return by_ext or default
    if by_ext is not None and by_ext != given:
        raise StringStabError(
            f"--format {given} conflicts with --out {out} (a {ext} file is {by_ext}); expected "
            f"--format {by_ext}, or an --out ending in the format's extension")
    return given


def gains_from_args(args: Any) -> GainTable:
    """The gains given as triples or ``--file`` (exactly one of the two).

    A gain beyond the physical bound is refused; one beyond the sensible range gets a warning.

    Parameters
    ----------
    args : argparse.Namespace
        With ``triples`` and ``file`` (:func:`add_gain_arguments`).

    Returns
    -------
    GainTable
        The gains k_x (1/s²), k_v (1/s), k_a, one row per triple or file row.

    Raises
    ------
    StringStabError
        Both or neither given, a malformed triple or file, or a gain beyond the physical bound.
    """
    if args.triples and args.file:
        raise StringStabError(
            f"expected gain triples or --file, not both; got {len(args.triples)} triple(s) "
            f"and --file {args.file}"
        )
    if args.file:
        table = read_gains(args.file)
        _warn_gains(args, table)
        return table
    if not args.triples:
        raise StringStabError(
            "expected gain triples K_X,K_V,K_A (e.g. 0.9,-0.5,1.1) or --file F; got none"
        )
    triples = [parse_triple(t, where=f"triple {i + 1} {show(t)}") for i, t in enumerate(args.triples)]
    table = GainTable.from_triples(triples, source="<command line>")
    _warn_gains(args, table)
    return table


def _warn_gains(args: Any, table: GainTable) -> None:
    """Refuse a gain beyond the physical bound, naming its row; warn beyond the sensible range.

    The physical bound (:mod:`stringstab.ranges`) is where the certificate's coefficients would
    overflow; the warning is given once.
    """
    from ..ranges import RANGES

    for name in ("k_x", "k_v", "k_a"):
        a = np.asarray(getattr(table, name), dtype=float)
        big = np.flatnonzero(np.abs(a) > RANGES["gain"][1])
        if big.size:
            check_magnitude("gain", float(a[big[0]]),
                            name=f"{table.source}, row {int(big[0]) + 1}, {name}")
    K = np.abs(np.stack([table.k_x, table.k_v, table.k_a]))
    if K.size and float(K.max()) > 0:
        j, i = np.unravel_index(int(np.argmax(K)), K.shape)
        name = ("k_x", "k_v", "k_a")[int(j)]
        warn_beyond_sensible(args, [("gain", float(getattr(table, name)[int(i)]),
                                     f"{name} (row {int(i) + 1})")])
