"""The figure and files of a map per reaction delay θ_r: the certified share vs θ_r, and each slice.

:func:`plot_certified_share` draws the share of the grid the exact certificate certifies
against θ_r (:class:`stringstab.regions.ReactionSweep`, computed beforehand);
:func:`save_reaction_sweep_outputs` writes what ``stringstab region --reaction-delay A,B,...``
writes: each θ_r's map files (:func:`stringstab.plots.save_region_outputs`, prefix
``<prefix>_theta_r_<θ_r>``, with its rule for the CSV), the table ``<prefix>_share_vs_theta_r.csv`` and that figure.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..io import atomic_write_text
from ..io.figures import check_figure_formats, figure_metadata, save_figure
from ..regions.reaction_sweep import ReactionSweep
from ._common import PlotResult, pyplot
from .outputs import save_region_outputs

__all__ = ["plot_certified_share", "save_reaction_sweep_outputs", "sweep_prefix"]


def sweep_prefix(prefix: str, theta: float) -> str:
    """The file stem of the map at θ_r: ``<prefix>_theta_r_<θ_r>`` (``%g``).

    Parameters
    ----------
    prefix : str
        The run's file stem.
    theta : float
        θ_r (s).

    Returns
    -------
    str
        For instance ``region_theta_r_0.1``.

    Examples
    --------
    >>> sweep_prefix("region", 0.1)
    'region_theta_r_0.1'
    """
    return f"{prefix}_theta_r_{theta:g}"


def plot_certified_share(sweep: ReactionSweep, *, ax: Any = None) -> PlotResult:
    """Draw the certified share of the grid (%) against the reaction delay θ_r.

    Parameters
    ----------
    sweep : ReactionSweep
        The maps (:func:`stringstab.regions.reaction_sweep`).
    ax : matplotlib Axes, optional
        Where to draw; default a new figure.

    Returns
    -------
    PlotResult
        ``ax``, ``lines`` (the certified share, markers and line; then, when any grid point
        is inconclusive, that share, dashed) and ``shares`` (the certified shares drawn).
    """
    if ax is None:
        fig = pyplot().figure(figsize=(5.6, 3.8), layout="constrained")
        ax = fig.subplots()
    th = sweep.reaction_delays
    shares = sweep.certified_shares()
    lines = ax.plot(th, 100 * shares, "o-", color="#1b7837", label="certified")
    inc = sweep.inconclusive_shares()
    if inc.any():
        lines += ax.plot(th, 100 * inc, "s--", color="#999999", label="inconclusive")
        ax.legend(loc="best", fontsize=8)
    ax.set_xlabel("reaction delay θ_r [s]")
    ax.set_ylabel("share of the grid [%]")
    m = sweep.maps[0]
    axes = ", ".join(f"{n} ∈ [{a[0]:g}, {a[-1]:g}]" for n, a in m.axes.items())
    title = m.title().replace(f", θ_r = {th[0]:g} s", "")
    ax.set_title(f"certified share vs θ_r\n{axes}; {title}", fontsize=8)
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    return PlotResult.of({"ax": ax, "lines": lines, "shares": shares})


def _table(sweep: ReactionSweep) -> str:
    """The CSV table of :meth:`ReactionSweep.rows`, with the grid and loop as comments."""
    rows = sweep.rows()
    head = ["# " + json.dumps(sweep.summary()["params"], ensure_ascii=False),
            ",".join(rows[0])]
    body = [",".join(repr(v) for v in r.values())
            for r in rows]
    return "\n".join(head + body) + "\n"


def save_reaction_sweep_outputs(
    sweep: ReactionSweep, out: Any, *, prefix: str = "region",
    formats: Sequence[str] = ("png", "pdf"), dpi: int = 150, figures: str = "default",
    csv: bool | None = None,
) -> list[Path]:
    """Write every θ_r's map files, the share table and the share-vs-θ_r figure.

    Parameters
    ----------
    sweep : ReactionSweep
        The maps.
    out : path or OutputDir
        An existing folder, or an :class:`stringstab.io.OutputDir` inside its ``with`` block.
    prefix : str
        File stem; each θ_r's files use :func:`sweep_prefix`.
    formats : sequence of str
        Figure formats (``png``, ``pdf``, ``svg``).
    dpi : int
        Resolution of PNG figures.
    figures : {"default", "all"}, default "default"
        Each map's class maps: the first method's only, or every method's
        (:func:`~stringstab.plots.figure_stems`).
    csv : bool or None, default None
        Each 2-D map's CSV table: by the size rule of :func:`~stringstab.plots.writes_csv`
        (``None``: at most :data:`~stringstab.plots.outputs.CSV_MAX_POINTS` points), always
        (``True``) or never (``False``).

    Returns
    -------
    list of Path
        The files written (final paths): the table, the figure, then each map's files.
    """
    formats = check_figure_formats(formats)

    def path(name: str) -> Path:
        return Path(out.path(name)) if hasattr(out, "path") else Path(out) / name

    def final(name: str) -> Path:
        return Path(out.final(name)) if hasattr(out, "final") else Path(out) / name

    table = f"{prefix}_share_vs_theta_r.csv"
    atomic_write_text(path(table), _table(sweep))
    stem = f"{prefix}_share_vs_theta_r"
    ax = plot_certified_share(sweep).ax
    try:
        meta = figure_metadata(f"stringstab {sweep.maps[0].version}",
                               json.dumps(sweep.summary(), ensure_ascii=False))
        save_figure(ax.figure, [(f, path(f"{stem}.{f}")) for f in formats], metadata=meta, dpi=dpi)
    finally:
        pyplot().close(ax.figure)
    written = [final(table), *(final(f"{stem}.{f}") for f in formats)]
    for th, m in zip(sweep.reaction_delays, sweep.maps):
        written += save_region_outputs(m, out, prefix=sweep_prefix(prefix, float(th)),
                                       formats=formats, dpi=dpi, figures=figures, csv=csv)
    return written
