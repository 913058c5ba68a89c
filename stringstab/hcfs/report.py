"""The verification report: Markdown and JSON, and the figures (Figs 4-6 of the paper, per J).

:func:`write_report` writes into a folder ``report.md``, ``report.json`` and, per leader and
jerk limit, ``speed_*.png``, ``jerk_*.png`` and ``switching_*.png``, all-or-nothing
(:class:`stringstab.io.OutputDir`).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

from ..io import OutputDir
from .theorem import Case, tight_example, weight_change
from .verify import Frame, Verification

__all__ = ["THEOREM", "report_dict", "report_markdown", "write_report"]

#: The theorem, its premises and conclusion, and the bound that holds, as the report states them.
THEOREM: dict[str, Any] = {
    "source": "HCFS paper, section III-C, theorem and proof (eqs 13-21)",
    "premises": {
        "P1": "|a1_k - a1_(k-1)| <= J T  (DDPG candidate rate-limited)",
        "P2": "|a2_k - a2_(k-1)| <= J T  (CACC candidate rate-limited)",
        "P3": "a1_(k-1) = a2_(k-1)  ('under the framework of HCFS', used in the proof's eq 19)",
    },
    "conclusion": "|aₖ - a_(k-1)| <= J T for the hybrid output a of eqs 13-14, "
                  "a_(k-1) being the previous hybrid output",
    "bound": "under P1 and P2 alone: |aₖ - a_(k-1)| <= J T + |lambdaₖ - lambda_(k-1)| "
             "|a1_(k-1) - a2_(k-1)|, with |lambdaₖ - lambda_(k-1)| = 0 (no switch at k-1 or k), "
             "1 - beta (switch at k), beta (switch at k-1 only), |1 - 2 beta| (both); attained",
    "safe_variant": "aₖ = clip(eq-13 output, a_(k-1) - J T, a_(k-1) + J T): "
                    "|aₖ - a_(k-1)| <= J T under P1 and P2 alone",
    "tolerance": "every inequality is read up to 1e-9 m/s^2 (float rounding is ~1e-15)",
}


def _f(x: float, nd: int = 3) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "—"
    return f"{x:.{nd}g}" if abs(x) < 1e4 else f"{x:.0f}"


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9.]+", "-", text).strip("-").lower() or "leader"


def _figure_names(ver: Verification) -> list[tuple[int, float, dict[str, str]]]:
    out = []
    for r, run in enumerate(ver.runs):
        stem = f"{r + 1}-{_slug(run.leader.name)}"
        for J in ver.jerk_limits:
            tag = f"{stem}_J{J:g}"
            out.append((r, J, {kind: f"{kind}_{tag}.png" for kind in ("speed", "jerk", "switching")}))
    return out


def report_dict(ver: Verification, *, command: str | None = None) -> dict[str, Any]:
    """Everything the report states, JSON-ready: the theorem, the set-up, the results.

    Parameters
    ----------
    ver : Verification
        The verification (:func:`stringstab.hcfs.verify.verify`); the set-up is read from its
        first run.
    command : str, optional
        The command that reproduces the run, recorded as ``command``.

    Returns
    -------
    dict
        ``theorem`` (:data:`THEOREM`: HCFS §III-C, eqs 13-21), ``setup`` (leaders, N, T, β,
        jerk limits, 2a_max/T, δ, L, h, limits, ω1, ω2, CACC gains, policy label),
        :meth:`Verification.to_dict`'s entries, and ``exit_code`` (0 if the verification
        passed, else 1).
    """
    run = ver.runs[0]
    p = run.params
    doc: dict[str, Any] = {
        "theorem": THEOREM,
        "setup": {
            "leaders": [{"name": r.leader.name, "duration_s": r.leader.duration,
                         "frames": r.leader.n_steps} for r in ver.runs],
            "n_followers": run.n_followers, "dt": run.dt, "beta": ver.beta,
            "jerk_limits": list(ver.jerk_limits),
            "paper_threshold_2amax_over_T": 2.0 * p["accel_max"] / run.dt,
            **{k: p[k] for k in ("delay", "length", "spacing", "accel_min", "accel_max",
                                 "speed_max", "omega_1", "omega_2", "cacc_gains", "cacc_label",
                                 "policy_label", "policy_is_stand_in")},
        },
        **ver.to_dict(),
        "exit_code": 0 if ver.ok else 1,
    }
    if command:
        doc["command"] = command
    return doc


def _frame_row(f: Frame) -> str:
    sw = {(False, False): "none", (False, True): "switch at k", (True, False): "switch at k-1",
          (True, True): "switch at k-1 and k"}[(f.prev_switch, f.switch)]
    return (f"| {f.leader} | {f.jerk_limit:g} | {f.vehicle} | {f.frame} | {f.t:.1f} | {_f(f.jerk)} | "
            f"{_f(f.gap_prev, 4)} | {sw} | {_f(f.weight_change)} | {_f(f.bound / f.step_limit, 4)} |")


def report_markdown(ver: Verification, *, command: str | None = None,
                    figures: list[tuple[int, float, dict[str, str]]] | None = None) -> str:
    """The report as Markdown (see :func:`write_report`).

    Parameters
    ----------
    ver : Verification
        The verification; the set-up is read from its first run.
    command : str, optional
        The command that reproduces the run (a "Reproduce" section).
    figures : list of (int, float, dict), optional
        ``(run index, J, {kind: file name})`` of the figures to link (a "Figures" section);
        None for none.

    Returns
    -------
    str
        The Markdown text, ending in a newline.
    """
    run = ver.runs[0]
    p = run.params
    T = run.dt
    lines: list[str] = []
    add = lines.append
    add("# HCFS jerk theorem: closed-loop verification\n")
    if ver.ok:
        add("**No frame falsifies the theorem where its premises P1-P3 hold, none exceeds the bound "
            "J T + |Δλ|·|a1ₖ₋₁ − a2ₖ₋₁| where P1 and P2 hold, and the jerk-safe variant keeps "
            "|aₖ − aₖ₋₁| ≤ J T everywhere (exit 0).**\n")
    else:
        add(f"**{len(ver.violations)} frame(s) falsify a guarantee (exit 1); they are listed below.**\n")
    if p["policy_is_stand_in"]:
        add(f"> The learned candidate a1 is a **stand-in**, not a DDPG: {p['policy_label']}.\n")
    add("## The theorem (HCFS paper, §III-C)\n")
    add("At every frame k, with a1 = a_DDPG, a2 = a_CACC and the hybrid output a of eqs 13-14:\n")
    for k, v in THEOREM["premises"].items():
        add(f"* **{k}**: `{v}`")
    add(f"* **Conclusion**: `{THEOREM['conclusion']}`\n")
    add("What holds (proof in docs/hcfs.md): under P1 and P2 alone,\n")
    add("    |aₖ − aₖ₋₁| ≤ J T + |λₖ − λₖ₋₁| · |a1ₖ₋₁ − a2ₖ₋₁|,\n")
    b = ver.beta
    wc = weight_change([False, True, False, True], [False, False, True, True], b)
    add(f"with |λₖ − λₖ₋₁| = {wc[0]:g} (no switch at k−1 or k), {wc[1]:g} (the frame after a "
        f"switch), {wc[2]:g} (a switch at k), {wc[3]:g} (switches at both) for β = {b:g}; the bound "
        "is attained.  P3 removes the second term: the theorem is true, and fails without P3.  The "
        "jerk-safe variant clips the eq-13 output into aₖ₋₁ ± J T and needs only P1 and P2.  "
        f"Inequalities are read up to 10⁻⁹ m/s².\n")
    add("## Set-up\n")
    leaders = ", ".join(f"`{r.leader.name}` ({r.leader.duration:g} s)" for r in ver.runs)
    add(f"* Leaders: {leaders}; {run.n_followers} followers; T = {T:g} s; V2V delay "
        f"{p['delay'] * 1e3:g} ms on the predecessor's and leader's position and speed.")
    add(f"* Jerk limits J = {', '.join(f'{J:g}' for J in ver.jerk_limits)} m/s³ (the paper's "
        f"figures use 2a_max/T = {2 * p['accel_max'] / T:g} m/s³, which the bounds "
        f"[{p['accel_min']:g}, {p['accel_max']:g}] m/s² guarantee alone); each candidate is "
        "rate-limited to J T about its own previous value (P1, P2).")
    add(f"* β = {b:g}; reward ω1 = {p['omega_1']:g}, ω2 = {p['omega_2']:g}, v_max = "
        f"{p['speed_max']:g} m/s; spacing L + h = {p['length']:g} + {p['spacing']:g} m.")
    add(f"* a2: {p['cacc_label']}.")
    add(f"* a1: {p['policy_label']}.\n")
    add("Modes: `cacc` and `policy` apply one candidate; `paper` is HCFS by eqs 12-14; `safe` is "
        "HCFS with the jerk-safe variant.\n")
    add("## Results\n")
    add("Totals over all followers and frames.  *max jerk* is max |aₖ − aₖ₋₁|/T of the "
        "command; *P3 holds* counts frames with a1ₖ₋₁ = a2ₖ₋₁; *C fails* counts frames with "
        "|aₖ − aₖ₋₁| > J T; *viol.* frames falsifying a guarantee; *cex* counterexamples (P1, "
        "P2 hold, P3 and C fail); *step/bound* the largest |aₖ − aₖ₋₁| / bound (≤ 1).\n")
    for r, rn in enumerate(ver.runs):
        add(f"### {rn.leader.name}, {rn.n_followers} followers\n")
        add("| mode | J | max jerk | max jerk / J | frames | P1 fails | P2 fails | P3 holds | "
            "C fails | viol. | cex | step/bound | collisions | Σ\\|e_v\\| | Σ\\|jerk\\| | Σr | "
            "policy share |")
        add("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        rows = [x for x in ver.results if x["run"] == r]
        for x in rows:
            t = x["totals"]
            viol = t["violations"] + t["bound_violations"] + (
                t["conclusion_fails"] if x["mode"] != "paper" else 0)
            add(f"| {x['mode']} | {x['jerk_limit']:g} | {_f(t['max_jerk'])} | "
                f"{_f(t['max_jerk_over_J'])} | {t['frames']} | {t['P1_fails']} | {t['P2_fails']} | "
                f"{t['P3_holds']} | {t['conclusion_fails']} | {viol} | {t['counterexamples']} | "
                f"{_f(t['max_step_over_bound'], 4)} | {t['collisions']} | "
                f"{_f(t['sum_abs_speed_error'], 4)} | {_f(t['sum_abs_jerk'], 4)} | "
                f"{_f(t['sum_reward'], 4)} | {_f(t['ddpg_share'], 2)} |")
        add("")
        paper = [x for x in rows if x["mode"] == "paper"]
        if paper:
            add("Max jerk of the HCFS (eqs 12-14) command per follower, m/s³:\n")
            add("| J | " + " | ".join(f"veh {v['vehicle']}" for v in paper[0]["vehicles"]) + " |")
            add("|---|" + "---|" * len(paper[0]["vehicles"]))
            for x in paper:
                add(f"| {x['jerk_limit']:g} | " + " | ".join(_f(v["max_jerk"]) for v in x["vehicles"]) + " |")
            add("")
    add("## Counterexamples (P3 dropped)\n")
    add(f"{len(ver.counterexamples)} frame(s) of the `paper` mode have P1 and P2 but not P3, and "
        "|aₖ − aₖ₋₁| > J T.  *Smallest* means the smallest |a1ₖ₋₁ − a2ₖ₋₁| (the amount "
        "by which P3 fails), then the smallest excess; every one lies within the bound.\n")
    sm = ver.smallest_counterexample
    if sm is not None:
        add("| leader | J | vehicle | frame k | t (s) | jerk (m/s³) | \\|a1−a2\\| at k−1 (m/s²) | "
            "switch state | \\|Δλ\\| | bound / (J T) |")
        add("|---|---|---|---|---|---|---|---|---|---|")
        add("| smallest → " + _frame_row(sm)[2:])
        for f in [f for f in sorted(ver.counterexamples, key=lambda f: -f.excess)
                  if f is not sm][:15]:
            add(_frame_row(f))
        add("\n(the smallest, then the largest excesses; all frames are in report.json.)\n")
        case: Case = "switch" if sm.switch and not sm.prev_switch else (
            "after-switch" if sm.prev_switch and not sm.switch else "double-switch")
        a1, a2, c = tight_example(sm.jerk_limit, gap=sm.gap_prev, case=case, beta=b, dt=T)
        add(f"The same failure in two frames (`tight_example(J={sm.jerk_limit:g}, "
            f"gap={sm.gap_prev:.4g}, case='{case}')`): a1 = {a1.round(6).tolist()}, "
            f"a2 = {a2.round(6).tolist()}, DDPG chosen = {c.tolist()}: P1 and P2 hold with "
            f"equality and |a_1 − a_0| = J T + |Δλ|·{sm.gap_prev:.4g}.  Since this works for any "
            "gap ≠ 0, no relaxation |a1ₖ₋₁ − a2ₖ₋₁| ≤ ε of P3 with ε > 0 saves the "
            "conclusion.\n")
    if ver.violations:
        add("## Frames falsifying a guarantee\n")
        add("| leader | J | vehicle | frame k | t (s) | jerk (m/s³) | \\|a1−a2\\| at k−1 | switch "
            "state | \\|Δλ\\| | bound / (J T) |")
        add("|---|---|---|---|---|---|---|---|---|---|")
        for f in ver.violations[:50]:
            add(_frame_row(f) + f" ({f.mode})")
        add("")
    if figures:
        add("## Figures\n")
        add("Speed (Fig. 4), jerk with ±J and ±2a_max/T drawn (Fig. 5), and the switching pattern "
            "(Fig. 6) for every mode.\n")
        for r, J, names in figures:
            add(f"### {ver.runs[r].leader.name}, J = {J:g} m/s³\n")
            for kind, name in names.items():
                add(f"![{kind}]({name})")
            add("")
    if command:
        add("## Reproduce\n")
        add(f"```console\n$ {command}\n```\n")
    return "\n".join(lines) + "\n"


def write_report(ver: Verification, out: str | Path | OutputDir, *, figures: bool = True,
                 command: str | None = None, started: float | None = None,
                 progress: Any = None) -> dict[str, str]:
    """Write ``report.md``, ``report.json`` and (optionally) the figures into ``out``.

    ``out`` is a folder path or an open :class:`~stringstab.io.OutputDir`; a path is written
    all-or-nothing through one (command ``"hcfs verify"``): a failure leaves the folder as it was.

    ``report.md`` and its self-contained ``report.html`` are rendered by
    :class:`stringstab.report.Report`, every figure with its caption.

    Parameters
    ----------
    ver : Verification
        The verification.
    out : path or OutputDir
        The folder.
    figures : bool, optional
        Draw the figures (speed, jerk, switching per leader and J).
    command : str, optional
        The command that reproduces the run, shown in the report.
    started : float, optional
        ``time.perf_counter()`` at the start of the run, for the report's wall time.
    progress : callable, optional
        ``progress(total)`` is called once with the number of figures to draw (0 without
        figures) and returns a callable called with 1 after each figure (e.g. a
        :class:`stringstab.progress.Progress`'s ``update``).

    Returns
    -------
    dict
        ``{kind: file name}`` of everything written.
    """
    if not isinstance(out, OutputDir):
        with OutputDir(out, command="hcfs verify") as od:
            return write_report(ver, od, figures=figures, command=command, started=started,
                                progress=progress)
    files: dict[str, str] = {}
    figs = _figure_names(ver) if figures else None
    done = None if progress is None else progress(sum(len(n) for _, _, n in figs or []))
    if figs:
        from matplotlib.figure import Figure

        from .plots import plot_figure

        for r, J, names in figs:
            for kind, name in names.items():
                n_panels = 4 if kind != "switching" else 2
                n = ver.runs[r].n_followers  # jerk: a panel per follower and mode
                height = 1.25 * n + 1.6 if kind == "jerk" and n > 1 else 2.2 * n_panels + 0.6
                # 9 in at 110 dpi: 990 px, shown at full size in the report (text ≥ 8 pt)
                fig = Figure(figsize=(9, height), layout="constrained")
                plot_figure(ver.runs[r], J, kind, fig=fig)
                fig.savefig(out.path(name), dpi=110)
                files[name] = name
                if done is not None:
                    done(1)
    out.write_json("report.json", report_dict(ver, command=command))
    files["json"] = "report.json"
    from ..report import Report, caption_for

    body = report_markdown(ver, command=None, figures=None).split("\n", 1)[1]
    rep = Report("HCFS jerk theorem: closed-loop verification",
                 command=command or "stringstab hcfs verify", started=started)
    rep.section("Verification").markdown(body, shift=1)
    if figs:
        sec = rep.section("Figures", "Speed (Fig. 4), jerk (Fig. 5) and the switching pattern "
                                     "(Fig. 6) for every mode.")
        for r, J, names in figs:
            for name in names.values():
                sec.figure(name, caption=f"{ver.runs[r].leader.name}, J = {J:g} m/s³. "
                                         + caption_for(name))
    rep.write(out)
    files["markdown"] = "report.md"
    files["html"] = "report.html"
    return files
