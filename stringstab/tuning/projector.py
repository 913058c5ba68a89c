"""The :class:`Projector`: nearest certified gains for a control loop, with a cache and warm starts.

A :class:`Projector` fixes the loop (τ, δ, T*, a box of them, a sample time) and the options
once, and repairs one K0 per call: the Newton predictor of :mod:`stringstab.tuning.predictor`
first, else the exchange (:mod:`stringstab.tuning.exchange`) on the NLPs of
:mod:`stringstab.tuning.nlp`, started from the nearest point of a certified map of the gain
bounds, which is also the fallback.  The exact certificate of the loop decides every output.
:func:`stringstab.tuning.project` is one call of a (cached) Projector without its state.
"""

from __future__ import annotations

import time
from collections import OrderedDict
from collections.abc import Sequence
from functools import lru_cache
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify.api import certify, check
from ..certify.grid import certified_lattice
from ..certify.screen import surely_uncertifiable
from ..certify.screen import violating_dips as screen_dips
from ..certify.verdicts import Verdict
from ..constants import GAIN_BOUNDS
from ..errors import StringStabError
from ..params import Box, Params, parameter_model, positive
from ..params import sample_time as _sample_time
from .constraints import LoopConstraints, Member, Slot, evaluate_forms
from .exchange import (
    CLUSTER,
    dedupe_frequencies,
    dedupe_slots,
    exchange,
    fit_forms,
    fit_frequencies,
)
from .inputs import as_bounds, as_k0, as_weights
from .nlp import solve_projection, solve_quadratic
from .predictor import predict, predict_dips, violating_dips
from .result import CERTIFIED_BY_CHECK, TuneResult, VerdictAndGain, make_result, wdist

__all__ = ["Projector"]

Array = npt.NDArray[np.float64]

#: Fixed frequencies (rad/s) in every first solve, besides ω = 0 and the dips of g(·; K0).
_LADDER: tuple[float, ...] = tuple(float(v) for v in np.geomspace(0.2, 5.0, 16))
#: Multipliers of the violating frequencies of K0 in the first solve.
_K0_CLUSTER = (1.0, 0.95, 0.9)
#: The largest ε the sampled and robust exchange widens the frequency constraints to when the
#: certificate is inconclusive at its solution.
_EPS_MAX = 1e-1
#: Multipliers of the predicted dips of the solution (:func:`~stringstab.tuning.predictor.predict_dips`) in the first solve.
_PRED_CLUSTER = (1.0, 0.98, 1.02)


def _surely_uncertifiable(K: Array, p: Params) -> tuple[bool, list[float]]:
    """(True, frequencies) when K provably cannot be certified (the one screen).

    The screen of :mod:`stringstab.certify.screen`: not Hurwitz, or a dip of g below its
    round-off threshold (|Γ(jω)| > 1 there, so the sound certificate can never certify K).
    """
    dips = screen_dips(K, p)
    return bool(dips) or bool(surely_uncertifiable(K, p, omega=())[0]), dips


@lru_cache(maxsize=16)
def _certified_map(tau: float, delta: float, headway: float, lo: float, hi: float,
                   margin: float, n: int = 21) -> Array:
    """Certified points of an n³ grid over the bounds (starting points and fallbacks).

    :func:`stringstab.certify.grid.certified_lattice`, keeping the points whose Hurwitz
    conditions are ≥ ``margin``.
    """
    return certified_lattice(lo, hi, n, Params(tau, delta, headway), hurwitz_margin=margin)


