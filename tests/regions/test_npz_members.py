"""The NPZ of a region map stores a member that zlib hardly shrinks and deflates the others
(issue 31: an 801² map's margin, assorted floats, took most of the archive's time for 15 %)."""

from __future__ import annotations

import zipfile
import zlib

import numpy as np

from stringstab.regions import files


def _npz(tmp_path, fields):
    path = files.write_npz(tmp_path / "m.npz", {"k_x": np.linspace(-2, 2, 3)}, fields,
                           {"format": files.FORMAT})
    with zipfile.ZipFile(path) as z:
        kinds = {i.filename[:-4]: i.compress_type for i in z.infolist()}
    return path, kinds


def test_incompressible_members_are_stored_and_read_back(tmp_path):
    rng = np.random.default_rng(0)
    noise = rng.standard_normal(200_000)  # assorted floats: zlib shrinks them little
    noise[:20_000] = np.inf  # a constant first region: the sample must look further
    flat = np.ones(200_000)  # one value: deflates to almost nothing
    codes = rng.integers(0, 3, 200_000).astype(np.int8)  # 3 symbols in a byte: deflates
    small = rng.standard_normal(10)  # small members are deflated whatever they hold
    fields = {"noise": noise, "flat": flat, "codes": codes, "small": small}
    path, kinds = _npz(tmp_path, fields)
    assert kinds["noise"] == zipfile.ZIP_STORED
    assert {kinds[k] for k in ("flat", "codes", "small", "metadata", "axis_k_x")} == {
        zipfile.ZIP_DEFLATED}
    assert [files.compresses(a) for a in fields.values()] == [False, True, True, True]
    with np.load(path) as back:  # numpy reads both kinds, bit for bit
        for k, a in fields.items():
            assert back[k].dtype == a.dtype and back[k].tobytes() == a.tobytes()


def test_the_sample_decides_as_the_whole_array_does():
    """On arrays whose halves differ, the spread sample's verdict is the whole array's."""
    rng = np.random.default_rng(1)
    decided = set()
    for _ in range(40):
        n = int(rng.integers(20_000, 300_000))
        a = rng.standard_normal(n)
        a[: int(rng.integers(0, n // 2))] = 1.0  # a constant part of random length
        whole = len(zlib.compress(a.tobytes(), 1)) / a.nbytes
        if abs(whole - files.DEFLATE_RATIO) > 0.05:  # clear cases only
            assert files.compresses(a) == (whole <= files.DEFLATE_RATIO), (n, whole)
            decided.add(whole <= files.DEFLATE_RATIO)
    assert decided == {True, False}  # both kinds were met
