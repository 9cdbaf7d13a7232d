"""`PolyhedralModel`: the example of continuous model synthesis in 3D (thesis Ch. 4;
Merrell & Manocha 2008).

A model is a list of *solids*: closed, oriented polyhedral surfaces, each carrying an object
label ``>= 1``; every other point of space is label 0 (empty space). A solid has

* ``vertices``, float64 ``(n, 3)``: coincident vertices are merged (exact equality of
  coordinates, first occurrence kept, in order) and unused ones dropped on construction;
* ``polygons``: the input faces as tuples of vertex indices, counter-clockwise seen from
  outside (the outward normal by the right-hand rule). When every input face is a triangle
  (STL files, say) adjacent coplanar triangles are merged into one polygon when their
  outline is a single loop, so that a cube has 6 polygons whatever the file (the 2008 paper
  counts "input polygons"; :attr:`PolyhedralModel.n_polygons`); files with polygon faces
  keep their own;
* ``faces``, int64 ``(m, 3)``: the triangles of the polygons (triangles as they are, other
  polygons cut by earcut in their plane), outward, and ``face_polygon`` ``(m,)`` the polygon
  of each triangle;
* ``extra``: anything else a reader keeps (the OBJ group and material, say).

Validation (each problem is one :class:`~csplab.errors.InputError` line naming the file,
the solid and the face or vertex): non-finite coordinates (or beyond ``1e100``), face
indices out of range, a solid without faces, zero-area faces, edges shared by more than two
faces (non-manifold), open surfaces (an edge of one face only: not watertight),
inconsistent winding (two faces traversing an edge in the same direction), zero volume,
and two solids of *different* labels whose interiors overlap (the manifold3d intersection
has volume above ``1e-9`` of the smaller solid; touching is fine, same-label solids may
overlap: they are one object). A solid that is consistently wound but inside out
(negative volume) is **fixed**: its faces are reversed, a :class:`UserWarning` says so and
``meta["reoriented"]`` lists the solid indices (pass ``fix_inverted=False`` to reject it
instead). Not checked: self-intersecting surfaces and vertices where two sheets meet at a
point only; a solid is one connected shell (an inner shell is a solid of its own, so
cavities are not represented).

The geometry uses the ``mesh`` extra (trimesh, manifold3d, scipy, mapbox-earcut), imported
through :func:`csplab.deps.require` on first use: a missing package is one
:class:`~csplab.errors.DependencyError` line naming the extra.

Examples
--------
>>> cube = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
...         [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]
>>> quads = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
>>> M = PolyhedralModel([{"label": 2, "vertices": cube, "faces": quads}])
>>> M.labels, M.volume(2), M.n_polygons, M.solids[0].faces.shape
((2,), 1.0, 6, (12, 3))
>>> PolyhedralModel([{"label": 1, "vertices": cube, "faces": quads[1:]}], source="box.obj")
Traceback (most recent call last):
...
csplab.errors.InputError: box.obj: solid 0: not closed (not watertight): the edge between \
vertices 0 and 1 belongs to face 1 only
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.continuous._parts import PartsModel
from csplab.deps import require
from csplab.errors import InputError

__all__ = ["PolyhedralModel", "Solid"]

_EXTRA = "mesh"
_OVERLAP_TOL = 1e-9  # of the smaller solid's volume
_AREA_TOL = 1e-12  # of the solid's extent squared (zero-area faces)
_VOLUME_TOL = 1e-12  # of the solid's extent cubed (zero volume)
_MAX_COORD = 1e100  # beyond this, volumes (cubes of coordinates) overflow


def _trimesh() -> Any:
    return require("trimesh", _EXTRA, "polyhedral models (3D continuous model synthesis)")


def _manifold() -> Any:
    return require("manifold3d", _EXTRA, "the overlap check of polyhedral models")


def _earcut() -> Any:
    return require("mapbox_earcut", _EXTRA, "triangulating polygon faces")


def _scipy_graph() -> Any:
    return require("scipy.sparse.csgraph", _EXTRA, "the face graph of polyhedral models")


@dataclass(frozen=True, eq=False)
class Solid:
    """One closed, outward-oriented polyhedral surface with an object ``label >= 1`` (see
    the module docstring for the fields); build solids through :class:`PolyhedralModel`,
    which validates them."""

    label: int
    vertices: NDArray[np.float64]
    faces: NDArray[np.int64]
    polygons: tuple[tuple[int, ...], ...]
    face_polygon: NDArray[np.int64]
    extra: Mapping[str, Any] = field(default_factory=dict)

    @property
    def volume(self) -> float:
        """The enclosed volume (positive: the faces point outwards)."""
        return float(self.to_trimesh().volume)

    @property
    def bounds(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """``((xmin, ymin, zmin), (xmax, ymax, zmax))``."""
        lo, hi = self.vertices.min(axis=0), self.vertices.max(axis=0)
        return (
            (float(lo[0]), float(lo[1]), float(lo[2])),
            (float(hi[0]), float(hi[1]), float(hi[2])),
        )

    def to_trimesh(self) -> Any:
        """The solid as a ``trimesh.Trimesh`` (triangles, vertices as they are)."""
        tm = _trimesh()
        return tm.Trimesh(vertices=self.vertices, faces=self.faces, process=False)

    def to_manifold(self, where: str = "solid") -> Any:
        """The solid as a ``manifold3d.Manifold`` (for Boolean operations and volumes);
        ``where`` names it in the error when manifold3d rejects it."""
        return _as_manifold(self, where)

    def to_json(self) -> dict[str, Any]:
        """``{"label", "vertices", "faces"}`` (faces: the polygons) and the extra keys."""
        d: dict[str, Any] = dict(self.extra)
        d["label"] = self.label
        d["vertices"] = self.vertices.tolist()
        d["faces"] = [list(p) for p in self.polygons]
        return d


class PolyhedralModel(PartsModel):
    """A labelled set of closed polyhedra (see the module docstring); immutable.

    Parameters
    ----------
    solids : sequence of Solid or of mappings
        ``{"label": int, "vertices": [[x, y, z], ...], "faces": [[i, j, k, ...], ...]}``
        (faces are polygons of 0-based vertex indices, counter-clockwise seen from outside;
        other keys are kept in :attr:`Solid.extra`). May be empty (an output that is all
        empty space).
    name : str
        A short name for reports.
    meta : mapping
        Provenance (``format``, ``label_names``, ...).
    source : str
        The file (or ``"<model>"``) named in error messages.
    fix_inverted : bool
        Reverse inside-out solids with a warning (default) instead of rejecting them.
    merge_coplanar : bool
        Merge adjacent coplanar triangles into polygons when every face of a solid is a
        triangle (default).

    Raises
    ------
    InputError
        When a solid fails a check of the module docstring's validation (one line naming
        the file, the solid and the face or vertex), or two solids of different labels
        overlap.
    DependencyError
        When a package of the ``mesh`` extra that the checks need is missing.

    Warns
    -----
    UserWarning
        When an inside-out solid is reversed (``fix_inverted``).
    """

    #: polyhedral models are spatial
    ndim = 3
    #: what the model is made of, and its adjective (shared names with PolygonModel)
    parts = "solids"
    kind = "polyhedral"

    def __init__(
        self,
        solids: Sequence[Solid | Mapping[str, Any]],
        *,
        name: str = "",
        meta: Mapping[str, Any] | None = None,
        source: str = "<model>",
        fix_inverted: bool = True,
        merge_coplanar: bool = True,
    ) -> None:
        self.name = name
        self.meta: dict[str, Any] = dict(meta or {})
        self.source = source
        out: list[Solid] = []
        reoriented: list[int] = []
        for i, s in enumerate(solids):
            where = f"{source}: solid {i}"
            solid, flipped = _solid(s, where, fix_inverted, merge_coplanar)
            if flipped:
                reoriented.append(i)
                warnings.warn(
                    f"{where} (label {solid.label}) was inside out (negative volume); "
                    "its faces were reversed",
                    UserWarning,
                    stacklevel=2,
                )
            out.append(solid)
        self.solids: tuple[Solid, ...] = tuple(out)
        if reoriented:
            self.meta["reoriented"] = reoriented
        self._check_overlaps()

    @classmethod
    def trusted(
        cls,
        solids: Sequence[Solid],
        *,
        name: str = "",
        meta: Mapping[str, Any] | None = None,
        source: str = "<model>",
    ) -> PolyhedralModel:
        """A model of solids known to be valid, built without validating them again.

        The solids must be closed, outward and non-overlapping by construction (csplab's
        own synthesis outputs). Reading the model back from a file (or
        ``PolyhedralModel(model.solids)``) runs every check of the module docstring; the
        test suite does so for synthesis outputs.

        Parameters
        ----------
        solids : sequence of Solid
            The solids, used as they are.
        name : str, default ""
            A short name for reports.
        meta : mapping of str to Any, optional
            Provenance (``format``, ``label_names``, ...).
        source : str, default "<model>"
            The file (or ``"<model>"``) named in error messages.

        Returns
        -------
        PolyhedralModel
            The model of ``solids``.
        """
        self = cls.__new__(cls)
        self.name = name
        self.meta = dict(meta or {})
        self.source = source
        self.solids = tuple(solids)
        return self

    # ------------------------------------------------------------------ queries
    def indexed_faces(self) -> tuple[NDArray[np.float64], list[list[int]]]:
        """Every solid's vertices and every polygon as a list of indices into them.

        This is the 3D form of :meth:`PolygonModel.indexed_faces
        <csplab.continuous.model.PolygonModel.indexed_faces>`, which gives rings.

        Returns
        -------
        points : float array ``(n, 3)``
            Every solid's vertices, one solid after another.
        polygons : list of list of int
            Every solid's polygons (faces), as indices into ``points``.
        """
        pts = np.concatenate([np.asarray(s.vertices, dtype=np.float64) for s in self.solids])
        polys: list[list[int]] = []
        base = 0
        for s in self.solids:
            polys += [[base + int(i) for i in p] for p in s.polygons]
            base += len(s.vertices)
        return pts, polys

    @property
    def n_polygons(self) -> int:
        """The number of input polygons (faces; adjacent coplanar triangles merged)."""
        return sum(len(s.polygons) for s in self.solids)

    @property
    def bounds(self) -> tuple[float, float, float, float, float, float]:
        """``(xmin, ymin, zmin, xmax, ymax, zmax)`` over all vertices.

        Raises
        ------
        InputError
            When the model has no solids.
        """
        if not self.solids:
            raise InputError(f"{self.source}: the model has no solids")
        a = np.concatenate([s.vertices for s in self.solids])
        lo, hi = a.min(axis=0), a.max(axis=0)
        return (float(lo[0]), float(lo[1]), float(lo[2]),
                float(hi[0]), float(hi[1]), float(hi[2]))  # fmt: skip

    def volume(self, label: int | None = None) -> float:
        """The volume of one label, or of all objects.

        Same-label solids that may overlap are united (manifold3d) first, so overlaps count
        once.

        Parameters
        ----------
        label : int, optional
            The object label; ``None`` (the default): all labels.

        Returns
        -------
        float
            The volume.

        Raises
        ------
        DependencyError
            When a package of the ``mesh`` extra (trimesh, manifold3d) is missing.
        """
        labs = self.labels if label is None else (label,)
        total = 0.0
        for b in labs:
            group = [s for s in self.solids if s.label == b]
            if any(_boxes_meet(s, t) for k, s in enumerate(group) for t in group[k + 1 :]):
                man = _manifold()
                union = man.Manifold()
                for s in group:
                    union = union + _as_manifold(s, self.source)
                total += float(union.volume())
            else:
                total += sum(s.volume for s in group)
        return total

    def labels_at(self, points: Any) -> NDArray[np.int64]:
        """The label of the solid containing each point, by compiled ray casting.

        See :func:`csplab.continuous._geom.point_labels`.

        Parameters
        ----------
        points : array_like of float
            Query points, ``(P, 3)`` (any shape of ``3 * P`` values); points on a face are
            ambiguous.

        Returns
        -------
        int64 array ``(P,)``
            The label at each point, 0 for empty space.
        """
        from csplab.continuous._geom import point_labels

        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        return point_labels(pts, [(s.label, s.vertices[s.faces]) for s in self.solids])

    def to_trimesh(self, label: int | None = None) -> Any:
        """The solids of one label, or all, as one ``trimesh.Trimesh``.

        The solids are concatenated, not united; :meth:`Solid.to_trimesh` gives one solid.

        Parameters
        ----------
        label : int, optional
            The object label; ``None`` (the default): all solids.

        Returns
        -------
        trimesh.Trimesh
            The solids' triangles (an empty mesh when there are none).

        Raises
        ------
        DependencyError
            When trimesh (the ``mesh`` extra) is missing.
        """
        tm = _trimesh()
        parts = [s.to_trimesh() for s in self.solids if label is None or s.label == label]
        if not parts:
            return tm.Trimesh()
        return parts[0] if len(parts) == 1 else tm.util.concatenate(parts)

    def to_json(self) -> dict[str, Any]:
        """The JSON form of the model.

        Returns
        -------
        dict of str to Any
            The JSON-compatible ``meta`` keys and ``"solids"``, a list of
            :meth:`Solid.to_json` (``{"label", "vertices", "faces"}`` and extra keys).
        """
        d: dict[str, Any] = {
            k: v for k, v in self.meta.items() if isinstance(v, str | int | float | list | dict)
        }
        d["solids"] = [s.to_json() for s in self.solids]
        return d

    def hash(self) -> str:
        """A short content hash of the model: equal models, equal hashes.

        Returns
        -------
        str
            16 hex digits of a SHA-256 of every solid's label, vertices and polygons (what
            the experiment harness keys trials by).
        """
        import hashlib

        h = hashlib.sha256(b"polyhedra")
        for s in self.solids:
            h.update(str((s.label, s.vertices.shape, s.polygons)).encode())
            h.update(np.ascontiguousarray(s.vertices, dtype=np.float64).tobytes())
        return h.hexdigest()[:16]

    # ------------------------------------------------------------------ validation
    def _check_overlaps(self) -> None:
        n = len(self.solids)
        if n < 2:
            return
        lo = np.array([s.vertices.min(axis=0) for s in self.solids])
        hi = np.array([s.vertices.max(axis=0) for s in self.solids])
        lab = np.array([s.label for s in self.solids])
        pairs = []
        for i in range(n - 1):  # bounding boxes sharing interior points, different labels
            js = np.arange(i + 1, n)
            meet = (lo[i] < hi[js]).all(axis=1) & (lo[js] < hi[i]).all(axis=1) & (lab[js] != lab[i])
            pairs += [(i, int(k)) for k in js[meet]]
        if not pairs:
            return
        cache: dict[int, Any] = {}

        def get(k: int) -> Any:
            if k not in cache:
                cache[k] = _as_manifold(self.solids[k], f"{self.source}: solid {k}")
            return cache[k]

        for i, j in pairs:
            a, b = self.solids[i], self.solids[j]
            vol = float((get(i) ^ get(j)).volume())
            if vol > _OVERLAP_TOL * min(abs(a.volume), abs(b.volume)):
                raise InputError(
                    f"{self.source}: solids {i} (label {a.label}) and {j} (label {b.label}) "
                    f"overlap (volume {vol:.6g})"
                )


# ---------------------------------------------------------------------------- helpers
def _boxes_meet(a: Solid, b: Solid) -> bool:
    """The bounding boxes of ``a`` and ``b`` share interior points."""
    return bool(
        np.all(a.vertices.min(axis=0) < b.vertices.max(axis=0))
        and np.all(b.vertices.min(axis=0) < a.vertices.max(axis=0))
    )


def _as_manifold(s: Solid, where: str) -> Any:
    man = _manifold()
    mesh = man.Mesh64(
        vert_properties=np.ascontiguousarray(s.vertices, dtype=np.float64),
        tri_verts=np.ascontiguousarray(s.faces, dtype=np.uint64),
    )
    m = man.Manifold(mesh=mesh)
    status = m.status()
    if status != man.Error.NoError:
        raise InputError(f"{where}: manifold3d rejects the solid ({status.name})")
    return m


def _label(raw: Any, where: str) -> int:
    if isinstance(raw, bool) or not isinstance(raw, int | np.integer):
        if isinstance(raw, float) and raw.is_integer():
            raw = int(raw)
        else:
            raise InputError(f"{where}: label must be an integer >= 1, not {raw!r}")
    label = int(raw)
    if label < 1:
        raise InputError(f"{where}: label must be >= 1 (0 is empty space), not {label}")
    from csplab.limits import check_label

    return check_label(label, where)  # a picture or a file must be able to hold it


def _vertices(raw: Any, where: str) -> NDArray[np.float64]:
    try:
        v = np.asarray(raw, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{where}: vertices must be [x, y, z] numbers") from None
    if v.ndim != 2 or v.shape[1] != 3:
        if v.size == 0:
            return np.zeros((0, 3))
        raise InputError(f"{where}: vertices must be [x, y, z] triples, not shape {v.shape}")
    bad = np.flatnonzero(~np.isfinite(v).all(axis=1))
    if bad.size:
        k = int(bad[0])
        raise InputError(f"{where}: vertex {k} has non-finite coordinates {v[k].tolist()}")
    big = np.flatnonzero((np.abs(v) > _MAX_COORD).any(axis=1))
    if big.size:
        k = int(big[0])
        raise InputError(f"{where}: vertex {k} has coordinates too large {v[k].tolist()}")
    return v


def _polygons(raw: Any, n: int, where: str) -> list[tuple[int, ...]]:
    if isinstance(raw, np.ndarray):
        raw = raw.tolist()
    if not isinstance(raw, Sequence) or isinstance(raw, str | bytes):
        raise InputError(f"{where}: faces must be a list of vertex index lists")
    out: list[tuple[int, ...]] = []
    for j, f in enumerate(raw):
        if isinstance(f, np.ndarray):
            f = f.tolist()
        if not isinstance(f, Sequence) or isinstance(f, str | bytes):
            raise InputError(f"{where}: face {j} must be a list of vertex indices")
        idx: list[int] = []
        for x in f:
            if isinstance(x, bool) or not isinstance(x, int | np.integer):
                raise InputError(f"{where}: face {j} has a non-integer vertex index {x!r}")
            if not 0 <= int(x) < n:
                raise InputError(f"{where}: face {j} refers to vertex {x} of {n}")
            idx.append(int(x))
        out.append(tuple(idx))
    return out


def _merge_vertices(
    v: NDArray[np.float64], polys: list[tuple[int, ...]]
) -> tuple[NDArray[np.float64], list[tuple[int, ...]]]:
    """Coincident vertices merged, unused ones dropped, first occurrences in order."""
    used = sorted({i for p in polys for i in p})
    sub = v[used] + 0.0  # -0.0 -> 0.0
    _, first, inverse = np.unique(sub, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    remap = np.full(len(v), -1, dtype=np.int64)
    remap[used] = rank[inverse.reshape(-1)]
    new_v = sub[first[order]]
    out: list[tuple[int, ...]] = []
    for p in polys:
        q = [int(remap[i]) for i in p]
        q = [x for k, x in enumerate(q) if x != q[k - 1]] if len(q) > 1 else q  # repeats
        out.append(tuple(q))
    return new_v, out


def _triangulate(
    v: NDArray[np.float64], polys: list[tuple[int, ...]], where: str, scale: float
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Triangles of the polygons (earcut in each polygon's plane) and each one's polygon;
    normals and orientations in bulk."""
    for j, p in enumerate(polys):
        if len(set(p)) < 3:
            raise InputError(f"{where}: face {j} has zero area (fewer than 3 distinct vertices)")
    lens = np.fromiter((len(p) for p in polys), dtype=np.int64, count=len(polys))
    flat = np.fromiter((i for p in polys for i in p), dtype=np.int64, count=int(lens.sum()))
    start = np.concatenate([[0], np.cumsum(lens)])
    nxt = np.arange(len(flat)) + 1
    nxt[start[1:] - 1] = start[:-1]
    a, b = v[flat], v[flat[nxt]]
    normals = np.add.reduceat(np.cross(a, b), start[:-1], axis=0)  # Newell: 2x vector area
    area = 0.5 * np.linalg.norm(normals, axis=1)
    bad = np.flatnonzero(area <= _AREA_TOL * scale**2)
    if bad.size:
        raise InputError(f"{where}: face {int(bad[0])} has zero area")
    tris: list[NDArray[np.int64]] = []
    owner: list[NDArray[np.int64]] = []
    tri3 = np.flatnonzero(lens == 3)
    if tri3.size:
        idx = start[tri3][:, None] + np.arange(3)[None, :]
        tris.append(flat[idx])
        owner.append(tri3)
    unit = normals / (2 * area)[:, None]
    for j in np.flatnonzero(lens > 3).tolist():
        ids = flat[start[j] : start[j + 1]]
        pts = v[ids]
        x, y, z = unit[j].tolist()
        # a basis of the face's plane (plain arithmetic: np.cross is slow on one vector)
        k = min(range(3), key=lambda i: abs((x, y, z)[i]))
        e1 = [(0.0, z, -y), (-z, 0.0, x), (y, -x, 0.0)][k]
        n1 = math.sqrt(e1[0] ** 2 + e1[1] ** 2 + e1[2] ** 2)
        a1 = (e1[0] / n1, e1[1] / n1, e1[2] / n1)
        a2 = (y * a1[2] - z * a1[1], z * a1[0] - x * a1[2], x * a1[1] - y * a1[0])
        rel = pts - pts[0]
        flat2 = np.column_stack([rel @ np.array(a1), rel @ np.array(a2)])
        ring = np.asarray([len(ids)], dtype=np.uint32)
        loc = np.asarray(_earcut().triangulate_float64(flat2, ring), dtype=np.int64)
        if len(loc) != 3 * (len(ids) - 2):
            raise InputError(f"{where}: face {j} cannot be triangulated (not a simple polygon)")
        tris.append(ids[_without_slivers(flat2, loc.reshape(-1, 3), scale)])
        owner.append(np.full(len(ids) - 2, j, dtype=np.int64))
    T = np.concatenate(tris)
    own = np.concatenate(owner)
    order = np.argsort(own, kind="stable")
    T, own = T[order], own[order]
    # earcut's winding in the (e1, e2) plane may be either, but is one per polygon: match
    # each polygon's normal by the sum over its triangles (a sliver triangle of collinear
    # points on a slanted face has a sign of rounding noise; alone it was flipped wrongly)
    ta, tb, tc = v[T[:, 0]], v[T[:, 1]], v[T[:, 2]]
    dots = (np.cross(tb - ta, tc - ta) * normals[own]).sum(axis=1)
    flip = (np.bincount(own, weights=dots, minlength=len(polys)) < 0)[own]
    T[flip] = T[flip][:, ::-1]
    return T, own


