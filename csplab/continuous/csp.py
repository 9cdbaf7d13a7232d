"""Continuous model synthesis as a binary CSP (thesis Sec. 4.5.1-4.5.6; 2008 paper Sec. 3.2-3.3).

**Neighbourhoods.** Around any point, a model looks like a set of rays (boundary directions)
with a label in each sector between consecutive rays. A neighbourhood is written *reduced*:
the rays whose two sides carry different labels, each with the label counter-clockwise after
it, in angular order; a point inside one label is ``((-1, label),)``. Eq. 4.1 asks that every
neighbourhood of the output occurs in the example.

**The example's neighbourhoods** are found as in the paper's Fig. 2(b): the example is cut by
the same line families (:class:`~csplab.continuous.arrangement.Arrangement` over its bounding
box plus one spacing), each face gets the label of the example there, and the reduced
neighbourhoods of every vertex, edge and face are collected. (The checker,
:func:`csplab.continuous.check.violations`, derives them independently from the polygons.)

**Variables** are the arrangement's vertices and edges (the paper's states live there; faces
are implied). An edge's value is the pair (label on its left, label on its right) w.r.t. its
family's direction, value ``left * K_l + right`` over the ``K_l`` labels (0 and the
example's object labels, compacted); it is allowed if the two labels are equal or the example
has an edge of that direction with those sides. A vertex's value indexes the list of allowed
states of its *type* (its rays, and which of its sectors are outside the region): the
expansions of the example's neighbourhoods whose rays are all among the vertex's rays (the
parallel-line assumption of Sec. 4.5.2), with outside sectors equal to the boundary label.
Value 0 is always all-empty. **Constraints**: one binary relation per (vertex type, ray): a
vertex state agrees with an edge value only when the edge's two labels are the vertex's
sectors on either side of that ray (paper Sec. 3.3). Every csplab solver runs unchanged on
the resulting :class:`~csplab.problem.Problem`; its ``positions`` (in spacings) let
``blocks`` modify it in boxes (Fig. 4.23).

Examples
--------
>>> from csplab.continuous.model import Polygon, PolygonModel
>>> E = PolygonModel.from_json({"polygons": [{"label": 1, "points": [[0, 0], [4, 0], [2, 3]]}]})
>>> C = ContinuousCSP(E, (8, 6))
>>> C.problem.n == C.arrangement.n_vertices + C.arrangement.n_edges
True
>>> sorted(len(s) for s in C.type_states)[-1]       # vertices where 3 families meet
8
>>> C.edge_states_allowed(0)                         # horizontal edges: 3 of 4 (Fig. 4.15)
[(0, 0), (1, 0), (1, 1)]
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Mapping, Sequence
from typing import Any, TypedDict, Unpack, overload

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from csplab.continuous.arrangement import Arrangement, Lattice
from csplab.continuous.csp3d import ContinuousCSP3
from csplab.continuous.lattice import check_snap, open_sides
from csplab.continuous.model import Polygon, PolygonModel
from csplab.continuous.polyhedra import PolyhedralModel
from csplab.continuous.user3d import UserConstraints3
from csplab.errors import InputError
from csplab.problem import Problem

__all__ = [
    "SIDES",
    "WINDOW2",
    "ContinuousCSP",
    "Signature",
    "continuous_csp",
    "example_signatures",
    "ground_sides",
    "reduce_signature",
]

Signature = tuple[tuple[int, int], ...]
_EPS = 1e-6  # offset (in lattice units / D) of the sample points beside an edge

#: the region's sides in 2D, named as the 3D faces, with their bits of
#: :meth:`~csplab.continuous.arrangement.Arrangement.on_side`
SIDES = {"x-": 1, "x+": 2, "y-": 4, "y+": 8}
#: ``ground="window"`` in 2D: every side but the sky
WINDOW2 = ("y-", "x-", "x+")


def ground_sides(ground: str | Sequence[str] | None) -> tuple[str, ...]:
    """The open sides of a 2D ``ground`` declaration (see :class:`ContinuousCSP`):
    ``None``, ``""`` or ``"none"``: none; ``"window"``: :data:`WINDOW2`; otherwise sides
    of :data:`SIDES`, comma-separated or a sequence.

    Examples
    --------
    >>> ground_sides("y-"), ground_sides("x+,y-"), ground_sides(None)
    (('y-',), ('x+', 'y-'), ())
    >>> ground_sides("z-")
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: ground: polygon sides are x-, x+, y-, y+ (or window, none), not z-
    """
    return open_sides(ground, SIDES, WINDOW2, "polygon sides")


def _continued(
    angles: NDArray[np.float64], rays: Sequence[int], outside: Sequence[bool], sides: int,
    open_bits: int,
) -> tuple[list[int], list[tuple[str, int]]]:  # fmt: skip
    """How a vertex on the region's sides sees past them: the full rays (``rays`` plus
    the axis rays that split its outside sector) and, per full ray, the label after it as
    ``("in", i)`` (sector ``i`` of ``rays``), ``("fixed", 0)`` (the boundary label: past a
    side that is not open) or ``("copy", i)`` (past open sides only: the continuation of
    the world, the label just inside, in sector ``i``; the example as a window).

    ``angles``: every ray's angle; ``sides``: the sides the vertex lies on
    (:meth:`~csplab.continuous.arrangement.Arrangement.on_side` bits); ``open_bits``: the
    open (ground) ones."""
    m = len(rays)
    full: list[int] = []
    after: list[tuple[str, int]] = []
    two = 2 * math.pi
    axis = {k: int(np.argmin(np.abs((angles - k * math.pi / 2 + math.pi) % two - math.pi)))
            for k in range(4)}  # fmt: skip

    def sector_at(psi: float) -> int:
        for j in range(m):
            a = float(angles[rays[j]])
            b = float(angles[rays[(j + 1) % m]]) if m > 1 else a + two
            if b <= a:
                b += two
            if a < psi < b or a < psi + two < b:
                return j
        raise AssertionError("a direction on a ray")  # pragma: no cover

    for i in range(m):
        full.append(rays[i])
        if not outside[i]:
            after.append(("in", i))
            continue
        a = float(angles[rays[i]])
        b = float(angles[rays[(i + 1) % m]]) if m > 1 else a + two
        if b <= a:
            b += two
        cuts = [k * math.pi / 2 for k in range(1, 9) if a + 1e-9 < k * math.pi / 2 < b - 1e-9]
        bounds = [a, *cuts, b]
        for k in range(len(bounds) - 1):
            phi = 0.5 * (bounds[k] + bounds[k + 1])
            c, sn = math.cos(phi), math.sin(phi)
            out = {1: c < 0, 2: c > 0, 4: sn < 0, 8: sn > 0}
            if any(out[bit] and sides & bit and not open_bits & bit for bit in out):
                what = ("fixed", 0)
            else:
                if (sides & 1 and c < 0) or (sides & 2 and c > 0):
                    c = (1e-6 if sides & 1 else -1e-6) * (abs(c) + abs(sn))
                if (sides & 4 and sn < 0) or (sides & 8 and sn > 0):
                    sn = (1.37e-6 if sides & 4 else -1.37e-6) * (abs(c) + abs(sn))
                what = ("copy", sector_at(math.atan2(sn, c) % two))
            if k:
                full.append(axis[round(bounds[k] / (math.pi / 2)) % 4])
            after.append(what)
    return full, after


def reduce_signature(rays: Sequence[int], labels: Sequence[int]) -> Signature:
    """The reduced neighbourhood of rays (angular order) with ``labels[i]`` in the sector
    counter-clockwise after ``rays[i]``.

    >>> reduce_signature([0, 1, 2, 3], [1, 1, 0, 0])
    ((0, 1), (2, 0))
    >>> reduce_signature([0, 2], [5, 5])
    ((-1, 5),)
    """
    m = len(rays)
    keep = [i for i in range(m) if labels[i - 1] != labels[i]]
    if not keep:
        return ((-1, int(labels[0]) if m else 0),)
    return tuple((int(rays[i]), int(labels[i])) for i in keep)


def _expand(sig: Signature, rays: Sequence[int]) -> tuple[int, ...] | None:
    """Sector labels of ``rays`` realising ``sig``, or None if ``sig`` uses another ray."""
    if sig[0][0] == -1:
        return (sig[0][1],) * len(rays)
    srays = [r for r, _ in sig]
    if not set(srays) <= set(rays):
        return None
    out = []
    for r in rays:
        j = bisect.bisect_right(srays, r) - 1
        out.append(sig[j][1])  # j == -1 wraps to the last ray
    return tuple(out)


def _edge_labels(
    A: Arrangement, shapes: dict[int, Any], offset: tuple[float, float]
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Labels left and right of each edge of ``A`` by point location in ``shapes``
    (``{label: geometry}`` in lattice units shifted by ``offset``)."""
    mid = A.edge_positions() - np.asarray(offset)
    d = A.dirs[A.edge_family].astype(np.float64)
    nrm = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.hypot(d[:, 0], d[:, 1])[:, None]
    eps = _EPS / A.D
    out = []
    for side in (1.0, -1.0):
        p = mid + side * eps * nrm
        lab = np.zeros(len(p), dtype=np.int64)
        for b, g in shapes.items():
            lab[shapely.contains_xy(g, p[:, 0], p[:, 1])] = b
        out.append(lab)
    return out[0], out[1]


