"""Benchmark of stability-region maps (:func:`stringstab.regions.region_map`).

Three maps over [-2, 2] per gain, τ = 0.1 s, δ = 0.2 s, T* = 1.1 s, each timed
once after a warm-up (SymPy lambdify caches built):

1. a 201³ volume with the Taylor criterion (``methods=("taylor",)``), and the
   same with the printed one too (``("taylor", "printed")``);
2. an 801 × 801 slice over (k_x, k_v) at k_a = 0.5 with the exact certificate;
3. a 101³ volume with the exact certificate.

Targets on 2 cores: Taylor 201³ < 1 s, exact 801² < 10 s, exact 101³ < 60 s.
For the exact maps it also times :func:`stringstab.certificate.certify_batch`
alone, in this process, on a 20 000-point sample of the same grid: the
certificate's own cost per point, which bounds what the map can reach.

The machine may be shared: the load average is printed before each map.
Prints its figures; asserts nothing.  Example::

    python analysis/bench_regions.py            # all three
    python analysis/bench_regions.py --only taylor --workers 1
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from stringstab.certificate import certify_batch
from stringstab.regions import region_map

P = dict(tau=0.1, delta=0.2, headway=1.1)


def _load() -> str:
    try:
        return f"load {os.getloadavg()[0]:.2f}"
    except OSError:  # pragma: no cover
        return "load ?"


def _time_map(label: str, axes: dict, fixed: dict | None, methods: tuple[str, ...], workers: int | None,
              target: float) -> float:
    n = int(np.prod([a.size for a in axes.values()]))
    print(f"{label:<34} {n:>10,} points  ({_load()}) ...", flush=True, end=" ")
    t0 = time.perf_counter()
    m = region_map(axes, fixed, **P, methods=methods, workers=workers, progress=False)
    dt = time.perf_counter() - t0
    ok = "meets" if dt < target else "MISSES"
    print(f"{dt:7.2f} s  {n / dt:>12,.0f} points/s   ({ok} the {target:g} s target)")
    shares = {k: round(v, 4) for k, v in m.verdict_shares()[methods[0]].items()}
    print(f"{'':<34} {methods[0]} verdict shares {shares}")
    return dt


def _time_certificate(axes: dict, fixed: dict | None, sample: int = 20_000) -> float:
    """certify_batch alone, one process, on a random sample of the grid's points."""
    grids = np.meshgrid(*axes.values(), indexing="ij")
    by = dict(zip(axes, (g.ravel() for g in grids)))
    for k, v in (fixed or {}).items():
        by[k] = np.full(grids[0].size, v)
    idx = np.random.default_rng(0).choice(grids[0].size, size=min(sample, grids[0].size), replace=False)
    t0 = time.perf_counter()
    certify_batch(by["k_x"][idx], by["k_v"][idx], by["k_a"][idx], **P)
    dt = time.perf_counter() - t0
    per = dt / idx.size
    print(f"{'':<34} certify_batch alone, 1 process: {1e6 * per:.1f} µs/point "
          f"({idx.size / dt:,.0f} points/s)")
    return per


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", choices=("taylor", "slice", "volume"), action="append",
                    help="run only these benchmarks (repeatable)")
    ap.add_argument("--workers", type=int, default=None,
                    help="worker processes (default: region_map's choice, all cores)")
    args = ap.parse_args()
    which = args.only or ["taylor", "slice", "volume"]
    print(f"cores available: {len(os.sched_getaffinity(0))}; workers: {args.workers or 'auto'}")
    # warm-up: lambdify caches, certificate code paths
    region_map({"k_x": np.linspace(-2, 2, 9), "k_v": np.linspace(-2, 2, 9), "k_a": np.linspace(-2, 2, 9)},
               **P, workers=1, progress=False)

    if "taylor" in which:
        g = np.linspace(-2, 2, 201)
        axes = {"k_x": g, "k_v": g, "k_a": g}
        _time_map("Taylor 201^3 (derived)", axes, None, ("taylor",), args.workers, 1.0)
        _time_map("Taylor 201^3 (derived + printed)", axes, None, ("taylor", "printed"), args.workers, 1.0)
    if "slice" in which:
        g = np.linspace(-2, 2, 801)
        axes = {"k_x": g, "k_v": g}
        _time_map("exact 801 x 801 slice (k_a = 0.5)", axes, {"k_a": 0.5}, ("exact",), args.workers, 10.0)
        _time_certificate(axes, {"k_a": 0.5})
    if "volume" in which:
        g = np.linspace(-2, 2, 101)
        axes = {"k_x": g, "k_v": g, "k_a": g}
        _time_map("exact 101^3 volume", axes, None, ("exact",), args.workers, 60.0)
        _time_certificate(axes, None)


if __name__ == "__main__":
    main()
