"""Record the continuous certificate's outputs at θ_r = 0 for the bit-for-bit test (issue 25).

Run once, at commit f6db69e of ``main`` (before the reaction delay θ_r existed), to write
``tests/data/theta_zero_f6db69e/``: the columns of ``certify_batch``, the verdicts of ``check``
and the rows of ``certify`` on a seeded set of gain triples at four (τ, δ, T*), and the files
``stringstab certify --file`` writes in each text format.  ``tests/certify/test_reaction_zero.py``
compares today's outputs with them, bit for bit, with and without ``reaction_delay=0.0``.
Re-running it on a later commit would overwrite the reference with that commit's outputs, so it
refuses to unless ``--force`` is given.

    python analysis/theta_zero_reference.py            # at f6db69e only
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

import stringstab as ss

OUT = Path(__file__).resolve().parents[1] / "tests" / "data" / "theta_zero_f6db69e"
#: (τ, δ, T*) settings, s.
SETTINGS = ((0.1, 0.2, 1.1), (0.5, 0.8, 2.0), (0.05, 0.0, 0.3), (1.0, 1.0, 3.0))
#: Columns of a continuous batch compared (taylor groups flattened).
SEED = 2025
N = 120


def triples() -> np.ndarray:
    """The seeded gain triples: uniform in [−2.5, 2.5]³ plus two of the docs' examples."""
    K = np.random.default_rng(SEED).uniform(-2.5, 2.5, (N, 3))
    return np.vstack([[[0.9, -0.5, 1.1], [1.5, 0.3, -0.1], [1.2, 0.5, 0.6]], K])


def flat(cols: dict, prefix: str = "") -> dict:
    out = {}
    for k, v in cols.items():
        if isinstance(v, dict):
            out.update(flat(v, f"{prefix}{k}."))
        else:
            a = np.asarray(v)
            out[prefix + k] = a.tolist()
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--force", action="store_true", help="overwrite an existing reference")
    args = ap.parse_args(argv)
    if OUT.exists() and not args.force:
        print(f"{OUT} exists: the reference is recorded once, at f6db69e (use --force)")
        return 1
    OUT.mkdir(parents=True, exist_ok=True)
    K = triples()
    rec: dict = {"seed": SEED, "K": K.tolist(), "settings": [list(s) for s in SETTINGS], "runs": []}
    for tau, delta, headway in SETTINGS:
        p = dict(tau=tau, delta=delta, headway=headway)
        b = ss.certify_batch(*K.T, **p)
        c = ss.check(*K.T, **p)
        singles = [ss.certify(*k, **p).as_dict() for k in K[:6]]
        rec["runs"].append({
            "params": p,
            "batch": flat(b.columns()),
            "summary": b.summary(),
            "check": {"verdict": c.verdict.tolist(), "hurwitz": c.hurwitz.tolist(),
                      "margin": c.margin.tolist(), "witness_omega": c.witness_omega.tolist()},
            "certify": singles,
        })
    (OUT / "api.json").write_text(json.dumps(rec), encoding="utf-8")
    gains = OUT / "gains.csv"
    gains.write_text("k_x,k_v,k_a\n" + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, b, c in K[:40]),
                     encoding="utf-8")
    exe = Path(sys.executable).with_name("stringstab")
    for fmt in ("table", "json", "csv"):
        out = subprocess.run([str(exe), "certify", "--file", str(gains), "--format", fmt,
                              "--tau", "0.2", "--delta", "0.3", "--headway", "1.5"],
                             capture_output=True, text=True, check=False)
        (OUT / f"certify.{fmt}").write_text(out.stdout, encoding="utf-8")
        (OUT / f"certify.{fmt}.rc").write_text(str(out.returncode), encoding="utf-8")
    print(f"wrote {OUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
