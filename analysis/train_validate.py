"""Choose the IDL training options on a validation split of the *training* episodes.

The held-out test episodes are never used here: the bundled training episodes are split again,
80/20 with seed 1 (:func:`stringstab.traffic.train_test_split`), each variant below is trained
on the 80 % with the same seed and budget, and evaluated on the 20 %.  The variant chosen here
becomes the default that ``analysis/train_compare.py`` then runs on the test episodes.

    python analysis/train_validate.py --steps 250000 --out analysis-out/train_validate

Long (minutes per variant); run it in the background, never in the tests.  Prints one line per
variant with the machine load beside its training time.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path
from typing import Any

from stringstab.rl import config_for, train
from stringstab.rl.episodes import default_leaders
from stringstab.rl.evaluate import evaluate, platoon_test
from stringstab.traffic import train_test_split

#: The variants compared (TD3Config overrides of the paper's configuration, config_for("idl", paper=True)).
VARIANTS: dict[str, dict[str, Any]] = {
    "paper": {},
    "rate0.05": {"gain_rate": 0.05, "observe": ("accel", "gains")},
    "rate0.05+spread": {"gain_rate": 0.05, "observe": ("accel", "gains"),
                        "start_spread": (0.3, 3.0)},
    "rate0.02+spread": {"gain_rate": 0.02, "observe": ("accel", "gains"),
                        "start_spread": (0.3, 3.0)},
    "rate0.05+spread+ttc4": {"gain_rate": 0.05, "observe": ("accel", "gains"),
                             "start_spread": (0.3, 3.0), "reward_ttc_star": 4.0},
}
KEYS = ("TIT", "M_CI", "M_lss", "m_fss", "m_fss_sampled", "collisions", "min_gap",
        "median_headway")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=250_000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--variants", default=",".join(VARIANTS))
    ap.add_argument("--platoon", action="store_true", help="also the 100-vehicle platoon")
    ap.add_argument("--out", default="analysis-out/train_validate")
    args = ap.parse_args()
    fit, val = train_test_split(default_leaders("train"), test_fraction=0.2, seed=1)
    print(f"{len(fit)} fitting and {len(val)} validation episodes (of the training split)")
    root = Path(args.out)
    root.mkdir(parents=True, exist_ok=True)
    store = root / "validation.json"
    rows = json.loads(store.read_text()) if store.is_file() else {}  # earlier variants kept
    for name in args.variants.split(","):
        cfg = config_for("idl", paper=True, total_steps=args.steps, seed=args.seed,
                         **VARIANTS[name])
        load0 = os.getloadavg()[0]
        t0 = time.perf_counter()
        res = train(cfg, leaders=fit, progress=False)
        sec = time.perf_counter() - t0
        ev = evaluate(res.policy, val, tau=cfg.tau, delta=cfg.delta, headway=cfg.headway)
        row = {k: ev.summary.get(k) for k in KEYS}
        row.update(seconds=round(sec, 1), steps=res.steps, load=[round(load0, 2),
                   round(os.getloadavg()[0], 2)], repair_share=round(res.timing["repair_share"], 3))
        if args.platoon:
            pt = platoon_test(res.policy, 100, tau=cfg.tau, delta=cfg.delta, headway=cfg.headway,
                              dt=cfg.dt)
            row["platoon100_max_m_p"] = pt["max_m_p"]
        rows[name] = row
        print(f"{name}: {json.dumps(row)}", flush=True)
        store.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
