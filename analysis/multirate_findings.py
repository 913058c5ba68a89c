"""What the multi-rate certificate finds: the gains the V2V message rate loses (issue 26, item 5).

Measured by the tool; prints its tables, asserts nothing.

1. **The IDL range.**  On an n³ grid over [−2, 2]³ (the IDL paper's action space, Table 2;
   default n = 41, step 0.1) at τ = 0.1 s, δ = 0.2 s, T* = 1.1 s: of the triples certified
   in continuous time, the share certified, not certified and inconclusive when every vehicle
   samples at H (0.01 or 0.1 s) and the predecessor's acceleration arrives by message every
   step (the sampled loop), at 10 Hz (every 0.1 s) and at 5 Hz (every 0.2 s)
   (:func:`stringstab.certify.api.check` with ``message_period``), and the largest peak
   sup σ_max(G) among those lost (:func:`~stringstab.certify.api.certify_batch`).
2. **Named gains.**  cavsandbox 0.11's default CACC K = (0.45, 0.25, 0.9), the demo's
   certified gains (``stringstab demo``: the triples of its certify step certified in
   continuous time, and K = (1.2, 0.5, 0.6) of its simulate step) at 10 Hz, and their
   largest certified message period (every shorter one certified too) up to 0.5 s.
3. **Non-monotonicity.**  On a sample of the continuous-certified grid triples at H = 0.1 s:
   triples certified at some N·H although not at a smaller N (the certified set of message
   periods is not always an interval).

    python analysis/multirate_findings.py                  # tens of minutes on 2 busy cores
    python analysis/multirate_findings.py --n 21 --skip-grid-h 0.01
"""

from __future__ import annotations

import argparse
import os
import time

# one BLAS thread per process: the batched linear algebra is many small problems, and a
# multi-threaded OpenBLAS waiting for busy cores made it 10-25x slower on a shared machine
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np

from stringstab import constants
from stringstab.certify.api import Loop, certify_batch, check
from stringstab.certify.message_period import largest_message_period
from stringstab.cli.demo_steps import DEMO_TRIPLES

TAU, DELTA, HEADWAY = constants.TAU, constants.DELTA, constants.HEADWAY
P = {"tau": TAU, "delta": DELTA, "headway": HEADWAY}
CAVSANDBOX = (0.45, 0.25, 0.9)
DEMO_SIMULATE = (1.2, 0.5, 0.6)


def load() -> str:
    return "load %.2f %.2f %.2f" % os.getloadavg()  # noqa: UP031


def grid(n: int) -> np.ndarray:
    g = np.linspace(*constants.GAIN_BOUNDS, n)
    return np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)


def pct(k: int, n: int) -> str:
    return f"{k:,} ({100.0 * k / n:.1f} %)"


def idl_range(n: int, hs: list[float]) -> np.ndarray:
    K = grid(n)
    t0 = time.perf_counter()
    cont = check(*K.T, **P).verdict
    C = K[cont == "certified"]
    print(f"grid {n}^3 = {len(K):,} triples over [-2, 2]^3; certified in continuous time: "
          f"{len(C):,} ({100.0 * len(C) / len(K):.2f} %)  [{time.perf_counter() - t0:.1f} s]")
    print("| H (s) | messages | certified | not certified | inconclusive | largest peak among the lost |")
    print("|---|---|---|---|---|---|")
    for H in hs:
        for label, period in (("every step", H), ("10 Hz", 0.1), ("5 Hz", 0.2)):
            if period < H - 1e-12:
                continue
            t0 = time.perf_counter()
            v = check(*C.T, **P, sample_time=H, message_period=period).verdict
            lost = C[v != "certified"]
            peak = ""
            nc = C[v == "not_certified"]
            if len(nc):
                b = certify_batch(*nc.T, **P, sample_time=H, message_period=period)
                j = int(np.nanargmax(np.where(np.isfinite(b.sup_gain), b.sup_gain, np.nan)))
                peak = (f"{b.sup_gain[j]:.4f} at K = ({nc[j, 0]:.1f}, {nc[j, 1]:.1f}, "
                        f"{nc[j, 2]:.1f})")
            print(f"| {H:g} | {label} ({period:g} s) | {pct(int((v == 'certified').sum()), len(C))} | "
                  f"{pct(int((v == 'not_certified').sum()), len(C))} | "
                  f"{pct(int((v == 'inconclusive').sum()), len(C))} | {peak} |  "
                  f"[{time.perf_counter() - t0:.0f} s, {load()}]", flush=True)
            del lost
    return C


