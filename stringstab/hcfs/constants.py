"""The HCFS paper's constants, in one place, each with its source or the reason for the choice.

The HCFS paper (*Hybrid Car-Following Strategy Based on Deep Deterministic Policy Gradient and
Cooperative Adaptive Cruise Control*, IEEE T-ASE 2021) prints its parameters in Tables I-III,
which are lost in the text we have.  What survives in the text is used as printed; the rest is
chosen here, and the reason is given next to each value.

Printed in the text (§II, §IV)
    ``DT`` = 0.2 s (§IV "the time step selected is 0.2 s"); ``V2V_DELAY`` = 5 ms (§IV);
    ``ACCEL_MAX`` = 3 m/s², from "all jerks are smaller than 2a_max/T = 30" (§IV-A) with
    T = 0.2 s; ``PLATOON_SIZES`` = (4, 6, 8) followers (cases 3, 2, 1) and
    ``TRAINING_FOLLOWERS`` = 6 (§IV); β = 0.5 at a switch (eq 14).

Chosen (Tables I-III lost)
    * ``ACCEL_MIN`` = −3 m/s²: the jerk normalisation 2a_max/T of eq 5 is the largest possible
      one-step change only if the action range is [−a_max, a_max].
    * ``SPEED_MAX`` = 33.3 m/s: the toolkit's road speed limit (IDL paper Table 2); it caps the
      followers' speed and normalises the speed error of eq 4.
    * ``OMEGA_1``, ``OMEGA_2``: eqs 4-6 give the reward sum as
      (ω1/v_max)·Σ|e_v| + (ω2·T/(2a_max))·Σ|Δa/T|.  Table IV of the paper reports, for case 1,
      Σ|e_v| = 159.39 / 146.22 / 25.26 m/s, Σ|jerk| = 720.06 / 2344.60 / 192.19 m/s³ and
      Σr = −59.70 / −56.81 / −9.64 for CACC / DDPG / HCFS.  The CACC and DDPG rows fix
      ω1/v_max = 0.3691 s/m and ω2/(2a_max/T) = 0.001213 s³/m; the HCFS row, not used in the
      fit, is then predicted as −9.556 against the printed −9.64 (0.9 % off), so the three rows
      are consistent with one pair of weights.  With v_max = 33.3 m/s this is ω1 = 12.29 and
      ω2 = 0.0364 (:func:`reward_weights_from_table_iv` recomputes them).
    * ``CACC_GAINS`` (k1, k2, k3, k4) = (0.1, 0.4, 0.05, 0.2) of the derived eq-11 law
      (:mod:`stringstab.hcfs.cacc`): with T = 0.2 s this is a = 0.5 e_x + 2 e_v + 0.25 e_x0 +
      1.0 e_v0 (s⁻², s⁻¹); the discrete closed loop of 8 followers has spectral radius 0.947
      (internally stable), and on the bundled cycles the spacing errors shrink along the
      platoon (tested in ``tests/hcfs/test_hcfs_model.py``).
    * ``LENGTH`` = 5 m (the toolkit's vehicle length) and ``SPACING`` h = 5 m: eq 1's "vehicle
      length L plus safe space headway h" is a constant-spacing policy; with leader information
      (eq 11's k3, k4 terms) constant spacing can be string stable.
"""

from __future__ import annotations

import numpy as np

from .. import constants as _toolkit
from ..traffic.limits import DEFAULT_LENGTH

__all__ = [
    "ACCEL_MAX",
    "ACCEL_MIN",
    "BETA",
    "CACC_GAINS",
    "DT",
    "LENGTH",
    "OMEGA_1",
    "OMEGA_2",
    "PAPER_JERK_LIMIT",
    "PLATOON_SIZES",
    "SPACING",
    "SPEED_MAX",
    "TRAINING_FOLLOWERS",
    "V2V_DELAY",
    "reward_weights_from_table_iv",
]

