"""The sensors and radio of the environment's followers: :class:`EnvOnboard` (issue 26).

What :class:`~stringstab.traffic.onboard.Onboard` is to :func:`~stringstab.traffic.simulate`,
:class:`EnvOnboard` is to the environment's episodes (:class:`~stringstab.traffic.episodes.Episodes`):
the true observation of each step passes through the follower's sensors
(:mod:`~stringstab.traffic.sensors`) and then its radio (:mod:`~stringstab.traffic.radio`), and
the policy's state and the eq-4 law see the result; where the messages are stale the radio's
fallback law replaces the command (:meth:`~stringstab.traffic.radio.RadioLink.command`).  The
reward, the collisions and the recorded trajectory stay the true ones.

Two things differ from a platoon run, both bookkeeping:

* episodes restart row by row; a row restarted at step k has its sensors and radio started
  afresh at that step (:meth:`EnvOnboard.reset`);
* the environment observes a step twice when some episodes ended in it (once for their last
  state, once for the first state of the new ones); the second pass starts again from the
  sensors' and radio's state before the step, so no row's noise or message schedule advances
  twice in one step.

The whole state is kept in checkpoints (:meth:`EnvOnboard.state`), so training resumes bit for
bit with the radio and sensors on too.
"""

from __future__ import annotations

import copy
import dataclasses
from typing import Any

import numpy as np
import numpy.typing as npt

from .controllers.base import Observation
from .controllers.linear import LinearController
from .radio import Radio, RadioLink
from .sensors import SensorNoise, Sensors

__all__ = ["EnvOnboard"]

Array = npt.NDArray[np.float64]
#: The array fields of an :class:`~stringstab.traffic.controllers.Observation`.
_OBS_ARRAYS = ("gap", "speed", "accel", "pred_speed", "rel_speed", "pred_accel", "pred_accel_delayed")


class EnvOnboard:
    """Sensors and radio of ``n`` one-follower episodes (see the module).

    Parameters
    ----------
    radio : Radio or None
        The V2V link (None: the acceleration every step).
    sensors : SensorNoise or None
        The sensors (None: exact).
    n : int
        Number of episodes (rows).
    dt : float
        The control step Δt, s.
    headway, standstill : float
        T* (s) and l_0 (m) of the eq-4 law (the fallback law's).
    """

    def __init__(self, radio: Radio | None, sensors: SensorNoise | None, n: int, dt: float, *,
                 headway: float, standstill: float) -> None:
        shape = (int(n), 1)
        law = LinearController(0.0, 0.0, 0.0, headway=headway, standstill=standstill)
        self.link: RadioLink | None = None if radio is None else radio.start(shape, dt, law)
        self.sensing: Sensors | None = None if sensors is None else sensors.start(shape, dt)
        self.seen: Observation | None = None
        self._step = -1  # the step last seen
        self._before: tuple[RadioLink | None, Sensors | None] | None = None
        self._pending: set[int] = set()
        self._reset_now: set[int] = set()  # the rows restarted at the step last seen
        self._loaded = False

    def reset(self, rows: npt.ArrayLike) -> None:
        """Start the sensors and radio of ``rows`` afresh at the next :meth:`see`.

        Parameters
        ----------
        rows : int array
            The episodes restarted.
        """
        self._pending.update(int(r) for r in np.asarray(rows).ravel())

    def see(self, obs: Observation) -> Observation:
        """What the followers see at this step: ``obs`` through the sensors, then the radio.

        Parameters
        ----------
        obs : Observation
            The true observation (shapes ``(n, 1)``).

        Returns
        -------
        Observation
            The measured observation with the held message (kept as :attr:`seen`).
        """
        if self._loaded and obs.step == self._step and self.seen is not None:
            self._loaded = False  # restored from a checkpoint: this step was seen before it
            self.seen = dataclasses.replace(self.seen, step=obs.step, t=obs.t, dt=obs.dt)
            return self.seen
        self._loaded = False
        if obs.step == self._step and self._before is not None:
            # observed again after restarts: start again from the state before this step,
            # with every restart of this step
            self.link, self.sensing = copy.deepcopy(self._before)
            self._pending |= self._reset_now
        else:
            self._before = copy.deepcopy((self.link, self.sensing))
        self._step = obs.step
        self._reset_now = set(self._pending)
        if self._pending:
            rows = np.array(sorted(self._pending))
            self._pending.clear()
            if self.sensing is not None:
                self.sensing.reset(rows)
            if self.link is not None:
                self.link.reset(rows)
        seen = obs if self.sensing is None else self.sensing.measure(obs)
        self.seen = seen if self.link is None else self.link.receive(seen)
        return self.seen

    def command(self, u: Array) -> Array:
        """The commands after the radio's fallback (the fallback law where messages are stale).

        Parameters
        ----------
        u : array (n, 1)
            The commands of the law for :attr:`seen`, m/s².

        Returns
        -------
        array (n, 1)
            ``u``, replaced by the fallback law's command where stale with fallback gains.
        """
        if self.link is None or self.seen is None:
            return u
        return np.asarray(self.link.command(self.seen, u), dtype=np.float64)

    def state(self) -> tuple[dict[str, Any], dict[str, Array]]:
        """The state between two steps (a checkpoint).

        Returns
        -------
        meta : dict
            JSON-ready: the step last seen, the restarts pending and the parts' meta data.
        arrays : dict of str to ndarray
            The radio's (``link.``), the sensors' (``sensors.``) and the last observation seen
            (``seen.``).
        """
        meta: dict[str, Any] = {"step": self._step, "pending": sorted(self._pending)}
        arrays: dict[str, Array] = {}
        for name, part in (("link", self.link), ("sensors", self.sensing)):
            if part is not None:
                m, a = part.snapshot()
                meta[name] = m
                arrays.update({f"{name}.{k}": np.asarray(v) for k, v in a.items()})
        if self.seen is not None:
            arrays.update({f"seen.{f}": np.array(getattr(self.seen, f), dtype=np.float64)
                           for f in _OBS_ARRAYS})
        return meta, arrays

    def load_state(self, meta: dict[str, Any], arrays: dict[str, Any], obs: Observation) -> None:
        """Restore :meth:`state` output; ``obs`` is the true observation of the step restored.

        Parameters
        ----------
        meta : dict
            As :meth:`snapshot` returns it.
        arrays : dict of str to array_like
            As :meth:`snapshot` returns them.
        obs : Observation
            The true observation at the restored step (its step and time).
        """
        for name, part in (("link", self.link), ("sensors", self.sensing)):
            if part is not None:
                pre = f"{name}."
                part.restore(meta[name], {k[len(pre):]: v for k, v in arrays.items()
                                             if k.startswith(pre)})
        self._step = int(meta["step"])
        self._pending = {int(r) for r in meta["pending"]}
        self._reset_now = set()
        self._before = None
        if "seen.gap" in arrays:
            seen: dict[str, Any] = {f: np.array(arrays[f"seen.{f}"], dtype=np.float64)
                                    for f in _OBS_ARRAYS}
            self.seen = dataclasses.replace(obs, **seen)
            self._loaded = True
