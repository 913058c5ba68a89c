"""What produced an output folder: the command line and its inputs' hashes, for the manifest.

Every argument of the command that names an existing file is recorded with its SHA-256; one
that names a run folder (a ``policy.json`` in it) with its policy's hash and the training steps
behind it.  :func:`stringstab.cli.main` hands :func:`provenance` to
:func:`stringstab.io.manifest.invocation`, so every :class:`~stringstab.io.OutputDir` manifest
records them without a line in the commands.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

__all__ = ["file_sha256", "policy_identity", "provenance"]

_SKIP = {"out", "func", "command", "hcfs_command"}


def file_sha256(path: Path) -> str:
    """SHA-256 of a file's bytes (hex), read in 1 MiB blocks.

    Parameters
    ----------
    path : Path
        The file.

    Returns
    -------
    str
        The 64-character hex digest.
    """
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def policy_identity(folder: Path) -> dict[str, Any] | None:
    """A run folder's policy: SHA-256 of ``policy.json`` + weights, and its training steps.

    Parameters
    ----------
    folder : Path
        A folder written by ``stringstab train`` (or holding a saved policy).

    Returns
    -------
    dict or None
        ``{"policy_sha256", "steps"}`` (steps None when no summary or checkpoint says), None
        when the folder holds no ``policy.json``.
    """
    if not (folder / "policy.json").is_file():
        return None
    h = hashlib.sha256()
    for name in sorted(p.name for p in folder.iterdir() if p.name.startswith("policy.")):
        h.update(name.encode())
        h.update(file_sha256(folder / name).encode())
    steps = None
    for name, key in (("summary.json", "steps"),):
        try:
            steps = int(json.loads((folder / name).read_text(encoding="utf-8"))[key])
        except (OSError, ValueError, KeyError, TypeError):
            pass
    return {"policy_sha256": h.hexdigest(), "steps": steps}


def provenance(args: Any, argv: list[str]) -> dict[str, Any]:
    """``{"argv": [...], "inputs": {argument value: hash entry}}`` of a parsed command line.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments.
    argv : list of str
        The command line after ``stringstab``.

    Returns
    -------
    dict
    """
    inputs: dict[str, Any] = {}
    for key, value in vars(args).items():
        if key in _SKIP:
            continue
        for v in value if isinstance(value, list) else [value]:
            if not isinstance(v, str) or not v or v in inputs:
                continue
            p = Path(v)
            try:
                if p.is_file():
                    inputs[v] = {"sha256": file_sha256(p), "bytes": p.stat().st_size}
                elif p.is_dir():
                    ident = policy_identity(p)
                    if ident is not None:
                        inputs[v] = ident
            except OSError:
                continue
    return {"argv": ["stringstab", *argv], "inputs": inputs}
