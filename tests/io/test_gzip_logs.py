"""Every log reader reads a gzip-compressed file (.csv.gz) as the same file uncompressed:
OpenACC and plain CSV platoon logs, NGSIM trajectory files (identify's and the RL leaders'),
leader CSV files; damaged compressed data is one line, not a traceback."""

from __future__ import annotations

import gzip
import math
import re
from pathlib import Path

import numpy as np
import pytest

from stringstab.cli import main
from stringstab.errors import StringStabError
from stringstab.identify import read_logs
from stringstab.io.text_input import is_gzip, open_text
from stringstab.traffic import LinearController, from_speed, simulate
from stringstab.traffic.leaders import leader_by_name
from stringstab.traffic.loaders import load_csv, load_ngsim_pairs


def _gz(path: Path, name: str | None = None) -> Path:
    out = path.with_name(name or path.name + ".gz")
    out.write_bytes(gzip.compress(path.read_bytes()))
    return out


def _same_logs(a, b) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert (x.positions, x.names, x.fmt) == (y.positions, y.names, y.fmt)
        np.testing.assert_array_equal(x.t, y.t)
        np.testing.assert_array_equal(x.speed, y.speed)
        assert x.gap.keys() == y.gap.keys()
        for k in x.gap:
            np.testing.assert_array_equal(x.gap[k], y.gap[k])
        assert (x.accel is None) == (y.accel is None)
        if x.accel is not None:
            np.testing.assert_array_equal(x.accel, y.accel)


def _platoon():
    t = np.arange(0.0, 60.05, 0.1)
    lead = from_speed(t, 14 + 3 * np.sin(2 * np.pi * t / 30), dt=0.1)
    return simulate(lead, LinearController(0.2, 0.6, 0.0, headway=1.2, standstill=3.0), 2,
                    tau=0.4, delta=0.0)


def test_openacc_and_plain_csv(tmp_path: Path) -> None:
    r = _platoon()
    head = ["Time"] + [f"{c}{k}" for k in (1, 2, 3) for c in ("Speed", "E", "N")] + ["IVS1", "IVS2"]
    lines = ["Date,8,10,2019", "Vehicle_order,A,B,C,", "Number_of_vehicles,3", "ACC,1",
             "Distance_setting,S", ",".join(head)]
    for j in range(r.t.size):
        row = [f"{r.t[j]:.1f}"]
        for k in range(3):
            row += [f"{r.speed[k, j]:.6f}", f"{r.position[k, j]:.4f}", "0.0"]
        lines.append(",".join([*row, f"{r.gap[0, j]:.4f}", f"{r.gap[1, j]:.4f}"]))
    acc = tmp_path / "openacc.csv"
    acc.write_text("\r\n".join(lines) + "\r\n")
    plain = tmp_path / "plain.csv"
    plain.write_text("t,v_lead,v,gap\n" + "".join(
        f"{r.t[j]:.1f},{r.speed[0, j]:.6f},{r.speed[1, j]:.6f},{r.gap[0, j]:.6f}\n"
        for j in range(r.t.size)))
    for f in (acc, plain):
        g = _gz(f)
        assert is_gzip(g) and not is_gzip(f)
        _same_logs(read_logs(f), read_logs(g))
        _same_logs(read_logs(f), read_logs(_gz(f, f.stem + ".dat")))  # by content, not name
    [log] = read_logs(tmp_path / "openacc.csv.gz")
    assert log.fmt == "openacc" and log.names == ("A", "B", "C")
    np.testing.assert_allclose(log.gap[2], r.gap[1], atol=1e-4)  # the simulator's, as written


def test_ngsim(tmp_path: Path) -> None:
    head = "Vehicle_ID,Frame_ID,Local_Y,v_Vel,v_Acc,Preceding,v_Length\n"
    rows = []
    for f in range(100, 500):  # 40 s: one pair longer than identify's 30 s
        t = (f - 100) * 0.1
        v, y, a = 40.0 + 5.0 * math.sin(0.5 * t), 40.0 * t - 10.0 * (math.cos(0.5 * t) - 1), 2.5 * math.cos(0.5 * t)
        rows.append(f"1,{f},{y + 80.0:.4f},{v:.4f},{a:.4f},0,15\n")
        rows.append(f"2,{f},{y:.4f},{v:.4f},{a:.4f},1,15\n")
    p = tmp_path / "ngsim.csv"
    p.write_text(head + "".join(rows))
    g = _gz(p)
    _same_logs(read_logs(p), read_logs(g))
    [a], [b] = load_ngsim_pairs(p), load_ngsim_pairs(g)
    np.testing.assert_array_equal(a.gap, b.gap)
    # the RL leaders' reader recognises an NGSIM file inside gzip too (its header line)
    from stringstab.rl.episodes import _is_ngsim

    assert _is_ngsim(g) and _is_ngsim(p)


def test_leader_csv(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    p = tmp_path / "lead.csv"
    t = np.arange(0.0, 30.0, 0.5)
    p.write_text("t,v\n" + "".join(f"{x:g},{12 + math.sin(0.3 * x):.6f}\n" for x in t))
    g = _gz(p)
    a, b = load_csv(p), load_csv(g)
    np.testing.assert_array_equal(a.speed, b.speed)
    np.testing.assert_array_equal(leader_by_name(str(g)).speed, a.speed)
    out = tmp_path / "run"
    assert main(["simulate", "--leader", str(g), "--followers", "2", "--no-figures",
                 "--out", str(out)]) == 0
    capsys.readouterr()
    # a missing .csv.gz is named as a leader file, not as an unknown leader
    with pytest.raises(StringStabError, match=r"leader CSV .*none.csv.gz'?: cannot read it"):
        leader_by_name(str(tmp_path / "none.csv.gz"))


def test_damaged_gzip_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    p = tmp_path / "plain.csv"
    p.write_text("t,v_lead,v,gap\n" + "".join(f"{0.1 * j:.1f},10,10,20\n" for j in range(400)))
    data = gzip.compress(p.read_bytes())
    cut = tmp_path / "cut.csv.gz"
    cut.write_bytes(data[: len(data) // 2])  # truncated
    crc = tmp_path / "crc.csv.gz"
    crc.write_bytes(data[:-8] + bytes(8))  # a wrong checksum and length
    for bad in (cut, crc):
        with pytest.raises(StringStabError,
                           match="platoon log .*" + re.escape(bad.name)
                                 + ".*: cannot read it .damaged gzip data") as e:
            read_logs(bad)
        assert "\n" not in str(e.value)
        with pytest.raises(StringStabError, match=r"leader CSV .*: cannot read it .damaged gzip data"):
            load_csv(bad)
        rc = main(["identify", str(bad), "--no-figures", "--out", str(tmp_path / "o")])
        err = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
        assert rc == 2 and len(err) == 1 and err[0].startswith("stringstab identify: error: "), err
    with open_text(cut, label="log 'cut.csv.gz'", expected="a CSV log") as fh, pytest.raises(
            StringStabError, match=r"^log 'cut\.csv\.gz': cannot read it \(damaged gzip data: "
                                   r".*\); expected a CSV log$"):
        fh.read()
