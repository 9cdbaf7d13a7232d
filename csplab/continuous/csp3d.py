"""Continuous model synthesis in 3D as a binary CSP (thesis Sec. 4.5.3-4.5.6; 2008 paper
Sec. 3.4, Alg. 2).

A neighbourhood is a label per cell of the central arrangement of all plane families
(:func:`csplab.continuous.space.central_cells`): the thesis' Boolean expression of
half-spaces (Fig. 4.17, 4.18), evaluated on every cell. The example's neighbourhoods
(:func:`example_signatures3`) come from the example cut by the same planes: at every vertex
and edge of that arrangement the label of each local cell is found by point location (the
generalised winding number of the example's triangles, :func:`labels_at`) just off the point
in a direction inside the cell; faces and solid interiors are derived from the edges and the
labels. A vertex of the output arrangement may take every example neighbourhood that uses
only its planes (Sec. 4.5.4; the tetrahedron's top vertex: the nine states of the 2008
paper's Fig. 9), an edge likewise with the planes containing it.

Variables are the arrangement's vertices and edges (values: indices into their type's state
list; value 0 is all-empty); one relation per (vertex type, ray, edge type): a vertex state
and an edge state agree when the vertex's labels, evaluated in the direction of the edge,
are the edge's labels (Sec. 4.5.5). It is an ordinary :class:`~csplab.problem.Problem`, so
every solver runs on it; ``positions`` are in plane spacings for ``blocks``.

Examples
--------
>>> from csplab.continuous.polyhedra import PolyhedralModel
>>> tet = PolyhedralModel([{"label": 1, "vertices": [[0, 0, 0], [4, 0, 0], [0, 4, 0],
...     [0, 0, 4]], "faces": [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]}])
>>> C = ContinuousCSP3(tet, (3, 3, 3))
>>> len(C.signatures)                  # Sec. 4.5.3: the tetrahedron's 16 labels
16
>>> C.states_at_planes([(1, 0, 0), (0, 1, 0), (1, 1, 1)])   # its top vertex (Fig. 9)
9
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.continuous.space import Arrangement3, Lattice3
from csplab.errors import InputError
from csplab.problem import Problem

__all__ = ["FACE_ORDER", "ContinuousCSP3", "example_signatures3", "labels_at"]

#: the region's faces; a point outside several takes the label of the first (the ground
#: ``z-`` wins at the bottom edges)
FACE_ORDER = ("z-", "z+", "x-", "x+", "y-", "y+")


def _boundary_faces(boundary: int | Mapping[str, int]) -> dict[str, int]:
    """The label outside each face of the region: one label for all, or ``{face: label}``
    (faces not named: 0, empty space), e.g. ``{"z-": 1}`` for a ground below."""
    if isinstance(boundary, Mapping):
        bad = sorted(set(boundary) - set(FACE_ORDER))
        if bad:
            raise InputError(f"boundary faces are {', '.join(FACE_ORDER)}, not {', '.join(bad)}")
        return {f: int(boundary.get(f, 0)) for f in FACE_ORDER}
    return {f: int(boundary) for f in FACE_ORDER}


Labeling = tuple[int, ...]


def _solid_angles(p: NDArray[np.float64], tri: NDArray[np.float64]) -> NDArray[np.float64]:
    """Signed solid angles ``(len(p),)`` of the triangles ``tri`` ``(m, 3, 3)`` summed, seen
    from the points ``p`` (Van Oosterom & Strackee)."""
    out = np.zeros(len(p))
    step = max(1, 200_000 // max(1, len(tri)))  # points per chunk: about 2e5 pairs
    for start in range(0, len(p), step):
        q = p[start : start + step, None, None, :]
        r = tri[None, :, :, :] - q  # (P, m, 3, 3)
        ln = np.linalg.norm(r, axis=3)
        a, b, c = r[:, :, 0], r[:, :, 1], r[:, :, 2]
        la, lb, lc = ln[:, :, 0], ln[:, :, 1], ln[:, :, 2]
        num = np.einsum("pmi,pmi->pm", a, np.cross(b, c))
        ab = np.einsum("pmi,pmi->pm", a, b)
        ac = np.einsum("pmi,pmi->pm", a, c)
        bc = np.einsum("pmi,pmi->pm", b, c)
        den = la * lb * lc + ab * lc + ac * lb + bc * la
        out[start : start + step] = 2 * np.arctan2(num, den).sum(axis=1)
    return out


def labels_at(
    points: NDArray[np.float64],
    triangles: dict[int, NDArray[np.float64]] | list[tuple[int, NDArray[np.float64]]],
) -> NDArray[np.int64]:
    """The label at each point: the label whose closed triangle mesh (``(m, 3, 3)``, outward
    orientation; a dict by label, or a list of ``(label, mesh)`` per solid) winds around it
    (generalised winding number > 1/2), else 0. A closed surface does not wind around points
    outside its bounding box, so each mesh is evaluated only at the points inside its box."""
    items = list(triangles.items()) if isinstance(triangles, dict) else list(triangles)
    lab = np.zeros(len(points), dtype=np.int64)
    order = np.argsort(points[:, 0], kind="stable")
    xs = points[order, 0]
    for b, tri in items:
        lo, hi = tri.reshape(-1, 3).min(axis=0), tri.reshape(-1, 3).max(axis=0)
        cand = order[np.searchsorted(xs, lo[0], "left") : np.searchsorted(xs, hi[0], "right")]
        inside = cand[((points[cand] >= lo) & (points[cand] <= hi)).all(axis=1)]
        if not inside.size:
            continue
        w = _solid_angles(points[inside], tri) / (4 * np.pi)
        lab[inside[w > 0.5]] = b
    return lab


def _groups(signs: NDArray[np.int8], fams: NDArray[np.int64]) -> tuple[NDArray[np.int64], int]:
    """Group id of each full cell by its signs on ``fams`` (the local cells there)."""
    if fams.size == 0:
        return np.zeros(len(signs), dtype=np.int64), 1
    _, inv = np.unique(signs[:, fams], axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    return inv.astype(np.int64), int(inv.max()) + 1


def _triangles(
    model: Any, lattice: Lattice3, shift: float
) -> list[tuple[int, NDArray[np.float64]]]:
    """Each solid's triangles in lattice units (plus ``shift``), with its label."""
    out = []
    for s in model.solids:
        v = lattice.to_lattice(np.asarray(s.vertices, dtype=np.float64)) + shift
        out.append((int(s.label), v[np.asarray(s.faces, dtype=np.int64)]))
    return out


