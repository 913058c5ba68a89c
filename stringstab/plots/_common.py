"""What every figure of the toolkit shares: the result object, the palette, small helpers.

Every plot function takes ``ax=None`` (``axes=None``/``fig=None`` for several panels), draws
into it or a new figure, and returns a :class:`PlotResult`, a small fixed object in the
pattern of python-control's ``ControlPlot``: the figure, the axes and the named artists (and
the few numbers the figure shows, e.g. the counts of a comparison).

Colours are the Okabe-Ito palette (safe for the common colour-vision deficiencies).

References
----------
M. Okabe and K. Ito, "Color Universal Design (CUD)", 2008,
https://jfly.uni-koeln.de/color/.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..certify.verdicts import Verdict

__all__ = [
    "CLASS_COLORS",
    "GAIN_LABELS",
    "OKABE_ITO",
    "PlotResult",
    "categorical",
    "dry_runs_without_images",
    "legend_below",
    "log_colorbar_ticks",
    "new_ax",
    "patch",
    "pct",
    "pyplot",
    "share_mathtext_parser",
    "warm_up",
]


@dataclass(frozen=True)
class PlotResult:
    """What a plot function drew: its figure, its axes and its named artists.

    Attributes
    ----------
    figure : matplotlib Figure
        The figure drawn in.
    axes : tuple of Axes
        The axes drawn in (one for most functions).
    artists : dict
        The artists by name (``"image"``, ``"legend"``, ``"contour"``, ``"lines"``, ...)
        and the numbers the figure shows (``"counts"``, ``"shares"``, ``"verdicts"``, ...).

    Notes
    -----
    ``result["name"]`` reads an artist (``"ax"``, ``"fig"`` and ``"axes"`` read the
    figure's axes and the figure), as a dict of artists would; ``fig, axes = result``
    unpacks like :func:`matplotlib.pyplot.subplots`.
    """

    figure: Any
    axes: tuple[Any, ...]
    artists: Mapping[str, Any] = field(default_factory=dict)

    @classmethod
    def of(cls, drawn: Mapping[str, Any]) -> PlotResult:
        """From the named things a plot function drew (``"ax"``/``"axes"``, ``"fig"``, ...)."""
        axes = drawn.get("axes")
        ax = drawn.get("ax")
        axs: tuple[Any, ...] = (tuple(np.ravel(np.asarray(axes, dtype=object))) if axes is not None
                                else (ax,) if ax is not None else ())
        fig = drawn.get("fig")
        if fig is None and axs:
            fig = axs[0].figure
        rest = {k: v for k, v in drawn.items() if k not in ("ax", "axes", "fig")}
        return cls(fig, axs, rest)

    @property
    def ax(self) -> Any:
        """The first (usually the only) axes."""
        return self.axes[0] if self.axes else None

    @property
    def legend(self) -> Any:
        """The legend drawn, or None."""
        return self.artists.get("legend")

    def __getitem__(self, key: str) -> Any:
        if key == "ax":
            return self.ax
        if key in ("fig", "figure"):
            return self.figure
        if key == "axes":
            return list(self.axes)
        return self.artists[key]

    def __contains__(self, key: object) -> bool:
        return key in ("ax", "fig", "figure", "axes") or key in self.artists

    def keys(self) -> list[str]:
        """The names :meth:`__getitem__` accepts."""
        return ["fig", "axes", "ax", *self.artists]

    def __iter__(self) -> Iterator[Any]:
        """``fig, axes = result``."""
        return iter((self.figure, self.axes))


#: The Okabe-Ito colours.
OKABE_ITO = {
    "orange": "#E69F00", "sky": "#56B4E9", "green": "#009E73", "yellow": "#F0E442",
    "blue": "#0072B2", "vermillion": "#D55E00", "purple": "#CC79A7", "black": "#000000",
    "grey": "#BBBBBB",
}
#: Colour of each class of :data:`stringstab.regions.TYPE_CLASSES` / ``EXACT_CLASSES``.
CLASS_COLORS: dict[str, str] = {
    "not internally stable": OKABE_ITO["grey"],
    "type III": OKABE_ITO["vermillion"],
    "type IV": OKABE_ITO["orange"],
    "type I": OKABE_ITO["blue"],
    "type II": OKABE_ITO["sky"],
    Verdict.NOT_CERTIFIED.words: OKABE_ITO["vermillion"],
    Verdict.INCONCLUSIVE.words: OKABE_ITO["black"],
    Verdict.CERTIFIED.words: OKABE_ITO["blue"],
}
#: Axis labels of the gains, with units (u = k_x Δp + k_v Δv + k_a a in m/s²).
GAIN_LABELS: dict[str, str] = {
    "k_x": r"$k_x$ (s$^{-2}$)",
    "k_v": r"$k_v$ (s$^{-1}$)",
    "k_a": r"$k_a$ (–)",
}


def pyplot() -> Any:
    """matplotlib.pyplot, imported on first use.

    Returns
    -------
    module
        The ``matplotlib.pyplot`` module.
    """
    import matplotlib.pyplot as plt

    return plt


def new_ax(ax: Any, figsize: tuple[float, float] = (6.4, 7.0)) -> Any:
    """``ax``, or the axes of a new figure (constrained layout) when it is None.

    Parameters
    ----------
    ax : matplotlib Axes or None
        Axes to draw on.
    figsize : tuple of float, default (6.4, 7.0)
        Size (inches) of the new figure; ignored when ``ax`` is given.

    Returns
    -------
    matplotlib Axes
        ``ax`` itself, or the new figure's single axes.
    """
    if ax is not None:
        return ax
    fig = pyplot().figure(figsize=figsize, layout="constrained")
    return fig.add_subplot()


def categorical(colors: Sequence[str]) -> tuple[Any, Any]:
    """A colormap and norm that map the integer codes 0, 1, ... to ``colors``.

    Parameters
    ----------
    colors : sequence of str
        Matplotlib colours, the i-th for code i.

    Returns
    -------
    cmap, norm : ListedColormap, BoundaryNorm
        Pass both to ``imshow``/``pcolormesh`` (boundaries at −0.5, 0.5, ...).
    """
    from matplotlib.colors import BoundaryNorm, ListedColormap

    cmap = ListedColormap(list(colors))
    norm = BoundaryNorm(np.arange(len(colors) + 1) - 0.5, len(colors))
    return cmap, norm


def pct(count: int, n: int) -> str:
    """``count`` of ``n`` as a percentage (one decimal; ``<0.1 %`` when tiny).

    Parameters
    ----------
    count : int
        The part.
    n : int
        The whole; 0 gives ``"nan %"``.

    Returns
    -------
    str
        E.g. ``"12.5 %"``.
    """
    share = 100.0 * count / n if n else float("nan")
    if 0 < share < 0.1:
        return "<0.1 %"
    return f"{share:.1f} %"


def legend_below(ax: Any, handles: list[Any], title: str | None = None, ncol: int = 2) -> Any:
    """A legend under the axes (below the x label), so it never covers the map.

    Parameters
    ----------
    ax : matplotlib Axes
        The axes that get the legend (it replaces any legend they had).
    handles : list
        The legend entries (artists with labels, e.g. from :func:`patch`).
    title : str, optional
        The legend's title.
    ncol : int, default 2
        Number of columns of entries.

    Returns
    -------
    matplotlib Legend
        The legend drawn.
    """
    return ax.legend(handles=handles, title=title, loc="upper center", bbox_to_anchor=(0.5, -0.12),
                     ncol=ncol, frameon=False, fontsize="small", title_fontsize="small",
                     columnspacing=1.2, handlelength=1.6)


def log_colorbar_ticks(cb: Any) -> None:
    """Label a logarithmic colourbar at 1, 2, 5 of every decade, as plain numbers.

    Matplotlib's default labels a log colourbar at powers of ten only, so a scale from 1 to 12
    reads "10⁰, 10¹" and nothing between; here it reads 1, 2, 5, 10.  A range under a decade
    also gets its ends' neighbours (1.1, 1.2, 1.5, ... via the 1-9 subs when 1-2-5 gives fewer
    than three ticks).

    Parameters
    ----------
    cb : matplotlib Colorbar
        A colourbar of a :class:`~matplotlib.colors.LogNorm` image.
    """
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    lo, hi = cb.norm.vmin, cb.norm.vmax
    subs: tuple[float, ...] = (1.0, 2.0, 5.0)
    if np.count_nonzero([lo <= m * 10.0 ** e <= hi for e in range(-3, 6) for m in subs]) < 3:
        subs = tuple(float(k) for k in range(1, 10))
    cb.ax.yaxis.set_major_locator(LogLocator(base=10.0, subs=subs))
    cb.ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    cb.ax.yaxis.set_minor_formatter(NullFormatter())


def patch(color: str, label: str) -> Any:
    """A legend patch of ``color``.

    Parameters
    ----------
    color : str
        Matplotlib colour of the face (the edge is grey).
    label : str
        The legend text.

    Returns
    -------
    matplotlib.patches.Patch
        A handle for :func:`legend_below`.
    """
    from matplotlib.patches import Patch

    return Patch(facecolor=color, edgecolor="#555555", linewidth=0.5, label=label)



def share_mathtext_parser() -> None:
    """Give every Agg renderer of this process one mathtext parser, so its cache is shared.

    Matplotlib's Agg renderer makes its own :class:`matplotlib.mathtext.MathTextParser`, whose
    cache of parsed expressions (:meth:`~matplotlib.mathtext.MathTextParser.parse`) is keyed
    by the parser: a figure saved with a tight bounding box uses two renderers, and every new
    figure new ones, so the gain labels (``$k_x$ (s$^{-2}$)``, ...) were parsed four times per
    figure, about 12 % of its drawing time.  The parse is a pure function of the expression,
    the dpi and the font, so one parser serves all renderers with the same pictures (pixel for
    pixel).  Idempotent; affects this process only.

    A process forked from this one starts with a parser of its own (``os.register_at_fork``):
    a parse holds the fonts it was made with, and Agg loads their glyphs again when it draws,
    reading the font file through a file offset that a fork shares with the parent and every
    sibling; two drawers forked from one warm process drawing at once then read each other's
    bytes (FreeType's "invalid outline", "too many hints", or a wrong glyph).  Matplotlib
    drops its own font cache at a fork for the same reason; the parses made before it must
    not outlive it either.
    """
    import os

    from matplotlib.backends.backend_agg import RendererAgg
    from matplotlib.mathtext import MathTextParser

    if getattr(RendererAgg, "_stringstab_shared_mathtext", None) is not None:
        return
    shared: list[MathTextParser] = []  # the one parser of this process
    init = RendererAgg.__init__

    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        init(self, *args, **kwargs)
        if isinstance(getattr(self, "mathtext_parser", None), MathTextParser):
            self.mathtext_parser = shared[0]

    def new_parser() -> None:  # what RendererAgg.__init__ makes for itself
        shared[:] = [MathTextParser("path")]

    new_parser()
    RendererAgg.__init__ = __init__  # type: ignore[method-assign]
    RendererAgg._stringstab_shared_mathtext = shared  # type: ignore[attr-defined]
    if hasattr(os, "register_at_fork"):
        os.register_at_fork(after_in_child=new_parser)


@contextlib.contextmanager
def dry_runs_without_images() -> Iterator[None]:
    """Within: the dry run of a tight-box save leaves images out (made once per save, not twice).

    ``savefig(bbox_inches="tight")`` draws a figure twice: a dry run, with the renderer's
    ``draw_*`` methods patched to no-ops (``RendererBase._draw_disabled``), to lay it out and
    measure its tight bounding box, then the real draw.  An image's part of the box is its
    extent (:meth:`~matplotlib.image.AxesImage.get_window_extent`, from the data limits), not
    its pixels, yet the dry run still resamples and colours it (``make_image``) only to hand
    the result to a no-op.  Within this context an :class:`~matplotlib.image.AxesImage` drawn
    on such a renderer returns at once; every other draw is unchanged, so the files are the
    same bytes.  The class is patched for the duration (this process, not thread-safe: the
    figure processes are single-threaded) and restored on leaving.

    Yields
    ------
    None
    """
    from matplotlib.backend_bases import RendererBase
    from matplotlib.image import AxesImage

    own = AxesImage.__dict__.get("draw")  # None: inherited (from matplotlib's image base)
    draw = AxesImage.draw

    def skipping(self: Any, renderer: Any, *args: Any, **kwargs: Any) -> Any:
        # the dry run's no-op draw_image wraps RendererBase.draw_image (functools.update_wrapper)
        no_op = getattr(getattr(renderer, "draw_image", None), "__wrapped__", None)
        if no_op is RendererBase.draw_image:
            self.stale = False
            return None
        return draw(self, renderer, *args, **kwargs)

    AxesImage.draw = skipping  # type: ignore[method-assign]
    try:
        yield
    finally:
        if own is None:
            del AxesImage.draw
        else:
            AxesImage.draw = own  # type: ignore[method-assign]


def warm_up(dpi: int = 150) -> None:
    """Import pyplot (Agg unless a backend is chosen) and draw one small figure off-screen.

    The first figure of a process pays for the imports, the font cache and the mathtext
    parser of the gain labels (about a second of CPU); a command that knows it will draw can
    pay it earlier, e.g. in a thread while its map is computed in worker processes (processes
    forked later inherit the warm state).  The Agg renderers share one mathtext parser
    (:func:`share_mathtext_parser`), so the gain labels parsed here at ``dpi`` are not parsed
    again by the figures this process saves at that resolution (a process forked from it
    parses them once more, with fonts of its own).

    Parameters
    ----------
    dpi : int, default 150
        The resolution the figures will be saved at (the labels are parsed for it).
    """
    import io
    import sys

    import matplotlib

    if "matplotlib.pyplot" not in sys.modules:
        matplotlib.use("Agg")
    share_mathtext_parser()
    plt = pyplot()
    fig = plt.figure(figsize=(2.0, 2.0), layout="constrained")
    ax = fig.add_subplot()
    ax.imshow(np.zeros((2, 2)), interpolation="nearest")
    ax.set_xlabel(GAIN_LABELS["k_x"])
    ax.set_ylabel(GAIN_LABELS["k_v"])
    ax.set_title("τ = 0.1 s\nwarm-up")
    ax.legend(handles=[patch(OKABE_ITO["blue"], "x")], loc="upper center", title="t")
    fig.savefig(io.BytesIO(), format="png", dpi=dpi)
    plt.close(fig)
