r"""The quartic minorant's root bound: Ω with ω⁴ − Aω² − Bω − C > 0 beyond it (A, B, C ≥ 0).

The tail of every margin of the continuous loop is bounded below by such a quartic times a
positive factor (:func:`stringstab.certify.margin.tail_bound`, and the reaction-delay margin,
:mod:`stringstab.certify.margin_reaction`), so a bound Ω on its one positive root ends the
frequency interval the branch and bound must cover.  Fujiwara's bound starts Newton's method
from above (:func:`fujiwara_bound`, :func:`quartic_tail_bound`); a few quartics (the point
certificate's one-row calls) iterate on Python floats, the same operations bit for bit.

References
----------
M. Fujiwara, "Über die obere Schranke des absoluten Betrages der Wurzeln einer algebraischen
Gleichung", Tôhoku Math. J. 10 (1916) 167–171.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

__all__ = ["SMALL_TAIL_BATCH", "fujiwara_bound", "quartic_tail_bound"]

Array = npt.NDArray[np.float64]
ArrayLike = npt.ArrayLike


def fujiwara_bound(A: ArrayLike, B: ArrayLike, C: ArrayLike) -> Array:
    """Fujiwara's bound 2·max(√A, ∛B, (C/2)^¼) on the roots of ω⁴ − Aω² − Bω − C.

    Parameters
    ----------
    A, B, C : array_like
        Non-negative coefficients of ω⁴ − Aω² − Bω − C
        (:func:`~stringstab.certify.margin.tail_coefficients`).

    Returns
    -------
    ndarray
        An upper bound on the absolute value of every root (Fujiwara 1916), elementwise.

    Examples
    --------
    >>> float(fujiwara_bound(4.0, 0.0, 0.0))  # ω⁴ − 4ω² has its roots at 0 and ±2
    4.0
    """
    return np.asarray(2.0 * np.maximum(np.maximum(np.sqrt(A), np.cbrt(B)),
                                       np.sqrt(np.sqrt(np.divide(C, 2.0)))))




def quartic_tail_bound(A: ArrayLike, B: ArrayLike, C: ArrayLike) -> Array:
    """Ω ≥ the positive root of L(ω) = ω⁴ − Aω² − Bω − C (A, B, C ≥ 0), so L > 0 beyond Ω.

    The quartic minorant of :func:`~stringstab.certify.margin.tail_bound` (and of the reaction-delay margin,
    :mod:`stringstab.certify.margin_reaction`): Newton's method from Fujiwara's bound
    (:func:`fujiwara_bound`) decreases monotonically to the one positive root (L is convex
    beyond it), and every iterate is ≥ it, so the iteration may stop at any step.

    Parameters
    ----------
    A, B, C : array_like
        Non-negative coefficients of the minorant
        (e.g. :func:`~stringstab.certify.margin.tail_coefficients`).

    Returns
    -------
    ndarray
        Ω ≥ 1e-3, elementwise.

    Examples
    --------
    >>> W = quartic_tail_bound(4.0, 0.0, 0.0)  # ω⁴ − 4ω² = 0 at ω = 2
    >>> bool(2.0 <= float(W) < 2.0 + 1e-5)
    True
    """
    A, B, C = (np.asarray(v, dtype=float) for v in (A, B, C))
    if A.size <= SMALL_TAIL_BATCH and A.shape == B.shape == C.shape:
        return _quartic_tail_bound_small(A, B, C)
    w = np.maximum(fujiwara_bound(A, B, C), 1e-3)
    for _ in range(30):
        L = ((w * w - A) * w - B) * w - C
        dL = (4.0 * w * w - 2.0 * A) * w - B
        step = np.where(dL > 0, L / np.where(dL > 0, dL, 1.0), 0.0)
        # iterates stay >= the root; stop shrinking below the floor
        w = np.maximum(w - step, 1e-3)
        if np.all(step <= 1e-6 * w):  # any iterate is a valid bound: stop when settled
            break
    W = w * (1.0 + 1e-9) + 1e-12
    Lw = ((W * W - A) * W - B) * W - C
    bad = ~(Lw > 0) & ((A > 0) | (B > 0) | (C > 0))
    if bad.any():  # pragma: no cover - defensive: fall back to the raw Fujiwara bound
        W = np.where(bad, fujiwara_bound(A, B, C) + 1.0, W)
    return np.asarray(W)


#: Up to this many quartics, :func:`quartic_tail_bound` iterates on Python floats (the point
#: certificate's one-row calls): the same operations, hence the same bits, without the cost
#: of numpy on arrays of one element.
SMALL_TAIL_BATCH = 8


def _quartic_tail_bound_small(A: Array, B: Array, C: Array) -> Array:
    """:func:`quartic_tail_bound` of a few quartics, on Python floats, bit for bit.

    Every operation is the vectorised one's, in its order and in IEEE double (``math.sqrt``
    is correctly rounded, as numpy's is; the cube roots are numpy's), and the iteration stops at the same
    step for all (the vectorised stopping rule), so the result is the same to the bit
    (``tests/derive/test_margin.py`` compares them).
    """
    a, b, c = A.ravel().tolist(), B.ravel().tolist(), C.ravel().tolist()
    cb = np.cbrt(B).ravel().tolist()  # numpy's cube root (math.cbrt is Python 3.11+)
    n = len(a)
    w = [max(2.0 * max(max(math.sqrt(a[i]), cb[i]), math.sqrt(math.sqrt(c[i] / 2.0))), 1e-3)
         for i in range(n)]
    for _ in range(30):
        settled = True
        for i in range(n):
            wi = w[i]
            L = ((wi * wi - a[i]) * wi - b[i]) * wi - c[i]
            dL = (4.0 * wi * wi - 2.0 * a[i]) * wi - b[i]
            step = L / dL if dL > 0 else 0.0
            w[i] = max(wi - step, 1e-3)
            settled = settled and step <= 1e-6 * w[i]
        if settled:
            break
    out = []
    for i in range(n):
        W = w[i] * (1.0 + 1e-9) + 1e-12
        Lw = ((W * W - a[i]) * W - b[i]) * W - c[i]
        if not Lw > 0 and (a[i] > 0 or b[i] > 0 or c[i] > 0):  # pragma: no cover - defensive
            W = float(fujiwara_bound(a[i], b[i], c[i])) + 1.0
        out.append(W)
    return np.array(out, dtype=float).reshape(A.shape)


