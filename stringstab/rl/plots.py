"""Figures of training and evaluation (IDL paper Figs 3, 6, 9, 11, 12); each takes ``ax=None``.

Every function draws on ``ax`` (a new figure when None) and returns a dict of what it drew
(``"ax"`` and the artists), like python-control's plots.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = [
    "JERK_RANGES",
    "plot_gains_over_region",
    "plot_headway_cdf",
    "plot_jerk_ranges",
    "plot_mp_histogram",
    "plot_rolling_reward",
    "plot_ttc_distribution",
]

#: The ranges of squared jerk c (m²/s⁶) of the IDL paper's Fig. 11.
JERK_RANGES: tuple[tuple[float, float], ...] = ((0.0, 0.1), (0.1, 1.0), (1.0, 10.0), (10.0, 60.0))


def _ax(ax: Any, figsize: tuple[float, float] = (6.4, 4.0)) -> Any:
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.figure(figsize=figsize).subplots()


def plot_rolling_reward(episodes: Sequence[Mapping[str, Any]], *, ax: Any = None,
                        window: int = 10, long_window: int | None = 100,
                        label: str | None = None) -> dict[str, Any]:
    """Rolling episode return over training episodes (Fig. 3): mean of the last ``window``.

    The paper's window is 10; episodes on different leaders differ widely in return, so a
    ``long_window`` mean is drawn too (None: only the paper's).  A rolling mean is drawn only
    where its window is full (from episode ``window`` on): a "window 100" curve of a run with
    96 episodes would be a cumulative mean under a wrong name, so it is left out and the figure
    says so.

    Parameters
    ----------
    episodes : sequence of mappings
        Training episodes in order, each with a ``"return"``.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).
    window : int
        The paper's rolling window (episodes).
    long_window : int or None
        A second, longer window (None: not drawn).
    label : str, optional
        Name of the run in the legend.

    Returns
    -------
    dict
        ``ax``, ``points`` (every episode's return), ``line`` (None when the run has fewer
        than ``window`` episodes), ``line_long`` (None when not drawn) and ``note`` (what is
        left out, or "").

    Examples
    --------
    >>> rows = [{"return": -float(i)} for i in range(30)]
    >>> d = plot_rolling_reward(rows)
    >>> float(d["line"].get_xdata()[0]), float(d["line"].get_ydata()[-1]), d["line_long"]
    (10.0, -24.5, None)
    >>> d["note"]
    'window 100 not drawn: 30 episodes < 100'
    >>> import matplotlib.pyplot as plt; plt.close("all")
    """
    ax = _ax(ax)
    r = np.array([float(e["return"]) for e in episodes])
    c = np.cumsum(np.r_[0.0, r])
    n = np.arange(1, r.size + 1)
    name = label or "episode return"
    points = ax.scatter(n, r, s=4, color="0.6", alpha=0.6, lw=0, label=f"{name}: each episode")
    out: dict[str, Any] = {"ax": ax, "points": points, "line": None, "line_long": None}
    missing = []
    for key, w, style in (("line", window, {"lw": 1.0, "alpha": 0.85}),
                          ("line_long", long_window, {"lw": 2.0})):
        if not w:
            continue
        if r.size < w:
            missing.append(f"window {w} not drawn: {r.size} episodes < {w}")
            continue
        full = n[w - 1:]
        (out[key],) = ax.plot(full, (c[full] - c[full - w]) / w,
                              label=f"{name}: mean of the last {w} episodes", **style)
    out["note"] = "; ".join(missing)
    if missing:
        ax.text(0.99, 0.02, out["note"], transform=ax.transAxes, ha="right", va="bottom",
                fontsize=8, color="0.3")
    ax.set_xlabel("training episode")
    ax.set_ylabel("episode return")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return out


def plot_mp_histogram(m_p: npt.ArrayLike, *, ax: Any = None, bins: int = 30,
                      label: str | None = None,
                      bin_range: tuple[float, float] | None = None) -> dict[str, Any]:
    """Histogram of per-episode m_p with its CDF on a twin axis (Fig. 6); m_p = 1 marked.

    Every finite value is drawn: a ``bin_range`` that does not hold them all is widened to
    hold them (the CDF ends at 1 inside the axes).  Episodes whose m_p is undefined (NaN: a
    predecessor that never accelerates) are counted on the figure, not dropped silently.  The
    CDF is a line without a fill, so the histogram keeps its colour.

    Parameters
    ----------
    m_p : array_like
        m_p per episode (IDL eq 29).
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).
    bins : int
        Number of bins.
    label : str, optional
        The strategy, in the title.
    bin_range : (float, float), optional
        Range of the bins and of the x axis: give the same to panels drawn side by side so
        they compare (default: the data's range, 1 included).

    Returns
    -------
    dict
        ``ax``, ``ax_cdf``, ``patches``, ``cdf``, ``share_below_1``, ``range`` (the bins'
        range drawn) and ``undefined`` (values left out as not finite).
    """
    ax = _ax(ax)
    x_all = np.asarray(m_p, dtype=np.float64).ravel()
    x = x_all[np.isfinite(x_all)]
    undefined = int(x_all.size - x.size)
    if bin_range is not None:
        lo, hi = bin_range
    elif x.size:
        lo, hi = min(1.0, float(x.min())) - 0.02, max(1.0, float(x.max())) + 0.02
    else:
        lo, hi = 0.0, 2.0
    if x.size:
        lo, hi = min(lo, float(x.min())), max(hi, float(x.max()))
    _, _, patches = ax.hist(x, bins=bins, range=(lo, hi), color="tab:orange", alpha=0.85)
    ax.set_xlim(lo, hi)
    ax2 = ax.twinx()
    xs = np.sort(x)
    (cdf,) = ax2.step(np.r_[lo, xs, hi], np.r_[0.0, np.arange(1, xs.size + 1), xs.size]
                      / max(xs.size, 1), where="post", color="tab:blue", lw=1.5)
    ax2.set_ylim(0, 1.02)
    ax2.set_ylabel("CDF (share of episodes ≤ m_p)")
    ax.axvline(1.0, color="k", ls="--", lw=1)
    share = float(np.mean(x < 1.0)) if x.size else float("nan")
    ax.set_title(f"{label + ': ' if label else ''}m_p < 1 in {100 * share:.0f}% of "
                 f"{x.size} episodes", fontsize=10)
    if undefined:
        ax.text(0.02, 0.98, f"{undefined} episode(s) with undefined m_p left out",
                transform=ax.transAxes, ha="left", va="top", fontsize=8, color="0.3")
    ax.set_xlabel("m_p (eq 29)")
    ax.set_ylabel("episodes")
    return {"ax": ax, "ax_cdf": ax2, "patches": patches, "cdf": cdf, "share_below_1": share,
            "range": (lo, hi), "undefined": undefined}


def plot_ttc_distribution(ttc: Mapping[str, npt.ArrayLike], *, ax: Any = None,
                          max_ttc: float = 100.0, bins: int = 40, min_ttc: float = 0.1,
                          ttc_star: float | None = None) -> dict[str, Any]:
    """Distribution of finite TTC values per strategy (Fig. 9), on a logarithmic TTC axis.

    The logarithmic axis makes the safety-relevant short times visible; the range below TTC* is
    shaded.

    Parameters
    ----------
    ttc : mapping
        ``{strategy: TTC samples}`` (s; closing moments only, non-finite values left out).
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).
    max_ttc, min_ttc : float
        The TTC range drawn, s (values below ``min_ttc`` fall in the first bin).
    bins : int
        Logarithmically spaced bins.
    ttc_star : float, optional
        TTC* of the TIT metric, s (default :data:`stringstab.constants.TTC_STAR`).

    Returns
    -------
    dict
        ``ax``, ``lines`` and ``share_below_ttc_star`` per strategy.
    """
    from ..constants import TTC_STAR

    star = TTC_STAR if ttc_star is None else ttc_star
    ax = _ax(ax)
    lines = {}
    below = {}
    edges = np.geomspace(min_ttc, max_ttc, bins + 1)
    for name, v in ttc.items():
        x = np.asarray(v, dtype=np.float64)
        x = x[np.isfinite(x) & (x >= 0)]
        below[name] = float(np.mean(x < star)) if x.size else float("nan")
        h, _ = np.histogram(np.clip(x, min_ttc, None), bins=edges)
        h = h / x.size if x.size else h.astype(np.float64)  # shares of all closing moments
        beyond = int(np.count_nonzero(x > max_ttc))
        (lines[name],) = ax.plot(np.sqrt(edges[1:] * edges[:-1]), h, marker=".",
                                 label=f"{name} ({100 * below[name]:.1f} % below TTC*"
                                       + (f"; {100 * beyond / x.size:.1f} % above {max_ttc:g} s, "
                                          "off the axis" if beyond else "") + ")")
    ax.set_xscale("log")
    ax.axvspan(min_ttc, star, color="tab:red", alpha=0.12, label=f"TTC < TTC* = {star:g} s (TIT)")
    ax.set_xlim(min_ttc, max_ttc)
    ax.set_xlabel("time to collision TTC (s, log scale; closing moments only)")
    ax.set_ylabel("share of closing moments per bin")
    ax.set_title("IDL Fig. 9: distribution of the time to collision")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    return {"ax": ax, "lines": lines, "share_below_ttc_star": below}


def plot_jerk_ranges(jerk_sq: Mapping[str, npt.ArrayLike], *, ax: Any = None,
                     ranges: Sequence[tuple[float, float]] = JERK_RANGES) -> dict[str, Any]:
    """Share of squared-jerk samples c (eq 33) in the ranges of Fig. 11, per strategy.

    Linear bars of the percentage of each strategy's samples (from a zero baseline), each bar
    labelled with its count, so small ranges stay readable without a logarithmic axis (whose
    baseline would be arbitrary).  Every finite sample is counted: those above the last range
    (the paper stops at 60 m²/s⁶) get a bar of their own, so the shares are of all samples and
    add up to 100 %; non-finite samples are counted in the legend.

    Parameters
    ----------
    jerk_sq : mapping
        ``{strategy: squared-jerk samples}``, m²/s⁶.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).
    ranges : sequence of (lo, hi)
        The ranges (half-open [lo, hi), the last one closed); a bar "> hi" follows.

    Returns
    -------
    dict
        ``ax``, ``bars``, ``counts`` (one per range, then the count above the last) and
        ``total`` (finite samples) per strategy.

    Examples
    --------
    >>> d = plot_jerk_ranges({"a": [0.05, 0.5, 5.0, 30.0, 100.0, float("nan")]})
    >>> d["counts"]["a"], d["total"]["a"]
    ([1, 1, 1, 1, 1], 5)
    >>> import matplotlib.pyplot as plt; plt.close("all")
    """
    ax = _ax(ax)
    names = list(jerk_sq)
    nb = len(ranges) + 1
    width = 0.8 / max(len(names), 1)
    bars = {}
    counts = {}
    totals = {}
    top = ranges[-1][1]
    for j, name in enumerate(names):
        c_all = np.asarray(jerk_sq[name], dtype=np.float64).ravel()
        c = c_all[np.isfinite(c_all)]
        counts[name] = [int(np.count_nonzero((c >= lo) & (c < hi) if k < len(ranges) - 1
                                             else (c >= lo) & (c <= hi)))
                        for k, (lo, hi) in enumerate(ranges)] + [int(np.count_nonzero(c > top))]
        totals[name] = int(c.size)
        total = max(c.size, 1)
        bad = c_all.size - c.size
        lab = f"{name} ({c.size:,} samples{f'; {bad:,} not finite, left out' if bad else ''})"
        bars[name] = ax.bar(np.arange(nb) + j * width,
                            [100.0 * k / total for k in counts[name]], width, label=lab)
        ax.bar_label(bars[name], labels=[f"{k:,}" for k in counts[name]], fontsize=8, padding=1)
    ax.set_xticks(np.arange(nb) + 0.4 - width / 2,
                  [f"[{lo:g}, {hi:g}]" for lo, hi in ranges] + [f"> {top:g}"])
    ax.set_xlabel("squared jerk c (m²/s⁶)")
    ax.set_ylabel("share of all samples (%); count on each bar")
    ax.set_ylim(0, 112)
    ax.set_title("IDL Fig. 11: squared jerk by range (comfort; lower ranges are better)",
                 fontsize=10)
    ax.legend(fontsize=8, loc="upper right")
    return {"ax": ax, "bars": bars, "counts": counts, "total": totals}


def plot_headway_cdf(headway: Mapping[str, npt.ArrayLike], *, ax: Any = None,
                     max_h: float = 3.0, t_star: float | None = None) -> dict[str, Any]:
    """CDF of the time headway per strategy (Fig. 12), drawn over [0, max_h] s, with T* marked.

    The CDF is of every finite sample; the shares below 0 s and above ``max_h`` (off the axis)
    are given in the legend, so the curve ending below 1 at ``max_h`` is explained.

    Parameters
    ----------
    headway : mapping
        ``{strategy: headway samples}``, s.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).
    max_h : float
        Largest headway drawn, s.
    t_star : float, optional
        The desired headway T*, s, drawn as a vertical line.

    Returns
    -------
    dict
        ``ax`` and ``lines``.
    """
    ax = _ax(ax)
    lines = {}
    for name, v in headway.items():
        x = np.sort(np.asarray(v, dtype=np.float64)[np.isfinite(np.asarray(v, dtype=np.float64))])
        y = np.arange(1, x.size + 1) / max(x.size, 1)  # the CDF of every finite sample
        keep = (x >= 0) & (x <= max_h)
        off = [f"{100 * np.mean(x < 0):.1f} % < 0 s"] if (x < 0).any() else []
        off += [f"{100 * np.mean(x > max_h):.1f} % > {max_h:g} s"] if (x > max_h).any() else []
        (lines[name],) = ax.plot(x[keep], y[keep],
                                 label=f"{name}{' (off the axis: ' + ', '.join(off) + ')' if off else ''}")
    if t_star is not None:
        ax.axvline(t_star, color="k", ls="--", lw=0.8, label=f"T* = {t_star:g} s")
    ax.set_xlabel("time headway h (s, eq 22)")
    ax.set_ylabel("CDF")
    ax.set_xlim(0, max_h)
    ax.set_title("IDL Fig. 12: CDF of the time headway")
    ax.legend()
    return {"ax": ax, "lines": lines}


def plot_gains_over_region(gains: Mapping[str, npt.ArrayLike], *, tau: float, delta: float,
                           headway: float, ax: Any = None, n: int = 161,
                           max_points: int = 4000) -> dict[str, Any]:
    """Executed gains of each policy over the certified region in the (k_x, k_v) plane.

    The executed gains do not share one k_a, so the background is not a slice: it is the exact
    certified region projected over the executed k_a values
    (:func:`stringstab.plots.projection.projected_region`: certified at every / some / none of
    them), on axes that extend past the ±2 gain bounds so gains on a bound are not clipped; the
    points are coloured by policy.

    Parameters
    ----------
    gains : mapping
        ``{strategy: (m, 3) executed gains}``.
    tau, delta, headway : float
        The loop's parameters.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).
    n : int
        Grid points per axis of the background.
    max_points : int
        Points drawn per strategy at most (a random subset beyond).

    Returns
    -------
    dict
        ``ax``, ``region`` (the projection drawn), ``points`` per strategy and ``k_a`` (the
        projected values).
    """
    from ..plots.projection import plot_projected_region, projected_region

    ax = _ax(ax, (6.4, 6.4))
    allk = np.concatenate([np.asarray(g, dtype=np.float64).reshape(-1, 3) for g in gains.values()])
    proj = projected_region(allk, tau=tau, delta=delta, headway=headway, n=min(n, 81),
                            max_values=24)
    drawn = plot_projected_region(proj, ax=ax, title="executed gains over the exact certified region")
    ka = proj.values
    pts = {}
    rng = np.random.default_rng(0)
    colors = ["black", "magenta", "yellow", "cyan"]
    for j, (name, v) in enumerate(gains.items()):
        K = np.asarray(v, dtype=np.float64).reshape(-1, 3)
        if K.shape[0] > max_points:
            K = K[rng.choice(K.shape[0], max_points, replace=False)]
        pts[name] = ax.scatter(K[:, 0], K[:, 1], s=5, alpha=0.6, color=colors[j % len(colors)],
                               label=f"{name}: executed K (each at its own k_a)")
    from matplotlib.legend import Legend

    # a second legend beside the region's (which stays the axes' legend, under the map)
    ax.add_artist(Legend(ax, list(pts.values()), [h.get_label() for h in pts.values()],
                         loc="lower left", fontsize=8))
    return {"ax": ax, "region": drawn, "points": pts, "k_a": ka}
