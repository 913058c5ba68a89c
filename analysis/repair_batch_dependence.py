"""Is a point verdict of ``Loop.check`` batch-dependent?  (issue 31, the repair's verdict cache)

The repair keeps each triple's verdict (:meth:`stringstab.tuning.repair.GainRepair.certified`)
and reuses it; the branch and bound sizes its splits over the whole call, so a row's verdict
could depend on the rows that share its call.  This script takes triples near the certified
boundary at the training defaults (τ = 0.1 s, δ = 0.2 s, T* = 1.1 s, H = dt = 0.1 s; θ_r = 0
and θ_r > 0), checks each row alone and in random batches of 8, and counts the rows whose
verdict differs (and how: certified versus not, or decided versus inconclusive).

Usage: ``OPENBLAS_NUM_THREADS=1 nice -n 5 .venv/bin/python analysis/repair_batch_dependence.py
[n] [theta_r] [loops]`` (default 2000 triples per loop, θ_r = 0.05 s, loops ``c0,s0,c1,s1``:
continuous / sampled at H, θ_r = 0 / θ_r > 0).

Measured 2026-11-28 (load 2.6-6.7, two runs: ``2000 0.05`` and ``2000 0.05 c0,s0,c1``, whose
c0 row reached 2,000 triples after the candidate pool was doubled): 0 rows differ alone versus
in random batches of 8 or in one batch of all, in each loop — continuous θ_r = 0 (2,000: 1,022
certified, 978 not), sampled θ_r = 0 (2,000), continuous θ_r = 0.05 s (2,000) and sampled
θ_r = 0.05 s (2,000: 808 certified, 1,128 not, 64 inconclusive, each inconclusive in all three
groupings).
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from stringstab.certify.api import Loop
from stringstab.constants import DELTA, DT, HEADWAY, TAU
from stringstab.params import Params
from stringstab.tuning.lattice import certified_lattice


def near_boundary(loop: Loop, pts: np.ndarray, n: int, rng: np.random.Generator) -> np.ndarray:
    """n triples within ~1e-4 of the loop's certified boundary (bisection from lattice points)."""
    ok = pts[rng.integers(0, pts.shape[0], 8 * n)]
    far = np.clip(ok + rng.normal(0.0, 0.3, ok.shape), -2.0, 2.0)
    v = loop.check(far[:, 0], far[:, 1], far[:, 2]).verdict
    keep = np.flatnonzero(v != "certified")[:n]
    a, b = ok[keep].copy(), far[keep].copy()
    for _ in range(12):
        m = 0.5 * (a + b)
        c = loop.check(m[:, 0], m[:, 1], m[:, 2]).verdict == "certified"
        a[c], b[~c] = m[c], m[~c]
    t = rng.uniform(0.0, 1.0, (a.shape[0], 1))
    return a + t * (b - a) + rng.normal(0.0, 1e-5, a.shape)


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    theta = float(sys.argv[2]) if len(sys.argv) > 2 else 0.05
    loops = (sys.argv[3] if len(sys.argv) > 3 else "c0,s0,c1,s1").split(",")
    rng = np.random.default_rng(31)
    pts = np.asarray(certified_lattice(TAU, DELTA, HEADWAY, -2.0, 2.0, 0.05, DT))
    print(f"load {os.getloadavg()}", flush=True)
    for th in (0.0, theta):
        p = Params(TAU, DELTA, HEADWAY, reaction_delay=th)
        for H in (None, DT):
            if f"{'s' if H else 'c'}{int(th > 0)}" not in loops:
                continue
            loop = Loop(p, H)
            t0 = time.perf_counter()
            K = near_boundary(loop, pts, n, rng)
            alone = np.array([loop.check(k[0], k[1], k[2]).verdict[0] for k in K])
            perm = rng.permutation(K.shape[0])
            in8 = np.empty_like(alone)
            for s in range(0, perm.size, 8):
                j = perm[s:s + 8]
                in8[j] = loop.check(K[j, 0], K[j, 1], K[j, 2]).verdict
            whole = loop.check(K[:, 0], K[:, 1], K[:, 2]).verdict
            d8, dw = alone != in8, alone != whole
            flip = int(np.sum(d8 & (alone != "inconclusive") & (in8 != "inconclusive")))
            name = f"{'sampled H=' + str(H) if H else 'continuous'}, theta_r={th:g}"
            counts = {v: int(np.sum(alone == v)) for v in ("certified", "not_certified",
                                                           "inconclusive")}
            print(f"{name}: {K.shape[0]} triples near the boundary, alone {counts}; "
                  f"differ alone vs batches of 8: {int(d8.sum())} (certified<->not: {flip}); "
                  f"alone vs one batch of all: {int(dw.sum())}; "
                  f"{time.perf_counter() - t0:.0f} s, load {os.getloadavg()[0]:.1f}", flush=True)
            for i in np.flatnonzero(d8 | dw)[:5]:
                print(f"   {K[i].tolist()}: alone {alone[i]}, in 8 {in8[i]}, in all {whole[i]}")


if __name__ == "__main__":
    main()
