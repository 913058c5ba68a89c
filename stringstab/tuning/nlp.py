"""The CasADi/IPOPT problems of the nearest-point projection, built once per process and size.

Two NLPs in the decision K = (k_x, k_v, k_a), both minimising the weighted distance
Σ w_i (K_i − K0_i)² within the gain bounds:

:func:`projection_nlp`
    the continuous loop at one τ, δ, T*: the internal-stability conditions
    (:func:`stringstab.certify.criteria.hurwitz_conditions`, ≥ a margin) and the exact frequency
    condition g(ω_j; K) ≥ ε (:func:`stringstab.tuning.margin_terms.casadi_g`) on ``n`` frequency slots;
:func:`quadratic_nlp`
    the sampled and robust loops: ``n`` quadratic forms q_j(K) = c + bᵀK + KᵀAK ≥ a bound
    (:mod:`stringstab.tuning.constraints`).

Each exists in the slot capacities :data:`SLOT_SIZES` (built on first use; the smallest that
fits is used: an unused slot costs IPOPT about as much per iteration as a used one, and is
disabled by a lower bound of −∞).  :func:`solve_projection` and :func:`solve_quadratic` fill in
the parameters and solve.  The exchange that chooses the constraints is
:mod:`stringstab.tuning.exchange`; the :class:`~stringstab.tuning.Projector` drives both.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import cache
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify.criteria import hurwitz_conditions
from ..errors import StringStabError
from ..params import Params
from . import margin_terms
from .constraints import FORM_SIZE, Slot

__all__ = [
    "IPOPT_OPTIONS",
    "SLOT_SIZES",
    "projection_nlp",
    "quadratic_nlp",
    "solve_projection",
    "solve_quadratic",
]

Array = npt.NDArray[np.float64]

#: Frequency-slot capacities of the NLPs, each built on first use (the smallest that fits is
#: used: an unused slot costs IPOPT about as much per iteration as a used one).
SLOT_SIZES = (4, 6, 8, 10, 12, 14, 16, 20, 24, 28, 32, 40, 48)

#: IPOPT's options for every projection NLP.
IPOPT_OPTIONS = {
    "print_time": False,
    "error_on_fail": False,
    "ipopt.print_level": 0,
    "ipopt.sb": "yes",
    "ipopt.tol": 1e-8,
    "ipopt.constr_viol_tol": 1e-9,
    "ipopt.max_iter": 100,
    "ipopt.mu_strategy": "adaptive",
    "ipopt.mu_oracle": "probing",
}


def _import_casadi() -> Any:
    try:
        import casadi
    except ImportError as e:  # pragma: no cover - casadi is a core dependency
        raise StringStabError(
            "the projection method needs CasADi with IPOPT; install it with "
            "`pip install stringstab` (casadi is a core dependency) or `pip install casadi`"
        ) from e
    return casadi


@cache
def projection_nlp(n_slots: int) -> Any:
    """The projection NLP with ``n_slots`` frequency slots, built once per process.

    Decision K = (k_x, k_v, k_a); parameters p = (K0, w, τ, δ, T*, ω_1..ω_n).
    Constraints: k_x, k_v + (T* − τ) k_x (Hurwitz, lower bound = margin) and
    g(ω_j; K) for every slot (lower bound ε when active, −inf when inactive).

    Parameters
    ----------
    n_slots : int
        The number of frequency slots (one of :data:`SLOT_SIZES`).

    Returns
    -------
    casadi.Function
        The IPOPT solver of the NLP.
    """
    ca = _import_casadi()
    x = ca.SX.sym("K", 3)
    par = ca.SX.sym("p", 9 + n_slots)
    K0, w = par[0:3], par[3:6]
    tau, delta, T = par[6], par[7], par[8]
    kx, kv, ka = x[0], x[1], x[2]
    gs = margin_terms.casadi_g([par[9 + j] for j in range(n_slots)], kx, kv, ka, tau, delta, T)
    f = ca.sum1(w * (x - K0) ** 2)
    g = ca.vertcat(*hurwitz_conditions(kx, kv, ka, tau=tau, headway=T), *gs)
    return ca.nlpsol(f"stringstab_projection_{n_slots}", "ipopt",
                     {"x": x, "p": par, "f": f, "g": g}, IPOPT_OPTIONS)


@cache
def quadratic_nlp(n_slots: int) -> Any:
    """The projection NLP with ``n_slots`` quadratic constraints, built once per process.

    Decision K = (k_x, k_v, k_a); parameters p = (K0, w, then per slot the 10 numbers of a
    quadratic form q_j(K) = c + bᵀK + KᵀAK, :func:`stringstab.tuning.constraints.quadratic_form`).
    Constraints q_j(K) ≥ lower bound (a margin, ε, or −inf for an unused slot).

    Parameters
    ----------
    n_slots : int
        The number of constraint slots (one of :data:`SLOT_SIZES`).

    Returns
    -------
    casadi.Function
        The IPOPT solver of the NLP.
    """
    ca = _import_casadi()
    x = ca.SX.sym("K", 3)
    par = ca.SX.sym("p", 6 + FORM_SIZE * n_slots)
    K0, w = par[0:3], par[3:6]
    kx, kv, ka = x[0], x[1], x[2]
    mono = ca.vertcat(1, kx, kv, ka, kx * kx, 2 * kx * kv, 2 * kx * ka, kv * kv, 2 * kv * ka,
                      ka * ka)
    gs = [ca.dot(par[6 + FORM_SIZE * j: 6 + FORM_SIZE * (j + 1)], mono) for j in range(n_slots)]
    f = ca.sum1(w * (x - K0) ** 2)
    return ca.nlpsol(f"stringstab_projection_quadratic_{n_slots}", "ipopt",
                     {"x": x, "p": par, "f": f, "g": ca.vertcat(*gs)}, IPOPT_OPTIONS)


def solve_projection(K0: Array, x0: Array, omegas: Sequence[float], *, params: Params,
                     weights: Array, bounds: tuple[float, float], hurwitz_margin: float,
                     eps: float) -> tuple[Array, str, int]:
    """Solve :func:`projection_nlp` from ``x0`` with the frequency constraints at ``omegas``.

    Parameters
    ----------
    K0 : ndarray, shape (3,)
        The gains to repair (k_x [1/s²], k_v [1/s], k_a [-]).
    x0 : ndarray, shape (3,)
        The starting point (clipped to the bounds).
    omegas : sequence of float
        The frequencies ω_j (rad/s) of the constraints g(ω_j; K) ≥ ε; at most
        ``SLOT_SIZES[-1]``.
    params : Params
        τ, δ, T* (s) of the continuous loop.
    weights : ndarray, shape (3,)
        Weights w of the distance.
    bounds : (float, float)
        Bounds on every gain.
    hurwitz_margin : float
        Lower bound m of k_x and k_v + (T* − τ) k_x.
    eps : float
        Lower bound ε of g(ω_j; K).

    Returns
    -------
    K : ndarray, shape (3,)
        IPOPT's solution (a local one; the certificate decides).
    status : str
        IPOPT's return status.
    iterations : int
        IPOPT's iteration count.
    """
    n = next(s for s in SLOT_SIZES if s >= len(omegas))
    solver = projection_nlp(n)
    p = params
    om = np.zeros(n)
    om[: len(omegas)] = omegas
    lbg = np.full(n + 2, -np.inf)
    lbg[:2] = hurwitz_margin
    lbg[2: 2 + len(omegas)] = eps
    lo, hi = bounds
    par = np.concatenate([K0, weights, [p.tau, p.delta, p.headway], om])
    sol = solver(x0=np.clip(x0, lo, hi), p=par, lbx=lo, ubx=hi, lbg=lbg, ubg=np.inf)
    st = solver.stats()
    return np.asarray(sol["x"], dtype=float).ravel(), str(st["return_status"]), int(st["iter_count"])


def solve_quadratic(K0: Array, x0: Array, slots: Sequence[Slot], *, weights: Array,
                    bounds: tuple[float, float], hurwitz_margin: float,
                    eps: float) -> tuple[Array, str, int]:
    """Solve :func:`quadratic_nlp` from ``x0`` with the constraints of ``slots``.

    A stability slot is bounded below by ``hurwitz_margin``, a margin slot by ``eps``.

    Parameters
    ----------
    K0 : ndarray, shape (3,)
        The gains to repair (k_x [1/s²], k_v [1/s], k_a [-]).
    x0 : ndarray, shape (3,)
        The starting point (clipped to the bounds).
    slots : sequence of Slot
        The quadratic constraints (:class:`stringstab.tuning.constraints.Slot`); at most
        ``SLOT_SIZES[-1]``.
    weights : ndarray, shape (3,)
        Weights w of the distance.
    bounds : (float, float)
        Bounds on every gain.
    hurwitz_margin : float
        Lower bound of the stability slots.
    eps : float
        Lower bound of the margin slots.

    Returns
    -------
    K : ndarray, shape (3,)
        IPOPT's solution (a local one; the certificate decides).
    status : str
        IPOPT's return status.
    iterations : int
        IPOPT's iteration count.
    """
    n = next(s for s in SLOT_SIZES if s >= len(slots))
    solver = quadratic_nlp(n)
    forms = np.zeros((n, FORM_SIZE))
    forms[: len(slots)] = [sl.form for sl in slots]
    lbg = np.full(n, -np.inf)
    lbg[: len(slots)] = [hurwitz_margin if sl.kind == "stability" else eps for sl in slots]
    lo, hi = bounds
    par = np.concatenate([K0, weights, forms.ravel()])
    sol = solver(x0=np.clip(x0, lo, hi), p=par, lbx=lo, ubx=hi, lbg=lbg, ubg=np.inf)
    st = solver.stats()
    return np.asarray(sol["x"], dtype=float).ravel(), str(st["return_status"]), int(st["iter_count"])
