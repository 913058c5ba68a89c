"""Worker processes, started one safe way: the package's one start-method policy.

Every process the package starts for its own work (a region map's pool, the process that
writes a map's figures) is started here, by one policy (issue 29):

* **fork only from a single-threaded process.**  A forked child inherits the parent's
  imports and caches for free (the cheapest start), but also every lock held by another
  thread at that instant, which nobody in the child will ever release: a worker forked while
  a thread imported matplotlib hung in ``_ModuleLock.acquire``.  So ``fork`` is used only
  where no other Python thread runs, and :func:`check_single_threaded` is called at every
  fork, just before it (a thread started later by mistake fails loudly instead of hanging).
* **otherwise forkserver** (``spawn`` where there is none, and on macOS, whose system
  libraries do not survive a fork): the children are forked by a fresh single-threaded
  server process, whatever threads run here (a Jupyter kernel's, a Dask client's).  They
  start from a fresh interpreter: what they run is pickled, and the module that calls the
  pool must be importable (a script needs ``if __name__ == "__main__":``).
  ``STRINGSTAB_START_METHOD=forkserver`` (or ``spawn``) asks for it always.
* **a worker dies with its parent.**  Each child ignores Ctrl-C (the parent stops it), ends
  on SIGTERM (the default action, whatever handler the parent had installed) and asks the
  kernel to kill it when its parent dies (``prctl(PR_SET_PDEATHSIG, SIGKILL)``, Linux); where
  that is not available, a watchdog thread in the child ends it when its parent pid changes.
  When the parent leaves a pool or a helper by an exception (Ctrl-C, SIGTERM turned into
  ``KeyboardInterrupt`` by the command line), the children are killed, not awaited.

:func:`process_pool` is a :class:`concurrent.futures.ProcessPoolExecutor` started this way
(forked children are all started at once, in the pool's ``with``, before the executor's own
management thread exists); :func:`map_processes` runs one callable on many items in such a
pool; :func:`start_helper` starts one child that warms up (imports, caches) while this
process works, then runs one call sent to it.  Start a helper *before* a pool: it is then
forked from a single-threaded process too.  Programs that start other programs
(``subprocess``: SUMO) are not concerned: the child replaces itself with the new program
at once and runs no Python code.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import multiprocessing
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator, Sequence
from types import TracebackType
from typing import Any

from .errors import StringStabError

__all__ = ["ENV", "HELD_SIGNALS", "Helper", "ThreadsRunning", "check_single_threaded",
           "cpu_count", "die_with_parent", "in_background", "in_daemon", "map_processes",
           "process_pool", "signals_held", "start_helper", "start_method"]

#: The environment variable that asks for ``forkserver`` or ``spawn`` always (never ``fork``).
ENV = "STRINGSTAB_START_METHOD"
#: Seconds between two looks of a child's watchdog at its parent (where prctl is absent).
WATCHDOG_SECONDS = 0.5
#: Seconds a child is given to end after SIGTERM before it is killed (SIGKILL).
STOP_SECONDS = 2.0

_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>


class ThreadsRunning(RuntimeError):
    """A fork was about to happen while other threads run (the child could hang for ever)."""


def cpu_count() -> int:
    """The cores this process may run on.

    Returns
    -------
    int
        The number of usable cores (at least 1).
    """
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def in_daemon() -> bool:
    """Whether this process is a daemon (e.g. a multiprocessing.Pool worker: no children).

    Returns
    -------
    bool
        True in a daemon process, which may not start children.
    """
    return bool(multiprocessing.current_process().daemon)


def check_single_threaded(what: str) -> None:
    """Refuse to fork while another Python thread runs: call it just before a fork.

    Parameters
    ----------
    what : str
        What was about to fork, for the message (e.g. ``"a process pool"``).

    Raises
    ------
    ThreadsRunning
        When ``threading.active_count() != 1``; the message names the threads.

    Examples
    --------
    >>> import threading
    >>> done = threading.Event()
    >>> t = threading.Thread(target=done.wait, name="busy")
    >>> t.start()
    >>> check_single_threaded("a pool")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    stringstab.parallel.ThreadsRunning: refusing to fork a pool while other threads run (...busy...)...
    >>> done.set(); t.join()
    """
    if threading.active_count() != 1:
        names = ", ".join(sorted(t.name for t in threading.enumerate()
                                 if t is not threading.current_thread()))
        raise ThreadsRunning(
            f"refusing to fork {what} while other threads run ({names}): a forked child "
            "inherits the locks they hold and can hang for ever; expected a single-threaded "
            f"process (start processes before threads, or set {ENV}=forkserver)")


def start_method(method: str | None = None) -> str:
    """The start method of the next child process, by the policy of this module.

    Parameters
    ----------
    method : {"fork", "forkserver", "spawn"}, optional
        Ask for one.  ``"fork"`` is refused while other threads run (no silent downgrade).
        Default: :data:`ENV` if set, else ``fork`` where it is safe now (Linux and the like,
        no other thread running), else ``forkserver`` (``spawn`` on macOS and Windows).

    Returns
    -------
    str
        The start method.

    Raises
    ------
    StringStabError
        On an unknown method, or one this platform does not have.
    ThreadsRunning
        When ``"fork"`` is asked for while other threads run.
    """
    available = multiprocessing.get_all_start_methods()
    if method is None:
        env = os.environ.get(ENV, "").strip()
        if env:
            if env not in ("forkserver", "spawn") or env not in available:
                ok = [m for m in ("forkserver", "spawn") if m in available]
                raise StringStabError(f"{ENV} must be one of {', '.join(ok)}; got {env!r}")
            return env
        fork_ok = "fork" in available and sys.platform != "darwin"
        if fork_ok and threading.active_count() == 1:
            return "fork"
        return "forkserver" if "forkserver" in available and sys.platform != "darwin" else "spawn"
    if method not in ("fork", "forkserver", "spawn") or method not in available:
        raise StringStabError(f"the start method must be one of {', '.join(available)}; "
                              f"got {method!r}")
    if method == "fork":
        check_single_threaded("a child process")
    return method


def _context(method: str | None, preload: Sequence[str]) -> Any:
    m = start_method(method)
    ctx = multiprocessing.get_context(m)
    if m == "forkserver":  # the server imports these once; its children start with them
        ctx.set_forkserver_preload(sorted({__name__, *preload}))
    return ctx


# --------------------------------------------------------------------------- in the child
def die_with_parent(parent: int) -> str:
    """In a child: end this process when ``parent`` (the process that started it) ends.

    Linux: the kernel sends SIGKILL when the parent (for a forkserver's child: the server,
    which ends when its own parent does) ends (``prctl(PR_SET_PDEATHSIG)``); elsewhere a
    daemon thread looks every :data:`WATCHDOG_SECONDS` and ends the process when the parent
    pid has changed or ``parent`` is gone.  Either way, a parent already gone ends the
    process at once.

    Parameters
    ----------
    parent : int
        The pid of the process that started this one.

    Returns
    -------
    str
        ``"prctl"`` or ``"watchdog"``: how.
    """
    ppid = os.getppid()
    how = "watchdog"
    if sys.platform.startswith("linux"):
        import ctypes

        try:
            libc = ctypes.CDLL(None, use_errno=True)
            if libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0:
                how = "prctl"
        except (OSError, AttributeError):  # pragma: no cover - no libc prctl
            pass
    if not _alive(parent) or os.getppid() != ppid:  # it ended before we asked
        os._exit(1)
    if how == "watchdog":  # pragma: no cover - not Linux
        def watch() -> None:
            import time

            while os.getppid() == ppid and _alive(parent):
                time.sleep(WATCHDOG_SECONDS)
            os._exit(1)

        threading.Thread(target=watch, name="stringstab-parent-watchdog", daemon=True).start()
    return how


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # pragma: no cover - exists, another user's (pid reused)
        return True
    return True


#: The signals held while children are forked (:func:`signals_held`).
HELD_SIGNALS = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM held (blocked, not lost) in this thread while children are forked.

    A forked child starts with its parent's signal handlers.  A signal landing between the
    fork and :func:`_become_child` would run the parent's handler in the child (the command
    line's, which raises), and an exception there makes multiprocessing's fork launcher
    return from ``Process.start`` *in the child*: a copy of the parent running on (under
    pytest-xdist, a second worker reporting the same test).  Held, the signal waits: the
    child inherits the mask and receives it once its own handlers are set
    (:func:`_become_child` releases it); the parent receives it on leaving this block.

    Yields
    ------
    None
    """
    if not hasattr(signal, "pthread_sigmask"):  # pragma: no cover - not POSIX
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, HELD_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _become_child(parent: int) -> None:
    """Signals and lifetime of a child started here (see the module docstring)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C: the parent stops its children
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # not the parent's KeyboardInterrupt
    if hasattr(signal, "pthread_sigmask"):  # held by the parent over the fork: ours now
        signal.pthread_sigmask(signal.SIG_UNBLOCK, HELD_SIGNALS)
    die_with_parent(parent)


def _start_worker(parent: int, initializer: Callable[..., Any] | None,
                  initargs: tuple[Any, ...]) -> None:
    _become_child(parent)
    if initializer is not None:
        initializer(*initargs)


def _nothing() -> None:
    return None


def _stop(procs: Sequence[Any]) -> None:
    """SIGTERM, then SIGKILL after :data:`STOP_SECONDS`; wait for each."""
    for p in procs:
        with contextlib.suppress(OSError, ValueError, AttributeError):
            p.terminate()
    for p in procs:
        with contextlib.suppress(OSError, ValueError, AssertionError):
            p.join(STOP_SECONDS)
            if p.is_alive():
                p.kill()
                p.join(STOP_SECONDS)


def _children() -> set[Any]:
    return set(multiprocessing.active_children())


# --------------------------------------------------------------------------- a pool
@contextlib.contextmanager
def process_pool(workers: int, initializer: Callable[..., Any] | None = None,
                 initargs: tuple[Any, ...] = (), *, method: str | None = None,
                 preload: Sequence[str] = ()) -> Iterator[cf.ProcessPoolExecutor]:
    """A process pool started by this module's policy, its workers stopped on any exit.

    Forked workers are all started here, in one go, right after
    :func:`check_single_threaded` (the executor's management thread starts after them).
    Each worker runs :func:`die_with_parent`, ignores Ctrl-C, ends on SIGTERM, then runs
    ``initializer(*initargs)``.  Leaving the ``with`` normally waits for the pool; leaving it
    by an exception (Ctrl-C, SIGTERM in the command line) cancels what is queued and kills
    the workers instead of waiting for them.  A worker that died (killed by a signal, or by
    the kernel when memory ran out) is reported as a :class:`StringStabError`, in one line.

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
        Override the policy (:func:`start_method`).
    preload : sequence of str
        Modules a forkserver imports before forking workers (their import is then paid once).

    Yields
    ------
    concurrent.futures.ProcessPoolExecutor
        The pool.

    Raises
    ------
    StringStabError
        When a worker died (the pool is broken).
    ThreadsRunning
        When ``method="fork"`` is asked for while other threads run.
    """
    ctx = _context(method, preload)
    before = _children()
    ex = cf.ProcessPoolExecutor(max_workers=max(int(workers), 1), mp_context=ctx,
                                initializer=_start_worker,
                                initargs=(os.getpid(), initializer, tuple(initargs)))
    ok = False
    try:
        if ctx.get_start_method() == "fork":
            check_single_threaded("a process pool")
            with signals_held():  # forks every worker now, before the management thread starts
                ex.submit(_nothing)
        try:
            yield ex
        except cf.process.BrokenProcessPool as e:
            raise StringStabError(
                "a worker process ended unexpectedly (killed: out of memory, or a signal such "
                "as SIGTERM sent to it alone); expected it to finish its work; nothing was "
                "written") from e
        ok = True
    finally:
        if ok:
            ex.shutdown(wait=True)
        else:
            ex.shutdown(wait=False, cancel_futures=True)
            _stop(sorted(_children() - before, key=lambda p: p.pid))
            ex.shutdown(wait=True)


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
        Override the policy (:func:`start_method`).

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


# --------------------------------------------------------------------------- a helper
def _message(e: BaseException) -> str:
    msg = str(e) if isinstance(e, StringStabError) else f"{type(e).__name__}: {e}"
    return msg.replace("\n", " ")


def _helper_main(conn: Any, other_end: Any, parent: int, warm: Callable[..., Any] | None,
                 warm_args: tuple[Any, ...]) -> None:
    """The helper child: warm up, wait for one call, run it, send back its result or error."""
    other_end.close()  # else the parent's closing its end would never reach us as EOF
    _become_child(parent)
    failed = None
    if warm is not None:
        try:
            warm(*warm_args)
        except Exception as e:  # reported with the call
            failed = f"warming up: {_message(e)}"
    try:
        job = conn.recv()
    except EOFError:  # the parent did not need us
        return
    try:
        if failed is not None:
            raise StringStabError(failed)
        fn, args = job
        result = fn(*args)
        conn.send((True, result))
    except BaseException as e:  # reported by Helper.result() in the parent
        conn.send((False, _message(e)))
    finally:
        conn.close()


class Helper:
    """A child process that warms up, then runs one call; see :func:`start_helper`.

    Use it as a context manager: leaving by an exception kills the child; leaving normally
    without a call lets it end.

    Parameters
    ----------
    proc : multiprocessing.Process or None
        The child (None: no child could be started; the call then runs here).
    conn : multiprocessing.connection.Connection or None
        This end of the pipe to the child.
    warm : callable, optional
        Without a child: the warm-up, run here before the call.
    warm_args : tuple
        Its arguments.
    """

    def __init__(self, proc: Any, conn: Any, warm: Callable[..., Any] | None = None,
                 warm_args: tuple[Any, ...] = ()) -> None:
        self.proc = proc
        self._conn = conn
        self._warm = warm
        self._warm_args = warm_args
        self._job: tuple[Callable[..., Any], tuple[Any, ...]] | None = None

    @property
    def pid(self) -> int | None:
        """The child's pid (None when the work runs here)."""
        return None if self.proc is None else int(self.proc.pid)

    def submit(self, fn: Callable[..., Any], *args: Any) -> None:
        """Send the call ``fn(*args)`` to the child (pickled: module-level functions, data).

        Parameters
        ----------
        fn : callable
            The work.
        *args
            Its arguments.
        """
        if self._job is not None:
            raise RuntimeError("a helper runs one call")
        self._job = (fn, args)
        if self._conn is not None:
            self._conn.send(self._job)

    def result(self) -> Any:
        """Wait for the call to finish; its return value.

        Returns
        -------
        object
            What ``fn`` returned (pickled back).

        Raises
        ------
        StringStabError
            With the child's error, in one line, if the call (or the warm-up) failed or the
            child died.
        """
        if self._job is None:
            raise RuntimeError("nothing was submitted to the helper")
        if self._conn is None:
            if self._warm is not None:
                self._warm(*self._warm_args)
            fn, args = self._job
            return fn(*args)
        try:
            ok, value = self._conn.recv()
        except EOFError:  # the child died without a word
            ok, value = False, None
        self._conn.close()
        self.proc.join()
        if not ok or self.proc.exitcode != 0:
            raise StringStabError(value or f"a helper process ended with exit code {self.proc.exitcode}")
        return value

    def stop(self) -> None:
        """Kill the child now (SIGTERM, then SIGKILL) and wait for it."""
        if self.proc is not None:
            _stop([self.proc])
            if self._conn is not None:
                self._conn.close()

    def __enter__(self) -> Helper:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if self.proc is None:
            return
        if exc_type is not None:
            self.stop()
        elif self._job is None:  # never asked: it sees EOF and ends
            self._conn.close()
            self.proc.join()


def start_helper(warm: Callable[..., Any] | None = None, *warm_args: Any,
                 method: str | None = None, preload: Sequence[str] = ()) -> Helper:
    """Start one child that runs ``warm(*warm_args)`` now, then the call sent to it.

    The child is started by the policy of this module (forked only from a single-threaded
    process: start it before any pool or thread) and dies with this process.  In a daemon
    process (no children allowed) nothing is started: the warm-up and the call run here,
    in :meth:`Helper.result`.

    Parameters
    ----------
    warm : callable, optional
        The warm-up (imports, caches), run in the child while this process works.
    *warm_args
        Its arguments.
    method : {"fork", "forkserver", "spawn"}, optional
        Override the policy (:func:`start_method`).
    preload : sequence of str
        Modules a forkserver imports before forking.

    Returns
    -------
    Helper
        The handle: :meth:`~Helper.submit`, then :meth:`~Helper.result`.

    Examples
    --------
    >>> import math
    >>> with start_helper() as h:
    ...     h.submit(math.sqrt, 16.0)
    ...     h.result()
    4.0
    """
    if in_daemon():
        return Helper(None, None, warm, warm_args)
    ctx = _context(method, preload)
    here, there = ctx.Pipe(duplex=True)
    proc = ctx.Process(target=_helper_main, args=(there, here, os.getpid(), warm, warm_args),
                       name="stringstab-helper", daemon=False)
    if ctx.get_start_method() == "fork":
        check_single_threaded("a helper process")
        with signals_held():
            proc.start()
    else:
        proc.start()
    there.close()
    return Helper(proc, here)


def in_background(fn: Callable[..., Any], *args: Any) -> Callable[[], None]:
    """Start ``fn(*args)`` in a helper process; returns ``join()``, to call when it must be done.

    ``join()`` waits for the child and raises :class:`StringStabError` with the child's
    error (one line) if it failed.  In a daemon process ``fn(*args)`` runs in ``join()``.

    Parameters
    ----------
    fn : callable
        The work to run (picklable under forkserver or spawn); its return value is discarded.
    *args
        Its arguments.

    Returns
    -------
    callable
        ``join()``: waits for the child; raises :class:`StringStabError` if it failed.
    """
    helper = start_helper()
    try:
        helper.submit(fn, *args)
    except BaseException:
        helper.stop()
        raise

    def join() -> None:
        try:
            helper.result()
        except BaseException:
            helper.stop()
            raise

    return join
