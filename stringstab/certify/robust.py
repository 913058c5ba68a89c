"""Robust string-stability certificates over boxes of uncertain lag, delay and headway.

A gain triple is *robustly certified* for the box τ ∈ [τ_lo, τ_hi], δ ∈ [δ_lo, δ_hi],
T* ∈ [h_lo, h_hi] (any of them may be a point) when the certificate of
:mod:`stringstab.certify.continuous` (continuous time) or :mod:`stringstab.certify.sampled` (sampled
data, period H) holds for *every* member of the box.  Since a vehicle's transfer function
depends only on its own τ, δ, T* (and, sampled, its predecessor's lag), a certificate
over the box covers a heterogeneous platoon whose vehicles each lie in it: every
|Γ_i(jω)| ≤ 1, so the product along the platoon is ≤ 1 too.

**Continuous time** (exact in the parameters).  The margin of
:func:`stringstab.certify.frequency.margin_g` separates:

.. math::
    g(ω) = (τω^2 - c)^2 + (1 - k_a^2)ω^2 - 2k_x - k_v^2
           + 2k_xk_a\\cos δω - 2k_vk_a ω \\sin δω,\\qquad c = k_v + T^*k_x ,

so at each ω the minimum over the box is a closed form (:func:`robust_margin`):
e = τω² − k_v − T*k_x is affine in (τ, T*), its range over the box is
[τ_lo ω² − k_v − max T*k_x, τ_hi ω² − k_v − min T*k_x] and min e² is 0 or the square
of the end nearer 0; and 2k_xk_a cos ψ − 2k_vk_aω sin ψ = R cos(ψ + φ) over
ψ = δω ∈ [δ_lo ω, δ_hi ω] is −R if the shifted range contains an odd multiple of π,
else the smaller end value.  The minimiser (τ*, δ*, T*) is the witness.

The branch and bound of :mod:`stringstab.certify.branch_bound` then runs on
G(ω) = min_box g(ω): for every member, g ≥ min(g(l), g(r)) − M h²/8 ≥
min(G(l), G(r)) − M h²/8 on [l, r] when M bounds |g''| *uniformly over the box*
(the certificate's bound at τ_hi, δ_hi and the largest |a| over the corners, a being
bilinear in τ and T*).  The tail bound of :func:`stringstab.certify.continuous.tail_bound` is
taken with the box's worst coefficients (τ_lo² for τ², the smallest a and b), which
bounds every member's g from below.  Internal stability over the box: with k_x > 0,
the Hurwitz condition k_v + (T* − τ)k_x > 0 increases with T* and decreases with τ, so
the worst member is (τ_hi, h_lo); with k_x ≤ 0 no member is stable.

**Sampled data.**  g_H of :func:`stringstab.certify.sampled.sampled_margin` has no closed-form
minimum over the box, so the branch and bound also splits the parameters: each item is
a cell (τ, τ_p, ε, T* intervals) whose coefficients are enclosed by interval arithmetic
with a round-off companion; a frequency interval where the cell's width, not the
curvature, prevents a decision is handed back and the cell is bisected.  The delay
enters as z^{−(m+1)} with m = ⌊δ/H⌋, so the δ interval is split at the multiples of H
and each piece is a fractional-delay interval ε ∈ [ε_lo, ε_hi] ⊂ [0, 1] (continuous at
the joins: ε = 1 at m equals ε = 0 at m + 1).  The predecessor's lag τ_p ranges over the
τ box independently (``heterogeneous=True``) or equals τ.  Schur stability over
(τ, T*) is decided by a two-dimensional bisection on the interval-evaluated Schur
conditions.

Verdicts: ``certified`` (proven for the whole box), ``not_certified`` (a member that is
not internally stable, or a member and a frequency with |Γ| > 1: the witness),
``inconclusive`` (neither within the budget).

References
----------
IDL paper, Definition 1 (eq 10) and eq 11 (derived form).
R. E. Moore, R. B. Kearfott, M. J. Cloud, *Introduction to Interval Analysis*, SIAM (2009).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt

from ..io import TableColumn
from ..params import Box, Interval, as_gains, as_interval, check_box, parse_interval
from ..params import sample_time as _sample_time
from .branch_bound import CERTIFIED, PENDING, VIOLATED, branch_and_bound, verdict_codes, zoom_max
from .criteria import hurwitz_bands
from .excess import EXCESS_SEARCH
from .excess import violation_peak as _violation_peak_continuous
from .frequency import gain_squared, margin_g_coefficients
from .margin import curvature_bound, separable, tail_bound
from .sampled import (
    _Ad,
    _cell_coefficients,
    _coefficients,
    _Coeffs,
    _curvature,
    _eval_cells,
    _part,
    _peak,
    _schur_terms,
    _spread,
    _violation_peak,
    split_delay,
)
from .verdicts import CERTIFIED as CERTIFIED_CODE
from .verdicts import (
    INCONCLUSIVE,
    NOT_CERTIFIED,
    ROUNDOFF_SLACK,
    ROW_COLUMNS,
    BatchResult,
    Check,
    SingleResult,
    chunks,
    names,
    one_triple,
)

__all__ = [
    "TABLE_COLUMNS",
    "Box",
    "Interval",
    "RobustCertificate",
    "RobustCertificateBatch",
    "as_interval",
    "certify_robust",
    "certify_robust_batch",
    "check_box",
    "check_robust",
    "parse_interval",
    "robust_margin",
]

Array = npt.NDArray[np.float64]
_CERT, _NOT, _INC = CERTIFIED_CODE, NOT_CERTIFIED, INCONCLUSIVE
_SLACK = ROUNDOFF_SLACK
_SCHUR_RTOL = 1e-12


# ---------------------------------------------------------------------------
# Continuous time: the exact minimum of g over the box at each ω
# ---------------------------------------------------------------------------
def _robust_g(
    w: Array, kx: Array, kv: Array, ka: Array, box: Box,
) -> tuple[Array, Array, Array, Array, Array]:
    """(min_box g(ω), τ*, δ*, T*, magnitude) at ω ≥ 0; gains broadcast against ω.

    g = (τω² − c)² + h2 ω² + h0 + cx cos δω − cv ω sin δω
    (:func:`stringstab.certify.margin.separable`, generated from the derivation): only the square
    depends on τ and T* (c = k_v + T*k_x is affine in T*), only the trigonometric terms on δ.
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
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.clip(np.where(e_hi > e_lo, e_lo / (e_lo - e_hi), 0.0), 0.0, 1.0)
    s = np.where(e_lo > 0, 0.0, np.where(e_hi < 0, 1.0, s))
    tau_w = np.clip(t_lo + s * (t_hi - t_lo), t_lo, t_hi)
    h_w = np.clip(h_at_max + s * (h_at_min - h_at_max), h_lo, h_hi)
    r0 = h2 * w2 + h0

    def trig(d: float) -> Array:
        return np.asarray(cx * np.cos(d * w) - cv * w * np.sin(d * w))

    t_a, t_b = trig(d_lo), trig(d_hi)
    R = np.hypot(cx, cv * w)
    phi = np.arctan2(cv * w, cx)
    a = d_lo * w + phi
    b = d_hi * w + phi
    k = np.ceil((a - np.pi) / (2.0 * np.pi))
    crit = np.pi + 2.0 * np.pi * k
    inside = (crit <= b + 1e-12 * (1.0 + np.abs(b))) & (d_hi > d_lo) & (w > 0)
    T = np.where(inside, -R, np.minimum(t_a, t_b))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        d_in = np.clip((crit - phi) / w, d_lo, d_hi)
    d_w = np.where(inside, d_in, np.where(t_a <= t_b, d_lo, d_hi))
    G = S + r0 + T
    e_mag = t_hi * w2 + np.maximum(s_ca, s_cb)
    mag = e_mag * e_mag + s_h2 * w2 + s_h0 + s_cx + s_cv * w
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
        The box (module docstring).

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
    return _robust_g(w, kx, kv, ka, box)[0]