def _local_labels(
    A: Arrangement3,
    points: NDArray[np.float64],
    fams_on: NDArray[np.bool_],
    tris: list[tuple[int, NDArray[np.float64]]],
    index: dict[int, int],
) -> list[Labeling]:
    """Full labelings (over the central cells) of the neighbourhoods at ``points`` whose
    planes are ``fams_on`` (per point), by point location just off each point."""
    signs, dirs = A.cells
    eps = 1e-3 / (A.D * float(np.abs(A.normals).sum(axis=1).max()))
    cache: dict[bytes, tuple[NDArray[np.int64], int, NDArray[np.int64]]] = {}
    queries, owners = [], []
    for i, fo in enumerate(fams_on):
        key = fo.tobytes()
        if key not in cache:
            g, ng = _groups(signs, np.flatnonzero(fo))
            rep = np.array([int(np.flatnonzero(g == k)[0]) for k in range(ng)])
            cache[key] = (g, ng, rep)
        g, ng, rep = cache[key]
        queries.append(points[i] + eps * dirs[rep])
        owners.append(i)
    q = np.concatenate(queries) if queries else np.zeros((0, 3))
    lab = labels_at(q, tris)
    lab = np.array([index[int(b)] if b else 0 for b in lab], dtype=np.int64)
    out = []
    pos = 0
    for fo in fams_on:
        g, ng, _ = cache[fo.tobytes()]
        local = lab[pos : pos + ng]
        pos += ng
        out.append(tuple(int(x) for x in local[g]))
    return out


