"""The IDL paper's region-growing repair (§3.3, Steps 1-6), as printed.

Its candidate test is the Taylor Proposition 1 (types I-IV), so its output may fail the exact
certificate; every output is reported with the exact certificate's verdict.  Choices made
where the paper is silent are listed in :func:`region_growing` and ``docs/tuning.md``.

References
----------
IDL paper, §3.3 "Parameter tuning method" (types I-IV, eqs 25-26, Steps 1-6); Table 2
(gain bounds [-2, 2]).
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ..certify.api import certify
from ..certify.criteria import TYPE_NAMES, hurwitz, taylor_criteria
from ..constants import GAIN_BOUNDS
from ..errors import StringStabError
from ..params import Params, positive
from .inputs import as_bounds, as_k0, as_weights
from .result import TuneResult, make_result, wdist

__all__ = ["region_growing"]

Array = npt.NDArray[np.float64]


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


#: The most grid points (summed over the regions R_k built) one region-growing search may
#: build: R_155 with the default grid of 2 (r0 >= 0.026 covers the bounds [-2, 2] within it).
MAX_POINTS = 1e8


def region_growing(
    K0: Sequence[float] | Array,
    *,
    tau: float,
    delta: float,
    headway: float,
    r0: float = 0.1,
    grid: int = 2,
    bounds: tuple[float, float] = GAIN_BOUNDS,
    max_iter: int | None = None,
    criterion: str = "derived",
    weights: Sequence[float] = (1.0, 1.0, 1.0),
    grow_ka: bool = False,
    check_hurwitz: bool = False,
) -> TuneResult:
    r"""Repair K0 with the IDL paper's region-growing search (§3.3, Steps 1-6).

    Step 1 sets the initial region R1 = K0 ± r0 in each gain.  Step 2 grid-searches
    it: for a type-III input the slice {k_x = k_x0, k_v ∈ [k_v0 − r0, k_v0],
    k_a ∈ [k_a0 − r0, k_a0]} is excluded (put in R_N; with k_x0 > 0 lowering k_v
    or k_a only lowers Ψ3, eq 26); for a type-IV input the whole R1 is searched.
    A grid point is accepted when the Taylor test calls it type I or II.
    Steps 3-5 grow the region: R_k has k_x ∈ k_x0 ± k r0, k_v ∈ k_v0 ± k r0 and,
    *as printed*, k_a ∈ k_a0 ± r0; R_{k−1} joins R_N, so only R_k \ R_{k−1} is
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
        (:func:`stringstab.certify.criteria.taylor_criteria`).
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
    k0 = as_k0(K0)
    r0 = positive("r0", r0)
    if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or grid < 1:
        raise StringStabError(f"grid must be an integer >= 1 (grid intervals per r0); got {grid!r}")
    G = int(grid)
    lo, hi = as_bounds(bounds)
    w = as_weights(weights)
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
        return make_result(method, k0, k0, cert0, "unchanged", w, 0, t0,
                       "already certified by the exact certificate; returned unchanged",
                       type_in=cert0.type, evaluated=0)
    tc0 = taylor_criteria(*k0, tau=p.tau, delta=p.delta, headway=p.headway, source=criterion)
    type0 = int(tc0.type)
    if _rg_accept(k0[None, :], p, criterion, check_hurwitz)[0]:
        return make_result(
            method, k0, k0, cert0, "taylor_stable", w, 0, t0,
            f"the {criterion} Taylor test calls K0 type {TYPE_NAMES[type0]} (stable), so the "
            f"paper's method leaves it unchanged; exact certificate: {cert0.verdict}",
            type_in=TYPE_NAMES[type0], evaluated=0,
        )

    h = r0 / G
    evaluated = 0
    k = 0
    # the shells R_k with k r0 short of the bounds hold no point inside them: start at the first
    # that can (a K0 far outside the bounds would otherwise walk through millions of empty shells)
    outside = max(max(lo - k0[i], k0[i] - hi, 0.0) for i in grow)
    if outside > hi - lo:  # its shells would grow by O(outside / r0)² points each before any fits
        raise StringStabError(
            f"region growing searches the gain bounds [{lo:g}, {hi:g}] outward from K0; expected "
            f"K0 within [{2 * lo - hi:g}, {2 * hi - lo:g}] (the bounds widened by their width); got "
            f"K0 = ({k0[0]:g}, {k0[1]:g}, {k0[2]:g}); the projection method takes any K0")
    k_first = max(1, math.floor((outside - 1e-12) / r0))
    work = 0.0
    for k in range(k_first, int(max_iter) + 1):
        # _shell builds the (2kG+1)² x (2G+1) grid of R_k: a tiny r0 would take hours and
        # gigabytes before covering the bounds
        work += float(2 * k * G + 1) ** 2 * (2 * k * G + 1 if grow_ka else 2 * G + 1)
        if work > MAX_POINTS:
            raise StringStabError(
                f"region growing reached region R_{k} of {float(k_cover):.4g} ({work:.3g} grid points) "
                f"without a solution; expected at most {MAX_POINTS:.0e} points: a larger r0 "
                f"(got {r0:g}), a smaller grid (got {G}) or --max-iter")
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
                d = np.round(wdist(cand, k0, w), 12)
                order = np.lexsort((coff[:, 2], coff[:, 1], coff[:, 0], d))
                best = cand[order[0]]
                cert = certify(*best, tau=p.tau, delta=p.delta, headway=p.headway)
                tc = taylor_criteria(*best, tau=p.tau, delta=p.delta, headway=p.headway,
                                     source=criterion)
                return make_result(
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
    return make_result(
        method, k0, k0, cert0, "no_solution", w, k, t0,
        f"No optimized solution found ({reason}); returned the input (type "
        f"{TYPE_NAMES[type0]}); exact certificate: {cert0.verdict}",
        type_in=TYPE_NAMES[type0], evaluated=evaluated,
    )

