"""The three speed targets of the command line (issue 9, item 4), as ratios measured in one run.

1. **Fast start.**  Wall time of ``stringstab certify 1,0.5,0.5`` (a fresh process) over that
   of ``python -c "import numpy, scipy.linalg"``; target ≤ 1.5.  The two are run alternately
   ``--repeat`` times and the medians compared, so load drift hits both alike.
2. **Fast outputs.**  ``stringstab certify --file`` on ``--n`` (10⁵) triples uniform in the
   IDL action box [−2, 2]³, end to end (a fresh process: start, reading the CSV, certifying,
   writing ``--out`` in each ``--formats``), per triple, against the per-triple cost of
   python-control's Padé-5 ``norm`` (:func:`stringstab.certify.pade.certify_pade`, on
   ``--pade-n`` triples of the same set, in this process).  Target ≥ 100×.  Whether slycot
   (which python-control's ``norm`` uses when present) is installed is printed.
3. **Region map through the CLI.**  ``stringstab region`` on an ``--region-n``² (801²) exact
   map over (k_x, k_v) at k_a = 0.5 with ``--format png`` and the CSV data, against
   :func:`stringstab.regions.region_map` alone (in this process) on the same grid, the two
   alternated ``--region-repeat`` times and the medians compared; target ≤ 1.5.

Every figure is printed with the machine load (``os.getloadavg()``) beside it; nothing is
asserted.  Run from the repository root::

    python analysis/bench_cli.py                    # all three, ~5 minutes on 2 cores
    python analysis/bench_cli.py --only start --repeat 15
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from stringstab.constants import DELTA, GAIN_BOUNDS, HEADWAY, TAU


def _load() -> str:
    one, five, _ = os.getloadavg()
    return f"load {one:.2f} (1 min), {five:.2f} (5 min) on {os.cpu_count()} cores"


def _cli() -> list[str]:
    script = Path(sys.executable).with_name("stringstab")
    return [str(script)] if script.exists() else [sys.executable, "-m", "stringstab"]


def _wall(cmd: list[str], **kw: object) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, check=False, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, **kw)  # type: ignore[call-overload]
    return time.perf_counter() - t0


def bench_start(repeat: int) -> None:
    base_cmd = [sys.executable, "-c", "import numpy, scipy.linalg"]
    lib_cmd = [sys.executable, "-c", "import stringstab.certify.api"]
    cmd = [*_cli(), "certify", "1,0.5,0.5"]
    r = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if r.returncode != 0:
        raise SystemExit(f"stringstab certify failed: {r.stderr}")
    base, lib, target = [], [], []
    _wall(base_cmd), _wall(lib_cmd), _wall(cmd)  # warm the file cache
    for _ in range(repeat):
        base.append(_wall(base_cmd))
        lib.append(_wall(lib_cmd))
        target.append(_wall(cmd))
    mb, ml, mt = statistics.median(base), statistics.median(lib), statistics.median(target)
    print("1. fast start: the command-line layer (lazy sub-commands, light io) adds the last "
          "line minus the middle one; the library's import chain is the middle one")
    for label, m, xs in (("baseline  python -c 'import numpy, scipy.linalg'", mb, base),
                         ("library   python -c 'import stringstab.certify.api'", ml, lib),
                         ("target    stringstab certify 1,0.5,0.5           ", mt, target)):
        print(f"   {label} median {m * 1e3:7.1f} ms (min {min(xs) * 1e3:.1f}, "
              f"max {max(xs) * 1e3:.1f}, n={repeat})")
    print(f"   ratio {mt / mb:.2f} (target <= 1.5); CLI layer and the certificate of one triple "
          f"{(mt - ml) * 1e3:.0f} ms   [{_load()}]")


def _triples(n: int, seed: int) -> np.ndarray:
    lo, hi = GAIN_BOUNDS
    return np.random.default_rng(seed).uniform(lo, hi, size=(n, 3))


def bench_outputs(n: int, pade_n: int, formats: list[str], seed: int, repeat: int) -> None:
    from stringstab.certify.api import certify_batch
    from stringstab.certify.pade import certify_pade

    K = _triples(n, seed)
    work = Path(tempfile.mkdtemp(prefix="bench_cli_"))
    try:
        src = work / "gains.csv"
        with open(src, "w") as fh:
            fh.write("k_x,k_v,k_a\n")
            np.savetxt(fh, K, delimiter=",", fmt="%.17g")
        sub = K[np.random.default_rng(seed + 1).choice(n, size=min(pade_n, n), replace=False)]
        certify_pade(*sub[0], tau=TAU, delta=DELTA, headway=HEADWAY, order=5)  # imports, warm-up
        certify_batch(K[:100, 0], K[:100, 1], K[:100, 2], tau=TAU, delta=DELTA, headway=HEADWAY)
        # the baseline is timed on a slice of `sub` just before each CLI run, so that both
        # sides of every ratio see the same machine load
        chunks = np.array_split(sub, max(1, len(formats) * repeat))

        def pade_per_triple(chunk: np.ndarray) -> float:
            t0 = time.perf_counter()
            for kx, kv, ka in chunk:
                certify_pade(kx, kv, ka, tau=TAU, delta=DELTA, headway=HEADWAY, order=5)
            return (time.perf_counter() - t0) / len(chunk)

        t0 = time.perf_counter()
        certify_batch(K[:, 0], K[:, 1], K[:, 2], tau=TAU, delta=DELTA, headway=HEADWAY)
        lib = (time.perf_counter() - t0) / n
        slycot = importlib.util.find_spec("slycot") is not None
        print(f"2. fast outputs: certify --file on {n} triples uniform in [-2, 2]^3 (seed {seed}); "
              f"baseline certify_pade (python-control Padé-5 norm; slycot "
              f"{'installed, so norm uses it' if slycot else 'NOT installed'}) on "
              f"{len(chunks[0])} triples before each CLI run")
        print(f"   context   certify_batch alone, in process: {lib * 1e6:8.1f} us/triple   [{_load()}]")
        k = 0
        for fmt in formats:
            out = work / f"out.{fmt}"
            cmd = [*_cli(), "certify", "--file", str(src), "--format", fmt, "--out", str(out),
                   "--no-progress"]
            walls, pades = [], []
            for _ in range(repeat):
                pades.append(pade_per_triple(chunks[k % len(chunks)]))
                k += 1
                walls.append(_wall(cmd))
            if not out.exists():
                raise SystemExit(f"stringstab certify --format {fmt} wrote nothing")
            w, pade = statistics.median(walls) / n, statistics.median(pades)
            print(f"   --format {fmt:<8} CLI end to end {w * 1e6:7.1f} us/triple (median of {repeat}: "
                  f"{w * n:.2f} s; {out.stat().st_size / 1e6:.1f} MB), Padé {pade * 1e6:7.0f} "
                  f"us/triple: ratio {pade / w:5.0f}x (target >= 100)   [{_load()}]")
    finally:
        shutil.rmtree(work, ignore_errors=True)


def bench_region(n: int, workers: int | None, repeat: int) -> None:
    from stringstab.regions import region_map

    g = np.linspace(-2.0, 2.0, n)
    kw = {} if workers is None else {"workers": workers}
    work = Path(tempfile.mkdtemp(prefix="bench_cli_region_"))
    cmd = [*_cli(), "region", "--x", "k_x", "--y", "k_v", "--fix", "k_a=0.5",
           "--range", "-2,2", "--n", str(n), "--method", "exact", "--format", "png",
           "--no-progress", "--out", str(work / "maps")]
    if workers is not None:
        cmd += ["--workers", str(workers)]
    alone: list[float] = []
    cli: list[float] = []
    print(f"3. region map {n}x{n} exact (k_x, k_v at k_a = 0.5), PNG and data; "
          f"region_map alone (in process) and the command (a fresh process) alternated {repeat} times")
    try:
        for i in range(repeat):
            t0 = time.perf_counter()
            region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=TAU, delta=DELTA, headway=HEADWAY,
                       methods="exact", progress=False, **kw)  # type: ignore[arg-type]
            alone.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            r = subprocess.run(cmd, capture_output=True, text=True, check=False)
            cli.append(time.perf_counter() - t0)
            if r.returncode != 0:
                raise SystemExit(f"stringstab region failed: {r.stderr.strip()}")
            print(f"   run {i + 1}: region_map alone {alone[-1]:6.2f} s, stringstab region {cli[-1]:6.2f} s, "
                  f"ratio {cli[-1] / alone[-1]:.2f}   [{_load()}]")
        files = sorted(p.name for p in (work / "maps").iterdir() if not p.name.startswith("."))
    finally:
        shutil.rmtree(work, ignore_errors=True)
    a, c = statistics.median(alone), statistics.median(cli)
    print(f"   baseline  region_map alone, in process: median {a:7.2f} s")
    print(f"   target    stringstab region (fresh process, writes {', '.join(files)}): median {c:7.2f} s")
    print(f"   ratio of medians {c / a:.2f} (target <= 1.5; per run {min(x / y for x, y in zip(cli, alone)):.2f}"
          f"-{max(x / y for x, y in zip(cli, alone)):.2f})   [{_load()}]")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", choices=("start", "outputs", "region"), action="append",
                    help="run only these targets (repeatable; default all three)")
    ap.add_argument("--repeat", type=int, default=9, help="start-up runs of each command (default 9)")
    ap.add_argument("--n", type=int, default=100_000, help="triples for target 2 (default 10^5)")
    ap.add_argument("--pade-n", type=int, default=300, help="triples timed with certify_pade (default 300)")
    ap.add_argument("--formats", default="table,csv,json,parquet",
                    help="output formats of target 2 (default table,csv,json,parquet)")
    ap.add_argument("--output-repeat", type=int, default=3, help="CLI runs per format (median; default 3)")
    ap.add_argument("--region-n", type=int, default=801, help="grid points per axis of target 3 (default 801)")
    ap.add_argument("--workers", type=int, default=None, help="worker processes for target 3 (both sides)")
    ap.add_argument("--region-repeat", type=int, default=5,
                    help="alternated runs of each side of target 3 (median; default 5)")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    only = set(args.only or ("start", "outputs", "region"))
    print(f"stringstab bench_cli: python {sys.version.split()[0]}, {_load()}")
    if "start" in only:
        bench_start(args.repeat)
    if "outputs" in only:
        bench_outputs(args.n, args.pade_n, args.formats.split(","), args.seed, args.output_repeat)
    if "region" in only:
        bench_region(args.region_n, args.workers, args.region_repeat)


if __name__ == "__main__":
    main()
