"""The training repair (:class:`stringstab.tuning.repair.GainRepair`): every executed gain certified.

Independent truths: each executed triple is checked afresh by both certificates
(:func:`stringstab.check`, continuous and sampled at H, no cache), and by a fine sweep of the
sampled loop's |H(e^{jθ})| and its poles built from ``scipy.linalg.expm``
(``tests/_sampled_truth.py``, not the package's sampled code) and of the continuous |Γ(jω)|
written out here; the repair with its verdict cache against the same repair asked with an empty
cache at every call (the same outputs, bit for bit).
"""

from __future__ import annotations

import numpy as np
import pytest

import stringstab as ss
from stringstab.tuning.repair import GainRepair
from tests._sampled_truth import pair_response, pair_roots

TAU, DELTA, HEADWAY, H = 0.1, 0.2, 1.1, 0.1


def continuous_peak(k) -> float:
    """sup |Γ(jω)| on a fine sweep, Γ of IDL eq 11 written out (the derived form)."""
    kx, kv, ka = k
    w = np.concatenate([np.linspace(1e-4, 5.0, 20_000), np.geomspace(5.0, 1e3, 4000)])
    s = 1j * w
    num = kx + kv * s + ka * s * s * np.exp(-DELTA * s)
    den = TAU * s**3 + s**2 + (kv + kx * HEADWAY) * s + kx
    return float(np.max(np.abs(num / den)))


def sampled_truth(k) -> tuple[float, float]:
    """(spectral radius of the follower's sampled loop, sup |H(e^{jθ})| on a fine θ sweep)."""
    kx, kv, ka = k
    rho = float(np.max(np.abs(pair_roots(kx, kv, TAU, HEADWAY, H))))
    theta = np.linspace(1e-4, np.pi, 3000)
    peak = np.max(np.abs(pair_response(theta, kx, kv, ka, TAU, DELTA, HEADWAY, H)))
    return rho, float(peak)


def walk(n_steps=60, n_envs=6, rate=0.02, seed=3):
    """Proposals the way training makes them: random ±rate steps from certified starts.

    Starting points near the certified region's edge (k_a large), so that many proposals leave
    the proven cells and some leave the certified region; the step after a repair starts from
    the executed gains, as the rate limit does.
    """
    rng = np.random.default_rng(seed)
    rep = GainRepair(tau=TAU, delta=DELTA, headway=HEADWAY, resolution=0.25, refine=3,
                     sample_time=H)
    E = np.array([[1.2, 0.5, 0.6], [0.8, 0.9, 0.7], [1.0, 0.6, 0.75], [0.6, 0.6, 0.3],
                  [1.4, 1.0, 0.8], [0.9, 0.7, 0.65]])[:n_envs]
    proposals, executed = [], []
    for _ in range(n_steps):
        P = np.clip(E + rate * rng.choice([-1.0, 1.0], size=E.shape), -2, 2)
        E = rep(P)
        proposals.append(P)
        executed.append(E)
    return rep, np.stack(proposals), np.stack(executed)


@pytest.fixture(scope="module")
def walked():
    return walk()


def test_every_executed_gain_is_certified_by_both_certificates(walked):
    rep, _, executed = walked
    K = np.unique(executed.reshape(-1, 3), axis=0)
    cont = ss.check(*K.T, tau=TAU, delta=DELTA, headway=HEADWAY)
    samp = ss.check(*K.T, tau=TAU, delta=DELTA, headway=HEADWAY, sample_time=H)
    assert (cont.verdict == "certified").all(), K[cont.verdict != "certified"]
    assert (samp.verdict == "certified").all(), K[samp.verdict != "certified"]
    # the walk used the cache and the continuous cells, and repaired some proposals
    assert rep.stats["reused"] > 0 and rep.stats["repaired"] > 0
    # independent truth on a sample of them: |Γ| ≤ 1 on a fine sweep, the sampled loop's
    # poles inside the unit circle and |H| ≤ 1 on a fine θ sweep (tolerances: sweep round-off)
    for k in K[np.random.default_rng(0).choice(len(K), 6, replace=False)]:
        assert continuous_peak(k) <= 1.0 + 1e-9, k
        rho, peak = sampled_truth(k)
        assert rho < 1.0 and peak <= 1.0 + 1e-9, (k, rho, peak)


