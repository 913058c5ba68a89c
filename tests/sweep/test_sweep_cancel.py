"""Ctrl-C of a sweep on an external scheduler stops its running points in the workers.

The scheduler and the worker are `dask scheduler` / `dask worker` subprocesses on 127.0.0.1
started (and stopped) by the test, as a user's cluster would be: they outlive the sweep's
client, so a point that went on computing after the interrupt would be seen running there.
Before the fix, the cancelled points of this very setup computed on for their whole 60 s.
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("distributed")

#: How soon after the interrupt the worker must be free of the sweep, s (a point takes 60 s).
STOPPED_WITHIN = 5.0


def _stop(proc: subprocess.Popen[bytes]) -> None:
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(30)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(30)


@pytest.fixture
def cluster(tmp_path: Path) -> Iterator[str]:
    """A scheduler and one worker (two threads) on 127.0.0.1; yields the scheduler's address."""
    sched_file = tmp_path / "scheduler.json"
    procs = [subprocess.Popen(
        [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
         "--port", "0", "--no-dashboard", "--scheduler-file", str(sched_file)],
        stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        deadline = time.monotonic() + 60
        while not sched_file.is_file() and time.monotonic() < deadline:
            assert procs[0].poll() is None, "the scheduler exited"
            time.sleep(0.1)
        time.sleep(0.2)  # the file is written whole: read it once it is there
        address = json.loads(sched_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        procs.append(subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", address, "--nworkers", "1",
             "--nthreads", "2", "--host", "127.0.0.1", "--no-dashboard",
             "--local-directory", str(tmp_path / "worker")],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        yield address
    finally:
        for p in reversed(procs):
            _stop(p)


def _running(client: Any) -> int:
    """Threads of the workers computing a task (Dask's own record, not the toolkit's)."""
    return sum(client.run(lambda dask_worker: len(dask_worker.active_threads)).values())


@pytest.mark.slow  # ~15 s: a scheduler, a worker and a sweep started as processes
def test_ctrl_c_stops_the_running_points_on_an_external_scheduler(cluster: str,
                                                                    tmp_path: Path) -> None:
    from distributed import Client

    spec = tmp_path / "probes.toml"
    spec.write_text('[sweep]\nkind = "probe"\nseeds = [0, 1, 2, 3, 4, 5]\n[base]\nseconds = 60.0\n')
    out = tmp_path / "out"
    sweep = subprocess.Popen(
        [sys.executable, "-m", "stringstab", "sweep", str(spec), "--out", str(out),
         "--scheduler", cluster, "--no-progress"],
        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        with Client(cluster, timeout="30s") as client:
            client.wait_for_workers(1, timeout=60)
            deadline = time.monotonic() + 90
            while _running(client) < 2:  # both threads computing a 60-s point
                assert sweep.poll() is None, sweep.communicate()[0]
                assert time.monotonic() < deadline, "the points never started"
                time.sleep(0.1)
            t0 = time.monotonic()
            sweep.send_signal(signal.SIGINT)  # Ctrl-C
            text, _ = sweep.communicate(timeout=60)
            assert sweep.returncode == 130, text
            assert "interrupted: 0 of 6 points are finished" in text
            while _running(client) or any(client.processing().values()):
                assert time.monotonic() - t0 < STOPPED_WITHIN, (
                    f"points still computing {STOPPED_WITHIN:g} s after Ctrl-C: "
                    f"{client.run(lambda dask_worker: dict(dask_worker.active_threads))}")
                time.sleep(0.1)
            assert client.submit(sum, [1, 2], pure=False).result(timeout=30) == 3  # worker fine
        assert not list((out / "points").glob("*.json"))  # no point recorded as finished
    finally:
        if sweep.poll() is None:
            sweep.kill()
            sweep.communicate()


def test_interrupt_points_stops_only_the_named_point_of_its_sweep(tmp_path: Path) -> None:
    import threading

    from stringstab.sweep import parse_spec, run_point
    from stringstab.sweep.tasks import PointCancelled, interrupt_points

    spec = parse_spec('[sweep]\nkind = "probe"\nseeds = [0, 1]\n[base]\nseconds = 30.0\n')
    a, b = (p.as_dict() for p in spec.points)
    root = str(tmp_path)
    outcome: dict[str, Any] = {}

    def compute(point: dict[str, Any]) -> None:
        try:
            outcome[point["id"]] = run_point(point, root)
        except PointCancelled as e:
            outcome[point["id"]] = e

    threads = [threading.Thread(target=compute, args=(p,), daemon=True) for p in (a, b)]
    for t in threads:
        t.start()
    time.sleep(0.3)
    assert interrupt_points(root, ["no-such-point"]) == 0
    assert interrupt_points(str(tmp_path / "another-sweep"), [a["id"], b["id"]]) == 0
    t0 = time.monotonic()
    assert interrupt_points(root, [a["id"]]) == 1
    threads[0].join(5)
    assert not threads[0].is_alive() and time.monotonic() - t0 < 1.0
    assert isinstance(outcome[a["id"]], PointCancelled)
    assert threads[1].is_alive()  # the other point computes on
    assert interrupt_points(root, [a["id"]]) == 0  # its thread left the registry
    assert interrupt_points(root, [b["id"]]) == 1
    threads[1].join(5)
    assert isinstance(outcome[b["id"]], PointCancelled)
