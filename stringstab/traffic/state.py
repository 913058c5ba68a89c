"""The policy's state: IDL eq 16 (:func:`state_vector`) and its extensions (:func:`extend_state`).

s = [Δp/α_p, Δv/α_v, a_{i−1}(t − δ)/α_acc] with Δp = gap − (T* v + l_0), α_p = 25,
α_v = 2.5, α_acc = 4.5 (Table 2).  Optionally (``observe``, not in the paper) the follower's
own acceleration a_i/α_acc and the gains it executed at the previous step (K_{t−1}/2, zero at
an episode's first step) are appended: the eq-16 state does not say what the vehicle is doing
now, which the comfort reward (eq 21) penalises changes of, nor which gains it runs, which a
gain rate limit makes part of the dynamics.  Used by the environments
(:mod:`stringstab.traffic.env`), the trained policies and their evaluation.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ..constants import STATE_SCALES
from ..errors import StringStabError
from ..params import DEFAULT_HEADWAY
from .controllers.base import DEFAULT_STANDSTILL, Observation

__all__ = ["GAIN_SCALE", "OBSERVE", "SCALES", "extend_state", "state_dim", "state_vector"]

#: What may be appended to the eq-16 state (``observe``): own acceleration, previous gains.
OBSERVE = ("accel", "gains")
#: Scale of the previous gains in the state (the half-range of Table 2's [−2, 2]).
GAIN_SCALE = 2.0
#: α_p, α_v, α_acc of eq 16 (Table 2).
SCALES = STATE_SCALES

Array = npt.NDArray[np.float64]


def state_vector(obs: Observation, *, headway: float = DEFAULT_HEADWAY,
                 standstill: float = DEFAULT_STANDSTILL,
                 scales: tuple[float, float, float] = SCALES) -> Array:
    """The IDL state (eq 16) of every follower in ``obs``, shape ``(*obs.gap.shape, 3)``.

    s = [(gap − T* v − l_0)/α_p, (v_{i−1} − v)/α_v, a_{i−1}(t − δ)/α_acc].  Usable as the input
    of a gain policy inside :class:`~stringstab.traffic.controllers.TimeVaryingLinearController`.

    Parameters
    ----------
    obs : Observation
        What the followers know at one step: gap Δx (m), own speed v (m/s), relative speed
        Δv = v_{i−1} − v (m/s) and the delayed predecessor acceleration a_{i−1}(t − δ) (m/s²).
    headway : float
        Desired time headway T* (IDL eq 3), s.
    standstill : float
        Standstill distance l_0 (eq 3), m.
    scales : (float, float, float)
        α_p (m), α_v (m/s), α_acc (m/s²) of eq 16 (Table 2: 25, 2.5, 4.5).

    Returns
    -------
    ndarray, shape ``(*obs.gap.shape, 3)``
        The normalised state [Δp/α_p, Δv/α_v, a_{i−1}(t − δ)/α_acc], Δp the spacing error of
        eq 3.
    """
    dp = obs.gap - headway * obs.speed - standstill
    return np.stack([dp / scales[0], obs.rel_speed / scales[1],
                     obs.pred_accel_delayed / scales[2]], axis=-1)


def state_dim(observe: Sequence[str] = ()) -> int:
    """Length of the state with the ``observe`` extras (:func:`extend_state`).

    It is 3 (eq 16), 1 more for ``"accel"`` and 3 more for ``"gains"``.

    Parameters
    ----------
    observe : sequence of str
        Extras appended to the eq-16 state, some of :data:`OBSERVE` (``"accel"``, ``"gains"``).

    Returns
    -------
    int
        3, 4, 6 or 7.

    Raises
    ------
    StringStabError
        If ``observe`` names something other than ``"accel"`` or ``"gains"``.

    Examples
    --------
    >>> state_dim(), state_dim(("accel", "gains"))
    (3, 7)
    """
    unknown = sorted(set(observe) - set(OBSERVE))
    if unknown:
        raise StringStabError(f"observe must name some of {list(OBSERVE)}; got {unknown}")
    return 3 + ("accel" in observe) + 3 * ("gains" in observe)


def extend_state(state: npt.ArrayLike, *, observe: Sequence[str] = (),
                 accel: npt.ArrayLike | None = None, prev_gains: npt.ArrayLike | None = None,
                 scales: tuple[float, float, float] = SCALES) -> Array:
    """The eq-16 ``state`` (..., 3) with the ``observe`` extras appended (not in the paper).

    ``"accel"`` appends the follower's own acceleration a_i/α_acc (``accel``, shape ``(...)``),
    ``"gains"`` the gains executed at the previous step K_{t−1}/2 (``prev_gains``, (..., 3)).

    Parameters
    ----------
    state : array_like, shape (..., 3)
        The normalised IDL state of eq 16 (:func:`state_vector`).
    observe : sequence of str
        Extras to append, some of :data:`OBSERVE`, always in the order accel, then gains.
    accel : array_like, shape (...), optional
        The follower's own acceleration a_i, m/s²; needed for ``"accel"``.
    prev_gains : array_like, shape (..., 3), optional
        The gains (k_x [1/s²], k_v [1/s], k_a [-]) executed at the previous step; needed for
        ``"gains"`` (zeros at an episode's first step).
    scales : (float, float, float)
        α_p, α_v, α_acc of eq 16; only α_acc is used here.

    Returns
    -------
    ndarray, shape (..., :func:`state_dim` (observe))
        The extended state (``state`` itself, as floats, when ``observe`` is empty).

    Raises
    ------
    StringStabError
        If ``observe`` names an unknown extra, or an extra's input is missing.

    Examples
    --------
    >>> extend_state([[0.1, 0.2, 0.3]], observe=("accel", "gains"), accel=[0.9],
    ...              prev_gains=[[1.0, 0.5, -0.4]]).round(2).tolist()
    [[0.1, 0.2, 0.3, 0.2, 0.5, 0.25, -0.2]]
    """
    s = np.asarray(state, dtype=np.float64)
    state_dim(observe)  # checks the names
    parts = [s]
    if "accel" in observe:
        if accel is None:
            raise StringStabError("observe 'accel' needs the follower's acceleration")
        parts.append(np.asarray(accel, dtype=np.float64)[..., None] / scales[2])
    if "gains" in observe:
        if prev_gains is None:
            raise StringStabError("observe 'gains' needs the previous gains")
        parts.append(np.asarray(prev_gains, dtype=np.float64) / GAIN_SCALE)
    return np.concatenate(parts, axis=-1) if len(parts) > 1 else s
