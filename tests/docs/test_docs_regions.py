"""docs/regions.md: its console example is the tool's actual output and its figures exist."""

import re
import shlex
from pathlib import Path

import numpy as np

from stringstab.regions import region_map

DOC = Path(__file__).resolve().parents[2] / "docs" / "regions.md"


def test_console_example_is_the_actual_output():
    text = DOC.read_text()
    block = re.search(r"```console\n\$ (stringstab region [^\n]*)\n(.*?)```", text, re.S)
    argv = shlex.split(block.group(1))
    opts = dict(zip(argv[2::2], argv[3::2]))
    assert opts["--x"] == "k_x" and opts["--y"] == "k_v" and opts["--range"] == "-2,2"
    gain, value = opts["--fix"].split("=")
    g = np.linspace(-2, 2, int(opts["--n"]))
    m = region_map({"k_x": g, "k_v": g}, {gain: float(value)}, tau=float(opts["--tau"]),
                   delta=float(opts["--delta"]), headway=float(opts["--headway"]),
                   methods=opts["--method"])
    printed = block.group(2).splitlines()
    assert printed[: len(m.report().splitlines())] == m.report().splitlines()


def test_figures_exist_and_are_small():
    names = re.findall(r"\]\((figures/[^)]+\.png)\)", DOC.read_text())
    assert len(names) >= 10
    for n in names:
        path = DOC.parent / n
        assert path.exists(), n
        assert 10_000 < path.stat().st_size < 250_000, (n, path.stat().st_size)
