"""Figures of a radio study (:mod:`stringstab.traffic.radio_study`): amplification against loss.

Each function takes a computed :class:`~stringstab.traffic.radio_study.RadioStudy` and
``ax=None``, and returns a :class:`~stringstab.plots.PlotResult`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import StringStabError
from ._common import PlotResult

__all__ = ["plot_amplification_vs_loss", "plot_link_gains"]

#: What each metric is called on the axis.
_LABELS = {"amplification": "max m_p along the string (per-link ℓ2 gain, eq 29)",
           "gain_first": "‖a_N‖₂ / ‖a_1‖₂ (first follower to last)",
           "gain_leader": "‖a_N‖₂ / ‖a_0‖₂ (leader to last)"}


def _ax(ax: Any) -> Any:
    if ax is None:
        from ._common import pyplot

        _, ax = pyplot().subplots(figsize=(6.4, 4.2))
    return ax


def _burst_label(b: float) -> str:
    return "independent losses" if b == 1 else f"bursts of {b:g} messages"


def plot_amplification_vs_loss(study: Any, *, triple: int = 0, metric: str = "amplification",
                               ax: Any = None) -> PlotResult:
    """The measured amplification against the loss rate, one line per burst length, with CI bands.

    The dashed line at 1 is the bound every certificate proves per link (‖Γ‖ ≤ 1) for the
    loop without loss.

    Parameters
    ----------
    study : RadioStudy
        The study (:func:`stringstab.traffic.radio_study.run_radio_study`).
    triple : int
        Which gain triple of the study.
    metric : {"amplification", "gain_first", "gain_leader"}
        The per-replicate metric drawn (mean and confidence band over the replicates).
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).

    Returns
    -------
    PlotResult
        ``ax``, ``lines`` (one per burst length, then the bound) and ``bands``.

    Raises
    ------
    StringStabError
        On an unknown metric or triple index.
    """
    if metric not in _LABELS:
        raise StringStabError(f"metric must be one of {sorted(_LABELS)}; got {metric!r}")
    if not (0 <= triple < len(study.gains)):
        raise StringStabError(f"triple must be in 0..{len(study.gains) - 1}; got {triple}")
    s = study.summary(metric)[triple]
    ax = _ax(ax)
    lines, bands = [], []
    for b, burst in enumerate(study.bursts):
        (line,) = ax.plot(study.losses, s[b, :, 0], marker="o", ms=4, label=_burst_label(float(burst)))
        bands.append(ax.fill_between(study.losses, s[b, :, 1], s[b, :, 2], color=line.get_color(),
                                     alpha=0.2, lw=0))
        lines.append(line)
    lines.append(ax.axhline(1.0, color="k", ls="--", lw=0.9, label="certificate's bound 1"))
    k = study.gains[triple]
    level = 100 * float(study.settings.get("level", 0.95))
    ax.set_title(f"K = ({k[0]:g}, {k[1]:g}, {k[2]:g}), messages every "
                 f"{study.settings.get('message_period', float('nan')):g} s; "
                 f"{level:g} % t-interval over {study.seeds} seeds", fontsize=9)
    ax.set_xlabel("message loss rate p")
    ax.set_ylabel(_LABELS[metric])
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return PlotResult.of({"ax": ax, "lines": lines, "bands": bands})


def plot_link_gains(study: Any, *, triple: int = 0, burst: int = 0, ax: Any = None) -> PlotResult:
    """m_p of every link (mean over the replicates), one line per loss rate.

    Parameters
    ----------
    study : RadioStudy
        The study.
    triple, burst : int
        Which gain triple and burst length.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).

    Returns
    -------
    PlotResult
        ``ax`` and ``lines`` (one per loss rate, then the bound).
    """
    if not (0 <= triple < len(study.gains) and 0 <= burst < len(study.bursts)):
        raise StringStabError(f"triple/burst out of range: {triple}, {burst}")
    with np.errstate(invalid="ignore"):
        link = np.nanmean(study.m_p[triple, burst], axis=1)  # (L, N)
    ax = _ax(ax)
    pos = np.arange(1, link.shape[-1] + 1)
    cmap = __import__("matplotlib").colormaps["viridis"]
    lines = []
    for li, p in enumerate(study.losses):
        (line,) = ax.plot(pos, link[li], marker="o", ms=3,
                          color=cmap(li / max(len(study.losses) - 1, 1)), label=f"p = {p:g}")
        lines.append(line)
    lines.append(ax.axhline(1.0, color="k", ls="--", lw=0.9))
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    k = study.gains[triple]
    ax.set_title(f"K = ({k[0]:g}, {k[1]:g}, {k[2]:g}), {_burst_label(float(study.bursts[burst]))}",
                 fontsize=9)
    ax.set_xlabel("follower position i")
    ax.set_ylabel("m_p of link i−1 → i (mean over seeds)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    return PlotResult.of({"ax": ax, "lines": lines})
