"""The exact certificate against independent truth: a fine frequency sweep and numpy.roots.

The sweep below evaluates Γ(jω) directly from the model with complex NumPy
(not through stringstab.certify.frequency), on a dense grid up to 400 rad/s plus a
logarithmic grid near 0.
"""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from stringstab.certify.api import certify, certify_batch
from stringstab.certify.frequency import margin_g, margin_g_coefficients
from stringstab.certify.margin import tail_bound
from stringstab.certify.pade import certify_pade
from stringstab.errors import StringStabError

W_SWEEP = np.unique(np.concatenate([
    np.geomspace(1e-4, 1.0, 3000),
    np.linspace(1.0, 30.0, 60_000),
    np.linspace(30.0, 400.0, 20_000),
]))

PARAMS = [(0.1, 0.2, 1.1), (0.05, 0.4, 0.6), (0.3, 0.0, 1.5), (0.5, 0.2, 1.1), (0.2, 0.5, 2.0)]


def sweep_peak(kx, kv, ka, tau, delta, headway):
    s = 1j * W_SWEEP
    G = (kx + kv * s + ka * s**2 * np.exp(-delta * s)) / (tau * s**3 + s**2 + (kv + headway * kx) * s + kx)
    return float(np.max(np.abs(G)))


def roots_stable(kx, kv, tau, headway):
    r = np.roots([tau, 1.0, kv + headway * kx, kx])
    return bool(np.all(r.real < 0)), float(-np.max(r.real))


# gains of physical size: exactly 0 or |k| ≥ 1e-6 (at k_x ~ 1e-89 the violation
# |Γ| − 1 ~ 1e-89 is real but below double precision at any ω)
gain = st.floats(-2, 2, allow_nan=False).filter(lambda k: k == 0 or abs(k) >= 1e-6)


@settings(max_examples=150)
@given(kx=gain, kv=gain, ka=gain, p=st.sampled_from(PARAMS))
def test_verdict_agrees_with_fine_sweep_and_roots(kx, kv, ka, p):
    tau, delta, headway = p
    c = certify(kx, kv, ka, tau=tau, delta=delta, headway=headway)
    stable, decay = roots_stable(kx, kv, tau, headway)
    peak = sweep_peak(kx, kv, ka, tau, delta, headway)
    if c.verdict == "certified":
        # soundness: never certified when the swept peak exceeds 1 + 1e-9
        assert stable
        assert peak <= 1 + 1e-9
        assert c.sup_gain == 1.0
    elif c.verdict == "not_certified":
        # a witness: unstable, or |Γ| > 1 somewhere (at the reported peak)
        assert (not stable) or c.sup_gain > 1.0
        if stable:
            s = 1j * c.peak_omega
            G = (kx + kv * s + ka * s**2 * np.exp(-delta * s)) / (
                tau * s**3 + s**2 + (kv + headway * kx) * s + kx)
            assert abs(G) > 1.0
            # the reported peak is at least the swept one (up to sweep resolution)
            assert c.sup_gain >= peak * (1 - 1e-6)
    # completeness away from the boundary: clearly stable, clearly |Γ| ≤ 1 ⇒ certified
    gmin = float(np.min(margin_g(W_SWEEP, kx, kv, ka, tau=tau, delta=delta, headway=headway)))
    g0 = float(margin_g(0.0, kx, kv, ka, tau=tau, delta=delta, headway=headway))
    if stable and decay > 1e-6 and min(gmin, g0) > 1e-6:
        assert c.verdict == "certified"
    if stable and decay > 1e-6 and peak > 1 + 1e-6:
        assert c.verdict == "not_certified"


@pytest.mark.parametrize("tau, delta, headway", PARAMS)
def test_no_false_certificate_across_the_psi3_boundary(tau, delta, headway):
    """Walk k_a across Ψ3 = 0 (g(0) = Ψ3): certified ⇒ swept peak ≤ 1 + 1e-9, everywhere."""
    rng = np.random.default_rng(0)
    kx = rng.uniform(0.2, 2.0, 12)
    kv = rng.uniform(-0.5, 2.0, 12)
    ka_star = (2 - kx * headway**2 - 2 * kv * headway) / 2  # Ψ3 = 0
    eps = np.array([-1e-3, -1e-6, -1e-9, -1e-12, 0.0, 1e-12, 1e-9, 1e-6, 1e-3])
    KX = np.repeat(kx, eps.size)
    KV = np.repeat(kv, eps.size)
    KA = (ka_star[:, None] + eps[None, :]).ravel()
    b = certify_batch(KX, KV, KA, tau=tau, delta=delta, headway=headway)
    for i in np.nonzero(b.certified)[0]:
        assert roots_stable(KX[i], KV[i], tau, headway)[0]
        assert sweep_peak(KX[i], KV[i], KA[i], tau, delta, headway) <= 1 + 1e-9
    psi3 = KX * (KX * headway**2 + 2 * KV * headway + 2 * KA - 2)
    # strictly negative Ψ3 means |Γ(jω)| > 1 near ω = 0: never certified
    assert not np.any(b.certified & (psi3 < 0))


