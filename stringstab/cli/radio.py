"""``stringstab radio``: loss and noise, measured — Monte-Carlo amplification of a platoon with its radio.

A command of its own rather than a ``simulate`` option: ``simulate`` writes one run (its
trajectories, metrics and figures), this writes a study over a grid of loss rates × burst
lengths × seeds (a table with confidence intervals, figures over the loss rate, the
certificates beside them), in a folder of its own kind.

Refused before anything is simulated or written (exit 2, one line): a loss rate outside [0, 1],
a burst below 1 or too short for a loss rate, a message period that is not a whole multiple of
``--dt``, σ < 0, NaN, fewer than two seeds, an output folder that cannot be written or holds
another command's outputs.  Exit status 0; 1 when some replicate collided (outputs written).
"""

from __future__ import annotations

import argparse
import copy
import itertools
import math
import sys
from typing import Any

import numpy as np

from ..errors import StringStabError, show
from ._common import (
    add_limit_arguments,
    add_vehicle_arguments,
    checked_leaders,
    integer,
    limits_from_args,
    warn_beyond_sensible,
)
from ._loop import add_loop_arguments, radio_from_args, reaction_from_args

__all__ = ["DEFAULT_TRIPLES", "FILES", "MAX_VEHICLES", "add_parser", "float_or", "run", "summary_lines"]

#: The demo's certified gains and cavsandbox 0.11's CACC (issue 26).
DEFAULT_TRIPLES = ("1.2,0.5,0.6", "0.45,0.25,0.9")
#: Largest batch (followers × seeds) one point may run: a guard against a mistyped size.
MAX_VEHICLES = 100_000
#: Every file the command writes.
FILES = ("table.csv", "table.md", "study.json", "amplification.png", "links.png", "report.md",
         "report.html")


def add_parser(sub: Any) -> None:
    """Register ``radio``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    p = sub.add_parser(
        "radio",
        help="measure a platoon's amplification with V2V message loss and noise (Monte Carlo)",
        description=(
            "Run platoons with their V2V radio over loss rates x burst lengths x seeds and write "
            "the measured amplification (max m_p along the string, IDL eq 29) and the empirical "
            "l2 gains (last over first follower, last over leader) with Student-t confidence "
            "intervals over the seeds, beside the certificates of the loop without loss "
            "(continuous; sampled at --dt, messages every step). Random loss, the fallback "
            "switching and sensor noise are covered by no certificate."),
    )
    p.add_argument("--gains", action="append", metavar="K_X,K_V,K_A",
                   help="a gain triple (repeat for several; default "
                        f"{' and '.join(DEFAULT_TRIPLES)}: the demo's certified gains and "
                        "cavsandbox's CACC)")
    p.add_argument("--leader", default="mix", metavar="SPEC",
                   help="leader, as for simulate (default: mix, the §5.1 leader)")
    p.add_argument("--followers", type=int, default=10, metavar="N", help="followers (default 10)")
    add_vehicle_arguments(p)
    p.add_argument("--dt", type=float, default=0.01, metavar="H",
                   help="control step H, s (default 0.01; the sampled certificate is at H)")
    p.add_argument("--duration", type=float, default=None, help="keep only the first seconds of the leader")
    p.add_argument("--hold", type=float, default=60.0, metavar="SECONDS",
                   help="then let the leader hold its final speed this long (default 60)")
    g = p.add_argument_group("the study")
    g.add_argument("--loss", default="0,0.01,0.02,0.05,0.1,0.2,0.3", metavar="RATES",
                   help="comma-separated increasing loss rates in [0, 1] (default "
                        "0,0.01,0.02,0.05,0.1,0.2,0.3)")
    g.add_argument("--burst", default="1,5", metavar="LENGTHS",
                   help="comma-separated increasing mean burst lengths in messages, >= 1; 1 means "
                        "independent (Bernoulli) losses, more Gilbert-Elliott bursts (default 1,5)")
    g.add_argument("--seeds", default="20", metavar="S",
                   help="replicates per point, >= 2: one batch of S platoons (default 20)")
    p.add_argument("--no-figures", action="store_true", help="skip the figures")
    p.add_argument("--no-progress", action="store_true", help="no progress bar or lines (stderr)")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="output folder (an earlier radio study in it is replaced)")
    add_limit_arguments(p)
    add_loop_arguments(p, loss=False,
                       message_period_note="(default 0.1: 10 Hz, as ETSI CAM / SAE BSM)")
    p.set_defaults(func=run, message_period="0.1")


def _list(option: str, text: str) -> list[str]:
    items = [t.strip() for t in str(text).split(",")]
    if not items or any(not t for t in items):
        raise StringStabError(f"{option} must be comma-separated numbers; got {show(text)}")
    return items


def _point(args: argparse.Namespace, loss: str, burst: str | None, dt: float) -> tuple[Any, Any]:
    """The Radio and SensorNoise of one point, checked by the loop flags' own checks."""
    ns = copy.copy(args)
    ns.loss, ns.burst = loss, burst
    return radio_from_args(ns, dt)


