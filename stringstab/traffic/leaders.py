"""Lead-vehicle trajectories: bundled driving cycles, synthetic profiles, NGSIM pairs, CSV files.

A :class:`Trajectory` is a lead vehicle's position, speed and acceleration sampled every ``dt``
seconds from ``t = 0``.  Sample ``k`` holds the state at ``t_k = k·dt``; ``accel[k]`` is the
acceleration over the step ``[t_k, t_{k+1})`` whenever the profile is piecewise constant in
acceleration (driving cycles, synthetic manoeuvres), so positions, speeds and accelerations
are mutually exact on the grid.

Sources

* :func:`cycle` — the EPA UDDS, HWFET, US06 and UN/ECE WLTC class 3b cycles bundled in
  ``stringstab/data/cycles`` (1 Hz speed, linearly interpolated to the step);
* synthetic profiles — :func:`sinusoid`, :func:`hard_braking` (−7.6 m/s², the IDL paper's
  acc_min, Table 2), :func:`hard_acceleration` (3 m/s², acc_max), :func:`stop_and_go` and
  :func:`paper_mix` (a reconstruction of the IDL paper's §5.1 leader);
* :func:`load_ngsim_pairs` — leader–follower pairs of at least 15 s from NGSIM US-101 / I-80
  trajectory files (IDL paper §4.1.1), in SI units;
* :func:`load_csv` — a generic ``t, v`` or ``t, v, a`` CSV file in SI units.

:func:`train_test_split` splits any list of trajectories or pairs reproducibly.
"""

from __future__ import annotations

import csv
import inspect
import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, TypeVar

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..params import positive

__all__ = [
    "CYCLES",
    "SYNTHETIC",
    "FollowingPair",
    "Trajectory",
    "cycle",
    "from_accel_segments",
    "from_speed",
    "hard_acceleration",
    "hard_braking",
    "leader_by_name",
    "load_csv",
    "load_ngsim_pairs",
    "paper_mix",
    "sinusoid",
    "stop_and_go",
    "train_test_split",
]

Array = npt.NDArray[np.float64]
T = TypeVar("T")

#: Speed limit of the road, m/s (IDL paper Table 2, v_max); leaders are capped at it by default.
SPEED_MAX = 33.3
FEET = 0.3048

#: Bundled driving cycles: name -> (file, description).
CYCLES: dict[str, tuple[str, str]] = {
    "udds": ("udds.csv", "EPA Urban Dynamometer Driving Schedule (FTP-72), 1369 s, stop-and-go"),
    "hwfet": ("hwfet.csv", "EPA Highway Fuel Economy Test, 765 s, highway"),
    "us06": ("us06.csv", "EPA US06 Supplemental FTP, 600 s, aggressive"),
    "wltc3b": ("wltc_3b.csv", "UN/ECE WLTC class 3b, 1800 s, four phases"),
}
_CYCLE_ALIASES = {"wltc": "wltc3b", "wltc_3b": "wltc3b", "wltc-3b": "wltc3b", "ftp72": "udds"}


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
    >>> tr = sinusoid(omega=0.5, amplitude=1.0, speed=20.0, duration=10.0, dt=0.1)
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
            raise StringStabError(f"trajectory step dt must be a finite number > 0 s; got {self.dt!r}")
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
        """This trajectory followed by ``seconds`` at its final speed (zero acceleration).

        Lets a long platoon settle before its damping ratios are measured (eq 29 sums over the
        whole run).

        Examples
        --------
        >>> tr = from_speed([0, 1], [10.0, 12.0], dt=0.5).hold(1.0)
        >>> tr.speed.tolist(), tr.accel.tolist()
        ([10.0, 11.0, 12.0, 12.0, 12.0], [2.0, 2.0, 0.0, 0.0, 0.0])
        """
        n = round(float(seconds) / self.dt)
        if n < 0:
            raise StringStabError(f"hold needs seconds >= 0; got {seconds!r}")
        v_end = self.speed[-1]
        x_tail = self.position[-1] + v_end * self.dt * np.arange(1, n + 1)
        accel = self.accel.copy()
        if n:
            accel[-1] = 0.0
        return Trajectory(self.dt, np.r_[self.position, x_tail], np.r_[self.speed, np.full(n, v_end)],
                          np.r_[accel, np.zeros(n)], self.name, dict(self.meta))

    def window(self, start: int, stop: int | None = None) -> Trajectory:
        """Samples ``start:stop``, re-timed to start at t = 0."""
        sl = slice(start, stop)
        return Trajectory(self.dt, self.position[sl], self.speed[sl], self.accel[sl], self.name,
                          dict(self.meta))


