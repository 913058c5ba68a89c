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
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import StringStabError
from ..gainio import FORMATS, format_results, write_text
from ..params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU
from ._common import add_gain_arguments, add_model_arguments, gains_from_args, model_params

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
    add_gain_arguments(p)
    p.add_argument("--method", "-m", choices=_METHODS, default="projection",
                   help="repair method (default: projection)")
    add_model_arguments(p)
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
    tau, delta, headway = model_params(args)
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
    table = gains_from_args(args)

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
    write_text(text, args.out if args.out else sys.stdout)
    if args.out:
        n_cert = sum(r["certified"] for r in records)
        print(f"stringstab tune: {n_cert} of {len(records)} outputs certified; "
              f"wrote {args.format} to {args.out}", file=sys.stderr)
    return 0 if all(r["certified"] for r in records) else 1
