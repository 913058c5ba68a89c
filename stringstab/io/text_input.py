"""The one reader of a user's text file: gzip recognised by content, then strict UTF-8.

Every reader of a text file a user gives (a leader CSV, a gain file, a recorded platoon, NGSIM
trajectories, a sweep spec, an ``identify.json``, a run folder's JSON) goes through
:func:`open_text` (a stream, for files read line by line: an NGSIM file is 1.5 GB) or
:func:`read_text` (the whole text).  Both

* recognise gzip by the file's first two bytes (``1f 8b``, RFC 1952), not its name, and
  decompress it (the OpenACC logs under ``stringstab/data/openacc/`` are ``.csv.gz``);
* decode the text as UTF-8, strictly (a leading byte-order mark dropped);
* refuse, with one :class:`~stringstab.errors.StringStabError` line that names the file and what
  was expected, a file that cannot be read (missing, a folder, no permission), damaged gzip data
  (truncated, a bad checksum), a binary file or text in another encoding (the first byte that is
  not UTF-8, or the UTF-16/32 byte-order mark found) and a NUL byte, which no text file holds
  (Python's :mod:`csv` would read it as a character).

``OSError``, ``EOFError``, ``zlib.error`` and ``UnicodeDecodeError`` never escape them.
"""

from __future__ import annotations

import codecs
import gzip
import os
import zlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import IO, Any, TypeVar

from ..errors import StringStabError

__all__ = ["GZIP_MAGIC", "is_gzip", "open_text", "read_stream", "read_text", "undecodable"]

#: The first two bytes of every gzip member (RFC 1952, ID1 ID2).
GZIP_MAGIC = b"\x1f\x8b"

#: Byte-order marks of the encodings a spreadsheet may save "Unicode text" in.
_BOMS = ((codecs.BOM_UTF32_LE, "UTF-32"), (codecs.BOM_UTF32_BE, "UTF-32"),
         (codecs.BOM_UTF16_LE, "UTF-16"), (codecs.BOM_UTF16_BE, "UTF-16"))

#: What damaged gzip data raises while it is read (BadGzipFile is an OSError).
_DAMAGED = (EOFError, zlib.error, gzip.BadGzipFile)

_T = TypeVar("_T")


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


def undecodable(label: str, expected: str, head: bytes, offset: int | None, *,
                compressed: bool = False) -> StringStabError:
    """The one-line refusal of a file that is not UTF-8 text.

    Parameters
    ----------
    label : str
        The file as the message names it, e.g. ``"leader CSV 'a.csv'"``.
    expected : str
        What the file should be, e.g. ``"a 't, v' CSV file"``.
    head : bytes
        The text's first bytes (its byte-order mark, if any, names the encoding found).
    offset : int or None
        Offset of the first byte that is not UTF-8 text (None: not known).
    compressed : bool, default False
        Whether the offset counts bytes of decompressed gzip data.

    Returns
    -------
    StringStabError
        To be raised by the caller (``raise undecodable(...) from e``).

    Examples
    --------
    >>> print(undecodable("leader CSV 'a.csv'", "a 't, v' CSV file", b"t,v", 7))
    leader CSV 'a.csv': expected a 't, v' CSV file (UTF-8 text); got a binary file or text in another encoding, not UTF-8 text (first at byte offset 7); save it as UTF-8
    """
    found = next((name for bom, name in _BOMS if head.startswith(bom)), None)
    if found is not None:
        what = f"{found} text (its byte-order mark), not UTF-8 text"
    else:
        of = " of the decompressed data" if compressed else ""
        where = f" (first at byte offset {offset}{of})" if offset is not None else ""
        what = f"a binary file or text in another encoding, not UTF-8 text{where}"
    return StringStabError(f"{label}: expected {expected} (UTF-8 text); got {what}; save it as UTF-8")


def _nul(label: str, expected: str, offset: int | None) -> StringStabError:
    """The one-line refusal of text holding a NUL byte (at ``offset``, when known)."""
    where = f"a NUL byte at offset {offset}" if offset is not None else "a NUL byte"
    return StringStabError(f"{label}: expected {expected} (UTF-8 text); got a binary file, not "
                           f"UTF-8 text ({where}, which no text file holds)")


