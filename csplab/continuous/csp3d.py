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

import warnings
from collections.abc import Callable, Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.constraints import Connected
from csplab.continuous._geom import labels_at
from csplab.continuous.lattice import Lattice, check_snap
from csplab.continuous.polyhedra import PolyhedralModel
from csplab.continuous.space import Arrangement3, check_budget3
from csplab.continuous.surface import surface_of
from csplab.continuous.user3d import UserConstraints3, allowed_states
from csplab.errors import InputError
from csplab.problem import Problem

__all__ = ["FACE_ORDER", "ContinuousCSP3", "example_signatures3", "snapped3"]

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
    model: PolyhedralModel, lattice: Lattice, shift: float
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


def snapped3(example: PolyhedralModel, lattice: Lattice) -> PolyhedralModel:
    """``example`` with every vertex rounded onto ``lattice`` (vertices that meet merged,
    faces flattened to a segment dropped); refused in one line
    (:class:`~csplab.errors.InputError`) when that breaks a solid (flattens it, turns it
    inside out, makes two overlap) or changes a label's volume by more than
    :data:`~csplab.continuous.lattice.MAX_SNAP_CHANGE` of itself."""
    solids = []
    for sol in example.solids:
        uv = np.rint(lattice.to_lattice(np.asarray(sol.vertices, dtype=np.float64)))
        uv, inv = np.unique(uv, axis=0, return_inverse=True)  # vertices that met: one
        inv = inv.reshape(-1)
        faces = []
        for f in sol.faces:
            ring = [int(inv[int(k)]) for k in f]
            ring = [k for i, k in enumerate(ring) if k != ring[i - 1]] if len(ring) > 1 else ring
            if len(set(ring)) >= 3:  # a face that snapping flattened to a segment is dropped
                faces.append(ring)
        solids.append({"label": int(sol.label), "vertices": lattice.to_world(uv).tolist(),
                       "faces": faces})  # fmt: skip
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            out = PolyhedralModel(solids, name=example.name, meta=example.meta,
                                  source=example.source)  # fmt: skip
    except (InputError, UserWarning) as e:
        raise InputError(
            f"{example.source}: snapping onto spacing {float(lattice.spacing):g} breaks it "
            f"({str(e).splitlines()[0].removeprefix(f'{example.source}: ')}); pass a smaller "
            "--spacing"
        ) from None
    for b in example.labels:  # each label's volume, as snapping left it
        check_snap(f"{example.source}: label {b}", float(lattice.spacing), "volume",
                   example.volume(b), out.volume(b))  # fmt: skip
    return out