def _vertex_sectors(
    A: Arrangement, left: NDArray[np.int64], right: NDArray[np.int64]
) -> list[tuple[list[int], list[int]]]:
    """Per vertex: its rays (sorted) and the label after each, from the edges' labels."""
    F = A.F
    after: list[dict[int, int]] = [{} for _ in range(A.n_vertices)]
    for e, (a, b, f) in enumerate(
        zip(A.edge_src.tolist(), A.edge_dst.tolist(), A.edge_family.tolist(), strict=True)
    ):
        after[a][f] = int(left[e])
        after[b][F + f] = int(right[e])
    out = []
    for d in after:
        rays = sorted(d)
        out.append((rays, [d[r] for r in rays]))
    return out


def _arrangement(
    example: PolygonModel, lattice: Lattice, W: int, H: int, lines: str = "lattice"
) -> Arrangement:
    """:class:`~csplab.continuous.arrangement.Arrangement`, its refusal naming the
    example's file."""
    try:
        return Arrangement(lattice, W, H, lines=lines)
    except InputError as e:
        raise InputError(f"{example.source}: {e}") from None


def example_signatures(
    example: PolygonModel, lattice: Lattice, label_index: dict[int, int],
    ground: Sequence[str] = (),
    coverage: dict[Signature, int] | None = None,
    on_ground: dict[str, set[Signature]] | None = None,
) -> set[Signature]:  # fmt: skip
    """Every reduced neighbourhood of ``example`` (labels compacted by ``label_index``),
    from the arrangement of its own bounding box plus one spacing (paper Fig. 2(b)).

    Past the sides of its bounding box named in ``ground`` (:func:`ground_sides`) the
    example continues: there the arrangement ends at the box, and the label past it is the
    one just inside (a polygon standing on the bottom goes on below it, so its bottom
    edge is no boundary; see :func:`_continued`). ``coverage``, if given, receives how much
    of the example each neighbourhood covers: the number of the arrangement's vertices and
    edges inside the example's box where it occurs (area, length or a count of corners, in
    line spacings). ``on_ground``, if given, receives per ``ground`` side the
    neighbourhoods at the example's vertices and edges on that side of its box, and empty
    space (what the output may have on the region's side: like the example's bottom, or
    bare ground)."""
    lo = np.rint(lattice.to_lattice(np.array([example.bounds[:2]]))[0]).astype(np.int64)
    hi = np.rint(lattice.to_lattice(np.array([example.bounds[2:]]))[0]).astype(np.int64)
    bits = sum(SIDES[g] for g in ground)
    m0 = np.array([0 if bits & 1 else 1, 0 if bits & 4 else 1])  # margins low
    m1 = np.array([0 if bits & 2 else 1, 0 if bits & 8 else 1])  # and high
    ext = hi - lo + m0 + m1
    A = _arrangement(example, lattice, int(ext[0]), int(ext[1]))
    s = float(lattice.spacing)
    o = np.array([float(lattice.origin[0]), float(lattice.origin[1])])
    shapes = {}
    for b in example.labels:
        g = example.shape(b)
        g = shapely.transform(g, lambda xy: (xy - o) / s - lo + m0)
        shapely.prepare(g)
        shapes[label_index[b]] = g
    left, right = _edge_labels(A, shapes, (0.0, 0.0))
    sigs: set[Signature] = {((-1, 0),)} | {((-1, i),) for i in shapes}
    F = A.F
    side = A.on_side()
    if bits:  # an edge on an open side: the world continues past it (no boundary there)
        common = side[A.edge_src] & side[A.edge_dst]
        eout = A.edge_outside()
        on_open = (common & bits) != 0
        left = np.where(on_open & (eout == 1), right, left)
        right = np.where(on_open & (eout == 2), left, right)
    tol = 1e-9  # inside the example's box (closed), in lattice units
    box_lo, box_hi = m0 - tol, m0 + (hi - lo) + tol
    vpos, epos = A.vertex_positions(), A.edge_positions()
    vin = ((vpos >= box_lo) & (vpos <= box_hi)).all(axis=1).tolist()
    ein = ((epos >= box_lo) & (epos <= box_hi)).all(axis=1).tolist()

    on_sides: dict[str, set[Signature]] = on_ground if on_ground is not None else {}

    def seen(sig: Signature, inside: bool, sides: int = 0) -> None:
        sigs.add(sig)
        if coverage is not None and inside:
            coverage[sig] = coverage.get(sig, 0) + 1
        for g in ground if on_ground is not None else ():
            if sides & SIDES[g]:  # on that side of the box: also bare ground
                on_sides.setdefault(g, {((-1, 0),)}).add(sig)

    eside = side[A.edge_src] & side[A.edge_dst]

    for e, (f, L, R) in enumerate(
        zip(A.edge_family.tolist(), left.tolist(), right.tolist(), strict=True)
    ):
        seen(reduce_signature([f, F + f], [L, R]), ein[e], int(eside[e]))
    angles = A.ray_angles
    for v, (rays, labs) in enumerate(_vertex_sectors(A, left, right)):
        if not rays:
            continue
        sd = int(side[v])
        if sd & bits:
            full, after = _continued(angles, rays, A.outside_sectors(rays, sd), sd, bits)
            flabs = [0 if k == "fixed" else labs[i] for k, i in after]
            seen(reduce_signature(full, flabs), vin[v], sd)
        else:
            seen(reduce_signature(rays, labs), vin[v])
    return sigs


