"""Issue 21, item 5, for the sampled-data certificate: a not-certified Schur row reports
sup|H| − 1 > 0 (``sup_gain_excess``, without cancellation) and the θ where it is attained, also
when the DC margin (H²φ1⁴ Ψ3 in a homogeneous platoon) is just below 0 and the violation sits
near θ → 0, as small as 1e-20.

The truth is independent of stringstab.certify.sampled: H(e^{jθ}) of two consecutive vehicles from the
continuous state equations discretised exactly (Van Loan's block exponential, as in
tests/_sampled_truth.py) in 60-digit arithmetic (mpmath), with the predecessor's held command as
the input.
"""

import math

import mpmath
import numpy as np
import pytest
from scipy.optimize import brentq

import stringstab as ss
from stringstab.certify import sampled, sampled_frequency
from stringstab.certify.margin import coefficients

TAU, DELTA, T = 0.1, 0.2, 1.1
DPS = 60


def _excess_mp(theta, kx, kv, ka, H, tau=TAU, delta=DELTA, T=T, tau_prev=None):
    """|H(e^{jθ})|² − 1 in 60 digits from the exact discretisation of [Δp, Δv, a_i, a_p]."""
    with mpmath.workdps(DPS):
        f = mpmath.mpf
        tp = f(tau if tau_prev is None else tau_prev)
        tau, T, H, delta = f(tau), f(T), f(H), f(delta)
        kx, kv, ka = f(kx), f(kv), f(ka)
        A = mpmath.zeros(6, 6)
        A[0, 1], A[0, 2] = 1, -T
        A[1, 2], A[1, 3] = -1, 1
        A[2, 2], A[3, 3] = -1 / tau, -1 / tp
        A[2, 4], A[3, 5] = 1 / tau, 1 / tp
        E = mpmath.expm(A * H)
        Phi = E[0:4, 0:4]
        Gam = E[0:4, 4:6]
        Acl = Phi[0:3, 0:3] + Gam[0:3, 0] * mpmath.matrix([[kx, kv, 0]])
        z = mpmath.expj(f(theta))
        Ap = Gam[3, 1] / (z - Phi[3, 3])
        m = int(mpmath.floor(delta / H + f("1e-30")))
        s = H * (m + 1) - delta  # a_p(kH − δ) = a_p((k − m − 1)H + s)
        es = mpmath.expm(mpmath.matrix([[-1 / tp, 1 / tp], [0, 0]]) * s)
        D = z ** (-(m + 1)) * (es[0, 0] * Ap + es[0, 1])
        rhs = Phi[0:3, 3] * Ap + Gam[0:3, 1] + Gam[0:3, 0] * (ka * D)
        X = mpmath.lu_solve(z * mpmath.eye(3) - Acl, rhs)
        return float(abs(X[2] / Ap) ** 2 - 1)


def _psi3(kx, kv, ka):
    c = coefficients(kx, kv, ka, tau=TAU, delta=DELTA, headway=T)
    return float(c.b + c.cx)


def _just_below_psi3_zero(kv, ka, rel):
    x0 = brentq(lambda x: _psi3(x, kv, ka), 0.2, 2.0, xtol=1e-15)
    for x in (x0 * (1 + rel), x0 * (1 - rel)):
        if _psi3(x, kv, ka) < 0:
            return x
    raise AssertionError("no side with Ψ3 < 0")


def test_the_truth_agrees_with_the_direct_double_precision_response():
    # a check of the 60-digit truth itself, away from |H| = 1
    th = np.array([0.05, 0.7, 2.0])
    h = sampled_frequency.sampled_response(th, 0.9, -0.5, 1.1, tau=TAU, delta=DELTA, headway=T,
                                             sample_time=0.1)
    for t, v in zip(th, h):
        assert _excess_mp(t, 0.9, -0.5, 1.1, 0.1) == pytest.approx(abs(v) ** 2 - 1, rel=1e-9)


@pytest.mark.parametrize("H", [0.05, 0.1, 0.2])
@pytest.mark.parametrize("kv, ka, rel", [
    (1.3422768660010966, -0.8724886905418314, 1e-10),
    (0.9058944412494818, -0.5399709459657642, 1e-10),
    (0.3444922592509312, 0.21636200869307132, 1e-7),
    (0.4615404459250154, -0.46528978295246626, 1e-4),
])
def test_dc_margin_just_below_zero_reports_the_violation_near_zero(H, kv, ka, rel):
    kx = _just_below_psi3_zero(kv, ka, rel)
    c = ss.certify(kx, kv, ka, tau=TAU, delta=DELTA, headway=T, sample_time=H)
    if not (c.verdict == "not_certified" and c.schur):
        pytest.skip(f"not a not-certified Schur row at H = {H}: {c.verdict}, schur {c.schur}")
    assert 0 < c.peak_theta <= math.pi and c.peak_omega == pytest.approx(c.peak_theta / H)
    assert c.sup_gain >= 1.0 and c.sup_gain_excess > 0
    # direct evaluation: |H| > 1 at the reported θ, by the reported amount
    e2 = _excess_mp(c.peak_theta, kx, kv, ka, H)
    assert e2 > 0
    reported = c.sup_gain_excess * (2 + c.sup_gain_excess)  # (1 + e)² − 1
    assert reported == pytest.approx(e2, rel=1e-4)
    # and it is the peak: no larger excess on a log sweep a decade either side (60 digits)
    grid = np.minimum(c.peak_theta * np.logspace(-1, 1, 41), math.pi)
    assert max(_excess_mp(t, kx, kv, ka, H) for t in grid) <= e2 * (1 + 1e-4)


