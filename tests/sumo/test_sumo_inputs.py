"""stringstab sumo: bad input, a SUMO failure mid-run, Ctrl-C (one line, exit 2, nothing
written; SUMO stopped).  Skipped without the sumo extra."""

from __future__ import annotations

import os
import signal

import pytest

pytest.importorskip("libsumo", reason="needs the optional extra 'sumo' (pip install 'stringstab[sumo]')")

from stringstab.cli import main
from stringstab.errors import StringStabError
from stringstab.sumo import runtime
from stringstab.sumo.runtime import SumoSession

SCENARIO = os.path.join(os.path.dirname(runtime.__file__), "..", "data", "sumo", "onramp",
                        "onramp.sumocfg")


def _bad(argv, match, capsys, out=None):
    rc = main(argv)
    err = capsys.readouterr().err
    assert rc == 2, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and match in lines[0], err
    if out is not None:
        assert not out.exists()


def _break_after(monkeypatch, n, action):
    orig = SumoSession.step
    count = {"n": 0}
    sessions = []

    def step(self):
        sessions.append(self)
        count["n"] += 1
        if count["n"] == n:
            action(self)
        return orig(self)

    monkeypatch.setattr(SumoSession, "step", step)
    return sessions


def test_sumo_killed_mid_run_one_line_exit_2_nothing_written(monkeypatch, capsys, tmp_path):
    out = tmp_path / "run"
    sessions = _break_after(monkeypatch, 30, lambda s: os.kill(s.proc.pid, signal.SIGKILL))
    _bad(["sumo", "run", "--leader", "udds", "--duration", "20", "--followers", "2",
          "--api", "traci", "--out", str(out)], "SUMO stopped", capsys, out)
    assert sessions and sessions[-1].proc.poll() is not None  # no SUMO left behind


def test_vehicle_removed_mid_run(monkeypatch, capsys, tmp_path):
    out = tmp_path / "run"
    _break_after(monkeypatch, 25, lambda s: s.vehicle.remove("F2"))
    _bad(["sumo", "run", "--leader", "udds", "--duration", "20", "--followers", "3",
          "--out", str(out)], "'F2'", capsys, out)
    # libsumo was closed: another simulation starts in this process
    assert main(["sumo", "check", "--leader", "udds", "--duration", "10", "--followers", "1"]) == 0


def test_ctrl_c_stops_sumo_and_writes_nothing(monkeypatch, capsys, tmp_path):
    out = tmp_path / "run"

    def interrupt(s):
        raise KeyboardInterrupt

    sessions = _break_after(monkeypatch, 10, interrupt)
    rc = main(["sumo", "run", "--leader", "udds", "--duration", "20", "--followers", "2",
               "--api", "traci", "--out", str(out)])
    assert rc == 130
    assert "interrupted" in capsys.readouterr().err
    assert not out.exists()
    assert sessions[-1].proc.poll() is not None


def test_missing_vehicle_ids(capsys, tmp_path):
    out = tmp_path / "run"
    _bad(["sumo", "run", "--sumocfg", SCENARIO, "--controlled", "c1,nobody", "--steps", "200",
          "--out", str(out)], "no vehicle 'nobody' in the route files of onramp.sumocfg", capsys,
         out)
    # route files SUMO reads but stringstab does not (gzip): the ids are checked at the end
    import gzip
    import shutil

    scen = tmp_path / "scen"
    shutil.copytree(os.path.dirname(SCENARIO), scen)
    routes = scen / "onramp.rou.xml"
    (scen / "onramp.rou.xml.gz").write_bytes(gzip.compress(routes.read_bytes()))
    routes.unlink()
    cfg = scen / "onramp.sumocfg"
    cfg.write_text(cfg.read_text().replace("onramp.rou.xml", "onramp.rou.xml.gz"))
    _bad(["sumo", "run", "--sumocfg", str(cfg), "--controlled", "c1,nobody", "--steps", "200",
          "--out", str(out)], "nobody never appeared", capsys, out)


def test_step_mismatch_and_euler_are_refused(capsys, tmp_path):
    out = tmp_path / "run"
    _bad(["sumo", "run", "--sumocfg", SCENARIO, "--controlled", "c1", "--dt", "0.05",
          "--tau", "0.1", "--out", str(out)], "step-length is 0.1 s but the controller's step is 0.05 s",
         capsys, out)
    euler = tmp_path / "euler.sumocfg"
    text = open(SCENARIO).read().replace('<step-method.ballistic value="true"/>', "")
    scen_dir = os.path.dirname(os.path.abspath(SCENARIO))
    euler.write_text(text.replace('value="onramp.', f'value="{scen_dir}/onramp.'))
    _bad(["sumo", "run", "--sumocfg", str(euler), "--controlled", "c1", "--out", str(out)],
         "Euler position update", capsys, out)
    # a running SUMO is asked too: a session whose step differs from the leader's is refused
    from stringstab.sumo import SumoPlatoon
    from stringstab.sumo.scenario import straight_road
    from stringstab.traffic import leader_by_name

    road = straight_road(tmp_path, distance=100.0, gaps=[2.0], speeds=[0.0], leader_speed=0.0,
                         length=5.0)
    with SumoSession(road.sumo_args(), dt=0.1) as s:
        s.step()
        with pytest.raises(StringStabError, match=r"leader's step is 0\.05 s but SUMO runs with 0\.1 s"):
            SumoPlatoon(s, leader_by_name("udds", dt=0.05, duration=5.0), ["F1"])


def test_other_bad_input(capsys, tmp_path):
    out = tmp_path / "run"
    _bad(["sumo", "run", "--sumocfg", SCENARIO, "--out", str(out)],
         "--sumocfg and --controlled go together", capsys, out)
    _bad(["sumo", "run", "--leader", "udds", "--gains", "1,2", "--out", str(out)],
         "--gains must be three finite numbers", capsys, out)
    _bad(["sumo", "check", "--leader", "udds", "--dt", "0.5"], "--dt 0.5 s is longer", capsys)
    _bad(["sumo", "run", "--sumocfg", str(tmp_path / "none.sumocfg"), "--controlled", "c1",
          "--out", str(out)], "does not exist", capsys, out)


def test_libsumo_one_simulation_per_process(tmp_path):
    from stringstab.sumo.scenario import straight_road

    road = straight_road(tmp_path, distance=100.0, gaps=[2.0], speeds=[0.0], leader_speed=0.0,
                         length=5.0)
    with SumoSession(road.sumo_args(), dt=0.1):
        with pytest.raises(StringStabError, match="one simulation per process"):
            SumoSession(road.sumo_args(), dt=0.1)
    with SumoSession(road.sumo_args(), dt=0.1) as s:  # closed: the next one starts
        s.step()


def test_missing_extra_is_one_line(monkeypatch):
    import builtins

    real = builtins.__import__

    def fake(name, *a, **k):
        if name in ("libsumo", "traci"):
            raise ImportError(f"No module named {name!r}")
        return real(name, *a, **k)

    monkeypatch.setattr(builtins, "__import__", fake)
    with pytest.raises(StringStabError, match=r"optional extra 'sumo'.*pip install 'stringstab\[sumo\]'"):
        runtime.import_api("libsumo")
