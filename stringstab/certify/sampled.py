"""Sound string-stability certificates for the sampled-data (zero-order hold) loop.

Every vehicle samples synchronously with period H (``sample_time``), holds its command
over the period and has the actuator lag τ; the delayed predecessor acceleration
a_{i−1}(kH − δ) is exact for any δ = mH + εH ≥ 0.  The string transfer function from
the predecessor's acceleration samples to the follower's, derived symbolically by
:mod:`stringstab.derive.sampled_symbolic`, is in w = z − 1

.. math::
    H(z) = \\frac{φ_1}{φ_{1p}}\\,\\frac{n(w) + z^{-(m+1)} k_a w^2 \\ell(w)}{Δ(w)}

with Δ = w³ + δ2 w² + δ1 w + δ0, n = ν2 w² + ν1 w + ν0, ℓ = φ_{1p} + (1 − C) w and

    δ0 = k_x H² φ1,  δ1 = H(c φ1 + k_x(τ ψ2 + H φ1/2)),  δ2 = φ1 + c τ ψ2 + k_x τ² ψ3,
    ν0 = k_x H² φ1p, ν1 = H(k_v φ1p + k_x(τ_p ψ2p + H φ1p/2)), ν2 = k_v τ_p ψ2p + k_x τ_p² ψ3p,

c = k_v + T* k_x, φ1 = 1 − e^{−x}, ψ2 = x − φ1, ψ3 = x²/2 − ψ2 at x = H/τ (the ``p``
forms at H/τ_p, the predecessor's lag, = τ in a homogeneous platoon) and
C = e^{−(1−ε)H/τ_p}.  Every coefficient is a sum of terms of one order in H, so nothing
cancels as H → 0 (tests check these closed forms against the SymPy derivation).

**The margin.**  On the unit circle z = e^{jθ}, with ρ = |w|² = 4 sin²(θ/2) and
w² = −ρz, |H(e^{jθ})| ≤ 1 iff

.. math::
    g_H(θ) = \\frac{τ^2 τ_p^2}{H^6}\\,
             \\frac{φ_{1p}^2|Δ|^2 - φ_1^2|n + z^{-(m+1)}k_a w^2\\ell|^2}{ρ}
           = P(ρ) + \\cos(mθ)\\,Y_r(ρ) + \\sin(mθ)\\sin θ\\,Y_i(ρ) \\;\\ge 0,

where P, Y_r (degree 2) and Y_i (degree 1) are polynomials in ρ computed from the
coefficients above (:func:`sampled_margin`).  The constant terms of |Δ|² and |n|²
cancel *exactly* (φ1p δ0 = φ1 ν0: H(1) = 1), which is what makes the division by
ρ ∝ 1 − cos θ exact — the analogue of dividing by ω² in the continuous margin g.
The normalisation makes g_H(ωH) → g(ω) of :func:`stringstab.certify.frequency.margin_g` as
H → 0.

**The decision** of max_{θ∈[0,π]} |H(e^{jθ})| ≤ 1 is a branch and bound on g_H over the
compact [0, π] (no tail): on [l, r] of width h,
g_H ≥ min(g_H(l), g_H(r)) − M h²/8 with an explicit bound M ≥ |g_H''| on [l, r] (from
bounds on P, Y_r, Y_i and their ρ-derivatives at ρ(r), |sin θ| on [l, r] and the
factors m, m² of the oscillating terms).  Every coefficient is computed together with
a magnitude companion (the same arithmetic on absolute values), and every comparison
carries a slack of 10⁻¹³ (1 + m) times the magnitude — hundreds of ulps, covering the
round-off of the coefficients and of the evaluation.  A tangency (g_H = 0 somewhere,
e.g. at θ = 0) is left ``inconclusive``, never ``certified``.

**Internal stability** is Schur stability of Δ, decided in the well-conditioned w-form
by the bilinear conditions of :func:`stringstab.derive.sampled_symbolic.schur_conditions`
(with a relative 10⁻¹² band left inconclusive).  The delay adds m + 1 poles at z = 0.

Verdicts: ``certified`` (Schur and g_H ≥ 0 on [0, π], so sup_θ |H(e^{jθ})| = 1,
attained at θ = 0), ``not_certified`` (not Schur, or some θ with g_H(θ) < −slack, a
witness with |H(e^{jθ})| > 1), ``inconclusive`` (neither shown within the budget).

References
----------
IDL paper, eqs 3-9 (model) and eq 4 (law); :mod:`stringstab.derive.sampled_symbolic`.
N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM (2002),
§3.1 (the error bound γ_n × the computation on absolute values).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt

from ..io import TableColumn
from ..params import Box, Params, as_gains, check_params, positive
from ..params import sample_time as _sample_time
from .branch_bound import BranchAndBound, Evaluate, branch_and_bound, verdict_codes, zoom_max
from .excess import EXCESS_SEARCH
from .verdicts import CERTIFIED as CERTIFIED_CODE
from .verdicts import (
    INCONCLUSIVE,
    NOT_CERTIFIED,
    ROUNDOFF_SLACK,
    ROW_COLUMNS,
    VERDICTS,
    BatchResult,
    Check,
    SingleResult,
    chunks,
    names,
    one_triple,
)

__all__ = [
    "TABLE_COLUMNS",
    "VERDICTS",
    "SampledCertificate",
    "SampledCertificateBatch",
    "SampledCheck",
    "certify_sampled",
    "certify_sampled_batch",
    "check_sampled",
    "sampled_margin",
    "sampled_response",
    "schur",
    "schur_margins",
    "spectral_radius",
    "split_delay",
]

Array = npt.NDArray[np.float64]

_CERT, _NOT, _INC = CERTIFIED_CODE, NOT_CERTIFIED, INCONCLUSIVE

_SLACK = ROUNDOFF_SLACK  # on g_H, per unit of the magnitude companion
_SCHUR_RTOL = 1e-12  # relative band around the Schur boundary left inconclusive


# ---------------------------------------------------------------------------
# The ZOH integrals of a lag: φ1, ψ2, ψ3 without cancellation
# ---------------------------------------------------------------------------
_INV_FACT = [1.0 / math.factorial(k) for k in range(40)]


def _phi(x: npt.ArrayLike) -> tuple[Array, Array, Array]:
    """(φ1, ψ2, ψ3) = (1 − e^{−x}, x − φ1, x²/2 − ψ2) for x ≥ 0, each to a few ulps.

    For x ≤ 1, ψ3 = Σ_{k≥3} (−1)^{k+1} x^k/k! (24 terms: truncation < 10⁻²⁸ relative),
    then ψ2 = x²/2 − ψ3 and φ1 = x − ψ2 (no cancellation: ψ3 ≤ x²/6, ψ2 ≤ x/2);
    for x > 1 the direct forms (cancellation ratio < 16).
    """
    x = np.asarray(x, dtype=float)
    xs = np.minimum(x, 1.0)
    acc = np.zeros_like(xs)
    for k in range(26, 2, -1):  # Horner on x³ Σ (−x)^{k−3}/k!
        acc = acc * (-xs) + _INV_FACT[k]
    p3s = acc * xs * xs * xs
    p2s = 0.5 * xs * xs - p3s
    p1s = xs - p2s
    p1l = -np.expm1(-x)
    p2l = x - p1l
    p3l = 0.5 * x * x - p2l
    small = x <= 1.0
    return np.where(small, p1s, p1l), np.where(small, p2s, p2l), np.where(small, p3s, p3l)


# ---------------------------------------------------------------------------
# Interval arithmetic with a magnitude companion (points are intervals lo = hi)
# ---------------------------------------------------------------------------
class _Iv:
    """[lo, hi] with ``mag`` ≥ the magnitude of every intermediate (round-off bound).

    A point has ``hi is lo``.  Only +, −, × are defined: the computed end points are
    within 10⁻¹³ × ``mag`` of the exact interval operations (γ_n for depth n ≤ 400).
    """

    __slots__ = ("hi", "lo", "mag")

    def __init__(self, lo: Any, hi: Any = None, mag: Any = None) -> None:
        self.lo = np.asarray(lo, dtype=float)
        self.hi = self.lo if hi is None else np.asarray(hi, dtype=float)
        self.mag = np.maximum(np.abs(self.lo), np.abs(self.hi)) if mag is None else mag

    @property
    def point(self) -> bool:
        return self.hi is self.lo

    @staticmethod
    def of(v: Any) -> _Iv:
        return v if isinstance(v, _Iv) else _Iv(np.asarray(v, dtype=float))

    def __add__(self, o: Any) -> _Iv:
        o = _Iv.of(o)
        if self.point and o.point:
            return _Iv(self.lo + o.lo, None, self.mag + o.mag)
        return _Iv(self.lo + o.lo, self.hi + o.hi, self.mag + o.mag)

    __radd__ = __add__

    def __neg__(self) -> _Iv:
        if self.point:
            return _Iv(-self.lo, None, self.mag)
        return _Iv(-self.hi, -self.lo, self.mag)

    def __sub__(self, o: Any) -> _Iv:
        return self + (-_Iv.of(o))

    def __rsub__(self, o: Any) -> _Iv:
        return _Iv.of(o) + (-self)

    def __mul__(self, o: Any) -> _Iv:
        o = _Iv.of(o)
        if self.point and o.point:
            return _Iv(self.lo * o.lo, None, self.mag * o.mag)
        p = (self.lo * o.lo, self.lo * o.hi, self.hi * o.lo, self.hi * o.hi)
        return _Iv(np.minimum.reduce(p), np.maximum.reduce(p), self.mag * o.mag)

    __rmul__ = __mul__

    def const(self, v: Any) -> _Iv:
        """A point constant of this item's shape."""
        return _Iv(np.zeros_like(self.lo) + v)


