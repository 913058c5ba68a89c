r"""The multi-rate V2V link lifted over one message period: an LTI system with N inputs and outputs.

**The model** (docs/sampled.md, §9).  Every vehicle of a homogeneous platoon samples its radar
and applies its command every H seconds (zero-order hold, actuator lag τ; IDL eqs 3-9).  The
predecessor's acceleration arrives by message at the follower's steps k ≡ φ (mod N): the
message used at step k carries a_{i−1}(kH − δ), the predecessor's acceleration δ = (m + ε)H
seconds earlier (exact, for any real δ ≥ 0, as in :mod:`stringstab.certify.zoh`), and it is
held until the next message, N steps later:

    u_k = k_x Δp(kH) + k_v Δv(kH) + k_a h_k,   h_k = a_{i−1}(k_j H − δ),  k_j = the last
    message step ≤ k.

The link from the predecessor's command sequence u_{i−1} to the follower's u_i is N-periodic.
Lifting it over one message period (Bamieh & Pearson 1992; Chen & Francis 1995, ch. 8) —
U_j = [u_{i−1, jN}, …, u_{i−1, jN+N−1}], Y_j = [u_{i, jN}, …] — gives an LTI system
G(z) = C(zI − A)^{−1}B + D with N inputs and N outputs, built here exactly (phase φ = 0; the
phase does not change the ℓ2-induced norm, docs §9).

**The per-step model.**  y = [Δp, Δv, a_i, a_{i−1}] with held u_i, u_{i−1} over a step
(x = H/τ, E = e^{−x}, φ1, ψ2, ψ3 of :func:`stringstab.certify.zoh.phi`; τ_{i−1} = τ):

    Δp⁺ = Δp + HΔv − (τ²ψ2 + T*τφ1) a_i + τ²ψ2 a_{i−1} − (τ²ψ3 + T*τψ2) u_i + τ²ψ3 u_{i−1}
    Δv⁺ = Δv − τφ1 a_i + τφ1 a_{i−1} − τψ2 u_i + τψ2 u_{i−1}
    a_i⁺ = E a_i + φ1 u_i,   a_{i−1}⁺ = E a_{i−1} + φ1 u_{i−1}

(the integrals of the lag over a held step: ∫a = τ(ψ2 u + φ1 a), ∫∫a = τ²(ψ3 u + ψ2 a)).  The
delayed sample: kH − δ = (k − m − 1)H + (1 − ε)H, so a_{i−1}(kH − δ) = q_{k−m−1} with
q_k = C a_{i−1,k} + (1 − C) u_{i−1,k}, C = e^{−(1−ε)x}, 1 − C = φ1((1 − ε)x).

**The lifted state** at the start of a block (a message step, k = jN): y and the J = ⌊m/N⌋ + 1
values q_{jN−m−1+iN}, i = 0 … J − 1, still to be used by a message (b_0 is the one held in
this block; the other delayed samples are never used and are left out, exactly).  Over the
block y_{l+1} = A_c y_l + g b_0 + Γ_p u_{i−1,l} with A_c = Φ + Γ_u [k_x, k_v, 0, 0],
g = k_a Γ_u; the output is u_{i,l} = [k_x, k_v, 0, 0] y_l + k_a b_0; after the block the
buffer shifts (b_i ← b_{i+1}) and b_{J−1} ← q at step l* = JN − m − 1.

**Internal stability.**  In the order (a_{i−1}, buffer, [Δp, Δv, a_i]) the lifted A is block
triangular: a_{i−1} evolves alone (E^N), the buffer is a shift fed by a_{i−1} (nilpotent), and
the follower's block is A_f^N with A_f its 3 × 3 closed-loop matrix, whose characteristic
polynomial is Δ(z) of the sampled certificate.  So A is Schur iff Δ is, decided soundly by
:func:`stringstab.certify.schur.schur_bands` (tests check the spectrum).

Every matrix is a :class:`~stringstab.certify.ball.Ball`: the per-step entries carry the
relative error :data:`~stringstab.certify.verdicts.ROUNDOFF_SLACK` of their closed forms, and
the products propagate it with their own round-off.

References
----------
B. A. Bamieh, J. B. Pearson, "A general framework for linear periodic systems with
applications to H∞ sampled-data control", *IEEE TAC* 37 (1992) 418-435.  T. Chen,
B. Francis, *Optimal Sampled-Data Control Systems*, Springer (1995), ch. 8 (lifting, multirate).
IDL paper, eqs 3-9 (model) and eq 4 (law).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..params import Params
from .ball import Ball
from .verdicts import ROUNDOFF_SLACK
from .zoh import phi, split_delay

__all__ = ["LiftedLink", "lift", "lifted_response", "message_buffer", "step_model"]

Array = npt.NDArray[np.float64]


def message_buffer(m: int, N: int) -> tuple[int, int]:
    """(J, l*): the delayed samples the lifted state keeps, and the step that stores one.

    Parameters
    ----------
    m : int
        Whole samples of the delay δ = (m + ε)H.
    N : int
        Steps per message period.

    Returns
    -------
    (int, int)
        J = ⌊m/N⌋ + 1 buffered samples; l* = JN − m − 1 ∈ [0, N − 1], the step of a block
        whose delayed sample the message N·J steps later uses.

    Examples
    --------
    >>> message_buffer(2, 1), message_buffer(20, 10), message_buffer(2, 10)
    ((3, 0), (3, 9), (1, 7))
    """
    J = m // N + 1
    return J, J * N - m - 1


def step_model(
    kx: Array, kv: Array, ka: Array, p: Params, H: float,
) -> tuple[Ball, Ball, Ball, Ball, Ball]:
    """The per-step closed loop of one follower: A_c, g, Γ_p, the output row and q's row.

    Parameters
    ----------
    kx, kv, ka : ndarray
        The gains, one triple per row (n rows).
    p : Params
        τ, δ, T*.
    H : float
        The control and radar period, s.

    Returns
    -------
    A_c : Ball, shape (n, 4, 4)
        y_{k+1} = A_c y_k + g h_k + Γ_p u_{i−1,k} with y = [Δp, Δv, a_i, a_{i−1}].
    g, Gp : Ball, shape (n, 4, 1)
        k_a Γ_u (the held message's path) and Γ_p (the predecessor's command).
    K : Ball, shape (n, 1, 4)
        The output row: u_{i,k} = K y_k + k_a h_k (exact: the gains).
    Q : Ball, shape (n, 1, 5)
        q_k = Q [y_k; u_{i−1,k}] = C a_{i−1,k} + (1 − C) u_{i−1,k}.
    """
    n = kx.size
    tau, T = p.tau, p.headway
    x = H / tau
    f1, p2, p3 = (float(v) for v in phi(x))
    E = math.exp(-x)
    _, eps = split_delay(p.delta, H)
    one_c = float(phi((1.0 - eps) * x)[0])
    C = math.exp(-(1.0 - eps) * x)
    t2 = tau * tau
    # the open-loop per-step matrices and their magnitude companions (absolute values of terms)
    Phi = np.array([[1.0, H, -(t2 * p2 + T * tau * f1), t2 * p2],
                    [0.0, 1.0, -tau * f1, tau * f1],
                    [0.0, 0.0, E, 0.0],
                    [0.0, 0.0, 0.0, E]])
    Phi_mag = np.abs(Phi)
    Phi_mag[0, 2] = t2 * p2 + T * tau * f1
    Gu = np.array([-(t2 * p3 + T * tau * p2), -tau * p2, f1, 0.0])
    Gu_mag = np.abs(Gu)
    Gu_mag[0] = t2 * p3 + T * tau * p2
    Gp = np.array([t2 * p3, tau * p2, 0.0, f1])
    Phi_b = Ball.relative(Phi, Phi_mag, ROUNDOFF_SLACK)
    Gu_b = Ball.relative(Gu[:, None], Gu_mag[:, None], ROUNDOFF_SLACK)
    K = np.zeros((n, 1, 4))
    K[:, 0, 0], K[:, 0, 1] = kx, kv
    Kb = Ball.exact(K)
    A_c = Ball(np.broadcast_to(Phi_b.mid, (n, 4, 4)), np.broadcast_to(Phi_b.rad, (n, 4, 4))) \
        + (Ball(np.broadcast_to(Gu_b.mid, (n, 4, 1)), np.broadcast_to(Gu_b.rad, (n, 4, 1))) @ Kb)
    g = Ball(np.broadcast_to(Gu_b.mid, (n, 4, 1)), np.broadcast_to(Gu_b.rad, (n, 4, 1))) \
        .scale(ka[:, None, None])
    Gp_b = Ball.relative(np.broadcast_to(Gp[:, None], (n, 4, 1)),
                         np.broadcast_to(Gp[:, None], (n, 4, 1)), ROUNDOFF_SLACK)
    Q = np.zeros((n, 1, 5))
    Q[:, 0, 3], Q[:, 0, 4] = C, one_c
    return A_c, g, Gp_b, Kb, Ball.relative(Q, Q, ROUNDOFF_SLACK)


@dataclass(frozen=True)
class LiftedLink:
    """The lifted link G(z) = C(zI − A)^{−1}B + D of many gain triples (module docstring).

    Attributes
    ----------
    A : Ball, shape (n, 4 + J, 4 + J)
        The lifted state matrix (state [Δp, Δv, a_i, a_{i−1}, b_0 … b_{J−1}]).
    B : Ball, shape (n, 4 + J, N)
    C : Ball, shape (n, N, 4 + J)
    D : Ball, shape (n, N, N)
        Strictly lower triangular (no feed-through within a step).
    N : int
        Steps per message period.
    m : int
        Whole samples of the delay.
    """

    A: Ball
    B: Ball
    C: Ball
    D: Ball
    N: int
    m: int

    @property
    def order(self) -> int:
        """The lifted state dimension 4 + J."""
        return int(self.A.mid.shape[-1])

    def take(self, idx: npt.NDArray[np.intp]) -> LiftedLink:
        """The rows ``idx`` (gain triples) of every matrix.

        Parameters
        ----------
        idx : ndarray of int
            Rows to keep.

        Returns
        -------
        LiftedLink
        """
        return LiftedLink(self.A[idx], self.B[idx], self.C[idx], self.D[idx], self.N, self.m)


def _unit(n: int, cols: int, j: int) -> Ball:
    """An exact (n, 1, cols) row selecting column j."""
    e = np.zeros((n, 1, cols))
    e[:, 0, j] = 1.0
    return Ball.exact(e)


def lift(kx: Array, kv: Array, ka: Array, p: Params, H: float, N: int) -> LiftedLink:
    """Lift the N-periodic link over one message period (module docstring), phase 0.

    The block is run on linear maps: Y_l (4 × (4 + J + N)) gives y_l in terms of the block's
    initial state and its N inputs, so [A B] and [C D] are read off exactly (up to the
    propagated round-off).

    Parameters
    ----------
    kx, kv, ka : ndarray
        The gains, one triple per row.
    p : Params
        τ, δ, T* (checked).
    H : float
        The control and radar period, s.
    N : int
        Steps per message period (≥ 1).

    Returns
    -------
    LiftedLink

    Examples
    --------
    >>> from stringstab.params import Params
    >>> L = lift(np.array([1.2]), np.array([0.5]), np.array([0.6]), Params(0.1, 0.2, 1.1), 0.1, 5)
    >>> L.order, L.B.mid.shape, L.D.mid.shape
    (5, (1, 5, 5), (1, 5, 5))
    """
    n = kx.size
    m, _ = split_delay(p.delta, H)
    J, lstar = message_buffer(m, N)
    nx = 4 + J
    cols = nx + N  # [initial state (nx) | inputs (N)]
    A_c, g, Gp, K, Q = step_model(kx, kv, ka, p, H)
    eye = np.zeros((n, 4, cols))
    eye[:, :, :4] = np.eye(4)
    Y = Ball.exact(eye)
    b0 = _unit(n, cols, 4)
    gb = g @ b0  # the held message's effect on a step, in block coordinates
    kab = b0.scale(ka[:, None, None])
    rows_out = []
    store: Ball | None = None
    for l_ in range(N):
        u_l = _unit(n, cols, nx + l_)
        rows_out.append(K @ Y + kab)
        if l_ == lstar:
            Yu = Ball(np.concatenate([Y.mid, u_l.mid], axis=1), np.concatenate([Y.rad, u_l.rad], axis=1))
            store = Q @ Yu
        Y = A_c @ Y + gb + Gp @ u_l
    assert store is not None
    out = Ball(np.concatenate([r.mid for r in rows_out], axis=1),
               np.concatenate([r.rad for r in rows_out], axis=1))
    shift = [_unit(n, cols, 4 + i + 1) for i in range(J - 1)]
    AB_rows = [Y, *shift, store]
    AB = Ball(np.concatenate([r.mid for r in AB_rows], axis=1),
              np.concatenate([r.rad for r in AB_rows], axis=1))
    return LiftedLink(AB[:, :, :nx], AB[:, :, nx:], out[:, :, :nx], out[:, :, nx:], N, m)


def lifted_response(link: LiftedLink, theta: npt.ArrayLike) -> npt.NDArray[np.complex128]:
    """G(e^{jθ}) at the computed matrices (for reporting and tests; no error bound).

    Parameters
    ----------
    link : LiftedLink
        The lifted link of n triples.
    theta : array_like, shape (n, k) or (k,)
        Frequencies θ in rad per message period (θ = ω N H).

    Returns
    -------
    ndarray of complex, shape (n, k, N, N)
        The lifted frequency response (NaN at an eigenvalue of A on the circle).
    """
    A, B, C, D = link.A.mid, link.B.mid, link.C.mid, link.D.mid
    th = np.broadcast_to(np.asarray(theta, dtype=float), (A.shape[0], np.shape(theta)[-1]))
    z = np.exp(1j * th)
    nx = A.shape[-1]
    W = z[..., None, None] * np.eye(nx) - A[:, None]
    rhs = np.broadcast_to(B[:, None], (*W.shape[:2], nx, B.shape[-1]))
    try:
        X = np.linalg.solve(W, rhs)
    except np.linalg.LinAlgError:  # a pole on the circle (k_x = 0: z = 1): NaN there
        X = np.full(rhs.shape, np.nan, dtype=complex)
        for i, j in np.ndindex(*W.shape[:2]):
            try:
                X[i, j] = np.linalg.solve(W[i, j], rhs[i, j])
            except np.linalg.LinAlgError:
                pass
    return np.asarray(C[:, None] @ X + D[:, None])
