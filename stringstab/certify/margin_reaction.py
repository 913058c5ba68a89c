r"""The margin g_θ(ω) with a reaction delay θ_r, and the bounds its branch and bound rests on.

With the command delayed by θ_r (issue 25), |Γ(jω)| ≤ 1 at ω > 0 iff

.. math::
    g_θ(ω) = \frac{|D(jω)|^2 − |N(jω)|^2}{ω^2}
      = τ^2ω^4 + aω^2 + b + c_x \cos δω − c_v ω \sin δω
        + r_0 \cos θ_rω + r_2 ω^2 \cos θ_rω + r_1 ω \sin θ_rω \;\ge\; 0,

a = 1 − k_a², b = c² − k_v², c_x = 2k_xk_a, c_v = 2k_vk_a, r_0 = −2k_x, r_2 = −2τc,
r_1 = −2(c − τk_x), c = k_v + T*k_x (derived: :func:`stringstab.derive.reaction.margin_reaction`;
the eight coefficients are generated, ``reaction_margin_coefficients``, from the basis of
:data:`stringstab.derive.codegen_reaction.REACTION_MARGIN_BASIS`).  At θ_r = 0 it is g of
:mod:`stringstab.certify.margin` (the certificate then runs that code, not this one).

The bounds, each proven term by term from the basis:

* **tail** (:func:`tail_bound`): bounding every trigonometric factor by 1 in magnitude,
  g_θ(ω) ≥ τ²ω⁴ − Aω² − Bω − C with A = max(|r_2| − a, 0), B = |c_v| + |r_1|,
  C = max(|c_x| + |r_0| − b, 0), so g_θ > 0 beyond the quartic's positive root
  (:func:`stringstab.certify.quartic_tail.quartic_tail_bound`: Fujiwara, then Newton from above);
* **curvature** (:func:`curvature_bound`): |d²/dω² ω^k f(dω)| ≤ k(k−1)r^{k−2} + 2kd r^{k−1}
  + d²r^k for f = cos, sin and a delay d ∈ {δ, θ_r}, so M ≥ |g_θ''| on [0, r];
* **round-off** (:func:`g_and_slack`): 10⁻¹³ times the sum of the magnitudes of the terms,
  a trigonometric term's scaled by (1 + dω) for the round-off of its angle.

References
----------
Issue 25; IDL paper, Definition 1 (eq 10) and eq 11 (θ_r = 0).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ..derive import generated as _gen
from .quartic_tail import quartic_tail_bound
from .verdicts import ROUNDOFF_SLACK

__all__ = [
    "N_COEFFICIENTS",
    "coefficient_table",
    "curvature_bound",
    "g",
    "g_and_slack",
    "tail_bound",
]

Array = npt.NDArray[np.float64]
#: Coefficients of g_θ (t2, a, b, cx, cv, r0, r2, r1): generated, in the basis's order.
N_COEFFICIENTS = len(_gen.REACTION_MARGIN_COEFFICIENTS)


def coefficient_table(kx: Array, kv: Array, ka: Array, tau: Any, delta: Any, headway: Any,
                      theta: Any) -> Array:
    """One row per coefficient of g_θ, per round-off scale, then δ and θ_r: shape (2·8 + 2, n).

    Parameters
    ----------
    kx, kv, ka : ndarray, shape (n,)
        The gains.
    tau, delta, headway, theta : float or ndarray of shape (n,)
        τ, δ, T*, θ_r (s).

    Returns
    -------
    ndarray, shape (18, n)
        Rows 0-7 the coefficients (``reaction_margin_coefficients``), 8-15 their scales
        (``reaction_margin_coefficient_scales``), 16 δ and 17 θ_r.

    Examples
    --------
    >>> Q = coefficient_table(np.array([1.0]), np.array([0.5]), np.array([0.2]), 0.1, 0.2, 1.1, 0.3)
    >>> Q[:8, 0].round(4).tolist()  # t2, a, b, cx, cv, r0, r2, r1
    [0.01, 0.96, 2.31, 0.4, 0.2, -2.0, -0.32, -3.0]
    """
    n = kx.size
    Q = np.empty((2 * N_COEFFICIENTS + 2, n))
    args = (kx, kv, ka, tau, delta, headway, theta)
    for i, v in enumerate((*_gen.reaction_margin_coefficients(*args),
                           *_gen.reaction_margin_coefficient_scales(*args), delta, theta)):
        Q[i] = v
    return Q


def g_and_slack(omega: Array, Q: Array) -> tuple[Array, Array]:
    """g_θ(ω) and its round-off slack 10⁻¹³·S(ω) from a :func:`coefficient_table` (columns).

    Parameters
    ----------
    omega : ndarray
        Frequencies, rad/s, broadcast against ``Q``'s rows.
    Q : ndarray, shape (18, ...)
        :func:`coefficient_table`, its rows broadcastable against ``omega``.

    Returns
    -------
    (ndarray, ndarray)
        g_θ(ω) and the slack (step "round-off" of the module docstring).
    """
    gv, sv = _and_scale(omega, Q[:N_COEFFICIENTS], Q[N_COEFFICIENTS:2 * N_COEFFICIENTS],
                        Q[2 * N_COEFFICIENTS], Q[2 * N_COEFFICIENTS + 1])
    return gv, ROUNDOFF_SLACK * sv


def _and_scale(omega: Any, co: Any, sc: Any, delta: Any, theta: Any) -> tuple[Any, Any]:
    """The generated (g_θ, scale) from the coefficients ``co`` and scales ``sc`` (8 each)."""
    t2, a, b, cx, cv, r0, r2, r1 = co
    s_t2, s_a, s_b, s_cx, s_cv, s_r0, s_r2, s_r1 = sc
    gv, sv = _gen.reaction_margin_and_scale(omega, t2, a, b, cx, cv, r0, r2, r1, s_t2, s_a, s_b,
                                            s_cx, s_cv, s_r0, s_r2, s_r1, delta, theta)
    return gv, sv


def g(omega: npt.ArrayLike, k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike, *,
      tau: npt.ArrayLike, delta: npt.ArrayLike, headway: npt.ArrayLike,
      reaction_delay: npt.ArrayLike) -> Array:
    """g_θ(ω) = (|D(jω)|² − |N(jω)|²)/ω² with the reaction delay (module docstring).

    Parameters
    ----------
    omega : array_like
        Frequencies ω ≥ 0, rad/s.
    k_x, k_v, k_a : array_like
        Gains of IDL eq 4.
    tau, delta, headway, reaction_delay : array_like
        τ, δ, T*, θ_r (s).

    Returns
    -------
    ndarray
        g_θ(ω), broadcast over every input; |Γ(jω)| ≤ 1 at ω > 0 iff g_θ(ω) ≥ 0.

    Examples
    --------
    >>> from stringstab.certify.margin import g as g0
    >>> args = (1.0, 0.5, 0.2)
    >>> bool(np.isclose(g(1.3, *args, tau=0.1, delta=0.2, headway=1.1, reaction_delay=0.0),
    ...                 g0(1.3, *args, tau=0.1, delta=0.2, headway=1.1)))
    True
    """
    kx, kv, ka, t, d, h, th = (np.asarray(v, dtype=float)
                               for v in (k_x, k_v, k_a, tau, delta, headway, reaction_delay))
    co = _gen.reaction_margin_coefficients(kx, kv, ka, t, d, h, th)
    sc = _gen.reaction_margin_coefficient_scales(kx, kv, ka, t, d, h, th)
    gv, _ = _and_scale(np.asarray(omega, dtype=float), co, sc, d, th)
    return np.asarray(gv)


def curvature_bound(r: Array, Q: Array) -> Array:
    """M ≥ |g_θ''(ω)| for every ω ∈ [0, r] (generated, term by term; module docstring).

    Parameters
    ----------
    r : ndarray
        Right ends of the intervals, rad/s.
    Q : ndarray, shape (18, ...)
        :func:`coefficient_table`, broadcastable against ``r``.

    Returns
    -------
    ndarray
        M, elementwise.
    """
    k = N_COEFFICIENTS
    t2, a, b, cx, cv, r0, r2, r1 = Q[:k]
    return np.asarray(_gen.reaction_margin_curvature_bound(r, t2, a, b, cx, cv, r0, r2, r1,
                                                           Q[2 * k], Q[2 * k + 1]))


def tail_bound(Q: Array) -> Array:
    """Ω with g_θ(ω) > 0 for every ω > Ω (module docstring: the quartic minorant).

    Parameters
    ----------
    Q : ndarray, shape (18, n)
        :func:`coefficient_table`.

    Returns
    -------
    ndarray, shape (n,)
        Ω ≥ 1e-3, rad/s.

    Examples
    --------
    >>> Q = coefficient_table(np.array([0.9]), np.array([-0.5]), np.array([1.1]), 0.1, 0.2, 1.1, 0.4)
    >>> W = tail_bound(Q)
    >>> w = np.linspace(W[0], 50 * W[0], 20_000)
    >>> bool(np.all(g(w, 0.9, -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1, reaction_delay=0.4) > 0))
    True
    """
    t2 = Q[0]
    # the polynomial part of each power of ω, less the amplitudes of its trigonometric terms
    lower = {0: np.array(Q[2]), 1: np.zeros_like(t2), 2: np.array(Q[1])}
    for i, (_name, trig, power) in enumerate(_gen.REACTION_MARGIN_BASIS):
        if trig != "1":
            lower[power] = lower[power] - np.abs(Q[i])
    A, B, C = (np.maximum(-lower[p], 0.0) / t2 for p in (2, 1, 0))
    return quartic_tail_bound(A, B, C)
