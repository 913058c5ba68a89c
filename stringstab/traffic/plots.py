"""Figures of a simulated platoon: now in :mod:`stringstab.plots.traffic`, re-exported here."""

from __future__ import annotations

from ..plots.traffic import plot_damping_ratios, plot_platoon, plot_vehicles

__all__ = ["plot_damping_ratios", "plot_platoon", "plot_vehicles"]
