"""Cells of the split form: bounds of F from below and of G from above over cells, at any θ.

The split form of :mod:`stringstab.certify.sampled_split` compares the follower's factor F,
minimised over (τ, T*), with the predecessor's G, maximised over τ_p and the ends of the
delay's pieces.  :class:`FollowerCells` and :class:`PredecessorCells` hold, one row per cell,
their coefficients in ρ with derivative enclosures over the cell
(:class:`~stringstab.certify.interval.IntervalAD`) as arrays, and bound F and G over each
cell at any frequencies by the better of the interval extension and the mean-value form,
with the round-off slack of :data:`~stringstab.certify.verdicts.ROUNDOFF_SLACK` times the
magnitudes.  The search over such cells is :mod:`stringstab.certify.robust_split`.

References
----------
R. E. Moore, R. B. Kearfott, M. J. Cloud, *Introduction to Interval Analysis*, SIAM (2009),
§6.4 (the mean-value form).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from .interval import IntervalAD
from .sampled_split import follower_terms, predecessor_terms
from .verdicts import ROUNDOFF_SLACK

__all__ = ["FollowerCells", "PredecessorCells"]

Array = npt.NDArray[np.float64]


def _stack(poly: list[IntervalAD], fields: tuple[str, ...], J: int = 3) -> Array:
    """The coefficients' ``fields`` as an array (rows, len(fields), J), zero-padded to J."""
    d = len(poly[0].g)
    getters: dict[str, Any] = {
        "c": lambda v: v.c.lo, "lo": lambda v: v.r.lo, "hi": lambda v: v.r.hi,
        **{f"glo{i}": (lambda v, i=i: v.g[i].lo) for i in range(d)},
        **{f"ghi{i}": (lambda v, i=i: v.g[i].hi) for i in range(d)},
    }
    n = np.shape(poly[0].c.lo)[0]
    out = np.zeros((n, len(fields), J))
    for j, v in enumerate(poly):
        for k, f in enumerate(fields):
            out[:, k, j] = getters[f](v)
    return out


def _magnitudes(poly: list[IntervalAD], J: int = 3) -> tuple[Array, Array, Array]:
    """Per cell: |coefficient| bounds, value magnitudes and gradient magnitudes, (n, J) each.

    max(|lo|, |hi|) + ROUNDOFF_SLACK·mag of the enclosure (the curvature bound's input), the
    magnitude companion of the value (the larger of the centre's and the enclosure's) and the
    gradients' magnitudes summed over the parameters (the round-off slacks' input),
    zero-padded to J.
    """
    n = np.shape(poly[0].c.lo)[0]
    a, mag, gmag = (np.zeros((n, J)) for _ in range(3))
    for j, v in enumerate(poly):
        a[:, j] = np.maximum(np.abs(v.r.lo), np.abs(v.r.hi)) + ROUNDOFF_SLACK * v.r.mag
        mag[:, j] = np.maximum(v.c.mag, v.r.mag)
        gmag[:, j] = np.broadcast_to(np.asarray(sum(g.mag for g in v.g)), (n,))
    return a, mag, gmag


_F_FIELDS = ("c", "lo", "glo0", "ghi0", "glo1", "ghi1")
_P_FIELDS = ("c", "hi", "glo0", "ghi0")
_Y_FIELDS = ("c", "lo", "hi", "glo0", "ghi0")


