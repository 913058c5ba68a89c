"""Figures of stability-region maps (:mod:`stringstab.regions`), with matplotlib.

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
:func:`plot_slices`        a 3-D map as a montage of slices over one gain
:func:`plot_region_3d`     the boundary of the certified region in 3-D
:func:`plot_facets`        one class map per τ (or δ): how the region shrinks
:func:`plot_boundaries`    the certified boundaries of several maps on one axes
:func:`plot_trajectory`    a policy's gain trajectory over a map, by verdict
=========================  ===================================================

References
----------
M. Okabe and K. Ito, "Color Universal Design (CUD)", 2008,
https://jfly.uni-koeln.de/color/.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from itertools import product
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..regions import CONTINUOUS, METHODS, RegionMap
from ._common import (
    CLASS_COLORS,
    GAIN_LABELS,
    OKABE_ITO,
    PlotResult,
    categorical,
    legend_below,
    new_ax,
    patch,
    pct,
    pyplot,
)

__all__ = [
    "FIGURE_FORMATS",
    "draw_figure",
    "figure_stems",
    "plot_boundaries",
    "plot_class_map",
    "plot_comparison",
    "plot_facets",
    "plot_region_3d",
    "plot_slices",
    "plot_sup_gain",
    "plot_trajectory",
    "save_figures",
    "trajectory_verdicts",
]

FIGURE_FORMATS: tuple[str, ...] = ("png", "pdf", "svg")
_METHOD_TITLES = {
    "exact": "exact certificate",
    "taylor": "Taylor Prop. 1 (derived Ψ) types",
    "printed": "Taylor Prop. 1 (printed Ψ) types",
    CONTINUOUS: "continuous-time certificate",
}
_AGREE_STABLE = "#BFE1F5"  # light tint of sky blue
_AGREE_UNSTABLE = "#E4E4E4"
_UNSAFE = [OKABE_ITO["vermillion"], OKABE_ITO["purple"], OKABE_ITO["orange"]]
_CONSERVATIVE = [OKABE_ITO["blue"], OKABE_ITO["green"], OKABE_ITO["yellow"]]
_VERDICT_MARKERS = {
    "certified": dict(marker="o", facecolor="white", edgecolor="black"),
    "not_certified": dict(marker="X", facecolor="black", edgecolor="white"),
    "inconclusive": dict(marker="D", facecolor=OKABE_ITO["yellow"], edgecolor="black"),
}


# --------------------------------------------------------------------------- helpers
def _method_title(rmap: RegionMap, method: str) -> str:
    """The title of ``method``'s classes: ``exact`` names the loop it certifies."""
    if method == "exact" and (rmap.sample_time is not None or rmap.is_box):
        return f"certificate of the {rmap.loop} loop"
    return _METHOD_TITLES[method]


def _short(rmap: RegionMap, method: str) -> str:
    """A method's name in a comparison legend (``exact`` is ``sampled`` on a sampled map)."""
    if method == "exact" and rmap.sample_time is not None:
        return "sampled"
    if method == "exact" and rmap.is_box:
        return "robust"
    return method


def _gain_symbol(rmap: RegionMap) -> tuple[str, str]:
    """(text, LaTeX) of the supremum the sup-gain map shows."""
    if rmap.sample_time is not None:
        return "sup|H(e^{jθ})|", r"$\sup_\theta |H(e^{j\theta})|$"
    return "sup|Γ(jω)|", r"$\sup_\omega |\Gamma(j\omega)|$"


def _need_2d(rmap: RegionMap, what: str) -> None:
    if not isinstance(rmap, RegionMap):
        raise StringStabError(f"{what} needs a RegionMap; got {type(rmap).__name__}")
    if rmap.ndim != 2:
        raise StringStabError(
            f"{what} draws a 2-D map; got a {rmap.ndim}-D map (use RegionMap.slice or plot_slices)"
        )


def _uniform(a: npt.NDArray[np.float64]) -> bool:
    d = np.diff(a)
    return bool(np.allclose(d, d[0], rtol=1e-6, atol=0.0))


