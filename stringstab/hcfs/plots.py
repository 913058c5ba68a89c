"""Figures of an HCFS run, like the paper's Figs 4-6: speed, jerk with the limit drawn, switching.

Every function takes ``ax=None`` (or ``fig=None``) and returns what it drew.  Followers are
coloured by their position in the platoon (:func:`stringstab.plots.plot_vehicles`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..plots.traffic import plot_vehicles
from .simulate import HCFSRun

__all__ = ["MODE_TITLES", "plot_figure", "plot_jerk", "plot_jerk_grid", "plot_learning", "plot_speed",
           "plot_switching"]

#: Panel titles of the modes; the policy's label says whether it is a DDPG or a stand-in.
MODE_TITLES = {
    "cacc": "CACC alone",
    "policy": "{policy} alone",
    "paper": "HCFS, eqs 12-14 (beta = {beta:g})",
    "safe": "HCFS, jerk-safe variant",
}


def _ax(ax: Any) -> Any:
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots()
    return ax


def _title(run: HCFSRun, i: int) -> str:
    p = run.params
    short = "stand-in policy" if p.get("policy_is_stand_in") else p.get("policy_label", "policy")
    return MODE_TITLES[run.configs[i].mode].format(policy=short, beta=p["beta"])


def plot_speed(run: HCFSRun, i: int, *, ax: Any = None) -> list[Any]:
    """Speed of the leader (dashed black) and every follower over time (Fig. 4).

    Parameters
    ----------
    run : HCFSRun
        The verified run.
    i : int
        Index of the configuration (mode and J) in ``run.configs``.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).

    Returns
    -------
    list
        [leader Line2D, followers LineCollection].
    """
    ax = _ax(ax)
    lc = plot_vehicles(run.t, run.speed[i, 1:], ax=ax, first_position=1,
                       n_positions=run.n_followers)["lines"]
    (lead,) = ax.plot(run.t, run.speed[i, 0], color="k", lw=0.9, ls="--", label="leader")
    lo, hi = float(run.speed[i].min()), float(run.speed[i].max())
    pad = 0.05 * (hi - lo) or 0.5
    ax.set_ylim(lo - pad, hi + pad)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("speed v (m/s)")
    ax.set_title(_title(run, i), fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper right", fontsize=8, framealpha=0.9)
    return [lead, lc]


def _jerk(run: HCFSRun, i: int) -> Any:
    """Jerk (a_k − a_{k−1})/T of every follower's command in configuration ``i``, m/s³."""
    a0 = run.params["initial_accel"]
    out = np.concatenate([np.full((run.n_followers, 1), a0), run.output[i]], axis=-1)
    return np.diff(out, axis=-1) / run.dt


def plot_jerk(run: HCFSRun, i: int, *, ax: Any = None) -> list[Any]:
    """Jerk (a_k − a_{k−1})/T of every follower's command, with ±J drawn (Fig. 5).

    Every frame is drawn (no decimation), so single-frame spikes show.  The scale fits the data
    and ±J; the bound 2a_max/T that the acceleration limits give alone is drawn only when the
    data reach it (otherwise :func:`plot_figure` says in a note how far off the scale it is).
    The largest |jerk| and the frames above J are written in the panel.

    Parameters
    ----------
    run : HCFSRun
        The verified run.
    i : int
        Index of the configuration (mode and J) in ``run.configs``.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).

    Returns
    -------
    list
        [followers LineCollection, +J line, −J line, and the ±2a_max/T lines when drawn].
    """
    ax = _ax(ax)
    jerk = _jerk(run, i)
    lc = plot_vehicles(run.t, jerk, ax=ax, first_position=1, n_positions=run.n_followers,
                       max_points=run.t.size)["lines"]
    lines = _jerk_limits(ax, run, i, float(np.abs(jerk).max()))
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("jerk (m/s³)")
    ax.set_title(_title(run, i), fontsize=9, loc="left")
    _jerk_note(ax, run, i, jerk)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper right", fontsize=8, framealpha=0.9)
    return [lc, *lines]


def _jerk_limits(ax: Any, run: HCFSRun, i: int, peak: float) -> list[Any]:
    """±J (and ±2a_max/T when the data reach 80 % of it) and a y-range holding the data."""
    J = run.configs[i].jerk_limit
    paper = 2.0 * run.params["accel_max"] / run.dt
    lines = [ax.axhline(s * J, color="r", ls="--", lw=1.0, label=f"±J = ±{J:g} m/s³" if s > 0 else None)
             for s in (1, -1)]
    if peak >= 0.8 * paper:
        lines += [ax.axhline(s * paper, color="0.5", ls=":", lw=1.0,
                             label="±2a_max/T" if s > 0 else None) for s in (1, -1)]
    m = max(peak, J, paper if peak >= 0.8 * paper else 0.0) * 1.3
    ax.set_ylim(-m, m)
    return lines


