"""The platoon simulator against independent truth.

The decisive test: a platoon driven by a sinusoidal leader at ω reaches a steady state in which
the ratio of follower to predecessor acceleration amplitudes is |Γ(jω)| — the frequency
response computed by :mod:`stringstab.certify.frequency` — for certified and uncertified gains.
"""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from stringstab.certify.frequency import gain
from stringstab.errors import StringStabError
from stringstab.traffic import (
    CACCController,
    FunctionController,
    IDMController,
    Limits,
    LinearController,
    MixedController,
    TimeVaryingLinearController,
    from_accel_segments,
    hard_braking,
    simulate,
    sinusoid,
)

TAU, DELTA, HEADWAY = 0.1, 0.2, 1.1
CERTIFIED = (1.2, 0.5, 0.6)  # certificate: certified (sup |Γ| = 1 at ω = 0)
UNCERTIFIED = (0.1, 0.58, 1.0)  # van Arem CACC gains: internally stable, |Γ(j2)| ≈ 1.14


def _amplitude(t, a, omega):
    """Least-squares amplitude of the ω component of a (with an offset)."""
    M = np.column_stack([np.sin(omega * t), np.cos(omega * t), np.ones_like(t)])
    c = np.linalg.lstsq(M, a, rcond=None)[0]
    return math.hypot(c[0], c[1])


def _zoh_gain(omega, k_x, k_v, k_a, dt, delta=DELTA):
    """|Γ| of the sampled loop: the control is held over each step, a factor (1 − e^{−sΔt})/(sΔt)
    on the controller (an independent model of the discretisation, not the simulator's code)."""
    s = 1j * omega
    z = (1 - np.exp(-s * dt)) / (s * dt)
    num = (k_x + k_v * s + k_a * s * s * np.exp(-delta * s)) * z
    den = TAU * s**3 + s * s + (k_x + (k_v + HEADWAY * k_x) * s) * z
    return abs(num / den)


CASES = [(CERTIFIED, 0.5), (CERTIFIED, 1.0), (CERTIFIED, 2.0), (UNCERTIFIED, 1.0), (UNCERTIFIED, 2.0)]


@pytest.mark.parametrize("delta", [0.2, 0.205])
def test_sinusoid_amplitude_ratio_matches_frequency_response(delta):
    dt, duration, settle = 0.01, 150.0, 75.0
    leaders = [sinusoid(omega=w, amplitude=0.5, speed=20.0, duration=duration, dt=dt) for _, w in CASES]
    K = np.array([k for k, _ in CASES])[:, None, :]  # (platoon, 1, 3)
    ctrl = LinearController(K[..., 0], K[..., 1], K[..., 2], headway=HEADWAY)
    res = simulate(leaders, ctrl, 2, tau=TAU, delta=delta)
    assert not res.collided.any()
    # limits never bind: |u| well inside [-7.6, 3], speeds well inside (0, 33.3)
    assert np.abs(res.command).max() < 2.0 and 15.0 < res.speed.min() and res.speed.max() < 25.0
    m = res.t >= settle
    for p, (k, w) in enumerate(CASES):
        amps = [_amplitude(res.t[m], res.accel[p, i, m], w) for i in range(3)]
        ratios = np.array([amps[1] / amps[0], amps[2] / amps[1]])
        predicted = float(gain(w, *k, tau=TAU, delta=delta, headway=HEADWAY))
        # continuous-time |Γ(jω)|: the hold adds ≈ Δt/2 of delay, < 1 % here
        assert_allclose(ratios, predicted, rtol=1.5e-2)
        # the sampled-data prediction; the fractional delay is interpolated (looser)
        assert_allclose(ratios, _zoh_gain(w, *k, dt, delta), rtol=1e-3 if delta == 0.2 else 3e-3)
        if k == UNCERTIFIED and w >= 1.0:
            assert ratios.min() > 1.05  # the disturbance grows car after car
        if k == CERTIFIED:
            assert ratios.max() < 1.0


