"""A sweep folder's point records: ``DIR/points/<id>.json``, one per finished or failed point."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from .spec import SweepSpec

__all__ = ["POINT_FORMAT", "read_records", "record_path"]

#: Format tag of a point's record file.
POINT_FORMAT = "stringstab-sweep-point/1"


def record_path(out: str | os.PathLike[str], pid: str) -> Path:
    """Where the record of point ``pid`` lives in the sweep folder ``out``.

    Parameters
    ----------
    out : path
        The sweep folder.
    pid : str
        The point's id.

    Returns
    -------
    Path
        ``out/points/<pid>.json`` (it need not exist).
    """
    return Path(out) / "points" / f"{pid}.json"


def read_records(out: str | os.PathLike[str], spec: SweepSpec) -> dict[str, dict[str, Any]]:
    """The records in ``out`` of the points of ``spec`` (by id); absent points are left out.

    A record file that cannot be read (it cannot be partial: records are written atomically,
    but it could be damaged by hand) counts as absent, so its point runs again.

    Parameters
    ----------
    out : path
        The sweep folder.
    spec : SweepSpec
        Whose points to read.

    Returns
    -------
    dict
        Point id → record.
    """
    recs: dict[str, dict[str, Any]] = {}
    for p in spec.points:
        f = record_path(out, p.id)
        try:
            doc = json.loads(f.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if isinstance(doc, dict) and doc.get("format") == POINT_FORMAT and doc.get("id") == p.id:
            recs[p.id] = doc
    return recs
