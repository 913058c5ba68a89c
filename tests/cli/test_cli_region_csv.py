"""The CSV of a region map (issue 31): written by default for a map of at most
``CSV_MAX_POINTS`` points, above it only when asked (``csv=True``, ``--csv``); ``--no-csv``
never.  The threshold is lowered here (monkeypatch), so no big map is computed."""

from __future__ import annotations

import numpy as np
import pytest

from stringstab.cli import main
from stringstab.errors import StringStabError
from stringstab.plots import outputs, save_region_outputs, writes_csv
from stringstab.regions import load_npz, region_map

REGION = ["region", "--fix", "k_a=0.5", "--n", "7", "--method", "taylor", "--dpi", "20",
          "--no-progress"]


@pytest.fixture(scope="module")
def small_map():
    g = np.linspace(-2, 2, 7)  # 49 points
    return region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1,
                      methods="taylor", workers=1, progress=False)


def _names(m, folder, **kw):
    folder.mkdir()
    names = [p.name for p in save_region_outputs(m, folder, formats=("png",), dpi=20,
                                                 processes=1, **kw)]
    assert sorted(p.name for p in folder.iterdir()) == sorted(names)  # what it says it wrote
    return names


def test_the_size_rule_of_the_library(tmp_path, small_map, monkeypatch):
    m = small_map
    assert outputs.CSV_MAX_POINTS == 300_000  # the documented default (docs, CHANGELOG, help)
    assert _names(m, tmp_path / "small") == ["region.npz", "region.csv", "region_class_taylor.png"]
    assert (tmp_path / "small" / "region.csv").read_text(encoding="utf-8") == m.csv_text()
    monkeypatch.setattr(outputs, "CSV_MAX_POINTS", 49)  # at the threshold: still written
    assert writes_csv(m) and "region.csv" in _names(m, tmp_path / "at")
    monkeypatch.setattr(outputs, "CSV_MAX_POINTS", 48)  # one point over: not by default
    assert not writes_csv(m)
    assert _names(m, tmp_path / "over") == ["region.npz", "region_class_taylor.png"]
    assert (load_npz(tmp_path / "over" / "region.npz").verdict["taylor"] == m.verdict["taylor"]).all()
    assert _names(m, tmp_path / "asked", csv=True) == ["region.npz", "region.csv",
                                                       "region_class_taylor.png"]
    assert (tmp_path / "asked" / "region.csv").read_text(encoding="utf-8") == m.csv_text()
    monkeypatch.setattr(outputs, "CSV_MAX_POINTS", 300_000)
    assert _names(m, tmp_path / "never", csv=False) == ["region.npz", "region_class_taylor.png"]
    with pytest.raises(StringStabError, match="csv must be None, True or False"):
        writes_csv(m, "yes")  # type: ignore[arg-type]


def test_a_volume_has_no_csv_whatever_asked():
    g = np.linspace(-1, 1, 3)
    v = region_map({"k_x": g, "k_v": g, "k_a": g}, None, tau=0.1, delta=0.2, headway=1.1,
                   methods="taylor", workers=1, progress=False)
    assert not any(writes_csv(v, c) for c in (None, True, False))