def test_a_proposal_certified_by_both_is_executed_unchanged_and_others_are_moved(walked):
    _, proposals, executed = walked
    P, E = proposals.reshape(-1, 3), executed.reshape(-1, 3)
    moved = (P != E).any(axis=1)
    cont = ss.check(*P.T, tau=TAU, delta=DELTA, headway=HEADWAY).verdict == "certified"
    samp = ss.check(*P.T, tau=TAU, delta=DELTA, headway=HEADWAY,
                    sample_time=H).verdict == "certified"
    both = cont & samp
    assert moved.any() and (~moved).any()
    assert not moved[both].any()  # certified both ways as proposed: executed as proposed
    assert moved[~both].all()  # not certified both ways: never executed as proposed


def test_the_verdict_cache_changes_no_output(walked):
    _, proposals, executed = walked
    fresh = GainRepair(tau=TAU, delta=DELTA, headway=HEADWAY, resolution=0.25, refine=3,
                       sample_time=H)
    out = []
    for P in proposals:
        fresh._verdicts.clear()  # no verdict kept from one call to the next
        out.append(fresh(P))
    np.testing.assert_array_equal(np.stack(out), executed)
    assert fresh.stats["reused"] < fresh.stats["checked"]


def test_verdicts_are_reused_for_the_same_triple_and_bounded(monkeypatch):
    from stringstab.tuning import repair as rp

    rep = GainRepair(tau=TAU, delta=DELTA, headway=HEADWAY, resolution=0.25, sample_time=H)
    K = np.array([[1.05, 0.55, 0.62], [0.9, -0.5, 1.1], [1.3, 0.41, 0.33]])
    first = rep.certified(K)
    calls = rep.stats["certificate_calls"]
    np.testing.assert_array_equal(rep.certified(K[::-1]), first[::-1])
    assert rep.stats["certificate_calls"] == calls and rep.stats["reused"] == 3
    truth = ((ss.check(*K.T, tau=TAU, delta=DELTA, headway=HEADWAY).verdict == "certified")
             & (ss.check(*K.T, tau=TAU, delta=DELTA, headway=HEADWAY,
                         sample_time=H).verdict == "certified"))
    np.testing.assert_array_equal(first, truth)
    monkeypatch.setattr(rp, "VERDICT_CACHE", 2)
    rep.certified(K + 0.01)
    assert len(rep._verdicts) == 2


def _kept(rep):
    """The kept verdicts as (gains, certified) arrays, oldest first (:meth:`GainRepair.state`)."""
    meta, arrays = rep.state()
    assert meta["verdicts"] == arrays["gains"].shape[0] == arrays["certified"].shape[0]
    return arrays["gains"], arrays["certified"]


