"""`Loop.check_rows` (the repair's way in) against `Loop.check`, and the cells' pending mask.

Truth: `Loop.check` of the same columns (the generic way in, with `gains()`' checks): every
field of the result equal bit for bit, continuous and sampled; the errors of `check` for
rows it refuses.  For `CertifiedCells`: the block structure written out here.
"""

import dataclasses

import numpy as np
import pytest

from stringstab.certify.api import Loop
from stringstab.certify.gain_cells import BLOCK_SIDE, CertifiedCells
from stringstab.errors import StringStabError
from stringstab.params import Params

RNG = np.random.default_rng(31)


def same(a, b):
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and x.shape == y.shape, f.name
            assert x.tobytes() == y.tobytes(), f.name
        else:
            assert x == y, f.name


@pytest.mark.parametrize("H", [None, 0.1])
def test_check_rows_is_check_bit_for_bit(H):
    """Rows near the certified region's boundary, 1 to 3 per call as the repair asks, and one
    call of 40: every verdict, margin and witness equal to `check`'s of the columns."""
    loop = Loop.of(0.1, 0.2, 1.1, sample_time=H)
    K = np.array([1.2, 0.5, 0.6]) + RNG.uniform(-0.6, 0.6, (40, 3))
    seen = set()
    for rows in (K[:1], K[1:3], K[3:6], K):
        c, r = loop.check(rows[:, 0], rows[:, 1], rows[:, 2]), loop.check_rows(rows)
        same(c, r)
        seen |= set(r.verdict.tolist())
    assert {"certified", "not_certified"} <= seen  # both sides of the boundary exercised


def test_check_rows_refuses_as_check():
    """Non-finite or out-of-range rows take `check`'s way and raise its error; a wrong shape
    is refused; no rows give no verdicts."""
    loop = Loop.of(0.1, 0.2, 1.1, sample_time=0.1)
    for bad in (np.nan, np.inf, 1e300):
        K = np.array([[1.2, 0.5, 0.6], [1.0, bad, 0.2]])
        with pytest.raises(StringStabError) as e1:
            loop.check(K[:, 0], K[:, 1], K[:, 2])
        with pytest.raises(StringStabError) as e2:
            loop.check_rows(K)
        assert str(e1.value) == str(e2.value)
    with pytest.raises(StringStabError, match=r"shape \(n, 3\)"):
        loop.check_rows(np.zeros((2, 2)))
    assert loop.check_rows(np.zeros((0, 3))).verdict.shape == (0,)


def test_pending_is_candidates_of_blocks_not_done():
    """After lookups in a few blocks, `pending` is (candidate) & (its block not done), the
    block of cell (i, j, k) being (i, j, k) // BLOCK_SIDE; a second lookup proves nothing."""
    n = 41
    cand = RNG.uniform(size=(n - 1,) * 3) < 0.3
    cells = CertifiedCells(-2.0, 2.0, n, Params(0.1, 0.2, 1.1), candidates=cand)
    K = RNG.uniform(-2.0, 2.0, (6, 3))
    first = cells.contains(K)
    m, b = n - 1, -(-(n - 1) // BLOCK_SIDE)
    ijk = np.stack(np.meshgrid(*[np.arange(m)] * 3, indexing="ij"), -1).reshape(-1, 3)
    bl = ijk // BLOCK_SIDE
    block = (bl[:, 0] * b + bl[:, 1]) * b + bl[:, 2]
    assert 0 < cells.done.sum() <= 6
    np.testing.assert_array_equal(cells.pending, cand.reshape(-1) & ~cells.done[block])
    blocks = cells.blocks
    np.testing.assert_array_equal(cells.contains(K), first)
    assert cells.blocks == blocks
