"""Every figure the toolkit writes, rendered from tiny inputs, is checked as a reader sees it:

* no text is clipped: after drawing, the window extent of every visible text (titles, labels,
  tick labels, legend entries, annotations, colorbar labels) lies inside the area the file
  keeps — the figure's box, or, for a figure saved with ``bbox_inches="tight"``, its tight
  box (which holds every artist by construction: for those the check is the layout's, not
  evidence, and the test says which);
* every artist with a label is in a legend: each label returned by
  ``Axes.get_legend_handles_labels`` appears among the texts of the figure's legends.

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


@pytest.fixture
def captured(monkeypatch):
    """(file name, figure, saved with a tight box) of every figure saved while the test runs."""
    saved: list[tuple[str, Figure, bool]] = []
    real = Figure.savefig

    def savefig(self, fname, *args, **kwargs):
        real(self, fname, *args, **kwargs)
        saved.append((str(getattr(fname, "name", fname)), self, kwargs.get("bbox_inches") == "tight"))

    monkeypatch.setattr(Figure, "savefig", savefig)
    return saved


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
    if not hasattr(fig.canvas, "get_renderer"):  # a Figure() made without pyplot
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        FigureCanvasAgg(fig)
    renderer = fig.canvas.get_renderer()
    fig.draw(renderer)
    box = fig.get_tightbbox(renderer).transformed(fig.dpi_scale_trans) if tight else fig.bbox
    parts = [(f"axes {ax.get_title()[:40]!r} ({ax.get_xlabel()[:20]!r})", ax.get_tightbbox(renderer))
             for ax in fig.get_axes() if ax.get_visible()]
    parts += [(t.get_text()[:60], t.get_window_extent(renderer)) for t in fig.texts
              if t.get_visible() and t.get_text().strip()]
    parts += [("figure legend", leg.get_window_extent(renderer)) for leg in fig.legends]
    return [what for what, e in parts if e is not None and (
        e.x0 < box.x0 - SLACK or e.y0 < box.y0 - SLACK or e.x1 > box.x1 + SLACK
        or e.y1 > box.y1 + SLACK)]


def _check(saved, expected):
    names = sorted({n.rsplit("/", 1)[-1] for n, _, _ in saved})
    for pattern in expected:
        assert any(pattern in n for n in names), f"no figure like {pattern!r} among {names}"
    problems = []
    for name, fig, tight in saved:
        short = name.rsplit("/", 1)[-1]
        clipped = _clipped_texts(fig, tight)
        if clipped:
            problems.append(f"{short}: clipped text {clipped}")
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
                 verdicts=trajectory_verdicts(m2, rollout))
    m3 = region_map({"k_x": g[::2], "k_v": g[::2], "k_a": np.linspace(-1, 1, 3)}, tau=0.1,
                    delta=0.2, headway=1.1, methods="exact", progress=False, workers=1)
    save_figures(m3, tmp_path, prefix="r3", formats=("png",), dpi=40)
    _check(captured, ["class_exact", "class_taylor", "class_printed", "compare", "sup_gain",
                      "overlay", "slices_exact", "3d_exact"])


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
    d["ax"].figure.savefig(tmp_path / "learning.png", dpi=40)
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
