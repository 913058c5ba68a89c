"""What to see in each figure the toolkit writes, keyed by file-name pattern.

A command adds a figure to its report by path; the caption comes from here unless it gives one,
so a figure says the same thing in every report.  Patterns are :mod:`fnmatch` patterns on the file
name (not the folder), tried in order.
"""

from __future__ import annotations

from fnmatch import fnmatch
from pathlib import PurePosixPath

__all__ = ["CAPTIONS", "caption_for"]

#: ``(pattern, caption)``: the first pattern matching a figure's file name gives its caption.
CAPTIONS: list[tuple[str, str]] = [
    # region maps (stringstab region; plots.save_region_outputs)
    ("*_class_exact.*", "The exact, delay-aware certificate on the gain slice: blue gains are "
     "string stable (‖Γ‖∞ ≤ 1, internally stable), orange are internally stable but amplify "
     "some frequency, grey are not internally stable; black cells are inconclusive (on the "
     "boundary within rounding). The legend gives each class's share of the grid."),
    ("*_class_taylor.*", "What the second-order Taylor criteria (Ψ1–Ψ3 derived from the model) "
     "say on the same slice: an approximation, shown to compare with the exact map, never a "
     "verdict."),
    ("*_class_printed.*", "What the IDL paper's printed Proposition 1 says on the same slice "
     "(its printed Ψ formulas, errata included): compare with the exact map to see where a reader "
     "of the paper would be misled."),
    ("*_share_vs_theta_r.*", "The share of the gain grid the exact certificate certifies at "
     "each reaction delay θ_r (the whole command applied θ_r late), the slices at each θ_r "
     "beside it; a dashed line gives the inconclusive share when there is one."),
    ("*_class_continuous.*", "The continuous-time certificate on the same slice, to compare with "
     "the sampled-data map: the gains it certifies that sampling loses are the difference."),
    ("*_compare.*", "Where the three verdicts (exact, Taylor, printed) agree and where they "
     "differ; each disagreement class is a colour with its count. Few coloured cells outside "
     "'all 3 agree' means the approximations are right on this slice."),
    ("*_sup_gain.*", "sup_ω |Γ(jω)| (log colour scale, from 1) over the internally stable gains, "
     "with the certified boundary sup |Γ| = 1 drawn: darkest blue is certified; the brighter, the "
     "more a disturbance grows from vehicle to vehicle."),
    ("*_overlay.*", "The gains a policy executed, over the certified region: each marker shows "
     "the exact verdict of its own (k_x, k_v, k_a). The points do not share one k_a, so the "
     "background is not a slice: it is the certified region projected over the points' own k_a "
     "values (certified at every one, at some, at none), so a certified point never sits in "
     "the 'none' area."),
    ("*_3d.*", "The boundary of the certified region in (k_x, k_v, k_a): inside the surface the "
     "gains are string stable."),
    # simulate (traffic.output.write_run)
    ("platoon.png", "The platoon behind the leader (IDL Figs 7-8): speed, acceleration, "
     "bumper-to-bumper spacing and time headway of every vehicle over time, coloured by position "
     "(0 = leader). String stability shows as the acceleration peaks shrinking from follower to "
     "follower; the headway panel's scale stops at the 99.5th percentile and says so when a peak "
     "is clipped."),
    ("damping.png", "Disturbance damping along the platoon: m_p (eq 29, follower-to-predecessor "
     "acceleration energy) per follower; below 1 means the disturbance shrinks."),
    # identify
    ("fit_*", "A fitted follower: measured speeds of the predecessor and the follower and the "
     "follower's speed and gap simulated by the fitted model from the predecessor's measured "
     "speed, on each clean segment; the title gives the fitted parameters and the RMSE. The "
     "dashed curves tracking the black ones means the model explains the data."),
    ("transfer_*", "The fitted model's |Γ(jω)| (string stable where it stays below the dotted line "
     "at 1; its peak marked, the curve drawn from a decade below it) beside the data's own speed "
     "transfer |Ĝ(jω)| with ± two standard errors and its coherence; only coherent points "
     "(black) left of the grey band count for the data's verdict (in it common-mode GPS error "
     "dominates), and the log holds no frequency below its first point (light band). Agreement "
     "of the curve and the points means the verdict is the data's, not only the model's."),
    ("sup_gain.png", "Along the identified platoon: the model's sup|Γ| per follower with its 5-95 % "
     "bootstrap interval, and the data's own amplification (max |Ĝ| ± two standard errors, and "
     "the energy ratio); points above the dotted line at 1 amplify disturbances."),
    ("cars.png", "One row per car and distance setting (every log of it pooled): the model's "
     "sup|Γ| with its 5-95 % bootstrap interval and the data's own max |Ĝ| ± two standard errors, "
     "pooled over the car's logs; points above the dotted line at 1 amplify disturbances."),
    # tune
    ("tune_moves.png", "Each uncertified triple (numbered dot) and where each repair moved it "
     "(square: certified, cross: not), over the certified region projected over the repaired "
     "gains' own k_a values; the moves' lengths and the output k_a are in the table."),
    # hcfs verify
    ("speed_*", "Speeds of the leader and every follower (HCFS paper Fig. 4 layout), one panel "
     "per switching mode."),
    ("jerk_*", "Jerk of each follower, with the jerk limit J: the paper's switch may exceed J "
     "(its theorem needs a1 = a2); the jerk-safe variant stays within it."),
    ("switching_*", "Which controller (DDPG or CACC) each follower uses over time, per mode."),
    # train / evaluate / compare
    ("rolling_reward.png", "Training curve (IDL Fig. 3): the return of each training episode (grey "
     "dots) and its rolling mean over training episodes, with the paper's window of 10 and a "
     "window of 100; a mean is drawn only where its window is full, and a window longer than the "
     "run is named on the figure instead of drawn."),
    ("fig6_mp.png", "IDL paper Fig. 6: histogram of m_p per episode (orange bars) with its CDF "
     "(blue line, right axis), every episode drawn (the axis holds all values, so each CDF ends "
     "at 1); mass left of the dashed line at 1 means disturbances shrink."),
    ("fig9_ttc.png", "IDL paper Fig. 9: distribution of the time to collision at closing "
     "moments, on a log axis, as shares of all closing moments; the shaded range below TTC* is "
     "the safety-relevant one (counted in TIT), and the legend gives each strategy's share there "
     "and the share beyond the axis."),
    ("fig11_jerk.png", "IDL paper Fig. 11: share of all squared-jerk samples in each of the "
     "paper's ranges per strategy, and above its last range (> 60 m²/s⁶), counts on the bars, "
     "so every sample is counted (comfort: more mass in the low ranges is better)."),
    ("fig12_headway.png", "IDL paper Fig. 12: CDF of the time headway per strategy over all "
     "samples, drawn from 0 to 3 s, with the desired headway T*; the legend gives the shares off "
     "the axis."),
    ("gains_region.png", "The gains each strategy executed (coloured by strategy) over the "
     "certified region projected over the executed k_a values (certified at every one, at some, "
     "at none); the axes extend past the ±2 gain bounds so gains on a bound are visible."),
]


def caption_for(path: str) -> str:
    """The registered caption of a figure file.

    Parameters
    ----------
    path : str
        The figure's path (only the file name is matched).

    Returns
    -------
    str
        Its caption, or a neutral one naming the file when none is registered.

    Examples
    --------
    >>> caption_for("maps/region_sup_gain.png").startswith("sup_ω |Γ(jω)|")
    True
    >>> caption_for("x/unknown.png")
    'Figure unknown.png.'
    """
    name = PurePosixPath(path).name
    for pattern, caption in CAPTIONS:
        if fnmatch(name, pattern):
            return caption
    return f"Figure {name}."
