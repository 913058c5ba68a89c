"""``stringstab simulate``: drive a platoon with a leader and write trajectories, metrics, figures.

Refused before anything is simulated or written (exit 2, one line): an output folder that
cannot be written or holds another command's outputs, a physically absurd leader (above 70 m/s
or beyond ±15 m/s²), a platoon that cannot fit in memory, and a step ``--dt`` longer than τ or
δ (the run would be a sampled-data system whose behaviour the continuous-time certificate and
M_fss do not describe).  A leader beyond the followers' limits (``--v-max``, ``--a-min``,
``--a-max``; IDL Table 2 by default) is simulated with a warning.  Exit status 0; 1 when a
follower collided (outputs written, a warning says who and when); 2 on bad input.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

import numpy as np

from ..constants import ACCEL_MAX, ACCEL_MIN, DT, SPEED_MAX, TTC_STAR
from ..errors import StringStabError, show
from ..params import check_params
from ..ranges import check_magnitude, metric_caveat
from ._common import (
    add_limit_arguments,
    add_vehicle_arguments,
    checked_leaders,
    integer,
    limits_from_args,
    warn_beyond_sensible,
)
from ._loop import add_loop_arguments, radio_from_args, reaction_from_args
from ._outcome import collision_status

__all__ = ["DEFAULT_GAINS", "add_parser", "check_step", "first_collision", "parse_gains", "radio_line",
           "run"]

#: A certified triple at the default τ, δ, T* (internally stable, sup_ω |Γ(jω)| = 1 at ω = 0).
DEFAULT_GAINS = "1.2,0.5,0.6"


def add_parser(sub: Any) -> None:
    """Register ``simulate``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    from ..traffic.cycles import CYCLES
    from ..traffic.synthetic import SYNTHETIC

    p = sub.add_parser(
        "simulate",
        help="simulate a platoon behind a leader; write trajectories, metrics JSON and figures",
        description=(
            "Simulate N followers (IDL third-order model, eqs 5-7, actuator lag tau, predecessor "
            f"acceleration received delta late, limits (default, IDL Table 2) [{ACCEL_MIN:g}, {ACCEL_MAX:g}] m/s^2 and "
            f"[0, {SPEED_MAX:g}] m/s) behind a "
            "leader, and write trajectories, the IDL metrics (m_p, M_lss, TIT, M_CI, M_effi, "
            "m_fss, collisions) and figures like the paper's Figs 7-8. A leader beyond the "
            "followers' limits (--v-max, --a-min, --a-max) runs with a warning; refused: a leader "
            "above 70 m/s or beyond ±15 m/s², --dt longer than tau or delta, an output folder "
            "that cannot be written."
        ),
        epilog=(
            f"Leaders: cycles {', '.join(sorted(CYCLES))}; synthetic {', '.join(SYNTHETIC)} "
            "(parameters as NAME:key=value,..., e.g. sinusoid:omega=0.5,amplitude=1); or the path "
            "of a CSV file with columns 't, v' or 't, v, a' (SI units)."
        ),
    )
    p.add_argument("--leader", default="mix", metavar="SPEC", help="leader (default: mix)")
    p.add_argument("--followers", type=int, default=10, metavar="N", help="followers (default 10)")
    p.add_argument("--controller", choices=("linear", "cacc", "idm"), default="linear",
                   help="eq-4 linear law (default), van Arem 2006 CACC, or IDM human drivers")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--gains", metavar="K_X,K_V,K_A", default=None,
                   help=f"fixed gains of the linear law (default {DEFAULT_GAINS}, certified)")
    g.add_argument("--gains-file", metavar="FILE",
                   help="time-varying gains: a gain file (as for certify --file) with columns "
                        "t,k_x,k_v,k_a held between rows; with a vehicle column, one series per "
                        "follower 1..N")
    p.add_argument("--from", dest="from_identify", metavar="IDENTIFY_JSON",
                   help="take k_x, k_v, k_a, tau, delta, headway, standstill (and the reaction delay, "
                        "if fitted) of a vehicle fitted by 'stringstab identify' (with --vehicle POS) "
                        "for every follower")
    p.add_argument("--vehicle", type=int, default=None, metavar="POS",
                   help="with --from: the platoon position of the fitted vehicle (default: the only one)")
    add_vehicle_arguments(p)
    p.add_argument("--dt", type=float, default=DT,
                   help=f"simulation step, s, at most tau and delta (default {DT:g})")
    p.add_argument("--duration", type=float, default=None, help="keep only the first seconds of the leader")
    p.add_argument("--hold", type=float, default=0.0, metavar="SECONDS",
                   help="then let the leader hold its final speed this long (lets the platoon settle)")
    p.add_argument("--model", choices=("lag", "kinematic"), default="lag",
                   help="third-order model with exact ZOH (default) or the paper's eqs 1-2")
    p.add_argument("--ttc-star", type=float, default=TTC_STAR,
                   help=f"TTC* threshold, s (default {TTC_STAR:g})")
    p.add_argument("--format", choices=("npz", "csv", "parquet"), default="npz",
                   help="trajectory file format (default: npz)")
    p.add_argument("--no-figures", action="store_true", help="skip the figures")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="output directory (an earlier run's files in it are replaced)")
    add_limit_arguments(p)
    add_loop_arguments(p)
    p.set_defaults(func=run)


