"""Gains drawn over the certified region when they do not share one slice.

A policy's gains (k_x, k_v, k_a) move in all three gains; drawn in the (k_x, k_v) plane over the
slice at one k_a, a point certified at its own k_a can sit in the slice's uncertified area.
:func:`projected_region` computes instead, on the plane's grid, the share of the points' own
third-gain values at which each (k_x, k_v) is certified (exact certificate), and
:func:`plot_projected_region` draws it as three classes — certified at *every* one of those
values, at *some*, at *none* — so each point lies where its own verdict says: a point certified
at its own k_a is in "every" or "some", an uncertified one in "some" or "none" (up to the grid's
resolution).  The values are the points' own when there are at most ``max_values`` distinct ones
(the picture is then exact for every point), else that many quantiles (the title says so).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ._common import GAIN_LABELS, OKABE_ITO, PlotResult, legend_below, new_ax, patch

__all__ = ["ProjectedRegion", "plot_projected_region", "projected_region"]

_GAINS = ("k_x", "k_v", "k_a")


@dataclass(frozen=True)
class ProjectedRegion:
    """The share of sampled third-gain values at which each plane point is certified.

    Attributes
    ----------
    axes : dict
        The two plane gains and their grids.
    third : str
        The gain projected out.
    values : ndarray
        The third-gain values evaluated.
    n_distinct : int
        Distinct third-gain values among the points (``values`` are all of them when equal to
        ``len(values)``).
    share : ndarray (nx, ny)
        Fraction of ``values`` at which the point is certified.
    """

    axes: dict[str, npt.NDArray[np.float64]]
    third: str
    values: npt.NDArray[np.float64]
    n_distinct: int
    share: npt.NDArray[np.float64]

    @property
    def exact_for_points(self) -> bool:
        """True when every point's own third-gain value was evaluated."""
        return self.n_distinct == len(self.values)


def projected_region(K: npt.ArrayLike, *, tau: Any, delta: Any, headway: Any,
                     plane: tuple[str, str] = ("k_x", "k_v"),
                     bounds: tuple[float, float] | None = None, n: int = 121,
                     max_values: int = 48, sample_time: float | None = None) -> ProjectedRegion:
    """Compute the projection of the certified region over the points' third-gain values.

    Parameters
    ----------
    K : array_like (m, 3)
        The points' gains k_x, k_v, k_a.
    tau, delta, headway : float or (lo, hi)
        The loop's parameters (numbers, or intervals for a box), as for
        :func:`stringstab.regions.region_map`.
    plane : (str, str)
        The two gains of the picture.
    bounds : (lo, hi), optional
        Range of both plane axes (default: the points' range and [-2, 2], padded by 5 %, so
        points on the k = ±2 bound are not clipped).
    n : int
        Grid points per plane axis.
    max_values : int
        Largest number of third-gain values evaluated.
    sample_time : float, optional
        The sampled-data loop's period (None: continuous time).

    Returns
    -------
    ProjectedRegion
        The grid and the certified share at each plane point.
    """
    from ..regions import region_map

    Karr = np.asarray(K, dtype=np.float64).reshape(-1, 3)
    third = next(g for g in _GAINS if g not in plane)
    col = _GAINS.index(third)
    distinct = np.unique(Karr[:, col]) if Karr.size else np.array([0.0])
    values = distinct if distinct.size <= max_values else np.unique(
        np.quantile(Karr[:, col], np.linspace(0.0, 1.0, max_values)))
    if bounds is None:
        xy = Karr[:, [_GAINS.index(plane[0]), _GAINS.index(plane[1])]]
        lo = min(-2.0, float(xy.min())) if xy.size else -2.0
        hi = max(2.0, float(xy.max())) if xy.size else 2.0
        pad = 0.05 * (hi - lo)
        bounds = (lo - pad, hi + pad)
    g = np.linspace(bounds[0], bounds[1], n)
    axes = {plane[0]: g, plane[1]: g, third: values}
    if values.size == 1:  # a 2-D slice: region_map wants a fixed value for one gain
        rmap = region_map({plane[0]: g, plane[1]: g}, {third: float(values[0])}, tau=tau,
                          delta=delta, headway=headway, methods="exact", sample_time=sample_time,
                          workers=1, progress=False)
        share = rmap.stable("exact").astype(float)
    else:
        rmap = region_map(axes, None, tau=tau, delta=delta, headway=headway, methods="exact",
                          sample_time=sample_time, workers=1, progress=False)
        order = list(rmap.axis_names)
        st = np.moveaxis(rmap.stable("exact"), order.index(third), -1)
        if order.index(plane[0]) > order.index(plane[1]):
            st = np.swapaxes(st, 0, 1)
        share = st.mean(axis=-1)
    return ProjectedRegion({plane[0]: g, plane[1]: g}, third, values, int(distinct.size), share)


#: Colours of the three classes of the projection.
PROJECTION_COLORS = {"every": OKABE_ITO["blue"], "some": OKABE_ITO["sky"], "none": "#D9D9D9"}


def plot_projected_region(proj: ProjectedRegion, *, ax: Any = None, legend: bool = True,
                          title: str | None = None) -> PlotResult:
    """Draw a :class:`ProjectedRegion` as three classes (certified at every / some / no value).

    Parameters
    ----------
    proj : ProjectedRegion
        The computed projection.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).
    legend : bool
        Put the classes in a legend under the axes.
    title : str, optional
        A first title line (the second says which values were projected).

    Returns
    -------
    PlotResult
        ``ax``, ``image``, ``handles`` (the classes' patches) and ``legend``.
    """
    from ._common import categorical

    ax = new_ax(ax)
    (xn, x), (yn, y) = proj.axes.items()
    codes = np.where(proj.share >= 1.0, 2, np.where(proj.share > 0.0, 1, 0))
    colors = [PROJECTION_COLORS["none"], PROJECTION_COLORS["some"], PROJECTION_COLORS["every"]]
    cmap, norm = categorical(colors)
    dx, dy = (x[1] - x[0]) / 2, (y[1] - y[0]) / 2
    im = ax.imshow(codes.T, origin="lower", extent=(x[0] - dx, x[-1] + dx, y[0] - dy, y[-1] + dy),
                   aspect="auto", interpolation="nearest", cmap=cmap, norm=norm)
    ax.set_xlabel(GAIN_LABELS[xn])
    ax.set_ylabel(GAIN_LABELS[yn])
    ax.set_box_aspect(1.0)
    v = proj.values
    sym = proj.third
    rng = f"{sym} = {v[0]:.3g}" if v.size == 1 else f"{sym} in [{v[0]:.3g}, {v[-1]:.3g}]"
    how = (f"the points' own {v.size} value(s) of {sym}" if proj.exact_for_points
           else f"{v.size} quantiles of the points' {proj.n_distinct} values of {sym}")
    names = [f"certified at no {sym} evaluated", f"certified at some {sym}",
             f"certified at every {sym} evaluated"]
    handles = [patch(c, t) for c, t in zip(colors, names)]
    leg = legend_below(ax, handles, title=f"background: exact certificate over {rng}",
                       ncol=1) if legend else None
    head = f"{title}\n" if title else ""
    ax.set_title(f"{head}background projected over {how}", fontsize="medium")
    return PlotResult.of({"ax": ax, "image": im, "handles": handles, "legend": leg})
