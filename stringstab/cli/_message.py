"""The V2V message schedule on the command line: ``--message-period`` and ``--message-phase``.

Shared by ``certify`` and ``region`` (the multi-rate loop, issue 26; docs/sampled.md §9).
"""

from __future__ import annotations

import argparse

from ..errors import StringStabError

__all__ = ["add_message_arguments", "message_from_args"]


def add_message_arguments(p: argparse.ArgumentParser) -> None:
    """``--message-period P`` and ``--message-phase PHI`` (the multi-rate loop).

    Parameters
    ----------
    p : argparse.ArgumentParser
        The command's parser (:func:`message_from_args` checks the values).
    """
    p.add_argument("--message-period", metavar="P",
                   help="the predecessor's acceleration arrives by V2V message every P s (a whole "
                        "multiple of --sample-time, which it needs) and is held: the multi-rate "
                        "loop; P = the sample time is the sampled loop")
    p.add_argument("--message-phase", metavar="PHI",
                   help="the control step (0..N-1, N = P/H) at which messages are used (default 0; "
                        "every phase has the same certificate)")


def message_from_args(args: argparse.Namespace, H: float | None) -> tuple[int | None, int]:
    """N = P/H and the phase of ``--message-period`` / ``--message-phase``, checked.

    Parameters
    ----------
    args : argparse.Namespace
        With ``message_period`` and ``message_phase`` (strings or None).
    H : float or None
        The checked ``--sample-time``.

    Returns
    -------
    (int or None, int)
        N (None without ``--message-period``) and φ.

    Raises
    ------
    StringStabError
        ``--message-period`` without ``--sample-time``, not a whole multiple of it, ≤ 0, not
        a number, or more than the largest N of :data:`stringstab.ranges.COUNTS`
        (``message_steps``: the lifted link's memory grows with N); ``--message-phase`` without
        ``--message-period`` or outside 0..N − 1.
    """
    from ..certify.message import message_phase, message_steps

    P, phase = getattr(args, "message_period", None), getattr(args, "message_phase", None)
    if P is None:
        if phase is not None:
            raise StringStabError(f"--message-phase is for the multi-rate loop; expected "
                                  f"--message-period with it, got --message-phase {phase}")
        return None, 0
    if H is None:
        raise StringStabError(f"--message-period needs the control period: expected --sample-time H "
                              f"with it, got --message-period {P} alone")
    N = message_steps(P, H, name="--message-period")
    from ..ranges import check_count
    from ._common import warn_beyond_sensible

    check_count("message_steps", N, name=f"--message-period {P} / --sample-time {H:g}")
    warn_beyond_sensible(args, [("message_steps", N, f"--message-period {P} / --sample-time {H:g}")])
    return N, (0 if phase is None else message_phase(phase, N, name="--message-phase"))
