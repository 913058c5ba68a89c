"""``identify(log)``: fit, certify and bootstrap each follower of a recorded platoon.

Each is also set beside the data's own amplification.

Per follower (a vehicle whose predecessor and gap are in the log):

1. the closed-loop simulation-error fit of the eq-4 law and the lag
   (:func:`stringstab.identify.fit.fit_follower`) on the clean segments;
2. the certificate of the point estimate through the façade (:func:`stringstab.certify`:
   continuous time, or the sampled loop with ``sample_time``), sup|Γ| and its frequency;
3. a **moving-block bootstrap** over time within the clean segments (Künsch 1989): blocks of
   ``block`` seconds are drawn at uniformly random starts inside the segments until they cover
   as many samples as the record, and each sample's residuals are weighted by how many drawn
   blocks cover it; the law is refitted (from the point estimate) to each such weighting.
   Blocks, not single samples, because simulation errors are strongly correlated over seconds
   (an i.i.d. bootstrap would treat a 10-s excursion as a hundred independent errors and
   understate the spread); within segments, because a block that bridged a data gap would join
   two unrelated stretches.  Each refit is certified (:func:`stringstab.certify`, the point's
   loop: continuous or sampled), which gives its verdict and sup|Γ|; the shares
   certified / not certified are the uncertainty of the verdict;
4. the robust certificate (:func:`stringstab.certify` with intervals) at the point gains over the
   5-95 % bootstrap intervals of τ, T* (and δ for ``cacc``): the box certificate covers those
   vehicle parameters, not the gains' own uncertainty;
5. the empirical transfer and amplifications (:mod:`stringstab.identify.empirical`) beside
   the model's |Γ(jω)|, with a note where they disagree.

The verdict is worded no more confidently than the bootstrap allows (:func:`statement`).
The certificates are the façade's functions (``stringstab.certify``, ``stringstab.check``),
imported from :mod:`stringstab.certify.api` because a sub-package does not import the root
package (``tests/test_house.py``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show
from ..io.platoon_logs import PlatoonLog, Segment, clean_segments
from ..progress import Progress
from .empirical import Empirical, empirical_transfer
from .fit import (
    PARAMETERS,
    FitResult,
    FollowerData,
    fit_follower,
    model_of,
    profile_headway,
    simulate_segments,
)

__all__ = ["IdentifyResult", "VehicleResult", "identify", "statement"]

Array = npt.NDArray[np.float64]

#: Default number of bootstrap refits per follower.
DEFAULT_BOOTSTRAP = 50
#: Default block length of the moving-block bootstrap, s.
DEFAULT_BLOCK = 20.0


@dataclass
class VehicleResult:
    """Everything identified about one follower (see :func:`identify`)."""

    platoon: int
    position: int
    name: str
    predecessor: str
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

    @property
    def certified_share(self) -> float:
        """Share of bootstrap fits certified (NaN without bootstrap)."""
        n = len(self.boot_verdicts)
        return sum(v == "certified" for v in self.boot_verdicts) / n if n else math.nan

    def interval(self, name: str) -> tuple[float, float]:
        """5-95 % bootstrap interval of a parameter (NaN, NaN without bootstrap)."""
        x = self.boot_params.get(name)
        if x is None or x.size == 0:
            return math.nan, math.nan
        lo, hi = np.percentile(x, [5, 95])
        return float(lo), float(hi)

    def statement(self) -> str:
        """The verdict in words (:func:`statement`)."""
        return statement(self.certificate.verdict, self.boot_verdicts, self.fit.at_bound)

    def row(self) -> dict[str, Any]:
        """The JSON/CSV row (field names of issue 16)."""
        p = self.fit.params
        c = self.certificate
        e = self.empirical
        out: dict[str, Any] = {
            "platoon": self.platoon, "position": self.position, "name": self.name,
            "predecessor": self.predecessor,
            **{k: p[k] for k in ("k_x", "k_v", "k_a", "tau", "delta", "headway", "standstill")},
            "rmse_speed": self.fit.rmse_speed, "rmse_gap": self.fit.rmse_gap,
            "sup_gain": float(c.sup_gain), "peak_omega": float(c.peak_omega),
            "verdict": c.verdict, "statement": self.statement(),
            "certified_share": self.certified_share, "n_bootstrap": len(self.boot_verdicts),
            "not_certified_share": (sum(v == "not_certified" for v in self.boot_verdicts)
                                    / len(self.boot_verdicts)) if self.boot_verdicts else math.nan,
            "box_verdict": None if self.box is None else self.box.verdict,
            "empirical_gain": e.gain, "empirical_omega": e.gain_omega,
            "empirical_gain_error": 2 * e.gain_error * e.gain, "data_amplifies": e.amplifies,
            "peak_to_peak": e.peak_to_peak, "energy_gain": e.energy,
            "at_bound": ",".join(self.fit.at_bound),
            "samples": self.data.n_samples,
        }
        for k in PARAMETERS["cacc"]:
            lo, hi = self.interval(k)
            out[f"{k}_lo"], out[f"{k}_hi"] = lo, hi
        lo, hi = self.interval("sup_gain")
        out["sup_gain_lo"], out["sup_gain_hi"] = lo, hi
        return out


@dataclass
class IdentifyResult:
    """The identification of every follower of one or more logs.

    Attributes
    ----------
    vehicles : list of VehicleResult
        In (log, position) order.
    model : str
        ``"acc"`` or ``"cacc"``.
    sample_time : float or None
        H of the sampled certificate, or None (continuous time).
    settings : dict
        Bootstrap count, block length, starts, seed, minimum segment length.
    sources : list of str
        The files read.
    skipped : list of str
        Followers not identified, with the reason.
    """

    vehicles: list[VehicleResult]
    model: str
    sample_time: float | None
    settings: dict[str, Any]
    sources: list[str]
    skipped: list[str] = field(default_factory=list)

    def rows(self) -> list[dict[str, Any]]:
        """One row per follower (:meth:`VehicleResult.row`)."""
        return [v.row() for v in self.vehicles]

    def document(self) -> dict[str, Any]:
        """The ``identify.json`` document: settings, ``vehicles`` (with ``segments`` and notes)."""
        vehicles = []
        for v in self.vehicles:
            r = v.row()
            r["segments"] = [{"start": s.start, "stop": s.stop, "t_start": float(s.start * v.data.dt),
                              "samples": len(s)} for s in v.segments]
            r["notes"] = v.fit.notes + v.notes
            r["correlation"] = v.fit.correlation
            r["headway_profile"] = v.profile
            vehicles.append(r)
        return {"command": "identify", "model": self.model, "sample_time": self.sample_time,
                "sources": self.sources, "settings": self.settings, "skipped": self.skipped,
                "vehicles": vehicles}


def statement(point_verdict: str, boot: Sequence[str], at_bound: Sequence[str] = ()) -> str:
    """The verdict worded no more confidently than the bootstrap allows.

    Parameters
    ----------
    point_verdict : str
        Verdict of the point fit: ``"certified"``, ``"not_certified"`` or ``"inconclusive"``
        (only worded when there is no bootstrap).
    boot : sequence of str
        Verdicts of the bootstrap refits; empty when no bootstrap was run.
    at_bound : sequence of str, optional
        Names of the parameters whose fit stopped at the bound of its search box; appended
        as a caveat.

    Returns
    -------
    str
        "string stable in n of n bootstrap fits" / "not string stable in n of n ..." when all
        refits agree, otherwise "inconclusive: p % of fits certified"; without a bootstrap, the
        point verdict qualified as unmeasured.

    Examples
    --------
    >>> statement("not_certified", ["not_certified"] * 50)
    'not string stable in 50 of 50 bootstrap fits'
    >>> statement("certified", ["certified"] * 61 + ["not_certified"] * 39)
    'inconclusive: 61 % of fits certified'
    >>> statement("certified", [])
    'certified at the point estimate (no bootstrap: no uncertainty measured)'
    """
    n = len(boot)
    if n == 0:
        words = {"certified": "certified", "not_certified": "not certified",
                 "inconclusive": "inconclusive"}[point_verdict]
        text = f"{words} at the point estimate (no bootstrap: no uncertainty measured)"
    else:
        c = sum(v == "certified" for v in boot)
        nc = sum(v == "not_certified" for v in boot)
        if c == n:
            text = f"string stable in {n} of {n} bootstrap fits"
        elif nc == n:
            text = f"not string stable in {n} of {n} bootstrap fits"
        else:
            text = f"inconclusive: {round(100 * c / n)} % of fits certified"
    if at_bound:
        text += f" (fit at the bound of {', '.join(at_bound)})"
    return text


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


class _Progress:
    """Count the fits through :class:`stringstab.progress.Progress`, naming the last one on the bar."""

    def __init__(self, total: int, show_it: bool | None) -> None:
        self.p = Progress(total, "identify", unit="fit",
                          enabled=total > 0 and (show_it if show_it is not None else True))

    def step(self, what: str) -> None:
        self.p.update(1)
        if self.p.bar is not None:
            self.p.bar.set_postfix_str(what, refresh=False)

    def close(self) -> None:
        self.p.close()


def _certify(p: dict[str, float], H: float | None) -> Any:
    from ..certify import api as ss

    return ss.certify(p["k_x"], p["k_v"], p["k_a"], tau=p["tau"], delta=p["delta"],
                      headway=p["headway"], sample_time=H)


def identify(log: PlatoonLog | Sequence[PlatoonLog], model: str = "acc", *,
             sample_time: float | None = None, bootstrap: int = DEFAULT_BOOTSTRAP,
             block: float = DEFAULT_BLOCK, n_starts: int = 4, seed: int = 0,
             min_duration: float = 30.0, progress: bool | None = None) -> IdentifyResult:
    """Identify, certify and bootstrap every follower of a recorded platoon.

    Parameters
    ----------
    log : PlatoonLog or sequence of PlatoonLog
        From :func:`stringstab.io.platoon_logs.read_platoon_logs`.
    model : {"acc", "cacc"}
        ``acc``: u = k_x Δp + k_v Δv (k_a = 0); ``cacc``: also k_a a_{i−1}(t − δ) (needs the
        predecessor's acceleration in the log).
    sample_time : float, optional
        Certify the sampled-data loop with this period H (s); default continuous time.
    bootstrap : int
        Moving-block bootstrap refits per follower (0: none).
    block : float
        Block length, s.
    n_starts : int
        Starting points of the point fit.
    seed : int
        Seed of the starting points and the bootstrap draws.
    min_duration : float
        Shortest clean segment used, s.
    progress : bool, optional
        Show progress on stderr (default: yes).

    Returns
    -------
    IdentifyResult

    Raises
    ------
    StringStabError
        If no follower has a usable segment, or an option is out of range.
    """
    logs = [log] if isinstance(log, PlatoonLog) else list(log)
    if model not in PARAMETERS:
        raise StringStabError(f"model must be 'acc' or 'cacc'; got {show(model)}")
    if int(bootstrap) < 0:
        raise StringStabError(f"bootstrap must be an integer >= 0; got {show(bootstrap)}")
    if not (math.isfinite(block) and block > 0):
        raise StringStabError(f"block must be a number of seconds > 0; got {show(block)}")
    jobs = []
    skipped = []
    for li, lg in enumerate(logs):
        for p in lg.followers():
            segs = clean_segments(lg, p, min_duration=min_duration)
            if not segs:
                skipped.append(f"{lg.name(p)} (position {p}): no clean segment of at least {min_duration:g} s")
                continue
            vp, v, g, ap = lg.pair(p)
            if model == "cacc":
                if ap is None or not all(np.isfinite(ap[s.start:s.stop]).all() for s in segs):
                    raise StringStabError(
                        f"--model cacc needs the predecessor's acceleration (an a column); "
                        f"{show(lg.source)} has none for {lg.name(p - 1)}")
            jobs.append((li, lg, p, tuple(segs), FollowerData(vp, v, g, ap, tuple(segs), lg.dt)))
    if not jobs:
        raise StringStabError(
            "no follower has a usable segment (predecessor speed, own speed and gap all measured "
            f"for at least {min_duration:g} s); " + ("; ".join(skipped) or "found none"))
    B = int(bootstrap)
    bar = _Progress(len(jobs) * (1 + B), progress)
    rng = np.random.default_rng(seed)
    out = []
    try:
        for li, lg, p, segs_t, data in jobs:
            segs = list(segs_t)
            fit = fit_follower(data, model, n_starts=n_starts, seed=seed)
            pre: list[str] = []
            prof: list[dict[str, Any]] = []
            if _weak_headway(fit, np.empty(0)):
                prof, pfits = _profile(data, model, sample_time, n_starts, seed)
                alt = min(pfits, key=lambda f: f.cost)
                if alt.cost < fit.cost * (1 - 1e-6):  # the starts missed a better optimum
                    refit = fit_follower(data, model, x0=alt.theta, seed=seed)
                    if refit.cost < fit.cost:
                        pre.append(f"the profile over T* found a better optimum than the {fit.starts} "
                                   f"starts (cost {100 * (refit.cost / fit.cost - 1):+.1f} %); the point "
                                   "fit was restarted from it")
                        fit = refit
            bar.step(f"{lg.name(p)} fitted")
            cert = _certify(fit.params, sample_time)
            L = max(round(block / lg.dt), 2)
            boot: dict[str, list[float]] = {k: [] for k in (*PARAMETERS["cacc"], "sup_gain")}
            verdicts: list[str] = []
            for _ in range(B):
                counts = block_counts(segs, data.v.size, L, rng)
                bf = fit_follower(data, model, x0=fit.theta, counts=counts, identifiability=False)
                q = bf.params
                bc = _certify(q, sample_time)  # the same certificate as the point's
                verdicts.append(str(bc.verdict))
                for k in PARAMETERS["cacc"]:
                    boot[k].append(q[k])
                boot["sup_gain"].append(float(bc.sup_gain))
                bar.step(f"{lg.name(p)} bootstrap")
            bp = {k: np.asarray(v) for k, v in boot.items()}
            box = _box(fit.params, bp, model, sample_time) if B >= 2 else None
            emp = empirical_transfer(data.v_pred, data.v, segs, lg.dt)
            vr = VehicleResult(li, p, lg.name(p), lg.name(p - 1), fit, list(segs), cert, bp, verdicts,
                               box, emp, data)
            vr.notes += pre
            if not prof and _weak_headway(fit, bp["headway"]):
                prof, _ = _profile(data, model, sample_time, n_starts, seed)
            if prof:
                vr.profile = prof
                vr.notes.append(_profile_note(prof, fit.rmse_speed))
            vr.notes += _disagreement(vr) + _quality(vr)
            out.append(vr)
    finally:
        bar.close()
    settings = {"bootstrap": B, "block": block, "starts": n_starts, "seed": seed,
                "min_duration": min_duration, "bootstrap_method": "moving-block over time within clean segments"}
    return IdentifyResult(out, model, sample_time, settings, [lg.source for lg in logs], skipped)


def _weak_headway(fit: FitResult, boot_headway: Array) -> bool:
    """T* is at a bound, the speed barely varies, or the bootstrap moves T* by over 0.5 s."""
    spread = (boot_headway.size >= 2
              and float(np.subtract(*np.percentile(boot_headway, [95, 5]))) > 0.5)
    return "headway" in fit.at_bound or any("T* and the standstill" in n for n in fit.notes) or spread


#: Time headways of the profile (those above what the data's gaps allow are dropped), s.
PROFILE_GRID = (0.0, 0.5, 1.0, 1.5, 2.0, 2.5)


def _profile(data: FollowerData, model: str, H: float | None, n_starts: int,
             seed: int) -> tuple[list[dict[str, Any]], list[FitResult]]:
    """Refit with T* held on :data:`PROFILE_GRID` and certify each refit."""
    from ..certify import api as ss

    v = np.concatenate([data.v[s.start:s.stop] for s in data.segments])
    g = np.concatenate([data.gap[s.start:s.stop] for s in data.segments])
    moving = v > 1.0
    t_max = float(np.percentile(g[moving] / v[moving], 5)) if moving.sum() > 10 else 0.0
    grid = np.array([T for T in PROFILE_GRID if T <= t_max] or [0.0])
    fits = profile_headway(data, model, grid, n_starts=max(1, min(n_starts, 2)), seed=seed)
    rows: list[dict[str, Any]] = []
    for T, pf in zip(grid, fits):
        q = pf.params
        c = ss.certify(q["k_x"], q["k_v"], q["k_a"], tau=q["tau"], delta=q["delta"], headway=q["headway"],
                       sample_time=H)
        rows.append({"headway": float(T), "k_x": q["k_x"], "k_v": q["k_v"], "tau": q["tau"],
                     "standstill": q["standstill"], "rmse_speed": pf.rmse_speed, "rmse_gap": pf.rmse_gap,
                     "verdict": c.verdict, "sup_gain": float(c.sup_gain), "at_bound": pf.at_bound})
    return rows, fits


def _profile_note(rows: list[dict[str, Any]], best: float) -> str:
    """Does the verdict depend on T*? (speed RMSE of each fixed T* relative to the point fit's)."""
    for r in rows:
        r["rmse_speed_increase"] = r["rmse_speed"] / best - 1.0 if best > 0 else math.nan
    verdicts = {r["verdict"] for r in rows}
    Ts = ", ".join(f"{r['headway']:g}" for r in rows)
    inc = [100 * r["rmse_speed_increase"] for r in rows]
    sups = [r["sup_gain"] for r in rows]
    if len(verdicts) == 1:
        return (f"profile over T*: with T* held at {Ts} s (the others refitted; speed RMSE "
                f"{min(inc):+.1f} to {max(inc):+.1f} % of the point fit's, sup|Γ| {min(sups):.4g}-{max(sups):.4g}) "
                f"the verdict is {verdicts.pop()} at every value: the T*/l_0 ambiguity does not change it")
    which = "; ".join(f"T* = {r['headway']:g} s: {r['verdict']} (speed RMSE {100 * r['rmse_speed_increase']:+.1f} %)"
                      for r in rows)
    return ("profile over T*: the verdict depends on T* (the others refitted; speed RMSE relative to "
            f"the point fit): {which}")


def _box(p: dict[str, float], bp: dict[str, Array], model: str, H: float | None) -> Any:
    """The robust certificate at the point gains over the 5-95 % bootstrap box of τ, T* (and δ)."""
    from ..certify import api as ss

    def iv(k: str) -> Any:
        lo, hi = (float(x) for x in np.percentile(bp[k], [5, 95]))
        lo, hi = min(lo, p[k]), max(hi, p[k])
        return (lo, hi) if hi > lo else p[k]

    delta = iv("delta") if model == "cacc" else p["delta"]
    try:
        return ss.certify(p["k_x"], p["k_v"], p["k_a"], tau=iv("tau"), delta=delta,
                          headway=iv("headway"), sample_time=H)
    except StringStabError:
        return None


def _disagreement(v: VehicleResult) -> list[str]:
    """Where the model's verdict and the data's own amplification part ways.

    The data's amplification is |Ĝ| ± 2ε (:mod:`stringstab.identify.empirical`).
    """
    e = v.empirical
    sup = float(v.certificate.sup_gain)
    model_amplifies = v.certificate.verdict == "not_certified"
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


def _quality(v: VehicleResult) -> list[str]:
    """Notes on the fit's quality and on the record itself."""
    notes = []
    d = v.data
    g = np.concatenate([d.gap[s.start:s.stop] for s in v.segments])
    if g.min() <= 0:
        notes.append(f"the recorded gap drops to {g.min():.3g} m (GPS error or a collision): the "
                     "record is used as it is")
    gaps, _ = simulated(v)
    smin = min(float(x.min()) for x in gaps)
    if smin <= 0 < g.min():
        notes.append(f"the fitted model's simulated gap reaches {smin:.3g} m where the measured one "
                     f"stays above {g.min():.3g} m: the linear law misses part of this car's response "
                     "(large, asymmetric manoeuvres)")
    rel = v.fit.rmse_gap / max(float(g.mean()), 1.0)
    if rel > 0.15:
        notes.append(f"poor fit: the gap RMSE is {100 * rel:.0f} % of the mean gap; the verdict "
                     "describes the best linear law, not necessarily this car")
    return notes


def simulated(v: VehicleResult) -> tuple[list[Array], list[Array]]:
    """Simulated gap and speed of the point fit on each segment (for figures).

    Parameters
    ----------
    v : VehicleResult
        An identified follower (its point fit must exist).

    Returns
    -------
    gaps, speeds : list of ndarray
        Per segment, the simulated gap (m) and speed (m/s) from the fitted initial states.
    """
    f = v.fit
    assert f.theta is not None
    return simulate_segments(model_of(f.theta[:len(f.names)], f.names), v.data, f.initial)
