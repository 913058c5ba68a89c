"""HCFS: the hybrid DDPG/CACC car-following strategy and a numerical check of its jerk theorem.

The HCFS paper (IEEE T-ASE 2021) switches every frame between a DDPG action and a CACC action
by comparing their rewards (eq 12), softened by β (eqs 13-14), and proves that the hybrid
output changes by less than jerk·T per frame whenever each controller does and
a1_{k−1} = a2_{k−1}.  This subpackage states that theorem as a checkable statement, proves and
checks the bound that holds without the last premise, and verifies both in closed loop.

* :mod:`~stringstab.hcfs.constants` — the paper's constants and the choices where its tables
  are lost;
* :mod:`~stringstab.hcfs.mdp` — the V2V-delayed measurements, the state (eq 3), the reward
  (eqs 4-6);
* :mod:`~stringstab.hcfs.cacc` — the CACC law (eq 11): printed, meant, used;
* :mod:`~stringstab.hcfs.policy` — the acceleration-policy seam, the rate limiter, a stand-in;
* :mod:`~stringstab.hcfs.switching` — eq 12 with its one-step prediction, eqs 13-14, the
  jerk-safe variant;
* :mod:`~stringstab.hcfs.theorem` — premises, conclusion, the bound, a tight example;
* :mod:`~stringstab.hcfs.simulate` — the closed loop of §IV;
* :mod:`~stringstab.hcfs.verify` — the closed-loop verification;
* :mod:`~stringstab.hcfs.report`, :mod:`~stringstab.hcfs.plots` — the report and Figs 4-6;
* :mod:`~stringstab.hcfs.leaders` — the paper's training leader and test cases, as far as the
  bundled data allows (UDDS at half speed);
* :mod:`~stringstab.hcfs.env`, :mod:`~stringstab.hcfs.ddpg` — the training environment, the
  DDPG trained through :mod:`stringstab.rl`, and the one bundled with the package;
* :mod:`~stringstab.hcfs.compare` — CACC alone, the DDPG alone and HCFS side by side (the
  paper's Tables IV-VI).

See ``docs/hcfs.md``.
"""

from __future__ import annotations

from .cacc import CACC, cacc_acceleration, cacc_printed, closed_loop_matrix
from .compare import compare_controllers, comparison_markdown
from .constants import (
    ACCEL_MAX,
    ACCEL_MIN,
    BETA,
    CACC_GAINS,
    DT,
    LENGTH,
    OMEGA_1,
    OMEGA_2,
    PAPER_JERK_LIMIT,
    PLATOON_SIZES,
    SPACING,
    SPEED_MAX,
    TRAINING_FOLLOWERS,
    V2V_DELAY,
    reward_weights_from_table_iv,
)
from .ddpg import (
    HCFSTraining,
    bundled_policy_dir,
    candidate,
    load_bundled_ddpg,
    load_ddpg,
    save_ddpg,
    train_ddpg,
    train_hcfs_ddpg,
)
from .env import HCFSVectorEnv, default_training_leaders
from .leaders import CASES, case_leader, half_speed, hcfs_leader, paper_cases, training_leader
from .mdp import STATE_NAMES, STATE_SCALES, received, reward, state
from .plots import plot_figure, plot_jerk, plot_learning, plot_speed, plot_switching
from .policy import (
    AccelerationPolicy,
    LeaderSpeedMatcher,
    ScaledPolicy,
    accelerations,
    policy_label,
    rate_limit,
)
from .report import report_dict, report_markdown, write_report
from .simulate import MODES, HCFSRun, RunConfig, simulate_hcfs
from .switching import (
    RULES,
    check_beta,
    choose,
    limit_step,
    predicted_lead_speed,
    predicted_rewards,
    step_weight,
    switch_weights,
)
from .theorem import (
    DEFAULT_TOL,
    LatticeSearch,
    TheoremCheck,
    check_jerk_limit,
    check_theorem,
    jerk_bound,
    lattice_search,
    tight_example,
    weight_change,
)
from .verify import Frame, Verification, verify

__all__ = [
    "ACCEL_MAX",
    "ACCEL_MIN",
    "BETA",
    "CACC",
    "CACC_GAINS",
    "CASES",
    "DEFAULT_TOL",
    "DT",
    "LENGTH",
    "MODES",
    "OMEGA_1",
    "OMEGA_2",
    "PAPER_JERK_LIMIT",
    "PLATOON_SIZES",
    "RULES",
    "SPACING",
    "SPEED_MAX",
    "STATE_NAMES",
    "STATE_SCALES",
    "TRAINING_FOLLOWERS",
    "V2V_DELAY",
    "AccelerationPolicy",
    "Frame",
    "HCFSRun",
    "HCFSTraining",
    "HCFSVectorEnv",
    "LatticeSearch",
    "LeaderSpeedMatcher",
    "RunConfig",
    "ScaledPolicy",
    "TheoremCheck",
    "Verification",
    "accelerations",
    "bundled_policy_dir",
    "cacc_acceleration",
    "cacc_printed",
    "candidate",
    "case_leader",
    "check_beta",
    "check_jerk_limit",
    "check_theorem",
    "choose",
    "closed_loop_matrix",
    "compare_controllers",
    "comparison_markdown",
    "default_training_leaders",
    "half_speed",
    "hcfs_leader",
    "jerk_bound",
    "lattice_search",
    "limit_step",
    "load_bundled_ddpg",
    "load_ddpg",
    "paper_cases",
    "plot_figure",
    "plot_jerk",
    "plot_learning",
    "plot_speed",
    "plot_switching",
    "policy_label",
    "predicted_lead_speed",
    "predicted_rewards",
    "rate_limit",
    "received",
    "report_dict",
    "report_markdown",
    "reward",
    "reward_weights_from_table_iv",
    "save_ddpg",
    "simulate_hcfs",
    "state",
    "step_weight",
    "switch_weights",
    "tight_example",
    "train_ddpg",
    "train_hcfs_ddpg",
    "training_leader",
    "verify",
    "weight_change",
    "write_report",
]
