"""A small seeded run of the independent check of the multi-rate certificate (analysis/multirate_check.py).

The check simulates the N-periodic link step by step (scipy's expm, the full delay line, the
hold as a state, a random message phase) — impulse responses for the lifted frequency
response and a long simulation at the peak — and never calls the certificate's lifting.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "analysis" / "multirate_check.py"


@pytest.fixture(scope="module")
def mc():
    spec = importlib.util.spec_from_file_location("multirate_check", SCRIPT)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["multirate_check"] = mod  # its dataclasses look their module up
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.slow
def test_a_seeded_run_has_no_unsound_verdict(mc):
    out = mc.run(groups=5, per_group=6, seed=3, verbose=False)
    rows = out.pop("rows")
    assert out["cases"] == 30 and out["unsound_certified"] == 0
    assert out["unsound_not_certified"] == 0
    assert out["certified"] > 0 and out["not_certified"] > 0  # both verdicts are exercised
    ok = rows["stable"] & rows["resolved"]
    # the two truths agree with each other: the simulated gain never exceeds the swept sup
    assert (rows["sim"][ok] <= rows["sup"][ok] * (1 + 1e-6)).all()
    # a not-certified witness is a real violation, of the size the certificate reports
    nc = ok & (rows["verdict"] == "not_certified")
    np.testing.assert_allclose(rows["at_witness"][nc], rows["cert_sup"][nc], rtol=1e-7)
    assert (rows["at_witness"][nc] > 1).all()


@pytest.mark.parametrize("N", [3, 5])
def test_the_message_phase_does_not_change_the_singular_values(mc, N):
    # the lifted responses of two phases differ by a unitary (a block shift): the same σ's
    K = np.array([[1.2, 0.5, 0.6], [0.7, 1.3, 0.2]])
    base = mc.Case(tau=0.1, delta=0.25, headway=1.1, H=0.05, N=N, phase=0)
    G0, _, _ = mc.lifted_truth(base, K)
    th = np.linspace(0.05, np.pi, 50)[None].repeat(2, 0)
    s0 = np.linalg.svd(mc.response(G0, th), compute_uv=False)
    for phase in range(1, N):
        G, _, _ = mc.lifted_truth(mc.Case(0.1, 0.25, 1.1, 0.05, N, phase), K)
        s = np.linalg.svd(mc.response(G, th), compute_uv=False)
        np.testing.assert_allclose(s, s0, rtol=1e-8, atol=1e-10)
