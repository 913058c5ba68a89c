"""The certificate with a reaction delay θ_r > 0 (issue 25): the way in, the verdicts, the outputs.

Independent truths: a dense sweep of Γ(jω) evaluated here from complex exponentials (not the
toolkit's generated code), ``numpy.roots`` of a Padé(10, 10) approximant for stability (away
from the boundary), and the closed-form witnesses (a real root for k_x < 0).
"""

from __future__ import annotations

import contextlib
import io
import json
import re

import numpy as np
import pytest

import stringstab as ss
from stringstab.certify.api import Loop
from stringstab.certify.reaction_results import ReactionCertificateBatch
from stringstab.cli import main
from stringstab.errors import StringStabError

P = dict(tau=0.1, delta=0.2, headway=1.1)


def _gamma(w, kx, kv, ka, tau, delta, headway, theta):
    s = 1j * np.asarray(w, dtype=float)
    e = np.exp(-theta * s)
    return e * (kx + kv * s + ka * s * s * np.exp(-delta * s)) / (
        tau * s**3 + s * s + e * ((kv + headway * kx) * s + kx))


def _pade_rightmost(kx, kv, tau, headway, theta, m=10):
    import math

    a = np.array([math.factorial(2 * m - k) * math.factorial(m)
                  / (math.factorial(2 * m) * math.factorial(k) * math.factorial(m - k))
                  for k in range(m + 1)])
    den = np.polynomial.Polynomial(a * theta ** np.arange(m + 1))
    num = np.polynomial.Polynomial(a * (-theta) ** np.arange(m + 1))
    c = kv + headway * kx
    p = np.polynomial.Polynomial([0, 0, 1, tau]) * den + np.polynomial.Polynomial([kx, c]) * num
    return float(np.max(p.roots().real))


# --------------------------------------------------------------------------- the parameters
@pytest.mark.parametrize("value, message", [
    (-0.1, "reaction_delay (reaction delay θ_r) must be a finite number >= 0 s; got -0.1"),
    (float("nan"), "must be a finite number >= 0 s; got nan"),
    (150.0, "= 150 s is far outside the physically meaningful range"),
    ("abc", "reaction_delay must be a number or an interval LO:HI"),
])
def test_bad_reaction_delays_are_refused_in_one_line(value, message):
    with pytest.raises(StringStabError, match=message.replace("(", r"\(").replace(")", r"\)")):
        ss.certify(1.0, 0.5, 0.2, **P, reaction_delay=value)


def test_params_and_boxes_carry_theta_when_nonzero():
    p = ss.Params(0.1, 0.2, 1.1, reaction_delay=0.25)
    assert repr(p) == "Params(tau=0.1, delta=0.2, headway=1.1, reaction_delay=0.25)"
    assert p.as_dict()["reaction_delay"] == 0.25
    box = ss.Box((0.1, 0.2), (0.2, 0.2), (1.1, 1.1), (0.1, 0.3))
    assert box.as_dict()["reaction_delay"] == [0.1, 0.3] and not box.is_point
    assert ss.Box.of(p).reaction_delay == (0.25, 0.25)
    assert box.centre().reaction_delay == pytest.approx(0.2)
    with pytest.raises(StringStabError, match="reaction_delay"):
        ss.Box((0.1, 0.2), (0.2, 0.2), (1.1, 1.1), (-0.1, 0.3))


@pytest.mark.parametrize("kw, found", [
    # points with a sample time are certified (issue 25 item 3: test_sampled_reaction.py), boxes
    # in continuous time (item 4: test_robust_reaction.py); a θ_r box with a sample time is refused
    ({"reaction_delay": "0.1:0.3", "sample_time": 0.1},
     "θ_r > 0 over a parameter box is certified in continuous time only (the sampled-data loop "
     "has no sound θ_r box certificate yet); expected point values of tau, delta, headway and "
     "reaction_delay with sample_time=0.1 (each member certified on its own), or the box "
     "without sample_time; got reaction_delay=0.1:0.3 with sample_time=0.1"),
    ({"tau": (0.1, 0.2), "sample_time": 0.1},
     "got tau=0.1:0.2, reaction_delay=0.2 with sample_time=0.1"),
])
def test_a_theta_box_with_a_sample_time_is_refused(kw, found):
    args = {**P, "reaction_delay": 0.2, **kw}
    with pytest.raises(StringStabError, match=re.escape(found)):
        ss.certify_batch([1.0], [0.5], [0.2], **args)
    with pytest.raises(StringStabError, match=re.escape(found)):
        ss.check([1.0], [0.5], [0.2], **args)


