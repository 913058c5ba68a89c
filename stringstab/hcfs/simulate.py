"""Closed-loop HCFS: a platoon behind a leader under CACC, the learned policy, or the hybrid switch.

The set-up of HCFS §IV: every follower computes both candidates from its eq-3 state each frame
(T = 0.2 s), and its acceleration is held over the frame,

    v_{k+1} = v_k + a_k T,   x_{k+1} = x_k + v_k T + ½ a_k T²

(:class:`stringstab.traffic.dynamics.Platoon` with ``model="kinematic"``, which also applies
the acceleration bounds [a_min, a_max], the speed bounds [0, v_max] and detects collisions).
Predecessor and leader data arrive 5 ms late (:func:`stringstab.hcfs.mdp.received`).

Each candidate is rate-limited to J T about its own previous value
(:func:`~stringstab.hcfs.policy.rate_limit`), which is the theorem's premise (P1, P2).  One
run steps several *configurations* (mode, J) at once behind one leader:

``"cacc"``      the CACC candidate alone;
``"policy"``    the learned (or stand-in) candidate alone;
``"paper"``     HCFS by eqs 12-14 (β at a switch);
``"safe"``      HCFS with the jerk-safe variant (:func:`~stringstab.hcfs.switching.limit_step`).

The hybrid output of the frame before the start is the followers' initial acceleration (0),
both candidates' memories start there too, and the strategy starts on CACC (the
``"policy"`` mode on the policy, so that it never blends).

References
----------
HCFS paper, §III-C and §IV.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..params import count, positive
from ..traffic.dynamics import Platoon
from ..traffic.limits import Limits
from ..traffic.trajectory import Trajectory
from .cacc import CACC
from .constants import (
    ACCEL_MAX,
    ACCEL_MIN,
    BETA,
    CACC_GAINS,
    LENGTH,
    OMEGA_1,
    OMEGA_2,
    SPACING,
    SPEED_MAX,
    V2V_DELAY,
)
from .mdp import received, reward, state
from .policy import AccelerationPolicy, accelerations, policy_label, rate_limit
from .switching import (
    check_beta,
    choose,
    limit_step,
    predicted_lead_speed,
    predicted_rewards,
    step_weight,
)
from .theorem import TheoremCheck, check_jerk_limit, check_theorem

__all__ = ["MODES", "HCFSRun", "RunConfig", "simulate_hcfs"]

Array = npt.NDArray[np.float64]

#: The configurations a run can step (see the module docstring).
MODES = ("cacc", "policy", "paper", "safe")


@dataclass(frozen=True)
class RunConfig:
    """One configuration of a run: the mode and the jerk limit J (m/s³)."""

    mode: str
    jerk_limit: float

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise StringStabError(f"mode must be one of {list(MODES)}; got {self.mode!r}")
        object.__setattr__(self, "jerk_limit", check_jerk_limit(self.jerk_limit))


@dataclass
class HCFSRun:
    """A closed-loop run: arrays ``(B, N, K)`` for B configurations, N followers, K frames.

    Attributes
    ----------
    leader : Trajectory
        The leader (its step is T).
    configs : tuple of RunConfig
        The B configurations.
    t : array (K,)
        Frame times, s.
    speed, position : array (B, N + 1, K)
        State at each frame (column 0 the leader), m/s and m.
    accel : array (B, N + 1, K)
        Acceleration held over each frame (after the speed bounds), m/s².
    raw_ddpg, raw_cacc : array (B, N, K)
        The candidates before any limit, m/s².
    a_ddpg, a_cacc : array (B, N, K)
        The candidates a1, a2 after the bounds and the J T rate limit, m/s².
    use_ddpg : bool array (B, N, K)
        The choice applied (eq 12 in the HCFS modes; constant in the single-controller modes).
    weight : array (B, N, K)
        λ_k, the weight of a1 in the output (for ``"safe"``, the weight after the limit).
    output : array (B, N, K)
        The strategy's command a_k, m/s².
    reward_ddpg, reward_cacc : array (B, N, K)
        The predicted eq-6 rewards the choice compared.
    reward : array (B, N, K)
        The eq-6 reward earned, r_k(s_{k+1} | a_k, s_k) (NaN at the last frame).
    gap : array (B, N, K)
        Bumper-to-bumper gaps, m.
    collided : bool array (B, N)
        Followers that ever had a gap ≤ 0.
    params : dict
        β, δ, L, h, limits, gains, the policies' labels.
    """

    leader: Trajectory
    configs: tuple[RunConfig, ...]
    t: Array
    speed: Array
    position: Array
    accel: Array
    raw_ddpg: Array
    raw_cacc: Array
    a_ddpg: Array
    a_cacc: Array
    use_ddpg: npt.NDArray[np.bool_]
    weight: Array
    output: Array
    reward_ddpg: Array
    reward_cacc: Array
    reward: Array
    gap: Array
    collided: npt.NDArray[np.bool_]
    params: dict[str, Any] = field(default_factory=dict)

    @property
    def dt(self) -> float:
        """T, s."""
        return float(self.leader.dt)

    @property
    def n_followers(self) -> int:
        """N."""
        return int(self.output.shape[1])

    def index(self, mode: str, jerk_limit: float) -> int:
        """Position of configuration (mode, J) in :attr:`configs`.

        Parameters
        ----------
        mode : str
            The strategy (``"cacc"``, ``"policy"``, ``"paper"``, ``"safe"``).
        jerk_limit : float
            J, m/s³ (matched to a relative 1e-12).

        Returns
        -------
        int
            The index into :attr:`configs` and the per-configuration arrays.

        Raises
        ------
        StringStabError
            If the run has no such configuration.
        """
        for i, c in enumerate(self.configs):
            if c.mode == mode and np.isclose(c.jerk_limit, jerk_limit, rtol=1e-12, atol=0.0):
                return i
        raise StringStabError(
            f"no configuration ({mode!r}, J={jerk_limit!r}) in this run; it has "
            f"{[(c.mode, c.jerk_limit) for c in self.configs]}"
        )

    def check(self, i: int) -> TheoremCheck:
        """The theorem evaluated on configuration ``i`` (all followers, all frames).

        The frame before the start (both candidates and the output at the initial
        acceleration, the strategy on CACC) is prepended, so the K transitions
        −1 → 0, …, K − 2 → K − 1 are checked.  The checker recomputes the eq-13 output from the
        applied choices (the same arithmetic as the run, so the same numbers); for ``"safe"``
        it takes the applied, clipped output.

        Parameters
        ----------
        i : int
            Index of the configuration (:meth:`index`).

        Returns
        -------
        TheoremCheck
            Premises P1-P3, the conclusion and the bound (HCFS §III-C) at every follower and frame
            (:func:`stringstab.hcfs.theorem.check_theorem`).
        """
        a0 = self.params["initial_accel"]
        c0 = self.configs[i].mode == "policy"

        def pre(x: Any, v: Any) -> Any:
            return np.concatenate([np.full((*x.shape[:-1], 1), v, dtype=x.dtype), x], axis=-1)

        return check_theorem(
            pre(self.a_ddpg[i], a0), pre(self.a_cacc[i], a0), pre(self.use_ddpg[i], c0),
            jerk_limit=self.configs[i].jerk_limit, dt=self.dt, beta=self.params["beta"],
            initial=c0,
            output=pre(self.output[i], a0) if self.configs[i].mode == "safe" else None,
        )


def simulate_hcfs(
    leader: Trajectory,
    policy: AccelerationPolicy,
    *,
    n_followers: int,
    configs: Sequence[RunConfig | tuple[str, float]],
    beta: float = BETA,
    cacc_gains: Sequence[float] = CACC_GAINS,
    delay: float = V2V_DELAY,
    length: float = LENGTH,
    spacing: float = SPACING,
    accel_min: float = ACCEL_MIN,
    accel_max: float = ACCEL_MAX,
    speed_max: float = SPEED_MAX,
    omega_1: float = OMEGA_1,
    omega_2: float = OMEGA_2,
) -> HCFSRun:
    """Simulate N followers behind ``leader`` for every configuration (mode, J) at once.

    Parameters
    ----------
    leader : Trajectory
        The leader; its step is the frame period T (0.2 s in the paper).
    policy : AccelerationPolicy
        The learned candidate a1 (a trained DDPG, or a clearly labelled stand-in).
    n_followers : int
        N (the paper uses 4, 6 and 8).
    configs : sequence of RunConfig or (mode, J)
        Modes from :data:`MODES` and jerk limits J (m/s³).
    beta : float
        β at a switch (eq 14: 0.5).
    cacc_gains : (k1, k2, k3, k4)
        Gains of the eq-11 CACC.
    delay : float
        V2V delay δ, s (5 ms), 0 ≤ δ ≤ T.
    length, spacing : float
        L and h, m; followers start at the desired spacing, at the leader's speed, with a = 0.
    accel_min, accel_max, speed_max : float
        Bounds of the action and of the speed.
    omega_1, omega_2 : float
        Reward weights of eqs 4-5.

    Returns
    -------
    HCFSRun

    Raises
    ------
    StringStabError
        On bad parameters or a policy returning NaN or the wrong shape.

    Examples
    --------
    >>> from stringstab.traffic import sinusoid
    >>> from stringstab.hcfs.policy import LeaderSpeedMatcher
    >>> lead = sinusoid(omega=0.5, amplitude=2.0, speed=10.0, duration=10.0, dt=0.2)
    >>> run = simulate_hcfs(lead, LeaderSpeedMatcher(), n_followers=2,
    ...                     configs=[("paper", 5.0), ("safe", 5.0)])
    >>> run.output.shape, run.check(1).counts()["conclusion_fails"]
    ((2, 2, 51), 0)
    """
    if not all(hasattr(leader, a) for a in ("dt", "position", "speed", "accel", "n_steps")):
        raise StringStabError(f"leader must be a Trajectory; got {type(leader).__name__}")
    N = count("n_followers", n_followers)
    cfgs = tuple(c if isinstance(c, RunConfig) else RunConfig(*c) for c in configs)
    if not cfgs:
        raise StringStabError("configs must name at least one (mode, jerk limit)")
    b = check_beta(beta)
    T = float(leader.dt)
    d = positive("V2V delay", delay, allow_zero=True, unit=" s")
    if d > T:
        raise StringStabError(f"the V2V delay must be at most one frame T={T!r} s; got {delay!r}")
    limits = Limits(accel_min=accel_min, accel_max=accel_max, speed_min=0.0, speed_max=speed_max)
    cacc = CACC(cacc_gains, dt=T)
    B, K = len(cfgs), leader.n_steps
    modes = np.array([c.mode for c in cfgs])
    step_limit = np.array([c.jerk_limit * T for c in cfgs])[:, None]
    forced = np.isin(modes, ("cacc", "policy"))[:, None]
    forced_choice = (modes == "policy")[:, None]
    safe = (modes == "safe")[:, None]

    plat = Platoon(B, N, dt=T, model="kinematic", delta=0.0, limits=limits, length=length)
    LX, LV, LA = leader.position, leader.speed, leader.accel
    a_init = 0.0
    plat.reset(np.full(B, LX[0]), np.full(B, LV[0]), np.full(B, LA[0]), gap=float(spacing),
               speed=float(LV[0]), accel=a_init)
    rec = {name: np.empty((B, N, K)) for name in
           ("raw_ddpg", "raw_cacc", "a_ddpg", "a_cacc", "weight", "output", "reward_ddpg",
            "reward_cacc", "gap")}
    use = np.empty((B, N, K), dtype=bool)
    spd = np.empty((B, N + 1, K))
    pos = np.empty((B, N + 1, K))
    acc = np.empty((B, N + 1, K))
    rew = np.full((B, N, K), np.nan)
    prev1 = np.full((B, N), a_init)
    prev2 = np.full((B, N), a_init)
    prev_out = np.full((B, N), a_init)
    prev_choice = np.broadcast_to(forced_choice, (B, N)).copy()  # HCFS starts on CACC
    prev_lead_rx: Array | None = None
    weights = {"omega_1": omega_1, "omega_2": omega_2, "speed_max": speed_max, "accel_max": accel_max}
    for k in range(K):
        obs = plat.observe(np.full(B, LX[k]), np.full(B, LV[k]), np.full(B, LA[k]))
        last = plat.accel.copy()
        last[:, 0] = LA[k - 1] if k else LA[0]
        s = state(plat.position, plat.speed, last, delay=d, length=length, spacing=spacing)
        raw1 = accelerations(policy, s)
        raw2 = accelerations(cacc, s)
        a1 = rate_limit(raw1, prev1, step_limit, accel_min=accel_min, accel_max=accel_max)
        a2 = rate_limit(raw2, prev2, step_limit, accel_min=accel_min, accel_max=accel_max)
        _, lead_rx = received(plat.position[:, :1], plat.speed[:, :1], last[:, :1], d)
        v_hat = predicted_lead_speed(lead_rx, lead_rx if prev_lead_rx is None else prev_lead_rx,
                                     delay=d, dt=T)
        ego_v = plat.speed[:, 1:]
        r1 = predicted_rewards(a1, ego_v, v_hat, prev_out, dt=T, **weights)
        r2 = predicted_rewards(a2, ego_v, v_hat, prev_out, dt=T, **weights)
        choice = np.where(forced, forced_choice, choose(r1, r2))
        lam, _ = step_weight(choice, prev_choice, b)
        target = lam * a1 + (1.0 - lam) * a2
        out = np.where(safe, limit_step(target, prev_out, step_limit), target)
        if safe.any():
            diff = a1 - a2
            far = np.abs(diff) > 1e-12
            lam = np.where(safe & far, (out - a2) / np.where(far, diff, 1.0), lam)
        for name, val in (("raw_ddpg", raw1), ("raw_cacc", raw2), ("a_ddpg", a1), ("a_cacc", a2),
                          ("weight", lam), ("output", out), ("reward_ddpg", r1),
                          ("reward_cacc", r2), ("gap", obs.gap)):
            rec[name][:, :, k] = val
        use[:, :, k] = choice
        pos[:, :, k] = plat.position
        spd[:, :, k] = plat.speed
        if k < K - 1:
            plat.advance(out)
            ev_next = plat.speed[:, 1:] - LV[k + 1]
            rew[:, :, k], _, _ = reward(ev_next, out, prev_out, dt=T, **weights)
            acc[:, 1:, k] = plat.accel[:, 1:]
        else:
            acc[:, 1:, k] = np.clip(out, accel_min, accel_max)
        acc[:, 0, k] = LA[k]
        prev1, prev2, prev_out, prev_choice, prev_lead_rx = a1, a2, out, choice, lead_rx
    params = {
        "beta": b, "delay": d, "dt": T, "length": float(length), "spacing": float(spacing),
        "accel_min": accel_min, "accel_max": accel_max, "speed_max": speed_max,
        "omega_1": omega_1, "omega_2": omega_2, "cacc_gains": list(cacc.gains),
        "cacc_label": cacc.label, "policy_label": policy_label(policy),
        "policy_is_stand_in": bool(getattr(policy, "is_stand_in", False)),
        "initial_accel": a_init, "leader": leader.name,
    }
    return HCFSRun(leader=leader, configs=cfgs, t=leader.t, speed=spd, position=pos, accel=acc,
                   use_ddpg=use, reward=rew, collided=plat.collided.copy(), params=params,
                   **rec)
