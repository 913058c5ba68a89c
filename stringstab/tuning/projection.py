"""The nearest certified gains: a CasADi/IPOPT projection refined by exchange, and the Projector.

:func:`project` (and the stateful :class:`Projector`, for a control loop) solves
min ‖K − K0‖_W subject to the internal-stability conditions with a margin and the exact
frequency condition g(ω_j; K) ≥ ε on a finite set of frequencies, refined by exchange until
the exact certificate (:func:`stringstab.certify.api.check`) certifies; first, the Newton
predictor of :mod:`stringstab.tuning.predictor` answers without IPOPT when it can.  The NLP's
constraints are the generated Hurwitz conditions (:func:`stringstab.certify.criteria.hurwitz_conditions`)
and g (:func:`stringstab.certify.margin.casadi_g`).

For the sampled-data loop (``sample_time``) and for a box of parameters (intervals: every
member certified) the same exchange runs on the NLP of :func:`_quad_nlp`, whose constraints
are quadratic forms in K taken at members and frequencies of that loop
(:mod:`stringstab.tuning.constraints`: the sampled margin g_H(θ), the Schur conditions, g(ω)
at a member of the box), the certificate of that loop deciding every output and supplying
each new constraint (its witness member and frequency).

References
----------
R. Hettich, K. O. Kortanek, "Semi-infinite programming: theory, methods, and
applications", SIAM Review 35 (1993) 380-429 (the exchange method).
"""

from __future__ import annotations

import math
import time
from collections import OrderedDict
from collections.abc import Callable, Sequence
from functools import cache, lru_cache
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify import margin as _margin
from ..certify.api import certify, certify_batch, check
from ..certify.criteria import hurwitz_conditions, hurwitz_ok
from ..constants import GAIN_BOUNDS
from ..errors import StringStabError
from ..params import Box, Params, parameter_model, positive
from ..params import sample_time as _sample_time
from .constraints import FORM_SIZE, Loop, Member, Slot, evaluate_forms
from .inputs import as_bounds, as_k0, as_weights
from .predictor import predict, predict_dips, violating_dips
from .result import CERTIFIED, TuneResult, Verdict, make_result, wdist

__all__ = ["Projector", "project"]

Array = npt.NDArray[np.float64]

#: Frequency-slot capacities of the NLPs, each built on first use (the smallest that fits is
#: used: an unused slot costs IPOPT about as much per iteration as a used one).
_SLOTS = (4, 6, 8, 10, 12, 14, 16, 20, 24, 28, 32, 40, 48)
#: Fixed frequencies (rad/s) in every first solve, besides ω = 0 and the dips of g(·; K0).
_LADDER: tuple[float, ...] = tuple(float(v) for v in np.geomspace(0.2, 5.0, 16))
#: Relative offset of the two neighbours added with every exchanged frequency.
_CLUSTER = 0.05
#: Multipliers of the violating frequencies of K0 in the first solve.
_K0_CLUSTER = (1.0, 0.95, 0.9)
#: The largest ε the sampled and robust exchange widens the frequency constraints to when the
#: certificate is inconclusive at its solution.
_EPS_MAX = 1e-1
#: Multipliers of the predicted dips of the solution (:func:`~stringstab.tuning.predictor.predict_dips`) in the first solve.
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
    return ca.nlpsol(f"stringstab_projection_{n_slots}", "ipopt",
                     {"x": x, "p": par, "f": f, "g": g}, _IPOPT)


