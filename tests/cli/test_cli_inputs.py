"""Issue 29, items 2 and 3: undecodable files, the one leader check, sweep memory and folders.

The cases a user hit (the issue's *Why*): a 100 m/s leader trained on with exit 0, a 2-sample
leader simulated ("max m_p = n/a"), ``hcfs verify -J 1e9`` without a note, a sweep whose workers
were killed for memory, a sweep replacing a region map's report, ``region --out a/b/c`` creating
folders the docs said it refuses (now one rule: created, for files too), ``compare --reference zzz`` refused after the work, a refused
``--resume`` that did not say why.  Every refusal is one line on stderr, exit 2, nothing written
(and no folder created: an output's missing folders are created when the run succeeds).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from stringstab.cli import main
from stringstab.errors import StringStabError


def _refused(capsys, argv, match: str, out: Path | None = None) -> str:
    code = main(argv)
    stdout, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert code == 2, err
    assert len(lines) == 1 and ": error: " in lines[0] and match in lines[0], err
    assert "Traceback" not in err and stdout == ""
    assert out is None or not out.exists()
    return lines[0]


def _leader_csv(path: Path, t, v) -> Path:
    path.write_text("t,v\n" + "".join(f"{a:g},{b:.6f}\n" for a, b in zip(t, v)))
    return path


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A tiny trained run (DDPG, 64 steps)."""
    folder = tmp_path_factory.mktemp("run") / "run"
    assert main(["train", "--algo", "ddpg", "--steps", "64", "--num-envs", "2", "--seed", "0",
                 "--no-progress", "--out", str(folder)]) == 0
    return folder


# --------------------------------------------------------------------------- undecodable files
def test_read_text_names_the_first_byte_that_is_not_utf8(tmp_path):
    from stringstab.io.text_input import read_text

    p = tmp_path / "f.csv"
    cases = {  # payload -> what the message says (offsets counted by hand)
        b"t,v\n0,caf\xe9\n": "not UTF-8 text (first at byte offset 9)",
        b"\xff\xfet\x00,\x00v\x00": "got UTF-16 text (its byte-order mark), not UTF-8 text",
        b"t,v\n0,1\x00\n": "a NUL byte at offset 7",
        bytes(range(256)): "not UTF-8 text (first at byte offset 128)",  # 0x80
    }
    for payload, says in cases.items():
        p.write_bytes(payload)
        with pytest.raises(StringStabError) as e:
            read_text(p, label=f"leader CSV {str(p)!r}", expected="a 't, v' CSV file")
        msg = str(e.value)
        assert says in msg and str(p) in msg and "expected a 't, v' CSV file" in msg, msg
        assert "\n" not in msg
    p.write_bytes(b"\xef\xbb\xbft,v\n0,1\n")  # UTF-8 with a byte-order mark: read, mark dropped
    assert read_text(p, label="x", expected="y") == "t,v\n0,1\n"


def test_a_streamed_file_names_the_offset_of_a_bad_byte_past_a_chunk_boundary(tmp_path):
    import gzip

    from stringstab.io.text_input import open_text

    p = tmp_path / "big.csv"
    # 1 + 2 x 700000 bytes of text ('a', then two-byte characters straddling the 1 MiB chunks)
    data = b"a" + "é".encode() * 700_000 + b"\n\xff"
    p.write_bytes(data)
    g = tmp_path / "big.gz"  # the same text compressed: the offset counts decompressed bytes
    g.write_bytes(gzip.compress(data))
    for f, of in ((p, ")"), (g, " of the decompressed data)")):
        with pytest.raises(StringStabError, match=re.escape(f"first at byte offset 1400002{of}")):
            with open_text(f, label="NGSIM file", expected="an NGSIM file") as fh:
                assert next(iter(fh)).startswith("aé")  # the first line is text
                list(fh)


