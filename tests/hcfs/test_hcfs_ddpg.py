"""The HCFS DDPG: `stringstab hcfs train` (tiny budget) into a folder `hcfs verify --policy` reads,
the DDPG bundled with the package, and bad input to `hcfs train`."""

import json
import shutil
import sys

import numpy as np
import pytest

import stringstab
from stringstab.cli import main
from stringstab.errors import StringStabError
from stringstab.hcfs import constants as C
from stringstab.hcfs.compare import compare_controllers
from stringstab.hcfs.leaders import paper_cases

TINY = ["--steps", "480", "--seed", "3", "--platoons", "1", "--followers", "2",
        "--episode-seconds", "4", "--no-progress"]


def _torch():
    pytest.importorskip("torch")
    pytest.importorskip("safetensors")


@pytest.mark.torch
def test_train_tiny_then_verify_with_it(tmp_path, capsys):
    """hcfs train writes a policy folder; hcfs verify --policy DIR runs the DDPG it holds."""
    _torch()
    run = tmp_path / "ddpg"
    assert main(["hcfs", "train", *TINY, "--out", str(run)]) == 0
    printed = capsys.readouterr().out
    assert "trained the HCFS DDPG: 480 steps" in printed and "| hcfs-case1" in printed
    for name in ("policy.json", "policy.safetensors", "hcfs_policy.json", "train_log.csv",
                 "evaluation.json", "summary.json"):
        assert (run / name).is_file(), name
    side = json.loads((run / "hcfs_policy.json").read_text())
    assert side["label"] == "DDPG (stringstab.rl, HCFS reward, 480 steps, seed 3)"
    tr = side["training"]
    assert (tr["total_steps"], tr["seed"], tr["num_envs"], tr["leaders"]) == (480, 3, 2, ["udds/2 600-1369 s"])
    assert tr["config"]["algo"] == "ddpg" and tr["config"]["stop_episodes"] == 0
    rows = json.loads((run / "evaluation.json").read_text())["rows"]
    assert {r["controller"] for r in rows} == {"CACC", "DDPG", "HCFS", "stand-in", "HCFS (stand-in)"}

    rep = tmp_path / "rep"
    rc = main(["hcfs", "verify", "-J", "2.5", "-N", "3", "--leader", "hcfs-case3", "--policy", str(run),
               "--no-figures", "--out", str(rep)])
    assert rc == 0
    doc = json.loads((rep / "report.json").read_text())
    assert doc["setup"]["policy_label"] == side["label"] and doc["setup"]["policy_is_stand_in"] is False
    assert doc["ok"] is True and doc["setup"]["leaders"][0]["name"].startswith("hcfs-case3")
    # the DDPG the report ran is the one in the folder
    from stringstab.hcfs.ddpg import load_ddpg
    from stringstab.hcfs.leaders import case_leader
    from stringstab.hcfs.simulate import simulate_hcfs

    pol = load_ddpg(run)
    r = simulate_hcfs(case_leader("hcfs-case3")[0], pol, n_followers=3, configs=[("paper", 2.5)])
    tot = next(x["totals"] for x in doc["results"] if x["mode"] == "paper")
    # float32 network: a batch of another size rounds differently (~1e-8 relative)
    assert tot["sum_reward"] == pytest.approx(float(np.nansum(r.reward[0])), rel=1e-6)


@pytest.mark.torch
def test_training_is_seeded_and_checkpoints_are_evaluated(tmp_path):
    """Same seed, same policy; on_checkpoint sees the deterministic policy saved at each checkpoint,
    the last of which is the returned policy."""
    _torch()
    from stringstab.hcfs.ddpg import train_hcfs_ddpg
    from stringstab.hcfs.env import HCFSVectorEnv
    from stringstab.traffic.synthetic import stop_and_go

    def env():
        return HCFSVectorEnv(1, [stop_and_go(dt=C.DT)], n_followers=2, episode_seconds=4.0)

    probe = np.random.default_rng(0).normal(size=(16, 6)) * np.array([2, 1, 4, 1, 10, 1])
    runs = [train_hcfs_ddpg(total_steps=300, seed=5, env=env(), out=tmp_path / f"r{i}", progress=False,
                            checkpoint_every=100, learning_starts=50, batch_size=16,
                            on_checkpoint=lambda step, pol: pol(probe)) for i in range(2)]
    a, b = (np.asarray(r.policy(probe)) for r in runs)
    np.testing.assert_array_equal(a, b)
    steps = [s for s, _ in runs[0].checkpoints]
    assert steps == [100, 200, 300]
    np.testing.assert_array_equal(runs[0].checkpoints[-1][1], a)
    assert not np.array_equal(runs[0].checkpoints[0][1], a)  # it kept learning
    with pytest.raises(StringStabError, match="on_checkpoint needs a run folder"):
        train_hcfs_ddpg(total_steps=10, env=env(), on_checkpoint=lambda s, p: None)


