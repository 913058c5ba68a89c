"""Progress (stringstab.progress): plain lines off a terminal, honest times left.

The time left is checked on a synthetic clock against values computed by hand from the
definition (warm-up after the first unit, then the pace of the moving window), including the
case of issue 29: a first training step that pays for the start-up, which made the old
estimate (work done / time since the start) read "~192 h 41 min left".
"""

from __future__ import annotations

import io
import threading

import numpy as np
import pytest

from stringstab.progress import Pace, Progress


class Clock:
    """A synthetic clock: ``clock()`` reads ``clock.t``."""

    def __init__(self, t: float = 0.0) -> None:
        self.t = t

    def __call__(self) -> float:
        return self.t


class FakeTerminal(io.StringIO):
    def isatty(self) -> bool:
        return True


# --------------------------------------------------------------------------- the pace
def test_no_estimate_during_the_warm_up_then_the_pace_since_the_first_unit():
    p = Pace(warmup=10.0, window=60.0)
    p.add(4.0, 1)  # the first unit, after 4 s of start-up: the anchor
    p.add(9.0, 11)
    assert p.rate(13.9, 20) is None and p.left(13.9, 20, 121) is None  # 9.9 s after the anchor
    p.add(14.0, 21)
    # (21 - 1) units in (14 - 4) s = 2 units/s: 100 units in 50 s
    assert p.rate(14.0, 21) == pytest.approx(2.0, rel=1e-12)
    assert p.left(14.0, 21, 121) == pytest.approx(50.0, rel=1e-12)
    # no progress for 6 more seconds: the pace falls, 20 units / 16 s
    assert p.left(20.0, 21, 121) == pytest.approx(100 / (20 / 16), rel=1e-12)


def test_the_pace_is_that_of_the_last_window_not_of_the_whole_run():
    p = Pace(warmup=5.0, window=30.0)
    t, done = 1.0, 1
    p.add(t, done)
    for _ in range(60):  # 1 unit/s for 60 s
        t, done = t + 1.0, done + 1
        p.add(t, done)
    for _ in range(40):  # then 4 units/s for 40 s
        t, done = t + 1.0, done + 4
        p.add(t, done)
    # now t = 101, done = 221; the newest sample at least 30 s old is at t = 71 (done 61 + 40)
    assert (t, done) == (101.0, 221)
    ref = 61 + 4 * (71 - 61)
    assert p.rate(t, done) == pytest.approx((221 - ref) / 30.0, rel=1e-12) == pytest.approx(4.0)
    # the average since the start would say (221 - 1) / 100 = 2.2 units/s
    assert p.left(t, done, 621) == pytest.approx(100.0, rel=1e-12)


def test_a_slow_first_step_no_longer_reads_hundreds_of_hours():
    """Issue 29: 500 000 steps, the first after 9.875 s of start-up, then 1000 steps/s."""
    clock = Clock()
    buf = io.StringIO()
    meter = Progress(500_000, "train idl", unit="steps", stream=buf, tty=False, every=10.0,
                     clock=clock)
    clock.t = 9.875
    meter.update(1)
    for k in range(1, 162):  # 0.125 s apart, 125 steps each (exact binary times)
        clock.t = 9.875 + 0.125 * k
        meter.update(125)
    lines = buf.getvalue().splitlines()
    # the first line (t = 10 s) has no estimate: the old one, 126 steps in 10 s since the
    # start, read 499 874 / 12.6 s = ~11 h 01 min
    assert lines[0] == "train idl: 126/500000 steps (0%), 10 s elapsed"
    # t = 20 s: (10126 - 1) steps in (20 - 9.875) s = 1000 steps/s, 489 874 left: 489.874 s
    assert lines[1] == "train idl: 10126/500000 steps (2%), 20 s elapsed, ~8 min 10 s left"
    # t = 30 s: 20126 done, 479 874 left at 1000 steps/s
    assert lines[2] == "train idl: 20126/500000 steps (4%), 30 s elapsed, ~8 min 00 s left"
    assert meter.left() == pytest.approx(479.874, rel=1e-12)


def test_lines_come_every_few_seconds_and_a_last_one_says_how_long_it_took():
    clock = Clock()
    buf = io.StringIO()
    with Progress(10, "stringstab x", unit="runs", stream=buf, tty=False, every=5.0,
                  clock=clock, warmup=4.0) as p:
        for _ in range(10):
            clock.t += 3.0
            p.update(1)
    # updates at 3, 6, ..., 30 s; a line when 5 s have passed since the last one
    assert buf.getvalue().splitlines() == [
        "stringstab x: 2/10 runs (20%), 6 s elapsed",
        "stringstab x: 4/10 runs (40%), 12 s elapsed, ~18 s left",  # 3 runs / 9 s since the first
        "stringstab x: 6/10 runs (60%), 18 s elapsed, ~12 s left",
        "stringstab x: 8/10 runs (80%), 24 s elapsed, ~6 s left",
        "stringstab x: 10/10 runs done in 30 s",
    ]
    silent = io.StringIO()
    with Progress(10, "x", stream=silent, every=0.0, tty=False, enabled=False) as p:
        p.update(10)
    assert silent.getvalue() == ""


def test_a_bar_on_a_terminal_starts_no_thread_and_shows_the_same_estimate():
    clock = Clock()
    term = FakeTerminal()
    before = threading.active_count()
    p = Progress(100, "region map", unit="points", stream=term, clock=clock, warmup=1.0)
    assert p.bar is not None and threading.active_count() == before  # no tqdm monitor thread
    clock.t = 1.0
    p.update(10)
    clock.t = 3.0
    p.update(10)  # 10 points in 2 s since the first ten: 80 left in 16 s
    p.bar.refresh()
    assert "~16 s left" in term.getvalue().rsplit("\r", 1)[1]
    p.close()


# --------------------------------------------------------------------------- commands
def test_redirected_progress_has_no_carriage_return(capsys, monkeypatch):
    """certify (its chunks) and a region map report in plain lines when stderr is no terminal."""
    from stringstab.cli import certify as cli_certify
    from stringstab.cli import main
    from stringstab.regions import region_map

    monkeypatch.setattr(Progress, "EVERY", 0.0)
    monkeypatch.setattr(cli_certify, "PROGRESS_ROWS", 1)
    assert main(["certify", "1.3,0,0.6", "0.9,-0.5,1.1", "--format", "json"]) == 1
    g = np.linspace(-2, 2, 9)
    region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1, workers=1,
               block=27, progress=True)
    err = capsys.readouterr().err
    assert "\r" not in err
    assert "certify: 1/1 chunks done in " in err
    assert "region map: 27/81 points (33%), 0 s elapsed" in err  # blocks of 3 rows of 9
    assert "region map: 81/81 points done in " in err
