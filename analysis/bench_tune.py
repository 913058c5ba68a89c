"""Benchmark of gain repair: the IDL paper's region growing against the nearest-point projection.

Two sets of ``--n`` gain triples that the exact certificate does not certify
(verdict ``not_certified`` or ``inconclusive``), ``--seed`` fixed:

uniform
    K uniform in [-2, 2]³ (rejection of the certified ones, about 9 %).
boundary
    "near the boundary": a certified K_c drawn uniformly from the certified
    part of [-2, 2]³, plus isotropic Gaussian noise N(0, σ² I) with
    σ = ``--sigma`` (0.05), kept when the result is inside [-2, 2]³ and not
    certified — so a certified point lies within |noise| (median ≈ 0.077) of it.

Each triple is repaired by

* ``rg``: :func:`stringstab.tuning.region_growing` as printed in the paper
  (r0 = 0.1, grid spacing 0.05, derived Taylor test, k_a kept within k_a0 ± r0);
* ``rg+hurwitz``: the same with the internal-stability conditions added to its
  acceptance test (``check_hurwitz=True``, not in the paper);
* ``projection``: :func:`stringstab.tuning.project` (cold: no cache, no
  previous solution; CasADi/IPOPT solvers and the certified map built once
  before timing).

and the figures printed: the share of outputs certified by the exact
certificate; the distance moved ‖K − K0‖ (median and 95th percentile over the
outputs that moved); the latency per call (median, 99th percentile, wall
clock, and the process CPU time, less sensitive to other jobs on a shared
machine); and how often the projection moves no further than region growing
(+1e-9), over the inputs where region growing returned a *certified* repair
(the fair comparison) and over all inputs where it returned any repair.

``--baseline DIR`` adds a same-run A/B comparison of the projection: DIR holds an
older copy of the package (``DIR/stringstab``, e.g. ``git archive main stringstab |
tar -x -C DIR``), loaded under the name ``stringstab_baseline``; each triple is
repaired by both, alternating which goes first, and the medians, their ratio and
the largest difference in the outputs are printed.

``--loop N`` adds a control-loop scenario: a random walk of N steps
K_t = clip(K_{t−1} + N(0, 0.02² I)) from an uncertified start, repaired at each
step by a :class:`stringstab.tuning.Projector` (cache + warm start from the
previous step) and by cold :func:`project` calls.

Prints its figures; asserts nothing about time.  Example::

    python analysis/bench_tune.py --n 10000 --seed 0 --loop 2000 --json bench_tune.json
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import json
import os
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from stringstab.certify.api import certify_batch
from stringstab.params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU
from stringstab.tuning import Projector, project, region_growing

LO, HI = -2.0, 2.0


def uncertified_uniform(rng: np.random.Generator, n: int, p: dict[str, float]) -> np.ndarray:
    out: list[np.ndarray] = []
    while sum(len(o) for o in out) < n:
        K = rng.uniform(LO, HI, (max(2 * n, 1000), 3))
        b = certify_batch(K[:, 0], K[:, 1], K[:, 2], **p)
        out.append(K[~b.certified])
    return np.concatenate(out)[:n]


def uncertified_near_boundary(rng: np.random.Generator, n: int, p: dict[str, float],
                              sigma: float) -> np.ndarray:
    out: list[np.ndarray] = []
    while sum(len(o) for o in out) < n:
        K = rng.uniform(LO, HI, (20 * max(n, 500), 3))
        b = certify_batch(K[:, 0], K[:, 1], K[:, 2], **p)
        C = K[b.certified]
        Kn = C + rng.normal(0.0, sigma, C.shape)
        Kn = Kn[np.all((Kn >= LO) & (Kn <= HI), axis=1)]
        bn = certify_batch(Kn[:, 0], Kn[:, 1], Kn[:, 2], **p)
        out.append(Kn[~bn.certified])
    return np.concatenate(out)[:n]


def run_method(name: str, K: np.ndarray, p: dict[str, float]) -> dict[str, np.ndarray]:
    cert = np.zeros(len(K), dtype=bool)
    moved = np.zeros(len(K), dtype=bool)
    dist = np.zeros(len(K))
    secs = np.zeros(len(K))
    cpu = np.zeros(len(K))
    iters = np.zeros(len(K), dtype=int)
    status: list[str] = []
    extra: list[Any] = []
    for i, k in enumerate(K):
        t = time.perf_counter()
        c = time.process_time()
        if name == "rg":
            r = region_growing(k, **p)
        elif name == "rg+hurwitz":
            r = region_growing(k, **p, check_hurwitz=True)
        else:
            r = project(k, **p)
        secs[i] = time.perf_counter() - t
        cpu[i] = time.process_time() - c
        cert[i] = r.certified
        moved[i] = r.status == "repaired"
        dist[i] = r.distance
        iters[i] = r.iterations
        status.append(r.status)
        extra.append(r.details.get("fallback", False))
    return {"certified": cert, "repaired": moved, "distance": dist, "seconds": secs, "cpu": cpu,
            "iterations": iters, "status": np.array(status), "fallback": np.array(extra)}


def summarise(name: str, r: dict[str, np.ndarray]) -> dict[str, Any]:
    d = r["distance"][r["repaired"]]
    ms = 1e3 * r["seconds"]
    s = {
        "n": len(ms),
        "certified_share": float(r["certified"].mean()),
        "status": dict(Counter(r["status"].tolist())),
        "distance_median": float(np.median(d)) if d.size else float("nan"),
        "distance_p95": float(np.percentile(d, 95)) if d.size else float("nan"),
        "latency_ms_median": float(np.median(ms)),
        "latency_ms_p99": float(np.percentile(ms, 99)),
        "latency_ms_max": float(ms.max()),
        "cpu_ms_median": float(np.median(1e3 * r["cpu"])),
        "cpu_ms_p99": float(np.percentile(1e3 * r["cpu"], 99)),
        "iterations_median": float(np.median(r["iterations"])),
    }
    if name == "projection":
        s["fallback_share"] = float(np.mean(r["fallback"].astype(bool)))
        s["solves_histogram"] = np.bincount(r["iterations"]).tolist()
    return s


def compare(pj: dict[str, np.ndarray], rg: dict[str, np.ndarray]) -> dict[str, Any]:
    fair = rg["repaired"] & rg["certified"]
    anyr = rg["repaired"]
    le = pj["distance"] <= rg["distance"] + 1e-9
    return {
        "rg_certified_repairs": int(fair.sum()),
        "projection_no_further_on_certified_rg_repairs": float(le[fair].mean()) if fair.any() else float("nan"),
        "rg_any_repairs": int(anyr.sum()),
        "projection_no_further_on_any_rg_repair": float(le[anyr].mean()) if anyr.any() else float("nan"),
    }


def load_baseline(path: str) -> Any:
    """``DIR/stringstab`` imported as the package ``stringstab_baseline``; its tuning module."""
    root = Path(path) / "stringstab"
    spec = importlib.util.spec_from_file_location(
        "stringstab_baseline", root / "__init__.py", submodule_search_locations=[str(root)])
    if spec is None or spec.loader is None:
        raise SystemExit(f"--baseline {path}: expected a folder holding stringstab/__init__.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["stringstab_baseline"] = mod
    spec.loader.exec_module(mod)
    return importlib.import_module("stringstab_baseline.tuning")


def ab_projection(K: np.ndarray, p: dict[str, float], base: Any) -> dict[str, Any]:
    """The projection of this tree against the baseline's, interleaved triple by triple."""
    from stringstab import tuning as new

    t_new = np.empty(len(K))
    t_old = np.empty(len(K))
    dk = np.empty(len(K))
    dd = np.empty(len(K))
    same_verdict = np.empty(len(K), dtype=bool)
    for i, k in enumerate(K):
        order = ((new, t_new), (base, t_old)) if i % 2 else ((base, t_old), (new, t_new))
        res = {}
        for mod, out in order:
            t0 = time.perf_counter()
            r = mod.project(k, **p)
            out[i] = time.perf_counter() - t0
            res[mod is new] = r
        dk[i] = float(np.max(np.abs(np.subtract(res[True].k, res[False].k))))
        dd[i] = res[True].distance - res[False].distance
        same_verdict[i] = res[True].verdict == res[False].verdict
    return {
        "n": len(K),
        "this_ms_median": float(np.median(t_new) * 1e3),
        "baseline_ms_median": float(np.median(t_old) * 1e3),
        "ratio_median_this_over_baseline": float(np.median(t_new) / np.median(t_old)),
        "this_ms_p99": float(np.percentile(t_new, 99) * 1e3),
        "baseline_ms_p99": float(np.percentile(t_old, 99) * 1e3),
        "max_abs_difference_in_K": float(dk.max()) if len(K) else 0.0,
        "share_identical_K": float(np.mean(dk == 0.0)) if len(K) else float("nan"),
        "share_K_differs_over_1e-6": float(np.mean(dk > 1e-6)) if len(K) else float("nan"),
        "distance_this_minus_baseline_min_max": [float(dd.min()), float(dd.max())] if len(K) else [],
        "share_same_verdict": float(same_verdict.mean()) if len(K) else float("nan"),
    }


