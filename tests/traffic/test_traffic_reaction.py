"""The reaction delay θ_r in the simulator (issue 25 item 5) against independent truth.

τ ȧ_i = u_i(t − θ_r) − a_i with the command computed every Δt and held: the simulator integrates
the lag exactly over the two constant pieces of every step.  Checked here against

* a fine-step Runge-Kutta integration of the delay differential equation, written from the
  model alone (the held command looked up at t − θ_r at every stage), which converges to the
  simulator's trajectories as its step shrinks, and agrees to 10⁻⁸ when its grid contains the
  command's switching instants;
* the simulator itself without θ_r, fed commands delayed by whole steps (θ_r = qΔt);
* |Γ(jω)| of the θ_r certificate's transfer (``stringstab.certify.reaction.gain_squared``) and
  of the sampled loop written independently (hold, then e^{−θ_r s}): the steady-state
  amplitude ratio along the platoon under a sinusoidal leader;
* the certificate's verdicts: a triple certified with θ_r does not amplify behind every shipped
  driving cycle; one not certified does at its peak frequency.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import stringstab as ss
from stringstab.certify.reaction import gain_squared
from stringstab.errors import StringStabError
from stringstab.traffic import (
    Controller,
    LinearController,
    Platoon,
    cycle,
    paper_mix,
    simulate,
    sinusoid,
)

TAU, DELTA, HEADWAY, L0, LENGTH = 0.1, 0.2, 1.1, 2.0, 5.0
K = (1.2, 0.5, 0.6)


def dde_reference(leader, gains, n, *, tau, theta, sub, delta=DELTA):
    """RK4 at step Δt/sub of x' = v, v' = a, τa' = u(t − θ_r) − a, u computed every Δt and held.

    Independent of the simulator: the controller (IDL eq 4 with eq 3) and the delayed link
    (the predecessor's acceleration at t − δ read off this integration's own fine grid, which
    must contain t − δ; the leader's interpolated between its samples) are written out here, and the applied command at any time t is the
    command of step ⌊(t − θ_r)/Δt⌋ (0 before t = 0, the equilibrium command), taken constant
    over each Runge-Kutta step at its value in the step's middle.
    """
    dt, T = leader.dt, leader.n_steps
    tau = np.broadcast_to(np.asarray(tau, float), (n,))
    theta = np.broadcast_to(np.asarray(theta, float), (n,))
    kx, kv, ka = gains
    nd = round(delta / (dt / sub))  # δ in fine steps
    assert abs(nd * dt / sub - delta) < 1e-12
    v0 = leader.speed[0]
    x = leader.position[0] - np.cumsum(np.full(n, L0 + HEADWAY * v0 + LENGTH))
    v, a = np.full(n, v0), np.zeros(n)
    X, V, A, U = (np.zeros((T, n)) for _ in range(4))
    fine_a = np.zeros((T * sub + 1, n))  # a on the fine grid, 0 before t = 0
    h = dt / sub
    cols = np.arange(n)

    def applied(t):  # the held command at t − θ_r (0 before t = 0)
        j = np.floor((t - theta) / dt).astype(int)
        return np.where(j >= 0, U[np.maximum(j, 0), cols], 0.0)

    def rhs(u, y):
        return np.array([y[1], y[2], (u - y[2]) / tau])

    for k in range(T):
        X[k], V[k], A[k] = x, v, a
        xp = np.concatenate([[leader.position[k]], x[:-1]])
        vp = np.concatenate([[leader.speed[k]], v[:-1]])
        m0 = k * sub - nd  # t_k − δ on the fine grid
        ad = np.zeros(n)
        if m0 >= 0:
            ad[1:] = fine_a[m0, :-1]
            ad[0] = np.interp(m0 * h, leader.t, leader.accel)
        U[k] = np.clip(kx * (xp - x - LENGTH - HEADWAY * v - L0) + kv * (vp - v) + ka * ad, -7.6, 3.0)
        y = np.array([x, v, a])
        for m in range(sub):
            u = applied(k * dt + (m + 0.5) * h)  # the input over this substep (its middle)
            k1 = rhs(u, y)
            k2 = rhs(u, y + h / 2 * k1)
            k3 = rhs(u, y + h / 2 * k2)
            k4 = rhs(u, y + h * k3)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            fine_a[k * sub + m + 1] = y[2]
        x, v, a = y
    return X.T, V.T, A.T


def _errors(res, ref):
    return max(float(np.abs(res.position[1:] - ref[0]).max()),
               float(np.abs(res.speed[1:] - ref[1]).max()),
               float(np.abs(res.accel[1:] - ref[2]).max()))


TAUS = [0.1, 0.3, 0.5]


@pytest.mark.parametrize("theta", [0.2375, [0.05, 0.2375, 0.3125]], ids=["uniform", "per-vehicle"])
@pytest.mark.parametrize("delta", [0.2, 0.25], ids=["delta=2dt", "delta=2.5dt-exact"])
def test_dde_reference_on_a_grid_through_the_switches_agrees(theta, delta):
    # Δt/40 = 2.5 ms: every switching instant kΔt + θ_r and every t_k − δ lies on the
    # reference's grid, so RK4 integrates smooth pieces and agrees to its own O(h⁴) error
    lead = sinusoid(omega=2.0, amplitude=0.5, speed=20.0, duration=6.0, dt=0.1)
    res = simulate(lead, LinearController(*K), 3, tau=TAUS, delta=delta, reaction_delay=theta,
                   fractional_delay="exact")
    if delta == 0.25:  # the received value inside the step, not the interpolation: check it
        lin = simulate(lead, LinearController(*K), 3, tau=TAUS, delta=delta, reaction_delay=theta)
        assert np.abs(lin.accel - res.accel).max() > 1e-4
    ref = dde_reference(lead, K, 3, tau=TAUS, theta=theta, sub=40, delta=delta)
    assert _errors(res, ref) < 1e-8


def test_dde_reference_converges_to_the_exact_update():
    # θ_r = 0.2373 s: the command switches inside the reference's steps (first order there)
    lead = sinusoid(omega=2.0, amplitude=0.5, speed=20.0, duration=5.0, dt=0.1)
    theta = [0.0373, 0.2373, 0.4373]
    res = simulate(lead, LinearController(*K), 3, tau=TAUS, delta=DELTA, reaction_delay=theta)
    e = [_errors(res, dde_reference(lead, K, 3, tau=TAUS, theta=theta, sub=s)) for s in (12, 48)]
    assert e[1] < e[0] / 3  # the reference's step /4: its error at least /3
    assert e[1] < 2e-3
    # and it is θ_r the simulator applies: without it the trajectories are far off
    res0 = simulate(lead, LinearController(*K), 3, tau=TAUS, delta=DELTA)
    assert _errors(res0, dde_reference(lead, K, 3, tau=TAUS, theta=theta, sub=48)) > 20 * e[1]


class _Shifted(Controller):
    """The eq-4 law whose commands reach the simulator q steps late (0 before t = 0)."""

    def __init__(self, inner, q):
        self.inner, self.q, self.past = inner, q, []

    def command(self, obs):
        self.past.append(np.array(self.inner.command(obs)))
        return self.past[-1 - self.q] if len(self.past) > self.q else np.zeros_like(obs.gap)

    def equilibrium_gap(self, speed):
        return self.inner.equilibrium_gap(speed)

    def gains(self, obs):
        return self.inner.gains(obs)


@pytest.mark.parametrize("model", ["lag", "kinematic"])
@pytest.mark.parametrize("q", [1, 3])
def test_whole_steps_shift_the_held_command(model, q):
    lead = sinusoid(omega=1.5, amplitude=1.0, speed=20.0, duration=20.0, dt=0.1)
    ctrl = LinearController(*K)
    late = simulate(lead, ctrl, 3, delta=DELTA, model=model, reaction_delay=q * 0.1)
    shifted = simulate(lead, _Shifted(ctrl, q), 3, delta=DELTA, model=model)
    for name in ("position", "speed", "accel"):
        np.testing.assert_array_equal(getattr(late, name), getattr(shifted, name))
    assert late.params["reaction_delay"] == pytest.approx(q * 0.1, abs=0)


def test_kinematic_model_integrates_both_pieces():
    # a = the applied command; v and x are the exact integrals of a piecewise-constant a
    lead = sinusoid(omega=1.0, amplitude=1.0, speed=20.0, duration=4.0, dt=0.1)
    theta = 0.13
    res = simulate(lead, LinearController(*K), 2, delta=DELTA, model="kinematic", reaction_delay=theta)
    u, dt = res.command, 0.1
    t_fine = np.arange(0, 40 * 1000) * 1e-4  # 0.1 ms, on the switching instants (k Δt + 0.13)
    j = np.floor((t_fine - theta) / dt + 1e-9).astype(int)
    a_app = np.where(j >= 0, u[:, np.maximum(j, 0)], 0.0)  # (N, fine)
    v = res.speed[1:, :1] + np.concatenate([np.zeros((2, 1)), np.cumsum(a_app, axis=1) * 1e-4], axis=1)
    assert_allclose(res.speed[1:, 1:], v[:, 1000:40001:1000], rtol=0, atol=1e-9)
    assert_allclose(res.accel[1:, 1:], a_app[:, 999:40000:1000], rtol=0, atol=0)
    # v is piecewise linear on this grid, so the trapezoid rule integrates it exactly
    x = res.position[1:, :1] + np.concatenate(
        [np.zeros((2, 1)), np.cumsum((v[:, 1:] + v[:, :-1]) * 0.5e-4, axis=1)], axis=1)
    assert_allclose(res.position[1:, 1:], x[:, 1000:40001:1000], rtol=0, atol=1e-8)


def _amplitude(t, a, omega):
    M = np.column_stack([np.sin(omega * t), np.cos(omega * t), np.ones_like(t)])
    c = np.linalg.lstsq(M, a, rcond=None)[0]
    return math.hypot(c[0], c[1])


def _sampled_gain(omega, k, dt, theta):
    """The sampled loop written out: the command held (Z) and applied θ_r late."""
    s = 1j * omega
    z = (1 - np.exp(-s * dt)) / (s * dt) * np.exp(-theta * s)
    kx, kv, ka = k
    return abs((kx + kv * s + ka * s * s * np.exp(-DELTA * s)) * z
               / (TAU * s**3 + s * s + (kx + (kv + HEADWAY * kx) * s) * z))


#: (θ_r, ω): K = (1.2, 0.5, 0.6) is certified at θ_r = 0.1 s; not at 0.2 s, where its peak
#: |Γ(jω)| = 1.108 is at ω ≈ 3.07 rad/s (sup over a fine grid, checked below).
SINE_CASES = [(0.1, 0.5), (0.1, 1.0), (0.1, 2.0), (0.2, 3.07), (0.2, 1.0)]


def test_steady_state_gain_is_the_reaction_certificates_transfer():
    dt, duration, settle = 0.01, 100.0, 50.0
    assert ss.certify(*K, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=0.1).verdict == "certified"
    assert ss.certify(*K, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=0.2).verdict == "not_certified"
    leaders = [sinusoid(omega=w, amplitude=0.3, speed=20.0, duration=duration, dt=dt) for _, w in SINE_CASES]
    theta = np.array([[th, th, th] for th, _ in SINE_CASES])
    res = simulate(leaders, LinearController(*K), 3, tau=TAU, delta=DELTA, reaction_delay=theta)
    assert not res.collided.any() and np.abs(res.command).max() < 3.0
    m = res.t >= settle
    for p, (th, w) in enumerate(SINE_CASES):
        amps = [_amplitude(res.t[m], res.accel[p, i, m], w) for i in range(4)]
        chain = np.array([amps[2] / amps[1], amps[3] / amps[2]])  # lag vehicle over lag vehicle
        gamma = math.sqrt(float(gain_squared(w, *K, tau=TAU, delta=DELTA, headway=HEADWAY,
                                             reaction_delay=th)))
        assert_allclose(chain, _sampled_gain(w, K, dt, th), rtol=1e-3)
        assert_allclose(chain, gamma, rtol=2e-2)  # the hold: ≈ Δt/2 more delay
        if th == 0.1:
            assert chain.max() < 1.0
        elif w > 3:
            assert chain.min() > 1.08  # not certified: it amplifies at its peak, car after car


def test_certified_with_reaction_delay_never_amplifies_behind_the_cycles():
    # (0.9, 0.7, 0.2) is certified at θ_r = 0.3 s; (1.2, 0.5, 0.6), certified at θ_r = 0, is
    # not at θ_r = 0.2 s (peak |Γ| = 1.108).  10 followers behind every shipped cycle and the
    # §5.1 mix at Δt = 0.1 s, held to one length (+60 s), both triples in one batch
    cases = [((0.9, 0.7, 0.2), 0.3, "certified"), ((1.2, 0.5, 0.6), 0.2, "not_certified")]
    for k, theta, verdict in cases:
        assert ss.certify(*k, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=theta).verdict == verdict
    dt = 0.1
    leaders = [cycle(c, dt=dt) for c in ("udds", "hwfet", "us06", "wltc_3b")] + [paper_mix(dt=dt)]
    n = max(tr.n_steps for tr in leaders)
    leaders = [tr.hold((n - tr.n_steps) * dt + 60.0) for tr in leaders]
    G = np.repeat(np.array([k for k, _, _ in cases]), len(leaders), axis=0)[:, None, :]  # (10, 1, 3)
    theta = np.repeat([th for _, th, _ in cases], len(leaders))[:, None]
    res = simulate(leaders * 2, LinearController(G[..., 0], G[..., 1], G[..., 2]), 10, tau=TAU,
                   delta=DELTA, reaction_delay=theta, record=False)
    assert not res.collided.any()
    worst = res.damping_ratios.max(axis=1)  # max m_p over the platoon, per leader
    assert worst[:5].max() <= 1.0 + 1e-3, worst.round(4)  # measured 0.965-0.990
    assert worst[5:].min() > 1.05, worst.round(4)  # measured 1.057-1.125


@pytest.mark.parametrize("value, match", [
    (-0.1, "reaction_delay .* must be a finite number >= 0 s; got -0.1"),
    (float("nan"), "reaction_delay .* must be a finite number >= 0 s; got nan"),
    (150.0, "reaction_delay"),
    ("x", "reaction_delay"),
    ([0.1, 0.2], "reaction_delay must broadcast"),
])
def test_bad_reaction_delay(value, match):
    with pytest.raises(StringStabError, match=match):
        Platoon(1, 3, dt=0.1, reaction_delay=value)


def test_state_round_trip_with_reaction_delay_continues_bit_for_bit():
    lead = sinusoid(omega=1.0, amplitude=1.0, speed=20.0, duration=6.0, dt=0.1)
    ctrl = LinearController(*K)

    def make():
        p = Platoon(1, 3, dt=0.1, delta=0.25, fractional_delay="exact", reaction_delay=[0.05, 0.17, 0.3])
        p.reset(lead.position[:1], lead.speed[:1], lead.accel[:1], gap=ctrl.equilibrium_gap(20.0), speed=20.0)
        return p

    def steps(p, ks):
        for k in ks:
            p.advance(ctrl.command(p.observe(lead.position[k:k + 1], lead.speed[k:k + 1], lead.accel[k:k + 1])))

    a, b = make(), make()
    steps(a, range(60))
    steps(b, range(25))
    meta, arrays = b.state()
    assert {"_cbuf", "_mbuf"} <= set(arrays)
    c = make()
    c.load_state(meta, arrays)
    steps(c, range(25, 60))
    np.testing.assert_array_equal(a.position, c.position)
    np.testing.assert_array_equal(a.accel, c.accel)


def test_kinematic_exact_fractional_delay_receives_the_applied_command():
    # with model="kinematic" the acceleration is the applied command itself, so the exact
    # received value a_{i−1}(t_k − δ) is the command of step ⌊(t_k − δ − θ_r)/Δt⌋ of the predecessor
    lead = sinusoid(omega=1.0, amplitude=1.0, speed=20.0, duration=6.0, dt=0.1)
    seen = []
    inner = LinearController(*K)

    class Rec(Controller):
        def command(self, obs):
            seen.append(np.array(obs.pred_accel_delayed[0], copy=True))
            return inner.command(obs)

        def equilibrium_gap(self, speed):
            return inner.equilibrium_gap(speed)

    theta, delta = [0.13, 0.07, 0.31], 0.25
    res = simulate(lead, Rec(), 3, model="kinematic", delta=delta, fractional_delay="exact",
                   reaction_delay=theta)
    seen = np.array(seen)
    for k in range(res.t.size):
        for i in (1, 2):  # followers 2 and 3, whose predecessors are followers
            j = math.floor((k * 0.1 - delta - theta[i - 1]) / 0.1 + 1e-9)
            want = res.command[i - 1, j] if j >= 0 else 0.0
            assert seen[k, i] == pytest.approx(want, abs=1e-12)
