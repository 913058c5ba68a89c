"""``stringstab platoon`` and :mod:`stringstab.mixed` (issue 27, items 2-4 and 6).

Independent truths: ∏|Γ_i(jω)| of the written-out model on a fine grid
(``analysis/platoon_validate.py``), the toolkit's time-domain simulator against the transfer
functions (a sinusoid's steady amplitude), the recorded leader's replay in Eclipse SUMO against
the toolkit's simulator, and random gains against the exclusion proof.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
from pathlib import Path

import numpy as np
import pytest

from stringstab.certify.api import certify_string
from stringstab.certify.head_to_tail import Vehicle
from stringstab.cli import main
from stringstab.errors import StringStabError
from stringstab.mixed import read_vehicles
from stringstab.mixed.cav import CavSpec, string_with_cavs
from stringstab.mixed.design import design_cavs
from stringstab.mixed.exclusion import prove_no_cav
from stringstab.mixed.replay import probe
from stringstab.params import Params

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("platoon_validate_cli",
                                               ROOT / "analysis" / "platoon_validate.py")
VALIDATE = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(VALIDATE)

HEADER = "name,k_x,k_v,k_a,tau,delta,headway\n"
ACC = "acc,0.1,0.3,0,0.5,0,1.5\n"
CAV = "cav,0.5,1.0,0.6,0.2,0.2,2.0\n"


def run(*argv: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(argv))
    return code, out.getvalue(), err.getvalue()


def write(tmp_path: Path, text: str, name: str = "string.csv") -> str:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return str(p)


# ----------------------------------------------------------------------------- certify
def test_certify_a_csv_string_json_and_exit_codes(tmp_path):
    code, out, err = run("platoon", "certify", write(tmp_path, HEADER + ACC + CAV), "--format", "json")
    assert code == 0 and err == ""
    d = json.loads(out)
    assert d["head_to_tail"]["verdict"] == "certified"
    assert [v["verdict"] for v in d["vehicles"]] == ["not_certified", "certified"]
    assert d["head_to_tail"]["worst_substring"]["first"] == 1  # the ACC car alone amplifies
    code, out, _ = run("platoon", "certify", write(tmp_path, HEADER + ACC + ACC + CAV))
    assert code == 1 and "not_certified" in out.splitlines()[0]


@pytest.mark.parametrize("text, match", [
    ("", "expected a header"),
    (HEADER, "at least 2 vehicles .* got 0"),
    (HEADER + ACC, "at least 2 vehicles .* got 1"),
    ("name,k_x,k_v,k_a,tau,delta\n" + "a,1,1,0,0.1,0\n" * 2, "missing headway"),
    (HEADER + ACC + "cav,0.5,,0.6,0.2,0.2,2.0\n", "row 2: missing k_v"),
    (HEADER + ACC + "cav,0.5,fast,0.6,0.2,0.2,2.0\n", "row 2, column k_v must be a number"),
    (HEADER + ACC + "cav,nan,1,0.6,0.2,0.2,2.0\n", r"vehicle 2 \(cav\): k_x must be finite"),
    (HEADER + ACC + "cav,0.5,1,0.6,-0.2,0.2,2.0\n", r"vehicle 2 \(cav\): tau"),
    (HEADER + ACC + "cav,0.5,1,0.6,0.2,0.2,2.0,7\n", "row 2 has 8 cells"),
    ("name,k_x,k_v,k_a,tau,delta,headway,speed\n" + "a,1,1,0,0.1,0,1,3\n" * 2, "unknown column speed"),
])
def test_bad_csv_is_one_line_and_exit_2(tmp_path, text, match):
    code, out, err = run("platoon", "certify", write(tmp_path, text))
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1
    import re

    assert re.search(match, err), err


def test_bad_identify_json_is_one_line_and_exit_2(tmp_path):
    for text, match in (("{", "not valid JSON"), ("[1, 2]", "expected a JSON object"),
                        ('{"vehicles": 3}', "'vehicles' list")):
        code, _, err = run("platoon", "certify", write(tmp_path, text, "identify.json"))
        assert code == 2 and match in err and len(err.strip().splitlines()) == 1
    code, _, err = run("platoon", "certify", str(tmp_path / "absent.csv"))
    assert code == 2 and "no such file" in err


def _identify_json(tmp_path, positions, **extra):
    vs = [{"platoon": 0, "position": p, "name": f"car{p}", "predecessor": f"car{p - 1}",
           "k_x": 0.1, "k_v": 0.3, "k_a": 0.0, "tau": 0.5, "delta": 0.0, "headway": 1.5,
           "standstill": 5.0, **extra} for p in positions]
    return write(tmp_path, json.dumps({"command": "identify", "vehicles": vs, "skipped": []}),
                 "identify.json")


def test_identify_json_uses_the_longest_run_and_names_the_rest(tmp_path):
    path = _identify_json(tmp_path, [2, 3, 4, 7])
    rec = read_vehicles(path)
    assert rec.positions == (2, 3, 4) and rec.leader == "car1"
    assert "left out: 7 car7" in rec.note
    code, out, err = run("platoon", "certify", path, "--format", "json", "--positions", "7:7")
    assert code == 2 and "at least 2 vehicles" in err
    code, out, _ = run("platoon", "certify", path, "--format", "json")
    d = json.loads(out)
    assert [v["recorded_position"] for v in d["vehicles"]] == [2, 3, 4]
    assert d["head_to_tail"]["empirical"] is None  # no log named: said so, verdict given
    assert "names no log" in d["head_to_tail"]["empirical_note"]


def test_identify_json_with_a_missing_parameter(tmp_path):
    path = _identify_json(tmp_path, [1, 2], tau=None)
    code, _, err = run("platoon", "certify", path)
    assert code == 2 and "vehicle 1 (car1): missing tau" in err


def test_reaction_delay_with_a_sample_time_is_refused(tmp_path):
    text = "k_x,k_v,k_a,tau,delta,headway,reaction_delay\n0.1,0.3,0,0.5,0,1.5,0.2\n0.5,1,0.6,0.2,0.2,2,0\n"
    code, out, err = run("platoon", "certify", write(tmp_path, text))
    assert code in (0, 1) and "θ_r" in out  # certified with θ_r in continuous time
    code, _, err = run("platoon", "certify", write(tmp_path, text), "--sample-time", "0.1")
    assert code == 2 and "reaction delay" in err


# ----------------------------------------------------------------------------- design
@pytest.mark.parametrize("at, match", [("3", r"1\.\.2"), ("0", "the leader is 0"),
                                       ("1,1", "distinct"), ("x", "positions P")])
def test_cav_positions_outside_the_string_exit_2(tmp_path, at, match):
    code, out, err = run("platoon", "design", "--from", write(tmp_path, HEADER + ACC + ACC),
                         "--cav-at", at)
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    import re

    assert re.search(match, err), err


def test_a_designed_cav_is_certified_by_the_certificate_and_the_grid(tmp_path):
    code, out, _ = run("platoon", "design", "--from", write(tmp_path, HEADER + ACC + ACC),
                       "--cav-at", "2", "--cav-headway", "2", "--format", "json")
    assert code == 0
    d = json.loads(out)
    assert d["design"]["certified"] and d["head_to_tail"]["verdict"] == "certified"
    assert [v["cav"] for v in d["vehicles"]] == [False, True]
    g = d["design"]["gains"][0]
    vs = [Vehicle(0.1, 0.3, 0.0, Params(0.5, 0.0, 1.5)),
          Vehicle(g["k_x"], g["k_v"], g["k_a"], Params(0.1, 0.2, 2.0))]
    assert certify_string(vs).certified
    assert VALIDATE.product_continuous(vs).max() <= 1 + 1e-9  # the independent grid agrees
    assert all(VALIDATE.stable(v) for v in vs)


def test_no_single_cav_exists_is_proven_and_random_gains_agree():
    acc = Vehicle(0.125, 0.35, 0.0, Params(0.76, 0.0, 0.0))  # an amplifying ACC car
    string = [acc, acc, acc]
    spec = CavSpec()  # T* = 1.1 s, gains in [-2, 2], k_x >= 0.01
    ex = prove_no_cav(string, 3, spec)
    assert ex.proven
    rng = np.random.default_rng(0)
    K = np.column_stack([rng.uniform(0.01, 2, 300), rng.uniform(-2, 2, 300), rng.uniform(-2, 2, 300)])
    w = np.concatenate([[0.0], np.geomspace(1e-3, 10, 3000)])
    for k in K:  # none of them passes the independent check
        vs = string_with_cavs(string, [3], [k], spec)
        ok = all(VALIDATE.stable(v) for v in vs) and VALIDATE.product_continuous(vs, w).max() <= 1
        assert not ok
    # the proof does not claim what it cannot: with T* = 10 s a CAV exists, and is not excluded
    assert not prove_no_cav(string, 3, CavSpec(headway=10.0), max_boxes=20_000).proven
    d = design_cavs(string, [3], CavSpec(headway=10.0))
    assert d.certified and d.certificate.certified


def test_design_says_none_exists_and_gives_the_best_sup():
    acc = Vehicle(0.125, 0.35, 0.0, Params(0.76, 0.0, 0.0))
    d = design_cavs([acc, acc, acc], [3])
    assert not d.certified and d.proven_none
    assert "none exists (proven" in d.note and "not a proven minimum" in d.note
    assert np.isfinite(d.certificate.sup_gain) and d.certificate.sup_gain > 1


# ----------------------------------------------------------------------------- simulation
def test_the_simulated_sinusoid_matches_the_product_of_gains():
    acc = Vehicle(0.1, 0.3, 0.0, Params(0.5, 0.0, 1.5))
    cav = Vehicle(0.5, 1.0, 0.6, Params(0.2, 0.2, 2.0), "cav")
    w = 0.245  # the ACC car's peak
    pr = probe([("acc,acc", [acc, acc], [5.0, 5.0]), ("acc,cav", [acc, cav], [5.0, 5.0])], w)
    for m, p in zip(pr.measured, pr.predicted):
        assert m == pytest.approx(p, rel=0.03)
    assert pr.measured[0] > 1 > pr.measured[1]  # the wave grows without the CAV, not with it


def test_simulate_needs_an_identify_json(tmp_path):
    code, _, err = run("platoon", "simulate", "--from", write(tmp_path, HEADER + ACC + CAV),
                       "--cav-at", "2", "--out", str(tmp_path / "o"))
    assert code == 2 and "identify.json" in err
    with pytest.raises(StringStabError, match="names no log"):
        from stringstab.mixed.replay import leader_of

        leader_of(read_vehicles(_identify_json(tmp_path, [1, 2])))


@pytest.mark.parametrize("gains, bounds", [("5,1,0.6", "-2:2"), ("0.5,1,0.6", "-0.5:0.5"),
                                            ("0.001,1,0.6", "-2:2")])
def test_given_cav_gains_outside_the_bounds_are_refused_not_clipped(tmp_path, gains, bounds):
    out = tmp_path / "o"
    code, stdout, err = run("platoon", "simulate", "--from", _identify_json(tmp_path, [1, 2]),
                            "--cav-at", "2", "--cav-gains", gains, "--gain-bounds", bounds,
                            "--no-figures", "--out", str(out))
    assert code == 2 and stdout == "" and len(err.strip().splitlines()) == 1, err
    assert f"--cav-gains {gains}: expected gains within --gain-bounds {bounds}" in err, err
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.slow
def test_the_recorded_leader_replayed_in_sumo_matches_the_toolkit(tmp_path):
    """The replay's two simulators, SUMO and the toolkit's exact-ZOH one, agree (issue 27, item 4)."""
    pytest.importorskip("libsumo", reason="needs the optional extra 'sumo' (pip install 'stringstab[sumo]')")
    from stringstab.mixed.replay import replay

    log = ROOT / "stringstab" / "data" / "openacc" / "zalazone_acc_short_dynamic_part1.csv.gz"
    # the first two recorded followers, with the ACC log's identified parameters (rounded)
    vs = [{"platoon": 0, "position": p, "name": n, "predecessor": q, "k_x": kx, "k_v": kv,
           "k_a": 0.0, "tau": tau, "delta": 0.0, "headway": 0.0, "standstill": l0}
          for p, n, q, kx, kv, tau, l0 in ((1, "MERCEDES_GLE450", "SMART_TARGET", 0.125, 0.349, 0.76, 15.0),
                                           (2, "JAGUAR_I_PACE", "MERCEDES_GLE450", 0.15, 0.45, 0.6, 13.0))]
    path = write(tmp_path, json.dumps({"command": "identify", "vehicles": vs, "skipped": [],
                                       "sources": [str(log)]}), "identify.json")
    rec = read_vehicles(path)
    cav = (rec.vehicles[0], Vehicle(0.3, 1.0, 0.5, Params(0.1, 0.2, 1.1), "cav"))
    variants = [("cav", cav, list(rec.standstill))]
    toolkit = replay(rec, variants, simulator="toolkit")
    sumo = replay(rec, variants, simulator="sumo")
    assert toolkit.seconds > 500 and sumo.simulator == "sumo"
    for a, b in zip(toolkit.runs, sumo.runs):
        assert np.allclose(b.m_p, a.m_p, rtol=0.01)
        assert b.band_ratio == pytest.approx(a.band_ratio, rel=0.01)
        assert b.min_gap == pytest.approx(a.min_gap, abs=0.1)
        assert b.collisions == a.collisions == 0
    # the CAV changes the second follower's m_p: the comparison covers two different strings
    assert toolkit.runs[1].m_p[1] != pytest.approx(toolkit.runs[0].m_p[1], rel=0.05)