def test_the_one_reader_refuses_nul_bytes_folders_and_missing_files_in_every_form(tmp_path):
    """Plain or gzip (recognised by content, whatever the name), the same refusals."""
    import gzip

    from stringstab.io.text_input import open_text, read_text

    plain, packed = tmp_path / "a.csv", tmp_path / "a.csv.txt"  # a gzip file not named .gz
    for payload, says in ((b"t,v\n0,1\x00\n", "a NUL byte at offset 7, which no text file holds"),
                          (b"t,v\n0,caf\xe9\n", "not UTF-8 text (first at byte offset 9")):
        plain.write_bytes(payload)
        packed.write_bytes(gzip.compress(payload))
        for f in (plain, packed):
            for read in (lambda f: read_text(f, label=f"leader CSV {f.name!r}", expected="CSV"),
                         lambda f: list(open_text(f, label=f"leader CSV {f.name!r}", expected="CSV"))):
                with pytest.raises(StringStabError) as e:
                    read(f)
                assert says in str(e.value) and f.name in str(e.value), str(e.value)
    packed.write_bytes(gzip.compress(b"t,v\n0,1\n"))
    assert read_text(packed, label="x", expected="y") == "t,v\n0,1\n"
    for f, says in ((tmp_path, "x: expected y; got a folder"),
                    (tmp_path / "none.csv", "x: cannot read it (No such file or directory); expected y")):
        with pytest.raises(StringStabError, match=re.escape(says)):
            read_text(f, label="x", expected="y")


def test_gains_from_binary_standard_input_are_refused(capsys, monkeypatch):
    import io
    import sys

    stdin = io.TextIOWrapper(io.BytesIO(b"k_x,k_v,k_a\n1,1,\xe9\n"), encoding="utf-8")
    monkeypatch.setattr(sys, "stdin", stdin)  # 0xe9 after 12 + 4 bytes
    _refused(capsys, ["certify", "--file", "-"], "<stdin>: expected a CSV or JSON gain file (UTF-8 "
             "text); got a binary file or text in another encoding, not UTF-8 text (first at "
             "byte offset 16)")


def test_standard_input_goes_through_the_one_reader(capsys, monkeypatch):
    """gzip on standard input is decompressed; a stream that cannot be read is one line (the
    2000-example fuzz found ``certify --file -`` a traceback when reading stdin raised OSError)."""
    import gzip
    import io
    import json
    import sys

    class Broken(io.RawIOBase):
        def readable(self):
            return True

        def readinto(self, b):
            raise OSError(5, "Input/output error")

    text = b"k_x,k_v,k_a\n1.2,0.5,0.6\n"
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(gzip.compress(text))))
    assert main(["certify", "--file", "-", "--format", "json"]) == 0
    packed = json.loads(capsys.readouterr().out)["results"]
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(text)))
    assert main(["certify", "--file", "-", "--format", "json"]) == 0
    assert json.loads(capsys.readouterr().out)["results"] == packed
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BufferedReader(Broken())))
    _refused(capsys, ["certify", "--file", "-"], "<stdin>: cannot read it (Input/output error); "
             "expected a CSV or JSON gain file")


# --------------------------------------------------------------------------- the leader check
def test_settling_time_is_the_decay_rate_of_the_simulated_follower():
    """ln 50 / σ, σ from the roots of τs³ + s² + (k_v + k_x T*)s + k_x; σ checked against the
    simulator: a follower started 5 m off its spacing behind a steady leader."""
    from stringstab.traffic import LinearController, from_speed, simulate
    from stringstab.traffic.limits import settling_time

    c = LinearController(0.2, 0.7, 0.0, headway=1.1, standstill=2.0)
    ts = settling_time(c, 0.1)
    sigma = math.log(50.0) / ts
    t = np.arange(0.0, 40.0005, 0.01)  # a fine step: the ZOH at 0.1 s moves σ by 1.8 %
    lead = from_speed(t, np.full(t.size, 15.0), dt=0.01)
    r = simulate(lead, c, 1, tau=0.1, delta=0.2, initial_gap=2.0 + 1.1 * 15.0 + 5.0)
    e = np.abs(r.gap[0] - (2.0 + 1.1 * r.speed[1]))
    late = (t >= 20.0) & (t <= 35.0)  # the faster modes (σ = 0.66, 9.0) are gone by then
    slope = np.polyfit(t[late], np.log(e[late]), 1)[0]
    np.testing.assert_allclose(-slope, sigma, rtol=0.005)
    np.testing.assert_allclose(ts, math.log(50.0) / 0.33593862, rtol=1e-6)  # roots by hand: numpy
    # no settling time: time-varying gains, IDM, a loop that is not internally stable
    from stringstab.traffic.controllers import IDMController

    assert settling_time(IDMController(), 0.1) is None
    assert settling_time(LinearController(-0.2, 0.7, 0.0), 0.1) is None