def test_every_not_certified_schur_row_reports_an_excess():
    k = np.random.default_rng(5).uniform(-2.0, 2.0, (3, 600))
    # and rows with Ψ3 just below 0, where sup|H| rounds to 1.0
    extra = [(_just_below_psi3_zero(kv, ka, 1e-10), kv, ka)
             for kv, ka in [(1.3422768660010966, -0.8724886905418314),
                            (0.9058944412494818, -0.5399709459657642)]]
    k = np.concatenate([k, np.array(extra).T], axis=1)
    for H in (0.1, 0.2):
        b = ss.certify_batch(*k, tau=TAU, delta=DELTA, headway=T, sample_time=H)
        ex = b.columns()["sup_gain_excess"]
        viol = (b.verdict == "not_certified") & b.schur
        assert viol.sum() > 50 and viol[-2:].all()
        assert (ex[viol] > 0).all() and (b.peak_theta[viol] > 0).all()
        assert (ex[b.verdict == "certified"] == 0).all()
        assert np.isinf(ex[~b.schur]).all()
        # where the excess is large, it is sup_gain − 1
        big = viol & (ex > 1e-3)
        assert np.allclose(ex[big], b.sup_gain[big] - 1, rtol=1e-9)
        assert (b.sup_gain[-2:] == 1.0).all()  # what a user read before: "at most 1"
        assert (ex[-2:] < 1e-15).all()
        i = int(np.flatnonzero(viol)[0])
        assert b[i].as_dict()["sup_gain_excess"] == pytest.approx(ex[i])


def test_the_table_shows_the_excess():
    assert "sup_gain_excess" in [c.key for c in sampled.TABLE_COLUMNS]


@pytest.mark.parametrize("H", [None, 0.1])
@pytest.mark.parametrize("kv, ka", [(1.3422768660010966, -0.8724886905418314),
                                    (0.9058944412494818, -0.5399709459657642)])
def test_robust_witness_reports_its_excess(H, kv, ka):
    """A box whose worst member has Ψ3 just below 0: the robust row reports the witness
    member's sup gain − 1 > 0 where it is attained (60-digit truth at that member)."""
    kx = _just_below_psi3_zero(kv, ka, 1e-10)
    r = ss.certify(kx, kv, ka, tau=(TAU, TAU * 1.001), delta=(DELTA, DELTA), headway=(T, T),
                   sample_time=H)
    assert r.verdict == "not_certified" and r.stable
    assert r.sup_gain_excess > 0 and r.witness_omega > 0
    reported = r.sup_gain_excess * (2 + r.sup_gain_excess)
    if H is None:
        from tests.certify.test_violation_peak import _excess_mp as continuous_excess_mp

        truth = continuous_excess_mp(r.witness_omega, kx, kv, ka, tau=r.witness_tau,
                                     delta=r.witness_delta, T=r.witness_headway)
    else:
        truth = _excess_mp(r.witness_theta, kx, kv, ka, H, tau=r.witness_tau,
                           delta=r.witness_delta, T=r.witness_headway,
                           tau_prev=r.witness_tau_prev)
    assert truth > 0 and reported == pytest.approx(truth, rel=1e-4)
    assert r.as_dict()["sup_gain_excess"] == pytest.approx(r.sup_gain_excess)


@pytest.mark.parametrize("H", [None, 0.1])
def test_every_not_certified_stable_robust_row_reports_an_excess(H):
    k = np.random.default_rng(8).uniform(-2.0, 2.0, (3, 150))
    b = ss.certify_batch(*k, tau=(0.1, 0.12), delta=(0.15, 0.2), headway=(1.0, 1.1),
                         sample_time=H)
    ex = b.columns()["sup_gain_excess"]
    viol = (b.verdict == "not_certified") & b.stable
    assert viol.sum() > 10
    assert (ex[viol] > 0).all() and (b.witness_omega[viol] > 0).all()
    assert (ex[b.verdict == "certified"] == 0).all()
    assert np.isinf(ex[(b.verdict == "not_certified") & ~b.stable]).all()