# --------------------------------------------------------------------------------------------
# construction helpers


def _grid(t0: float, t1: float, dt: float) -> Array:
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
    dt: float = 0.1,
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
            f"t must be strictly increasing; got t[{i}]={tt[i]!r} then t[{i + 1}]={tt[i + 1]!r}"
        )
    if (vv < 0).any():
        i = int(np.argmax(vv < 0))
        raise StringStabError(f"speed must be >= 0 m/s; got {vv[i]!r} at t={tt[i]!r}")
    grid = _grid(tt[0], tt[-1], d)
    if grid.shape[0] < 2:
        raise StringStabError(f"the profile lasts {tt[-1] - tt[0]!r} s, shorter than one step dt={d!r} s")
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
    dt: float = 0.1,
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
        raise StringStabError(f"segments must be (finite accel, finite duration >= 0); got {segments!r}")
    edges = np.r_[0.0, np.cumsum(durs)]
    n = math.floor(edges[-1] / d + 1e-9)
    if n < 1:
        raise StringStabError(f"segments must last at least one step dt={d!r} s; got {edges[-1]!r} s")
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


# --------------------------------------------------------------------------------------------
# bundled cycles


def cycle(name: str, *, dt: float = 0.1, speed_max: float | None = SPEED_MAX) -> Trajectory:
    """A bundled standard driving cycle, resampled to the step ``dt``.

    The 1 Hz speed samples are linearly interpolated; the acceleration is the slope over each
    step.  US06 and WLTC 3b exceed the IDL paper's road limit v_max = 33.3 m/s (Table 2) for
    24 s and 87 s; by default the leader's speed is capped there (``speed_max=None`` keeps it).

    Parameters
    ----------
    name : {"udds", "hwfet", "us06", "wltc3b"}
        Cycle name (case-insensitive; "wltc", "wltc_3b", "wltc-3b" are aliases of "wltc3b").
    dt : float
        Step, s.
    speed_max : float or None
        Speed cap, m/s.

    Returns
    -------
    Trajectory

    Raises
    ------
    StringStabError
        For an unknown cycle name.

    Examples
    --------
    >>> us06 = cycle("us06", dt=0.1)
    >>> us06.duration, round(float(us06.speed.max()), 1)
    (600.0, 33.3)
    """
    key = str(name).strip().lower()
    key = _CYCLE_ALIASES.get(key, key)
    if key not in CYCLES:
        raise StringStabError(f"unknown driving cycle {name!r}; expected one of {sorted(CYCLES)}")
    fname = CYCLES[key][0]
    res = resources.files("stringstab").joinpath("data").joinpath("cycles").joinpath(fname)
    with res.open("r", encoding="utf-8-sig") as fh:
        rows = list(csv.DictReader(fh))
    t = np.array([float(r["cycSecs"]) for r in rows])
    v = np.array([float(r["cycMps"]) for r in rows])
    tr = from_speed(t, np.maximum(v, 0.0), dt=dt, speed_max=speed_max, name=key)
    tr.meta.update(source=f"stringstab/data/cycles/{fname}", description=CYCLES[key][1])
    return tr


# --------------------------------------------------------------------------------------------
# synthetic profiles


def sinusoid(
    *,
    omega: float,
    amplitude: float = 1.0,
    speed: float = 20.0,
    duration: float = 200.0,
    dt: float = 0.1,
) -> Trajectory:
    """Constant speed with a sinusoidal perturbation, in closed form.

    v(t) = v̄ − A cos(ωt), a(t) = A ω sin(ωt), x(t) = v̄ t − (A/ω) sin(ωt): the acceleration
    starts at 0 and its amplitude is A ω.

    Parameters
    ----------
    omega : float
        Angular frequency ω, rad/s (> 0).
    amplitude : float
        Speed amplitude A, m/s (≥ 0, ≤ v̄).
    speed : float
        Mean speed v̄, m/s.
    duration : float
        s.
    dt : float
        Step, s.

    Examples
    --------
    >>> tr = sinusoid(omega=1.0, amplitude=2.0, speed=20.0, duration=100.0)
    >>> round(float(tr.accel.max()), 3)
    2.0
    """
    d = positive("dt", dt, unit=" s")
    if not (math.isfinite(omega) and omega > 0):
        raise StringStabError(f"omega must be a finite number > 0 rad/s; got {omega!r}")
    if not (0 <= amplitude <= speed):
        raise StringStabError(
            f"amplitude must be between 0 and the mean speed {speed!r} m/s; got {amplitude!r}"
        )
    t = _grid(0.0, float(duration), d)
    if t.shape[0] < 2:
        raise StringStabError(f"duration must be at least one step; got {duration!r}")
    wt = omega * t
    tr = Trajectory(d, speed * t - amplitude / omega * np.sin(wt), speed - amplitude * np.cos(wt),
                    amplitude * omega * np.sin(wt), f"sinusoid(omega={omega:g})")
    tr.meta.update(omega=omega, amplitude=amplitude, speed=speed)
    return tr


