"""The files of a region map: its standard figures, and all its files at once in two processes.

:func:`figure_stems` names the standard figures of a map and :func:`draw_figure` draws one;
:func:`save_figures` draws them and saves each in every format (:func:`stringstab.io.save_figure`),
optionally in worker processes (:func:`stringstab.parallel.map_processes`).

:func:`save_region_outputs` writes what ``stringstab region`` writes — the NPZ archive, the
CSV table (2-D maps of at most :data:`CSV_MAX_POINTS` points unless asked, :func:`writes_csv`)
and the standard figures — and splits that work between this process
and a helper process: this one writes the data files (the NPZ, the CSV), the helper the
figures, shared among processes forked from it (two on a machine with two cores), which
inherit its warm plotting code: matplotlib is imported once.  The helper is a
:func:`stringstab.parallel.start_helper` (the package's start-method policy);
:func:`start_output_helper` starts one early, before a map's worker pool, so that it imports
and warms up the plotting code while the map is computed.  Files are staged in a
:class:`stringstab.io.OutputDir` or written into a folder.

Every function here draws results computed beforehand: a gain trajectory comes with its
verdicts (:func:`~stringstab.plots.trajectory_verdicts`).
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ..errors import StringStabError
from ..io.figures import check_figure_formats, figure_metadata, save_figure
from ..parallel import Helper, cpu_count, map_processes, start_helper
from ..regions import RegionMap
from ._common import dry_runs_without_images, pyplot, share_mathtext_parser
from .map_axes import method_title
from .projection import plot_projected_region, projected_region
from .regions import plot_class_map, plot_comparison, plot_sup_gain
from .regions_3d import plot_region_3d, plot_slices
from .trajectory import gain_rows, plot_trajectory

__all__ = ["CSV_MAX_POINTS", "FIGURE_SETS", "draw_figure", "figure_stems", "save_figures",
           "save_region_outputs", "start_output_helper", "writes_csv"]

#: The largest 2-D map whose CSV table :func:`save_region_outputs` writes by default (issue 31):
#: 300,000 points (a 547 x 547 slice, a CSV of about 28 MB).  Above it the CSV is written only
#: when asked (``csv=True``, ``stringstab region --csv``): an 801 x 801 map's is 60 MB and costs
#: more than every other file written after the map, while the NPZ (about 5 MB) holds the same
#: columns (:func:`stringstab.regions.load_npz`).
CSV_MAX_POINTS = 300_000


#: The figure sets of a 2-D map (issue 31): ``default`` draws the class map of the first method
#: only (with :func:`figure_stems`' comparison and sup|Γ| maps), ``all`` every method's.
FIGURE_SETS = ("default", "all")


def figure_stems(rmap: RegionMap, overlay: bool = False, figures: str = "default") -> list[str]:
    """The names (without prefix and format) of the standard figures of ``rmap``.

    2-D map: ``class_<method>`` for the first method (for each method with ``figures="all"``,
    or when there is one), ``compare`` (two or more methods, which draws where they
    disagree), ``sup_gain`` (``exact``) and, with ``overlay``, ``overlay``.  3-D map:
    ``slices_<method>`` and ``3d_<method>`` for each method, whatever ``figures``.

    Parameters
    ----------
    rmap : RegionMap
        The computed map.
    overlay : bool, default False
        Include the ``overlay`` figure (2-D maps only; it needs gains to draw).
    figures : {"default", "all"}, default "default"
        Which class maps of a 2-D map with two or more methods: the first method's only, or
        every method's (:data:`FIGURE_SETS`).

    Returns
    -------
    list of str
        The stems, in drawing order.

    Raises
    ------
    StringStabError
        On a ``figures`` not in :data:`FIGURE_SETS`.

    Examples
    --------
    >>> import numpy as np
    >>> from stringstab.regions import region_map
    >>> m = region_map({"k_x": np.linspace(-2, 2, 3), "k_v": np.linspace(-2, 2, 3)},
    ...                {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1, methods="taylor,printed")
    >>> figure_stems(m), figure_stems(m, figures="all")
    (['class_taylor', 'compare'], ['class_taylor', 'class_printed', 'compare'])
    """
    if figures not in FIGURE_SETS:
        raise StringStabError(f"figures must be one of {', '.join(FIGURE_SETS)}; got {figures!r}")
    if rmap.ndim == 2:
        classes = rmap.methods if figures == "all" else rmap.methods[:1]
        stems = [f"class_{m}" for m in classes]
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
        One of :func:`figure_stems` ``(rmap, True, "all")``.
    gains : GainTable or array_like of shape (n, 3), optional
        The gain trajectory; required for ``overlay`` (drawn over the exact region projected
        over the points' own values of the map's fixed gain, computed here).
    verdicts : CertificateBatch or sequence of str, optional
        The exact verdict of each gain triple (:func:`~stringstab.plots.trajectory_verdicts`);
        required for ``overlay``.

    Returns
    -------
    matplotlib Figure
        The new figure (the caller saves and closes it).

    Raises
    ------
    StringStabError
        On an unknown stem, or ``overlay`` without valid gains and their verdicts.
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
        if gains is None or verdicts is None:
            raise StringStabError("the overlay figure needs the gains and their verdicts "
                                  "(plots.trajectory_verdicts); got "
                                  f"{'no gains' if gains is None else 'no verdicts'}")
        K, _ = gain_rows(gains)
        xy = K[:, [("k_x", "k_v", "k_a").index(a) for a in rmap.axis_names]]
        lo = min(min(float(a[0]) for a in rmap.axes.values()), float(xy.min()))
        hi = max(max(float(a[-1]) for a in rmap.axes.values()), float(xy.max()))
        pad = 0.03 * (hi - lo)
        p = rmap.params
        proj = projected_region(K, tau=p.tau, delta=p.delta, headway=p.headway,
                                plane=(rmap.axis_names[0], rmap.axis_names[1]), bounds=(lo - pad, hi + pad),
                                sample_time=rmap.sample_time, n=81)
        loop = "; ".join(t for t in rmap.title().split("; ") if not t.startswith(tuple(rmap.fixed)))
        ax = plot_projected_region(proj, title=f"{method_title(rmap, 'exact')}; {loop}").ax
        plot_trajectory(rmap, gains, ax=ax, verdicts=verdicts)
        return ax.figure
    if stem.startswith("slices_"):
        return plot_slices(rmap, stem[len("slices_"):]).figure
    if stem.startswith("3d_"):
        return plot_region_3d(rmap, stem[len("3d_"):]).figure
    raise StringStabError(f"unknown figure {stem!r}; expected one of {figure_stems(rmap, True, 'all')}")


def save_figures(
    rmap: RegionMap, out: Any, *, prefix: str = "region",
    formats: Sequence[str] = ("png", "pdf"), gains: Any = None, verdicts: Any = None,
    dpi: int = 150, workers: int = 1, stems: Sequence[str] | None = None,
    figures: str = "default",
) -> list[Path]:
    """Draw the standard figures of a map and save each in every format.

    Each file carries the tool version and :meth:`RegionMap.metadata` (τ, δ,
    T*, axes, methods) as JSON in its own metadata (:func:`stringstab.io.figure_metadata`)
    and is written atomically (:func:`stringstab.io.save_figure`).  The figures are
    :func:`figure_stems`, saved as ``<prefix>_<stem>.<format>``.

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
        The exact verdicts of ``gains``, computed beforehand
        (:func:`~stringstab.plots.trajectory_verdicts`); required with ``gains``.
    dpi : int
        Resolution of raster formats.
    workers : int
        Processes drawing the figures (:func:`stringstab.parallel.map_processes`; 1 draws
        them here, one after another).
    stems : sequence of str, optional
        Draw these of :func:`figure_stems` ``(rmap, overlay, "all")`` (default: those of
        ``figures``).
    figures : {"default", "all"}, default "default"
        Without ``stems``: the first method's class map only, or every method's
        (:func:`figure_stems`).

    Returns
    -------
    list of Path
        The files written (their final paths).

    Raises
    ------
    StringStabError
        On an unknown format or figure set, ``gains`` with a 3-D map, or ``gains`` without
        ``verdicts``.
    """
    formats = check_figure_formats(formats)
    if gains is not None and rmap.ndim != 2:
        raise StringStabError(f"a gain trajectory can be overlaid on a 2-D map only; got a {rmap.ndim}-D map")
    _need_verdicts(gains, verdicts)
    every = figure_stems(rmap, gains is not None, "all")
    if stems is None:
        stems = figure_stems(rmap, gains is not None, figures)
    elif any(s not in every for s in stems):
        raise StringStabError(f"figures must be among {every}; got {list(stems)}")
    jobs = [(stem, [(f, _stage(out, f"{prefix}_{stem}.{f}")) for f in formats]) for stem in stems]
    map_processes(_FigureJob(rmap, gains, verdicts, dpi), jobs, workers)
    return [_final(out, f"{prefix}_{stem}.{f}") for stem in stems for f in formats]


class _FigureJob:
    """Draw one standard figure of a map and save it in its formats."""

    def __init__(self, rmap: RegionMap, gains: Any, verdicts: Any, dpi: int) -> None:
        self.rmap, self.gains, self.verdicts, self.dpi = rmap, gains, verdicts, dpi
        self.metadata = figure_metadata(f"stringstab {rmap.version}",
                                        json.dumps(rmap.metadata(), ensure_ascii=False))

    def __call__(self, job: tuple[str, list[tuple[str, Path]]]) -> None:
        stem, targets = job
        fig = draw_figure(self.rmap, stem, self.gains, self.verdicts)
        try:  # the tight box's dry run without the images: the same bytes, each image made once
            with dry_runs_without_images():
                save_figure(fig, targets, metadata=self.metadata, dpi=self.dpi)
        finally:
            pyplot().close(fig)


def _need_verdicts(gains: Any, verdicts: Any) -> None:
    """Refuse gains without their verdicts: the figures draw results, they do not compute them."""
    if gains is not None and verdicts is None:
        raise StringStabError("a gain trajectory needs its exact verdicts (verdicts=, e.g. from "
                              "stringstab.plots.trajectory_verdicts(rmap, gains)); got none")


def _warm_up_outputs(dpi: int = 150) -> None:
    """Import and warm up what drawing a map's figures needs: pyplot (Agg), a first figure.

    Run in the helper of :func:`start_output_helper` while the map is computed; the gain
    labels are parsed at ``dpi`` once for every figure (:func:`~stringstab.plots.warm_up`).
    """
    import matplotlib

    if "matplotlib.pyplot" not in sys.modules:
        matplotlib.use("Agg")
    from ._common import warm_up

    warm_up(dpi)


def start_output_helper(dpi: int = 150) -> Helper:
    """Start the helper process of :func:`save_region_outputs`, warming up now.

    Start it before the map's worker pool (both are then started from a single-threaded
    process, :mod:`stringstab.parallel`): it imports the plotting code and draws once while
    the map is computed, so that the figures it draws afterwards do not wait for that.

    Parameters
    ----------
    dpi : int, default 150
        The resolution the figures will be saved at (warmed up for it).

    Returns
    -------
    stringstab.parallel.Helper
        To pass to :func:`save_region_outputs` (``helper=``); use it as a context manager
        (leaving by an error stops it).
    """
    return start_helper(_warm_up_outputs, int(dpi), preload=("stringstab.plots.outputs",))


#: Drawing cost of a figure relative to a class map (measured on an 801² map: the sup|Γ| heat
#: map with its certified boundary, about twice as long); the costliest are drawn first.
_FIGURE_COST = {"sup_gain": 2.0, "overlay": 2.0}


def _draw_all(rmap: RegionMap, folder: Path, prefix: str, formats: Sequence[str],
              stems: Sequence[str], gains: Any, verdicts: Any, dpi: int, drawers: int) -> None:
    """The figures (in the helper): shared by ``drawers`` processes forked from it, warm.

    The drawers share one mathtext parser (:func:`share_mathtext_parser`).  The costliest
    first (the longest-processing-time rule), so that no drawer is left with a long figure at
    the end while the others wait.
    """
    import matplotlib

    if "matplotlib.pyplot" not in sys.modules:
        matplotlib.use("Agg")
    # each drawer forked below shares one parser among its renderers (a parser of its own: the
    # parses made here hold fonts whose file offset the drawers would share)
    share_mathtext_parser()
    order = sorted(stems, key=lambda s: -_FIGURE_COST.get(s, 1.0))
    save_figures(rmap, folder, prefix=prefix, formats=formats, gains=gains, verdicts=verdicts,
                 dpi=dpi, stems=order, workers=drawers)


def writes_csv(rmap: RegionMap, csv: bool | None = None) -> bool:
    """Whether :func:`save_region_outputs` writes the CSV table of ``rmap``: the one rule.

    A 3-D map: never.  A 2-D map: with ``csv=None`` (default) when it has at most
    :data:`CSV_MAX_POINTS` points, always with ``True``, never with ``False``.

    Parameters
    ----------
    rmap : RegionMap
        The map.
    csv : bool or None, default None
        ``None``: the size rule; ``True``: always (2-D); ``False``: never.

    Returns
    -------
    bool
        True when the CSV is written.

    Raises
    ------
    StringStabError
        When ``csv`` is not None, True or False.

    Examples
    --------
    >>> import numpy as np
    >>> from stringstab.regions import region_map
    >>> m = region_map({"k_x": np.linspace(-2, 2, 3), "k_v": np.linspace(-2, 2, 3)},
    ...                {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1, methods="taylor")
    >>> writes_csv(m), writes_csv(m, False)
    (True, False)
    """
    if csv is not None and not isinstance(csv, bool):
        raise StringStabError(f"csv must be None, True or False; got {csv!r}")
    if rmap.ndim != 2:
        return False
    return rmap.size <= CSV_MAX_POINTS if csv is None else csv


def _write_data(rmap: RegionMap, folder: Path, prefix: str, csv: bool) -> None:
    """The NPZ archive and, when ``csv`` (:func:`writes_csv`), the CSV table."""
    rmap.save_npz(folder / f"{prefix}.npz")
    if csv:
        rmap.save_csv(folder / f"{prefix}.csv")


def _stage(out: Any, name: str) -> Path:
    """Where to write ``name``: staged in an OutputDir (which registers it), or in the folder."""
    return Path(out.path(name)) if hasattr(out, "path") else Path(out) / name


def _final(out: Any, name: str) -> Path:
    """Where ``name`` will be once the run succeeds."""
    return Path(out.final(name)) if hasattr(out, "final") else Path(out) / name


def save_region_outputs(
    rmap: RegionMap, out: Any, *, prefix: str = "region", formats: Sequence[str] = ("png", "pdf"),
    gains: Any = None, verdicts: Any = None, dpi: int = 150, processes: int = 2,
    helper: Helper | None = None, figures: str = "default", csv: bool | None = None,
    meanwhile: Callable[[list[Path]], Any] | None = None,
) -> list[Path]:
    """Write ``<prefix>.npz``, ``<prefix>.csv`` (2-D maps, :func:`writes_csv`) and the figures.

    The CSV of a 2-D map is written by default when the map has at most
    :data:`CSV_MAX_POINTS` points (issue 31: an 801 x 801 map's is 60 MB; the NPZ holds the
    same columns).  The data files hold every method's fields; the figures are :func:`figure_stems`
    ``(rmap, gains is not None, figures)``: on a 2-D map with two or more methods, by default
    the first method's class map, the comparison and the sup|Γ| map (issue 31).

    Parameters
    ----------
    rmap : RegionMap
        The map.
    out : path or OutputDir
        An existing folder, or an :class:`stringstab.io.OutputDir` inside its ``with``
        block (the files appear when its run succeeds).
    prefix, formats, gains, verdicts, dpi
        As for :func:`save_figures` (``verdicts`` are required with ``gains``).
    processes : int
        1 writes everything here; 2 (default) shares the work with a helper process
        (:func:`stringstab.parallel.start_helper`, started now unless ``helper`` is given),
        which draws the figures in processes forked from it while this one writes the data.
    helper : stringstab.parallel.Helper, optional
        A helper started earlier by :func:`start_output_helper` (warm); it draws the figures
        (whatever ``processes``), and is done with when this returns.
    figures : {"default", "all"}, default "default"
        The class maps of a 2-D map with two or more methods: the first method's only, or
        every method's (:func:`figure_stems`).
    csv : bool or None, default None
        The CSV table of a 2-D map: ``None`` writes it when the map has at most
        :data:`CSV_MAX_POINTS` points, ``True`` always, ``False`` never (:func:`writes_csv`;
        a 3-D map has none).
    meanwhile : callable, optional
        Called here with the files' final paths once the data files are written, while the
        figures are still drawn (e.g. to build a report of them: ``stringstab region``);
        when the figures are drawn here, after them.

    Returns
    -------
    list of Path
        The files written (their final paths): the NPZ, the CSV when written, then the figures.

    Raises
    ------
    StringStabError
        On a bad format, figure set or ``csv``, ``gains`` without ``verdicts``, or when a file
        cannot be written (in either process).

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> from stringstab.regions import region_map
    >>> m = region_map({"k_x": np.linspace(-2, 2, 5), "k_v": np.linspace(-2, 2, 5)},
    ...                {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1, methods="taylor")
    >>> [p.name for p in save_region_outputs(m, tempfile.mkdtemp(), formats=("png",), dpi=20)]
    ['region.npz', 'region.csv', 'region_class_taylor.png']
    >>> [p.name for p in save_region_outputs(m, tempfile.mkdtemp(), formats=("png",), dpi=20,
    ...                                      csv=False)]
    ['region.npz', 'region_class_taylor.png']
    """
    formats = check_figure_formats(formats)
    _need_verdicts(gains, verdicts)
    with_csv = writes_csv(rmap, csv)
    stems = figure_stems(rmap, gains is not None, figures)
    names = [f"{prefix}.npz", *([f"{prefix}.csv"] if with_csv else []),
             *(f"{prefix}_{s}.{f}" for s in stems for f in formats)]
    folder = Path()
    for name in names:  # register every output here, whichever process writes it
        folder = _stage(out, name).parent
    drawing = (rmap, folder, prefix, formats, stems, gains, verdicts, dpi)
    final = [_final(out, n) for n in names]
    if helper is None and (int(processes) <= 1 or not stems):
        _write_data(rmap, folder, prefix, with_csv)
        _draw_all(*drawing, 1)
        if meanwhile is not None:
            meanwhile(final)
        return final
    if helper is None:
        helper = start_helper()
    with helper:  # the figures there (in its forked drawers), the data files here
        helper.submit(_draw_all, *drawing, min(max(2, cpu_count() - 1), len(stems)))
        _write_data(rmap, folder, prefix, with_csv)
        if meanwhile is not None:
            meanwhile(final)
        helper.result()
    return final
