"""The sampled head-to-tail certificate with a reaction delay θ_r > 0 (docs/sampled.md §10.6).

Independent truth: each vehicle's link u_{i−1} → u_i by an event-driven simulation written
here (scipy's expm of the continuous two-vehicle model between events: samples at kH, the
predecessor's acceleration at kH − δ_i, commands switched at kH + θ_r; the predecessor's lag
its own), its impulse response summed to H_i(e^{jθ}), and the product ∏|H_i| on a fine grid.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import expm

from stringstab.certify.api import certify_string
from stringstab.certify.head_to_tail_reaction import cascade, string_links
from stringstab.certify.lifting import lifted_response
from stringstab.certify.string_certificate import check_vehicles
from stringstab.errors import StringStabError


def _impulse(v, tau_p, theta_r, H, steps):
    """The impulse response h_k of u_{i−1} → u_i (a_{i−1}(kH − δ) every step)."""
    kx, kv, ka, tau, delta, T = (v[k] for k in ("k_x", "k_v", "k_a", "tau", "delta", "headway"))
    A = np.zeros((4, 4))
    A[0, 1], A[0, 2] = 1.0, -T
    A[1, 2], A[1, 3] = -1.0, 1.0
    A[2, 2], A[3, 3] = -1.0 / tau, -1.0 / tau_p
    M = np.zeros((6, 6))
    M[:4, :4] = A
    M[2, 4], M[3, 5] = 1.0 / tau, 1.0 / tau_p
    cache: dict[float, np.ndarray] = {}

    def flow(x, w, dt):
        if dt <= 0.0:
            return x
        key = round(dt, 13)
        if key not in cache:
            cache[key] = expm(M * dt)
        E = cache[key]
        return E[:4, :4] @ x + E[:4, 4:] @ w

    ev = sorted([(k * H - delta, 0, "a", k) for k in range(steps)]
                + [(k * H, 1, "u", k) for k in range(steps)]
                + [(k * H + theta_r, 2, "w", k) for k in range(steps)])
    up = np.zeros(steps)
    up[0] = 1.0
    ui = np.zeros(steps)
    x, w, t, msg = np.zeros(4), np.zeros(2), ev[0][0], {}
    for time, _, kind, j in ev:
        x, t = flow(x, w, time - t), time
        if kind == "a":
            msg[j] = x[3] if time >= 0.0 else 0.0
        elif kind == "u":
            ui[j] = kx * x[0] + kv * x[1] + ka * msg[j]
        else:
            w = np.array([ui[j], up[j]])
    return ui


def _truth_product(vs, leader_tau, H, steps=1500, n_theta=4001):
    th = np.linspace(0.0, np.pi, n_theta)
    prod = np.ones(n_theta, dtype=complex)
    z = np.exp(-1j * np.outer(th, np.arange(steps)))
    for i, v in enumerate(vs):
        h = _impulse(v, leader_tau if i == 0 else vs[i - 1]["tau"], v["reaction_delay"], H, steps)
        assert np.abs(h[-20:]).max() < 1e-10  # converged
        prod *= z @ h
    return th, prod


ACC = dict(k_x=0.2, k_v=0.6, k_a=0.0, tau=0.5, delta=0.1, headway=1.5)
CAV = dict(k_x=0.3, k_v=0.9, k_a=0.25, tau=0.3, delta=0.25, headway=1.2)
HOT = dict(k_x=0.5, k_v=0.8, k_a=0.3, tau=0.5, delta=0.1, headway=1.5)
STRINGS = [  # (vehicles, θ_r, leader τ): f > 0 with q ≥ 1, f = 0, q = 0
    ([ACC, CAV, ACC], 0.15, 0.5),
    ([CAV, CAV], 0.2, 0.3),
    ([ACC, HOT], 0.15, 0.5),
    ([CAV, ACC, CAV, ACC], 0.04, 0.4),
]


@pytest.mark.parametrize("vs, theta_r, lt", STRINGS)
def test_the_string_verdict_matches_the_simulated_product(vs, theta_r, lt):
    vs = [dict(v, reaction_delay=theta_r) for v in vs]
    c = certify_string(vs, sample_time=0.1, leader_tau=lt, substrings=False)
    th, prod = _truth_product(vs, lt, 0.1)
    sup = np.abs(prod).max()
    if c.verdict == "certified":
        assert sup <= 1.0 + 1e-7, sup
    else:
        assert c.verdict == "not_certified"
        assert sup > 1.0 + 1e-4
        assert c.sup_gain == pytest.approx(sup, rel=2e-3)
        # the witness is where the simulated product exceeds 1
        k = int(np.argmin(np.abs(th - c.witness_omega * 0.1)))
        assert np.abs(prod[max(k - 2, 0):k + 3]).max() > 1.0
    # the cascade's response is the simulated product at a few θ
    out, _, _ = check_vehicles(vs, sample_time=0.1)
    link = cascade(string_links(out, 0.1, lt))
    pick = [0, 500, 1700, 4000]
    G = lifted_response(link, th[pick][None, :])[0, :, 0, 0]
    np.testing.assert_allclose(G, prod[pick], atol=1e-9)


def test_the_verdicts_are_mixed_and_the_product_is_not_each_vehicle():
    v = [certify_string([dict(x, reaction_delay=t) for x in vs], sample_time=0.1, leader_tau=lt,
                        substrings=False).verdict for vs, t, lt in STRINGS]
    assert "certified" in v and "not_certified" in v
    # the first string is certified head to tail though its last vehicle alone is not
    c = certify_string([dict(x, reaction_delay=0.15) for x in STRINGS[0][0]], sample_time=0.1,
                       leader_tau=0.5)
    assert c.verdict == "certified" and c.certificates[2].verdict == "not_certified"
    assert c.worst_substring is not None and c.worst_substring.first == 3


def test_an_unstable_vehicle_makes_the_string_not_certified():
    bad = dict(k_x=3.0, k_v=0.1, k_a=0.0, tau=0.5, delta=0.1, headway=0.5, reaction_delay=0.3)
    c = certify_string([dict(ACC, reaction_delay=0.3), bad], sample_time=0.1, leader_tau=0.5,
                       substrings=False)
    assert c.verdict == "not_certified" and "not internally stable" in c.reason
    assert not c.certificates[1].schur


def test_different_reaction_delays_with_a_sample_time_are_one_line():
    with pytest.raises(StringStabError, match=r"same reaction delay .* got 0, 0.1 s") as e:
        certify_string([ACC, dict(CAV, reaction_delay=0.1)], sample_time=0.1)
    assert "\n" not in str(e.value)
