"""Training throughput (environment steps per second) and the repair's share of training time.

Same run, same machine load, arms of the IDL trainer for ``--steps`` environment steps: no
repair (the ablation, the baseline of the ratio); the default repair (certified lookup
projection, continuous and sampled-data certificates); the same with the sampled-data check as
it was before the point-path fix of issue 11 phase 2 ("before": the lag primitives of the sampled ``check`` built as
zero-width intervals, reproduced here by forcing the interval path of the first two
``phi_interval`` calls of each build, :mod:`stringstab.certify.zoh`); the continuous certificate alone (``repair_sampled=False``);
and the exact projection (:class:`stringstab.tuning.Projector`) for a shorter stretch.  Also
the sampled ``check`` per call on 8 triples (one control step of 8 environments), before and after.
Also the repair's per-triple latency against :func:`stringstab.tuning.project` on the same
uncertified proposals, and how much farther from the proposal the lookup lands than the exact
projection.  Ratios are what count: the 2 cores are shared.

Since issue 31 the point coefficients compute the parameters' quantities once per parameter set
(``zoh.point_coefficients``), so the "before" arms above (which re-route ``zoh.primitives``)
no longer reproduce the state before the point-path fix; ``analysis/bench_speed.py`` measures
the repair against the base commit itself.

    python analysis/bench_train.py --steps 20000
"""

from __future__ import annotations

import argparse
import contextlib
import os
import time
from collections.abc import Iterator
from typing import Any

import numpy as np

from stringstab.certify import zoh
from stringstab.certify.api import check
from stringstab.rl import config_for, train
from stringstab.tuning import project
from stringstab.tuning.repair import GainRepair


def arm(name: str, steps: int, **kw: object) -> dict[str, float]:
    cfg = config_for("idl", total_steps=steps, seed=0, stop_episodes=0, **kw)
    load = os.getloadavg()[0]
    res = train(cfg, progress=False)
    t = res.timing
    print(f"{name:>18}: {t['steps_per_second']:7.0f} env steps/s, repair {t['repair_seconds']:6.1f} s "
          f"= {100 * t['repair_share']:5.1f}% of {t['total_seconds']:.1f} s, updates "
          f"{100 * t['update_seconds'] / t['total_seconds']:4.1f}%   (load {load:.2f})", flush=True)
    return t


@contextlib.contextmanager
def sampled_before() -> Iterator[None]:
    """The sampled ``check`` as before the point-path fix: φ1, ψ2, ψ3 of τ and τ_p as zero-width intervals."""
    prim, phi = zoh.primitives, zoh.phi_interval
    left = [0]

    def phi_before(lo: Any, hi: Any) -> Any:
        if left[0] > 0 and hi is lo:
            left[0] -= 1
            hi = np.array(hi, copy=True)  # equal values, another array: the interval path
        return phi(lo, hi)

    def prim_before(*a: Any, **k: Any) -> Any:
        left[0] = 2
        return prim(*a, **k)

    zoh.primitives, zoh.phi_interval = prim_before, phi_before  # type: ignore[assignment]
    try:
        yield
    finally:
        zoh.primitives, zoh.phi_interval = prim, phi  # type: ignore[assignment]


def per_call(n_calls: int = 200) -> float:
    """Seconds per sampled ``check`` call on 8 triples near the certified set."""
    rng = np.random.default_rng(0)
    K = np.array([1.14, 1.03, 0.02]) + rng.normal(0.0, 0.05, (8, 3))
    check(*K.T, tau=0.1, delta=0.2, headway=1.1, sample_time=0.1)
    t0 = time.perf_counter()
    for _ in range(n_calls):
        check(*K.T, tau=0.1, delta=0.2, headway=1.1, sample_time=0.1)
    return (time.perf_counter() - t0) / n_calls


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20_000)
    ap.add_argument("--triples", type=int, default=200)
    args = ap.parse_args()
    with sampled_before():
        before_call = per_call()
    after_call = per_call()
    print(f"check (sampled), 8 triples: before {1e3 * before_call:.2f} ms, after "
          f"{1e3 * after_call:.2f} ms per call, ratio {before_call / after_call:.1f}x "
          f"(load {os.getloadavg()[0]:.2f})")
    # the certified lattice is built once per process (lru_cache) by the first arm that repairs;
    # build it here, timed before and after, so that no arm pays for it
    from stringstab.tuning.lattice import clear_caches

    for label, ctx in (("before", sampled_before), ("after", contextlib.nullcontext)):
        clear_caches()
        with ctx():
            t0 = time.perf_counter()
            n = GainRepair(tau=0.1, delta=0.2, headway=1.1, sample_time=0.1).lattice().shape[0]
        print(f"certified lattice (continuous and sampled, {n} points), {label}: "
              f"{time.perf_counter() - t0:.1f} s (load {os.getloadavg()[0]:.2f})", flush=True)
    GainRepair(tau=0.1, delta=0.2, headway=1.1).lattice()
    base = arm("repair off", args.steps, repair="off")
    look = arm("projection (lookup)", args.steps)
    with sampled_before():
        old = arm("lookup, before", args.steps)
    cont = arm("lookup, continuous", args.steps, repair_sampled=False)
    print(f"repair share: default {100 * look['repair_share']:.1f}% (before the point-path fix "
          f"{100 * old['repair_share']:.1f}%, continuous only {100 * cont['repair_share']:.1f}%); "
          f"steps/s ratio default/before = {look['steps_per_second'] / old['steps_per_second']:.2f}")
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
