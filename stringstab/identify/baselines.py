"""The usual car-following models beside the eq-4 law: IDM and OVRV, calibrated on the same data.

Both are fitted on the same clean segments as the law, by the same criterion (closed-loop
simulation error in speed and gap, each normalised by its measured spread, driven by the
measured predecessor), from the **measured** initial state of each segment — so their errors
compare with the law's ``rmse_*_measured_start``, not with its fitted restarts.

* **OVRV** (optimal velocity with relative velocity, the model Gunter et al. 2021 fitted to
  commercial ACC): v' = k_1 (s − η − τ_h v) + k_2 (v_p − v) — the eq-4 law without a lag
  (k_x = k_1, k_v = k_2, T* = τ_h, l_0 = η), simulated exactly like the law with τ = 0 (the
  command is the acceleration, held over each step).
* **IDM** (Treiber, Hennecke & Helbing 2000): v' = a [1 − (v/v_0)^4 − (s*/s)²],
  s* = s_0 + v T + v (v − v_p)/(2√(a b)), with the ballistic update on the log's grid
  (Treiber & Kanagaraj 2015) and the speed kept ≥ 0; parameters v_0, T, s_0, a, b.

**Their string verdicts, by linearisation about the equilibrium.**  A model v' = f(s, v, v_p)
about an equilibrium (s_e, v_e) (f = 0, v_p = v_e) is, to first order,
ṽ' = f_s s̃ − f_v⁻ ṽ + f_Δ (ṽ_p − ṽ) with f_s = ∂f/∂s, f_v⁻ = −∂f/∂v at fixed v_p − v and
f_Δ = ∂f/∂(v_p − v): the eq-4 law without lag with

    k_x = f_s,   k_v = f_Δ,   T* = f_v⁻ / f_s.

For the IDM at speed v_e (s* = s_0 + v_e T, s_e = s*/√(1 − (v_e/v_0)^4)):
f_s = 2a s*²/s_e³, f_v⁻ = a [4 v_e³/v_0⁴ + 2 s* T/s_e²], f_Δ = a s* v_e/(s_e² √(ab)); OVRV is
linear already.  The lag-free loop Γ(s) = (k_v s + k_x)/(s² + (k_x T* + k_v) s + k_x) is
internally stable iff k_x > 0 and k_x T* + k_v > 0, and |Γ(jω)| ≤ 1 at every ω iff
k_x T*² + 2 k_v T* − 2 ≥ 0 (|Γ|² ≤ 1 ⇔ ω² + (k_x T* + k_v)² − k_v² − 2k_x ≥ 0 for all ω); in
the model's derivatives, f_v⁻²/2 + f_Δ f_v⁻ − f_s ≥ 0, the criterion of Wilson & Ward (2011)
for general car-following models (their f_v = −f_v⁻), and Gunter et al.'s for OVRV.  **The certificate that
judges the baselines is this closed form** (:func:`lag_free_certificate`), exact for the
second-order loop; the toolkit's own certificate needs τ > 0 and is not used for them.  The
equilibrium speed is the median speed of the segments.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify.verdicts import Verdict
from .blas import single_threaded_blas
from .closed_loop import FollowerModel, simulate_follower
from .fit import FollowerData, measured_initial, rms

__all__ = ["IDM_BOUNDS", "OVRV_BOUNDS", "Baseline", "fit_baselines", "fit_idm", "fit_ovrv",
           "idm_linearisation", "lag_free_certificate", "simulate_idm"]

Array = npt.NDArray[np.float64]

#: IDM's parameters and search box: desired speed v_0 (m/s), time gap T (s), jam distance s_0 (m),
#: maximum acceleration a and comfortable deceleration b (m/s²).
IDM_BOUNDS: dict[str, tuple[float, float]] = {
    "v0": (3.0, 70.0), "T": (0.05, 5.0), "s0": (0.0, 30.0), "a": (0.05, 6.0), "b": (0.05, 10.0)}
#: OVRV's parameters and search box (as the law's k_x, k_v, T*, l_0).
OVRV_BOUNDS: dict[str, tuple[float, float]] = {
    "k1": (1e-3, 3.0), "k2": (-0.5, 4.0), "tau_h": (0.0, 5.0), "eta": (0.0, 40.0)}


@dataclass
class Baseline:
    """One calibrated baseline model and the string verdict of its linearisation.

    Attributes
    ----------
    name : str
        ``"idm"`` or ``"ovrv"``.
    params : dict
        Its fitted parameters.
    rmse_speed, rmse_gap : float
        Simulation error from the measured initial states (m/s, m).
    k_x, k_v, headway : float
        The linearisation as the lag-free eq-4 law (module docstring).
    v_e : float
        Equilibrium speed of the linearisation, m/s.
    verdict : Verdict
        :func:`lag_free_certificate` of the linearisation.
    sup_gain, peak_omega : float
        sup|Γ(jω)| of the linearisation and where.
    notes : list of str
        E.g. no equilibrium at v_e, a parameter at its bound.
    """

    name: str
    params: dict[str, float]
    rmse_speed: float
    rmse_gap: float
    k_x: float
    k_v: float
    headway: float
    v_e: float
    verdict: Verdict
    sup_gain: float
    peak_omega: float
    notes: list[str] = field(default_factory=list)

    def fields(self) -> dict[str, Any]:
        """Row fields, prefixed with the model's name (``idm_rmse_speed``, ...).

        Returns
        -------
        dict
            Errors, verdict, sup|Γ|, the linearisation and the parameters.
        """
        n = self.name
        out: dict[str, Any] = {f"{n}_rmse_speed": self.rmse_speed, f"{n}_rmse_gap": self.rmse_gap,
                               f"{n}_verdict": self.verdict.value, f"{n}_sup_gain": self.sup_gain,
                               f"{n}_k_x": self.k_x, f"{n}_k_v": self.k_v, f"{n}_headway": self.headway}
        out.update({f"{n}_{k}": v for k, v in self.params.items()})
        return out


def lag_free_certificate(k_x: float, k_v: float, headway: float) -> tuple[Verdict, float, float]:
    """String stability of the lag-free loop Γ(s) = (k_v s + k_x)/(s² + (k_x T* + k_v)s + k_x), in closed form.

    Parameters
    ----------
    k_x, k_v, headway : float
        Gains (1/s², 1/s) and T* (s) of the linearisation.

    Returns
    -------
    verdict : Verdict
        ``CERTIFIED`` when internally stable (k_x > 0, k_x T* + k_v > 0) and
        k_x T*² + 2 k_v T* − 2 > 0; ``NOT_CERTIFIED`` when unstable or the criterion is < 0;
        ``INCONCLUSIVE`` within 1e-12 of 0 (module docstring).
    sup_gain : float
        sup over ω of |Γ(jω)| (inf when unstable).
    peak_omega : float
        Where it is reached, rad/s (0 when the sup is |Γ(0)| = 1).

    Examples
    --------
    >>> lag_free_certificate(0.2, 0.5, 2.0)[0].value  # 0.8 + 2 - 2 > 0
    'certified'
    >>> v, sup, w = lag_free_certificate(0.2, 0.1, 1.0)  # 0.2 + 0.2 - 2 < 0
    >>> v.value, round(sup, 4) > 1
    ('not_certified', True)
    """
    c = k_x * headway + k_v
    if not (k_x > 0 and c > 0):
        return Verdict.NOT_CERTIFIED, math.inf, math.nan
    g = k_x * headway ** 2 + 2 * k_v * headway - 2
    A, B, M = k_x ** 2, k_v ** 2, c * c - 2 * k_x  # |Γ|² = (A + B x)/(A + M x + x²), x = ω²
    if B - M <= 0:
        return (Verdict.CERTIFIED if g > 1e-12 else Verdict.INCONCLUSIVE), 1.0, 0.0
    # d/dx = 0  <=>  B x² + 2 A x − A (B − M) = 0
    x = (B - M) / 2 if B == 0 else (-A + math.sqrt(A * A + A * B * (B - M))) / B
    sup = math.sqrt((A + B * x) / (A + M * x + x * x))
    verdict = Verdict.NOT_CERTIFIED if g < -1e-12 else Verdict.INCONCLUSIVE
    return verdict, sup, math.sqrt(x)


def idm_linearisation(p: dict[str, float], v_e: float) -> tuple[float, float, float] | None:
    """The IDM about its equilibrium at speed v_e as (k_x, k_v, T*) of the lag-free law.

    Parameters
    ----------
    p : dict
        ``v0, T, s0, a, b`` (module docstring).
    v_e : float
        Equilibrium speed, m/s.

    Returns
    -------
    tuple of float or None
        (f_s, f_Δ, f_v⁻/f_s); None when there is no equilibrium (v_e ≥ v_0).

    Examples
    --------
    >>> k_x, k_v, T = idm_linearisation({"v0": 33.3, "T": 1.5, "s0": 2.0, "a": 1.0, "b": 1.5}, 15.0)
    >>> round(T, 3) > 1.5  # the linearised headway exceeds T (the (v/v0)^4 term)
    True
    """
    r = v_e / p["v0"]
    if not (0 <= r < 1):
        return None
    ss = p["s0"] + v_e * p["T"]
    se = ss / math.sqrt(1 - r ** 4)
    f_s = 2 * p["a"] * ss ** 2 / se ** 3
    f_v = p["a"] * (4 * v_e ** 3 / p["v0"] ** 4 + 2 * ss * p["T"] / se ** 2)
    f_d = p["a"] * ss * v_e / (se ** 2 * math.sqrt(p["a"] * p["b"]))
    return f_s, f_d, f_v / f_s


def simulate_idm(p: dict[str, float], v_pred: Array, dt: float, s0: float, v0: float) -> tuple[Array, Array]:
    """Gap and speed of an IDM follower behind a measured predecessor (ballistic update).

    Parameters
    ----------
    p : dict
        ``v0, T, s0, a, b`` (module docstring).
    v_pred : ndarray
        Predecessor's speed, m/s.
    dt : float
        Step, s.
    s0, v0 : float
        Initial gap (m) and speed (m/s).

    Returns
    -------
    gap, speed : ndarray
        At each sample.
    """
    vd, T, sj, a, b = p["v0"], p["T"], p["s0"], p["a"], p["b"]
    root = 2.0 * math.sqrt(a * b)
    n = v_pred.size
    gap = np.empty(n)
    speed = np.empty(n)
    vp = v_pred.tolist()
    s, v = float(s0), float(v0)
    for k in range(n):
        gap[k] = s
        speed[k] = v
        if k == n - 1:
            break
        star = sj + max(0.0, v * T + v * (v - vp[k]) / root)
        acc = a * (1.0 - (v / vd) ** 4 - (star / max(s, 0.1)) ** 2)
        vn = v + acc * dt
        if vn < 0.0:  # stops within the step (ballistic update, Treiber & Kanagaraj 2015)
            dx = -0.5 * v * v / acc if acc < 0 else 0.0
            vn = 0.0
        else:
            dx = 0.5 * (v + vn) * dt
        s += 0.5 * dt * (vp[k] + vp[k + 1]) - dx
        v = vn
    return gap, speed


def _residuals(sim: Any, data: FollowerData, init: Array, sv: float, sg: float) -> Array:
    parts = []
    for seg, (g0, v0, _) in zip(data.segments, init):
        g, v = sim(data.v_pred[seg.start:seg.stop], float(g0), float(v0))
        parts.append((v - data.v[seg.start:seg.stop]) / sv)
        parts.append((g - data.gap[seg.start:seg.stop]) / sg)
    r = np.nan_to_num(np.concatenate(parts), nan=1e6, posinf=1e6, neginf=-1e6)
    return np.clip(r, -1e6, 1e6)


def _errors(sim: Any, data: FollowerData, init: Array) -> tuple[float, float]:
    ev, eg = [], []
    for seg, (g0, v0, _) in zip(data.segments, init):
        g, v = sim(data.v_pred[seg.start:seg.stop], float(g0), float(v0))
        ev.append(v - data.v[seg.start:seg.stop])
        eg.append(g - data.gap[seg.start:seg.stop])
    return rms(np.concatenate(ev)), rms(np.concatenate(eg))


def _calibrate(bounds: dict[str, tuple[float, float]], starts: list[dict[str, float]], make: Any,
               data: FollowerData) -> tuple[dict[str, float], list[str]]:
    from scipy.optimize import least_squares

    names = tuple(bounds)
    lb = np.array([bounds[k][0] for k in names])
    ub = np.array([bounds[k][1] for k in names])
    init = measured_initial(data)
    sv, sg = data.scales()
    best: Any = None
    with single_threaded_blas():
        for st in starts:
            x0 = np.clip([st[k] for k in names], lb + 1e-6 * (ub - lb), ub - 1e-6 * (ub - lb))
            res = least_squares(lambda x: _residuals(make(dict(zip(names, x))), data, init, sv, sg), x0,
                                bounds=(lb, ub), x_scale="jac", max_nfev=200, xtol=1e-6, ftol=1e-6)
            if best is None or res.cost < best.cost:
                best = res
    p = dict(zip(names, (float(x) for x in best.x)))
    at = [k for k in names if min(p[k] - bounds[k][0], bounds[k][1] - p[k]) < 1e-3 * (bounds[k][1] - bounds[k][0])]
    return p, [f"{k} stopped at the bound of its search box {list(bounds[k])}" for k in at]


def fit_ovrv(data: FollowerData) -> Baseline:
    """Calibrate OVRV (the lag-free law) on the segments and judge its string stability.

    Parameters
    ----------
    data : FollowerData
        The record and its clean segments.

    Returns
    -------
    Baseline
        Its parameters, errors from the measured initial states and verdict.
    """
    def make(p: dict[str, float]) -> Any:
        m = FollowerModel(p["k1"], p["k2"], 0.0, 0.0, 0.0, p["tau_h"], p["eta"])
        return lambda vp, g0, v0: simulate_follower(m, vp, data.dt, s0=g0, v0=v0)

    vbar = float(np.mean([data.v[s.start:s.stop].mean() for s in data.segments]))
    gbar = float(np.mean([data.gap[s.start:s.stop].mean() for s in data.segments]))
    starts = [{"k1": k1, "k2": k2, "tau_h": th, "eta": max(gbar - th * vbar, 0.5)}
              for k1, k2, th in ((0.1, 0.4, 1.2), (0.05, 0.8, 0.6))]
    p, notes = _calibrate(OVRV_BOUNDS, starts, make, data)
    rv, rg = _errors(make(p), data, measured_initial(data))
    v_e = float(np.median(np.concatenate([data.v[s.start:s.stop] for s in data.segments])))
    verdict, sup, w = lag_free_certificate(p["k1"], p["k2"], p["tau_h"])
    return Baseline("ovrv", p, rv, rg, p["k1"], p["k2"], p["tau_h"], v_e, verdict, sup, w, notes)


def fit_idm(data: FollowerData) -> Baseline:
    """Calibrate the IDM on the segments and judge its linearisation at the median speed.

    Parameters
    ----------
    data : FollowerData
        The record and its clean segments.

    Returns
    -------
    Baseline
        Its parameters, errors from the measured initial states and verdict (inconclusive,
        with a note, when the median speed is not below the fitted v_0).
    """
    def make(p: dict[str, float]) -> Any:
        return lambda vp, g0, v0: simulate_idm(p, vp, data.dt, g0, v0)

    v = np.concatenate([data.v[s.start:s.stop] for s in data.segments])
    vmax = float(np.max(v))
    starts = [{"v0": max(1.3 * vmax, 5.0), "T": 1.2, "s0": 3.0, "a": 1.0, "b": 1.5},
              {"v0": max(2.0 * vmax, 8.0), "T": 0.8, "s0": 6.0, "a": 2.0, "b": 3.0}]
    p, notes = _calibrate(IDM_BOUNDS, starts, make, data)
    rv, rg = _errors(make(p), data, measured_initial(data))
    v_e = float(np.median(v))
    lin = idm_linearisation(p, v_e)
    if lin is None:
        notes.append(f"no equilibrium at the median speed {v_e:.3g} m/s (v_0 = {p['v0']:.3g} m/s)")
        return Baseline("idm", p, rv, rg, math.nan, math.nan, math.nan, v_e, Verdict.INCONCLUSIVE,
                        math.nan, math.nan, notes)
    k_x, k_v, T = lin
    verdict, sup, w = lag_free_certificate(k_x, k_v, T)
    return Baseline("idm", p, rv, rg, k_x, k_v, T, v_e, verdict, sup, w, notes)


def fit_baselines(data: FollowerData, *, seed: int = 0) -> list[Baseline]:
    """IDM and OVRV on the same record (module docstring).

    Parameters
    ----------
    data : FollowerData
        The record and its clean segments.
    seed : int
        Unused (the starts are fixed); kept for a uniform signature.

    Returns
    -------
    list of Baseline
        ``[idm, ovrv]``.
    """
    return [fit_idm(data), fit_ovrv(data)]
