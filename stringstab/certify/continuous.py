r"""Exact, delay-aware, sound string-stability certificates for controller gains.

The certificate decides whether ‖Γ‖_{H∞} ≤ 1 for the derived transfer function

.. math::
    Γ(s) = \frac{k_x + k_v s + k_a s^2 e^{-δs}}{τs^3 + s^2 + (k_v + T^*k_x)s + k_x}

with the *exact* delay (no Padé, no Taylor).  Since the denominator carries no
delay, Γ is internally stable iff that cubic is Hurwitz; then
‖Γ‖_{H∞} = sup_{ω≥0} |Γ(jω)|, and |Γ(jω)| ≤ 1 iff

.. math::
    g(ω) = \frac{|D(jω)|^2 - |N(jω)|^2}{ω^2}
         = τ^2ω^4 + aω^2 + b + 2k_xk_a\cos δω - 2k_vk_a ω\sin δω \ge 0 ,

(:func:`stringstab.certify.frequency.margin_g`).  The method is a branch and bound on g
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
:func:`stringstab.derive.symbolic.gamma`).
M. Fujiwara, "Über die obere Schranke des absoluten Betrages der Wurzeln einer
algebraischen Gleichung", Tohoku Math. J. 10 (1916) 167-171.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt

from ..derive import generated as _gen
from ..errors import StringStabError
from ..io import TableColumn, columns_from_records
from ..params import Params
from . import margin as _margin
from .branch_bound import branch_and_bound, verdict_codes, zoom_max
from .criteria import (
    TYPE_NAMES,
    TaylorCriteria,
    hurwitz_bands_kernel,
    hurwitz_margin_kernel,
    taylor_criteria_kernel,
)
from .excess import EXCESS_SEARCH, col, excess_squared
from .excess import violation_peak as _violation_peak
from .frequency import gain_squared, resonances
from .verdicts import (
    CERTIFIED,
    INCONCLUSIVE,
    NOT_CERTIFIED,
    ROUNDOFF_SLACK,
    ROW_COLUMNS,
    BatchResult,
    Check,
    SingleResult,
    Verdict,
    chunks,
    names,
    num,
)

__all__ = [
    "TABLE_COLUMNS",
    "Certificate",
    "CertificateBatch",
    "certify_kernel",
    "check_kernel",
]

Array = npt.NDArray[np.float64]

_SLACK = ROUNDOFF_SLACK


# ---------------------------------------------------------------------------
# Step 1, the tail bound, is :func:`stringstab.certify.margin.tail_bound`; step 3 the slack:
# ---------------------------------------------------------------------------
def _g_and_slack(w: Array, Q: Array) -> tuple[Array, Array]:
    """g on the grid ``w`` and its round-off slack (step 3).

    ``Q`` holds, as columns (shape (11, n, 1)), the 5 coefficients of g, their 5
    round-off scales and δ of each row of ``w``.
    """
    g, scale = _margin.g_and_scale(w, Q[:5], Q[5:10], Q[10])
    return g, _SLACK * scale


# ---------------------------------------------------------------------------
# Step 2: branch and bound on g over [0, Omega] (stringstab.certify.branch_bound, the one engine)
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
    *, n_grid: int, max_rounds: int, max_intervals: int,
    refine: npt.NDArray[np.bool_] | None = None,
) -> _Exact:
    n = kx.size
    # one row per coefficient of g (5), per round-off scale (5), and δ: indexed together
    Q = np.empty((11, n))
    for i, v in enumerate((*_gen.margin_coefficients(kx, kv, ka, tau, delta, headway),
                           *_gen.margin_coefficient_scales(kx, kv, ka, tau, delta, headway),
                           delta)):
        Q[i] = v
    Om = _margin.tail_bound(*Q[:5])

    def evaluate(idx: npt.NDArray[np.intp], X: Array) -> tuple[Array, Array, Array, Array]:
        Qt = Q[:, idx, None]
        G, E = _g_and_slack(X, Qt)
        return G, G, E, _margin.curvature_bound(X[:, 1:], Qt[:5], Qt[10])

    bb = branch_and_bound(n, evaluate, right=Om, n_grid=n_grid, max_rounds=max_rounds,
                          max_intervals=max_intervals, refine=refine)
    return _Exact(verdict_codes(bb.status), bb.minimum, Om, bb.argmin, bb.n_evals, bb.grid_x, bb.grid_f)


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
    # the resonances (the roots of d|D|²/dx) and the branch and bound's witness, min g
    extra = np.concatenate([resonances(p0, p1, p2), worst[:, None]], axis=1)
    Ge = gain_squared(extra, col(kx), col(kv), col(ka), tau=tau, delta=delta, headway=headway)
    Wall = np.concatenate([W, extra], axis=1)
    Gall = np.concatenate([G2, Ge], axis=1)
    Gall = np.where(np.isnan(Gall), np.inf, Gall)
    j = np.argmax(Gall, axis=1)
    best_w = Wall[rows, j]
    best = Gall[rows, j]
    # local refinement around the best sample: grid spacing, then /4 each round
    best, best_w = zoom_max(
        lambda Wl: gain_squared(Wl, col(kx), col(kv), col(ka), tau=tau, delta=delta,
                                headway=headway),
        best_w, best, Om / (W.shape[1] - 1))
    return np.sqrt(best), best_w


# ---------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Certificate(SingleResult):
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
    sup_gain_excess : float
        sup|Γ| − 1 at the reported peak, computed without cancellation (−ω²g/|D|²): 0 when
        certified, > 0 when not certified and stable (also when ``sup_gain`` rounds to 1.0,
        e.g. Ψ3 just below 0: the violation sits near ω = 0 and is tiny), ``inf`` unstable.
    linf_gain : float
        sup_ω |Γ(jω)| regardless of stability (the L∞ norm).
    peak_omega : float
        Frequency (rad/s) of that supremum (0 when it is Γ(0) = 1).
    margin : float
        min_ω g(ω) = min (|D|² − |N|²)/ω² found (≥ 0 iff |Γ| ≤ 1); an upper
        bound on the true minimum.
    taylor_derived, taylor_printed : dict
        Ψ1, Ψ2, Ψ3, Λ, Proposition 1's answer from their signs (``"sign"``: ``"stable"`` /
        ``"unstable"``, not a verdict) and type from the derived and the printed formulas
        (:func:`stringstab.certify.criteria.taylor_criteria`).
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
    sup_gain_excess: float = float("nan")

    def as_dict(self) -> dict[str, Any]:
        """The JSON row of ``stringstab certify`` (non-finite numbers become None)."""
        d: dict[str, Any] = {
            "k_x": self.k_x,
            "k_v": self.k_v,
            "k_a": self.k_a,
            "hurwitz": self.hurwitz,
            "hurwitz_margin": num(self.hurwitz_margin),
            "verdict": self.verdict,
            "type": self.type,
            "sup_gain": num(self.sup_gain),
            "sup_gain_excess": num(self.sup_gain_excess),
            "linf_gain": num(self.linf_gain),
            "peak_omega": num(self.peak_omega),
            "margin": num(self.margin),
            "omega_max": num(self.omega_max),
            "taylor_derived": self.taylor_derived,
            "taylor_printed": self.taylor_printed,
            "method": self.method,
        }
        if self.pade is not None:
            d["pade"] = self.pade
        return d


#: The columns of the human table of certificates (``stringstab certify``).
TABLE_COLUMNS: list[TableColumn] = [
    *ROW_COLUMNS,
    TableColumn("hurwitz", "hurwitz"),
    TableColumn("verdict", "verdict"),
    TableColumn("type", "type"),
    TableColumn("sup|Γ|", "sup_gain", "%.6g", missing="inf"),
    TableColumn("sup|Γ|-1", "sup_gain_excess", "%.3g", missing="inf"),
    TableColumn("ω_peak[rad/s]", "peak_omega", "%.4g"),
    TableColumn("margin", "margin", "%.3g"),
    TableColumn("taylor(derived)", "taylor_derived.sign"),
    TableColumn("taylor(printed)", "taylor_printed.sign"),
    TableColumn("pade", "pade.verdict"),
    TableColumn("pade ‖Γ‖∞", "pade.hinf", "%.6g", missing="inf"),
]


@dataclass(frozen=True)
class CertificateBatch(BatchResult):
    """Certificates of many triples, as arrays (see :class:`Certificate` for fields)."""

    TABLE: ClassVar[Sequence[TableColumn]] = TABLE_COLUMNS

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
    sup_gain_excess: Array | None = field(default=None)

    @property
    def stable(self) -> npt.NDArray[np.bool_]:  # type: ignore[override]
        """Internally stable (Γ Hurwitz, surely): :attr:`hurwitz`, the protocol's name."""
        return self.hurwitz

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
            sup_gain_excess=float(self._excess()[i]),
        )

    def _excess(self) -> Array:
        if self.sup_gain_excess is not None:
            return self.sup_gain_excess
        return np.where(np.asarray(self.verdict) == Verdict.CERTIFIED, 0.0, self.sup_gain - 1.0)

    # -- result rendering: the rows, columns and totals every output format is written from --

    def columns(self) -> dict[str, Any]:
        """The result columns, in the order and with the keys of :meth:`Certificate.as_dict`.

        Groups (``taylor_derived``, ``taylor_printed``, ``pade``) are nested mappings of
        columns; write them with :func:`stringstab.io.write_results`.  Unlike the JSON rows,
        non-finite numbers stay as they are (``sup_gain`` is ``inf`` when Γ is unstable).

        Examples
        --------
        >>> from stringstab import certify_batch
        >>> b = certify_batch([1.5, -0.5], [0.3, 1.0], [-0.1, 1.0], tau=0.1, delta=0.2, headway=1.1)
        >>> b.columns()["sup_gain"].tolist(), b.columns()["taylor_printed"]["sign"].tolist()
        ([1.0, inf], ['stable', 'unstable'])
        """
        n = len(self)
        cols: dict[str, Any] = {
            "k_x": self.k_x, "k_v": self.k_v, "k_a": self.k_a, "hurwitz": self.hurwitz,
            "hurwitz_margin": self.hurwitz_margin, "verdict": self.verdict, "type": self.type,
            "sup_gain": self.sup_gain, "sup_gain_excess": self._excess(),
            "linf_gain": self.linf_gain, "peak_omega": self.peak_omega, "margin": self.margin, "omega_max": self.omega_max,
            "taylor_derived": _taylor_columns(self.taylor_derived),
            "taylor_printed": _taylor_columns(self.taylor_printed),
            "method": np.full(n, self.method),
        }
        if self.pade is not None:
            cols["pade"] = columns_from_records(self.pade)
        return cols

    def summary(self) -> dict[str, Any]:
        """Counts per verdict and ``certified_row_share``, the share of rows certified (a fraction).

        Each row counts once; m_fss (IDL eq 27) weighs each gain by the time it is in force and
        is computed where time is known (``simulate``, ``evaluate``; docs/conventions.md).
        """
        return super().summary()


