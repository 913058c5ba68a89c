"""A helper process: one child that warms up while this process works, then runs one call.

:func:`start_helper` and :func:`in_background`; the warm-up imports and fills caches.

Started by the package's policy (:mod:`stringstab.parallel.policy`): forked only from a
single-threaded process, so start a helper *before* a pool or a thread; it dies with this
process.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from types import TracebackType
from typing import Any

from ..errors import StringStabError
from .policy import (
    become_child,
    check_single_threaded,
    in_daemon,
    signals_held,
    start_context,
    stop_processes,
)

__all__ = ["Helper", "in_background", "start_helper"]


def _message(e: BaseException) -> str:
    msg = str(e) if isinstance(e, StringStabError) else f"{type(e).__name__}: {e}"
    return msg.replace("\n", " ")


def _helper_main(conn: Any, other_end: Any, parent: int, warm: Callable[..., Any] | None,
                 warm_args: tuple[Any, ...]) -> None:
    """The helper child: warm up, wait for one call, run it, send back its result or error."""
    other_end.close()  # else the parent's closing its end would never reach us as EOF
    become_child(parent)
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
            stop_processes([self.proc])
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
    ctx = start_context(method, preload)
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
