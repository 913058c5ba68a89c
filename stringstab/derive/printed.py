"""The IDL paper's formulas *as printed*, kept only as a reference to compare against.

These are transcriptions of eqs 11-15 and 25-26 of the IDL paper (text
extracted from the PDF; the garbled ``T^e`` of eqs 25-26 is read as T*).  The
toolkit never uses them for a verdict of its own; :mod:`stringstab.derive.errata`
compares them with the forms derived in :mod:`stringstab.derive.symbolic`, and the
``printed`` method of the criteria reproduces the paper's Proposition 1 as a
user of the paper would apply it.

References
----------
IDL paper, eqs 11-15 (§3.2.1) and eqs 25-26 (§3.3).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from .symbolic import delta, headway, k_a, k_v, k_x, s, tau

__all__ = ["PRINTED", "PrintedEquation", "printed_gradients", "printed_psi"]


@dataclass(frozen=True)
class PrintedEquation:
    """One printed formula: its equation number, its name and the expression."""

    equation: str
    name: str
    expr: sp.Expr
    latex_as_printed: str


_psi1 = tau**2 + k_v * k_a * delta**3 / 3
_psi2 = 1 - 2 * tau * (k_x + k_v * headway) + k_a * (-2 * k_v * delta + k_x * delta**2 - k_a)
_psi3 = k_x * (k_x * headway**2 + 2 * k_v * headway + 2 * k_a - 2)
_lam = _psi2**2 - 4 * _psi1 * _psi3
_gamma_num = k_x + k_v * s + k_a * s**2 * sp.exp(-delta * s)
_gamma_den = tau * s**3 + s**2 + (tau * k_x + k_v) * s + k_x

#: The printed formulas, keyed by the names used in ``stringstab derive``.
PRINTED: dict[str, PrintedEquation] = {
    "gamma_numerator": PrintedEquation(
        "11", "numerator of Γ(s)", _gamma_num, r"k_{x,i} + k_{v,i}s + k_{a,i}s^2 e^{-\delta s}"
    ),
    "gamma_denominator": PrintedEquation(
        "11",
        "denominator of Γ(s)",
        _gamma_den,
        r"\tau_i s^3 + s^2 + (\tau_i k_{x,i} + k_{v,i})s + k_{x,i}",
    ),
    "psi1": PrintedEquation("12", "Ψ1", _psi1, r"\tau_i^2 + \frac{k_{v,i}k_{a,i}\delta^3}{3}"),
    "psi2": PrintedEquation(
        "13",
        "Ψ2",
        _psi2,
        r"1 - 2\tau_i(k_{x,i} + k_{v,i}T^*) + k_{a,i}(-2k_{v,i}\delta + k_{x,i}\delta^2 - k_{a,i})",
    ),
    "psi3": PrintedEquation(
        "14", "Ψ3", _psi3, r"k_{x,i}(k_{x,i}T^{*2} + 2k_{v,i}T^* + 2k_{a,i} - 2)"
    ),
    "lambda": PrintedEquation("15", "Λ = Ψ2² − 4Ψ1Ψ3", _lam, r"\Psi_2^2 - 4\Psi_1\Psi_3"),
    "grad_psi2": PrintedEquation(
        "25",
        "∇_K Ψ2",
        sp.Matrix([1 - 2 * tau + k_a * delta**2, -2 * tau * headway - 2 * k_a * delta,
                   k_x * delta**2 - 2 * k_v * delta - 2 * k_a]),
        r"(1 - 2\tau_i + k_{a,i}\delta^2,\; -2\tau_i T^* - 2k_{a,i}\delta,\; "
        r"k_{x,i}\delta^2 - 2k_{v,i}\delta - 2k_{a,i})",
    ),
    "grad_psi3": PrintedEquation(
        "26",
        "∇_K Ψ3",
        sp.Matrix([2 * k_x * headway**2 + 2 * k_v * headway + 2 * k_a - 2, 2 * k_x * headway,
                   2 * k_x]),
        r"(2k_{x,i}T^{*2} + 2k_{v,i}T^* + 2k_{a,i} - 2,\; 2k_{x,i}T^*,\; 2k_{x,i})",
    ),
}


def printed_psi() -> tuple[sp.Expr, sp.Expr, sp.Expr, sp.Expr]:
    """(Ψ1, Ψ2, Ψ3, Λ) exactly as printed in IDL eqs 12-15.

    Returns
    -------
    tuple of sympy.Expr
        (Ψ1, Ψ2, Ψ3, Λ) as printed.

    Examples
    --------
    >>> printed_psi()[0]
    delta**3*k_a*k_v/3 + tau**2
    """
    return _psi1, sp.expand(_psi2), sp.expand(_psi3), sp.expand(_lam)


def printed_gradients() -> dict[str, list[sp.Expr]]:
    """∇_K Ψ2 and ∇_K Ψ3 exactly as printed in IDL eqs 25-26.

    Returns
    -------
    dict of str to list of sympy.Expr
        ``grad_psi2`` and ``grad_psi3``: ∂/∂k_x, ∂/∂k_v, ∂/∂k_a as printed.
    """
    return {
        "grad_psi2": list(PRINTED["grad_psi2"].expr),
        "grad_psi3": list(PRINTED["grad_psi3"].expr),
    }