def _corner_values(kx: Array, kv: Array, ka: Array, box: Box) -> tuple[Array, Array]:
    """(min a, max |a|) over the box; a = 1 − 2τ(k_v + T*k_x) − k_a² is bilinear."""
    vals = [1.0 - 2.0 * t * (kv + h * kx) - ka * ka for t in box.tau for h in box.headway]
    return np.minimum.reduce(vals), np.maximum.reduce([np.abs(v) for v in vals])


def _robust_continuous(kx: Array, kv: Array, ka: Array, box: Box, *, n_grid: int,
                       max_rounds: int, max_intervals: int) -> dict[str, Array]:
    n = kx.size
    (t_lo, t_hi), (d_lo, d_hi), (h_lo, h_hi) = box.tau, box.delta, box.headway
    # internal stability: the worst member is (τ_hi, h_lo) (module docstring)
    sure, fail = hurwitz_bands(kx, kv, tau=t_hi, headway=h_lo)
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
        G, _, _, _, mag = _robust_g(X, col(kx, idx), col(kv, idx), col(ka, idx), box)
        # M ≥ |g''| of every member: the bound of stringstab.certify.margin with its largest
        # coefficients (t2 at τ_hi, |a| over the box; b does not enter) and δ_hi
        M = curvature_bound(X[:, 1:], (t_hi * t_hi, col(a_absmax, idx), 0.0, col(cx, idx),
                                       col(cv, idx)), d_hi)
        return G, G, _SLACK * mag, M

    bb = branch_and_bound(n, evaluate, right=Om, n_grid=n_grid, max_rounds=max_rounds,
                          max_intervals=max_intervals, refine=~fail)
    v = verdict_codes(bb.status)
    v[~sure] = np.where(fail[~sure], _NOT, _INC)
    w = bb.argmin
    _, tw, dw, hw, _ = _robust_g(w, kx, kv, ka, box)
    out = {
        "verdict": v, "stable": sure, "margin": bb.minimum, "omega": w,
        "theta": np.full(n, np.nan), "tau": tw, "tau_prev": tw.copy(), "delta": dw,
        "headway": hw, "n_evals": bb.n_evals,
    }
    unstable = fail & ~sure
    out["tau"] = np.where(unstable, t_hi, tw)
    out["tau_prev"] = out["tau"].copy()
    out["headway"] = np.where(unstable, h_lo, hw)
    out["delta"] = np.where(unstable, d_lo, dw)
    out["omega"] = np.where(unstable, np.nan, w)
    sup = np.where(v == _CERT, 1.0, np.where(unstable, np.inf, np.nan))
    need = np.flatnonzero(np.isnan(sup))
    if need.size:
        sup[need], out["omega"][need] = _member_peak_continuous(
            kx[need], kv[need], ka[need], out["tau"][need], out["delta"][need],
            out["headway"][need], w[need])
    out["sup_gain_excess"] = sup - 1.0
    small = np.flatnonzero((v == _NOT) & sure & (sup - 1.0 < EXCESS_SEARCH))
    if small.size:
        t, d, h = (out[k][small] for k in ("tau", "delta", "headway"))
        co = margin_g_coefficients(kx[small], kv[small], ka[small], tau=t, delta=d, headway=h)
        Om = tail_bound(*(np.broadcast_to(np.asarray(c, float), small.shape) for c in co))
        e2, we = _violation_peak_continuous(kx[small], kv[small], ka[small], t, d, h, Om,
                                 np.stack([out["omega"][small], w[small]], axis=1))
        _take_excess(out, sup, small, e2, we, "omega")
    out["sup_gain"] = sup
    return out


