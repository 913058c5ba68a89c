r"""Sound certificates of the sampled-data loop with a reaction delay θ_r > 0 (issue 25 item 3).

The loop (docs/sampled.md, §10): zero-order hold and radar every H, lag τ, the predecessor's
acceleration a_{i−1}(kH − δ) exact for any δ, and the command computed at step k applied
θ_r = (q + f)H later — two held pieces per step, q + [f > 0] held-input states per vehicle,
exact (:mod:`stringstab.certify.lifting_reaction`).  The predecessor has the same θ_r (a
homogeneous platoon; its lag may differ).  θ_r = 0 is not answered here: the sampled
certificate (:mod:`stringstab.certify.sampled`) answers it, unchanged.

**The decision.**  ``certified`` means: the follower's block of the state matrix (3 + L
states, L = q + [f > 0]) is proven Schur by the Stein inertia theorem
(:func:`stringstab.certify.stein.stein_schur`) — so the link's state matrix is (block
triangular; the predecessor's states are a stable lag and nilpotent shifts) — and
λ_min(M(θ)) ≥ 0 on [0, π], M the tangency-free margin of
:mod:`stringstab.certify.lifted_frequency` at N = 1 (a positive multiple of 1 − |H(e^{jθ})|²
for θ ≠ 0), decided by the one branch and bound (:mod:`stringstab.certify.branch_bound`)
with proven slacks and curvature bounds (:func:`stringstab.certify.multirate.decide_lifted`).
Then sup_θ |H(e^{jθ})| = |H(1)| = 1.  ``not_certified``: a proven eigenvalue of modulus > 1,
or a θ with λ_min(M(θ)) < −slack (|H(e^{jθ})| > 1).  ``inconclusive``: neither.  The
reported peak (``sup_gain``, ``peak_theta``) is located on a grid and zoomed on |Ĥ|, and
never enters a verdict; ``margin`` is the smallest λ_min(M̂(θ)) found (not the g_H of the
sampled rows: another positive multiple of the same sign).

References
----------
docs/sampled.md §10; IDL paper, eqs 3-9 and eq 4.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..params import Params
from .branch_bound import zoom_max
from .lifting import LiftedLink, lifted_response
from .lifting_reaction import follower_block, held_steps, lift_reaction
from .multirate import decide_lifted
from .sampled import SampledCertificateBatch, SampledCheck
from .stein import stein_schur
from .verdicts import CERTIFIED, NOT_CERTIFIED, chunks, names

__all__ = ["GRID", "certify_kernel", "check_kernel", "decide"]

Array = npt.NDArray[np.float64]


#: Initial intervals on [0, π] of the first look (the second pass sizes its own grid from
#: the resolvent bounds, as the multi-rate certificate does).
GRID = 32


def decide(kx: Array, kv: Array, ka: Array, p: Params, H: float, tp: float, *,
           n_grid: int | None = None, max_rounds: int = 30, max_intervals: int = 1024,
           ) -> tuple[npt.NDArray[np.int8], npt.NDArray[np.bool_], Array, Array,
                      npt.NDArray[np.int64], Array, LiftedLink, Array]:
    """The sound decision for many gain triples (module docstring).

    Parameters
    ----------
    kx, kv, ka : ndarray
        The gains (checked), one triple per row.
    p : Params
        τ, δ, T*, θ_r > 0.
    H : float
        The control and radar period, s.
    tp : float
        The predecessor's lag τ_p, s.
    n_grid, max_rounds, max_intervals : int
        Initial intervals on [0, π] (default :data:`GRID`), refinement rounds, and the cap
        on undecided intervals per triple.

    Returns
    -------
    tuple
        Verdict codes, ``sure`` (proven Schur), the margin and where (θ, rad/sample), points
        evaluated, the initial grid, the link, and the spectral radius of the computed
        follower block (reporting).
    """
    _, _, L = held_steps(p.reaction_delay, H)
    link = lift_reaction(kx, kv, ka, p, H, 1, tp)
    Af = follower_block(link, L)
    sure, fail = stein_schur(Af)
    verdict, margin, argmin, n_evals, grid = decide_lifted(
        link, sure, fail, n_grid=n_grid or GRID, max_rounds=max_rounds,
        max_intervals=max_intervals)
    with np.errstate(invalid="ignore"):
        rho = np.array([np.abs(np.linalg.eigvals(a)).max() if np.all(np.isfinite(a)) else np.nan
                        for a in Af.mid])
    return verdict, sure, margin, argmin, n_evals, grid, link, rho


def _peak(link: LiftedLink, grid: Array, worst: Array) -> tuple[Array, Array]:
    """sup_θ |Ĥ(e^{jθ})| and where: the grid and the witness, refined by zooming (reporting)."""
    cand = np.concatenate([grid, worst[:, None]], axis=1)
    best = np.empty(cand.shape[0])
    where = np.empty(cand.shape[0])
    for s in range(0, cand.shape[0], 256):
        sl = slice(s, s + 256)
        sub = link.take(np.arange(cand.shape[0])[sl])

        def gain(th: Array, sub: LiftedLink = sub) -> Array:
            g = np.abs(lifted_response(sub, th)[..., 0, 0])
            return np.asarray(np.where(np.isfinite(g), g, np.inf))  # a pole on the circle

        S = gain(cand[sl])
        j = np.argmax(S, axis=1)
        rows = np.arange(S.shape[0])
        b, x = zoom_max(gain, cand[sl][rows, j], S[rows, j],
                        np.full(S.shape[0], np.pi / cand.shape[1]), lo=0.0, hi=np.pi)
        best[sl], where[sl] = b, x
    return best, where


def check_kernel(kx: Array, kv: Array, ka: Array, p: Params, H: float, tp: float, *,
                 n_grid: int | None = None, max_rounds: int = 30,
                 max_intervals: int = 1024) -> SampledCheck:
    """The verdicts alone (inputs checked by :func:`stringstab.certify.check`).

    Parameters
    ----------
    kx, kv, ka : ndarray of float64
        The gains, finite, one-dimensional, of one length.
    p : Params
        τ, δ, T*, θ_r > 0.
    H : float
        The sample time, s.
    tp : float
        The predecessor's lag, s.
    n_grid, max_rounds, max_intervals : int
        As for :func:`decide`.

    Returns
    -------
    SampledCheck
        ``margin`` is the smallest λ_min(M̂(θ)) found, ``witness_theta`` where.
    """
    v, sure, margin, argmin, *_ = decide(kx, kv, ka, p, H, tp, n_grid=n_grid,
                                         max_rounds=max_rounds, max_intervals=max_intervals)
    return SampledCheck(names(v), sure, margin, argmin / H, sample_time=H, witness_theta=argmin)


def certify_kernel(
    kx: Array, kv: Array, ka: Array, p: Params, H: float, tp: float, *, chunk: int = 1024,
    n_grid: int | None = None, max_rounds: int = 30, max_intervals: int = 1024,
    progress: bool = False,
) -> SampledCertificateBatch:
    """The sampled certificates with θ_r > 0 of many triples (rows as the sampled ones).

    Parameters
    ----------
    kx, kv, ka : ndarray of float64
        The gains, finite, one-dimensional, of one length.
    p : Params
        τ, δ, T*, θ_r > 0.
    H : float
        The sample time, s.
    tp : float
        The predecessor's lag, s.
    chunk, n_grid, max_rounds, max_intervals, progress
        Triples per chunk, and as for :func:`decide`; a tqdm bar over chunks.

    Returns
    -------
    SampledCertificateBatch
        ``margin`` is λ_min(M̂) (module docstring); ``sup_gain_excess`` is sup|Ĥ| − 1 from
        the search (0 when certified, ``inf`` when not proven Schur).

    Examples
    --------
    >>> b = certify_kernel(np.array([0.2]), np.array([0.6]), np.array([0.0]),
    ...                    Params(0.5, 0.0, 1.5, reaction_delay=0.15), 0.1, 0.5)
    >>> b.verdict.tolist(), bool(b.schur[0])
    (['certified'], True)
    """
    n = kx.size
    verdict = np.empty(n, dtype=np.int8)
    margin = np.empty(n)
    n_evals = np.empty(n, dtype=np.int64)
    sup = np.ones(n)
    peak = np.zeros(n)
    sure = np.empty(n, dtype=bool)
    rad = np.empty(n)
    for sl in chunks(n, chunk, progress=progress, desc="certify (sampled, θ_r)"):
        v, s_sure, mg, am, ne, grid, link, rho = decide(
            kx[sl], kv[sl], ka[sl], p, H, tp, n_grid=n_grid, max_rounds=max_rounds,
            max_intervals=max_intervals)
        verdict[sl], margin[sl], n_evals[sl], sure[sl], rad[sl] = v, mg, ne, s_sure, rho
        need = np.flatnonzero(v != CERTIFIED)
        if need.size:
            s_, w_ = _peak(link.take(need), grid[need], am[need])
            sup[sl][need], peak[sl][need] = s_, w_
    excess = np.where(verdict == CERTIFIED, 0.0, sup - 1.0)
    excess = np.where((verdict == NOT_CERTIFIED) & sure, np.maximum(excess, 0.0), excess)
    return SampledCertificateBatch(
        k_x=kx, k_v=kv, k_a=ka, params=p, sample_time=H, tau_prev=tp, schur=sure,
        spectral_radius=rad, verdict=names(verdict), sup_gain=np.where(sure, sup, np.inf),
        linf_gain=sup, peak_theta=peak, peak_omega=peak / H, margin=margin, n_evals=n_evals,
        sup_gain_excess=np.where(sure, excess, np.inf))
