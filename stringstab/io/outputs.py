"""Output files and folders that are checked before the work starts and written all-or-nothing.

Three guarantees, for every command of the toolkit:

1. **Checked first.**  :func:`check_output_file` and :func:`check_output_dir` (and
   :class:`OutputDir`, which calls the latter) refuse, with one sentence, a folder where a file
   is wanted and the reverse, a path through a file, and a place where nothing can be written —
   *before* any computation, so a long run never ends in a traceback.  One rule for files and
   folders alike: the missing folders on an output's path are created when the run succeeds
   (never when it fails).  Writability is probed by creating (and removing) a temporary file in
   the nearest existing folder, which is the only test that is right for root, ACLs and read-only
   file systems alike.
2. **Complete or absent.**  Files are written to a temporary name in the same folder and renamed
   into place (``os.replace``, atomic on POSIX), so a reader never sees half a file.
3. **One run per folder.**  An :class:`OutputDir` writes every file of a run into a staging folder
   and moves them in only when the run succeeds, deleting the files its own earlier run (listed in
   the folder's manifest, :data:`MANIFEST`) wrote and this one did not.  A command whose outputs
   have fixed names may instead declare them (``owns=``): then those of its names this run did
   not write are deleted.  Every run writes the manifest: the command, the version, the files
   and, from the command line (:func:`~stringstab.io.manifest.invocation`), the arguments and the inputs' hashes (a
   policy's hash and step count for an evaluation).  A failed run leaves the
   previous outputs untouched; a folder written by a *different* command is refused; files the
   toolkit did not write are never deleted.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path
from types import TracebackType
from typing import Any

from ..errors import StringStabError
from .manifest import MANIFEST, claim_folder, manifest_doc, read_manifest

__all__ = [
    "OutputDir",
    "atomic_path",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_output_dir",
    "check_output_file",
    "deferred_interrupt",
    "write_manifest",
]

_STAGING_PREFIX = ".stringstab-staging-"


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _reason(e: OSError) -> str:
    return e.strerror or str(e)


def _probe_writable(folder: Path, what: str) -> None:
    """Create and remove a temporary file in ``folder``; a clear error if that fails."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".stringstab-probe-", dir=folder)
    except OSError as e:
        raise StringStabError(
            f"{what}: cannot write in the folder {str(folder)!r} ({_reason(e)}); "
            "expected a folder you can write to"
        ) from e
    os.close(fd)
    os.unlink(tmp)


def check_output_file(path: str | os.PathLike[str], *, what: str = "output file") -> Path:
    """Check that a file can be written at ``path``, before any work is done.

    ``path`` must not be a folder, and the nearest existing folder on its path must be writable
    (probed by creating and removing a temporary file there).  Nothing is created: the missing
    folders are created when the file is written (:func:`atomic_path`), as an output folder's
    are (:func:`check_output_dir`): one rule for every command.

    Parameters
    ----------
    path : str or path-like
        The file to be written later (it may or may not exist).
    what : str, default "output file"
        What the file is, as the first words of the error message.

    Returns
    -------
    Path
        ``path`` as a :class:`~pathlib.Path`.

    Raises
    ------
    StringStabError
        One sentence naming the path, what was expected and what was found.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "a-file"
    >>> _ = f.write_text("x")
    >>> check_output_file(f / "x.json")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: output file: '...a-file' in '...a-file/x.json' is a file, not a folder
    """
    p = Path(path)
    if str(path) == "" or p.name in ("", ".", ".."):
        raise StringStabError(f"{what}: expected a file name; got {str(path)!r}")
    if p.is_dir():
        raise StringStabError(f"{what}: expected a file; {str(p)!r} is a folder")
    probe = p.parent
    while not probe.exists() and probe.parent != probe:
        probe = probe.parent
    if probe.exists() and not probe.is_dir():
        raise StringStabError(f"{what}: {str(probe)!r} in {str(p)!r} is a file, not a folder")
    if p.exists() and not p.is_file():
        raise StringStabError(f"{what}: expected a regular file; {str(p)!r} is something else")
    _probe_writable(probe, what)
    return p