def _jerk_note(ax: Any, run: HCFSRun, i: int, jerk: Any, *, short: bool = False,
               head: str = "") -> None:
    """Say the largest |jerk| and the frames above J in the panel's title (under ``head``)."""
    J = run.configs[i].jerk_limit
    above = int(np.count_nonzero(np.abs(jerk) > J * (1 + 1e-9)))
    peak = float(np.abs(jerk).max())
    frames = "frame" if above == 1 else "frames"
    text = (f"max {peak:.3g} m/s³; {above:,} {frames} > J" if short
            else f"max |jerk| {peak:.3g} m/s³; {above:,} of {jerk.size:,} frames above J")
    if head:
        ax.set_title(f"{head}\n{text}", fontsize=8, loc="left")
    else:
        ax.set_title(text, fontsize=8, loc="right", color="#B00000" if above else "0.25")


def plot_jerk_grid(run: HCFSRun, idx: Sequence[int], *, fig: Any) -> list[Any]:
    """Jerk of each follower in its own panel: a row per follower, a column per mode.

    With many followers over a long run, one panel per mode would overplot them; here each
    panel holds one follower's every frame, ±J, and (written inside) its largest |jerk| and
    frames above J.  The columns share their y scale.

    Parameters
    ----------
    run : HCFSRun
        The verified run.
    idx : sequence of int
        The configurations (modes at one J) to draw, one column each.
    fig : matplotlib Figure
        Where to draw.

    Returns
    -------
    list of Axes
        The panels, row by row.
    """
    import textwrap

    N = run.n_followers
    axes = np.atleast_2d(fig.subplots(N, len(idx), sharex=True, sharey="col", squeeze=False))
    for col, i in enumerate(idx):
        jerk = _jerk(run, i)
        peak = float(np.abs(jerk).max())
        for row in range(N):
            ax = axes[row, col]
            ax.plot(run.t, jerk[row], color="#0072B2", lw=0.6)
            _jerk_limits(ax, run, i, peak)
            _jerk_note(ax, run, i, jerk[row:row + 1], short=True,
                       head=textwrap.fill(_title(run, i), 40) if row == 0 else "")
            ax.grid(alpha=0.3)
            ax.tick_params(labelsize=8)
            if col == 0:
                ax.set_ylabel(f"follower {row + 1}", fontsize=8)
        axes[-1, col].set_xlabel("time t (s)", fontsize=9)
    axes[0, 0].legend(loc="lower right", fontsize=8, framealpha=0.9)
    fig.supylabel("jerk (m/s³), one panel per follower", fontsize=9)
    return list(axes.ravel())


def plot_switching(run: HCFSRun, i: int, *, ax: Any = None) -> Any:
    """Weight λ of the learned candidate per follower over time (Fig. 6): 0 CACC, 1 policy.

    Soft switches (λ = β or 1 − β) show as intermediate shades.

    Parameters
    ----------
    run : HCFSRun
        The verified run.
    i : int
        Index of the configuration (mode and J) in ``run.configs``.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).

    Returns
    -------
    matplotlib.image.AxesImage
    """
    ax = _ax(ax)
    N = run.n_followers
    t0, t1 = float(run.t[0]), float(run.t[-1]) + run.dt
    img = ax.imshow(run.weight[i], aspect="auto", interpolation="nearest", cmap="coolwarm",
                    vmin=0.0, vmax=1.0, extent=(t0, t1, N + 0.5, 0.5))
    ax.set_yticks(np.arange(1, N + 1))
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("follower")
    ax.set_title(f"{_title(run, i)}: weight of the policy (0 = CACC, 1 = policy)", fontsize=9)
    return img