class ContinuousCSP:
    """The binary CSP of continuous model synthesis for a polygon example in a 2D region.

    The region is ``W x H`` line spacings; see the module docstring.

    Parameters
    ----------
    example : PolygonModel
        The example; it needs at least one polygon.
    size : (int, int)
        Region ``W x H`` in line spacings.
    spacing : float, optional
        Line spacing in the example's units (default: derived, see
        :class:`~csplab.continuous.arrangement.Lattice`).
    snap : bool
        Round example vertices onto the lattice of ``spacing``.
    boundary : int
        The label outside the region (default 0, empty space).
    lines : {"lattice", "equal"}
        Line spacing per family (:data:`~csplab.continuous.arrangement.LINES`).
    lattice : Lattice, optional
        The lattice to use (``spacing`` and ``snap`` are then ignored); default: the
        example's own, :meth:`Lattice.of_model`.
    ground : str or sequence of str, optional
        The open sides (:func:`ground_sides`, e.g. ``"y-"``): the example is a window onto
        a world that continues past these sides of its bounding box, and so does the
        output past these sides of the region (a state there has, outside the region, what
        it has just inside: a polygon reaching the bottom stands on the ground). Default
        none.

    Attributes
    ----------
    problem : Problem
        The CSP; ``shape == (n,)``, cells in scan order (x outermost) of their positions.
    arrangement : Arrangement
    labels : tuple of int
        Compact label index -> model label (index 0 is empty space).
    type_rays, type_states : lists
        Per vertex type, its rays and its allowed sector-label tuples (compact labels).

    Raises
    ------
    InputError
        When ``size`` is not two extents, the example has no polygon, ``boundary`` does not
        occur in the example, or no neighbourhood of the example fits some vertex of the
        arrangement (as ``lines="equal"`` or a boundary label may cause); the lattice and
        the arrangement raise it for a bad ``spacing``, region or ``lines``.
    """

    def __init__(
        self,
        example: PolygonModel,
        size: Sequence[int],
        *,
        spacing: float | None = None,
        snap: bool = False,
        boundary: int = 0,
        lines: str = "lattice",
        lattice: Lattice | None = None,
        ground: str | Sequence[str] | None = None,
    ) -> None:
        if len(size) != 2:
            raise InputError(f"a continuous 2D region needs WxH, not {tuple(size)}")
        W, H = (int(v) for v in size)
        if not example.polygons:
            raise InputError(f"{example.source}: an example needs at least one polygon")
        self.example = example
        self.lattice = lattice or Lattice.of_model(example, spacing, snap=snap)
        if self.lattice.snapped:
            example = _snapped(example, self.lattice)
            self.example = example
        self.labels: tuple[int, ...] = (0, *example.labels)
        index = {b: i for i, b in enumerate(self.labels)}
        if boundary not in index:
            raise InputError(f"boundary label {boundary} does not occur in the example")
        self.boundary = boundary
        #: the open sides (:func:`ground_sides`): the example and the output continue past them
        self.ground = ground_sides(ground)
        opened = sum(SIDES[g] for g in self.ground)
        #: how much of the example each neighbourhood covers (vertices and edges of its
        #: arrangement inside its box where it occurs): the weights of ``choice="weighted"``
        self.coverage: dict[Signature, int] = {}
        #: per open side, the example's neighbourhoods on that side of its box (and bare
        #: ground): the only ones a vertex or edge on that side of the region may take
        self.on_ground: dict[str, set[Signature]] = {g: {((-1, 0),)} for g in self.ground}
        self.signatures = example_signatures(example, self.lattice, index, self.ground,
                                             self.coverage, self.on_ground)  # fmt: skip
        A = self.arrangement = _arrangement(example, self.lattice, W, H, lines)
        F, Kl = A.F, len(self.labels)
        self.Kl = Kl
        b0 = index[boundary]
        # vertex types
        side = A.on_side()
        tkey = (A.ray_mask << 4) | side
        ukeys, vtype = np.unique(tkey, return_inverse=True)
        self.vertex_type = vtype.astype(np.int64)
        self.type_rays: list[list[int]] = []
        self.type_states: list[list[tuple[int, ...]]] = []
        self.type_outside: list[tuple[bool, ...]] = []
        #: per vertex type, its rays seen past open sides and each state's label after
        #: each of them (:func:`_continued`; the type's own rays and states elsewhere)
        self.type_full: list[tuple[list[int], dict[tuple[int, ...], tuple[int, ...]]]] = []
        angles = A.ray_angles
        #: per vertex type then edge family, the weight of each value (``choice="weighted"``)
        self.state_weights: list[NDArray[np.float64]] = []
        for key in ukeys.tolist():
            mask, sd = key >> 4, key & 15
            rays = [r for r in range(2 * F) if (mask >> r) & 1]
            outside = A.outside_sectors(rays, sd) if sd else (False,) * len(rays)
            found: dict[tuple[int, ...], tuple[int, ...]] = {}
            cover: dict[tuple[int, ...], int] = {}  # per state: the example it covers
            if sd & opened:
                full, past = _continued(angles, rays, outside, sd, opened)
                at = [full.index(r) for r in rays]
                for sig in self.signatures:
                    ex = _expand(sig, full)
                    if ex is None or any(
                        ex[k] != (b0 if kind == "fixed" else ex[at[i]])
                        for k, (kind, i) in enumerate(past)
                    ):
                        continue
                    here = reduce_signature(full, ex)  # on an open side: as the example's
                    if any(sd & SIDES[g] and here not in self.on_ground[g] for g in self.ground):
                        continue
                    st = tuple(ex[j] for j in at)
                    found[st] = ex
                    cover[st] = cover.get(st, 0) + self.coverage.get(sig, 0)
            else:
                full = rays
                for sig in self.signatures:
                    got = _expand(sig, rays)
                    if got is not None and all(got[i] == b0 for i in range(len(rays))
                                               if outside[i]):  # fmt: skip
                        found[got] = got
                        cover[got] = cover.get(got, 0) + self.coverage.get(sig, 0)
            ordered = sorted(found, key=lambda st: (any(st), st))
            if not ordered:
                raise InputError(
                    f"{example.source}: no neighbourhood of the example fits a vertex with rays "
                    f"{rays} (boundary label {boundary})"
                )
            self.type_rays.append(rays)
            self.type_states.append(ordered)
            self.type_outside.append(outside)
            self.type_full.append((full, found))
            # Sec. 4.5.4's states, each weighted by the example it covers (+1: every state
            # stays possible): the neighbourhoods that look like it here
            self.state_weights.append(np.array([1.0 + cover[st] for st in ordered]))
        nst = max(len(s) for s in self.type_states)
        K = self.K = max(nst, Kl * Kl)
        # edge domains per family
        edge_ok = np.zeros((F, Kl * Kl), dtype=bool)
        for f in range(F):
            for L in range(Kl):
                for R in range(Kl):
                    edge_ok[f, L * Kl + R] = reduce_signature([f, F + f], [L, R]) in self.signatures
        eout = A.edge_outside()
        nv, ne = A.n_vertices, A.n_edges
        dom = np.zeros((nv + ne, K), dtype=bool)
        nstates = np.array([len(s) for s in self.type_states], dtype=np.int64)
        dom[:nv] = np.arange(K)[None, :] < nstates[vtype][:, None]
        dom[nv:, : Kl * Kl] = edge_ok[A.edge_family]
        Ls, Rs = np.divmod(np.arange(Kl * Kl), Kl)
        side = A.on_side()
        eopen = (side[A.edge_src] & side[A.edge_dst] & opened) != 0
        for code, labs in ((1, Ls), (2, Rs)):
            sel = np.flatnonzero((eout == code) & ~eopen)
            dom[nv + sel, : Kl * Kl] &= (labs == b0)[None, :]
        # on an open side the world goes on: the same label on both sides of the edge
        dom[nv + np.flatnonzero((eout > 0) & eopen), : Kl * Kl] &= (Ls == Rs)[None, :]
        for g in self.ground:  # and only what the example has on that side of its box
            ok = np.array([((-1, int(L)),) in self.on_ground[g] for L in Ls.tolist()])
            on_g = (side[A.edge_src] & side[A.edge_dst] & SIDES[g]) != 0
            dom[nv + np.flatnonzero(on_g), : Kl * Kl] &= ok[None, :]
        for f in range(F):  # an edge value (left, right): the example's edges like it
            self.state_weights.append(np.array(
                [1.0 + self.coverage.get(reduce_signature([f, F + f], [L, R]), 0)
                 for L in range(Kl) for R in range(Kl)]))  # fmt: skip
        # relations per (type, ray position), deduplicated
        rel_ids: dict[bytes, int] = {}
        rels: list[NDArray[np.bool_]] = []
        pos_rel = np.full((len(ukeys), 2 * F), -1, dtype=np.int64)
        for t, (rays, states) in enumerate(zip(self.type_rays, self.type_states, strict=True)):
            full, seen = self.type_full[t]
            S = np.array([seen[st] for st in states], dtype=np.int64).reshape(
                len(states), len(full)
            )
            for r in rays:
                i = full.index(r)
                before, after = S[:, i - 1], S[:, i]
                lab_l, lab_r = (after, before) if r < F else (before, after)
                M = np.zeros((K, K), dtype=bool)
                M[np.arange(len(states)), lab_l * Kl + lab_r] = True
                k = M.tobytes()
                if k not in rel_ids:
                    rel_ids[k] = len(rels)
                    rels.append(M)
                pos_rel[t, r] = rel_ids[k]
        # variables in scan order of their positions
        pos = np.concatenate([A.vertex_positions(), A.edge_positions()])
        order = np.lexsort((pos[:, 1], pos[:, 0]))
        var = np.empty(nv + ne, dtype=np.int64)
        var[order] = np.arange(nv + ne)
        self.var_vertex, self.var_edge = var[:nv], var[nv:]
        e = np.arange(ne)
        fe = A.edge_family
        arcs = np.concatenate([
            np.stack([var[A.edge_src], var[nv + e], pos_rel[vtype[A.edge_src], fe]], axis=1),
            np.stack([var[A.edge_dst], var[nv + e], pos_rel[vtype[A.edge_dst], F + fe]], axis=1),
        ])  # fmt: skip
        if (arcs[:, 2] < 0).any():  # pragma: no cover - every incidence is a ray
            raise AssertionError("an edge end without its ray")
        # the weighted choice: one weight class per vertex type and per edge family
        table = np.zeros((len(self.state_weights), K), dtype=np.float64)
        for t, w in enumerate(self.state_weights):
            table[t, : len(w)] = w
        cls = np.empty(nv + ne, dtype=np.int64)
        cls[self.var_vertex] = self.vertex_type
        cls[self.var_edge] = len(self.type_states) + A.edge_family
        self.problem = Problem(
            (nv + ne,),
            dom[order],
            np.stack(rels),
            arcs,
            name=example.name or "continuous",
            meta={
                "continuous": True,
                "example": example.name,
                "size": [W, H],
                "spacing": float(self.lattice.spacing),
                "families": A.dirs.tolist(),
                "vertices": nv,
                "edges": ne,
                "boundary": boundary,
                "lines": lines,
                "ground": list(self.ground),
            },
            positions=pos[order],
            value_weights=(table, cls),
        )

    # ------------------------------------------------------------------ queries
    def edge_states_allowed(self, family: int) -> list[tuple[int, int]]:
        """The (left, right) model labels an inside edge of one family may take.

        Parameters
        ----------
        family : int
            The family's index (angular order of the arrangement's families).

        Returns
        -------
        list of (int, int)
            The allowed (label on the left, label on the right) pairs w.r.t. the family's
            direction, in model labels (0 is empty space), in increasing order.
        """
        Kl, F = self.Kl, self.arrangement.F
        return [
            (self.labels[L], self.labels[R])
            for L in range(Kl)
            for R in range(Kl)
            if reduce_signature([family, F + family], [L, R]) in self.signatures
        ]

    def vertex_state_counts(self) -> dict[tuple[int, ...], int]:
        """The number of allowed states of each inside vertex type.

        Returns
        -------
        dict of tuple of int to int
            The families through an inside vertex type (each a whole line: both rays) to
            the number of states that type may take.
        """
        F = self.arrangement.F
        out: dict[tuple[int, ...], int] = {}
        for rays, st in zip(self.type_rays, self.type_states, strict=True):
            if len(rays) % 2 == 0 and all((r + F) in rays for r in rays if r < F):
                fams = tuple(r for r in rays if r < F)
                if len(fams) * 2 == len(rays):
                    out[fams] = len(st)
        return out

    # ------------------------------------------------------------------ decoding
    def edge_labels(self, grid: ArrayLike) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """The compact (left, right) labels of every edge in a solution.

        Parameters
        ----------
        grid : array_like of int
            A value per variable of :attr:`problem` (any shape of ``n`` values).

        Returns
        -------
        left, right : int64 arrays ``(n_edges,)``
            Per arrangement edge, the compact label (an index into :attr:`labels`) on its
            left and on its right w.r.t. its family's direction.
        """
        g = np.asarray(grid, dtype=np.int64).reshape(-1)
        v = g[self.var_edge]
        return v // self.Kl, v % self.Kl

    def model(self, grid: ArrayLike, *, name: str = "") -> PolygonModel:
        """The output polygons of a solution, in the example's coordinates.

        Faces are merged per label and collinear vertices dropped.

        Parameters
        ----------
        grid : array_like of int
            A complete solution: one non-negative value per variable of :attr:`problem`.
        name : str, default ""
            The model's name; empty: the example's name (or ``model``) with ``-synth``.

        Returns
        -------
        PolygonModel
            The output; its ``meta`` records the example's name, the size and the spacing
            (and the example's colours, if it has them).

        Raises
        ------
        InputError
            When ``grid`` has the wrong number of values or a negative (unassigned) one.
        """
        A = self.arrangement
        g = np.asarray(grid, dtype=np.int64).reshape(-1)
        if g.shape != (self.problem.n,) or (g < 0).any():
            raise InputError("model() needs a complete solution of this problem")
        F = A.F
        left, right = self.edge_labels(g)
        # outside the region is not part of the output: its sides bound every polygon
        eout = A.edge_outside()
        left[eout == 1] = -1
        right[eout == 2] = -1
        edge_at = np.full((A.n_vertices, 2 * F), -1, dtype=np.int64)
        edge_at[A.edge_src, A.edge_family] = np.arange(A.n_edges)
        edge_at[A.edge_dst, F + A.edge_family] = np.arange(A.n_edges)
        ends = A.edge_src + A.edge_dst
        vstate = g[self.var_vertex].tolist()
        vtype = self.vertex_type.tolist()
        sp, (ox, oy) = float(self.lattice.spacing), self.lattice.origin
        wx = (float(ox) + sp * (A.X / A.D)).tolist()
        wy = (float(oy) + sp * (A.Y / A.D)).tolist()
        polys: list[Polygon] = []
        for L in range(1, self.Kl):
            e1 = np.flatnonzero((left == L) & (right != L))
            e2 = np.flatnonzero((right == L) & (left != L))
            starts = list(zip(A.edge_src[e1].tolist(), A.edge_family[e1].tolist(), strict=True))
            starts += list(
                zip(A.edge_dst[e2].tolist(), (F + A.edge_family[e2]).tolist(), strict=True)
            )
            used: set[tuple[int, int]] = set()
            rings = []
            for start in starts:
                if start in used:
                    continue
                ring: list[int] = []
                v, r = start
                while (v, r) not in used:
                    used.add((v, r))
                    w = int(ends[edge_at[v, r]]) - v
                    back = (r + F) % (2 * F)
                    rays = self.type_rays[vtype[w]]
                    sect = self._sectors(vtype[w], vstate[w])
                    i = rays.index(back) - 1
                    while sect[i - 1] == L:
                        i -= 1
                    nxt = rays[i % len(rays)]
                    if nxt != r:
                        ring.append(w)
                    v, r = w, nxt
                rings.append(tuple((wx[w], wy[w]) for w in ring))
            polys.extend(_assemble(self.labels[L], rings))
        return PolygonModel._trusted(
            polys, name=name or f"{self.example.name or 'model'}-synth",
            meta={"example": self.example.name, "size": self.problem.meta["size"],
                  "spacing": float(self.lattice.spacing),
                  **({"colors": self.example.meta["colors"]}
                     if "colors" in self.example.meta else {})},
        )  # fmt: skip

    def _sectors(self, t: int, state: int) -> tuple[int, ...]:
        """Sector labels of a vertex state, -1 for the sectors outside the region."""
        st, out = self.type_states[t][state], self.type_outside[t]
        return tuple(-1 if o else b for b, o in zip(st, out, strict=True))

    def region(self) -> tuple[float, float, float, float]:
        """The output region in the example's coordinates.

        Returns
        -------
        (float, float, float, float)
            The region's corners ``(x0, y0, x1, y1)``.
        """
        s, (ox, oy) = float(self.lattice.spacing), self.lattice.origin
        W, H = self.problem.meta["size"]
        return (float(ox), float(oy), float(ox) + s * W, float(oy) + s * H)

    # ------------------------------------------------------------------ encoding
    def encode(self, model: PolygonModel) -> NDArray[np.int32]:
        """The CSP assignment that a model lying on the lines describes.

        Every vertex and edge is valued by point location beside the edges; vertices whose
        neighbourhood is not an allowed state get -1 and edges with disallowed label pairs
        keep their value, so :meth:`Problem.violations` tells whether ``model`` is a
        solution.

        Parameters
        ----------
        model : PolygonModel
            A model in the example's coordinates, its edges on the arrangement's lines.

        Returns
        -------
        int32 array ``(n,)``
            One value per variable of :attr:`problem` (-1 for a vertex whose neighbourhood
            is not an allowed state).

        Raises
        ------
        InputError
            When ``model`` has a label that does not occur in the example.
        """
        A, lat = self.arrangement, self.lattice
        index = {b: i for i, b in enumerate(self.labels)}
        s = float(lat.spacing)
        o = np.array([float(lat.origin[0]), float(lat.origin[1])])
        shapes = {}
        for b in model.labels:
            if b not in index:
                raise InputError(f"label {b} does not occur in the example")
            gm = shapely.transform(model.shape(b), lambda xy: (xy - o) / s)
            shapely.prepare(gm)
            shapes[index[b]] = gm
        left, right = _edge_labels(A, shapes, (0.0, 0.0))
        eout = A.edge_outside()
        b0 = index[self.boundary]
        side = A.on_side()
        opened = sum(SIDES[g] for g in self.ground)
        eopen = (side[A.edge_src] & side[A.edge_dst] & opened) != 0
        left[eout == 1] = np.where(eopen, right, b0)[eout == 1]  # past an open side: as inside
        right[eout == 2] = np.where(eopen, left, b0)[eout == 2]
        grid = np.full(self.problem.n, -1, dtype=np.int32)
        grid[self.var_edge] = left * self.Kl + right
        lookup = [{st: i for i, st in enumerate(sts)} for sts in self.type_states]
        for v, (_, labs) in enumerate(_vertex_sectors(A, left, right)):
            t = self.vertex_type[v]
            grid[self.var_vertex[v]] = lookup[t].get(tuple(labs), -1)
        return grid


