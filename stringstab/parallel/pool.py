"""A pool of worker processes, each with its own pipe: a dying worker is never a hang.

:class:`WorkerPool` is a :class:`concurrent.futures.Executor` (``submit``, ``map``, futures
for :func:`concurrent.futures.wait`) whose workers are started by the package's policy
(:mod:`stringstab.parallel.policy`) and talk to this process over **one pipe each**.

Why not :class:`concurrent.futures.ProcessPoolExecutor`: its workers send their results
through one shared pipe.  A worker killed half-way through sending a result (by the pool's
own stop on Ctrl-C or SIGTERM, by ``kill``, by the kernel out of memory) leaves a partial
message there, which the executor's management thread then waits to read for ever — and the
interpreter waits for that thread at exit.  It was seen: an interrupted ``stringstab region``
that printed its one line and never ended (1 run in 31 under load, CI's
``test_the_workers_of_a_killed_region_command_are_gone_within_seconds``).  Here a worker that
dies is the end of *its* pipe (EOF) and its process sentinel: its job fails, the pool is
broken (:class:`concurrent.futures.process.BrokenProcessPool`), and nothing waits for a
message that will not come.

One collector thread (a daemon: the interpreter never waits for it) sends the queued jobs to
idle workers and reads their results.  It starts after every worker was started, so a
forked pool forks from a single-threaded process.
"""

from __future__ import annotations

import collections
import concurrent.futures as cf
import contextlib
import os
import threading
import traceback
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures.process import BrokenProcessPool
from multiprocessing import connection
from multiprocessing.reduction import ForkingPickler
from typing import Any

from ..errors import StringStabError
from .policy import (
    STOP_SECONDS,
    become_child,
    check_single_threaded,
    in_daemon,
    signals_held,
    start_context,
    stop_processes,
)

__all__ = ["RemoteTraceback", "WorkerPool", "map_processes", "process_pool"]

#: The message of a pool one of whose workers died.
BROKEN = ("a worker process ended unexpectedly (killed: out of memory, or a signal such as "
          "SIGTERM sent to it alone); expected it to finish its work; nothing was written")


class RemoteTraceback(Exception):
    """The traceback of an error raised in a worker (the ``__cause__`` of the error here)."""

    def __init__(self, tb: str) -> None:
        super().__init__(tb)
        self.tb = tb

    def __str__(self) -> str:
        return self.tb


# --------------------------------------------------------------------------- in the worker
def _error_reply(e: BaseException) -> tuple[bool, Any]:
    tb = "".join(traceback.format_exception(type(e), e, e.__traceback__))
    try:
        ForkingPickler.dumps(e)
        return False, (e, tb)
    except Exception:  # an error that does not pickle: its type and message, in one line
        return False, (StringStabError(f"{type(e).__name__}: {e}".replace("\n", " ")), tb)


def _worker_main(conn: Any, parent: int, initializer: Callable[..., Any] | None,
                 initargs: tuple[Any, ...]) -> None:
    """A worker: its signals and lifetime, the initializer, then one job after another."""
    become_child(parent)
    failed = None
    if initializer is not None:
        try:
            initializer(*initargs)
        except Exception as e:  # reported with every job, not as a dead worker
            failed = f"the worker's initializer failed: {type(e).__name__}: {e}".replace("\n", " ")
    while True:
        try:
            data = conn.recv_bytes()
        except (EOFError, OSError):  # the pool is gone
            return
        try:
            job = ForkingPickler.loads(data)
            if job is None:  # the pool's shutdown
                return
            if failed is not None:
                raise StringStabError(failed)
            fn, args, kwargs = job
            reply: tuple[bool, Any] = (True, fn(*args, **kwargs))
        except BaseException as e:  # reaches the caller through the future
            reply = _error_reply(e)
        try:
            conn.send(reply)
        except (EOFError, OSError):
            return
        except Exception as e:  # a result that does not pickle
            conn.send(_error_reply(StringStabError(
                f"the result of {getattr(fn, '__name__', fn)!r} cannot be sent back: {e}")))


