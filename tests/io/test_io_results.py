"""The one result writer (stringstab.io.results): every format against an independent reader."""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_array_equal

from stringstab.errors import StringStabError
from stringstab.io import (
    RESULT_FORMATS,
    TableColumn,
    columns_from_records,
    flatten_columns,
    format_results,
    render_table,
    write_results,
)

COLUMNS = {
    "t": np.array([0.0, 0.25, 1e-5]),
    "vehicle": np.array([1, 2, 3]),
    "k_x": np.array([1.0, -0.5, 1 / 3]),
    "ok": np.array([True, False, True]),
    "verdict": np.array(["certified", "not_certified", 'odd, "quoted"']),
    "sup": np.array([1.0, np.inf, np.nan]),
    "taylor": {"psi1": np.array([0.1, 2e20, -0.0]), "verdict": np.array(["stable"] * 3)},
}
PARAMS = {"tau": 0.1, "method": "exact", "bounds": [-2.0, 2.0], "nested": {"a": 1}}
SUMMARY = {"n": 3, "share": 2 / 3}


def test_json_is_strict_and_exact():
    text = format_results(COLUMNS, "json", params=PARAMS, summary=SUMMARY)
    doc = json.loads(text, parse_constant=lambda c: pytest.fail(f"non-JSON constant {c}"))
    assert list(doc) == ["params", "results", "summary"]
    assert doc["params"] == {"tau": 0.1, "method": "exact", "bounds": [-2.0, 2.0], "nested": {"a": 1}}
    rows = doc["results"]
    assert [r["t"] for r in rows] == [0.0, 0.25, 1e-5]
    assert [r["k_x"] for r in rows] == [1.0, -0.5, 1 / 3]  # shortest digits read back exactly
    assert [r["vehicle"] for r in rows] == [1, 2, 3]
    assert [r["ok"] for r in rows] == [True, False, True]
    assert rows[2]["verdict"] == 'odd, "quoted"'
    assert [r["sup"] for r in rows] == [1.0, None, None]  # non-finite is null
    assert rows[1]["taylor"] == {"psi1": 2e20, "verdict": "stable"}
    assert math.copysign(1.0, rows[2]["taylor"]["psi1"]) == -1.0
    assert list(rows[0]) == ["t", "vehicle", "k_x", "ok", "verdict", "sup", "taylor"]
    lines = text.splitlines()
    assert lines[2] == ' "results": [' and lines[3].startswith('  {"t": 0.0, ')  # one row per line
    assert len(lines) == 1 + 1 + 1 + 3 + 1 + 1 + 1
    assert json.loads(format_results({"k_x": np.array([])}, "json")) == {"results": []}


def test_csv_against_the_csv_module():
    text = format_results(COLUMNS, "csv", params=PARAMS)
    rows = list(csv.DictReader(io.StringIO(text)))
    assert list(rows[0]) == ["t", "vehicle", "k_x", "ok", "verdict", "sup", "taylor_psi1",
                             "taylor_verdict", "tau", "method", "bounds"]
    assert [r["t"] for r in rows] == ["0.0", "0.25", repr(1e-5).replace("1e-05", rows[2]["t"])]
    assert float(rows[2]["t"]) == 1e-5
    assert [float(r["k_x"]) for r in rows] == [1.0, -0.5, 1 / 3]
    assert [r["ok"] for r in rows] == ["True", "False", "True"]
    assert rows[2]["verdict"] == 'odd, "quoted"'
    assert [r["sup"] for r in rows] == ["1.0", "", ""]
    assert {r["tau"] for r in rows} == {"0.1"} and {r["bounds"] for r in rows} == {"-2,2"}
    assert format_results({"a": np.array([], dtype=float)}, "csv") == "a\n"


