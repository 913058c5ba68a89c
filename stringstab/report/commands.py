"""The reports of the commands that write a folder, from the objects the command already has.

Those are a region map, a simulated run's metrics document, an evaluation, a comparison, a
verification.  A command calls one function and writes the result::

    region_report(rmap, files, command=command_line(args), started=t0).write(out)
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from ..certify.verdicts import Verdict
from ..ranges import metric_caveat
from .render import Report
from .skeleton import add_figures, grid_axes

__all__ = ["cars_report", "compare_report", "evaluate_report", "identify_report", "region_report",
           "scenario_report", "simulate_report", "sweep_report", "tune_report"]

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
    ("m_fss", "share of vehicle-moments whose gains are certified; higher is better", "fraction"),
]


def region_report(rmap: Any, files: Sequence[Any], *, command: str,
                  started: float | None = None) -> Report:
    """The report of ``stringstab region``.

    The grid, each method's class shares, where the methods disagree, and every figure.

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
    axes = grid_axes(rmap.axes)
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
    add_figures(rep, (Path(str(f)).name for f in files))
    return rep


def simulate_report(doc: Mapping[str, Any], files: Mapping[str, str], *, command: str,
                    title: str = "", started: float | None = None) -> Report:
    """The report of ``stringstab simulate``.

    The set-up, the certificate of the gains, the metrics with their units and meaning, m_p per
    follower, and the figures.

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
                                  "headway", "controller", "model", "reaction_delay") if k in run}
    for part in ("radio", "sensors"):  # the loop as it runs (issue 26): its settings in one row
        if run.get(part) is not None:
            params[part] = ", ".join(f"{k} = {v}" for k, v in run[part].items() if v is not None)
    rep = Report(f"Platoon simulation{': ' + title if title else ''}", command=command,
                 params=params, started=started)
    sec = rep.section("Verdicts")
    cert = doc.get("certificate")
    if cert:
        theta = f", reaction delay θ_r = {cert['reaction_delay']:g} s" if cert.get("reaction_delay") else ""
        sec.verdict(f"K = ({cert['k_x']:g}, {cert['k_v']:g}, {cert['k_a']:g}) certified string "
                    f"stable (exact delay{theta})", cert["verdict"] == Verdict.CERTIFIED,
                    f"{cert['verdict']}; sup|Γ| = {cert['sup_gain']:.4g}"
                    + (f"; scope: {cert['scope']}" if cert.get("scope") else ""))
    else:
        sec.verdict("gains certified", None, "no fixed eq-4 gains to certify (time-varying gains, "
                                             "CACC or IDM)")
    mp = doc.get("max_m_p")
    sec.verdict("every follower damps the leader's disturbance (m_p < 1)",
                None if mp is None else mp < 1, "max m_p = n/a" if mp is None else f"max m_p = {mp:.3f}")
    sec.verdict("no collision", doc.get("collisions") == 0, f"{doc.get('collisions')} collided")
    radio = doc.get("radio")
    if radio is not None:
        share = radio.get("loss_share")
        import numpy as np

        sec.verdict("the radio", None,
                    f"{int(np.sum(radio['messages_received']))} messages received"
                    + ("" if share is None else f", {100 * share:.2f} % lost")
                    + f"; time in fallback {100 * (radio.get('fallback_share') or 0.0):.2f} % of follower time")
    for w in doc.get("warnings", []):
        sec.verdict("leader", None, f"warning: {w}")
    m = rep.section("Metrics")
    m.table([{"metric": k, "value": doc.get(k), "unit": u or "–",
              "meaning": f"{what} {metric_caveat(k, doc.get(k))}".strip()}
             for k, what, u in METRICS if k in doc],
            caption="The IDL paper's metrics of this run (a value outside its sensible range "
                    "says so in its meaning).")
    if doc.get("m_p"):
        m.table([["m_p", *doc["m_p"]]],
                columns=["follower"] + [str(i + 1) for i in range(len(doc["m_p"]))],
                caption="m_p per follower (follower-to-predecessor acceleration energy).",
                digits=3)
    add_figures(rep, files.values())
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
    add_figures(rep, files)
    return rep


def _identify_params(res: Any) -> dict[str, Any]:
    """The parameter table of an identify report (per follower or per car): logs, model, H, bootstrap."""
    st = res.settings
    return {"logs": ", ".join(res.sources), "model": res.model,
            "sample time H": res.sample_time or "continuous",
            **{k: st[k] for k in ("bootstrap", "block", "starts", "seed", "min_duration") if k in st}}


def identify_report(res: Any, files: Sequence[Any], *, command: str,
                    started: float | None = None) -> Report:
    """The report of ``stringstab identify``.

    The per-follower table with the verdicts and the bootstrap shares, the data's own
    amplification, the notes, and every figure.

    Parameters
    ----------
    res : IdentifyResult
        The identification (:func:`stringstab.identify.identify`).
    files : sequence of path-like
        The files written (only their names are used; images become figures).
    command : str
        The command line.
    started : float, optional
        ``time.perf_counter()`` at the start of the command.

    Returns
    -------
    Report
        The report.
    """
    rep = Report("Identified followers", command=command,
                 params=_identify_params(res),
                 intro="Each follower's controller is fitted to the logged speeds and gaps, its "
                       "gains are certified with the exact delay (‖Γ‖∞ ≤ 1, internally stable), "
                       "and moving-block bootstrap refits give the share of plausible fits that "
                       "are certified. The data's own speed transfer is estimated beside the "
                       "model's, so a verdict can be checked against what the platoon did.",
                 started=started)
    sec = rep.section("Verdicts")
    for v in res.vehicles:
        r = v.row()
        sv = r["supported_verdict"]  # yes/no only where every bootstrap fit agrees (issue 28)
        sec.verdict(f"{v.position} {v.name}: fitted gains certified string stable (exact delay)",
                    None if sv == Verdict.INCONCLUSIVE else sv == Verdict.CERTIFIED,
                    f"{v.statement()}; the point fit: {r['verdict']}, sup|Γ| = {r['sup_gain']:.4g}")
    rows = []
    for v in res.vehicles:
        r = v.row()
        rows.append({"pos": r["position"], "name": r["name"], "k_x": _denoise(r["k_x"]),
                     "k_v": _denoise(r["k_v"]), "k_a": _denoise(r["k_a"]), "τ": _denoise(r["tau"]),
                     "T*": _denoise(r["headway"]), "l0": _denoise(r["standstill"]),
                     "θ_r": _denoise(r["reaction_delay"]),
                     "RMSE v": r["rmse_speed"], "RMSE gap": r["rmse_gap"], "sup|Γ|": r["sup_gain"],
                     "sup|Γ| 5 %": r["sup_gain_lo"], "sup|Γ| 95 %": r["sup_gain_hi"],
                     "verdict": r["verdict"], "bootstrap verdict": r["supported_verdict"],
                     "certified share (%)": 100 * r["certified_share"],
                     "not certified share (%)": 100 * r["not_certified_share"]})
    rep.section("Fitted followers").table(
        rows, caption="Per follower: the fitted parameters, the fit's error, sup|Γ| with its "
        "5-95 % bootstrap interval, the certificate's verdict on the point fit, the verdict the "
        "bootstrap supports (certified or not certified only when every refit agrees, else "
        "inconclusive) and the shares of bootstrap fits certified / not certified.",
        units={"k_x": "1/s²", "k_v": "1/s", "τ": "s", "T*": "s", "l0": "m", "θ_r": "s", "RMSE v": "m/s",
               "RMSE gap": "m"})
    amp = [{"pos": v.position, "name": v.name, "max |Ĝ|": v.empirical.gain,
            "at ω": v.empirical.gain_omega, "± (2ε)": 2 * v.empirical.gain_error * v.empirical.gain,
            "the data": v.empirical.amplifies, "peak-to-peak": v.empirical.peak_to_peak,
            "energy": v.empirical.energy} for v in res.vehicles]
    rep.section("The data's own amplification").table(
        amp, caption="From the logged speeds alone (no model): the largest coherent |Ĝ(jω)| with "
        "its ± two-standard-error band and whether it is above 1 beyond that band, the speed "
        "range ratio and the acceleration-energy ratio of follower to predecessor.",
        units={"at ω": "rad/s"})
    notes = [f"{v.position} {v.name}: {n}" for v in res.vehicles for n in v.fit.notes + v.notes]
    notes += [f"skipped: {s}" for s in res.skipped]
    if notes:  # plain text: T* is a name, not emphasis
        rep.section("Notes").text("\n".join(f"- {n}".replace("*", "\\*") for n in notes))
    add_figures(rep, (Path(str(f)).name for f in files), lambda f: _identify_caption(res, f))
    return rep


def cars_report(res: Any, files: Sequence[Any], *, command: str, started: float | None = None) -> Report:
    """The report of ``stringstab identify --by car``: one row per car and setting.

    Parameters
    ----------
    res : CarsResult
        :func:`stringstab.identify.cars.identify_cars`.
    files : sequence of path-like
        The files written (only their names are used; images become figures).
    command : str
        The command line.
    started : float, optional
        ``time.perf_counter()`` at the start of the command.

    Returns
    -------
    Report
        The report.
    """
    rep = Report("Identified cars (every log of a car and setting pooled)", command=command,
                 params=_identify_params(res),
                 intro="Each car's controller is fitted jointly to every log of it at one distance "
                       "setting (one law, the initial state of every segment free), certified with "
                       "the exact delay, and bootstrapped over all its logs; a verdict is certified "
                       "or not certified only when every bootstrap refit agrees, inconclusive "
                       "otherwise, with the share certified.",
                 started=started)
    sec = rep.section("Verdicts")
    for c in res.cars:
        r = c.row()
        sec.verdict(f"{c.car} ({c.setting}, {len(c.logs)} log{'s' if len(c.logs) != 1 else ''}): string "
                    "stable (exact delay)", None if r["verdict"] == Verdict.INCONCLUSIVE else r["verdict"] == Verdict.CERTIFIED,
                    f"{c.statement()}; sup|Γ| = {r['sup_gain']:.4g}"
                    + ("" if not all(math.isfinite(x) for x in r["sup_gain_interval"])
                       else f" ({r['sup_gain_interval'][0]:.3g}-{r['sup_gain_interval'][1]:.3g})"))
    rows = []
    for c in res.cars:
        r = c.row()
        lo, hi = r["headway_interval"]
        rows.append({"car": r["car"], "setting": r["setting"], "logs": len(r["logs"]),
                     "k_x": _denoise(r["k_x"]), "k_v": _denoise(r["k_v"]), "τ": _denoise(r["tau"]),
                     "θ_r": _denoise(r["reaction_delay"]), "T*": _denoise(r["headway"]),
                     "T* 5 %": lo, "T* 95 %": hi, "T* from": r["headway_source"],
                     "median time gap": r["median_time_gap"], "l0": _denoise(r["standstill"]),
                     "sup|Γ|": r["sup_gain"], "sup|Γ| 5 %": r["sup_gain_interval"][0],
                     "sup|Γ| 95 %": r["sup_gain_interval"][1], "verdict": r["verdict"],
                     "certified share (%)": 100 * r["certified_share"], "max |Ĝ|": r["empirical_gain"]})
    rep.section("Cars").table(
        rows, caption="Per car and setting: the jointly fitted parameters, T* with its interval and "
        "where it comes from (the spacing policy of the quasi-steady parts, or the dynamic fit), "
        "the logs' median time gap (T* + l_0/v), sup|Γ| with its 5-95 % bootstrap interval, the "
        "verdict the bootstrap supports with its share certified, and the data's own pooled max |Ĝ|.",
        units={"k_x": "1/s²", "k_v": "1/s", "τ": "s", "θ_r": "s", "T*": "s", "T* 5 %": "s", "T* 95 %": "s",
               "median time gap": "s", "l0": "m"})
    notes = [f"{c.car} ({c.setting}): {n}" for c in res.cars for n in c.fit.notes + c.notes]
    notes += [f"skipped: {sk}" for sk in res.skipped]
    if notes:
        rep.section("Notes").text("\n".join(f"- {n}".replace("*", "\\*") for n in notes))
    add_figures(rep, (Path(str(f)).name for f in files), lambda f: _cars_caption(res, f))
    return rep


def _cars_caption(res: Any, name: str) -> str:
    """The caption of one ``--by car`` figure: whose it is and its numbers, then what to see."""
    import re

    from .captions import caption_for

    for c in res.cars:
        tag = re.sub(r"[^A-Za-z0-9_-]", "_", f"{c.car}_{c.setting}")
        if name in (f"fit_{tag}.png", f"transfer_{tag}.png"):
            head = (f"{c.car} ({c.setting} setting, {len(c.logs)} log{'s' if len(c.logs) != 1 else ''} pooled): "
                    f"the model's sup|Γ| = {float(c.certificate.sup_gain):.3g}, {c.statement()}. ")
            return head + caption_for(name)
    return caption_for(name)


def _denoise(x: Any) -> Any:
    """Show a fitted value as a table should: within 1e-6 of 0, it is 0.

    A fit run onto the bound T* ≥ 0 returns 8.9e-08, which is solver noise, not a headway.
    """
    return 0.0 if isinstance(x, float) and abs(x) < 1e-6 else x


def _identify_caption(res: Any, name: str) -> str:
    """The caption of one identify figure: whose it is and its numbers, then what to see."""
    from .captions import caption_for

    for v in res.vehicles:
        tag = f"{v.platoon}_{v.position}" if len(res.sources) > 1 else f"{v.position}"
        if name in (f"fit_{tag}.png", f"transfer_{tag}.png"):
            c = v.certificate
            who = f"Follower {v.position} ({v.name}"
            who += f", {v.platoon})" if len(res.sources) > 1 else ")"
            if name.startswith("fit_"):
                head = (f"{who}: speed RMSE {v.fit.rmse_speed:.2g} m/s, gap RMSE "
                        f"{v.fit.rmse_gap:.2g} m over {len(v.segments)} clean segment"
                        f"{'' if len(v.segments) == 1 else 's'}. ")
            else:
                e = v.empirical
                data = (f"the data's max |Ĝ| = {e.gain:.3g} ± {2 * e.gain_error * e.gain:.2g} at "
                        f"{e.gain_omega:.2g} rad/s (amplifies: {e.amplifies})"
                        if math.isfinite(e.gain) else "no coherent frequency in the data")
                head = (f"{who}: the model's sup|Γ| = {float(c.sup_gain):.3g} at "
                        f"{float(c.peak_omega):.2g} rad/s ({c.verdict}); {data}. ")
            return head + caption_for(name)
    return caption_for(name)


def sweep_report(spec: Any, rows: Sequence[Mapping[str, Any]], files: Sequence[str],
                 root: str | Path, *, command: str, started: float | None = None) -> Report:
    """The report of ``stringstab sweep``.

    How many points finished, the results table, the failures, and the study's tables and
    figures (``report/``) the sweep already wrote.

    Parameters
    ----------
    spec : SweepSpec
        The sweep's spec.
    rows : sequence of mappings
        :func:`stringstab.sweep.sweep_table` (one row per point).
    files : sequence of str
        The files the sweep wrote, relative to ``root`` (study tables ``report/*.md`` are
        included as they are; images become figures).
    root : path-like
        The sweep folder.
    command : str
        The command line.
    started : float, optional
        ``time.perf_counter()`` at the start of the command.

    Returns
    -------
    Report
        The report, to :meth:`~stringstab.report.Report.write` into ``root``.
    """
    rep = Report(f"Sweep {spec.name}", command=command,
                 params={"spec": spec.source or spec.name, "kind": spec.kind, "study": spec.study,
                         "points": len(spec)}, started=started)
    status: dict[str, int] = {}
    for r in rows:
        status[str(r["status"])] = status.get(str(r["status"]), 0) + 1
    sec = rep.section("Verdicts")
    sec.verdict("every point finished", status.get("done", 0) == len(rows),
                ", ".join(f"{n} {k}" for k, n in status.items()))
    cols = [c for c in (rows[0] if rows else {}) if c not in ("kind", "error", "worker")]
    rep.section("Results").table(
        [{c: r.get(c) for c in cols} for r in rows],
        caption="One row per point, in the spec's order: its varied settings, its metrics (as in "
                "results.csv) and its wall time (s).")
    failed = [r for r in rows if r["status"] not in ("done", "pending")]
    if failed:
        rep.section("Failed points").table(
            [{"id": r["id"], "label": r["label"], "error": r.get("error")} for r in failed],
            caption="Points that did not finish, with the error; run the same command again to "
                    "retry them.")
    for f in files:
        if f.endswith(".md"):
            text = (Path(root) / f).read_text(encoding="utf-8")
            rep.section(f"Study: {Path(f).stem}").markdown(text)
    add_figures(rep, files)
    return rep


def scenario_report(doc: Mapping[str, Any], *, command: str, started: float | None = None) -> Report:
    """The report of ``stringstab sumo run --sumocfg``.

    The scenario, the vehicles driven, what each met (leaders, smallest gap, collisions, m_p)
    and the share of executed gains certified.

    Parameters
    ----------
    doc : mapping
        The run's ``metrics.json`` document (``run`` settings and the summary of
        :func:`stringstab.sumo.inscenario.run_scenario`).
    command : str
        The command line.
    started : float, optional
        ``time.perf_counter()`` at the start of the command.

    Returns
    -------
    Report
        The report.
    """
    run = dict(doc.get("run", {}))
    rep = Report(f"SUMO scenario {Path(str(run.get('sumocfg', ''))).name}", command=command,
                 params={k: (", ".join(v) if isinstance(v, list) else v) for k, v in run.items()},
                 intro="Named vehicles of a SUMO scenario driven by the controller, each following "
                       "the vehicle SUMO reports as its leader at every step.", started=started)
    sec = rep.section("Verdicts")
    sec.verdict("no collision of a driven vehicle", doc.get("collisions", 0) == 0,
                f"{doc.get('collisions', 0)} collisions")
    if doc.get("m_fss") is not None:
        sec.verdict("every executed gain triple certified string stable (exact delay)",
                    doc["m_fss"] >= 1.0,
                    f"m_fss = {doc['m_fss']:.4g} (exact), {doc['m_fss_sampled']:.4g} sampled-data, "
                    f"of {doc.get('n_gains')} gain triples")
    rep.section("Driven vehicles").table(
        [{"vehicle": v["vehicle"], "steps driven": v["steps_controlled"],
          "leaders": " → ".join(v["leaders"]) or "none", "leader changes": v["leader_changes"],
          "min gap": v["min_gap"], "collisions": v["collisions"], "m_p": v["m_p"]}
         for v in doc.get("vehicles", [])],
        caption="Per driven vehicle: the steps it was driven, the leaders it followed in turn, its "
                "smallest gap, its collisions and m_p (IDL eq 29: follower-to-leader acceleration "
                "energy; < 1: disturbances shrink).", units={"min gap": "m"})
    return rep
