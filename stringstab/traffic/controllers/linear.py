"""The IDL linear law (eqs 3-4): :func:`linear_law` and :class:`LinearController`.

u = k_x Δp + k_v Δv + k_a a_{i−1}(t − δ) with Δp = gap − (T* v + l_0) (eq 3): the law every
gain triple is certified for, executed by the fixed-gain controller, the time-varying one
(:mod:`~stringstab.traffic.controllers.time_varying`) and the environments.

References
----------
.. [IDL] Z. Yi, M. Xu, S. Wang, Transportation Research Part C 184 (2026) 105541, eqs 3-4, 17.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ...params import DEFAULT_HEADWAY, as_gains, positive
from .base import DEFAULT_STANDSTILL, Controller, Observation, time_headway_gap

__all__ = ["LinearController", "linear_law"]

Array = npt.NDArray[np.float64]


def linear_law(gains: npt.ArrayLike, obs: Observation, *, headway: float,
               standstill: float = DEFAULT_STANDSTILL) -> Array:
    """The IDL linear law (eqs 3-4) for the gains in force, vectorised over a batch.

    u = k_x (gap − T* v − l_0) + k_v Δv + k_a a_{i−1}(t − δ), the spacing error Δp of eq 3
    inside the eq-4 law, with a gain triple per follower (or one broadcast to all).

    Parameters
    ----------
    gains : array_like, shape (..., 3)
        K = (k_x [1/s²], k_v [1/s], k_a [-]) per follower; the leading axes broadcast against
        ``obs.gap`` (e.g. ``(n, 1, 3)`` for ``n`` platoons of one follower).
    obs : Observation
        What every follower knows at this step.
    headway : float
        Desired time headway T* of eq 3, s.
    standstill : float
        Standstill spacing l_0 of eq 3, m.

    Returns
    -------
    ndarray
        u, m/s², shaped like ``obs.gap`` broadcast with ``gains[..., 0]``, before the
        platoon's limits and actuator lag.

    Examples
    --------
    >>> z = np.zeros(1)
    >>> obs = Observation(0, 0.0, 0.1, gap=np.array([27.0]), speed=np.array([20.0]),
    ...                   accel=z, pred_speed=np.array([21.0]), rel_speed=np.array([1.0]),
    ...                   pred_accel=z, pred_accel_delayed=np.array([0.5]))
    >>> linear_law([1.2, 0.5, 0.6], obs, headway=1.1, standstill=2.0).round(6).tolist()
    [4.4]
    """
    K = np.asarray(gains, dtype=np.float64)
    k_x, k_v, k_a = K[..., 0], K[..., 1], K[..., 2]
    return np.asarray(k_x * (obs.gap - headway * obs.speed - standstill)
                      + k_v * obs.rel_speed + k_a * obs.pred_accel_delayed)


class LinearController(Controller):
    """The IDL linear law with fixed gains (IDL paper eqs 3-4).

    u = k_x (gap − T* v − l_0) + k_v (v_{i−1} − v) + k_a a_{i−1}(t − δ)

    Parameters
    ----------
    k_x, k_v, k_a : float or array
        Gains; arrays broadcast against the batch (e.g. shape ``(n_followers,)`` for a gain
        per position).
    headway : float
        Desired time headway T*, s (eq 3).
    standstill : float
        Standstill spacing l_0, m (eq 3).

    Examples
    --------
    >>> c = LinearController(1.2, 0.5, 0.6)
    >>> float(c.equilibrium_gap(20.0))
    24.0
    """

    def __init__(self, k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike, *,
                 headway: float = DEFAULT_HEADWAY, standstill: float = DEFAULT_STANDSTILL) -> None:
        self.k_x, self.k_v, self.k_a = as_gains(k_x, k_v, k_a)
        self._headway = positive("headway (T*)", headway, allow_zero=True)
        self.standstill = positive("standstill spacing l0", standstill, allow_zero=True)
        self._kxT = self.k_x * self._headway
        self._kxl = self.k_x * self.standstill
        self._K = np.stack([self.k_x, self.k_v, self.k_a], axis=-1)

    @property
    def headway(self) -> float:
        """T* of the eq-3 spacing policy, s (the ``headway`` given at construction)."""
        return self._headway

    def command(self, obs: Observation) -> Array:
        """The eq-4 law u = k_x (gap − T* v − l_0) + k_v Δv + k_a a_{i−1}(t − δ) (IDL eqs 3-4).

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step.

        Returns
        -------
        array
            u, m/s², shaped like ``obs.gap`` (broadcast with the gains).
        """
        u = self.k_x * obs.gap
        u -= self._kxT * obs.speed
        u -= self._kxl
        u += self.k_v * obs.rel_speed
        u += self.k_a * obs.pred_accel_delayed
        return u

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """l_0 + T* v, the eq-3 spacing at which u = 0 behind an equal-speed leader.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s.

        Returns
        -------
        array
            The equilibrium gap, m.
        """
        return time_headway_gap(speed, headway=self._headway, standstill=self.standstill)

    def gains(self, obs: Observation) -> Array:
        """The fixed gains.

        Parameters
        ----------
        obs : Observation
            Ignored.

        Returns
        -------
        array (..., 3)
            K = (k_x, k_v, k_a) as given at construction.
        """
        return self._K

    def describe(self) -> dict[str, Any]:
        """A JSON-ready description of the law and its fixed gains.

        Returns
        -------
        dict
            ``controller`` (``"linear"``), the gains ``k_x``, ``k_v``, ``k_a`` (as lists),
            ``headway`` T* (s) and ``standstill`` l_0 (m).
        """
        return {"controller": "linear", "k_x": self.k_x.tolist(), "k_v": self.k_v.tolist(),
                "k_a": self.k_a.tolist(), "headway": self._headway, "standstill": self.standstill}
