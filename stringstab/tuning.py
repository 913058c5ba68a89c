"""Repairing gains that are not string stable: region growing and a nearest-point projection.

In the IDL strategy every action K = [k_x, k_v, k_a] proposed by the agent goes
through a *parameter tuning* step that replaces gains that are not string
stable by nearby gains that are (IDL paper §3.3).  Two methods are offered;
both report whether their output is certified by the exact certificate
(:func:`stringstab.certificate.certify`, or its verdict-only form
:func:`stringstab.certificate.check`: the same sound decision), never by a
Taylor formula alone.

:func:`region_growing`
    The paper's region-growing grid search (§3.3, Steps 1-6) as written: its
    candidate test is the Taylor Proposition 1 (types I-IV), so its output may
    fail the exact certificate.  Choices made where the paper is silent are
    listed in the function's docstring and in ``docs/tuning.md``.
:func:`project` (and the stateful :class:`Projector` for a control loop)
    The certified gains nearest to K0 in a weighted Euclidean distance, solved
    with CasADi/IPOPT under the internal-stability conditions with a margin
    and the exact frequency condition g(ω_j) ≥ ε on a finite set of
    frequencies, refined by exchange until the exact certificate certifies;
    first, a Newton predictor on the KKT system of a small active set
    (usually one constraint) answers without IPOPT when the exact
    certificate certifies its point.

Both return a :class:`TuneResult`.  Gains that the exact certificate already
certifies are returned unchanged, without any search or solve.

References
----------
IDL paper, §3.3 "Parameter tuning method" (types I-IV, eqs 25-26, Steps 1-6);
Table 2 (gain bounds [-2, 2]).
R. Hettich, K. O. Kortanek, "Semi-infinite programming: theory, methods, and
applications", SIAM Review 35 (1993) 380-429 (the exchange method).
"""

from __future__ import annotations

import math
import time
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cache, lru_cache
from typing import Any

import numpy as np
import numpy.typing as npt

from . import margin as _margin
from .certificate import Certificate, certify, certify_batch, check
from .criteria import (
    HURWITZ_LABELS,
    TYPE_NAMES,
    hurwitz,
    hurwitz_conditions,
    hurwitz_gradients,
    hurwitz_ok,
    taylor_criteria,
)
from .errors import StringStabError
from .params import Params, positive

__all__ = [
    "METHODS",
    "Projector",
    "TuneResult",
    "plot_moves",
    "project",
    "region_growing",
    "tune",
]

Array = npt.NDArray[np.float64]

#: The repair methods, as named on the command line.
METHODS: tuple[str, str] = ("region-growing", "projection")

_GAIN_NAMES = ("k_x", "k_v", "k_a")


# ---------------------------------------------------------------------------
# Result
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class TuneResult:
    """The outcome of repairing one gain triple.

    Attributes
    ----------
    method : str
        ``"region-growing"`` or ``"projection"``.
    k_in : tuple of float
        The input gains K0 = (k_x, k_v, k_a).
    k : tuple of float
        The output gains (K0 itself when unchanged or when no solution was found).
    certified : bool
        The output is certified string stable by the exact certificate.
    verdict : str
        The exact certificate's verdict on the output
        (``"certified"``, ``"not_certified"`` or ``"inconclusive"``).
    status : str
        ``"unchanged"`` (the input was already certified), ``"repaired"`` (a new
        output was found), ``"taylor_stable"`` (region growing only: the
        paper's Taylor test calls the input stable, so the paper's method does
        not act), ``"no_solution"`` (the paper's "No optimized solution found")
        or ``"failed"`` (projection only; never observed, see ``docs/tuning.md``).
    distance : float
        Weighted Euclidean distance ‖K − K0‖_W = sqrt(Σ w_i (K_i − K0_i)²).
    iterations : int
        Region growing: the index k of the last region R_k searched.
        Projection: the number of NLP solves (exchange iterations); an output of
        the Newton predictor counts as one solve (``details["predictor"]``).
    seconds : float
        Wall-clock time of the call.
    message : str
        A one-line human-readable account of what happened.
    sup_gain : float
        ‖Γ‖_{H∞} of the output (``inf`` when not internally stable).
    details : dict
        Method-specific numbers (grid points evaluated, frequencies used, ...).
    """

    method: str
    k_in: tuple[float, float, float]
    k: tuple[float, float, float]
    certified: bool
    verdict: str
    status: str
    distance: float
    iterations: int
    seconds: float
    message: str
    sup_gain: float = float("nan")
    details: dict[str, Any] = field(default_factory=dict)

    @property
    def changed(self) -> bool:
        """The output differs from the input."""
        return self.k != self.k_in

    def as_dict(self) -> dict[str, Any]:
        """A flat JSON-ready row (non-finite numbers are left to the writer)."""
        return {
            "method": self.method,
            "k_x_in": self.k_in[0],
            "k_v_in": self.k_in[1],
            "k_a_in": self.k_in[2],
            "k_x": self.k[0],
            "k_v": self.k[1],
            "k_a": self.k[2],
            "certified": self.certified,
            "verdict": self.verdict,
            "status": self.status,
            "distance": self.distance,
            "iterations": self.iterations,
            "time_ms": 1e3 * self.seconds,
            "sup_gain": self.sup_gain,
            "message": self.message,
        }


# ---------------------------------------------------------------------------
# Input checks and small helpers
# ---------------------------------------------------------------------------
def _as_k0(K0: Any) -> Array:
    """K0 as a float array of shape (3,), or a StringStabError."""
    try:
        k = np.asarray(K0, dtype=float)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"K0 must be three numbers (k_x, k_v, k_a); got {K0!r}") from e
    if k.shape != (3,):
        raise StringStabError(
            f"K0 must be three numbers (k_x, k_v, k_a); got an array of shape {k.shape}"
        )
    for name, v in zip(_GAIN_NAMES, k):
        if not math.isfinite(v):
            raise StringStabError(f"K0: {name} must be finite; got {v!r}")
    return k


