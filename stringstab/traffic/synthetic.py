"""Synthetic leaders: a sinusoid, hard braking and acceleration, stop-and-go, the IDL §5.1 mix.

Braking and acceleration default to the IDL paper's limits acc_min = −7.6 m/s² and
acc_max = 3 m/s² (Table 2, :mod:`stringstab.constants`).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from ..constants import ACCEL_MAX, ACCEL_MIN, DT
from ..errors import StringStabError, show
from ..params import positive
from .trajectory import Trajectory, from_accel_segments, time_grid

__all__ = [
    "PAPER_MIX_SEGMENTS",
    "SYNTHETIC",
    "hard_acceleration",
    "hard_braking",
    "paper_mix",
    "sinusoid",
    "stop_and_go",
]


def sinusoid(
    *,
    omega: float,
    amplitude: float = 1.0,
    speed: float = 20.0,
    duration: float = 200.0,
    dt: float = DT,
) -> Trajectory:
    """Constant speed with a sinusoidal perturbation, in closed form.

    v(t) = v̄ − A cos(ωt), a(t) = A ω sin(ωt), x(t) = v̄ t − (A/ω) sin(ωt): the acceleration
    starts at 0 and its amplitude is A ω.

    Parameters
    ----------
    omega : float
        Angular frequency ω, rad/s (> 0).
    amplitude : float
        Speed amplitude A, m/s (≥ 0, ≤ v̄).
    speed : float
        Mean speed v̄, m/s.
    duration : float
        s.
    dt : float
        Step, s.

    Returns
    -------
    Trajectory
        The leader's speed profile.

    Examples
    --------
    >>> tr = sinusoid(omega=1.0, amplitude=2.0, speed=20.0, duration=100.0)
    >>> round(float(tr.accel.max()), 3)
    2.0
    """
    d = positive("dt", dt, unit=" s")
    if not (math.isfinite(omega) and omega > 0):
        raise StringStabError(f"omega must be a finite number > 0 rad/s; got {show(omega)}")
    if not (0 <= amplitude <= speed):
        raise StringStabError(
            f"amplitude must be between 0 and the mean speed {show(speed)} m/s; got {show(amplitude)}"
        )
    t = time_grid(0.0, float(duration), d)
    if t.shape[0] < 2:
        raise StringStabError(f"duration must be at least one step; got {show(duration)}")
    wt = omega * t
    tr = Trajectory(d, speed * t - amplitude / omega * np.sin(wt), speed - amplitude * np.cos(wt),
                    amplitude * omega * np.sin(wt), f"sinusoid(omega={omega:g})")
    tr.meta.update(omega=omega, amplitude=amplitude, speed=speed)
    return tr


def hard_braking(
    *,
    speed: float = 25.0,
    to_speed: float = 0.0,
    decel: float = ACCEL_MIN,
    cruise_before: float = 20.0,
    cruise_after: float = 30.0,
    dt: float = DT,
) -> Trajectory:
    """Cruise, brake at ``decel`` (default the IDL acc_min −7.6 m/s²) to ``to_speed``, cruise.

    Parameters
    ----------
    speed : float
        Initial cruise speed, m/s.
    to_speed : float
        Speed after braking, m/s (< ``speed``).
    decel : float
        Braking acceleration, m/s² (< 0).
    cruise_before, cruise_after : float
        Cruise durations before and after the braking, s.
    dt : float
        Sample step, s.

    Returns
    -------
    Trajectory
        The leader, integrated exactly from its piecewise-constant acceleration
        (:func:`~stringstab.traffic.trajectory.from_accel_segments`).

    Raises
    ------
    StringStabError
        If ``decel`` ≥ 0 or ``to_speed`` ≥ ``speed``.

    Examples
    --------
    >>> tr = hard_braking(speed=25.0, to_speed=0.0, dt=0.1)
    >>> float(tr.accel.min()), float(tr.speed[-1])
    (-7.6, 0.0)
    """
    if not (decel < 0 and to_speed < speed):
        raise StringStabError(
            f"hard_braking needs decel < 0 and to_speed < speed; got decel={show(decel)}, "
            f"speed={show(speed)}, to_speed={show(to_speed)}"
        )
    return from_accel_segments(
        [(0.0, cruise_before), (decel, (to_speed - speed) / decel), (0.0, cruise_after)],
        speed0=speed, dt=dt, name="hard-braking",
    )


def hard_acceleration(
    *,
    speed: float = 5.0,
    to_speed: float = 25.0,
    accel: float = ACCEL_MAX,
    cruise_before: float = 20.0,
    cruise_after: float = 30.0,
    dt: float = DT,
) -> Trajectory:
    """Cruise, accelerate at ``accel`` (default the IDL acc_max 3 m/s²) to ``to_speed``, cruise.

    Parameters
    ----------
    speed : float
        Initial cruise speed, m/s.
    to_speed : float
        Speed after the acceleration, m/s (> ``speed``).
    accel : float
        Acceleration, m/s² (> 0).
    cruise_before, cruise_after : float
        Cruise durations before and after the acceleration, s.
    dt : float
        Sample step, s.

    Returns
    -------
    Trajectory
        The leader (:func:`~stringstab.traffic.trajectory.from_accel_segments`).

    Raises
    ------
    StringStabError
        If ``accel`` ≤ 0 or ``to_speed`` ≤ ``speed``.

    Examples
    --------
    >>> float(hard_acceleration().accel.max())
    3.0
    """
    if not (accel > 0 and to_speed > speed):
        raise StringStabError(
            f"hard_acceleration needs accel > 0 and to_speed > speed; got accel={show(accel)}, "
            f"speed={show(speed)}, to_speed={show(to_speed)}"
        )
    return from_accel_segments(
        [(0.0, cruise_before), (accel, (to_speed - speed) / accel), (0.0, cruise_after)],
        speed0=speed, dt=dt, name="hard-acceleration",
    )


def stop_and_go(
    *,
    speed_high: float = 15.0,
    speed_low: float = 0.0,
    waves: int = 3,
    accel: float = 1.5,
    decel: float = -2.0,
    dwell_high: float = 20.0,
    dwell_low: float = 10.0,
    dt: float = DT,
) -> Trajectory:
    """Stop-and-go waves: ``waves`` trapezoidal dips from ``speed_high`` to ``speed_low`` and back.

    Each wave: brake at ``decel`` to ``speed_low``, dwell ``dwell_low``, accelerate at
    ``accel`` back to ``speed_high``, dwell ``dwell_high``; the trajectory starts with a
    ``dwell_high`` cruise.

    Parameters
    ----------
    speed_high, speed_low : float
        Cruise and trough speeds, m/s (speed_high > speed_low ≥ 0).
    waves : int
        Number of dips (≥ 1).
    accel : float
        Acceleration out of a dip, m/s² (> 0).
    decel : float
        Braking into a dip, m/s² (< 0).
    dwell_high, dwell_low : float
        Time spent at ``speed_high`` and at ``speed_low`` per wave, s.
    dt : float
        Sample step, s.

    Returns
    -------
    Trajectory
        The leader (:func:`~stringstab.traffic.trajectory.from_accel_segments`).

    Raises
    ------
    StringStabError
        If the speeds, accelerations or ``waves`` are out of range.

    Examples
    --------
    >>> tr = stop_and_go(waves=2)
    >>> float(tr.speed.min()), float(tr.speed.max())
    (0.0, 15.0)
    """
    if not (speed_high > speed_low >= 0 and accel > 0 and decel < 0 and waves >= 1):
        raise StringStabError(
            "stop_and_go needs speed_high > speed_low >= 0, accel > 0, decel < 0, waves >= 1; got "
            f"speed_high={show(speed_high)}, speed_low={show(speed_low)}, accel={show(accel)}, "
            f"decel={show(decel)}, waves={show(waves)}"
        )
    dv = speed_high - speed_low
    segs: list[tuple[float, float]] = [(0.0, dwell_high)]
    for _ in range(int(waves)):
        segs += [(decel, dv / -decel), (0.0, dwell_low), (accel, dv / accel), (0.0, dwell_high)]
    return from_accel_segments(segs, speed0=speed_high, dt=dt, name="stop-and-go")


#: (accel m/s², duration s) segments of :func:`paper_mix`, starting at 20 m/s.
PAPER_MIX_SEGMENTS: tuple[tuple[float, float], ...] = (
    (0.0, 10.0), (-3.0, 2.0), (0.0, 8.0), (ACCEL_MAX, 3.0), (0.0, 10.0),
    (ACCEL_MIN, 2.5), (0.0, 5.0), (ACCEL_MAX, 5.0), (0.0, 10.0), (-5.0, 2.0), (0.0, 5.0),
    (2.0, 5.0), (0.0, 10.0), (ACCEL_MIN, 2.5), (0.0, 5.0), (ACCEL_MAX, 6.0), (0.0, 34.0),
)


def paper_mix(*, dt: float = DT) -> Trajectory:
    """A reconstruction of the IDL paper's §5.1 leader: braking of varying severity and accelerations.

    The paper synthesises its Fig. 7 leader "from multiple representative driving profiles"
    with abrupt braking down to −7.6 m/s² and sudden accelerations up to 3 m/s², but does not
    publish it.  This one (125 s from 20 m/s, :data:`PAPER_MIX_SEGMENTS`) brakes at −3, −7.6,
    −5 and −7.6 m/s² (the last to a full stop) and accelerates at 3, 3, 2 and 3 m/s².

    Parameters
    ----------
    dt : float
        Sample step, s.

    Returns
    -------
    Trajectory
        The 125 s leader (a reconstruction, not the paper's data).

    Examples
    --------
    >>> tr = paper_mix()
    >>> tr.duration, float(tr.accel.min()), float(tr.accel.max()), float(tr.speed.min())
    (125.0, -7.6, 3.0, 0.0)
    """
    return from_accel_segments(list(PAPER_MIX_SEGMENTS), speed0=20.0, dt=dt, name="paper-mix")


#: Synthetic profiles by name (used by :func:`leader_by_name` and the CLI).
SYNTHETIC: dict[str, Callable[..., Trajectory]] = {
    "sinusoid": sinusoid,
    "braking": hard_braking,
    "acceleration": hard_acceleration,
    "stop-and-go": stop_and_go,
    "mix": paper_mix,
}