def _take_excess(out: dict[str, Any], sup: Array, rows: npt.NDArray[np.intp], e2: Array, at: Array,
                 key: str) -> None:
    """Report sup gain − 1 from |Γ|² − 1 (or |H|² − 1) searched without cancellation.

    The search's candidates include the direct peak, so its value replaces the direct
    gain − 1 (whose last bits are round-off at this size) unless it found nothing above 1.
    """
    e1 = e2 / (1.0 + np.sqrt(1.0 + np.maximum(e2, 0.0)))  # sup gain − 1
    ex = out["sup_gain_excess"]
    take = (e1 > 0) | (e1 >= ex[rows])
    ex[rows] = np.where(take, e1, ex[rows])
    out[key][rows] = np.where(take, at, out[key][rows])
    sup[rows] = np.where(take, 1.0 + e1, sup[rows])


def _member_peak_continuous(kx: Array, kv: Array, ka: Array, t: Array, d: Array, h: Array,
                            w0: Array) -> tuple[Array, Array]:
    """sup_ω |Γ(jω)| of each witness member (its own parameters) and where (reporting)."""
    co = margin_g_coefficients(kx, kv, ka, tau=t, delta=d, headway=h)
    Om = tail_bound(*(np.broadcast_to(np.asarray(c, float), kx.shape) for c in co))
    W = np.concatenate([Om[:, None] * np.linspace(0.0, 1.0, 513)[None, :], w0[:, None]], axis=1)

    def g2(x: Array) -> Array:
        v = gain_squared(x, kx[:, None], kv[:, None], ka[:, None], tau=t[:, None],
                         delta=d[:, None], headway=h[:, None])
        return np.where(np.isnan(v), np.inf, v)

    A = g2(W)
    j = np.argmax(A, axis=1)
    rows = np.arange(kx.size)
    best, bw = zoom_max(g2, W[rows, j], A[rows, j], Om / 512.0, rounds=10)
    return np.sqrt(best), bw


# ---------------------------------------------------------------------------
# Sampled data: bisection of parameter cells
# ---------------------------------------------------------------------------
@dataclass
class _Cells:
    owner: npt.NDArray[np.intp]
    m: Array
    t: Array  # (n, 2) τ interval
    tp: Array  # (n, 2) τ_p interval
    e: Array  # (n, 2) ε interval
    h: Array  # (n, 2) T* interval

    def __len__(self) -> int:
        return int(self.owner.size)

    def take(self, idx: npt.NDArray[np.intp]) -> _Cells:
        return _Cells(self.owner[idx], self.m[idx], self.t[idx], self.tp[idx], self.e[idx],
                      self.h[idx])

    @staticmethod
    def cat(parts: list[_Cells]) -> _Cells:
        return _Cells(*(np.concatenate([getattr(p, f) for p in parts])
                        for f in ("owner", "m", "t", "tp", "e", "h")))


def _delay_pieces(d_lo: float, d_hi: float, H: float) -> list[tuple[int, float, float]]:
    """(m, ε_lo, ε_hi) pieces covering δ ∈ [d_lo, d_hi] (ends widened by a few ulps)."""
    m_lo, e_lo = split_delay(d_lo, H, whole=False)  # the box's ends exactly: it covers them
    if d_hi == d_lo:
        return [(m_lo, e_lo, e_lo)]
    m_hi, e_hi = split_delay(d_hi, H, whole=False)
    tol = 8.0 * np.finfo(float).eps * (m_hi + 1.0)
    out = []
    for mm in range(m_lo, m_hi + 1):
        lo = e_lo if mm == m_lo else 0.0
        hi = e_hi if mm == m_hi else 1.0
        if mm == m_hi and hi == 0.0 and mm > m_lo:
            continue  # δ_hi on a multiple of H: the previous piece's ε = 1
        out.append((mm, max(lo - tol, 0.0), min(hi + tol, 1.0)))
    return out


def _cell_coeffs(kx: Array, kv: Array, ka: Array, c: _Cells, H: float,
                 heterogeneous: bool) -> Any:
    o = c.owner
    return _cell_coefficients(kx[o], kv[o], ka[o], H=H, tau=c.t,
                              tau_p=c.tp if heterogeneous else None, eps=c.e, headway=c.h)


def _take_cells(co: _Coeffs, idx: npt.NDArray[np.intp]) -> _Coeffs:
    def t(v: _Ad) -> _Ad:
        def s(x: Any) -> Any:
            lo = x.lo[idx]
            return type(x)(lo, None, x.mag[idx]) if x.point else type(x)(lo, x.hi[idx], x.mag[idx])

        return _Ad(s(v.c), s(v.r), tuple(s(g) for g in v.g))

    return _part(co, t)  # type: ignore[arg-type]


