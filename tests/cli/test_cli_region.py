"""`stringstab region` end to end: files, printed shares, and exit 2 with nothing written on bad input."""

import csv
import re
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import stringstab
from stringstab.cli import main
from stringstab.regions import load_npz, region_map

ROLLOUT = Path(stringstab.__file__).parent / "data" / "examples" / "gain_rollout.csv"


@pytest.mark.slow  # ~11.1 s with -n 2 on 2 shared cores (CI runs it)
def test_slice_writes_data_and_figures(tmp_path, capsys):
    out = tmp_path / "maps"
    rc = main(["region", "--x", "k_x", "--y", "k_v", "--fix", "k_a=0.5", "--range", "-2,2", "--n", "15",
               "--tau", "0.1", "--delta", "0.2", "--headway", "1.1", "--method", "exact,taylor,printed",
               "--out", str(out), "--format", "png,pdf", "--overlay", str(ROLLOUT), "--dpi", "40"])
    assert rc == 0
    names = {p.name for p in out.iterdir()}
    # the default figures (issue 31): the first method's class map, the comparison, sup|Γ|
    for stem in ("class_exact", "compare", "sup_gain", "overlay"):
        assert {f"region_{stem}.png", f"region_{stem}.pdf"} <= names
    assert not any("class_taylor" in n or "class_printed" in n for n in names)
    assert {"region.npz", "region.csv"} <= names
    m = load_npz(out / "region.npz")
    assert m.version == stringstab.__version__ and m.fixed == {"k_a": 0.5} and m.shape == (15, 15)
    ref = region_map({"k_x": np.linspace(-2, 2, 15), "k_v": np.linspace(-2, 2, 15)}, {"k_a": 0.5},
                     tau=0.1, delta=0.2, headway=1.1)
    for k, v in ref.verdict.items():
        assert (m.verdict[k] == v).all()
    text = capsys.readouterr().out
    shares = ref.class_shares()["exact"]
    assert f"certified {100 * shares['certified']:.1f} %" in text
    assert f"any {ref.disagreements()['any']:,} of 225 points" in text
    with open(out / "region.csv", newline="") as fh:
        rows = [r for r in csv.reader(fh) if not r[0].startswith("#")]
    assert len(rows) == 1 + 225 and rows[0][:3] == ["k_x", "k_v", "k_a"]