@pytest.mark.torch
def test_bundled_policy_loads_and_learned():
    """The shipped DDPG loads through the safe loader, says how it was trained, and beats CACC
    alone on the held-out cases (Σr, the HCFS reward) — it learned."""
    _torch()
    from stringstab.hcfs.ddpg import bundled_policy_dir, load_bundled_ddpg

    d = bundled_policy_dir()
    pol = load_bundled_ddpg()
    side = json.loads((d / "hcfs_policy.json").read_text())
    readme = (d / "README.md").read_text()
    tr = side["training"]
    assert pol.label == side["label"] and pol.label.startswith("DDPG (stringstab.rl, HCFS reward")
    cmd = (f"stringstab hcfs train --steps {tr['total_steps']} --seed {tr['seed']}")
    assert cmd in readme and tr["leaders"] == ["udds/2 600-1369 s"] and tr["n_followers"] == 6
    rows = compare_controllers(paper_cases(), pol)
    total = {c: sum(r["sum_reward"] for r in rows if r["controller"] == c) for c in ("CACC", "DDPG", "HCFS")}
    assert total["DDPG"] > total["CACC"] and total["HCFS"] > total["CACC"]
    for r in (r for r in rows if r["controller"] == "HCFS"):
        assert f"{r['sum_reward']:.2f}" in readme  # the README quotes what the policy earns


@pytest.mark.torch
def test_verify_uses_the_bundled_ddpg_by_default(tmp_path, capsys):
    _torch()
    from stringstab.hcfs.ddpg import load_bundled_ddpg

    out = tmp_path / "rep"
    assert main(["hcfs", "verify", "-J", "2.5", "-N", "4", "--leader", "hcfs-case3", "--no-figures",
                 "--out", str(out)]) == 0
    doc = json.loads((out / "report.json").read_text())
    assert doc["setup"]["policy_label"] == load_bundled_ddpg().label
    assert doc["setup"]["policy_is_stand_in"] is False and "--policy bundled" in doc["command"]
    assert "a1 = DDPG (stringstab.rl" in capsys.readouterr().out
    md = (out / "report.md").read_text()
    assert "stand-in" not in md
    out2 = tmp_path / "rep2"
    assert main(["hcfs", "verify", "-J", "2.5", "-N", "4", "--leader", "hcfs-case3", "--policy",
                 "stand-in", "--no-figures", "--out", str(out2)]) == 0
    assert json.loads((out2 / "report.json").read_text())["setup"]["policy_is_stand_in"] is True
    assert "is a **stand-in**, not a DDPG" in (out2 / "report.md").read_text()


