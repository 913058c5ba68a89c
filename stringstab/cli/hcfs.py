"""The ``stringstab hcfs`` commands: ``verify`` (the HCFS jerk theorem) and ``train`` (its DDPG).

``stringstab hcfs verify`` checks the HCFS jerk theorem in closed loop and writes a report;
``stringstab hcfs train`` trains the HCFS DDPG into a folder that ``verify --policy`` reads.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import shlex
from pathlib import Path
from typing import Any

from ..errors import StringStabError

__all__ = ["add_parser", "run", "run_train", "run_verify"]


def add_parser(sub: Any) -> None:
    """Register ``hcfs`` (with its sub-commands ``verify`` and ``train``).

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    from ..hcfs.constants import BETA, PAPER_JERK_LIMIT
    from ..traffic.cycles import CYCLES
    from ..traffic.synthetic import SYNTHETIC

    p = sub.add_parser(
        "hcfs",
        help="the HCFS hybrid DDPG/CACC strategy: verify its jerk theorem in closed loop",
        description="The HCFS paper's hybrid car-following strategy (DDPG and CACC switched by "
                    "reward, eqs 12-14) and its jerk theorem.",
    )
    hs = p.add_subparsers(dest="hcfs_command", metavar="SUBCOMMAND")
    hs.required = True
    v = hs.add_parser(
        "verify",
        help="simulate HCFS for jerk limits J and check the theorem's premises and conclusion at every frame",
        description=(
            "Simulate N followers (T = 0.2 s, 5 ms V2V delay, HCFS section IV) behind each leader "
            "under CACC alone, the learned policy alone, HCFS by eqs 12-14 and HCFS with a "
            "jerk-safe variant, each candidate rate-limited to J*T; evaluate the theorem's "
            "premises (P1, P2: candidates rate-limited; P3: a1 = a2 at the previous frame) and "
            "its conclusion |a_k - a_(k-1)| <= J T at every frame, and the bound that holds "
            "without P3.  Writes report.md, report.json and figures like the paper's Figs 4-6.  "
            "Exit 0 when no frame falsifies the theorem where its premises hold (nor the bound, "
            "nor the jerk-safe variant), 1 otherwise, 2 on bad input."
        ),
        epilog=(
            f"Leaders: cycles {', '.join(sorted(CYCLES))}; synthetic {', '.join(SYNTHETIC)} "
            "(NAME:key=value,...); or a CSV file with columns 't, v' or 't, v, a' (SI units). "
            f"The paper's figures compare the jerk with 2a_max/T = {PAPER_JERK_LIMIT:g} m/s^3, "
            "which the acceleration bounds alone guarantee."
        ),
    )
    v.add_argument("--jerk-limit", "-J", nargs="+", required=True, metavar="J",
                   help="jerk limits J in m/s^3 (each > 0 and at most 1e6; one above "
                        "(a_max - a_min)/T, 30 at the defaults, never binds: a warning)")
    v.add_argument("--followers", "-N", type=int, default=8, metavar="N",
                   help="followers per platoon (the paper uses 4, 6, 8; default 8)")
    v.add_argument("--leader", nargs="+", default=["udds"], metavar="SPEC",
                   help="one or more leaders (default: udds); also hcfs-train, hcfs-case1, "
                        "hcfs-case2, hcfs-case3 (the paper's leaders as far as the bundled data "
                        "allows: UDDS at half speed, see docs/hcfs.md)")
    v.add_argument("--duration", type=float, default=None, metavar="S",
                   help="keep only the first S seconds of each leader")
    v.add_argument("--beta", default=str(BETA), metavar="B",
                   help=f"soft-switch coefficient at a switch, in [0, 1] (eq 14: {BETA:g})")
    v.add_argument("--policy", default="bundled", metavar="bundled|stand-in|DIR",
                   help="the learned candidate: 'bundled' (default: the DDPG shipped with the "
                        "package, trained by 'stringstab hcfs train'), 'stand-in' (a hand-written, "
                        "deliberately imperfect law, labelled as such) or a folder written by "
                        "'stringstab hcfs train' or stringstab.hcfs.save_ddpg; needs the rl extra "
                        "(torch) unless 'stand-in'")
    v.add_argument("--no-figures", action="store_true", help="skip the figures")
    v.add_argument("--out", required=True, metavar="DIR", help="output directory")
    v.add_argument("--no-progress", action="store_true", help="no progress bar or lines (stderr)")
    from ..hcfs.constants import ACCEL_MAX as HCFS_ACCEL_MAX
    from ..hcfs.constants import ACCEL_MIN as HCFS_ACCEL_MIN
    from ._common import add_limit_arguments

    add_limit_arguments(v, accel_min=HCFS_ACCEL_MIN, accel_max=HCFS_ACCEL_MAX,
                        source="HCFS section IV, v_max IDL Table 2")
    v.set_defaults(func=run)

    t = hs.add_parser(
        "train",
        help="train the HCFS DDPG (HCFS reward, eqs 4-6) into a folder that 'hcfs verify --policy' reads",
        description=(
            "Train the HCFS paper's DDPG with its reward (eqs 4-6: speed error to the leader and "
            "jerk) through stringstab.rl, in platoons of --followers followers (section IV: 6) "
            "behind --leader (default hcfs-train: UDDS at half speed from 600 s to the end, the "
            "paper's training leader as far as the bundled data allows), T = 0.2 s, 5 ms V2V "
            "delay.  Writes the trainer's run folder (policy.safetensors + policy.json, "
            "checkpoint, train_log.csv, rolling_reward.png, summary.json) and hcfs_policy.json "
            "into --out, then compares the DDPG with CACC and the stand-in on the three held-out "
            "test cases (evaluation.json).  Exit 0 on success, 2 on bad input."
        ),
    )
    t.add_argument("--steps", default="400000", metavar="N",
                   help="environment steps, summed over the followers (default 400000, about a "
                        "minute on 2 cores)")
    t.add_argument("--seed", default="0", metavar="S", help="seed (default 0)")
    t.add_argument("--out", required=True, metavar="DIR", help="run folder (new or empty)")
    t.add_argument("--leader", nargs="+", default=["hcfs-train"], metavar="SPEC",
                   help="training leaders (default hcfs-train); cycles, synthetic profiles, CSV "
                        "files as for verify")
    t.add_argument("--platoons", default="4", metavar="P",
                   help="platoons stepped together (default 4)")
    t.add_argument("--followers", "-N", default="6", metavar="N",
                   help="followers per training platoon (section IV: 6)")
    t.add_argument("--episode-seconds", default="60", metavar="S",
                   help="length of a training episode, s (default 60)")
    t.add_argument("--no-progress", action="store_true", help="no progress bar")
    t.set_defaults(func=run)


