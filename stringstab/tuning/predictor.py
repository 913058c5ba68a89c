"""The projection's predictor: Newton's method on the KKT system of a small active set.

Before any IPOPT solve, :func:`predict` solves the projection problem of
:func:`stringstab.tuning.project` with the few constraints most violated at K0 active (an
internal-stability margin, a bound, Ψ3 = g(0) ≥ ε, or g ≥ ε at a dip whose frequency is a
variable), and hands its point back only when every multiplier is positive, nothing is
violated and the exact certificate certifies it.  The derivatives of g come from
:mod:`stringstab.certify.margin` (generated from the SymPy derivation; the scalar form, for latency).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify import margin as _margin
from ..certify.criteria import HURWITZ_LABELS, hurwitz_gradients
from ..certify.verdicts import Verdict
from ..params import Params
from . import margin_terms
from .inputs import GAIN_NAMES

__all__ = ["predict", "predict_dips", "violating_dips"]

Array = npt.NDArray[np.float64]


def violating_dips(K: Array, p: Params, threshold: float) -> tuple[float, list[float]]:
    """The violating dips of g(·; K) (:func:`stringstab.certify.margin.local_minima`).

    Parameters
    ----------
    K : ndarray, shape (3,)
        Gains (k_x [1/s²], k_v [1/s], k_a [-]) of IDL eq 4.
    p : Params
        τ, δ, T* of the continuous loop (s).
    threshold : float
        A local minimiser of the margin g(ω) = (|D(jω)|² − |N(jω)|²)/ω² is returned when g is
        below it (the projection passes its ε).

    Returns
    -------
    gmin : float
        The smallest g found by the scan (a heuristic: never a certificate).
    dips : list of float
        Local minimisers ω (rad/s) of g(·; K) with g < ``threshold``.
    """
    return _margin.local_minima(K, tau=p.tau, delta=p.delta, headway=p.headway, threshold=threshold)



def _g_and_grad(om: Array, K: Array, p: Params) -> tuple[Array, Array]:
    """g(ω; K) and ∇_K g (rows: frequencies): :func:`stringstab.tuning.margin_terms.gradient`."""
    return margin_terms.gradient(om, K, tau=p.tau, delta=p.delta, headway=p.headway)


def predict_dips(K0: Array, dips: list[float], p: Params, w: Array, eps: float,
                  rounds: int = 2) -> list[float]:
    """Predicted dips of the repaired gains: a frequency-selection heuristic, never a proof.

    For each violating dip ω of g(·; K0), the nearest point of the linearised
    constraint g(ω; K) ≥ ε is taken (a Gauss-Newton step from K0) and the dip
    of g at that point is followed by a local grid search on [0.7ω, 1.05ω]
    (the dip moves down in frequency as the gains are repaired, by up to
    ~20 % in the benchmark); twice.  The frequencies returned only seed the
    NLP's frequency set; the exact certificate decides.

    Parameters
    ----------
    K0 : ndarray, shape (3,)
        The gains to repair (k_x [1/s²], k_v [1/s], k_a [-]; IDL eq 4).
    dips : list of float
        Violating local minimisers ω of g(·; K0), in rad/s (:func:`violating_dips`).
    p : Params
        τ, δ, T* of the continuous loop (s).
    w : ndarray, shape (3,)
        Weights of the distance ‖K − K0‖_W the repair minimises.
    eps : float
        The margin the repair asks for: g(ω; K) ≥ ε.
    rounds : int, default 2
        Gauss-Newton step and dip-following rounds per dip.

    Returns
    -------
    list of float
        The predicted dip frequencies (rad/s, > 0), at most one per input dip; a dip whose
        prediction reaches ω = 0 is dropped.
    """
    out: list[float] = []
    v = np.linspace(0.7, 1.05, 36)
    z = np.linspace(-1.0, 1.0, 9)
    for om in dips:
        x = K0
        for _ in range(rounds):
            g, gr = _g_and_grad(np.array([om]), x, p)
            gr = gr[0]
            den = float(gr @ (gr / w))
            if not den > 0:
                break
            lam = (eps - float(g[0]) - float(gr @ (K0 - x))) / den
            x = K0 + lam * gr / w
            W = om * v
            j = int(np.argmin(_g_and_grad(W, x, p)[0]))
            Wl = np.maximum(W[j] + om * (v[1] - v[0]) * z, 0.0)
            om = float(Wl[int(np.argmin(_g_and_grad(Wl, x, p)[0]))])
        if om > 0:
            out.append(om)
    return out


def _g_full(om: float, K: Array, p: Params) -> tuple[float, Array, float, Array, float, Array]:
    """g(ω; K) with the derivatives the KKT Newton step needs, in scalar arithmetic.

    Returns (g, ∇_K g, g_ω, ∇_K g_ω, g_ωω, ∇²_KK g): :func:`stringstab.tuning.margin_terms.newton_terms`
    (the generated derivatives in ``math``-module arithmetic; the vectorised form costs
    ~0.5 ms of median repair latency).
    """
    return margin_terms.newton_terms(om, float(K[0]), float(K[1]), float(K[2]), p.tau, p.delta,
                                p.headway)


def _kkt_newton(K0: Array, cons: list[tuple[Any, ...]], p: Params, w: Array, eps: float,
                x: Array, lam: Array, max_iter: int = 25) -> tuple[Array, Array, list[float]] | None:
    """Newton's method on the KKT system of min ½‖K − K0‖²_W with the constraints ``cons`` active.

    Each constraint is ``("lin", a, m)`` (a·K = m: a bound or an internal-stability margin),
    ``("g0",)`` (g(0; K) = Ψ3 = ε) or ``("dip", ω)`` (g(ω; K) = ε at a dip ω of g(·; K):
    ∂g/∂ω = 0, ω a variable started at the given value; at the optimum of the semi-infinite
    problem the active dip is a minimiser in ω).  Unknowns: K, one multiplier per
    constraint and the dip frequencies.  Started from (x, lam); returns (K, λ, the
    constraints' frequencies) once the Newton step is below 1e-9 and the residual below
    1e-10, or None when it does not converge in ``max_iter`` steps (or a dip leaves ω > 0).
    """
    nc = len(cons)
    free = [i for i, c in enumerate(cons) if c[0] == "dip"]
    om = [float(c[1]) if c[0] == "dip" else 0.0 for c in cons]
    n = 3 + nc + len(free)
    lam = np.array(lam, dtype=float)
    J = np.zeros((n, n))
    r = np.zeros(n)
    converged = False
    for it in range(max_iter + 1):
        J[:] = 0.0
        J[:3, :3] = np.diag(w)
        r[:3] = w * (x - K0)
        for i, c in enumerate(cons):
            if c[0] == "lin":
                gk = c[1]
                val = float(gk @ x) - c[2]
            else:
                val, gk, gw, gwk, gww, gkk = _g_full(om[i], x, p)
                val -= eps
                J[:3, :3] -= lam[i] * gkk
            r[:3] -= lam[i] * gk
            J[:3, 3 + i] = -gk
            J[3 + i, :3] = gk
            r[3 + i] = val
            if c[0] == "dip":
                k = 3 + nc + free.index(i)
                J[:3, k] = -lam[i] * gwk
                J[3 + i, k] = gw
                J[k, :3] = gwk
                J[k, k] = gww
                r[k] = gw
        if converged:
            if float(np.max(np.abs(r))) <= 1e-10:
                return x, lam, om
            return None
        if it == max_iter:
            return None
        try:
            s = np.linalg.solve(J, -r)
        except np.linalg.LinAlgError:
            return None
        if not np.all(np.isfinite(s)):
            return None
        x = x + s[:3]
        lam = lam + s[3: 3 + nc]
        for j, i in enumerate(free):
            om[i] += float(s[3 + nc + j])
            if not om[i] > 0:
                return None
        converged = float(np.max(np.abs(s))) <= 1e-9
    return None  # pragma: no cover



def predict(k0: Array, pred: list[float], omegas: list[float], *, params: Params, weights: Array,
            eps: float, bounds: tuple[float, float], hurwitz_margin: float,
            check: Callable[[Array], tuple[str, bool, float]]) -> tuple[Array, list[str]] | None:
    """The NLP's solution by Newton's method on a small active set, without IPOPT, or None.

    The active set starts with the constraint most violated at K0 (relative
    to its gradient's length): an internal-stability margin, a bound, Ψ3 ≥ ε
    (ω = 0) or g ≥ ε at a predicted dip of the repaired gains (its
    frequency a variable: the dip of g at the solution).  After each
    :func:`_kkt_newton` solve the most violated remaining constraint (the
    margins, the bounds, and g ≥ ε at every frequency of the first NLP's set)
    is added, at most three in all.  The point is returned only when every
    multiplier is positive, nothing is violated (by more than 1e-10 in g)
    and the exact certificate certifies it, with the names of the active
    constraints; otherwise None (IPOPT decides).

    Parameters
    ----------
    k0 : ndarray, shape (3,)
        The gains to repair (k_x [1/s²], k_v [1/s], k_a [-]; IDL eq 4).
    pred : list of float
        Predicted dips of the repaired gains, rad/s (:func:`predict_dips`).
    omegas : list of float
        The first NLP's frequency set, rad/s; the frequencies > 0 are checked for violations.
    params : Params
        τ, δ, T* of the continuous loop (s).
    weights : ndarray, shape (3,)
        Weights of the distance ‖K − K0‖_W.
    eps : float
        The margin asked for: g(ω; K) ≥ ε, including Ψ3 = g(0) ≥ ε.
    bounds : (float, float)
        Lower and upper bound on every gain.
    hurwitz_margin : float
        m of the internal-stability constraints: each Hurwitz condition (linear in K,
        :func:`stringstab.certify.criteria.hurwitz_gradients`) ≥ m.
    check : callable
        ``check(K) -> (verdict, internally stable, witness frequency)``: the exact certificate
        of K (:func:`stringstab.certify.api.check`).

    Returns
    -------
    (ndarray, list of str) or None
        The certified gains and the names of the active constraints, or None when the
        predictor fails (IPOPT then solves the NLP).
    """
    p, w = params, weights
    lo, hi = bounds
    m = hurwitz_margin
    eye = np.eye(3)
    lins = [(row, m, f"{label} >= m") for row, label in
            zip(hurwitz_gradients(tau=p.tau, headway=p.headway), HURWITZ_LABELS)]
    lins += [(eye[i], lo, f"{GAIN_NAMES[i]} >= lo") for i in range(3)]
    lins += [(-eye[i], -hi, f"{GAIN_NAMES[i]} <= hi") for i in range(3)]
    om_arr = np.asarray([o for o in omegas if o > 0], dtype=float)

    def most_violated(x: Array, dips: Array) -> tuple[Any, ...] | None:
        worst = 0.0
        pick: tuple[Any, ...] | None = None
        for a, mm, name in lins:
            v = float(a @ x) - mm
            if v < -1e-12:
                d = -v / math.sqrt(float(a @ (a / w)))
                if d > worst:
                    worst, pick = d, ("lin", a, mm, name)
        om = np.concatenate([[0.0], dips])
        gv, gk = _g_and_grad(om, x, p)
        viol = eps - gv - 1e-10
        nrm = np.sqrt(np.sum(gk * gk / w, axis=1))
        for j in np.flatnonzero(viol > 0):
            d = float(viol[j]) / max(float(nrm[j]), 1e-300)
            if d > worst:
                worst, pick = d, (("g0",) if j == 0 else ("dip", float(om[j])))
        return pick

    first = most_violated(k0, np.asarray(pred, dtype=float))
    if first is None:
        return None
    cons: list[tuple[Any, ...]] = [first]
    x, lam = k0, np.zeros(1)
    for _ in range(6):
        sol = _kkt_newton(k0, cons, p, w, eps, x, lam)
        if sol is None:
            return None
        x, lam, oms = sol
        cons = [("dip", o) if c[0] == "dip" else c for c, o in zip(cons, oms)]
        if not np.all(lam > 0):
            if len(cons) == 1:
                return None
            j = int(np.argmin(lam))  # not active at the solution: drop the most negative
            del cons[j]
            lam = np.delete(lam, j)
            continue
        x = np.clip(x, lo, hi)  # a bound is met to rounding
        nxt = most_violated(x, om_arr)
        if nxt is None:
            verdict, hz, wit = check(x)
            if verdict == Verdict.CERTIFIED:
                return x, [c[3] if c[0] == "lin" else "psi3 >= eps" if c[0] == "g0" else
                           f"g >= eps at the dip omega = {c[1]!r}" for c in cons]
            if not hz:
                return None
            extra = [wit] if wit > 0 else []
        else:
            extra = []
        if nxt is None or nxt[0] == "dip":
            # a violated frequency enters at its dip: a local minimiser of g(·; K) below ε
            dips = np.asarray([*violating_dips(x, p, threshold=eps)[1], *extra], dtype=float)
            nxt = most_violated(x, dips)
            if nxt is None:
                return None
        if len(cons) == 3:
            return None
        cons.append(nxt)
        lam = np.append(lam, 0.0)
    return None
