"""Recorded platoons: the OpenACC format, plain CSV tables and NGSIM pairs, in SI units.

A :class:`PlatoonLog` holds what car-following identification needs from a log: each recorded
vehicle's speed on one regular time grid, its position in the platoon (the leader is 0), and
the bumper-to-bumper gap of each follower to its predecessor.  Missing samples are NaN; they
are never filled in: :func:`clean_segments` splits a follower's record at every missing sample
into the runs in which predecessor speed, follower speed and gap are all measured.

Formats (:func:`read_platoon_logs` tells them apart from the header):

* **OpenACC** (Makridis et al. 2021, JRC): metadata lines (``Date``, ``Vehicle_order``,
  ``Number_of_vehicles``, ``ACC``, ``Distance_setting``, ...), then ``Time``, per vehicle k
  ``Speedk`` (m/s), ``Ek``, ``Nk`` (m), ``Lonk``, ``Latk``, ``Altk``, and ``IVSk``, the spacing
  between vehicle k and k + 1.  Vehicles absent from a file (a column set missing) leave a hole:
  the vehicle behind them has no predecessor record and is not identified.
* **plain CSV**: ``t, v_lead, v, gap`` (one follower), the wide form ``t, v0, v1, gap1, v2,
  gap2, ...`` (a platoon, vehicle 0 the leader), or a long table ``vehicle, t, v, gap`` (vehicles
  in platoon order, the leader first, its gap empty); optional ``a``/``a_lead``/``a0``... columns
  (m/s²).  A unit in the header (``v [km/h]``, ``v_kmh``) is converted; anything else is SI.
* **NGSIM** (US-101 / I-80 trajectory files): the leader–follower pairs of
  :func:`stringstab.traffic.load_ngsim_pairs`, one two-vehicle log per pair (through the
  ``ngsim`` reader that :func:`stringstab.identify.read_logs` passes in: the parser lives in
  the simulator's package, above this bottom layer).

Units are checked against the data itself: the speeds must agree with the positions (OpenACC:
E/N displacement per step) or with the spacing (CSV: d gap/dt = v_pred − v).  A speed column that
is 3.6 times too large (km/h labelled as m/s) is refused with the ratio found.
"""

from __future__ import annotations

import csv
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show
from .text_input import open_text

__all__ = ["SPEED_ABSURD", "PlatoonLog", "Segment", "clean_segments", "read_platoon_logs"]

Array = npt.NDArray[np.float64]

#: A speed above this (m/s, 250 km/h) is not a car on a road: the file is refused.
SPEED_ABSURD = 70.0
KMH = 1.0 / 3.6


@dataclass(frozen=True)
class Segment:
    """A run of samples ``[start, stop)`` in which a follower's record is complete."""

    start: int
    stop: int

    def __len__(self) -> int:
        return self.stop - self.start


@dataclass(frozen=True)
class PlatoonLog:
    """A recorded platoon on one regular time grid (SI units; NaN where not measured).

    Attributes
    ----------
    t : array (T,)
        Sample times, s (strictly increasing, regular step ``dt``).
    positions : tuple of int
        Platoon position of each recorded vehicle (leader 0, first follower 1).
    names : tuple of str
        Vehicle names, as in the file.
    speed : array (n, T)
        Speed of each recorded vehicle, m/s.
    gap : dict int -> array (T,)
        Bumper-to-bumper gap of the follower at that position to its predecessor, m.
    accel : array (n, T) or None
        Measured accelerations, m/s², when the file has them.
    source, fmt : str
        File and format (``"openacc"``, ``"csv"``, ``"ngsim"``).
    meta : dict
        Metadata of the file (OpenACC header lines, unit conversions, ...).
    """

    t: Array
    positions: tuple[int, ...]
    names: tuple[str, ...]
    speed: Array
    gap: dict[int, Array]
    accel: Array | None = None
    source: str = ""
    fmt: str = ""
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def dt(self) -> float:
        """Sampling step, s."""
        return float(np.median(np.diff(self.t)))

    def row(self, position: int) -> int:
        """Index into :attr:`speed` of the vehicle at ``position``."""
        return self.positions.index(position)

    def followers(self) -> list[int]:
        """Positions whose predecessor's speed and whose gap are both in the log."""
        return [p for p in self.positions if p - 1 in self.positions and p in self.gap]

    def name(self, position: int) -> str:
        """Name of the vehicle at ``position``."""
        return self.names[self.row(position)]

    def pair(self, position: int) -> tuple[Array, Array, Array, Array | None]:
        """(predecessor speed, follower speed, gap, predecessor acceleration or None)."""
        i, j = self.row(position - 1), self.row(position)
        a = None if self.accel is None else self.accel[i]
        return self.speed[i], self.speed[j], self.gap[position], a


