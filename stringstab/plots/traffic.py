"""Figures of a simulated platoon (:mod:`stringstab.traffic`), in the style of the IDL paper's Figs 7-8.

Every function takes a result computed beforehand (a :class:`~stringstab.traffic.PlatoonResult`
or its arrays) and ``ax=None`` (or ``fig=None``), and returns a
:class:`~stringstab.plots.PlotResult`, so figures can be composed; vehicles are coloured by
their position in the platoon (0 = leader).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ._common import PlotResult

__all__ = ["plot_damping_ratios", "plot_platoon", "plot_vehicles"]


def _ax(ax: Any) -> Any:
    if ax is None:
        from ._common import pyplot

        _, ax = pyplot().subplots()
    return ax


def plot_vehicles(
    t: npt.ArrayLike,
    values: npt.ArrayLike,
    *,
    ax: Any = None,
    first_position: int = 0,
    n_positions: int | None = None,
    cmap: str = "viridis",
    max_points: int = 4000,
    linewidth: float = 1.0,
) -> PlotResult:
    """One line per vehicle (rows of ``values``), coloured by position in the platoon.

    Parameters
    ----------
    t : array_like (T,)
        Times, s.
    values : array_like (V, T)
        One row per vehicle; row j is platoon position ``first_position + j``.
    ax : matplotlib Axes, optional
        Where to draw (a new figure if None).
    first_position : int
        Position of the first row (0 = leader, 1 = first follower).
    n_positions : int, optional
        Largest position for the colour scale (default the last row's).
    cmap : str
        Colormap.
    max_points : int
        Draw at most this many samples per line (a regular stride).
    linewidth : float
        Line width.

    Returns
    -------
    PlotResult
        ``ax`` and ``lines``, the LineCollection (its ``.norm`` and ``.cmap`` give the
        position colour scale, for a colour bar).
    """
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize

    tt = np.asarray(t, dtype=np.float64)
    vv = np.atleast_2d(np.asarray(values, dtype=np.float64))
    if vv.shape[-1] != tt.shape[0]:
        raise StringStabError(f"values must have shape (vehicles, {tt.shape[0]}); got {vv.shape}")
    stride = max(1, int(np.ceil(tt.shape[0] / max_points)))
    tt, vv = tt[::stride], vv[:, ::stride]
    pos = first_position + np.arange(vv.shape[0])
    hi = n_positions if n_positions is not None else int(pos[-1])
    segs = np.stack([np.broadcast_to(tt, vv.shape), vv], axis=-1)
    lc = LineCollection(list(segs), cmap=cmap, norm=Normalize(0, max(hi, 1)), linewidths=linewidth)
    lc.set_array(pos.astype(float))
    ax = _ax(ax)
    ax.add_collection(lc)
    finite = vv[np.isfinite(vv)]
    if finite.size:
        lo_v, hi_v = float(finite.min()), float(finite.max())
        pad = 0.05 * (hi_v - lo_v) or 0.5
        ax.set_ylim(lo_v - pad, hi_v + pad)
    ax.set_xlim(float(tt[0]), float(tt[-1]))
    return PlotResult.of({"ax": ax, "lines": lc})


def plot_platoon(result: Any, *, platoon: int = 0, fig: Any = None,
                 cmap: str = "viridis", title: str | None = None) -> PlotResult:
    """Speed, acceleration, spacing and time headway of every vehicle over time (Figs 7-8).

    Parameters
    ----------
    result : PlatoonResult
        A run recorded with ``record=True``.
    platoon : int
        Which platoon of a batch.
    fig : matplotlib Figure, optional
        Figure to draw in (a new 2×2 one if None).
    cmap : str
        Colormap of platoon positions.
    title : str, optional
        Figure title.

    Returns
    -------
    PlotResult
        The figure, the axes [speed, acceleration, spacing, time headway] and the
        ``colorbar``; ``fig, axes = plot_platoon(...)`` unpacks the figure and the axes.
    """
    from ._common import pyplot

    plt = pyplot()

    if result.speed is None:
        raise StringStabError("plot_platoon needs a run recorded with record=True")
    pick = (lambda a: a[platoon]) if result.speed.ndim == 3 else (lambda a: a)
    spd, acc, gap = pick(result.speed), pick(result.accel), pick(result.gap)
    hw = pick(result.headway)
    N = gap.shape[0]
    if fig is None:
        fig = plt.figure(figsize=(9, 6.5), layout="constrained")
    axes = np.asarray(fig.subplots(2, 2, sharex=True)).ravel()
    panels = [
        (spd, 0, "speed v (m/s)"),
        (acc, 0, "acceleration a (m/s²)"),
        (gap, 1, "spacing Δx, bumper to bumper (m)"),
        (hw, 1, "time headway h = Δx / v (s)"),
    ]
    lc = None
    for ax, (vals, first, label) in zip(axes, panels):
        lc = plot_vehicles(result.t, vals, ax=ax, first_position=first, n_positions=N,
                           cmap=cmap)["lines"]
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    for ax in axes[2:]:
        ax.set_xlabel("time t (s)")
    hdw = result.params.get("headway")
    if hdw is not None:
        axes[3].axhline(hdw, color="k", ls="--", lw=0.8, label=f"T* = {hdw:g} s")
        axes[3].legend(loc="lower right")  # the clipping note takes the top
    finite = hw[np.isfinite(hw)]
    if finite.size:
        top = min(float(np.percentile(finite, 99.5)) * 1.1, 10.0)
        axes[3].set_ylim(0.0, top)
        if float(finite.max()) > top:  # say so: the scale leaves out the largest headways
            k = np.unravel_index(np.nanargmax(np.where(np.isfinite(hw), hw, -np.inf)), hw.shape)
            axes[3].annotate(f"clipped: h up to {float(finite.max()):.3g} s "
                             f"(vehicle {k[0] + 1}, t = {float(result.t[k[1]]):.4g} s)",
                             xy=(0.01, 0.97), xycoords="axes fraction", ha="left", va="top",
                             fontsize=9, color="0.25",
                             bbox={"boxstyle": "round", "fc": "white", "ec": "0.7", "alpha": 0.9})
    cb = fig.colorbar(lc, ax=list(axes), shrink=0.8, pad=0.01)
    cb.set_label("position in platoon (0 = leader)")
    if title:
        fig.suptitle(title)
    return PlotResult.of({"fig": fig, "axes": axes, "colorbar": cb})


def plot_damping_ratios(m_p: npt.ArrayLike, *, ax: Any = None, label: str | None = None,
                        marker: str = "o") -> PlotResult:
    """m_p of each follower relative to its predecessor (IDL eq 29), with the m_p = 1 line.

    Parameters
    ----------
    m_p : array_like
        m_p of each follower (IDL eq 29), in platoon order.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).
    label : str, optional
        Legend label of the line (a legend is drawn when given).
    marker : str
        Marker of the points.

    Returns
    -------
    PlotResult
        ``ax`` and ``lines``: the m_p line and the reference line.
    """
    mp = np.asarray(m_p, dtype=np.float64).ravel()
    ax = _ax(ax)
    pos = np.arange(1, mp.size + 1)
    (line,) = ax.plot(pos, mp, marker=marker, ms=3 if mp.size > 30 else 5, label=label)
    ref = ax.axhline(1.0, color="k", ls="--", lw=0.8)
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))  # positions are whole numbers
    ax.set_xlabel("follower position i")
    ax.set_ylabel("damping ratio m_p (follower / predecessor)")
    ax.grid(alpha=0.3)
    if label:
        ax.legend()
    return PlotResult.of({"ax": ax, "lines": [line, ref]})
