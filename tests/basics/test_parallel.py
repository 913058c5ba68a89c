"""The start-method policy (stringstab.parallel): no fork while a thread runs, no orphan.

The child processes are looked at from outside (``/proc``): which processes descend from a
command, and whether they are gone after the command was killed.  The repeated runs of
``stringstab region --workers 2`` are the watchdog of issue 29 (a forked worker that
inherited a lock held by a thread hung for ever: 3 hangs in 20 runs at 801²).
"""

from __future__ import annotations

import concurrent.futures as cf
import functools
import json
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from stringstab import parallel
from stringstab.errors import StringStabError
from stringstab.parallel import (
    ThreadsRunning,
    check_single_threaded,
    map_processes,
    process_pool,
    start_helper,
    start_method,
)

LINUX = sys.platform.startswith("linux")


@pytest.fixture
def a_thread():
    """A thread that runs for the length of the test."""
    stop = threading.Event()
    t = threading.Thread(target=stop.wait, name="test-thread-holding-on", daemon=True)
    t.start()
    yield t
    stop.set()
    t.join()


def _fresh(fn):
    """Run the test in a fresh interpreter (``python -c``; its asserts, its exit code).

    A fork needs a single-threaded process, and the tests run before this one in the same
    process may have left threads behind (a Dask client's offload pool does).
    """
    @functools.wraps(fn)
    def run() -> None:
        code = (f"import sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); "
                f"import test_parallel; test_parallel.{fn.__name__}.__wrapped__()")
        env = {k: v for k, v in os.environ.items() if k != parallel.ENV}
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             timeout=180, env=env)
        assert res.returncode == 0, res.stderr[-4000:]

    return run


def _signals() -> tuple[object, object, int]:
    return signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM), os.getppid()


def _square(x: int) -> int:
    return x * x


def _die() -> None:
    os.kill(os.getpid(), signal.SIGKILL)


def _record(path: str) -> None:
    Path(path).write_text(str(os.getpid()))


# --------------------------------------------------------------------------- the check
def test_the_check_refuses_a_fork_while_another_thread_runs(a_thread):
    with pytest.raises(ThreadsRunning, match="test-thread-holding-on"):
        check_single_threaded("a test pool")


@_fresh
def test_the_check_lets_a_single_threaded_process_fork():
    assert threading.active_count() == 1
    check_single_threaded("a test pool")


@pytest.mark.skipif(not LINUX, reason="fork is the policy's choice on Linux only")
def test_the_policy_forks_only_without_threads(a_thread, monkeypatch):
    monkeypatch.delenv(parallel.ENV, raising=False)
    assert start_method() == "forkserver"
    with pytest.raises(ThreadsRunning):  # asked for explicitly: refused, never downgraded
        start_method("fork")


@pytest.mark.skipif(not LINUX, reason="fork is the policy's choice on Linux only")
@_fresh
def test_the_policy_forks_a_single_threaded_process_and_the_variable_overrides():
    assert start_method() == "fork"
    os.environ[parallel.ENV] = "forkserver"
    assert start_method() == "forkserver"
    os.environ[parallel.ENV] = "fork"  # never "fork on demand": only the safe ones
    with pytest.raises(StringStabError, match=f"{parallel.ENV} must be one of forkserver, spawn; got 'fork'"):
        start_method()


def test_pools_and_helpers_refuse_to_fork_while_a_thread_runs(a_thread):
    with pytest.raises(ThreadsRunning), process_pool(2, method="fork"):
        pass
    with pytest.raises(ThreadsRunning):
        start_helper(method="fork")


# --------------------------------------------------------------------------- the children
def _workers_ignore_ctrl_c_end_on_sigterm_and_compute(method: str) -> None:
    with process_pool(2, method=method) as ex:
        assert list(ex.map(_square, range(6))) == [0, 1, 4, 9, 16, 25]
        sigint, sigterm, _ = ex.submit(_signals).result()
    assert sigint == signal.SIG_IGN and sigterm == signal.SIG_DFL


def test_forkserver_workers_ignore_ctrl_c_end_on_sigterm_and_compute():
    _workers_ignore_ctrl_c_end_on_sigterm_and_compute("forkserver")


@_fresh
def test_forked_workers_ignore_ctrl_c_end_on_sigterm_and_compute():
    _workers_ignore_ctrl_c_end_on_sigterm_and_compute("fork")


