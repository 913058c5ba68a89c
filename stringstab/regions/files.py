"""The file formats of a region map: a compressed NPZ archive and a CSV table.

``npz``
    ``axis_<gain>`` coordinates, one array per per-point field and ``metadata``, a JSON
    string whose ``format`` is :data:`FORMAT`: everything needed to rebuild the map
    (:func:`stringstab.regions.load_npz`).
``csv``
    ``#`` lines (the tool and the metadata as JSON), then one row per grid point, written
    column by column by :mod:`stringstab.io`'s result writer.

Both are written atomically (a temporary file renamed into place) by the map's methods.  This module knows the
formats, not the map: :class:`stringstab.regions.RegionMap` hands it arrays and columns.
"""

from __future__ import annotations

import io
import json
import os
import zipfile
import zlib
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..io import atomic_path, format_results
from ..io.text_formats import write_csv as write_csv_rows

__all__ = ["DEFLATE_RATIO", "FORMAT", "SAMPLE_CHUNK", "SAMPLE_CHUNKS", "compresses", "csv_text", "read_npz",
           "write_csv", "write_npz"]

#: The ``format`` entry of a region map's metadata.
FORMAT = "stringstab-region-map/1"


def write_npz(path: str | os.PathLike[str], axes: Mapping[str, npt.NDArray[Any]],
              fields: Mapping[str, npt.NDArray[Any]], metadata: Mapping[str, Any]) -> Path:
    """Write ``axis_<gain>`` coordinates, the fields and the metadata (JSON) to ``path``.

    The archive is a zip of ``.npy`` members (what :func:`numpy.load` reads), each
    compressed at zlib level 1 unless zlib hardly shrinks it (:func:`compresses`: then stored),
    written atomically (a temporary file renamed into place).

    Parameters
    ----------
    path : str or path-like
        The NPZ file to write.
    axes : mapping of str to ndarray
        The grid coordinates of each swept gain (``"k_x"``, ``"k_v"``, ``"k_a"``; 1/s², 1/s,
        dimensionless), stored as ``axis_<gain>``.
    fields : mapping of str to ndarray
        The per-point arrays (verdicts, types, sup |Γ|, margin, ...), stored under their names.
    metadata : mapping
        JSON-serialisable description of the map; its ``format`` should be :data:`FORMAT`
        (:func:`read_npz` refuses any other).

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    arrays: dict[str, npt.NDArray[Any]] = {f"axis_{n}": a for n, a in axes.items()}
    arrays.update(fields)
    arrays["metadata"] = np.array(json.dumps(metadata))
    # numpy.savez_compressed at zlib level 1: a third faster than its default level, 0.1 % larger;
    # a member that zlib hardly shrinks (a field of assorted floats) is stored as it is
    with atomic_path(path, what="region map") as tmp, \
            zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=1) as z:
        for name, a in arrays.items():
            a = np.asanyarray(a)
            if compresses(a):
                with z.open(f"{name}.npy", "w", force_zip64=True) as fh:
                    np.lib.format.write_array(fh, a, allow_pickle=False)
            else:
                buf = io.BytesIO()
                np.lib.format.write_array(buf, a, allow_pickle=False)
                z.writestr(f"{name}.npy", buf.getbuffer(), compress_type=zipfile.ZIP_STORED)
    return Path(path)


#: :func:`compresses`: the sample's bytes, as chunks of this many bytes spread over the array.
SAMPLE_CHUNK = 4096
#: :func:`compresses`: how many chunks the sample holds at most.
SAMPLE_CHUNKS = 32
#: :func:`compresses`: the largest compressed/raw size of the sample at which a member is deflated.
DEFLATE_RATIO = 0.75


def compresses(a: npt.NDArray[Any]) -> bool:
    """Whether zlib (level 1) shrinks ``a``'s bytes by at least a quarter, on a spread sample.

    :func:`write_npz` deflates such members and stores the others (a field of assorted
    floats, such as an 801² map's margin, shrinks by 15 % for most of the archive's time).
    The sample is :data:`SAMPLE_CHUNKS` chunks of :data:`SAMPLE_CHUNK` bytes evenly spread
    over the array (its first rows alone can be a constant region); an array of at most that
    many bytes is deflated without a test (it costs little either way).  Either way the
    archive is one ``numpy.load`` reads.

    Parameters
    ----------
    a : ndarray
        A member of the archive.

    Returns
    -------
    bool
        True when the sample deflates to at most :data:`DEFLATE_RATIO` of its size (small
        arrays: always; an object array, which is never written: True).
    """
    if a.dtype.hasobject or a.nbytes <= SAMPLE_CHUNK * SAMPLE_CHUNKS:
        return True
    raw = np.ascontiguousarray(a).reshape(-1).view(np.uint8)
    starts = np.linspace(0, raw.size - SAMPLE_CHUNK, SAMPLE_CHUNKS).astype(np.intp)
    sample = b"".join(raw[s:s + SAMPLE_CHUNK].tobytes() for s in starts)
    return len(zlib.compress(sample, 1)) <= DEFLATE_RATIO * len(sample)


def read_npz(path: str | os.PathLike[str]) -> tuple[dict[str, Any], dict[str, npt.NDArray[Any]]]:
    """(metadata, arrays) of a file written by :func:`write_npz`.

    Parameters
    ----------
    path : str or path-like
        A region-map NPZ file.

    Returns
    -------
    metadata : dict
        The decoded ``metadata`` entry (its ``format`` is :data:`FORMAT`).
    arrays : dict of str to ndarray
        Every entry of the archive, ``metadata`` included, by name.

    Raises
    ------
    StringStabError
        If the file is not a stringstab region map.
    """
    try:
        with np.load(path, allow_pickle=False) as z:
            data = {k: z[k] for k in z.files}
    except (OSError, ValueError) as e:
        raise StringStabError(f"{path}: expected a region-map NPZ file; could not read it ({e})") from e
    if "metadata" not in data:
        raise StringStabError(f"{path}: expected a region-map NPZ with a 'metadata' entry; found {sorted(data)}")
    try:
        meta = json.loads(str(data["metadata"]))
    except ValueError as e:
        raise StringStabError(f"{path}: expected JSON in the 'metadata' entry of a region-map NPZ; "
                              f"could not decode it ({e})") from e
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        found = meta.get("format") if isinstance(meta, dict) else type(meta).__name__
        raise StringStabError(f"{path}: expected format {FORMAT!r}; found {found!r}")
    return meta, data


def csv_text(columns: Mapping[str, npt.NDArray[Any]], comments: Sequence[str] | None) -> str:
    """``# comment`` lines and the header, then one CSV row per element of the columns.

    Every cell is formatted by :func:`stringstab.io.format_results` (shortest round-trip
    numbers, ``True``/``False``, a non-finite number as an empty field).  With
    ``comments=None``, the rows alone (no header): the texts of consecutive row ranges
    concatenate to the text of the whole.

    Parameters
    ----------
    columns : mapping of str to ndarray
        The table, column by column; every column has one element per row.
    comments : sequence of str or None
        Lines written first, each as ``# <line>``, before the header; None to leave out both
        the comment lines and the header.

    Returns
    -------
    str
        The CSV text, ending in a newline.
    """
    text = format_results(columns, "csv")
    if comments is None:
        return text[text.index("\n") + 1:]
    return "".join(f"# {c}\n" for c in comments) + text


def write_csv(path: str | os.PathLike[str], columns: Mapping[str, npt.NDArray[Any]],
              comments: Sequence[str]) -> Path:
    """Write :func:`csv_text` ``(columns, comments)`` to ``path`` as UTF-8, atomically.

    The same bytes as ``csv_text(columns, comments).encode("utf-8")``, streamed to the file
    (:func:`stringstab.io.text_formats.write_csv`) without forming the text.

    Parameters
    ----------
    path : str or path-like
        The CSV file to write.
    columns : mapping of str to ndarray
        The table, column by column; every column has one element per row.
    comments : sequence of str
        Lines written first, each as ``# <line>``, before the header.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    head = "".join(f"# {c}\n" for c in comments).encode("utf-8")
    with atomic_path(path, what="region map CSV") as tmp, open(tmp, "wb") as fh:
        fh.write(head)
        write_csv_rows(columns, fh)
    return Path(path)
