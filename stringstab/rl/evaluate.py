"""Held-out evaluation of a policy or a baseline: the IDL paper's metrics per episode and pooled.

Each test episode is one follower behind one leader (a test episode of
:mod:`~stringstab.rl.episodes`, or a user's file), simulated by
:func:`stringstab.traffic.simulate` — the same dynamics as training, but a collision does not end
the episode (§4.1.2).  Every strategy starts from the same state: the recorded follower's gap
and speed for an NGSIM pair, else the IDL equilibrium gap l_0 + T* v at the leader's speed.

Metrics (:mod:`stringstab.traffic.metrics`): m_p of each episode (eq 29, follower over leader) and their
mean M_lss (eq 30), TIT per episode (eqs 31-32) and its mean, M_CI (eq 34, pooled), M_effi
(eq 35, pooled), collisions, and for gain policies m_fss (eq 27's M_fss, as a fraction in
[0, 1]): the share of executed (vehicle, moment) gains certified by the exact certificate, and
beside it m_fss_sampled, the
share certified by the sampled-data certificate of the zero-order-hold loop at the control step
``dt`` (:mod:`stringstab.certify.sampled`).  Both are computed in one place, :func:`fss`.

With a reaction delay θ_r > 0 (issue 25) the follower applies its command θ_r late and m_fss is
the share certified by the continuous certificate at θ_r (exact); m_fss_sampled is *not
available* (None, and the reports say so): the sampled-data certificate has no θ_r, and a
share computed without it would describe another loop.  The radio and sensors (issue 26) act
in the simulation only; no certificate covers message loss or noise.

A platoon test (§5.1): 10 and 100 vehicles running the strategy behind
:func:`stringstab.traffic.paper_mix` (held 100 s at its final speed so the disturbance reaches
the tail), m_p per vehicle next to the paper's values.  The certificate holds for frozen gains;
a learned policy switches gains every step, so this time-domain check is the evidence that the
switching does not amplify disturbances — it is evidence, not a proof.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify.verdicts import Verdict
from ..constants import STANDSTILL, TTC_STAR
from ..errors import StringStabError
from ..traffic.metrics import (
    efficiency_index,
    fss_ratio,
    jerk_squared,
    time_integrated_ttc,
    time_to_collision,
)
from .policy import Policy

__all__ = ["PAPER_MP_10", "SAMPLED_NOT_AVAILABLE", "Evaluation", "controller_for", "evaluate", "fss", "platoon_test"]

Array = npt.NDArray[np.float64]

#: m_p per vehicle of the paper's 10-vehicle IDL platoon (§5.1).
PAPER_MP_10 = (0.45, 0.53, 0.61, 0.68, 0.73, 0.77, 0.81, 0.83, 0.85, 0.86)
#: The paper's 100-vehicle platoon: m_p between 0.978 and 0.989 after vehicle 39, all < 1.
PAPER_MP_100_MAX = 0.989
BASELINES = ("cacc", "idm")


#: What the reports say for m_fss_sampled with θ_r > 0 when the sampled certificate with θ_r
#: refuses the loop (θ_r of more than 2,000 steps: :func:`fss`).
SAMPLED_NOT_AVAILABLE = "not available: the sampled certificate refuses this θ_r at this step"


def fss(gains: npt.ArrayLike, *, tau: float, delta: float, headway: float,
        dt: float | npt.ArrayLike, reaction_delay: float = 0.0) -> dict[str, Any]:
    """m_fss (eq 27) of executed gains ``(..., 3)``: the one call site of the certificates.

    The continuous certificate is what the repair guarantees (and what the exit code of
    ``stringstab evaluate`` requires); the sampled one is the loop the simulator actually runs
    (u held over each step of ``dt``).

    Parameters
    ----------
    gains : array_like, shape (..., 3)
        Executed gains (k_x [1/s²], k_v [1/s], k_a [-]; IDL eq 4), one triple per (vehicle,
        moment).
    tau : float
        Actuator lag τ (IDL eq 7), s.
    delta : float
        Communication delay δ (eq 4), s.
    headway : float
        Time headway T* (eq 3), s.
    dt : float or array_like of float
        Control step, s: the sampling period H of the sampled-data certificate; one per triple
        when the triples ran at different steps (episodes of leaders sampled differently).
    reaction_delay : float
        θ_r, s (issue 25): m_fss by the continuous certificate at θ_r, m_fss_sampled by the
        sampled-data certificate with θ_r at each step (:class:`stringstab.certify.api.Loop`
        with ``reaction_delay`` and ``sample_time``; docs/sampled.md §10); None where that
        certificate refuses the loop (:data:`SAMPLED_NOT_AVAILABLE`: θ_r of more than 2,000
        steps).

    Returns
    -------
    dict
        ``"m_fss"``: the fraction in [0, 1] of triples certified by the exact continuous-time
        certificate (IDL eqs 27-28 without the ×100 %, :func:`stringstab.traffic.metrics.fss_ratio`);
        ``"m_fss_sampled"``: the fraction certified by the
        sampled-data certificate of the zero-order-hold loop at each triple's own ``dt``
        (:func:`stringstab.certify.api.check`); ``"n"``: the number of triples;
        ``"certificate"``, ``"dt"``: what was checked (the step, or the sorted list of steps).

    Raises
    ------
    StringStabError
        If there is no gain triple, or ``dt`` is an array of another length.
    """
    from ..certify.api import check

    K = np.asarray(gains, dtype=np.float64).reshape(-1, 3)
    if not K.shape[0]:
        raise StringStabError("m_fss needs at least one executed gain triple")
    step = np.asarray(dt, dtype=np.float64)
    if step.ndim and step.size != K.shape[0]:
        raise StringStabError(f"dt: expected one step or one per gain triple ({K.shape[0]}); "
                              f"found {step.size}")
    steps = np.broadcast_to(step.reshape(-1) if step.ndim else step, K.shape[:1])
    hs = sorted(float(h) for h in np.unique(steps))
    if reaction_delay:  # both certificates with θ_r (issue 25), through certify.api
        from ..certify.api import Loop

        m_s: float | None = None
        sampled = f"sampled-data {SAMPLED_NOT_AVAILABLE}"
        try:
            ok_r = np.zeros(K.shape[0], dtype=bool)
            for h in np.unique(steps):  # each triple at the step it ran at
                rows = np.flatnonzero(steps == h)
                uniq, inverse = np.unique(K[rows], axis=0, return_inverse=True)
                loop = Loop.of(tau, delta, headway, sample_time=float(h),
                               reaction_delay=reaction_delay)
                cr = loop.check(uniq[:, 0], uniq[:, 1], uniq[:, 2])
                ok_r[rows] = np.asarray(cr.verdict == Verdict.CERTIFIED)[np.ravel(inverse)]
            m_s = float(ok_r.mean())
            sampled = "sampled-data (ZOH) at dt with θ_r beside it"
        except StringStabError as e:  # θ_r too many steps of dt for the sampled certificate
            sampled += f" ({e})"
        return {"m_fss": fss_ratio(K[:, 0], K[:, 1], K[:, 2], tau=tau, delta=delta, headway=headway,
                                   reaction_delay=reaction_delay),
                "m_fss_sampled": m_s, "n": int(K.shape[0]),
                "certificate": f"exact (continuous time) with reaction delay θ_r = {reaction_delay:g} s; "
                               + sampled,
                "dt": hs[0] if len(hs) == 1 else hs}
    ok_s = np.zeros(K.shape[0], dtype=bool)
    for h in np.unique(steps):  # each triple at the step it ran at
        rows = np.flatnonzero(steps == h)
        uniq, inverse = np.unique(K[rows], axis=0, return_inverse=True)
        cs = check(uniq[:, 0], uniq[:, 1], uniq[:, 2], tau=tau, delta=delta, headway=headway,
                   sample_time=float(h))
        ok_s[rows] = np.asarray(cs.verdict == Verdict.CERTIFIED)[np.ravel(inverse)]
    return {"m_fss": fss_ratio(K[:, 0], K[:, 1], K[:, 2], tau=tau, delta=delta, headway=headway),
            "m_fss_sampled": float(ok_s.mean()), "n": int(K.shape[0]),
            "certificate": "exact (continuous time); sampled-data (ZOH) at dt beside it",
            "dt": hs[0] if len(hs) == 1 else hs}


def controller_for(strategy: Policy | str, *, headway: float,
                   standstill: float = STANDSTILL) -> Any:
    """A :mod:`stringstab.traffic.controllers` controller running ``strategy``.

    A gain policy runs the eq-4 law with its *executed* (repaired) gains
    (:meth:`Policy.gains`); an acceleration policy commands its output; ``"cacc"`` is van Arem
    et al.'s CACC with T* as time gap, ``"idm"`` the IDM (the paper's HDV row replays recorded
    NGSIM followers; without NGSIM the IDM stands in for the human driver).

    Parameters
    ----------
    strategy : Policy or {"cacc", "idm"}
        A trained policy or a baseline's name.
    headway : float
        Time headway T* (eq 3), s: of the eq-16 state and the eq-4 law (the CACC's time gap).
    standstill : float
        Standstill distance l_0 (eq 3), m (the IDM's minimum gap).

    Returns
    -------
    controller
        A ``TimeVaryingLinearController`` (gain policy; it remembers the previous step's
        executed gains for the policy's rate limit and extended state, reset at step 0), a
        ``FunctionController`` (acceleration policy), a ``CACCController`` or an
        ``IDMController``.

    Raises
    ------
    StringStabError
        On an unknown baseline name.
    """
    from ..traffic.controllers import (
        CACCController,
        FunctionController,
        IDMController,
        TimeVaryingLinearController,
    )
    from ..traffic.state import state_vector

    if isinstance(strategy, str):
        if strategy == "cacc":
            return CACCController(t_system=headway, r_min=standstill)
        if strategy == "idm":
            return IDMController(min_gap=standstill)
        raise StringStabError(f"baseline must be one of {', '.join(BASELINES)}; got {strategy!r}")
    pol = strategy

    def state(obs: Any) -> Array:
        return state_vector(obs, headway=headway, standstill=standstill)

    if pol.action == "gains":
        memory: dict[str, Any] = {}  # the previous step's executed gains, per vehicle

        def schedule(obs: Any) -> Array:
            s = state(obs)
            prev = memory.get("K")
            if obs.step == 0 or prev is None or prev.shape != s.shape:
                prev = None  # a new run: no previous gains
            K = pol.step_gains(s.reshape(-1, 3), accel=np.asarray(obs.accel).reshape(-1),
                               prev_gains=prev).reshape(s.shape)
            memory["K"] = K
            return K

        return TimeVaryingLinearController(schedule, headway=headway, standstill=standstill)

    def accel(obs: Any) -> Array:
        s = state(obs)
        return pol(s.reshape(-1, s.shape[-1]))[:, 0].reshape(s.shape[:-1])

    return FunctionController(accel, headway=headway, standstill=standstill)


@dataclass
class Evaluation:
    """The outcome of :func:`evaluate` for one strategy."""

    name: str
    episodes: list[dict[str, Any]]
    summary: dict[str, Any]
    gains: Array | None = None  # (rows, 5): t, episode, k_x, k_v, k_a
    samples: dict[str, Array] = field(default_factory=dict)  # ttc, jerk_sq, headway, m_p

    def gains_csv(self) -> str:
        """The executed gains as CSV ``t,vehicle,k_x,k_v,k_a`` (``stringstab certify --file``)."""
        if self.gains is None:
            raise StringStabError(f"{self.name} executes no gains")
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["t", "vehicle", "k_x", "k_v", "k_a"])
        for t, ep, kx, kv, ka in self.gains:
            w.writerow([f"{t:.6g}", int(ep), repr(float(kx)), repr(float(kv)), repr(float(ka))])
        return buf.getvalue()

    def episodes_csv(self) -> str:
        """One row per episode."""
        cols = ["episode", "leader", "seconds", "m_p", "TIT", "collisions", "min_gap", "m_fss"]
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(cols)
        for e in self.episodes:
            w.writerow([e.get(c, "") if e.get(c) is not None else "" for c in cols])
        return buf.getvalue()


def _start(leader: Any, headway: float, standstill: float) -> tuple[Any, float, float]:
    if hasattr(leader, "follower"):
        return leader.leader, float(leader.gap[0]), float(leader.follower.speed[0])
    v0 = float(leader.speed[0])
    return leader, standstill + headway * v0, v0


def evaluate(strategy: Policy | str, leaders: Sequence[Any], *, tau: float, delta: float,
             headway: float, name: str | None = None, standstill: float = STANDSTILL,
             ttc_star: float = TTC_STAR, limits: Any = None, progress: Any = None,
             reaction_delay: float = 0.0, radio: Any = None, sensors: Any = None) -> Evaluation:
    """Run ``strategy`` (a policy, ``"cacc"`` or ``"idm"``) on every leader; see the module.

    Leaders of equal length and step are simulated together, one follower each.

    Parameters
    ----------
    strategy : Policy or {"cacc", "idm"}
        What the follower runs (:func:`controller_for`).
    leaders : sequence of Trajectory or FollowingPair
        The held-out leaders; a pair starts from the recorded follower's gap and speed, a
        trajectory from the equilibrium gap l_0 + T* v.
    tau : float
        Actuator lag τ of the follower (IDL eq 7), s.
    delta : float
        Communication delay δ (eq 4), s.
    headway : float
        Time headway T* (eq 3), s.
    name : str, optional
        Label of the strategy (default the baseline's name or the policy's ``algo``).
    standstill : float
        Standstill distance l_0 (eq 3), m.
    ttc_star : float
        TTC* of the time-integrated TTC (eqs 31-32), s.
    limits : Limits, optional
        Bounds on the followers (default IDL Table 2).
    progress : callable, optional
        Receives the number of leaders done after each group of equally long leaders (for a
        progress line).
    reaction_delay : float
        Reaction delay θ_r of the follower, s (issue 25; :func:`stringstab.traffic.simulate`);
        m_fss is certified at θ_r (:func:`fss`).
    radio : Radio, optional
        The follower's V2V link (issue 26).
    sensors : SensorNoise, optional
        The follower's sensors (issue 26).

    Returns
    -------
    Evaluation
        ``episodes``: one dict per leader (``m_p`` of eq 29, ``TIT``, ``collisions``,
        ``min_gap``, ``m_fss``); ``summary``: ``episodes``, ``M_lss`` (eq 30),
        ``share_m_p_below_1``, ``TIT`` (mean per episode), ``TIT_total``, ``M_CI`` (eq 34),
        ``M_effi`` (eq 35), ``median_headway``, ``collisions``, ``collided_episodes``,
        ``min_gap``, and for gain policies ``m_fss`` (eq 27 as a fraction, with ``n_gains``)
        and ``m_fss_sampled``; ``gains``: the executed gains, rows (t, episode, k_x, k_v, k_a).

    Raises
    ------
    StringStabError
        If ``leaders`` is empty or ``strategy`` an unknown baseline.
    """
    from ..traffic.platoon import simulate

    if not leaders:
        raise StringStabError("evaluation needs at least one leader")
    label = name or (strategy if isinstance(strategy, str) else strategy.algo)
    ctrl = controller_for(strategy, headway=headway, standstill=standstill)
    starts = [_start(tr, headway, standstill) for tr in leaders]
    groups: dict[tuple[int, float], list[int]] = {}
    for i, (tr, _, _) in enumerate(starts):
        groups.setdefault((tr.n_steps, tr.dt), []).append(i)
    episodes: list[dict[str, Any]] = [{} for _ in leaders]
    ttc_all, jerk_all, hw_all, gains_rows, gains_dt = [], [], [], [], []
    for (_, dt), idx in groups.items():
        trs = [starts[i][0] for i in idx]
        gap0 = np.array([[starts[i][1]] for i in idx])
        v0 = np.array([[starts[i][2]] for i in idx])
        res = simulate(trs, ctrl, 1, tau=tau, delta=delta, initial_gap=gap0, initial_speed=v0,
                       limits=limits, reaction_delay=reaction_delay, radio=radio, sensors=sensors)
        assert res.speed is not None and res.accel is not None
        gap = res.gap[:, 0, :]
        spd = res.speed
        ttc = time_to_collision(gap, spd[:, 1, :], spd[:, 0, :])
        tit = time_integrated_ttc(ttc, dt, ttc_star=ttc_star)
        mp = res.damping_ratios[:, 0]
        hw = res.headway[:, 0, :]
        ttc_all.append(ttc[np.isfinite(ttc)].ravel())
        jerk_all.append(jerk_squared(res.accel[:, 1, :], dt).ravel())
        hw_all.append(hw.ravel())
        for j, i in enumerate(idx):
            tr = trs[j]
            episodes[i] = {"episode": i, "leader": tr.name, "seconds": tr.duration,
                           "m_p": float(mp[j]) if np.isfinite(mp[j]) else None,
                           "TIT": float(tit[j]),
                           "collisions": int(res.collision_events[j, 0]),
                           "min_gap": float(res.min_gap[j, 0]), "m_fss": None}
        if res.gains is not None and res.gains.shape[2] == res.t.size:
            G = res.gains[:, 0, :, :]
            for j, i in enumerate(idx):
                f = fss(G[j], tau=tau, delta=delta, headway=headway, dt=dt,
                        reaction_delay=reaction_delay)
                episodes[i]["m_fss"] = f["m_fss"]
                gains_rows.append(np.column_stack([res.t, np.full(res.t.size, i), G[j]]))
                gains_dt.append(np.full(res.t.size, dt))
        if progress is not None:
            progress(len(idx))
    mps = np.array([np.nan if e["m_p"] is None else e["m_p"] for e in episodes])
    ok = np.isfinite(mps)
    tits = np.array([e["TIT"] for e in episodes])
    jerk = np.concatenate(jerk_all)
    hw = np.concatenate(hw_all)
    summary: dict[str, Any] = {
        "strategy": label, "episodes": len(episodes),
        # m_p is undefined where the leader never accelerates (Σ a² = 0): left out, counted
        "M_lss": float(mps[ok].mean()) if ok.any() else None,
        "share_m_p_below_1": float(np.mean(mps[ok] < 1.0)) if ok.any() else None,
        "m_p_undefined": int((~ok).sum()),
        "TIT": float(tits.mean()), "TIT_total": float(tits.sum()),
        "M_CI": float(jerk.mean()),  # eq 34: the pooled mean squared jerk
        "M_effi": efficiency_index(hw),
        # eq 35's mean is dominated by creeping near standstill (h = gap/v grows without
        # bound as v → v_min); the median is reported beside it
        "median_headway": float(np.nanmedian(hw)) if np.isfinite(hw).any() else None,
        "collisions": int(sum(e["collisions"] for e in episodes)),
        "collided_episodes": int(sum(e["collisions"] > 0 for e in episodes)),
        "min_gap": float(min(e["min_gap"] for e in episodes)),
        "m_fss": None,
    }
    gains = None
    if gains_rows:
        gains = np.concatenate(gains_rows)
        f = fss(gains[:, 2:], tau=tau, delta=delta, headway=headway, dt=np.concatenate(gains_dt),
                reaction_delay=reaction_delay)
        summary["m_fss"], summary["n_gains"] = f["m_fss"], f["n"]
        summary["m_fss_sampled"] = f["m_fss_sampled"]
        summary["certificate"] = f["certificate"]
    samples = {"ttc": np.concatenate(ttc_all), "jerk_sq": jerk, "headway": hw, "m_p": mps[ok]}
    return Evaluation(label, episodes, summary, gains, samples)


def platoon_test(strategy: Policy | str, n_vehicles: int, *, tau: float, delta: float,
                 headway: float, dt: float = 0.1, hold: float = 100.0,
                 standstill: float = STANDSTILL, limits: Any = None, progress: Any = None,
                 reaction_delay: float = 0.0, radio: Any = None,
                 sensors: Any = None) -> dict[str, Any]:
    """``n_vehicles`` running ``strategy`` behind the §5.1-style leader: m_p per vehicle and more.

    Parameters
    ----------
    strategy : Policy or {"cacc", "idm"}
        What every follower runs (:func:`controller_for`).
    n_vehicles : int
        Followers in the platoon (the paper: 10 and 100).
    tau : float
        Actuator lag τ (IDL eq 7), s.
    delta : float
        Communication delay δ (eq 4), s.
    headway : float
        Time headway T* (eq 3), s.
    dt : float
        Simulation step, s (also the sampled certificate's period).
    hold : float
        Seconds the leader (:func:`stringstab.traffic.paper_mix`) is held at its final speed,
        so the disturbance reaches the tail.
    standstill : float
        Standstill distance l_0 (eq 3), m; the platoon starts in equilibrium l_0 + T* v.
    limits : Limits, optional
        Bounds on the followers (default IDL Table 2).
    progress : callable, optional
        Called with 1 at each simulated step (a progress report's count).
    reaction_delay : float
        Reaction delay θ_r of every follower, s (issue 25).
    radio : Radio, optional
        Every follower's V2V link (issue 26).
    sensors : SensorNoise, optional
        Every follower's sensors (issue 26).

    Returns
    -------
    dict
        ``"n"``, ``"leader"``, ``"m_p"`` (per vehicle, eq 29), ``"max_m_p"``, ``"M_lss"``
        (eq 30), ``"collisions"``, ``"TIT"``, and for gain policies ``"m_fss"`` and
        ``"m_fss_sampled"`` (:func:`fss` of every vehicle's executed gains at every step;
        None otherwise).
    """
    from ..traffic.metrics import platoon_metrics
    from ..traffic.platoon import simulate
    from ..traffic.synthetic import paper_mix

    leader = paper_mix(dt=dt).hold(hold)
    ctrl = controller_for(strategy, headway=headway, standstill=standstill)
    res = simulate(leader, ctrl, n_vehicles, tau=tau, delta=delta,
                   initial_gap=standstill + headway * float(leader.speed[0]), limits=limits,
                   progress=progress, reaction_delay=reaction_delay, radio=radio,
                   sensors=sensors)
    m = platoon_metrics(res, certificate=False)
    out = {"n": n_vehicles, "leader": f"{leader.name} (+{hold:g} s hold)", "m_p": m["m_p"],
           "max_m_p": m["max_m_p"], "M_lss": m["M_lss"], "collisions": m["collisions"],
           "TIT": m["TIT"], "m_fss": None, "m_fss_sampled": None}
    if res.gains is not None and res.gains.shape[-2] == res.t.size:
        f = fss(res.gains, tau=tau, delta=delta, headway=headway, dt=dt,
                reaction_delay=reaction_delay)
        out["m_fss"], out["m_fss_sampled"] = f["m_fss"], f["m_fss_sampled"]
    return out
