"""``stringstab train``: train the IDL agent or a pure TD3/DDPG baseline into a run folder."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..errors import StringStabError
from ._common import checked_leaders, warn_beyond_sensible
from ._common import integer as _int

__all__ = ["add_parser", "run"]


def add_parser(sub: Any) -> None:
    """Register ``train``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The ``stringstab`` sub-command set (:func:`stringstab.cli.build_parser`); the parser
        added sets ``func`` to :func:`run`.
    """
    from ..rl.config import ALGOS, REPAIRS

    p = sub.add_parser(
        "train",
        help="train an IDL policy (TD3 emitting certified gains) or a pure TD3/DDPG baseline",
        description=(
            "Train a TD3/DDPG agent on car-following episodes (the bundled driving cycles' "
            "training split and synthetic disturbances, or your own files). --algo idl: the "
            "action is K=(k_x,k_v,k_a) of the eq-4 law, repaired to certified gains before it "
            "acts; td3/ddpg: the action is the acceleration. Writes checkpoints, the policy, "
            "train_log.csv, rolling_reward.png and summary.json into --out."),
    )
    p.add_argument("--algo", required=True, metavar="ALGO",
                   help=f"agent: {', '.join(ALGOS)}")
    p.add_argument("--steps", required=True, metavar="N",
                   help="environment steps (budget; training also stops after 700 collision-free "
                        "episode ends, IDL §4.1.2)")
    p.add_argument("--seed", default="0", metavar="S", help="seed (default 0)")
    p.add_argument("--out", required=True, metavar="DIR", help="run folder (new, or with --resume)")
    p.add_argument("--resume", action="store_true",
                   help="continue the newest checkpoint in --out up to --steps")
    p.add_argument("--leaders", nargs="+", metavar="FILE",
                   help="train on these 't, v' CSV or NGSIM files instead of the bundled episodes")
    p.add_argument("--repair", choices=REPAIRS, default=None,
                   help="IDL repair (default projection; 'off' is the ablation)")
    p.add_argument("--num-envs", default=None, metavar="N", help="parallel environments (default 8)")
    p.add_argument("--stop-episodes", default=None, metavar="N",
                   help="stop after N collision-free episode ends (default 700; 0: only --steps)")
    p.add_argument("--paper", action="store_true",
                   help="IDL as printed: the eq-16 state, no gain rate limit, episodes started in "
                        "equilibrium (without the toolkit's three IDL options observe, gain_rate and start_spread; docs/training.md)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    from ._loop import add_loop_arguments

    add_loop_arguments(p)
    p.set_defaults(func=run)


#: The largest step budget accepted (a year at ~300 steps/s).
MAX_STEPS = 10**10


def run(args: argparse.Namespace) -> int:
    """Run ``train``.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line of ``stringstab train``.

    Returns
    -------
    int
        Exit code: 0 when training finished and the run folder was written, 130 when
        interrupted (the folder holds a checkpoint to ``--resume`` from); bad input
        raises :class:`~stringstab.errors.StringStabError` (exit 2 from
        :func:`stringstab.cli.main`).
    """
    from ..rl.config import config_for
    from ..rl.train import check_run_folder, train

    kw: dict[str, Any] = {"total_steps": _int("--steps", args.steps, 1),
                          "seed": _int("--seed", args.seed, 0, "seed")}
    if kw["total_steps"] > MAX_STEPS:
        raise StringStabError(
            f"--steps {kw['total_steps']} is far beyond any training run (about a year at 300 "
            f"steps/s is 1e10); expected at most {MAX_STEPS:.0e}")
    warn_beyond_sensible(args, [("steps", kw["total_steps"], "--steps")])
    if args.num_envs is not None:
        kw["num_envs"] = _int("--num-envs", args.num_envs, 1)
    if args.stop_episodes is not None:
        kw["stop_episodes"] = _int("--stop-episodes", args.stop_episodes, 0, "episodes")
    if args.repair is not None:
        if args.algo != "idl":
            raise StringStabError(f"--repair applies to --algo idl; got --algo {args.algo}")
        kw["repair"] = args.repair
    if args.paper and args.algo != "idl":
        raise StringStabError(f"--paper applies to --algo idl; got --algo {args.algo}")
    config, note = _with_loop(config_for(args.algo, paper=args.paper, **kw), args)
    if args.num_envs is not None:
        from ..memory import refuse_if_too_big, training_bytes

        refuse_if_too_big(f"--num-envs {config.num_envs}",
                          training_bytes(config.num_envs, config.buffer_size),
                          "expected fewer parallel environments (8 by default)")
    out = Path(args.out)
    check_run_folder(out, resume=args.resume, config=config)
    leaders = None
    if args.leaders:
        from ..rl.episodes import leaders_from_files

        leaders = leaders_from_files(args.leaders, "train", seconds=config.episode_seconds,
                                     dt=config.dt)
        from ..traffic.limits import Limits

        checked_leaders(args, leaders, Limits())  # the environments' limits: IDL Table 2
    res = train(config, out=out, resume=args.resume, progress=not args.no_progress,
                leaders=leaders, log=print)
    if res.stopped_by == "interrupted":
        import shlex
        import sys

        again = ["stringstab", "train", *_argv_of(args), "--resume"]
        print(f"stringstab train: interrupted at step {res.steps} of {config.total_steps}; {out}/ "
              f"holds its checkpoint, policy, train_log.csv and summary.json; continue with: "
              f"{shlex.join(again)}", file=sys.stderr)
        return 130
    n = len(res.episodes)
    coll = sum(e["collision"] for e in res.episodes)
    t = res.timing
    print(f"trained {config.algo}: {res.steps} steps, {n} episodes ({n - coll} collision-free "
          f"ends), stopped by {res.stopped_by}; {t['steps_per_second']:.0f} steps/s this call, "
          f"repair {100 * t['repair_share']:.1f}% of the time")
    print(f"wrote the policy, checkpoint, train_log.csv, rolling_reward.png and summary.json to {out}/")
    if note:
        print(note)
    _note_stale_evaluation(out)
    return 0


def _with_loop(config: Any, args: argparse.Namespace) -> tuple[Any, str | None]:
    """The config with ``--reaction-delay`` and the radio and sensor options (issues 25, 26).

    With θ_r > 0 the repair certifies with the continuous certificate at θ_r only: the
    sampled-data certificate with θ_r costs about 30-90 ms per step as a repair, so
    ``repair_sampled`` is turned off, and said (the note returned, printed once training ran).
    """
    from ._loop import radio_from_args, reaction_from_args

    theta = reaction_from_args(args)
    radio, sensors = radio_from_args(args, config.dt)
    loop: dict[str, Any] = {}
    note = None
    if theta:
        loop["reaction_delay"] = theta
        if config.action == "gains" and config.repair != "off" and config.repair_sampled:
            loop["repair_sampled"] = False
            note = (f"note: --reaction-delay {theta:g}: every executed gain was certified by the "
                    "continuous certificate at θ_r (exact); the sampled-data repair with θ_r "
                    "(TD3Config.repair_sampled=True from Python) costs about 30-90 ms per step, "
                    "so it was not required")
    if radio is not None:
        loop["radio"] = radio
    if sensors is not None:
        loop["sensors"] = sensors
    return (config.replace(**loop) if loop else config), note


def _note_stale_evaluation(out: Path) -> None:
    """Say so when ``out/evaluation/`` evaluated another policy than the one just written."""
    import json
    import sys

    from ..io import MANIFEST
    from ._provenance import policy_identity

    try:
        prev = json.loads((out / "evaluation" / MANIFEST).read_text(encoding="utf-8")).get("policy")
    except (OSError, ValueError, AttributeError):
        return
    now = policy_identity(out) or {}
    if isinstance(prev, dict) and ((prev.get("policy_sha256"), prev.get("steps"))
                                   != (now.get("policy_sha256"), now.get("steps"))):
        print(f"stringstab train: note: {out}/evaluation/ evaluated the policy at step "
              f"{prev.get('steps')}, not this one (step {now.get('steps')}); it is stale: run "
              f"'stringstab evaluate {out}' to replace it", file=sys.stderr)


def _argv_of(args: argparse.Namespace) -> list[str]:
    """The options of this run that a resume must repeat (the configuration is checked)."""
    out = ["--algo", args.algo, "--steps", str(args.steps), "--seed", str(args.seed),
           "--out", str(args.out)]
    for flag, name in (("--num-envs", "num_envs"), ("--stop-episodes", "stop_episodes"),
                       ("--repair", "repair")):
        if getattr(args, name, None) is not None:
            out += [flag, str(getattr(args, name))]
    if getattr(args, "paper", False):
        out.append("--paper")
    from ._loop import RADIO_FLAGS

    for name in ("reaction_delay", *RADIO_FLAGS):
        if getattr(args, name, None) is not None:
            out += ["--" + name.replace("_", "-"), str(getattr(args, name))]
    if getattr(args, "leaders", None):
        out += ["--leaders", *map(str, args.leaders)]
    return out
