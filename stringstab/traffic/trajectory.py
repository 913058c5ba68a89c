"""A lead vehicle's trajectory on a time grid, and building one from speeds or accelerations.

A :class:`Trajectory` is a lead vehicle's position, speed and acceleration sampled every ``dt``
seconds from ``t = 0``.  Sample ``k`` holds the state at ``t_k = k·dt``; ``accel[k]`` is the
acceleration over the step ``[t_k, t_{k+1})`` whenever the profile is piecewise constant in
acceleration (driving cycles, synthetic manoeuvres), so positions, speeds and accelerations
are mutually exact on the grid.  :func:`from_speed` and :func:`from_accel_segments` build one.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..constants import DT, SPEED_MAX
from ..errors import StringStabError, show
from ..params import positive

__all__ = ["Trajectory", "from_accel_segments", "from_speed", "time_grid"]

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Trajectory:
    """A lead vehicle's position, speed and acceleration every ``dt`` seconds from t = 0.

    Parameters
    ----------
    dt : float
        Sampling step, s.
    position, speed, accel : array of shape (T,)
        Front-bumper position (m), speed (m/s) and acceleration (m/s²) at ``t_k = k·dt``.
    name : str
        A label for figures and file metadata.

    Examples
    --------
    >>> tr = from_speed([0.0, 10.0], [20.0, 20.0], dt=0.1)
    >>> tr.n_steps, tr.duration
    (101, 10.0)
    """

    dt: float
    position: Array
    speed: Array
    accel: Array
    name: str = "leader"
    meta: dict[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        if not (isinstance(self.dt, (int, float)) and math.isfinite(self.dt) and self.dt > 0):
            raise StringStabError(f"trajectory step dt must be a finite number > 0 s; got {show(self.dt)}")
        arrs = []
        for nm in ("position", "speed", "accel"):
            a = np.ascontiguousarray(getattr(self, nm), dtype=np.float64)
            if a.ndim != 1:
                raise StringStabError(f"trajectory {nm} must be one-dimensional; got shape {a.shape}")
            if not np.isfinite(a).all():
                raise StringStabError(f"trajectory {nm} must be finite; found NaN or inf")
            object.__setattr__(self, nm, a)
            arrs.append(a)
        n = {a.shape[0] for a in arrs}
        if len(n) != 1:
            raise StringStabError(
                f"trajectory position, speed and accel must have one length; got {[a.shape[0] for a in arrs]}"
            )
        if arrs[0].shape[0] < 2:
            raise StringStabError(f"a trajectory needs at least 2 samples; got {arrs[0].shape[0]}")

    @property
    def n_steps(self) -> int:
        """Number of samples T."""
        return int(self.speed.shape[0])

    @property
    def duration(self) -> float:
        """(T − 1)·dt, s."""
        return round((self.n_steps - 1) * self.dt, 12)

    @property
    def t(self) -> Array:
        """Sample times k·dt, s."""
        return np.asarray(np.arange(self.n_steps) * self.dt, dtype=np.float64)

    def hold(self, seconds: float) -> Trajectory:
        """The trajectory followed by ``seconds`` at its final speed (zero acceleration).

        Lets a long platoon settle before its damping ratios are measured (eq 29 sums over the
        whole run).

        Parameters
        ----------
        seconds : float
            Duration of the hold, s (rounded to whole steps; ≥ 0).

        Returns
        -------
        Trajectory
            The extended trajectory; the last original sample's acceleration is set to 0 when
            ``seconds`` adds a step.

        Raises
        ------
        StringStabError
            If ``seconds`` is negative or not finite.

        Examples
        --------
        >>> tr = from_speed([0, 1], [10.0, 12.0], dt=0.5).hold(1.0)
        >>> tr.speed.tolist(), tr.accel.tolist()
        ([10.0, 11.0, 12.0, 12.0, 12.0], [2.0, 2.0, 0.0, 0.0, 0.0])
        """
        if not math.isfinite(float(seconds)) or seconds < 0:
            raise StringStabError(f"hold needs a finite seconds >= 0; got {show(seconds)}")
        n = round(float(seconds) / self.dt)
        v_end = self.speed[-1]
        x_tail = self.position[-1] + v_end * self.dt * np.arange(1, n + 1)
        accel = self.accel.copy()
        if n:
            accel[-1] = 0.0
        return Trajectory(self.dt, np.r_[self.position, x_tail], np.r_[self.speed, np.full(n, v_end)],
                          np.r_[accel, np.zeros(n)], self.name, dict(self.meta))

    def window(self, start: int, stop: int | None = None) -> Trajectory:
        """Samples ``start:stop``, re-timed to start at t = 0.

        Parameters
        ----------
        start : int
            First sample index.
        stop : int, optional
            One past the last sample index (None: to the end).

        Returns
        -------
        Trajectory
            The samples, same name and metadata (the position is not shifted).
        """
        sl = slice(start, stop)
        return Trajectory(self.dt, self.position[sl], self.speed[sl], self.accel[sl], self.name,
                          dict(self.meta))

    def head(self, duration: float) -> Trajectory:
        """The first ``duration`` seconds (at least two samples, at most the whole trajectory).

        Parameters
        ----------
        duration : float
            Seconds to keep (> 0).

        Returns
        -------
        Trajectory
            Samples 0 … floor(duration/dt), at least two.

        Raises
        ------
        StringStabError
            If ``duration`` is not a finite number > 0.

        Examples
        --------
        >>> from stringstab.traffic import cycle
        >>> cycle("udds").head(10.0).duration
        10.0
        """
        if not (math.isfinite(float(duration)) and duration > 0):
            raise StringStabError(f"duration must be > 0 s; got {show(duration)}")
        n = min(self.n_steps, math.floor(duration / self.dt + 1e-9) + 1)
        return self.window(0, max(n, 2))


def time_grid(t0: float, t1: float, dt: float) -> Array:
    """The sample times t0, t0 + dt, ... up to t1 (included within 1e-9 of a step).

    Parameters
    ----------
    t0, t1 : float
        First and last time, s.
    dt : float
        Step, s (> 0).

    Returns
    -------
    ndarray
        ``t0 + k dt`` for k = 0 … ⌊(t1 − t0)/dt⌋.
    """
    n = math.floor((t1 - t0) / dt + 1e-9) + 1
    return np.asarray(t0 + np.arange(n, dtype=np.float64) * dt, dtype=np.float64)


def _accel_from_speed(v: Array, dt: float) -> Array:
    a = np.empty_like(v)
    a[:-1] = np.diff(v) / dt
    a[-1] = a[-2]
    return a


def _positions(v: Array, dt: float, x0: float) -> Array:
    x = np.empty_like(v)
    x[0] = x0
    np.cumsum((v[1:] + v[:-1]) * (0.5 * dt), out=x[1:])
    x[1:] += x0
    return x


def from_speed(
    t: npt.ArrayLike,
    speed: npt.ArrayLike,
    *,
    dt: float = DT,
    accel: npt.ArrayLike | None = None,
    position0: float = 0.0,
    speed_max: float | None = None,
    name: str = "leader",
) -> Trajectory:
    """A trajectory from speed samples, linearly interpolated to the step ``dt``.

    Without ``accel`` the acceleration is the slope of the interpolated speed over each step
    (held over ``[t_k, t_{k+1})``), and positions integrate the speed exactly (trapezoid rule
    on a piecewise-linear speed).  With ``accel`` the given accelerations are interpolated too.

    Parameters
    ----------
    t, speed : array_like
        Sample times (s, strictly increasing) and speeds (m/s, ≥ 0).
    dt : float
        Output step, s.
    accel : array_like, optional
        Measured accelerations (m/s²) at ``t``.
    position0 : float
        Position at the first sample, m.
    speed_max : float, optional
        Cap the speed at this value (m/s); the acceleration is zeroed where the cap binds.
    name : str
        Label.

    Returns
    -------
    Trajectory

    Raises
    ------
    StringStabError
        If times are not strictly increasing, values are not finite, or speeds are negative.

    Examples
    --------
    >>> tr = from_speed([0, 1, 2], [0.0, 1.0, 1.0], dt=0.5)
    >>> tr.speed.tolist(), tr.accel.tolist(), tr.position.tolist()
    ([0.0, 0.5, 1.0, 1.0, 1.0], [1.0, 1.0, 0.0, 0.0, 0.0], [0.0, 0.125, 0.5, 1.0, 1.5])
    """
    d = positive("dt", dt, unit=" s")
    tt = np.asarray(t, dtype=np.float64)
    vv = np.asarray(speed, dtype=np.float64)
    if tt.ndim != 1 or vv.shape != tt.shape:
        raise StringStabError(f"t and speed must be 1-D arrays of one length; got {tt.shape} and {vv.shape}")
    if tt.shape[0] < 2:
        raise StringStabError(f"a speed profile needs at least 2 samples; got {tt.shape[0]}")
    if not (np.isfinite(tt).all() and np.isfinite(vv).all()):
        raise StringStabError("t and speed must be finite; found NaN or inf")
    steps = np.diff(tt)
    if (steps <= 0).any():
        i = int(np.argmax(steps <= 0))
        raise StringStabError(
            f"t must be strictly increasing; got t[{i}]={show(tt[i])} then t[{i + 1}]={show(tt[i + 1])}"
        )
    if (vv < 0).any():
        i = int(np.argmax(vv < 0))
        raise StringStabError(f"speed must be >= 0 m/s; got {show(vv[i])} at t={show(tt[i])}")
    grid = time_grid(tt[0], tt[-1], d)
    if grid.shape[0] < 2:
        raise StringStabError(f"the profile lasts {show(tt[-1] - tt[0])} s, shorter than one step dt={show(d)} s")
    v = np.interp(grid, tt, vv)
    capped = np.zeros(v.shape, dtype=bool)
    if speed_max is not None:
        capped = v >= speed_max
        v = np.minimum(v, speed_max)
    if accel is None:
        a = _accel_from_speed(v, d)
    else:
        aa = np.asarray(accel, dtype=np.float64)
        if aa.shape != tt.shape or not np.isfinite(aa).all():
            raise StringStabError(f"accel must be finite and shaped like t {tt.shape}; got {aa.shape}")
        a = np.interp(grid, tt, aa)
        a[capped & (a > 0)] = 0.0
    return Trajectory(d, _positions(v, d, float(position0)), v, a, name)


def from_accel_segments(
    segments: Sequence[tuple[float, float]],
    *,
    speed0: float,
    dt: float = DT,
    speed_max: float = SPEED_MAX,
    name: str = "leader",
) -> Trajectory:
    """A trajectory of piecewise-constant accelerations, integrated exactly on the grid.

    Parameters
    ----------
    segments : sequence of (accel, duration)
        Accelerations (m/s²) held for durations (s), in order.
    speed0 : float
        Initial speed, m/s.
    dt : float
        Step, s.
    speed_max : float
        The speed stays within [0, speed_max]; where a bound binds the acceleration is cut.
    name : str
        Label.

    Returns
    -------
    Trajectory
        The integrated trajectory.

    Examples
    --------
    >>> tr = from_accel_segments([(0.0, 1.0), (-2.0, 1.0)], speed0=10.0, dt=0.5)
    >>> tr.speed.tolist(), tr.accel.tolist()
    ([10.0, 10.0, 10.0, 9.0, 8.0], [0.0, 0.0, -2.0, -2.0, -2.0])
    """
    d = positive("dt", dt, unit=" s")
    seg = np.asarray(segments, dtype=np.float64).reshape(-1, 2)
    accs, durs = seg[:, 0], seg[:, 1]
    if not (np.isfinite(seg).all() and (durs >= 0).all()):
        raise StringStabError(f"segments must be (finite accel, finite duration >= 0); got {show(segments)}")
    edges = np.r_[0.0, np.cumsum(durs)]
    n = math.floor(edges[-1] / d + 1e-9)
    if n < 1:
        raise StringStabError(f"segments must last at least one step dt={show(d)} s; got {show(edges[-1])} s")
    grid = np.arange(n + 1) * d
    # the step average of the piecewise-constant acceleration (exactly a_j inside a segment)
    lo = np.clip(np.searchsorted(edges, grid[:-1] + 1e-9 * d, side="right") - 1, 0, len(accs) - 1)
    hi = np.clip(np.searchsorted(edges, grid[1:] - 1e-9 * d, side="right") - 1, 0, len(accs) - 1)
    a = np.zeros(n + 1)
    a[:-1] = accs[lo]
    mixed = np.flatnonzero(lo != hi)
    if mixed.size:
        cum = np.r_[0.0, np.cumsum(accs * durs)]  # ∫ a dt at the edges

        def integral(t: Array) -> Array:
            j = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, len(accs) - 1)
            return cum[j] + accs[j] * (t - edges[j])

        a[mixed] = (integral(grid[mixed + 1]) - integral(grid[mixed])) / d
    v = np.empty(n + 1)
    v[0] = speed0
    for k in range(n):
        nv = v[k] + a[k] * d
        if nv < 0.0 or nv > speed_max:
            nv = min(max(nv, 0.0), speed_max)
            a[k] = (nv - v[k]) / d
        v[k + 1] = nv
    a[-1] = a[-2]
    return Trajectory(d, _positions(v, d, 0.0), v, a, name)
