"""Every figure the toolkit writes, rendered from tiny inputs, is checked as a reader sees it:

* no text is clipped: after drawing, the window extent of every visible text (titles, labels,
  tick labels, legend entries, annotations, colorbar labels) lies inside the area the file
  keeps — the figure's box, or, for a figure saved with ``bbox_inches="tight"``, its tight
  box (which holds every artist by construction: for those the check is the layout's, not
  evidence, and the test says which);
* every artist with a label is in a legend: each label returned by
  ``Axes.get_legend_handles_labels`` appears among the texts of the figure's legends;
* no two tick labels of one axes overlap (x, y and, in 3-D, z together: the corner of a 3-D
  map once printed "−2.0−2.0");
* for the figures a reader sees in a report (written at the toolkit's own dpi): every text is at
  least 8 pt at the size the report shows the image (the page is 985 px wide, so a wider image
  is scaled down), and every axes legend lies inside its axes (or, for a map, right under it,
  never beside it: ``stringstab.plots.legend_below``).

The figures are captured where the toolkit saves them (``Figure.savefig`` is wrapped), by
running the writers themselves: region maps (2-D with an overlay, 3-D), a simulated run, the
tune moves, an HCFS verification, and (with torch) the training curve, an evaluation and the
comparison figures.
"""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.legend import Legend

from stringstab.cli import main

SLACK = 1.0  # pixels: rounding of extents
PAGE_PX = 985  # the report's content width (64rem less its padding), CSS pixels at 100 %
MIN_PT = 8.0


@pytest.fixture
def captured(monkeypatch):
    """(file name, figure, saved with a tight box, dpi) of every figure saved while the test runs."""
    saved: list[tuple[str, Figure, bool, float]] = []
    real = Figure.savefig

    def savefig(self, fname, *args, **kwargs):
        real(self, fname, *args, **kwargs)
        saved.append((str(getattr(fname, "name", fname)), self, kwargs.get("bbox_inches") == "tight",
                      float(kwargs.get("dpi") or self.dpi)))

    monkeypatch.setattr(Figure, "savefig", savefig)
    return saved


def _renderer(fig: Figure):
    if not hasattr(fig.canvas, "get_renderer"):  # a Figure() made without pyplot
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        FigureCanvasAgg(fig)
    renderer = fig.canvas.get_renderer()
    fig.draw(renderer)
    return renderer


def _overlapping_ticks(fig: Figure) -> list[str]:
    """Pairs of visible, non-empty tick labels of one axes whose boxes overlap."""
    renderer = _renderer(fig)
    out = []
    for ax in fig.get_axes():
        if not ax.get_visible():
            continue
        axes = [ax.xaxis, ax.yaxis] + ([ax.zaxis] if hasattr(ax, "zaxis") else [])
        labels = []
        for axis in axes:
            lo, hi = sorted(axis.get_view_interval())
            span = 1e-9 * max(abs(lo), abs(hi), 1.0)
            for tick in axis.get_major_ticks():  # ticks beyond the view are not drawn
                t = tick.label1
                if (lo - span <= tick.get_loc() <= hi + span and t.get_visible()
                        and t.get_text().strip()):
                    labels.append((t.get_text(), t.get_window_extent(renderer)))
        for i, (a, ea) in enumerate(labels):
            for b, eb in labels[i + 1:]:
                w = min(ea.x1, eb.x1) - max(ea.x0, eb.x0)
                h = min(ea.y1, eb.y1) - max(ea.y0, eb.y0)
                if w > SLACK and h > SLACK:
                    out.append(f"{a!r} on {b!r}")
    return out


