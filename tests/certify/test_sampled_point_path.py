"""The sampled certificate's point path: point parameters give point coefficients.

The sampled ``check`` (the repair's inner loop in :mod:`stringstab.rl.repair`) builds its
coefficients with the interval type of :mod:`stringstab.certify.interval` (:mod:`stringstab.certify.zoh`); with point parameters every
coefficient must be a point, or each operation pays for interval arithmetic (four products and
a min/max) on intervals of zero width.  The verdicts of both paths are equal (the interval
operations on equal end points return those end points), which the second test checks against
the interval path forced by distinct-but-equal end-point arrays.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from stringstab.certify import zoh
from stringstab.params import Params


def _gains(n: int = 64) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(3)
    K = np.array([1.14, 1.03, 0.02]) + rng.normal(0.0, 0.4, (n, 3))
    return K[:, 0].copy(), K[:, 1].copy(), K[:, 2].copy()


@pytest.mark.parametrize("tau_prev", [0.1, 0.15])
def test_point_parameters_give_point_coefficients(tau_prev: float) -> None:
    kx, kv, ka = _gains()
    co, _ = zoh.point_coefficients(kx, kv, ka, Params(0.1, 0.2, 1.1), 0.1, tau_prev)
    items = [*co.delta, *co.nu, *co.ell, co.phi1, co.phi1p, *co.P, *co.Yr, *co.Yi]
    assert all(x.point for x in items)


def test_point_path_equals_the_interval_path() -> None:
    kx, kv, ka = _gains()
    n, H = kx.size, 0.1
    m, eps = zoh.split_delay(0.2, H)
    c = kv + 1.1 * kx

    def arr(v: float) -> np.ndarray:
        return np.full(n, v)

    point = zoh.coefficients(kx, kv, ka, H=H, tau=(t := arr(0.1), t), tau_p=(t, t),
                             eps=(e := arr(eps), e), c=(c, c))
    # equal values in distinct arrays: the interval path, on intervals of zero width
    interval = zoh.coefficients(kx, kv, ka, H=H, tau=(arr(0.1), arr(0.1)),
                                tau_p=(arr(0.1), arr(0.1)), eps=(arr(eps), arr(eps)),
                                c=(c, c.copy()))
    assert not all(x.point for x in interval.P)
    for a, b in zip([*point.delta, *point.P, *point.Yr, *point.Yi],
                    [*interval.delta, *interval.P, *interval.Yr, *interval.Yi]):
        assert_array_equal(a.lo, b.lo)
        assert_array_equal(a.hi, b.hi)
        assert_array_equal(a.mag, b.mag)
    assert m == 2
