"""The gain repair with a reaction delay θ_r (issue 25 part 2): how often it ends certified.

Draws triples the exact certificate certifies at θ_r = 0 but not at θ_r (a lattice of [−2, 2]³,
τ = 0.1 s, δ = 0.2 s, T* = 1.1 s), repairs each with ``project(..., reaction_delay=θ_r)`` and
prints, per θ_r: how many outputs are certified (by ``stringstab.certify`` with θ_r, asked
again here), how many came from the NLP or from the certified-map fallback, the median and
largest distance moved, and the median wall time per call, with the machine's load.

    python analysis/reaction_tune_check.py --n 40 --thetas 0.1,0.2,0.3
    python analysis/reaction_tune_check.py --n 20 --sample-time 0.1   # the sampled loop

With ``--sample-time H`` the triples are those of the lattice the sampled certificate certifies
at θ_r = 0 and not at θ_r, repaired and re-checked for the sampled loop with θ_r.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

import stringstab as ss
from stringstab.certify.grid import certified_lattice
from stringstab.params import Params
from stringstab.tuning import project

P = {"tau": 0.1, "delta": 0.2, "headway": 1.1}


def main(argv: list[str] | None = None) -> int:
    """Run the check; returns 0 when every output is certified, 1 otherwise."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=40, help="triples per θ_r (default 40)")
    ap.add_argument("--thetas", default="0.1,0.2,0.3", help="θ_r values, s")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--sample-time", type=float, default=None, help="H, s (the sampled loop)")
    a = ap.parse_args(argv)
    rng = np.random.default_rng(a.seed)
    base = certified_lattice(-2.0, 2.0, 21, Params(**P))
    kw = dict(P)
    if a.sample_time is not None:
        kw["sample_time"] = a.sample_time
        base = base[ss.check(*base.T, **kw).verdict == "certified"]
        print(f"sampled loop, H = {a.sample_time:g} s")
    print(f"load {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; {len(base)} certified "
          "lattice points at θ_r = 0 (21³ over [−2, 2]³)")
    print("| θ_r (s) | triples | certified (re-checked) | by the NLP | map fallback | "
          "median / max distance | median time (s) |")
    print("|---|---|---|---|---|---|---|")
    bad = 0
    for th in (float(v) for v in a.thetas.split(",")):
        lost = base[ss.check(*base.T, **kw, reaction_delay=th).verdict != "certified"]
        pick = lost[rng.choice(len(lost), size=min(a.n, len(lost)), replace=False)]
        ok = nlp = fb = 0
        dist, secs = [], []
        for K in pick:
            t = time.perf_counter()
            r = project(K, **kw, reaction_delay=th)
            secs.append(time.perf_counter() - t)
            again = ss.certify(*r.k, **kw, reaction_delay=th).verdict == "certified"
            assert again == r.certified, (K, r)
            ok += again
            fb += bool(r.details.get("fallback"))
            nlp += r.certified and not r.details.get("fallback")
            dist.append(r.distance)
        bad += len(pick) - ok
        print(f"| {th:g} | {len(pick)} | {ok} | {nlp} | {fb} | {np.median(dist):.3f} / "
              f"{max(dist):.3f} | {np.median(secs):.2f} |")
    return 0 if bad == 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
