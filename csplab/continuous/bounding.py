"""Bounding volumes for curved parts (thesis Sec. 4.5.7 and 4.6.4).

A curved surface (a cylindrical hole, a dome, a solid of revolution) is tessellated into
many faces of different orientations; each orientation is a family of planes, and the
cost of Alg. 4.1 grows with the cube of their number (Sec. 4.5.7). Sec. 4.6.4 replaces
such parts by *bounding volumes*: the synthesis runs on a proxy example in which each
curved part is a box of few orientations, and the original geometry is substituted back
into every box of the output.

**Which parts are curved** (:func:`curved_regions`). In every solid, two triangles that
share an edge lie on one smooth surface when they meet at a dihedral angle below
:data:`SMOOTH_DEGREES` (and are not coplanar, :data:`FLAT_RADIANS`); a triangle with such a
neighbour is *curved*. The curved triangles, joined across their edges below
:data:`SMOOTH_DEGREES` (coplanar ones included, so the two triangles of one cylinder
facet are one), form connected regions; a region with at least :data:`MIN_ORIENTATIONS`
distinct normals (unit normals rounded to 4 decimals, i.e. ~1e-4 rad, the same tolerance
as merging near-parallel CAD normals) is a curved part. Chamfers, bevels and slanted
faces meet at larger angles and are never curved parts.

**The bounding volume of a part** (:func:`bounding_volumes`). A part's *tight box* is the
axis-aligned bounding box of its curved triangles; parts whose tight boxes touch or
overlap are one part (the bands of a lathe solid). The *box* is the tight box rounded
outward onto the lattice of the synthesis (origin: the example's lowest corner; spacing:
``spacing`` or the derived default of :func:`~csplab.continuous.lattice.derived_spacing`),
at least one spacing thick; boxes that come to touch or overlap are merged again. In the
proxy example the box is filled with two new labels cut as Fig. 4.27 cuts it, which fixes
how the box may scale (model synthesis scales a triangle uniformly in its plane and a
tetrahedron uniformly in space):

* ``axis`` (every normal of the part is perpendicular to a coordinate axis ``a``: a
  cylinder or prism along ``a``): two triangular prisms, cut along the diagonal of the
  two other axes; the output box scales equally across ``a`` and freely along ``a``;
* ``uniform`` (anything else: a dome, a lathe solid): the tetrahedron cut off through the
  three corners next to the lowest one, and the rest of the box; the output box is a
  uniformly scaled copy.

Every solid loses the material inside the boxes (Boolean difference, manifold3d) and its
remaining vertices are rounded onto the same lattice (:func:`~csplab.continuous.csp3d.
snapped3`, the pipeline's one snapping), so the proxy is on the lattice as it is.

**Substituting back** (:meth:`Bounded.reinsert`). The *content* of a part is the
original geometry inside its lattice box (each solid intersected with it). Each output
solid of a part's first label is one placed box ``Q`` (its bounding box); the content is
mapped by the per-axis affine map taking the lattice box onto ``Q`` (so the curved faces
are the original's, moved and scaled as the box was), the box's labels are dropped and
each label's solids are joined (manifold3d union), so the output holds the curved
geometry and no proxy label.

What :mod:`~csplab.continuous.boundcheck` verifies of such an output is stated there.

**Limits.** Boxes are axis-aligned: the curved part of a rotated mesh gets a larger box than
its oriented one would be, and the ``axis`` kind needs a cylinder along a coordinate axis
(others scale uniformly). A part's content is the whole original inside its box, so
flat geometry there travels with the curved faces. ``csplab check`` rebuilds the proxy with
the derived spacing: an output made with another ``--spacing`` is checked against another
proxy. A lathe output of 40x40x20 spacings has about 800,000 triangles: ``csplab check``
reads it back when its memory budget allows
(:data:`csplab.io.mesh_repair.BYTES_PER_FACE` each); in Python,
:func:`~csplab.continuous.boundcheck.bounded_violations` checks it in memory.

Examples
--------
>>> from csplab.continuous.polyhedra import PolyhedralModel
>>> cube = PolyhedralModel([{"label": 1, "vertices": [[x, y, z] for z in (0, 1)
...     for y in (0, 1) for x in (0, 1)], "faces": [[0, 2, 3, 1], [4, 5, 7, 6],
...     [0, 1, 5, 4], [2, 6, 7, 3], [1, 3, 7, 5], [0, 4, 6, 2]]}])
>>> curved_regions(cube), bounding_volumes(cube) is None
([], True)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.continuous.csp3d import snapped3
from csplab.continuous.lattice import Lattice, derived_spacing
from csplab.continuous.polyhedra import PolyhedralModel, Solid
from csplab.deps import require
from csplab.errors import InputError

__all__ = [
    "FLAT_RADIANS",
    "MIN_ORIENTATIONS",
    "SMOOTH_DEGREES",
    "Bounded",
    "CurvedRegion",
    "Feature",
    "axis_map",
    "bounding_volumes",
    "curved_regions",
    "from_manifold",
]

#: adjacent triangles meeting at a smaller dihedral angle lie on one smooth surface
SMOOTH_DEGREES = 30.0
#: adjacent triangles meeting at a smaller angle (radians) are coplanar
FLAT_RADIANS = 1e-3
#: a smooth region with at least this many face orientations is a curved part
MIN_ORIENTATIONS = 6
_FLAT = 1e-6  # reinserted triangles lower than this share of the output's extent collapse
_SLIVER = 1e-9  # a Boolean's piece of less volume than this times its extent cubed: rounding
_DECIMALS = 4  # unit normals rounded to this many decimals count as one orientation
_EXTRA = "mesh"
_AXES = "xyz"


def _manifold() -> Any:
    return require("manifold3d", _EXTRA, "bounding volumes of curved parts")


def _graph() -> Any:
    return require("scipy.sparse.csgraph", _EXTRA, "finding the curved parts of a mesh")


@dataclass(frozen=True, eq=False)
class CurvedRegion:
    """A connected smooth region of one solid with many face orientations.

    Parameters
    ----------
    solid : int
        The solid's index in its model.
    label : int
        The solid's label.
    triangles : float array ``(m, 3, 3)``
        The region's triangles (corner coordinates).
    normals : float array ``(m, 3)``
        Their unit normals.
    orientations : int
        How many distinct normals (rounded to 4 decimals) the region has.
    """

    solid: int
    label: int
    triangles: NDArray[np.float64]
    normals: NDArray[np.float64]
    orientations: int

    @property
    def points(self) -> NDArray[np.float64]:
        """The region's distinct vertices, sorted lexicographically."""
        return np.unique(self.triangles.reshape(-1, 3), axis=0)

    @property
    def lo(self) -> NDArray[np.float64]:
        """The lowest corner of the region's bounding box."""
        return np.asarray(self.triangles.reshape(-1, 3).min(axis=0), dtype=np.float64)

    @property
    def hi(self) -> NDArray[np.float64]:
        """The highest corner of the region's bounding box."""
        return np.asarray(self.triangles.reshape(-1, 3).max(axis=0), dtype=np.float64)


