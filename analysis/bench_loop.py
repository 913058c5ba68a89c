"""Benchmark: what θ_r, the radio and the sensors cost the simulator, against the plain run.

Leader US06 at Δt = 0.05 s (12,001 steps), K = (1.2, 0.5, 0.6), τ = 0.1 s, δ = 0.2 s; a batch of
``--platoons`` (200) platoons × 10 followers (``record=False``) and one platoon of 10 followers
(``record=True``, bound by the per-step overhead).  Cases, each against the **plain run**
(no option) measured in the same process, best of ``--repeat``:

* θ_r = 0.2 s (a whole number of steps: one held piece per step);
* θ_r = 0.23 s (two pieces per step);
* the radio: messages every 0.1 s, 2 % loss in bursts of 3, stale after 0.5 s, fallback gains;
* the sensors: coloured noise on gap, gap rate and speed with a filter;
* all of them.

Prints vehicle-steps per second, the ratio to the plain run and the machine load
(``os.getloadavg()``); asserts nothing about time.

    python analysis/bench_loop.py
"""

from __future__ import annotations

import argparse
import os
import time
from typing import Any

import numpy as np

from stringstab.traffic import LinearController, Radio, SensorNoise, cycle, simulate

K = (1.2, 0.5, 0.6)
RADIO = Radio(message_period=0.1, loss=0.02, burst=3, stale_after=0.5, fallback_gains=(1.0, 0.8))
SENSORS = SensorNoise(gap=0.1, gap_rate=0.05, speed=0.05, correlation_time=1.0, filter_time=0.2)
CASES: dict[str, dict[str, Any]] = {
    "plain (baseline)": {},
    "theta_r = 0.2 s (whole steps)": {"reaction_delay": 0.2},
    "theta_r = 0.23 s (two pieces)": {"reaction_delay": 0.23},
    "radio (0.1 s, 2 % bursts, fallback)": {"radio": RADIO},
    "sensors (coloured, filtered)": {"sensors": SENSORS},
    "all of them": {"reaction_delay": 0.23, "radio": RADIO, "sensors": SENSORS},
}


def rate(platoons: int, record: bool, kw: dict[str, Any], repeat: int) -> float:
    """Best vehicle-steps per second of ``repeat`` runs.

    Parameters
    ----------
    platoons : int
        Platoons in the batch (10 followers each).
    record : bool
        Keep the trajectories.
    kw : dict
        Options of :func:`stringstab.traffic.simulate`.
    repeat : int
        Runs; the fastest counts.

    Returns
    -------
    float
        Vehicle-steps per second.
    """
    lead = cycle("us06", dt=0.05)
    leaders = [lead] * platoons if platoons > 1 else lead
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        simulate(leaders, LinearController(*K), 10, record=record, progress=False, **kw)
        best = min(best, time.perf_counter() - t0)
    return platoons * 10 * (lead.n_steps - 1) / best


def main() -> None:
    """Print the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--platoons", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    print(f"numpy {np.__version__}; US06 at dt = 0.05 s; load before: {os.getloadavg()[0]:.1f}")
    for platoons, record in ((a.platoons, False), (1, True)):
        base = None
        print(f"\n{platoons} platoon(s) x 10 followers, record={record}")
        for name, kw in CASES.items():
            r = rate(platoons, record, kw, a.repeat)
            base = base or r
            print(f"  {name:<40s} {r / 1e6:8.3f} M vehicle-steps/s   {r / base:6.3f} x plain")
    print(f"\nload after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