def _taylor_columns(tc: TaylorCriteria) -> dict[str, Any]:
    """The columns of :meth:`TaylorCriteria.row`, for every triple at once."""
    names = np.array(["", *(TYPE_NAMES[k] for k in sorted(TYPE_NAMES))])
    return {"psi1": tc.psi1, "psi2": tc.psi2, "psi3": tc.psi3, "lambda": tc.lam,
            "sign": np.where(tc.stable, "stable", "unstable"),
            "type": names[np.asarray(tc.type, dtype=np.intp)]}




# ---------------------------------------------------------------------------
# The kernels: inputs already checked by stringstab.certify (the way in, stringstab.certify.api)
# ---------------------------------------------------------------------------
def check_kernel(kx: Array, kv: Array, ka: Array, p: Params, *, n_grid: int = 64,
                     max_rounds: int = 30, max_intervals: int = 1024) -> Check:
    """The continuous-time verdicts alone (the kernel of :func:`stringstab.certify.check`).

    Inputs already checked by :func:`stringstab.certify.check` (the way in, which callers
    use): nothing is validated again here.

    Parameters
    ----------
    kx, kv, ka : ndarray of float64
        The gains, finite, one-dimensional, of one length.
    p : Params
        τ, δ, T* (checked on construction).
    n_grid, max_rounds, max_intervals : int
        As for :func:`certify_kernel`.

    Returns
    -------
    Check
        Verdicts, internal stability, min g found and where.
    """
    _theta_zero(p)
    hz_sure, hz_fail = hurwitz_bands_kernel(kx, kv, tau=p.tau, headway=p.headway)
    ex = _exact_chunk(kx, kv, ka, p.tau, p.delta, p.headway, n_grid=n_grid,
                      max_rounds=max_rounds, max_intervals=max_intervals, refine=~hz_fail)
    v = ex.verdict.copy()
    v[~hz_sure] = _unsure_verdict(v[~hz_sure], hz_fail[~hz_sure])
    return Check(names(v), hz_sure, ex.margin, ex.worst_omega)


