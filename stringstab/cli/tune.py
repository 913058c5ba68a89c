"""``stringstab tune``: repair gain triples that are not string stable.

Reads triples from the command line or a file (:mod:`stringstab.gainio`, the
same inputs as ``certify``), repairs each with the IDL paper's region-growing
search and/or the nearest-point projection (:mod:`stringstab.tuning`), and
writes a table, JSON or CSV.  Exit code 0 when every output is certified by the
exact certificate, 1 when some is not, 2 on bad input (nothing printed).
"""

from __future__ import annotations

import argparse
import math
import os
import re
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import StringStabError
from ..gainio import FORMATS, GainTable, format_results, parse_triple, read_gains
from ..params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU, check_params

__all__ = ["add_parser", "run"]

_METHODS = ("region-growing", "projection", "both")

_EPILOG = f"""\
examples:
  stringstab tune 0.9,-0.5,1.1                       # nearest certified gains (projection)
  stringstab tune 0.9,-0.5,1.1 --method both          # and the IDL paper's region growing
  stringstab tune --file rollout.csv --format json --out repaired.json
  stringstab tune 0.2,0.7,0 --method region-growing --r0 0.05 --criterion printed

input files: as for `stringstab certify` (CSV with a header k_x,k_v,k_a and
optional t, vehicle; JSON; NPZ).

output: per input and method, the input gains (k_x_in, ...), the output gains,
whether the output is certified by the exact certificate, the status
(unchanged / repaired / taylor_stable / no_solution / failed), the weighted
distance moved, iterations, time and a message.

exit status: 0 every output certified; 1 some output not certified;
2 bad input (nothing printed, no file written).
defaults: tau={DEFAULT_TAU} s, delta={DEFAULT_DELTA} s, headway={DEFAULT_HEADWAY} s. See docs/tuning.md.
"""

# Read "-0.5,1,1" as a positional, not an unknown option (as `certify` does).
_NEGATIVE = re.compile(r"^-(\.?\d|inf|nan)", re.IGNORECASE)


