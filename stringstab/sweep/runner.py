"""Running a sweep on Dask: one task per point, each result written the moment it finishes.

:func:`run_sweep` submits every point not finished before (a point is finished when
``DIR/points/<id>.json`` says ``"status": "done"``) as a task of :func:`~stringstab.sweep.tasks.run_point`
and writes each record atomically (:func:`stringstab.io.atomic_write_text`) as the tasks
complete, in completion order (:func:`distributed.as_completed`).  So a sweep interrupted at any
moment — Ctrl-C, a killed process, a lost machine — loses only the points in flight, and the
same command resumes it.  A point that raises is recorded as failed with its error and the
others go on (a failed point is tried again by the next run); a worker that dies mid-task has
its task rescheduled on another worker by the scheduler, and ``retries`` more times after the
scheduler gives up on it (``KilledWorker``).  At the end the table of all the spec's points
and the study's report are written (:mod:`stringstab.sweep.report`).

Interrupted (Ctrl-C, SIGTERM, an error), :func:`cancel_points` cancels the sweep's tasks on the
scheduler (``Client.cancel(force=True)``: none not yet started will start) and stops the ones
running in the workers (:func:`~stringstab.sweep.tasks.interrupt_points`): a cancelled Dask
task is forgotten by the scheduler but its thread would compute on, which on an external
scheduler (whose workers outlive this client) kept the workers busy for as long as the points
take.
"""

from __future__ import annotations

import contextlib
import logging
import os
import sys
import time
from collections.abc import Callable, Iterator
from typing import Any

from ..errors import StringStabError
from ..io import atomic_write_text, check_output_dir, claim_folder, dumps_json, write_manifest
from ..progress import Progress
from .records import POINT_FORMAT, read_records, record_path
from .spec import SweepSpec
from .tasks import interrupt_points, refuse_points_too_big, run_point

__all__ = ["cancel_points", "run_sweep"]

#: How long :func:`cancel_points` waits for the running points to stop, s.
STOP_WAIT = 10.0

class _Progress:
    """A tqdm bar on a terminal; otherwise a log line per finished point, with the time left.

    The bar is :class:`stringstab.progress.Progress`; the lines come at most every ``every`` s,
    and for every failure.
    """

    def __init__(self, total: int, done: int, log: Callable[[str], None], bar: bool | None,
                 every: float = 5.0) -> None:
        self.total, self.n, self.log, self.every = total, done, log, every
        self.failed = 0
        self.t0 = self.last = time.perf_counter()
        if bar is None:
            bar = sys.stderr.isatty()
        self.p = Progress(total, "sweep", unit="point", initial=done, enabled=bool(bar), tty=bool(bar))

    @property
    def bar(self) -> Any:
        return self.p.bar

    def update(self, rec: dict[str, Any]) -> None:
        self.n += 1
        self.failed += rec["status"] != "done"
        self.p.update(1)
        now = time.perf_counter()
        if self.bar is not None:
            self.bar.set_postfix(failed=self.failed)
            if rec["status"] != "done":
                self.bar.write(f"point {rec['id']} failed: {rec.get('error')}")
            return
        first = self.last == self.t0
        if first or rec["status"] != "done" or now - self.last >= self.every or self.n == self.total:
            what = "done" if rec["status"] == "done" else f"FAILED ({rec.get('error')})"
            name = rec["label"] or " ".join(f"{k}={v}" for k, v in rec.get("varied", {}).items())
            self.log(f"[{self.n}/{self.total}] point {rec['id']} {name} {what} in "
                     f"{rec['seconds']:.1f} s on {rec['worker']}; {self.failed} failed, "
                     f"{self.p.timing(now)}")
            self.last = now

    def close(self) -> None:
        self.p.close()


def _lost_record(point: dict[str, Any], error: str) -> dict[str, Any]:
    return {"id": point["id"], "kind": point["kind"], "label": point["label"],
            "varied": point["varied"], "status": "failed", "metrics": {}, "artefacts": {},
            "error": error, "seconds": float("nan"), "worker": None, "pid": None}


@contextlib.contextmanager
def _quiet_scheduler() -> Iterator[None]:
    """An in-process scheduler (a local cluster) does not log the workers a Ctrl-C already ended.

    A terminal's Ctrl-C reaches the local cluster's workers too; the scheduler then logs an
    ERROR for each worker ``Client.run`` cannot reach, which is expected here.
    """
    logger = logging.getLogger("distributed.scheduler")
    level = logger.level
    logger.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        logger.setLevel(level)


