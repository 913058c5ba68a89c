r"""Certificates over cells of gains: every K of a box [k_x] × [k_v] × [k_a] at once.

The gain repair of training (:mod:`stringstab.tuning.repair`) asks at every control step whether
the proposed gains are certified, by the continuous certificate and the sampled-data one.  A
cell of its lattice proven here needs no certificate call for any gain inside it: a lookup
answers.  :func:`certified_cells` proves cells of the lattice of
:func:`stringstab.certify.grid.lattice` for one loop, the gains ranging over each cell:

* **continuous** (:mod:`stringstab.certify.continuous`): Γ is internally stable over the cell
  when it is surely so at its 8 corners (the Hurwitz conditions k_x > 0 and
  k_v + (T* − τ)k_x > 0 are linear in K, so their minimum over a cell is at a corner), and
  g(ω) = τ²ω⁴ + aω² + b + c_x cos δω − c_v ω sin δω ≥ 0 for every member: a, b, c_x, c_v
  (polynomials in K) carry derivative enclosures over the cell
  (:class:`~stringstab.certify.interval.IntervalAD`), g is bounded below by the better of the
  interval extension and the mean-value form, and the branch and bound of
  :mod:`stringstab.certify.branch_bound` runs on [0, Ω] with the tail bound Ω and the curvature
  bound taken at the cell's worst coefficients (as the box certificate of
  :mod:`stringstab.certify.robust_continuous` does over parameters);
* **sampled data** (:mod:`stringstab.certify.sampled`, with ``sample_time``): the w-form
  coefficients of :func:`stringstab.certify.zoh.build` with the gains as the cell's variables;
  Δ is Schur over the cell when each Schur condition's lower bound clears its band, and g_H ≥ 0
  on [0, π] by the branch and bound on the mean-value bound of
  :func:`stringstab.certify.sampled_frequency.margin_over_cells`.

Both bounds hold for every member, so a proven cell is a certificate for each gain in it (the
round-off slacks of the point certificates apply).  A cell that is not proven says nothing:
its gains go to the point certificates.

References
----------
IDL paper, Definition 1 (eq 10), eq 11; R. E. Moore, R. B. Kearfott, M. J. Cloud,
*Introduction to Interval Analysis*, SIAM (2009), §6.4 (the mean-value form).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import numpy.typing as npt

from ..params import Params
from . import margin as _margin
from .branch_bound import branch_and_bound
from .criteria import hurwitz_bands_kernel
from .interval import Interval, IntervalAD
from .sampled_curvature import curvature_bound
from .sampled_split import vander
from .schur import SCHUR_RTOL
from .verdicts import CERTIFIED, ROUNDOFF_SLACK
from .zoh import build, primitives, schur_terms, split_delay

__all__ = ["CertifiedCells", "certified_cells", "continuous_cells", "sampled_cells"]

Array = npt.NDArray[np.float64]

#: Cells per vectorised block (bounds memory).
BLOCK = 4096
#: :class:`CertifiedCells` proves its cells by blocks of this many cells per side.
BLOCK_SIDE = 8


def _gain_variables(K_lo: Array, K_hi: Array) -> tuple[IntervalAD, IntervalAD, IntervalAD]:
    """k_x, k_v, k_a ranging over the cells [K_lo, K_hi] (rows), as derivative enclosures."""
    return tuple(IntervalAD.variable(K_lo[:, i], K_hi[:, i], i, 3)  # type: ignore[return-value]
                 for i in range(3))


def continuous_cells(K_lo: Array, K_hi: Array, p: Params, *, n_grid: int = 64,
                     max_rounds: int = 12, max_intervals: int = 256) -> npt.NDArray[np.bool_]:
    """Which cells [K_lo, K_hi] the continuous certificate holds on, for every gain in them.

    Parameters
    ----------
    K_lo, K_hi : ndarray, shape (n, 3)
        The cells' lower and upper corners (k_x, k_v, k_a).
    p : Params
        τ, δ, T* (s).
    n_grid, max_rounds, max_intervals : int
        Branch-and-bound budgets (an undecided cell is simply not proven).

    Returns
    -------
    ndarray of bool, shape (n,)
        True where every gain of the cell is certified (module docstring).
    """
    n = K_lo.shape[0]
    out = np.zeros(n, dtype=bool)
    if not n:
        return out
    # internal stability: conditions linear in (k_x, k_v), surely positive at the corners
    sure = np.ones(n, dtype=bool)
    for cx_hi in (False, True):
        for cv_hi in (False, True):
            kx = K_hi[:, 0] if cx_hi else K_lo[:, 0]
            kv = K_hi[:, 1] if cv_hi else K_lo[:, 1]
            sure &= hurwitz_bands_kernel(kx, kv, tau=p.tau, headway=p.headway)[0]
    idx = np.flatnonzero(sure)
    if not idx.size:
        return out
    Kx, Kv, Ka = _gain_variables(K_lo[idx], K_hi[idx])
    c = Kv + Kx * p.headway
    a = 1.0 - (2.0 * p.tau) * c - Ka * Ka
    b = c * c - 2.0 * Kx - Kv * Kv
    cx = 2.0 * (Kx * Ka)
    cv = 2.0 * (Kv * Ka)
    t2 = p.tau * p.tau
    hw = 0.5 * (K_hi[idx] - K_lo[idx])

    def absmax(v: IntervalAD) -> Array:
        return np.maximum(np.abs(v.r.lo), np.abs(v.r.hi)) + ROUNDOFF_SLACK * v.r.mag

    A, Cx, Cv = absmax(a), absmax(cx), absmax(cv)
    Om = _margin.tail_bound(np.full(idx.size, t2), a.r.lo, b.r.lo, Cx, Cv)
    mag = [np.maximum(v.c.mag, v.r.mag) for v in (a, b, cx, cv)]

    def col(v: Array, i: npt.NDArray[np.intp]) -> Array:
        return v[i][:, None]

    coefs = (a, b, cx, cv)

    def evaluate(i: npt.NDArray[np.intp], X: Array) -> tuple[Array, Array, Array, Array]:
        w2 = X * X
        basis: list[Array] = [w2, np.ones_like(X), np.cos(p.delta * X),
                              -X * np.sin(p.delta * X)]
        G = t2 * w2 * w2
        nat = t2 * w2 * w2
        scale = t2 * w2 * w2
        for v, f, m in zip(coefs, basis, mag):
            G = G + col(v.c.lo, i) * f
            nat = nat + np.minimum(col(v.r.lo, i) * f, col(v.r.hi, i) * f)
            scale = scale + col(m, i) * np.abs(f)
        spread = np.zeros_like(X)
        for d in range(3):  # the enclosure of ∂g/∂k_d = Σ_j (∂coef_j/∂k_d) f_j over the cell
            dlo, dhi, gmag = (np.zeros_like(X) for _ in range(3))
            for v, f in zip(coefs, basis):
                x, y = col(v.g[d].lo, i) * f, col(v.g[d].hi, i) * f
                dlo, dhi = dlo + np.minimum(x, y), dhi + np.maximum(x, y)
                gmag = gmag + col(np.asarray(v.g[d].mag) * np.ones(idx.size), i) * np.abs(f)
            spread = spread + (np.maximum(np.abs(dlo), np.abs(dhi)) + ROUNDOFF_SLACK * gmag) \
                * col(hw[:, d], i)
        low = np.maximum(nat, G - spread)
        M = _margin.curvature_bound(X[:, 1:], (t2, col(A, i), 0.0, col(Cx, i), col(Cv, i)),
                                    p.delta)
        return G, np.minimum(low, G), ROUNDOFF_SLACK * scale, M

    bb = branch_and_bound(idx.size, evaluate, right=Om, n_grid=n_grid, max_rounds=max_rounds,
                          max_intervals=max_intervals)
    out[idx] = bb.status == CERTIFIED
    return out


def _const(v: Interval, like: IntervalAD) -> IntervalAD:
    """A point quantity of the loop as a constant of the cells' arithmetic."""
    z = like.c.const(0.0)
    c = Interval(np.broadcast_to(v.lo, like.c.lo.shape).copy(), None,
                 np.broadcast_to(np.asarray(v.mag), like.c.lo.shape).copy())
    return IntervalAD(c, c, tuple(z for _ in like.g), True)