@given(kx=gain, kv=gain, ka=gain, p=st.sampled_from(PARAMS))
def test_tail_bound_is_a_bound(kx, kv, ka, p):
    tau, delta, headway = p
    co = margin_g_coefficients(np.array([kx]), kv, ka, tau=tau, delta=delta, headway=headway)
    W = float(tail_bound(*co)[0])
    w = np.linspace(W, 40 * W + 40, 20_000)
    assert np.all(margin_g(w, kx, kv, ka, tau=tau, delta=delta, headway=headway) > 0)


def test_not_internally_stable_is_never_certified():
    c = certify(0.0, 1.0, 0.5, tau=0.1, delta=0.2, headway=1.1)  # k_x = 0: pole at s = 0
    assert c.verdict == "not_certified" and not c.hurwitz and c.sup_gain == np.inf
    c = certify(-1.66, -1.05, 1.21, tau=0.1, delta=0.2, headway=1.1)
    assert c.verdict == "not_certified" and c.as_dict()["sup_gain"] is None
    # marginal: k_v + (T* − τ) k_x = 0 exactly → poles on the imaginary axis
    c = certify(1.0, -1.0, 0.2, tau=0.1, delta=0.2, headway=1.1)
    assert c.verdict in ("inconclusive", "not_certified")


# Triples where the Taylor verdicts and the exact certificate disagree, in both
# directions (τ = 0.1 s, δ = 0.2 s, T* = 1.1 s; found by a search over [-2, 2]³).
DISAGREE = [
    # (K, exact, taylor derived, printed)
    ((0.9, -0.5, 1.1), "not_certified", "unstable", "stable"),   # printed says stable: wrong
    ((-1.66, -1.05, 1.21), "not_certified", "stable", "stable"),  # not internally stable
    ((1.67, 1.34, -1.04), "certified", "stable", "unstable"),     # printed says unstable: wrong
    ((1.82, 0.91, -0.98), "certified", "unstable", "unstable"),   # Taylor truncation too strict
]


@pytest.mark.parametrize("K, exact, derived, printed", DISAGREE)
def test_printed_and_exact_disagree_both_ways(K, exact, derived, printed):
    c = certify(*K, tau=0.1, delta=0.2, headway=1.1)
    assert c.verdict == exact
    assert c.taylor_derived["sign"] == derived
    assert c.taylor_printed["sign"] == printed
    # independent truth
    stable = roots_stable(K[0], K[1], 0.1, 1.1)[0]
    peak = sweep_peak(*K, 0.1, 0.2, 1.1)
    assert (stable and peak <= 1 + 1e-9) == (exact == "certified")
    row = c.as_dict()
    assert set(row["taylor_derived"]) == {"psi1", "psi2", "psi3", "lambda", "sign", "type"}


def test_sup_gain_and_peak_match_sweep_for_uncertified():
    K = (0.9, -0.5, 1.1)
    c = certify(*K, tau=0.1, delta=0.2, headway=1.1)
    assert_allclose(c.sup_gain, sweep_peak(*K, 0.1, 0.2, 1.1), rtol=1e-6)
    assert 1.0 < c.peak_omega < 3.0


def test_batch_equals_single_and_summary():
    rng = np.random.default_rng(7)
    K = rng.uniform(-2, 2, (200, 3))
    b = certify_batch(*K.T, tau=0.1, delta=0.2, headway=1.1, chunk=37)
    for i in range(0, 200, 23):
        assert certify(*K[i], tau=0.1, delta=0.2, headway=1.1).verdict == b.verdict[i]
    s = b.summary()
    assert s["n"] == 200
    assert s["certified"] + s["not_certified"] + s["inconclusive"] == 200
    assert_allclose(s["certified_row_share"], np.mean(b.verdict == "certified"), rtol=0, atol=0)
    assert len(b.records()) == 200


