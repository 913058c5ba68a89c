r"""The lifted link on the unit circle: proven bounds on λ_min of the tangency-free margin M(θ).

The lifted link G(z) = C(zI − A)^{−1}B + D (:mod:`stringstab.certify.lifting`) has
σ_max(G(e^{jθ})) ≤ 1 iff I − G*G ⪰ 0.  At θ = 0 this is tight: a constant command propagates
(G(1)1 = 1), so I − G(1)*G(1) is singular and no bound on σ_max between points can prove ≤ 1
near θ = 0.  The tangency is removed by an exact congruence (docs/sampled.md, §9.3):

**The margin matrix.**  With e = s₀1 and the columns of V the exact (power-of-two scaled)
Helmert vectors — integers, exactly orthogonal to 1 and to each other — Q = [e V] is
invertible, and for θ ≠ 0, S = diag(1/(z − 1), I) makes

.. math::
    M(θ) = S^* Q^T (I − G^*G) Q S,\qquad
    M_{11} = m_{ee},\quad M_{12} = M_{21}^* = m_{eV},\quad M_{22} = V^T(I − G^*G)V,

    m_{ee} = 2\,\mathrm{Re}\,(γ(z) + c_1(z)) − γ(1) − \|\dot G(z) e\|^2,\qquad
    m_{eV} = z\, e^T \dot G(z) V − (\dot G(z) e)^* G(z) V,

with Ġ(z) = −C(zI − A)^{−1}F, F = (I − A)^{−1}B (so G(z) = G(1) + (z − 1)Ġ(z)),
γ(z) = eᵀĠ(z)e and c₁(z) = eᵀC(zI − A)^{−1}(I − A)^{−1}Fe.  The derivation uses G(1)e = e
and G(1)ᵀe = e, both exact for the model (a constant command propagates; over a period of
the periodic steady state, Σu_i = Σu_{i−1} because the speed difference returns to its
value); tests check both.  M is analytic in θ (no division by z − 1 is left), equals the
congruence for θ ≠ 0 — so M(θ) ⪰ 0 iff σ_max(G(e^{jθ})) ≤ 1 (Sylvester's law of inertia) —
and its limit at θ = 0 can be positive definite.

**Proven bounds** (:func:`evaluate`): every quantity is a computed value with a norm-wise
radius bounding its distance to the exact model's: the resolvent by a verified inverse —
X ≈ (zI − A)^{−1}, ε = ‖I − X(zI − Â)‖_F + ‖X‖_F‖A − Â‖_F (+ round-off) < 1 gives
‖R‖ ≤ ‖X‖_F/(1 − ε) and ‖R − X‖ ≤ ε‖R‖ — and products by
‖ab − fl(âb̂)‖ ≤ ‖a − â‖‖b‖ + ‖â‖‖b − b̂‖ + γ‖â‖‖b̂‖ (:mod:`stringstab.certify.ball`).  So
|λ_min(M(θ)) − λ_min(M̂)| ≤ r_M + the eigensolver's backward error (Weyl), the slack.

**Between points** (:func:`curvature`): on [l, r] of width h, every z is within h/2 (along
the arc, so also in distance) of an end z₀, so ‖R(z)‖ ≤ ρ = ‖R(z₀)‖/(1 − (h/2)‖R(z₀)‖)
(Neumann).  With R' = −jzR² and R'' = zR² − 2z²R³ (d/dθ), ‖R'‖ ≤ ρ², ‖R''‖ ≤ ρ² + 2ρ³, and
the product rule bounds ‖M''‖ ≤ K on [l, r].  Then λ_min(M(θ)) ≥ min(λ_min(M(l)),
λ_min(M(r))) − Kh²/8: M − L (L the chord of M) is at most Kh²/8 in norm (the interpolation
error of a C² function, vector-valued), λ_min is concave along the affine L, and Weyl's
inequality.  This is the bound of :mod:`stringstab.certify.branch_bound`.

References
----------
S. M. Rump, "Verification methods: rigorous results using floating-point arithmetic",
*Acta Numerica* 19 (2010) 287-449 (verified inverses).  R. A. Horn, C. R. Johnson, *Matrix
Analysis*, 2nd ed., CUP (2013), Thm 4.3.1 (Weyl) and Thm 4.5.8 (Sylvester's law of inertia).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from .ball import UNIT_ROUNDOFF, fro, gamma
from .lifting import LiftedLink

__all__ = ["LOCAL", "PIECES", "Margin", "Prepared", "balance", "curvature", "evaluate", "helmert", "prepare", "weighted"]

Array = npt.NDArray[np.float64]
CArray = npt.NDArray[np.complex128]


def helmert(N: int) -> tuple[Array, Array, float]:
    """e = s₀1 and V: exact, mutually orthogonal columns of norm in [1/√2, √2].

    Column k of V (k = 1 … N − 1) is (1, …, 1, −k, 0, …, 0) (k ones) times a power of two
    near 1/√(k(k + 1)): integers times powers of two, so 1ᵀV = 0 and VᵀV is diagonal
    exactly in floating point.

    Parameters
    ----------
    N : int
        The lifted dimension.

    Returns
    -------
    e : ndarray, shape (N,)
    V : ndarray, shape (N, N − 1)
    v_norm : float
        An upper bound of ‖V‖₂ (the largest column norm: the columns are orthogonal).

    Examples
    --------
    >>> e, V, nv = helmert(3)
    >>> V.T @ V, e @ V
    (array([[0.5, 0. ],
           [0. , 1.5]]), array([0., 0.]))
    """
    e = np.full(N, 2.0 ** -round(math.log2(math.sqrt(N))))
    V = np.zeros((N, N - 1))
    norms = [1.0]
    for k in range(1, N):
        s = 2.0 ** -round(math.log2(math.sqrt(k * (k + 1))))
        V[:k, k - 1] = s
        V[k, k - 1] = -k * s
        norms.append(s * math.sqrt(k * (k + 1)))
    return e, V, max(norms) * (1.0 + 4 * UNIT_ROUNDOFF)


def _spec(a: Array) -> Array:
    """Upper bounds of the spectral norms of a stack (computed σ_max plus its backward error)."""
    if a.shape[-1] == 0 or a.shape[-2] == 0:
        return np.zeros(a.shape[:-2])
    s = np.linalg.svd(a, compute_uv=False)[..., 0]
    return np.asarray(s + gamma(4 * max(a.shape[-2:])) * fro(a))


@dataclass(frozen=True)
class Prepared:
    """The per-triple constants of the margin: computed values and error bounds.

    The state is scaled by :func:`balance` (exactly); every ``r*`` bounds the spectral norm of
    the difference between the exact model's matrix and the computed one.

    Attributes
    ----------
    A, rA : ndarray
        The lifted state matrix and its error bound.
    C, rC, nC : ndarray
        The output matrix, its error bound and an upper bound of its norm.
    Q : ndarray, shape (n, nx, 2N)
        [BV | Fe | F2e | FV] with F = (I − A)^{−1}B, F2e = (I − A)^{−1}Fe: the right factors
        of the four resolvent products of the margin (module docstring).
    rQ : ndarray, shape (n, 4)
        Error bounds of the four blocks.
    DV, rDV : ndarray
        DV and its error bound.
    g1, rg1 : ndarray
        γ(1) = eᵀĠ(1)e = −eᵀC(I − A)^{−1}Fe and its error bound.
    ok : ndarray of bool
        The verified inverse at z = 1 succeeded (ε < 1/2); rows without it are never certified.
    e, V, v_norm
        From :func:`helmert`.
    r : ndarray
        The weight of the e direction, r ∈ [0, 1) per triple (:func:`weighted`).
    """

    A: Array
    rA: Array
    C: Array
    rC: Array
    nC: Array
    Q: Array
    rQ: Array
    DV: Array
    rDV: Array
    g1: Array
    rg1: Array
    ok: npt.NDArray[np.bool_]
    e: Array
    V: Array
    v_norm: float
    r: Array


def _verified_inverse(W: Any, rW: Array, complex_: bool) -> tuple[Any, Array, Array]:
    """X ≈ W^{−1} of a stack, ρ ≥ ‖exact W^{−1}‖₂ and d ≥ ‖exact W^{−1} − X‖₂ (inf if unproven).

    ``rW`` bounds ‖exact W − W‖₂.  ε = ‖I − XW‖_F (computed) + its round-off + ‖X‖_F rW;
    if ε < 1: ρ = ‖X‖_F/(1 − ε), d = ερ.
    """
    n = W.shape[-1]
    eye = np.eye(n)
    try:
        X = np.linalg.inv(W)
    except np.linalg.LinAlgError:  # a singular member in the stack: invert one by one
        X = np.stack([_safe_inv(w) for w in W])
    res = eye - X @ W
    nX = fro(X)
    g = gamma(2 * n + 4 if complex_ else n + 1)
    eps = fro(res) + g * (math.sqrt(n) + nX * fro(W)) + nX * rW
    with np.errstate(divide="ignore", invalid="ignore"):
        rho = np.where(eps < 0.5, nX / (1.0 - eps), np.inf)
    return X, rho, np.where(eps < 0.5, eps * rho, np.inf)


def _safe_inv(w: Any) -> Any:
    try:
        return np.asarray(np.linalg.inv(w))
    except np.linalg.LinAlgError:
        return np.full_like(w, np.nan)


def balance(A: Array, B: Array, C: Array, passes: int = 6) -> Array:
    """A diagonal state scaling T of powers of two making T^{−1}AT, T^{−1}B, CT balanced.

    Osborne's iteration (as LAPACK's ``gebal``), each state's off-diagonal row norm of
    [A B] made close to its column norm of [A; C]; powers of two keep the similarity exact
    in floating point, so G(z) and every bound are unchanged, while the norms that the
    bounds multiply (‖R‖, ‖CR‖, ‖RB‖) shrink.

    Parameters
    ----------
    A, B, C : ndarray, shapes (n, m, m), (n, m, N), (n, N, m)
        The lifted matrices.
    passes : int
        Sweeps over the states.

    Returns
    -------
    ndarray, shape (n, m)
        The diagonal of T.
    """
    n, m = A.shape[:2]
    t = np.ones((n, m))
    a = np.abs(A) * (1.0 - np.eye(m))
    b = np.abs(B).sum(axis=2)
    c = np.abs(C).sum(axis=1)
    for _ in range(passes):
        for i in range(m):
            r = (a[:, i, :] * t).sum(axis=1) / t[:, i] + b[:, i] / t[:, i]
            q = (a[:, :, i] / t).sum(axis=1) * t[:, i] + c[:, i] * t[:, i]
            with np.errstate(divide="ignore", invalid="ignore"):
                f = np.where((r > 0) & (q > 0), np.exp2(np.round(0.5 * np.log2(r / q))), 1.0)
            t[:, i] *= np.clip(f, 2.0**-20, 2.0**20)
    return t


def prepare(link: LiftedLink) -> Prepared:
    """The per-triple constants of :func:`evaluate` and :func:`curvature`, with their bounds.

    Parameters
    ----------
    link : LiftedLink
        The lifted link of n triples.

    Returns
    -------
    Prepared
    """
    t = balance(link.A.mid, link.B.mid, link.C.mid)
    ti = 1.0 / t  # powers of two: every scaling below is exact
    A = link.A.mid * ti[:, :, None] * t[:, None, :]
    B, C, D = link.B.mid * ti[:, :, None], link.C.mid * t[:, None, :], link.D.mid
    rA, rB, rC, rD = (fro(r) for r in (link.A.rad * ti[:, :, None] * t[:, None, :],
                                       link.B.rad * ti[:, :, None], link.C.rad * t[:, None, :],
                                       link.D.rad))
    nB, nC = _spec(B) + rB, _spec(C) + rC
    nx, N = A.shape[-1], link.N
    e, V, nv = helmert(N)
    ne = _ne(e)
    X1, _, d1 = _verified_inverse(np.eye(nx) - A, rA, complex_=False)
    g = gamma(nx)
    nX1 = _norm2(X1)
    F = X1 @ B
    rF = d1 * nB + nX1 * rB + g * nX1 * fro(B)
    Fe = F @ e
    rFe = rF * ne + gamma(N) * fro(F) * ne
    nFe = _vnorm(Fe) + rFe
    F2e = np.einsum("nij,nj->ni", X1, Fe)
    rF2e = d1 * nFe + nX1 * rFe + g * nX1 * _vnorm(Fe)
    nF2e = _vnorm(F2e) + rF2e
    BV, FV, DV = B @ V, F @ V, D @ V
    rBV = rB * nv + gamma(N) * fro(B) * nv
    rFV = rF * nv + gamma(N) * fro(F) * nv
    rDV = rD * nv + gamma(N) * fro(D) * nv
    Q = np.concatenate([BV, Fe[:, :, None], F2e[:, :, None], FV], axis=2)
    rQ = np.stack([rBV, rFe, rF2e, rFV], axis=1)
    CF2e = np.einsum("nij,nj->ni", C, F2e)
    g1 = -(CF2e @ e)
    rg1 = ne * (rC * nF2e + _norm2(C) * rF2e + gamma(nx) * fro(C) * _vnorm(F2e))
    rg1 = rg1 + gamma(N) * ne * _vnorm(CF2e)
    pr = Prepared(A, rA, C, rC, nC, Q, rQ, DV, rDV, g1, rg1, np.isfinite(d1), e, V, nv,
                  np.zeros(A.shape[0]))
    return weighted(pr)


def weighted(pr: Prepared) -> Prepared:
    """The constants with the weight of the e direction, r, chosen from m_ee(0).

    M_r = diag(z̄ − r, I) M diag(z − r, I) is a congruence for r ∈ [0, 1) (z − r ≠ 0 on the
    circle), so it is ⪰ 0 iff M is: it is the margin matrix of the scaling (z − r)/(z − 1)
    of the e direction instead of 1/(z − 1).  m_ee is typically far larger than the V block
    near θ = 0 (it is (1 − ‖Ge‖²)/|z − 1|², whose limit grows as the message period shrinks)
    and its variation would dominate the curvature bound although λ_min is set by the V
    block; r = 1 − 1/√m_ee(0) brings |1 − r|²m_ee(0) to 1 while leaving θ = π about as it
    was (|z − r|² ≈ 4 there, as |z − 1|²).

    Parameters
    ----------
    pr : Prepared
        Constants with r = 0.

    Returns
    -------
    Prepared
    """
    n = pr.A.shape[0]
    if n == 0:
        return pr
    m0 = evaluate(pr, np.arange(n), np.zeros((n, 1))).m_ee[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(np.isfinite(m0) & (m0 > 1.0), 1.0 - 1.0 / np.sqrt(m0), 0.0)
    return dataclasses.replace(pr, r=r)


#: The pieces of the margin, each P R(z) Q (+ a constant): GV = CR(BV) + DV, Ġe = −CR(Fe),
#: γ = eᵀĠe, c₁ = eᵀCR(F2e), eᵀĠV = −eᵀCR(FV).
PIECES = ("GV", "Gde", "gam", "c1", "eGdV")
#: Per piece, at a point θ₀: bounds of ‖Y(θ₀)‖, ‖Y'(θ₀)‖, ‖Y''(θ₀)‖ and ‖PR₀‖‖R₀Q‖ (for
#: the third derivative nearby); then ρ₀ ≥ ‖R₀‖, |γ(1)|, r, |m_ee(θ₀)|, ‖m_eV(θ₀)‖ (unweighted),
#: |z₀ − r|², |z₀ − r| and |sin θ₀|.  All bounds for the exact model.
LOCAL = (*(f"{p}_{q}" for p in PIECES for q in ("d0", "d1", "d2", "pq")), "rho", "g1", "r",
         "mee", "meV", "u", "f", "sin")


@dataclass(frozen=True)
class Margin:
    """λ_min of M at points, with its slack and the local bounds (:func:`evaluate`).

    Attributes
    ----------
    lam : ndarray, shape (k, p)
        λ_min(M̂(θ)) computed (+inf where the resolvent could not be bounded).
    slack : ndarray, shape (k, p)
        |λ_min(M(θ)) − lam| ≤ slack (for the exact model).
    local : ndarray, shape (k, p, len(LOCAL))
        The bounds named in :data:`LOCAL` (inf where unproven).
    m_ee : ndarray, shape (k, p)
        The unweighted m_ee(θ) computed (to choose the weight).
    M : ndarray of complex, shape (k, p, N, N), or None
        The computed M_r(θ) itself, when asked for (tests).
    """

    lam: Array
    slack: Array
    local: Array
    m_ee: Array
    M: npt.NDArray[np.complex128] | None = None

    @property
    def rho(self) -> Array:
        """‖(e^{jθ}I − A)^{−1}‖₂ ≤ rho (exact model)."""
        return np.asarray(self.local[..., LOCAL.index("rho")])


def _norm2(x: Any) -> Array:
    """Upper bounds of the spectral norms of a stack: min(‖x‖_F, √(‖x‖₁‖x‖_∞)), rounded up."""
    a = np.abs(x)
    if a.shape[-1] == 0 or a.shape[-2] == 0:
        return np.zeros(a.shape[:-2])
    f = np.sqrt(np.einsum("...ij,...ij->...", a, a))
    n1 = a.sum(axis=-2).max(axis=-1)
    ni = a.sum(axis=-1).max(axis=-1)
    return np.asarray(np.minimum(f, np.sqrt(n1 * ni)) * (1.0 + gamma(sum(x.shape[-2:]))))


def _vnorm(x: Any) -> Array:
    """Euclidean norms of a stack of vectors (last axis), rounded up."""
    a = np.abs(x)
    return np.asarray(np.sqrt(np.einsum("...i,...i->...", a, a)) * (1.0 + gamma(x.shape[-1])))


def _ne(e: Array) -> float:
    """‖e‖, rounded up."""
    return float(np.linalg.norm(e)) * (1.0 + gamma(e.size))


def evaluate(pr: Prepared, idx: npt.NDArray[np.intp], theta: Array, *,
             matrices: bool = False, local: bool = True) -> Margin:
    """λ_min(M_r(θ)) with a proven slack, and the local bounds, at the points θ of ``idx``.

    Parameters
    ----------
    pr : Prepared
        The constants of :func:`prepare`.
    idx : ndarray of int, shape (k,)
        The triple of each row of ``theta``.
    theta : ndarray, shape (k, p)
        Frequencies in rad per message period.
    matrices : bool
        Also return the matrices M_r(θ) computed.
    local : bool
        Compute the local bounds of :func:`curvature` (False: λ_min, its slack and ρ₀ only;
        the other local bounds are inf, so no interval can be settled from them).

    Returns
    -------
    Margin
    """
    k, p = theta.shape
    nx = pr.A.shape[-1]
    N = pr.V.shape[0]
    e, V = pr.e, pr.V
    ne, nv = _ne(e), pr.v_norm
    z = np.exp(1j * theta).reshape(-1)
    rows = np.repeat(idx, p)
    W = z[:, None, None] * np.eye(nx) - pr.A[rows]
    X, rho, dR = _verified_inverse(W, pr.rA[rows], complex_=True)
    nX = _norm2(X)
    gc = gamma(2 * nx + 2)
    Q, rQ = pr.Q[rows], pr.rQ[rows]
    C, rC = pr.C[rows], pr.rC[rows]
    nCh = _norm2(C)
    blocks = (slice(0, N - 1), slice(N - 1, N), slice(N, N + 1), slice(N + 1, 2 * N))

    def bnorms(a: Any) -> Array:
        return np.stack([_norm2(a[:, :, b]) for b in blocks], axis=1)

    # W_k = X^k Q ≈ R₀^k Q; per block b, Ek[k][b] bounds ‖R₀^k Q_b − W_k,b‖
    Wk = [Q]
    nW = [bnorms(Q)]
    Ek = [rQ]
    powers = 3 if local else 1
    for _ in range(powers):
        Wn = X @ Wk[-1]
        En = (dR[:, None] * (nW[-1] + Ek[-1]) + nX[:, None] * Ek[-1]
              + gc * nX[:, None] * nW[-1])
        Wk.append(Wn)
        nW.append(bnorms(Wn))
        Ek.append(En)
    # Y_j = C W_{j+1} ≈ C R₀^{j+1} Q, with error bounds per block
    Y = [C @ Wk[j] for j in range(1, powers + 1)]
    EY = [rC[:, None] * (nW[j] + Ek[j]) + nCh[:, None] * Ek[j] + gc * nCh[:, None] * nW[j]
          for j in range(1, powers + 1)]
    gN = gamma(2 * N + 2)
    # the pieces' values (with signs) at θ₀ and their error bounds
    GV = Y[0][:, :, blocks[0]] + pr.DV[rows]
    rGV = EY[0][:, 0] + pr.rDV[rows]
    Gde = -Y[0][:, :, N - 1]
    rGde = EY[0][:, 1]
    gam = Gde @ e
    rgam = ne * rGde + gN * ne * _vnorm(Gde)
    c1 = Y[0][:, :, N] @ e
    rc1 = ne * EY[0][:, 2] + gN * ne * _vnorm(Y[0][:, :, N])
    eGdV = -np.einsum("i,kij->kj", e, Y[0][:, :, blocks[3]])
    reGdV = ne * EY[0][:, 3] + gN * ne * _norm2(Y[0][:, :, blocks[3]])
    nGV, nGde, neGdV = _norm2(GV), _vnorm(Gde), _vnorm(eGdV)
    g1 = pr.g1[rows]
    m_ee0 = 2.0 * (gam + c1).real - g1 - nGde * nGde
    r_ee = 2.0 * (rgam + rc1) + pr.rg1[rows] + 2.0 * nGde * rGde + rGde * rGde
    r_ee = r_ee + gN * (2.0 * (np.abs(gam) + np.abs(c1)) + np.abs(g1) + nGde * nGde)
    m_eV = z[:, None] * eGdV - np.einsum("ki,kij->kj", Gde.conj(), GV)
    r_eV = reGdV + rGde * (nGV + rGV) + nGde * rGV + gN * (neGdV + nGde * nGV)
    # the weight of the e direction: diag(z̄ − r, I) M diag(z − r, I) (see :func:`weighted`)
    r = pr.r[rows]
    u = 1.0 + r * r - 2.0 * r * np.cos(theta.reshape(-1))  # |z − r|²
    gw = gamma(8)
    mee_b, meV_b = np.abs(m_ee0) + r_ee, _vnorm(m_eV) + r_eV
    fz = np.abs(z.conj() - r)
    m_ee = u * m_ee0
    r_ee = u * r_ee + gw * (1.0 + r) ** 2 * mee_b
    m_eV = (z.conj() - r)[:, None] * m_eV
    r_eV = fz * r_eV + gw * (1.0 + r) * meV_b
    MVV = V.T @ V - np.swapaxes(GV.conj(), 1, 2) @ GV
    r_VV = 2.0 * nGV * rGV + rGV * rGV + gN * (nv * nv + nGV * nGV)
    M = np.empty((k * p, N, N), dtype=complex)
    M[:, 0, 0] = m_ee
    M[:, 0, 1:] = m_eV
    M[:, 1:, 0] = m_eV.conj()
    M[:, 1:, 1:] = MVV
    M = 0.5 * (M + np.swapaxes(M.conj(), 1, 2))
    lam = np.linalg.eigvalsh(M)[:, 0]
    slack = r_ee + r_eV + r_VV + gamma(4 * N) * fro(M)
    good = np.isfinite(rho) & np.isfinite(slack)
    lam = np.where(good, lam, np.inf)
    slack = np.where(good, slack, np.inf)
    if local:
        # the derivatives at θ₀ (with their bounds), ‖PR₀‖ for P = C and eᵀC, and ‖R₀Q_b‖
        zz = z[:, None, None]
        D1 = -1j * zz * Y[1]                   # (PRQ)' = −jz PR²Q
        D2 = zz * Y[1] - 2.0 * zz * zz * Y[2]  # (PRQ)'' = P(zR² − 2z²R³)Q
        E1, E2 = EY[1], EY[1] + 2.0 * EY[2]
        CX = C @ X
        eCX = rC * rho + nCh * dR + gc * nCh * nX
        pC = _norm2(CX) + eCX
        peC = _vnorm(e @ CX) + ne * eCX
        Rq = nW[1] + Ek[1]
        cols = []
        for val, rv, b, P, contract in ((nGV, rGV, 0, pC, False), (nGde, rGde, 1, pC, False),
                                        (np.abs(gam), rgam, 1, peC, True),
                                        (np.abs(c1), rc1, 2, peC, True),
                                        (neGdV, reGdV, 3, peC, True)):
            d1, d2 = D1[:, :, blocks[b]], D2[:, :, blocks[b]]
            if contract:
                n1 = _vnorm(np.einsum("i,kij->kj", e, d1)) + ne * E1[:, b]
                n2 = _vnorm(np.einsum("i,kij->kj", e, d2)) + ne * E2[:, b]
            else:
                n1, n2 = _norm2(d1) + E1[:, b], _norm2(d2) + E2[:, b]
            # (the products by z, z² and 2 round by a few u: the factor covers them)
            cols += [val + rv, n1 * (1.0 + gw), n2 * (1.0 + gw), P * Rq[:, b]]
        ur = (1.0 + gw) * u + gw * (1.0 + r) ** 2
        loc = np.stack([*cols, rho, np.abs(g1) + pr.rg1[rows], r, mee_b, meV_b, ur,
                        (1.0 + gw) * fz + gw * (1.0 + r), np.abs(np.sin(theta.reshape(-1)))],
                       axis=-1)
        loc = np.where(good[:, None], loc, np.inf)
    else:
        loc = np.full((k * p, len(LOCAL)), np.inf)
        loc[:, LOCAL.index("rho")] = rho
    return Margin(lam.reshape(k, p), slack.reshape(k, p), loc.reshape(k, p, len(LOCAL)),
                  m_ee0.reshape(k, p), M.reshape(k, p, N, N) if matrices else None)


def _mul(a: tuple[Array, ...], b: tuple[Array, ...]) -> tuple[Array, Array, Array]:
    """Norm bounds of (ab), (ab)', (ab)'' from those of a and b (Leibniz)."""
    return (a[0] * b[0], a[1] * b[0] + a[0] * b[1], a[2] * b[0] + 2.0 * a[1] * b[1] + a[0] * b[2])


