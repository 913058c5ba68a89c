"""Derivative enclosures over cells in stacked arrays: the arithmetic of IntervalAD in few calls.

:class:`~stringstab.certify.interval.IntervalAD` holds the value at a cell's centre, the
enclosure over the cell and each partial derivative's enclosure as separate
:class:`~stringstab.certify.interval.Interval` objects, so one product of two such items is
several tens of numpy calls on small arrays.  :class:`StackedAD` holds them in one array
``X`` of shape (3, m, n): the lower ends, the upper ends and the magnitude companions
(``X[0]``, ``X[1]``, ``X[2]``) of m rows — the centre, the enclosure, then the d
derivatives (m = 2 + d) — of n cells; a constant (``k``) carries its zero derivatives as
IntervalAD does (their signs of zero included: a constant times −1 has −0 derivatives).
Every operation does what IntervalAD does, row by row, with the same floating-point
operations in the same order (the interval product's four end-point products and the same
pairing of their minima and maxima; a point's one product is the same number as the four
equal ones), so its numbers are those of IntervalAD bit for bit: the cells of
:mod:`stringstab.certify.sampled_split_cells` compute the split form's coefficients
(:func:`stringstab.certify.sampled_split.follower_of`, ``predecessor_of``) in it, a few numpy
calls per operation whatever d.

References
----------
R. E. Moore, R. B. Kearfott, M. J. Cloud, *Introduction to Interval Analysis*, SIAM (2009),
§2-3 (interval arithmetic) and §6.4 (the mean-value form).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from .interval import Interval
from .zoh import phi

__all__ = ["StackedAD", "exp_neg_stacked", "phi_stacked", "ratio_stacked"]

Array = npt.NDArray[np.float64]

_NEG = np.array([-1.0, -1.0, 1.0])[:, None, None]  # (−hi, −lo, mag) from (hi, lo, mag)
_SWAP = np.array([1, 0, 2], dtype=np.intp)


def _prod(A: Array, B: Array) -> Array:
    """The interval product of stacked (3, ...) arrays (broadcast), as ``Interval.__mul__``.

    The four end-point products a = lo·lo', b = lo·hi', c = hi·lo', d = hi·hi', then
    min(min(a, b), min(c, d)) and max(max(a, b), max(c, d)) (the pairing of
    ``Interval.__mul__``) and the magnitudes' product.  With a point operand the four are two
    pairs of equal numbers, and these are the point paths' end points exactly.
    """
    a0, a1 = A[0], A[1]
    b0, b1 = B[0], B[1]
    a, b, c, d = a0 * b0, a0 * b1, a1 * b0, a1 * b1
    out = np.empty((3, *a.shape))
    np.minimum(np.minimum(a, b), np.minimum(c, d), out=out[0])
    np.maximum(np.maximum(a, b), np.maximum(c, d), out=out[1])
    np.multiply(A[2], B[2], out=out[2])
    return out


def _pointk(v: Any) -> Array:
    """A point constant v (a float, or an array of n) as (v, v, |v|) of shape (3, 1, 1 or n)."""
    if isinstance(v, float):
        k = _POINTS.get(v) if v != 0.0 else None
        if k is None:
            k = np.array([v, v, abs(v)])[:, None, None]
            if v != 0.0 and len(_POINTS) < 256:
                _POINTS[v] = k
        return k
    a = np.asarray(v, dtype=float)
    return np.stack([a, a, np.maximum(np.abs(a), np.abs(a))]).reshape(3, 1, -1)


def _scale(X: Array, k: Array) -> Array:
    """X times a point k of :func:`_pointk`: ``Interval.__mul__``'s path with a point operand.

    The two products lo·v and hi·v, their minimum and maximum (the same end points as the
    four products, two pairs of equal ones), and the magnitudes times |v|.
    """
    Y = X * k
    lo = np.minimum(Y[0], Y[1])
    np.maximum(Y[0], Y[1], out=Y[1])
    Y[0] = lo
    return Y


#: The stacked point constants of :func:`_scale`, by value (the few constants of the
#: coefficients' formulas: H², 1/H, ±2, the polynomials' constants).
_POINTS: dict[float, Array] = {}
#: Row gathers of the general product (by d): [c, r, g…, r…] and [c, r, r…, g…].
_LEFT: dict[int, npt.NDArray[np.intp]] = {}
_RIGHT: dict[int, npt.NDArray[np.intp]] = {}


def _rows(d: int) -> tuple[npt.NDArray[np.intp], npt.NDArray[np.intp]]:
    """The gathers of the general product for d parameters."""
    if d not in _LEFT:
        m = 2 + d
        _LEFT[d] = np.array(list(range(m)) + [1] * d, dtype=np.intp)
        _RIGHT[d] = np.array([0, 1] + [1] * d + list(range(2, m)), dtype=np.intp)
    return _LEFT[d], _RIGHT[d]


class StackedAD:
    """Forward-mode derivative enclosures over cells, stacked (module docstring).

    Parameters
    ----------
    X : ndarray, shape (3, m, n)
        Lower ends, upper ends and magnitudes of the centre value, the enclosure and the d
        derivatives' enclosures (m = 2 + d); for a constant (``k``), shape (3, 1, n): the
        point, which is both its centre and its enclosure.
    d : int
        The number of parameters.
    k : bool
        A constant: every derivative zero (sums and products skip them, as IntervalAD).
    zs : float or ndarray
        A constant's derivatives: the zero ±0 of every derivative's ends (IntervalAD carries
        them, and a constant times a negative number has −0 derivatives).
    """

    __slots__ = ("X", "d", "k", "zs")

    def __init__(self, X: Array, d: int, k: bool = False, zs: Any = 0.0) -> None:
        self.X, self.d, self.k, self.zs = X, d, k, zs

    @staticmethod
    def variable(lo: Array, hi: Array, i: int, d: int) -> StackedAD:
        """Parameter ``i`` of ``d`` over [lo, hi]: as ``IntervalAD.variable``."""
        mid = np.ascontiguousarray(0.5 * (lo + hi))
        X = np.zeros((3, 2 + d, mid.size))
        X[0, 0] = X[1, 0] = mid
        X[2, 0] = np.maximum(np.abs(mid), np.abs(mid))
        X[0, 1], X[1, 1] = lo, hi
        X[2, 1] = np.maximum(np.abs(lo), np.abs(hi))
        X[:, 2 + i] = 1.0
        return StackedAD(X, d)

    def const(self, v: Any) -> StackedAD:
        """A constant of this item's shape (zero derivatives): ``IntervalAD.const``."""
        a = np.zeros(self.X.shape[2]) + v
        X = np.empty((3, 1, a.size))
        X[0, 0] = X[1, 0] = a
        X[2, 0] = np.maximum(np.abs(a), np.abs(a))
        return StackedAD(X, self.d, True)

    def full(self) -> Array:
        """``X`` of shape (3, 2 + d, n), a constant's point and ±0 derivatives written out."""
        if not self.k:
            return self.X
        X = np.empty((3, 2 + self.d, self.X.shape[2]))
        X[:, :2] = self.X
        X[:2, 2:] = np.asarray(self.zs)[..., None, :] if np.ndim(self.zs) else self.zs
        X[2, 2:] = 0.0
        return X

    @property
    def c(self) -> Interval:
        """The value at the centre (a point :class:`~stringstab.certify.interval.Interval`)."""
        return Interval(self.X[0, 0], None, self.X[2, 0])

    @property
    def r(self) -> Interval:
        """The enclosure over the cell (an :class:`~stringstab.certify.interval.Interval`)."""
        i = 0 if self.k else 1
        return Interval(self.X[0, i], self.X[1, i], self.X[2, i])

    @property
    def g(self) -> tuple[Interval, ...]:
        """The derivatives' enclosures, one :class:`~stringstab.certify.interval.Interval` each."""
        X = self.full()
        return tuple(Interval(X[0, i], X[1, i], X[2, i]) for i in range(2, 2 + self.d))

    def _of(self, v: Any) -> StackedAD:
        return v if isinstance(v, StackedAD) else self.const(v)

    def __add__(self, o: Any) -> StackedAD:
        o = self._of(o)
        if self.k and o.k:  # the derivatives stay the left one's (IntervalAD's choice)
            return StackedAD(self.X + o.X, self.d, True, self.zs)
        if o.k or self.k:  # a constant's derivatives are zero: the other's are the sum's
            a, c = (self, o) if o.k else (o, self)
            X = a.X.copy()
            np.add(a.X[:, :2], c.X, out=X[:, :2])
            return StackedAD(X, self.d)
        return StackedAD(self.X + o.X, self.d)

    __radd__ = __add__

    def __neg__(self) -> StackedAD:
        if self.k:  # a point: −hi is −lo
            return StackedAD(self.X * _NEG, self.d, True, -self.zs)
        return StackedAD(self.X.take(_SWAP, axis=0) * _NEG, self.d)

    def __sub__(self, o: Any) -> StackedAD:
        return self + (-self._of(o))

    def __rsub__(self, o: Any) -> StackedAD:
        return self._of(o) + (-self)

    def __mul__(self, o: Any) -> StackedAD:
        if not isinstance(o, StackedAD):
            v = float(o) if isinstance(o, (int, float)) else o
            k = _pointk(v)
            if self.k:  # point × point: one product of each end, and of the magnitudes
                return StackedAD(self.X * k, self.d, True, self.zs * v)
            return StackedAD(_scale(self.X, k), self.d)
        if self.k and o.k:
            return StackedAD(self.X * o.X, self.d, True, self.zs)
        if o.k or self.k:  # (a·b)' = a'·b when b is constant: every row times the point
            a, c = (self, o) if o.k else (o, self)
            return StackedAD(_scale(a.X, c.X), self.d)
        # c·c', r·r', then g_i·r' and r·g'_i in one product; g = g·r' + r·g'
        left, right = _rows(self.d)
        m = 2 + self.d
        P = _prod(self.X.take(left, axis=1), o.X.take(right, axis=1))
        np.add(P[:, 2:m], P[:, m:], out=P[:, 2:m])
        return StackedAD(P[:, :m], self.d)

    __rmul__ = __mul__

    def reciprocal(self) -> StackedAD:
        """1/x of a positive quantity: ``IntervalAD.reciprocal`` (−g·(1/x)² for the derivatives).

        Returns
        -------
        StackedAD
            The centre's and the enclosure's reciprocals and the derivatives.
        """
        if self.k:
            X = np.empty_like(self.X)
            np.divide(self.X[2], self.X[0] * self.X[0], out=X[2])
            X[0] = X[1] = 1.0 / self.X[0]
            return StackedAD(X, self.d, True, self.zs)
        cr = self.X[:, :2]
        X = np.empty_like(self.X)
        rec = X[:, :2]
        np.divide(cr[2], cr[0] * cr[0], out=rec[2])
        np.divide(1.0, cr[1], out=rec[0])
        np.divide(1.0, cr[0], out=rec[1])
        r = rec[:, 1:2]
        g = _prod(self.X[:, 2:], _prod(r, r))
        X[:, 2:] = g.take(_SWAP, axis=0) * _NEG
        return StackedAD(X, self.d)


