"""IDL metrics (eqs 19-35) on trajectories whose metrics are known in closed form."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from stringstab.errors import StringStabError
from stringstab.traffic.metrics import (
    collision_count,
    comfort_index,
    damping_ratio,
    efficiency_index,
    fss_ratio,
    jerk_squared,
    lss_index,
    platoon_damping_ratios,
    time_headway,
    time_integrated_ttc,
    time_to_collision,
)
from stringstab.traffic.reward import (
    comfort_reward,
    efficiency_reward,
    headway_density,
    safety_reward,
)

DT = 0.01


def test_ttc_constant_closing_speed():
    """Gap g0 − c t closing at c: TTC = g0/c − t (eq 19); ∞ when opening."""
    t = np.arange(0, 3, DT)
    g0, c = 30.0, 10.0
    ttc = time_to_collision(g0 - c * t, 20.0 + c, 20.0)
    assert_allclose(ttc, g0 / c - t, rtol=1e-12)
    assert np.isinf(time_to_collision(g0, 20.0, 20.0 + c))
    assert np.isinf(time_to_collision(g0, 20.0, 20.0))


def test_tit_linear_ttc_ramp():
    """TTC falling from TTC* = 3 s to 0 at slope −1: TIT = Σ_k (k Δt) Δt = Δt² K(K+1)/2 (eqs 31-32),
    → 4.5 s² as Δt → 0."""
    K = 300
    ttc = 3.0 - np.arange(K + 1) * DT
    tit = time_integrated_ttc(np.r_[np.inf, 10.0, ttc, np.inf], DT)
    assert_allclose(tit, DT**2 * K * (K + 1) / 2, rtol=1e-12)
    assert_allclose(tit, 4.5, rtol=2e-2)
    assert time_integrated_ttc([3.5, np.inf, -1.0], DT) == 0.0  # outside [0, TTC*]


def test_jerk_of_a_constant_jerk_ramp():
    """a = j t: c = j² at every step (eq 33), M_CI = j² (eq 34)."""
    j = 0.7
    a = j * np.arange(0, 10, DT)
    assert_allclose(jerk_squared(a, DT), j**2, rtol=1e-9)
    assert_allclose(comfort_index(np.stack([a, -a]), DT), j**2, rtol=1e-9)


def test_jerk_of_a_sinusoid():
    """a = A sin ωt over whole periods: mean squared jerk → (Aω)²/2 (finite differences at Δt)."""
    A, w = 2.0, 1.5
    t = np.arange(0, 20 * 2 * np.pi / w, DT)
    assert_allclose(comfort_index(A * np.sin(w * t), DT), (A * w) ** 2 / 2, rtol=1e-3)


def test_time_headway_constant_spacing_policy():
    """gap = l0 + T v: h = T + l0/v (eq 22); M_effi is its mean (eq 35); standstill → undefined."""
    v = np.linspace(5, 30, 11)
    h = time_headway(2.0 + 1.1 * v, v)
    assert_allclose(h, 1.1 + 2.0 / v, rtol=1e-12)
    assert_allclose(efficiency_index(h), np.mean(1.1 + 2.0 / v), rtol=1e-12)
    h0 = time_headway([2.0, 2.0], [0.0, 1e-4])
    assert np.isnan(h0).all()
    assert math.isnan(efficiency_index(h0))


def test_damping_ratio_scaled_and_phase_shifted():
    """a_i = ρ^i a_0 (any phase over whole periods): m_p = ρ for every follower, M_lss = ρ."""
    t = np.arange(0, 2 * np.pi * 10, DT)
    rho = 0.8
    acc = np.stack([rho**i * np.sin(t - 0.3 * i) for i in range(6)])
    mp = platoon_damping_ratios(acc)
    assert_allclose(mp, rho, rtol=2e-3)
    assert_allclose(lss_index(mp), rho, rtol=2e-3)
    assert_allclose(damping_ratio(1.25 * acc[0], acc[0]), 1.25, rtol=1e-12)


@given(st.floats(0.05, 5.0), st.integers(1, 6))
def test_damping_ratio_of_geometric_platoon(rho, n):
    a0 = np.sin(np.linspace(0, 7, 200)) + 0.1
    acc = np.stack([rho**i * a0 for i in range(n + 1)])
    assert_allclose(platoon_damping_ratios(acc), rho, rtol=1e-10)


def test_collision_count():
    gap = np.array([[1.0, 0.0, -1.0, 2.0, -0.5, -0.5, 3.0], [-1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]])
    assert collision_count(gap).tolist() == [2, 1]
    assert collision_count(gap.T, axis=0).tolist() == [2, 1]


def test_fss_ratio_counts_certified_moments():
    """Eq 27: 3 moments with the certified triple, 1 with the van Arem gains (|Γ(j2)| ≈ 1.14)."""
    K = np.array([[1.2, 0.5, 0.6]] * 3 + [[0.1, 0.58, 1.0]])
    assert fss_ratio(K[:, 0], K[:, 1], K[:, 2], tau=0.1, delta=0.2, headway=1.1) == 0.75  # a fraction
    with pytest.raises(StringStabError):
        fss_ratio([np.nan], [0.5], [0.6], tau=0.1, delta=0.2, headway=1.1)


def test_reward_terms():
    # eq 20
    assert_allclose(safety_reward([np.inf, 4.0, 3.0, 1.5, 0.0, -2.0]), [0, 0, 0, -0.5, -1, -1])
    assert safety_reward(np.inf, gap=-0.1) == -1.0
    # eq 21: the full swing acc_min → acc_max is −1
    assert_allclose(comfort_reward([3.0, 0.0], [-7.6, 0.0]), [-1.0, 0.0])
    # eq 23: the log-normal density peaks at e^{μ−σ²} = 1.26 s with 0.6588 (as the paper states)
    hs = np.linspace(0.2, 5, 20001)
    f = headway_density(hs)
    assert_allclose(hs[np.argmax(f)], 1.2612, atol=1e-3)
    assert_allclose(f.max(), 0.6588, atol=1e-4)
    # eq 24
    r = efficiency_reward([1.2612, 0.0, -1.0, np.nan, 4.0])
    assert_allclose(r[:4], [0.0, -1.0, -1.0, -1.0], atol=1e-6)
    assert -1.0 < r[4] < -0.9
