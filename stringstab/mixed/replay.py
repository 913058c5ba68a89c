"""The recorded leader replayed through a string: with the recorded cars, and with CAV(s).

The string's leader (the first follower's recorded predecessor) drives, as recorded, the
followers of the string in the toolkit's simulator (:func:`stringstab.traffic.simulate`: the
lag model of IDL eqs 5-7, exact ZOH, each follower with its own τ, gains and spacing policy
l_0 + T* v through a :class:`~stringstab.traffic.MixedController` of
:class:`~stringstab.traffic.LinearController`), or in Eclipse SUMO where the extra is installed
(:func:`stringstab.sumo.cosimulate`, the same controllers, SUMO moving the vehicles).  The
platoon starts in equilibrium at the leader's first speed; the acceleration and speed bounds
are set wide (±15 m/s², 0-70 m/s) so that the replay is the linear loop the certificate judges
unless a speed reaches 0 (the simulator keeps speeds ≥ 0).  The longest stretch on which every
vehicle of the string was measured is replayed (the one the data's own amplification uses).

For each variant: m_p of every follower (IDL eq 29, intended form: its acceleration energy
over its predecessor's), the head-to-tail energy ratio ‖a_N‖/‖a_0‖ (= ∏ m_p), the same in the
band 0 < ω ≤ 1 rad/s (:func:`band_energy`; the recorded leader's acceleration, the slope of a
10 Hz GPS speed, is dominated above it by sensor noise that any follower's lag filters out,
so the raw ratio says little about the waves — the band is that of the data's own energy
ratio, :data:`stringstab.identify.empirical.OMEGA_MAX`), the peak-to-peak speed ratio of the
last car to the leader, the smallest gap and the collisions.  For a linear
string with sup ∏|Γ_i| ≤ 1 the head-to-tail energy ratio cannot exceed 1 (Parseval), up to
the finite window and the start from equilibrium.  A recorded leader excites the frequencies
it happens to hold; :func:`probe` drives the strings instead with a sinusoid at the
certificate's peak frequency (around the recorded mean speed) and measures the last car's
steady acceleration amplitude over the leader's, to set beside ∏_i |Γ_i(jω)| computed from the
transfer functions.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify.head_to_tail import Vehicle
from ..errors import StringStabError
from .empirical import common_segments
from .vehicles import RecordedString

__all__ = ["Probe", "Replay", "ReplayRun", "band_energy", "leader_of", "probe", "replay"]

Array = npt.NDArray[np.float64]


@dataclass
class ReplayRun:
    """One variant of the string driven by the recorded leader.

    Attributes
    ----------
    label : str
        ``"recorded"``, ``"with CAV at 5"``, ...
    vehicles : tuple of Vehicle
        The followers.
    result : PlatoonResult
        The simulator's run (positions, speeds, accelerations, leader first).
    m_p : ndarray
        Each follower's m_p (IDL eq 29).
    energy_ratio : float
        ‖a_N‖₂/‖a_0‖₂, the last follower's acceleration energy over the leader's (∏ m_p).
    band_m_p : ndarray
        Each follower's m_p in the band 0 < ω ≤ 1 rad/s (:func:`band_energy`).
    band_ratio : float
        The head-to-tail energy ratio in that band.
    peak_to_peak : float
        The last follower's speed range over the leader's.
    min_gap : float
        The smallest gap of any follower, m.
    collisions : int
        Followers that collided.
    """

    label: str
    vehicles: tuple[Vehicle, ...]
    result: Any
    m_p: Array
    energy_ratio: float
    band_m_p: Array
    band_ratio: float
    peak_to_peak: float
    min_gap: float
    collisions: int

    @property
    def cumulative(self) -> Array:
        """The energy ratio of each follower to the leader along the string (∏_{i≤k} m_p)."""
        return np.asarray(np.cumprod(self.m_p), dtype=float)

    def as_dict(self) -> dict[str, Any]:
        """The JSON form (no trajectories).

        Returns
        -------
        dict
            ``label``, ``names``, ``m_p``, ``cumulative``, ``energy_ratio``, ``band_m_p``,
            ``band_cumulative``, ``band_ratio``, ``peak_to_peak``, ``min_gap``, ``collisions``.
        """
        def num(x: float) -> float | None:
            return float(x) if math.isfinite(x) else None

        return {"label": self.label, "names": [v.name for v in self.vehicles],
                "m_p": [num(x) for x in self.m_p], "cumulative": [num(x) for x in self.cumulative],
                "energy_ratio": num(self.energy_ratio),
                "band_m_p": [num(x) for x in self.band_m_p],
                "band_cumulative": [num(x) for x in np.cumprod(self.band_m_p)],
                "band_ratio": num(self.band_ratio), "peak_to_peak": num(self.peak_to_peak),
                "min_gap": num(self.min_gap), "collisions": int(self.collisions)}


@dataclass
class Replay:
    """The replays of one recorded leader (the recorded string first).

    Attributes
    ----------
    runs : list of ReplayRun
        The recorded string, then each CAV variant.
    simulator : str
        ``"toolkit"`` or ``"sumo"``.
    seconds : float
        The duration replayed, s.
    leader : str
        The leader's name.
    notes : list of str
        What the replay left out or changed.
    """

    runs: list[ReplayRun]
    simulator: str
    seconds: float
    leader: str
    notes: list[str] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        """The JSON form: simulator, seconds, leader, notes, runs.

        Returns
        -------
        dict
        """
        return {"simulator": self.simulator, "seconds": self.seconds, "leader": self.leader,
                "notes": self.notes, "runs": [r.as_dict() for r in self.runs]}


def leader_of(rec: RecordedString) -> tuple[Any, float]:
    """The recorded leader's trajectory on the longest fully measured stretch, and its length.

    Parameters
    ----------
    rec : RecordedString
        Read from an identify.json (it names its log).

    Returns
    -------
    (Trajectory, float)
        The leader (its recorded speed, at the log's step) and the stretch's duration, s.

    Raises
    ------
    StringStabError
        For a string without a log, or a log without such a stretch.
    """
    from ..identify.logs import read_logs
    from ..traffic import from_speed

    if rec.log is None:
        raise StringStabError(f"{rec.source} names no log: the replay needs the identify.json "
                              "of a recorded platoon")
    log = read_logs(rec.log, min_duration=rec.min_duration)[rec.platoon]
    segs = common_segments(log, rec.positions, min_duration=rec.min_duration)
    if not segs:
        raise StringStabError(f"the log {rec.log} has no stretch of {rec.min_duration:g} s with "
                              f"every follower {rec.positions[0]}..{rec.positions[-1]} measured")
    s = max(segs, key=len)
    v = np.asarray(log.speed[log.row(rec.positions[0] - 1)][s.start:s.stop], dtype=float)
    t = np.arange(v.size) * log.dt
    tr = from_speed(t, np.maximum(v, 0.0), dt=log.dt, name=rec.leader or "leader")
    return tr, float(t[-1])


def band_energy(accel: Array, dt: float, omega_max: float | None = None) -> Array:
    """Σ |A(ω)|² over 0 < ω ≤ ``omega_max`` of each row (its energy in the band, up to a constant).

    The discrete Fourier transform of each row (time along the last axis) after removing its
    mean; Parseval's theorem makes the sum the band's share of Σ a².

    Parameters
    ----------
    accel : ndarray
        Accelerations, m/s², time along the last axis (step ``dt``).
    dt : float
        Step, s.
    omega_max : float, optional
        The band's top, rad/s (default :data:`stringstab.identify.empirical.OMEGA_MAX`).

    Returns
    -------
    ndarray
        One energy per row.

    Examples
    --------
    >>> t = np.arange(0, 600, 0.1)
    >>> a = np.stack([np.sin(0.5 * t) + np.sin(5 * t), np.sin(5 * t)])
    >>> e = band_energy(a, 0.1)
    >>> bool(e[1] < 1e-3 * e[0])  # 5 rad/s is outside the band (up to the window's leakage)
    True
    """
    from ..identify.empirical import OMEGA_MAX

    top = OMEGA_MAX if omega_max is None else float(omega_max)
    a = np.asarray(accel, dtype=float)
    A = np.fft.rfft(a - a.mean(axis=-1, keepdims=True), axis=-1)
    w = 2.0 * np.pi * np.fft.rfftfreq(a.shape[-1], dt)
    band = (w > 0) & (w <= top)
    return np.asarray(np.sum(np.abs(A[..., band]) ** 2, axis=-1))


def _controller(vehicles: Sequence[Vehicle], standstill: Sequence[float]) -> Any:
    from ..traffic import LinearController, MixedController

    ctrls = [LinearController(v.k_x, v.k_v, v.k_a, headway=v.params.headway, standstill=l0)
             for v, l0 in zip(vehicles, standstill)]
    return MixedController(ctrls, list(range(len(ctrls))))


def _delta(vehicles: Sequence[Vehicle]) -> float:
    ds = {v.params.delta for v in vehicles if v.k_a != 0}
    if len(ds) > 1:
        raise StringStabError(
            "the simulator has one communication delay for the platoon; the vehicles with k_a != 0 "
            f"have δ = {sorted(ds)} s")
    return ds.pop() if ds else 0.0


def _no_reaction_delay(vehicles: Sequence[Vehicle]) -> None:
    late = [v.name or str(i) for i, v in enumerate(vehicles, start=1) if v.reaction_delay > 0]
    if late:
        raise StringStabError(
            f"the simulator has no reaction delay yet (issue 25, part 5); vehicle(s) "
            f"{', '.join(late)} have θ_r > 0: certify and design with it, replay without")


def _run(label: str, leader: Any, vehicles: tuple[Vehicle, ...], standstill: Sequence[float],
         simulator: str) -> ReplayRun:
    from ..traffic import Limits, simulate

    _no_reaction_delay(vehicles)
    limits = Limits(accel_min=-15.0, accel_max=15.0, speed_min=0.0, speed_max=70.0)
    tau = np.array([v.params.tau for v in vehicles])
    ctrl = _controller(vehicles, standstill)
    if simulator == "sumo":
        from ..sumo import cosimulate

        res = cosimulate(leader, ctrl, len(vehicles), tau=tau, delta=_delta(vehicles),  # type: ignore[arg-type]
                         limits=limits)
    else:
        res = simulate(leader, ctrl, len(vehicles), tau=tau, delta=_delta(vehicles),
                       limits=limits, progress=False)
    a = np.asarray(res.accel)  # a single leader: (N + 1, T)
    v = np.asarray(res.speed)
    eb = band_energy(a, float(res.dt))
    with np.errstate(divide="ignore", invalid="ignore"):
        m_p = np.sqrt(np.sum(a[1:] ** 2, axis=-1) / np.sum(a[:-1] ** 2, axis=-1))
        energy = float(np.sqrt(np.sum(a[-1] ** 2) / np.sum(a[0] ** 2)))
        band = np.sqrt(eb[1:] / eb[:-1])
        p2p = float(np.ptp(v[-1]) / np.ptp(v[0]))
    gap = np.asarray(res.gap)
    return ReplayRun(label, vehicles, res, m_p, energy, band, float(np.sqrt(eb[-1] / eb[0])), p2p,
                     float(np.min(gap)), int(np.count_nonzero(np.asarray(res.collided))))


def replay(rec: RecordedString, variants: Sequence[tuple[str, tuple[Vehicle, ...], Sequence[float]]],
           *, simulator: str = "toolkit") -> Replay:
    """The recorded leader through the recorded string and through each variant (module docstring).

    Parameters
    ----------
    rec : RecordedString
        The recorded string (from an identify.json with its log).
    variants : sequence of (label, vehicles, standstill)
        The strings with CAV(s), each with its followers' standstill distances.
    simulator : {"toolkit", "sumo"}
        The toolkit's simulator, or Eclipse SUMO (the ``sumo`` extra).

    Returns
    -------
    Replay
        The recorded string first.

    Raises
    ------
    StringStabError
        On a string without a log, a simulator not known, or (SUMO) the extra missing.
    """
    if simulator not in ("toolkit", "sumo"):
        raise StringStabError(f"simulator must be 'toolkit' or 'sumo'; got {simulator!r}")
    leader, seconds = leader_of(rec)
    runs = [_run("recorded", leader, rec.vehicles, rec.standstill, simulator)]
    for label, vs, l0 in variants:
        runs.append(_run(label, leader, tuple(vs), l0, simulator))
    notes = []
    if any(float(np.min(np.asarray(r.result.speed))) <= 0.0 for r in runs):
        notes.append("a simulated speed reached 0 m/s, where the simulator holds it (the loop is "
                     "not linear there)")
    return Replay(runs, simulator, seconds, leader.name, notes)


@dataclass
class Probe:
    """The strings driven by a sinusoid at ω: measured and predicted amplitude ratios.

    Attributes
    ----------
    omega : float
        The frequency, rad/s.
    labels : list of str
        The strings (as in :class:`Replay`).
    measured : list of float
        The last car's steady acceleration amplitude over the leader's, simulated (a least-
        squares sinusoid fitted to the last third of the run).
    predicted : list of float
        ∏_i |Γ_i(jω)| (:func:`stringstab.certify.frequency.gain`).
    """

    omega: float
    labels: list[str]
    measured: list[float]
    predicted: list[float]

    def as_dict(self) -> dict[str, Any]:
        """The JSON form.

        Returns
        -------
        dict
        """
        return {"omega": self.omega, "labels": self.labels, "measured": self.measured,
                "predicted": self.predicted}


def _amplitude(t: Array, a: Array, omega: float) -> float:
    """The amplitude of the sinusoid of frequency ω fitted to a(t) by least squares."""
    M = np.stack([np.sin(omega * t), np.cos(omega * t), np.ones_like(t)], axis=1)
    coef, *_ = np.linalg.lstsq(M, a, rcond=None)
    return float(np.hypot(coef[0], coef[1]))


def probe(strings: Sequence[tuple[str, Sequence[Vehicle], Sequence[float]]], omega: float, *,
          speed: float = 15.0, amplitude: float = 1.0, dt: float = 0.1,
          periods: int = 30) -> Probe:
    """Drive each string with v_0(t) = speed + amplitude·sin(ωt) (module docstring).

    Parameters
    ----------
    strings : sequence of (label, vehicles, standstill)
        The strings.
    omega : float
        The frequency, rad/s (> 0).
    speed, amplitude : float
        The leader's mean speed and speed amplitude, m/s.
    dt : float
        The simulator's step, s.
    periods : int
        The run's length in periods (at least 120 s).

    Returns
    -------
    Probe
    """
    from ..certify.frequency import gain
    from ..traffic import Limits, from_speed, simulate

    w = float(omega)
    if not (math.isfinite(w) and w > 0):
        raise StringStabError(f"the probe's frequency must be a number > 0 rad/s; got {omega!r}")
    T = max(120.0, periods * 2.0 * math.pi / w)
    t = np.arange(0.0, T, dt)
    leader = from_speed(t, speed + amplitude * np.sin(w * t), dt=dt, name=f"sine {w:.3g} rad/s")
    limits = Limits(accel_min=-15.0, accel_max=15.0, speed_min=0.0, speed_max=70.0)
    labels, measured, predicted = [], [], []
    for label, vs, l0 in strings:
        vs = tuple(vs)
        _no_reaction_delay(vs)
        res = simulate(leader, _controller(vs, l0), len(vs), tau=np.array([v.params.tau for v in vs]),
                       delta=_delta(vs), limits=limits, progress=False)
        a = np.asarray(res.accel)
        tt = np.asarray(res.t)
        keep = tt >= tt[-1] * 2.0 / 3.0
        measured.append(_amplitude(tt[keep], a[-1][keep], w) / _amplitude(tt[keep], a[0][keep], w))
        g = 1.0
        for v in vs:
            p = v.params
            g *= float(gain(w, v.k_x, v.k_v, v.k_a, tau=p.tau, delta=p.delta, headway=p.headway))
        predicted.append(g)
        labels.append(label)
    return Probe(w, labels, measured, predicted)