def ratio_stacked(t: StackedAD, H: float) -> StackedAD:
    """x = H/t of a lag t > 0 over the cells: :func:`stringstab.certify.zoh.ratio_ad`.

    Parameters
    ----------
    t : StackedAD
        A lag over the cells (τ or τ_p), s, > 0 (not a constant).
    H : float
        Sample time, s.

    Returns
    -------
    StackedAD
        H/t with its derivative enclosures (derivative −H/t² ∈ [−H/t_lo², −H/t_hi²]).
    """
    X = t.X
    lo, hi = X[0, 1], X[1, 1]
    dr = np.empty((3, 1, lo.size))
    dr[0, 0], dr[1, 0] = -H / (lo * lo), -H / (hi * hi)
    dr[2, 0] = np.maximum(np.abs(dr[0, 0]), np.abs(dr[1, 0]))
    out = np.empty_like(X)
    c = H / X[0, 0]
    out[0, 0] = out[1, 0] = c
    out[2, 0] = np.maximum(np.abs(c), np.abs(c))
    out[0, 1], out[1, 1] = H / hi, H / lo
    out[2, 1] = np.maximum(np.abs(out[0, 1]), np.abs(out[1, 1]))
    out[:, 2:] = _prod(dr, X[:, 2:])
    return StackedAD(out, t.d)


