"""How much a synthesized polyhedral (or polygon) model resembles its example: a few
figures computed from the geometry alone (no planes, lattice or CSP), to read beside Eq.
4.1's violations.

:func:`resemblance` gives, for an example and an output
(:class:`~csplab.continuous.polyhedra.PolyhedralModel`):

* ``solids`` and ``example_solids``: the numbers of solids;
* ``median_volume_ratio``: the output's median solid volume over the example's (a heap of
  tiny boxes is far below 1);
* ``edge_kinds``: the share of the example's edge kinds that occur in the output. An edge
  kind is the pair of face orientations meeting at a crease (which fixes the edge's
  direction, their cross product) and whether the crease is convex or reflex; creases are
  taken on the union of each label's solids (manifold3d), so solids that touch make no
  edge where they meet;
* ``face_orientations``: the share of the example's face orientations (outward normals,
  clustered within ``angle_tol`` radians: CAD exports differ in the 4th-6th decimal) that
  some output face has (on the same unions);
* ``floating`` and ``example_floating``: the solids that rest neither on the ground (the
  model's lowest ``z``) nor on another solid: none of their lowest vertices lies on a face
  of another solid that faces upwards. Floating solids in an output of an example without
  any are a defect a human sees at once.

:func:`resemblance` gives the same figures for polygon models
(:class:`~csplab.continuous.model.PolygonModel`), one dimension down: polygons for
solids, areas for volumes, corners for edges (the pair of edge directions meeting at a
corner of each label's union, shapely, and whether the corner is convex or reflex),
edge directions (outward normals) for face orientations, and ``y`` for up (a polygon
rests on the ground, the model's lowest ``y``, or on an upward-facing edge of another).

Examples
--------
>>> from csplab.continuous.polyhedra import PolyhedralModel
>>> def box(lo, hi):
...     (x0, y0, z0), (x1, y1, z1) = lo, hi
...     v = [[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0],
...          [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]]
...     f = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [2, 3, 7, 6], [1, 2, 6, 5], [0, 4, 7, 3]]
...     return {"label": 1, "vertices": v, "faces": f}
>>> ex = PolyhedralModel([box((0, 0, 0), (2, 2, 1))])
>>> out = PolyhedralModel([box((0, 0, 0), (2, 2, 1)), box((0, 0, 1), (1, 1, 2)),
...                        box((5, 5, 3), (6, 6, 4))])
>>> r = resemblance(ex, out)
>>> r.solids, r.floating, r.example_floating, r.face_orientations, r.edge_kinds
(3, 1, 0, 1.0, 1.0)
>>> r.median_volume_ratio
0.25
>>> from csplab.continuous.model import PolygonModel
>>> ex2 = PolygonModel.from_json({"polygons": [
...     {"label": 1, "points": [[0, 0], [4, 0], [4, 2], [0, 2]]}]})
>>> out2 = PolygonModel.from_json({"polygons": [
...     {"label": 1, "points": [[0, 0], [4, 0], [4, 2], [0, 2]]},
...     {"label": 1, "points": [[6, 3], [7, 3], [6, 4]]}]})
>>> r2 = resemblance(ex2, out2)
>>> r2.solids, r2.floating, r2.face_orientations, r2.edge_kinds, r2.median_volume_ratio
(2, 1, 1.0, 1.0, 0.53125)
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.continuous.model import PolygonModel
from csplab.continuous.polyhedra import PolyhedralModel
from csplab.deps import require
from csplab.errors import InputError

__all__ = [
    "Resemblance",
    "corner_kinds",
    "edge_kinds",
    "floating_polygons",
    "floating_solids",
    "resemblance",
]

#: normals closer than this (radians) are one face orientation
ANGLE_TOL = 1e-3


@dataclass(frozen=True)
class Resemblance:
    """The figures of :func:`resemblance` (see the module
    docstring; for polygons ``solids`` counts polygons, volumes are areas, edge kinds are
    corner kinds and face orientations are edge directions)."""

    solids: int
    example_solids: int
    median_volume_ratio: float
    edge_kinds: float
    example_edge_kinds: int
    face_orientations: float
    example_face_orientations: int
    floating: int
    example_floating: int

    def to_dict(self) -> dict[str, Any]:
        """The figures as JSON-ready numbers (ratios rounded to 6 digits)."""
        return {k: round(v, 6) if isinstance(v, float) else v for k, v in asdict(self).items()}


# ---------------------------------------------------------------------------- orientations
class _Normals:
    """Unit normals clustered greedily within an angle (the first one of a cluster stands
    for it)."""

    def __init__(self, tol: float) -> None:
        self.cos = math.cos(tol)
        self.reps = np.zeros((0, 3))

    def ids(self, normals: NDArray[np.float64], grow: bool = True) -> NDArray[np.int64]:
        """The cluster of each normal (``-1``: none and ``grow`` is false)."""
        out = np.full(len(normals), -1, dtype=np.int64)
        if not len(normals):
            return out
        uniq, inv = np.unique(np.round(normals, 9), axis=0, return_inverse=True)
        got = np.full(len(uniq), -1, dtype=np.int64)
        for k, n in enumerate(uniq):
            if len(self.reps):
                dots = self.reps @ n
                j = int(np.argmax(dots))
                if dots[j] >= self.cos:
                    got[k] = j
                    continue
            if grow:
                self.reps = np.vstack([self.reps, n / np.linalg.norm(n)])
                got[k] = len(self.reps) - 1
        out[:] = got[inv.reshape(-1)]
        return out


def _unions(model: PolyhedralModel) -> list[Any]:
    """Per label, the union of its solids as a ``trimesh.Trimesh`` (manifold3d)."""
    man = require("manifold3d", "mesh", "resemblance figures of polyhedral models")
    tm = require("trimesh", "mesh", "resemblance figures of polyhedral models")
    out = []
    for b in model.labels:
        parts = [s.to_manifold(f"{model.source}: solid") for s in model.solids if s.label == b]
        u = man.Manifold.batch_boolean(parts, man.OpType.Add) if len(parts) > 1 else parts[0]
        g = u.to_mesh64()
        v = np.asarray(g.vert_properties, dtype=np.float64)[:, :3]
        f = np.asarray(g.tri_verts, dtype=np.int64).reshape(-1, 3)
        if len(f):
            out.append(tm.Trimesh(vertices=v, faces=f, process=True))
    return out


def edge_kinds(
    model: PolyhedralModel, normals: _Normals, grow: bool = True
) -> tuple[set[tuple[int, int, bool]], set[int]]:
    """The model's edge kinds ``(orientation, orientation, convex)`` (orientations
    sorted) and its face orientations, as clusters of ``normals`` (new ones added when
    ``grow``; otherwise an unknown orientation is ``-1``)."""
    kinds: set[tuple[int, int, bool]] = set()
    faces: set[int] = set()
    for mesh in _unions(model):
        fn = np.asarray(mesh.face_normals, dtype=np.float64)
        ok = np.isfinite(fn).all(axis=1) & (np.asarray(mesh.area_faces) > 0)
        cid = np.full(len(fn), -1, dtype=np.int64)
        cid[ok] = normals.ids(fn[ok], grow)
        faces |= set(cid[ok].tolist())
        adj = np.asarray(mesh.face_adjacency, dtype=np.int64).reshape(-1, 2)
        if not len(adj):
            continue
        a, b = cid[adj[:, 0]], cid[adj[:, 1]]
        convex = np.asarray(mesh.face_adjacency_convex, dtype=bool)
        crease = (a != b) & ok[adj[:, 0]] & ok[adj[:, 1]]
        for x, y, c in zip(a[crease].tolist(), b[crease].tolist(), convex[crease].tolist(),
                           strict=True):  # fmt: skip
            kinds.add((min(x, y), max(x, y), bool(c)))
    return kinds, faces


# ---------------------------------------------------------------------------- floating
def _on_triangles(p: NDArray[np.float64], T: NDArray[np.float64], tol: float) -> bool:
    """Whether point ``p`` lies within ``tol`` of any triangle of ``T`` ``(m, 3, 3)``."""
    a, b, c = T[:, 0], T[:, 1], T[:, 2]
    n = np.cross(b - a, c - a)
    nn = np.linalg.norm(n, axis=1)
    ok = nn > 0
    a, b, c, n, nn = a[ok], b[ok], c[ok], n[ok], nn[ok]
    dist = np.abs(((p - a) * n).sum(axis=1)) / nn
    near = dist <= tol
    if not near.any():
        return False
    a, b, c, n = a[near], b[near], c[near], n[near]
    q = p - (((p - a) * n).sum(axis=1) / (n * n).sum(axis=1))[:, None] * n  # onto the plane
    s = []
    for u, w in ((a, b), (b, c), (c, a)):
        e = w - u
        side = (np.cross(e, q - u) * n).sum(axis=1) / np.linalg.norm(n, axis=1)
        s.append(side / np.maximum(np.linalg.norm(e, axis=1), 1e-300) >= -tol)
    return bool((s[0] & s[1] & s[2]).any())


def floating_solids(model: PolyhedralModel, ground: float | None = None) -> list[int]:
    """The indices of the solids that rest neither on the ground (``ground``, default the
    model's lowest ``z``) nor on another solid (a face of it whose normal points upwards
    holds one of the solid's lowest vertices), within ``1e-6`` of the model's extent."""
    if not model.solids:
        return []
    lo = np.array([s.vertices[:, 2].min() for s in model.solids])
    b = model.bounds
    tol = 1e-6 * max(b[3] - b[0], b[4] - b[1], b[5] - b[2], 1e-300)
    g = float(lo.min()) if ground is None else ground
    ups, owners = [], []
    for k, s in enumerate(model.solids):
        T = s.vertices[s.faces]
        n = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
        T = T[n[:, 2] > 1e-12 * np.linalg.norm(n, axis=1).clip(1e-300)]  # facing upwards
        ups.append(T)
        owners.append(np.full(len(T), k, dtype=np.int64))
    up = np.concatenate(ups) if ups else np.zeros((0, 3, 3))
    owner = np.concatenate(owners) if owners else np.zeros(0, dtype=np.int64)
    tlo, thi = up.min(axis=1), up.max(axis=1)
    out = []
    for i, s in enumerate(model.solids):
        z0 = float(lo[i])
        if abs(z0 - g) <= tol:
            continue
        low = s.vertices[s.vertices[:, 2] <= z0 + tol]
        plo, phi = low.min(axis=0) - tol, low.max(axis=0) + tol
        near = (owner != i) & (tlo <= phi).all(axis=1) & (thi >= plo).all(axis=1)
        T = up[near]
        if not (len(T) and any(_on_triangles(p, T, tol) for p in low)):
            out.append(i)
    return out


# ---------------------------------------------------------------------------- figures
def resemblance(
    example: PolygonModel | PolyhedralModel,
    output: PolygonModel | PolyhedralModel,
    *,
    angle_tol: float = ANGLE_TOL,
    ground: float | None = None,
) -> Resemblance:
    """The resemblance figures of ``output`` against ``example`` (module docstring), for
    polyhedral models or, one dimension down, polygon models.

    Parameters
    ----------
    example, output : PolyhedralModel or PolygonModel
        The example and a synthesized model (any two models of the same dimension).
    angle_tol : float
        Normals closer than this many radians are one face orientation (3D) or one edge
        direction (2D).
    ground : float, optional
        The height (``z`` in 3D, ``y`` in 2D) of the output's ground: a part whose lowest
        point is there rests on it (a synthesis with a ground: the region's bottom);
        default the output's lowest point. The example's ground is its own lowest point.

    Returns
    -------
    Resemblance
        The figures (in 2D: polygons, areas, corner kinds and edge directions).

    Raises
    ------
    InputError
        When the two models are not of the same dimension.
    """
    normals = _Normals(angle_tol)
    if isinstance(example, PolyhedralModel) and isinstance(output, PolyhedralModel):
        return _figures(
            edge_kinds(example, normals, grow=True),
            edge_kinds(output, normals, grow=False) if output.solids else (set(), set()),
            [s.volume for s in example.solids],
            [s.volume for s in output.solids],
            (len(floating_solids(example)), len(floating_solids(output, ground))),
        )
    if isinstance(example, PolygonModel) and isinstance(output, PolygonModel):
        return _figures(
            corner_kinds(example, normals, grow=True),
            corner_kinds(output, normals, grow=False) if output.polygons else (set(), set()),
            [p.shape.area for p in example.polygons],
            [p.shape.area for p in output.polygons],
            (len(floating_polygons(example)), len(floating_polygons(output, ground))),
        )
    raise InputError(
        f"resemblance compares two models of one dimension, not a {type(example).__name__} "
        f"with a {type(output).__name__}"
    )


def _figures(
    ex: tuple[set[Any], set[Any]],
    out: tuple[set[Any], set[Any]],
    ex_sizes: list[float],
    out_sizes: list[float],
    floating: tuple[int, int],
) -> Resemblance:
    """The :class:`Resemblance` of either dimension from the example's and the output's
    (kinds, orientations), part sizes (volumes or areas) and floating parts."""
    (ex_kinds, ex_dirs), (out_kinds, out_dirs) = ex, out
    ex_med = float(np.median(ex_sizes)) if ex_sizes else 0.0
    out_med = float(np.median(out_sizes)) if out_sizes else 0.0
    return Resemblance(
        solids=len(out_sizes),
        example_solids=len(ex_sizes),
        median_volume_ratio=out_med / ex_med if ex_med > 0 else 0.0,
        edge_kinds=len(ex_kinds & out_kinds) / len(ex_kinds) if ex_kinds else 1.0,
        example_edge_kinds=len(ex_kinds),
        face_orientations=len(ex_dirs & out_dirs) / len(ex_dirs) if ex_dirs else 1.0,
        example_face_orientations=len(ex_dirs),
        floating=floating[1],
        example_floating=floating[0],
    )


# ---------------------------------------------------------------------------- polygons
def _rings2(model: PolygonModel) -> list[NDArray[np.float64]]:
    """The rings of each label's union (shapely), interior on the left of each (exterior
    counter-clockwise, holes clockwise), without a repeated closing point."""
    from shapely import unary_union
    from shapely.geometry import Polygon as ShapelyPolygon
    from shapely.geometry.polygon import orient

    out = []
    for b in model.labels:
        u = unary_union([p.shape for p in model.polygons if p.label == b])
        parts = list(getattr(u, "geoms", [u]))
        for g in parts:
            if not isinstance(g, ShapelyPolygon) or g.is_empty:
                continue
            g = orient(g, 1.0)
            for ring in (g.exterior, *g.interiors):
                out.append(np.asarray(ring.coords, dtype=np.float64)[:-1])
    return out


def corner_kinds(
    model: PolygonModel, normals: _Normals, grow: bool = True
) -> tuple[set[tuple[int, int, bool]], set[int]]:
    """The model's corner kinds ``(direction, direction, convex)`` (the outward normals
    of the two edges meeting at a corner of a label's union, as clusters of ``normals``,
    sorted) and its edge directions (new clusters added when ``grow``; otherwise an
    unknown direction is ``-1``). Collinear points make no corner."""
    kinds: set[tuple[int, int, bool]] = set()
    dirs: set[int] = set()
    for r in _rings2(model):
        e = np.roll(r, -1, axis=0) - r  # edge k: point k -> point k + 1
        ln = np.linalg.norm(e, axis=1)
        ok = ln > 0
        e, ln = e[ok], ln[ok]
        if len(e) < 3:
            continue
        n = np.column_stack([e[:, 1] / ln, -e[:, 0] / ln, np.zeros(len(e))])  # outward
        cid = normals.ids(n, grow)
        dirs |= set(cid.tolist())
        prev = np.roll(np.arange(len(e)), 1)
        turn = e[prev, 0] * e[:, 1] - e[prev, 1] * e[:, 0]  # > 0: a left turn, convex
        for a, c, t in zip(cid[prev].tolist(), cid.tolist(), turn.tolist(), strict=True):
            if a != c:
                kinds.add((min(a, c), max(a, c), t > 0))
    return kinds, dirs


def _segment_distance(p: NDArray[np.float64], A: NDArray[np.float64],
                      B: NDArray[np.float64]) -> NDArray[np.float64]:  # fmt: skip
    """The distance of point ``p`` to each segment ``A[k] B[k]`` (or of each point
    ``p[k]`` to one segment ``A[0] B[0]``)."""
    d = B - A
    dd = (d * d).sum(axis=1)
    t = np.clip(((p - A) * d).sum(axis=1) / np.maximum(dd, 1e-300), 0.0, 1.0)
    q = A + t[:, None] * d
    return np.asarray(np.linalg.norm(p - q, axis=1), dtype=np.float64)


def floating_polygons(model: PolygonModel, ground: float | None = None) -> list[int]:
    """The indices of the polygons that rest neither on the ground (``ground``, default
    the model's lowest ``y``) nor on another polygon (an edge of it whose outward normal
    points upwards touches the polygon's bottom: its lowest points and the edges between
    them, so a slab on two posts rests on them), within ``1e-6`` of the model's
    extent."""
    polys = model.polygons
    if not polys:
        return []
    x0, y0, x1, y1 = model.bounds
    tol = 1e-6 * max(x1 - x0, y1 - y0, 1e-300)
    pts = [np.asarray(p.points, dtype=np.float64) for p in polys]
    lo = np.array([q[:, 1].min() for q in pts])
    g = float(lo.min()) if ground is None else ground
    As, Bs, owners = [], [], []
    for k, p in enumerate(polys):
        for ring in p.rings():  # interior on the left: an upward outward normal is -dx > 0
            a = np.asarray(ring, dtype=np.float64)
            b = np.roll(a, -1, axis=0)
            up = b[:, 0] < a[:, 0]
            As.append(a[up])
            Bs.append(b[up])
            owners.append(np.full(int(up.sum()), k, dtype=np.int64))
    A, B, owner = np.concatenate(As), np.concatenate(Bs), np.concatenate(owners)
    out = []
    for i, q in enumerate(pts):
        if abs(lo[i] - g) <= tol:
            continue
        near = (owner != i) & (np.minimum(A[:, 1], B[:, 1]) <= lo[i] + tol) & (
            np.maximum(A[:, 1], B[:, 1]) >= lo[i] - tol)  # fmt: skip
        a, b = A[near], B[near]
        bottom = q[:, 1] <= lo[i] + tol  # the bottom: its points, and edges between two
        r = np.roll(q, -1, axis=0)
        segs = [(p, p) for p in q[bottom]] + [
            (u, w) for u, w, z in zip(q, r, bottom & np.roll(bottom, -1), strict=True) if z]
        touch = len(a) > 0 and any(  # segments that do not cross: the nearest endpoints
            min(_segment_distance(u, a, b).min(), _segment_distance(w, a, b).min(),
                _segment_distance(a, u[None], w[None]).min(),
                _segment_distance(b, u[None], w[None]).min()) <= tol
            for u, w in segs)  # fmt: skip
        if not touch:
            out.append(i)
    return out