class _Ad:
    """Forward-mode derivative enclosures over a parameter cell (the mean-value form).

    ``c`` is the value at the cell's centre (a point :class:`_Iv`), ``r`` an enclosure of
    the value over the cell and ``g[i]`` an enclosure of ∂/∂p_i over the cell.  For any
    member p: value(p) ∈ c + Σ_i g[i] (p_i − c_i) (mean-value theorem), which is
    tighter than ``r`` (the natural interval extension) on small cells.
    """

    __slots__ = ("c", "g", "r")

    def __init__(self, c: _Iv, r: _Iv, g: tuple[_Iv, ...]) -> None:
        self.c, self.r, self.g = c, r, g

    def const(self, v: Any) -> _Ad:
        k = self.c.const(v)
        z = self.c.const(0.0)
        return _Ad(k, k, tuple(z for _ in self.g))

    @staticmethod
    def of(v: Any, like: _Ad) -> _Ad:
        return v if isinstance(v, _Ad) else like.const(v)

    def __add__(self, o: Any) -> _Ad:
        o = _Ad.of(o, self)
        return _Ad(self.c + o.c, self.r + o.r, tuple(a + b for a, b in zip(self.g, o.g)))

    __radd__ = __add__

    def __neg__(self) -> _Ad:
        return _Ad(-self.c, -self.r, tuple(-a for a in self.g))

    def __sub__(self, o: Any) -> _Ad:
        return self + (-_Ad.of(o, self))

    def __rsub__(self, o: Any) -> _Ad:
        return _Ad.of(o, self) + (-self)

    def __mul__(self, o: Any) -> _Ad:
        if not isinstance(o, _Ad):
            k = _Iv.of(o)
            return _Ad(self.c * k, self.r * k, tuple(a * k for a in self.g))
        return _Ad(self.c * o.c, self.r * o.r,
                   tuple(a * o.r + self.r * b for a, b in zip(self.g, o.g)))

    __rmul__ = __mul__


def _phi_iv(x_lo: Array, x_hi: Array) -> tuple[_Iv, _Iv, _Iv]:
    """φ1, ψ2, ψ3 over x ∈ [x_lo, x_hi]: all three increase with x."""
    lo = _phi(x_lo)
    if x_hi is x_lo:
        return tuple(_Iv(v) for v in lo)  # type: ignore[return-value]
    hi = _phi(x_hi)
    return tuple(_Iv(a, b) for a, b in zip(lo, hi))  # type: ignore[return-value]


def _iv(lo: Array, hi: Array) -> _Iv:
    return _Iv(lo) if hi is lo else _Iv(lo, hi)


# ---------------------------------------------------------------------------
# Coefficients
# ---------------------------------------------------------------------------
@dataclass
class _Coeffs:
    """w-form coefficients (δ, ν, ℓ) and the margin polynomials P, Y_r, Y_i in ρ."""

    delta: list[Any]  # δ0, δ1, δ2 (δ3 = 1); _Iv, or _Ad over a cell
    nu: list[Any]
    ell: list[Any]
    phi1: Any
    phi1p: Any
    P: list[Any]
    Yr: list[Any]
    Yi: list[Any]


def _poly_mul(a: list[_Iv], b: list[_Iv]) -> list[_Iv]:
    out: list[_Iv | None] = [None] * (len(a) + len(b) - 1)
    for i, ai in enumerate(a):
        for j, bj in enumerate(b):
            t = ai * bj
            cur = out[i + j]
            out[i + j] = t if cur is None else cur + t
    return [o for o in out if o is not None]


def _poly_add(a: list[_Iv], b: list[_Iv], sign: float = 1.0) -> list[_Iv]:
    n = max(len(a), len(b))
    out = []
    for k in range(n):
        x = a[k] if k < len(a) else None
        y = b[k] if k < len(b) else None
        if y is not None and sign < 0:
            y = -y
        out.append(x if y is None else y if x is None else x + y)  # type: ignore[operator]
    return out  # type: ignore[return-value]


def _scale(c: _Iv, p: list[_Iv]) -> list[_Iv]:
    return [c * q for q in p]


# Re(w^j) = R_j(ρ), Im(w^j) = sin θ · T_j(ρ), and R_j/ρ (j ≥ 1), as ascending ρ-coefficients:
# w + w̄ = −ρ, w w̄ = ρ, so w^j + w̄^j follows s_j = −ρ s_{j−1} − ρ s_{j−2}.
_R = {0: [1.0], 1: [0.0, -0.5], 2: [0.0, -1.0, 0.5], 3: [0.0, 0.0, 1.5, -0.5]}
_T = {0: [0.0], 1: [1.0], 2: [0.0, -1.0], 3: [0.0, -1.0, 1.0]}


def _const_poly(c: list[float], like: Any) -> list[Any]:
    return [like.const(v) for v in c]


def _abs2_over_rho(p: list[_Iv]) -> list[_Iv]:
    """(|Σ p_k w^k|² − p_0²)/ρ on the unit circle, as a polynomial in ρ.

    |Σp_k w^k|² = Σ_k p_k² ρ^k + 2 Σ_{k<l} p_k p_l ρ^k R_{l−k}(ρ); every term but p_0²
    carries a factor ρ (R_j(0) = 0 for j ≥ 1), divided out exactly.
    """
    out: list[_Iv] = []
    like = p[0]
    for k in range(1, len(p)):
        out = _poly_add(out, [like.const(0.0)] * (k - 1) + [p[k] * p[k]])
    for k in range(len(p)):
        for l_ in range(k + 1, len(p)):
            r = _R[l_ - k]
            # ρ^k R_j / ρ = ρ^{k-1} R_j  (k ≥ 1) or R_j/ρ (k = 0: drop R_j's zero constant)
            rr = ([0.0] * (k - 1) + r) if k >= 1 else r[1:]
            term = _scale(2.0 * (p[k] * p[l_]), _const_poly(rr, like))
            out = _poly_add(out, term)
    return out


def _cross(ell: list[_Iv], nu: list[_Iv]) -> tuple[list[_Iv], list[_Iv]]:
    """Y = ℓ(w)·conj(n(w)) = Y_r(ρ) + j sin θ · Y_i(ρ)."""
    like = ell[0]
    yr: list[_Iv] = []
    yi: list[_Iv] = []
    for a, la in enumerate(ell):
        for b, nb in enumerate(nu):
            c = la * nb
            lo_, d = min(a, b), abs(a - b)
            shift = [0.0] * lo_
            yr = _poly_add(yr, _scale(c, _const_poly(shift + _R[d], like)))
            if d:
                sgn = 1.0 if a > b else -1.0
                yi = _poly_add(yi, _scale(c, _const_poly(shift + [sgn * t for t in _T[d]], like)))
    return yr, yi


