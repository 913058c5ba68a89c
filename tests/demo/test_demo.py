"""The main job runs and writes what it says."""

import json

from stringstab.cli import main


def test_demo_derive_step(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path), "--only", "derive"]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert "eq 13 (Ψ2)" in summary["derive"]["errata"]  # named for a reader, not by its key
    assert "Proposition 1 (logic)" in summary["derive"]["errata"]
    doc = json.loads((tmp_path / "derive" / "derive.json").read_text())
    assert "psi1" in doc


def test_demo_unknown_step(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path), "--only", "nope"]) == 2
