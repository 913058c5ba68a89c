"""Writing a simulated run: trajectories (NPZ or CSV), a metrics JSON and figures."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any, Literal

import numpy as np

from ..errors import StringStabError
from .platoon import PlatoonResult

__all__ = ["save_trajectories", "write_run"]

Format = Literal["npz", "csv"]


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, np.generic):
        return _jsonable(x.item())
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def save_trajectories(result: PlatoonResult, path: str | Path, *, fmt: Format = "npz") -> Path:
    """Save a single-platoon run's trajectories.

    ``npz``: arrays ``t`` (T,), ``position``, ``speed``, ``accel`` (N + 1, T; row 0 the
    leader), ``gap``, ``headway``, ``command`` (N, T), ``gains`` if any, and ``params`` (JSON).
    ``csv``: one row per (time, vehicle) with columns ``t, vehicle, position, speed, accel,
    gap, headway, command`` (vehicle 0 is the leader; its gap, headway and command are empty).

    Returns
    -------
    Path
        The file written.
    """
    if result.speed is None or result.position is None or result.accel is None:
        raise StringStabError("save_trajectories needs a run recorded with record=True")
    if result.speed.ndim != 2:
        raise StringStabError("save_trajectories saves one platoon; select one from the batch first")
    p = Path(path)
    gap, hw = result.gap, result.headway
    cmd = result.command if result.command is not None else np.full_like(gap, np.nan)
    if fmt == "npz":
        arrays: dict[str, Any] = dict(t=result.t, position=result.position, speed=result.speed,
                                      accel=result.accel, gap=gap, headway=hw, command=cmd,
                                      params=np.array(json.dumps(_jsonable(result.params))))
        if result.gains is not None:
            arrays["gains"] = result.gains
        np.savez_compressed(p, **arrays)
    elif fmt == "csv":
        n_veh, T = result.speed.shape
        with p.open("w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["t", "vehicle", "position", "speed", "accel", "gap", "headway", "command"])
            for k in range(T):
                t = f"{result.t[k]:.6g}"
                for i in range(n_veh):
                    extra = ["", "", ""] if i == 0 else [
                        f"{gap[i - 1, k]:.6f}",
                        "" if not np.isfinite(hw[i - 1, k]) else f"{hw[i - 1, k]:.6f}",
                        f"{cmd[i - 1, k]:.6f}",
                    ]
                    w.writerow([t, i, f"{result.position[i, k]:.6f}", f"{result.speed[i, k]:.6f}",
                                f"{result.accel[i, k]:.6f}", *extra])
    else:
        raise StringStabError(f"trajectory format must be 'npz' or 'csv'; got {fmt!r}")
    return p


def write_run(result: PlatoonResult, out: str | Path, *, metrics: dict[str, Any],
              fmt: Format = "npz", figures: bool = True, title: str | None = None) -> dict[str, str]:
    """Write ``trajectories.{npz,csv}``, ``metrics.json`` and (optionally) the figures.

    Figures: ``platoon.png`` (speed, acceleration, spacing and headway of every vehicle,
    like the IDL paper's Figs 7-8) and ``damping.png`` (m_p per follower).

    Returns
    -------
    dict
        ``{kind: file name}`` of everything written under ``out``.
    """
    d = Path(out)
    d.mkdir(parents=True, exist_ok=True)
    files: dict[str, str] = {}
    traj = save_trajectories(result, d / f"trajectories.{fmt}", fmt=fmt)
    files["trajectories"] = traj.name
    if figures:
        from matplotlib.figure import Figure

        from .plots import plot_damping_ratios, plot_platoon

        fig, _ = plot_platoon(result, title=title,
                              fig=Figure(figsize=(12, 7.5), layout="constrained"))
        fig.savefig(d / "platoon.png", dpi=110)
        fig = Figure(figsize=(6, 3.5), layout="constrained")
        ax = fig.subplots()
        plot_damping_ratios(result.damping_ratios, ax=ax)
        ax.set_title("acceleration L2 damping ratio per follower (IDL eq 29)")
        fig.savefig(d / "damping.png", dpi=110)
        files["figure_platoon"] = "platoon.png"
        files["figure_damping"] = "damping.png"
    files["metrics"] = "metrics.json"
    doc = {**metrics, "files": dict(files)}
    (d / "metrics.json").write_text(json.dumps(_jsonable(doc), indent=2, ensure_ascii=False) + "\n",
                                    encoding="utf-8")
    return files
