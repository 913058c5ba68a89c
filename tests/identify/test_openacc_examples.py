"""The OpenACC logs shipped in stringstab/data/openacc: attribution beside them, every row of
the originals, and `stringstab identify --example` (a file, or --example, one of the two)."""

from __future__ import annotations

from pathlib import Path

import pytest

from stringstab.cli import main
from stringstab.identify import EXAMPLES, example_log, read_logs

DATA = Path(__file__).resolve().parents[2] / "stringstab" / "data" / "openacc"


def test_shipped_with_attribution_licence_and_citation() -> None:
    readme = (DATA / "README.md").read_text(encoding="utf-8")
    for needed in ("CC BY 4.0", "creativecommons.org/licenses/by/4.0", "Makridis",
                   "doi:10.1016/j.trc.2021.103047", "columns removed"):
        assert needed in readme, needed
    cite = (DATA.parents[2] / "docs" / "cite.md").read_text(encoding="utf-8")
    assert "doi:10.1016/j.trc.2021.103047" in cite
    assert "doi: 10.1016/j.trc.2021.103047" in (DATA.parents[2] / "CITATION.cff").read_text()
    for name, (fname, _) in EXAMPLES.items():
        p = example_log(name)
        assert p == DATA / fname and p.read_bytes()[:2] == b"\x1f\x8b"  # gzip
    rows = {name: read_logs(example_log(name))[0].t.size for name in EXAMPLES}
    assert rows == {"acc": 5497, "human": 3200}  # every data row of the originals


def test_example_or_log_not_both(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "o"
    for argv, what in ((["--example", "acc", str(example_log("human"))], "got both"),
                       ([], "got neither")):
        assert main(["identify", *argv, "--out", str(out)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert err == [f"stringstab identify: error: expected a log file LOG or --example "
                       f"acc|human (one of the two); {what}"]
        assert not out.exists()
    with pytest.raises(SystemExit):
        main(["identify", "--example", "other", "--out", str(out)])
    capsys.readouterr()
