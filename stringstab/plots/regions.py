"""Figures of one 2-D stability-region map (:mod:`stringstab.regions`): classes, agreement, sup|Γ|.

Every function takes a :class:`~stringstab.regions.RegionMap` computed beforehand and
``ax=None`` (or ``axes=None`` / ``fig=None`` for multi-panel figures), draws into it or
into a new figure, and returns a :class:`~stringstab.plots.PlotResult` (``result["ax"]``
and the artists: ``"image"``, ``"legend"``, ``"contour"``, ...), so figures can be composed
and tested.

Colours are the Okabe-Ito palette (safe for the common colour-vision
deficiencies); marker shapes repeat the information of marker colours.

=========================  ===================================================
function                   shows
=========================  ===================================================
:func:`plot_class_map`     classes of one method (types, or exact verdicts)
:func:`plot_comparison`    where exact, taylor and printed agree and disagree
:func:`plot_sup_gain`      sup_ω |Γ(jω)| (log scale), with the certified boundary
=========================  ===================================================

3-D maps are drawn by :mod:`~stringstab.plots.regions_3d`, several maps by
:mod:`~stringstab.plots.region_sets`, a gain trajectory over a map by
:mod:`~stringstab.plots.trajectory`, and the standard figure files of a map by
:mod:`~stringstab.plots.outputs`.

References
----------
M. Okabe and K. Ito, "Color Universal Design (CUD)", 2008,
https://jfly.uni-koeln.de/color/.
"""


from __future__ import annotations

from collections.abc import Sequence
from itertools import product
from typing import Any

import numpy as np

from ..errors import StringStabError
from ..regions import CONTINUOUS, METHODS, RegionMap
from ._common import (
    CLASS_COLORS,
    OKABE_ITO,
    PlotResult,
    categorical,
    legend_below,
    log_colorbar_ticks,
    new_ax,
    patch,
    pct,
)
from .map_axes import draw_field, gain_symbol, label_axes, method_label, method_title, need_2d

__all__ = ["plot_class_map", "plot_comparison", "plot_sup_gain"]

_AGREE_STABLE = "#BFE1F5"  # light tint of sky blue
_AGREE_UNSTABLE = "#E4E4E4"
_UNSAFE = [OKABE_ITO["vermillion"], OKABE_ITO["purple"], OKABE_ITO["orange"]]
_CONSERVATIVE = [OKABE_ITO["blue"], OKABE_ITO["green"], OKABE_ITO["yellow"]]


# --------------------------------------------------------------------------- class map
def plot_class_map(
    rmap: RegionMap, method: str = "exact", *, ax: Any = None, legend: bool = True,
    title: bool = True,
) -> PlotResult:
    """Draw a 2-D map coloured by the classes of one method.

    ``exact``: not internally stable / not certified / inconclusive /
    certified.  ``taylor``, ``printed``: not internally stable / type III /
    type IV / type I / type II of that method's Ψ (IDL §3.3); see
    :meth:`stringstab.regions.RegionMap.classes`.

    Parameters
    ----------
    rmap : RegionMap
        A 2-D map.
    method : {"exact", "taylor", "printed"}
        Whose classes to show (must be in ``rmap.methods``).
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    legend, title : bool
        Draw the legend (classes with their shares, right of the axes) and the title.

    Returns
    -------
    PlotResult
        ``ax``, ``image`` (the AxesImage or QuadMesh), ``legend`` (or None) and
        ``handles`` (one legend patch per class).

    Raises
    ------
    StringStabError
        If ``rmap`` is not 2-D or ``method`` was not evaluated.

    Examples
    --------
    >>> from stringstab.regions import region_map
    >>> m = region_map({"k_x": np.linspace(-2, 2, 21), "k_v": np.linspace(-2, 2, 21)},
    ...                {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1, methods="taylor")
    >>> out = plot_class_map(m, "taylor")
    >>> out.keys()
    ['fig', 'axes', 'ax', 'image', 'legend', 'handles']
    >>> out.ax is out["ax"] and out.legend is out["legend"]
    True
    >>> import matplotlib.pyplot as plt; plt.close("all")
    """
    need_2d(rmap, "plot_class_map")
    names = rmap.class_names(method)
    ax = new_ax(ax)
    codes = rmap.classes(method)
    colors = [CLASS_COLORS[n] for n in names]
    cmap, norm = categorical(colors)
    im = draw_field(ax, rmap, codes, cmap=cmap, norm=norm)
    label_axes(ax, rmap)
    counts = np.bincount(codes.ravel(), minlength=len(names))
    handles = [patch(c, f"{n} ({pct(k, rmap.size)})") for n, c, k in zip(names, colors, counts)]
    leg = legend_below(ax, handles, title=f"{rmap.size:,} grid points") if legend else None
    if title:
        ax.set_title(f"{method_title(rmap, method)}\n{rmap.title()}", fontsize="medium")
    return PlotResult.of({"ax": ax, "image": im, "legend": leg, "handles": handles})