# --------------------------------------------------------------------------- in the parent
class WorkerPool(cf.Executor):
    """Worker processes started now, each with its own pipe; see the module docstring.

    Use :func:`process_pool`, which starts it by the package's policy and stops it on any
    exit; the constructor forks (under ``fork``) and must be called where that is safe.

    Parameters
    ----------
    ctx : multiprocessing context
        How the workers start (:func:`stringstab.parallel.start_context`).
    workers : int
        Worker processes (>= 1).
    initializer : callable, optional
        Run once in each worker before its first job (an error there fails every job).
    initargs : tuple
        Its arguments.
    """

    def __init__(self, ctx: Any, workers: int, initializer: Callable[..., Any] | None = None,
                 initargs: tuple[Any, ...] = ()) -> None:
        self._procs: list[Any] = []
        self._conns: list[Any] = []
        self._lock = threading.Lock()
        self._queue: collections.deque[tuple[cf.Future[Any], bytes]] = collections.deque()
        self._closing = False
        self._broken: str | None = None
        self._woken = False
        try:
            for _ in range(max(int(workers), 1)):
                here, there = ctx.Pipe(duplex=True)
                proc = ctx.Process(target=_worker_main, name="stringstab-worker",
                                   args=(there, os.getpid(), initializer, tuple(initargs)))
                proc.start()
                there.close()  # else a dead worker's pipe would never end here (EOF)
                self._procs.append(proc)
                self._conns.append(here)
        except BaseException:
            stop_processes(self._procs)
            raise
        self._wake_r, self._wake_w = ctx.Pipe(duplex=False)
        self._collector = threading.Thread(target=self._collect, name="stringstab-pool",
                                           daemon=True)
        self._collector.start()

    @property
    def processes(self) -> list[Any]:
        """The worker processes (:class:`multiprocessing.Process`)."""
        return list(self._procs)

    # ------------------------------------------------------------------ the caller's side
    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> cf.Future[Any]:
        """Queue ``fn(*args, **kwargs)`` for the next idle worker.

        Parameters
        ----------
        fn : callable
            The work (pickled: a module-level function, or inherited data under fork).
        *args, **kwargs
            Its arguments (pickled).

        Returns
        -------
        concurrent.futures.Future
            Its result or error; an error that cannot be pickled arrives as
            :class:`~stringstab.errors.StringStabError` with its type and message, the
            worker's traceback as ``__cause__``.

        Raises
        ------
        concurrent.futures.process.BrokenProcessPool
            When a worker has died.
        RuntimeError
            After :meth:`shutdown`.
        """
        fut: cf.Future[Any] = cf.Future()
        try:
            data = bytes(ForkingPickler.dumps((fn, args, kwargs)))
        except Exception as e:  # as ProcessPoolExecutor: through the future
            fut.set_exception(e)
            return fut
        with self._lock:
            if self._broken is not None:
                raise BrokenProcessPool(self._broken)
            if self._closing:
                raise RuntimeError("cannot submit to a worker pool after its shutdown")
            self._queue.append((fut, data))
        self._wake()
        return fut

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        """Let the workers end after the queued jobs (or cancel those first).

        Parameters
        ----------
        wait : bool, default True
            Wait for the jobs and the workers' end.
        cancel_futures : bool, default False
            Cancel the jobs not yet started.
        """
        with self._lock:
            self._closing = True
            if cancel_futures:
                self._cancel_queued()
        self._wake()
        if wait:
            self._collector.join()
            for conn in self._conns:  # each worker ends on None, or already has
                with contextlib.suppress(OSError, ValueError):
                    conn.send_bytes(ForkingPickler.dumps(None))
            for p in self._procs:
                p.join(STOP_SECONDS)
            stop_processes([p for p in self._procs if p.is_alive()])
            self._close()

    def terminate(self) -> None:
        """Stop now: cancel the queued jobs, kill the workers (SIGTERM, then SIGKILL).

        The jobs the workers were running fail with ``BrokenProcessPool``.
        """
        with self._lock:
            self._closing = True
            self._cancel_queued()
        self._wake()
        stop_processes(self._procs)
        self._collector.join(STOP_SECONDS)  # it sees every pipe end; a daemon either way
        if not self._collector.is_alive():
            self._close()

    def _cancel_queued(self) -> None:
        while self._queue:
            fut, _ = self._queue.popleft()
            fut.cancel()

    def _wake(self) -> None:
        with self._lock:
            if self._woken:
                return
            self._woken = True
            with contextlib.suppress(OSError, ValueError):
                self._wake_w.send_bytes(b"")

    def _close(self) -> None:
        for c in (*self._conns, self._wake_r, self._wake_w):
            with contextlib.suppress(OSError):
                c.close()

    # ------------------------------------------------------------------ the collector
    def _next_job(self) -> tuple[cf.Future[Any], bytes] | None:
        with self._lock:
            while self._queue:
                fut, data = self._queue.popleft()
                if fut.set_running_or_notify_cancel():
                    return fut, data
            return None

    def _collect(self) -> None:
        """Send queued jobs to idle workers, read their results, notice a dead worker."""
        n = len(self._procs)
        idle = list(range(n - 1, -1, -1))
        busy: dict[int, cf.Future[Any]] = {}
        by_conn = {id(c): i for i, c in enumerate(self._conns)}
        by_sentinel = {p.sentinel: i for i, p in enumerate(self._procs)}
        while self._broken is None:
            while idle:
                job = self._next_job()
                if job is None:
                    break
                i = idle.pop()
                try:
                    self._conns[i].send_bytes(job[1])
                except (OSError, ValueError):  # the worker died
                    busy[i] = job[0]
                    self._break(busy)
                    return
                busy[i] = job[0]
            with self._lock:
                if self._closing and not self._queue and not busy:
                    return
            ready: list[Any] = connection.wait([self._wake_r, *(self._conns[i] for i in busy),
                                     *by_sentinel])
            for r in ready:
                if r is self._wake_r:
                    with self._lock:
                        self._woken = False
                        with contextlib.suppress(OSError, EOFError):
                            while self._wake_r.poll():
                                self._wake_r.recv_bytes()
                elif isinstance(r, int):  # a worker's process ended
                    i = by_sentinel[r]
                    if i in busy:
                        self._read(i, busy, idle)  # a whole result sent before it ended
                    if not self._closing or i in busy:
                        self._break(busy)
                        return
                    del by_sentinel[r]
                else:
                    i = by_conn[id(r)]
                    if i in busy and not self._read(i, busy, idle):
                        self._break(busy)
                        return

    def _read(self, i: int, busy: dict[int, cf.Future[Any]], idle: list[int]) -> bool:
        """Worker ``i``'s result into its future; False when its pipe ended instead."""
        conn = self._conns[i]
        try:
            if not conn.poll():
                return True
            data = conn.recv_bytes()
        except (EOFError, OSError):
            return False
        fut = busy.pop(i)
        idle.append(i)
        try:
            ok, value = ForkingPickler.loads(data)
        except Exception as e:  # e.g. an error class this process cannot import
            fut.set_exception(StringStabError(
                f"a worker's reply could not be read here: {type(e).__name__}: {e}"))
            return True
        if ok:
            fut.set_result(value)
        else:
            exc, tb = value
            exc.__cause__ = RemoteTraceback(tb)
            fut.set_exception(exc)
        return True

    def _break(self, busy: dict[int, cf.Future[Any]]) -> None:
        """A worker died: every job running or queued fails; no new job is taken."""
        with self._lock:
            self._broken = BROKEN
            queued = [f for f, _ in self._queue]
            self._queue.clear()
        err = BrokenProcessPool(BROKEN)
        for fut in [*busy.values(), *queued]:
            if fut.cancelled() or fut.done():
                continue
            if fut.running() or fut.set_running_or_notify_cancel():
                fut.set_exception(err)
        busy.clear()


