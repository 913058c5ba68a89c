r"""Internal stability with a reaction delay: the roots of D(s) = P(s) + e^{−θ_r s} Q(s) in Re s ≥ 0.

With the command delayed by θ_r > 0 (issue 25; :mod:`stringstab.derive.reaction`) Γ's
denominator is the quasi-polynomial

.. math::
    D(s) = P(s) + e^{−θ_r s} Q(s),\qquad P(s) = τs^3 + s^2,\qquad Q(s) = cs + k_x,
    \qquad c = k_v + T^*k_x ,

with infinitely many roots; no finite set of coefficient conditions decides it.  Since
deg P = 3 > deg Q = 1 (τ > 0) it is *retarded*: finitely many roots lie in any half plane
Re s ≥ −ε, and the number N of roots in Re s > 0 follows from the argument principle on the
imaginary axis (Stépán's root-counting formula):

.. math::
    N = \frac{3}{2} − \frac{1}{π}\, Δ_{ω ∈ [0, ∞)} \arg D(jω)

provided D has no zero on jℝ.  (Proof: on the right half of the circle |s| = R,
D = τs³(1 + 1/(τs) + e^{−θ_r s}Q(s)/(τs³)) with |e^{−θ_r s}| ≤ 1, so the bracket tends to 1
uniformly and arg D changes by 3π there as R → ∞; the contour's other side is the axis
traversed downwards; D(−jω) = conj D(jω) makes the change over ω ∈ [−R, R] twice that over
[0, R]; so 2πN = 3π − 2Δ.)  The change is computed *exactly*, not sampled:

1. **D(0) = k_x.**  k_x = 0 puts a root at s = 0 and k_x < 0 a real root in (0, σ_hi)
   (D(0) < 0 < D(σ_hi), intermediate values; σ_hi with σ² ≥ |c|σ + |k_x|): neither is
   stable; :func:`real_root` locates the root by bisection (the witness).
2. **Tail.**  Ω² = x ≥ the positive root of f(x) = τ²x³ + x² − c²x − k_x²
   (:func:`tail_frequency`).  f is convex on x ≥ 0 with f(0) = −k_x² < 0, so it has one
   positive root x*, beyond which it increases; Newton's method from x₀ = c² + |k_x| (where
   x₀² ≥ c²x₀ + |k_x|x₀ ≥ c²x₀ + k_x², so f(x₀) ≥ τ²x₀³ > 0) decreases monotonically to x*,
   and the iterate used is accepted only if f evaluates above 10⁻¹² times its terms.  Then
   for ω ≥ Ω, |P(jω)|² = ω⁴ + τ²ω⁶ > c²ω² + k_x² = |Q(jω)|², so
   D = P·B with B(ω) = 1 + e^{−jθ_rω}Q(jω)/P(jω) in the open disc |B − 1| < 1 (no zero of
   D there), arg B → 0 as ω → ∞ and arg P(jω) = −π + atan(τω):

   .. math:: Δ_{[Ω, ∞)} \arg D = π/2 − \operatorname{atan}(τΩ) − \operatorname{Arg} B(Ω).

3. **Body** [0, Ω]: on an interval [a, b] with midpoint m and half-width h,
   |dD(jω)/dω| ≤ L(b) = 3τb² + 2b + |c| + θ_r(|c|b + |k_x|) (term by term, generated:
   ``reaction_denominator_slope_bound``), so |D(jω) − D(jm)| ≤ hL on [a, b].  When
   hL < |D(jm)| (with the round-off slack below), D stays in a disc that excludes 0, its
   argument moves by less than π/2 on each side of m, and the change over [a, b] is exactly
   Arg(D(jm)/D(ja)) + Arg(D(jb)/D(jm)) (principal values).  Other intervals are split
   (vectorised over every item and interval, as :mod:`stringstab.certify.branch_bound`).
4. **Round-off.**  Each D̃(jω) is within E(ω) = 10⁻¹³·S(ω) of D(jω), S = τω³ + ω² +
   (|k_x| + |c|ω)(1 + θ_rω) (the terms, and the round-off of the angle θ_rω; generated:
   ``reaction_denominator_parts``); the disc test is hL + E(m) < |D̃(jm)|.  Each computed
   argument is within (π/2)·E/(|D̃| − E) + 10⁻¹⁵ of the true one; their sum ε_Δ bounds the error
   of the computed Δ.  Since the true Δ is (3/2 − N)π, N = round(3/2 − Δ̃/π) is exact when
   ε_Δ < π/2; it is accepted when ε_Δ < π/4, else the item is undecided.

An item whose budget (rounds, intervals) runs out is undecided; the smallest |D̃(jω)| met is
its stated distance to the stability boundary (a root on the axis makes it 0).  Everything
takes arrays of parameters (one per item), so a box of parameters can reuse it.

References
----------
G. Stépán, *Retarded Dynamical Systems: Stability and Characteristic Functions*, Longman 1989,
Thm 2.19 (root counting on the imaginary axis).
W. Michiels, S.-I. Niculescu, *Stability, Control, and Computation for Time-Delay Systems*,
2nd ed., SIAM 2014, §1.2 (retarded quasi-polynomials: finitely many roots in Re s ≥ −ε).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..derive import generated as _gen
from .verdicts import CERTIFIED, INCONCLUSIVE, NOT_CERTIFIED, ROUNDOFF_SLACK

__all__ = ["RootCount", "count_unstable_roots", "denominator_at", "real_root", "tail_frequency"]

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.intp]
#: A parameter: one value per item, or one shared value.
Param = Array | float

#: Accept a root count when the bound on the error of the computed argument change is below this.
ERROR_BUDGET = math.pi / 4


@dataclass
class RootCount:
    """The roots of D(s) = P(s) + e^{−θ_r s}Q(s) in Re s > 0, per item.

    Attributes
    ----------
    status : ndarray of int8
        CERTIFIED (0): internally stable, proven (N = 0, k_x > 0); NOT_CERTIFIED (1):
        unstable, proven (N ≥ 1, or a root at s = 0 when k_x = 0); INCONCLUSIVE (2): undecided.
    unstable_roots : ndarray of int64
        N, the number of roots in Re s > 0 counted with multiplicity; −1 where not counted
        (undecided, or k_x = 0: a root on the axis).
    min_abs : ndarray
        The smallest |D(jω)| evaluated on [0, Ω] (0 at k_x = 0): an undecided item's stated
        distance to the boundary (a root on jℝ makes it 0).
    min_omega : ndarray
        Where, rad/s.
    omega_tail : ndarray
        Ω of the tail (rad/s): |Q(jω)| < |P(jω)| for ω ≥ Ω.
    real_root : ndarray
        k_x < 0: a real root σ > 0 of D (bisection to 10⁻¹² relative), the witness; else NaN.
    n_evals : ndarray of int64
        Evaluations of D(jω) per item.
    error : ndarray
        The bound ε_Δ on the error of the computed argument change (rad); NaN where not counted.
    """

    status: npt.NDArray[np.int8]
    unstable_roots: npt.NDArray[np.int64]
    min_abs: Array
    min_omega: Array
    omega_tail: Array
    real_root: Array
    n_evals: npt.NDArray[np.int64]
    error: Array

    @property
    def stable(self) -> npt.NDArray[np.bool_]:
        """Internally stable, proven."""
        return np.asarray(self.status == CERTIFIED)

    @property
    def unstable(self) -> npt.NDArray[np.bool_]:
        """Not internally stable, proven."""
        return np.asarray(self.status == NOT_CERTIFIED)


def _col(v: Array) -> Array:
    return v[:, None]


def denominator_at(omega: Array, kx: Array, kv: Array, tau: Param, headway: Param,
                   theta: Param) -> tuple[Array, Array]:
    """D(jω) and its round-off bound E(ω) (step 4 of the module docstring).

    Parameters
    ----------
    omega : ndarray
        Frequencies ω ≥ 0, rad/s (broadcast against the parameters).
    kx, kv : ndarray
        Gains k_x (1/s²), k_v (1/s).
    tau, headway, theta : ndarray
        τ > 0, T* ≥ 0 and θ_r ≥ 0, s.

    Returns
    -------
    D : ndarray of complex
        D(jω) = −ω² − jτω³ + e^{−jθ_rω}(k_x + jcω) (generated: ``reaction_denominator_parts``).
    E : ndarray
        10⁻¹³·S(ω) ≥ |D̃(jω) − D(jω)|, S the sum of the magnitudes of the terms.

    Examples
    --------
    >>> D, E = denominator_at(np.array([0.0]), np.array([1.0]), np.array([0.5]), np.array([0.1]),
    ...                       np.array([1.1]), np.array([0.2]))
    >>> complex(D[0]), bool(E[0] < 1e-12)
    ((1+0j), True)
    """
    re, im, scale = _gen.reaction_denominator_parts(omega, kx, kv, 0.0, tau, 0.0, headway, theta)
    return re + 1j * im, ROUNDOFF_SLACK * scale


def tail_frequency(kx: Array, kv: Array, tau: Array, headway: Array) -> Array:
    """Ω with |Q(jω)| < |P(jω)| for every ω ≥ Ω (step 2 of the module docstring).

    Parameters
    ----------
    kx, kv : ndarray
        Gains, k_x ≠ 0.
    tau, headway : ndarray
        τ > 0 and T* ≥ 0, s.

    Returns
    -------
    ndarray
        Ω > 0, rad/s.

    Examples
    --------
    >>> W = tail_frequency(np.array([1.0]), np.array([0.5]), np.array([0.1]), np.array([1.1]))
    >>> w = np.linspace(W[0], 100 * W[0], 1000)
    >>> bool(np.all(w**4 + 0.01 * w**6 > 1.6**2 * w**2 + 1.0))
    True
    """
    c = kv + headway * kx
    t2, c2, k2 = tau * tau, c * c, kx * kx
    x0 = c2 + np.abs(kx)
    x = x0.copy()
    for _ in range(12):
        f = ((t2 * x + 1.0) * x - c2) * x - k2
        df = (3.0 * t2 * x + 2.0) * x - c2
        x = np.where(df > 0, x - f / np.where(df > 0, df, 1.0), x)
    x = x * (1.0 + 1e-9) + 1e-300
    f = ((t2 * x + 1.0) * x - c2) * x - k2
    scale = ((t2 * x + 1.0) * x + c2) * x + k2
    x = np.where(f > 1e-12 * scale, x, x0)  # x0 is proven (f(x0) ≥ τ²x0³ > 0)
    return np.asarray(np.sqrt(x))


def real_root(kx: Array, kv: Array, tau: Array, headway: Array, theta: Array) -> Array:
    """A real root σ > 0 of D(σ) = τσ³ + σ² + e^{−θ_rσ}(cσ + k_x) where k_x < 0 (NaN elsewhere).

    D(0) = k_x < 0 and D(σ_hi) ≥ τσ_hi³ > 0 for σ_hi = (|c| + √(c² + 4|k_x|))/2 (so that
    σ_hi² ≥ |c|σ_hi + |k_x|); bisection on the sign keeps a bracket.

    Parameters
    ----------
    kx, kv : ndarray
        Gains.
    tau, headway, theta : ndarray
        τ, T*, θ_r (s).

    Returns
    -------
    ndarray
        The midpoint of the final bracket (width ≤ 10⁻¹² σ_hi), 1/s; NaN where k_x ≥ 0.

    Examples
    --------
    >>> r = real_root(np.array([-1.0]), np.array([0.5]), np.array([0.1]), np.array([1.1]),
    ...               np.array([0.2]))
    >>> s = r[0]; c = 0.5 - 1.1
    >>> bool(abs(0.1 * s**3 + s**2 + np.exp(-0.2 * s) * (c * s - 1.0)) < 1e-9)
    True
    """
    c = kv + headway * kx
    lo = np.zeros_like(kx)
    hi = (np.abs(c) + np.sqrt(c * c + 4.0 * np.abs(kx))) / 2.0 + 1e-300
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        d = (tau * mid + 1.0) * mid * mid + np.exp(-theta * mid) * (c * mid + kx)
        neg = d < 0
        lo = np.where(neg, mid, lo)
        hi = np.where(neg, hi, mid)
    return np.where(kx < 0, 0.5 * (lo + hi), np.nan)


def count_unstable_roots(
    kx: Array, kv: Array, tau: Param, headway: Param, theta: Param, *, n_grid: int = 32,
    max_rounds: int = 40, max_intervals: int = 4096,
) -> RootCount:
    """Count the roots of D(s) = τs³ + s² + e^{−θ_r s}((k_v + T*k_x)s + k_x) in Re s > 0.

    The exact argument change of D(jω) over [0, ∞) (module docstring: body on [0, Ω] by
    discs that exclude 0, tail in closed form), vectorised over the items.

    Parameters
    ----------
    kx, kv : ndarray, shape (n,)
        Gains k_x (1/s²), k_v (1/s), finite.
    tau, headway, theta : ndarray, shape (n,) or broadcastable
        τ > 0, T* ≥ 0, θ_r ≥ 0 (s): one value per item, or shared.
    n_grid : int
        Initial intervals on [0, Ω].
    max_rounds : int
        Splitting rounds.
    max_intervals : int
        Undecided intervals per item beyond which the item is undecided.

    Returns
    -------
    RootCount

    Examples
    --------
    >>> one = lambda v: np.array([v])
    >>> rc = count_unstable_roots(one(1.0), one(0.5), one(0.1), one(1.1), one(0.2))
    >>> rc.status.tolist(), rc.unstable_roots.tolist()
    ([0], [0])
    >>> rc = count_unstable_roots(one(1.0), one(0.5), one(0.1), one(1.1), one(1.5))
    >>> rc.status.tolist(), rc.unstable_roots.tolist()
    ([1], [2])
    """
    n = kx.size
    tau, headway, theta = (np.broadcast_to(np.asarray(v, dtype=float), (n,))
                           for v in (tau, headway, theta))
    return _count(kx, kv, tau, headway, theta, n_grid, max_rounds, max_intervals)


def _count(kx: Array, kv: Array, tau: Array, headway: Array, theta: Array, n_grid: int,
           max_rounds: int, max_intervals: int) -> RootCount:
    """:func:`count_unstable_roots` with every parameter an array of the items' length."""
    n = kx.size
    status = np.full(n, INCONCLUSIVE, dtype=np.int8)
    N = np.full(n, -1, dtype=np.int64)
    min_abs, min_w = np.full(n, np.inf), np.zeros(n)
    n_evals = np.zeros(n, dtype=np.int64)
    body, err = np.zeros(n), np.zeros(n)
    failed = np.zeros(n, dtype=bool)
    zero = kx == 0
    status[zero] = NOT_CERTIFIED  # a root at s = 0
    min_abs[zero] = 0.0
    Om = np.zeros(n)
    live = np.flatnonzero(~zero)
    if live.size:
        Om[live] = tail_frequency(kx[live], kv[live], tau[live], headway[live])
        idx = live
        X = _col(Om[live]) * np.linspace(0.0, 1.0, n_grid + 1)[None, :]
        for rnd in range(max_rounds + 1):
            ckx, ckv, ctau, chw, cth = (_col(v[idx]) for v in (kx, kv, tau, headway, theta))
            M = 0.5 * (X[:, :-1] + X[:, 1:])
            Dx, Ex = denominator_at(X, ckx, ckv, ctau, chw, cth)
            Dm, Em = denominator_at(M, ckx, ckv, ctau, chw, cth)
            n_evals += np.bincount(idx, minlength=n) * (X.shape[1] + M.shape[1])
            _track_min(idx, X, Dx, M, Dm, min_abs, min_w)
            h = 0.5 * (X[:, 1:] - X[:, :-1])
            L = _gen.reaction_denominator_slope_bound(X[:, 1:], ckx, ckv, 0.0, ctau, 0.0, chw, cth)
            aM = np.abs(Dm)
            ok = h * L + Em < aM
            ax = np.abs(Dx)
            # the increments of the accepted intervals and the bound on their round-off
            phi = np.angle(Dm * np.conj(Dx[:, :-1])) + np.angle(Dx[:, 1:] * np.conj(Dm))
            with np.errstate(divide="ignore", invalid="ignore"):
                ex = np.where(ax > Ex, Ex / (ax - Ex), np.inf)
                em = np.where(aM > Em, Em / (aM - Em), np.inf)
            e_iv = (math.pi / 2) * (ex[:, :-1] + 2.0 * em + ex[:, 1:]) + 4e-15
            rows = np.repeat(idx, ok.shape[1])[ok.ravel()]
            body += np.bincount(rows, weights=phi[ok], minlength=n)
            err += np.bincount(rows, weights=e_iv[ok], minlength=n)
            ii, kk = np.nonzero(~ok)
            if ii.size == 0:
                break
            it = idx[ii]
            counts = np.bincount(it, minlength=n)
            over = counts > max_intervals
            if rnd == max_rounds or over.any():
                failed[np.unique(it) if rnd == max_rounds else np.flatnonzero(over)] = True
            keep = ~failed[it]
            if not keep.any():
                break
            ii, kk, it = ii[keep], kk[keep], it[keep]
            lo, hi = X[ii, kk], X[ii, kk + 1]
            need = h[ii, kk] * L[ii, kk] / np.maximum(aM[ii, kk] - Em[ii, kk], 1e-300)
            split = int(min(max(2, 2 ** math.ceil(math.log2(max(1.5 * float(np.max(need)), 1.0)))),
                            64))
            while split > 2 and it.size * split > 2_000_000:
                split //= 2
            idx = it
            X = _col(lo) + _col(hi - lo) * np.linspace(0.0, 1.0, split + 1)[None, :]
        done = live[~failed[live]]
        if done.size:
            prm1 = tuple(v[done] for v in (kx, kv, tau, headway, theta))
            tail, e_tail = _tail_change(Om[done], *prm1)
            delta_arg = body[done] + tail
            err[done] += e_tail
            count = np.rint(1.5 - delta_arg / math.pi)
            good = (err[done] < ERROR_BUDGET) & (count >= 0)
            N[done[good]] = count[good].astype(np.int64)
            status[done[good]] = np.where(count[good] == 0, CERTIFIED, NOT_CERTIFIED)
    neg = kx < 0
    status[neg] = NOT_CERTIFIED  # a real root in (0, σ_hi), whatever the count says
    root = real_root(kx, kv, tau, headway, theta) if neg.any() else np.full(n, np.nan)
    err = np.where(N >= 0, err, np.nan)
    return RootCount(status, N, min_abs, min_w, Om, root, n_evals, err)


