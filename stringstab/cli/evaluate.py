"""``stringstab evaluate``: roll a trained policy on held-out leaders and certify every gain."""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path
from typing import Any

from ..errors import StringStabError
from ..memory import refuse_platoon
from ..progress import Progress
from ._common import add_limit_arguments, checked_leaders, limits_from_args

__all__ = ["add_parser", "loop_of", "run"]


def add_parser(sub: Any) -> None:
    """Register ``evaluate``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    p = sub.add_parser(
        "evaluate",
        help="evaluate a trained policy on held-out leaders; certify every executed gain",
        description=(
            "Roll the policy of a run folder on held-out leaders (the bundled test episodes, or "
            "'t, v' CSV / NGSIM files), certify every executed gain with the exact certificate "
            "(m_fss), compute TIT, M_CI, M_effi, m_p per episode and M_lss, collisions, and the "
            "10- and 100-vehicle platoon test. Exit 0 when every executed gain is certified and "
            "nothing collided, 1 otherwise (an acceleration policy has no gains to certify), "
            "2 on bad input."),
    )
    p.add_argument("run", metavar="RUN", help="run folder written by stringstab train")
    p.add_argument("--leaders", nargs="+", metavar="test|FILE",
                   help="'test' (default: the bundled test episodes) or CSV/NGSIM files")
    p.add_argument("--platoon", default="10,100", metavar="N,N",
                   help="platoon sizes of the §5.1 test (default 10,100; 'none' to skip)")
    p.add_argument("--out", metavar="DIR", help="output folder (default RUN/evaluation)")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bar or progress lines (stderr)")
    add_limit_arguments(p)
    from ._loop import add_loop_arguments

    add_loop_arguments(p)
    p.set_defaults(func=run)


def _sizes(text: str) -> list[int]:
    if text.strip().lower() == "none":
        return []
    try:
        sizes = [int(s) for s in text.split(",") if s.strip()]
    except ValueError as e:
        raise StringStabError(f"--platoon must be sizes like 10,100 or 'none'; got {text!r}") from e
    if not sizes or any(n < 1 for n in sizes):
        raise StringStabError(f"--platoon sizes must be integers >= 1; got {text!r}")
    return sizes


def run(args: argparse.Namespace) -> int:
    """Run ``evaluate``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab evaluate``.

    Returns
    -------
    int
        Exit code: 0 when every executed gain is certified and no vehicle collided (on
        the episodes and platoon tests), 1 otherwise (always 1 for an acceleration
        policy); bad input raises :class:`~stringstab.errors.StringStabError` (exit 2
        from :func:`stringstab.cli.main`).
    """
    import time

    from ..io import OutputDir
    from ..rl.evaluate import evaluate, platoon_test
    from ..rl.report import verdict as report_verdict
    from ..rl.report import write_evaluation
    from ..rl.runs import open_run, test_leaders

    t0 = time.perf_counter()
    sizes = _sizes(args.platoon)
    limits = limits_from_args(args)
    info, policy = open_run(args.run)
    p = policy.info
    theta, radio, sensors, loop_doc = loop_of(args, p)
    leaders, desc = test_leaders(args.leaders, dt=p["dt"])
    out = OutputDir(Path(args.out) if args.out else Path(args.run) / "evaluation",
                    command="evaluate")
    policy_doc = _policy_of(Path(args.run), out)
    from ..traffic.synthetic import paper_mix

    warnings = checked_leaders(args, [*leaders, *([paper_mix(dt=p["dt"])] if sizes else [])],
                               limits)
    for n in sizes:
        refuse_platoon(n, int(paper_mix(dt=p["dt"]).n_steps + 100.0 / p["dt"]), f"--platoon {n}")
    # progress in vehicle-steps (each follower is simulated and its gains certified at every
    # step), counted at every step of the platoon tests: no silent minute, and the time left
    # follows the pace of the last 30 s (a 100-vehicle platoon runs faster per vehicle-step)
    episode_steps = [int(ld.n_steps) for ld in leaders]
    platoon_steps = int(paper_mix(dt=p["dt"]).hold(100.0).n_steps)  # platoon_test's leader
    with Progress(sum(episode_steps) + platoon_steps * sum(sizes), "stringstab evaluate",
                  unit="vehicle-steps", enabled=not args.no_progress, window=30.0) as bar:
        per_episode = sum(episode_steps) / max(len(leaders), 1)
        counted = [0, 0]  # episodes and vehicle-steps reported so far

        def episodes_done(k: int) -> None:
            counted[0] += k
            steps = (sum(episode_steps) if counted[0] >= len(leaders)
                     else round(counted[0] * per_episode))
            bar.update(steps - counted[1])
            counted[1] = steps

        ev = evaluate(policy, leaders, tau=p["tau"], delta=p["delta"], headway=p["headway"],
                      limits=limits, progress=episodes_done, reaction_delay=theta, radio=radio,
                      sensors=sensors)
        platoons = []
        for n in sizes:
            platoons.append(platoon_test(policy, n, tau=p["tau"], delta=p["delta"],
                                         headway=p["headway"], dt=p["dt"], limits=limits,
                                         progress=lambda _, n=n: bar.update(n),
                                         reaction_delay=theta, radio=radio, sensors=sensors))
    s = ev.summary
    verdict, passed = report_verdict(ev, platoons, policy.action)
    run_doc = {**info, "leaders": desc, "tau": p["tau"], "delta": p["delta"],
               "headway": p["headway"], "dt": p["dt"], "repair": p.get("repair"),
               "limits": dataclasses.asdict(limits), "warnings": warnings,
               "policy_sha256": policy_doc["policy_sha256"], "steps": policy_doc["steps"],
               **loop_doc}
    with out:
        files = write_evaluation(out, ev, platoons, run_doc, verdict)
        from ..report import command_line
        from ..report.commands import evaluate_report
        from ..rl.report import evaluation_markdown

        files += evaluate_report(evaluation_markdown(ev, platoons, run_doc, verdict), files,
                                 command=command_line(args), verdict=verdict, passed=passed,
                                 started=t0).write(out)
    print(f"evaluated {info['folder']} ({policy.algo}) on {s['episodes']} held-out episodes ({desc})")
    from ..ranges import metric_caveat
    from ..rl.compare import format_m_fss

    fss = format_m_fss(s["m_fss"])
    mlss = "n/a" if s["M_lss"] is None else f"{s['M_lss']:.3f}"
    if s.get("m_fss_sampled") is not None:
        fss += f" (sampled-data at dt={p['dt']} s: {s['m_fss_sampled']:.4g})"
    elif theta and s.get("m_fss") is not None:
        from ..rl.evaluate import SAMPLED_NOT_AVAILABLE

        fss += f" (certified at θ_r = {theta:g} s; sampled-data {SAMPLED_NOT_AVAILABLE})"
    print(f"m_fss = {fss} of {s.get('n_gains', 0)} executed gains, collisions {s['collisions']}, "
          f"TIT {s['TIT']:.3f}, M_CI {s['M_CI']:.3f}, M_effi {s['M_effi']:.3f}, M_lss {mlss}")
    for k in ("TIT", "M_CI", "M_effi", "M_lss"):
        if metric_caveat(k, s.get(k)):
            print(f"note: {k} = {s[k]:.3g} {metric_caveat(k, s[k])}")
    for q in platoons:
        print(f"platoon of {q['n']}: max m_p {q['max_m_p']:.3f}, collisions {q['collisions']}, "
              f"m_fss = {format_m_fss(q['m_fss'])}")
    print(f"verdict: {verdict}")
    print(f"wrote {', '.join(files)} to {out.root}/")
    return 0 if passed else 1


def loop_of(args: argparse.Namespace, info: Any) -> tuple[float, Any, Any, dict[str, Any]]:
    """The loop to evaluate in: the loop options when any is given, else the run's own.

    With any of ``--reaction-delay`` and the radio and sensor options, the loop is what they
    say (the others at their defaults: θ_r = 0, no radio, exact sensors); with none, the loop
    the policy was trained in (``policy.json``; θ_r = 0, no radio and exact sensors for a run
    trained without them).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line (the options of :func:`~stringstab.cli._loop.add_loop_arguments`).
    info : mapping
        The policy's info (``policy.json``): its ``dt`` and its training loop.

    Returns
    -------
    (float, Radio or None, SensorNoise or None, dict)
        θ_r (s), the radio, the sensors, and their record for the output (empty at the
        defaults).
    """
    from ..rl.config import loop_from_info, sensor_fields
    from ._loop import loop_asked, radio_from_args, reaction_from_args

    if loop_asked(args):
        theta = reaction_from_args(args)
        radio, sensors = radio_from_args(args, float(info["dt"]))
    else:
        theta, radio, sensors = loop_from_info(info)
        if radio is not None and radio.message_period is not None:
            from ..traffic.radio import message_steps

            message_steps(radio.message_period, float(info["dt"]))
    doc: dict[str, Any] = {}
    if theta:
        doc["reaction_delay"] = theta
    if radio is not None:
        doc["radio"] = radio.describe()
    if sensors is not None:
        doc["sensors"] = sensor_fields(sensors)
    return theta, radio, sensors, doc


def _policy_of(run: Path, out: Any) -> dict[str, Any]:
    """The evaluated policy's identity, recorded in the manifest; a stale evaluation is named.

    An output folder holding the evaluation of *another* run folder is refused (two policies'
    results are never mixed, nor one silently replaced by another's); one holding an evaluation
    of an older policy of this run (before ``train --resume``) is replaced, and the command
    says so.
    """
    import sys

    from ._provenance import policy_identity

    ident = policy_identity(run) or {"policy_sha256": None, "steps": None}
    doc = {"run": str(run.resolve()), **ident}
    prev = (out.previous() or {}).get("policy")
    if isinstance(prev, dict):
        if prev.get("run") not in (None, doc["run"]):
            raise StringStabError(
                f"--out {out.root} holds the evaluation of another run ({prev.get('run')}); "
                f"expected an empty folder or an evaluation of {run}; choose another --out")
        if (prev.get("policy_sha256"), prev.get("steps")) != (doc["policy_sha256"], doc["steps"]):
            print(f"stringstab evaluate: note: {out.root}/ held the evaluation of an older policy "
                  f"of this run (step {prev.get('steps')}); it is replaced by this one's "
                  f"(step {doc['steps']})", file=sys.stderr)
    out.record(policy=doc)
    return doc
