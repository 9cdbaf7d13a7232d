"""``.npy`` outputs are written in slabs: the bytes of ``np.save``, the file's label ids."""

import io

import numpy as np
import pytest

from csplab.io import npy
from csplab.io.common import Output


@pytest.mark.parametrize(
    "grid",
    [np.arange(24).reshape(2, 3, 4) % 5, np.zeros((0, 3), dtype=int), np.array([[0, -1], [1, 0]]),
     np.arange(3000).reshape(300, 10) % 7],
)
@pytest.mark.parametrize("slab", [1, 7, 1 << 22])
def test_slabs_write_the_bytes_of_np_save(monkeypatch, tmp_path, grid, slab):
    monkeypatch.setattr(npy, "SLAB_CELLS", slab)
    path = tmp_path / "g.npy"
    npy.write_output(Output.of(grid), path)
    want = io.BytesIO()
    np.save(want, np.asarray(grid, dtype=np.int32))
    assert path.read_bytes() == want.getvalue()


def test_label_ids_beyond_int32_are_written_as_int64(monkeypatch, tmp_path):
    monkeypatch.setattr(npy, "SLAB_CELLS", 2)
    grid = np.array([[0, 1], [1, -1], [0, 0]])
    path = tmp_path / "g.npy"
    npy.write_output(Output.of(grid, meta={"label_ids": (5, 2**40)}), path)
    got = np.load(path)
    assert got.dtype == np.int64
    assert got.tolist() == [[5, 2**40], [2**40, -1], [5, 5]]


@pytest.mark.parametrize("slab", [1, 1 << 22])
def test_label_ids_within_int32_write_the_bytes_of_np_save(monkeypatch, tmp_path, slab):
    monkeypatch.setattr(npy, "SLAB_CELLS", slab)
    grid = np.array([[0, 1, -1], [1, 1, 0]], dtype=np.int32)
    path = tmp_path / "g.npy"
    npy.write_output(Output.of(grid, meta={"label_ids": (7, 2**31 - 1)}), path)
    want = io.BytesIO()
    np.save(want, np.array([[7, 2**31 - 1, -1], [2**31 - 1, 2**31 - 1, 7]], dtype=np.int32))
    assert path.read_bytes() == want.getvalue()