def run_verify(args: argparse.Namespace) -> int:
    """Run ``hcfs verify``: validate everything, simulate, check, write the report.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab hcfs verify``.

    Returns
    -------
    int
        Exit code: 0 when no frame falsifies the theorem, the bound or the jerk-safe
        guarantee, 1 otherwise; bad input raises
        :class:`~stringstab.errors.StringStabError` (exit 2 from
        :func:`stringstab.cli.main`).
    """
    import time

    from ..hcfs.constants import DT
    from ..hcfs.ddpg import candidate
    from ..hcfs.leaders import hcfs_leader
    from ..hcfs.report import write_report
    from ..hcfs.switching import check_beta
    from ..hcfs.verify import verify
    from ..io import OutputDir
    from ..params import positive
    from ..ranges import check_magnitude
    from ._common import integer, warn_beyond_sensible

    t0 = time.perf_counter()
    Js = [check_magnitude("jerk", positive("--jerk-limit J", s, unit=" m/s^3"), name="--jerk-limit J")
          for s in args.jerk_limit]
    beta = check_beta(args.beta)
    integer("--followers", args.followers, 1)  # the memory estimate bounds it (below)
    if args.duration is not None and not (math.isfinite(args.duration) and args.duration > 0):
        raise StringStabError(f"--duration must be a finite number of seconds > 0; got {args.duration!r}")
    if args.duration is not None:
        check_magnitude("duration", args.duration, name="--duration")
    out = OutputDir(args.out, command="hcfs verify", what="--out")  # checked before any work
    leaders = [hcfs_leader(s, dt=DT, duration=args.duration) for s in args.leader]
    from ..memory import refuse_platoon

    refuse_platoon(args.followers * max(len(leaders), 1), max(len(ld.speed) for ld in leaders),
                   f"--followers {args.followers}")
    from ._common import checked_leaders, limits_from_args

    limits = limits_from_args(args)
    checked_leaders(args, leaders, limits, settling=cacc_settling_time())
    warn_beyond_sensible(args, [("followers", args.followers, "--followers")])
    _note_jerk_limits(args, Js, limits)
    policy = candidate(args.policy)
    command = shlex.join([
        "stringstab", "hcfs", "verify", "--jerk-limit", *[f"{J:g}" for J in Js],
        "--followers", str(args.followers), "--leader", *args.leader,
        *(["--duration", f"{args.duration:g}"] if args.duration is not None else []),
        "--beta", f"{beta:g}", "--policy", args.policy,
        *(["--no-figures"] if args.no_figures else []), "--out", args.out,
        "--v-max", f"{limits.speed_max:g}", "--a-min", f"{limits.accel_min:g}",
        "--a-max", f"{limits.accel_max:g}",
    ])
    from ..progress import Progress

    with Progress(len(leaders), "stringstab hcfs verify", unit="leaders",
                  enabled=not args.no_progress) as bar:
        ver = verify(leaders, policy, jerk_limits=Js, n_followers=args.followers, beta=beta,
                     progress=bar.update, accel_min=limits.accel_min,
                     accel_max=limits.accel_max, speed_max=limits.speed_max)
    with contextlib.ExitStack() as stack:  # the figures are counted too: no silent minute
        def figures(total: int) -> Any:
            return stack.enter_context(Progress(
                total, "stringstab hcfs verify: figures", unit="figures",
                enabled=not args.no_progress and total > 0)).update

        with out:
            files = write_report(ver, out, figures=not args.no_figures, command=command,
                                 started=t0, progress=figures)
    print(f"HCFS jerk theorem, {args.followers} followers, beta = {beta:g}, a1 = {ver.runs[0].params['policy_label']}")
    for x in ver.results:
        if x["mode"] in ("paper", "safe"):
            t = x["totals"]
            print(f"  {x['leader']:>14s}  J = {x['jerk_limit']:<6g} {x['mode']:5s}: max jerk "
                  f"{t['max_jerk']:.3g} m/s^3 ({t['max_jerk_over_J']:.3g} J), P3 fails "
                  f"{t['P3_fails']}/{t['frames']}, conclusion fails {t['conclusion_fails']}, "
                  f"theorem violations {t['violations']}, bound violations {t['bound_violations']}")
    sm = ver.smallest_counterexample
    if sm is not None:
        print(f"smallest counterexample: |a1 - a2| = {sm.gap_prev:.3g} m/s^2 at the previous frame "
              f"({sm.leader}, J = {sm.jerk_limit:g}, follower {sm.vehicle}, t = {sm.t:.1f} s): "
              f"jerk {sm.jerk:.4g} > J")
    verdict = ("no frame falsifies the theorem, the bound or the jerk-safe variant" if ver.ok
               else f"{len(ver.violations)} frame(s) falsify a guarantee")
    n_fig = sum(name.endswith(".png") for name in files.values())
    print(f"{verdict}; wrote report.md, report.json" + (f" and {n_fig} figures" if n_fig else "")
          + f" to {args.out.rstrip('/')}/")
    return 0 if ver.ok else 1


