"""The multi-rate loop through the one way in, the command line and the region maps (issue 26).

N = 1 (a message every step) is the sampled certificate by construction (the way in routes it
there); these tests hold that routing bit for bit, the fallback columns against the sampled
certificate at k_a = 0, the largest certified message period against a scan of every period,
and every bad input: one line, exit code 2, nothing written.
"""

from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pytest

import stringstab as ss
from stringstab.certify.api import Loop
from stringstab.certify.message_period import largest_message_period
from stringstab.certify.multirate import SCOPE, MultirateCertificateBatch
from stringstab.cli import main
from stringstab.errors import StringStabError

P = dict(tau=0.1, delta=0.2, headway=1.1)
K = np.array([[1.2, 0.5, 0.6], [0.45, 0.25, 0.9], [0.9, -0.5, 1.1], [-0.5, 1.0, 1.0]])


def _run(argv):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = main(argv)
    return code, out.getvalue()


def test_the_loop_kind_is_multirate_from_two_steps_and_sampled_at_one():
    assert Loop.of(**P, sample_time=0.01, message_period=0.1).kind == "multirate"
    assert Loop.of(**P, sample_time=0.01, message_period=0.1).message_steps == 10
    assert Loop.of(**P, sample_time=0.1, message_period=0.1).kind == "sampled"
    assert Loop.of(**P, sample_time=0.1, message_period=0.3).message_steps == 3  # 0.3/0.1 ≠ 3 in binary


def test_a_message_every_step_is_the_sampled_certificate_bit_for_bit():
    a = ss.certify_batch(*K.T, **P, sample_time=0.1)
    b = ss.certify_batch(*K.T, **P, sample_time=0.1, message_period=0.1)
    assert type(a) is type(b)
    for k, v in a.columns().items():
        if isinstance(v, dict):
            for kk, vv in v.items():
                np.testing.assert_array_equal(vv, b.columns()[k][kk])
        else:
            np.testing.assert_array_equal(v, b.columns()[k], err_msg=k)
    c1, o1 = _run(["certify", "1.2,0.5,0.6", "0.9,-0.5,1.1", "--sample-time", "0.1"])
    c2, o2 = _run(["certify", "1.2,0.5,0.6", "0.9,-0.5,1.1", "--sample-time", "0.1",
                   "--message-period", "0.1"])
    assert (c1, o1) == (c2, o2)


def test_the_batch_carries_the_schedule_the_fallback_and_the_scope():
    b = ss.certify_batch(*K.T, **P, sample_time=0.01, message_period=0.1, message_phase=3)
    assert isinstance(b, MultirateCertificateBatch)
    assert b.verdict.tolist() == ["certified", "not_certified", "not_certified", "not_certified"]
    s = b.summary()
    assert (s["message_period"], s["message_steps"], s["message_phase"]) == (0.1, 10, 3)
    assert s["not_covered"] == SCOPE and "random message loss" in SCOPE
    assert not b.schur[3] and np.isinf(b.sup_gain[3])  # k_x < 0: not internally stable
    # the fallback column is the sampled certificate of (k_x, k_v, 0)
    f = ss.certify_batch(K[:, 0], K[:, 1], 0.0, **P, sample_time=0.01)
    np.testing.assert_array_equal(b.fallback_verdict, f.verdict)
    np.testing.assert_array_equal(b.fallback_sup_gain, f.sup_gain)
    g = ss.certify_batch(*K.T, **P, sample_time=0.01, message_period=0.1,
                         fallback_gains=(1.2, 0.5))
    assert set(g.fallback_verdict.tolist()) == {"certified"}
    cols = {c.key for c in b.table_columns()} - {"t", "vehicle"}
    assert cols <= set(b.columns())
    one = ss.certify(*K[0], **P, sample_time=0.01, message_period=0.1)
    assert one.verdict == "certified" and one.message_steps == 10 and one.as_dict()["sup_gain"] == 1.0
    c = ss.check(*K.T, **P, sample_time=0.01, message_period=0.1)
    np.testing.assert_array_equal(c.verdict, b.verdict)