def curved_regions(model: PolyhedralModel) -> list[CurvedRegion]:
    """The curved parts of every solid of ``model`` (see the module docstring).

    Parameters
    ----------
    model : PolyhedralModel
        The model.

    Returns
    -------
    list of CurvedRegion
        One per connected smooth region with at least :data:`MIN_ORIENTATIONS` face
        orientations, by solid and then by lowest triangle index.

    Examples
    --------
    >>> from csplab.continuous.polyhedra import PolyhedralModel
    >>> import numpy as np, trimesh
    >>> m = trimesh.creation.cylinder(radius=1.0, height=2.0, sections=16)
    >>> M = PolyhedralModel([{"label": 1, "vertices": m.vertices.tolist(),
    ...                       "faces": m.faces.tolist()}])
    >>> [(r.label, r.orientations, len(r.triangles)) for r in curved_regions(M)]
    [(1, 16, 32)]
    """
    graph = _graph()
    from scipy.sparse import coo_matrix

    out: list[CurvedRegion] = []
    smooth = math.radians(SMOOTH_DEGREES)
    for i, s in enumerate(model.solids):
        tm = s.to_trimesh()
        n = len(tm.faces)
        adj = np.asarray(tm.face_adjacency, dtype=np.int64).reshape(-1, 2)
        if not len(adj):
            continue
        ang = np.asarray(tm.face_adjacency_angles, dtype=np.float64)
        bent = (ang > FLAT_RADIANS) & (ang < smooth)
        curved = np.zeros(n, dtype=bool)
        curved[adj[bent].ravel()] = True
        if not curved.any():
            continue
        join = (ang < smooth) & curved[adj[:, 0]] & curved[adj[:, 1]]
        a = adj[join]
        g = coo_matrix((np.ones(len(a)), (a[:, 0], a[:, 1])), shape=(n, n))
        _, comp = graph.connected_components(g, directed=False)
        normals = np.asarray(tm.face_normals, dtype=np.float64)
        tris = np.asarray(tm.triangles, dtype=np.float64)
        seen: set[int] = set()
        for f in np.flatnonzero(curved):
            c = int(comp[f])
            if c in seen:
                continue
            seen.add(c)
            faces = np.flatnonzero((comp == c) & curved)
            k = len(np.unique(np.round(normals[faces], _DECIMALS) + 0.0, axis=0))
            if k >= MIN_ORIENTATIONS:
                out.append(CurvedRegion(i, int(s.label), tris[faces], normals[faces], k))
    return out


