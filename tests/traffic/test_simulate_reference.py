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

import numpy as np
import pytest

from stringstab.traffic import Radio, SensorNoise

ROOT = Path(__file__).resolve().parents[2]
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
    # a message every step, no loss, no staleness; sensors with σ = 0 and no filter
    "radio": {"radio": Radio()},
    "radio+sensors": {"radio": Radio(message_phase=0, loss=0.0, seed=7), "sensors": SensorNoise(seed=3)},
}


def test_the_reference_covers_every_case():
    assert sorted(RECORDED) == sorted(CASES) and len(CASES) == 20


@pytest.mark.parametrize("extra", list(NEUTRAL), ids=list(NEUTRAL))
@pytest.mark.parametrize("name", sorted(CASES))
def test_outputs_are_unchanged_bit_for_bit(name, extra):
    res = CASES[name](**NEUTRAL[extra])
    given = [k for k in ("radio", "sensors") if k in NEUTRAL[extra]]
    for k in given:  # recorded in params; the rest of params is what it was
        assert res.params.pop(k) == NEUTRAL[extra][k].describe()
    got = ref.fingerprint(res)
    want = RECORDED[name]
    diff = [k for k in want if got[k] != want[k]]
    assert diff == [], {k: (got[k], want[k]) for k in diff}
    if "radio" in given:  # every message received, none lost, no fallback
        steps = res.t.size
        np.testing.assert_array_equal(res.radio["messages_received"], steps)
        np.testing.assert_array_equal(res.radio["messages_lost"], 0)
        np.testing.assert_array_equal(res.radio["fallback_time"], 0.0)
    else:
        assert res.radio is None