def test_the_pade_cross_check_refuses_theta():
    with pytest.raises(StringStabError, match=r"method='pade'.*reaction_delay=0\.2"):
        ss.certify(1.0, 0.5, 0.2, **P, reaction_delay=0.2, method="pade")


def test_the_loop_is_checked_once_and_stays_continuous():
    loop = Loop.of(0.1, 0.2, 1.1, reaction_delay="0.2")
    assert loop.kind == "continuous" and loop.model.reaction_delay == 0.2


# --------------------------------------------------------------------------- the verdicts
K = np.vstack([np.random.default_rng(25).uniform(-2, 2, (400, 3)),
               np.random.default_rng(26).uniform([0, 0, -1], [0.8, 1.5, 1], (200, 3))])


@pytest.mark.parametrize("theta, headway", [(0.1, 1.1), (0.3, 2.0), (0.5, 3.0)])
def test_verdicts_against_a_sweep_and_a_pade_root_count(theta, headway):
    p = dict(tau=0.2, delta=0.3, headway=headway, reaction_delay=theta)
    b = ss.certify_batch(*K.T, **p)
    assert isinstance(b, ReactionCertificateBatch)
    chk = ss.check(*K.T, **p)
    assert np.array_equal(chk.verdict, b.verdict)
    assert np.array_equal(chk.hurwitz, b.hurwitz)
    w = np.concatenate([np.logspace(-4, 0, 400), np.linspace(1, 60, 6000)])
    n_cert = 0
    for i, (kx, kv, ka) in enumerate(K):
        right = _pade_rightmost(kx, kv, 0.2, headway, theta)
        gain = np.abs(_gamma(w, kx, kv, ka, 0.2, 0.3, headway, theta))
        if b.verdict[i] == "certified":
            n_cert += 1
            assert right < 1e-7 and gain.max() <= 1 + 1e-9
            assert b.unstable_roots[i] == 0 and b.hurwitz_margin[i] > 0
        elif b.verdict[i] == "not_certified":
            if b.hurwitz[i]:  # stable: a frequency with |Γ| > 1, reported as the peak
                assert abs(_gamma(b.peak_omega[i], kx, kv, ka, 0.2, 0.3, headway, theta)) > 1
                assert right < 1e-6
            elif b.unstable_roots[i] >= 1:
                assert right > -1e-6
        # the reported rightmost-root estimate agrees in sign with the proof, and with Padé
        hm = b.hurwitz_margin[i]
        if np.isfinite(hm):
            assert (hm > 0) == bool(b.hurwitz[i])
            if abs(right) > 1e-3:
                assert -hm == pytest.approx(right, abs=1e-6)
    assert n_cert > 5  # the checks of certified rows ran


def test_a_delay_too_large_for_anything_says_why():
    b = ss.certify_batch([1.0, 0.5, -0.5], [0.5, 1.0, 0.5], [0.2, 0.0, 0.0], **P,
                         reaction_delay=20.0)
    assert b.verdict.tolist() == ["not_certified"] * 3
    assert b.reason[0].startswith("unstable: ") and "roots in Re s > 0" in b.reason[0]
    assert b.unstable_roots[0] >= 2 and not b.hurwitz.any()
    assert b.sup_gain[0] == np.inf


def test_reasons_name_the_witness():
    b = ss.certify_batch([1.0, 0.9, -1.0, 0.0], [0.5, -0.5, 0.5, 0.5], [0.2, 1.1, 0.0, 0.0], **P,
                         reaction_delay=0.2)
    assert b.verdict.tolist() == ["certified", "not_certified", "not_certified", "not_certified"]
    assert b.reason[0].startswith("stable (no root in Re s ≥ 0)")
    assert b.reason[1].startswith("|Γ(jω)| > 1 at ω = ")
    assert b.reason[2].startswith("unstable: ") and b.unstable_roots[2] % 2 == 1
    assert b.reason[3] == "unstable: a root at s = 0 (k_x = 0)"


def test_rows_and_columns_carry_theta_and_the_count():
    c = ss.certify(0.9, -0.5, 1.1, **P, reaction_delay=0.2)
    d = c.as_dict()
    assert list(d)[:8] == ["k_x", "k_v", "k_a", "reaction_delay", "hurwitz", "hurwitz_margin",
                           "unstable_roots", "verdict"]
    assert d["reaction_delay"] == 0.2 and d["reason"] == c.reason
    b = ss.certify_batch([0.9], [-0.5], [1.1], **P, reaction_delay=0.2)
    assert b.records()[0] == d


