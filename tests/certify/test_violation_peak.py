"""Issue 21, item 5: a not-certified row's numbers agree with its verdict.

sup|Γ| > 1 (or, when the violation is below double precision, sup|Γ| − 1 > 0) at the frequency
where it is exceeded — also when Ψ3 is just below 0 and the violation sits near ω = 0 —
checked against an independent truth: Γ(jω) evaluated directly in 60-digit arithmetic (mpmath)
from the transfer function, not from the margin g the certificate uses.
"""

import mpmath
import numpy as np
import pytest
from scipy.optimize import brentq

import stringstab as ss
from stringstab.certify.frequency import gain_squared
from stringstab.certify.margin import coefficients
from stringstab.certify.zoh import split_delay

TAU, DELTA, T = 0.1, 0.2, 1.1
mpmath.mp.dps = 60


def _excess_mp(w, kx, kv, ka, tau=TAU, delta=DELTA, T=T):
    """|Γ(jω)|² − 1 in 60 digits, from Γ = (k_x + k_v s + k_a s² e^{−δs}) / (τs³ + s² + (k_v + T*k_x)s + k_x)."""
    s = mpmath.mpc(0, mpmath.mpf(w))
    kx, kv, ka = (mpmath.mpf(k) for k in (kx, kv, ka))
    num = kx + kv * s + ka * s**2 * mpmath.exp(-mpmath.mpf(delta) * s)
    den = mpmath.mpf(tau) * s**3 + s**2 + (kv + mpmath.mpf(T) * kx) * s + kx
    return float(abs(num / den) ** 2 - 1)


def _psi3(kx, kv, ka):
    c = coefficients(kx, kv, ka, tau=TAU, delta=DELTA, headway=T)
    return float(c.b + c.cx)


def _just_below_psi3_zero(kv, ka, rel):
    """k_x with Ψ3(k_x, k_v, k_a) just below 0 (a relative step ``rel`` past the root)."""
    x0 = brentq(lambda x: _psi3(x, kv, ka), 0.2, 2.0, xtol=1e-15)
    for x in (x0 * (1 + rel), x0 * (1 - rel)):
        if _psi3(x, kv, ka) < 0:
            return x
    raise AssertionError("no side with Ψ3 < 0")


@pytest.mark.parametrize("kv, ka, rel", [
    (0.4615404459250154, -0.46528978295246626, 1e-10),
    (0.3444922592509312, 0.21636200869307132, 1e-10),
    (1.1027647524073134, -0.764570549122956, 1e-7),
    (0.4615404459250154, -0.46528978295246626, 1e-4),
])
def test_psi3_just_below_zero_reports_the_violation_near_zero(kv, ka, rel):
    kx = _just_below_psi3_zero(kv, ka, rel)
    psi3 = _psi3(kx, kv, ka)
    assert psi3 < 0
    c = ss.certify(kx, kv, ka, tau=TAU, delta=DELTA, headway=T)
    assert c.verdict == "not_certified" and c.hurwitz and c.type == "III"
    assert c.peak_omega > 0 and c.sup_gain >= 1.0 and c.sup_gain_excess > 0
    # direct evaluation: |Γ| > 1 at the reported frequency, by the reported amount
    e2 = _excess_mp(c.peak_omega, kx, kv, ka)
    assert e2 > 0
    reported = c.sup_gain_excess * (2 + c.sup_gain_excess)  # (1 + e)² − 1
    assert reported == pytest.approx(e2, rel=1e-6)
    # and it is the peak: no larger excess on a log sweep a decade either side (60 digits)
    sweep = [_excess_mp(w, kx, kv, ka) for w in c.peak_omega * np.logspace(-1, 1, 81)]
    assert max(sweep) <= e2 * (1 + 1e-6)
    # small-ω expansion: |Γ|² − 1 ≈ −Ψ3 ω²/k_x² (its leading term) where ω is well below the peak
    w = c.peak_omega * 1e-3
    assert _excess_mp(w, kx, kv, ka) == pytest.approx(-psi3 * w * w / kx**2, rel=1e-3)


@pytest.mark.parametrize("kx, kv, ka", [
    (1.5532784944662756, -0.07701199229574218, 0.14497970227924606),
    (1.3304562740313015, 0.5738898165441055, -0.43620484406794624),
])
def test_a_rounded_direct_excess_does_not_replace_the_computed_one(kx, kv, ka):
    # |Γ| − 1 from the direct search was 2.2e-16 (round-off) at an ω where the truth is ≤ 1e-20
    # (once even negative); the excess computed without cancellation is the one reported
    c = ss.certify(kx, kv, ka, tau=TAU, delta=DELTA, headway=T)
    assert c.verdict == "not_certified" and c.hurwitz and _psi3(kx, kv, ka) < 0
    e2 = _excess_mp(c.peak_omega, kx, kv, ka)
    assert e2 > 0 and c.sup_gain_excess * (2 + c.sup_gain_excess) == pytest.approx(e2, rel=1e-4)


def test_a_violation_away_from_zero_matches_a_fine_sweep():
    c = ss.certify(0.9, -0.5, 1.1, tau=TAU, delta=DELTA, headway=T)
    W = np.linspace(1e-4, 20.0, 400_001)
    direct = np.sqrt(gain_squared(W, 0.9, -0.5, 1.1, tau=TAU, delta=DELTA, headway=T))
    assert c.sup_gain == pytest.approx(float(direct.max()), abs=1e-8)
    assert c.sup_gain_excess == pytest.approx(c.sup_gain - 1, rel=1e-9)
    assert c.peak_omega == pytest.approx(float(W[np.argmax(direct)]), abs=1e-3)


def test_batch_columns_and_table_carry_the_excess():
    b = ss.certify_batch([1.2, 0.9, 1.0], [0.5, -0.5, -3.0], [0.6, 1.1, 0.0],
                         tau=TAU, delta=DELTA, headway=T)
    ex = b.columns()["sup_gain_excess"]
    assert ex[0] == 0.0 and ex[1] > 0.04 and np.isinf(ex[2])
    assert b[1].as_dict()["sup_gain_excess"] == pytest.approx(ex[1])


def test_split_delay_rounds_to_the_nearest_whole_sample():
    assert split_delay(0.3, 0.1) == (3, 0.0)
    assert split_delay(0.7, 0.1) == (7, 0.0)
    assert split_delay(0.25, 0.1) == (2, pytest.approx(0.5))
    assert split_delay(0.3 - 1e-6, 0.1) == (2, pytest.approx(0.99999))  # a real fraction stays
    # the box ends of the robust certificate keep the exact split (they must be covered)
    assert split_delay(0.3, 0.1, whole=False)[0] == 2


def test_sampled_certificate_of_three_samples_is_the_same_however_0_3_is_written():
    a = ss.certify(1.2, 0.5, 0.6, tau=TAU, delta=0.3, headway=T, sample_time=0.1)
    b = ss.certify(1.2, 0.5, 0.6, tau=TAU, delta=3 * 0.1, headway=T, sample_time=0.1)
    assert 3 * 0.1 != 0.3
    assert (a.verdict, a.sup_gain) == (b.verdict, b.sup_gain)
