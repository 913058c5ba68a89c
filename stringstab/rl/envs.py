"""The training environments of a config: the car-following env, wrapped in the repair for gains.

:func:`make_env` is CleanRL's ``make_env``: the one place a config becomes the vector
environment the training loop steps (:func:`~stringstab.rl.train.train` sees only ``envs``).
For IDL gain actions the environment is wrapped in :class:`RepairedGains`, the action wrapper
that turns the policy's *proposed* gains into the gains the vehicle *executes*:

1. clip to the gain box (Table 2: [−2, 2]³);
2. with ``gain_rate`` r > 0 (not in the paper), clip each gain to within r of the gain executed
   at the previous step (:func:`~stringstab.traffic.rate.limit_rate`; an episode's first step
   is not limited);
3. repair (§3.3, :class:`~stringstab.tuning.repair.GainRepair`), so every executed triple is
   certified.

The order matters: the rate limit keeps the gains near the previous (certified) triple, and the
repair acts last, so what is executed is certified even when the limit alone would not be.
The rate limit needs the gains executed at the previous step and where episodes start; the
wrapped environment keeps both (it observes the previous gains and saves them in its
checkpoints) and exposes them (:attr:`~stringstab.traffic.env.BatchedCarFollowingEnv.prev_gains`,
:attr:`~stringstab.traffic.env.BatchedCarFollowingEnv.first_step`), so the wrapper holds no
state of its own.  Acceleration actions (pure TD3/DDPG) get the environment unwrapped.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
from gymnasium.vector import VectorActionWrapper, VectorEnv, VectorWrapper

from ..errors import StringStabError, show
from ..traffic.env import BatchedCarFollowingEnv
from ..traffic.rate import limit_rate
from ..tuning.repair import GainRepair
from .config import TD3Config
from .repair import repair_for

__all__ = ["RepairedGains", "executed_gains", "make_env", "repair_of"]

Array = npt.NDArray[np.float64]


def executed_gains(proposed: npt.ArrayLike, repair: GainRepair, *,
                   prev_gains: npt.ArrayLike | None = None,
                   fresh: npt.ArrayLike | bool = False, gain_rate: float = 0.0) -> Array:
    """The gains executed for proposed ones: clip to the box, rate limit, repair (module docstring).

    The one map from a gain policy's proposal to what the eq-4 law executes, used by
    :class:`RepairedGains` in training and by
    :meth:`~stringstab.rl.policy.Policy.step_gains` in evaluation.

    Parameters
    ----------
    proposed : array_like (n, 3)
        The proposed gains (k_x, k_v, k_a) of eq 4 (the policy's action, eq 17).
    repair : GainRepair
        The repair (§3.3); its gain box is the one clipped to.
    prev_gains : array_like (n, 3), optional
        The gains executed at the previous step; None: no rate limit (an episode's first step).
    fresh : array_like of bool (n,), or bool
        True where an episode takes its first step (those rows are not rate limited).
    gain_rate : float
        Largest change r of each gain per step (0: no limit).

    Returns
    -------
    ndarray (n, 3)
        The executed gains, each certified by the repair (unless it is ``"off"``).
    """
    K = np.clip(np.asarray(proposed, dtype=np.float64).reshape(-1, 3), *repair.bounds)
    if gain_rate > 0 and prev_gains is not None:
        K = limit_rate(K, prev_gains, gain_rate, fresh=fresh)
    return np.asarray(repair(K), dtype=np.float64)


class RepairedGains(VectorActionWrapper):
    """Proposed gains → executed gains: clip, rate limit, repair (module docstring).

    Parameters
    ----------
    env : BatchedCarFollowingEnv or a vector wrapper of one
        A car-following environment with gain actions; its gain box must be the repair's.
    repair : GainRepair
        The repair (§3.3); ``GainRepair("off", ...)`` for the ablation.
    gain_rate : float
        Largest change r of each gain per control step (gain units; 0: no limit).

    Attributes
    ----------
    repair : GainRepair
        The repair, with its statistics (``repair.stats``: calls, rows, repaired, seconds).
    gain_rate : float
        The rate limit r.

    Raises
    ------
    StringStabError
        If ``env`` is not a car-following environment with gain actions, its gain box differs
        from the repair's, or ``gain_rate`` is not a number >= 0.

    Examples
    --------
    >>> from stringstab.traffic import BatchedCarFollowingEnv, paper_mix
    >>> rep = GainRepair(tau=0.1, delta=0.2, headway=1.1, resolution=0.25)
    >>> envs = RepairedGains(BatchedCarFollowingEnv(2, [paper_mix()]), rep, gain_rate=0.05)
    >>> _ = envs.reset(seed=0)
    >>> _, _, _, _, info = envs.step(np.array([[1.2, 0.5, 0.6], [0.9, -0.5, 1.1]]))
    >>> info["gains"][0].tolist(), bool((info["gains"][1] != [0.9, -0.5, 1.1]).any())
    ([1.2, 0.5, 0.6], True)
    """

    def __init__(self, env: VectorEnv, repair: GainRepair, *, gain_rate: float = 0.0) -> None:
        super().__init__(env)
        base = env.unwrapped
        if not isinstance(base, BatchedCarFollowingEnv) or base.action_mode != "gains":
            raise StringStabError("RepairedGains: expected a BatchedCarFollowingEnv with gain "
                                  f"actions; got {type(base).__name__}")
        if tuple(base.gain_bounds) != tuple(repair.bounds):
            raise StringStabError(f"RepairedGains: the repair's gain box {list(repair.bounds)} "
                                  f"must be the environment's; found {list(base.gain_bounds)}")
        if isinstance(gain_rate, bool) or not isinstance(gain_rate, (int, float)) \
                or not (np.isfinite(gain_rate) and gain_rate >= 0):
            raise StringStabError(f"gain_rate must be a number >= 0; got {show(gain_rate)}")
        self._base = base
        self.repair = repair
        self.gain_rate = float(gain_rate)

    def actions(self, actions: npt.ArrayLike) -> Array:
        """The executed gains ``(num_envs, 3)`` for proposed gains ``actions``.

        Parameters
        ----------
        actions : array_like (num_envs, 3)
            The proposed gains (k_x, k_v, k_a) of eq 4, one row per sub-environment (eq 17).

        Returns
        -------
        ndarray (num_envs, 3)
            Clipped to the gain box, rate limited (``gain_rate``) and repaired.

        Raises
        ------
        StringStabError
            If ``actions`` is not one triple per sub-environment.
        """
        n = self._base.num_envs
        a = np.asarray(actions, dtype=np.float64)
        if a.size != 3 * n:
            raise StringStabError(f"gain actions must be (k_x, k_v, k_a) per env; got shape {a.shape}")
        return executed_gains(a.reshape(n, 3), self.repair, prev_gains=self._base.prev_gains,
                              fresh=self._base.first_step, gain_rate=self.gain_rate)

    def state_dict(self) -> tuple[dict[str, Any], dict[str, npt.NDArray[Any]]]:
        """The wrapped environment's state (the wrapper has none).

        See :meth:`~stringstab.traffic.env.BatchedCarFollowingEnv.state_dict`.

        Returns
        -------
        meta : dict
            JSON-ready counters and the RNG state.
        arrays : dict of str to ndarray
            The environment's arrays (previous executed gains included).
        """
        return self._base.state_dict()

    def load_state_dict(self, meta: dict[str, Any], arrays: dict[str, npt.NDArray[Any]]) -> None:
        """Restore :meth:`state_dict` output into the wrapped environment.

        Parameters
        ----------
        meta : dict
            The JSON-ready part of :meth:`state_dict`.
        arrays : dict of str to ndarray
            The arrays of :meth:`state_dict`.
        """
        self._base.load_state_dict(meta, arrays)


def repair_of(envs: VectorEnv) -> GainRepair | None:
    """The repair of a :class:`RepairedGains` in the wrapper stack ``envs``, or None.

    Parameters
    ----------
    envs : gymnasium VectorEnv
        The training environments, possibly wrapped.

    Returns
    -------
    GainRepair or None
        The outermost :class:`RepairedGains`'s repair; None when there is none (acceleration
        actions, or a custom environment).
    """
    e: Any = envs
    while isinstance(e, VectorWrapper):
        if isinstance(e, RepairedGains):
            return e.repair
        e = e.env
    return None


def make_env(config: TD3Config, leaders: list[Any] | None = None) -> VectorEnv:
    """The training environments of ``config`` (CleanRL's ``make_env``).

    Parameters
    ----------
    config : TD3Config
        Supplies the number of environments, action mode, τ, δ, T*, gain bounds, reward
        weights (eq 18) and TTC* (eq 20), ``observe``, the start spread, the reaction delay
        θ_r, the radio and the sensors (issues 25, 26), and for gain actions the repair
        (:func:`~stringstab.rl.repair.repair_for`, certifying at θ_r) and ``gain_rate``.
    leaders : list, optional
        The training leaders (trajectories or following pairs); default the bundled training
        episodes (:func:`~stringstab.rl.episodes.default_leaders`).

    Returns
    -------
    gymnasium VectorEnv
        A :class:`~stringstab.traffic.env.BatchedCarFollowingEnv`, wrapped in
        :class:`RepairedGains` for gain actions.
    """
    from .episodes import default_leaders

    if leaders is None:
        leaders = list(default_leaders("train", seconds=config.episode_seconds, dt=config.dt))
    env = BatchedCarFollowingEnv(config.num_envs, leaders, action=config.action, tau=config.tau,
                                 delta=config.delta, headway=config.headway,
                                 gain_bounds=config.gain_bounds, weights=config.weights,
                                 terminate_on_collision=True, ttc_star=config.reward_ttc_star,
                                 observe=config.observe, start_spread=config.start_spread,
                                 reaction_delay=config.reaction_delay, radio=config.radio,
                                 sensors=config.sensors)
    repair = repair_for(config)
    if repair is None:
        return env
    return RepairedGains(env, repair, gain_rate=config.gain_rate)
