r"""Sound string-stability certificates for the sampled-data (zero-order hold) loop.

Every vehicle samples synchronously with period H (``sample_time``), holds its command
over the period and has the actuator lag τ; the delayed predecessor acceleration
a_{i−1}(kH − δ) is exact for any δ = mH + εH ≥ 0 (:func:`split_delay`).  The string
transfer function H(z) from the predecessor's acceleration samples to the follower's,
derived symbolically by :mod:`stringstab.derive.sampled_symbolic`, has the w-form
(w = z − 1) coefficients of :mod:`stringstab.certify.zoh`, computed without cancellation
as H → 0 in the interval arithmetic of :mod:`stringstab.certify.interval`.

**The margin.**  On the unit circle z = e^{jθ}, |H(e^{jθ})| ≤ 1 iff

.. math::
    g_H(θ) = P(ρ) + \cos(mθ)\,Y_r(ρ) + \sin(mθ)\sin θ\,Y_i(ρ) \;\ge 0,
    \qquad ρ = 4\sin^2(θ/2),

(:func:`sampled_margin`, :mod:`stringstab.certify.sampled_frequency`), the analogue of the
continuous margin g; g_H(ωH) → g(ω) of :func:`stringstab.certify.frequency.margin_g` as
H → 0.

**The decision** of max_{θ∈[0,π]} |H(e^{jθ})| ≤ 1 is a branch and bound
(:mod:`stringstab.certify.branch_bound`) on g_H over the compact [0, π] (no tail): on
[l, r] of width h, g_H ≥ min(g_H(l), g_H(r)) − M h²/8 with an explicit bound M ≥ |g_H''|
on [l, r] (:func:`~stringstab.certify.sampled_curvature.margin_curvature`).  Every
coefficient is computed together with a magnitude companion (the same arithmetic on
absolute values), and every comparison carries a slack of 10⁻¹³ (1 + m) times the
magnitude — hundreds of ulps, covering the round-off of the coefficients and of the
evaluation.  A tangency (g_H = 0 somewhere, e.g. at θ = 0) is left ``inconclusive``,
never ``certified``.

**Internal stability** is Schur stability of Δ (:mod:`stringstab.certify.schur`: the
bilinear conditions in the w-form, with a relative 10⁻¹² band left inconclusive).  The
delay adds m + 1 poles at z = 0.

Verdicts: ``certified`` (Schur and g_H ≥ 0 on [0, π], so sup_θ |H(e^{jθ})| = 1,
attained at θ = 0), ``not_certified`` (not Schur, or some θ with g_H(θ) < −slack, a
witness with |H(e^{jθ})| > 1), ``inconclusive`` (neither shown within the budget).  The
reported peak and sup|H| − 1 (:mod:`stringstab.certify.sampled_excess`) never enter a
verdict.

References
----------
IDL paper, eqs 3-9 (model) and eq 4 (law); :mod:`stringstab.derive.sampled_symbolic`.
N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM (2002),
§3.1 (the error bound γ_n × the computation on absolute values).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt

from ..io import TableColumn
from ..params import Box, Params
from .branch_bound import BranchAndBound, Evaluate, branch_and_bound, verdict_codes
from .excess import EXCESS_SEARCH, searched_excess
from .sampled_curvature import interval_terms, margin_curvature, point_curvature, point_stack
from .sampled_excess import peak_gain, violation_peak
from .sampled_frequency import circle_terms, margin_bound, point_margin
from .schur import schur_bands, spectral_radius_of
from .verdicts import (
    CERTIFIED,
    INCONCLUSIVE,
    NOT_CERTIFIED,
    ROW_COLUMNS,
    BatchResult,
    Check,
    SingleResult,
    chunks,
    names,
)
from .zoh import Coefficients, coefficients, point_coefficients, split_delay

__all__ = [
    "TABLE_COLUMNS",
    "SampledCertificate",
    "SampledCertificateBatch",
    "SampledCheck",
    "certify_kernel",
    "check_kernel",
    "check_members",
]

Array = npt.NDArray[np.float64]
Circle = tuple[Array, Array, Array, Array]


# ---------------------------------------------------------------------------
# The branch and bound of g_H ≥ 0 on [0, π]
# ---------------------------------------------------------------------------
@lru_cache(maxsize=32)
def _initial_grid(m: int, n_grid: int) -> tuple[Array, Circle, tuple[Array, Array]]:
    """The engine's initial grid on [0, π] (one row) and its terms (each row's), once per loop."""
    X = np.array([np.pi])[:, None] * np.linspace(0.0, 1.0, n_grid + 1)[None, :]
    circle = circle_terms(X, float(m))
    ends = interval_terms(X[:, :-1], X[:, 1:])
    for a in (X, *circle, *ends):
        a.setflags(write=False)
    return X, circle, ends


def _point_evaluator(co: Coefficients, m: int, n_grid: int) -> Evaluate:
    """The :data:`~stringstab.certify.branch_bound.Evaluate` of g_H for point coefficients.

    From one stack of :class:`~stringstab.certify.interval.Point` coefficients (a later round
    takes its rows), on the initial grid with :func:`_initial_grid`'s terms: the same numbers.
    """
    n = co.P[0].lo.size
    mm = np.full(n, float(m))
    every = np.arange(n)
    grid, circle, ends = _initial_grid(m, n_grid)
    S = point_stack(co)
    mcol = mm[:, None]

    def evaluate(idx: npt.NDArray[np.intp], X: Array) -> tuple[Array, Array, Array, Array]:
        full = idx.size == n and bool((idx == every).all())
        if S is None:
            sub = co if full else co.take(idx)
            G, E = margin_bound(X, sub, mm[idx])
            return G, G, E, margin_curvature(sub, mm[idx], X[:, :-1], X[:, 1:])
        L, R = X[:, :-1], X[:, 1:]
        if full and X.shape == (n, grid.shape[1]) and bool((X == grid).all()):
            G, E = point_margin(S, circle, mcol)
            return G, G, E, point_curvature(S, mm, L, R, ends)
        Si = S if full else S[..., idx]
        G, E = point_margin(Si, circle_terms(X, mm[idx]), mcol[idx])
        return G, G, E, point_curvature(Si, mm[idx], L, R)

    return evaluate


def _bnb_points(
    co: Coefficients, m: int, *, n_grid: int, max_rounds: int, max_intervals: int,
    refine: npt.NDArray[np.bool_] | None = None,
) -> BranchAndBound:
    """Branch and bound of g_H ≥ 0 on [0, π] for point coefficients (one item per triple)."""
    n = co.P[0].lo.size
    return branch_and_bound(n, _point_evaluator(co, m, n_grid), right=np.full(n, np.pi), n_grid=n_grid,
                            max_rounds=max_rounds, max_intervals=max_intervals, refine=refine)


# ---------------------------------------------------------------------------
# The verdicts alone
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class SampledCheck(Check):
    """The verdicts of the sampled certificate alone (:func:`stringstab.certify.api.check`).

    A :class:`~stringstab.certify.verdicts.Check` whose ``hurwitz`` is Schur stability of
    Δ(z), with ``sample_time`` and ``witness_theta`` filled.

    Attributes
    ----------
    verdict : ndarray of str
        ``"certified"``, ``"not_certified"`` or ``"inconclusive"``.
    hurwitz : ndarray of bool
        Internally stable (Δ Schur, surely, outside the 10⁻¹² boundary band); also
        :attr:`schur`.
    margin : ndarray
        Smallest g_H(θ) found.
    witness_omega, witness_theta : ndarray
        Where (ω = θ/H in rad/s, θ in rad/sample): for a Schur, not-certified triple a
        frequency with |H(e^{jθ})| > 1.
    """

    @property
    def schur(self) -> npt.NDArray[np.bool_]:
        """Δ(z) is Schur (internal stability of the sampled loop)."""
        return self.hurwitz


def _default_grid(m: int) -> int:
    """Initial intervals on [0, π]: more for a longer delay (cos mθ oscillates m/2 times)."""
    return 64 + 8 * m


def check_kernel(
    kx: Array, kv: Array, ka: Array, p: Params, H: float, tp: float, *,
    n_grid: int | None = None, max_rounds: int = 30, max_intervals: int = 1024,
) -> SampledCheck:
    """The sampled verdicts alone, for inner loops.

    The same sound decision as :func:`certify_kernel` without the peak search and the
    spectral radii.

    Inputs already checked by :func:`stringstab.certify.api.check` or
    :meth:`stringstab.certify.api.Loop.check` (the way in): nothing is validated again here.

    Parameters
    ----------
    kx, kv, ka : ndarray of float64
        The gains, finite, one-dimensional, of one length.
    p : Params
        τ, δ, T* (checked on construction).
    H : float
        Sampling period H > 0, s.
    tp : float
        The predecessor's lag τ_p > 0, s.
    n_grid, max_rounds, max_intervals : int
        Initial intervals on [0, π] (default 64 + 8m), refinement rounds, and the cap on
        undecided intervals per triple beyond which it is inconclusive.

    Returns
    -------
    SampledCheck
    """
    co, m = point_coefficients(kx, kv, ka, p, H, tp)
    sure, fail = schur_bands(co.delta, co.schur)
    bb = _bnb_points(co, m, n_grid=n_grid or _default_grid(m), max_rounds=max_rounds,
                     max_intervals=max_intervals, refine=~fail)
    v = verdict_codes(bb.status)
    v[~sure] = np.where(fail[~sure], NOT_CERTIFIED, INCONCLUSIVE)
    return SampledCheck(names(v), sure, bb.minimum, bb.argmin / H, sample_time=H,
                        witness_theta=bb.argmin)


def check_members(kx: Array, kv: Array, ka: Array, *, tau: Array, tau_prev: Array, delta: Array,
                  headway: Array, H: float) -> tuple[npt.NDArray[np.int8], Array, Array]:
    """The point certificate of :func:`check_kernel` at one member (τ, τ_p, δ, T*) per row.

    Row i is decided exactly as ``check(kx[i], kv[i], ka[i], tau=tau[i], delta=delta[i],
    headway=headway[i], sample_time=H, tau_prev=tau_prev[i])`` (the way in) decides it
    (the same coefficients, Schur test and branch and bound, grouped by m = ⌊δ/H⌋): what a
    box's members say of themselves (:mod:`stringstab.certify.robust_sampled`).

    Parameters
    ----------
    kx, kv, ka : ndarray, shape (n,)
        The gains (checked).
    tau, tau_prev, delta, headway : ndarray, shape (n,)
        Each row's member: τ > 0, τ_p > 0, δ ≥ 0, T* ≥ 0, s.
    H : float
        Sample time, s.

    Returns
    -------
    (ndarray of int8, ndarray, ndarray)
        Verdict codes, the smallest g_H found and where (θ, rad/sample; NaN when Δ is not
        Schur there).
    """
    n = kx.size
    v = np.full(n, INCONCLUSIVE, dtype=np.int8)
    g, th = np.full(n, np.nan), np.full(n, np.nan)
    split = [split_delay(float(d), H) for d in delta]
    m_all = np.array([s[0] for s in split], dtype=np.intp)
    e_all = np.array([s[1] for s in split], dtype=float)
    for m in np.unique(m_all):
        idx = np.flatnonzero(m_all == m)
        c = kv[idx] + headway[idx] * kx[idx]
        t, tp, e = tau[idx], tau_prev[idx], e_all[idx]
        co = coefficients(kx[idx], kv[idx], ka[idx], H=H, tau=(t, t), tau_p=(tp, tp),
                          eps=(e, e), c=(c, c))
        sure, fail = schur_bands(co.delta)
        bb = _bnb_points(co, int(m), n_grid=_default_grid(int(m)), max_rounds=30,
                         max_intervals=1024, refine=~fail)
        vi = verdict_codes(bb.status)
        vi[~sure] = np.where(fail[~sure], NOT_CERTIFIED, INCONCLUSIVE)
        v[idx], g[idx], th[idx] = vi, bb.minimum, np.where(fail, np.nan, bb.argmin)
    return v, g, th


# ---------------------------------------------------------------------------
# The certificate: verdicts, peaks and the result types
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class SampledCertificate(SingleResult):
    """The sampled-data certificate of one gain triple.

    Attributes
    ----------
    k_x, k_v, k_a : float
        The gains.
    params : Params
        τ, δ, T*.
    sample_time : float
        H, s.
    tau_prev : float
        The predecessor's lag (τ in a homogeneous platoon).
    schur : bool
        Δ(z) is Schur (internal stability of the sampled loop).
    spectral_radius : float
        max |root| of Δ(z); < 1 iff Schur.
    verdict : str
        ``"certified"``, ``"not_certified"`` or ``"inconclusive"``.
    sup_gain : float
        ‖H‖_∞ = sup_θ |H(e^{jθ})| for a Schur loop, ``inf`` otherwise.
    linf_gain : float
        sup_θ |H(e^{jθ})| regardless of stability.
    peak_theta, peak_omega : float
        Where that supremum is attained: θ in rad/sample and ω = θ/H in rad/s.
    margin : float
        Smallest g_H(θ) found (≥ 0 iff |H| ≤ 1; → the continuous margin as H → 0).
    n_evals : int
        Evaluations of g_H used.
    sup_gain_excess : float
        sup_θ |H(e^{jθ})| − 1 computed without cancellation: 0 when certified, > 0 when
        not certified and Schur (also when ``sup_gain`` rounds to 1.0, a violation near
        θ → 0 from a DC margin just below 0: ``peak_theta`` is then where it is attained),
        ``inf`` when Δ is not Schur.
    """

    k_x: float
    k_v: float
    k_a: float
    params: Params
    sample_time: float
    tau_prev: float
    schur: bool
    spectral_radius: float
    verdict: str
    sup_gain: float
    linf_gain: float
    peak_theta: float
    peak_omega: float
    margin: float
    n_evals: int = 0
    sup_gain_excess: float = float("nan")


#: The columns of the human table of sampled certificates (``stringstab certify --sample-time``).
TABLE_COLUMNS: list[TableColumn] = [
    *ROW_COLUMNS,
    TableColumn("schur", "schur"),
    TableColumn("ρ(Δ)", "spectral_radius", "%.4g"),
    TableColumn("verdict", "verdict"),
    TableColumn("sup|H|", "sup_gain", "%.6g", missing="inf"),
    TableColumn("sup|H|-1", "sup_gain_excess", "%.3g", missing="inf"),
    TableColumn("ω_peak[rad/s]", "peak_omega", "%.4g"),
    TableColumn("θ_peak[rad/sample]", "peak_theta", "%.4g"),
    TableColumn("margin", "margin", "%.3g"),
]


@dataclass(frozen=True)
class SampledCertificateBatch(BatchResult):
    """Sampled certificates of many triples, as arrays (fields of :class:`SampledCertificate`)."""

    SINGLE: ClassVar[type[SampledCertificate]] = SampledCertificate
    SHARED: ClassVar[tuple[str, ...]] = ("params", "sample_time", "tau_prev")
    TABLE: ClassVar[Sequence[TableColumn]] = TABLE_COLUMNS

    k_x: Array
    k_v: Array
    k_a: Array
    params: Params
    sample_time: float
    tau_prev: float
    schur: npt.NDArray[np.bool_]
    spectral_radius: Array
    verdict: npt.NDArray[np.str_]
    sup_gain: Array
    linf_gain: Array
    peak_theta: Array
    peak_omega: Array
    margin: Array
    n_evals: npt.NDArray[np.int64]
    sup_gain_excess: Array


    def __getitem__(self, i: int) -> SampledCertificate:
        return super().__getitem__(i)  # type: ignore[no-any-return]

    @property
    def stable(self) -> npt.NDArray[np.bool_]:  # type: ignore[override]
        """Internally stable (Δ(z) Schur, surely): :attr:`schur`, the protocol's name."""
        return self.schur

    @property
    def box(self) -> Box:
        """The parameters as a (point) box."""
        return Box.of(self.params)

    def columns(self) -> dict[str, Any]:
        """The result columns, one row per triple, with the (point) box group.

        The gains, ``schur``, ``spectral_radius``, ``verdict``, ``sup_gain``,
        ``sup_gain_excess``, ``linf_gain``, the peak (``peak_omega``, ``peak_theta``) and
        ``margin``; then ``sample_time``, ``tau_prev`` and the ``box`` group (``tau_lo``,
        ``tau_hi``, ...).  Non-finite numbers stay as they are (``sup_gain`` is ``inf`` when Δ
        is not Schur).

        Returns
        -------
        dict
            Column name to ndarray; ``box`` maps to a dict of ndarrays.

        Examples
        --------
        >>> from stringstab.certify.api import certify_batch
        >>> b = certify_batch([1.2], [0.5], [0.6], tau=0.1, delta=0.2, headway=1.1,
        ...                   sample_time=0.1)
        >>> c = b.columns()
        >>> c["verdict"].tolist(), c["sample_time"].tolist(), c["box"]["delta_hi"].tolist()
        (['certified'], [0.1], [0.2])
        """
        n = len(self)
        return {
            "k_x": self.k_x, "k_v": self.k_v, "k_a": self.k_a, "schur": self.schur,
            "spectral_radius": self.spectral_radius, "verdict": self.verdict,
            "sup_gain": self.sup_gain, "sup_gain_excess": self.sup_gain_excess,
            "linf_gain": self.linf_gain,
            "peak_omega": self.peak_omega, "peak_theta": self.peak_theta, "margin": self.margin,
            "sample_time": np.full(n, self.sample_time), "tau_prev": np.full(n, self.tau_prev),
            "box": self.box.columns(n),
        }

    def summary_extra(self) -> dict[str, Any]:
        """The sample time, the predecessor's lag and the (point) box."""
        return {"sample_time": self.sample_time, "tau_prev": self.tau_prev,
                "box": self.box.as_dict()}


