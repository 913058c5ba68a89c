"""The derivation as a document: Γ(s), Ψ1-Ψ3, Λ, gradients, Hurwitz conditions and errata.

:func:`derivation` derives everything once (:func:`stringstab.derive.symbolic.derive_all`) and returns a
:class:`Derivation` that renders itself as JSON-ready data, text or LaTeX; ``stringstab derive``
and the demo print or write these renderings.  :func:`sampled_derivation` does the same for the
sampled-data loop (``stringstab derive --sample-time H``: H(z), the characteristic polynomial
Δ(z) and its Schur conditions, from :mod:`stringstab.derive.sampled_symbolic`).  SymPy is imported when
a derivation is made.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

__all__ = ["Derivation", "derivation", "reaction_derivation", "sampled_derivation"]

_LABELS = {
    "gamma": ("Γ(s)", r"\Gamma(s)"),
    "gamma_numerator": ("N(s)", r"N(s)"),
    "gamma_denominator": ("D(s)", r"D(s)"),
    "psi1": ("Ψ1", r"\Psi_1"),
    "psi2": ("Ψ2", r"\Psi_2"),
    "psi3": ("Ψ3", r"\Psi_3"),
    "lambda": ("Λ", r"\Lambda"),
    "grad_psi2": ("∇_K Ψ2", r"\nabla_K \Psi_2"),
    "grad_psi3": ("∇_K Ψ3", r"\nabla_K \Psi_3"),
    "hurwitz": ("Hurwitz (each > 0)", r"\text{Hurwitz}"),
}
_SAMPLED_LABELS = {
    "H": ("H(z)", r"H(z)"),
    "H_numerator_direct": ("N_0(z)", r"N_0(z)"),
    "H_numerator_delayed": ("N_1(z)", r"N_1(z)"),
    "H_denominator": ("D(z)", r"D(z)"),
    "characteristic_polynomial": ("Δ(z) (characteristic polynomial)", r"\Delta(z)"),
    "w_coefficients": ("w-coefficients (w = z - 1)", r"\text{w-coefficients}"),
    "schur_conditions": ("Schur (each > 0, in delta0, delta1, delta2)", r"\text{Schur}"),
    "schur_conditions_gains": ("Schur (each > 0, in the gains)", r"\text{Schur}"),
    "dc_margin": ("c2 (θ² coefficient of |D|² - |N|²; H² φ1⁴ Ψ3 when tau_prev = tau)", r"c_2"),
}


_REACTION_LABELS = {
    "gamma": ("Γ(s)", r"\Gamma(s)"),
    "gamma_numerator": ("N(s)", r"N(s)"),
    "gamma_denominator": ("D(s) = P(s) + exp(-reaction_delay*s) Q(s)", r"D(s)"),
    "denominator_P": ("P(s)", r"P(s)"),
    "denominator_Q": ("Q(s)", r"Q(s)"),
    "margin": ("g_θ(ω) = (|D(jω)|² - |N(jω)|²)/ω²", r"g_\theta(\omega)"),
    "psi1": ("Ψ1 (with θ_r)", r"\Psi_1"),
    "psi2": ("Ψ2 (with θ_r)", r"\Psi_2"),
    "psi3": ("Ψ3 (with θ_r)", r"\Psi_3"),
    "lambda": ("Λ (with θ_r)", r"\Lambda"),
    "taylor1_hurwitz": ("Taylor route, exp(-θ_r s) ≈ 1 - θ_r s: Hurwitz (each > 0; NOT a certificate)",
                        r"\text{Taylor}"),
    "pade11_hurwitz": ("Padé(1,1) route: Hurwitz (each > 0; NOT a certificate)", r"\text{Pad\'e}"),
}


@dataclass(frozen=True)
class Derivation:
    """The derived expressions (SymPy) and their JSON document (strings that parse with ``sympify``)."""

    exprs: dict[str, Any]
    document: dict[str, Any]
    labels: dict[str, tuple[str, str]] = field(default_factory=lambda: dict(_LABELS))

    def text(self) -> str:
        """Plain-text rendering (``stringstab derive --format text``)."""
        return _text(self.exprs, self.document, self.labels)

    def latex(self) -> str:
        """LaTeX rendering (``stringstab derive --format latex``; needs amsmath)."""
        return _latex(self.exprs, self.document, self.labels)

    def json(self) -> str:
        """JSON rendering (``stringstab derive --format json``)."""
        from ..io import dumps_json

        return dumps_json(self.document)


def derivation(
    delay_order: int | None = None, substitute: str | None = None, with_errata: bool = False
) -> Derivation:
    """Derive Γ(s), Ψ1-Ψ3, Λ, ∇Ψ2, ∇Ψ3 and the Hurwitz conditions from the IDL model (eqs 3-9).

    Parameters
    ----------
    delay_order : int or None
        Taylor order of e^{−δs} used for Ψ; ``None`` is the exact delay (the printed Ψ1
        corresponds to 3).
    substitute : str, optional
        ``"tau=0.1,delta=0.2,headway=1.1"``-style specialisation (also gains).
    with_errata : bool
        Add the comparison with the IDL paper's printed formulas (:func:`stringstab.derive.errata.errata`).

    Returns
    -------
    Derivation
        The derived expressions, their rendered document and, with ``with_errata``,
        the comparison with the printed formulas.

    Examples
    --------
    >>> d = derivation(substitute="tau=0.1,delta=0.2,headway=1.1")
    >>> d.document["hurwitz"]
    ['k_x', 'k_v + k_x']
    """
    from .symbolic import derive_all, parse_substitutions

    if substitute and "reaction_delay" in substitute:  # θ_r (issue 25): its own derivation
        from .symbolic import SUBSTITUTABLE

        theta = parse_substitutions(substitute, {**SUBSTITUTABLE, "reaction_delay": _theta()})
        if theta.get(_theta(), 0) != 0:
            return reaction_derivation(substitute, delay_order, with_errata)
        substitute = ",".join(x for x in substitute.split(",")
                              if x.partition("=")[0].strip() != "reaction_delay")
    subs = parse_substitutions(substitute)
    exprs = derive_all(delay_order, subs)
    doc: dict[str, Any] = {}
    for key, val in exprs.items():
        doc[key] = [str(v) for v in val] if isinstance(val, list) else str(val)
    doc["symbols"] = ["k_x", "k_v", "k_a", "tau", "delta", "headway", "s", "omega"]
    doc["substitute"] = {str(k): str(v) for k, v in subs.items()}
    doc["delay_order"] = "exact" if delay_order is None else delay_order
    doc["conventions"] = {
        "psi": "Psi1, Psi2, Psi3 are the omega^6, omega^4, omega^2 coefficients of |D(j omega)|^2 - |N(j omega)|^2",
        "hurwitz": "each expression must be > 0 for internal stability",
        "printed_forms_correspond_to": "delay_order=3 (3rd-order Taylor polynomial of exp(-delta*s)), omega order 6",
    }
    if with_errata:
        from .errata import errata

        kw = {str(k): float(v) for k, v in subs.items() if str(k) in ("tau", "delta", "headway")}
        doc["errata"] = [e.as_dict() for e in errata(**kw)]
    return Derivation(exprs, doc)


def _theta() -> Any:
    from .reaction import reaction_delay

    return reaction_delay


def reaction_derivation(substitute: str | None = None, delay_order: int | None = None,
                        with_errata: bool = False) -> Derivation:
    """Derive the loop with a reaction delay θ_r (issue 25): ``derive --reaction-delay``.

    Γ(s) with e^{−θ_r s} on the whole command, its quasi-polynomial denominator
    D = P + e^{−θ_r s}Q, the margin g_θ(ω), Ψ1-Ψ3 and Λ with θ_r, and what the Taylor route
    would test for internal stability (e^{−θ_r s} ≈ 1 − θ_r s, or Padé(1,1): Hurwitz
    determinants of a cubic or quartic — not a certificate; docs/theory.md)
    (:mod:`stringstab.derive.reaction`).

    Parameters
    ----------
    substitute : str, optional
        ``"tau=0.1,delta=0.2,headway=1.1,reaction_delay=0.2"``-style specialisation.
    delay_order, with_errata
        Refused: ``--delay-order`` and ``--errata`` are about the θ_r = 0 loop's Ψ.

    Returns
    -------
    Derivation
        With the keys of :func:`stringstab.derive.reaction.derive_reaction`.

    Raises
    ------
    StringStabError
        On a bad substitution, or with ``delay_order`` or ``with_errata``.

    Examples
    --------
    >>> d = reaction_derivation("tau=0.1,delta=0.2,headway=1.1,reaction_delay=0.2")
    >>> d.document["denominator_Q"]
    'k_x + s*(k_v + 11*k_x/10)'
    """
    from ..errors import StringStabError
    from .reaction import derive_reaction
    from .symbolic import SUBSTITUTABLE, parse_substitutions

    if delay_order is not None or with_errata:
        raise StringStabError(
            "--errata and --delay-order are about the θ_r = 0 loop's Ψ (IDL eqs 12-15); expected "
            f"neither with a reaction delay; got {'--errata' if with_errata else '--delay-order'}")
    subs = parse_substitutions(substitute, {**SUBSTITUTABLE, "reaction_delay": _theta()})
    exprs = derive_reaction(subs)
    doc: dict[str, Any] = {k: [str(v) for v in val] if isinstance(val, list) else str(val)
                           for k, val in exprs.items()}
    doc["symbols"] = ["k_x", "k_v", "k_a", "tau", "delta", "headway", "reaction_delay", "s", "omega"]
    doc["substitute"] = {str(k): str(v) for k, v in subs.items()}
    doc["conventions"] = {
        "model": "tau a' = u(t - reaction_delay) - a: the whole command applied reaction_delay s late",
        "psi": "Psi1, Psi2, Psi3 are the omega^4, omega^2, omega^0 coefficients of the margin g",
        "stability": "D(s) is a quasi-polynomial (infinitely many roots): no finite set of "
                     "conditions decides it; stringstab certify --reaction-delay counts its roots "
                     "in Re s > 0 exactly (argument principle); the taylor1/pade11 conditions are "
                     "what a Taylor or Pade(1,1) treatment would test, and can be wrong",
    }
    return Derivation(exprs, doc, dict(_REACTION_LABELS))


_IMPACT_WORDS = {
    "sign_disagreement": "the sign (the verdict) differs",
    "hurwitz_disagreement": "the Hurwitz verdict differs",
    "verdict_disagreement_printed_vs_derived": "the printed and the derived Proposition 1 disagree",
    "verdict_disagreement_logic_only": "the printed logic on the derived Ψ disagrees",
}


def _impact(impact: dict[str, Any]) -> str:
    """An erratum's practical impact in words: shares of the grid in %, parameters in s."""
    p = impact.get("params", {})
    where = impact.get("grid", "the grid")
    if {"tau", "delta", "headway"} <= set(p):
        where += f"; τ = {p['tau']:g} s, δ = {p['delta']:g} s, T* = {p['headway']:g} s"
    parts = [f"{_IMPACT_WORDS.get(k, k.replace('_', ' '))} on {100 * float(v):.2f} %"
             for k, v in impact.items() if k not in ("grid", "params")]
    return "; ".join(parts) + f" of the points ({where})"


