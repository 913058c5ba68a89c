"""``stringstab simulate`` end to end: a tiny run, and bad input → exit 2 with no output."""

import json

import numpy as np
import pytest

from stringstab.cli import main
from stringstab.io import MANIFEST


def test_simulate_tiny_run(tmp_path, capsys):
    out = tmp_path / "sim"
    rc = main(["simulate", "--leader", "us06", "--duration", "50", "--hold", "10", "--followers", "3",
               "--gains", "1.2,0.5,0.6", "--tau", "0.1", "--delta", "0.2", "--out", str(out)])
    assert rc == 0
    assert sorted(p.name for p in out.iterdir() if p.name != MANIFEST) == [
        "damping.png", "metrics.json", "platoon.png", "report.html", "report.md", "trajectories.npz"]
    doc = json.loads((out / "metrics.json").read_text())
    assert len(doc["m_p"]) == 3 and doc["max_m_p"] < 1.0 and doc["collisions"] == 0
    assert doc["m_fss"] == 1.0 and doc["certificate"]["verdict"] == "certified"
    assert doc["run"]["k_x"] == 1.2 and doc["run"]["delta"] == 0.2
    with np.load(out / "trajectories.npz") as z:
        assert z["speed"].shape == (4, 601) and z["gap"].shape == (3, 601)
        np.testing.assert_allclose(z["gap"], z["position"][:-1] - z["position"][1:] - 5.0)
    assert "m_p per follower" in capsys.readouterr().out


def test_simulate_csv_leader_cacc_kinematic(tmp_path):
    leader = tmp_path / "lead.csv"
    leader.write_text("t,v\n0,10\n5,10\n10,15\n20,15\n")
    out = tmp_path / "sim"
    rc = main(["simulate", "--leader", str(leader), "--followers", "2", "--controller", "cacc",
               "--model", "kinematic", "--format", "csv", "--no-figures", "--out", str(out)])
    assert rc == 0
    assert sorted(p.name for p in out.iterdir() if p.name != MANIFEST) == [
        "metrics.json", "report.html", "report.md", "trajectories.csv"]
    lines = (out / "trajectories.csv").read_text().splitlines()
    assert lines[0] == "t,vehicle,position,speed,accel,gap,headway,command"
    assert len(lines) == 1 + 201 * 3
    doc = json.loads((out / "metrics.json").read_text())
    assert doc["certificate"]["verdict"] == "not_certified" and doc["m_fss"] == 0.0


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["--leader", "moon"], "unknown leader 'moon'"),
        (["--gains", "1.2,0.5"], "--gains must be three"),
        (["--gains", "1.2,x,0.6"], "--gains must be three"),
        (["--tau", "-0.1"], "tau (actuator lag) must be"),
        (["--delta", "-1"], "delta"),
        (["--followers", "0"], "--followers"),
        (["--dt", "0"], "--dt"),
        (["--hold", "-1"], "--hold"),
        (["--leader", "sinusoid:omega=-1"], "omega must be"),
        (["--controller", "idm", "--gains", "1,1,1"], "apply to --controller linear"),
        (["--leader", "BADCSV"], "expected columns 't, v' or 't, v, a'"),
        (["--gains-file", "BADGAINS"], "expected columns"),
    ],
)
def test_simulate_bad_input(tmp_path, capsys, args, match):
    bad = tmp_path / "bad.csv"
    bad.write_text("time,speed\n0,1\n1,2\n")
    args = [str(bad) if a in ("BADCSV", "BADGAINS") else a for a in args]
    out = tmp_path / "out"
    assert main(["simulate", *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert match in err and err.count("\n") == 1
    assert not out.exists()


def test_simulate_time_varying_gains_file(tmp_path):
    gains = tmp_path / "gains.csv"
    gains.write_text("t,k_x,k_v,k_a\n0,1.2,0.5,0.6\n5,0.1,0.58,1.0\n")
    out = tmp_path / "sim"
    assert main(["simulate", "--leader", "mix", "--duration", "10", "--followers", "2",
                 "--gains-file", str(gains), "--no-figures", "--out", str(out)]) == 0
    doc = json.loads((out / "metrics.json").read_text())
    assert doc["m_fss"] == pytest.approx(50 / 101)  # steps 0-49 of 0-100 certified
