"""A small seeded run of the independent check of the θ_r certificate (``analysis/reaction_check.py``).

The full run (≥ 100,000 cases) is the analysis script's; here a few hundred cases of every kind
(random, on the stability boundary, on Ψ3 = 0, on |Γ| = 1 by bisection) go through the same
code: a pseudospectral discretisation of the DDE's generator (Breda et al.) and a Padé(12, 12)
root count for stability, a dense exact-delay sweep for sup|Γ|.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "analysis" / "reaction_check.py"


@pytest.fixture(scope="module")
def summary():
    spec = importlib.util.spec_from_file_location("reaction_check", SCRIPT)
    assert spec and spec.loader
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.run(400, seed=2025)


def test_no_unsound_verdict(summary):
    assert summary["unsound"] == {k: 0 for k in summary["unsound"]}
    assert summary["verdicts"]["certified"] >= 20  # certified rows were checked


def test_root_counts_agree_with_both_independent_checks(summary):
    assert summary["spectral_unresolved"] == 0
    assert summary["root_count_vs_spectral_mismatch"] == 0
    assert summary["root_count_vs_pade12_mismatch"] == 0


def test_inconclusive_only_near_a_boundary(summary):
    assert summary["inconclusive_share"] < 0.05
    assert summary["inconclusive_far_from_boundary"] == 0


def test_the_rightmost_root_estimate(summary):
    assert summary["hurwitz_margin_sign_vs_hurwitz_disagree"] == 0
    assert summary["hurwitz_margin_vs_spectral_share_within_1e-6"] > 0.99
