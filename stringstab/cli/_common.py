"""Arguments and helpers shared by the sub-commands (one definition of each)."""

from __future__ import annotations

import argparse
import re
from collections.abc import Sequence
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
    parameter_model,
    positive,
)
from ..ranges import check_magnitude, sensible_warning
from ._outcome import command_name

__all__ = [
    "NEGATIVE_NUMBER",
    "add_gain_arguments",
    "add_limit_arguments",
    "add_model_arguments",
    "add_output_arguments",
    "check_horizon",
    "check_output",
    "checked_leaders",
    "gains_from_args",
    "integer",
    "limits_from_args",
    "loop_params",
    "resolve_format",
    "shown_params",
    "warn_beyond_sensible",
]

#: argparse (< 3.13) reads "-0.5,1,1" or "-2,2" as an unknown option; anything that
#: starts like a negative number (or -inf/-nan, rejected later with a clear
#: message) is a value.  Installed on every sub-parser by ``stringstab.cli``.
NEGATIVE_NUMBER = re.compile(r"^-(\.?\d|inf|nan)", re.IGNORECASE)


def integer(name: str, text: Any, minimum: int, kind: str | None = None) -> int:
    """A command-line integer >= ``minimum`` (a step budget, a seed, a count).

    Parameters
    ----------
    name : str
        The option, for the error message (e.g. ``"--steps"``).
    text : object
        The value as given (its ``str`` is parsed as a base-10 integer).
    minimum : int
        The smallest value accepted.
    kind : str, optional
        A key of :data:`stringstab.ranges.COUNTS`: the largest value accepted
        (:func:`~stringstab.ranges.check_count`).

    Returns
    -------
    int
        The value.

    Raises
    ------
    StringStabError
        When it is not an integer, is below ``minimum`` or above the largest count of ``kind``.

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
    if kind is not None:
        from ..ranges import check_count

        check_count(kind, v, name=name)
    return v


def add_vehicle_arguments(p: argparse.ArgumentParser, *, defaults: bool = True) -> None:
    """``--tau --delta --headway --standstill --length`` of a simulated platoon's vehicles.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The parser to add them to.
    defaults : bool, optional
        True: τ, δ and T* default to the toolkit's values; False: to None (the command fills
        them, e.g. from a trained policy), the help still naming the toolkit's value.
    """
    from ..constants import STANDSTILL

    def default(v: float) -> float | None:
        return v if defaults else None

    p.add_argument("--tau", type=float, default=default(DEFAULT_TAU),
                   help=f"actuator lag, s (default {DEFAULT_TAU})")
    p.add_argument("--delta", type=float, default=default(DEFAULT_DELTA),
                   help=f"communication delay, s (default {DEFAULT_DELTA})")
    p.add_argument("--headway", type=float, default=default(DEFAULT_HEADWAY),
                   help=f"desired time headway T*, s (default {DEFAULT_HEADWAY})")
    p.add_argument("--standstill", type=float, default=STANDSTILL,
                   help=f"standstill spacing l0, m (default {STANDSTILL:g})")
    p.add_argument("--length", type=float, default=5.0, help="vehicle length, m (default 5)")


def add_model_arguments(p: argparse.ArgumentParser) -> None:
    """``--tau --delta --headway`` (numbers or ``LO:HI`` intervals) and ``--sample-time``.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The command's parser (the values are kept as strings; :func:`loop_params` checks them).
    """
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
    """The loop asked for, checked: the model (a point or a box) and the sample time H.

    The model is (τ, δ, T*) as :class:`Params` or, with any ``LO:HI``, a :class:`Box`; the
    sample time H is None for continuous time.  Warns on stderr (one line each) for values
    beyond their sensible range.

    Parameters
    ----------
    args : argparse.Namespace
        With ``tau``, ``delta``, ``headway`` (s, numbers or ``LO:HI``) and ``sample_time``
        (s or None), as added by :func:`add_model_arguments`.

    Returns
    -------
    model : Params or Box
        The point (τ, δ, T*) or the box of intervals.
    H : float or None
        The sample time (s), None for the continuous-time loop.

    Raises
    ------
    StringStabError
        A value that is not a number or interval, out of its domain (τ > 0, δ ≥ 0, T* ≥ 0,
        H > 0) or beyond the physical bound.
    """
    values = (args.tau, args.delta, args.headway)
    # the reaction delay θ_r of the commands that take --reaction-delay (issue 25)
    theta = getattr(args, "reaction_delay", None)
    values += () if theta is None else (theta,)
    if any(":" in str(v) for v in values):
        model: Params | Box = parameter_model(*(str(v) for v in values))
    else:  # numbers: the point checks and messages ('tau ... must be ... > 0 s; got '0'')
        model = Params(*values)
    H = None if args.sample_time is None else positive(
        "--sample-time (sampling period H)", args.sample_time, unit=" s")
    if H is not None:
        check_magnitude("sample_time", H, name="--sample-time")
    box = Box.of(model)
    warn_beyond_sensible(args, [("tau", box.tau[1], "--tau"), ("delta", box.delta[1], "--delta"),
                                ("headway", box.headway[1], "--headway"),
                                ("sample_time", H, "--sample-time"),
                                ("reaction_delay", box.reaction_delay[1], "--reaction-delay")])
    return model, H


def warn_beyond_sensible(args: Any, values: Sequence[tuple[str, float | None, str]]) -> None:
    """One warning line on stderr per value beyond its sensible range (:mod:`stringstab.ranges`).

    Parameters
    ----------
    args : argparse.Namespace
        The command's arguments (``args.command`` names it in the warning).
    values : list of (kind, value, option)
        The kind of :data:`stringstab.ranges.RANGES`, the value (None: skipped) and the option.
    """
    import sys

    from ..ranges import COUNTS, count_warning

    sub = getattr(args, "hcfs_command", None)
    command = f"{getattr(args, 'command', '')}{' ' + sub if sub else ''}"
    for kind, value, option in values:
        if value is None:
            continue
        w = (count_warning(kind, int(value), name=option) if kind in COUNTS
             else sensible_warning(kind, value, name=option))
        if w is not None:
            print(f"stringstab {command}: warning: {w}", file=sys.stderr)


def shown_params(model: Params | Box, H: float | None) -> dict[str, Any]:
    """τ, δ, T* (a number, or [lo, hi] for an interval) and the sample time, for outputs.

    Parameters
    ----------
    model : Params or Box
        The loop (from :func:`loop_params`).
    H : float or None
        The sample time (s); None for continuous time.

    Returns
    -------
    dict
        ``tau``, ``delta``, ``headway`` (s; a number, or [lo, hi]) and ``sample_time``.

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

    Nothing is checked for continuous time or a table without (or with an empty) ``t``.

    Parameters
    ----------
    H : float or None
        The sample time (s).
    table : GainTable
        The gains read.

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