def _half(loc: Array, h: Array) -> Array:
    """K over the half of an interval nearest an end whose local bounds are ``loc``."""
    L = dict(zip(LOCAL, np.moveaxis(loc, -1, 0)))
    half = 0.5 * h
    rho, r = L["rho"], L["r"]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        s = np.where(half * rho < 1.0, 1.0 / (1.0 - half * rho), np.inf)
        rs = rho * s
        f3 = s * s * (1.0 + 6.0 * rs + 6.0 * rs * rs)  # ‖Y'''‖ ≤ ‖PR₀‖‖R₀Q‖ f3
        J: dict[str, tuple[Array, Array, Array]] = {}
        for pc in PIECES:
            t3 = L[f"{pc}_pq"] * f3
            t2 = L[f"{pc}_d2"] + half * t3
            t1 = L[f"{pc}_d1"] + half * t2
            t0 = L[f"{pc}_d0"] + half * t1
            J[pc] = (t0, t1, t2)
        gv, a = J["GV"], J["Gde"]
        aa = _mul(a, a)
        ee = [2.0 * (J["gam"][i] + J["c1"][i]) + aa[i] for i in range(3)]
        ee[0] = np.minimum(ee[0] + L["g1"], L["mee"] + half * ee[1])
        q = J["eGdV"]
        zq = (q[0], q[1] + q[0], q[2] + 2.0 * q[1] + q[0])  # z·q, |z^(k)| = 1
        ag = _mul(a, gv)
        eV = [zq[i] + ag[i] for i in range(3)]
        eV[0] = np.minimum(eV[0], L["meV"] + half * eV[1])
        VV2 = _mul(gv, gv)[2]
        # the weights near θ₀: u = |z − r|² = 1 + r² − 2r cos θ, u' = 2r sin θ, u'' = 2r cos θ;
        # f = z̄ − r: |f| ≤ |z₀ − r| + h/2, |f'| = |f''| = 1
        us = 2.0 * r * (L["sin"] + half)
        u0 = L["u"] + half * us
        ee2 = 2.0 * r * ee[0] + 2.0 * us * ee[1] + u0 * ee[2]
        eV2 = eV[0] + 2.0 * eV[1] + (L["f"] + half) * eV[2]
        K = np.maximum(ee2, VV2) + eV2
    return np.asarray(np.where(np.isfinite(K), K, np.inf))