def _without_slivers(
    xy: NDArray[np.float64], tri: NDArray[np.int64], scale: float
) -> NDArray[np.int64]:
    """A polygon's triangulation ``tri`` (indices into its 2D points ``xy``) with every
    zero-area triangle removed by an edge flip: earcut takes three nearly collinear
    vertices of a slanted face (float coordinates) as an ear; its long side is a diagonal
    shared with one other triangle, and the two become two proper triangles through the
    middle vertex. Orientation follows the polygon's."""
    t = tri.copy()

    def area(a: int, b: int, c: int) -> float:
        (ax, ay), (bx, by), (cx, cy) = xy[a], xy[b], xy[c]
        return float((bx - ax) * (cy - ay) - (by - ay) * (cx - ax))

    tol = 1e-9 * scale * scale
    areas = np.array([area(*map(int, r)) for r in t])
    sign = 1.0 if areas.sum() >= 0 else -1.0
    for _ in range(4 * len(t)):
        bad = [i for i in range(len(t)) if abs(area(*map(int, t[i]))) <= tol]
        if not bad:
            break
        i = bad[0]
        a, b, c = (int(x) for x in t[i])
        # the middle vertex m of the three (on the segment between the other two, p and q)
        pts = {v: xy[v] for v in (a, b, c)}
        d = max(((u, w) for u in (a, b, c) for w in (a, b, c) if u < w),
                key=lambda uw: float(np.hypot(*(pts[uw[0]] - pts[uw[1]]))))  # fmt: skip
        p, q = d
        m = ({a, b, c} - {p, q}).pop()
        other = [k for k in range(len(t)) if k != i and p in t[k] and q in t[k]]
        if not other:
            break  # pragma: no cover - a degenerate triangle on the boundary: left as is
        k = other[0]
        r = ({int(x) for x in t[k]} - {p, q}).pop()
        new = []
        for tr in ((p, m, r), (m, q, r)):
            new.append(tr if area(*tr) * sign > 0 else (tr[0], tr[2], tr[1]))
        t[i], t[k] = new
    return t