def _primitives_iv(
    kx: Array, kv: Array, ka: Array, *, H: float,
    tau: tuple[Array, Array], tau_p: tuple[Array, Array], eps: tuple[Array, Array],
    c: tuple[Array, Array],
) -> dict[str, _Iv]:
    """The model quantities over a cell by interval arithmetic (a point when lo is hi)."""
    T = _iv(*tau)
    Tp = _iv(*tau_p)
    # a point parameter gives one array for both ends, so that _phi_iv returns points and the
    # whole build takes the point path of _Iv (two arrays of equal values would be an interval)
    x_lo = H / tau[1]
    f1, p2, p3 = _phi_iv(x_lo, x_lo if tau[0] is tau[1] else H / tau[0])
    xp_lo = H / tau_p[1]
    xp_hi = xp_lo if tau_p[0] is tau_p[1] else H / tau_p[0]
    f1p, p2p, p3p = _phi_iv(xp_lo, xp_hi)
    point = tau_p[0] is tau_p[1] and eps[0] is eps[1]
    y_lo = (1.0 - eps[1]) * xp_lo
    y_hi = y_lo if point else (1.0 - eps[0]) * xp_hi
    ell1 = _phi_iv(y_lo, y_hi)[0]
    ex = _Iv(np.exp(-y_lo)) if point else _Iv(np.exp(-y_hi), np.exp(-y_lo))
    ex_lo = eps[0] * xp_lo
    cm = ex * _phi_iv(ex_lo, ex_lo if point else eps[1] * xp_hi)[0]
    return {"K_x": _Iv(kx), "K_v": _Iv(kv), "K_a": _Iv(ka), "T": T, "Tp": Tp, "Cc": _iv(*c),
            "f1": f1, "p2": p2, "p3": p3, "f1p": f1p, "p2p": p2p, "p3p": p3p,
            "ell1": ell1, "cm": cm}


def _build(q: dict[str, Any], H: float) -> _Coeffs:
    """δ, ν, ℓ and the margin polynomials from the primitives (any arithmetic type)."""
    K_x, K_v, K_a, T, Tp, Cc = (q[k] for k in ("K_x", "K_v", "K_a", "T", "Tp", "Cc"))
    f1, p2, p3, f1p, p2p, p3p = (q[k] for k in ("f1", "p2", "p3", "f1p", "p2p", "p3p"))
    ell1, cm = q["ell1"], q["cm"]
    Hs = float(H)
    d0 = K_x * (Hs * Hs) * f1
    d1 = Hs * (Cc * f1 + K_x * (T * p2 + (0.5 * Hs) * f1))
    d2 = f1 + Cc * T * p2 + K_x * T * T * p3
    n0 = K_x * (Hs * Hs) * f1p
    n1 = Hs * (K_v * f1p + K_x * (Tp * p2p + (0.5 * Hs) * f1p))
    n2 = K_v * Tp * p2p + K_x * Tp * Tp * p3p
    nu = [n0, n1, n2]
    ell = [f1p, ell1]
    # κ² = τ² τ_p² / H⁶ and the two prefactors κ φ1p (on Δ) and κ φ1 (on the numerator)
    kap = T * Tp * (1.0 / Hs**3)
    A = kap * f1p
    B = kap * f1
    A2, B2 = A * A, B * B
    Ad = _abs2_over_rho([d0, d1, d2, d0.const(1.0)])
    An = _abs2_over_rho(nu)
    # |ℓ|² = ℓ0² − ℓ1 (ℓ0 − ℓ1) ρ, with ℓ0 − ℓ1 = C − E_p = C (1 − e^{−εH/τ_p}) ≥ 0
    L = [f1p * f1p, -(ell1 * cm)]
    kaL = _scale(B2 * K_a * K_a, [d0.const(0.0), *L])
    P = _poly_add(_poly_add(_scale(A2, Ad), _scale(B2, An), -1.0), kaL, -1.0)
    yr, yi = _cross(ell, nu)
    k2 = 2.0 * (B2 * K_a)
    return _Coeffs([d0, d1, d2], nu, ell, f1, f1p, P, _scale(k2, yr), _scale(k2, yi))


def _coefficients(
    kx: Array, kv: Array, ka: Array, *, H: float,
    tau: tuple[Array, Array], tau_p: tuple[Array, Array], eps: tuple[Array, Array],
    c: tuple[Array, Array],
) -> _Coeffs:
    """All coefficients over a parameter cell (a point when every lo is its hi).

    ``tau``, ``tau_p``, ``eps`` and ``c`` = k_v + T* k_x are (lo, hi) pairs of arrays.
    """
    return _build(_primitives_iv(kx, kv, ka, H=H, tau=tau, tau_p=tau_p, eps=eps, c=c), H)


# ---------------------------------------------------------------------------
# Parameter cells: the mean-value form (used by stringstab.certify.robust)
# ---------------------------------------------------------------------------
def _param_ad(lo: Array, hi: Array, i: int, d: int) -> _Ad:
    mid = np.ascontiguousarray(0.5 * (lo + hi))
    c = _Iv(mid)
    return _Ad(c, _Iv(lo, hi), tuple(c.const(1.0 if j == i else 0.0) for j in range(d)))


def _recip_ad(t: _Ad, H: float) -> _Ad:
    """H/t for t > 0: decreasing, derivative −H/t² ∈ [−H/t_lo², −H/t_hi²]."""
    lo, hi = t.r.lo, t.r.hi
    dr = _Iv(-H / (lo * lo), -H / (hi * hi))
    return _Ad(_Iv(H / t.c.lo), _Iv(H / hi, H / lo), tuple(dr * gi for gi in t.g))


def _phi_ad(x: _Ad) -> tuple[_Ad, _Ad, _Ad]:
    """φ1, ψ2, ψ3 of x ≥ 0: increasing, with φ1' = 1 − φ1, ψ2' = φ1, ψ3' = ψ2."""
    c = tuple(_Iv(v) for v in _phi(x.c.lo))
    r = _phi_iv(x.r.lo, x.r.hi)
    ders = (1.0 - r[0], r[0], r[1])
    return tuple(_Ad(ci, ri, tuple(dk * gi for gi in x.g))  # type: ignore[return-value]
                 for ci, ri, dk in zip(c, r, ders))


def _exp_neg_ad(y: _Ad) -> _Ad:
    r = _Iv(np.exp(-y.r.hi), np.exp(-y.r.lo))
    return _Ad(_Iv(np.exp(-y.c.lo)), r, tuple(-(r * gi) for gi in y.g))


def _cell_coefficients(
    kx: Array, kv: Array, ka: Array, *, H: float, tau: Array, tau_p: Array | None,
    eps: Array, headway: Array,
) -> _Coeffs:
    """Coefficients with derivative enclosures over cells ((n, 2) bounds per parameter).

    The parameters are (τ, τ_p, ε, T*), or (τ, ε, T*) with τ_p = τ when ``tau_p`` is None.
    """
    d = 3 if tau_p is None else 4
    T = _param_ad(tau[:, 0], tau[:, 1], 0, d)
    Tp = T if tau_p is None else _param_ad(tau_p[:, 0], tau_p[:, 1], 1, d)
    E = _param_ad(eps[:, 0], eps[:, 1], d - 2, d)
    Th = _param_ad(headway[:, 0], headway[:, 1], d - 1, d)
    K_x, K_v, K_a = T.const(kx), T.const(kv), T.const(ka)
    f1, p2, p3 = _phi_ad(_recip_ad(T, H))
    xp = _recip_ad(Tp, H)
    f1p, p2p, p3p = _phi_ad(xp)
    y = (1.0 - E) * xp
    cm = _exp_neg_ad(y) * _phi_ad(E * xp)[0]
    q = {"K_x": K_x, "K_v": K_v, "K_a": K_a, "T": T, "Tp": Tp, "Cc": K_v + Th * K_x,
         "f1": f1, "p2": p2, "p3": p3, "f1p": f1p, "p2p": p2p, "p3p": p3p,
         "ell1": _phi_ad(y)[0], "cm": cm}
    return _build(q, H)


def _part(co: _Coeffs, f: Callable[[Any], _Iv]) -> _Coeffs:
    return _Coeffs([f(v) for v in co.delta], [f(v) for v in co.nu], [f(v) for v in co.ell],
                   f(co.phi1), f(co.phi1p), [f(v) for v in co.P], [f(v) for v in co.Yr],
                   [f(v) for v in co.Yi])


