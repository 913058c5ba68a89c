"""Every figure of the toolkit, under one roof, in python-control's pattern.

Compute a result object first, then draw it: each plot function takes the result
(:class:`~stringstab.regions.RegionMap`, :class:`~stringstab.tuning.TuneResult`,
:class:`~stringstab.traffic.PlatoonResult`, ...) and ``ax=None`` (``axes=None``/``fig=None``
for several panels), and returns a :class:`PlotResult` (the figure, the axes and the named
artists), so figures can be composed and tested.

=============================  ===============================================================
module / function              shows
=============================  ===============================================================
**region maps**                (:mod:`~stringstab.plots.regions`, ``regions_3d``, ``region_sets``)
:func:`plot_class_map`         classes of one method (types, or exact verdicts)
:func:`plot_comparison`        where exact, taylor and printed agree and disagree
:func:`plot_sup_gain`          sup_ω |Γ(jω)| (log scale), with the certified boundary
:func:`plot_slices`            a 3-D map as a montage of slices over one gain
:func:`plot_region_3d`         the boundary of the certified region in 3-D
:func:`plot_facets`            one class map per τ (or δ): how the region shrinks
:func:`plot_boundaries`        the certified boundaries of several maps on one axes
:func:`plot_certified_share`   certified share vs θ_r (files: save_reaction_sweep_outputs)
**gain trajectories**          (:mod:`stringstab.plots.trajectory`)
:func:`trajectory_verdicts`    the exact verdict of each triple for a map's loop (compute)
:func:`plot_trajectory`        a policy's gain trajectory over a map, by verdict
**files of a map**             (:mod:`stringstab.plots.outputs`)
:func:`save_figures`           the standard figures of a map, in every format
:func:`save_region_outputs`    a map's NPZ, CSV and figures, shared by two processes
:func:`writes_csv`             whether it writes the CSV (2-D, <= CSV_MAX_POINTS unless asked)
:func:`start_output_helper`    the second of those processes, started (and warming up) early
**gain repair**                (:mod:`stringstab.plots.tuning`)
:func:`moves_projection`       the certified region over the repairs' k_a (compute)
:func:`plot_moves`             repairs K0 → K over the certified region
**platoons**                   (:mod:`stringstab.plots.traffic`)
:func:`plot_vehicles`          one line per vehicle, coloured by position
:func:`plot_platoon`           speed, acceleration, spacing, headway (IDL Figs 7-8)
:func:`plot_damping_ratios`    m_p of each follower (IDL eq 29)
**mixed strings**              (:mod:`stringstab.plots.mixed`)
:func:`plot_head_to_tail`      ∏|Γ_i(jω)| of strings, with the data's first-to-last |Ĝ|
:func:`plot_replay_speeds`     the leader's and the last car's speed in each replay
:func:`plot_replay_energy`     the acceleration-energy ratio to the leader along the string
=============================  ===============================================================

matplotlib is imported on first use.
"""

from __future__ import annotations

from ..io.figures import FIGURE_FORMATS
from ._common import (
    CLASS_COLORS,
    GAIN_LABELS,
    OKABE_ITO,
    PlotResult,
    dry_runs_without_images,
    share_mathtext_parser,
    warm_up,
)
from .mixed import plot_head_to_tail, plot_replay_energy, plot_replay_speeds
from .outputs import (
    CSV_MAX_POINTS,
    FIGURE_SETS,
    draw_figure,
    figure_stems,
    save_figures,
    save_region_outputs,
    start_output_helper,
    writes_csv,
)
from .reaction_sweep import plot_certified_share, save_reaction_sweep_outputs
from .region_sets import plot_boundaries, plot_facets
from .regions import plot_class_map, plot_comparison, plot_sup_gain
from .regions_3d import plot_region_3d, plot_slices
from .traffic import plot_damping_ratios, plot_platoon, plot_vehicles
from .trajectory import plot_trajectory, trajectory_verdicts
from .tuning import moves_projection, moves_region, plot_moves

__all__ = [
    "CLASS_COLORS",
    "CSV_MAX_POINTS",
    "FIGURE_FORMATS",
    "FIGURE_SETS",
    "GAIN_LABELS",
    "OKABE_ITO",
    "PlotResult",
    "draw_figure",
    "dry_runs_without_images",
    "figure_stems",
    "moves_projection",
    "moves_region",
    "plot_boundaries",
    "plot_certified_share",
    "plot_class_map",
    "plot_comparison",
    "plot_damping_ratios",
    "plot_facets",
    "plot_head_to_tail",
    "plot_moves",
    "plot_platoon",
    "plot_region_3d",
    "plot_replay_energy",
    "plot_replay_speeds",
    "plot_slices",
    "plot_sup_gain",
    "plot_trajectory",
    "plot_vehicles",
    "save_figures",
    "save_reaction_sweep_outputs",
    "save_region_outputs",
    "share_mathtext_parser",
    "start_output_helper",
    "trajectory_verdicts",
    "warm_up",
    "writes_csv",
]
