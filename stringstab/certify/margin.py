r"""The frequency-domain margin g(ω) and everything computed from it: one home.

For the derived transfer function Γ(s) = N(s)/D(s) (IDL eq 11, derived form,
:func:`stringstab.derive.symbolic.gamma`), |Γ(jω)| ≤ 1 at ω > 0 iff

.. math::
    g(ω) = \frac{|D(jω)|^2 - |N(jω)|^2}{ω^2}
         = t_2 ω^4 + a ω^2 + b + c_x \cos δω - c_v ω \sin δω \;\ge\; 0,

with t₂ = τ², c = k_v + T*k_x, a = 1 − 2τc − k_a², b = c² − 2k_x − k_v²,
c_x = 2k_xk_a, c_v = 2k_vk_a (g(0) = Ψ3).  Every formula here is *generated* from
the SymPy derivation into :mod:`stringstab.derive.generated` (``python -m stringstab.derive.codegen``),
so the certificate, the region maps, the gain repair and the NLP evaluate the same
expressions (vectorised, NumPy broadcasting): :func:`coefficients`, :func:`g`,
:func:`g_and_scale`, :func:`curvature_bound`.  The derivatives only the tuning uses (∇_K g, the
Newton terms, the CasADi form) live in :mod:`stringstab.tuning.margin_terms`.

Beside them, the bounds the branch and bound of :mod:`stringstab.certify.continuous`
rests on: :func:`curvature_bound` (M ≥ |g''| on [0, r]) and :func:`tail_bound`
(Ω with g > 0 beyond it, from Fujiwara's root bound refined by Newton's method).

References
----------
IDL paper, Definition 1 (eq 10), eq 11 (derived form) and eqs 12-14 (g(0) = Ψ3).
M. Fujiwara, "Über die obere Schranke des absoluten Betrages der Wurzeln einer
algebraischen Gleichung", Tohoku Math. J. 10 (1916) 167-171.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt

from ..derive import generated as _gen
from .quartic_tail import fujiwara_bound, quartic_tail_bound

__all__ = [
    "MarginCoefficients",
    "coefficient_scales",
    "coefficients",
    "curvature_bound",
    "g",
    "g_and_scale",
    "g_from_coefficients",
    "local_minima",
    "separable",
    "tail_bound",
    "tail_coefficients",
]

ArrayLike = npt.ArrayLike
Array = npt.NDArray[np.float64]
#: Coefficients (or scales) of g: a :class:`MarginCoefficients`, a tuple or an array of 5 rows.
_Coefficients = Any


class MarginCoefficients(NamedTuple):
    """g(ω) = t2 ω⁴ + a ω² + b + cx cos(δω) − cv ω sin(δω) (broadcast arrays or floats)."""

    t2: Any
    a: Any
    b: Any
    cx: Any
    cv: Any


def coefficients(
    k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> MarginCoefficients:
    """The coefficients (t2, a, b, cx, cv) of g (generated from the SymPy derivation).

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains of IDL eq 4: k_x in 1/s², k_v in 1/s, k_a dimensionless.
    tau : array_like
        Actuator lag τ, s.
    delta : array_like
        Communication delay δ, s.
    headway : array_like
        Desired time headway T*, s.

    Returns
    -------
    MarginCoefficients
        t2 = τ², a = 1 − 2τc − k_a², b = c² − 2k_x − k_v², cx = 2k_xk_a, cv = 2k_vk_a with
        c = k_v + T*k_x (module docstring), broadcast over the inputs.

    Examples
    --------
    >>> c = coefficients(1.0, 0.5, 0.2, tau=0.1, delta=0.2, headway=1.1)
    >>> round(float(c.b + c.cx), 12)  # g(0) = Ψ3
    0.71
    """
    kx, kv, ka = (np.asarray(k, dtype=float) for k in (k_x, k_v, k_a))
    return MarginCoefficients(*_gen.margin_coefficients(kx, kv, ka, tau, delta, headway))


def coefficient_scales(
    k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> MarginCoefficients:
    """Σ |term| of each coefficient: the scale of its round-off (≥ its absolute value).

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains of IDL eq 4: k_x in 1/s², k_v in 1/s, k_a dimensionless.
    tau : array_like
        Actuator lag τ, s.
    delta : array_like
        Communication delay δ, s.
    headway : array_like
        Desired time headway T*, s.

    Returns
    -------
    MarginCoefficients
        For each coefficient of :func:`coefficients`, the sum of the absolute values of
        the terms it is computed from (a round-off error is a small multiple of it).
    """
    kx, kv, ka = (np.asarray(k, dtype=float) for k in (k_x, k_v, k_a))
    return MarginCoefficients(*_gen.margin_coefficient_scales(kx, kv, ka, tau, delta, headway))


def separable(
    k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike, *, headway: ArrayLike,
) -> tuple[tuple[Any, ...], tuple[Any, ...]]:
    """g split as (τω² − c)² + h2 ω² + h0 + cx cos δω − cv ω sin δω, and round-off scales.

    Returns ((c, h2, h0, cx, cv), their Σ |term| scales); only c depends on the parameters
    (on T*), so the minimum of g over a box of τ, δ, T* has a closed form
    (:mod:`stringstab.certify.robust`).  Generated from the derivation (:func:`stringstab.derive.codegen.margin_separable`).

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains of IDL eq 4: k_x in 1/s², k_v in 1/s, k_a dimensionless.
    headway : array_like
        Desired time headway T*, s (the only parameter the split depends on).

    Returns
    -------
    values : tuple
        (c, h2, h0, cx, cv) with c = k_v + T*k_x; broadcast arrays.
    scales : tuple
        The Σ |term| round-off scale of each entry of ``values``.

    Examples
    --------
    >>> (c, h2, h0, cx, cv), _ = separable(1.0, 0.5, 0.2, headway=1.1)
    >>> w, tau, delta = 2.0, 0.1, 0.2
    >>> split = (tau * w * w - c) ** 2 + h2 * w * w + h0 + cx * np.cos(delta * w) - cv * w * np.sin(delta * w)
    >>> bool(np.isclose(split, g(w, 1.0, 0.5, 0.2, tau=tau, delta=delta, headway=1.1)))
    True
    """
    kx, kv, ka = (np.asarray(k, dtype=float) for k in (k_x, k_v, k_a))
    return (_gen.margin_separable(kx, kv, ka, 0.0, 0.0, headway),
            _gen.margin_separable_scales(kx, kv, ka, 0.0, 0.0, headway))


def g_from_coefficients(omega: ArrayLike, co: _Coefficients,
                        delta: ArrayLike) -> Array:
    """g(ω) from its coefficients (broadcasting coefficient columns against a grid of ω).

    Parameters
    ----------
    omega : array_like
        Angular frequencies ω ≥ 0, rad/s.
    co : MarginCoefficients or sequence of 5 array_like
        (t2, a, b, cx, cv) from :func:`coefficients`, broadcast against ``omega``.
    delta : array_like
        Communication delay δ, s.

    Returns
    -------
    ndarray
        g(ω) = t2ω⁴ + aω² + b + cx cos δω − cv ω sin δω, of the broadcast shape.
    """
    t2, a, b, cx, cv = co
    return np.asarray(_gen.margin_from_coefficients(np.asarray(omega, dtype=float), t2, a, b, cx, cv,
                                                    delta))


def g_and_scale(omega: Array, co: _Coefficients,
                scales: _Coefficients, delta: Any) -> tuple[Array, Array]:
    """(g(ω), S(ω)) with S(ω) ≥ Σ |terms of g(ω)|: a round-off slack is a multiple of S.

    Parameters
    ----------
    omega : ndarray
        Angular frequencies ω ≥ 0, rad/s.
    co : MarginCoefficients or sequence of 5 array_like
        (t2, a, b, cx, cv) from :func:`coefficients`.
    scales : MarginCoefficients or sequence of 5 array_like
        Their round-off scales from :func:`coefficient_scales`.
    delta : array_like
        Communication delay δ, s.

    Returns
    -------
    gv : ndarray
        g(ω).
    sv : ndarray
        S(ω) ≥ Σ |terms of g(ω)|, the scale of the round-off in ``gv``.
    """
    t2, a, b, cx, cv = co
    st2, sa, sb, scx, scv = scales
    gv, sv = _gen.margin_and_scale(omega, t2, a, b, cx, cv, st2, sa, sb, scx, scv, delta)
    return gv, sv


def g(
    omega: ArrayLike, k_x: ArrayLike, k_v: ArrayLike, k_a: ArrayLike,
    *, tau: ArrayLike, delta: ArrayLike, headway: ArrayLike,
) -> Array:
    """g(ω) = (|D(jω)|² − |N(jω)|²)/ω², continuous at ω = 0 where g(0) = Ψ3.

    Parameters
    ----------
    omega : array_like
        Angular frequencies ω ≥ 0, rad/s.
    k_x, k_v, k_a : array_like
        Gains of IDL eq 4: k_x in 1/s², k_v in 1/s, k_a dimensionless.
    tau : array_like
        Actuator lag τ, s.
    delta : array_like
        Communication delay δ, s.
    headway : array_like
        Desired time headway T*, s.

    Returns
    -------
    ndarray
        g(ω), broadcast over all inputs; |Γ(jω)| ≤ 1 (IDL eq 10) at ω > 0 iff g(ω) ≥ 0.

    Examples
    --------
    >>> float(g(0.0, 1.0, 0.5, 0.2, tau=0.1, delta=0.2, headway=1.1))  # = Ψ3
    0.71
    """
    co = coefficients(k_x, k_v, k_a, tau=tau, delta=delta, headway=headway)
    return g_from_coefficients(omega, co, delta)


def curvature_bound(r: ArrayLike, co: _Coefficients,
                    delta: ArrayLike) -> Array:
    """M ≥ |g''(ω)| for every ω ∈ [0, r], term by term (generated from the basis of g).

    For g = t2ω⁴ + aω² + b + cx cos δω − cv ω sin δω this is
    M = 12 t2 r² + 2|a| + |cx| δ² + |cv| (2δ + δ² r).

    Parameters
    ----------
    r : array_like
        Right end of the frequency interval [0, r], rad/s.
    co : MarginCoefficients or sequence of 5 array_like
        (t2, a, b, cx, cv) from :func:`coefficients`.
    delta : array_like
        Communication delay δ, s.

    Returns
    -------
    ndarray
        M, elementwise.
    """
    t2, a, b, cx, cv = co
    return np.asarray(_gen.margin_curvature_bound(r, t2, a, b, cx, cv, delta))


# --------------------------------------------------------------------------- tail bound
def tail_coefficients(t2: ArrayLike, a: ArrayLike, b: ArrayLike, cx: ArrayLike,
                      cv: ArrayLike) -> tuple[Array, Array, Array]:
    """(A, B, C) with g(ω)/t2 ≥ ω⁴ − Aω² − Bω − C for ω ≥ 0.

    Each trigonometric term is bounded by its magnitude: cx cos δω ≥ −|cx|,
    −cv ω sin δω ≥ −|cv| ω; so A = max(−a, 0)/t2, B = |cv|/t2, C = max(|cx| − b, 0)/t2.

    Parameters
    ----------
    t2, a, b, cx, cv : array_like
        Coefficients of g (:func:`coefficients`); t2 = τ² must be > 0.

    Returns
    -------
    A, B, C : ndarray
        Non-negative coefficients of the quartic minorant, broadcast together.
    """
    A = np.maximum(np.negative(a), 0.0) / t2
    B = np.abs(cv) / t2
    C = np.maximum(np.abs(cx) - b, 0.0) / t2
    if not np.shape(A) == np.shape(B) == np.shape(C):
        A, B, C = np.broadcast_arrays(A, B, C)
    return np.asarray(A, dtype=float), np.asarray(B, dtype=float), np.asarray(C, dtype=float)


def tail_bound(t2: ArrayLike, a: ArrayLike, b: ArrayLike, cx: ArrayLike, cv: ArrayLike) -> Array:
    """A frequency Ω with g(ω) > 0 for every ω > Ω.

    g(ω) ≥ t2·L(ω) with L(ω) = ω⁴ − Aω² − Bω − C (:func:`tail_coefficients`).  L has
    one positive root ω* (Descartes); Newton's method from Fujiwara's bound
    (:func:`~stringstab.certify.quartic_tail.fujiwara_bound`) decreases monotonically to it
    (L is convex beyond ω*),
    and every iterate is ≥ ω*, so the iteration may stop at any step.

    Parameters
    ----------
    t2, a, b, cx, cv : array_like
        Coefficients of g (:func:`coefficients`).

    Returns
    -------
    ndarray
        Ω ≥ 1e-3, elementwise.

    Examples
    --------
    >>> co = coefficients(np.array([0.9]), -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1)
    >>> W = tail_bound(*co)
    >>> w = np.linspace(W[0], 50 * W[0], 10_000)
    >>> bool(np.all(g(w, 0.9, -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1) > 0))
    True
    """
    return quartic_tail_bound(*tail_coefficients(t2, a, b, cx, cv))


# --------------------------------------------------------------------------- dips
def local_minima(K: ArrayLike, *, tau: float, delta: float, headway: float, threshold: float,
                 n: int = 384, max_minima: int = 12) -> tuple[float, list[float]]:
    """Cheap scan of g(·; K): (minimum found, refined local minimisers with g < threshold).

    A dense grid on [0, max(Ω_F, 1)], Ω_F Fujiwara's bound beyond which g > 0
    (:func:`~stringstab.certify.quartic_tail.fujiwara_bound`), then the ``max_minima``
    lowest local minima of the grid
    (including the end point ω = 0) are zoomed into (a 9-point grid, shrunk ×4, six
    times) and those below ``threshold`` returned.  A heuristic to pick frequencies and
    detect violations; it never certifies anything.

    Parameters
    ----------
    K : array_like, shape (3,)
        The gains (k_x, k_v, k_a): k_x in 1/s², k_v in 1/s, k_a dimensionless.
    tau : float
        Actuator lag τ, s.
    delta : float
        Communication delay δ, s.
    headway : float
        Desired time headway T*, s.
    threshold : float
        Only refined minimisers with g below this value are returned.
    n : int
        Number of points of the initial grid.
    max_minima : int
        How many of the lowest grid minima are refined.

    Returns
    -------
    gmin : float
        The smallest value of g found (grid and refined points).
    dips : list of float
        The refined local minimisers ω (rad/s) at which g < ``threshold``.

    Examples
    --------
    >>> gmin, dips = local_minima([0.9, -0.5, 1.1], tau=0.1, delta=0.2, headway=1.1, threshold=0.0)
    >>> gmin < 0, [round(w, 3) for w in dips]
    (True, [2.709])
    """
    kx, kv, ka = (float(v) for v in np.asarray(K, dtype=float))
    co = _gen.margin_coefficients(kx, kv, ka, tau, delta, headway)
    A, B, C = (float(v) for v in tail_coefficients(*co))
    om_max = max(float(fujiwara_bound(A, B, C)), 1.0)
    W = np.linspace(0.0, om_max, n)
    Gv = g_from_coefficients(W, co, delta)
    gmin = float(Gv.min())
    # local minima of the grid, the lowest first; a dip narrower than the grid spacing can
    # hide between samples, so all are refined
    left = np.concatenate([[np.inf], Gv[:-1]])
    right = np.concatenate([Gv[1:], [np.inf]])
    idx = np.flatnonzero((Gv <= left) & (Gv <= right))
    idx = idx[np.argsort(Gv[idx])[:max_minima]]
    centres = W[idx]
    half = np.full(idx.size, om_max / (n - 1))
    v = np.linspace(-1.0, 1.0, 9)
    for _ in range(6):
        Wl = np.maximum(centres[:, None] + half[:, None] * v[None, :], 0.0)
        Gl = g_from_coefficients(Wl, co, delta)
        jl = np.argmin(Gl, axis=1)
        centres = Wl[np.arange(idx.size), jl]
        half = half / 4.0
    gl = g_from_coefficients(centres, co, delta)
    gmin = min(gmin, float(gl.min()))
    return gmin, [float(c) for c, gv in zip(centres, gl) if gv < threshold]
