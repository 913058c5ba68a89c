"""The sampled-data certificate against independent truth.

(a) a fine θ sweep of H(e^{jθ}) from the exactly discretised state space of two
consecutive vehicles built in tests/_sampled_truth.py with scipy's expm, and numpy.roots;
(b) the platoon simulator with a sinusoidal leader; (c) the continuous limit H → 0;
(e) a walk across the Ψ3 boundary; (f) bad input.
"""

import ast
import inspect
import json

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from stringstab.certify import sampled as sampled_module
from stringstab.certify.api import certify, certify_batch, check
from stringstab.certify.frequency import gain, margin_g
from stringstab.certify.sampled_frequency import sampled_margin, sampled_response
from stringstab.certify.schur import schur, spectral_radius
from stringstab.certify.zoh import split_delay
from stringstab.errors import StringStabError
from tests._sampled_truth import THETA, pair_response, pair_roots

# (tau, delta, headway, sample_time, tau_prev): δ on and between multiples of H, δ < H,
# δ = 0, H > τ, and a heterogeneous pair
SETTINGS = [
    (0.1, 0.2, 1.1, 0.1, None), (0.1, 0.25, 1.1, 0.1, None), (0.3, 0.05, 0.8, 0.2, None),
    (0.05, 0.4, 1.5, 0.05, None), (0.5, 0.0, 2.0, 0.2, None), (0.1, 0.2, 1.1, 0.5, None),
    (0.1, 0.2, 1.1, 0.1, 0.3),
]
gain_st = st.floats(-2, 2, allow_nan=False).filter(lambda k: k == 0 or abs(k) >= 1e-6)


def truth(kx, kv, ka, tau, delta, headway, H, tp):
    h = pair_response(THETA, kx, kv, ka, tau, delta, headway, H, tau_prev=tp)
    r = np.max(np.abs(pair_roots(kx, kv, tau, headway, H)))
    a = np.abs(h)
    rel = np.min((1 - a**2) / np.minimum(1.0, (THETA / H) ** 2))
    return float(np.max(a)), float(r), float(rel)


@given(kx=gain_st, kv=gain_st, ka=gain_st, p=st.sampled_from(SETTINGS))
# a resonance of a pole at radius 0.979 narrower than the grid, below another local maximum
@example(kx=1.875, kv=-1.875, ka=1.1875, p=(0.05, 0.4, 1.5, 0.05, None))
def test_verdict_agrees_with_direct_sweep_and_roots(kx, kv, ka, p):
    tau, delta, headway, H, tp = p
    c = certify(kx, kv, ka, tau=tau, delta=delta, headway=headway, sample_time=H,
                        tau_prev=tp)
    peak, radius, rel = truth(kx, kv, ka, tau, delta, headway, H, tp)
    if c.verdict == "certified":  # soundness
        assert radius < 1.0
        assert peak <= 1 + 1e-9
        assert c.sup_gain == 1.0 and c.schur
    elif c.verdict == "not_certified":  # a witness
        assert radius >= 1.0 - 1e-9 or c.sup_gain > 1.0
        if radius < 1.0 - 1e-9:
            h = pair_response(np.array([c.peak_theta]), kx, kv, ka, tau, delta, headway, H,
                              tau_prev=tp)
            assert abs(h[0]) > 1.0
            assert_allclose(c.sup_gain, abs(h[0]), rtol=1e-9)
            assert c.sup_gain >= peak * (1 - 1e-6)
            assert_allclose(c.peak_omega, c.peak_theta / H, rtol=1e-15)
    # completeness away from the boundary
    if radius < 1 - 1e-6 and rel > 1e-4:
        assert c.verdict == "certified"
    if radius > 1 + 1e-6 or (radius < 1 - 1e-6 and peak > 1 + 1e-6):
        assert c.verdict == "not_certified"
    assert_allclose(c.spectral_radius, radius, rtol=1e-9)