@pytest.mark.parametrize("kw, match", [
    ({"sample_time": 0.01, "message_period": 0.015}, r"whole multiple N >= 1 .* got 0.015 s = 1.5 steps"),
    ({"sample_time": 0.01, "message_period": 0.005}, r"whole multiple N >= 1 .* got 0.005 s = 0.5 steps"),
    ({"sample_time": 0.01, "message_period": -0.1}, r"finite number of seconds > 0; got -0.1"),
    ({"sample_time": 0.01, "message_period": float("nan")}, r"finite number of seconds > 0; got nan"),
    ({"sample_time": 0.01, "message_period": "x"}, r"number of seconds > 0; got 'x'"),
    ({"message_period": 0.1}, r"needs the control period: expected sample_time"),
    ({"sample_time": 0.01, "message_phase": 1}, r"message_phase is for the multi-rate loop"),
    ({"sample_time": 0.01, "message_period": 0.1, "message_phase": 10}, r"0\.\.9 .* got 10"),
    ({"sample_time": 0.01, "message_period": 0.1, "tau": (0.1, 0.2)}, r"parameter box"),
    ({"sample_time": 0.01, "message_period": 0.1, "tau_prev": 0.2}, r"homogeneous platoon"),
    ({"sample_time": 0.01, "message_period": 0.1, "fallback_gains": (1.0,)}, r"two numbers"),
    ({"sample_time": 0.01, "fallback_gains": (1.0, 1.0)}, r"fallback gains are for the multi-rate"),
])
def test_bad_schedules_are_refused_with_what_was_expected(kw, match):
    with pytest.raises(StringStabError, match=match):
        ss.certify_batch(*K.T, **{**P, **kw})


@pytest.mark.parametrize("flags, says", [
    (["--sample-time", "0.01", "--message-period", "0.015"], "got 0.015 s = 1.5 steps"),
    (["--sample-time", "0.01", "--message-period", "-1"], "finite number of seconds > 0; got '-1'"),
    (["--sample-time", "0.01", "--message-period", "nan"], "got 'nan'"),
    (["--message-period", "0.1"], "expected --sample-time H with it"),
    (["--sample-time", "0.01", "--message-period", "0.1", "--message-phase", "-1"], "0..9"),
    (["--sample-time", "0.01", "--message-period", "0.1", "--tau", "0.1:0.2"], "parameter box"),
    (["--sample-time", "0.01", "--fallback-gains", "1,1"], "expected --message-period"),
    (["--sample-time", "0.01", "--max-message-period", "0.001"], ">= --sample-time 0.01"),
    (["--max-message-period"], "expected --sample-time H"),
])
def test_bad_command_lines_are_one_line_exit_2_and_no_file(tmp_path, capsys, flags, says):
    out = tmp_path / "o.json"
    code = main(["certify", "1.2,0.5,0.6", *flags, "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and says in err[0], err
    assert not out.exists()


def test_the_command_line_certifies_the_multirate_loop_in_every_format(tmp_path):
    code, text = _run(["certify", "1.2,0.5,0.6", "0.45,0.25,0.9", "--sample-time", "0.01",
                       "--message-period", "0.1"])
    assert code == 1
    lines = text.splitlines()
    assert "message_period = 0.1" in lines[0] and "sup σ(G)" in lines[1]
    assert lines[2].split()[5] == "certified" and lines[3].split()[5] == "not_certified"
    assert "random message loss are not covered" in text
    out = tmp_path / "c.json"
    assert main(["certify", "1.2,0.5,0.6", "--sample-time", "0.01", "--message-period", "0.1",
                 "--out", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["params"]["message_period"] == 0.1
    row = doc["results"][0] if "results" in doc else doc["rows"][0]
    assert row["verdict"] == "certified" and row["fallback_verdict"] == "certified"


def test_the_largest_message_period_is_the_prefix_of_certified_periods():
    loop = Loop.of(**P, sample_time=0.1)
    b = largest_message_period(loop, *K[:3].T, cap=0.6)
    scan = np.stack([ss.check(*K[:3].T, **P, sample_time=0.1,
                              message_period=round(N * 0.1, 10)).verdict == "certified"
                     for N in range(1, 7)], axis=1)
    want = [int(np.argmin(r)) if not r.all() else 6 for r in scan]
    assert b.max_message_steps.tolist() == want
    np.testing.assert_allclose(b.max_message_period, np.array(want) * 0.1)
    assert b.verdict[0] != "certified" or scan[0].all()
    code, text = _run(["certify", "1.2,0.5,0.6", "--sample-time", "0.1", "--max-message-period"])
    assert code == 1 and "0.2" in text.splitlines()[2]
    with pytest.raises(StringStabError, match="sampled loop at one"):
        largest_message_period(Loop.of(**P), [1.0], [1.0], [0.5])


def test_a_region_map_over_the_message_rate(tmp_path):
    from stringstab.regions import region_map
    from stringstab.regions.result import load_npz

    g = np.linspace(0.2, 1.8, 4)
    m = region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, **P, sample_time=0.1, message_period=0.2,
                   methods="exact,continuous", workers=1)
    b = ss.check(*np.meshgrid(g, g, indexing="ij"), 0.5, **P, sample_time=0.1, message_period=0.2)
    np.testing.assert_array_equal(m.stable("exact"), (b.verdict == "certified").reshape(4, 4))
    assert m.message_period == 0.2 and "messages every 0.2 s" in m.title()
    path = tmp_path / "m.npz"
    m.save_npz(path)
    assert load_npz(path).message_period == 0.2
    with pytest.raises(StringStabError, match="expected sample_time"):
        region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, **P, message_period=0.2)
