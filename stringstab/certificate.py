"""Exact, delay-aware, sound string-stability certificates for controller gains.

The certificate decides whether ‖Γ‖_{H∞} ≤ 1 for the derived transfer function

.. math::
    Γ(s) = \\frac{k_x + k_v s + k_a s^2 e^{-δs}}{τs^3 + s^2 + (k_v + T^*k_x)s + k_x}

with the *exact* delay (no Padé, no Taylor).  Since the denominator carries no
delay, Γ is internally stable iff that cubic is Hurwitz; then
‖Γ‖_{H∞} = sup_{ω≥0} |Γ(jω)|, and |Γ(jω)| ≤ 1 iff

.. math::
    g(ω) = \\frac{|D(jω)|^2 - |N(jω)|^2}{ω^2}
         = τ^2ω^4 + aω^2 + b + 2k_xk_a\\cos δω - 2k_vk_a ω\\sin δω \\ge 0 ,

(:func:`stringstab.frequency.margin_g`).  The method is a branch and bound on g
that is sound by construction:

1. **Tail.**  For ω ≥ 0, g(ω) ≥ L(ω) = τ²ω⁴ − Aω² − Bω − C with A = max(−a, 0),
   B = |2k_vk_a|, C = max(|2k_xk_a| − b, 0).  L has one positive root ω*
   (Descartes); Ω ≥ ω* is found by Newton's method from Fujiwara's root bound
   (monotone from above because L is convex beyond ω*), so g > 0 on (Ω, ∞).
2. **Body.**  On each grid interval [l, r] ⊂ [0, Ω] of width h,
   g ≥ min(g(l), g(r)) − M h²/8 with the explicit bound
   M = 12τ²r² + 2|a| + |2k_xk_a|δ² + |2k_vk_a|(2δ + δ²r) ≥ |g''| on [l, r].
   Intervals whose lower bound is not positive are split (×4 to ×64, by need) and re-checked,
   vectorised over every undecided interval of every triple.
3. **Round-off.**  Every comparison carries a slack of 10⁻¹³ times the sum of
   the absolute values of the terms of g (hundreds of ulps).

Verdicts: ``certified`` when Γ is Hurwitz and the lower bound of g is ≥ 0 on
every interval (so sup|Γ(jω)| ≤ 1 exactly, up to that slack); ``not_certified``
when Γ is not Hurwitz (‖Γ‖_{H∞} = ∞) or some sampled ω has g(ω) < −slack
(so |Γ(jω)| > 1 there); ``inconclusive`` otherwise (a boundary case such as
Ψ3 = 0, or the refinement budget ran out).  Γ(0) = 1 whenever k_x ≠ 0, so a
certified triple has sup |Γ| = 1, attained at ω = 0.

References
----------
IDL paper, Definition 1 (eq 10) and eq 11 (derived form, see
:func:`stringstab.symbolic.gamma`).
M. Fujiwara, "Über die obere Schranke des absoluten Betrages der Wurzeln einer
algebraischen Gleichung", Tohoku Math. J. 10 (1916) 167-171.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from . import _generated as _gen
from . import margin as _margin
from .criteria import TYPE_NAMES, TaylorCriteria, hurwitz, hurwitz_margin, taylor_criteria
from .errors import StringStabError
from .frequency import gain_squared
from .io.results import TableColumn, columns_from_records, records_from_columns
from .margin import tail_bound
from .params import Params, as_gains

__all__ = [
    "TABLE_COLUMNS",
    "VERDICTS",
    "Certificate",
    "CertificateBatch",
    "Check",
    "PadeResult",
    "certify",
    "certify_batch",
    "certify_pade",
    "check",
    "tail_bound",
]

Array = npt.NDArray[np.float64]

#: The three possible verdicts.
VERDICTS = ("certified", "not_certified", "inconclusive")
_CERT, _NOT, _INC = 0, 1, 2

_SLACK = 1e-13  # relative round-off slack on g
_HURWITZ_RTOL = 1e-12  # relative band around the Hurwitz boundary left inconclusive


# ---------------------------------------------------------------------------
# Step 1, the tail bound, is :func:`stringstab.margin.tail_bound` (re-exported here).
# ---------------------------------------------------------------------------
def col(v: Array) -> Array:
    """A 1-D array as a column, to broadcast against a frequency grid."""
    return v[:, None]


def _g_and_slack(w: Array, Q: Array) -> tuple[Array, Array]:
    """g on the grid ``w`` and its round-off slack (step 3).

    ``Q`` holds, as columns (shape (11, n, 1)), the 5 coefficients of g, their 5
    round-off scales and δ of each row of ``w``.
    """
    g, scale = _margin.g_and_scale(w, Q[:5], Q[5:10], Q[10])
    return g, _SLACK * scale


# ---------------------------------------------------------------------------
# Step 2: branch and bound on g over [0, Omega]
# ---------------------------------------------------------------------------
@dataclass
class _Exact:
    verdict: npt.NDArray[np.int8]
    margin: Array
    omega_max: Array
    worst_omega: Array
    n_evals: npt.NDArray[np.int64]
    grid_omega: Array  # (n, n_grid + 1) initial grid
    grid_g: Array  # g on that grid


def _exact_chunk(
    kx: Array, kv: Array, ka: Array, tau: float, delta: float, headway: float,
    *, n_grid: int, max_rounds: int, split_min: int, max_intervals: int,
    refine: npt.NDArray[np.bool_] | None = None,
) -> _Exact:
    n = kx.size
    # one row per coefficient of g (5), per round-off scale (5), and δ: indexed together
    Q = np.empty((11, n))
    for i, v in enumerate((*_gen.margin_coefficients(kx, kv, ka, tau, delta, headway),
                           *_gen.margin_coefficient_scales(kx, kv, ka, tau, delta, headway),
                           delta)):
        Q[i] = v
    Om = tail_bound(*Q[:5])

    u = np.linspace(0.0, 1.0, n_grid + 1)
    W = Om[:, None] * u[None, :]
    Qc = Q[:, :, None]
    G, E = _g_and_slack(W, Qc)
    violated = np.any(G < -E, axis=1)
    imin = np.argmin(G, axis=1)
    margin = G[np.arange(n), imin]
    worst = W[np.arange(n), imin]
    n_evals = np.full(n, n_grid + 1, dtype=np.int64)

    # interval lower bounds
    h = (Om / n_grid)[:, None]
    M = _margin.curvature_bound(W[:, 1:], Qc[:5], Qc[10])
    Gl, Gr = G[:, :-1], G[:, 1:]
    slack = np.maximum(E[:, :-1], E[:, 1:])
    lower = np.minimum(Gl, Gr) - M * h * h / 8.0 - slack
    undecided = (lower < 0) & ~violated[:, None]
    if refine is not None:  # e.g. skip triples already known not to be internally stable
        undecided &= refine[:, None]
    tri, k = np.nonzero(undecided)
    L = W[tri, k]
    R = W[tri, k + 1]
    # what an interval needs: min(g(l), g(r)) against its curvature bound
    gap = np.minimum(Gl, Gr)[tri, k] - slack[tri, k]
    Mi = M[tri, k]
    inconclusive = np.zeros(n, dtype=bool)

    for _ in range(max_rounds):
        if tri.size == 0:
            break
        # budget, per triple (so a verdict never depends on the other triples
        # of its chunk): too many undecided intervals → inconclusive
        counts = np.bincount(tri, minlength=n)
        over = counts > max_intervals
        if over.any():
            inconclusive |= over
            sel = ~over[tri]
            tri, L, R, gap, Mi = tri[sel], L[sel], R[sel], gap[sel], Mi[sel]
            if tri.size == 0:
                break
        # adaptive split: enough pieces that M h²/8 ≤ gap/2 where the endpoints
        # are clearly positive (one round instead of several near a shallow dip);
        # the bound is re-checked on every piece, so this only saves rounds
        with np.errstate(divide="ignore", invalid="ignore"):
            need = np.where(gap > 0, (R - L) * np.sqrt(Mi / (4.0 * gap)), split_min)
        split = int(min(max(split_min, 2 ** math.ceil(math.log2(max(float(np.max(need)), 1.0)))), 64))
        while split > split_min and tri.size * split > 2_000_000:
            split //= 2
        v = np.linspace(0.0, 1.0, split + 1)
        Wn = L[:, None] + (R - L)[:, None] * v[None, :]
        Qt = Q[:, tri, None]
        Gn, En = _g_and_slack(Wn, Qt)
        np.add.at(n_evals, tri, split - 1)
        # track the minimum found and violations
        jmin = np.argmin(Gn, axis=1)
        gmin = Gn[np.arange(tri.size), jmin]
        np.minimum.at(margin, tri, gmin)
        better = gmin <= margin[tri]
        worst[tri[better]] = Wn[np.arange(tri.size), jmin][better]
        viol_int = np.any(Gn < -En, axis=1)
        if viol_int.any():
            violated[np.unique(tri[viol_int])] = True
        hn = ((R - L) / split)[:, None]
        Mn = _margin.curvature_bound(Wn[:, 1:], Qt[:5], Qt[10])
        lowern = np.minimum(Gn[:, :-1], Gn[:, 1:]) - Mn * hn * hn / 8.0 - np.maximum(En[:, :-1], En[:, 1:])
        und = (lowern < 0) & ~violated[tri][:, None]
        ii, kk = np.nonzero(und)
        gap = (np.minimum(Gn[:, :-1], Gn[:, 1:]) - np.maximum(En[:, :-1], En[:, 1:]))[ii, kk]
        Mi = Mn[ii, kk]
        tri, L, R = tri[ii], Wn[ii, kk], Wn[ii, kk + 1]
    if tri.size:
        inconclusive[np.unique(tri)] = True

    verdict = np.full(n, _CERT, dtype=np.int8)
    verdict[inconclusive] = _INC
    verdict[violated] = _NOT
    return _Exact(verdict, margin, Om, worst, n_evals, W, G)


# ---------------------------------------------------------------------------
# Peak of |Γ(jω)| (for reporting; the verdict never depends on it)
# ---------------------------------------------------------------------------
def _peak(
    kx: Array, kv: Array, ka: Array, tau: float, delta: float, headway: float, Om: Array,
    W: Array, G: Array, worst: Array,
) -> tuple[Array, Array]:
    """sup_ω |Γ(jω)| on [0, Ω] and where it is attained (reporting only).

    Starts from the branch-and-bound grid (|Γ|² = 1 − ω² g/|D|², no new
    evaluations), adds the minimisers of |D(jω)|² (a cubic in x = ω², so they
    are roots of a quadratic: the resonance frequencies) and the frequency where
    the branch and bound found its smallest g (the witness of a violation,
    which may be far narrower than the grid), and refines locally.
    """
    n = kx.size
    rows = np.arange(n)
    p0, p1, p2, p3 = (np.broadcast_to(np.asarray(v, float), (n,))
                      for v in _gen.denominator_abs2_coefficients(kx, kv, ka, tau, delta, headway))
    w2 = W * W
    D2 = ((col(p0) * w2 + col(p1)) * w2 + col(p2)) * w2 + col(p3)  # |D(jω)|², a cubic in ω²
    with np.errstate(divide="ignore", invalid="ignore"):
        G2 = np.where(D2 > 0, 1.0 - w2 * G / D2, np.inf)
    G2[:, 0] = np.where(kx != 0, 1.0, np.inf)  # Γ(0) = k_x/k_x
    # resonances: the roots of d|D|²/dx = 3p0 x² + 2p1 x + p2
    qa, qb, qc = 3.0 * p0, 2.0 * p1, p2
    disc = qb * qb - 4.0 * qa * qc
    sq = np.sqrt(np.maximum(disc, 0.0))
    extra = np.stack([np.where((disc >= 0) & (x > 0), np.sqrt(np.abs(x)), 0.0)
                      for x in ((-qb + sq) / (2.0 * qa), (-qb - sq) / (2.0 * qa))]
                     + [worst], axis=1)  # and the branch and bound's witness, min g
    Ge = gain_squared(extra, col(kx), col(kv), col(ka), tau=tau, delta=delta, headway=headway)
    Wall = np.concatenate([W, extra], axis=1)
    Gall = np.concatenate([G2, Ge], axis=1)
    Gall = np.where(np.isnan(Gall), np.inf, Gall)
    j = np.argmax(Gall, axis=1)
    best_w = Wall[rows, j]
    best = Gall[rows, j]
    # local refinement around the best sample: grid spacing, then /4 each round
    half = Om / (W.shape[1] - 1)
    v = np.linspace(-1.0, 1.0, 9)
    for _ in range(8):
        Wl = np.maximum(best_w[:, None] + half[:, None] * v[None, :], 0.0)
        Gl = gain_squared(Wl, col(kx), col(kv), col(ka), tau=tau, delta=delta, headway=headway)
        Gl = np.where(np.isnan(Gl), np.inf, Gl)
        jl = np.argmax(Gl, axis=1)
        gl = Gl[rows, jl]
        upd = gl > best
        best = np.where(upd, gl, best)
        best_w = np.where(upd, Wl[rows, jl], best_w)
        half = half / 4.0
    return np.sqrt(best), best_w


# ---------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------
def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


@dataclass(frozen=True)
class Certificate:
    """The certificate of one gain triple.

    Attributes
    ----------
    k_x, k_v, k_a : float
        The gains.
    params : Params
        τ, δ, T*.
    hurwitz : bool
        Γ's denominator is Hurwitz (internal stability).
    hurwitz_margin : float
        −max Re(pole) of Γ (the slowest decay rate, 1/s); > 0 iff stable.
    verdict : str
        ``"certified"``, ``"not_certified"`` or ``"inconclusive"``.
    type : str
        Stability type I-IV of IDL §3.3 from the derived Ψ.
    sup_gain : float
        ‖Γ‖_{H∞}: sup_ω |Γ(jω)| for a stable Γ, ``inf`` otherwise (largest value
        found: exact to ~1e-12 at the reported peak frequency).
    linf_gain : float
        sup_ω |Γ(jω)| regardless of stability (the L∞ norm).
    peak_omega : float
        Frequency (rad/s) of that supremum (0 when it is Γ(0) = 1).
    margin : float
        min_ω g(ω) = min (|D|² − |N|²)/ω² found (≥ 0 iff |Γ| ≤ 1); an upper
        bound on the true minimum.
    taylor_derived, taylor_printed : dict
        Ψ1, Ψ2, Ψ3, Λ, Proposition-1 verdict and type from the derived and
        the printed formulas (:func:`stringstab.criteria.taylor_criteria`).
    method : str
        ``"exact"``.
    omega_max : float
        Ω of the tail bound: g > 0 is proven for ω > Ω.
    n_evals : int
        Evaluations of g used.
    pade : dict or None
        The python-control cross-check, when requested (``method="pade"``).
    """

    k_x: float
    k_v: float
    k_a: float
    params: Params
    hurwitz: bool
    hurwitz_margin: float
    verdict: str
    type: str
    sup_gain: float
    linf_gain: float
    peak_omega: float
    margin: float
    taylor_derived: dict[str, Any]
    taylor_printed: dict[str, Any]
    method: str = "exact"
    omega_max: float = float("nan")
    n_evals: int = 0
    pade: dict[str, Any] | None = None

    @property
    def certified(self) -> bool:
        """True iff the verdict is ``"certified"``."""
        return self.verdict == "certified"

    def as_dict(self) -> dict[str, Any]:
        """The JSON row of ``stringstab certify`` (non-finite numbers become None)."""
        d: dict[str, Any] = {
            "k_x": self.k_x,
            "k_v": self.k_v,
            "k_a": self.k_a,
            "hurwitz": self.hurwitz,
            "hurwitz_margin": _num(self.hurwitz_margin),
            "verdict": self.verdict,
            "type": self.type,
            "sup_gain": _num(self.sup_gain),
            "linf_gain": _num(self.linf_gain),
            "peak_omega": _num(self.peak_omega),
            "margin": _num(self.margin),
            "omega_max": _num(self.omega_max),
            "taylor_derived": self.taylor_derived,
            "taylor_printed": self.taylor_printed,
            "method": self.method,
        }
        if self.pade is not None:
            d["pade"] = self.pade
        return d


@dataclass(frozen=True)
class CertificateBatch:
    """Certificates of many triples, as arrays (see :class:`Certificate` for fields)."""

    k_x: Array
    k_v: Array
    k_a: Array
    params: Params
    hurwitz: npt.NDArray[np.bool_]
    hurwitz_margin: Array
    verdict: npt.NDArray[np.str_]
    type: npt.NDArray[np.str_]
    sup_gain: Array
    linf_gain: Array
    peak_omega: Array
    margin: Array
    omega_max: Array
    n_evals: npt.NDArray[np.int64]
    taylor_derived: TaylorCriteria
    taylor_printed: TaylorCriteria
    method: str = "exact"
    pade: list[dict[str, Any]] | None = field(default=None)

    def __len__(self) -> int:
        return int(self.k_x.size)

    @property
    def certified(self) -> npt.NDArray[np.bool_]:
        """Boolean array: verdict == "certified"."""
        return np.asarray(self.verdict == "certified")

    def __getitem__(self, i: int) -> Certificate:
        return Certificate(
            k_x=float(self.k_x[i]), k_v=float(self.k_v[i]), k_a=float(self.k_a[i]),
            params=self.params, hurwitz=bool(self.hurwitz[i]),
            hurwitz_margin=float(self.hurwitz_margin[i]), verdict=str(self.verdict[i]),
            type=str(self.type[i]), sup_gain=float(self.sup_gain[i]),
            linf_gain=float(self.linf_gain[i]), peak_omega=float(self.peak_omega[i]),
            margin=float(self.margin[i]), taylor_derived=self.taylor_derived.row(i),
            taylor_printed=self.taylor_printed.row(i), method=self.method,
            omega_max=float(self.omega_max[i]), n_evals=int(self.n_evals[i]),
            pade=None if self.pade is None else self.pade[i],
        )

    # -- result rendering: the rows, columns and totals every output format is written from --
    def columns(self) -> dict[str, Any]:
        """The result columns, in the order and with the keys of :meth:`Certificate.as_dict`.

        Groups (``taylor_derived``, ``taylor_printed``, ``pade``) are nested mappings of
        columns; write them with :func:`stringstab.io.write_results`.  Unlike the JSON rows,
        non-finite numbers stay as they are (``sup_gain`` is ``inf`` when Γ is unstable).

        Examples
        --------
        >>> b = certify_batch([1.5, -0.5], [0.3, 1.0], [-0.1, 1.0], tau=0.1, delta=0.2, headway=1.1)
        >>> b.columns()["sup_gain"].tolist(), b.columns()["taylor_printed"]["verdict"].tolist()
        ([1.0, inf], ['stable', 'unstable'])
        """
        n = len(self)
        cols: dict[str, Any] = {
            "k_x": self.k_x, "k_v": self.k_v, "k_a": self.k_a, "hurwitz": self.hurwitz,
            "hurwitz_margin": self.hurwitz_margin, "verdict": self.verdict, "type": self.type,
            "sup_gain": self.sup_gain, "linf_gain": self.linf_gain,
            "peak_omega": self.peak_omega, "margin": self.margin, "omega_max": self.omega_max,
            "taylor_derived": _taylor_columns(self.taylor_derived),
            "taylor_printed": _taylor_columns(self.taylor_printed),
            "method": np.full(n, self.method),
        }
        if self.pade is not None:
            cols["pade"] = columns_from_records(self.pade)
        return cols

    def records(self) -> list[dict[str, Any]]:
        """One JSON row per triple (:meth:`Certificate.as_dict`; non-finite numbers are None)."""
        return records_from_columns(self.columns())

    def summary(self) -> dict[str, Any]:
        """Counts per verdict and m_fss, the share certified as a fraction in [0, 1] (IDL eq 27).

        ``m_fss`` is eq 27's M_fss without its ×100 % (docs/conventions.md): every M_fss of
        the toolkit is a fraction; the simulator's metrics keep a percentage under an old key.
        """
        n = len(self)
        counts = {v: int(np.count_nonzero(self.verdict == v)) for v in VERDICTS}
        return {"n": n, **counts, "m_fss": counts["certified"] / n if n else float("nan")}


def _taylor_columns(tc: TaylorCriteria) -> dict[str, Any]:
    """The columns of :meth:`TaylorCriteria.row`, for every triple at once."""
    names = np.array(["", *(TYPE_NAMES[k] for k in sorted(TYPE_NAMES))])
    return {"psi1": tc.psi1, "psi2": tc.psi2, "psi3": tc.psi3, "lambda": tc.lam,
            "verdict": np.where(tc.stable, "stable", "unstable"),
            "type": names[np.asarray(tc.type, dtype=np.intp)]}


#: The columns of the human table of certificates (``stringstab certify``).
TABLE_COLUMNS: list[TableColumn] = [
    TableColumn("t", "t"),
    TableColumn("vehicle", "vehicle"),
    TableColumn("k_x", "k_x"),
    TableColumn("k_v", "k_v"),
    TableColumn("k_a", "k_a"),
    TableColumn("hurwitz", "hurwitz"),
    TableColumn("verdict", "verdict"),
    TableColumn("type", "type"),
    TableColumn("sup|Γ|", "sup_gain", "%.6g", missing="inf"),
    TableColumn("ω_peak[rad/s]", "peak_omega", "%.4g"),
    TableColumn("margin", "margin", "%.3g"),
    TableColumn("taylor(derived)", "taylor_derived.verdict"),
    TableColumn("taylor(printed)", "taylor_printed.verdict"),
    TableColumn("pade", "pade.verdict"),
    TableColumn("pade ‖Γ‖∞", "pade.hinf", "%.6g", missing="inf"),
]


def _hurwitz_bands(kx: Array, kv: Array, p: Params) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_]]:
    """(surely Hurwitz, surely not Hurwitz); neither within 1e-12 of the boundary."""
    hz_sure = hurwitz(kx, kv, tau=p.tau, headway=p.headway, rtol=_HURWITZ_RTOL)
    hz_fail = ~hurwitz(kx, kv, tau=p.tau, headway=p.headway, rtol=-_HURWITZ_RTOL)
    return hz_sure, hz_fail


@dataclass(frozen=True)
class Check:
    """Verdicts only (see :func:`check`).

    Attributes
    ----------
    verdict : ndarray of str
        ``"certified"``, ``"not_certified"`` or ``"inconclusive"``.
    hurwitz : ndarray of bool
        Internally stable (surely, outside the 1e-12 boundary band).
    margin : ndarray
        Smallest g(ω) found.
    witness_omega : ndarray
        Where it was found: for an internally stable, not-certified triple,
        a frequency with |Γ(jω)| > 1.
    """

    verdict: npt.NDArray[np.str_]
    hurwitz: npt.NDArray[np.bool_]
    margin: Array
    witness_omega: Array


def check(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: float, delta: float, headway: float,
    n_grid: int = 64, max_rounds: int = 30, max_intervals: int = 1024,
) -> Check:
    """The exact certificate's verdicts alone, for inner loops (e.g. gain repair).

    The same sound decision as :func:`certify_batch` (same branch and bound,
    same verdicts) without the reporting extras — no peak search, no Taylor
    criteria, no pole margins — so one triple costs a fraction of a
    millisecond.

    Examples
    --------
    >>> check([1.5, 0.9], [0.3, -0.5], [-0.1, 1.1], tau=0.1, delta=0.2, headway=1.1).verdict.tolist()
    ['certified', 'not_certified']
    """
    p = Params(tau, delta, headway)
    kx, kv, ka = (np.ascontiguousarray(v, dtype=float).ravel() for v in as_gains(k_x, k_v, k_a))
    hz_sure, hz_fail = _hurwitz_bands(kx, kv, p)
    ex = _exact_chunk(kx, kv, ka, p.tau, p.delta, p.headway, n_grid=n_grid,
                      max_rounds=max_rounds, split_min=4, max_intervals=max_intervals,
                      refine=~hz_fail)
    v = ex.verdict.copy()
    v[~hz_sure] = np.where(hz_fail[~hz_sure], _NOT, _INC)
    return Check(np.array(VERDICTS)[v], hz_sure, ex.margin, ex.worst_omega)


def certify_batch(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: float, delta: float, headway: float, method: str = "exact",
    pade_order: int = 5, progress: bool = False, chunk: int = 4096,
    n_grid: int = 64, max_rounds: int = 30, max_intervals: int = 1024,
) -> CertificateBatch:
    """Certify many gain triples at once (exact delay, sound; see the module docstring).

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains, broadcast together and flattened.
    tau, delta, headway : float
        Actuator lag τ > 0, delay δ ≥ 0, desired headway T* ≥ 0 (seconds).
    method : {"exact", "pade"}
        ``"pade"`` additionally runs the python-control cross-check
        (:func:`certify_pade`) per triple and warns where it disagrees; the
        verdict is always the exact one.
    pade_order : int
        Padé order for the cross-check.
    progress : bool
        Show a tqdm progress bar over chunks.
    chunk : int
        Triples per vectorised chunk (bounds memory).
    n_grid, max_rounds, max_intervals : int
        Initial intervals on [0, Ω], refinement rounds, and the cap on undecided
        intervals *per triple* beyond which that triple is declared inconclusive
        (per triple, so a verdict never depends on the rest of the batch).

    Returns
    -------
    CertificateBatch

    Raises
    ------
    StringStabError
        On non-finite gains or parameters out of range.

    Examples
    --------
    >>> b = certify_batch([1.5, 0.9], [0.3, -0.5], [-0.1, 1.1], tau=0.1, delta=0.2, headway=1.1)
    >>> b.verdict.tolist()
    ['certified', 'not_certified']
    >>> b.summary()["m_fss"]
    0.5
    """
    p = Params(tau, delta, headway)
    if method not in ("exact", "pade"):
        raise StringStabError(f"method must be 'exact' or 'pade'; got {method!r}")
    kx, kv, ka = (np.ascontiguousarray(v, dtype=float).ravel() for v in as_gains(k_x, k_v, k_a))
    n = kx.size
    verdict = np.empty(n, dtype=np.int8)
    margin = np.empty(n)
    omega_max = np.empty(n)
    n_evals = np.empty(n, dtype=np.int64)
    sup = np.empty(n)
    peak_w = np.empty(n)

    # internal stability, with an inconclusive band around the boundary
    hz_sure, hz_fail = _hurwitz_bands(kx, kv, p)
    hz_margin = hurwitz_margin(kx, kv, tau=p.tau, headway=p.headway)

    starts = range(0, n, chunk)
    if progress:
        from tqdm.auto import tqdm

        starts = tqdm(starts, total=math.ceil(n / chunk), desc="certify", unit="chunk")
    for s0 in starts:
        sl = slice(s0, min(s0 + chunk, n))
        ex = _exact_chunk(kx[sl], kv[sl], ka[sl], p.tau, p.delta, p.headway,
                          n_grid=n_grid, max_rounds=max_rounds, split_min=4,
                          max_intervals=max_intervals, refine=~hz_fail[sl])
        verdict[sl], margin[sl], omega_max[sl], n_evals[sl] = ex.verdict, ex.margin, ex.omega_max, ex.n_evals
        # certified ⇒ sup |Γ| = 1 at ω = 0: only the others need a peak search
        need = ex.verdict != _CERT
        sup[sl], peak_w[sl] = 1.0, 0.0
        if need.any():
            idx = np.arange(sl.start, sl.stop)[need]
            sup[idx], peak_w[idx] = _peak(
                kx[idx], kv[idx], ka[idx], p.tau, p.delta, p.headway, ex.omega_max[need],
                ex.grid_omega[need], ex.grid_g[need], ex.worst_omega[need],
            )

    verdict[~hz_sure] = np.where(hz_fail[~hz_sure], _NOT, _INC)
    # certified ⇒ sup |Γ| = 1 exactly, at ω = 0 (Γ(0) = 1 for k_x ≠ 0)
    cert = verdict == _CERT
    sup[cert] = np.maximum(sup[cert], 1.0)
    hinf = np.where(hz_sure, sup, np.inf)
    td = taylor_criteria(kx, kv, ka, tau=p.tau, delta=p.delta, headway=p.headway, source="derived")
    tp = taylor_criteria(kx, kv, ka, tau=p.tau, delta=p.delta, headway=p.headway, source="printed")
    names = np.array(VERDICTS)[verdict]
    pade_rows = None
    if method == "pade":
        pade_rows = []
        disagree = []
        for i in range(n):
            pr = certify_pade(kx[i], kv[i], ka[i], tau=p.tau, delta=p.delta, headway=p.headway,
                              order=pade_order)
            row = pr.as_dict()
            row["agrees"] = pr.verdict == names[i] or names[i] == "inconclusive"
            if not row["agrees"]:
                disagree.append(
                    f"K=({kx[i]:g}, {kv[i]:g}, {ka[i]:g}): exact {names[i]} (sup {hinf[i]:.9g}), "
                    f"Padé {pr.verdict} (norm {pr.hinf:.9g})"
                )
            pade_rows.append(row)
        if disagree:
            more = f" and {len(disagree) - 3} more" if len(disagree) > 3 else ""
            warnings.warn(
                f"Padé({pade_order}) cross-check disagrees with the exact certificate on "
                f"{len(disagree)} of {n} triples: " + "; ".join(disagree[:3]) + more,
                stacklevel=2,
            )
    return CertificateBatch(
        k_x=kx, k_v=kv, k_a=ka, params=p, hurwitz=np.asarray(hz_sure),
        hurwitz_margin=hz_margin, verdict=names, type=np.array([TYPE_NAMES[int(t)] for t in td.type]) if n else np.array([], dtype=str),
        sup_gain=hinf, linf_gain=sup, peak_omega=peak_w, margin=margin, omega_max=omega_max,
        n_evals=n_evals, taylor_derived=td, taylor_printed=tp, method=method, pade=pade_rows,
    )


def certify(
    k_x: float, k_v: float, k_a: float, *, tau: float, delta: float, headway: float,
    method: str = "exact", pade_order: int = 5,
) -> Certificate:
    """Certify one gain triple K = [k_x, k_v, k_a] (exact delay, sound).

    Examples
    --------
    >>> c = certify(1.5, 0.3, -0.1, tau=0.1, delta=0.2, headway=1.1)
    >>> c.verdict, c.sup_gain
    ('certified', 1.0)
    >>> c = certify(0.9, -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1)
    >>> c.verdict, c.type, c.taylor_printed["verdict"]
    ('not_certified', 'IV', 'stable')
    """
    for name, v in (("k_x", k_x), ("k_v", k_v), ("k_a", k_a)):
        if np.ndim(v) != 0:
            raise StringStabError(f"certify takes one triple; {name} has shape {np.shape(v)}; use certify_batch")
    return certify_batch([k_x], [k_v], [k_a], tau=tau, delta=delta, headway=headway,
                         method=method, pade_order=pade_order)[0]


# ---------------------------------------------------------------------------
# python-control cross-check
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class PadeResult:
    """python-control's view: Padé(n) delay, own stability check, then ``norm(·, 'inf')``."""

    order: int
    stable: bool
    hinf: float
    linf: float
    verdict: str

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return {"order": self.order, "stable": self.stable, "hinf": _num(self.hinf),
                "linf": _num(self.linf), "verdict": self.verdict}


