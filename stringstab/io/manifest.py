"""A folder's manifest: which command wrote it, with which command line and inputs.

Every output folder holds :data:`MANIFEST`, written when a run succeeds
(:class:`~stringstab.io.OutputDir`, or :func:`stringstab.io.write_manifest` for a folder filled as
it goes, like a sweep's): the command, the version, the files it wrote and, from the command line
(:func:`invocation`), the arguments and the inputs' hashes.  :func:`claim_folder` refuses, before
any work, a folder whose manifest names another command, so two commands never mix their
outputs in one folder.
"""

from __future__ import annotations

import contextlib
import contextvars
import json
import os
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

from ..errors import StringStabError

__all__ = ["MANIFEST", "claim_folder", "invocation", "manifest_doc", "read_manifest"]

#: Name of the file in which an output folder lists what it wrote, and who wrote it.
MANIFEST = ".stringstab-manifest.json"


#: What produced the outputs being written (the command line and its inputs' hashes), set by
#: the command-line entry point (:func:`invocation`) and copied into every manifest.
_INVOCATION: contextvars.ContextVar[Any] = contextvars.ContextVar(
    "stringstab_invocation", default=None)


@contextlib.contextmanager
def invocation(doc: Any) -> Iterator[None]:
    """Within the block, every manifest (:func:`manifest_doc`) also records ``doc``.

    Parameters
    ----------
    doc : dict or callable
        JSON-serialisable entries, e.g. ``{"argv": [...], "inputs": {...}}``, or a callable
        returning them (called when a manifest is written: hashing inputs only when needed).

    Yields
    ------
    None
        Control returns to the block; the record is dropped when it ends.

    Examples
    --------
    >>> with invocation({"argv": ["stringstab", "demo"]}):
    ...     _INVOCATION.get()["argv"][1]
    'demo'
    """
    token = _INVOCATION.set(doc)
    try:
        yield
    finally:
        _INVOCATION.reset(token)


def read_manifest(folder: str | os.PathLike[str]) -> dict[str, Any] | None:
    """The manifest :data:`MANIFEST` of a folder a command wrote (None: none, or unreadable).

    Parameters
    ----------
    folder : path-like
        The folder.

    Returns
    -------
    dict or None
        The manifest (``command``, ``version``, ``files``, ``argv``, ...); None when there is
        none or it cannot be read (an unreadable manifest protects nothing).
    """
    m = Path(folder) / MANIFEST
    if not m.is_file():
        return None
    try:
        doc = json.loads(m.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return doc if isinstance(doc, dict) else None


def claim_folder(folder: str | os.PathLike[str], *, command: str, what: str = "output folder") -> None:
    """Refuse a folder whose manifest says another command wrote it (before any work).

    Parameters
    ----------
    folder : path-like
        The output folder (it may not exist yet).
    command : str
        The command that will write it (e.g. ``"sweep"``).
    what : str, default "output folder"
        What the folder is, as the first words of the error message.

    Raises
    ------
    StringStabError
        When :func:`read_manifest` names another command.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> root = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (root / MANIFEST).write_text('{"command": "region"}')
    >>> claim_folder(root, command="sweep")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: output folder: '...' holds the outputs of 'stringstab region'; expected an empty folder or one written by 'stringstab sweep'; choose another folder
    """
    old = read_manifest(folder)
    if old is not None and old.get("command") != command:
        raise StringStabError(
            f"{what}: {str(folder)!r} holds the outputs of 'stringstab {old.get('command')}'; "
            f"expected an empty folder or one written by 'stringstab {command}'; "
            "choose another folder"
        )


def manifest_doc(command: str, files: Iterable[str] = (),
                 extra: dict[str, Any] | None = None) -> dict[str, Any]:
    """The manifest of a folder ``command`` wrote: command, version, files, command line, ``extra``.

    Parameters
    ----------
    command : str
        The command that wrote it.
    files : iterable of str, default ()
        The files it wrote (relative paths), which its next run may replace.
    extra : dict, optional
        More entries (e.g. the policy an evaluation is of).

    Returns
    -------
    dict
        JSON-ready; the command line and inputs are those of the current :func:`invocation`.

    Examples
    --------
    >>> with invocation({"argv": ["stringstab", "sweep"]}):
    ...     sorted(manifest_doc("sweep"))
    ['argv', 'command', 'files', 'version']
    """
    from .._version import __version__

    inv = _INVOCATION.get()
    return {"command": command, "version": __version__, "files": list(files),
            **((inv() if callable(inv) else inv) or {}), **(extra or {})}
