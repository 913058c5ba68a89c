"""The run report of ``stringstab region`` with a map per reaction delay θ_r (issue 25)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from .render import Report
from .skeleton import add_figures, grid_axes

__all__ = ["reaction_sweep_report"]


def reaction_sweep_report(sweep: Any, files: Sequence[Any], *, command: str,
                          started: float | None = None) -> Report:
    """The report of ``stringstab region --reaction-delay A,B,...``.

    The grid, the certified share at each θ_r (a table), each map's report, and every figure.

    Parameters
    ----------
    sweep : ReactionSweep
        The maps (:func:`stringstab.regions.reaction_sweep`).
    files : sequence of path-like
        The files written (only their names are used; images become figures).
    command : str
        The command line.
    started : float, optional
        ``time.perf_counter()`` at the start of the command.

    Returns
    -------
    Report
        The report, to :meth:`~stringstab.report.Report.write`.
    """
    first = sweep.maps[0]
    axes = grid_axes(first.axes)
    th = ", ".join(f"{v:g}" for v in sweep.reaction_delays)
    rep = Report("Map of the string-stable gains per reaction delay θ_r", command=command,
                 params={**axes, **dict(first.fixed), "loop": first.title(),
                         "reaction delays θ_r [s]": th},
                 intro="The same grid of gain triples K = (k_x, k_v, k_a) judged by the exact "
                       "certificate at each reaction delay θ_r (the whole command applied θ_r "
                       "late, τ a' = u(t − θ_r) − a): internal stability of the retarded "
                       "quasi-polynomial and ‖Γ‖∞ ≤ 1, both exact in δ and θ_r.",
                 started=started)
    sec = rep.section("Certified share vs θ_r")
    sec.table([{"θ_r [s]": r["reaction_delay"], "certified points": r["certified"],
                "certified (%)": 100 * r["certified_share"],
                "inconclusive (%)": 100 * r["inconclusive_share"]} for r in sweep.rows()],
              caption="Share of the grid the exact certificate certifies at each θ_r.", digits=4)
    sec.code(sweep.report())
    add_figures(rep, (Path(str(f)).name for f in files))
    return rep
