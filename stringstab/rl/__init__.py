"""A compact TD3/DDPG trainer whose IDL policy emits certified gains (CleanRL's shape, importable).

* :mod:`~stringstab.rl.config` — :class:`TD3Config`, :class:`DDPGConfig` (IDL Table 1 defaults),
  :func:`config_for` ("idl", "td3", "ddpg");
* :mod:`~stringstab.rl.episodes` — training and test leaders;
* :mod:`~stringstab.rl.repair` — :func:`~stringstab.rl.repair.repair_for`, the one way to rebuild
  the §3.3 repair (:class:`stringstab.tuning.repair.GainRepair`, the certified lookup, which lives
  in :mod:`stringstab.tuning`) from a config or policy;
* :mod:`~stringstab.rl.envs` — :func:`~stringstab.rl.envs.make_env` (the training environments
  of a config) and :class:`~stringstab.rl.envs.RepairedGains`, the action wrapper that rate
  limits and repairs the proposed gains;
* :mod:`~stringstab.rl.networks`, :mod:`~stringstab.rl.buffer`, :mod:`~stringstab.rl.agent` —
  actor/critics, replay memory, the TD3 and DDPG update rules;
* :mod:`~stringstab.rl.train` — :func:`train` → :class:`TrainResult`;
* :mod:`~stringstab.rl.checkpoint`, :mod:`~stringstab.rl.policy` — safe checkpoints,
  :class:`Policy`, :func:`load_policy`;
* :mod:`~stringstab.rl.evaluate`, :mod:`~stringstab.rl.compare`, :mod:`~stringstab.rl.plots` —
  held-out evaluation, the Table-4 comparison and the paper's figures.

torch (the ``rl`` extra) is imported only by the modules that need it, so this package and its
configuration import without it (calling :func:`train` or :func:`load_policy` needs it).
"""

from __future__ import annotations

from .config import ALGOS, REPAIRS, DDPGConfig, TD3Config, config_for, config_from_dict
from .policy import Policy, load_policy
from .train import TrainResult, train

__all__ = [
    "ALGOS",
    "REPAIRS",
    "DDPGConfig",
    "Policy",
    "TD3Config",
    "TrainResult",
    "config_for",
    "config_from_dict",
    "load_policy",
    "train",
]