def _binary(path: Path) -> IO[bytes]:
    """The file's bytes, decompressed when it is gzip data."""
    if is_gzip(path):
        return gzip.GzipFile(path, "rb")  # type: ignore[return-value]  # a BufferedIOBase
    return open(path, "rb")


def _first(path: Path, found: Callable[[bytes, int], int | None]) -> int | None:
    """Offset of the first byte ``found(chunk, pending)`` flags (None: none, or unreadable)."""
    offset = 0
    try:
        with _binary(path) as fh:
            while chunk := fh.read(1 << 20):
                at = found(chunk, offset)
                if at is not None:
                    return at
                offset += len(chunk)
    except (OSError, *_DAMAGED):
        return None
    return None


def _first_bad_byte(path: Path) -> int | None:
    """Offset of the first byte that is not UTF-8 text (decompressed; None: none found)."""
    decoder = codecs.getincrementaldecoder("utf-8")()

    def bad(chunk: bytes, offset: int) -> int | None:
        pending = len(decoder.getstate()[0])  # bytes of a character cut by the chunk
        try:
            decoder.decode(chunk)
        except UnicodeDecodeError as e:
            return offset - pending + e.start
        return None

    return _first(path, bad)


def _first_nul(path: Path) -> int | None:
    """Offset of the first NUL byte (decompressed; None: none found)."""
    return _first(path, lambda chunk, offset: offset + chunk.index(0) if 0 in chunk else None)


class _Text:
    """A text stream whose every failure is the one-line refusal naming the file."""

    def __init__(self, path: Path, label: str, expected: str) -> None:
        self._path, self._label, self._expected = path, label, expected
        try:
            if path.is_dir():
                raise StringStabError(f"{label}: expected {expected}; got a folder")
            self._gzip = is_gzip(path)
            self._fh: IO[str] = (gzip.open(path, "rt", encoding="utf-8-sig", newline="")
                                 if self._gzip else
                                 path.open(encoding="utf-8-sig", newline=""))
        except OSError as e:
            raise self._unreadable(e) from e

    def _unreadable(self, e: BaseException) -> StringStabError:
        reason = (f"damaged gzip data: {e}" if isinstance(e, _DAMAGED)
                  else getattr(e, "strerror", None) or str(e))
        return StringStabError(f"{self._label}: cannot read it ({reason}); expected "
                               f"{self._expected}")

    def _checked(self, read: Callable[[], _T]) -> _T:
        try:
            return read()
        except UnicodeDecodeError as e:
            try:
                with _binary(self._path) as fh:
                    head = fh.read(4)
            except (OSError, *_DAMAGED):
                head = b""
            raise undecodable(self._label, self._expected, head, _first_bad_byte(self._path),
                              compressed=self._gzip) from e
        except (OSError, *_DAMAGED) as e:
            raise self._unreadable(e) from e

    def _no_nul(self, text: str) -> str:
        if "\0" in text:
            raise _nul(self._label, self._expected, _first_nul(self._path))
        return text

    def __iter__(self) -> Iterator[str]:
        lines = iter(self._fh)
        while True:
            line = self._checked(lambda: next(lines, None))
            if line is None:
                return
            yield self._no_nul(line)

    def read(self, size: int = -1) -> str:
        """Up to ``size`` characters (all that is left by default)."""
        return self._no_nul(self._checked(lambda: self._fh.read(size)))

    def readline(self) -> str:
        """The next line ("" at the end)."""
        return self._no_nul(self._checked(self._fh.readline))

    def close(self) -> None:
        """Close the file."""
        self._fh.close()

    def __enter__(self) -> _Text:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def open_text(path: str | os.PathLike[str], *, label: str, expected: str) -> Any:
    r"""Open a user's text file for reading: plain or gzip (by content), strict UTF-8.

    The stream is opened with ``newline=""`` (what :mod:`csv` expects), skips a UTF-8
    byte-order mark and is a context manager; iterate it for lines, or ``read()`` /
    ``readline()`` it.

    Parameters
    ----------
    path : path-like
        The file, plain text or gzip-compressed text (recognised by :func:`is_gzip`).
    label : str
        How the messages name it, e.g. ``"leader CSV 'a.csv'"``.
    expected : str
        What it should be, e.g. ``"a 't, v' or 't, v, a' CSV file"``.

    Returns
    -------
    text stream
        Iterable over lines, with ``read``, ``readline``, ``close`` and ``with`` support.

    Raises
    ------
    StringStabError
        When the file cannot be opened or read (missing, a folder, no permission, damaged gzip
        data), is not UTF-8 text (the first offending byte's offset; the encoding when a
        byte-order mark names it) or holds a NUL byte — at opening or while reading.

    Examples
    --------
    >>> import gzip, tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as d:
    ...     f = pathlib.Path(d, "a.csv.gz")
    ...     _ = f.write_bytes(gzip.compress(b"t,v\n0,1\n"))
    ...     with open_text(f, label="leader CSV", expected="a 't, v' CSV file") as fh:
    ...         print(fh.read().splitlines())
    ['t,v', '0,1']
    """
    return _Text(Path(path), label, expected)