def _theta_zero(p: Params) -> None:
    """Refuse θ_r > 0: this is the θ_r = 0 kernel (the way in sends θ_r > 0 to ``reaction``)."""
    if p.reaction_delay:
        raise StringStabError(
            "stringstab.certify.continuous certifies reaction_delay = 0 only; expected "
            f"stringstab.certify.reaction (chosen by stringstab.certify.api) for {p!r}")


def _unsure_verdict(v: npt.NDArray[np.int8], fail: npt.NDArray[np.bool_]) -> npt.NDArray[np.int8]:
    """The verdict of rows not surely Hurwitz.

    Not certified when surely not Hurwitz, and also within the Hurwitz band when the branch
    and bound proved g(ω) < 0 somewhere (issue 29 item 7: ‖Γ‖∞ ≥ |Γ(jω)| > 1, or ∞, so not
    string stable either way); else inconclusive.
    """
    return np.where(fail | (v == NOT_CERTIFIED), NOT_CERTIFIED, INCONCLUSIVE).astype(np.int8)


def _band_excess(kx: Array, kv: Array, ka: Array, p: Params, witness: Array,
                 Om: Array) -> tuple[Array, Array]:
    """|Γ(jω)| − 1 > 0 where g(ω) < 0 was proven, for rows in the Hurwitz band (issue 29 item 7).

    The largest finite excess (cancellation-free, :func:`stringstab.certify.excess.excess_squared`)
    at the branch and bound's witness and on a short logarithmic grid near ω = 0 (a witness at
    ω = 0 is Ψ3 < 0: the excess lives at small ω); the L∞ peak itself may be a pole on the axis.
    """
    W = np.concatenate([witness[:, None], Om[:, None] * np.logspace(-8.0, -1.0, 57)[None, :]],
                       axis=1)
    e2 = excess_squared(W, col(kx), col(kv), col(ka), p.tau, p.delta, p.headway)
    e2 = np.where(np.isfinite(e2), e2, -np.inf)
    j = np.argmax(e2, axis=1)
    rows = np.arange(kx.size)
    best = e2[rows, j]
    e1 = best / (1.0 + np.sqrt(1.0 + np.maximum(best, 0.0)))
    return np.where(np.isfinite(e1), e1, np.inf), W[rows, j]


