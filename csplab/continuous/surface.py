"""Surface tracing of continuous model synthesis in 3D: the solids of a solution.

A solution of :class:`~csplab.continuous.csp3d.ContinuousCSP3` gives every vertex of the
plane arrangement its state: a label per cell of the central arrangement of the planes
through it. On each plane the sectors around every vertex (between consecutive edges in the
plane) have a label above and a label below the plane; where they differ, a face of a solid
lies there. :func:`surface_of` traces these regions into rings (every arrangement vertex on
them kept, so that neighbouring faces share all their vertices: no T-junctions), orients
each ring outward from its solid, triangulates it (ear clipping on exact integer
coordinates; constrained Delaunay for regions with holes or rings that touch themselves)
and splits each label's polygons into closed surfaces (connected through shared edges),
one :class:`~csplab.continuous.polyhedra.Solid` each. Outputs are closed and outward by
construction, so they are built with :meth:`PolyhedralModel.trusted` (the 3D tests
re-validate them).

The module reads the CSP's states (:class:`~csplab.continuous.space.States3`); it does not
build them (:mod:`csplab.continuous.csp3d` does, and calls :func:`surface_of` from
:meth:`~csplab.continuous.csp3d.ContinuousCSP3.model`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from csplab.continuous._geom import triangulate_rings
from csplab.continuous.polyhedra import PolyhedralModel, Solid
from csplab.continuous.space import States3
from csplab.errors import InputError

__all__ = ["surface_of"]


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


def surface_of(self: States3, grid: ArrayLike, name: str = "") -> PolyhedralModel:
    """The output solids of a solution ``grid`` of ``self`` (the CSP): on every plane the
    regions between two different labels are traced from the vertex states (every vertex
    kept, so that the surface is watertight), triangulated and given to the label below
    (outward normal up) and the label above (down); each label's triangles split into
    closed surfaces. :meth:`~csplab.continuous.csp3d.ContinuousCSP3.model` is this function."""
    A = self.arrangement
    N = A.normals
    signs, _ = A.cells
    g = np.asarray(grid, dtype=np.int64).reshape(-1)
    if g.shape != (self.problem.n,) or (g < 0).any():
        raise InputError("model() needs a complete solution of this problem")
    vstate = g[self.var_vertex]
    XYZ = np.stack([A.X, A.Y, A.Z], axis=1)
    s = XYZ @ N.T
    xyz = A.vertex_positions()
    size = np.array(A.size, dtype=np.float64)
    efam = A.edge_families()
    # vertices whose labels all agree lie on no face (unless an object reaches the region's
    # side there, where its solid is closed): their rays are never traced
    uniform = np.zeros(A.n_vertices, dtype=bool)
    for t, (_, states, _) in enumerate(self.vtypes):
        sel = np.flatnonzero(self.vertex_type == t)
        if sel.size:
            side = bool((np.asarray(self.vertex_outside[t]) != -1).any())
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
            side = bool((self.edge_outside[t] != -1).any())
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
                    ok = (g >= 0) & (outside[gc] == -1)
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
