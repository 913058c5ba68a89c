"""A string of followers from a file: ``identify.json`` or a CSV list of parameters.

:func:`read_vehicles` reads

* an ``identify.json`` written by ``stringstab identify`` (:mod:`stringstab.identify.report`):
  its ``vehicles`` in recorded order (positions 1..N behind the leader, position 0) with their
  fitted k_x, k_v, k_a, τ, δ, T* (and the standstill distance l_0), and the log they were
  identified from (``sources``).  A string needs every follower between its head and its
  tail: the longest run of consecutive identified positions is used (the others are named in
  a note), or the run chosen with ``positions``; its head's predecessor is the string's
  leader.  The string's own positions are 1..N (the leader 0), whatever the log's numbers; or
* a CSV with one row per follower in order and the columns ``k_x,k_v,k_a,tau,delta,headway``
  (optional ``reaction_delay``, ``name``, ``standstill``).

Every value is checked by the certificates' way in
(:func:`stringstab.certify.string_certificate.check_vehicles`); a file that cannot be read, a
missing column or cell, a cell that is not a number, an empty or one-vehicle list, or a
string with a follower missing (a position identify skipped) is refused in one line naming
the file and the place (:class:`~stringstab.errors.StringStabError`).
"""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..certify.head_to_tail import Vehicle
from ..certify.string_certificate import OPTIONAL, REQUIRED, check_vehicles
from ..errors import StringStabError, show

__all__ = ["DEFAULT_STANDSTILL", "RecordedString", "read_vehicles"]

#: l_0 of a CSV row without a ``standstill`` column, m (used by the simulation only).
DEFAULT_STANDSTILL = 2.0


@dataclass(frozen=True)
class RecordedString:
    """Followers in order behind a leader, as read from a file.

    Attributes
    ----------
    vehicles : tuple of Vehicle
        Positions 1..N, checked.
    standstill : tuple of float
        l_0 of each, m (the simulation's spacing policy l_0 + T* v).
    source : str
        The file read.
    kind : str
        ``"identify"`` or ``"csv"``.
    log : str or None
        The recorded log the vehicles were identified from (identify.json only).
    platoon : int
        The platoon (log) of identify.json used.
    positions : tuple of int
        The recorded positions (in the log's numbering) of followers 1..N.
    sample_time : float or None
        identify's sample time (identify.json), s.
    min_duration : float
        identify's shortest clean segment, s (the empirical transfer uses the same).
    leader : str
        The name of the string's leader (the first follower's recorded predecessor).
    note : str
        Followers of the file left out of the string, and why ("" when none).
    """

    vehicles: tuple[Vehicle, ...]
    standstill: tuple[float, ...]
    source: str
    kind: str
    log: str | None = None
    platoon: int = 0
    positions: tuple[int, ...] = ()
    sample_time: float | None = None
    min_duration: float = 30.0
    leader: str = ""
    note: str = ""

    @property
    def names(self) -> list[str]:
        """The vehicles' names (``"vehicle i"`` where a file gives none)."""
        return [v.name or f"vehicle {i}" for i, v in enumerate(self.vehicles, start=1)]


def _where(path: Path) -> str:
    return f"vehicle list {show(str(path))}"


def _number(text: Any, what: str) -> float | None:
    """A cell as a float; None when empty; an error naming ``what`` otherwise."""
    if text is None:
        return None
    if isinstance(text, bool):
        raise StringStabError(f"{what} must be a number; got {show(text)}")
    if isinstance(text, (int, float)):
        return float(text)
    s = str(text).strip()
    if s == "":
        return None
    try:
        return float(s)
    except ValueError as e:
        raise StringStabError(f"{what} must be a number; got {show(text)}") from e


