"""The demo's training step: a tiny budget, every executed gain re-certified independently."""

from __future__ import annotations

import csv

import numpy as np
import pytest

pytest.importorskip("torch")
pytest.importorskip("safetensors")

pytestmark = pytest.mark.torch


@pytest.mark.slow  # ~13.5 s with -n 2 on 2 shared cores (CI runs it)
def test_demo_train_step(tmp_path):
    from stringstab.certify.api import check
    from stringstab.cli import demo_steps as demo

    lines: list[str] = []
    out = tmp_path / "train"
    out.mkdir()
    s = demo._step_train(out, lines.append, steps=400, episodes=6, platoon=0)
    assert s["steps"] == 400
    assert s["idl"]["m_fss"] == 1.0 and s["idl"]["m_fss_sampled"] == 1.0
    assert s["passed"] == (s["idl"]["collisions"] == 0)
    for f in ("run/policy.json", "run/rolling_reward.png", "evaluation/gains.csv",
              "evaluation/evaluation.md", "comparison/table.md", "comparison/gains_region.png"):
        assert (out / f).is_file(), f
    with (out / "evaluation" / "gains.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == s["idl"]["n_gains"] == 6 * 301  # 6 episodes of 30 s at 0.1 s, ends included
    K = np.unique(np.array([[float(r[k]) for k in ("k_x", "k_v", "k_a")] for r in rows]), axis=0)
    # an independent look at the written gains: the exact certificate on every distinct triple
    assert (check(K[:, 0], K[:, 1], K[:, 2], tau=0.1, delta=0.2, headway=1.1).verdict
            == "certified").all()
    assert any("m_fss = 1 of" in line for line in lines)
    assert "train" in [name for name, _ in demo.STEPS]