def curvature(loc_l: Array, loc_r: Array, h: Array) -> Array:
    """K ≥ ‖M_r''(θ)‖₂ on each interval [l, r] (module docstring).

    Each half of the interval is within h/2 of its end z₀ (θ₀).  Every piece Y = PR(z)Q of
    the margin has Y' = −jzPR²Q, Y'' = P(zR² − 2z²R³)Q and Y''' = jP(zR² − 6z²R³ + 6z³R⁴)Q;
    the first two are computed at θ₀ (:func:`evaluate`, with error bounds).  Near θ₀,
    R(z) = R₀(I + (z − z₀)R₀)^{−1} gives ‖PR(z)‖ ≤ ‖PR₀‖s, ‖R(z)Q‖ ≤ ‖R₀Q‖s and ‖R(z)‖ ≤ ‖R₀‖s
    with s = 1/(1 − (h/2)‖R₀‖), so on the half ‖Y'''‖ ≤ ‖PR₀‖‖R₀Q‖s²(1 + 6ρ + 6ρ²),
    ρ = ‖R₀‖s; then sup‖Y''‖ ≤ ‖Y''(θ₀)‖ + (h/2) sup‖Y'''‖, and likewise down to the values,
    and Leibniz's rule on the products of the margin (and its weight) bounds ‖M_r''‖ block
    by block (‖[a b; b* D]‖ ≤ max(|a|, ‖D‖) + ‖b‖).

    Parameters
    ----------
    loc_l, loc_r : ndarray, shape (k, q, len(LOCAL))
        The local bounds (:attr:`Margin.local`) at the intervals' ends.
    h : ndarray, shape (k, q) or (k, 1)
        The intervals' widths (rad per message period).

    Returns
    -------
    ndarray, shape (k, q)
        The bounds (inf where a Neumann series is not proven to converge).
    """
    return np.asarray(np.maximum(_half(loc_l, h), _half(loc_r, h)))