def cacc_settling_time() -> float:
    """The 2 % settling time of the HCFS CACC candidate, s: ln 50 / σ with σ = −ln ρ / T.

    ρ is the spectral radius of the CACC's discrete closed loop
    (:func:`stringstab.hcfs.cacc.closed_loop_matrix`, the same for every platoon size: the map
    is block triangular with one 2 × 2 block per follower), T the frame (0.2 s): the slowest
    mode decays as ρ^k = e^{−σ k T}.

    Returns
    -------
    float
        The settling time, s (about 14 s at the default gains, ρ = 0.947).
    """
    import numpy as np

    from ..hcfs.cacc import closed_loop_matrix
    from ..hcfs.constants import DT
    from ..traffic.limits import SETTLING_FRACTION

    rho = float(max(abs(np.linalg.eigvals(closed_loop_matrix(1)))))
    return math.log(1.0 / SETTLING_FRACTION) / (-math.log(rho) / DT)


def _note_jerk_limits(args: argparse.Namespace, Js: list[float], limits: Any) -> None:
    """A note for each J that never binds: J T above the acceleration range a_max − a_min."""
    import sys

    from ..hcfs.constants import DT

    loose = (limits.accel_max - limits.accel_min) / DT
    for J in Js:
        if J > loose:
            print(f"stringstab hcfs verify: warning: --jerk-limit {J:g} m/s^3 is above the "
                  f"sensible range (up to (a_max - a_min)/T = {loose:g} m/s^3): a rate limit of "
                  f"{J * DT:g} m/s^2 per frame never binds within [{limits.accel_min:g}, "
                  f"{limits.accel_max:g}] m/s^2, so the theorem holds by the acceleration bounds "
                  "alone", file=sys.stderr)


