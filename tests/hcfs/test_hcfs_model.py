"""The HCFS model pieces against independent truths: V2V delay, state (eq 3), reward (eqs 4-6),
the eq-11 CACC and its closed loop, the eq-12 one-step prediction."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from stringstab.errors import StringStabError
from stringstab.hcfs import constants as C
from stringstab.hcfs.cacc import CACC, cacc_acceleration, cacc_printed, closed_loop_matrix
from stringstab.hcfs.mdp import received, reward, state
from stringstab.hcfs.policy import LeaderSpeedMatcher, ScaledPolicy, accelerations, rate_limit
from stringstab.hcfs.simulate import simulate_hcfs
from stringstab.hcfs.switching import (
    check_beta,
    choose,
    predicted_lead_speed,
    predicted_rewards,
    switch_weights,
)
from stringstab.traffic.trajectory import from_accel_segments


@given(x=st.floats(-1e3, 1e3), v=st.floats(0, 40), a=st.floats(-3, 3),
       delay=st.floats(0, 0.2))
def test_received_is_the_state_delay_seconds_ago(x, v, a, delay):
    """Integrate backwards in closed form: x(t−δ) = x − vδ + aδ²/2 at constant a, v(t−δ) = v − aδ."""
    x0, v0 = x - v * delay + 0.5 * a * delay**2, v - a * delay  # state at t − δ
    # forward from t − δ with a held: the state now
    x_now, v_now = x0 + v0 * delay + 0.5 * a * delay**2, v0 + a * delay
    xr, vr = received(x_now, v_now, a, delay)
    np.testing.assert_allclose([xr, vr], [x0, v0], rtol=1e-12, atol=1e-9)


def test_state_signs_and_values():
    """Hand-computed eq-3 state: leader at 100 m, follower 1 too close, follower 2 too far."""
    L, h = C.LENGTH, C.SPACING
    x = np.array([100.0, 100.0 - (L + h) + 1.0, 100.0 - 2 * (L + h) - 1.0])
    v = np.array([20.0, 21.0, 19.0])
    a = np.array([0.0, 0.5, -0.5])
    s = state(x, v, a, delay=0.0)
    np.testing.assert_allclose(s, [[1.0, 1.0, 1.0, 1.0, 21.0, 0.5],
                                   [-2.0, -2.0, -1.0, -1.0, 19.0, -0.5]], rtol=0, atol=1e-12)
    with pytest.raises(StringStabError, match="share a shape"):
        state(x, v[:2], a, delay=0.0)


def test_reward_matches_eqs_4_to_6():
    r, r_v, r_j = reward([0.5, -0.5], [1.0, 1.0], [0.0, 3.0], omega_1=2.0, omega_2=3.0,
                         speed_max=10.0, accel_max=3.0, dt=0.2)
    np.testing.assert_allclose(r_v, [-0.1, -0.1], rtol=0, atol=1e-15)
    # |jerk| / (2 a_max / T) = |Δa| / (2 a_max)
    np.testing.assert_allclose(r_j, [-3.0 / 6.0, -3.0 * 2.0 / 6.0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(r, r_v + r_j, rtol=0, atol=0)


def test_reward_weights_reproduce_table_iv():
    w = C.reward_weights_from_table_iv()
    assert w["omega_1"] == pytest.approx(C.OMEGA_1, abs=0.005)
    assert w["omega_2"] == pytest.approx(C.OMEGA_2, abs=5e-5)
    assert w["hcfs_predicted"] == pytest.approx(w["hcfs_printed"], rel=0.01)


def test_cacc_derived_and_printed():
    s = np.array([[1.0, 2.0, 3.0, 4.0, 10.0, 0.0]])
    k = (0.1, 0.4, 0.05, 0.2)
    pd = 0.1 * 1 + 0.4 * 2 + 0.05 * 3 + 0.2 * 4
    np.testing.assert_allclose(cacc_acceleration(s, k, dt=0.2), [-pd / 0.2], rtol=1e-15)
    np.testing.assert_allclose(cacc_printed(s, k), [10.0 + pd], rtol=1e-15)
    np.testing.assert_allclose(CACC(k, dt=0.2)(s), [-pd / 0.2], rtol=1e-15)
    with pytest.raises(StringStabError, match="four finite numbers"):
        CACC((1.0, 2.0, 3.0))
    with pytest.raises(StringStabError, match="6 components"):
        cacc_acceleration(np.zeros((2, 5)))


def _rho(A):
    return float(max(abs(np.linalg.eigvals(A))))


@pytest.mark.parametrize("n", [1, 4, 6, 8])
def test_cacc_closed_loop_is_stable_and_the_printed_signs_are_not(n):
    assert _rho(closed_loop_matrix(n)) < 0.96
    assert _rho(closed_loop_matrix(n, sign=-1.0)) > 1.0


def test_closed_loop_matrix_matches_the_simulator():
    """After a one-frame leader acceleration the relative state evolves by the matrix exactly."""
    leader = from_accel_segments([(0.0, 1.0), (1.0, 0.2), (0.0, 6.0)], speed0=10.0, dt=0.2)
    run = simulate_hcfs(leader, LeaderSpeedMatcher(), n_followers=4, configs=[("cacc", 1e6)],
                        delay=0.0)
    k0 = 6  # leader constant from frame 6 on
    L, h = C.LENGTH, C.SPACING

    def rel(k):
        x = run.position[0, :, k]
        v = run.speed[0, :, k]
        desired = x[0] - np.arange(1, 5) * (L + h)
        return np.r_[x[1:] - desired, v[1:] - v[0]]

    A = closed_loop_matrix(4, dt=0.2)
    z = rel(k0)
    assert np.abs(z).max() > 1e-3  # a real transient
    for k in range(k0 + 1, leader.n_steps):
        z = A @ z
        np.testing.assert_allclose(rel(k), z, rtol=0, atol=1e-9)


def test_cacc_spacing_errors_shrink_along_the_platoon():
    """Without a binding jerk limit the CACC attenuates spacing errors along 8 followers (us06)."""
    from stringstab.traffic.leaders import leader_by_name

    lead = leader_by_name("us06", dt=C.DT, duration=150)
    run = simulate_hcfs(lead, LeaderSpeedMatcher(), n_followers=8, configs=[("cacc", 1e6)])
    err = np.abs(run.gap[0] - C.SPACING).max(axis=-1)
    assert not run.collided.any()
    assert (np.diff(err[1:]) < 0).all() and err[-1] < 0.5 * err[0]


def test_one_step_prediction_is_exact_for_a_constant_acceleration_leader():
    """predicted_lead_speed: v(t_k+1) from the speeds received at t_k − δ and t_{k−1} − δ."""
    a, T, d = 1.3, 0.2, 0.005
    v = lambda t: 10.0 + a * t  # noqa: E731
    pred = predicted_lead_speed(v(1.0 - d), v(1.0 - T - d), delay=d, dt=T)
    assert float(pred) == pytest.approx(v(1.0 + T), abs=1e-12)


def test_predicted_rewards_and_choice():
    """The candidate closer to the predicted leader speed wins unless its jerk costs more."""
    cands = np.array([0.0, 1.0])
    r = predicted_rewards(cands, 10.0, 10.2, 0.0, omega_1=1.0, omega_2=0.0, speed_max=1.0, dt=0.2)
    np.testing.assert_allclose(r, [-0.2, 0.0], rtol=0, atol=1e-12)
    r = predicted_rewards(cands, 10.0, 10.2, 0.0, omega_1=1.0, omega_2=1.0, speed_max=1.0,
                          accel_max=0.1, dt=0.2)
    np.testing.assert_allclose(r, [-0.2, -5.0], rtol=0, atol=1e-12)
    assert choose(r[1], r[0]).item() is False
    assert choose(-1.0, -1.0).item() is False  # a tie goes to CACC


def test_switch_weights_eqs_13_14():
    lam, alpha = switch_weights([True, True, False, False, True], beta=0.3)
    np.testing.assert_allclose(lam, [0.7, 1.0, 0.3, 0.0, 0.7], rtol=0, atol=1e-15)
    assert alpha.tolist() == [True, False, True, False, True]
    lam, _ = switch_weights([True, False], beta=0.0)  # the hard switch of eq 12
    assert lam.tolist() == [1.0, 0.0]
    for bad in (-0.1, 1.1, float("nan"), "x"):
        with pytest.raises(StringStabError, match=r"beta must be a number in \[0, 1\]"):
            check_beta(bad)


def test_rate_limit_and_policy_seam():
    out = rate_limit([10.0, -10.0, 0.1], [2.9, -2.9, 0.0], 0.5)
    np.testing.assert_allclose(out, [3.0, -3.0, 0.1], rtol=0, atol=0)
    s = np.zeros((2, 3, 6))
    s[..., 3] = 0.1
    assert accelerations(LeaderSpeedMatcher(kappa=1.0, dt=0.2), s).shape == (2, 3)
    np.testing.assert_allclose(accelerations(LeaderSpeedMatcher(kappa=1.0, dt=0.2), s), -0.5)
    with pytest.raises(StringStabError, match="one acceleration per state"):
        accelerations(lambda z: np.zeros((len(z), 2)), s)
    with pytest.raises(StringStabError, match="NaN or inf"):
        accelerations(lambda z: np.full(len(z), np.nan), s)
    p = ScaledPolicy(lambda z: z[:, :1], scales=[2, 1, 1, 1, 1, 1])
    np.testing.assert_allclose(accelerations(p, np.ones((1, 6))), [0.5])


def test_a_torch_policy_with_the_wrong_input_size_is_refused_in_one_line():
    torch = pytest.importorskip("torch")
    net = torch.nn.Linear(5, 1)  # expects 5 inputs; the HCFS state has 6

    def policy(s):
        with torch.no_grad():
            return net(torch.as_tensor(s, dtype=torch.float32)).numpy()

    with pytest.raises(StringStabError, match="failed on a state batch"):
        accelerations(policy, np.zeros((3, 6)))


@pytest.mark.parametrize("value", [True, False, float("inf"), 2.5, "x", 0])
def test_count_refuses_what_is_not_a_count(value):
    from stringstab.params import count

    with pytest.raises(StringStabError, match="must be an integer >= 1"):
        count("n_followers", value)
