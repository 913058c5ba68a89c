"""Vehicle bounds and the one leader check: :class:`Limits`, :func:`check_leader`, the length.

The acceleration and speed bounds of IDL Table 2 that the simulator, the environments and the
SUMO co-simulation apply; :func:`check_leader`, which every command that simulates runs on its
leader (refuse the absurd, warn the rest); and the vehicle length :data:`DEFAULT_LENGTH`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..constants import ACCEL_MAX, ACCEL_MIN, SPEED_MAX
from ..errors import StringStabError, show
from .trajectory import Trajectory

__all__ = ["DEFAULT_LENGTH", "Limits", "check_leader"]

#: Vehicle length, m (front bumper to rear bumper); only offsets positions.
DEFAULT_LENGTH = 5.0


@dataclass(frozen=True)
class Limits:
    """Acceleration and speed bounds (IDL paper Table 2).

    Examples
    --------
    >>> Limits()
    Limits(accel_min=-7.6, accel_max=3.0, speed_min=0.0, speed_max=33.3)
    """

    accel_min: float = ACCEL_MIN
    accel_max: float = ACCEL_MAX
    speed_min: float = 0.0
    speed_max: float = SPEED_MAX

    def __post_init__(self) -> None:
        vals = (self.accel_min, self.accel_max, self.speed_min, self.speed_max)
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in vals):
            raise StringStabError(f"limits must be finite numbers; got {vals}")
        if not (self.accel_min < 0 < self.accel_max):
            raise StringStabError(
                f"acceleration limits must satisfy accel_min < 0 < accel_max; got "
                f"[{self.accel_min}, {self.accel_max}]"
            )
        if not (0 <= self.speed_min < self.speed_max):
            raise StringStabError(
                f"speed limits must satisfy 0 <= speed_min < speed_max; got [{self.speed_min}, {self.speed_max}]"
            )
        from ..ranges import LEADER_ACCEL_ABSURD, LEADER_SPEED_ABSURD

        if self.speed_max > LEADER_SPEED_ABSURD or max(-self.accel_min, self.accel_max) > LEADER_ACCEL_ABSURD:
            raise StringStabError(
                f"limits beyond any road vehicle: expected speed_max <= {LEADER_SPEED_ABSURD:g} m/s "
                f"and accelerations within ±{LEADER_ACCEL_ABSURD:g} m/s²; got speed_max "
                f"{self.speed_max:g}, [{self.accel_min:g}, {self.accel_max:g}]")


def check_leader(leader: Trajectory, limits: Limits | None = None) -> list[str]:
    """The one leader check of every command that simulates: refuse the absurd, warn the rest.

    A leader faster than :data:`~stringstab.ranges.LEADER_SPEED_ABSURD` (70 m/s) or
    accelerating beyond ±:data:`~stringstab.ranges.LEADER_ACCEL_ABSURD` (15 m/s²) is no road
    vehicle and is refused.  A leader beyond the followers' limits is run with a warning: above
    v_max they saturate there and the gap opens while the leader stays faster (spacing, TTC, m_p
    and M_lss describe the limit as well as the controller); beyond [acc_min, acc_max] their
    commands are limited, so they cannot match it there.

    Parameters
    ----------
    leader : Trajectory
        The leader's speed and acceleration samples.
    limits : Limits, optional
        The followers' limits (default: IDL Table 2).

    Returns
    -------
    list of str
        Warnings, one sentence each (empty when the leader is within every limit).

    Raises
    ------
    StringStabError
        If the leader is physically absurd (speed > 70 m/s or |acceleration| > 15 m/s²).

    Examples
    --------
    >>> from stringstab.traffic.trajectory import from_speed
    >>> print(*check_leader(from_speed([0, 1], [20.0, 25.0], dt=0.1)))
    the leader accelerates at up to 5 m/s², beyond the followers' limit acc_max = 3 m/s² (first at t = 0 s): they cannot match it there, so the metrics measure the limits as well as the controller
    >>> print(*check_leader(from_speed([0, 10, 20], [30.0, 34.7, 34.7], dt=0.1)))
    the leader reaches 34.7 m/s at t = 7.1 s, above the followers' speed limit v_max = 33.3 m/s (IDL Table 2; --v-max raises it): they saturate there and the gap opens, so the metrics measure the limit as well as the controller
    """
    from ..ranges import LEADER_ACCEL_ABSURD, LEADER_SPEED_ABSURD

    lim = limits or Limits()
    v, a = leader.speed, leader.accel
    k = int(np.argmax(v))
    if v[k] > LEADER_SPEED_ABSURD:
        raise StringStabError(
            f"leader {show(leader.name)} reaches {float(v[k]):.4g} m/s at t = {k * leader.dt:.4g} s: "
            f"no road vehicle; expected a leader within [0, {LEADER_SPEED_ABSURD:g}] m/s "
            f"(the followers' limit is v_max = {lim.speed_max:g} m/s)")
    ka = int(np.argmax(np.abs(a))) if a.size else 0
    if a.size and abs(float(a[ka])) > LEADER_ACCEL_ABSURD:
        raise StringStabError(
            f"leader {show(leader.name)} accelerates at {float(a[ka]):.4g} m/s² at t = "
            f"{ka * leader.dt:.4g} s: no road vehicle; expected accelerations within "
            f"±{LEADER_ACCEL_ABSURD:g} m/s²")
    warnings = []
    if v[k] > lim.speed_max + 1e-9:
        first = int(np.argmax(v > lim.speed_max + 1e-9)) * leader.dt
        table2 = " (IDL Table 2; --v-max raises it)" if lim.speed_max == SPEED_MAX else ""
        warnings.append(
            f"the leader reaches {float(v[k]):.4g} m/s at t = {first:.4g} s, above the followers' "
            f"speed limit v_max = {lim.speed_max:g} m/s{table2}: they saturate there and the gap "
            "opens, so the metrics measure the limit as well as the controller")
    for side, bound, beyond in (("max", lim.accel_max, a > lim.accel_max + 1e-9),
                                ("min", lim.accel_min, a < lim.accel_min - 1e-9)):
        if beyond.any():
            peak = float(a.max() if side == "max" else a.min())
            first = int(np.argmax(beyond)) * leader.dt
            word = "accelerates" if side == "max" else "brakes"
            warnings.append(
                f"the leader {word} at up to {abs(peak):.4g} m/s², beyond the followers' limit "
                f"acc_{side} = {bound:g} m/s² (first at t = {first:.4g} s): they cannot match "
                "it there, so the metrics measure the limits as well as the controller"
            )
    return warnings