def _agreeing_margin(hm: Array, sure: npt.NDArray[np.bool_]) -> Array:
    """``hurwitz_margin`` in sign agreement with ``hurwitz`` (issue 29 item 7).

    > 0 only where surely Hurwitz (NaN there if the eigenvalues say otherwise), else ≤ 0 (a
    root on the axis within round-off, 2e-16 from the eigenvalues, is reported as 0).
    """
    with np.errstate(invalid="ignore"):
        return np.where(sure, np.where(hm > 0, hm, np.nan), np.where(hm > 0, 0.0, hm))


def certify_kernel(
    kx: Array, kv: Array, ka: Array, p: Params, *, progress: bool = False, chunk: int = 4096,
    n_grid: int = 64, max_rounds: int = 30, max_intervals: int = 1024,
) -> CertificateBatch:
    """The continuous-time certificates of many triples (the kernel; module docstring).

    Inputs already checked by :func:`stringstab.certify.certify_batch` (the way in, which
    callers use): nothing is validated again here.

    Parameters
    ----------
    kx, kv, ka : ndarray of float64
        The gains, finite, one-dimensional, of one length.
    p : Params
        τ, δ, T* (checked on construction).
    progress : bool
        Show a tqdm progress bar over chunks.
    chunk : int
        Triples per vectorised chunk (bounds memory).
    n_grid, max_rounds, max_intervals : int
        Initial intervals on [0, Ω], refinement rounds, and the cap on undecided intervals
        per triple beyond which that triple is inconclusive.

    Returns
    -------
    CertificateBatch
        With ``method="exact"`` (the way in adds the Padé cross-check,
        :func:`stringstab.certify.pade.cross_check`).
    """
    n = kx.size
    verdict = np.empty(n, dtype=np.int8)
    margin = np.empty(n)
    omega_max = np.empty(n)
    n_evals = np.empty(n, dtype=np.int64)
    sup = np.empty(n)
    peak_w = np.empty(n)
    worst_w = np.empty(n)

    _theta_zero(p)
    # internal stability, with an inconclusive band around the boundary
    hz_sure, hz_fail = hurwitz_bands_kernel(kx, kv, tau=p.tau, headway=p.headway)
    hz_margin = _agreeing_margin(hurwitz_margin_kernel(kx, kv, tau=p.tau, headway=p.headway),
                                 hz_sure)

    for sl in chunks(n, chunk, progress=progress):
        ex = _exact_chunk(kx[sl], kv[sl], ka[sl], p.tau, p.delta, p.headway,
                          n_grid=n_grid, max_rounds=max_rounds, max_intervals=max_intervals,
                          refine=~hz_fail[sl])
        verdict[sl], margin[sl], omega_max[sl], n_evals[sl] = ex.verdict, ex.margin, ex.omega_max, ex.n_evals
        worst_w[sl] = ex.worst_omega
        # certified ⇒ sup |Γ| = 1 at ω = 0: only the others need a peak search
        need = ex.verdict != CERTIFIED
        sup[sl], peak_w[sl] = 1.0, 0.0
        if need.any():
            idx = np.arange(sl.start, sl.stop)[need]
            sup[idx], peak_w[idx] = _peak(
                kx[idx], kv[idx], ka[idx], p.tau, p.delta, p.headway, ex.omega_max[need],
                ex.grid_omega[need], ex.grid_g[need], ex.worst_omega[need],
            )

    verdict[~hz_sure] = _unsure_verdict(verdict[~hz_sure], hz_fail[~hz_sure])
    # rows in the Hurwitz band proven not string stable by g < 0 (their excess is reported)
    band_viol = ~hz_sure & ~hz_fail & (verdict == NOT_CERTIFIED)
    # certified ⇒ sup |Γ| = 1 exactly, at ω = 0 (Γ(0) = 1 for k_x ≠ 0)
    cert = verdict == CERTIFIED
    sup[cert] = np.maximum(sup[cert], 1.0)
    # not certified and stable ⇒ |Γ| > 1 somewhere: sup|Γ| − 1 without cancellation, so a
    # violation of 1e-20 (Ψ3 just below 0) is reported as such, at its frequency, not as 1 at 0;
    # searched only where the direct excess is below EXCESS_SEARCH (above it, it is exact enough)
    excess = np.where(cert, 0.0, sup - 1.0)
    viol = np.flatnonzero((verdict == NOT_CERTIFIED) & hz_sure & (excess < EXCESS_SEARCH))
    if viol.size:
        e2, w_e = _violation_peak(kx[viol], kv[viol], ka[viol], p.tau, p.delta, p.headway,
                                  omega_max[viol], np.stack([peak_w[viol], worst_w[viol]], axis=1))
        e1 = e2 / (1.0 + np.sqrt(1.0 + np.maximum(e2, 0.0)))  # sup|Γ| − 1
        # the candidates include the direct peak, so the search's value replaces the direct
        # |Γ| − 1, whose last bits are round-off when it is tiny (2.2e-16 for a 1e-20 excess)
        take = (e1 > 0) | (e1 >= excess[viol])
        excess[viol] = np.where(take, e1, excess[viol])
        peak_w[viol] = np.where(take, w_e, peak_w[viol])
        sup[viol] = np.where(take, 1.0 + e1, sup[viol])
    bv = np.flatnonzero(band_viol)
    if bv.size:  # a pole may sit on the axis: the excess at the proven witness of g < 0
        excess[bv], peak_w[bv] = _band_excess(kx[bv], kv[bv], ka[bv], p, worst_w[bv],
                                              omega_max[bv])
    excess = np.where(hz_sure | band_viol, excess, np.inf)
    hinf = np.where(hz_sure, sup, np.inf)
    td = taylor_criteria_kernel(kx, kv, ka, tau=p.tau, delta=p.delta, headway=p.headway,
                                source="derived")
    tp = taylor_criteria_kernel(kx, kv, ka, tau=p.tau, delta=p.delta, headway=p.headway,
                                source="printed")
    vnames = names(verdict)
    return CertificateBatch(
        k_x=kx, k_v=kv, k_a=ka, params=p, hurwitz=np.asarray(hz_sure),
        hurwitz_margin=hz_margin, verdict=vnames, type=np.array([TYPE_NAMES[int(t)] for t in td.type]) if n else np.array([], dtype=str),
        sup_gain=hinf, linf_gain=sup, peak_omega=peak_w, margin=margin, omega_max=omega_max,
        n_evals=n_evals, taylor_derived=td, taylor_printed=tp,
        sup_gain_excess=excess,
    )
