r"""The continuous-time certificate with a reaction delay θ_r > 0: sound, exact in both delays.

With the whole command delayed by θ_r (issue 25; :mod:`stringstab.derive.reaction`),

.. math::
    Γ(s) = \frac{e^{−θ_r s}(k_x + k_v s + k_a s^2 e^{−δs})}
                {τs^3 + s^2 + e^{−θ_r s}((k_v + T^*k_x)s + k_x)} ,

and a triple is ``certified`` when both are proven:

1. **internal stability**: the quasi-polynomial denominator has no root in Re s ≥ 0 — the
   exact root count of :mod:`stringstab.certify.quasipolynomial` (argument principle on the
   imaginary axis, Stépán's formula) is 0;
2. **‖Γ‖_H∞ ≤ 1**: g_θ(ω) = (|D(jω)|² − |N(jω)|²)/ω² ≥ 0 for every ω ≥ 0, by the one branch
   and bound (:mod:`stringstab.certify.branch_bound`) on the bounds of
   :mod:`stringstab.certify.margin_reaction` (a proven tail, a proven curvature bound, the same
   round-off slack rule).

``not_certified`` when either fails provably: N ≥ 1 roots in Re s > 0 (or k_x ≤ 0: a root at
0 or a real one in (0, ∞)), or some ω with g_θ(ω) < −slack (then |Γ(jω)| > 1, so ‖Γ‖∞ ≥
|Γ(jω)| > 1 whether or not Γ is stable).  Otherwise ``inconclusive``, within a stated
distance of a boundary: the smallest |D(jω)| met (a root near the axis) or the smallest g_θ
found (|Γ| = 1 touched).  The ``reason`` column says which, in words.

θ_r = 0 never comes here: :mod:`stringstab.certify.continuous` certifies it with today's code,
bit for bit.  Boxes with θ_r (a point θ_r > 0 or an interval) are certified by
:mod:`stringstab.certify.robust_reaction`; the sampled certificates refuse θ_r > 0 so far.

References
----------
Issue 25; IDL paper, Definition 1 (eq 10); G. Stépán, *Retarded Dynamical Systems*, 1989.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..derive import generated as _gen
from ..params import Params
from . import margin_reaction as _mr
from .branch_bound import BranchAndBound, branch_and_bound, verdict_codes, zoom_max
from .criteria import (
    TYPE_NAMES,
    TaylorCriteria,
    proposition1,
    stability_type,
    taylor_criteria_kernel,
)
from .excess import EXCESS_SEARCH, col, searched_excess
from .quasipolynomial import RootCount, count_unstable_roots, denominator_at
from .reaction_results import ReactionCertificateBatch, reasons
from .rightmost import rightmost_root
from .verdicts import CERTIFIED, INCONCLUSIVE, NOT_CERTIFIED, Check, chunks, names

__all__ = [
    "approximation_verdicts",
    "certify_kernel",
    "check_kernel",
    "excess_squared",
    "gain_squared",
    "taylor_criteria",
]

Array = npt.NDArray[np.float64]


def gain_squared(omega: npt.ArrayLike, kx: npt.ArrayLike, kv: npt.ArrayLike, ka: npt.ArrayLike,
                 *, tau: npt.ArrayLike, delta: npt.ArrayLike, headway: npt.ArrayLike,
                 reaction_delay: npt.ArrayLike) -> Array:
    """|Γ(jω)|² = |N(jω)|²/|D(jω)|² with the reaction delay, ``inf`` where D(jω) = 0.

    Parameters
    ----------
    omega : array_like
        Frequencies, rad/s.
    kx, kv, ka : array_like
        Gains.
    tau, delta, headway, reaction_delay : array_like
        τ, δ, T*, θ_r (s).

    Returns
    -------
    ndarray
        |Γ(jω)|², broadcast (generated: ``reaction_gamma_parts``).

    Examples
    --------
    >>> from stringstab.certify.frequency import gain_squared as g0
    >>> bool(np.isclose(gain_squared(1.0, 0.9, -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1,
    ...                              reaction_delay=0.0),
    ...                 g0(1.0, 0.9, -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1)))
    True
    """
    nr, ni, dr, di = _gen.reaction_gamma_parts(omega, kx, kv, ka, tau, delta, headway,
                                               reaction_delay)
    num, den = nr * nr + ni * ni, dr * dr + di * di
    with np.errstate(divide="ignore", invalid="ignore"):
        out = num / den
    return np.asarray(np.where(den > 0, out, np.inf))


def excess_squared(omega: Array, kx: Array, kv: Array, ka: Array, tau: float, delta: float,
                   headway: float, theta: float) -> Array:
    """|Γ(jω)|² − 1 = −ω² g_θ(ω)/|D(jω)|², without cancellation (``inf`` where D(jω) = 0).

    As :func:`stringstab.certify.excess.excess_squared`, with the reaction delay: keeps its
    sign and digits for an excess of 10⁻²⁰ (Ψ3 just below 0).

    Parameters
    ----------
    omega : ndarray
        Frequencies, rad/s (broadcast against the gains).
    kx, kv, ka : ndarray
        Gains.
    tau, delta, headway, theta : float
        τ, δ, T*, θ_r (s).

    Returns
    -------
    ndarray
        |Γ(jω)|² − 1.
    """
    gv = _mr.g(omega, kx, kv, ka, tau=tau, delta=delta, headway=headway, reaction_delay=theta)
    D, _ = denominator_at(omega, kx, kv, tau, headway, theta)
    d2 = D.real * D.real + D.imag * D.imag
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        out = -(omega * omega) * gv / d2
    return np.asarray(np.where(d2 > 0, out, np.inf))


def taylor_criteria(kx: Array, kv: Array, ka: Array, p: Params) -> TaylorCriteria:
    """Proposition 1 (corrected logic) on Ψ1-Ψ3 *with* θ_r (``taylor_derived`` when θ_r > 0).

    Ψ are the ω⁴, ω², ω⁰ coefficients of g_θ (generated: ``psi_reaction``; Ψ3 does not depend
    on θ_r).  A truncated series, never a verdict (as at θ_r = 0).

    Parameters
    ----------
    kx, kv, ka : ndarray
        Gains.
    p : Params
        τ, δ, T*, θ_r.

    Returns
    -------
    TaylorCriteria
        ``source="derived"``.
    """
    p1, p2, p3 = (np.broadcast_to(np.asarray(v, dtype=float), kx.shape) for v in _gen.psi_reaction(
        kx, kv, ka, p.tau, p.delta, p.headway, p.reaction_delay))
    lam = p2 * p2 - 4.0 * p1 * p3
    return TaylorCriteria("derived", p1, p2, p3, lam, proposition1(p1, p2, p3, lam),
                          stability_type(p2, p3, lam))


def approximation_verdicts(kx: Array, kv: Array, p: Params) -> dict[str, npt.NDArray[np.bool_]]:
    """What the Taylor route concludes about internal stability: e^{−θ_r s} ≈ 1 − θ_r s or Padé(1,1).

    The approximated denominator is a cubic (``taylor1``) or a quartic (``pade11``) whose
    Hurwitz determinants (derived: :func:`stringstab.derive.reaction.approximate_hurwitz`;
    generated) are all > 0.  Not a certificate: the exact answer is the root count of the
    quasi-polynomial (:mod:`stringstab.certify.quasipolynomial`); docs/theory.md lists triples
    where they differ.

    Parameters
    ----------
    kx, kv : ndarray
        Gains k_x, k_v.
    p : Params
        τ, δ, T*, θ_r.

    Returns
    -------
    dict of str to ndarray of bool
        ``{"taylor1": ..., "pade11": ...}``: True where the approximation says stable.

    Examples
    --------
    >>> v = approximation_verdicts(np.array([1.56]), np.array([-1.03]),
    ...                            Params(0.1, 0.2, 1.1, reaction_delay=0.3))
    >>> bool(v["taylor1"][0]), bool(v["pade11"][0])  # both wrong: 2 roots in Re s > 0
    (True, True)
    """
    out = {}
    args = (kx, kv, 0.0, p.tau, p.delta, p.headway, p.reaction_delay)
    for kind, fn in (("taylor1", _gen.reaction_taylor1_hurwitz),
                     ("pade11", _gen.reaction_pade11_hurwitz)):
        ok = np.ones(kx.shape, dtype=bool)
        for cond in fn(*args):
            ok &= np.asarray(cond) > 0
        out[kind] = ok
    return out


# ---------------------------------------------------------------------------
# The two proofs, and the verdict
# ---------------------------------------------------------------------------
def _margin_bb(kx: Array, kv: Array, ka: Array, p: Params, *, n_grid: int, max_rounds: int,
               max_intervals: int, refine: npt.NDArray[np.bool_] | None) -> tuple[BranchAndBound, Array]:
    """The branch and bound of g_θ ≥ 0 on [0, Ω] (Ω the proven tail) and Ω."""
    Q = _mr.coefficient_table(kx, kv, ka, p.tau, p.delta, p.headway, p.reaction_delay)
    Om = _mr.tail_bound(Q)

    def evaluate(idx: npt.NDArray[np.intp], X: Array) -> tuple[Array, Array, Array, Array]:
        Qt = Q[:, idx, None]
        G, E = _mr.g_and_slack(X, Qt)
        return G, G, E, _mr.curvature_bound(X[:, 1:], Qt)

    bb = branch_and_bound(kx.size, evaluate, right=Om, n_grid=n_grid, max_rounds=max_rounds,
                          max_intervals=max_intervals, refine=refine)
    return bb, Om


def _decide(kx: Array, kv: Array, ka: Array, p: Params, *, n_grid: int, max_rounds: int,
            max_intervals: int) -> tuple[npt.NDArray[np.int8], RootCount, BranchAndBound, Array]:
    """Root count, then the margin's branch and bound (not refined where proven unstable)."""
    rc = count_unstable_roots(kx, kv, p.tau, p.headway, p.reaction_delay, max_rounds=max_rounds + 10,
                              max_intervals=4 * max_intervals)
    bb, Om = _margin_bb(kx, kv, ka, p, n_grid=n_grid, max_rounds=max_rounds,
                        max_intervals=max_intervals, refine=~rc.unstable)
    m = verdict_codes(bb.status)
    v = np.full(kx.size, INCONCLUSIVE, dtype=np.int8)
    v[rc.stable & (m == CERTIFIED)] = CERTIFIED
    v[rc.unstable | (m == NOT_CERTIFIED)] = NOT_CERTIFIED
    return v, rc, bb, Om