def control_loop(rng: np.random.Generator, steps: int, p: dict[str, float]) -> dict[str, Any]:
    K = np.empty((steps, 3))
    k = uncertified_uniform(rng, 1, p)[0]
    for t in range(steps):
        k = np.clip(k + rng.normal(0.0, 0.02, 3), LO, HI)
        K[t] = k
    pr = Projector(**p)
    fast = np.empty(steps)
    cold = np.empty(steps)
    cert_fast = np.empty(steps, dtype=bool)
    for t in range(steps):
        t0 = time.perf_counter()
        r = pr(K[t])
        fast[t] = time.perf_counter() - t0
        cert_fast[t] = r.certified
        t0 = time.perf_counter()
        project(K[t], **p)
        cold[t] = time.perf_counter() - t0
    b = certify_batch(K[:, 0], K[:, 1], K[:, 2], **p)
    return {
        "steps": steps,
        "inputs_certified_share": float(b.certified.mean()),
        "fast_certified_share": float(cert_fast.mean()),
        "fast_latency_ms_median": float(np.median(fast) * 1e3),
        "fast_latency_ms_p99": float(np.percentile(fast, 99) * 1e3),
        "cold_latency_ms_median": float(np.median(cold) * 1e3),
        "cold_latency_ms_p99": float(np.percentile(cold, 99) * 1e3),
        "projector_stats": pr.stats,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="triples per set (default 10000)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--sigma", type=float, default=0.05, help="noise of the boundary set")
    ap.add_argument("--sets", default="uniform,boundary")
    ap.add_argument("--methods", default="projection,rg,rg+hurwitz")
    ap.add_argument("--loop", type=int, default=0, help="control-loop steps (0: skip)")
    ap.add_argument("--tau", type=float, default=DEFAULT_TAU)
    ap.add_argument("--delta", type=float, default=DEFAULT_DELTA)
    ap.add_argument("--headway", type=float, default=DEFAULT_HEADWAY)
    ap.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    ap.add_argument("--baseline", metavar="DIR",
                    help="also compare the projection with the package in DIR/stringstab (A/B)")
    args = ap.parse_args()
    p = {"tau": args.tau, "delta": args.delta, "headway": args.headway}
    rng = np.random.default_rng(args.seed)
    print(f"# bench_tune: n={args.n} seed={args.seed} params={p} "
          f"cpus={os.cpu_count()} load={os.getloadavg()[0]:.2f}")
    # build solvers, the certified map and lambdified criteria before timing
    project((0.9, -0.5, 1.1), **p)
    region_growing((0.9, -0.5, 1.1), **p)
    base = None
    if args.baseline:
        base = load_baseline(args.baseline)
        base.project((0.9, -0.5, 1.1), **p)
    report: dict[str, Any] = {"n": args.n, "seed": args.seed, "params": p, "sigma": args.sigma}
    for set_name in args.sets.split(","):
        K = (uncertified_uniform(rng, args.n, p) if set_name == "uniform"
             else uncertified_near_boundary(rng, args.n, p, args.sigma))
        print(f"\n## {set_name}: {len(K)} uncertified triples")
        res: dict[str, dict[str, np.ndarray]] = {}
        rep: dict[str, Any] = {}
        for m in args.methods.split(","):
            t0 = time.perf_counter()
            res[m] = run_method(m, K, p)
            rep[m] = summarise(m, res[m])
            rep[m]["total_s"] = time.perf_counter() - t0
            print(f"{m:>11}: " + json.dumps(rep[m]))
        if "projection" in res:
            for m in ("rg", "rg+hurwitz"):
                if m in res:
                    rep[f"projection_vs_{m}"] = compare(res["projection"], res[m])
                    print(f"projection vs {m}: " + json.dumps(rep[f"projection_vs_{m}"]))
        if base is not None:
            rep["ab_projection"] = ab_projection(K, p, base)
            print(f"A/B projection, this tree vs {args.baseline} "
                  f"(load {os.getloadavg()[0]:.2f}): " + json.dumps(rep["ab_projection"]))
        report[set_name] = rep
    if args.loop:
        report["control_loop"] = control_loop(rng, args.loop, p)
        print("\n## control loop (random walk, sigma 0.02): " + json.dumps(report["control_loop"]))
    report["load_end"] = os.getloadavg()[0]
    print(f"# load at end: {report['load_end']:.2f}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(report, fh, indent=1)


if __name__ == "__main__":
    main()
