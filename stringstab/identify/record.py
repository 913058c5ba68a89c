"""A follower's record as the fit uses it: bridged, screened for "not following", segmented.

From a recorded platoon (:class:`stringstab.io.platoon_logs.PlatoonLog`) to the
:class:`~stringstab.identify.fit.FollowerData` of one follower:

1. **Single missing samples are bridged** (:func:`bridge_single`): a sample missing between two
   measured ones (one NaN between finite neighbours, in the predecessor's speed, the follower's
   speed or the gap) is the mean of its neighbours, linear interpolation over one step (0.1 s
   on the OpenACC logs), where any of these signals changes by a few cm/s or cm.  A gap of two
   or more samples is never filled: it splits the record, as before.
2. **Stretches where the car does not follow its predecessor are excluded**
   (:func:`not_following`), each with its reason:

   * *standstill*: both cars below :data:`V_STOP` (a stopped car holds its brake, whatever
     the law would command);
   * *gap jump* (a cut-in or a change of target): the gap changes over one step by more than
     :data:`GAP_JUMP` beyond what the two speeds explain (|Δs − Δt (v_p − v)|; the GPS spacing
     errors are ~0.2 m);
   * *no target in range* (target loss): a gap above :data:`GAP_RANGE`, or a time gap above
     :data:`TIME_GAP_RANGE` at speeds above 5 m/s;
   * *not driven by its predecessor* (ACC off, an own speed target, another target): for at
     least :data:`DIVERGE_MIN` seconds the follower's speed moves *away* from its
     predecessor's (relative speed above :data:`DIVERGE_SPEED` and the follower's
     acceleration, above 0.1 m/s² in size, of the other sign), which a follower obeying any
     law with positive gains does only for the lag of a reaction.

   Accelerations are the slopes of straight lines fitted to 2 s of speed
   (:func:`scipy.signal.savgol_filter`), not differences of noisy GPS speeds.  Each excluded
   stretch is widened by :data:`PAD` on both sides (the transient into and out of it).
3. **Clean segments**: maximal runs of usable samples (all three signals measured, not
   excluded) of at least ``min_duration``.

Vehicles listed in a file's ``Vehicle_order`` but without columns are named
(:func:`missing_vehicles`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from ..io.platoon_logs import PlatoonLog, Segment
from .fit import FollowerData

__all__ = ["DIVERGE_MIN", "DIVERGE_SPEED", "GAP_JUMP", "GAP_RANGE", "PAD", "TIME_GAP_RANGE", "V_STOP",
           "Exclusion", "FollowerRecord", "bridge_single", "follower_record", "missing_vehicles",
           "not_following", "segments_of", "smoothed_acceleration"]

Array = npt.NDArray[np.float64]

#: Both cars below this speed (m/s): standstill.
V_STOP = 1.0
#: Gap change over one step beyond the speeds' account (m): a cut-in or a change of target.
GAP_JUMP = 2.0
#: Gap (m) beyond which no car is followed (an ACC radar's range is ~150-200 m).
GAP_RANGE = 120.0
#: Time gap (s) beyond which a car above 5 m/s is not following.
TIME_GAP_RANGE = 6.0
#: Relative speed (m/s) and duration (s) of a follower moving away from its predecessor's speed.
DIVERGE_SPEED = 1.5
DIVERGE_MIN = 5.0
#: Widening of each excluded stretch on both sides, s.
PAD = 2.0
#: Window of the smoothed acceleration, s.
SLOPE_WINDOW = 2.0


@dataclass(frozen=True)
class Exclusion:
    """A stretch ``[start, stop)`` of samples excluded from the fit, and why."""

    start: int
    stop: int
    reason: str

    def __len__(self) -> int:
        return self.stop - self.start


@dataclass
class FollowerRecord:
    """One follower's record ready for the fit (module docstring).

    Attributes
    ----------
    data : FollowerData
        Signals (single missing samples bridged) and the clean segments.
    bridged : int
        Samples bridged (over the three signals).
    excluded : list of Exclusion
        Stretches excluded as "not following its predecessor".
    notes : list of str
        What was bridged and excluded, in words.
    """

    data: FollowerData
    bridged: int = 0
    excluded: list[Exclusion] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def bridge_single(x: Array) -> tuple[Array, int]:
    """Fill each isolated missing sample with the mean of its two measured neighbours.

    Parameters
    ----------
    x : ndarray
        A signal sampled on a regular grid, NaN where not measured.

    Returns
    -------
    bridged : ndarray
        A copy with every NaN whose two neighbours are finite replaced by their mean (linear
        interpolation over one step); runs of two or more NaN are left as they are.
    n : int
        Samples filled.

    Examples
    --------
    >>> import numpy as np
    >>> y, n = bridge_single(np.array([1.0, np.nan, 3.0, np.nan, np.nan, 6.0]))
    >>> y.tolist()[:3], n
    ([1.0, 2.0, 3.0], 1)
    """
    y = np.array(x, dtype=float, copy=True)
    if y.size < 3:
        return y, 0
    bad = ~np.isfinite(y)
    single = np.zeros_like(bad)
    single[1:-1] = bad[1:-1] & ~bad[:-2] & ~bad[2:]
    k = np.flatnonzero(single)
    y[k] = 0.5 * (y[k - 1] + y[k + 1])
    return y, int(k.size)


def smoothed_acceleration(v: Array, dt: float, window: float = SLOPE_WINDOW) -> Array:
    """Acceleration as the slope of a straight line fitted to ``window`` seconds of speed.

    Parameters
    ----------
    v : ndarray
        Speed (m/s) on a regular grid, NaN where not measured.
    dt : float
        Step, s.
    window : float
        Length of the fitted line, s.

    Returns
    -------
    ndarray
        m/s², NaN where not measured or in a measured run shorter than five samples.
    """
    from scipy.signal import savgol_filter

    out = np.full(v.shape, np.nan)
    ok = np.isfinite(v)
    edges = np.flatnonzero(np.diff(np.r_[0, ok.astype(np.int8), 0]))
    n = max(round(window / dt) // 2 * 2 + 1, 5)
    for a, b in zip(edges[::2], edges[1::2]):
        m = min(n, (b - a) // 2 * 2 - 1)
        if m >= 5:
            out[a:b] = savgol_filter(v[a:b], m, 1, deriv=1, delta=dt)
    return out


def _runs(mask: npt.NDArray[np.bool_]) -> list[tuple[int, int]]:
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(np.int8), 0]))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]


def not_following(v_pred: Array, v: Array, gap: Array, dt: float) -> list[Exclusion]:
    """Stretches in which the follower is not following its predecessor (module docstring).

    Parameters
    ----------
    v_pred, v, gap : ndarray
        Predecessor's speed (m/s), follower's speed (m/s) and the gap (m), NaN where not
        measured.
    dt : float
        Step, s.

    Returns
    -------
    list of Exclusion
        Widened by :data:`PAD` on both sides, in time order, overlapping stretches merged
        (their reasons joined).
    """
    T = v.size
    pad = round(PAD / dt)
    dv = v_pred - v
    with np.errstate(invalid="ignore", divide="ignore"):
        jump = np.zeros(T)
        jump[1:] = np.abs(np.diff(gap) - 0.5 * dt * (dv[1:] + dv[:-1]))
        acc = smoothed_acceleration(v, dt)
        away = (np.abs(dv) > DIVERGE_SPEED) & (np.abs(acc) > 0.1) & (dv * acc < 0)
        far = (gap > GAP_RANGE) | ((v > 5.0) & (gap / v > TIME_GAP_RANGE))
        kinds = [
            ((v < V_STOP) & (v_pred < V_STOP), 1,
             lambda a, b: f"standstill ({(b - a) * dt:.3g} s below {V_STOP:g} m/s)"),
            (jump > GAP_JUMP, 1,
             lambda a, b: f"gap jump{'s' if (jump[a:b] > GAP_JUMP).sum() > 1 else ''} of up to "
                          f"{np.nanmax(jump[a:b]):.3g} m in one step beyond the speeds' account "
                          "(a cut-in or a change of target)"),
            (far, 1,
             lambda a, b: f"no target in range (gap up to {np.nanmax(gap[a:b]):.3g} m: above "
                          f"{GAP_RANGE:g} m or {TIME_GAP_RANGE:g} s)"),
            (away, math.ceil(DIVERGE_MIN / dt - 1e-9),
             lambda a, b: f"moving away from its predecessor's speed for {(b - a) * dt:.3g} s "
                          f"(relative speed up to {np.nanmax(np.abs(dv[a:b])):.3g} m/s): not driven "
                          "by it (ACC off, an own speed target or another target)"),
        ]
    found: list[tuple[int, int, str]] = []
    for mask, n_min, why in kinds:
        runs = [(a, b) for a, b in _runs(mask) if b - a >= n_min]
        merged: list[list[int]] = []
        for a, b in runs:  # runs of one kind closer than the padding are one stretch
            if merged and a - merged[-1][1] <= 2 * pad:
                merged[-1][1] = b
            else:
                merged.append([a, b])
        found += [(max(a - pad, 0), min(b + pad, T), why(a, b)) for a, b in merged]
    out: list[Exclusion] = []
    for a, b, r in sorted(found):
        if out and a <= out[-1].stop:
            last = out[-1]
            out[-1] = Exclusion(last.start, max(last.stop, b), f"{last.reason}; {r}")
        else:
            out.append(Exclusion(a, b, r))
    return out


def segments_of(usable: npt.NDArray[np.bool_], dt: float, min_duration: float) -> list[Segment]:
    """Maximal runs of usable samples of at least ``min_duration`` seconds.

    Parameters
    ----------
    usable : ndarray of bool
        Per sample: measured and not excluded.
    dt : float
        Step, s.
    min_duration : float
        Shortest run kept, s.

    Returns
    -------
    list of Segment
        In time order.
    """
    n_min = max(math.ceil(min_duration / dt - 1e-9), 2)
    return [Segment(a, b) for a, b in _runs(usable) if b - a >= n_min]


def follower_record(log: PlatoonLog, position: int, *, min_duration: float = 30.0,
                    screen: bool = True) -> FollowerRecord:
    """The follower at ``position`` of ``log``, bridged, screened and segmented (module docstring).

    Parameters
    ----------
    log : PlatoonLog
        The recorded platoon.
    position : int
        The follower's position (its predecessor at ``position - 1`` must be in the log).
    min_duration : float
        Shortest clean segment kept, s.
    screen : bool
        Exclude the stretches of :func:`not_following` (default); False keeps them.

    Returns
    -------
    FollowerRecord
        Its ``data.segments`` may be empty (no usable stretch long enough).
    """
    vp, v, g, ap = log.pair(position)
    vp, n1 = bridge_single(vp)
    v, n2 = bridge_single(v)
    g, n3 = bridge_single(g)
    dt = log.dt
    notes = []
    bridged = n1 + n2 + n3
    if bridged:
        notes.append(f"{bridged} single missing sample{'s' if bridged > 1 else ''} bridged (the mean "
                     "of the two neighbours, one step of linear interpolation); longer gaps split "
                     "the record")
    measured = np.isfinite(vp) & np.isfinite(v) & np.isfinite(g)
    excluded = not_following(vp, v, g, dt) if screen else []
    usable = measured.copy()
    for e in excluded:
        usable[e.start:e.stop] = False
    segs = segments_of(usable, dt, min_duration)
    if excluded:
        total = sum(len(e) for e in excluded) * dt
        parts = "; ".join(f"t = {log.t[e.start]:.4g}-{log.t[min(e.stop, log.t.size - 1)]:.4g} s: {e.reason}"
                          for e in excluded)
        notes.append(f"not following its predecessor: {len(excluded)} stretch"
                     f"{'es' if len(excluded) > 1 else ''} ({total:.3g} s, widened by {PAD:g} s) "
                     f"excluded from the fit ({parts})")
    data = FollowerData(vp, v, g, ap, tuple(segs), dt)
    return FollowerRecord(data, bridged, excluded, notes)


def missing_vehicles(log: PlatoonLog) -> list[str]:
    """Vehicles of the file's platoon (its ``Vehicle_order``) without columns, named.

    Parameters
    ----------
    log : PlatoonLog
        An OpenACC log (other formats list no platoon beyond their columns).

    Returns
    -------
    list of str
        One sentence per missing vehicle: its number, name and what it costs (the follower
        behind it has no predecessor record).
    """
    order = log.meta.get("Vehicle_order") or []
    try:
        n = int((log.meta.get("Number_of_vehicles") or ["0"])[0])
    except ValueError:
        return []
    out = []
    for k in range(1, n + 1):
        if k - 1 in log.positions:
            continue
        name = order[k - 1] if k <= len(order) else f"vehicle{k}"
        behind = (f"; vehicle {k + 1} ({log.name(k)}) has no predecessor record and is not identified"
                  if k in log.positions else "")
        out.append(f"vehicle {k} ({name}) of the Vehicle_order has no columns in this log{behind}")
    return out
