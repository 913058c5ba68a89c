"""The papers' constants, in one place.

Every module that needs a number printed in one of the two papers imports it from here; the
command-line defaults, the simulator's limits, the reward and the metrics all read the same value.

IDL paper, Table 2 (parameters for the longitudinal control)
--------------------------------------------------------------
=====================  ==========  ==========================================================
name                   value       meaning
=====================  ==========  ==========================================================
``ACCEL_MAX``          3 m/s²      upper bound of acceleration, acc_max
``ACCEL_MIN``          −7.6 m/s²   lower bound of acceleration, acc_min
``STATE_SCALES``       25, 2.5,    α_p, α_v, α_acc: scaling of the eq-16 state
                       4.5
``DELTA``              0.2 s       delay δ of the preceding vehicle's information
``GAIN_BOUNDS``        [−2, 2]     range of each of k_x, k_v, k_a (the action space, eq 17)
``PENALTY``            −1          penalty value p_e (eqs 20, 24)
``STANDSTILL``         2 m         standstill spacing l_0 (eq 3)
``TTC_STAR``           3 s         TTC* threshold of the safety reward and metrics (eqs 20, 31)
``HEADWAY``            1.1 s       desired time headway T* of the linear controller (eq 3)
``SPEED_MIN``          0.001 m/s   lower bound of velocity v_min (eq 22's guard)
``SPEED_MAX``          33.3 m/s    upper bound of velocity v_max
``REWARD_WEIGHTS``     1/3 each    ω1, ω2, ω3 of the reward (eq 18)
=====================  ==========  ==========================================================

Not in Table 2 but used with it:

``TAU`` = 0.1 s
    the actuator lag τ; the IDL paper does not print it; 0.1 s is the value of its reference
    Zhou et al. (2020) and of every example in this toolkit.
``DT`` = 0.1 s
    the control and simulation step Δt (NGSIM is sampled at 10 Hz, IDL §4.1.1).
``HEADWAY_MU``, ``HEADWAY_SIGMA`` = 0.4226, 0.4365
    the log-normal time-headway density of the efficiency reward (IDL eq 23, from Zhu et al. 2020).
``ROAD_SPEED_LIMIT`` = ``SPEED_MAX``.

IDL paper, Table 1 (the DRL agent) lives with the trainer's configuration dataclasses
(:mod:`stringstab.rl`), where each value documents a field.
"""

from __future__ import annotations

__all__ = [
    "ACCEL_MAX",
    "ACCEL_MIN",
    "DELTA",
    "DT",
    "GAIN_BOUNDS",
    "HEADWAY",
    "HEADWAY_MU",
    "HEADWAY_SIGMA",
    "PENALTY",
    "REWARD_WEIGHTS",
    "SPEED_MAX",
    "SPEED_MIN",
    "STANDSTILL",
    "STATE_SCALES",
    "TAU",
    "TTC_STAR",
]

ACCEL_MAX: float = 3.0
ACCEL_MIN: float = -7.6
STATE_SCALES: tuple[float, float, float] = (25.0, 2.5, 4.5)
DELTA: float = 0.2
GAIN_BOUNDS: tuple[float, float] = (-2.0, 2.0)
PENALTY: float = -1.0
STANDSTILL: float = 2.0
TTC_STAR: float = 3.0
HEADWAY: float = 1.1
SPEED_MIN: float = 0.001
SPEED_MAX: float = 33.3
REWARD_WEIGHTS: tuple[float, float, float] = (1 / 3, 1 / 3, 1 / 3)

TAU: float = 0.1
DT: float = 0.1
HEADWAY_MU: float = 0.4226
HEADWAY_SIGMA: float = 0.4365