def certify_pade(
    k_x: float, k_v: float, k_a: float, *, tau: float, delta: float, headway: float,
    order: int = 5, tol: float = 1e-6, norm_tol: float = 1e-10,
) -> PadeResult:
    """The python-control cross-check of one triple.

    The delay is replaced by ``control.pade(delta, order)``; stability is
    checked on the poles *before* ``control.norm(sys, 'inf')`` is trusted
    (that function returns the L∞ norm and never checks stability).  The
    verdict is ``"certified"`` when stable and the norm ≤ 1 + ``tol``; it is an
    approximation (Padé) and a cross-check only.  ``norm_tol`` is passed to
    ``control.norm`` (its default, 1e-6, cannot resolve sup |Γ| = 1).

    Examples
    --------
    >>> r = certify_pade(1.5, 0.3, -0.1, tau=0.1, delta=0.2, headway=1.1)
    >>> r.stable, r.verdict
    (True, 'certified')
    """
    import control

    p = Params(tau, delta, headway)
    kx, kv, ka = (float(v) for v in as_gains(k_x, k_v, k_a))
    if p.delta > 0:
        num_d, den_d = control.pade(p.delta, order)
        delay = control.tf(num_d, den_d)
    else:
        delay = control.tf([1.0], [1.0])
    # N(s) = n0(s) + n1(s) e^{-δs} and D(s), generated from the derivation
    d_co = [float(c) for c in _gen.denominator_coefficients(kx, kv, ka, p.tau, p.delta, p.headway)]
    n_co = [float(c) for c in _gen.numerator_coefficients(kx, kv, ka, p.tau, p.delta, p.headway)]
    n0, n1 = n_co[:_gen.NUMERATOR_SPLIT], n_co[_gen.NUMERATOR_SPLIT:]
    den = control.tf(d_co, [1.0])
    sys = (control.tf(n0, [1.0]) + control.tf(n1, [1.0]) * delay) / den
    poles = np.concatenate([np.roots(d_co), np.asarray(control.poles(delay))])
    stable = bool(np.all(poles.real < 0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            linf = float(control.norm(sys, "inf", tol=norm_tol))
        except Exception:  # python-control raises on poles on the imaginary axis
            linf = float("inf")
    hinf = linf if stable else float("inf")
    verdict = "certified" if stable and hinf <= 1.0 + tol else "not_certified"
    return PadeResult(order, stable, hinf, linf, verdict)
