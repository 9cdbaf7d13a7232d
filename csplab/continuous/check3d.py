"""The checker of continuous model synthesis in 3D: Eq. 4.1 on the output solids.

:func:`violations3` works on the two polyhedral models only (not on the planes or the CSP
that produced the output). The example's face orientations, up to sign and within
``angle_tol``, are its plane families; an output face of another orientation is a violation.
A neighbourhood is written as the label in every cell of the central arrangement of all
families' planes through the point (:func:`cone_cells`, the checker's own enumeration,
written apart from the CSP's): the label just off the point in a direction inside the cell,
found by point location in each label's triangles. Two points are locally identical exactly
when these labelings agree.

The example's neighbourhoods are sampled densely (every vertex; points along every edge;
a grid of points on every triangle), so that features that change along an edge or across a
face are all found. The output is sampled at every vertex, at the middle of every edge piece
between the vertices lying on that edge, and at the centre of every triangle: the output's
triangles must each have one neighbourhood, which holds for csplab's outputs (each is cut
where the label on its other side changes); a hand-made output that another solid touches on
part of one triangle needs that triangle split there.

Examples
--------
>>> from csplab.continuous.polyhedra import PolyhedralModel
>>> cube = lambda lo, hi, b=1: {"label": b, "vertices": [[x, y, z] for z in (lo, hi)
...     for y in (lo, hi) for x in (lo, hi)], "faces": [[0, 2, 3, 1], [4, 5, 7, 6],
...     [0, 1, 5, 4], [2, 6, 7, 3], [1, 3, 7, 5], [0, 4, 6, 2]]}
>>> E = PolyhedralModel([cube(0, 1)])
>>> len(violations3(E, PolyhedralModel([cube(2, 5)])))
0
>>> tet = PolyhedralModel([{"label": 1, "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0],
...     [0, 0, 1]], "faces": [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]}])
>>> violations3(E, tet).counts()["direction"]
1
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from csplab.continuous._geom import point_labels, points_on_segments
from csplab.continuous.defects import Defect, Violations
from csplab.continuous.polyhedra import PolyhedralModel, Solid
from csplab.errors import InputError

if TYPE_CHECKING:  # the constraints' data only: the checker reads them, as given
    from csplab.continuous.user3d import UserConstraints3

__all__ = ["cone_cells", "user_violations3", "violations3"]

ANGLE_TOL = 1e-7
# per model (immutable), its polygons' normals and points: computed once per check
_POLYGON_ARRAYS: weakref.WeakKeyDictionary[
    PolyhedralModel | _Joined, tuple[NDArray[np.float64], NDArray[np.float64]]
] = weakref.WeakKeyDictionary()


class _Joined:
    """Solids of a model plus the frame of outside labels (no validation: the frame touches
    the model on the region's faces by construction)."""

    def __init__(self, solids: list[Solid], model: PolyhedralModel) -> None:
        self.solids = solids
        self.labels = tuple(sorted({int(s.label) for s in solids}))
        self.bounds = model.bounds if len(model.solids) else (0.0,) * 6

    @property
    def n_polygons(self) -> int:
        return sum(len(s.polygons) for s in self.solids)


#: what the checker reads: a model, or a model with the frame of outside labels
Solids = PolyhedralModel | _Joined


def cone_cells(normals: NDArray[np.float64]) -> tuple[NDArray[np.int8], NDArray[np.float64]]:
    """The cells of the central arrangement of the planes ``n . x = 0`` (``normals``
    ``(F, 3)`` with three independent ones; relative tolerance 1e-9): their sign vectors
    ``(c, F)`` sorted, and a unit direction inside each.

    On the unit sphere the planes are great circles and every cell is a convex polygon with
    at least three corners. At a corner ``q`` where circles ``A`` and ``B`` bound the cell,
    the next vertices ``p`` along ``A`` and ``r`` along ``B`` are corners of the cell too,
    so ``p + q + r`` points into it: the candidates are these sums for every vertex, every
    two circles through it and both ways along each; those on no circle name a cell.

    >>> cone_cells(np.eye(3))[0].shape                  # the eight octants
    (8, 3)
    >>> len(cone_cells(np.array([[1., 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]]))[0])
    14
    """
    N = np.asarray(normals, dtype=np.float64)
    N = N / np.linalg.norm(N, axis=1)[:, None]
    tol = 1e-9
    verts: list[NDArray[np.float64]] = []
    for i in range(len(N)):
        for j in range(i + 1, len(N)):
            c = np.cross(N[i], N[j])
            size = float(np.linalg.norm(c))
            if size > tol:
                verts += [c / size, -c / size]
    V: NDArray[np.float64] = np.zeros((0, 3))
    if verts:
        V = _unique_rows(np.round(np.array(verts, dtype=np.float64), 9).astype(np.float64) + 0.0)
    on = np.abs(V @ N.T) <= tol  # (vertices, circles): which circles pass through a vertex
    # along each circle, the vertices on it in angular order
    nxt: dict[tuple[int, int, int], int] = {}  # (vertex, circle, +-1) -> the next vertex
    for f in range(len(N)):
        ids = np.flatnonzero(on[:, f])
        if len(ids) < 2:
            continue
        a = np.eye(3)[int(np.argmin(np.abs(N[f])))]
        e1 = np.cross(N[f], a)
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(N[f], e1)
        ang = np.arctan2(V[ids] @ e2, V[ids] @ e1)
        ring = ids[np.argsort(ang)].tolist()
        for k, v in enumerate(ring):
            nxt[(v, f, 1)] = ring[(k + 1) % len(ring)]
            nxt[(v, f, -1)] = ring[k - 1]
    cand = []
    for q in range(len(V)):
        circles = np.flatnonzero(on[q]).tolist()
        for ai, A in enumerate(circles):
            for B in circles[ai + 1 :]:
                for sa in (1, -1):
                    for sb in (1, -1):
                        p, r = nxt.get((q, A, sa)), nxt.get((q, B, sb))
                        if p is not None and r is not None:
                            cand.append(V[p] + V[q] + V[r])
    D = np.array(cand).reshape(-1, 3)
    D = D[np.linalg.norm(D, axis=1) > tol]
    D /= np.linalg.norm(D, axis=1)[:, None]
    proj = D @ N.T
    D = D[(np.abs(proj) > tol).all(axis=1)]
    sg = np.sign(D @ N.T).astype(np.int8)
    keys, inv = np.unique(sg, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    dirs = np.zeros((len(keys), 3))
    np.add.at(dirs, inv, D)  # the mean of points of a convex cone lies in it
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    return keys, dirs


def _polygon_arrays(model: Solids) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Unit normal and one point (a triangle's centre) of every polygon of every solid,
    ``(n, 3)`` each, from the triangles grouped by polygon (cached on the model)."""
    cached = _POLYGON_ARRAYS.get(model)
    if cached is not None:
        return cached
    solids = [s for s in model.solids if len(s.faces)]
    if not solids:
        return np.zeros((0, 3)), np.zeros((0, 3))
    tris, owners = [], []
    base = 0
    for s in solids:
        tris.append(np.asarray(s.vertices, dtype=np.float64)[np.asarray(s.faces, dtype=np.int64)])
        owners.append(np.asarray(s.face_polygon, dtype=np.int64) + base)
        base += len(s.polygons)
    t = np.concatenate(tris)
    own = np.concatenate(owners)
    cr = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    n = np.zeros((base, 3))
    np.add.at(n, own, cr)
    c = np.zeros((base, 3))
    c[own] = t.mean(axis=1)
    n /= np.linalg.norm(n, axis=1)[:, None]
    _POLYGON_ARRAYS[model] = (n, c)
    return n, c


def _families(example: PolyhedralModel, tol: float) -> NDArray[np.float64]:
    fams: list[NDArray[np.float64]] = []
    for n in _polygon_arrays(example)[0]:
        if not any(abs(abs(float(n @ f)) - 1) <= tol for f in fams):
            first = next(x for x in n if abs(x) > 1e-12)
            fams.append(n if first > 0 else -n)
    return np.array(fams)


def _triangles(model: Solids) -> list[tuple[int, NDArray[np.float64]]]:
    return [(int(s.label), np.asarray(s.vertices, dtype=np.float64)[np.asarray(s.faces)])
            for s in model.solids]  # fmt: skip


def _samples(model: Solids, dense: int) -> NDArray[np.float64]:
    """Points where ``model``'s neighbourhoods are taken: vertices, edge pieces, triangles
    (``dense`` > 1: that many points along each edge and a grid on each triangle)."""
    pts = [np.asarray(s.vertices, dtype=np.float64) for s in model.solids]
    verts = _unique_rows(np.concatenate(pts) + 0.0) if pts else np.zeros((0, 3))
    out = [verts]
    if dense <= 1:
        if not pts:
            return verts
        tri = np.concatenate([np.asarray(s.vertices, dtype=np.float64)[np.asarray(s.faces)]
                              for s in model.solids])  # fmt: skip
        out.append(tri.mean(axis=1))
        # every edge once (by coordinates: solids have their own vertex arrays)
        ab = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
        key = np.where(_lex_less(ab[:, 0], ab[:, 1])[:, None, None], ab, ab[:, ::-1])
        edges = _unique_rows(key.reshape(-1, 6) + 0.0).reshape(-1, 2, 3)
        out.append(_edge_pieces(edges[:, 0], edges[:, 1], verts))
        return np.concatenate(out)
    for s in model.solids:
        v = np.asarray(s.vertices, dtype=np.float64)
        f = np.asarray(s.faces, dtype=np.int64)
        tri = v[f]
        edges = np.unique(np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]),
                                  axis=1), axis=0)  # fmt: skip
        a, b = v[edges[:, 0]], v[edges[:, 1]]
        ts = (np.arange(dense) + 0.5) / dense
        out.append((a[:, None] + ts[None, :, None] * (b - a)[:, None]).reshape(-1, 3))
        grid = [(i, j) for i in range(1, dense) for j in range(1, dense - i)]
        for i, j in grid:
            u, w = i / dense, j / dense
            out.append(tri[:, 0] + u * (tri[:, 1] - tri[:, 0]) + w * (tri[:, 2] - tri[:, 0]))
        out.append(tri.mean(axis=1))
    return np.concatenate(out)


def _unique_rows(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """The distinct rows of a float array (``-0.0`` given as ``0.0``), in some order."""
    a = np.ascontiguousarray(a)
    v = a.view(np.dtype((np.void, a.dtype.itemsize * a.shape[1]))).reshape(-1)
    _, idx = np.unique(v, return_index=True)
    out: NDArray[np.float64] = a[np.sort(idx)]
    return out


def _lex_less(p: NDArray[np.float64], q: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Row-wise lexicographic ``p < q`` of ``(n, 3)`` arrays."""
    out: NDArray[np.bool_] = (p[:, 0] < q[:, 0]) | ((p[:, 0] == q[:, 0]) & (
        (p[:, 1] < q[:, 1]) | ((p[:, 1] == q[:, 1]) & (p[:, 2] < q[:, 2]))))  # fmt: skip
    return out


def _edge_pieces(
    a: NDArray[np.float64], b: NDArray[np.float64], verts: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Midpoints of the pieces of the segments ``a -> b`` between the vertices on them."""
    if not len(a):
        return np.zeros((0, 3))
    scale = float(np.ptp(verts, axis=0).max()) if len(verts) else 1.0
    tol = 1e-9 * max(scale, 1.0)
    seg, t = points_on_segments(a, b, verts, tol)
    k = np.concatenate([np.arange(len(a)), np.arange(len(a)), seg])
    tt = np.concatenate([np.zeros(len(a)), np.ones(len(a)), t])
    order = np.lexsort((tt, k))
    k, tt = k[order], tt[order]
    same = k[1:] == k[:-1]
    mid = 0.5 * (tt[1:] + tt[:-1])[same]
    ks = k[1:][same]
    keep = tt[1:][same] > tt[:-1][same]  # repeated vertices give empty pieces
    d = b - a
    out: NDArray[np.float64] = a[ks[keep]] + mid[keep][:, None] * d[ks[keep]]
    return out


def _labelings(
    points: NDArray[np.float64], cells: tuple[NDArray[np.int8], NDArray[np.float64]],
    tris: list[tuple[int, NDArray[np.float64]]], planes: list[NDArray[np.float64]],
    normals: NDArray[np.float64], eps: float,
    window: tuple[NDArray[np.float64], NDArray[np.float64], Sequence[str]] | None = None,
) -> NDArray[np.int64]:  # fmt: skip
    """``(len(points), cells)``: the label just off each point in each cell's direction.

    Only the planes through a point (``planes[f]``: the offsets of the model's faces of
    family ``f``) can change the label around it, so one query per group of cells that agree
    on those planes suffices. ``window`` ``(lo, hi, faces)``: the model continues past
    those faces of the box ``lo..hi`` (a ground): a query past one is taken just inside."""
    signs, dirs = cells
    scale = max(1.0, float(np.abs(points).max()) if len(points) else 1.0)
    through = np.zeros((len(points), len(normals)), dtype=bool)
    for f, offs in enumerate(planes):
        if len(offs):  # the nearest offset (sorted), without a points x offsets matrix
            d = points @ normals[f]
            o = np.sort(offs)
            k = np.clip(np.searchsorted(o, d), 1, len(o) - 1) if len(o) > 1 else np.zeros(
                len(d), dtype=np.int64)  # fmt: skip
            near = np.minimum(np.abs(d - o[k]), np.abs(d - o[np.maximum(k - 1, 0)]))
            through[:, f] = near <= 1e-9 * scale
    out = np.zeros((len(points), len(dirs)), dtype=np.int64)
    code = through.astype(np.int64) @ (1 << np.arange(through.shape[1], dtype=np.int64))
    ucode, inv = np.unique(code, return_inverse=True)
    keys = (ucode[:, None] >> np.arange(through.shape[1])) & 1 > 0
    inv = inv.reshape(-1)
    jobs = []
    queries = []
    for k, key in enumerate(keys):
        idx = np.flatnonzero(inv == k)
        fams = np.flatnonzero(key)
        if fams.size:
            _, g = np.unique(signs[:, fams], axis=0, return_inverse=True)
            g = g.reshape(-1)
        else:
            g = np.zeros(len(signs), dtype=np.int64)
        rep = np.array([int(np.flatnonzero(g == j)[0]) for j in range(int(g.max()) + 1)])
        queries.append((points[idx][:, None, :] + eps * dirs[rep][None, :, :]).reshape(-1, 3))
        jobs.append((idx, rep, g))
    q = np.concatenate(queries) if queries else np.zeros((0, 3))
    if window is not None:
        lo, hi, faces = window
        inward = 1e-3 * eps  # well inside the query's cell next to the face
        for face in faces:
            a = "xyz".index(face[0])
            if face[1] == "-":
                q[:, a] = np.maximum(q[:, a], lo[a] + inward * (1 + 0.29 * a))
            else:
                q[:, a] = np.minimum(q[:, a], hi[a] - inward * (1 + 0.29 * a))
    lab_all = point_labels(q, tris) if queries else np.zeros(0, np.int64)
    pos = 0
    for idx, rep, g in jobs:
        lab = lab_all[pos : pos + len(idx) * len(rep)].reshape(len(idx), len(rep))
        pos += len(idx) * len(rep)
        out[idx] = lab[:, g]
    return out


def _plane_offsets(models: list[Solids], normals: NDArray[np.float64],
                   tol: float) -> list[NDArray[np.float64]]:  # fmt: skip
    """Per family, the offsets ``n . x`` of the models' faces of that orientation."""
    out: list[list[NDArray[np.float64]]] = [[] for _ in normals]
    for m in models:
        n, c = _polygon_arrays(m)
        off = (n * c).sum(axis=1)
        dots = n @ normals.T  # (polygons, families)
        for f in range(len(normals)):
            hit = np.abs(np.abs(dots[:, f]) - 1) <= tol
            out[f].append(off[hit] * np.sign(dots[hit, f]))
    return [np.unique(np.round(np.concatenate(o), 12)) for o in out]


def _frame(region: tuple[float, ...], outside: Mapping[str, int]) -> list[dict[str, Any]]:
    """Boxes of the outside labels around ``region``, in the precedence of
    :data:`~csplab.continuous.csp3d.FACE_ORDER` (``z`` faces span the corners, then ``x``,
    then ``y``)."""
    x0, y0, z0, x1, y1, z1 = region
    t = max(x1 - x0, y1 - y0, z1 - z0)
    boxes = {
        "z-": ((x0 - t, y0 - t, z0 - t), (x1 + t, y1 + t, z0)),
        "z+": ((x0 - t, y0 - t, z1), (x1 + t, y1 + t, z1 + t)),
        "x-": ((x0 - t, y0 - t, z0), (x0, y1 + t, z1)),
        "x+": ((x1, y0 - t, z0), (x1 + t, y1 + t, z1)),
        "y-": ((x0, y0 - t, z0), (x1, y0, z1)),
        "y+": ((x0, y1, z0), (x1, y1 + t, z1)),
    }
    out = []
    for face, (lo, hi) in boxes.items():
        b = int(outside.get(face, 0))
        if b:
            v = [[x, y, z] for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])]
            f = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [1, 3, 7, 5], [0, 4, 6, 2]]
            out.append({"label": b, "vertices": v, "faces": f})
    return out


def violations3(
    example: PolyhedralModel,
    model: PolyhedralModel,
    *,
    angle_tol: float = ANGLE_TOL,
    region: tuple[float, float, float, float, float, float] | None = None,
    outside: Mapping[str, int] | None = None,
    dense: int = 8,
    ground: Sequence[str] = (),
) -> Violations:
    """Every place where ``model`` breaks Eq. 4.1 w.r.t. ``example`` (see the module
    docstring); ``len() == 0`` means a valid output. ``region`` (``x0, y0, z0, x1, y1,
    z1``): only points in it are checked; outside it is empty space, or the labels
    ``outside`` gives per face (``{"z-": 1}``: a ground below). ``ground``: faces (``"z-"``
    ...) past which both models continue, the example past its bounding box and the output
    past ``region`` (needed with a ground): what lies past such a face is what lies just
    inside it, so a solid standing on the face has no surface there."""
    defects: list[Defect] = []
    solids: Solids = model
    ground = tuple(ground)
    if ground and region is None:
        raise InputError("a ground needs the output's region")
    if region is not None and outside and any(v for f, v in outside.items() if f not in ground):
        fixed = {f: v for f, v in outside.items() if f not in ground}
        frame = PolyhedralModel(_frame(tuple(region), fixed), merge_coplanar=False)
        solids = _Joined([*model.solids, *frame.solids], model)
    fams = _families(example, angle_tol)
    for b in solids.labels:
        if b not in example.labels:
            defects.append(Defect("label", (math.nan, math.nan),
                                  f"label {b} does not occur in the example"))  # fmt: skip
    pn, pc = _polygon_arrays(solids)
    off_family = (np.abs(np.abs(pn @ fams.T) - 1) > angle_tol).all(axis=1)
    for i in np.flatnonzero(off_family).tolist():
        n, c = pn[i], pc[i].tolist()
        where = tuple(round(x, 6) for x in c)
        msg = f"a face with normal {np.round(n, 6)} at {where}, an orientation the example"
        defects.append(Defect("direction", (c[0], c[1]), msg + " does not have"))
    if any(d.kind == "direction" for d in defects) or not len(solids.solids):
        return Violations(defects)
    # every family plus the axes, so that at least three independent normals exist
    N = np.concatenate([fams, np.eye(3)])
    keep: list[int] = []
    for i, n in enumerate(N):
        if not any(abs(abs(float(n @ N[j])) - 1) <= angle_tol for j in keep):
            keep.append(i)
    N = N[keep]
    cells = cone_cells(N)
    dirs = cells[1]
    lo = np.minimum(np.array(example.bounds[:3]), np.array(solids.bounds[:3]))
    hi = np.maximum(np.array(example.bounds[3:]), np.array(solids.bounds[3:]))
    scale = float(max(1.0, (hi - lo).max()))
    eps = 1e-5 * scale
    E_tris, M_tris = _triangles(example), _triangles(solids)
    e_pts = _samples(example, dense)
    e_planes = _plane_offsets([example], N, angle_tol)
    e_box = np.array(example.bounds[:3]), np.array(example.bounds[3:])
    e_win = (*e_box, ground) if ground else None
    allowed = {tuple(r) for r in _labelings(e_pts, cells, E_tris, e_planes, N, eps,
                                            e_win).tolist()}  # fmt: skip
    allowed |= {(b,) * len(dirs) for b in (0, *example.labels)}
    m_pts = _samples(solids, 1)
    if region is not None:
        r = np.asarray(region, dtype=np.float64)
        t = 1e-9 * scale
        m_pts = m_pts[((m_pts >= r[:3] - t) & (m_pts <= r[3:] + t)).all(axis=1)]
    seen: set[tuple[int, ...]] = set()
    m_planes = _plane_offsets([solids], N, angle_tol)
    m_win = None
    if ground and region is not None:
        m_win = (np.asarray(region[:3], dtype=np.float64), np.asarray(region[3:],
                 dtype=np.float64), ground)  # fmt: skip
    m_arr = _labelings(m_pts, cells, M_tris, m_planes, N, eps, m_win)
    # each distinct neighbourhood once, at its first point (in the points' order)
    rows = np.ascontiguousarray(m_arr.astype(np.int32))
    _, first = np.unique(rows.view(np.dtype((np.void, rows.dtype.itemsize * rows.shape[1]))),
                         return_index=True)  # fmt: skip
    for i in np.sort(first).tolist():
        p, lab = m_pts[i], m_arr[i].tolist()
        key = tuple(lab)
        if key in allowed or key in seen:
            continue
        seen.add(key)
        defects.append(Defect("neighbourhood", (float(p[0]), float(p[1])),
                              f"the neighbourhood at {tuple(round(float(x), 6) for x in p)} "
                              f"(labels {sorted(set(lab))} around it) does not occur in the "
                              "example"))  # fmt: skip
    return Violations(defects)


# ----------------------------------------------------------------------------- user constraints
def user_violations3(
    model: PolyhedralModel,
    c: UserConstraints3,
    *,
    origin: Sequence[float],
    spacing: float,
) -> list[Defect]:
    """The user constraints ``model`` breaks, from its solids alone (see the module
    docstring); ``origin`` and ``spacing`` place the plane lattice and the voxels (the
    region's corner and the plane spacing)."""
    out: list[Defect] = []
    o = np.asarray(origin, dtype=np.float64)
    s = float(spacing)
    tol = 1e-7
    for b, n in c.dimensional:
        nn = np.asarray(n, dtype=np.float64)
        for i, sol in enumerate(model.solids):
            if sol.label != b:
                continue
            k = ((np.asarray(sol.vertices) - o) / s) @ nn
            if k.max() - k.min() > 1 + tol:
                p = sol.vertices[int(k.argmax())]
                out.append(Defect("dimensional", (float(p[0]), float(p[1])),
                                  f"solid {i} (label {b}) spans {k.max() - k.min():.6g} plane "
                                  f"spacings along {list(n)} (at most 1)"))  # fmt: skip
    if c.allowed and c.voxel is not None:
        out += _large_scale(model, c, o, s)
    for b in c.connected:
        groups = _touching_groups([sol for sol in model.solids if sol.label == b])
        if groups != 1:
            out.append(Defect("connected", (float("nan"), float("nan")),
                              f"the objects of label {b} form {groups} separate groups "
                              "(exactly one is required)"))  # fmt: skip
    return out


def _touching_groups(solids: list[Solid]) -> int:
    """Groups of solids whose closures meet at a common vertex."""
    if len(solids) <= 1:
        return len(solids)
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    pts = np.concatenate([np.asarray(sol.vertices) for sol in solids])
    owner = np.repeat(np.arange(len(solids)), [len(sol.vertices) for sol in solids])
    _, inv = np.unique(np.round(pts, 9), axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    n = len(solids)
    g = coo_matrix((np.ones(len(owner)), (owner, n + inv)), shape=(n + int(inv.max()) + 1,) * 2)
    comp = connected_components(g, directed=False)[1][:n]
    return len(np.unique(comp))


def _large_scale(
    model: PolyhedralModel, c: UserConstraints3, o: NDArray[np.float64], s: float
) -> list[Defect]:
    """Solids of a large-scale label meeting a voxel not allowed for it (manifold3d
    intersection volume above 1e-9 of the voxel)."""
    import manifold3d as man

    assert c.voxel is not None
    size = np.asarray(c.voxel, dtype=np.float64) * s
    out: list[Defect] = []
    for b, cells in c.allowed:
        for i, sol in enumerate(model.solids):
            if sol.label != b:
                continue
            lo = np.floor((sol.vertices.min(axis=0) - o) / size + 1e-9).astype(int)
            hi = np.ceil((sol.vertices.max(axis=0) - o) / size - 1e-9).astype(int)
            m = None
            for x in range(lo[0], hi[0]):
                for y in range(lo[1], hi[1]):
                    for z in range(lo[2], hi[2]):
                        if (x, y, z) in cells:
                            continue
                        if m is None:
                            m = sol.to_manifold(f"solid {i}")
                        box = man.Manifold.cube(size.tolist()).translate(
                            (o + np.array([x, y, z]) * size).tolist()
                        )
                        vol = float((m ^ box).volume())
                        if vol > 1e-9 * float(np.prod(size)):
                            out.append(Defect("large-scale", (float(o[0] + x * size[0]),
                                                              float(o[1] + y * size[1])),
                                              f"solid {i} (label {b}) has volume {vol:.6g} "
                                              f"in voxel {[x, y, z]}, where label {b} is "
                                              "not allowed"))  # fmt: skip
    return out
