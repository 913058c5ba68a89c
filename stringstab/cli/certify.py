"""``stringstab certify``: exact, delay-aware string-stability certificates for gain triples.

Reads triples from the command line or a file (:func:`stringstab.io.read_gains`),
certifies them with :func:`stringstab.certificate.certify_batch` and writes the
batch's columns (:meth:`~stringstab.certificate.CertificateBatch.columns`) as a
table, JSON, CSV, Parquet or NPZ (:func:`stringstab.io.write_results`).  Exit code 0
when every triple is certified, 1 when any is not (``not_certified`` or
``inconclusive``), 2 on bad input (nothing printed, no file written).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from typing import Any

from ..errors import StringStabError, show
from ..params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU
from ._common import (
    add_gain_arguments,
    add_model_arguments,
    add_output_arguments,
    check_output,
    gains_from_args,
    model_params,
)

__all__ = ["PROGRESS_ROWS", "add_parser", "run"]

#: Show a progress bar when there are more rows than this (or stderr is a terminal).
PROGRESS_ROWS = 10_000

_EPILOG = f"""\
examples:
  stringstab certify 0.9,-0.5,1.1 1.3,0,0.6
  stringstab certify -0.5,1,1 --delta 0.3              # negative gains need no quoting
  stringstab certify --file rollout.csv --format json --out certificates.json
  stringstab certify --file big.npz --format parquet --out certificates.parquet
  stringstab certify 0.9,-0.5,1.1 --method pade         # also python-control's Padé numbers

input files: CSV with a header k_x,k_v,k_a (a gain time series adds t and
optionally vehicle), JSON (a list of {{"k_x","k_v","k_a"}} objects or of triples,
bare or under "gains"), NPZ (arrays k_x, k_v, k_a [, t, vehicle] or K (n,3)) or
Parquet (columns k_x, k_v, k_a [, t, vehicle]).

output: table (for people: sup|Γ| and margin rounded, ω_peak in rad/s), or every
column in json, csv, parquet or npz (the last two need --out).

exit status: 0 every triple certified; 1 some triple not_certified or
inconclusive; 2 bad input (no verdicts printed, no file written).
defaults: tau={DEFAULT_TAU} s, delta={DEFAULT_DELTA} s, headway={DEFAULT_HEADWAY} s (IDL paper
Table 2; tau from Zhou et al. 2020). See docs/certify.md.
"""

def add_parser(sub: Any) -> None:
    """Register ``certify``."""
    p = sub.add_parser(
        "certify",
        help="certify gain triples K = [k_x, k_v, k_a] as string stable (exact delay)",
        description=(
            "Certify whether each gain triple K = [k_x, k_v, k_a] is string stable: Γ(s) "
            "(IDL eq 11, derived) is internally stable and sup_ω |Γ(jω)| ≤ 1 with the exact "
            "delay e^{-jδω}. Reports the verdict (certified / not_certified / inconclusive), "
            "sup|Γ|, its frequency, the margin, and the Taylor Proposition 1 (derived and "
            "printed Ψ) for comparison."
        ),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_gain_arguments(p)
    add_model_arguments(p)
    p.add_argument("--method", choices=("exact", "pade"), default="exact",
                   help="exact: the sound certificate (default); pade: the same, plus "
                        "python-control's Padé + norm('inf') numbers, warning where they disagree")
    p.add_argument("--pade-order", default="5", metavar="N",
                   help="Padé order of the delay for --method pade (default: 5)")
    add_output_arguments(p)
    p.add_argument("--no-progress", action="store_true",
                   help=f"never show the progress bar (default: shown on a terminal or > {PROGRESS_ROWS} rows)")
    p.set_defaults(func=run)


def _pade_order(text: str) -> int:
    try:
        n = int(text)
    except ValueError as e:
        raise StringStabError(f"--pade-order must be an integer >= 1; got {show(text)}") from e
    if n < 1:
        raise StringStabError(f"--pade-order must be an integer >= 1; got {show(text)}")
    return n


def _warn_disagreements(records: list[dict[str, Any]], order: int) -> None:
    """One warning on stderr listing (up to five) rows where Padé and the exact verdict differ."""
    bad = [(i, r) for i, r in enumerate(records) if r.get("pade") and not r["pade"].get("agrees", True)]
    if not bad:
        return
    print(
        f"stringstab certify: warning: python-control (Padé order {order}) disagrees with the "
        f"exact certificate on {len(bad)} of {len(records)} row(s); the exact verdict is reported",
        file=sys.stderr,
    )
    for i, r in bad[:5]:
        pade = r["pade"]
        print(
            f"  row {i + 1}: K=({r['k_x']:g}, {r['k_v']:g}, {r['k_a']:g}) exact {r['verdict']} "
            f"(sup|Γ| {r['sup_gain'] if r['sup_gain'] is not None else 'inf'}), "
            f"pade {pade['verdict']} (stable {pade['stable']}, norm {pade['hinf']})",
            file=sys.stderr,
        )
    if len(bad) > 5:
        print(f"  ... and {len(bad) - 5} more", file=sys.stderr)


def run(args: argparse.Namespace) -> int:
    """Run ``certify``; returns 0 (all certified), 1 (some not) or raises on bad input."""
    tau, delta, headway = model_params(args)
    order = _pade_order(args.pade_order)
    out = check_output(args)
    table = gains_from_args(args)

    from ..certificate import TABLE_COLUMNS, certify_batch
    from ..io import write_results

    n = len(table)
    progress = not args.no_progress and (sys.stderr.isatty() or n > PROGRESS_ROWS)
    with warnings.catch_warnings():
        # Padé disagreements are reported once, below, instead of per row.
        warnings.simplefilter("ignore")
        batch = certify_batch(
            table.k_x, table.k_v, table.k_a, tau=tau, delta=delta, headway=headway,
            method=args.method, pade_order=order, progress=progress,
        )
    params: dict[str, Any] = {"tau": tau, "delta": delta, "headway": headway, "method": args.method}
    if args.method == "pade":
        params["pade_order"] = order
    summary = batch.summary()
    write_results({**table.meta_columns(), **batch.columns()}, out, args.format, params=params,
                  summary=summary, table=TABLE_COLUMNS, what="--out")
    if args.method == "pade":
        _warn_disagreements([{**table.meta(i), **r} for i, r in enumerate(batch.records())], order)
    if out is not None:
        print(
            f"stringstab certify: {summary['certified']} of {summary['n']} certified; "
            f"wrote {args.format} to {out}",
            file=sys.stderr,
        )
    return 0 if summary["certified"] == summary["n"] else 1
