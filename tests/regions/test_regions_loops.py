"""Region maps of the sampled and robust loops, and the band that sampling removes (phase 2)."""

import json

import matplotlib.pyplot as plt
import numpy as np
import pytest

from stringstab.certify.api import certify_batch
from stringstab.cli import main
from stringstab.errors import StringStabError
from stringstab.params import Box
from stringstab.plots import plot_class_map, plot_comparison, plot_sup_gain
from stringstab.regions import CONTINUOUS, load_npz, region_map

AXES = {"k_x": np.linspace(0.05, 2.0, 14), "k_v": np.linspace(-0.5, 2.0, 13)}
P = dict(tau=0.1, delta=0.2, headway=1.1)


@pytest.fixture(scope="module")
def sampled_map():
    return region_map(AXES, {"k_a": 0.5}, sample_time=0.2, methods=("exact", CONTINUOUS),
                      workers=1, **P)


def test_sampled_map_is_the_sampled_certificate_and_the_continuous_one(sampled_map):
    m = sampled_map
    kx, kv, ka = (g.ravel() for g in m.gains())
    s = certify_batch(kx, kv, ka, sample_time=0.2, **P)
    c = certify_batch(kx, kv, ka, **P)
    assert np.array_equal(m.stable("exact").ravel(), s.certified)
    assert np.array_equal(m.stable(CONTINUOUS).ravel(), c.certified)
    assert np.array_equal(m.hurwitz.ravel(), s.schur)
    assert np.array_equal(m.hurwitz_continuous.ravel(), c.hurwitz)
    assert np.allclose(m.sup_gain.ravel(), s.sup_gain, equal_nan=True)
    assert m.type is None and m.sample_time == 0.2
    band = m.stable(CONTINUOUS) & ~m.stable("exact")
    assert band.sum() > 0  # sampling at 5 Hz removes certified gains here
    assert not (m.stable("exact") & ~m.stable(CONTINUOUS)).any()
    assert "sampled Δt = 0.2 s" in m.title()
    assert f"certified in continuous time but not when sampled: {int(band.sum()):,} points" in m.report()


def test_the_comparison_figure_counts_the_band(sampled_map):
    out = plot_comparison(sampled_map)
    band = int((sampled_map.stable(CONTINUOUS) & ~sampled_map.stable("exact")).sum())
    assert out["counts"]["sampled ✗ · continuous ✓"] == band
    labels = [t.get_text() for t in out["legend"].get_texts()]
    assert f"sampled ✗ · continuous ✓ (n = {band:,})" in labels
    assert "sampled vs continuous" in out.ax.get_title()
    heat = plot_sup_gain(sampled_map)
    assert "sup|H(e^{jθ})|" in heat.ax.get_title()
    cls = plot_class_map(sampled_map, CONTINUOUS)
    assert "continuous-time certificate" in cls.ax.get_title()
    plt.close("all")


def test_box_map_is_the_robust_certificate_and_round_trips(tmp_path):
    m = region_map({"k_x": np.linspace(0.2, 2.0, 6), "k_v": np.linspace(0.0, 2.0, 5)},
                   {"k_a": 0.5}, tau=(0.1, 0.3), delta=(0.1, 0.3), headway=1.1, workers=1)
    kx, kv, ka = (g.ravel() for g in m.gains())
    r = certify_batch(kx, kv, ka, tau=(0.1, 0.3), delta=(0.1, 0.3), headway=1.1)
    assert np.array_equal(m.stable("exact").ravel(), r.certified)
    assert m.is_box and m.methods == ("exact",)
    assert "τ ∈ [0.1, 0.3] s, δ ∈ [0.1, 0.3] s, T* = 1.1 s" in m.title()
    back = load_npz(m.save_npz(tmp_path / "m.npz"))
    assert back.params == Box((0.1, 0.3), (0.1, 0.3), (1.1, 1.1)) and back.sample_time is None
    assert np.array_equal(back.verdict["exact"], m.verdict["exact"])
    plt.close(plot_sup_gain(m).figure)


@pytest.mark.parametrize("kw, msg", [
    ({"sample_time": 0.1, "methods": "exact,taylor"}, "Taylor criteria"),
    ({"tau": (0.1, 0.2), "methods": "printed"}, "Taylor criteria"),
    ({"methods": "exact,continuous"}, "needs sample_time"),
    ({"tau": (0.1, 0.2), "methods": "continuous"}, "needs sample_time"),
    ({"sample_time": 0.1, "methods": "continuous"}, "evaluates 'exact'"),
    ({"sample_time": 0.0}, "sample_time"),
])
def test_bad_methods_for_the_loop(kw, msg):
    p = {**P, **kw}
    with pytest.raises(StringStabError, match=msg):
        region_map(AXES, {"k_a": 0.5}, **p)


def test_cli_region_sample_time_compare_continuous(tmp_path, capsys):
    out = tmp_path / "maps"
    code = main(["region", "--fix", "k_a=0.5", "--range", "k_x=0.05,2", "--range", "k_v=-0.5,2",
                 "--n", "12", "--sample-time", "0.2", "--compare", "continuous", "--out", str(out),
                 "--format", "png", "--workers", "1"])
    stdout = capsys.readouterr().out
    assert code == 0
    names = {p.name for p in out.iterdir()}
    assert {"region_class_exact.png", "region_compare.png",
            "region_sup_gain.png", "region.npz", "region.csv"} <= names
    assert "region_class_continuous.png" not in names  # with --figures all (issue 31)
    assert "certified in continuous time but not when sampled" in stdout
    m = load_npz(out / "region.npz")
    assert m.sample_time == 0.2 and m.methods == ("exact", "continuous")
    meta = json.loads((out / "region.csv").read_text().splitlines()[1][2:])
    assert meta["sample_time"] == 0.2


@pytest.mark.parametrize("args, msg", [
    (["--compare", "continuous"], "expected --sample-time"),
    (["--sample-time", "0.1", "--method", "taylor"], "Taylor criteria"),
    (["--tau", "0.2:0.1"], "lo <= hi"),
    (["--sample-time", "-1"], "--sample-time"),
])
def test_cli_region_bad_input_writes_nothing(tmp_path, capsys, args, msg):
    out = tmp_path / "maps"
    code = main(["region", "--fix", "k_a=0.5", "--n", "5", "--out", str(out), *args])
    _, err = capsys.readouterr()
    assert code == 2 and msg in err and not out.exists()
