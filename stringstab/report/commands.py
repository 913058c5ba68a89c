"""The reports of the commands that write a folder, each built from the objects the command
already has (a region map, a simulated run's metrics document, an evaluation, a comparison, a
verification).  A command calls one function and writes the result::

    region_report(rmap, files, command=command_line(args), started=t0).write(out)
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from .render import Report

__all__ = ["compare_report", "evaluate_report", "region_report", "simulate_report",
           "tune_report"]

#: Metrics of a run with their meaning and unit, in the order a report lists them.
METRICS: list[tuple[str, str, str]] = [
    ("max_m_p", "largest m_p over the followers (IDL eq 29); < 1: disturbances shrink", ""),
    ("M_lss", "mean m_p over the followers", ""),
    ("collisions", "vehicles that collided", ""),
    ("min_gap", "smallest gap", "m"),
    ("TIT", "time-integrated time to collision below TTC* (IDL eq 31); lower is safer", "s²"),
    ("min_ttc", "smallest time to collision", "s"),
    ("M_CI", "comfort index: mean squared jerk (IDL eq 32); lower is better", "m²/s⁶"),
    ("M_effi", "mean time headway (efficiency; IDL eq 33)", "s"),
    ("min_headway", "smallest time headway", "s"),
    ("M_fss", "share of vehicle-moments whose gains are certified; higher is better", "%"),
]


def _pngs(names: Iterable[str]) -> list[str]:
    return [str(n) for n in names if str(n).endswith((".png", ".svg", ".jpg"))]


def region_report(rmap: Any, files: Sequence[Any], *, command: str,
                  started: float | None = None) -> Report:
    """The report of ``stringstab region``: the grid, each method's class shares, where the
    methods disagree, and every figure.

    Parameters
    ----------
    rmap : RegionMap
        The computed map.
    files : sequence of path-like
        The files written (only their names are used; images become figures).
    command : str
        The command line.
    started : float, optional
        ``time.perf_counter()`` at the start of the command.

    Returns
    -------
    Report
        The report, to :meth:`~stringstab.report.Report.write`.
    """
    axes = {n: f"[{a[0]:g}, {a[-1]:g}] in {len(a)} points" for n, a in rmap.axes.items()}
    rep = Report("Map of the string-stable gains", command=command,
                 params={**axes, **{k: v for k, v in rmap.fixed.items()}, "loop": rmap.title(),
                         "methods": ", ".join(rmap.methods)},
                 intro="Every grid point is a gain triple K = (k_x, k_v, k_a), judged by each "
                       "method: *exact* is the certificate (internal stability and ‖Γ‖∞ ≤ 1 with "
                       "the exact delay), *taylor* the derived second-order criteria, *printed* "
                       "the IDL paper's Proposition 1 as printed.", started=started)
    sec = rep.section("Classes")
    sec.code(rmap.report())
    for m, shares in rmap.class_shares().items():
        sec.table([{"class": k, "share (%)": 100 * v} for k, v in shares.items()],
                  caption=f"{m}: share of the grid in each class.", digits=3)
    if len(rmap.methods) > 1:
        d = rmap.disagreements()
        s2 = rep.section("Where the methods disagree")
        for k, v in d.items():
            if " vs " in k:
                s2.verdict(f"{k} agree on every decided point", v == 0, f"{v:,} points differ")
        s2.verdict("exact certificate decided at every point", d["inconclusive"] == 0,
                   f"{d['inconclusive']:,} inconclusive points (within rounding of the boundary)")
    figs = _pngs(Path(str(f)).name for f in files)
    if figs:
        rep.section("Figures").figures(figs)
    return rep


def simulate_report(doc: Mapping[str, Any], files: Mapping[str, str], *, command: str,
                    title: str = "", started: float | None = None) -> Report:
    """The report of ``stringstab simulate``: the set-up, the certificate of the gains, the
    metrics with their units and meaning, m_p per follower, and the figures.

    Parameters
    ----------
    doc : mapping
        The run's metrics document (:func:`stringstab.traffic.output.run_document`).
    files : mapping
        ``{kind: file name}`` written by :func:`stringstab.traffic.output.write_run`.
    command : str
        The command line.
    title : str, optional
        The run's title (leader, followers, controller).
    started : float, optional
        ``time.perf_counter()`` at the start of the command.

    Returns
    -------
    Report
        The report.
    """
    run = dict(doc.get("run", {}))
    params = {k: run[k] for k in ("leader_name", "followers", "duration_s", "dt", "tau", "delta",
                                  "headway", "controller", "model") if k in run}
    rep = Report(f"Platoon simulation{': ' + title if title else ''}", command=command,
                 params=params, started=started)
    sec = rep.section("Verdicts")
    cert = doc.get("certificate")
    if cert:
        sec.verdict(f"K = ({cert['k_x']:g}, {cert['k_v']:g}, {cert['k_a']:g}) certified string "
                    "stable (exact delay)", cert["verdict"] == "certified",
                    f"{cert['verdict']}; sup|Γ| = {cert['sup_gain']:.4g}")
    else:
        sec.verdict("gains certified", None, "no fixed eq-4 gains to certify (time-varying gains, "
                                             "CACC or IDM)")
    mp = doc.get("max_m_p")
    sec.verdict("every follower damps the leader's disturbance (m_p < 1)",
                None if mp is None else mp < 1, "max m_p = n/a" if mp is None else f"max m_p = {mp:.3f}")
    sec.verdict("no collision", doc.get("collisions") == 0, f"{doc.get('collisions')} collided")
    for w in doc.get("warnings", []):
        sec.verdict("leader", None, f"warning: {w}")
    m = rep.section("Metrics")
    m.table([{"metric": k, "value": doc.get(k), "unit": u or "–", "meaning": what}
             for k, what, u in METRICS if k in doc], caption="The IDL paper's metrics of this run.")
    if doc.get("m_p"):
        m.table([["m_p", *doc["m_p"]]],
                columns=["follower"] + [str(i + 1) for i in range(len(doc["m_p"]))],
                caption="m_p per follower (follower-to-predecessor acceleration energy).",
                digits=3)
    figs = _pngs(files.values())
    if figs:
        rep.section("Figures").figures(figs)
    return rep


def tune_report(results: Sequence[Any], *, command: str, params: Mapping[str, Any],
                figure: str | None = None, started: float | None = None) -> Report:
    """The report of ``stringstab tune --report DIR``: every repair and the moves figure.

    Parameters
    ----------
    results : sequence of TuneResult
        One per (triple, method).
    command : str
        The command line.
    params : mapping
        τ, δ, T*, the method and its settings.
    figure : str, optional
        The moves figure's file name, if drawn.
    started : float, optional
        ``time.perf_counter()`` at the start of the command.

    Returns
    -------
    Report
        The report.
    """
    rep = Report("Repairing gains", command=command, params=params, started=started,
                 intro="Each uncertified gain triple is moved into the certified region; the "
                       "result is certified again with the exact delay.")
    recs = [r.as_dict() for r in results]
    sec = rep.section("Repairs")
    n_cert = sum(bool(r["certified"]) for r in recs)
    sec.verdict("every output certified", n_cert == len(recs), f"{n_cert} of {len(recs)} certified")
    sec.table([{"method": r["method"], "from K": f"({r['k_x_in']:g}, {r['k_v_in']:g}, {r['k_a_in']:g})",
                "to K": f"({r['k_x']:.4g}, {r['k_v']:.4g}, {r['k_a']:.4g})",
                "distance moved": r["distance"], "certified": r["certified"],
                "status": r["status"]} for r in recs],
              caption="Every repair; distance in weighted gain units (k_x in s⁻², k_v in s⁻¹, "
                      "k_a dimensionless).")
    if figure:
        sec.figure(figure)
    return rep


def evaluate_report(markdown: str, files: Sequence[str], *, command: str,
                    verdict: str, passed: bool, started: float | None = None) -> Report:
    """The report of ``stringstab evaluate``: the verdict, the evaluation's tables, the files.

    Parameters
    ----------
    markdown : str
        The evaluation's Markdown (:func:`stringstab.rl.report.evaluation_markdown`).
    files : sequence of str
        The files written.
    command : str
        The command line.
    verdict : str
        The one-line verdict.
    passed : bool
        Whether the evaluation passes (exit 0).
    started : float, optional
        ``time.perf_counter()`` at the start of the command.

    Returns
    -------
    Report
        The report.
    """
    rep = Report("Evaluation of a trained policy", command=command, started=started)
    rep.section("Verdict").verdict("every executed gain certified and no collision", passed, verdict)
    body = "\n".join(line for line in markdown.splitlines() if not line.startswith("# "))
    rep.section("Results").markdown(body, shift=1)
    rep.section("Files").text(", ".join(f"`{f}`" for f in files if not f.startswith("report.")))
    return rep


def compare_report(markdown: str, files: Sequence[str], *, command: str,
                   started: float | None = None) -> Report:
    """The report of ``stringstab compare``: the Table-4 comparison and the paper's figures.

    Parameters
    ----------
    markdown : str
        The comparison's Markdown (``table.md``).
    files : sequence of str
        The files written (images become figures).
    command : str
        The command line.
    started : float, optional
        ``time.perf_counter()`` at the start of the command.

    Returns
    -------
    Report
        The report.
    """
    rep = Report("Comparison of strategies on held-out episodes", command=command, started=started)
    body = "\n".join(line for line in markdown.splitlines() if not line.startswith("# "))
    rep.section("Table 4 layout").markdown(body, shift=1)
    figs = _pngs(files)
    if figs:
        rep.section("Figures").figures(figs)
    return rep
