"""Issue 21, items 2-4: the followers' limits as parameters with one leader check, manifests
that say what produced a folder, --out's extension choosing the format, and progress."""

import io
import json

import pytest

from stringstab.cli import main
from stringstab.io import MANIFEST
from stringstab.progress import Progress

SHORT = ["--duration", "20", "--no-figures", "--followers", "2"]


def _leader(tmp_path, v_top, name="lead.csv"):
    """A highway leader that speeds up from 30 m/s to ``v_top`` (0.47 m/s², within the limits)."""
    f = tmp_path / name
    f.write_text(f"t,v\n0,30\n10,{v_top}\n30,{v_top}\n")
    return f


def _err_lines(capsys):
    return capsys.readouterr().err.strip().splitlines()


def test_a_real_highway_speed_warns_and_v_max_raises_the_limit(capsys, tmp_path):
    lead = _leader(tmp_path, 34.7)  # 125 km/h: above the IDL paper's 33.3 m/s
    out = tmp_path / "sim"
    assert main(["simulate", "--leader", str(lead), *SHORT, "--out", str(out)]) == 0
    err = _err_lines(capsys)
    assert len(err) == 1 and "warning: the leader reaches 34.7 m/s" in err[0]
    assert "v_max = 33.3 m/s (IDL Table 2; --v-max raises it)" in err[0]
    assert main(["simulate", "--leader", str(lead), *SHORT, "--v-max", "36", "--out", str(out)]) == 0
    assert _err_lines(capsys) == []
    doc = json.loads((out / "metrics.json").read_text())
    assert doc["run"]["limits"]["speed_max"] == 36.0 and doc["warnings"] == []


@pytest.mark.parametrize("argv, match", [
    (["--v-max", "100"], "limits beyond any road vehicle: expected speed_max <= 70 m/s"),
    (["--a-min", "2"], "expected --a-min < 0 < --a-max; got --a-min 2"),
    (["--a-max", "nan"], "--a-max must be a finite number; got 'nan'"),
    (["--a-max", "20"], "accelerations within ±15 m/s²"),
])
def test_absurd_limits_are_refused(capsys, tmp_path, argv, match):
    out = tmp_path / "sim"
    assert main(["simulate", *SHORT, *argv, "--out", str(out)]) == 2
    err = _err_lines(capsys)
    assert len(err) == 1 and match in err[0], err
    assert not out.exists()


def test_hcfs_verify_uses_the_same_leader_check(capsys, tmp_path):
    fast = _leader(tmp_path, 100.0, "fast.csv")
    out = tmp_path / "h"
    argv = ["hcfs", "verify", "-J", "2.5", "--followers", "2", "--policy", "stand-in",
            "--no-figures", "--no-progress"]
    assert main([*argv, "--leader", str(fast), "--out", str(out)]) == 2
    err = _err_lines(capsys)
    assert len(err) == 1 and "reaches 100 m/s at t = " in err[0] and "no road vehicle" in err[0]
    assert not out.exists()
    lead = _leader(tmp_path, 34.7)
    assert main([*argv, "--leader", str(lead), "--out", str(out)]) in (0, 1)
    err = capsys.readouterr().err
    assert "stringstab hcfs verify: warning: the leader reaches 34.7 m/s" in err
    manifest = json.loads((out / MANIFEST).read_text())
    assert manifest["inputs"][str(lead)]["sha256"]
    assert manifest["argv"][:3] == ["stringstab", "hcfs", "verify"]


def test_out_extension_picks_the_format_and_a_conflict_is_an_error(capsys, tmp_path):
    src = tmp_path / "g.csv"
    src.write_text("k_x,k_v,k_a\n1.2,0.5,0.6\n")
    y = tmp_path / "y.json"
    assert main(["certify", "--file", str(src), "--out", str(y)]) == 0
    assert json.loads(y.read_text())["results"][0]["verdict"] == "certified"
    z = tmp_path / "z.json"
    assert main(["certify", "--file", str(src), "--format", "csv", "--out", str(z)]) == 2
    err = _err_lines(capsys)
    assert err[-1].startswith("stringstab certify: error: --format csv conflicts with --out")
    assert not z.exists()
    r = tmp_path / "r.csv"
    assert main(["tune", "0.9,-0.5,1.1", "--out", str(r)]) == 0
    assert r.read_text().startswith("method,")
    t = tmp_path / "t.txt"  # an unknown-to-the-table extension is a table
    assert main(["certify", "1.2,0.5,0.6", "--out", str(t)]) == 0
    assert t.read_text().startswith("# tau")