def _halfwidths(c: _Cells, heterogeneous: bool) -> Array:
    cols = [c.t] + ([c.tp] if heterogeneous else []) + [c.e, c.h]
    return np.stack([0.5 * (x[:, 1] - x[:, 0]) for x in cols], axis=1)


def _dims(heterogeneous: bool) -> list[str]:
    """The cell fields in the order of :func:`stringstab.certify.sampled._cell_coefficients`."""
    return ["t", "tp", "e", "h"] if heterogeneous else ["t", "e", "h"]


def _bisect(c: _Cells, dim: npt.NDArray[np.intp], heterogeneous: bool) -> tuple[_Cells, Array]:
    """Split cell j in half along dimension ``dim[j]``; returns the children and parents."""
    names = _dims(heterogeneous)
    lo, hi = c.take(np.arange(len(c))), c.take(np.arange(len(c)))
    for k, name in enumerate(names):
        sel = dim == k
        if not sel.any():
            continue
        x = getattr(c, name)
        mid = 0.5 * (x[sel, 0] + x[sel, 1])
        a, b = getattr(lo, name), getattr(hi, name)
        a[sel, 1] = mid
        b[sel, 0] = mid
    if not heterogeneous:
        lo.tp, hi.tp = lo.t.copy(), hi.t.copy()
    parent = np.concatenate([np.arange(len(c)), np.arange(len(c))])
    return _Cells.cat([lo, hi]), parent


def _schur_box(kx: Array, kv: Array, box: Box, H: float, max_depth: int = 14) -> tuple[
        npt.NDArray[np.bool_], npt.NDArray[np.bool_], Array, Array]:
    """Schur stability of Δ over (τ, T*) ∈ box by bisection: (sure, fail, witness τ, T*).

    A cell is Schur when every condition's lower bound (natural interval extension or
    mean-value form, whichever is larger) exceeds a relative 10⁻¹² band; a condition
    below −band at a cell's centre is a witness member that is not Schur.
    """
    n = kx.size
    owner = np.arange(n)
    t = np.tile(np.array(box.tau, dtype=float), (n, 1))
    h = np.tile(np.array(box.headway, dtype=float), (n, 1))
    fail = np.zeros(n, dtype=bool)
    undecided = np.zeros(n, dtype=bool)
    wt = np.full(n, np.nan)
    wh = np.full(n, np.nan)
    for depth in range(max_depth + 1):
        if owner.size == 0:
            break
        z2 = np.zeros((owner.size, 2))
        co = _cell_coefficients(kx[owner], kv[owner], np.zeros(owner.size), H=H, tau=t,
                                tau_p=None, eps=z2, headway=h)
        hw = np.stack([0.5 * (t[:, 1] - t[:, 0]), np.zeros(owner.size),
                       0.5 * (h[:, 1] - h[:, 0])], axis=1)
        ok = np.ones(owner.size, dtype=bool)
        bad = np.zeros(owner.size, dtype=bool)
        term: Any
        for term in _schur_terms(co.delta):
            spread = sum((np.maximum(np.abs(g.lo), np.abs(g.hi)) + _SLACK * g.mag) * hw[:, i]
                         for i, g in enumerate(term.g))
            low = np.maximum(term.r.lo, term.c.lo - spread)
            ok &= low > _SCHUR_RTOL * term.r.mag
            bad |= term.c.lo <= -_SCHUR_RTOL * term.c.mag
        if bad.any():
            b_own = owner[bad]
            new = ~fail[b_own]
            fail[b_own] = True
            wt[b_own[new]] = t[bad][new].mean(axis=1)
            wh[b_own[new]] = h[bad][new].mean(axis=1)
        rest = ~ok & ~fail[owner]
        if not rest.any():
            break
        if depth == max_depth:
            undecided[np.unique(owner[rest])] = True
            break
        owner, t, h = owner[rest], t[rest], h[rest]
        tm, hm = t.mean(axis=1), h.mean(axis=1)
        t_wide, h_wide = t[:, 1] > t[:, 0], h[:, 1] > h[:, 0]
        parts = []
        for tl, tr in ((t[:, 0], tm), (tm, t[:, 1])):
            for hl, hr in ((h[:, 0], hm), (hm, h[:, 1])):
                parts.append((np.stack([tl, tr], 1), np.stack([hl, hr], 1)))
        # keep a half only along a dimension that has width
        sel = [np.ones(owner.size, bool), h_wide, t_wide, t_wide & h_wide]
        owner = np.concatenate([owner[k] for k in sel])
        t = np.concatenate([p[0][k] for p, k in zip(parts, sel)])
        h = np.concatenate([p[1][k] for p, k in zip(parts, sel)])
    sure = ~fail & ~undecided
    return sure, fail, wt, wh


