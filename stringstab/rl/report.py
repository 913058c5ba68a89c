"""Writing evaluations and comparisons: JSON, Markdown, CSV and the paper's figures.

Both writers stage every file in an :class:`~stringstab.io.OutputDir`, so an output folder is
complete or untouched.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..io import OutputDir
from .compare import table_csv, table_markdown, table_rows
from .evaluate import PAPER_MP_10, PAPER_MP_100_MAX, SAMPLED_NOT_AVAILABLE, Evaluation

__all__ = ["EVALUATION_METRICS", "evaluation_markdown", "platoon_markdown", "verdict", "write_comparison",
           "write_evaluation"]


def _sampled_cell(s: Mapping[str, Any], reaction_delay: float) -> str:
    """The comparison table's m_fss_sampled cell."""
    if s["m_fss_sampled"] is not None:
        return _ms(s["m_fss_sampled"])
    if reaction_delay and s.get("m_fss") is not None:
        return SAMPLED_NOT_AVAILABLE
    return "0 (no certified gains executed)"


def _loop_words(run: Mapping[str, Any]) -> str:
    """θ_r, the radio and the sensors of an evaluation, in words (empty at the defaults)."""
    words = ""
    if run.get("reaction_delay"):
        words += f", reaction delay θ_r = {run['reaction_delay']:g} s"
    if run.get("radio"):
        words += f", radio {run['radio']}"
    if run.get("sensors"):
        words += f", sensors {run['sensors']}"
    return words


def _fmt(v: Any) -> str:
    if v is None:
        return "–"
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def platoon_markdown(platoons: Sequence[Mapping[str, Any]], *, note: bool = True) -> str:
    """m_p per vehicle of each platoon test next to the paper's values (§5.1).

    Parameters
    ----------
    platoons : sequence of mappings
        Platoon tests (:func:`stringstab.rl.evaluate.platoon_test`).
    note : bool
        Add the paragraph on what m_p shows for a switching policy.

    Returns
    -------
    str
        Markdown.
    """
    out = []
    for p in platoons:
        mp = p["m_p"]
        out.append(f"**{p['n']} vehicles** behind {p['leader']}: max m_p {p['max_m_p']:.3f}, "
                   f"M_lss {p['M_lss']:.3f}, collisions {p['collisions']}, TIT {p['TIT']:.3f}, "
                   f"m_fss {_fmt(p['m_fss'])}, m_fss sampled at dt {_fmt(p.get('m_fss_sampled'))}\n")
        if p["n"] == 10:
            out.append("\n| vehicle | " + " | ".join(str(i + 1) for i in range(10)) + " |\n")
            out.append("|---|" + "---|" * 10 + "\n")
            out.append("| m_p (this policy) | " + " | ".join(f"{v:.3f}" for v in mp) + " |\n")
            out.append("| m_p (IDL paper §5.1) | " + " | ".join(f"{v:.2f}" for v in PAPER_MP_10)
                       + " |\n")
        else:
            marks = [i for i in (1, 10, 15, 39, 50, 100) if i <= len(mp)]
            out.append("\n" + ", ".join(f"m_p[{i}] = {mp[i - 1]:.3f}" for i in marks)
                       + f"; the paper: 0.90 at vehicle 15, 0.97 at 39, then 0.978-"
                       f"{PAPER_MP_100_MAX} (all < 1)\n")
        out.append("\n")
    if note:
        out.append("The certificate covers frozen gains; a learned policy changes its gains every "
               "step, so these m_p values are the time-domain evidence that the switching does "
                   "not amplify disturbances along the platoon: evidence, not a proof.\n")
    return "".join(out)


