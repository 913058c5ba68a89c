"""The faster CSV writer (issue 31 item 2) writes the same bytes as the writer it replaced.

The reference is the previous writer, kept here verbatim (``_old_render_csv``: every float
cast to text then nulled where missing, booleans as NumPy strings, the text decoded from
Arrow's buffer and joined).  :func:`stringstab.io.text_formats.render_csv` and
:func:`~stringstab.io.text_formats.write_csv` must give its text byte for byte on columns of
every kind and edge value, and a region map's CSV file (:meth:`RegionMap.save_csv`, now
streamed to the file) the reference's text of its columns.
"""

from __future__ import annotations

import io
import json
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.csv as pa_csv
import pytest

from stringstab.io import Categorical, dumps_json
from stringstab.io.columns import Leaf, flat_leaves, n_rows, normalise_columns
from stringstab.io.plain import to_plain
from stringstab.io.table import human_value
from stringstab.io.text_formats import render_csv, write_csv
from stringstab.regions import region_map


# --------------------------------------------------------------------------- the old writer
def _mapped(values, fn: Callable[[Any], str]):
    uniq, inverse = np.unique(values, return_inverse=True)
    return pa.array([fn(u) for u in uniq.tolist()], type=pa.string()).take(pa.array(np.ravel(inverse)))


def _old_cells(leaf: Leaf, style: str):
    if leaf.codes is not None:
        return _old_cells(Leaf(leaf.base, None), style).take(pa.array(leaf.codes))
    v = leaf.values
    mask = leaf.mask
    k = leaf.kind
    if k == "f":
        bad = ~np.isfinite(v)
        if bad.any():
            mask = bad if mask is None else (mask | bad)
        s = pc.cast(pa.array(v, type=pa.float64()), pa.string())
        whole = (np.abs(v) < 1e15) & (np.trunc(v) == v)
        if whole.any():
            as_int = pc.cast(pa.array(np.where(whole, v, 0.0).astype(np.int64)), pa.string())
            s = pc.if_else(pa.array(whole), pc.binary_join_element_wise(as_int, ".0", ""), s)
            negative_zero = whole & (v == 0.0) & np.signbit(v)
            if negative_zero.any():
                s = pc.if_else(pa.array(negative_zero), pa.scalar("-0.0", pa.string()), s)
    elif k == "i":
        s = pc.cast(pa.array(v, type=pa.int64()), pa.string())
    elif k == "b":
        t, f = ("true", "false") if style == "json" else ("True", "False")
        s = pa.array(np.where(v, t, f), type=pa.string())
    else:
        if style == "json":
            s = _mapped(v, lambda x: json.dumps(x, ensure_ascii=False))
        else:
            s = _mapped(v, _csv_quote)
    if mask is not None and mask.any():
        s = pc.if_else(pa.array(mask), pa.scalar(None, pa.string()), s)
    return s


def _filled(cells, text: str):
    return pc.fill_null(cells, text) if cells.null_count else cells


def _csv_quote(x: str) -> str:
    if any(c in x for c in ',"\r\n') or x != x.strip():
        return '"' + x.replace('"', '""') + '"'
    return x


def _join_rows(rows, sep: str) -> str:
    if len(rows) == 0:
        return ""
    ended = pc.binary_join_element_wise(rows.cast(pa.large_string()),
                                        pa.scalar(sep, pa.large_string()),
                                        pa.scalar("", pa.large_string()))
    offsets = np.frombuffer(ended.buffers()[1], dtype=np.int64, count=len(ended) + 1,
                            offset=8 * ended.offset)
    data = ended.buffers()[2]
    end = int(offsets[-1]) - len(sep.encode("utf-8"))
    return data[int(offsets[0]):end].to_pybytes().decode("utf-8")


def _params_flat(params: Mapping[str, Any] | None) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in to_plain(dict(params or {})).items():
        if isinstance(v, Mapping):
            continue
        if isinstance(v, list):
            v = ",".join(human_value(x) for x in v)
        out[k] = v
    return out


