"""The command line for the sampled and robust loops: certify, derive (issue 10, phase 2).

Exit codes, the outputs in every format (with the sample time and the box), the verdicts
against independent truth, and bad input: one line, exit 2, nothing on stdout, no file.
"""

import csv
import io
import json

import numpy as np
import pytest
import sympy as sp
from numpy.testing import assert_allclose

from stringstab.certify.sampled_frequency import sampled_response
from stringstab.certify.schur import schur_margins
from stringstab.cli import main
from tests._sampled_truth import THETA, pair_response, pair_roots

ISSUE = ["1.2,0.5,0.6", "--sample-time", "0.1", "--tau", "0.1", "--delta", "0.2", "--headway", "1.1"]


def _run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_the_issue_command_gives_a_sound_verdict_with_the_peak(capsys):
    code, out, err = _run(capsys, "certify", *ISSUE)
    assert code == 0 and err == ""
    lines = out.splitlines()
    assert lines[0] == "# tau = 0.1, delta = 0.2, headway = 1.1, sample_time = 0.1, method = exact"
    head = lines[1].split()
    assert head[:4] == ["k_x", "k_v", "k_a", "schur"]
    assert {"sup|H|", "ω_peak[rad/s]", "θ_peak[rad/sample]"} <= set(head)
    row = dict(zip(head, lines[2].split()))
    assert row["verdict"] == "certified" and row["sup|H|"] == "1" and row["ω_peak[rad/s]"] == "0"
    # independent truth: Schur by numpy.roots of the expm construction, |H| ≤ 1 on a sweep
    assert np.max(np.abs(pair_roots(1.2, 0.5, 0.1, 1.1, 0.1))) < 1
    assert np.max(np.abs(pair_response(THETA, 1.2, 0.5, 0.6, 0.1, 0.2, 1.1, 0.1))) <= 1 + 1e-12


def test_json_carries_the_sample_time_the_box_and_the_peak(capsys):
    code, out, _ = _run(capsys, "certify", "1.2,0.5,0.6", "0.9,-0.5,1.1", "--sample-time", "0.1",
                        "--format", "json")
    assert code == 1
    doc = json.loads(out)
    assert doc["params"] == {"tau": 0.1, "delta": 0.2, "headway": 1.1, "sample_time": 0.1,
                             "method": "exact"}
    r = doc["results"][1]
    assert r["verdict"] == "not_certified" and r["sample_time"] == 0.1
    assert r["box"] == {"tau_lo": 0.1, "tau_hi": 0.1, "delta_lo": 0.2, "delta_hi": 0.2,
                        "headway_lo": 1.1, "headway_hi": 1.1}
    # the peak and its frequency, in rad/s and rad/sample, on the independent construction
    assert_allclose(r["peak_omega"] * 0.1, r["peak_theta"], rtol=1e-12)
    h = abs(pair_response(np.array([r["peak_theta"]]), 0.9, -0.5, 1.1, 0.1, 0.2, 1.1, 0.1))[0]
    assert_allclose(r["sup_gain"], h, rtol=1e-9)
    assert r["sup_gain"] > 1.09
    assert doc["summary"]["sample_time"] == 0.1 and doc["summary"]["box"]["tau"] == [0.1, 0.1]


def test_intervals_give_the_robust_certificate_with_a_witness(capsys):
    code, out, _ = _run(capsys, "certify", "1.2,0.5,0.6", "0.9,-0.5,1.1", "--tau", "0.1:0.5",
                        "--delta", "0.1:0.3", "--format", "json")
    assert code == 1
    doc = json.loads(out)
    assert doc["params"]["tau"] == [0.1, 0.5] and doc["params"]["delta"] == [0.1, 0.3]
    assert doc["params"]["sample_time"] is None
    good, bad = doc["results"]
    assert good["verdict"] == "certified" and bad["verdict"] == "not_certified"
    w = bad["witness"]
    assert 0.1 <= w["tau"] <= 0.5 and 0.1 <= w["delta"] <= 0.3 and bad["sup_gain"] > 1
    assert doc["summary"]["box"] == {"tau": [0.1, 0.5], "delta": [0.1, 0.3], "headway": [1.1, 1.1]}
    code, out, _ = _run(capsys, "certify", "1.2,0.5,0.6", "--tau", "0.1:0.5")
    assert code == 0 and out.startswith("# tau = 0.1:0.5, delta = 0.2, headway = 1.1")


