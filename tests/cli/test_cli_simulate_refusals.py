"""`stringstab simulate`: impossible or meaningless input is one sentence (exit 2) or a warning."""

import json
from pathlib import Path

import pytest

import stringstab
from stringstab.cli import main
from stringstab.io import MANIFEST

ROLLOUT = Path(stringstab.__file__).parent / "data" / "examples" / "gain_rollout.csv"
SHORT = ["--duration", "10", "--no-figures"]


def _refused(capsys, tmp_path, *argv, match):
    out = tmp_path / "refused-out"
    code = main(["simulate", *argv, "--out", str(out)])
    std, err = capsys.readouterr()
    assert code == 2, err
    assert err.count("\n") == 1 and err.startswith("stringstab simulate: error: ")
    assert match in err, err
    assert "np.float64" not in err and "Traceback" not in err
    assert std == "" and not out.exists()
    return err


def test_absurd_leader_is_refused_and_one_above_v_max_warns(capsys, tmp_path):
    """Issue 21: one leader check; beyond the followers' limits a warning, beyond 70 m/s refused."""
    lead = tmp_path / "fast.csv"
    lead.write_text("t,v\n0,100\n10,100\n20,100\n")
    _refused(capsys, tmp_path, "--leader", str(lead), *SHORT,
             match="reaches 100 m/s at t = 0 s: no road vehicle; expected a leader within [0, 70] m/s")
    out = tmp_path / "out40"
    assert main(["simulate", "--leader", "sinusoid:omega=0.5,speed=40", "--followers", "2", *SHORT,
                 "--out", str(out)]) in (0, 1)
    err = capsys.readouterr().err
    assert "warning: the leader reaches" in err and "above the followers' speed limit v_max = " \
        "33.3 m/s (IDL Table 2; --v-max raises it): they saturate there and the gap opens" in err
    assert "v_max" in json.loads((out / "metrics.json").read_text())["warnings"][0]


@pytest.mark.parametrize("argv, match", [
    (["--dt", "1"], "--dt 1 s is longer than the actuator lag tau = 0.1 s and the delay "
                    "delta = 0.2 s"),
    (["--dt", "0.15"], "--dt 0.15 s is longer than the actuator lag tau = 0.1 s: "),
    (["--dt", "0.1", "--delta", "0.05"], "longer than the delay delta = 0.05 s: "),
    (["--dt", "nan"], "--dt must be a finite number > 0; got nan"),
])
def test_step_longer_than_tau_or_delta_is_refused(capsys, tmp_path, argv, match):
    _refused(capsys, tmp_path, *argv, *SHORT, match=match)


def test_leader_beyond_the_acceleration_limits_warns(capsys, tmp_path):
    lead = tmp_path / "jump.csv"
    lead.write_text("t,v\n0,10\n5,10\n6,20\n20,20\n")  # +10 m/s in 1 s
    out = tmp_path / "out"
    assert main(["simulate", "--leader", str(lead), "--followers", "2", "--no-figures",
                 "--out", str(out)]) == 0
    err = capsys.readouterr().err
    assert "warning: the leader accelerates at up to 10 m/s², beyond the followers' limit " \
           "acc_max = 3 m/s² (first at t = 5 s)" in err
    doc = json.loads((out / "metrics.json").read_text())
    assert len(doc["warnings"]) == 1 and "acc_max" in doc["warnings"][0]


def test_bundled_rollout_drives_the_followers(capsys, tmp_path):
    out = tmp_path / "out"
    assert main(["simulate", "--gains-file", str(ROLLOUT), "--followers", "2", *SHORT,
                 "--out", str(out)]) == 0
    capsys.readouterr()
    doc = json.loads((out / "metrics.json").read_text())
    assert 0.0 <= doc["m_fss"] <= 1.0 and "M_fss" not in doc  # a fraction, under one key
    _refused(capsys, tmp_path, "--gains-file", str(ROLLOUT), "--followers", "3", *SHORT,
             match="has gain series for followers 1..2; expected --followers 2, got 3")


def test_units_and_undefined_ratios_are_printed_as_such(capsys, tmp_path):
    # a leader that never accelerates: m_p is 0/0 for every follower
    assert main(["simulate", "--leader", "sinusoid:omega=1,amplitude=0", "--followers", "2",
                 *SHORT, "--out", str(tmp_path / "out")]) == 0
    text = capsys.readouterr().out
    assert "nan" not in text and "max m_p = n/a" in text
    assert " s², M_CI = " in text and " m²/s⁶" in text and "M_effi = " in text and " s, m_fss = " in text


def test_output_folder_checked_before_work(capsys, tmp_path, monkeypatch):
    f = tmp_path / "a-file"
    f.write_text("x")
    code = main(["simulate", *SHORT, "--out", str(f)])
    assert code == 2 and "expected a folder" in capsys.readouterr().err
    other = tmp_path / "maps"
    other.mkdir()
    (other / MANIFEST).write_text(json.dumps({"command": "region", "files": []}))
    assert main(["simulate", *SHORT, "--out", str(other)]) == 2
    assert "holds the outputs of 'stringstab region'" in capsys.readouterr().err

    import stringstab.io.outputs as outputs

    def deny(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(outputs.tempfile, "mkstemp", deny)  # root ignores chmod: fail the probe
    _refused(capsys, tmp_path, *SHORT, match="cannot write in the folder")


def test_a_second_run_replaces_the_first(capsys, tmp_path):
    out = tmp_path / "out"
    assert main(["simulate", "--duration", "10", "--followers", "2", "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "damping.png", "metrics.json",
                                                     "platoon.png", "report.html", "report.md",
                                                     "trajectories.npz"]
    (out / "notes.txt").write_text("mine")
    assert main(["simulate", *SHORT, "--followers", "2", "--format", "csv", "--out", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "metrics.json", "notes.txt",
                                                     "report.html", "report.md", "trajectories.csv"]


def test_parquet_trajectories(tmp_path, capsys):
    pq = pytest.importorskip("pyarrow.parquet")
    out = tmp_path / "out"
    assert main(["simulate", *SHORT, "--followers", "2", "--format", "parquet", "--out", str(out)]) == 0
    t = pq.read_table(out / "trajectories.parquet")
    assert t.column_names == ["t", "vehicle", "position", "speed", "accel", "gap", "headway", "command"]
    assert t.num_rows == 101 * 3
    with open(out / "metrics.json") as fh:  # the run document beside it
        doc = json.load(fh)
    assert doc["run"]["followers"] == 2
    assert doc["units"]["TIT"] == "s^2" and doc["units"]["M_CI"] == "m^2/s^6"
    assert set(doc["units"]) <= set(doc)
