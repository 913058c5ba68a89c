"""The CAV put in place of recorded followers: its parameters and the string with it.

A CAV runs the predecessor-following eq-4 law (IDL eq 4) with its own τ, δ, T* and gains
within bounds (:class:`CavSpec`); :func:`string_with_cavs` puts CAVs at given positions of a
recorded string (the leader is 0; :func:`check_positions` says which positions are valid).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from .. import constants
from ..certify.head_to_tail import Vehicle
from ..errors import StringStabError, show
from ..params import Params

__all__ = ["CavSpec", "check_positions", "string_with_cavs"]


@dataclass(frozen=True)
class CavSpec:
    """The CAV: its parameters (fixed) and the bounds of its gains (designed).

    Attributes
    ----------
    tau : float
        Actuator lag τ, s (default the toolkit's 0.1 s).
    delta : float
        Communication delay δ on the predecessor's acceleration, s (IDL Table 2: 0.2 s).
    headway : float
        Desired time headway T*, s (IDL Table 2: 1.1 s).
    reaction_delay : float
        The CAV's reaction (actuation) delay θ_r, s (issue 25; default 0).
    bounds : (float, float)
        Bounds of each gain (IDL Table 2: [−2, 2]).
    min_kx : float
        The least k_x, 1/s² (default 0.01: a spacing error decays within about 10 s).  With
        k_x → 0 the CAV stops holding its gap: it then filters its predecessor's speed ever
        more slowly and the string's sup ∏|Γ_i| creeps towards 1 — a CAV in name only.
    hurwitz_margin : float
        Lower bound of the CAV's Hurwitz conditions k_x and k_v + (T* − τ)k_x in the NLP.
    standstill : float
        l_0 of the CAV's spacing policy, m (simulation only).
    name : str
        The CAV's name in outputs.
    """

    tau: float = constants.TAU
    delta: float = constants.DELTA
    headway: float = constants.HEADWAY
    reaction_delay: float = 0.0
    bounds: tuple[float, float] = constants.GAIN_BOUNDS
    min_kx: float = 0.01
    hurwitz_margin: float = 1e-3
    standstill: float = 2.0
    name: str = "CAV"

    def params(self) -> Params:
        """τ, δ, T*, θ_r as checked :class:`~stringstab.params.Params`."""
        return Params(self.tau, self.delta, self.headway, self.reaction_delay)

    def lower(self) -> npt.NDArray[np.float64]:
        """The lower bounds of (k_x, k_v, k_a): k_x ≥ max(bounds[0], min_kx).

        Returns
        -------
        ndarray, shape (3,)
        """
        lo = self.bounds[0]
        return np.array([max(lo, self.min_kx), lo, lo])

    def upper(self) -> npt.NDArray[np.float64]:
        """The upper bounds of (k_x, k_v, k_a).

        Returns
        -------
        ndarray, shape (3,)
        """
        return np.full(3, float(self.bounds[1]))

    def clip(self, K: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """K within the bounds (:meth:`lower`, :meth:`upper`).

        Parameters
        ----------
        K : array_like, shape (..., 3)
            Gains.

        Returns
        -------
        ndarray
        """
        return np.asarray(np.clip(np.asarray(K, dtype=float), self.lower(), self.upper()))

    def vehicle(self, K: Any) -> Vehicle:
        """The CAV with gains K = (k_x, k_v, k_a).

        Parameters
        ----------
        K : sequence of float
            The gains.

        Returns
        -------
        Vehicle
        """
        return Vehicle(float(K[0]), float(K[1]), float(K[2]), self.params(), self.name)


def string_with_cavs(vehicles: Sequence[Vehicle], positions: Sequence[int],
                     gains: Sequence[Any], spec: CavSpec) -> tuple[Vehicle, ...]:
    """The string with the followers at ``positions`` replaced by CAVs with ``gains``.

    Parameters
    ----------
    vehicles : sequence of Vehicle
        The recorded followers, positions 1..N.
    positions : sequence of int
        1-based positions.
    gains : sequence of (k_x, k_v, k_a)
        One per position.
    spec : CavSpec
        The CAV's parameters.

    Returns
    -------
    tuple of Vehicle
    """
    out = list(vehicles)
    for p, K in zip(positions, gains):
        out[p - 1] = spec.vehicle(K)
    return tuple(out)


def check_positions(positions: Sequence[int], n: int) -> tuple[int, ...]:
    """The CAV positions checked: integers within 1..n (the leader is 0), distinct, sorted.

    Parameters
    ----------
    positions : sequence of int
        1-based follower positions.
    n : int
        The string's length.

    Returns
    -------
    tuple of int
        Sorted.

    Raises
    ------
    StringStabError
        On a position outside 1..n, not an integer, repeated, or none at all.

    Examples
    --------
    >>> check_positions([3, 1], 5)
    (1, 3)
    >>> check_positions([6], 5)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: a CAV position must be a follower's position 1..5 (the leader is 0); got 6
    """
    out = []
    for p in positions:
        if isinstance(p, bool) or not float(p).is_integer() or not 1 <= int(p) <= n:
            raise StringStabError(f"a CAV position must be a follower's position 1..{n} "
                                  f"(the leader is 0); got {show(p)}")
        out.append(int(p))
    if not out:
        raise StringStabError("expected at least one CAV position; got none")
    if len(set(out)) != len(out):
        raise StringStabError(f"CAV positions must be distinct; got {out}")
    return tuple(sorted(out))
