"""``stringstab sweep``: run a sweep spec on Dask (a local cluster, or a scheduler's address)."""

from __future__ import annotations

import argparse
import importlib.util
import time
from typing import Any

from ._common import integer as _int
from ._common import warn_beyond_sensible

__all__ = ["add_parser", "run"]

_EPILOG = """\
examples:
  stringstab sweep analysis/sweeps/smoke.toml --out sweeps/smoke              # local cluster, all cores
  stringstab sweep analysis/sweeps/table3_reduced.toml --out sweeps/t3 --workers 2
  stringstab sweep analysis/sweeps/table3_paper.toml --out /shared/t3 --scheduler tcp://head:8786

outputs in --out: points/<id>.json (one record per point, written as it finishes),
points/<id>/ (its artefacts), spec.toml, results.csv, results.parquet, report/.
Re-running the same command skips the finished points (an interrupted sweep resumes).
With --scheduler, --out must be on a filesystem every worker sees. See docs/sweeps.md.
"""


def add_parser(sub: Any) -> None:
    """Register ``sweep``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    p = sub.add_parser(
        "sweep",
        help="run a study (a TOML sweep spec) as Dask tasks; resumable, one record per point",
        description=(
            "Run every point of a sweep spec (trainings, region maps, certified shares) as a Dask "
            "task: on a local cluster of --workers processes (127.0.0.1 only), or on the cluster "
            "of the scheduler at --scheduler. Each point's record is written atomically when it "
            "finishes; a re-run skips finished points; a failed point is recorded and the others "
            "go on; a task whose worker dies is retried. Ends with results.csv/.parquet and the "
            "study's report (Table 3, Table 5, Fig. 4, Fig. 5 or the certificate table)."),
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("spec", metavar="SPEC", help="TOML sweep spec (see analysis/sweeps/)")
    p.add_argument("--out", required=True, metavar="DIR", help="sweep folder (new, or to resume)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="address of a running Dask scheduler, e.g. tcp://10.0.0.5:8786")
    where.add_argument("--workers", metavar="N",
                       help="worker processes of the local cluster (default: the cores)")
    p.add_argument("--retries", default="2", metavar="N",
                   help="extra attempts of a task whose workers died (default 2)")
    p.add_argument("--check", action="store_true",
                   help="check the spec and list its points; run nothing")
    p.add_argument("--no-progress", action="store_true", help="progress lines instead of a bar")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run ``sweep``; 0 when every point is done, 1 when some failed, 130 when interrupted.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab sweep``.

    Returns
    -------
    int
        Exit code: 0 when every point is done (or with ``--check``, after listing the
        points), 1 when some point failed, 130 when interrupted (finished points are
        kept; a rerun resumes); bad input raises
        :class:`~stringstab.errors.StringStabError` (exit 2 from
        :func:`stringstab.cli.main`).
    """
    from ..io import check_output_dir, claim_folder
    from ..memory import available_bytes, human_bytes
    from ..sweep import dask_client, load_spec, read_records, run_sweep
    from ..sweep.cluster import dashboard_address
    from ..sweep.tasks import point_bytes, refuse_points_too_big

    t0 = time.perf_counter()
    spec = load_spec(args.spec)
    if args.check:
        print(f"{args.spec}: {len(spec)} points of kind {spec.kind}, study {spec.study}")
        for pt in spec.points:
            print(f"  {pt.id}  {pt.label}  " + ", ".join(f"{k}={v}" for k, v in pt.varied.items())
                  + f"  (memory: about {human_bytes(point_bytes(pt.kind, pt.settings))})")
        return 0
    workers = None if args.workers is None else _int("--workers", args.workers, 1, "workers")
    retries = _int("--retries", args.retries, 0, "retries")
    check_output_dir(args.out, what="--out")
    claim_folder(args.out, command="sweep", what="--out")
    if args.scheduler is None:  # the local cluster shares this machine's memory among its workers
        from ..parallel import cpu_count

        n = workers or cpu_count()
        refuse_points_too_big(spec.points, available_bytes() / n,
                              f"each of the {n} local worker(s) (the memory available, shared)")
    warn_beyond_sensible(args, [("workers", workers, "--workers"), ("retries", retries, "--retries")])
    try:  # SIGTERM arrives as KeyboardInterrupt too (stringstab.cli.main)
        with dask_client(args.scheduler, workers) as client:
            dash = dashboard_address(client)
            if dash is not None and importlib.util.find_spec("bokeh") is None:
                dash += " (its pages need bokeh: pip install bokeh)"
            print(f"dask scheduler {client.scheduler.address}; dashboard: "
                  + (dash or "not served"), flush=True)
            summary = run_sweep(spec, args.out, client=client, retries=retries,
                                progress=False if args.no_progress else None,
                                log=lambda s: print(s, flush=True))
    except KeyboardInterrupt:
        recs = read_records(args.out, spec)
        n = sum(r.get("status") == "done" for r in recs.values())
        print(f"interrupted: {n} of {len(spec)} points are finished in {args.out}; run the same "
              "command again to resume", flush=True)
        return 130
    from ..report import command_line
    from ..report.commands import sweep_report
    from ..sweep.report import sweep_table

    summary["files"] += sweep_report(spec, sweep_table(spec, args.out), summary["files"], args.out,
                                     command=command_line(args), started=t0).write(args.out)
    print(f"sweep {spec.name}: {summary['done']} points done, {summary['failed']} failed, "
          f"{summary['skipped']} finished before; {summary['seconds']:.1f} s")
    print(f"wrote {', '.join(summary['files'])} in {args.out}/")
    return 0 if summary["failed"] == 0 else 1