def axis_map(
    src_lo: NDArray[np.float64],
    src_hi: NDArray[np.float64],
    dst_lo: NDArray[np.float64],
    dst_hi: NDArray[np.float64],
) -> Callable[[NDArray[np.float64]], NDArray[np.float64]]:
    """The per-axis affine map taking the box ``src`` onto the box ``dst`` (an axis of
    zero extent in ``src`` is moved, not scaled).

    Examples
    --------
    >>> f = axis_map(np.zeros(3), np.ones(3), np.array([1.0, 0, 0]), np.array([3.0, 1, 2]))
    >>> f(np.array([[0.5, 0.5, 0.5]])).tolist()
    [[2.0, 0.5, 1.0]]
    """
    ext = src_hi - src_lo
    flat = ext <= 0
    safe = np.where(flat, 1.0, ext)

    def f(x: NDArray[np.float64]) -> NDArray[np.float64]:
        # lo * (1 - t) + hi * t: the box's own faces land exactly on the target's
        d = np.asarray(x, dtype=np.float64) - src_lo
        t = d / safe
        return np.asarray(np.where(flat, dst_lo + d, dst_lo * (1 - t) + dst_hi * t))

    return f


def _parts(m: Any, flat: float = 0.0) -> list[tuple[NDArray[np.float64], NDArray[np.int64]]]:
    """The connected solids of a manifold3d ``Manifold``: ``(vertices, triangles)``, with
    triangles lower than ``flat`` collapsed (manifold3d's ``simplify``; at least its own
    tolerance): a union of csplab's solids (polygons with collinear points, so that
    neighbours share vertices) leaves zero-area and near-zero-area triangles."""
    out = []
    for part in m.simplify(flat).decompose():
        g = part.to_mesh64()
        # own, writable copies (manifold3d's buffers are read-only views)
        v = np.array(np.asarray(g.vert_properties)[:, :3], dtype=np.float64, order="C")
        f = np.array(np.asarray(g.tri_verts).reshape(-1, 3), dtype=np.int64, order="C")
        ext = np.ptp(v, axis=0) if len(v) else np.zeros(3)
        if len(f) and abs(float(part.volume())) > _SLIVER * float(ext.max(initial=0.0)) ** 3:
            out.append((v, f))
    return out


