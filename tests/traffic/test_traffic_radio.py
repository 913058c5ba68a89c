"""The radio and the sensors in the simulator (issue 26 item 1) against independent truth.

* the schedule and the hold: what the law sees is the link's value at the last message step;
* the multi-rate loop of docs/sampled.md §9.1: the simulated command link u_1 → u_2 equals, to
  round-off, an N-periodic state-space model built here from the continuous model by the
  matrix exponential (scipy) and lifted over one message period; its steady state under the
  top singular direction of the lifted G(e^{jθ}) has gain σ_max(G(e^{jθ}));
* loss statistics (Bernoulli rate; Gilbert–Elliott rate and mean burst length) over many draws;
* staleness and fallback: the time in fallback counted by hand, the fallback law recomputed
  from the recorded trajectories, the gains in force;
* sensor noise: σ and the lag-1 correlation of white and Gauss–Markov noise, the filter's step
  response (1 − (1 − α)^k);
* same seed, same run; another seed, another run.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.linalg import expm

from stringstab.errors import StringStabError
from stringstab.traffic import (
    FunctionController,
    LinearController,
    MixedController,
    Observation,
    Radio,
    SensorNoise,
    simulate,
    sinusoid,
)
from stringstab.traffic.loss import MessageLoss

TAU, DELTA, HEADWAY, L0 = 0.1, 0.2, 1.1, 2.0
K = (1.2, 0.5, 0.6)


def _recording(ctrl):
    """Wrap a controller to keep the pred_accel_delayed it sees at every step."""
    seen = []

    class Rec(type(ctrl)):
        pass

    rec = Rec.__new__(Rec)
    rec.__dict__.update(ctrl.__dict__)
    orig = ctrl.command

    def command(obs):
        seen.append(np.array(obs.pred_accel_delayed, copy=True))
        return orig(obs)

    rec.command = command
    return rec, seen


@pytest.mark.parametrize("n, phase", [(1, 0), (5, 0), (5, 2), (10, 7)])
def test_the_law_sees_the_last_message(n, phase):
    dt = 0.05
    lead = sinusoid(omega=1.3, amplitude=1.0, speed=20.0, duration=15.0, dt=dt)
    ctrl, seen = _recording(LinearController(*K))
    res = simulate(lead, ctrl, 3, tau=TAU, delta=DELTA, radio=Radio(message_period=n * dt, message_phase=phase))
    seen = np.array(seen)[:, 0]  # (T, N)
    m = round(DELTA / dt)
    T = res.t.size
    for k in range(T):
        last = k - ((k - phase) % n)  # the last step ≡ φ (mod N) at or before k
        src = max(last, 0) - m  # before the first message: the link's value at step 0
        want = res.accel[:-1, max(src, 0)]  # before t = 0: the initial accelerations
        assert_allclose(seen[k], want, rtol=0, atol=0)
    msgs = sum(1 for k in range(T) if (k - phase) % n == 0)
    np.testing.assert_array_equal(res.radio["messages_received"], msgs)
    np.testing.assert_array_equal(res.radio["messages_lost"], 0)


def _pair_model(k, n, phase, dt, delta, tau=TAU, headway=HEADWAY):
    """Per-step state-space of follower 2 behind follower 1 (input u_1, output u_2), N-periodic.

    Deviation state x = [ĝ, v̂1, v̂2, a1, a2, a1 at the last m samples, h]: ĝ' = v̂1 − v̂2,
    v̂' = a, τa' = u − a, the inputs held over the step (exact ZOH by the matrix exponential of
    the augmented matrix); u_2 = k_x(ĝ − T* v̂2) + k_v(v̂1 − v̂2) + k_a h with h the held
    message, refreshed with a1(t_k − δ) at k ≡ φ (mod N).
    """
    kx, kv, ka = k
    m = round(delta / dt)
    Ac = np.zeros((5, 5))
    Ac[0, 1], Ac[0, 2], Ac[1, 3], Ac[2, 4] = 1, -1, 1, 1
    Ac[3, 3] = Ac[4, 4] = -1 / tau
    Bc = np.zeros((5, 2))
    Bc[3, 0] = Bc[4, 1] = 1 / tau
    M = expm(np.block([[Ac, Bc], [np.zeros((2, 7))]]) * dt)
    Ad, Bd = M[:5, :5], M[:5, 5:]
    nx = 5 + m + 1
    steps = []
    for r in range(n):
        due = (r - phase) % n == 0
        # the received value: a1 now (m = 0) or m samples ago (the history's last entry)
        recv = np.zeros(nx)
        recv[3 if m == 0 else 5 + m - 1] = 1.0
        hsel = recv if due else np.eye(nx)[nx - 1]
        C = np.zeros(nx)
        C[0], C[1], C[2] = kx, kv, -(kx * headway + kv)
        C = C + ka * hsel  # u_2 = C x (D = 0: u_1 does not reach u_2 at once)
        A = np.zeros((nx, nx))
        B = np.zeros(nx)
        A[:5, :5] = Ad
        A[:5, :] += np.outer(Bd[:, 1], C)
        B[:5] = Bd[:, 0]
        if m:  # the history shifts: newest a1 (at this step) first
            A[5, 3] = 1.0
            for i in range(1, m):
                A[5 + i, 5 + i - 1] = 1.0
        A[nx - 1] = hsel
        steps.append((A, B, C))
    return steps


def _lift(steps):
    n = len(steps)
    nx = steps[0][0].shape[0]
    Abar = np.eye(nx)
    Bbar = np.zeros((nx, n))
    Cbar = np.zeros((n, nx))
    Dbar = np.zeros((n, n))
    for r, (A, B, C) in enumerate(steps):
        Cbar[r] = C @ Abar
        Dbar[r] = C @ Bbar
        Bbar = A @ Bbar
        Bbar[:, r] += B
        Abar = A @ Abar
    return Abar, Bbar, Cbar, Dbar


def _mixed(u1, k, headway=HEADWAY):
    prescribed = FunctionController(lambda obs: u1[min(obs.step, u1.size - 1)], headway=headway)
    return MixedController([prescribed, LinearController(*k, headway=headway)], [0, 1])


@pytest.mark.parametrize("n, phase", [(1, 0), (4, 0), (4, 3), (10, 2)])
def test_the_simulated_link_is_the_lifted_multirate_model(n, phase):
    dt, T = 0.05, 800
    rng = np.random.default_rng(5)
    u1 = 0.3 * rng.standard_normal(T)
    lead = sinusoid(omega=1.0, amplitude=0.0, speed=20.0, duration=(T - 1) * dt, dt=dt)
    res = simulate(lead, _mixed(u1, K), 2, tau=TAU, delta=DELTA,
                   radio=Radio(message_period=n * dt, message_phase=phase))
    steps = _pair_model(K, n, phase, dt, DELTA)
    x = np.zeros(steps[0][0].shape[0])
    u2 = np.empty(T)
    for k in range(T):
        A, B, C = steps[k % n]
        u2[k] = C @ x
        x = A @ x + B * u1[k]
    assert_allclose(res.command[0], u1, rtol=0, atol=0)
    assert_allclose(res.command[1], u2, rtol=0, atol=1e-11)
    # the lifted model reproduces the per-step one
    Ab, Bb, Cb, Db = _lift(steps)
    if phase == 0:
        xl = np.zeros(Ab.shape[0])
        Y = []
        for j in range(T // n):
            U = u1[j * n:(j + 1) * n]
            Y.append(Cb @ xl + Db @ U)
            xl = Ab @ xl + Bb @ U
        assert_allclose(np.concatenate(Y), u2[:T // n * n], rtol=0, atol=1e-11)


@pytest.mark.parametrize("n", [1, 5])
def test_steady_state_gain_is_the_lifted_singular_value(n):
    # input along the top right singular vector of G(e^{jθ}); output/input energy → σ_max
    dt = 0.05
    steps = _pair_model(K, n, 0, dt, DELTA)
    Ab, Bb, Cb, Db = _lift(steps)
    lam, vec = np.linalg.eig(Ab)
    # stable but for one mode at 1: the common speed (v̂1 = v̂2), which u_2 does not see
    assert np.sort(np.abs(lam))[-2] < 1 and abs(np.abs(lam).max() - 1) < 1e-12
    common = vec[:, np.argmax(np.abs(lam))]
    assert np.abs(Cb @ common).max() < 1e-12 and abs(common[1] - common[2]) < 1e-12
    periods = 8 if n == 5 else 40  # θ = 2π/periods rad per message period: 40 steps
    theta = 2 * math.pi / periods
    z = np.exp(1j * theta)
    G = Cb @ np.linalg.solve(z * np.eye(Ab.shape[0]) - Ab, Bb) + Db
    _, s, vh = np.linalg.svd(G)
    v = vh[0].conj()
    J = 800 // n  # 800 steps: 400 to settle, then 10 whole periods of the input
    U = np.real(np.outer(np.exp(1j * theta * np.arange(J)), v))  # (J, N)
    u1 = 0.3 * U.ravel() / np.abs(U).max()
    lead = sinusoid(omega=1.0, amplitude=0.0, speed=20.0, duration=(u1.size - 1) * dt, dt=dt)
    res = simulate(lead, _mixed(u1, K), 2, tau=TAU, delta=DELTA, radio=Radio(message_period=n * dt))
    tail = slice(400, 800)
    ratio = np.linalg.norm(res.command[1, tail]) / np.linalg.norm(u1[tail])
    assert_allclose(ratio, s[0], rtol=1e-6)


def test_bernoulli_and_gilbert_elliott_statistics():
    shape = (400, 50)
    lb = MessageLoss(0.3, None, shape, np.random.default_rng(0))
    due = np.ones(shape, dtype=bool)
    lost = np.stack([lb.lost(due) for _ in range(100)])
    assert abs(lost.mean() - 0.3) < 0.003  # 2·10⁶ draws: σ ≈ 3·10⁻⁴
    ge = MessageLoss(0.2, 4.0, shape, np.random.default_rng(1))
    lost = np.stack([ge.lost(due) for _ in range(200)])  # (time, ...)
    assert abs(lost.mean() - 0.2) < 0.01
    seq = lost.reshape(200, -1).T  # per link
    runs = []
    for row in seq[:2000]:
        d = np.diff(np.concatenate([[0], row.astype(int), [0]]))
        starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
        runs.extend((ends - starts)[(starts > 0) & (ends < row.size)])  # whole bursts only
    assert abs(np.mean(runs) - 4.0) < 0.15
    # messages not due leave the chain alone and are never lost
    nd = np.zeros(shape, dtype=bool)
    before = ge.bad.copy()
    assert not ge.lost(nd).any()
    np.testing.assert_array_equal(ge.bad, before)


def test_stale_messages_fall_back_to_acc():
    dt, n = 0.1, 2
    lead = sinusoid(omega=1.0, amplitude=1.0, speed=20.0, duration=20.0, dt=dt)
    radio = Radio(message_period=n * dt, loss=1.0, stale_after=0.5, fallback_gains=(0.8, 0.9))
    res = simulate(lead, LinearController(*K), 3, tau=TAU, delta=DELTA, radio=radio)
    T = res.t.size
    # every message lost: stale once (k − 0)·Δt > 0.5 s, i.e. from step 6 on
    stale = np.arange(T) * dt > 0.5 + 1e-9
    assert_allclose(res.radio["fallback_time"], stale.sum() * dt, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(res.radio["messages_received"], 0)
    np.testing.assert_array_equal(res.radio["messages_lost"], len(range(0, T, n)))
    # the fallback law, from the recorded (true) trajectories: k_x'(Δx − T*v − l0) + k_v'Δv
    gap = res.gap
    v = res.speed
    u_fb = 0.8 * (gap - HEADWAY * v[1:] - L0) + 0.9 * (v[:-1] - v[1:])
    assert_allclose(res.command[:, stale], np.clip(u_fb[:, stale], -7.6, 3.0), rtol=1e-12, atol=1e-12)
    # the gains in force are recorded step by step
    assert res.gains.shape == (3, T, 3)
    assert_allclose(res.gains[:, stale], np.broadcast_to([0.8, 0.9, 0.0], (3, stale.sum(), 3)))
    assert_allclose(res.gains[:, ~stale], np.broadcast_to(K, (3, (~stale).sum(), 3)))


def test_fallback_without_gains_drops_the_acceleration_term():
    dt = 0.1
    lead = sinusoid(omega=1.0, amplitude=1.0, speed=20.0, duration=10.0, dt=dt)
    res = simulate(lead, LinearController(*K), 2, tau=TAU, delta=DELTA,
                   radio=Radio(loss=1.0, stale_after=0.3))
    acc = simulate(lead, LinearController(K[0], K[1], 0.0), 2, tau=TAU, delta=DELTA)
    # from step 4 on both run (k_x, k_v, 0); before, the held initial value is 0 too
    assert_allclose(res.accel, acc.accel, rtol=0, atol=1e-12)
    assert res.metrics()["m_fss"] is not None


def test_messages_resume_after_a_burst():
    # loss p = 0.5 in bursts of 5 messages: fallback comes and goes; counts add up
    dt = 0.1
    lead = sinusoid(omega=1.0, amplitude=1.0, speed=20.0, duration=60.0, dt=dt)
    res = simulate(lead, LinearController(*K), 4, tau=TAU, delta=DELTA,
                   radio=Radio(loss=0.5, burst=5, stale_after=0.3, seed=2))
    T = res.t.size
    r, lo = res.radio["messages_received"], res.radio["messages_lost"]
    np.testing.assert_array_equal(r + lo, T)
    assert 0.35 < lo.sum() / (4 * T) < 0.65
    assert (res.radio["fallback_time"] > 0).all() and (res.radio["fallback_time"] < T * dt / 2).all()


def test_same_seed_same_run_other_seed_other_run():
    dt = 0.1
    lead = sinusoid(omega=1.0, amplitude=1.0, speed=20.0, duration=30.0, dt=dt)

    def run(seed):
        return simulate(lead, LinearController(*K), 3, tau=TAU, delta=DELTA,
                        radio=Radio(message_period=0.2, loss=0.2, burst=2, stale_after=0.6, seed=seed),
                        sensors=SensorNoise(gap=0.2, gap_rate=0.05, speed=0.05, correlation_time=1.0,
                                            filter_time=0.2, seed=seed))

    a, b, c = run(4), run(4), run(5)
    for name in ("position", "speed", "accel", "command", "gains"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    for key in a.radio:
        np.testing.assert_array_equal(a.radio[key], b.radio[key])
    assert np.abs(a.accel - c.accel).max() > 1e-3


def _obs(shape, gap=30.0, rel=0.0, speed=20.0, step=0):
    z = np.zeros(shape)
    return Observation(step, step * 0.1, 0.1, gap + z, speed + z, z, speed + rel + z, rel + z, z, z)


@pytest.mark.parametrize("tc", [None, 0.5])
def test_sensor_noise_statistics(tc):
    dt, shape = 0.1, (200, 50)
    s = SensorNoise(gap=0.3, gap_rate=0.1, speed=0.05, correlation_time=tc, seed=1).start(shape, dt)
    ms = [s.measure(_obs(shape, step=k)) for k in range(400)]
    gap = np.stack([m.gap for m in ms]) - 30.0
    rel = np.stack([m.rel_speed for m in ms])
    spd = np.stack([m.speed for m in ms]) - 20.0
    for e, sigma in ((gap, 0.3), (rel, 0.1), (spd, 0.05)):
        assert abs(e.std() / sigma - 1) < 0.01
        assert abs(e.mean()) < 0.01 * sigma * (10 if tc else 1)
        r1 = np.mean(e[1:] * e[:-1]) / e.var()
        assert abs(r1 - (0.0 if tc is None else math.exp(-dt / tc))) < 0.01
    # the predecessor's speed is the measured speed plus the measured gap rate
    assert_allclose(ms[3].pred_speed, ms[3].speed + ms[3].rel_speed, rtol=0, atol=0)
    # independent noise on the three quantities
    assert abs(np.corrcoef(gap.ravel(), spd.ravel())[0, 1]) < 0.01


def test_sensor_filter_step_response():
    dt, tf, shape = 0.1, 0.7, (1, 2)
    s = SensorNoise(filter_time=tf).start(shape, dt)
    first = s.measure(_obs(shape, gap=10.0))
    assert_allclose(first.gap, 10.0)
    alpha = 1 - math.exp(-dt / tf)
    for k in range(1, 30):
        m = s.measure(_obs(shape, gap=20.0, step=k))
        assert_allclose(m.gap, 20.0 - 10.0 * (1 - alpha) ** k, rtol=1e-13)
    assert_allclose(m.rel_speed, 0.0) and assert_allclose(m.speed, 20.0)


def test_sensors_change_what_the_law_sees_not_the_truth():
    dt = 0.1
    lead = sinusoid(omega=1.0, amplitude=1.0, speed=20.0, duration=20.0, dt=dt)
    noisy = simulate(lead, LinearController(*K), 2, tau=TAU, delta=DELTA, sensors=SensorNoise(gap=0.5, seed=1))
    clean = simulate(lead, LinearController(*K), 2, tau=TAU, delta=DELTA)
    assert np.abs(noisy.command - clean.command).max() > 0.1
    # the recorded minimum gap is the true one (from the recorded positions)
    assert_allclose(noisy.min_gap, noisy.gap.min(axis=-1), rtol=0, atol=0)
    assert noisy.params["sensors"]["noise_gap"] == 0.5


@pytest.mark.parametrize("kwargs, match", [
    ({"loss": 1.2}, r"loss \(message loss rate\) must be a number in \[0, 1\]; got 1.2"),
    ({"loss": float("nan")}, r"loss .* in \[0, 1\]; got nan"),
    ({"loss": -0.1}, r"in \[0, 1\]; got -0.1"),
    ({"loss": 0.2, "burst": 0.5}, "burst .* must be a finite number >= 1; got 0.5"),
    ({"loss": 0.9, "burst": 2}, "impossible"),
    ({"message_period": -0.1}, "message period must be a finite number of seconds > 0; got -0.1"),
    ({"message_period": float("nan")}, "message period must be a finite number"),
    ({"message_phase": -1}, "message phase must be a whole number of steps >= 0"),
    ({"message_phase": 0.5}, "message phase must be a whole number"),
    ({"stale_after": 0.0}, "stale_after must be a finite number of seconds > 0; got 0.0"),
    ({"message_period": 0.5, "stale_after": 0.2}, "stale_after must be at least the message period 0.5 s"),
    ({"fallback_gains": (1.0, 0.5)}, "expected stale_after with them"),
    ({"stale_after": 1.0, "fallback_gains": (1.0, float("nan"))}, "two finite numbers"),
    ({"seed": -1}, "seed must be an integer >= 0"),
])
def test_bad_radio(kwargs, match):
    with pytest.raises(StringStabError, match=match):
        Radio(**kwargs)


@pytest.mark.parametrize("kwargs, match", [
    ({"gap": -0.1}, r"noise σ of the gap \(m\) must be a finite number >= 0; got -0.1"),
    ({"speed": float("nan")}, "noise σ of the speed"),
    ({"correlation_time": 0.0}, "correlation time .* > 0"),
    ({"filter_time": -1.0}, "filter time constant"),
])
def test_bad_sensors(kwargs, match):
    with pytest.raises(StringStabError, match=match):
        SensorNoise(**kwargs)


def test_bad_schedule_against_the_step():
    lead = sinusoid(omega=1.0, amplitude=1.0, speed=20.0, duration=2.0, dt=0.01)
    with pytest.raises(StringStabError, match=r"whole multiple \(>= 1\) of the step dt = 0.01 s; got 0.015 s"):
        simulate(lead, LinearController(*K), 2, radio=Radio(message_period=0.015))
    with pytest.raises(StringStabError, match=r"message phase must be a step in 0\.\.9"):
        simulate(lead, LinearController(*K), 2, radio=Radio(message_period=0.1, message_phase=10))
    with pytest.raises(StringStabError, match="fallback gains need a controller of the eq-4 form"):
        from stringstab.traffic import IDMController

        simulate(lead, IDMController(), 2, radio=Radio(stale_after=0.5, fallback_gains=(1, 1)))


def test_describe_round_trips_through_json():
    import json

    r = Radio(message_period=0.1, message_phase=[0, 1, 2], loss=0.1, burst=2, stale_after=0.3,
              fallback_gains=(1, 0.5), seed=3)
    assert json.loads(json.dumps(r.describe()))["message_phase"] == [0, 1, 2]
    assert dataclasses.asdict(SensorNoise(gap=0.1))["gap"] == 0.1
