"""The projection's constraints for any loop: quadratic forms in K from the one home of each margin.

The gain repair (:mod:`stringstab.tuning.projection`) asks for gains certified for the loop a
controller runs: the continuous loop at one τ, δ, T* (its own NLP, built on
:func:`stringstab.tuning.margin_terms.casadi_g`), the sampled-data loop (``sample_time``) or every member of
a box of τ, δ, T* (the robust certificate), sampled or not.  For the last three, every
constraint of the NLP is a *quadratic form in the gains*:

* the continuous margin g(ω; K) (:func:`stringstab.certify.margin.g`) at one member (τ, δ, T*) and one
  frequency ω is a polynomial of degree 2 in K = (k_x, k_v, k_a): t2 does not depend on K,
  a is affine, b, c_x, c_v are quadratic;
* the sampled margin g_H(θ; K) (:func:`stringstab.certify.sampled_frequency.sampled_margin`) is one too: every
  w-coefficient of Δ(w) and n(w) is affine in K, and g_H is a sum of products of two of them;
* with a reaction delay θ_r > 0, sampled, the margin g_{H,θ_r}(θ; K) of
  :mod:`stringstab.tuning.sampled_reaction_margin` (|χ_f|² − |N χ_f(·; 0)|², the follower's
  characteristic polynomial and the link's numerator, both affine in K) is one too;
* so are the internal-stability conditions: the Hurwitz conditions (linear,
  :func:`stringstab.certify.criteria.hurwitz_conditions`) and the normalised Schur conditions of the
  sampled loop (:func:`stringstab.certify.schur.schur_margins`).

A quadratic q(K) = c + bᵀK + KᵀAK is recovered *exactly* (up to round-off) from ten evaluations
by polarisation (:func:`quadratic_form`), so each constraint is evaluated by the same code as
the certificate it serves, and the NLP sees only the numbers (c, b, A) of each slot: one NLP for
every loop.  :class:`LoopConstraints` says which member and frequency each constraint is taken
at: a few fixed ones to start, then the certificate's witnesses (the exchange method), and decides every
output with the certificate of that loop (:func:`stringstab.certify.api.check`).

References
----------
R. Hettich, K. O. Kortanek, "Semi-infinite programming: theory, methods, and applications",
SIAM Review 35 (1993) 380-429 (the exchange method).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from itertools import product
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify import margin as _margin
from ..certify import margin_reaction as _margin_reaction
from ..certify.criteria import hurwitz_conditions
from ..certify.grid import certified
from ..errors import StringStabError
from ..params import Box, Params

__all__ = ["FORM_SIZE", "LoopConstraints", "Member", "Slot", "quadratic_form"]

Array = npt.NDArray[np.float64]

#: Numbers per quadratic form: c, b (3), the upper triangle of A (xx, xv, xa, vv, va, aa).
FORM_SIZE = 10
#: The evaluation points of :func:`quadratic_form`: 0, ±e_i, e_i + e_j.
_E = np.eye(3)
_POINTS = np.array([np.zeros(3), *_E, *(-_E), _E[0] + _E[1], _E[0] + _E[2], _E[1] + _E[2]])


def quadratic_form(f: Callable[[Array, Array, Array], Array]) -> Array:
    """(c, b, A) of a polynomial q(K) of degree ≤ 2 in K = (k_x, k_v, k_a), from 10 values.

    ``f(k_x, k_v, k_a)`` evaluates q on arrays.  With q(0) = c, q(±e_i) = c ± b_i + A_ii and
    q(e_i + e_j) = c + b_i + b_j + A_ii + A_jj + 2A_ij, the identities are exact for a quadratic.

    Parameters
    ----------
    f : callable
        ``f(k_x, k_v, k_a) -> ndarray``: the quadratic q evaluated elementwise on three arrays of
        gains (k_x in 1/s², k_v in 1/s, k_a dimensionless; IDL eq 4), for instance a margin
        g(ω; K) at one member and frequency.  It is called once, on the 10 polarisation points
        0, ±e_i, e_i + e_j.  A q of degree > 2 is not detected: its form is then wrong.

    Returns
    -------
    ndarray, shape (10,)
        c, b_x, b_v, b_a, A_xx, A_xv, A_xa, A_vv, A_va, A_aa (q = c + bᵀK + KᵀAK).

    Examples
    --------
    >>> q = quadratic_form(lambda x, v, a: 1 + 2 * x - v + 3 * x * a + a * a)
    >>> q.round(12).tolist()
    [1.0, 2.0, -1.0, 0.0, 0.0, 0.0, 1.5, 0.0, 0.0, 1.0]
    """
    v = np.asarray(f(*_POINTS.T), dtype=float)
    c = v[0]
    plus, minus = v[1:4], v[4:7]
    b = 0.5 * (plus - minus)
    diag = 0.5 * (plus + minus) - c
    off = []
    for k, (i, j) in enumerate(((0, 1), (0, 2), (1, 2))):
        off.append(0.5 * (v[7 + k] - plus[i] - plus[j] + c))
    return np.array([c, *b, diag[0], off[0], off[1], diag[1], off[2], diag[2]])


def evaluate_forms(forms: Array, K: Array) -> Array:
    """q(K) for each row of ``forms`` (shape (n, 10)) at K (shape (3,), or (m, 3): (n, m)).

    Parameters
    ----------
    forms : ndarray, shape (n, 10)
        Quadratic forms as returned by :func:`quadratic_form`, one per row: (c, b_x, b_v, b_a,
        A_xx, A_xv, A_xa, A_vv, A_va, A_aa).
    K : ndarray, shape (3,) or (m, 3)
        Gains (k_x [1/s²], k_v [1/s], k_a [-]) of IDL eq 4: one triple or m triples.

    Returns
    -------
    ndarray, shape (n,) or (n, m)
        q(K) = c + bᵀK + KᵀAK of each form at each triple.

    Examples
    --------
    >>> f = quadratic_form(lambda x, v, a: 1 + x * v)
    >>> evaluate_forms(f[None, :], np.array([2.0, 3.0, 0.0])).tolist()
    [7.0]
    """
    x, v, a = np.asarray(K, dtype=float).T
    mono = np.stack([np.ones_like(x), x, v, a, x * x, 2 * x * v, 2 * x * a, v * v, 2 * v * a, a * a])
    return np.asarray(forms @ mono)


@dataclass(frozen=True)
class Member:
    """One member of the parameter box: τ, the predecessor's lag τ_p, δ, T* (s)."""

    tau: float
    tau_prev: float
    delta: float
    headway: float


