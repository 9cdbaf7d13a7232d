"""Geometry synthesis (Lagae, Dumont & Dutré 2004): block matching on a signed distance field.

Analysis: the example's closed solids are sampled on a voxel grid (``resolution`` samples
along the longest side) as a signed distance field (inside negative; exact point location,
Euclidean distance transforms), quantized to 256 values. Every block of ``block`` samples
per side (a power of 2) gets a *block pyramid* (levels ``1, 2, 4, ... block`` samples per
side, by averaging, Sec. 4.1); the pyramids form a search tree whose nodes at one level with
identical quantized content are one node (Fig. 3b). Matching (Sec. 4.3) is a best-first
search: a priority queue of nodes by their distance to the query's pyramid at their level
(mean squared difference, Eq. 1); since a finer level is never closer (Eq. 2), the first leaf
popped is the best block. :func:`match_speedup` times it against a linear search.

Synthesis (Sec. 5.1): the target field starts as random source samples; blocks are placed
in scan order half a block apart (7/8 of each block already synthesized in 3D), and the
best-matching source block is copied into each; with ``levels > 1`` (Sec. 5.2) the passes
run from the source subsampled ``2^(levels-1)`` times to the full field, each seeded with
the previous result. The surface is the zero level
set (scikit-image marching cubes, the field padded with outside so that the mesh is closed).

Examples
--------
>>> from csplab.examples.continuous3d import load_polyhedral_example
>>> field = signed_distance(load_polyhedral_example("houses"), 12)
>>> field.shape, bool((field < 0).any() and (field > 0).any())
((12, 9, 12), True)
"""

from __future__ import annotations

import heapq
import itertools
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.deps import require
from csplab.errors import InputError
from csplab.rng import RngLike, make_rng

__all__ = [
    "SearchTree",
    "geometry",
    "geometry_synthesis",
    "match_speedup",
    "occupancy",
    "signed_distance",
    "surface",
]


def signed_distance(model: Any, resolution: int = 32) -> NDArray[np.float64]:
    """The signed distance field of a polyhedral model's solids (voxel units, negative
    inside) on a grid with ``resolution`` samples along the longest side of its bounds."""
    ndi = require("scipy.ndimage", "mesh", "the geometry baseline")
    if resolution < 4:
        raise InputError(f"resolution must be >= 4, not {resolution}")
    b = np.array(model.bounds, dtype=np.float64)
    lo, hi = b[:3], b[3:]
    h = float((hi - lo).max()) / (resolution - 1)
    shape = tuple(int(np.ceil((hi[a] - lo[a]) / h)) + 1 for a in range(3))
    inside = occupancy(model, [lo[a] + h * (np.arange(shape[a]) + 0.5e-3) for a in range(3)])
    out: NDArray[np.float64] = ndi.distance_transform_edt(~inside) - ndi.distance_transform_edt(
        inside
    )
    return out


def occupancy(model: Any, axes: Sequence[NDArray[np.float64]]) -> NDArray[np.bool_]:
    """Whether each point of the grid ``axes[0] x axes[1] x axes[2]`` is inside a solid."""
    pts = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    out: NDArray[np.bool_] = (model.labels_at(pts) > 0).reshape([len(x) for x in axes])
    return out


def _quantize(f: NDArray[np.float64], lo: float, hi: float) -> NDArray[np.int64]:
    q = np.rint((np.clip(f, lo, hi) - lo) / max(hi - lo, 1e-12) * 255.0)
    return np.asarray(q, dtype=np.int64)


