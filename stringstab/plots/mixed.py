"""Figures of mixed strings (:mod:`stringstab.mixed`): the head-to-tail gain, the replays, m_p.

Each function takes what was computed (vehicles, a :class:`~stringstab.mixed.replay.Replay`,
the data's :class:`~stringstab.mixed.empirical.StringEmpirical`) and ``ax=None``, and returns
a :class:`~stringstab.plots.PlotResult` with the lines it drew.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ._common import PlotResult, new_ax

__all__ = ["plot_head_to_tail", "plot_replay_energy", "plot_replay_speeds"]


def _product(vehicles: Sequence[Any], omega: np.ndarray) -> np.ndarray:
    from ..certify.frequency import gain

    out = np.ones(omega.shape)
    for v in vehicles:
        p = v.params
        out = out * gain(omega, v.k_x, v.k_v, v.k_a, tau=p.tau, delta=p.delta, headway=p.headway)
    return out


def plot_head_to_tail(strings: Sequence[tuple[str, Sequence[Any]]], *, empirical: Any = None,
                      omega: np.ndarray | None = None, ax: Any = None) -> PlotResult:
    """∏_i |Γ_i(jω)| of each string (log ω), with the data's |Ĝ| from first to last car.

    Parameters
    ----------
    strings : sequence of (label, vehicles)
        The strings (each a sequence of :class:`~stringstab.certify.head_to_tail.Vehicle`).
    empirical : StringEmpirical, optional
        The data's head-to-tail transfer, drawn where its coherence is ≥ 0.5 and ω ≤ 1 rad/s
        (:data:`stringstab.identify.empirical.OMEGA_MAX`: above it the logs' coherent |Ĝ|
        measures the GPS receivers, not the cars).
    omega : ndarray, optional
        Frequencies, rad/s (default 400 log-spaced on [10⁻², 10]).
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    PlotResult
        Artists ``lines`` (label → Line2D), ``empirical`` (or None) and ``peaks``
        (label → (ω, max ∏|Γ_i|) on the grid).
    """
    ax = new_ax(ax, (7.0, 4.2))
    w = np.geomspace(1e-2, 10.0, 400) if omega is None else np.asarray(omega, dtype=float)
    lines = {}
    peaks = {}
    for label, vs in strings:
        g = _product(vs, w)
        (lines[label],) = ax.semilogx(w, g, lw=1.5, label=label)
        j = int(np.argmax(g))
        peaks[label] = (float(w[j]), float(g[j]))
    emp = None
    if empirical is not None:
        e = empirical.empirical
        cmin, wmax = empirical.coherence_min, empirical.omega_max
        ok = (e.omega > 0) & (e.coherence >= cmin) & (e.omega <= wmax)
        (emp,) = ax.semilogx(e.omega[ok], np.abs(e.transfer[ok]), "k.", ms=5,
                             label=f"data |Ĝ| first → last car (coherence ≥ {cmin:g}, "
                                   f"ω ≤ {wmax:g} rad/s)")
    ax.axhline(1.0, color="0.5", lw=0.8, ls="--")
    ax.set_xlabel("ω [rad/s]")
    ax.set_ylabel("∏ |Γ_i(jω)|  (head to tail)")
    ax.legend(fontsize=8)
    return PlotResult.of({"ax": ax, "lines": lines, "empirical": emp, "peaks": peaks})


def plot_replay_speeds(replay: Any, *, ax: Any = None) -> PlotResult:
    """The leader's and the last follower's speed in each replay.

    Parameters
    ----------
    replay : Replay
        From :func:`stringstab.mixed.replay.replay`.
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    PlotResult
        Artists ``leader`` (Line2D) and ``lines`` (label → the last follower's Line2D).
    """
    ax = new_ax(ax, (8.0, 4.0))
    first = replay.runs[0].result
    t = np.asarray(first.t)
    (lead,) = ax.plot(t, np.asarray(first.speed)[0], color="0.5", lw=1.0,
                      label=f"leader ({replay.leader}, recorded)")
    lines = {}
    for r in replay.runs:
        name = r.vehicles[-1].name or "last follower"
        (lines[r.label],) = ax.plot(t, np.asarray(r.result.speed)[-1], lw=1.2,
                                    label=f"last car, {r.label} ({name})")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("speed [m/s]")
    ax.legend(fontsize=8)
    return PlotResult.of({"ax": ax, "leader": lead, "lines": lines})


def plot_replay_energy(replay: Any, *, band: bool = True, ax: Any = None) -> PlotResult:
    """The acceleration-energy ratio of each follower to the leader along the string (∏ m_p).

    Parameters
    ----------
    replay : Replay
        From :func:`stringstab.mixed.replay.replay`.
    band : bool
        In the band 0 < ω ≤ 1 rad/s (default; see :func:`stringstab.mixed.replay.band_energy`),
        or over all frequencies (IDL eq 29 as it stands).
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    PlotResult
        Artists ``lines`` (label → Line2D) and ``values`` (label → the ratios drawn).
    """
    ax = new_ax(ax, (6.4, 4.0))
    lines = {}
    values = {}
    for r in replay.runs:
        y = np.cumprod(r.band_m_p if band else r.m_p)
        x = np.arange(1, y.size + 1)
        (lines[r.label],) = ax.plot(x, y, "o-", label=r.label)
        values[r.label] = y
    ax.axhline(1.0, color="0.5", lw=0.8, ls="--")
    ax.set_xlabel("follower position in the string")
    ax.set_ylabel("‖a_k‖/‖a_0‖" + (" (0 < ω ≤ 1 rad/s)" if band else ""))
    ax.set_xticks(np.arange(1, len(replay.runs[0].vehicles) + 1))
    ax.legend(fontsize=8)
    return PlotResult.of({"ax": ax, "lines": lines, "values": values})
