"""The radio study with a reaction delay θ_r (issue 25): its sampled certificate takes θ_r.

Independent truth: the simulator's platoon (two held pieces per step, integrated exactly) with a
message every step and no loss. A loop the sampled certificate with θ_r certifies cannot amplify
a signal started at rest (the finite-horizon ℓ2 gain of a causal stable LTI system is at most its
H∞ norm); one it does not certify amplifies a sinusoid at its peak frequency, by about its
sup|H| far down the string.
"""

from __future__ import annotations

import numpy as np

import stringstab as ss
from stringstab.traffic import sinusoid
from stringstab.traffic.radio_study import run_radio_study

LOOP = {"tau": 0.5, "delta": 0.0, "headway": 1.5}
H, THETA = 0.1, 0.15  # θ_r = 1.5 steps: two held pieces per step


def test_certified_with_reaction_delay_does_not_amplify():
    K = (0.2, 0.6, 0.0)
    leader = sinusoid(omega=0.5, amplitude=0.5, duration=120.0, dt=H)
    st = run_radio_study([K], leader, n_followers=6, message_period=H, losses=[0.0], bursts=[1.0],
                         seeds=2, reaction_delay=THETA, **LOOP)
    cert = st.certificates[0]
    want = ss.certify(*K, **LOOP, sample_time=H, reaction_delay=THETA)
    assert cert["sampled"]["verdict"] == want.verdict == "certified"
    assert cert["sampled"]["sup_gain"] == float(want.sup_gain)
    assert st.covered(0.0) == "sampled certificate (messages every step)"
    assert np.all(st.amplification[0, 0, 0] <= 1.0 + 1e-6), st.amplification[0, 0, 0]


def test_not_certified_with_reaction_delay_amplifies_at_the_peak():
    K = (0.6, 0.3, 0.0)
    c = ss.certify(*K, **LOOP, sample_time=H, reaction_delay=THETA)
    assert c.verdict == "not_certified" and float(c.sup_gain) > 1.1
    # the same gains without θ_r: certified for the sampled loop (θ_r is what breaks it)
    assert ss.certify(*K, **LOOP, sample_time=H).verdict == "certified"
    leader = sinusoid(omega=float(c.peak_omega), amplitude=0.5, duration=200.0, dt=H)
    st = run_radio_study([K], leader, n_followers=8, message_period=H, losses=[0.0], bursts=[1.0],
                         seeds=2, reaction_delay=THETA, **LOOP)
    assert st.certificates[0]["sampled"]["verdict"] == "not_certified"
    m_p = st.m_p[0, 0, 0, 0]
    assert m_p[-1] > 1.05 and abs(m_p[-1] - float(c.sup_gain)) < 0.05, (m_p, float(c.sup_gain))
