"""Certified multi-rate gains behind a slice of a shipped cycle, radio on (analysis/multirate_cycles.py).

Truth: the simulator (exact lag integration between samples, the radio's hold; tested against a
lifted per-step model in tests/traffic/test_traffic_radio.py), not the certificate.  A certified triple
must not amplify the command energy along the platoon (‖u_i‖₂ ≤ ‖u_{i−1}‖₂ on any horizon, the
link being causal, docs/sampled.md §9.2) up to round-off; and the same measure does exceed 1
for a triple not certified at 10 Hz, K = (0.5, 0.2, 1.0), behind a sinusoid at its peak
frequency — so the check can fail (behind the real cycles, mostly slow, even that triple does
not amplify: the cycles alone would not tell the verdicts apart).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

from stringstab.certify.api import check
from stringstab.traffic.synthetic import sinusoid

SCRIPT = Path(__file__).resolve().parents[2] / "analysis" / "multirate_cycles.py"


@pytest.fixture(scope="module")
def mc():
    spec = importlib.util.spec_from_file_location("multirate_cycles", SCRIPT)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["multirate_cycles"] = mod
    spec.loader.exec_module(mod)
    return mod


def test_certified_gains_do_not_amplify_behind_a_us06_slice(mc):
    H, N, delta = 0.05, 4, 0.15
    K = mc.gains(H, N, delta, 2, 1, np.random.default_rng(1))
    assert len(K) == 3  # two random, one at the k_a boundary
    kw = dict(tau=mc.TAU, delta=delta, headway=mc.HEADWAY, sample_time=H, message_period=N * H)
    assert (np.asarray(check(*K.T, **kw).verdict) == "certified").all()
    edge = K[2] + [0.0, 0.0, 0.01]
    assert check(*edge, **kw).verdict[0] == "not_certified"
    lead = mc.leaders(H, 20.0, ["us06"])["us06"]
    lead = type(lead)(lead.dt, lead.position[:2401], lead.speed[:2401], lead.accel[:2401],
                      name="us06 0-120 s")
    r = mc.measure(K, lead, H, N, delta)
    assert not r["limit"]
    assert r["u_link"] <= 1 + mc.TOL and r["a_u1"] <= 1 + mc.TOL, r
    assert r["u_link"] > 0.5  # the platoon was excited


def test_the_measure_fails_for_gains_not_certified_at_10_hz(mc):
    H, N, delta = 0.01, 10, 0.2
    K = np.array([[0.5, 0.2, 1.0]])  # sup σ(G) = 1.122 at ω = 2.40 rad/s
    kw = dict(tau=mc.TAU, delta=delta, headway=mc.HEADWAY, sample_time=H, message_period=N * H)
    assert check(*K.T, **kw).verdict[0] == "not_certified"
    lead = sinusoid(omega=2.4, amplitude=0.5, speed=20.0, duration=60.0, dt=H)
    r = mc.measure(K, lead, H, N, delta)
    assert not r["limit"]
    assert r["u_link"] > 1.05, r  # 1.074 when written
