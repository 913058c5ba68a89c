"""One follower driven by its measured predecessor: the closed loop as a linear filter.

The follower obeys the toolkit's vehicle model (IDL eqs 5-7, lag τ) under the eq-4 law,
u = k_x (s − T* v − l_0) + k_v (v_p − v) + k_a a_p(t − δ), with the command held over each step
(zero-order hold) and the lag integrated exactly, as :class:`stringstab.traffic.Platoon` does
(``model="lag"``): with e = exp(−Δt/τ), c_1 = τ(1 − e), c_2 = τ(Δt − c_1),

    a_{k+1} = e a_k + (1 − e) u_k,
    v_{k+1} = v_k + c_1 a_k + (Δt − c_1) u_k,
    s_{k+1} = s_k + d_k − (Δt v_k + c_2 a_k + (Δt²/2 − c_2) u_k),

where d_k is the predecessor's measured displacement over the step (the trapezoid of its speed,
exact for piecewise-constant acceleration) and a_p(t − δ) is read like the simulator's default
``fractional_delay="linear"``.  A lag τ = 0 (the lag-free loop of the OVRV baseline) is the
limit e = c_1 = c_2 = 0: the command is the acceleration, held over the step.

**A reaction delay θ_r on the whole law** (issue 25: τ a' = u(t − θ_r) − a) is discretised
exactly as well: with θ_r = qΔt + ε (0 ≤ ε < Δt) the applied command over [t_k, t_k + ε) is
u_{k−q−1} and over [t_k + ε, t_{k+1}) it is u_{k−q}, so

    x_{k+1} = A(Δt) x_k + A(Δt − ε) b(ε) u_{k−q−1} + b(Δt − ε) u_{k−q} + e_1 d_k,

with A(h), b(h) the step above over a duration h; commands before t_0 are the initial
acceleration a_0 (the car was holding it).  The loop is then of order q + 4; it is computed in
two filter passes: the commands u_k = K x_k + w_k through the closed loop's characteristic
polynomial D(z) = z^{q+1} det(zI − A) − K adj(zI − A)(z Γ_0 + Γ_1), then the states through
the open-loop lag and integrators.  ``tests/identify/test_identify_delay.py`` checks it against a direct
time-stepping of the model (matrix exponentials over each sub-step).  Without the simulator's limits this is a linear time-invariant
system x_{k+1} = F x_k + b w_k + e_1 d_k in the state x = (s, v, a), with
w_k = k_v v_{p,k} − k_x l_0 + k_a a_p(t_k − δ); its response is computed with
:func:`scipy.signal.lfilter` (compiled) instead of a Python loop over samples, which makes it
cheap enough for the inner loop of a least-squares fit.  ``tests/identify/test_identify.py`` checks it
against :func:`stringstab.traffic.simulate` on the same predecessor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

__all__ = ["FollowerModel", "delayed", "lag_step", "simulate_follower"]

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class FollowerModel:
    """The eq-4 law and the follower's lag: the parameters the fit estimates.

    Attributes
    ----------
    k_x, k_v, k_a : float
        Gains (IDL eq 4).
    tau : float
        Actuator lag τ, s (eq 7).
    delta : float
        Delay on the predecessor's acceleration δ, s (eq 4).
    headway, standstill : float
        T* (s) and l_0 (m) of the spacing policy (eq 3).
    reaction_delay : float
        θ_r (s), the pure delay on the whole law (issue 25); 0 by default.
    """

    k_x: float
    k_v: float
    k_a: float
    tau: float
    delta: float
    headway: float
    standstill: float
    reaction_delay: float = 0.0


def delayed(a: Array, delta: float, dt: float) -> Array:
    """a(t_k − δ), linearly interpolated between samples, history before t_0 held at a_0.

    The simulator's default reading of a delay that is not a multiple of Δt
    (:class:`stringstab.traffic.Platoon`, ``fractional_delay="linear"``).

    Parameters
    ----------
    a : ndarray
        Signal sampled every ``dt`` from t_0 (here an acceleration, m/s²).
    delta : float
        Delay δ (s), ≥ 0; need not be a multiple of ``dt``.
    dt : float
        Sample time Δt (s), > 0.

    Returns
    -------
    ndarray
        The delayed signal, same length as ``a``.
    """
    q = delta / dt
    n = math.floor(q + 1e-9)
    f = q - n
    if f < 1e-9:
        f = 0.0
    k = np.arange(a.size)
    i0 = np.clip(k - n, 0, None)
    i1 = np.clip(k - n - 1, 0, None)
    return np.asarray((1.0 - f) * a[i0] + f * a[i1])


def lag_step(tau: float, h: float) -> tuple[Array, Array]:
    """One step of the follower's lag and kinematics over a duration h, command held.

    x = (s, v, a): the gap loses the follower's own displacement, v' = a, τ a' = u − a.

    Parameters
    ----------
    tau : float
        Lag τ (s), ≥ 0 (0: the command is the acceleration).
    h : float
        Duration (s), ≥ 0.

    Returns
    -------
    A : ndarray (3, 3)
        The free motion x(t + h) = A x(t) (with u = 0).
    b : ndarray (3,)
        The response to a command u held over the step.
    """
    if tau > 0:
        e = math.exp(-h / tau)
        c1 = tau * (1.0 - e)
        c2 = tau * (h - c1)
    else:
        e = c1 = c2 = 0.0
    A = np.array([[1.0, -h, -c2], [0.0, 1.0, c1], [0.0, 0.0, e]])
    b = np.array([-(0.5 * h * h - c2), h - c1, 1.0 - e])
    return A, b


def _charpoly(M: Array) -> Array:
    """det(zI − M) of a 3×3 matrix: [1, −tr M, Σ principal 2×2 minors, −det M]."""
    m = M.tolist()
    (a, b, c), (d, e, f), (g, h, i) = m
    minors = (a * e - b * d) + (a * i - c * g) + (e * i - f * h)
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    return np.array([1.0, -(a + e + i), minors, -det])


def _numerators(F: Array, B: Array) -> Array:
    """Numerators (s and v rows) over det(zI − F) of x_{k+1} = F x_k + B u_k, y = (x[0], x[1]).

    By the SISO identity C adj(zI − F) B = det(zI − F + B C) − det(zI − F) (as in
    :func:`scipy.signal.ss2tf`, without its checks).
    """
    den = _charpoly(F)
    out = np.empty((2, den.size))
    for r in range(2):
        c = np.zeros(3)
        c[r] = 1.0
        out[r] = _charpoly(F - np.outer(B, c)) - den
    return out


def simulate_follower(m: FollowerModel, v_pred: Array, dt: float, *, s0: float, v0: float,
                      a0: float = 0.0, a_pred: Array | None = None,
                      x_pred: Array | None = None) -> tuple[Array, Array]:
    """Gap and speed of a follower behind a measured predecessor (module docstring).

    Parameters
    ----------
    m : FollowerModel
        The law and the lag.
    v_pred : array (T,)
        Predecessor's speed at t_k, m/s.
    dt : float
        Step, s.
    s0, v0, a0 : float
        Follower's gap (m), speed (m/s) and acceleration (m/s²) at t_0.
    a_pred : array (T,), optional
        Predecessor's acceleration (needed when k_a ≠ 0).
    x_pred : array (T,), optional
        Predecessor's position; its differences replace the trapezoid of ``v_pred``.

    Returns
    -------
    gap, speed : array (T,)
        Simulated at t_k (non-finite values of a diverging loop are kept).
    """
    T = v_pred.size
    A0, b = lag_step(m.tau, dt)
    K = np.array([m.k_x, -(m.k_x * m.headway + m.k_v), 0.0])
    w = m.k_v * v_pred - m.k_x * m.standstill
    if m.k_a != 0.0:
        if a_pred is None:
            raise ValueError("k_a != 0 needs the predecessor's acceleration")
        w = w + m.k_a * delayed(a_pred, m.delta, dt)
    d = np.empty(T)
    d[:-1] = np.diff(x_pred) if x_pred is not None else 0.5 * dt * (v_pred[1:] + v_pred[:-1])
    d[-1] = 0.0
    if m.reaction_delay > 0:
        return _delayed_loop(m, A0, K, w, d, dt, np.array([s0, v0, a0]))
    F = A0 + np.outer(b, K)
    from scipy.signal import lfilter

    den = _charpoly(F)
    # y = Σ_inputs num_i(z)/den(z) u_i: each numerator's FIR part per input, then one all-pole
    # pass over both outputs (one lfilter call instead of one per input and output)
    with np.errstate(all="ignore"):
        z = np.zeros((2, T))
        for B, u in ((b, w), (np.array([1.0, 0.0, 0.0]), d)):
            nums = _numerators(F, B)
            for r in range(2):
                z[r] += np.convolve(nums[r], u)[:T]
        # the free response C F^k x0 is the impulse response of (F, x0, C) one step later
        nums = _numerators(F, np.array([s0, v0, a0]))
        n0 = min(T, nums.shape[1] - 1)
        z[:, :n0] += nums[:, 1:n0 + 1]
        y = lfilter([1.0], den, z, axis=1)
    return y[0], y[1]


def _charpolys(M: Array) -> Array:
    """det(zI − M) of a stack of 3×3 matrices (N, 3, 3): rows [1, −tr M, Σ 2×2 minors, −det M]."""
    a, b, c = M[:, 0, 0], M[:, 0, 1], M[:, 0, 2]
    d, e, f = M[:, 1, 0], M[:, 1, 1], M[:, 1, 2]
    g, h, i = M[:, 2, 0], M[:, 2, 1], M[:, 2, 2]
    minors = (a * e - b * d) + (a * i - c * g) + (e * i - f * h)
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    return np.stack([np.ones_like(a), -(a + e + i), minors, -det], axis=1)


def _delayed_loop(m: FollowerModel, A0: Array, K: Array, w: Array, d: Array, dt: float,
                  x0: Array) -> tuple[Array, Array]:
    """Gap and speed with a reaction delay θ_r > 0 on the whole law (module docstring).

    The sequences run from index −1 (zero state; the initial state enters there as an impulse
    x0, so x_0 = x0) to T − 1; commands before t_0 are a_0.  With G(z) = z^{−q−1}(z Γ_0 + Γ_1),
    the state obeys M(z) x = f + G w with M(z) = zI − A − G K, so each output is one closed-loop
    filter over D(z) = z^{q+1} det M(z): its numerators are c adj(M) b = det(M + b c) − det(M)
    (linear in b: three per output, for the unit vectors), and each determinant comes from 3×3
    characteristic polynomials, det(zI − A − G K) = det(zI − A) − K adj(zI − A) G.
    """
    from scipy.signal import lfilter

    T = w.size
    q = math.floor(m.reaction_delay / dt + 1e-9)
    eps = m.reaction_delay - q * dt
    if eps < 1e-9 * dt:
        eps = 0.0
    A_late, G0 = lag_step(m.tau, dt - eps)  # G0 multiplies u_{k-q}
    _, b_early = lag_step(m.tau, eps)
    G1 = A_late @ b_early  # multiplies u_{k-q-1}
    # the matrices X whose z^{q+1} det(zI − X − G K) are needed: A, and A − e_j c_r (r: gap, speed)
    X = np.repeat(A0[None], 7, axis=0)
    X[np.arange(1, 7), [0, 1, 2, 0, 1, 2], [0, 0, 0, 1, 1, 1]] -= 1.0  # A − e_j c_r, r-major
    ph = _charpolys(np.concatenate([X, X - np.outer(G0, K), X - np.outer(G1, K)]))
    nX = X.shape[0]
    zd = np.zeros((nX, q + 5))
    zd[:, :4] = ph[:nX]
    zd[:, -5:-1] -= ph[nX:2 * nX] - ph[:nX]  # z K adj(zI − X) Γ_0
    zd[:, -4:] -= ph[2 * nX:] - ph[:nX]  # K adj(zI − X) Γ_1
    D = zd[0]
    N = (zd[1:] - D).reshape(2, 3, q + 5)  # N[r, j]: numerator of input e_j to output r
    n = T + 1
    z = np.zeros((2, n))
    h0 = np.zeros(q + 2)  # the commands before t_0 (= a_0) as forcing: h0 on k < q, h1 on k < q + 1
    h0[1:1 + q] = x0[2]
    h1 = np.zeros(q + 2)
    h1[1:2 + q] = x0[2]
    nG0 = np.einsum("j,rjk->rk", G0, N)  # (2, q + 5): the numerators of the inputs Γ_0, Γ_1
    nG1 = np.einsum("j,rjk->rk", G1, N)
    head = np.zeros((2, 2 * q + 6))
    head[:, :q + 5] = np.einsum("j,rjk->rk", x0, N)  # the initial state, an impulse at index 0
    nw = np.zeros((2, 2 * q + 6))
    nw[:, q + 1:-1] += nG0[:, 1:]  # z num(Γ_0), delayed q + 1
    nw[:, q + 1:] += nG1
    k = min(2 * q + 6, n)
    with np.errstate(all="ignore"):
        for r in range(2):
            head[r] += np.convolve(nG0[r], h0) + np.convolve(nG1[r], h1)
            z[r, 1:] += np.convolve(N[r, 0], d)[:T]  # the predecessor's displacement (gap row)
            z[r, 1:] += np.convolve(nw[r], w)[:T]
        z[:, :k] += head[:, :k]
        y = lfilter([1.0], D, z, axis=1)
    return y[0, 1:], y[1, 1:]
