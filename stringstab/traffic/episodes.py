"""The episodes shared by both environments: :class:`Episodes`, n leader–follower runs at once.

One :class:`~stringstab.traffic.dynamics.Platoon` of ``n`` one-follower platoons over a shared
list of leaders (trajectories, or recorded NGSIM pairs started where the human follower was):
it resets rows, observes the eq-16 state (:mod:`stringstab.traffic.state`), executes gains
through the eq-4 law (:func:`~stringstab.traffic.controllers.linear_law`) or an acceleration,
advances the dynamics and scores the step with the reward of eqs 18-24
(:mod:`stringstab.traffic.reward`).  :class:`~stringstab.traffic.env.CarFollowingEnv` (n = 1)
and :class:`~stringstab.traffic.env.BatchedCarFollowingEnv` wrap it in the Gymnasium APIs.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal, TypeGuard

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show
from .controllers.base import Observation
from .controllers.linear import linear_law
from .dynamics import Model, Platoon
from .limits import Limits
from .loaders import FollowingPair
from .metrics import time_headway, time_to_collision
from .reward import reward
from .state import extend_state, state_dim, state_vector
from .trajectory import Trajectory

__all__ = ["ActionMode", "Episodes"]

Array = npt.NDArray[np.float64]
#: ``"gains"``: the action is K of eq 17; ``"accel"``: the desired acceleration (pure RL).
ActionMode = Literal["gains", "accel"]


def _is_pair(x: Any) -> TypeGuard[FollowingPair]:
    # duck typing, as the simulator's leader check (a re-imported module defines a second class)
    return hasattr(x, "leader") and hasattr(x, "follower") and hasattr(x, "gap")


class Episodes:
    """``n`` independent leader–follower episodes over a shared list of leaders.

    The parameters are those of :class:`~stringstab.traffic.env.BatchedCarFollowingEnv`
    (``n`` is its ``num_envs``), which documents them.

    Attributes
    ----------
    platoon : Platoon
        ``n`` platoons of one follower each (column 0 the leader).
    which, k : int array (n,)
        Each row's leader index and step within its episode.
    prev_gains : array (n, 3)
        Gains executed at the previous step (zero, and not rate limited, at an episode start).
    ret : array (n,)
        Each row's return so far.
    obs : Observation or None
        The last observation (None before the first :meth:`observe`).
    """

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
        """Each row's leader state now (held at its last sample after the end).

        Returns
        -------
        position, speed, accel : array (n,)
            m, m/s, m/s².
        """
        kk = np.minimum(self.k, self.lengths[self.which] - 1)
        return self.LX[self.which, kk], self.LV[self.which, kk], self.LA[self.which, kk]

    def reset_rows(self, rows: npt.NDArray[np.int64], which: npt.NDArray[np.int64],
                   rng: np.random.Generator | None = None) -> None:
        """Start new episodes in ``rows`` over the leaders ``which``.

        A trajectory starts in equilibrium (scattered by ``start_spread`` when ``rng`` is
        given), a recorded pair where its human follower was.

        Parameters
        ----------
        rows : int array
            The rows to reset.
        which : int array, same length
            The leader index of each row.
        rng : numpy.random.Generator, optional
            Draws the start scatter (none without it).
        """
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
        """Observe the followers now (kept as :attr:`obs`).

        Returns
        -------
        Observation
            What the followers know at this step (shapes ``(n, 1)``).
        """
        self.obs = self.platoon.observe(*self.leader_now())
        return self.obs

    def state(self) -> npt.NDArray[np.float32]:
        """The policy's state of every row: eq 16 with the ``observe`` extras.

        Returns
        -------
        ndarray (n, state_dim), float32
            :func:`~stringstab.traffic.state.state_vector`, extended by
            :func:`~stringstab.traffic.state.extend_state`.
        """
        assert self.obs is not None
        s = state_vector(self.obs, headway=self.headway, standstill=self.standstill,
                         scales=self.scales)[:, 0, :]
        if self.extras:
            s = extend_state(s, observe=self.extras, accel=self.obs.accel[:, 0],
                             prev_gains=self.prev_gains, scales=self.scales)
        return s.astype(np.float32)

    def command(self, actions: npt.ArrayLike) -> tuple[Array, Array | None]:
        """The desired accelerations u of ``actions`` (gains clipped to the box, through eq 4).

        Parameters
        ----------
        actions : array_like (n, 3) or (n, 1)
            Gains K (``action="gains"``) or accelerations (``action="accel"``).

        Returns
        -------
        u : array (n, 1)
            Desired accelerations, m/s².
        gains : array (n, 3) or None
            The executed (clipped) gains; None for acceleration actions.
        """
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
        """Execute ``actions``, advance one step and score it (eqs 18-24).

        Parameters
        ----------
        actions : array_like (n, 3) or (n, 1)
            As for :meth:`command`.

        Returns
        -------
        reward : array (n,)
            The step's rewards.
        terminated, truncated : bool array (n,)
            A collision (when ``terminate_on_collision``), the leader's last sample.
        info : dict
            Gap, speed, acceleration, command, TTC, headway, reward terms, collision,
            leader index, time, and the executed gains.
        """
        u, K = self.command(actions)
        prev_accel = self.platoon.accel[:, 1].copy()
        u_lim = self.platoon.advance(u)
        self.k += 1
        o = self.observe()
        gap, spd, pspd = o.gap[:, 0], o.speed[:, 0], o.pred_speed[:, 0]
        ttc, hw = time_to_collision(gap, spd, pspd), time_headway(gap, spd)
        r, r_f, r_j, r_e = reward(gap, spd, pspd, o.accel[:, 0], prev_accel, weights=self.weights,
                                  ttc_star=self.ttc_star, ttc=ttc, headway=hw)
        collision = gap <= 0
        terminated = collision & self.terminate_on_collision
        truncated = (self.k >= self.lengths[self.which] - 1) & ~terminated
        self.ret += r
        info: dict[str, Any] = {
            "gap": gap.copy(), "speed": spd.copy(), "accel": o.accel[:, 0].copy(),
            "command": u_lim[:, 0].copy(), "ttc": ttc,
            "headway": hw, "r_f": r_f, "r_j": r_j, "r_e": r_e,
            "collision": collision, "leader_index": self.which.copy(), "t": self.k * self.dt,
        }
        if K is not None:
            info["gains"] = K
        return np.asarray(r, dtype=np.float64), terminated, truncated, info
