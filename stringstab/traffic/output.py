"""Writing a simulated run: trajectories (NPZ or CSV), a metrics JSON and figures.

Every file is written all-or-nothing: :func:`save_trajectories` through a temporary file,
:func:`write_run` through an :class:`~stringstab.io.OutputDir` that owns the names in
:data:`RUN_FILES`, so a run into a folder of an earlier run replaces its files (and removes
those this run does not write) or, if it fails, leaves them as they were.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Literal

import numpy as np

from ..constants import TTC_STAR
from ..errors import StringStabError, show
from ..io import OutputDir, atomic_path, dumps_json, to_plain, write_results
from .result import PlatoonResult

__all__ = ["RUN_FILES", "UNITS", "radio_summary", "run_document", "save_trajectories", "write_run"]

Format = Literal["npz", "csv", "parquet"]

#: The unit of each metric of ``metrics.json`` (SI; "" for ratios and counts).
UNITS: dict[str, str] = {
    "m_p": "", "max_m_p": "", "M_lss": "", "collisions": "", "collided_vehicles": "",
    "min_gap": "m", "TIT": "s^2", "TIT_per_vehicle": "s^2", "M_CI": "m^2/s^6", "M_effi": "s",
    "min_ttc": "s", "min_headway": "s", "ttc_star": "s", "m_fss": "",
}

#: Every file :func:`write_run` may write (its folder holds these and nothing of another run).
RUN_FILES: tuple[str, ...] = ("trajectories.npz", "trajectories.csv", "trajectories.parquet",
                              "metrics.json", "platoon.png", "damping.png", "report.md",
                              "report.html")


def run_document(result: PlatoonResult, *, leader: Any, controller: Any, spec: str | None = None,
                 ttc_star: float = TTC_STAR, warnings: Sequence[str] = ()) -> dict[str, Any]:
    """The ``metrics.json`` document of a run: its settings, the IDL metrics and a certificate.

    ``certificate`` holds the exact certificate (:func:`stringstab.certify.api.certify`) of
    the controller's gains when they are fixed and of the eq-4 form, else None.

    Parameters
    ----------
    result : PlatoonResult
        The run.
    leader : Trajectory
        Its leader.
    controller : Controller
        Its controller.
    spec : str, optional
        How the leader was named (e.g. on the command line).
    ttc_star : float
        TTC* of the safety metrics, s.
    warnings : sequence of str
        Warnings about the run (e.g. from :func:`~stringstab.traffic.limits.check_leader`).

    Returns
    -------
    dict
        The JSON-serialisable document written as ``metrics.json``.
    """
    metrics = result.metrics(ttc_star=ttc_star)
    doc = {
        "run": {"leader": spec if spec is not None else leader.name, "leader_name": leader.name,
                "followers": result.n_followers, "duration_s": leader.duration, **result.params},
        **metrics,
        "units": {k: v for k, v in UNITS.items() if k in metrics},
        "certificate": _certificate(controller, result.params),
        "warnings": list(warnings),
    }
    if result.radio is not None:
        doc["radio"] = radio_summary(result)
    return doc


def radio_summary(result: PlatoonResult) -> dict[str, Any]:
    """What the radio did in a run (:mod:`stringstab.traffic.radio`), JSON-ready.

    Parameters
    ----------
    result : PlatoonResult
        A run with a radio (``result.radio`` not None).

    Returns
    -------
    dict
        Per follower (nested per platoon for a batch): ``messages_received``,
        ``messages_lost``, ``fallback_time`` (s); and pooled: ``loss_share`` (lost / due
        messages) and ``fallback_share`` (time in fallback / (followers × run time)).
    """
    r = result.radio
    assert r is not None
    rec, lost = np.asarray(r["messages_received"]), np.asarray(r["messages_lost"])
    fb = np.asarray(r["fallback_time"], dtype=np.float64)
    due = int(rec.sum() + lost.sum())
    span = result.t.size * result.dt * rec.size
    return {"messages_received": rec.tolist(), "messages_lost": lost.tolist(),
            "fallback_time": fb.round(6).tolist(),
            "loss_share": float(lost.sum() / due) if due else None,
            "fallback_share": float(fb.sum() / span) if span else None}


def _certificate(controller: Any, params: dict[str, Any]) -> dict[str, Any] | None:
    K = controller.gains(None) if not controller.time_varying else None
    taus = np.unique(np.asarray(params.get("tau"), dtype=np.float64))
    thetas = np.unique(np.asarray(params.get("reaction_delay", 0.0), dtype=np.float64))
    if K is None or controller.headway is None or np.ndim(K) != 1 or taus.size != 1 or thetas.size != 1:
        return None
    from ..certify.api import certify

    theta = float(thetas[0])
    c = certify(float(K[0]), float(K[1]), float(K[2]), tau=float(taus[0]),
                delta=params["delta"], headway=controller.headway, reaction_delay=theta)
    out = {"k_x": float(K[0]), "k_v": float(K[1]), "k_a": float(K[2]), "verdict": c.verdict,
           "sup_gain": c.sup_gain, "peak_omega": c.peak_omega}
    if theta:
        out["reaction_delay"] = theta
    if params.get("radio") is not None or params.get("sensors") is not None:
        out["scope"] = ("the continuous-time loop, with the acceleration received continuously and "
                        "exact measurements; messages every period P are the multi-rate certificate's "
                        "(issue 26); message loss, switching to the fallback and sensor noise are "
                        "covered by no certificate")
    return out


def _trajectory_columns(result: PlatoonResult, digits: int | None = 6) -> dict[str, np.ndarray]:
    """One row per (time, vehicle); vehicle 0 (the leader) has no gap, headway or command.

    Values are rounded to ``digits`` decimals (None: full precision).
    """
    assert result.speed is not None and result.position is not None and result.accel is not None
    n_veh, T = result.speed.shape
    gap, hw = result.gap, result.headway
    cmd = result.command if result.command is not None else np.full_like(gap, np.nan)

    def followers(a: np.ndarray) -> np.ndarray:  # (N, T) -> (T, N + 1) with NaN for the leader
        out = np.full((T, n_veh), np.nan)
        out[:, 1:] = a.T
        return out.ravel()

    def r(a: np.ndarray) -> np.ndarray:
        return a if digits is None else np.round(a, digits)

    return {
        "t": np.repeat(np.round(result.t, 9), n_veh),
        "vehicle": np.tile(np.arange(n_veh), T),
        "position": r(result.position.T.ravel()),
        "speed": r(result.speed.T.ravel()),
        "accel": r(result.accel.T.ravel()),
        "gap": r(followers(gap)),
        "headway": r(followers(hw)),
        "command": r(followers(cmd)),
    }


def save_trajectories(result: PlatoonResult, path: str | Path, *, fmt: Format = "npz") -> Path:
    """Save a single-platoon run's trajectories (atomically: complete or absent).

    ``npz``: arrays ``t`` (T,), ``position``, ``speed``, ``accel`` (N + 1, T; row 0 the
    leader), ``gap``, ``headway``, ``command`` (N, T), ``gains`` if any, and ``params`` (JSON).
    ``csv``: one row per (time, vehicle) with columns ``t, vehicle, position, speed, accel,
    gap, headway, command`` (vehicle 0 is the leader; its gap, headway and command are empty;
    values rounded to 1e-6 in SI units: s, m, m/s, m/s², s, m/s²).  ``parquet``: the same
    columns at full precision (the leader's empty cells are NaN), the run's parameters as
    JSON in the file metadata.

    Parameters
    ----------
    result : PlatoonResult
        One platoon's run, recorded with ``record=True`` (not a batch).
    path : str or Path
        The file to write.
    fmt : {"npz", "csv", "parquet"}
        The file format.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    StringStabError
        If the run was not recorded, is a batch, or ``fmt`` is unknown.
    """
    if result.speed is None or result.position is None or result.accel is None:
        raise StringStabError("save_trajectories needs a run recorded with record=True")
    if result.speed.ndim != 2:
        raise StringStabError("save_trajectories saves one platoon; select one from the batch first")
    if fmt not in ("npz", "csv", "parquet"):
        raise StringStabError(f"trajectory format must be 'npz', 'csv' or 'parquet'; got {show(fmt)}")
    p = Path(path)
    if fmt == "csv":
        write_results(_trajectory_columns(result), p, "csv", what="trajectories")
        return p
    if fmt == "parquet":
        write_results(_trajectory_columns(result, None), p, "parquet", params=result.params,
                      what="trajectories")
        return p
    gap, hw = result.gap, result.headway
    cmd = result.command if result.command is not None else np.full_like(gap, np.nan)
    arrays: dict[str, Any] = dict(t=result.t, position=result.position, speed=result.speed,
                                  accel=result.accel, gap=gap, headway=hw, command=cmd,
                                  params=np.array(json.dumps(to_plain(result.params))))
    if result.gains is not None:
        arrays["gains"] = result.gains
    with atomic_path(p, what="trajectories") as tmp:
        np.savez_compressed(tmp, **arrays)
    return p


def _write(result: PlatoonResult, out: OutputDir, metrics: dict[str, Any], fmt: Format,
           figures: bool, title: str | None) -> dict[str, str]:
    files: dict[str, str] = {}
    name = f"trajectories.{fmt}"
    save_trajectories(result, out.path(name), fmt=fmt)
    files["trajectories"] = name
    if figures:
        from matplotlib.figure import Figure

        from ..plots.traffic import plot_damping_ratios, plot_platoon

        fig, _ = plot_platoon(result, title=title,
                              fig=Figure(figsize=(9, 6.5), layout="constrained"))
        fig.savefig(out.path("platoon.png"), dpi=110)
        fig = Figure(figsize=(6, 3.5), layout="constrained")
        ax = fig.subplots()
        plot_damping_ratios(result.damping_ratios, ax=ax)
        ax.set_title("acceleration L2 damping ratio per follower (IDL eq 29)"
                     + (f"\n{title}" if title else ""), fontsize=10)
        fig.savefig(out.path("damping.png"), dpi=110)
        files["figure_platoon"] = "platoon.png"
        files["figure_damping"] = "damping.png"
    files["metrics"] = "metrics.json"
    out.write_text("metrics.json", dumps_json({**metrics, "files": dict(files)}))
    return files


def write_run(result: PlatoonResult, out: str | Path | OutputDir, *, metrics: dict[str, Any],
              fmt: Format = "npz", figures: bool = True, title: str | None = None) -> dict[str, str]:
    """Write ``trajectories.{npz,csv}``, ``metrics.json`` and (optionally) the figures.

    Figures: ``platoon.png`` (speed, acceleration, spacing and headway of every vehicle,
    like the IDL paper's Figs 7-8) and ``damping.png`` (m_p per follower).

    Parameters
    ----------
    result : PlatoonResult
        The simulated run (:func:`~stringstab.traffic.simulate`).
    out : path or OutputDir
        The folder: written all-or-nothing, replacing the files of an earlier run (see
        :data:`RUN_FILES`); or an open :class:`~stringstab.io.OutputDir` (e.g. checked by a
        command before it simulated) that the caller commits.
    metrics : dict
        The ``metrics.json`` document (:func:`run_document`).
    fmt : {"npz", "csv"}
        The trajectories' format.
    figures : bool
        Also draw ``platoon.png`` and ``damping.png``.
    title : str, optional
        The figures' title.

    Returns
    -------
    dict
        ``{kind: file name}`` of everything written under ``out``.
    """
    if fmt not in ("npz", "csv", "parquet"):
        raise StringStabError(f"trajectory format must be 'npz', 'csv' or 'parquet'; got {show(fmt)}")
    if isinstance(out, OutputDir):
        return _write(result, out, metrics, fmt, figures, title)
    with OutputDir(out, command="simulate", owns=RUN_FILES) as d:
        return _write(result, d, metrics, fmt, figures, title)
