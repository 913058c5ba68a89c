"""``stringstab region``: maps of where the gains K = [k_x, k_v, k_a] are string stable.

Parses the grid, calls :func:`stringstab.regions.region_map`, saves the data
(:meth:`~stringstab.regions.RegionMap.save_npz`, and ``save_csv`` for a 2-D
slice of at most :data:`stringstab.plots.outputs.CSV_MAX_POINTS` points unless ``--csv``)
and the figures (:func:`stringstab.plots.save_figures`), and prints the
class shares per method and the disagreements.  Bad input: a one-line error,
exit code 2 and nothing written.
"""

from __future__ import annotations

import argparse
import contextlib
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ..constants import GAIN_BOUNDS
from ..errors import StringStabError
from ..params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU, Box
from ..regions import CONTINUOUS, GAIN_NAMES
from ._common import add_model_arguments, loop_params
from ._message import add_message_arguments, message_from_args

__all__ = ["add_parser", "run"]

DEFAULT_RANGE = GAIN_BOUNDS
DEFAULT_N_2D = 201
DEFAULT_N_3D = 61
#: ``--figures``: as :data:`stringstab.plots.outputs.FIGURE_SETS` (not imported: the parser
#: stays free of the plotting code; a test compares the two).
FIGURE_SETS = ("default", "all")
#: The CSV size rule in the help: :data:`stringstab.plots.outputs.CSV_MAX_POINTS` (not imported:
#: as FIGURE_SETS; a test compares the two).
CSV_MAX_POINTS = 300_000

_EPILOG = f"""\
examples:
  stringstab region --x k_x --y k_v --fix k_a=0.5 --range -2,2 --n 401 --out maps/
  stringstab region --x k_x --y k_a --fix k_v=0.5 --method exact,printed --tau 0.2
  stringstab region --3d --n 81 --method exact --out maps3d/
  stringstab region --fix k_a=0.3 --range k_x=0,1.5 --range k_v=-1,1 --overlay rollout.csv
  stringstab region --fix k_a=0.5 --sample-time 0.1 --compare continuous --out maps_dt01/
  stringstab region --fix k_a=0.5 --tau 0.1:0.3 --delta 0.1:0.3 --n 101 --out maps_box/
  stringstab region --fix k_a=0.5 --sample-time 0.01 --message-period 0.2 --compare continuous
  stringstab region --3d --n 81 --method exact --scheduler tcp://head:8786 --out maps3d/
  stringstab region --fix k_a=0.5 --reaction-delay 0.2 --out maps_r02/
  stringstab region --fix k_a=0.5 --reaction-delay 0:0.3:4 --n 101 --out maps_r/
  stringstab region --fix k_a=0.5 --reaction-delay 0.2 --sample-time 0.1 --n 41 --out maps_rH/

outputs in --out: <prefix>.npz (all per-point fields, parameters and tool version
in 'metadata'), <prefix>.csv (2-D only; by default only for a map of at most
{CSV_MAX_POINTS:,} points, e.g. --n 547: --csv writes it whatever the size, --no-csv
never; the NPZ holds the same columns), and per --format: <prefix>_class_<method>
(the first method's; every method's with --figures all), <prefix>_compare,
<prefix>_sup_gain, <prefix>_overlay (2-D) or <prefix>_slices_<method>,
<prefix>_3d_<method> (3-D); report.md and report.html.
classes: exact = not internally stable / not certified / inconclusive / certified;
taylor, printed = not internally stable / type III / type IV / type I / type II.
with --sample-time or a LO:HI interval, exact is the sampled or robust certificate (the
only method; the Taylor criteria are of the continuous loop at one tau, delta, headway);
--compare continuous adds the continuous certificate and the band where they differ.
with --reaction-delay S > 0, exact is the certificate with the reaction delay (the only
method; sampled with --sample-time, where --compare continuous adds the continuous
certificate with the same θ_r); a list A,B,... or a range LO:HI:N maps each θ_r (files <prefix>_theta_r_<θ_r>.*)
and writes the certified share vs θ_r: <prefix>_share_vs_theta_r.csv and its figure.
defaults: range {DEFAULT_RANGE[0]:g},{DEFAULT_RANGE[1]:g}, n {DEFAULT_N_2D} (2-D) or {DEFAULT_N_3D} (3-D),
tau={DEFAULT_TAU} s, delta={DEFAULT_DELTA} s, headway={DEFAULT_HEADWAY} s. See docs/regions.md.
"""



