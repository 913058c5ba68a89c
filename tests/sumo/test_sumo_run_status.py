"""stringstab sumo run: exit codes as simulate's, simulate's limit flags, scenario ids checked
when due, and M_effi from the one metrics function (skipped without the sumo extra)."""

from __future__ import annotations

import argparse
import csv
import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("libsumo", reason="needs the optional extra 'sumo' (pip install 'stringstab[sumo]')")

from stringstab.cli import build_parser, main
from stringstab.sumo import cosimulate, runtime
from stringstab.sumo.runtime import SumoSession
from stringstab.traffic import LinearController, leader_by_name, simulate

SCENARIO = os.path.join(os.path.dirname(runtime.__file__), "..", "data", "sumo", "onramp",
                        "onramp.sumocfg")
#: Gains that are not string stable: behind 50 s of UDDS, 3 followers collide (IDL eq 4).
UNSTABLE = "0.05,0.1,0"


def _err_lines(capsys: pytest.CaptureFixture[str]) -> list[str]:
    return [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]


def test_collisions_exit_1_like_simulate(tmp_path, capsys):
    # 60 s: at least these gains' settling time (51.4 s), which the leader check asks for
    args = ["--leader", "udds", "--duration", "60", "--followers", "3", "--gains", UNSTABLE,
            "--no-figures"]
    assert main(["simulate", *args, "--out", str(tmp_path / "sim")]) == 1
    sim_err = _err_lines(capsys)
    assert main(["sumo", "run", *args, "--out", str(tmp_path / "sumo")]) == 1
    sumo_err = _err_lines(capsys)
    a = json.loads((tmp_path / "sim" / "metrics.json").read_text())
    b = json.loads((tmp_path / "sumo" / "metrics.json").read_text())
    assert a["collisions"] == b["collisions"] == 3  # written, and counted alike
    assert sim_err == [ln.replace("stringstab sumo run:", "stringstab simulate:") for ln in sumo_err]
    assert sumo_err == ["stringstab sumo run: warning: 3 collision(s): follower 1 first reached "
                        "its predecessor at t = 42.1 s (m_fss = 0.000); exit status 1"]


def _limit_actions(parser: argparse.ArgumentParser) -> list[tuple[object, ...]]:
    return [(a.option_strings, a.default, a.help, a.metavar) for a in parser._actions
            if a.dest in ("v_max", "a_min", "a_max")]