def sampled_cells(K_lo: Array, K_hi: Array, p: Params, H: float, tau_prev: float | None = None,
                  *, max_rounds: int = 12, max_intervals: int = 256) -> npt.NDArray[np.bool_]:
    """Which cells [K_lo, K_hi] the sampled-data certificate holds on, for every gain in them.

    Parameters
    ----------
    K_lo, K_hi : ndarray, shape (n, 3)
        The cells' lower and upper corners (k_x, k_v, k_a).
    p : Params
        τ, δ, T* (s).
    H : float
        Sample time, s.
    tau_prev : float, optional
        The predecessor's lag (default τ).
    max_rounds, max_intervals : int
        Branch-and-bound budgets (an undecided cell is simply not proven).

    Returns
    -------
    ndarray of bool, shape (n,)
        True where every gain of the cell is certified (module docstring).
    """
    n = K_lo.shape[0]
    out = np.zeros(n, dtype=bool)
    if not n:
        return out
    tp = p.tau if tau_prev is None else tau_prev
    m, eps = split_delay(p.delta, H)
    one = np.ones(n)
    t, t_p, e = p.tau * one, tp * one, eps * one
    q0 = primitives(one, one, one, H=H, tau=(t, t), tau_p=(t_p, t_p), eps=(e, e), c=(one, one))
    Kx, Kv, Ka = _gain_variables(K_lo, K_hi)
    q: dict[str, Any] = {k: _const(q0[k], Kx) for k in
                         ("T", "Tp", "f1", "p2", "p3", "f1p", "p2p", "p3p", "ell1", "cm")}
    q.update(K_x=Kx, K_v=Kv, K_a=Ka, Cc=Kv + Kx * p.headway)
    co = build(q, H)
    hw = 0.5 * (K_hi - K_lo)
    # Schur over the cell: every condition's lower bound (interval or mean-value) above its band
    sure = np.ones(n, dtype=bool)
    for term in schur_terms(co.delta):
        spread = sum((np.maximum(np.abs(g.lo), np.abs(g.hi)) + ROUNDOFF_SLACK * g.mag)
                     * hw[:, d] for d, g in enumerate(term.g))
        sure &= np.maximum(term.r.lo, term.c.lo - spread) > SCHUR_RTOL * term.r.mag
    idx = np.flatnonzero(sure)
    if not idx.size:
        return out
    V, mags, grads, a = _stacked(co, idx)
    hw = hw[idx]
    mf = float(m)

    def evaluate(i: npt.NDArray[np.intp], X: Array) -> tuple[Array, Array, Array, Array]:
        W = np.matmul(V[i], vander(X))  # (r, 26, k): the fields of _FIELDS at each θ
        st = np.sin(X)
        cm, f = np.cos(mf * X), np.sin(mf * X) * st
        Pc, Plo = W[:, 0], W[:, 1]
        Rc, Rlo, Rhi = W[:, 8], W[:, 9], W[:, 10]
        Ic, Ilo, Ihi = W[:, 17], W[:, 18], W[:, 19]
        G = Pc + cm * Rc + f * Ic
        nat = (Plo + np.minimum(cm * Rlo, cm * Rhi) + np.minimum(f * Ilo, f * Ihi))
        M = np.matmul(np.concatenate([mags[i], grads[i]], axis=1), vander(X))  # (r, 6, k)
        m1, ast = 1.0 + mf, np.abs(st)
        E = ROUNDOFF_SLACK * m1 * (M[:, 0] + m1 * (M[:, 1] + ast * M[:, 2]))
        Eg = ROUNDOFF_SLACK * m1 * (M[:, 3] + m1 * (M[:, 4] + ast * M[:, 5]))
        spread = np.zeros_like(X)
        for d in range(3):  # the enclosure of ∂g_H/∂k_d over the cell
            x, y = cm * W[:, 11 + d], cm * W[:, 14 + d]
            u, v = f * W[:, 20 + d], f * W[:, 23 + d]
            dlo = W[:, 2 + d] + np.minimum(x, y) + np.minimum(u, v)
            dhi = W[:, 5 + d] + np.maximum(x, y) + np.maximum(u, v)
            spread = spread + (np.maximum(np.abs(dlo), np.abs(dhi)) + Eg) * hw[i, d][:, None]
        low = np.maximum(nat, G - spread)
        aP, aYr, aYi = ([a[i, k, j] for j in range(3)] for k in range(3))
        curv = curvature_bound(aP, aYr, aYi, np.full(i.size, mf), X[:, :-1], X[:, 1:])
        return G, np.minimum(low, G), E, curv

    bb = branch_and_bound(idx.size, evaluate, right=np.full(idx.size, np.pi),
                          n_grid=64 + 8 * m, max_rounds=max_rounds,
                          max_intervals=max_intervals)
    out[idx] = bb.status == CERTIFIED
    return out


