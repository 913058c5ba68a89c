"""Figures of several stability-region maps (differing in τ, δ or T*) side by side or overlaid.

=========================  ===================================================
function                   shows
=========================  ===================================================
:func:`plot_facets`        one class map per τ (or δ): how the region shrinks
:func:`plot_boundaries`    the certified boundaries of several maps on one axes
=========================  ===================================================
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import StringStabError
from ..regions import RegionMap
from ._common import CLASS_COLORS, OKABE_ITO, PlotResult, legend_below, new_ax, patch, pyplot
from .map_axes import gain_symbol, label_axes, method_title, need_2d
from .regions import plot_class_map, plot_sup_gain

__all__ = ["plot_boundaries", "plot_facets"]


def _param_values(rmap: RegionMap) -> dict[str, str]:
    """τ, δ, T* of a map as text: ``0.1`` or ``[0.1, 0.3]``."""
    out = {}
    for k, v in rmap.params.as_dict().items():
        out[k] = f"[{v[0]:g}, {v[1]:g}]" if isinstance(v, list) and v[0] != v[1] else \
            f"{v[0] if isinstance(v, list) else v:g}"
    return out


def _param_label(rmap: RegionMap, vary: Sequence[str]) -> str:
    """The varying parameters of a map as a label: ``τ = 0.1 s, δ = 0.2 s``."""
    p = _param_values(rmap)
    sym = {"tau": "τ", "delta": "δ", "headway": "T*"}
    return ", ".join(f"{sym[k]} = {p[k]} s" for k in vary)


def _varying(maps: Sequence[RegionMap]) -> list[str]:
    """Which of τ, δ, T* differ between the maps (τ when none does)."""
    keys = ["tau", "delta", "headway"]
    vary = [k for k in keys if len({_param_values(m)[k] for m in maps}) > 1]
    return vary or ["tau"]


def _check_same_axes(maps: Sequence[RegionMap], what: str) -> None:
    """Refuse no maps, a map that is not 2-D, or maps over other gains or fixed gains."""
    if not maps:
        raise StringStabError(f"{what} needs at least one map; got none")
    for m in maps:
        need_2d(m, what)
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

        fig.colorbar(images[-1], ax=axes, extend="max", shrink=0.9, label=gain_symbol(maps[0])[1])
        sym = "H" if maps[0].sample_time else "Γ"
        leg = fig.legend(handles=[patch("#E4E4E4", f"not internally stable (‖{sym}‖∞ = ∞)"),
                                  Line2D([], [], color=OKABE_ITO["vermillion"], lw=1.6,
                                         label=f"boundary of sup|{sym}| ≤ 1 (certified)")],
                         loc="outside lower center", ncol=2, frameon=False, fontsize="small")
    fixed = "; ".join(f"{k} = {v:g}" for k, v in maps[0].fixed.items())
    p = _param_values(maps[0])
    const = ", ".join(f"{s} = {p[k]} s" for k, s in (("tau", "τ"), ("delta", "δ"), ("headway", "T*"))
                      if k not in vary)
    what = method_title(maps[0], method) if kind == "class" else gain_symbol(maps[0])[0]
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
    label_axes(ax, maps[0])
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