def test_sampled_box_table(capsys):
    code, out, _ = _run(capsys, "certify", "1.2,0.5,0.6", "--tau", "0.1:0.2", "--sample-time",
                        "0.1")
    assert code == 0
    assert out.splitlines()[0].startswith("# tau = 0.1:0.2, delta = 0.2, headway = 1.1, sample_time = 0.1")
    assert "heterogeneous = yes" in out


@pytest.mark.parametrize("fmt", ["csv", "parquet", "npz"])
def test_files_carry_the_sample_time_and_the_box(tmp_path, capsys, fmt):
    out = tmp_path / f"r.{fmt}"
    code, stdout, _ = _run(capsys, "certify", "1.2,0.5,0.6", "0.9,-0.5,1.1", "--sample-time",
                           "0.1", "--delta", "0.15:0.25", "--format", fmt, "--out", str(out))
    assert code == 1 and stdout == ""
    if fmt == "csv":
        rows = list(csv.DictReader(io.StringIO(out.read_text())))
        cols = {k: [r[k] for r in rows] for k in rows[0]}
    elif fmt == "parquet":
        import pyarrow.parquet as pq

        t = pq.read_table(out)
        cols = {k: [str(v) for v in t.column(k).to_pylist()] for k in t.column_names}
        meta = json.loads(t.schema.metadata[b"stringstab.params"])
        assert meta["delta"] == [0.15, 0.25] and meta["sample_time"] == 0.1
    else:
        with np.load(out) as z:
            cols = {k: [str(v) for v in z[k].tolist()] for k in z.files if not k.startswith("_")}
            assert json.loads(str(z["_summary"]))["box"]["delta"] == [0.15, 0.25]
    assert cols["sample_time"] == ["0.1", "0.1"]
    assert cols["box_delta_lo"] == ["0.15", "0.15"] and cols["box_delta_hi"] == ["0.25", "0.25"]
    assert cols["verdict"] == ["certified", "not_certified"]
    assert {"witness_omega", "witness_theta", "witness_tau_prev"} <= set(cols)


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("args, msg", [
    (["--sample-time", "0"], "--sample-time .* > 0 s; got '0'"),
    (["--sample-time", "-0.1"], "--sample-time"),
    (["--sample-time", "nan"], "--sample-time"),
    (["--sample-time", "inf"], "--sample-time"),
    (["--sample-time", "fast"], "--sample-time .* must be a number"),
    (["--tau", "0.5:0.1"], "tau interval must have lo <= hi"),
    (["--delta", "-0.1:0.2"], "delta .* interval must be >= 0"),
    (["--headway", "-1:1"], "headway .* interval must be >= 0"),
    (["--tau", "0:0.5"], "tau .* interval must stay > 0"),
    (["--tau", "0.1:"], "LO:HI"),
    (["--tau", "0.1:0.2:0.3"], "LO:HI"),
    (["--delta", "a:b"], "LO:HI"),
    (["--tau", "0.1:nan"], "finite"),
    (["--sample-time", "0.1", "--method", "pade"], "continuous loop"),
    (["--tau", "0.1:0.2", "--method", "pade"], "continuous loop"),
])
def test_bad_input_one_line_exit_2_no_verdicts(tmp_path, capsys, args, msg):
    out = tmp_path / "r.json"
    code, stdout, err = _run(capsys, "certify", "1.2,0.5,0.6", *args, "--format", "json",
                             "--out", str(out))
    assert code == 2 and stdout == "" and not out.exists()
    assert err.count("\n") == 1 and err.startswith("stringstab certify: error: ")
    import re

    assert re.search(msg, err), err