@pytest.mark.parametrize("tau, delta, headway, H, tp", SETTINGS)
def test_response_equals_direct_construction(tau, delta, headway, H, tp):
    rng = np.random.default_rng(1)
    th = np.linspace(1e-3, np.pi, 57)
    for kx, kv, ka in rng.uniform(-2, 2, (5, 3)):
        ours = sampled_response(th, kx, kv, ka, tau=tau, delta=delta, headway=headway,
                                sample_time=H, tau_prev=tp)
        assert_allclose(ours, pair_response(th, kx, kv, ka, tau, delta, headway, H, tau_prev=tp),
                        rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("tau, delta, headway, H, tp", SETTINGS[:4])
def test_margin_sign_is_the_sign_of_one_minus_gain(tau, delta, headway, H, tp):
    rng = np.random.default_rng(2)
    th = np.linspace(1e-3, np.pi, 301)
    for kx, kv, ka in rng.uniform(-2, 2, (8, 3)):
        g = sampled_margin(th, kx, kv, ka, tau=tau, delta=delta, headway=headway, sample_time=H)
        a = np.abs(pair_response(th, kx, kv, ka, tau, delta, headway, H))
        clear = np.abs(1 - a) > 1e-7
        assert np.array_equal((g > 0)[clear], (a < 1)[clear])


def test_check_and_batch_agree_and_do_not_depend_on_chunking():
    rng = np.random.default_rng(3)
    K = rng.uniform(-2, 2, (400, 3))
    K[:40, 2] = (2 - K[:40, 0] * 1.1**2 - 2 * K[:40, 1] * 1.1) / 2  # Ψ3 = 0: tangent at θ = 0
    kw = dict(tau=0.1, delta=0.25, headway=1.1, sample_time=0.1)
    a = certify_batch(*K.T, **kw)
    b = certify_batch(*K.T, chunk=7, **kw)
    c = check(*K.T, **kw)
    assert a.verdict.tolist() == b.verdict.tolist() == c.verdict.tolist()
    assert_allclose(a.margin, c.margin, rtol=0, atol=0)
    s = a.summary()
    assert s["certified"] + s["not_certified"] + s["inconclusive"] == 400
    json.dumps(a.records())  # strict JSON: no inf/nan


# ---------------------------------------------------------------------------
# (b) the platoon simulator at the same Δt
# ---------------------------------------------------------------------------
def _amplitude(t, x, w):
    X = np.stack([np.cos(w * t), np.sin(w * t), np.ones_like(t)], axis=1)
    c, *_ = np.linalg.lstsq(X, x, rcond=None)
    return np.hypot(c[0], c[1])


@pytest.mark.parametrize("H, delta, w", [(0.1, 0.2, 3.0), (0.05, 0.2, 2.0), (0.2, 0.2, 1.5),
                                         (0.1, 0.0, 3.0)])
def test_simulator_amplitude_ratio_equals_H_when_delta_is_a_multiple_of_the_step(H, delta, w):
    """Followers 2 and 3 of a platoon behind a sinusoidal leader: ratio = |H(e^{jωH})|.

    The simulator holds u (ZOH) and integrates the lag exactly; with δ a multiple of Δt
    its delayed sample is exact too, so it is the sampled loop certified here.
    """
    from stringstab.traffic import LinearController, simulate, sinusoid

    K = (1.2, 0.5, 0.6)
    res = simulate(sinusoid(omega=w, amplitude=0.3, speed=20.0, duration=120.0, dt=H),
                   LinearController(*K, headway=1.1), 3, tau=0.1, delta=delta)
    sel = res.t > 60.0
    A = [_amplitude(res.t[sel], res.accel[i][sel], w) for i in range(4)]
    h = abs(sampled_response(w * H, *K, tau=0.1, delta=delta, headway=1.1, sample_time=H))
    assert_allclose(A[2] / A[1], h, rtol=1e-6)
    assert_allclose(A[3] / A[2], h, rtol=1e-6)


def test_simulator_interpolates_a_fractional_delay_linearly():
    """With δ/Δt not an integer the simulator's received sample is a linear interpolation,
    not a(kΔt − δ): its ratio matches the direct model with that interpolation and differs
    from the exact sampled loop (by ~1% here)."""
    from stringstab.traffic import LinearController, simulate, sinusoid

    K, H, delta, w = (1.2, 0.5, 0.6), 0.1, 0.25, 3.0
    res = simulate(sinusoid(omega=w, amplitude=0.3, speed=20.0, duration=120.0, dt=H),
                   LinearController(*K, headway=1.1), 3, tau=0.1, delta=delta)
    sel = res.t > 60.0
    ratio = _amplitude(res.t[sel], res.accel[2][sel], w) / _amplitude(res.t[sel], res.accel[1][sel], w)
    lin = abs(pair_response(np.array([w * H]), *K, 0.1, delta, 1.1, H, delay="linear")[0])
    exact = abs(sampled_response(w * H, *K, tau=0.1, delta=delta, headway=1.1, sample_time=H))
    assert_allclose(ratio, lin, rtol=1e-6)
    assert abs(ratio - exact) > 1e-3


# ---------------------------------------------------------------------------
# (c) the continuous limit
# ---------------------------------------------------------------------------
def test_continuous_limit_away_from_the_boundary():
    """At H = 5 ms the sampled verdict equals the continuous one wherever the continuous
    verdict holds with a relative margin of 2 % (in |Γ|² or in the peak)."""
    rng = np.random.default_rng(5)
    K = rng.uniform(-2, 2, (600, 3))
    kw = dict(tau=0.1, delta=0.2, headway=1.1)
    c = certify_batch(*K.T, **kw)
    s = certify_batch(*K.T, sample_time=0.005, **kw)
    W = np.concatenate([np.geomspace(1e-3, 1, 200), np.linspace(1, 80, 3000)])
    G = gain(W[None, :], K[:, :1], K[:, 1:2], K[:, 2:], **kw)
    rel = np.min((1 - G**2) / np.minimum(1, W**2), axis=1)
    far = (((c.verdict == "certified") & (rel > 0.02))
           | ((c.verdict == "not_certified") & ((c.sup_gain > 1.02) | (c.hurwitz_margin < -0.02))))
    assert far.sum() > 550
    assert np.array_equal(s.verdict[far], c.verdict[far])


def test_margin_tends_to_the_continuous_margin():
    w = np.array([0.0, 0.5, 1.5, 3.0])
    gc = margin_g(w, 1.2, 0.5, 0.6, tau=0.1, delta=0.2, headway=1.1)
    errs = []
    for H in (0.01, 0.001, 0.0001):
        gs = sampled_margin(w * H, 1.2, 0.5, 0.6, tau=0.1, delta=0.2, headway=1.1, sample_time=H)
        errs.append(np.max(np.abs(gs - gc)))
    assert errs[1] < 0.15 * errs[0] and errs[2] < 0.15 * errs[1]  # first order in H
    assert errs[2] < 3e-3 * np.max(np.abs(gc))


# ---------------------------------------------------------------------------
# (e) the Ψ3 boundary: in a homogeneous platoon the sampled θ² coefficient is H²φ1⁴Ψ3
#     (stringstab.derive.sampled_symbolic.dc_margin), so Ψ3 < 0 means |H| > 1 near θ = 0
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("tau, delta, headway, H", [(0.1, 0.2, 1.1, 0.1), (0.3, 0.25, 0.8, 0.2),
                                                    (0.05, 0.4, 1.5, 0.05)])
def test_no_false_certificate_across_the_psi3_boundary(tau, delta, headway, H):
    rng = np.random.default_rng(0)
    kx = rng.uniform(0.2, 2.0, 12)
    kv = rng.uniform(-0.5, 2.0, 12)
    ka_star = (2 - kx * headway**2 - 2 * kv * headway) / 2
    eps = np.array([-1e-3, -1e-6, -1e-9, -1e-12, 0.0, 1e-12, 1e-9, 1e-6, 1e-3])
    KX, KV = np.repeat(kx, eps.size), np.repeat(kv, eps.size)
    KA = (ka_star[:, None] + eps[None, :]).ravel()
    b = certify_batch(KX, KV, KA, tau=tau, delta=delta, headway=headway, sample_time=H)
    psi3 = KX * (KX * headway**2 + 2 * KV * headway + 2 * KA - 2)
    assert not np.any(b.certified & (psi3 < 0))
    for i in np.flatnonzero(b.certified):
        peak, radius, _ = truth(KX[i], KV[i], KA[i], tau, delta, headway, H, None)
        assert radius < 1 and peak <= 1 + 1e-9
    # clearly on the good side and stable: certified
    ok = np.tile(eps >= 1e-3, kx.size) & b.schur
    assert np.all(b.certified[ok] | (b.margin[ok] < 0))


# ---------------------------------------------------------------------------
# API, internal stability, bad input
# ---------------------------------------------------------------------------
def test_schur_and_spectral_radius():
    kx, kv = np.array([1.2, 1.2, -0.5, 0.0]), np.array([0.5, 40.0, 1.0, 1.0])
    s = schur(kx, kv, tau=0.1, headway=1.1, sample_time=0.1)
    r = spectral_radius(kx, kv, tau=0.1, headway=1.1, sample_time=0.1)
    want = [np.max(np.abs(pair_roots(a, b, 0.1, 1.1, 0.1))) for a, b in zip(kx, kv)]
    assert_allclose(r, want, rtol=1e-9)
    assert s.tolist() == [True, False, False, False]
    c = certify(0.0, 1.0, 0.5, tau=0.1, delta=0.2, headway=1.1, sample_time=0.1)
    assert c.verdict == "not_certified" and not c.schur and c.as_dict()["sup_gain"] is None


def test_split_delay_is_exact_on_multiples():
    assert split_delay(0.2, 0.1) == (2, 0.0)
    assert split_delay(0.3, 0.1)[0] in (2, 3)
    m, e = split_delay(0.25, 0.1)
    assert m == 2 and abs(e - 0.5) < 1e-12


def test_no_sympy_on_the_numeric_path():
    tree = ast.parse(inspect.getsource(sampled_module))
    mods = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            mods.add((node.module or "").split(".")[0])
        elif isinstance(node, ast.Import):
            mods.update(a.name.split(".")[0] for a in node.names)
    assert not mods & {"sympy", "symbolic", "criteria", "certificate", "sampled_symbolic"}


@pytest.mark.parametrize("kwargs, msg", [
    ({"sample_time": 0.0}, "sample_time"), ({"sample_time": -0.1}, "sample_time"),
    ({"sample_time": float("nan")}, "sample_time"), ({"sample_time": float("inf")}, "sample_time"),
    ({"sample_time": "fast"}, "sample_time"), ({"tau": 0.0}, "tau"), ({"delta": -0.1}, "delta"),
    ({"headway": -1.0}, "headway"), ({"tau_prev": 0.0}, "tau_prev"),
])
def test_bad_input(kwargs, msg):
    p = {"tau": 0.1, "delta": 0.2, "headway": 1.1, "sample_time": 0.1, **kwargs}
    with pytest.raises(StringStabError, match=msg):
        certify(1.0, 0.5, 0.2, **p)
    with pytest.raises(StringStabError, match=msg):
        check([1.0], [0.5], [0.2], **p)


def test_bad_gains():
    with pytest.raises(StringStabError, match="k_a must be finite"):
        certify_batch([1.0], [0.5], [np.nan], tau=0.1, delta=0.2, headway=1.1,
                              sample_time=0.1)
    with pytest.raises(StringStabError, match="one triple"):
        certify([1.0, 2.0], 0.5, 0.2, tau=0.1, delta=0.2, headway=1.1, sample_time=0.1)