def _text(exprs: dict[str, Any], doc: dict[str, Any], labels: dict[str, tuple[str, str]]) -> str:
    if "sample_time" in doc and "reaction_delay" in doc:
        lines = [f"# stringstab derive --sample-time {doc['sample_time']} --reaction-delay "
                 f"{doc['reaction_delay']}: the sampled-data loop with a reaction delay "
                 "(zero-order hold, exact lag, delay and reaction delay), derived from the IDL "
                 "model (eqs 3-9)", f"# delay: {doc['delay']}", f"# reaction: {doc['reaction']}"]
    elif "sample_time" in doc:
        lines = [f"# stringstab derive --sample-time {doc['sample_time']}: the sampled-data loop "
                 "(zero-order hold, exact lag and delay), derived from the IDL model (eqs 3-9)",
                 f"# delay: {doc['delay']}"]
    elif "reaction_delay" in doc.get("symbols", []):
        lines = ["# stringstab derive: derived from the IDL model (eqs 3-9) with a reaction delay "
                 "θ_r on the whole command (issue 25)"]
    else:
        lines = ["# stringstab derive: derived from the IDL model (eqs 3-9)"]
    if doc["substitute"]:
        unit = {"tau": " s", "tau_prev": " s", "delta": " s", "headway": " s",
                "sample_time": " s", "k_x": " 1/s²", "k_v": " 1/s", "reaction_delay": " s"}
        lines.append("# substituted: " + ", ".join(f"{k}={v}{unit.get(k, '')}"
                                                    for k, v in doc["substitute"].items()))
    if "delay_order" in doc:
        lines.append(f"# delay in Psi: {doc['delay_order']}")
    for key, (label, _) in labels.items():
        val = exprs[key]
        if isinstance(val, list):
            lines.append(f"{label}:")
            lines.extend(f"    {v}" for v in val)
        elif isinstance(val, dict):
            lines.append(f"{label}:")
            lines.extend(f"    {k} = {v}" for k, v in val.items())
        else:
            lines.append(f"{label} = {val}")
    if "errata" in doc:
        lines.append("")
        lines.append("# errata: printed (IDL paper) vs derived")
        for e in doc["errata"]:
            status = "OK " if e["matches"] else "ERR"
            lines.append(f"[{status}] eq {e['equation']} {e['name']}")
            if not e["matches"]:
                lines.append(f"      printed - derived = {e['difference']}")
                lines.append(f"      {e['explanation']}")
                if e["impact"]:
                    lines.append(f"      impact: {_impact(e['impact'])}")
    return "\n".join(lines) + "\n"