#: Each metric of an evaluation's summary: (what it is, unit).
EVALUATION_METRICS: dict[str, tuple[str, str]] = {
    "m_fss": ("share of executed gains certified, continuous time (eq 27; ↑)", "fraction"),
    "m_fss_sampled": ("share of executed gains certified, sampled-data loop at dt (↑)", "fraction"),
    "n_gains": ("executed gains checked", "count"),
    "collisions": ("collisions", "count"),
    "collided_episodes": ("episodes with a collision", "count"),
    "min_gap": ("smallest gap", "m"),
    "TIT": ("time-integrated TTC below TTC*, mean per episode (eqs 31-32; ↓)", "s²"),
    "TIT_total": ("TIT summed over the episodes", "s²"),
    "M_CI": ("comfort index, mean squared jerk (eq 34; ↓)", "m²/s⁶"),
    "M_effi": ("mean time headway (eq 35; ↓)", "s"),
    "median_headway": ("median time headway", "s"),
    "M_lss": ("mean m_p over the episodes (eq 30; ↓)", "–"),
    "share_m_p_below_1": ("share of episodes with m_p < 1 (↑)", "fraction"),
    "m_p_undefined": ("episodes where m_p is undefined (no leader acceleration)", "count"),
}


def evaluation_markdown(ev: Evaluation, platoons: Sequence[Mapping[str, Any]],
                        run: Mapping[str, Any], verdict: str) -> str:
    """The Markdown report of ``stringstab evaluate``.

    Parameters
    ----------
    ev : Evaluation
        The evaluation.
    platoons : sequence of mappings
        Its platoon tests.
    run : mapping
        The run's folder, leaders, τ, δ, T*, dt.
    verdict : str
        The one-line verdict (:func:`verdict`).

    Returns
    -------
    str
        Markdown: the verdict, the metrics with names and units, the platoon tests.
    """
    s = ev.summary
    lines = [f"# Evaluation of {run.get('folder', ev.name)} ({ev.name})\n\n",
             f"**Verdict: {verdict}**\n\n",
             f"{s['episodes']} held-out episodes ({run.get('leaders', '')}); τ = {run['tau']} s, "
             f"δ = {run['delta']} s, T* = {run['headway']} s"
             + _loop_words(run) + ".\n\n",
             "| metric | value | unit |\n|---|---|---|\n"]
    for k, (what, unit) in EVALUATION_METRICS.items():
        if k in s:
            lines.append(f"| {what} ({k}) | {_fmt(s[k])} | {unit} |\n")
    if run.get("reaction_delay"):
        lines.append("\nm_fss: share (a fraction in [0, 1]) of executed (episode, moment) gains "
                     "certified by the exact, delay-aware certificate (continuous time, frozen "
                     f"gains) with the reaction delay θ_r = {run['reaction_delay']:g} s; "
                     "m_fss_sampled: by the sampled-data certificate with θ_r of the "
                     f"zero-order-hold loop at the control step dt = {run.get('dt')} s "
                     f"({SAMPLED_NOT_AVAILABLE} when it refuses θ_r).\n\n")
    else:
        lines.append("\nm_fss: share (a fraction in [0, 1]) of executed (episode, moment) gains "
                     "certified by the exact, delay-aware certificate (continuous time, frozen gains); "
                     "m_fss_sampled: by the "
                     "sampled-data certificate of the zero-order-hold loop at the control step "
                     f"dt = {run.get('dt')} s, which the simulator runs.\n\n")
    lines.append("## Platoon test\n\n" + platoon_markdown(platoons))
    return "".join(lines)


def verdict(ev: Evaluation, platoons: Sequence[Mapping[str, Any]], action: str) -> tuple[str, bool]:
    """The one-line verdict of an evaluation and whether it passes.

    It passes (``stringstab evaluate`` exits 0) when every executed gain is certified and there is
    no collision, on the episodes and platoons.

    Parameters
    ----------
    ev : Evaluation
        The evaluation.
    platoons : sequence of mappings
        Its platoon tests.
    action : str
        The policy's action (``"gains"`` or an acceleration).

    Returns
    -------
    (str, bool)
        The verdict and whether it passes.
    """
    s = ev.summary
    gains_ok = s["m_fss"] is not None and s["m_fss"] == 1.0 and all(
        q["m_fss"] == 1.0 for q in platoons)
    no_coll = s["collisions"] == 0 and all(q["collisions"] == 0 for q in platoons)
    if action != "gains":
        return "not certified: an acceleration policy executes no gains to certify", False
    if gains_ok and no_coll:
        return "every executed gain certified, no collision", True
    text = "NOT every executed gain certified" if not gains_ok else "certified gains"
    return text + ("" if no_coll else ", COLLISIONS"), False