def _track_min(idx: Index, X: Array, Dx: Array, M: Array, Dm: Array, min_abs: Array,
               min_w: Array) -> None:
    """Update the smallest |D(jω)| met per item (in place)."""
    W = np.concatenate([X, M], axis=1)
    A = np.abs(np.concatenate([Dx, Dm], axis=1))
    j = np.argmin(A, axis=1)
    rows = np.arange(idx.size)
    a, w = A[rows, j], W[rows, j]
    order = np.argsort(a)[::-1]  # the smallest last, so it wins the scatter below
    better = a[order] < min_abs[idx[order]]
    sel = order[better]
    min_abs[idx[sel]] = a[sel]
    min_w[idx[sel]] = w[sel]


def _tail_change(Om: Array, kx: Array, kv: Array, tau: Array, headway: Array,
                 theta: Array) -> tuple[Array, Array]:
    """Δ_{[Ω, ∞)} arg D = π/2 − atan(τΩ) − Arg B(Ω) and the bound on its round-off."""
    D, E = denominator_at(Om, kx, kv, tau, headway, theta)
    P = -Om * Om - 1j * tau * Om**3
    arg_b = np.angle(D * np.conj(P))  # Arg(D/P) = Arg B, B in the open right half plane
    aD = np.abs(D)
    with np.errstate(divide="ignore", invalid="ignore"):
        e = np.where(aD > E, (math.pi / 2) * E / (aD - E), np.inf) + 1e-14
    return math.pi / 2 - np.arctan(tau * Om) - arg_b, e
