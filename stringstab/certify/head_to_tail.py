r"""Head-to-tail certificates of heterogeneous strings: sup_ω ∏_i |Γ_i(jω)| ≤ 1, soundly.

A string of N followers, vehicle i with its own gains (k_x, k_v, k_a)_i and parameters
(τ, δ, T*)_i, carries a disturbance of the leader's acceleration to the last follower through
∏_i Γ_i(s) (each Γ_i of IDL eq 11).  The string is certified *head to tail* when every vehicle
is internally stable and sup_{ω≥0} ∏_i |Γ_i(jω)| ≤ 1, with the exact delays.

**The margin.**  With d_i = |D_i(jω)|², n_i = |N_i(jω)|² and the one-vehicle margin
g_i = (d_i − n_i)/ω² (:mod:`stringstab.certify.margin`), the telescoping identity

.. math::
    \prod_i d_i − \prod_i n_i
      = \sum_k \Big(\prod_{i<k} n_i\Big)(d_k − n_k)\Big(\prod_{i>k} d_i\Big)
      = ω^2 G(ω),\qquad
    G(ω) = \sum_k \Big(\prod_{i<k} n_i\Big)\, g_k \Big(\prod_{i>k} d_i\Big)

(each term of the sum replaces one more d by an n, so consecutive terms cancel) removes the
tangency at ω = 0 exactly (every Γ_i(0) = 1): at ω > 0, ∏_i |Γ_i(jω)| ≤ 1 iff G(ω) ≥ 0, and
G(0) = Σ_k Ψ3_k ∏_{i≠k} k_{x,i}².  Every factor may be scaled by its own constant c_i > 0
(n_i, d_i and g_i alike), which scales G by ∏ c_i and keeps its sign; c_i is chosen so that the
products neither overflow nor underflow (:func:`normalisation`).

**The decision** is the one branch and bound (:mod:`stringstab.certify.branch_bound`) on G:

1. *tail*: each g_k > 0 beyond its own Ω_k (:func:`stringstab.certify.margin.tail_bound`), and
   then d_k = n_k + ω²g_k > 0, so every term of G is ≥ 0 and the first one > 0: G > 0 beyond
   Ω = max_k Ω_k;
2. *body*: on [l, r] ⊂ [0, Ω], G ≥ min(G(l), G(r)) − M h²/8 with M ≥ |G''| on [l, r] from
   second-order jets on intervals (:mod:`stringstab.certify.interval_jets`): the real and
   imaginary parts of N_i, D_i (the generated ``gamma_parts``) and g_i (the generated
   ``margin_from_coefficients``) are evaluated on jets, and G is assembled from them by the
   same telescoping sum;
3. *round-off*: the parts of each factor — Re and Im of N_i and D_i, and g_i — carry their
   magnitude companions (the same arithmetic on absolute values,
   :class:`stringstab.certify.interval.Interval`) and the slack rule of the one-vehicle
   certificates, an error of at most ``ROUNDOFF_SLACK`` times it; n_i = (Re N_i)² + (Im N_i)²
   and d_i then have a *relative* error bound (:func:`square_sum`, both are ≥ 0), relative
   errors of a product add up (Higham §3.1), and the slack of G follows term by term
   (:func:`point_margin`).  A product of magnitude companions instead would multiply the
   factors' condition numbers and grow without need along the string.  The curvature
   bounds are rigorous by outward rounding (:class:`stringstab.certify.interval_jets.Enclosure`).

A point with G < −slack is a witness (∏|Γ_i| > 1 there, or near ω = 0 when it is at 0).  A
string whose vehicles are not all surely internally stable is not certified (one surely
unstable: ``not_certified``; one within the 10⁻¹² boundary band: ``inconclusive``).

The loop is an object with the parts the decision needs (:class:`ContinuousString` here,
:class:`stringstab.certify.head_to_tail_sampled.SampledString` for the sampled-data loop):
its items (strings of one length, as columns), its domain, the factors (n_i, d_i, g_i) at
points or on jets, and the internal stability of each item.  The branch and bound on them is
:func:`stringstab.certify.string_decision.decide`.

References
----------
IDL paper, Definition 1 (eq 10), eq 11 (Γ).
S. Stüdli, M. M. Seron, R. H. Middleton, "From vehicular platoons to general networked
systems: String stability and related concepts", Annual Reviews in Control 44 (2017) 157-172
(head-to-tail string stability of heterogeneous strings).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt

from ..derive import generated as _gen
from ..params import Params
from . import margin as _margin
from .criteria import hurwitz_bands_kernel
from .interval import Interval
from .interval_jets import Enclosure, Jet, jet_cos, jet_sin
from .verdicts import ROUNDOFF_SLACK

__all__ = [
    "MAX_VEHICLES",
    "ContinuousString",
    "Factor",
    "Index",
    "Parts",
    "StringArrays",
    "StringLoop",
    "Vehicle",
    "normalisation",
    "point_margin",
    "square_sum",
    "string_margin",
]

Array = npt.NDArray[np.float64]
Index = npt.NDArray[np.intp]

#: The longest string certified: the normalised products of ≤ 64 factors stay far inside the
#: floating-point range for ordinary gains (:func:`normalisation`), and the sub-strings of a
#: string (N(N − 1)/2 of them) stay a few thousand.
MAX_VEHICLES = 64


@dataclass(frozen=True)
class Vehicle:
    """One follower of a string: its eq-4 gains and its parameters (checked by the way in).

    Attributes
    ----------
    k_x, k_v, k_a : float
        Gains of IDL eq 4: k_x in 1/s², k_v in 1/s, k_a dimensionless.
    params : Params
        τ, δ, T* and the reaction delay θ_r (issue 25), s.
    name : str
        A label (the recorded car's name, ``"CAV"``, ...).
    """

    k_x: float
    k_v: float
    k_a: float
    params: Params
    name: str = ""

    @property
    def reaction_delay(self) -> float:
        """θ_r, s (``params.reaction_delay``)."""
        return float(self.params.reaction_delay)


@dataclass(frozen=True)
class StringArrays:
    """Strings of one length as arrays: row i is vehicle i of every string, column j string j.

    Attributes
    ----------
    kx, kv, ka, tau, delta, headway, reaction_delay : ndarray, shape (N, n)
        The gains and parameters of vehicle i (row) of string j (column).
    """

    kx: Array
    kv: Array
    ka: Array
    tau: Array
    delta: Array
    headway: Array
    reaction_delay: Array

    @property
    def length(self) -> int:
        """N, the vehicles per string."""
        return int(self.kx.shape[0])

    @property
    def count(self) -> int:
        """n, the strings."""
        return int(self.kx.shape[1])

    @staticmethod
    def of(strings: Sequence[Sequence[Vehicle]]) -> StringArrays:
        """The arrays of strings of one length.

        Parameters
        ----------
        strings : sequence of sequence of Vehicle
            n strings of N vehicles each.

        Returns
        -------
        StringArrays
        """
        def rows(get: Callable[[Vehicle], float]) -> Array:
            return np.array([[get(v) for v in s] for s in strings], dtype=float).T.copy()

        return StringArrays(rows(lambda v: v.k_x), rows(lambda v: v.k_v), rows(lambda v: v.k_a),
                            rows(lambda v: v.params.tau), rows(lambda v: v.params.delta),
                            rows(lambda v: v.params.headway), rows(lambda v: v.reaction_delay))


#: A factor (n_i, d_i, g_i) of the telescoping sum, as jets.
Factor = tuple[Any, Any, Any]


@dataclass
class Parts:
    """One vehicle's parts at points, as point intervals with magnitude companions.

    n_i = pre_n ((Re N)² + (Im N)²), d_i = pre_d ((Re D)² + (Im D)²) and g_i (a prefactor of
    None is 1).
    """

    re_n: Interval
    im_n: Interval
    re_d: Interval
    im_d: Interval
    g: Interval
    pre_n: Interval | None = None
    pre_d: Interval | None = None


class StringLoop(Protocol):
    """What :func:`decide` needs of a loop (continuous or sampled): see the module docstring."""

    arrays: StringArrays
    #: c_i of every vehicle (row) and item (column), :func:`normalisation`.
    scale: Array

    def right(self) -> Array:
        """The right end of each item's domain (Ω, or π on the unit circle)."""

    def parts(self, idx: Index, x: Interval) -> list[Parts]:
        """The parts of every vehicle of the items ``idx`` at the points ``x``."""

    def factors(self, idx: Index, x: Jet) -> list[Factor]:
        """(c_i n_i, c_i d_i, c_i g_i) of every vehicle of the items ``idx`` on the jet ``x``."""

    def stability(self) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
        """(surely internally stable, surely not) per item: every vehicle, any vehicle."""


def string_margin(factors: Sequence[Factor]) -> Any:
    """G = Σ_k (∏_{i<k} n_i) g_k (∏_{i>k} d_i), the telescoping sum (module docstring).

    Parameters
    ----------
    factors : sequence of (n_i, d_i, g_i)
        Per vehicle, in order from the head; any arithmetic with +, × (floats, arrays,
        :class:`~stringstab.certify.interval.Interval`, :class:`~stringstab.certify.interval_jets.Jet`).

    Returns
    -------
    object
        G in the arithmetic of the factors.

    Examples
    --------
    >>> n, d = [0.5, 2.0, 1.0], [1.0, 1.5, 3.0]  # at ω = 1, so g_i = d_i − n_i
    >>> G = string_margin([(a, b, b - a) for a, b in zip(n, d)])
    >>> float(G), float(np.prod(d) - np.prod(n))
    (3.5, 3.5)
    """
    N = len(factors)
    suffix: list[Any] = [None] * N  # ∏_{i>k} d_i (None: the empty product)
    acc: Any = None
    for k in range(N - 1, -1, -1):
        suffix[k] = acc
        acc = factors[k][1] if acc is None else factors[k][1] * acc
    G: Any = None
    prefix: Any = None  # ∏_{i<k} n_i
    for k, (n, _, g) in enumerate(factors):
        term = g if prefix is None else prefix * g
        if suffix[k] is not None:
            term = term * suffix[k]
        G = term if G is None else G + term
        prefix = n if prefix is None else prefix * n
    return G


def normalisation(kx: Array, kv: Array, tau: Array, headway: Array, right: Array) -> Array:
    """The scale c_i = 1/√(k_x² s_i) of each factor, s_i = (|k_x| + |c|Ω + Ω² + τΩ³)².

    s_i bounds |D_i(jω)|² on [0, Ω] and k_x² = |D_i(0)|², so c_i d_i lies between about
    √(k_x²/s_i) and √(s_i/k_x²): the products of N factors stay within the floating-point
    range for N ≤ :data:`MAX_VEHICLES` and ordinary gains.  Any c_i > 0 keeps the sign of G.

    Parameters
    ----------
    kx, kv, tau, headway : ndarray
        Gains and parameters of the vehicles (c = k_v + T* k_x).
    right : ndarray
        Ω of each item, broadcast against them.

    Returns
    -------
    ndarray
        c_i > 0, elementwise.
    """
    c = kv + headway * kx
    s = np.abs(kx) + np.abs(c) * right + right * right + tau * right ** 3
    return np.asarray(1.0 / np.sqrt(np.maximum(kx * kx, 1e-300) * np.maximum(s * s, 1e-300)))


#: The unit roundoff of binary64 (rounding to nearest).
_U = 2.0 ** -53


def square_sum(re: Interval, im: Interval) -> tuple[Array, Array]:
    """re² + im² at points and a bound on its *relative* error.

    With absolute errors e_r, e_i ≤ ``ROUNDOFF_SLACK`` × the magnitude companions of ``re``
    and ``im`` (the slack rule), |(r + ε_r)² − r²| ≤ 2|r|e_r + e_r² (and so for im), plus three
    roundings of the result (two squares, one sum).

    Parameters
    ----------
    re, im : Interval
        Point intervals with their magnitude companions.

    Returns
    -------
    value : ndarray
        re² + im² (≥ 0).
    relative : ndarray
        A bound on |computed − exact|/computed (``inf`` where the value is 0).

    Examples
    --------
    >>> v, r = square_sum(Interval(np.array([3.0])), Interval(np.array([4.0])))
    >>> float(v[0]), bool(r[0] < 1e-12)
    (25.0, True)
    """
    r, i = re.lo, im.lo
    er, ei = ROUNDOFF_SLACK * re.mag, ROUNDOFF_SLACK * im.mag
    v = r * r + i * i
    e = 2.0 * (np.abs(r) * er + np.abs(i) * ei) + er * er + ei * ei + 3.0 * _U * v
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(v > 0, e / np.where(v > 0, v, 1.0), np.inf)
    return np.asarray(v), np.asarray(rel)


def _factor(re: Interval, im: Interval, pre: Interval | None, c: Array) -> tuple[Array, Array]:
    """c · pre · (re² + im²) and its relative error bound."""
    v, rel = square_sum(re, im)
    if pre is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = rel + ROUNDOFF_SLACK * pre.mag / np.abs(pre.lo) + _U
        v = v * pre.lo
    return v * c, rel + _U


def point_margin(parts: Sequence[Parts], scale: Array) -> tuple[Array, Array, Array]:
    """G at points (normalised by the c_i), a bound on its round-off, and ∏|Γ_i|².

    With n_i, d_i known to relative errors r_i, q_i (:func:`square_sum`) and g_i to the
    absolute error e_i = ``ROUNDOFF_SLACK`` × its magnitude companion, the computed product
    A_k = ∏_{i<k} n_i ∏_{i>k} d_i is within a relative ρ_k = ∏_{i<k}(1 + r_i) ∏_{i>k}(1 + q_i)
    (1 + u)^{N+2} − 1 of the exact one, so the k-th term is within
    A_k(ρ'_k(|g_k| + e_k) + e_k) + 2u|T_k| (ρ' = ρ/(1 − ρ)), and the sum adds N u Σ|T_k|.
    The bound is then enlarged by 1 % for the rounding of its own computation.

    Parameters
    ----------
    parts : sequence of Parts
        Per vehicle, from the head, at the same points (arrays of one shape).
    scale : ndarray
        c_i per vehicle (rows), broadcast against the points.

    Returns
    -------
    G : ndarray
        Σ_k (∏_{i<k} c_i n_i) c_k g_k (∏_{i>k} c_i d_i).
    slack : ndarray
        A bound on |G computed − G exact| (``inf`` where a product of factors is computed as
        0 — a factor computed as 0, or an underflow — or the bound fails).
    gain2 : ndarray
        ∏_i n_i/d_i = ∏_i |Γ_i|² (reporting; NaN where a d_i = 0).
    """
    N = len(parts)
    ns, nr, ds, dr, gs, ge = [], [], [], [], [], []
    gain2: Array | None = None
    for i, p in enumerate(parts):
        c = scale[i]
        n, r = _factor(p.re_n, p.im_n, p.pre_n, c)
        d, q = _factor(p.re_d, p.im_d, p.pre_d, c)
        ns.append(n)
        nr.append(r)
        ds.append(d)
        dr.append(q)
        gs.append(p.g.lo * c)
        ge.append(ROUNDOFF_SLACK * p.g.mag * c * (1.0 + 4.0 * _U) + _U * np.abs(p.g.lo * c))
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(d > 0, n / np.where(d > 0, d, 1.0), np.nan)
        gain2 = ratio if gain2 is None else gain2 * ratio
    # suffixes ∏_{i>k} d_i and ∏_{i>k} (1 + q_i)
    suf: list[Any] = [1.0] * N
    sufr: list[Any] = [1.0] * N
    for k in range(N - 2, -1, -1):
        suf[k] = ds[k + 1] * suf[k + 1]
        sufr[k] = (1.0 + dr[k + 1]) * sufr[k + 1]
    G: Any = 0.0
    E: Any = 0.0
    T_abs: Any = 0.0
    pre: Any = 1.0
    prer: Any = 1.0
    grow = (1.0 + _U) ** (N + 2)
    for k in range(N):
        A = pre * suf[k]
        T = (pre * gs[k]) * suf[k]
        rho = prer * sufr[k] * grow - 1.0
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            rho1 = np.where(rho < 0.5, rho / (1.0 - np.minimum(rho, 0.5)), np.inf)
            Ek = np.abs(A) * (rho1 * (np.abs(gs[k]) + ge[k]) + ge[k])
        # a product computed as 0 (a factor computed as 0, or an underflow) bounds nothing:
        # the point is left undecided (its slack infinite)
        Ek = np.where(A == 0, np.inf, Ek) + 2.0 * _U * np.abs(T)
        G = G + T
        E = E + Ek
        T_abs = T_abs + np.abs(T)
        pre = pre * ns[k]
        prer = prer * (1.0 + nr[k])
    E = 1.01 * (E + N * _U * T_abs)
    assert gain2 is not None
    return np.asarray(G), np.asarray(E), gain2


# ---------------------------------------------------------------------------
# The continuous loop
# ---------------------------------------------------------------------------
class ContinuousString:
    """The continuous-time loop of strings of one length (module docstring).

    A vehicle slot in which some string has a reaction delay θ_r > 0 (issue 25) takes the
    θ_r margin g_θ of :mod:`stringstab.certify.margin_reaction` (its coefficients, round-off
    scales and proven tail; at θ_r = 0 it equals g), the generated ``reaction_gamma_parts``
    for N_i and D_i, and the exact root count of the retarded quasi-polynomial
    (:func:`stringstab.certify.quasipolynomial.count_unstable_roots`) for its internal
    stability; a slot without θ_r runs the θ_r = 0 code (:mod:`stringstab.certify.margin`,
    the Hurwitz bands).

    Parameters
    ----------
    arrays : StringArrays
        The strings.
    """

    def __init__(self, arrays: StringArrays) -> None:
        from . import margin_reaction as _mr

        self.arrays = a = arrays
        self.react = [bool(np.any(a.reaction_delay[i] > 0)) for i in range(a.length)]
        self.co: list[Array] = []
        self.sc: list[Array] = []
        om = []
        for i in range(a.length):
            args = (a.kx[i], a.kv[i], a.ka[i], a.tau[i], a.delta[i], a.headway[i])
            if self.react[i]:
                Q = _mr.coefficient_table(*args, a.reaction_delay[i])
                k = _mr.N_COEFFICIENTS
                self.co.append(Q[:k])
                self.sc.append(Q[k:2 * k])
                om.append(_mr.tail_bound(Q))
            else:
                self.co.append(np.asarray(_gen.margin_coefficients(*args), dtype=float))
                self.sc.append(np.asarray(_gen.margin_coefficient_scales(*args), dtype=float))
                om.append(_margin.tail_bound(*(self.co[-1][r] for r in range(5))))
        self._right = np.stack(om).max(axis=0)
        self.scale = normalisation(a.kx, a.kv, a.tau, a.headway, self._right[None, :])

    def right(self) -> Array:
        """Ω per item: the largest of its vehicles' tail bounds (module docstring, step 1)."""
        return self._right

    def _vehicle(self, i: int, idx: Index, x: Any, const: Callable[[Array], Any],
                 coef: Callable[[Array, Array], Any]) -> tuple[Any, ...]:
        """(Re N, Im N, Re D, Im D, g) of vehicle ``i`` at ``x``, in the arithmetic of ``x``."""
        a = self.arrays

        def par(v: Array) -> Any:
            return const(v[i, idx][:, None])

        co = [coef(self.co[i][r, idx][:, None], self.sc[i][r, idx][:, None])
              for r in range(self.co[i].shape[0])]
        if self.react[i]:
            th = par(a.reaction_delay)
            parts = _gen.reaction_gamma_parts(x, par(a.kx), par(a.kv), par(a.ka), par(a.tau),
                                              par(a.delta), par(a.headway), th, jet_cos, jet_sin)
            z = 0.0  # the scales' output is not used
            g = _gen.reaction_margin_and_scale(x, co[0], co[1], co[2], co[3], co[4], co[5], co[6],
                                               co[7], z, z, z, z, z, z, z, z, par(a.delta), th,
                                               jet_cos, jet_sin)[0]
        else:
            parts = _gen.gamma_parts(x, par(a.kx), par(a.kv), par(a.ka), par(a.tau),
                                     par(a.delta), par(a.headway), jet_cos, jet_sin)
            g = _gen.margin_from_coefficients(x, co[0], co[1], co[2], co[3], co[4], par(a.delta),
                                              jet_cos, jet_sin)
        return (*parts, g)

    def parts(self, idx: Index, x: Interval) -> list[Parts]:
        """Re N_i, Im N_i, Re D_i, Im D_i (the generated ``gamma_parts``) and g_i at ω = ``x``.

        Parameters
        ----------
        idx : ndarray of int
            The items (strings), one row of ``x`` each.
        x : Interval
            ω, rad/s, points of shape (len(idx), k).

        Returns
        -------
        list of Parts
            Per vehicle, point intervals with their magnitude companions (a coefficient of g
            carries its round-off scale as its companion).
        """
        out = []
        for i in range(self.arrays.length):
            ren, imn, red, imd, g = self._vehicle(i, idx, x, Interval,
                                                  lambda v, sc: Interval(v, None, sc))
            out.append(Parts(ren, imn, red, imd, g))
        return out

    def factors(self, idx: Index, x: Jet) -> list[Factor]:
        """(c_i n_i, c_i d_i, c_i g_i) of every vehicle on the jet ``x`` (curvature bounds).

        Parameters
        ----------
        idx : ndarray of int
            The items (strings), one row of ``x`` each.
        x : Jet
            ω over intervals, rad/s, of shape (len(idx), k).

        Returns
        -------
        list of (n, d, g)
            Jets; the coefficients of g enter as enclosures of their round-off.
        """
        out = []
        for i in range(self.arrays.length):
            ren, imn, red, imd, g = self._vehicle(
                i, idx, x, lambda v: Jet(Enclosure(v)),
                lambda v, sc: Jet(Enclosure.around(v, ROUNDOFF_SLACK * sc)))
            c = Jet(Enclosure(self.scale[i, idx][:, None]))
            out.append((c * (ren * ren + imn * imn), c * (red * red + imd * imd), c * g))
        return out

    def stability(self) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
        """(every vehicle surely internally stable, some vehicle surely not), per item.

        The Hurwitz bands (θ_r = 0) or the exact root count of the quasi-polynomial (θ_r > 0).
        """
        a = self.arrays
        sure = np.ones(a.count, dtype=bool)
        fail = np.zeros(a.count, dtype=bool)
        for i in range(a.length):
            s, f = hurwitz_bands_kernel(a.kx[i], a.kv[i], tau=a.tau[i],  # type: ignore[arg-type]
                                        headway=a.headway[i])  # type: ignore[arg-type]
            th = a.reaction_delay[i] > 0
            if th.any():
                from .quasipolynomial import count_unstable_roots

                j = np.flatnonzero(th)
                rc = count_unstable_roots(a.kx[i][j], a.kv[i][j], a.tau[i][j], a.headway[i][j],
                                          a.reaction_delay[i][j])
                s[j], f[j] = rc.stable, rc.unstable
            sure &= s
            fail |= f
        return sure, fail
