"""Saving a drawn figure: each format at once, with its metadata, every file complete or absent.

:func:`save_figure` writes a matplotlib figure in the formats asked (:data:`FIGURE_FORMATS`),
each through :func:`~stringstab.io.atomic_path` (a temporary file renamed into place), with
the metadata of :func:`figure_metadata` in the file itself: PNG ``Software`` and
``Description`` text chunks, PDF ``Creator`` and ``Subject``, SVG ``Creator`` and
``Description``.  Knows nothing of what the figure shows; matplotlib is not imported here.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from ..errors import StringStabError
from .outputs import atomic_path

__all__ = ["FIGURE_FORMATS", "check_figure_formats", "figure_metadata", "save_figure"]

#: File formats :func:`save_figure` writes.
FIGURE_FORMATS: tuple[str, ...] = ("png", "pdf", "svg")


def check_figure_formats(formats: Iterable[str]) -> tuple[str, ...]:
    """The formats, checked to be among :data:`FIGURE_FORMATS`.

    Parameters
    ----------
    formats : iterable of str
        File formats (``"png"``, ``"pdf"``, ``"svg"``).

    Returns
    -------
    tuple of str
        The same formats, in order.

    Raises
    ------
    StringStabError
        On a format that is not among :data:`FIGURE_FORMATS`.
    """
    out = tuple(formats)
    for f in out:
        if f not in FIGURE_FORMATS:
            raise StringStabError(f"figure formats must be among {list(FIGURE_FORMATS)}; got {f!r}")
    return out


def figure_metadata(software: str, description: str) -> dict[str, dict[str, str]]:
    """The metadata of a figure file in each format, under that format's own keys.

    Parameters
    ----------
    software : str
        What wrote the file (e.g. ``"stringstab 1.2.0"``).
    description : str
        What the figure shows (e.g. a map's parameters as JSON).

    Returns
    -------
    dict
        Format → the ``metadata`` argument of :meth:`matplotlib.figure.Figure.savefig`.

    Examples
    --------
    >>> figure_metadata("stringstab 1", "{}")["pdf"]
    {'Creator': 'stringstab 1', 'Subject': '{}'}
    """
    return {
        "png": {"Software": software, "Description": description},
        "pdf": {"Creator": software, "Subject": description},
        "svg": {"Creator": software, "Description": description},
    }


def save_figure(fig: Any, targets: Sequence[tuple[str, str | os.PathLike[str]]], *,
                metadata: Mapping[str, Mapping[str, str]] | None = None,
                dpi: int = 150) -> list[Path]:
    """Save ``fig`` once per ``(format, path)`` of ``targets``, each file atomically.

    The bounding box is tight (0.1 inch of padding): whatever the layout engine could not fit
    (a long title, a wide legend under the axes) is kept in the file rather than cut off.

    Parameters
    ----------
    fig : matplotlib Figure
        The drawn figure (not closed here).
    targets : sequence of (str, path)
        The format (among :data:`FIGURE_FORMATS`) and the file of each copy.
    metadata : mapping, optional
        Format → the metadata written in the file (:func:`figure_metadata`).
    dpi : int, default 150
        Resolution of raster formats.

    Returns
    -------
    list of Path
        The files written.

    Raises
    ------
    StringStabError
        On an unknown format, or when a file cannot be written (that file is left as it was).
    """
    check_figure_formats(f for f, _ in targets)
    written = []
    for f, path in targets:
        with atomic_path(path, what="figure") as tmp:
            fig.savefig(tmp, format=f, dpi=dpi, metadata=dict((metadata or {}).get(f, {})),
                        bbox_inches="tight", pad_inches=0.1)
        written.append(Path(path))
    return written
