"""The HCFS training environment (VectorEnv, same-step autoreset) and the stringstab.rl seam."""

import dataclasses
import json
import sys
import types

import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import stringstab
from stringstab.errors import StringStabError
from stringstab.hcfs import constants as C
from stringstab.hcfs.ddpg import load_ddpg, save_ddpg, train_ddpg
from stringstab.hcfs.env import HCFSVectorEnv
from stringstab.hcfs.mdp import STATE_SCALES
from stringstab.hcfs.policy import LeaderSpeedMatcher
from stringstab.hcfs.simulate import simulate_hcfs
from stringstab.traffic.leaders import leader_by_name
from stringstab.traffic.synthetic import stop_and_go


def test_spaces_and_autoreset_contract():
    env = HCFSVectorEnv(2, [stop_and_go(dt=C.DT)], n_followers=3, episode_seconds=1.0, delay=0.0)
    assert env.metadata["autoreset_mode"] == AutoresetMode.SAME_STEP
    assert env.num_envs == 6 and env.single_observation_space.shape == (6,)
    assert env.single_action_space.low[0] == C.ACCEL_MIN and env.single_action_space.high[0] == C.ACCEL_MAX
    obs, info = env.reset(seed=1)
    assert obs.shape == (6, 6) and obs.dtype == np.float32 and info["leader_index"].shape == (6,)
    for k in range(1, 6):
        obs, r, term, trunc, info = env.step(np.full((6, 1), 0.3))
        assert r.shape == term.shape == trunc.shape == (6,) and not term.any()
        assert np.array_equal(info["_final_obs"], trunc)
        if k < 5:
            assert not trunc.any() and np.isnan(info["episode_return"]).all()
    assert trunc.all()  # 1 s = 5 frames
    assert np.isfinite(info["final_obs"]).all() and np.isfinite(info["episode_return"]).all()
    # the new episodes start in equilibrium: zero deviations, a = 0 (no V2V delay here)
    np.testing.assert_allclose(obs[:, [0, 1, 2, 3, 5]], 0.0, rtol=0, atol=1e-6)
    with pytest.raises(StringStabError, match="one value per sub-environment"):
        env.step(np.zeros((5, 1)))


def test_reward_is_eqs_4_to_6():
    env = HCFSVectorEnv(1, [stop_and_go(dt=C.DT)], n_followers=2, episode_seconds=30.0)
    env.reset(seed=0)
    prev = np.zeros(2)
    for a in ([0.5, -0.5], [1.0, 0.0], [-2.0, 3.0]):
        _, r, _, _, info = env.step(np.array(a)[:, None])
        expected = (-C.OMEGA_1 * np.abs(info["speed_error"]) / C.SPEED_MAX
                    - C.OMEGA_2 * np.abs(np.array(a) - prev) / (2 * C.ACCEL_MAX))
        np.testing.assert_allclose(r, expected, rtol=1e-12, atol=1e-15)
        prev = np.array(a)


def test_env_and_simulator_agree():
    """The env stepped by a policy reproduces simulate_hcfs's 'policy' mode (two implementations)."""
    lead = leader_by_name("us06", dt=C.DT, duration=20)
    pol = LeaderSpeedMatcher()
    run = simulate_hcfs(lead, pol, n_followers=3, configs=[("policy", 1e6)])
    env = HCFSVectorEnv(1, [lead], n_followers=3, episode_seconds=lead.duration)
    obs, _ = env.reset(seed=0)
    scales = np.asarray(STATE_SCALES)
    for k in range(lead.n_steps - 1):
        # the env observes the eq-3 state / scales (float32): the policy on it gives the run's output
        a = np.clip(pol(obs.astype(np.float64) * scales), C.ACCEL_MIN, C.ACCEL_MAX)
        np.testing.assert_allclose(a, run.output[0, :, k], rtol=0, atol=1e-4)
        obs, _, _, trunc, _ = env.step(run.output[0, :, k][:, None])
        if k < lead.n_steps - 2:
            np.testing.assert_allclose(env.platoon.speed[0], run.speed[0, :, k + 1], rtol=0, atol=1e-12)
            np.testing.assert_allclose(env.platoon.position[0], run.position[0, :, k + 1], rtol=0, atol=1e-9)
    assert trunc.all()


