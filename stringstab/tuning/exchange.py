"""The exchange method of the projection: solve, ask the certificate, grow the constraint set.

:func:`exchange` alternates an NLP solve (:mod:`stringstab.tuning.nlp`) with the exact
certificate's verdict until it certifies.  The helpers keep the constraint sets of the two
NLPs in order: frequencies (:func:`dedupe_frequencies`, :func:`fit_frequencies`) for the
continuous loop, quadratic-form slots (:func:`dedupe_slots`, :func:`fit_forms`) for the
sampled and robust loops, each within the largest slot capacity
(:data:`stringstab.tuning.nlp.SLOT_SIZES`).

References
----------
R. Hettich, K. O. Kortanek, "Semi-infinite programming: theory, methods, and
applications", SIAM Review 35 (1993) 380-429 (the exchange method).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import numpy.typing as npt

from ..certify import margin as _margin
from ..certify.verdicts import Verdict
from ..params import Params
from .constraints import Member, Slot, evaluate_forms
from .nlp import SLOT_SIZES

__all__ = [
    "CLUSTER",
    "dedupe_frequencies",
    "dedupe_slots",
    "exchange",
    "fit_forms",
    "fit_frequencies",
]

Array = npt.NDArray[np.float64]

#: Relative offset of the two neighbours added with every exchanged frequency.
CLUSTER = 0.05


def exchange(
    x: Array, max_solves: int, solve: Callable[[Array], tuple[Array, str, int]],
    step: Callable[[Array], str],
) -> tuple[Array | None, Array, int, int, list[str]]:
    """The exchange method: solve from x, ask the certificate (``step``), repeat.

    ``solve(x)`` solves the NLP with the current constraints from x; ``step(x)`` asks the
    certificate and returns ``"certified"``, ``"grown"`` (it added constraints at its witness)
    or ``"stuck"`` (nothing new to add).  Stops at a certified point, when stuck, at a
    non-finite solution or after ``max_solves`` solves.

    Parameters
    ----------
    x : ndarray, shape (3,)
        The starting point.
    max_solves : int
        The largest number of solves.
    solve : callable
        ``solve(x) -> (K, IPOPT status, IPOPT iterations)``.
    step : callable
        ``step(K) -> "certified" | "grown" | "stuck"``.

    Returns
    -------
    (best or None, last x, solves, IPOPT iterations, IPOPT statuses)
        ``best`` is the certified point, or None when none was found.
    """
    statuses: list[str] = []
    n_solves = iters = 0
    for _ in range(max_solves):
        x, status, its = solve(x)
        n_solves += 1
        iters += its
        statuses.append(status)
        if not np.all(np.isfinite(x)):
            break
        outcome = step(x)
        if outcome == Verdict.CERTIFIED:
            return x, x, n_solves, iters, statuses
        if outcome == "stuck":
            break
    return None, x, n_solves, iters, statuses


def dedupe_slots(slots: list[Slot], rtol: float = 1e-6) -> list[Slot]:
    """The slots in order, dropping one at the same member and (nearly) the same frequency.

    Parameters
    ----------
    slots : list of Slot
        Constraint slots (:class:`stringstab.tuning.constraints.Slot`).
    rtol : float, default 1e-6
        Relative tolerance of "the same frequency".

    Returns
    -------
    list of Slot
        The distinct slots (a margin slot at a negative or non-finite frequency dropped).
    """
    out: list[Slot] = []
    seen: list[tuple[str, Member, int, float]] = []
    for s in slots:
        if s.kind == "margin" and not (math.isfinite(s.freq) and s.freq >= 0):
            continue
        dup = any(k == s.kind and m == s.member and i == s.index
                  and (s.kind == "stability" or abs(f - s.freq) <= rtol * max(1.0, f))
                  for k, m, i, f in seen)
        if not dup:
            out.append(s)
            seen.append((s.kind, s.member, s.index, s.freq))
    return out


def fit_forms(slots: list[Slot], x: Array) -> list[Slot]:
    """At most the largest slot capacity: drop the slackest margin slots at x (never stability).

    Parameters
    ----------
    slots : list of Slot
        Constraint slots.
    x : ndarray, shape (3,)
        The gains at which the margin slots' values are compared.

    Returns
    -------
    list of Slot
        The stability slots, then the tightest margin slots, at most ``SLOT_SIZES[-1]``.
    """
    cap = SLOT_SIZES[-1]
    if len(slots) <= cap:
        return slots
    stab = [s for s in slots if s.kind == "stability"]
    marg = [s for s in slots if s.kind != "stability"]
    vals = evaluate_forms(np.array([s.form for s in marg]), x)
    keep = np.sort(np.argsort(vals)[: cap - len(stab)])
    return stab + [marg[i] for i in keep]


def dedupe_frequencies(omegas: list[float], rtol: float = 1e-6) -> list[float]:
    """ω = 0 first, then the others in order, dropping near-duplicates.

    Parameters
    ----------
    omegas : list of float
        Frequencies (rad/s); non-finite and non-positive ones are dropped.
    rtol : float, default 1e-6
        Relative tolerance of a near-duplicate.

    Returns
    -------
    list of float
        ``[0.0, ...]``, the distinct positive frequencies in order.
    """
    out = [0.0]
    for o in omegas:
        if not math.isfinite(o) or o <= 0:
            continue
        if all(abs(o - q) > rtol * max(1.0, o) for q in out):
            out.append(float(o))
    return out


def fit_frequencies(omegas: list[float], x: Array, p: Params) -> list[float]:
    """Keep at most the largest slot capacity: drop the slackest frequencies (never ω = 0).

    Parameters
    ----------
    omegas : list of float
        The frequency set, ω = 0 first (rad/s).
    x : ndarray, shape (3,)
        The gains at which the margins g(ω; x) are compared.
    p : Params
        τ, δ, T* (s) of the continuous loop.

    Returns
    -------
    list of float
        ω = 0 and the frequencies of the smallest margins, at most ``SLOT_SIZES[-1]``.
    """
    cap = SLOT_SIZES[-1]
    if len(omegas) <= cap:
        return omegas
    om = np.asarray(omegas[1:])
    gv = _margin.g(om, x[0], x[1], x[2], tau=p.tau, delta=p.delta, headway=p.headway)
    keep = np.sort(np.argsort(gv)[: cap - 1])
    return [omegas[0], *om[keep].tolist()]
