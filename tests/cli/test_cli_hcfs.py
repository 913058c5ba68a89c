"""``stringstab hcfs verify`` end to end: exit 0 on a tiny run, 1 when a guarantee breaks, 2 on bad input."""

import importlib.util
import json

import numpy as np
import pytest

from stringstab.cli import main

#: runs that reach the simulation use the bundled DDPG (the default --policy), which needs torch
needs_torch = pytest.mark.skipif(importlib.util.find_spec("torch") is None,
                                 reason="the bundled DDPG needs torch (the rl extra)")


@pytest.mark.torch
@needs_torch
def test_verify_tiny_run(tmp_path, capsys):
    out = tmp_path / "rep"
    rc = main(["hcfs", "verify", "--jerk-limit", "2.5", "5", "--followers", "4", "--leader", "us06",
               "stop-and-go:waves=1", "--duration", "60", "--no-figures", "--out", str(out)])
    assert rc == 0
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "report.html", "report.json", "report.md"]
    doc = json.loads((out / "report.json").read_text())
    assert doc["ok"] is True and doc["exit_code"] == 0 and doc["violations"] == []
    assert doc["setup"]["n_followers"] == 4 and doc["setup"]["jerk_limits"] == [2.5, 5.0]
    assert [x["name"] for x in doc["setup"]["leaders"]] == ["us06", "stop-and-go"]
    assert len(doc["results"]) == 2 * 2 * 4
    assert doc["counterexamples"]["count"] > 0
    assert doc["command"].startswith("stringstab hcfs verify --jerk-limit 2.5 5 --followers 4")
    text = capsys.readouterr().out
    assert "smallest counterexample" in text and "no frame falsifies" in text


@pytest.mark.torch
@needs_torch
def test_verify_beta_and_csv_leader(tmp_path, capsys):
    lead = tmp_path / "lead.csv"
    lead.write_text("t,v\n0,10\n5,10\n10,15\n20,15\n")
    out = tmp_path / "rep"
    assert main(["hcfs", "verify", "-J", "3", "-N", "2", "--leader", str(lead), "--beta", "0.25",
                 "--no-figures", "--out", str(out)]) == 0
    doc = json.loads((out / "report.json").read_text())
    assert doc["beta"] == 0.25 and doc["setup"]["leaders"][0] == {"name": "lead", "duration_s": 20.0,
                                                                  "frames": 101}
    assert "wrote report.md, report.json to" in capsys.readouterr().out


@pytest.mark.torch
@needs_torch
def test_verify_exit_1_when_a_guarantee_breaks(tmp_path, monkeypatch):
    """A broken jerk-safe variant (no clipping) is caught: frames listed, exit 1."""
    import stringstab.hcfs.simulate as sim

    monkeypatch.setattr(sim, "limit_step", lambda target, previous, step_limit: np.asarray(target))
    out = tmp_path / "rep"
    rc = main(["hcfs", "verify", "-J", "2.5", "-N", "4", "--leader", "us06", "--duration", "60",
               "--no-figures", "--out", str(out)])
    assert rc == 1
    doc = json.loads((out / "report.json").read_text())
    assert doc["ok"] is False and doc["exit_code"] == 1
    assert doc["violations"] and {v["mode"] for v in doc["violations"]} == {"safe"}
    assert "falsify a guarantee (exit 1)" in (out / "report.md").read_text()


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["-J", "0"], "--jerk-limit J must be a finite number > 0 m/s^3; got '0'"),
        (["-J", "-1"], "--jerk-limit J must be a finite number > 0 m/s^3; got '-1'"),
        (["-J", "nan"], "--jerk-limit J must be a finite number > 0 m/s^3; got 'nan'"),
        (["-J", "inf"], "--jerk-limit J must be a finite number > 0 m/s^3; got 'inf'"),
        (["-J", "2", "x"], "--jerk-limit J must be a number; got 'x'"),
        (["-J", "2", "--beta", "1.5"], r"beta must be a number in [0, 1] (eq 13); got '1.5'"),
        (["-J", "2", "--beta", "-0.1"], "beta must be a number in [0, 1]"),
        (["-J", "2", "--beta", "nan"], "beta must be a number in [0, 1]"),
        (["-J", "2", "--followers", "0"], "--followers must be an integer >= 1"),
        (["-J", "2", "--duration", "-5"], "--duration must be a finite number"),
        (["-J", "2", "--leader", "moon"], "unknown leader 'moon'"),
        (["-J", "2", "--leader", "WRONGCOLS"], "expected columns 't, v' or 't, v, a'"),
        (["-J", "2", "--leader", "NANCSV"], "values must be finite"),
        (["-J", "2", "--policy", "nowhere"], "--policy must be 'stand-in' or a directory"),
        (["-J", "2", "--policy", "EMPTYDIR"], "not an HCFS policy directory"),
    ],
)
def test_verify_bad_input(tmp_path, capsys, args, match):
    wrong = tmp_path / "wrong.csv"
    wrong.write_text("time,speed\n0,1\n1,2\n")
    nan = tmp_path / "nan.csv"
    nan.write_text("t,v\n0,1\n1,nan\n2,3\n")
    empty = tmp_path / "empty"
    empty.mkdir()
    sub = {"WRONGCOLS": str(wrong), "NANCSV": str(nan), "EMPTYDIR": str(empty)}
    out = tmp_path / "out"
    rc = main(["hcfs", "verify", *[sub.get(a, a) for a in args], "--no-figures", "--out", str(out)])
    assert rc == 2
    err = capsys.readouterr().err
    assert match in err and err.count("\n") == 1 and err.startswith("stringstab hcfs: error:")
    assert not out.exists()


def test_verify_out_is_a_file(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["hcfs", "verify", "-J", "2", "--out", str(f)]) == 2
    assert f"--out: expected a folder; {str(f)!r} is a file" in capsys.readouterr().err
    assert f.read_text() == "x"


@pytest.mark.torch
@needs_torch
def test_verify_refuses_another_commands_folder_and_replaces_its_own(tmp_path, capsys):
    from stringstab.io import OutputDir

    other = tmp_path / "other"
    with OutputDir(other, command="region") as od:
        od.write_text("x.txt", "x")
    assert main(["hcfs", "verify", "-J", "2", "--leader", "stop-and-go:waves=1", "--no-figures",
                 "--out", str(other)]) == 2
    assert "holds the outputs of 'stringstab region'" in capsys.readouterr().err
    out = tmp_path / "rep"
    args = ["hcfs", "verify", "-J", "2", "--leader", "stop-and-go:waves=1", "--out", str(out)]
    assert main(args) == 0 and len(list(out.glob("*.png"))) == 3
    assert main([*args, "--no-figures"]) == 0  # the second run removes the first run's figures
    assert not list(out.glob("*.png")) and (out / "report.md").is_file()


def test_hcfs_needs_a_subcommand(capsys):
    with pytest.raises(SystemExit) as e:
        main(["hcfs"])
    assert e.value.code == 2
