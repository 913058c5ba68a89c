"""What runs on board a follower between the true state and its law: :class:`Onboard`.

The simulator observes the true state (:meth:`stringstab.traffic.Platoon.observe`); a real
follower sees it through its sensors (:mod:`~stringstab.traffic.sensors`: noise and a filter on
the gap, the gap rate and the own speed) and its radio (:mod:`~stringstab.traffic.radio`: the
predecessor's acceleration by message, held, lost, gone stale, with a fallback to ACC).
:class:`Onboard` wraps a controller with both and is itself a
:class:`~stringstab.traffic.controllers.Controller`, so every loop that steps a controller
(:func:`~stringstab.traffic.simulate`, :mod:`stringstab.sumo`) runs it unchanged.  It holds
state: call :meth:`Onboard.command` once per step, in order, then :meth:`Onboard.gains` for
that step.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from .controllers.base import Controller, Observation
from .radio import Radio, RadioLink
from .sensors import SensorNoise, Sensors

__all__ = ["Onboard"]

Array = npt.NDArray[np.float64]


class Onboard(Controller):
    """A controller behind the follower's sensors and radio (see the module).

    Parameters
    ----------
    controller : Controller
        The law every follower runs.
    shape : (int, int)
        ``(n_platoons, n_followers)``.
    dt : float
        The control step Δt, s.
    radio : Radio, optional
        The V2V link (None: the acceleration arrives every step, as without radio).
    sensors : SensorNoise, optional
        The sensors (None: exact measurements).

    Attributes
    ----------
    link : RadioLink or None
        The radio's state.
    sensing : Sensors or None
        The sensors' state.
    """

    def __init__(self, controller: Controller, shape: tuple[int, int], dt: float, *,
                 radio: Radio | None = None, sensors: SensorNoise | None = None) -> None:
        self.inner = controller
        self.link: RadioLink | None = None if radio is None else radio.start(shape, dt, controller)
        self.sensing: Sensors | None = None if sensors is None else sensors.start(shape, dt)
        self.time_varying = bool(controller.time_varying
                                 or (self.link is not None and self.link.may_fall_back))
        self._seen: Observation | None = None

    def see(self, obs: Observation) -> Observation:
        """The observation of this step through the sensors, then the radio.

        Parameters
        ----------
        obs : Observation
            The true observation.

        Returns
        -------
        Observation
            What the followers' law sees.
        """
        seen = obs if self.sensing is None else self.sensing.measure(obs)
        return seen if self.link is None else self.link.receive(seen)

    def command(self, obs: Observation) -> Array:
        """The commands of this step: sensors, radio, the law, the fallback.

        Parameters
        ----------
        obs : Observation
            The true observation of this step.

        Returns
        -------
        array
            u per follower, m/s².
        """
        seen = self._seen = self.see(obs)
        u = np.asarray(self.inner.command(seen), dtype=np.float64)
        return u if self.link is None else self.link.command(seen, u)

    def gains(self, obs: Observation) -> Array | None:
        """The gains in force at the step last commanded (the fallback's where stale).

        Parameters
        ----------
        obs : Observation
            The true observation of that step (its measured twin is used).

        Returns
        -------
        array (..., 3) or None
            None if the law is not of the eq-4 form.
        """
        seen = self._seen if self._seen is not None and self._seen.step == obs.step else self.see(obs)
        K = self.inner.gains(seen)
        return K if self.link is None else self.link.gains(K)

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """The law's equilibrium gap (:meth:`Controller.equilibrium_gap`).

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s.

        Returns
        -------
        array
            The gap, m.
        """
        return self.inner.equilibrium_gap(speed)

    @property
    def headway(self) -> float | None:
        """T* of the law."""
        return self.inner.headway

    def describe(self) -> dict[str, Any]:
        """The law's description (the radio and sensors are the run's own ``params`` entries).

        Returns
        -------
        dict
            :meth:`Controller.describe` of the wrapped law.
        """
        return self.inner.describe()

    def summary(self) -> dict[str, Array] | None:
        """What the radio did per follower (:meth:`RadioLink.summary`), None without radio.

        Returns
        -------
        dict or None
            Messages received and lost and the time in fallback, per follower.
        """
        return None if self.link is None else self.link.summary()

    def reset(self, rows: Any = None) -> None:
        """Start the sensors and radios of ``rows`` (default all) afresh.

        Parameters
        ----------
        rows : index array, optional
            Platoons (first axis).
        """
        self._seen = None
        if self.sensing is not None:
            self.sensing.reset(rows)
        if self.link is not None:
            self.link.reset(rows)
