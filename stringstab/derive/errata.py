"""Errata: where the IDL paper's printed formulas differ from the derived ones.

For each printed expression of eqs 11-15 and 25-26 (:mod:`stringstab.derive.printed`)
the report says whether it equals the form derived from the model
(:mod:`stringstab.derive.symbolic`), and if not gives the simplified difference
(printed − derived), the terms that differ, an explanation, and how much it
matters in practice: the share of a gain grid over [-2, 2]³ on which the sign
(hence the verdict) of the printed expression differs from the derived one.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import sympy as sp

from .printed import PRINTED
from .symbolic import GAINS, PARAMS, derived_psi, gamma, gradients, hurwitz_conditions, lambdify_psi

__all__ = ["Erratum", "errata", "proposition1_conditions"]

_EXPLANATIONS: dict[str, str] = {
    "gamma_numerator": "matches.",
    "gamma_denominator": (
        "the s¹ coefficient is printed τ·k_x + k_v; the model gives T*·k_x + k_v "
        "(the spacing error is Δp = Δx − T* v − l_0, so T* and not τ multiplies k_x). "
        "With the printed denominator the Hurwitz condition becomes k_v > 0 instead of "
        "k_v + (T* − τ)k_x > 0."
    ),
    "psi1": (
        "truncation, not a typo: the printed Ψ1 equals the derived one with e^{-δs} "
        "replaced by its 3rd-order Taylor polynomial; the exact-delay series adds "
        "k_x k_a δ⁴/12 (1.3e-4·k_x k_a at δ = 0.2 s). Note also that the paper argues "
        "Ψ1 ≥ 0 from non-negative gains, but its gains range over [-2, 2] and Ψ1 < 0 "
        "when k_v k_a < −3τ²/δ³ (about −3.75 at τ = 0.1 s, δ = 0.2 s)."
    ),
    "psi2": (
        "two errors: the lag term is printed −2τ(k_x + k_v T*) but the model gives "
        "−2τ(k_v + k_x T*) (k_x and k_v swapped, the same slip as in eq 11), and the "
        "k_a k_x δ² term has the wrong sign (derived −k_a k_x δ², from the cos(δω) "
        "expansion of |N(jω)|²)."
    ),
    "psi3": "matches.",
    "lambda": (
        "the formula Λ = Ψ2² − 4Ψ1Ψ3 is right; expanded in the gains it inherits the "
        "errors of eqs 12-13."
    ),
    "grad_psi2": (
        "∂Ψ2/∂k_x is printed 1 − 2τ + k_a δ²: the '1' is spurious even for the printed "
        "Ψ2 (whose ∂/∂k_x is −2τ + k_a δ²), and from the derived Ψ2 it is −2τT* − k_a δ². "
        "∂Ψ2/∂k_v is printed −2τT* − 2k_a δ, derived −2τ − 2k_a δ; ∂Ψ2/∂k_a has the sign "
        "of its k_x δ² term flipped. Components 2-3 are consistent with the printed Ψ2."
    ),
    "grad_psi3": "matches (T^e in the extracted text is T*).",
    "proposition1": (
        "Ψ1 ω⁴ + Ψ2 ω² + Ψ3 ≥ 0 for all ω² ≥ 0 holds iff Ψ1 ≥ 0, Ψ3 ≥ 0 and "
        "(Ψ2 ≥ 0 or Λ ≤ 0). The printed 'or Λ ≤ 0' alone also accepts Ψ1 < 0 with Λ ≤ 0 "
        "(then Ψ3 ≤ 0 and the quartic is negative), so the toolkit's 'taylor' (derived) "
        "verdict uses the corrected logic and its 'printed' verdict the printed one."
    ),
}


@dataclass(frozen=True)
class Erratum:
    """One row of the errata report (the JSON object under ``errata``)."""

    equation: str
    name: str
    key: str
    printed: str
    derived: str
    difference: str
    matches: bool
    wrong_terms: list[str] = field(default_factory=list)
    explanation: str = ""
    impact: dict[str, Any] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready dict."""
        return asdict(self)


