"""Figures of gain repairs (:mod:`stringstab.tuning`): the moves K0 → K over the certified region.

The background is computed first (:func:`moves_projection` or :func:`moves_region`), then
drawn with the moves (:func:`plot_moves`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..constants import GAIN_BOUNDS
from ..errors import StringStabError
from ._common import PlotResult, pyplot

if TYPE_CHECKING:
    from ..regions import RegionMap
    from ..tuning import TuneResult
    from .projection import ProjectedRegion

__all__ = ["moves_projection", "moves_region", "plot_moves"]


def moves_region(results: Sequence[TuneResult], *, tau: float, delta: float, headway: float,
                 k_a: float | None = None, bounds: tuple[float, float] = GAIN_BOUNDS,
                 n: int = 121) -> RegionMap:
    """The exact region map behind :func:`plot_moves`: a k_x–k_v slice at ``k_a`` (compute step).

    ``k_a`` defaults to the median input k_a of ``results``; the slice is an ``n`` × ``n``
    grid over ``bounds``.

    Parameters
    ----------
    results : sequence of TuneResult
        The repairs (only their input k_a is used, for the default slice).
    tau : float
        Actuator lag τ (s).
    delta : float
        Communication delay δ (s).
    headway : float
        Time headway T* (s).
    k_a : float, optional
        The fixed k_a of the slice; default the median input k_a (0 without results).
    bounds : tuple of float, default GAIN_BOUNDS
        Range (lo, hi) of both k_x (1/s²) and k_v (1/s).
    n : int, default 121
        Grid points per axis.

    Returns
    -------
    RegionMap
        The continuous-time exact map (``methods="exact"``), computed serially.
    """
    from ..regions import region_map
    from ..tuning.inputs import as_bounds

    lo, hi = as_bounds(bounds)
    if k_a is None:
        k_a = float(np.median([r.k_in[2] for r in results])) if results else 0.0
    g = np.linspace(lo, hi, n)
    return region_map({"k_x": g, "k_v": g}, {"k_a": k_a}, tau=tau, delta=delta, headway=headway,
                      methods="exact", workers=1, progress=False)


def moves_projection(results: Sequence[TuneResult], *, tau: float, delta: float,
                     headway: float, bounds: tuple[float, float] = GAIN_BOUNDS,
                     n: int = 101) -> ProjectedRegion:
    """The exact region behind :func:`plot_moves`, projected over the outputs' k_a (compute step).

    The certified region in the (k_x, k_v) plane projected over the output k_a values
    (:func:`stringstab.plots.projection.projected_region`: certified at every / some / none
    of them), so every repaired gain lies where its own verdict says, whatever its k_a.

    Parameters
    ----------
    results : sequence of TuneResult
        The repairs (their output gains give the k_a values).
    tau : float
        Actuator lag τ (s).
    delta : float
        Communication delay δ (s).
    headway : float
        Time headway T* (s).
    bounds : tuple of float, default GAIN_BOUNDS
        Range (lo, hi) of k_x (1/s²) and k_v (1/s), padded by 5 % so gains on a bound are
        not clipped.
    n : int, default 101
        Grid points per axis.

    Returns
    -------
    ProjectedRegion
        The plane's grid and the certified share at each of its points.
    """
    from ..tuning.inputs import as_bounds
    from .projection import projected_region

    lo, hi = as_bounds(bounds)
    pad = 0.05 * (hi - lo)
    ends = np.array([r.k for r in results], dtype=float).reshape(-1, 3)
    return projected_region(ends, tau=tau, delta=delta, headway=headway,
                            bounds=(lo - pad, hi + pad), n=n)


def plot_moves(
    results: Sequence[TuneResult],
    region: RegionMap | ProjectedRegion,
    *,
    ax: Any = None,
) -> PlotResult:
    """Draw repairs as arrows K0 → K over the certified region in the (k_x, k_v) plane.

    The background is computed beforehand: the exact certified region projected over the
    output k_a values (a :class:`~stringstab.plots.projection.ProjectedRegion` from
    :func:`moves_projection`), so every repaired gain lies where its own verdict says, or one
    k_x–k_v slice (a 2-D :class:`~stringstab.regions.RegionMap` with ``exact``, e.g. from
    :func:`moves_region`), and the title says so.  The arrows are the moves projected onto
    (k_x, k_v), coloured by method; each input is numbered in the order of ``results`` (the
    report's table gives its output k_a and distance moved).

    Parameters
    ----------
    results : sequence of TuneResult
        The repairs.
    region : ProjectedRegion or RegionMap
        The background: :func:`moves_projection` or :func:`moves_region` of the results.
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    PlotResult
        ``ax``, ``region`` (the background image) and ``arrows``.

    Raises
    ------
    StringStabError
        If ``region`` is neither a projection nor a k_x–k_v slice with the exact verdicts.
    """
    from ._common import GAIN_LABELS
    from .projection import ProjectedRegion, plot_projected_region

    if ax is None:
        _, ax = pyplot().subplots(figsize=(6.4, 6.4), layout="constrained")
    if isinstance(region, ProjectedRegion):
        mesh = plot_projected_region(region, ax=ax, title="repairs K0 → K (arrows, by method)")["image"]
    else:
        if getattr(region, "axis_names", None) != ("k_x", "k_v") or "exact" not in region.methods:
            raise StringStabError(
                "plot_moves draws over a projection (moves_projection) or a k_x-k_v slice with "
                f"the exact verdicts; got {type(region).__name__} with axes "
                f"{list(getattr(region, 'axis_names', []))} and methods "
                f"{list(getattr(region, 'methods', []))}")
        KX, KV, _ = region.gains()
        mesh = ax.pcolormesh(KX, KV, region.stable("exact").astype(float), cmap="Greens",
                             vmin=0.0, vmax=1.6, shading="auto")
        ax.set_title(f"repairs K0 → K over the certified slice k_a = {region.fixed['k_a']:g} "
                     "(the outputs' own k_a may differ)", fontsize=9)
        ax.set_xlabel(GAIN_LABELS["k_x"])
        ax.set_ylabel(GAIN_LABELS["k_v"])
    colours = {"region-growing": "tab:orange", "projection": "tab:red"}
    arrows = []
    labelled: set[str] = set()
    starts: dict[tuple[float, float], int] = {}
    for r in results:
        c = colours.get(r.method, "k")
        x0, y0, x1, y1 = r.k_in[0], r.k_in[1], r.k[0], r.k[1]
        key = (round(float(x0), 9), round(float(y0), 9))
        if key not in starts:  # one number per input triple, however many methods repair it
            starts[key] = len(starts) + 1
            ax.plot([x0], [y0], "o", color="k", ms=3.5, zorder=5)
            ax.annotate(str(starts[key]), (x0, y0), xytext=(-3, 3), textcoords="offset points",
                        ha="right", fontsize=8, zorder=6,
                        bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8})
        label = None if r.method in labelled else f"{r.method} (■ certified, × not)"
        labelled.add(r.method)
        arrows.append(ax.annotate("", xy=(x1, y1), xytext=(x0, y0), zorder=5,
                                  arrowprops={"arrowstyle": "->", "color": c, "lw": 1.4}))
        ax.plot([x1], [y1], "s" if r.certified else "x", color=c, ms=5, label=label, zorder=6)
    from matplotlib.legend import Legend

    handles = [h for h in ax.get_lines() if not h.get_label().startswith("_")]
    ax.add_artist(Legend(ax, handles, [h.get_label() for h in handles], loc="lower left",
                         fontsize=8))
    return PlotResult.of({"ax": ax, "region": mesh, "arrows": arrows})