#: Time step T, s (HCFS §IV).
DT = 0.2
#: V2V communication delay between adjacent vehicles, s (HCFS §IV).
V2V_DELAY = 0.005
#: a_max, m/s² (HCFS §IV-A: 2a_max/T = 30 with T = 0.2 s).
ACCEL_MAX = 3.0
#: a_min, m/s² (chosen: −a_max, see the module docstring).
ACCEL_MIN = -3.0
#: v_max, m/s (chosen: the toolkit's road speed limit, IDL Table 2).
SPEED_MAX = _toolkit.SPEED_MAX
#: The jerk threshold the paper's figures compare with, 2a_max/T = 30 m/s³ (HCFS §IV-A).
PAPER_JERK_LIMIT = 2.0 * ACCEL_MAX / DT
#: Soft-switch coefficient at a switch (HCFS eq 14).
BETA = 0.5
#: Platoon sizes of the paper's cases 3, 2, 1 (HCFS §IV).
PLATOON_SIZES = (4, 6, 8)
#: Followers in the DDPG training platoon (HCFS §IV).
TRAINING_FOLLOWERS = 6
#: Vehicle length L, m (chosen: the toolkit's vehicle length).
LENGTH = DEFAULT_LENGTH
#: Safe space headway h, m: the desired bumper-to-bumper gap (chosen).
SPACING = 5.0
#: Gains k1-k4 of the derived eq-11 CACC law (chosen, Table I lost).
CACC_GAINS = (0.1, 0.4, 0.05, 0.2)

_TABLE_IV = {  # case 1: (Σ|e_v| m/s, Σ|jerk| m/s³, Σ reward)
    "CACC": (159.39, 720.06, -59.70),
    "DDPG": (146.22, 2344.60, -56.81),
    "HCFS": (25.26, 192.19, -9.64),
}


def reward_weights_from_table_iv(*, speed_max: float = SPEED_MAX, accel_max: float = ACCEL_MAX,
                                 dt: float = DT) -> dict[str, float]:
    """ω1 and ω2 of eqs 4-6 that reproduce the CACC and DDPG rows of the paper's Table IV.

    Solves (ω1/v_max)·Σ|e_v| + (ω2·T/(2a_max))·Σ|jerk| = −Σr for the two rows, then predicts
    the HCFS row as a consistency check.

    Parameters
    ----------
    speed_max : float
        v_max of eq 4's normalisation, m/s.
    accel_max : float
        a_max of eq 5's jerk normalisation 2a_max/T, m/s².
    dt : float
        Frame length T, s.

    Returns
    -------
    dict
        ``omega_1``, ``omega_2`` and ``hcfs_predicted``/``hcfs_printed`` (Σr of HCFS).

    References
    ----------
    HCFS paper, eqs 4-6 and Table IV (case 1).

    Examples
    --------
    >>> w = reward_weights_from_table_iv()
    >>> round(w["omega_1"], 2), round(w["omega_2"], 4), round(w["hcfs_predicted"], 3)
    (12.29, 0.0364, -9.556)
    """
    rows = np.array([_TABLE_IV["CACC"][:2], _TABLE_IV["DDPG"][:2]])
    rhs = -np.array([_TABLE_IV["CACC"][2], _TABLE_IV["DDPG"][2]])
    a, b = np.linalg.solve(rows, rhs)
    pred = -(a * _TABLE_IV["HCFS"][0] + b * _TABLE_IV["HCFS"][1])
    return {"omega_1": float(a * speed_max), "omega_2": float(b * 2.0 * accel_max / dt),
            "hcfs_predicted": float(pred), "hcfs_printed": _TABLE_IV["HCFS"][2]}


#: ω1 of eq 4 (chosen from Table IV, see :func:`reward_weights_from_table_iv`).
OMEGA_1 = 12.29
#: ω2 of eq 5 (chosen from Table IV, see :func:`reward_weights_from_table_iv`).
OMEGA_2 = 0.0364