def _eval_cells(theta: Array, co: _Coeffs, m: Array, hw: Array) -> tuple[Array, Array, Array]:
    """(g_H at the cells' centres, a lower bound over the cells, slack) at θ (n, k).

    The lower bound is the larger of the natural interval extension and the mean-value
    form g(centre) − Σ_i max|∂g/∂p_i| · halfwidth_i (``hw``: (n, d) half-widths).
    """
    G, E = _eval_margin(theta, _part(co, lambda v: v.c), m)
    low_r, E_r = _eval_margin(theta, _part(co, lambda v: v.r), m)
    spread = _spread(theta, co, m, hw).sum(axis=-1)
    return G, np.maximum(low_r, G - spread), np.maximum(E, E_r)


def _grad_getter(i: int) -> Callable[[Any], _Iv]:
    def get(v: Any) -> _Iv:
        return v.g[i]  # type: ignore[no-any-return]

    return get


def _spread(theta: Array, co: _Coeffs, m: Array, hw: Array) -> Array:
    """max|∂g_H/∂p_i| × halfwidth_i at θ, per parameter i: shape θ.shape + (d,)."""
    out = np.zeros((*np.shape(theta), hw.shape[1]))
    for i in range(hw.shape[1]):
        if not np.any(hw[:, i] > 0):
            continue
        gi = _part(co, _grad_getter(i))
        lo, Ei = _eval_margin(theta, gi, m)
        nlo, _ = _eval_margin(theta, _part(gi, lambda v: -v), m)
        out[..., i] = (np.maximum(-lo, -nlo) + Ei) * hw[:, i][:, None]
    return out


#: A delay this close to a whole number of samples (relative to H) is that whole number.
WHOLE_SAMPLE_RTOL = 1e-9


def split_delay(delta: float, sample_time: float, *, whole: bool = True) -> tuple[int, float]:
    """δ = (m + ε) H with m an integer ≥ 0 and 0 ≤ ε < 1.

    A δ within :data:`WHOLE_SAMPLE_RTOL` of a sample of a whole number of samples is that
    whole number (ε = 0): ``0.3`` is not a multiple of ``0.1`` in binary floating point
    (``math.fmod(0.3, 0.1)`` is 0.0999...), but the delay meant, and the loop certified, is
    three samples, not two samples and 0.9999999999999998 of a third.  Otherwise the exact
    ``math.fmod`` gives m and ε.

    Parameters
    ----------
    delta, sample_time : float
        δ ≥ 0 and H > 0, s (not validated here).
    whole : bool
        Round a δ within :data:`WHOLE_SAMPLE_RTOL` H of a whole number of samples to it
        (default).  False: the exact split of the float δ (the robust certificate's box ends,
        which must cover every δ in the box).

    Returns
    -------
    (int, float)
        m and ε.

    Examples
    --------
    >>> split_delay(0.2, 0.1), split_delay(0.25, 0.1)[0], split_delay(0.0, 0.05)
    ((2, 0.0), 2, (0, 0.0))
    >>> split_delay(0.3, 0.1), split_delay(0.7, 0.1)
    ((3, 0.0), (7, 0.0))
    """
    n = round(delta / sample_time)
    if whole and abs(delta - n * sample_time) <= WHOLE_SAMPLE_RTOL * sample_time:
        return int(n), 0.0
    r = math.fmod(delta, sample_time)
    m = round((delta - r) / sample_time)
    return m, r / sample_time


def _validate(tau: Any, delta: Any, headway: Any, sample_time: Any,
              tau_prev: Any) -> tuple[Params, float, float]:
    p = Params(*check_params(tau, delta, headway))
    H = _sample_time(sample_time)
    tp = p.tau if tau_prev is None else positive("tau_prev (predecessor's actuator lag)",
                                                  tau_prev, unit=" s")
    return p, H, tp


def _point_coeffs(kx: Array, kv: Array, ka: Array, p: Params, H: float, tp: float) -> tuple[_Coeffs, int]:
    m, eps = split_delay(p.delta, H)
    n = kx.size
    t = np.full(n, p.tau)
    t_p = np.full(n, tp)
    e = np.full(n, eps)
    c = kv + p.headway * kx
    return _coefficients(kx, kv, ka, H=H, tau=(t, t), tau_p=(t_p, t_p), eps=(e, e), c=(c, c)), m


# ---------------------------------------------------------------------------
# Frequency response and margin
# ---------------------------------------------------------------------------
def _polyval(coefs: list[Array], rho: Array) -> Array:
    out = np.zeros(np.broadcast_shapes(np.shape(rho), *(np.shape(c) for c in coefs)))
    for c in reversed(coefs):
        out = out * rho + c
    return out


def _response(theta: Array, co: _Coeffs, m: int, ka: Array) -> npt.NDArray[np.complex128]:
    s2 = np.sin(0.5 * theta)
    w = 2j * s2 * np.exp(0.5j * theta)  # e^{jθ} − 1 without cancellation
    d0, d1, d2 = (x.lo for x in co.delta)
    n0, n1, n2 = (x.lo for x in co.nu)
    l0, l1 = (x.lo for x in co.ell)
    D = ((w + d2) * w + d1) * w + d0
    N = (n2 * w + n1) * w + n0 + np.exp(-1j * (m + 1) * theta) * ka * w * w * (l0 + l1 * w)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.asarray(co.phi1.lo / co.phi1p.lo * N / D)


def _on_circle(theta: Any, k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any,
               sample_time: Any, tau_prev: Any) -> tuple[Array, Array, _Coeffs, int,
                                                         tuple[int, ...]]:
    """Validated, broadcast and flattened θ and k_a, the coefficients, m and the shape."""
    p, H, tp = _validate(tau, delta, headway, sample_time, tau_prev)
    th = np.asarray(theta, dtype=float)
    kx, kv, ka = as_gains(k_x, k_v, k_a)
    shape = np.broadcast_shapes(th.shape, kx.shape)
    kx, kv, ka, th = (np.broadcast_to(v, shape).ravel() for v in (kx, kv, ka, th))
    co, m = _point_coeffs(kx, kv, ka, p, H, tp)
    return th, ka, co, m, shape


def sampled_response(
    theta: npt.ArrayLike, k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: float, delta: float, headway: float, sample_time: float,
    tau_prev: float | None = None,
) -> npt.NDArray[np.complex128]:
    """H(e^{jθ}): the sampled string transfer function on the unit circle.

    Parameters
    ----------
    theta : array_like
        Normalised frequency θ = ωH in rad per sample, broadcast against the gains.
    k_x, k_v, k_a : array_like
        Gains (broadcast together).
    tau, delta, headway : float
        Actuator lag τ > 0, delay δ ≥ 0 (any real: exact between samples), headway T* ≥ 0.
    sample_time : float
        Sampling period H > 0 of every vehicle (zero-order hold), s.
    tau_prev : float, optional
        The predecessor's actuator lag (default τ: a homogeneous platoon).

    Returns
    -------
    ndarray of complex
        ``nan`` where Δ(e^{jθ}) = 0.

    Examples
    --------
    >>> h = sampled_response([0.0, 0.3], 1.2, 0.5, 0.6, tau=0.1, delta=0.2, headway=1.1,
    ...                      sample_time=0.1)
    >>> np.round(np.abs(h), 6).tolist()
    [1.0, 0.760411]
    """
    th, ka, co, m, shape = _on_circle(theta, k_x, k_v, k_a, tau, delta, headway, sample_time,
                                      tau_prev)
    # H(1) = 1 whenever Δ(1) ≠ 0 (k_x ≠ 0); at k_x = 0 the w-form gives 0/0 = nan at θ = 0
    return _response(th, co, m, ka).reshape(shape)


def _eval_margin(theta: Array, co: _Coeffs, m: Array | int) -> tuple[Array, Array]:
    """(lower bound of g_H over the coefficient cell, round-off slack) at θ.

    For point coefficients the lower bound is g_H itself.  Coefficients broadcast as
    columns against ``theta`` of shape (n, k).
    """
    rho = 4.0 * np.sin(0.5 * theta) ** 2
    st = np.sin(theta)
    mm = np.asarray(m, dtype=float)
    mcol = mm[:, None] if mm.ndim else mm
    cm = np.cos(mcol * theta)
    f = np.sin(mcol * theta) * st

    def col(x: Array) -> Array:
        return x[:, None] if np.ndim(x) and np.ndim(theta) == 2 else x

    P_lo = _polyval([col(c.lo) for c in co.P], rho)
    Yr_lo = _polyval([col(c.lo) for c in co.Yr], rho)
    Yi_lo = _polyval([col(c.lo) for c in co.Yi], rho)
    mag = (_polyval([col(c.mag) for c in co.P], rho)
           + (1.0 + mcol) * (_polyval([col(c.mag) for c in co.Yr], rho)
                             + np.abs(st) * _polyval([col(c.mag) for c in co.Yi], rho)))
    slack = _SLACK * (1.0 + mcol) * mag
    if all(c.point for c in (*co.P, *co.Yr, *co.Yi)):
        return P_lo + cm * Yr_lo + f * Yi_lo, slack
    Yr_hi = _polyval([col(c.hi) for c in co.Yr], rho)
    Yi_hi = _polyval([col(c.hi) for c in co.Yi], rho)
    low = P_lo + np.where(cm >= 0, cm * Yr_lo, cm * Yr_hi) + np.where(f >= 0, f * Yi_lo, f * Yi_hi)
    return np.asarray(low), slack


