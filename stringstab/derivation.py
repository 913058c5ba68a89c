"""The derivation as a document: Γ(s), Ψ1-Ψ3, Λ, gradients, Hurwitz conditions and errata.

:func:`derivation` derives everything once (:func:`stringstab.symbolic.derive_all`) and returns a
:class:`Derivation` that renders itself as JSON-ready data, text or LaTeX; ``stringstab derive``
and the demo print or write these renderings.  SymPy is imported when a derivation is made.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

__all__ = ["Derivation", "derivation"]

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



@dataclass(frozen=True)
class Derivation:
    """The derived expressions (SymPy) and their JSON document (strings that parse with ``sympify``)."""

    exprs: dict[str, Any]
    document: dict[str, Any]

    def text(self) -> str:
        """Plain-text rendering (``stringstab derive --format text``)."""
        return _text(self.exprs, self.document)

    def latex(self) -> str:
        """LaTeX rendering (``stringstab derive --format latex``; needs amsmath)."""
        return _latex(self.exprs, self.document)

    def json(self) -> str:
        """JSON rendering (``stringstab derive --format json``)."""
        from .io import dumps_json

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
        Add the comparison with the IDL paper's printed formulas (:func:`stringstab.errata.errata`).

    Examples
    --------
    >>> d = derivation(substitute="tau=0.1,delta=0.2,headway=1.1")
    >>> d.document["hurwitz"]
    ['k_x', 'k_v + k_x']
    """
    from .symbolic import derive_all, parse_substitutions

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


def _text(exprs: dict[str, Any], doc: dict[str, Any]) -> str:
    lines = ["# stringstab derive: derived from the IDL model (eqs 3-9)"]
    if doc["substitute"]:
        unit = {"tau": " s", "delta": " s", "headway": " s", "k_x": " 1/s²", "k_v": " 1/s"}
        lines.append("# substituted: " + ", ".join(f"{k}={v}{unit.get(k, '')}"
                                                    for k, v in doc["substitute"].items()))
    lines.append(f"# delay in Psi: {doc['delay_order']}")
    for key, (label, _) in _LABELS.items():
        val = exprs[key]
        if isinstance(val, list):
            lines.append(f"{label}:")
            lines.extend(f"    {v}" for v in val)
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


def _latex(exprs: dict[str, Any], doc: dict[str, Any]) -> str:
    import sympy as sp

    syms = {sp.Symbol("headway", positive=True): sp.Symbol("T^*")}
    out = ["% stringstab derive --format latex (needs amsmath)", r"\begin{align*}"]
    rows = []
    for key, (_, tex) in _LABELS.items():
        val = exprs[key]
        if key == "hurwitz":
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
