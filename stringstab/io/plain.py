"""JSON-safe plain Python values: the one JSON clean-up of the toolkit."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

__all__ = ["dumps_json", "to_plain"]


def to_plain(x: Any) -> Any:
    """``x`` with NumPy scalars and arrays as plain Python values; non-finite floats as ``None``.

    Mappings keep their order (keys become strings), tuples become lists, dataclass-like objects
    with an ``as_dict()`` method are converted through it.

    Parameters
    ----------
    x : object
        Any value; containers are converted recursively.

    Returns
    -------
    object
        The JSON-ready value; objects of other types are returned unchanged.

    Examples
    --------
    >>> to_plain({"a": np.float64(0.5), "b": np.array([1, 2]), "c": float("nan"), 1: (True,)})
    {'a': 0.5, 'b': [1, 2], 'c': None, '1': [True]}
    """
    t = type(x)
    if t is float:
        return x if x - x == 0.0 else None  # inf - inf and nan - nan are nan
    if t is str or t is int or t is bool or x is None:
        return x
    if isinstance(x, Mapping):
        return {k if type(k) is str else str(k): to_plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [to_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return to_plain(x.tolist())
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        f = float(x)
        return f if math.isfinite(f) else None
    if isinstance(x, np.generic):
        return to_plain(x.item())
    as_dict = getattr(x, "as_dict", None)
    if callable(as_dict):
        return to_plain(as_dict())
    return x


def dumps_json(doc: Any, *, indent: int | None = 2) -> str:
    """``doc`` as JSON text (UTF-8 characters kept, non-finite numbers as ``null``), newline-ended.

    Parameters
    ----------
    doc : object
        The document, converted by :func:`to_plain` first.
    indent : int or None, default 2
        Indentation of nested values; ``None`` writes one line.

    Returns
    -------
    str
        The JSON text, ending in a newline.

    Examples
    --------
    >>> print(dumps_json({"sup|Γ|": np.float64(1.0), "peak": float("inf")}, indent=None), end="")
    {"sup|Γ|": 1.0, "peak": null}
    """
    return json.dumps(to_plain(doc), indent=indent, ensure_ascii=False, allow_nan=False) + "\n"
