"""One follower's (or one car's pooled) estimate: fit, certificate, bootstrap, profiles, data.

:func:`estimate` runs, on one :class:`~stringstab.identify.fit.FollowerData` (one follower of
one log, or every log of one car pooled: :mod:`stringstab.identify.cars`):

1. the **spacing policy** from the quasi-steady parts (:func:`~stringstab.identify.spacing.
   spacing_policy`).  Where it identifies T* (enough steady stretches over a wide enough speed
   range), it constrains the fit: T* is searched only within its 5-95 % interval widened by
   :data:`SPACING_MARGIN` on each side (the point fit and every bootstrap refit), so a log whose
   dynamics barely separate T* from l_0 takes T* from its steady parts; where the constraint
   binds, the unconstrained fit is reported beside it.  Otherwise T* is fitted with the rest
   and, where it is weakly determined, profiled;
2. the closed-loop simulation-error **fit** (:func:`~stringstab.identify.fit.fit_follower`,
   with θ_r when ``fit_delay``);
3. its **certificate** through the façade (``stringstab.certify``: continuous time or the
   sampled loop; θ_r as ``reaction_delay``);
4. a **moving-block bootstrap** over time within the segments (Künsch 1989; :func:`block_counts`)
   whose refits start from the point estimate *and* from a random draw (the better optimum
   kept, so a second optimum is seen), each certified;
5. the **box certificate** at the point gains over the bootstrap's 5-95 % intervals of τ, T*
   (and δ, and θ_r when fitted: the θ_r box certificate);
6. the **profiles** over T* (when weakly determined) and over θ_r (when fitted);
7. the data's own **empirical transfer** (:mod:`stringstab.identify.empirical`) and, on
   request, the **baselines** (:mod:`stringstab.identify.baselines`).

The verdict is the bootstrap-supported one (:func:`~stringstab.identify.wording.
supported_verdict`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify.verdicts import Verdict
from ..errors import StringStabError
from ..io.platoon_logs import Segment
from .empirical import Empirical, empirical_transfer
from .fit import (
    BOUNDS,
    PARAMETERS,
    FitResult,
    FollowerData,
    fit_follower,
    model_of,
    profile_headway,
    simulate_segments,
    start_points,
)
from .spacing import SpacingPolicy, spacing_policy
from .wording import model_only, profile_note, statement, supported_verdict

__all__ = ["DELAY_GRID", "PROFILE_GRID", "SPACING_MARGIN", "Estimate", "Settings", "block_counts", "certify_fit", "estimate",
           "simulated"]

Array = npt.NDArray[np.float64]

#: Time headways of the T* profile (those above what the data's gaps allow are dropped), s.
PROFILE_GRID = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5)
#: Reaction delays of the θ_r profile, s.
DELAY_GRID = (0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.5)
#: Widening (s) of the spacing policy's T* interval on each side when it constrains the fit: the
#: quasi-steady stretches still carry small transients, which bias the straight line by a few
#: thousandths of a second on noise-free simulated logs (tests/identify/test_identify_cars.py) — a bias
#: the bootstrap does not see, and which, forced on the fit, moves τ and θ_r along their ridge.
SPACING_MARGIN = 0.1
#: Parameters with bootstrap intervals.
BOOT_KEYS = (*PARAMETERS["cacc"], "reaction_delay")


@dataclass(frozen=True)
class Settings:
    """How :func:`estimate` runs (the command's options).

    Attributes
    ----------
    model : str
        ``"acc"`` (k_a = 0) or ``"cacc"``.
    sample_time : float or None
        H of the sampled certificate, None for continuous time.
    bootstrap : int
        Moving-block bootstrap refits.
    block : float
        Block length, s.
    n_starts : int
        Starting points of the point fit.
    seed : int
        Seed of the starts and the draws.
    min_duration : float
        Shortest clean segment, s.
    fit_delay : bool
        Fit θ_r too.
    baselines : bool
        Fit IDM and OVRV beside the law.
    screen : bool
        Exclude the stretches where the car does not follow its predecessor.
    """

    model: str = "acc"
    sample_time: float | None = None
    bootstrap: int = 50
    block: float = 20.0
    n_starts: int = 4
    seed: int = 0
    min_duration: float = 30.0
    fit_delay: bool = False
    baselines: bool = False
    screen: bool = True

    def document(self) -> dict[str, Any]:
        """The settings as written into the JSON files.

        Returns
        -------
        dict
            Bootstrap count, block, starts, seed, minimum segment, θ_r fitted, baselines,
            screening and the bootstrap's method.
        """
        return {"bootstrap": self.bootstrap, "block": self.block, "starts": self.n_starts, "seed": self.seed,
                "min_duration": self.min_duration, "fit_delay": self.fit_delay, "baselines": self.baselines,
                "not_following_screen": self.screen,
                "bootstrap_method": "moving-block over time within clean segments, refits from the "
                                    "point estimate and a random start"}


@dataclass
class Estimate:
    """Everything estimated on one record (see :func:`estimate`)."""

    fit: FitResult
    segments: list[Segment]
    certificate: Any
    boot_params: dict[str, Array]
    boot_verdicts: list[str]
    box: Any
    empirical: Empirical
    data: FollowerData
    notes: list[str] = field(default_factory=list)
    profile: list[dict[str, Any]] = field(default_factory=list)
    delay_profile: list[dict[str, Any]] = field(default_factory=list)
    policy: SpacingPolicy | None = None
    free_fit: FitResult | None = None
    second_optimum: int = 0
    baselines: list[Any] = field(default_factory=list)

    @property
    def certified_share(self) -> float:
        """Share of bootstrap fits certified (NaN without bootstrap)."""
        n = len(self.boot_verdicts)
        return sum(v == Verdict.CERTIFIED for v in self.boot_verdicts) / n if n else math.nan

    @property
    def verdict(self) -> Verdict:
        """The verdict the bootstrap supports (:func:`~stringstab.identify.wording.supported_verdict`)."""
        return supported_verdict(self.certificate.verdict, self.boot_verdicts)

    @property
    def lowest_resolved_omega(self) -> float:
        """The data's lowest resolved frequency (first Welch bin above 0), rad/s."""
        w = self.empirical.omega
        return float(w[1]) if w.size > 1 else math.nan

    def model_only(self) -> str:
        """Words when the point fit's instability peak is below the resolved band, else ""."""
        c = self.certificate
        return model_only(c.verdict, float(c.peak_omega), self.lowest_resolved_omega)

    def interval(self, name: str) -> tuple[float, float]:
        """5-95 % bootstrap interval of a parameter (NaN, NaN without bootstrap)."""
        x = self.boot_params.get(name)
        if x is None or x.size == 0:
            return math.nan, math.nan
        lo, hi = np.percentile(x, [5, 95])
        return float(lo), float(hi)

    def headway_interval(self) -> tuple[float, float]:
        """T*'s 5-95 % bootstrap interval (the refits within the spacing policy's constraint, if any)."""
        return self.interval("headway")

    def statement(self) -> str:
        """The verdict in words (:func:`~stringstab.identify.wording.statement`)."""
        return statement(self.certificate.verdict, self.boot_verdicts, self.fit.at_bound, self.model_only())

    def fields(self) -> dict[str, Any]:
        """The estimate's row fields (parameters, errors, verdicts, data, intervals)."""
        p = self.fit.params
        c = self.certificate
        e = self.empirical
        n = len(self.boot_verdicts)
        pol = self.policy
        out: dict[str, Any] = {
            **{k: p[k] for k in ("k_x", "k_v", "k_a", "tau", "delta", "headway", "standstill")},
            "rmse_speed": self.fit.rmse_speed, "rmse_gap": self.fit.rmse_gap,
            "sup_gain": float(c.sup_gain), "peak_omega": float(c.peak_omega),
            "verdict": c.verdict, "statement": self.statement(),
            "certified_share": self.certified_share, "n_bootstrap": n,
            "not_certified_share": (sum(v == Verdict.NOT_CERTIFIED for v in self.boot_verdicts) / n) if n else math.nan,
            "box_verdict": None if self.box is None else self.box.verdict,
            "empirical_gain": e.gain, "empirical_omega": e.gain_omega,
            "empirical_gain_error": 2 * e.gain_error * e.gain, "data_amplifies": e.amplifies,
            "peak_to_peak": e.peak_to_peak, "energy_gain": e.energy,
            "at_bound": ",".join(self.fit.at_bound),
            "samples": self.data.n_samples,
            "reaction_delay": p.get("reaction_delay", 0.0),
            "supported_verdict": self.verdict.value,
            "model_only": bool(self.model_only()),
            "lowest_resolved_omega": self.lowest_resolved_omega,
            "rmse_speed_measured_start": self.fit.rmse_speed_measured_start,
            "rmse_gap_measured_start": self.fit.rmse_gap_measured_start,
            "headway_source": ("dynamic fit within the spacing policy's interval"
                               if pol is not None and pol.identified else "dynamic fit"),
            "spacing_headway": math.nan if pol is None else pol.headway,
            "spacing_headway_lo": math.nan if pol is None else pol.headway_interval[0],
            "spacing_headway_hi": math.nan if pol is None else pol.headway_interval[1],
            "spacing_standstill": math.nan if pol is None else pol.standstill,
            "median_time_gap": math.nan if pol is None else pol.median_time_gap,
            "second_optimum": self.second_optimum,
        }
        for k in BOOT_KEYS:
            lo, hi = self.interval(k)
            out[f"{k}_lo"], out[f"{k}_hi"] = lo, hi
        lo, hi = self.interval("sup_gain")
        out["sup_gain_lo"], out["sup_gain_hi"] = lo, hi
        for b in self.baselines:
            out.update(b.fields())
        return out


def certify_fit(p: dict[str, float], H: float | None) -> Any:
    """The certificate of fitted parameters through the façade's way in.

    Parameters
    ----------
    p : dict
        ``k_x, k_v, k_a, tau, delta, headway`` (and ``reaction_delay``, passed when > 0).
    H : float or None
        Sample time of the sampled certificate; None for continuous time.

    Returns
    -------
    Certificate
        From :func:`stringstab.certify` (imported from :mod:`stringstab.certify.api`: a
        sub-package does not import the root package).
    """
    from ..certify import api as ss

    extra: dict[str, Any] = {}
    if p.get("reaction_delay", 0.0) > 0:
        extra["reaction_delay"] = p["reaction_delay"]
    return ss.certify(p["k_x"], p["k_v"], p["k_a"], tau=p["tau"], delta=p["delta"],
                      headway=p["headway"], sample_time=H, **extra)


def block_counts(segments: Sequence[Segment], T: int, L: int, rng: np.random.Generator) -> Array:
    """Per-sample multiplicities of one moving-block bootstrap draw (module docstring).

    Blocks never straddle two segments: a segment is drawn with probability proportional to
    its number of block starts, then a start uniformly within it; blocks are drawn until as
    many samples as the segments hold are covered (so the total may exceed it by < one block).

    Parameters
    ----------
    segments : sequence of Segment
        The contiguous segments of the data (sample index ranges).
    T : int
        Number of samples of the whole record (length of the result).
    L : int
        Block length (samples); a segment shorter than ``L`` is drawn as one whole block.
    rng : numpy.random.Generator
        Source of the draw.

    Returns
    -------
    ndarray
        Length-``T`` float array: how many times each sample was drawn (0 outside segments).
    """
    starts: list[tuple[int, int]] = []  # (first valid start, number of starts) per segment
    for s in segments:
        Ls = min(L, len(s))
        starts.append((s.start, len(s) - Ls + 1))
    sizes = np.array([n for _, n in starts], dtype=float)
    lens = [min(L, len(s)) for s in segments]
    total = sum(len(s) for s in segments)
    counts = np.zeros(T)
    covered = 0
    while covered < total:
        j = int(rng.choice(len(starts), p=sizes / sizes.sum()))
        a = starts[j][0] + int(rng.integers(starts[j][1]))
        counts[a:a + lens[j]] += 1.0
        covered += lens[j]
    return counts


def _clip(name: str, x: float) -> float:
    lo, hi = BOUNDS[name]
    return min(max(float(x), lo), hi)


def estimate(data: FollowerData, s: Settings, rng: np.random.Generator,
             step: Callable[[str], None] = lambda what: None) -> Estimate:
    """Fit, certify, bootstrap and profile one record (module docstring).

    Parameters
    ----------
    data : FollowerData
        The record (one follower, or a car's logs pooled) with its clean segments.
    s : Settings
        The options.
    rng : numpy.random.Generator
        Source of the bootstrap's draws and random starts.
    step : callable, optional
        Called with a word after the point fit and after each refit (progress).

    Returns
    -------
    Estimate
        Everything estimated.
    """
    policy = spacing_policy(data, seed=s.seed)
    box = None
    if policy.identified:
        lo, hi = policy.headway_interval
        box = {"headway": (max(lo - SPACING_MARGIN, BOUNDS["headway"][0]),
                           min(hi + SPACING_MARGIN, BOUNDS["headway"][1]))}
    fit = fit_follower(data, s.model, n_starts=s.n_starts, seed=s.seed, fit_delay=s.fit_delay, bounds=box)
    pre: list[str] = [policy.describe()]
    prof: list[dict[str, Any]] = []
    free = None
    if box is not None:
        lo, hi = box["headway"]
        text = (f"T* constrained to the spacing policy's interval widened by {SPACING_MARGIN:g} s, "
                f"[{lo:.3g}, {hi:.3g}] s (also in every bootstrap refit): the dynamic fit puts it at "
                f"{fit.params['headway']:.3g} s")
        if "headway" in fit.at_bound:
            free = fit_follower(data, s.model, n_starts=s.n_starts, seed=s.seed, fit_delay=s.fit_delay,
                                identifiability=False)
            text += (f", at the constraint's bound; unconstrained it goes to {free.params['headway']:.3g} s "
                     f"(l_0 {free.params['standstill']:.3g} m) at a cost {100 * (free.cost / fit.cost - 1):+.1f} % "
                     "of the constrained fit's")
        pre.append(text)
    elif _weak_headway(fit, np.empty(0)):  # T* profiled before the bootstrap: a better optimum restarts the fit
        prof, pfits = _profile(data, s, fit, policy)
        alt = min(pfits, key=lambda f: f.cost)
        if alt.cost < fit.cost * (1 - 1e-6):  # the starts missed a better optimum
            refit = fit_follower(data, s.model, x0=alt.theta, seed=s.seed, fit_delay=s.fit_delay)
            if refit.cost < fit.cost:
                pre.append(f"the profile over T* found a better optimum than the {fit.starts} starts "
                           f"(cost {100 * (refit.cost / fit.cost - 1):+.1f} %); the point fit was restarted "
                           "from it")
                fit = refit
    dfits: list[FitResult] = []
    if s.fit_delay:  # the θ_r profile, also before the bootstrap, for the same reason
        dfits = _delay_fits(data, s, fit, box)
        alt = min(dfits, key=lambda f: f.cost)
        if alt.cost < fit.cost * (1 - 1e-6):
            refit = fit_follower(data, s.model, x0=alt.theta, seed=s.seed, fit_delay=True, bounds=box)
            if refit.cost < fit.cost:
                pre.append(f"the profile over θ_r found a better optimum than the {fit.starts} starts "
                           f"(cost {100 * (refit.cost / fit.cost - 1):+.1f} %); the point fit was restarted "
                           "from it")
                fit = refit
    step("fitted")
    cert = certify_fit(fit.params, s.sample_time)
    boot, verdicts, second = _bootstrap(data, s, fit, box, rng, step)
    box_cert = _box(fit.params, boot, s) if s.bootstrap >= 2 else None
    emp = empirical_transfer(data.v_pred, data.v, data.segments, data.dt)
    est = Estimate(fit, list(data.segments), cert, boot, verdicts, box_cert, emp, data, policy=policy,
                   free_fit=free, second_optimum=second)
    est.notes += pre
    if s.bootstrap and second:
        est.notes.append(f"in {second} of {s.bootstrap} bootstrap refits the random start reached an "
                         "optimum lower by more than 0.1 % than the start at the point estimate: the "
                         "cost has more than one valley (each refit keeps the lower)")
    if not prof and not policy.identified and _weak_headway(fit, boot["headway"]):
        prof, _ = _profile(data, s, fit, policy)
    if prof:
        est.profile = prof
        est.notes.append(profile_note(prof, fit.rmse_speed, str(cert.verdict)))
    if dfits:
        est.delay_profile = _profile_rows(data, s, np.asarray(DELAY_GRID), "reaction_delay", dfits)
        est.notes.append(profile_note(est.delay_profile, fit.rmse_speed, str(cert.verdict),
                                      name="reaction_delay", symbol="θ_r"))
        sep = _separation_note(est.delay_profile, min(fit.rmse_speed, *(f.rmse_speed for f in dfits)))
        if sep:
            est.notes.append(sep)
    est.notes.append(f"RMSE from the measured initial state of each segment: speed "
                     f"{fit.rmse_speed_measured_start:.3g} m/s, gap {fit.rmse_gap_measured_start:.3g} m "
                     f"(with the fitted restarts: {fit.rmse_speed:.3g} m/s, {fit.rmse_gap:.3g} m)")
    mo = est.model_only()
    if mo:
        est.notes.append(mo + "; the verdict rests on the model's extrapolation there")
    est.notes += _disagreement(est) + _quality(est)
    if s.baselines:
        from .baselines import fit_baselines

        est.baselines = fit_baselines(data, seed=s.seed)
    return est


def _bootstrap(data: FollowerData, s: Settings, fit: FitResult, box: dict[str, tuple[float, float]] | None,
               rng: np.random.Generator, step: Callable[[str], None]
               ) -> tuple[dict[str, Array], list[str], int]:
    """Multi-start moving-block refits, each certified (module docstring)."""
    L = max(round(s.block / data.dt), 2)
    keys = (*BOOT_KEYS, "sup_gain")
    boot: dict[str, list[float]] = {k: [] for k in keys}
    verdicts: list[str] = []
    second = 0
    assert fit.theta is not None
    for _ in range(s.bootstrap):
        counts = block_counts(data.segments, data.v.size, L, rng)
        x_rand = start_points(data, s.model, 2, seed=int(rng.integers(2**31)), fit_delay=s.fit_delay)[1]
        bf = fit_follower(data, s.model, x0=[fit.theta, x_rand], counts=counts, identifiability=False,
                          fit_delay=s.fit_delay, bounds=box)
        # a second valley: the random start's optimum is lower by more than 0.1 % of the cost
        second += bf.start_costs[1] < bf.start_costs[0] * (1 - 1e-3)
        q = bf.params
        bc = certify_fit(q, s.sample_time)  # the same certificate as the point's
        verdicts.append(str(bc.verdict))
        for k in BOOT_KEYS:
            boot[k].append(q.get(k, 0.0))
        boot["sup_gain"].append(float(bc.sup_gain))
        step("bootstrap")
    return {k: np.asarray(v) for k, v in boot.items()}, verdicts, second


def _weak_headway(fit: FitResult, boot_headway: Array) -> bool:
    """T* is at a bound, the speed barely varies, or the bootstrap moves T* by over 0.5 s."""
    spread = (boot_headway.size >= 2
              and float(np.subtract(*np.percentile(boot_headway, [95, 5]))) > 0.5)
    return "headway" in fit.at_bound or any("T* and the standstill" in n for n in fit.notes) or spread


def _profile_rows(data: FollowerData, s: Settings, grid: Array, name: str,
                  fits: list[FitResult]) -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = []
    for T, pf in zip(grid, fits):
        q = pf.params
        c = certify_fit(q, s.sample_time)
        row = {"k_x": q["k_x"], "k_v": q["k_v"], "tau": q["tau"], "headway": q["headway"],
               "standstill": q["standstill"], "reaction_delay": q.get("reaction_delay", 0.0),
               "rmse_speed": pf.rmse_speed, "rmse_gap": pf.rmse_gap, "verdict": c.verdict,
               "sup_gain": float(c.sup_gain), "at_bound": pf.at_bound}
        row[name] = float(T)  # the held value exactly (the fit holds it within 1e-9)
        rows.append(row)
    return rows


def _profile(data: FollowerData, s: Settings, fit: FitResult,
             policy: SpacingPolicy) -> tuple[list[dict[str, Any]], list[FitResult]]:
    """Refit with T* held on :data:`PROFILE_GRID` (up to what the gaps allow) and certify each.

    The grid stops at the 5th percentile of gap/speed (l_0 ≥ 0 stays feasible there) but
    reaches at least the median time gap's lower grid value, so a setting the data suggest is
    always shown.
    """
    v = np.concatenate([data.v[g.start:g.stop] for g in data.segments])
    g = np.concatenate([data.gap[x.start:x.stop] for x in data.segments])
    moving = v > 1.0
    t_max = float(np.percentile(g[moving] / v[moving], 5)) if moving.sum() > 10 else 0.0
    grid = np.array([T for T in PROFILE_GRID if T <= t_max] or [0.0])
    fits = profile_headway(data, s.model, grid, n_starts=max(1, min(s.n_starts, 2)), seed=s.seed,
                           fit_delay=s.fit_delay)
    return _profile_rows(data, s, grid, "headway", fits), fits


def _delay_fits(data: FollowerData, s: Settings, fit: FitResult,
                box: dict[str, tuple[float, float]] | None) -> list[FitResult]:
    """Refit with θ_r held on :data:`DELAY_GRID`, each from the point estimate.

    A refit whose loop diverges from there (gains that are stable without the delay may not be
    with it) is restarted from a typical ACC as well, the lower optimum kept.
    """
    assert fit.theta is not None
    i = fit.names.index("reaction_delay")
    fits = []
    for th in DELAY_GRID:
        x = fit.theta.copy()
        x[i] = th
        fixed = {"reaction_delay": th}
        f = fit_follower(data, s.model, x0=x, identifiability=False, fit_delay=True, fixed=fixed, bounds=box)
        if not f.rmse_speed <= 10 * fit.rmse_speed:
            typical = start_points(data, s.model, 1, fit_delay=True, fixed=fixed)
            f = fit_follower(data, s.model, x0=[x, *typical], identifiability=False, fit_delay=True,
                             fixed=fixed, bounds=box)
        fits.append(f)
    return fits


def _separation_note(rows: list[dict[str, Any]], best_rmse: float) -> str:
    """Which θ_r the data tell apart: the held values within 1 % of the best speed RMSE."""
    near = [r["reaction_delay"] for r in rows if r["rmse_speed"] <= 1.01 * best_rmse]
    if len(near) <= 1:
        return ""
    return (f"θ_r held at {', '.join(f'{x:g}' for x in near)} s fits within 1 % of the best speed RMSE "
            "(τ and the others refitted): the data separate the delay θ_r from the lag τ only weakly; "
            "read θ_r's bootstrap interval and the profile above, not the point value")


def _box(p: dict[str, float], bp: dict[str, Array], s: Settings) -> Any:
    """The robust certificate at the point gains over the 5-95 % bootstrap box of τ, T* (δ, θ_r).

    θ_r's interval when it is fitted (``fit_delay``); a sampled loop with θ_r is refused by the
    way in, and then there is no box certificate (None), as for any refused box.
    """
    from ..certify import api as ss

    def iv(k: str) -> Any:
        lo, hi = (float(x) for x in np.percentile(bp[k], [5, 95]))
        lo, hi = min(lo, p[k]), max(hi, p[k])
        return (lo, hi) if hi > lo else p[k]

    delta = iv("delta") if s.model == "cacc" else p["delta"]
    # θ_r fitted: its bootstrap interval too (the θ_r box certificate, issue 25 item 4)
    theta = iv("reaction_delay") if s.fit_delay else p.get("reaction_delay", 0.0)
    try:
        return ss.certify(p["k_x"], p["k_v"], p["k_a"], tau=iv("tau"), delta=delta,
                          headway=iv("headway"), sample_time=s.sample_time, reaction_delay=theta)
    except StringStabError:
        return None


def _disagreement(v: Estimate) -> list[str]:
    """Where the model's verdict and the data's own amplification part ways.

    The data's amplification is |Ĝ| ± 2ε (:mod:`stringstab.identify.empirical`).
    """
    e = v.empirical
    sup = float(v.certificate.sup_gain)
    model_amplifies = v.certificate.verdict == Verdict.NOT_CERTIFIED
    shown = f"max |Ĝ| = {e.gain:.3g} ± {2 * e.gain_error * e.gain:.2g} at {e.gain_omega:.3g} rad/s"
    if not math.isfinite(e.gain):
        return ["the measured transfer has no frequency with coherence >= 0.5 below 1 rad/s: the "
                "data give no verdict of their own"]
    if e.amplifies == "undecided":
        return [f"the data alone do not decide ({shown}, coherence >= 0.5): within their error of 1"]
    if model_amplifies and e.amplifies == "no":
        return [f"model and data disagree: the fitted model amplifies (sup|Γ| = {sup:.4g} at "
                f"{float(v.certificate.peak_omega):.3g} rad/s) but the measured transfer stays below 1 "
                f"where coherent ({shown})"]
    if not model_amplifies and e.amplifies == "yes":
        return [f"model and data disagree: the fitted model is certified (sup|Γ| = {sup:.4g}) but the "
                f"measured transfer exceeds 1 ({shown}, coherence >= 0.5)"]
    return [f"model and data agree: the measured transfer {'exceeds 1' if e.amplifies == 'yes' else 'stays below 1'} "
            f"({shown})"]


def _quality(v: Estimate) -> list[str]:
    """Notes on the fit's quality and on the record itself."""
    notes = []
    d = v.data
    g = np.concatenate([d.gap[s.start:s.stop] for s in v.segments])
    if g.min() <= 0:
        notes.append(f"the recorded gap drops to {g.min():.3g} m (GPS error or a collision): the "
                     "record is used as it is")
    gaps, speeds = simulated(v)
    smin = min(float(x.min()) for x in gaps)
    if smin <= 0 < g.min():
        notes.append(f"the fitted model's simulated gap reaches {smin:.3g} m where the measured one "
                     f"stays above {g.min():.3g} m: the linear law misses part of this car's response "
                     "(large, asymmetric manoeuvres)")
    vmin = min(float(x.min()) for x in speeds)
    vmeas = float(np.concatenate([d.v[s.start:s.stop] for s in v.segments]).min())
    if vmin < -0.1 and vmeas >= -0.1:
        notes.append(f"the fitted model's simulated speed goes negative ({vmin:.3g} m/s) where the "
                     f"measured one stays at {vmeas:.3g} m/s or more: the linear law has no v >= 0")
    rel = v.fit.rmse_gap / max(float(g.mean()), 1.0)
    if rel > 0.15:
        notes.append(f"poor fit: the gap RMSE is {100 * rel:.0f} % of the mean gap; the verdict "
                     "describes the best linear law, not necessarily this car")
    return notes


def simulated(v: Estimate) -> tuple[list[Array], list[Array]]:
    """Simulated gap and speed of the point fit on each segment (for figures).

    Parameters
    ----------
    v : Estimate
        An estimate (its point fit must exist).

    Returns
    -------
    gaps, speeds : list of ndarray
        Per segment, the simulated gap (m) and speed (m/s) from the fitted initial states.
    """
    f = v.fit
    assert f.theta is not None
    return simulate_segments(model_of(f.theta[:len(f.names)], f.names), v.data, f.initial)