def _increasing(option: str, items: list[str]) -> None:
    x = [float(t) for t in items]
    if any(b <= a for a, b in itertools.pairwise(x)):
        raise StringStabError(f"{option} must be strictly increasing; got {','.join(items)}")


def run(args: argparse.Namespace) -> int:
    """Run ``radio``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab radio``.

    Returns
    -------
    int
        0 when the study was written without collision, 1 when some replicate collided
        (outputs written); bad input raises :class:`~stringstab.errors.StringStabError`
        (exit 2 from :func:`stringstab.cli.main`).
    """
    import time

    from ..io import OutputDir
    from ..params import check_params
    from ..progress import Progress
    from ..traffic.leaders import leader_by_name
    from ..traffic.radio_study import run_radio_study
    from .simulate import check_step, parse_gains

    t0 = time.perf_counter()
    tau, delta, headway = check_params(args.tau, args.delta, args.headway)
    triples = [parse_gains(t) for t in (args.gains or DEFAULT_TRIPLES)]
    if args.followers < 2:
        raise StringStabError(f"--followers must be an integer >= 2 (an l2 gain from the first "
                              f"follower to the last); got {args.followers}")
    for name in ("dt", "standstill", "length"):
        v = getattr(args, name)
        if not (math.isfinite(v) and (v > 0 or (name == "standstill" and v == 0))):
            raise StringStabError(f"--{name} must be a finite number > 0; got {show(v)}")
    if not (math.isfinite(args.hold) and args.hold >= 0):
        raise StringStabError(f"--hold must be a finite number of seconds >= 0; got {show(args.hold)}")
    from ..ranges import check_magnitude

    sizes = [("step", args.dt, "--dt"), ("length", args.standstill, "--standstill"),
             ("length", args.length, "--length")]
    for kind, v, opt in sizes:  # as simulate
        check_magnitude(kind, v, name=opt)
    check_step(args.dt, tau, delta)
    for opt, v in (("--duration", args.duration), ("--hold", args.hold)):
        if v is not None and math.isfinite(v):
            check_magnitude("duration", v, name=opt)
    seeds = integer("--seeds", args.seeds, 2)
    losses, bursts = _list("--loss", args.loss), _list("--burst", args.burst)
    theta = reaction_from_args(args)
    # every point through the loop flags' checks: one line naming the option, exit 2
    for b in bursts:
        for p in losses:
            _point(args, p, None if float_or(b) == 1 else b, args.dt)
    _increasing("--loss", losses)
    _increasing("--burst", bursts)
    any_radio, sensors = _point(args, losses[0], None, args.dt)
    out = OutputDir(args.out, command="radio", owns=FILES, what="--out")
    leader = leader_by_name(args.leader, dt=args.dt, duration=args.duration).hold(args.hold)
    limits = limits_from_args(args)
    if args.followers * seeds > MAX_VEHICLES:
        raise StringStabError(f"--followers {args.followers} x --seeds {seeds} = "
                              f"{args.followers * seeds} vehicles per batch; expected at most "
                              f"{MAX_VEHICLES} (each point is one batch of --seeds platoons)")
    from ..memory import refuse_platoon

    refuse_platoon(args.followers * seeds, len(leader.speed),
                   f"--followers {args.followers} x --seeds {seeds}")
    from ..traffic.controllers import LinearController
    from ..traffic.limits import settling_time

    settle = [settling_time(LinearController(*K, headway=headway, standstill=args.standstill), tau)
              for K in triples]  # the slowest triple's, as simulate's one controller
    known = [x for x in settle if x is not None]
    checked_leaders(args, [leader], limits, settling=max(known) if known else None)
    warn_beyond_sensible(args, [("followers", args.followers, "--followers"), *sizes])
    total = len(triples) * len(bursts) * len(losses) * seeds
    seed = any_radio.seed
    with Progress(total, "stringstab radio", unit="platoon-runs", enabled=not args.no_progress) as bar:
        study = run_radio_study(
            triples, leader, n_followers=args.followers, tau=tau, delta=delta, headway=headway,
            standstill=args.standstill, length=args.length,
            message_period=any_radio.message_period or args.dt,
            message_phase=int(np.asarray(any_radio.message_phase)),
            losses=[float(x) for x in losses], bursts=[float(x) for x in bursts], seeds=seeds,
            seed=seed, stale_after=any_radio.stale_after, fallback_gains=any_radio.fallback_gains,
            sensors=sensors, limits=limits, reaction_delay=theta, progress=bar.update)
    from ..report import command_line
    from ..report.radio import radio_report, write_study

    with out:
        files = write_study(study, out, figures=not args.no_figures)
        files += radio_report(study, files, command=command_line(args), started=t0).write(out)
    for line in summary_lines(study):
        print(line)
    print(f"wrote {', '.join(files)} to {out.root}/")
    n_coll = int(study.collisions.sum())
    if n_coll:
        print(f"stringstab radio: warning: {n_coll} collision event(s) among the replicates "
              "(the table's collisions column); exit status 1", file=sys.stderr)
        return 1
    return 0


