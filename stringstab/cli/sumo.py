"""``stringstab sumo``: run the toolkit's controllers inside Eclipse SUMO.

* ``sumo check`` — one case through the toolkit's simulator and through SUMO; the largest
  differences in acceleration, speed, gap and m_p; exit 1 above the tolerance (1e-3);
* ``sumo run`` — a platoon (fixed gains, a gain file or a trained policy) driven in SUMO,
  writing what ``stringstab simulate`` writes; or, with ``--sumocfg``, named vehicles of an
  existing scenario driven by the controller, each following whatever SUMO says leads it.
  Exit 1 (outputs written, one warning line each) when a vehicle collided, as ``simulate``,
  or when a controlled vehicle of the scenario never had a leader (the controller never drove
  it);
* ``sumo cacc`` — SUMO's own CACC vType: per-mode equivalent linear gains, their certificates
  (continuous and sampled) and the amplification SUMO measures along a 10-vehicle platoon.

Needs the optional extra ``sumo`` (``pip install 'stringstab[sumo]'``); without it every
sub-command stops with one line naming the extra (exit 2).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from typing import Any

import numpy as np

from ..errors import StringStabError, show

__all__ = ["add_parser", "run", "run_cacc", "run_check", "run_platoon"]

HELP = "run certified and learned controllers inside Eclipse SUMO (check, run, cacc)"


def _case_arguments(p: argparse.ArgumentParser, *, policy: bool) -> None:
    from ..constants import DT
    from ._common import add_limit_arguments, add_vehicle_arguments
    from .simulate import DEFAULT_GAINS

    p.add_argument("--leader", default="udds", metavar="SPEC",
                   help="leader: a cycle (udds, hwfet, us06, wltc_3b), a synthetic profile "
                        "(e.g. sinusoid:omega=0.5,amplitude=1) or a 't, v' CSV (default udds)")
    p.add_argument("--followers", type=int, default=10, metavar="N", help="followers (default 10)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--gains", metavar="K_X,K_V,K_A", default=None,
                   help=f"fixed gains of the eq-4 law (default {DEFAULT_GAINS}, certified)")
    g.add_argument("--gains-file", metavar="FILE",
                   help="a gain time series t,k_x,k_v,k_a (as for simulate --gains-file)")
    if policy:
        g.add_argument("--policy", metavar="RUN",
                       help="a run folder of 'stringstab train' (gain policies: each executed "
                            "gain is certified; tau, delta, T* and dt are the policy's)")
    add_vehicle_arguments(p, defaults=False)  # None: the policy's, else the toolkit's
    p.add_argument("--dt", type=float, default=None,
                   help=f"step of the controller and of SUMO, s (default {DT:g})")
    p.add_argument("--duration", type=float, default=None, metavar="S",
                   help="keep only the first S seconds of the leader")
    p.add_argument("--hold", type=float, default=0.0, metavar="S",
                   help="then hold the leader's final speed S seconds")
    p.add_argument("--api", choices=("libsumo", "traci"), default="libsumo",
                   help="libsumo in this process (default) or TraCI to a SUMO subprocess on 127.0.0.1")
    add_limit_arguments(p)  # the followers' limits, as simulate's


def add_parser(sub: Any) -> None:
    """Register ``sumo`` and its sub-commands ``check``, ``run`` and ``cacc``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    p = sub.add_parser(
        "sumo", help=HELP,
        description="Drive vehicles of Eclipse SUMO (1.28, ballistic update, speed mode 0) with "
                    "the toolkit's controllers; the actuator lag tau and the delay delta stay on "
                    "the toolkit's side (exact zero-order hold). Needs the extra 'sumo'.")
    ss = p.add_subparsers(dest="sumo_command", metavar="SUBCOMMAND")
    ss.required = True
    c = ss.add_parser(
        "check", help="the same case through the toolkit's simulator and through SUMO",
        description="Simulate one case with stringstab's simulator (trapezoidal positions, "
                    "SUMO's ballistic rule) and inside SUMO; print the largest differences in "
                    "acceleration, speed, gap and m_p. Exit 0 when all are <= --tolerance, "
                    "1 otherwise, 2 on bad input.")
    _case_arguments(c, policy=False)
    c.add_argument("--tolerance", type=float, default=1e-3, help="largest accepted difference (default 1e-3)")
    c.add_argument("--json", metavar="FILE", help="also write the differences as JSON")
    c.set_defaults(func=run)

    r = ss.add_parser(
        "run", help="drive a platoon (or named vehicles of a scenario) in SUMO; write what simulate writes",
        description="Drive N followers behind a leader in SUMO with fixed gains, a gain file or "
                    "a trained policy, and write trajectories, metrics.json (m_p, M_lss, TIT, "
                    "M_CI, M_effi, m_fss, collisions) and figures as 'stringstab simulate' does. "
                    "With --sumocfg FILE --controlled ID,...: those vehicles of the scenario are "
                    "driven by the controller, each following the vehicle SUMO reports as its "
                    "leader at every step, and the rest of the traffic is SUMO's. Exit 0; 1 when "
                    "a vehicle collided or a controlled vehicle never had a leader (outputs "
                    "written, a warning says which); 2 on bad input.")
    _case_arguments(r, policy=True)
    from ._loop import add_loop_arguments

    add_loop_arguments(r)  # θ_r, the radio and the sensors: on the toolkit's side, like τ
    r.add_argument("--sumocfg", metavar="FILE",
                   help="an existing scenario (its step-length must be --dt and it must use "
                        "step-method.ballistic); needs --controlled")
    r.add_argument("--controlled", metavar="ID,ID,...",
                   help="SUMO vehicle ids driven by the controller (with --sumocfg)")
    r.add_argument("--steps", type=int, default=None, metavar="K",
                   help="with --sumocfg: steps to run (default: until the controlled vehicles arrive)")
    r.add_argument("--format", choices=("npz", "csv", "parquet"), default="npz",
                   help="trajectory file format (default: npz)")
    r.add_argument("--no-figures", action="store_true", help="skip the figures")
    r.add_argument("--out", required=True, metavar="DIR", help="output directory")
    r.set_defaults(func=run)

    a = ss.add_parser(
        "cacc", help="certify SUMO's own CACC mode by mode, beside the amplification SUMO measures",
        description="Read a vType with carFollowModel CACC from a route file, derive the linear "
                    "law of each of its modes (gap control, gap closing; speed control has no "
                    "spacing term), certify each (continuous time and sampled at the step), and "
                    "run a platoon of CACC vehicles in SUMO behind a leader to measure the "
                    "amplification m_p along it. Certifying each mode does not certify the "
                    "switching between them.")
    a.add_argument("--vtype", required=True, metavar="FILE.rou.xml:TYPE",
                   help="route/additional file and vType id")
    a.add_argument("--followers", type=int, default=10, metavar="N", help="platoon size (default 10)")
    a.add_argument("--leader", default="sinusoid:omega=0.5,amplitude=1", metavar="SPEC",
                   help="leader of the SUMO platoon (default sinusoid:omega=0.5,amplitude=1)")
    a.add_argument("--duration", type=float, default=120.0, metavar="S",
                   help="seconds of the leader (default 120)")
    a.add_argument("--dt", type=float, default=0.1, help="SUMO step, s (default 0.1)")
    a.add_argument("--api", choices=("libsumo", "traci"), default="libsumo", help="how SUMO runs")
    a.add_argument("--json", metavar="FILE", help="also write the findings as JSON")
    a.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Dispatch ``sumo check|run|cacc``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab sumo``.

    Returns
    -------
    int
        Exit code: that of :func:`run_check`, :func:`run_platoon` or :func:`run_cacc`;
        130 when interrupted (SUMO stopped, nothing written).
    """
    cmd = {"check": run_check, "run": run_platoon, "cacc": run_cacc}[args.sumo_command]
    try:
        return cmd(args)
    except KeyboardInterrupt:
        print(f"stringstab sumo {args.sumo_command}: interrupted; SUMO was stopped and nothing "
              "was written", file=sys.stderr)
        return 130


def _number(name: str, v: float | None, *, zero: bool = False) -> None:
    if v is not None and not (math.isfinite(v) and (v > 0 or (zero and v == 0))):
        raise StringStabError(f"--{name} must be a finite number {'>=' if zero else '>'} 0; got {show(v)}")


def _case(args: argparse.Namespace, *, leader: bool = True) -> dict[str, Any]:
    """Leader, controller, τ, δ, T*, dt, limits of a case; with ``--policy`` the policy's own.

    Without ``leader`` (a scenario of SUMO's: its own traffic leads) no leader is built.
    """
    from ..constants import DT
    from ..params import DEFAULT_DELTA, DEFAULT_HEADWAY, DEFAULT_TAU, check_params
    from ..traffic.leaders import leader_by_name
    from ._common import checked_leaders, limits_from_args
    from .simulate import parse_gains

    for name in ("standstill", "length", "dt", "duration", "tau", "delta", "headway", "hold"):
        if hasattr(args, name):
            _number(name, getattr(args, name), zero=name in ("standstill", "delta", "headway", "hold"))
    if args.followers < 1:
        raise StringStabError(f"--followers must be an integer >= 1; got {args.followers}")
    info: dict[str, Any] = {}
    policy = None
    if getattr(args, "policy", None):
        from ..rl.runs import open_run

        run_info, policy = open_run(args.policy)
        p = policy.info
        if policy.action != "gains":
            raise StringStabError(
                f"--policy {args.policy}: a {policy.algo} policy outputs accelerations; expected "
                "a gain policy (stringstab train --algo idl) whose executed gains can be certified")
        for name in ("tau", "delta", "headway", "dt"):
            given = getattr(args, name)
            if given is not None and abs(given - float(p[name])) > 1e-12:
                raise StringStabError(
                    f"--{name} {given:g} differs from the policy's {name} = {float(p[name]):g}; "
                    f"the policy's gains are certified for its own; omit --{name}")
        tau, delta, headway, dt = float(p["tau"]), float(p["delta"]), float(p["headway"]), float(p["dt"])
        info = {"policy": run_info.get("folder"), "algo": policy.algo}
    else:
        tau, delta, headway = check_params(
            DEFAULT_TAU if args.tau is None else args.tau,
            DEFAULT_DELTA if args.delta is None else args.delta,
            DEFAULT_HEADWAY if args.headway is None else args.headway)
        dt = DT if args.dt is None else float(args.dt)
    from ..ranges import check_magnitude
    from .simulate import check_step

    sizes = [("step", dt, "--dt"), *[("length", getattr(args, n), f"--{n}") for n in ("standstill", "length")],
             *[("duration", getattr(args, n, None), f"--{n}") for n in ("duration", "hold")]]
    for kind, v, option in sizes:  # as simulate's
        if v is not None:
            check_magnitude(kind, v, name=option)
    check_step(dt, tau, delta)
    limits = limits_from_args(args)
    lead, warnings = None, []
    if leader:
        lead = leader_by_name(args.leader, dt=dt, duration=args.duration).hold(args.hold)
        from ..memory import refuse_platoon

        refuse_platoon(args.followers, len(lead.speed), f"--followers {args.followers}")  # as simulate
        warnings = checked_leaders(args, [lead], limits)  # printed on stderr
    if policy is not None:
        from ..rl.evaluate import controller_for

        controller = controller_for(policy, headway=headway, standstill=args.standstill)
        label = f"policy {args.policy}"
    elif args.gains_file:
        from ..traffic.controllers import TimeVaryingLinearController

        controller = TimeVaryingLinearController.from_csv(args.gains_file, headway=headway,
                                                          standstill=args.standstill)
        n_series = controller.followers
        if n_series is not None and n_series != args.followers:
            raise StringStabError(
                f"--gains-file {args.gains_file} has gain series for followers 1..{n_series}; "
                f"expected --followers {n_series}, got {args.followers}")
        label = f"gains from {args.gains_file}"
    else:
        from ..traffic.controllers import LinearController
        from .simulate import DEFAULT_GAINS

        controller = LinearController(*parse_gains(args.gains or DEFAULT_GAINS), headway=headway,
                                      standstill=args.standstill)
        label = f"K=({args.gains or DEFAULT_GAINS})"
    return {"leader": lead, "controller": controller, "tau": tau, "delta": delta,
            "headway": headway, "dt": dt, "limits": limits, "warnings": warnings, "label": label,
            **info}


def run_check(args: argparse.Namespace) -> int:
    """``sumo check``: toolkit vs SUMO on one case; exit 1 above the tolerance.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab sumo check``.

    Returns
    -------
    int
        Exit code: 0 when the toolkit and SUMO agree within ``--tolerance``, 1
        otherwise; bad input raises :class:`~stringstab.errors.StringStabError` (exit 2
        from :func:`stringstab.cli.main`).
    """
    from ..io import atomic_write_text, check_output_file, dumps_json
    from ..sumo.agreement import agreement

    _number("tolerance", args.tolerance)
    target = check_output_file(args.json, what="--json") if args.json else None
    case = _case(args)
    res = agreement(case["leader"], case["controller"], args.followers, tau=case["tau"],
                    delta=case["delta"], api=args.api, length=args.length,
                    limits=case["limits"], tolerance=args.tolerance, progress=True)
    d, de = res["differences"], res["differences_exact_positions"]
    lead = case["leader"]
    print(f"sumo check: {lead.name} ({lead.duration:g} s, dt = {case['dt']:g} s), "
          f"{args.followers} followers, {case['label']}, tau = {case['tau']:g} s, "
          f"delta = {case['delta']:g} s, SUMO {res['sumo_version']} via {args.api}")
    print("largest |toolkit - SUMO| over followers and time (toolkit with SUMO's ballistic "
          "position rule; the toolkit's default exact positions in brackets):")
    units = {"accel": "m/s²", "speed": "m/s", "gap": "m", "m_p": ""}
    for k in ("accel", "speed", "gap", "m_p"):
        print(f"  {k:6s} {d[k]:.3e} {units[k]:5s} [{de[k]:.3e}]")
    if res["leader_position_change"] > 1e-9:
        print(f"  (the leader's positions are SUMO's trapezoidal integral of its speeds on both "
              f"sides: up to {res['leader_position_change']:.3g} m from the profile's own)")
    verdict = "passed" if res["passed"] else "FAILED"
    print(f"{verdict}: largest difference {max(d.values()):.3e} "
          f"{'<=' if res['passed'] else '>'} tolerance {args.tolerance:g}")
    if target is not None:
        atomic_write_text(target, dumps_json(res))
        print(f"wrote {target}")
    return 0 if res["passed"] else 1


def _fmt(v: Any, spec: str, unit: str = "") -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "n/a"
    return f"{v:{spec}}{unit}"


def run_platoon(args: argparse.Namespace) -> int:
    """``sumo run``: a platoon (or a scenario's vehicles) in SUMO, written like ``simulate``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab sumo run``.

    Returns
    -------
    int
        Exit code: 0 when the run was written without collision; 1 when a vehicle collided
        or (``--sumocfg``) a controlled vehicle never had a leader, the outputs written and a
        warning printed; bad input raises :class:`~stringstab.errors.StringStabError`
        (exit 2 from :func:`stringstab.cli.main`).
    """
    from ..io import OutputDir
    from ..traffic.output import RUN_FILES, run_document, write_run
    from ._outcome import collision_status
    from .simulate import first_collision

    if (args.sumocfg is None) != (args.controlled is None):
        raise StringStabError("--sumocfg and --controlled go together; expected both or neither, "
                              f"got {'--sumocfg' if args.sumocfg else '--controlled'} alone")
    from ._loop import RADIO_FLAGS, radio_from_args, reaction_from_args

    if args.sumocfg:
        given = [f"--{n.replace('_', '-')}" for n in ("reaction_delay", *RADIO_FLAGS)
                 if getattr(args, n, None) is not None]
        if given:
            raise StringStabError(f"{', '.join(given)}: simulated for a platoon behind a leader; "
                                  "expected none of them with --sumocfg")
        return _run_scenario(args)
    if args.steps is not None:
        raise StringStabError(f"--steps is for a scenario (--sumocfg); a platoon runs its leader's "
                              f"length: expected no --steps without --sumocfg, got --steps {args.steps}")
    t0 = time.perf_counter()
    out = OutputDir(args.out, command="sumo run", owns=RUN_FILES, what="--out")
    case = _case(args)
    theta = reaction_from_args(args)
    radio, sensors = radio_from_args(args, case["dt"])
    from ..sumo.platoon import cosimulate

    leader, controller = case["leader"], case["controller"]
    result = cosimulate(leader, controller, args.followers, tau=case["tau"], delta=case["delta"],
                        api=args.api, limits=case["limits"], length=args.length, progress=True,
                        reaction_delay=theta, radio=radio, sensors=sensors)
    warnings = list(case["warnings"])
    over = float(result.params["sumo_speed_override"])
    if over > 1e-9:
        warnings.append(f"SUMO did not execute the commanded speeds exactly (largest difference "
                        f"{over:.3g} m/s): the run is SUMO's, not the controller's alone")
        print(f"stringstab sumo run: warning: {warnings[-1]}", file=sys.stderr)
    doc = run_document(result, leader=leader, controller=controller, spec=args.leader,
                       warnings=warnings)
    if result.gains is not None and result.gains.shape[-2] == result.t.size and not theta:
        # (with θ_r > 0 the executed gains' m_fss is metrics.json's: the sampled certificate
        # has no θ_r yet)
        from ..rl.evaluate import fss

        f = fss(result.gains, tau=case["tau"], delta=case["delta"], headway=case["headway"],
                dt=case["dt"])
        doc["executed_gains"] = {"m_fss": f["m_fss"], "m_fss_sampled": f["m_fss_sampled"],
                                 "n": f["n"], "certificate": f["certificate"]}
    if "policy" in case:
        doc["run"]["policy"] = case["policy"]
    title = f"{leader.name} in SUMO: {args.followers} followers, {case['label']}"
    with out:
        files = write_run(result, out, metrics=doc, fmt=args.format, figures=not args.no_figures,
                          title=title)
        from ..report import command_line
        from ..report.commands import simulate_report

        simulate_report(doc, files, command=command_line(args), title=title,
                        started=t0).write(out)
    _print_summary(f"ran {leader.name} ({leader.duration:g} s, dt = {case['dt']:g} s) in SUMO "
                   f"{result.params['sumo_version']} via {args.api}, {args.followers} followers, "
                   f"{case['label']}", doc)
    if "executed_gains" in doc:
        e = doc["executed_gains"]
        print(f"executed gains: m_fss = {e['m_fss']:.4g} certified (exact), "
              f"{e['m_fss_sampled']:.4g} (sampled-data at dt = {case['dt']:g} s) of {e['n']}")
    if "radio" in doc:
        from .simulate import radio_line

        print(radio_line(doc["radio"], radio))
    print(f"wrote {', '.join(files.values())} to {out.root}/")
    return collision_status(args, doc["collisions"], first_collision(result), doc["m_fss"])


def _print_summary(head: str, doc: dict[str, Any]) -> None:
    mp = doc["m_p"]
    print(head)
    shown = ", ".join(_fmt(v, ".3f") for v in mp[:20]) + (", ..." if len(mp) > 20 else "")
    print(f"m_p per follower (eq 29): {shown}")
    print(f"max m_p = {_fmt(doc['max_m_p'], '.3f')}, M_lss = {_fmt(doc['M_lss'], '.3f')}, "
          f"collisions = {doc['collisions']}, TIT = {_fmt(doc.get('TIT'), '.3f', ' s²')}, "
          f"M_CI = {_fmt(doc.get('M_CI'), '.4g', ' m²/s⁶')}, "
          f"M_effi = {_fmt(doc.get('M_effi'), '.3f', ' s')}, "
          f"m_fss = {_fmt(doc.get('m_fss'), '.3f')}")


#: The files of an in-scenario run.
SCENARIO_FILES = ("scenario.csv", "metrics.json", "report.md", "report.html")


def _run_scenario(args: argparse.Namespace) -> int:
    """``sumo run --sumocfg F --controlled IDS``: the vehicles IDS of F driven by the controller."""
    import time

    from ..io import OutputDir, write_results
    from ..sumo.inscenario import run_scenario
    from ._outcome import collision_status

    t0 = time.perf_counter()
    if args.steps is not None:
        from ._common import integer

        integer("--steps", args.steps, 1, "steps")
    ids = [i.strip() for i in str(args.controlled).split(",")]
    if not all(ids):
        raise StringStabError(f"--controlled: expected vehicle ids ID,ID,...; got {args.controlled!r}")
    out = OutputDir(args.out, command="sumo run", owns=SCENARIO_FILES, what="--out")
    case = _case(args, leader=False)
    res = run_scenario(args.sumocfg, ids, case["controller"], dt=case["dt"], tau=case["tau"],
                       delta=case["delta"], api=args.api, steps=args.steps,
                       limits=case["limits"], progress=args.steps is not None)
    cols = dict(res.columns)
    cols["vehicle"] = np.array([res.ids[j] for j in cols["vehicle"]], dtype=object)
    doc = {"run": {"sumocfg": str(args.sumocfg), "controlled": res.ids, "dt": case["dt"],
                   "tau": case["tau"], "delta": case["delta"], "headway": case["headway"],
                   "controller": case["label"], "api": args.api, "steps": args.steps},
           **res.summary}
    with out:
        write_results(cols, out.path("scenario.csv"), "csv", what="scenario.csv")
        out.write_json("metrics.json", doc)
        from ..report import command_line
        from ..report.commands import scenario_report

        scenario_report(doc, command=command_line(args), started=t0).write(out)
    s = res.summary
    print(f"ran {args.sumocfg} with {', '.join(res.ids)} driven by {case['label']} "
          f"(tau = {case['tau']:g} s, delta = {case['delta']:g} s, dt = {case['dt']:g} s) via {args.api}")
    for v in s["vehicles"]:
        print(f"  {v['vehicle']}: {v['steps_controlled']} steps driven, leaders "
              f"{' -> '.join(v['leaders']) or 'none'}, min gap {_fmt(v['min_gap'], '.2f', ' m')}, "
              f"collisions {v['collisions']}, m_p {_fmt(v['m_p'], '.3f')}")
    if s.get("m_fss") is not None:
        print(f"executed gains: m_fss = {s['m_fss']:.4g} certified (exact), "
              f"{s['m_fss_sampled']:.4g} (sampled-data at dt = {case['dt']:g} s) of {s['n_gains']}")
    print(f"wrote {', '.join(SCENARIO_FILES)} to {out.root}/")
    return max(_without_leader(args, s), collision_status(
        args, s["collisions"], _first_scenario_collision(res), s.get("m_fss")))


def _without_leader(args: argparse.Namespace, summary: dict[str, Any]) -> int:
    """1 with a warning per controlled vehicle that never had a leader (never driven), else 0."""
    from ..sumo.inscenario import LOOKAHEAD
    from ._outcome import command_name

    steps = {v["vehicle"]: v["steps_present"] for v in summary["vehicles"]}
    for vid in summary["without_leader"]:
        print(f"{command_name(args)}: warning: vehicle {vid!r} never had a leader within "
              f"{LOOKAHEAD:g} m in its {steps[vid]} steps, so SUMO's own model drove it "
              "throughout and the controller was never exercised; exit status 1",
              file=sys.stderr)
    return 1 if summary["without_leader"] else 0


def _first_scenario_collision(res: Any) -> str:
    """Which controlled vehicle first reached its leader, and when (empty without collision)."""
    c = res.columns
    if not c["t"].size:
        return ""
    hit = np.flatnonzero((c["controlled"] == 1) & (c["gap"] <= 0))
    if not hit.size:
        return ""
    k = int(hit[0])
    return (f"vehicle {res.ids[int(c['vehicle'][k])]!r} first reached its leader "
            f"{str(c['leader'][k])!r} at t = {float(c['t'][k]):.4g} s")


SWITCHING_NOTE = (
    "Each verdict is for one mode frozen; certifying every mode does not certify the switched "
    "law (SUMO changes mode from step to step, and clamps the speed with its safe-speed rule and "
    "bounds), so the platoon run below is the evidence for the switched law, not a proof.")


def _verdict(c: dict[str, Any]) -> str:
    sup = c.get("sup_gain")
    return f"{c['verdict']} ({'sup|Γ| = ' + format(sup, '.4f') if sup is not None else 'unstable'})"


def run_cacc(args: argparse.Namespace) -> int:
    """``sumo cacc``: per-mode certificates of SUMO's CACC beside the measured amplification.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab sumo cacc``.

    Returns
    -------
    int
        Exit code: 0 when the report was written; bad input raises
        :class:`~stringstab.errors.StringStabError` (exit 2 from
        :func:`stringstab.cli.main`).
    """
    from ..io import atomic_write_text, check_output_file, dumps_json
    from ..sumo.cacc import NO_LAG_TAU, certify_modes, measure_platoon, read_vtype
    from ..traffic.leaders import leader_by_name

    _number("dt", args.dt)
    _number("duration", args.duration)
    if args.followers < 1:
        raise StringStabError(f"--followers must be an integer >= 1; got {args.followers}")
    target = check_output_file(args.json, what="--json") if args.json else None
    vt = read_vtype(args.vtype)
    modes = certify_modes(vt, args.dt)
    leader = leader_by_name(args.leader, dt=args.dt, duration=args.duration)
    meas = measure_platoon(vt, leader, args.followers, api=args.api)
    print(f"SUMO CACC vType {vt.id!r} ({vt.source}): tau = T* = {vt.headway:g} s, minGap = l0 = "
          f"{vt.min_gap:g} m, step {args.dt:g} s")
    print("per-mode linear law u = k_x (gap - T* v - l0) + k_v dv (k_a = 0), certified with "
          f"delta = 0 and tau = {NO_LAG_TAU * 1000:g} ms for SUMO's lag-free vehicles:")
    for r in modes:
        cf = r["no_lag_closed_form"]
        sw = r["sumo_discrete_sweep"]
        swt = (f"sup |H| = {sw['sup_gain']:.4f}" if sw["sup_gain"] is not None
               else f"not Schur (radius {sw['spectral_radius']:.4f})")
        print(f"  {r['mode']:20s} g = ({r['g_space']:g}, {r['g_speed']:g}) -> k_x = {r['k_x']:.4g} 1/s², "
              f"k_v = {r['k_v']:.4g} 1/s")
        print(f"  {'':20s} continuous: {_verdict(r['continuous'])}; sampled at {args.dt:g} s: "
              f"{_verdict(r['sampled'])}")
        print(f"  {'':20s} closed form k_x T*² + 2 k_v T* = {cf['kxT2_plus_2kvT']:.4g} "
              f"{'>=' if cf['string_stable'] else '<'} 2; SUMO's discrete law swept: {swt}")
    print(SWITCHING_NOTE)
    share = ", ".join(f"{k} {100 * v:.1f} %" for k, v in meas["mode_share"].items())
    mp = ", ".join(f"{v:.3f}" for v in meas["m_p"])
    print(f"measured in SUMO: {args.followers} CACC vehicles behind {leader.name} "
          f"({leader.duration:g} s): m_p per vehicle {mp}; max m_p = {meas['max_m_p']:.4f}; "
          f"RMS acceleration last/leader = {_fmt(meas['amplification'], '.4f')}")
    res = "; ".join(f"{k}: {v['steps']} steps, max {_fmt(v['max_residual'], '.2g', ' m/s')}"
                    for k, v in meas["law_residual"].items())
    print(f"mode occupancy (follower-steps): {share}")
    print(f"derived law vs SUMO's speeds, per mode: {res}")
    if target is not None:
        atomic_write_text(target, dumps_json({
            "vtype": {"id": vt.id, "source": vt.source, **vt.params}, "dt": args.dt,
            "modes": modes, "switching": SWITCHING_NOTE, "platoon": meas}))
        print(f"wrote {target}")
    return 0
