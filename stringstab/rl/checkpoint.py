"""Checkpoints that are safe to load: tensors in safetensors files, everything else in JSON.

Nothing here unpickles: tensors are read by :func:`safetensors.numpy.load_file` (a JSON header and
raw little-endian buffers; no code), and every tensor file's SHA-256 is recorded in the JSON that
names it and verified *before* the file is parsed, so a truncated or altered file is refused.
Each JSON file carries a ``format`` tag; a file from another program, another kind of checkpoint
or another agent is refused.  Every refusal is one :class:`~stringstab.errors.StringStabError`
naming the file, what was expected and what was found.

A training checkpoint is a folder ``checkpoint/ckpt-<step>/`` holding ``state.json`` (config,
counters, RNG states of NumPy and the environment, optimiser hyper-parameters, the episode log)
and ``agent.safetensors`` (networks, targets, Adam moments, torch's RNG state) and
``buffer.safetensors`` (the replay memory and the environments' arrays) and, for gain actions,
``repair.safetensors`` (the repair's kept verdicts, :meth:`stringstab.tuning.repair.GainRepair.state`).  It is written into a
staging folder, renamed into place, and only then named by ``checkpoint/latest.json`` (written
atomically), so an interrupted write never replaces a good checkpoint.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..io import atomic_path, atomic_write_text, dumps_json

__all__ = [
    "CHECKPOINT_FORMAT",
    "latest_checkpoint",
    "read_json",
    "read_tensors",
    "sha256",
    "write_checkpoint",
    "write_tensors",
]

#: Format tags of the JSON files.
CHECKPOINT_FORMAT = "stringstab-rl-checkpoint/1"
LATEST_FORMAT = "stringstab-rl-latest/1"


def sha256(path: str | os.PathLike[str]) -> str:
    """Hex SHA-256 of a file.

    Parameters
    ----------
    path : str or path-like
        The file, read in 1 MiB blocks.

    Returns
    -------
    str
        64 lower-case hex digits.
    """
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def write_tensors(path: str | os.PathLike[str], arrays: dict[str, npt.NDArray[Any]]) -> str:
    """Write NumPy arrays to a safetensors file atomically; returns its SHA-256.

    Parameters
    ----------
    path : str or path-like
        The ``.safetensors`` file to write (complete or absent).
    arrays : dict of str to ndarray
        The tensors by name (made C-contiguous before writing).

    Returns
    -------
    str
        The hex SHA-256 of the file written (:func:`sha256`), to record in the JSON naming it.
    """
    from safetensors.numpy import save_file

    clean = {k: np.ascontiguousarray(v) for k, v in arrays.items()}
    with atomic_path(path, what="checkpoint file") as tmp:
        save_file(clean, str(tmp))
    return sha256(path)


def read_tensors(path: str | os.PathLike[str], *, expected_sha256: str | None,
                 what: str = "checkpoint") -> dict[str, npt.NDArray[Any]]:
    """Arrays of a safetensors file, after checking its SHA-256 (no code is ever run).

    Parameters
    ----------
    path : str or path-like
        The ``.safetensors`` file.
    expected_sha256 : str or None
        The hex digest recorded when it was written; None skips the check.
    what : str
        What the file is, for the error messages (``"checkpoint"``, ``"policy"``).

    Returns
    -------
    dict of str to ndarray
        The tensors by name.

    Raises
    ------
    StringStabError
        If the file is missing, its checksum differs, or it is not a safetensors file.
    """
    p = Path(path)
    if not p.is_file():
        raise StringStabError(f"{what}: missing file {str(p)!r}; expected a safetensors file "
                              "written by stringstab train")
    if expected_sha256 is not None:
        found = sha256(p)
        if found != expected_sha256:
            raise StringStabError(
                f"{what}: {str(p)!r} was altered or truncated (SHA-256 {found[:12]}..., "
                f"expected {expected_sha256[:12]}...); refusing to load it")
    from safetensors.numpy import load_file

    try:
        return dict(load_file(str(p)))
    except Exception as e:  # safetensors raises its own error types
        raise StringStabError(
            f"{what}: {str(p)!r} is not a safetensors tensor file ({type(e).__name__}: {e}); "
            "refusing to load it") from e


def read_json(path: str | os.PathLike[str], *, fmt: str, what: str) -> dict[str, Any]:
    """A JSON object whose ``format`` tag is ``fmt``.

    Parameters
    ----------
    path : str or path-like
        The JSON file (UTF-8).
    fmt : str
        The ``format`` tag expected (e.g. :data:`CHECKPOINT_FORMAT`).
    what : str
        What the file is, for the error messages.

    Returns
    -------
    dict
        The decoded object, ``format`` included.

    Raises
    ------
    StringStabError
        If the file is missing, not JSON, not an object, or has another format tag.
    """
    from ..io.text_input import read_text

    p = Path(path)
    if not p.exists():
        raise StringStabError(f"{what}: missing file {str(p)!r}")
    text = read_text(p, label=f"{what}: {str(p)!r}", expected=f"a JSON file of format {fmt!r}")
    try:
        doc = json.loads(text)
    except ValueError as e:
        raise StringStabError(f"{what}: {str(p)!r} is not valid JSON ({e})") from e
    if not isinstance(doc, dict) or doc.get("format") != fmt:
        found = doc.get("format") if isinstance(doc, dict) else type(doc).__name__
        raise StringStabError(f"{what}: {str(p)!r} has format {found!r}; expected {fmt!r}")
    return doc


def write_checkpoint(folder: str | os.PathLike[str], step: int, state: dict[str, Any],
                     tensors: dict[str, dict[str, npt.NDArray[Any]]], *, keep: int = 1) -> Path:
    """Write a training checkpoint under ``folder`` (see the module docstring).

    Parameters
    ----------
    folder : path
        The run's ``checkpoint`` folder (created if needed).
    step : int
        Environment steps done (names the checkpoint).
    state : dict
        JSON-ready state; ``format`` and ``files`` are added.
    tensors : dict
        ``{file stem: {name: array}}``, one safetensors file each.
    keep : int
        Checkpoints kept (the newest).

    Returns
    -------
    Path
        The checkpoint's folder.
    """
    root = Path(folder)
    root.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=".staging-", dir=root))
    try:
        files = {f"{stem}.safetensors": write_tensors(staging / f"{stem}.safetensors", arrs)
                 for stem, arrs in tensors.items()}
        doc = {"format": CHECKPOINT_FORMAT, "step": int(step), **state, "files": files}
        atomic_write_text(staging / "state.json", dumps_json(doc, indent=None))
        name = f"ckpt-{int(step):010d}"
        final = root / name
        if final.exists():
            shutil.rmtree(final)
        os.replace(staging, final)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    atomic_write_text(root / "latest.json",
                      dumps_json({"format": LATEST_FORMAT, "checkpoint": name}))
    olds = sorted(p for p in root.iterdir() if p.is_dir() and p.name.startswith("ckpt-"))
    for old in olds[:-keep] if keep > 0 else []:
        if old.name != name:
            shutil.rmtree(old, ignore_errors=True)
    return final


def latest_checkpoint(folder: str | os.PathLike[str]) -> tuple[dict[str, Any],
                                                             dict[str, dict[str, npt.NDArray[Any]]]]:
    """Read the newest checkpoint under ``folder``: (state, {file stem: arrays}), verified.

    Parameters
    ----------
    folder : str or path-like
        A run's ``checkpoint`` folder, holding ``latest.json`` and ``ckpt-<step>/`` folders
        (:func:`write_checkpoint`).

    Returns
    -------
    state : dict
        The checkpoint's ``state.json`` (config, counters, RNG states, episode log, ``files``).
    tensors : dict of str to dict of str to ndarray
        The arrays of each tensor file, by file stem (``"agent"``, ``"buffer"``, ``"repair"``), each file's
        SHA-256 checked against ``state.json`` before it is parsed.

    Raises
    ------
    StringStabError
        If there is no checkpoint, or any file of it is missing, altered or foreign.
    """
    root = Path(folder)
    if not (root / "latest.json").is_file():
        raise StringStabError(f"no checkpoint in {str(root)!r}; expected a folder written by "
                              "stringstab train (with checkpoint/latest.json)")
    latest = read_json(root / "latest.json", fmt=LATEST_FORMAT, what="checkpoint")
    name = latest.get("checkpoint")
    if not isinstance(name, str) or not name.startswith("ckpt-") or "/" in name or ".." in name:
        raise StringStabError(f"checkpoint: {str(root / 'latest.json')!r} names {name!r}; "
                              "expected a folder ckpt-<step>")
    d = root / name
    state = read_json(d / "state.json", fmt=CHECKPOINT_FORMAT, what="checkpoint")
    files = state.get("files")
    if not isinstance(files, dict) or not files:
        raise StringStabError(f"checkpoint: {str(d / 'state.json')!r} lists no tensor files")
    tensors = {}
    for fname, digest in files.items():
        if not (isinstance(fname, str) and fname.endswith(".safetensors") and "/" not in fname
                and isinstance(digest, str)):
            raise StringStabError(f"checkpoint: unexpected file entry {fname!r} in state.json")
        tensors[fname[: -len(".safetensors")]] = read_tensors(d / fname, expected_sha256=digest)
    return state, tensors
