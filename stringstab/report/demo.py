"""The demo's report: the front page of the toolkit, the story of the two papers checked.

Read top to bottom: IDL (derive, certify, map, repair, simulate, train), then HCFS (the jerk
theorem).

Built from the summaries the demo steps return (:func:`stringstab.cli.demo_steps.run_demo`), never from
re-reading their files; the figures are the files the steps wrote, found in the output folder.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from ..certify.verdicts import Verdict
from ..ranges import metric_caveat
from .maths import inline_tex
from .render import Report, Section

__all__ = ["demo_report"]

_INTRO = (
    r"""This report checks two papers on car-following control with the stringstab toolkit, on bundled
data. The **IDL paper** (Yi, Xu & Wang 2026, *Transportation Research Part C* 184:105541) lets a
TD3 agent choose the gains $K = (k_x, k_v, k_a)$ of the linear controller
$u = k_x\,\Delta p + k_v\,\Delta v + k_a\,a_{i-1}(t-\delta)$ (its eq 4) and claims string
stability from a Taylor approximation of the delay (its Proposition 1). The **HCFS paper**
(IEEE T-ASE 2021) switches between a DDPG policy and CACC and proves a jerk bound. Read in order: what the model really
gives (derive), which gains are truly string stable with the exact delay (certify, the region
map), how uncertified gains are repaired (tune), what it means for a platoon (simulate), whether a
trained IDL agent only ever executes certified gains (train), and whether the HCFS jerk theorem
holds in closed loop (hcfs). A gain triple is *certified* when the closed loop is internally
stable and $\Vert\Gamma\Vert_{\mathcal{H}_\infty} \leq 1$ with the exact delay $e^{-\delta s}$;
"printed" means the paper's own formulas.""")


def _plural(n: int, word: str) -> str:
    """``1 triple``, ``2 triples``."""
    return f"{n} {word}{'' if n == 1 else 's'}"


def _k(K: Any) -> str:
    return "(" + ", ".join(f"{float(x):.4g}" for x in K) + ")"


def _natural(name: str) -> list[Any]:
    """Sort key: fig6 before fig11 (numbers compared as numbers)."""
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", name)]


def _files(root: Path, step: str, summary: Mapping[str, Any], sub: str = "") -> list[str]:
    """PNG figures a step wrote, relative to the demo folder, in the step's own order."""
    names = [f for f in summary.get("files", []) if str(f).endswith(".png")]
    found = [f"{step}/{f}" for f in names if (root / step / f).is_file()]
    if sub:
        found += sorted((p.relative_to(root).as_posix() for p in (root / step / sub).glob("*.png")),
                        key=_natural)
    return found


def _derive(rep: Report, s: Mapping[str, Any]) -> None:
    sec = rep.section("1. The model, derived (IDL eqs 3-15)",
                      "SymPy derives the string-stability transfer function "
                      "$\\Gamma(s) = A_i(s)/A_{i-1}(s)$ (follower over predecessor acceleration) "
                      "and the Taylor criteria $\\Psi_1$–$\\Psi_3$, $\\Lambda$ of the IDL paper "
                      "from the vehicle model, then compares them term by term with the printed "
                      "equations.")
    if s.get("gamma_latex"):
        sec.text(f"$${s['gamma_latex']}$$")
    elif s.get("gamma"):
        sec.code(f"Γ(s) = {s['gamma']}")
    table = s.get("errata_table")
    if table:
        sec.table([{"eq": e["equation"],
                    "expression": f"${e['tex']}$" if e.get("tex") else e["name"],
                    "printed = derived": e["matches"],
                    "what differs": inline_tex(e["explanation"])}
                   for e in table], caption="The printed formulas against the derivation "
                                            "(`derive/derive.txt` has every expression).")
        wrong = [e.get("label", e["name"]) for e in table if not e["matches"]]
    else:
        wrong = s.get("errata", [])
    sec.verdict("the paper's printed formulas match the model", not wrong,
                f"{len(wrong)} differ: {', '.join(wrong)}" if wrong else "all match")


