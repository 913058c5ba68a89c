"""The reaction delay θ_r in identify's closed loop (stringstab.identify.closed_loop): the
two-pass filter against a direct time-stepping of the same model, written independently here
(matrix exponentials of the continuous lag over each sub-step, a Python loop, a command
buffer), for fractional and whole-step delays, with and without k_a."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm

from stringstab.identify import FollowerModel, simulate_follower
from stringstab.identify.closed_loop import delayed


def _direct(m: FollowerModel, v_pred, a_pred, dt: float, s0: float, v0: float, a0: float):
    """Step the model x = (s, v, a), τ a' = u(t − θ_r) − a, u held over each step (ZOH), the
    predecessor's displacement the trapezoid of its speed; commands before t_0 equal a_0."""
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


@pytest.mark.parametrize(("theta", "k_x", "k_v", "k_a", "delta"), [
    (0.35, 0.25, 0.6, 0.0, 0.0), (0.05, 0.25, 0.6, 0.0, 0.0), (1.2, 0.05, 0.3, 0.0, 0.0),
    (0.4, 0.25, 0.6, 0.5, 0.15), (0.999999, 0.1, 0.4, 0.0, 0.0)])
def test_delayed_loop_matches_direct_stepping(theta: float, k_x: float, k_v: float, k_a: float,
                                              delta: float) -> None:
    dt = 0.1
    t = np.arange(0.0, 80.0, dt)
    v_pred = 15 + 3 * np.sin(0.3 * t) + np.sin(1.1 * t + 0.4)
    a_pred = 0.9 * np.cos(0.3 * t) + 1.1 * np.cos(1.1 * t + 0.4)
    m = FollowerModel(k_x, k_v, k_a, 0.45, delta, 1.3, 4.0, reaction_delay=theta)
    s0, v0, a0 = 25.0, 14.5, 0.3
    g, v = simulate_follower(m, v_pred, dt, s0=s0, v0=v0, a0=a0, a_pred=a_pred)
    g_ref, v_ref = _direct(m, v_pred, a_pred, dt, s0, v0, a0)
    assert np.abs(v_ref - v_pred).max() < 10  # a loop that follows (the check is not of a blow-up)
    np.testing.assert_allclose(g, g_ref, rtol=0, atol=1e-8)
    np.testing.assert_allclose(v, v_ref, rtol=0, atol=1e-8)


def test_delay_changes_the_response() -> None:
    """Not a no-op: θ_r = 0.5 s moves the simulated speed by more than the 1e-8 tolerance above
    (by centimetres per second here), and θ_r → 0 joins the undelayed loop."""
    dt = 0.1
    t = np.arange(0.0, 60.0, dt)
    v_pred = 15 + 3 * np.sin(0.4 * t)
    base = FollowerModel(0.25, 0.6, 0.0, 0.45, 0.0, 1.3, 4.0)
    _, v0 = simulate_follower(base, v_pred, dt, s0=23.5, v0=15.0)
    _, v1 = simulate_follower(FollowerModel(0.25, 0.6, 0.0, 0.45, 0.0, 1.3, 4.0, 0.5), v_pred, dt,
                              s0=23.5, v0=15.0)
    assert np.abs(v1 - v0).max() > 0.05
    _, v2 = simulate_follower(FollowerModel(0.25, 0.6, 0.0, 0.45, 0.0, 1.3, 4.0, 1e-7), v_pred, dt,
                              s0=23.5, v0=15.0)
    np.testing.assert_allclose(v2, v0, rtol=0, atol=1e-5)