def check_output_dir(path: str | os.PathLike[str], *, what: str = "output folder") -> Path:
    """Check that a folder can be written (or created, with its parents) at ``path``.

    Nothing is created: the nearest existing ancestor must be a writable folder (probed with a
    temporary file, removed at once).  The missing folders are created when the run succeeds,
    as an output file's are (:func:`check_output_file`): one rule for every command.

    Parameters
    ----------
    path : str or path-like
        The folder to be written later (it may not exist yet).
    what : str, default "output folder"
        What the folder is, as the first words of the error message.

    Returns
    -------
    Path
        ``path`` as a :class:`~pathlib.Path`.

    Raises
    ------
    StringStabError
        When ``path`` (or an ancestor) is a file, or nothing can be written there.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "a-file"
    >>> _ = f.write_text("x")
    >>> check_output_dir(f)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: output folder: expected a folder; '...a-file' is a file
    """
    p = Path(path)
    if str(path) == "":
        raise StringStabError(f"{what}: expected a folder path; got ''")
    if p.exists() and not p.is_dir():
        raise StringStabError(f"{what}: expected a folder; {str(p)!r} is a file")
    probe = p
    while not probe.exists():
        if probe.parent == probe:
            break
        probe = probe.parent
    if probe.exists() and not probe.is_dir():
        raise StringStabError(f"{what}: {str(probe)!r} in {str(p)!r} is a file, not a folder")
    _probe_writable(probe, what)
    return p


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str], *, what: str = "output file") -> Iterator[Path]:
    """A temporary path beside ``path`` that is renamed onto it if the block succeeds.

    For libraries that write to a file name themselves (``numpy.savez``, ``Figure.savefig``,
    ``safetensors``): the temporary name keeps ``path``'s suffix, so format detection works.
    If the block raises, the temporary file is removed and ``path`` is left as it was.

    Parameters
    ----------
    path : str or path-like
        The final file; its missing folders are created (the temporary file is created there)
        and removed again if the block fails.
    what : str, default "output file"
        What the file is, as the first words of an error message.

    Yields
    ------
    Path
        The temporary path to write to; renamed onto ``path`` (with the umask's permissions)
        when the block exits without an exception.

    Raises
    ------
    StringStabError
        When the temporary file cannot be created or renamed (the temporary file is removed).

    Examples
    --------
    >>> import tempfile, pathlib, numpy as np
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "a.npz"
    >>> with atomic_path(target) as tmp:
    ...     np.savez(tmp, x=np.arange(3))
    >>> np.load(target)["x"].tolist()
    [0, 1, 2]
    """
    p = Path(path)
    created = [q for q in p.parents if not q.exists()]
    try:
        p.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{p.stem}.", suffix=f".tmp{p.suffix}", dir=p.parent)
    except OSError as e:
        _remove_empty(created)
        raise StringStabError(f"{what}: cannot write {str(p)!r} ({_reason(e)})") from e
    os.close(fd)
    tmp_path = Path(tmp)
    try:
        yield tmp_path
        os.chmod(tmp_path, 0o666 & ~_umask())
        os.replace(tmp_path, p)
    except OSError as e:
        tmp_path.unlink(missing_ok=True)
        _remove_empty(created)
        raise StringStabError(f"{what}: cannot write {str(p)!r} ({_reason(e)})") from e
    except BaseException:
        tmp_path.unlink(missing_ok=True)
        _remove_empty(created)
        raise


def _remove_empty(folders: list[Path]) -> None:
    """Remove the folders a failed write created (deepest first; only if still empty)."""
    for q in folders:  # Path.parents order: deepest first
        with contextlib.suppress(OSError):
            q.rmdir()


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes, *, what: str = "output file") -> Path:
    """Write ``data`` to ``path`` atomically (temporary file + rename); returns the path.

    Parameters
    ----------
    path : str or path-like
        The file written; its folder must exist.
    data : bytes
        The complete contents.
    what : str, default "output file"
        What the file is, as the first words of an error message.

    Returns
    -------
    Path
        ``path`` as a :class:`~pathlib.Path`.

    Raises
    ------
    StringStabError
        When the file cannot be written (``path`` is then left as it was).
    """
    with atomic_path(path, what=what) as tmp, open(tmp, "wb") as fh:
        fh.write(data)
    return Path(path)


def atomic_write_text(path: str | os.PathLike[str], text: str, *, what: str = "output file") -> Path:
    r"""Write UTF-8 ``text`` to ``path`` atomically (temporary file + rename); returns the path.

    Parameters
    ----------
    path : str or path-like
        The file written; its folder must exist.
    text : str
        The complete contents, encoded as UTF-8.
    what : str, default "output file"
        What the file is, as the first words of an error message.

    Returns
    -------
    Path
        ``path`` as a :class:`~pathlib.Path`.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = atomic_write_text(pathlib.Path(tempfile.mkdtemp()) / "r.txt", "Γ ≤ 1\n")
    >>> p.read_text(encoding="utf-8")
    'Γ ≤ 1\n'
    """
    return atomic_write_bytes(path, text.encode("utf-8"), what=what)


