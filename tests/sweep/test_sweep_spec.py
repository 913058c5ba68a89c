"""Sweep specs: axes crossed and zipped, ranges, stable ids, and bad specs refused on load."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from stringstab.errors import StringStabError
from stringstab.sweep import load_spec, parse_spec
from stringstab.sweep.spec import expand_axis

SPECS = Path(__file__).resolve().parents[2] / "analysis" / "sweeps"

TRAIN = """
[sweep]
kind = "train"
seeds = [0, 1]
[base]
algo = "td3"
total_steps = 100
[axes]
exploration_noise = {start = 0.1, stop = 0.3, step = 0.1}
[zip]
label = ["a", "b"]
weights = [[0.5, 0.25, 0.25], [0.2, 0.6, 0.2]]
"""


def test_points_cross_axes_zip_and_seeds() -> None:
    spec = parse_spec(TRAIN)
    assert len(spec) == 2 * 3 * 2  # zip rows × noise levels × seeds
    noise = sorted({p.settings["exploration_noise"] for p in spec.points})
    assert noise == pytest.approx([0.1, 0.2, 0.3], abs=1e-12)
    # zipped: label a always goes with its own weights
    for p in spec.points:
        w = [0.5, 0.25, 0.25] if p.label == "a" else [0.2, 0.6, 0.2]
        assert p.settings["weights"] == pytest.approx(w)
        assert p.settings["algo"] == "td3" and p.settings["action"] == "accel"  # config_for("td3")
        assert p.settings["total_steps"] == 100
    assert {p.settings["seed"] for p in spec.points} == {0, 1}


def test_ids_stable_and_distinct() -> None:
    a, b = parse_spec(TRAIN), parse_spec(TRAIN.replace('total_steps = 100', 'total_steps = 100 '))
    assert [p.id for p in a.points] == [p.id for p in b.points]
    assert len({p.id for p in a.points}) == len(a)
    # a label is not part of the settings; any setting is
    c = parse_spec(TRAIN.replace('"a", "b"', '"x", "y"'))
    assert [p.id for p in c.points] == [p.id for p in a.points]
    d = parse_spec(TRAIN.replace("total_steps = 100", "total_steps = 101"))
    assert not {p.id for p in d.points} & {p.id for p in a.points}


def test_ranges() -> None:
    assert expand_axis("n", {"start": 1, "stop": 7, "step": 3}) == [1, 4, 7]
    assert expand_axis("x", {"start": 0.0, "stop": 1.0, "num": 5}) == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert expand_axis("x", {"start": 1.0, "stop": 0.0, "step": -0.5}) == [1.0, 0.5, 0.0]
    with pytest.raises(StringStabError, match="does not lead"):
        expand_axis("x", {"start": 0.0, "stop": 1.0, "step": -0.5})


@pytest.mark.parametrize(("edit", "message"), [
    (("total_steps = 100", "total_stepz = 100"),
     r"\[base\] unknown field 'total_stepz' for kind train; allowed: algo, paper, .*total_steps"),
    (("total_steps = 100", "total_steps = -5"), r"config field total_steps must be >= 1; got -5"),
    (('algo = "td3"', 'algo = "ppo"'), r"field algo must be one of idl, td3, ddpg; got 'ppo'"),
    (("exploration_noise = {start = 0.1, stop = 0.3, step = 0.1}", "exploration_noise = []"),
     r"axis exploration_noise is empty"),
    (("exploration_noise = {start = 0.1, stop = 0.3, step = 0.1}", "exploration_noise = [-0.1]"),
     r"exploration_noise=-0.1.*config field exploration_noise must be >= 0"),
    (('kind = "train"', 'kind = "trian"'),
     r"\[sweep\] field kind must be one of \['train', 'region', 'certify', 'probe'\]; got 'trian'"),
    (('label = ["a", "b"]', 'label = ["a"]'), r"\[zip\] lists must have equal lengths"),
    (("[base]", "[bsae]"), r"unknown table \[bsae\]; allowed: sweep, base, axes, zip"),
    (("seeds = [0, 1]", "seeds = [0, 0]"), r"have the same settings"),
    (("seeds = [0, 1]", 'seeds = [0, 1]\nstudy = "table4"'),
     r"field study must be one of \['none', 'table3', 'table5', 'fig4', 'fig5', 'certificate'\]"),
])
def test_bad_specs_refused(edit: tuple[str, str], message: str) -> None:
    text = TRAIN.replace(*edit)
    assert text != TRAIN
    with pytest.raises(StringStabError, match=message):
        parse_spec(text)


def test_bad_region_fields_refused() -> None:
    base = '[sweep]\nkind = "region"\n[base]\nfix = "k_a=0.5"\nn = 5\n'
    assert len(parse_spec(base)) == 1
    with pytest.raises(StringStabError, match=r"field fix must be 'k_a=VALUE'"):
        parse_spec(base.replace("k_a=0.5", "k_v=0.5"))
    with pytest.raises(StringStabError, match=r"field methods must be a list among"):
        parse_spec(base + 'methods = ["exact", "pade"]\n')
    with pytest.raises(StringStabError, match=r"tau"):
        parse_spec(base + "tau = -0.1\n")
    with pytest.raises(StringStabError, match=r"seeds apply to kind train or probe"):
        parse_spec(base.replace('kind = "region"', 'kind = "region"\nseeds = [1]'))


def test_not_toml_and_missing_file(tmp_path: Path) -> None:
    with pytest.raises(StringStabError, match="not valid TOML"):
        parse_spec("[sweep\nkind=")
    with pytest.raises(StringStabError, match="cannot read it"):
        load_spec(tmp_path / "absent.toml")


@pytest.mark.parametrize("path", sorted(SPECS.glob("*.toml")), ids=lambda p: p.name)
def test_shipped_specs_load(path: Path) -> None:
    spec = load_spec(path)
    assert len(spec) >= 1


def test_cli_refuses_bad_spec_in_one_line(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text(TRAIN.replace("total_steps = 100", "total_stepz = 100"))
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "stringstab", "sweep", str(bad), "--out", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0 and "unknown field 'total_stepz'" in r.stderr
    assert not out.exists()
