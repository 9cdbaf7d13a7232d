"""The plane arrangement of continuous model synthesis in 3D (thesis Sec. 4.5.3-4.5.8), exact.

The 2D construction of :mod:`csplab.continuous.arrangement`, one dimension up. The example's
vertices are put on an integer lattice (``origin``, ``spacing``: the largest length putting
every vertex on a lattice point, or ``spacing=`` with ``snap=``); every face normal is then an
integer vector, and normals equal up to sign are one *family*. A family with primitive
normal ``n`` has the planes ``n . x = k`` for every integer ``k`` (in lattice units), so every
lattice point lies on a plane of every family: vertices where four or more planes meet (the
apex of a four-sided pyramid, Sec. 4.5.8, Eq. 4.23-4.25) exist at every lattice point by
construction, and no spacing equations need solving. Three planes with independent normals
meet at a point with rational coordinates of denominator ``det``; with ``D`` the least common
multiple of these determinants every vertex has integer coordinates ``D * (x, y, z)``, and
all incidences are integer arithmetic.

The region is ``[0, A] x [0, B] x [0, C]`` (lattice units); its sides are planes of the axis
families, added as *boundary-only* families (just the two side planes) when the example has
no faces of that orientation.

Neighbourhoods are described on the *cells* of the central arrangement of all families'
planes through one point (:func:`central_cells`): a cell is a sign vector over the families
(which side of each plane a direction lies on). The neighbourhood of any point is a label
per cell that depends only on the signs of the planes through that point (thesis Sec. 4.5.5:
the Boolean expression of half-spaces, evaluated on each cell).

Examples
--------
>>> tet = [[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4]]
>>> from csplab.continuous.lattice import Lattice
>>> lat = Lattice.of_points(np.array(tet, dtype=float), [[0, 2, 1], [0, 1, 3], [0, 3, 2],
...     [1, 2, 3]])
>>> lat.spacing, lat.normals
(Fraction(4, 1), ((0, 0, 1), (0, 1, 0), (1, 0, 0), (1, 1, 1)))
>>> A = Arrangement3(lat, (4, 4, 4))
>>> A.D, A.F, int(A.on.all(axis=1).sum())     # lattice points: every family meets there
(1, 4, 125)
>>> len(central_cells(A.normals)[0])            # cells of 4 planes in general position
14
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from functools import cached_property
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import NDArray

from csplab.continuous.lattice import MAX_FAMILIES3, ArrangementGraph, Lattice, primitive3
from csplab.errors import InputError

if TYPE_CHECKING:  # types only: neither imports this module
    from csplab.continuous.polyhedra import PolyhedralModel
    from csplab.problem import Problem

__all__ = [
    "MAX_FAMILIES3",
    "Arrangement3",
    "States3",
    "central_cells",
    "check_budget3",
    "estimate3",
    "plane_counts",
    "plane_ks",
    "primitive3",
]

#: per vertex or edge type: its families, its states (a label per group of central cells)
#: and the group of every central cell
TypeStates = tuple[NDArray[np.int64], list[tuple[int, ...]], NDArray[np.int64]]


def _lcm(a: int, b: int) -> int:
    return a * b // math.gcd(a, b)


def _det3(m: NDArray[np.int64]) -> int:
    """Exact determinant of an integer 3x3 matrix."""
    a = [[int(x) for x in row] for row in m]
    return (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]))  # fmt: skip


def _adj3(m: NDArray[np.int64]) -> NDArray[np.int64]:
    """Exact adjugate (``det * inverse``) of an integer 3x3 matrix."""
    out = np.zeros((3, 3), dtype=np.int64)
    for i in range(3):
        for j in range(3):
            minor = np.delete(np.delete(m, i, axis=0), j, axis=1)
            out[j, i] = (-1) ** (i + j) * (int(minor[0, 0]) * int(minor[1, 1])
                                           - int(minor[0, 1]) * int(minor[1, 0]))  # fmt: skip
    return out


def central_cells(
    normals: NDArray[np.int64],
) -> tuple[NDArray[np.int8], NDArray[np.float64]]:
    """The cells of the central arrangement of the planes ``n . x = 0`` (``normals``
    ``(F, 3)``, at least two independent; integers are exact, floats use a relative
    tolerance of 1e-9): their sign vectors ``(c, F)`` (+1/-1) and one unit direction inside
    each.

    Every cell has a vertex of the spherical arrangement (a direction ``+-n_i x n_j``) on its
    boundary; around each such vertex the sectors between the great circles through it are
    sampled on their bisectors (signs of the planes through the vertex from the bisector,
    the others from the vertex), which finds every cell exactly for integer normals.
    """
    N = np.asarray(normals)
    exact = np.issubdtype(N.dtype, np.integer)
    N = N.astype(np.int64) if exact else N.astype(np.float64)
    nn = np.linalg.norm(N.astype(np.float64), axis=1)

    def zero(x: NDArray[Any], scale: float) -> NDArray[np.bool_]:
        out: NDArray[np.bool_] = x == 0 if exact else np.abs(x) <= 1e-9 * nn * scale
        return out

    F = len(N)
    found: dict[bytes, list[NDArray[np.float64]]] = {}
    for i, j in itertools.combinations(range(F), 2):
        p0 = np.cross(N[i], N[j])
        if (np.abs(p0) <= (0 if exact else 1e-9 * nn[i] * nn[j])).all():
            continue
        for p in (p0, -p0):
            on = np.flatnonzero(zero(N @ p, float(np.linalg.norm(p))))
            pf = p.astype(np.float64) / np.linalg.norm(p)
            tang = []
            for k in on:
                t = np.cross(N[k], p).astype(np.float64)
                t /= np.linalg.norm(t)
                tang.extend([t, -t])
            e1 = tang[0]
            e2 = np.cross(pf, e1)
            ang = np.array([math.atan2(float(t @ e2), float(t @ e1)) for t in tang])
            o = np.argsort(ang)
            base = np.sign(N @ p).astype(np.int8)
            base[on] = 0
            # step off the vertex by less than half its angular distance to any plane not
            # through it, so each sample keeps the vertex's signs on those planes (a fixed
            # step crossed planes of nearly parallel families: a sample filed under the
            # wrong cell, and the cell's mean direction outside it)
            off = np.ones(F, dtype=bool)
            off[on] = False
            gap = np.abs(N[off].astype(np.float64) @ pf) / nn[off]
            step = min(1e-3, 0.5 * float(gap.min())) if gap.size else 1e-3
            for a in range(len(o)):
                ta, tb = tang[o[a]], tang[o[(a + 1) % len(o)]]
                b = ta + tb
                if np.linalg.norm(b) < 1e-9:  # a sector of exactly pi: take the normal side
                    b = np.cross(pf, ta)
                b /= np.linalg.norm(b)
                sig = base.copy()
                sig[on] = np.sign(N[on] @ b).astype(np.int8)
                if (sig == 0).any():  # pragma: no cover - bisectors avoid the circles
                    continue
                w = pf + step * b
                found.setdefault(sig.tobytes(), []).append(w / np.linalg.norm(w))
    signs = np.array([np.frombuffer(k, dtype=np.int8) for k in sorted(found)], dtype=np.int8)
    dirs = np.array([np.mean(found[k], axis=0) for k in sorted(found)])
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    # a cell's mean sample direction is inside it (cells are convex cones)
    ok = np.sign(dirs @ N.T.astype(np.float64)).astype(np.int8) == signs
    if not ok.all():  # pragma: no cover - convexity
        raise AssertionError("a cell's representative direction left the cell")
    return signs, dirs


#: peak bytes per vertex of :func:`estimate3` while building the arrangement and its CSP,
#: the largest measured: 2,150 for the float tetrahedron (CAD STL) in 8x8x6 at its derived
#: spacing 0.5 (6.1 GB peak RSS; its own arrangement estimated 2.84e6 vertices); 270 for
#: the bevelled part at spacing 0.5 in 40x40x20 (298 MiB, 1.16e6 estimated)
BYTES_PER_VERTEX = 2200


def _gib(b: float) -> str:
    return f"{b / 2**30:.1f} GiB" if b >= 2**29 else f"{b / 2**20:.0f} MiB"


def plane_ks(
    lattice: Lattice, size: Sequence[int], shift: Sequence[int] = (0, 0, 0)
) -> list[NDArray[np.int64]]:
    """The planes ``n . x = k`` of each family (:meth:`Lattice.families` order) meeting the
    box ``size`` (lattice units, the lattice moved by ``shift``): the ``k`` of its step and
    residue (:meth:`Lattice.plane_steps`), the two sides for a boundary-only family."""
    fams, bonly = lattice.families()
    steps, residues = lattice.plane_steps()
    corners = np.array(list(itertools.product(*[(0, int(s)) for s in size])), dtype=np.int64)
    t = np.array([int(x) for x in shift], dtype=np.int64)
    out = []
    for n, b, st, r in zip(fams, bonly, steps, residues, strict=True):
        nv = np.array(n, dtype=np.int64)
        kc = corners @ nv
        lo, hi = int(kc.min()), int(kc.max())
        if b:
            out.append(np.array([lo, hi], dtype=np.int64))
            continue
        r0 = (r + int(nv @ t)) % st
        first = lo + (r0 - lo) % st
        out.append(np.arange(first, hi + 1, st, dtype=np.int64))
    return out


def plane_counts(lattice: Lattice, size: Sequence[int]) -> list[int]:
    """Planes of each family (:meth:`Lattice.families` order) in the box ``size``
    (:func:`plane_ks`)."""
    return [len(k) for k in plane_ks(lattice, size)]


def estimate3(lattice: Lattice, size: Sequence[int]) -> tuple[int, int, int]:
    """Estimated vertices, edges and peak bytes of the arrangement of ``lattice`` in the
    box ``size`` and of its CSP, before building anything.

    Thesis Sec. 4.5.7: three planes with independent normals meet once, so families of
    ``n_a, n_b, n_c`` planes give at most ``n_a n_b n_c`` vertices (``C(m, 3) n^3`` for
    ``m`` families of ``n``). Most of those meeting points lie outside the box: the points
    of a triple form a lattice of ``|det(N_a, N_b, N_c)|`` points per unit volume, so a
    triple counts ``min(n_a n_b n_c, |det| (A + 1)(B + 1)(C + 1))`` (the full product when
    one family is boundary-only; with equal planes, :meth:`Lattice.plane_steps`, that
    density divided by the product of the three steps). Each vertex starts at most three
    edges per triple through it; bytes are :data:`BYTES_PER_VERTEX` per vertex.

    Examples
    --------
    >>> lat = Lattice.of_points(np.array([[0, 0, 0], [1, 1, 1.0]]), [])
    >>> estimate3(lat, (2, 2, 2))[:2]     # boundary-only axis families: the 8 corners
    (8, 24)
    """
    n = plane_counts(lattice, size)
    fams, bonly = lattice.families()
    steps, _ = lattice.plane_steps()
    N = np.array(fams, dtype=np.int64).reshape(-1, 3)
    vol = math.prod(int(x) + 1 for x in size)
    v = 0
    for t in itertools.combinations(range(len(n)), 3):
        det = abs(_det3(N[list(t)]))
        if det == 0:
            continue
        full = n[t[0]] * n[t[1]] * n[t[2]]
        dense = -(-det * vol // (steps[t[0]] * steps[t[1]] * steps[t[2]]))
        v += full if any(bonly[k] for k in t) else min(full, dense)
    return v, 3 * v, BYTES_PER_VERTEX * v


def check_budget3(
    lattice: Lattice,
    size: Sequence[int],
    max_memory: int | None,
    where: str = "<model>",
    hint: str = " or a smaller --size",
) -> int:
    """Refuse in one line (:class:`~csplab.errors.MemoryLimitError`) an arrangement whose
    :func:`estimate3` exceeds ``max_memory`` bytes (default :data:`csplab.limits.MEMORY_SHARE` of
    :func:`~csplab.limits.available_memory`; ``hint`` follows "a larger --spacing" in the
    message); returns the estimated bytes."""
    from csplab.errors import MemoryLimitError
    from csplab.limits import MEMORY_SHARE, available_memory

    v, e, need = estimate3(lattice, size)
    budget = int(MEMORY_SHARE * available_memory()) if max_memory is None else int(max_memory)
    if need > budget:
        box = "x".join(str(int(s)) for s in size)
        n = plane_counts(lattice, size)
        raise MemoryLimitError(
            f"{where}: {len(n)} plane families ({max(n)} planes in the densest) in {box} "
            f"spacings make about {v:.3g} vertices and {e:.3g} edges, {_gib(need)} "
            f"(the memory budget is {_gib(budget)}: --memory-limit); a larger --spacing{hint} "
            "lowers it"
        )
    return need


class Arrangement3(ArrangementGraph):
    """Vertices and edges of the planes of ``lattice``'s families in the box ``size``
    (lattice units); see the module docstring. Refused before building when
    :func:`estimate3` exceeds ``max_memory`` bytes (:func:`check_budget3`; ``where`` names
    the example and ``hint`` the other remedy in the message).

    Attributes
    ----------
    normals : int array ``(F, 3)``; ``boundary_only`` bool ``(F,)``
    D : int
        Vertex ``v`` is at ``(X[v], Y[v], Z[v]) / D`` lattice units.
    X, Y, Z : int64 arrays
        Vertices sorted by ``(X, Y, Z)``.
    on : bool array ``(n_vertices, F)``
        Which families have a plane through each vertex.
    edge_src, edge_dst, edge_line : int64 arrays
        Edges between consecutive vertices of one line, from ``edge_src`` to ``edge_dst``
        along ``lines[edge_line]`` (a primitive integer direction).
    """

    def __init__(
        self,
        lattice: Lattice,
        size: Sequence[int],
        *,
        max_memory: int | None = None,
        where: str = "<model>",
        hint: str = " or a smaller --size",
        shift: Sequence[int] = (0, 0, 0),
    ) -> None:
        if len(size) != 3 or any(int(s) < 1 for s in size):
            raise InputError(f"the region must be AxBxC with positive sides, not {tuple(size)}")
        check_budget3(lattice, size, max_memory, where, hint)
        self.lattice = lattice
        self.size = tuple(int(s) for s in size)
        fams, bonly = lattice.families()
        self.normals = np.array(fams, dtype=np.int64).reshape(-1, 3)
        self.boundary_only = np.array(bonly, dtype=bool)
        F = self.F = len(fams)
        N = self.normals
        triples = [t for t in itertools.combinations(range(F), 3) if _det3(N[list(t)])]
        D = 1
        for t in triples:
            D = _lcm(D, abs(_det3(N[list(t)])))
        self.D = D
        if math.prod(int(x) * D + 1 for x in self.size) >= 2**62:
            raise InputError(
                f"{where}: the planes of {F} families meet at points of denominator "
                f"{D if D < 10**9 else f'~10^{len(str(D)) - 1}'}: their exact coordinates in "
                f"{'x'.join(map(str, self.size))} spacings exceed 64-bit integers; a larger "
                "--spacing (with --snap) gives simpler normals"
            )
        ext = np.array(self.size, dtype=np.int64) * D
        self.k_range: list[NDArray[np.int64]] = plane_ks(lattice, self.size, shift)
        steps, _ = lattice.plane_steps()
        self.steps = np.array(steps, dtype=np.int64)
        keys = []
        stride = (ext + 1).astype(np.int64)
        for t in triples:
            M = N[list(t)]
            det = _det3(M)
            adj = _adj3(M)
            m = D // det
            gg, hh = np.meshgrid(self.k_range[t[1]], self.k_range[t[2]], indexing="ij")
            base = adj[:, 1:2] * gg.ravel() + adj[:, 2:3] * hh.ravel()  # (3, G)
            kfs = self.k_range[t[0]]
            chunk = max(1, 1_000_000 // max(1, base.shape[1]))  # planes of f at once
            for c0 in range(0, len(kfs), chunk):
                kc = kfs[c0 : c0 + chunk]
                P = ((adj[:, 0:1, None] * kc[None, None, :] + base[:, :, None]) * m).reshape(3, -1)
                ok = ((P >= 0) & (P <= ext[:, None])).all(axis=0)
                if ok.any():
                    q = P[:, ok]
                    keys.append((q[0] * stride[1] + q[1]) * stride[2] + q[2])
        key = np.unique(np.concatenate(keys)) if keys else np.zeros(0, dtype=np.int64)
        self.X = key // (stride[1] * stride[2])
        self.Y = (key // stride[2]) % stride[1]
        self.Z = key % stride[2]
        XYZ = np.stack([self.X, self.Y, self.Z], axis=1)
        s = XYZ @ N.T  # (nv, F)
        on = s % D == 0
        for f in range(F):
            if bonly[f] or self.steps[f] > 1:
                on[:, f] &= np.isin(s[:, f] // D, self.k_range[f])
        self.on = on
        # edges: consecutive vertices on the line of two planes
        lines: dict[tuple[int, int, int], int] = {}
        src, dst, lid = [], [], []
        for f, g in itertools.combinations(range(F), 2):
            u0 = np.cross(N[f], N[g])
            if not u0.any():
                continue
            u = primitive3(u0.tolist())
            li = lines.setdefault(u, len(lines))
            idx = np.flatnonzero(on[:, f] & on[:, g])
            if idx.size < 2:
                continue
            kf, kg = s[idx, f] // D, s[idx, g] // D
            tpos = XYZ[idx] @ np.array(u)
            o = np.lexsort((tpos, kg, kf))
            idx, kf, kg = idx[o], kf[o], kg[o]
            same = (kf[1:] == kf[:-1]) & (kg[1:] == kg[:-1])
            src.append(idx[:-1][same])
            dst.append(idx[1:][same])
            lid.append(np.full(int(same.sum()), li, dtype=np.int64))
        self.lines = np.array(sorted(lines, key=lines.__getitem__), dtype=np.int64).reshape(-1, 3)
        # a line in three or more planes comes from several pairs: one edge per (src, dst)
        # (its line is the same), in (src, dst) order
        a, b, c = (np.concatenate(x) if x else np.zeros(0, dtype=np.int64)
                   for x in (src, dst, lid))  # fmt: skip
        _, first = np.unique(a * max(1, self.n_vertices) + b, return_index=True)
        self.edge_src, self.edge_dst, self.edge_line = a[first], b[first], c[first]

    @property
    def family_vectors(self) -> NDArray[np.int64]:
        """The vector naming each family: its face normal (3D; an edge direction in 2D)."""
        return self.normals

    def vertex_positions(self) -> NDArray[np.float64]:
        """Vertices in lattice units."""
        out: NDArray[np.float64] = np.stack([self.X, self.Y, self.Z], axis=1) / self.D
        return out

    def on_side(self) -> NDArray[np.int64]:
        """Per vertex, bits 1/2 (x = 0 / A), 4/8 (y), 16/32 (z) of the region's sides."""
        e = np.array(self.size) * self.D
        out = np.zeros(self.n_vertices, dtype=np.int64)
        for a, c in enumerate((self.X, self.Y, self.Z)):
            out |= (c == 0) * (1 << (2 * a)) | (c == e[a]) * (2 << (2 * a))
        return out

    def edge_families(self) -> NDArray[np.bool_]:
        """``(n_edges, F)``: the families with a plane containing each edge (computed once,
        read-only)."""
        return self._edge_families

    @cached_property
    def _edge_families(self) -> NDArray[np.bool_]:
        # a line lies in a family's planes when its direction is orthogonal to the normal
        # (per line, not per edge) and its edge's first vertex is on one of them
        along = self.lines @ self.normals.T == 0  # (lines, F)
        out: NDArray[np.bool_] = along[self.edge_line] & self.on[self.edge_src]
        out.setflags(write=False)
        return out

    @cached_property
    def cells(self) -> tuple[NDArray[np.int8], NDArray[np.float64]]:
        """:func:`central_cells` of all families."""
        return central_cells(self.normals)

    def axis_family(self, axis: int) -> int:
        """The family whose planes are the region's sides across ``axis``."""
        target = np.zeros(3, dtype=np.int64)
        target[axis] = 1
        return int(np.flatnonzero((self.normals == target).all(axis=1))[0])


