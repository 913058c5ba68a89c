"""The same case through the toolkit's simulator and through SUMO: how far apart they are.

Both sides run the leader as SUMO moves it (its speed samples, positions by the trapezoid
rule: :func:`~stringstab.sumo.platoon.ballistic_leader`).  The toolkit side runs :func:`stringstab.traffic.simulate` with ``position_update="trapezoid"``
(SUMO's ballistic position update); everything else — the exact zero-order-hold lag, the delay,
the limits, the controller — is the same code on both sides, so what is compared is SUMO's
motion of the vehicles against the toolkit's.  The difference from the toolkit's default exact
position integral is reported beside it (it is not a disagreement with SUMO: it is the
in-step position rule, of order ā Δt³/(12 τ) per step).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..params import DEFAULT_DELTA, DEFAULT_TAU
from ..traffic import Limits, PlatoonResult, Trajectory, simulate
from ..traffic.controllers import Controller
from .platoon import DEFAULT_LENGTH, ballistic_leader, cosimulate

__all__ = ["TOLERANCE", "agreement", "differences"]

#: The largest difference `stringstab sumo check` accepts (SI units of each quantity).
TOLERANCE = 1e-3


def differences(a: PlatoonResult, b: PlatoonResult) -> dict[str, float]:
    """Largest absolute differences between two runs of one platoon, over followers and time.

    Parameters
    ----------
    a, b : PlatoonResult
        Two recorded runs of the same platoon (same shape; e.g. SUMO and the toolkit's
        simulator), with accelerations and speeds recorded.

    Returns
    -------
    dict
        ``accel`` (m/s²), ``speed`` (m/s), ``gap`` (m) and ``m_p`` (eq 29, per follower; over
        the followers where it is defined in both runs, ``inf`` if it is defined in only one).
    """
    assert a.accel is not None and b.accel is not None and a.speed is not None and b.speed is not None
    mp_a, mp_b = a.damping_ratios, b.damping_ratios
    ok = np.isfinite(mp_a) & np.isfinite(mp_b)
    if (np.isfinite(mp_a) != np.isfinite(mp_b)).any():
        mp = float("inf")  # defined in one run and not in the other
    else:  # m_p is undefined (0/0) where a predecessor never accelerates, in both runs alike
        mp = float(np.max(np.abs(mp_a[ok] - mp_b[ok]))) if ok.any() else 0.0
    return {
        "accel": float(np.max(np.abs(a.accel[1:] - b.accel[1:]))),
        "speed": float(np.max(np.abs(a.speed[1:] - b.speed[1:]))),
        "gap": float(np.max(np.abs(a.gap - b.gap))),
        "m_p": mp,
    }


def agreement(leader: Trajectory, controller: Controller, n_followers: int, *,
              tau: float = DEFAULT_TAU, delta: float = DEFAULT_DELTA, api: str = "libsumo",
              length: float = DEFAULT_LENGTH, limits: Limits | None = None,
              tolerance: float = TOLERANCE, progress: bool = False) -> dict[str, Any]:
    """Run one case through :func:`~stringstab.traffic.simulate` and through SUMO; compare.

    Parameters
    ----------
    leader, controller, n_followers, tau, delta, length, limits
        The case (as for :func:`~stringstab.traffic.simulate`; ``limits`` default: IDL Table 2).
    api : {"libsumo", "traci"}
        How SUMO runs.
    tolerance : float
        The largest accepted difference.
    progress : bool
        Show SUMO's run with a progress bar (or periodic lines off a terminal).

    Returns
    -------
    dict
        ``differences`` (toolkit with the trapezoid position rule vs SUMO),
        ``differences_exact_positions`` (toolkit's default exact positions vs SUMO, for
        reference), ``tolerance``, ``passed`` (every difference of ``differences`` ≤ tolerance),
        ``steps``, ``followers``, the two runs' ``m_p``, SUMO's largest speed override, and
        ``leader_position_change``: how far (m) the leader's positions moved when re-integrated
        by the trapezoid rule (:func:`~stringstab.sumo.platoon.ballistic_leader`; both sides
        run that leader).
    """
    leader, moved = ballistic_leader(leader)
    toolkit = simulate(leader, controller, n_followers, tau=tau, delta=delta, length=length,
                       limits=limits, position_update="trapezoid")
    exact = simulate(leader, controller, n_followers, tau=tau, delta=delta, length=length,
                     limits=limits)
    sumo = cosimulate(leader, controller, n_followers, tau=tau, delta=delta, api=api,
                      limits=limits, length=length, progress=progress)
    d = differences(toolkit, sumo)
    finite = [v for v in d.values() if np.isfinite(v)]
    return {
        "leader": leader.name, "followers": int(n_followers), "steps": int(leader.n_steps),
        "dt": float(leader.dt), "tau": float(tau), "delta": float(delta), "api": api,
        "differences": d, "differences_exact_positions": differences(exact, sumo),
        "tolerance": float(tolerance),
        "passed": bool(len(finite) == len(d) and max(finite) <= tolerance),
        "m_p_toolkit": toolkit.damping_ratios.tolist(), "m_p_sumo": sumo.damping_ratios.tolist(),
        "sumo_speed_override": sumo.params["sumo_speed_override"],
        "leader_position_change": moved,
        "sumo_version": sumo.params["sumo_version"],
    }
