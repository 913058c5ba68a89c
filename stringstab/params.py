"""Validation of the physical parameters shared by every analysis.

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

Each may also be uncertain: an interval ``(lo, hi)`` (or ``"LO:HI"`` on the command line),
and the three intervals form a :class:`Box` (the robust certificate,
:mod:`stringstab.certify.robust`, holds for every member).  :func:`parameter_model` turns what a
caller gives into :class:`Params` (every value a point) or a :class:`Box`.

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
from .ranges import RANGES, check_magnitude

__all__ = [
    "DEFAULT_DELTA",
    "DEFAULT_HEADWAY",
    "DEFAULT_TAU",
    "Box",
    "Interval",
    "Params",
    "as_gains",
    "as_interval",
    "check_box",
    "check_params",
    "check_reaction_delay",
    "count",
    "parameter_model",
    "parse_interval",
    "positive",
    "sample_time",
]

DEFAULT_TAU = constants.TAU
DEFAULT_DELTA = constants.DELTA
DEFAULT_HEADWAY = constants.HEADWAY

#: A closed interval (lo, hi) of a parameter, s.
Interval = tuple[float, float]


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
    t = _finite("tau (actuator lag)", tau)
    if not t > 0:
        raise StringStabError(f"tau (actuator lag) must be a finite number > 0 s; got {show(tau)}")
    d = _finite("delta (communication delay)", delta)
    if d < 0:
        raise StringStabError(f"delta (communication delay) must be >= 0 s; got {show(delta)}")
    h = _finite("headway (desired time headway T*)", headway)
    if h < 0:
        raise StringStabError(f"headway (desired time headway T*) must be >= 0 s; got {show(headway)}")
    for kind, x in (("tau", t), ("delta", d), ("headway", h)):
        check_magnitude(kind, x)
    return t, d, h


def check_reaction_delay(value: Any, name: str = "reaction_delay (reaction delay θ_r)") -> float:
    """The reaction (actuation) delay θ_r as a float: finite, ≥ 0 s and ≤ 100 s.

    The one check of θ_r (issue 25), behind :class:`Params` and :class:`Box`; the bound is
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


# ---------------------------------------------------------------------------
# Intervals and boxes of uncertain parameters
# ---------------------------------------------------------------------------
def _interval_error(name: str, text: Any) -> StringStabError:
    return StringStabError(
        f"{name} must be a number or an interval LO:HI (e.g. 0.1:0.5); got {show(text)}")


def parse_interval(text: str, name: str = "value") -> Interval:
    """Parse ``"LO:HI"`` (or a plain number, a point interval) into ``(lo, hi)``.

    For the command line (``--tau 0.1:0.5``); range checks (τ > 0, δ ≥ 0) are
    :class:`Box`'s.

    Parameters
    ----------
    text : str
        ``"0.1:0.5"`` or ``"0.2"``.
    name : str
        What the interval is, for the error message.

    Returns
    -------
    (float, float)

    Raises
    ------
    StringStabError
        On a malformed or non-finite end, or lo > hi.

    Examples
    --------
    >>> parse_interval("0.1:0.5"), parse_interval("0.2")
    ((0.1, 0.5), (0.2, 0.2))
    >>> parse_interval("0.5:0.1", "tau")
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: tau interval must have lo <= hi; got '0.5:0.1'
    """
    parts = str(text).strip().split(":")
    if len(parts) not in (1, 2) or not all(p.strip() for p in parts):
        raise _interval_error(name, text)
    try:
        ends = [float(p) for p in parts]
    except ValueError as e:
        raise _interval_error(name, text) from e
    if not all(math.isfinite(v) for v in ends):
        raise StringStabError(f"{name} interval ends must be finite numbers; got {show(text)}")
    lo, hi = ends[0], ends[-1]
    if lo > hi:
        raise StringStabError(f"{name} interval must have lo <= hi; got {show(text)}")
    return lo, hi


