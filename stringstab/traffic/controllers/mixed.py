"""Different controllers at different platoon positions: :class:`MixedController`.

E.g. IDM humans among CAVs; every candidate runs on the whole batch and the results are
selected per follower position.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ...errors import StringStabError
from .base import Controller, Observation

__all__ = ["MixedController"]

Array = npt.NDArray[np.float64]


class MixedController(Controller):
    """Different controllers at different platoon positions (e.g. IDM humans among CAVs).

    Every candidate is evaluated on the whole batch and the results are selected per position,
    so the cost is the sum of the candidates'.  :meth:`gains` returns K only if every candidate
    is of the eq-4 form with one headway.

    Parameters
    ----------
    controllers : sequence of Controller
        The candidates.
    assignment : sequence of int
        For each follower position (1..N), the index of its controller.
    """

    def __init__(self, controllers: Sequence[Controller], assignment: Sequence[int]) -> None:
        self.controllers = list(controllers)
        self.assignment = np.asarray(assignment, dtype=np.int64)
        if self.assignment.ndim != 1 or not self.controllers:
            raise StringStabError("MixedController needs controllers and a 1-D assignment per position")
        if (self.assignment < 0).any() or (self.assignment >= len(self.controllers)).any():
            raise StringStabError(
                f"assignment indices must be in [0, {len(self.controllers) - 1}]; got {self.assignment.tolist()}"
            )
        self.time_varying = any(c.time_varying for c in self.controllers)

    def command(self, obs: Observation) -> Array:
        """Each follower position's own controller's command.

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step (last axis: the N follower positions).

        Returns
        -------
        array
            u, m/s², shaped like ``obs.gap``.
        """
        return np.asarray(np.choose(self.assignment, [c.command(obs) for c in self.controllers]))

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """Each follower position's own controller's equilibrium gap.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s (broadcast against the N positions).

        Returns
        -------
        array (..., N)
            The equilibrium gaps, m.
        """
        v = np.asarray(speed, dtype=np.float64)
        shape = np.broadcast_shapes(v.shape, (self.assignment.size,))
        gaps = [np.broadcast_to(c.equilibrium_gap(v), shape) for c in self.controllers]
        return np.asarray(np.choose(self.assignment, gaps))

    @property
    def headway(self) -> float | None:
        """The candidates' common T*, s, or None if they differ or one of them has none."""
        hs = {c.headway for c in self.controllers}
        return hs.pop() if len(hs) == 1 else None

    def gains(self, obs: Observation) -> Array | None:
        """Each position's eq-4 gains, if every candidate is of the eq-4 form with one headway.

        Parameters
        ----------
        obs : Observation
            The current step.

        Returns
        -------
        array (..., N, 3) or None
            The gains per follower, or None if a candidate has none or the headways differ.
        """
        gs = [c.gains(obs) for c in self.controllers]
        if any(g is None for g in gs) or self.headway is None:
            return None
        shape = (*obs.gap.shape, 3)
        stacked = [np.broadcast_to(g, shape) for g in gs if g is not None]
        return np.asarray(np.choose(self.assignment[:, None], stacked))