SampledCertificate.BATCH = SampledCertificateBatch


def certify_kernel(
    kx: Array, kv: Array, ka: Array, p: Params, H: float, tp: float, *, chunk: int = 4096,
    n_grid: int | None = None, max_rounds: int = 30, max_intervals: int = 1024,
    progress: bool = False,
) -> SampledCertificateBatch:
    """The sampled-data certificates of many triples (sound; module docstring).

    Inputs already checked by :func:`stringstab.certify.api.certify_batch` or
    :meth:`stringstab.certify.api.Loop.certify_batch` (the way in): nothing is validated
    again here.

    Parameters
    ----------
    kx, kv, ka : ndarray of float64
        The gains, finite, one-dimensional, of one length.
    p : Params
        τ, δ, T* (checked on construction).
    H : float
        Sampling period H > 0, s.
    tp : float
        The predecessor's lag τ_p > 0, s.
    chunk : int
        Triples per vectorised chunk.
    n_grid, max_rounds, max_intervals : int
        As for :func:`check_kernel`.
    progress : bool
        Show a tqdm progress bar over chunks.

    Returns
    -------
    SampledCertificateBatch
    """
    n = kx.size
    verdict = np.empty(n, dtype=np.int8)
    margin = np.empty(n)
    n_evals = np.empty(n, dtype=np.int64)
    sup = np.ones(n)
    peak = np.zeros(n)
    excess = np.zeros(n)
    sure = np.empty(n, dtype=bool)
    rad = np.empty(n)
    for sl in chunks(n, chunk, progress=progress, desc="certify (sampled)"):
        co, m = point_coefficients(kx[sl], kv[sl], ka[sl], p, H, tp)
        s_sure, s_fail = schur_bands(co.delta)
        bb = _bnb_points(co, m, n_grid=n_grid or _default_grid(m), max_rounds=max_rounds,
                         max_intervals=max_intervals, refine=~s_fail)
        v = verdict_codes(bb.status)
        v[~s_sure] = np.where(s_fail[~s_sure], NOT_CERTIFIED, INCONCLUSIVE)
        verdict[sl], margin[sl], n_evals[sl], sure[sl] = v, bb.minimum, bb.n_evals, s_sure
        rad[sl] = spectral_radius_of([d.lo for d in co.delta])
        need = v != CERTIFIED
        if need.any():
            idx = np.flatnonzero(need)
            sub = co.take(idx)
            sp_, pw = peak_gain(sub, m, ka[sl][idx], bb.grid_x[idx], bb.argmin[idx])
            sup[sl][idx] = sp_
            peak[sl][idx] = pw
            # not certified and Schur ⇒ |H| > 1 somewhere: sup|H| − 1 without cancellation,
            # so a violation of 1e-20 near θ = 0 is reported as such, where it is attained
            # (rows whose |H| − 1 from the direct search keeps ≥ 12 digits are left as they are)
            excess[sl][idx] = sp_ - 1.0
            viol = np.flatnonzero((v == NOT_CERTIFIED) & s_sure & (excess[sl] < EXCESS_SEARCH))
            if viol.size:
                kappa = np.full(viol.size, p.tau * tp / H**3)
                e2, th = violation_peak(co.take(viol), m, kappa,
                                         np.stack([peak[sl][viol], bb.argmin[viol]], axis=1))
                e1, take = searched_excess(e2, excess[sl][viol])
                excess[sl][viol] = np.where(take, e1, excess[sl][viol])
                peak[sl][viol] = np.where(take, th, peak[sl][viol])
                sup[sl][viol] = np.where(take, 1.0 + e1, sup[sl][viol])
    excess = np.where(sure, excess, np.inf)
    hinf = np.where(sure, sup, np.inf)
    return SampledCertificateBatch(
        k_x=kx, k_v=kv, k_a=ka, params=p, sample_time=H, tau_prev=tp, schur=sure,
        spectral_radius=rad, verdict=names(verdict), sup_gain=hinf, linf_gain=sup,
        peak_theta=peak, peak_omega=peak / H, margin=margin, n_evals=n_evals,
        sup_gain_excess=excess,
    )
