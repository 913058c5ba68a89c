"""The training loop: ``train(config) -> TrainResult`` (CleanRL's loop, importable and resumable).

Each vector step: the actor proposes actions for all ``num_envs`` environments (uniformly random
before ``learning_starts``), Gaussian exploration noise is added (std ``exploration_noise`` × the
action half-range, Table 1) and the result clipped to the bounds; the environments apply them —
for IDL through the action wrapper that rate limits and repairs the proposed gains
(:class:`~stringstab.rl.envs.RepairedGains`, built with the environments by
:func:`~stringstab.rl.envs.make_env`); the transitions enter the replay memory (a sub-episode
that ended contributes its last state from ``info["final_obs"]``; only a termination, i.e. a
collision, stops the bootstrap); then ``updates_per_step`` gradient steps are taken (:class:`~stringstab.rl.agent.Agent`).

Stopping (§4.1.2): after ``stop_episodes`` collision-free episode ends (700 in the paper) or
``total_steps`` environment steps, whichever comes first.

With ``out``, the run folder holds a checkpoint every ``checkpoint_every`` steps and at the end
(:mod:`~stringstab.rl.checkpoint`), the policy (:mod:`~stringstab.rl.policy`), the episode log
(``train_log.csv``), the rolling-reward curve (``rolling_reward.png``, the paper's Fig. 3, window
10) and ``summary.json``.  The folder appears with the first checkpoint, and every checkpoint
also writes the log and the summary (``stopped_by: "checkpoint"`` until the run ends), each file
whole while Ctrl-C is held: whenever a run is stopped (a second Ctrl-C raises at once), it leaves
no folder or a resumable one with its log and summary.  ``resume=True`` continues the newest checkpoint: networks, optimisers,
the replay memory, the RNG states of NumPy, torch and the environments, the environments' state
every counter and the repair's kept verdicts (:meth:`~stringstab.tuning.repair.GainRepair.state`)
are restored, so an interrupted run ends bit for bit where an uninterrupted one would.
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import io
import os
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import StringStabError
from ..io import atomic_path, atomic_write_text, check_output_dir, dumps_json
from .config import TD3Config, config_from_dict, loop_info
from .policy import Policy

__all__ = ["RESUMABLE_FIELDS", "RUN_FORMAT", "TrainResult", "refuse_other_config", "train"]

#: Format tag of a run folder's ``run.json``.
RUN_FORMAT = "stringstab-rl-run/1"
#: Columns of ``train_log.csv``.
LOG_COLUMNS = ("episode", "step", "env", "length", "return", "mean_reward", "collision",
               "rolling_return")


@dataclass
class TrainResult:
    """What :func:`train` returns.

    Attributes
    ----------
    policy : Policy
        The trained deterministic policy.
    config : TD3Config
        The configuration.
    steps : int
        Environment steps taken (all environments).
    episodes : list of dict
        One row per finished episode (``LOG_COLUMNS``).
    stopped_by : str
        ``"steps"`` (budget) or ``"episodes"`` (the collision-free-ends rule).
    seconds : float
        Wall-clock time of this call (a resumed run counts only its own part).
    timing : dict
        Seconds in the environment (repair included), in the repair, in gradient updates, and
        environment steps per second.
    repair : dict or None
        The repair's statistics (:attr:`stringstab.tuning.repair.GainRepair.stats`) for an IDL run.
    out : Path or None
        The run folder.
    """

    policy: Policy
    config: TD3Config
    steps: int
    episodes: list[dict[str, Any]]
    stopped_by: str
    seconds: float
    timing: dict[str, float] = field(default_factory=dict)
    repair: dict[str, float] | None = None
    out: Path | None = None


def _rolling(returns: list[float], window: int = 10) -> float:
    """The paper's rolling reward: mean of the last ``window`` episode returns (Fig. 3)."""
    tail = returns[-window:]
    return float(np.mean(tail)) if tail else float("nan")


def _policy_info(config: TD3Config, obs_dim: int, act_dim: int, low: Any, high: Any,
                 repair: Any) -> dict[str, Any]:
    return {"algo": config.algo, "action": config.action, "obs_dim": int(obs_dim),
            "act_dim": int(act_dim), "low": [float(v) for v in low],
            "high": [float(v) for v in high], "hidden": list(config.hidden),
            "tau": config.tau, "delta": config.delta, "headway": config.headway, "dt": config.dt,
            "observe": list(config.observe), "gain_rate": config.gain_rate,
            "repair": repair.describe() if repair is not None else None,
            **loop_info(config)}


