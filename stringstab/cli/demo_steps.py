"""The main job: a demo of the whole pipeline on bundled data (``stringstab demo``).

Each capability of the toolkit contributes one *step*: a function
``step(out: Path, log: Callable[[str], None]) -> dict`` that calls the library, writes its
outputs under ``out`` and returns a small summary built from the results it computed (never
from files it wrote).  :func:`run_demo` runs them in order and writes ``summary.json``; the
output folder is checked before any step runs and written all-or-nothing
(:class:`stringstab.io.OutputDir`), so a failed demo leaves an earlier one untouched and a
new one replaces it whole.
"""

from __future__ import annotations

import inspect
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..constants import DELTA, HEADWAY, TAU

__all__ = ["DEMO_TRIPLES", "STEPS", "TRAIN_STEPS", "TUNE_TRIPLES", "run_demo"]

Log = Callable[[str], None]
Step = Callable[..., dict[str, Any]]  # (out, log) plus limits= for LIMITED_STEPS

PARAMS = {"tau": TAU, "delta": DELTA, "headway": HEADWAY}
ROLLOUT = Path(__file__).parents[1] / "data" / "examples" / "gain_rollout.csv"


def _step_derive(out: Path, log: Log) -> dict[str, Any]:
    """Derive Γ(s), Ψ1-Ψ3, Λ and compare with the printed formulas."""
    from ..derive.derivation import derivation
    from ..io import atomic_write_text

    d = derivation(None, None, with_errata=True)
    doc = d.document
    atomic_write_text(out / "derive.json", d.json())
    atomic_write_text(out / "derive.tex", d.latex())
    atomic_write_text(out / "derive.txt", d.text())
    wrong = [_errata_label(e) for e in doc["errata"] if not e["matches"]]
    log(f"derived Γ(s) = {doc['gamma']}")
    log(f"errata: {len(wrong)} printed formulas differ from the derivation: {', '.join(wrong)}")
    return {"files": ["derive.json", "derive.tex", "derive.txt"], "errata": wrong,
            "gamma": doc["gamma"], "gamma_latex": _gamma_latex(d.exprs["gamma"]),
            "errata_table": [{**{k: e[k] for k in ("equation", "name", "matches", "explanation")},
                              "label": _errata_label(e),
                              "tex": d.labels.get(e["key"], ("", ""))[1]}
                             for e in doc["errata"]]}


def _errata_label(e: dict[str, Any]) -> str:
    """How a printed formula is named for a reader: ``eq 11 (denominator of Γ(s))``.

    Parameters
    ----------
    e : dict
        One erratum (:meth:`stringstab.derive.errata.Erratum.as_dict`).

    Returns
    -------
    str
        ``eq N (name)`` for a numbered equation, the name alone otherwise (``Proposition 1
        (logic)``).
    """
    eq = str(e["equation"])
    return f"eq {eq} ({e['name']})" if eq.isdigit() else str(e["name"])


def _gamma_latex(gamma: Any) -> str:
    """Γ(s) in TeX, T* written as such (the derivation's symbol is ``headway``)."""
    import sympy as sp

    subs = {x: sp.Symbol("T^*") for x in gamma.free_symbols if x.name == "headway"}
    return r"\Gamma(s) = " + sp.latex(gamma.subs(subs))


#: Paper-style gain triples for the certify step: the two of ``stringstab certify --help``,
#: a moderate CACC-like triple, one with Ψ3 < 0 and one that is not internally stable.
DEMO_TRIPLES = ["0.9,-0.5,1.1", "1.3,0,0.6", "0.45,0.6,0.3", "0.2,0.7,0", "-0.5,1,1"]