def test_state_load_state_round_trips_the_kept_verdicts_in_order(walked, monkeypatch):
    from stringstab.errors import StringStabError
    from stringstab.tuning import repair as rp

    rep = walked[0]
    meta, arrays = rep.state()
    assert meta["verdicts"] > 0 and arrays["certified"].any() and not arrays["certified"].all()
    # the arrays are the kept verdicts, in their insertion order
    keys = list(rep._verdicts)
    np.testing.assert_array_equal(arrays["gains"],
                                  np.array([np.frombuffer(k) for k in keys]))
    np.testing.assert_array_equal(arrays["certified"], [int(v) for v in rep._verdicts.values()])
    back = GainRepair(tau=TAU, delta=DELTA, headway=HEADWAY, resolution=0.25, refine=3,
                      sample_time=H)
    back.load_state(json_round_trip(meta), {k: v.copy() for k, v in arrays.items()})
    assert list(back._verdicts.items()) == list(rep._verdicts.items())  # bits and order
    # the restored verdicts answer without a certificate call, as the saved ones did
    K = arrays["gains"][:50]
    np.testing.assert_array_equal(back.certified(K), arrays["certified"][:50].astype(bool))
    assert back.stats["certificate_calls"] == 0 and back.stats["reused"] == 50
    # and they are dropped in the same order when the bound is reached
    monkeypatch.setattr(rp, "VERDICT_CACHE", meta["verdicts"])
    a = GainRepair(tau=TAU, delta=DELTA, headway=HEADWAY, resolution=0.25, refine=3,
                   sample_time=H)
    a.load_state(meta, arrays)
    new = np.array([[1.01, 0.51, 0.61], [0.91, 0.71, 0.66], [1.31, 0.42, 0.34]])
    for r in (a, back):
        r.certified(new)
    ga, ca = _kept(a)
    gb, cb = _kept(back)
    np.testing.assert_array_equal(ga, gb)
    np.testing.assert_array_equal(ca, cb)
    np.testing.assert_array_equal(ga[:-3], arrays["gains"][3:])  # the three oldest dropped
    np.testing.assert_array_equal(ga[-3:], new)
    # an empty repair round-trips to empty; other settings or bad arrays are refused
    empty = GainRepair(tau=TAU, delta=DELTA, headway=HEADWAY, resolution=0.25, sample_time=H)
    m0, a0 = empty.state()
    assert m0["verdicts"] == 0 and a0["gains"].shape == (0, 3)
    empty.load_state(m0, a0)
    other = GainRepair(tau=TAU, delta=DELTA, headway=1.2, resolution=0.25, refine=3,
                       sample_time=H)
    with pytest.raises(StringStabError, match="expected the settings"):
        other.load_state(meta, arrays)
    bad = [{"gains": arrays["gains"][:, :2], "certified": arrays["certified"]},
           {"gains": arrays["gains"], "certified": arrays["certified"][:-1]},
           {"gains": arrays["gains"], "certified": arrays["certified"] + 2},
           {"gains": np.vstack([arrays["gains"][:-1], arrays["gains"][:1]]),
            "certified": arrays["certified"]},
           {"gains": arrays["gains"]}]
    before = list(back._verdicts.items())
    for arrs in bad:
        with pytest.raises(StringStabError, match="repair state: expected"):
            back.load_state(meta, arrs)
    assert list(back._verdicts.items()) == before  # unchanged by a refusal


def test_projection_exact_state_includes_the_projectors_cache():
    """``"projection-exact"``: the Projector's cache (by rounded K0) is saved and restored."""
    pytest.importorskip("casadi")
    kw = dict(tau=TAU, delta=DELTA, headway=HEADWAY, resolution=0.25, sample_time=H)
    rep = GainRepair("projection-exact", **kw)
    P = np.array([[0.9, -0.5, 1.1], [1.5, 0.2, 1.4], [0.3, 1.8, 1.2]])
    out = rep(P)
    meta, arrays = rep.state()
    assert arrays["projector.keys"].shape[0] > 0
    back = GainRepair("projection-exact", **kw)
    back.load_state(json_round_trip(meta), arrays)
    for k, v in back.state()[1].items():
        np.testing.assert_array_equal(v, arrays[k], err_msg=k)
    # a proposal a rounding step away is answered from the restored cache, as by the original
    near = P + 1e-9
    np.testing.assert_array_equal(back(near), rep(near))
    assert back._projector.stats["cache_hits"] > 0
    # the executed gains are certified by both certificates (independent of the cache)
    for K in (out, back(near)):
        assert (ss.check(*K.T, tau=TAU, delta=DELTA, headway=HEADWAY).verdict == "certified").all()
        assert (ss.check(*K.T, tau=TAU, delta=DELTA, headway=HEADWAY,
                         sample_time=H).verdict == "certified").all()
    from stringstab.errors import StringStabError

    with pytest.raises(StringStabError, match="expected the arrays"):
        back.load_state(meta, {"gains": arrays["gains"], "certified": arrays["certified"]})