def add_limit_arguments(p: argparse.ArgumentParser, *, speed_max: float | None = None,
                        accel_min: float | None = None, accel_max: float | None = None,
                        source: str = "IDL Table 2") -> None:
    """``--v-max --a-min --a-max``: the followers' limits (default: IDL Table 2).

    Parameters
    ----------
    p : argparse.ArgumentParser
        The command's parser.
    speed_max, accel_min, accel_max : float, optional
        Other defaults (the HCFS paper's ±3 m/s²), named by ``source`` in the help.
    source : str
        Where the defaults come from.
    """
    from .. import constants as c

    v = c.SPEED_MAX if speed_max is None else speed_max
    lo = c.ACCEL_MIN if accel_min is None else accel_min
    hi = c.ACCEL_MAX if accel_max is None else accel_max
    g = p.add_argument_group(f"followers' limits (defaults: {source})")
    g.add_argument("--v-max", default=str(v), metavar="M/S",
                   help=f"followers' speed limit v_max in m/s (default {v:g}); a faster leader "
                        "runs with a warning, one above 70 m/s is refused")
    g.add_argument("--a-min", default=str(lo), metavar="M/S2",
                   help=f"followers' braking limit acc_min in m/s², < 0 (default {lo:g})")
    g.add_argument("--a-max", default=str(hi), metavar="M/S2",
                   help=f"followers' acceleration limit acc_max in m/s², > 0 (default {hi:g})")


def limits_from_args(args: Any) -> Any:
    """The :class:`~stringstab.traffic.Limits` of ``--v-max --a-min --a-max``, checked.

    Parameters
    ----------
    args : argparse.Namespace
        With ``v_max`` (m/s), ``a_min`` and ``a_max`` (m/s²) as given
        (:func:`add_limit_arguments`).

    Returns
    -------
    Limits
        The followers' speed and acceleration limits.

    Raises
    ------
    StringStabError
        A limit that is not a finite number, acc_min ≥ 0, acc_max ≤ 0, v_max ≤ 0, or a limit
        beyond any road vehicle (v_max > 70 m/s, |acc| > 15 m/s²).
    """
    from ..traffic.limits import Limits

    def number(option: str, text: Any) -> float:
        try:
            x = float(str(text))
        except ValueError as e:
            raise StringStabError(f"{option} must be a number; got {show(text)}") from e
        if not np.isfinite(x):
            raise StringStabError(f"{option} must be a finite number; got {show(text)}")
        return x

    v_max = number("--v-max", args.v_max)
    a_min, a_max = number("--a-min", args.a_min), number("--a-max", args.a_max)
    if not v_max > 0:
        raise StringStabError(f"--v-max must be > 0 m/s; got {v_max:g}")
    if not a_min < 0 < a_max:
        raise StringStabError(f"expected --a-min < 0 < --a-max; got --a-min {a_min:g}, --a-max {a_max:g}")
    return Limits(accel_min=a_min, accel_max=a_max, speed_max=v_max)


def checked_leaders(args: Any, leaders: Any, limits: Any, *,
                    settling: float | None = None) -> list[str]:
    """:func:`stringstab.traffic.check_leader` on every leader, its warnings printed (stderr).

    Parameters
    ----------
    args : argparse.Namespace
        The command's arguments (``args.command`` names it in the warnings).
    leaders : sequence of Trajectory or FollowingPair
        The leaders the command will run (a recorded leader-follower pair: its leader).
    limits : Limits
        The followers' limits.
    settling : float, optional
        The controller's settling time, s (:func:`stringstab.traffic.limits.settling_time`):
        a shorter leader is refused, as is one shorter than 10 s.

    Returns
    -------
    list of str
        The warnings (also for the run's metrics), each once.

    Raises
    ------
    StringStabError
        A physically absurd leader (above 70 m/s or beyond ±15 m/s²), or one shorter than
        10 s or than ``settling``.
    """
    import sys

    from ..traffic.limits import check_leader

    leaders = [getattr(x, "leader", x) for x in leaders]  # a FollowingPair: its leader
    out: list[str] = []
    for leader in leaders:
        for w in check_leader(leader, limits, settling=settling):
            text = w if len(leaders) == 1 else f"{leader.name}: {w}"
            if text not in out:
                out.append(text)
    for w in out:
        print(f"{command_name(args)}: warning: {w}", file=sys.stderr)
    return out