def parse_gains(text: str) -> tuple[float, float, float]:
    """``"k_x,k_v,k_a"`` → three finite floats (:func:`stringstab.io.parse_triple`).

    Parameters
    ----------
    text : str
        Three comma-separated numbers: k_x (1/s²), k_v (1/s), k_a.

    Returns
    -------
    tuple of float
        (k_x, k_v, k_a).

    Raises
    ------
    StringStabError
        Unless the text is exactly three comma-separated finite numbers.

    Examples
    --------
    >>> parse_gains("1.2, 0.5,0.6")
    (1.2, 0.5, 0.6)
    """
    from ..io import parse_triple

    try:
        return parse_triple(str(text))
    except StringStabError as e:
        raise StringStabError(f"--gains must be three finite numbers k_x,k_v,k_a; {e}") from e


def _controller(args: argparse.Namespace, headway: float) -> Any:
    from ..traffic.controllers import (
        CACCController,
        IDMController,
        LinearController,
        TimeVaryingLinearController,
    )

    if args.controller != "linear" and (args.gains or args.gains_file):
        raise StringStabError(f"--gains/--gains-file apply to --controller linear, not {show(args.controller)}")
    if args.controller == "cacc":
        return CACCController(t_system=headway, r_min=args.standstill)
    if args.controller == "idm":
        return IDMController(min_gap=args.standstill)
    if args.gains_file:
        return TimeVaryingLinearController.from_csv(args.gains_file, headway=headway,
                                                    standstill=args.standstill)
    return LinearController(*parse_gains(args.gains or DEFAULT_GAINS), headway=headway,
                            standstill=args.standstill)


def check_step(dt: float, tau: float, delta: float) -> None:
    """Refuse a step ``--dt`` longer than the actuator lag τ or the delay δ (module docstring).

    Parameters
    ----------
    dt : float
        The simulation step, s (checked finite and > 0).
    tau, delta : float
        The actuator lag τ and the communication delay δ, s (checked).

    Raises
    ------
    StringStabError
        When dt > τ, or dt > δ > 0: the exact-ZOH step would hold the command over more than
        one lag, or interpolate the delayed acceleration across a whole step.
    """
    limit = min(tau, delta) if delta > 0 else tau
    if dt > limit * (1 + 1e-12):
        longer = [f"the actuator lag tau = {tau:g} s"] if dt > tau * (1 + 1e-12) else []
        if delta > 0 and dt > delta * (1 + 1e-12):
            longer.append(f"the delay delta = {delta:g} s")
        raise StringStabError(
            f"--dt {dt:g} s is longer than {' and '.join(longer)}: the command would be held "
            "over more than one lag or the delayed acceleration interpolated across a whole "
            "step, so the run would not be the continuous-time platoon its certificate and "
            f"M_fss describe; expected --dt <= {limit:g} s"
        )


def _fmt(v: Any, spec: str, unit: str = "") -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "n/a"
    return f"{v:{spec}}{unit}"


