"""Measures of synthesized models: objects, patterns, label and pattern frequencies.

These quantify what a model contains, to compare the outputs of different algorithms or
settings (the expressiveness of Alg. 3.4 with small blocks, Sec. 3.3.6; the bias of a
sampler).

Examples
--------
>>> import numpy as np
>>> g = np.array([[0, 0, 0, 0], [0, 1, 1, 0], [0, 0, 0, 0], [0, 2, 0, 0]])
>>> objects(g, background=[0])
{'objects': 2, 'largest_object': 2, 'largest_extent': [1, 2], 'nonempty_fraction': 0.1875}
>>> len(pattern_hashes(g, 3))                # 2x2 windows of 3x3 = 4 distinct
4
>>> unpack_hashes(pack_hashes(pattern_hashes(g, 3))).tolist() == pattern_hashes(g, 3).tolist()
True
>>> pattern_counts(np.array([[0, 1], [1, 0]]), 2, K=2).nonzero()[0].tolist()
[6]
>>> unpack_grid(pack_grid(g)).tolist() == g.tolist()
True
"""

from __future__ import annotations

import base64
import zlib
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "components",
    "dead_ends",
    "label_counts",
    "objects",
    "pack_grid",
    "pack_hashes",
    "pattern_counts",
    "pattern_distance",
    "pattern_hashes",
    "unpack_grid",
    "unpack_hashes",
]


def components(mask: ArrayLike) -> NDArray[np.int64]:
    """Connected components of the true cells (face neighbours): a root index per cell,
    ``-1`` for false cells.

    Min-label hooking with pointer jumping (vectorised), so it takes a few numpy passes
    even for long snaking objects.
    """
    m = np.asarray(mask, dtype=bool)
    n = m.size
    idx = np.arange(n, dtype=np.int64).reshape(m.shape)
    src_l, dst_l = [], []
    for d in range(m.ndim):
        a = np.moveaxis(m, d, 0)
        i = np.moveaxis(idx, d, 0)
        both = a[:-1] & a[1:]
        src_l.append(i[:-1][both])
        dst_l.append(i[1:][both])
    src = np.concatenate(src_l) if src_l else np.zeros(0, dtype=np.int64)
    dst = np.concatenate(dst_l) if dst_l else np.zeros(0, dtype=np.int64)
    parent = np.arange(n, dtype=np.int64)
    while src.size:
        ru, rv = parent[src], parent[dst]
        if np.array_equal(ru, rv):
            break
        lo, hi = np.minimum(ru, rv), np.maximum(ru, rv)
        np.minimum.at(parent, hi, lo)
        while True:
            p2 = parent[parent]
            if np.array_equal(p2, parent):
                break
            parent = p2
    out = np.where(m.ravel(), parent, -1)
    return out.reshape(m.shape)


def objects(grid: ArrayLike, background: Sequence[int]) -> dict[str, Any]:
    """Objects = connected groups of non-background cells.

    Returns the number of objects, the size of the largest (cells), its bounding-box extent
    per axis, and the fraction of non-background cells.
    """
    g = np.asarray(grid)
    mask = ~np.isin(g, np.asarray(background)) & (g >= 0)
    roots = components(mask).ravel()
    live = roots[roots >= 0]
    if live.size == 0:
        return {"objects": 0, "largest_object": 0, "largest_extent": [0] * g.ndim,
                "nonempty_fraction": 0.0}  # fmt: skip
    uniq, counts = np.unique(live, return_counts=True)
    big = int(uniq[np.argmax(counts)])
    coords = np.argwhere(roots.reshape(g.shape) == big)
    ext = (coords.max(axis=0) - coords.min(axis=0) + 1).tolist()
    return {
        "objects": int(uniq.size),
        "largest_object": int(counts.max()),
        "largest_extent": [int(e) for e in ext],
        "nonempty_fraction": float(mask.mean()),
    }


_MULT = np.random.default_rng(20090101).integers(1, 2**63, size=64, dtype=np.uint64) | np.uint64(1)


def pattern_hashes(grid: ArrayLike, window: int = 3) -> NDArray[np.uint64]:
    """Sorted distinct 64-bit hashes of all ``window``-wide sub-blocks (3×3 in 2D, 3×3×3
    in 3D; an axis shorter than the window is taken whole)."""
    g = np.asarray(grid, dtype=np.int64)
    w = tuple(min(window, s) for s in g.shape)
    win = sliding_window_view(g, w).reshape(-1, int(np.prod(w)))
    rows = np.unique(win, axis=0).astype(np.uint64)
    with np.errstate(over="ignore"):
        h = (rows + np.uint64(1)) * _MULT[: rows.shape[1]]
        acc = np.zeros(rows.shape[0], dtype=np.uint64)
        for j in range(rows.shape[1]):
            acc = (acc ^ h[:, j]) * np.uint64(0x9E3779B97F4A7C15)
            acc ^= acc >> np.uint64(29)
    return np.unique(acc)


