"""Generate :mod:`stringstab.derive.generated`, the numeric code of every derived formula.

The numeric library never imports SymPy: each formula it evaluates (the margin g(ω)
and its derivatives, Ψ1-Ψ3, the Hurwitz conditions, the parts of Γ(jω)) is derived
once by :mod:`stringstab.derive.symbolic` (and, for the printed Ψ, :mod:`stringstab.derive.printed`),
printed as plain Python arithmetic by this module, and committed as
``stringstab/derive/generated.py``.  Rerun after changing the model::

    python -m stringstab.derive.codegen            # rewrite stringstab/derive/generated.py
    python -m stringstab.derive.codegen --check    # exit 1 if the committed file is stale

The generated functions use only ``+ - * /``, ``abs`` and the ``cos``/``sin`` they
are handed (NumPy's by default), so the *same* code evaluates NumPy arrays
(vectorised), Python floats (pass ``math.cos, math.sin``: the scalar form of the
inner loops) and CasADi symbols (pass ``casadi.cos, casadi.sin``: the projection
NLP).  ``tests/derive/test_margin.py`` checks that the committed file equals a fresh
generation and that every generated form agrees with the SymPy derivation.

References
----------
IDL paper, eqs 11-15 (derived forms, :mod:`stringstab.derive.symbolic`).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import sympy as sp
from sympy.printing.precedence import PRECEDENCE
from sympy.printing.str import StrPrinter

from . import symbolic as S
from .printed import printed_psi

__all__ = ["MARGIN_BASIS", "TARGET", "generate", "main", "margin_basis", "margin_separable"]

#: The committed file this module writes.
TARGET = Path(__file__).with_name("generated.py")

#: The terms of g(ω) = (|D(jω)|² − |N(jω)|²)/ω², as (name, sign, trigonometric factor, power
#: of ω): g = τ²ω⁴ + aω² + b + c_x cos(δω) − c_v ω sin(δω).  :func:`margin_basis` checks the
#: derivation has exactly these terms; the tail and curvature bounds of
#: :mod:`stringstab.certify.margin` rely on it.
MARGIN_BASIS: tuple[tuple[str, int, str, int], ...] = (
    ("t2", 1, "1", 4),
    ("a", 1, "1", 2),
    ("b", 1, "1", 0),
    ("cx", 1, "cos", 0),
    ("cv", -1, "sin", 1),
)

_HEADER = '''\
"""Numeric code generated from the symbolic derivation: DO NOT EDIT.

Written by ``python -m stringstab.derive.codegen`` from :mod:`stringstab.derive.symbolic` (and the
printed Ψ of :mod:`stringstab.derive.printed`); ``tests/derive/test_margin.py`` checks that this file
equals a fresh generation and agrees with SymPy.  Only arithmetic, ``abs`` and the
``cos``/``sin`` passed in are used, so every function evaluates NumPy arrays (the
default), Python floats (``cos=math.cos, sin=math.sin``) and CasADi symbols
(``cos=casadi.cos, sin=casadi.sin``) alike.  The public interface is
:mod:`stringstab.certify.margin` and :mod:`stringstab.certify.criteria`.
"""

from __future__ import annotations

from typing import Any

from numpy import cos as _np_cos
from numpy import sin as _np_sin
'''


class _Printer(StrPrinter):
    """SymPy's ``str`` printer with small integer powers as products and ``abs``."""

    def _print_Pow(self, expr: sp.Pow, rational: bool = False) -> str:
        b, e = expr.as_base_exp()
        if e.is_Integer and 2 <= int(e) <= 4:
            base = self.parenthesize(b, PRECEDENCE["Mul"], strict=False)
            return "(" + "*".join([base] * int(e)) + ")"
        if e.is_Integer and -4 <= int(e) <= -1:
            return "(1/" + self._print(sp.Pow(b, -e, evaluate=False)) + ")"
        return str(super()._print_Pow(expr, rational))

    def _print_Abs(self, expr: sp.Abs) -> str:
        return f"abs({self._print(expr.args[0])})"

    def _print_Rational(self, expr: sp.Rational) -> str:
        return f"({expr.p}/{expr.q})" if expr.q != 1 else str(expr.p)

    def _print_Half(self, expr: sp.Rational) -> str:
        return "(1/2)"


