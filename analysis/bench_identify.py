"""Benchmark of ``stringstab identify``: identification time per vehicle-hour of data.

For each follower of a log (the OpenACC ACC log shipped in stringstab/data/openacc, else a simulated 10-min
platoon of 5 followers), measured in the same run:

* **baseline** — one closed-loop simulation of the same data by the toolkit's simulator:
  :func:`stringstab.traffic.simulate` with the measured predecessor as leader (a
  :class:`~stringstab.traffic.Trajectory` built from its speed), the follower at its fitted law;
* **one simulation** by the identifier's linear-filter recursion
  (:func:`stringstab.identify.simulate_follower`) on the same data, and the same with a reaction
  delay θ_r = 0.55 s on the whole law (a filter of order q + 4 = 9);
* **point fit** — :func:`stringstab.identify.fit_follower` with ``--starts`` starting points;
* **bootstrap refit** — one moving-block bootstrap refit (from the point estimate and from a
  random start, the lower optimum kept, as :func:`stringstab.identify.identify` does);
* **point fit with θ_r** — the same with the reaction delay fitted (``--fit-delay``);
* **identify** — the whole :func:`stringstab.identify.identify` with ``--bootstrap`` refits
  (fits, certificates, T* profile, empirical transfer; no figures).

Prints seconds per vehicle-hour and each as a ratio to the baseline, with the machine load
(``os.getloadavg()``) before and after; asserts nothing about time.  Example::

    python analysis/bench_identify.py --bootstrap 10
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from stringstab.identify import (
    FollowerData,
    clean_segments,
    fit_follower,
    identify,
    read_platoon_logs,
    simulate_follower,
)
from stringstab.identify.closed_loop import FollowerModel
from stringstab.identify.estimate import block_counts
from stringstab.identify.fit import start_points
from stringstab.identify.logs import example_log
from stringstab.traffic import LinearController, from_speed, simulate

#: The OpenACC ACC log shipped with the package (stringstab/data/openacc/README.md)
SHARED = example_log("acc")


def _log(path: Path | None):
    if path is not None and path.is_file():
        return read_platoon_logs(path)[0], str(path)
    from stringstab.io.platoon_logs import PlatoonLog

    t = np.arange(0.0, 600.05, 0.1)
    lead = from_speed(t, 12 + 3 * np.sin(2 * np.pi * t / 90) + np.sin(0.4 * t), dt=0.1)
    c = LinearController(0.15, 0.5, 0.0, headway=1.3, standstill=4.0)
    r = simulate(lead, c, 5, tau=0.4, delta=0.0)
    gaps = {k: r.gap[k - 1] + np.random.default_rng(k).normal(0, 0.2, t.size) for k in range(1, 6)}
    return (PlatoonLog(r.t, tuple(range(6)), tuple(f"car{k}" for k in range(6)), r.speed, gaps, None,
                       "<simulated>", "csv", {}), "a simulated 10-min platoon of 5 followers")


def _best(repeat: int, fn, *args, **kwargs) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn(*args, **kwargs)
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--log", type=Path, default=SHARED, help="the log (default: the shipped OpenACC ACC log)")
    ap.add_argument("--starts", type=int, default=4)
    ap.add_argument("--bootstrap", type=int, default=10)
    ap.add_argument("--repeat", type=int, default=3, help="best of N for the single simulations")
    args = ap.parse_args()
    load0 = os.getloadavg()
    log, what = _log(args.log)
    print(f"log: {what}; followers {log.followers()}; load before {load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}")
    tot = {"baseline": 0.0, "filter": 0.0, "filter_delay": 0.0, "fit": 0.0, "fit_delay": 0.0, "boot": 0.0}
    hours = 0.0
    for p in log.followers():
        segs = tuple(clean_segments(log, p))
        if not segs:
            continue
        vp, v, g, _ = log.pair(p)
        data = FollowerData(vp, v, g, None, segs, log.dt)
        h = data.n_samples * log.dt / 3600.0
        hours += h
        fit = fit_follower(data, "acc", n_starts=args.starts)
        tot["fit"] += _best(1, fit_follower, data, "acc", n_starts=args.starts)
        tot["fit_delay"] += _best(1, fit_follower, data, "acc", n_starts=args.starts, fit_delay=True)
        q = fit.params
        m = FollowerModel(q["k_x"], q["k_v"], 0.0, q["tau"], 0.0, q["headway"], q["standstill"])
        md = FollowerModel(q["k_x"], q["k_v"], 0.0, q["tau"], 0.0, q["headway"], q["standstill"], 0.55)
        ctrl = LinearController(q["k_x"], q["k_v"], 0.0, headway=q["headway"], standstill=q["standstill"])
        base = filt = filt_d = 0.0
        for s in segs:
            n = len(s)
            tr = from_speed(np.arange(n) * log.dt, np.maximum(vp[s.start:s.stop], 0.0), dt=log.dt)
            base += _best(args.repeat, simulate, tr, ctrl, 1, tau=q["tau"], delta=0.0,
                          initial_gap=float(g[s.start]), initial_speed=float(v[s.start]), progress=False)
            filt += _best(args.repeat, simulate_follower, m, vp[s.start:s.stop], log.dt,
                          s0=float(g[s.start]), v0=float(v[s.start]))
            filt_d += _best(args.repeat, simulate_follower, md, vp[s.start:s.stop], log.dt,
                            s0=float(g[s.start]), v0=float(v[s.start]))
        tot["baseline"] += base
        tot["filter"] += filt
        tot["filter_delay"] += filt_d
        rng = np.random.default_rng(0)
        counts = block_counts(list(segs), v.size, 200, rng)
        x_rand = start_points(data, "acc", 2, seed=1)[1]
        tot["boot"] += _best(1, fit_follower, data, "acc", x0=[fit.theta, x_rand], counts=counts,
                             identifiability=False)
    t0 = time.perf_counter()
    identify(log, bootstrap=args.bootstrap, n_starts=args.starts, progress=False)
    t_all = time.perf_counter() - t0
    load1 = os.getloadavg()
    b = tot["baseline"]
    print(f"data: {hours:.3f} vehicle-hours at {1 / log.dt:g} Hz")
    rows = [
        ("baseline: one closed-loop simulation (traffic.simulate)", b),
        ("one simulation (identify's linear-filter recursion)", tot["filter"]),
        ("one simulation with θ_r = 0.55 s (order-9 filter)", tot["filter_delay"]),
        (f"point fit ({args.starts} starts)", tot["fit"]),
        (f"point fit with θ_r ({args.starts} starts)", tot["fit_delay"]),
        ("one bootstrap refit (two starts)", tot["boot"]),
        (f"identify, {args.bootstrap} bootstrap refits, certificates, profile", t_all),
    ]
    print(f"{'what':<66} {'s per vehicle-hour':>19} {'x baseline':>11}")
    for name, sec in rows:
        print(f"{name:<66} {sec / hours:>19.4g} {sec / b:>11.3g}")
    print(f"load after {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f} (2 cores shared)")


if __name__ == "__main__":
    main()