def proposition1_conditions(
    psi1: sp.Expr, psi2: sp.Expr, psi3: sp.Expr, lam: sp.Expr, *, printed: bool
) -> sp.Basic:
    """Proposition 1 as a SymPy boolean: the printed logic or the corrected one.

    Printed (IDL Proposition 1): (Ψ1 ≥ 0 ∧ Ψ2 ≥ 0 ∧ Ψ3 ≥ 0) ∨ Λ ≤ 0.
    Corrected: the quadratic q(x) = Ψ1x² + Ψ2x + Ψ3 is ≥ 0 for all x ≥ 0 iff
    Ψ1 ≥ 0 ∧ Ψ3 ≥ 0 ∧ (Ψ2 ≥ 0 ∨ Λ ≤ 0).

    Parameters
    ----------
    psi1, psi2, psi3, lam : sympy.Expr
        Ψ1, Ψ2, Ψ3 (IDL eqs 12-14) and Λ = Ψ2² − 4Ψ1Ψ3 (eq 15).
    printed : bool
        True: the printed logic; False: the corrected one.

    Returns
    -------
    sympy.Basic
        The condition as a SymPy boolean (``Or``/``And`` of relations, or a literal
        ``true``/``false`` when the relations evaluate).
    """
    if printed:
        return sp.Or(sp.And(psi1 >= 0, psi2 >= 0, psi3 >= 0), lam <= 0)
    return sp.And(psi1 >= 0, psi3 >= 0, sp.Or(psi2 >= 0, lam <= 0))


def _grid(n: int = 41) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    g = np.linspace(-2.0, 2.0, n)
    kx, kv, ka = np.meshgrid(g, g, g, indexing="ij")
    return kx.ravel(), kv.ravel(), ka.ravel()


def _sign_disagreement(printed: sp.Expr, derived: sp.Expr, params: dict[str, float]) -> float:
    f = sp.lambdify([*GAINS, *PARAMS], [printed, derived], modules="numpy")
    kx, kv, ka = _grid()
    p, d = (np.broadcast_to(np.asarray(v, float), kx.shape) for v in f(
        kx, kv, ka, params["tau"], params["delta"], params["headway"]))
    return float(np.mean((p >= 0) != (d >= 0)))


def errata(
    tau: float = 0.1, delta: float = 0.2, headway: float = 1.1
) -> list[Erratum]:
    """Compare every printed formula with its derived counterpart.

    Parameters
    ----------
    tau, delta, headway : float
        Parameters at which the practical impact (share of a 41³ grid over
        [-2, 2]³ where the sign/verdict differs) is measured.

    Returns
    -------
    list of Erratum
        In the order eq 11 (numerator, denominator), 12, 13, 14, 15, 25, 26 and
        Proposition 1.

    Examples
    --------
    >>> rows = {e.key: e for e in errata()}
    >>> rows["psi3"].matches, rows["psi2"].matches
    (True, False)
    >>> rows["psi1"].difference
    '-delta**4*k_a*k_x/12'
    """
    params = {"tau": tau, "delta": delta, "headway": headway}
    g = gamma()
    psi1, psi2, psi3, lam = derived_psi()
    grads = gradients()
    derived: dict[str, Any] = {
        "gamma_numerator": g.numerator,
        "gamma_denominator": g.denominator,
        "psi1": psi1,
        "psi2": psi2,
        "psi3": psi3,
        "lambda": lam,
        "grad_psi2": sp.Matrix(grads["grad_psi2"]),
        "grad_psi3": sp.Matrix(grads["grad_psi3"]),
    }
    out: list[Erratum] = []
    for key, pe in PRINTED.items():
        d = derived[key]
        p = pe.expr
        if isinstance(p, sp.MatrixBase):
            diff = sp.Matrix([sp.expand(a - b) for a, b in zip(p, d)])
            matches = all(x == 0 for x in diff)
            wrong = [
                f"component {i + 1} ({k}): {x}" for i, (k, x) in enumerate(zip(GAINS, diff)) if x != 0
            ]
            diff_str = str(list(diff))
            printed_str, derived_str = str(list(p)), str(list(d))
            impact: dict[str, Any] = {}
        else:
            diff_e = sp.expand(sp.simplify(p - d))
            matches = diff_e == 0
            wrong = [str(t) for t in sp.Add.make_args(diff_e)] if not matches else []
            diff_str = str(diff_e)
            printed_str, derived_str = str(p), str(d)
            impact = {}
            if key in ("psi1", "psi2", "psi3", "lambda") and not matches:
                impact = {
                    "grid": "41^3 gains over [-2, 2]^3",
                    "params": params,
                    "sign_disagreement": _sign_disagreement(p, d, params),
                }
            if key == "gamma_denominator" and not matches:
                impact = _hurwitz_impact(p, params)
        out.append(
            Erratum(
                equation=pe.equation,
                name=pe.name,
                key=key,
                printed=printed_str,
                derived=derived_str,
                difference=diff_str,
                matches=bool(matches),
                wrong_terms=wrong,
                explanation=_EXPLANATIONS[key],
                impact=impact,
            )
        )
    out.append(_proposition1_row(params))
    return out


