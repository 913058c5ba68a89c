"""Leader trajectories: bundled cycles, synthetic profiles, the NGSIM and CSV loaders, the split."""

import csv

import numpy as np
import pytest
from numpy.testing import assert_allclose

from stringstab.errors import StringStabError
from stringstab.traffic import (
    CYCLES,
    cycle,
    from_speed,
    hard_acceleration,
    hard_braking,
    leader_by_name,
    load_csv,
    load_ngsim_pairs,
    paper_mix,
    sinusoid,
    stop_and_go,
    train_test_split,
)

# Durations and peak speeds of the cycles (the README table; the peaks from the FASTSim files).
CYCLE_TABLE = [
    ("udds", 1369.0, 25.34757924),
    ("hwfet", 765.0, 26.77813045),
    ("us06", 600.0, 35.897312),
    ("wltc3b", 1800.0, 36.47222222),
]


@pytest.mark.parametrize(("name", "duration", "vmax"), CYCLE_TABLE)
def test_cycles_resampled_and_capped(name, duration, vmax):
    raw = cycle(name, dt=1.0, speed_max=None)
    assert raw.duration == duration
    assert_allclose(raw.speed.max(), vmax, rtol=1e-9)
    tr = cycle(name, dt=0.1)
    assert tr.n_steps == round(duration / 0.1) + 1
    assert tr.speed.max() <= 33.3 + 1e-12 and tr.speed.min() >= 0.0
    # resampling is linear interpolation of the 1 Hz samples
    assert_allclose(tr.speed[::10], np.minimum(raw.speed, 33.3), rtol=0, atol=1e-12)
    # x, v, a are consistent on the grid: v_{k+1} = v_k + a_k Δt, x by the trapezoid rule
    assert_allclose(np.diff(tr.speed), tr.accel[:-1] * 0.1, atol=1e-12)
    assert_allclose(np.diff(tr.position), (tr.speed[1:] + tr.speed[:-1]) * 0.05, atol=1e-9)


def test_cycle_names():
    assert set(CYCLES) == {"udds", "hwfet", "us06", "wltc3b"}
    assert cycle("WLTC_3b").name == "wltc3b"
    with pytest.raises(StringStabError, match="unknown driving cycle"):
        cycle("nedc")


def test_sinusoid_closed_form():
    tr = sinusoid(omega=0.8, amplitude=1.5, speed=20.0, duration=50.0, dt=0.05)
    t = tr.t
    assert_allclose(tr.accel, 1.5 * 0.8 * np.sin(0.8 * t), atol=1e-12)
    assert_allclose(tr.speed, 20.0 - 1.5 * np.cos(0.8 * t), atol=1e-12)
    # position is the exact integral of speed
    assert_allclose(np.gradient(tr.position, 0.05, edge_order=2), tr.speed, atol=1e-3)


def test_synthetic_manoeuvres():
    b = hard_braking(speed=25.0, to_speed=5.0)
    assert b.accel.min() == -7.6 and b.speed[-1] == pytest.approx(5.0, abs=1e-9)
    a = hard_acceleration(speed=5.0, to_speed=25.0)
    assert a.accel.max() == 3.0 and a.speed[-1] == pytest.approx(25.0, abs=1e-9)
    sg = stop_and_go(waves=3, speed_high=12.0)
    stops = np.flatnonzero(np.diff((sg.speed <= 1e-9).astype(int)) == 1)
    assert stops.size == 3 and sg.speed.max() == pytest.approx(12.0)
    mix = paper_mix()
    assert mix.accel.min() == pytest.approx(-7.6) and mix.accel.max() == pytest.approx(3.0)
    assert (mix.accel < -7.0).sum() > 0 and mix.speed.min() == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(StringStabError, match="decel < 0"):
        hard_braking(decel=2.0)


def test_leader_by_name_specs(tmp_path):
    assert leader_by_name("sinusoid:omega=0.5,amplitude=2", dt=0.2).meta["amplitude"] == 2.0
    assert leader_by_name("stop-and-go:waves=2").name == "stop-and-go"
    assert leader_by_name("us06", duration=10.0).duration == 10.0
    with pytest.raises(StringStabError, match="KEY=VALUE"):
        leader_by_name("sinusoid:frequency=1")
    with pytest.raises(StringStabError, match="must be a number"):
        leader_by_name("sinusoid:omega=fast")
    with pytest.raises(StringStabError, match="unknown leader"):
        leader_by_name("moon-landing")