def test_table_layout_units_and_missing():
    spec = [TableColumn("k_x", "k_x"), TableColumn("sup|Γ|", "sup", "%.4g", missing="n/a"),
            TableColumn("taylor", "taylor.verdict"), TableColumn("ok", "ok"),
            TableColumn("absent", "nope")]
    text = render_table(COLUMNS, spec, params={"tau": 0.1, "check": False}, summary={
        "n": 3, "share": 2 / 3, "projection": {"n": 2, "median": 0.123456}})
    lines = text.splitlines()
    assert lines[0] == "# tau = 0.1, check = no"
    assert lines[1].split() == ["k_x", "sup|Γ|", "taylor", "ok"]
    assert lines[2].split() == ["1", "1", "stable", "yes"]
    assert lines[3].split() == ["-0.5", "inf", "stable", "no"]
    assert lines[4].split() == ["0.333333", "n/a", "stable", "yes"]
    assert lines[5:] == ["# n = 3, share = 0.6667", "# projection: n = 2, median = 0.1235"]
    # columns line up: every cell of a column starts where its header starts
    starts = [lines[1].index(h) for h in ("sup|Γ|", "taylor", "ok")]
    for ln in lines[2:5]:
        assert [ln[s - 2:s] for s in starts] == ["  "] * 3


def test_binary_formats(tmp_path: Path):
    pq = pytest.importorskip("pyarrow.parquet")
    write_results(COLUMNS, tmp_path / "r.parquet", "parquet", params=PARAMS, summary=SUMMARY)
    t = pq.read_table(tmp_path / "r.parquet")
    assert t.column_names == list(flatten_columns(COLUMNS))
    assert_array_equal(t.column("sup").to_numpy(), COLUMNS["sup"])  # inf and nan kept
    assert t.column("ok").to_pylist() == [True, False, True]
    meta = t.schema.metadata
    assert json.loads(meta[b"stringstab.params"])["bounds"] == [-2.0, 2.0]
    assert json.loads(meta[b"stringstab.summary"]) == SUMMARY
    write_results(COLUMNS, tmp_path / "r.npz", "npz", params=PARAMS, summary=SUMMARY)
    with np.load(tmp_path / "r.npz") as z:
        assert_array_equal(z["taylor_psi1"], COLUMNS["taylor"]["psi1"])
        assert z["verdict"].tolist() == COLUMNS["verdict"].tolist()
        assert json.loads(str(z["_summary"])) == SUMMARY
    with pytest.raises(StringStabError, match="the parquet format is binary: expected an output file"):
        write_results(COLUMNS, io.StringIO(), "parquet")


def test_bad_columns_and_formats():
    with pytest.raises(StringStabError, match="result column 'b' has 1 rows; expected 2"):
        format_results({"a": [1.0, 2.0], "b": [1.0]}, "csv")
    with pytest.raises(StringStabError, match="must be one-dimensional"):
        format_results({"a": np.zeros((2, 2))}, "csv")
    with pytest.raises(StringStabError, match="output format must be one of"):
        write_results({"a": [1.0]}, io.StringIO(), "xlsx")
    assert set(RESULT_FORMATS) == {"table", "json", "csv", "parquet", "npz"}


def test_records_with_missing_values():
    cols = columns_from_records([{"a": 1, "b": None, "g": {"x": True}}, {"a": None, "b": "s"}])
    assert cols == {"a": [1, None], "b": [None, "s"], "g": {"x": [True, None]}}
    doc = json.loads(format_results(cols, "json"))
    assert doc["results"] == [{"a": 1, "b": None, "g": {"x": True}},
                              {"a": None, "b": "s", "g": {"x": None}}]
    rows = list(csv.reader(io.StringIO(format_results(cols, "csv"))))
    assert rows == [["a", "b", "g_x"], ["1", "", "True"], ["", "s", ""]]


def test_write_is_atomic(tmp_path: Path):
    out = tmp_path / "r.csv"
    out.write_text("old")
    write_results({"a": [1.0]}, out, "csv")
    assert out.read_text() == "a\n1.0\n"
    with pytest.raises(StringStabError, match="cannot write"):
        write_results({"a": [1.0]}, tmp_path / "r.csv" / "missing" / "r.csv", "csv")  # a file
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv"]


