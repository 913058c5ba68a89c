"""The point coefficients of the sampled loop as a recorded program: the same numbers, cheaper.

:func:`stringstab.certify.zoh.build` computes the coefficients of H(z) and of the margin g_H
in the arithmetic of :mod:`stringstab.certify.interval`; at a point (one gain triple per
row) every step is an operation of :class:`~stringstab.certify.interval.Point` — one array
operation on the rows (value, magnitude).  At one loop (τ, τ_p, ε, H) the sequence of those
operations is the same for every call; only the gains differ.  :func:`record` runs ``build``
once on recording values (:class:`_Traced`), with the Schur conditions of δ
(:func:`stringstab.certify.zoh.schur_terms`; ``zoh`` keeps one recording per loop), and
keeps the sequence (:class:`Program`): the steps whose operands are all parameters are
computed then (in :class:`Point` arithmetic on one element, as ``point_coefficients``
computes them at every call), the others are kept as (ufunc, operands).  :meth:`Program.run` replays them on the gains' rows: each step is the
same IEEE operation on the same operands as in ``build``, so every coefficient has the same
bits, without ``build``'s Python structure (polynomial lists, objects) per call — the fixed
cost per call of the point certificate of the training repair (docs/sampled.md §8.1).

References
----------
:mod:`stringstab.certify.zoh` (the formulas; IDL paper, eqs 3-9 and 4); R. E. Moore,
R. B. Kearfott, M. J. Cloud, *Introduction to Interval Analysis*, SIAM (2009), §2 (the
arithmetic); N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM
(2002), §3.1 (the magnitude companion).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from .interval import Point

__all__ = ["Program", "record"]

Array = npt.NDArray[np.float64]
Ufunc = Callable[[Array, Array], Array]

#: The factors of a negation, rows (value, magnitude): −lo (exact), ``mag`` unchanged.
_NEG = np.array([[-1.0], [1.0]])


class _Recorder:
    """The registers and steps of a program being recorded."""

    def __init__(self) -> None:
        self.values: list[Array | None] = []  # a parameter-only register's value, else None
        self.steps: list[tuple[Ufunc, int, int, int]] = []

    def constant(self, s: Array) -> _Traced:
        self.values.append(s)
        return _Traced(self, len(self.values) - 1)

    def input(self) -> _Traced:
        self.values.append(None)
        return _Traced(self, len(self.values) - 1)

    def lift(self, v: Any) -> _Traced:
        """A recorded value, a :class:`Point` (a parameter) or a number (rows (v, |v|))."""
        if isinstance(v, _Traced):
            return v
        if isinstance(v, Point):
            return self.constant(v.s)
        return self.constant(Point.of(float(v)).s)

    def op(self, f: Ufunc, a: Any, b: Any) -> _Traced:
        x, y = self.lift(a), self.lift(b)
        vx, vy = self.values[x.i], self.values[y.i]
        if vx is not None and vy is not None:  # parameters only: computed now, as Point does
            return self.constant(f(vx, vy))
        out = self.input()
        self.steps.append((f, out.i, x.i, y.i))
        return out


class _Traced:
    """A value of the program being recorded: +, −, × and ``const`` as :class:`Point`'s."""

    __slots__ = ("i", "rec")

    def __init__(self, rec: _Recorder, i: int) -> None:
        self.rec, self.i = rec, i

    def __add__(self, o: Any) -> _Traced:
        return self.rec.op(np.add, self, o)

    __radd__ = __add__

    def __neg__(self) -> _Traced:
        return self.rec.op(np.multiply, self, Point(_NEG))

    def __sub__(self, o: Any) -> _Traced:
        return self + (-self.rec.lift(o))

    def __rsub__(self, o: Any) -> _Traced:
        return self.rec.lift(o) + (-self)

    def __mul__(self, o: Any) -> _Traced:
        return self.rec.op(np.multiply, self, o)

    __rmul__ = __mul__

    def const(self, v: Any) -> _Traced:
        """A constant (:meth:`Point.const`: value 0 + v, magnitude its absolute value)."""
        lo = np.zeros(1) + v
        return self.rec.constant(np.stack((lo, np.abs(lo))))


@dataclass(frozen=True)
class Program:
    """A recorded ``build`` at one loop: registers, steps and where each output is.

    Attributes
    ----------
    values : list of ndarray or None
        The parameter-only registers' values (rows (value, magnitude), one element); None
        for the inputs and the steps' results.
    steps : list of (ufunc, int, int, int)
        ``registers[out] = ufunc(registers[a], registers[b])``, in order.
    inputs : tuple of int
        The registers of k_x, k_v, k_a and c = k_v + T* k_x.
    outputs : Any
        The :class:`~stringstab.certify.zoh.Coefficients` of register numbers.
    schur : tuple of int
        The registers of the further outputs (:func:`stringstab.certify.zoh.schur_terms` of δ).
    """

    values: list[Array | None]
    steps: list[tuple[Ufunc, int, int, int]]
    inputs: tuple[int, ...]
    outputs: Any
    schur: tuple[int, ...]

    def run(self, rows: list[Array]) -> list[Array]:
        """Every register for the inputs' rows (value, magnitude) of k_x, k_v, k_a and c."""
        regs: list[Any] = list(self.values)
        for i, s in zip(self.inputs, rows):
            regs[i] = s
        for f, out, a, b in self.steps:
            regs[out] = f(regs[a], regs[b])
        return regs


def record(f: Callable[[dict[str, Any]], tuple[Any, list[Any]]], constants: dict[str, Point],
           inputs: tuple[str, ...]) -> Program:
    """Record ``f`` (e.g. :func:`stringstab.certify.zoh.build` and the Schur conditions).

    Parameters
    ----------
    f : callable
        Maps the named values to (outputs with a ``map`` method, e.g.
        :class:`~stringstab.certify.zoh.Coefficients`; a list of more outputs), computed in
        :class:`Point`'s arithmetic (+, −, ×, ``const``).
    constants : dict of str to Point
        The parameter-only values (one element).
    inputs : tuple of str
        The names of the values given at each run (:meth:`Program.run`, in this order).

    Returns
    -------
    Program
    """
    rec = _Recorder()
    q: dict[str, Any] = {k: rec.lift(v) for k, v in constants.items()}
    ins = {k: rec.input() for k in inputs}
    q.update(ins)
    out, more = f(q)
    return Program(rec.values, rec.steps, tuple(ins[k].i for k in inputs),
                   out.map(lambda v: rec.lift(v).i), tuple(rec.lift(t).i for t in more))
