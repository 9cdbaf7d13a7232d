"""NumPy ``.npy`` label grids: an int array indexed ``[x, y, z]`` (``-1`` = unassigned in
results).

Examples
--------
>>> import tempfile, pathlib
>>> from csplab.io.common import Output
>>> with tempfile.TemporaryDirectory() as d:
...     p = pathlib.Path(d) / "g.npy"
...     write_output(Output.of([[0, 1], [1, 0]]), p)
...     read_npy(p).labels.tolist()
[[0, 1], [1, 0]]
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.errors import FormatError, InputError
from csplab.example import ExampleModel
from csplab.io.common import NO, SURE, Output

__all__ = ["read_npy", "sniff", "write_output"]

MAGIC = b"\x93NUMPY"


def sniff(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for the ``.npy`` magic number."""
    return SURE if head.startswith(MAGIC) else NO


def load_int_array(path: str | Path) -> NDArray[np.integer[Any]]:
    """The integer array of an ``.npy`` file (no pickles); one :class:`FormatError` line
    for a damaged file or another dtype."""
    p = Path(path)
    try:
        arr = np.load(p, allow_pickle=False)
    except Exception as e:  # numpy raises many kinds of errors on damaged files
        raise FormatError(f"not a readable .npy array ({e})", path=p) from None
    if not np.issubdtype(arr.dtype, np.integer):
        raise FormatError(f".npy array must hold integers, got {arr.dtype}", path=p)
    return np.asarray(arr)


def read_npy(path: str | Path) -> ExampleModel:
    """An example model from an ``.npy`` int array (no pickles).

    Parameters
    ----------
    path : str or Path
        The ``.npy`` file to read.

    Returns
    -------
    ExampleModel
        The array's labels (indexed ``[x, y, z]``), named after the file's stem.

    Raises
    ------
    FormatError
        Naming the file when it is not a readable ``.npy`` array, does not hold integers, or
        is not a valid example (negative labels, more than 4 dimensions, empty ...).
    """
    p = Path(path)
    arr = load_int_array(p)
    try:
        return ExampleModel(arr, name=p.stem, meta={"format": "npy", "source": str(p)})
    except InputError as e:
        raise FormatError(str(e), path=p) from None


def write_output(out: Output, path: Path) -> None:
    """The grid as an int32 array (int64 when the file's label ids need it).

    Unassigned cells are written as ``-1``. The file is written in slabs along the first
    axis (about :data:`SLAB_CELLS` cells each): no copy of a large grid is held.

    Parameters
    ----------
    out : Output
        The grid to write, with its model's names, meta (its file's label ids are written).
    path : Path
        The file to write (overwritten).
    """

    import io

    from csplab.example import file_labels
    from csplab.io.common import write_atomic

    g = out.grid
    rows = max(1, SLAB_CELLS // max(1, math.prod(g.shape[1:]))) if g.ndim else 1
    ids = out.meta.get("label_ids")

    def slabs(dtype: type[np.integer[Any]]) -> Iterator[NDArray[np.integer[Any]]]:
        """The file's labels slab by slab, as ``dtype`` (one conversion per slab)."""
        parts = [g] if g.ndim == 0 or not g.shape[0] else (
            g[i : i + rows] for i in range(0, g.shape[0], rows))  # fmt: skip
        for part in parts:
            yield np.asarray(part, dtype=dtype) if ids is None else file_labels(
                part, out.meta).astype(dtype, copy=False)  # fmt: skip

    # int64 only when a label id of the file needs it: read off the grid's type or the ids
    # when they fit (no pass over the grid), else from the grid's slabs
    fits = np.iinfo(np.int32).max
    if ids is None and np.can_cast(g.dtype, np.int32):
        big = False
    elif ids is not None and (not len(ids) or max(int(i) for i in ids) <= fits):
        big = False
    else:
        big = any(s.size and s.max() > fits for s in slabs(np.int64))
    dtype = np.int64 if big else np.int32
    head = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        head, {"descr": np.lib.format.dtype_to_descr(np.dtype(dtype)),
               "fortran_order": False, "shape": g.shape},
    )  # fmt: skip
    write_atomic(path, itertools.chain([head.getvalue()], (s.tobytes() for s in slabs(dtype))))


#: cells per slab written by :func:`write_output`
SLAB_CELLS = 1 << 22