def write_evaluation(out: OutputDir, ev: Evaluation, platoons: Sequence[Mapping[str, Any]],
                     run: Mapping[str, Any], verdict: str) -> list[str]:
    """Stage ``evaluation.json``, ``evaluation.md``, ``episodes.csv`` and ``gains.csv``.

    Parameters
    ----------
    out : OutputDir
        The open output folder.
    ev, platoons, run, verdict
        As for :func:`evaluation_markdown`.

    Returns
    -------
    list of str
        The names staged so far.
    """
    doc = {"run": dict(run), "verdict": verdict, "summary": ev.summary,
           "platoons": list(platoons), "episodes": ev.episodes}
    out.write_json("evaluation.json", doc)
    out.write_text("evaluation.md", evaluation_markdown(ev, platoons, run, verdict))
    out.write_text("episodes.csv", ev.episodes_csv())
    if ev.gains is not None:
        out.write_text("gains.csv", ev.gains_csv())
    return out.written


def _ms(v: Any) -> str:
    if isinstance(v, Mapping):
        return f"{v['mean']:.3g} ± {v['std']:.2g}"
    return _fmt(v)


def _mean_std(vals: list[Any]) -> Any:
    xs = [float(v) for v in vals if v is not None]
    if not xs:
        return None
    if len(vals) == 1:
        return xs[0]
    return {"mean": float(np.mean(xs)), "std": float(np.std(xs, ddof=1)) if len(xs) > 1 else 0.0,
            "n": len(xs)}


