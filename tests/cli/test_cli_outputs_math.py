"""Output paths of derive, region and tune: checked before any work, one line, exit 2, nothing
written; a region run into an existing folder replaces its own files, never leaves a mix."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from stringstab.cli import main
from stringstab.io import MANIFEST, outputs

REGION = ["region", "--fix", "k_a=0.5", "--n", "7", "--method", "taylor", "--dpi", "30"]


def _one_line_error(capsys, command: str, match: str) -> None:
    cap = capsys.readouterr()
    assert cap.out == ""
    assert cap.err.startswith(f"stringstab {command}: error:") and cap.err.count("\n") == 1
    assert match in cap.err


def _files(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


@pytest.mark.parametrize("command", [["derive"], ["tune", "0.9,-0.5,1.1"]])
def test_out_in_a_missing_folder(tmp_path, capsys, command):
    """One rule for files and folders (issue 29): the missing folders are created on success."""
    target = tmp_path / "missing" / "x.txt"
    assert main([*command, "--out", str(target)]) in (0, 1)
    assert target.is_file() and _files(tmp_path / "missing") == ["x.txt"]


@pytest.mark.parametrize("command", [["derive"], ["tune", "0.9,-0.5,1.1"]])
def test_out_is_a_folder(tmp_path, capsys, command):
    assert main([*command, "--out", str(tmp_path)]) == 2
    _one_line_error(capsys, command[0], "is a folder")
    assert _files(tmp_path) == []


@pytest.mark.parametrize("command", [["derive"], ["tune", "0.9,-0.5,1.1"], REGION])
def test_read_only_output_folder(tmp_path, capsys, monkeypatch, command):
    # tests run as root, which ignores folder permissions: deny the writability probe instead
    def deny(*args: object, **kwargs: object) -> None:
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(outputs.tempfile, "mkstemp", deny)
    target = tmp_path / ("maps" if command is REGION else "x.txt")
    assert main([*command, "--out", str(target)]) == 2
    _one_line_error(capsys, command[0], "Permission denied")
    assert _files(tmp_path) == []


def test_derive_writes_its_file(tmp_path, capsys):
    target = tmp_path / "d.json"
    assert main(["derive", "--format", "json", "--out", str(target)]) == 0
    assert "wrote json" in capsys.readouterr().err
    assert "psi1" in json.loads(target.read_text(encoding="utf-8"))
    assert _files(tmp_path) == ["d.json"]  # no temporary file left


@pytest.mark.slow  # ~9.8 s with -n 2 on 2 shared cores (CI runs it)
def test_region_rerun_replaces_its_own_files(tmp_path, capsys):
    out = tmp_path / "maps"
    assert main([*REGION, "--format", "png,pdf", "--out", str(out)]) == 0
    first = _files(out)
    assert "region_class_taylor.pdf" in first and MANIFEST in first
    (out / "notes.txt").write_text("mine")  # not written by the toolkit: kept
    assert main([*REGION, "--format", "png", "--prefix", "run2", "--out", str(out)]) == 0
    second = _files(out)
    assert not any(n.startswith("region") for n in second)  # the earlier run's files are gone
    assert {"run2.npz", "run2.csv", "run2_class_taylor.png", "notes.txt"} <= set(second)
    assert json.loads((out / MANIFEST).read_text())["command"] == "region"
    capsys.readouterr()


def test_region_refuses_another_commands_folder(tmp_path, capsys):
    out = tmp_path / "maps"
    out.mkdir()
    (out / MANIFEST).write_text(json.dumps({"command": "simulate", "files": ["a.csv"]}))
    (out / "a.csv").write_text("x")
    assert main([*REGION, "--out", str(out)]) == 2
    _one_line_error(capsys, "region", "holds the outputs of 'stringstab simulate'")
    assert _files(out) == sorted([MANIFEST, "a.csv"])


def test_region_bad_input_after_an_earlier_run_leaves_it_untouched(tmp_path, capsys):
    out = tmp_path / "maps"
    assert main([*REGION, "--format", "png", "--out", str(out)]) == 0
    before = {n: (out / n).read_bytes() for n in _files(out)}
    capsys.readouterr()
    assert main([*REGION, "--format", "gif", "--out", str(out)]) == 2
    _one_line_error(capsys, "region", "--format")
    assert {n: (out / n).read_bytes() for n in _files(out)} == before


def test_region_prints_units(tmp_path, capsys):
    assert main([*REGION, "--format", "png", "--out", str(tmp_path / "m")]) == 0
    text = capsys.readouterr().out
    assert "τ = 0.1 s, δ = 0.2 s, T* = 1.1 s" in text and "%" in text


def _fails() -> None:
    raise ValueError("the figure could not be drawn")


def _writes(path: str) -> None:
    Path(path).write_text("drawn")


def test_background_process_reports_its_failure(tmp_path):
    from stringstab.errors import StringStabError
    from stringstab.parallel import in_background

    join = in_background(_writes, str(tmp_path / "f.txt"))
    join()
    assert (tmp_path / "f.txt").read_text() == "drawn"
    join = in_background(_fails)
    with pytest.raises(StringStabError, match="ValueError: the figure could not be drawn"):
        join()


@pytest.mark.parametrize("processes", [1, 2])
def test_region_outputs_shared_by_two_processes_equal_one(tmp_path, processes):
    import numpy as np

    from stringstab.plots import save_region_outputs
    from stringstab.regions import load_npz, region_map

    g = np.linspace(-2, 2, 23)
    m = region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1)
    written = save_region_outputs(m, tmp_path, formats=("png",), dpi=20, processes=processes)
    assert [p.name for p in written] == ["region.npz", "region.csv", "region_class_exact.png",
                                         "region_compare.png", "region_sup_gain.png"]
    assert all(p.is_file() and p.stat().st_size > 0 for p in written)
    assert (tmp_path / "region.csv").read_text(encoding="utf-8") == m.csv_text()
    assert (load_npz(tmp_path / "region.npz").verdict["exact"] == m.verdict["exact"]).all()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in written)
    every = tmp_path / "all"  # figures="all": every method's class map as well
    every.mkdir()
    names = [p.name for p in save_region_outputs(m, every, formats=("png",), dpi=20,
                                                 processes=processes, figures="all")]
    assert names == ["region.npz", "region.csv", "region_class_exact.png", "region_class_taylor.png",
                     "region_class_printed.png", "region_compare.png", "region_sup_gain.png"]
    assert sorted(p.name for p in every.iterdir()) == sorted(names)