def _write(path, text):
    path.write_text(text, encoding="utf-8")
    return path


def test_load_csv_t_v_and_t_v_a(tmp_path):
    tr = load_csv(_write(tmp_path / "l.csv", "t,v\n0,10\n1,12\n2,12\n"), dt=0.5)
    assert_allclose(tr.speed, [10, 11, 12, 12, 12])
    assert_allclose(tr.accel, [2, 2, 0, 0, 0])
    tr = load_csv(_write(tmp_path / "la.csv", " T , V , A \n0,10,0.5\n2,11,0.5\n"), dt=1.0)
    assert_allclose(tr.accel, [0.5, 0.5, 0.5])


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("", "empty"),
        ("time,speed\n0,1\n1,2\n", "expected columns 't, v' or 't, v, a'"),
        ("t,v,a,b\n0,1,0,0\n", "expected columns"),
        ("t,v\n0,1\n", "at least 2 data rows"),
        ("t,v\n0,1\n1,x\n", "line 3: not a number"),
        ("t,v\n0,1\n1,nan\n", "line 3: values must be finite"),
        ("t,v\n0,1\n0,2\n", "strictly increasing"),
        ("t,v\n0,1\n1,-2\n", "speed must be >= 0"),
        ("t,v\n0,1\n1\n", "line 3: expected 2 values"),
    ],
)
def test_load_csv_errors(tmp_path, text, match):
    with pytest.raises(StringStabError, match=match):
        load_csv(_write(tmp_path / "bad.csv", text))


def test_load_csv_missing_file(tmp_path):
    with pytest.raises(StringStabError, match="cannot read"):
        load_csv(tmp_path / "nope.csv")


NGSIM_HEADER = ["Vehicle_ID", "Frame_ID", "Total_Frames", "Global_Time", "Local_X", "Local_Y",
                "Global_X", "Global_Y", "v_length", "v_Width", "v_Class", "v_Vel", "v_Acc",
                "Lane_ID", "Preceding", "Following", "Space_Headway", "Time_Headway", "Location"]


def _ngsim_rows(loc, vid, frames, y0, vel, acc, length, preceding):
    rows = []
    for f in frames:
        t = (f - frames[0]) * 0.1
        rows.append({"Vehicle_ID": vid, "Frame_ID": f, "Total_Frames": len(frames),
                     "Global_Time": 1113433135300 + 100 * f, "Local_X": 6.0,
                     "Local_Y": y0 + vel * t + 0.5 * acc * t * t, "Global_X": 0, "Global_Y": 0,
                     "v_length": length, "v_Width": 6.0, "v_Class": 2, "v_Vel": vel + acc * t,
                     "v_Acc": acc, "Lane_ID": 2, "Preceding": preceding(f), "Following": 0,
                     "Space_Headway": 0, "Time_Headway": 0, "Location": loc})
    return rows


@pytest.fixture
def ngsim_file(tmp_path):
    """A small NGSIM-format file (feet): vehicle 2 follows 1 for 20 s, then 3 for 10 s; vehicle 4
    follows 1 for only 10 s; vehicle 6 follows 5 whose frames 250-251 are missing; vehicle IDs
    are reused at a second location; one duplicated row."""
    rows = []
    rows += _ngsim_rows("i-80", 1, range(100, 401), 1000.0, 50.0, 0.0, 15.0, lambda f: 0)
    rows += _ngsim_rows("i-80", 2, range(100, 401), 920.0, 50.0, 0.0, 14.0,
                        lambda f: 1 if f <= 300 else 3)
    rows += _ngsim_rows("i-80", 3, range(301, 401), 2000.0, 50.0, 0.0, 16.0, lambda f: 0)
    rows += _ngsim_rows("i-80", 4, range(100, 201), 500.0, 40.0, 1.0, 15.0, lambda f: 1)
    five = _ngsim_rows("i-80", 5, range(100, 500), 3000.0, 30.0, 0.0, 20.0, lambda f: 0)
    rows += [r for r in five if r["Frame_ID"] not in (250, 251)]
    rows += _ngsim_rows("i-80", 6, range(100, 500), 2900.0, 30.0, 0.0, 15.0, lambda f: 5)
    rows += _ngsim_rows("us-101", 1, range(100, 300), 10.0, 30.0, 0.0, 15.0, lambda f: 0)
    rows += _ngsim_rows("us-101", 2, range(100, 300), 0.0, 30.0, 0.0, 15.0, lambda f: 1)
    rows.append(dict(rows[0]))
    p = tmp_path / "ngsim.csv"
    with p.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=NGSIM_HEADER)
        w.writeheader()
        w.writerows(rows)
    return p


