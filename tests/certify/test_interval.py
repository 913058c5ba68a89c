"""The interval arithmetic of the sampled certificates encloses what it claims to enclose.

Checked against members drawn at random (the independent truth: plain floating point at a
point), with the round-off slack the certificates use (10⁻¹³ × the magnitude companion):

* :class:`~stringstab.certify.interval.Interval`: x ∘ y of members lies in a ∘ b;
* :func:`~stringstab.certify.zoh.cell_coefficients` (derivative enclosures over a cell of
  τ, τ_p, ε, T*): every coefficient of the loop at a member of the cell, computed at that
  point by :func:`~stringstab.certify.zoh.coefficients`, lies in the enclosure over the cell
  and in the mean-value form c + Σ_i ∂_i (p_i − c_i).
"""

from __future__ import annotations

import numpy as np
import pytest

from stringstab.certify.interval import Interval, IntervalAD, interval, poly_add, poly_scale
from stringstab.certify.zoh import cell_coefficients, coefficients

SLACK = 1e-13


def _inside(x, iv: Interval) -> np.ndarray:
    tol = SLACK * iv.mag + 1e-300
    return (x >= iv.lo - tol) & (x <= iv.hi + tol)


def test_interval_operations_enclose_their_members():
    rng = np.random.default_rng(0)
    n = 20_000
    lo_a, lo_b = rng.normal(0, 3, n), rng.normal(0, 3, n)
    a = Interval(lo_a, lo_a + rng.exponential(1.0, n))
    b = Interval(lo_b, lo_b + rng.exponential(1.0, n))
    x = a.lo + rng.random(n) * (a.hi - a.lo)
    y = b.lo + rng.random(n) * (b.hi - b.lo)
    for got, want in ((a + b, x + y), (a - b, x - y), (a * b, x * y), (2.5 - a * b + a, 2.5 - x * y + x),
                      (-(a * a * b), -(x * x * y))):
        assert _inside(want, got).all()
    # the enclosure is tight at the ends: some member comes close to each end of a * b
    p = a * b
    assert np.all(p.lo <= p.hi) and np.any(np.isclose(p.lo, np.minimum(a.lo * b.lo, a.hi * b.lo)))


def test_points_stay_points_and_take_keeps_rows():
    v = np.array([1.0, -2.0, 3.0])
    p = interval(v, v)
    assert p.point and (p * p + 1.0).point
    q = interval(v, v + 1.0)
    assert not q.point and not (p * q).point
    idx = np.array([2, 0])
    t = (p * q).take(idx)
    assert np.array_equal(t.lo, (p * q).lo[idx]) and np.array_equal(t.hi, (p * q).hi[idx])
    # polynomials: (1 + 2ρ) − (3 + 0ρ + ρ²) = −2 + 2ρ − ρ²
    one = p.const(1.0)
    s = poly_add([one, one * 2.0], [one * 3.0, one * 0.0, one], -1.0)
    assert [float(c.lo[0]) for c in s] == [-2.0, 2.0, -1.0]
    assert [float(c.lo[1]) for c in poly_scale(p, [one])] == [-2.0]


def test_mean_value_form_of_a_product_encloses_members():
    rng = np.random.default_rng(1)
    n = 5000
    lo = rng.uniform(0.5, 2.0, (n, 2))
    hi = lo + rng.uniform(0.0, 0.3, (n, 2))
    X = IntervalAD.variable(lo[:, 0], hi[:, 0], 0, 2)
    Y = IntervalAD.variable(lo[:, 1], hi[:, 1], 1, 2)
    f = X * X * Y - 3.0 * Y + 1.0
    u = lo + rng.random((n, 2)) * (hi - lo)
    truth = u[:, 0] ** 2 * u[:, 1] - 3.0 * u[:, 1] + 1.0
    assert _inside(truth, f.r).all()
    centre = 0.5 * (lo + hi)
    mv_lo = f.c.lo + sum(np.minimum(g.lo * (u[:, i] - centre[:, i]), g.hi * (u[:, i] - centre[:, i]))
                         for i, g in enumerate(f.g))
    mv_hi = f.c.lo + sum(np.maximum(g.lo * (u[:, i] - centre[:, i]), g.hi * (u[:, i] - centre[:, i]))
                         for i, g in enumerate(f.g))
    tol = 1e-12 * (np.abs(truth) + 1.0)
    assert np.all(truth >= mv_lo - tol) and np.all(truth <= mv_hi + tol)


@pytest.mark.parametrize("heterogeneous", [True, False])
def test_cell_coefficients_enclose_the_point_coefficients_of_members(heterogeneous):
    rng = np.random.default_rng(2 + heterogeneous)
    n, H = 400, 0.1
    kx, kv, ka = rng.uniform(-2, 2, n), rng.uniform(-2, 2, n), rng.uniform(-2, 2, n)

    def cell(a, b, w):
        lo = rng.uniform(a, b, n)
        return np.stack([lo, lo + rng.uniform(0.0, w, n)], axis=1)

    tau, eps, hw = cell(0.05, 0.4, 0.05), cell(0.0, 0.9, 0.1), cell(0.3, 2.0, 0.3)
    tau_p = cell(0.05, 0.4, 0.05) if heterogeneous else None
    co = cell_coefficients(kx, kv, ka, H=H, tau=tau, tau_p=tau_p, eps=eps, headway=hw)
    cells = [tau] + ([tau_p] if heterogeneous else []) + [eps, hw]
    for _ in range(3):
        u = [c[:, 0] + rng.random(n) * (c[:, 1] - c[:, 0]) for c in cells]
        t, e, h = u[0], u[-2], u[-1]
        tp = u[1] if heterogeneous else t
        c = kv + h * kx
        pt = coefficients(kx, kv, ka, H=H, tau=(t, t), tau_p=(tp, tp), eps=(e, e), c=(c, c))
        for enc, val in zip([*co.delta, *co.nu, *co.ell, co.phi1, co.phi1p, *co.P, *co.Yr, *co.Yi],
                            [*pt.delta, *pt.nu, *pt.ell, pt.phi1, pt.phi1p, *pt.P, *pt.Yr, *pt.Yi]):
            x = val.lo
            tol = 1e-12 * (val.mag + enc.r.mag) + 1e-300
            assert np.all((x >= enc.r.lo - tol) & (x <= enc.r.hi + tol))
            d = [ui - 0.5 * (ci[:, 0] + ci[:, 1]) for ui, ci in zip(u, cells)]
            lo = enc.c.lo + sum(np.minimum(g.lo * di, g.hi * di) for g, di in zip(enc.g, d))
            hi = enc.c.lo + sum(np.maximum(g.lo * di, g.hi * di) for g, di in zip(enc.g, d))
            tol = tol + 1e-12 * sum(g.mag * np.abs(di) for g, di in zip(enc.g, d))
            assert np.all((x >= lo - tol) & (x <= hi + tol))
