"""stringstab.sumo.routes: the vehicles a scenario's route files define and their depart times
(plain XML; SUMO is not needed).  That SUMO inserts them then is tested in
tests/sumo/test_sumo_run_status.py."""

from __future__ import annotations

import gzip
from pathlib import Path

import pytest

from stringstab.errors import StringStabError
from stringstab.sumo.routes import scheduled_departures

ROUTES = """<routes>
  <vehicle id="a" depart="5"/>
  <trip id="b" depart="0:01:30" from="x" to="y"/>
  <vehicle id="c" depart="triggered"/>
  <flow id="f" begin="10" end="100" period="20"/>
  <flow id="g" begin="0" end="100" vehsPerHour="720"/>
  <flow id="p" begin="30" end="100" probability="0.1"/>
  <flow id="n" begin="0" end="100" number="4"/>
  <flow id="d" end="100" period="exp(0.1)"/>
</routes>
"""


def _cfg(tmp: Path, routes: str, *, begin: str = "2", extra: str = "") -> Path:
    (tmp / "r.rou.xml").write_text(routes)
    cfg = tmp / "s.sumocfg"
    cfg.write_text(f'<configuration><input><route-files value="r.rou.xml"/>{extra}</input>'
                   f'<time><begin value="{begin}"/></time></configuration>')
    return cfg


def test_vehicles_trips_and_flows(tmp_path: Path) -> None:
    s = scheduled_departures(_cfg(tmp_path, ROUTES))
    assert s.complete and s.begin == 2.0 and [p.name for p in s.files] == ["r.rou.xml"]
    assert (s.depart("a"), s.depart("b"), s.depart("c")) == (5.0, 90.0, None)  # H:M:S; triggered
    assert s.depart("f.0") == 10.0 and s.depart("f.3") == 70.0  # begin + k period
    assert s.depart("g.2") == pytest.approx(10.0)  # 720 veh/h: every 5 s
    for random_or_sumos in ("p.1", "n.1", "d.0"):  # probability, number alone, exp(): unknown
        assert s.defines(random_or_sumos) and s.depart(random_or_sumos) is None
    assert s.flows["d"][0] == 2.0  # a flow without begin starts at the configuration's begin
    for unknown in ("z", "f", "f.x", "q.1"):
        assert not s.defines(unknown)


def test_additional_files_count_and_unreadable_files_leave_it_incomplete(tmp_path: Path) -> None:
    (tmp_path / "more.add.xml").write_text('<additional><vehicle id="m" depart="7"/></additional>')
    s = scheduled_departures(_cfg(tmp_path, ROUTES,
                                  extra='<additional-files value="more.add.xml"/>'))
    assert s.defines("m") and s.depart("m") == 7.0 and s.complete
    (tmp_path / "r.rou.xml.gz").write_bytes(gzip.compress(ROUTES.encode()))
    cfg = tmp_path / "gz.sumocfg"
    cfg.write_text('<configuration><input><route-files value="r.rou.xml.gz"/></input>'
                   '</configuration>')
    s = scheduled_departures(cfg)
    assert not s.complete and not s.defines("a")  # not read here: the run checks the ids
    bad = tmp_path / "bad.sumocfg"
    bad.write_text("<configuration>")
    with pytest.raises(StringStabError, match="expected a SUMO configuration"):
        scheduled_departures(bad)