@dataclass
class FollowerCells:
    """F over cells of (τ, T*), one row per cell (of the triple ``owner``).

    Attributes
    ----------
    owner : ndarray of int, shape (n,)
        The item (gain triple) of each cell.
    tau, headway : ndarray, shape (n, 2)
        The cells' bounds.
    V : ndarray, shape (n, 6, 3)
        F's coefficients in ρ: the centre value, the enclosure's lower end and the two
        gradients' enclosures (τ, T*).
    a, mag, gmag : ndarray, shape (n, 3)
        |coefficient| bounds (curvature), magnitudes of the value and of the gradients
        (round-off slacks).
    """

    owner: npt.NDArray[np.intp]
    tau: Array
    headway: Array
    V: Array
    a: Array
    mag: Array
    gmag: Array

    @classmethod
    def of(cls, owner: npt.NDArray[np.intp], kx: Array, kv: Array, *, H: float, tau: Array,
           headway: Array) -> FollowerCells:
        """The cells ``tau`` × ``headway`` of the triples ``owner`` (gains indexed by owner).

        Parameters
        ----------
        owner : ndarray of int, shape (n,)
            The item of each cell.
        kx, kv : ndarray
            The items' gains.
        H : float
            Sample time, s.
        tau, headway : ndarray, shape (n, 2)
            The cells' bounds of τ and T*.

        Returns
        -------
        FollowerCells
        """
        Fp = follower_terms(kx[owner], kv[owner], H=H, tau=tau, headway=headway)
        return cls(owner, tau, headway, _stack(Fp, _F_FIELDS), *_magnitudes(Fp))

    def __len__(self) -> int:
        return int(self.owner.size)

    @property
    def hw(self) -> Array:
        """Half-widths (n, 2) along τ and T*."""
        return 0.5 * np.stack([self.tau[:, 1] - self.tau[:, 0],
                               self.headway[:, 1] - self.headway[:, 0]], axis=1)

    def take(self, idx: npt.NDArray[np.intp]) -> FollowerCells:
        """The cells ``idx``."""
        return FollowerCells(self.owner[idx], self.tau[idx], self.headway[idx], self.V[idx],
                             self.a[idx], self.mag[idx], self.gmag[idx])

    @staticmethod
    def slacks(mag: Array, gmag: Array, Z: Array) -> tuple[Array, Array]:
        """The round-off slacks of F and of its gradients from magnitudes (r, 3) at θ.

        Parameters
        ----------
        mag, gmag : ndarray, shape (r, 3)
            Magnitudes of F's coefficients and of their gradients (of a cell, or the largest
            over an item's cells: a bound for each of them).
        Z : ndarray, shape (r, 3, k)
            :func:`vander` of each row's frequencies.

        Returns
        -------
        (ndarray, ndarray)
            The slacks of the value and of each gradient, shape (r, k).
        """
        mags = np.matmul(np.stack([mag, gmag], axis=1), Z)
        return ROUNDOFF_SLACK * mags[:, 0], ROUNDOFF_SLACK * mags[:, 1]

    def bounds(self, cell: npt.NDArray[np.intp], Z: Array,
               slack: tuple[Array, Array] | None = None) -> tuple[Array, Array, Array]:
        """F at the centres, a lower bound over the cells, and the slack, at θ.

        Parameters
        ----------
        cell : ndarray of int, shape (r,)
            The cells, one per row.
        Z : ndarray, shape (r, 3, k)
            :func:`vander` of each row's frequencies.
        slack : (ndarray, ndarray), optional
            The slacks of :meth:`slacks` for each row, when the caller has them (from
            magnitudes at least the cells'); computed from the cells' own otherwise.

        Returns
        -------
        (ndarray, ndarray, ndarray)
            Of shape (r, k): F at the centre, the lower bound (the better of the interval
            extension and the mean-value form) and the round-off slack of both.
        """
        V = np.matmul(self.V[cell], Z)
        E, gmag = self.slacks(self.mag[cell], self.gmag[cell], Z) if slack is None else slack
        hw = self.hw[cell]
        spread = ((np.maximum(np.abs(V[:, 2]), np.abs(V[:, 3])) + gmag) * hw[:, 0, None]
                  + (np.maximum(np.abs(V[:, 4]), np.abs(V[:, 5])) + gmag) * hw[:, 1, None])
        Fc = V[:, 0]
        return Fc, np.maximum(V[:, 1], Fc - spread), E

    def spreads(self, cell: npt.NDArray[np.intp], Z: Array) -> Array:
        """max |∂F/∂p| × half-width along τ and T* over each cell, shape (r, 2, k).

        Parameters
        ----------
        cell : ndarray of int, shape (r,)
            The cells, one per row.
        Z : ndarray, shape (r, 3, k)
            :func:`vander` of each row's frequencies.

        Returns
        -------
        ndarray, shape (r, 2, k)
            How much each parameter's width costs the mean-value bound (where to halve).
        """
        V = np.matmul(self.V[cell][:, 2:6], Z)
        hw = self.hw[cell]
        return np.stack([np.maximum(np.abs(V[:, 0]), np.abs(V[:, 1])) * hw[:, 0, None],
                         np.maximum(np.abs(V[:, 2]), np.abs(V[:, 3])) * hw[:, 1, None]], axis=1)