def as_interval(value: Any, name: str = "value") -> Interval:
    """A number, a ``(lo, hi)`` pair or a ``"LO:HI"`` string as a checked ``(lo, hi)``.

    Parameters
    ----------
    value : float, (float, float) or str
        A number (a point interval), a ``(lo, hi)`` pair or ``"LO:HI"``.
    name : str
        What the interval is, for the error message.

    Returns
    -------
    (float, float)
        ``(lo, hi)`` with finite ends and lo ≤ hi.

    Raises
    ------
    StringStabError
        On a value that is none of these, a non-finite end, or lo > hi.

    Examples
    --------
    >>> as_interval(0.1), as_interval((0.1, 0.3)), as_interval("0:0.2")
    ((0.1, 0.1), (0.1, 0.3), (0.0, 0.2))
    """
    if isinstance(value, str):
        return parse_interval(value, name)
    if isinstance(value, (tuple, list, np.ndarray)):
        if len(value) != 2:
            raise StringStabError(
                f"{name} must be a number or a (lo, hi) pair; got {len(value)} values")
        lo, hi = (_finite(f"{name} interval end", v) for v in value)
        if lo > hi:
            raise StringStabError(f"{name} interval must have lo <= hi; got {show(value)}")
        return lo, hi
    v = _finite(name, value)
    return v, v


@dataclass(frozen=True)
class Box:
    """A box of model parameters, each a ``(lo, hi)`` interval in seconds.

    ``reaction_delay`` (θ_r, issue 25) is (0, 0) by default and then left out of the repr and
    of :meth:`as_dict`.

    Examples
    --------
    >>> Box((0.1, 0.5), (0.2, 0.2), (1.1, 1.1)).is_point
    False
    >>> Box((0.0, 0.5), (0.2, 0.2), (1.1, 1.1))
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: tau (actuator lag) interval must stay > 0 s; got [0.0, 0.5]
    """

    tau: Interval
    delta: Interval
    headway: Interval
    reaction_delay: Interval = (0.0, 0.0)

    def __post_init__(self) -> None:
        for name, (lo, hi) in (("tau (actuator lag)", self.tau),
                               ("delta (communication delay)", self.delta),
                               ("headway (desired time headway T*)", self.headway),
                               ("reaction_delay (reaction delay θ_r)", self.reaction_delay)):
            if not (math.isfinite(lo) and math.isfinite(hi)) or lo > hi:
                raise StringStabError(f"{name} interval must be finite with lo <= hi; got [{lo}, {hi}]")
        if not self.tau[0] > 0:
            raise StringStabError(
                f"tau (actuator lag) interval must stay > 0 s; got [{self.tau[0]}, {self.tau[1]}]")
        if self.delta[0] < 0:
            raise StringStabError(
                f"delta (communication delay) interval must be >= 0 s; got [{self.delta[0]}, {self.delta[1]}]")
        if self.headway[0] < 0:
            raise StringStabError(
                f"headway (desired time headway T*) interval must be >= 0 s; "
                f"got [{self.headway[0]}, {self.headway[1]}]")
        if self.reaction_delay[0] < 0:
            raise StringStabError(
                f"reaction_delay (reaction delay θ_r) interval must be >= 0 s; "
                f"got [{self.reaction_delay[0]}, {self.reaction_delay[1]}]")
        for kind, (_, hi) in (("tau", self.tau), ("delta", self.delta), ("headway", self.headway),
                              ("reaction_delay", self.reaction_delay)):
            check_magnitude(kind, hi)

    def __repr__(self) -> str:
        extra = (f", reaction_delay={self.reaction_delay!r}"
                 if self.reaction_delay != (0.0, 0.0) else "")
        return f"Box(tau={self.tau!r}, delta={self.delta!r}, headway={self.headway!r}{extra})"

    @property
    def is_point(self) -> bool:
        """Every interval is a single value."""
        return all(lo == hi for lo, hi in (self.tau, self.delta, self.headway,
                                           self.reaction_delay))

    def centre(self) -> Params:
        """The member at the box's centre: each parameter at the middle of its interval.

        Returns
        -------
        Params
            τ, δ, T* (and θ_r) at (lo + hi)/2 (the point itself for a point box).
        """
        (t0, t1), (d0, d1), (h0, h1) = self.tau, self.delta, self.headway
        r0, r1 = self.reaction_delay
        return Params(0.5 * (t0 + t1), 0.5 * (d0 + d1), 0.5 * (h0 + h1), 0.5 * (r0 + r1))

    def as_dict(self) -> dict[str, list[float]]:
        """``{"tau": [lo, hi], "delta": [lo, hi], "headway": [lo, hi]}`` (for JSON).

        With ``"reaction_delay": [lo, hi]`` too when θ_r is not (0, 0).
        """
        out = {"tau": list(self.tau), "delta": list(self.delta), "headway": list(self.headway)}
        if self.reaction_delay != (0.0, 0.0):
            out["reaction_delay"] = list(self.reaction_delay)
        return out

    def columns(self, n: int) -> dict[str, npt.NDArray[np.float64]]:
        """``tau_lo, tau_hi, delta_lo, ...``: the box repeated on ``n`` result rows.

        Parameters
        ----------
        n : int
            Number of result rows.

        Returns
        -------
        dict of str to ndarray
            ``tau_lo``, ``tau_hi``, ``delta_lo``, ``delta_hi``, ``headway_lo``, ``headway_hi``
            (s), each of length ``n``.
        """
        return {f"{k}_{e}": np.full(n, float(v)) for k, iv in self.as_dict().items()
                for e, v in zip(("lo", "hi"), iv)}

    @classmethod
    def of(cls, p: Params | Box) -> Box:
        """The box of a :class:`Params` (a point box), or ``p`` itself.

        Parameters
        ----------
        p : Params or Box
            Point parameters or a box.

        Returns
        -------
        Box
        """
        if isinstance(p, Box):
            return p
        # the point box of parameters already checked (by Params): not checked again
        box = object.__new__(cls)
        for name in ("tau", "delta", "headway", "reaction_delay"):
            v = getattr(p, name)
            object.__setattr__(box, name, (v, v))
        return box


