"""Reading gain triples (CSV, JSON, NPZ, command line) and writing result records (stringstab.io)."""

import csv
import io
import json

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_array_equal

from stringstab.certify.continuous import TABLE_COLUMNS
from stringstab.errors import StringStabError
from stringstab.io import GainTable, columns_from_records, parse_triple, read_gains
from stringstab.io import results as io_results
from stringstab.io.plain import to_plain


def format_results(records, fmt="table", **kw):
    """Records (one dict per triple) through the columnar writer, as the CLI writes them."""
    columns = columns_from_records([to_plain(r) for r in records])
    return io_results.format_results(columns, fmt, table=TABLE_COLUMNS if fmt == "table" else None,
                                     **kw)


def write_results(records, dest, fmt="table", **kw):
    io_results.write_text(format_results(records, fmt, **kw), dest)


def _write(tmp_path, name, text, encoding="utf-8"):
    p = tmp_path / name
    p.write_text(text, encoding=encoding)
    return p


# --------------------------------------------------------------------------- triples


@pytest.mark.parametrize("text, expected", [
    ("0.9,-0.5,1.1", (0.9, -0.5, 1.1)),
    (" 1.3 , 0 , 0.6 ", (1.3, 0.0, 0.6)),
    ("-5e-1,1E0,+2", (-0.5, 1.0, 2.0)),
])
def test_parse_triple(text, expected):
    assert parse_triple(text) == expected


@pytest.mark.parametrize("text, match", [
    ("0.9,-0.5", r"expected 3 comma-separated numbers k_x,k_v,k_a; found 2 fields"),
    ("1,2,3,4", r"found 4 fields"),
    ("1", r"found 1 field$"),
    ("1,,3", r"k_v: expected a finite number; found an empty field"),
    ("nan,1,1", r"k_x: expected a finite number; found 'nan'"),
    ("1,inf,1", r"k_v: expected a finite number; found 'inf'"),
    ("1,1,-inf", r"k_a: expected a finite number; found '-inf'"),
    ("1,x,1", r"k_v: expected a finite number; found 'x'"),
    ("1;2;3", r"found 1 field"),
])
def test_parse_triple_bad(text, match):
    with pytest.raises(StringStabError, match=match):
        parse_triple(text)


def test_from_triples_and_rows():
    g = GainTable.from_triples([(0.9, -0.5, 1.1), (1, 2, 3)], source="x")
    assert g.rows() == [{"k_x": 0.9, "k_v": -0.5, "k_a": 1.1}, {"k_x": 1.0, "k_v": 2.0, "k_a": 3.0}]
    assert g.columns == ["k_x", "k_v", "k_a"]
    with pytest.raises(StringStabError, match=r"x, triple 2, k_a: expected a finite number"):
        GainTable.from_triples([(1, 1, 1), (1, 1, float("nan"))], source="x")
    with pytest.raises(StringStabError, match="at least one"):
        GainTable.from_triples([], source="x")


def test_table_lengths_checked():
    with pytest.raises(StringStabError, match=r"t must have one entry per gain triple \(2\); found 1"):
        GainTable(np.zeros(2), np.zeros(2), np.zeros(2), t=np.zeros(1))


# --------------------------------------------------------------------------- CSV


def test_csv_plain_and_time_series(tmp_path):
    g = read_gains(_write(tmp_path, "a.csv", "k_x,k_v,k_a\n0.9,-0.5,1.1\n1.3,0,0.6\n"))
    assert_array_equal(g.K, [[0.9, -0.5, 1.1], [1.3, 0.0, 0.6]])
    assert g.t is None and g.vehicle is None and g.source.endswith("a.csv")

    text = "# rollout\nt, vehicle, k_x, k_v, k_a, reward\n\n0.0,1,0.9,-0.5,1.1,3\n0.1,2,1.3,0,0.6,4\n"
    g = read_gains(_write(tmp_path, "ts.csv", text))
    assert_array_equal(g.t, [0.0, 0.1])
    assert g.vehicle.dtype.kind == "i" and g.vehicle.tolist() == [1, 2]
    assert g.ignored_columns == ("reward",)
    assert g.rows()[1] == {"t": 0.1, "vehicle": 2, "k_x": 1.3, "k_v": 0.0, "k_a": 0.6}
    assert g.columns == ["t", "vehicle", "k_x", "k_v", "k_a"]


