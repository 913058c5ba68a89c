"""The loop as it runs, on the command line: ``--reaction-delay`` and the radio and sensor flags.

One definition for the commands that run the platoon (issues 25 and 26; ``simulate``,
``sumo run``, ``train``, ``evaluate`` and ``compare``):
the reaction delay θ_r of every follower, its V2V radio (:class:`stringstab.traffic.Radio`) and
its sensors (:class:`stringstab.traffic.SensorNoise`).  Without any of them a command runs what
it always ran, bit for bit.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

from ..errors import StringStabError, show

__all__ = ["RADIO_FLAGS", "add_loop_arguments", "loop_asked", "radio_from_args", "reaction_from_args"]

#: The radio and sensor options (dest names), for commands that refuse or report them.
RADIO_FLAGS = ("message_period", "message_phase", "loss", "burst", "stale_after", "fallback_gains",
               "noise_gap", "noise_gap_rate", "noise_speed", "noise_correlation", "noise_filter",
               "radio_seed")


def add_loop_arguments(p: argparse.ArgumentParser, *, reaction: bool = True,
                       loss: bool = True, message_period_note: str = "") -> None:
    """``--reaction-delay`` and the radio and sensor options (values checked later).

    Parameters
    ----------
    p : argparse.ArgumentParser
        The command's parser.
    reaction : bool
        Also add ``--reaction-delay`` (False where the command defines it already).
    loss : bool
        Also add ``--loss`` and ``--burst`` (False where the command defines them, e.g. as the
        lists ``stringstab radio`` sweeps; :func:`radio_from_args` checks each value).
    message_period_note : str
        Appended to ``--message-period``'s help (a command's own default, said in words).
    """
    if reaction:
        p.add_argument("--reaction-delay", metavar="SECONDS", default=None,
                       help="reaction (actuation) delay θ_r in s, >= 0: every follower applies its "
                            "command θ_r late, integrated exactly (default 0)")
    g = p.add_argument_group(
        "radio and sensors (default: the predecessor's acceleration every step, exact sensors)")
    g.add_argument("--message-period", metavar="SECONDS",
                   help="V2V messages every P s (a whole multiple of the step), the last one held"
                        + (f" {message_period_note}" if message_period_note else ""))
    g.add_argument("--message-phase", metavar="STEPS",
                   help="the step (0..P/dt - 1) at which messages are used (default 0)")
    if loss:
        g.add_argument("--loss", metavar="RATE", help="share of messages lost at random, in [0, 1]")
        g.add_argument("--burst", metavar="MESSAGES",
                       help="mean number of messages lost in a row (Gilbert-Elliott; default: "
                            "independent losses)")
    g.add_argument("--stale-after", metavar="SECONDS",
                   help="fall back to ACC (k_a = 0) when the last message is older than this, "
                        "until the next one (>= the message period)")
    g.add_argument("--fallback-gains", metavar="K_X,K_V",
                   help="the fallback's gains (k_a = 0; default: the follower's own k_x, k_v)")
    g.add_argument("--noise-gap", metavar="SIGMA", help="noise σ on the measured gap, m")
    g.add_argument("--noise-gap-rate", metavar="SIGMA", help="noise σ on the measured gap rate, m/s")
    g.add_argument("--noise-speed", metavar="SIGMA", help="noise σ on the measured own speed, m/s")
    g.add_argument("--noise-correlation", metavar="SECONDS",
                   help="correlation time of the noise (Gauss-Markov; default: white)")
    g.add_argument("--noise-filter", metavar="SECONDS",
                   help="time constant of a first-order filter on the measurements")
    g.add_argument("--radio-seed", metavar="N", help="seed of the message loss and the noise (default 0)")


def loop_asked(args: Any) -> bool:
    """Whether any option of :func:`add_loop_arguments` was given.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    bool
        True when ``--reaction-delay`` or a radio or sensor option is present.
    """
    return any(getattr(args, n, None) is not None for n in ("reaction_delay", *RADIO_FLAGS))


def reaction_from_args(args: Any) -> float:
    """θ_r of ``--reaction-delay`` (0 when absent), checked.

    Parameters
    ----------
    args : argparse.Namespace
        With ``reaction_delay`` (a string, a number or None).

    Returns
    -------
    float
        θ_r, s.

    Raises
    ------
    StringStabError
        Negative, NaN, not a number or above 100 s.
    """
    from ..params import check_reaction_delay

    theta = getattr(args, "reaction_delay", None)
    if theta is None:
        return 0.0
    return check_reaction_delay(theta, "--reaction-delay (reaction delay θ_r)")


#: What each numeric option must be: (test, the words of the message).
_DOMAINS = {
    "unit": (lambda x: 0.0 <= x <= 1.0, "a number in [0, 1]"),
    "nonneg": (lambda x: math.isfinite(x) and x >= 0.0, "a finite number >= 0"),
    "pos": (lambda x: math.isfinite(x) and x > 0.0, "a finite number of seconds > 0"),
    "ge1": (lambda x: math.isfinite(x) and x >= 1.0, "a finite number >= 1"),
}
_KIND = {"message_period": "pos", "loss": "unit", "burst": "ge1", "stale_after": "pos",
         "noise_gap": "nonneg", "noise_gap_rate": "nonneg", "noise_speed": "nonneg",
         "noise_correlation": "pos", "noise_filter": "pos"}
#: The magnitude of each (:data:`stringstab.ranges.RANGES`): warned beyond the sensible range,
#: refused beyond the valid one.
_RANGE = {"message_period": "duration", "burst": "burst", "stale_after": "duration",
          "noise_gap": "length", "noise_gap_rate": "speed_noise", "noise_speed": "speed_noise",
          "noise_correlation": "duration", "noise_filter": "duration"}


def _float(name: str, text: Any, notes: list[tuple[str, float | None, str]]) -> float:
    from ..ranges import check_magnitude

    ok, words = _DOMAINS[_KIND[name]]
    try:
        x = float(text)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"{_flag(name)} must be {words}; got {show(text)}") from e
    if not ok(x):
        raise StringStabError(f"{_flag(name)} must be {words}; got {show(text)}")
    if name in _RANGE:
        check_magnitude(_RANGE[name], x, name=_flag(name))
        notes.append((_RANGE[name], x, _flag(name)))
    return x


def _given(args: Any, *names: str) -> list[str]:
    return [n for n in names if getattr(args, n, None) is not None]


def _flag(name: str) -> str:
    return "--" + name.replace("_", "-")


def _fallback_gains(text: str) -> tuple[float, float]:
    parts = [t.strip() for t in str(text).split(",")]
    try:
        values = [float(t) for t in parts]
    except ValueError as e:
        raise StringStabError(f"--fallback-gains must be K_X,K_V (two numbers; k_a is 0); got {text!r}") from e
    if len(values) == 3 and values[2] == 0.0:
        values = values[:2]
    if len(values) != 2:
        raise StringStabError(f"--fallback-gains must be K_X,K_V (two numbers; the fallback has k_a = 0); "
                              f"got {text!r}")
    if not all(math.isfinite(v) for v in values):
        raise StringStabError(f"--fallback-gains must be two finite numbers K_X,K_V; got {text!r}")
    from ..ranges import check_magnitude

    for name, v in zip(("k_x", "k_v"), values):
        check_magnitude("gain", v, name=f"--fallback-gains {name}")
    return values[0], values[1]


def radio_from_args(args: Any, dt: float) -> tuple[Any, Any]:
    """The :class:`~stringstab.traffic.Radio` and :class:`~stringstab.traffic.SensorNoise` asked for.

    Parameters
    ----------
    args : argparse.Namespace
        With the options of :func:`add_loop_arguments` (strings or None).
    dt : float
        The control (simulation) step, s: the message period must be a whole multiple of it.

    Returns
    -------
    (Radio or None, SensorNoise or None)
        None for each that no option asks for.

    Raises
    ------
    StringStabError
        One line naming the option: not a number, out of range (a loss rate outside [0, 1],
        σ < 0, NaN), a message period that is not a whole multiple of the step, an option
        without the one it needs (``--message-phase`` without ``--message-period``,
        ``--burst`` without ``--loss``, ``--fallback-gains`` without ``--stale-after``,
        ``--noise-correlation`` without a σ, ``--radio-seed`` with nothing random).
    """
    from ..traffic import Radio, SensorNoise
    from ..traffic.radio import message_steps
    from ._common import integer, warn_beyond_sensible

    notes: list[tuple[str, float | None, str]] = []  # (kind, value, option) for the range notes
    radio_names = ("message_period", "message_phase", "loss", "burst", "stale_after", "fallback_gains")
    noise_names = ("noise_gap", "noise_gap_rate", "noise_speed", "noise_correlation", "noise_filter")
    needs = [("message_phase", "message_period"), ("burst", "loss"), ("fallback_gains", "stale_after")]
    for opt, need in needs:
        if _given(args, opt) and not _given(args, need):
            raise StringStabError(f"{_flag(opt)} needs {_flag(need)}; got {_flag(opt)} "
                                  f"{getattr(args, opt)} without it")
    sigmas = _given(args, "noise_gap", "noise_gap_rate", "noise_speed")
    if _given(args, "noise_correlation") and not sigmas:
        raise StringStabError("--noise-correlation colours the noise of --noise-gap, --noise-gap-rate or "
                              f"--noise-speed; expected one of them with it, got --noise-correlation "
                              f"{args.noise_correlation} alone")
    seed = 0
    if _given(args, "radio_seed"):
        if not (_given(args, "loss") or sigmas):
            raise StringStabError("--radio-seed seeds the message loss (--loss) and the sensor noise "
                                  f"(--noise-*); expected one of them with it, got --radio-seed {args.radio_seed}")
        seed = integer("--radio-seed", args.radio_seed, 0, "seed")
    radio = sensors = None
    if _given(args, *radio_names):
        kw: dict[str, Any] = {"seed": seed}
        if _given(args, "message_period"):
            P = _float("message_period", args.message_period, notes)
            try:
                n = message_steps(P, dt)
            except StringStabError as e:
                raise StringStabError(f"--message-period: {e}") from e
            kw["message_period"] = P
            if _given(args, "message_phase"):
                phase = integer("--message-phase", args.message_phase, 0)
                if phase >= n:
                    raise StringStabError(f"--message-phase must be a step in 0..{n - 1} (messages every "
                                          f"{n} steps); got {phase}")
                kw["message_phase"] = phase
        for name in ("loss", "burst", "stale_after"):
            if _given(args, name):
                kw[name] = _float(name, getattr(args, name), notes)
        period = kw.get("message_period")
        if "stale_after" in kw and period is not None and kw["stale_after"] < period * (1 - 1e-12):
            raise StringStabError(f"--stale-after {kw['stale_after']:g} s is shorter than the message period "
                                  f"{period:g} s: every follower would fall back between two messages; "
                                  f"expected --stale-after >= {period:g}")
        if _given(args, "fallback_gains"):
            kw["fallback_gains"] = _fallback_gains(args.fallback_gains)
        try:
            radio = Radio(**kw)
        except StringStabError as e:
            raise StringStabError(f"--loss/--burst/--stale-after: {e}") from e
    if _given(args, *noise_names):
        kn: dict[str, Any] = {"seed": seed}
        for name, field in (("noise_gap", "gap"), ("noise_gap_rate", "gap_rate"), ("noise_speed", "speed"),
                            ("noise_correlation", "correlation_time"), ("noise_filter", "filter_time")):
            if _given(args, name):
                kn[field] = _float(name, getattr(args, name), notes)
        try:
            sensors = SensorNoise(**kn)
        except StringStabError as e:
            raise StringStabError(f"--noise-*: {e}") from e
    warn_beyond_sensible(args, notes)
    return radio, sensors
