"""Plots in python-control's pattern: compute a result, draw it, get a PlotResult back."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
from numpy.testing import assert_array_equal

from stringstab import plots
from stringstab.certify.api import certify_batch
from stringstab.errors import StringStabError
from stringstab.regions import region_map
from stringstab.tuning import TuneResults, project, region_growing

P = dict(tau=0.1, delta=0.2, headway=1.1)


@pytest.fixture(autouse=True)
def _close():
    yield
    plt.close("all")


def test_plot_result_reads_like_the_old_dicts_and_unpacks_like_subplots():
    m = region_map({"k_x": np.linspace(-2, 2, 9), "k_v": np.linspace(-2, 2, 9)}, {"k_a": 0.5},
                   **P, methods="taylor")
    out = plots.plot_class_map(m, "taylor")
    fig, axes = out
    assert fig is out.figure is out["fig"] is out.ax.figure and axes == (out["ax"],)
    assert out["axes"] == [out.ax] and "image" in out and "nothing" not in out
    with pytest.raises(KeyError):
        out["nothing"]


def test_plot_moves_draws_a_region_computed_beforehand():
    rs = [f((0.9, -0.5, 1.1), **P) for f in (region_growing, project)]
    region = plots.moves_region(rs, **P, n=15)
    assert region.fixed == {"k_a": 1.1} and region.shape == (15, 15)  # the median input k_a
    out = plots.plot_moves(rs, region=region)
    assert len(out["arrows"]) == 2
    assert_array_equal(out["region"].get_array().reshape(15, 15), region.stable("exact"))
    with pytest.raises(TypeError, match="region"):  # the background is computed beforehand
        plots.plot_moves(rs)  # type: ignore[call-arg]
    taylor = region_map({"k_x": np.linspace(-2, 2, 5), "k_v": np.linspace(-2, 2, 5)},
                        {"k_a": 1.1}, **P, methods="taylor")
    with pytest.raises(StringStabError, match="exact verdicts"):
        plots.plot_moves(rs, region=taylor)


def test_trajectory_with_verdicts_computed_beforehand_runs_no_certificate(monkeypatch):
    m = region_map({"k_x": np.linspace(0, 2, 9), "k_v": np.linspace(-1, 1, 9)}, {"k_a": 0.5},
                   **P, methods="taylor")
    K = np.array([[1.5, 0.3, -0.1], [0.9, -0.5, 1.1]])
    batch = certify_batch(K[:, 0], K[:, 1], K[:, 2], **P)
    from stringstab.certify import api as cert

    def boom(*a, **k):
        raise AssertionError("the plot ran a certificate")

    monkeypatch.setattr(cert, "certify_batch", boom)
    out = plots.plot_trajectory(m, K, verdicts=batch)
    assert out["verdicts"] == ["certified", "not_certified"]
    with pytest.raises(StringStabError, match="one verdict per gain triple"):
        plots.plot_trajectory(m, K, verdicts=["certified"])


def test_traffic_figures_return_plot_results():
    t = np.linspace(0, 10, 50)
    v = np.vstack([np.sin(t), np.cos(t)])
    out = plots.plot_vehicles(t, v)
    assert out["lines"].get_array().tolist() == [0.0, 1.0]
    mp = plots.plot_damping_ratios([0.9, 1.1, 0.95])
    assert len(mp["lines"]) == 2 and mp.ax.get_ylabel().startswith("damping ratio")


def test_tune_results_own_columns_records_and_summary():
    rs = TuneResults.collect([project((0.9, -0.5, 1.1), **P), project((1.3, 0.0, 0.6), **P)],
                             meta={"t": [0.0, 0.1]}, methods=["projection"])
    cols = rs.columns()
    assert list(cols)[:2] == ["t", "method"] and cols["status"].tolist() == ["repaired", "unchanged"]
    assert rs.records()[1]["t"] == 0.1 and rs.records()[1]["k_x"] == 1.3
    s = rs.summary()["projection"]
    assert (s["n"], s["certified"], s["repaired"], s["unchanged"]) == (2, 2, 1, 1)
    assert s["median_distance_moved"] == rs[0].distance
    assert rs.certified.tolist() == [True, True]
