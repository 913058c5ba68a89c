"""``stringstab tune``: repair gain triples that are not string stable.

Reads triples from the command line or a file (:mod:`stringstab.io.gains`, the
same inputs as ``certify``), repairs each with the IDL paper's region-growing
search and/or the nearest-point projection (:mod:`stringstab.tuning`), and
writes a table, JSON or CSV.  Exit code 0 when every output is certified by the
exact certificate, 1 when some is not, 2 on bad input (nothing printed).
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

import numpy as np

from ..errors import StringStabError
from ..io import check_output_file, format_results, write_text
from ..params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU, Box
from ._common import (
    add_gain_arguments,
    add_model_arguments,
    check_horizon,
    gains_from_args,
    loop_params,
    shown_params,
)

__all__ = ["add_parser", "run"]

_METHODS = ("region-growing", "projection", "both")
_FORMATS = ("table", "json", "csv")

_EPILOG = f"""\
examples:
  stringstab tune 0.9,-0.5,1.1                       # nearest certified gains (projection)
  stringstab tune 0.9,-0.5,1.1 --method both          # and the IDL paper's region growing
  stringstab tune --file rollout.csv --format json --out repaired.json
  stringstab tune 0.2,0.7,0 --method region-growing --r0 0.05 --criterion printed
  stringstab tune 0.9,-0.5,1.1 --sample-time 0.1      # certified for the loop sampled at 10 Hz
  stringstab tune 0.9,-0.5,1.1 --tau 0.1:0.2 --delta 0.15:0.25   # for every τ, δ in the box
  stringstab tune 1.2,0.5,0.6 --reaction-delay 0.2    # certified with the command 0.2 s late
  stringstab tune 0.5,0.4,0 --tau 0.5 --delta 0.1 --headway 1.5 --sample-time 0.1 --reaction-delay 0.2

input files: as for `stringstab certify` (CSV with a header k_x,k_v,k_a and
optional t, vehicle; JSON; NPZ).

with --sample-time or a LO:HI interval the projection repairs to gains certified for
that loop (sampled, or every member of the box); region growing (a continuous-time
Taylor test at one tau, delta, headway) takes neither. With --reaction-delay S > 0 the
projection repairs to gains certified with the reaction delay, continuous or sampled (at one
tau, delta, headway: a box with a reaction delay is refused).

output: per input and method, the input gains (k_x_in, ...), the output gains,
whether the output is certified by the exact certificate, the status
(unchanged / repaired / taylor_stable / no_solution / failed), the weighted
distance moved, iterations, time and a message.

exit status: 0 every output certified; 1 some output not certified;
2 bad input (nothing printed, no file written).
defaults: tau={DEFAULT_TAU} s, delta={DEFAULT_DELTA} s, headway={DEFAULT_HEADWAY} s. See docs/tuning.md.
"""



def add_parser(sub: Any) -> None:
    """Register ``tune``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
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
    # -- the reaction delay θ_r (issue 25 part 2)
    p.add_argument("--reaction-delay", metavar="SECONDS",
                   help="reaction (actuation) delay θ_r in s, >= 0, on the whole command "
                        "(τ a' = u(t − θ_r) − a): the projection repairs to gains certified with "
                        "it, continuous or with --sample-time (default: 0)")
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
    p.add_argument("--format", choices=_FORMATS, default=None,
                   help="output format (default: the --out file's extension .json/.csv, else table)")
    p.add_argument("--out", "-o", metavar="FILE", help="write to FILE instead of standard output")
    p.add_argument("--report", metavar="DIR",
                   help="also write report.md, report.html (self-contained) and tune_moves.png "
                        "(the moves over the certified region) into the folder DIR")
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