_P = _Printer({"order": "none"})


def _code(e: sp.Expr) -> str:
    return str(_P.doprint(e))


def _function(name: str, args: Sequence[str], outputs: Sequence[sp.Expr], doc: str,
              *, trig: bool = False, single: bool = False,
              pre: Sequence[tuple[sp.Symbol, sp.Expr]] = ()) -> str:
    """Python source of ``def name(args): <common subexpressions>; return outputs``.

    ``pre`` are named intermediate values ``(symbol, expression)`` the outputs refer to
    (computed first, e.g. the ω-independent coefficients of g and their K-derivatives).
    """
    sig = ", ".join(f"{a}: Any" for a in args)
    if trig:
        sig += ", cos: Any = _np_cos, sin: Any = _np_sin"
    ret = "Any" if single else "tuple[Any, ...]"
    lines = [f"def {name}({sig}) -> {ret}:", f'    """{doc}"""']
    exprs = [e for _, e in pre] + list(outputs)
    repl, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("_x"), order="none")
    repl, reduced = _reuse_squares(repl, reduced)
    # subexpressions of the ``pre`` values first, then those values, then the rest
    named = {sym for sym, _ in pre}
    late: set[sp.Symbol] = set()
    first, second = [], []
    for sym, sub in repl:
        if sub.free_symbols & (named | late):
            late.add(sym)
            second.append((sym, sub))
        else:
            first.append((sym, sub))
    for sym, sub in first:
        lines.append(f"    {sym} = {_code(sub)}")
    alias: dict[sp.Symbol, sp.Expr] = {}  # a named value that is just another symbol
    for (sym, _), r in zip(pre, reduced[:len(pre)]):
        if r.is_Symbol or r.is_number:
            alias[sym] = r
        else:
            lines.append(f"    {sym} = {_code(r)}")
    for sym, sub in second:
        lines.append(f"    {sym} = {_code(sub.xreplace(alias))}")
    reduced = [e.xreplace(alias) for e in reduced[len(pre):]]
    body = [_code(e) for e in reduced]
    if single:
        lines.append(f"    return {body[0]}")
    else:
        lines.append("    return (")
        lines.extend(f"        {b}," for b in body)
        lines.append("    )")
    return "\n".join(lines) + "\n"


def _reuse_squares(repl: list[tuple[sp.Symbol, sp.Expr]], reduced: list[sp.Expr]
                   ) -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[sp.Expr]]:
    """Write b³ and b⁴ through an earlier common subexpression b² (one product, not three)."""
    squares: dict[sp.Expr, sp.Symbol] = {}

    def rewrite(e: sp.Expr) -> sp.Expr:
        if not squares:
            return e
        subs = {}
        for p in e.atoms(sp.Pow):
            b, n = p.as_base_exp()
            if b in squares and n in (2, 3, 4) and not (p == e and n == 2):
                q = squares[b]
                subs[p] = {2: q, 3: sp.Mul(q, b, evaluate=False), 4: sp.Mul(q, q, evaluate=False)}[n]
        return e.xreplace(subs) if subs else e

    out: list[tuple[sp.Symbol, sp.Expr]] = []
    # a base raised to the 3rd or 4th power with no square among the subexpressions: add one
    have = {sub.as_base_exp()[0] for _, sub in repl if isinstance(sub, sp.Pow) and sub.exp == 2}
    need: list[sp.Expr] = []
    for e in [sub for _, sub in repl] + list(reduced):
        for p in sorted(e.atoms(sp.Pow), key=str):
            b, n = p.as_base_exp()
            if n in (3, 4) and b not in have and b not in need and b.is_Symbol:
                need.append(b)
    for i, b in enumerate(need):
        q = sp.Symbol(f"_q{i}")
        out.append((q, b**2))
        squares[b] = q
    for sym, sub in repl:
        sub = rewrite(sub)
        out.append((sym, sub))
        b, n = sub.as_base_exp() if isinstance(sub, sp.Pow) else (None, None)
        if n == 2 and b is not None:
            squares[b] = sym
    return out, [rewrite(e) for e in reduced]


