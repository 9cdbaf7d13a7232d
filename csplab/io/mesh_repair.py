"""Repairs and limits of meshes as CAD and modelling tools write them, applied by the mesh
readers (:mod:`csplab.io.meshes`) before the solids are built and validated
(:class:`~csplab.continuous.polyhedra.PolyhedralModel`).

Repaired (and reported in one note, :meth:`Repairs.note`):

* duplicate vertices (exactly equal coordinates) are merged (in STL files every triangle
  has its own copies: that is the format, not a defect, and is not reported);
* faces with fewer than 3 distinct vertices are dropped (their edges cancel);
* zero-area triangles whose three vertices are distinct (slivers: a vertex on the opposite
  edge, as CAD exports close T-junctions; a height below :data:`SLIVER_TOL` of the model's
  extent) are removed by flipping their longest edge with the neighbouring triangle
  across it, which keeps the surface closed and every other triangle's geometry;
* inconsistent winding (two faces running along an edge in the same direction) is made
  consistent over each connected shell (a breadth-first walk over the faces), and a shell
  so made is turned outward when its signed volume is negative.

Refused (one :class:`~csplab.errors.InputError` or :class:`~csplab.errors.FormatError`
line naming the file and the element): a mesh whose faces would need more memory than
the budget (:data:`BYTES_PER_FACE` each against :func:`csplab.limits.memory_budget`,
checked from the counts before the faces are read), non-finite coordinates, coordinates beyond
:data:`MAX_COORDINATE`, and solids whose surface crosses itself
(:func:`self_intersection`).

Examples
--------
>>> import numpy as np
>>> v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0], [0, 0, 2], [1, 0, 0]], dtype=float)
>>> # a tetrahedron whose bottom edge 0-1 is split at vertex 4 on one side, closed by a sliver
>>> tris = [[0, 2, 1], [0, 4, 3], [4, 1, 3], [1, 2, 3], [0, 3, 2], [0, 1, 4]]
>>> r = Repairs()
>>> out = flip_slivers(v, tris, r)
>>> r.slivers, len(out), r.note("t.stl")
(1, 6, 't.stl: repaired 1 zero-area triangle (an edge flip each)')
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from csplab.errors import InputError
from csplab.limits import check_memory

__all__ = [
    "BYTES_PER_FACE",
    "MAX_COORDINATE",
    "SLIVER_TOL",
    "Repairs",
    "check_coordinates",
    "check_face_count",
    "flip_slivers",
    "merge_duplicates",
    "orient_shell",
    "self_intersection",
]

#: the peak memory reading a triangle takes, repairs and validation included (the lists
#: and arrays of :func:`merge_duplicates`, :func:`orient_shell`, :func:`self_intersection`
#: and the model): 3.3 kB per face measured (tracemalloc peak) reading an 81,920-triangle
#: sphere as STL, OBJ and glTF, rounded up
BYTES_PER_FACE = 4096
#: the largest coordinate (absolute value) read: beyond it the model's planes and lattice
#: lose their precision and their size (a 10^9-sized tetrahedron takes minutes and GBs)
MAX_COORDINATE = 1e7
#: a triangle whose height (over its longest edge) is below this fraction of the model's
#: extent has zero area (float32 STL coordinates are exact to about 6e-8)
SLIVER_TOL = 1e-6


@dataclass
class Repairs:
    """What the readers repaired in one file (counts), and the note that says so."""

    duplicates: int = 0
    degenerate: int = 0
    slivers: int = 0
    rewound: int = 0
    outward: int = 0

    def __bool__(self) -> bool:
        return any((self.duplicates, self.degenerate, self.slivers, self.rewound, self.outward))

    def as_dict(self) -> dict[str, int]:
        """The non-zero counts (what ``meta["repaired"]`` holds)."""
        d = {"duplicate_vertices": self.duplicates, "degenerate_faces": self.degenerate,
             "zero_area_triangles": self.slivers, "rewound_faces": self.rewound,
             "outward_solids": self.outward}  # fmt: skip
        return {k: v for k, v in d.items() if v}

    def note(self, path: str | Path) -> str:
        """One line: the file and what was repaired (``""`` when nothing was).

        Examples
        --------
        >>> Repairs(duplicates=3, rewound=2, outward=1).note("p.off")
        'p.off: repaired 3 duplicate vertices (merged), 2 faces wound against their \
neighbours (reversed), 1 solid inside out after that (reversed)'
        """

        def n(k: int, one: str, many: str) -> str:
            return f"{k} {one if k == 1 else many}"

        parts = []
        if self.duplicates:
            parts.append(n(self.duplicates, "duplicate vertex", "duplicate vertices") + " (merged)")
        if self.degenerate:
            parts.append(
                n(self.degenerate, "face", "faces") + " with fewer than 3 distinct vertices "
                "(dropped)"
            )
        if self.slivers:
            parts.append(
                n(self.slivers, "zero-area triangle", "zero-area triangles")
                + " (an edge flip each)"
            )
        if self.rewound:
            parts.append(
                n(self.rewound, "face", "faces") + " wound against their neighbours (reversed)"
            )
        if self.outward:
            parts.append(n(self.outward, "solid", "solids") + " inside out after that (reversed)")
        return f"{path}: repaired {', '.join(parts)}" if parts else ""


# ---------------------------------------------------------------------------- limits
def check_face_count(n: int, path: str | Path, budget: float | None = None) -> None:
    """Refuse a mesh whose ``n`` faces would need more memory than ``budget`` bytes
    (default :func:`csplab.limits.memory_budget`), before reading them.

    Examples
    --------
    >>> check_face_count(100_000, "ok.stl", budget=1e9)
    >>> check_face_count(1_000_000, "big.stl", budget=1e9)
    Traceback (most recent call last):
    ...
    csplab.errors.MemoryLimitError: big.stl: reading 1000000 faces would need about 4.1 GB, \