def test_lag_step_is_exact_zoh():
    """Constant command from rest: a(t) = u(1 − e^{−t/τ}), v and x in closed form."""
    dt, u = 0.1, 1.5
    lead = from_accel_segments([(0.0, 3.0)], speed0=10.0, dt=dt)
    res = simulate(lead, FunctionController(lambda o: np.full(o.gap.shape, u)), 1, tau=0.3, delta=0.0,
                   initial_gap=50.0)
    t = res.t
    e = np.exp(-t / 0.3)
    assert_allclose(res.accel[1], u * (1 - e), rtol=0, atol=1e-12)
    assert_allclose(res.speed[1], 10.0 + u * (t - 0.3 * (1 - e)), rtol=0, atol=1e-12)
    x0 = res.position[1, 0]
    x_exact = x0 + 10.0 * t + u * (t**2 / 2 - 0.3 * t + 0.09 * (1 - e))
    assert_allclose(res.position[1], x_exact, rtol=0, atol=1e-10)


def test_kinematic_model_is_eqs_1_2():
    dt = 0.1
    lead = from_accel_segments([(0.0, 2.0)], speed0=10.0, dt=dt)
    res = simulate(lead, FunctionController(lambda o: np.full(o.gap.shape, -1.0)), 1,
                   model="kinematic", delta=0.0, initial_gap=100.0)
    v, x, gap = res.speed[1], res.position[1], res.gap[0]
    assert_allclose(np.diff(v), -1.0 * dt, atol=1e-12)  # eq 1
    lv = res.speed[0]
    # eq 2: Δx_t = Δx_{t−Δt} + (v^{i−1}_t − v^i_t + v^{i−1}_{t−Δt} − v^i_{t−Δt}) Δt / 2
    assert_allclose(np.diff(gap), (lv[1:] - v[1:] + lv[:-1] - v[:-1]) * dt / 2, atol=1e-12)
    assert x[0] < x[-1]


def test_equilibrium_is_kept():
    lead = from_accel_segments([(0.0, 30.0)], speed0=20.0)
    for ctrl in (LinearController(*CERTIFIED), CACCController(), IDMController()):
        res = simulate(lead, ctrl, 5)
        assert_allclose(res.speed[1:], 20.0, atol=1e-9)
        assert_allclose(res.gap, ctrl.equilibrium_gap(20.0), atol=1e-9)


def test_batch_equals_single_runs():
    leads = [sinusoid(omega=w, duration=30.0) for w in (0.3, 0.9)]
    batch = simulate(leads, LinearController(*CERTIFIED), 4)
    for p, lead in enumerate(leads):
        single = simulate(lead, LinearController(*CERTIFIED), 4)
        assert_allclose(batch.accel[p], single.accel, rtol=0, atol=1e-12)
        assert_allclose(batch.damping_ratios[p], single.damping_ratios, rtol=1e-12)


def test_record_false_keeps_the_summaries():
    lead = sinusoid(omega=0.8, duration=40.0)
    full = simulate(lead, LinearController(*CERTIFIED), 3)
    light = simulate(lead, LinearController(*CERTIFIED), 3, record=False)
    assert light.position is None
    assert_allclose(light.damping_ratios, full.damping_ratios, rtol=1e-10)
    assert_allclose(light.min_gap, full.gap.min(axis=-1), rtol=1e-12)


def test_fractional_delay_interpolates_between_samples():
    """With δ = 1.5 Δt the received acceleration is the mean of the samples 1 and 2 steps back."""
    dt = 0.1
    lead = from_accel_segments([(0.0, 1.0), (1.0, 1.0), (0.0, 1.0)], speed0=10.0, dt=dt)
    seen = []
    ctrl = FunctionController(lambda o: seen.append(o.pred_accel_delayed[0, 0]) or np.zeros(o.gap.shape))
    simulate(lead, ctrl, 1, delta=0.15)
    a = lead.accel
    expected = [0.5 * (a[max(k - 1, 0)] + a[max(k - 2, 0)]) for k in range(lead.n_steps)]
    assert_allclose(seen, expected, atol=1e-12)