# --------------------------------------------------------------------------- comparison
def _comparison_codes(
    rmap: RegionMap, methods: Sequence[str]
) -> tuple[np.ndarray, list[str], list[str], list[bool]]:
    """Category per point, with labels, colours and whether each is a disagreement."""
    short = {m: method_label(rmap, m) for m in methods}
    stable = [rmap.stable(m) for m in methods]
    inc = np.zeros(rmap.shape, dtype=bool)
    for m in methods:
        inc |= rmap.verdict[m] == 2
    labels = [f"all {len(methods)} say string stable" if len(methods) > 2 else "both say string stable",
              f"all {len(methods)} say not string stable" if len(methods) > 2 else "both say not string stable"]
    colors = [_AGREE_STABLE, _AGREE_UNSTABLE]
    disagree = [False, False]
    codes = np.full(rmap.shape, -1, dtype=np.int8)
    codes[np.logical_and.reduce(stable)] = 0
    codes[np.logical_and.reduce([~s for s in stable])] = 1
    n_unsafe = n_cons = 0
    # reference (first method) says not stable but another says stable: unsafe first
    for ref in (False, True):
        for rest in product((True, False) if not ref else (False, True), repeat=len(methods) - 1):
            if all(r == ref for r in rest):
                continue
            pattern = (ref, *rest)
            mask = np.ones(rmap.shape, dtype=bool)
            for s, want in zip(stable, pattern):
                mask &= s if want else ~s
            codes[mask] = len(labels)
            labels.append(" · ".join(f"{short[m]} {'✓' if w else '✗'}" for m, w in zip(methods, pattern)))
            if ref:
                colors.append(_CONSERVATIVE[n_cons % 3])
                n_cons += 1
            else:
                colors.append(_UNSAFE[n_unsafe % 3])
                n_unsafe += 1
            disagree.append(True)
    codes[inc] = len(labels)
    labels.append("a certificate inconclusive" if CONTINUOUS in methods else "exact inconclusive")
    colors.append(CLASS_COLORS["inconclusive"])
    disagree.append(False)
    return codes, labels, colors, disagree


def plot_comparison(
    rmap: RegionMap, methods: Sequence[str] | None = None, *, ax: Any = None,
    legend: bool = True, title: bool = True,
) -> PlotResult:
    """Draw where methods agree and disagree on string stability, counting each case.

    Each point is coloured by the pattern of verdicts (✓ = says string stable:
    exact certified, or Hurwitz and Proposition 1).  Agreement is drawn in
    light tints; each disagreement pattern in a strong colour: warm colours
    where the first method (the reference, normally ``exact``) says *not*
    stable but another says stable (unsafe), cool colours the reverse
    (conservative).  The legend gives the count of points of every pattern
    present and the number of disagreeing points in its title.

    Parameters
    ----------
    rmap : RegionMap
        A 2-D map.
    methods : sequence of str, optional
        Two or three evaluated methods, reference first; default all of the map's
        methods in the order exact, taylor, printed.
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    legend, title : bool
        Draw the legend and the title.

    Returns
    -------
    PlotResult
        ``ax``, ``image``, ``legend``, ``counts`` (label → number of points)
        and ``disagreements`` (total number of disagreeing points).

    Raises
    ------
    StringStabError
        If ``rmap`` is not 2-D or fewer than two evaluated methods are given.
    """
    need_2d(rmap, "plot_comparison")
    ms = ([m for m in (*METHODS, CONTINUOUS) if m in rmap.methods] if methods is None
          else list(methods))
    if len(ms) < 2 or len(set(ms)) != len(ms):
        raise StringStabError(f"plot_comparison needs 2 or 3 distinct evaluated methods; got {ms}")
    for m in ms:
        if m not in rmap.methods:
            raise StringStabError(f"method {m!r} was not evaluated in this map (methods {list(rmap.methods)})")
    ax = new_ax(ax)
    codes, labels, colors, disagree = _comparison_codes(rmap, ms)
    cmap, norm = categorical(colors)
    im = draw_field(ax, rmap, codes, cmap=cmap, norm=norm)
    label_axes(ax, rmap)
    counts_arr = np.bincount(codes.ravel(), minlength=len(labels))
    counts = {lab: int(c) for lab, c in zip(labels, counts_arr)}
    n_dis = int(sum(c for c, d in zip(counts_arr, disagree) if d))
    handles = [
        patch(col, f"{lab} (n = {c:,})")
        for lab, col, c, d in zip(labels, colors, counts_arr, disagree)
        if c > 0 or not d
    ]
    leg = legend_below(ax, handles, title=f"disagreements: {n_dis:,} of {rmap.size:,} points") if legend else None
    if title:
        ax.set_title(f"{' vs '.join(method_label(rmap, m) for m in ms)}: where the verdicts differ\n"
                     f"{rmap.title()}", fontsize="medium")
    return PlotResult.of({"ax": ax, "image": im, "legend": leg, "counts": counts, "disagreements": n_dis})