def _check_edges(faces: NDArray[np.int64], owner: NDArray[np.int64], where: str) -> None:
    """Every edge of exactly two faces, traversed in opposite directions."""
    directed = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    tri = np.tile(np.arange(len(faces)), 3)
    key = np.sort(directed, axis=1)
    uniq, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    # an edge inside a polygon (a triangulation diagonal) is fine: it is used twice
    many = np.flatnonzero(counts > 2)
    if many.size:
        e = uniq[many[0]]
        fs = sorted({int(owner[tri[k]]) for k in np.flatnonzero(inverse == many[0])})
        raise InputError(
            f"{where}: non-manifold edge between vertices {e[0]} and {e[1]} "
            f"(shared by {int(counts[many[0]])} faces: {', '.join(map(str, fs))})"
        )
    once = np.flatnonzero(counts == 1)
    if once.size:
        e = uniq[once[0]]
        k = int(np.flatnonzero(inverse == once[0])[0])
        raise InputError(
            f"{where}: not closed (not watertight): the edge between vertices {e[0]} and "
            f"{e[1]} belongs to face {int(owner[tri[k]])} only"
        )
    order = np.argsort(inverse, kind="stable")
    first, second = order[0::2], order[1::2]
    same = np.flatnonzero((directed[first] == directed[second]).all(axis=1))
    if same.size:
        k1, k2 = int(first[same[0]]), int(second[same[0]])
        e = directed[k1]
        raise InputError(
            f"{where}: inconsistent winding: faces {int(owner[tri[k1]])} and "
            f"{int(owner[tri[k2]])} both run from vertex {e[0]} to {e[1]} (one of them is "
            "flipped)"
        )


