r"""The reaction (actuation) delay θ_r: Γ(s), the margin g_θ(ω) and Ψ with θ_r, derived.

Issue 25's model: the follower applies its command θ_r ≥ 0 seconds late (sensor filtering,
the controller's cycle, the powertrain; for people, reaction time),

.. math::
    τ \dot a_i = u_i(t − θ_r) − a_i,\qquad
    u_i = k_x Δp + k_v Δv + k_a a_{i−1}(t − δ),

so the whole law is delayed and the delay reaches Γ's *denominator*:

.. math::
    Γ(s) = \frac{e^{−θ_r s}(k_x + k_v s + k_a s^2 e^{−δs})}
                {τs^3 + s^2 + e^{−θ_r s}((k_v + T^*k_x)s + k_x)}
         = \frac{N(s)}{P(s) + e^{−θ_r s} Q(s)} .

Nothing here is typed in: :func:`gamma_reaction` closes the loop of the state-space model of
:func:`stringstab.derive.symbolic.vehicle_model` with the command delayed by e^{−θ_r s};
:func:`denominator_parts` splits the quasi-polynomial D = P + e^{−θ_r s}Q;
:func:`margin_reaction` is g_θ(ω) = (|D(jω)|² − |N(jω)|²)/ω² with both delays exact;
:func:`psi_reaction` its low-frequency coefficients (Ψ1, Ψ2, Ψ3 with θ_r, for the record);
:func:`approximate_denominators` and :func:`approximate_hurwitz` what the Taylor route
(e^{−θ_r s} ≈ 1 − θ_r s, or Padé(1,1)) would make of internal stability: a cubic or quartic
Hurwitz test, which is *not* a certificate (the quasi-polynomial has infinitely many roots).
At θ_r = 0 every expression reduces to the one of :mod:`stringstab.derive.symbolic`
(``tests/derive/test_reaction_derive.py``).

The symbol θ_r is ``reaction_delay`` (θ alone is the sampled certificate's normalised frequency
ωH; docs/conventions.md).

References
----------
IDL paper, eqs 3-11 (the model, θ_r = 0); issue 25 (the delayed law).
G. Stépán, *Retarded Dynamical Systems: Stability and Characteristic Functions*, Longman 1989
(the root count of a retarded quasi-polynomial, used by :mod:`stringstab.certify.quasipolynomial`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import sympy as sp

from . import symbolic as S

__all__ = [
    "APPROXIMATIONS",
    "ReactionTransferFunction",
    "approximate_denominators",
    "approximate_hurwitz",
    "at_jomega",
    "denominator_parts",
    "derive_reaction",
    "gamma_reaction",
    "margin_reaction",
    "margin_reaction_hand",
    "psi_reaction",
    "reaction_delay",
]

#: θ_r, the delay on the whole command (s, ≥ 0); ``reaction_delay`` in code, CLI and files.
reaction_delay = sp.Symbol("reaction_delay", nonnegative=True)

#: Placeholders for e^{−θ_r s} and e^{−δs} during the rational algebra.
_ER, _ED = sp.symbols("E_reaction E_delay")

#: The approximations of e^{−θ_r s} the Taylor route would use in the denominator.
APPROXIMATIONS: dict[str, str] = {
    "taylor1": "e^{-θ_r s} ≈ 1 − θ_r s (first-order Taylor): a cubic",
    "pade11": "e^{-θ_r s} ≈ (1 − θ_r s/2)/(1 + θ_r s/2) (Padé(1,1)): a quartic",
}


@dataclass(frozen=True)
class ReactionTransferFunction:
    """Γ(s) = N(s)/D(s) with the reaction delay, D(s) = P(s) + e^{−θ_r s} Q(s).

    Attributes
    ----------
    numerator : sympy.Expr
        N(s), with ``exp(-reaction_delay*s)`` and ``exp(-delta*s)``.
    denominator : sympy.Expr
        D(s), with ``exp(-reaction_delay*s)``, normalised so that P's s³ coefficient is τ.
    P, Q : sympy.Expr
        The undelayed part of D and the coefficient of e^{−θ_r s} (polynomials in s).
    """

    numerator: sp.Expr
    denominator: sp.Expr
    P: sp.Expr
    Q: sp.Expr

    @property
    def expr(self) -> sp.Expr:
        """Γ(s) as one expression."""
        return self.numerator / self.denominator


@cache
def gamma_reaction() -> ReactionTransferFunction:
    """Γ(s) with the reaction delay, from the state-space model (issue 25).

    The delayed command enters the lag equation as M2 u(t − θ_r), i.e. M2 e^{−θ_r s} u in the
    Laplace domain, so the closed loop is ẋ = (M1 + M2 e^{−θ_r s} K_x) x
    + (M3 + M2 e^{−θ_r s} k_a e^{−δs}) a_{i−1} with K_x = [k_x, k_v, 0], and
    Γ(s) = C (sI − A_cl)^{−1} B, C = [0, 0, 1] (as :func:`stringstab.derive.symbolic.gamma`
    with the extra factor).

    Returns
    -------
    ReactionTransferFunction

    Raises
    ------
    AssertionError
        If the denominator is not affine in e^{−θ_r s} (a retarded quasi-polynomial
        P + e^{−θ_r s}Q), which the certificate relies on.

    Examples
    --------
    >>> g = gamma_reaction()
    >>> g.P, sp.collect(g.Q, S.s)
    (s**3*tau + s**2, k_x + s*(headway*k_x + k_v))
    """
    m = S.vehicle_model()
    s = S.s
    A_cl = m.M1 + m.M2 * _ER * sp.Matrix([[S.k_x, S.k_v, 0]])
    B = m.M3 + m.M2 * _ER * S.k_a * _ED
    C = sp.Matrix([[0, 0, 1]])
    sI_A = s * sp.eye(3) - A_cl
    det = sp.expand(sI_A.det())
    num = sp.expand((C * sI_A.adjugate() * B)[0, 0])
    # normalise as symbolic.gamma does: P's s^3 coefficient is tau
    scale = S.tau / sp.Poly(det.coeff(_ER, 0), s).LC()
    num = sp.expand(sp.simplify(num * scale))
    den = sp.expand(sp.simplify(det * scale))
    P, Q = sp.expand(den.coeff(_ER, 0)), sp.expand(den.coeff(_ER, 1))
    if sp.expand(den - P - _ER * Q) != 0 or P.has(_ER) or Q.has(_ER):  # pragma: no cover
        raise AssertionError(f"D(s) is not affine in exp(-reaction_delay*s): {den}")
    exps = {_ER: sp.exp(-reaction_delay * s), _ED: sp.exp(-S.delta * s)}
    return ReactionTransferFunction(num.subs(exps), den.subs(exps), P, Q)


def denominator_parts() -> tuple[sp.Expr, sp.Expr]:
    """(P(s), Q(s)) with D(s) = P(s) + e^{−θ_r s} Q(s): τs³ + s² and (k_v + T*k_x)s + k_x.

    Returns
    -------
    P, Q : sympy.Expr
        Polynomials in s; deg P = 3 > deg Q = 1, so D is *retarded* (finitely many roots in
        any right half plane Re s ≥ −ε).

    Examples
    --------
    >>> P, Q = denominator_parts()
    >>> sp.degree(P, S.s), sp.degree(Q, S.s)
    (3, 1)
    """
    g = gamma_reaction()
    return g.P, g.Q


def at_jomega(expr: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """Re and Im of an expression in s, e^{−θ_r s} and e^{−δs} at s = jω (delays exact).

    Parameters
    ----------
    expr : sympy.Expr
        An expression in ``s``, ``exp(-reaction_delay*s)`` and ``exp(-delta*s)``.

    Returns
    -------
    re, im : sympy.Expr
        Its real and imaginary parts at s = jω, expanded, with cos and sin of δω, θ_rω.
    """
    w = S.omega
    e = expr.subs({sp.exp(-reaction_delay * S.s): sp.cos(reaction_delay * w)
                   - sp.I * sp.sin(reaction_delay * w),
                   sp.exp(-S.delta * S.s): sp.cos(S.delta * w) - sp.I * sp.sin(S.delta * w)})
    re, im = sp.expand(e.subs(S.s, sp.I * w)).as_real_imag()
    return sp.expand(re), sp.expand(im)


@cache
def margin_reaction() -> sp.Expr:
    """g_θ(ω) = (|D(jω)|² − |N(jω)|²)/ω² with both delays exact, expanded.

    |Γ(jω)| ≤ 1 at ω > 0 iff g_θ(ω) ≥ 0 (|e^{−jθ_rω}| = 1 leaves |N| as at θ_r = 0; the
    delay moves into |D|², as cos θ_rω and sin θ_rω terms).

    Returns
    -------
    sympy.Expr
        g_θ in ω, the gains, τ, δ, T* and θ_r (``reaction_delay``).

    Examples
    --------
    >>> sp.expand(margin_reaction() - margin_reaction_hand())
    0
    """
    g = gamma_reaction()
    nr, ni = at_jomega(g.numerator)
    dr, di = at_jomega(g.denominator)
    F = sp.expand(dr**2 + di**2 - nr**2 - ni**2)
    w = S.omega
    for d in (reaction_delay, S.delta):  # sin² + cos² = 1
        F = sp.expand(F.subs(sp.sin(d * w) ** 2, 1 - sp.cos(d * w) ** 2))
    return sp.expand(F / w**2)


def margin_reaction_hand() -> sp.Expr:
    """The hand derivation of g_θ given in issue 25's brief, for the cross-check only.

    With c = k_v + T*k_x, g_θ(ω) = τ²ω⁴ + (1 − k_a²)ω² + c² − k_v²
    − 2(k_x + τcω²) cos θ_rω − 2(c − τk_x)ω sin θ_rω + 2k_xk_a cos δω − 2k_vk_a ω sin δω.

    Returns
    -------
    sympy.Expr
        The hand formula (never used by the toolkit: :func:`margin_reaction` is derived).
    """
    w, th = S.omega, reaction_delay
    c = S.k_v + S.headway * S.k_x
    return sp.expand(
        S.tau**2 * w**4 + (1 - S.k_a**2) * w**2 + c**2 - S.k_v**2
        - 2 * (S.k_x + S.tau * c * w**2) * sp.cos(th * w) - 2 * (c - S.tau * S.k_x) * w * sp.sin(th * w)
        + 2 * S.k_x * S.k_a * sp.cos(S.delta * w) - 2 * S.k_v * S.k_a * w * sp.sin(S.delta * w))


@cache
def psi_reaction() -> tuple[sp.Expr, sp.Expr, sp.Expr, sp.Expr]:
    """Ψ1, Ψ2, Ψ3 and Λ with θ_r: the ω⁴, ω², ω⁰ coefficients of g_θ's series (eqs 12-15).

    As :func:`stringstab.derive.symbolic.derived_psi` (the ω⁶, ω⁴, ω² coefficients of
    F = ω² g), with both delays expanded exactly.  Ψ3 does not depend on θ_r (g_θ(0) = g(0));
    Ψ2 gains k_xθ_r² − 2(c − τk_x)θ_r; Ψ1 gains terms up to θ_r⁴.  For the record and the
    Taylor columns of the certificate; never a verdict.

    Returns
    -------
    tuple of sympy.Expr
        (Ψ1, Ψ2, Ψ3, Λ = Ψ2² − 4Ψ1Ψ3).

    Examples
    --------
    >>> p1, p2, p3, _ = psi_reaction()
    >>> d1, d2, d3, _ = S.derived_psi()
    >>> sp.factor(p2 - d2), sp.expand(p3 - d3)
    (-reaction_delay*(2*headway*k_x + 2*k_v - k_x*reaction_delay - 2*k_x*tau), 0)
    """
    ser = sp.expand(sp.series(margin_reaction(), S.omega, 0, 5).removeO())
    poly = sp.Poly(ser, S.omega)
    psi3, psi2, psi1 = (sp.expand(poly.coeff_monomial(S.omega**k)) for k in (0, 2, 4))
    return psi1, psi2, psi3, sp.expand(psi2**2 - 4 * psi1 * psi3)


@cache
def approximate_denominators() -> dict[str, sp.Expr]:
    """D(s) with e^{−θ_r s} replaced as the Taylor route would (:data:`APPROXIMATIONS`).

    Returns
    -------
    dict of str to sympy.Expr
        ``taylor1``: τs³ + s² + (1 − θ_r s)Q(s), a cubic; ``pade11``: (τs³ + s²)(1 + θ_r s/2)
        + (1 − θ_r s/2)Q(s), a quartic (D times the Padé denominator).

    Examples
    --------
    >>> sp.Poly(approximate_denominators()["pade11"], S.s).degree()
    4
    """
    P, Q = denominator_parts()
    th, s = reaction_delay, S.s
    return {"taylor1": sp.expand(P + (1 - th * s) * Q),
            "pade11": sp.expand(P * (1 + th * s / 2) + (1 - th * s / 2) * Q)}


@cache
def approximate_hurwitz(kind: str) -> list[sp.Expr]:
    """The Hurwitz determinants of an approximated denominator (each must be > 0).

    Leading principal minors of the Hurwitz matrix (:func:`stringstab.derive.symbolic.routh_hurwitz`)
    of :func:`approximate_denominators` ``[kind]``; with a positive leading coefficient (τ, or
    τθ_r/2 for θ_r > 0) the polynomial is Hurwitz iff all are > 0.  This is what a Taylor or
    Padé(1,1) treatment of θ_r concludes about internal stability: not a certificate
    (``docs/theory.md`` shows triples where it is wrong).

    Parameters
    ----------
    kind : {"taylor1", "pade11"}
        The approximation.

    Returns
    -------
    list of sympy.Expr
        Δ_1, …, Δ_n, factored.

    Examples
    --------
    >>> [sp.factor(c) for c in approximate_hurwitz("taylor1")][:1]
    [-headway*k_x*reaction_delay - k_v*reaction_delay + 1]
    """
    return S.routh_hurwitz(sp.Poly(approximate_denominators()[kind], S.s))


def derive_reaction(substitute: dict[sp.Symbol, sp.Expr] | None = None) -> dict[str, object]:
    """Every θ_r expression under the keys of ``stringstab derive --reaction-delay``.

    Parameters
    ----------
    substitute : dict, optional
        Symbol → value substitutions applied to every expression (``reaction_delay`` among
        them).

    Returns
    -------
    dict of str to object
        ``gamma``, ``gamma_numerator``, ``gamma_denominator``, ``denominator_P``,
        ``denominator_Q``, ``margin`` (g_θ), ``psi1``, ``psi2``, ``psi3``, ``lambda``,
        ``taylor1_hurwitz`` and ``pade11_hurwitz`` (lists: what the Taylor route would test).
    """
    sub = substitute or {}

    def f(e: sp.Expr) -> sp.Expr:
        return sp.expand(e.subs(sub)) if sub else e

    g = gamma_reaction()
    psi1, psi2, psi3, lam = psi_reaction()
    # kept as e^{-θ_r s}·(n0 + n1 e^{-δs}) and P + e^{-θ_r s}·Q (expanding would split the
    # exponentials into powers of exp(s))
    e_r = sp.exp(-f(reaction_delay) * S.s)
    n0, n1 = S.delay_parts(sp.expand(g.numerator / sp.exp(-reaction_delay * S.s)))
    num = sp.Mul(e_r, sp.collect(f(n0), S.s) + f(n1) * sp.exp(-f(S.delta) * S.s), evaluate=False)
    den = sp.Add(f(g.P), sp.Mul(e_r, sp.collect(f(g.Q), S.s), evaluate=False), evaluate=False)
    approx = {k: [f(c) for c in approximate_hurwitz(k)] for k in APPROXIMATIONS}
    return {
        "gamma": num / den,
        "gamma_numerator": num,
        "gamma_denominator": den,
        "denominator_P": f(g.P),
        "denominator_Q": sp.collect(f(g.Q), S.s),
        "margin": f(margin_reaction()),
        "psi1": f(psi1),
        "psi2": f(psi2),
        "psi3": f(psi3),
        "lambda": f(lam),
        "taylor1_hurwitz": [c for c in approx["taylor1"] if not (c.is_number and c > 0)],
        "pade11_hurwitz": [c for c in approx["pade11"] if not (c.is_number and c > 0)],
    }
