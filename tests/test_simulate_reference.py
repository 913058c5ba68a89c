"""Without θ_r and without the radio the simulator is what it was, bit for bit (issues 25, 26).

``analysis/simulate_reference.py`` recorded, at commit bb1b890 (before either existed), the
SHA-256 of every array of 20 runs that exercise every branch of the simulator (lag and
kinematic models, integer, interpolated and exact fractional delays, trapezoid positions,
heterogeneous lags and gains, limits, a collision, every controller, batches, ``record=False``)
with their params and metrics.  The same runs today, with no new option and with the new
options at their neutral values, must give the same bytes.
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = ROOT / "analysis" / "simulate_reference.py"
_spec = importlib.util.spec_from_file_location("simulate_reference", SCRIPT)
assert _spec is not None and _spec.loader is not None
ref = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ref)

RECORDED = json.loads(ref.OUT.read_text(encoding="utf-8"))["runs"]
CASES = ref.cases()

NEUTRAL = {
    "none": {},
    "reaction_delay=0": {"reaction_delay": 0.0},
}


def test_the_reference_covers_every_case():
    assert sorted(RECORDED) == sorted(CASES) and len(CASES) == 20


@pytest.mark.parametrize("extra", list(NEUTRAL), ids=list(NEUTRAL))
@pytest.mark.parametrize("name", sorted(CASES))
def test_outputs_are_unchanged_bit_for_bit(name, extra):
    got = ref.fingerprint(CASES[name](**NEUTRAL[extra]))
    want = RECORDED[name]
    diff = [k for k in want if got[k] != want[k]]
    assert diff == [], {k: (got[k], want[k]) for k in diff}
