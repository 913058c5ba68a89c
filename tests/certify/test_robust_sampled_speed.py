"""The robust sampled certificate after the speed work (issue 31): the same verdicts, the same cells.

``robust_sampled_verdicts_031c8b1.npz`` holds 480 gain triples (random, the adversarial rows
of ``tests/data/speed_verdicts.csv``, and the refinement's stragglers) with the verdicts of
main at 031c8b1, before the change, over four boxes (written by
``PYTHONPATH=<main> python analysis/robust_sampled_verdicts.py <file>``): every verdict,
inconclusive included, must be the same now.  The cells the search computes ahead
(``sampled_split_cells.CellCache``) must be, bit for bit, the cells computed directly.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stringstab.certify.api import certify_batch
from stringstab.certify.sampled_split_cells import (
    CellCache,
    FollowerCells,
    PredecessorCells,
    halves,
)

DATA = Path(__file__).parent / "robust_sampled_verdicts_031c8b1.npz"
BOXES = {
    "hetero": dict(tau=(0.1, 0.2), delta=(0.15, 0.25), headway=(1.0, 1.2), sample_time=0.1),
    "hom": dict(tau=(0.1, 0.2), delta=(0.15, 0.25), headway=(1.0, 1.2), sample_time=0.1,
                heterogeneous=False),
    "pieces": dict(tau=(0.1, 0.15), delta=(0.05, 0.32), headway=(0.9, 1.4), sample_time=0.1),
    "delay": dict(tau=0.1, delta=(0.1, 0.3), headway=1.1, sample_time=0.05),
}


@pytest.mark.parametrize("name", list(BOXES))
def test_every_verdict_is_main_s(name, monkeypatch):
    data = np.load(DATA)
    K, base = data["K"], data[name]
    assert K.shape == (480, 3) and base.shape == (480,)
    served = [0]
    orig = CellCache._assemble

    def count(chunks, loc):
        served[0] += len(loc)
        return orig(chunks, loc)

    monkeypatch.setattr(CellCache, "_assemble", staticmethod(count))
    now = np.asarray(certify_batch(*K.T, **BOXES[name]).verdict).astype(str)
    changed = np.flatnonzero(now != base)
    assert changed.size == 0, [(K[i].tolist(), base[i], now[i]) for i in changed[:5]]
    if name != "delay":  # a box of τ or T*: the stragglers' cells were computed ahead
        assert served[0] > 0


def _fields(x):
    return {k: getattr(x, k) for k in x.__dataclass_fields__}


def test_cells_computed_ahead_are_the_cells_computed_directly():
    rng = np.random.default_rng(5)
    n = 3
    kx, kv, ka = rng.uniform(-2, 2, (3, n))
    H, ends = 0.1, [(1, 0.5), (2, 0.0), (2, 0.25)]
    cache = CellCache(kx, kv, ka, H, ends)
    # a few cells (items 0-2): computed with their halves and quarters
    owner = np.array([0, 1, 2, 2])
    tau = np.array([[0.1, 0.15], [0.15, 0.2], [0.1, 0.125], [0.125, 0.2]])
    hd = np.array([[1.0, 1.1], [1.1, 1.2], [1.0, 1.2], [1.05, 1.05]])
    first = cache.follower(owner, tau, hd)
    assert len(cache.f_chunks) == 1
    for k, v in _fields(FollowerCells.of(owner, kx, kv, H=H, tau=tau, headway=hd)).items():
        assert np.array_equal(_fields(first)[k], v), k
    # their halves along τ, then along T* of a half: served, not computed
    t_a, t_b = halves(tau)
    own2 = np.concatenate([owner, owner, owner[:1]])
    t2 = np.concatenate([t_a, t_b, t_a[:1]])
    h_a, _ = halves(hd[:1])
    h2 = np.concatenate([hd, hd, h_a])
    got = cache.follower(own2, t2, h2)
    assert len(cache.f_chunks) == 1
    for k, v in _fields(FollowerCells.of(own2, kx, kv, H=H, tau=t2, headway=h2)).items():
        assert np.array_equal(_fields(got)[k], v), k
    # predecessor cells: the owner is the caller's, the rest the direct computation's
    gains = np.array([0, 1, 2])
    tp = np.array([[0.1, 0.2], [0.1, 0.15], [0.15, 0.2]])
    end = np.array([0, 2, 1])
    cache.predecessor(gains + 10, gains, tp, end)
    q_a, q_b = halves(tp)
    g2, tp2, e2 = np.tile(gains, 2), np.concatenate([q_b, q_a]), np.tile(end, 2)
    got = cache.predecessor(g2 + 7, g2, tp2, e2)
    assert len(cache.g_chunks) == 1
    want = PredecessorCells.of(g2 + 7, g2, kx, kv, ka, H=H, tau_p=tp2, end=e2, ends=ends)
    for k, v in _fields(want).items():
        assert np.array_equal(_fields(got)[k], v), k
    # no new cell: empty cells of the right shapes, nothing computed
    none = cache.follower(owner[:0], tau[:0], hd[:0])
    assert len(none) == 0 and none.V.shape == (0, 6, 3)
