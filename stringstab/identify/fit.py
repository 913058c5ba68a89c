"""Closed-loop simulation-error fit of the eq-4 law to one follower's record.

The follower is driven by its *measured* predecessor (speed, and acceleration for ``cacc``)
from an initial gap, speed and acceleration at the start of each clean segment
(:func:`stringstab.identify.closed_loop.simulate_follower`).  Those initial states are fitted
too, as nuisance parameters within :data:`INITIAL_SLACK` of the measured ones (standard in
output-error identification): a start taken from two noisy samples, or an acceleration the
log does not hold, leaves a transient that a lightly damped follower carries for tens of
seconds, and a fit would bend the law's parameters to reproduce it.  The parameters minimise the sum of
squares of the simulated-minus-measured speed and gap over every sample of every segment, each
normalised by the spread of its measured signal so that neither dominates by its unit
(:func:`scipy.optimize.least_squares`, trust-region reflective with the LSMR sub-solver,
bounds below; the dense-SVD sub-solver was up to 60x slower on a shared machine, where the
multi-threaded BLAS of a 5000 × 11 SVD contends with other processes).  This is the
simulation (not one-step prediction) error used for car-following calibration in the
literature (Punzo et al. 2012; Gunter et al. 2021): a one-step fit rewards models that track
the data with feedback they do not have.

Identifiability is judged at the optimum from the Jacobian J of the normalised residuals:
the correlation matrix of (JᵀJ)⁻¹ (two parameters whose estimates correlate beyond 0.99 are
reported: the log separates them only through small differences, so their bootstrap intervals,
not their point values, are what the log says) and the speed range (T* v + l_0 is only
separable into T* and l_0 when v varies).  A high correlation alone is not
non-identifiability (a noise-free log pins down even strongly correlated parameters); the
block bootstrap measures how far the noise actually moves them, and the profile over T*
(:func:`profile_headway`) whether the verdict depends on the weakly separated T*.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..io.platoon_logs import Segment
from .blas import single_threaded_blas
from .closed_loop import FollowerModel, simulate_follower

__all__ = ["BOUNDS", "PARAMETERS", "FitResult", "FollowerData", "fit_follower", "model_of",
           "parameter_names"]

Array = npt.NDArray[np.float64]

#: Parameters estimated per model, in the order of the parameter vector.
PARAMETERS: dict[str, tuple[str, ...]] = {
    "acc": ("k_x", "k_v", "tau", "headway", "standstill"),
    "cacc": ("k_x", "k_v", "tau", "headway", "standstill", "k_a", "delta"),
}

#: Search box of each parameter (units of docs/conventions.md; standstill in m).  Wide enough
#: for commercial ACC (k_x ~ 0.01-0.3 s⁻², k_v ~ 0.1-1 s⁻¹, lags up to ~1 s, headways 0.6-3 s)
#: and for people (reaction delays θ_r of 0.5-2 s).
BOUNDS: dict[str, tuple[float, float]] = {
    "k_x": (1e-3, 3.0),
    "k_v": (-0.5, 4.0),
    "tau": (0.02, 3.0),
    "headway": (0.0, 5.0),
    "standstill": (0.0, 40.0),
    "k_a": (-1.0, 2.0),
    "delta": (0.0, 1.5),
    "reaction_delay": (0.0, 2.5),
}

#: |correlation| of two estimates beyond which they are reported as not separately identified.
CORRELATION_LIMIT = 0.99


@dataclass(frozen=True)
class FollowerData:
    """One follower's record: predecessor and follower signals and the clean segments."""

    v_pred: Array
    v: Array
    gap: Array
    a_pred: Array | None
    segments: tuple[Segment, ...]
    dt: float

    @property
    def n_samples(self) -> int:
        """Samples used by the fit."""
        return sum(len(s) for s in self.segments)

    def scales(self) -> tuple[float, float]:
        """Normalisers of the speed and gap residuals (m/s, m).

        The spread (std) of each measured signal over the segments, floored at 0.1 m/s and
        0.5 m.
        """
        v = np.concatenate([self.v[s.start:s.stop] for s in self.segments])
        g = np.concatenate([self.gap[s.start:s.stop] for s in self.segments])
        return max(float(v.std()), 0.1), max(float(g.std()), 0.5)


