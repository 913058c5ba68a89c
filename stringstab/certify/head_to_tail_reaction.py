r"""The sampled head-to-tail certificate with a reaction delay θ_r > 0: the string as one cascade.

Every vehicle of the string samples every H (zero-order hold) and applies its command θ_r late
(docs/sampled.md §10.1); θ_r is **common to the string** (the link model of
:mod:`stringstab.certify.lifting_reaction` has the predecessor's θ_r equal to the follower's;
the leader's too), while τ_i, δ_i, T*_i and the gains are each vehicle's own, and vehicle i's
predecessor's lag is τ_{i−1} (τ_0: the leader's).

**The cascade.**  Vehicle i's link u_{i−1} → u_i is the exact held-input model of
:func:`stringstab.certify.lifting_reaction.lift_reaction` at N = 1, (A_i, B_i, C_i, D_i = 0)
as balls.  The string's transfer u_0 → u_n is their series connection
G = G_n ⋯ G_1, built exactly in ball arithmetic:

.. math::
    x = (x_1, x_2),\quad x_1^{+} = A_1 x_1 + B_1 u,\quad x_2^{+} = A_2 x_2 + B_2 C_1 x_1,\quad
    y = C_2 x_2

(x⁺ the next step's state; the series connection: A is block lower triangular with A_1, A_2 on its diagonal and
B_2 C_1 below it, B = (B_1, 0), C = (0, C_2), D = 0;
repeated for every vehicle; D_i = 0: no feed-through within a step), so
G(e^{jθ}) = ∏_i H_i(e^{jθ}) and |G| = ∏_i |H_i| — the head-to-tail product of
:mod:`stringstab.certify.head_to_tail_sampled`.

**The decision.**  ``certified``: every vehicle's follower block is proven Schur (the Stein test
of docs/sampled.md §10.2; A is block triangular with the links' state matrices on its diagonal,
each Schur iff its follower block is) and λ_min(M(θ)) ≥ 0 on [0, π], M the tangency-free
margin of :mod:`stringstab.certify.lifted_frequency` at N = 1 for the cascade (G(1) = 1: every
H_i(1) = 1), decided by :func:`stringstab.certify.multirate.decide_lifted`; then
∏|H_i(e^{jθ})| ≤ 1.  ``not_certified``: a follower block proven not Schur, or a θ with
λ_min(M(θ)) < −slack.  ``inconclusive``: neither.

References
----------
docs/sampled.md §10.6; IDL paper, Definition 1 (eq 10).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from .ball import Ball
from .head_to_tail import Vehicle
from .lifted_peak import lifted_peak
from .lifting import LiftedLink
from .lifting_reaction import follower_block, held_steps, lift_reaction
from .multirate import decide_lifted
from .stein import stein_schur
from .string_decision import StringDecision
from .verdicts import CERTIFIED

__all__ = ["cascade", "check_common_reaction_delay", "decide_strings", "string_links"]

Array = npt.NDArray[np.float64]


def check_common_reaction_delay(vehicles: Sequence[Vehicle]) -> float:
    """θ_r of a sampled string, refused in one line unless every vehicle has the same.

    Parameters
    ----------
    vehicles : sequence of Vehicle
        The followers (checked).

    Returns
    -------
    float
        The common θ_r, s.

    Raises
    ------
    StringStabError
        When the vehicles' θ_r differ.
    """
    th = sorted({float(v.reaction_delay) for v in vehicles})
    if len(th) > 1:
        raise StringStabError(
            "with a sample time every vehicle of the string must have the same reaction delay "
            "θ_r (the sampled link model has the predecessor's θ_r equal to the follower's); "
            f"got {', '.join(f'{t:g}' for t in th)} s")
    return th[0]


def string_links(vehicles: Sequence[Vehicle], H: float, leader_tau: float) -> list[LiftedLink]:
    """Each vehicle's link u_{i−1} → u_i (N = 1, one row), the predecessor's lag its own.

    Parameters
    ----------
    vehicles : sequence of Vehicle
        The string (common θ_r > 0).
    H : float
        The sample time, s.
    leader_tau : float
        τ_0, the first follower's predecessor's lag, s.

    Returns
    -------
    list of LiftedLink
    """
    out = []
    for i, v in enumerate(vehicles):
        tp = leader_tau if i == 0 else vehicles[i - 1].params.tau
        k = (np.array([v.k_x]), np.array([v.k_v]), np.array([v.k_a]))
        out.append(lift_reaction(*k, v.params, H, 1, tp))
    return out


def _blocks(rows: list[list[Ball | None]], shapes_r: list[int], shapes_c: list[int]) -> Ball:
    """A block matrix of balls (None: an exact zero block), one stack row."""
    n = next(b.mid.shape[0] for r in rows for b in r if b is not None)
    mid = np.zeros((n, sum(shapes_r), sum(shapes_c)))
    rad = np.zeros_like(mid)
    r0 = 0
    for r, nr in zip(rows, shapes_r):
        c0 = 0
        for b, nc in zip(r, shapes_c):
            if b is not None:
                mid[:, r0:r0 + nr, c0:c0 + nc] = b.mid
                rad[:, r0:r0 + nr, c0:c0 + nc] = b.rad
            c0 += nc
        r0 += nr
    return Ball(mid, rad)


def cascade(links: Sequence[LiftedLink]) -> LiftedLink:
    """The series connection G_n ⋯ G_1 of SISO links with D_i = 0 (module docstring).

    Parameters
    ----------
    links : sequence of LiftedLink
        N = 1 links of one stack size, first the head's.

    Returns
    -------
    LiftedLink
        The cascade (``m`` is the head's, recorded only).

    Raises
    ------
    ValueError
        If a link has feed-through (D ≠ 0) or N ≠ 1.
    """
    for lk in links:
        if lk.N != 1 or np.any(lk.D.mid != 0) or np.any(lk.D.rad != 0):
            raise ValueError("cascade: links with N = 1 and D = 0 only")
    A, B, C = links[0].A, links[0].B, links[0].C
    for lk in links[1:]:
        n1, n2 = A.mid.shape[-1], lk.order
        A = _blocks([[A, None], [lk.B @ C, lk.A]], [n1, n2], [n1, n2])
        B = _blocks([[B], [None]], [n1, n2], [1])
        C = _blocks([[None, lk.C]], [1], [n1, n2])
    return LiftedLink(A, B, C, links[-1].D, 1, links[0].m)


def decide_strings(strings: Sequence[Sequence[Vehicle]], H: float, leader_taus: Sequence[float],
                   *, n_grid: int, max_rounds: int = 30, max_intervals: int = 4096,
                   ) -> StringDecision:
    """The head-to-tail verdict of every string (common θ_r > 0, sample time H).

    Parameters
    ----------
    strings : sequence of sequences of Vehicle
        The strings (one item each), any lengths ≥ 1.
    H : float
        The sample time, s.
    leader_taus : sequence of float
        Each string's first predecessor's lag, s.
    n_grid, max_rounds, max_intervals : int
        The first grid on [0, π] and the budget of :func:`stringstab.certify.multirate.decide_lifted`.

    Returns
    -------
    StringDecision
        θ (``argmin``, ``peak``) in rad/sample; ``minimum`` is the smallest λ_min(M̂(θ)).
    """
    n = len(strings)
    verdict = np.empty(n, dtype=np.int8)
    sure, fail = np.empty(n, dtype=bool), np.empty(n, dtype=bool)
    minimum, argmin = np.empty(n), np.empty(n)
    sup, peak = np.ones(n), np.zeros(n)
    n_evals = np.empty(n, dtype=np.int64)
    for j, (vs, lt) in enumerate(zip(strings, leader_taus)):
        links = string_links(vs, H, float(lt))
        s_all, f_any = True, False
        for v, lk in zip(vs, links):
            s, f = stein_schur(follower_block(lk, held_steps(v.reaction_delay, H)[2]))
            s_all, f_any = s_all and bool(s[0]), f_any or bool(f[0])
        link = cascade(links)
        v_, mg, am, ne, grid = decide_lifted(link, np.array([s_all]), np.array([f_any]),
                                             n_grid=n_grid, max_rounds=max_rounds,
                                             max_intervals=max_intervals)
        verdict[j], sure[j], fail[j], minimum[j], argmin[j], n_evals[j] = (
            v_[0], s_all, f_any, mg[0], am[0], ne[0])
        if v_[0] != CERTIFIED and s_all:
            s_, w_ = lifted_peak(link, grid, am)
            sup[j], peak[j] = s_[0], w_[0]
    sup = np.where(sure, sup, np.inf)
    return StringDecision(verdict, sure, fail, np.full(n, np.pi), minimum, argmin, sup, peak,
                          n_evals)
