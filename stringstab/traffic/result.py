"""The result of a platoon run: :class:`PlatoonResult`, what :func:`~stringstab.traffic.platoon.simulate` returns.

Recorded trajectories or their summaries, the gains in force, collisions, and the IDL paper's
evaluation metrics of the run (:mod:`stringstab.traffic.metrics`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..constants import TTC_STAR
from ..errors import StringStabError
from .limits import DEFAULT_LENGTH
from .metrics import damping_ratios_from_energy, platoon_metrics, time_headway

__all__ = ["PlatoonResult"]

Array = npt.NDArray[np.float64]


@dataclass
class PlatoonResult:
    """A simulated run.  Vehicle axis: 0 is the leader, 1..N the followers.

    Shapes below are for a batch of platoons ``(P, ...)``; for a single leader trajectory the
    leading ``P`` axis is dropped.

    Attributes
    ----------
    dt : float
        Step, s.
    t : array (T,)
        Sample times, s.
    position, speed, accel : array (P, N + 1, T) or None
        Recorded states (None when ``record=False``).
    command : array (P, N, T) or None
        Limited desired accelerations u.
    gains : array (P, N, T, 3) or (P, N, 1, 3) or None
        The eq-4 gains in force (one column when constant); None if the controller is not of
        the eq-4 form, or is time-varying and the run was not recorded.
    collided : bool array (P, N)
        Followers that ever had gap ≤ 0.
    collision_events : int array (P, N)
        Entries into a collision.
    first_collision_time : array (P, N)
        Time of the first collision, s (NaN if none).
    min_gap : array (P, N)
        Smallest gap over the run, m.
    sum_sq_accel : array (P, N + 1)
        Σ_t a_i(t)² (for m_p, eq 29).
    params : dict
        τ, δ, T*, model, limits, length, controller (and θ_r, the radio and the sensors when
        given).
    length : float
        Vehicle length, m.
    radio : dict or None
        What the radio did (:mod:`stringstab.traffic.radio`), per follower (P, N):
        ``messages_received``, ``messages_lost`` and ``fallback_time`` (s); None without radio.
    """

    dt: float
    t: Array
    position: Array | None
    speed: Array | None
    accel: Array | None
    command: Array | None
    gains: Array | None
    collided: npt.NDArray[np.bool_]
    collision_events: npt.NDArray[np.int64]
    first_collision_time: Array
    min_gap: Array
    sum_sq_accel: Array
    params: dict[str, Any] = field(default_factory=dict)
    length: float = DEFAULT_LENGTH
    radio: dict[str, Array] | None = None

    @property
    def n_followers(self) -> int:
        """Platoon size N."""
        return int(self.collided.shape[-1])

    def _need(self, name: str) -> Array:
        a = getattr(self, name)
        if a is None:
            raise StringStabError(f"{name} was not recorded; run simulate(..., record=True)")
        return a

    @property
    def gap(self) -> Array:
        """Bumper-to-bumper gaps (P, N, T), m."""
        x = self._need("position")
        return x[..., :-1, :] - x[..., 1:, :] - self.length

    @property
    def headway(self) -> Array:
        """Time headway h (eq 22) of each follower (P, N, T), s; NaN at standstill."""
        return time_headway(self.gap, self._need("speed")[..., 1:, :])

    @property
    def damping_ratios(self) -> Array:
        """m_p of each follower relative to its predecessor (eq 29, intended form), (P, N)."""
        return damping_ratios_from_energy(self.sum_sq_accel)

    def metrics(self, *, ttc_star: float = TTC_STAR, certificate: bool = True) -> dict[str, Any]:
        """The IDL paper's evaluation metrics of this run (see :func:`stringstab.traffic.metrics.platoon_metrics`).

        Parameters
        ----------
        ttc_star : float
            TTC* of the time-integrated TTC (eqs 31-32), s.
        certificate : bool
            Also compute m_fss (eq 27) of the executed gains with the exact certificate.

        Returns
        -------
        dict
            ``m_p`` (eq 29), ``M_lss`` (eq 30), ``TIT``, ``M_CI`` (eq 34), ``M_effi`` (eq 35),
            ``collisions``, ``m_fss`` (eq 27 as a fraction; None without ``certificate``), ...
        """
        return platoon_metrics(self, ttc_star=ttc_star, certificate=certificate)
