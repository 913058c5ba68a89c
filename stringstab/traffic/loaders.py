"""Recorded leaders: a ``t, v[, a]`` CSV file, and leader–follower pairs from NGSIM files.

:func:`load_csv` reads a generic speed profile in SI units; :func:`load_ngsim_pairs` cuts
the US-101 / I-80 trajectory files (IDL paper §4.1.1) into leader–follower pairs in SI units.
Both read plain or gzip-compressed files, strictly UTF-8, through the one reader
(:mod:`stringstab.io.text_input`).
"""

from __future__ import annotations

import csv
import io
import itertools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from ..constants import DT
from ..errors import StringStabError, show
from ..io.text_input import open_text, read_text
from .trajectory import Trajectory, from_speed

__all__ = ["FEET", "FollowingPair", "load_csv", "load_ngsim_pairs"]

Array = npt.NDArray[np.float64]

#: One foot in metres (NGSIM files are in feet).
FEET = 0.3048


def load_csv(path: str | Path, *, dt: float = DT, speed_max: float | None = None) -> Trajectory:
    """A leader from a CSV file with header ``t, v`` or ``t, v, a`` (s, m/s, m/s²).

    Parameters
    ----------
    path : path
        The file.
    dt : float
        Output step (the file may be sampled at any increasing times), s.
    speed_max : float, optional
        Cap the speed, m/s.

    Returns
    -------
    Trajectory
        The leader read from the file.

    Raises
    ------
    StringStabError
        If the file is missing, empty, binary or not UTF-8 text, its columns are not ``t, v`` or
        ``t, v, a``, a value is not a finite number, times are not strictly increasing or a
        speed is negative.
    """
    p = Path(path)
    text = read_text(p, label=f"leader CSV {show(str(p))}",  # plain or gzip (.csv.gz)
                     expected="a CSV file with columns 't, v' or 't, v, a'")
    rows = [r for r in csv.reader(io.StringIO(text, newline="")) if r and any(c.strip() for c in r)]
    if not rows:
        raise StringStabError(f"leader CSV {show(str(p))} is empty; expected a header 't, v' or 't, v, a'")
    header = [c.strip().lower() for c in rows[0]]
    if header not in (["t", "v"], ["t", "v", "a"]):
        raise StringStabError(
            f"leader CSV {show(str(p))}: expected columns 't, v' or 't, v, a' (SI units: s, m/s, "
            f"m/s^2); found {[c.strip() for c in rows[0]]}"
        )
    data = []
    for i, r in enumerate(rows[1:], start=2):
        if len(r) != len(header):
            raise StringStabError(
                f"leader CSV {show(str(p))} line {i}: expected {len(header)} values; got {len(r)}"
            )
        try:
            vals = [float(c) for c in r]
        except ValueError as e:
            raise StringStabError(f"leader CSV {show(str(p))} line {i}: not a number in {r}") from e
        if not all(math.isfinite(x) for x in vals):
            raise StringStabError(f"leader CSV {show(str(p))} line {i}: values must be finite; got {r}")
        data.append(vals)
    if len(data) < 2:
        raise StringStabError(f"leader CSV {show(str(p))}: needs at least 2 data rows; got {len(data)}")
    arr = np.asarray(data)
    try:
        tr = from_speed(arr[:, 0], arr[:, 1], dt=dt, accel=arr[:, 2] if arr.shape[1] == 3 else None,
                        speed_max=speed_max, name=p.stem)
    except StringStabError as e:
        raise StringStabError(f"leader CSV {show(str(p))}: {e}") from e
    tr.meta["source"] = str(p)
    return tr


@dataclass(frozen=True)
class FollowingPair:
    """A leader–follower pair from a trajectory data set, in SI units on one time grid.

    ``leader.position`` and ``follower.position`` are front-bumper positions along the road, so
    the bumper-to-bumper gap is ``leader.position − follower.position − leader_length``.

    Attributes
    ----------
    leader, follower : Trajectory
        The two vehicles (the follower is the human driver, the HDV baseline).
    leader_id, follower_id : int
        Vehicle_ID values in the source file.
    start_frame : int
        Frame_ID of the first sample.
    leader_length : float
        Length of the leader, m.
    location : str
        The source's Location column, or "".
    """

    leader: Trajectory
    follower: Trajectory
    leader_id: int
    follower_id: int
    start_frame: int
    leader_length: float
    location: str = ""

    @property
    def gap(self) -> Array:
        """Bumper-to-bumper gap of the follower, m."""
        return self.leader.position - self.follower.position - self.leader_length

    @property
    def duration(self) -> float:
        """Length of the pair, s."""
        return self.leader.duration


_NGSIM_REQUIRED = ("Vehicle_ID", "Frame_ID", "Local_Y", "v_Vel", "v_Acc", "Preceding")


