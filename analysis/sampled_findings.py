"""What the sampled-data and robust certificates find over the IDL paper's gain range.

Measured by the tool (issue 10, item 4); prints its tables, asserts nothing.

1. **Sampling.**  On an n³ grid over [−2, 2]³ (the IDL paper's action space, Table 2:
   each of k_x, k_v, k_a in [−2, 2]; default n = 41, step 0.1) at τ = 0.1 s, δ = 0.2 s,
   T* = 1.1 s: the share certified in continuous time, and the share of those that are
   *not* certified when every vehicle samples at Δt = 0.05, 0.1, 0.2 s with a
   zero-order hold (:func:`stringstab.certify.api.certify_batch` with ``sample_time``), with the largest
   sampled peak sup|H(e^{jθ})| among them and its gains.
2. **Robustness.**  How the certified share shrinks as the τ and δ boxes widen
   (:func:`stringstab.certify.api.certify_batch` with intervals): continuous time on the same grid,
   and sampled at Δt = 0.1 s on a coarser grid (``--n-robust-sampled``, default 11³).
3. **The paper's range and example gains.**  How much of the continuous-certified part
   of [−2, 2]³ survives at the paper's own step (Δt = 0.1 s: not printed, but its leaders
   are NGSIM trajectories at 10 Hz, IDL §4.1.1),
   and the verdicts of gains used as examples: K = (1.2, 0.5, 0.6) (this toolkit's
   examples) and the CACC baseline (k_x, k_v, k_a) = (0.1, 0.58, 1.0) of van Arem et al.
   used by the IDL paper, also at the HCFS paper's step Δt = 0.2 s.

Example::

    python analysis/sampled_findings.py              # a few minutes on 2 cores
    python analysis/sampled_findings.py --n 61 --n-robust-sampled 15
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from stringstab import constants
from stringstab.certify.api import certify, certify_batch, check

TAU, DELTA, HEADWAY = constants.TAU, constants.DELTA, constants.HEADWAY
PERIODS = (0.05, constants.DT, 0.2)  # around the IDL paper's step; 0.2 s is HCFS's


def load() -> str:
    return "load %.2f %.2f %.2f" % os.getloadavg()  # noqa: UP031


def grid(n: int) -> np.ndarray:
    g = np.linspace(*constants.GAIN_BOUNDS, n)
    return np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)


def share(mask: np.ndarray) -> str:
    return f"{100.0 * np.count_nonzero(mask) / mask.size:6.2f} %"


def sampling(K: np.ndarray) -> np.ndarray:
    t0 = time.perf_counter()
    cont = check(*K.T, tau=TAU, delta=DELTA, headway=HEADWAY).verdict
    print(f"continuous: certified {share(cont == 'certified')} of the grid, "
          f"inconclusive {np.count_nonzero(cont == 'inconclusive')}  "
          f"({time.perf_counter() - t0:.1f} s)")
    cert = cont == "certified"
    print("\n| Δt (s) | sampled certified | continuous-certified not certified sampled "
          "| of which not_certified / inconclusive | sampled-only certified | largest sampled peak among them (K, ω) |")
    print("|---|---|---|---|---|---|")
    for H in PERIODS:
        t0 = time.perf_counter()
        s = check(*K.T, tau=TAU, delta=DELTA, headway=HEADWAY, sample_time=H).verdict
        lost = cert & (s != "certified")
        n_not = np.count_nonzero(lost & (s == "not_certified"))
        n_inc = np.count_nonzero(lost & (s == "inconclusive"))
        gained = (s == "certified") & ~cert
        peak = "—"
        if lost.any():
            b = certify_batch(*K[lost].T, tau=TAU, delta=DELTA, headway=HEADWAY, sample_time=H)
            i = int(np.nanargmax(np.where(np.isfinite(b.sup_gain), b.sup_gain, -np.inf)))
            peak = (f"{b.sup_gain[i]:.4f} at K = ({b.k_x[i]:.1f}, {b.k_v[i]:.1f}, "
                    f"{b.k_a[i]:.1f}), ω = {b.peak_omega[i]:.3f} rad/s")
        print(f"| {H} | {share(s == 'certified')} | {np.count_nonzero(lost)} of "
              f"{np.count_nonzero(cert)} ({100.0 * np.count_nonzero(lost) / max(1, np.count_nonzero(cert)):.1f} %) "
              f"| {n_not} / {n_inc} | {np.count_nonzero(gained)} | {peak} |"
              f"  ({time.perf_counter() - t0:.1f} s)")
    return np.asarray(cert)


def robust_tables(K: np.ndarray, Ks: np.ndarray) -> None:
    taus = [(0.1, 0.1), (0.1, 0.15), (0.1, 0.2), (0.1, 0.3), (0.1, 0.5)]
    deltas = [(0.2, 0.2), (0.15, 0.25), (0.1, 0.3), (0.0, 0.4)]
    print(f"\ncontinuous time, T* = {HEADWAY} s, {len(K)} triples: certified share of the grid")
    print("| τ box (s) | " + " | ".join(f"δ ∈ [{a}, {b}]" for a, b in deltas) + " |")
    print("|---|" + "---|" * len(deltas))
    t0 = time.perf_counter()
    for t in taus:
        row = []
        for d in deltas:
            v = certify_batch(*K.T, tau=t, delta=d, headway=HEADWAY).verdict
            row.append(share(v == "certified").strip())
        print(f"| [{t[0]}, {t[1]}] | " + " | ".join(row) + " |")
    print(f"({time.perf_counter() - t0:.1f} s)")
    H = constants.DT
    print(f"\nsampled at Δt = {H} s, heterogeneous lags (τ_prev in the τ box), "
          f"{len(Ks)} triples: certified / inconclusive share")
    sub_t, sub_d = taus[:3], deltas[:3]
    print("| τ box (s) | " + " | ".join(f"δ ∈ [{a}, {b}]" for a, b in sub_d) + " |")
    print("|---|" + "---|" * len(sub_d))
    for t in sub_t:
        row = []
        for d in sub_d:
            t0 = time.perf_counter()
            v = certify_batch(*Ks.T, tau=t, delta=d, headway=HEADWAY, sample_time=H).verdict
            row.append(f"{share(v == 'certified').strip()} / {share(v == 'inconclusive').strip()}"
                       f" ({time.perf_counter() - t0:.0f} s)")
        print(f"| [{t[0]}, {t[1]}] | " + " | ".join(row) + " |")


def examples() -> None:
    print("\nexample gains (τ = 0.1 s, δ = 0.2 s)")
    print("| K | T* (s) | continuous | Δt = 0.05 | Δt = 0.1 | Δt = 0.2 |")
    print("|---|---|---|---|---|---|")
    for K, h in (((1.2, 0.5, 0.6), 1.1), ((0.1, 0.58, 1.0), 1.1), ((0.1, 0.58, 1.0), 0.5)):
        c = check(*([k] for k in K), tau=TAU, delta=DELTA, headway=h).verdict[0]
        cells = []
        for H in PERIODS:
            r = certify(*K, tau=TAU, delta=DELTA, headway=h, sample_time=H)
            cells.append(r.verdict if r.certified else f"{r.verdict} (peak {r.sup_gain:.4f})")
        print(f"| {K} | {h} | {c} | " + " | ".join(cells) + " |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=41, help="grid points per gain axis")
    ap.add_argument("--n-robust-sampled", type=int, default=11,
                    help="grid points per axis for the sampled robust table")
    args = ap.parse_args()
    K = grid(args.n)
    print(f"# sampled and robust findings: {args.n}³ = {len(K)} triples over [-2, 2]³, "
          f"τ = {TAU} s, δ = {DELTA} s, T* = {HEADWAY} s; {load()}")
    cert = sampling(K)
    H = constants.DT
    s = check(*K[cert].T, tau=TAU, delta=DELTA, headway=HEADWAY, sample_time=H).verdict
    print(f"\nthe paper's range at its own step (Δt = {H} s): {np.count_nonzero(s == 'certified')} of "
          f"the {np.count_nonzero(cert)} continuous-certified grid points survive "
          f"({100.0 * np.count_nonzero(s == 'certified') / max(1, np.count_nonzero(cert)):.1f} %)")
    examples()
    robust_tables(K, grid(args.n_robust_sampled))
    print(f"\n{load()}")


if __name__ == "__main__":
    main()
