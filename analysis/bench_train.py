"""Training throughput (environment steps per second) and the repair's share of training time.

Same run, same machine load, three arms of the IDL trainer for ``--steps`` environment steps:
the default repair (certified lookup projection), no repair (the ablation, the baseline of the
ratio), and the exact projection (:class:`stringstab.tuning.Projector`) for a shorter stretch.
Also the repair's per-triple latency against :func:`stringstab.tuning.project` on the same
uncertified proposals, and how much farther from the proposal the lookup lands than the exact
projection.  Ratios are what count: the 2 cores are shared.

    python analysis/bench_train.py --steps 20000
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from stringstab.rl import config_for, train
from stringstab.rl.repair import GainRepair
from stringstab.tuning import project


def arm(name: str, steps: int, **kw: object) -> dict[str, float]:
    cfg = config_for("idl", total_steps=steps, seed=0, stop_episodes=0, **kw)
    load = os.getloadavg()[0]
    res = train(cfg, progress=False)
    t = res.timing
    print(f"{name:>18}: {t['steps_per_second']:7.0f} env steps/s, repair {t['repair_seconds']:6.1f} s "
          f"= {100 * t['repair_share']:5.1f}% of {t['total_seconds']:.1f} s, updates "
          f"{100 * t['update_seconds'] / t['total_seconds']:4.1f}%   (load {load:.2f})", flush=True)
    return t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20_000)
    ap.add_argument("--triples", type=int, default=200)
    args = ap.parse_args()
    base = arm("repair off", args.steps, repair="off")
    look = arm("projection (lookup)", args.steps)
    # shorter (it is slow), but past learning_starts so that its updates are counted too
    exact = arm("projection-exact", max(args.steps // 4, 4000), repair="projection-exact")
    print(f"steps/s ratio lookup/off = {look['steps_per_second'] / base['steps_per_second']:.2f}, "
          f"exact/off = {exact['steps_per_second'] / base['steps_per_second']:.3f}")
    rng = np.random.default_rng(0)
    K = rng.uniform(-2, 2, (args.triples, 3))
    rep = GainRepair(tau=0.1, delta=0.2, headway=1.1)
    rep.lattice()
    t0 = time.perf_counter()
    out = np.array([rep(k[None])[0] for k in K])
    t_look = (time.perf_counter() - t0) / len(K)
    t0 = time.perf_counter()
    res = [project(k, tau=0.1, delta=0.2, headway=1.1) for k in K]
    t_proj = (time.perf_counter() - t0) / len(K)
    d_look = np.linalg.norm(out - K, axis=1)
    d_proj = np.array([r.distance for r in res])
    extra = d_look - d_proj
    print(f"per triple (uniform proposals): lookup {1e3 * t_look:.3f} ms, tuning.project "
          f"{1e3 * t_proj:.3f} ms, ratio {t_proj / t_look:.1f}x (load {os.getloadavg()[0]:.2f})")
    print(f"lookup distance minus exact projection distance: median {np.median(extra):.4f}, "
          f"p95 {np.percentile(extra, 95):.4f}, max {extra.max():.4f} (gain units)")


if __name__ == "__main__":
    main()