@dataclass
class SearchTree:
    """Block pyramids of every ``block``-sided block of the field ``sdf`` in a tree
    (Sec. 4.1)."""

    sdf: NDArray[np.float64]
    block: int
    lo: float = 0.0
    hi: float = 1.0
    levels: list[NDArray[np.int64]] = field(default_factory=list)  # per level: (blocks, n^3)
    children: list[dict[int, list[int]]] = field(default_factory=list)
    keys: list[NDArray[np.int64]] = field(default_factory=list)  # node id of each block
    nodes: list[NDArray[np.int64]] = field(default_factory=list)  # content of each node
    corners: NDArray[np.int64] = field(default_factory=lambda: np.zeros((0, 3), np.int64))

    @classmethod
    def build(cls, f: NDArray[np.float64], block: int) -> SearchTree:
        if block < 2 or block & (block - 1) or any(s < block for s in f.shape):
            raise InputError(f"block must be a power of 2 no larger than the field {f.shape}")
        lo, hi = float(f.min()), float(f.max())
        t = cls(f, block, lo, hi)
        view = np.lib.stride_tricks.sliding_window_view(f, (block,) * 3)
        nb = view.shape[:3]
        t.corners = np.array(list(np.ndindex(*nb)), dtype=np.int64)
        full = view.reshape(-1, block, block, block)
        n = 1
        while n <= block:
            s = block // n  # averaging windows of s samples per side
            lev = full.reshape(-1, n, s, n, s, n, s).mean(axis=(2, 4, 6)).reshape(-1, n**3)
            q = _quantize(lev, lo, hi)
            content, key = np.unique(q, axis=0, return_inverse=True)
            t.levels.append(q)
            t.keys.append(key.reshape(-1))
            t.nodes.append(content)
            n *= 2
        # children: node ids of level l+1 under each node of level l (and the root)
        t.children.append({0: sorted(set(t.keys[0].tolist()))})
        for lvl in range(len(t.keys) - 1):
            ch: dict[int, set[int]] = {}
            for a, b2 in zip(t.keys[lvl].tolist(), t.keys[lvl + 1].tolist(), strict=True):
                ch.setdefault(a, set()).add(b2)
            t.children.append({k: sorted(v) for k, v in ch.items()})
        return t

    def pyramid(self, query: NDArray[np.float64]) -> list[NDArray[np.float64]]:
        b = self.block
        out = []
        n = 1
        while n <= b:
            s = b // n
            lev = query.reshape(n, s, n, s, n, s).mean(axis=(1, 3, 5)).reshape(-1)
            out.append(_quantize(lev, self.lo, self.hi).astype(np.float64))
            n *= 2
        return out

    def best(self, query: NDArray[np.float64]) -> tuple[int, int]:
        """Best-first search (Fig. 4): the index of a best block and the nodes visited."""
        pyr = self.pyramid(query)
        heap: list[tuple[float, int, int]] = [(0.0, -1, 0)]  # (distance, level, node)
        visited = 0
        leaves = len(self.nodes) - 1
        while heap:
            _, lvl, node = heapq.heappop(heap)
            visited += 1
            if lvl == leaves:
                return int(np.flatnonzero(self.keys[lvl] == node)[0]), visited
            kids = self.children[lvl + 1][node]
            content = self.nodes[lvl + 1][kids]
            dist = ((content - pyr[lvl + 1][None, :]) ** 2).mean(axis=1)
            for d, k in zip(dist.tolist(), kids, strict=True):
                heapq.heappush(heap, (d, lvl + 1, k))
        raise AssertionError("the tree has leaves")  # pragma: no cover

    def linear(self, query: NDArray[np.float64]) -> int:
        """The best block by comparing the query with every block (the reference)."""
        q = self.pyramid(query)[-1]
        d = ((self.levels[-1] - q[None, :]) ** 2).mean(axis=1)
        return int(d.argmin())


def match_speedup(
    model: Any, resolution: int = 32, block: int = 8, queries: int = 20, rng: RngLike = 0
) -> dict[str, float]:
    """Lagae's Table 1 measure: tree search against linear search on random query blocks
    of the model's own field (noisy copies), the same best distance required."""
    f = signed_distance(model, resolution)
    t0 = time.perf_counter()
    tree = SearchTree.build(f, block)
    build = time.perf_counter() - t0
    gen, _ = make_rng(rng)
    tt = tl = 0.0
    agree = 0
    for _ in range(queries):
        c = tree.corners[int(gen.integers(len(tree.corners)))]
        q = f[tuple(slice(a, a + block) for a in c)] + gen.normal(0, 0.5, (block,) * 3)
        a = time.perf_counter()
        bi, _ = tree.best(q)
        b = time.perf_counter()
        li = tree.linear(q)
        c2 = time.perf_counter()
        tt += b - a
        tl += c2 - b
        pq = tree.pyramid(q)[-1]
        agree += int(np.isclose(((tree.levels[-1][bi] - pq) ** 2).mean(),
                                ((tree.levels[-1][li] - pq) ** 2).mean()))  # fmt: skip
    return {
        "blocks": float(len(tree.corners)),
        "nodes": float(sum(len(n) for n in tree.nodes)),
        "build_s": build,
        "tree_s": tt / queries,
        "linear_s": tl / queries,
        "speedup": tl / max(tt, 1e-12),
        "agree": agree / queries,
    }


