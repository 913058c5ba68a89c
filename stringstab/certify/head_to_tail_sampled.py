r"""The sampled-data loop of a heterogeneous string: products of |H_i(e^{jθ})| on the unit circle.

Every vehicle samples with the same period H (zero-order hold); vehicle i's transfer from its
predecessor's acceleration samples to its own (:mod:`stringstab.certify.zoh`) is

.. math::
    H_i(z) = \frac{φ_{1,i}}{φ_{1p,i}}\,\frac{N_i(w)}{Δ_i(w)},\qquad
    N_i = n_i(w) + z^{-(m_i+1)} k_{a,i} w^2 \ell_i(w),\quad w = z − 1,

with its own τ_i, δ_i = (m_i + ε_i)H, T*_i and gains, and the *predecessor's* lag τ_p = τ_{i−1}
(τ_0, the leader's, given).  With κ_i = τ_i τ_{i−1}/H³, A_i = κ_i φ_{1p,i} and B_i = κ_i φ_{1,i},
the factors of the telescoping sum of :mod:`stringstab.certify.head_to_tail` on z = e^{jθ} are

.. math::
    d_i = A_i^2 |Δ_i|^2,\quad n_i = B_i^2 |N_i|^2,\quad
    d_i − n_i = ρ\, g_{H,i}(θ),\quad ρ = 4\sin^2(θ/2),

g_{H,i} the sampled margin of :mod:`stringstab.certify.sampled_frequency` (P + cos(mθ) Y_r +
sin(mθ) sin θ Y_i, from the same coefficients): the tangency at θ = 0 (every H_i(1) = 1) is
removed by the exact division by ρ that the one-vehicle certificate makes.  On θ ∈ [0, π]
(no tail: the domain is compact), ∏_i |H_i(e^{jθ})| ≤ 1 iff G_H(θ) ≥ 0 at θ > 0, decided by
the same branch and bound, curvature from jets, round-off rule.  Internal stability: every
Δ_i Schur (:func:`stringstab.certify.schur.schur_bands`).

References
----------
:mod:`stringstab.certify.zoh` (the coefficients), :mod:`stringstab.certify.sampled` (the
one-vehicle certificate).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

from .head_to_tail import Factor, Index, Parts, StringArrays
from .interval import Interval
from .interval_jets import Enclosure, Jet, jet_cos, jet_sin
from .schur import schur_bands
from .verdicts import ROUNDOFF_SLACK
from .zoh import Coefficients, coefficients, split_delay

__all__ = ["SampledString", "sampled_factor_scale"]

Array = npt.NDArray[np.float64]


def _cmul(a: tuple[Any, Any], b: tuple[Any, Any]) -> tuple[Any, Any]:
    """(a_r + j a_i)(b_r + j b_i) in any arithmetic with +, −, ×."""
    return a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]


def sampled_factor_scale(co: Coefficients, A: Interval) -> Array:
    """The normalisation c_i of :func:`stringstab.certify.head_to_tail.normalisation`, sampled.

    |Δ(w)| ≤ 8 + 4|δ2| + 2|δ1| + |δ0| on the unit circle (|w| ≤ 2) and |Δ(0)| = δ0, so
    c_i = 1/(A² δ0 (8 + 4|δ2| + 2|δ1| + |δ0|)) keeps c_i d_i between their ratio and its
    inverse.

    Parameters
    ----------
    co : Coefficients
        Point coefficients of the vehicles (one row each).
    A : Interval
        A_i = κ_i φ_{1p,i} (module docstring), points.

    Returns
    -------
    ndarray
        c_i > 0.
    """
    d0, d1, d2 = (np.abs(x.lo) for x in co.delta)
    a2 = A.lo * A.lo
    return np.asarray(1.0 / np.maximum(a2 * np.maximum(d0, 1e-300) * (8.0 + 4.0 * d2 + 2.0 * d1 + d0),
                                       1e-300))


class SampledString:
    """The sampled-data loop of strings of one length (module docstring).

    Parameters
    ----------
    arrays : StringArrays
        The strings (no reaction delay: the sampled loop has none yet).
    sample_time : float
        H > 0, s (checked).
    leader_tau : ndarray, shape (n,)
        τ_0, the leader's lag of each string (the first follower's predecessor), s.
    """

    def __init__(self, arrays: StringArrays, sample_time: float, leader_tau: Array) -> None:
        if np.any(arrays.reaction_delay != 0):
            raise ValueError("the sampled head-to-tail certificate has no reaction delay")
        self.arrays = a = arrays
        self.H = H = float(sample_time)
        self.co: list[Coefficients] = []
        self.m: list[Array] = []
        self.kap: list[tuple[Interval, Interval]] = []
        scales = []
        for i in range(a.length):
            tp = np.ascontiguousarray(leader_tau if i == 0 else a.tau[i - 1], dtype=float)
            t = np.ascontiguousarray(a.tau[i])
            split = [split_delay(float(d), H) for d in a.delta[i]]
            m = np.array([s[0] for s in split], dtype=float)
            e = np.array([s[1] for s in split], dtype=float)
            c = a.kv[i] + a.headway[i] * a.kx[i]
            co = coefficients(a.kx[i], a.kv[i], a.ka[i], H=H, tau=(t, t), tau_p=(tp, tp),
                              eps=(e, e), c=(c, c))
            kap = Interval(t) * Interval(tp) * (1.0 / H**3)
            A, B = kap * co.phi1p, kap * co.phi1
            self.co.append(co)
            self.m.append(m)
            self.kap.append((A, B))
            scales.append(sampled_factor_scale(co, A))
        self.scale = np.stack(scales)

    def right(self) -> Array:
        """π for every item: θ ∈ [0, π] (rad/sample)."""
        return np.full(self.arrays.count, math.pi)

    def _expr(self, i: int, idx: Index, x: Any, const: Any) -> tuple[Any, ...]:
        """(Re N, Im N, Re Δ, Im Δ, g_H) of vehicle i at θ = ``x``, coefficients through ``const``."""
        co = self.co[i]
        m = self.m[i][idx][:, None]
        d0, d1, d2 = (const(v, idx) for v in co.delta)
        n0, n1, n2 = (const(v, idx) for v in co.nu)
        l0, l1 = (const(v, idx) for v in co.ell)
        ka = const(Interval(self.arrays.ka[i]), idx)
        s = jet_sin(0.5 * x)
        s2 = s * s
        rho = 4.0 * s2
        w = (-2.0 * s2, jet_sin(x))  # e^{jθ} − 1 = −2 sin²(θ/2) + j sin θ
        # Δ = ((w + δ2) w + δ1) w + δ0
        z = _cmul((w[0] + d2, w[1]), w)
        z = _cmul((z[0] + d1, z[1]), w)
        dr, di = z[0] + d0, z[1]
        # N = (ν2 w + ν1) w + ν0 + e^{−j(m+1)θ} k_a w² (ℓ0 + ℓ1 w)
        q = _cmul((n2 * w[0] + n1, n2 * w[1]), w)
        kq = _cmul(_cmul(w, w), (l0 + l1 * w[0], l1 * w[1]))
        ang = const(Interval(m + 1.0), None) * x
        eq = _cmul((jet_cos(ang), -jet_sin(ang)), (ka * kq[0], ka * kq[1]))
        nr, ni = q[0] + n0 + eq[0], q[1] + eq[1]
        # g_H = P(ρ) + cos(mθ) Y_r(ρ) + sin(mθ) sin θ Y_i(ρ)
        mth = const(Interval(m), None) * x
        g = (_horner([const(v, idx) for v in co.P], rho)
             + jet_cos(mth) * _horner([const(v, idx) for v in co.Yr], rho)
             + jet_sin(mth) * w[1] * _horner([const(v, idx) for v in co.Yi], rho))
        return nr, ni, dr, di, g

    def parts(self, idx: Index, x: Interval) -> list[Parts]:
        """Re N_i, Im N_i, Re Δ_i, Im Δ_i, g_{H,i} and the prefactors B_i², A_i² at θ = ``x``.

        Parameters
        ----------
        idx : ndarray of int
            The items (strings), one row of ``x`` each.
        x : Interval
            θ, rad/sample, points of shape (len(idx), k).

        Returns
        -------
        list of Parts
            Per vehicle, point intervals with their magnitude companions.
        """
        out = []
        for i in range(self.arrays.length):
            A, B = self.kap[i]
            nr, ni, dr, di, g = self._expr(i, idx, x, _point)
            out.append(Parts(nr, ni, dr, di, g, _point(B * B, idx), _point(A * A, idx)))
        return out

    def factors(self, idx: Index, x: Jet) -> list[Factor]:
        """(c_i n_i, c_i d_i, c_i g_{H,i}) of every vehicle on the jet θ = ``x``.

        Parameters
        ----------
        idx : ndarray of int
            The items (strings), one row of ``x`` each.
        x : Jet
            θ over intervals, rad/sample, of shape (len(idx), k).

        Returns
        -------
        list of (n, d, g)
            Jets; the coefficients enter as enclosures of their round-off.
        """
        out = []
        for i in range(self.arrays.length):
            A, B = self.kap[i]
            nr, ni, dr, di, g = self._expr(i, idx, x, _enclosed)
            c = Jet(Enclosure(self.scale[i, idx][:, None]))
            out.append((c * (_enclosed(B * B, idx) * (nr * nr + ni * ni)),
                        c * (_enclosed(A * A, idx) * (dr * dr + di * di)), c * g))
        return out

    def stability(self) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
        """(every Δ_i surely Schur, some Δ_i surely not), per item."""
        sure = np.ones(self.arrays.count, dtype=bool)
        fail = np.zeros(self.arrays.count, dtype=bool)
        for co in self.co:
            s, f = schur_bands(co.delta)
            sure &= s
            fail |= f
        return sure, fail


def _point(v: Interval, idx: Index | None) -> Interval:
    """A coefficient's rows ``idx`` as a column of points (its magnitude companion kept)."""
    if idx is None:
        return v
    t = v.take(idx)
    return Interval(t.lo[:, None], None, t.mag[:, None])


def _enclosed(v: Interval, idx: Index | None) -> Jet:
    """A coefficient's rows ``idx`` as a constant jet enclosing its round-off (the slack rule)."""
    if idx is None:
        return Jet(Enclosure(v.lo))
    t = v.take(idx)
    return Jet(Enclosure.around(t.lo[:, None], ROUNDOFF_SLACK * t.mag[:, None]))


def _horner(coefs: list[Any], rho: Any) -> Any:
    """Σ_j coefs[j] ρ^j by Horner's rule (constant term first)."""
    out = coefs[-1]
    for c in reversed(coefs[:-1]):
        out = out * rho + c
    return out