# --------------------------------------------------------------------------- the command line
def _run(*argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main(list(argv))
        except SystemExit as e:  # argparse
            rc = e.code
    return rc, out.getvalue(), err.getvalue()


def test_cli_prints_theta_in_the_header_and_the_rows():
    rc, out, _ = _run("certify", "1,0.5,0.2", "--reaction-delay", "0.2")
    assert rc == 0
    assert out.splitlines()[0] == "# tau = 0.1, delta = 0.2, headway = 1.1, reaction_delay = 0.2, method = exact"
    assert "roots Re>0" in out.splitlines()[1] and "reason" in out.splitlines()[1]
    rc, out, _ = _run("certify", "1,0.5,0.2", "--reaction-delay", "0.2", "--format", "json")
    doc = json.loads(out)
    assert doc["params"]["reaction_delay"] == 0.2 and doc["results"][0]["reaction_delay"] == 0.2


@pytest.mark.parametrize("value", ["-1", "nan", "150", "abc", "0.3:0.1"])
def test_cli_bad_reaction_delays_exit_2_in_one_line(value):
    rc, out, err = _run("certify", "1,0.5,0.2", "--reaction-delay", value)
    assert rc == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and "reaction_delay" in err


def test_cli_sampled_with_theta_certifies():
    # issue 25 item 3: the sampled certificate with θ_r (tests/certify/test_sampled_reaction.py)
    rc, out, err = _run("certify", "1,0.5,0.2", "--reaction-delay", "0.2", "--sample-time", "0.1")
    assert rc == 0 and err == "" and " certified " in out
    rc, out, err = _run("certify", "1,0.5,0.2", "--reaction-delay", "2.5", "--sample-time", "0.001")
    errors = [line for line in err.splitlines() if "error:" in line]  # (a range warning first)
    assert rc == 2 and out == "" and len(errors) == 1
    assert "at most 2000 whole samples" in errors[0] and "2500 samples" in err


def test_derive_shows_the_theta_forms():
    rc, out, _ = _run("derive", "--substitute", "tau=0.1,delta=0.2,headway=1.1,reaction_delay=0.2")
    assert rc == 0
    assert "Q(s) = k_x + s*(k_v + 11*k_x/10)" in out
    assert "Taylor route" in out and "Padé(1,1) route" in out
    rc2, out2, _ = _run("derive", "--reaction-delay", "0.2", "--substitute", "tau=0.1,delta=0.2,headway=1.1")
    assert rc2 == 0 and out2 == out
    rc, _, err = _run("derive", "--reaction-delay", "-0.2")
    assert rc == 2 and "reaction delay" in err


def test_the_tuning_keeps_theta_on_the_point_and_refuses_it_elsewhere():
    # issue 25 part 2: the point loop, continuous or sampled, is tuned with θ_r
    # (tests/tuning/test_reaction_tune.py, test_reaction_tune_sampled.py); boxes refuse it with
    # a line, never drop it
    from stringstab.tuning.constraints import LoopConstraints

    assert LoopConstraints(ss.Params(0.1, 0.2, 1.1, reaction_delay=0.2), None).reaction_delay == 0.2
    assert LoopConstraints(ss.Params(0.1, 0.2, 1.1, reaction_delay=0.2), 0.1).reaction_delay == 0.2
    with pytest.raises(StringStabError, match=r"tuning takes θ_r at a point"):
        LoopConstraints(ss.Box((0.1, 0.2), (0.2, 0.2), (1.1, 1.1), (0.2, 0.2)), None)
    assert LoopConstraints(ss.Params(0.1, 0.2, 1.1), None).box.reaction_delay == (0.0, 0.0)


def test_theta_is_checked_once_on_the_way_in():
    import sys

    from stringstab import params

    seen: list[str] = []

    def prof(frame, event, arg):
        if (event == "call" and frame.f_code.co_filename == params.points.__file__
                and frame.f_code.co_name in ("check_reaction_delay", "check_params")):
            seen.append(frame.f_code.co_name)

    ss.certify_batch([1.0], [0.5], [0.2], **P, reaction_delay=0.2)  # import everything first
    for fn in (lambda: ss.certify_batch([1.0, 0.9], [0.5, -0.5], [0.2, 1.1], **P, reaction_delay=0.2),
               lambda: ss.check([1.0, 0.9], [0.5, -0.5], [0.2, 1.1], **P, reaction_delay=0.2)):
        seen.clear()
        sys.setprofile(prof)
        try:
            fn()
        finally:
            sys.setprofile(None)
        assert sorted(seen) == ["check_params", "check_reaction_delay"]
