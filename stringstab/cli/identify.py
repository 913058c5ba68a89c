"""``stringstab identify``: fit the eq-4 law to each follower of a recorded platoon and certify it.

Reads one or more logs (OpenACC, plain CSV or NGSIM: :func:`stringstab.io.platoon_logs.
read_platoon_logs`), identifies every follower (:func:`stringstab.identify.identify`: closed-loop
simulation-error fit, certificate, moving-block bootstrap, the data's own transfer), prints the
table and writes ``identify.json``, ``identify.csv``, ``identify.parquet`` and figures into
``--out`` (:mod:`stringstab.identify.report`); with ``--by car`` one row per car and setting,
every log of it pooled (:func:`stringstab.identify.cars.identify_cars`), in ``cars.json``,
``cars.csv``, ``cars.parquet``.  Exit 0 when it ran (whatever the verdicts), 2 on bad input
(one line; nothing written).
"""

from __future__ import annotations

import argparse
import math
import sys
from typing import Any

from ..errors import StringStabError, show
from ._common import integer, warn_beyond_sensible

__all__ = ["add_parser", "run"]

_EPILOG = """\
examples:
  stringstab identify --example acc --out runs/acc                    # a shipped OpenACC log
  stringstab identify stringstab/data/openacc/zalazone_human_handling_part22.csv.gz --out runs/human
  stringstab identify platoon.csv --model cacc --bootstrap 200 --out runs/cacc
  stringstab identify log.csv --sample-time 0.1 --out runs/sampled   # certify the 10 Hz loop
  stringstab identify day1.csv day2.csv day3.csv --by car --out runs/cars   # one row per car
  stringstab certify --from runs/acc/identify.json                    # re-certify the fits
  stringstab simulate --from runs/acc/identify.json --vehicle 2 --followers 10 --out runs/sim

log formats: OpenACC (metadata lines, Time, Speedk, Ek, Nk, ..., IVSk); CSV with columns
t,v_lead,v,gap (one follower), t,v0,v1,gap1,v2,gap2,... (a platoon) or a long table
vehicle,t,v,gap (platoon order, leader first); optional a columns (needed by --model cacc);
units SI unless the header says '[km/h]'; an NGSIM US-101/I-80 trajectory file (its
leader-follower pairs); any of them gzip-compressed (.csv.gz). A single missing sample is
bridged (the mean of its neighbours); longer gaps split the record; stretches where a car does
not follow its predecessor (standstill, a gap jump, no target in range, moving away from its
predecessor's speed) are excluded and named. --example acc|human: the two OpenACC logs shipped in
stringstab/data/openacc/ (JRC, CC BY 4.0; cite Makridis et al. 2021, see the README there).

See docs/identify.md.
"""


