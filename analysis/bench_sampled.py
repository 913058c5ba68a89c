"""Per-triple cost of the sampled-data and robust certificates next to the continuous one.

The same ``--n`` random gain triples K uniform in [−2, 2]³ (``--seed``) at τ = 0.1 s,
δ = 0.2 s, T* = 1.1 s are certified, in the same run, by

* the continuous certificate: :func:`stringstab.certificate.certify_batch` (the
  baseline) and its verdict-only :func:`~stringstab.certificate.check`;
* the sampled-data certificate at Δt = 0.1 s (δ on a multiple of Δt) and at Δt = 0.08 s
  (δ/Δt = 2.5): :func:`stringstab.sampled.certify_sampled_batch` and
  :func:`~stringstab.sampled.check_sampled`;
* the robust certificate over τ ∈ [0.1, 0.2], δ ∈ [0.15, 0.25], T* ∈ [1.0, 1.2]:
  continuous, and sampled at Δt = 0.1 s (heterogeneous lags) on the first
  ``--n-robust-sampled`` triples (it is the slow one).

Each is timed as the best of ``--repeat`` runs; printed as ms per triple and as the
ratio to the baseline measured in the same run, with the machine load
(``os.getloadavg()``) before and after.  Asserts nothing about time.  Example::

    python analysis/bench_sampled.py --n 5000 --repeat 3
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

import numpy as np

from stringstab.certificate import certify_batch, check
from stringstab.robust import certify_robust_batch
from stringstab.sampled import certify_sampled_batch, check_sampled

P = dict(tau=0.1, delta=0.2, headway=1.1)
BOX = dict(tau=(0.1, 0.2), delta=(0.15, 0.25), headway=(1.0, 1.2))


def best_of(f: Callable[[], object], repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=5000)
    ap.add_argument("--n-robust-sampled", type=int, default=500)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    K = np.random.default_rng(args.seed).uniform(-2.0, 2.0, (args.n, 3))
    Ks = K[: args.n_robust_sampled]
    print(f"# {args.n} triples in [-2, 2]^3 (seed {args.seed}), best of {args.repeat}; "
          "load before %.2f %.2f %.2f" % os.getloadavg())
    cases: list[tuple[str, Callable[[], object], int]] = [
        ("continuous certify_batch (baseline)", lambda: certify_batch(*K.T, **P), args.n),
        ("continuous check", lambda: check(*K.T, **P), args.n),
        ("sampled certify_sampled_batch, Δt = 0.1 s",
         lambda: certify_sampled_batch(*K.T, sample_time=0.1, **P), args.n),
        ("sampled check_sampled, Δt = 0.1 s", lambda: check_sampled(*K.T, sample_time=0.1, **P),
         args.n),
        ("sampled certify_sampled_batch, Δt = 0.08 s (δ/Δt = 2.5)",
         lambda: certify_sampled_batch(*K.T, sample_time=0.08, **P), args.n),
        ("robust continuous, box τ/δ/T*", lambda: certify_robust_batch(*K.T, **BOX), args.n),
        ("robust sampled Δt = 0.1 s, box τ/δ/T*, heterogeneous",
         lambda: certify_robust_batch(*Ks.T, sample_time=0.1, **BOX), len(Ks)),
    ]
    base = None
    print("\n| certificate | ms per triple | ratio to certify_batch |")
    print("|---|---|---|")
    for name, f, n in cases:
        t = best_of(f, args.repeat) / n * 1e3
        base = t if base is None else base
        print(f"| {name} | {t:.4f} | {t / base:.2f} |")
    verdicts = {
        "continuous": check(*K.T, **P).verdict,
        "sampled 0.1": check_sampled(*K.T, sample_time=0.1, **P).verdict,
        "robust continuous": certify_robust_batch(*K.T, **BOX).verdict,
        "robust sampled 0.1": certify_robust_batch(*Ks.T, sample_time=0.1, **BOX).verdict,
    }
    print("\n| verdicts | certified | not_certified | inconclusive |")
    print("|---|---|---|---|")
    for name, v in verdicts.items():
        print(f"| {name} ({v.size}) | " + " | ".join(
            str(int(np.count_nonzero(v == x))) for x in ("certified", "not_certified", "inconclusive"))
            + " |")
    print("\nload after %.2f %.2f %.2f" % os.getloadavg())  # noqa: UP031


if __name__ == "__main__":
    main()