def test_volume_and_per_axis_ranges(tmp_path, capsys):
    rc = main(["region", "--3d", "--x", "k_a", "--y", "k_x", "--range", "k_a=-1,1.5", "--n", "5,6,4",
               "--method", "taylor", "--out", str(tmp_path), "--format", "png", "--dpi", "40"])
    assert rc == 0
    m = load_npz(tmp_path / "region.npz")
    assert m.axis_names == ("k_a", "k_x", "k_v") and m.shape == (5, 6, 4)
    assert_allclose([m.axes["k_a"][0], m.axes["k_a"][-1], m.axes["k_x"][0]], [-1.0, 1.5, -2.0], rtol=0, atol=0)
    assert (tmp_path / "region_slices_taylor.png").exists() and (tmp_path / "region_3d_taylor.png").exists()
    assert not (tmp_path / "region.csv").exists()
    assert "taylor:" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv,match",
    [
        (["--x", "k_v", "--y", "k_v", "--fix", "k_a=1"], "different gains"),
        (["--x", "k_q", "--fix", "k_a=1"], "--x must be one of"),
        (["--fix", "k_a=1", "--range", "2,-2"], "LO < HI"),
        (["--fix", "k_a=1", "--range", "1,2,3"], "LO,HI"),
        (["--fix", "k_a=1", "--range", "k_a=0,1"], "not on an axis"),
        (["--fix", "k_a=1", "--n", "1"], "integer >= 2"),
        (["--fix", "k_a=1", "--n", "3,4,5"], "comma-separated"),
        (["--fix", "k_a=1", "--tau", "0"], "tau"),
        (["--fix", "k_a=1", "--delta", "-0.1"], "delta"),
        (["--fix", "k_v=1"], "must fix k_a"),
        (["--fix", "k_a"], "GAIN=VALUE"),
        ([], "expected --fix k_a=VALUE"),
        (["--3d", "--fix", "k_a=1"], "--3d maps all three"),
        (["--fix", "k_a=1", "--method", "exact,foo"], "methods must be among"),
        (["--fix", "k_a=1", "--format", "gif"], "--format"),
        (["--fix", "k_a=1", "--overlay", "/no/such/file.csv"], "no such file"),
        (["--3d", "--overlay", str(ROLLOUT)], "2-D map"),
        (["--fix", "k_a=1", "--workers", "0"], "--workers"),
    ],
)
def test_bad_input_exits_2_and_writes_nothing(tmp_path, capsys, argv, match):
    out = tmp_path / "maps"
    assert main(["region", *argv, "--n", "5", "--out", str(out)] if "--n" not in argv
                else ["region", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("stringstab region: error:") and match in err
    assert err.count("\n") == 1
    assert not out.exists()


def test_an_unknown_figure_set_exits_2_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "maps"
    with pytest.raises(SystemExit) as e:  # refused by the parser, before any work
        main(["region", "--fix", "k_a=1", "--n", "5", "--figures", "some", "--out", str(out)])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("stringstab region: error: argument --figures: invalid choice: 'some'")
    assert err.count("\n") == 1 and "default" in err and "all" in err
    assert not out.exists()


def test_figures_all_draws_every_class_map_and_the_data_is_the_same(tmp_path, capsys):
    from stringstab.cli import build_parser
    from stringstab.plots import FIGURE_SETS

    base = ["region", "--fix", "k_a=0.5", "--n", "7", "--dpi", "30", "--no-progress"]
    assert main([*base, "--out", str(tmp_path / "d")]) == 0
    assert main([*base, "--figures", "all", "--out", str(tmp_path / "a")]) == 0
    stdout = capsys.readouterr().out
    figures = {d: sorted(p.name for p in (tmp_path / d).glob("*.png")) for d in ("d", "a")}
    assert figures["d"] == ["region_class_exact.png", "region_compare.png", "region_sup_gain.png"]
    assert figures["a"] == sorted([*figures["d"], "region_class_taylor.png",
                                   "region_class_printed.png"])
    assert "wrote 7 files" in stdout and "wrote 5 files" in stdout
    # every method's data either way: the same CSV, the same verdicts in the NPZ
    assert (tmp_path / "d" / "region.csv").read_bytes() == (tmp_path / "a" / "region.csv").read_bytes()
    d, a = load_npz(tmp_path / "d" / "region.npz"), load_npz(tmp_path / "a" / "region.npz")
    assert d.methods == a.methods == ("exact", "taylor", "printed")
    assert all((d.verdict[k] == a.verdict[k]).all() for k in d.methods)
    # the report shows the figures drawn, and only those
    for folder, pngs in figures.items():
        md = (tmp_path / folder / "report.md").read_text(encoding="utf-8")
        shown = set(re.findall(r"\]\((region_\w+\.png)\)", md))
        assert shown == set(pngs), (folder, shown)
    # the parser's choices are the plotting code's figure sets (the parser does not import it)
    sub = next(a for a in build_parser("region")._actions if a.__class__.__name__ == "_SubParsersAction")
    flag = next(a for a in sub.choices["region"]._actions if "--figures" in a.option_strings)
    assert tuple(flag.choices) == FIGURE_SETS and flag.default == "default"


def test_out_must_not_be_a_file(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["region", "--fix", "k_a=1", "--n", "5", "--out", str(f)]) == 2
    assert "expected a directory" in capsys.readouterr().err


def test_demo_region_step(tmp_path, capsys):
    import json

    assert main(["demo", "--out", str(tmp_path), "--only", "region"]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())["region"]
    assert "region_compare.png" in summary["files"] and "region_overlay.png" in summary["files"]
    assert summary["seconds"] > 0  # its cost is measured in analysis/bench_regions.py, not here
    assert abs(sum(summary["class_shares"]["exact"].values()) - 1.0) < 1e-12
    for f in summary["files"]:
        assert (tmp_path / "region" / f).stat().st_size > 0