def _reader_problems(fig: Figure, tight: bool, dpi: float) -> list[str]:
    """Text under 8 pt at the size the report shows the image; axes legends outside their axes."""
    from matplotlib.text import Text

    renderer = _renderer(fig)
    box = fig.get_tightbbox(renderer) if tight else fig.bbox_inches
    width_px = box.width * dpi
    scale = min(1.0, PAGE_PX / width_px)
    problems = []
    small = sorted({f"{t.get_text()[:30]!r} at {t.get_fontsize() * dpi / 96 * scale:.1f} pt"
                    for t in fig.findobj(Text) if t.get_visible() and t.get_text().strip()
                    and t.get_fontsize() * dpi / 96 * scale < MIN_PT - 0.05})
    if small:
        problems.append(f"text under {MIN_PT:g} pt as embedded: {small[:6]}")
    for ax in fig.get_axes():
        leg = ax.get_legend()
        if leg is None or not leg.get_visible():
            continue
        e, a = leg.get_window_extent(renderer), ax.get_window_extent(renderer)
        within_x = e.x0 >= a.x0 - SLACK and e.x1 <= a.x1 + SLACK
        inside = within_x and e.y0 >= a.y0 - SLACK and e.y1 <= a.y1 + SLACK
        below = within_x and e.y1 <= a.y0 + SLACK  # stringstab.plots.legend_below: under a map
        if not (inside or below):
            problems.append(f"legend outside its axes {ax.get_title()[:30]!r}")
    return problems


def _legend_texts(fig: Figure) -> set[str]:
    legends = list(fig.legends)
    for ax in fig.get_axes():
        if ax.get_legend() is not None:
            legends.append(ax.get_legend())
        legends += [a for a in ax.get_children() if isinstance(a, Legend)]
    return {t.get_text() for leg in legends for t in leg.get_texts()}


def _clipped_texts(fig: Figure, tight: bool) -> list[str]:
    """What is drawn outside the kept area: each axes' tight box (its tick labels, labels,
    title, legend, annotations, as drawn) and the figure's own texts and legends."""
    renderer = _renderer(fig)
    box = fig.get_tightbbox(renderer).transformed(fig.dpi_scale_trans) if tight else fig.bbox
    parts = [(f"axes {ax.get_title()[:40]!r} ({ax.get_xlabel()[:20]!r})", ax.get_tightbbox(renderer))
             for ax in fig.get_axes() if ax.get_visible()]
    parts += [(t.get_text()[:60], t.get_window_extent(renderer)) for t in fig.texts
              if t.get_visible() and t.get_text().strip()]
    parts += [("figure legend", leg.get_window_extent(renderer)) for leg in fig.legends]
    return [what for what, e in parts if e is not None and (
        e.x0 < box.x0 - SLACK or e.y0 < box.y0 - SLACK or e.x1 > box.x1 + SLACK
        or e.y1 > box.y1 + SLACK)]


def _check(saved, expected, *, reader: bool = True):
    """The checks of the module docstring on every captured figure (``reader``: also the font
    sizes and legends, for figures written at the toolkit's own dpi)."""
    names = sorted({n.rsplit("/", 1)[-1] for n, *_ in saved})
    for pattern in expected:
        assert any(pattern in n for n in names), f"no figure like {pattern!r} among {names}"
    problems = []
    for name, fig, tight, dpi in saved:
        short = name.rsplit("/", 1)[-1]
        clipped = _clipped_texts(fig, tight)
        if clipped:
            problems.append(f"{short}: clipped text {clipped}")
        overlaps = _overlapping_ticks(fig)
        if overlaps:
            problems.append(f"{short}: tick labels overlap: {overlaps[:4]}")
        if reader:
            problems += [f"{short}: {p}" for p in _reader_problems(fig, tight, dpi)]
        texts = _legend_texts(fig)
        for ax in fig.get_axes():
            _, labels = ax.get_legend_handles_labels()
            missing = [lab for lab in labels if lab not in texts]
            if missing:
                problems.append(f"{short}: labelled artists not in a legend: {missing}")
    assert not problems, "\n".join(problems)
    return names


@pytest.mark.slow  # ~9.9 s with -n 2 on 2 shared cores (CI runs it)
def test_region_figures(tmp_path, captured):
    # the writer the region command uses, in this process (the command shares it with a fork)
    from stringstab.io import read_gains
    from stringstab.plots import save_figures
    from stringstab.regions import region_map

    g = np.linspace(-2, 2, 15)
    m2 = region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1,
                    progress=False, workers=1)
    from stringstab.plots import trajectory_verdicts

    rollout = read_gains("stringstab/data/examples/gain_rollout.csv")
    save_figures(m2, tmp_path, formats=("png",), dpi=40, gains=rollout,
                 verdicts=trajectory_verdicts(m2, rollout), figures="all")
    m3 = region_map({"k_x": g[::2], "k_v": g[::2], "k_a": np.linspace(-1, 1, 3)}, tau=0.1,
                    delta=0.2, headway=1.1, methods="exact", progress=False, workers=1)
    save_figures(m3, tmp_path, prefix="r3", formats=("png",), dpi=40)
    # dpi 40 keeps the test fast, so the sizes as embedded are not the command's: no font check;
    # the region maps' legends sit below the map by design (they must never cover it)
    _check(captured, ["class_exact", "class_taylor", "class_printed", "compare", "sup_gain",
                      "overlay", "slices_exact", "3d_exact"], reader=False)
    sup = next(f for n, f, *_ in captured if "sup_gain" in n.rsplit("/", 1)[-1])
    cbar = next(c for ax in sup.axes for c in ax.child_axes)  # the inset colourbar
    labels = [t.get_text() for t in cbar.get_yticklabels() if t.get_text()]
    assert len(labels) >= 3, labels  # a log colourbar labelled beyond its decades (1, 2, 5, 10)


