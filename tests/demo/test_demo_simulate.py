"""The demo's simulate step: certified gains damp the disturbance, the van Arem CACC does not."""

import json

from stringstab.cli import main


def test_demo_simulate_step(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path), "--only", "simulate"]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())["simulate"]
    cert, cacc = summary["certified"], summary["cacc"]
    assert cert["max_m_p"] < 1.0 and cert["collisions"] == 0 and cert["m_fss"] == 1.0
    assert cacc["max_m_p"] > 1.0 and cacc["m_fss"] == 0.0
    for f in cert["files"] + cacc["files"]:
        assert (tmp_path / "simulate" / f).is_file()
