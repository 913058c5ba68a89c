"""IDL vs pure TD3 vs pure DDPG (and CACC, IDM) on the held-out episodes, several seeds each.

Trains every (agent, seed) into ``OUT/runs/<algo>-s<seed>`` (skipped when that run already
finished with the same budget), evaluates each on the bundled test episodes, runs the 10- and
100-vehicle platoon tests with the first seed of each agent, and writes the Table-4 comparison
(mean ± standard deviation over seeds) and figures into ``OUT/comparison``.  Prints the training
time of every run with the machine load beside it.

    python analysis/train_compare.py --steps 100000 --seeds 0,1,2 --out analysis-out/train_compare

Long: minutes per run.  Run it in the background (nohup ... &); never part of the tests.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

from stringstab.io import OutputDir
from stringstab.rl import config_for, load_policy, train
from stringstab.rl.episodes import default_leaders
from stringstab.rl.evaluate import evaluate, platoon_test
from stringstab.rl.report import write_comparison


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=100_000)
    ap.add_argument("--seeds", default="0,1,2")
    ap.add_argument("--algos", default="idl,td3,ddpg")
    ap.add_argument("--out", default="analysis-out/train_compare")
    args = ap.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    algos = args.algos.split(",")
    root = Path(args.out)
    (root / "runs").mkdir(parents=True, exist_ok=True)
    timings = {}
    for algo in algos:
        for seed in seeds:
            run = root / "runs" / f"{algo}-s{seed}"
            summ = run / "summary.json"
            if summ.is_file() and json.loads(summ.read_text()).get("steps", 0) >= min(
                    args.steps, 1):
                print(f"{run}: done before, skipped", flush=True)
                timings[run.name] = json.loads(summ.read_text())
                continue
            cfg = config_for(algo, total_steps=args.steps, seed=seed)
            load0 = os.getloadavg()
            t0 = time.perf_counter()
            res = train(cfg, out=run, progress=False)
            sec = time.perf_counter() - t0
            t = res.timing
            print(f"{run.name}: {res.steps} steps, {len(res.episodes)} episodes, stopped by "
                  f"{res.stopped_by}, {sec:.0f} s ({t['steps_per_second']:.0f} steps/s, repair "
                  f"{100 * t['repair_share']:.1f}% of the time); load before/after "
                  f"{load0[0]:.2f}/{os.getloadavg()[0]:.2f}", flush=True)
            timings[run.name] = {"seconds": sec, **t}
    leaders = default_leaders("test")
    groups: dict[str, list] = {}
    platoons: dict[str, dict] = {}
    p = config_for("idl")
    kw = {"tau": p.tau, "delta": p.delta, "headway": p.headway}
    for algo in algos:
        for seed in seeds:
            pol = load_policy(root / "runs" / f"{algo}-s{seed}")
            ev = evaluate(pol, leaders, name=algo, **kw)
            groups.setdefault(algo, []).append(ev)
            print(f"{algo}-s{seed}: {json.dumps({k: ev.summary.get(k) for k in ('TIT', 'M_CI', 'M_effi', 'M_lss', 'm_fss', 'collisions')})}", flush=True)
            if seed == seeds[0]:
                platoons[algo] = {"run": f"{algo}-s{seed}",
                                  "tests": [platoon_test(pol, n, dt=p.dt, **kw) for n in (10, 100)]}
    for b in ("cacc", "idm"):
        groups[b] = [evaluate(b, leaders, name=b, **kw)]
        platoons[b] = {"run": None, "tests": [platoon_test(b, n, dt=p.dt, **kw) for n in (10, 100)]}
        print(f"{b}: {json.dumps({k: groups[b][0].summary.get(k) for k in ('TIT', 'M_CI', 'M_effi', 'M_lss', 'collisions')})}", flush=True)
    with OutputDir(root / "comparison", command="compare") as out:
        write_comparison(out, groups, reference="idl" if "idl" in groups else None,
                         platoons=platoons, **kw)
        out.write_json("timings.json", {"runs": timings, "load_average": list(os.getloadavg())})
    print((root / "comparison" / "table.md").read_text())


if __name__ == "__main__":
    main()