@contextlib.contextmanager
def process_pool(workers: int, initializer: Callable[..., Any] | None = None,
                 initargs: tuple[Any, ...] = (), *, method: str | None = None,
                 preload: Sequence[str] = ()) -> Iterator[WorkerPool]:
    """A :class:`WorkerPool` started by the package's policy, its workers stopped on any exit.

    Forked workers are all started here, in one go, right after
    :func:`~stringstab.parallel.check_single_threaded`, with SIGINT and SIGTERM held over the
    forks (the pool's collector thread starts after them).  Each worker runs
    :func:`~stringstab.parallel.become_child` (ignores Ctrl-C, ends on SIGTERM, dies with this
    process), then ``initializer(*initargs)``.  Leaving the ``with`` normally waits for the
    jobs; leaving it by an exception (Ctrl-C, SIGTERM in the command line) cancels what is
    queued and kills the workers instead of waiting for them.  A worker that died (killed by a
    signal, or by the kernel when memory ran out) is reported as a
    :class:`~stringstab.errors.StringStabError`, in one line.

    Parameters
    ----------
    workers : int
        Worker processes (>= 1).
    initializer : callable, optional
        Run once in each worker (a warm-up: imports, caches).  Pickled under forkserver or
        spawn (a module-level function).
    initargs : tuple
        Its arguments.
    method : {"fork", "forkserver", "spawn"}, optional
        Override the policy (:func:`~stringstab.parallel.start_method`).
    preload : sequence of str
        Modules a forkserver imports before forking workers (their import is then paid once).

    Yields
    ------
    WorkerPool
        The pool (a :class:`concurrent.futures.Executor`).

    Raises
    ------
    StringStabError
        When a worker died (the pool is broken).
    ThreadsRunning
        When ``method="fork"`` is asked for while other threads run.
    """
    ctx = start_context(method, preload)
    if ctx.get_start_method() == "fork":
        check_single_threaded("a process pool")
        with signals_held():  # forks every worker now, before the collector thread starts
            pool = WorkerPool(ctx, workers, initializer, initargs)
    else:
        pool = WorkerPool(ctx, workers, initializer, initargs)
    ok = False
    try:
        try:
            yield pool
        except BrokenProcessPool as e:
            raise StringStabError(BROKEN) from e
        ok = True
    finally:
        if ok:
            pool.shutdown(wait=True)
        else:
            pool.terminate()


