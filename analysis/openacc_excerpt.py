"""Build the OpenACC excerpts shipped in ``stringstab/data/openacc/`` from the original logs.

Each original file (the JRC's OpenACC database, CC BY 4.0; see the README written beside the
excerpts) is kept in its own format — the five metadata lines byte for byte, the header, every
data row, the cells' text unchanged, CRLF line ends — with only the columns ``stringstab
identify`` reads: ``Time``, every ``Speedk`` and every ``IVSk`` (the E, N, Lon, Lat and Alt
columns go: the reader uses E and N only to cross-check the speed unit, done here on the
originals, the ratios printed).  The result is gzip-compressed with a zero timestamp, so the
same input gives the same bytes.  The script then reads both through the toolkit's reader and
checks that every array identify uses is identical (it exits 1 otherwise).  With
``--identify`` it also runs ``stringstab identify`` (default settings, no figures) on each
original and on its excerpt and compares the two ``identify.json`` (everything but ``sources``,
the file names) and ``identify.csv`` (about 3 min on 2 busy cores).

    python analysis/openacc_excerpt.py ../shared/data/openacc [--identify]
"""

from __future__ import annotations

import argparse
import gzip
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from stringstab.io.platoon_logs import read_platoon_logs

FILES = ("zalazone_acc_short_dynamic_part1.csv", "zalazone_human_handling_part22.csv")
KEEP = re.compile(r"Time|Speed\d+|IVS\d+", re.IGNORECASE)
OUT = Path(__file__).resolve().parents[1] / "stringstab" / "data" / "openacc"


def excerpt(src: Path) -> bytes:
    """The excerpt of one original file, uncompressed."""
    raw = src.read_bytes()
    lines = raw.split(b"\r\n") if b"\r\n" in raw else raw.split(b"\n")
    eol = b"\r\n" if b"\r\n" in raw else b"\n"
    k = next(i for i, ln in enumerate(lines) if ln.split(b",")[0].strip().lower() == b"time")
    header = lines[k].decode("utf-8").split(",")
    keep = [j for j, c in enumerate(header) if KEEP.fullmatch(c.strip())]
    out = lines[:k]  # the metadata lines, byte for byte
    for ln in lines[k:]:
        if not ln:
            continue
        cells = ln.split(b",")
        out.append(b",".join(cells[j] if j < len(cells) else b"" for j in keep))
    return eol.join(out) + eol


def same(a_path: Path, b_path: Path) -> list[str]:
    """What differs between two logs in what identify reads (empty: nothing)."""
    [a], [b] = read_platoon_logs(a_path), read_platoon_logs(b_path)
    diffs = []
    for name in ("positions", "names"):
        if getattr(a, name) != getattr(b, name):
            diffs.append(name)
    for name in ("t", "speed"):
        if not np.array_equal(getattr(a, name), getattr(b, name), equal_nan=True):
            diffs.append(name)
    if a.gap.keys() != b.gap.keys() or not all(
            np.array_equal(a.gap[k], b.gap[k], equal_nan=True) for k in a.gap):
        diffs.append("gap")
    meta_a = {k: v for k, v in a.meta.items() if k != "speed_position_ratio"}
    meta_b = {k: v for k, v in b.meta.items() if k != "speed_position_ratio"}
    if meta_a != meta_b:
        diffs.append("meta")
    return diffs


def same_identify(a_path: Path, b_path: Path) -> str:
    """Run ``stringstab identify`` on both files; say whether the outputs are the same."""
    with tempfile.TemporaryDirectory() as tmp:
        outs = []
        for k, f in enumerate((a_path, b_path)):
            out = Path(tmp) / str(k)
            subprocess.run([sys.executable, "-m", "stringstab", "identify", str(f), "--out",
                            str(out), "--no-figures", "--no-progress"], check=True,
                           stdout=subprocess.DEVNULL)
            doc = json.loads((out / "identify.json").read_text())
            doc.pop("sources")
            outs.append((doc, (out / "identify.csv").read_bytes()))
    (da, ca), (db, cb) = outs
    return (f"identify.json {'identical' if da == db else 'DIFFERENT'} but for 'sources' "
            f"({len(da['vehicles'])} vehicles), identify.csv "
            f"{'identical' if ca == cb else 'DIFFERENT'}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("source", type=Path, help="the folder of the original OpenACC files")
    ap.add_argument("--out", type=Path, default=OUT, help=f"where to write (default {OUT})")
    ap.add_argument("--identify", action="store_true",
                    help="also compare stringstab identify's outputs on original and excerpt")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    bad = 0
    for name in FILES:
        src = args.source / name
        dst = args.out / (name + ".gz")
        data = excerpt(src)
        dst.write_bytes(gzip.compress(data, compresslevel=9, mtime=0))
        [orig] = read_platoon_logs(src)
        diffs = same(src, dst)
        bad += bool(diffs)
        print(f"{name}: {src.stat().st_size:,} B -> {len(data):,} B of CSV -> "
              f"{dst.stat().st_size:,} B gzip ({dst}); rows {orig.t.size}; speed/position ratio "
              f"on the original {orig.meta['speed_position_ratio']}; "
              + ("identical arrays" if not diffs else f"DIFFERENT: {diffs}"))
        if args.identify:
            verdict = same_identify(src, dst)
            bad += "DIFFERENT" in verdict
            print(f"  {verdict}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