def from_manifold(m: Any, label: int) -> list[dict[str, Any]]:
    """The connected solids of a manifold3d ``Manifold`` as solid mappings of ``label``
    (triangles, outward, no zero-area triangle), for
    :class:`~csplab.continuous.polyhedra.PolyhedralModel`."""
    return [{"label": int(label), "vertices": v.tolist(), "faces": f.tolist()}
            for v, f in _parts(m)]  # fmt: skip


def _hull(points: NDArray[np.float64]) -> Any:
    return _manifold().Manifold.hull_points(np.asarray(points, dtype=np.float64))


def _pieces(lo: NDArray[np.float64], hi: NDArray[np.float64], axis: int) -> tuple[Any, Any]:
    """The two pieces of the box ``lo..hi`` (Fig. 4.27): triangular prisms cut along the
    diagonal across ``axis`` (``axis >= 0``), or the corner tetrahedron at ``lo`` and the
    rest of the box (``axis < 0``)."""
    corners = np.array([[hi[a] if k >> a & 1 else lo[a] for a in range(3)] for k in range(8)])
    if axis >= 0:
        b, c = (x for x in range(3) if x != axis)
        # first: the corners whose (b, c) are (lo, lo), (hi, lo), (lo, hi)
        u = np.array([(p[b] - lo[b]) / (hi[b] - lo[b]) + (p[c] - lo[c]) / (hi[c] - lo[c])
                      for p in corners])  # fmt: skip
        first = corners[u <= 1 + 1e-12]
        second = corners[u >= 1 - 1e-12]
    else:
        u = ((corners - lo) / (hi - lo)).sum(axis=1)
        first = corners[u <= 1 + 1e-12]
        second = corners[u >= 1 - 1e-12]
    return _hull(first), _hull(second)


@dataclass(frozen=True, eq=False)
class Feature:
    """One curved part replaced by a bounding volume.

    Parameters
    ----------
    regions : tuple of CurvedRegion
        The curved regions it holds (several when their tight boxes touched).
    axis : int
        The axis along which the box scales freely (``axis`` kind, 0-2), or -1 (uniform).
    tight_lo, tight_hi : float arrays ``(3,)``
        The tight box (of the regions' triangles).
    box_lo, box_hi : float arrays ``(3,)``
        The box on the lattice (contains the tight box).
    labels : (int, int)
        The proxy labels of the two pieces of the box.
    contents : tuple of (int, Any)
        ``(label, manifold3d.Manifold)``: the original geometry inside the lattice box.
    """

    regions: tuple[CurvedRegion, ...]
    axis: int
    tight_lo: NDArray[np.float64]
    tight_hi: NDArray[np.float64]
    box_lo: NDArray[np.float64]
    box_hi: NDArray[np.float64]
    labels: tuple[int, int]
    contents: tuple[tuple[int, Any], ...]

    @property
    def scaling(self) -> str:
        """How the box scales (Sec. 4.6.4): ``"x=y, z free"`` or ``"uniform"``."""
        if self.axis < 0:
            return "uniform"
        b, c = (_AXES[x] for x in range(3) if x != self.axis)
        return f"{b}={c}, {_AXES[self.axis]} free"

    def pieces(self) -> tuple[Any, Any]:
        """The box's two pieces (manifold3d solids), as in the proxy example."""
        return _pieces(self.box_lo, self.box_hi, self.axis)