def add_parser(sub: Any) -> None:
    """Register ``tune``."""
    p = sub.add_parser(
        "tune",
        help="repair gain triples that are not string stable (region growing or projection)",
        description=(
            "Replace each gain triple K = [k_x, k_v, k_a] that the exact certificate does not "
            "certify by nearby gains: the IDL paper's region-growing search (§3.3, Steps 1-6, "
            "Taylor test) and/or the nearest certified gains (weighted Euclidean projection "
            "solved with CasADi/IPOPT). Certified inputs are returned unchanged. Every output is "
            "checked by the exact certificate."
        ),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p._negative_number_matcher = _NEGATIVE  # type: ignore[attr-defined]
    p.add_argument("triples", nargs="*", metavar="K_X,K_V,K_A",
                   help="gain triples, e.g. 0.9,-0.5,1.1 (or use --file)")
    p.add_argument("--file", "-f", metavar="F",
                   help="read triples from a .csv, .json or .npz file ('-' reads CSV/JSON from stdin)")
    p.add_argument("--method", "-m", choices=_METHODS, default="projection",
                   help="repair method (default: projection)")
    p.add_argument("--tau", default=str(DEFAULT_TAU), metavar="S",
                   help=f"actuator lag τ in s, > 0 (default: {DEFAULT_TAU})")
    p.add_argument("--delta", default=str(DEFAULT_DELTA), metavar="S",
                   help=f"communication delay δ in s, >= 0 (default: {DEFAULT_DELTA})")
    p.add_argument("--headway", default=str(DEFAULT_HEADWAY), metavar="S",
                   help=f"desired time headway T* in s, >= 0 (default: {DEFAULT_HEADWAY})")
    p.add_argument("--bounds", default="-2,2", metavar="LO,HI",
                   help="bounds on every gain (default: -2,2, IDL Table 2)")
    p.add_argument("--weights", default="1,1,1", metavar="WX,WV,WA",
                   help="weights of the distance sqrt(sum w_i (K_i - K0_i)^2) (default: 1,1,1)")
    g = p.add_argument_group("region growing")
    g.add_argument("--r0", default="0.1", metavar="R", help="initial region half-width r0 (default: 0.1)")
    g.add_argument("--grid", default="2", metavar="N", help="grid intervals per r0 (default: 2)")
    g.add_argument("--max-iter", default=None, metavar="N",
                   help="maximum number of regions (default: until the bounds are covered)")
    g.add_argument("--criterion", choices=("derived", "printed"), default="derived",
                   help="Taylor test: derived (default) or the paper's printed formulas")
    g.add_argument("--check-hurwitz", action="store_true",
                   help="also require internal stability of accepted points (not in the paper)")
    g.add_argument("--grow-ka", action="store_true",
                   help="grow k_a with the region too (the paper keeps k_a0 ± r0)")
    q = p.add_argument_group("projection")
    q.add_argument("--hurwitz-margin", default="1e-3", metavar="M",
                   help="margin m in k_x >= m, k_v + (T* - tau) k_x >= m (default: 1e-3)")
    q.add_argument("--eps", default="1e-4", metavar="E",
                   help="margin of the frequency constraints g(omega_j) >= E (default: 1e-4)")
    p.add_argument("--format", choices=FORMATS, default="table", help="output format (default: table)")
    p.add_argument("--out", "-o", metavar="FILE", help="write to FILE instead of standard output")
    p.set_defaults(func=run)


def _numbers(text: str, n: int, option: str) -> list[float]:
    parts = text.split(",")
    if len(parts) != n:
        raise StringStabError(f"{option} expects {n} comma-separated numbers; got {text!r}")
    out = []
    for s in parts:
        try:
            x = float(s)
        except ValueError as e:
            raise StringStabError(f"{option} expects {n} comma-separated numbers; got {text!r}") from e
        if not math.isfinite(x):
            raise StringStabError(f"{option} expects finite numbers; got {text!r}")
        out.append(x)
    return out


def _number(text: str, option: str) -> float:
    return _numbers(text, 1, option)[0]


def _integer(text: str | None, option: str) -> int | None:
    if text is None:
        return None
    try:
        n = int(text)
    except ValueError as e:
        raise StringStabError(f"{option} must be an integer >= 1; got {text!r}") from e
    if n < 1:
        raise StringStabError(f"{option} must be an integer >= 1; got {text!r}")
    return n


def _gains(args: argparse.Namespace) -> GainTable:
    if args.triples and args.file:
        raise StringStabError(
            f"expected gain triples or --file, not both; got {len(args.triples)} triple(s) "
            f"and --file {args.file}"
        )
    if args.file:
        return read_gains(args.file)
    if not args.triples:
        raise StringStabError("expected gain triples K_X,K_V,K_A (e.g. 0.9,-0.5,1.1) or --file F; got none")
    triples = [parse_triple(t, where=f"triple {i + 1} {t!r}") for i, t in enumerate(args.triples)]
    return GainTable.from_triples(triples, source="<command line>")


_TABLE = [
    # header, key, format
    ("t", "t", ".6g"),
    ("vehicle", "vehicle", ""),
    ("method", "method", ""),
    ("k_x_in", "k_x_in", ".6g"),
    ("k_v_in", "k_v_in", ".6g"),
    ("k_a_in", "k_a_in", ".6g"),
    ("k_x", "k_x", ".6g"),
    ("k_v", "k_v", ".6g"),
    ("k_a", "k_a", ".6g"),
    ("certified", "certified", ""),
    ("status", "status", ""),
    ("distance", "distance", ".4g"),
    ("iter", "iterations", "d"),
    ("ms", "time_ms", ".3g"),
]


def _cell(v: Any, spec: str) -> str:
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, (int, float)) and spec:
        return format(v, spec)
    return str(v)


def _table(records: list[dict[str, Any]], params: dict[str, Any], summary: dict[str, Any]) -> str:
    cols = [c for c in _TABLE if any(c[1] in r for r in records)]
    body = [[_cell(r[k], spec) if k in r else "" for _, k, spec in cols] for r in records]
    widths = [max([len(h), *(len(row[j]) for row in body)]) for j, (h, _, _) in enumerate(cols)]
    lines = ["# " + ", ".join(f"{k} = {v}" for k, v in params.items())]
    lines.append("  ".join(h.ljust(w) for (h, _, _), w in zip(cols, widths)).rstrip())
    lines += ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in body]
    for m, s in summary.items():
        lines.append(f"# {m}: " + ", ".join(
            f"{k} = {v:.4g}" if isinstance(v, float) else f"{k} = {v}" for k, v in s.items()))
    return "\n".join(lines) + "\n"


def _write(text: str, dest: str | None) -> None:
    if dest is None:
        sys.stdout.write(text)
        return
    path = Path(dest)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as e:
        raise StringStabError(f"{dest}: cannot write the output file ({e.strerror or e})") from e
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as fh:
            fh.write(text)
        mask = os.umask(0o022)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, path)
    except OSError as e:
        Path(tmp).unlink(missing_ok=True)
        raise StringStabError(f"{dest}: cannot write the output file ({e.strerror or e})") from e


