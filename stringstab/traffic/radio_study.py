"""Loss and noise, measured: a Monte-Carlo study of a platoon's amplification with its radio (issue 26 item 4).

For each gain triple K = (k_x, k_v, k_a) of the eq-4 law, each burst length B and each loss
rate p, a batch of S platoons of N followers (one platoon per replicate) runs behind one leader
with the V2V radio of :mod:`stringstab.traffic.radio` (messages every P = NΔt, held, lost at
rate p, independently when B = 1, in Gilbert–Elliott bursts of mean length B otherwise) and,
optionally, sensor noise (:mod:`stringstab.traffic.sensors`).  Per replicate it measures, from
the acceleration energies Σ_t a_i(t)² of the run:

* m_p of every link i (IDL eq 29, intended form: ‖a_i‖₂ / ‖a_{i−1}‖₂, the empirical ℓ2 gain of
  the link) and its maximum along the string, the **amplification**;
* the empirical ℓ2 gain from the first follower to the last, ‖a_N‖₂ / ‖a_1‖₂, and from the leader
  to the last, ‖a_N‖₂ / ‖a_0‖₂;
* the share of messages lost and the share of follower time in fallback.

Over the S replicates each is summarised by its mean and a two-sided Student-t confidence
interval (:func:`t_interval`, 95 % by default): mean ± t_{(1+c)/2, S−1} s/√S, s the sample
standard deviation.  Replicate r of a study with S replicates is platoon r of one batch whose
loss and noise are drawn from the streams seeded by ``seed`` (:class:`~stringstab.traffic.Radio`,
:class:`~stringstab.traffic.SensorNoise`): the same seed and S give the same study, bit for bit.

Beside each triple, the certificates of the loop **without loss** through the one way in
(:mod:`stringstab.certify.api`): the continuous-time one and the sampled-data one at the control
step H = Δt (messages every step).  Random loss, the switching between the cooperative and the
fallback mode and sensor noise are covered by no certificate; a message period P > H is the
multi-rate loop, whose certificate is not part of this module.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show
from .controllers import LinearController
from .limits import Limits
from .loss import check_loss
from .metrics import damping_ratios_from_energy
from .platoon import simulate
from .radio import Radio, message_steps
from .sensors import SensorNoise
from .trajectory import Trajectory

__all__ = ["DEFAULT_BURSTS", "DEFAULT_LOSSES", "NOT_COVERED", "RadioStudy", "first_exceedance",
           "run_radio_study", "t_interval"]

Array = npt.NDArray[np.float64]

#: Loss rates of the default study.
DEFAULT_LOSSES: tuple[float, ...] = (0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3)
#: Mean burst lengths (messages) of the default study; 1 means independent (Bernoulli) losses.
DEFAULT_BURSTS: tuple[float, ...] = (1.0, 5.0)
#: What no certificate covers, said beside every row.
NOT_COVERED = ("random message loss, the switching between the cooperative and the fallback "
               "(ACC) mode and sensor noise are covered by no certificate")


def t_interval(samples: npt.ArrayLike, level: float = 0.95) -> tuple[float, float, float]:
    """Mean and two-sided Student-t confidence interval of the mean of i.i.d. samples.

    mean ± t_{(1+c)/2, n−1} · s / √n, with s the sample standard deviation (ddof = 1) and c
    the confidence level.

    Parameters
    ----------
    samples : array_like
        The n replicate values (NaN entries are dropped).
    level : float
        Confidence level c in (0, 1).

    Returns
    -------
    (float, float, float)
        (mean, lower, upper); the bounds are NaN with fewer than two finite samples, and the
        mean too with none.

    Raises
    ------
    StringStabError
        If ``level`` is not in (0, 1).

    Examples
    --------
    >>> m, lo, hi = t_interval([1.0, 2.0, 3.0])
    >>> round(m, 6), round(lo, 4), round(hi, 4)
    (2.0, -0.4841, 4.4841)
    """
    from scipy.stats import t as student_t

    if not (0.0 < level < 1.0):
        raise StringStabError(f"confidence level must be in (0, 1); got {show(level)}")
    x = np.asarray(samples, dtype=np.float64).ravel()
    x = x[np.isfinite(x)]
    n = x.size
    if n == 0:
        return math.nan, math.nan, math.nan
    mean = float(x.mean())
    if n < 2:
        return mean, math.nan, math.nan
    half = float(student_t.ppf(0.5 + level / 2.0, n - 1) * x.std(ddof=1) / math.sqrt(n))
    return mean, mean - half, mean + half


def _crossing(x: Array, y: Array, bound: float) -> float | None:
    """First x at which the piecewise-linear y(x) rises above ``bound`` (None if never)."""
    above = y > bound
    if not above.any():
        return None
    k = int(np.argmax(above))
    if k == 0:
        return float(x[0])
    x0, x1, y0, y1 = x[k - 1], x[k], y[k - 1], y[k]
    return float(x0 + (bound - y0) * (x1 - x0) / (y1 - y0))


def first_exceedance(losses: npt.ArrayLike, mean: npt.ArrayLike, lower: npt.ArrayLike,
                     upper: npt.ArrayLike, bound: float = 1.0) -> dict[str, float | None]:
    """The loss rate at which the measured amplification first exceeds ``bound``, with its interval.

    Linear interpolation between the loss rates of the grid: ``loss`` where the mean first
    rises above the bound, ``loss_lo`` where the upper confidence bound does (the earliest
    rate compatible with the interval) and ``loss_hi`` where the lower bound does (from there on
    the amplification exceeds the bound at the interval's confidence).  A value at the first
    grid point means it is exceeded already there; None means not on the grid.

    Parameters
    ----------
    losses : array_like
        Increasing loss rates.
    mean, lower, upper : array_like
        The amplification's mean and confidence bounds at each loss rate.
    bound : float
        The threshold (1: the certificate's bound on every link).

    Returns
    -------
    dict
        ``loss``, ``loss_lo``, ``loss_hi`` (float or None).

    Examples
    --------
    >>> first_exceedance([0, 0.1, 0.2], [0.9, 0.98, 1.06], [0.89, 0.96, 1.02], [0.91, 1.0, 1.1])
    {'loss': 0.125, 'loss_lo': 0.1, 'loss_hi': 0.16666666666666669}
    """
    p = np.asarray(losses, dtype=np.float64)
    out: dict[str, float | None] = {}
    for key, y in (("loss", mean), ("loss_lo", upper), ("loss_hi", lower)):
        out[key] = _crossing(p, np.asarray(y, dtype=np.float64), bound)
    return out


@dataclass
class RadioStudy:
    """The measured amplification over gains × bursts × loss rates × replicates.

    Attributes
    ----------
    gains : array (G, 3)
        The triples (k_x, k_v, k_a).
    bursts : array (B,)
        Mean burst lengths in messages (1: independent losses).
    losses : array (L,)
        Loss rates p.
    seeds : int
        Replicates S per point.
    m_p : array (G, B, L, S, N)
        m_p of every link (IDL eq 29), per replicate.
    gain_first : array (G, B, L, S)
        ‖a_N‖₂ / ‖a_1‖₂, first follower to last.
    gain_leader : array (G, B, L, S)
        ‖a_N‖₂ / ‖a_0‖₂, leader to last.
    loss_share, fallback_share : array (G, B, L, S)
        Messages lost over messages due, and follower time in fallback over follower time.
    collisions : int array (G, B, L, S)
        Collision events per replicate.
    certificates : list of dict
        Per triple: the verdicts and sup-gains of the loop without loss (``continuous``,
        ``sampled``) and ``multirate`` (None: not part of this module).
    settings : dict
        τ, δ, T*, H, P, the leader, the radio and sensor settings, the seed, the level.
    """

    gains: Array
    bursts: Array
    losses: Array
    seeds: int
    m_p: Array
    gain_first: Array
    gain_leader: Array
    loss_share: Array
    fallback_share: Array
    collisions: npt.NDArray[np.int64]
    certificates: list[dict[str, Any]]
    settings: dict[str, Any] = field(default_factory=dict)

    @property
    def amplification(self) -> Array:
        """Max m_p along the string per replicate, (G, B, L, S)."""
        with np.errstate(invalid="ignore"):
            return np.asarray(np.nanmax(self.m_p, axis=-1))

    def summary(self, metric: str = "amplification") -> Array:
        """Mean and t-interval of a per-replicate metric at every point, (G, B, L, 3).

        Parameters
        ----------
        metric : str
            ``"amplification"``, ``"gain_first"`` or ``"gain_leader"``.

        Returns
        -------
        array (G, B, L, 3)
            (mean, lower, upper) at the study's level (:func:`t_interval`).
        """
        values = {"amplification": self.amplification, "gain_first": self.gain_first,
                  "gain_leader": self.gain_leader}[metric]
        level = float(self.settings.get("level", 0.95))
        out = np.empty((*values.shape[:-1], 3))
        for idx in np.ndindex(*values.shape[:-1]):
            out[idx] = t_interval(values[idx], level)
        return out

    def exceedance(self, g: int, b: int, bound: float = 1.0) -> dict[str, float | None]:
        """:func:`first_exceedance` of the amplification of triple ``g`` at burst ``b``.

        Parameters
        ----------
        g, b : int
            Indices of the triple and the burst length.
        bound : float
            The threshold.

        Returns
        -------
        dict
            ``loss``, ``loss_lo``, ``loss_hi``.
        """
        s = self.summary()[g, b]
        return first_exceedance(self.losses, s[:, 0], s[:, 1], s[:, 2], bound)

    def rows(self) -> list[dict[str, Any]]:
        """One row per (triple, burst, loss rate): the table the command writes.

        Returns
        -------
        list of dict
            K, loss, burst, replicates, the amplification and the two ℓ2 gains with their
            intervals, the mean m_p per link, the realised loss and fallback shares, the
            collisions, the certificates of the loop without loss and what no certificate
            covers.
        """
        amp, gf, gl = (self.summary(m) for m in ("amplification", "gain_first", "gain_leader"))
        with np.errstate(invalid="ignore"):
            link = np.nanmean(self.m_p, axis=3)
        rows = []
        for g, b, li in np.ndindex(len(self.gains), len(self.bursts), len(self.losses)):
            cert = self.certificates[g]
            row: dict[str, Any] = {
                "k_x": float(self.gains[g, 0]), "k_v": float(self.gains[g, 1]),
                "k_a": float(self.gains[g, 2]), "loss": float(self.losses[li]),
                "burst": float(self.bursts[b]), "seeds": self.seeds,
                "max_m_p": float(amp[g, b, li, 0]), "max_m_p_lo": float(amp[g, b, li, 1]),
                "max_m_p_hi": float(amp[g, b, li, 2]),
                "gain_first": float(gf[g, b, li, 0]), "gain_first_lo": float(gf[g, b, li, 1]),
                "gain_first_hi": float(gf[g, b, li, 2]),
                "gain_leader": float(gl[g, b, li, 0]), "gain_leader_lo": float(gl[g, b, li, 1]),
                "gain_leader_hi": float(gl[g, b, li, 2]),
                "loss_share": float(np.mean(self.loss_share[g, b, li])),
                "fallback_share": float(np.mean(self.fallback_share[g, b, li])),
                "collisions": int(self.collisions[g, b, li].sum()),
                "continuous": cert["continuous"]["verdict"],
                "continuous_sup_gain": cert["continuous"]["sup_gain"],
                "sampled": None if cert["sampled"] is None else cert["sampled"]["verdict"],
                "sampled_sup_gain": None if cert["sampled"] is None else cert["sampled"]["sup_gain"],
                "multirate": cert["multirate"],
                "covered": self.covered(float(self.losses[li])),
            }
            for i in range(link.shape[-1]):
                row[f"m_p_{i + 1}"] = float(link[g, b, li, i])
            rows.append(row)
        return rows

    def covered(self, loss: float) -> str:
        """What certificate, if any, covers the loop at this loss rate (a sentence).

        Parameters
        ----------
        loss : float
            The loss rate p.

        Returns
        -------
        str
            ``"sampled certificate (messages every step)"`` for the loop it describes exactly,
            else what leaves every certificate.
        """
        s = self.settings
        outside = []
        if s.get("message_steps", 1) > 1:
            outside.append("messages every P > H held (the multi-rate loop; its certificate is "
                           "not on this branch)")
        if loss > 0:
            outside.append("random loss")
        if s.get("stale_after") is not None:
            outside.append("fallback switching")
        if s.get("sensors") is not None:
            outside.append("sensor noise")
        if not outside:
            return "sampled certificate (messages every step)"
        return "not covered: " + ", ".join(outside)


def _certificates(K: Sequence[float], *, tau: float, delta: float, headway: float, dt: float,
                  reaction_delay: float) -> dict[str, Any]:
    """The continuous and sampled (H = Δt) certificates of the loop without loss (with θ_r too)."""
    from ..certify.api import certify
    from ..certify.verdicts import Verdict

    c = certify(K[0], K[1], K[2], tau=tau, delta=delta, headway=headway,
                reaction_delay=reaction_delay)
    out: dict[str, Any] = {"continuous": {"verdict": Verdict(c.verdict).value, "sup_gain": float(c.sup_gain)},
                           "sampled": None, "multirate": None}
    # θ_r > 0: the sampled certificate with θ_r (docs/sampled.md §10; the simulator's two held
    # pieces per step are its model)
    s = certify(K[0], K[1], K[2], tau=tau, delta=delta, headway=headway, sample_time=dt,
                reaction_delay=reaction_delay)
    out["sampled"] = {"verdict": Verdict(s.verdict).value, "sup_gain": float(s.sup_gain)}
    return out


def _check_grid(name: str, values: Sequence[float], check: Callable[[float], Any]) -> Array:
    x = np.asarray(values, dtype=np.float64).ravel()
    if x.size == 0:
        raise StringStabError(f"{name} must hold at least one value; got none")
    for v in x:
        check(float(v))
    if np.any(np.diff(x) <= 0):
        raise StringStabError(f"{name} must be strictly increasing; got {show(list(map(float, x)))}")
    return x


def run_radio_study(
    gains: Sequence[Sequence[float]],
    leader: Trajectory,
    *,
    n_followers: int = 10,
    tau: float = 0.1,
    delta: float = 0.2,
    headway: float = 1.1,
    standstill: float = 2.0,
    message_period: float = 0.1,
    message_phase: int = 0,
    losses: Sequence[float] = DEFAULT_LOSSES,
    bursts: Sequence[float] = DEFAULT_BURSTS,
    seeds: int = 20,
    seed: int = 0,
    stale_after: float | None = None,
    fallback_gains: tuple[float, float] | None = None,
    sensors: SensorNoise | None = None,
    limits: Limits | None = None,
    reaction_delay: float = 0.0,
    length: float | None = None,
    level: float = 0.95,
    progress: Callable[[int], Any] | None = None,
) -> RadioStudy:
    """Measure the amplification of a platoon with its radio over loss rates and burst lengths.

    Every point (triple, burst B, loss p) is one batch of ``seeds`` platoons of ``n_followers``
    behind ``leader`` (:func:`stringstab.traffic.platoon.simulate`, ``record=False``), with
    ``Radio(message_period, loss=p, burst=None if B == 1 else B, ...)`` seeded by ``seed``.

    Parameters
    ----------
    gains : sequence of (k_x, k_v, k_a)
        The eq-4 triples (IDL eq 4).
    leader : Trajectory
        The leader; its step Δt is the control step H.
    n_followers : int
        Followers N per platoon.
    tau, delta, headway, standstill : float
        τ (s), the transport delay δ (s), T* (s), l_0 (m).
    message_period : float
        P, s, a whole multiple of Δt (P = Δt: a message every step).
    message_phase : int
        φ, the step (0..P/Δt − 1) at which messages are used.
    losses : sequence of float
        Increasing loss rates in [0, 1].
    bursts : sequence of float
        Increasing mean burst lengths ≥ 1 (1: independent losses).
    seeds : int
        Replicates S ≥ 2 per point (platoons of one batch).
    seed : int
        Seed of the loss and noise streams.
    stale_after, fallback_gains
        The staleness fallback (:class:`~stringstab.traffic.Radio`).
    sensors : SensorNoise, optional
        Sensor noise (its seed is replaced by ``seed``).
    limits : Limits, optional
        The followers' limits (IDL Table 2 by default).
    reaction_delay : float
        θ_r, s.
    length : float, optional
        Vehicle length, m (the simulator's default when None).
    level : float
        Confidence level of the intervals.
    progress : callable, optional
        Called with the number of platoon-runs just done.

    Returns
    -------
    RadioStudy
        The measured values per replicate and the certificates.

    Raises
    ------
    StringStabError
        On a loss rate outside [0, 1], a burst below 1 or too short for a loss rate, a message
        period that is not a whole multiple of Δt, fewer than two replicates, a bad triple.
    """
    dt = float(leader.dt)
    N = message_steps(message_period, dt)
    if not (isinstance(seeds, (int, np.integer)) and seeds >= 2):
        raise StringStabError(f"seeds must be an integer >= 2 (a confidence interval needs two "
                              f"replicates); got {show(seeds)}")
    if not (isinstance(n_followers, (int, np.integer)) and n_followers >= 2):
        raise StringStabError(f"n_followers must be an integer >= 2; got {show(n_followers)}")
    p = _check_grid("losses", losses, lambda v: check_loss(v))
    b = _check_grid("bursts", bursts, lambda v: check_loss(0.0, v))
    for bb in b[b > 1]:
        for pp in p:
            check_loss(float(pp), float(bb))
    K = np.asarray(gains, dtype=np.float64).reshape(-1, 3)
    if not np.isfinite(K).all():
        raise StringStabError(f"gains must be finite (k_x, k_v, k_a) triples; got {show(K.tolist())}")
    shape = (len(K), len(b), len(p), seeds)
    mp = np.full((*shape, n_followers), np.nan)
    gf, gl, ls, fs = (np.full(shape, np.nan) for _ in range(4))
    coll = np.zeros(shape, dtype=np.int64)
    noise = None if sensors is None else dataclasses.replace(sensors, seed=seed)
    kw: dict[str, Any] = {"tau": tau, "delta": delta, "limits": limits, "record": False,
                          "progress": False, "reaction_delay": reaction_delay, "sensors": noise}
    if length is not None:
        kw["length"] = length
    batch = [leader] * seeds
    for g, bi, li in np.ndindex(*shape[:3]):
        radio = Radio(message_period=message_period, message_phase=message_phase,
                      loss=float(p[li]), burst=None if b[bi] == 1 else float(b[bi]),
                      stale_after=stale_after, fallback_gains=fallback_gains, seed=seed)
        ctrl = LinearController(*K[g], headway=headway, standstill=standstill)
        res = simulate(batch, ctrl, n_followers, radio=radio, **kw)
        s = np.asarray(res.sum_sq_accel, dtype=np.float64)  # (S, N + 1)
        mp[g, bi, li] = damping_ratios_from_energy(s)
        with np.errstate(divide="ignore", invalid="ignore"):
            gf[g, bi, li] = np.sqrt(s[:, -1] / s[:, 1])
            gl[g, bi, li] = np.sqrt(s[:, -1] / s[:, 0])
        r = res.radio or {}
        rec = np.asarray(r.get("messages_received", 0), dtype=np.float64)
        lost = np.asarray(r.get("messages_lost", 0), dtype=np.float64)
        due = np.sum(rec + lost, axis=-1)
        ls[g, bi, li] = np.where(due > 0, np.sum(lost, axis=-1) / np.maximum(due, 1), np.nan)
        fb = np.asarray(r.get("fallback_time", np.zeros((seeds, n_followers))), dtype=np.float64)
        fs[g, bi, li] = np.sum(fb, axis=-1) / (n_followers * res.t.size * res.dt)  # as radio_summary
        coll[g, bi, li] = np.sum(res.collision_events, axis=-1)
        if progress is not None:
            progress(seeds)
    certs = [_certificates(k, tau=tau, delta=delta, headway=headway, dt=dt,
                           reaction_delay=reaction_delay) for k in K.tolist()]
    settings = {"tau": tau, "delta": delta, "headway": headway, "standstill": standstill,
                "dt": dt, "message_period": message_period, "message_steps": N,
                "message_phase": message_phase, "stale_after": stale_after,
                "fallback_gains": None if fallback_gains is None else list(fallback_gains),
                "sensors": None if noise is None else noise.describe(),
                "reaction_delay": reaction_delay, "seed": seed, "level": level,
                "leader": getattr(leader, "name", "leader"), "duration": leader.duration,
                "followers": n_followers,
                "interval": f"two-sided Student-t, {100 * level:g} % over the replicates"}
    return RadioStudy(gains=K, bursts=b, losses=p, seeds=int(seeds), m_p=mp, gain_first=gf,
                      gain_leader=gl, loss_share=ls, fallback_share=fs, collisions=coll,
                      certificates=certs, settings=settings)