def _pass(f: NDArray[np.float64], target: NDArray[np.float64], block: int) -> NDArray[np.float64]:
    """One single-resolution synthesis pass over ``target`` with source field ``f``."""
    shape = target.shape
    tree = SearchTree.build(f, block)
    step = block // 2
    starts = [list(range(0, s - block + 1, step)) or [0] for s in shape]
    for a in range(3):  # the last block flush with the far side
        if starts[a][-1] != shape[a] - block:
            starts[a].append(shape[a] - block)
    for c in itertools.product(*starts):
        win = tuple(slice(x, x + block) for x in c)
        bi, _ = tree.best(target[win])
        src = tree.corners[bi]
        target[win] = f[tuple(slice(x, x + block) for x in src)]
    return target


def _down(f: NDArray[np.float64], k: int) -> NDArray[np.float64]:
    """``f`` averaged over ``k``-sided cubes (the sides cut to multiples of ``k``)."""
    n = [s // k for s in f.shape]
    g = f[: n[0] * k, : n[1] * k, : n[2] * k].reshape(n[0], k, n[1], k, n[2], k)
    out: NDArray[np.float64] = g.mean(axis=(1, 3, 5))
    return out


def geometry_synthesis(
    model: Any,
    size: Sequence[int],
    *,
    resolution: int = 24,
    block: int = 8,
    levels: int = 1,
    rng: RngLike = None,
) -> NDArray[np.float64]:
    """A synthesized signed distance field of ``size`` samples: single resolution
    (``levels=1``, Sec. 5.1) or multiresolution (Sec. 5.2: the first pass on the source
    subsampled ``2^(levels-1)`` times, each next pass on the previous result upsampled, the
    block size in samples the same at every level, so coarse passes place large features)."""
    shape = tuple(int(s) for s in size)
    if len(shape) != 3 or any(s < block for s in shape):
        raise InputError(f"size {shape} must be three sides of at least block={block}")
    if levels < 1:
        raise InputError(f"levels must be >= 1, not {levels}")
    gen, _ = make_rng(rng)
    f = signed_distance(model, resolution)
    target: NDArray[np.float64] | None = None
    for lvl in range(levels - 1, -1, -1):
        k = 2**lvl
        src = _down(f, k) if k > 1 else f
        tshape = tuple(max(block, s // k) for s in shape)
        if any(s < block for s in src.shape):
            continue  # too coarse for a block: start at a finer level
        if target is None:
            t = gen.choice(src.reshape(-1), size=tshape)
        else:  # the previous (coarser) result, upsampled by repetition
            up = np.repeat(np.repeat(np.repeat(target, 2, 0), 2, 1), 2, 2)
            t = np.empty(tshape)
            sl = tuple(slice(0, min(a, b)) for a, b in zip(tshape, up.shape, strict=True))
            t[...] = gen.choice(src.reshape(-1), size=tshape)
            t[sl] = up[sl]
        target = _pass(src, t, block)
    assert target is not None
    if target.shape != shape:  # the finest level has the requested size
        target = _pass(f, np.resize(target, shape), block)
    return np.asarray(target, dtype=np.float64)


def surface(sdf: NDArray[np.float64]) -> Any:
    """The zero level set as a closed ``trimesh.Trimesh`` (outside padding)."""
    measure = require("skimage.measure", "baselines", "the geometry baseline's surface")
    tm = require("trimesh", "mesh", "the geometry baseline's surface")
    pad = np.pad(sdf, 1, constant_values=max(1.0, float(sdf.max())))
    if not (pad < 0).any():
        raise InputError("the synthesized field has no inside: no surface")
    v, f, _, _ = measure.marching_cubes(pad, 0.0)
    mesh = tm.Trimesh(vertices=v - 1.0, faces=f, process=True)
    return mesh


def geometry(model: Any, size: Sequence[int], *, resolution: int = 24, **options: Any) -> Any:
    """:func:`geometry_synthesis` then :func:`surface`: a closed ``trimesh.Trimesh`` in the
    example's units (one voxel of the example's field per sample); ``options`` are
    :func:`geometry_synthesis`' others (``block``, ``levels``, ``rng``)."""
    from csplab.continuous.polyhedra import PolyhedralModel

    if not isinstance(model, PolyhedralModel):
        raise InputError("the geometry baseline takes a polyhedral model (a closed mesh)")
    sdf = geometry_synthesis(model, size, resolution=resolution, **options)
    mesh = surface(sdf)
    b = np.array(model.bounds, dtype=np.float64)
    h = float((b[3:] - b[:3]).max()) / (resolution - 1)
    mesh.apply_scale(h)
    return mesh