def test_csv_bom_headerless_case_and_string_ids(tmp_path):
    p = tmp_path / "bom.csv"
    p.write_bytes("\ufeffK_X,k_v,k_a,Vehicle\n1,2,3,car-7\n".encode())
    g = read_gains(p)
    assert_array_equal(g.K, [[1.0, 2.0, 3.0]])
    assert g.vehicle.tolist() == ["car-7"]
    g = read_gains(_write(tmp_path, "nohead.csv", "0.9,-0.5,1.1\n1.3,0,0.6\n"))
    assert_array_equal(g.k_v, [-0.5, 0.0])


@pytest.mark.parametrize("text, match", [
    ("", r"empty file; expected a CSV header with columns k_x,k_v,k_a"),
    ("# only a comment\n\n", r"empty file"),
    ("k_x,k_v,k_a\n", r"no data rows after the header"),
    ("t,k_x,kv,k_a\n0,1,1,1\n", r"missing column 'k_v'; .*is 'kv' a misspelling of 'k_v'\?"),
    ("k_x,k_v,k_acc\n1,1,1\n", r"missing column 'k_a'.*is 'k_acc' a misspelling of 'k_a'\?"),
    ("k_x,k_v\n1,1\n", r"missing column 'k_a'; expected columns k_x, k_v, k_a"),
    ("vehicel,k_x,k_v,k_a\n1,1,1,1\n", r"unknown column 'vehicel'; is it a misspelling of 'vehicle'\?"),
    ("k_x,k_v,k_a,k_x\n1,1,1,1\n", r"column 'k_x' appears twice"),
    ("k_x,k_v,k_a\n1,1,1\n1,nan,1\n", r"line 3, column 'k_v': expected a finite number; found 'nan'"),
    ("k_x,k_v,k_a\n1,1,inf\n", r"line 2, column 'k_a': expected a finite number; found 'inf'"),
    ("k_x,k_v,k_a\n1,1,1\n# c\n1,abc,1\n", r"line 4, column 'k_v': expected a finite number; found 'abc'"),
    ("k_x,k_v,k_a\n1,,1\n", r"line 2, column 'k_v': expected a finite number; found an empty field"),
    ("t,k_x,k_v,k_a\nnan,1,1,1\n", r"line 2, column 't': expected a finite number"),
    ("k_x,k_v,k_a\n1,1\n", r"line 2: expected 3 comma-separated fields \(k_x,k_v,k_a\); found 2"),
    ("1,2,3,4\n", r"line 1: expected a header naming the columns"),
    ("k_x;k_v;k_a\n1;1;1\n", r"line 1: expected comma-separated columns; found fields separated by ';'"),
    ("vehicle,k_x,k_v,k_a\n,1,1,1\n", r"line 2, column 'vehicle': expected a vehicle id"),
])
def test_csv_bad(tmp_path, text, match):
    p = _write(tmp_path, "bad.csv", text)
    with pytest.raises(StringStabError, match=match) as e:
        read_gains(p)
    assert "\n" not in str(e.value)
    assert str(p) in str(e.value)


def test_csv_not_utf8(tmp_path):
    p = tmp_path / "latin.csv"
    p.write_bytes(b"k_x,k_v,k_a\n1,1,\xe9\n")
    with pytest.raises(StringStabError, match=r"not UTF-8 text"):
        read_gains(p)


# --------------------------------------------------------------------------- files


def test_file_errors(tmp_path):
    with pytest.raises(StringStabError, match=r"no such file; expected a readable CSV file"):
        read_gains(tmp_path / "missing.csv")
    with pytest.raises(StringStabError, match=r"unsupported file extension '.txt'; expected .csv, .json or .npz"):
        read_gains(_write(tmp_path, "gains.txt", "k_x,k_v,k_a\n1,1,1\n"))
    with pytest.raises(StringStabError, match=r"unsupported file extension '\(none\)'"):
        read_gains(_write(tmp_path, "gains", "k_x,k_v,k_a\n1,1,1\n"))
    (tmp_path / "d.csv").mkdir()
    with pytest.raises(StringStabError, match=r"is a directory"):
        read_gains(tmp_path / "d.csv")
    with pytest.raises(StringStabError, match=r"format must be csv, json or npz"):
        read_gains(tmp_path / "x.csv", fmt="xlsx")
    # fmt overrides the extension
    g = read_gains(_write(tmp_path, "gains.dat", "[[1, 2, 3]]"), fmt="json")
    assert_array_equal(g.K, [[1.0, 2.0, 3.0]])


