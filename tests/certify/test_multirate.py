"""The multi-rate V2V certificate (issue 26): the lifted link, its bounds, its verdicts.

Independent truths: the sampled certificate's H(z) (itself checked against an expm
construction in tests/_sampled_truth.py) for the lifting at N = 1; the structure of the model
(a constant command propagates; Σu_i = Σu_{i−1} over a period) for G(1); numpy eigenvalues
of the follower's closed loop for the lifted spectrum; the congruence computed directly from
G for the margin matrix; finite differences and brute-force norms for every bound; and the
sampled certificate's verdicts and sup|H| for the lifted decision at N = 1.  The impulse-response
and simulation truth of analysis/multirate_check.py is tests/certify/test_multirate_check.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from stringstab.certify import multirate, sampled
from stringstab.certify.lifted_frequency import LOCAL, curvature, evaluate, helmert, prepare
from stringstab.certify.lifting import lift, lifted_response
from stringstab.certify.sampled_frequency import sampled_response
from stringstab.certify.schur import poles
from stringstab.certify.verdicts import codes
from stringstab.certify.zoh import point_coefficients
from stringstab.params import Params

RNG = np.random.default_rng(26)
# (τ, δ, T*, H): δ on and between multiples of H, δ < H, δ = 0, H > τ
SETTINGS = [(0.1, 0.2, 1.1, 0.1), (0.1, 0.25, 1.1, 0.1), (0.1, 0.2, 1.1, 0.01),
            (0.2, 0.03, 0.8, 0.05), (0.15, 0.0, 1.5, 0.02), (0.05, 0.33, 1.2, 0.1)]


def _stable_gains(n, p, H, rng=RNG):
    """Random gains whose follower loop is Schur (Δ roots from numpy)."""
    out = []
    while len(out) < n:
        K = np.stack([rng.uniform(0.05, 2.0, 64), rng.uniform(-0.5, 2.0, 64),
                      rng.uniform(-0.5, 1.2, 64)], axis=1)
        co, _ = point_coefficients(*K.T.copy(), p, H, p.tau)
        r = np.abs(poles([d.lo for d in co.delta])).max(axis=1)
        out += list(K[r < 0.999])
    return np.array(out[:n])


@pytest.mark.parametrize("tau, delta, headway, H", SETTINGS)
def test_the_lifted_link_at_one_step_is_the_sampled_transfer_function(tau, delta, headway, H):
    p = Params(tau, delta, headway)
    K = _stable_gains(6, p, H)
    link = lift(*K.T.copy(), p, H, 1)
    th = np.linspace(0.001, np.pi, 41)
    G = lifted_response(link, th)[..., 0, 0]
    Hz = sampled_response(th[None, :], K[:, :1], K[:, 1:2], K[:, 2:], tau=tau, delta=delta,
                          headway=headway, sample_time=H)
    np.testing.assert_allclose(G, Hz, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("N", [2, 5, 10, 20])
def test_a_constant_command_propagates_and_the_period_sums_are_kept(N):
    # G(1)1 = 1 (steady state of a constant command) and 1ᵀG(1) = 1ᵀ (over a period of the
    # periodic steady state the speed difference returns: Σu_i = Σu_{i−1}); the margin matrix
    # is derived from both
    for tau, delta, headway, H in SETTINGS:
        p = Params(tau, delta, headway)
        K = _stable_gains(4, p, H)
        L = lift(*K.T.copy(), p, H, N)
        A, B, C, D = L.A.mid, L.B.mid, L.C.mid, L.D.mid
        G1 = C @ np.linalg.solve(np.eye(A.shape[-1]) - A, B) + D
        one = np.ones(N)
        np.testing.assert_allclose(G1 @ one, np.ones((4, N)), atol=1e-9)
        np.testing.assert_allclose(one @ G1, np.ones((4, N)), atol=1e-9)


@pytest.mark.parametrize("N", [1, 3, 10])
def test_the_lifted_spectrum_is_the_follower_s_to_the_nth_power_and_the_lag(N):
    # the cascade predecessor lag → delay line → hold → follower: spec(A) = {λ^N} ∪ {E^N} ∪ {0}
    tau, delta, headway, H = 0.1, 0.25, 1.1, 0.05
    p = Params(tau, delta, headway)
    K = np.array([[1.2, 0.5, 0.6], [0.3, -0.4, 1.0], [2.5, 3.0, 0.1]])
    L = lift(*K.T.copy(), p, H, N)
    co, _ = point_coefficients(*K.T.copy(), p, H, tau)
    lam = poles([d.lo for d in co.delta])
    for i in range(len(K)):
        ev = np.linalg.eigvals(L.A.mid[i])
        want = np.concatenate([lam[i] ** N, [np.exp(-N * H / tau)],
                               np.zeros(L.order - 4)])
        got = np.sort_complex(np.round(ev, 9))
        np.testing.assert_allclose(np.sort(np.abs(got)), np.sort(np.abs(want)), atol=1e-7)


def test_the_entry_radii_cover_a_recomputation_in_long_double():
    # the state block of the lifted A (A_c^N) recomputed in 80-bit extended precision from the
    # same per-step A_c lies within the propagated radii (the products' round-off is covered)
    if np.finfo(np.longdouble).eps >= np.finfo(float).eps:
        pytest.skip("no extended precision on this platform")
    p = Params(0.1, 0.25, 1.1)
    K = np.array([[1.2, 0.5, 0.6], [0.4, 1.9, -0.3]])
    N, H = 7, 0.02
    L = lift(*K.T.copy(), p, H, N)
    from stringstab.certify.lifting import step_model

    A_c = step_model(*K.T.copy(), p, H)[0]
    for i in range(len(K)):
        Ac = A_c.mid[i].astype(np.longdouble)
        P = np.eye(4, dtype=np.longdouble)
        for _ in range(N):
            P = Ac @ P
        err = np.abs(P[:4, :4].astype(float) - L.A.mid[i][:4, :4])
        assert (err <= L.A.rad[i][:4, :4] + 1e-300).all()
        assert L.A.rad[i].max() < 1e-11  # and the radii are small


@pytest.mark.parametrize("N", [2, 5])
def test_the_margin_matrix_is_the_weighted_congruence_of_i_minus_g_star_g(N):
    p = Params(0.1, 0.25, 1.1)
    H = 0.05
    K = _stable_gains(5, p, H)
    L = lift(*K.T.copy(), p, H, N)
    pr = prepare(L)
    th = np.tile(np.linspace(0.2, np.pi, 9), (len(K), 1))
    mg = evaluate(pr, np.arange(len(K)), th, matrices=True)
    G = lifted_response(L, th)
    e, V, _ = helmert(N)
    Q = np.concatenate([e[:, None], V], axis=1)
    z = np.exp(1j * th)
    for i in range(len(K)):
        for j in range(th.shape[1]):
            t = (z[i, j] - pr.r[i]) / (z[i, j] - 1.0)
            S = np.diag(np.r_[t, np.ones(N - 1)])
            M = S.conj().T @ Q.T @ (np.eye(N) - G[i, j].conj().T @ G[i, j]) @ Q @ S
            np.testing.assert_allclose(mg.M[i, j], M, rtol=1e-9, atol=1e-11)
            lam = np.linalg.eigvalsh(M)[0]
            assert abs(lam - mg.lam[i, j]) <= mg.slack[i, j] + 1e-12
            # the sign of λ_min is that of 1 − σ_max²: the congruence keeps the inertia
            s = np.linalg.norm(G[i, j], 2)
            assert np.sign(round(lam, 9)) == np.sign(round(1.0 - s * s, 9)) or abs(1 - s) < 1e-9


def test_the_resolvent_and_local_bounds_hold_by_brute_force():
    p = Params(0.1, 0.2, 1.1)
    for N, H in ((10, 0.01), (3, 0.1)):
        K = _stable_gains(4, p, H)
        L = lift(*K.T.copy(), p, H, N)
        pr = prepare(L)
        th = np.tile(np.linspace(0.0, np.pi, 13), (len(K), 1))
        mg = evaluate(pr, np.arange(len(K)), th)
        for i in range(len(K)):
            for j in range(th.shape[1]):
                R = np.linalg.inv(np.exp(1j * th[i, j]) * np.eye(pr.A.shape[-1]) - pr.A[i])
                assert np.linalg.norm(R, 2) <= mg.rho[i, j]
                CR = np.linalg.norm(pr.C[i] @ R, 2)
                RBV = np.linalg.norm(R @ pr.Q[i][:, :N - 1], 2) if N > 1 else 0.0
                assert CR * RBV <= mg.local[i, j, LOCAL.index("GV_pq")] * (1 + 1e-12)


@pytest.mark.parametrize("N, H", [(10, 0.01), (2, 0.1), (20, 0.01)])
def test_the_curvature_bound_holds_by_finite_differences(N, H):
    # ‖M''‖ (central differences of the computed M, step 1e-4) ≤ K on every interval, and the
    # λ_min of every fine point ≥ min(ends) − K h²/8 − slack (the inequality the proof uses)
    p = Params(0.1, 0.2, 1.1)
    K = _stable_gains(3, p, H)
    L = lift(*K.T.copy(), p, H, N)
    pr = prepare(L)
    n = len(K)
    edges = np.tile(np.linspace(0.0, np.pi, 25), (n, 1))
    mg = evaluate(pr, np.arange(n), edges)
    h = edges[:, 1:2] - edges[:, :1]
    Kb = curvature(mg.local[:, :-1], mg.local[:, 1:], h)
    inner = edges[:, :-1, None] + h[:, :, None] * np.linspace(0.0, 1.0, 9)[None, None, :]
    d = 1e-4
    for k, th in enumerate(np.moveaxis(inner, 2, 0)):
        th = np.clip(th, d, np.pi - d)
        Ms = [evaluate(pr, np.arange(n), th + s, matrices=True).M for s in (-d, 0.0, d)]
        second = np.linalg.norm((Ms[0] - 2 * Ms[1] + Ms[2]) / d**2, 2, axis=(-2, -1))
        assert (second <= Kb * (1 + 1e-6) + 1e-6).all(), (k, (second / Kb).max())
        lam = evaluate(pr, np.arange(n), inner[:, :, k]).lam
        low = (np.minimum(mg.lam[:, :-1], mg.lam[:, 1:]) - Kb * h * h / 8
               - np.maximum(mg.slack[:, :-1], mg.slack[:, 1:]))
        assert (lam >= low).all()


@pytest.mark.parametrize("tau, delta, headway, H", SETTINGS[:4])
def test_the_lifted_decision_at_one_step_agrees_with_the_sampled_certificate(tau, delta, headway, H):
    # evidence (not by construction: the lifted decision is a different computation)
    p = Params(tau, delta, headway)
    rng = np.random.default_rng(7)
    n = 120 if H >= 0.05 else 24  # at H = 0.01 the lifted state has m + 5 = 25 dimensions
    Kr = np.stack([rng.uniform(0.05, 2.0, n), rng.uniform(-0.5, 2.0, n),
                   rng.uniform(-0.5, 1.2, n)], axis=1)
    kx, kv, ka = (np.ascontiguousarray(c) for c in Kr.T)
    d = multirate.decide(kx, kv, ka, p, H, 1)
    s = sampled.certify_kernel(kx, kv, ka, p, H, tau)
    np.testing.assert_array_equal(d.verdict, codes(s.verdict))
    b = multirate.certify_kernel(kx, kv, ka, p, H, 1)
    ok = np.isfinite(s.sup_gain)
    np.testing.assert_allclose(b.sup_gain[ok], s.sup_gain[ok], rtol=1e-6)


def test_certified_means_no_gain_above_one_on_a_fine_sweep_and_not_certified_has_a_witness():
    p = Params(0.1, 0.2, 1.1)
    for N, H in ((10, 0.01), (4, 0.05)):
        K = _stable_gains(30, p, H, np.random.default_rng(N))
        b = multirate.certify_kernel(*K.T.copy(), p, H, N)
        link = lift(*K.T.copy(), p, H, N)
        th = np.linspace(0.0, np.pi, 3001)
        S = np.linalg.norm(lifted_response(link, th), 2, axis=(-2, -1))
        cert = b.certified
        assert cert.any() and (~cert).any()
        assert (S[cert].max(axis=1) <= 1 + 1e-9).all()
        nc = b.verdict == "not_certified"
        at = np.linalg.norm(lifted_response(link.take(np.flatnonzero(nc)),
                                            b.peak_theta[nc][:, None]), 2, axis=(-2, -1))[:, 0]
        assert (at > 1.0).all()
        np.testing.assert_allclose(at, b.sup_gain[nc], rtol=1e-9)