def parameter_names(model: str, fit_delay: bool = False) -> tuple[str, ...]:
    """The parameters a fit estimates, in the order of its parameter vector.

    Parameters
    ----------
    model : {"acc", "cacc"}
        :data:`PARAMETERS`.
    fit_delay : bool
        Also the reaction delay θ_r (``reaction_delay``, issue 25), last.

    Returns
    -------
    tuple of str
        The names.

    Examples
    --------
    >>> parameter_names("acc", fit_delay=True)
    ('k_x', 'k_v', 'tau', 'headway', 'standstill', 'reaction_delay')
    """
    return PARAMETERS[model] + (("reaction_delay",) if fit_delay else ())


def model_of(theta: Array, names: tuple[str, ...]) -> FollowerModel:
    """The :class:`FollowerModel` of a parameter vector (k_a = δ = θ_r = 0 when not estimated).

    Parameters
    ----------
    theta : ndarray
        Parameter values, in the order of ``names``.
    names : tuple of str
        Their names, among ``k_x``, ``k_v``, ``k_a``, ``tau``, ``delta``, ``headway``,
        ``standstill``, ``reaction_delay`` (all but ``k_a``, ``delta`` and ``reaction_delay``
        required).

    Returns
    -------
    FollowerModel
        The follower law with those parameters.
    """
    p = dict(zip(names, (float(x) for x in theta)))
    return FollowerModel(p["k_x"], p["k_v"], p.get("k_a", 0.0), p["tau"], p.get("delta", 0.0),
                         p["headway"], p["standstill"], p.get("reaction_delay", 0.0))


#: Samples of the straight line fitted to the start of a segment for its initial state.
INITIAL_WINDOW = 20


def initial_state(v: Array, dt: float) -> tuple[float, float]:
    """Initial speed and acceleration of a segment, from a line through its first speeds.

    The straight line is fitted by least squares to the first :data:`INITIAL_WINDOW` speeds (a
    difference of two noisy GPS speeds would make
    a0 err by ~σ√2/Δt, 0.7 m/s² for σ = 0.05 m/s at 10 Hz).

    Parameters
    ----------
    v : ndarray
        Measured speeds of the segment (m/s), sampled every ``dt``.
    dt : float
        Sample time (s).

    Returns
    -------
    v0, a0 : float
        The line's intercept (m/s) and slope (m/s²) at the segment's first sample.
    """
    n = min(v.size, INITIAL_WINDOW)
    slope, icpt = np.polyfit(np.arange(n) * dt, v[:n], 1)
    return float(icpt), float(slope)


def measured_initial(data: FollowerData) -> Array:
    """(s0, v0, a0) of each segment from the data: the starting values of the fit's initial states.

    Straight lines are fitted to each segment's first :data:`INITIAL_WINDOW` gaps and speeds.

    Parameters
    ----------
    data : FollowerData
        The follower's measured record and its segments.

    Returns
    -------
    ndarray
        Shape (number of segments, 3): gap s0 (m), speed v0 (m/s), acceleration a0 (m/s²).
    """
    out = np.empty((len(data.segments), 3))
    for i, s in enumerate(data.segments):
        n = min(len(s), INITIAL_WINDOW)
        v0, a0 = initial_state(data.v[s.start:s.stop], data.dt)
        g0 = float(np.polyval(np.polyfit(np.arange(n) * data.dt, data.gap[s.start:s.start + n], 1), 0.0))
        out[i] = (g0, v0, a0)
    return out


#: How far the fitted initial state of a segment may move from the measured one: gap (m),
#: speed (m/s), acceleration (m/s²).
INITIAL_SLACK = (3.0, 1.0, 2.0)


