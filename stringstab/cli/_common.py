"""Arguments and helpers shared by the sub-commands (one definition of each)."""

from __future__ import annotations

import argparse
import re
from pathlib import Path
from typing import Any

from ..errors import StringStabError, show
from ..io import (
    BINARY_FORMATS,
    RESULT_FORMATS,
    GainTable,
    check_output_file,
    parse_triple,
    read_gains,
)
from ..params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU, check_params

__all__ = [
    "NEGATIVE_NUMBER",
    "RESULT_FORMATS",
    "add_gain_arguments",
    "add_model_arguments",
    "add_output_arguments",
    "check_output",
    "gains_from_args",
    "model_params",
]

#: argparse (< 3.13) reads "-0.5,1,1" or "-2,2" as an unknown option; anything that
#: starts like a negative number (or -inf/-nan, rejected later with a clear
#: message) is a value.  Installed on every sub-parser by ``stringstab.cli``.
NEGATIVE_NUMBER = re.compile(r"^-(\.?\d|inf|nan)", re.IGNORECASE)


def add_model_arguments(p: argparse.ArgumentParser) -> None:
    """``--tau --delta --headway`` with the documented defaults (IDL Table 2)."""
    p.add_argument("--tau", default=str(DEFAULT_TAU), metavar="S",
                   help=f"actuator lag τ in s, > 0 (default: {DEFAULT_TAU})")
    p.add_argument("--delta", default=str(DEFAULT_DELTA), metavar="S",
                   help=f"communication delay δ in s, >= 0 (default: {DEFAULT_DELTA})")
    p.add_argument("--headway", default=str(DEFAULT_HEADWAY), metavar="S",
                   help=f"desired time headway T* in s, >= 0 (default: {DEFAULT_HEADWAY})")


def model_params(args: argparse.Namespace) -> tuple[float, float, float]:
    """Validated (τ, δ, T*) from ``--tau --delta --headway``."""
    return check_params(args.tau, args.delta, args.headway)


def add_gain_arguments(p: argparse.ArgumentParser) -> None:
    """Positional ``K_X,K_V,K_A`` triples and ``--file F``."""
    p.add_argument("triples", nargs="*", metavar="K_X,K_V,K_A",
                   help="gain triples, e.g. 0.9,-0.5,1.1 (or use --file)")
    p.add_argument("--file", "-f", metavar="F",
                   help="read triples from a .csv, .json, .npz or .parquet file "
                        "('-' reads CSV/JSON from stdin)")


def add_output_arguments(p: argparse.ArgumentParser,
                         formats: tuple[str, ...] = RESULT_FORMATS) -> None:
    """``--format`` (default ``table``) and ``--out FILE`` of a command that writes results."""
    p.add_argument("--format", choices=formats, default="table",
                   help="output format (default: table); parquet and npz need --out")
    p.add_argument("--out", "-o", metavar="FILE", help="write to FILE instead of standard output")


def check_output(args: Any) -> Path | None:
    """``--out`` checked before any work (see :func:`stringstab.io.check_output_file`).

    Returns the path, or None for standard output; a binary ``--format`` needs ``--out``.
    """
    if args.out is None:
        if args.format in BINARY_FORMATS:
            raise StringStabError(
                f"--format {args.format} writes a binary file; expected --out FILE, got none"
            )
        return None
    return check_output_file(args.out, what="--out (expected a file path in an existing directory)")


def gains_from_args(args: Any) -> GainTable:
    """The gains given as triples or ``--file`` (exactly one of the two)."""
    if args.triples and args.file:
        raise StringStabError(
            f"expected gain triples or --file, not both; got {len(args.triples)} triple(s) "
            f"and --file {args.file}"
        )
    if args.file:
        return read_gains(args.file)
    if not args.triples:
        raise StringStabError(
            "expected gain triples K_X,K_V,K_A (e.g. 0.9,-0.5,1.1) or --file F; got none"
        )
    triples = [parse_triple(t, where=f"triple {i + 1} {show(t)}") for i, t in enumerate(args.triples)]
    return GainTable.from_triples(triples, source="<command line>")