def _robust_sampled(kx: Array, kv: Array, ka: Array, box: Box, H: float, *, heterogeneous: bool,
                    n_grid: int | None, max_rounds: int, max_intervals: int, max_splits: int,
                    max_cells: int) -> dict[str, Array]:
    n = kx.size
    sure, fail, wt, wh = _schur_box(kx, kv, box, H)
    pieces = _delay_pieces(*box.delta, H)
    live0 = np.flatnonzero(~fail)  # an undecided Schur band still looks for a witness
    tau2 = np.array(box.tau, dtype=float)
    cells = _Cells.cat([
        _Cells(live0, np.full(live0.size, float(mm)), np.tile(tau2, (live0.size, 1)),
               np.tile(tau2, (live0.size, 1)), np.tile(np.array([e0, e1]), (live0.size, 1)),
               np.tile(np.array(box.headway, dtype=float), (live0.size, 1)))
        for mm, e0, e1 in pieces])
    grid = n_grid or (64 + 8 * max(p[0] for p in pieces))
    status = np.full(n, _CERT, dtype=np.int8)
    status[~sure] = np.where(fail[~sure], _NOT, _INC)
    active = ~fail
    margin = np.full(n, np.inf)
    wit = {k: np.full(n, np.nan) for k in ("theta", "m", "t", "tp", "e", "h")}
    n_evals = np.zeros(n, dtype=np.int64)
    n_cells = np.bincount(cells.owner, minlength=n)
    intervals: tuple[npt.NDArray[np.intp], Array, Array] | None = None
    for split_round in range(max_splits + 1):
        if len(cells) == 0:
            break
        co = _cell_coeffs(kx, kv, ka, cells, H, heterogeneous)
        hw_c = _halfwidths(cells, heterogeneous)
        wide = ((cells.t[:, 1] > cells.t[:, 0]) | (cells.tp[:, 1] > cells.tp[:, 0])
                | (cells.e[:, 1] > cells.e[:, 0]) | (cells.h[:, 1] > cells.h[:, 0]))
        can_split = wide & (split_round < max_splits)
        m_c = cells.m

        def evaluate(idx: npt.NDArray[np.intp], X: Array, co: Any = co, hw_c: Array = hw_c,
                     m_c: Array = m_c) -> tuple[Array, Array, Array, Array]:
            sub = _take_cells(co, idx)
            G, low, E = _eval_cells(X, sub, m_c[idx], hw_c[idx])
            M = _curvature(_part(sub, lambda v: v.r), m_c[idx], X[:, :-1], X[:, 1:])
            return G, np.minimum(low, G), E, M

        def hold(idx: npt.NDArray[np.intp], L: Array, R: Array, low_gap: Array, curv: Array,
                 can_split: npt.NDArray[np.bool_] = can_split) -> npt.NDArray[np.bool_]:
            # the cell's width, not the frequency interval, prevents a decision: bisect it
            return np.asarray(can_split[idx] & (low_gap > curv))

        if intervals is None:
            bb = branch_and_bound(len(cells), evaluate, right=np.full(len(cells), np.pi),
                                  n_grid=grid, max_rounds=max_rounds,
                                  max_intervals=max_intervals, hold=hold)
        else:
            bb = branch_and_bound(len(cells), evaluate, intervals=intervals,
                                  max_rounds=max_rounds, max_intervals=max_intervals, hold=hold)
        np.add.at(n_evals, cells.owner, bb.n_evals)
        # the smallest point value per triple, and the member where it was found
        order = np.lexsort((bb.minimum, cells.owner))
        own, first = np.unique(cells.owner[order], return_index=True)
        best = order[first]
        upd = bb.minimum[best] < margin[own]
        o, b = own[upd], best[upd]
        margin[o] = bb.minimum[b]
        wit["theta"][o] = bb.argmin[b]
        wit["m"][o] = cells.m[b]
        for k in ("t", "tp", "e", "h"):
            wit[k][o] = getattr(cells, k)[b].mean(axis=1)
        viol = np.unique(cells.owner[bb.status == VIOLATED])
        status[viol] = _NOT
        active[viol] = False
        inc = np.unique(cells.owner[np.isin(bb.status, (CERTIFIED, VIOLATED, PENDING),
                                            invert=True)])
        inc = inc[status[inc] != _NOT]
        status[inc] = _INC
        active[inc] = False
        # hand-backs: bisect their cells; each child inherits its parent's held intervals
        pi, pl, ph = bb.pending_item, bb.pending_lo, bb.pending_hi
        sel = active[cells.owner[pi]]
        pi, pl, ph = pi[sel], pl[sel], ph[sel]
        if pi.size == 0:
            break
        ucell, inv = np.unique(pi, return_inverse=True)
        # bisect each cell along the parameter that widens its bound most where it failed
        Xp = np.stack([pl, ph], axis=1)
        sp = _spread(Xp, _take_cells(co, pi), cells.m[pi], hw_c[pi]).max(axis=1)  # (k, d)
        worst_dim = np.zeros((ucell.size, sp.shape[1]))
        np.maximum.at(worst_dim, inv, sp)
        kids, parent = _bisect(cells.take(ucell), np.argmax(worst_dim, axis=1), heterogeneous)
        n_cells += np.bincount(kids.owner, minlength=n)
        over = active & (n_cells > max_cells)
        status[over] = _INC
        active[over] = False
        # the held intervals of each parent, repeated for each of its children
        order = np.argsort(inv, kind="stable")
        starts = np.concatenate([[0], np.cumsum(np.bincount(inv, minlength=ucell.size))[:-1]])
        counts = np.bincount(inv, minlength=ucell.size)[parent]
        kid = np.repeat(np.arange(len(kids)), counts)
        offs = np.arange(kid.size) - np.repeat(np.cumsum(counts) - counts, counts)
        src = order[starts[parent][kid] + offs]
        live = active[kids.owner[kid]]
        cells = kids
        intervals = (kid[live].astype(np.intp), pl[src][live], ph[src][live])
    # members and frequencies of the witnesses; the unstable member when Schur fails
    tau_w = np.where(fail, wt, wit["t"])
    taup_w = np.where(fail, wt, wit["tp"])
    h_w = np.where(fail, wh, wit["h"])
    d_w = np.where(fail, box.delta[0], (wit["m"] + wit["e"]) * H)
    theta = np.where(fail, np.nan, wit["theta"])
    sup = np.where(status == _CERT, 1.0, np.where(fail, np.inf, np.nan))
    need = np.isnan(sup) & np.isfinite(tau_w)
    for mm in np.unique(wit["m"][need]):
        idx = np.flatnonzero(need & (wit["m"] == mm))
        e_i = wit["e"][idx]
        cc = kv[idx] + h_w[idx] * kx[idx]
        co = _coefficients(kx[idx], kv[idx], ka[idx], H=H, tau=(tau_w[idx], tau_w[idx]),
                           tau_p=(taup_w[idx], taup_w[idx]), eps=(e_i, e_i), c=(cc, cc))
        ng = 65 + 8 * int(mm)
        th_grid = np.broadcast_to(np.linspace(0.0, np.pi, ng), (idx.size, ng))
        sup[idx], theta[idx] = _peak(co, int(mm), ka[idx], th_grid, theta[idx])
    out = {"verdict": status, "stable": sure, "margin": margin, "theta": theta,
           "tau": tau_w, "tau_prev": taup_w, "delta": d_w, "headway": h_w,
           "n_evals": n_evals, "sup_gain_excess": sup - 1.0}
    small_ = (status == _NOT) & sure & need & (sup - 1.0 < EXCESS_SEARCH)
    for mm in np.unique(wit["m"][small_]):
        idx = np.flatnonzero(small_ & (wit["m"] == mm))
        e_i = wit["e"][idx]
        cc = kv[idx] + h_w[idx] * kx[idx]
        co = _coefficients(kx[idx], kv[idx], ka[idx], H=H, tau=(tau_w[idx], tau_w[idx]),
                           tau_p=(taup_w[idx], taup_w[idx]), eps=(e_i, e_i), c=(cc, cc))
        kappa = tau_w[idx] * taup_w[idx] / H**3
        e2, th = _violation_peak(co, int(mm), kappa, np.stack([theta[idx], wit["theta"][idx]], 1))
        _take_excess(out, sup, idx, e2, th, "theta")
    out["omega"] = out["theta"] / H
    out["sup_gain"] = sup
    return out