def _area(r: Sequence[tuple[float, float]]) -> float:
    return 0.5 * sum(
        x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(r, (*r[1:], r[0]), strict=True)
    )


def _assemble(label: int, rings: list[tuple[tuple[float, float], ...]]) -> list[Polygon]:
    """Polygons of one label from traced rings: counter-clockwise rings are shells,
    clockwise ones holes of the smallest shell covering them."""
    from shapely.geometry import Polygon as SP

    shells = [r for r in rings if _area(r) > 0]
    holes = [r for r in rings if _area(r) <= 0]
    owned: list[list[tuple[tuple[float, float], ...]]] = [[] for _ in shells]
    if holes:
        box = np.array([[min(x for x, _ in r), min(y for _, y in r),
                         max(x for x, _ in r), max(y for _, y in r)] for r in shells])  # fmt: skip
        for h in holes:
            hb = (min(x for x, _ in h), min(y for _, y in h),
                  max(x for x, _ in h), max(y for _, y in h))  # fmt: skip
            cand = np.flatnonzero((box[:, 0] <= hb[0]) & (box[:, 1] <= hb[1])
                                  & (box[:, 2] >= hb[2]) & (box[:, 3] >= hb[3]))  # fmt: skip
            hp = SP(h)
            inside = [int(i) for i in cand if SP(shells[i]).covers(hp)]
            if not inside:  # pragma: no cover - a hole always has a shell around it
                raise AssertionError("a hole outside every shell")
            owned[min(inside, key=lambda i: abs(_area(shells[i])))].append(h)
    return [Polygon(label, s, tuple(hs)) for s, hs in zip(shells, owned, strict=True)]


