"""sup |H(e^{jθ})| − 1 of the sampled loop without cancellation, and where it is attained.

The sampled twin of :mod:`stringstab.certify.excess`, for reporting: the peak of |H| on
[0, π] (:func:`peak_gain`: a grid, the branch and bound's witness and the angles of the
poles of Δ(z), each refined by zooming) and, for a not-certified row whose violation is
tiny, |H|² − 1 written as −ρ g_H/(κ² φ1p² |Δ|²) with g_H evaluated from its coefficients
(:func:`excess_squared`, searched by :func:`violation_peak`), which keeps the sign and the
digits of a violation of 10⁻²⁰ near θ = 0 that |H|² computed directly rounds to 1.  Used
by :mod:`stringstab.certify.sampled` and, at the witness member of a box,
:mod:`stringstab.certify.robust_sampled`; no verdict depends on it.

References
----------
:mod:`stringstab.certify.sampled_frequency` (g_H and H on the unit circle).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from .branch_bound import zoom_max
from .interval import Interval
from .sampled_frequency import margin_bound, response
from .schur import pole_angles
from .zoh import Coefficients

__all__ = ["excess_squared", "peak_gain", "violation_peak"]

Array = npt.NDArray[np.float64]


def peak_gain(co: Coefficients, m: int, ka: Array, W: Array, worst: Array) -> tuple[Array, Array]:
    """sup_θ |H(e^{jθ})| on [0, π] and where (reporting only; the verdict never uses it).

    The largest |H| on the grid ``W`` and at ``worst`` is refined by zooming, and so is the
    largest at the angles of the poles of Δ(z); the larger of the two is kept.

    Parameters
    ----------
    co : Coefficients
        Point coefficients, n rows.
    m : int
        Whole samples of delay.
    ka : ndarray, shape (n,)
        k_a of each row.
    W : ndarray, shape (n, k)
        A uniform grid on [0, π] (the branch and bound's initial grid), starting at θ = 0.
    worst : ndarray, shape (n,)
        One more candidate per row (the branch and bound's witness).

    Returns
    -------
    (ndarray, ndarray)
        sup |H| and the θ where it is attained, rad/sample.
    """
    n = ka.size
    rows = np.arange(n)
    Wall = np.concatenate([W, worst[:, None]], axis=1)

    # the coefficients as columns, once (every call of absH reads the same ones)
    cols = Coefficients(
        [Interval(d.lo[:, None]) for d in co.delta],
        [Interval(d.lo[:, None]) for d in co.nu],
        [Interval(d.lo[:, None]) for d in co.ell], Interval(co.phi1.lo[:, None]),
        Interval(co.phi1p.lo[:, None]), co.P, co.Yr, co.Yi)
    kac = ka[:, None]

    def absH(th: Array) -> Array:
        a = np.abs(response(th, cols, m, kac))
        return np.where(np.isnan(a), np.inf, a)

    A = absH(Wall)
    A[:, 0] = np.where(co.delta[0].lo != 0, 1.0, A[:, 0])  # H(1) = 1 exactly
    half = np.full(n, np.pi / (W.shape[1] - 1))
    j = np.argmax(A, axis=1)
    best, where = zoom_max(absH, Wall[rows, j], A[rows, j], half, hi=np.pi)
    # A lightly damped pole of the loop (radius near 1) makes a resonance narrower than the
    # grid, which can sit between two grid points below another local maximum: zoom also
    # from the angles of the poles of Δ(z), and keep the larger peak.
    P = pole_angles([d.lo for d in co.delta])
    Ap = absH(P)
    k = np.argmax(Ap, axis=1)
    pb, pw = zoom_max(absH, P[rows, k], Ap[rows, k], half, hi=np.pi)
    take = pb > best
    return np.where(take, pb, best), np.where(take, pw, where)


def excess_squared(theta: Array, co: Coefficients, m: int, kappa: Array) -> Array:
    """|H(e^{jθ})|² − 1 = −ρ g_H(θ) / (κ² φ1p² |Δ(w)|²), without the cancellation of |H|² − 1.

    From the margin's definition (:mod:`stringstab.certify.sampled_frequency`) with
    κ = τ τ_p/H³:
    φ1p²|Δ|² − φ1²|n + z^{−(m+1)} k_a w² ℓ|² = ρ g_H/κ², divided by φ1p²|Δ|².  g_H is
    evaluated from its polynomial coefficients, so an excess of 10⁻²⁰ near θ = 0 (a DC
    margin just below 0), which |H|² computed directly rounds to exactly 1, keeps its sign
    and digits.

    Parameters
    ----------
    theta : ndarray, shape (n, k)
        θ, rad/sample.
    co : Coefficients
        Point coefficients, one row per triple.
    m : int
        Whole samples of delay.
    kappa : ndarray, shape (n,)
        κ = τ τ_p/H³ of each row.

    Returns
    -------
    ndarray, shape (n, k)
        |H(e^{jθ})|² − 1 (``inf`` where Δ(e^{jθ}) = 0).
    """
    g, _ = margin_bound(theta, co, np.full(co.P[0].lo.size, float(m)))
    s2 = np.sin(0.5 * theta)
    rho = 4.0 * s2 * s2
    w = 2j * s2 * np.exp(0.5j * theta)
    d0, d1, d2 = (x.lo[:, None] for x in co.delta)
    D = ((w + d2) * w + d1) * w + d0
    den = (kappa * co.phi1p.lo)[:, None] ** 2 * (D.real * D.real + D.imag * D.imag)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        out = -rho * g / den
    return np.asarray(np.where(den > 0, out, np.inf))


def violation_peak(co: Coefficients, m: int, kappa: Array, cand: Array) -> tuple[Array, Array]:
    """max over θ ∈ (0, π] of |H(e^{jθ})|² − 1 (:func:`excess_squared`) and where.

    For not-certified Schur rows: a logarithmic grid θ = π·10^u, u ∈ [−12, 0] (a violation
    from a DC margin just below 0 sits near θ → 0 and can be 10⁻²⁰), the candidates ``cand``
    (the peak of :func:`peak_gain` and the branch and bound's witness), then a refinement
    in log θ.  Reporting only: the verdict is the branch and bound's.

    Parameters
    ----------
    co : Coefficients
        Point coefficients, n rows.
    m : int
        Whole samples of delay.
    kappa : ndarray, shape (n,)
        κ = τ τ_p/H³ of each row.
    cand : ndarray, shape (n, k)
        Candidate θ of each row, rad/sample.

    Returns
    -------
    (ndarray, ndarray)
        The largest |H|² − 1 found and its θ, per row.
    """
    n = kappa.size
    rows = np.arange(n)
    u = np.linspace(-12.0, 0.0, 241)
    T = np.concatenate([np.broadcast_to(np.pi * 10.0 ** u, (n, u.size)), cand], axis=1)
    E = excess_squared(T, co, m, kappa)
    E = np.where(np.isnan(E) | (T <= 0), -np.inf, E)
    j = np.argmax(E, axis=1)
    best_t, best = T[rows, j], E[rows, j]
    step = np.full(n, 0.05)  # in log10(θ)
    v = np.linspace(-1.0, 1.0, 9)
    for _ in range(12):
        Tl = np.minimum(best_t[:, None] * 10.0 ** (step[:, None] * v[None, :]), np.pi)
        El = excess_squared(Tl, co, m, kappa)
        El = np.where(np.isnan(El), -np.inf, El)
        k = np.argmax(El, axis=1)
        better = El[rows, k] > best
        best = np.where(better, El[rows, k], best)
        best_t = np.where(better, Tl[rows, k], best_t)
        step = step / 3.0
    return best, best_t