def _step_certify(out: Path, log: Log) -> dict[str, Any]:
    """Certify a few triples and a bundled gain time series (exact delay)."""
    import numpy as np

    from ..certify.api import certify_batch
    from ..io import GainTable, parse_triple, read_gains, write_results

    params = {**PARAMS, "method": "exact"}
    files = []
    tables = {"triples": GainTable.from_triples([parse_triple(t) for t in DEMO_TRIPLES]),
              "rollout": read_gains(ROLLOUT)}
    batches = {}
    for name, g in tables.items():
        b = batches[name] = certify_batch(g.k_x, g.k_v, g.k_a, tau=TAU, delta=DELTA, headway=HEADWAY)
        columns = {**g.meta_columns(), **b.columns()}
        for fmt in ("json", "table") if name == "triples" else ("json", "csv", "table"):
            fname = f"{name}.{'txt' if fmt == 'table' else fmt}"
            write_results(columns, out / fname, fmt, params=params, summary=b.summary(),
                          table=b.table_columns())
            files.append(fname)
    triples = batches["triples"]
    for i in range(len(triples)):
        c = triples[i]
        sup = f"{c.sup_gain:.4g}"
        log(f"K=({c.k_x:g}, {c.k_v:g}, {c.k_a:g}): {c.verdict} (sup|Γ| = {sup}); "
            f"printed Proposition 1: {c.taylor_printed['sign']}")
    roll, g = batches["rollout"], tables["rollout"]
    s = roll.summary()
    first_bad: dict[str, float] = {}
    assert g.vehicle is not None and g.t is not None
    for i in np.flatnonzero(~roll.certified).tolist():
        first_bad.setdefault(str(g.vehicle[i]), float(g.t[i]))
    log(f"gain time series ({ROLLOUT.name}): {s['certified']} of {s['n']} rows certified "
        f"(certified_row_share = {s['certified_row_share']:.3f}, each row counted once); first "
        f"uncertified t per vehicle: {first_bad}")
    return {
        "files": files,
        "params": params,
        "triples": [{"K": [float(triples.k_x[i]), float(triples.k_v[i]), float(triples.k_a[i])],
                     "verdict": str(triples.verdict[i]),
                     "sup_gain": float(triples.sup_gain[i]),
                     "taylor_printed": triples[i].taylor_printed["sign"]}
                    for i in range(len(triples))],
        "rollout": s,
        "rollout_first_uncertified_t": first_bad,
    }


def _step_simulate(out: Path, log: Log, limits: Any = None) -> dict[str, Any]:
    """A 10-vehicle platoon behind the §5.1-style leader: certified gains vs the CACC baseline."""
    from ..traffic.controllers import CACCController, LinearController
    from ..traffic.leaders import leader_by_name
    from ..traffic.limits import check_leader
    from ..traffic.output import run_document, write_run
    from ..traffic.platoon import simulate

    leader = leader_by_name("mix")
    warnings = check_leader(leader, limits)
    for w in warnings:
        log(f"   warning: {w}")
    runs = {"certified": LinearController(1.2, 0.5, 0.6, headway=HEADWAY),
            "cacc": CACCController(t_system=HEADWAY)}
    summary: dict[str, Any] = {}
    for name, controller in runs.items():
        result = simulate(leader, controller, 10, tau=TAU, delta=DELTA, limits=limits)
        doc = run_document(result, leader=leader, controller=controller, spec="mix",
                           warnings=warnings)
        label = ("CACC (gains not of the eq-4 form)" if name == "cacc"
                 else "K = (1.2, 0.5, 0.6), certified")
        files = write_run(result, out / name, metrics=doc, title=f"{leader.name}: 10 followers, {label}")
        cert = doc["certificate"] or {}
        m_p = ", ".join("n/a" if v is None else f"{v:.2f}" for v in doc["m_p"])
        log(f"{name}: K={cert.get('k_x')},{cert.get('k_v')},{cert.get('k_a')} "
            f"({cert.get('verdict')}); m_p = {m_p}; max m_p {doc['max_m_p']:.3f}, "
            f"collisions {doc['collisions']}, TIT {doc['TIT']:.3f} s², "
            f"M_CI {doc['M_CI']:.3f} m²/s⁶, m_fss {doc['m_fss']}")
        summary[name] = {k: doc[k] for k in ("m_p", "max_m_p", "M_lss", "collisions", "TIT", "M_CI",
                                             "M_effi", "m_fss")}
        summary[name]["files"] = [f"{name}/{f}" for f in files.values()]
    return summary


