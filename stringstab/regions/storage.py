"""The files of a region map: its metadata, per-point fields and columns, writers and reader.

:class:`~stringstab.regions.RegionMap` is the result; this module turns one into what its
files hold and back (issue 32 item 5: the result apart from its files):

* :func:`metadata` (parameters, axes, methods, code tables, tool version) and :func:`fields`
  (the per-point arrays by name): what the NPZ archive holds (:func:`save_npz`);
* :func:`columns` (one column per field, one row per grid point, labels for people) and
  :func:`csv_text`: what the CSV table holds (:func:`save_csv`);
* :func:`read_map`: the fields of a :class:`~stringstab.regions.RegionMap` read back from an
  NPZ archive (:func:`stringstab.regions.load_npz` builds the map from them).

The byte formats themselves are :mod:`stringstab.regions.files`'.  The map's methods of the
same names (:meth:`RegionMap.save_npz <stringstab.regions.RegionMap.save_npz>`, ...) call
these functions.
"""

from __future__ import annotations

import builtins
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from ..certify.criteria import TYPE_NAMES
from ..errors import StringStabError
from ..io import dumps_json
from ..params import Box, Params
from .codes import GAIN_NAMES, VERDICT_LABELS
from .files import FORMAT, read_npz, write_csv, write_npz
from .files import csv_text as format_csv

if TYPE_CHECKING:  # type hints only: RegionMap's module imports this one
    from .result import RegionMap

__all__ = ["categorical_columns", "columns", "csv_text", "fields", "metadata", "read_map",
           "save_csv", "save_npz"]


def metadata(rmap: RegionMap) -> dict[str, Any]:
    """Parameters, axes, methods, code tables and the tool version of ``rmap`` (for files).

    Parameters
    ----------
    rmap : RegionMap
        The map.

    Returns
    -------
    dict
        JSON-ready; its ``format`` is :data:`stringstab.regions.files.FORMAT`.
    """
    return {
        "format": FORMAT,
        "stringstab_version": rmap.version,
        "params": rmap.params.as_dict(),
        **({} if rmap.sample_time is None else {"sample_time": rmap.sample_time}),
        **({} if rmap.message_period is None else {"message_period": rmap.message_period}),
        **({"heterogeneous": rmap.heterogeneous}
           if rmap.sample_time is not None and rmap.is_box else {}),
        "axes": {n: {"min": float(a[0]), "max": float(a[-1]), "n": int(a.size)}
                 for n, a in rmap.axes.items()},
        "fixed": dict(rmap.fixed),
        "methods": list(rmap.methods),
        "verdict_labels": {m: list(VERDICT_LABELS[m]) for m in rmap.methods},
        "type_names": {str(k): v for k, v in TYPE_NAMES.items()},
    }


def fields(rmap: RegionMap) -> dict[str, npt.NDArray[Any]]:
    """The per-point arrays of ``rmap`` by name (``hurwitz``, ``type``, ``verdict_<method>``, ...).

    Parameters
    ----------
    rmap : RegionMap
        The map.

    Returns
    -------
    dict of str to ndarray
        Each of the grid's shape; the fields not evaluated are left out.
    """
    f: dict[str, npt.NDArray[Any]] = {"hurwitz": rmap.hurwitz}
    if rmap.type is not None:
        f["type"] = rmap.type
    if rmap.hurwitz_continuous is not None:
        f["hurwitz_continuous"] = rmap.hurwitz_continuous
    if rmap.stability_undecided is not None:
        f["stability_undecided"] = rmap.stability_undecided
    if rmap.type_printed is not None:
        f["type_printed"] = rmap.type_printed
    for m, code in rmap.verdict.items():
        f[f"verdict_{m}"] = code
    for m, ok in rmap.prop1.items():
        f[f"prop1_{m}"] = ok
    if rmap.sup_gain is not None:
        f["sup_gain"] = rmap.sup_gain
    if rmap.margin is not None:
        f["margin"] = rmap.margin
    return f


def categorical_columns(rmap: RegionMap) -> dict[str, Any]:
    """:func:`columns` with the coordinates and labels as :class:`~stringstab.io.Categorical`.

    Categorical columns are codes into a few distinct values: what the CSV writer formats
    fastest.  Computed once per map (the map is immutable) and kept on it.

    Parameters
    ----------
    rmap : RegionMap
        The map.

    Returns
    -------
    dict
        The columns of :func:`columns`, in order.
    """
    cached = rmap.__dict__.get("_categorical")
    if cached is not None:
        return dict(cached)
    from ..io import Categorical

    shape = rmap.shape
    cols: dict[str, Any] = {}
    index = np.indices(shape).reshape(len(shape), -1)
    axis_pos = {name: i for i, name in enumerate(rmap.axis_names)}
    for name in GAIN_NAMES:  # the axes' values, or the fixed value, spread over the grid
        if name in axis_pos:
            cols[name] = Categorical(index[axis_pos[name]], np.asarray(rmap.axes[name], float))
        else:
            cols[name] = Categorical(np.zeros(rmap.size, dtype=np.intp),
                                     np.asarray([rmap.fixed[name]], dtype=float))
    names = np.array(["", *TYPE_NAMES.values()])
    cols["hurwitz"] = rmap.hurwitz.ravel()
    if rmap.type is not None:
        cols["type"] = Categorical(rmap.type.ravel(), names)
    if rmap.type_printed is not None:
        cols["type_printed"] = Categorical(rmap.type_printed.ravel(), names)
    for m in rmap.methods:
        cols[m] = Categorical(rmap.verdict[m].ravel(), np.array(VERDICT_LABELS[m]))
    if rmap.sup_gain is not None:
        cols["sup_gain"] = rmap.sup_gain.ravel()
    if rmap.margin is not None:
        cols["margin"] = rmap.margin.ravel()
    object.__setattr__(rmap, "_categorical", cols)  # computed once (the map is immutable)
    return dict(cols)


