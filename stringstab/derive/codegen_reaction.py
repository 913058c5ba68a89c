"""The generated numeric code of the reaction-delay formulas (θ_r, issue 25).

:mod:`stringstab.derive.codegen` writes :mod:`stringstab.derive.generated`; the blocks of the
θ_r formulas (:mod:`stringstab.derive.reaction`) come from :func:`reaction_blocks`, which it
calls with its own source printer.  The same rules hold: plain arithmetic, ``abs`` and the
``cos``/``sin`` handed in, so the numeric certificate (:mod:`stringstab.certify.quasipolynomial`,
:mod:`stringstab.certify.margin_reaction`) never imports SymPy, and ``tests/derive/test_margin.py``
checks the committed file against a fresh generation.

References
----------
Issue 25 (the model with θ_r); :mod:`stringstab.derive.reaction` (the derivation).
"""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp

from . import reaction as R
from . import symbolic as S

__all__ = ["REACTION_MARGIN_BASIS", "reaction_blocks", "reaction_margin_basis"]

#: The terms of g_θ(ω) = (|D(jω)|² − |N(jω)|²)/ω² with the reaction delay, as (name, sign,
#: trigonometric factor, power of ω): g_θ = t2 ω⁴ + a ω² + b + cx cos δω − cv ω sin δω
#: + r0 cos θ_rω + r2 ω² cos θ_rω + r1 ω sin θ_rω.  :func:`reaction_margin_basis` checks the
#: derivation has exactly these; the tail and curvature bounds of
#: :mod:`stringstab.certify.margin_reaction` rely on it.
REACTION_MARGIN_BASIS: tuple[tuple[str, int, str, int], ...] = (
    ("t2", 1, "1", 4),
    ("a", 1, "1", 2),
    ("b", 1, "1", 0),
    ("cx", 1, "cos_delta", 0),
    ("cv", -1, "sin_delta", 1),
    ("r0", 1, "cos_reaction", 0),
    ("r2", 1, "cos_reaction", 2),
    ("r1", 1, "sin_reaction", 1),
)

#: Gain and parameter arguments of every generated θ_r function.
_ARGS = [str(x) for x in (*S.GAINS, *S.PARAMS, R.reaction_delay)]


def _trig() -> dict[str, sp.Expr]:
    w, d, th = S.omega, S.delta, R.reaction_delay
    return {"1": sp.Integer(1), "cos_delta": sp.cos(d * w), "sin_delta": sp.sin(d * w),
            "cos_reaction": sp.cos(th * w), "sin_reaction": sp.sin(th * w)}


def _delay_of(trig: str) -> sp.Expr:
    return {"1": sp.Integer(0), "cos_delta": S.delta, "sin_delta": S.delta}.get(trig, R.reaction_delay)


def reaction_margin_basis() -> dict[str, sp.Expr]:
    """The coefficient of each term of :data:`REACTION_MARGIN_BASIS` in the derived g_θ(ω).

    Returns
    -------
    dict of str to sympy.Expr
        Each basis term's name mapped to its coefficient in g_θ(ω)
        (:func:`stringstab.derive.reaction.margin_reaction`).

    Raises
    ------
    AssertionError
        When the derived g_θ has other terms (a changed model needs new bounds).
    """
    trig = _trig()
    factors = [v for k, v in trig.items() if k != "1"]
    parts = sp.collect(R.margin_reaction(), factors, evaluate=False)
    found: dict[tuple[str, int], sp.Expr] = {}
    for tname, factor in trig.items():
        expr = parts.get(factor, 0)
        if expr == 0:
            continue
        for (k,), c in sp.Poly(expr, S.omega).terms():
            found[(tname, k)] = sp.expand(c)
    expected = {(t, k) for _, _, t, k in REACTION_MARGIN_BASIS}
    if set(found) != expected:  # pragma: no cover - only when the model changes
        raise AssertionError(f"g_θ has terms {sorted(found)}; expected {sorted(expected)}")
    return {name: sp.expand(sign * found[(t, k)]) for name, sign, t, k in REACTION_MARGIN_BASIS}


