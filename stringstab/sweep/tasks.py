"""What one sweep point computes: :func:`run_point`, the function every Dask task calls.

A point only calls the library: :func:`stringstab.rl.train` then
:func:`stringstab.rl.evaluate.evaluate` on the bundled test episodes (``train``),
:func:`stringstab.regions.region_map` (``region``, ``certify``).  Its artefacts (a training run
folder, a region map NPZ) go to ``<root>/points/<id>/``; the returned record holds the metrics,
the certificate summary, the artefact paths, the wall time, the worker and the process id.

An ordinary exception of a point becomes a record with ``status = "failed"`` and the error (a
retry would fail the same way); only the death of a worker is retried (by the scheduler, and by
the runner's ``retries``).

A running point can be stopped: Dask's cancel forgets a task but cannot stop the thread that
computes it, so :func:`interrupt_points` (run in each worker by ``Client.run``, see
:func:`stringstab.sweep.runner.cancel_points`) raises :class:`PointCancelled` in the threads
computing the named points, at their next Python instruction.  A point's thread is registered
only while :func:`run_point` computes it, and leaves the registry in a way that lets the
exception land inside :func:`run_point` only, never in Dask's own code around it.
"""

from __future__ import annotations

import ctypes
import os
import shutil
import socket
import threading
import time
import traceback
from collections.abc import Collection
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import StringStabError, show

__all__ = ["PointCancelled", "interrupt_points", "point_bytes", "refuse_points_too_big",
           "run_point"]

#: Metrics of a training point's evaluation copied into its record (IDL eqs 27-35).
EVAL_METRICS = ("TIT", "M_CI", "M_effi", "M_lss", "m_fss", "m_fss_sampled", "collisions",
                "collided_episodes", "share_m_p_below_1", "min_gap", "episodes")


class PointCancelled(BaseException):
    """Raised in a worker thread whose point was cancelled (:func:`interrupt_points`).

    A :class:`BaseException`, as :class:`KeyboardInterrupt` is: no ``except Exception`` of the
    library records it as a failed point; the cleanups (``finally``, atomic writes) still run.
    """


#: The threads computing a point in this process: thread id -> (sweep folder, point id).
_RUNNING: dict[int, tuple[str, str]] = {}
_RUNNING_LOCK = threading.Lock()


def interrupt_points(root: str, ids: Collection[str]) -> int:
    """Raise :class:`PointCancelled` in this process's threads computing points ``ids`` of ``root``.

    Meant to run in every worker through ``distributed.Client.run``; the exception lands at the
    thread's next Python instruction (a long call into C, a NumPy or torch kernel, finishes
    first).  Calling it again for a thread still computing is harmless.

    Parameters
    ----------
    root : str
        The sweep folder as passed to :func:`run_point` (absolute).
    ids : collection of str
        The point ids to stop.

    Returns
    -------
    int
        How many threads of this process were computing one of those points (each was sent
        the exception); 0 when none is.
    """
    wanted = set(ids)
    n = 0
    with _RUNNING_LOCK:
        for ident, (r, pid) in _RUNNING.items():
            if r == root and pid in wanted:
                ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(ident),
                                                           ctypes.py_object(PointCancelled))
                n += 1
    return n


def _settle() -> None:
    """A Python call: an exception sent to this thread earlier is raised at its start."""


def _worker_name() -> str:
    try:
        from distributed import get_worker

        return str(get_worker().address)
    except (ImportError, ValueError):
        return f"local:{socket.gethostname()}:{os.getpid()}"


def _limit_threads() -> None:
    """One thread per task: a worker process is one core of the sweep."""
    import sys

    if "torch" in sys.modules:
        sys.modules["torch"].set_num_threads(1)


def run_point(point: dict[str, Any], root: str) -> dict[str, Any]:
    """Compute one point (see :mod:`stringstab.sweep.spec` for the kinds) and return its record.

    Parameters
    ----------
    point : dict
        :meth:`stringstab.sweep.spec.Point.as_dict`.
    root : str
        The sweep's output folder (shared by every worker: a local folder, or a shared
        filesystem for a remote cluster).

    Returns
    -------
    dict
        ``id``, ``kind``, ``label``, ``varied``, ``status`` ("done" or "failed"), ``metrics``,
        ``artefacts`` (paths relative to ``root``), ``seconds``, ``worker``, ``pid``, and
        ``error`` / ``traceback`` for a failed point.
    """
    ident = threading.get_ident()
    cancelled = False
    try:
        with _RUNNING_LOCK:  # inside the try: an interrupt can only land where it is caught
            _RUNNING[ident] = (root, point["id"])
        rec = _compute(point, root)
    except PointCancelled:
        cancelled = True
    while True:  # leave the registry; an interrupt sent before that is raised (and caught) here
        try:
            with _RUNNING_LOCK:
                _RUNNING.pop(ident, None)
            _settle()
            break
        except PointCancelled:
            cancelled = True
    if cancelled:
        raise PointCancelled(f"point {point['id']} was cancelled")
    return rec