def _summary(records: list[dict[str, Any]], methods: list[str]) -> dict[str, dict[str, Any]]:
    out: dict[str, dict[str, Any]] = {}
    for m in methods:
        rs = [r for r in records if r["method"] == m]
        moved = [r["distance"] for r in rs if r["status"] == "repaired"]
        out[m] = {
            "n": len(rs),
            "certified": sum(r["certified"] for r in rs),
            "repaired": len(moved),
            "unchanged": sum(r["status"] == "unchanged" for r in rs),
            "not_certified": sum(not r["certified"] for r in rs),
            "median_distance_moved": float(np.median(moved)) if moved else 0.0,
        }
    return out


def run(args: argparse.Namespace) -> int:
    """Run ``tune``; returns 0 (every output certified), 1 (some not) or raises on bad input."""
    tau, delta, headway = check_params(args.tau, args.delta, args.headway)
    lo, hi = _numbers(args.bounds, 2, "--bounds")
    if not lo < hi:
        raise StringStabError(f"--bounds expects LO,HI with LO < HI; got {args.bounds!r}")
    weights = _numbers(args.weights, 3, "--weights")
    if min(weights) <= 0:
        raise StringStabError(f"--weights must all be > 0; got {args.weights!r}")
    r0 = _number(args.r0, "--r0")
    if r0 <= 0:
        raise StringStabError(f"--r0 must be > 0; got {args.r0!r}")
    grid = _integer(args.grid, "--grid")
    max_iter = _integer(args.max_iter, "--max-iter")
    margin = _number(args.hurwitz_margin, "--hurwitz-margin")
    eps = _number(args.eps, "--eps")
    if margin < 0 or eps <= 0:
        raise StringStabError(
            f"--hurwitz-margin must be >= 0 and --eps > 0; got {args.hurwitz_margin!r}, {args.eps!r}"
        )
    if args.out:
        out = Path(args.out)
        if out.is_dir() or not out.resolve().parent.is_dir():
            raise StringStabError(f"--out {args.out}: expected a file path in an existing directory")
    table = _gains(args)

    from ..tuning import Projector, region_growing

    methods = ["region-growing", "projection"] if args.method == "both" else [args.method]
    projector = None
    if "projection" in methods:
        projector = Projector(tau=tau, delta=delta, headway=headway, weights=weights,
                              bounds=(lo, hi), hurwitz_margin=margin, eps=eps, cache_size=0)
    records: list[dict[str, Any]] = []
    K = table.K
    for i in range(len(table)):
        for m in methods:
            if m == "region-growing":
                r = region_growing(K[i], tau=tau, delta=delta, headway=headway, r0=r0,
                                   grid=grid or 2, bounds=(lo, hi), max_iter=max_iter,
                                   criterion=args.criterion, weights=weights,
                                   grow_ka=args.grow_ka, check_hurwitz=args.check_hurwitz)
            else:
                assert projector is not None
                r = projector(K[i], use_state=False)
            records.append({**table.meta(i), **r.as_dict()})
    params: dict[str, Any] = {"tau": tau, "delta": delta, "headway": headway,
                              "method": args.method, "bounds": [lo, hi], "weights": weights}
    if "region-growing" in methods:
        params.update(r0=r0, grid=grid, max_iter=max_iter, criterion=args.criterion,
                      check_hurwitz=args.check_hurwitz, grow_ka=args.grow_ka)
    if "projection" in methods:
        params.update(hurwitz_margin=margin, eps=eps)
    summary = _summary(records, methods)
    if args.format == "table":
        flat = {k: (",".join(f"{x:g}" for x in v) if isinstance(v, list) else v)
                for k, v in params.items()}
        text = _table(records, flat, summary)
    elif args.format == "csv":  # lists as "lo,hi" cells
        flat = {k: (",".join(f"{x:g}" for x in v) if isinstance(v, list) else v)
                for k, v in params.items()}
        text = format_results(records, "csv", params=flat)
    else:
        text = format_results(records, "json", params=params, summary=summary)
    _write(text, args.out)
    if args.out:
        n_cert = sum(r["certified"] for r in records)
        print(f"stringstab tune: {n_cert} of {len(records)} outputs certified; "
              f"wrote {args.format} to {args.out}", file=sys.stderr)
    return 0 if all(r["certified"] for r in records) else 1
