"""Region maps against independent truth: single-point certificates, the Taylor criteria
evaluated point by point, a dense frequency sweep with numpy.roots, and file round trips."""

import csv
import json

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

import stringstab
from stringstab.certify.api import certify, certify_batch
from stringstab.certify.criteria import TYPE_NAMES, hurwitz, taylor_criteria
from stringstab.errors import StringStabError
from stringstab.regions import (
    EXACT_CLASSES,
    TYPE_CLASSES,
    load_npz,
    region_map,
)
from stringstab.regions.grid import grid_blocks

TAU, DELTA, HEADWAY = 0.1, 0.2, 1.1
P = dict(tau=TAU, delta=DELTA, headway=HEADWAY)
#: Round-off band: a Ψ within this of 0 may take either sign between two evaluation orders.
PSI_TIE = 1e-9


@pytest.fixture(scope="module")
def slice_map():
    """A 2-D slice with every exact class present (k_a = 0.8 crosses the interesting part)."""
    return region_map(
        {"k_x": np.linspace(-0.5, 2.0, 11), "k_v": np.linspace(-1.05, 1.95, 13)}, {"k_a": 0.8}, **P
    )


@pytest.fixture(scope="module")
def volume_map():
    g = np.linspace(-1.9, 1.9, 9)
    return region_map({"k_a": g, "k_x": g + 0.05, "k_v": g}, tau=0.2, delta=0.3, headway=1.5)


def _ties(kx, kv, ka, tau, delta, headway, source):
    """Points where some Ψ or Λ is within round-off of 0 (their sign is not determined)."""
    c = taylor_criteria(kx, kv, ka, tau=tau, delta=delta, headway=headway, source=source)
    return (np.abs(c.psi1) < PSI_TIE) | (np.abs(c.psi2) < PSI_TIE) | (np.abs(c.psi3) < PSI_TIE) | (
        np.abs(c.lam) < PSI_TIE
    )


# --------------------------------------------------------------------------- single points
@pytest.mark.parametrize("which", ["slice", "volume"])
def test_map_equals_single_point_certificates(which, slice_map, volume_map):
    m = slice_map if which == "slice" else volume_map
    p = m.params
    kx, kv, ka = m.gains()
    rng = np.random.default_rng(4)
    idx = [tuple(int(rng.integers(0, s)) for s in m.shape) for _ in range(25)]
    # and one point of every exact class present
    cls = m.classes("exact")
    idx += [tuple(int(v) for v in np.argwhere(cls == c)[0]) for c in np.unique(cls)]
    assert len(np.unique(cls)) >= 3
    for i in idx:
        c = certify(float(kx[i]), float(kv[i]), float(ka[i]), tau=p.tau, delta=p.delta, headway=p.headway)
        assert c.verdict == ("certified", "not_certified", "inconclusive")[m.verdict["exact"][i]], i
        if np.isinf(c.sup_gain):
            assert np.isinf(m.sup_gain[i])
        else:
            assert_allclose(m.sup_gain[i], c.sup_gain, rtol=1e-12, atol=0)
        assert_allclose(m.margin[i], c.margin, rtol=1e-12, atol=1e-15)
        tie = _ties(kx[i], kv[i], ka[i], p.tau, p.delta, p.headway, "derived")
        if not tie:
            assert TYPE_NAMES[int(m.type[i])] == c.type, i
            assert m.prop1["taylor"][i] == (c.taylor_derived["sign"] == "stable"), i
        if not _ties(kx[i], kv[i], ka[i], p.tau, p.delta, p.headway, "printed"):
            assert TYPE_NAMES[int(m.type_printed[i])] == c.taylor_printed["type"], i
            assert m.prop1["printed"][i] == (c.taylor_printed["sign"] == "stable"), i
        # the map's Taylor verdicts include internal stability
        assert m.verdict["taylor"][i] == (0 if (m.prop1["taylor"][i] and m.hurwitz[i]) else 1)