def clean_segments(log: PlatoonLog, position: int, *, min_duration: float = 30.0) -> list[Segment]:
    """Maximal runs in which the follower at ``position`` is completely measured.

    A sample is usable when the predecessor's speed, the follower's speed and the gap are all
    finite; runs shorter than ``min_duration`` seconds are dropped.  Gaps are never bridged.

    Parameters
    ----------
    log : PlatoonLog
        The log.
    position : int
        The follower's platoon position (>= 1).
    min_duration : float
        Shortest run kept, s.

    Returns
    -------
    list of Segment
        In time order (possibly empty).
    """
    vp, v, g, _ = log.pair(position)
    ok = np.isfinite(vp) & np.isfinite(v) & np.isfinite(g)
    edges = np.flatnonzero(np.diff(np.r_[0, ok.astype(np.int8), 0]))
    n_min = max(math.ceil(min_duration / log.dt - 1e-9), 2)
    return [Segment(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2]) if b - a >= n_min]


# --------------------------------------------------------------------------- shared checks


def _where(path: Path) -> str:
    return f"platoon log {show(str(path))}"


def _check_time(t: Array, path: Path) -> Array:
    if t.size < 3:
        raise StringStabError(f"{_where(path)}: expected at least 3 samples; found {t.size}")
    if not np.isfinite(t).all():
        raise StringStabError(f"{_where(path)}: the time column must be finite; found NaN or empty cells")
    d = np.diff(t)
    if (d <= 0).any():
        k = int(np.argmax(d <= 0))
        raise StringStabError(
            f"{_where(path)}: time must increase strictly; found t = {t[k]:g} s followed by {t[k + 1]:g} s "
            f"(row {k + 2} of the data)")
    dt = float(np.median(d))
    if np.abs(d - dt).max() > 1e-3 * dt:
        k = int(np.argmax(np.abs(d - dt)))
        raise StringStabError(
            f"{_where(path)}: expected a regular time step; found steps of {dt:g} s and {d[k]:g} s "
            f"(at t = {t[k]:g} s)")
    return t


def _check_speeds(speed: Array, names: tuple[str, ...], path: Path) -> None:
    for v, nm in zip(speed, names):
        fin = v[np.isfinite(v)]
        if fin.size == 0:
            raise StringStabError(f"{_where(path)}: the speed of {show(nm)} is empty or NaN in every row")
        if fin.min() < -0.5:
            raise StringStabError(
                f"{_where(path)}: the speed of {show(nm)} must be >= 0 m/s; found {fin.min():.4g} m/s")
        if fin.max() > SPEED_ABSURD:
            raise StringStabError(
                f"{_where(path)}: the speed of {show(nm)} reaches {fin.max():.4g}, absurd for m/s "
                f"(expected at most {SPEED_ABSURD:g} m/s); if the column is in km/h, name it "
                "'... [km/h]'")


def _unit_ratio(speed: Array, rate: Array) -> float:
    """Median-free least-squares slope of ``rate`` on ``speed`` over samples where both are finite."""
    ok = np.isfinite(speed) & np.isfinite(rate)
    s, r = speed[ok], rate[ok]
    den = float(s @ s)
    return float(s @ r) / den if den > 0 else math.nan


