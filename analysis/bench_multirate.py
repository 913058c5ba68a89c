"""Benchmark of the multi-rate certificate against the sampled one, in the same run (issue 26).

The same ``--n`` random gain triples K uniform in [−2, 2]³ (``--seed``; τ = 0.1 s, δ = 0.2 s,
T* = 1.1 s) are certified through the way in (:func:`stringstab.certify.api.certify_batch` and
:func:`~stringstab.certify.api.check`):

* the baseline: the sampled certificate (a message every control step) at the sample time H;
* the multi-rate certificate at the same H with messages every N steps, for each ``--steps``.

Each is timed as the best of ``--repeat`` runs and printed as ms per triple and as the ratio to
the baseline *of the same H in the same run*, with the verdict counts.  The target of issue 26
is a ratio ≤ 50 at N = 10.  The machine load (``os.getloadavg()``) is printed before and after;
nothing about time is asserted.  Most random triples are not internally stable (decided by the
Schur conditions alone); the stable ones carry the cost, so the mean over the Schur-stable
triples is printed too.

    python analysis/bench_multirate.py --n 2000 --repeat 3
    python analysis/bench_multirate.py --n 500 --h 0.1 --steps 2,5,10
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from stringstab.certify.api import certify_batch, check

P = {"tau": 0.1, "delta": 0.2, "headway": 1.1}


def best_of(fn, repeat: int) -> tuple[float, object]:
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def counts(v: np.ndarray) -> str:
    return " / ".join(str(int((v == w).sum())) for w in ("certified", "not_certified", "inconclusive"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--h", type=float, action="append", help="sample times (default 0.01 and 0.1)")
    ap.add_argument("--steps", default="10", help="message periods in steps, e.g. 2,5,10")
    a = ap.parse_args()
    K = np.random.default_rng(a.seed).uniform(-2, 2, (a.n, 3))
    steps = [int(s) for s in a.steps.split(",")]
    print(f"{a.n} random triples in [-2, 2]^3 (seed {a.seed}), tau = 0.1 s, delta = 0.2 s, "
          f"T* = 1.1 s; best of {a.repeat}; load before {os.getloadavg()}")
    print("| H (s) | certificate | call | ms per triple | ratio to the sampled baseline | "
          "ms per Schur-stable triple | certified / not / inconclusive |")
    print("|---|---|---|---|---|---|---|")
    for H in a.h or [0.01, 0.1]:
        for call, fn in (("certify_batch", certify_batch), ("check", check)):
            tb, b = best_of(lambda fn=fn, H=H: fn(*K.T, **P, sample_time=H), a.repeat)
            stable = int(np.asarray(b.stable).sum())
            print(f"| {H:g} | sampled (baseline) | {call} | {1e3 * tb / a.n:.4f} | 1.00 | "
                  f"{1e3 * tb / max(stable, 1):.3f} | {counts(b.verdict)} |", flush=True)
            for N in steps:
                t, m = best_of(lambda fn=fn, N=N, H=H: fn(*K.T, **P, sample_time=H,
                                                     message_period=N * H), a.repeat)
                print(f"| {H:g} | multi-rate, N = {N} ({N * H:g} s) | {call} | {1e3 * t / a.n:.4f} | "
                      f"{t / tb:.1f} | {1e3 * t / max(stable, 1):.3f} | {counts(m.verdict)} |",
                      flush=True)
    print(f"load after {os.getloadavg()}")


if __name__ == "__main__":
    main()
