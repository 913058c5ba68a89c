"""The Gymnasium environments: API conformance, state (eq 16), reward (eq 18), batching."""

import warnings

import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from numpy.testing import assert_allclose

from stringstab.errors import StringStabError
from stringstab.traffic import (
    BatchedCarFollowingEnv,
    CarFollowingEnv,
    FollowingPair,
    LinearController,
    from_accel_segments,
    hard_braking,
    paper_mix,
    simulate,
)

K = np.array([1.2, 0.5, 0.6], dtype=np.float32)


@pytest.mark.parametrize("action", ["gains", "accel"])
def test_check_env(action):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # advice about unbounded Box observations
        check_env(CarFollowingEnv([paper_mix()], action=action), skip_render_check=True)


def test_gain_episode_reproduces_the_simulator():
    """Playing the fixed-gain action through the env is the eq-4 controller in simulate()."""
    lead = paper_mix()
    env = CarFollowingEnv([lead])
    obs, _ = env.reset(seed=0)
    assert_allclose(obs, 0.0, atol=1e-6)  # starts in equilibrium
    gaps, accels, done, steps = [], [], False, 0
    while not done:
        obs, r, term, trunc, info = env.step(K)
        gaps.append(info["gap"])
        accels.append(info["accel"])
        assert -1.0 <= r <= 0.0
        done = term or trunc
        steps += 1
    assert trunc and not term and steps == lead.n_steps - 1
    res = simulate(lead, LinearController(*K.astype(float)), 1)
    assert_allclose(gaps, res.gap[0, 1:], rtol=1e-6, atol=1e-6)
    assert_allclose(accels, res.accel[1, 1:], rtol=1e-6, atol=1e-6)


def test_state_is_eq_16():
    lead = from_accel_segments([(0.0, 5.0)], speed0=20.0)
    env = CarFollowingEnv([lead], action="accel", delta=0.0)
    env.reset(seed=0)
    obs, _r, *_ , info = env.step(np.array([1.0], dtype=np.float32))
    gap, v = info["gap"], info["speed"]
    expected = [(gap - (1.1 * v + 2.0)) / 25.0, (20.0 - v) / 2.5, 0.0 / 4.5]
    assert_allclose(obs, expected, rtol=1e-5, atol=1e-6)


def test_reward_is_eq_18_mean_of_terms():
    env = CarFollowingEnv([paper_mix()])
    env.reset(seed=0)
    for _ in range(50):
        _, r, _, _, info = env.step(K)
        assert_allclose(r, (info["r_f"] + info["r_j"] + info["r_e"]) / 3, rtol=1e-12)


def test_collision_terminates_training_episode():
    lead = hard_braking(speed=25.0, to_speed=0.0, cruise_before=2.0, cruise_after=10.0)
    env = CarFollowingEnv([lead], action="accel")
    env.reset(seed=0)
    done = False
    while not done:
        _, _r, term, trunc, info = env.step(np.array([0.0], dtype=np.float32))
        done = term or trunc
    assert term and info["collision"] and info["r_f"] == -1.0
    env = CarFollowingEnv([lead], action="accel", terminate_on_collision=False)
    env.reset(seed=0)
    n = 0
    while True:
        *_, term, trunc, info = env.step(np.array([0.0], dtype=np.float32))
        n += 1
        if term or trunc:
            break
    assert not term and n == lead.n_steps - 1


def test_following_pair_starts_where_the_human_was():
    lead = from_accel_segments([(0.0, 20.0)], speed0=15.0)
    foll = from_accel_segments([(0.0, 20.0)], speed0=14.0)
    import dataclasses

    foll = dataclasses.replace(foll, position=foll.position - 30.0)
    pair = FollowingPair(lead, foll, 1, 2, 0, 4.0)
    env = CarFollowingEnv([pair], action="accel", delta=0.0)
    obs, _ = env.reset(seed=0)
    assert_allclose(obs[0] * 25.0, 26.0 - (1.1 * 14.0 + 2.0), rtol=1e-5)
    assert_allclose(obs[1] * 2.5, 1.0, rtol=1e-5)


def test_gain_filter_and_sequential_order():
    seen = []

    def filt(k):
        seen.append(k.copy())
        return np.clip(k, 0.0, None)

    leads = [paper_mix(), hard_braking()]
    env = CarFollowingEnv(leads, gain_filter=filt, order="sequential")
    assert env.reset(seed=0)[1]["leader_index"] == 0
    _, _, _, _, info = env.step(np.array([-1.0, 0.5, 3.0], dtype=np.float32))
    assert_allclose(seen[0], [[-1.0, 0.5, 2.0]])  # clipped to the Table 2 bounds first
    assert_allclose(info["gains"], [0.0, 0.5, 2.0])
    assert env.reset()[1]["leader_index"] == 1
    assert env.reset(options={"index": 0})[1]["leader_index"] == 0


def test_batched_env_matches_single_and_autoresets():
    lead = from_accel_segments([(0.0, 1.0), (-2.0, 1.0)], speed0=20.0)  # 21 samples → 20 steps
    venv = BatchedCarFollowingEnv(3, [lead])
    obs, info = venv.reset(seed=3)
    assert obs.shape == (3, 3) and obs.dtype == np.float32
    assert venv.observation_space.shape == (3, 3) and venv.action_space.shape == (3, 3)
    single = CarFollowingEnv([lead])
    single.reset(seed=0)
    acts = np.tile(K, (3, 1))
    for k in range(lead.n_steps - 1):
        obs, r, _term, trunc, info = venv.step(acts)
        s_obs, s_r, _s_term, s_trunc, _ = single.step(K)
        assert r.shape == (3,)
        assert_allclose(r, s_r, rtol=1e-9)
        if k < lead.n_steps - 2:
            assert not trunc.any() and not info["_final_obs"].any()
            assert_allclose(obs, np.tile(s_obs, (3, 1)), rtol=1e-6)
    assert trunc.all() and s_trunc
    assert_allclose(info["final_obs"], np.tile(s_obs, (3, 1)), rtol=1e-6)
    assert np.isfinite(info["episode_return"]).all()
    assert_allclose(obs, 0.0, atol=1e-6)  # reset in the same step: a fresh equilibrium


def test_bad_env_arguments():
    with pytest.raises(StringStabError, match="action"):
        CarFollowingEnv([paper_mix()], action="jerk")
    with pytest.raises(StringStabError, match="share one step"):
        CarFollowingEnv([paper_mix(dt=0.1), paper_mix(dt=0.2)])
    env = CarFollowingEnv([paper_mix()])
    with pytest.raises(StringStabError, match="reset"):
        env.step(K)
    env.reset(seed=0)
    with pytest.raises(StringStabError, match="gain actions"):
        env.step(np.zeros(2, dtype=np.float32))