# --------------------------------------------------------------------------- derivations
def _margin_expr() -> sp.Expr:
    """g(ω) = (|D(jω)|² − |N(jω)|²)/ω², expanded (IDL eq 10 with the exact delay)."""
    return sp.expand(S.margin_exact() / S.omega**2)


def margin_basis() -> dict[str, sp.Expr]:
    """The coefficient of each term of :data:`MARGIN_BASIS` in the derived g(ω).

    Returns
    -------
    dict of str to sympy.Expr
        Each basis term's name mapped to its coefficient in g(ω).

    Raises
    ------
    AssertionError
        When the derived g has other terms (a changed model needs a new basis and new
        bounds in :mod:`stringstab.certify.margin`).
    """
    w, d = S.omega, S.delta
    trig = {"1": sp.Integer(1), "cos": sp.cos(d * w), "sin": sp.sin(d * w)}
    parts = sp.collect(_margin_expr(), [trig["cos"], trig["sin"]], evaluate=False)
    found: dict[tuple[str, int], sp.Expr] = {}
    for tname, factor in trig.items():
        expr = parts.get(factor, 0)
        if expr == 0:
            continue
        for (k,), c in sp.Poly(expr, w).terms():
            found[(tname, k)] = sp.expand(c)
    expected = {(t, k) for _, _, t, k in MARGIN_BASIS}
    if set(found) != expected:  # pragma: no cover - only when the model changes
        raise AssertionError(f"the derived margin has terms {sorted(found)}; expected {sorted(expected)}")
    return {name: sp.expand(sign * found[(t, k)]) for name, sign, t, k in MARGIN_BASIS}


def margin_separable() -> dict[str, sp.Expr]:
    """g(ω) split as (τω² − c)² + h2 ω² + h0 + c_x cos(δω) − c_v ω sin(δω).

    The robust certificate (:mod:`stringstab.certify.robust`) minimises g over a box of τ, δ, T*
    in closed form because only the square depends on τ and T* (through τ and
    c = k_v + T*k_x) and only the trigonometric terms on δ.  Everything is derived from
    :func:`margin_basis`: t2 = τ², c = −½ ∂a/∂τ (a is affine in τ), h2 = a + 2τc,
    h0 = b − c².

    Returns
    -------
    dict of str to sympy.Expr
        ``t2``, ``c``, ``h2``, ``h0``, ``c_x``, ``c_v``: the pieces of the split.

    Raises
    ------
    AssertionError
        When the split does not hold (h2, h0, c_x, c_v depend on τ, δ or T*).
    """
    basis = margin_basis()
    tau, headway, delta = S.tau, S.headway, S.delta
    a, b = basis["a"], basis["b"]
    c = sp.expand(-sp.diff(a, tau) / 2)
    out = {"c": c, "h2": sp.expand(a + 2 * tau * c), "h0": sp.expand(b - c**2),
           "cx": basis["cx"], "cv": basis["cv"]}
    ok = (sp.expand(basis["t2"] - tau**2) == 0 and sp.diff(a, tau, 2) == 0
          and not (out["c"].free_symbols & {tau, delta})
          and all(not (out[k].free_symbols & {tau, headway, delta}) for k in ("h2", "h0", "cx", "cv")))
    if not ok:  # pragma: no cover - only when the model changes
        raise AssertionError(f"g does not split as (τω² − c)² + h(ω) + trig terms: {out}")
    return out


