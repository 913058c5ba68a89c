"""Plot functions draw into the axes they are given and return what they drew."""

import json

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.collections import PathCollection
from matplotlib.contour import ContourSet
from matplotlib.image import AxesImage
from matplotlib.legend import Legend
from numpy.testing import assert_array_equal

from stringstab import plots
from stringstab.certify.api import certify_batch
from stringstab.errors import StringStabError
from stringstab.io import GainTable
from stringstab.regions import EXACT_CLASSES, TYPE_CLASSES, region_map

P = dict(tau=0.1, delta=0.2, headway=1.1)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def m2():
    # k_x = 0.9 slice over (k_v, k_a): every comparison pattern of interest occurs here
    return region_map({"k_v": np.linspace(-2, 2, 41), "k_a": np.linspace(-2, 2, 41)}, {"k_x": 0.9}, **P)


@pytest.fixture(scope="module")
def m3():
    g = np.linspace(-2, 2, 9)
    return region_map({"k_x": g, "k_v": g, "k_a": g}, **P, methods=("exact", "taylor"))


@pytest.mark.parametrize("method", ["exact", "taylor", "printed"])
def test_class_map_draws_into_ax_with_shares_in_the_legend(m2, method):
    _fig, ax = plt.subplots()
    out = plots.plot_class_map(m2, method, ax=ax)
    assert out["ax"] is ax and isinstance(out["image"], AxesImage) and isinstance(out["legend"], Legend)
    names = EXACT_CLASSES if method == "exact" else TYPE_CLASSES
    labels = [t.get_text() for t in out["legend"].get_texts()]
    assert [lab.split(" (")[0] for lab in labels] == list(names)
    assert_array_equal(out["image"].get_array(), m2.classes(method).T)
    assert "τ = 0.1 s" in ax.get_title() and "k_x = 0.9" in ax.get_title()
    assert ax.get_xlabel().startswith("$k_v$") and ax.get_ylabel().startswith("$k_a$")


def test_comparison_counts_add_up_to_the_disagreements(m2):
    out = plots.plot_comparison(m2)
    d = m2.disagreements()
    assert out["disagreements"] == d["any"] > 0
    assert sum(out["counts"].values()) == m2.size
    assert out["counts"]["exact inconclusive"] == d["inconclusive"]
    unsafe = out["counts"]["exact ✗ · taylor ✗ · printed ✓"]
    direct = np.count_nonzero(~m2.stable("exact") & ~m2.stable("taylor") & m2.stable("printed")
                              & (m2.verdict["exact"] != 2))
    assert unsafe == direct > 0
    assert f"disagreements: {d['any']:,}" in out["legend"].get_title().get_text()


def test_comparison_of_two_methods_and_errors(m2):
    out = plots.plot_comparison(m2, ["exact", "printed"])
    assert out["disagreements"] == m2.disagreements()["exact vs printed"]
    with pytest.raises(StringStabError, match="2 or 3 distinct"):
        plots.plot_comparison(m2, ["exact"])


def test_sup_gain_heat_map_has_log_scale_and_boundary(m2):
    _fig, ax = plt.subplots()
    out = plots.plot_sup_gain(m2, ax=ax)
    assert out["ax"] is ax and isinstance(out["contour"], ContourSet)
    assert isinstance(out["image"].norm, matplotlib.colors.LogNorm) and out["image"].norm.vmin == 1.0
    assert out["colorbar"] is not None
    # not internally stable points are masked (drawn in the 'bad' colour)
    data = out["image"].get_array()
    assert_array_equal(np.ma.getmaskarray(data), ~np.isfinite(m2.sup_gain).T)


