"""The I/O home: output checks before work, atomic files, all-or-nothing output folders."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from stringstab.errors import StringStabError, show
from stringstab.io import (
    MANIFEST,
    OutputDir,
    atomic_path,
    atomic_write_text,
    check_output_dir,
    check_output_file,
    dumps_json,
    to_plain,
)

ROOT = os.geteuid() == 0 if hasattr(os, "geteuid") else False


def test_check_output_file_cases(tmp_path: Path) -> None:
    assert check_output_file(tmp_path / "x.json") == tmp_path / "x.json"
    # one rule with output folders (issue 29): missing folders are created when written
    assert check_output_file(tmp_path / "missing" / "x.json") == tmp_path / "missing" / "x.json"
    assert not (tmp_path / "missing").exists()  # nothing created by the check
    with pytest.raises(StringStabError, match=r"expected a file; .* is a folder"):
        check_output_file(tmp_path)
    f = tmp_path / "file"
    f.write_text("x")
    with pytest.raises(StringStabError, match="is a file, not a folder"):
        check_output_file(f / "x.json")
    with pytest.raises(StringStabError, match=r"'.*file' in .* is a file, not a folder"):
        check_output_file(f / "y" / "z.json")
    with pytest.raises(StringStabError, match="expected a file name"):
        check_output_file("")


def test_atomic_write_creates_missing_folders_and_removes_them_on_failure(tmp_path: Path) -> None:
    from stringstab.io import atomic_path

    target = tmp_path / "a" / "b" / "x.txt"
    atomic_write_text(target, "ok")
    assert target.read_text() == "ok"
    other = tmp_path / "c" / "d" / "y.txt"
    with pytest.raises(RuntimeError), atomic_path(other) as tmp:
        tmp.write_text("half")
        raise RuntimeError("the writer failed")
    assert not (tmp_path / "c").exists()  # the folders it created are gone with the file


def test_check_output_dir_cases(tmp_path: Path) -> None:
    assert check_output_dir(tmp_path / "a" / "b") == tmp_path / "a" / "b"
    assert not (tmp_path / "a").exists()  # nothing created by the check
    f = tmp_path / "file"
    f.write_text("x")
    with pytest.raises(StringStabError, match=r"expected a folder; .* is a file"):
        check_output_dir(f)
    with pytest.raises(StringStabError, match="is a file, not a folder"):
        check_output_dir(f / "sub")


def test_unwritable_folder_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    # The probe really creates a file; as root chmod cannot deny it, so fail the probe instead.
    import stringstab.io.outputs as outputs

    def deny(*args: object, **kwargs: object) -> None:
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(outputs.tempfile, "mkstemp", deny)
    with pytest.raises(StringStabError, match=r"cannot write in the folder .*Permission denied"):
        check_output_file(tmp_path / "x.txt")
    with pytest.raises(StringStabError, match=r"cannot write in the folder .*Permission denied"):
        OutputDir(tmp_path / "run", command="demo")


@pytest.mark.skipif(ROOT, reason="root ignores folder permissions")
def test_readonly_folder_really_refused(tmp_path: Path) -> None:  # pragma: no cover - non-root
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        with pytest.raises(StringStabError, match="cannot write in the folder"):
            check_output_file(ro / "x.txt")
    finally:
        ro.chmod(0o755)


def test_atomic_path_leaves_target_untouched_on_error(tmp_path: Path) -> None:
    target = tmp_path / "a.npz"
    atomic_write_text(target, "old")
    with pytest.raises(RuntimeError), atomic_path(target) as tmp:
        tmp.write_text("half")
        raise RuntimeError("boom")
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.npz"]
    with atomic_path(target) as tmp:
        np.savez(tmp, x=np.arange(2))  # keeps the .npz suffix: savez adds none
    assert np.load(target)["x"].tolist() == [0, 1]


def test_output_dir_replaces_own_files_only(tmp_path: Path) -> None:
    run = tmp_path / "run"
    run.mkdir()
    (run / "notes.txt").write_text("mine")  # a file the toolkit did not write
    with OutputDir(run, command="region") as out:
        out.write_text("a.png", "1")
        out.write_text("sub/b.csv", "1")
    assert (run / "sub" / "b.csv").read_text() == "1"
    with OutputDir(run, command="region") as out:
        out.write_text("a.png", "2")
    names = sorted(str(p.relative_to(run)) for p in run.rglob("*") if p.is_file())
    assert names == [MANIFEST, "a.png", "notes.txt"]
    assert (run / "a.png").read_text() == "2"
    assert json.loads((run / MANIFEST).read_text())["files"] == ["a.png"]


def test_output_dir_failed_run_leaves_previous_outputs(tmp_path: Path) -> None:
    run = tmp_path / "run"
    with OutputDir(run, command="simulate") as out:
        out.write_text("metrics.json", "{}")
    with pytest.raises(ValueError, match="boom"), OutputDir(run, command="simulate") as out:
        out.write_text("metrics.json", "half")
        raise ValueError("boom")
    assert (run / "metrics.json").read_text() == "{}"
    assert sorted(p.name for p in run.iterdir()) == [MANIFEST, "metrics.json"]


def test_output_dir_refuses_other_commands_folder(tmp_path: Path) -> None:
    with OutputDir(tmp_path / "run", command="simulate") as out:
        out.write_text("x.txt", "1")
    with pytest.raises(StringStabError, match="holds the outputs of 'stringstab simulate'"):
        OutputDir(tmp_path / "run", command="region")


def test_output_dir_rejects_escaping_names(tmp_path: Path) -> None:
    with OutputDir(tmp_path / "run", command="x") as out:
        for bad in ("../x", "/etc/x", MANIFEST):
            with pytest.raises(ValueError, match="relative paths inside the folder"):
                out.path(bad)


def test_plain_and_json() -> None:
    doc = {"a": np.float32(0.5), "b": np.arange(2), "c": float("inf"), "d": (np.bool_(True),)}
    assert to_plain(doc) == {"a": 0.5, "b": [0, 1], "c": None, "d": [True]}
    assert json.loads(dumps_json(doc)) == to_plain(doc)
    assert show(np.float64(-0.25)) == "-0.25"
    assert show((np.int64(3),)) == "(3,)"
