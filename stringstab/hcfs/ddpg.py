"""Training the HCFS DDPG with the trainer of :mod:`stringstab.rl` (imported lazily).

:func:`train_ddpg` trains a DDPG (HCFS §III-A, the algorithm of Lillicrap et al.) on
:class:`~stringstab.hcfs.env.HCFSVectorEnv` with the HCFS reward through
``stringstab.rl.train(DDPGConfig(...), env=...)`` and returns it as an acceleration policy on
SI states.  :func:`save_ddpg` / :func:`load_ddpg` store it with its observation scales.  When
``stringstab.rl`` (or torch, which it needs) is not installed, they raise a
:class:`~stringstab.errors.StringStabError` naming the missing piece.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from ..errors import StringStabError
from ..io import atomic_write_text
from .env import HCFSVectorEnv
from .policy import ScaledPolicy

__all__ = ["load_ddpg", "save_ddpg", "train_ddpg"]

_SIDECAR = "hcfs_policy.json"


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


def train_ddpg(*, total_steps: int = 100_000, seed: int = 0, env: HCFSVectorEnv | None = None,
               **config: Any) -> ScaledPolicy:
    """Train the HCFS DDPG and return it as an acceleration policy on SI eq-3 states.

    Parameters
    ----------
    total_steps : int
        Environment steps (summed over sub-environments, as :mod:`stringstab.rl` counts them).
    seed : int
        Seed of the trainer and of the environment.
    env : HCFSVectorEnv, optional
        The training environment (default: 4 platoons of 6 followers behind the bundled cycles).
    **config
        Further ``DDPGConfig`` fields.

    Returns
    -------
    ScaledPolicy
        The deterministic actor, labelled ``"DDPG (...)"``.

    Raises
    ------
    StringStabError
        If :mod:`stringstab.rl` or torch is missing.
    """
    rl = _rl()
    env = env if env is not None else HCFSVectorEnv()
    result = rl.train(rl.DDPGConfig(total_steps=int(total_steps), seed=int(seed), **config), env=env)
    return ScaledPolicy(result.policy, env.scales,
                        label=f"DDPG (stringstab.rl, HCFS reward, {int(total_steps)} steps, seed {int(seed)})")


def save_ddpg(policy: ScaledPolicy, directory: str | Path) -> Path:
    """Save a trained policy (``policy.policy.save``) with its scales and label beside it."""
    d = Path(directory)
    if not hasattr(policy.policy, "save"):
        raise StringStabError(f"only a policy trained by stringstab.rl can be saved; got {type(policy.policy).__name__}")
    policy.policy.save(d)
    atomic_write_text(d / _SIDECAR, json.dumps({"scales": policy.scales.tolist(), "label": policy.label}) + "\n")
    return d


def load_ddpg(directory: str | Path) -> ScaledPolicy:
    """Load a policy saved by :func:`save_ddpg` (``stringstab.rl.load_policy`` + scales).

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
    return ScaledPolicy(rl.load_policy(d), scales, label=label)
