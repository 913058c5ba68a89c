"""The cost of the robust certificate over a box with the reaction delay θ_r (issue 25, item 4).

On the same random triples, in one run, through the one way in (``certify_batch``), µs per
triple (best of ``--repeat`` runs):

* the **point** θ_r certificate at the box's centre (τ, δ, T*, θ_r) — the baseline;
* the **θ_r = 0 box** over τ × δ × T* (today's closed-form box certificate);
* the **θ_r box**: the same τ × δ × T* box with θ_r ∈ [θ_lo, θ_hi] (and a narrow θ_r
  interval, and a point θ_r inside the τ × δ × T* box);

each as ratios to the point θ_r certificate and to the θ_r = 0 box, with the verdict counts.
Two samples of gains: the IDL range K ∈ [−2, 2]³ (half has k_x < 0: decided at once) and a
range where certified gains are common (k_x ∈ [0.05, 1.2], k_v ∈ [0, 2], k_a ∈ [−0.5, 1]).
The machine load (``os.getloadavg()``) is printed before and after; nothing is asserted.

    nice -n 5 python analysis/bench_box_reaction.py --n 1000      # the docs' table
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

import numpy as np

from stringstab.certify.api import certify_batch

TAU, DELTA, HEADWAY = (0.1, 0.2), (0.15, 0.25), (1.0, 1.4)


def best_of(f: Callable[[], object], repeat: int) -> float:
    """The shortest of ``repeat`` runs of ``f``, s."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t0)
    return best


def counts(v: np.ndarray) -> str:
    """certified / not_certified / inconclusive counts."""
    return " / ".join(str(int(np.count_nonzero(v == x)))
                      for x in ("certified", "not_certified", "inconclusive"))


def table(name: str, K: np.ndarray, theta: tuple[float, float], repeat: int) -> None:
    """One sample of gains: the rows of the module docstring."""
    mid = {k: 0.5 * (lo + hi) for k, (lo, hi) in
           (("tau", TAU), ("delta", DELTA), ("headway", HEADWAY))}
    th_mid = 0.5 * (theta[0] + theta[1])
    box = {"tau": TAU, "delta": DELTA, "headway": HEADWAY}
    runs = {
        f"point θ_r = {th_mid:g} at the centre (baseline)": dict(**mid, reaction_delay=th_mid),
        "θ_r = 0 box (today's)": dict(**box),
        f"θ_r box [{theta[0]:g}, {theta[1]:g}]": dict(**box, reaction_delay=theta),
        f"θ_r box [{th_mid - 0.01:g}, {th_mid + 0.01:g}]": dict(
            **box, reaction_delay=(th_mid - 0.01, th_mid + 0.01)),
        f"point θ_r = {th_mid:g} in the τ × δ × T* box": dict(**box, reaction_delay=th_mid),
    }
    n = len(K)
    print(f"\n{name}: {n} triples, τ {TAU}, δ {DELTA}, T* {HEADWAY} "
          f"(load {os.getloadavg()[0]:.2f})")
    print("| run | µs per triple | ratio to the point θ_r | ratio to the θ_r = 0 box "
          "| certified / not / inconclusive |")
    print("|---|---|---|---|---|")
    times: dict[str, float] = {}
    for label, prm in runs.items():
        certify_batch(*K[:2].T, **prm)  # warm-up
        times[label] = best_of(lambda prm=prm: certify_batch(*K.T, **prm), repeat) / n
        v = certify_batch(*K.T, **prm).verdict
        t_point, t_box = next(iter(times.values())), times.get("θ_r = 0 box (today's)")
        print(f"| {label} | {times[label] * 1e6:.0f} | {times[label] / t_point:.2f} | "
              f"{'' if t_box is None else f'{times[label] / t_box:.2f}'} | {counts(v)} |")


def main(argv: list[str] | None = None) -> int:
    """Print the tables (module docstring)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--theta", default="0.1:0.3", help="θ_r interval LO:HI (default 0.1:0.3)")
    a = ap.parse_args(argv)
    lo, hi = (float(x) for x in a.theta.split(":"))
    rng = np.random.default_rng(a.seed)
    print(f"load before: {os.getloadavg()}")
    table("IDL range K ∈ [−2, 2]³", rng.uniform(-2.0, 2.0, size=(a.n, 3)), (lo, hi), a.repeat)
    K = np.column_stack([rng.uniform(0.05, 1.2, a.n), rng.uniform(0.0, 2.0, a.n),
                         rng.uniform(-0.5, 1.0, a.n)])
    table("certifiable range", K, (lo, hi), a.repeat)
    print(f"\nload after: {os.getloadavg()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
