r"""The sampled link with a reaction delay θ_r: the exact per-step model with held-input states.

**The model** (issue 25 item 3; docs/sampled.md, §10).  Every vehicle of a homogeneous platoon
samples its radar and computes its command every H seconds (zero-order hold, lag τ; IDL eqs
3-9), and applies the command computed at step k a reaction delay θ_r later.  With
θ_r = (q + f)H, q = ⌊θ_r/H⌋ and 0 ≤ f < 1 (the split of :func:`stringstab.certify.zoh.split_delay`,
with its floating tolerance), the input applied over [kH, (k + 1)H) is

.. math::
    w(t) = u_{k-q-1}\ \text{on}\ [kH,\ kH + fH),\qquad
    w(t) = u_{k-q}\ \text{on}\ [kH + fH,\ (k + 1)H),

so a step is two held pieces of lengths fH and (1 − f)H (one piece, length H, when f = 0).
The predecessor has the same θ_r (a homogeneous platoon, as in the sampled loop without it;
its lag may differ, τ_p).  A held piece of length t maps y = [Δp, Δv, a_i, a_{i−1}] as

.. math::
    \Delta p^+ = \Delta p + t\Delta v - (τ^2ψ_2 + T^*τφ_1)a_i + τ_p^2ψ_{2p} a_{i-1}
                 - (τ^2ψ_3 + T^*τψ_2) w_i + τ_p^2ψ_{3p} w_{i-1},

    \Delta v^+ = \Delta v - τφ_1 a_i + τ_pφ_{1p} a_{i-1} - τψ_2 w_i + τ_pψ_{2p} w_{i-1},\qquad
    a_i^+ = e^{-t/τ} a_i + φ_1 w_i,\qquad a_{i-1}^+ = e^{-t/τ_p} a_{i-1} + φ_{1p} w_{i-1},

with φ1, ψ2, ψ3 of :func:`stringstab.certify.zoh.phi` at t/τ (and t/τ_p for the ``p`` ones):
the closed forms of :func:`stringstab.certify.lifting.step_model` with H replaced by t.  The
step is the composition of the two pieces — exact, no Padé or Taylor.  The command is
u_{i,k} = k_x Δp(kH) + k_v Δv(kH) + k_a a_{i−1}(kH − δ), and a_{i−1}(kH − δ) is exact for
any δ = (m + ε)H: it is the predecessor's acceleration (1 − ε)H into step k − m − 1, in the
first or the second piece.

**The state** is y, the L = q + [f > 0] last commands of the follower r_j = u_{i,k−j} and of the
predecessor s_j = u_{i−1,k−j} (j = 1 … L: the held-input states), and the buffer of delayed
samples of :func:`stringstab.certify.lifting.message_buffer`; the link u_{i−1} → u_i is lifted
over N steps exactly as :func:`stringstab.certify.lifting.lift` does (N = 1: the sampled loop).
θ_r = 0 is never built here (the sampled certificate answers it).

**Internal stability.**  In the order (a_{i−1}, s, buffer, [Δp, Δv, a_i, r]) the state matrix
is block triangular: the predecessor's acceleration (e^{−H/τ_p}), its delay line and the
buffer (shifts: nilpotent) evolve alone, so A is Schur iff the follower's block (3 + L
states) is; :func:`follower_block` returns it (checked to be exactly decoupled).

Every matrix is a :class:`~stringstab.certify.ball.Ball` (relative error
:data:`~stringstab.certify.verdicts.ROUNDOFF_SLACK` on the closed forms, products with their
own round-off), so :mod:`stringstab.certify.lifted_frequency` bounds |G(e^{jθ})| soundly.

References
----------
T. Chen, B. Francis, *Optimal Sampled-Data Control Systems*, Springer (1995), §3.4
(fractional delays in discretisation) and ch. 8 (lifting).  IDL paper, eqs 3-9 and eq 4.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..params import Params
from .ball import Ball
from .lifting import LiftedLink, message_buffer
from .verdicts import ROUNDOFF_SLACK
from .zoh import phi, split_delay

__all__ = ["MAX_HELD_STEPS", "check_reaction_sampled", "follower_block", "held_piece", "held_steps", "lift_reaction"]

Array = npt.NDArray[np.float64]

#: The largest q = ⌊θ_r/H⌋ built (each whole step adds two states; beyond it the lifted
#: state is too large to certify in reasonable time and memory).
MAX_HELD_STEPS = 2000


def held_steps(theta_r: float, H: float) -> tuple[int, float, int]:
    """(q, f, L): θ_r = (q + f)H by :func:`stringstab.certify.zoh.split_delay`, and L = q + [f > 0].

    Parameters
    ----------
    theta_r, H : float
        The reaction delay θ_r ≥ 0 and the sample time H > 0, s.

    Returns
    -------
    (int, float, int)
        q, f and the number L of held-input states per vehicle.

    Examples
    --------
    >>> held_steps(0.3, 0.1), held_steps(0.05, 0.1), held_steps(0.25, 0.1)[0::2]
    ((3, 0.0, 3), (0, 0.5, 1), (2, 3))
    """
    q, f = split_delay(theta_r, H)
    return q, f, q + (1 if f > 0.0 else 0)


def check_reaction_sampled(theta_r: float, H: float) -> None:
    """Refuse, in one line, a sampled loop with θ_r > 0 too long to build.

    Parameters
    ----------
    theta_r, H : float
        θ_r > 0 and H > 0, s (each checked already).  A message period is lifted as well
        (:func:`lift_reaction` with N ≥ 2; docs/sampled.md §10.5).

    Raises
    ------
    StringStabError
        With q = ⌊θ_r/H⌋ > :data:`MAX_HELD_STEPS`.

    Examples
    --------
    >>> check_reaction_sampled(0.3, 0.1)
    >>> check_reaction_sampled(30.0, 0.001)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: reaction_delay / sample_time must be at most 2000 whole samples (each adds two held-input states to the sampled loop); got reaction_delay=30 with sample_time=0.001: 30000 samples
    """
    q, _, _ = held_steps(theta_r, H)
    if q > MAX_HELD_STEPS:
        raise StringStabError(
            f"reaction_delay / sample_time must be at most {MAX_HELD_STEPS} whole samples (each "
            "adds two held-input states to the sampled loop); got "
            f"reaction_delay={theta_r:g} with sample_time={H!r}: {q} samples")


def held_piece(t: float, tau: float, tau_p: float, headway: float) -> tuple[Ball, Ball, Ball]:
    """One held piece of length t: y⁺ = Φ y + Γ_u w_i + Γ_p w_{i−1} (module docstring).

    Parameters
    ----------
    t : float
        The piece's length, s (> 0).
    tau, tau_p : float
        The follower's and the predecessor's lags, s.
    headway : float
        T*, s.

    Returns
    -------
    (Ball, Ball, Ball)
        Φ (4 × 4), Γ_u and Γ_p (4 × 1), each entry within
        :data:`~stringstab.certify.verdicts.ROUNDOFF_SLACK` of its magnitude companion.

    Examples
    --------
    >>> Phi, Gu, Gp = held_piece(0.1, 0.1, 0.1, 1.0)
    >>> bool(np.all(Phi.rad >= 0)), Gu.mid.shape
    (True, (4, 1))
    """
    f1, p2, p3 = (float(v) for v in phi(t / tau))
    g1, q2, q3 = (float(v) for v in phi(t / tau_p))
    T, t2, tp2 = headway, tau * tau, tau_p * tau_p
    Phi = np.array([[1.0, t, -(t2 * p2 + T * tau * f1), tp2 * q2],
                    [0.0, 1.0, -tau * f1, tau_p * g1],
                    [0.0, 0.0, math.exp(-t / tau), 0.0],
                    [0.0, 0.0, 0.0, math.exp(-t / tau_p)]])
    mag = np.abs(Phi)
    mag[0, 2] = t2 * p2 + T * tau * f1
    Gu = np.array([[-(t2 * p3 + T * tau * p2)], [-tau * p2], [f1], [0.0]])
    gmag = np.abs(Gu)
    gmag[0, 0] = t2 * p3 + T * tau * p2
    Gp = np.array([[tp2 * q3], [tau_p * q2], [0.0], [g1]])
    return (Ball.relative(Phi, mag, ROUNDOFF_SLACK), Ball.relative(Gu, gmag, ROUNDOFF_SLACK),
            Ball.relative(Gp, Gp, ROUNDOFF_SLACK))


def _stack(n: int, b: Ball) -> Ball:
    """One ball broadcast to n rows (a copy: the rows are written by products only)."""
    return Ball(np.broadcast_to(b.mid, (n, *b.mid.shape)), np.broadcast_to(b.rad, (n, *b.rad.shape)))


def _rows(parts: list[Ball]) -> Ball:
    """Rows stacked (axis 1)."""
    return Ball(np.concatenate([r.mid for r in parts], axis=1),
                np.concatenate([r.rad for r in parts], axis=1))


def _unit(n: int, cols: int, j: int) -> Ball:
    """An exact (n, 1, cols) row selecting column j."""
    e = np.zeros((n, 1, cols))
    e[:, 0, j] = 1.0
    return Ball.exact(e)


def _sample_row(s: float, fH: float, tau_p: float) -> Ball:
    """The exact row c with a_{i−1}(s into a step) = c · [a_{i−1}, w⁰_{i−1}, w¹_{i−1}].

    The first piece lasts fH (0 when f = 0), the second the rest of the step; s ∈ (0, H].
    """
    if s <= fH:  # in the first piece
        c = np.array([[math.exp(-s / tau_p), float(phi(s / tau_p)[0]), 0.0]])
        return Ball.relative(c, c, ROUNDOFF_SLACK)
    m1 = np.array([[math.exp(-fH / tau_p), float(phi(fH / tau_p)[0]), 0.0],
                   [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    e1 = Ball.relative(m1, m1, ROUNDOFF_SLACK)  # (the exact 0/1 entries get a harmless radius)
    r = s - fH
    e2 = np.array([[math.exp(-r / tau_p), 0.0, float(phi(r / tau_p)[0])]])
    return Ball.relative(e2, e2, ROUNDOFF_SLACK) @ e1


def lift_reaction(kx: Array, kv: Array, ka: Array, p: Params, H: float, N: int,
                  tau_p: float | None = None) -> LiftedLink:
    """The link u_{i−1} → u_i with θ_r = ``p.reaction_delay`` > 0, lifted over N steps.

    Parameters
    ----------
    kx, kv, ka : ndarray
        The gains, one triple per row.
    p : Params
        τ, δ, T*, θ_r (θ_r > 0).
    H : float
        The control and radar period, s.
    N : int
        Steps per message period (1: the sampled loop).
    tau_p : float, optional
        The predecessor's lag (default τ).

    Returns
    -------
    LiftedLink
        State [Δp, Δv, a_i, a_{i−1}, r_1 … r_L, s_1 … s_L, b_0 … b_{J−1}].

    Examples
    --------
    >>> from stringstab.params import Params
    >>> L = lift_reaction(np.array([1.2]), np.array([0.5]), np.array([0.6]),
    ...                   Params(0.1, 0.2, 1.1, reaction_delay=0.15), 0.1, 1)
    >>> L.order  # 4 + 2·2 held inputs + 3 delayed samples
    11
    """
    n = kx.size
    tp = p.tau if tau_p is None else float(tau_p)
    m, eps = split_delay(p.delta, H)
    q, f, L = held_steps(p.reaction_delay, H)
    J, lstar = message_buffer(m, N)
    r0, s0, b0i = 4, 4 + L, 4 + 2 * L
    nx = b0i + J
    cols = nx + N
    fH = f * H
    pieces = ([held_piece(fH, p.tau, tp, p.headway)] if f > 0.0 else []) \
        + [held_piece(H - fH, p.tau, tp, p.headway)]
    pieces_n = [tuple(_stack(n, b) for b in pc) for pc in pieces]
    crow = _stack(n, _sample_row((1.0 - eps) * H, fH, tp))
    K = np.zeros((n, 1, 4))
    K[:, 0, 0], K[:, 0, 1] = kx, kv
    Kb = Ball.exact(K)
    eye = np.zeros((n, 4, cols))
    eye[:, :, :4] = np.eye(4)
    Y = Ball.exact(eye)
    R = [_unit(n, cols, r0 + j) for j in range(L)]  # R[j] = r_{j+1}
    S = [_unit(n, cols, s0 + j) for j in range(L)]
    kab = _unit(n, cols, b0i).scale(ka[:, None, None])
    rows_out = []
    store: Ball | None = None
    for l_ in range(N):
        u_p = _unit(n, cols, nx + l_)
        u_i = Kb @ Y + kab
        rows_out.append(u_i)
        # the applied inputs: (first piece, second piece) of the follower and the predecessor
        wi = ([R[L - 1]] if f > 0.0 else []) + [R[q - 1] if q >= 1 else u_i]
        wp = ([S[L - 1]] if f > 0.0 else []) + [S[q - 1] if q >= 1 else u_p]
        if l_ == lstar:
            w0 = wp[0] if f > 0.0 else Ball.exact(np.zeros((n, 1, cols)))
            store = crow @ _rows([Y[:, 3:4], w0, wp[-1]])
        for (Phi, Gu, Gp), a, b in zip(pieces_n, wi, wp):
            Y = Phi @ Y + Gu @ a + Gp @ b
        R = [u_i, *R[:-1]] if L else R
        S = [u_p, *S[:-1]] if L else S
    assert store is not None
    out = _rows(rows_out)
    shift = [_unit(n, cols, b0i + i + 1) for i in range(J - 1)]
    AB = _rows([Y, *R, *S, *shift, store])
    return LiftedLink(AB[:, :, :nx], AB[:, :, nx:], out[:, :, :nx], out[:, :, nx:], N, m)


def follower_block(link: LiftedLink, L: int) -> Ball:
    """The follower's block of the state matrix: rows and columns [Δp, Δv, a_i, r_1 … r_L].

    A is Schur iff this block is (module docstring), provided the other states do not
    depend on the follower's; that is checked here on the computed balls (exact zeros).

    Parameters
    ----------
    link : LiftedLink
        From :func:`lift_reaction`.
    L : int
        The held-input states per vehicle.

    Returns
    -------
    Ball, shape (n, 3 + L, 3 + L)

    Raises
    ------
    AssertionError
        If the predecessor's states depend on the follower's (a construction error).
    """
    f = np.r_[0:3, 4:4 + L]
    o = np.setdiff1d(np.arange(link.order), f)
    A = link.A
    cross = np.abs(A.mid[:, o][:, :, f]) + A.rad[:, o][:, :, f]
    assert not cross.any(), "the predecessor's states depend on the follower's"
    return Ball(A.mid[:, f][:, :, f], A.rad[:, f][:, :, f])
