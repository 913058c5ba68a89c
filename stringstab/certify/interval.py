"""Interval arithmetic with a round-off companion, and derivative enclosures over a cell.

The sampled-data certificate (:mod:`stringstab.certify.sampled`) and the robust one over a
box of parameters (:mod:`stringstab.certify.robust_sampled`) compute the coefficients of the
sampled loop (:mod:`stringstab.certify.zoh`) in this arithmetic, vectorised over rows (one
gain triple, or one parameter cell, per row):

* :class:`Interval` — [lo, hi] with ``mag``, a bound on the magnitude of every intermediate
  quantity (the same computation on absolute values), so that the round-off of the end
  points is at most γ_n × ``mag`` (a few hundred ulps × ``mag`` for the depths used here);
  a *point* (lo = hi, one array) takes a faster path with the same numbers;
* :class:`IntervalAD` — forward-mode differentiation on intervals: a value at the cell's
  centre, an enclosure over the cell and an enclosure of each partial derivative over the
  cell, for the mean-value form value(p) ∈ value(c) + Σ_i ∂_i(cell) (p_i − c_i);
* polynomials with interval coefficients (ascending lists): :func:`poly_add`,
  :func:`poly_scale`.

Only +, −, × and the reciprocal of a positive quantity are defined (the coefficients of the
loop need nothing else; the reciprocal is for the split form of
:mod:`stringstab.certify.sampled_split`); the end points are not rounded outward: every
comparison made with them carries a slack proportional to ``mag`` instead
(:data:`stringstab.certify.verdicts.ROUNDOFF_SLACK`).

References
----------
R. E. Moore, R. B. Kearfott, M. J. Cloud, *Introduction to Interval Analysis*, SIAM (2009),
§2-3 (interval arithmetic) and §6.4 (the mean-value form).
N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM (2002),
§3.1 (the error bound γ_n × the computation on absolute values).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = ["Interval", "IntervalAD", "Point", "interval", "poly_add", "poly_scale"]

Array = npt.NDArray[np.float64]


class Interval:
    """[lo, hi] with ``mag`` ≥ the magnitude of every intermediate (round-off bound).

    A point has ``hi is lo``.  Only +, −, × and :meth:`reciprocal` are defined: the computed
    end points are within 10⁻¹³ × ``mag`` of the exact interval operations (γ_n for depth
    n ≤ 400).

    Parameters
    ----------
    lo : array_like
        Lower ends.
    hi : array_like, optional
        Upper ends; None (default) makes a point (``hi is lo``).
    mag : ndarray, optional
        The magnitude companion; default max(|lo|, |hi|).
    """

    __slots__ = ("hi", "lo", "mag")

    def __init__(self, lo: Any, hi: Any = None, mag: Any = None) -> None:
        self.lo = np.asarray(lo, dtype=float)
        self.hi = self.lo if hi is None else np.asarray(hi, dtype=float)
        self.mag = np.maximum(np.abs(self.lo), np.abs(self.hi)) if mag is None else mag

    @classmethod
    def _new(cls, lo: Any, hi: Any, mag: Any) -> Interval:
        """The result of an operation (arrays already): no conversion, ``hi is lo`` for points."""
        out = object.__new__(cls)
        out.lo, out.hi, out.mag = lo, hi, mag
        return out

    @property
    def point(self) -> bool:
        """True for a point (``hi is lo``): the fast path, one array for both ends."""
        return self.hi is self.lo

    @staticmethod
    def of(v: Any) -> Interval:
        """``v`` itself if it is an :class:`Interval`, else the point ``v``."""
        return v if isinstance(v, Interval) else Interval(np.asarray(v, dtype=float))

    def __add__(self, o: Any) -> Interval:
        if not isinstance(o, Interval):
            o = Interval(np.asarray(o, dtype=float))
        if self.hi is self.lo and o.hi is o.lo:
            lo = self.lo + o.lo
            return Interval._new(lo, lo, self.mag + o.mag)
        return Interval._new(self.lo + o.lo, self.hi + o.hi, self.mag + o.mag)

    __radd__ = __add__

    def __neg__(self) -> Interval:
        if self.hi is self.lo:
            lo = -self.lo
            return Interval._new(lo, lo, self.mag)
        return Interval._new(-self.hi, -self.lo, self.mag)

    def __sub__(self, o: Any) -> Interval:
        return self + (-Interval.of(o))

    def __rsub__(self, o: Any) -> Interval:
        return Interval.of(o) + (-self)

    def __mul__(self, o: Any) -> Interval:
        if type(o) is float:  # a constant: the products with the one number, no conversion
            if self.hi is self.lo:
                lo = self.lo * o
                return Interval._new(lo, lo, self.mag * abs(o))
            a, c = self.lo * o, self.hi * o
            return Interval._new(np.minimum(a, c), np.maximum(a, c), self.mag * abs(o))
        if not isinstance(o, Interval):
            o = Interval(np.asarray(o, dtype=float))
        if self.hi is self.lo and o.hi is o.lo:
            lo = self.lo * o.lo
            return Interval._new(lo, lo, self.mag * o.mag)
        if o.hi is o.lo or self.hi is self.lo:
            # one point p: the four products are two pairs of equal ones (x·p twice), so
            # min(min(a, b), min(c, d)) is min(a, c) exactly: the same end points, two
            # products and two comparisons fewer
            a, c = (self.lo * o.lo, self.hi * o.lo) if o.hi is o.lo else (self.lo * o.lo,
                                                                         self.lo * o.hi)
            return Interval._new(np.minimum(a, c), np.maximum(a, c), self.mag * o.mag)
        a, b, c, d = self.lo * o.lo, self.lo * o.hi, self.hi * o.lo, self.hi * o.hi
        # pairwise min/max: the same end points as a reduction over the four, without
        # stacking them into one array first
        return Interval._new(np.minimum(np.minimum(a, b), np.minimum(c, d)),
                             np.maximum(np.maximum(a, b), np.maximum(c, d)), self.mag * o.mag)

    __rmul__ = __mul__

    def const(self, v: Any) -> Interval:
        """A point constant of this item's shape."""
        return Interval(np.zeros_like(self.lo) + v)

    def reciprocal(self) -> Interval:
        """1/x over an interval of positive numbers (lo > 0: the caller's guarantee).

        1/x decreases, so the ends are 1/hi and 1/lo.  The magnitude companion is
        ``mag``/lo²: an error e ≤ γ·``mag`` of x moves 1/x by about e/x², and the division's
        own rounding (one ulp of 1/x ≤ 1/lo ≤ ``mag``/lo²) is within the same bound.

        Returns
        -------
        Interval
            [1/hi, 1/lo] (a point stays a point).
        """
        mag = self.mag / (self.lo * self.lo)
        if self.point:
            return Interval(1.0 / self.lo, None, mag)
        return Interval(1.0 / self.hi, 1.0 / self.lo, mag)

    def take(self, idx: npt.NDArray[np.intp]) -> Interval:
        """The rows ``idx`` (a point stays a point)."""
        lo = self.lo[idx]
        return Interval(lo, None, self.mag[idx]) if self.point else Interval(lo, self.hi[idx],
                                                                            self.mag[idx])


