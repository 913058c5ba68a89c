"""In-scenario mode: controlled vehicles follow whatever SUMO says leads them (skipped without
the sumo extra)."""

from __future__ import annotations

import csv
import json
import os
import re

import numpy as np
import pytest

pytest.importorskip("libsumo", reason="needs the optional extra 'sumo' (pip install 'stringstab[sumo]')")

from stringstab.cli import main
from stringstab.sumo import runtime
from stringstab.sumo.inscenario import run_scenario
from stringstab.traffic import LinearController

SCENARIO = os.path.join(os.path.dirname(runtime.__file__), "..", "data", "sumo", "onramp",
                        "onramp.sumocfg")


def test_leader_change_outside_a_platoon():
    # c1 follows 'exiting' until it takes the off-ramp (t ~ 84 s), then 'front'
    r = run_scenario(SCENARIO, ["c1", "c2"], LinearController(1.2, 0.5, 0.6), dt=0.1, steps=950)
    c1, c2 = r.summary["vehicles"]
    assert c1["leaders"] == ["exiting", "front"] and c1["leader_changes"] == 1
    assert c2["leaders"] == ["acc1"]  # SUMO's ACC vehicle
    assert r.summary["collisions"] == 0 and r.summary["m_fss"] == 1.0
    cols = r.columns
    m = (cols["vehicle"] == 0) & (cols["controlled"] == 1)
    lead = cols["leader"][m]
    k = int(np.argmax(lead == "front"))
    assert 80.0 < cols["t"][m][k] < 90.0
    # the gap jumps to the new leader's (it is further ahead) and stays bumper to bumper
    assert cols["gap"][m][k] > cols["gap"][m][k - 1] + 5.0
    # the controlled vehicle's speed is exactly what the lag model commanded (speed mode 0):
    # consecutive speeds differ by the exact-ZOH lag's speed change
    tau, dt = 0.1, 0.1
    e = np.exp(-dt / tau)
    v, a, u = cols["speed"][m], cols["accel"][m], cols["command"][m]
    t = cols["t"][m]
    nxt = np.flatnonzero(np.isclose(np.diff(t), dt))  # consecutive driven steps
    pred = v[nxt] + u[nxt] * dt + (a[nxt] - u[nxt]) * tau * (1 - e)
    pred = np.clip(pred, 0.0, 33.3)
    assert np.abs(v[nxt + 1] - pred).max() < 1e-9


def test_scenario_cli_writes_its_files(tmp_path, capsys):
    out = tmp_path / "scen"
    rc = main(["sumo", "run", "--sumocfg", SCENARIO, "--controlled", "c1", "--steps", "300",
               "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0, text
    doc = json.loads((out / "metrics.json").read_text())
    assert doc["run"]["controlled"] == ["c1"] and doc["vehicles"][0]["leaders"] == ["exiting"]
    with open(out / "scenario.csv") as f:
        rows = list(csv.DictReader(f))
    assert rows and {r["vehicle"] for r in rows} == {"c1"} and rows[0]["leader"] == "exiting"
    names = {p.name for p in out.iterdir() if not p.name.startswith(".")}
    assert names == {"scenario.csv", "metrics.json", "report.md", "report.html"}
    md = (out / "report.md").read_text(encoding="utf-8")
    steps = doc["vehicles"][0]["steps_controlled"]
    assert f"| c1 | {steps} | exiting | 0 |" in md.split("## Driven vehicles")[1]
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "<img" not in html and not re.search(r'(?:src|href)="https?://', html)  # no figures here


def test_scenario_traci_equals_libsumo():
    c = LinearController(1.2, 0.5, 0.6)
    a = run_scenario(SCENARIO, ["c1", "c2"], c, dt=0.1, steps=300, api="libsumo")
    b = run_scenario(SCENARIO, ["c1", "c2"], c, dt=0.1, steps=300, api="traci")
    for key in ("t", "gap", "speed", "accel", "command"):
        np.testing.assert_array_equal(a.columns[key], b.columns[key])
    assert list(a.columns["leader"]) == list(b.columns["leader"])