@lru_cache(maxsize=16)
def _loop_map(box: Box, sample_time: float | None, heterogeneous: bool, lo: float, hi: float,
              margin: float, n: int = 21) -> Array:
    """Certified points of an n³ grid over the bounds for a sampled or robust loop.

    Only points whose stability conditions (at the box's corners) are ≥ ``margin`` are kept;
    they serve as starting points and fallbacks.
    """
    loop = LoopConstraints(box if not box.is_point else Params(box.tau[0], box.delta[0], box.headway[0],
                                                               box.reaction_delay[0]),
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
    reaction_delay : float
        θ_r ≥ 0 (s), the reaction delay on the whole command (issue 25): with θ_r > 0 the
        gains are certified by :mod:`stringstab.certify.reaction` or, with ``sample_time``, by
        :mod:`stringstab.certify.sampled_reaction` (a point loop only; a box is refused).
        The exchange then runs on the quadratic forms of g_θ(ω_j; K) or g_{H,θ_r}(θ_j; K)
        (:mod:`stringstab.tuning.constraints`) under k_x ≥ ``hurwitz_margin`` (and, sampled,
        the condition of χ_f at z = −1), without the predictor.
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
        reaction_delay: Any = 0.0,
    ) -> None:
        self.params: Params | Box = parameter_model(tau, delta, headway, reaction_delay)
        self.sample_time = None if sample_time is None else _sample_time(sample_time)
        #: The sampled, robust or reaction-delay loop (None: the continuous loop at one τ, δ, T*).
        self.loop = (None if self.sample_time is None and isinstance(self.params, Params)
                     and not self.params.reaction_delay
                     else LoopConstraints(self.params, self.sample_time, heterogeneous))
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
        self._cache: OrderedDict[tuple[float, ...], tuple[Array, VerdictAndGain]] = OrderedDict()
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
            # (and with θ_r > 0 sampled: its lifted certificate is slower still)
            n = 11 if self.loop.sampled and (isinstance(self.params, Box)
                                             or self.loop.reaction_delay) else 21
            return _loop_map(self.loop.box, self.sample_time, self.loop.heterogeneous,
                             *self.bounds, self.hurwitz_margin, n)
        p = self._point
        return _certified_map(p.tau, p.delta, p.headway, *self.bounds, self.hurwitz_margin)

    def reset(self) -> None:
        """Forget the cache and the previous solution."""
        self._cache.clear()
        self._last = None

    def state(self) -> dict[str, npt.NDArray[np.float64]]:
        """The state kept between calls, as arrays (a training checkpoint saves it).

        Returns
        -------
        dict of str to ndarray
            ``keys`` (m, 3): the cache's rounded K0, least recently used first; ``gains``
            (m, 3): the certified gains kept for each; ``last`` (3,): the previous solution
            (NaN when there is none).
        """
        m = len(self._cache)
        keys = np.array(list(self._cache), dtype=np.float64).reshape(m, 3)
        gains = np.array([k for k, _ in self._cache.values()], dtype=np.float64).reshape(m, 3)
        last = np.full(3, np.nan) if self._last is None else np.array(self._last, dtype=np.float64)
        return {"keys": keys, "gains": gains, "last": last}

    def load_state(self, arrays: dict[str, npt.NDArray[np.float64]]) -> None:
        """Restore :meth:`state` output (replaces the cache and the previous solution).

        Every kept gain was certified by the exact certificate when it was kept (the cache
        holds only such gains); the arrays are checked for shape and finiteness only.

        Raises
        ------
        StringStabError
            If an array is missing, mis-shaped or not finite, or there are more rows than
            ``cache_size``.
        """
        try:
            keys = np.asarray(arrays["keys"], dtype=np.float64)
            gains = np.asarray(arrays["gains"], dtype=np.float64)
            last = np.asarray(arrays["last"], dtype=np.float64)
        except (KeyError, TypeError, ValueError) as e:
            raise StringStabError(f"projector state: expected arrays keys, gains, last; "
                                  f"found {sorted(arrays)}") from e
        if (keys.ndim != 2 or keys.shape[1:] != (3,) or gains.shape != keys.shape
                or last.shape != (3,) or keys.shape[0] > self.cache_size
                or not (np.isfinite(keys).all() and np.isfinite(gains).all())):
            raise StringStabError(
                f"projector state: expected keys and gains of one shape (m, 3), m <= "
                f"{self.cache_size}, finite, and last (3,); found {keys.shape}, {gains.shape}, "
                f"{last.shape}")
        self._cache = OrderedDict((tuple(k.tolist()), (g.copy(), CERTIFIED_BY_CHECK))
                                  for k, g in zip(keys, gains))
        self._last = None if np.isnan(last).all() else last.copy()

    # -- one NLP solve ------------------------------------------------------------------
    def _solve(self, K0: Array, x0: Array, omegas: list[float]) -> tuple[Array, str, int]:
        return solve_projection(K0, x0, omegas, params=self._point, weights=self.weights,
                                bounds=self.bounds, hurwitz_margin=self.hurwitz_margin,
                                eps=self.eps)

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
            if verdict0 == Verdict.CERTIFIED:
                self._remember(key, k0, use_state)
                return make_result(method, k0, k0, CERTIFIED_BY_CHECK, "unchanged", w, 0, t0,
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
        omegas = dedupe_frequencies(omegas)

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
            omegas = fit_frequencies(omegas, x, self._point)
            return self._solve(k0, x, omegas)

        def step(x: Array) -> str:
            # the exact certificate's verdict; when it does not certify, its witness
            # frequency (|Γ| > 1 there) and the violating dips of a cheap scan are added
            nonlocal omegas
            verdict, hz, wit = self._check(x)
            if verdict == Verdict.CERTIFIED:
                return "certified"
            new = [wit] if hz and wit > 0 else []
            new += violating_dips(x, p, threshold=0.0)[1]
            # each new frequency comes with two neighbours ±CLUSTER: the dip moves as K moves
            new = [o * f for o in new for f in (1.0, 1.0 - CLUSTER, 1.0 + CLUSTER)]
            grown = dedupe_frequencies([*omegas, *new])
            if len(grown) == len(omegas):  # nothing new to add: stop
                return "stuck"
            omegas = grown
            return "grown"

        if not predicted:
            best, x, n_solves, ipopt_iters, statuses = exchange(x, self.max_exchange, solve, step)

        fallback = False
        if im >= 0 and (best is None or float(wdist(best, k0, w)) > float(dm[im])):
            # the nearest certified map point is nearer (or the exchange failed): use it
            if self._check(M[im])[0] == Verdict.CERTIFIED:
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
        return make_result(method, k0, best, CERTIFIED_BY_CHECK, "repaired", w, n_solves, t0, msg,
                       start=start, fallback=fallback, predictor=predicted and not fallback,
                       active=active, frequencies=omegas,
                       ipopt_iterations=ipopt_iters, ipopt_status=statuses)

    # -- the sampled and robust loops: the same exchange on quadratic constraints ------
    def _solve_quad(self, K0: Array, x0: Array, slots: list[Slot],
                    eps: float) -> tuple[Array, str, int]:
        return solve_quadratic(K0, x0, slots, weights=self.weights, bounds=self.bounds,
                               hurwitz_margin=self.hurwitz_margin, eps=eps)

    def _first_slots(self, loop: LoopConstraints, k0: Array, witnesses: list[tuple[Member, float]]) -> list[Slot]:
        """The exchange's first constraint slots for ``loop`` (duplicates removed).

        They are stability at the corners of the (τ, T*) box (sampled loop) or at its member with
        the largest τ = τ_p and the smallest T* (robust loop), δ at its centre; the margin at 0
        at every corner of the box and at its centre, and on a ladder of frequencies at the
        centre; and the margin at the certificate's witnesses for K0 (at each witness frequency
        and 5 % and 10 % below it).
        """
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
        return dedupe_slots(slots)

    def _repair_loop(self, loop: LoopConstraints, k0: Array, key: tuple[float, ...], use_state: bool,
                     warm_start: Sequence[float] | None, t0: float) -> TuneResult:
        """Repair K0 for the sampled or robust loop.

        The exchange runs on :func:`~stringstab.tuning.nlp.quadratic_nlp`; every output is
        decided by that loop's certificate (:meth:`LoopConstraints.check`).
        """
        method, w = "projection", self.weights
        verdict0, _, wit0 = loop.check(k0)
        if verdict0 == Verdict.CERTIFIED:
            self._remember(key, k0, use_state)
            return make_result(method, k0, k0, CERTIFIED_BY_CHECK, "unchanged", w, 0, t0,
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
            return self._solve_quad(k0, x, fit_forms(slots, x), eps)

        def step(x: Array) -> str:
            nonlocal slots, eps
            verdict, stable, wits = loop.check(x)
            if verdict == Verdict.CERTIFIED:
                return "certified"
            new: list[Slot] = []
            for m, f in wits:
                if not stable:  # an unstable member: all its stability conditions
                    new += loop.stability_slots(m)
                    continue
                new += [loop.margin_slot(m, f * r) for r in (1.0, 1.0 - CLUSTER, 1.0 + CLUSTER)]
                new += [loop.margin_slot(m, d * r) for d in loop.dips(x, m, 0.0)
                        for r in (1.0, 1.0 - CLUSTER, 1.0 + CLUSTER)]
                # the worst member of a box is usually a corner: the frequency there too
                new += [loop.margin_slot(c, f) for c in loop.extreme_members()]
            grown = dedupe_slots([*slots, *new])
            if verdict == Verdict.INCONCLUSIVE and stable and eps < _EPS_MAX:
                # a margin too thin for the certificate to decide (a near-tangency): widen it
                eps = min(10.0 * eps, _EPS_MAX)
            elif len(grown) == len(slots):
                return "stuck"
            slots = grown
            return "grown"

        best, x, n_solves, ipopt_iters, statuses = exchange(x, self.max_exchange, solve, step)
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
        return make_result(method, k0, best, CERTIFIED_BY_CHECK, "repaired", w, n_solves, t0, msg,
                           start=start, fallback=fallback, constraints=len(slots),
                           ipopt_iterations=ipopt_iters, ipopt_status=statuses)

    def _loop_name(self) -> str:
        H = self.sample_time
        what = "continuous" if H is None else f"sampled (Δt = {H:g} s)"
        if self.loop is not None and self.loop.reaction_delay:
            what += f" (θ_r = {self.loop.reaction_delay:g} s)"
        return f"{what}, robust over the box," if isinstance(self.params, Box) else what

    def _remember(self, key: tuple[float, ...], k: Array, use_state: bool) -> None:
        """Cache gains that the exact certificate certified."""
        if not (use_state and self.cache_size):
            return
        self._cache[key] = (k, CERTIFIED_BY_CHECK)
        if len(self._cache) > self.cache_size:
            self._cache.popitem(last=False)