def check_kernel(kx: Array, kv: Array, ka: Array, p: Params, *, n_grid: int = 64,
                 max_rounds: int = 30, max_intervals: int = 1024) -> Check:
    """The verdicts alone with θ_r > 0 (the kernel of :func:`stringstab.certify.check`).

    Inputs already checked by the way in (:mod:`stringstab.certify.api`).

    Parameters
    ----------
    kx, kv, ka : ndarray of float64
        The gains, finite, one-dimensional, of one length.
    p : Params
        τ, δ, T* and θ_r > 0 (checked on construction).
    n_grid, max_rounds, max_intervals : int
        As for :func:`certify_kernel`.

    Returns
    -------
    Check
        Verdicts, internal stability (proven), min g_θ found and where.
    """
    v, rc, bb, _ = _decide(kx, kv, ka, p, n_grid=n_grid, max_rounds=max_rounds,
                           max_intervals=max_intervals)
    return Check(names(v), rc.stable, bb.minimum, bb.argmin)


# ---------------------------------------------------------------------------
# Reporting: the peak, the excess, the rightmost root (no verdict depends on them)
# ---------------------------------------------------------------------------
def _peak(kx: Array, kv: Array, ka: Array, p: Params, Om: Array, W: Array, G: Array,
          worst: Array) -> tuple[Array, Array]:
    """sup_ω |Γ(jω)| on [0, Ω] and where: the branch and bound's grid, its witness, refined."""
    th = p.reaction_delay
    D, _ = denominator_at(W, col(kx), col(kv), p.tau, p.headway, th)
    d2 = D.real * D.real + D.imag * D.imag
    with np.errstate(divide="ignore", invalid="ignore"):
        G2 = np.where(d2 > 0, 1.0 - W * W * G / d2, np.inf)
    G2[:, 0] = np.where(kx != 0, 1.0, np.inf)  # Γ(0) = k_x/k_x

    def f(Wl: Array) -> Array:
        return gain_squared(Wl, col(kx), col(kv), col(ka), tau=p.tau, delta=p.delta,
                            headway=p.headway, reaction_delay=th)

    Wall = np.concatenate([W, worst[:, None]], axis=1)
    Gall = np.concatenate([G2, f(worst[:, None])], axis=1)
    Gall = np.where(np.isnan(Gall), np.inf, Gall)
    rows = np.arange(kx.size)
    j = np.argmax(Gall, axis=1)
    best, best_w = zoom_max(f, Wall[rows, j], Gall[rows, j], Om / (W.shape[1] - 1))
    return np.sqrt(best), best_w


