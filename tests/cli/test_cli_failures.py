"""Issue 21, item 1: every failure is one sentence with the right exit code, and no output.

The cases are the ones a new user hit (the issue's *Why*): absurd magnitudes reaching a solver,
grids and platoons that cannot fit in memory, Ctrl-C, MemoryError.
"""

import signal

import pytest

from stringstab.cli import main
from stringstab.errors import StringStabError


def _one_line(capsys, argv, code, starts, match=""):
    rc = main(argv)
    out, err = capsys.readouterr()
    assert rc == code, err
    assert err.count("\n") == 1 and err.startswith(starts), err
    assert match in err, err
    assert "Traceback" not in err
    return out, err


@pytest.mark.parametrize("argv, match", [
    (["certify", "1e308,1e308,1e308"], "k_x = 1e+308 is far outside the physically meaningful "
                                        "range (sensible: |k| up to 10; refused above 1e+06)"),
    (["tune", "1e308,1,1"], "k_x = 1e+308 is far outside"),
    (["certify", "1,1,1", "--tau", "1e300"], "actuator lag tau = 1e+300 s is far outside"),
    (["certify", "1,1,1", "--tau", "0.1:1e200"], "actuator lag tau = 1e+200 s"),
    (["certify", "1,1,1", "--sample-time", "1e6"], "--sample-time = 1e+06 s is far outside"),
    (["certify", "1.2,0.5,0.6", "--sample-time", "1e-300"],
     "--sample-time = 1e-300 s is far outside the physically meaningful range (sensible: 0.001 to "
     "1 s; refused below 0.0001 s)"),
    (["tune", "0.9,-0.5,1.1", "--sample-time", "5e-5"], "--sample-time = 5e-05 s is far outside"),
    (["simulate", "--dt", "2.2250738585072014e-308", "--out", "unused"],  # fuzz: OverflowError
     "--dt = 2.22507e-308 s is far outside the physically meaningful range (sensible: 0.001 to 1 "
     "s; refused below 0.0001 s)"),
    (["certify", "1,1,1", "--delta", "1e5"], "communication delay delta = 100000 s"),
    (["tune", "7,1,1", "--method", "both"], "expected K0 within [-6, 6]"),
    (["tune", "0.9,-0.5,1.1", "--bounds", "-1e308,1e308"], "--bounds = -1e+308 is far outside"),
    (["region", "--fix", "k_a=0.5", "--range", "-1e308,1e308", "--out", "unused"],
     "--range = -1e+308 is far outside"),
    (["region", "--fix", "k_a=1e300", "--out", "unused"], "--fix k_a = 1e+300 is far outside"),
    (["train", "--algo", "idl", "--steps", "99999999999999999999999", "--out", "unused"],
     "is far beyond any training run"),
    (["train", "--algo", "idl", "--steps", "100", "--num-envs", "1000000000000", "--out", "unused"],
     "--num-envs 1000000000000 needs about "),
])
def test_absurd_magnitudes_are_refused_before_any_solver(capsys, argv, match):
    out, _ = _one_line(capsys, argv, 2, f"stringstab {argv[0]}: error: ", match)
    assert out == ""


def test_a_gain_file_holding_1e308_is_refused(capsys, tmp_path):
    f = tmp_path / "g.csv"
    f.write_text("k_x,k_v,k_a\n1,1,1\n0.5,1e308,1\n")
    out_file = tmp_path / "v.json"
    _one_line(capsys, ["certify", "--file", str(f), "--format", "json", "--out", str(out_file)], 2,
              "stringstab certify: error: ", "g.csv, row 2, k_v = 1e+308 is far outside")
    assert not out_file.exists()


def test_large_but_finite_gains_are_certified_without_a_crash(capsys):
    """1e6 is the largest accepted magnitude: the certificate runs (no overflow) and warns."""
    rc = main(["certify", "1e6,1e6,1e6", "--format", "json"])
    out, err = capsys.readouterr()
    assert rc in (0, 1) and "warning: k_x (row 1) = 1e+06 is outside the sensible range" in err
    assert '"verdict"' in out


