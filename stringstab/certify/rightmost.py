r"""The rightmost root of D(s) = τs³ + s² + e^{−θ_r s}(cs + k_x), estimated (reporting only).

``hurwitz_margin`` of a loop with a reaction delay θ_r > 0 is −Re s* for the rightmost root s*
of the quasi-polynomial (the slowest decay rate, 1/s).  It is *estimated*, never proven: the
roots of a Padé(m, m) approximant of e^{−θ_r s} (a polynomial of degree 3 + m, all roots from
one companion matrix per item) and of the cubic at θ_r = 0 start Newton's method on the exact
D, and the converged root
with the largest real part is reported (plus the real root of :func:`stringstab.certify.
quasipolynomial.real_root` where k_x < 0).  The proven statement is the root count of
:mod:`stringstab.certify.quasipolynomial`; :mod:`stringstab.certify.reaction` reports this
estimate only where its sign agrees with that proof, NaN elsewhere.

References
----------
H. Padé (1892); the rational approximant of e^{−x} of degrees (m, m):
Σ_k (2m−k)! m! / ((2m)! k! (m−k)!) (−x)^k over the same sum in x.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

__all__ = ["pade_coefficients", "rightmost_root"]

Array = npt.NDArray[np.float64]
CArray = npt.NDArray[np.complex128]


def pade_coefficients(m: int) -> Array:
    """The coefficients a_k (k = 0…m) of Padé(m, m) of e^{−x} ≈ Σ a_k (−x)^k / Σ a_k x^k.

    Parameters
    ----------
    m : int
        The order, ≥ 1.

    Returns
    -------
    ndarray, shape (m + 1,)
        a_k = (2m − k)! m! / ((2m)! k! (m − k)!), a_0 = 1.

    Examples
    --------
    >>> pade_coefficients(1).tolist()  # (1 − x/2)/(1 + x/2)
    [1.0, 0.5]
    """
    f = math.factorial
    return np.array([f(2 * m - k) * f(m) / (f(2 * m) * f(k) * f(m - k)) for k in range(m + 1)])


def _newton(s: CArray, tau: Array, c: Array, kx: Array, theta: Array,
            steps: int) -> tuple[CArray, npt.NDArray[np.bool_]]:
    """Newton on the exact D from the starts ``s`` (columns); (roots, converged)."""
    tau, c, kx, theta = (v[:, None] for v in (tau, c, kx, theta))
    with np.errstate(all="ignore"):
        for i in range(steps):
            e = np.exp(-theta * s)
            q = c * s + kx
            d = (tau * s + 1.0) * s * s + e * q
            dd = (3.0 * tau * s + 2.0) * s + e * (c - theta * q)
            step = d / dd
            s = s - step
            if i % 4 == 3 and not np.any(np.abs(step) > 1e-13 * np.abs(s)):
                break
        e = np.exp(-theta * s)
        d = (tau * s + 1.0) * s * s + e * (c * s + kx)
        size = np.abs(tau * s**3) + np.abs(s * s) + np.abs(e) * (np.abs(c * s) + np.abs(kx))
        ok = np.isfinite(s) & (np.abs(d) <= 1e-9 * np.maximum(size, 1e-300))
    return s, ok


def rightmost_root(kx: Array, kv: Array, tau: Array | float, headway: Array | float,
                   theta: Array | float, *,
                   order: int = 4, starts: int = 3, steps: int = 24,
                   extra: Array | None = None) -> CArray:
    """Estimate the rightmost root of D(s) = τs³ + s² + e^{−θ_r s}((k_v + T*k_x)s + k_x).

    Parameters
    ----------
    kx, kv : ndarray, shape (n,)
        Gains.
    tau, headway, theta : ndarray, shape (n,) or broadcastable
        τ > 0, T*, θ_r > 0 (s).
    order : int
        Padé order m of the starting polynomial (degree 3 + m).
    starts : int
        How many of its rightmost roots start Newton's method.
    steps : int
        Newton steps.
    extra : ndarray, shape (n,), optional
        Further real starts (e.g. a known real root; NaN: none).

    Returns
    -------
    ndarray of complex, shape (n,)
        The converged root with the largest real part (upper half plane of a conjugate
        pair); NaN where no start converged.

    Examples
    --------
    >>> one = lambda v: np.array([v])
    >>> s = rightmost_root(one(1.0), one(0.5), one(0.1), one(1.1), one(0.2))[0]
    >>> D = 0.1 * s**3 + s**2 + np.exp(-0.2 * s) * (1.6 * s + 1.0)
    >>> bool(abs(D) < 1e-9 and s.real < 0)
    True
    """
    n = kx.size
    tau, headway, theta = (np.broadcast_to(np.asarray(v, dtype=float), (n,))
                           for v in (tau, headway, theta))
    c = kv + headway * kx
    a = pade_coefficients(order)
    k = np.arange(order + 1)
    # Padé: e^{-θs} ≈ num(s)/den(s), num_k = a_k (−θ)^k, den_k = a_k θ^k (ascending powers)
    den = a[None, :] * theta[:, None] ** k[None, :]
    num = den * (-1.0) ** k[None, :]
    deg = 3 + order
    poly = np.zeros((n, deg + 1))  # ascending powers of s
    poly[:, 2:2 + order + 1] += den  # s² den
    poly[:, 3:3 + order + 1] += tau[:, None] * den  # τ s³ den
    poly[:, 0:order + 1] += kx[:, None] * num  # k_x num
    poly[:, 1:order + 2] += c[:, None] * num  # c s num
    lead = poly[:, -1]
    C = np.zeros((n, deg, deg))
    with np.errstate(all="ignore"):  # θ_r → 0 makes the leading coefficient vanish: no start
        C[:, 0, :] = -poly[:, -2::-1] / lead[:, None]
    C[:, np.arange(1, deg), np.arange(deg - 1)] = 1.0
    with np.errstate(all="ignore"):
        ok_rows = np.all(np.isfinite(C), axis=(1, 2))
        ev = np.full((n, deg), np.nan + 0j)
        if ok_rows.any():
            ev[ok_rows] = np.linalg.eigvals(C[ok_rows])
    order_re = np.argsort(-np.nan_to_num(ev.real, nan=-np.inf), axis=1)[:, :starts]
    s0 = np.take_along_axis(ev, order_re, axis=1)
    # and the roots of the cubic at θ_r = 0 (the starts that matter as θ_r → 0)
    C3 = np.zeros((n, 3, 3))
    C3[:, 0, :] = -np.stack([np.ones(n), c, kx], axis=1) / tau[:, None]
    C3[:, 1, 0] = C3[:, 2, 1] = 1.0
    s0 = np.concatenate([s0, np.linalg.eigvals(C3) if n else np.zeros((0, 3), complex)], axis=1)
    if extra is not None:
        s0 = np.concatenate([s0, np.asarray(extra, dtype=complex)[:, None]], axis=1)
    s, ok = _newton(s0, tau, c, kx, theta, steps)
    re = np.where(ok, s.real, -np.inf)
    j = np.argmax(re, axis=1)
    best = s[np.arange(n), j]
    best = np.where(np.isfinite(re[np.arange(n), j]), best, np.nan + 0j)
    return np.where(best.imag < 0, np.conj(best), best)