@dataclass(frozen=True)
class Slot:
    """One constraint: its kind, the member and frequency it is taken at, and its form.

    ``kind`` is ``"margin"`` (g ≥ ε at ``freq``: ω in rad/s, or θ in rad/sample when
    sampled) or ``"stability"`` (the ``index``-th internal-stability condition ≥ the margin).
    """

    kind: str
    member: Member
    freq: float
    index: int
    form: Array


class LoopConstraints:
    """The loop to repair gains for, its constraints and its certificate.

    Parameters
    ----------
    params : Params or Box
        τ, δ, T* (a point) or the box every member of which must be certified.
    sample_time : float or None
        H (s) for the sampled-data loop.
    heterogeneous : bool
        Sampled box: the predecessor's lag ranges over the τ box independently.
    """

    def __init__(self, params: Params | Box, sample_time: float | None,
                 heterogeneous: bool = True) -> None:
        self.params = params
        self.sample_time = sample_time
        self.heterogeneous = bool(heterogeneous)
        self.box = Box.of(params)
        lo, hi = self.box.reaction_delay
        if hi:
            # θ_r > 0: the certificate's own refusal line first (a message period, q > 2000, ...)
            from ..certify.api import Loop

            Loop(params, sample_time)
            if not isinstance(params, Params):
                # a box with θ_r is certified but its constraints are not written
                raise StringStabError(
                    "tuning takes θ_r at a point (the box certificate with θ_r is certify's); "
                    "expected a point τ, δ, T* with reaction_delay, got "
                    f"reaction_delay={lo:g}" + (f":{hi:g}" if hi != lo else "") + " with a box")
        #: The reaction delay θ_r (s) of the point loop, continuous or sampled (issue 25); 0
        #: otherwise.
        self.reaction_delay = float(lo)

    @property
    def sampled(self) -> bool:
        """The sampled-data loop."""
        return self.sample_time is not None

    @property
    def H(self) -> float:
        """The sample time of a sampled loop."""
        assert self.sample_time is not None
        return self.sample_time

    # ------------------------------------------------------------------ members
    def centre(self) -> Member:
        """The box's centre (the point itself for a point)."""
        c = self.box.centre()
        return Member(c.tau, c.tau, c.delta, c.headway)

    def corners(self) -> list[Member]:
        """The corners of the (τ, T*) box with δ at its centre (where stability is worst)."""
        c = self.centre()
        return [Member(t, t, c.delta, h) for t, h in product(sorted(set(self.box.tau)),
                                                             sorted(set(self.box.headway)))]

    def first_members(self) -> list[Member]:
        """Members whose margins are constrained in the first solve: the box's corners and centre.

        The corners take every end of τ, δ and T* (with τ_p = τ); for a point, the one member
        is the point itself.

        Returns
        -------
        list of Member
            Sorted by τ, δ, T*.
        """
        out = {self.centre()}
        for t, d, h in product(*(sorted(set(iv)) for iv in (self.box.tau, self.box.delta,
                                                             self.box.headway))):
            out.add(Member(t, t, d, h))
        return sorted(out, key=lambda m: (m.tau, m.delta, m.headway))

    def extreme_members(self) -> list[Member]:
        """Every corner of the box, where a box's worst member usually is.

        Every end of τ, δ and T*; when sampled and heterogeneous, the predecessor's lag τ_p
        also takes either end of the τ box independently (otherwise τ_p = τ).

        Returns
        -------
        list of Member
            The corners (8, or 16 when τ_p is free; fewer when an interval is a point).
        """
        ends = [sorted(set(iv)) for iv in (self.box.tau, self.box.delta, self.box.headway)]
        tp_free = self.sampled and self.heterogeneous
        out = []
        for t, tp, d, h in product(ends[0], ends[0] if tp_free else [None], ends[1], ends[2]):
            out.append(Member(t, t if tp is None else tp, d, h))
        return out

    # ------------------------------------------------------------------ the one homes
    def margin(self, member: Member, freq: Array, K: Array) -> Array:
        """The margin g (or g_H, sampled) at ``member`` on frequencies ``freq`` for the gains K.

        Taken from the one home of each margin (:func:`stringstab.certify.margin.g`,
        :func:`stringstab.certify.sampled_frequency.sampled_margin`; with θ_r > 0
        :func:`stringstab.certify.margin_reaction.g` and, sampled,
        :func:`stringstab.tuning.sampled_reaction_margin.sampled_reaction_margin`: the
        certificate's own link model, its margin a positive multiple of 1 − |H(e^{jθ})|²).

        Parameters
        ----------
        member : Member
            τ, τ_p, δ, T* (s); τ_p is used by the sampled margin only.
        freq : ndarray
            ω in rad/s (continuous) or θ = ωH in rad/sample (sampled).
        K : ndarray, shape (3,)
            Gains (k_x, k_v, k_a) of IDL eq 4.

        Returns
        -------
        ndarray
            g(ω) = (|D(jω)|² − |N(jω)|²)/ω² (≥ 0 iff |Γ(jω)| ≤ 1), or the normalised sampled
            margin g_H(θ), at each frequency.
        """
        if self.reaction_delay and self.sampled:  # θ_r > 0 sampled: g_{H,θ_r}, quadratic in K
            return self._sampled_reaction(member, freq, K)
        if self.reaction_delay:  # θ_r > 0: g_θ of its one home (issue 25)
            return _margin_reaction.g(freq, K[0], K[1], K[2], tau=member.tau, delta=member.delta,
                                      headway=member.headway, reaction_delay=self.reaction_delay)
        if not self.sampled:
            return _margin.g(freq, K[0], K[1], K[2], tau=member.tau, delta=member.delta,
                             headway=member.headway)
        from ..certify.sampled_frequency import sampled_margin

        return sampled_margin(freq, K[0], K[1], K[2], tau=member.tau, delta=member.delta,
                              headway=member.headway, sample_time=self.H,
                              tau_prev=member.tau_prev)

    def _sampled_reaction(self, member: Member, freq: Array, K: Array) -> Array:
        """g_{H,θ_r} (:mod:`stringstab.tuning.sampled_reaction_margin`) shaped as ``freq``.

        ``K`` holds three floats (the result has the shape of ``freq``) or three arrays of
        one shape (one frequency: the result has the arrays' shape).
        """
        from .sampled_reaction_margin import sampled_reaction_margin

        p = Params(member.tau, member.delta, member.headway, self.reaction_delay)
        kx, kv, ka = (np.asarray(k, dtype=float) for k in K)
        f = np.asarray(freq, dtype=float)
        g = sampled_reaction_margin(f.ravel(), kx.ravel(), kv.ravel(), ka.ravel(), p, self.H,
                                    tau_prev=member.tau_prev)
        if kx.ndim == 0:
            return np.asarray(g[0].reshape(f.shape))
        return np.asarray(g[:, 0].reshape(kx.shape))

    def margin_slot(self, member: Member, freq: float) -> Slot:
        """The constraint g(freq; K) ≥ ε at ``member``, as a quadratic form in K.

        Parameters
        ----------
        member : Member
            The member of the box the margin is taken at.
        freq : float
            ω (rad/s) or, sampled, θ (rad/sample).

        Returns
        -------
        Slot
            Kind ``"margin"``, with the form (c, b, A) of g (:func:`quadratic_form`).
        """
        if self.reaction_delay:  # g_θ(ω; K) is quadratic in K too (margin_reaction's basis)
            form = quadratic_form(lambda x, v, a: self.margin(member, np.asarray(freq),
                                                              np.array([x, v, a])))
        elif not self.sampled:
            form = quadratic_form(lambda x, v, a: _margin.g(
                freq, x, v, a, tau=member.tau, delta=member.delta, headway=member.headway))
        else:
            from ..certify.sampled_frequency import sampled_margin

            form = quadratic_form(lambda x, v, a: sampled_margin(
                freq, x, v, a, tau=member.tau, delta=member.delta, headway=member.headway,
                sample_time=self.H, tau_prev=member.tau_prev))
        return Slot("margin", member, float(freq), 0, form)

    def stability_slots(self, member: Member) -> list[Slot]:
        """Internal stability at ``member``, as constraints that are quadratic forms in K.

        The Hurwitz conditions (continuous) or the normalised Schur conditions (sampled).
        With a reaction delay θ_r > 0 the one condition is k_x ≥ margin: the characteristic
        function D(s) = τs³ + s² + e^{−θ_r s}((k_v + T*k_x)s + k_x) is real on the real axis,
        D(0) = k_x and D(σ) → +∞, so k_x ≤ 0 puts a root on [0, ∞) (necessary, not
        sufficient: internal stability is the certificate's, which decides every output).
        Sampled with θ_r > 0: the two normalised necessary Schur conditions of the follower
        block's characteristic polynomial χ_f(z; K), at z = 1 (k_x) and z = −1
        (:func:`stringstab.tuning.sampled_reaction_margin.stability_conditions`).

        Parameters
        ----------
        member : Member
            The member of the box.

        Returns
        -------
        list of Slot
            Kind ``"stability"``: two Hurwitz conditions
            (:func:`stringstab.certify.criteria.hurwitz_conditions`) or five Schur conditions
            (:func:`stringstab.certify.schur.schur_margins`), ``index`` 0, 1, …; with θ_r > 0,
            k_x alone (index 0).
        """
        if self.reaction_delay and self.sampled:  # two necessary Schur conditions of χ_f
            from .sampled_reaction_margin import stability_conditions

            p = Params(member.tau, member.delta, member.headway, self.reaction_delay)
            both = np.array([quadratic_form(lambda x, v, a: stability_conditions(x, v, a, p, self.H)[0]),
                             quadratic_form(lambda x, v, a: stability_conditions(x, v, a, p, self.H)[1])])
            return [Slot("stability", member, math.nan, i, f) for i, f in enumerate(both)]
        if self.reaction_delay:
            return [Slot("stability", member, math.nan, 0, quadratic_form(lambda x, v, a: x))]
        def conditions(x: Array, v: Array, a: Array) -> Array:
            if not self.sampled:
                return np.asarray(hurwitz_conditions(x, v, a, tau=member.tau,
                                                     headway=member.headway))
            from ..certify.schur import schur_margins

            return schur_margins(x, v, tau=member.tau, headway=member.headway, sample_time=self.H)

        n = 5 if self.sampled else 2

        def one(i: int) -> Callable[[Array, Array, Array], Array]:
            return lambda x, v, a: conditions(x, v, a)[i]

        return [Slot("stability", member, math.nan, i, quadratic_form(one(i))) for i in range(n)]

    # ------------------------------------------------------------------ frequencies
    def ladder(self) -> list[float]:
        """Fixed frequencies of the first solve.

        Continuous: 0 and 16 frequencies from 0.2 to 5 rad/s (geometric).  Sampled: as θ = ωH
        (rad/sample), 0, the same 16 and 3 more from 6 to 10 rad/s (geometric), each capped at
        π, and π itself, without duplicates.

        Returns
        -------
        list of float
            ω (rad/s) or θ (rad/sample), increasing.
        """
        w = np.geomspace(0.2, 5.0, 16)
        if not self.sampled:
            return [0.0, *w.tolist()]
        th = np.concatenate([w, np.geomspace(6.0, 10.0, 3)]) * self.H
        return [0.0, *sorted({float(min(t, math.pi)) for t in th} | {math.pi})]

    def dips(self, K: Array, member: Member, threshold: float, n: int = 384) -> list[float]:
        """Local minima of the margin at ``member`` below ``threshold`` (a scan, zoomed).

        A heuristic to pick frequencies, never a proof.

        Parameters
        ----------
        K : ndarray, shape (3,)
            Gains (k_x, k_v, k_a).
        member : Member
            The member of the box.
        threshold : float
            Only minima with a margin below it are returned.
        n : int
            Grid points of the scan on [0, π] (sampled) or on [0, Ω] (θ_r > 0, Ω the proven
            tail bound of g_θ; the continuous scan without θ_r is
            :func:`stringstab.certify.margin.local_minima`'s).

        Returns
        -------
        list of float
            The minimisers: ω (rad/s) or θ (rad/sample), at most 12.
        """
        top = math.pi
        if self.reaction_delay and self.sampled:  # θ_r > 0 sampled: the scan below on [0, π]
            pass
        elif self.reaction_delay:  # θ_r > 0: the scan below on [0, Ω], g_θ > 0 beyond Ω (proven)
            Q = _margin_reaction.coefficient_table(
                np.array([K[0]]), np.array([K[1]]), np.array([K[2]]), member.tau, member.delta,
                member.headway, self.reaction_delay)
            top = float(_margin_reaction.tail_bound(Q)[0])
        elif not self.sampled:
            return _margin.local_minima(K, tau=member.tau, delta=member.delta,
                                        headway=member.headway, threshold=threshold)[1]
        grid = np.linspace(0.0, top, n)
        g = self.margin(member, grid, K)
        left = np.concatenate([[np.inf], g[:-1]])
        right = np.concatenate([g[1:], [np.inf]])
        idx = np.flatnonzero((g <= left) & (g <= right) & (g < threshold))[:12]
        out = []
        for i in idx:
            lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, n - 1)]
            for _ in range(5):
                z = np.linspace(lo, hi, 9)
                j = int(np.argmin(self.margin(member, z, K)))
                h = (hi - lo) / 8.0
                lo, hi = max(z[j] - h, 0.0), min(z[j] + h, top)
            out.append(float(0.5 * (lo + hi)))
        return out

    # ------------------------------------------------------------------ the certificate
    def check(self, K: Array) -> tuple[str, bool, list[tuple[Member, float]]]:
        """The certificate of this loop on K: (verdict, internally stable, witnesses).

        A witness is a member and a frequency (ω, or θ when sampled) where the margin was
        found smallest: |Γ| > 1 (|H| > 1) there when K is internally stable and not certified.

        Parameters
        ----------
        K : ndarray, shape (3,)
            Gains (k_x, k_v, k_a).

        Returns
        -------
        verdict : str
            ``"certified"``, ``"not_certified"`` or ``"inconclusive"``
            (:func:`stringstab.certify.api.check`).
        stable : bool
            Internally stable (every member of the box, for a box).
        witnesses : list of (Member, float)
            The witness, if its frequency is finite; the box's centre stands in for a member the
            certificate does not report.
        """
        from ..certify.api import check

        b = self.box
        c = check(K[0], K[1], K[2], tau=b.tau, delta=b.delta, headway=b.headway,
                  sample_time=self.sample_time, heterogeneous=self.heterogeneous,
                  reaction_delay=self.reaction_delay)
        verdict, stable = str(c.verdict[0]), bool(c.hurwitz[0])
        freq = c.witness_theta if c.witness_theta is not None else c.witness_omega
        f = float(np.asarray(freq)[0])
        if c.witness_tau is not None:
            t = float(c.witness_tau[0])
            tp = float(np.asarray(c.witness_tau_prev)[0]) if c.witness_tau_prev is not None else t
            member = Member(t, tp if math.isfinite(tp) else t,
                            float(np.asarray(c.witness_delta)[0]),
                            float(np.asarray(c.witness_headway)[0]))
        else:
            member = self.centre()
        if not all(math.isfinite(x) for x in (member.tau, member.delta, member.headway)):
            member = self.centre()
        return verdict, stable, ([(member, f)] if math.isfinite(f) else [])

    def certify(self, K: Array) -> Any:
        """The full certificate of K (for a result that failed: its verdict and sup gain).

        Parameters
        ----------
        K : ndarray, shape (3,)
            Gains (k_x, k_v, k_a).

        Returns
        -------
        Certificate
            :func:`stringstab.certify.api.certify` on this loop (point or box, continuous or
            sampled).
        """
        from ..certify.api import certify

        b = self.box
        return certify(K[0], K[1], K[2], tau=b.tau, delta=b.delta, headway=b.headway,
                       sample_time=self.sample_time, heterogeneous=self.heterogeneous,
                       reaction_delay=self.reaction_delay)

    def certified_points(self, K: Array) -> npt.NDArray[np.bool_]:
        """Which rows of K (n, 3) this loop's certificate certifies.

        :func:`stringstab.certify.grid.certified` on this loop (its cheap steps first: the
        screen, and for a box the certificate at the box's centre).

        Parameters
        ----------
        K : ndarray, shape (n, 3)
            Gain triples (k_x, k_v, k_a).

        Returns
        -------
        bool ndarray, shape (n,)
            True where certified.
        """
        return certified(K, self.params, sample_time=self.sample_time,
                         heterogeneous=self.heterogeneous)