def _step_region(out: Path, log: Log) -> dict[str, Any]:
    """A coarse 121 × 121 slice over (k_x, k_v) at k_a = 0.5: class, comparison and sup|Γ| maps."""
    import matplotlib

    matplotlib.use("Agg")
    import numpy as np

    from ..io import read_gains
    from ..plots import save_figures, trajectory_verdicts
    from ..regions import region_map

    g = np.linspace(-2.0, 2.0, 121)
    rmap = region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=TAU, delta=DELTA, headway=HEADWAY,
                      progress=False)
    files = [rmap.save_npz(out / "region.npz").name]
    rollout = read_gains(ROLLOUT)
    files += [p.name for p in save_figures(rmap, out, formats=("png",), gains=rollout,
                                           verdicts=trajectory_verdicts(rmap, rollout), dpi=110)]
    for line in rmap.report().splitlines():
        log(line)
    return {"files": files, "class_shares": rmap.class_shares(),
            "disagreements": rmap.disagreements()}


#: Uncertified triples repaired by the tune step (the first three are from DEMO_TRIPLES).
TUNE_TRIPLES = ["0.9,-0.5,1.1", "0.2,0.7,0", "-0.5,1,1", "1,-1.2,0.5", "0.3,0.2,0.5",
                "1.6,-0.9,0.6", "0.5,0.3,1.2"]


