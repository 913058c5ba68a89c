"""Vehicle bounds and the one leader check: :class:`Limits`, :func:`check_leader`, the length.

The acceleration and speed bounds of IDL Table 2 that the simulator, the environments and the
SUMO co-simulation apply; :func:`check_leader`, which every command that simulates or trains
runs on its leaders (refuse the absurd and the too short, warn the rest), with the
controller's :func:`settling_time`; and the vehicle length :data:`DEFAULT_LENGTH`.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ..constants import ACCEL_MAX, ACCEL_MIN, SPEED_MAX
from ..errors import StringStabError, show
from .trajectory import Trajectory

__all__ = ["DEFAULT_LENGTH", "SETTLING_FRACTION", "Limits", "check_leader", "settling_time"]

#: Vehicle length, m (front bumper to rear bumper); only offsets positions.
DEFAULT_LENGTH = 5.0
#: The settling criterion: the slowest mode has decayed to this fraction (2 %).
SETTLING_FRACTION = 0.02


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


def settling_time(controller: Any, tau: float | npt.ArrayLike) -> float | None:
    """The 2 % settling time of a follower under a controller of the eq-4 form, s (None: none).

    A follower's own loop (its predecessor held still) has the characteristic polynomial
    D(s) = τ s³ + s² + (k_v + k_x T*) s + k_x, the denominator of Γ(s) (IDL eq 11; the delay δ
    enters only the numerator).  Its slowest mode decays as e^{−σt}, σ the smallest −Re of
    the roots, so the response has settled to :data:`SETTLING_FRACTION` (2 %) after
    ln(50)/σ.  The largest over the followers' gains (and lags) is returned.

    Parameters
    ----------
    controller : Controller
        The followers' controller: fixed eq-4 gains (:class:`LinearController`, or
        :class:`CACCController` through its gap-control gains) give a settling time;
        time-varying gains, IDM or a policy give None.
    tau : float or array_like
        Actuator lag τ, s (per follower if an array); 0 for the kinematic model (eqs 1-2).

    Returns
    -------
    float or None
        ln(50)/σ in s; None when the controller has no fixed eq-4 gains or no follower's loop
        is internally stable (an unstable loop never settles).

    Examples
    --------
    >>> from stringstab.traffic.controllers import LinearController
    >>> round(settling_time(LinearController(1.2, 0.5, 0.6, headway=1.1), 0.1), 3)
    3.699
    >>> settling_time(LinearController(-1.0, 0.5, 0.6), 0.1) is None  # k_x < 0: not Hurwitz
    True
    """
    if getattr(controller, "time_varying", False):
        return None
    headway = getattr(controller, "headway", None)
    try:
        K = controller.gains(None)
    except (AttributeError, TypeError):
        return None
    if K is None or headway is None:
        return None
    K = np.asarray(K, dtype=np.float64).reshape(-1, 3)
    taus = np.broadcast_to(np.asarray(tau, dtype=np.float64).ravel(), (max(K.shape[0], 1),)) \
        if np.size(tau) in (1, K.shape[0]) else np.asarray(tau, dtype=np.float64).ravel()
    worst: float | None = None
    for (k_x, k_v, _k_a), t in itertools.product(K, np.unique(taus)):
        roots = np.roots([t, 1.0, k_v + k_x * headway, k_x])
        sigma = float(np.min(-roots.real)) if roots.size else 0.0
        if np.isfinite(sigma) and sigma > 0:
            ts = math.log(1.0 / SETTLING_FRACTION) / sigma
            worst = ts if worst is None else max(worst, ts)
    return worst


def check_leader(leader: Trajectory, limits: Limits | None = None, *,
                 settling: float | None = None) -> list[str]:
    """The one leader check of every command that simulates or trains: refuse the absurd, warn the rest.

    A leader faster than :data:`~stringstab.ranges.LEADER_SPEED_ABSURD` (70 m/s) or
    accelerating beyond ±:data:`~stringstab.ranges.LEADER_ACCEL_ABSURD` (15 m/s²) is no road
    vehicle and is refused; so is a leader shorter than
    :data:`~stringstab.ranges.MIN_LEADER_SECONDS` (10 s) or than the controller's settling time
    (:func:`settling_time`): its run would show the platoon's start-up, not its response (a
    2-sample leader gives m_p = n/a).  A leader beyond the followers' limits is run with a
    warning: above v_max they saturate there and the gap opens while the leader stays faster
    (spacing, TTC, m_p and M_lss describe the limit as well as the controller); beyond
    [acc_min, acc_max] their commands are limited, so they cannot match it there.

    Parameters
    ----------
    leader : Trajectory
        The leader's speed and acceleration samples.
    limits : Limits, optional
        The followers' limits (default: IDL Table 2).
    settling : float, optional
        The controller's settling time, s (:func:`settling_time`); the leader must last at
        least this long, and at least 10 s.

    Returns
    -------
    list of str
        Warnings, one sentence each (empty when the leader is within every limit).

    Raises
    ------
    StringStabError
        If the leader is physically absurd (speed > 70 m/s or |acceleration| > 15 m/s²) or
        shorter than 10 s or than ``settling``.

    Examples
    --------
    >>> from stringstab.traffic.trajectory import from_speed
    >>> print(*check_leader(from_speed([0, 1, 12], [20.0, 25.0, 25.0], dt=0.1)))
    the leader accelerates at up to 5 m/s², beyond the followers' limit acc_max = 3 m/s² (first at t = 0 s): they cannot match it there, so the metrics measure the limits as well as the controller
    >>> print(*check_leader(from_speed([0, 10, 20], [30.0, 34.7, 34.7], dt=0.1)))
    the leader reaches 34.7 m/s at t = 7.1 s, above the followers' speed limit v_max = 33.3 m/s (IDL Table 2; --v-max raises it): they saturate there and the gap opens, so the metrics measure the limit as well as the controller
    >>> check_leader(from_speed([0, 1], [20.0, 20.0], dt=0.1))  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: leader 'leader' lasts 1 s (11 samples at dt = 0.1 s); expected at least 10 s: ...
    """
    from ..ranges import LEADER_ACCEL_ABSURD, LEADER_SPEED_ABSURD, MIN_LEADER_SECONDS

    lim = limits or Limits()
    v, a = leader.speed, leader.accel
    if leader.duration < MIN_LEADER_SECONDS - 1e-9:
        raise StringStabError(
            f"leader {show(leader.name)} lasts {leader.duration:.4g} s ({leader.speed.size} "
            f"samples at dt = {leader.dt:g} s); expected at least {MIN_LEADER_SECONDS:g} s: a "
            "shorter run shows the platoon's start-up, not its response (m_p and M_lss are "
            "undefined or meaningless); use a longer leader")
    if settling is not None and leader.duration < settling - 1e-9:
        raise StringStabError(
            f"leader {show(leader.name)} lasts {leader.duration:.4g} s; expected at least the "
            f"controller's settling time {settling:.4g} s (its slowest mode decays to 2 % in "
            "that time): a shorter run measures the start-up, not the response; use a longer "
            "leader")
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
