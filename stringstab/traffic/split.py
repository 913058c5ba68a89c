"""A reproducible train/test split of leaders or leader–follower pairs."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TypeVar

import numpy as np

from ..errors import StringStabError, show

__all__ = ["train_test_split"]

T = TypeVar("T")


def train_test_split(
    items: Sequence[T], *, test_fraction: float = 0.3, seed: int = 0, shuffle: bool = True
) -> tuple[list[T], list[T]]:
    """Split items (trajectories, pairs, ...) into train and test lists, reproducibly.

    The IDL paper uses 900 training and 386 testing pairs (test fraction ≈ 0.3).

    Parameters
    ----------
    items : sequence
        At least two items.
    test_fraction : float
        In (0, 1); the test list gets ``round(test_fraction·n)`` items, at least one, and the
        training list at least one.
    seed : int
        Seed of the shuffle.
    shuffle : bool
        If False, the last items are the test set (a chronological split).

    Returns
    -------
    (list, list)
        The train items and the test items.

    Examples
    --------
    >>> train_test_split(list(range(10)), test_fraction=0.3, shuffle=False)
    ([0, 1, 2, 3, 4, 5, 6], [7, 8, 9])
    """
    n = len(items)
    if n < 2:
        raise StringStabError(f"train_test_split needs at least 2 items; got {n}")
    if not (0.0 < test_fraction < 1.0):
        raise StringStabError(f"test_fraction must be in (0, 1); got {show(test_fraction)}")
    n_test = min(max(round(test_fraction * n), 1), n - 1)
    order = np.random.default_rng(seed).permutation(n) if shuffle else np.arange(n)
    return [items[i] for i in order[: n - n_test]], [items[i] for i in order[n - n_test:]]