def test_a_pool_started_while_a_thread_runs_is_not_forked_and_works(a_thread, tmp_path):
    with process_pool(2) as ex:
        assert sorted(ex.map(_square, [3, 4])) == [9, 16]
        _, _, ppid = ex.submit(_signals).result()
    assert ppid != os.getpid()  # forked by the forkserver, not by this (threaded) process
    map_processes(_record, [str(tmp_path / "a"), str(tmp_path / "b")], 2)
    pids = {int((tmp_path / n).read_text()) for n in "ab"}
    assert os.getpid() not in pids


@pytest.mark.skipif(not LINUX, reason="prctl(PR_SET_PDEATHSIG) is Linux's")
@_fresh
def test_a_child_asks_the_kernel_to_kill_it_with_its_parent():
    with process_pool(1, method="fork") as ex:
        how = ex.submit(parallel.die_with_parent, os.getpid()).result()
    assert how == "prctl"


def test_a_helper_runs_its_call_and_reports_a_failure_in_one_line(tmp_path):
    with start_helper(_record, str(tmp_path / "warm")) as h:
        h.submit(_square, 7)
        assert h.result() == 49
    assert int((tmp_path / "warm").read_text()) == h.pid != os.getpid()
    with start_helper() as h:
        h.submit(_square, "x")
        with pytest.raises(StringStabError, match=r"^TypeError: can't multiply sequence"):
            h.result()


