"""The certified points of a gain grid (stringstab.certify.grid) and the screen (certify.screen).

* The screen is sound: no triple it flags is certified by the exact certificate — on random
  triples, and on triples within 1e-9 of the boundary of the certified region (the hardest
  case); and what it flags fails for an independent reason (|Γ(jω)| > 1 from Γ itself, or an
  unstable pole).
* The helper returns exactly the points of each construction it replaces, on small grids: the
  RL repair's lattice (called), the projection's certified maps and the tuning loop's
  ``certified_points`` (their code as it was before they called the helper, copied below as
  the reference), and the region map's ``exact`` verdicts.
"""

from __future__ import annotations

import numpy as np
import pytest

from stringstab.certify.api import certify_batch, check
from stringstab.certify.criteria import hurwitz, hurwitz_conditions
from stringstab.certify.frequency import gain, margin_g
from stringstab.certify.grid import certified, certified_lattice, lattice
from stringstab.certify.screen import SCREEN_OMEGA, surely_uncertifiable, violating_dips
from stringstab.errors import StringStabError
from stringstab.params import Box, Params
from stringstab.regions import region_map

P = Params(0.1, 0.2, 1.1)
PARAMS = [P, Params(0.3, 0.5, 0.8), Params(0.05, 0.0, 2.0)]


def _certified_by_check(K, p, **kw):
    return check(K[:, 0], K[:, 1], K[:, 2], tau=p.tau, delta=p.delta, headway=p.headway,
                 **kw).verdict == "certified"


# ------------------------------------------------------------------------------ the screen
@pytest.mark.parametrize("p", PARAMS)
def test_screen_never_flags_a_certified_triple(p):
    rng = np.random.default_rng(20)
    K = rng.uniform(-2.0, 2.0, (3000, 3))
    flagged = surely_uncertifiable(K, p)
    cert = _certified_by_check(K, p)
    assert not (flagged & cert).any()
    # not vacuous: it flags most of the uncertified triples, and some certified ones exist
    assert cert.sum() > 30
    assert flagged.sum() > 0.6 * (~cert).sum()
    # what it flags fails independently: an unstable pole, or |Γ(jω)| > 1 at a screen frequency
    hz = hurwitz(K[:, 0], K[:, 1], tau=p.tau, headway=p.headway)
    peak = gain(SCREEN_OMEGA[None, :], K[:, 0:1], K[:, 1:2], K[:, 2:3], tau=p.tau,
                delta=p.delta, headway=p.headway).max(axis=1)
    assert np.all(~hz[flagged] | (peak[flagged] > 1.0 + 1e-12))


@pytest.mark.parametrize("p", PARAMS[:2])
def test_screen_is_sound_at_the_boundary_of_the_certified_region(p):
    # bisect between a certified and an uncertified triple down to 1e-9: the certified end is
    # as close to the boundary as the certificate can decide, where rounding would show
    rng = np.random.default_rng(7)
    K = rng.uniform(-2.0, 2.0, (4000, 3))
    cert = _certified_by_check(K, p)
    m = min(150, int(cert.sum()), int((~cert).sum()))
    good, bad = K[cert][:m], K[~cert][:m]
    assert m > 50
    lo, hi = np.zeros(len(good)), np.ones(len(good))
    while (hi - lo).max() > 1e-9:
        mid = 0.5 * (lo + hi)
        ok = _certified_by_check(good + mid[:, None] * (bad - good), p)
        lo, hi = np.where(ok, mid, lo), np.where(ok, hi, mid)
    inside = good + lo[:, None] * (bad - good)
    outside = good + hi[:, None] * (bad - good)
    assert _certified_by_check(inside, p).all()
    assert not surely_uncertifiable(inside, p).any()
    # and the dip scan of one triple finds no violation on the certified side either
    assert all(violating_dips(k, p) == [] for k in inside[:40])
    # the screen is not idle there: it flags part of the uncertified side (by a violation)
    assert surely_uncertifiable(outside + 1e-3 * (bad - good), p).any()