def sampled_margin(
    theta: npt.ArrayLike, k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: float, delta: float, headway: float, sample_time: float,
    tau_prev: float | None = None,
) -> Array:
    """g_H(θ) = τ²τ_p²(|D|² − |N|²)/(H⁶ ρ): ≥ 0 iff |H(e^{jθ})| ≤ 1 (module docstring).

    Tends to the continuous margin g(ω) of :func:`stringstab.certify.frequency.margin_g` at
    θ = ωH as H → 0; at θ = 0 it is the sampled analogue of Ψ3
    (:func:`stringstab.derive.sampled_symbolic.dc_margin`).

    Parameters
    ----------
    theta, k_x, k_v, k_a, tau, delta, headway, sample_time, tau_prev
        As for :func:`sampled_response`.

    Returns
    -------
    ndarray
        g_H at each θ (broadcast shape).

    Examples
    --------
    >>> from stringstab.certify.frequency import margin_g
    >>> kw = dict(tau=0.1, delta=0.2, headway=1.1)
    >>> gc = margin_g(1.5, 1.2, 0.5, 0.6, **kw)
    >>> [round(float(sampled_margin(H * 1.5, 1.2, 0.5, 0.6, sample_time=H, **kw) - gc), 3)
    ...  for H in (0.1, 0.01, 0.001)]  # the gap shrinks like H
    [-2.117, -0.471, -0.052]
    """
    th, _, co, m, shape = _on_circle(theta, k_x, k_v, k_a, tau, delta, headway, sample_time,
                                     tau_prev)
    return np.asarray(_eval_margin(th, co, m)[0]).reshape(shape)


# ---------------------------------------------------------------------------
# Schur stability
# ---------------------------------------------------------------------------
def _schur_terms(delta: list[_Iv]) -> list[_Iv]:
    """The five quantities of :func:`stringstab.derive.sampled_symbolic.schur_conditions` (each > 0)."""
    d0, d1, d2 = delta
    b0 = d0
    b1 = 2.0 * d1 - 3.0 * d0
    b2 = 3.0 * d0 - 4.0 * d1 + 4.0 * d2
    b3 = 8.0 - d0 + 2.0 * d1 - 4.0 * d2
    h2 = 8.0 * (d1 * d2 - d0 * d2 - d1 * d1 + 2.0 * (d0 * d1) - d0 * d0 - d0)
    return [b0, b1, b2, b3, h2]


def _schur_bands(delta: list[_Iv]) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
    """(surely Schur, surely not Schur) with a relative band around the boundary."""
    terms = _schur_terms(delta)
    sure = np.ones(np.shape(delta[0].lo), dtype=bool)
    fail = np.zeros_like(sure)
    for t in terms:
        band = _SCHUR_RTOL * t.mag
        sure &= t.lo > band
        fail |= t.hi <= -band  # the boundary itself (a root on |z| = 1) is not Schur
    return sure, fail


def _loop_delta(k_x: Any, k_v: Any, tau: Any, headway: Any,
                sample_time: Any) -> tuple[list[_Iv], tuple[int, ...]]:
    """δ0, δ1, δ2 of the follower's loop (flattened) and the gains' shape."""
    p = Params(*check_params(tau, 0.0, headway))
    H = _sample_time(sample_time)
    kx, kv, _ = as_gains(k_x, k_v, 0.0)
    shape = kx.shape
    kx, kv = kx.ravel(), kv.ravel()
    return _point_coeffs(kx, kv, np.zeros_like(kx), p, H, p.tau)[0].delta, shape


def schur(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, *, tau: float, headway: float, sample_time: float,
) -> npt.NDArray[np.bool_]:
    """Internal stability of the sampled loop: is Δ(z) Schur (all roots inside |z| < 1)?

    Decided by the bilinear conditions (:func:`stringstab.derive.sampled_symbolic.schur_conditions`)
    in the w-form; True only outside a relative 10⁻¹² band around the boundary.  Δ does not
    depend on δ, k_a or the predecessor's lag.

    Parameters
    ----------
    k_x, k_v : array_like
        Gains (broadcast together).
    tau, headway, sample_time : float
        τ > 0, T* ≥ 0, H > 0 (s).

    Returns
    -------
    ndarray of bool

    Raises
    ------
    StringStabError
        On parameters out of range or non-finite gains.

    Examples
    --------
    >>> schur([1.2, 1.2, -0.5], [0.5, 40.0, 1.0], tau=0.1, headway=1.1, sample_time=0.1).tolist()
    [True, False, False]
    """
    delta, shape = _loop_delta(k_x, k_v, tau, headway, sample_time)
    return _schur_bands(delta)[0].reshape(shape)


def schur_margins(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, *, tau: float, headway: float, sample_time: float,
) -> Array:
    """The five Schur conditions of Δ(z), each divided by its leading order in H (> 0 iff Schur).

    The conditions of :func:`stringstab.derive.sampled_symbolic.schur_conditions` (b0, b1, b2, b3 and
    the Hurwitz determinant h2) divided by H²φ1, 2Hφ1, 4φ1, 8 and 8τx³ (x = H/τ, φ1 = 1 − e^{−x}),
    so that as H → 0 they tend to k_x, c = k_v + T*k_x, 1, 1 and k_v + (T* − τ)k_x: the
    continuous Hurwitz conditions and the same margins (the gain repair of
    :mod:`stringstab.tuning` asks each to be ≥ a margin).  Each is a polynomial of degree ≤ 2
    in the gains.

    Parameters
    ----------
    k_x, k_v : array_like
        Position gain k_x (1/s²) and velocity gain k_v (1/s), broadcast together.
    tau : float
        Actuator lag τ > 0, s.
    headway : float
        Desired time headway T* ≥ 0, s.
    sample_time : float
        Sampling period H > 0, s.

    Returns
    -------
    ndarray, shape (5,) + the gains' shape

    Examples
    --------
    >>> np.round(schur_margins(1.2, 0.5, tau=0.1, headway=1.1, sample_time=1e-4), 3).tolist()
    [1.2, 1.82, 1.0, 1.0, 1.7]
    """
    delta, shape = _loop_delta(k_x, k_v, tau, headway, sample_time)
    H = float(sample_time)
    x = H / float(tau)
    f1 = float(_phi(x)[0])
    scale = np.array([H * H * f1, 2.0 * H * f1, 4.0 * f1, 8.0, 8.0 * float(tau) * x**3])
    terms = np.stack([t.lo for t in _schur_terms(delta)])
    return np.asarray(terms / scale[:, None]).reshape((5, *shape))


def _z_coeffs(delta: list[Array]) -> tuple[Array, Array, Array]:
    d0, d1, d2 = delta
    # Δ(z) = (z−1)³ + δ2 (z−1)² + δ1 (z−1) + δ0 = z³ + a2 z² + a1 z + a0
    return d2 - 3.0, 3.0 - 2.0 * d2 + d1, d2 - d1 + d0 - 1.0


def spectral_radius(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, *, tau: float, headway: float, sample_time: float,
) -> Array:
    """max |root| of Δ(z) (< 1 iff Schur), from companion-matrix eigenvalues.

    Raises :class:`~stringstab.errors.StringStabError` on bad input, as :func:`schur`.

    Parameters
    ----------
    k_x, k_v : array_like
        Position gain k_x (1/s²) and velocity gain k_v (1/s), broadcast together.
    tau : float
        Actuator lag τ > 0, s.
    headway : float
        Desired time headway T* ≥ 0, s.
    sample_time : float
        Sampling period H > 0, s.

    Returns
    -------
    ndarray
        The spectral radius max |z| over the three roots of Δ(z), of the gains' shape.

    Examples
    --------
    >>> float(np.round(spectral_radius(1.2, 0.5, tau=0.1, headway=1.1, sample_time=0.1), 4))
    0.8888
    """
    delta, shape = _loop_delta(k_x, k_v, tau, headway, sample_time)
    return _spectral_radius([d.lo for d in delta]).reshape(shape)