def _stacked(co: Any, idx: npt.NDArray[np.intp]) -> tuple[Array, Array, Array, Array]:
    """P, Y_r, Y_i over the cells ``idx`` as arrays for :func:`sampled_cells`.

    Returns the fields (n, 26, 3): P's centre, lower end and gradient ends (3 + 3), then
    Y_r's and Y_i's centre, ends and gradient ends; the value and gradient magnitudes
    (n, 3, 3) each; and the |coefficient| bounds of the enclosures (n, 3, 3).
    """
    n = idx.size
    V = np.zeros((n, 26, 3))
    mags, grads, a = (np.zeros((n, 3, 3)) for _ in range(3))
    for k, (poly, base) in enumerate(((co.P, 0), (co.Yr, 8), (co.Yi, 17))):
        for j, v in enumerate(poly):
            c, r = v.c.take(idx), v.r.take(idx)
            g = [gi.take(idx) for gi in v.g]
            ends = [c.lo, r.lo] if k == 0 else [c.lo, r.lo, r.hi]
            for f, x in enumerate(ends + [gi.lo for gi in g] + [gi.hi for gi in g]):
                V[:, base + f, j] = x
            mags[:, k, j] = np.maximum(c.mag, r.mag)
            grads[:, k, j] = sum(np.broadcast_to(np.asarray(gi.mag), (n,)) for gi in g)
            a[:, k, j] = np.maximum(np.abs(r.lo), np.abs(r.hi)) + ROUNDOFF_SLACK * r.mag
    return V, mags, grads, a