def read_text(path: str | os.PathLike[str], *, label: str, expected: str) -> str:
    r"""The whole text of a user's file (gzip decompressed, UTF-8 decoded), or a refusal.

    Parameters
    ----------
    path : path-like
        The file.
    label : str
        How the messages name it, e.g. ``"leader CSV 'a.csv'"``.
    expected : str
        What it should be, e.g. ``"a 't, v' or 't, v, a' CSV file"``.

    Returns
    -------
    str
        The text (a leading byte-order mark dropped, line ends as in the file).

    Raises
    ------
    StringStabError
        As :func:`open_text`.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "latin.csv"
    >>> _ = p.write_bytes(b"t,v\n0,caf\xe9\n")
    >>> read_text(p, label="leader CSV", expected="a 't, v' CSV file")
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: leader CSV: expected a 't, v' CSV file (UTF-8 text); got a binary file or text in another encoding, not UTF-8 text (first at byte offset 9); save it as UTF-8
    """
    with open_text(path, label=label, expected=expected) as fh:
        text: str = fh.read()
    return text


def read_stream(stream: IO[str], *, label: str, expected: str) -> str:
    r"""All of an open text stream (standard input), read as :func:`read_text` reads a file.

    A stream with a byte buffer (``sys.stdin``) is read as bytes: gzip data is recognised by
    its first two bytes and decompressed, then the bytes are decoded as strict UTF-8 here
    (the stream's own decoder may be another encoding's or lenient).  A plain text stream
    (``io.StringIO``) is read as text.

    Parameters
    ----------
    stream : text stream
        The stream, read to its end.
    label : str
        How the messages name it, e.g. ``"<stdin>"``.
    expected : str
        What it should hold, e.g. ``"a CSV or JSON gain file"``.

    Returns
    -------
    str
        The text (a leading byte-order mark dropped).

    Raises
    ------
    StringStabError
        When the stream cannot be read, holds damaged gzip data, text that is not UTF-8 or a
        NUL byte.

    Examples
    --------
    >>> import io
    >>> raw = io.TextIOWrapper(io.BytesIO(b"k_x,k_v,k_a\n1,1,\xe9\n"))
    >>> read_stream(raw, label="<stdin>", expected="a CSV gain file")
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: <stdin>: expected a CSV gain file (UTF-8 text); got a binary file or text in another encoding, not UTF-8 text (first at byte offset 16); save it as UTF-8
    """
    raw = getattr(stream, "buffer", None)
    try:
        if raw is None:
            text = stream.read()
            text = text[1:] if text.startswith("\ufeff") else text
        else:
            data = raw.read()
            compressed = data[:2] == GZIP_MAGIC
            if compressed:
                data = gzip.decompress(data)
            try:
                text = data.decode("utf-8-sig")
            except UnicodeDecodeError as e:
                raise undecodable(label, expected, data[:4], e.start, compressed=compressed) from e
    except UnicodeDecodeError as e:  # a text stream's own decoder
        raise undecodable(label, expected, b"", None) from e
    except (OSError, *_DAMAGED) as e:
        reason = (f"damaged gzip data: {e}" if isinstance(e, _DAMAGED)
                  else getattr(e, "strerror", None) or str(e))
        raise StringStabError(f"{label}: cannot read it ({reason}); expected {expected}") from e
    at = text.find("\0")
    if at >= 0:
        raise _nul(label, expected, len(text[:at].encode("utf-8")))
    return text
