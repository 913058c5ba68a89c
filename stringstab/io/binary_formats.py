"""The binary files of a result: ``parquet`` and ``npz``, keeping the columns' NumPy types.

Both keep ``inf`` and ``nan`` and carry the run's ``params`` and ``summary`` as JSON.  The
columns come in the model of :mod:`stringstab.io.columns`.
"""

from __future__ import annotations

import io
import json
from collections.abc import Mapping
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from .columns import Columns, flat_leaves, normalise_columns
from .plain import to_plain

__all__ = ["npz_arrays", "parquet_bytes"]


def parquet_bytes(columns: Columns, params: Mapping[str, Any] | None = None,
                  summary: Mapping[str, Any] | None = None) -> bytes:
    """The ``parquet`` file of result columns, as bytes.

    The flattened columns keep their NumPy types (``inf`` and ``nan`` kept; missing values
    null); ``params`` and ``summary`` are JSON in the file's metadata (keys
    ``stringstab.params``, ``stringstab.summary``).

    Parameters
    ----------
    columns : mapping
        Ordered columns ``name → 1-D array`` (or ``name → {name → array}``), one length.
    params, summary : mapping, optional
        Settings and totals of the run.

    Returns
    -------
    bytes
        The Parquet file.

    Raises
    ------
    StringStabError
        On ragged columns, or when pyarrow is missing.
    """
    cols = normalise_columns(columns)
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError as e:  # pragma: no cover - pyarrow is a dependency
        raise StringStabError("writing parquet needs pyarrow; install it with 'pip install pyarrow'") from e

    arrays = {}
    for name, leaf in flat_leaves(cols).items():
        mask = leaf.mask
        arrays[name] = pa.array(leaf.values, mask=mask) if mask is not None else pa.array(leaf.values)
    meta = {b"stringstab.params": json.dumps(to_plain(dict(params or {})), ensure_ascii=False),
            b"stringstab.summary": json.dumps(to_plain(dict(summary or {})), ensure_ascii=False)}
    table = pa.table(arrays).replace_schema_metadata(meta)
    buf = io.BytesIO()
    pq.write_table(table, buf)
    return buf.getvalue()


def npz_arrays(columns: Columns, params: Mapping[str, Any] | None = None,
               summary: Mapping[str, Any] | None = None) -> dict[str, npt.NDArray[Any]]:
    """The arrays of the ``npz`` file of result columns (for :func:`numpy.savez`).

    The flattened columns as arrays (``inf``/``nan`` kept; a missing value is NaN, integer and
    boolean columns with one become float), ``params`` and ``summary`` as JSON strings in the
    0-d arrays ``_params`` and ``_summary``.

    Parameters
    ----------
    columns : mapping
        Ordered columns ``name → 1-D array`` (or ``name → {name → array}``), one length.
    params, summary : mapping, optional
        Settings and totals of the run.

    Returns
    -------
    dict of str to ndarray
        The members of the archive, by name.

    Raises
    ------
    StringStabError
        On ragged columns.
    """
    cols = normalise_columns(columns)
    arrays: dict[str, npt.NDArray[Any]] = {}
    for name, leaf in flat_leaves(cols).items():
        v = leaf.values
        if leaf.mask is not None and leaf.kind in "ib":
            v = np.where(leaf.mask, np.nan, v.astype(np.float64))
        elif leaf.mask is not None and leaf.kind == "f":
            v = np.where(leaf.mask, np.nan, v)
        arrays[name] = v
    arrays["_params"] = np.array(json.dumps(to_plain(dict(params or {})), ensure_ascii=False))
    arrays["_summary"] = np.array(json.dumps(to_plain(dict(summary or {})), ensure_ascii=False))
    return arrays