def test_ngsim_pairs(ngsim_file):
    pairs = load_ngsim_pairs(ngsim_file, location="I-80")
    found = [(p.follower_id, p.leader_id, p.start_frame, p.follower.n_steps) for p in pairs]
    # 2 behind 1: frames 100-300 (20 s); 2 behind 3 (10 s) and 4 behind 1 (10 s) are too short;
    # 6 behind 5 splits at the missing frames into 100-249 (14.9 s, dropped) and 252-499 (24.7 s)
    assert found == [(2, 1, 100, 201), (6, 5, 252, 248)]
    p = pairs[0]
    assert p.duration == pytest.approx(20.0)
    assert p.leader.dt == 0.1 and p.location == "i-80"
    ft = 0.3048
    assert_allclose(p.leader.speed, 50.0 * ft)
    assert_allclose(p.gap, (80.0 - 15.0) * ft, atol=1e-9)  # Local_Y difference minus leader length
    assert_allclose(p.leader_length, 15.0 * ft)
    assert_allclose(p.follower.position[0], 920.0 * ft)
    # the other location reuses vehicle IDs: 2 behind 1 for 19.9 s there
    every = load_ngsim_pairs(ngsim_file)
    assert {(q.location, q.follower_id) for q in every} == {("i-80", 2), ("i-80", 6), ("us-101", 2)}
    assert load_ngsim_pairs(ngsim_file, min_duration=5.0, location="i-80")[1].follower_id == 2


def test_ngsim_accelerating_pair_in_si(tmp_path):
    rows = _ngsim_rows("", 7, range(0, 200), 100.0, 20.0, 2.0, 15.0, lambda f: 0)
    rows += _ngsim_rows("", 8, range(0, 200), 0.0, 20.0, 2.0, 15.0, lambda f: 7)
    p = tmp_path / "acc.csv"
    with p.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=[c for c in NGSIM_HEADER if c != "Location"])
        w.writeheader()
        w.writerows([{k: v for k, v in r.items() if k != "Location"} for r in rows])
    (pair,) = load_ngsim_pairs(p)
    assert_allclose(pair.leader.accel, 2.0 * 0.3048)
    assert_allclose(pair.follower.speed[-1], (20.0 + 2.0 * 19.9) * 0.3048)


def test_ngsim_missing_columns(tmp_path):
    p = _write(tmp_path / "x.csv", "Vehicle_ID,Frame_ID,Local_Y\n1,1,1\n")
    with pytest.raises(StringStabError, match=r"missing columns \['v_Vel', 'v_Acc', 'Preceding'\]"):
        load_ngsim_pairs(p)
    p = _write(tmp_path / "y.csv", "Vehicle_ID,Frame_ID,Local_Y,v_Vel,v_Acc,Preceding\n1,1,1,1,0,0\n")
    assert load_ngsim_pairs(p) == []
    with pytest.raises(StringStabError, match="no Location column"):
        load_ngsim_pairs(p, location="i-80")


def test_train_test_split():
    items = list(range(100))
    train, test = train_test_split(items, test_fraction=0.3, seed=1)
    assert len(train) == 70 and len(test) == 30
    assert sorted(train + test) == items
    assert train_test_split(items, test_fraction=0.3, seed=1) == (train, test)
    assert train_test_split(items, test_fraction=0.3, seed=2) != (train, test)
    with pytest.raises(StringStabError, match="test_fraction"):
        train_test_split(items, test_fraction=1.0)
    with pytest.raises(StringStabError, match="at least 2"):
        train_test_split([1])


def test_from_speed_rejects_bad_profiles():
    with pytest.raises(StringStabError, match="strictly increasing"):
        from_speed([0, 1, 1], [1, 1, 1])
    with pytest.raises(StringStabError, match="dt"):
        from_speed([0, 1], [1, 1], dt=0)