def test_the_hcfs_cacc_settling_time_is_that_of_any_platoon_size():
    """The closed-loop map, ordered (x_1, v_1, x_2, v_2, ...), is block lower triangular with
    the one-follower map on its diagonal: every platoon size has its spectral radius (numerical
    eigenvalues of the repeated blocks scatter by ~1e-4, so the structure is checked exactly)."""
    from stringstab.cli.hcfs import cacc_settling_time
    from stringstab.hcfs.cacc import closed_loop_matrix

    one = closed_loop_matrix(1)
    A = closed_loop_matrix(8)
    order = np.ravel(np.column_stack([np.arange(8), np.arange(8) + 8]))
    B = A[np.ix_(order, order)]
    for i in range(8):
        np.testing.assert_array_equal(B[2 * i:2 * i + 2, 2 * i:2 * i + 2], one)
        assert not B[2 * i:2 * i + 2, 2 * i + 2:].any()  # nothing above the diagonal blocks
    rho = max(abs(np.linalg.eigvals(one)))
    np.testing.assert_allclose(rho, 0.947, atol=5e-4)  # the HCFS constants' value
    np.testing.assert_allclose(cacc_settling_time(), math.log(50) * 0.2 / -math.log(rho), rtol=1e-12)


@pytest.mark.parametrize("argv", [
    ["train", "--algo", "idl", "--steps", "64", "--no-progress", "--leaders", "{L}", "--out", "{O}"],
    ["hcfs", "train", "--steps", "64", "--no-progress", "--leader", "{L}", "--out", "{O}"],
    ["simulate", "--leader", "{L}", "--no-figures", "--out", "{O}"],
    ["hcfs", "verify", "-J", "2.5", "--policy", "stand-in", "--no-figures", "--leader", "{L}",
     "--out", "{O}"],
], ids=lambda a: " ".join(a[:2]))
def test_every_command_refuses_a_leader_no_road_vehicle_drives(argv, tmp_path, capsys):
    t = np.arange(0.0, 60.1, 1.0)
    lead = _leader_csv(tmp_path / "fast.csv", t, np.full(t.size, 100.0))  # 360 km/h
    out = tmp_path / "out"
    _refused(capsys, [a.format(L=lead, O=out) for a in argv], "reaches 100 m/s", out)


@pytest.mark.parametrize("argv", [
    ["simulate", "--leader", "{L}", "--no-figures", "--out", "{O}"],
    ["train", "--algo", "ddpg", "--steps", "64", "--no-progress", "--leaders", "{L}", "--out", "{O}"],
    ["hcfs", "train", "--steps", "64", "--no-progress", "--leader", "{L}", "--out", "{O}"],
    ["hcfs", "verify", "-J", "2.5", "--policy", "stand-in", "--no-figures", "--leader", "{L}",
     "--out", "{O}"],
    ["evaluate", "{RUN}", "--platoon", "none", "--leaders", "{L}", "--no-progress", "--out", "{O}"],
    ["compare", "{RUN}", "--baselines", "none", "--leaders", "{L}", "--no-progress", "--out", "{O}"],
], ids=lambda a: " ".join(a[:2]))
def test_every_command_refuses_a_two_sample_leader(argv, run, tmp_path, capsys):
    lead = _leader_csv(tmp_path / "two.csv", [0, 1], [10.0, 10.0])  # 1 s: was "max m_p = n/a"
    out = tmp_path / "out"
    line = _refused(capsys, [a.format(L=lead, O=out, RUN=run) for a in argv], "lasts 1 s (", out)
    assert "; expected at least 10 s" in line


def test_a_leader_shorter_than_the_settling_time_is_refused_then_held(tmp_path, capsys):
    from stringstab.traffic import LinearController
    from stringstab.traffic.limits import settling_time

    ts = settling_time(LinearController(0.05, 0.5, 0.0, headway=1.1), 0.1)
    assert 30.0 < ts < 120.0  # 34.7 s: k_x = 0.05 1/s² is slow
    out = tmp_path / "sim"
    argv = ["simulate", "--leader", "sinusoid:omega=0.5,duration=30", "--gains", "0.05,0.5,0",
            "--followers", "2", "--no-figures", "--out", str(out)]
    _refused(capsys, argv, f"expected at least the controller's settling time {ts:.4g} s", out)
    assert main([*argv, "--hold", f"{math.ceil(ts)}"]) in (0, 1)  # held long enough: it runs
    assert (out / "metrics.json").is_file()


