"""The vehicles a SUMO scenario will insert, and when, read from its route files.

:func:`scheduled_departures` reads the ``route-files`` and ``additional-files`` of a
``.sumocfg`` (SUMO's XML: ``<vehicle>`` and ``<trip>`` with ``depart``, ``<flow>`` with
``begin`` and ``period``/``vehsPerHour``) so that
:func:`~stringstab.sumo.inscenario.run_scenario` can refuse a ``--controlled`` id that no file
defines before SUMO starts, and one that does not appear when it is due at the step it was due
(SUMO's own flow vehicles are named ``FLOW.INDEX``, the k-th departing at ``begin + k·period``).
A file it cannot read as plain XML (a ``.gz`` route file, say) leaves the schedule incomplete:
then nothing is refused up front and the ids are checked as the run goes and at its end.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import StringStabError

__all__ = ["Schedule", "scheduled_departures"]


def _seconds(text: str | None) -> float | None:
    """A SUMO time (seconds, or ``H:M:S``) as a number; None for 'triggered', 'now', ... ."""
    if text is None:
        return None
    t = text.strip()
    try:
        if ":" in t:
            parts = [float(p) for p in t.split(":")]
            value = 0.0
            for p in parts:
                value = 60.0 * value + p
            return value
        return float(t)
    except ValueError:
        return None


@dataclass
class Schedule:
    """What a scenario's route files say about its vehicles.

    Attributes
    ----------
    vehicles : dict of str to float or None
        Each ``<vehicle>``/``<trip>`` id and its depart time (s; None when not a number, e.g.
        ``"triggered"``).
    flows : dict of str to (float, float or None)
        Each ``<flow>`` id, its ``begin`` (s) and the time between its vehicles (s; None when
        unknown, e.g. a ``probability`` flow).
    begin : float
        The configuration's begin time, s.
    files : list of Path
        The route and additional files read.
    complete : bool
        False when a file could not be read as plain XML: the schedule may lack vehicles.
    """

    vehicles: dict[str, float | None] = field(default_factory=dict)
    flows: dict[str, tuple[float, float | None]] = field(default_factory=dict)
    begin: float = 0.0
    files: list[Path] = field(default_factory=list)
    complete: bool = True

    def depart(self, vid: str) -> float | None:
        """When ``vid`` is due to depart, s (None: unknown or not a number).

        Parameters
        ----------
        vid : str
            A vehicle id (a flow's vehicles are ``FLOW.INDEX``).

        Returns
        -------
        float or None
            The scheduled depart time.
        """
        if vid in self.vehicles:
            return self.vehicles[vid]
        flow, k = self.flow_of(vid)
        if flow is None:
            return None
        begin, period = self.flows[flow]
        return None if period is None else begin + k * period

    def flow_of(self, vid: str) -> tuple[str | None, int]:
        """The flow a vehicle id belongs to (``FLOW.INDEX``) and its index, or (None, -1).

        Parameters
        ----------
        vid : str
            A vehicle id.

        Returns
        -------
        (str or None, int)
            The flow's id and the vehicle's index in it.
        """
        m = re.fullmatch(r"(.+)\.(\d+)", vid)
        if m and m.group(1) in self.flows:
            return m.group(1), int(m.group(2))
        return None, -1

    def defines(self, vid: str) -> bool:
        """Whether some route file defines ``vid`` (a vehicle, a trip or a flow's vehicle).

        Parameters
        ----------
        vid : str
            A vehicle id.

        Returns
        -------
        bool
            True when ``vid`` is defined.
        """
        return vid in self.vehicles or self.flow_of(vid)[0] is not None


def _files(root: ET.Element, option: str, base: Path) -> list[Path]:
    out = []
    for el in root.iter(option):
        for name in re.split(r"[,\s]+", el.get("value") or ""):
            if name:
                out.append(Path(name) if os.path.isabs(name) else base / name)
    return out


def _flow_period(el: ET.Element) -> float | None:
    """The fixed time between a flow's vehicles (``period``, or 3600/``vehsPerHour``), s.

    None when it is random (``period="exp(...)"``, ``probability``) or left to SUMO
    (``number`` alone): such a flow's vehicles are checked at the run's end only.
    """
    period = _seconds(el.get("period"))  # None for a random "exp(rate)" period
    if period is not None:
        return period if period > 0 else None
    vph = _seconds(el.get("vehsPerHour"))
    if vph is not None and vph > 0:
        return 3600.0 / vph
    return None


def scheduled_departures(sumocfg: str | os.PathLike[str]) -> Schedule:
    """Read the vehicles, trips and flows of the route and additional files of ``sumocfg``.

    Parameters
    ----------
    sumocfg : path-like
        A SUMO configuration (already checked to be readable XML).

    Returns
    -------
    Schedule
        The ids, their depart times and the flows (see :class:`Schedule`).

    Raises
    ------
    StringStabError
        When the configuration itself is not readable XML.
    """
    cfg = Path(sumocfg)
    try:
        root = ET.parse(cfg).getroot()
    except (ET.ParseError, OSError) as e:
        raise StringStabError(f"--sumocfg {cfg}: expected a SUMO configuration (XML); {e}") from e
    begins = [_seconds(el.get("value")) for el in root.iter("begin")]
    sched = Schedule(begin=next((b for b in begins if b is not None), 0.0))
    base = cfg.resolve().parent
    for path in _files(root, "route-files", base) + _files(root, "additional-files", base):
        try:
            doc = ET.parse(path).getroot()
        except (ET.ParseError, OSError):
            sched.complete = False  # SUMO reads it (or fails); the run checks the ids
            continue
        sched.files.append(path)
        for el in doc.iter():
            vid = el.get("id")
            if vid is None:
                continue
            if el.tag in ("vehicle", "trip"):
                sched.vehicles[vid] = _seconds(el.get("depart"))
            elif el.tag == "flow":
                begin = _seconds(el.get("begin"))
                b = sched.begin if begin is None else begin
                sched.flows[vid] = (b, _flow_period(el))
    return sched
