"""The V2V radio of every follower (issue 26): messages every N steps, held, lost, gone stale.

The eq-4 feed-forward term k_a a_{i−1}(t − δ) reaches a real follower by radio.  Per link
(follower i hearing its predecessor i − 1), with the control step Δt:

schedule
    a message is used at the steps k ≡ φ (mod N): message period P = N·Δt (N ≥ 1, a whole
    number of steps), phase φ ∈ {0, …, N − 1} (per link if an array);
content
    the predecessor's acceleration δ seconds earlier, a_{i−1}(t_k − δ), exactly as the link
    without radio delivers it (:mod:`stringstab.traffic.dynamics`: the transport delay δ, by
    default interpolated between samples, exact inside the step with
    ``fractional_delay="exact"``);
hold
    between messages the follower uses the last one received.  Before the first message it
    holds the value of the link at its first step (the initial history: 0 in an equilibrium
    start), which counts as fresh;
loss
    each due message is lost at random (:class:`~stringstab.traffic.loss.MessageLoss`:
    Bernoulli with rate p, or Gilbert–Elliott bursts of mean length B), seeded; a lost
    message leaves the hold as it was;
staleness and fallback
    with ``stale_after`` = T_s, a follower whose last received message is more than T_s old
    ((k − k_last)·Δt > T_s) falls back to ACC until a message arrives: it uses no
    acceleration (k_a a = 0: the observation's ``pred_accel_delayed`` is 0) and, if
    ``fallback_gains`` = (k_x', k_v') are given, the eq-4 law with (k_x', k_v', 0) at the
    controller's T* and l_0 (IDL eqs 3-4) instead of its own.

This is the loop of the multi-rate certificate (docs/sampled.md §9.1) when every message
arrives (p = 0, no fallback): N = 1 is the link without radio, bit for bit.  Random loss and
the switching between modes are not covered by any certificate; simulate them.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show
from .controllers.base import DEFAULT_STANDSTILL, Controller, Observation
from .controllers.linear import linear_law
from .loss import MessageLoss, check_loss

__all__ = ["MESSAGE_RTOL", "Radio", "RadioLink", "message_steps"]

Array = npt.NDArray[np.float64]

#: A message period this close to a whole number of steps (relative to Δt) is that number
#: (the rule of the multi-rate certificate's schedule check).
MESSAGE_RTOL = 1e-9
#: Stream of the seed the message loss draws from (the sensors use another).
LOSS_STREAM = 0x7AD10


def message_steps(message_period: Any, dt: float) -> int:
    """N = P/Δt, the message period in steps: a whole number ≥ 1 (within 10⁻⁹ Δt).

    Parameters
    ----------
    message_period : float
        P, s.
    dt : float
        The control step Δt, s (> 0).

    Returns
    -------
    int
        N ≥ 1.

    Raises
    ------
    StringStabError
        P not a finite number > 0, or not a whole multiple of Δt.

    Examples
    --------
    >>> message_steps(0.1, 0.01)
    10
    >>> message_steps(0.015, 0.01)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: message period must be a whole multiple (>= 1) of the step dt = 0.01 s; got 0.015 s (1.5 steps)
    """
    try:
        P = float(message_period)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"message period must be a number of seconds > 0; got {show(message_period)}") from e
    if not (math.isfinite(P) and P > 0):
        raise StringStabError(f"message period must be a finite number of seconds > 0; got {show(message_period)}")
    n = round(P / dt)
    if n < 1 or abs(P - n * dt) > MESSAGE_RTOL * dt:
        raise StringStabError(f"message period must be a whole multiple (>= 1) of the step dt = {dt:g} s; "
                              f"got {P:g} s ({P / dt:.4g} steps)")
    return int(n)


@dataclass(frozen=True)
class Radio:
    """The V2V link of every follower: schedule, loss, staleness and fallback (see the module).

    Attributes
    ----------
    message_period : float or None
        P, s: a whole multiple of the simulation step; None: a message every step.
    message_phase : int or array of int
        φ ∈ {0, …, N − 1}: the steps k ≡ φ (mod N) at which messages are used; an array
        broadcasting to ``(n_platoons, n_followers)`` gives each link its own.
    loss : float
        Mean message loss rate p ∈ [0, 1].
    burst : float or None
        Mean number of messages lost in a row (Gilbert–Elliott), ≥ 1; None: independent losses.
    stale_after : float or None
        T_s, s (≥ P): fall back to ACC when the last message received is older; None: never.
    fallback_gains : (float, float) or None
        (k_x', k_v') of the fallback law (k_a = 0); None: the controller's own law without the
        acceleration term.  Needs ``stale_after``.
    seed : int
        Seed of the message loss (≥ 0).

    Examples
    --------
    >>> Radio(message_period=0.1, loss=0.02, burst=3).describe()["message_period"]
    0.1
    """

    message_period: float | None = None
    message_phase: Any = 0
    loss: float = 0.0
    burst: float | None = None
    stale_after: float | None = None
    fallback_gains: tuple[float, float] | None = None
    seed: int = 0

    def __post_init__(self) -> None:
        """Check what can be checked without the step Δt (one line each)."""
        p, b = check_loss(self.loss, self.burst)
        object.__setattr__(self, "loss", p)
        object.__setattr__(self, "burst", b)
        if self.message_period is not None:
            object.__setattr__(self, "message_period", self._period())
        phase = np.asarray(self.message_phase)
        if phase.dtype.kind not in "iu" and not (phase.dtype.kind == "f" and np.all(phase == np.round(phase))):
            raise StringStabError(f"message phase must be a whole number of steps >= 0; got {show(self.message_phase)}")
        if (phase < 0).any():
            raise StringStabError(f"message phase must be a whole number of steps >= 0; got {show(self.message_phase)}")
        if self.stale_after is not None:
            try:
                ts = float(self.stale_after)
            except (TypeError, ValueError) as e:
                raise StringStabError(f"stale_after must be a number of seconds > 0; got {show(self.stale_after)}") from e
            if not (math.isfinite(ts) and ts > 0):
                raise StringStabError(f"stale_after must be a finite number of seconds > 0; got {show(self.stale_after)}")
            if self.message_period is not None and ts < self.message_period * (1 - 1e-12):
                raise StringStabError(
                    f"stale_after must be at least the message period {self.message_period:g} s (or every "
                    f"follower would fall back between two messages); got {ts:g} s")
            object.__setattr__(self, "stale_after", ts)
        if self.fallback_gains is not None:
            if self.stale_after is None:
                raise StringStabError("fallback_gains apply once messages are stale; expected stale_after "
                                      f"with them, got fallback_gains {show(self.fallback_gains)} alone")
            g = np.asarray(self.fallback_gains, dtype=np.float64).ravel()
            if g.size != 2 or not np.isfinite(g).all():
                raise StringStabError(f"fallback_gains must be two finite numbers (k_x, k_v); "
                                      f"got {show(self.fallback_gains)}")
            object.__setattr__(self, "fallback_gains", (float(g[0]), float(g[1])))
        if not (isinstance(self.seed, (int, np.integer)) and self.seed >= 0):
            raise StringStabError(f"seed must be an integer >= 0; got {show(self.seed)}")

    def _period(self) -> float:
        try:
            P = float(self.message_period)  # type: ignore[arg-type]
        except (TypeError, ValueError) as e:
            raise StringStabError(f"message period must be a number of seconds > 0; "
                                  f"got {show(self.message_period)}") from e
        if not (math.isfinite(P) and P > 0):
            raise StringStabError(f"message period must be a finite number of seconds > 0; "
                                  f"got {show(self.message_period)}")
        return P

    def describe(self) -> dict[str, Any]:
        """A JSON-ready description (the run's ``params["radio"]``).

        Returns
        -------
        dict
            Every field (the phase as a number or a nested list).
        """
        return {"message_period": self.message_period,
                "message_phase": np.asarray(self.message_phase).tolist(),
                "loss": self.loss, "burst": self.burst, "stale_after": self.stale_after,
                "fallback_gains": None if self.fallback_gains is None else list(self.fallback_gains),
                "seed": int(self.seed)}

    def start(self, shape: tuple[int, int], dt: float, controller: Controller) -> RadioLink:
        """The links of a batch, ready to :meth:`RadioLink.receive` (checks P against Δt).

        Parameters
        ----------
        shape : (int, int)
            ``(n_platoons, n_followers)``.
        dt : float
            The control step Δt, s.
        controller : Controller
            The followers' law (its T* and l_0 serve the fallback gains).

        Returns
        -------
        RadioLink
            The links' state.
        """
        return RadioLink(self, shape, dt, controller)


class RadioLink:
    """The stepping state of a :class:`Radio` for a batch of links (see the module).

    Parameters
    ----------
    radio : Radio
        The radio.
    shape : (int, int)
        ``(n_platoons, n_followers)``.
    dt : float
        The control step Δt, s.
    controller : Controller
        The followers' law.

    Attributes
    ----------
    received, lost : int arrays of ``shape``
        Messages received and lost per link so far.
    fallback_steps : int array of ``shape``
        Steps each follower spent in the fallback mode.
    stale : bool array of ``shape``
        Who is in the fallback mode at the current step.
    """

    def __init__(self, radio: Radio, shape: tuple[int, int], dt: float, controller: Controller) -> None:
        self.radio, self.shape, self.dt = radio, shape, float(dt)
        self.n = 1 if radio.message_period is None else message_steps(radio.message_period, dt)
        try:
            phase = np.broadcast_to(np.asarray(radio.message_phase).astype(np.int64), shape)
        except ValueError as e:
            raise StringStabError(f"message phase must broadcast to (n_platoons, n_followers)={shape}; "
                                  f"got shape {np.shape(radio.message_phase)}") from e
        if (phase >= self.n).any():
            raise StringStabError(f"message phase must be a step in 0..{self.n - 1} (the message period is "
                                  f"{self.n} steps); got {show(radio.message_phase)}")
        self.phase: int | npt.NDArray[np.int64] = int(phase.flat[0]) if (phase == phase.flat[0]).all() else phase
        self.loss = (MessageLoss(radio.loss, radio.burst, shape,
                                 np.random.default_rng([int(radio.seed), LOSS_STREAM]))
                     if radio.loss > 0 else None)
        self.fallback: tuple[float, float, float, float] | None = None  # k_x', k_v', T*, l_0
        if radio.fallback_gains is not None:
            if controller.headway is None:
                raise StringStabError(
                    f"fallback gains need a controller of the eq-4 form (with a headway T*); got "
                    f"{type(controller).__name__}")
            self.fallback = (*radio.fallback_gains, float(controller.headway),
                             float(getattr(controller, "standstill", DEFAULT_STANDSTILL)))
        self.received = np.zeros(shape, dtype=np.int64)
        self.lost = np.zeros(shape, dtype=np.int64)
        self.fallback_steps = np.zeros(shape, dtype=np.int64)
        self.stale = np.zeros(shape, dtype=bool)
        self.held: Array | None = None
        self.last = np.zeros(shape, dtype=np.int64)
        self._all = np.ones(shape, dtype=bool)
        # stale once (k − k_last)Δt > T_s, i.e. k − k_last > T_s/Δt (10⁻⁹ relative slack)
        self._stale_steps = (None if radio.stale_after is None
                             else radio.stale_after / self.dt * (1 + 1e-9))
        self._fresh: npt.NDArray[np.bool_] | None = None  # rows to start afresh at the next step

    @property
    def may_fall_back(self) -> bool:
        """Whether a follower can ever be in the fallback mode (a ``stale_after`` is set)."""
        return self.radio.stale_after is not None

    def receive(self, obs: Observation) -> Observation:
        """Deliver, lose or hold the messages of this step; the observation the law then sees.

        Parameters
        ----------
        obs : Observation
            This step's observation; ``pred_accel_delayed`` is the link's value a_{i−1}(t_k − δ).

        Returns
        -------
        Observation
            ``pred_accel_delayed`` replaced by the held message (0 for a follower in the
            fallback mode); every other field as in ``obs``.
        """
        k = obs.step
        value = np.broadcast_to(np.asarray(obs.pred_accel_delayed, dtype=np.float64), self.shape)
        if self.held is None:
            self.held = np.array(value, copy=True)
            self.last[...] = k
        elif self._fresh is not None:
            self.held[self._fresh] = value[self._fresh]
            self.last[self._fresh] = k
            self._fresh = None
        if isinstance(self.phase, int):  # one schedule for every link: all due or none
            due: Any = self._all if (k - self.phase) % self.n == 0 else None
        else:
            due = (k - self.phase) % self.n == 0
        if due is not None:
            if self.loss is None:
                np.copyto(self.held, value, where=due)
                np.copyto(self.last, k, where=due)
                self.received += due
            else:
                lost = self.loss.lost(due)
                got = due & ~lost
                np.copyto(self.held, value, where=got)
                np.copyto(self.last, k, where=got)
                self.received += got
                self.lost += lost
        ad = self.held
        if self._stale_steps is not None:
            self.stale = (k - self.last) > self._stale_steps
            self.fallback_steps += self.stale
            ad = np.where(self.stale, 0.0, self.held)
        return dataclasses.replace(obs, pred_accel_delayed=ad)

    def command(self, seen: Observation, u: Array) -> Array:
        """The commands after the fallback: the fallback law where a follower's messages are stale.

        Parameters
        ----------
        seen : Observation
            What the followers saw (from :meth:`receive`).
        u : array
            The controller's commands for ``seen``, m/s².

        Returns
        -------
        array
            ``u``, with the eq-4 law of (k_x', k_v', 0) (IDL eqs 3-4) where stale and fallback
            gains are given.
        """
        if self.fallback is None or not self.stale.any():
            return u
        kx, kv, headway, standstill = self.fallback
        ufb = linear_law((kx, kv, 0.0), seen, headway=headway, standstill=standstill)
        return np.asarray(np.where(self.stale, ufb, u))

    def gains(self, K: Array | None) -> Array | None:
        """The gains in force after the fallback: (k_x', k_v', 0) or (k_x, k_v, 0) where stale.

        Parameters
        ----------
        K : array (..., 3) or None
            The controller's gains for this step.

        Returns
        -------
        array (P, N, 3) or None
            None when ``K`` is None.
        """
        if K is None:
            return None
        G = np.array(np.broadcast_to(K, (*self.shape, 3)), dtype=np.float64)
        if self.radio.stale_after is None or not self.stale.any():
            return G
        if self.fallback is not None:
            G[self.stale, 0], G[self.stale, 1] = self.fallback[0], self.fallback[1]
        G[self.stale, 2] = 0.0
        return G

    def summary(self) -> dict[str, Array]:
        """What the radio did per follower (the run's ``radio`` record).

        Returns
        -------
        dict
            ``messages_received``, ``messages_lost`` (counts) and ``fallback_time`` (s), each
            of ``shape``.
        """
        return {"messages_received": self.received.copy(), "messages_lost": self.lost.copy(),
                "fallback_time": self.fallback_steps * self.dt}

    def reset(self, rows: Any = None) -> None:
        """Start the links of ``rows`` (default all) afresh: held value, age, loss chains.

        Parameters
        ----------
        rows : index array, optional
            Platoons whose radios restart at the next :meth:`receive` (counts are kept).
        """
        if rows is None:
            self.held = None
        else:
            fresh = np.zeros(self.shape, dtype=bool)
            fresh[np.asarray(rows)] = True
            self._fresh = fresh
        if self.loss is not None:
            self.loss.reset(rows)
