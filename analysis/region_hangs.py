"""Consecutive ``stringstab region`` runs under a watchdog: does any hang? (issue 29).

Runs ``stringstab region --fix k_a=0.5 --n N --workers W`` (default outputs: every method,
the NPZ, the CSV, the figures, the report) ``--runs`` times, one after another, each in a
fresh process with a watchdog: a run that takes longer than ``--timeout`` seconds counts as
a hang, its processes are listed (from ``/proc``) and killed.  Prints one line per run (its
wall time, its exit code, the load average) and the count of runs that finished, failed and
hung, with the median time per run.  Asserts nothing.

The closing figure of issue 29 is ``--runs 50 --n 801 --workers 2``.  ``--base DIR`` runs the
command from another checkout (e.g. ``git archive f6db69e | tar -x -C /tmp/base``) on this
interpreter, to compare with the code before the start-method policy.

Examples
--------
    python analysis/region_hangs.py --runs 50 --n 801 --workers 2
    python analysis/region_hangs.py --runs 30 --n 201 --base /tmp/base --timeout 60
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _load() -> str:
    one, five, _ = os.getloadavg()
    return f"load {one:.2f} (1 min), {five:.2f} (5 min)"


def _descendants(pid: int) -> list[int]:
    parent = {}
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                parent[int(d.name)] = int((d / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, ValueError, IndexError):
                continue
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        kids = [c for c, pp in parent.items() if pp == p]
        out += kids
        todo += kids
    return sorted(out)


def _wchan(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/wchan").read_text() or "?"
    except OSError:
        return "gone"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=50)
    ap.add_argument("--n", type=int, default=801)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds before a run is a hang")
    ap.add_argument("--base", metavar="DIR", help="run the stringstab package found in DIR")
    ap.add_argument("extra", nargs="*", help="more arguments for stringstab region (after --)")
    args = ap.parse_args()
    env = dict(os.environ)
    if args.base:
        env["PYTHONPATH"] = str(Path(args.base).resolve())
    work = Path(tempfile.mkdtemp(prefix="region_hangs_"))
    cmd = [sys.executable, "-m", "stringstab", "region", "--fix", "k_a=0.5", "--n", str(args.n),
           "--workers", str(args.workers), *args.extra]
    print(f"{' '.join(cmd[2:])} --out ... x {args.runs}, watchdog {args.timeout:g} s, "
          f"{'base ' + args.base if args.base else 'this checkout'}; {os.cpu_count()} cores; {_load()}",
          flush=True)
    times, failed, hung = [], [], []
    try:
        for i in range(args.runs):
            out = work / f"m{i}"
            t0 = time.perf_counter()
            p = subprocess.Popen([*cmd, "--out", str(out)], stdout=subprocess.DEVNULL,
                                 stderr=subprocess.PIPE, env=env, start_new_session=True,
                                 cwd=work)  # not the repository root: it would shadow --base
            try:
                _, err = p.communicate(timeout=args.timeout)
                dt = time.perf_counter() - t0
                what = f"exit {p.returncode}"
                if p.returncode != 0:
                    failed.append(i)
                    what += ": " + err.decode(errors="replace").strip().splitlines()[-1][:200]
                else:
                    times.append(dt)
            except subprocess.TimeoutExpired:
                dt = time.perf_counter() - t0
                procs = [(q, _wchan(q)) for q in [p.pid, *_descendants(p.pid)]]
                hung.append(i)
                what = f"HUNG (killed): processes {procs}"
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
            shutil.rmtree(out, ignore_errors=True)
            print(f"run {i + 1:3d}: {dt:7.2f} s  {what}  ({_load()})", flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    med = f"{statistics.median(times):.2f} s" if times else "n/a"
    print(f"{len(times)} of {args.runs} runs finished (median {med} per run, "
          f"min {min(times, default=float('nan')):.2f}, max {max(times, default=float('nan')):.2f}); "
          f"{len(failed)} failed {failed}; {len(hung)} hung {hung}; {_load()}")


if __name__ == "__main__":
    main()