def simulate_segments(m: FollowerModel, data: FollowerData,
                      initial: Array | None = None) -> tuple[list[Array], list[Array]]:
    """Simulated gap and speed on every segment from its initial state.

    The initial states default to the measured ones (:func:`measured_initial`).

    Parameters
    ----------
    m : FollowerModel
        The follower law simulated.
    data : FollowerData
        The record: the predecessor's speed (and acceleration, if measured) drive the follower.
    initial : ndarray, optional
        Initial (s0 m, v0 m/s, a0 m/s²) of each segment, any shape reshapable to (n, 3).

    Returns
    -------
    gaps, speeds : list of ndarray
        Per segment, the simulated gap (m) and speed (m/s).
    """
    init = measured_initial(data) if initial is None else np.asarray(initial).reshape(-1, 3)
    gaps, speeds = [], []
    for s, (g0, v0, a0) in zip(data.segments, init):
        vp = data.v_pred[s.start:s.stop]
        ap = None if data.a_pred is None else data.a_pred[s.start:s.stop]
        g, vs = simulate_follower(m, vp, data.dt, s0=float(g0), v0=float(v0), a0=float(a0), a_pred=ap)
        gaps.append(g)
        speeds.append(vs)
    return gaps, speeds


def _residuals(x: Array, names: tuple[str, ...], data: FollowerData, sv: float, sg: float,
               w: Array | None) -> Array:
    p = len(names)
    gaps, speeds = simulate_segments(model_of(x[:p], names), data, x[p:])
    parts = []
    for s, g, v in zip(data.segments, gaps, speeds):
        parts.append((v - data.v[s.start:s.stop]) / sv)
        parts.append((g - data.gap[s.start:s.stop]) / sg)
    r = np.concatenate(parts)
    r = np.nan_to_num(r, nan=1e6, posinf=1e6, neginf=-1e6)
    np.clip(r, -1e6, 1e6, out=r)
    if w is not None:
        r *= w
    return r


def residual_weights(data: FollowerData, counts: Array) -> Array:
    """Per-residual weights √c_k from per-sample counts c_k.

    c_k is the block bootstrap's multiplicity of sample k; the weights are in the order of the
    residual vector (speed then gap of each segment).

    Parameters
    ----------
    data : FollowerData
        The record whose segments order the residuals.
    counts : ndarray
        Per-sample counts over the whole record (:func:`~stringstab.identify.core.block_counts`).

    Returns
    -------
    ndarray
        The weights, one per residual.
    """
    parts = []
    for s in data.segments:
        c = np.sqrt(counts[s.start:s.stop])
        parts += [c, c]
    return np.concatenate(parts)


@dataclass
class FitResult:
    """The fit of one follower.

    Attributes
    ----------
    params : dict
        Estimated parameters by name (plus k_a = δ = 0 for ``acc``, θ_r = 0 unless fitted).
    rmse_speed, rmse_gap : float
        Root-mean-square simulation error in speed (m/s) and gap (m).
    cost : float
        Half the sum of squared normalised residuals.
    at_bound : list of str
        Parameters within 0.1 % of the search box's width of a bound.
    notes : list of str
        Identifiability notes (module docstring).
    correlation : dict
        Correlations of the estimates above :data:`CORRELATION_LIMIT` in absolute value.
    starts : int
        Starting points tried; ``nfev`` evaluations in all; ``best_start`` the index of the
        one whose optimum was kept (0: the first; a later one only when better by more than
        10⁻⁶ of the cost), ``start_costs`` the optimum's cost from each.
    theta, names : array, tuple of str
        The whole solution vector (the parameters ``names``, then the initial states) and
        the parameter names.
    initial : array (n_segments, 3)
        Fitted initial gap, speed and acceleration of each segment.
    rmse_speed_measured_start, rmse_gap_measured_start : float
        The same fit's errors simulated from the *measured* initial state of each segment
        (:func:`measured_initial`) instead of the fitted one: a free restart per segment
        flatters the error, this does not.
    """

    params: dict[str, float]
    rmse_speed: float
    rmse_gap: float
    cost: float
    at_bound: list[str]
    notes: list[str] = field(default_factory=list)
    correlation: dict[str, float] = field(default_factory=dict)
    starts: int = 1
    nfev: int = 0
    theta: Array | None = None
    names: tuple[str, ...] = ()
    initial: Array | None = None
    best_start: int = 0
    start_costs: list[float] = field(default_factory=list)
    rmse_speed_measured_start: float = math.nan
    rmse_gap_measured_start: float = math.nan


