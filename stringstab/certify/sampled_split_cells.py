"""Cells of the split form: bounds of F from below and of G from above over cells, at any θ.

The split form of :mod:`stringstab.certify.sampled_split` compares the follower's factor F,
minimised over (τ, T*), with the predecessor's G, maximised over τ_p and the ends of the
delay's pieces.  :class:`FollowerCells` and :class:`PredecessorCells` hold, one row per cell,
their coefficients in ρ with derivative enclosures over the cell
(:class:`~stringstab.certify.interval.IntervalAD`, computed in the stacked arrays of
:class:`~stringstab.certify.interval_stack.StackedAD`) as arrays, and bound F and G over each
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

from .interval_stack import StackedAD
from .sampled_split import follower_stacked, predecessor_stacked
from .verdicts import ROUNDOFF_SLACK

__all__ = ["CellCache", "FollowerCells", "PredecessorCells", "halves"]

Array = npt.NDArray[np.float64]

#: The refinement's stragglers (:class:`CellCache`): a round that needs at most this many
#: new cells computes them with their descendants _AHEAD_DEPTH halvings deep; requests of
#: more than _LOOKUP_LIMIT cells are not looked up (the search's first, wide rounds).
_AHEAD_LIMIT = 48
_AHEAD_DEPTH = 2
_AROUND_DEPTH = 1
_LOOKUP_LIMIT = 512


def _stacked(polys: list[list[StackedAD]], J: int = 3) -> Array:
    """Polynomials' coefficients as one array (polynomial, J, 3, 2 + d, n), zero-padded to J.

    Axis 2 is (lower end, upper end, magnitude), axis 3 the centre, the enclosure and the
    derivatives (:class:`~stringstab.certify.interval_stack.StackedAD`).
    """
    v0 = polys[0][0]
    S = np.zeros((len(polys), J, 3, 2 + v0.d, v0.X.shape[2]))
    for i, poly in enumerate(polys):
        for j, v in enumerate(poly):
            S[i, j] = v.full()
    return S


def _stacked_magnitudes(S: Array) -> tuple[Array, Array, Array]:
    """:func:`_magnitudes` of :func:`_stacked` polynomials, each (polynomial, J, n)."""
    a = np.maximum(np.abs(S[:, :, 0, 1]), np.abs(S[:, :, 1, 1])) + ROUNDOFF_SLACK * S[:, :, 2, 1]
    mag = np.maximum(S[:, :, 2, 0], S[:, :, 2, 1])
    gmag = S[:, :, 2, 2]
    for i in range(3, S.shape[3]):  # Σ over the parameters, in order
        gmag = gmag + S[:, :, 2, i]
    return a, mag, gmag


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
        S = _stacked([follower_stacked(kx[owner], kv[owner], H=H, tau=tau, headway=headway)])
        V = S[0][:, [0, 0, 0, 1, 0, 1], [0, 1, 2, 2, 3, 3]]  # c, lo, glo0, ghi0, glo1, ghi1: (J, 6, n)
        return cls(owner, tau, headway, np.ascontiguousarray(V.transpose(2, 1, 0)),
                   *(np.ascontiguousarray(x[0].T) for x in _stacked_magnitudes(S)))

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
        me = np.array(ends, dtype=float).reshape(-1, 2)[end]  # (m, ε) of each cell
        m, eps = me[:, 0], me[:, 1]
        S = _stacked(list(predecessor_stacked(kx[gains], kv[gains], ka[gains], H=H,
                                              tau_p=tau_p, eps=eps)))
        # P_G's c, hi, glo, ghi; Y_r's and Y_i's c, lo, hi, glo, ghi: (14, J, n)
        V = S[[0] * 4 + [1] * 5 + [2] * 5, :, [0, 1, 0, 1] + [0, 0, 1, 0, 1] * 2,
              [0, 1, 2, 2] + [0, 1, 1, 2, 2] * 2]
        return cls(owner, tau_p, end, m, np.ascontiguousarray(V.transpose(2, 0, 1)),
                   *(np.ascontiguousarray(x.transpose(2, 0, 1)) for x in _stacked_magnitudes(S)))

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


def halves(cells: Array) -> tuple[Array, Array]:
    """The two halves of cells (k, 2) at their midpoints, as the split search halves them.

    Parameters
    ----------
    cells : ndarray, shape (k, 2)
        Intervals [lo, hi] along one parameter.

    Returns
    -------
    tuple of ndarray
        ([lo, mid], [mid, hi]) per row, the midpoint computed as the split search does.
    """
    mid = cells.mean(axis=1)
    a, b = cells.copy(), cells.copy()
    a[:, 1] = b[:, 0] = mid
    return a, b


def _descend_f(o: Any, t: Array, h: Array, depth: int,
               own: bool) -> tuple[Any, Array, Array]:
    """Follower cells and their halves along τ and T* (of positive width), ``depth`` deep.

    The cells themselves are included when ``own``.  Rows may repeat (the caller dedupes).
    """
    lo, lt, lh = o, t, h
    out_o, out_t, out_h = ([lo], [lt], [lh]) if own else ([lo[:0]], [lt[:0]], [lh[:0]])
    for _ in range(depth):
        st = lt[:, 1] > lt[:, 0]
        sh = lh[:, 1] > lh[:, 0]
        ta, tb = halves(lt[st])
        ha, hb = halves(lh[sh])
        lo = np.concatenate([lo[st], lo[st], lo[sh], lo[sh]])
        lt = np.concatenate([ta, tb, lt[sh], lt[sh]])
        lh = np.concatenate([lh[st], lh[st], ha, hb])
        out_o.append(lo)
        out_t.append(lt)
        out_h.append(lh)
    return np.concatenate(out_o), np.concatenate(out_t), np.concatenate(out_h)


def _descend_g(g: Any, t: Array, e: Any, depth: int, own: bool) -> tuple[Any, Array, Any]:
    """Predecessor cells and their halves along τ_p (of positive width), ``depth`` deep."""
    lg, lt, le = g, t, e
    out_g, out_t, out_e = ([lg], [lt], [le]) if own else ([lg[:0]], [lt[:0]], [le[:0]])
    for _ in range(depth):
        st = lt[:, 1] > lt[:, 0]
        ta, tb = halves(lt[st])
        lg = np.concatenate([lg[st], lg[st]])
        lt = np.concatenate([ta, tb])
        le = np.concatenate([le[st], le[st]])
        out_g.append(lg)
        out_t.append(lt)
        out_e.append(le)
    return np.concatenate(out_g), np.concatenate(out_t), np.concatenate(out_e)


class CellCache:
    """Cells of the few items left in the search, computed ahead (the refinement's stragglers).

    Each refinement round builds its new cells in one call of :meth:`FollowerCells.of` and one
    of :meth:`PredecessorCells.of`, whose cost is mostly fixed (a few hundred operations of
    interval arithmetic on small arrays) when few cells are new: the last rounds, for one or
    two triples, cost as much as the first.  When a round needs at most :data:`_AHEAD_LIMIT`
    new cells, this cache computes them together with their halves and quarters along every
    parameter of positive width (the cells any of the next two rounds can ask for), in the
    same one call, and serves the later rounds' requests from them.  Each row of a cell is a
    function of that cell's bounds and gains only (the arithmetic is elementwise), so a cell
    served from the cache is bit for bit the cell the round would have built: the search and
    its verdicts are unchanged.
    """

    def __init__(self, kx: Array, kv: Array, ka: Array, H: float,
                 ends: list[tuple[int, float]]) -> None:
        self.kx, self.kv, self.ka, self.H, self.ends = kx, kv, ka, H, ends
        self.f_chunks: list[FollowerCells] = []
        self.f_index: dict[tuple[float, ...], tuple[int, int]] = {}
        self.g_chunks: list[PredecessorCells] = []
        self.g_index: dict[tuple[float, ...], tuple[int, int]] = {}

    @staticmethod
    def _assemble(chunks: list[Any], loc: list[tuple[int, int]]) -> Any:
        """The rows ``loc`` (chunk, row) of the chunks, in order."""
        ch = np.array([c for c, _ in loc], dtype=np.intp)
        rw = np.array([r for _, r in loc], dtype=np.intp)
        used = np.unique(ch)
        if used.size == 1:
            return chunks[int(used[0])].take(rw)
        parts, order = [], []
        for c in used:
            sel = np.flatnonzero(ch == c)
            parts.append(chunks[int(c)].take(rw[sel]))
            order.append(sel)
        pos = np.empty(len(loc), dtype=np.intp)
        pos[np.concatenate(order)] = np.arange(len(loc))
        cat = type(parts[0])(*(np.concatenate([getattr(x, f) for x in parts])
                               for f in parts[0].__dataclass_fields__))
        return cat.take(pos)

    def follower(self, owner: npt.NDArray[np.intp], tau: Array, headway: Array,
                 around: tuple[Any, Array, Array] | None = None) -> FollowerCells:
        """:meth:`FollowerCells.of` of the cells, from the cache or computed (and ahead).

        ``around``: the items' cells kept this round (owner, τ, T*), whose halves and
        quarters the next rounds may ask for: computed ahead with the new cells'.
        """
        if owner.size == 0:  # no new cell: nothing to compute (the arrays' shapes only)
            return FollowerCells(owner, tau, headway, np.zeros((0, 6, 3)),
                                 *(np.zeros((0, 3)) for _ in range(3)))
        if owner.size > _LOOKUP_LIMIT or (owner.size > _AHEAD_LIMIT and not self.f_index):
            # too many to look up, or more than _AHEAD_LIMIT and none computed yet (all new)
            return FollowerCells.of(owner, self.kx, self.kv, H=self.H, tau=tau, headway=headway)
        keys = list(zip(owner.tolist(), *tau.T.tolist(), *headway.T.tolist()))
        miss = np.array([i for i, k in enumerate(keys) if k not in self.f_index],
                        dtype=np.intp)
        if miss.size > _AHEAD_LIMIT:
            return FollowerCells.of(owner, self.kx, self.kv, H=self.H, tau=tau, headway=headway)
        if miss.size:
            o, t, h = _descend_f(owner[miss], tau[miss], headway[miss], _AHEAD_DEPTH, True)
            if around is not None and around[0].size <= _LOOKUP_LIMIT:
                ao, at_, ah = _descend_f(*around, _AROUND_DEPTH, False)
                o, t, h = np.concatenate([o, ao]), np.concatenate([t, at_]), np.concatenate([h, ah])
            # each cell once, in the order first seen (a cell's row depends on it alone)
            first: dict[tuple[float, ...], int] = {}
            for i, k in enumerate(zip(o.tolist(), *t.T.tolist(), *h.T.tolist())):
                first.setdefault(k, i)
            u = np.fromiter(first.values(), dtype=np.intp, count=len(first))
            new = FollowerCells.of(o[u], self.kx, self.kv, H=self.H, tau=t[u], headway=h[u])
            c = len(self.f_chunks)
            self.f_chunks.append(new)
            for r, k in enumerate(first):
                self.f_index.setdefault(k, (c, r))
        return self._assemble(self.f_chunks, [self.f_index[k] for k in keys])  # type: ignore[no-any-return]

    def predecessor(self, owner: npt.NDArray[np.intp], gains: npt.NDArray[np.intp],
                    tau_p: Array, end: npt.NDArray[np.intp],
                    around: tuple[Any, Array, Any] | None = None) -> PredecessorCells:
        """:meth:`PredecessorCells.of` of the cells, from the cache or computed (and ahead).

        ``around``: the items' cells kept this round (gains, τ_p, end), as in :meth:`follower`.
        """
        def compute(o: npt.NDArray[np.intp], g: npt.NDArray[np.intp], t: Array,
                    e: npt.NDArray[np.intp]) -> PredecessorCells:
            return PredecessorCells.of(o, g, self.kx, self.kv, self.ka, H=self.H, tau_p=t,
                                       end=e, ends=self.ends)

        if owner.size == 0:
            return PredecessorCells(owner, tau_p, end, np.zeros(0), np.zeros((0, 14, 3)),
                                    *(np.zeros((0, 3, 3)) for _ in range(3)))
        if owner.size > _LOOKUP_LIMIT or (owner.size > _AHEAD_LIMIT and not self.g_index):
            return compute(owner, gains, tau_p, end)
        keys = list(zip(gains.tolist(), *tau_p.T.tolist(), end.tolist()))
        miss = np.array([i for i, k in enumerate(keys) if k not in self.g_index],
                        dtype=np.intp)
        if miss.size > _AHEAD_LIMIT:
            return compute(owner, gains, tau_p, end)
        if miss.size:
            g, t, e = _descend_g(gains[miss], tau_p[miss], end[miss], _AHEAD_DEPTH, True)
            if around is not None and around[0].size <= _LOOKUP_LIMIT:
                ag, at_, ae = _descend_g(*around, _AROUND_DEPTH, False)
                g, t, e = np.concatenate([g, ag]), np.concatenate([t, at_]), np.concatenate([e, ae])
            first_g: dict[tuple[float, ...], int] = {}
            for i, k in enumerate(zip(g.tolist(), *t.T.tolist(), e.tolist())):
                first_g.setdefault(k, i)
            u = np.fromiter(first_g.values(), dtype=np.intp, count=len(first_g))
            new = compute(g[u], g[u], t[u], e[u])
            c = len(self.g_chunks)
            self.g_chunks.append(new)
            for r, k in enumerate(first_g):
                self.g_index.setdefault(k, (c, r))
        out: PredecessorCells = self._assemble(self.g_chunks, [self.g_index[k] for k in keys])
        out.owner = owner.copy()
        return out

