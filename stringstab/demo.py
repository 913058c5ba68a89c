"""The main job: a demo of the whole pipeline on bundled data (``stringstab demo``).

Each capability of the toolkit contributes one *step*: a function
``step(out: Path, log: Callable[[str], None]) -> dict`` that writes its outputs
under ``out`` and returns a small summary.  :func:`run_demo` runs them in order
and writes ``summary.json``.  The whole demo runs in a few minutes at most.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["STEPS", "run_demo"]

Log = Callable[[str], None]
Step = Callable[[Path, Log], dict[str, Any]]


def _step_derive(out: Path, log: Log) -> dict[str, Any]:
    """Derive Γ(s), Ψ1-Ψ3, Λ and compare with the printed formulas."""
    from .cli import main

    for fmt, name in (("json", "derive.json"), ("latex", "derive.tex"), ("text", "derive.txt")):
        main(["derive", "--errata", "--format", fmt, "--out", str(out / name)])
    doc = json.loads((out / "derive.json").read_text())
    wrong = [f"eq {e['equation']} ({e['key']})" for e in doc["errata"] if not e["matches"]]
    log(f"derived Γ(s) = {doc['gamma']}")
    log(f"errata: {len(wrong)} printed formulas differ from the derivation: {', '.join(wrong)}")
    return {"files": ["derive.json", "derive.tex", "derive.txt"], "errata": wrong}


#: Paper-style gain triples for the certify step: the two of ``stringstab certify --help``,
#: a moderate CACC-like triple, one with Ψ3 < 0 and one that is not internally stable.
DEMO_TRIPLES = ["0.9,-0.5,1.1", "1.3,0,0.6", "0.45,0.6,0.3", "0.2,0.7,0", "-0.5,1,1"]


def _step_certify(out: Path, log: Log) -> dict[str, Any]:
    """Certify a few triples and a bundled gain time series (exact delay)."""
    from .cli import main

    rollout = Path(__file__).parent / "data" / "examples" / "gain_rollout.csv"
    files = []
    for fmt in ("json", "table"):
        name = f"triples.{'txt' if fmt == 'table' else fmt}"
        main(["certify", *DEMO_TRIPLES, "--format", fmt, "--out", str(out / name)])
        files.append(name)
    for fmt in ("json", "csv", "table"):
        name = f"rollout.{'txt' if fmt == 'table' else fmt}"
        main(["certify", "--file", str(rollout), "--format", fmt, "--out", str(out / name)])
        files.append(name)
    triples = json.loads((out / "triples.json").read_text())
    for r in triples["results"]:
        sup = "inf" if r["sup_gain"] is None else f"{r['sup_gain']:.4g}"
        log(
            f"K=({r['k_x']:g}, {r['k_v']:g}, {r['k_a']:g}): {r['verdict']} (sup|Γ| = {sup}); "
            f"printed Proposition 1: {r['taylor_printed']['verdict']}"
        )
    rollout_doc = json.loads((out / "rollout.json").read_text())
    s = rollout_doc["summary"]
    first_bad: dict[str, float] = {}
    for r in rollout_doc["results"]:
        if r["verdict"] != "certified":
            first_bad.setdefault(str(r["vehicle"]), r["t"])
    log(
        f"gain time series ({rollout.name}): {s['certified']} of {s['n']} rows certified "
        f"(M_fss = {s['m_fss']:.3f}); first uncertified t per vehicle: {first_bad}"
    )
    return {
        "files": files,
        "params": triples["params"],
        "triples": [
            {"K": [r["k_x"], r["k_v"], r["k_a"]], "verdict": r["verdict"],
             "taylor_printed": r["taylor_printed"]["verdict"]}
            for r in triples["results"]
        ],
        "rollout": s,
        "rollout_first_uncertified_t": first_bad,
    }


def _step_simulate(out: Path, log: Log) -> dict[str, Any]:
    """A 10-vehicle platoon behind the §5.1-style leader: certified gains vs the CACC baseline."""
    from .cli import main

    runs = {
        "certified": ["--controller", "linear", "--gains", "1.2,0.5,0.6"],
        "cacc": ["--controller", "cacc"],
    }
    summary: dict[str, Any] = {}
    for name, extra in runs.items():
        main(["simulate", "--leader", "mix", "--followers", "10", *extra, "--out", str(out / name)])
        doc = json.loads((out / name / "metrics.json").read_text())
        cert = doc["certificate"] or {}
        log(
            f"{name}: K={cert.get('k_x')},{cert.get('k_v')},{cert.get('k_a')} "
            f"({cert.get('verdict')}); m_p = {', '.join(f'{v:.2f}' for v in doc['m_p'])}; "
            f"max m_p {doc['max_m_p']:.3f}, collisions {doc['collisions']}, TIT {doc['TIT']:.3f}, "
            f"M_CI {doc['M_CI']:.3f}, M_fss {doc['M_fss']}%"
        )
        summary[name] = {k: doc[k] for k in ("m_p", "max_m_p", "M_lss", "collisions", "TIT", "M_CI",
                                             "M_effi", "M_fss")}
        summary[name]["files"] = [f"{name}/{f}" for f in doc["files"].values()]
    return summary


def _step_region(out: Path, log: Log) -> dict[str, Any]:
    """A coarse 121 × 121 slice over (k_x, k_v) at k_a = 0.5: class, comparison and sup|Γ| maps."""
    import matplotlib

    matplotlib.use("Agg")
    import numpy as np

    from .gainio import read_gains
    from .plots import save_figures
    from .regions import region_map

    g = np.linspace(-2.0, 2.0, 121)
    rmap = region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1,
                      progress=False)
    rollout = read_gains(Path(__file__).parent / "data" / "examples" / "gain_rollout.csv")
    files = [rmap.save_npz(out / "region.npz").name]
    files += [p.name for p in save_figures(rmap, out, formats=("png",), gains=rollout, dpi=110)]
    for line in rmap.report().splitlines():
        log(line)
    return {"files": files, "class_shares": rmap.class_shares(),
            "disagreements": rmap.disagreements()}


#: Uncertified triples repaired by the tune step (the first three are from DEMO_TRIPLES).
TUNE_TRIPLES = ["0.9,-0.5,1.1", "0.2,0.7,0", "-0.5,1,1", "1,-1.2,0.5", "0.3,0.2,0.5",
                "1.6,-0.9,0.6", "0.5,0.3,1.2"]


def _step_tune(out: Path, log: Log) -> dict[str, Any]:
    """Repair uncertified triples by region growing (IDL §3.3) and by projection; draw the moves."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .cli import main
    from .gainio import parse_triple
    from .tuning import plot_moves, project, region_growing

    main(["tune", *TUNE_TRIPLES, "--method", "both", "--format", "json",
          "--out", str(out / "tune.json")])
    main(["tune", *TUNE_TRIPLES, "--method", "both", "--out", str(out / "tune.txt")])
    doc = json.loads((out / "tune.json").read_text())
    for r in doc["results"]:
        log(
            f"{r['method']:>14}: K0=({r['k_x_in']:g}, {r['k_v_in']:g}, {r['k_a_in']:g}) -> "
            f"({r['k_x']:.4g}, {r['k_v']:.4g}, {r['k_a']:.4g}), moved {r['distance']:.4g}, "
            f"{'certified' if r['certified'] else 'NOT certified'} ({r['status']})"
        )
    tau, delta, headway = 0.1, 0.2, 1.1
    results = []
    for t in TUNE_TRIPLES:
        K = parse_triple(t)
        results += [region_growing(K, tau=tau, delta=delta, headway=headway),
                    project(K, tau=tau, delta=delta, headway=headway)]
    drawn = plot_moves(results, tau=tau, delta=delta, headway=headway, k_a=0.6, n=101)
    fig = drawn["ax"].figure
    fig.tight_layout()
    fig.savefig(out / "tune_moves.png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return {"files": ["tune.json", "tune.txt", "tune_moves.png"], "summary": doc["summary"]}


#: The demo's steps, in order: (name, function).  Later capabilities append here.
STEPS: list[tuple[str, Step]] = [
    ("derive", _step_derive),
    ("certify", _step_certify),
    ("simulate", _step_simulate),
    ("region", _step_region),
    ("tune", _step_tune),
]


def run_demo(out: str | Path, *, log: Log = print, only: list[str] | None = None) -> dict[str, Any]:
    """Run every demo step, writing outputs under ``out``.

    Parameters
    ----------
    out : path
        Output directory (created if needed).
    log : callable
        Receives one line of progress at a time.
    only : list of str, optional
        Run only the named steps.

    Returns
    -------
    dict
        ``{step: summary}``, also written to ``out/summary.json``.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    summary: dict[str, Any] = {}
    for name, step in STEPS:
        if only and name not in only:
            continue
        t0 = time.perf_counter()
        log(f"== {name} ==")
        d = out / name
        d.mkdir(exist_ok=True)
        result = step(d, log)
        result["seconds"] = round(time.perf_counter() - t0, 2)
        summary[name] = result
        log(f"   ({result['seconds']} s, outputs in {d})")
    (out / "summary.json").write_text(json.dumps(summary, indent=2, ensure_ascii=False) + "\n")
    return summary