@dataclass(frozen=True, eq=False)
class Bounded:
    """An example whose curved parts became bounding volumes (see the module docstring).

    Parameters
    ----------
    example : PolyhedralModel
        The original example.
    proxy : PolyhedralModel
        The example synthesized in its place (on the lattice of ``spacing``).
    features : tuple of Feature
        The curved parts, in the order of their labels.
    spacing : float
        The lattice spacing the proxy is on.
    origin : float array ``(3,)``
        The lattice's origin (the example's lowest corner; synthesis outputs are on the
        lattice of ``origin`` and ``spacing``).
    """

    example: PolyhedralModel
    proxy: PolyhedralModel
    features: tuple[Feature, ...]
    spacing: float
    origin: NDArray[np.float64]

    def describe(self) -> str:
        """One line naming the parts that became bounding volumes.

        Examples
        --------
        >>> import trimesh
        >>> from csplab.continuous.polyhedra import PolyhedralModel
        >>> m = trimesh.creation.cylinder(radius=1.0, height=2.0, sections=16)
        >>> M = PolyhedralModel([{"label": 1, "vertices": m.vertices.tolist(),
        ...                       "faces": m.faces.tolist()}], name="rod")
        >>> print(bounding_volumes(M, spacing=0.5).describe())
        bounding volumes: 1 curved part of rod -> box (solid 0 label 1: 32 curved faces, \
16 orientations -> 4x4x4 spacings, labels 2+3, scales x=y, z free)
        """
        parts = []
        for f in self.features:
            size = np.rint((f.box_hi - f.box_lo) / self.spacing).astype(int)
            solids = sorted({(r.solid, r.label) for r in f.regions})
            who = ", ".join(f"solid {s} label {b}" for s, b in solids)
            nf = sum(len(r.triangles) for r in f.regions)
            no = len(np.unique(np.round(np.concatenate([r.normals for r in f.regions]),
                                        _DECIMALS) + 0.0, axis=0))  # fmt: skip
            parts.append(
                f"{who}: {nf} curved faces, {no} orientations -> "
                f"{'x'.join(map(str, size))} spacings, labels {f.labels[0]}+{f.labels[1]}, "
                f"scales {f.scaling}"
            )
        n = len(self.features)
        name = self.example.name or self.example.source
        return (f"bounding volumes: {n} curved part{'s' if n != 1 else ''} of {name} -> "
                f"box ({'; '.join(parts)})")  # fmt: skip

    @property
    def proxy_labels(self) -> frozenset[int]:
        """The labels of the boxes' pieces (absent from the original example)."""
        return frozenset(b for f in self.features for b in f.labels)

    def placements(
        self, output: PolyhedralModel
    ) -> list[tuple[Feature, NDArray[np.float64], NDArray[np.float64]]]:
        """Every box placed in a proxy ``output``: ``(feature, lo, hi)`` per solid of a
        feature's first label (the first piece spans the whole box)."""
        by = {f.labels[0]: f for f in self.features}
        out = []
        for s in output.solids:
            f = by.get(int(s.label))
            if f is not None:
                v = np.asarray(s.vertices, dtype=np.float64)
                out.append((f, v.min(axis=0), v.max(axis=0)))
        return out

    def reinsert(self, output: PolyhedralModel) -> PolyhedralModel:
        """The original geometry substituted into every box of a proxy ``output``.

        Parameters
        ----------
        output : PolyhedralModel
            A synthesis output of :attr:`proxy`.

        Returns
        -------
        PolyhedralModel
            The output without the boxes' labels: each box's content mapped onto it
            (:func:`axis_map` from the lattice box), each label's solids joined.
        """
        man = _manifold()
        kept = [s for s in output.solids if int(s.label) not in self.proxy_labels]
        placed: list[tuple[int, Any]] = []
        for f, lo, hi in self.placements(output):
            move = axis_map(f.box_lo, f.box_hi, lo, hi)
            placed += [(label, c.warp_batch(move)) for label, c in f.contents]
        # a placed content is joined with the solids of its label that its box touches
        # (union-find over touching bounding boxes): the others stay as they are
        items: list[tuple[int, Any, NDArray[np.float64], NDArray[np.float64]]] = []
        for s in kept:
            v = np.asarray(s.vertices, dtype=np.float64)
            items.append((int(s.label), s, v.min(axis=0), v.max(axis=0)))
        for label, c in placed:
            blo, bhi = c.bounding_box()[:3], c.bounding_box()[3:]
            items.append((label, c, np.asarray(blo, dtype=np.float64),
                          np.asarray(bhi, dtype=np.float64)))  # fmt: skip
        pairs: list[tuple[int, int]] = []
        if placed:
            lab = np.array([it[0] for it in items])
            los = np.array([it[2] for it in items]).reshape(-1, 3)
            his = np.array([it[3] for it in items]).reshape(-1, 3)
            tol = 1e-9 * max(1.0, float(np.abs(his).max()))
            for i in range(len(kept), len(items)):
                meet = (lab == lab[i]) & np.all(los <= his[i] + tol, axis=1) & np.all(
                    los[i] <= his + tol, axis=1)  # fmt: skip
                pairs += [(i, j) for j in np.flatnonzero(meet).tolist()]
        groups = _components(len(items), pairs)
        # as thin as the mesh readers' slivers (a height of 1e-6 of the model's extent):
        # collapsed, so that the written output reads back without a repair
        ext = np.ptp(np.concatenate([los, his]), axis=0).max() if placed else 0.0
        flat = _FLAT * float(ext)
        solids: list[Solid] = []
        for members in groups:
            if len(members) == 1 and members[0] < len(kept):
                solids.append(kept[members[0]])
                continue
            parts = [items[i][1] for i in members]
            ms = [p.to_manifold() if isinstance(p, Solid) else p for p in parts]
            joined = man.Manifold.batch_boolean(ms, man.OpType.Add)
            label = int(items[members[0]][0])
            solids += [_trusted_solid(label, v, f) for v, f in _parts(joined, flat)]
        meta = {**output.meta, "bounding volumes": len(self.features)}
        return PolyhedralModel.trusted(solids, name=output.name, meta=meta, source=output.source)


