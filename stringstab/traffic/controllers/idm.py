"""The Intelligent Driver Model (Treiber, Hennecke & Helbing 2000): :class:`IDMController`.

A stand-in for human-driven followers (no communicated acceleration).

References
----------
.. [IDM] M. Treiber, A. Hennecke, D. Helbing, "Congested traffic states in empirical
   observations and microscopic simulations", Phys. Rev. E 62 (2000) 1805-1824.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

from ...constants import SPEED_MAX, STANDSTILL
from ...params import positive
from .base import Controller, Observation

__all__ = ["IDMController"]

Array = npt.NDArray[np.float64]


class IDMController(Controller):
    """The Intelligent Driver Model (Treiber et al. 2000), a human-driver stand-in.

    u = a [1 − (v/v_0)^4 − (s*/s)²],  s* = s_0 + max(0, v T + v (v − v_{i−1}) / (2√(a b))).

    Human drivers receive no communicated acceleration.  The defaults are the highway values
    of Treiber et al. (2000), Table 1: v_0 = 120 km/h (here the IDL v_max 33.3 m/s), T = 1.6 s,
    s_0 = 2 m, a = 0.73 m/s², b = 1.67 m/s².  The gap in the formula is floored at 1 cm so u
    stays finite during a collision (which the simulator still reports).

    Examples
    --------
    >>> round(float(IDMController().equilibrium_gap(20.0)), 2)
    36.45
    """

    def __init__(self, *, desired_speed: float = SPEED_MAX, time_headway: float = 1.6,
                 min_gap: float = STANDSTILL, max_accel: float = 0.73, comfortable_decel: float = 1.67,
                 exponent: float = 4.0) -> None:
        self.v0 = positive("desired_speed", desired_speed)
        self.T = positive("time_headway", time_headway, allow_zero=True)
        self.s0 = positive("min_gap", min_gap, allow_zero=True)
        self.a = positive("max_accel", max_accel)
        self.b = positive("comfortable_decel", comfortable_decel)
        self.exponent = positive("exponent", exponent)
        self._ab2 = 2.0 * math.sqrt(self.a * self.b)

    def command(self, obs: Observation) -> Array:
        """The IDM acceleration u = a [1 − (v/v_0)^exponent − (s*/s)²] (Treiber et al. 2000).

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step (the delayed predecessor acceleration is not
            used).

        Returns
        -------
        array
            u, m/s² (the gap s floored at 1 cm).
        """
        v = obs.speed
        s_star = self.s0 + np.maximum(0.0, v * self.T - v * obs.rel_speed / self._ab2)
        s = np.maximum(obs.gap, 0.01)
        return self.a * (1.0 - (v / self.v0) ** self.exponent - (s_star / s) ** 2)

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """s_e = (s_0 + v T) / sqrt(1 − (v/v_0)^exponent), where u = 0 behind an equal-speed leader.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s (capped at 0.999 v_0, where the gap is still finite).

        Returns
        -------
        array
            The equilibrium gap, m.
        """
        v = np.minimum(np.asarray(speed, dtype=np.float64), 0.999 * self.v0)
        return (self.s0 + v * self.T) / np.sqrt(1.0 - (v / self.v0) ** self.exponent)

    def describe(self) -> dict[str, Any]:
        """A JSON-ready description of the IDM and its parameters.

        Returns
        -------
        dict
            ``controller`` (``"idm (Treiber et al. 2000)"``), ``desired_speed`` v_0 (m/s),
            ``time_headway`` T (s), ``min_gap`` s_0 (m), ``max_accel`` a and
            ``comfortable_decel`` b (m/s²) and ``exponent``.
        """
        return {"controller": "idm (Treiber et al. 2000)", "desired_speed": self.v0,
                "time_headway": self.T, "min_gap": self.s0, "max_accel": self.a,
                "comfortable_decel": self.b, "exponent": self.exponent}
