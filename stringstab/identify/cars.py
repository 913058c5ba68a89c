"""One certificate per car: every log of the same car and distance setting pooled.

A car's law does not change from one log to the next; its verdict should not either.
:func:`identify_cars` groups the followers of all the logs given by **(car, setting)** — the
car is its name in the logs (OpenACC: the ``Vehicle_order`` names; a long CSV table: its
``vehicle`` column), the setting comes from the metadata (:func:`~stringstab.identify.spacing.
distance_setting`: short/medium/long where ACC is on, ``human`` where it is off) — and fits
each group **jointly**: one set of law parameters (k_x, k_v, τ, T*, l_0, θ_r) for all its logs,
with the initial state of every segment of every log free as before (nuisance parameters).
The records are laid end to end with a missing sample between logs, so a segment never
straddles two logs: the closed-loop simulation restarts at each, the block bootstrap draws
blocks within each (the pooled bootstrap resamples all the car's data at once), the spectra
of the data's own transfer are averaged over all of them, and the spacing policy sees every
quasi-steady stretch of every log (so logs at different speeds identify T* where one log
alone cannot).

Why a joint fit rather than averaging per-log verdicts: each log is a noisy view of the same
law, and the least-squares fit over all of them is the estimate that weights each log by how
much it says (a short or flat log moves it little); the per-log verdicts differ mostly by
what each log's speed profile excites.  The bootstrap of the joint fit gives the car's
uncertainty.  Logs with different sample times are refused (one line).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import StringStabError, show
from ..io.platoon_logs import PlatoonLog, Segment
from .core import FitProgress, check_settings
from .estimate import Estimate, Settings, estimate
from .fit import FollowerData
from .record import FollowerRecord, follower_record, missing_vehicles
from .spacing import distance_setting

__all__ = ["CarResult", "CarsResult", "identify_cars", "pool_records"]


@dataclass(kw_only=True)
class CarResult(Estimate):
    """One car at one setting, every log pooled (module docstring)."""

    car: str
    setting: str
    distance_setting: str = ""
    logs: list[str] = field(default_factory=list)
    records: list[dict[str, Any]] = field(default_factory=list)

    def row(self) -> dict[str, Any]:
        """The ``cars.json`` row (issue 28's fields first, then the estimate's).

        ``verdict`` is the bootstrap-supported verdict (``point_verdict`` the certificate's on
        the pooled point fit); the intervals are ``[lo, hi]`` lists.
        """
        f = self.fields()
        head = {"car": self.car, "setting": self.setting, "logs": list(self.logs),
                "k_x": f["k_x"], "k_v": f["k_v"], "k_a": f["k_a"], "tau": f["tau"],
                "reaction_delay": f["reaction_delay"], "headway": f["headway"],
                "headway_interval": list(self.headway_interval()), "standstill": f["standstill"],
                "sup_gain": f["sup_gain"], "sup_gain_interval": [f["sup_gain_lo"], f["sup_gain_hi"]],
                "verdict": f["supported_verdict"], "certified_share": f["certified_share"],
                "empirical_gain": f["empirical_gain"], "point_verdict": f["verdict"],
                "distance_setting": self.distance_setting}
        rest = {k: v for k, v in f.items() if k not in head and k not in ("verdict", "supported_verdict")}
        return {**head, **rest}

    def flat_row(self) -> dict[str, Any]:
        """:meth:`row` for CSV and Parquet: intervals as ``_lo``/``_hi`` columns, logs joined."""
        r = self.row()
        for k in ("headway_interval", "sup_gain_interval"):
            lo, hi = r.pop(k)
            r[k + "_lo"], r[k + "_hi"] = lo, hi
        r["logs"] = "; ".join(r["logs"])
        return r


@dataclass
class CarsResult:
    """The car-level table: one :class:`CarResult` per (car, setting).

    Attributes
    ----------
    cars : list of CarResult
        In the order the cars first appear in the logs.
    model : str
        ``"acc"`` or ``"cacc"``.
    sample_time : float or None
        H of the sampled certificate, or None.
    settings : dict
        The options.
    sources : list of str
        The files read.
    skipped : list of str
        Followers not used (no usable segment), vehicles absent from a log.
    """

    cars: list[CarResult]
    model: str
    sample_time: float | None
    settings: dict[str, Any]
    sources: list[str]
    skipped: list[str] = field(default_factory=list)

    def rows(self) -> list[dict[str, Any]]:
        """One flat row per car (:meth:`CarResult.flat_row`)."""
        return [c.flat_row() for c in self.cars]

    def document(self) -> dict[str, Any]:
        """The ``cars.json`` document: settings and the ``cars`` list (rows with notes)."""
        cars = []
        for c in self.cars:
            r = c.row()
            r["records"] = c.records
            r["notes"] = c.fit.notes + c.notes
            r["headway_profile"] = c.profile
            r["delay_profile"] = c.delay_profile
            cars.append(r)
        return {"command": "identify", "by": "car", "model": self.model, "sample_time": self.sample_time,
                "sources": self.sources, "settings": self.settings, "skipped": self.skipped, "cars": cars}


def pool_records(records: Sequence[FollowerRecord]) -> FollowerData:
    """Lay the records of one car end to end, a missing sample between two, as one record.

    Parameters
    ----------
    records : sequence of FollowerRecord
        The car's records (same sample time).

    Returns
    -------
    FollowerData
        The signals concatenated (NaN between records) and every record's segments, shifted.

    Raises
    ------
    StringStabError
        If the records' sample times differ.
    """
    dt = records[0].data.dt
    for r in records[1:]:
        if abs(r.data.dt - dt) > 1e-6 * dt:
            raise StringStabError(f"--by car pools logs of one sample time; found {dt:g} s and "
                                  f"{r.data.dt:g} s for the same car")
    parts: dict[str, list[np.ndarray]] = {"v_pred": [], "v": [], "gap": [], "a_pred": []}
    segs: list[Segment] = []
    offset = 0
    with_acc = all(r.data.a_pred is not None for r in records)
    for r in records:
        d = r.data
        for k in ("v_pred", "v", "gap"):
            parts[k] += [getattr(d, k), np.full(1, np.nan)]
        if with_acc:
            parts["a_pred"] += [d.a_pred, np.full(1, np.nan)]  # type: ignore[list-item]
        segs += [Segment(s.start + offset, s.stop + offset) for s in d.segments]
        offset += d.v.size + 1
    a_pred = np.concatenate(parts["a_pred"]) if with_acc else None
    return FollowerData(np.concatenate(parts["v_pred"]), np.concatenate(parts["v"]),
                        np.concatenate(parts["gap"]), a_pred, tuple(segs), dt)


def identify_cars(logs: Sequence[PlatoonLog], model: str = "acc", *, sample_time: float | None = None,
                  bootstrap: int = 50, block: float = 20.0, n_starts: int = 4, seed: int = 0,
                  min_duration: float = 30.0, progress: bool | None = None, fit_delay: bool = False,
                  baselines: bool = False, screen: bool = True) -> CarsResult:
    """Identify each car once, pooling all its logs at one setting (module docstring).

    Parameters
    ----------
    logs : sequence of PlatoonLog
        The recorded platoons.
    model, sample_time, bootstrap, block, n_starts, seed, min_duration, progress, fit_delay, baselines, screen
        As for :func:`stringstab.identify.identify`.

    Returns
    -------
    CarsResult
        One row per (car, setting).

    Raises
    ------
    StringStabError
        If no follower has a usable segment, an option is out of range, or the logs of one car
        have different sample times.
    """
    s = Settings(model, sample_time, int(bootstrap), float(block), n_starts, seed, min_duration, fit_delay,
                 baselines, screen)
    check_settings(s)
    groups: dict[tuple[str, str], list[tuple[PlatoonLog, int, FollowerRecord]]] = {}
    raw_setting: dict[tuple[str, str], str] = {}
    skipped: list[str] = []
    for lg in logs:
        skipped += [f"{lg.source}: {m}" for m in missing_vehicles(lg)]
        setting, raw = distance_setting(lg.meta)
        for p in lg.followers():
            rec = follower_record(lg, p, min_duration=min_duration, screen=screen)
            if not rec.data.segments:
                skipped.append(f"{lg.source}: {lg.name(p)} (position {p}): no clean segment of at least "
                               f"{min_duration:g} s")
                continue
            if model == "cacc" and rec.data.a_pred is None:
                raise StringStabError(f"--model cacc needs the predecessor's acceleration (an a column); "
                                      f"{show(lg.source)} has none for {lg.name(p - 1)}")
            key = (lg.name(p), setting)
            groups.setdefault(key, []).append((lg, p, rec))
            raw_setting.setdefault(key, raw)
    if not groups:
        raise StringStabError(
            "no follower has a usable segment (predecessor speed, own speed and gap all measured "
            f"for at least {min_duration:g} s); " + ("; ".join(skipped) or "found none"))
    bar = FitProgress(len(groups) * (1 + s.bootstrap), progress)
    rng = np.random.default_rng(seed)
    cars = []
    try:
        for (car, setting), members in groups.items():
            data = pool_records([r for _, _, r in members])
            est = estimate(data, s, rng, bar.labelled(car))
            names = [f"{Path(lg.source).name}#{p}" for lg, p, _ in members]
            records = [{"log": lg.source, "position": p, "predecessor": lg.name(p - 1),
                        "samples": r.data.n_samples, "segments": len(r.data.segments)} for lg, p, r in members]
            cr = CarResult(**{k: getattr(est, k) for k in est.__dataclass_fields__}, car=car, setting=setting,
                           distance_setting=raw_setting[(car, setting)], logs=names, records=records)
            cr.notes = [f"{n} ({Path(lg.source).name}#{p})" for lg, p, r in members for n in r.notes] + cr.notes
            if len(members) > 1:
                cr.notes.insert(0, f"pooled: {len(members)} logs, {data.n_samples} samples in "
                                   f"{len(data.segments)} segments, one joint fit")
            cars.append(cr)
    finally:
        bar.close()
    return CarsResult(cars, model, sample_time, s.document(), [lg.source for lg in logs], skipped)
