"""The HCFS switch: reward-based choice (eq 12) with its one-step prediction, the soft switch (eqs 13-14), and a jerk-safe variant.

Every frame two candidate accelerations are available, a1 = a_DDPG (the learned policy, or a
stand-in) and a2 = a_CACC.  The hybrid output is a convex combination

    a_k = λ_k a1_k + (1 − λ_k) a2_k,

and the rules differ only in the weight λ_k of a1.

Eq 12 (choice)
    c_k = [r_DDPG > r_CACC]: the candidate with the larger reward wins (a tie goes to CACC).
    The reward r_k(s_{k+1} | a_k, s_k) depends on the state *after* the action, so the switch
    needs a one-step prediction (:func:`predicted_rewards`): the ego speed follows exactly from
    the kinematics (v_{k+1} = v_k + a T), the leader's speed is extrapolated from the last two
    speeds received over V2V at constant acceleration.

Eqs 13-14 (soft switch, ``rule="paper"``)
    α_k = [c_k ≠ c_{k−1}] (a switch); β_k = β α_k (eq 14: β = 0.5 at a switch, 0 otherwise);
    a_k = (1 − β_k) a_{winner} + β_k a_{loser} (eq 13), i.e. λ_k = 1 − β_k if c_k else β_k.

Jerk-safe variant (``rule="safe"``)
    a_k = clip(eq-13 output, a_{k−1} − J T, a_{k−1} + J T).  Because a_k(λ) is affine in λ,
    this is the eq-13 weight moved towards the previous frame's weight just as far as needed; the
    output stays a convex combination of a1_k and a2_k, and |a_k − a_{k−1}| ≤ J T holds at
    every frame whenever each candidate satisfies its own rate premise, *without* the premise
    a1_{k−1} = a2_{k−1} (proof in ``docs/hcfs.md``; checked by
    :func:`stringstab.hcfs.theorem.check_theorem`).

References
----------
HCFS paper, §III-C, eqs 12-14.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from .constants import BETA, DT
from .mdp import reward

__all__ = [
    "RULES",
    "check_beta",
    "choose",
    "limit_step",
    "predicted_lead_speed",
    "predicted_rewards",
    "step_weight",
    "switch_weights",
]

Array = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

#: Switching rules: the paper's eqs 12-14, and the jerk-safe variant.
RULES = ("paper", "safe")


def check_beta(beta: object) -> float:
    """β as a float in [0, 1] (eq 13).

    Parameters
    ----------
    beta : object
        β of eqs 13-14, the weight of the losing candidate at a switch (the paper: 0.5).

    Returns
    -------
    float
        β.

    Raises
    ------
    StringStabError
        Unless β is a finite number with 0 ≤ β ≤ 1.

    Examples
    --------
    >>> check_beta(0.5)
    0.5
    >>> check_beta(1.5)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: beta must be a number in [0, 1] (eq 13); got 1.5
    """
    try:
        b = float(beta)  # type: ignore[arg-type]
    except (TypeError, ValueError) as e:
        raise StringStabError(f"beta must be a number in [0, 1] (eq 13); got {beta!r}") from e
    if not 0.0 <= b <= 1.0:  # also rejects NaN
        raise StringStabError(f"beta must be a number in [0, 1] (eq 13); got {beta!r}")
    return b


def choose(r_ddpg: npt.ArrayLike, r_cacc: npt.ArrayLike) -> BoolArray:
    """Eq 12: True where the DDPG action wins (r_DDPG > r_CACC; a tie goes to CACC).

    Parameters
    ----------
    r_ddpg, r_cacc : array_like
        The eq-6 rewards the two candidates would earn (:func:`predicted_rewards`).

    Returns
    -------
    bool array
        c_k: True where a1 (DDPG) wins.

    Examples
    --------
    >>> choose([-1.0, -0.5, -0.5], [-0.5, -1.0, -0.5]).tolist()
    [False, True, False]
    """
    return np.asarray(np.asarray(r_ddpg) > np.asarray(r_cacc))


def step_weight(use_ddpg: npt.ArrayLike, prev_use_ddpg: npt.ArrayLike,
                beta: float = BETA) -> tuple[Array, BoolArray]:
    """Weight λ_k of a1 (the DDPG action) at one frame, by eqs 13-14.

    Parameters
    ----------
    use_ddpg, prev_use_ddpg : bool array_like
        The eq-12 choice c_k and c_{k−1} (True: DDPG wins).
    beta : float
        β applied at a switch (eq 14: 0.5); β = 0 is the hard switch of eq 12.

    Returns
    -------
    (λ_k, α_k) : arrays
        The weight of a1 and whether the frame is a switch.

    Examples
    --------
    >>> lam, alpha = step_weight([True, True, False], [True, False, True], 0.5)
    >>> lam.tolist(), alpha.tolist()
    ([1.0, 0.5, 0.5], [False, True, True])
    """
    c = np.asarray(use_ddpg, dtype=bool)
    switch = c != np.asarray(prev_use_ddpg, dtype=bool)
    b = np.where(switch, check_beta(beta), 0.0)
    return np.asarray(np.where(c, 1.0 - b, b)), np.asarray(switch)


def switch_weights(use_ddpg: npt.ArrayLike, *, beta: float = BETA,
                   initial: npt.ArrayLike = False) -> tuple[Array, BoolArray]:
    """Weights λ_k of a1 over a sequence of frames (last axis), by eqs 13-14.

    Parameters
    ----------
    use_ddpg : bool array (..., K)
        The eq-12 choices c_0 … c_{K−1}.
    beta : float
        β at a switch (eq 14).
    initial : bool or bool array (...)
        The choice before frame 0 (False: the strategy starts on CACC).

    Returns
    -------
    (λ, α) : arrays (..., K)

    Examples
    --------
    >>> lam, alpha = switch_weights([False, True, True, False])
    >>> lam.tolist(), alpha.tolist()
    ([0.0, 0.5, 1.0, 0.5], [False, True, False, True])
    """
    c = np.asarray(use_ddpg, dtype=bool)
    if c.ndim < 1:
        raise StringStabError(f"use_ddpg must have a frame axis (..., K); got shape {c.shape}")
    prev = np.concatenate([np.broadcast_to(np.asarray(initial, dtype=bool), c.shape[:-1])[..., None],
                           c[..., :-1]], axis=-1)
    return step_weight(c, prev, beta)


def limit_step(target: npt.ArrayLike, previous: npt.ArrayLike, step_limit: npt.ArrayLike) -> Array:
    """The jerk-safe variant: clip the output into [a_{k−1} − J T, a_{k−1} + J T].

    Parameters
    ----------
    target : array_like
        The eq-13 output λ*_k a1_k + (1 − λ*_k) a2_k, m/s².
    previous : array_like
        The previous hybrid output a_{k−1}, m/s².
    step_limit : float or array_like
        J T, m/s² (broadcast against ``target``).

    Returns
    -------
    ndarray
        The clipped accelerations, m/s².

    Examples
    --------
    >>> limit_step([1.0, -1.0, 0.1], 0.0, 0.5).tolist()
    [0.5, -0.5, 0.1]
    """
    p = np.asarray(previous, dtype=np.float64)
    lim = np.asarray(step_limit, dtype=np.float64)
    return np.asarray(np.clip(np.asarray(target, dtype=np.float64), p - lim, p + lim))


def predicted_lead_speed(lead_speed_rx: npt.ArrayLike, prev_lead_speed_rx: npt.ArrayLike, *,
                         delay: float, dt: float = DT) -> Array:
    """The leader's speed at t_{k+1}, extrapolated from the last two speeds received over V2V.

    The received speeds are those of t_k − δ and t_{k−1} − δ; at constant acceleration
    â = (ṽ_k − ṽ_{k−1}) / T the speed at t_{k+1} is ṽ_k + â (T + δ).

    Parameters
    ----------
    lead_speed_rx : array_like
        ṽ_k, the leader's speed received at frame k (that of t_k − δ), m/s.
    prev_lead_speed_rx : array_like
        ṽ_{k−1}, the one received at frame k − 1, m/s.
    delay : float
        V2V delay δ, s.
    dt : float
        Frame length T, s.

    Returns
    -------
    array
        The predicted leader speed at t_{k+1}, m/s (for the reward of eq 12's choice).

    Examples
    --------
    >>> float(predicted_lead_speed(10.2, 10.0, delay=0.0, dt=0.2))
    10.4
    """
    v = np.asarray(lead_speed_rx, dtype=np.float64)
    acc = (v - np.asarray(prev_lead_speed_rx, dtype=np.float64)) / dt
    return np.asarray(v + acc * (dt + float(delay)))


def predicted_rewards(candidates: npt.ArrayLike, speed: npt.ArrayLike, lead_speed_next: npt.ArrayLike,
                      last_output: npt.ArrayLike, *, dt: float = DT, **weights: float) -> Array:
    """The eq-6 reward each candidate action would earn, by a one-step prediction (for eq 12).

    Parameters
    ----------
    candidates : array_like
        Candidate accelerations a (any shape broadcasting with the rest), m/s².
    speed : array_like
        Ego speed v_k, m/s; the prediction is v_{k+1} = v_k + a T (§IV kinematics).
    lead_speed_next : array_like
        Predicted leader speed at t_{k+1} (:func:`predicted_lead_speed`), m/s.
    last_output : array_like
        The previous hybrid output a_{k−1} (the jerk of eq 5 is measured from it), m/s².
    dt : float
        T, s.
    **weights : float
        ``omega_1, omega_2, speed_max, accel_max`` passed to :func:`~stringstab.hcfs.mdp.reward`.

    Returns
    -------
    ndarray
        The predicted eq-6 reward of each candidate.

    Examples
    --------
    >>> predicted_rewards([0.0, 1.0], 10.0, 10.2, 0.0, omega_1=1.0, omega_2=0.0,
    ...                   speed_max=1.0).round(6).tolist()
    [-0.2, -0.0]
    """
    a = np.asarray(candidates, dtype=np.float64)
    ev_next = np.asarray(speed, dtype=np.float64) + a * dt - np.asarray(lead_speed_next, dtype=np.float64)
    r, _, _ = reward(ev_next, a, last_output, dt=dt, **weights)
    return r