def hard_braking(
    *,
    speed: float = 25.0,
    to_speed: float = 0.0,
    decel: float = -7.6,
    cruise_before: float = 20.0,
    cruise_after: float = 30.0,
    dt: float = 0.1,
) -> Trajectory:
    """Cruise, brake at ``decel`` (default the IDL acc_min −7.6 m/s²) to ``to_speed``, cruise.

    Examples
    --------
    >>> tr = hard_braking(speed=25.0, to_speed=0.0, dt=0.1)
    >>> float(tr.accel.min()), float(tr.speed[-1])
    (-7.6, 0.0)
    """
    if not (decel < 0 and to_speed < speed):
        raise StringStabError(
            f"hard_braking needs decel < 0 and to_speed < speed; got decel={decel!r}, "
            f"speed={speed!r}, to_speed={to_speed!r}"
        )
    return from_accel_segments(
        [(0.0, cruise_before), (decel, (to_speed - speed) / decel), (0.0, cruise_after)],
        speed0=speed, dt=dt, name="hard-braking",
    )


def hard_acceleration(
    *,
    speed: float = 5.0,
    to_speed: float = 25.0,
    accel: float = 3.0,
    cruise_before: float = 20.0,
    cruise_after: float = 30.0,
    dt: float = 0.1,
) -> Trajectory:
    """Cruise, accelerate at ``accel`` (default the IDL acc_max 3 m/s²) to ``to_speed``, cruise.

    Examples
    --------
    >>> float(hard_acceleration().accel.max())
    3.0
    """
    if not (accel > 0 and to_speed > speed):
        raise StringStabError(
            f"hard_acceleration needs accel > 0 and to_speed > speed; got accel={accel!r}, "
            f"speed={speed!r}, to_speed={to_speed!r}"
        )
    return from_accel_segments(
        [(0.0, cruise_before), (accel, (to_speed - speed) / accel), (0.0, cruise_after)],
        speed0=speed, dt=dt, name="hard-acceleration",
    )


def stop_and_go(
    *,
    speed_high: float = 15.0,
    speed_low: float = 0.0,
    waves: int = 3,
    accel: float = 1.5,
    decel: float = -2.0,
    dwell_high: float = 20.0,
    dwell_low: float = 10.0,
    dt: float = 0.1,
) -> Trajectory:
    """Stop-and-go waves: ``waves`` trapezoidal dips from ``speed_high`` to ``speed_low`` and back.

    Examples
    --------
    >>> tr = stop_and_go(waves=2)
    >>> float(tr.speed.min()), float(tr.speed.max())
    (0.0, 15.0)
    """
    if not (speed_high > speed_low >= 0 and accel > 0 and decel < 0 and waves >= 1):
        raise StringStabError(
            "stop_and_go needs speed_high > speed_low >= 0, accel > 0, decel < 0, waves >= 1; got "
            f"speed_high={speed_high!r}, speed_low={speed_low!r}, accel={accel!r}, "
            f"decel={decel!r}, waves={waves!r}"
        )
    dv = speed_high - speed_low
    segs: list[tuple[float, float]] = [(0.0, dwell_high)]
    for _ in range(int(waves)):
        segs += [(decel, dv / -decel), (0.0, dwell_low), (accel, dv / accel), (0.0, dwell_high)]
    return from_accel_segments(segs, speed0=speed_high, dt=dt, name="stop-and-go")


#: (accel m/s², duration s) segments of :func:`paper_mix`, starting at 20 m/s.
PAPER_MIX_SEGMENTS: tuple[tuple[float, float], ...] = (
    (0.0, 10.0), (-3.0, 2.0), (0.0, 8.0), (3.0, 3.0), (0.0, 10.0),
    (-7.6, 2.5), (0.0, 5.0), (3.0, 5.0), (0.0, 10.0), (-5.0, 2.0), (0.0, 5.0),
    (2.0, 5.0), (0.0, 10.0), (-7.6, 2.5), (0.0, 5.0), (3.0, 6.0), (0.0, 34.0),
)


