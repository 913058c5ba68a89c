"""The multi-rate certificate with a reaction delay θ_r > 0 (issue 25; docs/sampled.md §10.5).

Independent truth: an event-driven simulation of the two-vehicle loop written here (scipy's
expm of the continuous model between events — no closed form of the certificate's, no lift):
commands computed every H from the sampled gap, speed difference and the held message
a_{i−1}(k_j H − δ), applied θ_r late by both vehicles; its impulse responses give the lifted
Markov parameters, and sup_θ σ_max(Σ_m G_m e^{−jθm}) on a fine grid is the ℓ2-induced gain.
Also: N = 1 is the sampled θ_r certificate (§10) bit for bit, θ_r = 0 is the multi-rate
certificate (§9) bit for bit, and the lifted follower block is A_f^N.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.linalg import expm

import stringstab as ss
from stringstab.certify import Loop, multirate, sampled_reaction
from stringstab.certify.lifting import lifted_response
from stringstab.certify.lifting_reaction import follower_block, held_steps, lift_reaction
from stringstab.cli import main
from stringstab.params import Params


def _markov(k, tau, delta, T, theta_r, H, N, periods):
    """Lifted Markov parameters G_m (periods, N, N) of u_{i−1} → u_i, by simulation.

    State x = [Δp, Δv, a_i, a_{i−1}], Δp' = Δv − T*a_i, Δv' = a_{i−1} − a_i,
    τa' = w − a for both vehicles (w: the command applied θ_r late).  Message phase 0.
    """
    kx, kv, ka = k
    A = np.zeros((4, 4))
    A[0, 1], A[0, 2] = 1.0, -T
    A[1, 2], A[1, 3] = -1.0, 1.0
    A[2, 2] = A[3, 3] = -1.0 / tau
    B = np.zeros((4, 2))
    B[2, 0] = B[3, 1] = 1.0 / tau
    M = np.zeros((6, 6))
    M[:4, :4], M[:4, 4:] = A, B
    cache: dict[float, np.ndarray] = {}

    def flow(x, w, dt):
        if dt <= 0.0:
            return x
        key = round(dt, 13)
        if key not in cache:
            cache[key] = expm(M * dt)
        E = cache[key]
        return E[:4, :4] @ x + E[:4, 4:] @ w

    K = periods * N
    # events: (time, order, kind, index); at one instant: sample states, then switch inputs
    ev = [(k_ * H - delta, 0, "a", k_) for k_ in range(0, K, N)]
    ev += [(k_ * H, 1, "u", k_) for k_ in range(K)]
    ev += [(k_ * H + theta_r, 2, "w", k_) for k_ in range(K)]
    ev.sort()
    G = np.zeros((periods, N, N))
    for c in range(N):
        up = np.zeros(K)
        up[c] = 1.0
        x, w, t = np.zeros(4), np.zeros(2), ev[0][0]
        ui = np.zeros(K)
        msg: dict[int, float] = {}
        for time, _, kind, j in ev:
            x = flow(x, w, time - t)
            t = time
            if kind == "a":
                msg[j] = x[3] if time >= 0.0 else 0.0
            elif kind == "u":
                ui[j] = kx * x[0] + kv * x[1] + ka * msg[N * (j // N)]
            else:
                w = np.array([ui[j], up[j]])
        G[:, :, c] = ui.reshape(periods, N)
    return G


def _truth_sup(G, n_theta=4001):
    th = np.linspace(0.0, np.pi, n_theta)
    z = np.exp(-1j * np.outer(th, np.arange(G.shape[0])))
    Gz = np.einsum("tm,mrc->trc", z, G)
    return np.linalg.svd(Gz, compute_uv=False)[:, 0].max()


# (gains, τ, δ, T*, θ_r, H, N): θ_r = (q + f)H with q ≥ 1 and f > 0, with f = 0, with q = 0;
# δ with a fractional part and longer than a message period
CASES = [
    ((0.2, 0.6, 0.0), 0.5, 0.1, 1.5, 0.15, 0.1, 3),
    ((0.3, 0.9, 0.25), 0.3, 0.25, 1.2, 0.2, 0.1, 2),
    ((0.3, 0.9, 0.25), 0.3, 0.05, 1.2, 0.04, 0.1, 2),
    ((1.2, 0.5, 0.6), 0.1, 0.2, 1.1, 0.15, 0.1, 2),
    ((0.5, 0.8, 0.3), 0.5, 0.1, 1.5, 0.15, 0.1, 3),
    ((0.25, 1.0, 0.4), 0.4, 0.37, 1.0, 0.13, 0.1, 4),
]


@pytest.mark.parametrize("k, tau, delta, T, theta_r, H, N", CASES)
def test_verdict_and_gain_match_the_simulated_periodic_loop(k, tau, delta, T, theta_r, H, N):
    b = ss.certify_batch(*[[v] for v in k], tau=tau, delta=delta, headway=T, sample_time=H,
                         reaction_delay=theta_r, message_period=N * H)
    assert b.schur[0], "every case here is internally stable"
    G = _markov(k, tau, delta, T, theta_r, H, N, periods=int(np.ceil(1500 / N)))
    assert np.abs(G[-5:]).max() < 1e-9  # the truth has converged (a stable loop)
    sup = _truth_sup(G)
    if b.verdict[0] == "certified":
        assert sup <= 1.0 + 1e-7, sup
        assert b.sup_gain[0] == 1.0
    else:
        assert b.verdict[0] == "not_certified"
        assert sup > 1.0 + 1e-4, sup
        # the reported peak is the simulated one (located on a grid, both sides)
        assert b.sup_gain[0] == pytest.approx(sup, rel=2e-3)
    # and the whole lifted response agrees with the simulation at a few θ
    p = Params(tau, delta, T, reaction_delay=theta_r)
    link = lift_reaction(*[np.array([v]) for v in k], p, H, N)
    th = np.array([[0.0, 0.3, 1.7, np.pi]])
    Gl = lifted_response(link, th)[0]
    z = np.exp(-1j * np.outer(th[0], np.arange(G.shape[0])))
    Gs = np.einsum("tm,mrc->trc", z, G)
    np.testing.assert_allclose(Gl, Gs, atol=1e-9)


def test_the_verdicts_are_mixed():
    """The cases above are not all of one verdict (the test can fail both ways)."""
    v = [ss.certify_batch(*[[x] for x in k], tau=tau, delta=delta, headway=T, sample_time=H,
                          reaction_delay=th, message_period=N * H).verdict[0]
         for k, tau, delta, T, th, H, N in CASES]
    assert "certified" in v and "not_certified" in v


def test_n_equal_1_is_the_sampled_reaction_certificate_bit_for_bit():
    rng = np.random.default_rng(7)
    kx, kv, ka = rng.uniform(0.05, 1.5, 40), rng.uniform(0.1, 1.5, 40), rng.uniform(0, 0.8, 40)
    p = Params(0.4, 0.13, 1.2, reaction_delay=0.17)
    d = multirate.decide(kx, kv, ka, p, 0.1, 1, n_grid=sampled_reaction.GRID)
    v, sure, mg, am, ne, grid, _, rho = sampled_reaction.decide(kx, kv, ka, p, 0.1, 0.4)
    assert np.array_equal(d.verdict, v) and np.array_equal(d.sure, sure)
    assert np.array_equal(d.margin, mg, equal_nan=True) and np.array_equal(d.argmin, am)
    assert np.array_equal(d.n_evals, ne) and np.array_equal(d.rho, rho, equal_nan=True)
    assert np.array_equal(d.grid, grid)
    assert len(set(v.tolist())) > 1


def test_theta_r_zero_is_the_multirate_certificate_bit_for_bit():
    K = ([0.2, 1.2, 0.5], [0.6, 0.5, 0.8], [0.0, 0.6, 0.3])
    P = {"tau": 0.5, "delta": 0.1, "headway": 1.5, "sample_time": 0.1, "message_period": 0.3}
    a = ss.certify_batch(*K, **P).columns()
    b = ss.certify_batch(*K, reaction_delay=0.0, **P).columns()
    assert a.keys() == b.keys()
    for key in a:
        if key != "box":
            assert np.array_equal(a[key], b[key], equal_nan=a[key].dtype.kind == "f"), key


@pytest.mark.parametrize("theta_r, N", [(0.15, 3), (0.2, 2), (0.04, 4)])
def test_the_lifted_follower_block_is_the_one_step_block_to_the_n(theta_r, N):
    k = [np.array([0.3]), np.array([0.9]), np.array([0.25])]
    p = Params(0.3, 0.25, 1.2, reaction_delay=theta_r)
    L = held_steps(theta_r, 0.1)[2]
    one = follower_block(lift_reaction(*k, p, 0.1, 1), L).mid[0]
    lifted = lift_reaction(*k, p, 0.1, N)
    blk = follower_block(lifted, L).mid[0]
    np.testing.assert_allclose(blk, np.linalg.matrix_power(one, N), atol=1e-12)
    # G(1)e = e and G(1)ᵀe = e (the margin matrix's identities, lifted_frequency)
    G1 = lifted_response(lifted, np.array([[0.0]]))[0, 0].real
    e = np.ones(N)
    np.testing.assert_allclose(G1 @ e, e, atol=1e-9)
    np.testing.assert_allclose(G1.T @ e, e, atol=1e-9)


def test_the_fallback_loop_has_the_reaction_delay():
    K = ([0.5], [0.8], [0.3])
    P = {"tau": 0.5, "delta": 0.1, "headway": 1.5, "sample_time": 0.1, "reaction_delay": 0.15}
    b = ss.certify_batch(*K, message_period=0.3, **P)
    acc = ss.certify_batch([0.5], [0.8], [0.0], **P)
    assert b.fallback_verdict[0] == acc.verdict[0] == "not_certified"
    assert b.fallback_sup_gain[0] == pytest.approx(acc.sup_gain[0], rel=1e-6)
    ok = ss.certify_batch([0.2], [0.6], [0.0], message_period=0.3, **P)
    assert ok.fallback_verdict[0] == "certified" and ok.fallback_sup_gain[0] == 1.0


def test_the_largest_message_period_with_theta_r(tmp_path, capsys):
    loop = Loop.of(0.5, 0.1, 1.5, sample_time=0.1, reaction_delay=0.15)
    from stringstab.certify.message_period import largest_message_period

    r = largest_message_period(loop, [0.2, 0.5, 0.33, 0.39], [0.6, 0.8, 0.63, 0.61],
                               [0.0, 0.3, 0.29, 0.06], cap=0.4)
    assert r.max_message_steps.tolist() == [4, 0, 3, 2]
    for i, n_star in enumerate(r.max_message_steps):
        for N in range(1, 5):
            lp = dataclasses.replace(loop, message_steps=N if N > 1 else None)
            v = lp.check([r.k_x[i]], [r.k_v[i]], [r.k_a[i]]).verdict[0]
            if N <= n_star:
                assert v == "certified"
            elif N == n_star + 1:
                assert v != "certified"
    out = tmp_path / "o.json"
    code = main(["certify", "0.2,0.6,0", "--tau", "0.5", "--delta", "0.1", "--headway", "1.5",
                 "--sample-time", "0.1", "--message-period", "0.3", "--reaction-delay", "0.15",
                 "--out", str(out)])
    capsys.readouterr()
    assert code == 0 and out.exists()
