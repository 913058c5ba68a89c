"""A trained IDL policy drives SUMO vehicles; every executed gain certified (skipped without
the sumo extra or torch)."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("libsumo", reason="needs the optional extra 'sumo' (pip install 'stringstab[sumo]')")
pytest.importorskip("torch", reason="needs the optional extra 'rl' (torch) to train a policy")

from stringstab.cli import main


@pytest.fixture(scope="module")
def policy_run(tmp_path_factory):
    run = tmp_path_factory.mktemp("idl") / "run"
    assert main(["train", "--algo", "idl", "--steps", "32", "--seed", "1", "--num-envs", "2",
                 "--out", str(run), "--no-progress"]) == 0
    return run


def test_policy_drives_sumo_with_every_gain_certified(policy_run, tmp_path, capsys):
    out = tmp_path / "sumo-run"
    rc = main(["sumo", "run", "--leader", "udds", "--duration", "12", "--followers", "2",
               "--policy", str(policy_run), "--out", str(out), "--no-figures"])
    text = capsys.readouterr().out
    assert rc == 0, text
    doc = json.loads((out / "metrics.json").read_text())
    assert doc["run"]["simulator"] == "sumo" and doc["run"]["policy"] == str(policy_run)
    g = doc["executed_gains"]
    assert g["n"] == 2 * 121 and g["m_fss"] == 1.0
    assert doc["m_fss"] == 1.0
    assert "m_fss = 1 certified" in text
    traj = np.load(out / "trajectories.npz")
    assert traj["t"].size == 121


def test_policy_metrics_equal_the_toolkit_simulators(policy_run):
    from stringstab.rl.evaluate import controller_for, fss
    from stringstab.rl.runs import open_run
    from stringstab.sumo import cosimulate
    from stringstab.sumo.platoon import ballistic_leader
    from stringstab.traffic import simulate, sinusoid

    _, pol = open_run(policy_run)
    p = pol.info
    lead = sinusoid(omega=0.5, amplitude=1.0, duration=12.0, dt=p["dt"])
    co = cosimulate(lead, controller_for(pol, headway=p["headway"]), 2, tau=p["tau"], delta=p["delta"])
    tk = simulate(ballistic_leader(lead)[0], controller_for(pol, headway=p["headway"]), 2, tau=p["tau"], delta=p["delta"],
                  position_update="trapezoid")
    np.testing.assert_allclose(co.gains, tk.gains, atol=1e-9)
    m1, m2 = co.metrics(), tk.metrics()
    for k in ("max_m_p", "M_lss", "TIT", "M_CI", "M_effi", "m_fss", "collisions"):
        assert m1[k] == pytest.approx(m2[k], abs=1e-6), k
    f = fss(co.gains, tau=p["tau"], delta=p["delta"], headway=p["headway"], dt=p["dt"])
    assert f["m_fss"] == 1.0