def float_or(text: str) -> float:
    """``float(text)``, or NaN when it is not a number (the loop checks then say why).

    Parameters
    ----------
    text : str
        A list item of ``--burst``.

    Returns
    -------
    float
        Its value or NaN.
    """
    try:
        return float(text)
    except ValueError:
        return math.nan


def summary_lines(study: Any) -> list[str]:
    """What the command prints: per triple, its certificates and where amplification exceeds 1.

    Parameters
    ----------
    study : RadioStudy
        The study.

    Returns
    -------
    list of str
        Lines to print.
    """
    s = study.settings
    lines = [f"radio study: {s['leader']} ({s['duration']:g} s, H = {s['dt']:g} s), "
             f"{s['followers']} followers, messages every {s['message_period']:g} s, "
             f"{study.seeds} seeds per point ({s['interval']})"]
    amp = study.summary()
    for g, k in enumerate(study.gains):
        c = study.certificates[g]
        samp = "n/a" if c["sampled"] is None else f"{c['sampled']['verdict']} (sup {c['sampled']['sup_gain']:.4g})"
        lines.append(f"K = ({k[0]:g}, {k[1]:g}, {k[2]:g}): continuous {c['continuous']['verdict']} "
                     f"(sup {c['continuous']['sup_gain']:.4g}), sampled at H {samp}; "
                     "multi-rate certificate: not on this branch")
        for b, burst in enumerate(study.bursts):
            e = study.exceedance(g, b)
            kind = "independent" if burst == 1 else f"bursts of {burst:g}"
            a0 = amp[g, b, 0]
            where = ("never on the grid" if e["loss"] is None else f"at p = {e['loss']:.3g}"
                     f" (interval {_p(e['loss_lo'])} to {_p(e['loss_hi'])})")
            lines.append(f"  {kind}: max m_p {a0[0]:.4f} [{a0[1]:.4f}, {a0[2]:.4f}] at p = "
                         f"{study.losses[0]:g}, {amp[g, b, -1, 0]:.4f} [{amp[g, b, -1, 1]:.4f}, "
                         f"{amp[g, b, -1, 2]:.4f}] at p = {study.losses[-1]:g}; exceeds 1 {where}")
    return lines


def _p(x: float | None) -> str:
    return "beyond the grid" if x is None else f"{x:.3g}"
