"""OutputDir extensions: folders filled by other writers, and fixed-name outputs without a manifest."""

from pathlib import Path

import pytest

from stringstab.errors import StringStabError
from stringstab.io import MANIFEST, OutputDir


def test_folder_adopts_everything_written_in_it(tmp_path: Path) -> None:
    run = tmp_path / "run"
    with OutputDir(run, command="demo") as out:
        step = out.folder("step")
        (step / "a.txt").write_text("a")
        (step / "sub").mkdir()
        (step / "sub" / "b.txt").write_text("b")
        out.write_text("summary.json", "{}")
    names = sorted(str(p.relative_to(run)) for p in run.rglob("*") if p.is_file())
    assert names == [MANIFEST, "step/a.txt", "step/sub/b.txt", "summary.json"]
    with OutputDir(run, command="demo") as out:
        out.write_text("summary.json", "{}")
    assert sorted(p.name for p in run.iterdir()) == [MANIFEST, "summary.json"]  # emptied folders go


def test_owned_names_replace_an_earlier_run_without_a_manifest(tmp_path: Path) -> None:
    run = tmp_path / "run"
    owns = ("a.npz", "a.csv", "fig.png")
    with OutputDir(run, command="simulate", owns=owns) as out:
        out.write_text("a.npz", "1")
        out.write_text("fig.png", "1")
    (run / "mine.txt").write_text("kept")
    with OutputDir(run, command="simulate", owns=owns) as out:
        out.write_text("a.csv", "2")
    assert sorted(p.name for p in run.iterdir()) == [MANIFEST, "a.csv", "mine.txt"]
    with pytest.raises(RuntimeError), OutputDir(run, command="simulate", owns=owns) as out:
        out.write_text("a.npz", "3")
        raise RuntimeError("failed run")
    assert sorted(p.name for p in run.iterdir()) == [MANIFEST, "a.csv", "mine.txt"]
    (run / MANIFEST).write_text('{"command": "region", "files": []}')
    with pytest.raises(StringStabError, match="holds the outputs of 'stringstab region'"):
        OutputDir(run, command="simulate", owns=owns)