def _read_csv(path: Path, text: str) -> RecordedString:
    rows = list(csv.reader(io.StringIO(text)))
    rows = [r for r in rows if any(c.strip() for c in r) and not r[0].lstrip().startswith("#")]
    if not rows:
        raise StringStabError(f"{_where(path)}: expected a header with the columns "
                              f"{','.join(REQUIRED)} and one row per follower; found an empty file")
    header = [c.strip() for c in rows[0]]
    missing = [c for c in REQUIRED if c not in header]
    if missing:
        raise StringStabError(f"{_where(path)}: expected the columns {','.join(REQUIRED)} "
                              f"(optional {','.join((*OPTIONAL, 'standstill'))}); missing "
                              f"{','.join(missing)} in the header {','.join(header)}")
    known = set(REQUIRED) | set(OPTIONAL) | {"standstill"}
    unknown = [c for c in header if c not in known]
    if unknown:
        raise StringStabError(f"{_where(path)}: unknown column {','.join(unknown)}; expected "
                              f"{','.join(REQUIRED)} (optional {','.join((*OPTIONAL, 'standstill'))})")
    recs: list[dict[str, Any]] = []
    standstill: list[float] = []
    for k, r in enumerate(rows[1:], start=1):
        if len(r) != len(header):
            raise StringStabError(f"{_where(path)}: row {k} has {len(r)} cells; expected "
                                  f"{len(header)} (the header's)")
        cells = dict(zip(header, (c.strip() for c in r)))
        rec: dict[str, Any] = {}
        for c in header:
            if c == "name":
                rec["name"] = cells[c]
                continue
            v = _number(cells[c], f"{_where(path)}: row {k}, column {c}")
            if v is None and c in REQUIRED:
                raise StringStabError(f"{_where(path)}: row {k}: missing {c} (each vehicle needs "
                                      f"{', '.join(REQUIRED)})")
            rec[c] = v
        standstill.append(_standstill(rec.pop("standstill", None), f"{_where(path)}: row {k}"))
        recs.append(rec)
    vs = _checked(path, recs)
    return RecordedString(vs, tuple(standstill), str(path), "csv",
                          positions=tuple(range(1, len(vs) + 1)))


def _standstill(v: Any, where: str) -> float:
    if v is None:
        return DEFAULT_STANDSTILL
    x = float(v)
    if not (math.isfinite(x) and x >= 0):
        raise StringStabError(f"{where}: standstill (l0) must be a finite number >= 0 m; got {show(v)}")
    return x


def _checked(path: Path, recs: list[dict[str, Any]]) -> tuple[Vehicle, ...]:
    try:
        return check_vehicles(recs)[0]
    except StringStabError as e:
        raise StringStabError(f"{_where(path)}: {e}") from e


def _runs(positions: list[int]) -> list[list[int]]:
    """Runs of consecutive integers in a sorted list."""
    runs: list[list[int]] = []
    for p in positions:
        if runs and p == runs[-1][-1] + 1:
            runs[-1].append(p)
        else:
            runs.append([p])
    return runs