def named(hs: list[float]) -> None:
    demo = [tuple(float(x) for x in t.split(",")) for t in DEMO_TRIPLES]
    cont = check(*np.array(demo).T, **P).verdict
    gains = {"cavsandbox CACC": CAVSANDBOX, "demo simulate step": DEMO_SIMULATE}
    for t, v in zip(demo, cont):
        if v == "certified":
            gains[f"demo certify step #{demo.index(t) + 1}"] = t
    print("\n| gains | H (s) | continuous | messages every step | 10 Hz | sup σ(G) at 10 Hz | "
          "fallback (k_a = 0) | largest certified period (cap 0.5 s) |")
    print("|---|---|---|---|---|---|---|---|")
    for name, K in gains.items():
        c = check(*([v] for v in K), **P).verdict[0]
        for H in hs:
            s = check(*([v] for v in K), **P, sample_time=H).verdict[0]
            b = certify_batch(*([v] for v in K), **P, sample_time=H, message_period=0.1)
            m10 = b.verdict[0]
            sup = b.sup_gain[0]
            fbs = check([K[0]], [K[1]], [0.0], **P, sample_time=H).verdict[0]
            mp = largest_message_period(Loop.of(**P, sample_time=H), *([v] for v in K), cap=0.5)
            first = (f"{mp.verdict[0]} at {mp.first_failure_period[0]:g} s"
                     if mp.verdict[0] != "certified" else "every period up to the cap")
            print(f"| {name} {K} | {H:g} | {c} | {s} | {m10} | {sup:.4f} | {fbs} | "
                  f"{mp.max_message_period[0]:g} s ({first}) |", flush=True)


def non_monotone(C: np.ndarray, H: float, n_max: int, sample: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    S = C[rng.choice(len(C), size=min(sample, len(C)), replace=False)]
    V = np.stack([check(*S.T, **P, sample_time=H, message_period=N * H).verdict == "certified"
                  for N in range(1, n_max + 1)], axis=1)
    first_fail = np.where(~V.all(axis=1), np.argmin(V, axis=1), n_max)
    later = np.array([V[i, first_fail[i]:].any() for i in range(len(S))])
    print(f"\nnon-monotone (H = {H:g} s, N = 1..{n_max}, {len(S)} continuous-certified grid "
          f"triples): {int(later.sum())} certified at some N after a failing smaller N")
    for i in np.flatnonzero(later)[:5]:
        print(f"  K = {tuple(float(x) for x in np.round(S[i], 2))}: certified N = "
              f"{[int(N) + 1 for N in np.flatnonzero(V[i])]}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=41)
    ap.add_argument("--skip-grid-h", type=float, action="append", default=[])
    ap.add_argument("--monotone-sample", type=int, default=600)
    a = ap.parse_args()
    t0 = time.perf_counter()
    print(f"τ = {TAU} s, δ = {DELTA} s, T* = {HEADWAY} s; {load()}")
    hs = [h for h in (0.01, 0.1) if h not in a.skip_grid_h]
    C = idl_range(a.n, hs)
    named([0.01, 0.1])
    non_monotone(C, 0.1, 10, a.monotone_sample, 0)
    print(f"\ntotal {time.perf_counter() - t0:.0f} s; {load()}")


if __name__ == "__main__":
    main()
