"""The IDL paper's evaluation metrics (§4.2), on simulated or measured trajectories.

Every function works on NumPy arrays whose *last axis is time* (sampled every ``dt``) and
broadcasts over the leading axes (vehicles, platoons).  Positions are front bumpers and the
``gap`` is bumper to bumper (the paper's Δx, eq 4): gap = x_{i−1} − x_i − length.

==========================  ===================================  ==========
metric                      function                             IDL eq
==========================  ===================================  ==========
TTC                         :func:`time_to_collision`            19
TIT                         :func:`time_integrated_ttc`          31-32
jerk squared c              :func:`jerk_squared`                 33
M_CI (mean squared jerk)    :func:`comfort_index`                34
time headway h              :func:`time_headway`                 22
M_effi                      :func:`efficiency_index`             35
m_p (damping ratio)         :func:`damping_ratio`,                29
                            :func:`damping_ratios_from_energy`
M_lss                       :func:`lss_index`                    30
m_fss (M_fss, a fraction)   :func:`fss_ratio`                    27-28
all of a simulated run      :func:`platoon_metrics`              —
collisions                  :func:`collision_count`              —
==========================  ===================================  ==========

Notes on the printed equations
------------------------------
* **Eq 29 is garbled**: it prints m_p^i = sqrt(Σ_t acc_t^{i 2} / Σ_t acc_{t−1}^{i 2}), a ratio
  of one vehicle's accelerations to themselves shifted by one step (≈ 1 always).  The text
  defines m_p as the "acceleration L2 norm cumulative damping ratio" of Shi et al. (2021) and
  reads m_p < 1 as "the cumulative squared acceleration of the following vehicle is lower than
  that of the leading vehicle", so the intended form — implemented here — is the follower
  over its predecessor:  m_p^i = sqrt(Σ_t (acc_t^i)² / Σ_t (acc_t^{i−1})²).
* Eq 30 names its mean "M_fss" and the text uses M_lss/M_TSS for it; here it is M_lss, the
  mean of m_p over the followers (the paper's i = 2..N with i = 1 the leader).
* Eq 22 prints h = (x^i − x^{i−1}) / v^i (negative as written); h = gap / v is meant.  It is
  undefined at standstill: where v ≤ v_min = 0.001 m/s (Table 2) h is NaN and M_effi (eq 35)
  averages over the moments where h is defined (eq 35 divides by every moment; the two agree
  whenever no vehicle stands still).
* Eq 31 writes the time step as τ; it is Δt here (τ is the actuator lag elsewhere).
* Eq 34 divides by N·T; M_CI is called the *mean* squared jerk, so the mean over the N·(T−1)
  jerk samples is returned.
* Eq 27 multiplies by 100 %; the toolkit reports M_fss as a fraction in [0, 1] (key ``m_fss``,
  as ``stringstab certify`` does; docs/conventions.md).

Layering: these functions work on arrays.  :func:`platoon_metrics` reads a run's arrays
(:class:`stringstab.traffic.PlatoonResult` is one such run) and calls nothing back on it;
``PlatoonResult.metrics()`` calls :func:`platoon_metrics`, never the reverse.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

from .. import constants
from ..certify.verdicts import Verdict
from ..errors import StringStabError
from ..params import positive

__all__ = [
    "collision_count",
    "comfort_index",
    "damping_ratio",
    "damping_ratios_from_energy",
    "efficiency_index",
    "fss_ratio",
    "jerk_squared",
    "lss_index",
    "platoon_damping_ratios",
    "platoon_metrics",
    "time_headway",
    "time_integrated_ttc",
    "time_to_collision",
]

Array = npt.NDArray[np.float64]
ArrayLike = npt.ArrayLike

#: TTC* threshold of the safety metrics, s (IDL Table 2).
TTC_STAR = constants.TTC_STAR
#: Lower speed bound v_min, m/s (IDL Table 2).
V_MIN = constants.SPEED_MIN


def time_to_collision(gap: ArrayLike, speed: ArrayLike, pred_speed: ArrayLike) -> Array:
    """Time to collision TTC (IDL eq 19).

    TTC = gap / (v_i − v_{i−1}) if the follower is faster than its predecessor, else ∞.
    A negative value means the vehicles already overlap (gap < 0) while closing.

    Parameters
    ----------
    gap : array_like
        Bumper-to-bumper gap, m.
    speed, pred_speed : array_like
        Speeds of the follower and of its predecessor, m/s.

    Returns
    -------
    ndarray
        TTC, s (``inf`` when not closing).

    Examples
    --------
    >>> time_to_collision([10.0, 10.0], [12.0, 10.0], [10.0, 12.0]).tolist()
    [5.0, inf]
    """
    g = np.asarray(gap, dtype=np.float64)
    closing = np.asarray(speed, dtype=np.float64) - np.asarray(pred_speed, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray(np.where(closing > 0, g / np.where(closing > 0, closing, 1.0), np.inf))


def time_integrated_ttc(ttc: ArrayLike, dt: float, *, ttc_star: float = TTC_STAR,
                        axis: int = -1) -> Array:
    """Time-integrated time to collision TIT (IDL eqs 31-32; Minderhoud & Bovy 2001).

    TIT = Σ_t (TTC* − TTC_t) · Δt · ϑ_t with ϑ_t = 1 if 0 ≤ TTC_t ≤ TTC*, else 0.

    Parameters
    ----------
    ttc : array_like
        TTC series, s (time along ``axis``).
    dt : float
        Sampling step, s (the τ of eq 31).
    ttc_star : float
        Threshold TTC*, s (Table 2: 3 s).
    axis : int
        Time axis.

    Returns
    -------
    ndarray
        TIT per series, s².

    Examples
    --------
    >>> float(time_integrated_ttc([1.0, 2.0, 5.0, np.inf], 0.1))
    0.30000000000000004
    """
    d = positive("dt", dt, unit=" s")
    x = np.asarray(ttc, dtype=np.float64)
    inside = (x >= 0) & (x <= ttc_star)
    return np.asarray(np.sum(np.where(inside, ttc_star - x, 0.0), axis=axis) * d)


def jerk_squared(accel: ArrayLike, dt: float, *, axis: int = -1) -> Array:
    """Squared jerk c_t = ((acc_t − acc_{t−Δt}) / Δt)² (IDL eq 33), m²/s⁶.

    Returns one sample fewer than ``accel`` along ``axis``.

    Parameters
    ----------
    accel : array_like
        Accelerations acc_t, m/s², sampled every ``dt`` along ``axis``.
    dt : float
        Sample time Δt > 0, s.
    axis : int
        The time axis.

    Returns
    -------
    ndarray
        c_t, m²/s⁶, one sample shorter than ``accel`` along ``axis``.

    Raises
    ------
    StringStabError
        If ``dt`` is not a finite number > 0.

    Examples
    --------
    >>> jerk_squared([0.0, 0.1, 0.3], 0.1).round(12).tolist()
    [1.0, 4.0]
    """
    d = positive("dt", dt, unit=" s")
    return np.asarray((np.diff(np.asarray(accel, dtype=np.float64), axis=axis) / d) ** 2)


def comfort_index(accel: ArrayLike, dt: float, *, axis: int = -1) -> float:
    """M_CI, the mean squared jerk over every vehicle and moment (IDL eq 34), m²/s⁶.

    Parameters
    ----------
    accel : array_like
        Accelerations, m/s², time along ``axis`` (any leading axes: vehicles, platoons).
    dt : float
        Sample time Δt > 0, s.
    axis : int
        The time axis.

    Returns
    -------
    float
        M_CI, the mean of :func:`jerk_squared` over every entry, m²/s⁶.

    Examples
    --------
    >>> round(comfort_index([[0.0, 0.1, 0.3], [0.0, 0.0, 0.0]], 0.1), 12)
    1.25
    """
    return float(np.mean(jerk_squared(accel, dt, axis=axis)))


def time_headway(gap: ArrayLike, speed: ArrayLike, *, v_min: float = V_MIN) -> Array:
    """Time headway h = gap / v (IDL eq 22), s; NaN where v ≤ ``v_min`` (standstill).

    Parameters
    ----------
    gap : array_like
        Bumper-to-bumper gap to the predecessor, m.
    speed : array_like
        The follower's speed v, m/s, broadcast with ``gap``.
    v_min : float
        Speeds at or below this (m/s) count as standstill.

    Returns
    -------
    ndarray
        h, s, of the broadcast shape; NaN at standstill.

    Examples
    --------
    >>> time_headway([22.0, 2.0], [20.0, 0.0]).tolist()
    [1.1, nan]
    """
    g = np.asarray(gap, dtype=np.float64)
    v = np.asarray(speed, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray(np.where(v > v_min, g / np.where(v > v_min, v, 1.0), np.nan))


def efficiency_index(headway: ArrayLike) -> float:
    """M_effi, the mean time headway over every vehicle and moment where it is defined (eq 35), s.

    Returns NaN if h is nowhere defined (every vehicle always stopped).

    Parameters
    ----------
    headway : array_like
        Time headways h (:func:`time_headway`), s; NaN entries are ignored.

    Returns
    -------
    float
        M_effi, s, or NaN if no entry is finite.

    Examples
    --------
    >>> efficiency_index([[1.0, 2.0], [np.nan, 3.0]])
    2.0
    """
    h = np.asarray(headway, dtype=np.float64)
    ok = np.isfinite(h)
    return float(h[ok].mean()) if ok.any() else float("nan")


def damping_ratio(accel: ArrayLike, pred_accel: ArrayLike, *, axis: int = -1) -> Array:
    """Acceleration L2 damping ratio m_p of a follower over its predecessor (IDL eq 29, intended).

    m_p = sqrt(Σ_t acc_t^{i 2} / Σ_t acc_t^{i−1 2}).  The printed eq 29 divides by the same
    vehicle's shifted accelerations, which is a typesetting error (see the module notes).
    m_p < 1: the follower's acceleration energy is smaller than its predecessor's.

    Parameters
    ----------
    accel : array_like
        The follower's accelerations acc^i, m/s², time along ``axis``.
    pred_accel : array_like
        Its predecessor's accelerations acc^{i−1} on the same time grid, m/s².
    axis : int
        The time axis.

    Returns
    -------
    ndarray
        m_p (dimensionless), the time axis removed; NaN or inf where the predecessor
        never accelerates.

    Examples
    --------
    >>> float(damping_ratio([0.0, 0.5, -0.5], [0.0, 1.0, -1.0]))
    0.5
    """
    a = np.asarray(accel, dtype=np.float64)
    p = np.asarray(pred_accel, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray(np.sqrt(np.sum(a * a, axis=axis) / np.sum(p * p, axis=axis)))


def damping_ratios_from_energy(sum_sq_accel: ArrayLike) -> Array:
    """m_p of every follower from each vehicle's Σ_t a_t² (eq 29, intended form), (..., N).

    ``sum_sq_accel`` has shape (..., N + 1) with vehicle 0 the leader.  NaN where a
    predecessor never accelerates (0/0), ``inf`` where only the follower does.

    Parameters
    ----------
    sum_sq_accel : array_like, shape (..., N + 1)
        Σ_t a_t² of each vehicle, m²/s⁴, vehicle 0 the leader.

    Returns
    -------
    ndarray, shape (..., N)
        m_p of followers 1..N relative to their predecessors.

    Raises
    ------
    StringStabError
        If the last axis has fewer than two vehicles.

    Examples
    --------
    >>> damping_ratios_from_energy([4.0, 1.0, 0.25]).tolist()
    [0.5, 0.5]
    """
    s = np.asarray(sum_sq_accel, dtype=np.float64)
    if s.ndim < 1 or s.shape[-1] < 2:
        raise StringStabError(f"sum_sq_accel must have shape (..., N + 1 >= 2); got {s.shape}")
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray(np.sqrt(s[..., 1:] / s[..., :-1]))


def platoon_damping_ratios(accel: ArrayLike) -> Array:
    """m_p of every follower of a platoon relative to its predecessor (eq 29, intended form).

    Parameters
    ----------
    accel : array_like (..., N + 1, T)
        Accelerations, vehicle 0 the leader.

    Returns
    -------
    ndarray (..., N)

    Examples
    --------
    >>> platoon_damping_ratios([[1.0, -1.0], [0.5, -0.5], [0.4, -0.4]]).tolist()
    [0.5, 0.8]
    """
    a = np.asarray(accel, dtype=np.float64)
    if a.ndim < 2 or a.shape[-2] < 2:
        raise StringStabError(f"accel must have shape (..., N + 1 >= 2, T); got {a.shape}")
    return damping_ratios_from_energy(np.sum(a * a, axis=-1))


def lss_index(m_p: ArrayLike) -> Array:
    """M_lss, the mean damping ratio over the followers (IDL eq 30), along the last axis.

    Parameters
    ----------
    m_p : array_like
        Damping ratios of the followers (:func:`damping_ratios_from_energy`), along the last axis.

    Returns
    -------
    ndarray
        M_lss, the last axis removed (a 0-d array for one platoon).

    Examples
    --------
    >>> float(lss_index([0.5, 0.7, 0.9]))
    0.7
    """
    return np.asarray(np.mean(np.asarray(m_p, dtype=np.float64), axis=-1))


def fss_ratio(k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike, *, tau: float, delta: float,
              headway: float, reaction_delay: float = 0.0) -> float:
    """m_fss, the share of (vehicle, moment) gains that are string stable (IDL eqs 27-28).

    m_fss = 1 where the gains in force are *certified* by the exact delay-aware certificate
    (:func:`stringstab.certify.api.certify_batch`: internally stable and sup_ω |Γ(jω)| ≤ 1),
    else 0 ("inconclusive" counts as 0); the share is Σ m_fss / (N · T/Δt), eq 27's M_fss
    without its ×100 % (a fraction, as everywhere in the toolkit: docs/conventions.md).
    Identical triples are certified once.

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains at every (vehicle, moment), any common shape.
    tau, delta, headway : float
        τ, δ and T*, s.
    reaction_delay : float
        θ_r, s (issue 25): the triples are certified for the loop with the command applied θ_r
        late; 0 (default) is the loop without it.

    Returns
    -------
    float
        The fraction in [0, 1] of the triples certified.

    Raises
    ------
    StringStabError
        On no triple, or non-finite gains.

    Examples
    --------
    >>> fss_ratio([1.2, 0.1], [0.5, 0.58], [0.6, 1.0], tau=0.1, delta=0.2, headway=1.1)
    0.5
    """
    from ..certify.api import certify_batch
    from ..params import as_gains

    kx, kv, ka = as_gains(k_x, k_v, k_a)
    K = np.stack([kx.ravel(), kv.ravel(), ka.ravel()], axis=1)
    if K.shape[0] == 0:
        raise StringStabError("fss_ratio needs at least one gain triple")
    uniq, inverse = np.unique(K, axis=0, return_inverse=True)
    cert = certify_batch(uniq[:, 0], uniq[:, 1], uniq[:, 2], tau=tau, delta=delta, headway=headway,
                         reaction_delay=reaction_delay)
    ok = np.asarray(cert.verdict == Verdict.CERTIFIED)[np.ravel(inverse)]
    return float(ok.mean())


def collision_count(gap: ArrayLike, *, axis: int = -1) -> npt.NDArray[np.int64]:
    """Number of collisions per series: entries into gap ≤ 0 (a run starting in collision counts).

    Parameters
    ----------
    gap : array_like
        Bumper-to-bumper gaps, m, time along ``axis``.
    axis : int
        The time axis.

    Returns
    -------
    ndarray of int64
        Number of entries into gap ≤ 0 per series (the time axis removed).

    Examples
    --------
    >>> collision_count([[1.0, 0.0, -1.0, 2.0, -0.5], [1.0, 1.0, 1.0, 1.0, 1.0]]).tolist()
    [2, 0]
    """
    c = np.moveaxis(np.asarray(gap, dtype=np.float64) <= 0, axis, -1)
    first = c[..., :1]
    entries = c[..., 1:] & ~c[..., :-1]
    return np.asarray(first.sum(axis=-1) + entries.sum(axis=-1), dtype=np.int64)


def _collided_positions(collided: npt.NDArray[np.bool_]) -> list[Any]:
    """1-based follower positions that collided ([platoon, position] pairs for a batch)."""
    if collided.ndim == 1:
        return [int(i) + 1 for i in np.flatnonzero(collided)]
    return [[int(p), int(i) + 1] for p, i in np.argwhere(collided)]


def platoon_metrics(result: Any, *, ttc_star: float = TTC_STAR,
                    certificate: bool = True) -> dict[str, Any]:
    """All IDL metrics of a simulated run (:class:`stringstab.traffic.PlatoonResult`).

    Followers only (the leader is prescribed).  For a batch of platoons, per-vehicle lists are
    nested per platoon and the scalar indices pool every platoon.  Only the run's arrays are
    read (``sum_sq_accel``, ``gap``, ``speed``, ``accel``, ``gains``, ``params``, ...).

    Parameters
    ----------
    result : stringstab.traffic.PlatoonResult
        A simulated run (one platoon or a batch).
    ttc_star : float
        TTC threshold TTC* of TIT (IDL eqs 31-32), s.
    certificate : bool
        Compute M_fss (certifies every distinct gain triple in force, with the run's reaction
        delay θ_r; skipped also when the actuator lag τ or θ_r differs between vehicles).

    Returns
    -------
    dict
        ``m_p`` (eq 29, per follower), ``max_m_p``, ``M_lss`` (eq 30), ``TIT`` (eqs 31-32,
        summed over followers) and ``TIT_per_vehicle``, ``M_CI`` (eq 34), ``M_effi`` (eq 35),
        ``min_ttc``, ``min_gap``, ``min_headway``, ``collisions`` (events) and
        ``collided_vehicles`` (1-based positions), ``m_fss`` (eq 27 as a fraction in [0, 1];
        None if the controller is not of the eq-4 form or ``certificate`` is False).  Units: s² for TIT,
        m²/s⁶ for M_CI, s for M_effi, min_ttc and min_headway, m for min_gap.
    """
    mp = damping_ratios_from_energy(result.sum_sq_accel)
    out: dict[str, Any] = {
        "m_p": mp.round(6).tolist(),
        "max_m_p": float(np.max(mp)),
        "M_lss": float(np.mean(mp)),
        "collisions": int(np.sum(result.collision_events)),
        "collided_vehicles": _collided_positions(np.asarray(result.collided)),
        "min_gap": float(np.min(result.min_gap)),
    }
    if result.speed is not None:
        gap = result.gap
        spd = result.speed
        ttc = time_to_collision(gap, spd[..., 1:, :], spd[..., :-1, :])
        tit = time_integrated_ttc(ttc, result.dt, ttc_star=ttc_star)
        h = time_headway(gap, spd[..., 1:, :])
        out.update(
            TIT=float(np.sum(tit)),
            TIT_per_vehicle=tit.round(6).tolist(),
            M_CI=comfort_index(result.accel[..., 1:, :], result.dt),
            M_effi=efficiency_index(h),
            min_ttc=float(np.min(np.where(ttc >= 0, ttc, np.inf))) if ttc.size else float("inf"),
            min_headway=float(np.nanmin(h)) if np.isfinite(h).any() else float("nan"),
            ttc_star=ttc_star,
        )
    out["m_fss"] = None
    if certificate and result.gains is not None and result.params.get("headway") is not None:
        taus = np.unique(np.asarray(result.params["tau"], dtype=np.float64))
        thetas = np.unique(np.asarray(result.params.get("reaction_delay", 0.0), dtype=np.float64))
        if taus.size == 1 and thetas.size == 1:
            G = result.gains
            out["m_fss"] = fss_ratio(G[..., 0], G[..., 1], G[..., 2], tau=float(taus[0]),
                                     delta=result.params["delta"],
                                     headway=result.params["headway"],
                                     reaction_delay=float(thetas[0]))
    for key in ("min_ttc", "min_headway", "M_effi"):
        if key in out and not math.isfinite(out[key]):
            out[key] = None
    return out
