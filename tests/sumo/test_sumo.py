"""stringstab.sumo: SUMO runs the toolkit's controllers exactly (skipped without the extra)."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("libsumo", reason="needs the optional extra 'sumo' (pip install 'stringstab[sumo]')")
pytest.importorskip("traci", reason="needs the optional extra 'sumo' (pip install 'stringstab[sumo]')")

from stringstab.cli import main
from stringstab.sumo import cosimulate
from stringstab.sumo.agreement import agreement
from stringstab.traffic import LinearController, leader_by_name, simulate, sinusoid


def test_toolkit_and_sumo_agree_on_a_udds_leader_with_stops():
    lead = leader_by_name("udds", dt=0.1, duration=140.0)  # moves at 20.1 s, stops at 124.9 s
    assert lead.speed[1300:].min() == 0.0 and lead.speed[300:1200].min() > 0.0
    res = agreement(lead, LinearController(1.2, 0.5, 0.6), 3)
    assert res["passed"]
    for k, v in res["differences"].items():
        assert v < 1e-9, k  # round-off: the same equations on both sides
    # the toolkit's default exact positions are measurably different (the option matters)
    assert res["differences_exact_positions"]["accel"] > 1e-5
    assert res["sumo_speed_override"] == 0.0
    co = cosimulate(lead, LinearController(1.2, 0.5, 0.6), 3)
    assert co.speed[1, -50:].max() == 0.0  # the first follower stopped too (clipped at 0)


def test_traci_equals_libsumo():
    lead = sinusoid(omega=0.5, amplitude=1.0, duration=15.0)
    c = LinearController(1.2, 0.5, 0.6)
    a = cosimulate(lead, c, 3, api="libsumo")
    b = cosimulate(lead, c, 3, api="traci")
    assert a.params["sumo_api"] == "libsumo" and b.params["sumo_api"] == "traci"
    np.testing.assert_array_equal(a.position, b.position)
    np.testing.assert_array_equal(a.speed, b.speed)
    np.testing.assert_array_equal(a.accel, b.accel)


def test_speed_mode_semantics():
    # a controller that drives into its leader (u = +3 m/s² throughout)
    from stringstab.traffic import FunctionController

    lead = sinusoid(omega=0.5, amplitude=0.1, duration=12.0)
    c = FunctionController(lambda obs: 3.0)
    # speed mode 0: SUMO executes the commanded speed exactly, into a collision the toolkit counts
    exact = cosimulate(lead, c, 2, speed_mode=0)
    assert exact.params["sumo_speed_override"] == 0.0
    assert exact.collided.any()
    # SUMO's default speed mode (31): its safe-speed rule silently overrides the controller
    safe = cosimulate(lead, c, 2, speed_mode=31)
    assert safe.params["sumo_speed_override"] > 0.1
    assert not safe.collided.any()


def test_check_command_passes_on_a_sine(capsys, tmp_path):
    out = tmp_path / "check.json"
    rc = main(["sumo", "check", "--leader", "sinusoid:omega=0.5,amplitude=1", "--duration", "20",
               "--followers", "3", "--json", str(out)])
    text = capsys.readouterr().out
    assert rc == 0, text
    assert "passed" in text and "accel" in text
    doc = json.loads(out.read_text())
    assert doc["passed"] and max(doc["differences"].values()) < 1e-3


def test_check_fails_above_the_tolerance(capsys):
    # a tolerance below round-off: the check must be able to fail (exit 1)
    rc = main(["sumo", "check", "--leader", "sinusoid:omega=0.5", "--duration", "10",
               "--followers", "2",
               "--tolerance", "1e-300"])
    assert rc == 1
    assert "FAILED" in capsys.readouterr().out


def test_cosimulate_matches_simulate_metrics():
    lead = leader_by_name("udds", dt=0.1, duration=30.0)
    c = LinearController(1.2, 0.5, 0.6)
    co = cosimulate(lead, c, 2)
    tk = simulate(lead, c, 2, position_update="trapezoid")
    m1, m2 = co.metrics(), tk.metrics()
    assert m1["m_fss"] == m2["m_fss"] == 1.0
    assert m1["max_m_p"] == pytest.approx(m2["max_m_p"], abs=1e-9)
    assert m1["TIT"] == pytest.approx(m2["TIT"], abs=1e-6)


def test_run_writes_what_simulate_writes(tmp_path, capsys):
    sim, sumo = tmp_path / "sim", tmp_path / "sumo"
    args = ["--leader", "udds", "--duration", "40", "--followers", "2"]
    assert main(["simulate", *args, "--out", str(sim)]) == 0
    assert main(["sumo", "run", *args, "--out", str(sumo)]) == 0
    capsys.readouterr()
    names = {p.name for p in sim.iterdir() if not p.name.startswith(".")}
    assert names == {p.name for p in sumo.iterdir() if not p.name.startswith(".")}
    a = json.loads((sim / "metrics.json").read_text())
    b = json.loads((sumo / "metrics.json").read_text())
    assert b["run"]["simulator"] == "sumo" and b["certificate"] == a["certificate"]
    # same controller and leader; the position rule differs (simulate's default is exact)
    assert b["max_m_p"] == pytest.approx(a["max_m_p"], abs=1e-3)
    assert b["m_fss"] == a["m_fss"] == 1.0


def test_run_with_a_gain_file(tmp_path, capsys):
    from pathlib import Path

    import stringstab

    f = Path(stringstab.__file__).parent / "data" / "examples" / "gain_rollout.csv"
    out = tmp_path / "run"
    rc = main(["sumo", "run", "--leader", "udds", "--duration", "30", "--followers", "2",
               "--gains-file", str(f), "--no-figures", "--format", "parquet", "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0, text
    assert "pyarrow" not in text  # libsumo's import-time version warning is kept out
    doc = json.loads((out / "metrics.json").read_text())
    assert doc["executed_gains"]["n"] == 2 * 301
    # pyarrow writes and reads Parquet in the process that loaded libsumo (its own libarrow)
    import pyarrow.parquet as pq

    assert pq.read_table(out / "trajectories.parquet").num_rows == 3 * 301


@pytest.mark.parametrize("kind", ["cacc", "idm", "mixed"])
def test_other_controllers_run_unchanged(kind):
    from stringstab.sumo.platoon import ballistic_leader
    from stringstab.traffic import CACCController, IDMController, MixedController

    ctrl = {"cacc": CACCController(), "idm": IDMController(),
            "mixed": MixedController([LinearController(1.2, 0.5, 0.6), IDMController()], [0, 1, 0])}[kind]
    lead = sinusoid(omega=0.5, amplitude=1.0, duration=15.0)
    co = cosimulate(lead, ctrl, 3)
    tk = simulate(ballistic_leader(lead)[0], ctrl, 3, position_update="trapezoid")
    assert np.abs(co.accel - tk.accel).max() < 1e-9
    assert np.abs(co.gap - tk.gap).max() < 1e-9