def _latex(exprs: dict[str, Any], doc: dict[str, Any], labels: dict[str, tuple[str, str]]) -> str:
    import sympy as sp

    syms = {sp.Symbol("headway", positive=True): sp.Symbol("T^*"),
            sp.Symbol("reaction_delay", nonnegative=True): sp.Symbol(r"\theta_r"),
            sp.Symbol("sample_time", positive=True): sp.Symbol("H"),
            sp.Symbol("tau_prev", positive=True): sp.Symbol(r"\tau_p")}
    out = ["% stringstab derive --format latex (needs amsmath)", r"\begin{align*}"]
    rows: list[str] = []
    for key, (_, tex) in labels.items():
        val = exprs[key]
        if isinstance(val, dict):
            rows.extend(sp.latex(sp.Symbol(k)) + " &= " + sp.latex(sp.sympify(v).subs(syms))
                        for k, v in val.items())
        elif key in ("hurwitz", "schur_conditions", "schur_conditions_gains", "taylor1_hurwitz",
                     "pade11_hurwitz"):
            rows.append(tex + r" &:\ " + r",\quad ".join(sp.latex(v.subs(syms)) + " > 0" for v in val))
        elif isinstance(val, list):
            rows.append(
                tex + r" &= \begin{pmatrix}" + r" \\ ".join(sp.latex(v.subs(syms)) for v in val)
                + r"\end{pmatrix}"
            )
        else:
            rows.append(tex + " &= " + sp.latex(val.subs(syms)))
    out.append(" \\\\\n".join(rows))
    out.append(r"\end{align*}")
    if "errata" in doc:
        out.append("% errata (printed - derived):")
        for e in doc["errata"]:
            if not e["matches"]:
                out.append(f"% eq {e['equation']} {e['name']}: {e['difference']}")
    return "\n".join(out) + "\n"


