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

    Unassigned cells are written as ``-1``.

    Parameters
    ----------
    out : Output
        The grid to write, with its model's names, meta (its file's label ids are written).
    path : Path
        The file to write (overwritten).
    """

    import io

    from csplab.io.common import write_atomic

    g = out.file_grid()
    buf = io.BytesIO()
    np.save(buf, g.astype(np.int32) if g.size == 0 or g.max() <= 2**31 - 1 else g)
    write_atomic(path, buf.getvalue())