def pack_hashes(h: NDArray[np.uint64]) -> str:
    """Sorted hashes -> a compact text (zlib + base64) to keep in a stats JSON."""
    return base64.b64encode(zlib.compress(np.sort(h).astype("<u8").tobytes(), 6)).decode()


def unpack_hashes(text: str) -> NDArray[np.uint64]:
    raw = zlib.decompress(base64.b64decode(text))
    return np.frombuffer(raw, dtype="<u8").astype(np.uint64)


def pack_grid(grid: ArrayLike) -> str:
    """A label grid -> compact text (shape, int32 labels, zlib, base64) for a stats JSON."""
    g = np.ascontiguousarray(np.asarray(grid, dtype="<i4"))
    head = ",".join(str(s) for s in g.shape).encode() + b";"
    return base64.b64encode(zlib.compress(head + g.tobytes(), 6)).decode()


def unpack_grid(text: str) -> NDArray[np.int32]:
    """Inverse of :func:`pack_grid`."""
    raw = zlib.decompress(base64.b64decode(text))
    head, _, body = raw.partition(b";")
    shape = tuple(int(s) for s in head.decode().split(","))
    return np.frombuffer(body, dtype="<i4").astype(np.int32).reshape(shape)


def label_counts(grid: ArrayLike, K: int) -> NDArray[np.int64]:
    """How often each label occurs."""
    g = np.asarray(grid).ravel()
    return np.bincount(g[g >= 0], minlength=K).astype(np.int64)


def pattern_counts(grid: ArrayLike, window: int, K: int) -> NDArray[np.int64]:
    """Counts of every ``window``-wide sub-block, indexed by the block's labels read as a
    base-``K`` number (length ``K ** window ** ndim``; for small ``K`` only)."""
    g = np.asarray(grid, dtype=np.int64)
    w = tuple(min(window, s) for s in g.shape)
    size = int(np.prod(w))
    if K**size > 50_000_000:
        raise ValueError(f"K={K} is too large for a dense {w} pattern histogram")
    win = sliding_window_view(g, w).reshape(-1, size)
    codes = win @ (K ** np.arange(size - 1, -1, -1, dtype=np.int64))
    return np.bincount(codes, minlength=K**size).astype(np.int64)


def _patterns(grid: ArrayLike) -> dict[bytes, float]:
    """Frequencies of the distinct 2-wide sub-blocks."""
    g = np.asarray(grid, dtype=np.int64)
    w = tuple(min(2, s) for s in g.shape)
    win = np.ascontiguousarray(sliding_window_view(g, w).reshape(-1, int(np.prod(w))))
    keys, counts = np.unique(win.view(np.dtype((np.void, 8 * win.shape[1]))).reshape(-1),
                             return_counts=True)  # fmt: skip
    total = float(counts.sum())
    return {bytes(k): float(c) / total for k, c in zip(keys, counts, strict=True)}


def pattern_distance(grid: ArrayLike, example: ArrayLike) -> float:
    """Total variation distance between the 2-wide sub-block frequencies of ``grid`` and
    ``example`` (0: same patterns, same proportions; 1: no pattern in common).

    Examples
    --------
    >>> import numpy as np
    >>> e = np.array([[0, 1], [1, 0]])
    >>> pattern_distance(np.tile(e, (3, 3)), e) > 0, pattern_distance(e, e)
    (True, 0.0)
    """
    p, q = _patterns(grid), _patterns(example)
    return float(0.5 * sum(abs(p.get(k, 0.0) - q.get(k, 0.0)) for k in p.keys() | q.keys()))


#: where each piece of a path example connects (label name -> unit offsets), ``loops``
_CONNECTS = {
    "path_x": ((-1, 0), (1, 0)), "path_y": ((0, -1), (0, 1)),
    "corner_+x+y": ((1, 0), (0, 1)), "corner_-x+y": ((-1, 0), (0, 1)),
    "corner_+x-y": ((1, 0), (0, -1)), "corner_-x-y": ((-1, 0), (0, -1)),
}  # fmt: skip


def dead_ends(grid: ArrayLike, names: tuple[str, ...] | None) -> int | None:
    """Connections of path pieces that their neighbour does not return (thesis Fig. 5.1's
    dead ends; connections leaving the grid are not counted), for examples whose label
    names say where pieces connect; ``None`` for other examples.

    Examples
    --------
    >>> names = ("empty", "path_x", "path_y", "corner_+x+y", "corner_-x+y")
    >>> dead_ends([[0, 0], [1, 0], [0, 0]], names)      # a lone x piece: both ends open
    2
    """
    if not names or not any(n in _CONNECTS for n in names):
        return None
    g = np.asarray(grid)
    conn = {i: _CONNECTS.get(n, ()) for i, n in enumerate(names)}
    count = 0
    for (x, y), b in np.ndenumerate(g):
        for dx, dy in conn.get(int(b), ()):
            u, v = x + dx, y + dy
            if not (0 <= u < g.shape[0] and 0 <= v < g.shape[1]):
                continue
            if (-dx, -dy) not in conn.get(int(g[u, v]), ()):
                count += 1
    return count