def _certify(rep: Report, s: Mapping[str, Any]) -> None:
    sec = rep.section("2. Certifying gains with the exact delay",
                      "Each triple is certified with the exact delay (no Taylor or Padé "
                      "approximation in the verdict), beside the verdict of the paper's printed "
                      "Proposition 1. Where they differ, the paper's test is wrong for that K.")
    rows = []
    misled = 0
    for t in s.get("triples", []):
        exact = t["verdict"] == Verdict.CERTIFIED
        printed = t["taylor_printed"] == "stable"
        misled += printed and not exact
        rows.append({"K = (k_x, k_v, k_a)": _k(t["K"]), "exact verdict": t["verdict"],
                     "$\\sup_\\omega \\vert\\Gamma(j\\omega)\\vert$": t.get("sup_gain"),
                     "printed Proposition 1": t["taylor_printed"],
                     "agree": exact == printed})
    if rows:
        sec.table(rows, caption="Gain triples at τ = 0.1 s, δ = 0.2 s, T* = 1.1 s "
                                "(`certify/triples.txt`); sup |Γ| > 1 means some frequency is "
                                "amplified, inf that the loop is not internally stable.")
        sec.verdict("the printed Proposition 1 agrees with the exact certificate on these triples",
                    misled == 0, f"{_plural(misled, 'triple')} called stable by the paper's test "
                                 f"{'is' if misled == 1 else 'are'} not string stable" if misled
                    else "no triple misjudged")
    r = s.get("rollout")
    if r:
        first = s.get("rollout_first_uncertified_t", {})
        share = r.get("certified_row_share", r.get("m_fss"))
        sec.verdict("every gain of the bundled time series (a policy rollout) is certified",
                    r["certified"] == r["n"],
                    f"{r['certified']} of {r['n']} rows certified (certified_row_share = "
                    f"{share:.3f}: each row counted once, however long its gains hold; m_fss "
                    "weighs them by time, see `simulate --gains-file`); first uncertified moment "
                    "per vehicle: "
                    + (", ".join(f"vehicle {v} at t = {t:g} s" for v, t in first.items()) or "none"))


def _region(rep: Report, s: Mapping[str, Any], root: Path) -> None:
    sec = rep.section("3. The map of string-stable gains",
                      "A 121 × 121 slice over (k_x, k_v) at k_a = 0.5, each point certified "
                      "exactly and judged by the Taylor criteria (derived) and the printed ones.")
    shares = s.get("class_shares", {}).get("exact")
    if shares:
        sec.table([{"class": k, "share of the slice (%)": 100 * v} for k, v in shares.items()],
                  caption="The exact certificate's classes on the slice.", digits=3)
    d = s.get("disagreements")
    if d:
        sec.verdict("the Taylor criteria (derived) agree with the exact certificate on the slice",
                    d.get("exact vs taylor", 0) == 0,
                    f"{d.get('exact vs taylor', 0)} points differ")
        sec.verdict("the printed criteria agree with the exact certificate on the slice",
                    d.get("exact vs printed", 0) == 0,
                    f"{d.get('exact vs printed', 0)} points differ; {d.get('inconclusive', 0)} points "
                    "inconclusive (on the boundary within rounding)")
    sec.figures(_files(root, "region", s))


def _tune(rep: Report, s: Mapping[str, Any], root: Path) -> None:
    sec = rep.section("4. Repairing uncertified gains",
                      "Uncertified triples are moved into the certified region by the paper's "
                      "region-growing search (§3.3) and by the nearest certified point (a CasADi "
                      "projection); the result of each is certified again, exactly.")
    moves = s.get("moves")
    if moves:
        sec.table([{"method": m["method"], "from K": _k(m["from"]), "to K": _k(m["to"]),
                    "distance moved": m["distance"], "certified": m["certified"],
                    "status": m["status"]} for m in moves],
                  caption="Every repair (`tune/tune.txt`); distance in weighted gain units "
                          "(Euclidean with weights 1, 1, 1 on k_x in s⁻², k_v in s⁻¹, k_a "
                          "dimensionless).")
    for method, m in s.get("summary", {}).items():
        sec.verdict(f"{method} returns certified gains for every triple",
                    m["certified"] == m["n"],
                    f"{m['certified']} of {m['n']} certified; median distance moved "
                    f"{m['median_distance_moved']:.3g}")
    sec.figures(_files(root, "tune", s))


