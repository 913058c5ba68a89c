"""Figures of gain repairs (:mod:`stringstab.tuning`): the moves K0 → K over the certified region."""

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

__all__ = ["moves_region", "plot_moves"]


def moves_region(results: Sequence[TuneResult], *, tau: float, delta: float, headway: float,
                 k_a: float | None = None, bounds: tuple[float, float] = GAIN_BOUNDS,
                 n: int = 121) -> RegionMap:
    """The exact region map behind :func:`plot_moves`: a k_x–k_v slice at ``k_a`` (compute step).

    ``k_a`` defaults to the median input k_a of ``results``; the slice is an ``n`` × ``n``
    grid over ``bounds``.
    """
    from ..regions import region_map
    from ..tuning.inputs import as_bounds

    lo, hi = as_bounds(bounds)
    if k_a is None:
        k_a = float(np.median([r.k_in[2] for r in results])) if results else 0.0
    g = np.linspace(lo, hi, n)
    return region_map({"k_x": g, "k_v": g}, {"k_a": k_a}, tau=tau, delta=delta, headway=headway,
                      methods="exact", workers=1, progress=False)


def plot_moves(
    results: Sequence[TuneResult],
    *,
    region: RegionMap | None = None,
    tau: float | None = None,
    delta: float | None = None,
    headway: float | None = None,
    k_a: float | None = None,
    bounds: tuple[float, float] = GAIN_BOUNDS,
    n: int = 121,
    ax: Any = None,
) -> PlotResult:
    """Draw repairs as arrows K0 → K on a k_x–k_v slice of the certified region.

    The background shades the gains certified by the exact certificate on the slice
    ``region`` (a 2-D k_x–k_v :class:`~stringstab.regions.RegionMap` with ``exact``,
    computed beforehand, e.g. by :func:`moves_region`); the arrows are the moves projected
    onto (k_x, k_v), coloured by method; the output k_a is written next to each arrow head.
    Without ``region``, it is computed first from ``tau, delta, headway, k_a, bounds, n``
    (:func:`moves_region`), as python-control's plot functions compute the response they
    draw.

    Returns
    -------
    PlotResult
        ``ax``, ``region`` (the QuadMesh of the certified region) and ``arrows``.

    Raises
    ------
    StringStabError
        If ``region`` is not a k_x–k_v slice with the exact verdicts, or neither it nor the
        parameters are given.
    """
    if region is None:
        if tau is None or delta is None or headway is None:
            raise StringStabError("plot_moves needs region= (a RegionMap) or tau, delta and headway")
        region = moves_region(results, tau=tau, delta=delta, headway=headway, k_a=k_a,
                              bounds=bounds, n=n)
    if region.axis_names != ("k_x", "k_v") or "exact" not in region.methods:
        raise StringStabError(
            f"plot_moves draws over a k_x-k_v slice with the exact verdicts; got axes "
            f"{list(region.axis_names)} and methods {list(region.methods)}")
    if ax is None:
        _, ax = pyplot().subplots(figsize=(6, 5))
    KX, KV, _ = region.gains()
    k_a_fixed = region.fixed["k_a"]
    mesh = ax.pcolormesh(KX, KV, region.stable("exact").astype(float), cmap="Greens",
                         vmin=0.0, vmax=1.6, shading="auto")
    colours = {"region-growing": "tab:orange", "projection": "tab:blue"}
    arrows = []
    labelled: set[str] = set()
    for r in results:
        c = colours.get(r.method, "k")
        x0, y0, x1, y1 = r.k_in[0], r.k_in[1], r.k[0], r.k[1]
        ax.plot([x0], [y0], "o", color="k", ms=3)
        label = None if r.method in labelled else r.method
        labelled.add(r.method)
        arrows.append(ax.annotate("", xy=(x1, y1), xytext=(x0, y0),
                                  arrowprops={"arrowstyle": "->", "color": c, "lw": 1.4}))
        ax.plot([x1], [y1], "s" if r.certified else "x", color=c, ms=4, label=label)
        ax.text(x1, y1, f" {r.k[2]:.2f}", fontsize=7, color=c)
    ax.set_xlabel("k_x")
    ax.set_ylabel("k_v")
    ax.set_title(f"repairs K0 → K over the certified region (shaded) at k_a = {k_a_fixed:g}\n"
                 "arrows projected on (k_x, k_v); label: output k_a; ■ certified, × not",
                 fontsize=9)
    ax.legend(loc="lower right", fontsize=8)
    return PlotResult.of({"ax": ax, "region": mesh, "arrows": arrows})