def _step_tune(out: Path, log: Log) -> dict[str, Any]:
    """Repair uncertified triples by region growing (IDL §3.3) and by projection; draw the moves.

    Each triple is solved once per method; the files and the figure are written from those
    results.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from ..io import atomic_path, columns_from_records, parse_triple, write_results
    from ..plots import moves_projection, plot_moves
    from ..tuning import project, region_growing

    results = []
    for t in TUNE_TRIPLES:
        K = parse_triple(t)
        results += [region_growing(K, tau=TAU, delta=DELTA, headway=HEADWAY),
                    project(K, tau=TAU, delta=DELTA, headway=HEADWAY)]
    records = [r.as_dict() for r in results]
    for r in records:
        log(f"{r['method']:>14}: K0=({r['k_x_in']:g}, {r['k_v_in']:g}, {r['k_a_in']:g}) -> "
            f"({r['k_x']:.4g}, {r['k_v']:.4g}, {r['k_a']:.4g}), moved {r['distance']:.4g}, "
            f"{'certified' if r['certified'] else 'NOT certified'} ({r['status']})")
    summary: dict[str, Any] = {}
    for method in dict.fromkeys(r["method"] for r in records):
        rs = [r for r in records if r["method"] == method]
        moved = [r["distance"] for r in rs if r["status"] in ("repaired", "moved_not_certified")]
        summary[method] = {"n": len(rs), "certified": sum(r["certified"] for r in rs),
                           "repaired": sum(r["status"] == "repaired" for r in rs),
                           "median_distance_moved": float(np.median(moved)) if moved else 0.0}
    params = {**PARAMS, "method": "both"}
    columns = columns_from_records(records)
    write_results(columns, out / "tune.json", "json", params=params, summary=summary)
    write_results(columns, out / "tune.txt", "table", params=params, summary=summary)
    drawn = plot_moves(results, moves_projection(results, tau=TAU, delta=DELTA, headway=HEADWAY))
    fig = drawn["ax"].figure
    with atomic_path(out / "tune_moves.png") as tmp:
        fig.savefig(tmp, dpi=110, bbox_inches="tight")
    plt.close(fig)
    moves = [{"method": r["method"], "from": [r["k_x_in"], r["k_v_in"], r["k_a_in"]],
              "to": [r["k_x"], r["k_v"], r["k_a"]], "distance": r["distance"],
              "certified": r["certified"], "status": r["status"]} for r in records]
    return {"files": ["tune.json", "tune.txt", "tune_moves.png"], "summary": summary,
            "moves": moves}


def _step_hcfs(out: Path, log: Log, *, final: Path | None = None) -> dict[str, Any]:
    """``hcfs verify`` of the bundled DDPG on the paper's case 1: the jerk theorem at every frame.

    Case 1 is played by its analogue on UDDS at half speed (20 s, 8 followers); J = 2.5 m/s³.
    """
    import matplotlib

    matplotlib.use("Agg")
    from ..hcfs import case_leader, load_bundled_ddpg, verify, write_report

    leader, n = case_leader("hcfs-case1")
    ver = verify([leader], load_bundled_ddpg(), jerk_limits=[2.5], n_followers=n)
    import shlex

    files = write_report(ver, out, command=shlex.join([
        "stringstab", "hcfs", "verify", "--jerk-limit", "2.5", "--followers", str(n), "--leader",
        "hcfs-case1", "--out", str(final if final is not None else out)]))
    log(f"a1 = {ver.runs[0].params['policy_label']}; leader {leader.name}, {n} followers")
    rows = {}
    for x in ver.results:
        t = x["totals"]
        rows[f"{x['mode']} J={x['jerk_limit']:g}"] = {k: t[k] for k in (
            "max_jerk", "conclusion_fails", "counterexamples", "violations", "bound_violations",
            "sum_abs_speed_error", "sum_abs_jerk", "sum_reward", "collisions")}
        if x["mode"] in ("paper", "safe"):
            log(f"  J = {x['jerk_limit']:<4g} {x['mode']:5s}: max jerk {t['max_jerk']:.3g} m/s^3, "
                f"conclusion fails {t['conclusion_fails']}, P3 fails {t['P3_fails']}/{t['frames']}, "
                f"theorem violations {t['violations']}, bound violations {t['bound_violations']}")
    log("no frame falsifies the theorem, the bound or the jerk-safe variant" if ver.ok
        else f"{len(ver.violations)} frame(s) falsify a guarantee")
    return {"files": sorted(files.values()), "policy": ver.runs[0].params["policy_label"],
            "ok": ver.ok, "results": rows}


#: Environment steps of the demo's training run (tens of seconds on 2 cores; the results in
#: docs/training.md use 250,000).
TRAIN_STEPS = 30_000


def _step_train(out: Path, log: Log, *, steps: int = TRAIN_STEPS, episodes: int | None = None,
                platoon: int = 10) -> dict[str, Any]:
    """Train an IDL policy for a small budget, evaluate it beside CACC and certify its gains.

    The evaluation runs on the held-out test episodes, every gain the policy executed is
    certified, and the comparison is drawn (docs/training.md).

    ``episodes`` keeps only the first held-out episodes and ``platoon`` sets the platoon test's
    size (0: none); the demo uses all 57 and 10 (the tests use less).

    The budget is far below the results' (the policy is young: expect a worse table than
    docs/training.md's), but every executed gain is certified whatever the budget: the repair
    guarantees it and the evaluation re-checks each one (m_fss, continuous and sampled).
    """
    import importlib.util

    if importlib.util.find_spec("torch") is None or importlib.util.find_spec("safetensors") is None:
        log("skipped: training needs the rl extra (pip install 'stringstab[rl]')")
        return {"skipped": "torch or safetensors not installed (the rl extra)", "files": []}
    import matplotlib

    matplotlib.use("Agg")
    from ..io import OutputDir
    from ..rl import config_for, train
    from ..rl.episodes import default_leaders
    from ..rl.evaluate import evaluate, platoon_test
    from ..rl.report import verdict, write_comparison, write_evaluation

    cfg = config_for("idl", total_steps=steps, seed=0, learning_starts=min(2_000, steps // 4),
                     checkpoint_every=max(steps, 1))
    res = train(cfg, out=out / "run", progress=None)  # a bar on a terminal, else lines
    if getattr(res, "stopped_by", None) == "interrupted":  # Ctrl-C: the demo's folder is discarded as a whole
        raise KeyboardInterrupt
    t = res.timing
    log(f"trained IDL for {res.steps} steps ({len(res.episodes)} episodes) in {t['total_seconds']:.1f} s: "
        f"{t['steps_per_second']:.0f} steps/s, repair {100 * t['repair_share']:.0f}% of the time")
    kw = {"tau": cfg.tau, "delta": cfg.delta, "headway": cfg.headway}
    leaders = default_leaders("test", seconds=cfg.episode_seconds, dt=cfg.dt)[:episodes]
    ev = evaluate(res.policy, leaders, name="idl", **kw)
    platoons = [platoon_test(res.policy, platoon, dt=cfg.dt, **kw)] if platoon else []
    text, passed = verdict(ev, platoons, "gains")
    cacc = evaluate("cacc", leaders, name="cacc", **kw)
    run_doc = {"folder": "run", "leaders": f"{len(leaders)} bundled test episodes", **kw,
               "dt": cfg.dt, "repair": res.policy.info.get("repair")}
    with OutputDir(out / "evaluation", command="evaluate") as o:
        write_evaluation(o, ev, platoons, run_doc, text)
    with OutputDir(out / "comparison", command="compare") as o:
        write_comparison(o, {"idl": [ev], "cacc": [cacc]}, reference="idl",
                         platoons={"idl": {"run": "run", "tests": platoons}}, **kw)
    s = ev.summary
    log(f"held-out episodes: {s['episodes']}; m_fss = {s['m_fss']:.4g} of {s['n_gains']} executed "
        f"gains (sampled-data at dt: {s['m_fss_sampled']:.4g}), collisions {s['collisions']}, "
        f"TIT {s['TIT']:.3f} s² (CACC {cacc.summary['TIT']:.3f}), M_CI {s['M_CI']:.3f} m²/s⁶ "
        f"(CACC {cacc.summary['M_CI']:.3f}), M_lss {s['M_lss']:.3f}")
    for q in platoons:
        log(f"{q['n']}-vehicle platoon: max m_p {q['max_m_p']:.3f}")
    log(f"verdict: {text}")
    keys = ("m_fss", "m_fss_sampled", "n_gains", "collisions", "TIT", "M_CI", "M_effi", "M_lss")
    return {"steps": res.steps, "episodes": len(res.episodes),
            "train_seconds": round(t["total_seconds"], 2), "repair_share": t["repair_share"],
            "idl": {k: s.get(k) for k in keys}, "cacc": {k: cacc.summary.get(k) for k in keys},
            "platoon_max_m_p": {q["n"]: q["max_m_p"] for q in platoons}, "verdict": text,
            "passed": passed,
            "files": ["run/", "evaluation/", "comparison/"]}


#: The steps that take the followers' limits (``run_demo(limits=...)``).
LIMITED_STEPS = ("simulate",)

#: The demo's steps, in order: (name, function).  Later capabilities append here.
STEPS: list[tuple[str, Step]] = [
    ("derive", _step_derive),
    ("certify", _step_certify),
    ("simulate", _step_simulate),
    ("region", _step_region),
    ("tune", _step_tune),
    ("hcfs", _step_hcfs),
    ("train", _step_train),
]


def run_demo(out: str | Path, *, log: Log = print, only: list[str] | None = None,
             limits: Any = None, command: str = "stringstab demo") -> dict[str, Any]:
    """Run every demo step, writing outputs under ``out``.

    Parameters
    ----------
    out : path
        Output folder: checked before any step runs (a file, a folder that cannot be written
        or one holding another command's outputs is refused), created if needed, and written
        all-or-nothing, replacing an earlier demo's files.
    log : callable
        Receives one line of progress at a time.
    only : list of str, optional
        Run only the named steps.
    limits : Limits, optional
        The followers' limits of the simulate step (default: IDL Table 2).
    command : str, optional
        The command line shown in the report (``report.md``, ``report.html``).

    Returns
    -------
    dict
        ``{step: summary}``, also written to ``out/summary.json``; the report of the run
        (:func:`stringstab.report.demo.demo_report`) is written to ``out/report.md`` and
        ``out/report.html``.

    Raises
    ------
    StringStabError
        If ``out`` cannot be used or a step name is unknown (before any work).
    """
    from ..errors import StringStabError
    from ..io import OutputDir

    names = [n for n, _ in STEPS]
    for o in only or []:
        if o not in names:
            raise StringStabError(f"unknown demo step {o!r}; expected one of {names}")
    summary: dict[str, Any] = {}
    from ..progress import duration

    todo = sum(1 for n in names if not only or n in only)
    done, started = 0, time.perf_counter()
    with OutputDir(out, command="demo", what="demo output folder") as d:
        for name, step in STEPS:
            if only and name not in only:
                continue
            t0 = time.perf_counter()
            done += 1
            log(f"== {name} == (step {done} of {todo}, {duration(time.perf_counter() - started)} "
                "elapsed)")
            kw: dict[str, Any] = {"limits": limits} if name in LIMITED_STEPS else {}
            if "final" in inspect.signature(step).parameters:
                kw["final"] = d.final(name)
            result = step(d.folder(name), log, **kw)
            result["seconds"] = round(time.perf_counter() - t0, 2)
            summary[name] = result
            log(f"   ({result['seconds']} s, outputs in {d.final(name)})")
        d.write_json("summary.json", summary)
        from ..report.demo import demo_report

        demo_report(summary, d.staging, command=command, params=PARAMS, started=started).write(d)
    return summary