# ---------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class RobustCertificate(SingleResult):
    """The robust certificate of one gain triple over a parameter box.

    Attributes
    ----------
    k_x, k_v, k_a : float
        The gains.
    box : Box
        τ, δ, T* intervals.
    sample_time : float or None
        H for the sampled-data certificate; None for continuous time.
    heterogeneous : bool
        Sampled only: the predecessor's lag ranges over the τ box independently.
    stable : bool
        Every member is internally stable (Hurwitz / Schur), proven.
    verdict : str
        ``"certified"``, ``"not_certified"`` or ``"inconclusive"``.
    sup_gain : float
        1 when certified (every member's norm is exactly 1); otherwise |Γ| (or |H|) at
        the witness (a lower bound on the worst member's norm), ``inf`` when the witness
        is a member that is not internally stable.
    margin : float
        Smallest g (or g_H) found at a member (an upper bound on the box minimum).
    witness_tau, witness_tau_prev, witness_delta, witness_headway : float
        The member where it was found (or the unstable member); for a certified triple,
        the tightest member found.
    witness_omega, witness_theta : float
        Its frequency in rad/s (and in rad/sample when sampled; NaN otherwise).
    n_evals : int
        Evaluations used.
    sup_gain_excess : float
        ``sup_gain`` − 1 computed without cancellation: 0 when certified, > 0 when not
        certified and stable (also when ``sup_gain`` rounds to 1.0: the witness member's
        violation near ω → 0, the frequency then where it is attained), ``inf`` when the
        witness member is not internally stable.
    """

    k_x: float
    k_v: float
    k_a: float
    box: Box
    sample_time: float | None
    heterogeneous: bool
    stable: bool
    verdict: str
    sup_gain: float
    margin: float
    witness_tau: float
    witness_tau_prev: float
    witness_delta: float
    witness_headway: float
    witness_omega: float
    witness_theta: float
    n_evals: int = 0
    sup_gain_excess: float = float("nan")


#: The columns of the human table of robust certificates (``stringstab certify`` with an
#: interval).
TABLE_COLUMNS: list[TableColumn] = [
    *ROW_COLUMNS,
    TableColumn("stable", "stable"),
    TableColumn("verdict", "verdict"),
    TableColumn("sup gain at witness", "sup_gain", "%.6g", missing="inf"),
    TableColumn("sup gain-1", "sup_gain_excess", "%.3g", missing="inf"),
    TableColumn("ω[rad/s]", "witness.omega", "%.4g"),
    TableColumn("θ[rad/sample]", "witness.theta", "%.4g"),
    TableColumn("τ", "witness.tau", "%.4g"),
    TableColumn("τ_prev", "witness.tau_prev", "%.4g"),
    TableColumn("δ", "witness.delta", "%.4g"),
    TableColumn("T*", "witness.headway", "%.4g"),
    TableColumn("margin", "margin", "%.3g"),
]