finite = st.floats(allow_nan=False, allow_infinity=False, width=64)


@given(x=st.lists(st.floats(width=64), min_size=1, max_size=20))
def test_floats_read_back_exactly(x):
    """Any double (subnormal, huge, negative zero) reads back bit for bit; non-finite is null."""
    a = np.array(x, dtype=np.float64)
    doc = json.loads(format_results({"x": a}, "json"))
    back = [r["x"] for r in doc["results"]]
    lines = format_results({"x": a}, "csv").splitlines()[1:]  # one column: no csv module needed
    for v, j, c in zip(a.tolist(), back, lines, strict=True):
        if math.isfinite(v):
            assert float(j) == v and math.copysign(1, float(j)) == math.copysign(1, v)
            assert float(c) == v and repr(float(c)) == repr(v)
        else:
            assert j is None and c == ""


def test_gain_csv_fast_and_cell_by_cell_paths_agree(tmp_path: Path):
    """Plain rows are parsed in C; quoted ones cell by cell: the same table either way."""
    from stringstab.io import read_gains

    rng = np.random.default_rng(3)
    K = rng.uniform(-2, 2, (50, 3))
    plain = "# a comment\nt, vehicle, k_x, k_v, k_a\n" + "".join(
        f"{0.25 * i!r},{1 + i % 2},{a!r},{b!r},{c!r}\n" for i, (a, b, c) in enumerate(K.tolist()))
    quoted = plain.replace(",1,", ',"1",')
    (tmp_path / "plain.csv").write_text(plain)
    (tmp_path / "quoted.csv").write_text(quoted)
    a, b = read_gains(tmp_path / "plain.csv"), read_gains(tmp_path / "quoted.csv")
    assert_array_equal(a.K, K)
    assert_array_equal(b.K, K)
    assert_array_equal(a.t, b.t)
    assert a.vehicle.tolist() == b.vehicle.tolist() == [1 + i % 2 for i in range(50)]


def test_categorical_columns_write_as_their_values():
    """A Categorical column is written exactly as the plain column it stands for, in every format."""
    from stringstab.io import Categorical

    rng = np.random.default_rng(5)
    labels = np.array([-2.0, 0.1, 1e-300, np.pi])
    codes = rng.integers(0, 4, 40)
    words = np.array(["certified", "not_certified", "a,b"])
    wcodes = rng.integers(0, 3, 40)
    plain = {"k": labels[codes], "v": words[wcodes], "x": rng.normal(size=40)}
    cat = {"k": Categorical(codes, labels), "v": Categorical(wcodes, words), "x": plain["x"]}
    for fmt in ("csv", "json", "table"):
        assert format_results(cat, fmt) == format_results(plain, fmt)
    assert_array_equal(np.asarray(cat["k"]), plain["k"])


def test_csv_fast_layout_equals_joined_rows():
    """Cells needing no quotes go through Arrow's CSV writer, others through the row join:
    both give the text Python's csv module would."""
    rng = np.random.default_rng(6)
    x = rng.normal(size=30)
    for words in (np.array(["u", "v"]), np.array(["u,1", 'say "v"'])):
        cols = {"x": x, "w": words[rng.integers(0, 2, 30)], "b": x > 0}
        text = format_results(cols, "csv", params={"tau": 0.1})
        rows = list(csv.reader(io.StringIO(text)))
        assert rows[0] == ["x", "w", "b", "tau"]
        assert [float(r[0]) for r in rows[1:]] == x.tolist()
        assert [r[1] for r in rows[1:]] == cols["w"].tolist()
        assert [r[2] for r in rows[1:]] == [str(bool(v)) for v in cols["b"]]
        assert {r[3] for r in rows[1:]} == {"0.1"}
