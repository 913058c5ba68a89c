"""Every output field of the robust sampled ``certify_batch``, this checkout against a base commit.

Issue 31's speed work on the robust sampled-data certificate must leave its results the same
bit for bit, not only its verdicts.  This script decides the same gain triples over several
boxes (``BOXES`` of :mod:`analysis.robust_sampled_verdicts`: heterogeneous lags, τ_p = τ,
delays over several pieces, a delay box alone) with the base commit (unpacked with
``git archive``) and with this checkout, each in its own process, and compares every field
of the :class:`~stringstab.certify.robust.RobustCertificateBatch` byte for byte (floats by
their bits: NaN patterns and signs of zero included).  The triples: ``--n`` random ones in
[−2, 2]³ (seed 33, mostly not certified), ``--n-near`` in k_x ∈ [0, 1], k_v ∈ [0, 2],
k_a ∈ [−0.5, 0.5] (seed 34, about half certified: the searches that run to the end) and
every adversarial row of the robust sampled kinds in ``tests/data/speed_verdicts.csv``
(near Schur, near |H| = 1 over the box, boxes straddling the boundary).  Prints the counts per box and field; exits 1 when any field differs::

    python analysis/robust_sampled_fields.py --base 8043ba3            # ~1 min
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(HERE / "analysis"))
from robust_sampled_verdicts import BOXES  # noqa: E402


def inputs(n: int, n_near: int) -> np.ndarray:
    """The gain triples (rows, 3): random ones, random ones near certified, adversarial."""
    rand = np.random.default_rng(33).uniform(-2, 2, (n, 3))
    near = np.random.default_rng(34).uniform([0.0, 0.0, -0.5], [1.0, 2.0, 0.5], (n_near, 3))
    data = HERE / "tests" / "data" / "speed_verdicts.csv"
    with data.open(encoding="utf-8") as f:
        adv = np.array([[float(r["k_x"]), float(r["k_v"]), float(r["k_a"])]
                        for r in csv.DictReader(f)
                        if r["set"] in ("sampled_adversarial", "sampledhom_adversarial")])
    return np.concatenate([rand, near, adv])


def worker(inp: str, out: str) -> None:
    """Decide the triples of ``inp`` over every box with the stringstab on the path; save."""
    from stringstab.certify.api import certify_batch

    K = np.load(inp)["K"]
    res = {}
    for name, box in BOXES.items():
        r = certify_batch(*K.T, **box)
        for f in dataclasses.fields(r):
            v = getattr(r, f.name)
            res[f"{name}/{f.name}"] = np.asarray(v if isinstance(v, np.ndarray) else repr(v))
    np.savez(out, **res)


def _bits(a: np.ndarray) -> np.ndarray:
    """Per row, the bytes of a float or integer array (or the values of others)."""
    if a.dtype.kind in "fiub" and a.ndim:
        return a.reshape(a.shape[0], -1).view(np.uint8).reshape(a.shape[0], -1)
    return a


def compare(before: dict, after: dict) -> tuple[dict[str, int], int, int]:
    """Rows that differ per field (``box/field``), the rows compared and the fields."""
    diff = {}
    rows = 0
    for key in before:
        a, b = before[key], after.get(key)
        if b is None or a.shape != b.shape or a.dtype != b.dtype:
            diff[key] = -1
            continue
        if a.ndim == 0:
            diff[key] = int(a != b)
            continue
        rows = max(rows, a.shape[0])
        x, y = _bits(a), _bits(b)
        ne = (x != y)
        diff[key] = int(ne.reshape(ne.shape[0], -1).any(axis=1).sum()) if ne.ndim else int(ne)
    return diff, rows, len(before)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--base", default="8043ba3", help="the base commit (default 8043ba3)")
    ap.add_argument("--n", type=int, default=3000, help="random triples (default 3000)")
    ap.add_argument("--n-near", type=int, default=1500,
                    help="random triples near the certified region (default 1500)")
    ap.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        worker(*args.worker)
        return 0
    tmp = tempfile.mkdtemp(prefix="robust_fields_")
    base = os.path.join(tmp, "base")
    os.makedirs(base)
    subprocess.run(f"git -C {HERE} archive {args.base} stringstab | tar -x -C {base}",
                   shell=True, check=True)
    K = inputs(args.n, args.n_near)
    inp = os.path.join(tmp, "inputs.npz")
    np.savez(inp, K=K)
    res = {}
    for side, path in (("before", base), ("after", str(HERE))):
        out = os.path.join(tmp, f"{side}.npz")
        env = {**os.environ, "PYTHONPATH": path}
        subprocess.run([sys.executable, __file__, "--worker", inp, out], env=env, check=True,
                       cwd=tmp)
        with np.load(out) as z:
            res[side] = {k: z[k] for k in z.files}
    diff, rows, nf = compare(res["before"], res["after"])
    print(f"# base {args.base} vs {HERE}: {rows} triples × {len(BOXES)} boxes = "
          f"{rows * len(BOXES)} verdicts, {nf} fields compared")
    for name in BOXES:
        v = res["after"][f"{name}/verdict"]
        counts = {str(a): int(b) for a, b in zip(*np.unique(v, return_counts=True))}
        bad = {k.split("/", 1)[1]: d for k, d in diff.items() if k.startswith(name + "/") and d}
        print(f"{name}: verdicts {counts}; rows with a field different: "
              f"{bad if bad else 0}")
    total = sum(abs(d) for d in diff.values())
    print(f"total differing (rows × fields): {total}")
    return 1 if total else 0


if __name__ == "__main__":
    sys.exit(main())