def certified_cells(lo: float, hi: float, n: int, p: Params, *,
                    sample_time: float | None = None,
                    candidates: npt.NDArray[np.bool_] | None = None) -> npt.NDArray[np.bool_]:
    """The cells of the lattice ``linspace(lo, hi, n)``³ on which the certificates hold.

    Parameters
    ----------
    lo, hi : float
        The gain box of every gain.
    n : int
        Lattice points per axis (``np.linspace(lo, hi, n)``); the cells are the (n − 1)³
        boxes between neighbours, cell (i, j, k) = [g_i, g_{i+1}] × [g_j, g_{j+1}] ×
        [g_k, g_{k+1}].
    p : Params
        τ, δ, T* (s).
    sample_time : float, optional
        Also require the sampled-data certificate at this period H, s.
    candidates : ndarray of bool, shape (n − 1, n − 1, n − 1), optional
        Only these cells are tried (e.g. those whose 8 corners are certified points).

    Returns
    -------
    ndarray of bool, shape (n − 1, n − 1, n − 1)
        True where every gain of the cell is certified by the continuous certificate (and
        the sampled-data one with ``sample_time``).

    Examples
    --------
    >>> cells = certified_cells(-2.0, 2.0, 9, Params(0.1, 0.2, 1.1))
    >>> cells.shape, bool(cells.any())
    ((8, 8, 8), True)
    """
    g = np.linspace(float(lo), float(hi), int(n))
    shape = (n - 1, n - 1, n - 1)
    cand = np.ones(shape, dtype=bool) if candidates is None else np.asarray(candidates, bool)
    flat = np.flatnonzero(cand.ravel())
    ijk = np.stack(np.unravel_index(flat, shape), axis=1)
    proven = np.zeros(flat.size, dtype=bool)
    for s in range(0, flat.size, BLOCK):
        b = slice(s, s + BLOCK)
        K_lo, K_hi = g[ijk[b]], g[ijk[b] + 1]
        ok = continuous_cells(K_lo, K_hi, p)
        if sample_time is not None and ok.any():
            j = np.flatnonzero(ok)
            ok[j] = sampled_cells(K_lo[j], K_hi[j], p, sample_time)
        proven[b] = ok
    out = np.zeros(int(np.prod(shape)), dtype=bool)
    out[flat] = proven
    return out.reshape(shape)