def _refuse_units(what: str, ratio: float, path: Path) -> None:
    """Refuse speeds inconsistent with positions/spacing by the factor ``ratio`` (1 = m/s)."""
    if not math.isfinite(ratio):
        return
    if abs(ratio - KMH) < abs(ratio - 1.0) and abs(ratio - KMH) < 0.1:
        raise StringStabError(
            f"{_where(path)}: {what} changes at {ratio:.3g} times the speed column: the speeds look "
            "like km/h labelled as m/s; expected m/s (or a column named '... [km/h]')")
    if not 0.7 < ratio < 1.3:
        raise StringStabError(
            f"{_where(path)}: {what} changes at {ratio:.3g} times the speed column; expected about "
            "1 (speeds in m/s, distances in m)")


def _check_last_line(path: Path, n_rows: int) -> None:
    """Refuse a file whose last line has no line break: it may be cut mid-row.

    A number cut short is still a number (a spacing of 17.17 cut to "1" reads as 1 m), so a
    truncated last row cannot be told from a complete one by its cells; every row a CSV writer
    writes ends with a line break, so a missing one is taken as the sign of a cut.
    """
    try:
        with open_text(path, label=_where(path),
                       expected="a recorded platoon as CSV text (OpenACC, plain CSV or NGSIM)") as fh:
            last = ""
            while chunk := fh.read(1 << 20):
                last = chunk[-1]
    except (OSError, StringStabError):
        return  # the reader has already read it; its own errors are reported there
    if last not in ("\n", "\r"):
        raise StringStabError(
            f"{_where(path)}: the last line (line {n_rows}) does not end with a line break: the file "
            "looks cut mid-row (a number cut short would be read as another number); expected "
            "every row to end with a line break")


# --------------------------------------------------------------------------- OpenACC


def _cell(c: str) -> float:
    c = c.strip()
    if not c:
        return math.nan
    return float(c)


def _read_rows(path: Path) -> list[list[str]]:
    with open_text(path, label=_where(path),  # plain or gzip-compressed (.csv.gz)
                   expected="a recorded platoon as CSV text (OpenACC, plain CSV or NGSIM)") as fh:
        return [r for r in csv.reader(fh) if r and any(c.strip() for c in r)]


def _numeric(rows: list[list[str]], ncol: int, path: Path, first_line: int) -> Array:
    out = np.full((len(rows), ncol), np.nan)
    for i, r in enumerate(rows):
        if len(r) > ncol and any(c.strip() for c in r[ncol:]):
            raise StringStabError(
                f"{_where(path)} line {first_line + i}: expected {ncol} values; found {len(r)}")
        if len(r) < ncol:  # a row cut short: its last cell may be a number cut short too
            raise StringStabError(
                f"{_where(path)} line {first_line + i}: expected {ncol} values (empty cells "
                f"separated by commas where not measured); found {len(r)}: the row is cut short "
                "(a file cut mid-row?)")
        try:
            vals = [_cell(c) for c in r[:ncol]]
        except ValueError as e:
            raise StringStabError(
                f"{_where(path)} line {first_line + i}: expected numbers or empty cells; found {r[:ncol]}"
            ) from e
        out[i, :len(vals)] = vals
    return out


