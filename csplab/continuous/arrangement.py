"""The line arrangement of continuous model synthesis (Alg. 4.1 step 1), exact.

**The lattice** (:class:`~csplab.continuous.lattice.Lattice`, one type in 2D and 3D). The
example's vertices are put on an integer lattice: ``origin`` is the
lower-left corner of its bounding box and ``spacing`` the largest length ``s`` such that every
vertex is ``origin + s * (i, j)`` for integers ``i, j`` (the example's own vertices then lie on
lines, and stretched copies of the example are solutions; ``--spacing`` overrides it, and
``snap=True`` rounds vertices that are off the lattice). Every edge direction is then an
integer vector; directions equal up to sign are one family. For each family with primitive
integer normal ``n = (p, q)`` the lines are ``p x + q y = k`` for *every* integer ``k`` (in
lattice units): lines of one family are equally spaced (``s / |n|`` apart), and every lattice
point lies on a line of every family, which is Sec. 4.5.8's requirement (several families meet
where the example has a vertex of several edges) met by construction in 2D.

**Exactness.** Two lines of families ``f, g`` meet at a point with rational coordinates of
denominator ``det(n_f, n_g)``; with ``D`` the least common multiple of all these
determinants, every arrangement vertex has integer coordinates ``(X, Y) = D * (x, y)``. All
incidences (which lines pass through a vertex, consecutive vertices along a line) are integer
arithmetic, so three or more lines meeting at a point are found exactly.

**The region** is ``[0, W] x [0, H]`` in lattice units. Its sides are lines of the horizontal
and vertical families; when the example has no such edges these families are added as
*boundary-only* families with just the two side lines (the example never has an edge of their
direction, so only empty space may touch a side that is not an example direction).

Families are sorted by the angle of their direction ``d`` in ``[0, pi)``; rays are numbered
``f`` (along ``+d_f``) and ``F + f`` (along ``-d_f``), so ray numbers are in angular order.

Examples
--------
>>> lat = Lattice.of([[(0, 0), (4, 0), (2, 3)]])
>>> lat.spacing, lat.directions
(Fraction(1, 1), ((1, 0), (2, 3), (-2, 3)))
>>> A = Arrangement(lat, 4, 3)
>>> A.D, A.n_vertices > 0, sorted(set(A.edge_family.tolist()))
(12, True, [0, 1, 2, 3])
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from csplab.continuous.lattice import (
    MAX_FAMILIES,
    ArrangementGraph,
    Lattice,
    gcd_fractions,
    rational,
)
from csplab.errors import InputError

__all__ = ["LINES", "MAX_FAMILIES", "Arrangement", "Lattice", "gcd_fractions", "rational"]

#: how the lines of a family are spaced: ``lattice`` (every integer ``k``: every lattice
#: point on every family, exact copies of the example's corners anywhere) or ``equal``
#: (``k`` a multiple of the integer nearest ``|n|``: all families about one spacing apart,
#: as the 2008 paper spaces them; the example's corners then appear where those lines meet)
LINES = ("lattice", "equal")


def _lcm(a: int, b: int) -> int:
    return a * b // math.gcd(a, b)


class Arrangement(ArrangementGraph):
    """Vertices and edges of the lines of a lattice's families in a rectangular region.

    The region is ``[0, W] x [0, H]`` in lattice units; see the module docstring.

    Parameters
    ----------
    lattice : Lattice
        The example's lattice; its :meth:`~Lattice.families` give the line directions.
    W, H : int
        Width and height of the region in spacings (lattice units), each at least 1.
    lines : {"lattice", "equal"}, default "lattice"
        How the lines of a family are spaced (:data:`LINES`): a line through every lattice
        point, or lines about one spacing apart in every family.

    Attributes
    ----------
    dirs : int array ``(F, 2)``
        Family directions (angular order); ``normals`` ``(F, 2)`` is ``(dy, -dx)``.
    boundary_only : bool array ``(F,)``
    D : int
        Scale: vertex ``v`` is at ``(X[v], Y[v]) / D`` lattice units.
    X, Y : int64 arrays
        Vertices, sorted by ``(X, Y)`` (the thesis' scan order, x outermost).
    edge_src, edge_dst, edge_family : int64 arrays
        Edges, each from ``edge_src`` to ``edge_dst`` along ``+d`` of its family; consecutive
        vertices on one line.
    ray_mask : int64 array
        Bit ``f`` (ray along ``+d_f``) and bit ``F + f`` (along ``-d_f``) of each vertex.

    Raises
    ------
    InputError
        When ``W`` or ``H`` is below 1, ``lines`` is not one of :data:`LINES`, or the
        meeting points' exact coordinates (denominator ``D``) exceed 64-bit integers.
    """

    def __init__(self, lattice: Lattice, W: int, H: int, *, lines: str = "lattice") -> None:
        if W < 1 or H < 1:
            raise InputError(f"the region must be at least 1x1 spacings, not {W}x{H}")
        if lines not in LINES:
            raise InputError(f"lines must be one of {', '.join(LINES)}, not {lines!r}")
        self.lattice, self.W, self.H, self.lines = lattice, int(W), int(H), lines
        dirs, bonly = lattice.families()
        self.dirs = np.array(dirs, dtype=np.int64).reshape(-1, 2)
        self.boundary_only = np.array(bonly, dtype=bool)
        self.normals = np.stack([self.dirs[:, 1], -self.dirs[:, 0]], axis=1)
        F = self.F = len(dirs)
        # lines p x + q y = k for k a multiple of step[f]: 1 ("lattice"), or the integer
        # nearest to |n| ("equal": every family's lines about one spacing apart, Sec. 3.2)
        norm = np.hypot(self.normals[:, 0], self.normals[:, 1])
        self.step = (
            np.maximum(1, np.rint(norm)).astype(np.int64)
            if lines == "equal"
            else np.ones(F, dtype=np.int64)
        )
        D = 1
        for f in range(F):
            for g in range(f + 1, F):
                D = _lcm(D, abs(self._det(f, g)))
        self.D = D
        WD, HD = self.W * D, self.H * D
        big = max(int(np.abs(self.normals).max(initial=0)), 1)
        if (WD + 1) * (HD + 1) >= 2**62 or 2 * (W + H) * big * big * D >= 2**62:
            raise InputError(
                f"the lines of {F} families meet at points of denominator "
                f"{D if D < 10**9 else f'~10^{len(str(D)) - 1}'}: their exact coordinates in "
                f"{W}x{H} spacings exceed 64-bit integers; a larger --spacing (with --snap) "
                "gives simpler directions"
            )
        corners = np.array([[0, 0], [W, 0], [0, H], [W, H]], dtype=np.int64)
        self.k_range: list[NDArray[np.int64]] = []
        for f in range(F):
            kc = corners @ self.normals[f]
            lo, hi = int(kc.min()), int(kc.max())
            st = int(self.step[f])
            ks = np.array([lo, hi]) if bonly[f] else np.arange(-(-lo // st) * st, hi + 1, st)
            self.k_range.append(ks.astype(np.int64))
        keys = []
        for f in range(F):
            for g in range(f + 1, F):
                det = self._det(f, g)
                (pf, qf), (pg, qg) = self.normals[f], self.normals[g]
                kf, kg = np.meshgrid(self.k_range[f], self.k_range[g], indexing="ij")
                m = D // det
                X = (kf * qg - kg * qf) * m
                Y = (pf * kg - pg * kf) * m
                ok = (X >= 0) & (X <= WD) & (Y >= 0) & (Y <= HD)
                keys.append(X[ok] * (HD + 1) + Y[ok])
        key = np.unique(np.concatenate(keys))
        self.X, self.Y = key // (HD + 1), key % (HD + 1)
        nv = self.n_vertices
        # families through each vertex, and the edges along each line
        src, dst, fam = [], [], []
        mask = np.zeros(nv, dtype=np.int64)
        for f in range(F):
            p, q = self.normals[f]
            s = p * self.X + q * self.Y
            on = s % (D * int(self.step[f])) == 0
            k = s // D
            if bonly[f]:
                on = (s % D == 0) & np.isin(k, self.k_range[f])
            idx = np.flatnonzero(on)
            dx, dy = self.dirs[f]
            t = dx * self.X[idx] + dy * self.Y[idx]
            o = np.lexsort((t, k[idx]))
            idx, kk = idx[o], k[idx][o]
            same = kk[1:] == kk[:-1]
            a, b = idx[:-1][same], idx[1:][same]
            src.append(a)
            dst.append(b)
            fam.append(np.full(a.size, f, dtype=np.int64))
            mask[a] |= np.int64(1) << f
            mask[b] |= np.int64(1) << (F + f)
        self.edge_src = np.concatenate(src)
        self.edge_dst = np.concatenate(dst)
        self.edge_family = np.concatenate(fam)
        self.ray_mask = mask

    def _det(self, f: int, g: int) -> int:
        (pf, qf), (pg, qg) = self.normals[f], self.normals[g]
        return int(pf * qg - pg * qf)

    # ------------------------------------------------------------------ sizes
    @property
    def family_vectors(self) -> NDArray[np.int64]:
        """The vector naming each family: its edge direction (2D; a face normal in 3D)."""
        return self.dirs

    @property
    def size(self) -> tuple[int, int]:
        """The region ``(W, H)`` in spacings."""
        return self.W, self.H

    # ------------------------------------------------------------------ geometry
    @cached_property
    def ray_angles(self) -> NDArray[np.float64]:
        """Angle of ray ``r`` (``2F`` values, increasing)."""
        a = np.arctan2(self.dirs[:, 1], self.dirs[:, 0]).astype(np.float64)
        return np.concatenate([a, a + np.pi])

    def vertex_positions(self) -> NDArray[np.float64]:
        """Vertices in lattice units.

        Returns
        -------
        float array ``(n_vertices, 2)``
            The ``(x, y)`` of each vertex, ``(X, Y) / D``.
        """
        out: NDArray[np.float64] = np.stack([self.X, self.Y], axis=1) / self.D
        return out

    def on_side(self) -> NDArray[np.int64]:
        """The sides of the region each vertex lies on, as bits.

        Returns
        -------
        int64 array ``(n_vertices,)``
            Per vertex, bits 1 (x=0), 2 (x=W), 4 (y=0) and 8 (y=H) of the sides it lies on
            (0 for an interior vertex).
        """
        WD, HD = self.W * self.D, self.H * self.D
        out: NDArray[np.int64] = (
            (self.X == 0) * 1 + (self.X == WD) * 2 + (self.Y == 0) * 4 + (self.Y == HD) * 8
        ).astype(np.int64)
        return out

    def outside_sectors(self, rays: Sequence[int], side: int) -> tuple[bool, ...]:
        """Which sectors around a vertex on the region's sides lie outside the region.

        Parameters
        ----------
        rays : sequence of int
            The vertex's ray numbers, sorted (so in angular order).
        side : int
            The sides the vertex lies on (bits of :meth:`on_side`).

        Returns
        -------
        tuple of bool
            One per ray: whether sector ``i`` (running counter-clockwise from ray ``i`` to the
            next) lies outside the region.
        """
        ang = self.ray_angles
        out = []
        m = len(rays)
        for i in range(m):
            a = ang[rays[i]]
            b = ang[rays[(i + 1) % m]] if m > 1 else a + 2 * np.pi
            if b <= a:
                b += 2 * np.pi
            mid = 0.5 * (a + b)
            c, s = math.cos(mid), math.sin(mid)
            o = ((side & 1) and c < -1e-9) or ((side & 2) and c > 1e-9)
            o = o or ((side & 4) and s < -1e-9) or ((side & 8) and s > 1e-9)
            out.append(bool(o))
        return tuple(out)

    def edge_outside(self) -> NDArray[np.int8]:
        """Which side of each edge lies outside the region.

        Returns
        -------
        int8 array ``(n_edges,)``
            Per edge: 0 if both sides are inside, 1 if its left side is outside the region,
            2 if its right side is.
        """
        side = self.on_side()
        common = side[self.edge_src] & side[self.edge_dst]
        out = np.zeros(self.n_edges, dtype=np.int8)
        for bit, outward in ((1, (-1, 0)), (2, (1, 0)), (4, (0, -1)), (8, (0, 1))):
            sel = (common & bit) != 0
            if not sel.any():
                continue
            d = self.dirs[self.edge_family[sel]]
            left = -d[:, 1] * outward[0] + d[:, 0] * outward[1]  # left normal . outward
            out[np.flatnonzero(sel)] = np.where(left > 0, 1, 2)
        return out
