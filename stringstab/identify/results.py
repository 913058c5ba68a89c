"""The results of :func:`stringstab.identify.identify`: one follower's, and the whole run's.

:class:`VehicleResult` is everything identified about one follower of one log (an
:class:`~stringstab.identify.estimate.Estimate` with who it is); :class:`IdentifyResult` holds
them all with the settings, the files read and what was skipped, and writes the rows and the
``identify.json`` document.  The pipeline that makes them is :mod:`stringstab.identify.core`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from .estimate import Estimate

__all__ = ["IdentifyResult", "VehicleResult"]


@dataclass(kw_only=True)
class VehicleResult(Estimate):
    """Everything identified about one follower of one log (see :func:`identify`)."""

    platoon: int
    position: int
    name: str
    predecessor: str
    setting: str = "unknown"
    distance_setting: str = ""

    def row(self) -> dict[str, Any]:
        """The JSON/CSV row: who (platoon, position, name, predecessor), then the estimate."""
        return {"platoon": self.platoon, "position": self.position, "name": self.name,
                "predecessor": self.predecessor, **self.fields(), "setting": self.setting,
                "distance_setting": self.distance_setting}


@dataclass
class IdentifyResult:
    """The identification of every follower of one or more logs.

    Attributes
    ----------
    vehicles : list of VehicleResult
        In (log, position) order.
    model : str
        ``"acc"`` or ``"cacc"``.
    sample_time : float or None
        H of the sampled certificate, or None (continuous time).
    settings : dict
        Bootstrap count, block length, starts, seed, minimum segment length, ...
    sources : list of str
        The files read.
    skipped : list of str
        Followers not identified, and vehicles absent from a log, with the reason.
    """

    vehicles: list[VehicleResult]
    model: str
    sample_time: float | None
    settings: dict[str, Any]
    sources: list[str]
    skipped: list[str] = field(default_factory=list)

    def rows(self) -> list[dict[str, Any]]:
        """One row per follower (:meth:`VehicleResult.row`)."""
        return [v.row() for v in self.vehicles]

    def document(self) -> dict[str, Any]:
        """The ``identify.json`` document: settings, ``vehicles`` (with ``segments`` and notes)."""
        vehicles = []
        for v in self.vehicles:
            r = v.row()
            r["segments"] = [{"start": s.start, "stop": s.stop, "t_start": float(s.start * v.data.dt),
                              "samples": len(s)} for s in v.segments]
            r["notes"] = v.fit.notes + v.notes
            r["correlation"] = v.fit.correlation
            r["headway_profile"] = v.profile
            r["delay_profile"] = v.delay_profile
            vehicles.append(r)
        return {"command": "identify", "model": self.model, "sample_time": self.sample_time,
                "sources": self.sources, "settings": self.settings, "skipped": self.skipped,
                "vehicles": vehicles}