def test_collision_is_reported_not_clipped():
    """A follower that ignores the leader's hard braking (−7.6 m/s²) runs into it."""
    lead = hard_braking(speed=25.0, to_speed=0.0, cruise_before=5.0, cruise_after=10.0)
    res = simulate(lead, FunctionController(lambda o: np.zeros(o.gap.shape)), 2, initial_gap=10.0)
    assert res.collided[0]
    assert res.collision_events[0] == 1
    assert res.gap[0].min() < -10.0  # positions overlap: nothing was clipped
    first = res.first_collision_time[0]
    assert_allclose(first, res.t[np.argmax(res.gap[0] <= 0)])
    assert res.metrics()["collisions"] >= 1


def test_limits_bind():
    lead = from_accel_segments([(0.0, 10.0)], speed0=0.0)
    res = simulate(lead, FunctionController(lambda o: np.full(o.gap.shape, -50.0)), 1, initial_gap=5.0)
    assert res.speed[1].min() >= 0.0 and res.accel[1].min() >= -7.6 - 1e-12
    assert_allclose(res.command[0], -7.6)
    lead = from_accel_segments([(0.0, 30.0)], speed0=30.0)
    res = simulate(lead, FunctionController(lambda o: np.full(o.gap.shape, 50.0)), 1, initial_gap=500.0,
                   limits=Limits(speed_max=33.3))
    assert res.speed[1].max() <= 33.3 + 1e-12 and res.accel[1].max() <= 3.0 + 1e-12


def test_time_varying_gains_and_mixed_platoon():
    lead = sinusoid(omega=0.5, duration=20.0)
    T = lead.n_steps
    sched = np.tile(np.array(CERTIFIED), (T, 1))
    sched[T // 2:] = UNCERTIFIED
    res = simulate(lead, TimeVaryingLinearController(sched), 2)
    assert res.gains.shape == (2, T, 3)
    assert_allclose(res.gains[0, -1], UNCERTIFIED)
    # eq 27: the certified share of (vehicle, moment) pairs — the first T//2 moments of both
    assert res.metrics()["m_fss"] == pytest.approx((T // 2) / T, abs=1e-9)
    mixed = MixedController([LinearController(*CERTIFIED), IDMController()], [0, 1, 0])
    res = simulate(lead, mixed, 3)
    assert res.gains is None and not res.collided.any()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"tau": -0.1}, "tau"),
        ({"tau": 0.0}, "tau"),
        ({"delta": -0.2}, "delta"),
        ({"model": "euler"}, "model"),
    ],
)
def test_bad_parameters(kwargs, match):
    with pytest.raises(StringStabError, match=match):
        simulate(sinusoid(omega=1.0, duration=2.0), LinearController(*CERTIFIED), 2, **kwargs)


def test_bad_followers_and_leaders():
    lead = sinusoid(omega=1.0, duration=2.0)
    with pytest.raises(StringStabError, match="n_followers"):
        simulate(lead, LinearController(*CERTIFIED), 0)
    with pytest.raises(StringStabError, match="share dt and length"):
        simulate([lead, sinusoid(omega=1.0, duration=3.0)], LinearController(*CERTIFIED), 1)