def test_sensible_range_warnings(capsys):
    rc = main(["certify", "1.2,0.5,0.6", "--tau", "3"])
    err = capsys.readouterr().err
    assert rc in (0, 1)
    assert "stringstab certify: warning: --tau = 3 s is outside the sensible range (up to 2 s)" in err


def test_a_sample_time_between_the_floors_is_warned_and_certified(capsys):
    """1e-4 <= H < 1e-3 s runs (the certificate answers) with a warning naming the range."""
    rc = main(["certify", "1.2,0.5,0.6", "--sample-time", "5e-4", "--format", "json"])
    out, err = capsys.readouterr()
    assert rc in (0, 1) and '"verdict"' in out
    assert ("stringstab certify: warning: --sample-time = 0.0005 s is outside the sensible range "
            "(0.001 to 1 s)") in err


@pytest.mark.parametrize("value", [1e-300, 1e-8, 9.9e-5])
def test_the_library_refuses_a_sample_time_below_the_floor(value):
    """The library's way in holds the same floor as the command line (1e-300 divided by zero)."""
    from stringstab.certify.api import Loop
    from stringstab.params import sample_time

    with pytest.raises(StringStabError, match=r"refused below 0\.0001 s"):
        sample_time(value)
    with pytest.raises(StringStabError, match=r"refused below 0\.0001 s"):
        Loop.of(0.1, 0.2, 1.1, sample_time=value)
    assert sample_time(1e-4) == 1e-4


def test_region_grid_too_big_is_refused_with_the_estimate(capsys, tmp_path):
    out = tmp_path / "maps"
    _one_line(capsys, ["region", "--fix", "k_a=0.5", "--n", "100000", "--out", str(out)], 2,
              "stringstab region: error: --n 100000 (100000 x 100000 = 1e+10 points) needs about ",
              "is available; expected at most about --n ")
    _one_line(capsys, ["region", "--3d", "--n", "5000", "--out", str(out)], 2,
              "stringstab region: error: --n 5000 --3d (5000 x 5000 x 5000")
    assert not out.exists()


def test_platoon_too_big_is_refused_with_the_estimate(capsys, tmp_path):
    out = tmp_path / "sim"
    _one_line(capsys, ["simulate", "--followers", "1000000000", "--out", str(out)], 2,
              "stringstab simulate: error: --followers 1000000000 (", "TiB of memory")
    assert not out.exists()


def test_ctrl_c_is_one_line_exit_130_and_no_output_folder(capsys, tmp_path, monkeypatch):
    import stringstab.regions

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(stringstab.regions, "region_map", interrupted)
    out = tmp_path / "new" / "maps"
    _one_line(capsys, ["region", "--fix", "k_a=0.5", "--n", "5", "--out", str(out)], 130,
              "stringstab region: interrupted; nothing partial was written")
    assert not out.exists() and not out.parent.exists()


def test_ctrl_c_while_writing_keeps_the_old_run_whole(capsys, tmp_path, monkeypatch):
    """An interrupt inside the OutputDir block discards the staged files: the earlier run stays."""
    out = tmp_path / "sim"
    argv = ["simulate", "--followers", "2", "--duration", "10", "--no-figures", "--out", str(out)]
    assert main(argv) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    capsys.readouterr()
    import stringstab.traffic.output as output

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(output, "write_run", interrupted)
    _one_line(capsys, [*argv[:-3], "--gains", "1,1,0.5", *argv[-3:]], 130,
              "stringstab simulate: interrupted")
    after = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    assert after == before


def test_sigterm_while_writing_stops_like_ctrl_c_and_keeps_the_old_run_whole(capsys, tmp_path,
                                                                             monkeypatch):
    """SIGTERM (a scheduler's time limit) is handled as Ctrl-C: one line, exit 130, no partial run."""
    previous = signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        out = tmp_path / "sim"
        argv = ["simulate", "--followers", "2", "--duration", "10", "--no-figures", "--out",
                str(out)]
        assert main(argv) == 0
        before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
        capsys.readouterr()
        import stringstab.traffic.output as output

        def terminated(*a, **k):
            signal.raise_signal(signal.SIGTERM)  # without the handler: the process dies here

        monkeypatch.setattr(output, "write_run", terminated)
        _one_line(capsys, [*argv[:-3], "--gains", "1,1,0.5", *argv[-3:]], 130,
                  "stringstab simulate: interrupted")
        after = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
        assert after == before
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # handler restored
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_memory_error_is_one_line(capsys, monkeypatch):
    from stringstab.certify.api import Loop

    def oom(*a, **k):
        raise MemoryError("Unable to allocate 74.5 GiB for an array")

    monkeypatch.setattr(Loop, "certify_batch", oom)
    _one_line(capsys, ["certify", "1,1,1"], 2, "stringstab certify: error: out of memory (Unable "
              "to allocate 74.5 GiB for an array); expected a smaller request")


