"""The cost per triple of the sampled certificate with a reaction delay θ_r > 0 (issue 25 item 3).

Baseline: the sampled certificate at θ_r = 0 (today's code path), measured in the same run on
the same random triples (uniform in [0, 2] × [0, 3] × [0, 1], seeded), τ = 0.5 s, δ = 0.1 s,
T* = 1.5 s; best of ``--repeat``; the machine's load (``os.getloadavg()``) printed before and
after.  Printed: ms per triple through ``certify_batch`` and ``check`` and the ratio to the
θ_r = 0 baseline, for each H and θ_r.

    OPENBLAS_NUM_THREADS=1 nice -n 5 .venv/bin/python analysis/bench_sampled_reaction.py --n 200 --repeat 2

(The continuous θ_r certificate's cost is in analysis/bench_certify.py, part (e).)
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

import numpy as np

import stringstab as ss


def best_of(fn: Callable[[], object], repeat: int) -> float:
    """The best wall time of ``repeat`` calls, s."""
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=200, help="random triples")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    K = np.column_stack([rng.uniform(0, 2, a.n), rng.uniform(0, 3, a.n), rng.uniform(0, 1, a.n)])
    P = {"tau": 0.5, "delta": 0.1, "headway": 1.5}
    print(f"load before: {os.getloadavg()[0]:.2f}; {a.n} triples, best of {a.repeat}")
    print("| H (s) | θ_r (s) | call | θ_r = 0, ms/triple | θ_r > 0, ms/triple | ratio |")
    print("|---|---|---|---|---|---|")
    for H in (0.01, 0.1):
        for name, fn in (("certify_batch", ss.certify_batch), ("check", ss.check)):
            t0 = best_of(lambda fn=fn, H=H: fn(*K.T, **P, sample_time=H), a.repeat) / a.n
            for th in (0.5 * H, 2 * H, 0.25):
                t1 = best_of(lambda fn=fn, H=H, th=th: fn(*K.T, **P, sample_time=H,
                                                           reaction_delay=th), a.repeat) / a.n
                print(f"| {H:g} | {th:g} | `{name}` | {1e3 * t0:.3f} | {1e3 * t1:.3f} | "
                      f"{t1 / t0:.1f} |")
    print(f"load after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