def _draw_field(ax: Any, rmap: RegionMap, values: np.ndarray, **kw: Any) -> Any:
    """Draw a 2-D field over the map's axes (imshow on a uniform grid, else pcolormesh)."""
    x, y = rmap.axes.values()
    if _uniform(x) and _uniform(y):
        dx, dy = (x[1] - x[0]) / 2, (y[1] - y[0]) / 2
        return ax.imshow(
            np.asarray(values).T, origin="lower", extent=(x[0] - dx, x[-1] + dx, y[0] - dy, y[-1] + dy),
            aspect="auto", interpolation="nearest", **kw,
        )
    return ax.pcolormesh(x, y, np.asarray(values).T, shading="nearest", **kw)


def _label_axes(ax: Any, rmap: RegionMap) -> None:
    xn, yn = rmap.axis_names
    ax.set_xlabel(GAIN_LABELS[xn])
    ax.set_ylabel(GAIN_LABELS[yn])
    ax.set_box_aspect(1.0)


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
    _need_2d(rmap, "plot_class_map")
    names = rmap.class_names(method)
    ax = new_ax(ax)
    codes = rmap.classes(method)
    colors = [CLASS_COLORS[n] for n in names]
    cmap, norm = categorical(colors)
    im = _draw_field(ax, rmap, codes, cmap=cmap, norm=norm)
    _label_axes(ax, rmap)
    counts = np.bincount(codes.ravel(), minlength=len(names))
    handles = [patch(c, f"{n} ({pct(k, rmap.size)})") for n, c, k in zip(names, colors, counts)]
    leg = legend_below(ax, handles, title=f"{rmap.size:,} grid points") if legend else None
    if title:
        ax.set_title(f"{_method_title(rmap, method)}\n{rmap.title()}", fontsize="medium")
    return PlotResult.of({"ax": ax, "image": im, "legend": leg, "handles": handles})


