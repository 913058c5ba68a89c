"""Checks of the tuning's inputs: gains, bounds and weights (one clear error each)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError

__all__ = ["GAIN_NAMES", "as_bounds", "as_k0", "as_weights"]

Array = npt.NDArray[np.float64]

#: The gains, in the order of K = [k_x, k_v, k_a] (IDL eq 4).
GAIN_NAMES = ("k_x", "k_v", "k_a")


def as_k0(K0: Any) -> Array:
    """K0 as a float array of shape (3,), or a StringStabError.

    Parameters
    ----------
    K0 : array_like
        The gains to repair, (k_x [1/s²], k_v [1/s], k_a [-]) of IDL eq 4.

    Returns
    -------
    ndarray, shape (3,)
        The gains as floats.

    Raises
    ------
    StringStabError
        If K0 is not three numbers or one of them is not finite.
    """
    try:
        k = np.asarray(K0, dtype=float)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"K0 must be three numbers (k_x, k_v, k_a); got {K0!r}") from e
    if k.shape != (3,):
        raise StringStabError(
            f"K0 must be three numbers (k_x, k_v, k_a); got an array of shape {k.shape}"
        )
    for name, v in zip(GAIN_NAMES, k):
        if not math.isfinite(v):
            raise StringStabError(f"K0: {name} must be finite; got {v!r}")
    return k


def as_bounds(bounds: Any) -> tuple[float, float]:
    """``(lower, upper)`` as finite floats with lower < upper, or a StringStabError.

    Parameters
    ----------
    bounds : pair of numbers
        The box every gain of the repair must stay in, (lower, upper); the same bounds for k_x,
        k_v and k_a (the IDL paper searches [−2, 2]).

    Returns
    -------
    tuple of float
        ``(lower, upper)``.

    Raises
    ------
    StringStabError
        If ``bounds`` is not a pair of numbers, a bound is not finite, or lower ≥ upper.
    """
    try:
        lo, hi = (float(b) for b in bounds)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"bounds must be a pair (lower, upper); got {bounds!r}") from e
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise StringStabError(f"bounds must be finite with lower < upper; got {bounds!r}")
    return lo, hi


def as_weights(weights: Any) -> Array:
    """Three finite weights > 0 as an array, or a StringStabError.

    Parameters
    ----------
    weights : array_like
        The weights (w_x, w_v, w_a) of the distance ‖K − K0‖_W = sqrt(Σ w_i (K_i − K0_i)²) the
        repair minimises, one per gain in the order (k_x, k_v, k_a).

    Returns
    -------
    ndarray, shape (3,)
        The weights as floats.

    Raises
    ------
    StringStabError
        If ``weights`` is not three finite numbers > 0.
    """
    try:
        w = np.asarray(weights, dtype=float)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"weights must be three positive numbers; got {weights!r}") from e
    if w.shape != (3,) or not np.all(np.isfinite(w)) or not np.all(w > 0):
        raise StringStabError(f"weights must be three finite numbers > 0; got {weights!r}")
    return w
