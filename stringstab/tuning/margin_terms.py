r"""The margin g(ω; K) in the forms only the gain tuning uses: gradient, Newton terms, CasADi.

The margin g(ω) = (|D(jω)|² − |N(jω)|²)/ω² of :mod:`stringstab.certify.margin` (IDL eq 11,
derived form; g(0) = Ψ3, eqs 12-14) and its derivatives, all *generated* from the SymPy
derivation into :mod:`stringstab.derive.generated`, in three forms:

* **vectorised** (NumPy broadcasting): :func:`gradient` (g and ∇_K g, the Newton predictor);
* **scalar** (the ``math`` module, for inner loops where NumPy's per-call overhead dominates):
  :func:`newton_terms` (the predictor's Newton step on the KKT system);
* **CasADi** (symbolic, for the projection NLP): :func:`casadi_g`.

The certificates never use them (they live in :mod:`stringstab.certify.margin`); they moved here
from there (issue 32 item 3).

References
----------
IDL paper, Definition 1 (eq 10), eq 11 (derived form) and eqs 12-14 (g(0) = Ψ3).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ..derive import generated as _gen

__all__ = ["casadi_g", "gradient", "newton_terms"]

ArrayLike = npt.ArrayLike
Array = npt.NDArray[np.float64]


def gradient(omega: ArrayLike, K: ArrayLike, *, tau: float, delta: float,
             headway: float) -> tuple[Array, Array]:
    """g(ω; K) and ∇_K g(ω; K) on an array of frequencies (rows of the gradient: ω).

    Parameters
    ----------
    omega : array_like, shape (n,)
        Frequencies, rad/s.
    K : array_like, shape (3,)
        The gains (k_x, k_v, k_a).
    tau, delta, headway : float
        Lag τ, delay δ and time headway T*, s.

    Returns
    -------
    (ndarray (n,), ndarray (n, 3))
    """
    w = np.asarray(omega, dtype=float)
    kx, kv, ka = K[0], K[1], K[2]  # type: ignore[index]
    gv, gx, gvv, ga = _gen.margin_gradient(w, kx, kv, ka, tau, delta, headway)
    grad = np.empty((*w.shape, 3))
    grad[..., 0] = gx
    grad[..., 1] = gvv
    grad[..., 2] = ga
    return np.asarray(gv, dtype=float), grad


def newton_terms(omega: float, k_x: float, k_v: float, k_a: float,
                 tau: float, delta: float, headway: float
                 ) -> tuple[float, Array, float, Array, float, Array]:
    """g and the derivatives a Newton step on the KKT system needs, in scalar arithmetic.

    The ``math``-module form of the generated derivatives (NumPy's per-call overhead
    costs more than the arithmetic at one frequency).

    Parameters
    ----------
    omega : float
        Angular frequency ω, rad/s.
    k_x, k_v, k_a : float
        Gains of IDL eq 4: k_x in 1/s², k_v in 1/s, k_a dimensionless.
    tau : float
        Actuator lag τ, s.
    delta : float
        Communication delay δ, s.
    headway : float
        Desired time headway T*, s.

    Returns
    -------
    tuple
        (g, ∇_K g, ∂g/∂ω, ∇_K ∂g/∂ω, ∂²g/∂ω², ∇²_KK g) at ω, the vectors as arrays of
        shape (3,) and the Hessian (3, 3).
    """
    (gv, g0, g1, g2, gw, gw0, gw1, gw2, gww,
     hxx, hxv, hxa, hvv, hva, haa) = _gen.margin_newton(
        omega, k_x, k_v, k_a, tau, delta, headway, math.cos, math.sin)
    return (gv, np.array((g0, g1, g2)), gw, np.array((gw0, gw1, gw2)), gww,
            np.array(((hxx, hxv, hxa), (hxv, hvv, hva), (hxa, hva, haa))))


def casadi_g(omegas: Sequence[Any], k_x: Any, k_v: Any, k_a: Any, tau: Any, delta: Any,
             headway: Any) -> list[Any]:
    """g(ω_j; K) for each ω_j of ``omegas``, as CasADi expressions (the projection NLP).

    The generated coefficients are built once and shared by every frequency (as in
    :func:`g_from_coefficients`), with ``casadi.cos``/``casadi.sin``.

    Parameters
    ----------
    omegas : sequence
        Frequencies ω_j, rad/s (floats or CasADi expressions).
    k_x, k_v, k_a : float or casadi.SX or casadi.MX
        Gains of IDL eq 4 (k_x in 1/s², k_v in 1/s, k_a dimensionless), typically symbols.
    tau : float or CasADi expression
        Actuator lag τ, s.
    delta : float or CasADi expression
        Communication delay δ, s.
    headway : float or CasADi expression
        Desired time headway T*, s.

    Returns
    -------
    list
        One CasADi expression g(ω_j; K) per entry of ``omegas``.

    Examples
    --------
    >>> import casadi
    >>> K = casadi.SX.sym("K", 3)
    >>> (e,) = casadi_g([0.0], K[0], K[1], K[2], 0.1, 0.2, 1.1)
    >>> float(casadi.Function("g", [K], [e])([1.0, 0.5, 0.2]))  # = Ψ3
    0.71
    """
    import casadi

    t2, a, b, cx, cv = _gen.margin_coefficients(k_x, k_v, k_a, tau, delta, headway)
    return [_gen.margin_from_coefficients(w, t2, a, b, cx, cv, delta, casadi.cos, casadi.sin)
            for w in omegas]
