"""stringstab identify: the closed-loop recursion against the simulator, recovery of known
parameters from logs made by the toolkit's own platoon simulator (GPS-like noise, dropouts),
the verdict wording, the bootstrap and the empirical transfer.

Recovery tolerances (stated once, checked below): k_x within 15 % of the truth, k_v within 15 %
(stable car) and 35 % (unstable car), τ within 25 %, T* within 0.15 s, l_0 within 1.5 m, the fitted sup|Γ| within 5 % of the true one, and the
certificate of the fit equal to the certificate of the truth, for a string-stable and a
string-unstable car, from 4 min of 10 Hz data with speed noise σ = 0.05 m/s, gap noise
σ = 0.2 m and two 1.5-s dropouts.  The unstable car's k_v and τ trade off under the noise on
its predecessor's measured speed (the input of the simulation: errors in variables); over seeds
1-4 its k_v fell in 0.18-0.25 (truth 0.2) and τ in 0.56-0.71 s (truth 0.6) while its sup|Γ|
stayed within 1 % of the truth, and the fits' RMSE equalled the noise added (0.05 m/s, 0.20 m).
"""

from __future__ import annotations

import numpy as np
import pytest

import stringstab as ss
from stringstab.identify import (
    FollowerData,
    FollowerModel,
    PlatoonLog,
    clean_segments,
    empirical_transfer,
    fit_follower,
    identify,
    simulate_follower,
    statement,
)
from stringstab.traffic import LinearController, from_speed, simulate, sinusoid

#: (k_x, k_v, τ) of the two followers; T* = 1.5 s and l_0 = 4 m for both.
STABLE = (0.2, 0.7, 0.3)
UNSTABLE = (0.3, 0.2, 0.6)
HEADWAY, STANDSTILL = 1.5, 4.0


def _leader(duration: float = 240.0, dt: float = 0.1):
    t = np.arange(0.0, duration + dt / 2, dt)
    v = 15 + 4 * np.sin(2 * np.pi * t / 90) + 1.2 * np.sin(0.5 * t) + 0.6 * np.sin(1.3 * t + 1)
    return from_speed(t, v, dt=dt)


def _log(noise: bool = True, seed: int = 1) -> PlatoonLog:
    """Leader + stable car + unstable car from :func:`stringstab.traffic.simulate`, with noise
    and dropouts; the truth is in ``meta``."""
    lead = _leader()
    c = LinearController([STABLE[0], UNSTABLE[0]], [STABLE[1], UNSTABLE[1]], [0.0, 0.0],
                         headway=HEADWAY, standstill=STANDSTILL)
    r = simulate(lead, c, 2, tau=np.array([STABLE[2], UNSTABLE[2]]), delta=0.0)
    assert not r.collided.any()
    rng = np.random.default_rng(seed)
    speed = r.speed.copy()
    gap = r.gap.copy()
    if noise:
        speed += rng.normal(0, 0.05, speed.shape)
        gap += rng.normal(0, 0.2, gap.shape)
        speed[1, 700:715] = np.nan  # GPS dropouts of 1.5 s
        gap[1, 1500:1515] = np.nan
    return PlatoonLog(r.t, (0, 1, 2), ("lead", "stable", "unstable"), speed,
                      {1: gap[0], 2: gap[1]}, None, "<simulated>", "csv", {})


def test_closed_loop_matches_the_simulator() -> None:
    """The lfilter recursion equals stringstab.traffic.simulate on the same predecessor
    (independent code path: the simulator's step-by-step Platoon), with and without k_a and a
    fractional delay."""
    lead = sinusoid(omega=0.5, duration=60.0)
    for k_a, delta in ((0.0, 0.2), (0.4, 0.25)):
        c = LinearController(0.3, 0.6, k_a, headway=1.4, standstill=3.0)
        r = simulate(lead, c, 1, tau=0.4, delta=delta)
        m = FollowerModel(0.3, 0.6, k_a, 0.4, delta, 1.4, 3.0)
        g, v = simulate_follower(m, lead.speed, lead.dt, s0=float(r.gap[0, 0]), v0=float(r.speed[1, 0]),
                                 a_pred=lead.accel, x_pred=lead.position)
        assert np.abs(g - r.gap[0]).max() < 1e-8
        assert np.abs(v - r.speed[1]).max() < 1e-8
        # without the position, the trapezoid of the predecessor's speed is its displacement
        # (exact for piecewise-constant a; a sinusoid leader: within a millimetre here)
        g2, _ = simulate_follower(m, lead.speed, lead.dt, s0=float(r.gap[0, 0]), v0=float(r.speed[1, 0]),
                                  a_pred=lead.accel)
        assert np.abs(g2 - r.gap[0]).max() < 1e-3