#: The factors of a negation, rows (value, magnitude): −lo, and ``mag`` unchanged.
_NEG = np.array([[-1.0], [1.0]])
#: (c, |c|) of the numbers met, by value (read-only).
_PAIRS: dict[float, Array] = {}


def _pair(v: Any) -> Array:
    """A number or array as the rows (v, |v|) of a point: its value and magnitude.

    A number gives shape (2, 1) (broadcast against points of one-dimensional rows).
    """
    if type(v) is float:
        pair = _PAIRS.get(v)
        if pair is None:
            pair = np.array([[v], [abs(v)]])
            pair.setflags(write=False)
            if len(_PAIRS) < 4096:  # the constants of the loop's formulas, and H's powers
                _PAIRS[v] = pair
        return pair
    lo = np.asarray(v, dtype=float)
    if lo.ndim == 0:
        return np.array([[float(lo)], [abs(float(lo))]])
    return np.stack((lo, np.abs(lo)))


class Point(Interval):
    """A point :class:`Interval` whose ``lo`` and ``mag`` are the two rows of one array ``s``.

    Each operation of two points is one array operation on the stacked rows (value,
    magnitude) instead of two, and computes the same numbers as :class:`Interval`'s point
    path element by element: a product is lo·lo and mag·mag, a sum lo + lo and mag + mag, a
    negation −lo (as lo·(−1), exact) with ``mag`` unchanged, and a number c multiplies the
    rows by (c, |c|).  Operations with any other :class:`Interval` take
    :class:`Interval`'s own paths (IEEE + and × commute, so the operands' order does not
    matter).  :func:`stringstab.certify.zoh.point_coefficients` computes in it (the
    sampled point certificate's fixed cost per call: Moore et al. §2, Higham §3.1 as in
    the module docstring).

    Parameters
    ----------
    s : ndarray, shape (2, n) or (2, 1)
        The values (row 0) and their magnitude companions (row 1), one-dimensional rows.
    """

    __slots__ = ("_lo", "_mag", "s")

    def __init__(self, s: Array) -> None:
        self.s = s
        self._lo = self._mag = None

    # the rows as views, made when first read (the build reads none of them)
    @property
    def lo(self) -> Array:  # type: ignore[override]
        """The values (row 0 of ``s``)."""
        v = self._lo
        if v is None:
            v = self._lo = self.s[0]
        return v

    @property
    def hi(self) -> Array:  # type: ignore[override]
        """The values again (a point: ``hi is lo``)."""
        return self.lo

    @property
    def mag(self) -> Array:  # type: ignore[override]
        """The magnitude companions (row 1 of ``s``)."""
        v = self._mag
        if v is None:
            v = self._mag = self.s[1]
        return v

    @property
    def point(self) -> bool:
        """True (a point)."""
        return True

    @staticmethod
    def of(v: Any) -> Point:  # type: ignore[override]
        """The point of an :class:`Interval` point, or of a number or array (``mag`` = |v|)."""
        if isinstance(v, Point):
            return v
        if isinstance(v, Interval):
            lo, mag = np.broadcast_arrays(v.lo, v.mag)
            return Point(np.stack((lo, mag)))
        return Point(_pair(v))

    def __add__(self, o: Any) -> Interval:
        if type(o) is Point:
            return Point(self.s + o.s)
        if isinstance(o, Interval):
            return Interval.__add__(self, o)
        return Point(self.s + _pair(o))

    __radd__ = __add__

    def __neg__(self) -> Point:
        return Point(self.s * _NEG)

    def __sub__(self, o: Any) -> Interval:
        return self + (-o if isinstance(o, Interval) else -Point(_pair(o)))

    def __rsub__(self, o: Any) -> Interval:
        return (o if isinstance(o, Interval) else Point(_pair(o))) + (-self)

    def __mul__(self, o: Any) -> Interval:
        if type(o) is Point:
            return Point(self.s * o.s)
        if isinstance(o, Interval):
            return Interval.__mul__(self, o)
        return Point(self.s * _pair(o))

    __rmul__ = __mul__

    def const(self, v: Any) -> Point:
        """A point constant of this item's shape (``mag`` = |v|, as :meth:`Interval.const`)."""
        lo = np.zeros_like(self.lo) + v
        return Point(np.stack((lo, np.abs(lo))))

    def take(self, idx: npt.NDArray[np.intp]) -> Point:
        """The rows ``idx``."""
        return Point(self.s[:, idx])


