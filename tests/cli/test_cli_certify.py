"""`stringstab certify` end to end: inputs, outputs, exit codes and bad input."""

import csv
import io
import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

from stringstab.cli import certify as cli_certify
from stringstab.cli import main
from stringstab.io.gains import read_gains

TAU, DELTA, HEADWAY = 0.1, 0.2, 1.1
#: Certified: internally stable and sup|Γ| = |Γ(0)| = 1 (checked against the sweep below).
GOOD = ["1.3,0,0.6", "0.45,0.6,0.3"]
#: Not certified: sup|Γ| ≈ 1.0438 at ω ≈ 1.70 rad/s, yet the printed Proposition 1 says stable.
BAD = "0.9,-0.5,1.1"
#: Not internally stable (k_x < 0): ‖Γ‖∞ = ∞.
UNSTABLE = "-0.5,1,1"

RESULT_KEYS = {"k_x", "k_v", "k_a", "hurwitz", "verdict", "type", "sup_gain", "peak_omega",
               "margin", "hurwitz_margin", "taylor_derived", "taylor_printed", "method"}
TAYLOR_KEYS = {"psi1", "psi2", "psi3", "lambda", "sign", "type"}
SUMMARY_KEYS = {"n", "certified", "not_certified", "inconclusive", "certified_row_share"}


def _sweep(k, tau=TAU, delta=DELTA, headway=HEADWAY):
    """Independent truth: |Γ(jω)| on a fine grid and the poles by numpy.roots."""
    kx, kv, ka = k
    w = np.linspace(0.0, 50.0, 200_001)
    s = 1j * w
    num = kx + kv * s + ka * s**2 * np.exp(-delta * s)
    den = tau * s**3 + s**2 + (kv + headway * kx) * s + kx
    g = np.abs(num / den)
    poles = np.roots([tau, 1.0, kv + headway * kx, kx])
    return g.max(), w[g.argmax()], bool(np.all(poles.real < 0))