def _compute(point: dict[str, Any], root: str) -> dict[str, Any]:
    """:func:`run_point`'s record of one point (its thread is registered meanwhile)."""
    t0 = time.perf_counter()
    rec: dict[str, Any] = {"id": point["id"], "kind": point["kind"], "label": point["label"],
                           "varied": point["varied"], "worker": _worker_name(), "pid": os.getpid()}
    folder = Path(root) / "points" / point["id"]
    try:
        _limit_threads()
        fn = {"train": _train, "region": _region, "certify": _certify, "probe": _probe}[point["kind"]]
        metrics, artefacts = fn(point["settings"], folder)
        rec.update(status="done", metrics=metrics,
                   artefacts={k: os.path.relpath(v, root) for k, v in artefacts.items()})
    except Exception as e:  # recorded, not raised: a retry would fail the same way
        msg = str(e) if isinstance(e, StringStabError) else f"{type(e).__name__}: {e}"
        rec.update(status="failed", metrics={}, artefacts={}, error=msg.replace("\n", " "),
                   traceback=traceback.format_exc())
    rec["seconds"] = time.perf_counter() - t0
    return rec


# --------------------------------------------------------------------------- memory
def point_bytes(kind: str, settings: dict[str, Any]) -> float:
    """The peak memory one point of ``kind`` will need (:mod:`stringstab.memory`), bytes.

    ``region``: the map's n² (with ``fix``) or n³ points (:func:`stringstab.memory.grid_bytes`,
    the estimate ``stringstab region`` refuses with); ``certify``: n³ points, twice with a sample
    time or an interval (the continuous map is held beside it); ``train``: the trainer, its
    ``num_envs`` environments and its ``buffer_size`` replay buffer
    (:func:`stringstab.memory.training_bytes`, as ``stringstab train``); ``probe``: nothing.

    Parameters
    ----------
    kind : str
        The point's kind (:data:`stringstab.sweep.spec.KINDS`).
    settings : dict
        Its resolved settings (:attr:`stringstab.sweep.spec.Point.settings`).

    Returns
    -------
    float
        Bytes.

    Examples
    --------
    >>> from stringstab.memory import human_bytes
    >>> human_bytes(point_bytes("certify", {"n": 100_000, "sample_time": None, "tau": 0.1,
    ...                                     "delta": 0.2, "headway": 1.1}))
    '532.9 PiB'
    """
    from ..memory import grid_bytes, training_bytes

    if kind == "region":
        return grid_bytes(float(settings["n"]) ** (2 if settings.get("fix") is not None else 3))
    if kind == "certify":
        special = settings.get("sample_time") is not None or any(
            isinstance(settings.get(k), str) for k in ("tau", "delta", "headway"))
        return grid_bytes((2 if special else 1) * float(settings["n"]) ** 3)
    if kind == "train":
        return training_bytes(int(settings["num_envs"]), int(settings["buffer_size"]))
    return 0.0


def refuse_points_too_big(points: Any, per_worker: float, where: str) -> None:
    """Refuse a sweep with a point whose estimated memory exceeds what a worker has.

    A Dask worker that outgrows its memory is killed by its nanny and the task retried on
    the next worker until all are lost (``KilledWorker``); this refuses the sweep before
    anything is dispatched, naming the largest point, its estimate and what a worker has.

    Parameters
    ----------
    points : sequence of Point
        The spec's points (:attr:`stringstab.sweep.spec.SweepSpec.points`).
    per_worker : float
        Bytes one worker may use.
    where : str
        What ``per_worker`` is, for the message (e.g. ``"each of the 2 local workers"``).

    Raises
    ------
    StringStabError
        When some point's estimate exceeds ``per_worker``; with the largest grid that fits
        for ``region``/``certify`` points.
    """
    from ..memory import grid_fit, human_bytes

    need = [(point_bytes(p.kind, p.settings), p) for p in points]
    if not need:
        return
    nbytes, worst = max(need, key=lambda x: x[0])
    if nbytes <= per_worker:
        return
    what = ", ".join(f"{k}={show(v)}" for k, v in worst.varied.items()) or "the base settings"
    if worst.kind in ("region", "certify"):
        dims = 2 if worst.kind == "region" and worst.settings.get("fix") is not None else 3
        hint = f"expected n <= {grid_fit(per_worker, dims)} for this worker memory"
    elif worst.kind == "train":
        hint = "expected a smaller buffer_size or num_envs"
    else:
        hint = "expected a smaller point"
    raise StringStabError(
        f"sweep point {worst.id} ({worst.kind}, {what}) needs about {human_bytes(nbytes)} of "
        f"memory; {where} has {human_bytes(per_worker)}; {hint} (or more memory per worker)")