@pytest.mark.parametrize(("position", "truth"), [(1, STABLE), (2, UNSTABLE)])
def test_recovers_known_parameters(position: int, truth: tuple[float, float, float]) -> None:
    log = _log()
    segs = clean_segments(log, position)
    # dropouts split the record (the predecessor's too); nothing is interpolated
    assert [(x.start, x.stop) for x in segs] == (
        [(0, 700), (715, 2401)] if position == 1 else [(0, 700), (715, 1500), (1515, 2401)])
    vp, v, g, _ = log.pair(position)
    fit = fit_follower(FollowerData(vp, v, g, None, tuple(segs), log.dt), "acc", n_starts=2)
    p = fit.params
    kx, kv, tau = truth
    assert p["k_x"] == pytest.approx(kx, rel=0.15)
    assert p["k_v"] == pytest.approx(kv, rel=0.15 if truth is STABLE else 0.35)
    assert p["tau"] == pytest.approx(tau, rel=0.25)
    assert p["headway"] == pytest.approx(HEADWAY, abs=0.15)
    assert p["standstill"] == pytest.approx(STANDSTILL, abs=1.5)
    assert p["k_a"] == 0.0
    assert fit.rmse_speed < 0.1 and fit.rmse_gap < 0.5  # about the noise added
    assert not fit.at_bound
    true_c = ss.certify(kx, kv, 0.0, tau=tau, delta=0.0, headway=HEADWAY)
    fit_c = ss.certify(p["k_x"], p["k_v"], 0.0, tau=p["tau"], delta=0.0, headway=p["headway"])
    assert fit_c.verdict == true_c.verdict == ("certified" if truth is STABLE else "not_certified")
    assert fit_c.sup_gain == pytest.approx(true_c.sup_gain, rel=0.05)


def test_identify_bootstrap_and_verdicts() -> None:
    """A few bootstrap fits: the stable car is certified in every one, the unstable car in none,
    and the data's own transfer agrees with the model's side of 1."""
    res = identify(_log(), bootstrap=4, n_starts=1, progress=False)
    stable, unstable = res.vehicles
    assert [v.position for v in res.vehicles] == [1, 2]
    assert stable.certificate.verdict == "certified"
    assert stable.statement() == "string stable in 4 of 4 bootstrap fits"
    assert unstable.statement() == "not string stable in 4 of 4 bootstrap fits"
    assert unstable.box is not None and unstable.box.verdict == "not_certified"
    lo, hi = unstable.interval("k_x")
    assert lo <= UNSTABLE[0] * 1.15 and hi >= UNSTABLE[0] * 0.85
    # the measured transfer: at most ~1 for the stable car, above 1 for the unstable one
    assert unstable.empirical.gain > 1.05
    assert stable.empirical.gain < 1.05
    # ... beyond the estimate's random error (±2ε) for the unstable car, never above for the stable
    assert unstable.empirical.amplifies == "yes"
    assert stable.empirical.amplifies != "yes"
    assert any(n.startswith("model and data agree") for n in unstable.notes)
    doc = res.document()
    need = {"position", "name", "k_x", "k_v", "k_a", "tau", "delta", "headway", "standstill",
            "rmse_speed", "rmse_gap", "sup_gain", "peak_omega", "verdict", "certified_share",
            "empirical_gain", "segments"}
    assert need <= set(doc["vehicles"][0])
    assert doc["vehicles"][1]["segments"][0]["start"] == 0


def test_empirical_transfer_of_a_known_filter() -> None:
    """|Ĝ| of a noiseless first-order follower against the exact |Γ(jω)| (k_x = 0 law
    replaced by a direct filter: y = lowpass(x)), where coherent."""
    from scipy.signal import lfilter

    rng = np.random.default_rng(0)
    dt = 0.1
    x = np.cumsum(rng.normal(0, 0.05, 6000)) * 0.1 + 15
    a = np.exp(-dt / 2.0)
    y = lfilter([1 - a], [1, -a], x - 15, zi=[0.0 * a])[0] + 15
    from stringstab.io.platoon_logs import Segment

    e = empirical_transfer(x, y, [Segment(0, 6000)], dt, nperseg=512)
    z = np.exp(1j * e.omega * dt)
    exact = np.abs((1 - a) / (1 - a / z))
    m = (e.omega > 0.2) & (e.omega < 1.0)  # the lowest bins leak (a random walk input)
    assert np.allclose(np.abs(e.transfer[m]), exact[m], rtol=0.05)
    assert e.gain <= 1.0 + 0.05