def test_stringstab_error_stays_exit_2():
    with pytest.raises(StringStabError):
        from stringstab.ranges import check_magnitude

        check_magnitude("gain", float("nan"))


def test_interrupted_training_leaves_a_resumable_folder_with_its_log(capsys, tmp_path, monkeypatch):
    pytest.importorskip("torch")
    import importlib

    rl_envs = importlib.import_module("stringstab.rl.envs")

    real = rl_envs.make_env
    calls = {"n": 0}

    def make_env(config, leaders=None):
        env = real(config, leaders)
        step = env.step

        def stepped(actions):
            calls["n"] += 1
            if calls["n"] == 5:  # Ctrl-C in the middle of the run
                signal.raise_signal(signal.SIGINT)
            return step(actions)

        env.step = stepped
        return env

    monkeypatch.setattr(rl_envs, "make_env", make_env)
    handler = signal.getsignal(signal.SIGINT)  # SIG_IGN when pytest runs in a background job
    out = tmp_path / "run"
    argv = ["train", "--algo", "ddpg", "--steps", "64", "--num-envs", "4", "--out", str(out),
            "--no-progress"]
    rc = main(argv)
    _std, err = capsys.readouterr()
    assert rc == 130, err
    assert err.count("\n") == 1 and err.startswith("stringstab train: interrupted at step 20 of 64;")
    assert "continue with: stringstab train --algo ddpg --steps 64 --seed 0 --out" in err
    assert err.rstrip().endswith("--resume") and "--num-envs 4" in err
    for name in ("train_log.csv", "summary.json", "policy.json", "checkpoint"):
        assert (out / name).exists(), name
    assert signal.getsignal(signal.SIGINT) is handler  # handler restored
    monkeypatch.setattr(rl_envs, "make_env", real)
    assert main([*argv, "--resume"]) == 0
    assert "trained ddpg: 64 steps" in capsys.readouterr().out


def _ctrl_c_twice_at(env, at_call):
    """``env.step`` presses Ctrl-C twice on its call ``at_call``: recorded, then raised at once."""
    step, calls = env.step, {"n": 0}

    def stepped(actions):
        calls["n"] += 1
        if calls["n"] == at_call:
            signal.raise_signal(signal.SIGINT)  # the first: recorded (stop at the next step)
            signal.raise_signal(signal.SIGINT)  # the second: KeyboardInterrupt here, mid-step
        return step(actions)

    env.step = stepped
    return env


def _tiny(**kw):
    from stringstab.rl import config_for

    return config_for("ddpg", total_steps=64, learning_starts=16, batch_size=8, num_envs=4, seed=0,
                      **kw)


def test_a_second_ctrl_c_before_the_first_checkpoint_leaves_no_folder(capsys, tmp_path, monkeypatch):
    """The window of the flaky fuzz case: the folder used to exist from before the loop."""
    pytest.importorskip("torch")
    import importlib

    rl_envs = importlib.import_module("stringstab.rl.envs")
    real = rl_envs.make_env
    monkeypatch.setattr(rl_envs, "make_env", lambda c, leaders=None: _ctrl_c_twice_at(real(c, leaders), 1))
    handler = signal.getsignal(signal.SIGINT)
    out = tmp_path / "run"
    rc = main(["train", "--algo", "ddpg", "--steps", "64", "--num-envs", "4", "--out", str(out),
               "--no-progress"])
    err = capsys.readouterr().err
    assert rc == 130 and "interrupted; nothing partial was written" in err, err
    assert not out.exists(), sorted(p.name for p in out.iterdir())  # (was run.json, config.json)
    assert signal.getsignal(signal.SIGINT) is handler