def _poles(delta: list[Array]) -> npt.NDArray[np.complex128]:
    """The roots of Δ(z), one row of three per triple (companion-matrix eigenvalues)."""
    a2, a1, a0 = _z_coeffs(delta)
    n = a2.size
    if not n:
        return np.zeros((0, 3), dtype=complex)
    C = np.zeros((n, 3, 3))
    C[:, 0, :] = -np.stack([a2, a1, a0], axis=1)
    C[:, 1, 0] = 1.0
    C[:, 2, 1] = 1.0
    return np.asarray(np.linalg.eigvals(C), dtype=complex)


def _spectral_radius(delta: list[Array]) -> Array:
    return np.asarray(np.abs(_poles(delta)).max(axis=1) if delta[0].size else np.zeros(0))


def _pole_angles(delta: list[Array]) -> Array:
    """|arg z| ∈ [0, π] of the roots of Δ(z): where a lightly damped pole makes |H| peak."""
    return np.abs(np.angle(_poles(delta)))


# ---------------------------------------------------------------------------
# Branch and bound over θ (and, for the robust certificate, over parameter cells)
# ---------------------------------------------------------------------------
def _bounds_poly(c: list[_Iv], rho_r: Array) -> tuple[Array, Array, Array]:
    """(max|Q|, max|Q_ρ|, max|Q_ρρ|) over ρ ∈ [0, ρ_r] for Q with coefficients c (≤ 2)."""
    a = [np.maximum(np.abs(q.lo), np.abs(q.hi)) + _SLACK * q.mag for q in c]
    A0 = np.zeros_like(rho_r)
    A1 = np.zeros_like(rho_r)
    A2 = np.zeros_like(rho_r)
    for j, aj in enumerate(a):
        aj = aj[:, None] if rho_r.ndim == 2 else aj
        A0 = A0 + aj * rho_r**j
        if j >= 1:
            A1 = A1 + j * aj * rho_r ** (j - 1)
        if j >= 2:
            A2 = A2 + j * (j - 1) * aj * rho_r ** (j - 2)
    return A0, A1, A2


def _curvature(co: _Coeffs, m: Array, L: Array, R: Array) -> Array:
    """M ≥ |g_H''(θ)| on [L, R] (module docstring; derivation in docs/sampled.md)."""
    rho_r = 4.0 * np.sin(0.5 * R) ** 2
    S1 = np.where(R <= 0.5 * np.pi, np.sin(R), np.where(L >= 0.5 * np.pi, np.sin(L), 1.0))
    mm = m[:, None] if (np.ndim(m) and R.ndim == 2) else m

    def d2(c: list[_Iv]) -> tuple[Array, Array, Array]:
        A0, A1, A2 = _bounds_poly(c, rho_r)
        return A0, 2.0 * S1 * A1, 4.0 * S1 * S1 * A2 + 2.0 * A1

    _, _, p2 = d2(co.P)
    r0, r1, r2 = d2(co.Yr)
    i0, i1, i2 = d2(co.Yi)
    f0 = S1
    f1 = mm * S1 + 1.0
    f2 = (mm * mm + 1.0) * S1 + 2.0 * mm
    return np.asarray(p2 + (mm * mm * r0 + 2.0 * mm * r1 + r2) + (f2 * i0 + 2.0 * f1 * i1 + f0 * i2))


def _take(co: _Coeffs, idx: npt.NDArray[np.intp]) -> _Coeffs:
    def t(x: _Iv) -> _Iv:
        lo = x.lo[idx]
        return _Iv(lo, None, x.mag[idx]) if x.point else _Iv(lo, x.hi[idx], x.mag[idx])

    return _Coeffs([t(v) for v in co.delta], [t(v) for v in co.nu], [t(v) for v in co.ell],
                   t(co.phi1), t(co.phi1p), [t(v) for v in co.P],
                   [t(v) for v in co.Yr], [t(v) for v in co.Yi])


def _point_evaluator(co: _Coeffs, m: int) -> Evaluate:
    """The :data:`~stringstab.certify.branch_bound.Evaluate` of g_H for point coefficients."""
    mm = np.full(co.P[0].lo.size, float(m))

    def evaluate(idx: npt.NDArray[np.intp], X: Array) -> tuple[Array, Array, Array, Array]:
        sub = _take(co, idx)
        G, E = _eval_margin(X, sub, mm[idx])
        return G, G, E, _curvature(sub, mm[idx], X[:, :-1], X[:, 1:])

    return evaluate


def _bnb_points(
    co: _Coeffs, m: int, *, n_grid: int, max_rounds: int, max_intervals: int,
    refine: npt.NDArray[np.bool_] | None = None,
) -> BranchAndBound:
    """Branch and bound of g_H ≥ 0 on [0, π] for point coefficients (one item per triple)."""
    n = co.P[0].lo.size
    return branch_and_bound(n, _point_evaluator(co, m), right=np.full(n, np.pi), n_grid=n_grid,
                            max_rounds=max_rounds, max_intervals=max_intervals, refine=refine)


# ---------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class SampledCheck(Check):
    """Verdicts only (see :func:`check_sampled`): a :class:`~stringstab.certify.verdicts.Check` whose
    ``hurwitz`` is Schur stability of Δ(z), with ``sample_time`` and ``witness_theta``.

    Attributes
    ----------
    verdict : ndarray of str
        ``"certified"``, ``"not_certified"`` or ``"inconclusive"``.
    hurwitz : ndarray of bool
        Internally stable (Δ Schur, surely, outside the 10⁻¹² boundary band); also
        :attr:`schur`.
    margin : ndarray
        Smallest g_H(θ) found.
    witness_omega, witness_theta : ndarray
        Where (ω = θ/H in rad/s, θ in rad/sample): for a Schur, not-certified triple a
        frequency with |H(e^{jθ})| > 1.
    """

    @property
    def schur(self) -> npt.NDArray[np.bool_]:
        """Δ(z) is Schur (internal stability of the sampled loop)."""
        return self.hurwitz


def _prepare(k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any, headway: Any,
             sample_time: Any, tau_prev: Any) -> tuple[Array, Array, Array, Params, float, float]:
    p, H, tp = _validate(tau, delta, headway, sample_time, tau_prev)
    kx, kv, ka = (np.ascontiguousarray(v, dtype=float).ravel() for v in as_gains(k_x, k_v, k_a))
    return kx, kv, ka, p, H, tp


def _default_grid(m: int) -> int:
    return 64 + 8 * m


def check_sampled(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: float, delta: float, headway: float, sample_time: float,
    tau_prev: float | None = None, n_grid: int | None = None, max_rounds: int = 30,
    max_intervals: int = 1024,
) -> SampledCheck:
    """The sampled certificate's verdicts alone, for inner loops.

    The same sound decision as :func:`certify_sampled_batch` without the peak search and
    the spectral radii.

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains, broadcast together and flattened.
    tau, delta, headway : float
        Lag τ > 0, delay δ ≥ 0 (any real), headway T* ≥ 0 (seconds).
    sample_time : float
        Sampling period H > 0, s.
    tau_prev : float, optional
        The predecessor's lag (default τ).
    n_grid, max_rounds, max_intervals : int
        Initial intervals on [0, π] (default 64 + 8m), refinement rounds, and the cap on
        undecided intervals per triple beyond which it is inconclusive.

    Returns
    -------
    SampledCheck

    Examples
    --------
    >>> check_sampled([1.2, 0.9], [0.5, -0.5], [0.6, 1.1], tau=0.1, delta=0.2, headway=1.1,
    ...               sample_time=0.1).verdict.tolist()
    ['certified', 'not_certified']
    """
    kx, kv, ka, p, H, tp = _prepare(k_x, k_v, k_a, tau, delta, headway, sample_time, tau_prev)
    co, m = _point_coeffs(kx, kv, ka, p, H, tp)
    sure, fail = _schur_bands(co.delta)
    bb = _bnb_points(co, m, n_grid=n_grid or _default_grid(m), max_rounds=max_rounds,
                     max_intervals=max_intervals, refine=~fail)
    v = verdict_codes(bb.status)
    v[~sure] = np.where(fail[~sure], _NOT, _INC)
    return SampledCheck(names(v), sure, bb.minimum, bb.argmin / H, sample_time=H,
                        witness_theta=bb.argmin)