def _read_openacc(path: Path, rows: list[list[str]]) -> PlatoonLog:
    meta: dict[str, Any] = {}
    k = 0
    while k < len(rows) and rows[k][0].strip().lower() != "time":
        meta[rows[k][0].strip()] = [c.strip() for c in rows[k][1:] if c.strip()]
        k += 1
    header = [c.strip() for c in rows[k]]
    data = _numeric(rows[k + 1:], len(header), path, k + 2)
    t = _check_time(data[:, 0], path)
    speed_cols = {int(m.group(1)): j for j, c in enumerate(header)
                  if (m := re.fullmatch(r"speed(\d+)", c, re.IGNORECASE))}
    if not speed_cols:
        raise StringStabError(f"{_where(path)}: OpenACC header without Speedk columns; found {header[:8]}")
    ivs_cols = {int(m.group(1)): j for j, c in enumerate(header)
                if (m := re.fullmatch(r"ivs(\d+)", c, re.IGNORECASE))}
    if len(speed_cols) == 1:
        (n,) = speed_cols
        order = meta.get("Vehicle_order", [])
        who = f"vehicle {n}" + (f" ({order[n - 1]})" if 0 < n <= len(order) else "")
        raise StringStabError(
            f"{_where(path)}: expected at least two recorded vehicles (a predecessor and its "
            f"follower, with their spacing IVSk); found one vehicle, {who}: a one-vehicle log has "
            "no car following to identify")
    if not ivs_cols:
        raise StringStabError(
            f"{_where(path)}: no spacing columns IVSk; expected the inter-vehicle spacing of each pair")
    order = meta.get("Vehicle_order", [])
    nums = sorted(speed_cols)
    names = tuple(order[n - 1] if 0 < n <= len(order) else f"vehicle{n}" for n in nums)
    speed = np.stack([data[:, speed_cols[n]] for n in nums])
    _check_speeds(speed, names, path)
    # units: the E/N displacement per step against the speed column
    notes = []
    for n, nm, v in zip(nums, names, speed):
        low = [c.lower() for c in header]
        if f"e{n}" in low and f"n{n}" in low:
            e, nn = data[:, low.index(f"e{n}")], data[:, low.index(f"n{n}")]
            rate = np.hypot(np.diff(e), np.diff(nn)) / np.diff(t)
            vm = 0.5 * (v[1:] + v[:-1])
            ratio = _unit_ratio(vm, rate)
            try:
                _refuse_units(f"the position (E, N) of {nm}", ratio, path)
            except StringStabError:
                raise
            notes.append(round(ratio, 3))
    gap = {}
    for n, j in ivs_cols.items():
        if n + 1 in speed_cols:  # spacing between vehicle n and n + 1: the gap of n + 1
            g = data[:, j]
            gap[n] = g  # position of vehicle n + 1 is n (vehicle 1 is the leader, position 0)
    positions = tuple(n - 1 for n in nums)
    meta = {**meta, "speed_position_ratio": notes}
    return PlatoonLog(t, positions, names, speed, gap, None, str(path), "openacc", meta)


# --------------------------------------------------------------------------- plain CSV


_UNIT = re.compile(r"\s*[\[(]\s*([^\])]+)\s*[\])]\s*$")


def _split_unit(col: str) -> tuple[str, str]:
    c = col.strip()
    m = _UNIT.search(c)
    if m:
        return c[:m.start()].strip().lower(), m.group(1).strip().lower().replace(" ", "")
    low = c.lower()
    for suf, unit in (("_kmh", "km/h"), ("_kph", "km/h"), ("_mps", "m/s"), ("_ms", "m/s")):
        if low.endswith(suf):
            return low[: -len(suf)], unit
    return low, ""


def _scale(name: str, unit: str, kind: str, path: Path) -> float:
    ok = {"speed": {"": 1.0, "m/s": 1.0, "km/h": KMH, "kmh": KMH, "kph": KMH},
          "gap": {"": 1.0, "m": 1.0},
          "accel": {"": 1.0, "m/s^2": 1.0, "m/s2": 1.0, "m/s²": 1.0},
          "time": {"": 1.0, "s": 1.0}}[kind]
    if unit not in ok:
        raise StringStabError(
            f"{_where(path)}: column {show(name)} is in {show(unit)}; expected one of "
            f"{[u for u in ok if u]} for a {kind}")
    return ok[unit]


def _kind(base: str) -> str | None:
    if base in ("t", "time"):
        return "time"
    if re.fullmatch(r"(v|speed)(_lead|\d+)?", base):
        return "speed"
    if re.fullmatch(r"(gap|spacing)\d*", base):
        return "gap"
    if re.fullmatch(r"(a|accel)(_lead|\d+)?", base):
        return "accel"
    return None