def test_violating_dips_only_where_not_certified():
    rng = np.random.default_rng(3)
    K = rng.uniform(-2.0, 2.0, (300, 3))
    cert = _certified_by_check(K, P)
    dips = [violating_dips(k, P) for k in K]
    assert not any(d and c for d, c in zip(dips, cert))
    assert sum(bool(d) for d in dips) > 50
    # each clear dip is a violation, checked on Γ itself (a dip at ω = 0, where |Γ(0)| = 1,
    # means |Γ(jω)| > 1 just above it: looked at ω = 0.01)
    clear = 0
    for k, d in zip(K, dips):
        for w in d:
            if margin_g(w, *k, tau=P.tau, delta=P.delta, headway=P.headway) < -1e-3:
                w = max(w, 1e-2)
                assert gain(w, *k, tau=P.tau, delta=P.delta, headway=P.headway) > 1.0
                clear += 1
    assert clear > 50


def test_screen_with_no_frequencies_is_internal_stability():
    K = lattice(-2.0, 2.0, 7)
    np.testing.assert_array_equal(surely_uncertifiable(K, P, omega=()),
                                  ~hurwitz(K[:, 0], K[:, 1], tau=P.tau, headway=P.headway))


# ------------------------------------------------------------------------------ the helper
def test_certified_is_check_on_random_triples():
    rng = np.random.default_rng(11)
    K = rng.uniform(-2.0, 2.0, (2000, 3))
    np.testing.assert_array_equal(certified(K, P), _certified_by_check(K, P))
    assert certified(np.empty((0, 3)), P).shape == (0,)


def test_lattice_order_and_input_errors():
    K = lattice(-1.0, 1.0, 3)
    g = np.linspace(-1.0, 1.0, 3)
    KX, KV, KA = np.meshgrid(g, g, g, indexing="ij")
    np.testing.assert_array_equal(K, np.column_stack([KX.ravel(), KV.ravel(), KA.ravel()]))
    with pytest.raises(StringStabError, match="n >= 2"):
        lattice(-1.0, 1.0, 1)
    with pytest.raises(StringStabError, match="lo < hi"):
        lattice(1.0, -1.0, 3)
    with pytest.raises(StringStabError, match="Params or a Box"):
        certified(K, (0.1, 0.2, 1.1))  # type: ignore[arg-type]
    with pytest.raises(StringStabError, match="hurwitz_margin"):
        certified_lattice(-1.0, 1.0, 3, P, sample_time=0.1, hurwitz_margin=1e-3)


def _repair_certified(K, p, sample_time=None):
    """rl/repair.py's ``_certified`` before it called the helper (verbatim, its screen inlined:
    Hurwitz, then g(ω) ≥ 0 at the 48 fixed frequencies, then ``check``, then the sampled one)."""
    out = np.zeros(K.shape[0], dtype=bool)
    cand = hurwitz(K[:, 0], K[:, 1], tau=p.tau, headway=p.headway)
    if cand.any():
        idx = np.flatnonzero(cand)
        g = margin_g(SCREEN_OMEGA[None, :], K[idx, 0:1], K[idx, 1:2], K[idx, 2:3],
                     tau=p.tau, delta=p.delta, headway=p.headway)
        idx = idx[g.min(axis=1) >= 0.0]
        if idx.size:
            ok = _certified_by_check(K[idx], p)
            if sample_time is not None and ok.any():
                ok[ok] = _certified_by_check(K[idx[ok]], p, sample_time=sample_time)
            out[idx] = ok
    return out


@pytest.mark.parametrize("sample_time", [None, 0.1])
def test_same_points_as_the_rl_repair_lattice(sample_time):
    from stringstab.tuning.lattice import certified_lattice as repair_lattice

    K = lattice(-2.0, 2.0, 9)
    new = certified_lattice(-2.0, 2.0, 9, P, sample_time=sample_time, also_continuous=True)
    np.testing.assert_array_equal(new, K[_repair_certified(K, P, sample_time)])
    np.testing.assert_array_equal(new, repair_lattice(0.1, 0.2, 1.1, -2.0, 2.0, 0.5, sample_time))
    assert len(new) > 20
    # and on random triples (the repair's bisection certifies arbitrary points)
    R = np.random.default_rng(5).uniform(-2.0, 2.0, (1000 if sample_time else 5000, 3))
    np.testing.assert_array_equal(
        certified(R, P, sample_time=sample_time, also_continuous=True),
        _repair_certified(R, P, sample_time))


