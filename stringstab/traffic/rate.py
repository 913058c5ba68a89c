"""The gain rate limit (not in the paper): :func:`limit_rate`.

Each executed gain stays within r of the previous step's, so a policy cannot jump between
distant certified triples; the repair (:mod:`stringstab.tuning.repair`) still certifies the
result.  Applied by the action wrapper :class:`stringstab.rl.envs.RepairedGains` in training,
and identically in evaluation.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

__all__ = ["limit_rate"]

Array = npt.NDArray[np.float64]


def limit_rate(gains: npt.ArrayLike, prev_gains: npt.ArrayLike, rate: float, *,
               fresh: npt.ArrayLike | bool = False) -> Array:
    """Clip each gain to within ``rate`` of the previous step's (a gain rate limit; not in the paper).

    Rows where ``fresh`` is true (an episode's first step: no previous gains) are left as
    they are.  The result still needs the repair: the rate limit keeps the gains near a
    certified triple, it does not certify them.

    Parameters
    ----------
    gains : array_like, shape (..., 3)
        The proposed gains (k_x, k_v, k_a) of IDL eq 4 (the policy's action, eq 17).
    prev_gains : array_like, shape (..., 3)
        The gains executed at the previous step.
    rate : float
        The largest change r of each gain per step (in the gain's unit per step).
    fresh : array_like of bool, shape (...), or bool
        True where there are no previous gains (the proposed gains pass unchanged).

    Returns
    -------
    ndarray, shape (..., 3)
        clip(gains, prev_gains − r, prev_gains + r), or ``gains`` where ``fresh``.

    Examples
    --------
    >>> limit_rate([[1.5, 0.0, 0.3]], [[1.0, 0.1, 0.3]], 0.2).tolist()
    [[1.2, 0.0, 0.3]]
    """
    K = np.asarray(gains, dtype=np.float64)
    P = np.asarray(prev_gains, dtype=np.float64)
    out = np.clip(K, P - rate, P + rate)
    f = np.asarray(fresh, dtype=bool)
    return np.asarray(np.where(f[..., None] if f.ndim else f, K, out))