class IntervalAD:
    """Forward-mode derivative enclosures over a parameter cell (the mean-value form).

    ``c`` is the value at the cell's centre (a point :class:`Interval`), ``r`` an enclosure
    of the value over the cell and ``g[i]`` an enclosure of ∂/∂p_i over the cell.  For any
    member p: value(p) ∈ c + Σ_i g[i] (p_i − c_i) (mean-value theorem), which is
    tighter than ``r`` (the natural interval extension) on small cells.

    Parameters
    ----------
    c : Interval
        The value at the centre of the cell (a point).
    r : Interval
        An enclosure of the value over the cell.
    g : tuple of Interval
        Enclosures of the partial derivatives over the cell, one per parameter.
    """

    __slots__ = ("c", "g", "k", "r")

    def __init__(self, c: Interval, r: Interval, g: tuple[Interval, ...],
                 k: bool = False) -> None:
        # k: a constant (every derivative zero), so sums and products skip its derivatives
        self.c, self.r, self.g, self.k = c, r, g, k

    @staticmethod
    def variable(lo: Array, hi: Array, i: int, d: int) -> IntervalAD:
        """Parameter ``i`` of ``d`` ranging over the cell [lo, hi]: ∂/∂p_i = 1, the others 0."""
        mid = np.ascontiguousarray(0.5 * (lo + hi))
        c = Interval(mid)
        return IntervalAD(c, Interval(lo, hi), tuple(c.const(1.0 if j == i else 0.0)
                                                     for j in range(d)))

    def const(self, v: Any) -> IntervalAD:
        """A constant of this item's shape (zero derivatives)."""
        k = self.c.const(v)
        z = self.c.const(0.0)
        return IntervalAD(k, k, tuple(z for _ in self.g), True)

    @staticmethod
    def of(v: Any, like: IntervalAD) -> IntervalAD:
        """``v`` itself if it is an :class:`IntervalAD`, else a constant shaped as ``like``."""
        return v if isinstance(v, IntervalAD) else like.const(v)

    def __add__(self, o: Any) -> IntervalAD:
        o = IntervalAD.of(o, self)
        if o.k or self.k:  # a constant's derivatives are zero: the other's are the sum's
            return IntervalAD(self.c + o.c, self.r + o.r, self.g if o.k else o.g,
                              self.k and o.k)
        return IntervalAD(self.c + o.c, self.r + o.r, tuple(a + b for a, b in zip(self.g, o.g)))

    __radd__ = __add__

    def __neg__(self) -> IntervalAD:
        return IntervalAD(-self.c, -self.r, tuple(-a for a in self.g), self.k)

    def __sub__(self, o: Any) -> IntervalAD:
        return self + (-IntervalAD.of(o, self))

    def __rsub__(self, o: Any) -> IntervalAD:
        return IntervalAD.of(o, self) + (-self)

    def __mul__(self, o: Any) -> IntervalAD:
        if not isinstance(o, IntervalAD):
            k = Interval.of(o)
            return IntervalAD(self.c * k, self.r * k, tuple(a * k for a in self.g), self.k)
        if self.k and o.k:
            return IntervalAD(self.c * o.c, self.r * o.r, self.g, True)
        if o.k:  # (a·b)' = a'·b when b is constant
            return IntervalAD(self.c * o.c, self.r * o.r, tuple(a * o.r for a in self.g))
        if self.k:
            return IntervalAD(self.c * o.c, self.r * o.r, tuple(self.r * b for b in o.g))
        return IntervalAD(self.c * o.c, self.r * o.r,
                          tuple(a * o.r + self.r * b for a, b in zip(self.g, o.g)))

    __rmul__ = __mul__

    def reciprocal(self) -> IntervalAD:
        """1/x of a positive quantity: derivative −x'/x², enclosed by −g·(1/x)² over the cell.

        Returns
        -------
        IntervalAD
            The value at the centre, the enclosure [1/hi, 1/lo] and the derivatives.
        """
        r = self.r.reciprocal()
        if self.k:
            return IntervalAD(self.c.reciprocal(), r, self.g, True)
        r2 = r * r
        return IntervalAD(self.c.reciprocal(), r, tuple(-(g * r2) for g in self.g))

    def take(self, idx: npt.NDArray[np.intp]) -> IntervalAD:
        """The rows ``idx`` of the value, the enclosure and every derivative."""
        return IntervalAD(self.c.take(idx), self.r.take(idx), tuple(g.take(idx) for g in self.g),
                          self.k)