def test_seeded_reset_is_reproducible():
    leaders = [stop_and_go(dt=C.DT), leader_by_name("us06", dt=C.DT, duration=60)]
    a = HCFSVectorEnv(3, leaders, n_followers=2, episode_seconds=5.0)
    b = HCFSVectorEnv(3, leaders, n_followers=2, episode_seconds=5.0)
    oa, _ = a.reset(seed=7)
    ob, _ = b.reset(seed=7)
    for _ in range(30):
        act = np.full((6, 1), 0.1)
        oa = a.step(act)[0]
        ob = b.step(act)[0]
    np.testing.assert_array_equal(oa, ob)


def test_train_ddpg_names_the_missing_trainer(monkeypatch):
    monkeypatch.setitem(sys.modules, "stringstab.rl", None)
    with pytest.raises(StringStabError, match=r"needs the policy trainer stringstab\.rl"):
        train_ddpg(total_steps=10)


def test_train_ddpg_through_the_contract(monkeypatch, tmp_path):
    """A fake stringstab.rl with the contract's API: the env handed over, the policy returned."""
    seen = {}

    @dataclasses.dataclass
    class DDPGConfig:
        total_steps: int = 1
        seed: int = 0

    class Policy:
        def __call__(self, obs):
            obs = np.asarray(obs)
            seen["obs_shape"] = obs.shape
            return np.full((obs.shape[0], 1), 0.25)

        def save(self, directory):
            directory.mkdir(parents=True, exist_ok=True)
            (directory / "config.json").write_text("{}")

    def train(config, envs=None):
        seen["config"], seen["env"] = config, envs
        return types.SimpleNamespace(policy=Policy())

    fake = types.ModuleType("stringstab.rl")
    fake.DDPGConfig, fake.train, fake.load_policy = DDPGConfig, train, lambda d: Policy()
    monkeypatch.setitem(sys.modules, "stringstab.rl", fake)
    # once the real trainer has been imported (by another test in this process), the package
    # attribute wins over sys.modules in 'import stringstab.rl as rl': fake it too
    monkeypatch.setattr(stringstab, "rl", fake, raising=False)
    env = HCFSVectorEnv(1, [stop_and_go(dt=C.DT)], n_followers=2)
    pol = train_ddpg(total_steps=123, seed=4, env=env)
    assert seen["config"] == DDPGConfig(total_steps=123, seed=4) and seen["env"] is env
    assert pol.label.startswith("DDPG (stringstab.rl")
    run = simulate_hcfs(stop_and_go(waves=1, dt=C.DT), pol, n_followers=2,
                        configs=[("policy", 100.0)])
    assert seen["obs_shape"] == (2, 6)
    np.testing.assert_allclose(run.raw_ddpg[0], 0.25)
    assert run.params["policy_is_stand_in"] is False
    save_ddpg(pol, tmp_path / "p")
    assert json.loads((tmp_path / "p" / "hcfs_policy.json").read_text())["label"] == pol.label
    back = load_ddpg(tmp_path / "p")
    np.testing.assert_allclose(back.scales, STATE_SCALES)
    assert back.label == pol.label
    with pytest.raises(StringStabError, match="not an HCFS policy directory"):
        load_ddpg(tmp_path)


@pytest.mark.torch
def test_train_a_tiny_ddpg_and_verify():
    """With the real trainer: a tiny DDPG trains on the HCFS env and plugs into the verification."""
    pytest.importorskip("stringstab.rl")  # first: it is absent until the trainer lands
    pytest.importorskip("torch")
    from stringstab.hcfs.verify import verify

    env = HCFSVectorEnv(2, [stop_and_go(dt=C.DT)], n_followers=2, episode_seconds=10.0)
    pol = train_ddpg(total_steps=400, seed=0, env=env)
    ver = verify([stop_and_go(waves=1, dt=C.DT)], pol, jerk_limits=[5.0], n_followers=2)
    assert ver.ok and ver.runs[0].params["policy_label"].startswith("DDPG")
