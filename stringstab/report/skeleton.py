"""The skeleton every command's report shares: the grid it ran on and its closing figures.

A command's report (:mod:`stringstab.report.commands`, :mod:`stringstab.report.radio`,
:mod:`stringstab.report.reaction_sweep`) is a :class:`~stringstab.report.render.Report` with the
command line, the settings, the sections of that command, and last the figures among the files
it wrote.  The pieces written once here: which files are figures (:func:`image_names`), the
closing section (:func:`add_figures`) and a grid's axes as settings (:func:`grid_axes`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any

from .render import Report

__all__ = ["IMAGE_SUFFIXES", "add_figures", "grid_axes", "image_names"]

#: The file endings a report shows as figures.
IMAGE_SUFFIXES = (".png", ".svg", ".jpg")


def image_names(names: Iterable[Any]) -> list[str]:
    """The figures among ``names``, in order, as strings.

    Parameters
    ----------
    names : iterable of str or path-like
        File names (as the report links them).

    Returns
    -------
    list of str
        Those ending in one of :data:`IMAGE_SUFFIXES`.

    Examples
    --------
    >>> image_names(["map.png", "map.csv", "a/b.svg"])
    ['map.png', 'a/b.svg']
    """
    return [str(n) for n in names if str(n).endswith(IMAGE_SUFFIXES)]


def add_figures(rep: Report, names: Iterable[Any],
                caption: Callable[[str], str | None] | None = None) -> None:
    """Close ``rep`` with a "Figures" section of the figures among ``names`` (none: no section).

    Parameters
    ----------
    rep : Report
        The report.
    names : iterable of str or path-like
        The files the command wrote, as the report links them.
    caption : callable, optional
        ``caption(name)``: each figure's caption; without it the figures are shown uncaptioned
        (:meth:`~stringstab.report.render.Section.figures`).
    """
    figs = image_names(names)
    if not figs:
        return
    sec = rep.section("Figures")
    if caption is None:
        sec.figures(figs)
        return
    for f in figs:
        sec.figure(f, caption(f))


def grid_axes(axes: Mapping[str, Any]) -> dict[str, str]:
    """A map's grid as report settings: ``{axis: "[lo, hi] in n points"}``.

    Parameters
    ----------
    axes : mapping of str to sequence of float
        Each axis's grid values (:attr:`stringstab.regions.RegionMap.axes`).

    Returns
    -------
    dict of str to str

    Examples
    --------
    >>> grid_axes({"k_x": [-2.0, 0.0, 2.0]})
    {'k_x': '[-2, 2] in 3 points'}
    """
    return {n: f"[{a[0]:g}, {a[-1]:g}] in {len(a)} points" for n, a in axes.items()}
