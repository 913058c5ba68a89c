"""The V2V message schedule of the multi-rate loop: its period in steps and its phase, checked.

A message period P (seconds) is a whole number N ≥ 1 of control steps H: P = N·H.  Floating
point makes 0.1/0.01 = 9.999999999999998, so the rule (the one of
:func:`stringstab.certify.zoh.split_delay` for delays) is: N = round(P/H) ≥ 1 and
|P − N·H| ≤ 10⁻⁹·H; anything else (0.015 at H = 0.01, 0.005 at H = 0.01, a negative, NaN or
infinite P) is refused with one line saying what was expected and what was found.  The phase
φ ∈ {0, …, N − 1} is the step, modulo N, at which messages are used (it does not change the
certificate: docs/sampled.md, §9.2).

This module imports nothing heavy: :meth:`stringstab.certify.api.Loop.of` calls it
(:func:`message_schedule`, :func:`check_message_loop`) when a message period is given.
"""

from __future__ import annotations

import math
from typing import Any

from ..errors import StringStabError, show

__all__ = [
    "MESSAGE_RTOL",
    "check_message_loop",
    "message_phase",
    "message_schedule",
    "message_steps",
]

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


def message_schedule(sample_time: float | None, message_period: Any, phase: Any,
                     fallback_gains: Any) -> tuple[int | None, int, tuple[float, float] | None]:
    """The message schedule and fallback gains a caller gives, checked.

    Parameters
    ----------
    sample_time : float or None
        H (checked), s.
    message_period : float or None
        P = N·H, s.
    phase : int or None
        φ, the message phase (default 0).
    fallback_gains : (float, float) or None
        The fallback (ACC) gains (k_x, k_v).

    Returns
    -------
    (int or None, int, (float, float) or None)
        N, φ and the fallback gains.

    Raises
    ------
    StringStabError
        A phase or fallback gains without a message period, a message period without a
        sample time, or any value out of its range.

    Examples
    --------
    >>> message_schedule(0.01, 0.1, 3, (1.0, 0.5))
    (10, 3, (1.0, 0.5))
    """
    if message_period is None:
        what = "message_phase is" if phase is not None else "fallback gains are"
        raise StringStabError(f"{what} for the multi-rate loop; expected message_period "
                              "with it, got none")
    if sample_time is None:
        raise StringStabError("message_period (the V2V message period) needs the control "
                              "period: expected sample_time with it, got none")
    N = message_steps(message_period, sample_time)
    phi = 0 if phase is None else message_phase(phase, N)
    fb = None
    if fallback_gains is not None:
        from ..params import as_gains

        try:
            fx, fv = (float(v) for v in fallback_gains)
        except (TypeError, ValueError) as e:
            raise StringStabError("fallback gains must be two numbers (k_x, k_v); got "
                                  f"{show(fallback_gains)}") from e
        gx, gv, _ = as_gains(fx, fv, 0.0)
        fb = (float(gx), float(gv))
    return N, phi, fb


def check_message_loop(N: int | None, sample_time: float | None, box: bool,
                       tau_prev: float | None, fallback: tuple[float, float] | None) -> None:
    """Refuse the combinations of a message schedule that no certificate answers.

    Parameters
    ----------
    N : int or None
        Steps per message period.
    sample_time : float or None
        H, s.
    box : bool
        The parameters are a box of intervals.
    tau_prev : float or None
        The predecessor's lag, s.
    fallback : (float, float) or None
        The fallback gains.

    Raises
    ------
    StringStabError
        Fallback gains without a multi-rate loop (N ≥ 2); a message period without a sample
        time; a multi-rate loop over a box of parameters or with a predecessor's lag of its
        own (the certificate is for one τ, δ, T* in a homogeneous platoon).
    """
    if N is None or N < 2:
        if fallback is not None:
            raise StringStabError("fallback gains are for the multi-rate loop; expected a message "
                                  "period of at least two sample times with them")
        if N is not None and sample_time is None:
            raise StringStabError("message_period needs sample_time; got none")
        return
    if sample_time is None:
        raise StringStabError("message_period (the V2V message period) needs the control "
                              "period: expected sample_time with it, got none")
    if box:
        raise StringStabError("the multi-rate certificate is for one τ, δ, T*; got a parameter "
                              "box with message_period (not supported)")
    if tau_prev is not None:
        raise StringStabError("the multi-rate certificate is for a homogeneous platoon; got "
                              f"tau_prev={tau_prev!r} with message_period")
