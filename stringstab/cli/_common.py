"""Arguments and helpers shared by the sub-commands (one definition of each)."""

from __future__ import annotations

import argparse
import re
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
from ..params import (
    DEFAULT_DELTA,
    DEFAULT_HEADWAY,
    DEFAULT_TAU,
    Box,
    Params,
    check_params,
    parameter_model,
    positive,
)
from ..ranges import check_magnitude, sensible_warning

__all__ = [
    "NEGATIVE_NUMBER",
    "RESULT_FORMATS",
    "add_gain_arguments",
    "add_model_arguments",
    "add_output_arguments",
    "check_horizon",
    "check_output",
    "gains_from_args",
    "integer",
    "loop_params",
    "shown_params",
    "warn_beyond_sensible",
]

#: argparse (< 3.13) reads "-0.5,1,1" or "-2,2" as an unknown option; anything that
#: starts like a negative number (or -inf/-nan, rejected later with a clear
#: message) is a value.  Installed on every sub-parser by ``stringstab.cli``.
NEGATIVE_NUMBER = re.compile(r"^-(\.?\d|inf|nan)", re.IGNORECASE)


def integer(name: str, text: Any, minimum: int) -> int:
    """A command-line integer >= ``minimum`` (a step budget, a seed, a count).

    Examples
    --------
    >>> integer("--steps", "200", 1)
    200
    >>> integer("--seed", "-1", 0)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: --seed must be an integer >= 0; got -1
    """
    try:
        v = int(str(text))
    except ValueError as e:
        raise StringStabError(f"{name} must be an integer >= {minimum}; got {text!r}") from e
    if v < minimum:
        raise StringStabError(f"{name} must be an integer >= {minimum}; got {v}")
    return v


def add_model_arguments(p: argparse.ArgumentParser) -> None:
    """``--tau --delta --headway`` (numbers or ``LO:HI`` intervals) and ``--sample-time``."""
    p.add_argument("--tau", default=str(DEFAULT_TAU), metavar="S|LO:HI",
                   help=f"actuator lag τ in s, > 0, or an interval LO:HI (default: {DEFAULT_TAU})")
    p.add_argument("--delta", default=str(DEFAULT_DELTA), metavar="S|LO:HI",
                   help=f"communication delay δ in s, >= 0, or an interval LO:HI (default: {DEFAULT_DELTA})")
    p.add_argument("--headway", default=str(DEFAULT_HEADWAY), metavar="S|LO:HI",
                   help=f"desired time headway T* in s, >= 0, or an interval LO:HI "
                        f"(default: {DEFAULT_HEADWAY})")
    p.add_argument("--sample-time", metavar="H",
                   help="certify the sampled-data loop: every vehicle samples with period H s and "
                        "holds its command (zero-order hold); default: the continuous-time loop")


def loop_params(args: argparse.Namespace) -> tuple[Params | Box, float | None]:
    """The loop asked for: (τ, δ, T*) as :class:`Params` or, with any ``LO:HI``, a :class:`Box`;
    and the sample time H (None: continuous time), each checked."""
    values = (args.tau, args.delta, args.headway)
    if any(":" in str(v) for v in values):
        model: Params | Box = parameter_model(*(str(v) for v in values))
    else:  # numbers: the point checks and messages ('tau ... must be ... > 0 s; got '0'')
        model = Params(*check_params(*values))
    H = None if args.sample_time is None else positive(
        "--sample-time (sampling period H)", args.sample_time, unit=" s")
    if H is not None:
        check_magnitude("sample_time", H, name="--sample-time")
    box = Box.of(model)
    warn_beyond_sensible(args, [("tau", box.tau[1], "--tau"), ("delta", box.delta[1], "--delta"),
                                ("headway", box.headway[1], "--headway"),
                                ("sample_time", H, "--sample-time")])
    return model, H


def warn_beyond_sensible(args: Any, values: list[tuple[str, float | None, str]]) -> None:
    """One warning line on stderr per value beyond its sensible range (:mod:`stringstab.ranges`).

    Parameters
    ----------
    args : argparse.Namespace
        The command's arguments (``args.command`` names it in the warning).
    values : list of (kind, value, option)
        The kind of :data:`stringstab.ranges.RANGES`, the value (None: skipped) and the option.
    """
    import sys

    for kind, value, option in values:
        if value is None:
            continue
        w = sensible_warning(kind, value, name=option)
        if w is not None:
            print(f"stringstab {getattr(args, 'command', '')}: warning: {w}", file=sys.stderr)


def shown_params(model: Params | Box, H: float | None) -> dict[str, Any]:
    """τ, δ, T* (a number, or [lo, hi] for an interval) and the sample time, for outputs.

    Examples
    --------
    >>> shown_params(Box((0.1, 0.5), (0.2, 0.2), (1.1, 1.1)), 0.1)
    {'tau': [0.1, 0.5], 'delta': 0.2, 'headway': 1.1, 'sample_time': 0.1}
    """
    out: dict[str, Any] = {}
    for k, (lo, hi) in Box.of(model).as_dict().items():
        out[k] = lo if lo == hi else [lo, hi]
    out["sample_time"] = H
    return out


def check_horizon(H: float | None, table: GainTable) -> None:
    """Refuse a sample time longer than the time span of a gain time series (its ``t`` column).

    Raises
    ------
    StringStabError
        When H exceeds max(t) − min(t): no sampled loop of period H fits in the data.
    """
    t = getattr(table, "t", None)
    if H is None or t is None or len(t) == 0:
        return
    t = np.asarray(t, dtype=float)
    span = float(t.max() - t.min())
    if H > span:
        raise StringStabError(
            f"--sample-time must not exceed the horizon of the data; the t column of "
            f"{table.source} spans {span:g} s ({len(t)} row(s), from {t.min():g} to {t.max():g} s); "
            f"got --sample-time {H:g} s")


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
    """One warning when some gain is beyond the sensible range (the largest one named)."""
    K = np.abs(np.stack([table.k_x, table.k_v, table.k_a]))
    if K.size and float(K.max()) > 0:
        j, i = np.unravel_index(int(np.argmax(K)), K.shape)
        name = ("k_x", "k_v", "k_a")[int(j)]
        warn_beyond_sensible(args, [("gain", float(getattr(table, name)[int(i)]),
                                     f"{name} (row {int(i) + 1})")])