@contextlib.contextmanager
def deferred_interrupt() -> Iterator[None]:
    """Hold Ctrl-C (SIGINT) until the block is done, then raise KeyboardInterrupt.

    For the few milliseconds that move finished files into place: an interrupt there would
    leave a mix of two runs.  Outside the main thread (where signals cannot be handled) the
    block runs unprotected.

    Yields
    ------
    None
        Control returns to the block; a held Ctrl-C is raised when it ends.

    Examples
    --------
    >>> with deferred_interrupt():
    ...     x = 1
    """
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    old = signal.signal(signal.SIGINT, lambda signum, frame: caught.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)
    if caught:
        raise KeyboardInterrupt


def write_manifest(folder: str | os.PathLike[str], *, command: str, files: Iterable[str] = (),
                   extra: dict[str, Any] | None = None, what: str = "output folder") -> None:
    """Write a folder's manifest atomically (:func:`stringstab.io.manifest.manifest_doc`).

    For a folder filled as it goes (a sweep's) rather than through :class:`OutputDir`.

    Parameters
    ----------
    folder : path-like
        An existing folder.
    command : str
        The command that wrote it.
    files : iterable of str, default ()
        The files it wrote (relative paths), which its next run may replace.
    extra : dict, optional
        More entries (e.g. the policy an evaluation is of).
    what : str, default "output folder"
        What the folder is, for an error message.
    """
    doc = manifest_doc(command, files, extra)
    atomic_write_text(Path(folder) / MANIFEST, json.dumps(doc, indent=1) + "\n", what=what)


