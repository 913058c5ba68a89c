"""Why a learned IDL policy's 100-vehicle platoon can show m_p slightly above 1.

For each run folder given, the §5.1 platoon test (100 followers behind ``paper_mix`` held 100 s)
is simulated four ways, and the largest m_p (eq 29) is printed with how many vehicles exceed 1:

1. the policy as trained (gains switching every step, each executed gain certified);
2. every vehicle frozen at the policy's median executed gain (certified too);
3. and 4. the same two in the *linear* regime: the leader's speed raised by 20 m/s (it never
   stops) and the acceleration limits widened to ±1000 m/s², so that neither the speed floor
   v ≥ 0 nor the acceleration saturation acts.

The certificate is a statement about the linear loop with frozen gains; (4) vs (3) isolates the
gain switching, (2) vs (4) the nonlinear limits.  Two frozen reference gains are run as well.

    python analysis/platoon100_explain.py analysis-out/train_compare/runs/idl-s0 [...]

Minutes per run (100 vehicles, the repair at every step); never part of the tests.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import time

import numpy as np

from stringstab.certify.api import check
from stringstab.constants import DELTA, HEADWAY, STANDSTILL, TAU
from stringstab.rl import load_policy
from stringstab.rl.evaluate import controller_for
from stringstab.traffic.controllers import LinearController
from stringstab.traffic.limits import Limits
from stringstab.traffic.metrics import platoon_metrics
from stringstab.traffic.platoon import simulate
from stringstab.traffic.synthetic import paper_mix

N = 100
WIDE = Limits(accel_min=-1e3, accel_max=1e3, speed_min=0.0, speed_max=1e3)


def leaders() -> dict[str, tuple[object, Limits | None]]:
    base = paper_mix(dt=0.1).hold(100.0)
    t = np.arange(base.speed.size) * base.dt
    shifted = dataclasses.replace(base, speed=base.speed + 20.0, position=base.position + 20.0 * t,
                                  name="paper-mix+20")
    return {"as tested": (base, None), "linear regime": (shifted, WIDE)}


def run(ctrl: object, leader: object, limits: Limits | None) -> tuple[np.ndarray, object]:
    res = simulate(leader, ctrl, N, tau=TAU, delta=DELTA, limits=limits,  # type: ignore[arg-type]
                   initial_gap=STANDSTILL + HEADWAY * float(leader.speed[0]))  # type: ignore[attr-defined]
    return np.asarray(platoon_metrics(res, certificate=False)["m_p"]), res


def line(name: str, mp: np.ndarray, t0: float) -> str:
    return (f"  {name:<44} max m_p {mp.max():.4f} (vehicle {int(mp.argmax()) + 1}), "
            f"{int((mp > 1).sum())} vehicles > 1   [{time.perf_counter() - t0:.0f} s, load "
            f"{os.getloadavg()[0]:.2f}]")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+")
    args = ap.parse_args()
    ls = leaders()
    for K in ((1.2, 0.5, 0.6), (0.5, 1.0, 0.5)):
        print(f"frozen reference K = {K}")
        for lname, (leader, lim) in ls.items():
            t0 = time.perf_counter()
            print(line(lname, run(LinearController(*K, headway=HEADWAY), leader, lim)[0], t0))
    for folder in args.runs:
        pol = load_policy(folder)
        print(f"{folder} (gain_rate {pol.gain_rate}, observe {list(pol.observe)})")
        Km = None
        for lname, (leader, lim) in ls.items():
            t0 = time.perf_counter()
            mp, res = run(controller_for(pol, headway=HEADWAY), leader, lim)
            print(line(f"policy, {lname}", mp, t0))
            if Km is None:
                G = np.asarray(res.gains).reshape(-1, 3)  # type: ignore[attr-defined]
                Km = np.median(G, axis=0)
                dK = np.abs(np.diff(np.asarray(res.gains), axis=-2)).sum(-1)  # type: ignore[attr-defined]
                v = [np.ravel(check(*Km, tau=TAU, delta=DELTA, headway=HEADWAY).verdict)[0],
                     np.ravel(check(*Km, tau=TAU, delta=DELTA, headway=HEADWAY,
                                    sample_time=0.1).verdict)[0]]
                print(f"  median executed K = {np.round(Km, 3).tolist()} ({v[0]}, sampled {v[1]}); "
                      f"mean Σ|ΔK| per step {dK.mean():.4f}")
            t0 = time.perf_counter()
            print(line(f"frozen median K, {lname}", run(LinearController(*Km, headway=HEADWAY),
                                                        leader, lim)[0], t0))


if __name__ == "__main__":
    main()
