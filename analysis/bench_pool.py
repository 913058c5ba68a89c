"""The worker pool's cost: a region map on 2 workers, before (a base commit) and after, one run.

``stringstab.parallel.WorkerPool`` (a pipe per worker) replaced
``concurrent.futures.ProcessPoolExecutor`` (whose shared result pipe could wait for ever for the
rest of a reply from a killed worker).  This measures what the change costs where users wait:
``region_map`` of an exact map on 2 workers (wall time, the command's own path: forked
workers, blocks as they finish), alternating base and checkout, each in a fresh process, with
the machine's load beside each run::

    python analysis/bench_pool.py --base 943e095 --n 601 --reps 5

The base is exported with ``git archive`` into a temporary folder and run from there
(``PYTHONPATH``); both sides use this checkout's interpreter and packages.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

WORKER = """
import json, os, sys, time
import numpy as np
from stringstab.regions import region_map
n = int(sys.argv[1])
axes = {"k_x": np.linspace(-1, 2, n), "k_v": np.linspace(-1, 2, n)}
t0 = time.perf_counter()
m = region_map(axes, {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1, methods="exact",
               workers=2, progress=False)
wall = time.perf_counter() - t0
print(json.dumps({"wall": wall, "certified": int((m.verdict["exact"] == 1).sum()),
                  "load": os.getloadavg()[0]}))
"""


def _run(src: Path, n: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(src), OPENBLAS_NUM_THREADS="1")
    out = subprocess.run([sys.executable, "-c", WORKER, str(n)], env=env, capture_output=True,
                         text=True, check=True, cwd=tempfile.gettempdir())
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--base", default="943e095", help="the commit before (default 943e095)")
    ap.add_argument("--n", type=int, default=601, help="grid points per axis (default 601)")
    ap.add_argument("--reps", type=int, default=5, help="alternations (default 5)")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        arch = subprocess.run(["git", "archive", a.base, "stringstab"], cwd=ROOT, check=True,
                              capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", tmp], input=arch, check=True)
        sides = {"before": Path(tmp), "after": ROOT}
        got: dict[str, list[dict]] = {k: [] for k in sides}
        for r in range(a.reps):
            for k, src in (sides.items() if r % 2 == 0 else reversed(sides.items())):
                res = _run(src, a.n)
                got[k].append(res)
                print(f"rep {r} {k:6s} wall {res['wall']:.2f} s  certified {res['certified']}  "
                      f"load {res['load']:.1f}", flush=True)
    b = statistics.median(x["wall"] for x in got["before"])
    f = statistics.median(x["wall"] for x in got["after"])
    same = {x["certified"] for x in got["before"]} == {x["certified"] for x in got["after"]}
    print(f"\nregion_map {a.n}² exact, 2 workers, median wall: before ({a.base}) {b:.2f} s, "
          f"after {f:.2f} s, after/before {f / b:.3f}; same certified count: {same}")


if __name__ == "__main__":
    main()