def _abs_terms(e: sp.Expr) -> sp.Expr:
    """Σ |term| over the terms of the expanded ``e`` (a round-off scale of ``e``)."""
    return sp.Add(*[sp.Abs(t) for t in sp.Add.make_args(sp.expand(e))])


def _basis_symbols() -> dict[str, sp.Symbol]:
    return {name: sp.Symbol(name, positive=True) if name == "t2" else sp.Symbol(name, real=True)
            for name, *_ in MARGIN_BASIS}


def _basis_sum(c: dict[str, sp.Symbol], w: sp.Symbol, cos: Any, sin: Any) -> sp.Expr:
    trig = {"1": 1, "cos": cos(S.delta * w), "sin": sin(S.delta * w)}
    return sp.Add(*[sign * c[n] * w**k * trig[t] for n, sign, t, k in MARGIN_BASIS])


def _curvature(c: dict[str, sp.Symbol], r: sp.Symbol) -> sp.Expr:
    """A bound on |g''(ω)| for 0 ≤ ω ≤ r, term by term from :data:`MARGIN_BASIS`.

    |d²/dω² ω^k f(δω)| ≤ k(k−1) r^{k−2} + 2kδ r^{k−1} + δ² r^k for f = cos, sin (|f|,
    |f'|, |f''| ≤ 1), and k(k−1) r^{k−2} without a trigonometric factor.
    """
    d = S.delta
    out = sp.Integer(0)
    for n, _sign, t, k in MARGIN_BASIS:
        bound = k * (k - 1) * r ** max(k - 2, 0) if k >= 2 else sp.Integer(0)
        if t != "1":
            bound += 2 * k * d * r ** max(k - 1, 0) + d**2 * r**k
        out += sp.Abs(c[n]) * bound
    return sp.expand(out)


