"""A Dask client: a local cluster on 127.0.0.1 started and closed here, or a remote scheduler.

:func:`dask_client` is a context manager: without an address it starts a
:class:`distributed.LocalCluster` of ``workers`` processes with one thread each (torch and the
BLAS libraries limited to one thread in every worker), listening on 127.0.0.1 only (the
dashboard too, on a free port; it needs ``bokeh``); a script that uses it needs the
``if __name__ == "__main__":`` guard (the workers are spawned processes); with an address (``tcp://host:8786``) it connects to that scheduler.  Whatever it
started is closed when the ``with`` block ends — normally, on an error or on Ctrl-C.
"""

from __future__ import annotations

import contextlib
import logging
import re
from collections.abc import Iterator
from typing import Any

from ..errors import StringStabError

__all__ = ["THREAD_ENV", "dashboard_address", "dask_client"]

#: Environment of every local worker: one thread for OpenMP, BLAS and torch.
THREAD_ENV = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
              "TORCH_NUM_THREADS": "1"}
_ADDRESS = re.compile(r"^(tcp|tls|inproc|ws|wss)://[^\s/]+$")


def _import() -> Any:
    try:
        import distributed
    except ImportError as e:
        raise StringStabError("a sweep needs Dask: pip install 'stringstab[dask]' (dask and "
                              "distributed)") from e
    return distributed


@contextlib.contextmanager
def dask_client(scheduler: str | None = None, workers: int | None = None) -> Iterator[Any]:
    """A :class:`distributed.Client` for the duration of a ``with`` block.

    Parameters
    ----------
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://HOST:PORT``).  None: start a local cluster.
    workers : int, optional
        Worker processes of the local cluster (default: the cores this process may use).

    Yields
    ------
    distributed.Client

    Raises
    ------
    StringStabError
        On a malformed address, a scheduler that does not answer, workers < 1 or Dask missing.
    """
    distributed = _import()
    if scheduler is not None:
        if workers is not None:
            raise StringStabError("--workers sizes the local cluster; with --scheduler the remote "
                                  "cluster's workers are used (got both)")
        if not _ADDRESS.match(scheduler):
            raise StringStabError(f"--scheduler must be an address like tcp://HOST:8786; got {scheduler!r}")
        try:
            client = distributed.Client(scheduler, timeout="10s")
        except OSError as e:
            raise StringStabError(f"--scheduler {scheduler}: no Dask scheduler answered ({e})") from e
        with client:
            yield client
        return
    from ..parallel import cpu_count

    n = cpu_count() if workers is None else int(workers)
    if n < 1:
        raise StringStabError(f"--workers must be >= 1; got {workers!r}")
    # the scheduler's HTTP server (the dashboard with bokeh; health and metrics without) always
    # runs: on 127.0.0.1 and a free port, never the default :8787 on every interface
    # Dask's nannies set MALLOC_TRIM_THRESHOLD_=65536 in every worker by default, which turns
    # off glibc's dynamic mmap threshold: every large NumPy temporary is then a fresh mmap, and
    # the certificates ran 2.4x slower in a worker than in this process (analysis/bench_sweep.py)
    import dask

    with dask.config.set({"distributed.nanny.pre-spawn-environ": dict(THREAD_ENV)}):
        cluster = distributed.LocalCluster(
            n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
            dashboard_address="127.0.0.1:0", env=dict(THREAD_ENV), silence_logs=logging.ERROR)
    with cluster, distributed.Client(cluster) as client:
        yield client


def dashboard_address(client: Any) -> str | None:
    """The dashboard's address, or None when the scheduler serves none.

    Parameters
    ----------
    client : distributed.Client

    Returns
    -------
    str or None
    """
    try:
        services = client.scheduler_info().get("services", {})
    except Exception:
        return None
    if "dashboard" not in services:
        return None
    return str(client.dashboard_link)