def _csv_cell(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return repr(v)
    return _csv_quote(str(v))


def _old_render_csv(columns, params=None) -> str:
    cols = normalise_columns(columns)
    flat = flat_leaves(cols)
    n = n_rows(cols)
    extra = {k: v for k, v in _params_flat(params).items() if k not in flat}
    header = ",".join(_csv_quote(h) for h in [*flat, *extra])
    if n == 0:
        return header + "\n"
    pieces = [_filled(_old_cells(leaf, "csv"), "") for leaf in flat.values()]
    extra_cells = [_csv_cell(v) for v in extra.values()]
    pieces += [pa.repeat(pa.scalar(c, pa.string()), n) for c in extra_cells]
    quoted = any(c.startswith('"') for c in extra_cells) or any(
        any(_csv_quote(str(x)) != str(x) for x in leaf.base.tolist()) if leaf.codes is not None
        else pc.any(pc.starts_with(cells, '"')).as_py()
        for leaf, cells in zip(flat.values(), pieces) if leaf.kind not in "bif")
    if not quoted:
        buf = io.BytesIO()
        table = pa.table({str(i): p for i, p in enumerate(pieces)})
        pa_csv.write_csv(table, buf, pa_csv.WriteOptions(include_header=False,
                                                         quoting_style="none"))
        return header + "\n" + buf.getvalue().decode("utf-8")
    rows = pc.binary_join_element_wise(*pieces, ",")
    return header + "\n" + _join_rows(rows, "\n") + "\n"


# --------------------------------------------------------------------------- the cases
EDGE = np.array([0.0, -0.0, 1.0, -1.0, 0.1, 1e-05, 5e-324, 2.5, 1e15, -1e15, 1e15 - 1.0, 1e16,
                 2.0 ** 53, 2.0 ** 53 + 2.0, 1e22, 1.7976931348623157e308, -123456789.0,
                 float("nan"), float("inf"), float("-inf"), 0.30000000000000004, 3.0e-7])


def _floats(rng: np.random.Generator, n: int) -> np.ndarray:
    kind = rng.integers(4)
    if kind == 0:
        return rng.choice(EDGE, n)
    if kind == 1:  # integral values of every size, some non-finite
        v = np.round(rng.normal(0, 10.0 ** rng.integers(0, 17), n))
        v[rng.random(n) < 0.2] = np.nan
        return v
    if kind == 2:
        return rng.normal(0, 10.0 ** rng.integers(-8, 9), n)
    return np.where(rng.random(n) < 0.5, rng.choice(EDGE, n), rng.standard_cauchy(n))


def _columns(rng: np.random.Generator, n: int) -> dict[str, Any]:
    cols: dict[str, Any] = {
        "f": _floats(rng, n),
        "f32": np.clip(_floats(rng, n), -3e38, 3e38).astype(np.float32),
        "i": rng.integers(-10 ** 12, 10 ** 12, n),
        "u": rng.integers(0, 300, n).astype(np.uint16),
        "b": rng.random(n) < 0.5,
        "cat": Categorical(rng.integers(0, 3, n), np.array([-0.0, 0.5, 2.0])),
        "label": Categorical(rng.integers(0, 2, n), np.array(["certified", "not_certified"])),
        "group": {"psi1": _floats(rng, n), "ok": rng.random(n) < 0.3},
    }
    with_none = rng.random(n) < 0.3  # missing values (None) in object columns
    cols["f_none"] = np.array([None if m else float(x) for m, x in zip(with_none, _floats(rng, n))],
                              dtype=object)
    cols["b_none"] = np.array([None if m else bool(x) for m, x in zip(with_none, rng.random(n) < 0.5)],
                              dtype=object)
    cols["i_none"] = np.array([None if m else int(x) for m, x in zip(with_none, rng.integers(-5, 5, n))],
                              dtype=object)
    if rng.random() < 0.5:  # text that needs quotes: the other row writer
        cols["text"] = rng.choice(np.array(["a", 'say "hi"', "x,y", " pad", "Γ ≤ 1"]), n)
    return cols


@pytest.mark.parametrize("seed", range(40))
def test_csv_writer_gives_the_old_writers_bytes(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.choice([0, 1, 2, 7, 300]))
    cols = _columns(rng, n)
    params = {"tau": 0.1, "box": [0.1, 0.3], "name": "a,b" if seed % 3 == 0 else "plain",
              "nested": {"x": 1}} if seed % 2 else None
    old = _old_render_csv(cols, params)
    assert render_csv(cols, params) == old
    buf = io.BytesIO(b"prefix")
    buf.seek(len(b"prefix"))
    write_csv(cols, buf, params)
    assert buf.getvalue() == b"prefix" + old.encode("utf-8")  # written from its position


def test_the_comparison_can_fail():
    cols = {"f": np.array([1.0, 0.5])}
    assert _old_render_csv(cols) == "f\n1.0\n0.5\n"
    assert render_csv({"f": np.array([1.0, 0.25])}) != _old_render_csv(cols)


def test_region_map_csv_file_has_the_old_writers_bytes(tmp_path):
    g = np.linspace(-2, 2, 23)
    m = region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1,
                   workers=1, progress=False)
    assert np.isinf(m.sup_gain).any() and (m.sup_gain == 1.0).any()  # empty and integral cells
    comments = [f"stringstab {m.version} region map", dumps_json(m.metadata(), indent=None).rstrip("\n")]
    expected = "".join(f"# {c}\n" for c in comments) + _old_render_csv(m.columns())
    path = m.save_csv(tmp_path / "m.csv")
    assert path.read_bytes() == expected.encode("utf-8")
    assert m.csv_text() == expected
