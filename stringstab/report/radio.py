"""The outputs and the report of ``stringstab radio`` (:mod:`stringstab.traffic.radio_study`).

:func:`write_study` writes the table (``table.csv``, ``table.md``), every replicate's values
(``study.json``) and the figures (``amplification.png``, ``links.png``); :func:`radio_report`
builds the report from the study and the names written.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from typing import Any

from .render import Report
from .skeleton import add_figures

__all__ = ["AMPLIFICATION_CAPTION", "LINKS_CAPTION", "markdown_table", "radio_report", "write_study"]

#: Caption of ``amplification.png``.
AMPLIFICATION_CAPTION = (
    "Measured amplification (max m_p along the string, IDL eq 29: the largest per-link ℓ2 "
    "gain) against the message loss rate, one line per burst length, the band the Student-t "
    "confidence interval of the mean over the seeds; one panel per gain triple. The dashed line "
    "is the bound 1 the certificates prove for the loop without loss; random loss is covered by "
    "no certificate.")
#: Caption of ``links.png``.
LINKS_CAPTION = (
    "m_p of every link (mean over the seeds) along the platoon, one line per loss rate (darker: "
    "lower); rows: gain triples, columns: burst lengths. Above the dashed line the link amplifies.")

#: Columns of ``table.md``: (key, heading).
_MD_COLUMNS = [("K", "K"), ("loss", "loss p"), ("burst", "burst"), ("max_m_p", "max m_p [CI]"),
               ("gain_first", "‖a_N‖/‖a_1‖ [CI]"), ("gain_leader", "‖a_N‖/‖a_0‖ [CI]"),
               ("loss_share", "lost"), ("collisions", "collisions"),
               ("cert", "loop without loss: continuous / sampled"), ("covered", "covered by")]


def _num(v: Any, spec: str = ".4f") -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "n/a"
    return f"{v:{spec}}"


def _cells(r: dict[str, Any]) -> dict[str, str]:
    ci = {m: f"{_num(r[m])} [{_num(r[m + '_lo'])}, {_num(r[m + '_hi'])}]"
          for m in ("max_m_p", "gain_first", "gain_leader")}
    samp = "n/a" if r["sampled"] is None else f"{r['sampled']} ({_num(r['sampled_sup_gain'], '.4g')})"
    return {"K": f"({r['k_x']:g}, {r['k_v']:g}, {r['k_a']:g})", "loss": f"{r['loss']:g}",
            "burst": "independent" if r["burst"] == 1 else f"{r['burst']:g}", **ci,
            "loss_share": _num(r["loss_share"], ".4f"), "collisions": str(r["collisions"]),
            "cert": f"{r['continuous']} ({_num(r['continuous_sup_gain'], '.4g')}) / {samp}",
            "covered": r["covered"]}


def markdown_table(rows: Sequence[dict[str, Any]]) -> str:
    """The rows of :meth:`RadioStudy.rows` as a Markdown table (``table.md``'s body).

    Parameters
    ----------
    rows : sequence of dict
        The study's rows.

    Returns
    -------
    str
        A Markdown table, one line per row.
    """
    head = "| " + " | ".join(h for _, h in _MD_COLUMNS) + " |\n|" + "---|" * len(_MD_COLUMNS)
    body = ["| " + " | ".join(_cells(r)[k].replace("|", "\\|") for k, _ in _MD_COLUMNS) + " |"
            for r in rows]
    return "\n".join([head, *body])


def _figures(study: Any, out: Any) -> list[str]:
    from matplotlib.figure import Figure

    from ..plots.radio import plot_amplification_vs_loss, plot_link_gains

    G, B = len(study.gains), len(study.bursts)
    fig = Figure(figsize=(6.2 * G, 4.4), layout="constrained")
    axes = fig.subplots(1, G, squeeze=False)[0]
    for g in range(G):
        plot_amplification_vs_loss(study, triple=g, ax=axes[g])
    fig.savefig(out.path("amplification.png"), dpi=110)
    fig = Figure(figsize=(5.2 * B, 3.6 * G), layout="constrained")
    axes2 = fig.subplots(G, B, squeeze=False)
    for g in range(G):
        for b in range(B):
            plot_link_gains(study, triple=g, burst=b, ax=axes2[g, b])
    fig.savefig(out.path("links.png"), dpi=110)
    return ["amplification.png", "links.png"]


def write_study(study: Any, out: Any, *, figures: bool = True) -> list[str]:
    """Write ``table.csv``, ``table.md``, ``study.json`` and the figures into an open folder.

    Parameters
    ----------
    study : RadioStudy
        The study.
    out : OutputDir
        The open output folder (committed by the caller).
    figures : bool
        Also draw ``amplification.png`` and ``links.png``.

    Returns
    -------
    list of str
        The names written.
    """
    from ..io import dumps_json

    rows = study.rows()
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow({k: "" if v is None else v for k, v in r.items()})
    out.write_text("table.csv", buf.getvalue())
    s = study.settings
    out.write_text("table.md", "# Loss and noise, measured\n\n" + _intro(study) + "\n\n"
                   + markdown_table(rows) + "\n")
    doc = {"settings": s, "gains": study.gains.tolist(), "losses": study.losses.tolist(),
           "bursts": study.bursts.tolist(), "seeds": study.seeds,
           "certificates": study.certificates,
           "exceedance": [[study.exceedance(g, b) for b in range(len(study.bursts))]
                          for g in range(len(study.gains))],
           "not_covered": _not_covered(),
           "replicates": {"m_p": study.m_p.tolist(), "gain_first": study.gain_first.tolist(),
                          "gain_leader": study.gain_leader.tolist(),
                          "loss_share": study.loss_share.tolist(),
                          "fallback_share": study.fallback_share.tolist(),
                          "collisions": study.collisions.tolist(),
                          "axes": ["gains", "bursts", "losses", "seeds", "links (m_p only)"]},
           "rows": rows}
    out.write_text("study.json", dumps_json(doc))
    files = ["table.csv", "table.md", "study.json"]
    if figures:
        files += _figures(study, out)
    return files


def _not_covered() -> str:
    from ..traffic.radio_study import NOT_COVERED

    return NOT_COVERED


def _intro(study: Any) -> str:
    s = study.settings
    return (f"Leader {s['leader']} ({s['duration']:g} s), {s['followers']} followers, τ = {s['tau']:g} s, "
            f"δ = {s['delta']:g} s, T* = {s['headway']:g} s, H = {s['dt']:g} s, messages every "
            f"{s['message_period']:g} s (held), {study.seeds} seeds per point (replicates: the "
            f"platoons of one batch seeded by {s['seed']}); intervals: {s['interval']}. "
            "Burst 'independent': Bernoulli losses; a number: Gilbert–Elliott bursts of that mean "
            "length. The certificates are of the loop without loss (continuous; sampled at H with "
            "a message every step; the multi-rate certificate of messages every P is not on this "
            f"branch); {_not_covered()}.")


def radio_report(study: Any, files: Sequence[str], *, command: str,
                 started: float | None = None) -> Report:
    """The report of ``stringstab radio``: settings, the loss rate where amplification exceeds 1, the table, the figures.

    Parameters
    ----------
    study : RadioStudy
        The study.
    files : sequence of str
        The names written (the figures among them are shown).
    command : str
        The command line.
    started : float, optional
        ``time.perf_counter()`` at the start of the command.

    Returns
    -------
    Report
        The report.
    """
    s = study.settings
    params = {k: s[k] for k in ("tau", "delta", "headway", "dt", "message_period", "followers",
                                "leader", "seed") if k in s}
    rep = Report("Loss and noise, measured", command=command, params=params, started=started,
                 intro=_intro(study))
    sec = rep.section("Where the measured amplification first exceeds 1",
                      "Linear interpolation over the loss-rate grid of the mean of max m_p; the "
                      "interval runs from where the upper confidence bound crosses 1 to where the "
                      "lower one does.")
    table = []
    for g, k in enumerate(study.gains):
        c = study.certificates[g]
        for b, burst in enumerate(study.bursts):
            e = study.exceedance(g, b)
            table.append({"K": f"({k[0]:g}, {k[1]:g}, {k[2]:g})",
                          "continuous": c["continuous"]["verdict"],
                          "sampled at H": "n/a" if c["sampled"] is None else c["sampled"]["verdict"],
                          "losses": "independent" if burst == 1 else f"bursts of {burst:g}",
                          "exceeds 1 at p": "not on the grid" if e["loss"] is None else f"{e['loss']:.3g}",
                          "interval": ("" if e["loss"] is None and e["loss_lo"] is None else
                                       f"{'n/a' if e['loss_lo'] is None else format(e['loss_lo'], '.3g')}"
                                       f" – {'beyond the grid' if e['loss_hi'] is None else format(e['loss_hi'], '.3g')}")})
    sec.table(table)
    rep.section("Table").markdown(markdown_table(study.rows()), shift=1)
    add_figures(rep, (f for f in files if f.endswith(".png")),
                lambda f: AMPLIFICATION_CAPTION if f == "amplification.png" else LINKS_CAPTION)
    rep.section("Files").text(", ".join(f"`{f}`" for f in files))
    return rep
