"""θ_r, the radio and the sensors in the RL environment, the repair and the evaluation (issues 25, 26).

Independent truths: the environment's platoon against a direct :func:`stringstab.traffic.simulate`
run with the same gains at every step (the simulator's own path: ``Onboard`` around a controller,
not the environment's ``EnvOnboard``); the repaired gains against the façade's certificate with
``reaction_delay`` and a fine frequency sweep of |Γ(jω)| with the exact e^{−θ_r s} written out
here; defaults against the outputs of the same commands without the new options (bit for bit).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import stringstab as ss
from stringstab.cli import main
from stringstab.errors import StringStabError
from stringstab.traffic import (
    BatchedCarFollowingEnv,
    Radio,
    SensorNoise,
    TimeVaryingLinearController,
    simulate,
    sinusoid,
)

torch = pytest.importorskip("torch")
pytest.importorskip("safetensors")

from stringstab.rl import config_for, train  # noqa: E402
from stringstab.rl.evaluate import evaluate, fss  # noqa: E402
from stringstab.tuning.repair import GainRepair  # noqa: E402

pytestmark = pytest.mark.torch

TAU, DELTA, HEADWAY, THETA = 0.1, 0.2, 1.1, 0.2


def tiny(algo: str = "idl", **kw):
    base = dict(total_steps=96, learning_starts=32, batch_size=16, buffer_size=256, num_envs=3,
                stop_episodes=0, seed=3, hidden=(16, 16), repair_resolution=0.25,
                checkpoint_every=10_000)
    base.update(kw)
    return config_for(algo, paper=True, **base)


def short_leaders():
    return [sinusoid(omega=w, amplitude=2.0, speed=15.0, duration=2.0) for w in (0.5, 1.0, 2.0)]


# ------------------------------------------------------------------ the env's platoon, θ_r and radio
@pytest.mark.parametrize("loop", [
    {"reaction_delay": 0.25},
    {"reaction_delay": 0.13, "radio": Radio(message_period=0.3, message_phase=1, loss=0.3, seed=4,
                                            stale_after=0.5, fallback_gains=(0.4, 0.6)),
     "sensors": SensorNoise(gap=0.3, gap_rate=0.1, speed=0.05, correlation_time=0.5,
                            filter_time=0.2, seed=7)},
])
def test_env_platoon_equals_a_direct_simulator_run(loop):
    lead = sinusoid(omega=0.8, amplitude=2.5, speed=15.0, duration=12.0)
    T = lead.n_steps
    rng = np.random.default_rng(1)
    G = np.column_stack([rng.uniform(0.3, 1.5, T), rng.uniform(0.2, 1.2, T), rng.uniform(0.0, 0.8, T)])
    env = BatchedCarFollowingEnv(1, [lead], tau=TAU, delta=DELTA, headway=HEADWAY, **loop)
    env.reset(seed=0)
    gap, speed, accel, cmd = [], [], [], []
    for k in range(T - 1):
        _, _, term, trunc, info = env.step(G[k][None])
        assert not term[0]
        assert bool(trunc[0]) == (k == T - 2)
        gap.append(info["gap"][0])
        speed.append(info["speed"][0])
        accel.append(info["accel"][0])
        cmd.append(info["command"][0])
    ctrl = TimeVaryingLinearController(lambda obs: G[obs.step][None, None, :], headway=HEADWAY)
    res = simulate(lead, ctrl, 1, tau=TAU, delta=DELTA, **loop)
    assert res.gap is not None and res.speed is not None and res.accel is not None
    np.testing.assert_allclose(gap, res.gap[0, 1:], rtol=0, atol=1e-9)
    np.testing.assert_allclose(speed, res.speed[1, 1:], rtol=0, atol=1e-9)
    np.testing.assert_allclose(accel, res.accel[1, 1:], rtol=0, atol=1e-9)
    np.testing.assert_allclose(cmd, res.command[0, :-1], rtol=0, atol=1e-9)
    if "radio" in loop:  # the radio did something: messages lost, a fallback
        assert res.radio is not None and res.radio["messages_lost"].sum() > 0
        assert res.radio["fallback_time"].sum() > 0
    # and θ_r matters: the same gains without it give another trajectory
    plain = simulate(lead, ctrl, 1, tau=TAU, delta=DELTA)
    assert np.abs(plain.gap[0, 1:] - np.asarray(gap)).max() > 1e-3


def test_env_restarts_leave_the_other_rows_sensors_and_radio_alone():
    # deterministic sensors (a filter, no noise) and radio (messages every 3 steps, no loss): a
    # row whose neighbour restarts mid-run must see what a platoon run of its own sees, so the
    # second observation of a step (after the restart) must not advance its filter or messages
    short = sinusoid(omega=1.0, amplitude=2.0, speed=12.0, duration=2.0)
    long_ = sinusoid(omega=0.8, amplitude=2.5, speed=15.0, duration=8.0)
    loop = {"radio": Radio(message_period=0.3), "sensors": SensorNoise(filter_time=0.4),
            "reaction_delay": 0.15}
    env = BatchedCarFollowingEnv(2, [short, long_], tau=TAU, delta=DELTA, headway=HEADWAY, **loop)
    for seed in range(50):
        _, info = env.reset(seed=seed)
        if info["leader_index"].tolist() == [0, 1]:
            break
    else:
        pytest.fail("no seed draws the short leader for row 0 and the long one for row 1")
    K = np.array([1.0, 0.7, 0.5])
    gap, restarts = [], 0
    for _ in range(long_.n_steps - 1):
        _, _, _, trunc, info = env.step(np.tile(K, (2, 1)))
        restarts += int(trunc[0])
        gap.append(info["gap"][1])
    assert restarts >= 1  # row 0 restarted while row 1 ran
    res = simulate(long_, TimeVaryingLinearController(np.tile(K, (long_.n_steps, 1, 1, 1)),
                                                      headway=HEADWAY), 1, tau=TAU, delta=DELTA, **loop)
    np.testing.assert_allclose(gap, res.gap[0, 1:], rtol=0, atol=1e-9)


def test_env_defaults_unchanged_bit_for_bit():
    lead = sinusoid(omega=0.8, amplitude=2.5, speed=15.0, duration=5.0)
    a = BatchedCarFollowingEnv(2, [lead])
    b = BatchedCarFollowingEnv(2, [lead], reaction_delay=0.0, radio=None, sensors=None)
    oa, _ = a.reset(seed=5)
    ob, _ = b.reset(seed=5)
    np.testing.assert_array_equal(oa, ob)
    for k in range(lead.n_steps + 5):  # through an autoreset
        act = np.tile([1.2, 0.5, 0.6 + 0.01 * k], (2, 1))
        ra, rb = a.step(act), b.step(act)
        for x, y in zip(ra[:4], rb[:4]):
            np.testing.assert_array_equal(x, y)
    assert a.state_dict()[0] == b.state_dict()[0]


# ------------------------------------------------------------------ the repair certifies at θ_r
def independent_gamma_ok(K, theta: float) -> bool:
    """max |Γ(jω)| ≤ 1 on a fine sweep of (0, 60] rad/s, Γ with the exact e^{−θ_r s} (issue 25)."""
    kx, kv, ka = (float(v) for v in K)
    w = np.concatenate([np.linspace(1e-4, 10.0, 40_000), np.linspace(10.0, 60.0, 5_000)])
    s = 1j * w
    eth = np.exp(-theta * s)
    num = eth * (kx + kv * s + ka * s**2 * np.exp(-DELTA * s))
    den = TAU * s**3 + s**2 + eth * ((kx * HEADWAY + kv) * s + kx)
    return bool(np.abs(num / den).max() <= 1.0 + 1e-9)


def test_repair_output_is_certified_at_theta():
    proposals = np.array([[1.2, 0.5, 0.6], [0.9, -0.5, 1.1], [2.0, 2.0, 2.0], [0.4, 0.3, 0.95],
                          [-1.0, 0.5, 0.0]])
    before = ss.check(*proposals.T, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA)
    assert (before.verdict != "certified").all()  # none certified at θ_r as proposed
    at0 = ss.check(*proposals[:1].T, tau=TAU, delta=DELTA, headway=HEADWAY)
    assert at0.verdict[0] == "certified"  # the first one is, without θ_r
    rep = GainRepair(tau=TAU, delta=DELTA, headway=HEADWAY, resolution=0.25, refine=3,
                     reaction_delay=THETA)
    K = rep(proposals)
    for k in K:
        c = ss.certify(*k, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA)
        assert c.verdict == "certified", k
        assert independent_gamma_ok(k, THETA), k
    assert rep.describe()["reaction_delay"] == THETA
    # a triple certified at θ_r is executed unchanged
    ok = K[:1]
    np.testing.assert_array_equal(rep(ok), ok)


def test_repair_and_config_with_theta_and_the_sampled_certificate():
    rep = GainRepair(tau=TAU, delta=DELTA, headway=HEADWAY, sample_time=0.1, reaction_delay=THETA,
                     resolution=0.25)
    assert rep.describe()["sample_time"] == 0.1 and rep.describe()["reaction_delay"] == THETA
    from stringstab.rl.repair import repair_for

    both = repair_for(config_for("idl", reaction_delay=THETA))  # repair_sampled by default
    assert both is not None and both.sample_time == 0.1 and both.reaction_delay == THETA
    with pytest.raises(StringStabError, match="at most 2000 whole samples"):
        config_for("idl", reaction_delay=30.0, dt=0.01)
    with pytest.raises(StringStabError, match="reaction_delay"):
        config_for("idl", reaction_delay=-0.1, repair_sampled=False)
    with pytest.raises(StringStabError, match="message period must be a whole multiple"):
        config_for("td3", radio=Radio(message_period=0.15))
    cfg = config_for("idl", reaction_delay=THETA, repair_sampled=False)
    rep = repair_for(cfg)
    assert rep is not None and rep.sample_time is None and rep.reaction_delay == THETA


def test_fss_at_theta_with_the_sampled_certificate():
    K = np.array([[1.2, 0.5, 0.6], [0.6, 0.6, 0.3], [0.6, 0.6, 0.3], [0.9, 0.9, 0.7]])
    f0 = fss(K, tau=TAU, delta=DELTA, headway=HEADWAY, dt=0.1)
    ft = fss(K, tau=TAU, delta=DELTA, headway=HEADWAY, dt=0.1, reaction_delay=THETA)
    truth = ss.check(*K.T, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA)
    assert ft["m_fss"] == pytest.approx(float(np.mean(truth.verdict == "certified")), abs=0)
    st = ss.check(*K.T, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA,
                  sample_time=0.1)
    assert ft["m_fss_sampled"] == pytest.approx(float(np.mean(st.verdict == "certified")), abs=0)
    assert "with θ_r" in ft["certificate"]
    assert f0["m_fss_sampled"] is not None
    # refused by the sampled certificate (θ_r of more than 2,000 steps): None, and said
    fr = fss(K, tau=TAU, delta=DELTA, headway=HEADWAY, dt=0.001, reaction_delay=30.0)
    assert fr["m_fss_sampled"] is None and "refuses" in fr["certificate"]


# ------------------------------------------------------------------ training and resuming
def test_training_with_theta_and_radio_executes_certified_gains_and_resumes_bit_for_bit(tmp_path):
    loop = dict(reaction_delay=THETA, repair_sampled=False,
                radio=Radio(message_period=0.2, loss=0.2, burst=2.0, stale_after=0.4, seed=1),
                sensors=SensorNoise(gap=0.2, speed=0.05, correlation_time=1.0, filter_time=0.3, seed=2))
    cfg = tiny(total_steps=120, checkpoint_every=60, **loop)
    full = train(cfg, leaders=short_leaders(), out=tmp_path / "full", progress=False)
    half = train(cfg.replace(total_steps=60), leaders=short_leaders(), out=tmp_path / "half",
                 progress=False)
    assert half.steps == 60
    resumed = train(cfg, leaders=short_leaders(), out=tmp_path / "half", resume=True, progress=False)
    assert full.episodes == resumed.episodes
    from stringstab.rl.checkpoint import latest_checkpoint

    s1, t1 = latest_checkpoint(tmp_path / "full" / "checkpoint")
    s2, t2 = latest_checkpoint(tmp_path / "half" / "checkpoint")
    assert "onboard" in s1["env"] and s1["env"] == s2["env"]  # the sensors' and radio's state too
    assert any(k.startswith("env.onboard.link.") for k in t1["buffer"])
    for k in t1["buffer"]:
        np.testing.assert_array_equal(t1["buffer"][k], t2["buffer"][k], err_msg=k)
    for (k, a), (_, b) in zip(full.policy.actor.state_dict().items(),
                              resumed.policy.actor.state_dict().items()):
        assert torch.equal(a, b), k
    info = json.loads((tmp_path / "full" / "policy.json").read_text())
    assert info["reaction_delay"] == THETA and info["repair"]["reaction_delay"] == THETA
    assert info["radio"]["message_period"] == 0.2 and info["sensors"]["gap"] == 0.2
    # the policy's executed gains in evaluation: certified at θ_r by the façade
    lead = sinusoid(omega=0.8, amplitude=2.0, speed=15.0, duration=4.0)
    ev = evaluate(full.policy, [lead], tau=TAU, delta=DELTA, headway=HEADWAY,
                  reaction_delay=THETA, radio=cfg.radio, sensors=cfg.sensors)
    assert ev.gains is not None
    u = np.unique(ev.gains[:, 2:], axis=0)
    v = ss.check(*u.T, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA).verdict
    # the repaired gains are certified at θ_r; the radio's fallback (k_x, k_v, 0), in force
    # while messages are stale, is not repaired and need not be (reported in m_fss)
    assert (v[u[:, 2] != 0] == "certified").all()
    share = np.mean([v[np.flatnonzero((u == k).all(axis=1))[0]] == "certified" for k in ev.gains[:, 2:]])
    assert ev.summary["m_fss"] == pytest.approx(float(share), abs=1e-12)
    vs = ss.check(*u.T, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA,
                  sample_time=cfg.dt).verdict
    # m_fss_sampled: the sampled certificate with θ_r at dt (issue 25), on the same gains
    share_s = np.mean([vs[np.flatnonzero((u == k).all(axis=1))[0]] == "certified"
                       for k in ev.gains[:, 2:]])
    assert ev.summary["m_fss_sampled"] == pytest.approx(float(share_s), abs=1e-12)


def test_resume_restores_the_repairs_kept_verdicts_bit_for_bit(tmp_path):
    """The default repair (both certificates, θ_r = 0): interrupted + resumed = uninterrupted.

    The truth: the uninterrupted run's kept verdicts (their bits and order) equal the resumed
    run's at the end, which holds only if the checkpoint's verdicts were restored (a resumed
    run starting with none would keep only its second half's, in another order).
    """
    from stringstab.rl.checkpoint import CHECKPOINT_FORMAT, latest_checkpoint, read_json, sha256

    cfg = tiny(total_steps=90, learning_starts=30, checkpoint_every=45)
    assert cfg.repair == "projection" and cfg.repair_sampled
    full = train(cfg, leaders=short_leaders(), out=tmp_path / "full", progress=False)
    train(cfg.replace(total_steps=45), leaders=short_leaders(), out=tmp_path / "half",
          progress=False)
    sh, th = latest_checkpoint(tmp_path / "half" / "checkpoint")
    assert sh["step"] == 45 and sh["repair"]["verdicts"] > 0  # the cache is not empty there
    assert sh["repair"]["settings"]["sample_time"] == cfg.dt
    resumed = train(cfg, leaders=short_leaders(), out=tmp_path / "half", resume=True,
                    progress=False)
    assert full.repair["repaired"] > 0
    assert full.episodes == resumed.episodes
    s1, t1 = latest_checkpoint(tmp_path / "full" / "checkpoint")
    s2, t2 = latest_checkpoint(tmp_path / "half" / "checkpoint")
    assert s1["repair"] == s2["repair"] and s1["step"] == s2["step"] == 90
    for stem in ("repair", "buffer", "agent"):
        assert t1[stem].keys() == t2[stem].keys()
        for k in t1[stem]:
            np.testing.assert_array_equal(t1[stem][k], t2[stem][k], err_msg=f"{stem}.{k}")
    assert t1["repair"]["gains"].shape[0] > th["repair"]["gains"].shape[0]
    np.testing.assert_array_equal(  # the resumed run kept the first half's verdicts first
        t2["repair"]["gains"][: th["repair"]["gains"].shape[0]], th["repair"]["gains"])
    # a checkpoint written before the verdicts were saved (no repair file) still resumes,
    # with none kept (docs/training.md, "Resuming")
    train(cfg.replace(total_steps=45), leaders=short_leaders(), out=tmp_path / "old",
          progress=False)
    d = tmp_path / "old" / "checkpoint" / "ckpt-0000000045"
    doc = read_json(d / "state.json", fmt=CHECKPOINT_FORMAT, what="test")
    del doc["repair"], doc["files"]["repair.safetensors"]
    (d / "repair.safetensors").unlink()
    (d / "state.json").write_text(json.dumps(doc))
    assert all(sha256(d / f) == h for f, h in doc["files"].items())
    old = train(cfg, leaders=short_leaders(), out=tmp_path / "old", resume=True, progress=False)
    assert old.steps == 90
    t3 = latest_checkpoint(tmp_path / "old" / "checkpoint")[1]
    assert 0 < t3["repair"]["gains"].shape[0] < t1["repair"]["gains"].shape[0]


def test_resume_refuses_a_changed_loop(tmp_path):
    cfg = tiny(total_steps=40, learning_starts=16, reaction_delay=0.1, repair_sampled=False)
    train(cfg, leaders=short_leaders(), out=tmp_path / "r", progress=False)
    for change in ({"reaction_delay": 0.2}, {"radio": Radio(message_period=0.2)},
                   {"sensors": SensorNoise(gap=0.1)}):
        with pytest.raises(StringStabError, match="another configuration; expected its "
                           + next(iter(change))):
            train(cfg.replace(total_steps=80, **change), leaders=short_leaders(),
                  out=tmp_path / "r", resume=True, progress=False)


# ------------------------------------------------------------------ the command line
def _leader_csv(tmp_path: Path) -> Path:
    f = tmp_path / "lead.csv"
    tr = sinusoid(omega=0.8, amplitude=2.0, speed=15.0, duration=25.0)
    f.write_text("t,v\n" + "".join(f"{t:.1f},{v:.6f}\n" for t, v in zip(tr.t, tr.speed)))
    return f


def _strip(doc):
    """A JSON document without what names its folder or the time it ran."""
    if isinstance(doc, dict):
        return {k: _strip(v) for k, v in doc.items()
                if k not in ("folder", "run", "out", "started", "elapsed", "command")
                and "timing" not in k and "seconds" not in k and k != "load_average"}
    if isinstance(doc, list):
        return [_strip(v) for v in doc]
    return doc


def test_cli_reaction_delay_zero_is_the_default_bit_for_bit(tmp_path, capsys):
    lead = _leader_csv(tmp_path)
    outs, codes = [], []
    for name, extra in (("a", []), ("b", ["--reaction-delay", "0"])):
        run = tmp_path / name
        assert main(["train", "--algo", "idl", "--steps", "48", "--num-envs", "2", "--seed", "2",
                     "--out", str(run), "--no-progress", *extra]) == 0
        codes.append(main(["evaluate", str(run), "--leaders", str(lead), "--platoon", "none",
                           "--no-progress", *extra]))
        outs.append(run)
    assert codes[0] == codes[1]
    a, b = outs
    for f in ("config.json", "policy.json", "summary.json"):
        assert _strip(json.loads((a / f).read_text())) == _strip(json.loads((b / f).read_text())), f
    assert (a / "policy.safetensors").read_bytes() == (b / "policy.safetensors").read_bytes()
    ea = json.loads((a / "evaluation" / "evaluation.json").read_text())
    eb = json.loads((b / "evaluation" / "evaluation.json").read_text())
    assert _strip(ea) == _strip(eb)
    assert "reaction_delay" not in ea["run"] and ea["summary"]["m_fss_sampled"] is not None
    for f in ("gains.csv", "episodes.csv"):
        assert (a / "evaluation" / f).read_bytes() == (b / "evaluation" / f).read_bytes(), f


def test_cli_train_evaluate_compare_with_theta_and_radio(tmp_path, capsys):
    lead = _leader_csv(tmp_path)
    run = tmp_path / "idl"
    loop = ["--reaction-delay", "0.2", "--message-period", "0.2", "--noise-gap", "0.1"]
    assert main(["train", "--algo", "idl", "--steps", "48", "--num-envs", "2", "--out", str(run),
                 "--no-progress", *loop]) == 0
    assert "certified by the continuous certificate at θ_r" in capsys.readouterr().out
    cfg = json.loads((run / "config.json").read_text())
    assert cfg["reaction_delay"] == 0.2 and cfg["repair_sampled"] is False
    assert cfg["radio"]["message_period"] == 0.2 and cfg["sensors"]["gap"] == 0.1
    code = main(["evaluate", str(run), "--leaders", str(lead), "--platoon", "none", "--no-progress"])
    out = capsys.readouterr().out
    doc = json.loads((run / "evaluation" / "evaluation.json").read_text())
    assert doc["run"]["reaction_delay"] == 0.2 and doc["run"]["radio"]["message_period"] == 0.2
    assert doc["summary"]["m_fss"] == 1.0 and doc["summary"]["m_fss_sampled"] is not None
    assert "sampled-data at dt=" in out
    assert code == (0 if doc["summary"]["collisions"] == 0 else 1)
    # evaluated in another loop on request: θ_r = 0.3, no radio
    assert main(["evaluate", str(run), "--leaders", str(lead), "--platoon", "none", "--no-progress",
                 "--reaction-delay", "0.3", "--out", str(tmp_path / "ev3")]) in (0, 1)
    doc3 = json.loads((tmp_path / "ev3" / "evaluation.json").read_text())
    assert doc3["run"]["reaction_delay"] == 0.3 and "radio" not in doc3["run"]
    g = np.unique(np.loadtxt(tmp_path / "ev3" / "gains.csv", delimiter=",", skiprows=1)[:, 2:], axis=0)
    truth = ss.check(*g.T, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=0.3)
    counts = np.loadtxt(tmp_path / "ev3" / "gains.csv", delimiter=",", skiprows=1)[:, 2:]
    share = float(np.mean([truth.verdict[np.flatnonzero((g == k).all(axis=1))[0]] == "certified"
                           for k in counts]))
    assert doc3["summary"]["m_fss"] == pytest.approx(share, abs=1e-12)
    cmp = tmp_path / "cmp"
    assert main(["compare", str(run), "--baselines", "cacc", "--leaders", str(lead), "--out",
                 str(cmp), "--no-progress"]) == 0
    table = (cmp / "table.md").read_text()
    assert "reaction delay θ_r = 0.2 s" in table and "not available" not in table  # m_fss_sampled at θ_r
    assert not (cmp / "gains_region.png").exists() and "region map has no reaction delay" in table
    assert json.loads((cmp / "comparison.json").read_text())["loop"]["reaction_delay"] == 0.2
    import matplotlib.pyplot as plt

    plt.close("all")


@pytest.mark.parametrize("argv, words", [
    (["--reaction-delay", "-0.1"], "--reaction-delay (reaction delay θ_r) must be"),
    (["--reaction-delay", "nan"], "--reaction-delay (reaction delay θ_r) must be"),
    (["--reaction-delay", "150"], "--reaction-delay (reaction delay θ_r) = 150 s is far outside"),
    (["--message-period", "0.15"], "--message-period: message period must be a whole multiple"),
    (["--loss", "1.5"], "--loss must be a number in [0, 1]"),
    (["--noise-gap", "-1"], "--noise-gap must be a finite number >= 0"),
    (["--burst", "2"], "--burst needs --loss"),
    (["--reaction-delay", "5"], "no certified gains on the 81^3 lattice"),
])
def test_cli_bad_loop_input_is_one_line_exit_2(tmp_path, capsys, argv, words):
    out = tmp_path / "t"
    assert main(["train", "--algo", "idl", "--steps", "10", "--out", str(out), "--no-progress",
                 *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_cli_evaluate_bad_loop_input_and_compare_of_different_loops(tmp_path, capsys):
    lead = _leader_csv(tmp_path)
    a, b = tmp_path / "a", tmp_path / "b"
    assert main(["train", "--algo", "ddpg", "--steps", "32", "--num-envs", "2", "--out", str(a),
                 "--no-progress"]) == 0
    assert main(["train", "--algo", "ddpg", "--steps", "32", "--num-envs", "2", "--out", str(b),
                 "--no-progress", "--reaction-delay", "0.1"]) == 0
    capsys.readouterr()
    assert main(["evaluate", str(a), "--leaders", str(lead), "--platoon", "none",
                 "--message-period", "0.25"]) == 2
    assert "--message-period" in capsys.readouterr().err
    assert not (a / "evaluation").exists()
    assert main(["compare", str(a), str(b), "--baselines", "none", "--leaders", str(lead),
                 "--out", str(tmp_path / "c")]) == 2
    assert "trained in different loops" in capsys.readouterr().err
    # the loop given on the command line puts both in one
    assert main(["compare", str(a), str(b), "--baselines", "none", "--leaders", str(lead),
                 "--out", str(tmp_path / "c"), "--reaction-delay", "0.1", "--no-progress"]) == 0
    import matplotlib.pyplot as plt

    plt.close("all")