def _violation_peak(kx: Array, kv: Array, ka: Array, p: Params, Om: Array,
                    cand: Array) -> tuple[Array, Array]:
    """max |Γ(jω)|² − 1 (cancellation-free) and where: a log grid down to 10⁻¹² Ω, refined."""
    n = kx.size
    rows = np.arange(n)
    args = (p.tau, p.delta, p.headway, p.reaction_delay)
    _p1, p2, p3 = (np.broadcast_to(np.asarray(v, float), (n,))
                   for v in _gen.psi_reaction(kx, kv, ka, *args))
    with np.errstate(divide="ignore", invalid="ignore"):
        w_small = np.where((p3 < 0) & (p2 > 0), np.sqrt(-p3 / (2.0 * p2)), 0.0)
    u = np.linspace(-12.0, 0.0, 241)
    W = np.concatenate([col(np.maximum(Om, 1.0)) * 10.0 ** u[None, :], cand, col(w_small)], axis=1)
    E = excess_squared(W, col(kx), col(kv), col(ka), *args)
    E = np.where(np.isnan(E) | (W <= 0), -np.inf, E)
    j = np.argmax(E, axis=1)
    best_w, best = W[rows, j], E[rows, j]
    step = np.full(n, 0.05)
    v = np.linspace(-1.0, 1.0, 9)
    for _ in range(12):
        Wl = best_w[:, None] * 10.0 ** (step[:, None] * v[None, :])
        El = excess_squared(Wl, col(kx), col(kv), col(ka), *args)
        El = np.where(np.isnan(El), -np.inf, El)
        k = np.argmax(El, axis=1)
        better = El[rows, k] > best
        best = np.where(better, El[rows, k], best)
        best_w = np.where(better, Wl[rows, k], best_w)
        step = step / 3.0
    return best, best_w