def _peak(co: _Coeffs, m: int, ka: Array, W: Array, worst: Array) -> tuple[Array, Array]:
    """sup_θ |H(e^{jθ})| on [0, π] and where (reporting only; the verdict never uses it)."""
    n = ka.size
    rows = np.arange(n)
    Wall = np.concatenate([W, worst[:, None]], axis=1)

    def absH(th: Array) -> Array:
        cols = _Coeffs(
            [_Iv(d.lo[:, None]) for d in co.delta], [_Iv(d.lo[:, None]) for d in co.nu],
            [_Iv(d.lo[:, None]) for d in co.ell], _Iv(co.phi1.lo[:, None]),
            _Iv(co.phi1p.lo[:, None]), co.P, co.Yr, co.Yi)
        a = np.abs(_response(th, cols, m, ka[:, None]))
        return np.where(np.isnan(a), np.inf, a)

    A = absH(Wall)
    A[:, 0] = np.where(co.delta[0].lo != 0, 1.0, A[:, 0])  # H(1) = 1 exactly
    half = np.full(n, np.pi / (W.shape[1] - 1))
    j = np.argmax(A, axis=1)
    best, where = zoom_max(absH, Wall[rows, j], A[rows, j], half, hi=np.pi)
    # A lightly damped pole of the loop (radius near 1) makes a resonance narrower than the
    # grid, which can sit between two grid points below another local maximum: zoom also
    # from the angles of the poles of Δ(z), and keep the larger peak.
    P = _pole_angles([d.lo for d in co.delta])
    Ap = absH(P)
    k = np.argmax(Ap, axis=1)
    pb, pw = zoom_max(absH, P[rows, k], Ap[rows, k], half, hi=np.pi)
    take = pb > best
    return np.where(take, pb, best), np.where(take, pw, where)


def _excess_squared(theta: Array, co: _Coeffs, m: int, kappa: Array) -> Array:
    """|H(e^{jθ})|² − 1 = −ρ g_H(θ) / (κ² φ1p² |Δ(w)|²), without the cancellation of |H|² − 1.

    From the margin's definition (module docstring) with κ = τ τ_p/H³:
    φ1p²|Δ|² − φ1²|n + z^{−(m+1)} k_a w² ℓ|² = ρ g_H/κ², divided by φ1p²|Δ|².  g_H is
    evaluated from its polynomial coefficients, so an excess of 10⁻²⁰ near θ = 0 (a DC
    margin just below 0), which |H|² computed directly rounds to exactly 1, keeps its sign
    and digits.  ``co`` holds point coefficients, one row per triple; ``theta`` is (n, k).
    """
    g, _ = _eval_margin(theta, co, np.full(co.P[0].lo.size, float(m)))
    s2 = np.sin(0.5 * theta)
    rho = 4.0 * s2 * s2
    w = 2j * s2 * np.exp(0.5j * theta)
    d0, d1, d2 = (x.lo[:, None] for x in co.delta)
    D = ((w + d2) * w + d1) * w + d0
    den = (kappa * co.phi1p.lo)[:, None] ** 2 * (D.real * D.real + D.imag * D.imag)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        out = -rho * g / den
    return np.asarray(np.where(den > 0, out, np.inf))


def _violation_peak(co: _Coeffs, m: int, kappa: Array, cand: Array) -> tuple[Array, Array]:
    """max over θ ∈ (0, π] of |H(e^{jθ})|² − 1 (:func:`_excess_squared`) and where.

    For not-certified Schur rows: a logarithmic grid θ = π·10^u, u ∈ [−12, 0] (a violation
    from a DC margin just below 0 sits near θ → 0 and can be 10⁻²⁰), the candidates ``cand``
    (n, k) (the peak of :func:`_peak` and the branch and bound's witness), then a refinement
    in log θ.  Reporting only: the verdict is the branch and bound's.
    """
    n = kappa.size
    rows = np.arange(n)
    u = np.linspace(-12.0, 0.0, 241)
    T = np.concatenate([np.broadcast_to(np.pi * 10.0 ** u, (n, u.size)), cand], axis=1)
    E = _excess_squared(T, co, m, kappa)
    E = np.where(np.isnan(E) | (T <= 0), -np.inf, E)
    j = np.argmax(E, axis=1)
    best_t, best = T[rows, j], E[rows, j]
    step = np.full(n, 0.05)  # in log10(θ)
    v = np.linspace(-1.0, 1.0, 9)
    for _ in range(12):
        Tl = np.minimum(best_t[:, None] * 10.0 ** (step[:, None] * v[None, :]), np.pi)
        El = _excess_squared(Tl, co, m, kappa)
        El = np.where(np.isnan(El), -np.inf, El)
        k = np.argmax(El, axis=1)
        better = El[rows, k] > best
        best = np.where(better, El[rows, k], best)
        best_t = np.where(better, Tl[rows, k], best_t)
        step = step / 3.0
    return best, best_t


@dataclass(frozen=True)
class SampledCertificate(SingleResult):
    """The sampled-data certificate of one gain triple.

    Attributes
    ----------
    k_x, k_v, k_a : float
        The gains.
    params : Params
        τ, δ, T*.
    sample_time : float
        H, s.
    tau_prev : float
        The predecessor's lag (τ in a homogeneous platoon).
    schur : bool
        Δ(z) is Schur (internal stability of the sampled loop).
    spectral_radius : float
        max |root| of Δ(z); < 1 iff Schur.
    verdict : str
        ``"certified"``, ``"not_certified"`` or ``"inconclusive"``.
    sup_gain : float
        ‖H‖_∞ = sup_θ |H(e^{jθ})| for a Schur loop, ``inf`` otherwise.
    linf_gain : float
        sup_θ |H(e^{jθ})| regardless of stability.
    peak_theta, peak_omega : float
        Where that supremum is attained: θ in rad/sample and ω = θ/H in rad/s.
    margin : float
        Smallest g_H(θ) found (≥ 0 iff |H| ≤ 1; → the continuous margin as H → 0).
    n_evals : int
        Evaluations of g_H used.
    sup_gain_excess : float
        sup_θ |H(e^{jθ})| − 1 computed without cancellation: 0 when certified, > 0 when
        not certified and Schur (also when ``sup_gain`` rounds to 1.0, a violation near
        θ → 0 from a DC margin just below 0: ``peak_theta`` is then where it is attained),
        ``inf`` when Δ is not Schur.
    """

    k_x: float
    k_v: float
    k_a: float
    params: Params
    sample_time: float
    tau_prev: float
    schur: bool
    spectral_radius: float
    verdict: str
    sup_gain: float
    linf_gain: float
    peak_theta: float
    peak_omega: float
    margin: float
    n_evals: int = 0
    sup_gain_excess: float = float("nan")


#: The columns of the human table of sampled certificates (``stringstab certify --sample-time``).
TABLE_COLUMNS: list[TableColumn] = [
    *ROW_COLUMNS,
    TableColumn("schur", "schur"),
    TableColumn("ρ(Δ)", "spectral_radius", "%.4g"),
    TableColumn("verdict", "verdict"),
    TableColumn("sup|H|", "sup_gain", "%.6g", missing="inf"),
    TableColumn("sup|H|-1", "sup_gain_excess", "%.3g", missing="inf"),
    TableColumn("ω_peak[rad/s]", "peak_omega", "%.4g"),
    TableColumn("θ_peak[rad/sample]", "peak_theta", "%.4g"),
    TableColumn("margin", "margin", "%.3g"),
]


