r"""Symbolic derivation of the sampled link with a reaction delay θ_r: H(z) = U_i(z)/U_{i−1}(z).

The loop of docs/sampled.md §10 (issue 25 item 3): every vehicle samples with period H, holds
its command (zero-order hold), has the lag τ ȧ = w − a (IDL eq 7), and the command computed at
step k is applied θ_r = (q + f)H later (q whole steps, 0 ≤ f < 1).  Over [kH, (k + 1)H) the
applied input is u_{k−q−1} for a time fH, then u_{k−q} for (1 − f)H: two held pieces.

Nothing below is typed in from a paper or from the certificate's code.  The derivation is:

1. **Pieces.** Φ(t) = exp(A t) of the augmented model [Δp, Δv, a_i, a_p, u_p, u] of
   :func:`stringstab.derive.sampled_symbolic.sampled_model` (SymPy's matrix exponential) at
   t = fH and t = (1 − f)H; Φ_yy its 4 × 4 block on y = [Δp, Δv, a_i, a_p], Φ_u and Φ_p the
   columns of the held own and predecessor commands.
2. **One step.** y_{k+1} = Φ₂Φ₁ y_k + z^{−q−1}(g_u u + g_p u_p) in the z-domain, with
   g_u = zΦ₂,u + Φ₂,yy Φ₁,u and g_p likewise (f = 0: one piece, g_u = Φ_u(H), z^{−q}).
3. **The delayed sample.** a_{i−1}(kH − δ), δ = (m + ε)H, is the predecessor's acceleration
   s = (1 − ε)H into step k − m − 1:
   c_a a_{p} + c_0 w_0 + c_1 w_1 with, when s ≤ fH (first piece),
   c_a = e^{−s/τ_p}, c_0 = 1 − e^{−s/τ_p}, c_1 = 0, and otherwise, r = s − fH,
   c_a = e^{−s/τ_p}, c_0 = e^{−r/τ_p}(1 − e^{−fH/τ_p}), c_1 = 1 − e^{−r/τ_p}
   (:func:`sample_coefficients`).
4. **Closing the loop** u_i = k_xΔp + k_vΔv + k_a a_{i−1}(kH − δ) with Y = adj(zI − Φ)(·)/det:

   .. math::
       H(z) = \frac{N_0(z) + z^{-(m+1)} N_1(z)}{D(z)},\quad
       D = z^{q+1}\det(zI - Φ) - K\,\mathrm{adj}_{0:2}\,g_u,\quad
       N_0 = K\,\mathrm{adj}_{0:2}\,g_p,\quad
       N_1 = k_a\bigl(c_a\,\mathrm{adj}_3\,g_p + \det(zI - Φ)(c_0 + c_1 z)\bigr),

   K = (k_x, k_v).  D = (z − e^{−H/τ_p}) χ_f(z), χ_f the follower's closed-loop characteristic
   polynomial of degree 3 + L, L = q + [f > 0] (:func:`characteristic_polynomial`).

The chain variable is the command (as in the certificate, :mod:`stringstab.certify.lifting_reaction`):
H(z) maps the predecessor's commands to the follower's.  q and f enter as symbols
(``reaction_steps``, ``reaction_fraction``) and through the pieces' lengths; a derivation at a
given θ_r and H substitutes them (:func:`sampled_reaction_derivation`).

References
----------
E. I. Jury, *Theory and Application of the z-Transform Method*, Wiley (1964) (the modified
z-transform); T. Chen, B. Francis, *Optimal Sampled-Data Control Systems*, Springer (1995),
§3.4 (fractional delays).  IDL paper, eqs 3-9 and eq 4.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from typing import Any

import sympy as sp

from .sampled_symbolic import epsilon, m, sample_time, sampled_model, tau_prev, z
from .symbolic import k_a, k_v, k_x

__all__ = [
    "SAMPLED_REACTION_LABELS",
    "SNAP",
    "SampledReactionTransfer",
    "c_0",
    "c_1",
    "c_a",
    "characteristic_polynomial",
    "held_split",
    "reaction_fraction",
    "reaction_steps",
    "sample_coefficients",
    "sampled_reaction_derivation",
    "sampled_reaction_transfer",
    "transfer_at",
]

#: q, the whole sample times of θ_r = (q + f)H.
reaction_steps = sp.Symbol("reaction_steps", integer=True, nonnegative=True)
#: f, the fractional part of θ_r/H, 0 ≤ f < 1.
reaction_fraction = sp.Symbol("reaction_fraction", nonnegative=True)
#: The coefficients of the delayed sample (step 3): c_a a_p + c_0 w_0 + c_1 w_1.
c_a, c_0, c_1 = sp.symbols("c_a c_0 c_1", real=True)

#: Within this many sample times of a whole number, θ_r/H is that number (as
#: :func:`stringstab.certify.zoh.split_delay` rounds).
SNAP = sp.Rational(1, 10**9)


def held_split(reaction_delay: float, sample_time_: float) -> tuple[int, sp.Rational]:
    """(q, f): θ_r = (q + f)H exactly, from the decimals as written.

    Parameters
    ----------
    reaction_delay, sample_time_ : float
        θ_r ≥ 0 and H > 0, s.

    Returns
    -------
    (int, sympy.Rational)
        q and f; f within 10⁻⁹ of 0 or 1 is snapped to a whole number of steps.

    Examples
    --------
    >>> held_split(0.3, 0.1), held_split(0.25, 0.1)
    ((3, 0), (2, 1/2))
    """
    r = sp.Rational(str(Fraction(repr(float(reaction_delay))))) / sp.Rational(
        str(Fraction(repr(float(sample_time_)))))
    q = int(sp.floor(r))
    f = r - q
    if f < SNAP:
        f = sp.Integer(0)
    elif 1 - f < SNAP:
        q, f = q + 1, sp.Integer(0)
    return q, sp.Rational(f)


def sample_coefficients(fraction: sp.Expr, eps: sp.Expr) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """(c_a, c_0, c_1) of the delayed sample (module docstring, step 3).

    Parameters
    ----------
    fraction : sympy.Expr
        f (a number or :data:`reaction_fraction`).
    eps : sympy.Expr
        ε, the fractional part of δ/H (a number or ``epsilon``).

    Returns
    -------
    tuple of sympy.Expr
        Piecewise in (1 − ε) ≤ f unless both are numbers.

    Examples
    --------
    >>> sample_coefficients(sp.Integer(0), sp.Integer(0))[2]
    1 - exp(-sample_time/tau_prev)
    """
    s = (1 - eps) * sample_time
    r = s - fraction * sample_time
    first = (sp.exp(-s / tau_prev), 1 - sp.exp(-s / tau_prev), sp.Integer(0))
    second = (sp.exp(-s / tau_prev),
              sp.exp(-r / tau_prev) * (1 - sp.exp(-fraction * sample_time / tau_prev)),
              1 - sp.exp(-r / tau_prev))
    cond = sp.Le(1 - eps, fraction)
    if cond in (sp.true, sp.false):
        return first if cond is sp.true else second
    return tuple(sp.Piecewise((a, cond), (b, True)) for a, b in zip(first, second))  # type: ignore[return-value]


@dataclass(frozen=True)
class SampledReactionTransfer:
    """H(z) = (N_0(z) + z^{−(m+1)} N_1(z))/D(z) from u_{i−1} to u_i, and χ_f(z).

    Attributes
    ----------
    numerator_direct, numerator_delayed, denominator : sympy.Expr
        N_0, N_1 (with c_a, c_0, c_1 as symbols) and D, polynomials in z times z^{q}.
    characteristic : sympy.Expr
        χ_f(z) = D(z)/(z − e^{−H/τ_p}).
    one_piece : bool
        f = 0 (one held piece per step).
    """

    numerator_direct: sp.Expr
    numerator_delayed: sp.Expr
    denominator: sp.Expr
    characteristic: sp.Expr
    one_piece: bool

    @property
    def expr(self) -> sp.Expr:
        """H(z) as one expression (the delay as z**(-m - 1))."""
        return (self.numerator_direct + z ** (-m - 1) * self.numerator_delayed) / self.denominator


def _piece(t: sp.Expr) -> sp.Matrix:
    """Φ(t) of the augmented model (rows y = [Δp, Δv, a_i, a_p]; columns y, u_p, u)."""
    return sampled_model().Phi[:4, :].subs(sample_time, t)


@lru_cache(maxsize=4)
def sampled_reaction_transfer(one_piece: bool = False) -> SampledReactionTransfer:
    """Derive H(z) with θ_r (module docstring, steps 1-4), in q, f, m and c_a, c_0, c_1.

    Parameters
    ----------
    one_piece : bool
        f = 0: one held piece of length H per step (the two-piece form with f = 0 has a
        common factor z in N and D; this form has none).

    Returns
    -------
    SampledReactionTransfer

    Examples
    --------
    >>> tf = sampled_reaction_transfer(True)
    >>> sp.Poly(tf.characteristic.subs(reaction_steps, 2), z).degree()  # 3 + L, L = q
    5
    """
    q, f, H = reaction_steps, reaction_fraction, sample_time
    if one_piece:
        P = _piece(H)
        Phi, gu, gp, shift = P[:, :4], P[:, 5], P[:, 4], z**q
    else:
        P1, P2 = _piece(f * H), _piece((1 - f) * H)
        Phi = P2[:, :4] * P1[:, :4]
        gu = z * P2[:, 5] + P2[:, :4] * P1[:, 5]
        gp = z * P2[:, 4] + P2[:, :4] * P1[:, 4]
        shift = z ** (q + 1)
    M = z * sp.eye(4) - Phi
    Mf = M[:3, :3]  # the follower's block: a_p does not depend on it
    adj_f = Mf.adjugate()
    det_f = sp.expand(Mf.det())
    Kr = sp.Matrix([[k_x, k_v, 0]])
    chi = sp.expand(shift * det_f - (Kr * adj_f * gu[:3, 0])[0, 0])
    lam_p = M[3, 3]  # z − e^{−H/τ_p} (a product of the pieces' exponentials)
    det = det_f * lam_p
    # det·Y for the predecessor's input (block triangular M): det·Y_3 = det_f g_p3 and
    # det·Y_f = adj_f (λ_p g_p,f − M_f3 g_p3)
    b = M[:3, 3]
    n0 = sp.expand((Kr * adj_f * (lam_p * gp[:3, 0] - b * gp[3, 0]))[0, 0])
    ap = det_f * gp[3, 0]
    n1 = sp.expand(k_a * (c_a * ap + det * (c_1 if one_piece else c_0 + c_1 * z)))
    return SampledReactionTransfer(n0, n1, sp.expand(chi * lam_p), chi, one_piece)


def characteristic_polynomial(q: int, f: sp.Expr) -> sp.Expr:
    """χ_f(z) at given q and f: degree 3 + q + [f > 0] in z.

    Parameters
    ----------
    q : int
        Whole steps of θ_r.
    f : sympy.Expr
        Its fractional part (0 ≤ f < 1, a number).

    Returns
    -------
    sympy.Expr
        The follower's closed-loop characteristic polynomial, monic in z.

    Examples
    --------
    >>> sp.Poly(characteristic_polynomial(1, sp.Rational(1, 2)), z).degree()
    5
    """
    tf = sampled_reaction_transfer(f == 0)
    sub = {reaction_steps: q} if f == 0 else {reaction_steps: q, reaction_fraction: f}
    return sp.expand(tf.characteristic.subs(sub))


def transfer_at(q: int, f: sp.Expr, substitute: dict[sp.Symbol, Any]) -> dict[str, sp.Expr]:
    """N_0, N_1 (with c_a, c_0, c_1 substituted), D, χ_f at given q, f and substitutions.

    Parameters
    ----------
    q : int
        Whole steps of θ_r.
    f : sympy.Expr
        Its fractional part (a number).
    substitute : dict
        Symbol → value (τ, τ_p, H, the gains, m and ε when δ is given, ...).

    Returns
    -------
    dict of str to sympy.Expr
        Keys ``numerator_direct``, ``numerator_delayed``, ``denominator``, ``characteristic``,
        ``c_a``, ``c_0``, ``c_1``.
    """
    tf = sampled_reaction_transfer(f == 0)
    sub = {**substitute, reaction_steps: sp.Integer(q), reaction_fraction: f}
    cs = sample_coefficients(f, substitute.get(epsilon, epsilon))
    cs = tuple(sp.simplify(c.subs(sub)) for c in cs)
    csub = dict(zip((c_a, c_0, c_1), cs))

    def at(e: sp.Expr) -> sp.Expr:
        return sp.expand(e.subs(csub).subs(sub))

    return {"numerator_direct": at(tf.numerator_direct),
            "numerator_delayed": at(tf.numerator_delayed),
            "denominator": at(tf.denominator), "characteristic": at(tf.characteristic),
            "c_a": cs[0], "c_0": cs[1], "c_1": cs[2]}

#: The rows of ``stringstab derive --sample-time H --reaction-delay S`` (text and LaTeX labels).
SAMPLED_REACTION_LABELS = {
    "H": ("H(z) = U_i(z)/U_{i-1}(z)", r"H(z)"),
    "H_numerator_direct": ("N_0(z)", r"N_0(z)"),
    "H_numerator_delayed": ("N_1(z) (times z^-(m+1))", r"N_1(z)"),
    "H_denominator": ("D(z) = (z - exp(-sample_time/tau_prev)) chi_f(z)", r"D(z)"),
    "characteristic_polynomial": ("chi_f(z) (the follower's characteristic polynomial, degree 3 + L)",
                                  r"\chi_f(z)"),
    "sample_coefficients": ("delayed sample a_{i-1}(kH - delta) = c_a a_p + c_0 w_0 + c_1 w_1",
                            r"c_a, c_0, c_1"),
}


def sampled_reaction_derivation(sample_time_: float, reaction_delay_: float,
                                substitute: str | None = None) -> Any:
    """Derive the sampled link's H(z) with θ_r (``derive --sample-time H --reaction-delay S``).

    θ_r and H are substituted exactly (the decimals as written): q and f of θ_r = (q + f)H;
    when δ is substituted too, so are m = ⌊δ/H⌋, ε = δ/H − m and the case of the delayed
    sample (otherwise c_a, c_0, c_1 are Piecewise in ε).  ``tau_prev`` is τ unless substituted.

    Parameters
    ----------
    sample_time_ : float
        H > 0, s.
    reaction_delay_ : float
        θ_r > 0, s.
    substitute : str, optional
        ``"tau=0.1,delta=0.2,headway=1.1"``-style specialisation (also the gains and
        ``tau_prev``; ``reaction_delay`` is ``reaction_delay_``).

    Returns
    -------
    Derivation
        Keys :data:`SAMPLED_REACTION_LABELS`; the document also has ``q``, ``f``, ``m``,
        ``epsilon``, ``L``.

    Raises
    ------
    StringStabError
        On a bad sample time or substitution.

    Examples
    --------
    >>> d = sampled_reaction_derivation(0.1, 0.25, "tau=0.5,delta=0.1,headway=1.5")
    >>> d.document["q"], d.document["f"], d.document["L"], d.document["m"]
    (2, '1/2', 3, 1)
    """
    from ..params import sample_time as check_sample_time
    from .derivation import Derivation
    from .symbolic import SUBSTITUTABLE, parse_substitutions

    H = check_sample_time(sample_time_)
    H_exact = sp.Rational(str(Fraction(repr(H))))
    q, f = held_split(reaction_delay_, H)
    text = ",".join(x for x in (substitute or "").split(",")
                    if x.strip() and x.partition("=")[0].strip() != "reaction_delay")
    subs = parse_substitutions(text, {**SUBSTITUTABLE, "tau_prev": tau_prev})
    given = {str(k): str(v) for k, v in subs.items()}
    given["reaction_delay"] = repr(float(reaction_delay_))
    subs.setdefault(tau_prev, subs.get(SUBSTITUTABLE["tau"], SUBSTITUTABLE["tau"]))
    subs[sample_time] = H_exact
    delta = SUBSTITUTABLE["delta"]
    m_val: Any = "m"
    eps_val: Any = "epsilon"
    if delta in subs:
        r = sp.Rational(subs[delta]) / H_exact
        m_val, eps_val = int(sp.floor(r)), r - sp.floor(r)
        subs[m], subs[epsilon] = sp.Integer(m_val), eps_val
    d = transfer_at(q, f, subs)
    m_expr = subs.get(m, m)
    full = (d["numerator_direct"] + z ** (-(m_expr + 1)) * d["numerator_delayed"]) / d["denominator"]
    N0, N1, D = (sp.Function(name)(z) for name in ("N_0", "N_1", "D"))
    exprs: dict[str, Any] = {
        "H": (N0 + z ** (-(m_expr + 1)) * N1) / D,
        "H_numerator_direct": d["numerator_direct"],
        "H_numerator_delayed": d["numerator_delayed"],
        "H_denominator": d["denominator"],
        "characteristic_polynomial": sp.collect(d["characteristic"], z),
        "sample_coefficients": {"c_a": d["c_a"], "c_0": d["c_0"], "c_1": d["c_1"]},
    }
    doc: dict[str, Any] = {}
    for key, val in exprs.items():
        doc[key] = {k: str(v) for k, v in val.items()} if isinstance(val, dict) else str(val)
    L = q + (1 if f else 0)
    doc["H"] = str(full)
    doc.update(sample_time=H, reaction_delay=float(reaction_delay_), q=q, f=str(f), L=L,
               m=m_val, epsilon=str(eps_val))
    doc["delay"] = (f"delta = (m + epsilon) sample_time with m = {m_val}, epsilon = {eps_val}"
                    if delta in subs else "delta = (m + epsilon) sample_time, m integer, 0 <= epsilon < 1")
    doc["reaction"] = (f"reaction_delay = (q + f) sample_time with q = {q}, f = {f}: the command "
                       f"of step k is applied over [kH, kH + fH) at step k + q + 1 and over "
                       f"[kH + fH, (k + 1)H) at step k + q; {L} held commands per vehicle")
    doc["symbols"] = ["k_x", "k_v", "k_a", "tau", "tau_prev", "delta", "headway", "sample_time",
                      "m", "epsilon", "z"]
    doc["substitute"] = given
    doc["conventions"] = {
        "H": "U_i(z)/U_{i-1}(z): predecessor's to follower's commands (the certificate's link, "
             "docs/sampled.md §10), zero-order hold, the command applied reaction_delay later",
        "characteristic_polynomial": "internal stability: every root inside the unit circle "
                                     "(decided by the certificate's Stein inertia test; no "
                                     "closed-form Schur conditions at this degree)",
        "tau_prev": "the predecessor's actuator lag; tau unless substituted (homogeneous platoon)",
    }
    return Derivation(exprs, doc, dict(SAMPLED_REACTION_LABELS))
