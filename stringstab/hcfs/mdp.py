"""The HCFS Markov decision process: the V2V-delayed measurements, the state (eq 3), the reward (eqs 4-6).

Positions ``x`` are front-bumper positions along the road (the leader is ahead, so
x_{k−1} > x_k for follower k behind vehicle k − 1), in m; speeds in m/s; accelerations in m/s².
Vehicle 0 is the leader, vehicles 1..N the followers.

State (eq 3)
    s = [e_x(k, k−1), e_v(k, k−1), e_x(k, 0), e_v(k, 0), v_k, a_k] with

        e_x(k, k−1) = x_k − x̃_{k−1} + (L + h),     e_v(k, k−1) = v_k − ṽ_{k−1},
        e_x(k, 0)   = x_k − x̃_0 + k (L + h),         e_v(k, 0)   = v_k − ṽ_0,

    where x̃, ṽ are what arrives over V2V (:func:`received`).  Both deviations are ego minus
    predecessor (eq 2 prints e_v = v_k − v_{k−1}), so e_x is the negative spacing error: it is
    0 at the desired spacing L + h and > 0 when too close.  *Printed:* eq 1 reads
    e_x = x_k − x_{k−1} − (L + h), which never vanishes (x_k − x_{k−1} < 0 for a follower): the
    sign of (L + h) is a misprint, and e_x must be the deviation whose derivative is eq 2's e_v.
    a_k is the acceleration the vehicle drove with over the frame that just ended (the previous
    frame's command, unless a speed bound cut it): the action of this frame is not known yet.

V2V delay (§IV, 5 ms)
    The paper writes x_{k+1} = x_k + v_k T + ½a_k T² + η "where η is the position deviation
    caused by time delay".  Adding η to the true position would make positions drift away from
    the integrated speeds by η every frame (≈ −0.1 m per frame at 20 m/s, 10 m after 20 s), so
    here η is modelled where the delay acts: on the *measurements*.  Positions and speeds of the
    predecessor and the leader arrive δ late, and since accelerations are held over each frame
    the values at t − δ follow exactly from the last frame's acceleration a⁻ (:func:`received`):
    x̃ = x − v δ + ½ a⁻ δ², ṽ = v − a⁻ δ.  The position error η = x̃ − x ≈ −v δ is then the
    paper's "position deviation caused by time delay".

Reward (eqs 4-6)
    r = −ω1 |e_v(k, 0)| / v_max − ω2 |jerk| / (2 a_max / T),  jerk = (a_k − a_{k−1}) / T,
    evaluated at the state the action leads to (r_k(s_{k+1} | a_k, s_k), §II-A).

References
----------
HCFS paper, §II eqs 1-6 and §IV.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from .constants import ACCEL_MAX, DT, LENGTH, OMEGA_1, OMEGA_2, SPACING, SPEED_MAX

__all__ = ["STATE_NAMES", "STATE_SCALES", "received", "reward", "state"]

Array = npt.NDArray[np.float64]

#: Names of the eq-3 state components, in order.
STATE_NAMES = ("e_x_pred", "e_v_pred", "e_x_lead", "e_v_lead", "speed", "accel")
#: Scales dividing the eq-3 state before it enters a neural network (m, m/s, m, m/s, m/s, m/s²).
STATE_SCALES = (10.0, 5.0, 20.0, 5.0, SPEED_MAX, ACCEL_MAX)


def received(position: npt.ArrayLike, speed: npt.ArrayLike, last_accel: npt.ArrayLike,
             delay: float) -> tuple[Array, Array]:
    """Position and speed as received over V2V ``delay`` seconds late (HCFS §IV).

    With the acceleration ``last_accel`` held over the frame that just ended, the state at
    t − δ (0 ≤ δ ≤ T) is exactly x − v δ + ½ a δ² and v − a δ.

    Parameters
    ----------
    position, speed : array_like
        Current positions (m) and speeds (m/s).
    last_accel : array_like
        Acceleration held over the frame that ended now, m/s².
    delay : float
        δ, s (5 ms in the paper).

    Returns
    -------
    (x̃, ṽ) : arrays

    Examples
    --------
    >>> x, v = received(100.0, 20.0, 1.0, 0.005)
    >>> float(x), float(v)
    (99.9000125, 19.995)
    """
    d = float(delay)
    a = np.asarray(last_accel, dtype=np.float64)
    v = np.asarray(speed, dtype=np.float64)
    return (np.asarray(position, dtype=np.float64) - v * d + 0.5 * a * d * d,
            np.asarray(v - a * d, dtype=np.float64))


def state(position: npt.ArrayLike, speed: npt.ArrayLike, last_accel: npt.ArrayLike, *,
          delay: float, length: float = LENGTH, spacing: float = SPACING) -> Array:
    """The eq-3 state of every follower of a batch of platoons.

    Parameters
    ----------
    position, speed : array (..., N + 1)
        Current positions (m) and speeds (m/s); column 0 is the leader.
    last_accel : array (..., N + 1)
        Accelerations held over the frame that just ended (the leader's, then the followers'
        previous commands), m/s².
    delay : float
        V2V delay δ, s: predecessor and leader data are those of t − δ (:func:`received`).
    length, spacing : float
        Vehicle length L and safe space headway h, m (desired spacing L + h, eq 1).

    Returns
    -------
    array (..., N, 6)
        [e_x(k,k−1), e_v(k,k−1), e_x(k,0), e_v(k,0), v_k, a_k] per follower (see the module
        docstring for the signs).

    References
    ----------
    HCFS paper, eqs 1-3.

    Examples
    --------
    >>> s = state([30.0, 20.0, 10.0], [10.0, 10.0, 10.0], [0.0, 0.0, 0.0], delay=0.0)
    >>> s.tolist()
    [[0.0, 0.0, 0.0, 0.0, 10.0, 0.0], [0.0, 0.0, 0.0, 0.0, 10.0, 0.0]]
    """
    x = np.asarray(position, dtype=np.float64)
    v = np.asarray(speed, dtype=np.float64)
    a = np.asarray(last_accel, dtype=np.float64)
    if x.shape != v.shape or x.shape != a.shape or x.ndim < 1 or x.shape[-1] < 2:
        raise StringStabError(
            "position, speed and last_accel must share a shape (..., N + 1) with N >= 1; got "
            f"{x.shape}, {v.shape}, {a.shape}"
        )
    xr, vr = received(x, v, a, delay)
    gap = float(length) + float(spacing)
    n = x.shape[-1] - 1
    ego_x, ego_v = x[..., 1:], v[..., 1:]
    out = np.empty((*ego_x.shape, 6))
    out[..., 0] = ego_x - xr[..., :-1] + gap
    out[..., 1] = ego_v - vr[..., :-1]
    out[..., 2] = ego_x - xr[..., :1] + gap * np.arange(1, n + 1)
    out[..., 3] = ego_v - vr[..., :1]
    out[..., 4] = ego_v
    out[..., 5] = a[..., 1:]
    return out


def reward(lead_speed_error: npt.ArrayLike, accel: npt.ArrayLike, last_accel: npt.ArrayLike, *,
           omega_1: float = OMEGA_1, omega_2: float = OMEGA_2, speed_max: float = SPEED_MAX,
           accel_max: float = ACCEL_MAX, dt: float = DT) -> tuple[Array, Array, Array]:
    """The HCFS reward r = r_v + r_jerk (eqs 4-6).

    Parameters
    ----------
    lead_speed_error : array_like
        e_v(k, 0) = v_k − v_0 at the state the action leads to, m/s.
    accel, last_accel : array_like
        The action a_k and the previous frame's a_{k−1}, m/s².
    omega_1, omega_2, speed_max, accel_max, dt : float
        ω1, ω2, v_max, a_max and T.

    Returns
    -------
    (r, r_v, r_jerk) : arrays
        r_v = −ω1 |e_v(k,0)| / v_max (eq 4), r_jerk = −ω2 |(a_k − a_{k−1})/T| / (2 a_max/T)
        (eq 5), r = r_v + r_jerk (eq 6).

    References
    ----------
    HCFS paper, eqs 4-6.

    Examples
    --------
    >>> r, r_v, r_j = reward(0.0, 3.0, -3.0, omega_1=1.0, omega_2=1.0)
    >>> float(r_v), float(r_j)
    (-0.0, -1.0)
    """
    ev = np.asarray(lead_speed_error, dtype=np.float64)
    jerk = (np.asarray(accel, dtype=np.float64) - np.asarray(last_accel, dtype=np.float64)) / dt
    r_v = -omega_1 * np.abs(ev) / speed_max
    r_j = -omega_2 * np.abs(jerk) / (2.0 * accel_max / dt)
    return np.asarray(r_v + r_j), np.asarray(r_v), np.asarray(r_j)