over the memory budget of 1.0 GB: simplify the mesh first, or raise --memory-limit
    """
    check_memory(float(n) * BYTES_PER_FACE, f"{path}: reading {n} faces",
                 "simplify the mesh first", budget=budget)  # fmt: skip


def check_coordinates(v: NDArray[np.float64], path: str | Path, name: Callable[[int], str]) -> None:
    """Refuse non-finite coordinates and coordinates beyond :data:`MAX_COORDINATE`;
    ``name(k)`` names vertex row ``k`` in the file (``"line 7"``, ``"triangle 3"``).

    Examples
    --------
    >>> check_coordinates(np.array([[0, 0, 0], [1, np.nan, 0]]), "t.off", lambda k: f"line {k}")
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: t.off: line 1: a vertex with a non-finite coordinate \
(1.0, nan, 0.0)
    >>> check_coordinates(np.array([[4e9, 0, 0]]), "t.off", lambda k: f"line {k}")
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: t.off: line 0: coordinate 4e+09 beyond the 1e+07 csplab reads \
(scale the model down or move it towards the origin)
    """
    if not len(v):
        return
    bad = np.flatnonzero(~np.isfinite(v).all(axis=1))
    if bad.size:
        k = int(bad[0])
        xyz = ", ".join(repr(float(x)) for x in v[k])
        raise InputError(f"{path}: {name(k)}: a vertex with a non-finite coordinate ({xyz})")
    big = np.abs(v).max(axis=1)
    far = np.flatnonzero(big > MAX_COORDINATE)
    if far.size:
        k = int(far[0])
        raise InputError(
            f"{path}: {name(k)}: coordinate {float(big[k]):g} beyond the {MAX_COORDINATE:g} "
            "csplab reads (scale the model down or move it towards the origin)"
        )


# ---------------------------------------------------------------------------- repairs
def merge_duplicates(
    v: NDArray[np.float64], polys: Sequence[Sequence[int]]
) -> tuple[NDArray[np.float64], list[list[int]], int]:
    """Vertices with equal coordinates given one index (first occurrence order), faces
    renumbered with consecutive repeats dropped, and the number of duplicates merged.

    Examples
    --------
    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 0.0]])
    >>> u, f, k = merge_duplicates(v, [[0, 1, 2]])
    >>> u.tolist(), f, k
    ([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [[1, 0]], 1)
    """
    if not len(v):
        return v, [list(p) for p in polys], 0
    _, first, inv = np.unique(v + 0.0, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    remap = rank[inv.reshape(-1)]
    flat, start = _flat(polys)
    new = remap[flat]
    nxt = np.arange(len(flat)) + 1
    nxt[start[1:] - 1] = start[:-1]
    rep = np.flatnonzero(new == new[nxt])  # a vertex equal to the next one (cyclically)
    lens = np.diff(start)
    if len(set(lens.tolist())) == 1 and not rep.size:
        out = new.reshape(len(polys), -1).tolist()
    else:
        out = [new[start[j] : start[j + 1]].tolist() for j in range(len(polys))]
        for j in set(np.searchsorted(start, rep, side="right").tolist()):
            q = out[j - 1]
            out[j - 1] = [x for k, x in enumerate(q) if x != q[k - 1]] if len(q) > 1 else q
    return v[first[order]], out, len(v) - len(first)


def _flat(polys: Sequence[Sequence[int]]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The faces' vertex indices in one array and where each face starts (and the end)."""
    lens = np.fromiter((len(p) for p in polys), dtype=np.int64, count=len(polys))
    flat = np.fromiter((i for p in polys for i in p), dtype=np.int64, count=int(lens.sum()))
    return flat, np.concatenate([[0], np.cumsum(lens)]).astype(np.int64)


def _height(v: NDArray[np.float64], t: Sequence[int]) -> tuple[float, int]:
    """The triangle's height over its longest edge and that edge's position (0: t0-t1)."""
    a, b, c = v[t[0]], v[t[1]], v[t[2]]
    lens = [float(np.dot(b - a, b - a)), float(np.dot(c - b, c - b)), float(np.dot(a - c, a - c))]
    k = max(range(3), key=lens.__getitem__)
    area2 = float(np.linalg.norm(np.cross(b - a, c - a)))
    return (area2 / math.sqrt(lens[k]) if lens[k] > 0 else 0.0), k


def _thin(v: NDArray[np.float64], tris: NDArray[np.int64], tol: float) -> NDArray[np.bool_]:
    """Which triangles have a height (over the longest edge) of at most ``tol``."""
    a, b, c = v[tris[:, 0]], v[tris[:, 1]], v[tris[:, 2]]
    area2 = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    longest = np.sqrt(
        np.max([((b - a) ** 2).sum(1), ((c - b) ** 2).sum(1), ((a - c) ** 2).sum(1)], axis=0)
    )
    return np.asarray(area2 <= tol * np.maximum(longest, 1e-300))


def flip_slivers(
    v: NDArray[np.float64], polys: list[list[int]], repairs: Repairs, scale: float | None = None
) -> list[list[int]]:
    """``polys`` with every zero-area triangle (height below :data:`SLIVER_TOL` of
    ``scale``, the model's extent) removed by flipping its longest edge ``a-b`` with the
    triangle across it: the sliver ``(a, b, c)`` (``c`` on ``a-b``) and its neighbour
    ``(b, a, d)`` become ``(b, c, d)`` and ``(c, a, d)`` (a polygon neighbour instead gets
    ``c`` on its edge ``b-a`` and the sliver goes), and ``c`` moves onto the line
    ``a-b`` (in place in ``v``: by less than the tolerance). Counts go to ``repairs``; a
    sliver without a neighbour across its longest edge is left (validation names it)."""
    tri_idx = [j for j, p in enumerate(polys) if len(p) == 3]
    if not tri_idx:
        return polys
    if scale is None:
        scale = float(np.ptp(v, axis=0).max()) if len(v) else 1.0
    tol = SLIVER_TOL * max(scale, 1e-300)
    T = np.asarray([polys[j] for j in tri_idx], dtype=np.int64)
    thin = np.flatnonzero(_thin(v, T, tol))
    if not thin.size:
        return polys
    out: list[list[int] | None] = [list(p) for p in polys]
    edge: dict[tuple[int, int], int] = {}
    for j, p in enumerate(polys):
        for k in range(len(p)):
            edge.setdefault((p[k], p[(k + 1) % len(p)]), j)
    queue = [tri_idx[int(i)] for i in thin]
    fixed: set[int] = set()
    steps = 0

    def unlink(jj: int) -> None:
        p = out[jj]
        assert p is not None
        for q in range(len(p)):
            if edge.get((p[q], p[(q + 1) % len(p)])) == jj:
                del edge[(p[q], p[(q + 1) % len(p)])]

    def link(jj: int) -> None:
        p = out[jj]
        assert p is not None
        for q in range(len(p)):
            edge[(p[q], p[(q + 1) % len(p)])] = jj

    while queue and steps < 20 * len(thin) + 100:
        steps += 1
        j = queue.pop()
        t = out[j]
        if t is None or len(t) != 3:
            continue
        h, k = _height(v, t)
        if h > tol:
            continue
        a, b, c = t[k], t[(k + 1) % 3], t[(k + 2) % 3]
        n = edge.get((b, a))
        u = out[n] if n is not None and n != j else None
        if n is None or u is None or c in u:
            continue
        m = u.index(b)
        if u[(m + 1) % len(u)] != a:
            continue
        unlink(j)
        unlink(n)
        if len(u) == 3:  # flip a-b: two triangles again
            d = u[(m + 2) % 3]
            out[j], out[n] = [b, c, d], [c, a, d]
            link(j)
        else:  # a polygon: c joins its edge b-a, the sliver goes
            out[j] = None
            out[n] = [*u[: m + 1], c, *u[m + 1 :]]
        link(n)
        ab = v[b] - v[a]  # c onto the line a-b (float32 files round it off the line)
        v[c] = v[a] + ab * (float(np.dot(v[c] - v[a], ab)) / float(np.dot(ab, ab)))
        fixed.add(j)
        queue += [jj for jj in (j, n) if (f := out[jj]) is not None and len(f) == 3
                  and _height(v, f)[0] <= tol]  # fmt: skip
    still = [jj for jj in fixed if (f := out[jj]) is not None and _height(v, f)[0] <= tol]
    repairs.slivers += len(fixed) - len(still)
    return [f for f in out if f is not None]


def orient_shell(
    v: NDArray[np.float64], polys: list[list[int]], repairs: Repairs
) -> list[list[int]]:
    """A connected shell's faces wound consistently (when two faces run along an edge in
    the same direction: a breadth-first walk from face 0 reverses the faces that disagree
    with it, then the whole shell when its signed volume is negative); counts go to
    ``repairs``. Consistent shells (and non-manifold ones: validation names them) are
    returned as they are."""
    flat, start = _flat(polys)
    nxt = np.arange(len(flat)) + 1
    nxt[start[1:] - 1] = start[:-1]
    code = flat * (int(flat.max(initial=0)) + 1) + flat[nxt]
    if len(np.unique(code)) == len(code):
        return polys  # every directed edge once: consistent
    directed: dict[tuple[int, int], list[int]] = {}
    for j, p in enumerate(polys):
        for k in range(len(p)):
            directed.setdefault((p[k], p[(k + 1) % len(p)]), []).append(j)
    if all(len(fs) == 1 for fs in directed.values()):
        return polys
    nbrs: list[list[tuple[int, bool]]] = [[] for _ in polys]
    undirected: dict[tuple[int, int], list[tuple[int, bool]]] = {}
    for (a, b), fs in directed.items():
        key = (a, b) if a < b else (b, a)
        for f in fs:
            undirected.setdefault(key, []).append((f, a < b))
    for pair in undirected.values():
        if len(pair) != 2:
            return polys  # non-manifold or open: validation says which edge
        f0, s0 = pair[0]
        f1, s1 = pair[1]
        nbrs[f0].append((f1, s0 == s1))  # the same direction: one of them must turn
        nbrs[f1].append((f0, s0 == s1))
    flip = [-1] * len(polys)
    for first in range(len(polys)):
        if flip[first] >= 0:
            continue
        flip[first] = 0
        stack = [first]
        while stack:
            f = stack.pop()
            for g, same in nbrs[f]:
                want = flip[f] ^ int(same)
                if flip[g] < 0:
                    flip[g] = want
                    stack.append(g)
                elif flip[g] != want:
                    return polys  # not orientable (a Klein bottle): validation rejects it
    out = [list(reversed(p)) if fl else list(p) for p, fl in zip(polys, flip, strict=True)]
    vol = 0.0
    for p in out:  # fan triangles: exact for planar polygons
        a = v[p[0]]
        for k in range(1, len(p) - 1):
            vol += float(np.dot(a, np.cross(v[p[k]], v[p[k + 1]])))
    n_flip = sum(flip)
    if vol < 0:
        out = [list(reversed(p)) for p in out]
        n_flip = len(polys) - n_flip
    repairs.rewound += n_flip
    return out


# ---------------------------------------------------------------------------- self-crossing
def self_intersection(
    v: NDArray[np.float64], tris: NDArray[np.int64], chunk: int = 4096
) -> tuple[int, int] | None:
    """Two triangles of a closed surface that cross (an edge of one passes through the
    other's interior), or ``None``; triangles sharing an edge are not compared.
    Candidates come from a 2D R-tree of the triangles' ``x-y`` boxes (shapely), filtered
    by ``z``, in chunks of ``chunk`` triangles (bounded memory).

    Examples
    --------
    >>> v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0], [0.5, 0.5, -1], [0.5, 0.5, 1],
    ...               [1.5, 1.5, 0.2]], dtype=float)
    >>> self_intersection(v, np.array([[0, 1, 2], [3, 4, 5]]))
    (0, 1)
    >>> self_intersection(v, np.array([[0, 1, 2], [3, 5, 1]])) is None
    True
    """
    import shapely

    if len(tris) < 2:
        return None
    P = v[tris]  # (m, 3, 3)
    lo, hi = P.min(axis=1), P.max(axis=1)
    scale = max(float(np.ptp(v, axis=0).max()), 1e-300)
    eps = 1e-9 * scale
    boxes = shapely.box(lo[:, 0] - eps, lo[:, 1] - eps, hi[:, 0] + eps, hi[:, 1] + eps)
    tree = shapely.STRtree(boxes)
    vol_tol = 1e-12 * scale**3
    nrm = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])  # 2x area, along the normal
    off = np.einsum("ij,ij->i", nrm, P[:, 0])
    for s in range(0, len(tris), chunk):
        qi, qj = tree.query(boxes[s : s + chunk], predicate="intersects")
        qi = qi + s
        keep = qi < qj
        qi, qj = qi[keep], qj[keep]
        keep = (lo[qi, 2] <= hi[qj, 2] + eps) & (lo[qj, 2] <= hi[qi, 2] + eps)
        qi, qj = qi[keep], qj[keep]
        # neighbours across an edge are not compared; across a vertex they are (an edge
        # from the shared vertex meets the other's plane there only: not a crossing)
        share = (tris[qi][:, :, None] == tris[qj][:, None, :]).any(axis=2).sum(axis=1)
        qi, qj = qi[share < 2], qj[share < 2]
        # a triangle wholly on one side of the other's plane cannot cross it
        dj = np.einsum("kj,kvj->kv", nrm[qi], P[qj]) - off[qi][:, None]
        di = np.einsum("kj,kvj->kv", nrm[qj], P[qi]) - off[qj][:, None]
        apart = ((dj > vol_tol).all(1) | (dj < -vol_tol).all(1)
                 | (di > vol_tol).all(1) | (di < -vol_tol).all(1))  # fmt: skip
        qi, qj = qi[~apart], qj[~apart]
        if not qi.size:
            continue
        hit = _crossing(P[qi], P[qj], vol_tol) | _crossing(P[qj], P[qi], vol_tol)
        if hit.any():
            k = int(np.flatnonzero(hit)[0])
            return int(qi[k]), int(qj[k])
    return None


