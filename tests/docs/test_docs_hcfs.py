"""docs/hcfs.md shows what `stringstab hcfs verify` prints and what the library computes."""

import contextlib
import importlib.util
import io
import re
from pathlib import Path

import numpy as np
import pytest

from stringstab.cli import main
from stringstab.hcfs import closed_loop_matrix, reward_weights_from_table_iv

DOC = (Path(__file__).resolve().parents[2] / "docs" / "hcfs.md").read_text()


@pytest.mark.torch
@pytest.mark.skipif(importlib.util.find_spec("torch") is None, reason="the bundled DDPG needs torch")
def test_console_example_is_what_the_tool_prints(tmp_path):
    block = re.search(r"```console\n\$ (stringstab hcfs verify [^\n]*)\n(.*?)```", DOC, re.S)
    assert block is not None
    cmd, shown = block.group(1).split(), block.group(2).splitlines()
    out = tmp_path / "hcfs"
    args = [*cmd[1:cmd.index("--out")], "--no-figures", "--out", str(out)]
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        assert main(args) == 0
    printed = buf.getvalue().splitlines()
    assert printed[:-1] == shown[:-1]  # the last line lists the files (figures skipped here)
    assert shown[-1].startswith(printed[-1].split("; wrote")[0])


def test_quoted_numbers():
    w = reward_weights_from_table_iv()
    assert f"{w['omega_1']:.2f} and {w['omega_2']:.4f}" in DOC
    quoted = f"{w['hcfs_predicted']:.3f} against the printed {w['hcfs_printed']:.2f}"
    assert quoted.replace("-", "−") in DOC

    def rho(a):
        return max(abs(np.linalg.eigvals(a)))

    printed, derived = rho(closed_loop_matrix(8, sign=-1)), rho(closed_loop_matrix(8))
    assert f"spectral radius {printed:.3f} for 8 followers, against {derived:.3f}" in DOC
