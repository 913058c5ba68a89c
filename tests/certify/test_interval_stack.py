"""The stacked derivative enclosures (interval_stack.StackedAD) are IntervalAD's numbers, bit for bit.

The robust sampled certificate computes its cells (``FollowerCells.of``,
``PredecessorCells.of``) and the Schur box's δ cells in :class:`StackedAD` since issue 31's
fourth pass; its outputs must stay those of :class:`~stringstab.certify.interval.IntervalAD`
(itself tested for enclosure in ``test_interval.py``) to the last bit, signs of zero
included.  The truth here is the IntervalAD computation of the same formulas.
"""

from __future__ import annotations

import numpy as np
import pytest

from stringstab.certify.interval import IntervalAD
from stringstab.certify.interval_stack import (
    StackedAD,
    exp_neg_stacked,
    phi_stacked,
    ratio_stacked,
)
from stringstab.certify.sampled_split import follower_terms, predecessor_terms
from stringstab.certify.sampled_split_cells import FollowerCells, PredecessorCells
from stringstab.certify.schur import schur_terms
from stringstab.certify.verdicts import ROUNDOFF_SLACK
from stringstab.certify.zoh import exp_neg_ad, phi_ad, ratio_ad


def _bits(x, n):
    return np.broadcast_to(np.asarray(x, dtype=float), (n,)).tobytes()


def _same(a, b, n):
    """Every number of a StackedAD ``a`` and an IntervalAD ``b``: centre, enclosure, derivatives."""
    pairs = [(a.c.lo, b.c.lo), (a.c.mag, b.c.mag), (a.r.lo, b.r.lo), (a.r.hi, b.r.hi),
             (a.r.mag, b.r.mag)]
    assert len(a.g) == len(b.g)
    for ga, gb in zip(a.g, b.g):
        pairs += [(ga.lo, gb.lo), (ga.hi, gb.hi), (ga.mag, gb.mag)]
    return all(_bits(x, n) == _bits(y, n) for x, y in pairs)


def _cells(rng, n, d):
    """Bounds (n, 2) per parameter: some of no width, some equal to others."""
    out = []
    for _ in range(d):
        lo = rng.uniform(0.05, 0.5, n)
        w = rng.uniform(0.0, 0.2, n) * (rng.random(n) < 0.8)
        out.append(np.stack([lo, lo + w], axis=1))
    return out


@pytest.mark.parametrize("d", [1, 2])
def test_every_operation_is_interval_ad_bit_for_bit(d):
    rng = np.random.default_rng(7 + d)
    n = 57
    cells = _cells(rng, n, d)
    S = [StackedAD.variable(c[:, 0], c[:, 1], i, d) for i, c in enumerate(cells)]
    A = [IntervalAD.variable(c[:, 0], c[:, 1], i, d) for i, c in enumerate(cells)]
    kx = rng.uniform(-2, 2, n)
    H = 0.1
    for s, a in zip(S, A):
        assert _same(s, a, n)

    def chain(X, ratio, phi_, exp_neg, batched):
        T = X[0]
        K = T.const(kx)
        x = ratio(T, H)
        f1, p2, p3 = phi_(x)[0] if batched else phi_(x)
        u = f1.reciprocal()
        out = [K, -K, K * (-2.0), (K * (-2.0)) * K, 1.0 - K, K + 0.5, (-K).reciprocal(),
               K * K * 3.0, 2.0 * (T * T), T - x, 1.0 + T * p2 * u, K * f1, f1 * K,
               (T * T) * (p2 - p3), exp_neg((1.0 - T.const(0.25)) * x),
               -(u * (p3 * 0.5)), (T + K) * (T * -1.5)]
        if len(X) > 1:
            out += [X[1] * K + T, (X[1] * T) * (K - X[1]), X[1].const(0.0) * X[1]]
        return out

    got = chain(S, ratio_stacked, phi_stacked, exp_neg_stacked, True)
    want = chain(A, ratio_ad, phi_ad, exp_neg_ad, False)
    for i, (s, a) in enumerate(zip(got, want)):
        assert s.k == a.k, i
        assert _same(s, a, n), i
    # a constant times −2 has −0 derivatives, as IntervalAD's
    assert np.signbit(got[2].g[0].lo).all() and np.signbit(want[2].g[0].lo).all()


def test_phi_of_several_quantities_is_phi_of_each():
    rng = np.random.default_rng(3)
    n = 40
    (t,) = _cells(rng, n, 1)
    T = StackedAD.variable(t[:, 0], t[:, 1], 0, 1)
    x = ratio_stacked(T, 0.3)
    y = x * 0.4
    both = phi_stacked(x, y)
    for q, got in zip((x, y), both):
        alone = phi_stacked(q)[0]
        for a, b in zip(got, alone):
            assert a.X.tobytes() == np.ascontiguousarray(b.X).tobytes()


