"""Validation of the physical parameters shared by every analysis.

The three parameters of the IDL paper's vehicle model (eqs 3-9):

``tau``
    actuator lag τ in seconds, > 0 (eq 7);
``delta``
    communication delay δ in seconds on the predecessor's acceleration, ≥ 0 (eq 4);
``headway``
    desired time headway T* in seconds, ≥ 0 (eq 3).

Defaults follow the IDL paper's Table 2 (δ = 0.2 s, T* = 1.1 s); the paper does
not print τ, and τ = 0.1 s is the value used in its reference Zhou et al. (2020)
and throughout this toolkit's examples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from . import constants
from .errors import StringStabError, show

__all__ = [
    "DEFAULT_DELTA",
    "DEFAULT_HEADWAY",
    "DEFAULT_TAU",
    "Params",
    "as_gains",
    "check_params",
    "count",
    "positive",
]

DEFAULT_TAU = constants.TAU
DEFAULT_DELTA = constants.DELTA
DEFAULT_HEADWAY = constants.HEADWAY


@dataclass(frozen=True)
class Params:
    """Model parameters τ, δ, T* (IDL paper eqs 3-9), validated on construction.

    Examples
    --------
    >>> Params(tau=0.1, delta=0.2, headway=1.1)
    Params(tau=0.1, delta=0.2, headway=1.1)
    >>> Params(tau=-0.1, delta=0.2, headway=1.1)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: tau (actuator lag) must be a finite number > 0 s; got -0.1
    """

    tau: float = DEFAULT_TAU
    delta: float = DEFAULT_DELTA
    headway: float = DEFAULT_HEADWAY

    def __post_init__(self) -> None:
        check_params(self.tau, self.delta, self.headway)

    def as_dict(self) -> dict[str, float]:
        """The parameters as a plain dict (for JSON and file metadata)."""
        return {"tau": float(self.tau), "delta": float(self.delta), "headway": float(self.headway)}


def positive(name: str, value: Any, *, allow_zero: bool = False, unit: str = "") -> float:
    """``value`` as a float that is finite and > 0 (≥ 0 with ``allow_zero``).

    The one check behind every step size, lag, margin and tolerance of the
    toolkit; ``unit`` (e.g. ``" s"``) is appended to the expectation.

    Raises
    ------
    StringStabError
        Saying what was expected and what was found.

    Examples
    --------
    >>> positive("dt", "0.1", unit=" s")
    0.1
    >>> positive("dt", 0, unit=" s")
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: dt must be a finite number > 0 s; got 0
    """
    try:
        x = float(value)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"{name} must be a number; got {show(value)}") from e
    if not (math.isfinite(x) and (x >= 0 if allow_zero else x > 0)):
        op = ">=" if allow_zero else ">"
        raise StringStabError(f"{name} must be a finite number {op} 0{unit}; got {show(value)}")
    return x


def count(name: str, value: Any) -> int:
    """``value`` as an int that is >= 1 (a number of vehicles, platoons, steps).

    Raises
    ------
    StringStabError
        Unless ``value`` is an integer (or an integral number) >= 1.

    Examples
    --------
    >>> count("n_followers", 4)
    4
    >>> count("n_followers", 2.5)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: n_followers must be an integer >= 1; got 2.5
    """
    try:
        n = int(value)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"{name} must be an integer >= 1; got {show(value)}") from e
    if n < 1 or n != value:
        raise StringStabError(f"{name} must be an integer >= 1; got {show(value)}")
    return n


def _finite(name: str, value: Any) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"{name} must be a number; got {show(value)}") from e
    if not math.isfinite(x):
        raise StringStabError(f"{name} must be finite; got {show(value)}")
    return x


def check_params(tau: Any, delta: Any, headway: Any) -> tuple[float, float, float]:
    """Validate τ > 0, δ ≥ 0, T* ≥ 0 and return them as floats.

    Raises
    ------
    StringStabError
        If any parameter is not a finite number in its range.
    """
    t = _finite("tau (actuator lag)", tau)
    if not t > 0:
        raise StringStabError(f"tau (actuator lag) must be a finite number > 0 s; got {show(tau)}")
    d = _finite("delta (communication delay)", delta)
    if d < 0:
        raise StringStabError(f"delta (communication delay) must be >= 0 s; got {show(delta)}")
    h = _finite("headway (desired time headway T*)", headway)
    if h < 0:
        raise StringStabError(f"headway (desired time headway T*) must be >= 0 s; got {show(headway)}")
    return t, d, h


def as_gains(
    k_x: Any, k_v: Any, k_a: Any
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Broadcast three gain arrays to a common shape and check they are finite.

    Raises
    ------
    StringStabError
        If the gains are not numeric, cannot be broadcast, or contain NaN/inf.
    """
    try:
        arrs = np.broadcast_arrays(
            *(np.asarray(g, dtype=np.float64) for g in (k_x, k_v, k_a))
        )
    except (TypeError, ValueError) as e:
        raise StringStabError(
            f"gains k_x, k_v, k_a must be numbers or numeric arrays of one shape; got {e}"
        ) from e
    for name, a in zip(("k_x", "k_v", "k_a"), arrs):
        bad = ~np.isfinite(a)
        if bad.any():
            idx = np.argwhere(bad)[0]
            where = f" at index {tuple(int(i) for i in idx)}" if a.ndim else ""
            raise StringStabError(f"{name} must be finite{where}; got {show(float(a[tuple(idx)]))}")
    return arrs[0], arrs[1], arrs[2]