def example_signatures3(example: Any, lattice: Lattice3, index: dict[int, int]) -> set[Labeling]:
    """Every neighbourhood of ``example`` (labels compacted by ``index``) as a full labeling
    of the central cells: vertices and edges of its own arrangement (its bounding box plus
    one spacing), the faces next to those edges, and the solid interiors."""
    pts = np.concatenate([np.asarray(s.vertices, dtype=np.float64) for s in example.solids])
    lo = np.floor(lattice.to_lattice(pts).min(axis=0) + 1e-9)
    hi = np.ceil(lattice.to_lattice(pts).max(axis=0) - 1e-9)
    shift = 1.0 - lo
    A = Arrangement3(lattice, tuple(int(h - l) + 2 for l, h in zip(lo, hi, strict=True)))
    tris = [(b, t + shift) for b, t in _triangles(example, lattice, 0.0)]
    signs, _ = A.cells
    sigs: set[Labeling] = {(b,) * len(signs) for b in (0, *index.values())}
    sigs |= set(_local_labels(A, A.vertex_xyz(), A.on, tris, index))
    efam = A.edge_families()
    edge_sigs = _local_labels(A, A.edge_xyz(), efam, tris, index)
    sigs |= set(edge_sigs)
    # faces beside each edge: in each plane through the edge, both half-planes
    N = A.normals
    for e, lab in enumerate(edge_sigs):
        u = A.lines[A.edge_line[e]]
        for f in np.flatnonzero(efam[e]):
            for d in (np.cross(N[f], u), -np.cross(N[f], u)):
                sd = np.sign(N @ d)
                others = [k for k in np.flatnonzero(efam[e]) if k != f]
                sel = np.all(signs[:, others] == sd[others], axis=1) if others else None
                face: dict[int, int] = {}
                for c in np.flatnonzero(sel) if sel is not None else range(len(signs)):
                    face[int(signs[c, f])] = lab[c]
                sigs.add(tuple(face[int(signs[c, f])] for c in range(len(signs))))
    return sigs