def _from_identified(args: argparse.Namespace) -> None:
    """``--from identify.json``: the gains and vehicle parameters of one fitted vehicle."""
    from ..identify.report import read_identified

    if args.gains or args.gains_file or args.controller != "linear":
        raise StringStabError("--from replaces --gains/--gains-file and needs --controller linear")
    rows = read_identified(args.from_identify, vehicle=args.vehicle)
    if len(rows) != 1:
        raise StringStabError(f"--from {args.from_identify}: {len(rows)} vehicles; expected --vehicle POS, "
                              f"one of {[r['position'] for r in rows]}")
    r = rows[0]
    args.gains = f"{r['k_x']!r},{r['k_v']!r},{r['k_a']!r}"
    args.tau, args.delta, args.headway, args.standstill = r["tau"], r["delta"], r["headway"], r["standstill"]
    theta = r.get("reaction_delay", 0.0)  # absent in a file written before θ_r was fitted
    if getattr(args, "reaction_delay", None) is not None:
        raise StringStabError(f"--from {args.from_identify} takes the reaction delay of the fit "
                              f"({theta!r} s); expected no --reaction-delay with it, got "
                              f"--reaction-delay {args.reaction_delay}")
    args.reaction_delay = theta if theta else None


def run(args: argparse.Namespace) -> int:
    """Run ``simulate``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab simulate``.

    Returns
    -------
    int
        Exit code: 0 when the run was written without collision, 1 when some follower
        collided (the outputs are still written); bad input raises
        :class:`~stringstab.errors.StringStabError` (exit 2 from
        :func:`stringstab.cli.main`).
    """
    import time

    from ..io import OutputDir
    from ..traffic.leaders import leader_by_name
    from ..traffic.output import RUN_FILES, run_document, write_run
    from ..traffic.platoon import simulate

    t0 = time.perf_counter()
    if getattr(args, "vehicle", None) is not None and not getattr(args, "from_identify", None):
        raise StringStabError(f"--vehicle picks a fitted vehicle of --from IDENTIFY_JSON: expected "
                              f"--from with it; got --vehicle {args.vehicle} without --from")
    if getattr(args, "from_identify", None):
        _from_identified(args)
    tau, delta, headway = check_params(args.tau, args.delta, args.headway)
    integer("--followers", args.followers, 1)  # the memory estimate bounds it (below)
    for name in ("dt", "standstill", "length", "ttc_star"):
        v = getattr(args, name)
        if not (math.isfinite(v) and (v > 0 or (name == "standstill" and v == 0))):
            raise StringStabError(
                f"--{name.replace('_', '-')} must be a finite number > 0; got {show(v)}"
            )
    sizes = [(kind, getattr(args, name), f"--{name.replace('_', '-')}")
             for name, kind in (("standstill", "length"), ("length", "length"), ("ttc_star", "ttc"))]
    for kind, v, option in [("step", args.dt, "--dt"), *sizes]:
        check_magnitude(kind, v, name=option)
    if not (math.isfinite(args.hold) and args.hold >= 0):
        raise StringStabError(f"--hold must be a finite number of seconds >= 0; got {show(args.hold)}")
    check_step(args.dt, tau, delta)
    theta = reaction_from_args(args)
    radio, sensors = radio_from_args(args, args.dt)

    for opt, v in (("--duration", args.duration), ("--hold", args.hold)):
        if v is not None and math.isfinite(v):
            check_magnitude("duration", v, name=opt)
    out = OutputDir(args.out, command="simulate", owns=RUN_FILES, what="--out")
    leader = leader_by_name(args.leader, dt=args.dt, duration=args.duration).hold(args.hold)
    from ..memory import refuse_platoon

    refuse_platoon(args.followers, len(leader.speed), f"--followers {args.followers}")
    limits = limits_from_args(args)
    controller = _controller(args, headway)
    n_series = getattr(controller, "followers", None)
    if n_series is not None and n_series != args.followers:
        raise StringStabError(
            f"--gains-file {args.gains_file} has gain series for followers 1..{n_series}; "
            f"expected --followers {n_series}, got {args.followers}"
        )
    from ..traffic.limits import settling_time

    settling = settling_time(controller, tau if args.model == "lag" else 0.0)
    warnings = checked_leaders(args, [leader], limits, settling=settling)
    warn_beyond_sensible(args, [("followers", args.followers, "--followers"),
                                ("step", args.dt, "--dt"), *sizes])
    result = simulate(leader, controller, args.followers, tau=tau, delta=delta, model=args.model,
                      length=args.length, limits=limits, reaction_delay=theta, radio=radio,
                      sensors=sensors)
    doc = run_document(result, leader=leader, controller=controller, spec=args.leader,
                       ttc_star=args.ttc_star, warnings=warnings)
    metrics = doc
    title = (f"{leader.name}: {args.followers} followers, {args.controller}"
             + (f" K=({args.gains or DEFAULT_GAINS})" if args.controller == "linear" and not args.gains_file else ""))
    with out:
        files = write_run(result, out, metrics=doc, fmt=args.format, figures=not args.no_figures,
                          title=title)
        from ..report import command_line
        from ..report.commands import simulate_report

        simulate_report(doc, files, command=command_line(args), title=title,
                        started=t0).write(out)
    mp = metrics["m_p"]
    print(f"simulated {leader.name} ({leader.duration:g} s, dt = {args.dt:g} s), "
          f"{args.followers} followers, {args.controller} controller, model = {args.model}"
          + (f", reaction delay θ_r = {theta:g} s" if theta else ""))
    if "radio" in doc:
        print(radio_line(doc["radio"], radio))
    shown = ", ".join(_fmt(v, ".3f") for v in mp[:20]) + (", ..." if len(mp) > 20 else "")
    print(f"m_p per follower (eq 29, follower/predecessor acceleration energy): {shown}")
    print(f"max m_p = {_fmt(metrics['max_m_p'], '.3f')}, M_lss = {_fmt(metrics['M_lss'], '.3f')}, "
          f"collisions = {metrics['collisions']}, TIT = {_fmt(metrics.get('TIT'), '.3f', ' s²')}, "
          f"M_CI = {_fmt(metrics.get('M_CI'), '.4g', ' m²/s⁶')}, "
          f"M_effi = {_fmt(metrics.get('M_effi'), '.3f', ' s')}, "
          f"m_fss = {_fmt(metrics['m_fss'], '.3f')} (share of vehicle-moments certified)")
    for k in ("max_m_p", "M_lss", "TIT", "M_CI", "M_effi"):
        if metric_caveat(k, metrics.get(k)):
            print(f"note: {k} = {metrics[k]:.3g} {metric_caveat(k, metrics[k])}")
    print(f"wrote {', '.join(files.values())} to {out.root}/")
    return collision_status(args, metrics["collisions"], first_collision(result),
                            metrics["m_fss"])


