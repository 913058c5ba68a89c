"""Worker processes, started one safe way: the package's one start-method policy.

Every process the package starts for its own work (a region map's pool, the process that
writes a map's figures) is started here, by one policy (issue 29;
:mod:`stringstab.parallel.policy`): forked only from a single-threaded process (a forked
child inherits the locks other threads hold and can hang for ever), otherwise by a
forkserver; every child ignores Ctrl-C, ends on SIGTERM and dies with its parent.

* :mod:`~stringstab.parallel.policy` — the start method, the signals held over a fork, a
  child's signals and lifetime;
* :mod:`~stringstab.parallel.pool` — :func:`process_pool` (a :class:`WorkerPool`: workers
  with a pipe each, so that a worker dying half-way through sending its result is an error,
  never a wait for ever) and :func:`map_processes`;
* :mod:`~stringstab.parallel.helper` — :func:`start_helper`: one child that warms up while
  this process works, then runs one call; :func:`in_background`.

Programs that start other programs (``subprocess``: SUMO) are not concerned: the child
replaces itself with the new program at once and runs no Python code.
"""

from .helper import Helper, in_background, start_helper
from .policy import (
    ENV,
    HELD_SIGNALS,
    STOP_SECONDS,
    ThreadsRunning,
    become_child,
    check_single_threaded,
    cpu_count,
    die_with_parent,
    in_daemon,
    signals_held,
    start_context,
    start_method,
    stop_processes,
)
from .pool import RemoteTraceback, WorkerPool, map_processes, process_pool

__all__ = ["ENV", "HELD_SIGNALS", "STOP_SECONDS", "Helper", "RemoteTraceback", "ThreadsRunning",
           "WorkerPool", "become_child", "check_single_threaded", "cpu_count", "die_with_parent",
           "in_background", "in_daemon", "map_processes", "process_pool", "signals_held",
           "start_context", "start_helper", "start_method", "stop_processes"]
