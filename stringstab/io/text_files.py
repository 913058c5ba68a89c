"""A user's text file, decoded as UTF-8 or refused in one line that names it.

Every reader of a text file given on the command line (a leader CSV, a gain file, a recorded
platoon, NGSIM trajectories, a sweep spec, an ``identify.json``, a run folder's JSON) reads it
through :func:`read_text` (the whole file) or :func:`decoding` (a file read line by line), so a
binary file, or text saved in another encoding (Latin-1, UTF-16), is refused with
:class:`~stringstab.errors.StringStabError`: the file, what was expected and the first byte that
is not UTF-8 — never a ``UnicodeDecodeError`` traceback.  A NUL byte, which no text file holds,
marks a binary file and is refused too (Python's ``csv`` module would read it as a character).
"""

from __future__ import annotations

import codecs
import contextlib
import os
from collections.abc import Iterator
from pathlib import Path

from ..errors import StringStabError

__all__ = ["decoding", "read_text", "undecodable"]

#: Byte-order marks of the encodings a spreadsheet may save "Unicode text" in.
_BOMS = ((codecs.BOM_UTF32_LE, "UTF-32"), (codecs.BOM_UTF32_BE, "UTF-32"),
         (codecs.BOM_UTF16_LE, "UTF-16"), (codecs.BOM_UTF16_BE, "UTF-16"))


def undecodable(label: str, expected: str, head: bytes, offset: int | None) -> StringStabError:
    """The one-line refusal of a file that is not UTF-8 text.

    Parameters
    ----------
    label : str
        The file as the message names it, e.g. ``"leader CSV 'a.csv'"``.
    expected : str
        What the file should be, e.g. ``"a 't, v' or 't, v, a' CSV file"``.
    head : bytes
        The file's first bytes (its byte-order mark, if any, names the encoding found).
    offset : int or None
        Offset of the first byte that is not UTF-8 text (None: not known).

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
        where = f" (first at byte offset {offset})" if offset is not None else ""
        what = f"a binary file or text in another encoding, not UTF-8 text{where}"
    return StringStabError(f"{label}: expected {expected} (UTF-8 text); got {what}; save it as UTF-8")


def _nul(label: str, expected: str, offset: int) -> StringStabError:
    return StringStabError(f"{label}: expected {expected} (UTF-8 text); got a binary file, not "
                           f"UTF-8 text (a NUL byte at offset {offset}, which no text file holds)")


def read_text(path: str | os.PathLike[str], *, label: str, expected: str) -> str:
    r"""The whole file decoded as UTF-8 (a leading byte-order mark dropped), or a refusal.

    Parameters
    ----------
    path : path
        The file.
    label : str
        How the messages name it, e.g. ``"leader CSV 'a.csv'"``.
    expected : str
        What it should be, e.g. ``"a 't, v' or 't, v, a' CSV file"``.

    Returns
    -------
    str
        The text.

    Raises
    ------
    StringStabError
        When the file cannot be read (missing, a folder, no permission), is not UTF-8 text
        (the first offending byte's offset) or holds a NUL byte.
        ``OSError`` and ``UnicodeDecodeError`` never escape.

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
    p = Path(path)
    try:
        data = p.read_bytes()
    except IsADirectoryError as e:
        raise StringStabError(f"{label}: expected {expected}; got a folder") from e
    except OSError as e:
        raise StringStabError(f"{label}: cannot read it ({e.strerror or e}); expected "
                              f"{expected}") from e
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise undecodable(label, expected, data[:4], e.start) from e
    nul = text.find("\0")
    if nul >= 0:
        raise _nul(label, expected, len(text[:nul].encode("utf-8")))
    return text


def _first_bad_byte(path: Path) -> int | None:
    """Offset of the first byte of ``path`` that is not UTF-8 text (None: none found or unreadable)."""
    decoder = codecs.getincrementaldecoder("utf-8")()
    offset = 0
    try:
        with open(path, "rb") as fh:
            while chunk := fh.read(1 << 20):
                pending = len(decoder.getstate()[0])  # bytes of a character cut by the chunk
                try:
                    decoder.decode(chunk)
                except UnicodeDecodeError as e:
                    return offset - pending + e.start
                offset += len(chunk)
    except OSError:
        return None
    return None


@contextlib.contextmanager
def decoding(path: str | os.PathLike[str], *, label: str, expected: str) -> Iterator[None]:
    r"""Around a reader that decodes ``path`` as it goes: a ``UnicodeDecodeError`` becomes a refusal.

    For files too large to hold as one string (an NGSIM trajectory file is 1.5 GB); the offset
    of the first offending byte is found by a second, binary pass when the error happens.

    Parameters
    ----------
    path : path
        The file being read.
    label : str
        How the message names it.
    expected : str
        What it should be.

    Yields
    ------
    None
        Control returns to the block that reads the file.

    Raises
    ------
    StringStabError
        When the block raises ``UnicodeDecodeError``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "bin.csv"
    >>> _ = p.write_bytes(b"\xff\xfeV\x00")
    >>> with decoding(p, label="NGSIM file", expected="an NGSIM CSV file"):
    ...     _ = p.read_text(encoding="utf-8")
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: NGSIM file: expected an NGSIM CSV file (UTF-8 text); got UTF-16 text (its byte-order mark), not UTF-8 text; save it as UTF-8
    """
    try:
        yield
    except UnicodeDecodeError as e:
        p = Path(path)
        try:
            with open(p, "rb") as fh:
                head = fh.read(4)
        except OSError:
            head = b""
        raise undecodable(label, expected, head, _first_bad_byte(p)) from e