def _projection_certified_map(tau, delta, headway, lo, hi, margin, n):
    """tuning/projection.py's ``_certified_map`` before it called the helper (verbatim)."""
    g = np.linspace(lo, hi, n)
    KX, KV, KA = np.meshgrid(g, g, g, indexing="ij")
    kx, kv, ka = KX.ravel(), KV.ravel(), KA.ravel()
    keep = np.all([c >= margin for c in hurwitz_conditions(kx, kv, ka, tau=tau, headway=headway)],
                  axis=0)
    b = certify_batch(kx[keep], kv[keep], ka[keep], tau=tau, delta=delta, headway=headway)
    return np.column_stack([kx[keep], kv[keep], ka[keep]])[b.certified]


@pytest.mark.parametrize("p", PARAMS)
def test_same_points_as_the_projection_certified_map(p):
    old = _projection_certified_map(p.tau, p.delta, p.headway, -2.0, 2.0, 1e-3, 11)
    new = certified_lattice(-2.0, 2.0, 11, p, hurwitz_margin=1e-3)
    np.testing.assert_array_equal(new, old)
    assert len(new) > 10


def _loop_certified_points(K, params, sample_time, heterogeneous=True):
    """tuning/constraints.py's ``LoopConstraints.certified_points`` before it called the helper (verbatim,
    with the box's centre of ``LoopConstraints.centre``)."""
    b = Box.of(params)
    (t0, t1), (d0, d1), (h0, h1) = b.tau, b.delta, b.headway
    ct, cd, ch = 0.5 * (t0 + t1), 0.5 * (d0 + d1), 0.5 * (h0 + h1)
    ok = np.zeros(len(K), dtype=bool)
    screen = certify_batch(K[:, 0], K[:, 1], K[:, 2], tau=ct, delta=cd, headway=ch,
                           sample_time=sample_time).certified
    if isinstance(params, Params):
        return np.asarray(screen)
    idx = np.flatnonzero(screen)
    r = certify_batch(K[idx, 0], K[idx, 1], K[idx, 2], tau=b.tau, delta=b.delta,
                      headway=b.headway, sample_time=sample_time, heterogeneous=heterogeneous)
    ok[idx] = r.certified
    return ok


BOX = Box((0.08, 0.12), (0.15, 0.25), (1.0, 1.2))
LOOPS = [(P, None, 9), (P, 0.1, 9), (BOX, None, 9), (BOX, 0.1, 4)]


@pytest.mark.parametrize(("params", "sample_time", "n"), LOOPS)
def test_same_points_as_the_tuning_loop(params, sample_time, n):
    from stringstab.tuning.constraints import LoopConstraints as Loop

    K = lattice(-2.0, 2.0, n)
    old = _loop_certified_points(K, params, sample_time)
    new = certified(K, params, sample_time=sample_time)
    np.testing.assert_array_equal(new, old)
    np.testing.assert_array_equal(Loop(params, sample_time).certified_points(K), old)
    assert 0 < new.sum() < len(K)
    # the cheap steps drop nothing: the certificate of the loop on every row, unscreened
    b = Box.of(params)
    every = check(K[:, 0], K[:, 1], K[:, 2], tau=b.tau, delta=b.delta, headway=b.headway,
                  sample_time=sample_time).verdict == "certified"
    np.testing.assert_array_equal(new, every)


@pytest.mark.parametrize(("params", "sample_time", "n"), LOOPS)
def test_same_points_as_the_region_map(params, sample_time, n):
    g = np.linspace(-2.0, 2.0, n)
    kw = {"tau": params.tau, "delta": params.delta, "headway": params.headway}
    m = region_map({"k_x": g, "k_v": g, "k_a": g}, **kw, sample_time=sample_time,
                   methods="exact", workers=1, progress=False)
    # the map's grid is k_x × k_v × k_a in axis order: the lattice's order
    np.testing.assert_array_equal(certified(lattice(-2.0, 2.0, n), params,
                                            sample_time=sample_time),
                                  m.stable("exact").ravel())
