"""Figures of a 3-D stability-region map: a montage of 2-D slices, and the region in 3-D.

=========================  ===================================================
function                   shows
=========================  ===================================================
:func:`plot_slices`        a 3-D map as a montage of slices over one gain
:func:`plot_region_3d`     the boundary of the certified region in 3-D
=========================  ===================================================
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import StringStabError
from ..regions import RegionMap
from ._common import CLASS_COLORS, GAIN_LABELS, OKABE_ITO, PlotResult, patch, pyplot
from .map_axes import method_title
from .regions import plot_class_map

__all__ = ["plot_region_3d", "plot_slices"]


def plot_slices(
    rmap: RegionMap, method: str = "exact", *, gain: str | None = None, n: int = 9,
    fig: Any = None, ncols: int | None = None,
) -> PlotResult:
    """A 3-D map as a montage of 2-D class maps over one gain.

    Parameters
    ----------
    rmap : RegionMap
        A 3-D map.
    method : {"exact", "taylor", "printed"}
        Whose classes to show.
    gain : str, optional
        The gain to slice along; default the map's last axis.
    n : int
        Number of slices, evenly spaced over that gain's grid (at most its size).
    fig : matplotlib Figure, optional
        Where to draw; a new figure when None.
    ncols : int, optional
        Panels per row; default ⌈√n⌉.

    Returns
    -------
    PlotResult
        ``fig``, ``axes`` (list), ``images`` (list), ``values`` (the slice
        coordinates) and ``legend``.

    Raises
    ------
    StringStabError
        If ``rmap`` is not 3-D, ``gain`` is not an axis or ``n < 1``.
    """
    if rmap.ndim != 3:
        raise StringStabError(f"plot_slices needs a 3-D map; got a {rmap.ndim}-D map")
    gain = gain or rmap.axis_names[-1]
    if gain not in rmap.axes:
        raise StringStabError(f"gain must be one of {list(rmap.axes)}; got {gain!r}")
    if n < 1:
        raise StringStabError(f"n must be >= 1 slices; got {n}")
    coords = rmap.axes[gain]
    idx = np.unique(np.round(np.linspace(0, coords.size - 1, min(n, coords.size))).astype(int))
    ncols = ncols or int(np.ceil(np.sqrt(idx.size)))
    nrows = int(np.ceil(idx.size / ncols))
    if fig is None:
        fig = pyplot().figure(figsize=(2.5 * ncols + 2.6, 2.4 * nrows + 0.7), layout="constrained")
    axs = fig.subplots(nrows, ncols, sharex=True, sharey=True, squeeze=False).ravel()
    images, used = [], []
    handles: list[Any] = []
    for k, ax in zip(idx, axs):
        sl = rmap.slice(gain, float(coords[k]))
        out = plot_class_map(sl, method, ax=ax, legend=False, title=False)
        images.append(out["image"])
        used.append(ax)
        handles = out["handles"]
        share = sl.stable(method).mean()
        word = "certified" if method == "exact" else "stable"
        ax.set_title(f"{gain} = {coords[k]:.3g}: {100 * share:.1f} % {word}", fontsize="small")
        ax.label_outer()
    for ax in axs[idx.size:]:
        ax.set_visible(False)
    names = rmap.class_names(method)
    handles = [patch(CLASS_COLORS[c], c) for c in names]
    leg = fig.legend(handles=handles, loc="outside right upper", frameon=False, fontsize="small")
    fig.suptitle(f"{method_title(rmap, method)}, slices over {gain}\n{rmap.title()}",
                 fontsize="medium")
    return PlotResult.of({"fig": fig, "axes": used, "images": images, "values": coords[idx], "legend": leg})


def _corner_ticks(ax: Any, a0: Any, a1: Any, a2: Any) -> None:
    """Set at most 5 plain-number ticks per axis, one label at the corner the first two share.

    At the view drawn (azimuth −125°) the smallest values of the first two axes meet at one
    corner, so the second axis leaves its smallest label out there (the two would print
    "−2.0−2.0").
    """
    from matplotlib.ticker import FuncFormatter, MaxNLocator

    for k, (axis, a) in enumerate(((ax.xaxis, a0), (ax.yaxis, a1), (ax.zaxis, a2))):
        lo, hi = float(a[0]), float(a[-1])
        ticks = np.asarray(MaxNLocator(4, steps=[1, 2, 5, 10]).tick_values(lo, hi), dtype=float)
        span = 1e-9 * max(abs(lo), abs(hi), 1.0)
        ticks = ticks[(ticks >= lo - span) & (ticks <= hi + span)]
        if k == 1:
            ticks = ticks[ticks > lo + span]
        axis.set_ticks(ticks)
        axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}".replace("-", "−")))


def plot_region_3d(
    rmap: RegionMap, method: str = "exact", *, ax: Any = None, kind: str = "surface",
    max_points: int = 40_000, title: bool = True,
) -> PlotResult:
    """The string-stable region of a 3-D map, drawn in 3-D.

    ``kind="surface"`` (default): for every grid point of the first two axis
    gains, the lowest and the highest value of the third (the map's last axis)
    at which the method says string stable; the two surfaces enclose the
    region, and are its exact boundary where the stable set of each such
    column is one interval (``n_gapped`` counts the columns where it is not).
    ``kind="points"``: every stable grid point with a neighbour that is not
    (the boundary voxels), coloured by the third gain, thinned evenly to
    ``max_points``.

    Parameters
    ----------
    rmap : RegionMap
        A 3-D map.
    method : {"exact", "taylor", "printed"}
        Whose verdict defines the region.
    ax : mpl_toolkits.mplot3d Axes3D, optional
        A 3-D axes; a new figure when None.
    kind : {"surface", "points"}
        What to draw.
    max_points : int
        With ``kind="points"``, at most this many points are drawn.
    title : bool
        Draw the title.

    Returns
    -------
    PlotResult
        ``ax``, ``artists`` (the surfaces or the scatter; empty when the region
        is empty), ``n_gapped`` (surface) or ``n_boundary`` (points), and
        ``legend`` or ``colorbar``.

    Raises
    ------
    StringStabError
        If ``rmap`` is not 3-D or ``kind`` is unknown.
    """
    if rmap.ndim != 3:
        raise StringStabError(f"plot_region_3d needs a 3-D map; got a {rmap.ndim}-D map")
    if kind not in ("surface", "points"):
        raise StringStabError(f"kind must be 'surface' or 'points'; got {kind!r}")
    st = rmap.stable(method)
    if ax is None:
        fig = pyplot().figure(figsize=(7.2, 6.4), layout="constrained")
        ax = fig.add_subplot(projection="3d")
    names = rmap.axis_names
    a0, a1, a2 = rmap.axes.values()
    out: dict[str, Any] = {"ax": ax, "artists": []}
    if kind == "surface":
        from matplotlib.patches import Patch

        anyst = st.any(axis=2)
        lo_i = np.argmax(st, axis=2)
        hi_i = a2.size - 1 - np.argmax(st[:, :, ::-1], axis=2)
        lower = np.where(anyst, a2[lo_i], np.nan)
        upper = np.where(anyst, a2[hi_i], np.nan)
        n_gapped = int(np.count_nonzero(anyst & (st.sum(axis=2) < hi_i - lo_i + 1)))
        X, Y = np.meshgrid(a0, a1, indexing="ij")
        stride = max(1, int(np.ceil(max(a0.size, a1.size) / 80)))
        handles = []
        if anyst.any():
            for Z, col, lab in ((lower, OKABE_ITO["blue"], f"lowest {names[2]}"),
                                (upper, OKABE_ITO["orange"], f"highest {names[2]}")):
                surf = ax.plot_surface(X, Y, np.ma.masked_invalid(Z), color=col, rstride=stride,
                                       cstride=stride, linewidth=0.15, edgecolor="#333333",
                                       alpha=0.85, shade=True)
                out["artists"].append(surf)
                handles.append(Patch(facecolor=col, edgecolor="#333333", label=lab))
        out["n_gapped"] = n_gapped
        out["legend"] = ax.legend(handles=handles, loc="upper left", fontsize="small",
                                  title=f"{'certified' if method == 'exact' else 'stable'} {names[2]} "
                                        f"range over ({names[0]}, {names[1]})",
                                  title_fontsize="small") if handles else None
    else:
        pad = np.pad(st, 1, mode="constant", constant_values=False)
        inner = np.ones_like(st)
        for axis in range(3):
            for shift in (-1, 1):
                inner &= np.roll(pad, shift, axis=axis)[1:-1, 1:-1, 1:-1]
        i, j, k = np.nonzero(st & ~inner)
        nb = i.size
        if nb > max_points:
            keep = np.linspace(0, nb - 1, max_points).astype(int)
            i, j, k = i[keep], j[keep], k[keep]
        out["n_boundary"] = int(nb)
        out["colorbar"] = None
        if nb:
            sc = ax.scatter(a0[i], a1[j], a2[k], c=a2[k], cmap="cividis", s=6, depthshade=False,
                            linewidths=0)
            out["artists"].append(sc)
            out["colorbar"] = ax.figure.colorbar(sc, ax=ax, shrink=0.6, pad=0.1,
                                                 label=GAIN_LABELS[names[2]])
    for setter, a in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), (a0, a1, a2)):
        setter(a[0], a[-1])
    _corner_ticks(ax, a0, a1, a2)
    ax.set_xlabel(GAIN_LABELS[names[0]])
    ax.set_ylabel(GAIN_LABELS[names[1]])
    ax.set_zlabel(GAIN_LABELS[names[2]])
    ax.view_init(elev=22, azim=-125)
    if title:
        what = "certified" if method == "exact" else f"{method}-stable"
        ax.set_title(f"the {what} region ({100 * st.mean():.1f} % of the box)\n{rmap.title()}",
                     fontsize="medium")
    return PlotResult.of(out)
