"""The IDL repair step (§3.3) for a training loop: every executed gain triple is certified.

The agent proposes K = (k_x, k_v, k_a) for every environment at every step; before the eq-4 law
acts, :class:`GainRepair` replaces each K that the exact certificate
(:func:`stringstab.certify.api.check`) does not certify by a nearby certified triple.  The
library's repairs (:func:`stringstab.tuning.project`, :func:`stringstab.tuning.region_growing`)
take milliseconds per triple, and at the start of training about 90 % of the gain box is not
certified (at τ = 0.1 s, δ = 0.2 s, T* = 1.1 s, 9 % of a 0.05-spaced lattice over [−2, 2]³ is),
so calling them per environment step would dominate training.  The default method is therefore a
*certified lookup*:

``"projection"`` (default)
    1. a proposal inside a *proven cell* of the lattice below — a cell on which both
       certificates hold for every gain (:mod:`stringstab.certify.gain_cells`, proven by blocks
       the first time a proposal comes near: :func:`certified_cells`) — is executed unchanged,
       without a certificate call;
    2. the others are checked point by point by the exact certificates
       (:meth:`GainRepair.certified`): with a sample time H the sampled-data certificate at H
       first (one vectorised :meth:`stringstab.certify.api.Loop.check` call for the step's
       rows, except the rows its screen proves uncertifiable,
       :meth:`stringstab.certify.screen.SampledScreen.surely_uncertifiable`: about 97 % of the
       uncertified rows of the default training, answered without a certificate call), then
       the continuous one on the rows it certifies — except rows inside a proven
       cell of the continuous certificate alone (the cells of :func:`certified_cells` without
       H, whose 8 corners the continuous certificate certifies: near the sampled loop's
       boundary the continuous region is wider, so most such rows are); every verdict is kept
       by the triple's exact bits and reused when the same floats come again (a rate-limited
       training walks on a ±r lattice from each start and revisits its points); triples
       certified both ways are executed unchanged;
    3. every other triple goes to the nearest point (Euclidean) of a *certified lattice*: the
       points of a grid of spacing ``resolution`` over the gain box that the exact certificates
       certify (built once per process and parameter set, one vectorised call);
    4. ``refine`` bisection steps along the segment from that point towards the proposed K keep
       the farthest point in a proven cell (no certificate call).

    The result is within about one lattice spacing of the true projection (the nearest certified
    triple); ``analysis/bench_train.py`` measures the difference against
    :func:`stringstab.tuning.project`.
``"projection-exact"``
    :class:`stringstab.tuning.Projector` (IPOPT, with its cache) per uncertified triple.
``"region-growing"``
    the paper's search, :func:`stringstab.tuning.region_growing`, per uncertified triple; its
    candidate test is the Taylor Proposition 1, so where its output is not certified by the
    exact certificate the ``"projection"`` result is executed instead (counted in
    ``stats["fallbacks"]``).
``"off"``
    no repair: the ablation (executed gains may be uncertified).

Whatever the method, a triple is executed only if it is certified (``"off"`` excepted): by
:func:`~stringstab.certify.api.check` for exactly that triple, or by the proof of a proven cell
that contains it — and, with ``sample_time`` H, also by the sampled-data certificate
(:meth:`~stringstab.certify.api.Loop.check` of the loop at H, or the cell's proof): the loop the
simulator runs holds u over each control step, and gains on the continuous certificate's
boundary need not be string stable in that sampled loop.

With a reaction delay θ_r > 0 (issue 25, ``reaction_delay``) the judges are the continuous
certificate with θ_r (:func:`~stringstab.certify.api.check` with ``reaction_delay``, exact in
θ_r) and, with ``sample_time`` H, the sampled-data certificate with θ_r at H (the loop
:class:`~stringstab.certify.api.Loop` with ``reaction_delay`` and ``sample_time``: θ_r = qH + a
fraction, exact discretisation, docs/sampled.md §10).  The proven cells are objects of the loop
without θ_r and are not used: every proposal is checked at θ_r (verdicts kept, as above); the
certified lattice is the points of the θ_r = 0 lattice that the certificates at θ_r certify
(:func:`~stringstab.tuning.lattice.certified_lattice`: every point certified; points certified
only with θ_r are left out, which is conservative, never unsound); the ``refine`` steps move
towards the proposal by exact checks at θ_r.  A θ_r of more than 2,000 samples of H is refused
(one line, as by the certificate).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify.gain_cells import CertifiedCells
from ..certify.screen import sampled_screen, surely_uncertifiable
from ..certify.verdicts import Verdict
from ..constants import GAIN_BOUNDS
from ..errors import StringStabError
from ..params import Params, positive
from .lattice import certified_cells, certified_lattice

__all__ = ["REPAIR_METHODS", "GainRepair"]

Array = npt.NDArray[np.float64]

#: The most triples whose verdicts a :class:`GainRepair` keeps (:meth:`GainRepair.certified`;
#: about 150 bytes each).
VERDICT_CACHE = 200_000

#: Up to this many ``refine`` steps, :meth:`GainRepair._nearest` looks up every point the
#: bisection may visit (2^refine − 1 per row) in one call, then walks the table.
TABLE_REFINE = 6

#: Repair methods of the IDL action (``"off"``: the ablation without repair).
REPAIR_METHODS: tuple[str, ...] = ("projection", "projection-exact", "region-growing", "off")


class GainRepair:
    """Map proposed gains ``(n, 3)`` to executed gains ``(n, 3)``, each certified (see module).

    Parameters
    ----------
    method : {"projection", "projection-exact", "region-growing", "off"}
        The repair (module docstring).
    tau, delta, headway : float
        Model parameters, s.
    bounds : (float, float)
        Gain box (Table 2: [−2, 2]).
    resolution : float
        Lattice spacing of the lookup.
    refine : int
        Bisection steps after the lookup.
    sample_time : float, optional
        Also require the sampled-data certificate of the zero-order-hold loop at this step
        (:meth:`stringstab.certify.api.Loop.check` at H) for every executed triple.
    reaction_delay : float
        θ_r, s (issue 25): certify with the certificates at θ_r (continuous, and sampled at
        ``sample_time``; module docstring).

    Attributes
    ----------
    stats : dict
        ``calls``, ``rows``, ``unchanged`` (certified as proposed), ``repaired``, ``fallbacks``
        (``"projection-exact"``/``"region-growing"`` outputs not certified, replaced by the
        lookup's), ``seconds`` (time spent in the repair), ``checked`` (rows asked of the point
        certificates), ``reused`` (of them, answered by a kept verdict), ``screened`` (of the
        rest, rows the sampled loop's screen proves uncertifiable, without a point check) and
        ``certificate_calls`` (vectorised point-certificate calls).

    Examples
    --------
    >>> rep = GainRepair(tau=0.1, delta=0.2, headway=1.1, resolution=0.25)
    >>> K = rep([[1.2, 0.5, 0.6], [0.9, -0.5, 1.1]])
    >>> K[0].tolist(), bool((K[1] != [0.9, -0.5, 1.1]).any())
    ([1.2, 0.5, 0.6], True)
    >>> from stringstab.certify.api import check
    >>> check(K[:, 0], K[:, 1], K[:, 2], tau=0.1, delta=0.2, headway=1.1).verdict.tolist()
    ['certified', 'certified']
    """

    def __init__(self, method: str = "projection", *, tau: float, delta: float, headway: float,
                 bounds: tuple[float, float] = GAIN_BOUNDS, resolution: float = 0.05,
                 refine: int = 4, sample_time: float | None = None,
                 reaction_delay: float = 0.0) -> None:
        if method not in REPAIR_METHODS:
            raise StringStabError(f"repair method must be one of {list(REPAIR_METHODS)}; got {method!r}")
        self.method = method
        self.params = Params(tau, delta, headway, reaction_delay=reaction_delay)
        #: θ_r, s (0: the loop without reaction delay).
        self.reaction_delay = self.params.reaction_delay
        lo, hi = (float(b) for b in bounds)
        if not lo < hi:
            raise StringStabError(f"bounds must be (low, high) with low < high; got {bounds!r}")
        self.bounds = (lo, hi)
        self.resolution = positive("repair resolution", resolution)
        if isinstance(refine, bool) or not isinstance(refine, (int, np.integer)) or refine < 0:
            raise StringStabError(f"repair refine must be an integer >= 0; got {refine!r}")
        self.refine = int(refine)
        self.sample_time = None if sample_time is None else positive("repair sample_time",
                                                                      sample_time, unit=" s")
        if self.reaction_delay and self.sample_time is not None:
            from ..certify.lifting_reaction import check_reaction_sampled

            check_reaction_sampled(self.reaction_delay, self.sample_time)
        self._tree: Any = None
        self._projector: Any = None
        self._loops: tuple[Any, Any] | None = None
        #: Verdicts of both certificates by exact gains (row bytes → certified), bounded.
        self._verdicts: dict[bytes, bool] = {}
        self.stats: dict[str, float] = {"calls": 0, "rows": 0, "unchanged": 0, "repaired": 0,
                                        "fallbacks": 0, "seconds": 0.0, "checked": 0,
                                        "reused": 0, "screened": 0, "certificate_calls": 0}

    def describe(self) -> dict[str, Any]:
        """The settings, for logs and JSON (``reaction_delay`` only when θ_r > 0)."""
        return {"method": self.method, **self.params.as_dict(), "bounds": list(self.bounds),
                "resolution": self.resolution, "refine": self.refine,
                "sample_time": self.sample_time}

    # -- the state a resumed training needs ---------------------------------------------------
    def state(self) -> tuple[dict[str, Any], dict[str, npt.NDArray[Any]]]:
        """The repair's decision-affecting state: the kept verdicts, in their insertion order.

        Everything else the repair builds lazily is a function of its settings alone: the
        certified lattices (one vectorised call over the whole grid), the proven cells (each
        block of :class:`~stringstab.certify.gain_cells.CertifiedCells` proven in a call of its
        own) and the k-d tree.  The kept verdicts are not: a verdict of
        :meth:`stringstab.certify.api.Loop.check` is computed with the other rows of its call
        (the branch and bound sizes its splits over the batch; only an inconclusive-versus-
        decided outcome could differ, and none was found in ``analysis/repair_batch_dependence.py``),
        and which rows shared a call depends on the run's history.  A training checkpoint saves
        them (:func:`stringstab.rl.train.train`), so a resumed run repairs as the uninterrupted
        one by design.  With θ_r > 0 and a sample time the lazily checked lattice points are
        among these verdicts.  With ``"projection-exact"`` the state of its
        :class:`~stringstab.tuning.Projector` (its cache of solutions by rounded K0, which
        answers a nearby K0 with an earlier solution) is part of it too.

        Returns
        -------
        meta : dict
            JSON-ready: ``settings`` (:meth:`describe`) and ``verdicts`` (how many are kept).
        arrays : dict of str to ndarray
            ``gains`` (m, 3) float64, the triples' exact bits, oldest first; ``certified`` (m,)
            uint8, 1 where both certificates certify the triple; with ``"projection-exact"``
            also ``projector.keys``, ``projector.gains`` and ``projector.last``
            (:meth:`stringstab.tuning.Projector.state`).
        """
        m = len(self._verdicts)
        gains = np.frombuffer(b"".join(self._verdicts), dtype=np.float64).reshape(m, 3).copy()
        certified = np.fromiter(self._verdicts.values(), dtype=np.uint8, count=m)
        arrays: dict[str, npt.NDArray[Any]] = {"gains": gains, "certified": certified}
        if self.method == "projection-exact":
            arrays.update({f"projector.{k}": v for k, v in self._exact_projector().state().items()})
        return {"settings": self.describe(), "verdicts": m}, arrays

    def load_state(self, meta: dict[str, Any], arrays: dict[str, npt.NDArray[Any]]) -> None:
        """Restore :meth:`state` output: the kept verdicts, in the same order (replaces them).

        Parameters
        ----------
        meta : dict
            :meth:`state`'s ``meta``; its ``settings`` must be this repair's (:meth:`describe`).
        arrays : dict
            :meth:`state`'s ``arrays``: ``gains`` (m, 3) and ``certified`` (m,) of 0/1 (and
            the projector's arrays with ``"projection-exact"``).

        Raises
        ------
        StringStabError
            If the settings differ, or the arrays are missing, mis-shaped, not finite or hold
            more than :data:`VERDICT_CACHE` rows.
        """
        where = "repair state"
        if not isinstance(meta, dict) or meta.get("settings") != self.describe():
            found = meta.get("settings") if isinstance(meta, dict) else meta
            raise StringStabError(f"{where}: expected the settings {self.describe()}; "
                                  f"found {found}")
        names = {"gains", "certified"}
        if self.method == "projection-exact":
            names |= {"projector.keys", "projector.gains", "projector.last"}
        if set(arrays) != names:
            raise StringStabError(f"{where}: expected the arrays {sorted(names)}; "
                                  f"found {sorted(arrays)}")
        gains = np.ascontiguousarray(arrays["gains"], dtype=np.float64)
        cert = np.asarray(arrays["certified"])
        m = cert.shape[0] if cert.ndim == 1 else -1
        if (gains.ndim != 2 or gains.shape[1:] != (3,) or gains.shape[0] != m
                or meta.get("verdicts") != m or m > VERDICT_CACHE
                or not np.isin(cert, (0, 1)).all() or not np.isfinite(gains).all()):
            raise StringStabError(
                f"{where}: expected {meta.get('verdicts')!r} (at most {VERDICT_CACHE}) finite "
                f"gain triples (m, 3) with a 0/1 verdict each; found gains of shape "
                f"{gains.shape} and verdicts of shape {cert.shape}")
        kept = {row.tobytes(): bool(v) for row, v in zip(gains, cert.tolist())}
        if len(kept) != m:
            raise StringStabError(f"{where}: expected {m} distinct gain triples; found "
                                  f"{m - len(kept)} repeated")
        if self.method == "projection-exact":
            self._exact_projector().load_state(
                {k[len("projector."):]: v for k, v in arrays.items() if k.startswith("projector.")})
        self._verdicts = kept

    # -- the lookup -------------------------------------------------------------------------
    def lattice(self) -> Array:
        """The certified lattice of this repair (built on first use)."""
        p = self.params
        return certified_lattice(p.tau, p.delta, p.headway, *self.bounds, self.resolution,
                                 self.sample_time, self.reaction_delay)

    def _lazy(self) -> bool:
        """Whether lattice points are checked when first needed (θ_r > 0 with a sample time).

        The sampled certificate with θ_r checks a lattice point when a repair first needs it
        (:meth:`_nearest`), not all points at the start.
        """
        return bool(self.reaction_delay) and self.sample_time is not None

    def _candidates(self) -> Array:
        """The points the lookup searches.

        :meth:`lattice`, or with θ_r > 0 and a sample time the continuous lattice at θ_r (each
        point also checked by the sampled certificate with θ_r before it is executed).
        """
        if not self._lazy():
            return self.lattice()
        p = self.params
        return certified_lattice(p.tau, p.delta, p.headway, *self.bounds, self.resolution,
                                 None, self.reaction_delay)

    def cells(self) -> CertifiedCells:
        """The proven cells of this repair's lattice (:func:`certified_cells`, shared)."""
        p = self.params
        return certified_cells(p.tau, p.delta, p.headway, *self.bounds, self.resolution,
                               self.sample_time)

    def continuous_cells(self) -> CertifiedCells:
        """The proven cells of the continuous certificate alone (:func:`certified_cells` without H)."""
        p = self.params
        return certified_cells(p.tau, p.delta, p.headway, *self.bounds, self.resolution, None)

    def _kdtree(self) -> Any:
        if self._tree is None:
            from scipy.spatial import cKDTree

            self._tree = cKDTree(self._candidates())
        return self._tree

    def _certificate_loops(self) -> tuple[Any, Any]:
        """The continuous loop and (with ``sample_time``) the sampled loop, checked once."""
        if self._loops is None:
            from ..certify.api import Loop

            self._loops = (Loop(self.params),
                           None if self.sample_time is None else Loop(self.params, self.sample_time))
        return self._loops

    def _judge(self, loop: Any, K: Array) -> npt.NDArray[np.bool_]:
        """Rows of K that ``loop``'s exact certificate certifies (one vectorised call)."""
        self.stats["certificate_calls"] += 1
        c = loop.check_rows(K)  # the rows are clipped finite floats (:meth:`__call__`)
        return np.asarray(c.verdict == Verdict.CERTIFIED.value)

    def _screened(self, K: Array) -> npt.NDArray[np.bool_]:
        """Rows of K the sampled loop's screen flags: surely not certified at H (counted).

        :meth:`stringstab.certify.screen.SampledScreen.surely_uncertifiable` of the loop at H
        (sound: a flagged row is never certified by the sampled certificate, so never by both);
        none with θ_r > 0 (the screen is of the loop without θ_r).
        """
        if self.reaction_delay or self.sample_time is None:
            return np.zeros(K.shape[0], dtype=bool)
        p = self.params
        flagged = sampled_screen(p.tau, p.delta, p.headway, self.sample_time).surely_uncertifiable(K)
        self.stats["screened"] += int(flagged.sum())
        return flagged

    def certified(self, K: npt.ArrayLike) -> npt.NDArray[np.bool_]:
        """Which rows of K this repair's certificates all certify, point by point (cached).

        A row is certified when :meth:`stringstab.certify.api.Loop.check` of the continuous
        loop (at θ_r if > 0) and, with ``sample_time``, of the sampled-data loop at H both say
        ``"certified"`` for exactly that triple.  The sampled check runs first (one vectorised
        call on the rows not yet known), the continuous one on the rows it certifies (a row the
        sampled certificate does not certify is not certified, whatever the other says).
        Each answer is kept, keyed by the triple's exact bits, and reused when the same
        triple comes again — under a gain rate limit a training proposes the same floats
        often (``stats["reused"]``); at most :data:`VERDICT_CACHE` triples are kept (the
        oldest dropped first).  A verdict is computed with the other rows of its call, so
        an inconclusive-versus-decided outcome could depend on them (none did in
        ``analysis/repair_batch_dependence.py``); a training checkpoint saves the kept
        answers (:meth:`state`), so a resumed run does not rely on that.

        Parameters
        ----------
        K : array_like (n, 3)
            Gain triples (k_x, k_v, k_a) of eq 4.

        Returns
        -------
        ndarray of bool (n,)
        """
        K = np.ascontiguousarray(np.asarray(K, dtype=np.float64).reshape(-1, 3))
        out = np.zeros(K.shape[0], dtype=bool)
        cache = self._verdicts
        keys = [row.tobytes() for row in K]
        miss: list[int] = []
        for i, key in enumerate(keys):
            v = cache.get(key)
            if v is None:
                miss.append(i)
            else:
                out[i] = v
        self.stats["checked"] += K.shape[0]
        self.stats["reused"] += K.shape[0] - len(miss)
        if miss:
            idx = np.array(miss)
            cont, samp = self._certificate_loops()
            ok = np.ones(idx.size, dtype=bool)
            if samp is not None:
                # rows the sampled screen flags cannot be certified (sound, no point check)
                ok = ~self._screened(K[idx])
                j = np.flatnonzero(ok)
                if j.size:
                    ok[j] = self._judge(samp, K[idx[j]])
            j = np.flatnonzero(ok)
            if j.size and samp is not None and not self.reaction_delay:
                # a row in a proven cell of the continuous certificate needs no point check
                j = j[~self.continuous_cells().contains(K[idx[j]])]
            if j.size:
                ok[j] = self._judge(cont, K[idx[j]])
            out[idx] = ok
            for i, v in zip(miss, ok.tolist()):
                cache[keys[i]] = v
            while len(cache) > VERDICT_CACHE:
                del cache[next(iter(cache))]
        return out

    def _in_cells(self, K: Array) -> npt.NDArray[np.bool_]:
        """Rows of K in a proven cell; none with θ_r > 0 (the cells are of the loop without it)."""
        if self.reaction_delay:
            return np.zeros(K.shape[0], dtype=bool)
        return self.cells().contains(K)

    def _nearest(self, K0: Array) -> Array:
        """The lattice points nearest K0, moved towards K0 by bisection within proven cells.

        Each step keeps the farther point of the segment from the lattice point to K0 that
        lies in a proven cell of :meth:`cells`: every point returned is a certified lattice
        point or in a proven cell, so certified by both certificates.  With θ_r > 0 a point
        is kept when the certificate at θ_r certifies it (one vectorised check per step).
        """
        P = self._nearest_certified(K0) if self._lazy() else \
            np.array(self.lattice()[np.asarray(self._kdtree().query(K0)[1])], dtype=np.float64)
        if self.refine and not self.reaction_delay and self.refine <= TABLE_REFINE:
            return self._bisect_table(P, K0)
        if self.refine:
            lo = np.zeros(K0.shape[0])
            hi = np.ones(K0.shape[0])
            best = P.copy()
            for _ in range(self.refine):  # bisection within the proven cells
                mid = 0.5 * (lo + hi)
                C = P + mid[:, None] * (K0 - P)
                ok = self.certified(C) if self.reaction_delay else self.cells().contains(C)
                best[ok] = C[ok]
                lo = np.where(ok, mid, lo)
                hi = np.where(ok, hi, mid)
            P = best
        return P

    def _bisect_table(self, P: Array, K0: Array) -> Array:
        """:meth:`_nearest`'s bisection from P towards K0, with one lookup for all its points.

        The bisection's midpoints are the dyadic fractions k/2^refine, so every point it can
        visit, P + (k/2^refine)(K0 − P), is computed (the same floats as the step by step
        bisection) and looked up in one :meth:`CertifiedCells.contains` call; the bisection
        then walks that table.  The result is the step-by-step bisection's: a cell is proven or
        not whatever was asked before (its block alone decides), so looking up points the
        bisection does not visit changes nothing but the blocks proven.
        """
        n = 1 << self.refine
        mids = np.arange(1, n, dtype=np.float64) / n  # exact: n is a power of 2
        C = P[:, None, :] + mids[None, :, None] * (K0 - P)[:, None, :]
        table = self.cells().contains(C.reshape(-1, 3)).reshape(P.shape[0], n - 1)
        rows = np.arange(P.shape[0])
        lo = np.zeros(P.shape[0], dtype=np.intp)
        hi = np.full(P.shape[0], n, dtype=np.intp)
        best = P.copy()
        for _ in range(self.refine):
            mid = (lo + hi) // 2
            ok = table[rows, mid - 1]
            best[ok] = C[rows[ok], mid[ok] - 1]
            lo = np.where(ok, mid, lo)
            hi = np.where(ok, hi, mid)
        return best

    def _nearest_certified(self, K0: Array) -> Array:
        """The nearest points of :meth:`_candidates` that :meth:`certified` certifies (lazy).

        The k nearest candidates of each row, in order of distance, are checked (one call for
        all rows, verdicts kept); the first certified one is the nearest certified point of the
        eager lattice (:func:`~stringstab.tuning.lattice.certified_lattice` with θ_r and H).
        Rows with none among them look further (k × 8), up to every candidate.
        """
        C = self._candidates()
        out = np.empty_like(K0)
        todo = np.arange(K0.shape[0])
        k = 8
        while todo.size:
            k = min(k, C.shape[0])
            _, idx = self._kdtree().query(K0[todo], k=k)
            idx = np.asarray(idx).reshape(todo.size, k)
            uniq, inv = np.unique(idx, return_inverse=True)
            ok = self.certified(C[uniq])[inv.reshape(idx.shape)]
            found = ok.any(axis=1)
            first = np.argmax(ok, axis=1)
            rows = np.flatnonzero(found)
            out[todo[rows]] = C[idx[rows, first[rows]]]
            todo = todo[~found]
            if todo.size and k == C.shape[0]:
                p = self.params
                raise StringStabError(
                    f"no certified gains on the lattice at tau={p.tau}, delta={p.delta}, "
                    f"headway={p.headway}, reaction_delay={p.reaction_delay:g}, sample_time="
                    f"{self.sample_time:g}; expected parameters with a certified region")
            k *= 8
        return out

    def _exact_projector(self) -> Any:
        """The :class:`~stringstab.tuning.Projector` of ``"projection-exact"`` (built on first use)."""
        if self._projector is None:
            from .projector import Projector

            p = self.params
            self._projector = Projector(tau=p.tau, delta=p.delta, headway=p.headway,
                                        bounds=self.bounds)
        return self._projector

    def _exact(self, K0: Array) -> Array:
        from .region_growing import region_growing

        out = np.empty_like(K0)
        p = self.params
        for i, k in enumerate(K0):
            if self.method == "projection-exact":
                r = self._exact_projector()(k)
            else:
                r = region_growing(k, tau=p.tau, delta=p.delta, headway=p.headway,
                                   bounds=self.bounds)
            # a solver may return a point a rounding error outside its bounds: the env would
            # clip it before executing it, so the point certified is the clipped one
            kr = np.clip(np.asarray(r.k, dtype=np.float64), *self.bounds)
            if r.certified and self.certified(kr[None])[0]:
                out[i] = kr
            else:
                out[i] = self._nearest(k[None])[0]
                self.stats["fallbacks"] += 1
        return out

    def approximate(self, K: npt.ArrayLike) -> Array:
        """A cheap, *uncertified* stand-in for the repair, for training signals only.

        Rows that pass the cheap screen (module docstring, step 1) are returned unchanged, the
        others are replaced by their nearest certified lattice point, without the exact check
        or the refinement.  Used by the actor's proposal penalty
        (``TD3Config.proposal_penalty``); never executed.

        Parameters
        ----------
        K : array_like (..., 3)
            Proposed gains (k_x, k_v, k_a); clipped to the bounds first.

        Returns
        -------
        ndarray (n, 3)
            The approximate repaired gains (not certified); the clipped input if the repair is
            ``"off"``.
        """
        K0 = np.clip(np.asarray(K, dtype=np.float64).reshape(-1, 3), *self.bounds)
        if self.method == "off":
            return K0
        p = self.params
        out = K0.copy()
        # the screen of the loop without θ_r (an approximation either way: never executed)
        bad = np.flatnonzero(surely_uncertifiable(K0, Params(p.tau, p.delta, p.headway)))
        if bad.size:
            _, idx = self._kdtree().query(K0[bad])
            out[bad] = self._candidates()[np.asarray(idx)]
        return out

    # -- the call -----------------------------------------------------------------------------
    def __call__(self, K: npt.ArrayLike) -> Array:
        """Executed gains for proposed gains ``K`` (shape ``(n, 3)``; clipped to the bounds)."""
        t0 = time.perf_counter()
        K0 = np.clip(np.asarray(K, dtype=np.float64).reshape(-1, 3), *self.bounds)
        if not np.isfinite(K0).all():
            raise StringStabError("proposed gains must be finite; found NaN or inf")
        out = K0.copy()
        if self.method != "off":
            # a gain in a proven cell is certified by both certificates (the cell's proof);
            # the others by the point certificates (:meth:`certified`: sampled at H, then
            # continuous, at θ_r if > 0; answers reused by exact gains)
            in_cell = self._in_cells(K0)
            ok = in_cell.copy()
            rest = np.flatnonzero(~in_cell)
            if rest.size:
                ok[rest] = self.certified(K0[rest])
            bad = np.flatnonzero(~ok)
            if bad.size:
                if self.method == "projection":
                    # lattice points and points in proven cells: certified both ways
                    out[bad] = self._nearest(K0[bad])
                else:  # an output the point certificates certify, else the lookup's
                    out[bad] = self._exact(K0[bad])
            self.stats["unchanged"] += int(K0.shape[0] - bad.size)
            self.stats["repaired"] += int(bad.size)
        self.stats["calls"] += 1
        self.stats["rows"] += K0.shape[0]
        self.stats["seconds"] += time.perf_counter() - t0
        return out
