"""The sub-commands' vehicle limits (``--v-max --a-min --a-max``) and the check of their leaders."""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from ..errors import StringStabError, show
from ._outcome import command_name

__all__ = [
    "add_limit_arguments",
    "checked_leaders",
    "limits_from_args",
]


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
