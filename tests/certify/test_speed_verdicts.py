"""Verdicts before and after the speed work (issue 31): the decided ones do not change.

``tests/data/speed_verdicts.csv`` holds gain triples — random ones and the adversarial sets of
``analysis/bench_speed.py`` (near the Hurwitz/Schur boundary, near |Γ| = 1 and |H| = 1 over
the box, boxes straddling the boundary) — with the verdicts of the base commit f6db69e
(written by ``python analysis/bench_speed.py --parts verdicts --n-verdicts 400
--n-adversarial 300 --write-fixture tests/data/speed_verdicts.csv``).  Here every certificate
decides them again: a certified or not-certified verdict of the base must be the same now; a
base verdict left inconclusive that is now decided is checked against the truth (the point
certificates at members of the box for a certified box, the witness member's own point
certificate for a not-certified one; for ``check``, the rows on the Hurwitz boundary that main's
issue 29 item 7 decides, against g(ω) recomputed from Γ).
"""

import csv
from pathlib import Path

import numpy as np
import pytest

from stringstab.certify.api import certify, certify_batch, check
from stringstab.certify.sampled import check_members

DATA = Path(__file__).parents[1] / "data" / "speed_verdicts.csv"
BOX = dict(tau=(0.1, 0.2), delta=(0.15, 0.25), headway=(1.0, 1.2))
POINT = dict(tau=0.1, delta=0.2, headway=1.1)


def _g_exact(w, K, tau, delta, headway):
    """(|D(jω)|² − |N(jω)|²)/ω² of Γ (IDL eq 11) in extended precision, no toolkit code."""
    kx, kv, ka = (np.longdouble(k) for k in K)
    w = np.longdouble(w)
    c = kv + np.longdouble(headway) * kx
    dr, di = kx - w * w, w * (c - np.longdouble(tau) * w * w)
    dw = np.longdouble(delta) * w
    nr = kx - ka * w * w * np.cos(dw)
    ni = kv * w + ka * w * w * np.sin(dw)
    return float((dr * dr + di * di - nr * nr - ni * ni) / (w * w))


def rows(kind):
    with DATA.open(encoding="utf-8") as f:
        out = [r for r in csv.DictReader(f) if r["set"].split("_")[0] == kind]
    K = np.array([[float(r["k_x"]), float(r["k_v"]), float(r["k_a"])] for r in out])
    return K, np.array([r["base_verdict"] for r in out])


def decide(kind, K):
    if kind == "check":
        return check(*K.T, **POINT)
    if kind == "robust":
        return certify_batch(*K.T, **BOX)
    return certify_batch(*K.T, **BOX, sample_time=0.1, heterogeneous=kind == "sampled")


@pytest.mark.parametrize("kind", ["check", "robust", "sampled", "sampledhom"])
def test_decided_verdicts_are_unchanged_and_new_decisions_are_true(kind):
    K, base = rows(kind)
    assert len(K) >= 150
    now = decide(kind, K)
    v = np.asarray(now.verdict)
    decided = base != "inconclusive"
    assert np.array_equal(v[decided], base[decided]), kind
    for i in np.flatnonzero(~decided & (v != "inconclusive")):
        if kind == "check":
            # only main's issue 29 item 7 decides these: a row on the Hurwitz boundary
            # k_v + (T* − τ)k_x = 0 with a proven g(ω) < 0 is not certified (the same change
            # merged from main, not the speed work); g at the witness recomputed from Γ here
            assert v[i] == "not_certified", K[i]
            kx, kv = K[i][:2]
            assert abs(kv + (POINT["headway"] - POINT["tau"]) * kx) <= 1e-12 * (1 + abs(kv))
            # the witness frequency may be 0 (the limit ω → 0); g is continuous there
            w = max(float(now.witness_omega[i]), 1e-5)
            g = _g_exact(w, K[i], **POINT)
            assert g < 0 and g == pytest.approx(float(now.margin[i]), rel=1e-6), K[i]
            continue
        members = [(t, tp, d, h) for t in BOX["tau"] for tp in BOX["tau"]
                   for d in (0.15, 0.2, 0.25) for h in BOX["headway"]]
        if kind == "robust":
            if v[i] == "certified":
                for t, _, d, h in members:
                    assert certify(*K[i], tau=t, delta=d, headway=h).verdict == "certified"
            else:
                w = (now.witness_tau[i], now.witness_delta[i], now.witness_headway[i])
                assert certify(*K[i], tau=w[0], delta=w[1], headway=w[2]).verdict \
                    == "not_certified"
            continue
        if kind == "sampledhom":
            members = [m for m in members if m[0] == m[1]]
        if v[i] == "certified":
            M = np.array(members)
            k = np.repeat(K[i][None], len(M), axis=0)
            c, _, _ = check_members(*k.T.copy(), tau=M[:, 0], tau_prev=M[:, 1],
                                    delta=M[:, 2], headway=M[:, 3], H=0.1)
            assert np.all(c == 0), K[i]
        else:
            w = (now.witness_tau[i], now.witness_tau_prev[i], now.witness_delta[i],
                 now.witness_headway[i])
            p = certify(*K[i], tau=w[0], tau_prev=w[1], delta=w[2], headway=w[3],
                        sample_time=0.1)
            assert p.verdict == "not_certified", (K[i], w)
