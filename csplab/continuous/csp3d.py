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
from csplab.continuous.lattice import Lattice, check_snap, face_planes, open_sides
from csplab.continuous.polyhedra import PolyhedralModel
from csplab.continuous.space import Arrangement3, check_budget3
from csplab.continuous.surface import surface_of
from csplab.continuous.user3d import UserConstraints3, allowed_states
from csplab.errors import InputError
from csplab.problem import Problem

__all__ = [
    "FACE_ORDER",
    "OPEN",
    "WINDOW",
    "ContinuousCSP3",
    "as_synthesized",
    "example_signatures3",
    "ground_faces",
    "snapped3",
]

#: the region's faces; a point outside several takes the label of the first (the ground
#: ``z-`` wins at the bottom edges)
FACE_ORDER = ("z-", "z+", "x-", "x+", "y-", "y+")
#: ``ground="window"``: every face but the sky, the example seen through a window onto an
#: infinite ground
WINDOW = ("z-", "x-", "x+", "y-", "y+")
#: ``vertex_outside``/``edge_outside`` of a group past an open (ground) face: outside the
#: region, its label the continuation of the one inside (not a fixed label)
OPEN = -2
#: how far inside an open face a point past it is located, in spacings per axis (distinct
#: per axis, so that no plane whose normal mixes two axes passes through it)
_INWARD = np.array([1.0, 1.37, 1.71]) * 1e-6


def ground_faces(ground: str | Sequence[str] | None) -> tuple[str, ...]:
    """The open faces of a ``ground`` declaration (see :class:`ContinuousCSP3`):
    ``None``, ``""`` or ``"none"``: none; ``"window"``: :data:`WINDOW`; otherwise faces of
    :data:`FACE_ORDER`, as a comma-separated string or a sequence; in that order.

    Examples
    --------
    >>> ground_faces("z-"), ground_faces("x+,z-"), ground_faces(None)
    (('z-',), ('z-', 'x+'), ())
    >>> ground_faces("floor")
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: ground: faces are z-, z+, x-, x+, y-, y+ (or window, none), not floor
    """
    return open_sides(ground, FACE_ORDER, WINDOW, "faces")


def _clamped(
    points: NDArray[np.float64], lo: NDArray[np.float64], hi: NDArray[np.float64],
    faces: Sequence[str],
) -> NDArray[np.float64]:  # fmt: skip
    """``points`` past an open face of the box ``lo..hi`` moved just inside it: the label
    there is the continuation of the one at the face (the example as a window)."""
    q = np.array(points, dtype=np.float64, copy=True)
    for face in faces:
        a = "xyz".index(face[0])
        if face[1] == "-":
            q[:, a] = np.maximum(q[:, a], lo[a] + _INWARD[a])
        else:
            q[:, a] = np.minimum(q[:, a], hi[a] - _INWARD[a])
    return q


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


