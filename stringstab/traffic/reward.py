"""The IDL reward (eqs 18-24): safety (TTC), comfort (jerk) and efficiency (time headway).

All functions are vectorised; each term lies in [−1, 0] and the composite reward
r = ω₁ r_f + ω₂ r_j + ω₃ r_e (eq 18) uses ω = (1/3, 1/3, 1/3) by default (Table 2).

Notes on the printed equations
------------------------------
* Eq 23 prints F(h) = exp(−(ln h − μ)²/(2σ²)) / (σ√(2π)) and then states that F peaks at
  h* = 1.26 s with F(h*) ≈ 0.6588.  Those two numbers are those of the *log-normal density*
  F(h) = exp(−(ln h − μ)²/(2σ²)) / (h σ √(2π)) (mode e^{μ−σ²} = 1.2612 s, value 0.6588 for
  μ = 0.4226, σ = 0.4365, as in Zhu et al. 2020); the printed form lacks the 1/h and would peak
  at e^μ = 1.53 s with value 0.914.  The log-normal density is implemented.
* Eq 20 assigns −1 when TTC ≤ 0; a gap ≤ 0 (the vehicles touch) is also treated as −1 here,
  since eq 19 returns ∞ for an overlapping pair that is separating.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import numpy.typing as npt

from ..constants import ACCEL_MAX, ACCEL_MIN, HEADWAY_MU, HEADWAY_SIGMA, TTC_STAR
from .metrics import time_headway, time_to_collision

__all__ = [
    "comfort_reward",
    "efficiency_reward",
    "headway_density",
    "reward",
    "safety_reward",
]

Array = npt.NDArray[np.float64]

# acc_max, acc_min (Table 2) and the μ, σ of the log-normal headway density (eq 23, Zhu et al.
# 2020) are the toolkit's constants (:mod:`stringstab.constants`).


def safety_reward(ttc: npt.ArrayLike, *, ttc_star: float = TTC_STAR,
                  gap: npt.ArrayLike | None = None) -> Array:
    """r_f (IDL eq 20): 0 if TTC > TTC*, TTC/TTC* − 1 if 0 < TTC ≤ TTC*, −1 otherwise.

    Parameters
    ----------
    ttc : array_like
        Time to collision (eq 19), s.
    ttc_star : float
        Threshold, s (Table 2: 3 s).
    gap : array_like, optional
        Bumper-to-bumper gap; where gap ≤ 0 the reward is −1 (collision).

    Returns
    -------
    ndarray
        r_f, in [−1, 0], of the shape of the TTC.

    Examples
    --------
    >>> safety_reward([np.inf, 1.5, 0.0]).tolist()
    [0.0, -0.5, -1.0]
    """
    x = np.asarray(ttc, dtype=np.float64)
    r = np.where(x > ttc_star, 0.0, np.where(x > 0, x / ttc_star - 1.0, -1.0))
    if gap is not None:
        r = np.where(np.asarray(gap) <= 0, -1.0, r)
    return np.asarray(r)


def comfort_reward(accel: npt.ArrayLike, prev_accel: npt.ArrayLike, *,
                   accel_max: float = ACCEL_MAX, accel_min: float = ACCEL_MIN) -> Array:
    """r_j (IDL eq 21) = −(acc_t − acc_{t−1})² / (acc_max − acc_min)².

    Parameters
    ----------
    accel : array_like
        The follower's acceleration acc_t at this step, m/s².
    prev_accel : array_like
        Its acceleration acc_{t−1} at the previous step, m/s².
    accel_max, accel_min : float
        acc_max and acc_min, m/s² (Table 2: 3 and −7.6).

    Returns
    -------
    ndarray
        r_j, dimensionless, in [−1, 0] while both accelerations are within the limits.

    Examples
    --------
    >>> float(comfort_reward(3.0, -7.6))
    -1.0
    """
    d = np.asarray(accel, dtype=np.float64) - np.asarray(prev_accel, dtype=np.float64)
    return np.asarray(-(d * d) / (accel_max - accel_min) ** 2)


def headway_density(h: npt.ArrayLike, *, mu: float = HEADWAY_MU,
                    sigma: float = HEADWAY_SIGMA) -> Array:
    """F(h), the log-normal time-headway density (IDL eq 23, with the 1/h of the log-normal).

    Parameters
    ----------
    h : array_like
        Time headway h (eq 22: gap over the follower's speed), s.
    mu, sigma : float
        μ and σ of ln h (Zhu et al. 2020: 0.4226, 0.4365).

    Returns
    -------
    ndarray
        F(h) = exp(−(ln h − μ)²/(2σ²)) / (h σ √(2π)), in 1/s; 0 where h ≤ 0 or is not finite.

    Examples
    --------
    >>> round(float(headway_density(math.exp(HEADWAY_MU - HEADWAY_SIGMA**2))), 4)
    0.6588
    """
    x = np.asarray(h, dtype=np.float64)
    pos = np.isfinite(x) & (x > 0)
    xs = np.where(pos, x, 1.0)
    f = np.exp(-((np.log(xs) - mu) ** 2) / (2 * sigma**2)) / (xs * sigma * math.sqrt(2 * math.pi))
    return np.asarray(np.where(pos, f, 0.0))


@functools.lru_cache(maxsize=16)
def _density_peak(mu: float, sigma: float) -> float:
    """F(h*) of eq 23 at its mode h* = e^{μ − σ²} (computed once per (μ, σ))."""
    return float(headway_density(math.exp(mu - sigma**2), mu=mu, sigma=sigma))


def efficiency_reward(h: npt.ArrayLike, *, mu: float = HEADWAY_MU,
                      sigma: float = HEADWAY_SIGMA) -> Array:
    """r_e (IDL eq 24) = F(h)/F(h*) − 1 for h ∈ (0, ∞), −1 otherwise (NaN h counts as −1).

    h* = e^{μ − σ²} is the mode of :func:`headway_density` (1.26 s for the defaults).

    Parameters
    ----------
    h : array_like
        Time headway (eq 22), s.
    mu, sigma : float
        μ and σ of the log-normal headway density (eq 23).

    Returns
    -------
    ndarray
        r_e, dimensionless, in [−1, 0]; 0 at h = h*.

    Examples
    --------
    >>> efficiency_reward([1.2612, 0.0]).round(4).tolist()
    [0.0, -1.0]
    """
    peak = _density_peak(mu, sigma)
    x = np.asarray(h, dtype=np.float64)
    ok = np.isfinite(x) & (x > 0)
    return np.asarray(np.where(ok, headway_density(x, mu=mu, sigma=sigma) / peak - 1.0, -1.0))


def reward(
    gap: npt.ArrayLike,
    speed: npt.ArrayLike,
    pred_speed: npt.ArrayLike,
    accel: npt.ArrayLike,
    prev_accel: npt.ArrayLike,
    *,
    weights: tuple[float, float, float] = (1 / 3, 1 / 3, 1 / 3),
    ttc_star: float = TTC_STAR,
    ttc: npt.ArrayLike | None = None,
    headway: npt.ArrayLike | None = None,
) -> tuple[Array, Array, Array, Array]:
    """The composite IDL reward r = ω₁ r_f + ω₂ r_j + ω₃ r_e (eq 18) and its three terms.

    Parameters
    ----------
    gap, speed, pred_speed : array_like
        Gap (m), follower and predecessor speeds (m/s) after the step.
    accel, prev_accel : array_like
        The follower's acceleration after and before the step, m/s².
    weights : (float, float, float)
        ω₁, ω₂, ω₃ (Table 2: 1/3 each).
    ttc_star : float
        TTC*, s.
    ttc, headway : array_like, optional
        The TTC (eq 19) and the time headway (eq 22) of these gaps and speeds when the caller
        has them already (computed here from ``gap`` and the speeds when omitted).

    Returns
    -------
    (r, r_f, r_j, r_e)

    Examples
    --------
    >>> r, rf, rj, re = reward(27.0, 20.0, 20.0, 0.0, 0.0)
    >>> float(rf), float(rj), round(float(re), 3)
    (0.0, -0.0, -0.012)
    """
    if ttc is None:
        ttc = time_to_collision(gap, speed, pred_speed)
    if headway is None:
        headway = time_headway(gap, speed)
    r_f = safety_reward(ttc, ttc_star=ttc_star, gap=gap)
    r_j = comfort_reward(accel, prev_accel)
    r_e = efficiency_reward(headway)
    w1, w2, w3 = weights
    return w1 * r_f + w2 * r_j + w3 * r_e, r_f, r_j, r_e
