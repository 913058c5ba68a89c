"""Gain repair for the sampled and robust loops (issue 10, phase 2).

Every output reported certified is checked independently: for the sampled loop against the
expm construction of ``_sampled_truth`` (roots inside the unit circle, |H| ≤ 1 on a sweep), for
a box against a dense grid of its members (each certified by the point certificate, whose own
tests check it against sweeps).
"""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from stringstab.certify.api import certify_batch
from stringstab.certify.frequency import margin_g
from stringstab.certify.sampled_frequency import sampled_margin
from stringstab.certify.schur import schur_margins
from stringstab.cli import main
from stringstab.errors import StringStabError
from stringstab.tuning import Projector, project, tune
from stringstab.tuning.constraints import evaluate_forms, quadratic_form
from tests._sampled_truth import THETA, pair_response, pair_roots

P = dict(tau=0.1, delta=0.2, headway=1.1)
BAD = [[0.9, -0.5, 1.1], [2.0, 1.9, -1.2], [0.1, 0.58, 1.0], [-0.5, 1.0, 1.0]]


# --------------------------------------------------------------------------- the forms
gain = st.floats(-2, 2, allow_nan=False)


@settings(max_examples=40)
@given(kx=gain, kv=gain, ka=gain, th=st.floats(0, np.pi), w=st.floats(0, 30),
       H=st.sampled_from([0.05, 0.1, 0.2]), d=st.sampled_from([0.0, 0.2, 0.25]))
def test_every_margin_is_a_quadratic_form_in_the_gains(kx, kv, ka, th, w, H, d):
    """Polarisation recovers g, g_H and the Schur conditions exactly (they are quadratics)."""
    K = np.array([kx, kv, ka])
    fs = {
        "g": lambda x, v, a: margin_g(w, x, v, a, tau=0.1, delta=d, headway=1.1),
        "gH": lambda x, v, a: sampled_margin(th, x, v, a, tau=0.1, delta=d, headway=1.1,
                                             sample_time=H),
        "schur": lambda x, v, a: schur_margins(x, v, tau=0.1, headway=1.1, sample_time=H)[4],
    }
    for name, f in fs.items():
        q = quadratic_form(f)
        want = float(f(*(np.array([k]) for k in K))[0])
        scale = 1 + float(np.abs(evaluate_forms(np.abs(q)[None, :], np.abs(K))[0]))
        assert abs(evaluate_forms(q[None, :], K)[0] - want) <= 1e-12 * scale, name


# --------------------------------------------------------------------------- sampled
@pytest.mark.parametrize("H", [0.1, 0.2])
@pytest.mark.parametrize("K0", BAD)
def test_sampled_repair_is_certified_by_the_expm_truth(H, K0):
    r = project(K0, sample_time=H, **P)
    assert r.status == "repaired" and r.certified and r.verdict == "certified"
    K = np.array(r.k)
    assert np.max(np.abs(pair_roots(K[0], K[1], 0.1, 1.1, H))) < 1
    assert np.max(np.abs(pair_response(THETA, *K, 0.1, 0.2, 1.1, H))) <= 1 + 1e-9
    # and it is a repair: no further from K0 than the certified grid's nearest point
    grid = np.array(list(itertools.product(np.linspace(-2, 2, 11), repeat=3)))
    ok = certify_batch(*grid.T, sample_time=H, **P).certified
    assert r.distance <= np.min(np.linalg.norm(grid[ok] - K0, axis=1)) + 1e-9


def test_gains_repaired_for_continuous_time_can_fail_the_sampled_loop():
    """Gains repaired for continuous time can fail the 5 Hz loop; repaired for it, they pass."""
    K0 = [2.0, 1.9, -1.2]
    cont = project(K0, **P)
    samp = project(K0, sample_time=0.2, **P)
    assert certify_batch(*np.array([cont.k]).T, sample_time=0.2, **P).verdict[0] != "certified"
    assert samp.certified and samp.distance > cont.distance


def test_certified_input_is_unchanged():
    r = project([1.3, 0.0, 0.6], sample_time=0.1, **P)
    assert r.status == "unchanged" and r.k == r.k_in and r.certified


# --------------------------------------------------------------------------- robust
def _members(box, n=4):
    return list(itertools.product(*(np.linspace(lo, hi, n) for lo, hi in box)))


@pytest.mark.parametrize("K0", BAD)
def test_robust_repair_is_certified_on_a_dense_grid_of_the_box(K0):
    box = ((0.1, 0.2), (0.15, 0.25), (1.0, 1.2))
    r = project(K0, tau=box[0], delta=box[1], headway=box[2])
    assert r.status == "repaired" and r.certified
    K = np.array([r.k])
    for t, d, h in _members(box):
        assert certify_batch(*K.T, tau=t, delta=d, headway=h).verdict[0] == "certified"


def test_robust_sampled_repair_against_the_expm_truth_at_the_corners():
    box = dict(tau=(0.1, 0.15), delta=(0.2, 0.25), headway=1.1)
    proj = Projector(sample_time=0.1, **box)
    r = proj([0.1, 0.58, 1.0])
    assert r.certified
    K = np.array(r.k)
    for t, tp, d in itertools.product((0.1, 0.125, 0.15), (0.1, 0.15), (0.2, 0.225, 0.25)):
        assert np.max(np.abs(pair_roots(K[0], K[1], t, 1.1, 0.1))) < 1
        h = np.abs(pair_response(THETA[::4], *K, t, d, 1.1, 0.1, tau_prev=tp))
        assert h.max() <= 1 + 1e-9


def test_tune_refuses_region_growing_for_other_loops():
    with pytest.raises(StringStabError, match="region growing"):
        tune([0.9, -0.5, 1.1], "region-growing", sample_time=0.1, **P)
    with pytest.raises(StringStabError, match="region growing"):
        tune([0.9, -0.5, 1.1], "region-growing", tau=(0.1, 0.2), delta=0.2, headway=1.1)
    assert tune([0.9, -0.5, 1.1], "projection", sample_time=0.1, **P).certified


def test_cli_tune_sample_time(capsys):
    code = main(["tune", "0.9,-0.5,1.1", "1.3,0,0.6", "--sample-time", "0.1", "--format", "json"])
    import json

    doc = json.loads(capsys.readouterr().out)
    assert code == 0 and doc["params"]["sample_time"] == 0.1
    rows = doc["results"]
    assert [r["status"] for r in rows] == ["repaired", "unchanged"]
    K = np.array([[r["k_x"], r["k_v"], r["k_a"]] for r in rows])
    assert np.all(certify_batch(*K.T, sample_time=0.1, **P).certified)
    assert_allclose(rows[1]["distance"], 0.0)


@pytest.mark.parametrize("args, msg", [
    (["--sample-time", "0.1", "--method", "both"], "region growing"),
    (["--tau", "0.1:0.2", "--method", "region-growing"], "region growing"),
    (["--sample-time", "0"], "--sample-time"),
    (["--delta", "0.3:0.2"], "lo <= hi"),
])
def test_cli_tune_bad_input(capsys, args, msg):
    code = main(["tune", "0.9,-0.5,1.1", *args])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and msg in err