def _merge_coplanar(
    mesh: Any, polys: list[tuple[int, ...]]
) -> tuple[list[tuple[int, ...]], NDArray[np.int64]]:
    """Adjacent coplanar triangles as one polygon when their outline is one loop."""
    owner = np.arange(len(polys), dtype=np.int64)
    group = np.full(len(polys), -1, dtype=np.int64)
    outlines: dict[int, tuple[int, ...]] = {}
    for g, facet in enumerate(mesh.facets):
        loop = _outline(mesh.faces[facet])
        if loop is not None:
            group[facet] = g
            outlines[g] = loop
    out: list[tuple[int, ...]] = []
    seen: dict[int, int] = {}
    for j in range(len(polys)):
        g = int(group[j])
        if g < 0:
            owner[j] = len(out)
            out.append(polys[j])
        elif g in seen:
            owner[j] = seen[g]
        else:
            seen[g] = owner[j] = len(out)
            out.append(outlines[g])
    return out, owner


def _outline(tris: NDArray[np.int64]) -> tuple[int, ...] | None:
    """The boundary loop of a patch of consistently wound triangles (``None`` when it is
    not a single simple loop)."""
    directed = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    pairs = {(int(a), int(b)) for a, b in directed}
    boundary = [(a, b) for a, b in pairs if (b, a) not in pairs]
    nxt: dict[int, int] = {}
    for a, b in boundary:
        if a in nxt:
            return None
        nxt[a] = b
    if not nxt:
        return None
    start = min(nxt)
    loop = [start]
    while (b := nxt[loop[-1]]) != start:
        if len(loop) > len(nxt) or b not in nxt:
            return None
        loop.append(b)
    return tuple(loop) if len(loop) == len(nxt) else None