class States3(Protocol):
    """The states of the 3D CSP on an arrangement, as
    :class:`~csplab.continuous.csp3d.ContinuousCSP3` builds them: per vertex and edge type
    its families, states and cell groups (``vtypes``, ``etypes``), the compact label each
    group must have outside the region, -1 inside or -2 past a ground face (its label
    continues the inside; ``vertex_outside``, ``edge_outside``), each
    vertex's and edge's type and problem variable. What the user constraints
    (:func:`~csplab.continuous.user3d.allowed_states`) and the surface tracing
    (:func:`~csplab.continuous.surface.surface_of`) read, without importing the CSP."""

    @property
    def example(self) -> PolyhedralModel: ...

    @property
    def lattice(self) -> Lattice: ...

    @property
    def arrangement(self) -> Arrangement3: ...

    @property
    def labels(self) -> tuple[int, ...]: ...

    @property
    def problem(self) -> Problem: ...

    @property
    def vtypes(self) -> list[TypeStates]: ...

    @property
    def etypes(self) -> list[TypeStates]: ...

    @property
    def vertex_outside(self) -> list[NDArray[np.int64]]: ...

    @property
    def edge_outside(self) -> list[NDArray[np.int64]]: ...

    @property
    def vertex_type(self) -> NDArray[np.int64]: ...

    @property
    def edge_type(self) -> NDArray[np.int64]: ...

    @property
    def var_vertex(self) -> NDArray[np.int64]: ...

    @property
    def var_edge(self) -> NDArray[np.int64]: ...