def _read_plain(path: Path, rows: list[list[str]]) -> PlatoonLog:
    raw = [c.strip() for c in rows[0]]
    parts = [_split_unit(c) for c in raw]
    base = [b for b, _ in parts]
    if "vehicle" in base:
        return _read_long(path, rows, base, parts)
    kinds = [_kind(b) for b in base]
    bad = [raw[i] for i, k in enumerate(kinds) if k is None]
    if bad or "time" not in kinds:
        raise StringStabError(
            f"{_where(path)}: expected columns 't, v_lead, v, gap', 't, v0, v1, gap1, ...' or a long "
            f"table 'vehicle, t, v, gap' (SI units, optional a columns); found {raw}")
    data = _numeric(rows[1:], len(raw), path, 2)
    for j, (_b, u) in enumerate(parts):
        data[:, j] *= _scale(raw[j], u, kinds[j] or "", path)
    col = {b: data[:, j] for j, b in enumerate(base)}
    t = _check_time(col.get("t", col.get("time")), path)  # type: ignore[arg-type]
    if "v_lead" in col:
        need = [c for c in ("v", "gap") if c not in col]
        if need:
            raise StringStabError(f"{_where(path)}: with v_lead expected columns v and gap; missing {need}")
        speed = np.stack([col["v_lead"], col["v"]])
        gaps = {1: col["gap"]}
        acc = None
        if "a_lead" in col or "a" in col:
            acc = np.stack([col.get("a_lead", np.full_like(t, np.nan)), col.get("a", np.full_like(t, np.nan))])
        positions: tuple[int, ...] = (0, 1)
        names: tuple[str, ...] = ("lead", "follower")
    else:
        idx = sorted(int(b[1:]) for b in base if re.fullmatch(r"v\d+", b))
        if len(idx) < 2 or idx != list(range(idx[0], idx[0] + len(idx))) or idx[0] != 0:
            raise StringStabError(
                f"{_where(path)}: expected speed columns v0 (the leader), v1, v2, ... or v_lead, v; "
                f"found {raw}")
        speed = np.stack([col[f"v{i}"] for i in idx])
        gaps = {i: col[f"gap{i}"] for i in idx[1:] if f"gap{i}" in col}
        if not gaps:
            raise StringStabError(f"{_where(path)}: expected gap columns gap1, gap2, ...; found {raw}")
        acc = None
        if any(f"a{i}" in col for i in idx):
            acc = np.stack([col.get(f"a{i}", np.full_like(t, np.nan)) for i in idx])
        positions, names = tuple(idx), tuple(f"vehicle{i}" for i in idx)
    return _finish_plain(path, t, positions, names, speed, gaps, acc)


def _read_long(path: Path, rows: list[list[str]], base: list[str],
               parts: list[tuple[str, str]]) -> PlatoonLog:
    need = [c for c in ("vehicle", "t", "v", "gap") if c not in base]
    if need:
        raise StringStabError(
            f"{_where(path)}: a long table needs columns vehicle, t, v, gap; missing {need}")
    iv = base.index("vehicle")
    order: list[str] = []
    per: dict[str, list[list[str]]] = {}
    for i, r in enumerate(rows[1:]):
        if len(r) < len(base):
            raise StringStabError(
                f"{_where(path)} line {i + 2}: expected {len(base)} values; found {len(r)}: the row "
                "is cut short (a file cut mid-row?)")
        name = r[iv].strip() if iv < len(r) else ""
        if not name:
            raise StringStabError(f"{_where(path)}: a row without a vehicle name: {r}")
        if name not in per:
            order.append(name)
            per[name] = []
        per[name].append([c for j, c in enumerate(r) if j != iv])
    cols = [c for j, c in enumerate(base) if j != iv]
    units = [u for j, (_, u) in enumerate(parts) if j != iv]
    tabs = {}
    for name in order:
        d = _numeric(per[name], len(cols), path, 2)
        for j, (c, u) in enumerate(zip(cols, units)):
            d[:, j] *= _scale(c, u, _kind(c) or "time", path)
        tabs[name] = {c: d[:, j] for j, c in enumerate(cols)}
    t = _check_time(tabs[order[0]]["t"], path)
    for name in order[1:]:
        tn = tabs[name]["t"]
        if tn.shape != t.shape or np.abs(tn - t).max() > 1e-6:
            raise StringStabError(
                f"{_where(path)}: every vehicle of a long table needs the same times; {show(name)} "
                f"differs from {show(order[0])}")
    speed = np.stack([tabs[n]["v"] for n in order])
    gaps = {i: tabs[n]["gap"] for i, n in enumerate(order) if i > 0}
    acc = np.stack([tabs[n]["a"] for n in order]) if "a" in cols else None
    return _finish_plain(path, t, tuple(range(len(order))), tuple(order), speed, gaps, acc)