@pytest.mark.torch
def test_a_tampered_policy_is_refused(tmp_path, capsys):
    _torch()
    from stringstab.hcfs.ddpg import bundled_policy_dir

    d = tmp_path / "pol"
    shutil.copytree(bundled_policy_dir(), d)
    raw = bytearray((d / "policy.safetensors").read_bytes())
    raw[-1] ^= 1
    (d / "policy.safetensors").write_bytes(bytes(raw))
    out = tmp_path / "rep"
    assert main(["hcfs", "verify", "-J", "2", "--policy", str(d), "--no-figures", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "SHA-256" in err and not out.exists()


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["--steps", "0"], "--steps must be an integer >= 1; got 0"),
        (["--steps", "1e5"], "--steps must be an integer >= 1; got '1e5'"),
        (["--seed", "-1"], "--seed must be an integer >= 0; got -1"),
        (["--platoons", "0"], "--platoons must be an integer >= 1; got 0"),
        (["--followers", "x"], "--followers must be an integer >= 1; got 'x'"),
        (["--episode-seconds", "nan"], "--episode-seconds must be a finite number > 0 s; got 'nan'"),
        (["--leader", "moon"], "unknown leader 'moon'"),
        (["--leader", "NANCSV"], "values must be finite"),
        (["--out", "FILE"], "--out: expected a folder"),
        (["--out", "FULL"], "--out: expected a new or empty folder"),
    ],
)
def test_train_bad_input(tmp_path, capsys, args, match):
    nan = tmp_path / "nan.csv"
    nan.write_text("t,v\n0,1\n1,nan\n2,3\n")
    f = tmp_path / "file"
    f.write_text("x")
    full = tmp_path / "full"
    full.mkdir()
    (full / "keep.txt").write_text("keep")
    sub = {"NANCSV": str(nan), "FILE": str(f), "FULL": str(full)}
    out = tmp_path / "out"
    argv = ["hcfs", "train", "--out", str(out), *[sub.get(a, a) for a in args]]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert match in err and err.count("\n") == 1 and err.startswith("stringstab hcfs: error:")
    assert not out.exists() and f.read_text() == "x" and [p.name for p in full.iterdir()] == ["keep.txt"]


def test_train_names_the_missing_trainer(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "stringstab.rl", None)
    monkeypatch.delattr(stringstab, "rl", raising=False)
    out = tmp_path / "out"
    assert main(["hcfs", "train", "--steps", "10", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "needs the policy trainer stringstab.rl" in err and err.count("\n") == 1
    assert not out.exists()


@pytest.mark.torch
def test_demo_hcfs_step(tmp_path):
    _torch()
    from stringstab.cli.demo_steps import run_demo

    lines = []
    summary = run_demo(tmp_path / "demo", log=lines.append, only=["hcfs"])["hcfs"]
    assert summary["ok"] is True and summary["policy"].startswith("DDPG (stringstab.rl")
    d = tmp_path / "demo" / "hcfs"
    assert (d / "report.md").is_file() and len(list(d.glob("*.png"))) == 3
    paper = summary["results"]["paper J=2.5"]
    doc = json.loads((d / "report.json").read_text())
    tot = next(x["totals"] for x in doc["results"] if x["mode"] == "paper" and x["jerk_limit"] == 2.5)
    assert paper["max_jerk"] == tot["max_jerk"] and summary["results"]["safe J=2.5"]["conclusion_fails"] == 0
    assert any("no frame falsifies" in ln for ln in lines)


@pytest.mark.torch
def test_scaled_policy_runs_torch_on_one_thread_and_restores_the_pool():
    torch = pytest.importorskip("torch")
    from stringstab.hcfs.policy import ScaledPolicy

    seen = []
    net = ScaledPolicy(lambda z: seen.append(torch.get_num_threads()) or z[:, :1], torch_threads=1)
    before = torch.get_num_threads()
    torch.set_num_threads(2)
    try:
        out = net(np.ones((3, 6)) * np.asarray(C.ACCEL_MAX))
        assert seen == [1] and torch.get_num_threads() == 2
        np.testing.assert_allclose(out, C.ACCEL_MAX / 10.0, rtol=0, atol=0)  # scaled by STATE_SCALES[0]
    finally:
        torch.set_num_threads(before)


def test_verify_names_missing_torch(tmp_path, monkeypatch, capsys):
    """Without torch the default (bundled DDPG) is refused in one line; the stand-in still runs."""
    monkeypatch.setitem(sys.modules, "torch", None)
    out = tmp_path / "rep"
    assert main(["hcfs", "verify", "-J", "2", "-N", "2", "--leader", "hcfs-case3", "--no-figures",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "needs torch, which is not installed" in err and err.count("\n") == 1 and not out.exists()
    assert main(["hcfs", "verify", "-J", "2", "-N", "2", "--leader", "hcfs-case3", "--policy",
                 "stand-in", "--no-figures", "--out", str(out)]) == 0


def test_train_names_missing_torch(tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "torch", None)
    out = tmp_path / "out"
    assert main(["hcfs", "train", "--steps", "10", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "needs torch, which is not installed" in err and err.count("\n") == 1 and not out.exists()
