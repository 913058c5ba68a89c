"""Benchmark of stability-region maps (:func:`stringstab.regions.region_map`).

Three maps over [-2, 2] per gain, τ = 0.1 s, δ = 0.2 s, T* = 1.1 s, each timed
once after a warm-up (SymPy lambdify caches built):

1. a 201³ volume with the Taylor criterion (``methods=("taylor",)``), and the
   same with the printed one too (``("taylor", "printed")``);
2. an 801 × 801 slice over (k_x, k_v) at k_a = 0.5 with the exact certificate;
3. a 101³ volume with the exact certificate.

Targets on 2 cores: Taylor 201³ < 1 s, exact 801² < 10 s, exact 101³ < 60 s.

``--only cli`` (issues 9 and 31): the 801² slice through the command line with its
**default outputs** (every method, the NPZ, the default figures in the default formats, the
report; the CSV only up to ``stringstab.plots.outputs.CSV_MAX_POINTS`` points, so not for
801², since issue 31's sixth pass): ``stringstab region --fix k_a=0.5 --n 801 --workers 2``, a fresh process, against
:func:`region_map` alone on the same grid with the same methods and workers (timed in a fresh
process too, after a warm-up), ``--reps`` times, every variant alternated within a rep, with
the load beside each: wall and CPU time (all processes), and the median ratios CLI / map
(target ≤ 1.5 with the default outputs, issue 31).  The variants: *before* is the code of
``--base`` (default f6db69e, exported with ``git archive`` into a temporary folder, run on this
interpreter), *after* this checkout; *after, forkserver* this checkout with
``STRINGSTAB_START_METHOD=forkserver`` (the other start method of the policy, measured for the
choice); *after, png,pdf* this checkout with the figure formats of the base; *after, figures
all* this checkout with every method's class map (``--figures all``: the figures of the base
before the fifth pass of issue 31); *after, --csv* this checkout with the 60 MB CSV the base
writes by default (``--csv``).
For the exact maps it also times :func:`stringstab.certify.api.certify_batch`
alone, in this process, on a 20 000-point sample of the same grid: the
certificate's own cost per point, which bounds what the map can reach.

The machine may be shared: the load average is printed before each map.
Prints its figures; asserts nothing.  Example::

    python analysis/bench_regions.py            # all three
    python analysis/bench_regions.py --only taylor --workers 1
    python analysis/bench_regions.py --only cli --reps 5 --base f6db69e
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


#: Times region_map alone in a fresh process: a warm-up, then the map, wall and CPU
#: (this process and its reaped workers) printed as one line "<wall> <cpu>".
_MAP_ALONE = """
import resource, sys, time
import numpy as np
from stringstab.regions import region_map
def cpu():
    a, b = (resource.getrusage(w) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
    return a.ru_utime + a.ru_stime + b.ru_utime + b.ru_stime
n, workers = int(sys.argv[1]), int(sys.argv[2])
P = dict(tau=0.1, delta=0.2, headway=1.1)
g = np.linspace(-2, 2, 9)
region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, **P, workers=1, progress=False)
g = np.linspace(-2, 2, n)
c0, t0 = cpu(), time.perf_counter()
region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, **P, workers=workers, progress=False)
print(time.perf_counter() - t0, cpu() - c0)
"""


def _children_cpu() -> float:
    """CPU seconds of the finished children, and of their descendants that were reaped."""
    import resource

    b = resource.getrusage(resource.RUSAGE_CHILDREN)
    return b.ru_utime + b.ru_stime


def _adopt_orphans() -> None:
    """Become a subreaper (Linux): a command's orphans (a forkserver and the workers it forked,
    which outlive the command by a moment) are then reaped here and their CPU counted."""
    import ctypes

    PR_SET_CHILD_SUBREAPER = 36
    ctypes.CDLL(None).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)


def _reap_orphans(timeout: float = 10.0) -> None:
    """Wait for the adopted orphans to end (and count their CPU)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:  # no children left
            return
        if pid == 0:
            time.sleep(0.02)


def _checkout(commit: str) -> Path:
    """The package at ``commit``, exported into a temporary folder (no worktree, no checkout)."""
    root = Path(__file__).resolve().parents[1]
    dest = Path(tempfile.mkdtemp(prefix=f"bench_regions_{commit[:7]}_"))
    archive = subprocess.run(["git", "-C", str(root), "archive", commit, "stringstab"],
                             capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive, check=True)
    return dest