_SIM_METRICS = [("max_m_p", "max m_p", ""), ("M_lss", "M_lss", ""), ("collisions", "collisions", ""),
                ("TIT", "TIT", "s²"), ("M_CI", "M_CI", "m²/s⁶"), ("M_effi", "M_effi", "s"),
                ("m_fss", "m_fss", "fraction")]


def _simulate(rep: Report, s: Mapping[str, Any], root: Path) -> None:
    sec = rep.section("5. A platoon of 10 behind a mixed leader",
                      "The certified triple K = (1.2, 0.5, 0.6) against the CACC baseline, "
                      "10 followers, τ = 0.1 s, δ = 0.2 s. m_p (IDL eq 29) is the ratio of a "
                      "follower's acceleration energy to its predecessor's: below 1, disturbances "
                      "shrink along the platoon. m_fss is the share of vehicle-moments whose gains "
                      "are certified (CACC's gains, in its own form, are not).")
    rows = []
    for name in ("certified", "cacc"):
        if name in s:
            r = s[name]
            rows.append({"controller": name, **{label: r.get(k) for k, label, _ in _SIM_METRICS}})
    if rows:
        sec.table(rows, caption="Platoon metrics (lower is better except m_fss).",
                  units={label: u for _, label, u in _SIM_METRICS if u})
    for name in ("certified", "cacc"):
        for k, label, _ in _SIM_METRICS:
            caveat = metric_caveat(k, s.get(name, {}).get(k))
            if caveat:
                sec.verdict(f"{name}: {label} = {s[name][k]:.3g}", None, caveat.strip("()"))
    for name in ("certified", "cacc"):
        if name in s:
            mp = s[name]["max_m_p"]
            sec.verdict(f"{name}: every follower damps the disturbance (m_p < 1)",
                        mp is not None and mp < 1, f"max m_p = {mp:.3f}")
    for name in ("certified", "cacc"):
        if name in s:
            for f in _files(root, "simulate", s[name]):
                sec.figure(f, caption=f"{name}: " + _caption(f))


def _caption(path: str) -> str:
    from .captions import caption_for

    return caption_for(path)


def _train(rep: Report, s: Mapping[str, Any], root: Path) -> None:
    sec = rep.section("6. A trained IDL agent, every executed gain certified",
                      "A short IDL training run (TD3 choosing K, each K repaired to a certified one "
                      "before it acts), evaluated on the 57 held-out episodes beside CACC. The "
                      "budget is small; the certification of every executed gain holds whatever "
                      "the budget, because the repair guarantees it and the evaluation re-checks "
                      "each one.")
    if "skipped" in s:
        sec.verdict("IDL training", None, f"skipped: {s['skipped']}")
        return
    sec.text(f"{s['steps']:,} environment steps ({s['episodes']} episodes) in "
             f"{s['train_seconds']:.0f} s; the repair took {100 * s['repair_share']:.0f} % of it.")
    sec.verdict("every executed gain certified and no collision (held-out episodes and platoon)",
                bool(s.get("passed")), s.get("verdict", ""))
    table = root / "train" / "comparison" / "table.md"
    if table.is_file():
        sec.markdown(table.read_text(encoding="utf-8"), shift=2)
    sec.figures(_files(root, "train", {}, sub="comparison"))
    sec.figures(_files(root, "train", {}, sub="run"))


