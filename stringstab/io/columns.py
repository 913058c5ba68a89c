"""The column model of a result: ordered, typed 1-D columns with at most one level of grouping.

A result is a set of *ordered columns* — ``name → 1-D array``, with at most one level of
grouping (``"taylor_derived" → {"psi1": array, ...}``).  :func:`normalise_columns` checks their
shape and turns each into a :class:`Leaf` (values of kind b, i, f or U and a mask of missing
values; a :class:`Categorical` keeps its codes), the form every renderer
(:mod:`~stringstab.io.table`, :mod:`~stringstab.io.text_formats`,
:mod:`~stringstab.io.binary_formats`) reads.  :func:`columns_from_records` and
:func:`records_from_columns` convert between columns and row records.

Every result type owns its columns (e.g.
:meth:`stringstab.certify.continuous.CertificateBatch.columns`); this module knows none of them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError

__all__ = [
    "Categorical",
    "Columns",
    "Leaf",
    "Normalised",
    "columns_from_records",
    "flat_leaves",
    "flatten_columns",
    "n_rows",
    "normalise_columns",
    "records_from_columns",
]

#: Columns: name -> 1-D array, or name -> {name -> 1-D array} (one level of grouping).
Columns = Mapping[str, Any]

@dataclass(frozen=True)
class Categorical:
    """A column of few distinct values, ``labels[codes]``, written without forming every cell.

    Grid coordinates, verdicts and type labels repeat a handful of values over many rows; the
    writer formats each label once and spreads it (a region map's CSV is 3× faster so).
    ``numpy.asarray(c)`` and :meth:`tolist` give the plain values.

    Examples
    --------
    >>> c = Categorical(np.array([1, 0, 1]), np.array(["no", "yes"]))
    >>> c.tolist(), len(c), c[1:].tolist()
    (['yes', 'no', 'yes'], 3, ['no', 'yes'])
    """

    codes: npt.NDArray[np.integer[Any]]
    labels: npt.NDArray[Any]

    def __len__(self) -> int:
        return int(np.shape(self.codes)[0])

    def __getitem__(self, rows: Any) -> Categorical:
        return Categorical(np.asarray(self.codes)[rows], self.labels)

    def __array__(self, dtype: Any = None, copy: Any = None) -> npt.NDArray[Any]:
        out = np.asarray(self.labels)[np.asarray(self.codes)]
        return out if dtype is None else out.astype(dtype)

    def tolist(self) -> list[Any]:
        """The values as a list."""
        return np.asarray(self).tolist()


@dataclass(frozen=True)
class Leaf:
    """A normalised column: values (kind b, i, f or U), and a mask of missing values.

    With ``codes``, ``base`` holds the distinct labels and the values are ``base[codes]``.
    Built by :func:`normalise_columns`; every renderer reads columns in this form.

    Attributes
    ----------
    base : ndarray
        The values (or, with ``codes``, the distinct labels), of kind b, i, f or U.
    mask : ndarray of bool or None
        True where a value is missing (None in the input); None when nothing is missing.
    codes : ndarray of intp or None
        Indices into ``base`` of a categorical column.
    """

    base: npt.NDArray[Any]
    mask: npt.NDArray[np.bool_] | None
    codes: npt.NDArray[np.intp] | None = None

    @property
    def values(self) -> npt.NDArray[Any]:
        """The value of every row (``base[codes]`` for a categorical column)."""
        return self.base if self.codes is None else self.base[self.codes]

    @property
    def n(self) -> int:
        """The number of rows."""
        return int((self.base if self.codes is None else self.codes).shape[0])

    @property
    def kind(self) -> str:
        """The NumPy kind of the values: ``"b"``, ``"i"``, ``"f"`` or ``"U"``."""
        return self.base.dtype.kind


#: Normalised columns: name -> Leaf, or name -> {name -> Leaf}.
Normalised = Mapping[str, "Leaf | dict[str, Leaf]"]


def _leaf(name: str, values: Any) -> Leaf:
    if isinstance(values, Categorical):
        codes = np.asarray(values.codes)
        labels = _leaf(name, values.labels)
        if codes.ndim != 1 or codes.dtype.kind not in "iu" or labels.mask is not None:
            raise StringStabError(
                f"result column {name!r}: a Categorical needs 1-D integer codes and labels "
                f"without missing values; got codes of shape {codes.shape}, dtype {codes.dtype}"
            )
        return Leaf(labels.base, None, codes.astype(np.intp, copy=False))
    a = np.asarray(values)
    if a.ndim != 1:
        raise StringStabError(f"result column {name!r} must be one-dimensional; got shape {a.shape}")
    k = a.dtype.kind
    if k in "biuf":
        return Leaf(a.astype(np.int64) if k == "u" else a, None)
    if k == "U":
        return Leaf(a, None)
    if k == "S":
        return Leaf(a.astype(str), None)
    if k != "O":
        raise StringStabError(f"result column {name!r}: unsupported dtype {a.dtype}")
    items = a.tolist()
    mask = np.fromiter((v is None for v in items), dtype=bool, count=len(items))
    present = [v for v in items if v is not None]
    if all(isinstance(v, (bool, np.bool_)) for v in present):
        vals: npt.NDArray[Any] = np.array([bool(v) if v is not None else False for v in items])
    elif all(isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_))
             for v in present):
        vals = np.array([int(v) if v is not None else 0 for v in items], dtype=np.int64)
    elif all(isinstance(v, (int, float, np.integer, np.floating))
             and not isinstance(v, (bool, np.bool_)) for v in present):
        vals = np.array([float(v) if v is not None else np.nan for v in items], dtype=np.float64)
    else:
        vals = np.array(["" if v is None else str(v) for v in items], dtype=str)
    return Leaf(vals, mask if mask.any() else None)


def normalise_columns(columns: Columns) -> Normalised:
    """Check the shape of every column and normalise their types.

    Parameters
    ----------
    columns : mapping
        Ordered columns ``name → 1-D array`` (or ``name → {name → array}``), one length.

    Returns
    -------
    dict
        The same names, each column as a :class:`Leaf` (groups as dicts of them).

    Raises
    ------
    StringStabError
        On a column that is not one-dimensional, of an unsupported type, or of another length
        than the others.
    """
    out: dict[str, Leaf | dict[str, Leaf]] = {}
    n: int | None = None

    def check(name: str, leaf: Leaf) -> Leaf:
        nonlocal n
        if n is None:
            n = leaf.n
        elif leaf.n != n:
            raise StringStabError(
                f"result column {name!r} has {leaf.n} rows; expected {n} like the others"
            )
        return leaf

    for name, col in columns.items():
        if isinstance(col, Mapping):
            out[name] = {k: check(f"{name}.{k}", _leaf(f"{name}.{k}", v)) for k, v in col.items()}
        else:
            out[name] = check(name, _leaf(name, col))
    return out


def n_rows(cols: Normalised) -> int:
    """The number of rows of normalised columns (0 without columns).

    Parameters
    ----------
    cols : mapping
        Columns from :func:`normalise_columns`.

    Returns
    -------
    int
        The length shared by every column.
    """
    for c in cols.values():
        if isinstance(c, dict):
            for leaf in c.values():
                return leaf.n
        else:
            return c.n
    return 0


def flat_leaves(cols: Normalised, sep: str = "_") -> dict[str, Leaf]:
    """Normalised columns with the groups expanded in place (``group<sep>name``).

    Parameters
    ----------
    cols : mapping
        Columns from :func:`normalise_columns`.
    sep : str, default "_"
        Joins a group's name and a column's name.

    Returns
    -------
    dict of str to Leaf
        One flat mapping, in order.
    """
    out: dict[str, Leaf] = {}
    for name, c in cols.items():
        if isinstance(c, dict):
            for k, leaf in c.items():
                out[f"{name}{sep}{k}"] = leaf
        else:
            out[name] = c
    return out


def flatten_columns(columns: Columns, sep: str = "_") -> dict[str, npt.NDArray[Any]]:
    """Grouped columns as one flat mapping (``group_name``), in order.

    Missing values become NaN in float columns and ``""`` in string columns.

    Parameters
    ----------
    columns : mapping
        Ordered columns ``name → 1-D array`` (or ``name → {name → array}``), one length.
    sep : str, default "_"
        Joins a group's name and a column's name.

    Returns
    -------
    dict of str to ndarray
        The flat columns, groups expanded in place.

    Examples
    --------
    >>> flatten_columns({"k_x": [1.0], "taylor": {"sign": ["stable"]}})
    {'k_x': array([1.]), 'taylor_sign': array(['stable'], dtype='<U6')}
    """
    return {k: leaf.values for k, leaf in flat_leaves(normalise_columns(columns), sep).items()}


def columns_from_records(records: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """Row records (dicts, one nesting level) as columns; keys missing in a record are None.

    Parameters
    ----------
    records : sequence of mapping
        One dict per row; a value that is a mapping is a group of columns.

    Returns
    -------
    dict
        Columns as lists (groups as dicts of lists), keys in order of first appearance.

    Examples
    --------
    >>> columns_from_records([{"a": 1.0, "g": {"x": "u"}}, {"a": None, "g": {"x": "v"}}])
    {'a': [1.0, None], 'g': {'x': ['u', 'v']}}
    """
    keys: dict[str, dict[str, None] | None] = {}
    for r in records:
        for k, v in r.items():
            if isinstance(v, Mapping):
                sub = keys.get(k)
                if sub is None:
                    sub = keys[k] = {}
                for kk in v:
                    sub.setdefault(str(kk), None)
            else:
                keys.setdefault(k, None)
    out: dict[str, Any] = {}
    for k, sub in keys.items():
        if sub is None:
            out[k] = [r.get(k) for r in records]
        else:
            out[k] = {kk: [(r.get(k) or {}).get(kk) for r in records] for kk in sub}
    return out


def records_from_columns(columns: Columns) -> list[dict[str, Any]]:
    """The rows of result columns as plain dicts (groups nested; NaN, inf and None as None).

    The inverse of :func:`columns_from_records`, and the rows of the ``json`` format.

    Parameters
    ----------
    columns : mapping
        Ordered columns ``name → 1-D array`` (or ``name → {name → array}``), one length.

    Returns
    -------
    list of dict
        One dict per row, values as plain Python values.

    Examples
    --------
    >>> records_from_columns({"a": np.array([1.0, np.inf]), "g": {"x": np.array([1, 2])}})
    [{'a': 1.0, 'g': {'x': 1}}, {'a': None, 'g': {'x': 2}}]
    """
    cols = normalise_columns(columns)

    def plain(leaf: Leaf) -> list[Any]:
        vals = leaf.values.tolist()
        if leaf.kind == "f":
            vals = [v if v - v == 0.0 else None for v in vals]
        if leaf.mask is not None:
            for i in np.flatnonzero(leaf.mask).tolist():
                vals[i] = None
        return vals

    names: list[str] = []
    lists: list[Any] = []
    for name, c in cols.items():
        names.append(name)
        if isinstance(c, dict):
            keys = list(c)
            sub = [plain(leaf) for leaf in c.values()]
            lists.append([dict(zip(keys, row)) for row in zip(*sub)] if sub else [])
        else:
            lists.append(plain(c))
    return [dict(zip(names, row)) for row in zip(*lists)]