def plot_learning(curves: Mapping[str, Sequence[tuple[float, float]]], *,
                  references: Mapping[str, float] | None = None, ax: Any = None,
                  ylabel: str = "value", linestyle: str = "-") -> dict[str, Any]:
    """Learning curves (a value against training steps), with constant references drawn flat.

    Parameters
    ----------
    curves : mapping of label to [(step, value), …]
        E.g. the deterministic policy's Σr on held-out cases at every checkpoint, per seed.
    references : mapping of label to float, optional
        E.g. the same Σr of CACC alone and of the stand-in (dashed horizontal lines).
    ax : matplotlib Axes, optional
    ylabel : str
    linestyle : str
        Of the curves, which take the colours C0, C1, … in order (so that two calls with the
        same keys' order, e.g. two controllers per seed, match colours).

    Returns
    -------
    dict
        ``ax``, ``lines`` (one per curve) and ``references`` (one per reference).

    Examples
    --------
    >>> d = plot_learning({"seed 0": [(0, -3.0), (10, -1.0)]}, references={"CACC": -2.0})
    >>> len(d["lines"]), list(d["references"][0].get_ydata())
    (1, [-2.0, -2.0])
    >>> import matplotlib.pyplot as plt; plt.close("all")
    """
    ax = _ax(ax)
    lines = []
    for i, (label, pts) in enumerate(curves.items()):
        xy = np.asarray(pts, dtype=np.float64).reshape(-1, 2)
        (ln,) = ax.plot(xy[:, 0], xy[:, 1], marker="o", ms=3, lw=1.2, ls=linestyle, color=f"C{i}",
                        label=label)
        lines.append(ln)
    refs = [ax.axhline(v, ls=(0, (4, 2 + 2 * i)), lw=1.2, color=("k", "0.45", "0.7")[i % 3], label=label)
            for i, (label, v) in enumerate((references or {}).items())]
    ax.set_xlabel("training steps (all followers)")
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return {"ax": ax, "lines": lines, "references": refs}


def plot_figure(run: HCFSRun, jerk_limit: float, kind: str, *, fig: Any = None) -> tuple[Any, Any]:
    """One figure with a panel per mode of ``run`` at ``jerk_limit``.

    Parameters
    ----------
    run : HCFSRun
        A run containing configurations at ``jerk_limit``.
    jerk_limit : float
        J, m/s³.
    kind : {"speed", "jerk", "switching"}
        :func:`plot_speed`, the jerk (every mode; one panel per follower and mode,
        :func:`plot_jerk_grid`, when there are several followers, else :func:`plot_jerk`) or
        :func:`plot_switching` (the HCFS modes).
    fig : matplotlib Figure, optional
        Where to draw.

    Returns
    -------
    (Figure, list of Axes)
    """
    from ..errors import StringStabError

    draw = {"speed": plot_speed, "jerk": plot_jerk, "switching": plot_switching}
    if kind not in draw:
        raise StringStabError(f"kind must be one of {sorted(draw)}; got {kind!r}")
    idx = [i for i, c in enumerate(run.configs) if np.isclose(c.jerk_limit, jerk_limit)
           and (kind != "switching" or c.mode in ("paper", "safe"))]
    if not idx:
        raise StringStabError(f"the run has no configuration at J={jerk_limit!r} for a {kind} figure")
    paper = 2.0 * run.params["accel_max"] / run.dt
    grid = kind == "jerk" and run.n_followers > 1
    if fig is None:
        import matplotlib.pyplot as plt

        size = ((3.0 * len(idx) + 1.4, 1.3 * run.n_followers + 1.4) if grid
                else (11, 2.6 * len(idx) + 0.6))
        fig = plt.figure(figsize=size, layout="constrained")
    title = f"{run.leader.name}, {run.n_followers} followers, J = {jerk_limit:g} m/s³"
    if grid:
        axes = plot_jerk_grid(run, idx, fig=fig)
        peak = max(float(np.abs(_jerk(run, i)).max()) for i in idx)
        if peak < 0.8 * paper:
            title += (f"\nthe acceleration limits alone bound the jerk by 2a_max/T = {paper:g} m/s³, "
                      "beyond every panel's scale")
        fig.suptitle(title, fontsize=10)
        return fig, axes
    axes = list(np.atleast_1d(fig.subplots(len(idx), 1, sharex=True)))
    drawn = [draw[kind](run, i, ax=ax) for ax, i in zip(axes, idx)]
    for ax in axes[:-1]:
        ax.set_xlabel("")
    if kind == "switching":
        cb = fig.colorbar(drawn[0], ax=axes, shrink=0.9, pad=0.01)
        cb.set_label("weight λ of the policy (0 = CACC, 1 = policy)")
    else:  # the followers' colours: their position in the platoon
        cb = fig.colorbar(drawn[0][1 if kind == "speed" else 0], ax=axes, shrink=0.9, pad=0.01)
        cb.set_label("follower (position in the platoon)")
    if kind == "jerk" and max(float(np.abs(_jerk(run, i)).max()) for i in idx) < 0.8 * paper:
        title += (f"\nthe acceleration limits alone bound the jerk by 2a_max/T = {paper:g} m/s³, "
                  "beyond every panel's scale")
    fig.suptitle(title, fontsize=10)
    return fig, axes
