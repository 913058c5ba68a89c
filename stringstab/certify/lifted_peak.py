r"""The reported peak of the lifted link: sup_θ σ_max(Ĝ(e^{jθ})) and where (reporting only).

The multi-rate certificate (:mod:`stringstab.certify.multirate`) reports, for every row it
does not certify, the largest singular value of the computed lifted response
Ĝ(e^{jθ}) = Ĉ(e^{jθ}I − Â)^{−1}B̂ + D̂ over θ ∈ [0, π] and the θ where it was found
(docs/sampled.md §9.5, item 5).  Nothing here enters a verdict.

**The search.**  (1) Every candidate θ (a uniform grid and the branch and bound's witness)
gets the response in a complex Schur basis of Â, computed once per row
(Â = ZTZ*, Z unitary, so (zI − Â)^{−1}B̂ = Z(zI − T)^{−1}Z*B̂ by a vectorised back
substitution); with the cheap bounds max(column norm, row norm) ≤ σ_max ≤
min(‖Ĝ‖_F, √(‖Ĝ‖₁‖Ĝ‖_∞)), the exact σ_max (the largest eigenvalue of Ĝ*Ĝ) is computed only
where the upper bound reaches the row's largest lower bound — so the best candidate is the
same as with σ_max everywhere.  (2) The bracket around the best candidate is bisected
:data:`ROUNDS` times (two new points per round, again skipping a point whose upper bound
cannot beat the best value): the local maximum is located to within (π/n)/2^ROUNDS rad,
n the grid's intervals (5.8·10⁻⁸ rad at the default 52 intervals of N = 10).  (3) The value
reported is σ_max at the reported θ recomputed by numpy's 2-norm of
:func:`stringstab.certify.lifting.lifted_response` (the directly solved response).

A local maximum narrower than the grid's spacing that the grid does not see can be missed
(as by any grid search): the reported value is a lower bound of the sup, attained at the
reported θ.

References
----------
G. H. Golub, C. F. Van Loan, *Matrix Computations*, 4th ed., JHU Press (2013), §7.3 (the
complex Schur form) and §2.3.2 (‖A‖₂² ≤ ‖A‖₁‖A‖_∞).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from .lifting import LiftedLink, lifted_response

__all__ = ["ROUNDS", "SchurLink", "lifted_peak", "schur_basis"]

Array = npt.NDArray[np.float64]
CArray = npt.NDArray[np.complex128]

#: Bisections of the bracket around the best candidate.
ROUNDS = 20
#: Complex entries of responses held at once (≈ 64 MB).
_BUDGET = 1 << 22


@dataclass(frozen=True)
class SchurLink:
    """The computed lifted link in a complex Schur basis of its A.

    Attributes
    ----------
    T : ndarray of complex, shape (n, nx, nx)
        Upper triangular, Â = Z T Z*.
    CZ, ZB : ndarray of complex
        Ĉ Z, shape (n, N, nx), and Z* B̂, shape (n, nx, N).
    D : ndarray, shape (n, N, N)
        D̂.
    """

    T: CArray
    CZ: CArray
    ZB: CArray
    D: Array


def schur_basis(link: LiftedLink) -> SchurLink:
    """The computed link in a complex Schur basis (``scipy.linalg.schur``, one row at a time).

    Parameters
    ----------
    link : LiftedLink
        The lifted link of n triples (the computed matrices, no radii).

    Returns
    -------
    SchurLink
    """
    from scipy.linalg import schur

    A, B, C = link.A.mid, link.B.mid, link.C.mid
    T = np.empty(A.shape, dtype=complex)
    Z = np.empty(A.shape, dtype=complex)
    for i in range(A.shape[0]):
        T[i], Z[i] = schur(A[i], output="complex")
    CZ = np.asarray(C @ Z, dtype=complex)
    ZB = np.asarray(np.conj(np.swapaxes(Z, -1, -2)) @ B, dtype=complex)
    return SchurLink(T, CZ, ZB, link.D.mid)


def _response(s: SchurLink, rows: npt.NDArray[np.intp], theta: Array) -> CArray:
    """Ĝ(e^{jθ}) of ``rows`` at ``theta`` (shape (len(rows), k)) by back substitution.

    Non-finite at an eigenvalue of Â on the circle (a pole: reported as ``inf``).
    """
    T, ZB = s.T[rows], s.ZB[rows]
    z = np.exp(1j * theta)
    nx = T.shape[-1]
    Y = np.empty((*theta.shape, nx, ZB.shape[-1]), dtype=complex)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for i in range(nx - 1, -1, -1):
            acc = np.broadcast_to(ZB[:, None, i, :], Y[..., i, :].shape).copy()
            for j in range(i + 1, nx):
                acc += T[:, None, i, j, None] * Y[..., j, :]
            Y[..., i, :] = acc / (z[..., None] - T[:, None, i, i, None])
        return np.asarray(s.CZ[rows][:, None] @ Y + s.D[rows][:, None])


def _bounds(G: CArray) -> tuple[Array, Array, npt.NDArray[np.bool_]]:
    """Lower and upper bounds of σ_max per matrix, and which are not finite (a pole).

    Lower: ‖Ĝw‖/‖w‖ after two power steps w = (Ĝ*Ĝ)²e_j from the largest column e_j (any
    w ≠ 0 gives ‖Ĝw‖ ≤ σ_max‖w‖; two steps suffice when Ĝ is nearly of rank one, as the
    lifted links mostly are).  Upper: min(‖Ĝ‖_F, √(‖Ĝ‖₁‖Ĝ‖_∞)).
    """
    bad = np.asarray(~np.isfinite(G).all(axis=(-2, -1)))
    G = np.where(bad[..., None, None], 0.0, G)
    a2 = np.abs(G) ** 2
    col = a2.sum(axis=-2)
    w = np.take_along_axis(G, np.argmax(col, axis=-1)[..., None, None], axis=-1)
    for _ in range(2):
        w = np.conj(np.swapaxes(G, -1, -2)) @ (G @ w)
        w = w / np.maximum(np.linalg.norm(w, axis=(-2, -1), keepdims=True), 1e-300)
    lo = np.linalg.norm(G @ w, axis=(-2, -1)) * (1 - 1e-12)
    a = np.sqrt(a2)
    one, inf_ = a.sum(axis=-2).max(axis=-1), a.sum(axis=-1).max(axis=-1)
    hi = np.minimum(np.sqrt(a2.sum(axis=(-2, -1))), np.sqrt(one * inf_))
    hi = hi * (1 + 1e-12) + 1e-300  # the rounding of the bounds themselves
    return np.asarray(lo), np.asarray(hi), bad


def _sigma(G: CArray) -> Array:
    """σ_max of each matrix: √ of the largest eigenvalue of G*G (relative error ~ ε)."""
    M = np.conj(np.swapaxes(G, -1, -2)) @ G
    return np.asarray(np.sqrt(np.maximum(np.linalg.eigvalsh(M)[..., -1], 0.0)))


def _values(s: SchurLink, rows: npt.NDArray[np.intp], theta: Array, beat: Array) -> Array:
    """σ_max at ``theta`` where it can exceed ``beat`` (per row); ``-inf`` where it cannot."""
    G = _response(s, rows, theta)
    _, hi, bad = _bounds(G)
    out = np.full(theta.shape, -np.inf)
    r, c = np.nonzero(~bad & (hi >= beat[:, None]))
    if r.size:
        out[r, c] = _sigma(G[r, c])
    out[bad] = np.inf
    return out


def lifted_peak(link: LiftedLink, grid: Array, start: Array, *,
                rounds: int = ROUNDS) -> tuple[Array, Array]:
    """sup_θ σ_max(Ĝ(e^{jθ})) on [0, π] and where, for reporting (module docstring).

    Parameters
    ----------
    link : LiftedLink
        The lifted link of n triples.
    grid : ndarray, shape (n, g + 1)
        A uniform grid on [0, π] per row (g intervals).
    start : ndarray, shape (n,)
        One more candidate per row (the branch and bound's witness).
    rounds : int
        Bisections of the bracket around the best candidate.

    Returns
    -------
    best : ndarray, shape (n,)
        σ_max(Ĝ(e^{jθ})) at the reported θ (``inf`` at a pole on the circle).
    theta : ndarray, shape (n,)
        The reported θ, rad per message period.

    Examples
    --------
    >>> from stringstab.params import Params
    >>> from stringstab.certify.lifting import lift
    >>> link = lift(np.array([0.45]), np.array([0.25]), np.array([0.9]), Params(0.1, 0.2, 1.1),
    ...             0.01, 10)
    >>> s, th = lifted_peak(link, np.linspace(0, np.pi, 53)[None], np.zeros(1))
    >>> round(float(s[0]), 4), round(float(th[0]), 3)
    (1.0205, 0.244)
    """
    n = grid.shape[0]
    best = np.empty(n)
    where = np.empty(n)
    if n == 0:
        return best, where
    N, cand = link.N, np.concatenate([grid, start[:, None]], axis=1)
    k = cand.shape[1]
    sl = schur_basis(link)
    cols = max(1, min(k, _BUDGET // (N * N)))
    step = max(1, _BUDGET // (N * N * cols))
    for s0 in range(0, n, step):
        rows = np.arange(s0, min(s0 + step, n))
        # (1) the candidates: bounds everywhere, σ_max where the bounds leave it a chance
        lo = np.empty((rows.size, k))
        hi = np.empty((rows.size, k))
        pole = np.empty((rows.size, k), dtype=bool)
        kept: list[CArray] = []
        for c0 in range(0, k, cols):
            G = _response(sl, rows, cand[rows, c0:c0 + cols])
            lo[:, c0:c0 + cols], hi[:, c0:c0 + cols], pole[:, c0:c0 + cols] = _bounds(G)
            if cols == k:
                kept.append(G)  # one block: kept for the values (else recomputed)
        S = np.where(pole, np.inf, -np.inf)
        need = ~pole & (hi >= np.where(pole, -np.inf, lo).max(axis=1, keepdims=True))
        for c0 in range(0, k, cols):
            part = need[:, c0:c0 + cols]
            r, c = np.nonzero(part)
            if r.size:
                G = kept[0] if kept else _response(sl, rows, cand[rows, c0:c0 + cols])
                S[r, c0 + c] = _sigma(G[r, c])
        j = np.argmax(S, axis=1)
        b, x = S[np.arange(rows.size), j], cand[rows, j]
        # (2) bisect the bracket [x − h, x + h] around the best point
        h = np.full(rows.size, np.pi / (k - 2))
        live = np.isfinite(b)
        for _ in range(rounds):
            h = h / 2.0
            idx = np.flatnonzero(live)
            if not idx.size:
                break
            X = np.clip(x[idx, None] + h[idx, None] * np.array([-1.0, 1.0]), 0.0, np.pi)
            F = _values(sl, rows[idx], X, b[idx])
            jj = np.argmax(F, axis=1)
            fj = F[np.arange(idx.size), jj]
            up = fj > b[idx]
            b[idx] = np.where(up, fj, b[idx])
            x[idx] = np.where(up, X[np.arange(idx.size), jj], x[idx])
        # (3) the value at the reported point, by the direct response
        G = lifted_response(link.take(rows), x[:, None])[:, 0]
        bad = np.asarray(~np.isfinite(G).all(axis=(-2, -1)))
        val = np.linalg.norm(np.where(bad[:, None, None], 0.0, G), 2, axis=(-2, -1))
        best[rows] = np.where(bad | np.isinf(b), np.inf, val)
        where[rows] = x
    return best, where