def test_progress_lines_are_plain_and_say_when_done():
    # the time left, after a warm-up, is checked on a synthetic clock in tests/basics/test_progress.py
    buf = io.StringIO()
    with Progress(10, "stringstab x", unit="runs", stream=buf, every=0.0, tty=False) as p:
        for _ in range(10):
            p.update(1)
    lines = buf.getvalue().splitlines()
    assert lines[0].startswith("stringstab x: 1/10 runs (10%), ") and "\r" not in buf.getvalue()
    assert lines[-1].startswith("stringstab x: 10/10 runs done in ")
    silent = io.StringIO()
    with Progress(10, "x", stream=silent, every=0.0, tty=False, enabled=False) as p:
        p.update(10)
    assert silent.getvalue() == ""


def test_evaluate_records_the_policy_refuses_mixing_and_names_a_stale_evaluation(
        capsys, tmp_path, monkeypatch):
    pytest.importorskip("torch")
    monkeypatch.setattr(Progress, "EVERY", 0.0)
    run = tmp_path / "runA"
    train = ["train", "--algo", "ddpg", "--seed", "0", "--num-envs", "4", "--no-progress",
             "--out", str(run)]
    assert main([*train, "--steps", "64"]) == 0
    lead = _leader(tmp_path, 34.7)
    ev = ["evaluate", str(run), "--leaders", str(lead), "--platoon", "none"]
    assert main(ev) == 1  # an acceleration policy has no gains to certify
    err = capsys.readouterr().err
    assert "stringstab evaluate: 301/301 vehicle-steps done in" in err  # 30 s at 0.1 s
    assert "warning: the leader reaches 34.7 m/s" in err
    man = json.loads((run / "evaluation" / MANIFEST).read_text())
    assert man["command"] == "evaluate" and man["policy"]["steps"] == 64
    assert len(man["policy"]["policy_sha256"]) == 64 and man["inputs"][str(lead)]["sha256"]
    doc = json.loads((run / "evaluation" / "evaluation.json").read_text())
    assert doc["run"]["steps"] == 64 and doc["run"]["limits"]["speed_max"] == 33.3
    # a leader no road vehicle could drive is refused, as by simulate and hcfs verify
    fast = _leader(tmp_path, 100.0, "fast.csv")
    assert main(["evaluate", str(run), "--leaders", str(fast), "--platoon", "none"]) == 2
    err = _err_lines(capsys)
    assert len(err) == 1 and "reaches 100 m/s" in err[0] and "no road vehicle" in err[0]
    # the run goes on: the old evaluation is named stale, then replaced with a note
    assert main([*train, "--steps", "96", "--resume"]) == 0
    assert "evaluation/ evaluated the policy at step 64, not this one (step 96)" in \
        capsys.readouterr().err
    assert main(ev) == 1
    assert "held the evaluation of an older policy of this run (step 64)" in capsys.readouterr().err
    assert json.loads((run / "evaluation" / MANIFEST).read_text())["policy"]["steps"] == 96
    # another run's evaluation folder is never mixed with or replaced by this one's
    other = tmp_path / "runB"
    assert main(["train", "--algo", "ddpg", "--seed", "1", "--num-envs", "4", "--no-progress",
                 "--steps", "64", "--out", str(other)]) == 0
    before = (run / "evaluation" / "evaluation.json").read_bytes()
    assert main(["evaluate", str(other), "--leaders", str(lead), "--platoon", "none",
                 "--out", str(run / "evaluation")]) == 2
    assert "holds the evaluation of another run" in capsys.readouterr().err
    assert (run / "evaluation" / "evaluation.json").read_bytes() == before


def test_hcfs_verify_and_compare_report_progress_off_a_terminal(capsys, tmp_path, monkeypatch):
    monkeypatch.setattr(Progress, "EVERY", 0.0)
    out = tmp_path / "h"
    assert main(["hcfs", "verify", "-J", "2.5", "--followers", "2", "--policy", "stand-in",
                 "--leader", "stop-and-go", "braking", "--duration", "15",
                 "--out", str(out)]) in (0, 1)
    err = capsys.readouterr().err
    assert "stringstab hcfs verify: 1/2 leaders (50%), " in err and "\r" not in err
    assert "stringstab hcfs verify: 2/2 leaders done in " in err
    # the figures are counted too (they took 85 s after "2/2 leaders done", silently)
    n_fig = len(list(out.glob("*.png")))
    assert n_fig > 1 and f"stringstab hcfs verify: figures: 1/{n_fig} figures " in err
    assert f"stringstab hcfs verify: figures: {n_fig}/{n_fig} figures done in " in err


def test_demo_takes_the_limits(capsys, tmp_path):
    out = tmp_path / "demo"
    assert main(["demo", "--only", "simulate", "--v-max", "20", "--out", str(out)]) == 0
    std = capsys.readouterr().out
    assert "== simulate == (step 1 of 1," in std
    assert "warning: the leader reaches" in std  # the mix leader exceeds 20 m/s
    doc = json.loads((out / "simulate" / "certified" / "metrics.json").read_text())
    assert doc["run"]["limits"]["speed_max"] == 20.0
