"""The sampled point check's cheaper fixed cost (issue 31): the same bits as the generic path.

:class:`stringstab.certify.interval.Point` stacks a point's value and magnitude in one array,
:mod:`stringstab.certify.point_program` replays a recorded ``zoh.build``, and the branch and
bound of :func:`stringstab.certify.sampled.check_kernel` evaluates g_H and its curvature bound
from one stack of the coefficients with the initial grid's terms computed once per loop.
Each is meant to compute the same floating-point numbers as the code it replaces; the truth
here is that code itself: :class:`~stringstab.certify.interval.Interval` points, the
coefficients built row by row by :func:`stringstab.certify.zoh.coefficients` (its own
primitives, no recording), and :func:`stringstab.certify.sampled.check_members` (the
generic evaluator on those coefficients).  Compared bit for bit (``view(np.uint64)``).
"""

from __future__ import annotations

import numpy as np
import pytest

from stringstab.certify import zoh
from stringstab.certify.api import Loop
from stringstab.certify.interval import Interval, Point
from stringstab.certify.sampled import check_members
from stringstab.params import Params

#: Loops: δ a whole number of samples and not, τ_p ≠ τ, H > τ (the lag integrals' direct
#: forms), a short delay (m = 0).
LOOPS = [dict(tau=0.1, delta=0.2, headway=1.1, sample_time=0.1, tau_prev=0.1),
         dict(tau=0.15, delta=0.23, headway=1.0, sample_time=0.05, tau_prev=0.2),
         dict(tau=0.1, delta=0.05, headway=0.5, sample_time=0.4, tau_prev=0.1),
         dict(tau=0.3, delta=0.0, headway=2.0, sample_time=0.1, tau_prev=0.25)]


def _bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(np.asarray(a, dtype=np.float64)).view(np.uint64)


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    a, b = np.broadcast_arrays(np.asarray(a, dtype=float), np.asarray(b, dtype=float))
    return bool(np.array_equal(_bits(a), _bits(b)))


def _gains(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    K = rng.uniform(-2.0, 2.0, (n, 3))
    K[: n // 4] = np.array([1.14, 1.03, 0.4]) + rng.normal(0.0, 0.3, (n // 4, 3))  # near |H| = 1
    K[-3:] = [[0.0, 0.0, 0.0], [-0.0, 1.0, -1.0], [2.0, -2.0, 2.0]]
    return K


def test_point_arithmetic_is_the_interval_point_arithmetic_bit_for_bit():
    rng = np.random.default_rng(0)
    a, b = rng.normal(0, 3, 7), rng.normal(0, 3, 7)
    a[0], b[1] = 0.0, -0.0
    A, B = Interval(a), Interval(b)
    P, Q = Point.of(a), Point.of(b)
    cases = [(A * B, P * Q), (A + B, P + Q), (A - B, P - Q), (-A, -P), (2.5 * A, 2.5 * P),
             (A * -0.75, P * -0.75), (8.0 - A, 8.0 - P), (A - 3.0, P - 3.0), (1.5 + A, 1.5 + P),
             (A * np.float64(0.3), P * np.float64(0.3)), (A * b, P * b), (A.const(1.0), P.const(1.0)),
             (A.const(-2.0), P.const(-2.0)), (A.take(np.array([3, 0])), P.take(np.array([3, 0]))),
             ((A * B - 2.0 * A) * (8.0 - B), (P * Q - 2.0 * P) * (8.0 - Q))]
    for want, got in cases:
        assert type(got) is Point and got.point and got.hi is got.lo
        assert _same(want.lo, got.lo) and _same(want.mag, got.mag)
    # with an interval of width > 0 a point takes Interval's own paths (operands commute)
    W = Interval(a - 1.0, a + 1.0)
    for want, got in [(W * A, W * P), (A * W, P * W), (W + A, W + P), (A - W, P - W)]:
        assert _same(want.lo, got.lo) and _same(want.hi, got.hi) and _same(want.mag, got.mag)


@pytest.mark.parametrize("loop", LOOPS, ids=range(len(LOOPS)))
def test_recorded_build_gives_the_coefficients_of_the_row_by_row_build(loop):
    K = _gains(97, 1)
    kx, kv, ka = (np.ascontiguousarray(K[:, j]) for j in range(3))
    p = Params(loop["tau"], loop["delta"], loop["headway"])
    H, tp = loop["sample_time"], loop["tau_prev"]
    co, m = zoh.point_coefficients(kx, kv, ka, p, H, tp)
    m2, eps = zoh.split_delay(p.delta, H)
    n = kx.size
    full = lambda v: np.full(n, float(v))  # noqa: E731 - one array per parameter: points
    t, t_p, e = full(p.tau), full(tp), full(eps)
    c = kv + p.headway * kx
    ref = zoh.coefficients(kx, kv, ka, H=H, tau=(t, t), tau_p=(t_p, t_p), eps=(e, e), c=(c, c))
    assert m == m2
    mine = [*co.delta, *co.nu, *co.ell, co.phi1, co.phi1p, *co.P, *co.Yr, *co.Yi]
    theirs = [*ref.delta, *ref.nu, *ref.ell, ref.phi1, ref.phi1p, *ref.P, *ref.Yr, *ref.Yi]
    assert len(mine) == len(theirs) == 18
    for x, y in zip(mine, theirs):
        assert type(x) is Point and type(y) is Interval and y.point
        assert x.lo.shape == (n,)
        assert _same(x.lo, y.lo) and _same(x.mag, y.mag)
    # the Schur conditions recorded with them: those of the row-by-row δ
    assert co.schur is not None
    for x, y in zip(co.schur, zoh.schur_terms(ref.delta)):
        assert _same(x.lo, y.lo) and _same(x.mag, y.mag)


@pytest.mark.parametrize("loop", LOOPS, ids=range(len(LOOPS)))
@pytest.mark.parametrize("rows", [1, 2, 8, 300])
def test_check_decides_as_the_generic_evaluator_bit_for_bit(loop, rows):
    K = _gains(300, 2)
    L = Loop.of(**loop)
    parts = [L.check(K[i:i + rows, 0], K[i:i + rows, 1], K[i:i + rows, 2])
             for i in range(0, len(K), rows)]
    verdict = np.concatenate([np.asarray(c.verdict) for c in parts])
    margin = np.concatenate([c.margin for c in parts])
    theta = np.concatenate([np.asarray(c.witness_theta) for c in parts])
    one = np.ones(len(K))
    codes, g, th = check_members(*(np.ascontiguousarray(K[:, j]) for j in range(3)),
                                 tau=loop["tau"] * one, tau_prev=loop["tau_prev"] * one,
                                 delta=loop["delta"] * one, headway=loop["headway"] * one,
                                 H=loop["sample_time"])
    names = np.array(["certified", "not_certified", "inconclusive"])
    if rows == 300:  # one call each: the same batch, so the same refinement
        assert (verdict == names[codes]).all()
        stable = ~np.isnan(th)  # check_members gives no θ where Δ is not Schur
        assert _same(margin, g) and _same(theta[stable], th[stable])
        assert stable.mean() > 0.3
    else:  # a batch's splits are sized over it (branch_bound): compare the decided verdicts
        decided = (verdict != "inconclusive") & (names[codes] != "inconclusive")
        assert (verdict[decided] == names[codes][decided]).all()
        assert decided.mean() > 0.95
    assert {"certified", "not_certified"} <= set(verdict.tolist())
