"""`stringstab demo`: output folder checked first, written whole; the library is called once."""

import json

import pytest

import stringstab.cli
import stringstab.tuning
from stringstab.cli import demo_steps as demo
from stringstab.cli import main
from stringstab.io import MANIFEST


def test_out_is_a_file_or_unwritable(tmp_path, capsys, monkeypatch):
    f = tmp_path / "a-file"
    f.write_text("x")
    assert main(["demo", "--out", str(f), "--only", "certify"]) == 2
    _, err = capsys.readouterr()
    assert err.count("\n") == 1 and "demo output folder: expected a folder" in err
    assert f.read_text() == "x"

    import stringstab.io.outputs as outputs

    def deny(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(outputs.tempfile, "mkstemp", deny)  # root ignores chmod: fail the probe
    out = tmp_path / "ro"
    assert main(["demo", "--out", str(out), "--only", "certify"]) == 2
    _, err = capsys.readouterr()
    assert err.count("\n") == 1 and "cannot write in the folder" in err
    assert not out.exists()


def test_failed_step_leaves_the_previous_demo(tmp_path, capsys, monkeypatch):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--only", "certify"]) == 0
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}

    def boom(out, log):
        from stringstab.errors import StringStabError

        raise StringStabError("step failed on purpose")

    monkeypatch.setattr(demo, "STEPS", [("certify", demo._step_certify), ("tune", boom)])
    assert main(["demo", "--out", str(out)]) == 2
    assert "step failed on purpose" in capsys.readouterr().err
    after = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert after == before


def test_rerun_replaces_the_earlier_demo(tmp_path, capsys):
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "--only", "certify"]) == 0
    assert main(["demo", "--out", str(out), "--only", "derive"]) == 0
    assert not (out / "certify").exists()
    summary = json.loads((out / "summary.json").read_text())
    assert list(summary) == ["derive"]
    files = json.loads((out / MANIFEST).read_text())["files"]
    assert sorted(files) == ["derive/derive.json", "derive/derive.tex", "derive/derive.txt",
                             "report.html", "report.md", "summary.json"]


def test_demo_calls_the_library_once_per_triple(tmp_path, monkeypatch):
    def no_cli(*args, **kwargs):
        raise AssertionError("the demo must call the library, not the command line")

    monkeypatch.setattr(stringstab.cli, "main", no_cli)
    calls = {"project": 0, "region_growing": 0}
    for name in calls:
        real = getattr(stringstab.tuning, name)

        def counted(*args, _real=real, _name=name, **kwargs):
            calls[_name] += 1
            return _real(*args, **kwargs)

        monkeypatch.setattr(stringstab.tuning, name, counted)
    summary = demo.run_demo(tmp_path / "demo", log=lambda _: None, only=["certify", "tune"])
    assert calls == {"project": len(demo.TUNE_TRIPLES), "region_growing": len(demo.TUNE_TRIPLES)}
    assert summary["tune"]["summary"]["projection"]["n"] == len(demo.TUNE_TRIPLES)
    rows = json.loads((tmp_path / "demo" / "tune" / "tune.json").read_text())["results"]
    assert len(rows) == 2 * len(demo.TUNE_TRIPLES)
    assert summary["certify"]["rollout"]["n"] == 48


def test_unknown_step_before_any_work(tmp_path):
    with pytest.raises(Exception, match="unknown demo step 'nope'"):
        demo.run_demo(tmp_path / "d", only=["nope"])
    assert not (tmp_path / "d").exists()
