"""The IDL paper's numbers that a sweep is compared with (Yi, Xu, Wang 2026, §5).

Transcribed from the paper's text (Tables 3 and 5, §5 (2)); they are the values to compare
with, never used to compute anything.  Figs 4 and 5 are plots without printed values: the text
gives only their conclusions (:data:`FIG4_CHOICE`, :data:`FIG5_BEST_SIGMA`).
"""

from __future__ import annotations

__all__ = ["FIG4_ARCHITECTURES", "FIG4_CHOICE", "FIG5_BEST_SIGMA", "FIG5_SIGMAS", "TABLE3",
           "TABLE5", "TABLE_METRICS"]

#: Columns of Tables 3 and 5 (all lower is better): TIT (eq 32), M_CI (eq 34), M_effi (eq 35),
#: M_lss (eq 30).
TABLE_METRICS = ("TIT", "M_CI", "M_effi", "M_lss")

#: Table 3, "Performance metrics under different reward weight settings for Pareto front
#: exploration": label → (weights [ω1 safety, ω2 comfort, ω3 efficiency], TIT, M_CI, M_effi, M_lss).
TABLE3: dict[str, tuple[tuple[float, float, float], float, float, float, float]] = {
    "Tradeoff": ((1 / 3, 1 / 3, 1 / 3), 0.32, 0.31, 1.41, 0.71),
    "Mild safety bias": ((0.4, 0.3, 0.3), 0.29, 0.35, 1.42, 0.72),
    "Strong safety bias": ((0.6, 0.2, 0.2), 0.19, 0.41, 1.45, 0.74),
    "Mild comfort bias": ((0.3, 0.4, 0.3), 0.37, 0.32, 1.43, 0.71),
    "Strong comfort bias": ((0.2, 0.6, 0.2), 0.46, 0.30, 1.42, 0.70),
    "Mild efficiency bias": ((0.3, 0.3, 0.4), 0.31, 0.35, 1.40, 0.72),
    "Strong efficiency bias": ((0.2, 0.2, 0.6), 0.34, 0.38, 1.39, 0.75),
}

#: Table 5, "Ablation studies for the reward function": label → (TIT, M_CI, M_effi, M_lss,
#: collisions).  "– Safety" has TIT = ∞ in the paper (printed as ∞).
TABLE5: dict[str, tuple[float, float, float, float, int]] = {
    "Full reward": (0.32, 0.31, 1.41, 0.71, 0),
    "- Safety": (float("inf"), 0.20, 1.32, 0.87, 2),
    "- Efficiency": (0.23, 0.19, 1.54, 0.67, 0),
    "- Comfort": (0.18, 1.34, 1.36, 0.92, 0),
}

#: Fig. 5: the noise levels σ studied, and the best σ per agent stated in §5 (2).
FIG5_SIGMAS = (0.05, 0.10, 0.15, 0.20, 0.25, 0.30)
FIG5_BEST_SIGMA = {"idl": 0.15, "td3": 0.25}

#: Fig. 4: the architectures compared (hidden widths) at σ = 0.2, and the one chosen.
FIG4_ARCHITECTURES = {"small": (64, 64), "medium": (128, 128), "large": (256, 256),
                      "extra large": (256, 256, 256)}
FIG4_CHOICE = (128, 128)