def sampled_derivation(sample_time: float, substitute: str | None = None) -> Derivation:
    """Derive the sampled-data loop's H(z), Δ(z) and Schur conditions (``derive --sample-time``).

    Every vehicle samples with period H and holds its command (zero-order hold); the lag is
    discretised exactly and the delay δ = (m + ε)H is exact for any δ ≥ 0
    (:mod:`stringstab.derive.sampled_symbolic`).  H is substituted exactly (as the decimal it is
    written as); when δ is substituted too, so are m = ⌊δ/H⌋ and ε = δ/H − m.  The
    predecessor's lag ``tau_prev`` is τ (a homogeneous platoon) unless substituted.

    Parameters
    ----------
    sample_time : float
        H > 0, s.
    substitute : str, optional
        ``"tau=0.1,delta=0.2,headway=1.1"``-style specialisation (also the gains and
        ``tau_prev``).

    Returns
    -------
    Derivation
        Keys ``H``, ``H_numerator_direct``, ``H_numerator_delayed``, ``H_denominator``,
        ``characteristic_polynomial``, ``w_coefficients``, ``schur_conditions`` (in δ0, δ1,
        δ2), ``schur_conditions_gains`` (the same in the gains) and ``dc_margin``.

    Raises
    ------
    StringStabError
        On a sample time that is not a finite number > 0 or a bad substitution.

    Examples
    --------
    >>> d = sampled_derivation(0.1, "tau=0.1,delta=0.25,headway=1.1,k_x=1,k_v=0.5,k_a=0.2")
    >>> d.document["m"], d.document["epsilon"], len(d.document["schur_conditions_gains"])
    (2, '1/2', 5)
    """
    import sympy as sp

    from ..params import sample_time as check_sample_time
    from . import sampled_symbolic as SS
    from .symbolic import SUBSTITUTABLE, parse_substitutions

    H = check_sample_time(sample_time)
    H_exact = sp.Rational(str(Fraction(repr(H))))
    subs = parse_substitutions(substitute, {**SUBSTITUTABLE, "tau_prev": SS.tau_prev})
    given = {str(k): str(v) for k, v in subs.items()}
    subs.setdefault(SS.tau_prev, subs.get(SUBSTITUTABLE["tau"], SUBSTITUTABLE["tau"]))
    subs[SS.sample_time] = H_exact
    delta = SUBSTITUTABLE["delta"]
    m_val: Any = "m"
    eps_val: Any = "epsilon"
    if delta in subs:
        q = sp.Rational(subs[delta]) / H_exact
        m_val, eps_val = int(sp.floor(q)), q - sp.floor(q)
        subs[SS.m], subs[SS.epsilon] = sp.Integer(m_val), eps_val
    exprs: dict[str, Any] = dict(SS.derive_sampled_all(subs))
    m_expr = subs.get(SS.m, SS.m)
    delay = SS.z ** (-(m_expr + 1))
    full = (exprs["H_numerator_direct"] + delay * exprs["H_numerator_delayed"]) / exprs["H_denominator"]
    N0, N1, D = (sp.Function(f)(SS.z) for f in ("N_0", "N_1", "D"))
    exprs["H"] = (N0 + delay * N1) / D  # the form; the parts follow (the document has the whole)
    w = exprs["w_coefficients"]
    d0, d1, d2 = sp.symbols("delta0 delta1 delta2", real=True)
    exprs["schur_conditions_gains"] = [
        sp.expand(c.subs({d0: w["delta0"], d1: w["delta1"], d2: w["delta2"]}))
        for c in exprs["schur_conditions"]]
    exprs = {k: exprs[k] for k in _SAMPLED_LABELS}
    doc: dict[str, Any] = {}
    for key, val in exprs.items():
        if isinstance(val, dict):
            doc[key] = {k: str(v) for k, v in val.items()}
        else:
            doc[key] = [str(v) for v in val] if isinstance(val, list) else str(val)
    doc["H"] = str(full)
    doc["sample_time"] = H
    doc["m"] = m_val
    doc["epsilon"] = str(eps_val)
    doc["delay"] = (f"delta = (m + epsilon) sample_time with m = {m_val}, epsilon = {eps_val}"
                    if delta in subs else "delta = (m + epsilon) sample_time, m integer, 0 <= epsilon < 1")
    doc["symbols"] = ["k_x", "k_v", "k_a", "tau", "tau_prev", "delta", "headway", "sample_time",
                      "m", "epsilon", "z", "delta0", "delta1", "delta2"]
    doc["substitute"] = given
    doc["conventions"] = {
        "H": "A_i(z)/A_{i-1}(z): predecessor's to follower's acceleration samples, "
             "zero-order hold on every vehicle's command",
        "schur_conditions": "each expression must be > 0 for internal stability (all roots of "
                            "Delta(z) inside the unit circle)",
        "tau_prev": "the predecessor's actuator lag; tau unless substituted (homogeneous platoon)",
    }
    return Derivation(exprs, doc, dict(_SAMPLED_LABELS))