def test_simulate_and_tune_figures(tmp_path, captured, capsys):
    assert main(["simulate", "--leader", "us06", "--duration", "30", "--followers", "3",
                 "--out", str(tmp_path / "sim")]) == 0
    from stringstab.cli import demo_steps as demo

    (tmp_path / "tune").mkdir()
    demo._step_tune(tmp_path / "tune", lambda _: None)
    _check(captured, ["platoon", "damping", "tune_moves"])


def test_hcfs_figures(tmp_path, captured, capsys):
    assert main(["hcfs", "verify", "--jerk-limit", "2.5", "--followers", "3", "--leader", "us06",
                 "--duration", "20", "--out", str(tmp_path / "h")]) == 0
    from stringstab.hcfs.plots import plot_learning

    d = plot_learning({"seed 0": [(0, -3.0), (10, -1.0)]}, references={"CACC": -2.0},
                      ax=Figure(layout="constrained").subplots())
    d["ax"].figure.savefig(tmp_path / "learning.png", dpi=110)
    _check(captured, ["speed_", "jerk_", "switching_", "learning"])


@pytest.mark.torch
def test_training_and_comparison_figures(tmp_path, captured):
    pytest.importorskip("torch")
    pytest.importorskip("safetensors")
    from stringstab.cli import demo_steps as demo

    (tmp_path / "t").mkdir()
    demo._step_train(tmp_path / "t", lambda _: None, steps=300, episodes=3, platoon=0)
    names = _check(captured, ["rolling_reward", "fig6_mp", "fig9_ttc", "fig11_jerk",
                              "fig12_headway", "gains_region"])
    assert len(names) >= 6


def test_the_checks_can_fail():
    """The two checks catch what they are for (a title pushed off the figure, an unlisted label)."""
    fig = Figure(figsize=(3, 2))
    ax = fig.subplots()
    ax.plot([0, 1], [0, 1], label="listed")
    ax.plot([0, 1], [1, 0], label="not listed")
    ax.legend(handles=[ax.get_lines()[0]])
    ax.set_title("a title\n" * 6)
    assert _clipped_texts(fig, tight=False)
    texts = _legend_texts(fig)
    assert "listed" in texts and "not listed" not in texts
    assert np.isfinite(fig.dpi)


def _platoon_csv(path):
    """t, v0, v1, gap1, v2, gap2 of a simulated platoon (two followers), for ``identify``."""
    import math

    from stringstab.traffic import LinearController, from_speed, simulate

    t = np.arange(0.0, 150.05, 0.1)
    lead = from_speed(t, 15 + 3 * np.sin(2 * np.pi * t / 50) + np.sin(0.5 * t), dt=0.1)
    c = LinearController([0.2, 0.3], [0.7, 0.2], [0.0, 0.0], headway=1.5, standstill=4.0)
    r = simulate(lead, c, 2, tau=np.array([0.3, 0.6]), delta=0.0)
    cols = [t, r.speed[0], r.speed[1], r.gap[0], r.speed[2], r.gap[1]]
    rows = ["t,v0,v1,gap1,v2,gap2"] + [",".join("" if not math.isfinite(x) else f"{x:.6f}" for x in row)
                                       for row in np.column_stack(cols)]
    path.write_text("\n".join(rows) + "\n")
    return path