# --------------------------------------------------------------------------- sup gain
def plot_sup_gain(
    rmap: RegionMap, *, ax: Any = None, vmax: float | None = None, colorbar: bool = True,
    title: bool = True, cmap: str = "cividis",
) -> PlotResult:
    """Heat map of ‖Γ‖_{H∞} = sup_ω |Γ(jω)| on a log colour scale, with the ≤ 1 boundary.

    Points where Γ is not internally stable (‖Γ‖∞ = ∞) are drawn in light
    grey.  The boundary of the certified region (sup|Γ| ≤ 1) is drawn as a
    solid line; certified points have sup|Γ| = |Γ(0)| = 1 exactly, the bottom
    of the colour scale.

    Parameters
    ----------
    rmap : RegionMap
        A 2-D map evaluated with ``exact``.
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    vmax : float, optional
        Top of the colour scale (larger values saturate); default the 99th
        percentile of the finite values, at least 1.1.
    colorbar, title : bool
        Draw the colour bar and the title.
    cmap : str
        A perceptually uniform matplotlib colour map.

    Returns
    -------
    PlotResult
        ``ax``, ``image``, ``contour`` (the boundary, or None when the region
        is empty or everything), ``colorbar`` and ``legend``.

    Raises
    ------
    StringStabError
        If ``rmap`` is not 2-D or has no exact verdicts.
    """
    need_2d(rmap, "plot_sup_gain")
    if rmap.sup_gain is None:
        raise StringStabError(f"plot_sup_gain needs a map evaluated with 'exact'; got methods {list(rmap.methods)}")
    import matplotlib as mpl
    from matplotlib.colors import LogNorm
    from matplotlib.lines import Line2D

    ax = new_ax(ax)
    sup = np.asarray(rmap.sup_gain, dtype=float)
    finite = np.isfinite(sup)
    if vmax is None:
        vmax = float(np.percentile(sup[finite], 99)) if finite.any() else 10.0
        vmax = max(vmax, 1.1)
    text, tex = gain_symbol(rmap)
    cm = mpl.colormaps[cmap].with_extremes(bad="#E4E4E4")
    im = draw_field(ax, rmap, np.ma.masked_invalid(np.where(finite, sup, np.nan)),
                     cmap=cm, norm=LogNorm(vmin=1.0, vmax=vmax))
    cert = rmap.stable("exact").astype(float)
    contour = None
    handles = [patch("#E4E4E4", f"not internally stable (‖{'H' if rmap.sample_time else 'Γ'}‖∞ = ∞)")]
    if 0 < cert.sum() < cert.size:
        x, y = rmap.axes.values()
        contour = ax.contour(x, y, cert.T, levels=[0.5], colors=[OKABE_ITO["vermillion"]], linewidths=1.6)
        handles.append(Line2D([], [], color=OKABE_ITO["vermillion"], lw=1.6,
                              label=f"boundary of {text} ≤ 1 (certified, {pct(int(cert.sum()), cert.size)})"))
    leg = legend_below(ax, handles, ncol=1)
    cb = None
    if colorbar:
        # in an inset beside the axes: exactly the axes' height (a layout colorbar spans the
        # whole figure cell, taller than the square axes)
        cax = ax.inset_axes((1.04, 0.0, 0.045, 1.0))
        cb = ax.figure.colorbar(im, cax=cax, extend="max")
        log_colorbar_ticks(cb)
        cb.set_label(tex)
    label_axes(ax, rmap)
    if title:
        at = " at the witness member" if rmap.is_box else ""
        ax.set_title(f"{text}{at} (exact delay)\n{rmap.title()}", fontsize="medium")
    return PlotResult.of({"ax": ax, "image": im, "contour": contour, "colorbar": cb, "legend": leg})
