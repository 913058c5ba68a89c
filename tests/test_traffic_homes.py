"""The split traffic modules: every former public name is still importable where it was.

``traffic/platoon.py``, ``traffic/env.py`` and ``traffic/controllers.py`` were split by job
(issue 20, item 3).  The names they made public stay importable from them, and are the very
objects of their new homes (a re-export, not a copy).
"""

from __future__ import annotations

import importlib

import pytest

#: Old module -> {public name: its new home}.
HOMES = {
    "stringstab.traffic.platoon": {
        "DEFAULT_LENGTH": "limits", "Limits": "limits", "check_leader": "limits",
        "Platoon": "dynamics", "PlatoonResult": "result", "simulate": "platoon",
    },
    "stringstab.traffic.env": {
        "OBSERVE": "state", "SCALES": "state", "GAIN_SCALE": "state", "state_vector": "state",
        "state_dim": "state", "extend_state": "state", "limit_rate": "rate",
        "CarFollowingEnv": "env", "BatchedCarFollowingEnv": "env",
    },
    "stringstab.traffic.controllers": {
        "DEFAULT_STANDSTILL": "controllers.base", "Observation": "controllers.base",
        "Controller": "controllers.base", "linear_law": "controllers.linear",
        "LinearController": "controllers.linear",
        "TimeVaryingLinearController": "controllers.time_varying",
        "CACCController": "controllers.cacc", "IDMController": "controllers.idm",
        "FunctionController": "controllers.function", "MixedController": "controllers.mixed",
    },
}


@pytest.mark.parametrize("old", sorted(HOMES))
def test_former_names_are_re_exported_from_their_homes(old: str) -> None:
    module = importlib.import_module(old)
    assert set(module.__all__) == set(HOMES[old])
    for name, home in HOMES[old].items():
        new = importlib.import_module(f"stringstab.traffic.{home}")
        assert getattr(module, name) is getattr(new, name), (old, name, home)
        assert name in new.__all__, (home, name)
