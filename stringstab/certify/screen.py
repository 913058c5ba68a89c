"""The "surely not certifiable" screen: gains that no certificate can certify, found cheaply.

A gain triple K = (k_x, k_v, k_a) of the continuous loop (IDL eq 4) surely cannot be certified
string stable when

* Γ is not internally stable: a Hurwitz condition of τs³ + s² + (k_v + T*k_x)s + k_x fails
  (:func:`stringstab.certify.criteria.hurwitz`, strict inequalities), or
* the margin g(ω) = (|D(jω)|² − |N(jω)|²)/ω² (:func:`stringstab.certify.margin.g`) is below
  −:data:`SCREEN_RTOL` times the scale of its coefficients at some frequency ω ≥ 0: then
  |Γ(jω)| > 1 there (IDL eq 10), whatever the rounding of g.

Either is a proof that K fails, so a screen built on them is *sound*: it never drops a triple
the certificate (:func:`stringstab.certify.api.check`) would certify — a certified
triple is Hurwitz and has g(ω) ≥ 0 at every ω, up to a rounding error many orders of magnitude
below the screen's tolerance.  Which frequencies are tried is the caller's choice:
:data:`SCREEN_OMEGA` (a fixed set, vectorised over many triples: :func:`surely_uncertifiable`)
or the local minima of g found by a scan (one triple, :func:`violating_dips`, whose
frequencies then seed a repair).  The screen only saves certificate calls; it never certifies.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import numpy.typing as npt

from ..params import Params
from . import margin as _margin
from .criteria import hurwitz

__all__ = [
    "SAMPLED_SCREEN_RTOL",
    "SCREEN_OMEGA",
    "SCREEN_RTOL",
    "SampledScreen",
    "sampled_screen",
    "surely_uncertifiable",
    "violating_dips",
    "violation_threshold",
]

Array = npt.NDArray[np.float64]

#: Frequencies (rad/s) of the fixed screen: 32 on (0, 2] and 16 on [2.25, 6], where the
#: violations of gains in the Table-2 box [−2, 2]³ lie.
SCREEN_OMEGA: Array = np.concatenate([np.linspace(0.0, 2.0, 33)[1:], np.linspace(2.25, 6.0, 16)])
SCREEN_OMEGA.setflags(write=False)
#: Relative tolerance of the screen: g(ω) counts as a violation only below −SCREEN_RTOL times
#: 1 + |a| + |b| + |c_x| + |c_v| (the coefficients of g), far beyond its rounding error.
SCREEN_RTOL = 1e-9


def violation_threshold(K: npt.ArrayLike, p: Params) -> Array:
    """The value of g below which the screen counts a violation, for each row of K.

    Parameters
    ----------
    K : array_like, shape (3,) or (n, 3)
        Gains (k_x [1/s²], k_v [1/s], k_a [-]) of IDL eq 4.
    p : Params
        τ, δ, T* of the continuous loop (s).

    Returns
    -------
    ndarray, shape () or (n,)
        −:data:`SCREEN_RTOL` · (1 + |a| + |b| + |c_x| + |c_v|), the coefficients of g of
        :func:`stringstab.certify.margin.coefficients`.
    """
    K = np.asarray(K, dtype=float)
    _, a, b, cx, cv = _margin.coefficients(K[..., 0], K[..., 1], K[..., 2],
                                           tau=p.tau, delta=p.delta, headway=p.headway)
    scale = 1.0 + np.abs(a) + np.abs(b) + np.abs(cx) + np.abs(cv)
    return np.asarray(-SCREEN_RTOL * scale)


def surely_uncertifiable(K: npt.ArrayLike, p: Params,
                         omega: npt.ArrayLike = SCREEN_OMEGA) -> npt.NDArray[np.bool_]:
    """Which rows of K surely cannot be certified: not Hurwitz, or g(ω) < threshold at an ω.

    Sound (module docstring): a row flagged here is never certified by
    :func:`stringstab.certify.api.check`; a row not flagged may still fail.

    Parameters
    ----------
    K : array_like, shape (n, 3)
        Gain triples (k_x [1/s²], k_v [1/s], k_a [-]) of IDL eq 4.
    p : Params
        τ, δ, T* of the continuous loop (s).
    omega : array_like
        Frequencies ω ≥ 0 (rad/s) at which g is tried (default :data:`SCREEN_OMEGA`; empty:
        internal stability only).

    Returns
    -------
    ndarray of bool, shape (n,)
        True where K is not internally stable (Hurwitz) or g(ω) < :func:`violation_threshold`
        at some ω of ``omega``.

    Examples
    --------
    >>> surely_uncertifiable([[1.2, 0.5, 0.6], [0.9, -0.5, 1.1], [-1.0, 0.5, 0.0]],
    ...                      Params(0.1, 0.2, 1.1)).tolist()
    [False, True, True]
    """
    K = np.asarray(K, dtype=float).reshape(-1, 3)
    w = np.asarray(omega, dtype=float).ravel()
    out = ~hurwitz(K[:, 0], K[:, 1], tau=p.tau, headway=p.headway)
    idx = np.flatnonzero(~out)
    if idx.size and w.size:
        g = _margin.g(w[None, :], K[idx, 0:1], K[idx, 1:2], K[idx, 2:3],
                      tau=p.tau, delta=p.delta, headway=p.headway)
        out[idx] = g.min(axis=1) < violation_threshold(K[idx], p)
    return np.asarray(out)


def violating_dips(K: npt.ArrayLike, p: Params) -> list[float]:
    """The screen's frequencies found by a scan, for one triple: where g dips below the threshold.

    Each returned ω is a local minimiser of g(·; K) (:func:`stringstab.certify.margin.local_minima`)
    with g(ω) < :func:`violation_threshold`, so |Γ(jω)| > 1 there: K cannot be certified if
    the list is not empty (with :func:`surely_uncertifiable` at ``omega=()`` for the Hurwitz
    part, this is the screen of one triple).

    Parameters
    ----------
    K : array_like, shape (3,)
        Gains (k_x [1/s²], k_v [1/s], k_a [-]) of IDL eq 4.
    p : Params
        τ, δ, T* of the continuous loop (s).

    Returns
    -------
    list of float
        The violating local minimisers ω (rad/s), possibly empty.
    """
    K = np.asarray(K, dtype=float).reshape(3)
    threshold = float(violation_threshold(K, p))
    _, dips = _margin.local_minima(K, tau=p.tau, delta=p.delta, headway=p.headway,
                                   threshold=threshold)
    return dips


#: The frequencies of the sampled screen, rad/sample: the continuous screen's ω at H, then a
#: uniform grid up to π.
def _sampled_thetas(H: float) -> Array:
    th = np.concatenate([SCREEN_OMEGA * H, np.linspace(0.0, np.pi, 49)[1:]])
    return np.unique(th[(th > 0) & (th <= np.pi)])


#: Monomials of K̃ = (1, k_x, k_v, k_a) of degree ≤ 2, as index pairs.
_MONOMIALS = [(a, b) for a in range(4) for b in range(a, 4)]


#: The factors of each monomial of :data:`_MONOMIALS`, as column indices of K̃.
_FIRST = np.array([a for a, _ in _MONOMIALS])
_SECOND = np.array([b for _, b in _MONOMIALS])


def _monomials(K: Array) -> Array:
    """The 10 monomials of degree ≤ 2 of each row of K, shape (n, 10) (one product each)."""
    Kt = np.empty((K.shape[0], 4))
    Kt[:, 0] = 1.0
    Kt[:, 1:] = K
    return Kt[:, _FIRST] * Kt[:, _SECOND]


class SampledScreen:
    """The "surely not certifiable" screen of the sampled-data loop at one τ, δ, T*, H, τ_p.

    g_H(θ) of :func:`stringstab.certify.sampled_frequency.sampled_margin` is a polynomial of
    degree 2 in the gains at fixed parameters (every coefficient of
    :func:`stringstab.certify.zoh.build` is), so at each of the screen's frequencies it is a
    quadratic form in (1, k_x, k_v, k_a), fitted here once from g_H itself at 30 gain triples
    (and refused — the screen then flags nothing — unless it reproduces g_H at 30 others to
    10⁻¹⁰ of its terms' magnitude).  A row whose form is below −:data:`SAMPLED_SCREEN_RTOL`
    times that magnitude at some frequency has |H(e^{jθ})| > 1 there, far beyond any error of
    the fit: the sampled certificate cannot certify it.  Sound, like :func:`surely_uncertifiable`;
    it only saves certificate calls.

    Parameters
    ----------
    p : Params
        τ, δ, T* (s).
    H : float
        Sample time, s.
    tau_prev : float, optional
        The predecessor's lag (default τ).

    Examples
    --------
    >>> s = SampledScreen(Params(0.1, 0.2, 1.1), 0.1)
    >>> s.surely_uncertifiable([[1.2, 0.5, 0.6], [0.9, -0.5, 1.1]]).tolist()
    [False, True]
    """

    def __init__(self, p: Params, H: float, tau_prev: float | None = None) -> None:
        from .sampled_frequency import sampled_margin  # the sampled loop only when asked

        self.theta = _sampled_thetas(H)
        rng = np.random.default_rng(0)
        K = rng.uniform(-2.0, 2.0, (60, 3))
        g = np.stack([sampled_margin(self.theta, *k, tau=p.tau, delta=p.delta, headway=p.headway,
                                     sample_time=H, tau_prev=tau_prev) for k in K])
        Mf, Mv = _monomials(K[:30]), _monomials(K[30:])
        self.Q = np.linalg.lstsq(Mf, g[:30], rcond=None)[0]  # (10, nθ)
        err = np.abs(Mv @ self.Q - g[30:])
        self.ok = bool(np.all(err <= 1e-10 * (1.0 + np.abs(Mv) @ np.abs(self.Q))))

    def surely_uncertifiable(self, K: npt.ArrayLike) -> npt.NDArray[np.bool_]:
        """Which rows of K the sampled certificate surely cannot certify (class docstring).

        Parameters
        ----------
        K : array_like, shape (n, 3)
            Gain triples (k_x, k_v, k_a).

        Returns
        -------
        ndarray of bool, shape (n,)
            True where g_H is below its threshold at a screen frequency.
        """
        K = np.asarray(K, dtype=float).reshape(-1, 3)
        if not self.ok or not K.shape[0]:
            return np.zeros(K.shape[0], dtype=bool)
        M = _monomials(K)
        g = M @ self.Q
        scale = 1.0 + np.abs(M) @ np.abs(self.Q)
        return np.asarray(np.any(g < -SAMPLED_SCREEN_RTOL * scale, axis=1))


#: Relative tolerance of the sampled screen (of the magnitude of the quadratic form's terms).
SAMPLED_SCREEN_RTOL = 1e-7


@lru_cache(maxsize=16)
def sampled_screen(tau: float, delta: float, headway: float, sample_time: float,
                   tau_prev: float | None = None) -> SampledScreen:
    """The :class:`SampledScreen` of one loop, built once per process (16 cached).

    Parameters
    ----------
    tau, delta, headway : float
        τ, δ, T* (s).
    sample_time : float
        H (s).
    tau_prev : float, optional
        The predecessor's lag (default τ).

    Returns
    -------
    SampledScreen
    """
    return SampledScreen(Params(tau, delta, headway), sample_time, tau_prev)
