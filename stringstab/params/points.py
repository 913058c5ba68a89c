"""The model's parameters at a point: :class:`Params` and the checks of one value.

The three parameters of the IDL paper's vehicle model (eqs 3-9):

``tau``
    actuator lag τ in seconds, > 0 (eq 7);
``delta``
    communication delay δ in seconds on the predecessor's acceleration, ≥ 0 (eq 4);
``headway``
    desired time headway T* in seconds, ≥ 0 (eq 3);
``reaction_delay``
    reaction (actuation) delay θ_r in seconds, ≥ 0, on the whole command (issue 25:
    τ a' = u(t − θ_r) − a); 0 by default, today's model, and then left out of every output.

Here: :class:`Params` (every value a point), the checks of one number (:func:`positive`,
:func:`finite`, :func:`count`, :func:`check_params`, :func:`check_reaction_delay`,
:func:`sample_time`) and of the gains (:func:`as_gains`).  Intervals and their boxes are
:mod:`stringstab.params.intervals`.

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

from .. import constants
from ..errors import StringStabError, show
from ..ranges import RANGES, check_magnitude

__all__ = [
    "DEFAULT_DELTA",
    "DEFAULT_HEADWAY",
    "DEFAULT_TAU",
    "Params",
    "as_gains",
    "check_params",
    "check_reaction_delay",
    "count",
    "finite",
    "positive",
    "sample_time",
]

DEFAULT_TAU = constants.TAU
DEFAULT_DELTA = constants.DELTA
DEFAULT_HEADWAY = constants.HEADWAY

@dataclass(frozen=True)
class Params:
    """Model parameters τ, δ, T* (IDL paper eqs 3-9) and θ_r (issue 25), validated on construction.

    ``reaction_delay`` (θ_r) is left out of the repr and of :meth:`as_dict` when it is 0, so
    every output of a θ_r = 0 model is what it was before θ_r existed.

    Examples
    --------
    >>> Params(tau=0.1, delta=0.2, headway=1.1)
    Params(tau=0.1, delta=0.2, headway=1.1)
    >>> Params(tau=0.1, delta=0.2, headway=1.1, reaction_delay=0.3)
    Params(tau=0.1, delta=0.2, headway=1.1, reaction_delay=0.3)
    >>> Params(tau=-0.1, delta=0.2, headway=1.1)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: tau (actuator lag) must be a finite number > 0 s; got -0.1
    """

    tau: float = DEFAULT_TAU
    delta: float = DEFAULT_DELTA
    headway: float = DEFAULT_HEADWAY
    reaction_delay: float = 0.0

    def __post_init__(self) -> None:
        # checked once, here, and kept as the floats checked (so Params("0.1", ...) holds 0.1)
        for name, value in zip(("tau", "delta", "headway"),
                               check_params(self.tau, self.delta, self.headway)):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "reaction_delay", check_reaction_delay(self.reaction_delay))

    def __repr__(self) -> str:
        extra = f", reaction_delay={self.reaction_delay!r}" if self.reaction_delay else ""
        return f"Params(tau={self.tau!r}, delta={self.delta!r}, headway={self.headway!r}{extra})"

    def as_dict(self) -> dict[str, float]:
        """The parameters as a plain dict (for JSON and file metadata); θ_r only when > 0."""
        out = {"tau": float(self.tau), "delta": float(self.delta), "headway": float(self.headway)}
        if self.reaction_delay:
            out["reaction_delay"] = float(self.reaction_delay)
        return out


def positive(name: str, value: Any, *, allow_zero: bool = False, unit: str = "") -> float:
    """``value`` as a float that is finite and > 0 (≥ 0 with ``allow_zero``).

    The one check behind every step size, lag, margin and tolerance of the
    toolkit; ``unit`` (e.g. ``" s"``) is appended to the expectation.

    Parameters
    ----------
    name : str
        What the value is, for the error message.
    value : object
        Anything ``float()`` accepts.
    allow_zero : bool
        Accept 0 as well.
    unit : str
        Unit appended to the expectation in the message (e.g. ``" s"``).

    Returns
    -------
    float
        ``value`` as a float.

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

    Parameters
    ----------
    name : str
        What the value is, for the error message.
    value : object
        An int, or a number equal to an int.

    Returns
    -------
    int
        ``value`` as an int ≥ 1.

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
    if isinstance(value, bool):  # True == 1, but a flag is not a count
        raise StringStabError(f"{name} must be an integer >= 1; got {show(value)}")
    try:
        n = int(value)
    except (TypeError, ValueError, OverflowError) as e:
        raise StringStabError(f"{name} must be an integer >= 1; got {show(value)}") from e
    if n < 1 or n != value:
        raise StringStabError(f"{name} must be an integer >= 1; got {show(value)}")
    return n