def load_ngsim_pairs(
    path: str | Path,
    *,
    min_duration: float = 15.0,
    location: str | None = None,
    frame_period: float = DT,
    default_length: float = 5.0,
) -> list[FollowingPair]:
    """Leader–follower pairs of at least ``min_duration`` s from an NGSIM trajectory file.

    The US-101 / I-80 format (IDL paper §4.1.1): one row per vehicle and frame (10 Hz) with
    columns including ``Vehicle_ID, Frame_ID, Local_Y, v_Vel, v_Acc, Preceding`` (feet, ft/s,
    ft/s²) and optionally ``v_Length`` and ``Location`` (names matched case-insensitively).
    A pair is a maximal run of consecutive frames in which a follower's ``Preceding`` stays
    the same non-zero vehicle and that vehicle has a row at every frame; runs lasting at least
    ``min_duration`` (from first to last frame) are kept.  Everything is converted to SI (1 ft = 0.3048 m).  Duplicate (vehicle, frame)
    rows keep the first.

    Parameters
    ----------
    path : path
        The CSV file.
    min_duration : float
        Minimum pair duration, s (the paper uses 15 s).
    location : str, optional
        Keep rows whose ``Location`` equals this (case-insensitive), e.g. ``"i-80"``; the
        combined NGSIM file reuses vehicle IDs across locations.
    frame_period : float
        Time between frames, s.
    default_length : float
        Leader length (m) when the file has no ``v_Length`` column.

    Returns
    -------
    list of FollowingPair
        Sorted by (location, follower, start frame).

    Raises
    ------
    StringStabError
        If the file cannot be read, is not UTF-8 text or lacks a required column.
    """
    p = Path(path)
    with open_text(p, label=f"NGSIM file {show(str(p))}",  # plain or gzip (.csv.gz)
                   expected="an NGSIM US-101/I-80 trajectory CSV file") as fh:
        reader = csv.reader(fh)
        header = [c.strip().lower() for c in next(reader, [])]
        missing = [c for c in _NGSIM_REQUIRED if c.lower() not in header]
        if missing:
            raise StringStabError(
                f"NGSIM file {show(str(p))}: missing columns {missing}; expected the US-101/I-80 "
                f"format with {list(_NGSIM_REQUIRED)} (and optionally v_Length, Location)"
            )
        cols = [*_NGSIM_REQUIRED, *(c for c in ("v_Length",) if c.lower() in header)]
        idx = [header.index(c.lower()) for c in cols]
        loc_i = header.index("location") if "location" in header else None
        num: list[list[float]] = []
        locs: list[str] = []
        for line, r in enumerate(reader, start=2):
            if not r:
                continue
            try:
                num.append([float(r[i]) for i in idx])
            except (ValueError, IndexError) as e:
                raise StringStabError(f"NGSIM file {show(str(p))} line {line}: bad numeric value") from e
            locs.append(r[loc_i].strip().lower() if loc_i is not None and loc_i < len(r) else "")
    if not num:
        return []
    arr = np.asarray(num)
    loc_arr = np.asarray(locs)
    if location is not None:
        if loc_i is None:
            raise StringStabError(
                f"NGSIM file {show(str(p))} has no Location column; cannot select location {show(location)}"
            )
        keep = loc_arr == location.strip().lower()
        arr, loc_arr = arr[keep], loc_arr[keep]
    has_len = "v_Length" in cols
    loc_codes, loc_id = np.unique(loc_arr, return_inverse=True)
    vid = arr[:, 0].astype(np.int64)
    frame = arr[:, 1].astype(np.int64)
    order = np.lexsort((frame, vid, loc_id))
    arr, vid, frame, loc_id = arr[order], vid[order], frame[order], loc_id[order]
    first = np.ones(len(vid), dtype=bool)
    first[1:] = (vid[1:] != vid[:-1]) | (frame[1:] != frame[:-1]) | (loc_id[1:] != loc_id[:-1])
    arr, vid, frame, loc_id = arr[first], vid[first], frame[first], loc_id[first]

    # (location, vehicle) -> (frames, rows)
    starts = np.flatnonzero(np.r_[True, (vid[1:] != vid[:-1]) | (loc_id[1:] != loc_id[:-1])])
    bounds = np.r_[starts, len(vid)]
    index = {(int(loc_id[b0]), int(vid[b0])): (int(b0), int(b1)) for b0, b1 in itertools.pairwise(bounds)}
    min_frames = math.ceil(min_duration / frame_period - 1e-9) + 1
    pairs: list[FollowingPair] = []
    for (lc, fid), (s, stop) in index.items():
        prec = arr[s:stop, 5].astype(np.int64)
        fr = frame[s:stop]
        brk = np.flatnonzero((np.diff(prec) != 0) | (np.diff(fr) != 1)) + 1
        for rs, re_ in zip(np.r_[0, brk], np.r_[brk, stop - s]):
            lid = int(prec[rs])
            if lid == 0 or re_ - rs < min_frames or (lc, lid) not in index:
                continue
            ls, le = index[(lc, lid)]
            lfr = frame[ls:le]
            run_fr = fr[rs:re_]
            pos = np.searchsorted(lfr, run_fr)
            ok = (pos < len(lfr)) & (lfr[np.minimum(pos, len(lfr) - 1)] == run_fr)
            okb = np.flatnonzero(np.diff(np.r_[0, ok.astype(np.int8), 0]))
            for a0, a1 in zip(okb[::2], okb[1::2]):
                if a1 - a0 < min_frames:
                    continue
                frows = s + rs + np.arange(a0, a1)
                lrows = ls + pos[a0:a1]
                lead = _ngsim_traj(arr[lrows], frame_period, f"ngsim-{lid}")
                foll = _ngsim_traj(arr[frows], frame_period, f"ngsim-{fid}")
                length = float(arr[lrows[0], 6]) * FEET if has_len else default_length
                pairs.append(FollowingPair(lead, foll, lid, int(fid), int(frame[frows[0]]), length,
                                           str(loc_codes[lc])))
    pairs.sort(key=lambda q: (q.location, q.follower_id, q.start_frame))
    return pairs


def _ngsim_traj(rows: Array, dt: float, name: str) -> Trajectory:
    return Trajectory(dt, rows[:, 2] * FEET, np.maximum(rows[:, 3] * FEET, 0.0), rows[:, 4] * FEET, name)