def _region_cli(n: int, reps: int, workers: int | None, base: str) -> None:
    """CLI (default outputs) over region_map alone, before (``base``) and after, alternated."""
    w = str(workers or 2)
    cli = [sys.executable, "-m", "stringstab", "region", "--fix", "k_a=0.5", "--n", str(n),
           "--workers", w, "--no-progress"]
    base_dir = _checkout(base)
    # run every command from a neutral folder: from the repository root, Python would import
    # this checkout's package (the current directory comes before PYTHONPATH)
    outside = tempfile.mkdtemp(prefix="bench_regions_cwd_")
    _adopt_orphans()
    here = dict(os.environ)
    here.pop("STRINGSTAB_START_METHOD", None)
    old = {**here, "PYTHONPATH": str(base_dir)}
    variants = {  # name: (environment, extra arguments, ratio against the map of ...)
        "before": (old, [], "before"),
        "after": (here, [], "after"),
        "after, forkserver": ({**here, "STRINGSTAB_START_METHOD": "forkserver"}, [], "after"),
        "after, png,pdf": (here, ["--format", "png,pdf"], "after"),
        "after, figures all": (here, ["--figures", "all"], "after"),
        "after, --csv": (here, ["--csv"], "after"),
    }
    print(f"region CLI target (issue 31): {n}x{n} slice, default outputs: stringstab region "
          f"{' '.join(cli[4:])} --out DIR; before = {base} ({base_dir}), after = this checkout")
    rows: dict[str, list[tuple[float, float]]] = {k: [] for k in ("map before", "map after", *variants)}
    files: dict[str, list[str]] = {}
    try:
        for r in range(reps):
            for label, env in (("map before", old), ("map after", here)):
                res = subprocess.run([sys.executable, "-c", _MAP_ALONE, str(n), w], env=env,
                                     capture_output=True, text=True, check=True, cwd=outside)
                wall, cpu = (float(x) for x in res.stdout.split())
                rows[label].append((wall, cpu))
                print(f"  rep {r + 1}: {label:<18} {wall:6.2f} s wall {cpu:6.2f} s CPU ({_load()})",
                      flush=True)
            for name, (env, extra, _) in variants.items():
                work = Path(tempfile.mkdtemp(prefix="bench_regions_cli_"))
                try:
                    c0, t0 = _children_cpu(), time.perf_counter()
                    res = subprocess.run([*cli, *extra, "--out", str(work / "maps")], env=env,
                                         capture_output=True, text=True, cwd=outside)
                    wall = time.perf_counter() - t0
                    _reap_orphans()
                    cpu = _children_cpu() - c0
                    if res.returncode != 0:
                        raise SystemExit(f"{name}: stringstab region failed: {res.stderr.strip()}")
                    files[name] = sorted(p.name for p in (work / "maps").iterdir()
                                         if not p.name.startswith("."))
                finally:
                    shutil.rmtree(work, ignore_errors=True)
                rows[name].append((wall, cpu))
                print(f"  rep {r + 1}: CLI {name:<18} {wall:6.2f} s wall {cpu:6.2f} s CPU "
                      f"({_load()})", flush=True)
    finally:
        shutil.rmtree(base_dir, ignore_errors=True)
        shutil.rmtree(outside, ignore_errors=True)
    for name, fs in files.items():
        print(f"  files, {name}: {len(fs)}: {', '.join(fs)}")
    print(f"  medians over {reps} reps ({_load()}):")
    for label in ("map before", "map after"):
        wall, cpu = (float(np.median([x[k] for x in rows[label]])) for k in (0, 1))
        print(f"    region_map alone, {label[4:]:<18} {wall:6.2f} s wall {cpu:6.2f} s CPU")
    for name, (_, _, against) in variants.items():
        ratio = [a[0] / b[0] for a, b in zip(rows[name], rows[f"map {against}"])]
        cpu_ratio = [a[1] / b[1] for a, b in zip(rows[name], rows[f"map {against}"])]
        print(f"    CLI / region_map, {name:<18} {np.median(ratio):5.2f} wall "
              f"(min {min(ratio):.2f}, max {max(ratio):.2f}), {np.median(cpu_ratio):5.2f} CPU"
              f"{'   (target <= 1.5)' if name == 'after' else ''}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", choices=("taylor", "slice", "volume", "cli"), action="append",
                    help="run only these benchmarks (repeatable; 'cli' only when named)")
    ap.add_argument("--reps", type=int, default=5, help="repetitions of the cli target (default 5)")
    ap.add_argument("--workers", type=int, default=None,
                    help="worker processes (default: region_map's choice, all cores; 2 for cli)")
    ap.add_argument("--base", default="f6db69e",
                    help="the commit measured as 'before' by --only cli (default f6db69e)")
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
        _region_cli(801, args.reps, args.workers, args.base)


if __name__ == "__main__":
    main()