def _starts(names: tuple[str, ...], data: FollowerData, n: int, rng: np.random.Generator,
            fixed: dict[str, float] | None = None) -> list[Array]:
    """Starting points: a typical ACC first, then draws from plausible ranges.

    Each l_0 comes from the data's mean gap at the drawn T*.
    """
    vbar = float(np.mean([data.v[s.start:s.stop].mean() for s in data.segments]))
    gbar = float(np.mean([data.gap[s.start:s.stop].mean() for s in data.segments]))
    typical = {"k_x": 0.1, "k_v": 0.4, "tau": 0.5, "headway": 1.2, "k_a": 0.3, "delta": 0.2,
               "reaction_delay": 0.3}
    lo = {"k_x": 0.02, "k_v": 0.1, "tau": 0.1, "headway": 0.5, "k_a": 0.0, "delta": 0.05,
          "reaction_delay": 0.0}
    hi = {"k_x": 0.6, "k_v": 1.5, "tau": 1.2, "headway": 2.5, "k_a": 0.8, "delta": 0.5,
          "reaction_delay": 1.0}
    out = []
    for i in range(n):
        p = dict(typical) if i == 0 else {k: float(rng.uniform(lo[k], hi[k])) for k in lo}
        p.update(fixed or {})
        if "headway" not in (fixed or {}):
            p["headway"] = min(p["headway"], max(gbar / max(vbar, 0.1), 0.0))
        p["standstill"] = min(max(gbar - p["headway"] * vbar, 0.5), BOUNDS["standstill"][1] - 1)
        out.append(np.array([p[k] for k in names]))
    return out


def start_points(data: FollowerData, model: str = "acc", n: int = 1, *, seed: int = 0,
                 fit_delay: bool = False, fixed: dict[str, float] | None = None) -> list[Array]:
    """Whole starting vectors of :func:`fit_follower` (parameters, then measured initial states).

    The first is a typical ACC, the others random draws from plausible ranges (l_0 from the
    data's mean gap at the drawn T*).

    Parameters
    ----------
    data : FollowerData
        The record.
    model : {"acc", "cacc"}
        The law.
    n : int
        How many.
    seed : int
        Seed of the draws.
    fit_delay : bool
        Include θ_r.
    fixed : dict, optional
        Parameters held at a value.

    Returns
    -------
    list of ndarray
        ``n`` starting vectors.
    """
    names = parameter_names(model, fit_delay)
    init0 = measured_initial(data).ravel()
    return [np.r_[x, init0] for x in _starts(names, data, max(n, 1), np.random.default_rng(seed), fixed)]