def _solid(s: Solid | Mapping[str, Any], where: str, fix: bool, merge: bool) -> tuple[Solid, bool]:
    if isinstance(s, Solid):
        raw_label: Any = s.label
        raw_v: Any = s.vertices
        raw_f: Any = list(s.polygons)
        extra: dict[str, Any] = dict(s.extra)
    elif isinstance(s, Mapping):
        for key in ("vertices", "faces"):
            if key not in s:
                raise InputError(f'{where}: missing "{key}"')
        raw_label, raw_v, raw_f = s.get("label"), s["vertices"], s["faces"]
        extra = {k: v for k, v in s.items() if k not in ("label", "vertices", "faces")}
    else:
        raise InputError(f"{where}: expected a solid or a mapping, not {type(s).__name__}")
    label = _label(raw_label, where)
    v0 = _vertices(raw_v, where)
    polys0 = _polygons(raw_f, len(v0), where)
    if not polys0:
        raise InputError(f"{where}: the solid has no faces")
    v, polys = _merge_vertices(v0, polys0)
    scale = max(1e-300, float(np.ptp(v, axis=0).max()))
    faces, owner = _triangulate(v, polys, where, scale)
    _check_edges(faces, owner, where)
    tm = _trimesh()
    try:
        mesh = tm.Trimesh(vertices=v, faces=faces, process=False)
        vol = float(mesh.volume)
    except (ValueError, IndexError, FloatingPointError) as e:  # pragma: no cover - defensive
        raise InputError(f"{where}: trimesh cannot build the solid ({e})") from None
    if not math.isfinite(vol) or abs(vol) <= _VOLUME_TOL * scale**3:
        raise InputError(f"{where}: the solid has zero volume")
    flipped = vol < 0
    if flipped:
        if not fix:
            raise InputError(
                f"{where}: inverted: the faces point inwards (volume {vol:.6g}); reverse every face"
            )
        faces = faces[:, ::-1].copy()
        polys = [tuple(reversed(p)) for p in polys]
        mesh = tm.Trimesh(vertices=v, faces=faces, process=False)
    if merge and all(len(p) == 3 for p in polys):
        _scipy_graph()  # trimesh's facets use the face graph
        polys, owner = _merge_coplanar(mesh, polys)
    solid = Solid(label, v, np.ascontiguousarray(faces), tuple(polys), owner, extra)
    return solid, flipped