# --------------------------------------------------------------------------- comparison
def _comparison_codes(
    rmap: RegionMap, methods: Sequence[str]
) -> tuple[np.ndarray, list[str], list[str], list[bool]]:
    """Category per point, with labels, colours and whether each is a disagreement."""
    short = {m: _short(rmap, m) for m in methods}
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
    _need_2d(rmap, "plot_comparison")
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
    im = _draw_field(ax, rmap, codes, cmap=cmap, norm=norm)
    _label_axes(ax, rmap)
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
        ax.set_title(f"{' vs '.join(_short(rmap, m) for m in ms)}: where the verdicts differ\n"
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
    _need_2d(rmap, "plot_sup_gain")
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
    text, tex = _gain_symbol(rmap)
    cm = mpl.colormaps[cmap].with_extremes(bad="#E4E4E4")
    im = _draw_field(ax, rmap, np.ma.masked_invalid(np.where(finite, sup, np.nan)),
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
        cb.set_label(tex)
    _label_axes(ax, rmap)
    if title:
        at = " at the witness member" if rmap.is_box else ""
        ax.set_title(f"{text}{at} (exact delay)\n{rmap.title()}", fontsize="medium")
    return PlotResult.of({"ax": ax, "image": im, "contour": contour, "colorbar": cb, "legend": leg})


# --------------------------------------------------------------------------- 3-D
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
    fig.suptitle(f"{_method_title(rmap, method)}, slices over {gain}\n{rmap.title()}",
                 fontsize="medium")
    return PlotResult.of({"fig": fig, "axes": used, "images": images, "values": coords[idx], "legend": leg})


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
    ax.set_xlabel(GAIN_LABELS[names[0]])
    ax.set_ylabel(GAIN_LABELS[names[1]])
    ax.set_zlabel(GAIN_LABELS[names[2]])
    ax.view_init(elev=22, azim=-125)
    if title:
        what = "certified" if method == "exact" else f"{method}-stable"
        ax.set_title(f"the {what} region ({100 * st.mean():.1f} % of the box)\n{rmap.title()}",
                     fontsize="medium")
    return PlotResult.of(out)


# --------------------------------------------------------------------------- several maps
def _param_values(rmap: RegionMap) -> dict[str, str]:
    """τ, δ, T* of a map as text: ``0.1`` or ``[0.1, 0.3]``."""
    out = {}
    for k, v in rmap.params.as_dict().items():
        out[k] = f"[{v[0]:g}, {v[1]:g}]" if isinstance(v, list) and v[0] != v[1] else \
            f"{v[0] if isinstance(v, list) else v:g}"
    return out


def _param_label(rmap: RegionMap, vary: Sequence[str]) -> str:
    p = _param_values(rmap)
    sym = {"tau": "τ", "delta": "δ", "headway": "T*"}
    return ", ".join(f"{sym[k]} = {p[k]} s" for k in vary)


def _varying(maps: Sequence[RegionMap]) -> list[str]:
    keys = ["tau", "delta", "headway"]
    vary = [k for k in keys if len({_param_values(m)[k] for m in maps}) > 1]
    return vary or ["tau"]


def _check_same_axes(maps: Sequence[RegionMap], what: str) -> None:
    if not maps:
        raise StringStabError(f"{what} needs at least one map; got none")
    for m in maps:
        _need_2d(m, what)
    first = maps[0]
    for m in maps[1:]:
        if m.axis_names != first.axis_names or m.fixed != first.fixed:
            raise StringStabError(
                f"{what} needs maps over the same gains and fixed gain; got {first.axis_names} "
                f"{first.fixed} and {m.axis_names} {m.fixed}"
            )


def plot_facets(
    maps: Sequence[RegionMap], method: str = "exact", *, axes: Sequence[Any] | None = None,
    kind: str = "class",
) -> PlotResult:
    """One panel per map (e.g. per τ or δ), side by side, to show how the region changes.

    Parameters
    ----------
    maps : sequence of RegionMap
        2-D maps over the same gains (and fixed gain), differing in τ, δ or T*.
    method : {"exact", "taylor", "printed"}
        Whose classes to show (``kind="class"``).
    axes : sequence of Axes, optional
        One axes per map; a new one-row figure when None.
    kind : {"class", "sup_gain"}
        Class maps, or heat maps of sup|Γ| (then ``method`` is ignored).

    Returns
    -------
    PlotResult
        ``fig``, ``axes``, ``images``, ``legend`` (a shared legend or colour bar
        owner) and ``shares`` (share of stable points per map).

    Raises
    ------
    StringStabError
        If the maps differ in their axes, ``axes`` has the wrong length or
        ``kind`` is unknown.
    """
    _check_same_axes(maps, "plot_facets")
    if kind not in ("class", "sup_gain"):
        raise StringStabError(f"kind must be 'class' or 'sup_gain'; got {kind!r}")
    vary = _varying(maps)
    if axes is None:
        fig = pyplot().figure(figsize=(3.4 * len(maps) + 2.4, 3.9), layout="constrained")
        axes = list(fig.subplots(1, len(maps), sharex=True, sharey=True, squeeze=False).ravel())
    else:
        axes = list(axes)
        if len(axes) != len(maps):
            raise StringStabError(f"expected one axes per map ({len(maps)}); got {len(axes)}")
        fig = axes[0].figure
    images, shares = [], []
    vmax = None
    if kind == "sup_gain":
        fin = np.concatenate([m.sup_gain[np.isfinite(m.sup_gain)] for m in maps if m.sup_gain is not None])
        vmax = max(float(np.percentile(fin, 99)), 1.1) if fin.size else 10.0
    for i, (m, ax) in enumerate(zip(maps, axes)):
        if kind == "class":
            out = plot_class_map(m, method, ax=ax, legend=False, title=False)
            share = float(m.stable(method).mean())
        else:
            out = plot_sup_gain(m, ax=ax, vmax=vmax, colorbar=False, title=False)
            share = float(m.stable("exact").mean())
            out["legend"].remove()
        images.append(out["image"])
        shares.append(share)
        word = "certified" if (kind == "sup_gain" or method == "exact") else "stable"
        ax.set_title(f"{_param_label(m, vary)}\n{100 * share:.1f} % {word}", fontsize="medium")
        if i:
            ax.set_ylabel("")
    if kind == "class":
        names = maps[0].class_names(method)
        leg = fig.legend(handles=[patch(CLASS_COLORS[c], c) for c in names],
                         loc="outside right upper", frameon=False, fontsize="small")
    else:
        from matplotlib.lines import Line2D

        fig.colorbar(images[-1], ax=axes, extend="max", shrink=0.9, label=_gain_symbol(maps[0])[1])
        sym = "H" if maps[0].sample_time else "Γ"
        leg = fig.legend(handles=[patch("#E4E4E4", f"not internally stable (‖{sym}‖∞ = ∞)"),
                                  Line2D([], [], color=OKABE_ITO["vermillion"], lw=1.6,
                                         label=f"boundary of sup|{sym}| ≤ 1 (certified)")],
                         loc="outside lower center", ncol=2, frameon=False, fontsize="small")
    fixed = "; ".join(f"{k} = {v:g}" for k, v in maps[0].fixed.items())
    p = _param_values(maps[0])
    const = ", ".join(f"{s} = {p[k]} s" for k, s in (("tau", "τ"), ("delta", "δ"), ("headway", "T*"))
                      if k not in vary)
    what = _method_title(maps[0], method) if kind == "class" else _gain_symbol(maps[0])[0]
    fig.suptitle(f"{what}; {fixed}; {const}", fontsize="medium")
    return PlotResult.of({"fig": fig, "axes": axes, "images": images, "legend": leg, "shares": shares})


def plot_boundaries(
    maps: Sequence[RegionMap], method: str = "exact", *, ax: Any = None, title: bool = True,
) -> PlotResult:
    """The boundaries of the string-stable regions of several maps on one axes.

    Parameters
    ----------
    maps : sequence of RegionMap
        2-D maps over the same gains, differing in τ, δ or T*.
    method : {"exact", "taylor", "printed"}
        Whose verdict defines each region.
    ax : matplotlib Axes, optional
        Where to draw; a new figure when None.
    title : bool
        Draw the title.

    Returns
    -------
    PlotResult
        ``ax``, ``contours`` (one ContourSet or None per map), ``legend`` and
        ``shares``.
    """
    _check_same_axes(maps, "plot_boundaries")
    from matplotlib.lines import Line2D

    ax = new_ax(ax, figsize=(6.4, 7.4))
    vary = _varying(maps)
    colors = [OKABE_ITO["blue"], OKABE_ITO["vermillion"], OKABE_ITO["green"], OKABE_ITO["purple"], OKABE_ITO["orange"], OKABE_ITO["sky"]]
    styles = ["-", "--", "-.", ":"]
    contours, handles, shares = [], [], []
    for i, m in enumerate(maps):
        st = m.stable(method)
        share = float(st.mean())
        shares.append(share)
        col, ls = colors[i % len(colors)], styles[i % len(styles)]
        cs = None
        if 0 < st.sum() < st.size:
            x, y = m.axes.values()
            cs = ax.contour(x, y, st.T.astype(float), levels=[0.5], colors=[col], linestyles=[ls],
                            linewidths=1.8)
        contours.append(cs)
        handles.append(Line2D([], [], color=col, ls=ls, lw=1.8,
                              label=f"{_param_label(m, vary)} ({100 * share:.1f} % inside)"))
    x, y = maps[0].axes.values()
    ax.set_xlim(x[0], x[-1])
    ax.set_ylim(y[0], y[-1])
    ax.grid(True, lw=0.4, alpha=0.5)
    _label_axes(ax, maps[0])
    word = "certified" if method == "exact" else f"{method}-stable"
    leg = legend_below(ax, handles, title=f"boundary of the {word} region", ncol=1)
    if title:
        fixed = "; ".join(f"{k} = {v:g}" for k, v in maps[0].fixed.items())
        p = _param_values(maps[0])
        const = ", ".join(f"{s} = {p[k]} s" for k, s in (("tau", "τ"), ("delta", "δ"), ("headway", "T*"))
                          if k not in vary)
        sym = {"tau": "τ", "delta": "δ", "headway": "T*"}
        ax.set_title(f"boundary of the {word} region for several {', '.join(sym[v] for v in vary)}\n"
                     f"{fixed}; {const}", fontsize="medium")
    return PlotResult.of({"ax": ax, "contours": contours, "legend": leg, "shares": shares})


# --------------------------------------------------------------------------- trajectory
def _gain_rows(gains: Any) -> tuple[npt.NDArray[np.float64], Any]:
    """(K of shape (n, 3), vehicle ids or None) of a gain table or an (n, 3) array."""
    table_K = getattr(gains, "K", None)
    if table_K is not None:  # a gain table (stringstab.io.gains.GainTable)
        return np.asarray(table_K, dtype=float), getattr(gains, "vehicle", None)
    K = np.asarray(gains, dtype=float)
    if K.ndim != 2 or K.shape[1] != 3 or K.shape[0] == 0:
        raise StringStabError(f"gains must be an (n, 3) array of k_x, k_v, k_a; got shape {K.shape}")
    return K, None


def trajectory_verdicts(rmap: RegionMap, gains: Any) -> list[str]:
    """The exact verdict of each triple of ``gains`` for the map's loop (compute step).

    The certificate the map's ``exact`` method is: continuous or sampled (``sample_time``),
    at the map's τ, δ, T* or over its box.

    Parameters
    ----------
    rmap : RegionMap
        The map whose loop (τ s, δ s, T* s, sample time, heterogeneity) the gains are
        certified for.
    gains : GainTable or array_like of shape (n, 3)
        The triples k_x (1/s²), k_v (1/s), k_a (dimensionless).

    Returns
    -------
    list of str
        One verdict per triple (``"certified"``, ``"not_certified"``, ...).

    Raises
    ------
    StringStabError
        If the gains are not an n × 3 array.

    Examples
    --------
    >>> from stringstab.regions import region_map
    >>> m = region_map({"k_x": [0.5, 1.5], "k_v": [0.0, 1.0]}, {"k_a": 0.2}, tau=0.1, delta=0.2,
    ...                headway=1.1, methods="taylor")
    >>> trajectory_verdicts(m, [[1.5, 0.3, -0.1], [0.9, -0.5, 1.1]])
    ['certified', 'not_certified']
    """
    from ..certify.api import certify_batch

    K, _ = _gain_rows(gains)
    p = rmap.params
    return certify_batch(K[:, 0], K[:, 1], K[:, 2], tau=p.tau, delta=p.delta,
                         headway=p.headway, sample_time=rmap.sample_time,
                         heterogeneous=rmap.heterogeneous).verdict.tolist()


def plot_trajectory(
    rmap: RegionMap, gains: Any, *, ax: Any = None, verdicts: Any = None,
    legend: bool = True, label: str = "policy gains",
) -> PlotResult:
    """Overlay a gain trajectory (e.g. from a policy rollout) on a 2-D map.

    The trajectory is projected on the map's two axis gains; each point is
    marked by the exact verdict of *its own* triple (its own third gain, the
    map's τ, δ, T*), which need not equal the map's fixed gain.  Points of one
    vehicle are joined in order; the first point of each is labelled.

    Compute, then draw: pass the verdicts computed beforehand
    (:func:`stringstab.certify.api.certify_batch` of the triples, or its ``.verdict``).
    Without them, as python-control's ``bode_plot(sys)`` computes the response it draws,
    they are computed here first (one :func:`~stringstab.certify.api.certify_batch`
    call); the toolkit's own callers always pass them.

    Parameters
    ----------
    rmap : RegionMap
        The 2-D map it is drawn over (gives the axes and the parameters).
    gains : GainTable or array_like of shape (n, 3)
        The triples k_x, k_v, k_a in time order (a gain table, e.g. from
        :func:`stringstab.io.read_gains`, adds ``t`` and ``vehicle``).
    ax : matplotlib Axes, optional
        Usually the axes of a class map; a new figure when None.
    verdicts : CertificateBatch or sequence of str, optional
        The exact verdict of each row, computed beforehand.
    legend : bool
        Add the trajectory's entries to the axes' legend (under the axes).
    label : str
        What the points are, in the legend ("policy gains: certified (n = 12)").

    Returns
    -------
    PlotResult
        ``ax``, ``lines`` (one per vehicle), ``markers`` (verdict → the
        PathCollection), ``verdicts`` (list) and ``legend``.

    Raises
    ------
    StringStabError
        If ``rmap`` is not 2-D, the gains are not n × 3 or the verdicts are not one per row.
    """
    _need_2d(rmap, "plot_trajectory")
    K, vehicle = _gain_rows(gains)
    if verdicts is None:
        verdicts = trajectory_verdicts(rmap, K)
    verdicts = list(getattr(verdicts, "verdict", verdicts))
    if len(verdicts) != K.shape[0]:
        raise StringStabError(f"expected one verdict per gain triple ({K.shape[0]}); got {len(verdicts)}")
    ax = new_ax(ax)
    col = {"k_x": 0, "k_v": 1, "k_a": 2}
    xn, yn = rmap.axis_names
    x, y = K[:, col[xn]], K[:, col[yn]]
    groups = [np.arange(K.shape[0])] if vehicle is None else [
        np.flatnonzero(vehicle == v) for v in dict.fromkeys(vehicle.tolist())
    ]
    lines = []
    for g in groups:
        (ln,) = ax.plot(x[g], y[g], color="#333333", lw=1.0, zorder=3)
        lines.append(ln)
        if vehicle is not None:
            ax.annotate(f"veh {vehicle[g[0]]}", (x[g[0]], y[g[0]]), xytext=(4, 4),
                        textcoords="offset points", fontsize="x-small", zorder=5)
    v_arr = np.asarray(verdicts)
    markers = {}
    for name, style in _VERDICT_MARKERS.items():
        sel = v_arr == name
        if sel.any():
            markers[name] = ax.scatter(
                x[sel], y[sel], marker=style["marker"], s=40, facecolors=style["facecolor"],
                edgecolors=style["edgecolor"], linewidths=0.8, zorder=4,
                label=f"{label}: {name.replace('_', ' ')} (n = {int(sel.sum())})",
            )
    leg = None
    if legend:
        handles = list(markers.values())
        title = "markers: exact verdict of each point's own K"
        old = ax.get_legend()
        if old is not None:  # extend the map's legend rather than cover the map
            handles = [*old.legend_handles, *handles]
            for h, t in zip(old.legend_handles, old.get_texts()):
                h.set_label(t.get_text())
            title = f"{old.get_title().get_text()}\n{title}"
        leg = legend_below(ax, handles, title=title)
    return PlotResult.of({"ax": ax, "lines": lines, "markers": markers, "verdicts": verdicts, "legend": leg})


# --------------------------------------------------------------------------- files
def figure_stems(rmap: RegionMap, overlay: bool = False) -> list[str]:
    """The names (without prefix and format) of the standard figures of ``rmap``.

    2-D map: ``class_<method>`` for each method, ``compare`` (two or more methods),
    ``sup_gain`` (``exact``) and, with ``overlay``, ``overlay``.  3-D map:
    ``slices_<method>`` and ``3d_<method>`` for each method.

    Parameters
    ----------
    rmap : RegionMap
        The computed map.
    overlay : bool, default False
        Include the ``overlay`` figure (2-D maps only; it needs gains to draw).

    Returns
    -------
    list of str
        The stems, in drawing order.
    """
    if rmap.ndim == 2:
        stems = [f"class_{m}" for m in rmap.methods]
        if len(rmap.methods) >= 2:
            stems.append("compare")
        if "exact" in rmap.methods:
            stems.append("sup_gain")
        if overlay:
            stems.append("overlay")
        return stems
    return [s for m in rmap.methods for s in (f"slices_{m}", f"3d_{m}")]


def draw_figure(rmap: RegionMap, stem: str, gains: Any = None, verdicts: Any = None) -> Any:
    """Draw the standard figure ``stem`` (:func:`figure_stems`) of ``rmap``; returns its Figure.

    Parameters
    ----------
    rmap : RegionMap
        The computed map.
    stem : str
        One of :func:`figure_stems` ``(rmap, True)``.
    gains : GainTable or array_like of shape (n, 3), optional
        The gain trajectory; required for ``overlay`` (drawn over the exact region projected
        over the points' own values of the map's fixed gain).
    verdicts : CertificateBatch or sequence of str, optional
        The exact verdict of each gain triple (``overlay``); computed when None.

    Returns
    -------
    matplotlib Figure
        The new figure (the caller saves and closes it).

    Raises
    ------
    StringStabError
        On an unknown stem, or ``overlay`` without valid gains.
    """
    if stem.startswith("class_"):
        return plot_class_map(rmap, stem[len("class_"):]).figure
    if stem == "compare":
        return plot_comparison(rmap).figure
    if stem == "sup_gain":
        return plot_sup_gain(rmap).figure
    if stem == "overlay":
        # not the map's slice: the points need not share its fixed gain, so the background is
        # the certified region projected over the points' own values of that gain
        from .projection import plot_projected_region, projected_region

        K, _ = _gain_rows(gains)
        xy = K[:, [("k_x", "k_v", "k_a").index(a) for a in rmap.axis_names]]
        lo = min(min(float(a[0]) for a in rmap.axes.values()), float(xy.min()))
        hi = max(max(float(a[-1]) for a in rmap.axes.values()), float(xy.max()))
        pad = 0.03 * (hi - lo)
        p = rmap.params
        proj = projected_region(K, tau=p.tau, delta=p.delta, headway=p.headway,
                                plane=(rmap.axis_names[0], rmap.axis_names[1]), bounds=(lo - pad, hi + pad),
                                sample_time=rmap.sample_time, n=81)
        loop = "; ".join(t for t in rmap.title().split("; ") if not t.startswith(tuple(rmap.fixed)))
        ax = plot_projected_region(proj, title=f"{_method_title(rmap, 'exact')}; {loop}").ax
        plot_trajectory(rmap, gains, ax=ax, verdicts=verdicts)
        return ax.figure
    if stem.startswith("slices_"):
        return plot_slices(rmap, stem[len("slices_"):]).figure
    if stem.startswith("3d_"):
        return plot_region_3d(rmap, stem[len("3d_"):]).figure
    raise StringStabError(f"unknown figure {stem!r}; expected one of {figure_stems(rmap, True)}")


def save_figures(
    rmap: RegionMap, out: Any, *, prefix: str = "region",
    formats: Sequence[str] = ("png", "pdf"), gains: Any = None, verdicts: Any = None,
    dpi: int = 150, workers: int = 1, stems: Sequence[str] | None = None,
) -> list[Path]:
    """Draw the standard figures of a map and save each in every format.

    Each file carries the tool version and :meth:`RegionMap.metadata` (τ, δ,
    T*, axes, methods) as JSON in its own metadata: PNG ``Software`` and
    ``Description`` text chunks, PDF ``Creator`` and ``Subject``, SVG
    ``Creator`` and ``Description``.  The figures are :func:`figure_stems`, saved as
    ``<prefix>_<stem>.<format>``.

    Parameters
    ----------
    rmap : RegionMap
        The map.
    out : path or OutputDir
        An existing folder, or a :class:`stringstab.io.OutputDir` (the files are
        staged in it and appear when its run succeeds).
    prefix : str
        File name stem.
    formats : sequence of str
        Among :data:`FIGURE_FORMATS`.
    gains : GainTable or array_like, optional
        A gain trajectory to overlay (2-D maps only).
    verdicts : CertificateBatch or sequence of str, optional
        The exact verdicts of ``gains``, computed beforehand (else computed here once:
        :func:`trajectory_verdicts`).
    dpi : int
        Resolution of raster formats.
    workers : int
        Processes drawing the figures (forked; 1 draws them here, one after another).
    stems : sequence of str, optional
        Draw only these of :func:`figure_stems`.

    Returns
    -------
    list of Path
        The files written (their final paths).

    Raises
    ------
    StringStabError
        On an unknown format, or ``gains`` with a 3-D map.
    """
    for f in formats:
        if f not in FIGURE_FORMATS:
            raise StringStabError(f"figure formats must be among {list(FIGURE_FORMATS)}; got {f!r}")
    if gains is not None and rmap.ndim != 2:
        raise StringStabError(f"a gain trajectory can be overlaid on a 2-D map only; got a {rmap.ndim}-D map")
    if gains is not None and verdicts is None:
        verdicts = trajectory_verdicts(rmap, gains)
    every = figure_stems(rmap, gains is not None)
    if stems is None:
        stems = every
    elif any(s not in every for s in stems):
        raise StringStabError(f"figures must be among {every}; got {list(stems)}")
    stage: Callable[[str], Path]
    final: Callable[[str], Path]
    if hasattr(out, "path") and hasattr(out, "final"):  # an OutputDir
        stage, final = out.path, out.final
    else:
        stage = final = Path(out).joinpath
    jobs = [(stem, [(f, stage(f"{prefix}_{stem}.{f}")) for f in formats]) for stem in stems]
    job = _FigureJob(rmap, gains, verdicts, dpi)
    if workers > 1 and len(jobs) > 1:
        _run_parallel(job, jobs, workers)
    else:
        for j in jobs:
            job(j)
    return [final(f"{prefix}_{stem}.{f}") for stem in stems for f in formats]


class _FigureJob:
    """Draw one standard figure and save it in its formats (picklable for a forked pool)."""

    def __init__(self, rmap: RegionMap, gains: Any, verdicts: Any, dpi: int) -> None:
        import json

        self.rmap, self.gains, self.verdicts, self.dpi = rmap, gains, verdicts, dpi
        meta = json.dumps(rmap.metadata(), ensure_ascii=False)
        software = f"stringstab {rmap.version}"
        self.file_meta = {
            "png": {"Software": software, "Description": meta},
            "pdf": {"Creator": software, "Subject": meta},
            "svg": {"Creator": software, "Description": meta},
        }

    def __call__(self, job: tuple[str, list[tuple[str, Path]]]) -> None:
        stem, targets = job
        fig = draw_figure(self.rmap, stem, self.gains, self.verdicts)
        try:
            for f, path in targets:
                # a tight bounding box: whatever the layout engine could not fit (a long title,
                # a wide legend under the axes) is kept in the file rather than cut off
                fig.savefig(path, dpi=self.dpi, metadata=self.file_meta[f], bbox_inches="tight",
                            pad_inches=0.1)
        finally:
            pyplot().close(fig)


def _run_parallel(job: _FigureJob, jobs: list[tuple[str, list[tuple[str, Path]]]],
                  workers: int) -> None:
    """Draw the figures in ``workers`` forked processes (the map is inherited, not sent)."""
    import multiprocessing

    if "fork" not in multiprocessing.get_all_start_methods() or multiprocessing.current_process().daemon:
        for j in jobs:
            job(j)
        return
    global _JOB
    _JOB = job
    try:
        with multiprocessing.get_context("fork").Pool(min(workers, len(jobs))) as pool:
            pool.map(_run_job, jobs, chunksize=1)
    finally:
        _JOB = None


_JOB: _FigureJob | None = None


def _run_job(j: tuple[str, list[tuple[str, Path]]]) -> None:
    assert _JOB is not None
    _JOB(j)
