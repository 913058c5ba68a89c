"""The sweep's table and reports from records (written here by hand: no training needed)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from stringstab.io import atomic_write_text, dumps_json
from stringstab.sweep import parse_spec, sweep_table, write_outputs
from stringstab.sweep.records import POINT_FORMAT, record_path


def _write(root: Path, spec, metrics_of) -> None:  # type: ignore[no-untyped-def]
    (root / "points").mkdir(parents=True, exist_ok=True)
    for p in spec.points:
        m = metrics_of(p)
        rec = {"format": POINT_FORMAT, "id": p.id, "kind": p.kind, "label": p.label,
               "varied": p.varied, "status": "failed" if m is None else "done",
               "metrics": m or {}, "artefacts": {}, "seconds": 1.0, "worker": "w", "pid": 1,
               "error": "boom" if m is None else None}
        atomic_write_text(record_path(root, p.id), dumps_json(rec))


def test_table5_report_means_and_paper(tmp_path: Path) -> None:
    spec = parse_spec("""
[sweep]
kind = "train"
study = "table5"
seeds = [0, 1, 2]
[base]
total_steps = 10
[zip]
label = ["Full reward", "- Safety"]
weights = [[0.3333333333333333, 0.3333333333333333, 0.3333333333333333], [0.0, 0.5, 0.5]]
""")
    rng = np.random.default_rng(0)
    vals = {p.id: rng.uniform(0.1, 2.0, 5) for p in spec.points}
    failed = spec.points[-1].id  # one failed point: left out of the means

    def metrics(p):  # type: ignore[no-untyped-def]
        if p.id == failed:
            return None
        v = vals[p.id]
        return {"TIT": v[0], "M_CI": v[1], "M_effi": v[2], "M_lss": v[3], "collisions": int(10 * v[4])}

    _write(tmp_path, spec, metrics)
    files = write_outputs(spec, tmp_path)
    assert "report/table5.md" in files
    rows = list(csv.DictReader((tmp_path / "report" / "table5.csv").open()))
    assert [r["setting"] for r in rows] == ["Full reward", "Full reward", "- Safety", "- Safety"]
    for label, r in (("Full reward", rows[0]), ("- Safety", rows[2])):
        ids = [p.id for p in spec.points if p.label == label and p.id != failed]
        assert int(r["n"]) == len(ids)
        expect = np.array([vals[i][1] for i in ids])
        assert float(r["M_CI"]) == pytest.approx(expect.mean(), rel=1e-12)
        assert float(r["M_CI_sd"]) == pytest.approx(expect.std(ddof=1), rel=1e-12)
    assert rows[3]["source"] == "paper" and rows[3]["TIT"] == "inf" and rows[3]["collisions"] == "2"
    table = sweep_table(spec, tmp_path)
    assert [r["status"] for r in table].count("failed") == 1
    assert table[-1]["error"] == "boom"


def test_fig5_and_fig4_reports(tmp_path: Path) -> None:
    spec = parse_spec("""
[sweep]
kind = "train"
study = "fig5"
[base]
total_steps = 10
[axes]
algo = ["idl", "td3"]
exploration_noise = [0.1, 0.2, 0.3]
""")
    # TD3 best at 0.3 on every metric, IDL best at 0.1; TD3 at 0.2 collides (never best)
    def metrics(p):  # type: ignore[no-untyped-def]
        s = p.varied["exploration_noise"]
        v = s if p.varied["algo"] == "idl" else 1 - s
        crashed = p.varied["algo"] == "td3" and p.varied["exploration_noise"] == 0.2
        return {**dict.fromkeys(("TIT", "M_CI", "M_effi", "M_lss"), v), "collisions": int(crashed)}

    _write(tmp_path / "f5", spec, metrics)
    files = write_outputs(spec, tmp_path / "f5")
    assert "report/fig5_noise.png" in files
    md = (tmp_path / "f5" / "report" / "fig5.md").read_text()
    assert "idl: lowest mean rank over the four metrics (without collisions) at σ = 0.1 (the paper: σ = 0.15)" in md
    assert "td3: lowest mean rank over the four metrics (without collisions) at σ = 0.3 (the paper: σ = 0.25)" in md

    spec4 = parse_spec("""
[sweep]
kind = "train"
study = "fig4"
[base]
total_steps = 10
[zip]
label = ["small", "medium"]
hidden = [[64, 64], [128, 128]]
""")
    root = tmp_path / "f4"
    _write(root, spec4, lambda p: {"final_rolling_return": -1.0, "TIT": 0.1, "M_CI": 0.2,
                                   "M_effi": 1.0, "M_lss": 0.8})
    for p in spec4.points:
        log = root / "points" / p.id / "run" / "train_log.csv"
        log.parent.mkdir(parents=True)
        log.write_text("episode,step,rolling_return\n0,100,-3\n1,200,-2\n")
    files = write_outputs(spec4, root)
    assert "report/fig4_architectures.png" in files
    assert "| [64, 64] | 1 | -1.000 |" in (root / "report" / "fig4.md").read_text()
    rec = json.loads(record_path(root, spec4.points[0].id).read_text())
    assert rec["status"] == "done"


def test_sweep_run_report(tmp_path: Path) -> None:
    """report.md/report.html in the sweep folder: the results table, the failures, the study's
    table and its figure embedded as a data: URI (nothing loaded from the network)."""
    import base64
    import re

    from stringstab.report.commands import sweep_report

    spec = parse_spec("""
[sweep]
kind = "train"
study = "fig5"
[base]
total_steps = 10
[axes]
algo = ["idl", "td3"]
exploration_noise = [0.1, 0.2]
""")
    root = tmp_path / "s"
    _write(root, spec, lambda p: None if p.varied["exploration_noise"] == 0.2 and p.varied["algo"] == "td3"
           else dict.fromkeys(("TIT", "M_CI", "M_effi", "M_lss"), p.varied["exploration_noise"]))
    files = write_outputs(spec, root)
    assert sweep_report(spec, sweep_table(spec, root), files, root,
                        command="stringstab sweep s.toml --out s").write(root) == ["report.md", "report.html"]
    md = (root / "report.md").read_text(encoding="utf-8")
    assert "every point finished" in md and "3 done, 1 failed" in md and "boom" in md
    assert "](report/fig5_noise.png)" in md and "lowest mean rank" in md
    html = (root / "report.html").read_text(encoding="utf-8")
    srcs = re.findall(r'<img\b[^>]*\bsrc="([^"]+)"', html)
    assert len(srcs) == 1 and srcs[0].startswith("data:image/png;base64,")
    assert base64.b64decode(srcs[0].split(",", 1)[1]) == (root / "report" / "fig5_noise.png").read_bytes()
    assert not re.search(r'(?:src|href)="https?://', html)
