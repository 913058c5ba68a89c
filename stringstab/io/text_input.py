"""Opening a text input plain or gzip-compressed: :func:`open_text`, for every log reader.

A recorded platoon, a leader CSV or an NGSIM file may be stored compressed (``.csv.gz``, as the
OpenACC logs under ``stringstab/data/openacc/`` are): :func:`open_text` recognises gzip by the
file's first two bytes (``1f 8b``, RFC 1952), not its name, and returns a text stream either way,
so a reader parses one stream whatever the file.  Damaged compressed data (a truncated file, a
bad checksum) surfaces as :class:`OSError`, which the readers already turn into their one-line
"cannot read" error; undecodable bytes surface as :class:`UnicodeDecodeError`, as for a plain
file.
"""

from __future__ import annotations

import gzip
import os
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

__all__ = ["GZIP_MAGIC", "is_gzip", "open_text"]

#: The first two bytes of every gzip member (RFC 1952, ID1 ID2).
GZIP_MAGIC = b"\x1f\x8b"


def is_gzip(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` starts like gzip data (its first two bytes, whatever its name).

    Parameters
    ----------
    path : path-like
        An existing file.

    Returns
    -------
    bool
        True for gzip-compressed data.

    Raises
    ------
    OSError
        When the file cannot be opened.
    """
    with open(path, "rb") as fh:
        return fh.read(2) == GZIP_MAGIC


class _Text:
    """A text stream whose damaged-gzip errors (EOFError, zlib.error, BadGzipFile) say so (OSError)."""

    def __init__(self, fh: IO[str], name: str) -> None:
        self._fh, self._name = fh, name

    def __iter__(self) -> Iterator[str]:
        try:
            yield from self._fh
        except (EOFError, zlib.error, gzip.BadGzipFile) as e:
            raise OSError(f"damaged gzip data in {self._name} ({e})") from e

    def read(self, size: int = -1) -> str:
        try:
            return self._fh.read(size)
        except (EOFError, zlib.error, gzip.BadGzipFile) as e:
            raise OSError(f"damaged gzip data in {self._name} ({e})") from e

    def readline(self) -> str:
        try:
            return self._fh.readline()
        except (EOFError, zlib.error, gzip.BadGzipFile) as e:
            raise OSError(f"damaged gzip data in {self._name} ({e})") from e

    def close(self) -> None:
        self._fh.close()

    def __enter__(self) -> _Text:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def open_text(path: str | os.PathLike[str], *, encoding: str = "utf-8-sig") -> Any:
    r"""Open a text file for reading, decompressing it when it is gzip data.

    The stream is opened with ``newline=""`` (what :mod:`csv` expects) and is a context
    manager; iterate it for lines or ``read()`` it.

    Parameters
    ----------
    path : path-like
        The file, plain text or gzip-compressed text (recognised by :func:`is_gzip`).
    encoding : str, default "utf-8-sig"
        The text's encoding (a UTF-8 byte-order mark is skipped).

    Returns
    -------
    text stream
        Iterable over lines, with ``read``, ``readline``, ``close`` and ``with`` support.

    Raises
    ------
    OSError
        When the file cannot be opened, or (while reading) its gzip data is damaged.

    Examples
    --------
    >>> import gzip, tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as d:
    ...     f = pathlib.Path(d, "a.csv.gz")
    ...     _ = f.write_bytes(gzip.compress(b"t,v\n0,1\n"))
    ...     with open_text(f) as fh:
    ...         print(fh.read().splitlines())
    ['t,v', '0,1']
    """
    p = Path(path)
    if is_gzip(p):
        return _Text(gzip.open(p, "rt", encoding=encoding, newline=""), p.name)
    return _Text(p.open(encoding=encoding, newline=""), p.name)
