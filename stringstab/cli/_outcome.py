"""How a command that wrote its outputs ends: the words naming it, and exit 1 on a collision."""

from __future__ import annotations

import sys
from typing import Any

import numpy as np

__all__ = ["collision_status", "command_name"]


def command_name(args: Any) -> str:
    """``stringstab COMMAND [SUBCOMMAND]`` as typed, for warnings (``stringstab sumo run``).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (``command``, and ``hcfs_command`` or ``sumo_command``).

    Returns
    -------
    str
        The words that name the command.
    """
    sub = getattr(args, "hcfs_command", None) or getattr(args, "sumo_command", None)
    return f"stringstab {getattr(args, 'command', '')}{' ' + sub if sub else ''}"


def collision_status(args: Any, collisions: int, first: str, m_fss: float | None) -> int:
    """Exit status of a run that wrote its outputs: 1 with one warning line if it had collisions.

    Parameters
    ----------
    args : argparse.Namespace
        The command's arguments (:func:`command_name` names it in the warning).
    collisions : int
        Collision events of the run (entries into gap <= 0).
    first : str
        Who collided first and when, e.g. ``"follower 3 first reached its predecessor at
        t = 12.3 s"``.
    m_fss : float or None
        The run's m_fss (eq 27, a fraction), shown beside it.

    Returns
    -------
    int
        0 without collision, 1 with (the warning printed on stderr).
    """
    if not collisions:
        return 0
    shown = "n/a" if m_fss is None or not np.isfinite(m_fss) else f"{m_fss:.3f}"
    print(f"{command_name(args)}: warning: {collisions} collision(s): {first} (m_fss = {shown}); "
          "exit status 1", file=sys.stderr)
    return 1