def interval(lo: Array, hi: Array) -> Interval:
    """[lo, hi], a point when ``hi is lo`` (the same array for both ends).

    Parameters
    ----------
    lo, hi : ndarray
        The ends; pass the same array twice for a point.

    Returns
    -------
    Interval
        The interval, on the point path when ``hi is lo``.
    """
    return Interval(lo) if hi is lo else Interval(lo, hi)


def poly_add(a: list[Any], b: list[Any], sign: float = 1.0) -> list[Any]:
    """a + sign·b for polynomials with interval coefficients (ascending powers).

    Parameters
    ----------
    a, b : list of Interval or IntervalAD
        Coefficients, constant term first (of any lengths).
    sign : float
        +1 (default) adds, −1 subtracts ``b``.

    Returns
    -------
    list
        The coefficients of the sum, of the longer length.
    """
    n = max(len(a), len(b))
    out = []
    for k in range(n):
        x = a[k] if k < len(a) else None
        y = b[k] if k < len(b) else None
        if y is not None and sign < 0:
            y = -y
        out.append(x if y is None else y if x is None else x + y)
    return out


def poly_scale(c: Any, p: list[Any]) -> list[Any]:
    """c·p for a polynomial p with interval coefficients.

    Parameters
    ----------
    c : Interval, IntervalAD or float
        The factor.
    p : list of Interval or IntervalAD
        Coefficients, constant term first.

    Returns
    -------
    list
        ``[c * q for q in p]``.
    """
    return [c * q for q in p]