def test_limit_flags_are_simulates(tmp_path, capsys):
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    sim = sub.choices["simulate"]
    sumo_sub = next(a for a in sub.choices["sumo"]._actions
                    if isinstance(a, argparse._SubParsersAction))
    assert len(_limit_actions(sim)) == 3
    for name in ("run", "check"):
        assert _limit_actions(sumo_sub.choices[name]) == _limit_actions(sim)
    # the default limits' leader warning names --v-max ("unrecognized" in sumo run before);
    # now it runs, and SUMO's followers stay within the limits given
    out = tmp_path / "run"
    rc = main(["sumo", "run", "--leader", "udds", "--duration", "200", "--followers", "2",
               "--v-max", "15", "--a-min", "-2", "--a-max", "1.2", "--format", "csv",
               "--no-figures", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert "above the followers' speed limit v_max = 15 m/s" in err
    assert "beyond the followers' limit acc_max = 1.2 m/s²" in err
    doc = json.loads((out / "metrics.json").read_text())
    assert doc["run"]["limits"] == {"accel_min": -2.0, "accel_max": 1.2, "speed_min": 0.0,
                                    "speed_max": 15.0}
    with open(out / "trajectories.csv") as f:
        rows = [r for r in csv.DictReader(f) if r["vehicle"] != "0"]
    v = np.array([float(r["speed"]) for r in rows])
    a = np.array([float(r["accel"]) for r in rows])
    assert v.max() <= 15.0 + 1e-6 and v.max() > 14.9  # saturated at the limit, in SUMO
    assert a.min() >= -2.0 - 1e-6 and a.max() <= 1.2 + 1e-6
    # sumo check takes them too; toolkit and SUMO agree with the limits active
    assert main(["sumo", "check", "--leader", "udds", "--duration", "200", "--followers", "2",
                 "--v-max", "15"]) == 0


def test_m_effi_is_the_metrics_function_on_the_same_run(tmp_path, capsys):
    """sumo run's M_effi equals simulate's on the same run; the default simulate is another run.

    M_effi (eq 35) averages h = gap / v over v > 0.001 m/s, so near a stop a speed that differs
    in the 6th decimal moves a sample with h ~ 1000 s in or out of the mean: SUMO's ballistic
    position rule and simulate's default exact one then give visibly different M_effi.
    """
    lead = leader_by_name("udds", dt=0.1, duration=140.0)  # stops at 124.9 s
    c = LinearController(1.2, 0.5, 0.6)

    def by_hand(r) -> float:  # eq 35 from the positions and speeds, independently of the code
        gap = r.position[:-1] - r.position[1:] - r.length
        v = r.speed[1:]
        return float(np.mean(gap[v > 0.001] / v[v > 0.001]))

    sumo = cosimulate(lead, c, 3)
    same = simulate(lead, c, 3, position_update="trapezoid")  # SUMO's position rule
    exact = simulate(lead, c, 3)  # simulate's default
    out = tmp_path / "run"
    assert main(["sumo", "run", "--leader", "udds", "--duration", "140", "--followers", "3",
                 "--no-figures", "--out", str(out)]) == 0
    capsys.readouterr()
    cli = json.loads((out / "metrics.json").read_text())["M_effi"]
    np.testing.assert_allclose(cli, by_hand(sumo), rtol=1e-12)
    np.testing.assert_allclose(same.metrics()["M_effi"], by_hand(sumo), rtol=1e-10)
    np.testing.assert_allclose(exact.metrics()["M_effi"], by_hand(exact), rtol=1e-12)
    assert abs(exact.metrics()["M_effi"] - cli) > 0.1  # 9.257 s vs 9.415 s: the position rule


def test_vehicle_that_never_had_a_leader_exits_1(tmp_path, capsys):
    out = tmp_path / "run"
    rc = main(["sumo", "run", "--sumocfg", SCENARIO, "--controlled", "front,c1", "--steps", "300",
               "--out", str(out)])
    err = _err_lines(capsys)
    assert rc == 1
    assert err == ["stringstab sumo run: warning: vehicle 'front' never had a leader within 250 m "
                   "in its 300 steps, so SUMO's own model drove it throughout and the controller "
                   "was never exercised; exit status 1"]
    doc = json.loads((out / "metrics.json").read_text())
    assert doc["without_leader"] == ["front"]
    assert [v["steps_controlled"] > 0 for v in doc["vehicles"]] == [False, True]


def test_scenario_summary_is_eq_29_of_its_rows(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["sumo", "run", "--sumocfg", SCENARIO, "--controlled", "c1,c2", "--steps", "950",
                 "--out", str(out)]) == 0
    capsys.readouterr()
    doc = json.loads((out / "metrics.json").read_text())
    with open(out / "scenario.csv") as f:
        rows = list(csv.DictReader(f))
    for v in doc["vehicles"]:
        mine = [r for r in rows if r["vehicle"] == v["vehicle"] and r["controlled"] == "1"]
        a = np.array([float(r["accel"]) for r in mine])
        ap = np.array([float(r["pred_accel"]) for r in mine])
        assert np.sum(ap**2) > 0  # the leaders accelerate: m_p is defined
        np.testing.assert_allclose(v["m_p"], np.sqrt(np.sum(a**2) / np.sum(ap**2)), rtol=1e-5)
        assert v["collisions"] == 0 and min(float(r["gap"]) for r in mine) > 0


def _no_sumo(monkeypatch):
    def refuse(*a, **k):
        raise AssertionError("SUMO was started")

    monkeypatch.setattr("stringstab.sumo.inscenario.SumoSession", refuse)


def test_unknown_id_is_refused_before_sumo_starts(tmp_path, capsys, monkeypatch):
    _no_sumo(monkeypatch)
    out = tmp_path / "run"
    assert main(["sumo", "run", "--sumocfg", SCENARIO, "--controlled", "c1,nobody",
                 "--out", str(out)]) == 2
    assert _err_lines(capsys) == [
        "stringstab sumo: error: --controlled: no vehicle 'nobody' in the route files of "
        "onramp.sumocfg (onramp.rou.xml); expected ids of vehicles the scenario inserts, e.g. "
        "front, exiting, c1, acc1, c2, h1, ramp.N"]
    assert not out.exists()
    # a flow's vehicle is an id of the scenario; one departing after --steps is refused
    assert main(["sumo", "run", "--sumocfg", SCENARIO, "--controlled", "ramp.2", "--steps", "100",
                 "--out", str(out)]) == 2
    assert "vehicle 'ramp.2' departs at t = 44 s, after the run's end (--steps ends it at " \
           "t = 10 s)" in _err_lines(capsys)[0]


def test_id_due_but_not_inserted_stops_the_run_at_once(tmp_path, capsys, monkeypatch):
    # 'exiting' departs at 3 s, before this configuration's begin (4 s): SUMO never inserts it
    scen = tmp_path / "scen"
    shutil.copytree(Path(SCENARIO).parent, scen)
    cfg = scen / "onramp.sumocfg"
    cfg.write_text(cfg.read_text().replace('<begin value="0"/>', '<begin value="4"/>'))
    steps = []
    orig = SumoSession.step
    monkeypatch.setattr(SumoSession, "step", lambda self: (steps.append(1), orig(self))[1])
    out = tmp_path / "run"
    assert main(["sumo", "run", "--sumocfg", str(cfg), "--controlled", "c1,exiting",
                 "--out", str(out)]) == 2
    err = _err_lines(capsys)
    assert err == ["stringstab sumo: error: --controlled: vehicle 'exiting' of onramp.sumocfg was "
                   "due to depart at t = 3 s and at t = 4.1 s SUMO neither drives it nor waits to "
                   "insert it (it departs before the configuration's begin, t = 4 s, and SUMO "
                   "skips it); expected a vehicle the scenario inserts"]
    assert len(steps) == 1 and not out.exists()  # stopped at the first step, not the run's end


def test_schedule_is_when_sumo_inserts_the_vehicles():
    from stringstab.sumo.routes import scheduled_departures

    sched = scheduled_departures(SCENARIO)
    departed = {}
    with SumoSession(["-c", SCENARIO], dt=0.1, scenario=True) as s:
        for _ in range(700):
            s.step()
            for vid in s.simulation.getDepartedIDList():
                departed[vid] = float(s.simulation.getTime())
    assert len(departed) == 11 and {"ramp.0", "ramp.4"} <= departed.keys()
    for vid, t in departed.items():  # inserted in the step that starts at its depart time
        assert sched.depart(vid) == pytest.approx(t - 0.1, abs=1e-9), vid