def _finish_plain(path: Path, t: Array, positions: tuple[int, ...], names: tuple[str, ...], speed: Array,
                  gaps: dict[int, Array], acc: Array | None) -> PlatoonLog:
    _check_speeds(speed, names, path)
    for p, g in gaps.items():
        if not np.isfinite(g).any():
            raise StringStabError(
                f"{_where(path)}: the gap of {show(names[positions.index(p)])} is empty or NaN in every row")
        # units: d gap / dt against v_pred − v
        i, j = positions.index(p - 1), positions.index(p)
        dv = 0.5 * ((speed[i] - speed[j])[1:] + (speed[i] - speed[j])[:-1])
        _refuse_units(f"the gap of {names[j]}", _unit_ratio(dv, np.diff(g) / np.diff(t)), path)
    return PlatoonLog(t, positions, names, speed, gaps, acc, str(path), "csv", {})


# --------------------------------------------------------------------------- entry point


def read_platoon_logs(path: str | Path, *, min_duration: float = 30.0,
                      ngsim: Callable[[Path, float], list[PlatoonLog]] | None = None) -> list[PlatoonLog]:
    """Read a recorded platoon (OpenACC, plain CSV) or the pairs of an NGSIM file.

    Parameters
    ----------
    path : path
        The file, plain or gzip-compressed (``.csv.gz``); its format is recognised from its
        first lines (module docstring).
    min_duration : float
        For NGSIM files, the shortest leader–follower pair kept, s.
    ngsim : callable, optional
        ``ngsim(path, min_duration) -> list of PlatoonLog``, the reader of NGSIM files.  The
        NGSIM parser lives with the simulator's leaders (:mod:`stringstab.traffic.loaders`),
        above this bottom layer, so :func:`stringstab.identify.read_logs` passes it in;
        without it an NGSIM file is refused with a pointer there.

    Returns
    -------
    list of PlatoonLog
        One log for OpenACC and CSV files; one per pair for NGSIM.

    Raises
    ------
    StringStabError
        One line: a missing or unreadable file, an unknown header, a bad number, time not
        increasing or irregular, an empty or all-NaN speed or gap, negative or absurd speeds,
        speeds whose unit disagrees with the positions or the spacing, fewer than two vehicles,
        a row with fewer cells than the header or a last line without a line break (a file cut
        mid-row: a number cut short is still a number).
    """
    p = Path(path)
    if not p.is_file():
        raise StringStabError(f"{_where(p)}: expected an existing file; found none")
    rows = _read_rows(p)
    if len(rows) < 2:
        raise StringStabError(f"{_where(p)}: expected a header and data rows; found {len(rows)} line(s)")
    header_low = [c.strip().lower() for c in rows[0]]
    if any(r and r[0].strip().lower() == "time"
           and any(re.fullmatch(r"speed\d+", c.strip(), re.IGNORECASE) for c in r) for r in rows[:30]):
        _check_last_line(p, len(rows))
        logs = [_read_openacc(p, rows)]
    elif "vehicle_id" in header_low and "frame_id" in header_low:
        if ngsim is None:
            raise StringStabError(f"{_where(p)} is an NGSIM file; read it with "
                                  "stringstab.identify.read_logs (or stringstab identify)")
        logs = ngsim(p, min_duration)
    else:
        _check_last_line(p, len(rows))
        logs = [_read_plain(p, rows)]
    for log in logs:
        if len(log.positions) < 2 or not log.followers():
            raise StringStabError(
                f"{_where(p)}: expected at least two consecutive vehicles with a gap (a predecessor "
                f"and a follower); found vehicles {list(log.names)}")
    return logs