@pytest.mark.parametrize("kwargs, msg", [
    ({"tau": 0.0}, "tau"), ({"tau": -0.1}, "tau"), ({"delta": -0.2}, "delta"),
    ({"headway": float("nan")}, "headway"),
])
def test_bad_parameters(kwargs, msg):
    p = {"tau": 0.1, "delta": 0.2, "headway": 1.1, **kwargs}
    with pytest.raises(StringStabError, match=msg):
        certify(1.0, 0.5, 0.2, **p)


def test_bad_gains():
    with pytest.raises(StringStabError, match="k_v must be finite"):
        certify_batch([1.0, 1.0], [0.5, np.nan], [0.1, 0.1], tau=0.1, delta=0.2, headway=1.1)
    with pytest.raises(StringStabError, match="one triple"):
        certify([1.0, 2.0], 0.5, 0.2, tau=0.1, delta=0.2, headway=1.1)


def test_pade_cross_check_agrees_off_the_boundary():
    for K, verdict in [((1.67, 1.34, -1.04), "certified"), ((0.9, -0.5, 1.1), "not_certified")]:
        r = certify_pade(*K, tau=0.1, delta=0.2, headway=1.1, order=5)
        assert r.stable and r.verdict == verdict
        exact = certify(*K, tau=0.1, delta=0.2, headway=1.1)
        assert_allclose(r.hinf, exact.sup_gain, rtol=1e-3)
    # an unstable Γ: python-control's norm returns a finite L∞ value; we report H∞ = ∞
    r = certify_pade(-1.66, -1.05, 1.21, tau=0.1, delta=0.2, headway=1.1)
    assert not r.stable and r.hinf == np.inf and np.isfinite(r.linf)


def test_pade_method_reports_both_and_warns_on_disagreement():
    # a triple just inside: exact certified, Padé(1) too crude a delay model
    b = certify_batch([1.67], [1.34], [-1.04], tau=0.1, delta=0.2, headway=1.1, method="pade")
    assert b.pade is not None and b.pade[0]["order"] == 5
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        b = certify_batch([1.82], [0.91], [-0.98], tau=0.1, delta=0.2, headway=1.1,
                          method="pade", pade_order=1)
    row = b.records()[0]
    assert row["verdict"] == "certified" and "pade" in row
    if not row["pade"]["agrees"]:
        assert any("disagrees" in str(w.message) for w in rec)


def test_verdicts_do_not_depend_on_chunking():
    """Budgets are per triple: hard boundary triples get the same verdict alone or batched."""
    kx = np.array([0.5, 1.2, 0.8, 1.5])
    kv = np.array([0.3, 0.1, 1.0, -0.2])
    ka = (2 - kx * 1.1**2 - 2 * kv * 1.1) / 2  # Ψ3 = 0 exactly: the hardest case
    KX, KV, KA = (np.concatenate([v, v]) for v in (kx, kv, ka))
    KA[4:] += 1e-9
    big = certify_batch(KX, KV, KA, tau=0.1, delta=0.2, headway=1.1)
    one = certify_batch(KX, KV, KA, tau=0.1, delta=0.2, headway=1.1, chunk=1)
    assert big.verdict.tolist() == one.verdict.tolist()


def test_witness_of_a_tiny_violation_is_reported():
    """|Γ| exceeds 1 by ~2e-6 in a narrow band: sup_gain and peak_omega must show it."""
    K = (1.77510761, 1.24315872, -1.07339563)
    c = certify(*K, tau=0.1, delta=0.2, headway=1.1)
    assert c.verdict == "not_certified" and c.margin < 0
    s = 1j * c.peak_omega
    G = (K[0] + K[1] * s + K[2] * s**2 * np.exp(-0.2 * s)) / (0.1 * s**3 + s**2 + (K[1] + 1.1 * K[0]) * s + K[0])
    assert abs(G) > 1.0 and c.sup_gain > 1.0
    assert_allclose(c.sup_gain, abs(G), rtol=1e-12)


def test_check_gives_the_same_verdicts_as_certify_batch():
    from stringstab.certify.api import check

    rng = np.random.default_rng(11)
    K = rng.uniform(-2, 2, (500, 3))
    K[:50, 2] = (2 - K[:50, 0] * 1.1**2 - 2 * K[:50, 1] * 1.1) / 2  # Ψ3 = 0: hard cases
    a = certify_batch(*K.T, tau=0.1, delta=0.2, headway=1.1)
    b = check(*K.T, tau=0.1, delta=0.2, headway=1.1)
    assert a.verdict.tolist() == b.verdict.tolist()
    assert_allclose(a.margin, b.margin, rtol=0, atol=0)
