"""Sensor noise on what a follower measures: the gap, the gap rate and its own speed (issue 26).

:class:`SensorNoise` describes the sensors; :meth:`SensorNoise.start` gives the stepping state
(:class:`Sensors`) for a batch, whose :meth:`Sensors.measure` turns the true
:class:`~stringstab.traffic.controllers.Observation` into the measured one.  Per measured
quantity z (gap Δx in m, gap rate Δv = v_{i−1} − v_i in m/s, own speed v_i in m/s), at every
step k of Δt:

white noise (``correlation_time=None``)
    z̃_k = z_k + σ w_k, w_k independent standard normal;
coloured noise (``correlation_time=T_c``)
    a first-order Gauss–Markov process n_{k+1} = ρ n_k + σ √(1 − ρ²) w_k, ρ = e^{−Δt/T_c}, the
    exact sampling of the Ornstein–Uhlenbeck process with stationary standard deviation σ and
    autocorrelation e^{−|t|/T_c}, started in its stationary law (n_0 = σ w_0);
an optional first-order filter (``filter_time=T_f``)
    y_k = y_{k−1} + α (z̃_k − y_{k−1}), α = 1 − e^{−Δt/T_f}, y_0 = z̃_0 — the exact ZOH
    discretisation of T_f ẏ = z̃ − y; the controller sees y.

The predecessor's speed the controller sees is the measured own speed plus the measured gap
rate.  Collisions, minimum gaps and every recorded trajectory stay the true ones.  σ = 0 for a
quantity leaves it exact (no random number is drawn for it).  The noise is seeded: the same
seed and batch shape give the same run.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show
from .controllers.base import Observation

__all__ = ["SensorNoise", "Sensors"]

Array = npt.NDArray[np.float64]

#: The measured quantities, in the order of :attr:`SensorNoise.sigmas`: Observation fields.
MEASURED = ("gap", "rel_speed", "speed")
#: Stream of the seed that the sensors draw from (the radio's loss uses another).
SENSOR_STREAM = 0x5E50


def _nonneg(name: str, v: Any) -> float:
    try:
        x = float(v)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"{name} must be a finite number >= 0; got {show(v)}") from e
    if not (math.isfinite(x) and x >= 0):
        raise StringStabError(f"{name} must be a finite number >= 0; got {show(v)}")
    return x


def _time(name: str, v: Any) -> float | None:
    if v is None:
        return None
    x = _nonneg(name, v)
    if x == 0:
        raise StringStabError(f"{name} must be a finite number of seconds > 0 (or absent); got {show(v)}")
    return x


@dataclass(frozen=True)
class SensorNoise:
    """Noise (and an optional filter) on the gap, the gap rate and the own speed.

    Attributes
    ----------
    gap : float
        σ of the gap measurement, m (≥ 0).
    gap_rate : float
        σ of the gap-rate (Δv) measurement, m/s (≥ 0).
    speed : float
        σ of the own-speed measurement, m/s (≥ 0).
    correlation_time : float or None
        T_c of first-order Gauss–Markov (coloured) noise, s; None: white noise.
    filter_time : float or None
        T_f of a first-order low-pass filter on every measured quantity, s; None: no filter.
    seed : int
        Seed of the noise (≥ 0).

    Examples
    --------
    >>> SensorNoise(gap=0.1, correlation_time=1.0).describe()
    {'noise_gap': 0.1, 'noise_gap_rate': 0.0, 'noise_speed': 0.0, 'noise_correlation': 1.0, 'noise_filter': None, 'seed': 0}
    """

    gap: float = 0.0
    gap_rate: float = 0.0
    speed: float = 0.0
    correlation_time: float | None = None
    filter_time: float | None = None
    seed: int = 0

    def __post_init__(self) -> None:
        """Check every field (one line saying what was expected and what was found)."""
        for f, label in (("gap", "noise σ of the gap (m)"), ("gap_rate", "noise σ of the gap rate (m/s)"),
                         ("speed", "noise σ of the speed (m/s)")):
            object.__setattr__(self, f, _nonneg(label, getattr(self, f)))
        object.__setattr__(self, "correlation_time",
                           _time("noise correlation time (s)", self.correlation_time))
        object.__setattr__(self, "filter_time", _time("noise filter time constant (s)", self.filter_time))
        if not (isinstance(self.seed, (int, np.integer)) and self.seed >= 0):
            raise StringStabError(f"seed must be an integer >= 0; got {show(self.seed)}")

    @property
    def sigmas(self) -> tuple[float, float, float]:
        """σ of the gap, the gap rate and the speed (the order of ``MEASURED``)."""
        return (self.gap, self.gap_rate, self.speed)

    def describe(self) -> dict[str, Any]:
        """A JSON-ready description (the run's ``params["sensors"]``).

        Returns
        -------
        dict
            σ per quantity, the correlation and filter times (None when absent) and the seed.
        """
        return {"noise_gap": self.gap, "noise_gap_rate": self.gap_rate, "noise_speed": self.speed,
                "noise_correlation": self.correlation_time, "noise_filter": self.filter_time,
                "seed": int(self.seed)}

    def start(self, shape: tuple[int, ...], dt: float) -> Sensors:
        """The sensors of a batch of followers, ready to :meth:`Sensors.measure`.

        Parameters
        ----------
        shape : tuple of int
            ``(n_platoons, n_followers)``.
        dt : float
            The step Δt, s.

        Returns
        -------
        Sensors
            Their state (noise processes, filters and the generator).
        """
        return Sensors(self, shape, dt)


class Sensors:
    """The stepping state of :class:`SensorNoise` for a batch (see the module).

    Parameters
    ----------
    noise : SensorNoise
        The sensors.
    shape : tuple of int
        ``(n_platoons, n_followers)``.
    dt : float
        The step Δt, s.
    """

    def __init__(self, noise: SensorNoise, shape: tuple[int, ...], dt: float) -> None:
        self.noise, self.shape = noise, tuple(shape)
        self.rng = np.random.default_rng([int(noise.seed), SENSOR_STREAM])
        tc, tf = noise.correlation_time, noise.filter_time
        self.rho = None if tc is None else math.exp(-dt / tc)
        self.alpha = None if tf is None else -math.expm1(-dt / tf)
        self.noisy = [i for i, sg in enumerate(noise.sigmas) if sg > 0]  # quantities with noise
        self.sigma = np.array([noise.sigmas[i] for i in self.noisy]).reshape(-1, *([1] * len(shape)))
        self.state: Array | None = None  # the Gauss–Markov n of the noisy quantities
        self.filtered: Array | None = None  # y per quantity, (3, P, N)
        self._restart = False  # some rows of the filter start afresh (NaN) at the next step

    def _noise(self) -> Array:
        w = self.rng.standard_normal((len(self.noisy), *self.shape))
        if self.rho is None:
            return self.sigma * w
        if self.state is None:
            self.state = self.sigma * w
        else:
            self.state = self.rho * self.state + (self.sigma * math.sqrt(1.0 - self.rho**2)) * w
        return self.state

    def measure(self, obs: Observation) -> Observation:
        """The observation as the follower's sensors report it (this step's noise drawn).

        Parameters
        ----------
        obs : Observation
            The true observation of this step.

        Returns
        -------
        Observation
            Gap, gap rate and speed measured (noisy, filtered); the predecessor's speed is
            measured speed + measured gap rate; every other field as in ``obs``.
        """
        z = np.empty((3, *self.shape))
        for i, f in enumerate(MEASURED):
            z[i] = getattr(obs, f)
        if self.noisy:
            z[self.noisy] += self._noise()
        if self.alpha is not None:
            if self.filtered is None:
                self.filtered = z
            else:
                y = self.filtered + self.alpha * (z - self.filtered)
                self.filtered = np.where(np.isnan(y), z, y) if self._restart else y
                self._restart = False
            z = self.filtered
        gap, rel, spd = z[0], z[1], z[2]
        return dataclasses.replace(obs, gap=gap, rel_speed=rel, speed=spd, pred_speed=spd + rel)

    def reset(self, rows: Any = None) -> None:
        """Restart the noise processes and filters of ``rows`` (default all).

        Parameters
        ----------
        rows : index array, optional
            Platoons (first axis) whose sensors start afresh at the next measurement.
        """
        if rows is None:
            self.state = None
            self.filtered = None
            return
        r = np.asarray(rows)
        if self.state is not None:  # restarted in the stationary law
            self.state[:, r] = self.sigma * self.rng.standard_normal(self.state[:, r].shape)
        if self.filtered is not None:
            self.filtered[:, r] = np.nan  # y_0 = z̃_0 again at the next measurement
            self._restart = True
