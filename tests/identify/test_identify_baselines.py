"""The baselines beside the law (stringstab.identify.baselines): the lag-free closed-form
certificate against a fine frequency sweep of |Γ(jω)|, the IDM's linearisation against finite
differences of its acceleration, and both models' calibration against logs simulated here by
plain step-by-step loops (no noise: the fit must return the truth)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stringstab.identify import FollowerData
from stringstab.identify.baselines import (
    fit_idm,
    fit_ovrv,
    idm_linearisation,
    lag_free_certificate,
)
from stringstab.io.platoon_logs import Segment


def _sweep(k_x: float, k_v: float, T: float) -> float:
    w = np.geomspace(1e-4, 1e2, 40001)
    s = 1j * w
    return float(np.abs((k_v * s + k_x) / (s * s + (k_x * T + k_v) * s + k_x)).max())


def test_lag_free_certificate_against_a_frequency_sweep() -> None:
    """300 random (k_x, k_v, T*): the closed form's sup|Γ| equals the sweep's (the sweep on a
    grid of 40,001 frequencies may only fall short of it, by at most 0.1 %), and its verdict is
    the sweep's side of 1 wherever the criterion is not within 1e-3 of 0."""
    rng = np.random.default_rng(3)
    decided = 0
    for _ in range(300):
        k_x, k_v, T = rng.uniform(0.01, 1.0), rng.uniform(-0.2, 1.5), rng.uniform(0.0, 3.0)
        verdict, sup, _ = lag_free_certificate(k_x, k_v, T)
        if k_x * T + k_v <= 0:
            assert verdict.value == "not_certified" and math.isinf(sup)
            continue
        swept = _sweep(k_x, k_v, T)
        assert swept <= sup * (1 + 1e-9)
        assert swept >= sup * (1 - 1e-3)
        g = k_x * T * T + 2 * k_v * T - 2
        if abs(g) > 1e-3:
            decided += 1
            assert verdict.value == ("certified" if g > 0 else "not_certified")
            assert (swept <= 1 + 1e-9) == (g > 0)
    assert decided > 200


def _idm_acc(p: dict[str, float], s: float, v: float, vp: float) -> float:
    star = p["s0"] + max(0.0, v * p["T"] + v * (v - vp) / (2 * math.sqrt(p["a"] * p["b"])))
    return p["a"] * (1 - (v / p["v0"]) ** 4 - (star / s) ** 2)


def test_idm_linearisation_against_finite_differences() -> None:
    p = {"v0": 30.0, "T": 1.4, "s0": 2.5, "a": 1.2, "b": 2.0}
    v_e = 14.0
    k_x, k_v, T = idm_linearisation(p, v_e)  # type: ignore[misc]
    s_e = (p["s0"] + v_e * p["T"]) / math.sqrt(1 - (v_e / p["v0"]) ** 4)
    assert _idm_acc(p, s_e, v_e, v_e) == pytest.approx(0.0, abs=1e-12)  # an equilibrium
    h = 1e-5
    f_s = (_idm_acc(p, s_e + h, v_e, v_e) - _idm_acc(p, s_e - h, v_e, v_e)) / (2 * h)
    # d/dv with v_p - v held: v and v_p move together
    f_v = (_idm_acc(p, s_e, v_e + h, v_e + h) - _idm_acc(p, s_e, v_e - h, v_e - h)) / (2 * h)
    # d/d(v_p - v) at fixed v: move v_p (one-sided: the max(0, .) kink is at v_p far above v_e)
    f_d = (_idm_acc(p, s_e, v_e, v_e + h) - _idm_acc(p, s_e, v_e, v_e - h)) / (2 * h)
    assert k_x == pytest.approx(f_s, rel=1e-6)
    assert k_v == pytest.approx(f_d, rel=1e-6)
    assert T == pytest.approx(-f_v / f_s, rel=1e-6)
    assert idm_linearisation(p, 31.0) is None  # no equilibrium above v0


def _leader(n: int, dt: float) -> np.ndarray:
    t = np.arange(n) * dt
    return 14 + 3 * np.sin(2 * np.pi * t / 60) + 1.5 * np.sin(0.45 * t) + 0.8 * np.sin(1.1 * t + 1)


def _data(vp: np.ndarray, v: np.ndarray, gap: np.ndarray, dt: float) -> FollowerData:
    return FollowerData(vp, v, gap, None, (Segment(0, vp.size),), dt)


def test_ovrv_recovers_a_lag_free_follower() -> None:
    dt, n = 0.1, 1800
    vp = _leader(n, dt)
    k1, k2, th, eta = 0.15, 0.45, 1.3, 3.5
    s, v = eta + th * vp[0], vp[0]
    gap, speed = np.empty(n), np.empty(n)
    for k in range(n):  # the command held over the step (ballistic), plain floats
        gap[k], speed[k] = s, v
        if k < n - 1:
            u = k1 * (s - eta - th * v) + k2 * (vp[k] - v)
            s += 0.5 * dt * (vp[k] + vp[k + 1]) - dt * v - 0.5 * dt * dt * u
            v += dt * u
    b = fit_ovrv(_data(vp, speed, gap, dt))
    for key, want in (("k1", k1), ("k2", k2), ("tau_h", th), ("eta", eta)):
        assert b.params[key] == pytest.approx(want, rel=1e-3)
    # from the measured initial state (a straight line through the first 2 s, not the truth)
    assert b.rmse_speed < 0.02 and b.rmse_gap < 0.05
    assert b.verdict == lag_free_certificate(k1, k2, th)[0]


def test_idm_recovers_an_idm_follower() -> None:
    """A noise-free IDM log (2.5 min, a plain loop): the fit reproduces it (RMSE < 1 cm/s) and
    its linearisation's verdict and sup|Γ| are the truth's (v_0 is weakly determined when the
    car never nears it, so the parameters themselves are checked loosely)."""
    dt, n = 0.1, 1500
    vp = _leader(n, dt)
    p = {"v0": 25.0, "T": 1.2, "s0": 3.0, "a": 1.5, "b": 2.0}
    s_e = (p["s0"] + vp[0] * p["T"]) / math.sqrt(1 - (vp[0] / p["v0"]) ** 4)
    s, v = s_e, vp[0]
    gap, speed = np.empty(n), np.empty(n)
    for k in range(n):
        gap[k], speed[k] = s, v
        if k < n - 1:
            acc = _idm_acc(p, s, v, vp[k])
            vn = max(v + acc * dt, 0.0)
            s += 0.5 * dt * (vp[k] + vp[k + 1]) - 0.5 * (v + vn) * dt
            v = vn
    b = fit_idm(_data(vp, speed, gap, dt))
    assert b.rmse_speed < 0.01 and b.rmse_gap < 0.05
    assert b.params["T"] == pytest.approx(p["T"], rel=0.1)
    assert b.params["s0"] == pytest.approx(p["s0"], abs=0.5)
    v_e = float(np.median(speed))
    want = lag_free_certificate(*idm_linearisation(p, v_e))  # type: ignore[misc]
    assert b.verdict == want[0]
    assert b.sup_gain == pytest.approx(want[1], rel=0.02)
