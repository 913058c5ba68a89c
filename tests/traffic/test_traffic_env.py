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


def test_action_wrapper_and_sequential_order():
    """A gain filter is a standard gymnasium action wrapper; the env clips what it executes."""
    import gymnasium as gym

    seen = []

    def filt(k):
        seen.append(np.array(k, copy=True))
        return np.clip(k, 0.0, None)

    leads = [paper_mix(), hard_braking()]
    base = CarFollowingEnv(leads, order="sequential")
    env = gym.wrappers.TransformAction(base, filt, base.action_space)
    assert env.reset(seed=0)[1]["leader_index"] == 0
    _, _, _, _, info = env.step(np.array([-1.0, 0.5, 3.0], dtype=np.float32))
    assert_allclose(seen[0], [-1.0, 0.5, 3.0])  # the proposal, as given
    assert_allclose(info["gains"], [0.0, 0.5, 2.0])  # filtered, then clipped to Table 2's box
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


def test_linear_law_is_the_eq4_law_of_the_linear_controller():
    """The vectorised eq-4 law the environment executes agrees with LinearController.command
    (which expands k_x (gap − T* v − l_0) into three products: another rounding path)."""
    from stringstab.traffic import Observation, linear_law

    rng = np.random.default_rng(0)
    gap, speed, rel, ad = rng.uniform(0, 40, 50), rng.uniform(0, 30, 50), rng.normal(size=50), rng.normal(size=50)
    z = np.zeros(50)
    obs = Observation(0, 0.0, 0.1, gap=gap, speed=speed, accel=z, pred_speed=speed + rel,
                      rel_speed=rel, pred_accel=z, pred_accel_delayed=ad)
    Ks = rng.uniform(-2, 2, (50, 3))
    u = linear_law(Ks, obs, headway=1.1, standstill=2.0)
    want = [LinearController(*k, headway=1.1, standstill=2.0).command(obs)[i] for i, k in enumerate(Ks)]
    assert_allclose(u, want, rtol=1e-12, atol=1e-12)
    # by hand for one follower: 1.2 (27 − 1.1·20 − 2) + 0.5·1 + 0.6·0.5 = 4.4
    one = Observation(0, 0.0, 0.1, gap=np.array([27.0]), speed=np.array([20.0]), accel=z[:1],
                      pred_speed=np.array([21.0]), rel_speed=np.array([1.0]), pred_accel=z[:1],
                      pred_accel_delayed=np.array([0.5]))
    assert_allclose(linear_law([1.2, 0.5, 0.6], one, headway=1.1, standstill=2.0), [4.4], rtol=1e-14)


def test_environment_state_without_a_key_is_refused_in_one_line():
    env = BatchedCarFollowingEnv(2, [paper_mix()], observe=("gains",))
    env.reset(seed=0)
    env.step(np.tile(K, (2, 1)))
    meta, arrays = env.state_dict()
    del arrays["prev_gains"]
    with pytest.raises(StringStabError, match=r"expected key 'prev_gains' in the environment's "
                                              r"arrays, found keys \['k', 'platoon\."):
        BatchedCarFollowingEnv(2, [paper_mix()], observe=("gains",)).load_state_dict(meta, arrays)
    meta2 = {k: v for k, v in meta.items() if k != "rng"}
    with pytest.raises(StringStabError, match="expected key 'rng' in the environment's meta data"):
        BatchedCarFollowingEnv(2, [paper_mix()]).load_state_dict(meta2, env.state_dict()[1])