@dataclass(frozen=True)
class RobustCertificateBatch(BatchResult):
    """Robust certificates of many triples, as arrays (fields of :class:`RobustCertificate`)."""

    SINGLE: ClassVar[type[RobustCertificate]] = RobustCertificate
    SHARED: ClassVar[tuple[str, ...]] = ("box", "sample_time", "heterogeneous")

    k_x: Array
    k_v: Array
    k_a: Array
    box: Box
    sample_time: float | None
    heterogeneous: bool
    stable: npt.NDArray[np.bool_]
    verdict: npt.NDArray[np.str_]
    sup_gain: Array
    margin: Array
    witness_tau: Array
    witness_tau_prev: Array
    witness_delta: Array
    witness_headway: Array
    witness_omega: Array
    witness_theta: Array
    n_evals: npt.NDArray[np.int64]
    sup_gain_excess: Array

    def __getitem__(self, i: int) -> RobustCertificate:
        return super().__getitem__(i)  # type: ignore[no-any-return]

    def columns(self) -> dict[str, Any]:
        """The result columns: gains, stability over the box, verdict, sup gain and margin,
        the ``witness`` group (``tau``, ``tau_prev``, ``delta``, ``headway``, ``omega``,
        ``theta``), then ``sample_time`` (NaN in continuous time), ``heterogeneous`` (sampled
        only) and the ``box`` group (``tau_lo``, ``tau_hi``, ...).

        Examples
        --------
        >>> b = certify_robust_batch([1.2], [0.5], [0.6], tau=(0.1, 0.3), delta=0.2, headway=1.1)
        >>> c = b.columns()
        >>> c["verdict"].tolist(), c["box"]["tau_hi"].tolist(), c["sample_time"].tolist()
        (['certified'], [0.3], [nan])
        """
        n = len(self)
        cols: dict[str, Any] = {
            "k_x": self.k_x, "k_v": self.k_v, "k_a": self.k_a, "stable": self.stable,
            "verdict": self.verdict, "sup_gain": self.sup_gain,
            "sup_gain_excess": self.sup_gain_excess, "margin": self.margin,
            "witness": {k: getattr(self, f"witness_{k}")
                        for k in ("tau", "tau_prev", "delta", "headway", "omega", "theta")},
            "sample_time": np.full(n, np.nan if self.sample_time is None else self.sample_time),
        }
        if self.sample_time is not None:
            cols["heterogeneous"] = np.full(n, self.heterogeneous)
        cols["box"] = self.box.columns(n)
        return cols

    def summary_extra(self) -> dict[str, Any]:
        """The sample time (None in continuous time), heterogeneity (sampled) and the box."""
        out: dict[str, Any] = {"sample_time": self.sample_time}
        if self.sample_time is not None:
            out["heterogeneous"] = self.heterogeneous
        return {**out, "box": self.box.as_dict()}


RobustCertificate.BATCH = RobustCertificateBatch


def certify_robust_batch(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: Any, delta: Any, headway: Any, sample_time: float | None = None,
    heterogeneous: bool = True, chunk: int = 4096, n_grid: int | None = None,
    max_rounds: int = 30, max_intervals: int = 1024, max_splits: int = 48,
    max_cells: int = 4096, progress: bool = False,
) -> RobustCertificateBatch:
    """Certify gain triples for every τ, δ, T* in a box (module docstring).

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains, broadcast together and flattened.
    tau, delta, headway : float, (lo, hi) or "LO:HI"
        The box; a plain number is a point interval.  τ_lo > 0, δ_lo ≥ 0, T*_lo ≥ 0.
    sample_time : float, optional
        H > 0 for the sampled-data loop; None (default) for continuous time.
    heterogeneous : bool
        Sampled only: let the predecessor's lag range over the τ box independently of the
        follower's (a platoon of different vehicles); False ties it to τ.
    chunk : int
        Triples per vectorised chunk.
    n_grid, max_rounds, max_intervals : int
        Initial frequency intervals (default 64, or 64 + 8m sampled), refinement rounds per
        pass, and undecided intervals per item before it is inconclusive.
    max_splits, max_cells : int
        Sampled only: bisection passes of the parameter cells, and cells per triple,
        before the triple is inconclusive.
    progress : bool
        Show a tqdm progress bar over chunks.

    Returns
    -------
    RobustCertificateBatch

    Raises
    ------
    StringStabError
        On a malformed box (lo > hi, a negative end, τ reaching 0), a sample time that is
        not a finite number > 0, or non-finite gains.

    Examples
    --------
    >>> b = certify_robust_batch([1.2, 0.9], [0.5, -0.5], [0.6, 1.1], tau=(0.1, 0.3),
    ...                          delta="0.1:0.3", headway=1.1)
    >>> b.verdict.tolist()
    ['certified', 'not_certified']
    >>> bool(b[1].sup_gain > 1), b[1].witness_tau >= 0.1
    (True, True)
    """
    box = check_box(tau, delta, headway)
    H = None if sample_time is None else _sample_time(sample_time)
    kx, kv, ka = (np.ascontiguousarray(v, dtype=float).ravel() for v in as_gains(k_x, k_v, k_a))
    n = kx.size
    keys = ("verdict", "stable", "margin", "theta", "omega", "tau", "tau_prev", "delta",
            "headway", "n_evals", "sup_gain", "sup_gain_excess")
    acc: dict[str, list[Array]] = {k: [] for k in keys}
    for sl in chunks(n, chunk, progress=progress, desc="certify (robust)"):
        if H is None:
            r = _robust_continuous(kx[sl], kv[sl], ka[sl], box, n_grid=n_grid or 64,
                                   max_rounds=max_rounds, max_intervals=max_intervals)
        else:
            r = _robust_sampled(kx[sl], kv[sl], ka[sl], box, H, heterogeneous=heterogeneous,
                                n_grid=n_grid, max_rounds=max_rounds,
                                max_intervals=max_intervals, max_splits=max_splits,
                                max_cells=max_cells)
        for k in keys:
            acc[k].append(np.asarray(r[k]))

    def cat(k: str, dtype: Any = float) -> Any:
        return np.concatenate(acc[k]).astype(dtype) if acc[k] else np.zeros(0, dtype=dtype)

    return RobustCertificateBatch(
        k_x=kx, k_v=kv, k_a=ka, box=box, sample_time=H, heterogeneous=bool(heterogeneous),
        stable=cat("stable", bool), verdict=names(cat("verdict", np.int8)),
        sup_gain=cat("sup_gain"), margin=cat("margin"), witness_tau=cat("tau"),
        witness_tau_prev=cat("tau_prev"), witness_delta=cat("delta"),
        witness_headway=cat("headway"), witness_omega=cat("omega"),
        witness_theta=cat("theta"), n_evals=cat("n_evals", np.int64),
        sup_gain_excess=cat("sup_gain_excess"),
    )