def _as_bounds(bounds: Any) -> tuple[float, float]:
    try:
        lo, hi = (float(b) for b in bounds)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"bounds must be a pair (lower, upper); got {bounds!r}") from e
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise StringStabError(f"bounds must be finite with lower < upper; got {bounds!r}")
    return lo, hi


def _as_weights(weights: Any) -> Array:
    try:
        w = np.asarray(weights, dtype=float)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"weights must be three positive numbers; got {weights!r}") from e
    if w.shape != (3,) or not np.all(np.isfinite(w)) or not np.all(w > 0):
        raise StringStabError(f"weights must be three finite numbers > 0; got {weights!r}")
    return w


def _wdist(K: Array, K0: Array, w: Array) -> Array:
    """Weighted Euclidean distance(s) of the row(s) of K from K0."""
    d = np.asarray(K, dtype=float) - K0
    return np.asarray(np.sqrt(np.sum(w * d * d, axis=-1)))


def _triple(k: Array) -> tuple[float, float, float]:
    return float(k[0]), float(k[1]), float(k[2])


@dataclass(frozen=True)
class _Verdict:
    """What a :class:`TuneResult` reports of the exact certificate: verdict and sup |Γ|.

    Built from a full :class:`~stringstab.certificate.Certificate` or, in the
    projection's fast path, from :func:`stringstab.certificate.check` (the same
    sound decision without the reporting extras).  A certified triple has
    ‖Γ‖_{H∞} = 1 exactly (Γ(0) = 1 and |Γ(jω)| ≤ 1), which is what
    :func:`~stringstab.certificate.certify` reports for it too, so no peak
    search is needed; for any other verdict the full certificate is computed.
    """

    verdict: str
    sup_gain: float

    @property
    def certified(self) -> bool:
        return self.verdict == "certified"

    @classmethod
    def of(cls, cert: Certificate) -> _Verdict:
        return cls(cert.verdict, float(cert.sup_gain))


#: The verdict of a triple that :func:`stringstab.certificate.check` certified.
_CERTIFIED = _Verdict("certified", 1.0)


def _result(method: str, K0: Array, K: Array, cert: Certificate | _Verdict, status: str, w: Array,
            iterations: int, t0: float, message: str, **details: Any) -> TuneResult:
    v = cert if isinstance(cert, _Verdict) else _Verdict.of(cert)
    return TuneResult(
        method=method, k_in=_triple(K0), k=_triple(K), certified=v.certified,
        verdict=v.verdict, status=status, distance=float(_wdist(K, K0, w)),
        iterations=iterations, seconds=time.perf_counter() - t0, message=message,
        sup_gain=v.sup_gain, details=details,
    )


# ---------------------------------------------------------------------------
# Region growing (IDL §3.3, Steps 1-6)
# ---------------------------------------------------------------------------
def _rg_accept(K: Array, p: Params, criterion: str, check_hurwitz: bool) -> npt.NDArray[np.bool_]:
    """The paper's acceptance test on rows of K: Proposition 1 holds and the type is I or II.

    With ``check_hurwitz`` the internal-stability conditions k_x > 0 and
    k_v + (T* − τ) k_x > 0 are required as well (not part of the paper's test).
    """
    tc = taylor_criteria(K[:, 0], K[:, 1], K[:, 2], tau=p.tau, delta=p.delta, headway=p.headway,
                         source=criterion)
    ok = tc.stable & (tc.type <= 2)
    if check_hurwitz:
        ok &= hurwitz(K[:, 0], K[:, 1], K[:, 2], tau=p.tau, headway=p.headway)
    return np.asarray(ok)


def _shell(k: int, G: int, grow_ka: bool) -> npt.NDArray[np.int64]:
    """Integer offsets (i, j, l) of R_k minus R_{k-1} (R_0 empty); k_a offsets |l| ≤ G unless grow_ka."""
    n = k * G
    r = np.arange(-n, n + 1)
    la = r if grow_ka else np.arange(-G, G + 1)
    oi, oj, ol = np.meshgrid(r, r, la, indexing="ij")
    off = np.stack([oi.ravel(), oj.ravel(), ol.ravel()], axis=1)
    if k > 1:
        m = (k - 1) * G
        inner = (np.abs(off[:, 0]) <= m) & (np.abs(off[:, 1]) <= m)
        if grow_ka:
            inner &= np.abs(off[:, 2]) <= m
        off = off[~inner]
    return off


