"""The errata report: which printed formulas differ, and by exactly what."""

import sympy as sp

from stringstab.derive import symbolic as S
from stringstab.derive.errata import errata


def _rows():
    return {e.key: e for e in errata()}


def test_matching_equations():
    rows = _rows()
    for key in ("gamma_numerator", "psi3", "grad_psi3"):
        assert rows[key].matches, key
        assert rows[key].wrong_terms == []


def test_gamma_denominator_tau_for_headway():
    d = sp.sympify(_rows()["gamma_denominator"].difference, locals=dict(
        tau=S.tau, headway=S.headway, k_x=S.k_x, s=S.s))
    assert sp.expand(d - (S.tau - S.headway) * S.k_x * S.s) == 0


def test_psi2_difference_is_swap_and_sign():
    d = sp.sympify(_rows()["psi2"].difference, locals={str(x): x for x in (*S.GAINS, *S.PARAMS)})
    expect = (-2 * S.tau * (S.k_x + S.k_v * S.headway) + S.k_a * S.k_x * S.delta**2) - (
        -2 * S.tau * (S.k_v + S.k_x * S.headway) - S.k_a * S.k_x * S.delta**2
    )
    assert sp.expand(d - expect) == 0


def test_grad_psi2_has_spurious_one():
    row = _rows()["grad_psi2"]
    assert not row.matches
    assert row.wrong_terms[0].startswith("component 1 (k_x)")
    assert "+ 1" in row.wrong_terms[0]


def test_impacts_are_measured_shares():
    rows = _rows()
    for key in ("psi1", "psi2", "lambda"):
        share = rows[key].impact["sign_disagreement"]
        assert 0 < share < 1
    assert 0 < rows["gamma_denominator"].impact["hurwitz_disagreement"] < 1
    assert rows["proposition1"].impact["verdict_disagreement_printed_vs_derived"] > 0


def test_proposition1_impact_agrees_with_the_taylor_verdicts_of_certify():
    # derive computes the Proposition 1 row's impact from its own SymPy conditions on the
    # generated Ψ (derive does not import certify); the Taylor verdicts of
    # stringstab.certify.criteria (hand-written NumPy logic) must give the same shares
    import numpy as np

    from stringstab.certify.criteria import proposition1, taylor_criteria

    params = {"tau": 0.1, "delta": 0.4, "headway": 0.5}
    impact = {e.key: e for e in errata(**params)}["proposition1"].impact
    g = np.linspace(-2.0, 2.0, 41)
    kx, kv, ka = (a.ravel() for a in np.meshgrid(g, g, g, indexing="ij"))
    ok_p = taylor_criteria(kx, kv, ka, source="printed", **params).stable
    d = taylor_criteria(kx, kv, ka, source="derived", **params)
    logic_only = proposition1(d.psi1, d.psi2, d.psi3, d.lam, source="printed")
    assert impact["verdict_disagreement_printed_vs_derived"] == float(np.mean(ok_p != d.stable))
    assert impact["verdict_disagreement_logic_only"] == float(np.mean(d.stable != logic_only))
    # the check can fail: at these parameters the verdicts differ on part of the grid (both
    # shares are neither 0 nor 1, so a wrong logic or a wrong Ψ would change them)
    assert 0 < impact["verdict_disagreement_logic_only"] < impact["verdict_disagreement_printed_vs_derived"] < 1