# --------------------------------------------------------------------------- whole grids
@pytest.mark.parametrize("order", [("k_x", "k_v", "k_a"), ("k_a", "k_x", "k_v"), ("k_v", "k_a", "k_x")])
def test_taylor_fields_equal_taylor_criteria_on_every_point(order):
    axes = {"k_x": np.linspace(-2, 2, 17), "k_v": np.linspace(-1.5, 2.5, 15), "k_a": np.linspace(-2, 1.5, 13)}
    m = region_map({g: axes[g] for g in order}, tau=0.2, delta=0.25, headway=1.3,
                   methods=("taylor", "printed"))
    kx, kv, ka = m.gains()
    assert_array_equal(m.hurwitz, hurwitz(kx, kv, tau=0.2, headway=1.3))
    for source, method, types in (("derived", "taylor", m.type), ("printed", "printed", m.type_printed)):
        ref = taylor_criteria(kx, kv, ka, tau=0.2, delta=0.25, headway=1.3, source=source)
        ok = ~_ties(kx, kv, ka, 0.2, 0.25, 1.3, source)  # includes the plane k_x = 0 (Ψ3 = 0)
        assert ok.mean() > 0.9
        assert_array_equal(types[ok], ref.type[ok])
        assert_array_equal(m.prop1[method][ok], ref.stable[ok])
        # at ties, only a few points may fall on the other side by round-off
        assert np.count_nonzero(types != ref.type) <= 0.01 * types.size


def test_taylor_class_shares_equal_an_independent_computation():
    g = np.linspace(-2, 2, 41)
    m = region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, **P, methods=("taylor", "printed"))
    KX, KV = np.meshgrid(g, g, indexing="ij")
    hz = (KX > 0) & (KV + (HEADWAY - TAU) * KX > 0)  # Hurwitz conditions written out
    for source, method in (("derived", "taylor"), ("printed", "printed")):
        c = taylor_criteria(KX, KV, 0.5, **P, source=source)
        cls = np.where(
            ~hz, "not internally stable",
            np.where(c.psi3 < 0, "type III",
                     np.where(c.psi2 >= 0, "type I", np.where(c.lam <= 0, "type II", "type IV"))),
        )
        ties = _ties(KX, KV, 0.5, TAU, DELTA, HEADWAY, source) | (np.abs(KV + (HEADWAY - TAU) * KX) < 1e-12)
        shares = m.class_shares()[method]
        assert list(shares) == list(TYPE_CLASSES)
        for name in TYPE_CLASSES:
            assert_allclose(shares[name], np.mean(cls == name), rtol=0, atol=ties.mean() + 1e-15)
        assert_allclose(sum(shares.values()), 1.0, rtol=1e-12)


def _sweep_class(kx, kv, ka, tau, delta, headway):
    """Independent exact class: numpy.roots for stability, |Γ(jω)| on a dense grid otherwise.

    Returns the EXACT_CLASSES name, or None when the sweep cannot decide (borderline).
    """
    poles = np.roots([tau, 1.0, kv + headway * kx, kx])
    if np.max(poles.real) > 1e-9:
        return "not internally stable"
    if np.max(poles.real) > -1e-9:
        return None
    w = np.linspace(1e-3, 60.0, 60_001)
    s = 1j * w
    gam = (kx + kv * s + ka * s**2 * np.exp(-delta * s)) / (tau * s**3 + s**2 + (kv + headway * kx) * s + kx)
    m = np.min((1.0 - np.abs(gam) ** 2) / np.minimum(1.0, w**2))
    if abs(m) <= 1e-6:
        return None
    return "certified" if m > 0 else "not certified"


def test_exact_class_shares_equal_a_frequency_sweep():
    gx = np.linspace(-0.3, 2.0, 13)
    gv = np.linspace(-1.0, 1.9, 13)
    m = region_map({"k_x": gx, "k_v": gv}, {"k_a": 0.8}, **P, methods=("exact",))
    truth = np.empty(m.shape, dtype=object)
    for i, x in enumerate(gx):
        for j, v in enumerate(gv):
            truth[i, j] = _sweep_class(x, v, 0.8, TAU, DELTA, HEADWAY)
    decided = truth != None  # noqa: E711 - elementwise on an object array
    assert decided.mean() > 0.95
    names = np.array(EXACT_CLASSES)[m.classes("exact")]
    assert_array_equal(names[decided], truth[decided].astype(str))
    shares = m.class_shares()["exact"]
    for name in EXACT_CLASSES:
        assert_allclose(shares[name], np.mean(truth == name), atol=(~decided).mean())
    assert {"certified", "not certified", "not internally stable"} <= set(truth[decided])


def test_disagreements_equal_direct_counts(slice_map):
    m = slice_map
    kx, kv, ka = (a.ravel() for a in m.gains())
    ex = certify_batch(kx, kv, ka, **P).verdict.reshape(m.shape)
    pr = taylor_criteria(kx, kv, ka, **P, source="printed").stable.reshape(m.shape) & hurwitz(
        kx, kv, **{"tau": TAU, "headway": HEADWAY}).reshape(m.shape)
    decided = ex != "inconclusive"
    direct = int(np.count_nonzero(decided & ((ex == "certified") != pr)))
    assert m.disagreements()["exact vs printed"] == direct
    assert m.disagreements()["inconclusive"] == int(np.count_nonzero(~decided))
    d = m.disagreements()
    assert d["any"] >= max(d["exact vs taylor"], d["exact vs printed"], d["taylor vs printed"])


