"""The reaction delay θ_r in identify's closed loop (stringstab.identify.closed_loop): the
closed-loop filter against a direct time-stepping of the same model written apart from it
(``tests/identify_sim.py``: matrix exponentials of the continuous lag over each sub-step, a
Python loop, a command buffer), for fractional and whole-step delays, with and without k_a,
to 1e-8 m and m/s over 80 s (measured: 1e-10, not growing with the log's length)."""

from __future__ import annotations

import numpy as np
import pytest

from stringstab.identify import FollowerModel, simulate_follower
from tests.identify_sim import step_follower


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
    g_ref, v_ref = step_follower(m, v_pred, a_pred, dt, s0, v0, a0)
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
