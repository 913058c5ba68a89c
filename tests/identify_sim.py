"""Simulated logs for the identify tests, written independently of stringstab.identify.

:func:`step_follower` steps the follower model of docs/identify.md directly — x = (s, v, a),
τ a' = u(t − θ_r) − a with the command u held over each step (zero-order hold), the lag
integrated by matrix exponentials over each sub-step (before and after the delayed command
changes), a Python loop with a command buffer — so a test that compares it with
:func:`stringstab.identify.simulate_follower` (an lfilter over closed-form polynomials) compares
two implementations.  :func:`car_log` makes a two-vehicle OpenACC-like log of one car behind a
leader that holds several speeds (so the spacing policy has quasi-steady stretches at each).
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from scipy.linalg import expm

from stringstab.identify import FollowerModel, PlatoonLog
from stringstab.identify.closed_loop import delayed


def step_follower(m: FollowerModel, v_pred, a_pred, dt: float, s0: float, v0: float, a0: float):
    """Gap and speed of the follower, stepped directly (module docstring); commands before t_0
    equal a_0; the predecessor's displacement is the trapezoid of its speed."""
    Ac = np.array([[0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0 / m.tau]])
    Bc = np.array([0.0, 0.0, 1.0 / m.tau])

    def step(h: float):
        M = np.zeros((4, 4))
        M[:3, :3] = Ac
        M[:3, 3] = Bc
        E = expm(M * h)
        return E[:3, :3], E[:3, 3]

    q = math.floor(m.reaction_delay / dt + 1e-9)
    eps = m.reaction_delay - q * dt
    A1, b1 = step(eps)
    A2, b2 = step(dt - eps)
    ap = delayed(a_pred, m.delta, dt) if a_pred is not None else np.zeros_like(v_pred)
    x = np.array([s0, v0, a0])
    u_hist: list[float] = []
    gap, speed = [], []
    for k in range(v_pred.size):
        gap.append(x[0])
        speed.append(x[1])
        u = (m.k_x * (x[0] - m.headway * x[1] - m.standstill) + m.k_v * (v_pred[k] - x[1])
             + m.k_a * ap[k])
        u_hist.append(u)
        if k == v_pred.size - 1:
            break
        early = u_hist[k - q - 1] if k - q - 1 >= 0 else a0
        late = u_hist[k - q] if k - q >= 0 else a0
        x = A1 @ x + b1 * early
        x = A2 @ x + b2 * late
        x[0] += 0.5 * dt * (v_pred[k] + v_pred[k + 1])
    return np.array(gap), np.array(speed)


def leader_with_holds(speeds, *, hold: float = 35.0, ramp: float = 12.0, dt: float = 0.1,
                      wiggle: float = 0.3):
    """A leader holding each speed of ``speeds`` for ``hold`` s, joined by cosine ramps of
    ``ramp`` s, with a small ``wiggle`` (m/s) at 0.35 rad/s on top; returns (t, v)."""
    pieces = [np.full(round(hold / dt), float(speeds[0]))]
    for a, b in itertools.pairwise(speeds):
        r = np.arange(round(ramp / dt)) / round(ramp / dt)
        pieces.append(a + (b - a) * 0.5 * (1 - np.cos(np.pi * r)))
        pieces.append(np.full(round(hold / dt), float(b)))
    v = np.concatenate(pieces)
    t = np.arange(v.size) * dt
    return t, v + wiggle * np.sin(0.35 * t)


def car_log(m: FollowerModel, speeds, *, setting: str = "S", seed: int = 0, noise: bool = True,
            name: str = "TEST_CAR", ramp: float = 12.0) -> PlatoonLog:
    """A leader (``speeds`` held, :func:`leader_with_holds`) and one car obeying ``m``, from the
    car's equilibrium at the first speed, with GPS-like noise (speed σ = 0.05 m/s, gap σ = 0.2 m);
    OpenACC metadata with ``Distance_setting`` = ``setting`` and ACC on; ``ramp`` (s) sets how
    fast the leader changes speed."""
    t, vp = leader_with_holds(speeds, ramp=ramp)
    dt = float(t[1] - t[0])
    s_eq = m.standstill + m.headway * vp[0]
    gap, v = step_follower(m, vp, None, dt, s_eq, float(vp[0]), 0.0)
    rng = np.random.default_rng(seed)
    if noise:
        v = v + rng.normal(0, 0.05, v.shape)
        vp = vp + rng.normal(0, 0.05, vp.shape)
        gap = gap + rng.normal(0, 0.2, gap.shape)
    meta = {"Vehicle_order": ["LEAD", name], "Number_of_vehicles": ["2"], "ACC": ["1"],
            "Distance_setting": [setting]}
    return PlatoonLog(t, (0, 1), ("LEAD", name), np.stack([vp, v]), {1: gap}, None,
                      f"<{name}-{setting}-{seed}>", "openacc", meta)