def test_recorded_pairs_go_through_the_leader_check():
    import argparse

    from stringstab.cli._common import checked_leaders
    from stringstab.traffic import from_speed
    from stringstab.traffic.limits import Limits
    from stringstab.traffic.loaders import FollowingPair

    t = np.arange(0.0, 5.05, 0.1)
    tr = from_speed(t, np.full(t.size, 10.0), dt=0.1)
    pair = FollowingPair(tr, tr, 1, 2, 0, 5.0)
    with pytest.raises(StringStabError, match="lasts 5 s"):
        checked_leaders(argparse.Namespace(command="evaluate"), [pair], Limits())


def test_hcfs_verify_notes_a_jerk_limit_that_never_binds(tmp_path, capsys):
    code = main(["hcfs", "verify", "-J", "100", "--followers", "2", "--policy", "stand-in",
                 "--duration", "15", "--no-figures", "--no-progress", "--out", str(tmp_path / "h")])
    err = capsys.readouterr().err
    assert code in (0, 1)
    assert ("warning: --jerk-limit 100 m/s^3 is above the sensible range (up to (a_max - a_min)/T "
            "= 30 m/s^3): a rate limit of 20 m/s^2 per frame never binds") in err
    _refused(capsys, ["hcfs", "verify", "-J", "1e9", "--out", str(tmp_path / "h2")],
             "--jerk-limit J = 1e+09 m/s³ is far outside", tmp_path / "h2")


def test_a_count_beyond_its_sensible_bound_warns_and_runs_beyond_its_largest_is_refused(tmp_path,
                                                                                        capsys):
    """ranges.COUNTS: 1,001 followers is a note (the run is computed); 1,001 retries a refusal.

    (A platoon's size is bounded by the memory estimate, not by a count: a million followers of
    12 s fit in 20 GiB and run, with the note.)
    """
    argv = ["simulate", "--leader", "sinusoid:omega=0.5", "--duration", "12", "--no-figures"]
    out = tmp_path / "many"
    assert main([*argv, "--followers", "1001", "--out", str(out)]) in (0, 1)
    err = capsys.readouterr().err
    assert ("stringstab simulate: warning: --followers 1001 is more than the sensible 1000 "
            "followers; the run is computed but will take long") in err
    assert np.load(out / "trajectories.npz")["speed"].shape[0] == 1002  # leader + 1001 followers
    spec = _spec(tmp_path / "s.toml", "certify", n=3)
    _refused(capsys, ["sweep", str(spec), "--retries", "1001", "--out", str(tmp_path / "too")],
             "--retries must be at most 1000 retries (a task that fails this often will not "
             "succeed); got 1001", tmp_path / "too")


def test_the_radio_and_sensor_flags_have_their_ranges(tmp_path, capsys):
    """--message-period 1e300 was simulated (one message, 'radio: messages every 1e+300 s')."""
    argv = ["simulate", "--leader", "sinusoid:omega=0.5", "--duration", "20", "--followers", "2",
            "--no-figures"]
    _refused(capsys, [*argv, "--message-period", "1e300", "--out", str(tmp_path / "a")],
             "--message-period = 1e+300 s is far outside the physically meaningful range",
             tmp_path / "a")
    _refused(capsys, [*argv, "--stale-after", "0.5", "--fallback-gains", "nan,0.5", "--out",
                      str(tmp_path / "b")], "--fallback-gains must be two finite numbers",
             tmp_path / "b")
    assert main([*argv, "--noise-speed", "6", "--out", str(tmp_path / "c")]) in (0, 1)
    assert ("stringstab simulate: warning: --noise-speed = 6 m/s is outside the sensible range "
            "(up to 5 m/s)") in capsys.readouterr().err