def finite(name: str, value: Any) -> float:
    """``value`` as a finite float.

    Parameters
    ----------
    name : str
        What the value is, for the error message.
    value : Any
        A number, or a string or object :func:`float` accepts.

    Returns
    -------
    float

    Raises
    ------
    StringStabError
        On a value that is not a number, or not finite.

    Examples
    --------
    >>> finite("tau", "0.1")
    0.1
    """
    try:
        x = float(value)
    except (TypeError, ValueError) as e:
        raise StringStabError(f"{name} must be a number; got {show(value)}") from e
    if not math.isfinite(x):
        raise StringStabError(f"{name} must be finite; got {show(value)}")
    return x


def check_params(tau: Any, delta: Any, headway: Any) -> tuple[float, float, float]:
    """Validate τ > 0, δ ≥ 0, T* ≥ 0 and return them as floats.

    Parameters
    ----------
    tau : object
        Actuator lag τ, s (IDL eq 7); must be > 0.
    delta : object
        Communication delay δ, s (IDL eq 4); must be ≥ 0.
    headway : object
        Desired time headway T*, s (IDL eq 3); must be ≥ 0.

    Returns
    -------
    tau, delta, headway : float
        The checked values (each also within the magnitudes of :mod:`stringstab.ranges`).

    Raises
    ------
    StringStabError
        If any parameter is not a finite number in its range.
    """
    t = finite("tau (actuator lag)", tau)
    if not t > 0:
        raise StringStabError(f"tau (actuator lag) must be a finite number > 0 s; got {show(tau)}")
    d = finite("delta (communication delay)", delta)
    if d < 0:
        raise StringStabError(f"delta (communication delay) must be >= 0 s; got {show(delta)}")
    h = finite("headway (desired time headway T*)", headway)
    if h < 0:
        raise StringStabError(f"headway (desired time headway T*) must be >= 0 s; got {show(headway)}")
    for kind, x in (("tau", t), ("delta", d), ("headway", h)):
        check_magnitude(kind, x)
    return t, d, h


def check_reaction_delay(value: Any, name: str = "reaction_delay (reaction delay θ_r)") -> float:
    """The reaction (actuation) delay θ_r as a float: finite, ≥ 0 s and ≤ 100 s.

    The one check of θ_r (issue 25), behind :class:`Params` and :class:`~stringstab.params.intervals.Box`; the bound is
    :data:`stringstab.ranges.RANGES` ``["reaction_delay"]``.

    Parameters
    ----------
    value : object
        θ_r in s (anything ``float()`` accepts).
    name : str
        What the value is called in the message.

    Returns
    -------
    float
        θ_r.

    Raises
    ------
    StringStabError
        Saying what was expected and what was found.

    Examples
    --------
    >>> check_reaction_delay("0.2")
    0.2
    >>> check_reaction_delay(-0.1)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: reaction_delay (reaction delay θ_r) must be a finite number >= 0 s; got -0.1
    """
    return check_magnitude("reaction_delay", positive(name, value, allow_zero=True, unit=" s"),
                           name=name)


def as_gains(
    k_x: Any, k_v: Any, k_a: Any
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Broadcast three gain arrays to a common shape and check they are finite.

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains of IDL eq 4: k_x in 1/s², k_v in 1/s, k_a dimensionless.

    Returns
    -------
    k_x, k_v, k_a : ndarray of float64
        The gains broadcast to one shape: the inputs themselves or broadcast views of
        them (copy before writing).

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
        big = np.abs(a) > RANGES["gain"][1]
        if big.any():  # the certificate's coefficients (products of gains) would overflow
            idx = np.argwhere(big)[0]
            where = f" (index {tuple(int(i) for i in idx)})" if a.ndim else ""
            check_magnitude("gain", float(a[tuple(idx)]), name=f"{name}{where}")
    return arrs[0], arrs[1], arrs[2]


def sample_time(value: Any) -> float:
    """The sampling period H (``sample_time``) as a float: finite and > 0 s.

    Parameters
    ----------
    value : object
        The sampling period H, s (anything ``float()`` accepts).

    Returns
    -------
    float
        H, checked finite, > 0 and within the magnitudes of :mod:`stringstab.ranges`.

    Raises
    ------
    StringStabError
        Saying what was expected and what was found.

    Examples
    --------
    >>> sample_time("0.1")
    0.1
    >>> sample_time(0)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: sample_time (sampling period H) must be a finite number > 0 s; got 0
    """
    return check_magnitude("sample_time", positive("sample_time (sampling period H)", value, unit=" s"))