class CertifiedCells:
    """The cells of a lattice proven on demand: a lookup that certifies the gains in them.

    :meth:`contains` finds the cell of each gain triple (the exact comparison with the
    lattice's own numbers: a gain on a face belongs to both cells, and either proof covers
    it) and answers True for the gains in proven cells.  The cells are proven by blocks of
    :data:`BLOCK_SIDE`³ cells, a block the first time a gain falls in it, each block in a
    call of its own (:func:`continuous_cells`, then :func:`sampled_cells` with a sample time)
    on its candidate cells: what a cell is, proven or not, depends on its block alone, never
    on which gains were asked about before (a resumed training run repairs as the
    uninterrupted one).

    Parameters
    ----------
    lo, hi : float
        The gain box of every gain.
    n : int
        Lattice points per axis.
    params : Params
        τ, δ, T* (s).
    sample_time : float, optional
        Also require the sampled-data certificate at this period H, s.
    candidates : ndarray of bool, shape (n − 1, n − 1, n − 1), optional
        The only cells worth proving (e.g. those whose 8 corners are certified points);
        default all.

    Attributes
    ----------
    proven, refused, blocks : int
        Cells proven and tried without success, and blocks done, so far.
    seconds : float
        Wall time spent proving, so far.

    Examples
    --------
    >>> cells = CertifiedCells(-2.0, 2.0, 81, Params(0.1, 0.2, 1.1))
    >>> cells.contains([[1.2, 0.5, 0.6], [0.9, -0.5, 1.1]]).tolist()
    [True, False]
    """

    def __init__(self, lo: float, hi: float, n: int, params: Params, *,
                 sample_time: float | None = None,
                 candidates: npt.NDArray[np.bool_] | None = None) -> None:
        self.g = np.linspace(float(lo), float(hi), int(n))
        self.n = int(n)
        self.params = params
        self.sample_time = sample_time
        m = self.n - 1
        self.candidates = (np.ones(m**3, dtype=bool) if candidates is None
                           else np.asarray(candidates, dtype=bool).reshape(-1))
        self.proven_cells = np.zeros(m**3, dtype=bool)
        b = -(-m // BLOCK_SIDE)
        self.done = np.zeros(b**3, dtype=bool)
        #: Per cell: a candidate whose block is not done yet (what :meth:`contains` proves).
        self.pending = self.candidates.copy()
        self.proven = self.refused = self.blocks = 0
        self.seconds = 0.0

    def cells_of(self, K: npt.ArrayLike) -> tuple[npt.NDArray[np.intp], npt.NDArray[np.bool_]]:
        """The (i, j, k) of the cell of each row of K, and whether the row is in the box.

        Parameters
        ----------
        K : array_like, shape (r, 3)
            Gain triples.

        Returns
        -------
        (ndarray of int, ndarray of bool)
            Cell indices, shape (r, 3) (clipped into the lattice for rows outside the box),
            and the rows inside.
        """
        K = np.asarray(K, dtype=float).reshape(-1, 3)
        g, m = self.g, self.n - 1
        i = np.searchsorted(g, K, side="right")
        i -= 1
        np.maximum(i, 0, out=i)  # clipped into [0, m − 1] (two ufuncs: cheaper than np.clip)
        np.minimum(i, m - 1, out=i)
        return i, np.asarray(((g[i] <= K) & (K <= g[i + 1])).all(axis=1))

    def _prove_block(self, block: int) -> None:
        """Prove the candidate cells of one block (a call of its own)."""
        t0 = time.perf_counter()
        m, b = self.n - 1, -(-(self.n - 1) // BLOCK_SIDE)
        bi = np.array(np.unravel_index(block, (b, b, b)))
        r = [np.arange(x * BLOCK_SIDE, min((x + 1) * BLOCK_SIDE, m)) for x in bi]
        ijk = np.stack(np.meshgrid(*r, indexing="ij"), axis=-1).reshape(-1, 3)
        flat = (ijk[:, 0] * m + ijk[:, 1]) * m + ijk[:, 2]
        keep = self.candidates[flat]
        self.pending[flat] = False
        ijk, flat = ijk[keep], flat[keep]
        self.done[block] = True
        self.blocks += 1
        if flat.size:
            K_lo, K_hi = self.g[ijk], self.g[ijk + 1]
            ok = continuous_cells(K_lo, K_hi, self.params)
            if self.sample_time is not None and ok.any():
                j = np.flatnonzero(ok)
                ok[j] = sampled_cells(K_lo[j], K_hi[j], self.params, self.sample_time)
            self.proven_cells[flat] = ok
            self.proven += int(ok.sum())
            self.refused += int((~ok).sum())
        self.seconds += time.perf_counter() - t0

    def contains(self, K: npt.ArrayLike) -> npt.NDArray[np.bool_]:
        """Which rows of K lie in a proven cell (certified by the cell's proof).

        Parameters
        ----------
        K : array_like, shape (r, 3)
            Gain triples.

        Returns
        -------
        ndarray of bool, shape (r,)
            True where the row's cell is proven (every gain in it certified).
        """
        ijk, inside = self.cells_of(K)
        m, b = self.n - 1, -(-(self.n - 1) // BLOCK_SIDE)
        flat = (ijk[:, 0] * m + ijk[:, 1]) * m + ijk[:, 2]
        todo = inside & self.pending[flat]  # candidate cells of blocks not done yet
        if todo.any():  # (most calls: every block near the rows already done)
            bl = ijk[todo] // BLOCK_SIDE
            for blk in np.unique((bl[:, 0] * b + bl[:, 1]) * b + bl[:, 2]):
                self._prove_block(int(blk))
        return np.asarray(inside & self.proven_cells[flat])
