"""The start-method policy: which way a child process starts, its signals and its lifetime.

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
* **a child dies with its parent.**  Each child ignores Ctrl-C (the parent stops it), ends
  on SIGTERM (the default action, whatever handler the parent had installed) and asks the
  kernel to kill it when its parent dies (``prctl(PR_SET_PDEATHSIG, SIGKILL)``, Linux); where
  that is not available, a watchdog thread in the child ends it when its parent pid changes
  (:func:`become_child`).
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import sys
import threading
from collections.abc import Iterator, Sequence
from typing import Any

from ..errors import StringStabError

__all__ = ["ENV", "HELD_SIGNALS", "STOP_SECONDS", "ThreadsRunning", "become_child",
           "check_single_threaded", "cpu_count", "die_with_parent", "in_daemon", "signals_held",
           "start_context", "start_method", "stop_processes"]

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
    stringstab.parallel.policy.ThreadsRunning: refusing to fork a pool while other threads run (...busy...)...
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


def start_context(method: str | None, preload: Sequence[str] = ()) -> Any:
    """The multiprocessing context of the next child, by :func:`start_method`.

    Parameters
    ----------
    method : {"fork", "forkserver", "spawn"}, optional
        As for :func:`start_method`.
    preload : sequence of str
        Modules a forkserver imports before forking (their import is then paid once).

    Returns
    -------
    multiprocessing.context.BaseContext
        The context.
    """
    m = start_method(method)
    ctx = multiprocessing.get_context(m)
    if m == "forkserver":  # the server imports these once; its children start with them
        ctx.set_forkserver_preload(sorted({str(__package__), *preload}))
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
    fork and :func:`become_child` would run the parent's handler in the child (the command
    line's, which raises), and an exception there makes multiprocessing's fork launcher
    return from ``Process.start`` *in the child*: a copy of the parent running on (under
    pytest-xdist, a second worker reporting the same test).  Held, the signal waits: the
    child inherits the mask and receives it once its own handlers are set
    (:func:`become_child` releases it); the parent receives it on leaving this block.

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


def become_child(parent: int) -> None:
    """In a child: the signals and lifetime of a child started by this package.

    Ctrl-C ignored (the parent stops its children), SIGTERM ends it (not the parent's
    handler), the signals held over the fork released, and :func:`die_with_parent`.

    Parameters
    ----------
    parent : int
        The pid of the process that started this one.
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C: the parent stops its children
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # not the parent's KeyboardInterrupt
    if hasattr(signal, "pthread_sigmask"):  # held by the parent over the fork: ours now
        signal.pthread_sigmask(signal.SIG_UNBLOCK, HELD_SIGNALS)
    die_with_parent(parent)


def stop_processes(procs: Sequence[Any]) -> None:
    """SIGTERM, then SIGKILL after :data:`STOP_SECONDS`; wait for each.

    Parameters
    ----------
    procs : sequence of multiprocessing.Process
        The children to stop (those already ended are waited for only).
    """
    for p in procs:
        with contextlib.suppress(OSError, ValueError, AttributeError):
            p.terminate()
    for p in procs:
        with contextlib.suppress(OSError, ValueError, AssertionError):
            p.join(STOP_SECONDS)
            if p.is_alive():
                p.kill()
                p.join(STOP_SECONDS)