class OutputDir:
    """An output folder written all-or-nothing, replacing only its own earlier run.

    Use as a context manager around the work.  The folder is checked on construction (before the
    work); files are written with :meth:`path` (a staging path to hand to any writer),
    :meth:`write_text`, :meth:`write_bytes` or :meth:`write_json`; on success they are moved in
    and the manifest is updated, on failure the staging folder is removed and the folder is left
    exactly as it was.

    Parameters
    ----------
    path : path-like
        The output folder (created, with its parents, when the run succeeds).
    command : str
        Who writes it (e.g. ``"region"``); a folder whose manifest names another command is
        refused, so two different runs are never mixed in one folder.
    owns : iterable of str, optional
        Every name this command can write, for a folder without a manifest: on success, the
        names of ``owns`` this run did not write are deleted (an earlier run's leftovers).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> root = pathlib.Path(tempfile.mkdtemp())
    >>> with OutputDir(root / "run", command="demo") as out:
    ...     _ = out.write_text("a.txt", "first")
    ...     _ = out.write_text("b.txt", "first")
    >>> with OutputDir(root / "run", command="demo") as out:
    ...     _ = out.write_text("a.txt", "second")
    >>> sorted(p.name for p in (root / "run").iterdir() if not p.name.startswith("."))
    ['a.txt']
    >>> OutputDir(root / "run", command="region")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: output folder: '...run' holds the outputs of 'stringstab demo'; ...
    """

    def __init__(self, path: str | os.PathLike[str], *, command: str,
                 what: str = "output folder", owns: Iterable[str] | None = None) -> None:
        self.root = check_output_dir(path, what=what)
        self.command = command
        self.what = what
        self.owns = None if owns is None else tuple(owns)
        self._staging: Path | None = None
        self._written: list[str] = []
        self._folders: list[str] = []
        self._committed = False
        #: More manifest entries (e.g. the policy an evaluation is of): :meth:`record`.
        self.extra: dict[str, Any] = {}
        claim_folder(self.root, command=command, what=what)

    # -- manifest ---------------------------------------------------------------------------
    def record(self, **entries: Any) -> None:
        """Add JSON-serialisable ``entries`` to the manifest written on success."""
        self.extra.update(entries)

    def previous(self) -> dict[str, Any] | None:
        """The manifest of the run this one replaces (None: none, or unreadable)."""
        return self._read_manifest()

    def _read_manifest(self) -> dict[str, Any] | None:
        return read_manifest(self.root)

    # -- context ------------------------------------------------------------------------------
    def __enter__(self) -> OutputDir:
        try:
            self._created = [q for q in (self.root, *self.root.parents) if not q.exists()]
            self.root.mkdir(parents=True, exist_ok=True)
            self._staging = Path(tempfile.mkdtemp(prefix=_STAGING_PREFIX, dir=self.root))
        except OSError as e:
            raise StringStabError(
                f"{self.what}: cannot create {str(self.root)!r} ({_reason(e)})"
            ) from e
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if exc_type is None:
            self.commit()
        else:
            self.discard()

    @property
    def staging(self) -> Path:
        """The hidden staging folder the run writes into, moved in on success.

        Raises
        ------
        RuntimeError
            Outside the ``with`` block (there is no staging folder then).
        """
        if self._staging is None:
            raise RuntimeError("OutputDir is used outside its 'with' block")
        return self._staging

    def path(self, name: str) -> Path:
        """The staging path of output ``name`` (sub-folders allowed); hand it to any writer."""
        rel = Path(name)
        if rel.is_absolute() or ".." in rel.parts or name in ("", MANIFEST):
            raise ValueError(f"output names are relative paths inside the folder; got {name!r}")
        p = self.staging / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        if rel.as_posix() not in self._written:
            self._written.append(rel.as_posix())
        return p

    def folder(self, name: str) -> Path:
        """A staging sub-folder whose every file (written by anyone) is part of the run.

        For writers that fill a folder themselves (a demo step, a figure set).
        """
        p = self.path(name)
        self._written.remove(Path(name).as_posix())
        p.mkdir(parents=True, exist_ok=True)
        self._folders.append(Path(name).as_posix())
        return p

    def final(self, name: str) -> Path:
        """Where output ``name`` will be once the run has succeeded."""
        return self.root / name

    def write_bytes(self, name: str, data: bytes) -> Path:
        """Stage ``data`` as output ``name``; returns its final path."""
        self.path(name).write_bytes(data)
        return self.final(name)

    def write_text(self, name: str, text: str) -> Path:
        """Stage UTF-8 ``text`` as output ``name``; returns its final path."""
        return self.write_bytes(name, text.encode("utf-8"))

    def write_json(self, name: str, doc: Any) -> Path:
        """Stage ``doc`` as JSON (:func:`~stringstab.io.plain.dumps_json`); returns its final path."""
        from .plain import dumps_json

        return self.write_text(name, dumps_json(doc))

    @property
    def written(self) -> list[str]:
        """Names staged so far, in order."""
        return list(self._written)

    def discard(self) -> None:
        """Drop everything staged; the folder is left as it was."""
        if self._staging is not None:
            shutil.rmtree(self._staging, ignore_errors=True)
            self._staging = None
            if not self._committed:  # the folders this run created go too (emptied, not absent)
                for q in getattr(self, "_created", []):
                    with contextlib.suppress(OSError):
                        q.rmdir()

    def commit(self) -> None:
        """Move the staged files in, remove this command's stale files, update the manifest.

        Ctrl-C during the moves is held until they are done (:func:`deferred_interrupt`), so
        the folder holds the whole new run or, interrupted before, the whole old one.
        """
        self._committed = True  # from here, the folder is kept (it receives the run)
        with deferred_interrupt():
            self._commit()

    def _commit(self) -> None:
        staging = self.staging
        old = self._read_manifest() or {}
        new = [n for n in self._written if (staging / n).is_file()]
        for folder in self._folders:
            new += sorted(f.relative_to(staging).as_posix()
                          for f in (staging / folder).rglob("*") if f.is_file())
        new = list(dict.fromkeys(new))
        stale = list(self.owns) if self.owns is not None else old.get("files", [])
        try:
            mode = 0o666 & ~_umask()
            for name in stale:
                if isinstance(name, str) and name not in new and ".." not in Path(name).parts:
                    (self.root / name).unlink(missing_ok=True)
                    for parent in Path(name).parents[:-1]:  # folders it leaves empty go too
                        with contextlib.suppress(OSError):
                            (self.root / parent).rmdir()
            for name in new:
                dest = self.root / name
                dest.parent.mkdir(parents=True, exist_ok=True)
                os.chmod(staging / name, mode)
                os.replace(staging / name, dest)
            write_manifest(self.root, command=self.command, files=new, extra=self.extra,
                           what=self.what)
        except OSError as e:
            raise StringStabError(
                f"{self.what}: cannot move the outputs into {str(self.root)!r} ({_reason(e)})"
            ) from e
        finally:
            self.discard()