def region_growing(
    K0: Sequence[float] | Array,
    *,
    tau: float,
    delta: float,
    headway: float,
    r0: float = 0.1,
    grid: int = 2,
    bounds: tuple[float, float] = (-2.0, 2.0),
    max_iter: int | None = None,
    criterion: str = "derived",
    weights: Sequence[float] = (1.0, 1.0, 1.0),
    grow_ka: bool = False,
    check_hurwitz: bool = False,
) -> TuneResult:
    """Repair K0 with the IDL paper's region-growing search (§3.3, Steps 1-6).

    Step 1 sets the initial region R1 = K0 ± r0 in each gain.  Step 2 grid-searches
    it: for a type-III input the slice {k_x = k_x0, k_v ∈ [k_v0 − r0, k_v0],
    k_a ∈ [k_a0 − r0, k_a0]} is excluded (put in R_N; with k_x0 > 0 lowering k_v
    or k_a only lowers Ψ3, eq 26); for a type-IV input the whole R1 is searched.
    A grid point is accepted when the Taylor test calls it type I or II.
    Steps 3-5 grow the region: R_k has k_x ∈ k_x0 ± k r0, k_v ∈ k_v0 ± k r0 and,
    *as printed*, k_a ∈ k_a0 ± r0; R_{k−1} joins R_N, so only R_k \\ R_{k−1} is
    searched; points outside ``bounds`` are dropped.  Step 6 stops at the first
    region with an accepted point, or outputs K0 with the message "No optimized
    solution found" after ``max_iter`` regions or once R_k covers the bounds.

    Choices made where the paper is silent or ambiguous:

    * "k_y" in Steps 1-4 is k_v.
    * The grid inside each region is anchored at K0 with spacing r0/``grid`` in
      every gain (so regions nest and R_k ∩ grid ⊃ R_{k−1} ∩ grid).
    * When several points of a region are accepted, the nearest to K0 in the
      weighted distance is output (ties: the smallest (k_x, k_v, k_a)
      lexicographically); the paper says "the search stops" without an order.
    * The acceptance test is Proposition 1 for ``criterion`` *and* type I or II
      (Ψ2, Ψ3, Λ of that criterion); the paper assumes Ψ1 ≥ 0, which the
      ``"derived"`` Proposition 1 checks.  Internal stability is not part of
      the paper's test (its gains are assumed non-negative) and is not checked
      unless ``check_hurwitz=True`` (a deviation offered for comparison).
    * Step 4 keeps k_a ∈ k_a0 ± r0 for every k, as printed (``grow_ka=True``
      grows k_a too, a deviation offered for comparison).
    * An input the exact certificate certifies is returned unchanged (no
      search).  An input the Taylor test already calls type I or II is also
      returned unchanged: the paper's method only acts on types III and IV;
      such an output is reported with ``status="taylor_stable"`` and the exact
      verdict.
    * The default ``max_iter`` (None) is the number of regions needed for R_k
      to cover ``bounds`` in k_x and k_v from K0; the search also stops there.
    * The type of K0 (which decides the type-III exclusion) is that of
      ``criterion``.

    Parameters
    ----------
    K0 : sequence of 3 floats
        The gains to repair, (k_x, k_v, k_a).
    tau, delta, headway : float
        Actuator lag τ > 0, communication delay δ ≥ 0, desired headway T* ≥ 0 (s).
    r0 : float
        Initial half-width of the search region (the paper's "initial search
        step size"), > 0.  Default 0.1 (the paper gives no value).
    grid : int
        Grid intervals per r0 along each gain (grid spacing r0/grid), ≥ 1.
    bounds : (float, float)
        Bounds on every gain (IDL Table 2: [-2, 2]).
    max_iter : int or None
        Maximum number of regions R_1 ... R_max_iter; None: until R_k covers the bounds.
    criterion : {"derived", "printed"}
        Which Ψ formulas and Proposition-1 logic the Taylor test uses
        (:func:`stringstab.criteria.taylor_criteria`).
    weights : sequence of 3 floats
        Weights w of the distance sqrt(Σ w_i (K_i − K0_i)²) used to pick the
        nearest accepted point and reported in the result.
    grow_ka : bool
        Grow k_a with k as well (not the paper's Step 4).
    check_hurwitz : bool
        Also require internal stability (k_x > 0, k_v + (T* − τ)k_x > 0) of the
        input and of accepted points (not the paper's test).

    Returns
    -------
    TuneResult
        ``certified`` is the exact certificate's verdict on the output.

    Raises
    ------
    StringStabError
        On non-finite gains, parameters out of range or bad options.

    References
    ----------
    IDL paper, §3.3, Steps 1-6; eqs 12-15 (Proposition 1); eq 26 (∇_K Ψ3).

    Examples
    --------
    >>> r = region_growing([0.9, -0.5, 1.1], tau=0.1, delta=0.2, headway=1.1)
    >>> r.status, r.iterations, r.k, r.certified
    ('repaired', 1, (0.9, -0.5, 1.05), True)
    >>> region_growing([1.3, 0.0, 0.6], tau=0.1, delta=0.2, headway=1.1).status
    'unchanged'
    """
    t0 = time.perf_counter()
    p = Params(tau, delta, headway)
    k0 = _as_k0(K0)
    r0 = positive("r0", r0)
    if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or grid < 1:
        raise StringStabError(f"grid must be an integer >= 1 (grid intervals per r0); got {grid!r}")
    G = int(grid)
    lo, hi = _as_bounds(bounds)
    w = _as_weights(weights)
    if criterion not in ("derived", "printed"):
        raise StringStabError(f"criterion must be 'derived' or 'printed'; got {criterion!r}")
    grow = (0, 1, 2) if grow_ka else (0, 1)
    need = max(max(k0[i] - lo, hi - k0[i]) for i in grow)
    k_cover = max(1, math.ceil(need / r0 - 1e-9))
    if max_iter is None:
        max_iter = k_cover
    elif isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise StringStabError(f"max_iter must be an integer >= 1 or None; got {max_iter!r}")
    method = "region-growing"

    cert0 = certify(*k0, tau=p.tau, delta=p.delta, headway=p.headway)
    if cert0.certified:
        return _result(method, k0, k0, cert0, "unchanged", w, 0, t0,
                       "already certified by the exact certificate; returned unchanged",
                       type_in=cert0.type, evaluated=0)
    tc0 = taylor_criteria(*k0, tau=p.tau, delta=p.delta, headway=p.headway, source=criterion)
    type0 = int(tc0.type)
    if _rg_accept(k0[None, :], p, criterion, check_hurwitz)[0]:
        return _result(
            method, k0, k0, cert0, "taylor_stable", w, 0, t0,
            f"the {criterion} Taylor test calls K0 type {TYPE_NAMES[type0]} (stable), so the "
            f"paper's method leaves it unchanged; exact certificate: {cert0.verdict}",
            type_in=TYPE_NAMES[type0], evaluated=0,
        )

    h = r0 / G
    evaluated = 0
    k = 0
    for k in range(1, int(max_iter) + 1):
        off = _shell(k, G, grow_ka)
        if k == 1 and type0 == 3:  # Step 2: the type-III exclusion (into R_N)
            excl = (off[:, 0] == 0) & (off[:, 1] <= 0) & (off[:, 2] <= 0)
            off = off[~excl]
        pts = k0 + h * off
        inside = np.all((pts >= lo - 1e-12) & (pts <= hi + 1e-12), axis=1)
        pts, off = pts[inside], off[inside]
        evaluated += len(pts)
        if len(pts):
            ok = _rg_accept(pts, p, criterion, check_hurwitz)
            if ok.any():
                cand, coff = pts[ok], off[ok]
                d = np.round(_wdist(cand, k0, w), 12)
                order = np.lexsort((coff[:, 2], coff[:, 1], coff[:, 0], d))
                best = cand[order[0]]
                cert = certify(*best, tau=p.tau, delta=p.delta, headway=p.headway)
                tc = taylor_criteria(*best, tau=p.tau, delta=p.delta, headway=p.headway,
                                     source=criterion)
                return _result(
                    method, k0, best, cert, "repaired", w, k, t0,
                    f"type {TYPE_NAMES[type0]} input; {criterion} Taylor test passed "
                    f"(type {TYPE_NAMES[int(tc.type)]}) in region R_{k}; exact certificate: "
                    f"{cert.verdict}",
                    type_in=TYPE_NAMES[type0], type_out=TYPE_NAMES[int(tc.type)],
                    evaluated=evaluated, accepted_in_region=int(ok.sum()),
                )
        if k >= k_cover:
            break
    reason = f"R_{k} covers the bounds" if k >= k_cover else f"max_iter = {max_iter} regions searched"
    return _result(
        method, k0, k0, cert0, "no_solution", w, k, t0,
        f"No optimized solution found ({reason}); returned the input (type "
        f"{TYPE_NAMES[type0]}); exact certificate: {cert0.verdict}",
        type_in=TYPE_NAMES[type0], evaluated=evaluated,
    )


