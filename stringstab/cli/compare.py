"""``stringstab compare``: the IDL paper's Table 4 and figures for runs and baselines."""

from __future__ import annotations

import argparse
import json
from typing import Any

from ..errors import StringStabError
from ..progress import Progress
from ._common import add_limit_arguments, checked_leaders, limits_from_args

__all__ = ["add_parser", "run"]


def add_parser(sub: Any) -> None:
    """Register ``compare``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    p = sub.add_parser(
        "compare",
        help="compare trained runs and baselines on held-out leaders (Table 4, Figs 6, 9, 11, 12)",
        description=(
            "Evaluate every run folder and baseline on the same held-out leaders and write the "
            "IDL paper's Table 4 (Markdown and CSV, with the improvement percentages of the "
            "reference), the m_p histogram with CDF (Fig. 6), the TTC distribution (Fig. 9), "
            "jerk ranges (Fig. 11), the headway CDF (Fig. 12) and the executed gains over the "
            "certified region. Runs of the same --algo are pooled: mean ± standard deviation."),
    )
    p.add_argument("runs", nargs="+", metavar="RUN", help="run folders written by stringstab train")
    p.add_argument("--baselines", default="cacc,idm", metavar="LIST",
                   help="comma-separated baselines among cacc, idm (default cacc,idm; 'none')")
    p.add_argument("--leaders", nargs="+", metavar="test|FILE", help="held-out leaders (default test)")
    p.add_argument("--reference", default=None, metavar="ALGO",
                   help="strategy whose improvements are listed (default idl when present)")
    p.add_argument("--platoon", action="store_true", help="also run the 10-vehicle platoon test")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder")
    p.add_argument("--no-progress", action="store_true", help="no progress bar or lines (stderr)")
    add_limit_arguments(p)
    from ._loop import add_loop_arguments

    add_loop_arguments(p)
    p.set_defaults(func=run)


def _check_reference(reference: str | None, runs: list[str], baselines: list[str]) -> None:
    """Refuse a ``--reference`` that is none of the strategies, from the runs' ``run.json``.

    Reading ``run.json`` costs milliseconds (loading a policy imports torch), so a typo is
    refused at once; a run folder whose ``run.json`` cannot be read is left to
    :func:`stringstab.rl.runs.open_run`, which says what is wrong with it.
    """
    from pathlib import Path

    from ..rl.checkpoint import read_json
    from ..rl.train import RUN_FORMAT

    if reference is None:
        return
    algos = set()
    for r in runs:
        try:
            algos.add(str(read_json(Path(r) / "run.json", fmt=RUN_FORMAT, what="run folder")["algo"]))
        except (StringStabError, KeyError):
            return
    strategies = sorted(algos | set(baselines))
    if reference not in strategies:
        raise StringStabError(f"--reference {reference!r} is not among the strategies {strategies}; "
                              "expected the --algo of a RUN or a baseline of --baselines")


def run(args: argparse.Namespace) -> int:
    """Run ``compare``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab compare``.

    Returns
    -------
    int
        Exit code: 0 when the comparison ran; bad input raises
        :class:`~stringstab.errors.StringStabError` (exit 2 from
        :func:`stringstab.cli.main`).
    """
    import time

    from ..io import OutputDir
    from ..rl.compare import format_m_fss
    from ..rl.evaluate import BASELINES, evaluate, platoon_test
    from ..rl.report import write_comparison
    from ..rl.runs import open_run, test_leaders

    t0 = time.perf_counter()
    base = [] if args.baselines.strip().lower() == "none" else [
        b.strip() for b in args.baselines.split(",") if b.strip()]
    bad = [b for b in base if b not in BASELINES]
    if bad:
        raise StringStabError(f"--baselines: expected names among {', '.join(BASELINES)}; got {bad}")
    _check_reference(args.reference, args.runs, base)  # at once: before loading any policy
    opened = [open_run(r) for r in args.runs]
    params = {(p.info["tau"], p.info["delta"], p.info["headway"], p.info["dt"]) for _, p in opened}
    if len(params) != 1:
        raise StringStabError(f"runs must share tau, delta, headway and dt; found {sorted(params)}")
    tau, delta, headway, dt = params.pop()
    from .evaluate import loop_of

    loops = [loop_of(args, p.info) for _, p in opened]
    if len({json.dumps(lp[3], sort_keys=True) for lp in loops}) != 1:
        raise StringStabError(
            "runs were trained in different loops (reaction delay, radio or sensors): "
            f"{[lp[3] or 'default' for lp in loops]}; expected one, or give the loop to compare "
            "in with --reaction-delay and the radio and sensor options")
    theta, radio, sensors, loop_doc = loops[0]
    strategies = sorted({pol.algo for _, pol in opened} | set(base))
    ref = args.reference or ("idl" if "idl" in strategies else None)
    if ref is not None and ref not in strategies:  # (a run.json that lied about its algo)
        raise StringStabError(f"--reference {ref!r} is not among the strategies {strategies}; "
                              "expected the --algo of a RUN or a baseline of --baselines")
    leaders, desc = test_leaders(args.leaders, dt=dt)
    limits = limits_from_args(args)
    out = OutputDir(args.out, command="compare")
    from ..rl.evaluate import controller_for
    from ..traffic.limits import settling_time
    from ..traffic.synthetic import paper_mix

    times = [settling_time(controller_for(b, headway=headway), tau) for b in base]
    settling = max((t for t in times if t is not None), default=None)
    checked_leaders(args, [*leaders, *([paper_mix(dt=dt)] if args.platoon else [])], limits,
                    settling=settling)
    groups: dict[str, list[Any]] = {}
    platoons: dict[str, Any] = {}
    kw: dict[str, Any] = {"tau": tau, "delta": delta, "headway": headway, "limits": limits}
    if loop_doc:  # the loop of the runs or of the options (issues 25, 26); none: as before
        kw.update(reaction_delay=theta, radio=radio, sensors=sensors)
    per = len(leaders) + (10 if args.platoon else 0)
    with Progress(per * (len(opened) + len(base)), "stringstab compare", unit="vehicle-runs",
                  enabled=not args.no_progress) as bar:
        for info, pol in opened:
            ev = evaluate(pol, leaders, name=pol.algo, progress=bar.update, **kw)
            groups.setdefault(pol.algo, []).append(ev)
            print(f"{info['folder']} ({pol.algo}): TIT {ev.summary['TIT']:.3f}, "
                  f"M_CI {ev.summary['M_CI']:.3f}, collisions {ev.summary['collisions']}, "
                  f"m_fss = {format_m_fss(ev.summary['m_fss'])}")
            if args.platoon and pol.algo not in platoons:
                platoons[pol.algo] = {"run": info["folder"], "tests": [platoon_test(
                    pol, 10, dt=dt, **kw)]}
            if args.platoon:
                bar.update(10)
        for b in base:
            groups[b] = [evaluate(b, leaders, name=b, progress=bar.update, **kw)]
            if args.platoon:
                platoons[b] = {"run": None, "tests": [platoon_test(b, 10, dt=dt, **kw)]}
                bar.update(10)
    with out:
        files = write_comparison(out, groups, reference=ref, tau=tau, delta=delta,
                                 headway=headway, platoons=platoons or None,
                                 loop=loop_doc or None)
        from ..report import command_line
        from ..report.commands import compare_report

        files += compare_report((out.staging / "table.md").read_text(encoding="utf-8"), files,
                                command=command_line(args), started=t0).write(out)
    print(f"compared {', '.join(groups)} on {len(leaders)} held-out episodes ({desc})")
    print(f"wrote {', '.join(files)} to {out.root}/")
    return 0