def fit_follower(data: FollowerData, model: str = "acc", *, n_starts: int = 4, seed: int = 0,
                 x0: Array | list[Array] | None = None, counts: Array | None = None,
                 identifiability: bool = True, fixed: dict[str, float] | None = None,
                 fit_delay: bool = False,
                 bounds: dict[str, tuple[float, float]] | None = None) -> FitResult:
    """Fit the eq-4 law and the lag to one follower by closed-loop simulation error.

    Parameters
    ----------
    data : FollowerData
        The record and its clean segments.
    model : {"acc", "cacc"}
        ``acc``: k_a = 0 (no communication; δ is then irrelevant); ``cacc``: k_a and δ too
        (needs the predecessor's acceleration).
    n_starts : int
        Starting points (the best optimum is kept); ignored when ``x0`` is given.
    seed : int
        Seed of the random starting points.
    x0 : array or list of arrays, optional
        Whole starting vectors (parameters, then initial states) instead of ``n_starts``
        generated ones (the bootstrap starts from the point estimate and a random draw).
    counts : array (T,), optional
        Per-sample multiplicities (the block bootstrap); default 1.
    identifiability : bool
        Compute the correlation and speed-range notes.
    fixed : dict, optional
        Parameters held at a value (e.g. ``{"headway": 1.0}`` for a profile).
    fit_delay : bool
        Also estimate the reaction delay θ_r on the whole law (issue 25).
    bounds : dict, optional
        Narrower search intervals for some parameters (e.g. T* within the spacing policy's
        interval), replacing :data:`BOUNDS` for them.

    Returns
    -------
    FitResult
        The best optimum over the starting points.
    """
    from scipy.optimize import least_squares

    if model not in PARAMETERS:
        raise StringStabError(f"model must be 'acc' or 'cacc'; got {model!r}")
    names = parameter_names(model, fit_delay)
    if model == "cacc" and data.a_pred is None:
        raise StringStabError("--model cacc needs the predecessor's acceleration; this log has none")
    sv, sg = data.scales()
    w = None if counts is None else residual_weights(data, counts)
    box = {**BOUNDS, **(bounds or {})}
    for k, val in (fixed or {}).items():
        box[k] = (float(val), float(val) + 1e-9)
    init0 = measured_initial(data)
    slack = np.tile(INITIAL_SLACK, len(data.segments))
    p = len(names)
    lb = np.r_[[box[k][0] for k in names], init0.ravel() - slack]
    ub = np.r_[[box[k][1] for k in names], init0.ravel() + slack]
    if x0 is not None:
        xs = [np.asarray(x, dtype=float) for x in (x0 if isinstance(x0, list) else [x0])]
    else:
        xs = [np.r_[x, init0.ravel()]
              for x in _starts(names, data, max(n_starts, 1), np.random.default_rng(seed), fixed)]
    best: Any = None
    best_start = 0
    costs: list[float] = []
    nfev = 0
    with single_threaded_blas():
        for i, x in enumerate(xs):
            xc = np.clip(x, lb + 1e-9 * (ub - lb), ub - 1e-9 * (ub - lb))
            res = least_squares(_residuals, xc, bounds=(lb, ub), args=(names, data, sv, sg, w),
                                x_scale="jac", max_nfev=400, xtol=1e-8, ftol=1e-8, tr_solver="lsmr")
            nfev += int(res.nfev)
            costs.append(float(res.cost))
            if best is None or res.cost < best.cost * (1 - 1e-6):
                best, best_start = res, i
    theta = best.x
    m = model_of(theta[:p], names)
    init = theta[p:].reshape(-1, 3)
    gaps, speeds = simulate_segments(m, data, init)
    ev = np.concatenate([v - data.v[s.start:s.stop] for s, v in zip(data.segments, speeds)])
    eg = np.concatenate([g - data.gap[s.start:s.stop] for s, g in zip(data.segments, gaps)])
    width = ub - lb
    at_bound = [k for k, x, lo_, hi_, wd in zip(names, theta, lb, ub, width)
                if k not in (fixed or {}) and (x - lo_ < 1e-3 * wd or hi_ - x < 1e-3 * wd)]
    params = {"k_x": m.k_x, "k_v": m.k_v, "k_a": m.k_a, "tau": m.tau, "delta": m.delta,
              "headway": m.headway, "standstill": m.standstill, "reaction_delay": m.reaction_delay}
    gm, sm = simulate_segments(m, data)  # from the measured initial states
    evm = np.concatenate([v - data.v[s.start:s.stop] for s, v in zip(data.segments, sm)])
    egm = np.concatenate([g - data.gap[s.start:s.stop] for s, g in zip(data.segments, gm)])
    out = FitResult(params, float(np.sqrt(np.mean(ev ** 2))), float(np.sqrt(np.mean(eg ** 2))),
                    float(best.cost), at_bound, starts=len(xs), nfev=nfev, theta=theta, names=names,
                    initial=init, best_start=best_start, start_costs=costs,
                    rmse_speed_measured_start=float(np.sqrt(np.mean(evm ** 2))),
                    rmse_gap_measured_start=float(np.sqrt(np.mean(egm ** 2))))
    if identifiability:
        out.notes, out.correlation = _identifiability(best.jac, names, data, at_bound, box)
    return out