def _run(capsys, *argv):
    code = main(["certify", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def _json(capsys, *argv):
    code, out, err = _run(capsys, "--format", "json", *argv)
    return code, json.loads(out), err


# --------------------------------------------------------------------------- bad input (exit 2)


@pytest.fixture
def bad_files(tmp_path):
    (tmp_path / "empty.csv").write_text("")
    (tmp_path / "typo.csv").write_text("t,k_x,kv,k_a\n0,1,1,1\n")
    (tmp_path / "nan.csv").write_text("k_x,k_v,k_a\n1,1,1\n1,nan,1\n")
    (tmp_path / "text.json").write_text('[{"k_x": 1, "k_v": "fast", "k_a": 1}]')
    (tmp_path / "gains.txt").write_text("k_x,k_v,k_a\n1,1,1\n")
    (tmp_path / "latin.csv").write_bytes(b"k_x,k_v,k_a\n1,1,\xe9\n")
    return tmp_path


@pytest.mark.parametrize("argv, message", [
    (["nan,1,1"], "triple 1 'nan,1,1', k_x: expected a finite number; found 'nan'"),
    (["1.3,0,0.6", "1,inf,1"], "triple 2 '1,inf,1', k_v: expected a finite number; found 'inf'"),
    (["-inf,1,1"], "k_x: expected a finite number; found '-inf'"),
    (["1,fast,1"], "k_v: expected a finite number; found 'fast'"),
    (["1,2"], "expected 3 comma-separated numbers k_x,k_v,k_a; found 2 fields"),
    (["--tau", "0", "1,1,1"], "tau (actuator lag) must be a finite number > 0 s; got '0'"),
    (["--tau", "-0.1", "1,1,1"], "tau (actuator lag) must be a finite number > 0 s; got '-0.1'"),
    (["--delta", "-0.1", "1,1,1"], "delta (communication delay) must be >= 0 s; got '-0.1'"),
    (["--headway", "nan", "1,1,1"], "headway (desired time headway T*) must be finite"),
    (["--tau", "abc", "1,1,1"], "tau (actuator lag) must be a number; got 'abc'"),
    (["--pade-order", "0", "1,1,1"], "--pade-order must be an integer >= 1"),
    ([], "expected gain triples K_X,K_V,K_A"),
    (["1,1,1", "--file", "{d}/nan.csv"], "expected gain triples or --file, not both"),
    (["--file", "{d}/missing.csv"], "missing.csv: no such file"),
    (["--file", "{d}/empty.csv"], "empty.csv: empty file; expected a CSV header"),
    (["--file", "{d}/typo.csv"], "missing column 'k_v'"),
    (["--file", "{d}/nan.csv"], "nan.csv, line 3, column 'k_v': expected a finite number; found 'nan'"),
    (["--file", "{d}/text.json"], "item [0], key 'k_v': expected a finite number; found 'fast'"),
    (["--file", "{d}/gains.txt"], "unsupported file extension '.txt'; expected .csv, .json or .npz"),
    (["--file", "{d}/latin.csv"], "not UTF-8 text"),
    (["--file", "{d}"], "unsupported file extension"),
    (["1,1,1", "--out", "{d}/empty.csv/x.json"], "empty.csv' in "),  # a path through a file
])
def test_bad_input_exit_2(capsys, bad_files, argv, message):
    argv = [a.replace("{d}", str(bad_files)) for a in argv]
    out_file = bad_files / "out.json"
    if "--out" not in argv:
        argv += ["--out", str(out_file)]
    code, out, err = _run(capsys, *argv)
    assert code == 2
    assert out == ""
    assert err.count("\n") == 1 and err.startswith("stringstab certify: error: ")
    assert message in err
    assert not out_file.exists()
    assert sorted(p.name for p in bad_files.iterdir()) == sorted(
        ["empty.csv", "typo.csv", "nan.csv", "text.json", "gains.txt", "latin.csv"]
    )  # no partial or temporary output file


def test_bad_input_leaves_existing_output_untouched(capsys, tmp_path):
    out_file = tmp_path / "out.json"
    out_file.write_text("previous results")
    code, out, _ = _run(capsys, "1,nan,1", "--out", str(out_file))
    assert (code, out) == (2, "")
    assert out_file.read_text() == "previous results"


def test_argparse_usage_errors_exit_2(capsys):
    with pytest.raises(SystemExit) as e:
        main(["certify", "1,1,1", "--format", "xml"])
    assert e.value.code == 2
    out, err = capsys.readouterr()
    assert out == "" and "invalid choice: 'xml'" in err


# --------------------------------------------------------------------------- verdicts and exit codes


def test_exit_0_when_all_certified(capsys):
    code, doc, _ = _json(capsys, *GOOD)
    assert code == 0
    assert [r["verdict"] for r in doc["results"]] == ["certified", "certified"]
    for r in doc["results"]:
        peak, _, stable = _sweep((r["k_x"], r["k_v"], r["k_a"]))
        assert stable and r["hurwitz"] is True
        assert_allclose(peak, 1.0, rtol=0, atol=1e-12)  # independent sweep: never above 1
        assert_allclose(r["sup_gain"], 1.0, rtol=0, atol=1e-9)


def test_exit_1_and_verdicts_against_a_sweep(capsys):
    code, doc, _ = _json(capsys, *GOOD, BAD, UNSTABLE)
    assert code == 1
    bad, unstable = doc["results"][2], doc["results"][3]
    peak, w_peak, stable = _sweep((0.9, -0.5, 1.1))
    assert stable and peak > 1.04
    assert bad["verdict"] == "not_certified" and bad["hurwitz"] is True
    assert_allclose(bad["sup_gain"], peak, rtol=1e-6)
    assert_allclose(bad["peak_omega"], w_peak, atol=1e-3)
    assert bad["margin"] < 0
    # the printed Proposition 1 (IDL eqs 12-15) says stable here: the tool reports both
    assert bad["taylor_printed"]["sign"] == "stable"
    assert not _sweep((-0.5, 1.0, 1.0))[2]
    assert unstable["verdict"] == "not_certified" and unstable["hurwitz"] is False
    assert unstable["sup_gain"] is None  # ‖Γ‖∞ = ∞ is JSON null
    assert doc["summary"] == {"n": 4, "certified": 2, "not_certified": 2, "inconclusive": 0,
                              "certified_row_share": 0.5}


def test_negative_triples_are_positionals(capsys):
    code, doc, _ = _json(capsys, "-0.5,1,1", "-.5,-1,-1", "--delta", "0.3")
    assert code == 1
    assert [(r["k_x"], r["k_v"], r["k_a"]) for r in doc["results"]] == [(-0.5, 1, 1), (-0.5, -1, -1)]
    assert doc["params"]["delta"] == 0.3


def test_json_schema(capsys):
    code, doc, err = _json(capsys, BAD, "--tau", "0.2", "--headway", "1.5")
    assert code == 1
    assert list(doc) == ["params", "results", "summary"]
    assert doc["params"] == {"tau": 0.2, "delta": DELTA, "headway": 1.5, "method": "exact"}
    (r,) = doc["results"]
    assert RESULT_KEYS <= set(r)
    assert set(r["taylor_derived"]) >= TAYLOR_KEYS and set(r["taylor_printed"]) >= TAYLOR_KEYS
    assert r["verdict"] in ("certified", "not_certified", "inconclusive")
    assert r["type"] in ("I", "II", "III", "IV")
    assert r["method"] == "exact"
    assert set(doc["summary"]) == SUMMARY_KEYS
    assert err == ""


def test_cli_matches_library(capsys):
    from stringstab.certify.api import certify

    _, doc, _ = _json(capsys, BAD, "--delta", "0.25")
    ref = certify(0.9, -0.5, 1.1, tau=TAU, delta=0.25, headway=HEADWAY).as_dict()
    assert doc["results"][0] == json.loads(json.dumps(ref))


def test_table_prints_defaults(capsys):
    code, out, err = _run(capsys, *GOOD, BAD)
    lines = out.splitlines()
    assert lines[0] == f"# tau = {TAU}, delta = {DELTA}, headway = {HEADWAY}, method = exact"
    assert lines[1].split()[:5] == ["k_x", "k_v", "k_a", "hurwitz", "verdict"]
    assert "not_certified" in lines[4]
    assert lines[-1].startswith("# n = 3, certified = 2, not_certified = 1")
    assert code == 1 and err == ""


def test_help_documents_defaults(capsys):
    with pytest.raises(SystemExit) as e:
        main(["certify", "--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    for text in (f"(default: {TAU})", f"(default: {DELTA})", f"(default: {HEADWAY})",
                 "exit status", "K_X,K_V,K_A"):
        assert text in out


def test_csv_output_round_trips(capsys, tmp_path):
    out_file = tmp_path / "r.csv"
    code, out, err = _run(capsys, *GOOD, BAD, "--format", "csv", "--out", str(out_file))
    assert (code, out) == (1, "")
    assert "2 of 3 certified" in err
    rows = list(csv.DictReader(io.StringIO(out_file.read_text())))
    assert [r["verdict"] for r in rows] == ["certified", "certified", "not_certified"]
    assert {r["tau"] for r in rows} == {str(TAU)} and rows[2]["taylor_printed_sign"] == "stable"
    back = read_gains(out_file)  # the output is itself a valid gain file
    assert_allclose(back.K, [[1.3, 0, 0.6], [0.45, 0.6, 0.3], [0.9, -0.5, 1.1]], rtol=0, atol=0)


def test_json_output_round_trips(capsys, tmp_path):
    first = tmp_path / "a.json"
    assert main(["certify", *GOOD, "--format", "json", "--out", str(first)]) == 0
    code, doc, _ = _json(capsys, "--file", str(first))
    assert code == 0
    assert [(r["k_x"], r["k_v"], r["k_a"]) for r in doc["results"]] == [(1.3, 0, 0.6), (0.45, 0.6, 0.3)]


# --------------------------------------------------------------------------- files and time series

ROLLOUT = "# policy rollout\nt,vehicle,k_x,k_v,k_a\n0.0,1,1.3,0,0.6\n0.1,1,0.9,-0.5,1.1\n0.0,2,0.45,0.6,0.3\n"


def test_time_series_carries_t_and_vehicle(capsys, tmp_path):
    p = tmp_path / "rollout.csv"
    p.write_text(ROLLOUT)
    code, doc, _ = _json(capsys, "--file", str(p))
    assert code == 1
    assert [(r["t"], r["vehicle"], r["verdict"]) for r in doc["results"]] == [
        (0.0, 1, "certified"), (0.1, 1, "not_certified"), (0.0, 2, "certified")]
    assert list(doc["results"][0])[:5] == ["t", "vehicle", "k_x", "k_v", "k_a"]
    code, out, _ = _run(capsys, "--file", str(p), "--format", "csv")
    rows = list(csv.DictReader(io.StringIO(out)))
    assert [(r["t"], r["vehicle"]) for r in rows] == [("0.0", "1"), ("0.1", "1"), ("0.0", "2")]
    code, out, _ = _run(capsys, "--file", str(p))
    assert out.splitlines()[1].split()[:2] == ["t", "vehicle"]


def test_json_and_npz_files(capsys, tmp_path):
    j = tmp_path / "g.json"
    j.write_text(json.dumps({"gains": [{"k_x": 1.3, "k_v": 0, "k_a": 0.6}]}))
    assert _json(capsys, "--file", str(j))[0] == 0
    z = tmp_path / "g.npz"
    np.savez(z, K=np.array([[1.3, 0, 0.6], [0.9, -0.5, 1.1]]), t=[0.0, 0.5])
    code, doc, _ = _json(capsys, "--file", str(z))
    assert code == 1 and [r["t"] for r in doc["results"]] == [0.0, 0.5]


def test_stdin(capsys, monkeypatch):
    monkeypatch.setattr("sys.stdin", io.StringIO("k_x,k_v,k_a\n1.3,0,0.6\n"))
    code, doc, _ = _json(capsys, "--file", "-")
    assert code == 0 and doc["summary"]["n"] == 1


def test_bundled_example_file(capsys):
    from pathlib import Path

    import stringstab

    p = Path(stringstab.__file__).parent / "data" / "examples" / "gain_rollout.csv"
    code, doc, _ = _json(capsys, "--file", str(p))
    assert code == 1 and doc["summary"]["n"] == 48
    assert {r["vehicle"] for r in doc["results"]} == {1, 2}


def test_progress_bar(capsys, monkeypatch):
    from stringstab.progress import Progress

    monkeypatch.setattr(cli_certify, "PROGRESS_ROWS", 1)
    monkeypatch.setattr(Progress, "EVERY", 0.0)  # a line at once (not a terminal: lines)
    _, out, err = _run(capsys, *GOOD, "--format", "json")
    assert "certify" in err and "chunk" in err and "\r" not in err
    json.loads(out)  # the bar never goes to stdout
    _, _, err = _run(capsys, *GOOD, "--no-progress")
    assert err == ""


# --------------------------------------------------------------------------- --method pade


def test_pade_reports_python_control(capsys):
    code, doc, _ = _json(capsys, BAD, UNSTABLE, "--method", "pade", "--pade-order", "4")
    assert code == 1
    assert doc["params"]["method"] == "pade" and doc["params"]["pade_order"] == 4
    bad, unstable = doc["results"]
    assert {"order", "stable", "hinf", "verdict"} <= set(bad["pade"])
    assert bad["pade"]["order"] == 4 and bad["pade"]["verdict"] == "not_certified"
    assert_allclose(bad["pade"]["hinf"], bad["sup_gain"], rtol=1e-3)  # Padé(4) of a 0.2 s delay
    assert unstable["pade"]["stable"] is False and unstable["pade"]["hinf"] is None


def test_pade_disagreement_warning(capsys):
    records = [
        {"k_x": 1.0, "k_v": 0.5, "k_a": 0.2, "verdict": "certified", "sup_gain": 1.0,
         "pade": {"verdict": "not_certified", "stable": True, "hinf": 1.001, "agrees": False}},
        {"k_x": 1.0, "k_v": 0.5, "k_a": 0.2, "verdict": "certified", "sup_gain": 1.0,
         "pade": {"verdict": "certified", "stable": True, "hinf": 1.0, "agrees": True}},
    ]
    cli_certify._warn_disagreements(records, 5)
    err = capsys.readouterr().err
    assert "disagrees with the exact certificate on 1 of 2 row(s)" in err
    assert "row 1: K=(1, 0.5, 0.2) exact certified" in err and "pade not_certified" in err
    cli_certify._warn_disagreements(records[1:], 5)
    assert capsys.readouterr().err == ""


def test_demo_certify_step(capsys, tmp_path):
    assert main(["demo", "--out", str(tmp_path), "--only", "certify"]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())["certify"]
    assert summary["rollout"]["n"] == 48
    for name in summary["files"]:
        assert (tmp_path / "certify" / name).stat().st_size > 0
    bad = next(r for r in summary["triples"] if r["K"] == [0.9, -0.5, 1.1])
    assert bad == {"K": [0.9, -0.5, 1.1], "verdict": "not_certified", "taylor_printed": "stable",
                   "sup_gain": pytest.approx(1.0438, abs=1e-4)}


def test_docs_example_is_what_the_tool_prints(capsys):
    """The first console example of docs/certify.md is the tool's actual output."""
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[2] / "docs" / "certify.md").read_text()
    block = doc.split("```console\n", 1)[1].split("```", 1)[0].splitlines()
    assert block[0] == "$ stringstab certify 0.9,-0.5,1.1 1.3,0,0.6 -0.5,1,1"
    shown = block[1:block.index("$ echo $?")]
    code, out, _ = _run(capsys, "0.9,-0.5,1.1", "1.3,0,0.6", "-0.5,1,1")
    assert out.splitlines() == shown
    assert str(code) == block[block.index("$ echo $?") + 1]
