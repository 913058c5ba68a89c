"""A gain trajectory (e.g. a policy's rollout) over a 2-D region map, each point by its verdict.

:func:`trajectory_verdicts` computes the exact verdict of each triple for the map's loop (the
compute step); :func:`plot_trajectory` draws the triples, given those verdicts, over a map.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify.verdicts import Verdict
from ..errors import StringStabError
from ..regions import RegionMap
from ._common import OKABE_ITO, PlotResult, legend_below, new_ax
from .map_axes import need_2d

__all__ = ["gain_rows", "plot_trajectory", "trajectory_verdicts"]

_VERDICT_MARKERS = {
    Verdict.CERTIFIED: dict(marker="o", facecolor="white", edgecolor="black"),
    Verdict.NOT_CERTIFIED: dict(marker="X", facecolor="black", edgecolor="white"),
    Verdict.INCONCLUSIVE: dict(marker="D", facecolor=OKABE_ITO["yellow"], edgecolor="black"),
}


def gain_rows(gains: Any) -> tuple[npt.NDArray[np.float64], Any]:
    """(K of shape (n, 3), vehicle ids or None) of a gain table or an (n, 3) array.

    Parameters
    ----------
    gains : GainTable or array_like of shape (n, 3)
        The triples k_x (1/s²), k_v (1/s), k_a (dimensionless); a
        :class:`stringstab.io.GainTable` also gives the vehicle of each row.

    Returns
    -------
    K : ndarray, shape (n, 3)
        The triples.
    vehicle : ndarray or None
        The vehicle id of each row (a gain table with a ``vehicle`` column), else None.

    Raises
    ------
    StringStabError
        If the gains are not a non-empty n × 3 array.
    """
    table_K = getattr(gains, "K", None)
    if table_K is not None:  # a gain table (stringstab.io.GainTable)
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

    K, _ = gain_rows(gains)
    p = rmap.params
    return certify_batch(K[:, 0], K[:, 1], K[:, 2], tau=p.tau, delta=p.delta,
                         headway=p.headway, sample_time=rmap.sample_time,
                         heterogeneous=rmap.heterogeneous).verdict.tolist()


def plot_trajectory(
    rmap: RegionMap, gains: Any, *, verdicts: Any, ax: Any = None,
    legend: bool = True, label: str = "policy gains",
) -> PlotResult:
    """Overlay a gain trajectory (e.g. from a policy rollout) on a 2-D map.

    The trajectory is projected on the map's two axis gains; each point is
    marked by the exact verdict of *its own* triple (its own third gain, the
    map's τ, δ, T*), which need not equal the map's fixed gain.  Points of one
    vehicle are joined in order; the first point of each is labelled.

    Compute, then draw: the verdicts are computed beforehand, by :func:`trajectory_verdicts`
    or :func:`stringstab.certify.api.certify_batch` of the triples (or its ``.verdict``).

    Parameters
    ----------
    rmap : RegionMap
        The 2-D map it is drawn over (gives the axes and the parameters).
    gains : GainTable or array_like of shape (n, 3)
        The triples k_x, k_v, k_a in time order (a gain table, e.g. from
        :func:`stringstab.io.read_gains`, adds ``t`` and ``vehicle``).
    verdicts : CertificateBatch or sequence of str
        The exact verdict of each row, computed beforehand (:func:`trajectory_verdicts`).
    ax : matplotlib Axes, optional
        Usually the axes of a class map; a new figure when None.
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
    need_2d(rmap, "plot_trajectory")
    K, vehicle = gain_rows(gains)
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