def test_trajectory_is_marked_by_its_own_verdicts(m2):
    K = np.array([[0.9, 0.5, 0.3], [0.9, -0.5, 1.1], [0.9, 1.0, 0.2], [-0.5, 1.0, 1.0]])
    table = GainTable(K[:, 0], K[:, 1], K[:, 2], t=np.arange(4.0), vehicle=np.array([1, 1, 2, 2]))
    ax = plots.plot_class_map(m2, "exact")["ax"]
    expect = certify_batch(K[:, 0], K[:, 1], K[:, 2], **P).verdict.tolist()
    assert plots.trajectory_verdicts(m2, table) == expect  # the compute step: the map's loop
    out = plots.plot_trajectory(m2, table, verdicts=expect, ax=ax)
    assert out["verdicts"] == expect
    assert len(out["lines"]) == 2
    for v, coll in out["markers"].items():
        assert isinstance(coll, PathCollection)
        assert len(coll.get_offsets()) == expect.count(v)
    # the map's own legend entries are kept, the trajectory's added
    labels = [t.get_text() for t in out["legend"].get_texts()]
    assert any(lab.startswith("certified") for lab in labels)
    assert any(lab.startswith("policy gains: not certified") for lab in labels)
    with pytest.raises(StringStabError, match=r"\(n, 3\)"):
        plots.plot_trajectory(m2, np.zeros((3, 2)), verdicts=["certified"] * 3, ax=ax)
    # the figures draw results, they do not compute them: gains come with their verdicts
    with pytest.raises(TypeError, match="verdicts"):
        plots.plot_trajectory(m2, table, ax=ax)  # type: ignore[call-arg]


def test_3d_views(m3):
    out = plots.plot_slices(m3, "exact", n=4)
    assert len(out["axes"]) == len(out["images"]) == 4
    assert_array_equal(out["values"], m3.axes["k_a"][[0, 3, 5, 8]])
    fig = plt.figure()
    ax = fig.add_subplot(projection="3d")
    surf = plots.plot_region_3d(m3, "exact", ax=ax)
    assert surf["ax"] is ax and len(surf["artists"]) == 2
    pts = plots.plot_region_3d(m3, "taylor", kind="points")
    st = m3.stable("taylor")
    assert 0 < pts["n_boundary"] <= st.sum()
    with pytest.raises(StringStabError, match="3-D"):
        plots.plot_class_map(m3, "exact")


def test_facets_and_boundaries_over_tau():
    g = np.linspace(-2, 2, 21)
    maps = [region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=t, delta=0.2, headway=1.1) for t in (0.1, 0.5)]
    _fig, axes = plt.subplots(1, 2)
    out = plots.plot_facets(maps, "exact", axes=axes)
    assert out["axes"] == list(axes) and len(out["images"]) == 2
    assert out["shares"] == [m.stable("exact").mean() for m in maps]
    assert "τ = 0.5 s" in axes[1].get_title()
    heat = plots.plot_facets(maps, kind="sup_gain")
    assert len(heat["images"]) == 2
    b = plots.plot_boundaries(maps)
    assert len(b["contours"]) == 2 and all(isinstance(c, ContourSet) for c in b["contours"])
    other = region_map({"k_x": g, "k_a": g}, {"k_v": 0.5}, **P)
    with pytest.raises(StringStabError, match="same gains"):
        plots.plot_boundaries([maps[0], other])


def test_save_figures_writes_each_format(tmp_path, m2):
    written = plots.save_figures(m2, tmp_path, formats=("png", "svg"), dpi=40)
    names = sorted(p.name for p in written)
    # the default figures (issue 31): the first method's class map, the comparison and sup|Γ|
    assert names == sorted(f"region_{s}.{f}" for s in ("class_exact", "compare", "sup_gain")
                           for f in ("png", "svg"))
    assert all(p.stat().st_size > 0 for p in written)
    from PIL import Image

    info = Image.open(tmp_path / "region_compare.png").info
    assert info["Software"] == f"stringstab {m2.version}"
    meta = json.loads(info["Description"])
    assert meta["params"] == {"tau": 0.1, "delta": 0.2, "headway": 1.1} and meta["fixed"] == {"k_x": 0.9}
    assert m2.version in (tmp_path / "region_sup_gain.svg").read_text()
    with pytest.raises(StringStabError, match="formats"):
        plots.save_figures(m2, tmp_path, formats=("gif",))
    with pytest.raises(StringStabError, match="figures must be one of default, all"):
        plots.save_figures(m2, tmp_path, formats=("png",), figures="every")
    with pytest.raises(StringStabError, match="verdicts"):  # gains come with their verdicts
        plots.save_figures(m2, tmp_path, formats=("png",), gains=[[0.9, 0.5, 0.3]])
    # each file was written atomically: no temporary file is left beside them
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in written)