class ContinuousCSP3:
    """The binary CSP of continuous model synthesis for a polyhedral ``example`` in an
    ``A x B x C`` box of plane spacings (see the module docstring).

    Attributes
    ----------
    problem : Problem
    arrangement : Arrangement3
    labels : tuple of int
        Compact label index -> model label (0: empty space).
    signatures : set
        The example's neighbourhoods (full labelings of the central cells).
    """

    def __init__(
        self,
        example: Any,
        size: Sequence[int],
        *,
        spacing: float | None = None,
        snap: bool = False,
        boundary: int | Mapping[str, int] = 0,
    ) -> None:
        if not example.solids:
            raise InputError(f"{example.source}: an example needs at least one solid")
        pts = np.concatenate([np.asarray(s.vertices, dtype=np.float64) for s in example.solids])
        polys, base = [], 0
        for s in example.solids:
            polys += [[base + int(i) for i in p] for p in s.polygons]
            base += len(s.vertices)
        self.example = example
        self.lattice = Lattice3.of(pts, polys, spacing, snap=snap, where=example.source)
        self.labels: tuple[int, ...] = (0, *example.labels)
        index = {b: i for i, b in enumerate(self.labels)}
        faces = _boundary_faces(boundary)
        for face, lab in faces.items():
            if lab not in index:
                raise InputError(
                    f"boundary {face}={lab}: label {lab} does not occur in the example"
                )
        self.boundary = faces
        self.signatures = example_signatures3(example, self.lattice, index)
        sig = np.array(sorted(self.signatures), dtype=np.int64)
        A = self.arrangement = Arrangement3(self.lattice, size)
        signs, _ = A.cells
        F, N = A.F, A.normals
        side_fam = [A.axis_family(a) for a in range(3)]

        def outside_groups(fams: NDArray[np.int64], sides: int, g: NDArray[np.int64],
                           ng: int) -> NDArray[np.int64]:  # fmt: skip
            """Per group: the compact label it must have outside the region, or -1 (inside);
            a group outside several faces takes the first of ``FACE_ORDER``."""
            out = np.full(ng, -1, dtype=np.int64)
            for face in reversed(FACE_ORDER):
                a, hi = "xyz".index(face[0]), face[1] == "+"
                bit = (2 if hi else 1) << (2 * a)
                if sides & bit:
                    out[np.unique(g[signs[:, side_fam[a]] == (1 if hi else -1)])] = index[
                        faces[face]
                    ]
            return out

        def states(fams: NDArray[np.int64], sides: int) -> tuple[list[Labeling], Any]:
            g, ng = _groups(signs, fams)
            rep = np.array([int(np.flatnonzero(g == k)[0]) for k in range(ng)])
            local = sig[:, rep]  # (nsig, ng)
            ok = (sig == local[:, g]).all(axis=1)  # factors through these planes
            out = outside_groups(fams, sides, g, ng)
            req = out >= 0
            ok &= (local[:, req] == out[req]).all(axis=1)
            found = sorted({tuple(int(x) for x in row) for row in local[ok]},
                           key=lambda st: (any(st), st))  # fmt: skip
            return found, (g, ng, out)

        # vertex types
        vside = A.on_side()
        vmask = A.on.astype(np.int64) @ (1 << np.arange(F, dtype=np.int64))
        vkeys, vtype = np.unique((vmask << 6) | vside, return_inverse=True)
        vtype = vtype.reshape(-1)
        self.vertex_type = vtype
        self.vtypes: list[tuple[NDArray[np.int64], list[Labeling], NDArray[np.int64]]] = []
        self.vertex_outside: list[NDArray[np.int64]] = []
        for key in vkeys.tolist():
            fams = np.array([f for f in range(F) if (key >> 6) >> f & 1], dtype=np.int64)
            st, (g, _, out) = states(fams, key & 63)
            if not st:
                raise InputError(f"{example.source}: no neighbourhood of the example fits a "
                                 f"vertex on planes {N[fams].tolist()} with boundary "
                                 f"{self.boundary}")  # fmt: skip
            self.vtypes.append((fams, st, g))
            self.vertex_outside.append(out)
        # edge types
        efam = A.edge_families()
        eside = vside[A.edge_src] & vside[A.edge_dst]
        emask = efam.astype(np.int64) @ (1 << np.arange(F, dtype=np.int64))
        ekeys, etype = np.unique((emask << 6) | eside, return_inverse=True)
        etype = etype.reshape(-1)
        self.etypes: list[tuple[NDArray[np.int64], list[Labeling], NDArray[np.int64]]] = []
        for key in ekeys.tolist():
            fams = np.array([f for f in range(F) if (key >> 6) >> f & 1], dtype=np.int64)
            st, (g, _, _) = states(fams, key & 63)
            self.etypes.append((fams, st, g))
        nst = max(len(t[1]) for t in (*self.vtypes, *self.etypes))
        K = self.K = nst
        nv, ne = A.n_vertices, A.n_edges
        dom = np.zeros((nv + ne, K), dtype=bool)
        vn = np.array([len(t[1]) for t in self.vtypes])
        en = np.array([len(t[1]) for t in self.etypes])
        dom[:nv] = np.arange(K)[None, :] < vn[vtype][:, None]
        dom[nv:] = np.arange(K)[None, :] < en[etype][:, None]
        # relations per (vertex type, ray, edge type)
        rel_ids: dict[bytes, int] = {}
        rels: list[NDArray[np.bool_]] = []
        memo: dict[tuple[int, int, int, int], int] = {}

        def relation(t: int, line: int, sgn: int, et: int) -> int:
            k = (t, line, sgn, et)
            if k in memo:
                return memo[k]
            vf, vst, vg = self.vtypes[t]
            _, est, eg = self.etypes[et]
            r = sgn * A.lines[line]
            sr = np.sign(N @ r)
            # the full cell just off the edge in direction r: signs of the planes through
            # the vertex but not the edge from r, the edge's own planes free
            target = {}
            for c in range(len(signs)):
                want = signs[c].copy()
                away = [f for f in vf if sr[f] != 0]
                want[away] = sr[away]
                match = np.flatnonzero((signs[:, vf] == want[vf]).all(axis=1))
                target[int(eg[c])] = int(vg[match[0]])
            eidx = {st: i for i, st in enumerate(est)}
            M = np.zeros((K, K), dtype=bool)
            ne_groups = len(est[0]) if est else 0
            for i, st in enumerate(vst):
                induced = tuple(st[target[j]] for j in range(ne_groups))
                jj = eidx.get(induced)
                if jj is not None:
                    M[i, jj] = True
            kb = M.tobytes()
            if kb not in rel_ids:
                rel_ids[kb] = len(rels)
                rels.append(M)
            memo[k] = rel_ids[kb]
            return memo[k]

        pos = np.concatenate([A.vertex_xyz(), A.edge_xyz()])
        order = np.lexsort((pos[:, 2], pos[:, 1], pos[:, 0]))
        var = np.empty(nv + ne, dtype=np.int64)
        var[order] = np.arange(nv + ne)
        self.var_vertex, self.var_edge = var[:nv], var[nv:]
        arcs = np.empty((2 * ne, 3), dtype=np.int64)
        for e in range(ne):
            a, b, li, et = (
                int(A.edge_src[e]),
                int(A.edge_dst[e]),
                int(A.edge_line[e]),
                int(etype[e]),
            )
            arcs[2 * e] = (var[a], var[nv + e], relation(int(vtype[a]), li, 1, et))
            arcs[2 * e + 1] = (var[b], var[nv + e], relation(int(vtype[b]), li, -1, et))
        self.edge_type = etype
        self.problem = Problem(
            (nv + ne,), dom[order], np.stack(rels), arcs,
            name=getattr(example, "name", "") or "continuous3d",
            meta={"continuous": True, "dim": 3, "size": list(A.size),
                  "spacing": float(self.lattice.spacing), "families": N.tolist(),
                  "vertices": nv, "edges": ne, "boundary": dict(self.boundary)},
            positions=pos[order],
        )  # fmt: skip

    def model(self, grid: ArrayLike, *, name: str = "") -> Any:
        """The output solids of a solution: on every plane the regions between two
        different labels are traced from the vertex states (every vertex kept, so that the
        surface is watertight), triangulated (constrained Delaunay) and given to the label
        below (outward normal up) and the label above (down); each label's triangles
        split into closed surfaces, validated as a
        :class:`~csplab.continuous.polyhedra.PolyhedralModel`."""
        return _model3(self, grid, name)

    def states_at_planes(self, normals: Sequence[Sequence[int]]) -> int:
        """How many example neighbourhoods use only planes with these normals (a vertex
        where exactly those planes meet, inside the region)."""
        A = self.arrangement
        want = {tuple(int(x) for x in n) for n in normals}
        fams = np.array([f for f in range(A.F) if tuple(A.normals[f].tolist()) in want])
        if len(fams) != len(want):
            raise InputError(f"not all of {sorted(want)} are plane families here")
        signs, _ = A.cells
        g, ng = _groups(signs, fams)
        sig = np.array(sorted(self.signatures), dtype=np.int64)
        rep = np.array([int(np.flatnonzero(g == k)[0]) for k in range(ng)])
        return int((sig == sig[:, rep][:, g]).all(axis=1).sum())

    def encode(self, model: Any) -> NDArray[np.int32]:
        """The assignment that a polyhedral model lying on the planes describes (point
        location around every vertex and edge); -1 where a neighbourhood is not a state."""
        A = self.arrangement
        index = {b: i for i, b in enumerate(self.labels)}
        for b in model.labels:
            if b not in index:
                raise InputError(f"label {b} does not occur in the example")
        tris = _triangles(model, self.lattice, 0.0)
        grid = np.full(self.problem.n, -1, dtype=np.int32)
        for what, pts, fams_on, types, tlist, var in (
            ("v", A.vertex_xyz(), A.on, self.vertex_type, self.vtypes, self.var_vertex),
            ("e", A.edge_xyz(), A.edge_families(), self.edge_type, self.etypes, self.var_edge),
        ):
            labs = _local_labels(A, pts, fams_on, tris, index)
            size = np.array(A.size, dtype=np.float64)
            for i, full in enumerate(labs):
                _, st, g = tlist[int(types[i])]
                ng = int(g.max()) + 1
                local = [0] * ng
                for c, b in enumerate(full):
                    local[int(g[c])] = b
                # outside the region: the boundary label of the first face it is outside
                _, dirs = A.cells
                for k in range(ng):
                    c = int(np.flatnonzero(g == k)[0])
                    q = pts[i] + 1e-3 * dirs[c]
                    for face in FACE_ORDER:
                        a = "xyz".index(face[0])
                        if (q[a] > size[a]) if face[1] == "+" else (q[a] < 0):
                            local[k] = index[self.boundary[face]]
                            break
                lookup = {s: j for j, s in enumerate(st)}
                grid[var[i]] = lookup.get(tuple(local), -1)
            del what
        return grid