def test_sample_time_longer_than_the_data_is_refused(tmp_path, capsys):
    f = tmp_path / "rollout.csv"
    f.write_text("t,k_x,k_v,k_a\n0.0,1.2,0.5,0.6\n0.05,1.2,0.5,0.6\n0.08,1.2,0.5,0.6\n")
    code, stdout, err = _run(capsys, "certify", "--file", str(f), "--sample-time", "0.1")
    assert code == 2 and stdout == ""
    assert "spans 0.08 s" in err and "--sample-time 0.1 s" in err and err.count("\n") == 1
    code, stdout, _ = _run(capsys, "certify", "--file", str(f), "--sample-time", "0.05")
    assert code == 0 and stdout.splitlines()[1].startswith("t ")
    # the tuning command refuses it too
    code, stdout, err = _run(capsys, "tune", "--file", str(f), "--sample-time", "0.1")
    assert code == 2 and stdout == "" and "horizon" in err


# --------------------------------------------------------------------------- derive --sample-time
def test_derive_sample_time_json_is_the_sampled_loop(capsys):
    code, out, _ = _run(capsys, "derive", "--sample-time", "0.1", "--substitute",
                        "tau=0.1,delta=0.25,headway=1.1", "--format", "json")
    assert code == 0
    doc = json.loads(out)
    assert doc["sample_time"] == 0.1 and doc["m"] == 2 and doc["epsilon"] == "1/2"
    kx, kv, ka = sp.symbols("k_x k_v k_a", real=True)
    z = sp.Symbol("z")
    # H(z) of the document equals the numeric certificate's (and so the expm truth) on the circle
    H = sp.lambdify((z, kx, kv, ka), sp.sympify(doc["H"], locals={"k_x": kx, "k_v": kv,
                                                                   "k_a": ka, "z": z}))
    for th in (0.3, 1.1, 2.5):
        assert_allclose(complex(H(np.exp(1j * th), 1.2, 0.5, 0.6)),
                        complex(sampled_response(th, 1.2, 0.5, 0.6, tau=0.1, delta=0.25,
                                                 headway=1.1, sample_time=0.1)), rtol=1e-10)
    # the Schur conditions in the gains: their signs are those of the certificate's
    conds = [sp.lambdify((kx, kv), sp.sympify(c, locals={"k_x": kx, "k_v": kv}))
             for c in doc["schur_conditions_gains"]]
    rng = np.random.default_rng(0)
    for a, b in rng.uniform(-2, 3, (40, 2)):
        mine = np.array([float(c(a, b)) for c in conds])
        want = schur_margins(a, b, tau=0.1, headway=1.1, sample_time=0.1)
        assert np.array_equal(mine > 0, want > 0)
        radius = np.max(np.abs(pair_roots(a, b, 0.1, 1.1, 0.1)))
        assert bool(np.all(mine > 0)) == bool(radius < 1)


def test_derive_sample_time_text_and_latex(capsys):
    code, out, _ = _run(capsys, "derive", "--sample-time", "0.1", "--format", "text")
    assert code == 0 and "Schur (each > 0, in the gains):" in out
    assert out.startswith("# stringstab derive --sample-time 0.1")
    assert "H(z) = " in out and "Δ(z) (characteristic polynomial) = " in out
    code, out, _ = _run(capsys, "derive", "--sample-time", "0.1", "--format", "latex")
    assert code == 0 and r"\begin{align*}" in out and r"\Delta(z) &= " in out


@pytest.mark.parametrize("args, msg", [
    (["--sample-time", "0"], "--sample-time"), (["--sample-time", "x"], "--sample-time"),
    (["--sample-time", "0.1", "--errata"], "--errata"),
    (["--sample-time", "0.1", "--delay-order", "3"], "--delay-order"),
    (["--sample-time", "0.1", "--substitute", "tau_prev=0"], "tau_prev"),
])
def test_derive_sample_time_bad_input(capsys, args, msg):
    code, out, err = _run(capsys, "derive", *args)
    assert code == 2 and out == "" and msg in err and err.count("\n") == 1