def phi_stacked(*xs: StackedAD) -> list[tuple[StackedAD, StackedAD, StackedAD]]:
    """φ1, ψ2, ψ3 of each x ≥ 0 over the cells: :func:`stringstab.certify.zoh.phi_ad`.

    One call of :func:`stringstab.certify.zoh.phi` on every x's centres and both ends (it is
    elementwise: each number is the one a call on that x alone computes); the derivatives
    φ1' = 1 − φ1, ψ2' = φ1, ψ3' = ψ2 over the enclosure, each times every derivative of x,
    in one product.

    Parameters
    ----------
    *xs : StackedAD
        Quantities x ≥ 0 over the same cells with the same d (not constants).

    Returns
    -------
    list of (StackedAD, StackedAD, StackedAD)
        φ1, ψ2 and ψ3 of each x with their derivative enclosures.
    """
    XS = np.stack([x.X for x in xs], axis=1)  # (3, K, m, n)
    K, m, n = XS.shape[1:]
    vals = phi(XS[:2, :, :2])  # three (2, K, 2, n): [lo, hi] × x × [centre, enclosure]
    out = np.empty((3, 3, K, m, n))  # function × (lo, hi, mag) × x × row × cell
    for f, v in enumerate(vals):
        out[f, :2, :, :2] = v
        out[f, 2, :, :2] = np.maximum(np.abs(v[0]), np.abs(v[1]))
    r = out[:, :, :, 1]  # (function, 3, K, n): the enclosures
    ders = np.empty((3, 3, K, n))  # (lo, hi, mag) × function × x × cell
    ders[0, 0] = 1.0 + (-r[0, 1])
    ders[1, 0] = 1.0 + (-r[0, 0])
    ders[2, 0] = 1.0 + r[0, 2]
    ders[:, 1] = r[0]
    ders[:, 2] = r[1]
    g = _prod(ders[:, :, :, None], XS[:, None, :, 2:])  # (3, function, K, d, n)
    out[:, :, :, 2:] = g.transpose(1, 0, 2, 3, 4)
    d = xs[0].d
    return [(StackedAD(out[0, :, k], d), StackedAD(out[1, :, k], d), StackedAD(out[2, :, k], d))
            for k in range(K)]


def exp_neg_stacked(y: StackedAD) -> StackedAD:
    """e^{−y} over the cells: :func:`stringstab.certify.zoh.exp_neg_ad` (derivative −e^{−y}).

    Parameters
    ----------
    y : StackedAD
        The exponent over the cells (not a constant).

    Returns
    -------
    StackedAD
        e^{−y} with its derivative enclosures.
    """
    X = y.X
    e = np.exp(-np.stack([X[0, 0], X[1, 1], X[0, 1]]))  # centre, e^{−hi}, e^{−lo}
    out = np.empty_like(X)
    out[0, 0] = out[1, 0] = e[0]
    out[2, 0] = np.maximum(np.abs(e[0]), np.abs(e[0]))
    out[0, 1], out[1, 1] = e[1], e[2]
    out[2, 1] = np.maximum(np.abs(e[1]), np.abs(e[2]))
    g = _prod(out[:, 1:2], X[:, 2:])
    out[:, 2:] = g.take(_SWAP, axis=0) * _NEG
    return StackedAD(out, y.d)