# ---------------------------------------------------------------------------
# Projection: the nearest certified gains (CasADi / IPOPT, exchange method)
# ---------------------------------------------------------------------------
#: Frequency-slot capacities of the NLPs, each built on first use (the smallest that fits is
#: used: an unused slot costs IPOPT about as much per iteration as a used one).
_SLOTS = (4, 6, 8, 10, 12, 14, 16, 20, 24, 28, 32, 40, 48)
#: Fixed frequencies (rad/s) in every first solve, besides ω = 0 and the dips of g(·; K0).
_LADDER: tuple[float, ...] = tuple(float(v) for v in np.geomspace(0.2, 5.0, 16))
#: Relative offset of the two neighbours added with every exchanged frequency.
_CLUSTER = 0.05
#: Multipliers of the violating frequencies of K0 in the first solve.
_K0_CLUSTER = (1.0, 0.95, 0.9)
#: Multipliers of the predicted dips of the solution (:func:`_predict_dips`) in the first solve.
_PRED_CLUSTER = (1.0, 0.98, 1.02)


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
def _nlp(n_slots: int) -> Any:
    """The projection NLP with ``n_slots`` frequency slots, built once per process.

    Decision K = (k_x, k_v, k_a); parameters p = (K0, w, τ, δ, T*, ω_1..ω_n).
    Constraints: k_x, k_v + (T* − τ) k_x (Hurwitz, lower bound = margin) and
    g(ω_j; K) for every slot (lower bound ε when active, −inf when inactive).
    """
    ca = _import_casadi()
    x = ca.SX.sym("K", 3)
    par = ca.SX.sym("p", 9 + n_slots)
    K0, w = par[0:3], par[3:6]
    tau, delta, T = par[6], par[7], par[8]
    kx, kv, ka = x[0], x[1], x[2]
    gs = _margin.casadi_g([par[9 + j] for j in range(n_slots)], kx, kv, ka, tau, delta, T)
    f = ca.sum1(w * (x - K0) ** 2)
    g = ca.vertcat(*hurwitz_conditions(kx, kv, ka, tau=tau, headway=T), *gs)
    opts = {
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
    return ca.nlpsol(f"stringstab_projection_{n_slots}", "ipopt",
                     {"x": x, "p": par, "f": f, "g": g}, opts)


def _g_dips(K: Array, p: Params, threshold: float) -> tuple[float, list[float]]:
    """The violating dips of g(·; K) (:func:`stringstab.margin.local_minima`)."""
    return _margin.local_minima(K, tau=p.tau, delta=p.delta, headway=p.headway, threshold=threshold)


def _g_and_grad(om: Array, K: Array, p: Params) -> tuple[Array, Array]:
    """g(ω; K) and ∇_K g (rows: frequencies): :func:`stringstab.margin.gradient`."""
    return _margin.gradient(om, K, tau=p.tau, delta=p.delta, headway=p.headway)


def _predict_dips(K0: Array, dips: list[float], p: Params, w: Array, eps: float,
                  rounds: int = 2) -> list[float]:
    """Predicted dips of the repaired gains: a frequency-selection heuristic, never a proof.

    For each violating dip ω of g(·; K0), the nearest point of the linearised
    constraint g(ω; K) ≥ ε is taken (a Gauss-Newton step from K0) and the dip
    of g at that point is followed by a local grid search on [0.7ω, 1.05ω]
    (the dip moves down in frequency as the gains are repaired, by up to
    ~20 % in the benchmark); twice.  The frequencies returned only seed the
    NLP's frequency set; the exact certificate decides.
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

    Returns (g, ∇_K g, g_ω, ∇_K g_ω, g_ωω, ∇²_KK g): :func:`stringstab.margin.newton_terms`
    (the generated derivatives in ``math``-module arithmetic; the vectorised form costs
    ~0.5 ms of median repair latency).
    """
    return _margin.newton_terms(om, float(K[0]), float(K[1]), float(K[2]), p.tau, p.delta,
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


def _surely_uncertifiable(K: Array, p: Params) -> tuple[bool, list[float]]:
    """(True, frequencies) when K provably cannot be certified: not Hurwitz or g(ω) < 0 found.

    A violation g(ω) < −1e-9·scale at any ω means |Γ(jω)| > 1 there, so the
    (sound) certificate can never certify K; no certificate call is needed.
    """
    _, a, b, cx, cv = (float(c) for c in _margin.coefficients(
        K[0], K[1], K[2], tau=p.tau, delta=p.delta, headway=p.headway))
    scale = 1.0 + abs(a) + abs(b) + abs(cx) + abs(cv)
    _, dips = _g_dips(K, p, threshold=-1e-9 * scale)
    stable = hurwitz_ok(float(K[0]), float(K[1]), float(K[2]), tau=p.tau, headway=p.headway)
    return (not stable) or bool(dips), dips


@lru_cache(maxsize=16)
def _certified_map(tau: float, delta: float, headway: float, lo: float, hi: float,
                   margin: float, n: int = 21) -> Array:
    """Certified points of an n³ grid over the bounds (starting points and fallbacks)."""
    g = np.linspace(lo, hi, n)
    KX, KV, KA = np.meshgrid(g, g, g, indexing="ij")
    kx, kv, ka = KX.ravel(), KV.ravel(), KA.ravel()
    keep = np.all([c >= margin for c in hurwitz_conditions(kx, kv, ka, tau=tau, headway=headway)],
                  axis=0)
    b = certify_batch(kx[keep], kv[keep], ka[keep], tau=tau, delta=delta, headway=headway)
    pts = np.column_stack([kx[keep], kv[keep], ka[keep]])[b.certified]
    pts.setflags(write=False)
    return pts


class Projector:
    """Nearest certified gains, with a fast path for a control loop.

    A :class:`Projector` fixes the model parameters and options once, reuses the
    prebuilt CasADi/IPOPT problems of the process, and keeps two pieces of
    state between calls (the *fast path*; :func:`project` has neither):

    * a least-recently-used cache keyed on K0 rounded to ``cache_decimals``
      decimals (saturated policy outputs, e.g. at the bounds, repeat exactly);
    * optionally (``warm_from_previous``) the previous repaired gains: when
      they are nearer to the new K0 than the nearest point of the certified
      map, the solve starts from them (their frequency set is not carried
      over: along a trajectory that set grows and slows every later solve).

    Every output reported certified has been certified by the exact
    certificate, :func:`stringstab.certificate.check` (the verdicts of
    :func:`~stringstab.certificate.certify` without its reporting extras; a
    cache hit returns gains that were).

    Parameters
    ----------
    tau, delta, headway : float
        Model parameters (s).
    weights : sequence of 3 floats
        Weights w of the distance sqrt(Σ w_i (K_i − K0_i)²), > 0.
    bounds : (float, float)
        Bounds on every gain.
    hurwitz_margin : float
        Margin m ≥ 0 in the internal-stability constraints k_x ≥ m and
        k_v + (T* − τ) k_x ≥ m.
    eps : float
        Margin ε > 0 of the frequency constraints g(ω_j) ≥ ε (that is
        |D(jω_j)|² − |N(jω_j)|² ≥ ε ω_j²).
    max_exchange : int
        Maximum number of NLP solves (exchange iterations) per call.
    cache_size : int
        Entries of the LRU cache (0 disables it).
    cache_decimals : int
        Decimals of the cache key.
    predictor : bool
        Try the Newton predictor before IPOPT (see :func:`project`).
    warm_from_previous : bool
        Start IPOPT from the previous output when it is nearer to K0 than the
        nearest map point.  Off by default: on a 2,000-step random walk it made
        the median call slower than a cold one (6.1 vs 4.7 ms; with it off,
        4.6 vs 4.6 ms), because IPOPT's interior-point start gains little from
        a nearby point while the predictor already handles the easy steps.
    """

    def __init__(
        self,
        *,
        tau: float,
        delta: float,
        headway: float,
        weights: Sequence[float] = (1.0, 1.0, 1.0),
        bounds: tuple[float, float] = (-2.0, 2.0),
        hurwitz_margin: float = 1e-3,
        eps: float = 1e-4,
        max_exchange: int = 25,
        cache_size: int = 4096,
        cache_decimals: int = 6,
        predictor: bool = True,
        warm_from_previous: bool = False,
    ) -> None:
        self.params = Params(tau, delta, headway)
        self.weights = _as_weights(weights)
        self.bounds = _as_bounds(bounds)
        self.hurwitz_margin = positive("hurwitz_margin", hurwitz_margin, allow_zero=True)
        self.eps = positive("eps", eps)
        if isinstance(max_exchange, bool) or not isinstance(max_exchange, (int, np.integer)) \
                or max_exchange < 1:
            raise StringStabError(f"max_exchange must be an integer >= 1; got {max_exchange!r}")
        self.max_exchange = int(max_exchange)
        self.cache_size = int(cache_size)
        self.cache_decimals = int(cache_decimals)
        self._cache: OrderedDict[tuple[float, ...], tuple[Array, _Verdict]] = OrderedDict()
        self._last: Array | None = None
        self.predictor = bool(predictor)
        self.warm_from_previous = bool(warm_from_previous)
        self.stats = {"calls": 0, "cache_hits": 0, "warm_starts": 0, "fallbacks": 0,
                      "predicted": 0}

    # -- the certified map (starting points, fallbacks) -------------------------------
    def _map(self) -> Array:
        p = self.params
        return _certified_map(p.tau, p.delta, p.headway, *self.bounds, self.hurwitz_margin)

    def reset(self) -> None:
        """Forget the cache and the previous solution."""
        self._cache.clear()
        self._last = None

    # -- one NLP solve ------------------------------------------------------------------
    def _solve(self, K0: Array, x0: Array, omegas: list[float]) -> tuple[Array, str, int]:
        n = next(s for s in _SLOTS if s >= len(omegas))
        solver = _nlp(n)
        p = self.params
        om = np.zeros(n)
        om[: len(omegas)] = omegas
        lbg = np.full(n + 2, -np.inf)
        lbg[:2] = self.hurwitz_margin
        lbg[2: 2 + len(omegas)] = self.eps
        lo, hi = self.bounds
        par = np.concatenate([K0, self.weights, [p.tau, p.delta, p.headway], om])
        sol = solver(x0=np.clip(x0, lo, hi), p=par, lbx=lo, ubx=hi, lbg=lbg, ubg=np.inf)
        st = solver.stats()
        return np.asarray(sol["x"], dtype=float).ravel(), str(st["return_status"]), int(st["iter_count"])

    def _check(self, K: Array) -> tuple[str, bool, float]:
        """The exact certificate's verdict on K (:func:`stringstab.certificate.check`).

        Returns (verdict, internally stable, witness frequency: where the
        smallest g(ω) was found; |Γ(jω)| > 1 there when K is internally stable
        and not certified).
        """
        p = self.params
        c = check(K[0], K[1], K[2], tau=p.tau, delta=p.delta, headway=p.headway)
        return str(c.verdict[0]), bool(c.hurwitz[0]), float(c.witness_omega[0])

    def __call__(self, K0: Sequence[float] | Array, *, warm_start: Sequence[float] | None = None,
                 use_state: bool = True) -> TuneResult:
        """Repair one triple K0 (see :func:`project` for the algorithm)."""
        t0 = time.perf_counter()
        k0 = _as_k0(K0)
        p, w = self.params, self.weights
        self.stats["calls"] += 1
        method = "projection"

        key = tuple(np.round(k0, self.cache_decimals).tolist())
        if use_state and self.cache_size and key in self._cache:
            self._cache.move_to_end(key)
            kc, vc = self._cache[key]
            self.stats["cache_hits"] += 1
            status = "unchanged" if np.array_equal(kc, k0) else "repaired"
            return _result(method, k0, kc if status == "repaired" else k0, vc, status, w, 0, t0,
                           "cache hit: gains certified on an earlier call", cache_hit=True)

        # Is K0 already certified?  Skip the certificate when a violation is found cheaply.
        bad, dips = _surely_uncertifiable(k0, p)
        if not bad:
            verdict0, hz0, wit0 = self._check(k0)
            if verdict0 == "certified":
                self._remember(key, k0, use_state)
                return _result(method, k0, k0, _CERTIFIED, "unchanged", w, 0, t0,
                               "already certified by the exact certificate; returned unchanged")
            if hz0 and wit0 > 0:
                dips = [*dips, wit0]
        # the dips of the solution lie a little below those of K0, as a rule; where they
        # go is predicted from the linearised constraint at each dip
        pred = _predict_dips(k0, dips, p, w, self.eps)
        dips = [o * f for o in dips for f in _K0_CLUSTER]
        dips += [o * f for o in pred for f in _PRED_CLUSTER]

        # Starting point: the nearest certified map point, the previous solution or warm_start.
        M = self._map()
        dm = _wdist(M, k0, w)
        im = int(np.argmin(dm)) if len(M) else -1
        omegas = [0.0, *_LADDER, *dips]
        if warm_start is not None:
            x0 = _as_k0(warm_start)
            start = "warm_start"
        elif self.warm_from_previous and use_state and self._last is not None and (
                im < 0 or float(_wdist(self._last, k0, w)) < float(dm[im])):
            x0 = self._last
            start = "previous"
            self.stats["warm_starts"] += 1
        elif im >= 0:
            x0 = M[im]
            start = "map"
        else:  # pragma: no cover - no certified point in the bounds at all
            x0 = k0
            start = "input"
        omegas = _dedupe(omegas)

        best: Array | None = None
        n_solves = ipopt_iters = 0
        statuses: list[str] = []
        x = x0
        predicted = False
        active: list[str] = []
        if self.predictor:
            kp = self._predict(k0, pred, omegas)
            if kp is not None:
                (best, active), predicted = kp, True
                x = best
                n_solves = 1
                self.stats["predicted"] += 1
        for _ in range(0 if predicted else self.max_exchange):
            omegas = self._fit_slots(omegas, x)
            x, status, its = self._solve(k0, x, omegas)
            n_solves += 1
            ipopt_iters += its
            statuses.append(status)
            if not np.all(np.isfinite(x)):
                break
            # the exact certificate's verdict; when it does not certify, its witness
            # frequency (|Γ| > 1 there) and the violating dips of a cheap scan are added
            verdict, hz, wit = self._check(x)
            if verdict == "certified":
                best = x
                break
            new = [wit] if hz and wit > 0 else []
            new += _g_dips(x, p, threshold=0.0)[1]
            # each new frequency comes with two neighbours ±_CLUSTER: the dip moves as K moves
            new = [o * f for o in new for f in (1.0, 1.0 - _CLUSTER, 1.0 + _CLUSTER)]
            grown = _dedupe([*omegas, *new])
            if len(grown) == len(omegas):  # nothing new to add: stop
                break
            omegas = grown

        fallback = False
        if im >= 0 and (best is None or float(_wdist(best, k0, w)) > float(dm[im])):
            # the nearest certified map point is nearer (or the exchange failed): use it
            if self._check(M[im])[0] == "certified":
                best = M[im].copy()
                fallback = True
                self.stats["fallbacks"] += 1
        if best is None:
            xf = x if np.all(np.isfinite(x)) else k0
            cx = certify(*xf, tau=p.tau, delta=p.delta, headway=p.headway)  # full report
            return _result(method, k0, xf, cx, "failed", w, n_solves, t0,
                           f"no certified point found after {n_solves} solve(s) "
                           f"(IPOPT: {statuses[-1] if statuses else 'not run'})",
                           start=start, frequencies=omegas, ipopt_iterations=ipopt_iters,
                           ipopt_status=statuses)
        self._remember(key, best, use_state)
        if use_state:
            # only the gains: carrying the frequency set along a trajectory made it grow
            # towards the largest NLP (48 constraints) and every later solve slower; this
            # call's own dips (predicted from K0) are the relevant ones
            self._last = best
        msg = (f"nearest certified point of the {len(M)}-point certified map (the NLP solution "
               "was not nearer)" if fallback else
               "nearest certified point: Newton's method on the KKT system with active "
               f"{'; '.join(active)} (no IPOPT solve)" if predicted else
               f"nearest certified point: {n_solves} solve(s), {len(omegas)} frequencies")
        return _result(method, k0, best, _CERTIFIED, "repaired", w, n_solves, t0, msg,
                       start=start, fallback=fallback, predictor=predicted and not fallback,
                       active=active, frequencies=omegas,
                       ipopt_iterations=ipopt_iters, ipopt_status=statuses)

    def _predict(self, k0: Array, pred: list[float],
                 omegas: list[float]) -> tuple[Array, list[str]] | None:
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
        """
        p, w, eps = self.params, self.weights, self.eps
        lo, hi = self.bounds
        m = self.hurwitz_margin
        eye = np.eye(3)
        lins = [(row, m, f"{label} >= m") for row, label in
                zip(hurwitz_gradients(tau=p.tau, headway=p.headway), HURWITZ_LABELS)]
        lins += [(eye[i], lo, f"{_GAIN_NAMES[i]} >= lo") for i in range(3)]
        lins += [(-eye[i], -hi, f"{_GAIN_NAMES[i]} <= hi") for i in range(3)]
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
                verdict, hz, wit = self._check(x)
                if verdict == "certified":
                    return x, [c[3] if c[0] == "lin" else "psi3 >= eps" if c[0] == "g0" else
                               f"g >= eps at the dip omega = {c[1]!r}" for c in cons]
                if not hz:
                    return None
                extra = [wit] if wit > 0 else []
            else:
                extra = []
            if nxt is None or nxt[0] == "dip":
                # a violated frequency enters at its dip: a local minimiser of g(·; K) below ε
                dips = np.asarray([*_g_dips(x, p, threshold=eps)[1], *extra], dtype=float)
                nxt = most_violated(x, dips)
                if nxt is None:
                    return None
            if len(cons) == 3:
                return None
            cons.append(nxt)
            lam = np.append(lam, 0.0)
        return None

    def _remember(self, key: tuple[float, ...], k: Array, use_state: bool) -> None:
        """Cache gains that the exact certificate certified."""
        if not (use_state and self.cache_size):
            return
        self._cache[key] = (k, _CERTIFIED)
        if len(self._cache) > self.cache_size:
            self._cache.popitem(last=False)

    def _fit_slots(self, omegas: list[float], x: Array) -> list[float]:
        """Keep at most the largest slot capacity: drop the slackest frequencies (never ω = 0)."""
        cap = _SLOTS[-1]
        if len(omegas) <= cap:
            return omegas
        p = self.params
        om = np.asarray(omegas[1:])
        gv = _margin.g(om, x[0], x[1], x[2], tau=p.tau, delta=p.delta, headway=p.headway)
        keep = np.sort(np.argsort(gv)[: cap - 1])
        return [omegas[0], *om[keep].tolist()]


def _dedupe(omegas: list[float], rtol: float = 1e-6) -> list[float]:
    """ω = 0 first, then the others in order, dropping near-duplicates."""
    out = [0.0]
    for o in omegas:
        if not math.isfinite(o) or o <= 0:
            continue
        if all(abs(o - q) > rtol * max(1.0, o) for q in out):
            out.append(float(o))
    return out


@lru_cache(maxsize=64)
def _default_projector(tau: float, delta: float, headway: float, weights: tuple[float, ...],
                       bounds: tuple[float, float], hurwitz_margin: float, eps: float,
                       max_exchange: int, predictor: bool = True) -> Projector:
    return Projector(tau=tau, delta=delta, headway=headway, weights=weights, bounds=bounds,
                     hurwitz_margin=hurwitz_margin, eps=eps, max_exchange=max_exchange,
                     cache_size=0, predictor=predictor)


def project(
    K0: Sequence[float] | Array,
    *,
    tau: float,
    delta: float,
    headway: float,
    weights: Sequence[float] = (1.0, 1.0, 1.0),
    bounds: tuple[float, float] = (-2.0, 2.0),
    hurwitz_margin: float = 1e-3,
    eps: float = 1e-4,
    warm_start: Sequence[float] | None = None,
    max_exchange: int = 25,
    predictor: bool = True,
) -> TuneResult:
    """The certified gains nearest to K0: min ‖K − K0‖_W subject to string stability.

    Solves, with CasADi and IPOPT,

    .. math::
        \\min_K \\sum_i w_i (K_i - K_{0,i})^2 \\quad\\text{s.t.}\\quad
        k_x \\ge m,\\; k_v + (T^* - τ)k_x \\ge m,\\;
        g(ω_j; K) \\ge ε \\;(j = 1..n),\\; K \\in [\\text{lo}, \\text{hi}]^3,

    where g(ω) = (|D(jω)|² − |N(jω)|²)/ω² (:func:`stringstab.frequency.margin_g`;
    g(0) = Ψ3), so g(ω_j) ≥ ε is |D(jω_j)|² − |N(jω_j)|² ≥ ε ω_j².  The frequency
    set starts as {0}, a fixed ladder of 16 frequencies (0.2 to 5 rad/s,
    geometric), the violating local minima of g(·; K0) (each also at 0.95
    and 0.9 times itself) and, for each of them, the predicted dip of the
    repaired gains (the dip of g at the nearest point of the linearised
    constraint, followed twice; each also at 0.98 and 1.02 times itself).  It
    is refined by *exchange*: after each solve the exact certificate
    (:func:`stringstab.certificate.check`) is asked; if it does not certify
    K, its witness frequency (where |Γ(jω)| > 1) and the local minima of
    g(·; K) below 0 found by a dense scan are added, each with neighbours at
    ±5 %.  The loop ends when the certificate certifies K, when nothing new
    can be added, or after ``max_exchange`` solves.

    The first solve starts from the nearest point (weighted distance) of a
    precomputed map of certified gains (a 21³ grid over the bounds, certified
    once per process and parameter set), or from ``warm_start``.  Since the
    problem is not convex, IPOPT finds a local solution; if that map point is
    nearer than the local solution (or the exchange fails), the map point,
    which is certified, is returned instead, so the result is never further
    than the nearest certified grid point.

    The NLP is built once per process for each frequency-slot capacity
    (4, 6, ..., 16, 20, ..., 32, 40, 48; each on first use), with K0, the
    weights, τ, δ, T* and the frequencies as parameters; the smallest that
    fits is used and unused slots are disabled by a lower bound of −∞.

    Before any IPOPT solve, a *predictor* (``predictor=True``) solves the
    problem by Newton's method on its KKT system with a small active set:
    it starts with the constraint most violated at K0 relative to its
    gradient (a margin, a bound, Ψ3 = g(0) ≥ ε, or g ≥ ε at a predicted dip,
    the dip's frequency being a variable with ∂g/∂ω = 0, so that g ≥ ε holds
    at the dip itself), adds after each solve the constraint then most
    violated (at most three), and drops one whose multiplier turns negative.
    Its point is returned when every multiplier is positive, every
    constraint of the first NLP holds (the margins, the bounds, g ≥ ε on its
    frequency set) and the exact certificate certifies it; otherwise the
    IPOPT path above runs unchanged (and the map fallback applies to both).

    Parameters
    ----------
    K0 : sequence of 3 floats
        The gains to repair.
    tau, delta, headway : float
        Model parameters (s).
    weights : sequence of 3 floats
        Weights of the squared distance, > 0.
    bounds : (float, float)
        Bounds on every gain (IDL Table 2: [-2, 2]).
    hurwitz_margin : float
        m in k_x ≥ m and k_v + (T* − τ)k_x ≥ m (internal stability with a margin).
    eps : float
        ε > 0 of the frequency constraints.
    warm_start : sequence of 3 floats, optional
        Starting point of the first solve instead of the certified map.
    max_exchange : int
        Maximum number of solves.
    predictor : bool
        Try the Newton predictor before IPOPT (default); False: IPOPT only.

    Returns
    -------
    TuneResult
        ``certified`` is the exact certificate's verdict on the output.

    Raises
    ------
    StringStabError
        On non-finite gains, parameters out of range or bad options.

    See Also
    --------
    Projector : the same with a cache and warm starts for a control loop.

    Examples
    --------
    >>> r = project([0.9, -0.5, 1.1], tau=0.1, delta=0.2, headway=1.1)
    >>> r.status, r.certified, round(r.distance, 3)
    ('repaired', True, 0.033)
    >>> project([1.3, 0.0, 0.6], tau=0.1, delta=0.2, headway=1.1).status
    'unchanged'
    """
    p = Params(tau, delta, headway)
    proj = _default_projector(
        p.tau, p.delta, p.headway, tuple(float(v) for v in _as_weights(weights)),
        _as_bounds(bounds), positive("hurwitz_margin", hurwitz_margin, allow_zero=True),
        positive("eps", eps), max_exchange, bool(predictor),
    )
    return proj(K0, warm_start=warm_start, use_state=False)


def tune(
    K0: Sequence[float] | Array,
    method: str = "projection",
    *,
    tau: float,
    delta: float,
    headway: float,
    **options: Any,
) -> TuneResult:
    """Repair K0 with ``method`` (``"region-growing"`` or ``"projection"``).

    Examples
    --------
    >>> tune([0.9, -0.5, 1.1], "projection", tau=0.1, delta=0.2, headway=1.1).certified
    True
    """
    if method == "region-growing":
        return region_growing(K0, tau=tau, delta=delta, headway=headway, **options)
    if method == "projection":
        return project(K0, tau=tau, delta=delta, headway=headway, **options)
    raise StringStabError(f"method must be one of {', '.join(METHODS)}; got {method!r}")


# ---------------------------------------------------------------------------
# Plot
# ---------------------------------------------------------------------------
def plot_moves(
    results: Sequence[TuneResult],
    *,
    tau: float,
    delta: float,
    headway: float,
    k_a: float | None = None,
    bounds: tuple[float, float] = (-2.0, 2.0),
    n: int = 121,
    ax: Any = None,
) -> dict[str, Any]:
    """Draw repairs as arrows K0 → K on a k_x–k_v slice of the certified region.

    The background shades the gains certified by the exact certificate on the
    slice k_a = ``k_a`` (default: the median input k_a); the arrows are the
    moves projected onto (k_x, k_v), coloured by method; the output k_a is
    written next to each arrow head.

    Returns
    -------
    dict
        ``{"ax": ax, "region": QuadMesh, "arrows": [...]}``.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(6, 5))
    lo, hi = _as_bounds(bounds)
    if k_a is None:
        k_a = float(np.median([r.k_in[2] for r in results])) if results else 0.0
    g = np.linspace(lo, hi, n)
    KX, KV = np.meshgrid(g, g, indexing="ij")
    b = certify_batch(KX.ravel(), KV.ravel(), k_a, tau=tau, delta=delta, headway=headway)
    region = ax.pcolormesh(KX, KV, b.certified.reshape(KX.shape).astype(float), cmap="Greens",
                           vmin=0.0, vmax=1.6, shading="auto")
    colours = {"region-growing": "tab:orange", "projection": "tab:blue"}
    arrows = []
    labelled: set[str] = set()
    for r in results:
        c = colours.get(r.method, "k")
        x0, y0, x1, y1 = r.k_in[0], r.k_in[1], r.k[0], r.k[1]
        ax.plot([x0], [y0], "o", color="k", ms=3)
        label = None if r.method in labelled else r.method
        labelled.add(r.method)
        arrows.append(ax.annotate("", xy=(x1, y1), xytext=(x0, y0),
                                  arrowprops={"arrowstyle": "->", "color": c, "lw": 1.4}))
        ax.plot([x1], [y1], "s" if r.certified else "x", color=c, ms=4, label=label)
        ax.text(x1, y1, f" {r.k[2]:.2f}", fontsize=7, color=c)
    ax.set_xlabel("k_x")
    ax.set_ylabel("k_v")
    ax.set_title(f"repairs K0 → K over the certified region (shaded) at k_a = {k_a:g}\n"
                 "arrows projected on (k_x, k_v); label: output k_a; ■ certified, × not",
                 fontsize=9)
    ax.legend(loc="lower right", fontsize=8)
    return {"ax": ax, "region": region, "arrows": arrows}