def _snapped(example: PolygonModel, lattice: Lattice) -> PolygonModel:
    """The example with every vertex rounded onto ``lattice``; refused in one line
    (:class:`~csplab.errors.InputError`) when that collapses a polygon or changes a label's
    area by more than :data:`~csplab.continuous.lattice.MAX_SNAP_CHANGE` of itself."""

    def snap(r: Sequence[tuple[float, float]]) -> list[list[float]]:
        uv = np.rint(lattice.to_lattice(np.asarray(r, dtype=np.float64)))
        return lattice.to_world(uv).tolist()  # type: ignore[no-any-return]

    polys = [
        {"label": p.label, "points": snap(p.points), "holes": [snap(h) for h in p.holes],
         **dict(p.extra)}
        for p in example.polygons
    ]  # fmt: skip
    s = float(lattice.spacing)
    try:
        out = PolygonModel(polys, name=example.name, meta=example.meta, source=example.source)
    except InputError as e:
        raise InputError(
            f"{example.source}: snapping onto spacing {s:g} collapses it "
            f"({str(e).splitlines()[0].removeprefix(f'{example.source}: ')}); pass a smaller "
            "--spacing"
        ) from None
    for b in example.labels:  # each label's area, as snapping left it
        check_snap(f"{example.source}: label {b}", s, "area", example.area(b), out.area(b))
    return out


