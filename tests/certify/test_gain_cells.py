"""Certificates over cells of gains, the sampled screen, and the repair built on them.

Truth: the point certificates at gains inside the cells (each checked against sweeps in
test_certificate.py and test_sampled.py), |Γ(jω)| written out here on a fine grid, and the
expm construction of tests/_sampled_truth.py for the sampled loop.
"""

import numpy as np
import pytest

from stringstab.certify.api import check
from stringstab.certify.gain_cells import CertifiedCells, continuous_cells, sampled_cells
from stringstab.certify.sampled import check_members
from stringstab.certify.screen import SampledScreen
from stringstab.params import Params
from stringstab.tuning.repair import GainRepair
from tests._sampled_truth import pair_response

P = Params(0.1, 0.2, 1.1)
RNG = np.random.default_rng(7)


def gamma_abs(w, kx, kv, ka, tau=0.1, delta=0.2, headway=1.1):
    s = 1j * np.asarray(w, dtype=float)
    return np.abs((kx + kv * s + ka * s**2 * np.exp(-delta * s))
                  / (tau * s**3 + s**2 + (kv + headway * kx) * s + kx))


def lattice_cells(n_cells, spacing=0.05, centre=(1.1, 0.9, 0.3), spread=0.6):
    """Random cells of the 0.05-lattice over [−2, 2]³ around ``centre``."""
    g = np.linspace(-2.0, 2.0, 81)
    c = np.asarray(centre) + RNG.uniform(-spread, spread, (n_cells, 3))
    i = np.clip(np.searchsorted(g, c) - 1, 0, 79)
    return g[i], g[i + 1]


def test_proven_cells_hold_at_their_members():
    """Every gain of a proven cell (corners, faces, interior) is certified by the point
    certificates, continuous and sampled, and has |Γ| ≤ 1 on a fine grid (Γ written out)."""
    K_lo, K_hi = lattice_cells(300)
    ok = continuous_cells(K_lo, K_hi, P)
    ok[ok] = sampled_cells(K_lo[ok], K_hi[ok], P, 0.1)
    assert 30 <= ok.sum() < len(ok)  # some proven, some not: the test can fail either way
    lo, hi = K_lo[ok], K_hi[ok]
    U = RNG.uniform(0, 1, (4, *lo.shape))
    U[0] = np.round(U[0])  # corners
    U[1, :, 0] = 0.0  # a face
    K = np.concatenate([lo + u * (hi - lo) for u in U])
    assert (check(*K.T, **P.as_dict()).verdict == "certified").all()
    assert (check(*K.T, **P.as_dict(), sample_time=0.1).verdict == "certified").all()
    w = np.linspace(1e-3, 25.0, 20000)
    for k in K[RNG.choice(len(K), 25, replace=False)]:
        assert gamma_abs(w, *k).max() <= 1 + 1e-9
    th = np.linspace(1e-4, np.pi, 1500)
    for k in K[RNG.choice(len(K), 10, replace=False)]:
        assert np.abs(pair_response(th, *k, 0.1, 0.2, 1.1, 0.1)).max() <= 1 + 1e-9


def test_a_cell_with_a_violating_member_is_never_proven():
    """Cells around gains the point certificate does not certify are not proven."""
    K = RNG.uniform(-2, 2, (400, 3))
    bad = check(*K.T, **P.as_dict(), sample_time=0.1).verdict == "not_certified"
    K = K[bad]
    ok = continuous_cells(K - 0.01, K + 0.01, P)
    ok[ok] = sampled_cells(K[ok] - 0.01, K[ok] + 0.01, P, 0.1)
    assert not ok.any()


def test_certified_cells_do_not_depend_on_the_order_of_the_questions():
    """Blocks are proven whole: asking in another order proves the same cells."""
    K = np.array([1.1, 0.9, 0.3]) + RNG.uniform(-0.2, 0.2, (40, 3))
    a = CertifiedCells(-2.0, 2.0, 81, P, sample_time=0.1)
    b = CertifiedCells(-2.0, 2.0, 81, P, sample_time=0.1)
    ra = a.contains(K)
    rb = np.concatenate([b.contains(k[None]) for k in K[::-1]])[::-1]
    assert np.array_equal(ra, rb)
    assert np.array_equal(a.proven_cells, b.proven_cells) and a.proven == b.proven > 0


def test_cell_of_a_gain_on_a_face_contains_it():
    c = CertifiedCells(-2.0, 2.0, 81, P)
    K = np.array([[1.1, 0.9, 0.3], [-2.0, -2.0, -2.0], [2.0, 2.0, 2.0], [2.5, 0.0, 0.0]])
    ijk, inside = c.cells_of(K)
    assert inside.tolist() == [True, True, True, False]
    g = c.g
    assert np.all((g[ijk[:3]] <= K[:3]) & (K[:3] <= g[ijk[:3] + 1]))


def test_sampled_screen_flags_only_gains_the_certificate_rejects():
    """Sound: a flagged row is never certified by check with a sample time (random and near the
    boundary); and it flags every Schur-stable row whose violation the certificate finds
    (there are 1,253 here: the screen is not a no-op)."""
    s = SampledScreen(P, 0.1)
    assert s.ok
    K = np.concatenate([RNG.uniform(-2, 2, (3000, 3)),
                        np.array([1.1, 0.9, 0.3]) + RNG.normal(0, 0.3, (3000, 3))])
    flag = s.surely_uncertifiable(K)
    c = check(*K.T, **P.as_dict(), sample_time=0.1)
    assert not np.any(flag & (c.verdict == "certified"))
    violated = (c.verdict == "not_certified") & c.schur
    assert violated.sum() > 1000 and flag[violated].mean() >= 0.95


def test_check_members_is_the_point_certificate_row_by_row():
    K = RNG.uniform(-2, 2, (40, 3))
    tau, tp = RNG.uniform(0.05, 0.3, 40), RNG.uniform(0.05, 0.3, 40)
    d, h = RNG.uniform(0, 0.5, 40), RNG.uniform(0.5, 2, 40)
    v, g, _ = check_members(*K.T.copy(), tau=tau, tau_prev=tp, delta=d, headway=h, H=0.1)
    for i in range(40):
        c = check(*K[i], tau=tau[i], delta=d[i], headway=h[i], sample_time=0.1,
                  tau_prev=tp[i])
        assert ["certified", "not_certified", "inconclusive"][v[i]] == c.verdict[0]
        assert g[i] == c.margin[0]


@pytest.mark.parametrize("sample_time", [0.1, None])
def test_repair_executes_only_certified_gains(sample_time):
    """Whatever the proposals (uniform, near the boundary), every executed triple is
    certified by check (and by check at Δt with the sampled repair)."""
    rep = GainRepair(tau=0.1, delta=0.2, headway=1.1, resolution=0.25, sample_time=sample_time)
    K = np.concatenate([RNG.uniform(-2, 2, (60, 3)),
                        np.array([1.1, 0.9, 0.3]) + RNG.normal(0, 0.3, (60, 3))])
    out = np.concatenate([rep(K[i:i + 8]) for i in range(0, len(K), 8)])
    assert (check(*out.T, **P.as_dict()).verdict == "certified").all()
    if sample_time:
        assert (check(*out.T, **P.as_dict(), sample_time=0.1).verdict == "certified").all()
    ok = (check(*K.T, **P.as_dict()).verdict == "certified")
    if sample_time:
        ok &= check(*K.T, **P.as_dict(), sample_time=0.1).verdict == "certified"
    assert np.array_equal(out[ok], K[ok])  # certified proposals are executed unchanged