def _hcfs(rep: Report, s: Mapping[str, Any], root: Path) -> None:
    sec = rep.section("7. The HCFS jerk theorem in closed loop",
                      "HCFS switches between its DDPG policy ($a_1$) and CACC ($a_2$) and proves "
                      "$\\vert a_k - a_{k-1}\\vert \\leq J\\,T$. The proof needs "
                      "$a_{1,k-1} = a_{2,k-1}$ (premise P3), which the switch does not ensure. The verification checks premises and "
                      "conclusion at every frame, behind the paper's case 1 (UDDS at half speed, "
                      f"8 followers), J = 2.5 m/s³, with {s.get('policy', 'the bundled DDPG')}.")
    rows = []
    for key, r in s.get("results", {}).items():
        mode, _, J = key.partition(" ")
        rows.append({"mode": mode, "J": J.removeprefix("J="), "max jerk": r["max_jerk"],
                     "frames above J T": r["conclusion_fails"],
                     "counterexamples (P3 fails)": r["counterexamples"],
                     "theorem violations": r["violations"], "collisions": r["collisions"]})
    if rows:
        sec.table(rows, caption="Modes: cacc and policy alone, paper = HCFS eqs 12-14, safe = the "
                                "jerk-safe variant (`hcfs/report.md` has the full tables).",
                  units={"J": "m/s³", "max jerk": "m/s³"})
        paper = s["results"].get("paper J=2.5")
        safe = s["results"].get("safe J=2.5")
        if paper:
            sec.verdict("the paper's switch keeps the jerk within J", paper["conclusion_fails"] == 0,
                        f"max jerk {paper['max_jerk']:.3g} m/s³; {paper['counterexamples']} "
                        "frames where P1, P2 hold but P3 does not")
        sec.verdict("no frame falsifies the theorem as stated (with P3), nor the bound without it",
                    bool(s.get("ok")), "0 violations" if s.get("ok") else "violations found")
        if safe:
            sec.verdict("the jerk-safe variant keeps the jerk within J", safe["conclusion_fails"] == 0,
                        f"max jerk {safe['max_jerk']:.3g} m/s³")
    sec.figures(_files(root, "hcfs", s))


def demo_report(summary: Mapping[str, Any], root: str | Path, *, command: str,
                params: Mapping[str, Any] | None = None, started: float | None = None) -> Report:
    """Build the demo's report from the steps' summaries.

    Parameters
    ----------
    summary : mapping
        ``{step: summary}`` as returned by :func:`stringstab.cli.demo_steps.run_demo` (steps not run are
        left out of the report).
    root : path-like
        The folder holding the steps' outputs (the demo's staging folder while it runs).
    command : str
        The command that ran the demo.
    params : mapping, optional
        τ, δ, T* and anything else to list under the command.
    started : float, optional
        ``time.perf_counter()`` when the demo started.

    Returns
    -------
    Report
        Write it with :meth:`Report.write`.
    """
    root = Path(root)
    rep = Report("stringstab demo: the IDL and HCFS papers, checked", command=command,
                 params={k: f"{v:g} s" if isinstance(v, float) else v
                         for k, v in (params or {}).items()}, intro=_INTRO, started=started)
    glance = rep.section("The findings at a glance",
                         "Each line is a claim checked by this run; the sections below give the "
                         "evidence.")
    builders: list[tuple[str, Callable[[Report, Mapping[str, Any], Path], None]]] = [
        ("derive", lambda r, s, _: _derive(r, s)), ("certify", lambda r, s, _: _certify(r, s)),
        ("region", _region), ("tune", _tune), ("simulate", _simulate), ("train", _train),
        ("hcfs", _hcfs)]
    for name, build in builders:
        if name in summary:
            build(rep, summary[name], root)
    _glance(glance, rep.sections[1:])
    times = rep.section("Run time per step")
    times.table([{"step": n, "seconds": s.get("seconds")} for n, s in summary.items()],
                caption="Wall time of each step (the total is at the top).", digits=3)
    return rep


def _glance(glance: Section, sections: list[Section]) -> None:
    """Copy every verdict of the sections into the first one, with the section it comes from."""
    for sec in sections:
        for b in sec.blocks:
            if b.kind == "verdict":
                glance.verdict(b.data["what"], b.data["passed"],
                               f"{b.data['detail']} (§{sec.title.split('.')[0]})")