#: IPOPT's options for every projection NLP.
_IPOPT = {
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


@cache
def _quad_nlp(n_slots: int) -> Any:
    """The projection NLP with ``n_slots`` quadratic constraints, built once per process.

    Decision K = (k_x, k_v, k_a); parameters p = (K0, w, then per slot the 10 numbers of a
    quadratic form q_j(K) = c + bᵀK + KᵀAK, :func:`stringstab.tuning.constraints.quadratic_form`).
    Constraints q_j(K) ≥ lower bound (a margin, ε, or −inf for an unused slot).
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
                     {"x": x, "p": par, "f": f, "g": ca.vertcat(*gs)}, _IPOPT)



def _surely_uncertifiable(K: Array, p: Params) -> tuple[bool, list[float]]:
    """(True, frequencies) when K provably cannot be certified: not Hurwitz or g(ω) < 0 found.

    A violation g(ω) < −1e-9·scale at any ω means |Γ(jω)| > 1 there, so the
    (sound) certificate can never certify K; no certificate call is needed.
    """
    _, a, b, cx, cv = (float(c) for c in _margin.coefficients(
        K[0], K[1], K[2], tau=p.tau, delta=p.delta, headway=p.headway))
    scale = 1.0 + abs(a) + abs(b) + abs(cx) + abs(cv)
    _, dips = violating_dips(K, p, threshold=-1e-9 * scale)
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



@lru_cache(maxsize=16)
def _loop_map(box: Box, sample_time: float | None, heterogeneous: bool, lo: float, hi: float,
              margin: float, n: int = 21) -> Array:
    """Certified points of an n³ grid over the bounds for a sampled or robust loop, whose
    stability conditions (at the box's corners) are ≥ ``margin`` (starting points, fallbacks)."""
    loop = Loop(box if not box.is_point else Params(box.tau[0], box.delta[0], box.headway[0]),
                sample_time, heterogeneous)
    g = np.linspace(lo, hi, n)
    K = np.stack([a.ravel() for a in np.meshgrid(g, g, g, indexing="ij")], axis=1)
    keep = np.ones(len(K), dtype=bool)
    for m in loop.corners():
        forms = np.array([s.form for s in loop.stability_slots(m)])
        keep &= np.all(evaluate_forms(forms, K) >= margin, axis=0)
    pts = K[keep][loop.certified_points(K[keep])]
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
    certificate, :func:`stringstab.certify.api.check` (the verdicts of
    :func:`~stringstab.certify.api.certify` without its reporting extras; a
    cache hit returns gains that were).

    Parameters
    ----------
    tau, delta, headway : float, (lo, hi) or "LO:HI"
        Model parameters (s); an interval asks for gains certified for every member of the
        box (the robust certificate).
    sample_time : float, optional
        H (s): gains certified for the sampled-data loop (zero-order hold).
    heterogeneous : bool
        Sampled box only: the predecessor's lag ranges over the τ box independently.
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
        tau: Any,
        delta: Any,
        headway: Any,
        sample_time: float | None = None,
        heterogeneous: bool = True,
        weights: Sequence[float] = (1.0, 1.0, 1.0),
        bounds: tuple[float, float] = GAIN_BOUNDS,
        hurwitz_margin: float = 1e-3,
        eps: float = 1e-4,
        max_exchange: int = 25,
        cache_size: int = 4096,
        cache_decimals: int = 6,
        predictor: bool = True,
        warm_from_previous: bool = False,
    ) -> None:
        self.params: Params | Box = parameter_model(tau, delta, headway)
        self.sample_time = None if sample_time is None else _sample_time(sample_time)
        #: The sampled or robust loop (None: the continuous loop at one τ, δ, T*).
        self.loop = (None if self.sample_time is None and isinstance(self.params, Params)
                     else Loop(self.params, self.sample_time, heterogeneous))
        self.weights = as_weights(weights)
        self.bounds = as_bounds(bounds)
        self.hurwitz_margin = positive("hurwitz_margin", hurwitz_margin, allow_zero=True)
        self.eps = positive("eps", eps)
        if isinstance(max_exchange, bool) or not isinstance(max_exchange, (int, np.integer)) \
                or max_exchange < 1:
            raise StringStabError(f"max_exchange must be an integer >= 1; got {max_exchange!r}")
        self.max_exchange = int(max_exchange)
        self.cache_size = int(cache_size)
        self.cache_decimals = int(cache_decimals)
        self._cache: OrderedDict[tuple[float, ...], tuple[Array, Verdict]] = OrderedDict()
        self._last: Array | None = None
        self.predictor = bool(predictor)
        self.warm_from_previous = bool(warm_from_previous)
        self.stats = {"calls": 0, "cache_hits": 0, "warm_starts": 0, "fallbacks": 0,
                      "predicted": 0}

    @property
    def _point(self) -> Params:
        """The parameters of the continuous loop at one τ, δ, T*."""
        assert isinstance(self.params, Params)
        return self.params

    # -- the certified map (starting points, fallbacks) -------------------------------
    def _map(self) -> Array:
        if self.loop is not None:
            # a sampled box's certificate is the slow one: an 11³ map (72 points at
            # Δt = 0.1 s, τ ∈ [0.1, 0.2], δ ∈ [0.15, 0.25] s: 3.5 s) instead of 21³ (33.6 s)
            n = 11 if self.loop.sampled and isinstance(self.params, Box) else 21
            return _loop_map(self.loop.box, self.sample_time, self.loop.heterogeneous,
                             *self.bounds, self.hurwitz_margin, n)
        p = self._point
        return _certified_map(p.tau, p.delta, p.headway, *self.bounds, self.hurwitz_margin)

    def reset(self) -> None:
        """Forget the cache and the previous solution."""
        self._cache.clear()
        self._last = None

    # -- one NLP solve ------------------------------------------------------------------
    def _solve(self, K0: Array, x0: Array, omegas: list[float]) -> tuple[Array, str, int]:
        n = next(s for s in _SLOTS if s >= len(omegas))
        solver = _nlp(n)
        p = self._point
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
        """The exact certificate's verdict on K (:func:`stringstab.certify.api.check`).

        Returns (verdict, internally stable, witness frequency: where the
        smallest g(ω) was found; |Γ(jω)| > 1 there when K is internally stable
        and not certified).
        """
        p = self._point
        c = check(K[0], K[1], K[2], tau=p.tau, delta=p.delta, headway=p.headway)
        return str(c.verdict[0]), bool(c.hurwitz[0]), float(c.witness_omega[0])

    def __call__(self, K0: Sequence[float] | Array, *, warm_start: Sequence[float] | None = None,
                 use_state: bool = True) -> TuneResult:
        """Repair one triple K0 (see :func:`project` for the algorithm)."""
        t0 = time.perf_counter()
        k0 = as_k0(K0)
        w = self.weights
        self.stats["calls"] += 1
        method = "projection"

        key = tuple(np.round(k0, self.cache_decimals).tolist())
        if use_state and self.cache_size and key in self._cache:
            self._cache.move_to_end(key)
            kc, vc = self._cache[key]
            self.stats["cache_hits"] += 1
            status = "unchanged" if np.array_equal(kc, k0) else "repaired"
            return make_result(method, k0, kc if status == "repaired" else k0, vc, status, w, 0, t0,
                           "cache hit: gains certified on an earlier call", cache_hit=True)
        if self.loop is not None:
            return self._repair_loop(self.loop, k0, key, use_state, warm_start, t0)
        p = self._point

        # Is K0 already certified?  Skip the certificate when a violation is found cheaply.
        bad, dips = _surely_uncertifiable(k0, p)
        if not bad:
            verdict0, hz0, wit0 = self._check(k0)
            if verdict0 == "certified":
                self._remember(key, k0, use_state)
                return make_result(method, k0, k0, CERTIFIED, "unchanged", w, 0, t0,
                               "already certified by the exact certificate; returned unchanged")
            if hz0 and wit0 > 0:
                dips = [*dips, wit0]
        # the dips of the solution lie a little below those of K0, as a rule; where they
        # go is predicted from the linearised constraint at each dip
        pred = predict_dips(k0, dips, p, w, self.eps)
        dips = [o * f for o in dips for f in _K0_CLUSTER]
        dips += [o * f for o in pred for f in _PRED_CLUSTER]

        # Starting point: the nearest certified map point, the previous solution or warm_start.
        M = self._map()
        dm = wdist(M, k0, w)
        im = int(np.argmin(dm)) if len(M) else -1
        omegas = [0.0, *_LADDER, *dips]
        if warm_start is not None:
            x0 = as_k0(warm_start)
            start = "warm_start"
        elif self.warm_from_previous and use_state and self._last is not None and (
                im < 0 or float(wdist(self._last, k0, w)) < float(dm[im])):
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
            kp = predict(k0, pred, omegas, params=p, weights=w, eps=self.eps, bounds=self.bounds,
                         hurwitz_margin=self.hurwitz_margin, check=self._check)
            if kp is not None:
                (best, active), predicted = kp, True
                x = best
                n_solves = 1
                self.stats["predicted"] += 1

        def solve(x: Array) -> tuple[Array, str, int]:
            nonlocal omegas
            omegas = self._fit_slots(omegas, x)
            return self._solve(k0, x, omegas)

        def step(x: Array) -> str:
            # the exact certificate's verdict; when it does not certify, its witness
            # frequency (|Γ| > 1 there) and the violating dips of a cheap scan are added
            nonlocal omegas
            verdict, hz, wit = self._check(x)
            if verdict == "certified":
                return "certified"
            new = [wit] if hz and wit > 0 else []
            new += violating_dips(x, p, threshold=0.0)[1]
            # each new frequency comes with two neighbours ±_CLUSTER: the dip moves as K moves
            new = [o * f for o in new for f in (1.0, 1.0 - _CLUSTER, 1.0 + _CLUSTER)]
            grown = _dedupe([*omegas, *new])
            if len(grown) == len(omegas):  # nothing new to add: stop
                return "stuck"
            omegas = grown
            return "grown"

        if not predicted:
            best, x, n_solves, ipopt_iters, statuses = _exchange(x, self.max_exchange, solve, step)

        fallback = False
        if im >= 0 and (best is None or float(wdist(best, k0, w)) > float(dm[im])):
            # the nearest certified map point is nearer (or the exchange failed): use it
            if self._check(M[im])[0] == "certified":
                best = M[im].copy()
                fallback = True
                self.stats["fallbacks"] += 1
        if best is None:
            xf = x if np.all(np.isfinite(x)) else k0
            cx = certify(*xf, tau=p.tau, delta=p.delta, headway=p.headway)  # full report
            return make_result(method, k0, xf, cx, "failed", w, n_solves, t0,
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
        return make_result(method, k0, best, CERTIFIED, "repaired", w, n_solves, t0, msg,
                       start=start, fallback=fallback, predictor=predicted and not fallback,
                       active=active, frequencies=omegas,
                       ipopt_iterations=ipopt_iters, ipopt_status=statuses)

    # -- the sampled and robust loops: the same exchange on quadratic constraints ------
    def _solve_quad(self, K0: Array, x0: Array, slots: list[Slot],
                    eps: float) -> tuple[Array, str, int]:
        n = next(s for s in _SLOTS if s >= len(slots))
        solver = _quad_nlp(n)
        forms = np.zeros((n, FORM_SIZE))
        forms[: len(slots)] = [sl.form for sl in slots]
        lbg = np.full(n, -np.inf)
        lbg[: len(slots)] = [self.hurwitz_margin if sl.kind == "stability" else eps
                             for sl in slots]
        lo, hi = self.bounds
        par = np.concatenate([K0, self.weights, forms.ravel()])
        sol = solver(x0=np.clip(x0, lo, hi), p=par, lbx=lo, ubx=hi, lbg=lbg, ubg=np.inf)
        st = solver.stats()
        return np.asarray(sol["x"], dtype=float).ravel(), str(st["return_status"]), int(st["iter_count"])

    def _first_slots(self, loop: Loop, k0: Array, witnesses: list[tuple[Member, float]]) -> list[Slot]:
        """Stability at the box's corners, the margin at 0 at every corner and on a ladder of
        frequencies at the centre, and at the certificate's witness for K0 (±5 %)."""
        slots: list[Slot] = []
        worst = loop.corners() if loop.sampled else [Member(loop.box.tau[1], loop.box.tau[1],
                                                            loop.centre().delta,
                                                            loop.box.headway[0])]
        for m in worst:
            slots += [s for s in loop.stability_slots(m) if not loop.sampled or s.index in (0, 1, 4)]
        for m in loop.first_members():
            slots.append(loop.margin_slot(m, 0.0))
        c = loop.centre()
        slots += [loop.margin_slot(c, f) for f in loop.ladder()[1:]]
        for m, f in witnesses:
            slots += [loop.margin_slot(m, f * r) for r in _K0_CLUSTER if f > 0]
        return _dedupe_slots(slots)

    def _repair_loop(self, loop: Loop, k0: Array, key: tuple[float, ...], use_state: bool,
                     warm_start: Sequence[float] | None, t0: float) -> TuneResult:
        """Repair for the sampled or robust loop: exchange on :func:`_quad_nlp`, every output
        decided by that loop's certificate (:meth:`Loop.check`)."""
        method, w = "projection", self.weights
        verdict0, _, wit0 = loop.check(k0)
        if verdict0 == "certified":
            self._remember(key, k0, use_state)
            return make_result(method, k0, k0, CERTIFIED, "unchanged", w, 0, t0,
                               f"already certified for the {self._loop_name()} loop; returned unchanged")
        slots = self._first_slots(loop, k0, wit0)
        M = self._map()
        dm = wdist(M, k0, w)
        im = int(np.argmin(dm)) if len(M) else -1
        if warm_start is not None:
            x, start = as_k0(warm_start), "warm_start"
        elif im >= 0:
            x, start = M[im], "map"
        else:
            x, start = k0, "input"
        eps = self.eps

        def solve(x: Array) -> tuple[Array, str, int]:
            return self._solve_quad(k0, x, _fit_forms(slots, x), eps)

        def step(x: Array) -> str:
            nonlocal slots, eps
            verdict, stable, wits = loop.check(x)
            if verdict == "certified":
                return "certified"
            new: list[Slot] = []
            for m, f in wits:
                if not stable:  # an unstable member: all its stability conditions
                    new += loop.stability_slots(m)
                    continue
                new += [loop.margin_slot(m, f * r) for r in (1.0, 1.0 - _CLUSTER, 1.0 + _CLUSTER)]
                new += [loop.margin_slot(m, d * r) for d in loop.dips(x, m, 0.0)
                        for r in (1.0, 1.0 - _CLUSTER, 1.0 + _CLUSTER)]
                # the worst member of a box is usually a corner: the frequency there too
                new += [loop.margin_slot(c, f) for c in loop.extreme_members()]
            grown = _dedupe_slots([*slots, *new])
            if verdict == "inconclusive" and stable and eps < _EPS_MAX:
                # a margin too thin for the certificate to decide (a near-tangency): widen it
                eps = min(10.0 * eps, _EPS_MAX)
            elif len(grown) == len(slots):
                return "stuck"
            slots = grown
            return "grown"

        best, x, n_solves, ipopt_iters, statuses = _exchange(x, self.max_exchange, solve, step)
        fallback = False
        if im >= 0 and (best is None or float(wdist(best, k0, w)) > float(dm[im])):
            best, fallback = M[im].copy(), True  # certified when the map was made
            self.stats["fallbacks"] += 1
        if best is None:
            xf = x if np.all(np.isfinite(x)) else k0
            return make_result(method, k0, xf, loop.certify(xf), "failed", w, n_solves, t0,
                               f"no point certified for the {self._loop_name()} loop found after "
                               f"{n_solves} solve(s) (IPOPT: {statuses[-1] if statuses else 'not run'})",
                               start=start, ipopt_iterations=ipopt_iters, ipopt_status=statuses)
        self._remember(key, best, use_state)
        if use_state:
            self._last = best
        msg = (f"nearest certified point of the {len(M)}-point certified map of the "
               f"{self._loop_name()} loop (the NLP solution was not nearer)" if fallback else
               f"nearest point certified for the {self._loop_name()} loop: {n_solves} solve(s), "
               f"{len(slots)} constraints")
        return make_result(method, k0, best, CERTIFIED, "repaired", w, n_solves, t0, msg,
                           start=start, fallback=fallback, constraints=len(slots),
                           ipopt_iterations=ipopt_iters, ipopt_status=statuses)

    def _loop_name(self) -> str:
        H = self.sample_time
        what = "continuous" if H is None else f"sampled (Δt = {H:g} s)"
        return f"{what}, robust over the box," if isinstance(self.params, Box) else what

    def _remember(self, key: tuple[float, ...], k: Array, use_state: bool) -> None:
        """Cache gains that the exact certificate certified."""
        if not (use_state and self.cache_size):
            return
        self._cache[key] = (k, CERTIFIED)
        if len(self._cache) > self.cache_size:
            self._cache.popitem(last=False)

    def _fit_slots(self, omegas: list[float], x: Array) -> list[float]:
        """Keep at most the largest slot capacity: drop the slackest frequencies (never ω = 0)."""
        cap = _SLOTS[-1]
        if len(omegas) <= cap:
            return omegas
        p = self._point
        om = np.asarray(omegas[1:])
        gv = _margin.g(om, x[0], x[1], x[2], tau=p.tau, delta=p.delta, headway=p.headway)
        keep = np.sort(np.argsort(gv)[: cap - 1])
        return [omegas[0], *om[keep].tolist()]

def _exchange(
    x: Array, max_solves: int, solve: Callable[[Array], tuple[Array, str, int]],
    step: Callable[[Array], str],
) -> tuple[Array | None, Array, int, int, list[str]]:
    """The exchange method: solve from x, ask the certificate (``step``), repeat.

    ``solve(x)`` solves the NLP with the current constraints from x; ``step(x)`` asks the
    certificate and returns ``"certified"``, ``"grown"`` (it added constraints at its witness)
    or ``"stuck"`` (nothing new to add).  Stops at a certified point, when stuck, at a
    non-finite solution or after ``max_solves`` solves.

    Returns
    -------
    (best or None, last x, solves, IPOPT iterations, IPOPT statuses)
    """
    statuses: list[str] = []
    n_solves = iters = 0
    for _ in range(max_solves):
        x, status, its = solve(x)
        n_solves += 1
        iters += its
        statuses.append(status)
        if not np.all(np.isfinite(x)):
            break
        outcome = step(x)
        if outcome == "certified":
            return x, x, n_solves, iters, statuses
        if outcome == "stuck":
            break
    return None, x, n_solves, iters, statuses


def _dedupe_slots(slots: list[Slot], rtol: float = 1e-6) -> list[Slot]:
    """The slots in order, dropping one at the same member and (nearly) the same frequency."""
    out: list[Slot] = []
    seen: list[tuple[str, Member, int, float]] = []
    for s in slots:
        if s.kind == "margin" and not (math.isfinite(s.freq) and s.freq >= 0):
            continue
        dup = any(k == s.kind and m == s.member and i == s.index
                  and (s.kind == "stability" or abs(f - s.freq) <= rtol * max(1.0, f))
                  for k, m, i, f in seen)
        if not dup:
            out.append(s)
            seen.append((s.kind, s.member, s.index, s.freq))
    return out


def _fit_forms(slots: list[Slot], x: Array) -> list[Slot]:
    """At most the largest slot capacity: drop the slackest margin slots at x (never stability)."""
    cap = _SLOTS[-1]
    if len(slots) <= cap:
        return slots
    stab = [s for s in slots if s.kind == "stability"]
    marg = [s for s in slots if s.kind != "stability"]
    vals = evaluate_forms(np.array([s.form for s in marg]), x)
    keep = np.sort(np.argsort(vals)[: cap - len(stab)])
    return stab + [marg[i] for i in keep]


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
def _default_projector(params: Params | Box, weights: tuple[float, ...],
                       bounds: tuple[float, float], hurwitz_margin: float, eps: float,
                       max_exchange: int, predictor: bool = True,
                       sample_time: float | None = None, heterogeneous: bool = True) -> Projector:
    return Projector(tau=params.tau, delta=params.delta, headway=params.headway,
                     sample_time=sample_time, heterogeneous=heterogeneous, weights=weights,
                     bounds=bounds, hurwitz_margin=hurwitz_margin, eps=eps,
                     max_exchange=max_exchange, cache_size=0, predictor=predictor)


def project(
    K0: Sequence[float] | Array,
    *,
    tau: Any,
    delta: Any,
    headway: Any,
    sample_time: float | None = None,
    heterogeneous: bool = True,
    weights: Sequence[float] = (1.0, 1.0, 1.0),
    bounds: tuple[float, float] = GAIN_BOUNDS,
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

    where g(ω) = (|D(jω)|² − |N(jω)|²)/ω² (:func:`stringstab.certify.frequency.margin_g`;
    g(0) = Ψ3), so g(ω_j) ≥ ε is |D(jω_j)|² − |N(jω_j)|² ≥ ε ω_j².  The frequency
    set starts as {0}, a fixed ladder of 16 frequencies (0.2 to 5 rad/s,
    geometric), the violating local minima of g(·; K0) (each also at 0.95
    and 0.9 times itself) and, for each of them, the predicted dip of the
    repaired gains (the dip of g at the nearest point of the linearised
    constraint, followed twice; each also at 0.98 and 1.02 times itself).  It
    is refined by *exchange*: after each solve the exact certificate
    (:func:`stringstab.certify.api.check`) is asked; if it does not certify
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

    For the sampled-data loop and for a parameter box there is no predictor; the exchange
    runs on an NLP whose constraints are quadratic forms in K
    (:mod:`stringstab.tuning.constraints`): the Schur (or worst-corner Hurwitz) conditions,
    the margin at 0 at the box's corners and on the ladder at its centre, and then, after
    each solve, the margin at the certificate's witness member and frequency (θ when
    sampled) and at the dips of that member's margin; the certificate of that loop decides
    every output, and the fallback is the nearest point of that loop's certified map.

    Parameters
    ----------
    K0 : sequence of 3 floats
        The gains to repair.
    tau, delta, headway : float, (lo, hi) or "LO:HI"
        Model parameters (s); an interval asks for gains certified for every member of the
        box (the robust certificate, :mod:`stringstab.certify.robust`).
    sample_time : float, optional
        H (s): gains certified for the sampled-data loop (:mod:`stringstab.certify.sampled`).
    heterogeneous : bool
        Sampled box only: the predecessor's lag ranges over the τ box independently.
    weights : sequence of 3 floats
        Weights of the squared distance, > 0.
    bounds : (float, float)
        Bounds on every gain (IDL Table 2: [-2, 2]).
    hurwitz_margin : float
        m in k_x ≥ m and k_v + (T* − τ)k_x ≥ m (internal stability with a margin); sampled,
        m in each Schur condition normalised to these as H → 0
        (:func:`stringstab.certify.sampled.schur_margins`).
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
        ``certified`` is the exact certificate's verdict on the output (of the loop asked for).

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
    >>> r = project([0.9, -0.5, 1.1], tau=0.1, delta=0.2, headway=1.1, sample_time=0.1)
    >>> r.status, r.certified
    ('repaired', True)
    """
    proj = _default_projector(
        parameter_model(tau, delta, headway), tuple(float(v) for v in as_weights(weights)),
        as_bounds(bounds), positive("hurwitz_margin", hurwitz_margin, allow_zero=True),
        positive("eps", eps), max_exchange, bool(predictor),
        None if sample_time is None else _sample_time(sample_time), bool(heterogeneous),
    )
    return proj(K0, warm_start=warm_start, use_state=False)

