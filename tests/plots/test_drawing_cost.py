"""The cheaper ways the region figures are drawn (issue 31) draw the same pictures.

* a large map is resampled (nearest) before it is coloured (``interpolation_stage="data"``):
  the same pixels as colouring every grid point first (matplotlib's ``"rgba"`` stage, its own
  choice when a map is shrunk), for class codes and for a log-scaled field with holes;
* the Agg renderers of a process share one mathtext parser
  (:func:`stringstab.plots.share_mathtext_parser`): each label is parsed once, not once per
  renderer (a tight-box save uses two), and the pixels are the same;
* the dry run of a tight-box save leaves the images out
  (:func:`stringstab.plots.dry_runs_without_images`): each image is made once per save,
  and the PNG files are the same bytes.
"""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm
from matplotlib.mathtext import MathTextParser
from PIL import Image

from stringstab.plots import share_mathtext_parser
from stringstab.plots.map_axes import draw_field
from stringstab.regions import region_map


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def big():
    # more grid points per axis than the axes have pixels: the image is shrunk
    g = np.linspace(-2, 2, 401)
    return region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1,
                      methods="taylor", workers=1, progress=False)


def _pixels(fig) -> np.ndarray:
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba()).copy()


def _field_pixels(rmap, values, stage, size=3.0, **kw) -> tuple[np.ndarray, int]:
    fig = plt.figure(figsize=(size, size), dpi=100)
    ax = fig.add_subplot()
    im = draw_field(ax, rmap, values, **kw)
    if stage is not None:
        im.set_interpolation_stage(stage)
    px = _pixels(fig)
    width = round(ax.get_window_extent().width)
    plt.close(fig)
    return px, width


@pytest.mark.parametrize("size", [3.0, 5.0, 8.0])  # about 0.6, 1 and 1.5 pixels per grid point
def test_resampled_then_coloured_is_the_same_picture_as_coloured_then_resampled(big, size):
    codes = big.classes("taylor")
    colors = ["#BBBBBB", "#D55E00", "#E69F00", "#0072B2", "#56B4E9"]
    cmap, norm = ListedColormap(colors), BoundaryNorm(np.arange(6) - 0.5, 5)  # as the class maps
    new, width = _field_pixels(big, codes, None, size, cmap=cmap, norm=norm)
    old, _ = _field_pixels(big, codes, "rgba", size, cmap=cmap, norm=norm)
    assert width < 3 * 401  # where matplotlib's own choice would be the "rgba" stage
    assert len(np.unique(codes)) >= 3  # several classes, so the colours can differ
    np.testing.assert_array_equal(new, old)
    # a log-scaled field with holes (not internally stable: masked, drawn in the "bad" colour)
    rng = np.random.default_rng(0)
    field = np.where(codes > 0, 1.0 + rng.pareto(1.0, codes.shape), np.nan)
    cm = matplotlib.colormaps["cividis"].with_extremes(bad="#E4E4E4")
    kw = dict(cmap=cm, norm=LogNorm(vmin=1.0, vmax=20.0))
    new, _ = _field_pixels(big, np.ma.masked_invalid(field), None, size, **kw)
    old, _ = _field_pixels(big, np.ma.masked_invalid(field), "rgba", size, **kw)
    np.testing.assert_array_equal(new, old)
    # the check can fail: another colour map changes the pixels
    other, _ = _field_pixels(big, np.ma.masked_invalid(field), "rgba", size, cmap="viridis",
                             norm=LogNorm(vmin=1.0, vmax=20.0))
    assert np.any(other != old)


def _saved_label_figure(label: str, ylabel: str = r"$k_v$ (s$^{-1}$)") -> np.ndarray:
    fig = plt.figure(figsize=(3.0, 2.5), layout="constrained")
    ax = fig.add_subplot()
    ax.set_xlabel(label)
    ax.set_ylabel(ylabel)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=80, bbox_inches="tight", pad_inches=0.1)
    plt.close(fig)
    return np.asarray(Image.open(buf))


def test_renderers_share_one_mathtext_parser_and_draw_the_same_labels():
    label = r"$k_{\mathrm{share}}$ (s$^{-2}$)"  # parsed by no other test
    before = _saved_label_figure(label)  # whatever this process had: the reference pixels
    share_mathtext_parser()
    share_mathtext_parser()  # idempotent
    from matplotlib.backends.backend_agg import RendererAgg

    a, b = RendererAgg(10, 10, 72), RendererAgg(20, 20, 96)
    assert a.mathtext_parser is b.mathtext_parser
    assert isinstance(a.mathtext_parser, MathTextParser)
    # both labels new to this process whatever ran before in it (a shared parser may already
    # have parsed the default y label for another test)
    fresh, fresh_y = r"$k_{\mathrm{once}}$ (s$^{-2}$)", r"$k_{\mathrm{once},v}$ (s$^{-1}$)"
    misses = MathTextParser._parse_cached.cache_info().misses
    first = _saved_label_figure(fresh, fresh_y)
    after_one = MathTextParser._parse_cached.cache_info().misses - misses
    second = _saved_label_figure(fresh, fresh_y)
    after_two = MathTextParser._parse_cached.cache_info().misses - misses
    # each of the two labels once: a tight-box
    # save draws with two renderers, which without the shared parser parse each label twice
    assert after_one == 2, after_one
    assert after_two == 2, after_two  # the second figure parses nothing
    np.testing.assert_array_equal(first, second)
    np.testing.assert_array_equal(_saved_label_figure(label), before)