def cancel_points(client: Any, futures: list[Any], root: str, *,
                  log: Callable[[str], None] = print, wait: float = STOP_WAIT) -> int:
    """Cancel a sweep's tasks on the scheduler and stop those running; see the module.

    Parameters
    ----------
    client : distributed.Client
        The client that submitted them.
    futures : list of distributed.Future
        The sweep's futures (those already finished are left alone).
    root : str
        The sweep folder as given to :func:`~stringstab.sweep.tasks.run_point` (absolute).
    log : callable
        Receives one line if some point still runs after ``wait`` seconds.
    wait : float
        How long to wait for the running points to stop, s.

    Returns
    -------
    int
        How many points were still computing in a worker when this returned (0: the workers
        are free of this sweep).
    """
    pending = [f for f in futures if not f.done()]
    if not pending:
        return 0
    client.cancel(pending, force=True)
    ids = sorted({str(f.key).removeprefix("stringstab-point-") for f in pending})
    end = time.monotonic() + wait
    running = 0
    while True:
        try:
            with _quiet_scheduler():
                counts = client.run(interrupt_points, root, ids, on_error="return")
        except Exception as e:  # the scheduler is gone: nothing more to stop from here
            log(f"sweep: could not reach the workers to stop the running points ({e})")
            return 0
        running = sum(c for c in counts.values() if isinstance(c, int))
        if running == 0 or time.monotonic() > end:
            break
        time.sleep(0.1)
    if running:
        log(f"sweep: {running} point(s) still computing in the workers after {wait:g} s (a long "
            "call into C); they stop at their next Python instruction")
    return running


def run_sweep(spec: SweepSpec, out: str | os.PathLike[str], *, client: Any, retries: int = 2,
              progress: bool | None = None, log: Callable[[str], None] = print) -> dict[str, Any]:
    """Run the points of ``spec`` not finished in ``out`` on a Dask ``client``; see the module.

    Parameters
    ----------
    spec : SweepSpec
        The loaded spec (:func:`stringstab.sweep.load_spec`).
    out : path
        The sweep folder: ``points/<id>.json`` (records), ``points/<id>/`` (artefacts),
        ``spec.toml``, ``results.csv``, ``results.parquet`` and ``report/``.
    client : distributed.Client
        Where the tasks run (:func:`stringstab.sweep.dask_client`).
    retries : int
        Extra attempts of a task whose workers died (``distributed.Client.submit(retries=)``).
    progress : bool, optional
        tqdm bar (default: when standard error is a terminal); else progress lines via ``log``.
    log : callable
        Receives the progress lines.

    Returns
    -------
    dict
        ``points``, ``skipped`` (finished before), ``done``, ``failed``, ``seconds``, ``files``.

    Raises
    ------
    StringStabError
        When ``out`` cannot be written or holds another command's outputs, or a point needs
        more memory than the largest worker's limit (:func:`~stringstab.sweep.tasks.point_bytes`;
        nothing dispatched).  KeyboardInterrupt passes through after the tasks in flight are
        cancelled (the finished points are already on disk).
    """
    from distributed import as_completed

    from .report import write_outputs

    if isinstance(retries, bool) or not isinstance(retries, int) or retries < 0:
        raise StringStabError(f"retries must be an integer >= 0; got {retries!r}")
    root = check_output_dir(out, what="--out")
    claim_folder(root, command="sweep", what="--out")
    before = read_records(root, spec)
    skipped = [pid for pid, r in before.items() if r.get("status") == "done"]
    todo = [p for p in spec.points if p.id not in set(skipped)]
    workers = client.scheduler_info().get("workers", {})
    n_workers = len(workers)
    limits = [float(w["memory_limit"]) for w in workers.values() if w.get("memory_limit")]
    if limits:  # before anything is dispatched (or written): a point no worker can hold
        refuse_points_too_big(todo, max(limits), f"the largest of the {n_workers} Dask workers")
    (root / "points").mkdir(parents=True, exist_ok=True)
    atomic_write_text(root / "spec.toml", spec.text)
    write_manifest(root, command="sweep", what="--out")
    t0 = time.perf_counter()
    log(f"sweep {spec.name}: {len(spec)} points ({spec.kind}); {len(skipped)} finished before "
        f"(skipped), {len(todo)} to run on {n_workers} workers")
    bar = _Progress(len(spec), len(skipped), log, progress)
    root_abs = str(root.resolve())
    futures = {}
    by_key: dict[str, dict[str, Any]] = {}
    done = failed = 0
    try:
        for p in todo:
            d = p.as_dict()
            fut = client.submit(run_point, d, root_abs, key=f"stringstab-point-{p.id}", pure=False,
                                retries=retries)
            futures[fut.key] = fut
            by_key[fut.key] = {**d, "settings": p.settings}
        for fut in as_completed(list(futures.values())):
            point = by_key[fut.key]
            if fut.status == "finished":
                rec = fut.result()
            else:  # e.g. KilledWorker after every retry, or cancelled: the task never returned
                try:
                    exc = fut.exception()
                    why = f"{type(exc).__name__}: {exc}"
                except BaseException as e:  # a cancelled future raises here
                    if isinstance(e, KeyboardInterrupt):
                        raise
                    why = f"{type(e).__name__}: {e}"
                rec = _lost_record(point, why.replace("\n", " "))
            rec = {"format": POINT_FORMAT, **rec, "settings": point["settings"]}
            atomic_write_text(record_path(root, point["id"]), dumps_json(rec))
            fut.release()
            done += rec["status"] == "done"
            failed += rec["status"] != "done"
            bar.update(rec)
    except BaseException:
        cancel_points(client, list(futures.values()), root_abs, log=log)
        raise
    finally:
        bar.close()
    files = write_outputs(spec, root)
    return {"points": len(spec), "skipped": len(skipped), "done": done, "failed": failed,
            "seconds": time.perf_counter() - t0, "files": files}