def test_worker_processes_give_the_same_map():
    axes = {"k_x": np.linspace(-0.5, 2, 12), "k_v": np.linspace(-1, 2, 10), "k_a": np.array([-0.9, 0.4, 1.1])}
    one = region_map(axes, **P, workers=1, block=37)
    two = region_map(axes, **P, workers=2, block=37)
    for a, b in zip(one._fields().values(), two._fields().values()):
        assert_array_equal(a, b)


def _map_in_a_daemon(axes):
    return region_map(axes, **P, workers=2, block=37).verdict["exact"]


def test_map_inside_a_daemonic_worker_runs_in_one_process():
    import multiprocessing

    axes = {"k_x": np.linspace(-0.5, 2, 6), "k_v": np.linspace(-1, 2, 5)}
    fixed_axes = {**axes, "k_a": np.array([0.2, 0.9])}
    # multiprocessing.Pool workers are daemonic and may not start processes of their own
    with multiprocessing.get_context("fork").Pool(1) as pool:
        got = pool.apply_async(_map_in_a_daemon, (fixed_axes,)).get(timeout=60)
    assert_array_equal(got, region_map(fixed_axes, **P, workers=1).verdict["exact"])


@pytest.mark.parametrize("shape,target", [((7, 5, 3), 10), ((3, 40, 2), 9), ((1, 1, 1), 5), ((50, 1, 1), 7)])
def test_blocks_cover_the_grid_once(shape, target):
    seen = np.zeros(shape, dtype=int)
    for i0, i1, j0, j1 in grid_blocks(*shape, target):
        seen[i0:i1, j0:j1] += 1
        assert (i1 - i0) * (j1 - j0) * shape[2] <= max(target, shape[2])
    assert_array_equal(seen, 1)


def test_slice_of_a_volume_equals_the_direct_slice(volume_map):
    k = 3
    value = float(volume_map.axes["k_v"][k])
    s = volume_map.slice("k_v", value)
    direct = region_map({"k_a": volume_map.axes["k_a"], "k_x": volume_map.axes["k_x"]}, {"k_v": value},
                        tau=0.2, delta=0.3, headway=1.5)
    assert s.axis_names == ("k_a", "k_x") and s.fixed == {"k_v": value}
    for a, b in zip(s._fields().values(), direct._fields().values()):
        assert_array_equal(a, b)


# --------------------------------------------------------------------------- files
def test_npz_round_trip_keeps_fields_parameters_and_version(tmp_path, slice_map):
    path = slice_map.save_npz(tmp_path / "m.npz")
    back = load_npz(path)
    assert back.params == slice_map.params and back.fixed == {"k_a": 0.8}
    assert back.methods == slice_map.methods and back.version == stringstab.__version__
    for n in slice_map.axes:
        assert_array_equal(back.axes[n], slice_map.axes[n])
    for (ka, a), (kb, b) in zip(slice_map._fields().items(), back._fields().items()):
        assert ka == kb
        assert_array_equal(a, b)
    with np.load(path) as z:
        meta = json.loads(str(z["metadata"]))
    assert meta["stringstab_version"] == stringstab.__version__
    assert meta["params"] == {"tau": TAU, "delta": DELTA, "headway": HEADWAY}


def test_files_split_from_the_result_keep_every_import_path(tmp_path, slice_map):
    # issue 32 item 5: the map's files live in regions/storage, the names in regions/codes;
    # the methods and the old import paths give the same files and objects
    from stringstab.regions import codes, result, storage

    for name in ("CONTINUOUS", "EXACT_CLASSES", "GAIN_NAMES", "METHODS", "STABLE",
                 "TYPE_CLASSES", "UNSTABLE", "VERDICT_LABELS"):
        assert getattr(result, name) is getattr(codes, name)
    assert result.load_npz is load_npz
    a = slice_map.save_csv(tmp_path / "a.csv").read_text()
    b = storage.save_csv(slice_map, tmp_path / "b.csv").read_text()
    assert a == b == slice_map.csv_text()
    assert slice_map.metadata() == storage.metadata(slice_map)
    back = load_npz(storage.save_npz(slice_map, tmp_path / "m.npz"))
    assert back.csv_text() == a  # the reader rebuilds the map the writer saved