def _trusted_solid(label: int, v: NDArray[np.float64], f: NDArray[np.int64]) -> Solid:
    """A solid of triangles from manifold3d (closed and outward by construction)."""
    return Solid(label, v, f, tuple(map(tuple, f.tolist())), np.arange(len(f), dtype=np.int64))


def _axis(normals: NDArray[np.float64]) -> int:
    """The coordinate axis every normal is perpendicular to (a cylinder's), or -1."""
    for a in range(3):
        if float(np.abs(normals[:, a]).max()) < 1e-6:
            return a
    return -1


def _overlap(alo: Any, ahi: Any, blo: Any, bhi: Any, tol: float) -> bool:
    """Whether two closed boxes meet (touching counts)."""
    return bool(np.all(alo <= bhi + tol) and np.all(blo <= ahi + tol))


def _groups(boxes: list[tuple[Any, Any]], tol: float) -> list[list[int]]:
    """Indices of boxes grouped by touching or overlapping (transitively)."""
    n = len(boxes)
    return _components(n, [(i, j) for i in range(n) for j in range(i)
                           if _overlap(*boxes[i], *boxes[j], tol)])  # fmt: skip


def _components(n: int, pairs: list[tuple[int, int]]) -> list[list[int]]:
    """``0..n-1`` grouped by the connected components of the graph of ``pairs`` (scipy's
    ``connected_components``): each group ascending, the groups by their first member."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    e = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    graph = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
    comp = connected_components(graph, directed=False)[1]
    out: dict[int, list[int]] = {}
    for i, c in enumerate(comp.tolist()):
        out.setdefault(int(c), []).append(i)
    return list(out.values())


def bounding_volumes(
    example: PolyhedralModel, spacing: float | None = None
) -> Bounded | None:
    """The example with its curved parts replaced by bounding volumes, or ``None`` when
    it has no curved part (see the module docstring).

    Parameters
    ----------
    example : PolyhedralModel
        The example.
    spacing : float, optional
        The lattice spacing; default
        :func:`~csplab.continuous.lattice.derived_spacing` of the example.

    Returns
    -------
    Bounded or None
        The proxy example, its parts and the spacing.

    Raises
    ------
    InputError
        When ``spacing`` is not a positive number, or the proxy cannot be put on the
        lattice of ``spacing`` (one line naming the
        example; from :meth:`~csplab.continuous.lattice.Lattice.of_points` and
        :func:`~csplab.continuous.csp3d.snapped3`).
    DependencyError
        When a package of the ``mesh`` extra is missing.
    """
    regions = curved_regions(example)
    if not regions:
        return None
    pts = np.concatenate([np.asarray(s.vertices, dtype=np.float64) for s in example.solids])
    s = float(spacing) if spacing is not None else derived_spacing(pts)
    if not (math.isfinite(s) and s > 0):
        raise InputError(f"spacing must be a positive number, not {spacing!r}")
    origin = pts.min(axis=0)
    tol = 1e-9 * max(1.0, float(np.abs(pts).max()))
    # parts: regions whose tight boxes meet, then boxes on the lattice that meet
    groups = [[regions[i] for i in g] for g in _groups([(r.lo, r.hi) for r in regions], tol)]
    while True:
        tight = [(np.min([r.lo for r in g], axis=0), np.max([r.hi for r in g], axis=0))
                 for g in groups]  # fmt: skip
        boxes = []
        for lo, hi in tight:
            a = np.floor((lo - origin) / s + 1e-9)
            b = np.maximum(np.ceil((hi - origin) / s - 1e-9), a + 1)
            boxes.append((origin + a * s, origin + b * s))
        merged = _groups(boxes, -0.5 * s)  # boxes sharing interior (touching is fine)
        if len(merged) == len(groups):
            break
        groups = [[r for i in m for r in groups[i]] for m in merged]
    man = _manifold()
    base = max(example.labels) + 1
    solids = [s_.to_manifold(f"{example.source}: solid {i}") for i, s_ in enumerate(example.solids)]
    features = []
    for k, (g, (tlo, thi), (blo, bhi)) in enumerate(zip(groups, tight, boxes, strict=True)):
        tbox = man.Manifold.cube(tuple(float(x) for x in bhi - blo)).translate(
            tuple(float(x) for x in blo))
        contents = []
        for i, m in enumerate(solids):
            part = m ^ tbox
            if part.volume() > 1e-12 * float(np.prod(bhi - blo)):
                contents.append((int(example.solids[i].label), part))
        axis = _axis(np.concatenate([r.normals for r in g]))
        features.append(Feature(tuple(g), axis, tlo, thi, blo, bhi,
                                (base + 2 * k, base + 2 * k + 1), tuple(contents)))  # fmt: skip
    cut = man.Manifold.batch_boolean(
        [man.Manifold.cube(tuple(float(x) for x in f.box_hi - f.box_lo)).translate(
            tuple(float(x) for x in f.box_lo)) for f in features], man.OpType.Add)  # fmt: skip
    proxy: list[dict[str, Any]] = []
    for i, m in enumerate(solids):
        proxy += from_manifold(m - cut, int(example.solids[i].label))
    for f in features:
        for lab, piece in zip(f.labels, f.pieces(), strict=True):
            proxy += from_manifold(piece, lab)
    where = example.source
    model = PolyhedralModel(proxy, name=example.name, meta=example.meta, source=where)
    P, F = model.indexed_faces()
    lat = Lattice.of_points(np.vstack([P, origin[None, :]]), F, s, snap=True, where=where)
    if lat.snapped:
        model = snapped3(model, lat)
    names = dict(example.meta.get("label_names") or {})
    for k, f in enumerate(features):
        for j, lab in enumerate(f.labels):
            names[str(lab)] = f"bounding volume {k}{'ab'[j]}"
    model.meta["label_names"] = names
    return Bounded(example, model, tuple(features), s, origin)
