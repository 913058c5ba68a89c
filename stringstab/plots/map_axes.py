"""Drawing a region map on axes: the 2-D check, the field, the axis labels and the titles.

The pieces every region-map figure (:mod:`~stringstab.plots.regions`,
:mod:`~stringstab.plots.regions_3d`, :mod:`~stringstab.plots.region_sets`,
:mod:`~stringstab.plots.trajectory`, :mod:`~stringstab.plots.outputs`) shares.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..regions import CONTINUOUS, RegionMap
from ._common import GAIN_LABELS

__all__ = ["draw_field", "gain_symbol", "label_axes", "method_label", "method_title", "need_2d"]

_METHOD_TITLES = {
    "exact": "exact certificate",
    "taylor": "Taylor Prop. 1 (derived Ψ) types",
    "printed": "Taylor Prop. 1 (printed Ψ) types",
    CONTINUOUS: "continuous-time certificate",
}


def method_title(rmap: RegionMap, method: str) -> str:
    """The title of ``method``'s classes: ``exact`` names the loop it certifies.

    Parameters
    ----------
    rmap : RegionMap
        The map.
    method : str
        One of the map's methods.

    Returns
    -------
    str
        E.g. ``"exact certificate"`` or ``"certificate of the sampled loop"``.
    """
    if method == "exact" and (rmap.sample_time is not None or rmap.is_box):
        return f"certificate of the {rmap.loop} loop"
    return _METHOD_TITLES[method]


def method_label(rmap: RegionMap, method: str) -> str:
    """A method's name in a comparison legend (``exact`` is ``sampled`` on a sampled map).

    Parameters
    ----------
    rmap : RegionMap
        The map.
    method : str
        One of the map's methods.

    Returns
    -------
    str
        ``"sampled"`` or ``"robust"`` for the exact method of such a map, else ``method``.
    """
    if method == "exact" and rmap.sample_time is not None:
        return "sampled"
    if method == "exact" and rmap.is_box:
        return "robust"
    return method


def gain_symbol(rmap: RegionMap) -> tuple[str, str]:
    """(text, LaTeX) of the supremum the sup-gain map shows.

    Parameters
    ----------
    rmap : RegionMap
        The map (sampled: sup_θ |H(e^{jθ})|; else sup_ω |Γ(jω)|).

    Returns
    -------
    (str, str)
        The plain text and the matplotlib mathtext of the supremum.
    """
    if rmap.sample_time is not None:
        return "sup|H(e^{jθ})|", r"$\sup_\theta |H(e^{j\theta})|$"
    return "sup|Γ(jω)|", r"$\sup_\omega |\Gamma(j\omega)|$"


def need_2d(rmap: RegionMap, what: str) -> None:
    """Refuse, in one line, anything but a 2-D :class:`~stringstab.regions.RegionMap`.

    Parameters
    ----------
    rmap : RegionMap
        What the plot function was given.
    what : str
        The plot function's name, for the message.

    Raises
    ------
    StringStabError
        If ``rmap`` is not a RegionMap or not 2-D.
    """
    if not isinstance(rmap, RegionMap):
        raise StringStabError(f"{what} needs a RegionMap; got {type(rmap).__name__}")
    if rmap.ndim != 2:
        raise StringStabError(
            f"{what} draws a 2-D map; got a {rmap.ndim}-D map (use RegionMap.slice or plot_slices)"
        )


def _uniform(a: npt.NDArray[np.float64]) -> bool:
    d = np.diff(a)
    return bool(np.allclose(d, d[0], rtol=1e-6, atol=0.0))


def draw_field(ax: Any, rmap: RegionMap, values: np.ndarray, **kw: Any) -> Any:
    """Draw a 2-D field over the map's axes (imshow on a uniform grid, else pcolormesh).

    Parameters
    ----------
    ax : matplotlib Axes
        Where to draw.
    rmap : RegionMap
        A 2-D map (its axis grids place the cells).
    values : ndarray
        One value per grid point, shaped like the map.
    **kw
        Passed to ``imshow`` or ``pcolormesh`` (``cmap``, ``norm``, ...).

    Returns
    -------
    AxesImage or QuadMesh
        The artist drawn.
    """
    x, y = rmap.axes.values()
    if _uniform(x) and _uniform(y):
        dx, dy = (x[1] - x[0]) / 2, (y[1] - y[0]) / 2
        # nearest-neighbour resampling of the values, then the colours of the screen pixels
        # only: with "nearest", picking then colouring is the same picture as colouring then
        # picking (matplotlib's choice when a large map is shrunk to fewer pixels), pixel for
        # pixel, without colouring every grid point as an RGBA float image first
        return ax.imshow(
            np.asarray(values).T, origin="lower", extent=(x[0] - dx, x[-1] + dx, y[0] - dy, y[-1] + dy),
            aspect="auto", interpolation="nearest", interpolation_stage="data", **kw,
        )
    return ax.pcolormesh(x, y, np.asarray(values).T, shading="nearest", **kw)


def label_axes(ax: Any, rmap: RegionMap) -> None:
    """Label the axes with the map's two gains (with units) and make them square.

    Parameters
    ----------
    ax : matplotlib Axes
        The axes of a 2-D map.
    rmap : RegionMap
        The map drawn there.
    """
    xn, yn = rmap.axis_names
    ax.set_xlabel(GAIN_LABELS[xn])
    ax.set_ylabel(GAIN_LABELS[yn])
    ax.set_box_aspect(1.0)
