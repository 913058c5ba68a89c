"""A Gymnasium VectorEnv for training the HCFS DDPG with the HCFS reward (eqs 3-6, §IV).

The paper trains its DDPG in a platoon of one leader and six followers, every follower driven
by the same policy (§IV).  Here each *follower* is one sub-environment: ``num_platoons``
platoons of ``n_followers`` followers give ``num_envs = num_platoons · n_followers`` rows,
row ``p · N + (i − 1)`` being follower i of platoon p.  All rows of a platoon start and end
their episode together.

* observation: the eq-3 state of the follower divided by
  :data:`~stringstab.hcfs.mdp.STATE_SCALES` (float32, shape ``(num_envs, 6)``); a policy
  trained on it takes SI states through :class:`~stringstab.hcfs.policy.ScaledPolicy`;
* action: the target acceleration a_k ∈ [a_min, a_max] (shape ``(num_envs, 1)``);
* reward: eqs 4-6 at the state the action leads to (:func:`~stringstab.hcfs.mdp.reward`),
  the jerk measured from the follower's previous action;
* dynamics: the §IV kinematics with the 5 ms V2V delay, as in
  :func:`~stringstab.hcfs.simulate.simulate_hcfs`;
* episodes: a window of ``episode_seconds`` drawn at random from a random leader, started in
  equilibrium (gap h, the leader's speed, a = 0); it is *truncated* at the window's end.  It
  never *terminates*: the HCFS reward has no spacing or collision term, and with rewards ≤ 0 an
  episode ended by a collision would reward colliding.  Collisions are reported in
  ``info["collision"]``.

Autoreset is *same-step* (``metadata["autoreset_mode"] == AutoresetMode.SAME_STEP``): rows
whose episode ended in a step are reset at once, their last observation is in
``info["final_obs"]`` (NaN elsewhere, mask ``info["_final_obs"]``) and their episode return in
``info["episode_return"]`` (NaN elsewhere), as :mod:`stringstab.rl` expects.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from ..errors import StringStabError
from ..params import positive
from ..traffic.dynamics import Platoon
from ..traffic.limits import Limits
from ..traffic.trajectory import Trajectory
from .constants import (
    ACCEL_MAX,
    ACCEL_MIN,
    DT,
    LENGTH,
    OMEGA_1,
    OMEGA_2,
    SPACING,
    SPEED_MAX,
    TRAINING_FOLLOWERS,
    V2V_DELAY,
)
from .leaders import training_leader
from .mdp import STATE_SCALES, reward, state
from .policy import rate_limit

__all__ = ["HCFSVectorEnv", "default_training_leaders"]

Array = npt.NDArray[np.float64]
Obs = npt.NDArray[np.float32]


def default_training_leaders(*, dt: float = DT) -> list[Trajectory]:
    """The paper's training leader as far as the bundled data allows, at step ``dt``.

    UDDS at half speed from 600 s to the end (HCFS §IV;
    :func:`stringstab.hcfs.leaders.training_leader`).

    Parameters
    ----------
    dt : float
        Frame length T, s.

    Returns
    -------
    list of Trajectory
        One leader.
    """
    return [training_leader(dt=dt)]


class HCFSVectorEnv(VectorEnv[Obs, Obs, npt.NDArray[Any]]):
    """Followers of ``num_platoons`` platoons as sub-environments (see the module docstring).

    Parameters
    ----------
    num_platoons : int
        Platoons stepped together.
    leaders : sequence of Trajectory, optional
        Leaders to draw episode windows from (one step T); default
        :func:`default_training_leaders`.
    n_followers : int
        Followers per platoon (§IV: 6).
    episode_seconds : float
        Length of an episode window, s (a shorter leader is used whole).
    jerk_limit : float, optional
        Rate-limit actions to J T about the previous action, as inside HCFS (default: none).
    delay, length, spacing : float
        V2V delay (s), L and h (m).
    accel_min, accel_max, speed_max : float
        Bounds.
    omega_1, omega_2 : float
        Reward weights (eqs 4-5).
    scales : sequence of 6 floats
        Observation divisors.

    Examples
    --------
    >>> from stringstab.traffic import stop_and_go
    >>> env = HCFSVectorEnv(2, [stop_and_go(dt=0.2)], n_followers=3, episode_seconds=2.0)
    >>> obs, _ = env.reset(seed=0)
    >>> obs.shape, env.single_action_space.shape
    ((6, 6), (1,))
    >>> for _ in range(10):
    ...     obs, r, term, trunc, info = env.step(np.zeros((6, 1)))
    >>> bool(trunc.any()), int(info["_final_obs"].sum())
    (True, 6)
    """

    metadata: dict[str, Any] = {"autoreset_mode": AutoresetMode.SAME_STEP}  # noqa: RUF012

    def __init__(self, num_platoons: int = 4, leaders: Sequence[Trajectory] | None = None, *,
                 n_followers: int = TRAINING_FOLLOWERS, episode_seconds: float = 60.0,
                 jerk_limit: float | None = None, delay: float = V2V_DELAY,
                 length: float = LENGTH, spacing: float = SPACING,
                 accel_min: float = ACCEL_MIN, accel_max: float = ACCEL_MAX,
                 speed_max: float = SPEED_MAX, omega_1: float = OMEGA_1,
                 omega_2: float = OMEGA_2, scales: Sequence[float] = STATE_SCALES) -> None:
        P, N = int(num_platoons), int(n_followers)
        if P < 1 or N < 1:
            raise StringStabError(f"num_platoons and n_followers must be >= 1; got {num_platoons!r}, {n_followers!r}")
        trs = list(leaders) if leaders is not None else default_training_leaders()
        if not trs:
            raise StringStabError("the environment needs at least one leader trajectory")
        dts = {float(tr.dt) for tr in trs}
        if len(dts) != 1:
            raise StringStabError(f"all leaders must share one step T; got {sorted(dts)}")
        self.dt = dts.pop()
        self.leader_names = tuple(tr.name for tr in trs)
        self.P, self.N = P, N
        self.num_envs = P * N
        self.window = max(2, round(positive("episode_seconds", episode_seconds, unit=" s") / self.dt) + 1)
        self.step_limit = None if jerk_limit is None else positive("jerk_limit", jerk_limit) * self.dt
        self.delay = positive("delay", delay, allow_zero=True, unit=" s")
        self.length, self.spacing = float(length), float(spacing)
        self.accel_min, self.accel_max = float(accel_min), float(accel_max)
        self.weights = {"omega_1": float(omega_1), "omega_2": float(omega_2),
                        "speed_max": float(speed_max), "accel_max": float(accel_max)}
        self.scales = np.asarray(scales, dtype=np.float64)
        if self.scales.shape != (6,) or not (self.scales > 0).all():
            raise StringStabError(f"scales must be 6 numbers > 0; got {scales!r}")
        self.lengths = np.array([tr.n_steps for tr in trs])
        T = int(self.lengths.max())
        self.LX, self.LV, self.LA = (np.zeros((len(trs), T)) for _ in range(3))
        for j, tr in enumerate(trs):
            m = tr.n_steps
            self.LX[j, :m], self.LV[j, :m], self.LA[j, :m] = tr.position, tr.speed, tr.accel
        self.platoon = Platoon(P, N, dt=self.dt, model="kinematic", delta=0.0, length=self.length,
                               limits=Limits(accel_min=self.accel_min, accel_max=self.accel_max,
                                             speed_min=0.0, speed_max=float(speed_max)))
        self.which = np.zeros(P, dtype=np.int64)
        self.offset = np.zeros(P, dtype=np.int64)
        self.k = np.zeros(P, dtype=np.int64)
        self.stop = np.zeros(P, dtype=np.int64)
        self.prev_action = np.zeros((P, N))
        self.ret = np.zeros((P, N))
        self._started = False
        self.single_observation_space = spaces.Box(-np.inf, np.inf, shape=(6,), dtype=np.float32)
        self.single_action_space = spaces.Box(self.accel_min, self.accel_max, shape=(1,), dtype=np.float32)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)

    def _leader(self, shift: int = 0) -> tuple[Array, Array, Array]:
        idx = np.maximum(self.offset + self.k + shift, self.offset)
        return self.LX[self.which, idx], self.LV[self.which, idx], self.LA[self.which, idx]

    def _reset_rows(self, rows: npt.NDArray[np.int64]) -> None:
        n = rows.size
        which = self.np_random.integers(len(self.lengths), size=n)
        span = np.minimum(self.window, self.lengths[which])
        off = np.floor(self.np_random.random(n) * (self.lengths[which] - span + 1)).astype(np.int64)
        self.which[rows], self.offset[rows], self.k[rows] = which, off, 0
        self.stop[rows] = span - 1
        self.prev_action[rows] = 0.0
        self.ret[rows] = 0.0
        x, v, a = self.LX[which, off], self.LV[which, off], self.LA[which, off]
        self.platoon.reset(x, v, a, gap=self.spacing, speed=v[:, None], accel=0.0, rows=rows)

    def _observe(self) -> tuple[Obs, Array]:
        x, v, a = self._leader()
        obs = self.platoon.observe(x, v, a)
        last = self.platoon.accel.copy()
        last[:, 0] = self._leader(-1)[2]
        s = state(self.platoon.position, self.platoon.speed, last, delay=self.delay,
                  length=self.length, spacing=self.spacing)
        return (s / self.scales).reshape(self.num_envs, 6).astype(np.float32), obs.gap

    def reset(self, *, seed: int | None = None,
              options: dict[str, Any] | None = None) -> tuple[Obs, dict[str, Any]]:
        """Start every platoon on a new window; returns observations ``(num_envs, 6)``.

        Parameters
        ----------
        seed : int, optional
            Seeds the RNG that draws leaders and windows.
        options : dict, optional
            Ignored.

        Returns
        -------
        obs : ndarray (num_envs, 6), float32
            The scaled eq-3 state of every follower (divided by :data:`STATE_SCALES`).
        info : dict
            ``{"leader_index": array (num_envs,)}``: each row's leader.
        """
        super().reset(seed=seed)
        self._reset_rows(np.arange(self.P))
        self._started = True
        obs, _ = self._observe()
        return obs, {"leader_index": np.repeat(self.which, self.N)}

    def step(self, actions: npt.ArrayLike) -> tuple[Obs, Array, npt.NDArray[np.bool_],
                                                   npt.NDArray[np.bool_], dict[str, Any]]:
        """Apply one acceleration per row; see the module docstring for the returns.

        Parameters
        ----------
        actions : array_like, ``num_envs`` values
            Target accelerations a_k, m/s²; clipped to [a_min, a_max] (then to the previous
            action ± J T when a step limit is set).

        Returns
        -------
        obs : ndarray (num_envs, 6), float32
            The next scaled eq-3 states (a finished platoon's rows: the first state of its next
            window).
        reward : ndarray (num_envs,)
            r = r_v + r_jerk (HCFS eqs 4-6).
        terminated : bool ndarray (num_envs,)
            Always False (episodes never terminate).
        truncated : bool ndarray (num_envs,)
            True for every row of a platoon whose window ended.
        info : dict
            ``r_v``, ``r_jerk``, ``speed_error`` (e_v(k,0), m/s), ``gap`` (m), ``collision``,
            ``action`` (applied, m/s²), ``final_obs``/``_final_obs`` and ``episode_return``.

        Raises
        ------
        StringStabError
            If :meth:`reset` was not called first, or ``actions`` does not have ``num_envs``
            values.
        """
        if not self._started:
            raise StringStabError("call reset() before step()")
        a = np.asarray(actions, dtype=np.float64)
        if a.size != self.num_envs:
            raise StringStabError(f"actions must have one value per sub-environment ({self.num_envs}); got shape {a.shape}")
        a = np.clip(a.reshape(self.P, self.N), self.accel_min, self.accel_max)
        if self.step_limit is not None:
            a = rate_limit(a, self.prev_action, self.step_limit, accel_min=self.accel_min,
                           accel_max=self.accel_max)
        self.platoon.advance(a)
        self.k += 1
        obs, gap = self._observe()
        ev = self.platoon.speed[:, 1:] - self.platoon.speed[:, :1]
        r, r_v, r_j = reward(ev, a, self.prev_action, dt=self.dt, **self.weights)
        self.prev_action = a
        self.ret += r
        done_p = self.k >= self.stop
        done = np.repeat(done_p, self.N)
        terminated = np.zeros(self.num_envs, dtype=bool)
        info: dict[str, Any] = {
            "r_v": r_v.ravel(), "r_jerk": r_j.ravel(), "speed_error": ev.ravel(),
            "gap": gap.ravel().copy(), "collision": (gap <= 0).ravel(), "action": a.ravel().copy(),
            "final_obs": np.full((self.num_envs, 6), np.nan, dtype=np.float32),
            "_final_obs": done.copy(),
            "episode_return": np.where(done, self.ret.ravel(), np.nan),
        }
        if done_p.any():
            info["final_obs"][done] = obs[done]
            self._reset_rows(np.flatnonzero(done_p))
            obs, _ = self._observe()
        return obs, np.asarray(r, dtype=np.float64).ravel(), terminated, done, info
