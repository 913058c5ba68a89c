"""The readers of the array gain formats: NPZ and Parquet (:mod:`stringstab.io.gains` describes them).

Both read named arrays (NPZ arrays, Parquet columns) and check them with one function,
:func:`table_from_arrays`, which refuses bad input in one line naming the array and index.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show
from .gain_table import GAIN_COLUMNS, OPTIONAL_COLUMNS, GainTable, resolve_columns, vehicle_ids

__all__ = ["read_npz_gains", "read_parquet_gains", "table_from_arrays"]


def read_npz_gains(path: Path, source: str) -> GainTable:
    """Gain triples from an NPZ archive (:func:`numpy.savez`): ``k_x, k_v, k_a`` or ``K`` (n, 3).

    Parameters
    ----------
    path : Path
        The archive.
    source : str
        Its name, for messages.

    Returns
    -------
    GainTable
        The gains, with ``t`` and ``vehicle`` when the archive has them.

    Raises
    ------
    StringStabError
        If the file is not a readable NPZ of numeric arrays, or its arrays are not gains
        (:func:`table_from_arrays`).
    """
    import zipfile

    try:
        if not zipfile.is_zipfile(path):
            raise StringStabError(
                f"{source}: not an NPZ archive (numpy.savez); expected arrays k_x, k_v, k_a "
                "or K (n, 3)"
            )
        with np.load(path, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except StringStabError:
        raise
    except ValueError as e:
        raise StringStabError(
            f"{source}: not a readable NPZ of numeric arrays (object arrays are refused; {e})"
        ) from e
    except (OSError, EOFError, zipfile.BadZipFile) as e:
        raise StringStabError(f"{source}: not a readable NPZ file ({e})") from e
    if not arrays:
        raise StringStabError(
            f"{source}: empty NPZ; expected arrays k_x, k_v, k_a (optional t, vehicle) or K (n, 3)"
        )
    return table_from_arrays(arrays, source)


def read_parquet_gains(path: Path, source: str) -> GainTable:
    """Gain triples from a Parquet file: columns ``k_x, k_v, k_a`` (optional ``t``, ``vehicle``).

    Parameters
    ----------
    path : Path
        The file.
    source : str
        Its name, for messages.

    Returns
    -------
    GainTable
        The gains, with ``t`` and ``vehicle`` when the file has them.

    Raises
    ------
    StringStabError
        If the file is not readable Parquet, or its columns are not gains
        (:func:`table_from_arrays`).
    """
    try:
        import pyarrow.parquet as pq
    except ImportError as e:  # pragma: no cover - pyarrow is a dependency
        raise StringStabError(f"{source}: reading Parquet needs pyarrow (pip install pyarrow)") from e
    try:
        table = pq.read_table(path)
    except Exception as e:  # pyarrow raises its own ArrowInvalid / OSError types
        raise StringStabError(f"{source}: not a readable Parquet file; expected Parquet columns "
                              f"k_x, k_v, k_a [, t, vehicle] ({e})") from e
    arrays = {name: np.asarray(table.column(name).to_numpy(zero_copy_only=False))
              for name in table.column_names}
    if not arrays:
        raise StringStabError(
            f"{source}: no columns; expected columns k_x, k_v, k_a (optional t, vehicle)"
        )
    return table_from_arrays(arrays, source)


def table_from_arrays(arrays: dict[str, npt.NDArray[Any]], source: str) -> GainTable:
    """The gains from named arrays (NPZ arrays or Parquet columns).

    Parameters
    ----------
    arrays : dict of str to ndarray
        ``k_x, k_v, k_a`` (optional ``t``, ``vehicle``) of one length, or one ``(n, 3)``
        array ``K``; other arrays are ignored.
    source : str
        Where they came from, for messages.

    Returns
    -------
    GainTable
        The gains, checked finite.

    Raises
    ------
    StringStabError
        On missing or misspelt arrays, wrong shapes or dtypes, or an entry that is not finite.
    """
    names = list(arrays)
    if "K" in arrays and not any(c in arrays for c in GAIN_COLUMNS):
        K = arrays["K"]
        if K.ndim != 2 or K.shape[1] != 3:
            raise StringStabError(
                f"{source}: array 'K' must have shape (n, 3) with columns k_x, k_v, k_a; "
                f"found shape {K.shape}"
            )
        cols: dict[str, Any] = {c: K[:, j] for j, c in enumerate(GAIN_COLUMNS)}
        for c in OPTIONAL_COLUMNS:
            if c in arrays:
                cols[c] = arrays[c]
        ignored = tuple(n for n in names if n not in ("K", *OPTIONAL_COLUMNS))
    else:
        cand = [n for n in names if n not in OPTIONAL_COLUMNS]
        if len(cand) == 1 and arrays[cand[0]].ndim == 2 and arrays[cand[0]].shape[1] == 3:
            raise StringStabError(
                f"{source}: expected arrays k_x, k_v, k_a (optional t, vehicle) or one (n, 3) "
                f"array K; found {', '.join(map(repr, names))} (name the (n, 3) array 'K')"
            )
        index, ignored = resolve_columns(names, source, what="array")
        cols = {c: arrays[names[j]] for c, j in index.items()}
    n = len(cols["k_x"])
    for c, a in cols.items():
        if a.ndim != 1 or len(a) != n:
            raise StringStabError(
                f"{source}: array {show(c)} must be 1-D of length {n} (one entry per triple); "
                f"found shape {a.shape}"
            )
        if c != "vehicle" and not (np.issubdtype(a.dtype, np.number) and not np.iscomplexobj(a)):
            raise StringStabError(
                f"{source}: array {show(c)} must be real numbers; found dtype {a.dtype}"
            )
    # Fast vectorised check, then a precise message naming the first bad entry.
    for c in (*GAIN_COLUMNS, "t"):
        if c in cols:
            a = np.asarray(cols[c], dtype=np.float64)
            bad = np.flatnonzero(~np.isfinite(a))
            if bad.size:
                i = int(bad[0])
                raise StringStabError(
                    f"{source}: array {show(c)}, index {i}: expected a finite number; "
                    f"found {show(float(a[i]))}"
                )
            cols[c] = a
    vehicle = vehicle_ids(cols["vehicle"].tolist()) if "vehicle" in cols else None
    if n == 0:
        raise StringStabError(f"{source}: expected at least one gain triple; found none")
    return GainTable(
        cols["k_x"], cols["k_v"], cols["k_a"], cols.get("t"), vehicle, source=source,
        ignored_columns=ignored,
    )
