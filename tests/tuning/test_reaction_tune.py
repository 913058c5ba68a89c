"""The reaction delay θ_r on the gain repair (issue 25 part 2): `tune --reaction-delay`, `project`.

Independent truths: the quadratic form of g_θ(ω; K) the NLP sees against |D(jω)|² − |N(jω)|²
over ω² written here from the model of issue 25 (complex arithmetic); the tuned gains' verdict
against :func:`stringstab.certify` with ``reaction_delay``; a fine frequency sweep of |Γ(jω)|.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import stringstab as ss
from stringstab.cli import main
from stringstab.params import Params
from stringstab.tuning import Projector, project, tune
from stringstab.tuning.constraints import LoopConstraints, Member, evaluate_forms

pytest.importorskip("casadi")

P = {"tau": 0.1, "delta": 0.2, "headway": 1.1}
#: certified at θ_r = 0, not at θ_r = 0.2 (asserted below)
K0 = (1.2, 0.5, 0.6)


def margin_closed_form(omega, K, *, tau, delta, headway, theta):
    """(|D(jω)|² − |N(jω)|²)/ω² of Γ = e^{−θs}N/D, D = τs³ + s² + e^{−θs}((k_xT* + k_v)s + k_x)."""
    kx, kv, ka = K
    s = 1j * omega
    n = kx + kv * s + ka * s**2 * np.exp(-delta * s)
    d = tau * s**3 + s**2 + np.exp(-theta * s) * ((kx * headway + kv) * s + kx)
    return (abs(d) ** 2 - abs(n) ** 2) / omega**2


def test_the_form_of_g_theta_is_the_closed_form_margin():
    loop = LoopConstraints(Params(**P, reaction_delay=0.25), None)
    m = Member(P["tau"], P["tau"], P["delta"], P["headway"])
    rng = np.random.default_rng(7)
    for omega in (0.3, 1.7, 4.2):
        form = loop.margin_slot(m, omega).form
        for K in rng.uniform(-2, 2, (5, 3)):
            got = float(evaluate_forms(form[None, :], K)[0])
            want = margin_closed_form(omega, K, **P, theta=0.25)
            np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9)


def test_projection_certifies_with_the_reaction_delay():
    assert ss.certify(*K0, **P).verdict == "certified"
    assert ss.certify(*K0, **P, reaction_delay=0.2).verdict != "certified"
    r = project(K0, **P, reaction_delay=0.2)
    assert r.status == "repaired" and r.certified, r.message
    c = ss.certify(*r.k, **P, reaction_delay=0.2)
    assert (c.verdict == "certified") == r.certified
    # independent: |Γ(jω)| ≤ 1 on a fine sweep, with the reaction delay
    w = np.linspace(1e-4, 30.0, 60_001)
    assert np.all(margin_closed_form(w, r.k, **P, theta=0.2) >= -1e-9)
    # the NLP on the g_θ forms found it (not the certified-map fallback), and it is near K0
    assert not r.details["fallback"] and 0 < r.distance < 0.2
    # θ_r = 0 is the tuning of today (same call, same output)
    assert project(K0, **P, reaction_delay=0.0).status == "unchanged"
    assert tune(K0, "projection", **P, reaction_delay=0.2).certified


def test_the_refusals_pass_through():
    with pytest.raises(ss.StringStabError, match="at most 2000 whole samples"):
        Projector(**P, sample_time=0.001, reaction_delay=3.0)  # the certificate's own refusal
    with pytest.raises(ss.StringStabError, match="tuning takes θ_r at a point"):
        project(K0, tau=(0.1, 0.2), delta=0.2, headway=1.1, reaction_delay=0.2)
    with pytest.raises(ss.StringStabError, match="region growing"):
        tune(K0, "region-growing", **P, reaction_delay=0.2)


def _json(capsys):
    return json.loads(capsys.readouterr().out)


def test_cli_tune_with_reaction_delay(capsys):
    assert main(["tune", ",".join(map(str, K0)), "--reaction-delay", "0.2", "--format", "json"]) == 0
    doc = _json(capsys)
    assert doc["params"]["reaction_delay"] == 0.2 and "sample_time" not in doc["params"]
    row = doc["results"][0] if "results" in doc else doc["rows"][0]
    K = [row["k_x"], row["k_v"], row["k_a"]]
    assert row["certified"] is True
    assert ss.certify(*K, **P, reaction_delay=0.2).verdict == "certified"


def test_cli_tune_reaction_delay_zero_is_unchanged(capsys):
    assert main(["tune", "0.9,-0.5,1.1", "--format", "json"]) == 0
    a = _json(capsys)
    assert main(["tune", "0.9,-0.5,1.1", "--format", "json", "--reaction-delay", "0"]) == 0
    b = _json(capsys)
    assert a["params"] == b["params"] and "reaction_delay" not in a["params"]

    def strip(doc):  # the wall-clock time of each row differs run to run
        return json.dumps(doc, sort_keys=True, default=str).replace(" ", "")

    for doc in (a, b):
        for rows in (v for v in doc.values() if isinstance(v, list)):
            for r in rows:
                if isinstance(r, dict):
                    r.pop("time_ms", None)
    assert strip(a) == strip(b)


@pytest.mark.parametrize(
    "args,match",
    [
        (["--reaction-delay", "-0.1"], "reaction delay θ_r"),
        (["--reaction-delay", "nan"], "reaction delay θ_r"),
        (["--reaction-delay", "101"], "reaction"),
        (["--reaction-delay", "0.2", "--tau", "0.1:0.2"], "tuning takes θ_r at a point"),
        (["--reaction-delay", "0.2", "--tau", "0.1:0.2", "--sample-time", "0.1"],
         "over a parameter box"),  # the certificate's own refusal
        (["--reaction-delay", "0.2", "--sample-time", "0.1", "--method", "region-growing"],
         "region growing"),
        (["--reaction-delay", "0.2", "--method", "both"], "region growing"),
    ],
)
def test_cli_tune_bad_reaction_delay_exit_2(capsys, args, match):
    assert main(["tune", "1.2,0.5,0.6", *args]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.startswith("stringstab tune: error:") and match in captured.err, captured.err
    assert captured.err.count("\n") == 1


def test_cli_tune_sampled_reaction_delay_beyond_the_certificate_exit_2(capsys):
    """q = θ_r/H > 2000: the sampled certificate's refusal (after the sensible-range warning)."""
    assert main(["tune", "1.2,0.5,0.6", "--reaction-delay", "1.5", "--sample-time", "0.0005"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    last = captured.err.splitlines()[-1]
    assert last.startswith("stringstab tune: error:") and "at most 2000 whole samples" in last