@dataclass
class PredecessorCells:
    """G over cells of τ_p at one end (m, ε) of a piece of the delay, one row per cell.

    Attributes
    ----------
    owner : ndarray of int, shape (n,)
        What the cell belongs to: an item (heterogeneous), or a follower cell (τ_p = τ).
    tau_p : ndarray, shape (n, 2)
        The cells' bounds of τ_p.
    end : ndarray of int, shape (n,)
        The index of the cell's end of the delay.
    m : ndarray, shape (n,)
        Its whole samples of delay.
    V : ndarray, shape (n, 14, 3)
        P_G (centre, upper end, gradient enclosure), Y_r and Y_i (centre, enclosure,
        gradient enclosure) in ρ; gradients along τ_p.
    a, mag, gmag : ndarray, shape (n, 3, 3)
        Per polynomial (P_G, Y_r, Y_i): |coefficient| bounds, value and gradient magnitudes.
    """

    owner: npt.NDArray[np.intp]
    tau_p: Array
    end: npt.NDArray[np.intp]
    m: Array
    V: Array
    a: Array
    mag: Array
    gmag: Array

    @classmethod
    def of(cls, owner: npt.NDArray[np.intp], gains: npt.NDArray[np.intp], kx: Array, kv: Array,
           ka: Array, *, H: float, tau_p: Array, end: npt.NDArray[np.intp],
           ends: list[tuple[int, float]]) -> PredecessorCells:
        """The cells ``tau_p`` at the delay's ends ``end`` (indices into ``ends``).

        Parameters
        ----------
        owner : ndarray of int, shape (n,)
            What each cell belongs to.
        gains : ndarray of int, shape (n,)
            The index of each cell's gains in ``kx``, ``kv``, ``ka``.
        kx, kv, ka : ndarray
            The items' gains.
        H : float
            Sample time, s.
        tau_p : ndarray, shape (n, 2)
            The cells' bounds of τ_p.
        end : ndarray of int, shape (n,)
            Each cell's end of the delay.
        ends : list of (int, float)
            The ends (m, ε) (:func:`delay_ends`).

        Returns
        -------
        PredecessorCells
        """
        m = np.array([ends[e][0] for e in end], dtype=float)
        eps = np.array([ends[e][1] for e in end], dtype=float)
        P, Yr, Yi = predecessor_terms(kx[gains], kv[gains], ka[gains], H=H, tau_p=tau_p,
                                      eps=eps)
        V = np.concatenate([_stack(P, _P_FIELDS), _stack(Yr, _Y_FIELDS), _stack(Yi, _Y_FIELDS)],
                           axis=1)
        mags = [_magnitudes(p) for p in (P, Yr, Yi)]
        return cls(owner, tau_p, end, m, V, *(np.stack([x[i] for x in mags], axis=1)
                                              for i in range(3)))

    def __len__(self) -> int:
        return int(self.owner.size)

    def take(self, idx: npt.NDArray[np.intp]) -> PredecessorCells:
        """The cells ``idx``."""
        return PredecessorCells(self.owner[idx], self.tau_p[idx], self.end[idx], self.m[idx],
                                self.V[idx], self.a[idx], self.mag[idx], self.gmag[idx])

    @staticmethod
    def slacks(mag: Array, gmag: Array, m: Array, theta: Array,
               Z: Array) -> tuple[Array, Array]:
        """The round-off slacks of G and of its gradient from magnitudes (r, 3, 3) at θ.

        Parameters
        ----------
        mag, gmag : ndarray, shape (r, 3, 3)
            Magnitudes of P_G, Y_r, Y_i's coefficients and of their gradients (of a cell, or
            the largest over an item's cells).
        m : ndarray, shape (r,)
            Whole samples of delay (the largest of the cells').
        theta : ndarray, shape (r, k)
            Frequencies, rad/sample.
        Z : ndarray, shape (r, 3, k)
            :func:`vander` of ``theta``.

        Returns
        -------
        (ndarray, ndarray)
            The slacks of the value and of the gradient, shape (r, k).
        """
        m1 = (1.0 + m)[:, None, None]
        ast = np.abs(np.sin(theta))[:, None]
        mags = np.matmul(np.concatenate([mag, gmag], axis=1), Z)
        sl = ROUNDOFF_SLACK * m1 * (mags[:, [0, 3]] + m1 * (mags[:, [1, 4]]
                                                            + ast * mags[:, [2, 5]]))
        return sl[:, 0], sl[:, 1]

    def bounds(self, cell: npt.NDArray[np.intp], theta: Array, Z: Array,
               trig: tuple[Array, Array] | None = None,
               slack: tuple[Array, Array] | None = None) -> tuple[Array, Array, Array]:
        """G at the centres, an upper bound over the cells, and the slack, at θ.

        Parameters
        ----------
        cell : ndarray of int, shape (r,)
            The cells, one per row.
        theta : ndarray, shape (r, k)
            Frequencies, rad/sample.
        Z : ndarray, shape (r, 3, k)
            :func:`vander` of ``theta``.
        trig : (ndarray, ndarray), optional
            cos(mθ) and sin(mθ) sin θ of each row, shape (r, k), when the caller has them
            (computed here otherwise).
        slack : (ndarray, ndarray), optional
            The slacks of :meth:`slacks` for each row, when the caller has them (from
            magnitudes and m at least the cells'); computed from the cells' own otherwise.

        Returns
        -------
        (ndarray, ndarray, ndarray)
            Of shape (r, k): G at the centre, the upper bound (the better of the interval
            extension and the mean-value form) and the round-off slack of both.
        """
        if trig is None:
            m = self.m[cell][:, None]
            cm, f = np.cos(m * theta), np.sin(m * theta) * np.sin(theta)
        else:
            cm, f = trig
        V = np.matmul(self.V[cell], Z)
        Pc, Phi, Pglo, Pghi = V[:, 0], V[:, 1], V[:, 2], V[:, 3]
        Rc, Rlo, Rhi, Rglo, Rghi = (V[:, 4 + i] for i in range(5))
        Ic, Ilo, Ihi, Iglo, Ighi = (V[:, 9 + i] for i in range(5))
        Gc = Pc + cm * Rc + f * Ic
        a, b, c, e = cm * Rlo, cm * Rhi, f * Ilo, f * Ihi
        Gn = Phi + np.maximum(a, b) + np.maximum(c, e)
        a, b, c, e = cm * Rglo, cm * Rghi, f * Iglo, f * Ighi
        dlo = Pglo + np.minimum(a, b) + np.minimum(c, e)
        dhi = Pghi + np.maximum(a, b) + np.maximum(c, e)
        E, Eg = (self.slacks(self.mag[cell], self.gmag[cell], self.m[cell], theta, Z)
                 if slack is None else slack)
        hw = 0.5 * (self.tau_p[cell, 1] - self.tau_p[cell, 0])
        spread = (np.maximum(np.abs(dlo), np.abs(dhi)) + Eg) * hw[:, None]
        return Gc, np.minimum(Gn, Gc + spread), E
