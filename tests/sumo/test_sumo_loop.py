"""θ_r and the radio in SUMO (issues 25, 26): kept on the toolkit's side, like τ (skipped without SUMO).

The same case (θ_r, messages every 2 steps with loss and a fallback, sensor noise) through the
toolkit's simulator with SUMO's ballistic position rule and through SUMO agrees to round-off:
SUMO only moves the vehicles at the speeds the toolkit's platoon computes.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("libsumo", reason="needs the optional extra 'sumo' (pip install 'stringstab[sumo]')")

from stringstab.cli import main
from stringstab.sumo import cosimulate
from stringstab.sumo.agreement import differences
from stringstab.sumo.platoon import ballistic_leader
from stringstab.traffic import LinearController, Radio, SensorNoise, simulate, sinusoid


def test_sumo_runs_reaction_delay_radio_and_sensors_like_the_simulator():
    lead, _ = ballistic_leader(sinusoid(omega=1.0, amplitude=1.0, speed=20.0, duration=30.0, dt=0.1))
    c = LinearController(1.2, 0.5, 0.6)
    kw = {"reaction_delay": 0.15,
          "radio": Radio(message_period=0.2, loss=0.2, burst=2, stale_after=0.4, fallback_gains=(1.0, 0.8), seed=1),
          "sensors": SensorNoise(gap=0.2, speed=0.05, correlation_time=0.5, seed=1)}
    tk = simulate(lead, c, 3, position_update="trapezoid", **kw)
    su = cosimulate(lead, c, 3, **kw)
    d = differences(tk, su)
    assert max(d.values()) < 1e-9, d
    for k in tk.radio:
        np.testing.assert_array_equal(tk.radio[k], su.radio[k])
    assert su.radio["messages_lost"].sum() > 0 and su.radio["fallback_time"].sum() > 0
    for k in ("reaction_delay", "radio", "sensors"):
        assert su.params[k] == tk.params[k]
    # and θ_r is applied: without it the run differs
    plain = cosimulate(lead, c, 3, radio=kw["radio"], sensors=kw["sensors"])
    assert np.abs(plain.accel - su.accel).max() > 1e-3


def test_sumo_run_cli_takes_the_loop_options(tmp_path, capsys):
    out = tmp_path / "o"
    rc = main(["sumo", "run", "--leader", "sinusoid:omega=1,amplitude=1", "--duration", "10",
               "--followers", "2", "--reaction-delay", "0.1", "--message-period", "0.2",
               "--loss", "0.1", "--no-figures", "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0 and "radio: messages every 0.2 s" in text
    doc = json.loads((out / "metrics.json").read_text(encoding="utf-8"))
    assert doc["run"]["reaction_delay"] == 0.1 and doc["run"]["radio"]["message_period"] == 0.2
    assert doc["certificate"]["reaction_delay"] == 0.1


def test_sumo_run_refuses_the_loop_options_in_a_scenario(tmp_path, capsys):
    rc = main(["sumo", "run", "--sumocfg", str(tmp_path / "x.sumocfg"), "--controlled", "a",
               "--reaction-delay", "0.1", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1
    assert "--reaction-delay: simulated for a platoon behind a leader; expected none of them with --sumocfg" in err