def test_statement_wording() -> None:
    assert statement("not_certified", ["not_certified"] * 200) == "not string stable in 200 of 200 bootstrap fits"
    assert statement("certified", ["certified"] * 61 + ["not_certified"] * 39) == "inconclusive: 61 % of fits certified"
    assert statement("certified", ["certified"] * 3, ["tau"]).endswith("(fit at the bound of tau)")


def test_identify_refuses_a_log_without_usable_segment() -> None:
    log = _log(noise=False)
    speed = log.speed.copy()
    speed[1, ::100] = np.nan  # a two-sample dropout every 10 s: no clean segment of 30 s
    speed[1, 1::100] = np.nan
    speed[2, ::100] = np.nan
    speed[2, 1::100] = np.nan
    bad = PlatoonLog(log.t, log.positions, log.names, speed, log.gap, None, "<x>", "csv", {})
    with pytest.raises(ss.StringStabError, match="no follower has a usable segment"):
        identify(bad, bootstrap=0, progress=False)


def test_single_missing_samples_are_bridged() -> None:
    """One missing sample every 10 s (in the speeds and the gap) is bridged, stated, and the
    fit is the clean log's: the car is identified, not dropped (issue 28, robustness)."""
    log = _log(noise=False)
    speed, gap2 = log.speed.copy(), log.gap[2].copy()
    speed[1, 50::100] = np.nan
    gap2[70::100] = np.nan
    holed = PlatoonLog(log.t, log.positions, log.names, speed, {1: log.gap[1], 2: gap2}, None, "<x>",
                       "csv", {})
    res = identify(holed, bootstrap=0, n_starts=1, progress=False)
    assert [v.position for v in res.vehicles] == [1, 2]
    unstable = res.vehicles[1]
    assert [(x.start, x.stop) for x in unstable.segments] == [(0, log.t.size)]
    assert any("single missing samples bridged" in n for n in unstable.notes)
    ref = fit_follower(FollowerData(*log.pair(2)[:3], None, tuple(clean_segments(log, 2)), log.dt), "acc",
                       n_starts=1)
    for k in ("k_x", "k_v", "tau", "headway"):
        assert unstable.fit.params[k] == pytest.approx(ref.params[k], rel=0.02)


def test_cacc_recovers_k_a_and_delta() -> None:
    """--model cacc: k_a and δ from a log with the predecessor's acceleration (noise-free, 3 min):
    k_a within 10 %, δ within 0.05 s, the certificate of the fit equal to the truth's."""
    lead = _leader(180.0)
    truth = dict(k_x=0.25, k_v=0.5, k_a=0.6, tau=0.4, delta=0.3)
    c = LinearController(truth["k_x"], truth["k_v"], truth["k_a"], headway=1.2, standstill=3.0)
    r = simulate(lead, c, 1, tau=truth["tau"], delta=truth["delta"])
    log = PlatoonLog(r.t, (0, 1), ("lead", "cacc"), r.speed, {1: r.gap[0]}, r.accel, "<sim>", "csv", {})
    vp, v, g, ap = log.pair(1)
    fit = fit_follower(FollowerData(vp, v, g, ap, tuple(clean_segments(log, 1)), log.dt), "cacc", n_starts=2)
    p = fit.params
    assert p["k_a"] == pytest.approx(truth["k_a"], rel=0.10)
    assert p["delta"] == pytest.approx(truth["delta"], abs=0.05)
    assert p["k_x"] == pytest.approx(truth["k_x"], rel=0.10)
    want = ss.certify(truth["k_x"], truth["k_v"], truth["k_a"], tau=truth["tau"], delta=truth["delta"], headway=1.2)
    got = ss.certify(p["k_x"], p["k_v"], p["k_a"], tau=p["tau"], delta=p["delta"], headway=p["headway"])
    assert got.verdict == want.verdict
    assert got.sup_gain == pytest.approx(want.sup_gain, rel=0.05)


def test_single_threaded_blas_restores_the_thread_count() -> None:
    import scipy.optimize  # noqa: F401  (loads SciPy's OpenBLAS too)

    from stringstab.identify.blas import _libraries, single_threaded_blas

    libs = _libraries()
    if not libs:
        pytest.skip("no OpenBLAS library found in this process")
    before = [g() for g, _ in libs]
    with single_threaded_blas():
        assert [g() for g, _ in libs] == [1] * len(libs)
    assert [g() for g, _ in libs] == before