# --------------------------------------------------------------------------- exact fractional delay
@pytest.mark.parametrize("tau", [0.1, np.array([0.1, 0.15, 0.12])])
def test_exact_fractional_delay_is_the_certified_sampled_loop(tau):
    """With fractional_delay="exact" the follower receives a_p(kΔt − δ) itself: the amplitude
    ratios of followers 2/1 and 3/2 behind a sinusoidal leader equal |H(e^{jωΔt})| of the
    independent expm construction (tests/_sampled_truth.py), also with a different lag per car
    (the predecessor's lag τ_p enters the received sample).  The default interpolation differs."""
    from tests._sampled_truth import pair_response

    K, H, delta, w = (1.2, 0.5, 0.6), 0.1, 0.25, 3.0
    lead = sinusoid(omega=w, amplitude=0.3, speed=20.0, duration=120.0, dt=H)
    taus = np.broadcast_to(np.asarray(tau, dtype=float), (3,))
    res = simulate(lead, LinearController(*K, headway=HEADWAY), 3, tau=tau, delta=delta,
                   fractional_delay="exact")
    sel = res.t > 60.0
    amp = [_amplitude(res.t[sel], res.accel[i][sel], w) for i in range(4)]
    for i in (2, 3):  # follower i behind follower i − 1 (a lag vehicle)
        want = abs(pair_response(np.array([w * H]), *K, taus[i - 1], delta, HEADWAY, H,
                                 tau_prev=taus[i - 2])[0])
        assert_allclose(amp[i] / amp[i - 1], want, rtol=1e-6)
    assert res.params["fractional_delay"] == "exact"
    lin = simulate(lead, LinearController(*K, headway=HEADWAY), 3, tau=tau, delta=delta)
    amp_lin = [_amplitude(lin.t[sel], lin.accel[i][sel], w) for i in range(3)]
    assert abs(amp_lin[2] / amp_lin[1] - amp[2] / amp[1]) > 1e-3
    assert "fractional_delay" not in lin.params


def test_exact_fractional_delay_on_a_multiple_of_the_step_changes_nothing():
    lead = sinusoid(omega=2.0, amplitude=0.3, speed=20.0, duration=20.0, dt=0.1)
    a = simulate(lead, LinearController(1.2, 0.5, 0.6), 2, delta=0.2)
    b = simulate(lead, LinearController(1.2, 0.5, 0.6), 2, delta=0.2, fractional_delay="exact")
    assert np.array_equal(a.accel, b.accel)


def test_fractional_delay_option_is_checked():
    lead = sinusoid(omega=2.0, duration=2.0)
    with pytest.raises(StringStabError, match="fractional_delay must be 'linear' or 'exact'"):
        simulate(lead, LinearController(1.2, 0.5, 0.6), 2, fractional_delay="cubic")


@pytest.mark.parametrize("fractional_delay", ["linear", "exact"])
def test_platoon_state_round_trip_continues_bit_for_bit(fractional_delay):
    from stringstab.traffic.dynamics import Platoon

    dt, n = 0.1, 60
    t = np.arange(2 * n + 1) * dt
    lv = 15 + 2 * np.sin(0.8 * t)
    la = 1.6 * np.cos(0.8 * t)
    lx = np.cumsum(np.r_[0.0, lv[:-1] * dt])

    def make():
        # δ = 0.25 s is 2.5 steps: the fractional part of the delay is used
        p = Platoon(2, 3, dt=dt, tau=0.3, delta=0.25, fractional_delay=fractional_delay)
        p.reset(lx[0], lv[0], la[0], gap=np.full((2, 3), 20.0), speed=np.full((2, 3), 15.0),
                accel=0.0)
        return p

    def run(p, k0, k1):
        out = []
        for k in range(k0, k1):
            obs = p.observe(lx[k], lv[k], la[k])
            u = 0.4 * (obs.gap - 5 - 1.1 * obs.speed) + 0.6 * obs.rel_speed + 0.3 * obs.pred_accel_delayed
            out.append(p.advance(u).copy())
        return np.array(out)

    a = make()
    run(a, 0, n)
    meta, arrays = a.state()
    tail = run(a, n, 2 * n)
    b = make()
    b.load_state(meta, arrays)
    assert np.array_equal(run(b, n, 2 * n), tail)
    with pytest.raises(StringStabError, match="platoon state: expected _buf"):
        make().load_state(meta, {k: v for k, v in arrays.items() if k != "_buf"})