def run_train(args: argparse.Namespace) -> int:
    """Run ``hcfs train``: validate everything, train, write the run folder, compare.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab hcfs train``.

    Returns
    -------
    int
        Exit code: 0 when training finished and the run folder was written; bad input
        raises :class:`~stringstab.errors.StringStabError` (exit 2 from
        :func:`stringstab.cli.main`).
    """
    from ..hcfs.constants import DT
    from ..hcfs.leaders import hcfs_leader
    from ..params import positive
    from ..ranges import check_magnitude
    from ._common import checked_leaders, warn_beyond_sensible
    from ._common import integer as _int

    steps = _int("--steps", args.steps, 1, "steps")
    seed = _int("--seed", args.seed, 0, "seed")
    platoons = _int("--platoons", args.platoons, 1)  # the memory estimate bounds them (below)
    followers = _int("--followers", args.followers, 1)
    seconds = check_magnitude("duration", positive("--episode-seconds", args.episode_seconds,
                                                   unit=" s"), name="--episode-seconds")
    from ..memory import refuse_platoon

    refuse_platoon(platoons * followers, round(seconds / DT) + 1,
                   f"--platoons {platoons} --followers {followers}")
    out = Path(args.out)
    _check_new_folder(out)
    leaders = [hcfs_leader(s, dt=DT) for s in args.leader]
    from ..hcfs.constants import ACCEL_MAX, ACCEL_MIN, SPEED_MAX
    from ..traffic.limits import Limits

    checked_leaders(args, leaders, Limits(accel_min=ACCEL_MIN, accel_max=ACCEL_MAX,
                                          speed_max=SPEED_MAX), settling=cacc_settling_time())
    warn_beyond_sensible(args, [("steps", steps, "--steps"), ("platoons", platoons, "--platoons"),
                                ("followers", followers, "--followers"),
                                ("duration", seconds, "--episode-seconds")])
    from ..hcfs.ddpg import train_hcfs_ddpg
    from ..hcfs.env import HCFSVectorEnv

    env = HCFSVectorEnv(platoons, leaders, n_followers=followers, episode_seconds=seconds)
    existed = out.exists()
    try:
        run = train_hcfs_ddpg(total_steps=steps, seed=seed, env=env, out=out,
                              progress=False if args.no_progress else None, stop_episodes=0)
    except KeyboardInterrupt:  # the folder was new or empty: leave it so (outputs absent)
        _empty(out, remove=not existed)
        raise
    res = run.result
    n = len(res.episodes)
    if n:
        tenth = max(1, n // 10)
        first, last = (sum(e["mean_reward"] for e in part) / len(part)
                       for part in (res.episodes[:tenth], res.episodes[-tenth:]))
        curve = (f"mean reward per step (with exploration noise) {first:.4f} in the first tenth "
                 f"of the episodes, {last:.4f} in the last")
    else:
        curve = f"no episode ended yet (one lasts {env.window - 1} steps per follower)"
    print(f"trained the HCFS DDPG: {res.steps} steps, {n} episodes behind "
          f"{', '.join(tr.name for tr in leaders)}, {res.timing['steps_per_second']:.0f} steps/s; "
          f"{curve}")
    from ..hcfs.compare import compare_controllers, comparison_markdown
    from ..hcfs.leaders import paper_cases
    from ..hcfs.policy import LeaderSpeedMatcher
    from ..io import atomic_write_text, dumps_json

    rows = compare_controllers(paper_cases(), run.policy, others={"stand-in": LeaderSpeedMatcher()})
    atomic_write_text(out / "evaluation.json", dumps_json({
        "what": "held-out test cases (hcfs-case1..3), every controller limited only by the "
                "acceleration bounds (J = 2 a_max / T)", "rows": rows}))
    print("held-out test cases, sums over followers and frames (HCFS Tables IV-VI):")
    print(comparison_markdown(rows), end="")
    print(f"wrote the policy, checkpoint, train_log.csv, rolling_reward.png, summary.json, "
          f"hcfs_policy.json and evaluation.json to {args.out.rstrip('/')}/; use it with "
          f"'stringstab hcfs verify --policy {args.out}'")
    return 0


def _empty(out: Path, *, remove: bool) -> None:
    """Delete what an interrupted ``hcfs train`` wrote into its new (or empty) folder."""
    import shutil

    if not out.is_dir():
        return
    for p in out.iterdir():
        if not p.name.startswith("."):
            shutil.rmtree(p) if p.is_dir() else p.unlink()
    if remove:
        shutil.rmtree(out, ignore_errors=True)


def _check_new_folder(out: Path) -> None:
    from ..io import check_output_dir

    check_output_dir(out, what="--out")
    if out.exists() and any(not p.name.startswith(".") for p in out.iterdir()):
        raise StringStabError(f"--out: expected a new or empty folder; {str(out)!r} is not empty")


def run(args: argparse.Namespace) -> int:
    """Dispatch ``hcfs`` sub-commands.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab hcfs``.

    Returns
    -------
    int
        Exit code: that of :func:`run_train` (``hcfs train``) or :func:`run_verify`
        (``hcfs verify``).
    """
    return run_train(args) if args.hcfs_command == "train" else run_verify(args)