def paper_mix(*, dt: float = 0.1) -> Trajectory:
    """A reconstruction of the IDL paper's §5.1 leader: braking of varying severity and accelerations.

    The paper synthesises its Fig. 7 leader "from multiple representative driving profiles"
    with abrupt braking down to −7.6 m/s² and sudden accelerations up to 3 m/s², but does not
    publish it.  This one (125 s from 20 m/s, :data:`PAPER_MIX_SEGMENTS`) brakes at −3, −7.6,
    −5 and −7.6 m/s² (the last to a full stop) and accelerates at 3, 3, 2 and 3 m/s².

    Examples
    --------
    >>> tr = paper_mix()
    >>> tr.duration, float(tr.accel.min()), float(tr.accel.max()), float(tr.speed.min())
    (125.0, -7.6, 3.0, 0.0)
    """
    return from_accel_segments(list(PAPER_MIX_SEGMENTS), speed0=20.0, dt=dt, name="paper-mix")


#: Synthetic profiles by name (used by :func:`leader_by_name` and the CLI).
SYNTHETIC: dict[str, Callable[..., Trajectory]] = {
    "sinusoid": sinusoid,
    "braking": hard_braking,
    "acceleration": hard_acceleration,
    "stop-and-go": stop_and_go,
    "mix": paper_mix,
}


def _parse_kwargs(spec: str, fn: Callable[..., Any], what: str) -> dict[str, Any]:
    accepted = [p for p in inspect.signature(fn).parameters if p != "dt"]
    out: dict[str, Any] = {}
    for item in filter(None, (s.strip() for s in spec.split(","))):
        key, sep, val = item.partition("=")
        key = key.strip()
        if not sep or key not in accepted:
            raise StringStabError(
                f"{what}: expected KEY=VALUE with KEY in {accepted}; got {item!r}"
            )
        try:
            num = float(val)
        except ValueError as e:
            raise StringStabError(f"{what}: {key} must be a number; got {val.strip()!r}") from e
        out[key] = int(num) if key == "waves" else num
    return out


def leader_by_name(spec: str, *, dt: float = 0.1, duration: float | None = None) -> Trajectory:
    """The leader named by a command-line spec.

    ``spec`` is a cycle name (``udds``, ``hwfet``, ``us06``, ``wltc3b``), a synthetic profile
    with optional parameters (``sinusoid:omega=0.5,amplitude=1``, ``braking``,
    ``acceleration``, ``stop-and-go:waves=2``, ``mix``) or the path of a ``t, v[, a]`` CSV file.

    Parameters
    ----------
    spec : str
        See above.
    dt : float
        Step, s.
    duration : float, optional
        Keep only the first ``duration`` seconds.

    Raises
    ------
    StringStabError
        For an unknown name, a bad parameter or an unreadable file.

    Examples
    --------
    >>> leader_by_name("sinusoid:omega=0.5", dt=0.1).meta["omega"]
    0.5
    >>> leader_by_name("nope")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: unknown leader 'nope'; expected a cycle ...
    """
    name, _, params = str(spec).partition(":")
    key = name.strip().lower()
    if key in SYNTHETIC:
        fn = SYNTHETIC[key]
        tr = fn(dt=dt, **_parse_kwargs(params, fn, f"leader {key!r}"))
    elif key in CYCLES or key in _CYCLE_ALIASES:
        if params:
            raise StringStabError(f"leader {key!r} takes no parameters; got {params!r}")
        tr = cycle(key, dt=dt)
    elif spec.lower().endswith(".csv") or Path(spec).is_file():
        tr = load_csv(spec, dt=dt)
    else:
        raise StringStabError(
            f"unknown leader {spec!r}; expected a cycle {sorted(CYCLES)}, a synthetic profile "
            f"{sorted(SYNTHETIC)} (NAME:key=value,...) or the path of a 't, v[, a]' CSV file"
        )
    if duration is not None:
        if not duration > 0:
            raise StringStabError(f"duration must be > 0 s; got {duration!r}")
        n = min(tr.n_steps, math.floor(duration / tr.dt + 1e-9) + 1)
        tr = tr.window(0, max(n, 2))
    return tr


# --------------------------------------------------------------------------------------------
# files