def test_load_npz_rejects_other_files(tmp_path):
    np.savez(tmp_path / "x.npz", a=np.arange(3))
    with pytest.raises(StringStabError, match="metadata"):
        load_npz(tmp_path / "x.npz")
    (tmp_path / "y.npz").write_text("not a zip")
    with pytest.raises(StringStabError, match="expected a region-map NPZ"):
        load_npz(tmp_path / "y.npz")


def test_csv_has_metadata_and_one_row_per_point(tmp_path, slice_map):
    path = slice_map.save_csv(tmp_path / "m.csv")
    lines = path.read_text().splitlines()
    assert lines[0] == f"# stringstab {stringstab.__version__} region map"
    meta = json.loads(lines[1][2:])
    assert meta["params"]["tau"] == TAU and meta["fixed"] == {"k_a": 0.8}
    rows = list(csv.DictReader(lines[2:]))
    assert len(rows) == slice_map.size
    kx, kv, _ = slice_map.gains()
    i = (4, 7)
    r = rows[np.ravel_multi_index(i, slice_map.shape)]
    assert float(r["k_x"]) == kx[i] and float(r["k_v"]) == kv[i] and float(r["k_a"]) == 0.8
    assert r["exact"] == ("certified", "not_certified", "inconclusive")[slice_map.verdict["exact"][i]]
    assert float(r["sup_gain"]) == slice_map.sup_gain[i]


# --------------------------------------------------------------------------- bad input
G = np.linspace(-1, 1, 3)


@pytest.mark.parametrize(
    "axes,fixed,kw,match",
    [
        ({"k_x": G, "k_q": G}, {"k_a": 0.5}, {}, "axis gains must be among"),
        ({"k_x": G}, {"k_a": 0.5}, {}, "expected 2 or 3 axis gains"),
        ({"k_x": G, "k_v": G}, None, {}, "needs the third gain fixed"),
        ({"k_x": G, "k_v": G}, {"k_v": 0.5}, {}, "needs the third gain fixed"),
        ({"k_x": G, "k_v": G, "k_a": G}, {"k_a": 0.5}, {}, "fixes no gain"),
        ({"k_x": [0.0], "k_v": G}, {"k_a": 0.5}, {}, "at least 2 points"),
        ({"k_x": [1.0, 0.0], "k_v": G}, {"k_a": 0.5}, {}, "strictly increasing"),
        ({"k_x": [0.0, np.nan], "k_v": G}, {"k_a": 0.5}, {}, "must be finite"),
        ({"k_x": G, "k_v": G}, {"k_a": float("inf")}, {}, "must be finite"),
        ({"k_x": G, "k_v": G}, {"k_a": 0.5}, {"methods": "exact,nope"}, "methods must be among"),
        ({"k_x": G, "k_v": G}, {"k_a": 0.5}, {"methods": ("exact", "exact")}, "once"),
        ({"k_x": G, "k_v": G}, {"k_a": 0.5}, {"methods": ()}, "at least one method"),
        ({"k_x": G, "k_v": G}, {"k_a": 0.5}, {"tau": 0.0}, "tau"),
        ({"k_x": G, "k_v": G}, {"k_a": 0.5}, {"workers": 0}, "workers"),
    ],
)
def test_bad_input_is_an_error(axes, fixed, kw, match):
    args = {**P, **kw}
    with pytest.raises(StringStabError, match=match):
        region_map(axes, fixed, **args)


def test_unevaluated_method_is_an_error(slice_map):
    m = region_map({"k_x": G, "k_v": G}, {"k_a": 0.5}, **P, methods="taylor")
    with pytest.raises(StringStabError, match="evaluated"):
        m.classes("exact")
    with pytest.raises(StringStabError, match="3-D"):
        slice_map.slice("k_x", 0.0)


@pytest.mark.parametrize("damage", ["not json", "missing methods", "missing array"])
def test_load_npz_refuses_a_damaged_map_in_one_line(tmp_path, damage):
    import json

    rmap = region_map({"k_x": np.linspace(0.1, 2, 5), "k_v": np.linspace(-1, 1, 5)}, {"k_a": 0.5},
                      **P)
    good = tmp_path / "good.npz"
    rmap.save_npz(good)
    with np.load(good, allow_pickle=False) as z:
        data = {k: z[k] for k in z.files}
    meta = json.loads(str(data["metadata"]))
    if damage == "not json":
        data["metadata"] = np.array("{not json")
    elif damage == "missing methods":
        del meta["methods"]
        data["metadata"] = np.array(json.dumps(meta))
    else:
        del data["verdict_exact"]
    bad = tmp_path / "bad.npz"
    np.savez(bad, **data)
    with pytest.raises(StringStabError, match=r"bad\.npz: expected"):
        load_npz(bad)