def _identifiability(J: Array, names: tuple[str, ...], data: FollowerData, at_bound: list[str],
                     box: dict[str, tuple[float, float]]) -> tuple[list[str], dict[str, float]]:
    notes: list[str] = []
    corr: dict[str, float] = {}
    J = np.asarray(J, dtype=float)
    # parameters at a bound are fixed for this analysis (their column is not free)
    # (the initial states are free nuisance columns: the covariance of the parameters is the
    # corresponding block of the inverse over all free columns)
    free = [i for i, k in enumerate(names) if k not in at_bound]
    n_par = len(free)
    free += list(range(len(names), J.shape[1]))
    Jf = J[:, free]
    JtJ = Jf.T @ Jf
    ev = np.linalg.eigvalsh(JtJ)  # on the small normal matrix: no SVD of the tall Jacobian
    if ev.size == 0 or ev[0] <= ev[-1] * 1e-20:
        notes.append("the Jacobian is (numerically) rank deficient: some parameter does not "
                     "affect the simulated speed or gap on this log")
    else:
        cov = np.linalg.pinv(JtJ)
        d = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
        R = cov / np.outer(d, d)
        for a in range(n_par):
            for b in range(a + 1, n_par):
                if abs(R[a, b]) > CORRELATION_LIMIT:
                    ka, kb = names[free[a]], names[free[b]]
                    corr[f"{ka}/{kb}"] = float(R[a, b])
                    notes.append(f"{ka} and {kb} trade off (estimate correlation {R[a, b]:+.3f} from "
                                 "the fit's Jacobian): the log separates them only weakly; read "
                                 "their bootstrap intervals")
    v = np.concatenate([data.v[s_.start:s_.stop] for s_ in data.segments])
    lo, hi = np.percentile(v, [5, 95])
    if hi - lo < 0.2 * max(float(v.mean()), 1.0) and not any("headway" in n and "standstill" in n for n in notes):
        notes.append(f"the speed stays within {lo:.3g}-{hi:.3g} m/s (5-95 %): T* v + l_0 is "
                     "nearly constant, so T* and the standstill distance are weakly separated")
    for k in at_bound:
        lo_b, hi_b = box[k]
        where = "search box" if box[k] == BOUNDS[k] else "constraint"
        notes.append(f"{k} stopped at the bound of its {where} [{lo_b:.3g}, {hi_b:.3g}]: the "
                     "fit would go further; treat it and the verdict with care")
    return notes, corr


def rms(x: Array) -> float:
    """Root mean square.

    Parameters
    ----------
    x : ndarray
        Values (any shape).

    Returns
    -------
    float
        √mean(x²); NaN for an empty array.
    """
    return float(math.sqrt(float(np.mean(np.square(x))))) if x.size else math.nan


def profile_headway(data: FollowerData, model: str, grid: Array, *, n_starts: int = 2,
                    seed: int = 0, fit_delay: bool = False, name: str = "headway") -> list[FitResult]:
    """Refit with T* held at each value of ``grid`` (a profile over the time headway).

    When T* and l_0 are weakly separated (the speed varies little), the best fit may pick any T*
    at a small cost; the profile shows how much each fixed T* costs in RMSE and whether the
    verdict depends on it.

    Parameters
    ----------
    data, model, n_starts, seed, fit_delay
        As for :func:`fit_follower`.
    grid : array
        Values of the profiled parameter (T* by default), s.
    name : str
        The parameter held: ``"headway"`` (T*) or ``"reaction_delay"`` (θ_r).

    Returns
    -------
    list of FitResult
        One per grid value (the parameter at the grid value, the others refitted).
    """
    return [fit_follower(data, model, n_starts=n_starts, seed=seed, identifiability=False,
                         fixed={name: float(T)}, fit_delay=fit_delay) for T in grid]