def _check_env(env: Any) -> tuple[int, int, Any, Any]:
    from gymnasium import spaces
    from gymnasium.vector import AutoresetMode

    obs_space = getattr(env, "single_observation_space", None)
    act_space = getattr(env, "single_action_space", None)
    if not (isinstance(obs_space, spaces.Box) and isinstance(act_space, spaces.Box)):
        raise StringStabError("env: expected a gymnasium VectorEnv with Box observation and action "
                              f"spaces; got {type(obs_space).__name__} and {type(act_space).__name__}")
    mode = getattr(env, "metadata", {}).get("autoreset_mode")
    if mode != AutoresetMode.SAME_STEP:
        raise StringStabError(f"env: expected same-step autoreset (AutoresetMode.SAME_STEP); found {mode!r}")
    low, high = np.asarray(act_space.low, np.float64), np.asarray(act_space.high, np.float64)
    if not (np.isfinite(low).all() and np.isfinite(high).all()):
        raise StringStabError("env: the action space must have finite bounds")
    return int(np.prod(obs_space.shape)), int(np.prod(act_space.shape)), low, high


def _write_log(rows: list[dict[str, Any]]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(LOG_COLUMNS)
    for r in rows:
        w.writerow([r[c] if not isinstance(r[c], float) else f"{r[c]:.6g}" for c in LOG_COLUMNS])
    return buf.getvalue()


#: The fields a resumed run may change: the step budget and the checkpoint interval.
RESUMABLE_FIELDS = ("total_steps", "checkpoint_every")


def refuse_other_config(saved: TD3Config, config: TD3Config) -> None:
    """Refuse to resume a checkpoint written with another configuration, naming what differs.

    Parameters
    ----------
    saved : TD3Config
        The checkpoint's configuration.
    config : TD3Config
        The one asked for now.

    Raises
    ------
    StringStabError
        When a field other than :data:`RESUMABLE_FIELDS` differs (or the class does): each
        field with the checkpoint's value (expected) and the one given (found).

    Examples
    --------
    >>> from stringstab.rl import config_for
    >>> refuse_other_config(config_for("ddpg", seed=0), config_for("ddpg", seed=1, num_envs=4))
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: --resume: the checkpoint was written with another configuration; expected its seed = 0, num_envs = 8; got seed = 1, num_envs = 4 (only the step budget and the checkpoint interval may change on resume)
    """
    if type(saved) is not type(config):
        raise StringStabError(f"--resume: the checkpoint is a {type(saved).__name__} run; expected "
                              f"{type(saved).__name__}, got {type(config).__name__}")
    differ = [f.name for f in dataclasses.fields(saved) if f.name not in RESUMABLE_FIELDS
              and getattr(saved, f.name) != getattr(config, f.name)]
    if differ:
        def values(c: TD3Config) -> str:
            return ", ".join(f"{n} = {getattr(c, n)!r}" for n in differ)

        raise StringStabError(
            "--resume: the checkpoint was written with another configuration; expected its "
            f"{values(saved)}; got {values(config)} (only the step budget and the checkpoint "
            "interval may change on resume)")


def check_run_folder(out: Path, *, resume: bool, config: TD3Config) -> None:
    """Before any work: a new run needs an empty or absent folder; a resumed one its own run.

    Parameters
    ----------
    out : Path
        The run folder (``--out``).
    resume : bool
        Whether the run continues the one in ``out``.
    config : TD3Config
        The run's config; a resumed run must be of the same ``algo``.

    Raises
    ------
    StringStabError
        If ``out`` cannot be an output folder, a new run's folder has visible files in it, or a
        resumed folder holds no run, a run of another ``algo`` or a checkpoint of another
        configuration (:func:`refuse_other_config`).
    """
    check_output_dir(out, what="--out")
    if resume:
        from .checkpoint import CHECKPOINT_FORMAT, LATEST_FORMAT, read_json

        run = read_json(out / "run.json", fmt=RUN_FORMAT, what="--resume")
        if run.get("algo") != config.algo:
            raise StringStabError(
                f"--resume: {str(out)!r} holds a run of --algo {run.get('algo')!r}; "
                f"expected --algo {config.algo!r}")
        latest = out / "checkpoint" / "latest.json"
        if latest.is_file():  # the configuration, before any work (the tensors are read later)
            name = str(read_json(latest, fmt=LATEST_FORMAT, what="--resume").get("checkpoint"))
            state = out / "checkpoint" / name / "state.json"
            if "/" not in name and ".." not in name and state.is_file():
                doc = read_json(state, fmt=CHECKPOINT_FORMAT, what="--resume").get("config")
                refuse_other_config(config_from_dict(doc, source="checkpoint config"), config)
    elif out.exists() and any(not p.name.startswith(".") for p in out.iterdir()):
        raise StringStabError(f"--out: {str(out)!r} is not empty; choose a new folder, or pass "
                              "--resume to continue the run in it")


def train(config: TD3Config, *, envs: Any = None, out: str | os.PathLike[str] | None = None,
          resume: bool = False, progress: bool | None = None, leaders: list[Any] | None = None,
          log: Any = None) -> TrainResult:
    """Train a TD3 or DDPG agent (IDL or pure RL) and return its policy.

    Parameters
    ----------
    config : TD3Config or DDPGConfig
        Hyper-parameters (:func:`~stringstab.rl.config.config_for` builds them by name).
    envs : gymnasium VectorEnv, optional
        Box spaces, same-step autoreset, ``info["final_obs"]`` / ``info["_final_obs"]`` (as
        :class:`~stringstab.traffic.env.BatchedCarFollowingEnv`).  Default:
        :func:`~stringstab.rl.envs.make_env` of ``config`` and ``leaders``.  For gain actions
        they must be wrapped in the repair (:class:`~stringstab.rl.envs.RepairedGains`), which
        the loop reads for the proposal penalty, the timings and the repair statistics.
        Resuming needs ``state_dict``/``load_state_dict`` on the environments.
    out : path, optional
        Run folder (checkpoints, policy, log, figure, summary).
    resume : bool
        Continue the newest checkpoint in ``out`` up to ``config.total_steps``.
    progress : bool, optional
        None or True: a tqdm bar (steps/s, rolling episode reward) when stderr is a terminal,
        else one line every 10 s with the time left (:class:`stringstab.progress.Progress`);
        False: silent.
    leaders : list, optional
        Training leaders of the default environment.
    log : callable, optional
        Receives one line per checkpoint.

    Returns
    -------
    TrainResult
        ``stopped_by`` is ``"interrupted"`` when Ctrl-C stopped it (with ``out``: at a step
        boundary, the run folder written as at the end of a budget, so resume continues it).

    Raises
    ------
    StringStabError
        On a bad environment, run folder or checkpoint.

    Examples
    --------
    >>> from stringstab.rl import config_for
    >>> res = train(config_for("ddpg", total_steps=64, learning_starts=32, batch_size=16,
    ...                        num_envs=4, seed=0), progress=False)
    >>> res.steps, res.policy(np.zeros((2, 3))).shape
    (64, (2, 1))
    """
    interrupt = _StepInterrupt(active=out is not None)
    try:
        result = _train(config, envs=envs, out=out, resume=resume, progress=progress,
                        leaders=leaders, log=log, interrupt=interrupt)
    finally:
        interrupt.restore()
    if interrupt.caught and result.stopped_by != "interrupted":
        # Ctrl-C after the last step (while the outputs were written): the run is complete,
        # and the caller still learns that the user asked to stop
        result = dataclasses.replace(result, stopped_by="interrupted")
    return result


def _train(config: TD3Config, *, envs: Any, out: str | os.PathLike[str] | None, resume: bool,
           progress: bool | None, leaders: list[Any] | None, log: Any,
           interrupt: _StepInterrupt) -> TrainResult:
    import torch

    from .agent import Agent
    from .buffer import ReplayBuffer

    t_start = time.perf_counter()
    out_path = Path(out) if out is not None else None
    if out_path is not None:
        check_run_folder(out_path, resume=resume, config=config)
    elif resume:
        raise StringStabError("resume needs the run folder (out)")
    torch.set_num_threads(config.torch_threads)
    torch.manual_seed(config.seed)
    from .envs import make_env, repair_of

    envs = make_env(config, leaders) if envs is None else envs
    obs_dim, act_dim, low, high = _check_env(envs)
    n_env = int(envs.num_envs)
    repair = repair_of(envs)
    if config.action == "gains" and repair is None:
        raise StringStabError("envs: gain actions need the environments wrapped in the repair "
                              "(stringstab.rl.envs.RepairedGains, as make_env builds them); "
                              "found no RepairedGains")
    if repair is not None and repair.method != "off" and repair.reaction_delay:
        repair.lattice()  # a θ_r at which no lattice gain is certified: refused before any file
    agent = Agent(config, obs_dim, act_dim, low=low, high=high,
                  action_filter=repair.approximate if repair is not None else None)
    buffer = ReplayBuffer(config.buffer_size, obs_dim=obs_dim, act_dim=act_dim, seed=config.seed + 1)
    rng = np.random.default_rng(config.seed + 2)
    half = (high - low) / 2.0
    obs, _ = envs.reset(seed=config.seed)
    step, clean_ends = 0, 0
    ep_ret, ep_len = np.zeros(n_env), np.zeros(n_env, dtype=np.int64)
    episodes: list[dict[str, Any]] = []
    returns: list[float] = []
    info_fn = _policy_info(config, obs_dim, act_dim, low, high, repair)

    if resume:
        assert out_path is not None
        from .checkpoint import latest_checkpoint

        state, tensors = latest_checkpoint(out_path / "checkpoint")
        refuse_other_config(config_from_dict(state.get("config"), source="checkpoint config"),
                            config)
        if not hasattr(envs, "load_state_dict"):
            raise StringStabError("resume: the environment has no load_state_dict()")
        agent.load_state(state["agent"], {k: torch.as_tensor(np.array(v))
                                          for k, v in tensors["agent"].items()
                                          if not k.startswith("rng.")})
        torch.set_rng_state(torch.as_tensor(np.array(tensors["agent"]["rng.torch"])))
        buf_arrays = {k[len("buffer."):]: v for k, v in tensors["buffer"].items()
                      if k.startswith("buffer.")}
        buffer.load_state(state["buffer"], buf_arrays)
        env_arrays = {k[len("env."):]: v for k, v in tensors["buffer"].items() if k.startswith("env.")}
        envs.load_state_dict(state["env"], env_arrays)
        obs = np.array(tensors["buffer"]["obs_now"])
        rng.bit_generator.state = state["rng"]
        c = state["counters"]
        step, clean_ends = int(c["step"]), int(c["clean_ends"])
        ep_ret, ep_len = np.array(tensors["buffer"]["ep_ret"]), np.array(tensors["buffer"]["ep_len"])
        episodes = list(state["episodes"])
        returns = [float(r["return"]) for r in episodes]
        if repair is not None and "repair" in tensors:
            # the repair's kept verdicts, in order (a checkpoint without them, written before
            # they were saved, resumes with none kept: docs/training.md "Resuming")
            repair.load_state(state.get("repair", {}), tensors["repair"])

    def result_now(stopped_by: str) -> TrainResult:
        seconds = time.perf_counter() - t_start
        rep_s = (float(repair.stats["seconds"]) - rep0) if repair is not None else 0.0
        timing = {"env_seconds": t_env, "repair_seconds": rep_s, "update_seconds": t_upd,
                  "total_seconds": seconds,
                  "steps_per_second": steps_here / seconds if seconds else 0.0,
                  "repair_share": rep_s / seconds if seconds else 0.0}
        return TrainResult(Policy(agent.actor, info_fn), config, step, episodes, stopped_by,
                           seconds, timing, dict(repair.stats) if repair is not None else None,
                           out_path)

    def checkpoint(final: TrainResult | None = None) -> None:
        """The run folder as it stands, its files written whole whatever Ctrl-C does meanwhile.

        The folder is created at the first checkpoint (a run stopped before it leaves nothing),
        and every checkpoint also writes ``train_log.csv`` and ``summary.json`` (``stopped_by``
        ``"checkpoint"`` until the run ends): a second Ctrl-C, which raises at once, leaves a
        resumable folder with its log and summary, or no folder.
        """
        if out_path is None:
            return
        with interrupt.held():
            _checkpoint(final)

    def _checkpoint(final: TrainResult | None) -> None:
        assert out_path is not None
        from .checkpoint import write_checkpoint

        if not resume and not (out_path / "run.json").is_file():
            out_path.mkdir(parents=True, exist_ok=True)
            atomic_write_text(out_path / "config.json", dumps_json(config.as_dict()))
            atomic_write_text(out_path / "run.json", dumps_json(  # last: it makes a run folder
                {"format": RUN_FORMAT, "algo": config.algo, "action": config.action}))
        agent_meta, agent_t = agent.state()
        arrs = {k: v.numpy() for k, v in agent_t.items()}
        arrs["rng.torch"] = torch.get_rng_state().numpy()
        env_meta, env_arrays = envs.state_dict() if hasattr(envs, "state_dict") else ({}, {})
        barr: dict[str, Any] = {f"buffer.{k}": v for k, v in buffer.arrays().items()}
        barr.update({f"env.{k}": v for k, v in env_arrays.items()})
        barr.update(obs_now=np.asarray(obs), ep_ret=ep_ret, ep_len=ep_len)
        st = {"config": config.as_dict(), "agent": agent_meta, "buffer": buffer.state(),
              "env": env_meta, "rng": rng.bit_generator.state,
              "counters": {"step": step, "clean_ends": clean_ends}, "episodes": episodes}
        files = {"agent": arrs, "buffer": barr}
        if repair is not None:  # its kept verdicts: the resumed run repairs as this one would
            st["repair"], files["repair"] = repair.state()
        write_checkpoint(out_path / "checkpoint", step, st, files)
        Policy(agent.actor, info_fn).save(out_path)
        _write_outputs(final or result_now("checkpoint"), figure=final is not None)
        if log is not None:
            log(f"checkpoint at step {step}: {len(episodes)} episodes, rolling return "
                f"{_rolling(returns):.3f}")

    # Ctrl-C stops the loop at the next step boundary (interrupt.caught): the checkpoint,
    # policy, log and summary are written as at the end of a budget, so resume continues there;
    # the run folder itself appears with the first checkpoint (checkpoint())

    # a bar on a terminal, one line every 10 s with the time left otherwise (False: silent)
    from ..progress import Progress

    meter = Progress(config.total_steps, f"train {config.algo}", unit="steps",
                     enabled=progress is not False, initial=step)
    bar: Any = meter.bar
    t_env = t_upd = 0.0
    steps_here = 0
    rep0 = float(repair.stats["seconds"]) if repair is not None else 0.0
    next_ckpt = (step // config.checkpoint_every + 1) * config.checkpoint_every
    stopped_by = "steps"
    while step < config.total_steps:
        if config.stop_episodes and clean_ends >= config.stop_episodes:
            stopped_by = "episodes"
            break
        if interrupt.caught:
            stopped_by = "interrupted"
            break
        if step < config.learning_starts:
            actions = rng.uniform(low, high, size=(n_env, act_dim))
        else:
            actions = agent.act(obs).astype(np.float64)
            actions += rng.normal(0.0, 1.0, size=actions.shape) * (half * config.exploration_noise)
            actions = np.clip(actions, low, high)
        t0 = time.perf_counter()
        next_obs, reward, term, trunc, info = envs.step(actions.astype(np.float32))
        t_env += time.perf_counter() - t0
        real_next = np.array(next_obs, dtype=np.float32, copy=True)
        done = np.asarray(term) | np.asarray(trunc)
        if done.any():
            mask = np.asarray(info.get("_final_obs", done), dtype=bool)
            real_next[mask] = np.asarray(info["final_obs"])[mask]
        stored = actions
        if config.store_action == "executed" and "gains" in info:
            stored = np.asarray(info["gains"], dtype=np.float64)
        buffer.add(obs, stored, reward, real_next, term)
        ep_ret += np.asarray(reward, dtype=np.float64)
        ep_len += 1
        obs = next_obs
        step += n_env
        steps_here += n_env
        for i in np.flatnonzero(done):
            returns.append(float(ep_ret[i]))
            collided = bool(term[i])
            clean_ends += 0 if collided else 1
            episodes.append({"episode": len(episodes) + 1, "step": step, "env": int(i),
                             "length": int(ep_len[i]), "return": float(ep_ret[i]),
                             "mean_reward": float(ep_ret[i] / max(ep_len[i], 1)),
                             "collision": int(collided), "rolling_return": _rolling(returns)})
            ep_ret[i], ep_len[i] = 0.0, 0
        if step >= config.learning_starts and len(buffer) >= config.batch_size:
            t0 = time.perf_counter()
            for _ in range(config.updates_per_step):
                agent.update(buffer.sample(config.batch_size))
            t_upd += time.perf_counter() - t0
        meter.update(n_env)
        if bar is not None:
            el = max(bar.format_dict.get("elapsed", 0.0), 1e-9)
            bar.set_postfix({"steps/s": f"{steps_here / el:.0f}", "episodes": len(episodes),
                             "rolling": f"{_rolling(returns):.2f}"}, refresh=False)
        if step >= next_ckpt:
            checkpoint()
            next_ckpt = (step // config.checkpoint_every + 1) * config.checkpoint_every
    else:
        if config.stop_episodes and clean_ends >= config.stop_episodes:
            stopped_by = "episodes"
    interrupt.hold()  # the last outputs: a further Ctrl-C would leave a folder without its summary
    meter.close()
    result = result_now(stopped_by)
    checkpoint(result)
    return result


class _StepInterrupt:
    """SIGINT recorded instead of raised (a second Ctrl-C raises at once), main thread only.

    Once the loop is over (:meth:`hold`), every Ctrl-C is recorded: the final checkpoint, log
    and summary are written whole, so an interrupted run's folder is always resumable.
    """

    def __init__(self, active: bool = True) -> None:
        import signal
        import threading

        self.caught = False
        self._old: Any = None
        if active and threading.current_thread() is threading.main_thread():
            self._old = signal.signal(signal.SIGINT, self._handle)

    def _handle(self, signum: int, frame: Any) -> None:
        import signal

        self.caught = True
        signal.signal(signal.SIGINT, signal.default_int_handler)

    def _record(self, signum: int, frame: Any) -> None:
        self.caught = True

    def hold(self) -> None:
        """From now on record every Ctrl-C (the last checkpoint, log and summary take a moment)."""
        import signal

        if self._old is not None:
            signal.signal(signal.SIGINT, self._record)

    @contextlib.contextmanager
    def held(self) -> Iterator[None]:
        """Record every Ctrl-C inside (a checkpoint's files written whole).

        Afterwards Ctrl-C acts as before, or raises at once when one was caught meanwhile.
        """
        import signal

        if self._old is None:
            yield
            return
        before = signal.signal(signal.SIGINT, self._record)
        try:
            yield
        finally:
            if before != self._record:  # (after hold() every Ctrl-C is recorded to the end)
                signal.signal(signal.SIGINT, signal.default_int_handler if self.caught else before)

    def restore(self) -> None:
        import signal

        if self._old is not None:
            signal.signal(signal.SIGINT, self._old)
            self._old = None


def _write_outputs(result: TrainResult, *, figure: bool = True) -> None:
    """``train_log.csv``, ``rolling_reward.png`` (unless not ``figure``) and ``summary.json``."""
    out = result.out
    assert out is not None
    atomic_write_text(out / "train_log.csv", _write_log(result.episodes))
    if figure:
        from matplotlib.figure import Figure

        from .plots import plot_rolling_reward

        fig = Figure(figsize=(6.4, 3.6), layout="constrained")
        plot_rolling_reward(result.episodes, ax=fig.subplots(), label=result.config.algo)
        with atomic_path(out / "rolling_reward.png") as tmp:
            fig.savefig(tmp, dpi=110)
    n = len(result.episodes)
    coll = sum(r["collision"] for r in result.episodes)
    summary = {
        "algo": result.config.algo, "steps": result.steps, "episodes": n,
        "collision_free_ends": n - coll, "collisions": coll, "stopped_by": result.stopped_by,
        "rolling_return": _rolling([r["return"] for r in result.episodes]),
        "timing_this_call": result.timing, "repair": result.repair,
        "load_average": list(os.getloadavg()),
    }
    atomic_write_text(out / "summary.json", dumps_json(summary))