def add_parser(sub: Any) -> None:
    """Register ``identify``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    p = sub.add_parser(
        "identify",
        help="identify and certify the car-following law of recorded vehicles (OpenACC, CSV, NGSIM)",
        description=(
            "For each follower of a recorded platoon (or, with --by car, each car and distance "
            "setting over all its logs), fit u = k_x Δp + k_v Δv [+ k_a a_{i-1}(t-δ)], the actuator "
            "lag τ, the reaction delay θ_r, T*, l0 by closed-loop simulation error (driven by the "
            "measured predecessor; T* held to the spacing policy of the steady parts where they "
            "identify it), certify the fit (exact delay), bootstrap it (moving blocks over time, "
            "two starts per refit), and set the model's |Γ(jω)| beside the measured speed transfer "
            "and amplification."
        ),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("log", metavar="LOG", nargs="*",
                   help="the recorded platoon(s) (OpenACC, CSV or NGSIM files, plain or .gz)")
    p.add_argument("--example", choices=("acc", "human"),
                   help="instead of LOG, a shipped OpenACC log: acc (6 cars on factory ACC) or "
                        "human (11 cars driven by people)")
    p.add_argument("--model", choices=("acc", "cacc"), default="acc",
                   help="acc: k_a = 0 (default); cacc: also k_a and δ (needs the predecessor's acceleration)")
    p.add_argument("--sample-time", metavar="H",
                   help="certify the sampled-data loop (period H s, zero-order hold); default continuous")
    p.add_argument("--bootstrap", default="50", metavar="N",
                   help="moving-block bootstrap refits per follower (default 50; 0: none)")
    p.add_argument("--block", default="20", metavar="S", help="bootstrap block length, s (default 20)")
    p.add_argument("--starts", default="4", metavar="N", help="starting points of each fit (default 4)")
    p.add_argument("--seed", default="0", metavar="N", help="random seed (default 0)")
    p.add_argument("--min-segment", default="30", metavar="S",
                   help="shortest clean segment used, s (default 30)")
    p.add_argument("--by", choices=("log", "car"), default="log",
                   help="log: one row per follower of each log (default); car: one row per car and "
                        "distance setting, all its logs fitted jointly (cars.json)")
    p.add_argument("--fit-delay", action=argparse.BooleanOptionalAction, default=None,
                   help="fit the reaction delay θ_r on the whole law beside the lag τ and certify "
                        "with it (default: on; with --sample-time the sampled certificate with θ_r, "
                        "slower at small H)")
    p.add_argument("--baselines", action="store_true",
                   help="also calibrate IDM and OVRV on the same segments and judge their "
                        "linearisations (slower: the IDM is simulated step by step)")
    p.add_argument("--no-screen", action="store_true",
                   help="keep the stretches where a car does not follow its predecessor")
    p.add_argument("--no-figures", action="store_true", help="skip the figures")
    p.add_argument("--no-progress", action="store_true", help="no progress lines on stderr")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="output folder (an earlier identify run's files in it are replaced)")
    p.set_defaults(func=run)


def _seconds(name: str, text: str) -> float:
    try:
        v = float(text)
    except ValueError as e:
        raise StringStabError(f"{name} must be a number of seconds > 0; got {show(text)}") from e
    if not (math.isfinite(v) and v > 0):
        raise StringStabError(f"{name} must be a number of seconds > 0; got {show(text)}")
    return v


def run(args: argparse.Namespace) -> int:
    """Run ``identify``; 0 when it ran, bad input raises (exit 2).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab identify``.

    Returns
    -------
    int
        Exit code: 0 when it ran (whatever the verdicts); bad input raises
        :class:`~stringstab.errors.StringStabError` (exit 2 from
        :func:`stringstab.cli.main`).
    """
    import time

    from ..identify.logs import read_logs
    from ..io import OutputDir

    t0 = time.perf_counter()
    H = None if args.sample_time is None else _seconds("--sample-time", args.sample_time)
    B = integer("--bootstrap", args.bootstrap, 0, "refits")
    block = _seconds("--block", args.block)
    starts = integer("--starts", args.starts, 1, "starts")
    seed = integer("--seed", args.seed, 0, "seed")
    min_seg = _seconds("--min-segment", args.min_segment)
    from ..ranges import check_magnitude

    for kind, v, option in (("sample_time", H, "--sample-time"), ("duration", block, "--block"),
                            ("duration", min_seg, "--min-segment")):
        if v is not None:
            check_magnitude(kind, v, name=option)
    if (not args.log) == (args.example is None):
        raise StringStabError("expected a log file LOG or --example acc|human (one of the two); "
                              f"got {'both' if args.log else 'neither'}")
    out = OutputDir(args.out, command="identify", what="--out")
    from ..identify.logs import example_log

    logs = [lg for path in (args.log or [example_log(args.example)])
            for lg in read_logs(path, min_duration=min_seg)]
    warn_beyond_sensible(args, [("sample_time", H, "--sample-time"), ("refits", B, "--bootstrap"),
                                ("starts", starts, "--starts")])
    # θ_r fitted by default, with a sample time too (the sampled certificate with θ_r, issue 25)
    fit_delay = True if args.fit_delay is None else bool(args.fit_delay)
    opts = dict(sample_time=H, bootstrap=B, block=block, n_starts=starts, seed=seed, min_duration=min_seg,
                progress=not args.no_progress, baselines=args.baselines, screen=not args.no_screen,
                fit_delay=fit_delay)
    from ..report import command_line

    if args.by == "car":
        from ..identify.cars import identify_cars
        from ..identify.report import render_cars, write_cars_outputs
        from ..report.commands import cars_report

        cars = identify_cars(logs, args.model, **opts)
        with out:
            names = list(write_cars_outputs(cars, out, figures=not args.no_figures))
            names += cars_report(cars, names, command=command_line(args), started=t0).write(out)
        sys.stdout.write(render_cars(cars))
        print(f"wrote {len(names)} files to {out.root}/ (cars.json, cars.csv, cars.parquet"
              + (", figures" if not args.no_figures else "") + ", report.md, report.html)")
        return 0
    from ..identify import identify
    from ..identify.report import render, write_outputs

    res = identify(logs, args.model, **opts)
    with out:
        names = list(write_outputs(res, out, figures=not args.no_figures))
        from ..report.commands import identify_report

        names += identify_report(res, names, command=command_line(args), started=t0).write(out)
    sys.stdout.write(render(res))
    print(f"wrote {len(names)} files to {out.root}/ (identify.json, identify.csv, identify.parquet"
          + (", figures" if not args.no_figures else "") + ", report.md, report.html)")
    return 0