class CSPOptions(TypedDict, total=False):
    """The keyword options of :func:`continuous_csp` (defaults there), for its overloads."""

    spacing: float | None
    snap: bool
    boundary: int | Mapping[str, int]
    lines: str
    constraints: UserConstraints3 | None
    max_memory: int | None
    ground: str | Sequence[str] | None


@overload
def continuous_csp(
    example: PolygonModel, size: Sequence[int], **options: Unpack[CSPOptions]
) -> ContinuousCSP: ...


@overload
def continuous_csp(
    example: PolyhedralModel, size: Sequence[int], **options: Unpack[CSPOptions]
) -> ContinuousCSP3: ...


def continuous_csp(
    example: PolygonModel | PolyhedralModel,
    size: Sequence[int],
    *,
    spacing: float | None = None,
    snap: bool = False,
    boundary: int | Mapping[str, int] = 0,
    lines: str = "auto",
    constraints: UserConstraints3 | None = None,
    max_memory: int | None = None,
    ground: str | Sequence[str] | None = None,
) -> ContinuousCSP | ContinuousCSP3:
    """The CSP of continuous model synthesis (Alg. 4.1 steps 1-4), in either dimension.

    :class:`ContinuousCSP` of a polygon model in a ``W x H`` region (``lines``),
    :class:`~csplab.continuous.csp3d.ContinuousCSP3` of a polyhedral one in ``A x B x C``
    (``boundary`` also per face, user ``constraints`` of thesis Sec. 4.6). Both give
    ``problem``, ``lattice``, ``arrangement``, ``labels``, ``boundary``, ``region()``,
    ``model(grid)`` and ``encode(model)``.

    Parameters
    ----------
    example : PolygonModel or PolyhedralModel
        The example.
    size : sequence of int
        The region in line spacings: ``(W, H)`` in 2D, ``(A, B, C)`` in 3D.
    spacing : float, optional
        Line (plane) spacing in the example's units; default: derived from the example
        (:class:`~csplab.continuous.lattice.Lattice`).
    snap : bool, default False
        Round example vertices onto the lattice of ``spacing``.
    boundary : int or mapping of str to int, default 0
        The label outside the region (0: empty space); in 3D also one per face
        (``{"z-": 1}``).
    lines : {"auto", "lattice", "equal"}, default "auto"
        Line (plane) spacing per family: in 2D
        :data:`~csplab.continuous.arrangement.LINES` (``auto``: ``lattice``), in 3D
        :data:`~csplab.continuous.lattice.PLANES` (``auto``: ``equal`` planes for an
        example in real coordinates, ``lattice`` for exact ones).
    constraints : UserConstraints3, optional
        User constraints of thesis Sec. 4.6 (3D only).
    max_memory : int, optional
        Bytes (3D): refuse, before building it, an arrangement estimated larger
        (:func:`~csplab.continuous.space.estimate3`); default a share of the memory
        available.
    ground : str or sequence of str, optional
        The sides (2D, :func:`ground_sides`: ``x-, x+, y-, y+``) or faces (3D,
        :func:`~csplab.continuous.csp3d.ground_faces`) past which the example and the
        output continue (an infinite ground); default none.

    Returns
    -------
    ContinuousCSP or ContinuousCSP3
        The CSP, of the example's dimension.

    Raises
    ------
    InputError
        When a 2D example gets user ``constraints`` or a per-face ``boundary``; the CSP
        classes raise it for a bad size, example, ``lines`` or boundary label.
    """
    if isinstance(example, PolyhedralModel):
        return ContinuousCSP3(example, size, spacing=spacing, snap=snap, boundary=boundary,
                              constraints=constraints, max_memory=max_memory,
                              ground=ground, planes=lines)  # fmt: skip
    if lines == "auto":
        lines = "lattice"
    if constraints:
        raise InputError("polygon models (2D) take no user constraints yet")
    if isinstance(boundary, Mapping):
        raise InputError("a polygon model has one label outside its region, not one per face")
    return ContinuousCSP(
        example, size, spacing=spacing, snap=snap, boundary=boundary, lines=lines, ground=ground
    )
