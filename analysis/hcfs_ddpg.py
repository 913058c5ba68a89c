"""Train the HCFS DDPG for several seeds and check that it learned (docs/hcfs.md, "The DDPG").

    .venv/bin/python analysis/hcfs_ddpg.py --steps 200000 --seeds 0,1,2 --out analysis-out/hcfs_ddpg

Each seed is trained exactly as ``stringstab hcfs train --steps N --seed S --out OUT/s<S>``
(:func:`stringstab.hcfs.train_hcfs_ddpg`: UDDS at half speed from 600 s, 4 platoons of 6
followers, IDL Table 1 DDPG settings, no early stop).  At every checkpoint the deterministic
policy (no exploration noise) is evaluated on the three held-out cases ``hcfs-case1..3``: Σr
of the DDPG alone and of HCFS, against CACC alone and the stand-in alone — the training reward
itself carries the exploration noise and flattens out early.  Then the final policies are
compared as in the paper's Tables IV-VI.  Writes ``--figure`` (the learning curves).

Minutes per seed; run it in the background, never in the tests.
"""

from __future__ import annotations

import argparse
import os
import shutil
import time
from pathlib import Path

import numpy as np

from stringstab.hcfs import LeaderSpeedMatcher
from stringstab.hcfs.compare import compare_controllers, comparison_markdown
from stringstab.hcfs.ddpg import train_hcfs_ddpg
from stringstab.hcfs.env import HCFSVectorEnv
from stringstab.hcfs.leaders import paper_cases
from stringstab.hcfs.plots import plot_learning


def held_out(policy, cases):
    """Σr over the held-out cases of the policy alone and of HCFS with it."""
    rows = compare_controllers(cases, policy)
    return (sum(r["sum_reward"] for r in rows if r["controller"] == "DDPG"),
            sum(r["sum_reward"] for r in rows if r["controller"] == "HCFS"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200_000)
    ap.add_argument("--seeds", default="0,1,2")
    ap.add_argument("--checkpoint-every", type=int, default=20_000)
    ap.add_argument("--out", default="analysis-out/hcfs_ddpg")
    ap.add_argument("--figure", default="docs/figures/hcfs_ddpg_learning.png")
    args = ap.parse_args()
    cases = paper_cases()
    refs = compare_controllers(cases, LeaderSpeedMatcher(), name="stand-in")
    cacc = sum(r["sum_reward"] for r in refs if r["controller"] == "CACC")
    stand_in = sum(r["sum_reward"] for r in refs if r["controller"] == "stand-in")
    hcfs_si = sum(r["sum_reward"] for r in refs if r["controller"] == "HCFS")
    print(f"load average {os.getloadavg()}; held-out cases: "
          f"{', '.join(f'{tr.name} ({n} followers)' for tr, n in cases)}")
    print(f"references, sum of Σr over the cases: CACC alone {cacc:.3f}, stand-in alone "
          f"{stand_in:.3f}, HCFS with the stand-in {hcfs_si:.3f}")
    curves_ddpg, curves_hcfs, noisy, finals = {}, {}, {}, {}
    for seed in (int(s) for s in args.seeds.split(",")):
        out = Path(args.out) / f"s{seed}"
        if out.exists():
            shutil.rmtree(out)
        load0 = os.getloadavg()[0]
        t0 = time.perf_counter()
        run = train_hcfs_ddpg(total_steps=args.steps, seed=seed, env=HCFSVectorEnv(), out=out,
                              progress=False, stop_episodes=0,
                              checkpoint_every=args.checkpoint_every,
                              on_checkpoint=lambda step, pol: held_out(pol, cases))
        sec = time.perf_counter() - t0
        t = run.result.timing
        print(f"\nseed {seed}: {run.result.steps} steps in {sec:.0f} s with the checkpoint "
              f"evaluations ({t['steps_per_second']:.0f} steps/s in training; load before/after "
              f"{load0:.2f}/{os.getloadavg()[0]:.2f})")
        print("  step | Σr DDPG alone | Σr HCFS")
        for step, (r_d, r_h) in run.checkpoints:
            print(f"  {step:>7d} | {r_d:9.3f} | {r_h:9.3f}")
        curves_ddpg[f"DDPG alone, seed {seed}"] = [(s, v[0]) for s, v in run.checkpoints]
        curves_hcfs[f"HCFS, seed {seed}"] = [(s, v[1]) for s, v in run.checkpoints]
        ep = run.result.episodes
        steps = np.array([e["step"] for e in ep], dtype=float)
        r = np.array([e["mean_reward"] for e in ep])
        w = 2 * run.training["num_envs"]  # two episode windows of every follower
        c = np.cumsum(np.r_[0.0, r])
        idx = np.arange(w, r.size + 1, max(1, r.size // 60))
        noisy[f"seed {seed}"] = list(zip(steps[idx - 1], (c[idx] - c[idx - w]) / w))
        rows = compare_controllers(cases, run.policy, others={"stand-in": LeaderSpeedMatcher()})
        finals[seed] = rows
        print(comparison_markdown(rows), end="")
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 4.2), layout="constrained")
    a1, a2 = fig.subplots(1, 2)
    plot_learning(noisy, ax=a1, ylabel="mean reward per step (training, with noise)")
    a1.set_title("training reward: last two episodes of every follower", fontsize=9)
    vals = [v for c in (*curves_ddpg.values(), *curves_hcfs.values()) for _, v in c] + [stand_in]
    lo, hi = min(vals) - 3, max(vals) + 3
    refs = {"stand-in alone": stand_in, **({"CACC alone": cacc} if cacc >= lo else {})}
    plot_learning(curves_ddpg, ax=a2, ylabel="Σr over hcfs-case1..3", references=refs)
    if cacc < lo:
        a2.text(0.02, 0.03, f"CACC alone: Σr = {cacc:.1f} (below the axis)", transform=a2.transAxes,
                fontsize=8)
    plot_learning(curves_hcfs, ax=a2, ylabel="Σr over hcfs-case1..3", linestyle=":")
    a2.set_ylim(lo, hi)
    a2.set_title("deterministic policy, held-out cases: DDPG alone (solid), HCFS (dotted)",
                 fontsize=9)
    fig.savefig(args.figure, dpi=100)
    print(f"\nwrote {args.figure}")
    print("\nfinal policies, Σr summed over the cases (mean over seeds):")
    for ctrl in ("CACC", "DDPG", "HCFS", "stand-in", "HCFS (stand-in)"):
        vals = [sum(r["sum_reward"] for r in rows if r["controller"] == ctrl) for rows in finals.values()]
        coll = [sum(r["collisions"] for r in rows if r["controller"] == ctrl) for rows in finals.values()]
        print(f"  {ctrl:>16s}: {np.mean(vals):8.3f} (per seed {', '.join(f'{v:.3f}' for v in vals)}; "
              f"collisions {coll})")


if __name__ == "__main__":
    main()
