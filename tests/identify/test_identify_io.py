"""Readers of recorded platoons (stringstab.io.platoon_logs): the OpenACC logs shipped in
stringstab/data/openacc, OpenACC/CSV/NGSIM files written here from the toolkit's simulator, unit
checks and malformed files."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from stringstab.errors import StringStabError
from stringstab.identify.logs import example_log
from stringstab.io.platoon_logs import clean_segments, read_platoon_logs
from stringstab.traffic import LinearController, from_speed, simulate

#: The OpenACC logs shipped with the package (stringstab/data/openacc/README.md)
ACC = example_log("acc")
HUMAN = example_log("human")


def test_shipped_acc_file() -> None:
    [log] = read_platoon_logs(ACC)
    assert log.fmt == "openacc" and log.meta["ACC"] == ["1"] and log.meta["Number_of_vehicles"] == ["6"]
    assert log.names == ("SMART_TARGET", "MERCEDES_GLE450", "JAGUAR_I_PACE", "BMW_I3",
                         "TESLA_MODELX", "TESLA_MODEL3")
    assert log.positions == (0, 1, 2, 3, 4, 5) and log.followers() == [1, 2, 3, 4, 5]
    assert log.dt == pytest.approx(0.1) and log.t.size == 5497  # every row of the original
    # no E/N columns are shipped, so no unit cross-check here: it was made on the originals
    # (analysis/openacc_excerpt.py prints the ratios, README); the speeds are m/s ...
    assert log.meta["speed_position_ratio"] == []
    # ... as the spacing says: d IVS/dt = v_pred - v within GPS noise (a ratio of 1, not 1/3.6)
    vp, v, g, _ = log.pair(1)
    dv = 0.5 * ((vp - v)[1:] + (vp - v)[:-1])
    ok = np.isfinite(dv) & np.isfinite(np.diff(g))
    slope = float(dv[ok] @ (np.diff(g)[ok] / 0.1)) / float(dv[ok] @ dv[ok])
    assert 0.8 < slope < 1.2
    # Speed3 and IVS2/IVS3 are empty in the first two rows: vehicles 2 and 3 start at sample 2
    assert [(s.start, s.stop) for s in clean_segments(log, 2)] == [(2, log.t.size)]
    assert np.isnan(log.speed[2, :2]).all()


def test_shipped_human_file_has_holes() -> None:
    """Vehicles 1 and 9 of the Vehicle_order have no columns: vehicle 2 leads what is recorded
    and vehicle 10 has no predecessor record; dropouts split the others."""
    [log] = read_platoon_logs(HUMAN)
    assert log.positions == (1, 2, 3, 4, 5, 6, 7, 9, 10)
    assert log.names[0] == "TESLA_MODELX" and log.name(10) == "AUDI_A4"
    assert log.followers() == [2, 3, 4, 5, 6, 7, 10]
    segs = clean_segments(log, 4)
    assert len(segs) == 2 and segs[0].stop < segs[1].start  # split at the dropout, not bridged
    vp, v, g, _ = log.pair(4)
    gap_between = slice(segs[0].stop, segs[1].start)
    assert not (np.isfinite(vp[gap_between]) & np.isfinite(v[gap_between]) & np.isfinite(g[gap_between])).all()


def _platoon(duration: float = 120.0):
    t = np.arange(0.0, duration + 0.05, 0.1)
    lead = from_speed(t, 14 + 3 * np.sin(2 * np.pi * t / 60) + np.sin(0.6 * t), dt=0.1)
    c = LinearController(0.2, 0.6, 0.0, headway=1.2, standstill=3.0)
    return simulate(lead, c, 3, tau=0.4, delta=0.0)


def _openacc(path: Path, r, *, speed_scale: float = 1.0, drop_vehicle: int | None = None,
             holes: bool = True) -> Path:
    """An OpenACC-format file from a simulated platoon (E along the road, N = 0)."""
    n = r.speed.shape[0]
    names = [f"CAR_{k}" for k in range(1, n + 1)]
    ks = [k for k in range(1, n + 1) if k != drop_vehicle]
    head = ["Time"]
    for k in ks:
        head += [f"Speed{k}", f"E{k}", f"N{k}", f"Lon{k}", f"Lat{k}", f"Alt{k}"]
    head += [f"IVS{k}" for k in ks if k + 1 in ks]
    lines = ["Date,8,10,2019", "Vehicle_order," + ",".join(names) + ",UNUSED,", f"Number_of_vehicles,{n}",
             "ACC,1", "Distance_setting,S", ",".join(head)]
    for j, t in enumerate(r.t):
        row = [f"{t + 3.0:.1f}"]
        for k in ks:
            sp = r.speed[k - 1, j] * speed_scale
            cell = "" if holes and k == 2 and 300 <= j < 305 else f"{sp:.6f}"
            row += [cell, f"{r.position[k - 1, j]:.4f}", "0.0", "16.8", "46.9", "244.1"]
        row += [f"{r.gap[k - 1, j]:.4f}" for k in ks if k + 1 in ks]
        lines.append(",".join(row))
    path.write_text("\n".join(lines) + "\n")
    return path


def test_openacc_written_from_the_simulator(tmp_path: Path) -> None:
    r = _platoon()
    [log] = read_platoon_logs(_openacc(tmp_path / "a.csv", r))
    assert log.positions == (0, 1, 2, 3) and log.followers() == [1, 2, 3]
    assert np.allclose(log.speed[1, :300], r.speed[1, :300], atol=1e-6)
    assert np.allclose(log.gap[2], r.gap[1], atol=1e-4)
    # the empty Speed2 cells split the records of vehicles 2 (position 1) and 3 (its follower)
    assert [(s.start, s.stop) for s in clean_segments(log, 1)] == [(0, 300), (305, r.t.size)]
    assert [(s.start, s.stop) for s in clean_segments(log, 2)] == [(0, 300), (305, r.t.size)]
    assert [(s.start, s.stop) for s in clean_segments(log, 3)] == [(0, r.t.size)]


def test_openacc_missing_vehicle(tmp_path: Path) -> None:
    r = _platoon()
    [log] = read_platoon_logs(_openacc(tmp_path / "a.csv", r, drop_vehicle=2))
    assert log.positions == (0, 2, 3) and log.followers() == [3]


def test_openacc_kmh_refused(tmp_path: Path) -> None:
    r = _platoon()
    with pytest.raises(StringStabError, match="km/h"):
        read_platoon_logs(_openacc(tmp_path / "a.csv", r, speed_scale=3.6, holes=False))


def _plain(path: Path, header: str, cols: list[np.ndarray]) -> Path:
    rows = [header] + [",".join("" if not math.isfinite(x) else f"{x:.6f}" for x in row)
                       for row in np.column_stack(cols)]
    path.write_text("\n".join(rows) + "\n")
    return path


def test_plain_csv_forms(tmp_path: Path) -> None:
    r = _platoon()
    t = r.t
    one = _plain(tmp_path / "one.csv", "t,v_lead,v,gap", [t, r.speed[0], r.speed[1], r.gap[0]])
    [log] = read_platoon_logs(one)
    assert log.names == ("lead", "follower") and log.followers() == [1]
    wide = _plain(tmp_path / "wide.csv", "t,v0,v1,gap1,v2,gap2",
                  [t, r.speed[0], r.speed[1], r.gap[0], r.speed[2], r.gap[1]])
    [log] = read_platoon_logs(wide)
    assert log.followers() == [1, 2] and np.allclose(log.gap[2], r.gap[1], atol=1e-5)
    kmh = _plain(tmp_path / "kmh.csv", "t,v_lead [km/h],v [km/h],gap [m]",
                 [t, 3.6 * r.speed[0], 3.6 * r.speed[1], r.gap[0]])
    [log] = read_platoon_logs(kmh)
    assert np.allclose(log.speed[1], r.speed[1], atol=1e-5)  # recognised and converted
    long = tmp_path / "long.csv"
    lines = ["vehicle,t,v,gap"]
    for k, nm in enumerate(("lead", "A", "B")):
        for j in range(t.size):
            lines.append(f"{nm},{t[j]:.1f},{r.speed[k, j]:.6f},{'' if k == 0 else f'{r.gap[k - 1, j]:.6f}'}")
    long.write_text("\n".join(lines) + "\n")
    [log] = read_platoon_logs(long)
    assert log.names == ("lead", "A", "B") and log.followers() == [1, 2]


def test_ngsim_pairs(tmp_path: Path) -> None:
    head = "Vehicle_ID,Frame_ID,Local_Y,v_Vel,v_Acc,Preceding,v_Length\n"
    rows = []
    for f in range(100, 500):
        t = (f - 100) * 0.1
        v = 40.0 + 5.0 * math.sin(0.5 * t)
        y = 40.0 * t - 10.0 * (math.cos(0.5 * t) - 1)
        a = 2.5 * math.cos(0.5 * t)
        rows.append(f"1,{f},{y + 80.0:.4f},{v:.4f},{a:.4f},0,15\n")
        rows.append(f"2,{f},{y:.4f},{v:.4f},{a:.4f},1,15\n")
    p = tmp_path / "ngsim.csv"
    p.write_text(head + "".join(rows))
    with pytest.raises(StringStabError, match="is an NGSIM file; read it with"):
        read_platoon_logs(p)  # the bottom I/O layer does not import the simulator's parser
    from stringstab.identify import read_logs

    [log] = read_logs(p)
    assert log.fmt == "ngsim" and log.names == ("ngsim-1", "ngsim-2")
    assert np.allclose(log.gap[1], (80.0 - 15.0) * 0.3048, atol=1e-3)  # 65 ft bumper to bumper
    assert log.accel is not None


@pytest.mark.parametrize(("header", "mutate", "message"), [
    ("t,v_lead,v,gap", lambda c: c[0].__setitem__(5, c[0][4]), "time must increase strictly"),
    ("t,v_lead,v,gap", lambda c: c[2].__setitem__(slice(None), np.nan), "empty or NaN in every row"),
    ("t,v_lead,v,gap", lambda c: c[3].__setitem__(slice(None), np.nan), "gap of 'follower' is empty"),
    ("t,v_lead,v,gap", lambda c: c[2].__setitem__(7, -3.0), "must be >= 0 m/s"),
    ("t,v_lead,v,gap", lambda c: c[1].__setitem__(7, 300.0), "absurd"),
    ("t,v_lead,v,gap", lambda c: [c[1].__imul__(3.6), c[2].__imul__(3.6)], "km/h"),
    ("t,v_lead,v", lambda c: c.pop(), "missing \\['gap'\\]"),
    ("t,v0", lambda c: del_all_but_two(c), "expected speed columns"),
    ("t,v_lead,v,headway", lambda c: None, "expected columns"),
    ("t,v_lead,v,gap [ft]", lambda c: None, "is in 'ft'"),
    ("t,v_lead,v,gap", lambda c: c[0].__setitem__(slice(50, None), c[0][50:] + 0.05), "regular time step"),
])
def test_malformed_csv(tmp_path: Path, header: str, mutate, message: str) -> None:
    r = _platoon(60.0)
    cols = [r.t.copy(), r.speed[0].copy(), r.speed[1].copy(), r.gap[0].copy()]
    mutate(cols)
    p = _plain(tmp_path / "bad.csv", header, cols[:len(header.split(","))])
    with pytest.raises(StringStabError, match=message) as e:
        read_platoon_logs(p)
    assert "\n" not in str(e.value)


def del_all_but_two(c: list[np.ndarray]) -> None:
    del c[2:]


def test_malformed_files(tmp_path: Path) -> None:
    with pytest.raises(StringStabError, match="expected an existing file"):
        read_platoon_logs(tmp_path / "none.csv")
    (tmp_path / "e.csv").write_text("")
    with pytest.raises(StringStabError, match="expected a header and data rows"):
        read_platoon_logs(tmp_path / "e.csv")
    (tmp_path / "x.csv").write_text("t,v_lead,v,gap\n0,1,1,10\n0.1,1,abc,10\n0.2,1,1,10\n")
    with pytest.raises(StringStabError, match="line 3: expected numbers"):
        read_platoon_logs(tmp_path / "x.csv")
    (tmp_path / "b.bin").write_bytes(b"\xff\xfe\x00\x01" * 10)
    with pytest.raises(StringStabError):
        read_platoon_logs(tmp_path / "b.bin")
