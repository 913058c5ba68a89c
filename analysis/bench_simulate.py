"""Benchmark of the platoon simulator: vehicle-steps per second.

Cases (leader: the bundled US06 cycle at Δt = 0.1 s, 6001 steps; certified gains
K = (1.2, 0.5, 0.6); τ = 0.1 s, δ = 0.2 s, T* = 1.1 s):

1. ``--platoons`` (1,000) platoons × ``--followers`` (10) followers in one batched call,
   summaries only (``record=False``) and with full trajectories (``record=True``, on the first
   ``--record-steps`` steps, to bound memory);
2. one platoon of ``--long`` (100) followers, both ways;
3. the same batched case split over ``--processes`` worker processes (each simulates its share
   of the platoons; the figure is total vehicle-steps over wall time, start-up included);
4. the batched Gymnasium environment (``BatchedCarFollowingEnv``) with ``--envs`` (1,000)
   sub-environments: env-steps per second.

A vehicle-step is one follower advanced by one Δt.  Best of ``--repeat`` runs.  Prints its
figures; asserts nothing about time.  Example::

    python analysis/bench_simulate.py --processes 2
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from stringstab.parallel import process_pool
from stringstab.traffic import BatchedCarFollowingEnv, LinearController, cycle, simulate

K = (1.2, 0.5, 0.6)


def _run(n_platoons: int, n_followers: int, n_steps: int | None, record: bool) -> tuple[float, int]:
    lead = cycle("us06", dt=0.1)
    if n_steps is not None:
        lead = lead.window(0, n_steps)
    leaders = [lead] * n_platoons if n_platoons > 1 else lead
    t0 = time.perf_counter()
    simulate(leaders, LinearController(*K), n_followers, record=record, progress=False)
    return time.perf_counter() - t0, n_platoons * n_followers * (lead.n_steps - 1)


def best(repeat: int, *args: object) -> tuple[float, int]:
    runs = [_run(*args) for _ in range(repeat)]  # type: ignore[arg-type]
    return min(runs)


def parallel(processes: int, n_platoons: int, n_followers: int) -> tuple[float, int]:
    shares = [len(c) for c in np.array_split(np.arange(n_platoons), processes)]
    t0 = time.perf_counter()
    with process_pool(processes) as ex:  # the package's start-method policy
        done = list(ex.map(_run, shares, [n_followers] * processes, [None] * processes,
                           [False] * processes))
    return time.perf_counter() - t0, sum(n for _, n in done)


def env_rate(n_envs: int, steps: int) -> float:
    env = BatchedCarFollowingEnv(n_envs, [cycle("us06", dt=0.1)])
    env.reset(seed=0)
    acts = np.tile(np.array(K, dtype=np.float32), (n_envs, 1))
    t0 = time.perf_counter()
    for _ in range(steps):
        env.step(acts)
    return n_envs * steps / (time.perf_counter() - t0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--platoons", type=int, default=1000)
    ap.add_argument("--followers", type=int, default=10)
    ap.add_argument("--long", type=int, default=100)
    ap.add_argument("--record-steps", type=int, default=1001)
    ap.add_argument("--processes", type=int, default=1)
    ap.add_argument("--envs", type=int, default=1000)
    ap.add_argument("--env-steps", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    print(f"cpus: {os.cpu_count()}, numpy {np.__version__}; leader us06 at dt=0.1 s; K={K}")

    def show(label: str, sec: float, n: int) -> None:
        print(f"{label:<58s} {n:>12,d} vehicle-steps in {sec:7.3f} s = {n / sec / 1e6:8.2f} M/s")

    show(f"{a.platoons} platoons x {a.followers}, record=False", *best(a.repeat, a.platoons, a.followers, None, False))
    show(f"{a.platoons} platoons x {a.followers}, record=True ({a.record_steps} steps)",
         *best(a.repeat, a.platoons, a.followers, a.record_steps, True))
    show(f"1 platoon x {a.long}, record=False", *best(a.repeat, 1, a.long, None, False))
    show(f"1 platoon x {a.long}, record=True", *best(a.repeat, 1, a.long, None, True))
    if a.processes > 1:
        show(f"{a.platoons} platoons x {a.followers}, {a.processes} processes, record=False",
             *min(parallel(a.processes, a.platoons, a.followers) for _ in range(a.repeat)))
    rate = max(env_rate(a.envs, a.env_steps) for _ in range(a.repeat))
    print(f"{'BatchedCarFollowingEnv, ' + str(a.envs) + ' sub-envs':<58s} {rate / 1e6:8.2f} M env-steps/s")


if __name__ == "__main__":
    main()