def add_parser(sub: Any) -> None:
    """Register ``region``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    p = sub.add_parser(
        "region",
        help="map the string-stable gains on a 2-D slice or a 3-D grid (figures + data)",
        description=(
            "Evaluate a grid of gain triples K = [k_x, k_v, k_a] with the exact certificate and "
            "the Taylor Proposition 1 (derived and printed Ψ), and write class maps, a map of "
            "where the methods disagree, a heat map of sup|Γ(jω)|, and the data."
        ),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--x", default="k_x", metavar="GAIN", help="gain on the first axis (default k_x)")
    p.add_argument("--y", default="k_v", metavar="GAIN", help="gain on the second axis (default k_v)")
    p.add_argument("--fix", metavar="GAIN=V",
                   help="value of the third gain for a 2-D slice, e.g. k_a=0.5 (required without --3d)")
    p.add_argument("--3d", dest="three_d", action="store_true",
                   help="map the volume over all three gains (axes --x, --y, then the third)")
    p.add_argument("--range", action="append", metavar="[GAIN=]LO,HI",
                   help="grid range of every axis, or of one gain (repeatable); default -2,2")
    p.add_argument("--n", metavar="N[,N2[,N3]]",
                   help=f"grid points per axis, >= 2 (default {DEFAULT_N_2D}; {DEFAULT_N_3D} with --3d)")
    add_model_arguments(p)
    add_message_arguments(p)
    # -- the reaction delay θ_r (issue 25 part 2): one value, or a list/range as a map axis
    p.add_argument("--reaction-delay", metavar="S|A,B,...|LO:HI:N",
                   help="reaction (actuation) delay θ_r in s, >= 0, on the whole command "
                        "(τ a' = u(t − θ_r) − a), in continuous time or with --sample-time "
                        "(default: 0); a list A,B,... or a range LO:HI:N maps each θ_r and the "
                        "certified share vs θ_r")
    p.add_argument("--method", metavar="M[,M...]",
                   help="methods among exact, taylor, printed (default: all three; exact alone "
                        "with --sample-time or an interval)")
    p.add_argument("--compare", choices=(CONTINUOUS,),
                   help="with --sample-time: also map the continuous-time certificate and draw the "
                        "band certified in continuous time but not when sampled")
    p.add_argument("--overlay", metavar="FILE",
                   help="gain trajectory (.csv/.json/.npz as for certify) drawn on the 2-D map")
    p.add_argument("--out", "-o", default="maps", metavar="DIR", help="output directory (default: maps)")
    p.add_argument("--prefix", default="region", metavar="NAME", help="file name stem (default: region)")
    p.add_argument("--format", default="png", metavar="F[,F...]",
                   help="figure formats among png, pdf, svg (default: png; e.g. png,pdf for "
                        "print-ready copies too)")
    p.add_argument("--figures", choices=FIGURE_SETS, default="default", metavar="default|all",
                   help="the class maps of a 2-D map with two or more methods: the first "
                        "method's beside the comparison and sup|Γ| maps (default), or every "
                        "method's (all); the data files hold every method's either way")
    csv = p.add_mutually_exclusive_group()
    csv.add_argument("--csv", dest="csv", action="store_const", const=True, default=None,
                     help=f"write the CSV table of a 2-D map (PREFIX.csv) whatever the map's "
                          f"size (default: only for at most {CSV_MAX_POINTS:,} points; the NPZ "
                          f"holds the same columns)")
    csv.add_argument("--no-csv", dest="csv", action="store_const", const=False,
                     help="never write the CSV table (PREFIX.csv)")
    p.add_argument("--dpi", default="150", metavar="N", help="resolution of PNG figures (default: 150)")
    p.add_argument("--workers", metavar="N", help="worker processes (default: all cores for long maps)")
    p.add_argument("--scheduler", metavar="ADDRESS|local",
                   help="evaluate the grid's chunks as Dask tasks: on the scheduler at ADDRESS "
                        "(tcp://HOST:8786), or 'local' for a local cluster of --workers processes "
                        "on 127.0.0.1 (the dask extra); same outputs bit for bit")
    p.add_argument("--no-progress", action="store_true", help="never show the progress bar")
    p.set_defaults(func=run)


# --------------------------------------------------------------------------- parsing
def _number(text: str, what: str) -> float:
    try:
        v = float(text)
    except ValueError as e:
        raise StringStabError(f"{what} must be a number; got {text!r}") from e
    if not math.isfinite(v):
        raise StringStabError(f"{what} must be finite; got {text!r}")
    return v


def _int(text: str, what: str, low: int) -> int:
    try:
        v = int(text)
    except ValueError as e:
        raise StringStabError(f"{what} must be an integer >= {low}; got {text!r}") from e
    if v < low:
        raise StringStabError(f"{what} must be an integer >= {low}; got {text!r}")
    return v


def _gain(text: str, what: str) -> str:
    if text not in GAIN_NAMES:
        raise StringStabError(f"{what} must be one of {', '.join(GAIN_NAMES)}; got {text!r}")
    return text


def _pair(text: str, what: str) -> tuple[float, float]:
    parts = text.split(",")
    if len(parts) != 2:
        raise StringStabError(f"{what} must be LO,HI (two numbers); got {text!r}")
    lo, hi = (_number(s.strip(), what) for s in parts)
    from ..ranges import check_magnitude

    for v in (lo, hi):  # gains: refused far beyond physical sense (the maps would overflow)
        check_magnitude("gain", v, name=what)
    if not lo < hi:
        raise StringStabError(f"{what} must have LO < HI; got {text!r}")
    return lo, hi


def _ranges(items: list[str] | None, names: list[str]) -> dict[str, tuple[float, float]]:
    """Ranges per axis gain: ``LO,HI`` items apply to all axes, ``GAIN=LO,HI`` items override."""
    items = items or []
    out = dict.fromkeys(names, DEFAULT_RANGE)
    for item in items:
        if "=" not in item:
            out = dict.fromkeys(names, _pair(item, "--range"))
    for item in items:
        if "=" in item:
            g, _, rest = item.partition("=")
            g = _gain(g.strip(), f"--range {item!r}: the gain")
            if g not in names:
                raise StringStabError(f"--range {item!r}: {g} is not on an axis (axes: {', '.join(names)})")
            out[g] = _pair(rest, f"--range {g}")
    return out


def _sizes(text: str | None, k: int, default: int) -> list[int]:
    if text is None:
        return [default] * k
    parts = text.split(",")
    if len(parts) not in (1, k):
        raise StringStabError(f"--n must be N or {k} comma-separated counts; got {text!r}")
    ns = [_int(s.strip(), "--n", 2) for s in parts]
    return ns * k if len(ns) == 1 else ns


def _check_size(sizes: list[int], args: argparse.Namespace) -> None:
    """Refuse a grid whose estimated memory exceeds what is available, before allocating it."""
    from ..memory import available_bytes, grid_bytes, grid_fit, refuse_if_too_big

    points = float(np.prod(np.asarray(sizes, dtype=float)))
    cap = available_bytes()
    refuse_if_too_big(
        f"--n {args.n}{' --3d' if args.three_d else ''} ({' x '.join(map(str, sizes))} = {points:.4g} "
        "points)", grid_bytes(points),
        f"expected at most about --n {grid_fit(cap, len(sizes))} on this machine", limit=cap)


def _grid(args: argparse.Namespace) -> tuple[dict[str, np.ndarray], dict[str, float]]:
    x = _gain(args.x, "--x")
    y = _gain(args.y, "--y")
    if x == y:
        raise StringStabError(f"--x and --y must be different gains; got {x} twice")
    third = next(g for g in GAIN_NAMES if g not in (x, y))
    fixed: dict[str, float] = {}
    if args.three_d:
        if args.fix is not None:
            raise StringStabError(f"--3d maps all three gains; got --fix {args.fix}")
        names = [x, y, third]
    else:
        if args.fix is None:
            raise StringStabError(f"expected --fix {third}=VALUE (the gain not on --x/--y) or --3d; got neither")
        g, sep, v = args.fix.partition("=")
        if not sep:
            raise StringStabError(f"--fix must be GAIN=VALUE, e.g. {third}=0.5; got {args.fix!r}")
        g = _gain(g.strip(), "--fix gain")
        if g != third:
            raise StringStabError(f"--fix must fix {third} (the gain not on --x/--y); got {g}")
        fixed = {g: _number(v.strip(), f"--fix {g}")}
        from ..ranges import check_magnitude

        check_magnitude("gain", fixed[g], name=f"--fix {g}")
        names = [x, y]
    ranges = _ranges(args.range, names)
    sizes = _sizes(args.n, len(names), DEFAULT_N_3D if args.three_d else DEFAULT_N_2D)
    _check_size(sizes, args)
    axes = {g: np.linspace(*ranges[g], n) for g, n in zip(names, sizes)}
    return axes, fixed


@contextlib.contextmanager
def _executor(scheduler: str | None, workers: int | None) -> Iterator[tuple[Any, int | None]]:
    """(executor, its workers) of ``--scheduler``, or (None, None): the local process pool."""
    if scheduler is None:
        yield None, None
        return
    from ..sweep import dask_client

    address = None if scheduler == "local" else scheduler
    with dask_client(address, workers) as client:
        n = len(client.scheduler_info().get("workers", {})) or 1
        yield client.get_executor(pure=False), n


def run(args: argparse.Namespace) -> int:
    """Run ``region``; returns 0, or raises StringStabError (exit 2) before writing anything.

    The output folder is checked before the map is computed and written all-or-nothing
    (:class:`stringstab.io.OutputDir`): the files of an earlier ``region`` run there are
    replaced, never mixed with the new ones.  The files are written by
    :func:`stringstab.plots.save_region_outputs` (two processes share the work).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab region``.

    Returns
    -------
    int
        Exit code: 0 when the map and its files were written; bad input raises
        :class:`~stringstab.errors.StringStabError` (exit 2 from
        :func:`stringstab.cli.main`).
    """
    import time

    from ..io import FIGURE_FORMATS, OutputDir
    from ..regions import region_map

    t0 = time.perf_counter()
    axes, fixed = _grid(args)
    # -- θ_r as a map axis (issue 25 part 2): a list or range; one value goes to loop_params
    from ..regions.reaction_sweep import parse_reaction_delays

    thetas = None if args.reaction_delay is None else parse_reaction_delays(args.reaction_delay)
    if thetas is not None:
        args.reaction_delay = None  # the axis: loop_params checks τ, δ, T* alone
    model, H = loop_params(args)
    N, _ = message_from_args(args, H)  # the multi-rate map (issue 26): exact is its certificate
    with_theta = thetas is not None or Box.of(model).reaction_delay != (0.0, 0.0)
    # θ_r > 0 with --sample-time (issue 25 item 3): exact is the sampled θ_r certificate
    # (certify.sampled_reaction); what no certificate answers (θ_r over a box with a sample
    # time, θ_r beyond the held steps the lifting takes, ...) is refused here, before any work
    if with_theta and H is not None:
        from ..certify.api import Loop
        from ..params import parameter_model

        Loop(model if thetas is None else parameter_model(
            model.tau, model.delta, model.headway, float(max(thetas))), H, message_steps=N)
    methods = args.method
    if args.compare is not None:
        if H is None:
            raise StringStabError(
                "--compare continuous draws the gains certified in continuous time but not when "
                "sampled; expected --sample-time H with it, got none")
        methods = f"{methods or 'exact'},{CONTINUOUS}"
    formats = [f.strip() for f in args.format.split(",")]
    for f in formats:
        if f not in FIGURE_FORMATS:
            raise StringStabError(f"--format must be among {', '.join(FIGURE_FORMATS)}; got {f!r}")
    from ..ranges import check_count

    dpi = check_count("dpi", _int(args.dpi, "--dpi", 10), name="--dpi")
    workers = None if args.workers is None else check_count(
        "workers", _int(args.workers, "--workers", 1), name="--workers")
    if not args.prefix or "/" in args.prefix or args.prefix.startswith("."):
        raise StringStabError(f"--prefix must be a plain file name stem; got {args.prefix!r}")
    gains = None
    if args.overlay is not None:
        if with_theta:
            raise StringStabError("--overlay draws on the map without a reaction delay so far; "
                                  f"expected no --overlay with --reaction-delay, got --overlay "
                                  f"{args.overlay}")
        if args.three_d:
            raise StringStabError("--overlay draws on a 2-D map; got --3d")
        from ..io.gains import read_gains

        gains = read_gains(args.overlay)
    if args.csv and args.three_d:
        raise StringStabError("--csv writes the table of a 2-D map; got --3d (the NPZ holds "
                              "the volume's fields)")
    if Path(args.out).is_file():
        raise StringStabError(f"--out {args.out}: expected a directory; found a file")
    out = OutputDir(args.out, command="region", what="--out")

    # the process that draws the figures starts first, while this process is single-threaded
    # (stringstab.parallel: no fork while a thread runs), and imports and warms up the
    # plotting code while the map is computed in the worker pool
    from ..plots import start_output_helper

    with start_output_helper(dpi) as helper:
        # region_map validates the methods before computing anything
        with _executor(args.scheduler, workers) as (executor, n_dask):
            if thetas is not None:  # -- one map per θ_r (issue 25 part 2)
                from ..regions.reaction_sweep import reaction_sweep

                sweep = reaction_sweep(axes, fixed or None, reaction_delays=thetas,
                                       tau=model.tau, delta=model.delta, headway=model.headway,
                                       sample_time=H, methods=methods,
                                       workers=n_dask or workers, executor=executor,
                                       progress=False if args.no_progress else None,
                                       message_period=None if N is None else args.message_period)
            else:
                rmap = region_map(axes, fixed or None, tau=model.tau, delta=model.delta,
                                  headway=model.headway, sample_time=H, methods=methods,
                                  workers=n_dask or workers, executor=executor,
                                  progress=False if args.no_progress else None,
                                  reaction_delay=model.reaction_delay,
                                  message_period=None if N is None else args.message_period)
        if thetas is not None:  # each map's figures in its own helper (save_region_outputs)
            return _write_sweep(sweep, out, args, formats, dpi, t0)
        written = _write(rmap, out, args, formats, gains, dpi, helper, t0)
    print(rmap.report())
    print(f"wrote {len(written)} files to {out.root}: " + ", ".join(p.name for p in written))
    _say_csv_skipped(rmap, args, f"{args.prefix}.csv", f"{args.prefix}.npz")
    return 0


def _say_csv_skipped(rmap: Any, args: argparse.Namespace, csv_name: str, npz_name: str) -> None:
    """One line when the size rule (:func:`stringstab.plots.writes_csv`) left the CSV out."""
    from ..plots import outputs

    if args.csv is None and rmap.ndim == 2 and not outputs.writes_csv(rmap):
        print(f"{csv_name} not written: {rmap.size:,} points > {outputs.CSV_MAX_POINTS:,} "
              f"(pass --csv; {npz_name} holds the same columns)")


def _write(rmap: Any, out: Any, args: argparse.Namespace, formats: list[str], gains: Any,
           dpi: int, helper: Any, t0: float) -> list[Path]:
    """The map's files (shared with ``helper``) and the report, all-or-nothing in ``out``."""
    from ..plots import save_region_outputs

    verdicts = None
    if gains is not None:  # compute, then draw: the overlay's own exact verdicts
        from ..plots import trajectory_verdicts

        verdicts = trajectory_verdicts(rmap, gains)
    from ..report import command_line
    from ..report.commands import region_report

    reports: list[Any] = []

    def prepare(files: list[Path]) -> None:
        # while the helper draws: the report built (its tables) and its renderer imported
        from ..report.render import warm_renderer

        warm_renderer()
        reports.append(region_report(rmap, files, command=command_line(args), started=t0))

    with out:
        written = save_region_outputs(rmap, out, prefix=args.prefix, formats=formats, gains=gains,
                                      verdicts=verdicts, dpi=dpi, helper=helper,
                                      figures=args.figures, csv=args.csv, meanwhile=prepare)
        # written after the figures: the HTML report embeds them (written while they were
        # drawn, it embedded empty images)
        reports[0].write(out)
    return written


def _write_sweep(sweep: Any, out: Any, args: argparse.Namespace, formats: list[str], dpi: int,
                 t0: float) -> int:
    """The files of a map per θ_r (issue 25 part 2): each map's, the share table and figure."""
    from ..plots.reaction_sweep import save_reaction_sweep_outputs
    from ..report import command_line
    from ..report.reaction_sweep import reaction_sweep_report

    with out:
        written = save_reaction_sweep_outputs(sweep, out, prefix=args.prefix, formats=formats,
                                              dpi=dpi, figures=args.figures, csv=args.csv)
        reaction_sweep_report(sweep, written, command=command_line(args), started=t0).write(out)
    print(sweep.report())
    print(f"wrote {len(written)} files to {out.root}: " + ", ".join(p.name for p in written))
    # every θ_r's map has the same grid, so the same rule
    _say_csv_skipped(sweep.maps[0], args, f"{args.prefix}_theta_r_*.csv",
                     f"each {args.prefix}_theta_r_*.npz")
    return 0
