"""The sub-commands' model arguments: the vehicle, τ, δ, T* (points or LO:HI), H, and their checks."""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import StringStabError
from ..io import (
    GainTable,
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

__all__ = [
    "add_model_arguments",
    "add_vehicle_arguments",
    "check_horizon",
    "integer",
    "loop_params",
    "shown_params",
    "warn_beyond_sensible",
]


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
