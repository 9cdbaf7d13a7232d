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

from collections.abc import Callable, Mapping, Sequence

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from csplab.continuous._geom import labels_at
from csplab.continuous.polyhedra import PolyhedralModel, Solid
from csplab.continuous.space import Arrangement3, Lattice3
from csplab.continuous.user3d import UserConstraints3
from csplab.errors import InputError
from csplab.problem import Problem

__all__ = ["FACE_ORDER", "ContinuousCSP3", "example_signatures3"]

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


def _groups(signs: NDArray[np.int8], fams: NDArray[np.int64]) -> tuple[NDArray[np.int64], int]:
    """Group id of each full cell by its signs on ``fams`` (the local cells there)."""
    if fams.size == 0:
        return np.zeros(len(signs), dtype=np.int64), 1
    _, inv = np.unique(signs[:, fams], axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    return inv.astype(np.int64), int(inv.max()) + 1


def _triangles(
    model: PolyhedralModel, lattice: Lattice3, shift: float
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


def example_signatures3(
    example: PolyhedralModel, lattice: Lattice3, index: dict[int, int]
) -> set[Labeling]:
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
    # faces beside each edge: in each plane through the edge, both half-planes; the cells
    # whose label a face takes depend only on the edge's planes and line (one index map)
    N = A.normals
    L = np.array(edge_sigs, dtype=np.int64).reshape(len(edge_sigs), len(signs))
    L, which = np.unique(L, axis=0, return_inverse=True)  # few distinct edge labelings
    which = which.reshape(-1)
    fmask = efam.astype(np.int64) @ (1 << np.arange(A.F, dtype=np.int64))
    combo = np.stack([fmask, A.edge_line], axis=1)
    uniq, inv = np.unique(combo, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    for k, (mask, line) in enumerate(uniq.tolist()):
        members = np.unique(which[inv == k])
        fams = [f for f in range(A.F) if mask >> f & 1]
        u = A.lines[line]
        for f in fams:
            others = [x for x in fams if x != f]
            for d in (np.cross(N[f], u), -np.cross(N[f], u)):
                sd = np.sign(N @ d)
                sel = np.all(signs[:, others] == sd[others], axis=1) if others else None
                rep: dict[int, int] = {}
                for c in np.flatnonzero(sel) if sel is not None else range(len(signs)):
                    rep[int(signs[c, f])] = int(c)
                idx = np.array([rep[int(signs[c, f])] for c in range(len(signs))])
                sigs |= set(map(tuple, L[members][:, idx].tolist()))
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
    constraints : UserConstraints3 or None
        User constraints (thesis Sec. 4.6, :mod:`csplab.continuous.user3d`): the
        dimensional and large-scale ones restrict the problem's domains (every solver
        enforces them); connectivity is checked on the output by
        :func:`~csplab.continuous.synthesis.synthesize3`.
    """

    def __init__(
        self,
        example: PolyhedralModel,
        size: Sequence[int],
        *,
        spacing: float | None = None,
        snap: bool = False,
        boundary: int | Mapping[str, int] = 0,
        constraints: UserConstraints3 | None = None,
    ) -> None:
        if not example.solids:
            raise InputError(f"{example.source}: an example needs at least one solid")
        self.example = example
        self.lattice = Lattice3.of_model(example, spacing, snap=snap)
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

        def states(
            fams: NDArray[np.int64], sides: int
        ) -> tuple[list[Labeling], tuple[NDArray[np.int64], int, NDArray[np.int64]]]:
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
        self.edge_outside: list[NDArray[np.int64]] = []
        for key in ekeys.tolist():
            fams = np.array([f for f in range(F) if (key >> 6) >> f & 1], dtype=np.int64)
            st, (g, _, out) = states(fams, key & 63)
            self.etypes.append((fams, st, g))
            self.edge_outside.append(out)
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
        for end, sgn, k in ((A.edge_src, 1, 0), (A.edge_dst, -1, 1)):
            nl, nt = len(A.lines), len(self.etypes)
            key = (vtype[end].astype(np.int64) * nl + A.edge_line) * nt + etype
            uniq, inv = np.unique(key, return_inverse=True)
            rid = np.array([relation(int(c // (nl * nt)), int(c // nt % nl), sgn, int(c % nt))
                            for c in uniq.tolist()], dtype=np.int64)  # fmt: skip
            arcs[k::2, 0] = var[end]
            arcs[k::2, 1] = var[nv:]
            arcs[k::2, 2] = rid[inv.reshape(-1)]
        # relations numbered by first use along the arcs (edge by edge, as always)
        _, first = np.unique(arcs[:, 2], return_index=True)
        order_used = np.unique(arcs[:, 2])[np.argsort(first)]
        renum = np.full(len(rels), -1, dtype=np.int64)
        renum[order_used] = np.arange(len(order_used))
        rels = [rels[i] for i in order_used.tolist()]
        arcs[:, 2] = renum[arcs[:, 2]]
        self.edge_type = etype
        dom = dom[order]  # (the unordered copy is freed before the problem copies it)
        self.problem = Problem(
            (nv + ne,), dom, np.stack(rels), arcs,
            name=getattr(example, "name", "") or "continuous3d",
            meta={"continuous": True, "dim": 3, "size": list(A.size),
                  "spacing": float(self.lattice.spacing), "families": N.tolist(),
                  "vertices": nv, "edges": ne, "boundary": dict(self.boundary)},
            positions=pos[order],
        )  # fmt: skip
        #: the user constraints of Sec. 4.6 (:mod:`csplab.continuous.user3d`), if any
        self.constraints = constraints
        if constraints:
            from csplab.continuous.user3d import allowed_states

            keep = allowed_states(self, constraints)
            self.problem = self.problem.restrict(keep, key="user constraints (Sec. 4.6)")
            self.problem.meta["constraints"] = constraints.source

    def model(self, grid: ArrayLike, *, name: str = "") -> PolyhedralModel:
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

    def encode(self, model: PolyhedralModel) -> NDArray[np.int32]:
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
    inside: list[bool],
    starts: list[int],
    rw: list[int],
    rev: list[int],
    gs: list[int],
    gz: list[int],
) -> list[list[int]]:
    """Rings (vertex ids, every vertex kept) around the in-plane region of the sectors
    marked ``inside``, counter-clockwise. Rays are sorted by vertex, then angle; ray ``j``
    goes to vertex ``rw[j]``, ``rev[j]`` is the same edge seen from there, ``gs[j]`` and
    ``gz[j]`` the first ray and the number of rays of its vertex; ``inside[j]`` says whether
    the sector after ray ``j`` belongs, ``starts`` are the rays after which a region begins."""
    used = [False] * len(inside)
    rings = []
    for j0 in starts:
        if used[j0]:
            continue
        ring: list[int] = []
        j = j0
        while not used[j]:
            used[j] = True
            ring.append(rw[j])
            jr = rev[j]  # the ray at the next vertex pointing back
            g, m = gs[jr], gz[jr]
            k = jr - g - 1
            while inside[g + (k - 1) % m]:
                k -= 1
            j = g + k % m
        rings.append(ring)
    return rings


def _model3(self: ContinuousCSP3, grid: ArrayLike, name: str = "") -> PolyhedralModel:
    """See :meth:`ContinuousCSP3.model`."""
    from csplab.continuous._geom import triangulate_rings

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
    # vertices whose labels all agree lie on no face (unless an object reaches the region's
    # side there, where its solid is closed): their rays are never traced
    uniform = np.zeros(A.n_vertices, dtype=bool)
    for t, (_, states, _) in enumerate(self.vtypes):
        sel = np.flatnonzero(self.vertex_type == t)
        if sel.size:
            side = bool((np.asarray(self.vertex_outside[t]) >= 0).any())
            flat = np.array([len(set(st)) == 1 and (st[0] == 0 or not side) for st in states],
                            dtype=bool)  # fmt: skip
            uniform[sel] = flat[vstate[sel]]
    # likewise edges (an edge in no face's closure can be left out of the rays: the two
    # sectors it separates are both outside every face)
    estate = g[self.var_edge]
    eflat = np.zeros(A.n_edges, dtype=bool)
    for t, (_, estates, _) in enumerate(self.etypes):
        sel = np.flatnonzero(self.edge_type == t)
        if sel.size:
            side = bool((self.edge_outside[t] >= 0).any())
            flat = np.array([len(set(st)) == 1 and (st[0] == 0 or not side) for st in estates],
                            dtype=bool)  # fmt: skip
            eflat[sel] = flat[estate[sel]]
    lookups: dict[int, dict[tuple[int, ...], int]] = {}

    def group_of(t: int, sig: tuple[int, ...]) -> int:
        if t not in lookups:
            fams, _, gid = self.vtypes[t]
            lookups[t] = {tuple(int(x) for x in signs[c, fams]): int(gid[c])
                          for c in range(len(signs))}  # fmt: skip
        return lookups[t].get(sig, -1)

    sector_cache: dict[tuple[int, ...], tuple[int, int]] = {}
    tables: dict[int, NDArray[np.int64]] = {}

    def state_table(t: int) -> NDArray[np.int64]:
        """The states of vertex type ``t`` as an array (state, group) -> label."""
        if t not in tables:
            tables[t] = np.array(self.vtypes[t][1], dtype=np.int64).reshape(
                len(self.vtypes[t][1]), -1)  # fmt: skip
        return tables[t]

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

    # the faces: rings of vertex ids with their solid's label, outward
    rings_out: list[list[int]] = []
    ring_label: list[int] = []
    ring_axis: list[int] = []  # the coordinate dropped to project the ring's plane
    ring_sign: list[int] = []  # the sign of the outward normal along that coordinate
    ring_group: list[int] = []  # the region (one trace) of each ring
    groups: list[tuple[int, list[list[int]], int, NDArray[np.float64], NDArray[np.float64]]] = []
    loose: list[tuple[int, list[list[int]], int, NDArray[np.float64], NDArray[np.float64]]] = []
    for f in range(A.F):
        sel = np.flatnonzero(efam[:, f] & ~eflat & ~uniform[A.edge_src] & ~uniform[A.edge_dst])
        if not sel.size:
            continue
        e1, e2 = _plane_basis(N[f])
        axis = int(np.argmax(np.abs(N[f])))
        kk = s[A.edge_src[sel], f] // A.D
        for k in np.unique(kk).tolist():
            es = sel[kk == k]
            src, dst = A.edge_src[es], A.edge_dst[es]
            dvec = xyz[dst] - xyz[src]
            ne = len(es)
            # every ray (an edge seen from one end), sorted by vertex, then angle
            rv = np.concatenate([src, dst])
            rw = np.concatenate([dst, src])
            ra = np.concatenate([np.arctan2(dvec @ e2, dvec @ e1),
                                 np.arctan2(-dvec @ e2, -dvec @ e1)])  # fmt: skip
            li = A.edge_line[es]
            rid = np.concatenate([2 * li, 2 * li + 1])
            o = np.lexsort((ra, rv))
            rv, rw, ra, rid = rv[o], rw[o], ra[o], rid[o]
            back = np.empty(2 * ne, dtype=np.int64)
            back[o] = np.arange(2 * ne)
            rev = back[(o + ne) % (2 * ne)]  # the same edge seen from its other end
            first = np.flatnonzero(np.r_[True, rv[1:] != rv[:-1]])
            sizes = np.diff(np.r_[first, 2 * ne])
            gs = np.repeat(first, sizes)
            gz = np.repeat(sizes, sizes)
            j = np.arange(2 * ne)
            nxt = np.where(j + 1 < gs + gz, j + 1, gs)
            prv = np.where(j > gs, j - 1, gs + gz - 1)
            tt = self.vertex_type[rv]
            # the groups above and below the plane in each sector (after each ray)
            nl2 = 2 * len(A.lines) + 1
            key = ((tt.astype(np.int64) * nl2 + rid) * nl2 + rid[nxt]) * nl2 + gz
            uk, first_k, inv_k = np.unique(key, return_index=True, return_inverse=True)
            gpm = np.empty((len(uk), 2), dtype=np.int64)
            for u, c in enumerate(uk.tolist()):
                t, r0, r1, nr = c // nl2**3, c // nl2**2 % nl2, c // nl2 % nl2, c % nl2
                ck = (t, f, r0, r1, nr)
                if ck not in sector_cache:
                    jj = int(first_k[u])
                    sector_cache[ck] = sector_groups(int(rv[jj]), t, f, e1, e2, float(ra[jj]),
                                                     float(ra[nxt[jj]]), nr)  # fmt: skip
                gpm[u] = sector_cache[ck]
            gpm = gpm[inv_k.reshape(-1)]
            lab_a = np.full(2 * ne, -1, dtype=np.int64)  # the label above the plane
            lab_b = np.full(2 * ne, -1, dtype=np.int64)  # and below it
            for t in np.unique(tt).tolist():
                m = tt == t
                S, outside = state_table(t), np.asarray(self.vertex_outside[t])
                rows = vstate[rv[m]]
                for col, out_arr in ((0, lab_a), (1, lab_b)):
                    g = gpm[m, col]
                    gc = np.maximum(g, 0)
                    ok = (g >= 0) & (outside[gc] < 0)
                    out_arr[m] = np.where(ok, S[rows, gc], -1)
            diff = lab_a != lab_b
            labels = set(np.unique(np.concatenate([lab_a[diff], lab_b[diff]])).tolist()) - {-1, 0}
            arrays = (rw.tolist(), rev.tolist(), gs.tolist(), gz.tolist())
            for b in sorted(labels):
                # the faces of solid b on this plane: b below (outward +n), b above (-n)
                for is_below in (True, False):
                    mask = ((lab_b == b) & (lab_a != b)) if is_below else (
                        (lab_a == b) & (lab_b != b))  # fmt: skip
                    if not mask.any():
                        continue
                    starts = np.flatnonzero(mask & ~mask[prv]).tolist()
                    rings = _trace(mask.tolist(), starts, *arrays)
                    if not is_below:
                        rings = [r[::-1] for r in rings]  # counter-clockwise seen from -n
                    if all(len(set(r)) == len(r) for r in rings):
                        # checked after the loop: a ring turning the wrong way is a hole
                        for r in rings:
                            rings_out.append(r)
                            ring_label.append(b)
                            ring_axis.append(axis)
                            ring_sign.append(int(np.sign(N[f, axis])) * (1 if is_below else -1))
                            ring_group.append(len(groups))
                        groups.append((b, rings, 1 if is_below else -1, e1, e2))
                    else:  # rings touching themselves: constrained Delaunay
                        loose.append((b, [r[::-1] if not is_below else r for r in rings],
                                      1 if is_below else -1, e1, e2))  # fmt: skip
    holes = _clockwise(XYZ, rings_out, ring_axis, ring_sign)
    if holes.any():  # regions with holes: constrained Delaunay
        bad = set(np.asarray(ring_group)[holes].tolist())
        for gi in sorted(bad):
            b, rings, sgn, e1, e2 = groups[gi]
            loose.append((b, [r[::-1] if sgn < 0 else r for r in rings], sgn, e1, e2))
        keep = [i for i, gi in enumerate(ring_group) if gi not in bad]
        rings_out = [rings_out[i] for i in keep]
        ring_label = [ring_label[i] for i in keep]
        ring_axis = [ring_axis[i] for i in keep]
    polys, owner, tri_list = _triangulated(XYZ, rings_out, ring_axis, triangulate_rings)
    labels_of = list(ring_label)
    for b, rings, sgn, e1, e2 in loose:
        for tri in _cdt(xyz, rings, e1, e2):
            polys.append(tri if sgn > 0 else [tri[0], tri[2], tri[1]])
            tri_list.append(polys[-1])
            owner.append(len(polys) - 1)
            labels_of.append(b)
    world = self.lattice.to_world(xyz)
    solids = _solids(polys, owner, tri_list, labels_of, world, self.labels)
    return PolyhedralModel.trusted(
        solids, name=name or f"{getattr(self.example, 'name', '') or 'model'}-synth",
        meta={"size": list(A.size), "spacing": float(self.lattice.spacing)},
    )  # fmt: skip


def _projected(
    XYZ: NDArray[np.int64], rings: list[list[int]], axes: list[int]
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """The rings' vertex ids one after another, their start offsets, their integer 2D
    coordinates (the ring's plane projected along ``axes``, the other two coordinates in
    cyclic order) and twice their signed areas there."""
    flat = np.concatenate([np.asarray(r, dtype=np.int64) for r in rings])
    lens = np.array([len(r) for r in rings], dtype=np.int64)
    start = np.concatenate([[0], np.cumsum(lens)])
    ax = np.repeat(np.asarray(axes, dtype=np.int64), lens)
    keep = np.array([[1, 2], [2, 0], [0, 1]], dtype=np.int64)[ax]
    xy = np.take_along_axis(XYZ[flat], keep, axis=1)
    nxt = np.roll(np.arange(len(flat)), -1)
    nxt[start[1:] - 1] = start[:-1]
    cr = xy[:, 0] * xy[nxt, 1] - xy[:, 1] * xy[nxt, 0]
    return flat, start, xy, np.add.reduceat(cr, start[:-1])


def _clockwise(
    XYZ: NDArray[np.int64], rings: list[list[int]], axes: list[int], signs: list[int]
) -> NDArray[np.bool_]:
    """Rings turning clockwise seen from their outward side (holes), exactly."""
    if not rings:
        return np.zeros(0, dtype=bool)
    area = _projected(XYZ, rings, axes)[3]
    out: NDArray[np.bool_] = area * np.asarray(signs, dtype=np.int64) < 0
    return out


def _triangulated(
    XYZ: NDArray[np.int64],
    rings: list[list[int]],
    axes: list[int],
    earclip: Callable[
        [NDArray[np.int64], NDArray[np.int64]], tuple[NDArray[np.int64], NDArray[np.bool_]]
    ],
) -> tuple[list[list[int]], list[int], list[list[int]]]:
    """Polygons (the rings), each triangle's polygon, and the triangles (vertex ids,
    counter-clockwise like their ring): ear clipping on the integer coordinates with the
    ring's plane projected along ``axes``."""
    if not rings:
        return [], [], []
    flat, start, xy, area = _projected(XYZ, rings, axes)
    lens = np.diff(start)
    # orient every ring counter-clockwise in its projection (reverse the triangles after)
    flip = area < 0
    order = np.arange(len(flat))
    for r in np.flatnonzero(flip).tolist():
        order[start[r] : start[r + 1]] = order[start[r] : start[r + 1]][::-1]
    tri, ok = earclip(xy[order], start)
    if not ok.all():  # pragma: no cover - simple counter-clockwise lattice rings
        bad = int(np.flatnonzero(~ok)[0])
        raise RuntimeError(f"ear clipping failed on output ring {bad}")
    ids = flat[order][tri]
    rtri = np.repeat(np.arange(len(rings)), lens - 2)
    ids[flip[rtri]] = ids[flip[rtri]][:, ::-1]
    return [list(r) for r in rings], rtri.tolist(), ids.tolist()


def _cdt(
    xyz: NDArray[np.float64], rings: list[list[int]], e1: NDArray[np.float64],
    e2: NDArray[np.float64],
) -> list[list[int]]:  # fmt: skip
    """Constrained Delaunay triangles (vertex ids, counter-clockwise in ``e1, e2``) of the
    region bounded by ``rings`` (counter-clockwise shells, clockwise holes)."""
    uv = {v: (float(xyz[v] @ e1), float(xyz[v] @ e2)) for r in rings for v in r}
    key = {(round(x, 7), round(y, 7)): v for v, (x, y) in uv.items()}
    out = []
    for poly in _rings_to_polygons([[uv[v] for v in r] for r in rings]):
        for tri in shapely.constrained_delaunay_triangles(poly).geoms:
            c = np.asarray(tri.exterior.coords)[:3]
            ids = [key[(round(x, 7), round(y, 7))] for x, y in c]
            area = (c[1, 0] - c[0, 0]) * (c[2, 1] - c[0, 1]) - (
                c[1, 1] - c[0, 1]) * (c[2, 0] - c[0, 0])  # fmt: skip
            out.append(ids if area > 0 else [ids[0], ids[2], ids[1]])
    return out


def _solids(
    polys: list[list[int]], owner: list[int], tris: list[list[int]], labels: list[int],
    world: NDArray[np.float64], names: Sequence[int],
) -> list[Solid]:  # fmt: skip
    """Polygons of one label split into closed surfaces (connected through shared edges),
    each a :class:`~csplab.continuous.polyhedra.Solid` with its own vertex numbering."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    if not polys:
        return []
    lens = np.array([len(p) for p in polys], dtype=np.int64)
    flat = np.concatenate([np.asarray(p, dtype=np.int64) for p in polys])
    start = np.concatenate([[0], np.cumsum(lens)])
    pid = np.repeat(np.arange(len(polys)), lens)
    nxt = np.roll(np.arange(len(flat)), -1)
    nxt[start[1:] - 1] = start[:-1]
    lab = np.asarray(labels, dtype=np.int64)
    a, b = flat, flat[nxt]
    key = np.stack([lab[pid], np.minimum(a, b), np.maximum(a, b)], axis=1)
    _, inv = np.unique(key, axis=0, return_inverse=True)
    inv = inv.reshape(-1)
    n = len(polys)
    graph = coo_matrix((np.ones(len(pid)), (pid, n + inv)), shape=(n + int(inv.max()) + 1,) * 2)
    _, comp = connected_components(graph, directed=False)
    comp = comp[:n]
    T = np.asarray(tris, dtype=np.int64).reshape(-1, 3)
    own = np.asarray(owner, dtype=np.int64)
    out = []
    by_comp = np.argsort(comp, kind="stable")
    bounds = np.flatnonzero(np.diff(comp[by_comp])) + 1
    tri_order = np.argsort(comp[own], kind="stable")
    tri_bounds = np.searchsorted(comp[own][tri_order], np.unique(comp))
    tri_bounds = np.append(tri_bounds, len(own))
    for ci, members in enumerate(np.split(by_comp, bounds)):
        ts = tri_order[tri_bounds[ci] : tri_bounds[ci + 1]]
        verts = np.unique(np.concatenate([flat[start[j] : start[j + 1]] for j in members]))
        local = {int(v): i for i, v in enumerate(verts.tolist())}
        pmap = np.full(n, -1, dtype=np.int64)
        pmap[members] = np.arange(len(members))
        faces = np.searchsorted(verts, T[ts])
        out.append(Solid(
            label=int(names[int(lab[members[0]])]),
            vertices=world[verts],
            faces=np.ascontiguousarray(faces, dtype=np.int64),
            polygons=tuple(tuple(local[v] for v in polys[j]) for j in members.tolist()),
            face_polygon=pmap[own[ts]],
        ))  # fmt: skip
    return out


def _rings_to_polygons(rings: list[list[tuple[float, float]]]) -> list[shapely.Polygon]:
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
