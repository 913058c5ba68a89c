"""Uncertain model parameters: intervals of τ, δ, T*, θ_r and the :class:`Box` they form.

Each parameter of :mod:`stringstab.params.points` may be uncertain: an interval ``(lo, hi)`` (or
``"LO:HI"`` on the command line), and the intervals form a :class:`Box` (the robust certificate,
:mod:`stringstab.certify.robust`, holds for every member).  :func:`parameter_model` turns what a
caller gives into :class:`~stringstab.params.points.Params` (every value a point) or a
:class:`Box`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError, show
from ..ranges import check_magnitude
from .points import Params, finite

__all__ = ["Box", "Interval", "as_interval", "check_box", "parameter_model", "parse_interval"]

#: A closed interval (lo, hi) of a parameter, s.
Interval = tuple[float, float]


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
        lo, hi = (finite(f"{name} interval end", v) for v in value)
        if lo > hi:
            raise StringStabError(f"{name} interval must have lo <= hi; got {show(value)}")
        return lo, hi
    v = finite(name, value)
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