def check_box(tau: Any, delta: Any, headway: Any, reaction_delay: Any = 0.0) -> Box:
    """Validate three numbers, pairs or ``"LO:HI"`` strings into a :class:`Box`.

    Parameters
    ----------
    tau : float, (float, float) or str
        Actuator lag τ or its interval, s.
    delta : float, (float, float) or str
        Communication delay δ or its interval, s.
    headway : float, (float, float) or str
        Desired time headway T* or its interval, s.
    reaction_delay : float, (float, float) or str
        Reaction delay θ_r or its interval, s (default 0).

    Returns
    -------
    Box

    Raises
    ------
    StringStabError
        On a malformed interval, lo > hi, a negative end, or a τ interval reaching 0.

    Examples
    --------
    >>> check_box("0.1:0.3", 0.2, (1.0, 1.2))
    Box(tau=(0.1, 0.3), delta=(0.2, 0.2), headway=(1.0, 1.2))
    >>> check_box(0.1, "-0.1:0.2", 1.1)
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: delta (communication delay) interval must be >= 0 s; got [-0.1, 0.2]
    """
    return Box(as_interval(tau, "tau"), as_interval(delta, "delta"),
               as_interval(headway, "headway"), as_interval(reaction_delay, "reaction_delay"))


def _is_number(v: Any) -> bool:
    return not isinstance(v, (str, tuple, list, np.ndarray, Box)) or (
        isinstance(v, np.ndarray) and v.ndim == 0)


def parameter_model(tau: Any, delta: Any, headway: Any, reaction_delay: Any = 0.0) -> Params | Box:
    """:class:`Params` when τ, δ, T* (θ_r) are numbers (or intervals of one point), else a :class:`Box`.

    Numbers are checked by :func:`check_params` (so their errors are the point ones); any
    interval (``(lo, hi)`` or ``"LO:HI"``) makes the whole a box, checked by :func:`check_box`.

    Parameters
    ----------
    tau : float, (float, float) or str
        Actuator lag τ or its interval, s.
    delta : float, (float, float) or str
        Communication delay δ or its interval, s.
    headway : float, (float, float) or str
        Desired time headway T* or its interval, s.
    reaction_delay : float, (float, float) or str
        Reaction delay θ_r or its interval, s (default 0: today's model).

    Returns
    -------
    Params or Box
        ``Params`` if every value is a point, else the ``Box``.

    Raises
    ------
    StringStabError
        If a value is malformed or out of its range.

    Examples
    --------
    >>> parameter_model(0.1, 0.2, 1.1)
    Params(tau=0.1, delta=0.2, headway=1.1)
    >>> parameter_model(0.1, (0.2, 0.2), 1.1)
    Params(tau=0.1, delta=0.2, headway=1.1)
    >>> parameter_model("0.1:0.3", 0.2, 1.1)
    Box(tau=(0.1, 0.3), delta=(0.2, 0.2), headway=(1.1, 1.1))
    """
    if all(_is_number(v) for v in (tau, delta, headway, reaction_delay)):
        return Params(tau, delta, headway, reaction_delay)
    box = check_box(tau, delta, headway, reaction_delay)
    if box.is_point:
        return Params(box.tau[0], box.delta[0], box.headway[0], box.reaction_delay[0])
    return box