def run(args: argparse.Namespace) -> int:
    """Run ``tune``; returns 0 (every output certified), 1 (some not) or raises on bad input.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab tune``.

    Returns
    -------
    int
        Exit code: 0 when every repaired gain is certified, 1 when some is not; bad
        input raises :class:`~stringstab.errors.StringStabError` (exit 2 from
        :func:`stringstab.cli.main`).
    """
    model, H = loop_params(args)
    general = H is not None or isinstance(model, Box)
    # -- θ_r > 0 (issue 25 part 2): the projection only; beyond the continuous point loop the
    # certificate's refusal (raised by the Projector below, before any output)
    theta = Box.of(model).reaction_delay[1]
    if theta and args.method != "projection":
        raise StringStabError(
            "region growing tests candidates with the Taylor Proposition 1 of the loop without "
            f"reaction delay; expected --method projection with --reaction-delay, got --method "
            f"{args.method}")
    if general and args.method != "projection":
        raise StringStabError(
            "region growing tests candidates with the Taylor Proposition 1 of the continuous loop "
            f"at one tau, delta, headway; expected --method projection with "
            f"{'--sample-time' if H is not None else 'an interval'}, got --method {args.method}")
    lo, hi = _numbers(args.bounds, 2, "--bounds")
    from ..ranges import check_magnitude

    for v in (lo, hi):
        check_magnitude("gain", v, name="--bounds")
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
    from ..ranges import check_count
    from ._common import warn_beyond_sensible

    checked = [*(("weight", w, "--weights") for w in weights), ("gain", r0, "--r0"),
               ("margin", margin, "--hurwitz-margin"), ("margin", eps, "--eps")]
    for kind, v, option in checked:  # refused far beyond sense (the solvers would not return)
        check_magnitude(kind, v, name=option)
    for kind, n, option in (("grid", grid, "--grid"), ("iterations", max_iter, "--max-iter")):
        if n is not None:
            check_count(kind, n, name=option)
            checked.append((kind, n, option))
    warn_beyond_sensible(args, checked)
    import time

    from ._common import resolve_format

    t0 = time.perf_counter()
    args.format = resolve_format(args.format, args.out, _FORMATS)
    out = check_output_file(args.out, what="--out") if args.out else None
    report_dir = None
    if args.report:
        from ..io import OutputDir

        report_dir = OutputDir(args.report, command="tune", what="--report")  # checked first
    table = gains_from_args(args)
    check_horizon(H, table)

    from ..tuning import Projector, TuneResults, region_growing
    from ..tuning.result import TABLE_COLUMNS

    methods = ["region-growing", "projection"] if args.method == "both" else [args.method]
    projector = None
    if "projection" in methods:
        projector = Projector(tau=model.tau, delta=model.delta, headway=model.headway,
                              sample_time=H, weights=weights, bounds=(lo, hi),
                              hurwitz_margin=margin, eps=eps, cache_size=0,
                              reaction_delay=model.reaction_delay)
    results = []
    rows = []
    K = table.K
    for i in range(len(table)):
        for m in methods:
            if m == "region-growing":
                assert not isinstance(model, Box)
                r = region_growing(K[i], tau=model.tau, delta=model.delta,
                                   headway=model.headway, r0=r0,
                                   grid=grid or 2, bounds=(lo, hi), max_iter=max_iter,
                                   criterion=args.criterion, weights=weights,
                                   grow_ka=args.grow_ka, check_hurwitz=args.check_hurwitz)
            else:
                assert projector is not None
                r = projector(K[i], use_state=False)
            results.append(r)
            rows.append(i)
    meta = {k: np.asarray(getattr(table, k))[rows] for k in ("t", "vehicle")
            if getattr(table, k, None) is not None}
    repaired = TuneResults.collect(results, meta=meta, methods=methods)
    params: dict[str, Any] = {**shown_params(model, H), "method": args.method,
                              "bounds": [lo, hi], "weights": weights}
    if not general:
        del params["sample_time"]  # the continuous loop at one τ, δ, T*: no sample time
    if "region-growing" in methods:
        params.update(r0=r0, grid=grid, max_iter=max_iter, criterion=args.criterion,
                      check_hurwitz=args.check_hurwitz, grow_ka=args.grow_ka)
    if "projection" in methods:
        params.update(hurwitz_margin=margin, eps=eps)
    summary = repaired.summary()
    if args.format == "table":  # for people: units on the numbers
        shown = {k: _seconds(v) if k in ("tau", "delta", "headway", "sample_time",
                                         "reaction_delay") else v
                 for k, v in params.items()}
        text = format_results(repaired.columns(), "table", params=shown, table=TABLE_COLUMNS,
                              summary={m: _with_units(s) for m, s in summary.items()})
    elif args.format == "csv":
        text = format_results(repaired.columns(), "csv", params=params)
    else:
        text = format_results(repaired.columns(), "json", params=params, summary=summary)
    write_text(text, out if out is not None else sys.stdout, what="--out")
    if report_dir is not None:
        _write_report(report_dir, results, params, general or bool(theta), t0, args)
    n_cert = int(repaired.certified.sum())
    if out is not None:
        print(f"stringstab tune: {n_cert} of {len(repaired)} outputs certified; "
              f"wrote {args.format} to {out}", file=sys.stderr)
    return 0 if n_cert == len(repaired) else 1


def _write_report(out: Any, results: list[Any], params: dict[str, Any], general: bool,
                  t0: float, args: argparse.Namespace) -> None:
    """``--report DIR``: the moves figure (continuous loop at one τ, δ, T*) and the report."""
    from ..report import command_line
    from ..report.commands import tune_report

    with out:
        figure = None
        if not general:
            from matplotlib.figure import Figure

            from ..plots.tuning import moves_projection, plot_moves

            fig = Figure(figsize=(6.4, 6.4), layout="constrained")
            background = moves_projection(results, tau=params["tau"], delta=params["delta"],
                                          headway=params["headway"],
                                          bounds=tuple(params["bounds"]), n=81)
            plot_moves(results, background, ax=fig.subplots())
            fig.savefig(out.path("tune_moves.png"), dpi=110, bbox_inches="tight")
            figure = "tune_moves.png"
        tune_report(results, command=command_line(args), params=params, figure=figure,
                    started=t0).write(out)


def _seconds(v: Any) -> str:
    """A parameter in seconds for the table: ``0.1 s``, ``0.1:0.2 s``, or ``-`` (none)."""
    if v is None:
        return "-"
    return f"{v[0]:g}:{v[1]:g} s" if isinstance(v, list) else f"{v:g} s"


def _with_units(s: dict[str, Any]) -> dict[str, Any]:
    """A method's summary for the table: the median distance moved with its unit."""
    out = dict(s)
    d = out.pop("median_distance_moved", None)
    if d is not None:
        out["median distance moved"] = f"{d:.4g} (weighted gain units)"
    return out
