r"""Second-order jets on intervals: enclosures of f, f' and f'' over a frequency interval.

A :class:`Jet` carries three :class:`Enclosure` values — a rigorous enclosure of a function's
value, of its first and of its second derivative in one variable (the frequency ω, or θ on
the unit circle) over an interval [l, r] — and propagates them through +, −, × (Leibniz's
rule, (uv)'' = u''v + 2u'v' + uv'') and through cos and sin of a jet (the chain rule,
:func:`jet_cos`, :func:`jet_sin`, with the range of cos and sin over an interval,
:func:`cos_range`, :func:`sin_range`).  Started from the variable itself
(:meth:`Jet.variable`: value [l, r], derivative 1, second derivative 0) any expression of
+, −, ×, cos and sin — e.g. the generated code of :mod:`stringstab.derive.generated`, which
takes ``cos`` and ``sin`` as arguments — yields an enclosure of its second derivative over
[l, r]: the curvature bound M ≥ |f''| of the branch and bound
(:mod:`stringstab.certify.branch_bound`).  Every enclosure shrinks to the point value as the
interval shrinks (width O(r − l)), so the bound is tight where the branch and bound needs it.

**Round-off.**  An :class:`Enclosure` is interval arithmetic with outward rounding: after every
+, − and × the lower end moves down and the upper end up by 2⁻⁵²|x| + 2⁻¹⁰⁷⁴ (at least one
unit in the last place, and the smallest subnormal), which covers the rounding to nearest of
the operation (at most half a unit), so the exact result of the operation on any members
of the operands lies inside.  The ends of cos and sin are widened by 2⁻⁵¹ (more than the
library's error, under one unit in the last place at magnitude ≤ 1) and clipped to [−1, 1].
Inputs that are not exact floats (computed coefficients) enter as enclosures widened by their
own round-off bound (:meth:`Enclosure.around`).  No magnitude companion is needed: the ends
themselves are rigorous.

The same :func:`jet_cos` and :func:`jet_sin` take the point intervals of
:mod:`stringstab.certify.interval` (values with a magnitude companion, for the round-off
slack rule of the point values): :func:`point_cos`, :func:`point_sin`.

References
----------
R. E. Moore, R. B. Kearfott, M. J. Cloud, *Introduction to Interval Analysis*, SIAM (2009),
§3-4 (outward rounding), §5 (interval extensions) and §9.2 (differentiation on intervals).
N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM (2002), §2.1
(rounding to nearest: |fl(x) − x| ≤ 2⁻⁵³|x| for normal x, half the smallest subnormal below).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

from .interval import Interval

__all__ = [
    "Enclosure",
    "Jet",
    "cos_range",
    "jet_cos",
    "jet_sin",
    "point_cos",
    "point_sin",
    "sin_range",
]

Array = npt.NDArray[np.float64]

_TWO_PI = 2.0 * math.pi
#: Relative and absolute outward step after an operation (module docstring).
_REL = 2.0 ** -52
_ABS = 2.0 ** -1074
#: Outward step of the ends of cos and sin (values of magnitude ≤ 1).
_TRIG = 2.0 ** -51


def _down(x: Array) -> Array:
    return np.asarray(x - (np.abs(x) * _REL + _ABS))


def _up(x: Array) -> Array:
    return np.asarray(x + (np.abs(x) * _REL + _ABS))


class Enclosure:
    """[lo, hi] with outward rounding: holds every exact result (module docstring).

    An exact float constant may be a point (``hi is lo``); the result of any operation on a
    non-constant is an interval.  numpy never operates on an enclosure itself
    (``__array_ufunc__ = None``).

    Parameters
    ----------
    lo, hi : ndarray
        The ends (``hi`` None: the exact point ``lo``).

    Examples
    --------
    >>> e = Enclosure(np.array([0.1])) * 3.0
    >>> bool(e.lo[0] < 0.30000000000000004 < e.hi[0])
    True
    """

    __slots__ = ("hi", "lo")
    __array_ufunc__ = None

    def __init__(self, lo: Any, hi: Any = None) -> None:
        self.lo = np.asarray(lo, dtype=float)
        self.hi = self.lo if hi is None else np.asarray(hi, dtype=float)

    @staticmethod
    def of(x: Any) -> Enclosure:
        """``x`` itself if it is an :class:`Enclosure`, else the exact float point ``x``.

        Parameters
        ----------
        x : Enclosure, float or ndarray
            An enclosure, or exact floats.

        Returns
        -------
        Enclosure
        """
        return x if isinstance(x, Enclosure) else Enclosure(x)

    @staticmethod
    def around(value: Any, error: Any) -> Enclosure:
        """[value − error, value + error], rounded outward: a computed value and its error bound.

        Parameters
        ----------
        value, error : array_like
            The computed value and a bound on its absolute error (≥ 0).

        Returns
        -------
        Enclosure
        """
        v = np.asarray(value, dtype=float)
        e = np.asarray(error, dtype=float)
        return Enclosure(_down(v - e), _up(v + e))

    @property
    def point(self) -> bool:
        """True for an exact point (``hi is lo``)."""
        return self.hi is self.lo

    def magnitude(self) -> Array:
        """max(|lo|, |hi|): a bound on |x| over the enclosure.

        Returns
        -------
        ndarray
        """
        return np.asarray(np.maximum(np.abs(self.lo), np.abs(self.hi)))

    def __add__(self, o: Any) -> Enclosure:
        o = Enclosure.of(o)
        return Enclosure(_down(self.lo + o.lo), _up(self.hi + o.hi))

    __radd__ = __add__

    def __neg__(self) -> Enclosure:
        return Enclosure(-self.lo) if self.point else Enclosure(-self.hi, -self.lo)

    def __sub__(self, o: Any) -> Enclosure:
        return self + (-Enclosure.of(o))

    def __rsub__(self, o: Any) -> Enclosure:
        return Enclosure.of(o) + (-self)

    def __mul__(self, o: Any) -> Enclosure:
        o = Enclosure.of(o)
        if self.point or o.point:
            p, q = (self, o) if self.point else (o, self)
            x, y = p.lo * q.lo, p.lo * q.hi
            return Enclosure(_down(np.minimum(x, y)), _up(np.maximum(x, y)))
        p1, p2 = self.lo * o.lo, self.lo * o.hi
        p3, p4 = self.hi * o.lo, self.hi * o.hi
        return Enclosure(_down(np.minimum(np.minimum(p1, p2), np.minimum(p3, p4))),
                         _up(np.maximum(np.maximum(p1, p2), np.maximum(p3, p4))))

    __rmul__ = __mul__


def _contains(a: Array, b: Array, phase: float) -> npt.NDArray[np.bool_]:
    """Whether [a, b] holds a point phase + 2πk for some integer k."""
    k = np.ceil((a - phase) / _TWO_PI)
    return np.asarray(phase + _TWO_PI * k <= b)


def _widen(lo: Array, hi: Array) -> tuple[Array, Array]:
    return np.maximum(lo - _TRIG, -1.0), np.minimum(hi + _TRIG, 1.0)


def cos_range(a: Array, b: Array) -> tuple[Array, Array]:
    """An enclosure [min, max] of cos over [a, b] (a ≤ b), elementwise.

    The smaller and larger end values, widened to 1 where [a, b] holds a multiple of 2π and
    to −1 where it holds an odd multiple of π (the whole of [−1, 1] once b − a ≥ 2π), then
    widened by 2⁻⁵¹ for the library's rounding (module docstring).  A peak missed by the
    rounding of k (within an ulp of an end) changes cos by far less than that widening.

    Parameters
    ----------
    a, b : ndarray
        The ends of the angle intervals, rad.

    Returns
    -------
    (ndarray, ndarray)
        Lower and upper bounds of cos over [a, b].

    Examples
    --------
    >>> lo, hi = cos_range(np.array([0.5, -0.1]), np.array([1.0, 3.5]))
    >>> np.round(lo, 4).tolist(), np.round(hi, 4).tolist()
    ([0.5403, -1.0], [0.8776, 1.0])
    """
    ca, cb = np.cos(a), np.cos(b)
    lo, hi = np.minimum(ca, cb), np.maximum(ca, cb)
    wide = (b - a) >= _TWO_PI
    hi = np.where(wide | _contains(a, b, 0.0), 1.0, hi)
    lo = np.where(wide | _contains(a, b, math.pi), -1.0, lo)
    return _widen(lo, hi)


def sin_range(a: Array, b: Array) -> tuple[Array, Array]:
    """An enclosure [min, max] of sin over [a, b] (a ≤ b), elementwise (as :func:`cos_range`).

    Parameters
    ----------
    a, b : ndarray
        The ends of the angle intervals, rad.

    Returns
    -------
    (ndarray, ndarray)
        Lower and upper bounds of sin over [a, b].

    Examples
    --------
    >>> lo, hi = sin_range(np.array([0.0]), np.array([2.0]))
    >>> round(float(lo[0]), 4), float(hi[0])
    (0.0, 1.0)
    """
    sa, sb = np.sin(a), np.sin(b)
    lo, hi = np.minimum(sa, sb), np.maximum(sa, sb)
    wide = (b - a) >= _TWO_PI
    hi = np.where(wide | _contains(a, b, 0.5 * math.pi), 1.0, hi)
    lo = np.where(wide | _contains(a, b, 1.5 * math.pi), -1.0, lo)
    return _widen(lo, hi)


def point_cos(x: Interval) -> Interval:
    """cos of a point interval, its ``mag`` |cos x| + the angle's.

    The angle's round-off (at most ``ROUNDOFF_SLACK`` × its ``mag``) moves cos by no more
    (cos is 1-Lipschitz), so the slack rule carries over.

    Parameters
    ----------
    x : Interval
        A point (``hi is lo``).

    Returns
    -------
    Interval
        The point cos(x) with ``mag`` = |cos x| + ``x.mag``.
    """
    c = np.cos(x.lo)
    return Interval(c, None, np.abs(c) + x.mag)


def point_sin(x: Interval) -> Interval:
    """sin of a point interval, its ``mag`` |sin x| + the angle's (as :func:`point_cos`).

    Parameters
    ----------
    x : Interval
        A point (``hi is lo``).

    Returns
    -------
    Interval
        The point sin(x) with ``mag`` = |sin x| + ``x.mag``.
    """
    s = np.sin(x.lo)
    return Interval(s, None, np.abs(s) + x.mag)


def _add(a: Enclosure | None, b: Enclosure | None) -> Enclosure | None:
    return b if a is None else a if b is None else a + b


def _mul(a: Enclosure | None, b: Enclosure | None) -> Enclosure | None:
    return None if a is None or b is None else a * b


class Jet:
    """Enclosures (value, first, second derivative) over an interval of the variable.

    ``d1`` and ``d2`` may be None, meaning zero: a constant has neither (so the parameters of
    an expression cost nothing in the products), the variable itself has no ``d2``.  numpy
    never operates on a jet itself (``__array_ufunc__ = None``): ``array * jet`` calls
    ``jet.__rmul__``.

    Parameters
    ----------
    v : Enclosure
        Enclosure of the value.
    d1, d2 : Enclosure or None
        Enclosures of the first and second derivatives; None for zero.

    Examples
    --------
    >>> x = Jet.variable(np.array([1.0]), np.array([2.0]))
    >>> y = x * x * x  # y'' = 6x on [1, 2]
    >>> bool(y.d2.lo[0] <= 6.0 and y.d2.hi[0] >= 12.0), float(np.round(y.bound2()[0], 9))
    (True, 12.0)
    """

    __slots__ = ("d1", "d2", "v")
    __array_ufunc__ = None

    def __init__(self, v: Enclosure, d1: Enclosure | None = None,
                 d2: Enclosure | None = None) -> None:
        self.v, self.d1, self.d2 = v, d1, d2

    @staticmethod
    def variable(lo: Array, hi: Array) -> Jet:
        """The variable itself over [lo, hi]: value [lo, hi], derivative 1, second 0.

        Parameters
        ----------
        lo, hi : ndarray
            The interval's ends (lo ≤ hi, exact floats), of one shape.

        Returns
        -------
        Jet
        """
        lo = np.asarray(lo, dtype=float)
        return Jet(Enclosure(lo, np.asarray(hi, dtype=float)), Enclosure(np.ones_like(lo)))

    @staticmethod
    def of(x: Any) -> Jet:
        """``x`` itself if it is a :class:`Jet`, else the constant ``x``.

        Parameters
        ----------
        x : Jet, Enclosure, float or ndarray
            A jet, or a constant (an enclosure or exact floats).

        Returns
        -------
        Jet
        """
        return x if isinstance(x, Jet) else Jet(Enclosure.of(x))

    def __add__(self, o: Any) -> Jet:
        o = Jet.of(o)
        return Jet(self.v + o.v, _add(self.d1, o.d1), _add(self.d2, o.d2))

    __radd__ = __add__

    def __neg__(self) -> Jet:
        return Jet(-self.v, None if self.d1 is None else -self.d1,
                   None if self.d2 is None else -self.d2)

    def __sub__(self, o: Any) -> Jet:
        return self + (-Jet.of(o))

    def __rsub__(self, o: Any) -> Jet:
        return Jet.of(o) + (-self)

    def __mul__(self, o: Any) -> Jet:
        a, b = self, Jet.of(o)
        d1 = _add(_mul(a.d1, b.v), _mul(a.v, b.d1))
        cross = _mul(a.d1, b.d1)
        d2 = _add(_add(_mul(a.d2, b.v), _mul(a.v, b.d2)), None if cross is None else cross * 2.0)
        return Jet(a.v * b.v, d1, d2)

    __rmul__ = __mul__

    def bound2(self) -> Array:
        """max |second derivative| over the interval (a rigorous bound).

        Returns
        -------
        ndarray
            max(|lo|, |hi|) of ``d2`` (0 where it is zero).
        """
        if self.d2 is None:
            return np.zeros_like(self.v.lo)
        return self.d2.magnitude()


def _trig_enclosure(x: Enclosure, rng: Any) -> Enclosure:
    lo, hi = rng(x.lo, x.hi)
    return Enclosure(lo, hi)


def jet_cos(u: Any) -> Any:
    """cos of a jet (chain rule) or of a point :class:`~stringstab.certify.interval.Interval`.

    (cos u)' = −sin u · u', (cos u)'' = −cos u · u'² − sin u · u''.

    Parameters
    ----------
    u : Jet or Interval
        The angle.

    Returns
    -------
    Jet or Interval
        Of the same kind as ``u`` (:func:`point_cos` for a point interval).
    """
    if isinstance(u, Interval):
        return point_cos(u)
    c = _trig_enclosure(u.v, cos_range)
    if u.d1 is None:
        return Jet(c)
    s = _trig_enclosure(u.v, sin_range)
    d2 = -(c * (u.d1 * u.d1))
    return Jet(c, -(s * u.d1), d2 if u.d2 is None else d2 - s * u.d2)


def jet_sin(u: Any) -> Any:
    """sin of a jet (chain rule) or of a point :class:`~stringstab.certify.interval.Interval`.

    (sin u)' = cos u · u', (sin u)'' = −sin u · u'² + cos u · u''.

    Parameters
    ----------
    u : Jet or Interval
        The angle.

    Returns
    -------
    Jet or Interval
        Of the same kind as ``u`` (:func:`point_sin` for a point interval).
    """
    if isinstance(u, Interval):
        return point_sin(u)
    s = _trig_enclosure(u.v, sin_range)
    if u.d1 is None:
        return Jet(s)
    c = _trig_enclosure(u.v, cos_range)
    d2 = -(s * (u.d1 * u.d1))
    return Jet(s, c * u.d1, d2 if u.d2 is None else d2 + c * u.d2)