# --------------------------------------------------------------------------- kinds
def _train(s: dict[str, Any], folder: Path) -> tuple[dict[str, Any], dict[str, Path]]:
    """Train (resuming the point's own checkpoint after a killed attempt), then evaluate."""
    from ..rl import config_from_dict, train
    from ..rl.episodes import default_leaders
    from ..rl.evaluate import evaluate

    cfg = config_from_dict({k: v for k, v in s.items() if k != "paper"}, source="sweep point")
    run = folder / "run"
    resume = (run / "run.json").is_file() and (run / "checkpoint" / "latest.json").is_file()
    if run.exists() and not resume:  # an attempt killed before its first checkpoint
        shutil.rmtree(run)
    res = train(cfg, out=run, resume=resume, progress=False)
    leaders = list(default_leaders("test", seconds=cfg.episode_seconds, dt=cfg.dt))
    ev = evaluate(res.policy, leaders, tau=cfg.tau, delta=cfg.delta, headway=cfg.headway)
    m = {k: ev.summary.get(k) for k in EVAL_METRICS}
    returns = [float(e["return"]) for e in res.episodes]
    m.update(steps=res.steps, train_episodes=len(res.episodes), stopped_by=res.stopped_by,
             final_rolling_return=float(np.mean(returns[-10:])) if returns else None,
             train_seconds=res.seconds, resumed=resume)
    return m, {"run": run, "train_log": run / "train_log.csv"}


def _grid(s: dict[str, Any], names: list[str]) -> dict[str, Any]:
    lo, hi = s["range"]
    return {g: np.linspace(lo, hi, s["n"]) for g in names}


def _region(s: dict[str, Any], folder: Path) -> tuple[dict[str, Any], dict[str, Path]]:
    """A region map (2-D with ``fix``, else 3-D); its NPZ and the verdict shares."""
    from ..io import check_output_dir
    from ..regions import GAIN_NAMES, region_map

    if s["fix"] is not None:
        g, _, v = s["fix"].partition("=")
        axes, fixed = _grid(s, [s["x"], s["y"]]), {g.strip(): float(v)}
    else:
        third = next(g for g in GAIN_NAMES if g not in (s["x"], s["y"]))
        axes, fixed = _grid(s, [s["x"], s["y"], third]), None
    rmap = region_map(axes, fixed, tau=s["tau"], delta=s["delta"], headway=s["headway"],
                      sample_time=s["sample_time"], methods=s["methods"], workers=1,
                      progress=False)
    check_output_dir(folder, what="point folder")
    folder.mkdir(parents=True, exist_ok=True)
    npz = rmap.save_npz(folder / "region.npz")
    shares = rmap.verdict_shares()
    m: dict[str, Any] = {"n_points": rmap.size, "certified_share": shares.get("exact", {}).get("certified")}
    for method, d in shares.items():
        for lab, v in d.items():
            m[f"{method}_{lab}"] = v
    return m, {"npz": npz}


def _certify(s: dict[str, Any], folder: Path) -> tuple[dict[str, Any], dict[str, Path]]:
    """Certified share of an n³ gain grid; beside a sampled or robust one, the continuous share."""
    from ..params import Box, parameter_model
    from ..regions import region_map

    axes = _grid(s, ["k_x", "k_v", "k_a"])
    p = parameter_model(s["tau"], s["delta"], s["headway"])
    special = s["sample_time"] is not None or isinstance(p, Box)
    rmap = region_map(axes, None, tau=s["tau"], delta=s["delta"], headway=s["headway"],
                      sample_time=s["sample_time"], methods="exact", workers=1, progress=False)
    ok = rmap.stable("exact")
    m: dict[str, Any] = {"n_points": int(ok.size), "certified_share": float(ok.mean()),
                         "inconclusive_share": rmap.verdict_shares()["exact"].get("inconclusive")}
    if special:
        cont = region_map(axes, None, tau=_nominal(s["tau"]), delta=_nominal(s["delta"]),
                          headway=_nominal(s["headway"]), methods="exact", workers=1,
                          progress=False).stable("exact")
        m["continuous_share"] = float(cont.mean())
        m["lost_share"] = float((cont & ~ok).sum() / max(int(cont.sum()), 1))
    return m, {}


def _nominal(v: Any) -> float:
    """The midpoint of an interval ``"lo:hi"`` (or the number itself)."""
    if isinstance(v, str):
        lo, _, hi = v.partition(":")
        return 0.5 * (float(lo) + float(hi))
    return float(v)


def _probe(s: dict[str, Any], folder: Path) -> tuple[dict[str, Any], dict[str, Path]]:
    """Sleep ``seconds`` (in short naps), then fail if asked: for cluster checks and overhead."""
    end = time.perf_counter() + float(s["seconds"])
    while time.perf_counter() < end:
        time.sleep(min(0.05, max(end - time.perf_counter(), 0.0)))
    if s["fail"]:
        raise StringStabError("probe point asked to fail (fail = true)")
    return {"slept": float(s["seconds"]), "seed": s["seed"]}, {}