def test_a_second_ctrl_c_after_a_checkpoint_leaves_a_resumable_folder(tmp_path):
    pytest.importorskip("torch")
    import json

    from stringstab.rl import train
    from stringstab.rl.envs import make_env

    config = _tiny(checkpoint_every=16)
    out = tmp_path / "run"
    with pytest.raises(KeyboardInterrupt):  # on the 7th vector step (24 steps; checkpoint at 16)
        train(config, envs=_ctrl_c_twice_at(make_env(config), 7), out=out, progress=False)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["steps"] == 16 and summary["stopped_by"] == "checkpoint", summary
    assert (out / "train_log.csv").is_file() and (out / "policy.json").is_file()
    assert not (out / "rolling_reward.png").exists()  # the figure is the end's
    res = train(config, out=out, resume=True, progress=False)  # it resumes, to the end
    assert res.steps == 64 and res.stopped_by == "steps"
    assert json.loads((out / "summary.json").read_text())["stopped_by"] == "steps"
    uninterrupted = train(config, out=tmp_path / "whole", progress=False)
    assert [e["return"] for e in res.episodes] == [e["return"] for e in uninterrupted.episodes]


def test_ctrl_c_twice_while_a_checkpoint_is_written_is_held(tmp_path, monkeypatch):
    pytest.importorskip("torch")
    import json

    from stringstab.rl import checkpoint as ckpt
    from stringstab.rl import train

    real = ckpt.write_checkpoint

    def pressed(*a, **kw):
        signal.raise_signal(signal.SIGINT)
        signal.raise_signal(signal.SIGINT)  # held: the checkpoint's files are written whole
        return real(*a, **kw)

    monkeypatch.setattr(ckpt, "write_checkpoint", pressed)
    out = tmp_path / "run"
    res = train(_tiny(checkpoint_every=16), out=out, progress=False)
    assert res.stopped_by == "interrupted" and res.steps == 16  # stopped at the next step boundary
    assert json.loads((out / "summary.json").read_text())["stopped_by"] == "interrupted"
    assert (out / "rolling_reward.png").is_file()


def test_a_batch_file_too_big_for_memory_is_refused(capsys, tmp_path, monkeypatch):
    """The estimate (4.5 kB per row) against the memory available, before certifying."""
    import numpy as np

    import stringstab.memory as budget

    monkeypatch.setattr(budget, "available_bytes", lambda: 200_000_000)  # a small machine
    f = tmp_path / "big.npz"
    np.savez(f, K=np.tile([1.2, 0.5, 0.6], (20_000, 1)))
    out = tmp_path / "v.npz"
    _one_line(capsys, ["certify", "--file", str(f), "--out", str(out)], 2,
              f"stringstab certify: error: {f} (20000 rows) needs about 228.9 MiB of memory; "
              "190.7 MiB is available; expected at most about 11111 rows")
    assert not out.exists()


def test_the_example_rollout_that_collides_says_so_and_exits_1(capsys, tmp_path):
    from pathlib import Path

    import stringstab

    rollout = Path(stringstab.__file__).parent / "data" / "examples" / "gain_rollout.csv"
    out = tmp_path / "rollout"
    rc = main(["simulate", "--gains-file", str(rollout), "--followers", "2", "--no-figures",
               "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 1
    assert err[-1].startswith("stringstab simulate: warning: 2 collision(s): follower 1 first "
                              "reached its predecessor at t = 81.8 s (m_fss = 0.037)")
    assert (out / "metrics.json").is_file()  # the outputs are written: they show the collision


def test_region_growing_with_a_tiny_r0_stops_with_a_sentence(capsys, monkeypatch):
    """A tiny r0 would build ever larger grids for hours: the search stops at MAX_POINTS."""
    import importlib

    rg = importlib.import_module("stringstab.tuning.region_growing")  # the package exports the function
    monkeypatch.setattr(rg, "MAX_POINTS", 1e5)  # the same rule, reached sooner
    _one_line(capsys, ["tune", "0.9,-0.5,1.1", "--method", "region-growing", "--r0", "1e-300"], 2,
              "stringstab tune: error: region growing reached region R_", "without a solution; "
              "expected at most 1e+05 points: a larger r0 (got 1e-300)")
