"""Gymnasium environments for one controlled follower (the IDL paper's training set-up, §3.2.2, §4.1.2).

A controlled vehicle follows a recorded or synthetic leader.  Each step it observes the
normalised state of eq 16, acts, and receives the reward of eqs 18-24
(:mod:`~stringstab.traffic.reward`).  The vehicle obeys the platoon dynamics of
:mod:`~stringstab.traffic.platoon` (third-order model with lag τ, delayed leader acceleration,
limits and collision detection).

Two action modes:

``action="gains"`` (IDL, eq 17)
    the action is the executed K = (k_x, k_v, k_a) ∈ [−2, 2]³ (Table 2, clipped to the box),
    from which the eq-4 law (:func:`~stringstab.traffic.controllers.linear_law`) computes u;
``action="accel"`` (pure RL)
    the action is the desired acceleration u ∈ [−7.6, 3] m/s².

State (eq 16): s = [Δp/α_p, Δv/α_v, a_{i−1}(t − δ)/α_acc] with Δp = gap − (T* v + l_0),
α_p = 25, α_v = 2.5, α_acc = 4.5 (Table 2).  Optionally (``observe``, not in the paper) the
follower's own acceleration a_i/α_acc and the gains it executed at the previous step
(K_{t−1}/2, zero at an episode's first step) are appended (:func:`extend_state`): the eq-16
state does not say what the vehicle is doing now, which the comfort reward (eq 21) penalises
changes of, nor which gains it runs, which a gain rate limit makes part of the dynamics.

The environment executes the gains it is given.  What turns a policy's *proposed* gains into
executed ones — a gain rate limit (:func:`limit_rate`, not in the paper) and then the repair
(§3.3), so every executed gain is certified — is an action wrapper around the environment
(:class:`stringstab.rl.envs.RepairedGains`), which reads the previous step's executed gains
(:attr:`BatchedCarFollowingEnv.prev_gains`) and the episode starts
(:attr:`BatchedCarFollowingEnv.first_step`).  Training episodes may start off equilibrium
(``start_spread``, not in the paper): the initial gap scaled by 1 + s_g·U(−1, 1) and the speed
offset by s_v·U(−1, 1) m/s, so that closing situations are met in training.

An episode runs over one leader (a :class:`~stringstab.traffic.leaders.Trajectory`, started in
equilibrium, or a :class:`~stringstab.traffic.leaders.FollowingPair`, started where the recorded
human follower was, as in the paper §4.1.2) until its last sample (``truncated``) or a
collision (``terminated``, when ``terminate_on_collision``; the paper ends training events at a
collision and lets test events continue).

:class:`CarFollowingEnv` is a standard ``gymnasium.Env``.  :class:`BatchedCarFollowingEnv` steps
``num_envs`` independent episodes at once with NumPy, for fast training; see its docstring for
the (simple) API.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal, TypeGuard

import gymnasium as gym
import numpy as np
import numpy.typing as npt
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..constants import DT, GAIN_BOUNDS, STATE_SCALES, TTC_STAR
from ..errors import StringStabError, show
from ..params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU
from .controllers import DEFAULT_STANDSTILL, Observation, linear_law
from .cycles import cycle
from .loaders import FollowingPair
from .metrics import time_headway, time_to_collision
from .platoon import DEFAULT_LENGTH, Limits, Model, Platoon
from .reward import reward
from .trajectory import Trajectory

__all__ = ["OBSERVE", "SCALES", "BatchedCarFollowingEnv", "CarFollowingEnv", "extend_state",
           "limit_rate", "state_dim", "state_vector"]

#: Platoon arrays that make up the state of a :class:`BatchedCarFollowingEnv` (with the step).
_PLATOON_STATE = ("position", "speed", "accel", "_buf", "collided", "collision_events",
                  "first_collision_step", "_in_collision")
#: What may be appended to the eq-16 state (``observe``): own acceleration, previous gains.
OBSERVE = ("accel", "gains")
#: Scale of the previous gains in the state (the half-range of Table 2's [−2, 2]).
GAIN_SCALE = 2.0

Array = npt.NDArray[np.float64]
ActionMode = Literal["gains", "accel"]

#: α_p, α_v, α_acc of eq 16 (Table 2).
SCALES = STATE_SCALES


def state_vector(obs: Observation, *, headway: float = DEFAULT_HEADWAY,
                 standstill: float = DEFAULT_STANDSTILL,
                 scales: tuple[float, float, float] = SCALES) -> Array:
    """The IDL state (eq 16) of every follower in ``obs``, shape ``(*obs.gap.shape, 3)``.

    s = [(gap − T* v − l_0)/α_p, (v_{i−1} − v)/α_v, a_{i−1}(t − δ)/α_acc].  Usable as the input
    of a gain policy inside :class:`~stringstab.traffic.controllers.TimeVaryingLinearController`.

    Parameters
    ----------
    obs : Observation
        What the followers know at one step: gap Δx (m), own speed v (m/s), relative speed
        Δv = v_{i−1} − v (m/s) and the delayed predecessor acceleration a_{i−1}(t − δ) (m/s²).
    headway : float
        Desired time headway T* (IDL eq 3), s.
    standstill : float
        Standstill distance l_0 (eq 3), m.
    scales : (float, float, float)
        α_p (m), α_v (m/s), α_acc (m/s²) of eq 16 (Table 2: 25, 2.5, 4.5).

    Returns
    -------
    ndarray, shape ``(*obs.gap.shape, 3)``
        The normalised state [Δp/α_p, Δv/α_v, a_{i−1}(t − δ)/α_acc], Δp the spacing error of
        eq 3.
    """
    dp = obs.gap - headway * obs.speed - standstill
    return np.stack([dp / scales[0], obs.rel_speed / scales[1],
                     obs.pred_accel_delayed / scales[2]], axis=-1)


def state_dim(observe: Sequence[str] = ()) -> int:
    """Length of the state with the ``observe`` extras (:func:`extend_state`).

    It is 3 (eq 16), 1 more for ``"accel"`` and 3 more for ``"gains"``.

    Parameters
    ----------
    observe : sequence of str
        Extras appended to the eq-16 state, some of :data:`OBSERVE` (``"accel"``, ``"gains"``).

    Returns
    -------
    int
        3, 4, 6 or 7.

    Raises
    ------
    StringStabError
        If ``observe`` names something other than ``"accel"`` or ``"gains"``.

    Examples
    --------
    >>> state_dim(), state_dim(("accel", "gains"))
    (3, 7)
    """
    unknown = sorted(set(observe) - set(OBSERVE))
    if unknown:
        raise StringStabError(f"observe must name some of {list(OBSERVE)}; got {unknown}")
    return 3 + ("accel" in observe) + 3 * ("gains" in observe)


def extend_state(state: npt.ArrayLike, *, observe: Sequence[str] = (),
                 accel: npt.ArrayLike | None = None, prev_gains: npt.ArrayLike | None = None,
                 scales: tuple[float, float, float] = SCALES) -> Array:
    """The eq-16 ``state`` (..., 3) with the ``observe`` extras appended (not in the paper).

    ``"accel"`` appends the follower's own acceleration a_i/α_acc (``accel``, shape ``(...)``),
    ``"gains"`` the gains executed at the previous step K_{t−1}/2 (``prev_gains``, (..., 3)).

    Parameters
    ----------
    state : array_like, shape (..., 3)
        The normalised IDL state of eq 16 (:func:`state_vector`).
    observe : sequence of str
        Extras to append, some of :data:`OBSERVE`, always in the order accel, then gains.
    accel : array_like, shape (...), optional
        The follower's own acceleration a_i, m/s²; needed for ``"accel"``.
    prev_gains : array_like, shape (..., 3), optional
        The gains (k_x [1/s²], k_v [1/s], k_a [-]) executed at the previous step; needed for
        ``"gains"`` (zeros at an episode's first step).
    scales : (float, float, float)
        α_p, α_v, α_acc of eq 16; only α_acc is used here.

    Returns
    -------
    ndarray, shape (..., :func:`state_dim` (observe))
        The extended state (``state`` itself, as floats, when ``observe`` is empty).

    Raises
    ------
    StringStabError
        If ``observe`` names an unknown extra, or an extra's input is missing.

    Examples
    --------
    >>> extend_state([[0.1, 0.2, 0.3]], observe=("accel", "gains"), accel=[0.9],
    ...              prev_gains=[[1.0, 0.5, -0.4]]).round(2).tolist()
    [[0.1, 0.2, 0.3, 0.2, 0.5, 0.25, -0.2]]
    """
    s = np.asarray(state, dtype=np.float64)
    state_dim(observe)  # checks the names
    parts = [s]
    if "accel" in observe:
        if accel is None:
            raise StringStabError("observe 'accel' needs the follower's acceleration")
        parts.append(np.asarray(accel, dtype=np.float64)[..., None] / scales[2])
    if "gains" in observe:
        if prev_gains is None:
            raise StringStabError("observe 'gains' needs the previous gains")
        parts.append(np.asarray(prev_gains, dtype=np.float64) / GAIN_SCALE)
    return np.concatenate(parts, axis=-1) if len(parts) > 1 else s


def limit_rate(gains: npt.ArrayLike, prev_gains: npt.ArrayLike, rate: float, *,
               fresh: npt.ArrayLike | bool = False) -> Array:
    """Clip each gain to within ``rate`` of the previous step's (a gain rate limit; not in the paper).

    Rows where ``fresh`` is true (an episode's first step: no previous gains) are left as
    they are.  The result still needs the repair: the rate limit keeps the gains near a
    certified triple, it does not certify them.

    Parameters
    ----------
    gains : array_like, shape (..., 3)
        The proposed gains (k_x, k_v, k_a) of IDL eq 4 (the policy's action, eq 17).
    prev_gains : array_like, shape (..., 3)
        The gains executed at the previous step.
    rate : float
        The largest change r of each gain per step (in the gain's unit per step).
    fresh : array_like of bool, shape (...), or bool
        True where there are no previous gains (the proposed gains pass unchanged).

    Returns
    -------
    ndarray, shape (..., 3)
        clip(gains, prev_gains − r, prev_gains + r), or ``gains`` where ``fresh``.

    Examples
    --------
    >>> limit_rate([[1.5, 0.0, 0.3]], [[1.0, 0.1, 0.3]], 0.2).tolist()
    [[1.2, 0.0, 0.3]]
    """
    K = np.asarray(gains, dtype=np.float64)
    P = np.asarray(prev_gains, dtype=np.float64)
    out = np.clip(K, P - rate, P + rate)
    f = np.asarray(fresh, dtype=bool)
    return np.asarray(np.where(f[..., None] if f.ndim else f, K, out))


def _is_pair(x: Any) -> TypeGuard[FollowingPair]:
    # duck typing (see stringstab.traffic.platoon._is_trajectory)
    return hasattr(x, "leader") and hasattr(x, "follower") and hasattr(x, "gap")


class _Core:
    """``n`` independent leader–follower episodes over a shared list of leaders."""

    def __init__(self, leaders: Sequence[Trajectory | FollowingPair], n: int, *, action: ActionMode,
                 tau: float, delta: float, headway: float, standstill: float, model: Model,
                 limits: Limits | None, length: float, gain_bounds: tuple[float, float],
                 weights: tuple[float, float, float], ttc_star: float,
                 scales: tuple[float, float, float], terminate_on_collision: bool,
                 observe: Sequence[str] = (), start_spread: tuple[float, float] = (0.0, 0.0)
                 ) -> None:
        items = list(leaders)
        if not items:
            raise StringStabError("the environment needs at least one leader trajectory or pair")
        trs: list[Trajectory] = []
        for it in items:
            if _is_pair(it):
                trs.append(it.leader)
            elif hasattr(it, "speed") and hasattr(it, "dt"):
                trs.append(it)  # type: ignore[arg-type]
            else:
                raise StringStabError(f"leaders must be Trajectory or FollowingPair; got {type(it).__name__}")
        dts = {tr.dt for tr in trs}
        if len(dts) != 1:
            raise StringStabError(f"all leaders must share one step dt; got {sorted(dts)}")
        if action not in ("gains", "accel"):
            raise StringStabError(f"action must be 'gains' or 'accel'; got {show(action)}")
        lo, hi = (float(b) for b in gain_bounds)
        if not lo < hi:
            raise StringStabError(f"gain_bounds must be (low, high) with low < high; got {show(gain_bounds)}")
        self.items, self.n, self.dt = items, int(n), trs[0].dt
        self.action, self.gain_bounds = action, (lo, hi)
        self.headway, self.standstill = float(headway), float(standstill)
        self.weights, self.ttc_star, self.scales = weights, float(ttc_star), scales
        self.terminate_on_collision = terminate_on_collision
        spread = tuple(float(x) for x in start_spread)
        if len(spread) != 2 or not all(np.isfinite(x) and x >= 0 for x in spread):
            raise StringStabError(f"start_spread must be (gap fraction, speed m/s) >= 0; got {show(start_spread)}")
        state_dim(observe)  # checks the names
        self.extras, self.start_spread = tuple(observe), spread
        self.lengths = np.array([tr.n_steps for tr in trs])
        T = int(self.lengths.max())
        pad = [(tr.position, tr.speed, tr.accel) for tr in trs]
        self.LX = np.zeros((len(trs), T))
        self.LV = np.zeros((len(trs), T))
        self.LA = np.zeros((len(trs), T))
        for j, (x, v, a) in enumerate(pad):
            m = x.shape[0]
            self.LX[j, :m], self.LV[j, :m], self.LA[j, :m] = x, v, a
            self.LX[j, m:], self.LV[j, m:] = x[-1], v[-1]
        init_gap, init_speed = [], []
        for it, tr in zip(items, trs):
            if _is_pair(it):
                init_gap.append(float(it.gap[0]))
                init_speed.append(float(it.follower.speed[0]))
            else:
                init_gap.append(self.standstill + self.headway * float(tr.speed[0]))
                init_speed.append(float(tr.speed[0]))
        self.init_gap, self.init_speed = np.array(init_gap), np.array(init_speed)
        self.platoon = Platoon(self.n, 1, dt=self.dt, tau=tau, delta=delta, model=model,
                               limits=limits, length=length)
        self.which = np.zeros(self.n, dtype=np.int64)
        self.k = np.zeros(self.n, dtype=np.int64)
        #: Gains executed at the previous step (zero, and not rate limited, at an episode start).
        self.prev_gains = np.zeros((self.n, 3))
        self.obs: Observation | None = None
        self.ret = np.zeros(self.n)

    def leader_now(self) -> tuple[Array, Array, Array]:
        kk = np.minimum(self.k, self.lengths[self.which] - 1)
        return self.LX[self.which, kk], self.LV[self.which, kk], self.LA[self.which, kk]

    def reset_rows(self, rows: npt.NDArray[np.int64], which: npt.NDArray[np.int64],
                   rng: np.random.Generator | None = None) -> None:
        self.which[rows] = which
        self.k[rows] = 0
        self.ret[rows] = 0.0
        self.prev_gains[rows] = 0.0
        gap, speed = self.init_gap[which], self.init_speed[which]
        if rng is not None and any(self.start_spread):
            u = rng.uniform(-1.0, 1.0, size=(2, len(rows)))
            free = np.array([not _is_pair(self.items[j]) for j in which])  # NGSIM: as recorded
            gap = np.where(free, gap * (1.0 + self.start_spread[0] * u[0]), gap)
            speed = np.where(free, np.maximum(speed + self.start_spread[1] * u[1], 0.0), speed)
        self.platoon.reset(self.LX[which, 0], self.LV[which, 0], self.LA[which, 0],
                           gap=gap[:, None], speed=speed[:, None], accel=0.0, rows=rows)

    def observe(self) -> Observation:
        self.obs = self.platoon.observe(*self.leader_now())
        return self.obs

    def state(self) -> npt.NDArray[np.float32]:
        assert self.obs is not None
        s = state_vector(self.obs, headway=self.headway, standstill=self.standstill,
                         scales=self.scales)[:, 0, :]
        if self.extras:
            s = extend_state(s, observe=self.extras, accel=self.obs.accel[:, 0],
                             prev_gains=self.prev_gains, scales=self.scales)
        return s.astype(np.float32)

    def command(self, actions: npt.ArrayLike) -> tuple[Array, Array | None]:
        assert self.obs is not None
        a = np.asarray(actions, dtype=np.float64).reshape(self.n, -1)
        if self.action == "accel":
            if a.shape[1] != 1:
                raise StringStabError(f"accel actions must have 1 value per env; got shape {a.shape}")
            return a[:, :1], None
        if a.shape[1] != 3:
            raise StringStabError(f"gain actions must be (k_x, k_v, k_a) per env; got shape {a.shape}")
        K = np.clip(a, *self.gain_bounds)
        self.prev_gains = K.copy()
        u = linear_law(K[:, None, :], self.obs, headway=self.headway, standstill=self.standstill)
        return u, K

    def step(self, actions: npt.ArrayLike) -> tuple[Array, npt.NDArray[np.bool_], npt.NDArray[np.bool_], dict[str, Any]]:
        u, K = self.command(actions)
        prev_accel = self.platoon.accel[:, 1].copy()
        u_lim = self.platoon.advance(u)
        self.k += 1
        o = self.observe()
        gap, spd, pspd = o.gap[:, 0], o.speed[:, 0], o.pred_speed[:, 0]
        r, r_f, r_j, r_e = reward(gap, spd, pspd, o.accel[:, 0], prev_accel, weights=self.weights,
                                  ttc_star=self.ttc_star)
        collision = gap <= 0
        terminated = collision & self.terminate_on_collision
        truncated = (self.k >= self.lengths[self.which] - 1) & ~terminated
        self.ret += r
        info: dict[str, Any] = {
            "gap": gap.copy(), "speed": spd.copy(), "accel": o.accel[:, 0].copy(),
            "command": u_lim[:, 0].copy(), "ttc": time_to_collision(gap, spd, pspd),
            "headway": time_headway(gap, spd), "r_f": r_f, "r_j": r_j, "r_e": r_e,
            "collision": collision, "leader_index": self.which.copy(), "t": self.k * self.dt,
        }
        if K is not None:
            info["gains"] = K
        return np.asarray(r, dtype=np.float64), terminated, truncated, info


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
        Vehicle update (see :mod:`stringstab.traffic.platoon`).
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
                 order: Literal["random", "sequential"] = "random") -> None:
        if order not in ("random", "sequential"):
            raise StringStabError(f"order must be 'random' or 'sequential'; got {show(order)}")
        self._core = _Core(leaders if leaders is not None else _default_leaders(), 1, action=action,
                           tau=tau, delta=delta, headway=headway, standstill=standstill, model=model,
                           limits=limits, length=length, gain_bounds=gain_bounds, weights=weights,
                           ttc_star=ttc_star, scales=scales,
                           terminate_on_collision=terminate_on_collision)
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
                 start_spread: tuple[float, float] = (0.0, 0.0)) -> None:
        if int(num_envs) < 1:
            raise StringStabError(f"num_envs must be >= 1; got {show(num_envs)}")
        self.num_envs = int(num_envs)
        self._core = _Core(leaders if leaders is not None else _default_leaders(), self.num_envs,
                           action=action, tau=tau, delta=delta, headway=headway,
                           standstill=standstill, model=model, limits=limits, length=length,
                           gain_bounds=gain_bounds, weights=weights, ttc_star=ttc_star,
                           scales=scales, terminate_on_collision=terminate_on_collision,
                           observe=observe, start_spread=start_spread)
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
        arrays.update({f"platoon.{a}": getattr(p, a) for a in _PLATOON_STATE})
        meta = {"num_envs": self.num_envs, "n_leaders": len(c.items), "step": int(p.step),
                "any_in_collision": bool(p._any_in_collision),
                "rng": self.np_random.bit_generator.state}
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
        names = ["which", "k", "ret", "prev_gains", *(f"platoon.{a}" for a in _PLATOON_STATE)]
        for name in names:
            if name not in arrays:
                raise StringStabError(f"environment state: expected key {name!r} in the "
                                      f"environment's arrays, found keys {sorted(arrays)}")
        for name in ("which", "k", "ret", "prev_gains"):
            self._restore(getattr(c, name), arrays[name], name)
        for a in _PLATOON_STATE:
            self._restore(getattr(p, a), arrays[f"platoon.{a}"], f"platoon.{a}")
        p.step = int(meta["step"])
        p._any_in_collision = bool(meta["any_in_collision"])
        self.np_random.bit_generator.state = meta["rng"]
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
