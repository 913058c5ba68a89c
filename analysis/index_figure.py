"""The docs' landing-page figure: a disturbance that shrinks, and one that grows, along a platoon.

Run: ``python analysis/index_figure.py`` (writes docs/figures/index_string_stability.png).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
from matplotlib.figure import Figure

import stringstab as ss
from stringstab.plots import plot_vehicles
from stringstab.traffic.controllers import LinearController
from stringstab.traffic.leaders import leader_by_name
from stringstab.traffic.platoon import simulate

OUT = Path(__file__).resolve().parents[1] / "docs" / "figures" / "index_string_stability.png"


def main() -> None:
    leader = leader_by_name("mix", duration=60.0)
    fig = Figure(figsize=(10, 3.4), layout="constrained")
    axes = fig.subplots(1, 2, sharey=True)
    for ax, K in zip(axes, [(1.2, 0.5, 0.6), (0.9, -0.5, 1.1)]):
        c = ss.certify(*K, tau=0.1, delta=0.2, headway=1.1)
        res = simulate(leader, LinearController(*K, headway=1.1), 8, tau=0.1, delta=0.2)
        lc = plot_vehicles(res.t, res.accel, ax=ax, n_positions=8)["lines"]
        ax.set_title(f"K = {K}: {c.verdict.replace('_', ' ')} (sup|Γ| = {c.sup_gain:.3f})",
                     fontsize=10)
        ax.set_xlabel("time t (s)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("acceleration (m/s²)")
    fig.colorbar(lc, ax=list(axes), label="position (0 = leader)")
    fig.savefig(OUT, dpi=90)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
