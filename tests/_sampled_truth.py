"""Independent truth for the sampled-data tests: H(e^{jθ}) of two consecutive vehicles.

Built here from the continuous state equations with ``scipy.linalg.expm`` (Van Loan's
block exponential for the held inputs), *not* from stringstab.certify.sampled or
stringstab.derive.sampled_symbolic, and with the predecessor's held command u_p as the input:
the predecessor is a lag vehicle, a_p = Φ_p a_p + Γ_p u_p, and the follower's delayed
sample a_p(kH − δ) is its exact value inside the step (another ``expm`` over the
fraction of the step) — or, with ``delay="linear"``, the simulator's linear
interpolation (1 − f) a_p(t_{k−n}) + f a_p(t_{k−n−1}).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import expm


def _split(delta: float, H: float) -> tuple[int, float]:
    q = delta / H
    n = math.floor(q + 1e-9)
    f = q - n
    return n, (0.0 if f < 1e-9 else f)


def pair_matrices(kx, kv, tau, headway, H, tau_prev=None):
    """(Φ, Γ, closed-loop matrix) of [Δp, Δv, a_i, a_p] with held inputs [u, u_p]."""
    tp = tau if tau_prev is None else tau_prev
    A = np.zeros((4, 4))
    A[0, 1], A[0, 2] = 1.0, -headway
    A[1, 2], A[1, 3] = -1.0, 1.0
    A[2, 2] = -1.0 / tau
    A[3, 3] = -1.0 / tp
    B = np.zeros((4, 2))
    B[2, 0] = 1.0 / tau
    B[3, 1] = 1.0 / tp
    M = np.zeros((6, 6))
    M[:4, :4], M[:4, 4:] = A, B
    E = expm(M * H)
    Phi, Gam = E[:4, :4], E[:4, 4:]
    Acl = Phi[:3, :3] + np.outer(Gam[:3, 0], [kx, kv, 0.0])
    return Phi, Gam, Acl


def pair_response(theta, kx, kv, ka, tau, delta, headway, H, tau_prev=None, delay="exact"):
    """H(e^{jθ}) = A_i/A_{i−1} on the unit circle, vectorised over θ."""
    tp = tau if tau_prev is None else tau_prev
    Phi, Gam, Acl = pair_matrices(kx, kv, tau, headway, H, tau_prev)
    z = np.exp(1j * np.asarray(theta, dtype=float))
    Ap = Gam[3, 1] / (z - Phi[3, 3])  # per unit of U_p(z)
    if delay == "exact":
        r = math.fmod(delta, H)
        m = round((delta - r) / H)
        s = H - r  # a_p(kH − δ) = a_p((k − m − 1)H + s)
        Ms = np.array([[-1.0 / tp, 1.0 / tp], [0.0, 0.0]])
        es = expm(Ms * s)
        D = z ** (-(m + 1)) * (es[0, 0] * Ap + es[0, 1])
    else:  # the simulator's linear interpolation between received samples
        n, f = _split(delta, H)
        D = z ** (-n) * ((1.0 - f) + f / z) * Ap
    rhs = (Phi[:3, 3][None, :] * Ap[:, None] + Gam[:3, 1][None, :]
           + Gam[:3, 0][None, :] * (ka * D)[:, None])
    Mz = z[:, None, None] * np.eye(3)[None] - Acl[None]
    X = np.linalg.solve(Mz, rhs[..., None])[..., 0]
    return X[:, 2] / Ap


def pair_roots(kx, kv, tau, headway, H):
    """Roots of the follower's closed-loop characteristic polynomial (numpy.roots)."""
    _, _, Acl = pair_matrices(kx, kv, tau, headway, H)
    return np.roots(np.poly(Acl))


THETA = np.unique(np.concatenate([np.geomspace(1e-6, 0.1, 1500), np.linspace(0.1, np.pi, 15000)]))