def write_comparison(out: OutputDir, groups: Mapping[str, Sequence[Evaluation]], *,
                     reference: str | None, tau: float, delta: float, headway: float,
                     platoons: Mapping[str, Mapping[str, Any]] | None = None,
                     loop: Any = None) -> list[str]:
    """Stage the Table-4 comparison tables and its figures in ``out``.

    The tables are ``table.md``, ``table.csv`` and ``comparison.json``; the figures
    ``fig6_mp.png``, ``fig9_ttc.png``, ``fig11_jerk.png``, ``fig12_headway.png`` and
    ``gains_region.png``.

    ``groups`` maps a strategy label to its evaluations (several seeds give mean ± spread).

    Parameters
    ----------
    out : OutputDir
        The open output folder.
    groups : mapping
        ``{strategy: evaluations}``.
    reference : str or None
        The strategy whose improvements are listed.
    tau, delta, headway : float
        The loop's parameters (for the executed-gains figure).
    platoons : mapping, optional
        ``{strategy: {"run": ..., "tests": [...]}}``.
    loop : mapping, optional
        The loop evaluated when not the default (``reaction_delay``, ``radio``, ``sensors``;
        issues 25, 26): said in ``table.md`` and recorded in ``comparison.json``.

    Returns
    -------
    list of str
        The names staged so far.
    """
    from matplotlib.figure import Figure

    loop = dict(loop or {})
    reaction_delay = float(loop.get("reaction_delay", 0.0))

    from .plots import (
        plot_gains_over_region,
        plot_headway_cdf,
        plot_jerk_ranges,
        plot_mp_histogram,
        plot_ttc_distribution,
    )

    keys = ("TIT", "M_CI", "M_effi", "M_lss", "m_fss", "m_fss_sampled", "collisions",
            "share_m_p_below_1", "median_headway")
    summaries = {name: {k: _mean_std([e.summary.get(k) for e in evs]) for k in keys}
                 for name, evs in groups.items()}
    rows = table_rows(summaries, reference)
    md = ["# Comparison on the held-out episodes (IDL paper Table 4 layout)\n\n",
          "↓: lower is better (TIT, M_CI, M_effi, M_lss); ↑: higher is better (m_fss, the share of "
          "executed gains certified; CACC and IDM execute no certified gains). Rows 'X compared "
          "to Y': 100 (Y − X)/Y %, positive when X is better; where Y is 0 the row gives both "
          "values. Mean ± standard deviation over seeds where several runs are given.\n\n",
          *([f"Evaluated with{_loop_words(loop)[1:]}.\n\n"] if loop else []),
          table_markdown(rows), "\n| strategy | collisions | share of episodes with m_p < 1 | "
          "median headway (s) | m_fss sampled at dt (fraction) |\n|---|---|---|---|---|\n"]
    md += [f"| {n} | {_ms(s['collisions'])} | {_ms(s['share_m_p_below_1'])} | "
           f"{_ms(s['median_headway'])} | "
           f"{_sampled_cell(s, reaction_delay)} |\n"
           for n, s in summaries.items()]
    if platoons:
        md.append("\n## Platoon tests (§5.1)\n\n")
        for name, p in platoons.items():
            md.append(f"### {name}\n\n" + platoon_markdown(p["tests"], note=False) + "\n")
        md.append(platoon_markdown([], note=True))
    no_region = reaction_delay > 0 and any(evs[0].gains is not None for evs in groups.values())
    if no_region:
        md.append("\nThe executed gains are not drawn over the certified region (gains_region.png): "
                  "the region map has no reaction delay θ_r.\n")
    out.write_text("table.md", "".join(md))
    out.write_text("table.csv", table_csv(rows))
    out.write_json("comparison.json", {"summaries": summaries, "rows": rows,
                                       "runs": {n: [e.summary for e in evs] for n, evs in groups.items()},
                                       "platoons": platoons or {}, **({"loop": loop} if loop else {})})
    first = {name: evs[0] for name, evs in groups.items()}

    def save(fig: Any, name: str) -> None:
        fig.savefig(out.path(name), dpi=110, bbox_inches="tight")

    n = len(first)
    fig = Figure(figsize=(4.0 * n, 3.4), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, n))
    mp_all = np.concatenate([np.asarray(ev.samples["m_p"], dtype=float) for ev in first.values()])
    mp_all = mp_all[np.isfinite(mp_all)]
    span = (min(float(mp_all.min()), 1.0) - 0.02, max(float(mp_all.max()), 1.0) + 0.02) \
        if mp_all.size else None  # one x-range (and bins) for every panel, 1 included
    for ax, (name, ev) in zip(axes, first.items()):
        plot_mp_histogram(ev.samples["m_p"], ax=ax, label=name, bin_range=span)
    save(fig, "fig6_mp.png")
    for fname, fn, key in (("fig9_ttc.png", plot_ttc_distribution, "ttc"),
                           ("fig11_jerk.png", plot_jerk_ranges, "jerk_sq"),
                           ("fig12_headway.png", plot_headway_cdf, "headway")):
        fig = Figure(figsize=(6.4, 4.0), layout="constrained")
        kw: dict[str, Any] = {"t_star": headway} if key == "headway" else {}
        fn({name: ev.samples[key] for name, ev in first.items()}, ax=fig.subplots(), **kw)
        save(fig, fname)
    gains = {name: ev.gains[:, 2:] for name, ev in first.items() if ev.gains is not None}
    if gains and not no_region:
        fig = Figure(figsize=(6.4, 6.4), layout="constrained")
        plot_gains_over_region(gains, tau=tau, delta=delta, headway=headway, ax=fig.subplots())
        save(fig, "gains_region.png")
    return out.written