def json_round_trip(doc):
    """``doc`` as a checkpoint's state.json gives it back."""
    import json

    return json.loads(json.dumps(doc))


# -- θ_r > 0 with the sampled certificate (issue 25) ------------------------------------------
THETA = 0.2  # θ_r = qH with q = 2 (and δ = mH, m = 2): the truth below shifts by whole steps


def shifted_response(k, theta):
    """H(e^{jθ}) of the sampled loop whose command acts q = θ_r/H steps late, δ = mH.

    Built from ``scipy.linalg.expm`` of one vehicle over a held step (not the certificate's
    lifting): P(z) = (zI − Φ)⁻¹Γ delayed by z^{−q}, the predecessor's acceleration by z^{−m}.
    """
    from scipy.linalg import expm

    q, m = round(THETA / H), round(DELTA / H)
    M = np.zeros((4, 4))
    M[0, 1] = M[1, 2] = 1.0
    M[2, 2], M[2, 3] = -1.0 / TAU, 1.0 / TAU
    E = expm(M * H)
    Phi, G = E[:3, :3], E[:3, 3]
    z = np.exp(1j * theta)
    X = np.array([np.linalg.solve(zz * np.eye(3) - Phi, G) for zz in z])
    d = z ** (-q)
    Pp, Pv, Pa = X[:, 0] * d, X[:, 1] * d, X[:, 2] * d
    num = k[0] * Pp + k[1] * Pv + k[2] * Pa * z ** (-m)
    return num / (1.0 + k[0] * (Pp + HEADWAY * Pv) + k[1] * Pv)


def test_the_sampled_repair_with_theta_certifies_every_executed_gain_both_ways():
    rep = GainRepair(tau=TAU, delta=DELTA, headway=HEADWAY, resolution=0.25, refine=2,
                     sample_time=H, reaction_delay=THETA)
    P = np.array([[1.2, 0.5, 0.6], [0.6, 0.6, 0.3], [0.9, -0.5, 1.1], [0.3, 0.8, 0.1],
                  [1.5, 1.2, 0.9], [0.4, 0.7, 0.2]])
    K = rep(P)
    c = ss.check(*K.T, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA)
    s = ss.check(*K.T, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA,
                 sample_time=H)
    assert (c.verdict == "certified").all() and (s.verdict == "certified").all(), K
    both = ((ss.check(*P.T, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA)
             .verdict == "certified")
            & (ss.check(*P.T, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA,
                        sample_time=H).verdict == "certified"))
    np.testing.assert_array_equal((K == P).all(axis=1), both)  # unchanged iff certified
    assert (~both).any()
    th = np.linspace(1e-4, np.pi, 2000)
    for k in K:  # the independent truth: |H| ≤ 1 on a fine θ sweep
        assert np.max(np.abs(shifted_response(k, th))) <= 1.0 + 1e-9, k
    # the lattice: every point certified both ways at θ_r (a sample, afresh)
    L = rep.lattice()
    pick = L[np.random.default_rng(1).choice(len(L), min(20, len(L)), replace=False)]
    v = ss.check(*pick.T, tau=TAU, delta=DELTA, headway=HEADWAY, reaction_delay=THETA,
                 sample_time=H).verdict
    assert (v == "certified").all()


def test_theta_of_too_many_steps_is_refused_in_one_line():
    from stringstab.errors import StringStabError

    with pytest.raises(StringStabError, match="at most 2000 whole samples"):
        GainRepair(tau=TAU, delta=DELTA, headway=HEADWAY, sample_time=0.001, reaction_delay=30.0)