# --------------------------------------------------------------------------- sweep memory
def _spec(path: Path, kind: str, **base) -> Path:
    lines = [f'[sweep]\nname = "t"\nkind = "{kind}"\n[base]']
    lines += [f"{k} = {v!r}".replace("'", '"') for k, v in base.items()]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_sweep_refuses_a_point_no_worker_can_hold_before_dispatch(tmp_path, capsys):
    spec = _spec(tmp_path / "big.toml", "certify", n=100_000)
    out = tmp_path / "sweep"
    line = _refused(capsys, ["sweep", str(spec), "--workers", "2", "--out", str(out)],
                    "(certify, the base settings) needs about 532.9 PiB of memory; each of the 2 "
                    "local worker(s)", out)
    assert "expected n <= " in line


def test_sweep_and_region_use_one_estimate(tmp_path, capsys):
    """A region point of n = 100000 is refused with the estimate ``region --n 100000`` gives."""
    out = tmp_path / "maps"
    region = _refused(capsys, ["region", "--fix", "k_a=0.5", "--n", "100000", "--out", str(out)],
                      "needs about")
    spec = _spec(tmp_path / "big.toml", "region", n=100_000, fix="k_a=0.5")
    sweep = _refused(capsys, ["sweep", str(spec), "--workers", "1", "--out", str(out)],
                     "needs about")
    estimate = region.split("needs about ")[1].split(" of memory")[0]
    assert f"needs about {estimate} of memory" in sweep


def test_run_sweep_refuses_from_the_workers_memory_limit(tmp_path):
    """With a scheduler, the largest worker's memory_limit bounds a point; nothing is written."""
    from stringstab.sweep import load_spec, run_sweep

    class Client:  # what run_sweep asks a scheduler before dispatching anything
        def scheduler_info(self):
            return {"workers": {"tcp://a:1": {"memory_limit": 1 << 30},
                                "tcp://b:1": {"memory_limit": 2 << 30}}}

        def submit(self, *a, **k):  # pragma: no cover - must not be reached
            raise AssertionError("dispatched")

    spec = load_spec(_spec(tmp_path / "s.toml", "certify", n=2000))
    out = tmp_path / "sweep"
    with pytest.raises(StringStabError, match=r"the largest of the 2 Dask workers has 2\.0 GiB; "
                                              r"expected n <= 146 "):  # 250 MB + 600 B n³
        run_sweep(spec, out, client=Client())
    assert not out.exists()


def test_sweep_check_lists_each_points_memory(tmp_path, capsys):
    spec = _spec(tmp_path / "s.toml", "certify", n=201)
    assert main(["sweep", str(spec), "--check", "--out", str(tmp_path / "x")]) == 0
    assert "(memory: about 4.8 GiB)" in capsys.readouterr().out  # 250 MB + 600 B x 201^3


# --------------------------------------------------------------------------- output folders
def test_sweep_refuses_a_folder_region_wrote_and_region_a_sweep_folder(tmp_path, capsys):
    from distributed import Client, LocalCluster

    from stringstab.sweep import load_spec, run_sweep

    maps = tmp_path / "maps"
    assert main(["region", "--fix", "k_a=0.5", "--n", "5", "--no-progress", "--format", "png",
                 "--out", str(maps)]) == 0
    capsys.readouterr()
    before = {p.name: p.read_bytes() for p in maps.iterdir() if p.is_file()}
    spec = _spec(tmp_path / "probe.toml", "probe", seconds=0.0)
    _refused(capsys, ["sweep", str(spec), "--workers", "1", "--out", str(maps)],
             "holds the outputs of 'stringstab region'; expected an empty folder or one written "
             "by 'stringstab sweep'")
    assert {p.name: p.read_bytes() for p in maps.iterdir() if p.is_file()} == before
    sweep = tmp_path / "sweep"
    with LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        assert run_sweep(load_spec(spec), sweep, client=client, progress=False,
                         log=lambda s: None)["done"] == 1
        with pytest.raises(StringStabError, match="holds the outputs of 'stringstab region'"):
            run_sweep(load_spec(spec), maps, client=client, progress=False, log=lambda s: None)
    _refused(capsys, ["region", "--fix", "k_a=0.5", "--n", "5", "--out", str(sweep)],
             "holds the outputs of 'stringstab sweep'")


