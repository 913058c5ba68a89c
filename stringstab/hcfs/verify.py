"""Closed-loop verification of the jerk theorem: premises, conclusion and bound at every frame.

:func:`verify` simulates HCFS (:func:`~stringstab.hcfs.simulate.simulate_hcfs`) behind each
leader for every jerk limit J, in the four modes (CACC alone, the learned policy alone, HCFS by
eqs 12-14, HCFS with the jerk-safe variant), evaluates the theorem at every frame of every
follower (:meth:`~stringstab.hcfs.simulate.HCFSRun.check`) and collects

* per vehicle: the largest |a_k − a_{k−1}|/T of the command (and of the vehicle), the frames
  where each premise holds or fails, the frames where the conclusion fails;
* every frame where the conclusion fails with P1 and P2 holding (a counterexample: P3 fails);
* every frame that would falsify a guarantee: the theorem (P1 ∧ P2 ∧ P3 but not C), the bound
  (P1 ∧ P2 but |a_k − a_{k−1}| above J T + |Δλ||a1_{k−1} − a2_{k−1}|), or the jerk-safe
  variant (P1 ∧ P2 but not C).  :attr:`Verification.ok` is True when there is none.

The smallest counterexample is the one with the smallest |a1_{k−1} − a2_{k−1}|, the amount by
which the dropped premise P3 fails (ties: the smaller excess over J T).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from ..errors import StringStabError
from ..traffic.trajectory import Trajectory
from .constants import BETA
from .policy import AccelerationPolicy
from .simulate import MODES, HCFSRun, RunConfig, simulate_hcfs
from .switching import check_beta
from .theorem import TheoremCheck, check_jerk_limit

__all__ = ["Frame", "Verification", "verify"]


@dataclass(frozen=True)
class Frame:
    """One frame of one follower, where something of interest happened.

    ``frame`` is the index k (t = k T) of the frame whose output is compared with frame k − 1
    (k = 0 compares with the initial state).
    """

    leader: str
    n_followers: int
    mode: str
    jerk_limit: float
    vehicle: int
    frame: int
    t: float
    jerk: float
    step: float
    step_limit: float
    gap_prev: float
    weight_change: float
    prev_switch: bool
    switch: bool
    bound: float

    @property
    def excess(self) -> float:
        """|a_k − a_{k−1}| − J T, m/s²."""
        return self.step - self.step_limit


def _frames(run: HCFSRun, i: int, chk: TheoremCheck, mask: np.ndarray) -> list[Frame]:
    cfg = run.configs[i]
    out = []
    for v, k in zip(*np.nonzero(mask)):
        out.append(Frame(
            leader=run.leader.name, n_followers=run.n_followers, mode=cfg.mode,
            jerk_limit=cfg.jerk_limit, vehicle=int(v) + 1, frame=int(k), t=float(run.t[k]),
            jerk=float(chk.step[v, k] / run.dt), step=float(chk.step[v, k]),
            step_limit=chk.step_limit, gap_prev=float(chk.gap_prev[v, k]),
            weight_change=float(chk.weight_change[v, k]), prev_switch=bool(chk.prev_switch[v, k]),
            switch=bool(chk.switch[v, k]), bound=float(chk.bound[v, k]),
        ))
    return out


def _vehicle_stats(run: HCFSRun, i: int, chk: TheoremCheck) -> list[dict[str, Any]]:
    T = run.dt
    veh_jerk = np.abs(np.diff(run.accel[i, 1:], axis=-1)).max(axis=-1) / T
    rows = []
    for v in range(run.n_followers):
        rows.append({
            "vehicle": v + 1,
            "max_jerk": float(chk.step[v].max() / T),
            "max_jerk_over_J": float(chk.step[v].max() / chk.step_limit),
            "max_vehicle_jerk": float(veh_jerk[v]),
            **chk.counts(v),
            "max_step_over_bound": float((chk.step[v] / chk.bound[v]).max()),
            "ddpg_share": float(run.use_ddpg[i, v].mean()),
            "collided": bool(run.collided[i, v]),
            "min_gap": float(run.gap[i, v].min()),
        })
    return rows


def _totals(run: HCFSRun, i: int, chk: TheoremCheck, rows: list[dict[str, Any]]) -> dict[str, Any]:
    T = run.dt
    ev = np.abs(run.speed[i, 1:] - run.speed[i, :1])
    keys = ("frames", "P1_holds", "P1_fails", "P2_holds", "P2_fails", "P3_holds", "P3_fails",
            "premises_hold", "conclusion_fails", "violations", "counterexamples",
            "bound_violations", "switches")
    tot: dict[str, Any] = {k: sum(r[k] for r in rows) for k in keys}
    tot.update(
        max_jerk=max(r["max_jerk"] for r in rows),
        max_jerk_over_J=max(r["max_jerk_over_J"] for r in rows),
        max_vehicle_jerk=max(r["max_vehicle_jerk"] for r in rows),
        max_step_over_bound=max(r["max_step_over_bound"] for r in rows),
        collisions=int(run.collided[i].sum()),
        min_gap=min(r["min_gap"] for r in rows),
        sum_abs_speed_error=float(ev.sum()),
        sum_abs_jerk=float((chk.step / T).sum()),
        sum_reward=float(np.nansum(run.reward[i])),
        ddpg_share=float(run.use_ddpg[i].mean()),
    )
    return tot


@dataclass
class Verification:
    """The result of :func:`verify`.

    Attributes
    ----------
    runs : list of HCFSRun
        One run per leader (each with every (mode, J) configuration).
    jerk_limits : tuple of float
        The J values, m/s³.
    beta : float
        β.
    results : list of dict
        One entry per (leader, mode, J): ``leader``, ``n_followers``, ``mode``, ``jerk_limit``,
        ``vehicles`` (per-vehicle statistics), ``totals`` and ``run`` (index into :attr:`runs`).
    counterexamples : list of Frame
        Every frame of the ``"paper"`` mode where the conclusion fails while P1 and P2 hold.
    violations : list of Frame
        Every frame falsifying a guarantee (theorem, bound, or the jerk-safe variant).
    """

    runs: list[HCFSRun]
    jerk_limits: tuple[float, ...]
    beta: float
    results: list[dict[str, Any]] = field(default_factory=list)
    counterexamples: list[Frame] = field(default_factory=list)
    violations: list[Frame] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True when no frame falsifies the theorem, the bound, or the jerk-safe guarantee."""
        return not self.violations

    @property
    def smallest_counterexample(self) -> Frame | None:
        """The counterexample with the smallest |a1_{k−1} − a2_{k−1}| (then the smallest excess)."""
        if not self.counterexamples:
            return None
        return min(self.counterexamples, key=lambda f: (f.gap_prev, f.excess))

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready summary (counterexamples and violations listed in full)."""
        smallest = self.smallest_counterexample
        return {
            "ok": self.ok,
            "jerk_limits": list(self.jerk_limits),
            "beta": self.beta,
            "results": self.results,
            "counterexamples": {
                "count": len(self.counterexamples),
                "smallest": None if smallest is None else {**asdict(smallest), "excess": smallest.excess},
                "frames": [asdict(f) for f in self.counterexamples],
            },
            "violations": [asdict(f) for f in self.violations],
        }


def verify(
    leaders: Sequence[Trajectory],
    policy: AccelerationPolicy,
    *,
    jerk_limits: Sequence[float],
    n_followers: int,
    beta: float = BETA,
    modes: Sequence[str] = MODES,
    progress: Any = None,
    **kwargs: Any,
) -> Verification:
    """Simulate and check the jerk theorem for every leader, jerk limit and mode.

    Parameters
    ----------
    leaders : sequence of Trajectory
        Leaders (their step is T; 0.2 s in the paper).
    policy : AccelerationPolicy
        The learned candidate a1 (a trained DDPG, or a clearly labelled stand-in).
    jerk_limits : sequence of float
        J values, m/s³ (each > 0 and finite).
    n_followers : int
        N.
    beta : float
        β at a switch (eq 14).
    modes : sequence of str
        Subset of :data:`~stringstab.hcfs.simulate.MODES`.
    progress : callable, optional
        Called with 1 after each leader (a progress bar's ``update``).
    **kwargs
        Passed to :func:`~stringstab.hcfs.simulate.simulate_hcfs` (gains, delay, spacing, …).

    Returns
    -------
    Verification

    Raises
    ------
    StringStabError
        On a bad J, β, mode or leader.

    Examples
    --------
    >>> from stringstab.traffic import stop_and_go
    >>> from stringstab.hcfs.policy import LeaderSpeedMatcher
    >>> v = verify([stop_and_go(waves=1, dt=0.2)], LeaderSpeedMatcher(), jerk_limits=[2.5],
    ...            n_followers=2)
    >>> v.ok, len(v.results)
    (True, 4)
    """
    Js = tuple(check_jerk_limit(J) for J in jerk_limits)
    if not Js:
        raise StringStabError("at least one jerk limit J is needed; got none")
    b = check_beta(beta)
    bad = [m for m in modes if m not in MODES]
    if bad or not modes:
        raise StringStabError(f"modes must be a non-empty subset of {list(MODES)}; got {list(modes)}")
    if not leaders:
        raise StringStabError("at least one leader is needed; got none")
    configs = [RunConfig(m, J) for J in Js for m in modes]
    ver = Verification(runs=[], jerk_limits=Js, beta=b)
    for leader in leaders:
        run = simulate_hcfs(leader, policy, n_followers=n_followers, configs=configs, beta=b, **kwargs)
        ver.runs.append(run)
        for i, cfg in enumerate(run.configs):
            chk = run.check(i)
            rows = _vehicle_stats(run, i, chk)
            ver.results.append({"run": len(ver.runs) - 1, "leader": leader.name,
                                "n_followers": run.n_followers,
                                "mode": cfg.mode, "jerk_limit": cfg.jerk_limit,
                                "vehicles": rows, "totals": _totals(run, i, chk, rows)})
            if cfg.mode == "paper":
                ver.counterexamples += _frames(run, i, chk, chk.counterexamples)
            bad_mask = chk.violations | chk.bound_violations
            if cfg.mode in ("safe", "cacc", "policy"):
                bad_mask = bad_mask | (chk.rate_ddpg & chk.rate_cacc & ~chk.conclusion)
            ver.violations += _frames(run, i, chk, bad_mask)
        if progress is not None:
            progress(1)
    return ver
