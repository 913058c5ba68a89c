"""Named vehicles of an existing SUMO scenario driven by a toolkit controller.

Every step, each controlled vehicle in the simulation asks SUMO for its leader
(``vehicle.getLeader``, 250 m ahead along its route, any vehicle: SUMO's own Krauss/ACC
drivers, a car merging from a ramp, another controlled vehicle) and is commanded by the
controller from what it sees: the gap (``getLeader``'s distance plus the vehicle's minGap, so
bumper to bumper), its speed, the leader's speed, and the leader's acceleration received δ
late.  As in :mod:`~stringstab.sumo.platoon`, the actuator lag τ and the delay δ stay on the
toolkit's side: each controlled vehicle's acceleration is the exact zero-order-hold lag state
(a toolkit :class:`~stringstab.traffic.Platoon` row per vehicle integrates it, limits
included) and SUMO is sent the resulting speed with speed mode 0.

What is approximated: the acceleration received from a SUMO-driven leader is SUMO's
``getAcceleration`` (its speed change over the last step, the held acceleration of a lag-free
SUMO vehicle; a controlled leader's is its lag state), recorded every step for every vehicle
so a new leader's history is there
(linearly interpolated for a δ that is not a multiple of the step, as the toolkit does); a
leader that entered the simulation less than δ ago is assumed to have held its first
acceleration before.  A controlled vehicle with no leader within 250 m is handed back to SUMO
(speed mode restored, its own car-following model drives it) until a leader appears; its lag
state restarts from SUMO's acceleration then.

The controlled ids are checked against the scenario's route files before SUMO starts (an id no
file defines, or one departing after the last of ``steps``, is refused), and each one when it
is due: a vehicle neither driving nor waiting for insertion one step after its depart time
stops the run there (:mod:`~stringstab.sumo.routes`).  The summary's m_p and collisions are
the toolkit's metrics (:mod:`stringstab.traffic.metrics`, eq 29 and its collision count) over
the steps each vehicle was driven; a vehicle that never had a leader is listed in
``without_leader`` (nothing of the controller was exercised on it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..params import DEFAULT_DELTA, DEFAULT_TAU
from ..progress import Progress
from ..traffic import Limits, Platoon
from ..traffic.controllers import Controller, Observation
from ..traffic.metrics import collision_count, damping_ratio
from .routes import Schedule, scheduled_departures
from .runtime import SumoSession, check_config

__all__ = ["LOOKAHEAD", "ScenarioRun", "run_scenario"]

Array = npt.NDArray[np.float64]
#: How far ahead SUMO is asked for a leader, m.
LOOKAHEAD = 250.0
#: SUMO's default speed mode (every check on), restored for a vehicle without leader.
DEFAULT_SPEED_MODE = 31


@dataclass
class ScenarioRun:
    """The record of an in-scenario run: one row per (step, controlled vehicle present).

    Attributes
    ----------
    columns : dict of arrays
        ``t`` (s), ``vehicle`` (index into ``ids``), ``controlled`` (1 when the toolkit drove it
        this step, 0 when SUMO did: no leader), ``leader`` (SUMO id or ''), ``gap`` (m),
        ``speed`` (m/s), ``accel`` (m/s², the lag state or SUMO's), ``pred_speed``,
        ``pred_accel``, ``pred_accel_delayed``, ``command`` (m/s²), ``k_x``, ``k_v``, ``k_a`` (NaN when the
        controller has no eq-4 gains).
    ids : list of str
        The controlled vehicles.
    summary : dict
        Per vehicle and overall: steps controlled, leader changes (the leaders in order),
        minimum gap, collisions (entries into gap ≤ 0), m_p over the controlled steps (eq 29:
        its acceleration energy over its leaders'), m_fss of the executed gains, and
        ``without_leader``: the vehicles that never had a leader (never driven by the controller).
    """

    columns: dict[str, Any]
    ids: list[str]
    summary: dict[str, Any]


class _History:
    """Every vehicle's acceleration at every step since it appeared (for a_{i−1}(t − δ))."""

    def __init__(self, n_delay: int, frac: float) -> None:
        self.n, self.f = n_delay, frac
        self.data: dict[str, list[float]] = {}

    def push(self, accel: dict[str, float]) -> None:
        for vid, a in accel.items():
            self.data.setdefault(vid, []).append(a)

    def delayed(self, vid: str) -> float:
        h = self.data.get(vid)
        if not h:
            return 0.0
        last = len(h) - 1

        def at(j: int) -> float:
            return h[max(last - j, 0)]

        a = at(self.n)
        return (1.0 - self.f) * a + self.f * at(self.n + 1) if self.f else a


def run_scenario(sumocfg: str | Path, controlled: list[str], controller: Controller, *,
                 dt: float, tau: float = DEFAULT_TAU, delta: float = DEFAULT_DELTA,
                 api: str = "libsumo", steps: int | None = None, limits: Limits | None = None,
                 progress: bool = False) -> ScenarioRun:
    """Drive ``controlled`` vehicles of the scenario ``sumocfg`` with ``controller``.

    Parameters
    ----------
    sumocfg : path
        A SUMO configuration with ``step-length`` = ``dt`` and the ballistic update (refused
        otherwise, before SUMO starts).
    controlled : list of str
        Vehicle ids of the scenario's route files; each is refused before SUMO starts when no
        route file defines it or it departs after the last of ``steps``, and stops the run
        when it is due and SUMO neither drives it nor waits to insert it.
    controller : Controller
        Any toolkit controller (vectorised over the controlled vehicles present).
    dt, tau, delta : float
        Step, actuator lag and communication delay, s.
    api : {"libsumo", "traci"}
        How SUMO runs.
    steps : int, optional
        Steps to run; default until the controlled vehicles have all left (or SUMO's end).
    limits : Limits, optional
        The toolkit's acceleration and speed bounds.
    progress : bool
        Show progress.

    Returns
    -------
    ScenarioRun

    Raises
    ------
    StringStabError
        A configuration with another step or the Euler update, an id that is not in the
        scenario or never appears when due, or SUMO failing.
    """
    check_config(sumocfg, dt)
    ids = list(dict.fromkeys(controlled))
    if not ids or any(not i.strip() for i in ids):
        raise StringStabError(f"--controlled: expected vehicle ids ID,ID,...; got {controlled!r}")
    sched = scheduled_departures(sumocfg)
    _check_ids(ids, sched, Path(sumocfg).name, None if steps is None else sched.begin + steps * dt)
    due = {vid: d for vid in ids if (d := sched.depart(vid)) is not None}
    M = len(ids)
    lag = Platoon(M, 1, dt=dt, tau=tau, delta=delta, limits=limits)
    q = delta / dt
    n_delay = math.floor(q + 1e-9)
    frac = q - n_delay if q - n_delay > 1e-9 else 0.0
    hist = _History(n_delay, frac)
    active = np.zeros(M, dtype=bool)
    seen = np.zeros(M, dtype=bool)
    gone = np.zeros(M, dtype=bool)
    rows: dict[str, list[Any]] = {k: [] for k in (
        "t", "vehicle", "controlled", "leader", "gap", "speed", "accel", "pred_speed",
        "pred_accel", "pred_accel_delayed", "command", "k_x", "k_v", "k_a")}
    total = steps if steps is not None else None
    bar = Progress(total or 0, "sumo scenario", unit="step", enabled=progress and total is not None)
    cfg = Path(sumocfg).resolve()
    min_gap: dict[str, float] = {}
    try:
        with SumoSession(["-c", str(cfg)], dt=dt, api=api, scenario=True) as s:
            veh, c = s.vehicle, s.constants
            k = 0
            while True:
                if steps is not None and k >= steps:
                    break
                if steps is None and (gone[seen].all() and seen.all()):
                    break
                if s.simulation.getMinExpectedNumber() <= 0:
                    break
                s.step()
                for vid in s.simulation.getDepartedIDList():
                    veh.subscribe(vid, [c.VAR_SPEED, c.VAR_ACCELERATION])
                res = veh.getAllSubscriptionResults()
                acc_now = {vid: r[c.VAR_ACCELERATION] for vid, r in res.items()}
                for j in np.flatnonzero(active):  # a controlled vehicle's is its lag state
                    if ids[j] in acc_now:
                        acc_now[ids[j]] = float(lag.accel[j, 1])
                hist.push(acc_now)
                t = float(s.simulation.getTime())
                present = np.array([i in res for i in ids])
                gone |= seen & ~present
                seen |= present
                late = [v for j, v in enumerate(ids) if not seen[j] and v in due
                        and t >= due[v] + dt * (1 + 1e-9)]
                if late:
                    _refuse_late(late, set(s.simulation.getPendingVehicles()), due, t,
                                 Path(sumocfg).name, sched.begin)
                idx = np.flatnonzero(present)
                lead_info: list[Any] = []
                for j in idx:
                    vid = ids[j]
                    if vid not in min_gap:
                        min_gap[vid] = float(veh.getMinGap(vid))
                    lead = veh.getLeader(vid, LOOKAHEAD)
                    lead_info.append(lead if lead and lead[0] else None)
                led = np.array([li is not None for li in lead_info], dtype=bool)
                # vehicles without a leader go back to SUMO; those with one are (re)taken over
                for j, has in zip(idx, led):
                    vid = ids[j]
                    r = res[vid]
                    if has and not active[j]:
                        veh.setSpeedMode(vid, 0)
                        veh.setLaneChangeMode(vid, 0)
                        lag.accel[j, 1] = r[c.VAR_ACCELERATION]
                        active[j] = True
                    elif not has and active[j]:
                        veh.setSpeedMode(vid, DEFAULT_SPEED_MODE)
                        veh.setSpeed(vid, -1.0)
                        active[j] = False
                active &= present
                drive = idx[led]
                if drive.size:
                    found = [li for li in lead_info if li is not None]
                    lids = [str(li[0]) for li in found]
                    gaps = np.array([float(li[1]) for li in found])
                    gaps = gaps + np.array([min_gap[ids[j]] for j in drive])
                    v = np.array([res[ids[j]][c.VAR_SPEED] for j in drive])
                    a = lag.accel[drive, 1].copy()
                    vp = np.array([res[lid][c.VAR_SPEED] if lid in res else veh.getSpeed(lid)
                                   for lid in lids])
                    ap_now = np.array([acc_now.get(lid, 0.0) for lid in lids])
                    ap_del = np.array([hist.delayed(lid) for lid in lids])
                    obs = Observation(k, t, dt, gaps[None], v[None], a[None], vp[None],
                                      (vp - v)[None], ap_now[None], ap_del[None])
                    u = np.asarray(controller.command(obs), dtype=np.float64).reshape(-1)
                    K = controller.gains(obs)
                    Kb = (np.broadcast_to(np.asarray(K, dtype=np.float64), (1, drive.size, 3))[0]
                          if K is not None else np.full((drive.size, 3), np.nan))
                    # the lag rows of the driven vehicles: SUMO's speed, the toolkit's lag state
                    lag.speed[drive, 1] = v
                    ufull = np.zeros((M, 1))
                    ufull[drive, 0] = u
                    ul = lag.advance(ufull)
                    for n, j in enumerate(drive):
                        veh.setSpeed(ids[j], float(lag.speed[j, 1]))
                        rows["t"].append(t)
                        rows["vehicle"].append(int(j))
                        rows["controlled"].append(1)
                        rows["leader"].append(lids[n])
                        rows["gap"].append(float(gaps[n]))
                        rows["speed"].append(float(v[n]))
                        rows["accel"].append(float(a[n]))
                        rows["pred_speed"].append(float(vp[n]))
                        rows["pred_accel"].append(float(ap_now[n]))
                        rows["pred_accel_delayed"].append(float(ap_del[n]))
                        rows["command"].append(float(ul[j, 0]))
                        rows["k_x"].append(float(Kb[n, 0]))
                        rows["k_v"].append(float(Kb[n, 1]))
                        rows["k_a"].append(float(Kb[n, 2]))
                for j in idx[~led]:
                    r = res[ids[j]]
                    rows["t"].append(t)
                    rows["vehicle"].append(int(j))
                    rows["controlled"].append(0)
                    rows["leader"].append("")
                    for key in ("gap", "pred_speed", "pred_accel", "pred_accel_delayed", "command", "k_x",
                                "k_v", "k_a"):
                        rows[key].append(math.nan)
                    rows["speed"].append(float(r[c.VAR_SPEED]))
                    rows["accel"].append(float(r[c.VAR_ACCELERATION]))
                k += 1
                bar.update()
    finally:
        bar.close()
    missing = [i for i, ok in zip(ids, seen) if not ok]
    if missing:
        raise StringStabError(
            f"--controlled: vehicle(s) {', '.join(missing)} never appeared in {cfg.name} within "
            f"the run ({k} steps); expected ids of vehicles the scenario inserts")
    cols = {key: np.asarray(v) for key, v in rows.items()}
    return ScenarioRun(cols, ids, _summary(cols, ids, tau, delta, controller, dt))


def _check_ids(ids: list[str], sched: Schedule, name: str, end: float | None) -> None:
    """Refuse, before SUMO starts, ids no route file defines or departing after ``end`` (s)."""
    if not sched.complete:
        return  # a file not read here: the run checks the ids
    unknown = [v for v in ids if not sched.defines(v)]
    if unknown:
        known = list(sched.vehicles)[:12] + [f"{f}.N" for f in list(sched.flows)[:4]]
        raise StringStabError(
            f"--controlled: no vehicle {', '.join(map(repr, unknown))} in the route files of "
            f"{name} ({', '.join(p.name for p in sched.files) or 'none'}); expected ids of "
            f"vehicles the scenario inserts, e.g. {', '.join(known)}")
    if end is not None:
        after = [(v, d) for v in ids if (d := sched.depart(v)) is not None and d > end + 1e-9]
        if after:
            v, d = after[0]
            raise StringStabError(
                f"--controlled: vehicle {v!r} departs at t = {d:g} s, after the run's end "
                f"(--steps ends it at t = {end:g} s); expected more --steps or vehicles that "
                "depart within the run")


def _refuse_late(late: list[str], pending: set[str], due: dict[str, float], t: float,
                 name: str, begin: float) -> None:
    """Stop the run at a vehicle that is due but neither driving nor waiting for insertion."""
    missing = [v for v in late if v not in pending]
    if missing:
        v = missing[0]
        why = (f"it departs before the configuration's begin, t = {begin:g} s, and SUMO skips "
               "it" if due[v] < begin else "SUMO dropped it, e.g. for a route it could not use")
        raise StringStabError(
            f"--controlled: vehicle {v!r} of {name} was due to depart at t = {due[v]:g} s and "
            f"at t = {t:g} s SUMO neither drives it nor waits to insert it ({why}); expected a "
            "vehicle the scenario inserts")


def _summary(cols: dict[str, Any], ids: list[str], tau: float, delta: float,
             controller: Controller, dt: float) -> dict[str, Any]:
    per = []
    K_all = []
    for j, vid in enumerate(ids):
        m = (cols["vehicle"] == j) & (cols["controlled"] == 1) if cols["t"].size else np.array([], bool)
        leaders: list[str] = []
        for lid in cols["leader"][m]:
            if not leaders or leaders[-1] != lid:
                leaders.append(str(lid))
        gap = cols["gap"][m]
        coll = int(collision_count(gap)) if gap.size else 0
        a, ap = cols["accel"][m], cols["pred_accel"][m]
        mp_value = float(damping_ratio(a, ap))  # eq 29 over the driven steps
        mp = mp_value if math.isfinite(mp_value) else None
        K = np.column_stack([cols["k_x"][m], cols["k_v"][m], cols["k_a"][m]])
        if K.size and np.isfinite(K).all():
            K_all.append(K)
        per.append({"vehicle": vid, "steps_controlled": int(m.sum()),
                    "steps_present": int((cols["vehicle"] == j).sum()) if cols["t"].size else 0,
                    "leaders": leaders, "leader_changes": max(len(leaders) - 1, 0),
                    "min_gap": float(gap.min()) if gap.size else None, "collisions": coll,
                    "m_p": mp})
    out: dict[str, Any] = {"vehicles": per,
                           "leader_changes": sum(p["leader_changes"] for p in per),
                           "collisions": sum(p["collisions"] for p in per),
                           "without_leader": [p["vehicle"] for p in per
                                              if p["steps_controlled"] == 0],
                           "m_fss": None}
    if K_all and controller.headway is not None:
        from ..rl.evaluate import fss

        f = fss(np.concatenate(K_all), tau=tau, delta=delta, headway=controller.headway, dt=dt)
        out.update(m_fss=f["m_fss"], m_fss_sampled=f["m_fss_sampled"], n_gains=f["n"])
    return out