@pytest.mark.parametrize("argv", [
    ["region", "--fix", "k_a=0.5", "--n", "5", "--no-progress", "--format", "png", "--out", "{O}"],
    ["simulate", "--leader", "sinusoid:omega=0.5", "--duration", "12", "--followers", "1",
     "--no-figures", "--out", "{O}"],
    ["certify", "1.2,0.5,0.6", "--out", "{O}.json"],
    ["derive", "--out", "{O}.json"],
    ["tune", "0.9,-0.5,1.1", "--out", "{O}.csv"],
], ids=lambda a: a[0])
def test_every_output_creates_its_missing_folders_on_success(argv, tmp_path, capsys):
    """One rule for files and folders (docs/conventions.md): ``--out a/b/c`` creates a/b."""
    out = tmp_path / "a" / "b" / "c"
    assert main([a.format(O=out) for a in argv]) in (0, 1), capsys.readouterr().err
    made = [p for p in (out, out.with_suffix(".json"), out.with_suffix(".csv")) if p.exists()]
    assert len(made) == 1 and any(made[0].iterdir() if made[0].is_dir() else [made[0]])


@pytest.mark.parametrize("argv", [
    ["region", "--fix", "k_a=0.5", "--n", "5", "--tau", "-1", "--out", "{O}"],
    ["simulate", "--tau", "-1", "--out", "{O}"],
    ["train", "--algo", "ddpg", "--steps", "0", "--out", "{O}"],
    ["evaluate", "{RUN}", "--platoon", "-1", "--out", "{O}"],
    ["compare", "{RUN}", "--baselines", "zzz", "--out", "{O}"],
    ["hcfs", "verify", "-J", "-1", "--out", "{O}"],
    ["hcfs", "train", "--steps", "0", "--out", "{O}"],
    ["identify", "{LOG}", "--bootstrap", "-1", "--out", "{O}"],
    ["sweep", "{SPEC}", "--retries", "-1", "--out", "{O}"],
    ["demo", "--only", "certify", "--v-max", "-1", "--out", "{O}"],
    ["tune", "0.9,-0.5,1.1", "--tau", "-1", "--report", "{O}"],
    ["certify", "1.2,0.5,0.6", "--tau", "-1", "--out", "{O}.json"],
    ["derive", "--sample-time", "-1", "--out", "{O}.json"],
], ids=lambda a: " ".join(a[:2]))
def test_a_refused_run_creates_no_folder(argv, run, tmp_path, capsys):
    """The missing folders of an output are created only when the run succeeds."""
    log = tmp_path / "log.csv"
    log.write_text("t,v0,v1,gap1\n0,1,1,1\n")
    spec = _spec(tmp_path / "s.toml", "probe")
    out = tmp_path / "a" / "b" / "c"
    _refused(capsys, [a.format(O=out, RUN=run, LOG=log, SPEC=spec) for a in argv], "")
    assert not (tmp_path / "a").exists()


# --------------------------------------------------------------------------- compare, resume
def test_compare_refuses_an_unknown_reference_before_any_evaluation(run, tmp_path, capsys,
                                                                     monkeypatch):
    import stringstab.rl.evaluate as ev

    def never(*a, **k):  # pragma: no cover - the refusal comes first
        raise AssertionError("evaluated before the --reference check")

    monkeypatch.setattr(ev, "evaluate", never)
    _refused(capsys, ["compare", str(run), "--reference", "zzz", "--out", str(tmp_path / "c")],
             "--reference 'zzz' is not among the strategies ['cacc', 'ddpg', 'idm']",
             tmp_path / "c")


def test_a_refused_resume_names_the_fields_that_differ(run, tmp_path, capsys, monkeypatch):
    import shutil

    import stringstab.rl.envs as envs

    def never(*a, **k):  # pragma: no cover - the refusal comes first
        raise AssertionError("environments built before the configuration check")

    monkeypatch.setattr(envs, "make_env", never)
    folder = tmp_path / "run"
    shutil.copytree(run, folder)
    _refused(capsys, ["train", "--algo", "ddpg", "--steps", "128", "--seed", "1", "--num-envs", "4",
                      "--resume", "--no-progress", "--out", str(folder)],
             "--resume: the checkpoint was written with another configuration; expected its "
             "seed = 0, num_envs = 2; got seed = 1, num_envs = 4 (only the step budget and the "
             "checkpoint interval may change on resume)")
