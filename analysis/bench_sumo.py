"""Benchmark of the SUMO co-simulation: vehicle-steps per second, as ratios to the toolkit's.

One platoon of ``--followers`` (10) followers behind the bundled UDDS cycle (Δt = 0.1 s,
13,690 steps; K = (1.2, 0.5, 0.6), τ = 0.1 s, δ = 0.2 s), run once each way in the same
process, in this order:

1. the toolkit's simulator (:func:`stringstab.traffic.simulate`, trapezoidal positions: the
   baseline);
2. SUMO through libsumo (:func:`stringstab.sumo.cosimulate`, ``api="libsumo"``);
3. SUMO through TraCI with subscriptions (``api="traci"``; SUMO a subprocess on 127.0.0.1).

Each SUMO figure includes everything a run does: netconvert building the road, SUMO's start,
the controller and the recording (the toolkit's includes its own set-up).  A vehicle-step is one
follower advanced by one step.  The machine's load average is printed before and after (the
figures are one run on a shared machine: read the ratios, not the absolute numbers).  Asserts
nothing about time.  Example::

    python analysis/bench_sumo.py --followers 10
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from stringstab.sumo import cosimulate
from stringstab.traffic import LinearController, leader_by_name, simulate


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--followers", type=int, default=10)
    ap.add_argument("--leader", default="udds")
    args = ap.parse_args()
    lead = leader_by_name(args.leader, dt=0.1)
    c = LinearController(1.2, 0.5, 0.6)
    N, T = args.followers, lead.n_steps
    vsteps = N * (T - 1)
    print(f"platoon: {N} followers behind {lead.name} ({T} steps of {lead.dt:g} s); "
          f"load average before: {os.getloadavg()[0]:.2f}")
    rates: dict[str, float] = {}
    runs = {}
    for name, fn in (
        ("toolkit simulate", lambda: simulate(lead, c, N, position_update="trapezoid")),
        ("SUMO libsumo", lambda: cosimulate(lead, c, N, api="libsumo")),
        ("SUMO traci + subscriptions", lambda: cosimulate(lead, c, N, api="traci")),
    ):
        t0 = time.perf_counter()
        runs[name] = fn()
        dt = time.perf_counter() - t0
        rates[name] = vsteps / dt
        print(f"{name:28s} {dt:8.3f} s  {rates[name]:12.0f} vehicle-steps/s  "
              f"(load {os.getloadavg()[0]:.2f})")
    base = rates["toolkit simulate"]
    print("ratios (vehicle-steps/s over the toolkit's simulator, same run):")
    for name, r in rates.items():
        print(f"  {name:28s} {r / base:.4f}x")
    lib = rates["SUMO libsumo"]
    print(f"  libsumo over traci+subscriptions: {lib / rates['SUMO traci + subscriptions']:.2f}x")
    a = runs["toolkit simulate"].accel
    for name in ("SUMO libsumo", "SUMO traci + subscriptions"):
        print(f"  max |accel difference| {name} vs toolkit: "
              f"{float(np.max(np.abs(runs[name].accel - a))):.2e} m/s²")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