def columns(rmap: RegionMap) -> dict[str, npt.NDArray[Any]]:
    """One column per field, one row per grid point (flattened in C order), for people.

    ``k_x, k_v, k_a``, ``hurwitz``, ``type`` (I-IV), ``type_printed``, one verdict column per
    method (its labels, :data:`~stringstab.regions.VERDICT_LABELS`), ``sup_gain`` and
    ``margin`` (when evaluated): the columns of :func:`save_csv`.  Computed once per map.

    Parameters
    ----------
    rmap : RegionMap
        The map.

    Returns
    -------
    dict of str to ndarray
        The columns, each of ``rmap.size`` rows.
    """
    cached = rmap.__dict__.get("_columns")
    if cached is None:
        cached = {k: np.asarray(v) for k, v in categorical_columns(rmap).items()}
        object.__setattr__(rmap, "_columns", cached)  # computed once (the map is immutable)
    return dict(cached)


def save_npz(rmap: RegionMap, path: str | os.PathLike[str]) -> Path:
    """Write ``rmap`` to a compressed NPZ archive with its metadata, atomically.

    The archive holds ``axis_<gain>`` coordinates, one array per :func:`fields` entry and
    ``metadata``, :func:`metadata` as a JSON string (:func:`stringstab.regions.files.write_npz`).

    Parameters
    ----------
    rmap : RegionMap
        The map.
    path : str or path-like
        The file to write.

    Returns
    -------
    Path
        ``path``.
    """
    return write_npz(path, rmap.axes, fields(rmap), metadata(rmap))


def csv_text(rmap: RegionMap, rows: builtins.slice | None = None, *, head: bool = True) -> str:
    """The CSV text of ``rmap`` (:func:`save_csv`), or of the grid points ``rows`` only.

    ``head=False`` leaves out the ``#`` lines and the header, so that the texts of
    consecutive row ranges concatenate to the whole file (two processes can write one).

    Parameters
    ----------
    rmap : RegionMap
        The map.
    rows : slice, optional
        The grid points (flattened in C order) to write; None for all.
    head : bool
        Start with the ``#`` lines and the header.

    Returns
    -------
    str
        The CSV text.
    """
    comments = _comments(rmap) if head else None
    cols = categorical_columns(rmap)
    if rows is not None:
        cols = {k: v[rows] for k, v in cols.items()}
    return format_csv(cols, comments)


def _comments(rmap: RegionMap) -> list[str]:
    """The ``#`` lines of the CSV: the tool and the map's metadata as JSON."""
    return [f"stringstab {rmap.version} region map",
            dumps_json(metadata(rmap), indent=None).rstrip("\n")]


def save_csv(rmap: RegionMap, path: str | os.PathLike[str]) -> Path:
    """Write one CSV row per grid point of ``rmap``, after ``#`` lines with the metadata.

    Columns: :func:`columns`.  The first line is ``# stringstab <version> region map``, the
    second ``# `` followed by :func:`metadata` as JSON; then the header and the rows, written
    column by column (:mod:`stringstab.io`'s writer: numbers in their shortest round-trip
    form, booleans ``True``/``False``, a non-finite number, such as ``sup_gain`` where Γ is
    not internally stable, as an empty field).  Written atomically.

    Parameters
    ----------
    rmap : RegionMap
        The map.
    path : str or path-like
        The file to write.

    Returns
    -------
    Path
        The file written.
    """
    return write_csv(path, categorical_columns(rmap), _comments(rmap))


def read_map(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The fields of the :class:`~stringstab.regions.RegionMap` saved by :func:`save_npz`.

    Parameters
    ----------
    path : str or path-like
        The NPZ file.

    Returns
    -------
    dict
        The keyword arguments of ``RegionMap(...)``: axes, fixed gains, parameters (a
        :class:`~stringstab.params.Params` or a :class:`~stringstab.params.Box`), methods and
        per-point fields.

    Raises
    ------
    StringStabError
        If the file is not a stringstab region map.
    """
    meta, data = read_npz(path)
    need = ("methods", "params", "axes", "fixed", "stringstab_version")
    missing = [k for k in need if k not in meta]
    arrays = ["hurwitz", *(f"axis_{n}" for n in meta.get("axes", ())),
              *(f"verdict_{m}" for m in meta.get("methods", ()))]
    missing += [k for k in arrays if k not in data]
    if missing:
        raise StringStabError(f"{path}: expected a region map with {', '.join(missing)}; "
                              f"found metadata keys {sorted(meta)} and arrays {sorted(data)}")
    methods = tuple(meta["methods"])
    p = meta["params"]
    params: Params | Box = (Box(*(tuple(p[k]) for k in ("tau", "delta", "headway")))
                            if isinstance(p["tau"], list) else Params(**p))
    return dict(
        axes={n: data[f"axis_{n}"] for n in meta["axes"]},
        fixed={k: float(v) for k, v in meta["fixed"].items()},
        params=params, methods=methods,
        hurwitz=data["hurwitz"], type=data.get("type"),
        verdict={m: data[f"verdict_{m}"] for m in methods},
        prop1={m: data[f"prop1_{m}"] for m in methods if f"prop1_{m}" in data},
        type_printed=data.get("type_printed"), sup_gain=data.get("sup_gain"),
        margin=data.get("margin"), version=meta["stringstab_version"],
        sample_time=meta.get("sample_time"), heterogeneous=bool(meta.get("heterogeneous", True)),
        hurwitz_continuous=data.get("hurwitz_continuous"),
        message_period=meta.get("message_period"),
        stability_undecided=data.get("stability_undecided"),
    )
