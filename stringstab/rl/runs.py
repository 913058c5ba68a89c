"""Opening a training run folder and choosing held-out leaders (shared by evaluate and compare)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from ..errors import StringStabError
from .checkpoint import read_json
from .policy import Policy, load_policy

__all__ = ["open_run", "test_leaders"]


def open_run(folder: str | os.PathLike[str]) -> tuple[dict[str, Any], Policy]:
    """``run.json`` and the policy of a folder written by ``stringstab train``.

    Parameters
    ----------
    folder : str or path-like
        The training run folder.

    Returns
    -------
    run : dict
        ``run.json``, with ``"folder"`` added.
    policy : Policy
        The run's policy (:func:`~stringstab.rl.policy.load_policy`).

    Raises
    ------
    StringStabError
        For a missing folder, a folder not written by ``stringstab train``, a missing, altered
        or foreign policy file, or a policy of another ``algo`` than the run's.
    """
    from .train import RUN_FORMAT

    d = Path(folder)
    if not d.is_dir():
        raise StringStabError(f"run folder {str(d)!r} does not exist; expected a folder written "
                              "by stringstab train")
    if not (d / "run.json").is_file():
        raise StringStabError(f"{str(d)!r} is not a training run folder: it has no run.json; "
                              "expected a folder written by stringstab train")
    run = read_json(d / "run.json", fmt=RUN_FORMAT, what="run folder")
    policy = load_policy(d)
    if run.get("algo") != policy.algo:
        raise StringStabError(f"run folder {str(d)!r}: run.json says --algo {run.get('algo')!r} "
                              f"but the policy was trained by {policy.algo!r}")
    run["folder"] = str(d)
    return run, policy


def test_leaders(specs: list[str] | None, *, dt: float, seconds: float = 30.0) -> tuple[list[Any], str]:
    """The held-out leaders: ``None`` or ``["test"]`` → the bundled test episodes; else files.

    Parameters
    ----------
    specs : list of str or None
        ``None``/``["test"]`` for the bundled test split, else paths of ``t, v[, a]`` CSV or
        NGSIM files (:func:`~stringstab.rl.episodes.leaders_from_files`, test part).
    dt : float
        Sample step, s.
    seconds : float
        Episode length of the bundled split, s.

    Returns
    -------
    leaders : list
        Trajectories or following pairs.
    description : str
        Where they come from, for reports.

    Raises
    ------
    StringStabError
        If ``"test"`` is mixed with file paths, or a file cannot be read.
    """
    from .episodes import default_leaders, leaders_from_files

    if not specs or specs == ["test"]:
        return list(default_leaders("test", seconds=seconds, dt=dt)), "bundled test episodes"
    if "test" in specs:
        raise StringStabError(f"--leaders: expected 'test' alone or file paths; got {specs}")
    return leaders_from_files(specs, "test", seconds=seconds, dt=dt), ", ".join(specs)
