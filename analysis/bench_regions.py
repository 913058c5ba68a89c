"""Benchmark of stability-region maps (:func:`stringstab.regions.region_map`).

Three maps over [-2, 2] per gain, τ = 0.1 s, δ = 0.2 s, T* = 1.1 s, each timed
once after a warm-up (SymPy lambdify caches built):

1. a 201³ volume with the Taylor criterion (``methods=("taylor",)``), and the
   same with the printed one too (``("taylor", "printed")``);
2. an 801 × 801 slice over (k_x, k_v) at k_a = 0.5 with the exact certificate;
3. a 101³ volume with the exact certificate.

Targets on 2 cores: Taylor 201³ < 1 s, exact 801² < 10 s, exact 101³ < 60 s.

``--only cli`` (issue 9): the same 801² exact slice through the command line,
``stringstab region --method exact --format png`` in a fresh process (NPZ, CSV and the
PNG figures included), against :func:`region_map` alone in this process on the same
grid, ``--reps`` times, alternating, with the median ratio (target ≤ 1.5) and the
load beside each pair; then where the command's time goes (phases timed in
process: the map, the NPZ and CSV in this process, the figures in the forked one).
For the exact maps it also times :func:`stringstab.certify.api.certify_batch`
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
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from stringstab.certify.api import certify_batch
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


def _cpu() -> float:
    """CPU seconds of this process and of its finished child processes (user + system)."""
    import resource

    a = resource.getrusage(resource.RUSAGE_SELF)
    b = resource.getrusage(resource.RUSAGE_CHILDREN)
    return a.ru_utime + a.ru_stime + b.ru_utime + b.ru_stime


def _region_cli(n: int, reps: int, workers: int | None) -> None:
    """The 801² CLI target: the command (fresh process) against region_map alone, alternating."""
    g = np.linspace(-2, 2, n)
    kw = {} if workers is None else {"workers": workers}
    cmd = [sys.executable, "-m", "stringstab", "region", "--x", "k_x", "--y", "k_v", "--fix", "k_a=0.5",
           "--range", "-2,2", "--n", str(n), "--method", "exact", "--format", "png", "--no-progress"]
    if workers is not None:
        cmd += ["--workers", str(workers)]
    print(f"region CLI target: {n}x{n} exact slice, {' '.join(cmd[3:])}")
    ratios = []
    cpu_ratios = []
    for r in range(reps):
        c0 = _cpu()
        t0 = time.perf_counter()
        region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, **P, methods="exact", progress=False, **kw)
        alone = time.perf_counter() - t0
        cpu_alone = _cpu() - c0
        load_alone = _load()
        work = Path(tempfile.mkdtemp(prefix="bench_regions_cli_"))
        try:
            c0 = _cpu()
            t0 = time.perf_counter()
            res = subprocess.run([*cmd, "--out", str(work / "maps")], capture_output=True, text=True)
            cli = time.perf_counter() - t0
            cpu_cli = _cpu() - c0
            if res.returncode != 0:
                raise SystemExit(f"stringstab region failed: {res.stderr.strip()}")
            files = sorted(p.name for p in (work / "maps").iterdir() if not p.name.startswith("."))
        finally:
            shutil.rmtree(work, ignore_errors=True)
        ratios.append(cli / alone)
        cpu_ratios.append(cpu_cli / cpu_alone)
        print(f"  rep {r + 1}: region_map alone {alone:6.2f} s wall, {cpu_alone:5.2f} s CPU "
              f"({load_alone}); CLI {cli:6.2f} s wall, {cpu_cli:5.2f} s CPU ({_load()}); "
              f"ratio {cli / alone:.2f} wall, {cpu_cli / cpu_alone:.2f} CPU")
    print(f"  files written: {', '.join(files)}")
    print(f"  median ratio CLI / region_map alone: {np.median(ratios):.2f} wall "
          f"(target <= 1.5; min {min(ratios):.2f}, max {max(ratios):.2f}), "
          f"{np.median(cpu_ratios):.2f} CPU time (all processes)")
    _region_cli_phases(n, workers)


def _region_cli_phases(n: int, workers: int | None) -> None:
    """Where the command's time goes: its phases, timed in this process."""
    from stringstab.io import OutputDir
    from stringstab.plots import save_region_outputs

    g = np.linspace(-2, 2, n)
    kw = {} if workers is None else {"workers": workers}
    work = Path(tempfile.mkdtemp(prefix="bench_regions_phases_"))
    try:
        t0 = time.perf_counter()
        m = region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, **P, methods="exact", progress=False, **kw)
        t_map = time.perf_counter() - t0
        times = {}
        for processes in (2, 1):
            t1 = time.perf_counter()
            with OutputDir(work / f"maps{processes}", command="region") as out:
                save_region_outputs(m, out, formats=("png",), processes=processes)
            times[processes] = time.perf_counter() - t1
        t1 = time.perf_counter()
        m.save_csv(work / "alone.csv")
        t_csv = time.perf_counter() - t1
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(f"  phases (in process, {_load()}): map {t_map:.2f} s; outputs (NPZ, CSV, PNGs) "
          f"{times[2]:.2f} s shared by two processes, {times[1]:.2f} s in one "
          f"(of which the CSV alone {t_csv:.2f} s)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", choices=("taylor", "slice", "volume", "cli"), action="append",
                    help="run only these benchmarks (repeatable; 'cli' only when named)")
    ap.add_argument("--reps", type=int, default=5, help="repetitions of the cli target (default 5)")
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
    if "cli" in which:
        _region_cli(801, args.reps, args.workers)


if __name__ == "__main__":
    main()