def test_unreadable_file(tmp_path, monkeypatch):
    """An unreadable file (simulated, since root reads anything) is a one-line error."""
    p = _write(tmp_path, "locked.csv", "k_x,k_v,k_a\n1,1,1\n")

    def deny(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr("stringstab.io.gains.open", deny, raising=False)
    with pytest.raises(StringStabError, match=r"locked.csv: cannot read the file \(Permission denied\)"):
        read_gains(p)


def test_streams():
    g = read_gains(io.StringIO("\ufeffk_x,k_v,k_a\n1,2,3\n"))
    assert_array_equal(g.K, [[1.0, 2.0, 3.0]])
    assert g.source == "<stream>"
    g = read_gains(io.StringIO(' [{"k_x": 1, "k_v": 2, "k_a": 3}]'))
    assert_array_equal(g.K, [[1.0, 2.0, 3.0]])
    with pytest.raises(StringStabError, match="NPZ cannot be read from a text stream"):
        read_gains(io.StringIO(""), fmt="npz")


# --------------------------------------------------------------------------- JSON


def test_json_forms(tmp_path):
    objs = [{"t": 0.0, "vehicle": "a", "k_x": 0.9, "k_v": -0.5, "k_a": 1.1, "note": "x"},
            {"t": 0.1, "vehicle": "b", "k_x": 1.3, "k_v": 0, "k_a": 0.6, "note": "y"}]
    for doc in (objs, {"gains": objs}, {"params": {}, "results": objs}):
        g = read_gains(_write(tmp_path, "g.json", json.dumps(doc)))
        assert_array_equal(g.K, [[0.9, -0.5, 1.1], [1.3, 0.0, 0.6]])
        assert_array_equal(g.t, [0.0, 0.1])
        assert g.vehicle.tolist() == ["a", "b"]
    g = read_gains(_write(tmp_path, "t.json", "[[0.9, -0.5, 1.1], [1, 2, 3]]"))
    assert_array_equal(g.k_a, [1.1, 3.0])


@pytest.mark.parametrize("text, match", [
    ("", r"empty file; expected a JSON list of gain objects"),
    ("[1, 2", r"not valid JSON \(line 1, column"),
    ("[]", r"expected at least one gain triple; found an empty list"),
    ('{"gain": [[1, 2, 3]]}', r"expected a JSON list of gains or an object with a key 'gains'.*is 'gain' a misspelling of 'gains'\?"),
    ('{"gains": 3}', r"expected a list of gains under 'gains'; found int"),
    ("[[1, 2]]", r"item \[0\]: expected a triple \[k_x, k_v, k_a\]; found 2 values"),
    ('[[1, 2, "a"]]', r"item \[0\], k_a: expected a finite number; found 'a'"),
    ("[[1, 2, NaN]]", r"item \[0\], k_a: expected a finite number; found nan"),
    ("[3]", r"item \[0\]: expected an object with keys k_x, k_v, k_a"),
    ('[{"k_x": 1, "kv": 1, "k_a": 1}]', r"item \[0\]: missing key 'k_v'.*is 'kv' a misspelling of 'k_v'\?"),
    ('[{"k_x": 1, "k_v": 1, "k_a": 1}, {"k_x": 1, "k_v": 1, "k_a": Infinity}]',
     r"item \[1\], key 'k_a': expected a finite number; found inf"),
    ('{"gains": [{"k_x": 1, "k_v": null, "k_a": 1}]}', r"gains\[0\], key 'k_v': expected a finite number; found None"),
    ('[{"k_x": 1, "k_v": true, "k_a": 1}]', r"key 'k_v': expected a finite number; found True"),
    ('[{"k_x": 1, "k_v": 1, "k_a": 1, "t": 0}, {"k_x": 1, "k_v": 1, "k_a": 1}]',
     r"item \[1\]: expected the same keys as item 0 \(k_a, k_v, k_x, t\); missing t"),
])
def test_json_bad(tmp_path, text, match):
    p = _write(tmp_path, "bad.json", text)
    with pytest.raises(StringStabError, match=match) as e:
        read_gains(p)
    assert "\n" not in str(e.value)


# --------------------------------------------------------------------------- NPZ


def test_npz_forms(tmp_path):
    p = tmp_path / "a.npz"
    np.savez(p, k_x=[0.9, 1.3], k_v=[-0.5, 0.0], k_a=[1.1, 0.6], t=[0.0, 0.1], vehicle=[3, 4])
    g = read_gains(p)
    assert_array_equal(g.K, [[0.9, -0.5, 1.1], [1.3, 0.0, 0.6]])
    assert g.rows()[0] == {"t": 0.0, "vehicle": 3, "k_x": 0.9, "k_v": -0.5, "k_a": 1.1}
    np.savez(p, K=np.array([[0.9, -0.5, 1.1]]), vehicle=np.array(["lead"]))
    g = read_gains(p)
    assert_array_equal(g.K, [[0.9, -0.5, 1.1]])
    assert g.vehicle.tolist() == ["lead"]


@pytest.mark.parametrize("arrays, match", [
    ({"k_x": [1.0], "k_v": [1.0], "kaa": [1.0]}, r"missing array 'k_a'.*is 'kaa' a misspelling of 'k_a'\?"),
    ({"gains": np.ones((2, 3))}, r"expected arrays k_x, k_v, k_a .* or one \(n, 3\) array K; found 'gains' \(name the \(n, 3\) array 'K'\)"),
    ({"K": np.ones((2, 4))}, r"array 'K' must have shape \(n, 3\).*found shape \(2, 4\)"),
    ({"k_x": [1.0, 2.0], "k_v": [1.0], "k_a": [1.0, 2.0]}, r"array 'k_v' must be 1-D of length 2.*found shape \(1,\)"),
    ({"k_x": [1.0, np.nan], "k_v": [1.0, 1.0], "k_a": [1.0, 1.0]}, r"array 'k_x', index 1: expected a finite number; found nan"),
    ({"K": np.array([[1.0, 1.0, np.inf]])}, r"array 'k_a', index 0: expected a finite number; found inf"),
    ({"k_x": ["a"], "k_v": [1.0], "k_a": [1.0]}, r"array 'k_x' must be real numbers; found dtype <U1"),
    ({"k_x": [], "k_v": [], "k_a": []}, r"expected at least one gain triple"),
    ({"kx": [1.0], "kv": [1.0], "ka": [1.0]}, r"missing array 'k_x'.*is 'kx' a misspelling of 'k_x'\?"),
    ({}, r"empty NPZ"),
])
def test_npz_bad(tmp_path, arrays, match):
    p = tmp_path / "bad.npz"
    np.savez(p, **{k: np.asarray(v) for k, v in arrays.items()})
    with pytest.raises(StringStabError, match=match):
        read_gains(p)


def test_npz_not_an_archive_and_objects(tmp_path):
    p = _write(tmp_path, "fake.npz", "k_x,k_v,k_a\n1,1,1\n")
    with pytest.raises(StringStabError, match=r"not an NPZ archive"):
        read_gains(p)
    q = tmp_path / "obj.npz"
    np.savez(q, k_x=np.array([1.0, None], dtype=object), k_v=[1.0, 1.0], k_a=[1.0, 1.0])
    with pytest.raises(StringStabError, match=r"object arrays are refused"):
        read_gains(q)


# --------------------------------------------------------------------------- round trips

finite = st.floats(allow_nan=False, allow_infinity=False, width=64)


@given(
    K=st.lists(st.tuples(finite, finite, finite), min_size=1, max_size=8),
    with_t=st.booleans(),
    vehicles=st.sampled_from([None, "int", "str"]),
)
def test_round_trip_every_format(tmp_path_factory, K, with_t, vehicles):
    """Writing a table in each format and reading it back gives identical floats."""
    d = tmp_path_factory.mktemp("rt")
    n = len(K)
    arr = np.asarray(K, dtype=float).reshape(n, 3)
    t = np.linspace(0.0, 1.0, n) / 3 if with_t else None
    veh = None if vehicles is None else (
        np.arange(n) + 1 if vehicles == "int" else np.array([f"v{i}" for i in range(n)])
    )
    g = GainTable(arr[:, 0], arr[:, 1], arr[:, 2], t, veh, source="rt")
    rows = g.rows()
    write_results(rows, d / "g.csv", "csv")
    write_results(rows, d / "g.json", "json")
    np.savez(d / "g.npz", **{c: np.asarray([r[c] for r in rows]) for c in g.columns})
    for name in ("g.csv", "g.json", "g.npz"):
        back = read_gains(d / name)
        assert_array_equal(back.K, arr, err_msg=name)
        if with_t:
            assert_array_equal(back.t, t, err_msg=name)
        else:
            assert back.t is None
        assert back.rows() == rows, name


# --------------------------------------------------------------------------- writing

RECORDS = [
    {"t": 0.5, "k_x": 1.0, "k_v": 0.5, "k_a": 0.2, "hurwitz": True, "verdict": "certified",
     "sup_gain": 1.0, "margin": 0.1, "taylor_derived": {"sign": "stable", "psi3": 0.7}},
    {"t": 0.6, "k_x": -1.0, "k_v": 0.5, "k_a": 0.2, "hurwitz": False, "verdict": "not_certified",
     "sup_gain": None, "margin": float("-inf"), "taylor_derived": {"sign": "unstable", "psi3": -1.0}},
]
PARAMS = {"tau": 0.1, "delta": 0.2, "headway": 1.1, "method": "exact"}
SUMMARY = {"n": 2, "certified": 1, "not_certified": 1, "inconclusive": 0, "certified_row_share": 0.5}


def test_format_json_is_strict_json():
    text = format_results(RECORDS, "json", params=PARAMS, summary=SUMMARY)
    doc = json.loads(text, parse_constant=lambda c: pytest.fail(f"non-JSON constant {c}"))
    assert list(doc) == ["params", "results", "summary"]
    assert doc["results"][1]["sup_gain"] is None and doc["results"][1]["margin"] is None
    assert doc["results"][0]["taylor_derived"] == {"sign": "stable", "psi3": 0.7}
    assert text.splitlines()[3].startswith('  {"t": 0.5,')  # one result per line
    assert json.loads(format_results([], "json")) == {"results": []}


def test_format_csv_flattens_and_repeats_params():
    rows = list(csv.DictReader(io.StringIO(format_results(RECORDS, "csv", params=PARAMS))))
    assert rows[0]["taylor_derived_sign"] == "stable"
    assert rows[1]["sup_gain"] == "" and rows[1]["tau"] == "0.1" and rows[1]["method"] == "exact"
    assert float(rows[0]["taylor_derived_psi3"]) == 0.7


def test_format_table():
    text = format_results(RECORDS, "table", params=PARAMS, summary=SUMMARY)
    lines = text.splitlines()
    assert lines[0] == "# tau = 0.1, delta = 0.2, headway = 1.1, method = exact"
    assert lines[1].split()[:4] == ["t", "k_x", "k_v", "k_a"]
    assert "inf" in lines[3].split() and "not_certified" in lines[3]
    assert lines[-1].startswith("# n = 2, certified = 1")
    with pytest.raises(StringStabError, match=r"output format must be one of table, json, csv; got 'xml'"):
        format_results(RECORDS, "xml")


def test_write_results_atomic(tmp_path):
    out = tmp_path / "r.json"
    out.write_text("old")
    write_results(RECORDS, out, "json", params=PARAMS, summary=SUMMARY)
    assert json.loads(out.read_text())["summary"] == SUMMARY
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.json"]  # no temp file left
    with pytest.raises(StringStabError, match=r"cannot write .*Not a directory"):
        write_results(RECORDS, tmp_path / "r.json" / "no" / "dir.json", "json")  # through a file
    write_results(RECORDS, tmp_path / "no" / "dir.json", "json")  # missing folders are created
    write_results(RECORDS, tmp_path / "here.json", "json")
    assert (tmp_path / "no" / "dir.json").read_bytes() == (tmp_path / "here.json").read_bytes()
    buf = io.StringIO()
    write_results(RECORDS, buf, "csv")
    assert buf.getvalue().startswith("t,k_x,k_v,k_a,hurwitz")


def test_write_results_to_an_ascii_stream():
    raw = io.BytesIO()
    stream = io.TextIOWrapper(raw, encoding="ascii")
    write_results(RECORDS, stream, "table", params=PARAMS)
    stream.flush()
    text = raw.getvalue().decode("ascii")
    assert "sup|?|" in text and "not_certified" in text
