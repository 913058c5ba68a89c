"""The cheaper ways the region figures are drawn (issue 31) draw the same pictures.

* a large map is resampled (nearest) before it is coloured (``interpolation_stage="data"``):
  the same pixels as colouring every grid point first (matplotlib's ``"rgba"`` stage, its own
  choice when a map is shrunk), for class codes and for a log-scaled field with holes;
* the Agg renderers of a process share one mathtext parser
  (:func:`stringstab.plots.share_mathtext_parser`): each label is parsed once, not once per
  renderer (a tight-box save uses two), and the pixels are the same.
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