def test_cli_over_the_threshold_says_so_and_csv_writes_it(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(outputs, "CSV_MAX_POINTS", 48)
    assert main([*REGION, "--out", str(tmp_path / "d")]) == 0
    out = capsys.readouterr().out
    assert not (tmp_path / "d" / "region.csv").exists() and (tmp_path / "d" / "region.npz").exists()
    line = "region.csv not written: 49 points > 48 (pass --csv; region.npz holds the same columns)"
    assert out.splitlines()[-1] == line and out.count("not written") == 1
    assert "wrote 2 files" in out and "region.csv" not in out.replace(line, "")
    report = (tmp_path / "d" / "report.md").read_text(encoding="utf-8")
    assert "region.csv" not in report  # the report claims no CSV
    assert main([*REGION, "--csv", "--prefix", "p", "--out", str(tmp_path / "c")]) == 0
    out = capsys.readouterr().out
    assert (tmp_path / "c" / "p.csv").exists() and "not written" not in out
    m = load_npz(tmp_path / "c" / "p.npz")
    assert (tmp_path / "c" / "p.csv").read_text(encoding="utf-8") == m.csv_text()


def test_cli_no_csv_and_the_default_under_the_threshold(tmp_path, capsys):
    assert main([*REGION, "--out", str(tmp_path / "d")]) == 0
    assert (tmp_path / "d" / "region.csv").exists() and "not written" not in capsys.readouterr().out
    assert main([*REGION, "--no-csv", "--out", str(tmp_path / "n")]) == 0
    out = capsys.readouterr().out
    assert not (tmp_path / "n" / "region.csv").exists() and "not written" not in out  # as asked
    assert "wrote 2 files" in out


@pytest.mark.parametrize("argv,match", [
    ([*REGION, "--csv", "--no-csv"], "not allowed with argument"),
    (["region", "--3d", "--n", "3", "--method", "taylor", "--csv"],
     "--csv writes the table of a 2-D map; got --3d"),
])
def test_cli_bad_csv_flags_exit_2_and_write_nothing(tmp_path, capsys, argv, match):
    out = tmp_path / "maps"
    try:
        rc = main([*argv, "--out", str(out)])
    except SystemExit as e:  # refused by the parser
        rc = e.code
    assert rc == 2
    err = capsys.readouterr().err
    assert err.startswith("stringstab region: error:") and match in err and err.count("\n") == 1
    assert not out.exists()


def test_the_parser_states_the_plotting_codes_threshold():
    from stringstab.cli import build_parser
    from stringstab.cli import region as cli_region

    assert cli_region.CSV_MAX_POINTS == outputs.CSV_MAX_POINTS  # the help does not import it
    sub = next(a for a in build_parser("region")._actions
               if a.__class__.__name__ == "_SubParsersAction")
    text = sub.choices["region"].format_help()
    assert "300,000" in text and "--csv" in text and "--no-csv" in text


def test_cli_reaction_sweep_applies_the_same_rule(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(outputs, "CSV_MAX_POINTS", 24)
    base = ["region", "--fix", "k_a=0.5", "--n", "5", "--dpi", "20", "--no-progress",
            "--reaction-delay", "0,0.1"]
    assert main([*base, "--out", str(tmp_path / "d")]) == 0
    out = capsys.readouterr().out
    names = {p.name for p in (tmp_path / "d").iterdir()}
    assert {"region_theta_r_0.npz", "region_theta_r_0.1.npz", "region_share_vs_theta_r.csv"} <= names
    assert not {"region_theta_r_0.csv", "region_theta_r_0.1.csv"} & names
    assert out.splitlines()[-1] == ("region_theta_r_*.csv not written: 25 points > 24 (pass --csv; "
                                    "each region_theta_r_*.npz holds the same columns)")
    assert main([*base, "--csv", "--out", str(tmp_path / "c")]) == 0
    assert "not written" not in capsys.readouterr().out
    names = {p.name for p in (tmp_path / "c").iterdir()}
    assert {"region_theta_r_0.csv", "region_theta_r_0.1.csv"} <= names


@pytest.mark.parametrize("processes", [1, 2])
def test_meanwhile_is_called_once_with_the_final_paths(tmp_path, small_map, processes):
    """``meanwhile`` (the CLI builds its report there) gets the files' final paths, once:
    with a helper after the data files and before the figures are waited for; alone, after
    everything (the NPZ is on disk when it is called, in both cases)."""
    seen = []

    def meanwhile(files):
        seen.append((list(files), (tmp_path / "region.npz").is_file()))

    out = save_region_outputs(small_map, tmp_path, formats=("png",), dpi=20,
                              processes=processes, meanwhile=meanwhile)
    assert seen == [(out, True)]
    assert [p.name for p in out] == ["region.npz", "region.csv", "region_class_taylor.png"]
    assert all(p.is_file() for p in out)