def _hurwitz_impact(printed_den: sp.Expr, params: dict[str, float]) -> dict[str, Any]:
    from .symbolic import routh_hurwitz, s

    pc = routh_hurwitz(sp.Poly(printed_den, s))
    dc = hurwitz_conditions()
    f = sp.lambdify([*GAINS, *PARAMS], [*pc, *dc], modules="numpy")
    kx, kv, ka = _grid()
    vals = [np.broadcast_to(np.asarray(v, float), kx.shape)
            for v in f(kx, kv, ka, params["tau"], params["delta"], params["headway"])]
    hp = np.all([v > 0 for v in vals[: len(pc)]], axis=0)
    hd = np.all([v > 0 for v in vals[len(pc):]], axis=0)
    return {
        "grid": "41^3 gains over [-2, 2]^3",
        "params": params,
        "hurwitz_disagreement": float(np.mean(hp != hd)),
    }


def _proposition1_row(params: dict[str, float]) -> Erratum:

    p1, p2, p3, lam = sp.symbols("psi1 psi2 psi3 lambda_")
    printed_c = proposition1_conditions(p1, p2, p3, lam, printed=True)
    derived_c = proposition1_conditions(p1, p2, p3, lam, printed=False)
    # impact: verdict disagreement between printed logic on printed Ψ and corrected logic
    # on derived Ψ, on the grid: the two conditions above, evaluated by NumPy on the Ψ of
    # the generated code (the Taylor verdicts of stringstab.certify.criteria, from the same
    # expressions: tests/derive/test_errata.py checks they agree)
    printed_logic, derived_logic = (
        sp.lambdify([p1, p2, p3, lam], c, modules="numpy") for c in (printed_c, derived_c))
    kx, kv, ka = _grid()
    args = (kx, kv, ka, params["tau"], params["delta"], params["headway"])
    psi_p = lambdify_psi("printed")(*args)
    psi_d = lambdify_psi("derived")(*args)
    ok_p = np.asarray(printed_logic(*psi_p))
    ok_d = np.asarray(derived_logic(*psi_d))
    ok_printed_logic_on_derived = np.asarray(printed_logic(*psi_d))
    return Erratum(
        equation="Proposition 1",
        name="Proposition 1 (logic)",
        key="proposition1",
        printed=str(printed_c),
        derived=str(derived_c),
        difference="printed accepts Psi1 < 0 with Lambda <= 0",
        matches=False,
        wrong_terms=["lambda_ <= 0 (without psi1 >= 0 and psi3 >= 0)"],
        explanation=_EXPLANATIONS["proposition1"],
        impact={
            "grid": "41^3 gains over [-2, 2]^3",
            "params": params,
            "verdict_disagreement_printed_vs_derived": float(np.mean(ok_p != ok_d)),
            "verdict_disagreement_logic_only": float(
                np.mean(ok_d != ok_printed_logic_on_derived)
            ),
        },
    )
