"""The controller interface: :class:`Observation`, what a follower knows, and :class:`Controller`.

Every controller maps an :class:`Observation` of a batch of followers (arrays of any common
shape, typically ``(n_platoons, n_followers)``) to desired accelerations u (m/s²); the
simulator (:mod:`stringstab.traffic.platoon`) then limits u to the acceleration bounds and
passes it through the vehicle's actuator lag.  Also the standstill spacing l_0 every spacing
policy starts from (:data:`DEFAULT_STANDSTILL`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ...constants import STANDSTILL
from ...params import DEFAULT_HEADWAY

__all__ = ["DEFAULT_STANDSTILL", "Controller", "Observation", "time_headway_gap"]

Array = npt.NDArray[np.float64]


#: Standstill spacing l_0, m (IDL paper Table 2).
DEFAULT_STANDSTILL = STANDSTILL


def time_headway_gap(speed: npt.ArrayLike, *, headway: float, standstill: float) -> Array:
    """The constant time-headway spacing policy l_0 + T* v (IDL eq 3), m.

    The gap at which the eq-4 law commands u = 0 behind an equal-speed leader: the
    equilibrium gap of every controller with this spacing policy
    (:meth:`Controller.equilibrium_gap`).

    Parameters
    ----------
    speed : array_like
        Cruise speed v, m/s.
    headway : float
        Desired time headway T*, s.
    standstill : float
        Standstill spacing l_0, m.

    Returns
    -------
    array
        l_0 + T* v, m, shaped like ``speed``.

    Examples
    --------
    >>> time_headway_gap([0.0, 20.0], headway=1.1, standstill=2.0).tolist()
    [2.0, 24.0]
    """
    return standstill + headway * np.asarray(speed, dtype=np.float64)


@dataclass(frozen=True, slots=True)
class Observation:
    """What every follower of a batch knows at one step (arrays of one shape).

    Attributes
    ----------
    step : int
        Step index k (t = k·dt).
    t, dt : float
        Time and step, s.
    gap : array
        Bumper-to-bumper distance to the predecessor Δx, m (≤ 0 is a collision).
    speed, accel : array
        The follower's own speed (m/s) and acceleration (m/s²).
    pred_speed : array
        The predecessor's speed, m/s.
    rel_speed : array
        Δv = pred_speed − speed, m/s.
    pred_accel : array
        The predecessor's current acceleration (what a sensor would see), m/s².
    pred_accel_delayed : array
        a_{i−1}(t − δ), the predecessor's acceleration received over the delayed link, m/s².
    """

    step: int
    t: float
    dt: float
    gap: Array
    speed: Array
    accel: Array
    pred_speed: Array
    rel_speed: Array
    pred_accel: Array
    pred_accel_delayed: Array


class Controller:
    """Interface of a car-following controller (subclass and override :meth:`command`)."""

    #: True if :meth:`gains` returns a different K at different steps.
    time_varying: bool = False

    def command(self, obs: Observation) -> Array:
        """Desired accelerations u (m/s²), shaped like ``obs.gap``.

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step.

        Returns
        -------
        array
            u per follower, m/s², before the platoon's limits and actuator lag.
        """
        raise NotImplementedError

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """The gap (m) where u = 0 for a follower at ``speed`` behind an equal-speed leader.

        It is used to start a platoon in equilibrium.  The base class returns the IDL spacing
        policy l_0 + T* v (eq 3) with the defaults.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s.

        Returns
        -------
        array
            The equilibrium gap, m, shaped like ``speed``.
        """
        return time_headway_gap(speed, headway=DEFAULT_HEADWAY, standstill=DEFAULT_STANDSTILL)

    def gains(self, obs: Observation) -> Array | None:
        """The eq-4 gain vector K = (k_x, k_v, k_a) in force, shape ``(..., 3)``, or None.

        None means the controller is not of the eq-4 form (then M_fss, eq 27, is undefined).

        Parameters
        ----------
        obs : Observation
            The current step (time-varying controllers read ``obs.step`` or the state).

        Returns
        -------
        array (..., 3) or None
            None in the base class.
        """
        return None

    @property
    def headway(self) -> float | None:
        """T* of the equivalent eq-4 law (for the certificate), or None."""
        return None

    def describe(self) -> dict[str, Any]:
        """A JSON-ready description."""
        return {"controller": type(self).__name__}
