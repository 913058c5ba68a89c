"""Record the robust sampled certificate's verdicts on fixed sets (issue 31's speed work).

Run with the code whose verdicts are the reference on ``PYTHONPATH`` (main before the
change), e.g.::

    PYTHONPATH=/path/to/main python analysis/robust_sampled_verdicts.py \
        tests/certify/robust_sampled_verdicts_031c8b1.npz

The sets: 300 random gain triples in [−2, 2]³ (seed 31); every other adversarial row of the
robust sampled kinds in ``tests/data/speed_verdicts.csv`` (near Schur, near |H| = 1 over the
box, boxes straddling the boundary: 150 rows); and the 30 triples of 4,000 random ones (seed 32) whose search
took the most evaluations (the refinement's stragglers, the rows the cells computed ahead
serve).  Four boxes (``BOXES``): heterogeneous lags, τ_p = τ, delays over several pieces, and
a delay box alone at another sample time.  ``tests/certify/test_robust_sampled_speed.py``
decides them again and compares every verdict.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import numpy as np

BOXES = {
    "hetero": dict(tau=(0.1, 0.2), delta=(0.15, 0.25), headway=(1.0, 1.2), sample_time=0.1),
    "hom": dict(tau=(0.1, 0.2), delta=(0.15, 0.25), headway=(1.0, 1.2), sample_time=0.1,
                heterogeneous=False),
    "pieces": dict(tau=(0.1, 0.15), delta=(0.05, 0.32), headway=(0.9, 1.4), sample_time=0.1),
    "delay": dict(tau=0.1, delta=(0.1, 0.3), headway=1.1, sample_time=0.05),
}


def inputs() -> np.ndarray:
    """The gain triples (n, 3): random, adversarial, stragglers."""
    from stringstab.certify.api import certify_batch

    rand = np.random.default_rng(31).uniform(-2, 2, (300, 3))
    data = Path(__file__).parents[1] / "tests" / "data" / "speed_verdicts.csv"
    with data.open(encoding="utf-8") as f:
        adv = np.array([[float(r["k_x"]), float(r["k_v"]), float(r["k_a"])]
                        for r in csv.DictReader(f)
                        if r["set"] in ("sampled_adversarial", "sampledhom_adversarial")])[::2]
    pool = np.random.default_rng(32).uniform(-2, 2, (4000, 3))
    ev = np.asarray(certify_batch(*pool.T, **BOXES["hetero"]).n_evals)
    slow = pool[np.argsort(-ev, kind="stable")[:30]]
    return np.concatenate([rand, adv, slow])


def main(out: str) -> None:
    import stringstab
    from stringstab.certify.api import certify_batch

    K = inputs()
    res = {"K": K}
    for name, box in BOXES.items():
        res[name] = np.asarray(certify_batch(*K.T, **box).verdict).astype(str)
        print(name, dict(zip(*np.unique(res[name], return_counts=True))), file=sys.stderr)
    np.savez_compressed(out, **res)
    print(f"written {out} with {stringstab.__file__}", file=sys.stderr)


if __name__ == "__main__":
    main(sys.argv[1])