def _source() -> str:
    G, P = S.GAINS, S.PARAMS
    w = S.omega
    gain_args = [str(x) for x in (*G, *P)]
    blocks: list[str] = []

    # ---- the margin g(ω) in the basis of MARGIN_BASIS
    basis = margin_basis()
    names = [n for n, *_ in MARGIN_BASIS]
    blocks.append(
        f"#: Names of the coefficients returned by :func:`margin_coefficients`.\n"
        f"MARGIN_COEFFICIENTS = {tuple(names)!r}\n"
    )
    blocks.append(_function(
        "margin_coefficients", gain_args, [basis[n] for n in names],
        "(t2, a, b, cx, cv) with g(ω) = t2 ω⁴ + a ω² + b + cx cos(δω) − cv ω sin(δω).",
    ))
    blocks.append(_function(
        "margin_coefficient_scales", gain_args, [_abs_terms(basis[n]) for n in names],
        "Σ |term| of each coefficient of :func:`margin_coefficients` (round-off scales).",
    ))
    c = _basis_symbols()
    sc = {n: sp.Symbol(f"s_{n}", nonnegative=True) for n in names}
    g_basis = _basis_sum(c, w, sp.cos, sp.sin)
    scale = sp.Add(*[sc[n] * w**k for n, _s, _t, k in MARGIN_BASIS])
    blocks.append(_function(
        "margin_from_coefficients", ["omega", *names, "delta"], [g_basis],
        "g(ω) from the coefficients of :func:`margin_coefficients`.", trig=True, single=True,
    ))
    blocks.append(_function(
        "margin_and_scale", ["omega", *names, *(f"s_{n}" for n in names), "delta"],
        [g_basis, scale],
        "(g(ω), Σ |term of g(ω)| bound) from the coefficients and their scales.", trig=True,
    ))
    split = margin_separable()
    blocks.append(_function(
        "margin_separable", gain_args, list(split.values()),
        "(c, h2, h0, cx, cv) with g(ω) = (τω² − c)² + h2 ω² + h0 + cx cos(δω) − cv ω sin(δω).",
    ))
    blocks.append(_function(
        "margin_separable_scales", gain_args, [_abs_terms(e) for e in split.values()],
        "Σ |term| of each value of :func:`margin_separable` (round-off scales).",
    ))
    r = sp.Symbol("r", nonnegative=True)
    blocks.append(_function(
        "margin_curvature_bound", ["r", *names, "delta"], [_curvature(c, r)],
        "M ≥ |g''(ω)| for every ω in [0, r], from the coefficients.", single=True,
    ))

    # ---- g(ω; K) and its derivatives in K and ω, written as Σ c_i(K) B_i(ω) over the basis
    # (coefficients and their K-derivatives do not depend on ω: computed once per call)
    B = {n: sign * w**k * trig for n, sign, k, trig in
         ((n, sign, k, {"1": 1, "cos": sp.cos(S.delta * w), "sin": sp.sin(S.delta * w)}[t])
          for n, sign, t, k in MARGIN_BASIS)}

    pre: dict[sp.Expr, sp.Symbol] = {}  # ω-independent coefficient values, named once

    def named(e: sp.Expr) -> sp.Expr:
        if e.is_number or e.is_Symbol:
            return e
        if e not in pre:
            pre[e] = sp.Symbol(f"_c{len(pre)}", real=True)
        return pre[e]

    def comb(coef: dict[str, sp.Expr], basis: dict[str, sp.Expr]) -> sp.Expr:
        return sp.Add(*[named(coef[n]) * basis[n] for n in names
                        if coef[n] != 0 and basis[n] != 0])

    def d_coef(*ks: sp.Symbol) -> dict[str, sp.Expr]:
        return {n: sp.expand(sp.diff(basis[n], *ks)) for n in names}

    def function(fname: str, outs: list[sp.Expr], doc: str, single: bool = False) -> str:
        used = set().union(*(o.free_symbols for o in outs))
        pairs = [(sym, e) for e, sym in pre.items() if sym in used]
        return _function(fname, ["omega", *gain_args], outs, doc, trig=True, single=single,
                         pre=pairs)

    def d_basis(order: int) -> dict[str, sp.Expr]:
        return {n: sp.expand(sp.diff(B[n], w, order)) for n in names}

    g = comb(basis, B)
    dK = [comb(d_coef(k), B) for k in G]
    gw = comb(basis, d_basis(1))
    gwK = [comb(d_coef(k), d_basis(1)) for k in G]
    gww = comb(basis, d_basis(2))
    hess = [comb(d_coef(G[i], G[j]), B) for i in range(3) for j in range(i, 3)]
    blocks.append(function(
        "margin_g", [g], "g(ω) = (|D(jω)|² − |N(jω)|²)/ω² (IDL eq 10, exact delay).", single=True))
    blocks.append(function("margin_gradient", [g, *dK], "(g, ∂g/∂k_x, ∂g/∂k_v, ∂g/∂k_a) at ω."))
    blocks.append(function(
        "margin_newton", [g, *dK, gw, *gwK, gww, *hess],
        "(g, ∇_K g (3), ∂g/∂ω, ∇_K ∂g/∂ω (3), ∂²g/∂ω², ∇²_KK g (xx, xv, xa, vv, va, aa)) at ω."))

    # ---- Ψ1, Ψ2, Ψ3 (IDL eqs 12-14), derived and printed
    derived = S.derived_psi(None)
    printed = printed_psi()
    for source, exprs in (("derived", derived), ("printed", printed)):
        blocks.append(_function(
            f"psi_{source}", gain_args, list(exprs[:3]),
            f"(Ψ1, Ψ2, Ψ3), {source} forms (IDL eqs 12-14).",
        ))
    for source, exprs in (("derived", derived), ("printed", printed)):
        for g0 in G:
            others = [str(x) for x in G if x != g0]
            outs: list[sp.Expr] = []
            sizes = []
            for e in exprs:  # Ψ1, Ψ2, Ψ3, Λ
                coeffs = sp.Poly(sp.expand(e), g0).all_coeffs()
                sizes.append(len(coeffs))
                outs.extend(coeffs)
            fn = _function(
                f"_psi_poly_{source}_{g0}", [*others, *(str(p) for p in P)], outs,
                f"Coefficients (highest power first) of Ψ1, Ψ2, Ψ3, Λ as polynomials in {g0}, "
                f"{source} forms, flat.",
            )
            blocks.append(fn)
            blocks.append(f"_PSI_POLY_SIZES_{source.upper()}_{g0.name.upper()} = {tuple(sizes)!r}\n")
    blocks.append(
        "\ndef psi_polynomials(source: str, gain: str, **values: Any) -> tuple[tuple[Any, ...], ...]:\n"
        '    """Ψ1, Ψ2, Ψ3 (IDL eqs 12-14) and Λ as polynomials in ``gain``, '
        "as coefficient tuples.\n"
        "\n"
        "    Parameters\n"
        "    ----------\n"
        "    source : str\n"
        '        ``"derived"`` (from the model) or ``"printed"`` (the paper\'s forms).\n'
        "    gain : str\n"
        '        The polynomial variable: ``"k_x"``, ``"k_v"`` or ``"k_a"``.\n'
        "    **values : Any\n"
        "        The other two gains and ``tau``, ``delta``, ``headway``, by name (numbers or\n"
        "        broadcastable arrays).\n"
        "\n"
        "    Returns\n"
        "    -------\n"
        "    tuple of tuple\n"
        "        Four tuples (Ψ1, Ψ2, Ψ3, Λ), each the coefficients, highest power of\n"
        "        ``gain`` first, evaluated at ``values``.\n"
        '    """\n'
        "    flat = _PSI_POLY[source, gain](**values)\n"
        "    sizes = _PSI_POLY_SIZES[source, gain]\n"
        "    out, i = [], 0\n"
        "    for n in sizes:\n"
        "        out.append(flat[i:i + n])\n"
        "        i += n\n"
        "    return tuple(out)\n"
    )
    table = ", ".join(f"(\"{s}\", \"{g0}\"): _psi_poly_{s}_{g0}" for s in ("derived", "printed")
                      for g0 in G)
    sizes_t = ", ".join(f"(\"{s}\", \"{g0}\"): _PSI_POLY_SIZES_{s.upper()}_{g0.name.upper()}"
                        for s in ("derived", "printed") for g0 in G)
    blocks.append(f"_PSI_POLY: dict[tuple[str, str], Any] = {{{table}}}\n"
                  f"_PSI_POLY_SIZES: dict[tuple[str, str], tuple[int, ...]] = {{{sizes_t}}}\n")

    # ---- Hurwitz conditions of Γ's denominator (linear in the gains)
    conds = S.hurwitz_conditions()
    collected = []
    scales = []
    grads = []
    for cnd in conds:
        lin = [sp.diff(cnd, k) for k in G]
        if any(sp.diff(x, k) != 0 for x in lin for k in G):  # pragma: no cover
            raise AssertionError(f"Hurwitz condition {cnd} is not linear in the gains")
        const = sp.expand(cnd - sum(a * k for a, k in zip(lin, G)))
        collected.append(sp.Add(*[sp.factor(a) * k for a, k in zip(lin, G)], const))
        scales.append(sp.Add(*[sp.Abs(sp.factor(a)) * sp.Abs(k) for a, k in zip(lin, G)],
                             sp.Abs(const)))
        grads.extend(lin)
    blocks.append(_function(
        "hurwitz_conditions", gain_args, collected,
        "Internal-stability conditions of Γ: each must be > 0 (from symbolic.hurwitz_conditions).",
    ))
    blocks.append(_function(
        "hurwitz_scales", gain_args, scales,
        "Σ |coefficient|·|gain| of each Hurwitz condition (the scale of a relative margin).",
    ))
    blocks.append(_function(
        "hurwitz_gradients", [str(p) for p in P], grads,
        "∇_K of each Hurwitz condition, flat (3 per condition; the conditions are linear in K).",
    ))

    # ---- Γ(jω) = N(jω)/D(jω): real and imaginary parts, and the denominator's coefficients
    gam = S.gamma()
    jw = sp.I * w
    n_jw = sp.expand(gam.numerator.subs(S.s, jw).rewrite(sp.cos))
    d_jw = sp.expand(gam.denominator.subs(S.s, jw))
    n_re, n_im = (sp.expand(x) for x in n_jw.as_real_imag())
    d_re, d_im = (sp.expand(x) for x in d_jw.as_real_imag())
    blocks.append(_function(
        "gamma_parts", ["omega", *gain_args], [n_re, n_im, d_re, d_im],
        "(Re N(jω), Im N(jω), Re D(jω), Im D(jω)) of Γ = N/D (IDL eq 11, derived).", trig=True,
    ))
    blocks.append(_function(
        "denominator_coefficients", gain_args, sp.Poly(gam.denominator, S.s).all_coeffs(),
        "Coefficients of D(s), highest power of s first.",
    ))
    n0, n1 = S.delay_parts(gam.numerator)
    blocks.append(f"#: How many of :func:`numerator_coefficients` belong to the delay-free part n0(s).\n"
                  f"NUMERATOR_SPLIT = {sp.Poly(n0, S.s).degree() + 1}\n")
    blocks.append(_function(
        "numerator_coefficients", gain_args,
        [*sp.Poly(n0, S.s).all_coeffs(), *sp.Poly(n1, S.s).all_coeffs()],
        f"Coefficients of N(s) = n0(s) + n1(s)·e^(−δs), highest power of s first: "
        f"{sp.Poly(n0, S.s).degree() + 1} of n0, then {sp.Poly(n1, S.s).degree() + 1} of n1.",
    ))
    x = sp.Symbol("x", nonnegative=True)
    d_abs2 = sp.expand((d_re**2 + d_im**2).subs(w, sp.sqrt(x)))
    blocks.append(_function(
        "denominator_abs2_coefficients", gain_args, sp.Poly(d_abs2, x).all_coeffs(),
        "Coefficients of |D(jω)|² as a polynomial in x = ω², highest power first.",
    ))
    # ---- the reaction delay θ_r (issue 25): stringstab.derive.codegen_reaction
    from .codegen_reaction import reaction_blocks

    blocks.extend(reaction_blocks(_function))
    # two blank lines between top-level statements (PEP 8)
    return _HEADER + "\n" + "\n\n\n".join(b.strip("\n") for b in blocks) + "\n"


def generate() -> str:
    """The source text of ``stringstab/derive/generated.py`` (LF line endings).

    Returns
    -------
    str
        The module's full source text.
    """
    return _source()


def main(argv: Sequence[str] | None = None) -> int:
    """Write (or with ``--check``, compare) ``stringstab/derive/generated.py``; returns the exit code.

    Parameters
    ----------
    argv : sequence of str, optional
        Command-line arguments (default ``sys.argv[1:]``); ``--check`` compares only.

    Returns
    -------
    int
        0 when written or up to date; 1 with ``--check`` when the committed file is stale.
    """
    ap = argparse.ArgumentParser(prog="python -m stringstab.derive.codegen", description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="exit 1 if the committed file is stale")
    args = ap.parse_args(argv)
    src = generate()
    if args.check:
        same = TARGET.is_file() and TARGET.read_text(encoding="utf-8") == src
        print(f"{TARGET}: {'up to date' if same else 'STALE: run python -m stringstab.derive.codegen'}")
        return 0 if same else 1
    TARGET.write_text(src, encoding="utf-8")
    print(f"wrote {TARGET} ({len(src.splitlines())} lines)")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