def example_signatures3(
    example: PolyhedralModel,
    lattice: Lattice,
    index: dict[int, int],
    max_memory: int | None = None,
) -> set[Labeling]:
    """Every neighbourhood of ``example`` (labels compacted by ``index``) as a full labeling
    of the central cells: vertices and edges of its own arrangement (its bounding box plus
    one spacing), the faces next to those edges, and the solid interiors (``max_memory``
    as for :class:`~csplab.continuous.space.Arrangement3`)."""
    pts = np.concatenate([np.asarray(s.vertices, dtype=np.float64) for s in example.solids])
    lo = np.floor(lattice.to_lattice(pts).min(axis=0) + 1e-9)
    hi = np.ceil(lattice.to_lattice(pts).max(axis=0) - 1e-9)
    shift = 1.0 - lo
    A = Arrangement3(lattice, tuple(int(h - l) + 2 for l, h in zip(lo, hi, strict=True)),
                     max_memory=max_memory, where=example.source, hint="")  # fmt: skip
    tris = [(b, t + shift) for b, t in _triangles(example, lattice, 0.0)]
    signs, _ = A.cells
    sigs: set[Labeling] = {(b,) * len(signs) for b in (0, *index.values())}
    sigs |= set(_local_labels(A, A.vertex_positions(), A.on, tris, index))
    efam = A.edge_families()
    edge_sigs = _local_labels(A, A.edge_positions(), efam, tris, index)
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
        enforces them); connectivity is a :class:`~csplab.constraints.Connected` on the
        problem (:meth:`connected`).
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
        max_memory: int | None = None,
    ) -> None:
        if not example.solids:
            raise InputError(f"{example.source}: an example needs at least one solid")
        self.lattice = Lattice.of_model(example, spacing, snap=snap)
        if self.lattice.snapped:
            example = snapped3(example, self.lattice)
        #: the example as synthesized (its vertices snapped onto the lattice when they were not
        #: on it; the checker compares the output with this)
        self.example = example
        self.labels: tuple[int, ...] = (0, *example.labels)
        index = {b: i for i, b in enumerate(self.labels)}
        faces = _boundary_faces(boundary)
        for face, lab in faces.items():
            if lab not in index:
                raise InputError(
                    f"boundary {face}={lab}: label {lab} does not occur in the example"
                )
        self.boundary = faces
        # the region's estimate first: refused before the example's arrangement is built
        check_budget3(self.lattice, size, max_memory, example.source)
        self.signatures = example_signatures3(example, self.lattice, index, max_memory)
        self.arrangement = Arrangement3(self.lattice, size, max_memory=max_memory,
                                        where=example.source)  # fmt: skip
        self._types(index)
        self.problem = self._problem()
        #: the user constraints of Sec. 4.6 (:mod:`csplab.continuous.user3d`), if any
        self.constraints = constraints
        if constraints:
            keep = allowed_states(self, constraints)
            self.problem = self.problem.restrict(keep, key="user constraints (Sec. 4.6)")
            self.problem.meta["constraints"] = constraints.source
            if constraints.connected:  # one global constraint, for every solver
                self.problem = self.problem.with_constraints(self.connected(constraints.connected))

    def _types(self, index: dict[int, int]) -> None:
        """The vertex and edge types (planes through them, region sides they lie on) with
        their states, cell groups and outside labels (Sec. 4.5.4)."""
        sig = np.array(sorted(self.signatures), dtype=np.int64)
        A = self.arrangement
        signs, _ = A.cells
        F, N = A.F, A.normals
        faces = self.boundary
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
                raise InputError(f"{self.example.source}: no neighbourhood of the example fits "
                                 f"a vertex on planes {N[fams].tolist()} with boundary "
                                 f"{self.boundary}")  # fmt: skip
            self.vtypes.append((fams, st, g))
            self.vertex_outside.append(out)
        # edge types
        efam = A.edge_families()
        eside = vside[A.edge_src] & vside[A.edge_dst]
        emask = efam.astype(np.int64) @ (1 << np.arange(F, dtype=np.int64))
        ekeys, etype = np.unique((emask << 6) | eside, return_inverse=True)
        self.edge_type = etype.reshape(-1)
        self.etypes: list[tuple[NDArray[np.int64], list[Labeling], NDArray[np.int64]]] = []
        self.edge_outside: list[NDArray[np.int64]] = []
        for key in ekeys.tolist():
            fams = np.array([f for f in range(F) if (key >> 6) >> f & 1], dtype=np.int64)
            st, (g, _, out) = states(fams, key & 63)
            self.etypes.append((fams, st, g))
            self.edge_outside.append(out)

    def _relation_maker(
        self, K: int
    ) -> tuple[Callable[[int, int, int, int], int], list[NDArray[np.bool_]]]:
        """A function giving the relation id of (vertex type, line, direction, edge type),
        and the list it fills with the distinct relations (Sec. 4.5.5: a vertex state and an
        edge state agree when the vertex's labels, evaluated in the edge's direction, are
        the edge's labels)."""
        A = self.arrangement
        signs, _ = A.cells
        N = A.normals
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

        return relation, rels

    def _problem(self) -> Problem:
        """The binary CSP: domains by type, variables in scan order of their positions,
        one arc per (edge, end) with the relation of its types and direction."""
        A = self.arrangement
        vtype, etype = self.vertex_type, self.edge_type
        nst = max(len(t[1]) for t in (*self.vtypes, *self.etypes))
        K = self.K = nst
        nv, ne = A.n_vertices, A.n_edges
        dom = np.zeros((nv + ne, K), dtype=bool)
        vn = np.array([len(t[1]) for t in self.vtypes])
        en = np.array([len(t[1]) for t in self.etypes])
        dom[:nv] = np.arange(K)[None, :] < vn[vtype][:, None]
        dom[nv:] = np.arange(K)[None, :] < en[etype][:, None]
        # relations per (vertex type, ray, edge type)
        relation, rels = self._relation_maker(K)
        pos = np.concatenate([A.vertex_positions(), A.edge_positions()])
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
        used = [rels[i] for i in order_used.tolist()]
        arcs[:, 2] = renum[arcs[:, 2]]
        dom = dom[order]  # (the unordered copy is freed before the problem copies it)
        return Problem(
            (nv + ne,), dom, np.stack(used), arcs,
            name=getattr(self.example, "name", "") or "continuous3d",
            meta={"continuous": True, "dim": 3, "size": list(A.size),
                  "spacing": float(self.lattice.spacing), "families": A.normals.tolist(),
                  "vertices": nv, "edges": ne, "boundary": dict(self.boundary)},
            positions=pos[order],
        )  # fmt: skip

    def model(self, grid: ArrayLike, *, name: str = "") -> PolyhedralModel:
        """The output solids of a solution: on every plane the regions between two
        different labels are traced from the vertex states (every vertex kept, so that the
        surface is watertight), triangulated (constrained Delaunay) and given to the label
        below (outward normal up) and the label above (down); each label's triangles
        split into closed surfaces, validated as a
        :class:`~csplab.continuous.polyhedra.PolyhedralModel`."""
        return surface_of(self, grid, name)

    def region(self) -> tuple[float, float, float, float, float, float]:
        """The output region ``(x0, y0, z0, x1, y1, z1)`` in the example's coordinates."""
        lo = self.lattice.to_world(np.zeros(3)).tolist()
        hi = self.lattice.to_world(np.array(self.arrangement.size, dtype=np.float64)).tolist()
        return (lo[0], lo[1], lo[2], hi[0], hi[1], hi[2])

    def touching(self, label: int) -> NDArray[np.bool_]:
        """``(n, K)``: the values of each variable whose state has the model ``label`` in
        a group of cells inside the region (the vertex or edge touches an object of
        ``label`` there).

        Thesis Sec. 4.6.2 as one global constraint: the objects of ``label`` form one
        connected group exactly when the variables touching it, joined by the arcs (a
        vertex and an edge at it), form one component, and some variable touches it (see
        :meth:`connected`)."""
        index = {b: i for i, b in enumerate(self.labels)}
        if label not in index or label == 0:
            raise InputError(f"label {label} does not occur in the example")
        b = index[label]
        out = np.zeros(self.problem.domains.shape, dtype=bool)
        for types, tlist, outside, var in (
            (self.vertex_type, self.vtypes, self.vertex_outside, self.var_vertex),
            (self.edge_type, self.etypes, self.edge_outside, self.var_edge),
        ):
            for t, (_, states, _) in enumerate(tlist):
                sel = np.flatnonzero(types == t)
                if not sel.size or not states:
                    continue
                S = np.array(states, dtype=np.int64).reshape(len(states), -1)
                inside = np.asarray(outside[t]) < 0
                touch = ((S == b) & inside[None, :]).any(axis=1)
                out[np.ix_(var[sel], np.arange(len(states)))] = touch[None, :]
        out &= self.problem.domains
        return out

    def connected(self, labels: Sequence[int]) -> list[Connected]:
        """One :class:`~csplab.constraints.Connected` per model label: its objects form
        exactly one connected group (thesis Sec. 4.6.2; closures meeting at a point join)."""
        out = []
        for b in labels:
            members = self.touching(b)
            what = f"objects of label {b}"
            out.append(Connected((self.labels.index(b),), members=members, nonempty=True,
                                 what=what))  # fmt: skip
        return out

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
        for pts, fams_on, types, tlist, var in (
            (A.vertex_positions(), A.on, self.vertex_type, self.vtypes, self.var_vertex),
            (A.edge_positions(), A.edge_families(), self.edge_type, self.etypes, self.var_edge),
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
        return grid
