"""The spacing policy from the data: gap = l_0 + T* v on the quasi-steady parts of a record.

In equilibrium the eq-4 law holds the spacing error at zero, so the gap is l_0 + T* v (IDL
eq 3).  Where a follower and its predecessor drive at a nearly constant and common speed, the
measured gap *is* that policy, whatever the loop's dynamics: a straight line through the
(speed, gap) points of those stretches estimates T* (its slope) and l_0 (its intercept)
directly, without the trade-off between T* v and l_0 that a dynamic fit meets when the speed
varies little (docs/identify.md).

**Quasi-steady samples** (:func:`steady_mask`): inside the clean segments, both cars'
accelerations (slopes of 2-s straight-line fits of their speeds) below :data:`A_STEADY` in size
and their speeds within :data:`DV_STEADY` of each other, for at least :data:`STEADY_MIN`
seconds in a row.

**The fit and its interval** (:func:`spacing_policy`): least squares of gap on speed over those
samples; the interval is the 5-95 % range over :data:`N_BOOT` refits on resampled steady
stretches (a block bootstrap whose blocks are the stretches: samples within one stretch are
not independent).  The slope is only determined when the steady speeds span a range; the
policy is declared **identified** when the steady stretches number at least :data:`RUNS_MIN`
and their 5-95 % speed range is at least :data:`SPEED_RANGE_MIN` — otherwise the slope is
extrapolated from a cloud at one speed, and the caller reports the T* profile instead.

The **median time gap** (gap/speed over the moving samples) is reported beside T*: it is
T* + l_0/v, so it exceeds T* by l_0/v (0.2-0.5 s for l_0 of 2-5 m at 11 m/s) and is not an
estimate of T* unless l_0 = 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .fit import FollowerData
from .record import smoothed_acceleration

__all__ = ["A_STEADY", "DV_STEADY", "N_BOOT", "RUNS_MIN", "SPEED_RANGE_MIN", "STEADY_MIN",
           "SpacingPolicy", "distance_setting", "spacing_policy", "steady_mask"]

Array = npt.NDArray[np.float64]

#: Largest |acceleration| of either car in a quasi-steady sample, m/s².
A_STEADY = 0.15
#: Largest |v_p − v| in a quasi-steady sample, m/s.
DV_STEADY = 0.5
#: Shortest quasi-steady stretch, s.
STEADY_MIN = 3.0
#: Fewest steady stretches and smallest 5-95 % steady speed range (m/s) for T* to count as
#: identified by the spacing policy.
RUNS_MIN = 4
SPEED_RANGE_MIN = 3.0
#: Bootstrap refits of the straight line.
N_BOOT = 400


@dataclass(frozen=True)
class SpacingPolicy:
    """The equilibrium spacing policy of one follower (module docstring).

    Attributes
    ----------
    headway, standstill : float
        T* (s) and l_0 (m) of the straight line (NaN without steady samples).
    headway_interval, standstill_interval : tuple of float
        Their 5-95 % bootstrap intervals.
    n_steady, n_runs : int
        Quasi-steady samples and stretches.
    speed_range : tuple of float
        5-95 % range of the steady speeds, m/s.
    median_time_gap : float
        Median gap/speed over the moving samples (v > 1 m/s) of the segments, s.
    identified : bool
        Enough steady stretches over a wide enough speed range (module docstring).
    reason : str
        Why not, when not identified.
    """

    headway: float
    standstill: float
    headway_interval: tuple[float, float]
    standstill_interval: tuple[float, float]
    n_steady: int
    n_runs: int
    speed_range: tuple[float, float]
    median_time_gap: float
    identified: bool
    reason: str = ""

    def describe(self) -> str:
        """The policy in one sentence (for the notes).

        Returns
        -------
        str
            T* and l_0 with intervals, the steady data behind them and the median time gap.
        """
        if self.n_steady == 0:
            return ("spacing policy: no quasi-steady stretch of at least "
                    f"{STEADY_MIN:g} s; median time gap {self.median_time_gap:.3g} s")
        lo, hi = self.headway_interval
        text = (f"spacing policy from {self.n_runs} quasi-steady stretches ({self.n_steady} samples, "
                f"speeds {self.speed_range[0]:.3g}-{self.speed_range[1]:.3g} m/s): T* = "
                f"{self.headway:.3g} s (5-95 % {lo:.3g}-{hi:.3g}), l_0 = {self.standstill:.3g} m; "
                f"median time gap {self.median_time_gap:.3g} s (= T* + l_0/v)")
        if not self.identified:
            text += f"; not used: {self.reason}"
        return text


def steady_mask(data: FollowerData) -> npt.NDArray[np.bool_]:
    """Quasi-steady samples inside the segments (module docstring).

    Parameters
    ----------
    data : FollowerData
        The record and its clean segments.

    Returns
    -------
    ndarray of bool
        Per sample of the record.
    """
    T = data.v.size
    inside = np.zeros(T, dtype=bool)
    for s in data.segments:
        inside[s.start:s.stop] = True
    a = smoothed_acceleration(np.where(inside, data.v, np.nan), data.dt)
    ap = smoothed_acceleration(np.where(inside, data.v_pred, np.nan), data.dt)
    with np.errstate(invalid="ignore"):
        ok = inside & (np.abs(a) < A_STEADY) & (np.abs(ap) < A_STEADY) & (
            np.abs(data.v_pred - data.v) < DV_STEADY) & np.isfinite(data.gap)
    edges = np.flatnonzero(np.diff(np.r_[0, ok.astype(np.int8), 0]))
    n_min = math.ceil(STEADY_MIN / data.dt - 1e-9)
    out = np.zeros(T, dtype=bool)
    for a0, b0 in zip(edges[::2], edges[1::2]):
        if b0 - a0 >= n_min:
            out[a0:b0] = True
    return out


def _line(v: Array, g: Array) -> tuple[float, float]:
    """Least-squares (slope, intercept) of g on v; NaN when v does not vary."""
    if v.size < 2 or float(np.ptp(v)) <= 0:
        return math.nan, math.nan
    slope, icpt = np.polyfit(v, g, 1)
    return float(slope), float(icpt)


def spacing_policy(data: FollowerData, *, seed: int = 0) -> SpacingPolicy:
    """Fit gap = l_0 + T* v to the quasi-steady samples, with a block-bootstrap interval.

    Parameters
    ----------
    data : FollowerData
        The record and its clean segments.
    seed : int
        Seed of the bootstrap.

    Returns
    -------
    SpacingPolicy
        The line, its intervals and whether it identifies T* (module docstring).
    """
    v_all = np.concatenate([data.v[s.start:s.stop] for s in data.segments])
    g_all = np.concatenate([data.gap[s.start:s.stop] for s in data.segments])
    moving = v_all > 1.0
    tg = float(np.median(g_all[moving] / v_all[moving])) if moving.any() else math.nan
    m = steady_mask(data)
    edges = np.flatnonzero(np.diff(np.r_[0, m.astype(np.int8), 0]))
    runs = list(zip(edges[::2], edges[1::2]))
    nan2 = (math.nan, math.nan)
    if not runs:
        return SpacingPolicy(math.nan, math.nan, nan2, nan2, 0, 0, nan2, tg, False,
                             f"no quasi-steady stretch of at least {STEADY_MIN:g} s")
    v, g = data.v[m], data.gap[m]
    slope, icpt = _line(v, g)
    rng = np.random.default_rng(seed)
    draws = np.empty((N_BOOT, 2))
    for b in range(N_BOOT):
        pick = rng.integers(len(runs), size=len(runs))
        idx = np.concatenate([np.arange(*runs[j]) for j in pick])
        draws[b] = _line(data.v[idx], data.gap[idx])
    draws = draws[np.isfinite(draws).all(axis=1)]
    if draws.size:
        hl, hh = (float(x) for x in np.percentile(draws[:, 0], [5, 95]))
        sl, sh = (float(x) for x in np.percentile(draws[:, 1], [5, 95]))
    else:
        hl = hh = sl = sh = math.nan
    lo, hi = (float(x) for x in np.percentile(v, [5, 95]))
    reasons = []
    if len(runs) < RUNS_MIN:
        reasons.append(f"{len(runs)} steady stretch{'es' if len(runs) != 1 else ''} (fewer than {RUNS_MIN})")
    if hi - lo < SPEED_RANGE_MIN:
        reasons.append(f"the steady speeds span only {lo:.3g}-{hi:.3g} m/s (less than "
                       f"{SPEED_RANGE_MIN:g} m/s), so the slope T* is extrapolated")
    if math.isfinite(slope) and not reasons and slope < 0:
        reasons.append(f"the steady gaps fall with speed (slope {slope:.3g} s)")
    return SpacingPolicy(slope, icpt, (hl, hh), (sl, sh), int(m.sum()), len(runs),
                         (lo, hi), tg, not reasons, "; ".join(reasons))


def distance_setting(meta: dict[str, object]) -> tuple[str, str]:
    """The setting of a log from its metadata: ``short``/``medium``/``long``, ``human`` or ``unknown``.

    Parameters
    ----------
    meta : dict
        :attr:`stringstab.io.platoon_logs.PlatoonLog.meta` (OpenACC header lines as lists of
        cells: ``ACC`` 0 or 1, ``Distance_setting`` S, M or L, or empty).

    Returns
    -------
    setting : str
        ``"human"`` where ACC is off, the distance setting spelled out where it is on,
        ``"unknown"`` without metadata.
    raw : str
        The metadata's own ``Distance_setting`` cell (empty when absent).

    Examples
    --------
    >>> distance_setting({"ACC": ["1"], "Distance_setting": ["S"]})
    ('short', 'S')
    >>> distance_setting({"ACC": ["0"], "Distance_setting": []})
    ('human', '')
    """
    def first(key: str) -> str:
        val = meta.get(key)
        return str(val[0]).strip() if isinstance(val, list) and val else ""

    raw = first("Distance_setting")
    acc = first("ACC")
    if acc == "0":
        return "human", raw
    words = {"S": "short", "M": "medium", "L": "long", "XL": "extra long"}
    if raw:
        return words.get(raw.upper(), raw.lower()), raw
    return ("acc" if acc == "1" else "unknown"), raw
