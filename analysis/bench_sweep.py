"""Sweep speed: an 8-point sweep run serially vs on a local Dask cluster, and the overhead per task.

1. **Serial vs cluster.**  The same 8 points (``certify`` points: the share of an n³ gain grid
   certified by the sampled-data certificate at Δt = 0.1 s, and the continuous share beside it,
   at 8 (τ, δ) pairs; CPU-bound, a few seconds each) computed one after another by
   :func:`stringstab.sweep.run_point` in this process (the baseline), then by
   :func:`stringstab.sweep.run_sweep` on a local cluster of ``--workers`` processes.  Printed as
   the ratio serial / cluster, with and without starting the cluster; the ideal is the worker
   count.  Each run writes to its own temporary folder (a fresh sweep: nothing skipped).
2. **Overhead per task.**  ``--probes`` probe points that do nothing (``seconds = 0``) on the
   cluster: wall time per task, i.e. submit, schedule, run, return and write the record.

The machine load (``os.getloadavg()``) is printed before and after: on a shared machine the
ratio is only as good as the cores actually free.  Asserts nothing.

    python analysis/bench_sweep.py                # about a minute on 2 cores
    python analysis/bench_sweep.py --n 41 --probes 100
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

from stringstab.sweep import dask_client, parse_spec, run_point, run_sweep

SPEC = """
[sweep]
name = "bench"
kind = "certify"
[base]
n = {n}
sample_time = 0.1
[axes]
tau = [0.1, 0.2]
delta = [0.1, 0.2, 0.3, 0.4]
"""


def _load() -> str:
    return "/".join(f"{x:.2f}" for x in os.getloadavg())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=31, help="grid points per gain axis (default 31)")
    ap.add_argument("--workers", type=int, default=2, help="local cluster workers (default 2)")
    ap.add_argument("--probes", type=int, default=50, help="empty tasks for the overhead (50)")
    args = ap.parse_args()
    spec = parse_spec(SPEC.format(n=args.n), source="bench")
    print(f"load before (1/5/15 min): {_load()}; {len(spec)} certify points of {args.n}^3 gains; "
          f"{os.cpu_count()} cores", flush=True)

    with tempfile.TemporaryDirectory() as tmp:
        run_point(spec.points[0].as_dict(), tmp)  # imports and caches, as a worker's first task
        t0 = time.perf_counter()
        for p in spec.points:
            rec = run_point(p.as_dict(), tmp)
            assert rec["status"] == "done", rec.get("error")
        serial = time.perf_counter() - t0
    print(f"serial (this process): {serial:.2f} s ({serial / len(spec):.2f} s per point); "
          f"load {_load()}", flush=True)

    t0 = time.perf_counter()
    with dask_client(workers=args.workers) as client:
        started = time.perf_counter() - t0
        with tempfile.TemporaryDirectory() as tmp:  # warm every worker (imports), not timed
            warm = parse_spec(SPEC.format(n=5), source="warm")
            run_sweep(warm, tmp, client=client, progress=False, log=lambda s: None)
        with tempfile.TemporaryDirectory() as tmp:
            t1 = time.perf_counter()
            s = run_sweep(spec, tmp, client=client, progress=False, log=lambda s: None)
            cluster = time.perf_counter() - t1
        assert s["done"] == len(spec), s
        probes = parse_spec(f'[sweep]\nkind = "probe"\nseeds = {{start = 0, stop = {args.probes - 1}, '
                            'step = 1}\n', source="probes")
        with tempfile.TemporaryDirectory() as tmp:
            t2 = time.perf_counter()
            run_sweep(probes, tmp, client=client, progress=False, log=lambda s: None)
            per_task = (time.perf_counter() - t2) / len(probes)
        with tempfile.TemporaryDirectory() as tmp:
            t3 = time.perf_counter()
            for p in probes.points:
                run_point(p.as_dict(), tmp)
            direct = (time.perf_counter() - t3) / len(probes)
    print(f"local cluster, {args.workers} workers: {cluster:.2f} s for the sweep "
          f"(+ {started:.2f} s to start the cluster); load {_load()}")
    print(f"ratio serial / cluster: {serial / cluster:.2f}x (sweep alone), "
          f"{serial / (cluster + started):.2f}x (with the cluster's start); ideal {args.workers}x")
    print(f"overhead per task ({len(probes)} empty probe tasks incl. the atomic record write and "
          f"the final table): {1e3 * per_task:.1f} ms on the cluster vs {1e3 * direct:.2f} ms "
          f"calling run_point directly")
    print(f"load after: {_load()}")


if __name__ == "__main__":
    main()
