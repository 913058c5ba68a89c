"""`stringstab tune` end to end: outputs, formats and exit codes 0/1/2."""

import csv
import io
import json

import pytest

from stringstab.certify.api import certify
from stringstab.cli import main

P = {"tau": 0.1, "delta": 0.2, "headway": 1.1}


def _json(capsys, *args, code=0):
    assert main(["tune", *args, "--format", "json"]) == code
    return json.loads(capsys.readouterr().out)


def test_projection_json_exit_0(capsys):
    doc = _json(capsys, "0.9,-0.5,1.1", "1.3,0,0.6")
    rows = doc["results"]
    assert [r["status"] for r in rows] == ["repaired", "unchanged"]
    for r in rows:
        assert r["method"] == "projection" and r["certified"] and r["verdict"] == "certified"
        assert certify(r["k_x"], r["k_v"], r["k_a"], **P).certified
        assert set(r) >= {"k_x_in", "k_v_in", "k_a_in", "distance", "iterations", "time_ms", "message"}
    assert (rows[1]["k_x"], rows[1]["k_v"], rows[1]["k_a"]) == (1.3, 0.0, 0.6)
    assert doc["summary"]["projection"]["certified"] == 2
    assert doc["params"]["tau"] == 0.1


def test_both_methods_and_exit_1_when_an_output_is_not_certified(capsys):
    # region growing as printed cannot repair (-1.9, -1.9, -1.9): "No optimized solution found"
    doc = _json(capsys, "-1.9,-1.9,-1.9", "--method", "both", code=1)
    rg, pj = doc["results"]
    assert rg["method"] == "region-growing" and rg["status"] == "no_solution" and not rg["certified"]
    assert "No optimized solution found" in rg["message"]
    assert pj["method"] == "projection" and pj["certified"]


def test_table_and_csv(capsys):
    assert main(["tune", "0.9,-0.5,1.1", "-m", "both"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("# tau = 0.1")
    assert "region-growing" in out and "projection" in out and "distance" in out
    assert main(["tune", "0.9,-0.5,1.1", "--format", "csv"]) == 0
    rows = list(csv.DictReader(io.StringIO(capsys.readouterr().out)))
    assert len(rows) == 1 and rows[0]["certified"] == "True" and rows[0]["method"] == "projection"


def test_file_input_keeps_t_and_vehicle(tmp_path, capsys):
    f = tmp_path / "g.csv"
    f.write_text("t,vehicle,k_x,k_v,k_a\n0.0,1,0.9,-0.5,1.1\n0.1,2,1.3,0,0.6\n")
    out = tmp_path / "r.json"
    assert main(["tune", "--file", str(f), "--format", "json", "--out", str(out)]) == 0
    assert "2 of 2 outputs certified" in capsys.readouterr().err
    rows = json.loads(out.read_text())["results"]
    assert [(r["t"], r["vehicle"]) for r in rows] == [(0.0, 1), (0.1, 2)]


def test_region_growing_options(capsys):
    doc = _json(capsys, "0.9,-0.5,1.1", "-m", "region-growing", "--criterion", "printed", code=1)
    assert doc["results"][0]["status"] == "taylor_stable"
    doc = _json(capsys, "0.9,-0.5,1.1", "-m", "region-growing", "--r0", "0.05", "--grid", "1")
    assert doc["params"]["r0"] == 0.05


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (["0.9,-0.5"], "expected 3 comma-separated numbers"),
        (["0.9,-0.5,abc"], "k_a"),
        ([], "expected gain triples"),
        (["0.9,-0.5,1.1", "--tau", "-1"], "tau"),
        (["0.9,-0.5,1.1", "--weights", "1,0,1"], "--weights"),
        (["0.9,-0.5,1.1", "--bounds", "2,-2"], "--bounds"),
        (["0.9,-0.5,1.1", "--grid", "0"], "--grid"),
        (["0.9,-0.5,1.1", "--eps", "0"], "--eps"),
        (["--file", "/nonexistent/gains.csv"], "gains.csv"),
    ],
)
def test_bad_input_exit_2(capsys, args, match):
    assert main(["tune", *args]) == 2
    cap = capsys.readouterr()
    assert cap.out == ""
    assert match in cap.err and cap.err.count("\n") == 1


def test_bad_method_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as e:
        main(["tune", "0.9,-0.5,1.1", "--method", "newton"])
    assert e.value.code == 2