def _orient(
    a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64], d: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Six times the signed volume of the tetrahedra ``abcd`` (rows)."""
    u, w, z = (b - a).T, (c - a).T, (d - a).T
    return np.asarray(
        (u[1] * w[2] - u[2] * w[1]) * z[0]
        + (u[2] * w[0] - u[0] * w[2]) * z[1]
        + (u[0] * w[1] - u[1] * w[0]) * z[2]
    )


def _crossing(S: NDArray[np.float64], T: NDArray[np.float64], tol: float) -> NDArray[np.bool_]:
    """Whether an edge of each triangle of ``S`` passes strictly through the triangle of
    ``T`` in the same row."""
    a, b, c = T[:, 0], T[:, 1], T[:, 2]
    out = np.zeros(len(S), dtype=bool)
    for k in range(3):
        p, q = S[:, k], S[:, (k + 1) % 3]
        sp, sq = _orient(a, b, c, p), _orient(a, b, c, q)
        across = ((sp > tol) & (sq < -tol)) | ((sp < -tol) & (sq > tol))
        e1, e2, e3 = _orient(p, q, a, b), _orient(p, q, b, c), _orient(p, q, c, a)
        inside = ((e1 > tol) & (e2 > tol) & (e3 > tol)) | ((e1 < -tol) & (e2 < -tol) & (e3 < -tol))
        out |= across & inside
    return out