def _hurwitz_margin(kx: Array, kv: Array, p: Params, rc: RootCount) -> Array:
    """−Re of the estimated rightmost root, shown only where its sign agrees with the proof.

    Proven stable ⇒ shown when > 0; proven unstable or undecided ⇒ shown when ≤ 0; NaN
    otherwise (the estimate contradicts the proof, or no Newton start converged).
    """
    s = rightmost_root(kx, kv, p.tau, p.headway, p.reaction_delay, extra=rc.real_root)
    hm = -s.real
    with np.errstate(invalid="ignore"):
        return np.where(rc.stable, np.where(hm > 0, hm, np.nan), np.where(hm <= 0, hm, np.nan))


def certify_kernel(
    kx: Array, kv: Array, ka: Array, p: Params, *, progress: bool = False, chunk: int = 4096,
    n_grid: int = 64, max_rounds: int = 30, max_intervals: int = 1024,
) -> ReactionCertificateBatch:
    """The continuous-time certificates with θ_r > 0 of many triples (module docstring).

    Inputs already checked by :func:`stringstab.certify.certify_batch` (the way in).

    Parameters
    ----------
    kx, kv, ka : ndarray of float64
        The gains, finite, one-dimensional, of one length.
    p : Params
        τ, δ, T* and θ_r > 0.
    progress : bool
        Show a tqdm progress bar over chunks.
    chunk : int
        Triples per vectorised chunk (bounds memory).
    n_grid, max_rounds, max_intervals : int
        Initial intervals on [0, Ω], refinement rounds, and the cap on undecided intervals
        per triple (the root count gets 10 more rounds and 4× the intervals).

    Returns
    -------
    ReactionCertificateBatch
        The columns of :class:`stringstab.certify.continuous.CertificateBatch` plus
        ``reaction_delay``, ``unstable_roots`` and ``reason``.
    """
    n = kx.size
    verdict = np.empty(n, dtype=np.int8)
    margin, omega_max, worst_w = np.empty(n), np.empty(n), np.empty(n)
    n_evals = np.empty(n, dtype=np.int64)
    sup, peak_w = np.ones(n), np.zeros(n)
    stable, unstable, violated = (np.empty(n, dtype=bool) for _ in range(3))
    roots, min_abs, min_w, real = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    hmargin = np.empty(n)
    for sl in chunks(n, chunk, progress=progress):
        k3 = kx[sl], kv[sl], ka[sl]
        v, rc, bb, Om = _decide(*k3, p, n_grid=n_grid, max_rounds=max_rounds,
                                max_intervals=max_intervals)
        verdict[sl], margin[sl], omega_max[sl], worst_w[sl] = v, bb.minimum, Om, bb.argmin
        n_evals[sl] = bb.n_evals + rc.n_evals
        stable[sl], unstable[sl] = rc.stable, rc.unstable
        violated[sl] = verdict_codes(bb.status) == NOT_CERTIFIED  # g_θ < −slack: proven
        roots[sl] = np.where(rc.unstable_roots >= 0, rc.unstable_roots, np.nan)
        min_abs[sl], min_w[sl], real[sl] = rc.min_abs, rc.min_omega, rc.real_root
        hmargin[sl] = _hurwitz_margin(kx[sl], kv[sl], p, rc)
        need = v != CERTIFIED
        if need.any():
            idx = np.arange(sl.start, sl.stop)[need]
            sup[idx], peak_w[idx] = _peak(kx[idx], kv[idx], ka[idx], p, Om[need],
                                          bb.grid_x[need], bb.grid_f[need], bb.argmin[need])
    cert = verdict == CERTIFIED
    sup[cert] = np.maximum(sup[cert], 1.0)
    excess = np.where(cert, 0.0, sup - 1.0)
    # proven |Γ(jω)| > 1 (g_θ < −slack) where stability is proven or undecided: the excess at
    # the witness without cancellation (a finite number, also where stability is undecided)
    viol = np.flatnonzero(violated & ~unstable & (excess < EXCESS_SEARCH))
    if viol.size:
        e2, w_e = _violation_peak(kx[viol], kv[viol], ka[viol], p, omega_max[viol],
                                  np.stack([peak_w[viol], worst_w[viol]], axis=1))
        e1, take = searched_excess(e2, excess[viol])
        excess[viol] = np.where(take, e1, excess[viol])
        peak_w[viol] = np.where(take, w_e, peak_w[viol])
        sup[viol] = np.where(take, 1.0 + e1, sup[viol])
    excess = np.where(stable | (~unstable & violated), excess, np.inf)
    td = taylor_criteria(kx, kv, ka, p)
    tp = taylor_criteria_kernel(kx, kv, ka, tau=p.tau, delta=p.delta, headway=p.headway,
                                source="printed")
    return ReactionCertificateBatch(
        k_x=kx, k_v=kv, k_a=ka, params=p, hurwitz=stable, hurwitz_margin=hmargin,
        verdict=names(verdict),
        type=np.array([TYPE_NAMES[int(t)] for t in td.type]) if n else np.array([], dtype=str),
        sup_gain=np.where(stable, sup, np.inf), linf_gain=sup, peak_omega=peak_w, margin=margin,
        omega_max=omega_max, n_evals=n_evals, taylor_derived=td, taylor_printed=tp,
        sup_gain_excess=excess, unstable_roots=roots,
        reason=reasons(verdict, unstable, violated, roots, real, min_abs, min_w, margin, worst_w),
    )