def load_csv(path: str | Path, *, dt: float = 0.1, speed_max: float | None = None) -> Trajectory:
    """A leader from a CSV file with header ``t, v`` or ``t, v, a`` (s, m/s, m/s²).

    Parameters
    ----------
    path : path
        The file.
    dt : float
        Output step (the file may be sampled at any increasing times), s.
    speed_max : float, optional
        Cap the speed, m/s.

    Raises
    ------
    StringStabError
        If the file is missing or empty, its columns are not ``t, v`` or ``t, v, a``, a value is
        not a finite number, times are not strictly increasing or a speed is negative.
    """
    p = Path(path)
    try:
        with p.open(newline="", encoding="utf-8-sig") as fh:
            rows = [r for r in csv.reader(fh) if r and any(c.strip() for c in r)]
    except OSError as e:
        raise StringStabError(f"cannot read leader CSV {str(p)!r}: {e.strerror or e}") from e
    if not rows:
        raise StringStabError(f"leader CSV {str(p)!r} is empty; expected a header 't, v' or 't, v, a'")
    header = [c.strip().lower() for c in rows[0]]
    if header not in (["t", "v"], ["t", "v", "a"]):
        raise StringStabError(
            f"leader CSV {str(p)!r}: expected columns 't, v' or 't, v, a' (SI units: s, m/s, "
            f"m/s^2); found {[c.strip() for c in rows[0]]}"
        )
    data = []
    for i, r in enumerate(rows[1:], start=2):
        if len(r) != len(header):
            raise StringStabError(
                f"leader CSV {str(p)!r} line {i}: expected {len(header)} values; got {len(r)}"
            )
        try:
            vals = [float(c) for c in r]
        except ValueError as e:
            raise StringStabError(f"leader CSV {str(p)!r} line {i}: not a number in {r}") from e
        if not all(math.isfinite(x) for x in vals):
            raise StringStabError(f"leader CSV {str(p)!r} line {i}: values must be finite; got {r}")
        data.append(vals)
    if len(data) < 2:
        raise StringStabError(f"leader CSV {str(p)!r}: needs at least 2 data rows; got {len(data)}")
    arr = np.asarray(data)
    try:
        tr = from_speed(arr[:, 0], arr[:, 1], dt=dt, accel=arr[:, 2] if arr.shape[1] == 3 else None,
                        speed_max=speed_max, name=p.stem)
    except StringStabError as e:
        raise StringStabError(f"leader CSV {str(p)!r}: {e}") from e
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
    frame_period: float = 0.1,
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
        If the file cannot be read or lacks a required column.
    """
    p = Path(path)
    try:
        fh = p.open(newline="", encoding="utf-8-sig")
    except OSError as e:
        raise StringStabError(f"cannot read NGSIM file {str(p)!r}: {e.strerror or e}") from e
    with fh:
        reader = csv.reader(fh)
        header = [c.strip().lower() for c in next(reader, [])]
        missing = [c for c in _NGSIM_REQUIRED if c.lower() not in header]
        if missing:
            raise StringStabError(
                f"NGSIM file {str(p)!r}: missing columns {missing}; expected the US-101/I-80 "
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
                raise StringStabError(f"NGSIM file {str(p)!r} line {line}: bad numeric value") from e
            locs.append(r[loc_i].strip().lower() if loc_i is not None and loc_i < len(r) else "")
    if not num:
        return []
    arr = np.asarray(num)
    loc_arr = np.asarray(locs)
    if location is not None:
        if loc_i is None:
            raise StringStabError(
                f"NGSIM file {str(p)!r} has no Location column; cannot select location {location!r}"
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


def train_test_split(
    items: Sequence[T], *, test_fraction: float = 0.3, seed: int = 0, shuffle: bool = True
) -> tuple[list[T], list[T]]:
    """Split items (trajectories, pairs, ...) into train and test lists, reproducibly.

    The IDL paper uses 900 training and 386 testing pairs (test fraction ≈ 0.3).

    Parameters
    ----------
    items : sequence
        At least two items.
    test_fraction : float
        In (0, 1); the test list gets ``round(test_fraction·n)`` items, at least one, and the
        training list at least one.
    seed : int
        Seed of the shuffle.
    shuffle : bool
        If False, the last items are the test set (a chronological split).

    Examples
    --------
    >>> train_test_split(list(range(10)), test_fraction=0.3, shuffle=False)
    ([0, 1, 2, 3, 4, 5, 6], [7, 8, 9])
    """
    n = len(items)
    if n < 2:
        raise StringStabError(f"train_test_split needs at least 2 items; got {n}")
    if not (0.0 < test_fraction < 1.0):
        raise StringStabError(f"test_fraction must be in (0, 1); got {test_fraction!r}")
    n_test = min(max(round(test_fraction * n), 1), n - 1)
    order = np.random.default_rng(seed).permutation(n) if shuffle else np.arange(n)
    return [items[i] for i in order[: n - n_test]], [items[i] for i in order[n - n_test:]]