_INSTALLED: Callable[[Any], Any] | None = None


def _install(fn: Callable[[Any], Any]) -> None:
    global _INSTALLED
    _INSTALLED = fn


def _call_installed(item: Any) -> None:
    assert _INSTALLED is not None
    _INSTALLED(item)


def map_processes(fn: Callable[[Any], Any], items: Sequence[Any], workers: int, *,
                  method: str | None = None) -> None:
    """``fn(item)`` for every item, in at most ``workers`` processes (:func:`process_pool`).

    ``fn`` reaches each worker once (inherited when forked, pickled otherwise), the items
    one by one.  With ``workers`` ≤ 1, one item, or in a daemon process (no children
    allowed), the items are done here, in order.  Return values are discarded.

    Parameters
    ----------
    fn : callable
        The work on one item.
    items : sequence
        The items (picklable).
    workers : int
        The largest number of processes.
    method : {"fork", "forkserver", "spawn"}, optional
        Override the policy (:func:`~stringstab.parallel.start_method`).

    Raises
    ------
    Exception
        Whatever ``fn`` raised, here or in a worker.
    """
    if workers <= 1 or len(items) <= 1 or in_daemon():
        for item in items:
            fn(item)
        return
    with process_pool(min(int(workers), len(items)), _install, (fn,), method=method) as ex:
        for _ in ex.map(_call_installed, items):
            pass
