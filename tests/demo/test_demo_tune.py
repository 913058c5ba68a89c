"""The demo's tune step: both repair methods on a handful of uncertified triples."""

import json

from stringstab.certify.api import certify
from stringstab.cli import main


def test_demo_tune_step(tmp_path, capsys):
    assert main(["demo", "--out", str(tmp_path), "--only", "tune"]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())["tune"]
    for f in summary["files"]:
        assert (tmp_path / "tune" / f).is_file()
    assert summary["summary"]["projection"]["certified"] == summary["summary"]["projection"]["n"]
    rows = json.loads((tmp_path / "tune" / "tune.json").read_text())["results"]
    for r in rows:
        assert r["certified"] == certify(r["k_x"], r["k_v"], r["k_a"], tau=0.1, delta=0.2,
                                         headway=1.1).certified