def _plane_basis(n: NDArray[np.int64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Orthonormal ``e1, e2`` with ``(e1, e2, n)`` right-handed (counter-clockwise in the
    plane as seen from the side ``n`` points to)."""
    nf = n.astype(np.float64) / np.linalg.norm(n)
    a = np.eye(3)[int(np.argmin(np.abs(nf)))]
    e1 = np.cross(nf, a)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(nf, e1)


def _trace(
    rays: dict[int, list[tuple[float, int, int]]],
    sect: dict[int, list[tuple[int, int]]],
    pair: tuple[int, int],
) -> list[list[int]]:
    """Rings (vertex ids, every vertex kept) around the in-plane region whose sectors carry
    ``pair``, counter-clockwise; ``rays[v]`` are ``(angle, other vertex, ray id)`` sorted by
    angle, ``sect[v][i]`` the pair of the sector after ray ``i``."""
    where = {(v, int(w)): i for v, rs in rays.items() for i, (_, w, _) in enumerate(rs)}
    starts = [(v, i) for v in rays for i in range(len(rays[v]))
              if sect[v][i] == pair and sect[v][i - 1] != pair]  # fmt: skip
    used: set[tuple[int, int]] = set()
    rings = []
    for start in starts:
        if start in used:
            continue
        ring: list[int] = []
        v, i = start
        while (v, i) not in used:
            used.add((v, i))
            w = rays[v][i][1]
            ring.append(w)
            j = where[(w, v)]  # the ray at w pointing back to v
            k = j - 1
            m = len(rays[w])
            while sect[w][(k - 1) % m] == pair:
                k -= 1
            v, i = w, k % m
        rings.append(ring)
    return rings


def _model3(self: ContinuousCSP3, grid: ArrayLike, name: str = "") -> Any:
    """See :meth:`ContinuousCSP3.model`."""
    import shapely

    from csplab.continuous.polyhedra import PolyhedralModel

    A = self.arrangement
    N = A.normals
    signs, _ = A.cells
    g = np.asarray(grid, dtype=np.int64).reshape(-1)
    if g.shape != (self.problem.n,) or (g < 0).any():
        raise InputError("model() needs a complete solution of this problem")
    vstate = g[self.var_vertex]
    XYZ = np.stack([A.X, A.Y, A.Z], axis=1)
    s = XYZ @ N.T
    xyz = A.vertex_xyz()
    size = np.array(A.size, dtype=np.float64)
    efam = A.edge_families()
    lookups: dict[int, dict[tuple[int, ...], int]] = {}

    def group_of(t: int, sig: tuple[int, ...]) -> int:
        if t not in lookups:
            fams, _, gid = self.vtypes[t]
            lookups[t] = {tuple(int(x) for x in signs[c, fams]): int(gid[c])
                          for c in range(len(signs))}  # fmt: skip
        return lookups[t].get(sig, -1)

    sector_cache: dict[tuple[int, ...], tuple[int, int]] = {}

    def sector_groups(v: int, t: int, f: int, e1: NDArray[np.float64], e2: NDArray[np.float64],
                      a0: float, a1: float, nrays: int) -> tuple[int, int]:  # fmt: skip
        """The groups above and below plane ``f`` of the in-plane sector from angle ``a0``
        to ``a1`` at a vertex of type ``t`` (-1, -1: outside the region)."""
        if nrays == 1:
            a1 = a0 + 2 * np.pi
        if a1 <= a0:
            a1 += 2 * np.pi
        mid = 0.5 * (a0 + a1)
        d = np.cos(mid) * e1 + np.sin(mid) * e2
        q = xyz[v] + 1e-6 * d
        if (q < 0).any() or (q > size).any():
            return -1, -1
        fams = self.vtypes[t][0]
        proj = N[fams] @ d
        sig = [int(np.sign(x)) if abs(x) > 1e-9 else 0 for x in proj]
        out = []
        for side in (1, -1):
            sg = tuple(side if int(fk) == f else sig[j] for j, fk in enumerate(fams))
            out.append(group_of(t, sg) if 0 not in sg else -1)
        return out[0], out[1]

    tris: dict[int, list[tuple[int, int, int]]] = {}
    for f in range(A.F):
        sel = np.flatnonzero(efam[:, f])
        if not sel.size:
            continue
        e1, e2 = _plane_basis(N[f])
        kk = s[A.edge_src[sel], f] // A.D
        for k in np.unique(kk).tolist():
            es = sel[kk == k]
            rays: dict[int, list[tuple[float, int, int]]] = {}
            src, dst = A.edge_src[es], A.edge_dst[es]
            dvec = xyz[dst] - xyz[src]
            ang_f = np.arctan2(dvec @ e2, dvec @ e1).tolist()
            ang_b = np.arctan2(-dvec @ e2, -dvec @ e1).tolist()
            line = A.edge_line[es].tolist()
            for a, b, li, af, ab in zip(src.tolist(), dst.tolist(), line, ang_f, ang_b,
                                        strict=True):  # fmt: skip
                rays.setdefault(a, []).append((af, b, 2 * li))
                rays.setdefault(b, []).append((ab, a, 2 * li + 1))
            sect: dict[int, list[tuple[int, int]]] = {}
            for v, rs in rays.items():
                rs.sort()
                t = int(self.vertex_type[v])
                st = self.vtypes[t][1][int(vstate[v])]
                out = []
                for i in range(len(rs)):
                    nxt = rs[(i + 1) % len(rs)]
                    ck = (t, f, rs[i][2], nxt[2], len(rs))
                    if ck not in sector_cache:
                        sector_cache[ck] = sector_groups(v, t, f, e1, e2, rs[i][0], nxt[0],
                                                         len(rs))  # fmt: skip
                    gp, gm = sector_cache[ck]
                    outside = self.vertex_outside[t]  # outside the region: not the output
                    out.append((st[gp] if gp >= 0 and outside[gp] < 0 else -1,
                                st[gm] if gm >= 0 and outside[gm] < 0 else -1))  # fmt: skip
                sect[v] = out
            pairs = {p for ps in sect.values() for p in ps if p[0] != p[1] and max(p) > 0}
            for pair in pairs:
                rings = _trace(rays, sect, pair)
                uv = {v: (float(xyz[v] @ e1), float(xyz[v] @ e2)) for r in rings for v in r}
                key = {(round(x, 7), round(y, 7)): v for v, (x, y) in uv.items()}
                polys = _rings_to_polygons([[uv[v] for v in r] for r in rings])
                for poly in polys:
                    for tri in shapely.constrained_delaunay_triangles(poly).geoms:
                        c = np.asarray(tri.exterior.coords)[:3]
                        ids = [key[(round(x, 7), round(y, 7))] for x, y in c]
                        area = (c[1, 0] - c[0, 0]) * (c[2, 1] - c[0, 1]) - (
                            c[1, 1] - c[0, 1]) * (c[2, 0] - c[0, 0])  # fmt: skip
                        if area < 0:
                            ids = [ids[0], ids[2], ids[1]]  # counter-clockwise seen from +n
                        above, below = pair
                        if below > 0:  # solid below: outward normal +n
                            tris.setdefault(below, []).append((ids[0], ids[1], ids[2]))
                        if above > 0:  # solid above: outward normal -n
                            tris.setdefault(above, []).append((ids[0], ids[2], ids[1]))
    world = self.lattice.to_world(xyz)
    solids = []
    for b in sorted(tris):
        T = np.array(tris[b], dtype=np.int64)
        for comp in _components(T):
            used, inv = np.unique(comp, return_inverse=True)
            solids.append({"label": self.labels[b], "vertices": world[used].tolist(),
                           "faces": inv.reshape(-1, 3).tolist()})  # fmt: skip
    return PolyhedralModel(
        solids, name=name or f"{getattr(self.example, 'name', '') or 'model'}-synth",
        meta={"size": list(A.size), "spacing": float(self.lattice.spacing)},
        merge_coplanar=True,
    )  # fmt: skip


def _rings_to_polygons(rings: list[list[tuple[float, float]]]) -> list[Any]:
    """Shapely polygons from counter-clockwise shells and clockwise holes."""
    from shapely.geometry import Polygon as SP

    def area(r: list[tuple[float, float]]) -> float:
        pairs = zip(r, r[1:] + r[:1], strict=True)
        return 0.5 * sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in pairs)

    shells = [r for r in rings if area(r) > 0]
    holes = [r for r in rings if area(r) <= 0]
    owned: list[list[list[tuple[float, float]]]] = [[] for _ in shells]
    sp = [SP(r) for r in shells]
    for h in holes:
        hp = SP(h)
        inside = [i for i, p in enumerate(sp) if p.covers(hp)]
        if not inside:  # pragma: no cover - a hole always has a shell around it
            raise AssertionError("a hole outside every shell")
        owned[min(inside, key=lambda i: sp[i].area)].append(h)
    return [SP(s, hs) for s, hs in zip(shells, owned, strict=True)]


def _components(T: NDArray[np.int64]) -> list[NDArray[np.int64]]:
    """Triangles split into groups connected through shared edges."""
    parent = list(range(len(T)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    first: dict[tuple[int, int], int] = {}
    for i, t in enumerate(T.tolist()):
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            key = (min(a, b), max(a, b))
            if key in first:
                parent[find(i)] = find(first[key])
            else:
                first[key] = i
    groups: dict[int, list[int]] = {}
    for i in range(len(T)):
        groups.setdefault(find(i), []).append(i)
    return [T[idx] for idx in groups.values()]