def _read_identify(path: Path, doc: dict[str, Any], platoon: int | None,
                   span: tuple[int, int] | None) -> RecordedString:
    vehicles = doc.get("vehicles")
    if not isinstance(vehicles, list):
        raise StringStabError(f"{_where(path)}: expected an identify.json with a 'vehicles' list "
                              "(written by stringstab identify); found no such list")
    rows = [v for v in vehicles if isinstance(v, dict)]
    if len(rows) != len(vehicles):
        raise StringStabError(f"{_where(path)}: every entry of 'vehicles' must be an object")
    platoons = sorted({int(v.get("platoon", 0)) for v in rows})
    if platoon is None:
        if len(platoons) > 1:
            raise StringStabError(f"{_where(path)}: the vehicles come from {len(platoons)} logs "
                                  f"(platoons {platoons}); choose one with --platoon")
        platoon = platoons[0] if platoons else 0
    elif platoon not in platoons:
        raise StringStabError(f"{_where(path)}: --platoon {platoon} is not in the file; expected "
                              f"one of {platoons or 'none'}")
    rows = sorted((v for v in rows if int(v.get("platoon", 0)) == platoon),
                  key=lambda v: int(v.get("position", 0)))
    if not rows:
        raise StringStabError(f"{_where(path)}: expected vehicles in platoon {platoon}; found none")
    positions = [int(v.get("position", -1)) for v in rows]
    runs = _runs(positions)
    if span is not None:
        a, b = span
        if not any(r[0] <= a and b <= r[-1] for r in runs):
            raise StringStabError(
                f"{_where(path)}: --positions {a}:{b} is not a run of consecutive identified "
                f"followers; expected A:B within one of the runs "
                f"{', '.join(f'{r[0]}:{r[-1]}' for r in runs)}")
        chosen = list(range(a, b + 1))
    else:
        chosen = max(runs, key=len)  # the longest run (the first of equal ones)
    dropped = [v for v in rows if int(v["position"]) not in chosen]
    rows = [v for v in rows if int(v["position"]) in chosen]
    note = ""
    if dropped:
        note = (f"used the recorded followers {chosen[0]}..{chosen[-1]} (the "
                + ("chosen" if span is not None else "longest") + " run of consecutive identified "
                "positions); left out: " + ", ".join(f"{v.get('position')} {v.get('name', '')}".strip()
                                                      for v in dropped)
                + " (a string needs every follower between its head and its tail)")
    positions = chosen
    recs = []
    standstill = []
    for v in rows:
        rec = {k: v.get(k) for k in (*REQUIRED, "reaction_delay")}
        for k in (*REQUIRED, "reaction_delay"):
            rec[k] = _number(rec[k], f"{_where(path)}: vehicle {v.get('position')}, {k}")
        rec["name"] = str(v.get("name", ""))
        recs.append(rec)
        standstill.append(_standstill(_number(v.get("standstill"), f"{_where(path)}: standstill"),
                                      f"{_where(path)}: vehicle {v.get('position')}"))
    vs = _checked(path, recs)
    sources = doc.get("sources") or []
    log = str(sources[platoon]) if platoon < len(sources) else None
    settings = doc.get("settings") if isinstance(doc.get("settings"), dict) else {}
    H = doc.get("sample_time")
    return RecordedString(vs, tuple(standstill), str(path), "identify", log, platoon,
                          tuple(positions), None if H is None else float(H),
                          float(settings.get("min_duration", 30.0)),  # type: ignore[union-attr]
                          str(rows[0].get("predecessor", "")), note)


def read_vehicles(path: str | Path, *, platoon: int | None = None,
                  positions: tuple[int, int] | None = None) -> RecordedString:
    """The string of followers in a file (module docstring).

    Parameters
    ----------
    path : str or Path
        ``identify.json`` (any ``.json``) or a CSV list.
    platoon : int, optional
        identify.json of several logs: which one (its ``platoon`` index).
    positions : (int, int), optional
        identify.json: the recorded positions first..last of the string (a run of consecutive
        identified followers); default the longest such run.

    Returns
    -------
    RecordedString

    Raises
    ------
    StringStabError
        One line naming the file and what was expected (module docstring).
    """
    from ..io.text_input import read_text

    p = Path(path)
    if not p.exists():
        raise StringStabError(f"{_where(p)}: no such file")
    text = read_text(p, label=_where(p), expected="an identify.json or a CSV list of followers "
                     f"(columns {','.join(REQUIRED)})")
    if p.suffix.lower() == ".json" or text.lstrip().startswith("{"):
        try:
            doc = json.loads(text)
        except json.JSONDecodeError as e:
            raise StringStabError(f"{_where(p)}: not valid JSON ({e.msg} at line {e.lineno})") from e
        if not isinstance(doc, dict):
            raise StringStabError(f"{_where(p)}: expected a JSON object (identify.json); found "
                                  f"{type(doc).__name__}")
        if platoon is not None and platoon < 0:
            raise StringStabError(f"--platoon must be an integer >= 0; got {platoon}")
        return _read_identify(p, doc, platoon, positions)
    if platoon is not None or positions is not None:
        raise StringStabError("--platoon and --positions are for identify.json (a CSV list is "
                              "one string)")
    return _read_csv(p, text)
