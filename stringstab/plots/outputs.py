"""All the files of a region map at once: data and figures, shared between two processes.

:func:`save_region_outputs` writes what ``stringstab region`` writes — the NPZ archive, the
CSV table (2-D maps) and the standard figures (:func:`~stringstab.plots.save_figures`) — and
splits that work between this process and one forked process (on a machine with two cores,
writing is then about half as long): the tasks (the NPZ, the CSV, one task per figure) are
dealt out by their estimated cost, the larger first, each to the process with less work so
far (the longest-processing-time rule); each task writes its own file.  Files are staged in a
:class:`stringstab.io.OutputDir` or written into a folder.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..regions import RegionMap
from ..regions.pool import in_background
from .regions import FIGURE_FORMATS, figure_stems, save_figures, trajectory_verdicts

__all__ = ["save_region_outputs"]

#: Estimated costs (s) on one core: per grid point of the NPZ archive and per CSV row and
#: column; per figure file; importing pyplot in a process.  Only their ratios matter.
_NPZ_PER_POINT = 0.35e-6
_CSV_PER_CELL = 0.075e-6
_FIGURE_FILE = {"png": 0.3, "pdf": 0.4, "svg": 0.55}
_PYPLOT = 0.3


def _plan(rmap: RegionMap, stems: Sequence[str], formats: Sequence[str],
          processes: int) -> list[list[tuple[Any, ...]]]:
    """The tasks of each process (0 is this one), dealt out by estimated cost."""
    tasks: list[tuple[float, tuple[Any, ...]]] = [(_NPZ_PER_POINT * rmap.size, ("npz",))]
    if rmap.ndim == 2:
        tasks.append((_CSV_PER_CELL * rmap.n_columns * rmap.size, ("csv",)))
    tasks += [(sum(_FIGURE_FILE[f] for f in formats), ("fig", s)) for s in stems]
    load = [0.0] * processes
    plan: list[list[tuple[Any, ...]]] = [[] for _ in range(processes)]
    cold = "matplotlib.pyplot" not in sys.modules  # else forked processes inherit it

    def cost_in(k: int, cost: float, task: tuple[Any, ...]) -> float:
        # the first figure of a process also pays for importing pyplot there
        first = task[0] == "fig" and not any(t[0] == "fig" for t in plan[k])
        return cost + (_PYPLOT if first and cold else 0.0)

    for cost, task in sorted(tasks, key=lambda t: -t[0]):
        k = min(range(processes), key=lambda i: load[i] + cost_in(i, cost, task))
        load[k] += cost_in(k, cost, task)
        plan[k].append(task)
    return plan


def _run(tasks: Sequence[tuple[Any, ...]], rmap: RegionMap, out: Any, prefix: str,
         formats: Sequence[str], gains: Any, verdicts: Any, dpi: int) -> None:
    """Do ``tasks`` (in this process or a forked one): each writes its own staged file."""
    stems = [t[1] for t in tasks if t[0] == "fig"]
    for t in tasks:
        if t[0] == "npz":
            rmap.save_npz(_stage(out, f"{prefix}.npz"))
        elif t[0] == "csv":
            rmap.save_csv(_stage(out, f"{prefix}.csv"))
    if stems:
        import matplotlib

        if "matplotlib.pyplot" not in sys.modules:
            matplotlib.use("Agg")
        save_figures(rmap, out, prefix=prefix, formats=formats, gains=gains, verdicts=verdicts,
                     dpi=dpi, stems=stems)


def _stage(out: Any, name: str) -> Path:
    return Path(out.path(name)) if hasattr(out, "path") else Path(out) / name


def _final(out: Any, name: str) -> Path:
    return Path(out.final(name)) if hasattr(out, "final") else Path(out) / name


def save_region_outputs(
    rmap: RegionMap, out: Any, *, prefix: str = "region", formats: Sequence[str] = ("png", "pdf"),
    gains: Any = None, verdicts: Any = None, dpi: int = 150, processes: int = 2,
) -> list[Path]:
    """Write ``<prefix>.npz``, ``<prefix>.csv`` (2-D maps) and the standard figures.

    Parameters
    ----------
    rmap : RegionMap
        The map.
    out : path or OutputDir
        An existing folder, or an :class:`stringstab.io.OutputDir` inside its ``with``
        block (the files appear when its run succeeds).
    prefix, formats, gains, verdicts, dpi
        As for :func:`~stringstab.plots.save_figures` (``verdicts`` are computed here,
        once, when ``gains`` come without them).
    processes : int
        1 writes everything here; 2 (default) shares the work with one forked process.

    Returns
    -------
    list of Path
        The files written (their final paths): the NPZ, the CSV, then the figures.

    Raises
    ------
    StringStabError
        On a bad format, or when a file cannot be written (in either process).

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> from stringstab.regions import region_map
    >>> m = region_map({"k_x": np.linspace(-2, 2, 5), "k_v": np.linspace(-2, 2, 5)},
    ...                {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1, methods="taylor")
    >>> [p.name for p in save_region_outputs(m, tempfile.mkdtemp(), formats=("png",), dpi=20)]
    ['region.npz', 'region.csv', 'region_class_taylor.png']
    """
    for f in formats:
        if f not in FIGURE_FORMATS:
            from ..errors import StringStabError

            raise StringStabError(f"figure formats must be among {list(FIGURE_FORMATS)}; got {f!r}")
    if gains is not None and verdicts is None:
        verdicts = trajectory_verdicts(rmap, gains)
    stems = figure_stems(rmap, gains is not None)
    names = [f"{prefix}.npz", *([f"{prefix}.csv"] if rmap.ndim == 2 else []),
             *(f"{prefix}_{s}.{f}" for s in stems for f in formats)]
    for name in names:  # register every output here, whichever process writes it
        _stage(out, name)
    plan = _plan(rmap, stems, formats, max(1, int(processes)))
    args = (rmap, out, prefix, formats, gains, verdicts, dpi)
    join = in_background(_run, plan[1], *args) if len(plan) > 1 and plan[1] else None
    try:
        _run(plan[0], *args)
    finally:
        if join is not None:
            join()
    return [_final(out, n) for n in names]
