"""The table of all points of a sweep and the paper's tables and figures drawn from it.

:func:`sweep_table` gathers the records of a spec's points (one row each: id, label, status,
the varied fields, the metrics, wall time, worker, error); :func:`write_outputs` writes it as
``results.csv`` and ``results.parquet`` (:func:`stringstab.io.write_results`) and the study's
report into ``report/`` (an :class:`stringstab.io.OutputDir`):

``table3``
    Table 3's layout: TIT, M_CI, M_effi, M_lss per weight setting (mean ± sd over seeds) beside
    the paper's values (:data:`stringstab.sweep.paper.TABLE3`);
``table5``
    the ablation table (with collisions) beside :data:`~stringstab.sweep.paper.TABLE5`;
``fig5``
    the noise panel: the four metrics against σ per agent (``fig5_noise.png``), and the σ of
    lowest mean rank per agent beside the paper's 0.15 (IDL) and 0.25 (TD3);
``fig4``
    the architectures' rolling-reward curves (``fig4_architectures.png``, from each run's
    ``train_log.csv``) and their metrics;
``certificate``
    the certified share (and, sampled or robust, the continuous share and the share lost) per
    point.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..io import OutputDir, write_results
from .paper import FIG5_BEST_SIGMA, TABLE3, TABLE5, TABLE_METRICS
from .records import read_records
from .spec import SweepSpec

__all__ = ["grouped", "sweep_table", "write_outputs"]


def _cell(v: Any) -> Any:
    if isinstance(v, list):
        return "[" + ", ".join(f"{x:.4g}" if isinstance(x, float) else str(x) for x in v) + "]"
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def sweep_table(spec: SweepSpec, root: str | Path) -> list[dict[str, Any]]:
    """One flat row per point of ``spec`` in spec order (status ``pending`` when not run yet).

    Parameters
    ----------
    spec : SweepSpec
        The sweep's spec.
    root : path
        The sweep folder.

    Returns
    -------
    list of dict
        ``id``, ``label``, ``kind``, ``status``, the varied fields (lists as text), the metrics,
        ``seconds``, ``worker``, ``error``.
    """
    recs = read_records(root, spec)
    varied_keys: dict[str, None] = {}
    metric_keys: dict[str, None] = {}
    for p in spec.points:
        varied_keys.update(dict.fromkeys(p.varied))
        for k in recs.get(p.id, {}).get("metrics", {}):
            metric_keys[k] = None
    rows = []
    for p in spec.points:
        r = recs.get(p.id, {})
        row: dict[str, Any] = {"id": p.id, "label": p.label, "kind": p.kind,
                               "status": r.get("status", "pending")}
        row.update({k: _cell(p.varied.get(k)) for k in varied_keys})
        m = r.get("metrics", {})
        row.update({k: _cell(m.get(k)) for k in metric_keys})
        row.update(seconds=_cell(r.get("seconds")), worker=r.get("worker"),
                   error=r.get("error"))
        rows.append(row)
    return rows


def _columns(rows: Sequence[dict[str, Any]]) -> dict[str, list[Any]]:
    keys: dict[str, None] = {}
    for r in rows:
        keys.update(dict.fromkeys(r))
    return {k: [r.get(k) for r in rows] for k in keys}


def grouped(rows: Sequence[dict[str, Any]], key: Sequence[str],
            metrics: Sequence[str]) -> list[dict[str, Any]]:
    """Mean, standard deviation (ddof 1) and count over seeds of each group of finished rows.

    Groups keep the order of their first row; a metric that is missing in some row (e.g. TIT
    ∞, stored as null) makes its mean ∞ and its sd None.

    Parameters
    ----------
    rows : sequence of dict
        :func:`sweep_table` rows.
    key : sequence of str
        The columns that define a group (e.g. ``["label"]``).
    metrics : sequence of str
        The columns to average.

    Returns
    -------
    list of dict
        The key columns, ``n``, and ``<metric>`` and ``<metric>_sd`` per metric.
    """
    groups: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for r in rows:
        if r["status"] == "done":
            groups.setdefault(tuple(r.get(k) for k in key), []).append(r)
    out = []
    for gk, rs in groups.items():
        g: dict[str, Any] = dict(zip(key, gk))
        g["n"] = len(rs)
        for m in metrics:
            vals = np.array([np.inf if r.get(m) is None else float(r[m]) for r in rs])
            g[m] = float(vals.mean())
            g[m + "_sd"] = float(vals.std(ddof=1)) if len(vals) > 1 and np.isfinite(vals).all() else None
        out.append(g)
    return out


def _f(v: Any, nd: int = 3) -> str:
    if v is None:
        return "–"
    if isinstance(v, float):
        return "∞" if math.isinf(v) else f"{v:.{nd}f}"
    return str(v)


def _pm(g: dict[str, Any], m: str) -> str:
    sd = g.get(m + "_sd")
    return _f(g[m]) + ("" if sd is None else f" ± {sd:.3f}")


def _table_vs_paper(groups: list[dict[str, Any]], paper: dict[str, Any], metrics: Sequence[str],
                    title: str, extra: str = "") -> tuple[str, str]:
    """Markdown and CSV: this sweep's row, then the paper's, per label."""
    md = [f"# {title}\n\n", "| setting | source | n | " + " | ".join(metrics) + " |\n",
          "|---|---|---|" + "---|" * len(metrics) + "\n"]
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["setting", "source", "n", *metrics, *(m + "_sd" for m in metrics)])
    for g in groups:
        label = g["label"] or "(no label)"
        md.append(f"| {label} | this sweep | {g['n']} | " + " | ".join(_pm(g, m) for m in metrics) + " |\n")
        w.writerow([label, "sweep", g["n"], *(g[m] for m in metrics), *(g.get(m + "_sd") for m in metrics)])
        if g["label"] in paper:
            vals = paper[g["label"]]
            md.append(f"| {label} | IDL paper | – | " + " | ".join(_f(v, 2) for v in vals) + " |\n")
            w.writerow([label, "paper", "", *vals, *([""] * len(metrics))])
    md.append("\nMean ± sd over seeds (n finished points); every metric lower is better. " + extra)
    return "".join(md), buf.getvalue()


def _fig5(rows: list[dict[str, Any]], out: OutputDir) -> list[str]:
    from matplotlib.figure import Figure

    key = ["algo", "exploration_noise"]
    if not all(k in rows[0] for k in key):
        return []
    gs = grouped(rows, key, (*TABLE_METRICS, "collisions"))
    algos = list(dict.fromkeys(g["algo"] for g in gs))
    fig = Figure(figsize=(9.6, 6.4), layout="constrained")
    axs = fig.subplots(2, 2)
    md = ["# Fig. 5: sensitivity to the exploration noise σ\n\n",
          "| agent | σ | n | " + " | ".join(TABLE_METRICS) + " | collisions |\n",
          "|---|---|---|" + "---|" * 5 + "\n"]
    best_lines = []
    for algo in algos:
        ga = sorted((g for g in gs if g["algo"] == algo), key=lambda g: g["exploration_noise"])
        sig = [g["exploration_noise"] for g in ga]
        for ax, m in zip(axs.ravel(), TABLE_METRICS):
            y = np.array([g[m] for g in ga], dtype=float)
            sd = np.array([g.get(m + "_sd") or 0.0 for g in ga], dtype=float)
            ax.errorbar(sig, y, yerr=sd, marker="o", capsize=3, label=algo)
            ax.set_xlabel("exploration noise σ")
            ax.set_ylabel(m)
        for g in ga:
            md.append(f"| {algo} | {g['exploration_noise']:g} | {g['n']} | "
                      + " | ".join(_pm(g, m) for m in TABLE_METRICS) + f" | {_pm(g, 'collisions')} |\n")
        ranks = np.mean([np.argsort(np.argsort([g[m] for g in ga])) for m in TABLE_METRICS], axis=0)
        # a setting whose runs collided is never the best (the ranks ignore collisions)
        ranks = ranks + np.array([0.0 if g["collisions"] == 0 else np.inf for g in ga])
        if not np.isfinite(ranks).any():
            ranks = np.zeros(len(ga))
        best = sig[int(np.argmin(ranks))]
        paper = FIG5_BEST_SIGMA.get(algo)
        best_lines.append(f"- {algo}: lowest mean rank over the four metrics (without collisions) "
                          f"at σ = {best:g}"
                          + (f" (the paper: σ = {paper:g})" if paper is not None else "") + "\n")
    for ax in axs.ravel():
        ax.legend()
    fig.suptitle("Exploration noise σ (IDL paper Fig. 5 layout); lower is better")
    fig.savefig(out.path("fig5_noise.png"), dpi=120)
    md += ["\nBest σ (the paper prints no values for Fig. 5, only the best σ of each agent):\n\n",
           *best_lines]
    out.write_text("fig5.md", "".join(md))
    return ["fig5_noise.png", "fig5.md"]


def _fig4(rows: list[dict[str, Any]], root: Path, out: OutputDir) -> list[str]:
    from matplotlib.figure import Figure

    if "hidden" not in rows[0]:
        return []
    fig = Figure(figsize=(6.4, 4.0), layout="constrained")
    ax = fig.add_subplot()
    order = list(dict.fromkeys(r["hidden"] for r in rows))
    for hidden in dict.fromkeys(r["hidden"] for r in rows if r["status"] == "done"):
        curves = []
        for r in rows:
            f = root / "points" / r["id"] / "run" / "train_log.csv"
            if r["status"] != "done" or r["hidden"] != hidden or not f.is_file():
                continue
            with f.open(newline="") as fh:
                data = [(float(d["step"]), float(d["rolling_return"])) for d in csv.DictReader(fh)]
            if data:
                curves.append(np.array(data))
        for i, c in enumerate(curves):
            ax.plot(c[:, 0], c[:, 1], color=f"C{order.index(hidden)}",
                    alpha=0.8, label=f"hidden {hidden}" if i == 0 else None)
    ax.set_xlabel("environment step")
    ax.set_ylabel("rolling episode reward (window 10)")
    ax.set_title("Reward convergence per architecture (IDL paper Fig. 4 layout)")
    ax.legend()
    fig.savefig(out.path("fig4_architectures.png"), dpi=120)
    gs = grouped(rows, ["hidden"], (*TABLE_METRICS, "final_rolling_return"))
    md = ["# Fig. 4: network architectures\n\n",
          "| hidden | n | final rolling reward | " + " | ".join(TABLE_METRICS) + " |\n",
          "|---|---|---|" + "---|" * 4 + "\n"]
    for g in gs:
        md.append(f"| {g['hidden']} | {g['n']} | {_pm(g, 'final_rolling_return')} | "
                  + " | ".join(_pm(g, m) for m in TABLE_METRICS) + " |\n")
    md.append("\nThe paper prints no values for Fig. 4; it chose 2 × 128 for stable convergence "
              "near the best reward.\n")
    out.write_text("fig4.md", "".join(md))
    return ["fig4_architectures.png", "fig4.md"]


def _certificate(rows: list[dict[str, Any]], out: OutputDir) -> list[str]:
    keys: list[str] = [k for k in ("tau", "delta", "headway", "sample_time") if k in rows[0]]
    cols: list[str] = [c for c in ("certified_share", "continuous_share", "lost_share", "inconclusive_share",
                        "n_points") if c in rows[0]]
    md = ["# Certified share of the gain grid\n\n", "| " + " | ".join(keys + cols) + " |\n",
          "|" + "---|" * (len(keys) + len(cols)) + "\n"]
    for r in rows:
        if r["status"] == "done":
            md.append("| " + " | ".join(_f(r.get(k), 4) for k in keys + cols) + " |\n")
    md.append("\nlost_share: of the gains certified in continuous time at the nominal "
              "parameters, the share not certified by this point's (sampled or robust) certificate.\n")
    out.write_text("certificate.md", "".join(md))
    return ["certificate.md"]


def write_outputs(spec: SweepSpec, root: str | Path) -> list[str]:
    """Write ``results.csv``, ``results.parquet`` and the study's ``report/``; return the names.

    Parameters
    ----------
    spec : SweepSpec
        The sweep's spec (its points, in order, are the table's rows).
    root : path
        The sweep folder.

    Returns
    -------
    list of str
        Paths written, relative to ``root``.
    """
    root = Path(root)
    rows = sweep_table(spec, root)
    cols = _columns(rows)
    params = {"sweep": spec.name, "kind": spec.kind, "study": spec.study}
    write_results(cols, root / "results.csv", "csv")
    write_results(cols, root / "results.parquet", "parquet", params=params)
    files = ["results.csv", "results.parquet"]
    if spec.study == "none" or not any(r["status"] == "done" for r in rows):
        return files
    rep = OutputDir(root / "report", command="sweep", what="report folder")
    with rep:
        names: list[str] = []
        if spec.study in ("table3", "table5"):
            metrics: tuple[str, ...] = TABLE_METRICS
            if spec.study == "table5":
                metrics = (*TABLE_METRICS, "collisions")
            gs = grouped(rows, ["label"], metrics)
            paper: dict[str, Any]
            if spec.study == "table3":
                paper = {k: v[1:] for k, v in TABLE3.items()}
                title = "Table 3: reward weights (Pareto front)"
            else:
                paper = dict(TABLE5)
                title = "Table 5: reward ablation"
            md, text = _table_vs_paper(gs, paper, metrics, title, "m_fss (the fraction of executed gains certified) is in "
                                       "results.csv; the paper's rows are matched by label.\n")
            rep.write_text(f"{spec.study}.md", md)
            rep.write_text(f"{spec.study}.csv", text)
            names += [f"{spec.study}.md", f"{spec.study}.csv"]
        elif spec.study == "fig5":
            names += _fig5(rows, rep)
        elif spec.study == "fig4":
            names += _fig4(rows, root, rep)
        elif spec.study == "certificate":
            names += _certificate(rows, rep)
    return files + [f"report/{n}" for n in names]