@pytest.mark.parametrize("method", ["fork", "forkserver"])
def test_a_helper_never_asked_ends_with_the_with_block(method):
    code = ("from stringstab.parallel import start_helper\n"
            "if __name__ == '__main__':\n"
            f"    with start_helper(method={method!r}) as h:\n"
            "        pass\n"
            "    print(h.proc.exitcode)\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert res.stdout.strip() == "0", res.stderr


@_fresh
def test_leaving_a_pool_by_an_exception_kills_its_workers_at_once():
    t0 = time.perf_counter()
    pids = []
    with pytest.raises(KeyboardInterrupt), process_pool(2, method="fork") as ex:
        pids = [p.pid for p in __import__("multiprocessing").active_children()]
        ex.submit(time.sleep, 30)
        raise KeyboardInterrupt
    assert time.perf_counter() - t0 < 10  # not the 30 s the worker was asked to sleep
    assert pids and not any(_exists(p) for p in pids)


def _half_a_reply_then_die() -> None:
    """In a worker: write the start of a reply (a length and 4 of its bytes) on every pipe this
    process may write to, then die: a worker killed half-way through sending its result."""
    import gc
    import struct
    from multiprocessing.connection import Connection

    for c in gc.get_objects():
        if isinstance(c, Connection) and not c.closed and c.writable:
            os.write(c.fileno(), struct.pack("!i", 1 << 20) + b"half")
    os.kill(os.getpid(), signal.SIGKILL)


@_fresh
def test_a_worker_dying_half_way_through_its_reply_breaks_the_pool_and_never_hangs():
    # ProcessPoolExecutor's shared result pipe waited for the rest of such a reply for ever,
    # and the interpreter's exit waited for it (an interrupted region command that never
    # ended: CI, 2026-11-28); each worker's own pipe ends with it instead
    for method in ("fork", "forkserver"):
        t0 = time.perf_counter()
        with pytest.raises(StringStabError, match=r"^a worker process ended unexpectedly"), \
                process_pool(2, method=method) as ex:
            assert ex.submit(_square, 5).result(timeout=60) == 25
            ex.submit(_half_a_reply_then_die).result(timeout=60)
        with pytest.raises(KeyboardInterrupt), process_pool(2, method=method) as ex:
            fut = ex.submit(_half_a_reply_then_die)
            cf.wait([fut], timeout=60)
            raise KeyboardInterrupt
        assert time.perf_counter() - t0 < 60


# --------------------------------------------------------------------------- from outside
def _exists(pid: int) -> bool:
    """The process exists and is not a zombie."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def _descendants(pid: int) -> set[int]:
    """Every live process below ``pid`` (from /proc: each process's parent)."""
    parent: dict[int, int] = {}
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                stat = (d / "stat").read_text()
            except OSError:
                continue
            parent[int(d.name)] = int(stat.rsplit(")", 1)[1].split()[1])
    out: set[int] = set()
    todo = [pid]
    while todo:
        p = todo.pop()
        kids = [c for c, pp in parent.items() if pp == p and c not in out]
        out.update(kids)
        todo.extend(kids)
    return {p for p in out if _exists(p)}


def _region(out: Path, n: int, *extra: str) -> list[str]:
    return [sys.executable, "-m", "stringstab", "region", "--fix", "k_a=0.5", "--n", str(n),
            "--method", "exact", "--workers", "2", "--no-progress", "--out", str(out), *extra]


@pytest.mark.skipif(not LINUX, reason="reads /proc")
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_the_workers_of_a_killed_region_command_are_gone_within_seconds(tmp_path, sig):
    proc = subprocess.Popen(_region(tmp_path / "m", 1201), stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        kids: set[int] = set()
        while len(kids) < 3 and time.monotonic() < deadline and proc.poll() is None:
            kids = _descendants(proc.pid)  # the output helper, then the two workers
            time.sleep(0.05)
        assert len(kids) >= 3, f"expected a helper and two workers; found {sorted(kids)}"
        time.sleep(0.5)  # mid-map
        kids = _descendants(proc.pid)
        os.kill(proc.pid, sig)
        code = proc.wait(timeout=30)
        deadline = time.monotonic() + 5
        while any(_exists(k) for k in kids) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not [k for k in kids if _exists(k)], "orphans outlived the command"
        if sig == signal.SIGTERM:  # one line, exit 130, nothing written
            assert code == 130, proc.stderr.read().decode() if proc.stderr else ""
            assert not (tmp_path / "m").exists()
        else:
            assert code == -signal.SIGKILL
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


@pytest.mark.skipif(not LINUX, reason="reads /proc")
def test_a_worker_ended_by_sigterm_ends_and_the_command_says_so_in_one_line(tmp_path):
    proc = subprocess.Popen(_region(tmp_path / "m", 1201), stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        deadline = time.monotonic() + 60
        workers: list[int] = []
        while len(workers) < 2 and time.monotonic() < deadline and proc.poll() is None:
            # the workers are the children that are not the output helper (started first)
            kids = sorted(_descendants(proc.pid))
            workers = kids[1:] if len(kids) >= 3 else []
            time.sleep(0.05)
        assert len(workers) == 2
        os.kill(workers[0], signal.SIGTERM)
        code = proc.wait(timeout=60)
        err = proc.stderr.read() if proc.stderr else ""
        assert not _exists(workers[0])
        assert code == 2 and err.count("\n") == 1 and "worker process ended" in err, err
        assert not (tmp_path / "m").exists()
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


#: A Python audit hook records the threads running at every ``os.fork`` of the command's own
#: process (the event is raised just before the fork), independently of the package's check.
AUDIT = """
import json, os, sys, threading
forks, me = [], os.getpid()
def hook(event, args):
    if event == "os.fork" and os.getpid() == me:
        forks.append(sorted(t.name for t in threading.enumerate()))
sys.addaudithook(hook)
from stringstab.cli import main
code = main(sys.argv[1:])
print("FORKS " + json.dumps(forks), file=sys.stderr)
sys.exit(code)
"""


@pytest.mark.skipif(not LINUX, reason="fork is the policy's choice on Linux only")
@pytest.mark.parametrize("how", ["lines", "terminal", "dask"])
def test_region_forks_only_while_a_single_thread_runs(tmp_path, how):
    """The helper and both workers are forked from a single-threaded process.

    On a terminal (a pty) the progress bar is open during the map (801², long enough to show
    it); with ``--scheduler local`` a Dask client runs (and leaves threads behind) before the
    files are written.
    """
    n = "801" if how == "terminal" else "201"
    argv = ["region", "--fix", "k_a=0.5", "--n", n, "--method", "exact", "--workers", "2",
            "--format", "png", "--dpi", "30", "--out", str(tmp_path / "m")]
    if how == "dask":
        pytest.importorskip("distributed")
        argv += ["--scheduler", "local"]
    env = {k: v for k, v in os.environ.items() if k != parallel.ENV}
    if how == "terminal":
        import fcntl
        import pty
        import struct
        import termios

        main_fd, sub_fd = pty.openpty()
        fcntl.ioctl(sub_fd, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))  # 100 columns
        proc = subprocess.Popen([sys.executable, "-c", AUDIT, *argv], stdout=subprocess.DEVNULL,
                                stderr=sub_fd, env=env)
        os.close(sub_fd)
        chunks = []
        while True:
            try:
                data = os.read(main_fd, 65536)
            except OSError:  # the command ended (EIO on Linux)
                break
            if not data:
                break
            chunks.append(data)
        os.close(main_fd)
        proc.wait(timeout=300)
        err = b"".join(chunks).decode(errors="replace")
        assert re.search("region map: .*\r(?!\n)", err), err  # a bar, redrawn in place
    else:
        res = subprocess.run([sys.executable, "-c", AUDIT, *argv], capture_output=True,
                             text=True, env=env, timeout=300)
        proc, err = res, res.stderr
    assert proc.returncode == 0, err
    forks = json.loads(err.rsplit("FORKS ", 1)[1].splitlines()[0])
    assert forks == [["MainThread"]] * (1 if how == "dask" else 3)


#: Runs of the parallel path under the watchdog, and the seconds one may take.
RUNS = 30
WATCHDOG = 90.0


@pytest.mark.slow
@pytest.mark.skipif(not LINUX, reason="the hang was a fork's")
def test_region_with_two_workers_and_the_figure_writer_never_hangs(tmp_path):
    """30 runs (two at a time), each killed and failed if it takes over WATCHDOG seconds."""
    cmds = [_region(tmp_path / f"m{i}", 201, "--format", "png", "--dpi", "30") for i in range(RUNS)]
    running: list[tuple[int, subprocess.Popen[bytes], float]] = []
    hung, failed = [], []
    todo = list(enumerate(cmds))
    while todo or running:
        while todo and len(running) < 2:
            i, cmd = todo.pop(0)
            running.append((i, subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                                start_new_session=True), time.monotonic()))
        time.sleep(0.05)
        for item in list(running):
            i, p, t0 = item
            if p.poll() is not None:
                running.remove(item)
                if p.returncode != 0:
                    failed.append((i, p.returncode, p.stderr.read().decode() if p.stderr else ""))
            elif time.monotonic() - t0 > WATCHDOG:
                running.remove(item)
                hung.append((i, sorted(_descendants(p.pid))))
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
    assert hung == [], f"{len(hung)} of {RUNS} runs hung (run, its processes): {hung}"
    assert failed == []
    assert all((tmp_path / f"m{i}" / "region_class_exact.png").is_file() for i in range(RUNS))


def test_an_error_in_a_worker_reaches_the_caller_and_a_dead_worker_is_one_line():
    with pytest.raises(TypeError, match="can't multiply sequence"), process_pool(1) as ex:
        ex.submit(_square, "x").result()
    with pytest.raises(StringStabError, match=r"^a worker process ended unexpectedly"), \
            process_pool(1) as ex:
        ex.submit(_die).result()


# --------------------------------------------------------------------------- the fork window
def _mask_now() -> list[int]:
    return sorted(int(x) for x in signal.pthread_sigmask(signal.SIG_BLOCK, []))


def _masks_at_fork(start, tmp):
    """The signal mask each forked child has right after the fork (an at-fork hook records
    it) and the one the child works with (``_mask_now`` run in it)."""
    os.register_at_fork(after_in_child=lambda: Path(tmp, f"fork-{os.getpid()}").write_text(
        json.dumps(_mask_now())))
    working = start()
    at_fork = [json.loads(p.read_text()) for p in sorted(Path(tmp).glob("fork-*"))]
    return at_fork, working


@pytest.mark.skipif(not LINUX, reason="fork is the policy's choice on Linux only")
@_fresh
def test_sigint_and_sigterm_are_held_over_the_fork_and_released_in_the_child():
    # The window found under pytest-xdist (a test reported twice): a forked child receiving
    # SIGTERM before _become_child ran the parent's raising handler inside multiprocessing's
    # fork launcher and came back from Process.start as a copy of the parent.  Held over the
    # fork, such a signal waits until the child's own handlers are set.
    import tempfile

    held = sorted(int(s) for s in parallel.HELD_SIGNALS)
    with tempfile.TemporaryDirectory() as tmp:
        def helper():
            with start_helper(method="fork") as h:
                h.submit(_mask_now)
                return [h.result()]

        at_fork, working = _masks_at_fork(helper, tmp)
        assert at_fork and all(set(held) <= set(m) for m in at_fork), at_fork
        assert all(not set(held) & set(m) for m in working), working
    with tempfile.TemporaryDirectory() as tmp:
        def pool():
            with process_pool(2, method="fork") as ex:
                return [f.result(timeout=60) for f in [ex.submit(_mask_now) for _ in range(4)]]

        at_fork, working = _masks_at_fork(pool, tmp)
        assert len(at_fork) == 2 and all(set(held) <= set(m) for m in at_fork), at_fork
        assert all(not set(held) & set(m) for m in working), working
    assert not set(held) & set(_mask_now())  # and the parent's mask is restored


@pytest.mark.skipif(not LINUX, reason="fork is the policy's choice on Linux only")
@_fresh
def test_held_signals_reach_the_parent_after_the_fork():
    got = []
    signal.signal(signal.SIGTERM, lambda *_: got.append("SIGTERM"))
    with parallel.signals_held():
        # to this thread (a process-directed signal may be taken by another thread, e.g.
        # a BLAS worker, which does not hold it; a child forked here inherits only this one)
        signal.pthread_kill(threading.get_ident(), signal.SIGTERM)
        assert got == []  # held, not lost
    assert got == ["SIGTERM"]
