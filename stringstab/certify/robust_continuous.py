r"""The robust certificate of the continuous loop over a box: the exact minimum over the box.

The margin of :func:`stringstab.certify.frequency.margin_g` separates:

.. math::
    g(ω) = (τω^2 - c)^2 + (1 - k_a^2)ω^2 - 2k_x - k_v^2
           + 2k_xk_a\cos δω - 2k_vk_a ω \sin δω,\qquad c = k_v + T^*k_x ,

so at each ω the minimum over the box is a closed form (:func:`box_margin`,
:func:`robust_margin`): e = τω² − k_v − T*k_x is affine in (τ, T*), its range over the box
is [τ_lo ω² − k_v − max T*k_x, τ_hi ω² − k_v − min T*k_x] and min e² is 0 or the square of
the end nearer 0; and 2k_xk_a cos ψ − 2k_vk_aω sin ψ = R cos(ψ + φ) over
ψ = δω ∈ [δ_lo ω, δ_hi ω] is −R if the shifted range contains an odd multiple of π, else
the smaller end value.  The minimiser (τ*, δ*, T*) is the witness.

The branch and bound of :mod:`stringstab.certify.branch_bound` then runs on
G(ω) = min_box g(ω): for every member, g ≥ min(g(l), g(r)) − M h²/8 ≥
min(G(l), G(r)) − M h²/8 on [l, r] when M bounds |g''| *uniformly over the box* (the
certificate's bound at τ_hi, δ_hi and the largest |a| over the corners, a being bilinear
in τ and T*).  The tail bound of :func:`stringstab.certify.margin.tail_bound` is taken with
the box's worst coefficients (τ_lo² for τ², the smallest a and b), which bounds every
member's g from below.  Internal stability over the box: with k_x > 0, the Hurwitz
condition k_v + (T* − τ)k_x > 0 increases with T* and decreases with τ, so the worst
member is (τ_hi, h_lo); with k_x ≤ 0 no member is stable.

The way in, the result types and the verdicts are those of :mod:`stringstab.certify.robust`.

References
----------
IDL paper, Definition 1 (eq 10) and eq 11 (derived form).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ..derive import generated as _gen
from ..params import Box, Params, as_gains, check_box
from .branch_bound import branch_and_bound, verdict_codes, zoom_max
from .continuous import check_kernel
from .criteria import hurwitz_bands_kernel
from .excess import EXCESS_SEARCH, searched_excess, violation_peak
from .frequency import gain_squared, margin_g_coefficients, resonances
from .margin import curvature_bound, separable, tail_bound
from .verdicts import CERTIFIED, INCONCLUSIVE, NOT_CERTIFIED, ROUNDOFF_SLACK, Verdict

__all__ = ["box_margin", "certify_box_continuous", "robust_margin"]

Array = npt.NDArray[np.float64]

#: Points of the grid on [0, Ω] the witness member's sup |Γ| is searched on (with its
#: resonances and the box search's frequency; reporting only): on 6,202 not-certified rows
#: the peaks agree with those of a 513-point grid to 1e-9 and with a 20,001-point sweep to 1e-10.
PEAK_GRID = 129


def box_margin(
    w: Array, kx: Array, kv: Array, ka: Array, box: Box, *, minimiser: bool = True,
) -> tuple[Any, ...]:
    """(min_box g(ω), τ*, δ*, T*, magnitude) at ω ≥ 0; gains broadcast against ω.

    g = (τω² − c)² + h2 ω² + h0 + cx cos δω − cv ω sin δω
    (:func:`stringstab.certify.margin.separable`, generated from the derivation): only the
    square depends on τ and T* (c = k_v + T*k_x is affine in T*), only the trigonometric
    terms on δ (module docstring).

    Parameters
    ----------
    w : ndarray
        Frequencies ω ≥ 0, rad/s.
    kx, kv, ka : ndarray
        The gains, broadcast against ``w``.
    box : Box
        τ, δ, T* intervals (validated).
    minimiser : bool
        Also return the minimiser (default); False returns (min g, magnitude) alone, the
        same numbers without the work of the minimiser (the branch and bound's evaluations).

    Returns
    -------
    (ndarray, ndarray, ndarray, ndarray, ndarray)
        min over the box of g(ω); the minimiser τ*, δ*, T*; the magnitude of the terms
        (for the round-off slack).  Without ``minimiser``: (min g, magnitude).
    """
    (t_lo, t_hi), (d_lo, d_hi), (h_lo, h_hi) = box.tau, box.delta, box.headway
    (c_a, h2, h0, cx, cv), (s_ca, s_h2, s_h0, s_cx, s_cv) = separable(kx, kv, ka, headway=h_lo)
    (c_b, *_), (s_cb, *_) = separable(kx, kv, ka, headway=h_hi)
    w2 = w * w
    c_max, c_min = np.maximum(c_a, c_b), np.minimum(c_a, c_b)
    h_at_max = np.where(c_b >= c_a, h_hi, h_lo)
    h_at_min = np.where(c_b >= c_a, h_lo, h_hi)
    e_lo = t_lo * w2 - c_max  # at (τ_lo, argmax c)
    e_hi = t_hi * w2 - c_min  # at (τ_hi, argmin c)
    S = np.where(e_lo > 0, e_lo * e_lo, np.where(e_hi < 0, e_hi * e_hi, 0.0))
    r0 = h2 * w2 + h0

    def trig(d: float) -> Array:
        return np.asarray(cx * np.cos(d * w) - cv * w * np.sin(d * w))

    t_a, t_b = trig(d_lo), trig(d_hi)
    if d_hi > d_lo:
        R = np.hypot(cx, cv * w)
        phi = np.arctan2(cv * w, cx)
        a = d_lo * w + phi
        b = d_hi * w + phi
        k = np.ceil((a - np.pi) / (2.0 * np.pi))
        crit = np.pi + 2.0 * np.pi * k
        inside = (crit <= b + 1e-12 * (1.0 + np.abs(b))) & (w > 0)
        T = np.where(inside, -R, np.minimum(t_a, t_b))
    else:  # a point δ: the trigonometric terms at that δ
        inside = np.zeros(np.shape(t_a), dtype=bool)
        T = np.minimum(t_a, t_b)
    G = S + r0 + T
    e_mag = t_hi * w2 + np.maximum(s_ca, s_cb)
    mag = e_mag * e_mag + s_h2 * w2 + s_h0 + s_cx + s_cv * w
    if not minimiser:
        return G, mag
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.clip(np.where(e_hi > e_lo, e_lo / (e_lo - e_hi), 0.0), 0.0, 1.0)
    s = np.where(e_lo > 0, 0.0, np.where(e_hi < 0, 1.0, s))
    tau_w = np.clip(t_lo + s * (t_hi - t_lo), t_lo, t_hi)
    h_w = np.clip(h_at_max + s * (h_at_min - h_at_max), h_lo, h_hi)
    if d_hi > d_lo:
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            d_in = np.clip((crit - phi) / w, d_lo, d_hi)
    else:
        d_in = np.full(np.shape(t_a), d_lo)
    d_w = np.where(inside, d_in, np.where(t_a <= t_b, d_lo, d_hi))
    return G, tau_w, d_w, h_w, mag


def robust_margin(
    omega: npt.ArrayLike, k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: Any, delta: Any, headway: Any,
) -> Array:
    """min over the box of g(ω) (:func:`stringstab.certify.frequency.margin_g`), exactly.

    Parameters
    ----------
    omega : array_like
        Frequencies ω ≥ 0, rad/s, broadcast against the gains.
    k_x, k_v, k_a : array_like
        Gains.
    tau, delta, headway : float, (lo, hi) or "LO:HI"
        The box of lag τ, delay δ and headway T*, s; a plain number is a point interval.

    Returns
    -------
    ndarray
        min over the box of g(ω), of the broadcast shape of ``omega`` and the gains.

    Examples
    --------
    >>> from stringstab.certify.frequency import margin_g
    >>> w = np.array([0.5, 2.0])
    >>> G = robust_margin(w, 1.2, 0.5, 0.6, tau=(0.1, 0.3), delta=0.2, headway=1.1)
    >>> bool(np.all(G <= margin_g(w, 1.2, 0.5, 0.6, tau=0.2, delta=0.2, headway=1.1)))
    True
    """
    box = check_box(tau, delta, headway)
    w = np.asarray(omega, dtype=float)
    kx, kv, ka = as_gains(k_x, k_v, k_a)
    return box_margin(w, kx, kv, ka, box)[0]


def _corner_values(kx: Array, kv: Array, ka: Array, box: Box) -> tuple[Array, Array]:
    """(min a, max |a|) over the box; a = 1 − 2τ(k_v + T*k_x) − k_a² is bilinear."""
    vals = [1.0 - 2.0 * t * (kv + h * kx) - ka * ka for t in box.tau for h in box.headway]
    return np.minimum.reduce(vals), np.maximum.reduce([np.abs(v) for v in vals])


def certify_box_continuous(kx: Array, kv: Array, ka: Array, box: Box, *, n_grid: int,
                           max_rounds: int, max_intervals: int) -> dict[str, Array]:
    """The robust certificate of the continuous loop over a box, for a chunk of gain triples.

    The branch and bound on G(ω) = min_box g(ω) (:func:`box_margin`) with a curvature bound
    and a tail bound that hold for every member (module docstring); the worst member for
    internal stability is (τ_hi, T*_lo).

    Parameters
    ----------
    kx, kv, ka : ndarray, shape (n,)
        The gains (validated, finite).
    box : Box
        τ, δ, T* intervals (validated).
    n_grid, max_rounds, max_intervals : int
        Branch-and-bound budgets: initial intervals, refinement rounds, undecided
        intervals per triple.

    Returns
    -------
    dict of str to ndarray
        ``verdict`` (codes of :mod:`stringstab.certify.verdicts`), ``stable``, ``margin``,
        the witness member (``tau``, ``tau_prev``, ``delta``, ``headway``) and frequency
        (``omega``; ``theta`` NaN), ``n_evals``, ``sup_gain`` and ``sup_gain_excess``.
    """
    n = kx.size
    (t_lo, t_hi), (d_lo, d_hi), (h_lo, h_hi) = box.tau, box.delta, box.headway
    # internal stability: the worst member is (τ_hi, h_lo) (module docstring)
    sure, fail = hurwitz_bands_kernel(kx, kv, tau=t_hi, headway=h_lo)
    a_min, a_absmax = _corner_values(kx, kv, ka, box)
    c_lo = np.minimum(kv + h_lo * kx, kv + h_hi * kx)
    c_hi = np.maximum(kv + h_lo * kx, kv + h_hi * kx)
    c2_min = np.where((c_lo <= 0) & (c_hi >= 0), 0.0, np.minimum(c_lo * c_lo, c_hi * c_hi))
    b_min = c2_min - 2.0 * kx - kv * kv
    cx, cv = 2.0 * kx * ka, 2.0 * kv * ka
    Om = tail_bound(np.full(n, t_lo * t_lo), a_min, b_min, cx, cv)

    def col(v: Array, idx: npt.NDArray[np.intp]) -> Array:
        return v[idx][:, None]

    def evaluate(idx: npt.NDArray[np.intp], X: Array) -> tuple[Array, Array, Array, Array]:
        # in blocks of rows that stay in cache (the same numbers as all at once)
        G, mag = np.empty(X.shape), np.empty(X.shape)
        step = max(1, 32_768 // X.shape[1])
        for s in range(0, X.shape[0], step):
            q, i = slice(s, s + step), idx[s:s + step]
            G[q], mag[q] = box_margin(X[q], col(kx, i), col(kv, i), col(ka, i), box,
                                      minimiser=False)
        # M ≥ |g''| of every member: the bound of stringstab.certify.margin with its largest
        # coefficients (t2 at τ_hi, |a| over the box; b does not enter) and δ_hi
        M = curvature_bound(X[:, 1:], (t_hi * t_hi, col(a_absmax, idx), 0.0, col(cx, idx),
                                       col(cv, idx)), d_hi)
        return G, G, ROUNDOFF_SLACK * mag, M

    bb = branch_and_bound(n, evaluate, right=Om, n_grid=n_grid, max_rounds=max_rounds,
                          max_intervals=max_intervals, refine=~fail)
    v = verdict_codes(bb.status)
    v[~sure] = np.where(fail[~sure], NOT_CERTIFIED, INCONCLUSIVE)
    w = bb.argmin
    _, tw, dw, hw, _ = box_margin(w, kx, kv, ka, box)
    out = {
        "verdict": v, "stable": sure, "margin": bb.minimum, "omega": w,
        "theta": np.full(n, np.nan), "tau": tw, "tau_prev": tw.copy(), "delta": dw,
        "headway": hw, "n_evals": bb.n_evals,
    }
    unstable = fail & ~sure
    out["tau"] = np.where(unstable, t_hi, tw)
    out["headway"] = np.where(unstable, h_lo, hw)
    out["delta"] = np.where(unstable, d_lo, dw)
    out["omega"] = np.where(unstable, np.nan, w)
    # a box its own members prove not string stable is not certified (issue 29, item 7)
    rows = np.flatnonzero(v == INCONCLUSIVE)
    if rows.size:
        ev = _own_evidence(kx[rows], kv[rows], ka[rows], box,
                           (out["tau"][rows], out["delta"][rows], out["headway"][rows]))
        r, e = rows[ev["bad"]], ev["bad"]
        v[r] = NOT_CERTIFIED
        for key in ("tau", "delta", "headway", "omega", "margin"):
            out[key][r] = ev[key][e]
        unstable[r] = ev["unstable"][e]
        w = w.copy()
        w[r] = np.where(ev["unstable"][e], w[r], ev["omega"][e])
    out["tau_prev"] = out["tau"].copy()
    sup = np.where(v == CERTIFIED, 1.0, np.where(unstable, np.inf, np.nan))
    need = np.flatnonzero(np.isnan(sup))
    if need.size:
        sup[need], out["omega"][need] = _member_peak_continuous(
            kx[need], kv[need], ka[need], out["tau"][need], out["delta"][need],
            out["headway"][need], w[need])
    out["sup_gain_excess"] = sup - 1.0
    small = np.flatnonzero((v == NOT_CERTIFIED) & sure & (sup - 1.0 < EXCESS_SEARCH))
    if small.size:
        t, d, h = (out[k][small] for k in ("tau", "delta", "headway"))
        co = margin_g_coefficients(kx[small], kv[small], ka[small], tau=t, delta=d, headway=h)
        Om = tail_bound(*(np.broadcast_to(np.asarray(c, float), small.shape) for c in co))
        e2, we = violation_peak(kx[small], kv[small], ka[small], t, d, h, Om,
                                np.stack([out["omega"][small], w[small]], axis=1))
        e1, take = searched_excess(e2, out["sup_gain_excess"][small])
        out["sup_gain_excess"][small] = np.where(take, e1, out["sup_gain_excess"][small])
        out["omega"][small] = np.where(take, we, out["omega"][small])
        sup[small] = np.where(take, 1.0 + e1, sup[small])
    out["sup_gain"] = sup
    return out


def _own_evidence(kx: Array, kv: Array, ka: Array, box: Box,
                  witness: tuple[Array, Array, Array]) -> dict[str, Array]:
    """The point certificate (:func:`stringstab.certify.continuous.check_kernel`) at members.

    The members: the 8 corners of the box and each row's witness (τ, δ, T*).  Returns, per
    row, whether some member is not certified and that member (the one with the smallest
    margin when there are several): τ, δ, T*, its witness ω (NaN when Γ is not internally
    stable there), its margin and whether it is unstable.
    """
    n = kx.size
    corners = [(t, d, h) for t in sorted(set(box.tau)) for d in sorted(set(box.delta))
               for h in sorted(set(box.headway))]
    k = len(corners) + 1
    M = np.empty((n, k, 3))
    M[:, :-1] = np.array(corners)
    M[:, -1] = np.stack(witness, axis=1)
    verdict = np.empty((n, k), dtype=object)
    margin, omega, stable = np.full((n, k), np.inf), np.full((n, k), np.nan), np.ones((n, k), bool)

    def run(i: npt.NDArray[np.intp], j: int, p: Params) -> None:
        c = check_kernel(kx[i], kv[i], ka[i], p)
        verdict[i, j], margin[i, j], omega[i, j], stable[i, j] = (c.verdict, c.margin,
                                                                  c.witness_omega, c.hurwitz)

    for col_, (t, d, h) in enumerate(corners):
        run(np.arange(n), col_, Params(t, d, h))
    for row in range(n):
        if np.all(np.isfinite(M[row, -1])):
            run(np.array([row]), k - 1, Params(*M[row, -1]))
    bad = verdict == Verdict.NOT_CERTIFIED.value
    j = np.where(bad, margin, np.inf).argmin(axis=1)
    i = np.arange(n)
    unstable = ~stable[i, j]
    return {"bad": bad.any(axis=1), "tau": M[i, j, 0], "delta": M[i, j, 1],
            "headway": M[i, j, 2], "omega": np.where(unstable, np.nan, omega[i, j]),
            "margin": margin[i, j], "unstable": unstable}


def _member_peak_continuous(kx: Array, kv: Array, ka: Array, t: Array, d: Array, h: Array,
                            w0: Array) -> tuple[Array, Array]:
    """sup_ω |Γ(jω)| of each witness member (its own parameters) and where (reporting).

    As the point certificate's peak: a grid of :data:`PEAK_GRID` points on [0, Ω] (Ω the
    member's tail bound), the member's resonances (:func:`~.frequency.resonances`) and the
    box search's frequency ``w0``, the best refined by :func:`~.branch_bound.zoom_max`.  It
    never decides a verdict.
    """
    co = margin_g_coefficients(kx, kv, ka, tau=t, delta=d, headway=h)
    Om = tail_bound(*(np.broadcast_to(np.asarray(c, float), kx.shape) for c in co))
    p0, p1, p2, _ = (np.broadcast_to(np.asarray(v, float), kx.shape)
                     for v in _gen.denominator_abs2_coefficients(kx, kv, ka, t, d, h))
    W = np.concatenate([Om[:, None] * np.linspace(0.0, 1.0, PEAK_GRID)[None, :],
                        resonances(p0, p1, p2), w0[:, None]], axis=1)

    def g2(x: Array) -> Array:
        v = gain_squared(x, kx[:, None], kv[:, None], ka[:, None], tau=t[:, None],
                         delta=d[:, None], headway=h[:, None])
        return np.where(np.isnan(v), np.inf, v)

    # the grid in blocks of rows that stay in cache (the same numbers as all at once)
    A = np.empty(W.shape)
    step = max(1, 32_768 // W.shape[1])
    for s in range(0, kx.size, step):
        q = slice(s, s + step)
        v = gain_squared(W[q], kx[q, None], kv[q, None], ka[q, None], tau=t[q, None],
                         delta=d[q, None], headway=h[q, None])
        A[q] = np.where(np.isnan(v), np.inf, v)
    j = np.argmax(A, axis=1)
    rows = np.arange(kx.size)
    best, bw = zoom_max(g2, W[rows, j], A[rows, j], Om / (PEAK_GRID - 1), rounds=10)
    return np.sqrt(best), bw
