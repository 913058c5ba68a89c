"""Gymnasium environments for one controlled follower (the IDL paper's training set-up, §3.2.2, §4.1.2).

A controlled vehicle follows a recorded or synthetic leader.  Each step it observes the
normalised state of eq 16 (:mod:`~stringstab.traffic.state`), acts, and receives the reward
of eqs 18-24 (:mod:`~stringstab.traffic.reward`).  The vehicle obeys the platoon dynamics of
:mod:`~stringstab.traffic.dynamics` (third-order model with lag τ, delayed leader
acceleration, limits and collision detection); both environments step the shared episodes of
:mod:`~stringstab.traffic.episodes`.

Two action modes:

``action="gains"`` (IDL, eq 17)
    the action is the executed K = (k_x, k_v, k_a) ∈ [−2, 2]³ (Table 2, clipped to the box),
    from which the eq-4 law (:func:`~stringstab.traffic.controllers.linear_law`) computes u;
``action="accel"`` (pure RL)
    the action is the desired acceleration u ∈ [−7.6, 3] m/s².

State (eq 16): s = [Δp/α_p, Δv/α_v, a_{i−1}(t − δ)/α_acc] with Δp = gap − (T* v + l_0),
α_p = 25, α_v = 2.5, α_acc = 4.5 (Table 2).  Optionally (``observe``, not in the paper) the
follower's own acceleration a_i/α_acc and the gains it executed at the previous step
(K_{t−1}/2, zero at an episode's first step) are appended
(:func:`~stringstab.traffic.state.extend_state`): the eq-16
state does not say what the vehicle is doing now, which the comfort reward (eq 21) penalises
changes of, nor which gains it runs, which a gain rate limit makes part of the dynamics.

The environment executes the gains it is given.  What turns a policy's *proposed* gains into
executed ones — a gain rate limit (:func:`~stringstab.traffic.rate.limit_rate`, not in the paper) and then the repair
(§3.3), so every executed gain is certified — is an action wrapper around the environment
(:class:`stringstab.rl.envs.RepairedGains`), which reads the previous step's executed gains
(:attr:`BatchedCarFollowingEnv.prev_gains`) and the episode starts
(:attr:`BatchedCarFollowingEnv.first_step`).  Training episodes may start off equilibrium
(``start_spread``, not in the paper): the initial gap scaled by 1 + s_g·U(−1, 1) and the speed
offset by s_v·U(−1, 1) m/s, so that closing situations are met in training.

An episode runs over one leader (a :class:`~stringstab.traffic.trajectory.Trajectory`, started in
equilibrium, or a :class:`~stringstab.traffic.loaders.FollowingPair`, started where the recorded
human follower was, as in the paper §4.1.2) until its last sample (``truncated``) or a
collision (``terminated``, when ``terminate_on_collision``; the paper ends training events at a
collision and lets test events continue).

:class:`CarFollowingEnv` is a standard ``gymnasium.Env``.  :class:`BatchedCarFollowingEnv` steps
``num_envs`` independent episodes at once with NumPy, for fast training; see its docstring for
the (simple) API.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal

import gymnasium as gym
import numpy as np
import numpy.typing as npt
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..constants import DT, GAIN_BOUNDS, TTC_STAR
from ..errors import StringStabError, show
from ..params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU
from .controllers.base import DEFAULT_STANDSTILL
from .cycles import cycle
from .dynamics import Model
from .episodes import ActionMode, Episodes
from .limits import DEFAULT_LENGTH, Limits
from .loaders import FollowingPair
from .radio import Radio
from .sensors import SensorNoise
from .state import SCALES, state_dim
from .trajectory import Trajectory

__all__ = [
    "BatchedCarFollowingEnv",
    "CarFollowingEnv",
]

#: Platoon arrays that make up the state of a :class:`BatchedCarFollowingEnv` (with the step).

Array = npt.NDArray[np.float64]


def _spaces(action: ActionMode, gain_bounds: tuple[float, float],
            limits: Limits | None, observe: Sequence[str] = ()) -> tuple[spaces.Box, spaces.Box]:
    obs_space = spaces.Box(-np.inf, np.inf, shape=(state_dim(observe),), dtype=np.float32)
    if action == "gains":
        act_space = spaces.Box(float(gain_bounds[0]), float(gain_bounds[1]), shape=(3,), dtype=np.float32)
    else:
        lim = limits or Limits()
        act_space = spaces.Box(lim.accel_min, lim.accel_max, shape=(1,), dtype=np.float32)
    return obs_space, act_space


def _default_leaders() -> list[Trajectory]:
    return [cycle(name, dt=DT) for name in ("udds", "hwfet", "us06", "wltc3b")]


class CarFollowingEnv(gym.Env[npt.NDArray[np.float32], npt.NDArray[np.float32]]):
    """One controlled follower behind a leader (IDL paper §3.2.2): a ``gymnasium.Env``.

    Parameters
    ----------
    leaders : sequence of Trajectory or FollowingPair, optional
        Episodes to draw from (default: the four bundled driving cycles at Δt = 0.1 s).
    action : {"gains", "accel"}
        IDL gain vector K (eq 17) or pure-RL acceleration.
    tau, delta, headway, standstill : float
        τ (s), δ (s), T* (s), l_0 (m).
    model : {"lag", "kinematic"}
        Vehicle update (see :mod:`stringstab.traffic.dynamics`).
    limits : Limits, optional
        Acceleration and speed bounds (Table 2).
    length : float
        Vehicle length, m.
    gain_bounds : (float, float)
        Range of each gain (Table 2: [−2, 2]).
    weights : (float, float, float)
        ω₁, ω₂, ω₃ of eq 18.
    ttc_star : float
        TTC*, s.
    scales : (float, float, float)
        α_p, α_v, α_acc of eq 16.
    terminate_on_collision : bool
        End the episode at a collision (training, §4.1.2).
    order : {"random", "sequential"}
        How :meth:`reset` picks the next leader (``options={"index": i}`` picks one).
    reaction_delay : float
        Reaction delay θ_r of the follower, s (issue 25): τ ȧ = u(t − θ_r) − a, exact
        (:mod:`stringstab.traffic.dynamics`); 0 (default) changes nothing.
    radio : Radio, optional
        The follower's V2V link (issue 26, :mod:`stringstab.traffic.radio`); None: the
        predecessor's acceleration every step.
    sensors : SensorNoise, optional
        Noise and a filter on what the follower measures (:mod:`stringstab.traffic.sensors`).
        With a radio or sensors the state and the law see the measured, message-held
        observation (:mod:`stringstab.traffic.env_onboard`); reward and collisions stay true.

    Examples
    --------
    >>> from stringstab.traffic import paper_mix
    >>> env = CarFollowingEnv([paper_mix()])
    >>> obs, info = env.reset(seed=0)
    >>> obs.shape, env.action_space.shape
    ((3,), (3,))
    >>> obs, r, terminated, truncated, info = env.step(np.array([1.2, 0.5, 0.6], dtype=np.float32))
    >>> bool(terminated), -1.0 <= r <= 0.0
    (False, True)
    """

    metadata: dict[str, Any] = {"render_modes": []}  # noqa: RUF012 (gymnasium API)

    def __init__(self, leaders: Sequence[Trajectory | FollowingPair] | None = None, *,
                 action: ActionMode = "gains", tau: float = DEFAULT_TAU, delta: float = DEFAULT_DELTA,
                 headway: float = DEFAULT_HEADWAY, standstill: float = DEFAULT_STANDSTILL,
                 model: Model = "lag", limits: Limits | None = None, length: float = DEFAULT_LENGTH,
                 gain_bounds: tuple[float, float] = GAIN_BOUNDS,
                 weights: tuple[float, float, float] = (1 / 3, 1 / 3, 1 / 3),
                 ttc_star: float = TTC_STAR, scales: tuple[float, float, float] = SCALES,
                 terminate_on_collision: bool = True,
                 order: Literal["random", "sequential"] = "random", reaction_delay: float = 0.0,
                 radio: Radio | None = None, sensors: SensorNoise | None = None) -> None:
        if order not in ("random", "sequential"):
            raise StringStabError(f"order must be 'random' or 'sequential'; got {show(order)}")
        self._core = Episodes(leaders if leaders is not None else _default_leaders(), 1, action=action,
                           tau=tau, delta=delta, headway=headway, standstill=standstill, model=model,
                           limits=limits, length=length, gain_bounds=gain_bounds, weights=weights,
                           ttc_star=ttc_star, scales=scales,
                           terminate_on_collision=terminate_on_collision,
                           reaction_delay=reaction_delay, radio=radio, sensors=sensors)
        self.observation_space, self.action_space = _spaces(action, gain_bounds, limits)  # type: ignore[assignment]
        self.order = order
        self._next = 0

    @property
    def n_leaders(self) -> int:
        """Number of leaders (episodes) available."""
        return len(self._core.items)

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[npt.NDArray[np.float32], dict[str, Any]]:
        """Start an episode on the next leader (``options={"index": i}`` chooses it).

        Parameters
        ----------
        seed : int, optional
            Seeds the environment's RNG (leader order ``"random"``, start spread).
        options : dict, optional
            ``{"index": i}`` runs leader i; otherwise the next leader in ``order``.

        Returns
        -------
        state : ndarray (float32)
            The first state: eq 16, with the ``observe`` extras.
        info : dict
            ``{"leader_index": i}``.

        Raises
        ------
        StringStabError
            If ``options["index"]`` is out of range.
        """
        super().reset(seed=seed)
        m = self.n_leaders
        if options and "index" in options:
            j = int(options["index"])
            if not 0 <= j < m:
                raise StringStabError(f"options['index'] must be in [0, {m - 1}]; got {j}")
        elif self.order == "sequential":
            j = self._next % m
        else:
            j = int(self.np_random.integers(m))
        self._next = j + 1
        self._core.reset_rows(np.array([0]), np.array([j]))
        self._core.observe()
        return self._core.state()[0], {"leader_index": j}

    def step(self, action: npt.ArrayLike) -> tuple[npt.NDArray[np.float32], float, bool, bool, dict[str, Any]]:
        """Apply one action; returns (state, reward, terminated, truncated, info).

        Parameters
        ----------
        action : array_like
            Gains K = (k_x, k_v, k_a) (eq 17, clipped to the gain box) or the desired
            acceleration u, m/s², by the action mode.

        Returns
        -------
        state : ndarray (float32)
            The next state (eq 16, with the ``observe`` extras).
        reward : float
            r of eq 18 (eqs 19-24).
        terminated : bool
            A collision ended the episode (with ``terminate_on_collision``).
        truncated : bool
            The leader's last sample was reached.
        info : dict
            Scalars describing the step (``gap``, ``speed``, ``accel``, ``r_f``, ``r_j``, ``r_e``,
            ``collision``, ``gains``, ...).

        Raises
        ------
        StringStabError
            If :meth:`reset` was not called first.
        """
        if self._core.obs is None:
            raise StringStabError("call reset() before step()")
        r, term, trunc, info = self._core.step(np.asarray(action)[None])
        info = {k: (v[0] if isinstance(v, np.ndarray) and v.shape[:1] == (1,) else v)
                for k, v in info.items()}
        info = {k: (v.item() if isinstance(v, np.generic) else v) for k, v in info.items()}
        return self._core.state()[0], float(r[0]), bool(term[0]), bool(trunc[0]), info


class BatchedCarFollowingEnv(VectorEnv[npt.NDArray[np.float32], npt.NDArray[np.float32], npt.NDArray[Any]]):
    """``num_envs`` independent car-following episodes stepped together (NumPy, no subprocesses).

    The same model and parameters as :class:`CarFollowingEnv` (see it for the parameters);
    episodes draw their leader at random from ``leaders`` (seeded by :meth:`reset`).  Two
    training options, none in the paper (module docstring): ``observe`` (extras appended to the
    eq-16 state: ``"accel"``, ``"gains"``) and ``start_spread`` (random initial gap fraction and
    speed offset, m/s, for trajectory leaders).  :attr:`prev_gains` and :attr:`first_step` are
    what an action wrapper needs to limit the rate of the gains (module docstring).

    API (a Gymnasium ``VectorEnv`` with *same-step* autoreset):

    * ``obs, info = env.reset(seed=0)`` — ``obs`` is float32 ``(num_envs, 3)``;
    * ``obs, reward, terminated, truncated, info = env.step(actions)`` with ``actions`` of
      shape ``(num_envs, 3)`` (gains) or ``(num_envs, 1)`` (accel); ``reward``, ``terminated``,
      ``truncated`` have shape ``(num_envs,)``.  A sub-environment whose episode ended in this
      step is reset at once: its row of ``obs`` is the first state of its new episode, its last
      state is in ``info["final_obs"]`` (NaN rows elsewhere, mask ``info["_final_obs"]``) and its
      episode return in ``info["episode_return"]`` (NaN elsewhere).  Other ``info`` entries
      (``gap``, ``speed``, ``accel``, ``r_f``, ``r_j``, ``r_e``, ``collision``, ``gains``, …) are
      arrays of shape ``(num_envs,)`` describing the step just taken.

    Examples
    --------
    >>> from stringstab.traffic import paper_mix
    >>> env = BatchedCarFollowingEnv(4, [paper_mix()])
    >>> obs, _ = env.reset(seed=0)
    >>> obs, r, term, trunc, info = env.step(np.tile([1.2, 0.5, 0.6], (4, 1)))
    >>> obs.shape, r.shape
    ((4, 3), (4,))
    """

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.SAME_STEP}  # noqa: RUF012

    def __init__(self, num_envs: int, leaders: Sequence[Trajectory | FollowingPair] | None = None,
                 *, action: ActionMode = "gains", tau: float = DEFAULT_TAU,
                 delta: float = DEFAULT_DELTA, headway: float = DEFAULT_HEADWAY,
                 standstill: float = DEFAULT_STANDSTILL, model: Model = "lag",
                 limits: Limits | None = None, length: float = DEFAULT_LENGTH,
                 gain_bounds: tuple[float, float] = GAIN_BOUNDS,
                 weights: tuple[float, float, float] = (1 / 3, 1 / 3, 1 / 3),
                 ttc_star: float = TTC_STAR, scales: tuple[float, float, float] = SCALES,
                 terminate_on_collision: bool = True, observe: Sequence[str] = (),
                 start_spread: tuple[float, float] = (0.0, 0.0), reaction_delay: float = 0.0,
                 radio: Radio | None = None, sensors: SensorNoise | None = None) -> None:
        if int(num_envs) < 1:
            raise StringStabError(f"num_envs must be >= 1; got {show(num_envs)}")
        self.num_envs = int(num_envs)
        self._core = Episodes(leaders if leaders is not None else _default_leaders(), self.num_envs,
                           action=action, tau=tau, delta=delta, headway=headway,
                           standstill=standstill, model=model, limits=limits, length=length,
                           gain_bounds=gain_bounds, weights=weights, ttc_star=ttc_star,
                           scales=scales, terminate_on_collision=terminate_on_collision,
                           observe=observe, start_spread=start_spread,
                           reaction_delay=reaction_delay, radio=radio, sensors=sensors)
        self.single_observation_space, self.single_action_space = _spaces(action, gain_bounds,
                                                                          limits, observe)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)

    @property
    def action_mode(self) -> ActionMode:
        """``"gains"`` (IDL, eq 17) or ``"accel"`` (pure RL)."""
        return self._core.action

    @property
    def gain_bounds(self) -> tuple[float, float]:
        """The gain box (low, high) every gain action is clipped to (Table 2: (−2, 2))."""
        return self._core.gain_bounds

    @property
    def prev_gains(self) -> Array:
        """The gains executed at the previous step, ``(num_envs, 3)`` (read-only view).

        Zeros at an episode's first step (see :attr:`first_step`); with ``action="accel"``
        always zeros.
        """
        v = self._core.prev_gains.view()
        v.flags.writeable = False
        return v

    @property
    def first_step(self) -> npt.NDArray[np.bool_]:
        """``(num_envs,)`` bool: true where the episode has taken no step yet (no previous gains)."""
        return np.asarray(self._core.k == 0)

    def _draw(self, n: int) -> npt.NDArray[np.int64]:
        return np.asarray(self.np_random.integers(len(self._core.items), size=n), dtype=np.int64)

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[npt.NDArray[np.float32], dict[str, Any]]:
        """Reset every sub-environment; returns states ``(num_envs, 3)`` and ``{"leader_index"}``.

        Each sub-environment draws its leader at random (seeded by ``seed``).  With
        ``observe`` extras the states have :func:`state_dim` columns instead of 3.

        Parameters
        ----------
        seed : int, optional
            Seeds the episode-drawing RNG.
        options : dict, optional
            Ignored.

        Returns
        -------
        states : ndarray (num_envs, state_dim), float32
            The first states.
        info : dict
            ``{"leader_index": array (num_envs,)}``.
        """
        super().reset(seed=seed)
        rows = np.arange(self.num_envs)
        self._core.reset_rows(rows, self._draw(self.num_envs), self.np_random)
        self._core.observe()
        return self._core.state(), {"leader_index": self._core.which.copy()}

    def state_dict(self) -> tuple[dict[str, Any], dict[str, npt.NDArray[Any]]]:
        """The state of every sub-environment, to continue bit for bit (a training checkpoint).

        Returns ``(meta, arrays)``: JSON-ready counters and the episode-drawing RNG state, and
        plain arrays (platoon states, delay buffers, leader indices, steps, returns).  No
        objects: both can be stored in safe formats (JSON, safetensors).
        """
        if self._core.obs is None:
            raise StringStabError("call reset() before state_dict()")
        c, p = self._core, self._core.platoon
        arrays = {"which": c.which, "k": c.k, "ret": c.ret, "prev_gains": c.prev_gains}
        platoon_meta, platoon_arrays = p.state()
        arrays.update({f"platoon.{a}": v for a, v in platoon_arrays.items()})
        meta = {"num_envs": self.num_envs, "n_leaders": len(c.items), **platoon_meta,
                "rng": self.np_random.bit_generator.state}
        if c.onboard is not None:  # the sensors and radio (issue 26)
            onboard_meta, onboard_arrays = c.onboard.state()
            meta["onboard"] = onboard_meta
            arrays.update({f"onboard.{a}": v for a, v in onboard_arrays.items()})
        return meta, {k: np.array(v, copy=True) for k, v in arrays.items()}

    def load_state_dict(self, meta: dict[str, Any], arrays: dict[str, npt.NDArray[Any]]) -> None:
        """Restore :meth:`state_dict` output (same leaders and ``num_envs``; checked).

        Parameters
        ----------
        meta : dict
            The JSON-ready part of :meth:`state_dict`.
        arrays : dict of str to ndarray
            The arrays of :meth:`state_dict`.

        Raises
        ------
        StringStabError
            If the number of environments or leaders differs, a key of ``meta`` or an array is
            missing, or an array has another shape.
        """
        c, p = self._core, self._core.platoon
        if meta.get("num_envs") != self.num_envs or meta.get("n_leaders") != len(c.items):
            raise StringStabError(
                f"environment state: expected {self.num_envs} environments over {len(c.items)} "
                f"leaders; found {meta.get('num_envs')} over {meta.get('n_leaders')}")
        for key in ("step", "any_in_collision", "rng"):
            if key not in meta:
                raise StringStabError(f"environment state: expected key {key!r} in the "
                                      f"environment's meta data, found keys {sorted(meta)}")
        names = ["which", "k", "ret", "prev_gains", *(f"platoon.{a}" for a in p.state_arrays)]
        for name in names:
            if name not in arrays:
                raise StringStabError(f"environment state: expected key {name!r} in the "
                                      f"environment's arrays, found keys {sorted(arrays)}")
        for name in ("which", "k", "ret", "prev_gains"):
            self._restore(getattr(c, name), arrays[name], name)
        p.load_state(meta, {a: arrays[f"platoon.{a}"] for a in p.state_arrays})
        self.np_random.bit_generator.state = meta["rng"]
        if c.onboard is not None:
            if "onboard" not in meta:
                raise StringStabError("environment state: expected the sensors' and radio's state "
                                      "(key 'onboard'); found none")
            c.onboard.load_state(meta["onboard"],
                                 {a[len("onboard."):]: v for a, v in arrays.items()
                                  if a.startswith("onboard.")},
                                 p.observe(*c.leader_now()))
        c.observe()

    @staticmethod
    def _restore(dst: npt.NDArray[Any], src: Any, name: str) -> None:
        a = np.asarray(src)
        if a.shape != dst.shape:
            raise StringStabError(f"environment state {name}: expected shape {dst.shape}; found {a.shape}")
        dst[...] = a

    def step(self, actions: npt.ArrayLike) -> tuple[npt.NDArray[np.float32], Array,
                                                   npt.NDArray[np.bool_], npt.NDArray[np.bool_],
                                                   dict[str, Any]]:
        """Step every sub-environment (see the class docstring).

        Parameters
        ----------
        actions : array_like (num_envs, 3) or (num_envs, 1)
            Gains (eq 17) or desired accelerations (m/s²), one row per sub-environment.

        Returns
        -------
        states : ndarray (num_envs, state_dim), float32
            The next states; a finished episode's row is the first state of its new episode.
        rewards : ndarray (num_envs,)
            r of eq 18.
        terminated, truncated : bool ndarray (num_envs,)
            Collision ends and ends at the leader's last sample.
        info : dict
            ``final_obs``/``_final_obs`` and ``episode_return`` of the finished episodes (NaN
            elsewhere), and arrays (num_envs,) describing the step.

        Raises
        ------
        StringStabError
            If :meth:`reset` was not called first.
        """
        if self._core.obs is None:
            raise StringStabError("call reset() before step()")
        r, term, trunc, info = self._core.step(actions)
        done = term | trunc
        dim = self.single_observation_space.shape[0]  # type: ignore[index]
        info["final_obs"] = np.full((self.num_envs, dim), np.nan, dtype=np.float32)
        info["_final_obs"] = done.copy()
        info["episode_return"] = np.where(done, self._core.ret, np.nan)
        if done.any():
            rows = np.flatnonzero(done)
            info["final_obs"][rows] = self._core.state()[rows]
            self._core.reset_rows(rows, self._draw(rows.size), self.np_random)
            self._core.observe()
        return self._core.state(), r, term, trunc, info
