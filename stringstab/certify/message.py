"""The V2V message schedule of the multi-rate loop: its period in steps and its phase, checked.

A message period P (seconds) is a whole number N ≥ 1 of control steps H: P = N·H.  Floating
point makes 0.1/0.01 = 9.999999999999998, so the rule (the one of
:func:`stringstab.certify.zoh.split_delay` for delays) is: N = round(P/H) ≥ 1 and
|P − N·H| ≤ 10⁻⁹·H; anything else (0.015 at H = 0.01, 0.005 at H = 0.01, a negative, NaN or
infinite P) is refused with one line saying what was expected and what was found.  The phase
φ ∈ {0, …, N − 1} is the step, modulo N, at which messages are used (it does not change the
certificate: docs/sampled.md, §9.2).

This module imports nothing heavy: :meth:`stringstab.certify.api.Loop.of` calls it on every
path.
"""

from __future__ import annotations

import math
from typing import Any

from ..errors import StringStabError, show

__all__ = ["MESSAGE_RTOL", "message_phase", "message_steps"]

#: A message period this close to a whole number of samples (relative to H) is that number.
MESSAGE_RTOL = 1e-9


def message_steps(message_period: Any, sample_time: float, *,
                  name: str = "message_period") -> int:
    """N = P/H, the message period in control steps, checked.

    Parameters
    ----------
    message_period : float
        P, s: finite, > 0, a whole multiple of ``sample_time`` (within 10⁻⁹ H).
    sample_time : float
        H > 0, s (already checked).
    name : str
        How the caller names P in the message (``--message-period`` on the command line).

    Returns
    -------
    int
        N ≥ 1.

    Raises
    ------
    StringStabError
        Saying what was expected and what was found.

    Examples
    --------
    >>> message_steps(0.1, 0.01), message_steps("0.3", 0.1)
    (10, 3)
    >>> message_steps(0.015, 0.01)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: message_period must be a whole multiple N >= 1 of the sample time 0.01 s (within 1e-09 of a step); got 0.015 s = 1.5 steps
    """
    try:
        P = float(message_period)
    except (TypeError, ValueError) as e:
        raise StringStabError(
            f"{name} must be a number of seconds > 0; got {show(message_period)}") from e
    if not math.isfinite(P) or P <= 0:
        raise StringStabError(f"{name} must be a finite number of seconds > 0; got {show(message_period)}")
    q = P / sample_time
    N = round(q)
    if N < 1 or abs(P - N * sample_time) > MESSAGE_RTOL * sample_time:
        raise StringStabError(
            f"{name} must be a whole multiple N >= 1 of the sample time {sample_time:g} s "
            f"(within {MESSAGE_RTOL:g} of a step); got {P:g} s = {q:.6g} steps")
    return int(N)


def message_phase(phase: Any, N: int, *, name: str = "message_phase") -> int:
    """φ ∈ {0, …, N − 1}, the step (mod N) at which messages are used, checked.

    Parameters
    ----------
    phase : int
        The phase, a whole number.
    N : int
        Steps per message period.
    name : str
        How the caller names it in the message.

    Returns
    -------
    int
        φ.

    Raises
    ------
    StringStabError
        When it is not a whole number in [0, N − 1].

    Examples
    --------
    >>> message_phase(3, 10)
    3
    """
    try:
        f = float(phase)
        ok = math.isfinite(f) and f == int(f)
    except (TypeError, ValueError):
        ok = False
    if not ok or not 0 <= int(f) < N:
        raise StringStabError(
            f"{name} must be a whole number of steps in 0..{N - 1} (N = {N} steps per message); "
            f"got {show(phase)}")
    return int(f)
