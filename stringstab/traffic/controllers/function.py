"""A controller from any callable: :class:`FunctionController`.

E.g. a pure-RL acceleration policy; the spacing policy l_0 + T* v given to it only places a
platoon at the start.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from ...params import DEFAULT_HEADWAY
from .base import DEFAULT_STANDSTILL, Controller, Observation, time_headway_gap

__all__ = ["FunctionController"]

Array = npt.NDArray[np.float64]


class FunctionController(Controller):
    """A controller from a callable ``fn(obs) -> u`` (e.g. a pure-RL acceleration policy).

    Parameters
    ----------
    fn : callable
        Returns desired accelerations shaped like ``obs.gap``.
    headway, standstill : float
        The equilibrium spacing policy used to start a platoon (l_0 + T* v).
    """

    def __init__(self, fn: Callable[[Observation], npt.ArrayLike], *,
                 headway: float = DEFAULT_HEADWAY, standstill: float = DEFAULT_STANDSTILL) -> None:
        self.fn = fn
        self._headway, self.standstill = float(headway), float(standstill)

    def command(self, obs: Observation) -> Array:
        """``fn(obs)``, broadcast to the shape of ``obs.gap``.

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step.

        Returns
        -------
        array
            u, m/s² (a copy).
        """
        return np.broadcast_to(np.asarray(self.fn(obs), dtype=np.float64), obs.gap.shape).copy()

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """l_0 + T* v with the ``headway`` and ``standstill`` given.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s.

        Returns
        -------
        array
            The gap a platoon starts with, m.
        """
        return time_headway_gap(speed, headway=self._headway, standstill=self.standstill)
