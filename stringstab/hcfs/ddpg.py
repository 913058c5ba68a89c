"""The HCFS DDPG: its training with the trainer of :mod:`stringstab.rl`, and the one shipped.

The trainer is imported lazily.  :func:`train_hcfs_ddpg` trains a DDPG (HCFS §III-A, the
algorithm of Lillicrap et al.) on :class:`~stringstab.hcfs.env.HCFSVectorEnv` with the HCFS
reward (eqs 4-6) through ``stringstab.rl.train(DDPGConfig(...), envs=...)`` and returns it as an
acceleration policy on SI states; :func:`train_ddpg` returns only that policy.  With ``out`` the
trainer's run folder (policy, checkpoint, ``train_log.csv``, ``rolling_reward.png``,
``summary.json``) receives ``hcfs_policy.json`` beside it, and the folder is what
``stringstab hcfs verify --policy DIR`` reads.  :func:`save_ddpg` / :func:`load_ddpg` store and
load a policy with its observation scales; loading goes through
:func:`stringstab.rl.load_policy`, which checks the SHA-256 of the safetensors file and never
runs code from it.

:func:`load_bundled_ddpg` loads the DDPG shipped in ``stringstab/data/policies/hcfs_ddpg``
(its README says which command, seed and commit produced it).

When ``stringstab.rl`` (or torch, which it needs) is not installed, these raise a
:class:`~stringstab.errors.StringStabError` naming the missing piece.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from .._version import __version__
from ..errors import StringStabError
from ..io import atomic_write_text, dumps_json
from .env import HCFSVectorEnv
from .policy import AccelerationPolicy, LeaderSpeedMatcher, ScaledPolicy

__all__ = ["BUNDLED_POLICY", "HCFSTraining", "bundled_policy_dir", "candidate", "load_bundled_ddpg",
           "load_ddpg", "save_ddpg", "train_ddpg", "train_hcfs_ddpg"]

_SIDECAR = "hcfs_policy.json"
#: Folder of the bundled DDPG inside the package.
BUNDLED_POLICY = "data/policies/hcfs_ddpg"


def _rl() -> Any:
    try:
        import stringstab.rl as rl
    except ImportError as e:
        missing = getattr(e, "name", None) or str(e)
        if missing in ("stringstab.rl", "stringstab"):
            what = ("the policy trainer stringstab.rl (the trainer issue), which is not part of "
                    "this installation")
        else:
            what = f"the trainer stringstab.rl, which failed to import ({missing} is missing; " \
                   "install the rl extra: pip install -e '.[rl]')"
        raise StringStabError(f"training or loading the HCFS DDPG needs {what}") from e
    return rl


def _torch_missing(e: ImportError) -> StringStabError:
    """The error for a missing torch, which stringstab.rl imports only where a network runs."""
    return StringStabError(f"training or loading the HCFS DDPG needs torch, which is not installed "
                           f"({e}); install the rl extra: pip install -e '.[rl]' (or use --policy "
                           "stand-in)")


@dataclass
class HCFSTraining:
    """What :func:`train_hcfs_ddpg` returns.

    Attributes
    ----------
    policy : ScaledPolicy
        The deterministic actor on SI eq-3 states, labelled ``"DDPG (...)"``.
    result : stringstab.rl.TrainResult
        The trainer's result (episodes, timing, config).
    training : dict
        What ``hcfs_policy.json`` records about the training: leaders, platoon, reward
        weights, steps, seed, the trainer's configuration, the toolkit's version.
    out : Path or None
        The run folder.
    checkpoints : list of (int, Any)
        ``(step, on_checkpoint(step, policy))`` at every checkpoint, when ``on_checkpoint``
        was given.
    """

    policy: ScaledPolicy
    result: Any
    training: dict[str, Any] = field(default_factory=dict)
    out: Path | None = None
    checkpoints: list[tuple[int, Any]] = field(default_factory=list)


def _describe(env: HCFSVectorEnv, cfg: Any, total_steps: int, seed: int) -> dict[str, Any]:
    as_dict = getattr(cfg, "as_dict", None)
    return {
        "leaders": list(env.leader_names),
        "num_platoons": env.P, "n_followers": env.N, "num_envs": env.num_envs,
        "episode_seconds": round((env.window - 1) * env.dt, 9), "dt": env.dt,
        "jerk_limit": None if env.step_limit is None else env.step_limit / env.dt,
        "delay": env.delay, "length": env.length, "spacing": env.spacing,
        "accel_bounds": [env.accel_min, env.accel_max], **env.weights,
        "total_steps": int(total_steps), "seed": int(seed),
        "config": as_dict() if callable(as_dict) else None,
        "stringstab_version": __version__,
    }


def train_hcfs_ddpg(*, total_steps: int = 100_000, seed: int = 0, env: HCFSVectorEnv | None = None,
                    out: str | Path | None = None, progress: bool | None = None,
                    on_checkpoint: Callable[[int, ScaledPolicy], Any] | None = None,
                    **config: Any) -> HCFSTraining:
    """Train the HCFS DDPG; optionally into a run folder that ``hcfs verify --policy`` reads.

    Parameters
    ----------
    total_steps : int
        Environment steps (summed over sub-environments, as :mod:`stringstab.rl` counts them).
    seed : int
        Seed of the trainer and of the environment.
    env : HCFSVectorEnv, optional
        The training environment (default: 4 platoons of 6 followers behind
        :func:`~stringstab.hcfs.leaders.training_leader`, UDDS at half speed from 600 s).
    out : path, optional
        A new (absent or empty) run folder: the trainer's files and ``hcfs_policy.json``.
    progress : bool, optional
        The trainer's progress bar (default: when stderr is a terminal).
    on_checkpoint : callable, optional
        ``on_checkpoint(step, policy)`` at every checkpoint of the run folder (every
        ``checkpoint_every`` steps and at the end; needs ``out``) with the deterministic policy
        saved there — e.g. to evaluate it on held-out leaders, which the training reward (with
        exploration noise) does not show.  Its returns are kept in
        :attr:`HCFSTraining.checkpoints`.
    **config
        Further ``DDPGConfig`` fields (IDL Table 1 defaults otherwise; the HCFS paper's
        Table II is lost).

    Returns
    -------
    HCFSTraining

    Raises
    ------
    StringStabError
        If :mod:`stringstab.rl` or torch is missing, a config field is bad or ``out`` is not a
        new folder.
    """
    rl = _rl()
    env = env if env is not None else HCFSVectorEnv()
    cfg = rl.DDPGConfig(total_steps=int(total_steps), seed=int(seed), **config)
    kwargs: dict[str, Any] = {}
    if out is not None:
        kwargs["out"] = Path(out)
    if progress is not None:
        kwargs["progress"] = progress
    seen: list[tuple[int, Any]] = []
    if on_checkpoint is not None:
        if out is None:
            raise StringStabError("on_checkpoint needs a run folder (out)")
        folder, scales = Path(out), env.scales

        def log(_line: str) -> None:  # called by the trainer right after it saved the policy
            from stringstab.rl.checkpoint import LATEST_FORMAT, read_json

            name = str(read_json(folder / "checkpoint" / "latest.json", fmt=LATEST_FORMAT,
                                 what="checkpoint").get("checkpoint", ""))
            step = int(name.removeprefix("ckpt-"))
            if seen and seen[-1][0] == step:  # the final checkpoint can repeat the last one
                return
            pol = ScaledPolicy(rl.load_policy(folder), scales, torch_threads=1)
            seen.append((step, on_checkpoint(step, pol)))

        kwargs["log"] = log
    try:
        result = rl.train(cfg, envs=env, **kwargs)
        if getattr(result, "stopped_by", None) == "interrupted":
            raise KeyboardInterrupt
    except ModuleNotFoundError as e:
        if e.name != "torch":
            raise
        raise _torch_missing(e) from e
    label = f"DDPG (stringstab.rl, HCFS reward, {int(total_steps)} steps, seed {int(seed)})"
    policy = ScaledPolicy(result.policy, env.scales, label=label, torch_threads=1)
    training = _describe(env, cfg, total_steps, seed)
    if out is not None:
        _write_sidecar(Path(out), policy, training)
    return HCFSTraining(policy, result, training, None if out is None else Path(out), seen)


def train_ddpg(*, total_steps: int = 100_000, seed: int = 0, env: HCFSVectorEnv | None = None,
               **config: Any) -> ScaledPolicy:
    """Train the HCFS DDPG and return it as an acceleration policy on SI eq-3 states.

    :func:`train_hcfs_ddpg` without a run folder.

    Parameters
    ----------
    total_steps : int
        Environment steps (summed over sub-environments).
    seed : int
        Seed of the trainer and of the environment.
    env : HCFSVectorEnv, optional
        The training environment (default: 4 platoons of 6 followers behind
        :func:`~stringstab.hcfs.leaders.training_leader`).
    **config
        Further ``DDPGConfig`` fields, and ``progress``/``on_checkpoint`` of
        :func:`train_hcfs_ddpg`.

    Returns
    -------
    ScaledPolicy
        The deterministic actor, labelled ``"DDPG (...)"``.

    Raises
    ------
    StringStabError
        If :mod:`stringstab.rl` or torch is missing.
    """
    return train_hcfs_ddpg(total_steps=total_steps, seed=seed, env=env, **config).policy


def _write_sidecar(d: Path, policy: ScaledPolicy, training: dict[str, Any] | None = None) -> None:
    doc: dict[str, Any] = {"scales": policy.scales.tolist(), "label": policy.label}
    if training is not None:
        doc["training"] = training
    atomic_write_text(d / _SIDECAR, dumps_json(doc))


def save_ddpg(policy: ScaledPolicy, directory: str | Path) -> Path:
    """Save a trained policy (``policy.policy.save``) with its scales and label beside it.

    Parameters
    ----------
    policy : ScaledPolicy
        A policy trained by :mod:`stringstab.rl` (:func:`train_ddpg`), with its eq-3 state
        scales and label.
    directory : str or Path
        The folder to write (``policy.json``, ``policy.safetensors`` and the HCFS sidecar).

    Returns
    -------
    Path
        ``directory``.

    Raises
    ------
    StringStabError
        If the wrapped policy was not trained by :mod:`stringstab.rl` (it cannot be saved).
    """
    d = Path(directory)
    if not hasattr(policy.policy, "save"):
        raise StringStabError(f"only a policy trained by stringstab.rl can be saved; got {type(policy.policy).__name__}")
    policy.policy.save(d)
    _write_sidecar(d, policy)
    return d


def load_ddpg(directory: str | Path) -> ScaledPolicy:
    """Load a policy saved by :func:`save_ddpg` or :func:`train_hcfs_ddpg` (``stringstab.rl.load_policy`` + scales).

    Parameters
    ----------
    directory : str or Path
        A folder written by :func:`save_ddpg` or ``stringstab hcfs train``.

    Returns
    -------
    ScaledPolicy
        The acceleration policy on SI eq-3 states, with its label.

    Raises
    ------
    StringStabError
        If the directory has no HCFS sidecar, or :mod:`stringstab.rl` refuses the files or is
        missing.
    """
    d = Path(directory)
    side = d / _SIDECAR
    try:
        meta = json.loads(side.read_text(encoding="utf-8"))
        scales, label = meta["scales"], str(meta["label"])
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise StringStabError(
            f"{str(d)!r} is not an HCFS policy directory: expected {_SIDECAR} with 'scales' and "
            f"'label' (written by save_ddpg); {e}"
        ) from e
    rl = _rl()
    try:
        net = rl.load_policy(d)
    except ModuleNotFoundError as e:
        if e.name != "torch":
            raise
        raise _torch_missing(e) from e
    return ScaledPolicy(net, scales, label=label, torch_threads=1)


def bundled_policy_dir() -> Path:
    """The folder of the DDPG shipped with the package.

    Returns
    -------
    pathlib.Path
        The folder inside the installed package.
    """
    return Path(str(resources.files("stringstab").joinpath(BUNDLED_POLICY)))


def load_bundled_ddpg() -> ScaledPolicy:
    """The DDPG shipped with the package, trained by ``stringstab hcfs train`` (see its README).

    Returns
    -------
    ScaledPolicy
        The bundled trained actor.

    Raises
    ------
    StringStabError
        If torch (the ``rl`` extra) is missing or the files were altered.
    """
    return load_ddpg(bundled_policy_dir())


def candidate(spec: str, *, what: str = "--policy") -> AccelerationPolicy:
    """The learned candidate a1 named by ``spec``: the bundled DDPG, the stand-in or a folder.

    ``"bundled"`` is :func:`load_bundled_ddpg`, ``"stand-in"``
    :class:`~stringstab.hcfs.policy.LeaderSpeedMatcher`, and a folder is one written by
    ``stringstab hcfs train`` / :func:`save_ddpg`.

    Parameters
    ----------
    spec : str
        ``"stand-in"``, ``"bundled"`` or a folder path.
    what : str
        The option that gave ``spec``, for the error message.

    Returns
    -------
    AccelerationPolicy
        The candidate a1 of the switch (HCFS eqs 12-14).

    Raises
    ------
    StringStabError
        For anything else, a folder that is not an HCFS policy, altered files, or a missing
        torch (except for ``"stand-in"``).

    Examples
    --------
    >>> candidate("stand-in").label.startswith("stand-in")
    True
    """
    if spec == "stand-in":
        return LeaderSpeedMatcher()
    if spec == "bundled":
        return load_bundled_ddpg()
    p = Path(spec)
    if not p.is_dir():
        raise StringStabError(f"{what} must be 'stand-in' or a directory written by 'stringstab hcfs "
                              f"train' (or 'bundled', the DDPG shipped with the package); got {spec!r}")
    return load_ddpg(p)
