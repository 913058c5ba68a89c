"""`stringstab certify` writes every format from the batch's columns; results read back."""

import json

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from stringstab.certify.api import certify_batch
from stringstab.cli import main
from stringstab.io import read_gains

TRIPLES = ["1.3,0,0.6", "0.9,-0.5,1.1", "-0.5,1,1"]


def test_records_are_the_certificates_rows():
    b = certify_batch([1.3, 0.9, -0.5], [0.0, -0.5, 1.0], [0.6, 1.1, 1.0], tau=0.1, delta=0.2,
                      headway=1.1, method="pade")
    assert b.records() == [dict(b[i].as_dict()) for i in range(len(b))]
    assert b.records()[2]["sup_gain"] is None and np.isinf(b.columns()["sup_gain"][2])


@pytest.mark.parametrize("fmt", ["parquet", "npz", "csv", "json"])
def test_every_format_reads_back(tmp_path, capsys, fmt):
    out = tmp_path / f"r.{fmt}"
    assert main(["certify", *TRIPLES, "--format", fmt, "--out", str(out)]) == 1
    assert "1 of 3 certified" in capsys.readouterr().err
    back = read_gains(out)
    assert_array_equal(back.K, [[1.3, 0, 0.6], [0.9, -0.5, 1.1], [-0.5, 1, 1]])


def test_parquet_keeps_types_and_params(tmp_path, capsys):
    pq = pytest.importorskip("pyarrow.parquet")
    out = tmp_path / "r.parquet"
    main(["certify", *TRIPLES, "--format", "parquet", "--out", str(out)])
    t = pq.read_table(out)
    assert t.column("verdict").to_pylist() == ["certified", "not_certified", "not_certified"]
    assert t.column("hurwitz").to_pylist() == [True, True, False]
    assert t.column("sup_gain").to_pylist()[2] == float("inf")
    assert t.column("taylor_printed_sign").to_pylist()[1] == "stable"
    assert json.loads(t.schema.metadata[b"stringstab.params"])["tau"] == 0.1
    assert json.loads(t.schema.metadata[b"stringstab.summary"])["certified_row_share"] == pytest.approx(1 / 3)


@pytest.mark.parametrize("argv, message", [
    (["--format", "parquet"], "--format parquet writes a binary file; expected --out FILE, got none"),
    (["--format", "npz"], "--format npz writes a binary file; expected --out FILE"),
    (["--out", "{d}"], "expected a file; "),
    (["--out", "/dev/null/r.csv"], "is a file, not a folder"),  # a path through a file
])
def test_output_refused_before_work(tmp_path, capsys, argv, message):
    argv = [a.replace("{d}", str(tmp_path)) for a in argv]
    assert main(["certify", *TRIPLES, *argv]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and message in err
    assert list(tmp_path.iterdir()) == []