def certify_robust(
    k_x: float, k_v: float, k_a: float, *, tau: Any, delta: Any, headway: Any,
    sample_time: float | None = None, heterogeneous: bool = True,
) -> RobustCertificate:
    """Certify one gain triple over a parameter box (see :func:`certify_robust_batch`).

    Parameters
    ----------
    k_x, k_v, k_a : float
        One gain triple of IDL eq 4 (k_x in 1/s², k_v in 1/s, k_a dimensionless).
    tau, delta, headway : float, (lo, hi) or "LO:HI"
        The box of actuator lag τ, delay δ and desired headway T*, s; a plain number is a
        point interval.  τ_lo > 0, δ_lo ≥ 0, T*_lo ≥ 0.
    sample_time : float, optional
        H > 0, s, for the sampled-data loop; None (default) for continuous time.
    heterogeneous : bool
        Sampled only: let the predecessor's lag range over the τ box independently of the
        follower's; False ties it to τ.

    Returns
    -------
    RobustCertificate

    Raises
    ------
    StringStabError
        On a malformed box, a bad sample time or gains, or arrays instead of one triple.

    Examples
    --------
    >>> c = certify_robust(1.2, 0.5, 0.6, tau="0.1:0.2", delta="0.15:0.25", headway=1.1,
    ...                    sample_time=0.1)
    >>> c.verdict
    'certified'
    """
    one_triple("certify_robust", "certify_robust_batch", k_x=k_x, k_v=k_v, k_a=k_a)
    return certify_robust_batch([k_x], [k_v], [k_a], tau=tau, delta=delta, headway=headway,
                                sample_time=sample_time, heterogeneous=heterogeneous)[0]


def check_robust(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike, *, tau: Any, delta: Any,
    headway: Any, sample_time: float | None = None, heterogeneous: bool = True,
    n_grid: int | None = None, max_rounds: int = 30, max_intervals: int = 1024,
) -> Check:
    """The robust certificate's verdicts and witnesses, as a :class:`~stringstab.certify.verdicts.Check`.

    The decision of :func:`certify_robust_batch`; ``hurwitz`` is stability of every member,
    and the witness member (τ, τ_prev, δ, T*) and frequency (ω, and θ when sampled) of each
    triple are those of the batch.

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains of IDL eq 4 (k_x in 1/s², k_v in 1/s, k_a dimensionless), broadcast together.
    tau, delta, headway : float, (lo, hi) or "LO:HI"
        The box of actuator lag τ, delay δ and desired headway T*, s; a plain number is a
        point interval.
    sample_time : float, optional
        H > 0, s, for the sampled-data loop; None (default) for continuous time.
    heterogeneous : bool
        Sampled only: the predecessor's lag ranges over the τ box independently of the
        follower's; False ties it to τ.
    n_grid, max_rounds, max_intervals : int
        Branch-and-bound budgets, as for :func:`certify_robust_batch`.

    Returns
    -------
    Check
        Verdict, stability, margin and witness (member and frequency) of each triple.

    Raises
    ------
    StringStabError
        On a malformed box, a bad sample time or bad gains.

    Examples
    --------
    >>> c = check_robust([1.2, 0.9], [0.5, -0.5], [0.6, 1.1], tau=(0.1, 0.3), delta=0.2,
    ...                  headway=1.1)
    >>> c.verdict.tolist(), bool(0.1 <= c.witness_tau[1] <= 0.3)
    (['certified', 'not_certified'], True)
    """
    b = certify_robust_batch(k_x, k_v, k_a, tau=tau, delta=delta, headway=headway,
                             sample_time=sample_time, heterogeneous=heterogeneous, n_grid=n_grid,
                             max_rounds=max_rounds, max_intervals=max_intervals)
    return Check(b.verdict, b.stable, b.margin, b.witness_omega, sample_time=b.sample_time,
                 witness_theta=None if b.sample_time is None else b.witness_theta,
                 witness_tau=b.witness_tau, witness_tau_prev=b.witness_tau_prev,
                 witness_delta=b.witness_delta, witness_headway=b.witness_headway)