def _abs_terms(e: sp.Expr) -> sp.Expr:
    """Σ |term| over the terms of the expanded ``e`` (a round-off scale of ``e``)."""
    return sp.Add(*[sp.Abs(t) for t in sp.Add.make_args(sp.expand(e))])


def _curvature(c: dict[str, sp.Symbol], r: sp.Symbol) -> sp.Expr:
    """A bound on |g_θ''(ω)| for 0 ≤ ω ≤ r, term by term.

    |d²/dω² ω^k f(dω)| ≤ k(k−1) r^{k−2} + 2kd r^{k−1} + d² r^k for f = cos, sin of a delay d
    (|f|, |f'|, |f''| ≤ 1), and k(k−1) r^{k−2} without a trigonometric factor.
    """
    out = sp.Integer(0)
    for n, _sign, t, k in REACTION_MARGIN_BASIS:
        bound = k * (k - 1) * r ** max(k - 2, 0) if k >= 2 else sp.Integer(0)
        if t != "1":
            d = _delay_of(t)
            bound += 2 * k * d * r ** max(k - 1, 0) + d**2 * r**k
        out += sp.Abs(c[n]) * bound
    return sp.expand(out)


def reaction_blocks(function: Callable[..., str]) -> list[str]:
    """The source blocks of the θ_r functions of :mod:`stringstab.derive.generated`.

    Parameters
    ----------
    function : callable
        The code generator's printer of one function,
        ``function(name, args, outputs, doc, *, trig=False, single=False)`` → source text.

    Returns
    -------
    list of str
        One block per generated function or constant.
    """
    w = S.omega
    blocks: list[str] = []
    names = [n for n, *_ in REACTION_MARGIN_BASIS]
    basis = reaction_margin_basis()
    blocks.append("#: Names of the coefficients returned by :func:`reaction_margin_coefficients`.\n"
                  f"REACTION_MARGIN_COEFFICIENTS = {tuple(names)!r}\n")
    blocks.append("#: (name, trigonometric factor, power of ω) of each coefficient of g_θ.\n"
                  f"REACTION_MARGIN_BASIS = {tuple((n, t, k) for n, _s, t, k in REACTION_MARGIN_BASIS)!r}\n")
    blocks.append(function(
        "reaction_margin_coefficients", _ARGS, [basis[n] for n in names],
        "(t2, a, b, cx, cv, r0, r2, r1) of g_θ(ω) = t2 ω⁴ + a ω² + b + cx cos δω − cv ω sin δω "
        "+ r0 cos θ_rω + r2 ω² cos θ_rω + r1 ω sin θ_rω (issue 25).",
    ))
    blocks.append(function(
        "reaction_margin_coefficient_scales", _ARGS, [_abs_terms(basis[n]) for n in names],
        "Σ |term| of each coefficient of :func:`reaction_margin_coefficients` (round-off scales).",
    ))
    c = {n: sp.Symbol(n, positive=True) if n == "t2" else sp.Symbol(n, real=True) for n in names}
    sc = {n: sp.Symbol(f"s_{n}", nonnegative=True) for n in names}
    trig = _trig()
    g = sp.Add(*[sign * c[n] * w**k * trig[t] for n, sign, t, k in REACTION_MARGIN_BASIS])
    # the scale of a trigonometric term also covers the round-off of its angle d·ω (d ω ε)
    scale = sp.Add(*[sc[n] * w**k * (1 + _delay_of(t) * w) for n, _s, t, k in REACTION_MARGIN_BASIS])
    delays = ["delta", "reaction_delay"]
    blocks.append(function(
        "reaction_margin_and_scale", ["omega", *names, *(f"s_{n}" for n in names), *delays],
        [g, scale],
        "(g_θ(ω), Σ |term of g_θ(ω)|·(1 + its angle)) from the coefficients and their scales.",
        trig=True,
    ))
    r = sp.Symbol("r", nonnegative=True)
    blocks.append(function(
        "reaction_margin_curvature_bound", ["r", *names, *delays], [_curvature(c, r)],
        "M ≥ |g_θ''(ω)| for every ω in [0, r], from the coefficients.", single=True,
    ))

    # ---- Γ(jω) with θ_r, and the quasi-polynomial D = P + e^{-θ_r s} Q
    gam = R.gamma_reaction()
    P, Q = gam.P, gam.Q
    nr, ni = (sp.expand(x) for x in R.at_jomega(gam.numerator))
    dr, di = (sp.expand(x) for x in R.at_jomega(gam.denominator))
    blocks.append(function(
        "reaction_gamma_parts", ["omega", *_ARGS], [nr, ni, dr, di],
        "(Re N(jω), Im N(jω), Re D(jω), Im D(jω)) of Γ = N/D with the reaction delay.", trig=True,
    ))
    pc, qc = sp.Poly(P, S.s).all_coeffs(), sp.Poly(Q, S.s).all_coeffs()
    th = R.reaction_delay
    deg_p, deg_q = len(pc) - 1, len(qc) - 1
    p_abs = sp.Add(*[_abs_terms(a) * w ** (deg_p - i) for i, a in enumerate(pc)])
    q_abs = sp.Add(*[_abs_terms(a) * w ** (deg_q - i) for i, a in enumerate(qc)])
    blocks.append(function(
        "reaction_denominator_parts", ["omega", *_ARGS], [dr, di, p_abs + q_abs * (1 + th * w)],
        "(Re D(jω), Im D(jω), S(ω)) of D = P + e^{−θ_r s}Q; S = Σ|p_k|ω^k + (1 + θ_rω)Σ|q_k|ω^k "
        "bounds the terms (and the angle's round-off).", trig=True,
    ))
    slope = (sp.Add(*[(deg_p - i) * _abs_terms(a) * r ** max(deg_p - i - 1, 0) for i, a in enumerate(pc)])
             + sp.Add(*[(deg_q - i) * _abs_terms(a) * r ** max(deg_q - i - 1, 0) for i, a in enumerate(qc)])
             + th * sp.Add(*[_abs_terms(a) * r ** (deg_q - i) for i, a in enumerate(qc)]))
    blocks.append(function(
        "reaction_denominator_slope_bound", ["r", *_ARGS], [sp.expand(slope)],
        "L ≥ |d D(jω)/dω| for every ω in [0, r]: Σ k|p_k| r^{k−1} + Σ k|q_k| r^{k−1} "
        "+ θ_r Σ |q_k| r^k.", single=True,
    ))
    blocks.append("#: How many of :func:`reaction_denominator_coefficients` belong to P(s).\n"
                  f"REACTION_DENOMINATOR_SPLIT = {len(pc)}\n")
    blocks.append(function(
        "reaction_denominator_coefficients", _ARGS, [*pc, *qc],
        f"Coefficients of D = P + e^(−θ_r s)Q, highest power first: {len(pc)} of P, then "
        f"{len(qc)} of Q.",
    ))
    psi = R.psi_reaction()
    blocks.append(function(
        "psi_reaction", _ARGS, list(psi[:3]),
        "(Ψ1, Ψ2, Ψ3) with the reaction delay: the ω⁴, ω², ω⁰ coefficients of g_θ (eqs 12-14).",
    ))
    for kind in R.APPROXIMATIONS:
        blocks.append(function(
            f"reaction_{kind}_hurwitz", _ARGS, R.approximate_hurwitz(kind),
            f"Hurwitz determinants of D with e^(−θ_r s) replaced by {kind} (each > 0): "
            "the Taylor route's stability test, not a certificate.",
        ))
    return blocks