@dataclass(frozen=True)
class SampledCertificateBatch(BatchResult):
    """Sampled certificates of many triples, as arrays (fields of :class:`SampledCertificate`)."""

    SINGLE: ClassVar[type[SampledCertificate]] = SampledCertificate
    SHARED: ClassVar[tuple[str, ...]] = ("params", "sample_time", "tau_prev")

    k_x: Array
    k_v: Array
    k_a: Array
    params: Params
    sample_time: float
    tau_prev: float
    schur: npt.NDArray[np.bool_]
    spectral_radius: Array
    verdict: npt.NDArray[np.str_]
    sup_gain: Array
    linf_gain: Array
    peak_theta: Array
    peak_omega: Array
    margin: Array
    n_evals: npt.NDArray[np.int64]
    sup_gain_excess: Array

    def __getitem__(self, i: int) -> SampledCertificate:
        return super().__getitem__(i)  # type: ignore[no-any-return]

    @property
    def stable(self) -> npt.NDArray[np.bool_]:  # type: ignore[override]
        """Internally stable (Δ(z) Schur, surely): :attr:`schur`, the protocol's name."""
        return self.schur

    @property
    def box(self) -> Box:
        """The parameters as a (point) box."""
        return Box.of(self.params)

    def columns(self) -> dict[str, Any]:
        """The result columns: gains, Schur stability, verdict, peak (ω and θ), margin, then
        ``sample_time``, ``tau_prev`` and the ``box`` group (``tau_lo``, ``tau_hi``, ...).

        Non-finite numbers stay as they are (``sup_gain`` is ``inf`` when Δ is not Schur).

        Examples
        --------
        >>> b = certify_sampled_batch([1.2], [0.5], [0.6], tau=0.1, delta=0.2, headway=1.1,
        ...                           sample_time=0.1)
        >>> c = b.columns()
        >>> c["verdict"].tolist(), c["sample_time"].tolist(), c["box"]["delta_hi"].tolist()
        (['certified'], [0.1], [0.2])
        """
        n = len(self)
        return {
            "k_x": self.k_x, "k_v": self.k_v, "k_a": self.k_a, "schur": self.schur,
            "spectral_radius": self.spectral_radius, "verdict": self.verdict,
            "sup_gain": self.sup_gain, "sup_gain_excess": self.sup_gain_excess,
            "linf_gain": self.linf_gain,
            "peak_omega": self.peak_omega, "peak_theta": self.peak_theta, "margin": self.margin,
            "sample_time": np.full(n, self.sample_time), "tau_prev": np.full(n, self.tau_prev),
            "box": self.box.columns(n),
        }

    def summary_extra(self) -> dict[str, Any]:
        """The sample time, the predecessor's lag and the (point) box."""
        return {"sample_time": self.sample_time, "tau_prev": self.tau_prev,
                "box": self.box.as_dict()}


SampledCertificate.BATCH = SampledCertificateBatch


def certify_sampled_batch(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: float, delta: float, headway: float, sample_time: float,
    tau_prev: float | None = None, chunk: int = 4096, n_grid: int | None = None,
    max_rounds: int = 30, max_intervals: int = 1024, progress: bool = False,
) -> SampledCertificateBatch:
    """Certify many gain triples for the sampled-data loop (sound; module docstring).

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains, broadcast together and flattened.
    tau, delta, headway : float
        Lag τ > 0, delay δ ≥ 0 (any real, exact between samples), headway T* ≥ 0 (s).
    sample_time : float
        Sampling period H > 0 of every vehicle, s.
    tau_prev : float, optional
        The predecessor's lag (default τ, a homogeneous platoon).
    chunk : int
        Triples per vectorised chunk.
    n_grid, max_rounds, max_intervals : int
        See :func:`check_sampled`.
    progress : bool
        Show a tqdm progress bar over chunks.

    Returns
    -------
    SampledCertificateBatch

    Raises
    ------
    StringStabError
        On non-finite gains, parameters out of range, or a sample time that is not a
        finite number > 0.

    Examples
    --------
    >>> b = certify_sampled_batch([1.2, 0.9], [0.5, -0.5], [0.6, 1.1], tau=0.1, delta=0.2,
    ...                           headway=1.1, sample_time=0.1)
    >>> b.verdict.tolist(), np.round(b.sup_gain, 4).tolist()
    (['certified', 'not_certified'], [1.0, 1.0911])
    """
    kx, kv, ka, p, H, tp = _prepare(k_x, k_v, k_a, tau, delta, headway, sample_time, tau_prev)
    n = kx.size
    verdict = np.empty(n, dtype=np.int8)
    margin = np.empty(n)
    n_evals = np.empty(n, dtype=np.int64)
    sup = np.ones(n)
    peak = np.zeros(n)
    excess = np.zeros(n)
    sure = np.empty(n, dtype=bool)
    rad = np.empty(n)
    for sl in chunks(n, chunk, progress=progress, desc="certify (sampled)"):
        co, m = _point_coeffs(kx[sl], kv[sl], ka[sl], p, H, tp)
        s_sure, s_fail = _schur_bands(co.delta)
        bb = _bnb_points(co, m, n_grid=n_grid or _default_grid(m), max_rounds=max_rounds,
                         max_intervals=max_intervals, refine=~s_fail)
        v = verdict_codes(bb.status)
        v[~s_sure] = np.where(s_fail[~s_sure], _NOT, _INC)
        verdict[sl], margin[sl], n_evals[sl], sure[sl] = v, bb.minimum, bb.n_evals, s_sure
        rad[sl] = _spectral_radius([d.lo for d in co.delta])
        need = v != _CERT
        if need.any():
            idx = np.flatnonzero(need)
            sub = _take(co, idx)
            sp_, pw = _peak(sub, m, ka[sl][idx], bb.grid_x[idx], bb.argmin[idx])
            sup[sl][idx] = sp_
            peak[sl][idx] = pw
            # not certified and Schur ⇒ |H| > 1 somewhere: sup|H| − 1 without cancellation,
            # so a violation of 1e-20 near θ = 0 is reported as such, where it is attained
            # (rows whose |H| − 1 from the direct search keeps ≥ 12 digits are left as they are)
            excess[sl][idx] = sp_ - 1.0
            viol = np.flatnonzero((v == _NOT) & s_sure & (excess[sl] < EXCESS_SEARCH))
            if viol.size:
                kappa = np.full(viol.size, p.tau * tp / H**3)
                e2, th = _violation_peak(_take(co, viol), m, kappa,
                                         np.stack([peak[sl][viol], bb.argmin[viol]], axis=1))
                e1 = e2 / (1.0 + np.sqrt(1.0 + np.maximum(e2, 0.0)))  # sup|H| − 1
                # the candidates include the direct search's peak, so the search's value
                # replaces the direct |H| − 1 (whose last bits are round-off at this size)
                take = (e1 > 0) | (e1 >= excess[sl][viol])
                excess[sl][viol] = np.where(take, e1, excess[sl][viol])
                peak[sl][viol] = np.where(take, th, peak[sl][viol])
                sup[sl][viol] = np.where(take, 1.0 + e1, sup[sl][viol])
    excess = np.where(sure, excess, np.inf)
    hinf = np.where(sure, sup, np.inf)
    return SampledCertificateBatch(
        k_x=kx, k_v=kv, k_a=ka, params=p, sample_time=H, tau_prev=tp, schur=sure,
        spectral_radius=rad, verdict=names(verdict), sup_gain=hinf, linf_gain=sup,
        peak_theta=peak, peak_omega=peak / H, margin=margin, n_evals=n_evals,
        sup_gain_excess=excess,
    )


def certify_sampled(
    k_x: float, k_v: float, k_a: float, *, tau: float, delta: float, headway: float,
    sample_time: float, tau_prev: float | None = None,
) -> SampledCertificate:
    """Certify one gain triple for the sampled-data loop (see :func:`certify_sampled_batch`).

    Parameters
    ----------
    k_x, k_v, k_a : float
        One gain triple of IDL eq 4 (k_x in 1/s², k_v in 1/s, k_a dimensionless).
    tau : float
        Actuator lag τ > 0, s.
    delta : float
        Communication delay δ ≥ 0, s.
    headway : float
        Desired time headway T* ≥ 0, s.
    sample_time : float
        Sampling period H > 0 of every vehicle, s.
    tau_prev : float, optional
        The predecessor's lag, s (default τ, a homogeneous platoon).

    Returns
    -------
    SampledCertificate

    Raises
    ------
    StringStabError
        On bad parameters or gains, or arrays instead of one triple.

    Examples
    --------
    >>> c = certify_sampled(1.2, 0.5, 0.6, tau=0.1, delta=0.2, headway=1.1, sample_time=0.1)
    >>> c.verdict, c.sup_gain, c.schur
    ('certified', 1.0, True)
    """
    one_triple("certify_sampled", "certify_sampled_batch", k_x=k_x, k_v=k_v, k_a=k_a)
    return certify_sampled_batch([k_x], [k_v], [k_a], tau=tau, delta=delta, headway=headway,
                                 sample_time=sample_time, tau_prev=tau_prev)[0]