def radio_line(summary: dict[str, Any], radio: Any) -> str:
    """One line on what the radio did (the ``radio`` entry of ``metrics.json``).

    Parameters
    ----------
    summary : dict
        :func:`stringstab.traffic.output.radio_summary` of the run.
    radio : Radio
        The radio simulated.

    Returns
    -------
    str
        Messages received and lost, the share lost and the time in fallback.
    """
    rec = int(np.sum(summary["messages_received"]))
    lost = int(np.sum(summary["messages_lost"]))
    period = "every step" if radio.message_period is None else f"every {radio.message_period:g} s"
    share = summary["loss_share"]
    out = (f"radio: messages {period}: {rec} received, {lost} lost"
           + (f" ({100 * share:.2f} %)" if share is not None else ""))
    if radio.stale_after is not None:
        fb = float(np.sum(summary["fallback_time"]))
        out += (f"; time in fallback (ACC) {fb:.4g} s in all "
                f"({100 * (summary['fallback_share'] or 0.0):.2f} % of follower time)")
    return out


def first_collision(result: Any) -> str:
    """Who of a simulated platoon collided first, and when (for the collision warning).

    Parameters
    ----------
    result : PlatoonResult
        A run with at least one collision (its ``first_collision_time`` per follower, s).

    Returns
    -------
    str
        ``"follower I first reached its predecessor at t = T s"`` (or ``""`` without one).
    """
    first = np.asarray(result.first_collision_time, dtype=float).ravel()
    if not np.isfinite(first).any():
        return ""
    who = int(np.nanargmin(first)) + 1
    return f"follower {who} first reached its predecessor at t = {float(np.nanmin(first)):.4g} s"