def test_identify_figures(tmp_path, captured, capsys):
    """identify's figures: the checks above, plus what each shows (issue 30)."""
    import json
    import re

    from matplotlib.container import ErrorbarContainer

    out = tmp_path / "run"
    assert main(["identify", str(_platoon_csv(tmp_path / "log.csv")), "--bootstrap", "2",
                 "--starts", "1", "--no-fit-delay", "--no-progress", "--out", str(out)]) == 0
    _check(captured, ["fit_1", "fit_2", "transfer_1", "transfer_2", "sup_gain"])
    figs = {n.rsplit("/", 1)[-1]: f for n, f, *_ in captured}
    rows = {r["position"]: r for r in json.loads((out / "identify.json").read_text())["vehicles"]}
    for pos, r in rows.items():
        ax1 = figs[f"transfer_{pos}.png"].axes[0]
        # the model's curve starts a decade below its peak (it was cut at the data's first bin),
        # and at 0.01 rad/s at the latest (a peak at ω = 0 is |Γ(0)| = 1)
        assert ax1.get_xlim()[0] <= max(r["peak_omega"] / 10, 0.01) + 1e-12
        assert any(isinstance(c, ErrorbarContainer) and len(c.lines[2]) for c in ax1.containers)
        title = figs[f"fit_{pos}.png"].axes[0].get_title()
        assert not re.search(r"\de[-+]\d", title), title  # no solver noise like 1.25e-11
    sup = figs["sup_gain.png"].axes[0]
    assert sum(isinstance(c, ErrorbarContainer) for c in sup.containers) == 2  # model and data
    md = (out / "report.md").read_text(encoding="utf-8")
    caps = re.findall(r"\*Figure \d+\. (.*?)\* \(`(\w+)\.png`\)", md)
    assert len({c for c, _ in caps}) == len(caps) == 5  # one caption per figure, each its own


def test_comparison_figures_show_every_sample():
    """Figs 3, 6, 11, 12 against counts computed here from the samples (independent truth)."""
    import matplotlib.pyplot as plt

    from stringstab.rl.plots import (
        plot_headway_cdf,
        plot_jerk_ranges,
        plot_mp_histogram,
        plot_rolling_reward,
    )

    rng = np.random.default_rng(3)
    jerk = np.r_[rng.exponential(3.0, 500), [75.0, 120.0, 61.0], [np.nan, np.inf]]
    d = plot_jerk_ranges({"a": jerk})
    finite = jerk[np.isfinite(jerk)]
    assert d["counts"]["a"][-1] == int(np.sum(finite > 60)) == 3  # the samples above 60 counted
    assert sum(d["counts"]["a"]) == d["total"]["a"] == finite.size
    heights = [b.get_height() for b in d["bars"]["a"]]
    np.testing.assert_allclose(sum(heights), 100.0, rtol=1e-12, atol=0)
    assert d["ax"].get_xticklabels()[-1].get_text() == "> 60"

    mp = np.r_[rng.uniform(0.6, 1.2, 60), [2.7], [np.nan]]
    d = plot_mp_histogram(mp, bin_range=(0.5, 1.5))  # 2.7 lies beyond the requested range
    lo, hi = d["ax"].get_xlim()
    assert lo <= np.nanmin(mp) and hi >= np.nanmax(mp)
    assert sum(p.get_height() for p in d["patches"]) == 61 and d["undefined"] == 1
    assert d["cdf"].get_ydata()[-1] == 1.0 and max(d["cdf"].get_xdata()) <= hi
    assert any("1 episode(s) with undefined m_p" in t.get_text() for t in d["ax"].texts)

    r = rng.normal(-50, 10, 96)
    d = plot_rolling_reward([{"return": x} for x in r])
    assert d["line_long"] is None and "window 100 not drawn: 96 episodes < 100" in d["note"]
    want = np.convolve(r, np.ones(10) / 10, mode="valid")  # full windows only
    np.testing.assert_allclose(d["line"].get_ydata(), want, rtol=1e-12, atol=1e-12)
    assert d["line"].get_xdata()[0] == 10

    h = np.r_[rng.uniform(0.5, 2.5, 90), rng.uniform(3.5, 8.0, 10)]
    d = plot_headway_cdf({"a": h}, max_h=3.0)
    y = d["lines"]["a"].get_ydata()
    np.testing.assert_allclose(y[-1], np.mean(h <= 3.0), rtol=0, atol=1e-12)  # not renormalised
    assert "10.0 % > 3 s" in d["lines"]["a"].get_label()
    plt.close("all")
