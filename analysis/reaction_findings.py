"""What a reaction delay θ_r costs (issue 25, item 8): the minimum certified time gap, and the region lost.

1. **Minimum certified T* vs θ_r.**  For each θ_r, the smallest T* for which *some* gain triple
   of a wide grid is certified (the certificate is the judge, :func:`stringstab.check` with
   ``reaction_delay``): a scan of T* in steps of ``--step`` s, then a bisection to 10⁻³ s
   between the last T* with none certified and the first with one.  Two controllers:

   * PD ACC (k_a = 0): k_x ∈ 10^[−4, 0.7] (48 log-spaced), k_v ∈ 10^[−2, 1] (64) — δ plays no
     part;
   * CACC (k_a free): k_x ∈ 10^[−3, 0.5] (16), k_v ∈ 10^[−2, 1] (28), k_a ∈ [−0.5, 1.5] (21),
     with the communication delay δ = 0.2 s (the IDL paper's) and with δ = θ_r.

   τ = 0.1 s (the IDL paper's) and τ = 0.5 s.  Beside it, the classic bound with lag and
   delay, T* > 2(τ + θ_r) (Xiao, Darbha, Gao 2008, ACC with parasitic lag τ and delay θ_r),
   and Ma, Pagilla and Darbha's (2025) T* > 2θ_r for ACC and T* > 2θ_r/(1 + k_a) for CACC
   (k_a < 1; their model has no lag, docs/theory.md §6).  A grid search gives an *upper
   bound* on the true minimum (a finer or wider grid can only lower it).

2. **The IDL paper's certified region lost** at θ_r = 0.1, 0.2, 0.3 s: the 81³ grid of
   ``stringstab region --3d --n 81`` over [−2, 2]³ at τ = 0.1 s, δ = 0.2 s, T* = 1.1 s, certified
   at θ_r = 0 and at each θ_r: the share of the θ_r = 0 certified set no longer certified, and
   what is certified that was not.

3. **What the Taylor route gets wrong** (internal stability only): e^{−θ_r s} ≈ 1 − θ_r s or
   Padé(1,1) in the denominator turns it into a cubic or quartic Hurwitz test
   (:func:`stringstab.certify.reaction.approximation_verdicts`); on a 0.01 grid of
   (k_x, k_v) ∈ [−2, 2]² at τ = 0.1 s, T* = 1.1 s, the share where it says stable and the exact
   root count finds roots in Re s > 0, and the reverse.

    python analysis/reaction_findings.py                       # all three, ~15 min on 2 busy cores
    python analysis/reaction_findings.py --only region --n 41  # the region part on 41³
    python analysis/reaction_findings.py --only taylor

Prints markdown tables and the machine load; ``--out`` writes the figures as JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

import stringstab as ss

THETAS = (0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0)


def acc_grid() -> np.ndarray:
    """PD ACC gains (k_x, k_v, 0)."""
    kx, kv = np.meshgrid(np.logspace(-4, 0.7, 48), np.logspace(-2, 1, 64), indexing="ij")
    return np.stack([kx.ravel(), kv.ravel(), np.zeros(kx.size)], axis=1)


def cacc_grid() -> np.ndarray:
    """CACC gains (k_x, k_v, k_a)."""
    kx, kv, ka = np.meshgrid(np.logspace(-3, 0.5, 16), np.logspace(-2, 1, 28),
                             np.linspace(-0.5, 1.5, 21), indexing="ij")
    return np.stack([kx.ravel(), kv.ravel(), ka.ravel()], axis=1)


def _any_certified(K: np.ndarray, tau: float, delta: float, headway: float,
                   theta: float) -> np.ndarray | None:
    v = ss.check(*K.T, tau=tau, delta=delta, headway=headway, reaction_delay=theta).verdict
    ok = np.flatnonzero(v == "certified")
    return K[ok[0]] if ok.size else None


def min_headway(K: np.ndarray, tau: float, delta: float, theta: float, step: float = 0.1,
                top: float = 8.0) -> tuple[float, list[float] | None]:
    """The smallest T* (to 1e-3 s) at which some triple of K is certified, and that triple."""
    lo = 0.0
    h = 0.0
    found = None
    while h <= top:
        found = _any_certified(K, tau, delta, h, theta)
        if found is not None:
            break
        lo = h
        h = round(h + step, 10)
    if found is None:
        return float("nan"), None
    hi = h
    while hi - lo > 1e-3:
        mid = 0.5 * (lo + hi)
        f = _any_certified(K, tau, delta, mid, theta)
        if f is None:
            lo = mid
        else:
            hi, found = mid, f
    return hi, [float(x) for x in found]


def headway_part(taus, thetas, step) -> list[dict]:
    acc, cacc = acc_grid(), cacc_grid()
    rows = []
    print(f"\n## Minimum certified T* vs θ_r (load {os.getloadavg()[0]:.2f}); grids: ACC "
          f"{len(acc)} (k_x, k_v), CACC {len(cacc)} (k_x, k_v, k_a)")
    print("| τ (s) | θ_r (s) | ACC min T* (s) [K] | 2(τ+θ_r) | 2θ_r (Ma) | CACC δ=0.2 min T* [K] "
          "| CACC δ=θ_r min T* [K] | 2θ_r/(1+k_a) at that k_a (Ma) |")
    print("|---|---|---|---|---|---|---|---|")
    for tau in taus:
        for th in thetas:
            t0 = time.perf_counter()
            a, ka_ = min_headway(acc, tau, 0.2, th, step)
            c1, kc1 = min_headway(cacc, tau, 0.2, th, step)
            c2, kc2 = min_headway(cacc, tau, th, th, step)
            ma_c = (2 * th / (1 + kc1[2]) if kc1 and kc1[2] > -1 else float("nan"))
            row = {"tau": tau, "theta": th, "acc": a, "acc_gains": ka_, "cacc_delta_0.2": c1,
                   "cacc_delta_0.2_gains": kc1, "cacc_delta_theta": c2, "cacc_delta_theta_gains": kc2,
                   "classic_2(tau+theta)": 2 * (tau + th), "ma_acc_2theta": 2 * th,
                   "ma_cacc_at_found_ka": ma_c, "seconds": round(time.perf_counter() - t0, 1)}
            rows.append(row)

            def k(v):
                return "—" if v is None else f"({v[0]:.3g}, {v[1]:.3g}, {v[2]:.3g})"

            print(f"| {tau:g} | {th:g} | {a:.3f} {k(ka_)} | {2 * (tau + th):.2f} | {2 * th:.2f} | "
                  f"{c1:.3f} {k(kc1)} | {c2:.3f} {k(kc2)} | {ma_c:.3f} |", flush=True)
    return rows


def region_part(n: int, thetas) -> dict:
    g = np.linspace(-2.0, 2.0, n)
    kx, kv, ka = (a.ravel() for a in np.meshgrid(g, g, g, indexing="ij"))
    prm = dict(tau=0.1, delta=0.2, headway=1.1)
    t0 = time.perf_counter()
    base = ss.check(kx, kv, ka, **prm).verdict == "certified"
    out = {"grid": f"{n}^3 over [-2, 2]^3", "points": int(kx.size), "params": prm,
           "certified_theta_0": int(base.sum()), "rows": []}
    print(f"\n## The IDL certified region at θ_r > 0 ({n}³ = {kx.size} points over [−2, 2]³, "
          f"τ = 0.1, δ = 0.2, T* = 1.1 s; load {os.getloadavg()[0]:.2f})")
    print(f"θ_r = 0: {base.sum()} certified ({100 * base.mean():.2f} % of the grid), "
          f"{time.perf_counter() - t0:.1f} s")
    print("| θ_r (s) | certified | share of the grid | of the θ_r = 0 set: lost | newly certified "
          "| inconclusive | seconds |")
    print("|---|---|---|---|---|---|---|")
    for th in thetas:
        t0 = time.perf_counter()
        v = ss.check(kx, kv, ka, **prm, reaction_delay=th).verdict
        c = v == "certified"
        row = {"theta": th, "certified": int(c.sum()), "share": float(c.mean()),
               "lost_share_of_theta0": float((base & ~c).sum() / max(base.sum(), 1)),
               "newly_certified": int((c & ~base).sum()),
               "inconclusive": int((v == "inconclusive").sum()),
               "seconds": round(time.perf_counter() - t0, 1)}
        out["rows"].append(row)
        print(f"| {th:g} | {row['certified']} | {100 * row['share']:.2f} % | "
              f"{100 * row['lost_share_of_theta0']:.1f} % | {row['newly_certified']} | "
              f"{row['inconclusive']} | {row['seconds']} |", flush=True)
    return out


def taylor_part(thetas) -> list[dict]:
    from stringstab.certify.quasipolynomial import count_unstable_roots
    from stringstab.certify.reaction import approximation_verdicts

    g = np.round(np.arange(-2.0, 2.0 + 1e-9, 0.01), 2)
    kx, kv = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    rows = []
    print(f"\n## The Taylor route against the exact root count ({kx.size} (k_x, k_v) on a 0.01 "
          "grid of [−2, 2]², τ = 0.1 s, T* = 1.1 s)")
    print("| θ_r (s) | exact: stable | taylor1 says stable, exact unstable | taylor1 says unstable, "
          "exact stable | pade11 says stable, exact unstable | pade11 says unstable, exact stable |")
    print("|---|---|---|---|---|---|")
    for th in thetas:
        p = ss.Params(0.1, 0.2, 1.1, reaction_delay=th)
        rc = count_unstable_roots(kx, kv, 0.1, 1.1, th)
        av = approximation_verdicts(kx, kv, p)
        row = {"theta": th, "stable": float(rc.stable.mean()),
               "undecided": int((~rc.stable & ~rc.unstable).sum())}
        cells = []
        for k in ("taylor1", "pade11"):
            for name, m in (("false_stable", av[k] & rc.unstable), ("false_unstable", ~av[k] & rc.stable)):
                row[f"{k}_{name}"] = float(m.mean())
                i = np.flatnonzero(m)
                ex = f" e.g. ({kx[i[len(i) // 2]]:g}, {kv[i[len(i) // 2]]:g})" if i.size else ""
                cells.append(f"{100 * m.mean():.2f} %{ex}")
        rows.append(row)
        print(f"| {th:g} | {100 * row['stable']:.2f} % | " + " | ".join(cells) + " |", flush=True)
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", choices=("headway", "region", "taylor"), help="one part only")
    ap.add_argument("--n", type=int, default=81, help="region grid per axis (default 81)")
    ap.add_argument("--step", type=float, default=0.1, help="T* scan step, s (default 0.1)")
    ap.add_argument("--out", help="write the figures as JSON here")
    args = ap.parse_args(argv)
    print(f"# load before {os.getloadavg()}")
    res: dict = {}
    if args.only in (None, "headway"):
        res["headway"] = headway_part((0.1, 0.5), THETAS, args.step)
    if args.only in (None, "region"):
        res["region"] = region_part(args.n, (0.1, 0.2, 0.3))
    if args.only in (None, "taylor"):
        res["taylor"] = taylor_part((0.1, 0.2, 0.3, 0.5))
    print(f"\n# load after {os.getloadavg()}")
    if args.out:
        with open(args.out, "w", encoding="utf-8") as f:
            json.dump(res, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
