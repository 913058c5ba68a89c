"""The traffic simulator: leaders, platoon dynamics, controllers and Gymnasium environments.

* leaders: :mod:`~stringstab.traffic.trajectory` (the trajectory type),
  :mod:`~stringstab.traffic.cycles` (driving cycles), :mod:`~stringstab.traffic.synthetic`
  (synthetic profiles), :mod:`~stringstab.traffic.loaders` (CSV files, NGSIM pairs),
  :mod:`~stringstab.traffic.split` (a train/test split), and
  :mod:`~stringstab.traffic.leaders` (a leader by name from a command-line spec);
* platoons: :mod:`~stringstab.traffic.limits` (acceleration and speed bounds, the leader
  check, the vehicle length), :mod:`~stringstab.traffic.dynamics` (the vectorised stepping
  core, IDL eqs 1-2, 5-7), :mod:`~stringstab.traffic.platoon` (:func:`simulate`) and
  :mod:`~stringstab.traffic.result` (its :class:`PlatoonResult`);
* :mod:`~stringstab.traffic.controllers` — the eq-4 linear law, time-varying gains, CACC, IDM
  (a subpackage, one module per controller);
* the loop as it runs (issue 26): :mod:`~stringstab.traffic.radio` (V2V messages every N
  steps, held, lost, stale, the fallback to ACC), :mod:`~stringstab.traffic.loss` (Bernoulli
  and Gilbert–Elliott message loss), :mod:`~stringstab.traffic.sensors` (noise and a filter on
  gap, gap rate and speed) and :mod:`~stringstab.traffic.onboard` (a controller behind both);
* :mod:`~stringstab.traffic.metrics` — the IDL evaluation metrics;
* :mod:`~stringstab.traffic.reward` — the IDL reward (eqs 18-24);
* environments: :mod:`~stringstab.traffic.state` (the eq-16 state and its extensions),
  :mod:`~stringstab.traffic.rate` (the gain rate limit), :mod:`~stringstab.traffic.episodes`
  (the episodes both environments step) and :mod:`~stringstab.traffic.env` (a Gymnasium
  environment and a batched version for training);
* :mod:`~stringstab.traffic.output` — run files.

Their figures (like the IDL paper's Figs 7-8) are in :mod:`stringstab.plots.traffic`.
"""

from __future__ import annotations

from .controllers import (
    CACCController,
    Controller,
    FunctionController,
    IDMController,
    LinearController,
    MixedController,
    Observation,
    TimeVaryingLinearController,
    linear_law,
)
from .cycles import CYCLES, cycle
from .dynamics import Platoon
from .env import BatchedCarFollowingEnv, CarFollowingEnv
from .leaders import leader_by_name
from .limits import Limits, check_leader
from .loaders import FollowingPair, load_csv, load_ngsim_pairs
from .onboard import Onboard
from .output import RUN_FILES, run_document, save_trajectories, write_run
from .platoon import simulate
from .radio import Radio
from .result import PlatoonResult
from .reward import comfort_reward, efficiency_reward, headway_density, reward, safety_reward
from .sensors import SensorNoise
from .split import train_test_split
from .state import SCALES, state_vector
from .synthetic import SYNTHETIC, hard_acceleration, hard_braking, paper_mix, sinusoid, stop_and_go
from .trajectory import Trajectory, from_accel_segments, from_speed

__all__ = [
    "CYCLES",
    "RUN_FILES",
    "SCALES",
    "SYNTHETIC",
    "BatchedCarFollowingEnv",
    "CACCController",
    "CarFollowingEnv",
    "Controller",
    "FollowingPair",
    "FunctionController",
    "IDMController",
    "Limits",
    "LinearController",
    "MixedController",
    "Observation",
    "Onboard",
    "Platoon",
    "PlatoonResult",
    "Radio",
    "SensorNoise",
    "TimeVaryingLinearController",
    "Trajectory",
    "check_leader",
    "comfort_reward",
    "cycle",
    "efficiency_reward",
    "from_accel_segments",
    "from_speed",
    "hard_acceleration",
    "hard_braking",
    "headway_density",
    "leader_by_name",
    "linear_law",
    "load_csv",
    "load_ngsim_pairs",
    "paper_mix",
    "reward",
    "run_document",
    "safety_reward",
    "save_trajectories",
    "simulate",
    "sinusoid",
    "state_vector",
    "stop_and_go",
    "train_test_split",
    "write_run",
]
