r"""Sound Schur stability of a matrix known as a ball: the Stein inertia theorem.

For a real square A, pick a symmetric P (here the numerical solution of the Stein equation
P − AᵀPA = I) and bound W = P − AᵀPA for the *exact* A.  If W ≻ 0 then A has no eigenvalue
on the unit circle and P is nonsingular, and the number of eigenvalues of A outside the unit
circle equals the number of negative eigenvalues of P (the Stein, or discrete Lyapunov,
inertia theorem).  So

* W ≻ 0 and P ≻ 0 (both proven) — A is Schur (every |λ| < 1);
* W ≻ 0 and P has a proven negative eigenvalue — A is not Schur (some |λ| > 1);
* otherwise undecided (near the boundary, or P not found).

**The proofs.**  P is a floating-point matrix, exact as data.  W is computed in ball
arithmetic (:mod:`stringstab.certify.ball`) from the ball of A, so |W_exact − Ŵ| ≤ r entry by
entry; Ŵ is symmetrised (the exact W is symmetric: |W_exact − (Ŵ + Ŵᵀ)/2| ≤ (r + rᵀ)/2 plus
its round-off).  By Weyl's inequality λ_min(W_exact) ≥ λ̂_min − ‖r_sym‖_F − e, with e the
eigensolver's backward error, bounded by γ(4n)‖Ŵ‖_F as in
:mod:`stringstab.certify.lifted_frequency`; the eigenvalues of P likewise.

References
----------
O. Taussky, "Matrices C with Cⁿ → 0", *J. Algebra* 1 (1964) 5-10; H. K. Wimmer, "On the
Ostrowski-Schneider inertia theorem", *J. Math. Anal. Appl.* 41 (1973) 164-169 (the discrete
form).  R. A. Horn, C. R. Johnson, *Matrix Analysis*, 2nd ed., CUP (2013), Thm 4.3.1 (Weyl).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import scipy.linalg

from .ball import Ball, fro, gamma

__all__ = ["stein_schur"]

Array = npt.NDArray[np.float64]


def _lam_min(S: Array, r: Array) -> tuple[float, float]:
    """λ_min of the symmetric S and the proven distance to the exact matrix's (radius r)."""
    n = S.shape[-1]
    lam = float(np.linalg.eigvalsh(S)[0])
    return lam, float(fro(r) + gamma(4 * n) * fro(S))


def stein_schur(A: Ball) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
    """Whether each exact matrix in the ball is surely Schur, or surely not (module docstring).

    Parameters
    ----------
    A : Ball, shape (n, k, k)
        The matrices (real).

    Returns
    -------
    (ndarray of bool, ndarray of bool)
        ``sure`` (proven Schur) and ``fail`` (proven an eigenvalue of modulus > 1); neither
        when undecided.

    Examples
    --------
    >>> sure, fail = stein_schur(Ball.exact(np.array([[[0.5, 1.0], [0.0, 0.9]],
    ...                                                [[1.1, 0.0], [0.0, 0.2]]])))
    >>> sure.tolist(), fail.tolist()
    ([True, False], [False, True])
    """
    n, k = A.mid.shape[0], A.mid.shape[-1]
    sure = np.zeros(n, dtype=bool)
    fail = np.zeros(n, dtype=bool)
    eye = np.eye(k)
    for i in range(n):
        a = A.mid[i]
        if not np.all(np.isfinite(a)) or not np.all(np.isfinite(A.rad[i])):
            continue
        try:
            P = scipy.linalg.solve_discrete_lyapunov(a.T, eye)  # aᵀPa − P + I = 0
        except (np.linalg.LinAlgError, ValueError):
            continue
        if not np.all(np.isfinite(P)):
            continue
        P = 0.5 * (P + P.T)
        s = 1.0 / float(np.max(np.abs(P)))
        P = P * s if s != 1.0 else P  # a scaled P is as good (and exact as data)
        Ai = A[i]
        At = Ball(Ai.mid.T, Ai.rad.T)
        W = Ball.exact(P) - At @ (Ball.exact(P) @ Ai)
        Ws = 0.5 * (W.mid + W.mid.T)
        rs = 0.5 * (W.rad + W.rad.T) + gamma(1) * np.abs(Ws)
        lw, ew = _lam_min(Ws, rs)
        if not lw > ew:
            continue
        lp = np.linalg.eigvalsh(P)
        ep = float(gamma(4 * k) * fro(P))
        if lp[0] > ep:
            sure[i] = True
        elif lp[0] < -ep:
            fail[i] = True
    return sure, fail
