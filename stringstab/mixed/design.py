r"""CAVs that make a recorded string string stable head to tail: their gains, or the best sup found.

The followers at the chosen positions (the leader is 0) are replaced by CAVs running the
predecessor-following eq-4 law with their own τ, δ, T* (:class:`CavSpec`); their gains are
chosen to maximise the string's **attenuation margin**

.. math::
    μ(K) = \min_{ω > 0} \; −\ln\Big(\prod_i |Γ_i(jω)|^2\Big)\,\frac{1 + ω^2}{ω^2},

the largest μ with ∏_i |Γ_i(jω)|² ≤ exp(−μ ω²/(1 + ω²)) at every ω: the product's energy
falls by at least a factor e^{−μω²} at low frequency (μ → Σ_i Ψ3_i/k_{x,i}² = G(0)/∏ d_i(0)
as ω → 0, G the telescoping margin of :mod:`stringstab.certify.head_to_tail`) and e^{−μ}
well above the corner of 1 rad/s; μ > 0 iff the product stays below 1 at every ω > 0.  It is
maximised within the gain bounds, subject to the CAV's internal stability with a margin.  For
one CAV (the others held), G(ω) and ∏ d_i(ω) are linear in its n_c, d_c and g_c, hence
**quadratic forms in its gains** K_c at every ω, and so is the constraint
G(ω_j) − r_j ∏d_i(ω_j) ≥ 0 with r_j = (1 − e^{−μω_j²/(1+ω_j²)})/ω_j² (r = μ at ω = 0),
which is μ(ω_j) ≥ μ: recovered exactly by polarisation (:func:`stringstab.tuning.constraints.quadratic_form`) and
handed to the tuning's quadratic NLP (:func:`stringstab.tuning.nlp.solve_quadratic`, CasADi/
IPOPT) under the exchange method (:func:`stringstab.tuning.exchange.exchange`): solve, scan μ(ω)
on a dense grid, add the worst frequency, solve again.  A bisection on μ finds the largest
margin the search reaches; several CAVs are designed by block-coordinate sweeps (one CAV at a
time, the others held).

**The certificate is the final judge**: a design is reported certified only when
:func:`stringstab.certify.api.certify_string` certifies the whole string with it.  When no
μ > 0 is reached (or none certifies), the result says so and gives the smallest sup ∏|Γ_i|
found by a local search from the best margin's gains — a search result, not a proof that no
gains could do better.  ``auto`` tries every single position, then pairs, up to ``max_cavs``,
and keeps the fewest CAVs with a certified design (the largest margin among them).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from itertools import combinations
from typing import Any

import numpy as np
import numpy.typing as npt

from ..certify.head_to_tail import Vehicle
from ..certify.verdicts import Verdict
from .attenuation import (
    attenuation_margin,
    cav_forms,
    margin_curve,
    margins,
    rate,
    scan_grid,
    terms,
)
from .cav import CavSpec, check_positions, string_with_cavs

__all__ = ["Design", "design_auto", "design_cavs"]

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Design:
    """A CAV design for a string (module docstring).

    Attributes
    ----------
    positions : tuple of int
        Where the CAVs are (1-based; the leader is 0).
    gains : tuple of (float, float, float)
        Each CAV's (k_x, k_v, k_a).
    vehicles : tuple of Vehicle
        The whole string with the CAVs.
    certificate : StringCertificate
        The head-to-tail certificate of that string (the final judge).
    margin : float
        μ of the design on the search's dense grid (reporting; the certificate decides).
    certified : bool
        The certificate certifies the string.
    note : str
        What was found, in words.
    tried : list of dict
        ``auto``: every set of positions tried (positions, verdict, margin, sup).
    proven_none : bool
        Not certified, and proven that no gains within the bounds certify this one CAV
        (:func:`stringstab.mixed.exclusion.prove_no_cav`).
    """

    positions: tuple[int, ...]
    gains: tuple[tuple[float, float, float], ...]
    vehicles: tuple[Vehicle, ...]
    certificate: Any
    margin: float
    certified: bool
    note: str
    tried: list[dict[str, Any]] = field(default_factory=list)
    proven_none: bool = False

    def as_dict(self) -> dict[str, Any]:
        """The JSON of ``stringstab platoon design``: ``vehicles``, ``head_to_tail``, ``design``.

        Returns
        -------
        dict
            The certificate's :meth:`~stringstab.certify.string_certificate.StringCertificate.as_dict`
            (each vehicle with ``cav`` true or false) and a ``design`` object (positions, gains,
            margin, certified, note, tried).
        """
        d = self.certificate.as_dict()
        for row in d["vehicles"]:
            row["cav"] = row["position"] in self.positions
        d["design"] = {"cav_positions": list(self.positions),
                       "gains": [dict(zip(("k_x", "k_v", "k_a"), g)) for g in self.gains],
                       "margin": _num(self.margin), "certified": self.certified,
                       "proven_none": self.proven_none, "note": self.note, "tried": self.tried}
        return d


def _num(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


# ---------------------------------------------------------------------------
# One CAV: the largest margin by bisection, each level by the exchange method
# ---------------------------------------------------------------------------
def _stability_slots(spec: CavSpec) -> list[Any]:
    from ..certify.criteria import hurwitz_conditions
    from ..tuning.constraints import Member, Slot, quadratic_form

    m = Member(spec.tau, spec.tau, spec.delta, spec.headway)
    out = []
    # the Hurwitz conditions of the cubic hold for θ_r = 0 only; with θ_r the root count of the
    # certificate judges (k_x ≥ min_kx below stays necessary: k_x ≤ 0 puts a root in s ≥ 0)
    for i in range(2 if spec.reaction_delay == 0 else 0):
        def cond(kx: Array, kv: Array, ka: Array, i: int = i) -> Array:
            return np.asarray(hurwitz_conditions(kx, kv, ka, tau=spec.tau, headway=spec.headway)[i],
                              dtype=float) * np.ones_like(kx)

        form = quadratic_form(cond)
        out.append(Slot("stability", m, math.nan, i, form))
    # k_x ≥ min_kx, as a stability row (its lower bound is the Hurwitz margin m):
    # k_x − min_kx + m ≥ m
    form = np.zeros(10)
    form[0], form[1] = spec.hurwitz_margin - spec.min_kx, 1.0
    out.append(Slot("stability", m, math.nan, 2, form))
    return out


#: Relative tolerance of a margin level: the NLP asks for μ(1 + TOL/2) at its frequencies, the
#: scan accepts μ(1 − TOL) on its grid (the constraints hold at finitely many frequencies only).
TOL = 2e-3


def _feasible(vehicles: Sequence[Vehicle], pos: int, spec: CavSpec, mu: float, K: Array,
              omega: Array, start: list[float], max_solves: int = 12) -> Array | None:
    """Gains with μ(K) ≥ ``mu`` (within :data:`TOL`) on the grid near K (the exchange method)."""
    from ..tuning.constraints import Member, Slot
    from ..tuning.exchange import CLUSTER, dedupe_slots, exchange, fit_forms
    from ..tuning.nlp import solve_quadratic

    tol = TOL * max(1.0, abs(mu))
    level = mu + 0.5 * tol

    member = Member(spec.tau, spec.tau, spec.delta, spec.headway)
    stab = _stability_slots(spec)
    freqs: list[float] = list(start)

    def slots_for(x: Array, fs: list[float]) -> list[Any]:
        w = np.asarray(fs, dtype=float)
        fG, fD, _ = cav_forms(vehicles, pos, spec, w)
        F = fG - rate(level, w)[None, :] * fD
        # each constraint scaled by its ∏d_i at x: O(1) rows for IPOPT
        from ..tuning.constraints import evaluate_forms

        scale = np.abs(evaluate_forms(fD.T, x))
        F = F / np.where(scale > 0, scale, 1.0)[None, :]
        return stab + [Slot("margin", member, float(f), 0, F[:, j]) for j, f in enumerate(fs)]

    state = {"slots": slots_for(K, freqs)}

    def solve(x: Array) -> tuple[Array, str, int]:
        slots = fit_forms(dedupe_slots(state["slots"]), x)
        return solve_quadratic(K, x, slots, weights=np.ones(3), bounds=spec.bounds,
                               hurwitz_margin=spec.hurwitz_margin, eps=0.0)

    def step(x: Array) -> str:
        s = string_with_cavs(vehicles, [pos], [x], spec)
        G, _, D, stable = terms([s], omega)
        if not stable[0]:
            return "stuck"
        mu_w = margin_curve(G, D, omega)[0]
        j = int(np.argmin(mu_w))
        if mu_w[j] >= mu - tol:
            return "certified"  # feasible at this level (the certificate judges the end result)
        w = float(omega[j])
        if any(abs(w - f) <= 1e-9 * max(1.0, w) for f in freqs):
            return "stuck"
        freqs.extend([w, w * (1 - CLUSTER), w * (1 + CLUSTER)])
        state["slots"] = slots_for(x, freqs)
        return "grown"

    best, _, _, _, _ = exchange(np.asarray(K, dtype=float), max_solves, solve, step)
    return None if best is None else np.asarray(best, dtype=float)


def _local_minima(values: Array, omega: Array, k: int = 8) -> list[float]:
    left = np.r_[np.inf, values[:-1]]
    right = np.r_[values[1:], np.inf]
    idx = np.flatnonzero((values <= left) & (values <= right))
    idx = idx[np.argsort(values[idx])[:k]]
    return sorted({0.0, *(float(omega[i]) for i in idx)})


def _candidates(spec: CavSpec) -> Array:
    lo, hi = spec.bounds
    kx = [v for v in (0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0)
          if max(lo, spec.min_kx) <= v <= hi]
    kv = [v for v in (0.05, 0.1, 0.2, 0.4, 0.7, 1.0, 1.5, 2.0) if lo <= v <= hi]
    ka = [v for v in (-0.3, 0.0, 0.3, 0.6, 0.9) if lo <= v <= hi]
    if not (kx and kv and ka):
        return np.array([0.5 * (spec.lower() + spec.upper())])
    return np.array([(a, b, c) for a in kx for b in kv for c in ka])


def _best_start(vehicles: Sequence[Vehicle], pos: int, spec: CavSpec, omega: Array,
                current: Array | None) -> tuple[Array, float]:
    C = _candidates(spec)
    if current is not None:
        C = np.vstack([current[None, :], C])
    mus = margins([string_with_cavs(vehicles, [pos], [k], spec) for k in C], omega)
    j = int(np.argmax(mus))
    return C[j], float(mus[j])


def _design_one(vehicles: Sequence[Vehicle], pos: int, spec: CavSpec, omega: Array,
                K0: Array | None, steps: int) -> tuple[Array, float, list[tuple[float, Array]]]:
    """The CAV at ``pos`` with the largest margin the bisection reaches (others held).

    Starts from the best of a coarse grid of gains (and ``K0``); when its margin is ≤ 0, first
    asks for any μ ≥ 0; then doubles μ until a level is not reached, and bisects.
    """
    K, lo = _best_start(vehicles, pos, spec, omega, K0)
    feasible = [(lo, K)]
    if not math.isfinite(lo):
        return K, lo, feasible

    def start_freqs(K: Array) -> list[float]:
        G, _, D, _ = terms([string_with_cavs(vehicles, [pos], [K], spec)], omega)
        return _local_minima(margin_curve(G, D, omega)[0], omega)

    def attempt(mu: float) -> tuple[Array, float] | None:
        x = _feasible(vehicles, pos, spec, mu, K, omega, start_freqs(K))
        if x is None:
            return None
        return x, attenuation_margin(string_with_cavs(vehicles, [pos], [x], spec), omega)

    if lo <= 0:  # a derivative-free climb on the scanned margin first, then the NLP at μ = 0
        K2, lo2 = _climb(vehicles, pos, spec, omega, K)
        if lo2 > lo:
            K, lo = K2, lo2
            feasible.append((lo, K))
    if lo <= 0:
        got = attempt(0.0)
        if got is None or got[1] <= lo:
            return K, lo, feasible
        K, lo = got
        feasible.append((lo, K))
    hi = math.inf
    for _ in range(steps):
        if lo <= 0 or hi - lo <= 1e-3 * max(1.0, abs(lo)):
            break
        mid = 2.0 * max(lo, 0.5) if math.isinf(hi) else 0.5 * (lo + hi)
        got = attempt(mid)
        if got is None or got[1] <= lo:
            hi = mid
            continue
        K, lo = got
        feasible.append((lo, K))
    return K, lo, feasible


def _climb(vehicles: Sequence[Vehicle], pos: int, spec: CavSpec, omega: Array,
           K: Array) -> tuple[Array, float]:
    """Nelder-Mead on the scanned margin μ from K, within the bounds (a search, no proof)."""
    from scipy.optimize import minimize

    def neg_mu(k: Array) -> float:
        kc = spec.clip(k)
        m = attenuation_margin(string_with_cavs(vehicles, [pos], [kc], spec), omega)
        return 1e6 if not math.isfinite(m) else -m

    res = minimize(neg_mu, np.asarray(K, dtype=float), method="Nelder-Mead",
                   options={"maxfev": 300, "xatol": 1e-5, "fatol": 1e-6,
                            "initial_simplex": np.asarray(K)[None, :] + np.vstack(
                                [np.zeros(3), 0.3 * np.diag(np.maximum(np.abs(K), 0.05))])})
    k = spec.clip(res.x)
    return k, -neg_mu(k)


def _min_sup(vehicles: Sequence[Vehicle], positions: Sequence[int], gains: list[Array],
             spec: CavSpec, omega: Array) -> list[Array]:
    """A local search (Nelder-Mead) for the smallest sup ∏|Γ_i| on the grid (a search, no proof)."""
    from scipy.optimize import minimize

    gains = [np.asarray(g, dtype=float) for g in gains]

    def sup(flat: Array) -> float:
        gs = spec.clip(flat.reshape(-1, 3))
        s = string_with_cavs(vehicles, positions, list(gs), spec)
        G, _, D, stable = terms([s], omega)
        if not stable[0]:
            return 1e6
        prod2 = 1.0 - omega * omega * G[0] / D[0]
        return float(np.sqrt(max(float(np.max(prod2)), 0.0)))

    x0 = np.concatenate(gains)
    res = minimize(sup, x0, method="Nelder-Mead",
                   options={"maxfev": 400 * len(gains), "xatol": 1e-4, "fatol": 1e-6})
    best = res.x if res.fun <= sup(x0) else x0
    return list(spec.clip(best.reshape(-1, 3)))


def design_cavs(vehicles: Sequence[Vehicle], positions: Sequence[int], spec: CavSpec | None = None,
                *, sweeps: int = 3, steps: int = 14) -> Design:
    """CAV gains at ``positions`` for the largest margin; certified by the head-to-tail certificate.

    Parameters
    ----------
    vehicles : sequence of Vehicle
        The recorded followers, positions 1..N (N ≥ 2).
    positions : sequence of int
        1-based positions to replace by CAVs (distinct, within 1..N).
    spec : CavSpec, optional
        The CAV (default :class:`CavSpec`).
    sweeps : int
        Block-coordinate sweeps over the CAVs (one suffices for a single CAV).
    steps : int
        Bisection steps on μ per CAV and sweep.

    Returns
    -------
    Design
        ``certified`` only when :func:`stringstab.certify.api.certify_string` certifies the
        string with the CAVs.

    Raises
    ------
    StringStabError
        On a position outside 1..N or repeated, or a bad CAV parameter.
    """
    from ..certify.api import certify_string

    spec = spec or CavSpec()
    spec.params()
    vs = tuple(vehicles)
    pos = check_positions(positions, len(vs))
    omega = scan_grid(vs)
    proof = _exclusion(vs, pos, spec)
    gains: list[Array | None] = [None for _ in pos]
    mu = -math.inf
    history: list[list[tuple[float, Array]]] = [[] for _ in pos]
    if proof is None or not proof.proven:  # no search where none exists
        for _sweep in range(max(1, sweeps) if len(pos) > 1 else 1):
            for j, p in enumerate(pos):
                held = [(q, g) for i, (q, g) in enumerate(zip(pos, gains))
                        if i != j and g is not None]
                base = string_with_cavs(vs, [q for q, _ in held], [g for _, g in held], spec)
                K, mu, feas = _design_one(base, p, spec, omega, gains[j], steps)
                gains[j] = K
                history[j] = feas
        designed = [g for g in gains if g is not None]
        # the certificate judges, from the largest margin down
        tries: list[list[Array]] = [designed]
        if len(pos) == 1:
            tries += [[K] for m, K in sorted(history[0], key=lambda t: -t[0])[1:4] if m > 0]
        for gs in tries:
            cert = certify_string(string_with_cavs(vs, pos, gs, spec))
            if cert.certified:
                final = string_with_cavs(vs, pos, gs, spec)
                mu_final = attenuation_margin(final, omega)
                note = (f"certified head to tail with CAV(s) at {_positions(pos)}: attenuation "
                        f"margin μ = {mu_final:.4g} on the search grid")
                return Design(pos, tuple(_triple(g) for g in gs), final, cert, mu_final, True,
                              note)
    else:
        designed = [_min_sup_start(vs, p, spec, omega) for p in pos]
    # none certified: the smallest sup a local search finds, reported as such
    best = _min_sup(vs, pos, designed, spec, omega)
    final = string_with_cavs(vs, pos, best, spec)
    cert = certify_string(final)
    if cert.certified:
        mu_final = attenuation_margin(final, omega)
        note = (f"certified head to tail with CAV(s) at {_positions(pos)} (found by the search "
                f"for the smallest sup; attenuation margin μ = {mu_final:.4g} on the search grid)")
        return Design(pos, tuple(_triple(g) for g in best), final, cert, mu_final, True, note)
    why = _exclusion_words(proof)
    reached = "" if proof is not None and proof.proven else \
        f"; the largest margin the search reached is μ = {mu:.4g}"
    note = (f"no certified design at {_positions(pos)} within the gain bounds "
            f"{list(spec.bounds)} (k_x >= {spec.min_kx:g}): {why}{reached}; the smallest sup ∏|Γ_i| a local search "
            f"found is {cert.sup_gain:.4g} ({cert.verdict}; a search result, not a proven minimum)")
    return Design(pos, tuple(_triple(g) for g in best), final, cert,
                  attenuation_margin(final, omega), False, note, proven_none=bool(proof and proof.proven))


def _exclusion(vs: Sequence[Vehicle], pos: Sequence[int], spec: CavSpec) -> Any:
    """The exclusion proof for one CAV (None for several: it does not cover them)."""
    if len(pos) != 1:
        return None
    from .exclusion import prove_no_cav

    return prove_no_cav(vs, pos[0], spec)


def _exclusion_words(ex: Any) -> str:
    if ex is None:
        return "none found by the search (not proven: the proof covers one CAV)"
    if ex.proven:
        return (f"none exists (proven: every gain box fails the CAV's Hurwitz conditions or "
                f"G(ω) ≥ 0 at one of {ex.frequencies} frequencies; {ex.boxes} boxes)")
    return (f"none found by the search (the exclusion proof left {ex.remaining} of "
            f"{ex.boxes} boxes undecided: not proven)")


def _min_sup_start(vs: Sequence[Vehicle], pos: int, spec: CavSpec, omega: Array) -> Array:
    """The gains of the coarse grid with the smallest scanned sup ∏|Γ_i| (internally stable)."""
    C = _candidates(spec)
    strings = [string_with_cavs(vs, [pos], [k], spec) for k in C]
    G, _, D, stable = terms(strings, omega)
    sup2 = np.max(1.0 - omega * omega * G / D, axis=1)
    sup2 = np.where(stable, sup2, np.inf)
    return C[int(np.argmin(sup2))]


def _triple(g: Any) -> tuple[float, float, float]:
    return (float(g[0]), float(g[1]), float(g[2]))


def _positions(pos: Sequence[int]) -> str:
    return ("position " if len(pos) == 1 else "positions ") + ",".join(str(p) for p in pos)


def design_auto(vehicles: Sequence[Vehicle], spec: CavSpec | None = None, *, max_cavs: int = 2,
                steps: int = 12) -> Design:
    """The fewest CAVs (and where) that certify the string: every position, then pairs, ...

    Every set of ``k`` positions is designed (:func:`design_cavs`) for k = 1, 2, ...,
    ``max_cavs``; the first k with a certified design wins, and among its certified designs the
    one of the largest margin.  When none certifies, the design of the smallest sup found.

    Parameters
    ----------
    vehicles : sequence of Vehicle
        The recorded followers.
    spec : CavSpec, optional
        The CAV.
    max_cavs : int
        The most CAVs tried.
    steps : int
        Bisection steps per design.

    Returns
    -------
    Design
        With ``tried``: every set of positions, its verdict, margin and sup.
    """
    spec = spec or CavSpec()
    vs = tuple(vehicles)
    tried: list[dict[str, Any]] = []
    best_fail: Design | None = None
    for k in range(1, min(max_cavs, len(vs)) + 1):
        found: list[Design] = []
        for pos in combinations(range(1, len(vs) + 1), k):
            d = design_cavs(vs, pos, spec, steps=steps)
            tried.append({"positions": list(pos), "verdict": d.certificate.verdict,
                          "margin": _num(d.margin), "sup_gain": _num(d.certificate.sup_gain),
                          "proven_none": d.proven_none, "gains": [list(g) for g in d.gains]})
            if d.certified:
                found.append(d)
            elif best_fail is None or d.certificate.sup_gain < best_fail.certificate.sup_gain:
                best_fail = d
        if found:
            best = max(found, key=lambda d: d.margin)
            return replace(best, tried=tried,
                           note=best.note + f"; the fewest CAVs that certify: {k} "
                           f"({sum(1 for t in tried if t['verdict'] == Verdict.CERTIFIED)} of "
                           f"{len(tried)} sets tried certify)")
    assert best_fail is not None
    return replace(best_fail, tried=tried,
                   note=f"no set of up to {max_cavs} CAV(s) certified; " + best_fail.note)