def _dense_unique(key: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """``np.unique(key, return_inverse=True)`` of non-negative integers of a small range,
    without sorting (a table over the range)."""
    if not key.size:
        return key.astype(np.int64), np.zeros(0, dtype=np.int64)
    top = int(key.max()) + 1
    if key.min() < 0 or top > 4 * key.size + 1024:
        u, inv = np.unique(key, return_inverse=True)
        return u.astype(np.int64), inv.reshape(-1).astype(np.int64)
    present = np.zeros(top, dtype=bool)
    present[key] = True
    rank = np.cumsum(present) - 1
    return np.flatnonzero(present).astype(np.int64), rank[key].astype(np.int64)


def _unique_rows(a: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """``np.unique(a, axis=0, return_inverse=True)`` of small non-negative integer rows
    (compact labels), faster: rows as bytes."""
    if not len(a) or a.shape[1] == 0 or a.min() < 0 or a.max() > 255:
        u, inv = np.unique(a, axis=0, return_inverse=True)
        return u, inv.reshape(-1)
    b = np.ascontiguousarray(a.astype(np.uint8))
    v = b.view(np.dtype((np.void, b.shape[1]))).reshape(-1)
    _, first, inv = np.unique(v, return_index=True, return_inverse=True)
    return a[first], inv.reshape(-1)


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
    clamp: tuple[NDArray[np.float64], NDArray[np.float64], Sequence[str]] | None = None,
) -> NDArray[np.int64]:
    """Full labelings ``(len(points), cells)`` over the central cells of the neighbourhoods
    at ``points`` whose planes are ``fams_on`` (per point), by point location just off each
    point (one query per group of cells; points with the same planes in one batch;
    ``clamp``: ``(lo, hi, faces)``, points past those faces of the box located just inside
    it)."""
    signs, dirs = A.cells
    out = np.zeros((len(points), len(signs)), dtype=np.int64)
    if not len(points):
        return out
    eps = 1e-3 / (A.D * float(np.abs(A.normals).sum(axis=1).max()))
    F = fams_on.shape[1]
    code, inv = _dense_unique(fams_on.astype(np.int64) @ (np.int64(1) << np.arange(F)))
    keys = (code[:, None] >> np.arange(F)) & 1 > 0
    batches, queries = [], []
    for u in range(len(keys)):
        members = np.flatnonzero(inv == u)
        g, ng = _groups(signs, np.flatnonzero(keys[u]))
        rep = np.unique(g, return_index=True)[1]
        queries.append((points[members][:, None, :] + eps * dirs[rep][None, :, :]).reshape(-1, 3))
        batches.append((members, g, ng))
    q = np.concatenate(queries)
    if clamp is not None and clamp[2]:
        q = _clamped(q, *clamp)
    lab = labels_at(q, tris)
    compact = np.zeros(max(index) + 1, dtype=np.int64)
    for b, i in index.items():
        compact[b] = i
    lab = compact[lab]
    pos = 0
    for members, g, ng in batches:
        local = lab[pos : pos + len(members) * ng].reshape(len(members), ng)
        pos += len(members) * ng
        out[members] = local[:, g]
    return out


def _on_faces(
    A: Arrangement3, vertex: NDArray[np.int64], fams: NDArray[np.bool_],
    planes: dict[tuple[int, ...], list[int]],
) -> NDArray[np.bool_]:  # fmt: skip
    """Which points (on the planes ``fams`` through the arrangement vertex ``vertex``) lie
    on a plane of an example face (``planes``, :func:`~csplab.continuous.lattice.face_planes`
    in the arrangement's frame): the only points whose neighbourhood is not one label."""
    out = np.zeros(len(vertex), dtype=bool)
    XYZ = np.stack([A.X[vertex], A.Y[vertex], A.Z[vertex]], axis=1)
    for f, n in enumerate(A.normals.tolist()):
        ks = planes.get(tuple(n))
        if ks:
            sel = fams[:, f] & ~out
            kk = XYZ[sel] @ A.normals[f] // A.D
            out[np.flatnonzero(sel)[np.isin(kk, ks)]] = True
    return out


def snapped3(example: PolyhedralModel, lattice: Lattice) -> PolyhedralModel:
    """``example`` with every vertex rounded onto ``lattice`` (vertices that meet merged,
    faces flattened to a segment dropped); refused in one line
    (:class:`~csplab.errors.InputError`) when that breaks a solid (flattens it, turns it
    inside out, makes two overlap) or changes a label's volume by more than
    :data:`~csplab.continuous.lattice.MAX_SNAP_CHANGE` of itself."""
    solids = []
    base = 0
    for sol in example.solids:
        if lattice.moved is not None:  # snapped by planes (the lattice's moved vertices)
            uv = lattice.moved[base : base + len(sol.vertices)]
        else:
            uv = np.rint(lattice.to_lattice(np.asarray(sol.vertices, dtype=np.float64)))
        base += len(sol.vertices)
        # vertices that met: one
        _, first, inv = np.unique(np.round(uv, 9), axis=0, return_index=True,
                                  return_inverse=True)  # fmt: skip
        uv = uv[first]
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


def as_synthesized(
    example: PolyhedralModel,
    spacing: float | None = None,
    *,
    snap: bool = False,
    planes: str = "auto",
) -> tuple[Lattice, PolyhedralModel]:
    """The lattice of ``example`` and the example as synthesis uses it: snapped onto the
    lattice when its vertices are off it (by its planes, :func:`~csplab.continuous.lattice.
    plane_snap`, or, when moving the planes breaks a solid, by rounding its vertices),
    else unchanged. What :class:`ContinuousCSP3` synthesizes from and ``csplab check``
    compares an output with.

    Parameters
    ----------
    example : PolyhedralModel
        The example.
    spacing : float, optional
        The plane spacing (default: derived, :meth:`Lattice.of_points`).
    snap : bool, default False
        Snap vertices that are off the lattice of ``spacing``.
    planes : {"auto", "lattice", "equal"}, default "auto"
        Plane spacing per family (:data:`~csplab.continuous.lattice.PLANES`).

    Returns
    -------
    lattice : Lattice
    example : PolyhedralModel
        The example on the lattice's planes.

    Raises
    ------
    InputError
        As :meth:`Lattice.of_model`, or when snapping breaks a solid either way.
    """
    lat = Lattice.of_model(example, spacing, snap=snap, planes=planes)
    if lat.snapped and lat.moved is not None:
        try:
            return lat, snapped3(example, lat)
        except InputError:  # moving the planes broke it: round the vertices instead
            lat = Lattice.of_model(example, spacing, snap=snap, planes=planes, by_planes=False)
    if lat.snapped:
        return lat, snapped3(example, lat)
    return lat, example


def example_signatures3(
    example: PolyhedralModel,
    lattice: Lattice,
    index: dict[int, int],
    max_memory: int | None = None,
    ground: Sequence[str] = (),
    coverage: dict[Labeling, int] | None = None,
    on_ground: dict[str, set[Labeling]] | None = None,
    type_coverage: dict[tuple[int, Labeling], int] | None = None,
) -> set[Labeling]:
    """Every neighbourhood of ``example`` (labels compacted by ``index``) as a full labeling
    of the central cells: vertices and edges of its own arrangement (its bounding box plus
    one spacing), the faces next to those edges, and the solid interiors (``max_memory``
    as for :class:`~csplab.continuous.space.Arrangement3`). Past the faces of its bounding
    box named in ``ground`` the example continues: the label there is the one just inside
    (a solid standing on the box's bottom face goes on below it, so that face is no
    surface). ``coverage``, if given, receives how much of the example each neighbourhood
    covers: the number of vertices and edges of the arrangement inside the example's
    bounding box where it occurs (volume, area, length or a count of corners, in plane
    spacings). ``type_coverage``, if given, receives the same counts per kind of point:
    ``(planes, labeling)`` with ``planes`` the bit mask of the plane families through the
    vertex or containing the edge. ``on_ground``, if given, receives per ``ground`` face
    the neighbourhoods at the example's vertices and edges on that face of its box, and
    empty space (what the output may have on the region's face: its bottom layer is like
    the example's, or bare ground, unless a face perpendicular to it is open too: then
    the example is a window onto an endless ground and the face shows only its own
    neighbourhoods)."""
    pts = np.concatenate([np.asarray(s.vertices, dtype=np.float64) for s in example.solids])
    lo = np.floor(lattice.to_lattice(pts).min(axis=0) + 1e-9)
    hi = np.ceil(lattice.to_lattice(pts).max(axis=0) - 1e-9)
    shift = 1.0 - lo
    A = Arrangement3(lattice, tuple(int(h - l) + 2 for l, h in zip(lo, hi, strict=True)),
                     max_memory=max_memory, where=example.source, hint="",
                     shift=tuple(int(x) for x in shift))  # fmt: skip
    tris = [(b, t + shift) for b, t in _triangles(example, lattice, 0.0)]
    box = lattice.to_lattice(pts) + shift
    clamp = (box.min(axis=0), box.max(axis=0), tuple(ground))
    signs, _ = A.cells
    sigs: set[Labeling] = {(b,) * len(signs) for b in (0, *index.values())}
    # only points on a plane of an example face can see more than one label (the others'
    # uniform neighbourhoods are the labelings above)
    pts_, faces_ = example.indexed_faces()
    planes = face_planes(lattice.to_lattice(pts_) + shift, faces_, lattice.vectors)
    vpos = A.vertex_positions()
    von = _on_faces(A, np.arange(A.n_vertices), A.on, planes)
    vsel = np.flatnonzero(von)
    vsigs = _local_labels(A, vpos[vsel], A.on[vsel], tris, index, clamp)
    sigs |= set(map(tuple, _unique_rows(vsigs)[0].tolist()))
    efam_all = A.edge_families()
    epos = A.edge_positions()
    eon = _on_faces(A, A.edge_src, efam_all, planes)
    esel = np.flatnonzero(eon)
    efam = efam_all[esel]
    Lall = _local_labels(A, epos[esel], efam, tris, index, clamp)
    L, which = _unique_rows(Lall)  # few distinct edge labelings
    sigs |= set(map(tuple, L.tolist()))
    if coverage is not None or type_coverage is not None or (ground and on_ground is not None):
        compact = np.zeros(max(index) + 1, dtype=np.int64)
        for b, i in index.items():
            compact[b] = i
        tol = 1e-9
        bits = 1 << np.arange(A.F, dtype=np.int64)
        for pos, on, found, kind in ((vpos, von, vsigs, A.on.astype(np.int64) @ bits),
                                     (epos, eon, Lall, efam_all.astype(np.int64) @ bits)):
            inside = ((pos >= clamp[0] - tol) & (pos <= clamp[1] + tol)).all(axis=1)
            # every point inside the box: its labeling (uniform off the face planes)
            rows = np.empty((len(pos), len(signs)), dtype=np.int64)
            rows[on] = found
            off = np.flatnonzero(inside & ~on)
            rows[off] = compact[labels_at(pos[off], tris)][:, None]
            if coverage is not None:  # occurrences inside the example's box
                u, inv = _unique_rows(rows[inside])
                counts = np.bincount(inv, minlength=len(u))
                for r, c in zip(map(tuple, u.tolist()), counts.tolist(), strict=True):
                    coverage[r] = coverage.get(r, 0) + int(c)
            if type_coverage is not None:  # the same, per kind of point (planes through it)
                keyed = np.column_stack([kind[inside], rows[inside]])
                u, inv = _unique_rows(keyed)
                counts = np.bincount(inv, minlength=len(u))
                for r, c in zip(u.tolist(), counts.tolist(), strict=True):
                    key = (int(r[0]), tuple(int(x) for x in r[1:]))
                    type_coverage[key] = type_coverage.get(key, 0) + int(c)
            for face in ground:
                if on_ground is None:
                    break
                a = "xyz".index(face[0])
                at = clamp[1][a] if face[1] == "+" else clamp[0][a]
                at_face = inside & (np.abs(pos[:, a] - at) <= tol)
                # bare ground (empty space on the face) is added, so that objects standing
                # on it may stand apart, unless the example is also open across the face
                # (a window: a face perpendicular to it is open too, so the face cuts
                # through an endless ground and shows only what it has)
                window = any(f[0] != face[0] for f in ground)
                seen = on_ground.setdefault(face, set() if window else {(0,) * len(signs)})
                seen.update(map(tuple, _unique_rows(rows[at_face])[0].tolist()))
    # faces beside each edge: in each plane through the edge, both half-planes; the cells
    # whose label a face takes depend only on the edge's planes and line (one index map)
    N = A.normals
    fmask = efam.astype(np.int64) @ (1 << np.arange(A.F, dtype=np.int64))
    combo = np.stack([fmask, A.edge_line[esel]], axis=1)
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
    ground : tuple of str
        The open faces (:func:`ground_faces`): the example is a window onto a world that
        continues past these faces of its bounding box, and so does the output past these
        faces of the region (a state there has outside the region what it has just
        inside: a solid reaching the bottom stands on the ground). With ``("z-",)`` no
        output solid floats where the example's solids stand on the bottom of its box.
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
        ground: str | Sequence[str] | None = None,
        planes: str = "auto",
    ) -> None:
        if not example.solids:
            raise InputError(f"{example.source}: an example needs at least one solid")
        self.lattice, example = as_synthesized(example, spacing, snap=snap, planes=planes)
        #: the example as synthesized (its vertices snapped onto the lattice when they were not
        #: on it; the checker compares the output with this)
        self.example = example
        self.labels: tuple[int, ...] = (0, *example.labels)
        index = {b: i for i, b in enumerate(self.labels)}
        faces = _boundary_faces(boundary)
        self.ground = ground_faces(ground)
        named = set(boundary) if isinstance(boundary, Mapping) else set()
        both = [f for f in self.ground if f in named and faces[f]]
        if both:
            raise InputError(f"face {both[0]} is open (ground) and has boundary label "
                             f"{faces[both[0]]}: give it one or the other")  # fmt: skip
        for face, lab in faces.items():
            if lab not in index:
                raise InputError(
                    f"boundary {face}={lab}: label {lab} does not occur in the example"
                )
        self.boundary = faces
        # the region's estimate first: refused before the example's arrangement is built
        check_budget3(self.lattice, size, max_memory, example.source)
        #: how much of the example each neighbourhood covers (vertices and edges of its
        #: arrangement inside its box where it occurs): with ``type_coverage``, the weights
        #: of ``choice="weighted"``
        self.coverage: dict[Labeling, int] = {}
        #: per ground face, the example's neighbourhoods on that face of its box: the only
        #: ones a vertex or edge on that face of the region may take
        self.on_ground: dict[str, set[Labeling]] = {}
        #: the same per kind of point, ``(planes, labeling)``: a vertex or edge type's
        #: weights are the geometric mean of its states' shares among the example's points
        #: on the same planes and among all its points (``coverage``)
        self.type_coverage: dict[tuple[int, Labeling], int] = {}
        self.signatures = example_signatures3(example, self.lattice, index, max_memory,
                                              self.ground, self.coverage,
                                              self.on_ground, self.type_coverage)  # fmt: skip
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
        sig_keys = [tuple(int(x) for x in r) for r in sig.tolist()]
        cover = np.array([self.coverage.get(r, 0) for r in sig_keys], dtype=np.float64)
        by_kind: dict[int, NDArray[np.float64]] = {}  # planes -> counts per row of sig
        row_of = {r: k for k, r in enumerate(sig_keys)}
        for (mask, lab), c in self.type_coverage.items():
            if lab in row_of:
                by_kind.setdefault(mask, np.zeros(len(sig_keys)))[row_of[lab]] += c
        A = self.arrangement
        signs, _ = A.cells
        F, N = A.F, A.normals
        faces = self.boundary
        sig_rows = [tuple(int(x) for x in r) for r in sig.tolist()]
        on_face = {f: np.array([r in self.on_ground.get(f, ()) for r in sig_rows], dtype=bool)
                   for f in self.ground}  # fmt: skip
        side_fam = [A.axis_family(a) for a in range(3)]
        _, dirs = A.cells

        def outside_groups(fams: NDArray[np.int64], sides: int, g: NDArray[np.int64],
                           ng: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:  # fmt: skip
            """Per group: the compact label it must have outside the region, -1 (inside) or
            :data:`OPEN` (past open faces only); a group outside several fixed faces takes
            the first of ``FACE_ORDER``. And per group the group it continues (itself
            unless :data:`OPEN`): the one just inside the open faces it is past."""
            out = np.full(ng, -1, dtype=np.int64)
            mirror = np.arange(ng, dtype=np.int64)
            for face in reversed(FACE_ORDER):
                if face in self.ground:
                    continue
                a, hi = "xyz".index(face[0]), face[1] == "+"
                bit = (2 if hi else 1) << (2 * a)
                if sides & bit:
                    out[np.unique(g[signs[:, side_fam[a]] == (1 if hi else -1)])] = index[
                        faces[face]
                    ]
            for k in range(ng):
                if out[k] >= 0:
                    continue
                c = int(np.flatnonzero(g == k)[0])
                d = dirs[c].astype(np.float64).copy()
                moved = False
                for face in self.ground:
                    a, hi = "xyz".index(face[0]), face[1] == "+"
                    bit = (2 if hi else 1) << (2 * a)
                    if sides & bit and signs[c, side_fam[a]] == (1 if hi else -1):
                        d[a] = (-1.0 if hi else 1.0) * _INWARD[a] * float(np.abs(d).sum())
                        moved = True
                if not moved:
                    continue
                want = np.sign(N[fams] @ d)
                match = np.flatnonzero((signs[:, fams] == want).all(axis=1))
                if not match.size:  # a plane through the point and the inward direction
                    raise InputError(f"{self.example.source}: no cell continues a ground "
                                     f"face at planes {N[fams].tolist()}")  # fmt: skip
                out[k] = OPEN
                mirror[k] = int(g[match[0]])
            return out, mirror

        def states(
            fams: NDArray[np.int64], sides: int
        ) -> tuple[list[Labeling], tuple[NDArray[np.int64], int, NDArray[np.int64]]]:
            g, ng = _groups(signs, fams)
            rep = np.array([int(np.flatnonzero(g == k)[0]) for k in range(ng)])
            local = sig[:, rep]  # (nsig, ng)
            ok = (sig == local[:, g]).all(axis=1)  # factors through these planes
            out, mirror = outside_groups(fams, sides, g, ng)
            req = out >= 0
            ok &= (local[:, req] == out[req]).all(axis=1)
            ok &= (local == local[:, mirror]).all(axis=1)  # past a ground face: continued
            for face in self.ground:  # on a ground face: as the example on its box's face
                a, hi = "xyz".index(face[0]), face[1] == "+"
                if sides & ((2 if hi else 1) << (2 * a)):
                    ok &= on_face[face]
            found = sorted({tuple(int(x) for x in row) for row in local[ok]},
                           key=lambda st: (any(st), st))  # fmt: skip
            # Sec. 4.5.4's states, each weighted by the example it covers (+1: every state
            # stays possible), from two estimates of its share: among the example's points
            # on the same planes (a rock's corner among the vertices where its planes meet,
            # not among every flat point; all its points where it has none on these
            # planes), and among all its points (an object's face or inside, which goes on
            # through points of every kind, weighs more there than a corner ending it).
            # The first alone draws each state at the example's rate, so extents are
            # geometric and half the objects short; the second alone lets the inside of a
            # ground grow over the rocks on it. Their normalized geometric mean: the q
            # that minimizes KL(q || first) + KL(q || second)
            mask = int((1 << fams).sum()) if len(fams) else 0
            share = []
            for counts in (by_kind.get(mask, cover), cover):
                w = dict.fromkeys(found, 1.0)
                for row, c in zip(local[ok].tolist(), counts[ok].tolist(), strict=True):
                    w[tuple(row)] += c
                v = np.array([w[st] for st in found], dtype=np.float64)
                share.append(v / v.sum())
            weights.append(np.sqrt(share[0] * share[1]))
            return found, (g, ng, out)

        weights: list[NDArray[np.float64]] = []  # per vertex type, then per edge type
        # vertex types
        vside = A.on_side()
        vmask = A.on.astype(np.int64) @ (1 << np.arange(F, dtype=np.int64))
        vkeys, vtype = np.unique((vmask << 6) | vside, return_inverse=True)
        vtype = vtype.reshape(-1).astype(np.int64)
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
        #: per vertex type then edge type, the weight of each state (``choice="weighted"``)
        self.state_weights = weights

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

        bits: dict[int, tuple[NDArray[np.int64], NDArray[np.int64]]] = {}
        states: dict[tuple[str, int], NDArray[np.int64]] = {}

        def packed(t: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
            """The signs of vertex type ``t``'s planes packed in an integer per cell, and
            the first cell of each packed value (a lookup table)."""
            if t not in bits:
                vf = self.vtypes[t][0]
                w = np.int64(1) << np.arange(len(vf), dtype=np.int64)
                key = (signs[:, vf] > 0).astype(np.int64) @ w
                first = np.full(1 << len(vf), -1, dtype=np.int64)
                first[key[::-1]] = np.arange(len(signs))[::-1]
                bits[t] = (w, first)
            return bits[t]

        def table(kind: str, t: int) -> NDArray[np.int64]:
            if (kind, t) not in states:
                st = (self.vtypes if kind == "v" else self.etypes)[t][1]
                states[kind, t] = np.array(st, dtype=np.int64).reshape(len(st), -1)
            return states[kind, t]

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
            want = signs[:, vf].copy()
            away = sr[vf] != 0
            want[:, away] = sr[vf][away]
            w, first = packed(t)
            match = first[(want > 0).astype(np.int64) @ w]
            ne_groups = len(est[0]) if est else 0
            target = np.zeros(ne_groups, dtype=np.int64)
            target[eg] = vg[match]
            M = np.zeros((K, K), dtype=bool)
            if ne_groups and len(vst):
                induced = table("v", t)[:, target]
                E = table("e", et)
                eidx = {row.tobytes(): i for i, row in enumerate(E)}
                for i, row in enumerate(induced):
                    jj = eidx.get(row.tobytes())
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
        vn = np.array([len(t[1]) for t in self.vtypes], dtype=np.int64)
        en = np.array([len(t[1]) for t in self.etypes], dtype=np.int64)
        nvals = np.concatenate([vn[vtype], en[etype]])  # values of each variable
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
            uniq, inv = _dense_unique(key)
            rid = np.array([relation(int(c // (nl * nt)), int(c // nt % nl), sgn, int(c % nt))
                            for c in uniq.tolist()], dtype=np.int64)  # fmt: skip
            arcs[k::2, 0] = var[end]
            arcs[k::2, 1] = var[nv:]
            arcs[k::2, 2] = rid[inv.reshape(-1)]
        # relations numbered by first use along the arcs (edge by edge, as always)
        first = np.full(len(rels), len(arcs), dtype=np.int64)
        first[arcs[::-1, 2]] = np.arange(len(arcs) - 1, -1, -1)  # the first use wins
        used_ids = np.flatnonzero(first < len(arcs))
        order_used = used_ids[np.argsort(first[used_ids], kind="stable")]
        renum = np.full(len(rels), -1, dtype=np.int64)
        renum[order_used] = np.arange(len(order_used))
        used = [rels[i] for i in order_used.tolist()]
        arcs[:, 2] = renum[arcs[:, 2]]
        dom = np.arange(K)[None, :] < nvals[order][:, None]
        # the weighted choice: one weight class per vertex and edge type
        table = np.zeros((len(self.state_weights), K), dtype=np.float64)
        for t, w in enumerate(self.state_weights):
            table[t, : len(w)] = w
        cls = np.empty(nv + ne, dtype=np.int64)
        cls[self.var_vertex] = vtype
        cls[self.var_edge] = len(self.vtypes) + etype
        return Problem(
            (nv + ne,), dom, np.stack(used), arcs,
            name=getattr(self.example, "name", "") or "continuous3d",
            meta={"continuous": True, "dim": 3, "size": list(A.size),
                  "spacing": float(self.lattice.spacing), "families": A.normals.tolist(),
                  "vertices": nv, "edges": ne, "boundary": dict(self.boundary),
                  "ground": list(self.ground)},
            positions=pos[order], value_weights=(table, cls),
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
                inside = np.asarray(outside[t]) == -1
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
        size = np.array(A.size, dtype=np.float64)
        clamp = (np.zeros(3), size, self.ground)  # past a ground face: the continuation
        for pts, fams_on, types, tlist, var in (
            (A.vertex_positions(), A.on, self.vertex_type, self.vtypes, self.var_vertex),
            (A.edge_positions(), A.edge_families(), self.edge_type, self.etypes, self.var_edge),
        ):
            labs = _local_labels(A, pts, fams_on, tris, index, clamp).tolist()
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
                        if face in self.ground:
                            continue
                        a = "xyz".index(face[0])
                        if (q[a] > size[a]) if face[1] == "+" else (q[a] < 0):
                            local[k] = index[self.boundary[face]]
                            break
                lookup = {s: j for j, s in enumerate(st)}
                grid[var[i]] = lookup.get(tuple(local), -1)
        return grid
