"""The IDL training environment's outputs are bit for bit those of the base commit (issue 31).

``tests/data/env_f6db69e.npz`` was written by ``analysis/env_reference.py`` with PYTHONPATH on
commit f6db69e of ``main`` (before issue 31's speed work): 400 seeded steps of random gains,
collisions and episode restarts included, with one and with three sub-environments.  Today's
environment, on the same actions, must give the same arrays to the last bit.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

REF = np.load(Path(__file__).parents[1] / "data" / "env_f6db69e.npz")
_spec = importlib.util.spec_from_file_location(
    "env_reference", Path(__file__).parents[2] / "analysis" / "env_reference.py")
assert _spec is not None and _spec.loader is not None
env_reference = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(env_reference)


@pytest.mark.parametrize("num_envs", [1, 3])
def test_env_outputs_are_those_of_the_base_commit(num_envs):
    """States, rewards, ends and every info array equal the recorded ones (NaN where NaN)."""
    now = env_reference.rollout(num_envs, 400)
    keys = sorted(k[len(f"n{num_envs}_"):] for k in REF.files if k.startswith(f"n{num_envs}_"))
    assert sorted(now) == keys
    assert REF[f"n{num_envs}_terminated"].any()  # the rollout does cover episode restarts
    for k in keys:
        ref = REF[f"n{num_envs}_{k}"]
        assert now[k].dtype == ref.dtype, k
        assert now[k].tobytes() == ref.tobytes(), k