def _tight_png(fig) -> bytes:
    buf = io.BytesIO()  # as stringstab.io.save_figure saves
    fig.savefig(buf, format="png", dpi=60, bbox_inches="tight", pad_inches=0.1,
                metadata={"Software": "test"})
    return buf.getvalue()


def test_dry_runs_without_images_write_the_same_png_bytes(monkeypatch):
    from stringstab.io import read_gains
    from stringstab.plots import (
        draw_figure,
        dry_runs_without_images,
        figure_stems,
        outputs,
        trajectory_verdicts,
    )

    # the overlay's background (the exact region projected over the points' k_a) computed once
    projected, cache = outputs.projected_region, {}
    monkeypatch.setattr(outputs, "projected_region",
                        lambda *a, **k: cache.get("p") or cache.setdefault("p", projected(*a, **k)))

    g = np.linspace(-2, 2, 161)  # more grid points than the axes have pixels at 60 dpi
    m2 = region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1,
                    workers=1, progress=False)
    m3 = region_map({"k_x": g[::20], "k_v": g[::20], "k_a": np.linspace(-1, 1, 3)}, tau=0.1,
                    delta=0.2, headway=1.1, methods="exact", workers=1, progress=False)
    rollout = read_gains("stringstab/data/examples/gain_rollout.csv")
    verdicts = trajectory_verdicts(m2, rollout)
    jobs = [(m2, s) for s in figure_stems(m2, True, "all")] + [(m3, s) for s in figure_stems(m3)]
    assert len(jobs) == 6 + 2

    def saved(m, stem) -> bytes:  # a new figure each time: a second save of one lays it out anew
        fig = draw_figure(m, stem, rollout, verdicts)
        try:
            return _tight_png(fig)
        finally:
            plt.close(fig)

    for m, stem in jobs:
        plain = saved(m, stem)
        with dry_runs_without_images():
            skipped = saved(m, stem)
        assert skipped == plain, stem


def test_dry_runs_without_images_make_each_image_once_and_restore_matplotlib(monkeypatch):
    from matplotlib.image import AxesImage

    from stringstab.plots import dry_runs_without_images

    made = []
    make = AxesImage.make_image
    monkeypatch.setattr(AxesImage, "make_image",
                        lambda self, *a, **k: made.append(self) or make(self, *a, **k))
    fig = plt.figure(figsize=(2.0, 2.0))
    ax = fig.add_subplot()
    ax.imshow(np.arange(400.0).reshape(20, 20), interpolation="nearest")
    ax.imshow(np.ones((3, 3)), extent=(0, 5, 0, 5), alpha=0.5)  # two images
    assert "draw" not in AxesImage.__dict__  # inherited from matplotlib's image base class
    _tight_png(fig)
    assert len(made) == 4  # two images, each made in the dry run and in the real draw
    made.clear()
    with dry_runs_without_images():
        assert "draw" in AxesImage.__dict__
        _tight_png(fig)
        assert len(made) == 2  # each once: the dry run left them out
        made.clear()
        fig.canvas.draw()  # a plain draw (no dry run) still makes them
        assert len(made) == 2
    assert "draw" not in AxesImage.__dict__  # restored on leaving
    made.clear()
    _tight_png(fig)
    assert len(made) == 4


def _glyph_fonts(label: str, dpi: int) -> list[int]:
    """The identities of the font objects a label's parse (by the Agg renderers' parser) holds."""
    from matplotlib.backends.backend_agg import RendererAgg

    parse = RendererAgg(10, 10, dpi).mathtext_parser.parse(label, dpi)
    return sorted({id(g[0]) for g in parse.glyphs})


def test_a_forked_drawer_parses_with_fonts_of_its_own():
    """A parse made before a fork is not drawn after it (its fonts' file offset is shared).

    Agg loads a parse's glyphs from its fonts when it draws, reading through the font file's
    offset, which a fork shares: two drawers forked from one warm process, drawing the labels
    parsed there, read each other's bytes (FreeType errors, or a wrong glyph).
    """
    from stringstab.parallel import start_helper

    share_mathtext_parser()
    label = r"$k_{\mathrm{fork}}$ (s$^{-2}$)"
    here = _glyph_fonts(label, 80)
    assert here and _glyph_fonts(label, 80) == here  # in this process: the parse is reused
    with start_helper(method="fork") as h:
        h.submit(_glyph_fonts, label, 80)
        there = h.result()
    # the parent's font objects are still alive in the child (its old parses hold them), so a
    # fresh parse's fonts cannot take their addresses: other identities mean other fonts
    assert there and not set(there) & set(here), (here, there)