def _reference_rows(poly, fields, n, J=3):
    out = np.zeros((n, len(fields), J))
    for j, v in enumerate(poly):
        for k, f in enumerate(fields):
            if f in ("c", "lo", "hi"):
                x = {"c": v.c.lo, "lo": v.r.lo, "hi": v.r.hi}[f]
            else:
                g = v.g[int(f[-1])]
                x = g.lo if f.startswith("glo") else g.hi
            out[:, k, j] = x
    return out


def _reference_magnitudes(poly, n, J=3):
    a, mag, gmag = (np.zeros((n, J)) for _ in range(3))
    for j, v in enumerate(poly):
        a[:, j] = np.maximum(np.abs(v.r.lo), np.abs(v.r.hi)) + ROUNDOFF_SLACK * v.r.mag
        mag[:, j] = np.maximum(v.c.mag, v.r.mag)
        gmag[:, j] = np.broadcast_to(np.asarray(sum(g.mag for g in v.g)), (n,))
    return a, mag, gmag


@pytest.mark.parametrize("H", [0.05, 0.1, 0.3])
def test_cells_are_the_interval_ad_cells_bit_for_bit(H):
    rng = np.random.default_rng(int(H * 100))
    for n in (1, 9, 140):
        kx, kv, ka = rng.uniform(-2, 2, (3, 6))
        own = rng.integers(0, 6, n)
        tau, hd = _cells(rng, n, 2)
        hd = hd + 0.5
        F = FollowerCells.of(own, kx, kv, H=H, tau=tau, headway=hd)
        Fp = follower_terms(kx[own], kv[own], H=H, tau=tau, headway=hd)
        assert F.V.tobytes() == _reference_rows(
            Fp, ("c", "lo", "glo0", "ghi0", "glo1", "ghi1"), n).tobytes()
        for x, y in zip((F.a, F.mag, F.gmag), _reference_magnitudes(Fp, n)):
            assert x.tobytes() == y.tobytes()
        ends = [(1, 0.5), (2, 0.0), (2, 0.5), (0, 1.0), (3, 0.123)]
        end = rng.integers(0, len(ends), n)
        G = PredecessorCells.of(own, own, kx, kv, ka, H=H, tau_p=tau, end=end, ends=ends)
        eps = np.array([ends[e][1] for e in end])
        P, Yr, Yi = predecessor_terms(kx[own], kv[own], ka[own], H=H, tau_p=tau, eps=eps)
        Y = ("c", "lo", "hi", "glo0", "ghi0")
        V = np.concatenate([_reference_rows(P, ("c", "hi", "glo0", "ghi0"), n),
                            _reference_rows(Yr, Y, n), _reference_rows(Yi, Y, n)], axis=1)
        assert G.V.tobytes() == V.tobytes()  # Y_r's constant term has −0 derivatives
        mags = [_reference_magnitudes(p, n) for p in (P, Yr, Yi)]
        for i, x in enumerate((G.a, G.mag, G.gmag)):
            assert x.tobytes() == np.stack([m[i] for m in mags], axis=1).tobytes()
        assert np.array_equal(G.m, [ends[e][0] for e in end])


def test_schur_terms_of_the_delta_cells_are_interval_ad_s():
    rng = np.random.default_rng(11)
    n = 200
    tau, hd = _cells(rng, n, 2)
    kx, kv = rng.uniform(-2, 2, (2, n))
    H = 0.1

    def delta(var, ratio, phi_, batched):  # the formula of robust_sampled's δ cells
        T = var(tau[:, 0], tau[:, 1], 0, 2)
        Th = var(hd[:, 0], hd[:, 1], 1, 2)
        K_x, K_v = T.const(kx), T.const(kv)
        Cc = K_v + Th * K_x
        f1, p2, p3 = phi_(ratio(T, H))[0] if batched else phi_(ratio(T, H))
        return [K_x * (H * H) * f1, H * (Cc * f1 + K_x * (T * p2 + (0.5 * H) * f1)),
                f1 + Cc * T * p2 + K_x * T * T * p3]

    got = schur_terms(delta(StackedAD.variable, ratio_stacked, phi_stacked, True))
    want = schur_terms(delta(IntervalAD.variable, ratio_ad, phi_ad, False))
    for s, a in zip(got, want):
        assert _same(s, a, n)
