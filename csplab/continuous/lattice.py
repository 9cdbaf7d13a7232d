"""The lattice and the plane families of continuous model synthesis, in 2D and 3D alike.

Alg. 4.1 step 1 puts the example's vertices on an integer lattice: ``origin`` is the lower
corner of its bounding box and ``spacing`` the largest length ``s`` such that every vertex is
``origin + s * (i, j[, k])`` for integers (the example's own vertices then lie on the lines
or planes, and stretched copies of the example are solutions; ``spacing=`` overrides it, and
``snap=True`` rounds vertices that are off the lattice). Every edge direction (2D) or face
normal (3D) is then an integer vector; vectors equal up to sign are one *family*, and its
lines or planes are ``n . x = k`` for integers ``k`` (:mod:`~csplab.continuous.arrangement`
in 2D, :mod:`~csplab.continuous.space` in 3D).

Which families an example has is decided in one place, :func:`family_vectors`: the edge
directions of its polygons (2D), the Newell normals of its faces (3D).

Examples
--------
>>> lat = Lattice.of([[(0, 0), (4, 0), (2, 3)]])
>>> lat.ndim, lat.spacing, lat.vectors
(2, Fraction(1, 1), ((1, 0), (2, 3), (-2, 3)))
>>> tet = np.array([[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4]], dtype=float)
>>> lat = Lattice.of_points(tet, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
>>> lat.ndim, lat.spacing, lat.vectors
(3, Fraction(4, 1), ((0, 0, 1), (0, 1, 0), (1, 0, 0), (1, 1, 1)))
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray

from csplab.errors import InputError

if TYPE_CHECKING:
    from csplab.continuous.model import PolygonModel
    from csplab.continuous.polyhedra import PolyhedralModel

__all__ = [
    "DIVISIONS",
    "MAX_FAMILIES",
    "MAX_FAMILIES3",
    "MAX_SNAP_CHANGE",
    "Lattice",
    "PlaneArrangement",
    "check_snap",
    "derived_spacing",
    "family_vectors",
    "gcd_fractions",
    "primitive3",
    "rational",
]

#: most line families in 2D (rays are bits of an int64 mask, two per family)
MAX_FAMILIES = 31
#: most plane families in 3D (the central arrangement has O(F^2) cells and a neighbourhood
#: is a label per cell)
MAX_FAMILIES3 = 16
#: the largest example, in spacings, by dimension (a default spacing that is tiny because
#: coordinates share no common unit asks for ``spacing=``)
MAX_EXTENT = {2: 256, 3: 128}
_DEN = 10**6  # largest denominator when reading a float coordinate as a rational
_REL = 1e-9  # a float coordinate is that rational if within this relative distance
_SNAP_TOL = 1e-6  # a vertex is on the lattice if within this many spacings
_AXES3 = ((1, 0, 0), (0, 1, 0), (0, 0, 1))
#: a derived spacing divides the example's thinnest side into at least this many spacings
DIVISIONS = 4


#: the largest relative change of an example's area (2D) or of a solid's volume (3D) that
#: snapping may make; beyond it the example is not the one given (an icosphere of radius 1
#: snapped onto spacing 1 becomes a cube of twice its volume)
MAX_SNAP_CHANGE = 0.5


def check_snap(where: str, spacing: float, what: str, before: float, after: float) -> None:
    """Refuse (:class:`~csplab.errors.InputError`, one line) a snapped example whose
    ``what`` (an area or a volume) went from ``before`` to ``after``: collapsed to nothing,
    or changed by more than :data:`MAX_SNAP_CHANGE` of itself.

    Examples
    --------
    >>> check_snap("ball.stl", 0.5, "volume", 4.15, 4.0)      # a blocky ball: accepted
    >>> check_snap("ball.stl", 1, "volume", 4.15, 8.0)
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: ball.stl: snapping onto spacing 1 distorts it (its volume 4.15 \
becomes 8; more than 50 % changed); pass a smaller --spacing
    """
    if after <= 0 or abs(after - before) > MAX_SNAP_CHANGE * abs(before):
        how = "collapses" if after <= 0 else "distorts"
        raise InputError(
            f"{where}: snapping onto spacing {float(spacing):g} {how} it (its {what} "
            f"{before:.3g} becomes {max(after, 0.0):.3g}; more than "
            f"{MAX_SNAP_CHANGE:.0%} changed); pass a smaller --spacing".replace("%", " %")
        )


def derived_spacing(points: NDArray[np.float64]) -> float:
    """The default spacing of an example whose coordinates have no exact common unit (CAD
    floats): the smallest positive side of its bounding box divided by :data:`DIVISIONS`,
    rounded down to 1, 2 or 5 times a power of ten (its thinnest feature spans at least four
    spacings; a coarse lattice gives small integer normals, few plane families and few
    planes; ``spacing=`` overrides it).

    >>> derived_spacing(np.array([[0, 0, 0], [6, 4, 2.5]]))
    0.5
    >>> derived_spacing(np.array([[0.0, 0.0], [130.0, 45.0]]))
    10.0
    """
    ext = np.ptp(np.asarray(points, dtype=np.float64), axis=0)
    pos = ext[ext > 0]
    if not pos.size or not np.isfinite(pos).all():
        raise InputError("the example has no extent")
    x = float(pos.min()) / DIVISIONS
    e = math.floor(math.log10(x))
    for m in (5, 2, 1):
        if m * 10.0**e <= x * (1 + 1e-12):
            return float(f"{m}e{e}")
    return float(f"1e{e}")  # pragma: no cover - m = 1 always fits


def _normal_change(
    pts: NDArray[np.float64], ip: NDArray[np.int64], faces: Sequence[Sequence[int]]
) -> float:
    """The largest angle (degrees) between a polygon's Newell normal before (``pts``) and
    after snapping (lattice points ``ip``); 180 for a polygon that snapping flattened."""

    def newell(q: NDArray[np.float64]) -> NDArray[np.float64]:
        nxt = np.roll(q, -1, axis=0)
        return np.array([((q[:, 1] - nxt[:, 1]) * (q[:, 2] + nxt[:, 2])).sum(),
                         ((q[:, 2] - nxt[:, 2]) * (q[:, 0] + nxt[:, 0])).sum(),
                         ((q[:, 0] - nxt[:, 0]) * (q[:, 1] + nxt[:, 1])).sum()])  # fmt: skip

    worst = 0.0
    for poly in faces:
        a = newell(pts[list(poly)] - pts[list(poly)].mean(axis=0))
        b = newell(ip[list(poly)].astype(np.float64))
        na, nb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
        if na == 0:
            continue
        if nb == 0:
            return 180.0
        c = float(np.clip(a @ b / (na * nb), -1.0, 1.0))
        worst = max(worst, math.degrees(math.acos(c)))
    return worst


def rational(x: float) -> Fraction:
    """A float as the nearest fraction of denominator at most 10^6 (the example's
    coordinates are checked against it)."""
    return Fraction(x).limit_denominator(_DEN)


def gcd_fractions(fs: Iterable[Fraction]) -> Fraction:
    """The largest fraction of which every ``fs`` is an integer multiple (0 if all are 0).

    >>> gcd_fractions([Fraction(5, 2), Fraction(15, 2), Fraction(10)])
    Fraction(5, 2)
    """
    g = Fraction(0)
    for f in fs:
        f = abs(f)
        if f == 0:
            continue
        if g == 0:
            g = f
        else:
            lcm_den = g.denominator * f.denominator // math.gcd(g.denominator, f.denominator)
            g = Fraction(
                math.gcd(g.numerator * (lcm_den // g.denominator),
                         f.numerator * (lcm_den // f.denominator)),
                lcm_den,
            )  # fmt: skip
    return g


def _primitive2(dx: int, dy: int) -> tuple[int, int]:
    """A direction divided by its gcd, pointing into the upper half-plane (angle in
    ``[0, pi)``)."""
    g = math.gcd(dx, dy)
    dx, dy = dx // g, dy // g
    if dy < 0 or (dy == 0 and dx < 0):
        dx, dy = -dx, -dy
    return dx, dy


def angle(d: Sequence[int]) -> float:
    """The angle of a 2D direction (families are sorted by it)."""
    return math.atan2(d[1], d[0])


def primitive3(v: Sequence[int]) -> tuple[int, int, int]:
    """An integer vector divided by its gcd, its first non-zero component positive (one
    representative per plane family)."""
    a, b, c = (int(x) for x in v)
    g = math.gcd(math.gcd(a, b), c)
    a, b, c = a // g, b // g, c // g
    first = next(x for x in (a, b, c) if x != 0)
    if first < 0:
        a, b, c = -a, -b, -c
    return a, b, c


def family_vectors(
    ip: NDArray[np.int64], faces: Sequence[Sequence[int]], where: str = "<model>"
) -> tuple[tuple[int, ...], ...]:
    """The families of an example whose vertices are the integer lattice points ``ip``
    ``(n, d)``: in 2D the primitive directions of the edges of the rings ``faces`` (each a
    list of vertex indices, closed), sorted by angle; in 3D the primitive Newell normals of
    the polygons ``faces``, sorted. The one place that decides the plane families."""
    if ip.shape[1] == 2:
        dirs: set[tuple[int, int]] = set()
        for ring in faces:
            q = ip[list(ring)]
            nxt = np.roll(q, -1, axis=0)
            for (x0, y0), (x1, y1) in zip(q.tolist(), nxt.tolist(), strict=True):
                if (x0, y0) != (x1, y1):
                    dirs.add(_primitive2(x1 - x0, y1 - y0))
        if len(dirs) > MAX_FAMILIES - 2:
            raise InputError(
                f"{where}: {len(dirs)} edge directions; at most {MAX_FAMILIES - 2} are supported "
                "(use bounding shapes, Sec. 4.6.4, or a coarser spacing with snap=true)"
            )
        return tuple(sorted(dirs, key=angle))
    normals: set[tuple[int, int, int]] = set()
    for poly in faces:
        q = ip[list(poly)]
        nxt = np.roll(q, -1, axis=0)
        # Newell's normal, exact in integers (twice the area vector)
        n = (
            int(((q[:, 1] - nxt[:, 1]) * (q[:, 2] + nxt[:, 2])).sum()),
            int(((q[:, 2] - nxt[:, 2]) * (q[:, 0] + nxt[:, 0])).sum()),
            int(((q[:, 0] - nxt[:, 0]) * (q[:, 1] + nxt[:, 1])).sum()),
        )
        if n != (0, 0, 0):
            normals.add(primitive3(n))
    if len(normals | set(_AXES3)) > MAX_FAMILIES3:
        raise InputError(
            f"{where}: {len(normals)} face orientations; at most {MAX_FAMILIES3} planes "
            "families are supported (use bounding shapes, Sec. 4.6.4)"
        )
    return tuple(sorted(normals))


def _exact(pts: NDArray[np.float64], limit: int) -> bool:
    """Whether every coordinate is a rational of denominator at most 10^6 and their common
    unit spans the example in at most ``limit`` steps."""
    fr = [rational(float(v)) for v in pts.ravel().tolist()]
    if any(
        abs(float(q) - v) > _REL * max(1.0, abs(v)) for q, v in zip(fr, pts.ravel(), strict=True)
    ):
        return False
    d = pts.shape[1]
    lo = [min(fr[a::d]) for a in range(d)]
    g = gcd_fractions([f - lo[i % d] for i, f in enumerate(fr)])
    if g == 0:
        return True  # no extent: refused below with that message
    return bool(max((f - lo[i % d]) / g for i, f in enumerate(fr)) <= limit)


def _show(p: Sequence[float]) -> str:
    return "(" + ", ".join(f"{v:g}" for v in p) + ")"


@dataclass(frozen=True)
class Lattice:
    """Origin, spacing and family vectors of an example in ``d`` = 2 or 3 dimensions.

    See the module docstring; build one with :meth:`of_model`, :meth:`of_points` or
    :meth:`of`.

    Parameters
    ----------
    origin : tuple of Fraction
        The lower corner of the example's bounding box (``d`` coordinates); lattice point
        ``(i, j[, k])`` is at ``origin + spacing * (i, j[, k])``.
    spacing : Fraction
        The lattice spacing, in the example's units.
    vectors : tuple of tuple of int
        The family vectors: the edge directions (2D: primitive, angle in ``[0, pi)``, in
        angular order) or the face normals (3D: primitive, first non-zero component
        positive, sorted).
    snapped : float, default 0.0
        The largest distance (in spacings) a vertex was moved by ``snap`` (0 when exact).
    normal_change : float, default 0.0
        The largest angle (degrees) by which snapping turned a face (3D).
    derived : bool, default False
        Whether the spacing is :func:`derived_spacing` (the example had no exact unit).
    """

    origin: tuple[Fraction, ...]
    spacing: Fraction
    vectors: tuple[tuple[int, ...], ...]
    snapped: float = 0.0
    normal_change: float = 0.0
    derived: bool = False

    @property
    def ndim(self) -> int:
        """The dimension ``d``, 2 or 3."""
        return len(self.origin)

    @property
    def directions(self) -> tuple[tuple[int, ...], ...]:
        """The 2D name of :attr:`vectors` (edge directions)."""
        return self.vectors

    @property
    def normals(self) -> tuple[tuple[int, ...], ...]:
        """The 3D name of :attr:`vectors` (face normals)."""
        return self.vectors

    @classmethod
    def of_points(
        cls,
        points: NDArray[np.float64],
        faces: Sequence[Sequence[int]],
        spacing: float | None = None,
        *,
        snap: bool = False,
        max_extent: int | None = None,
        where: str = "<model>",
    ) -> Lattice:
        """The lattice of an example given as points and faces, in 2D or 3D.

        Parameters
        ----------
        points : float array ``(n, d)``
            The example's vertices, ``d`` = 2 or 3.
        faces : sequence of sequence of int
            The rings (2D, closed) or polygons (3D) of the example, as indices into
            ``points``; their edges or normals give the families (:func:`family_vectors`).
        spacing : float, optional
            The spacing; default: the largest that puts every vertex on a lattice point
            when the coordinates are exact rationals spanning at most ``max_extent`` of it
            (the built-in examples), otherwise (CAD floats) :func:`derived_spacing`, with
            the vertices snapped onto it.
        snap : bool, default False
            Accept vertices off the lattice of ``spacing`` (they are rounded onto it;
            :attr:`snapped` records how far).
        max_extent : int, optional
            The largest example size in spacings; default :data:`MAX_EXTENT` of the
            dimension.
        where : str, default "<model>"
            What the example is called in error messages.

        Returns
        -------
        Lattice
            The example's lattice.

        Raises
        ------
        InputError
            When ``spacing`` is not a positive number, a vertex has no exact rational form
            (without ``spacing``), the example has no extent, a vertex is off the lattice
            without ``snap``, the example spans more than ``max_extent`` spacings, or it has
            more families than are supported (:data:`MAX_FAMILIES`,
            :data:`MAX_FAMILIES3`).
        """
        d = int(np.shape(points)[1])
        pts = np.asarray(points, dtype=np.float64).reshape(-1, d)
        lo = pts.min(axis=0)
        limit = MAX_EXTENT[d] if max_extent is None else max_extent
        derived = False
        if spacing is None and not _exact(pts, limit):
            spacing, snap, derived = derived_spacing(pts), True, True
        if spacing is not None:
            if not (math.isfinite(spacing) and spacing > 0):
                raise InputError(f"spacing must be a positive number, not {spacing!r}")
            s = rational(float(spacing))
            origin = tuple(rational(float(v)) for v in lo)
        else:
            fr = [[rational(float(v)) for v in p] for p in pts.tolist()]
            for i, (p, f) in enumerate(zip(pts.tolist(), fr, strict=True)):
                for v, q in zip(p, f, strict=True):
                    if abs(float(q) - v) > _REL * max(1.0, abs(v)):
                        raise InputError(
                            f"{where}: vertex {i} {_show(p)} has no exact rational form; "
                            "pass a spacing (and snap=true to round vertices onto it)"
                        )
            origin = tuple(min(f[a] for f in fr) for a in range(d))
            s = gcd_fractions([f[a] - origin[a] for f in fr for a in range(d)])
            if s == 0:
                raise InputError(f"{where}: the example has no extent")
        span = float(np.ptp(pts, axis=0).max()) if pts.size else 0.0
        step = float(spacing) if spacing is not None else float(s)
        if not step > 0 or not math.isfinite(span / step) or span / step > limit:
            raise InputError(
                f"{where}: the example spans {span / step if step > 0 else math.inf:.3g} "
                f"spacings of {step:g} (more than {limit}); pass a larger spacing (with "
                "snap=true if vertices are off it)"
            )
        u = (pts - np.array([float(v) for v in origin])) / float(s)
        iu = np.rint(u)
        off = float(np.abs(u - iu).max()) if u.size else 0.0
        if off > _SNAP_TOL and not snap:
            k = int(np.abs(u - iu).max(axis=1).argmax())
            raise InputError(
                f"{where}: vertex {_show(pts[k].tolist())} is {off:.3g} spacings off the "
                f"lattice of spacing {float(s):g}; choose another spacing or snap=true"
            )
        ext = int(iu.max()) if iu.size else 0
        if ext > limit:
            raise InputError(
                f"{where}: the example spans {ext} spacings of {float(s):g} (more than "
                f"{limit}); pass a larger spacing (with snap=true if vertices are off it)"
            )
        vectors = family_vectors(iu.astype(np.int64), faces, where)
        turned = _normal_change(pts, iu.astype(np.int64), faces) if snap and d == 3 else 0.0
        return cls(origin, s, vectors, off if snap else 0.0, turned, derived)

    @classmethod
    def of(
        cls,
        rings: Sequence[Sequence[tuple[float, float]]],
        spacing: float | None = None,
        *,
        snap: bool = False,
        max_extent: int | None = None,
        where: str = "<model>",
    ) -> Lattice:
        """The lattice of a set of 2D rings (lists of points).

        Parameters
        ----------
        rings : sequence of sequence of (float, float)
            The rings, each a list of points (closed: the last joins the first).
        spacing : float, optional
            The spacing; default: derived, as in :meth:`of_points`.
        snap : bool, default False
            Round vertices that are off the lattice of ``spacing`` onto it.
        max_extent : int, optional
            The largest example size in spacings; default :data:`MAX_EXTENT` of 2D.
        where : str, default "<model>"
            What the example is called in error messages.

        Returns
        -------
        Lattice
            The rings' lattice (2D).

        Raises
        ------
        InputError
            When ``spacing`` is not a positive number, a vertex has no exact rational form
            (without ``spacing``), the example has no extent, a vertex is off the lattice
            without ``snap``, the example spans more than ``max_extent`` spacings, or it has
            more families than are supported (:data:`MAX_FAMILIES`,
            :data:`MAX_FAMILIES3`).
        """
        arrays = [np.asarray(r, dtype=np.float64).reshape(-1, 2) for r in rings]
        starts = np.cumsum([0, *(len(a) for a in arrays)])
        faces = [list(range(int(a), int(b))) for a, b in itertools.pairwise(starts)]
        pts = np.concatenate(arrays)
        return cls.of_points(pts, faces, spacing, snap=snap, max_extent=max_extent, where=where)

    @classmethod
    def of_model(
        cls,
        example: PolygonModel | PolyhedralModel,
        spacing: float | None = None,
        *,
        snap: bool = False,
    ) -> Lattice:
        """The lattice of a polygon or polyhedral model.

        It is found from the model's
        :meth:`~csplab.continuous.model.PolygonModel.indexed_faces`, by :meth:`of_points`.

        Parameters
        ----------
        example : PolygonModel or PolyhedralModel
            The example; its ``source`` names it in errors.
        spacing : float, optional
            The spacing; default: derived, as in :meth:`of_points`.
        snap : bool, default False
            Round vertices that are off the lattice of ``spacing`` onto it.

        Returns
        -------
        Lattice
            The example's lattice, of its dimension.

        Raises
        ------
        InputError
            As :meth:`of_points`: for a bad ``spacing``, a vertex off the lattice without
            ``snap``, an example too large or with too many families.
        """
        pts, faces = example.indexed_faces()
        return cls.of_points(pts, faces, spacing, snap=snap, where=example.source)

    def to_lattice(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """World coordinates to lattice coordinates.

        Parameters
        ----------
        x : float array ``(..., d)``
            Points in the example's (world) coordinates.

        Returns
        -------
        float array ``(..., d)``
            The points in lattice units, ``(x - origin) / spacing`` (floats; ``np.rint``
            them for the nearest lattice point).
        """
        o = np.array([float(v) for v in self.origin])
        out: NDArray[np.float64] = (np.asarray(x, dtype=np.float64) - o) / float(self.spacing)
        return out

    def to_world(self, u: NDArray[np.float64]) -> NDArray[np.float64]:
        """Lattice coordinates to world coordinates.

        Parameters
        ----------
        u : float array ``(..., d)``
            Points in lattice units.

        Returns
        -------
        float array ``(..., d)``
            The points in the example's coordinates, ``origin + u * spacing``.
        """
        o = np.array([float(v) for v in self.origin])
        out: NDArray[np.float64] = o + np.asarray(u, dtype=np.float64) * float(self.spacing)
        return out

    def families(self) -> tuple[tuple[tuple[int, ...], ...], tuple[bool, ...]]:
        """All families, with the axis ones the region's sides need added if missing.

        Returns
        -------
        vectors : tuple of tuple of int
            The family vectors: in 2D sorted by angle (so rays are numbered in angular
            order), in 3D the example's first, then the added axes.
        boundary_only : tuple of bool
            Per family, whether it was added for the region's sides only (the example has
            no edge or face of it).
        """
        if self.ndim == 2:
            ds = list(self.vectors)
            extra2: list[tuple[int, ...]] = [d for d in ((1, 0), (0, 1)) if d not in ds]
            allds = sorted(ds + extra2, key=angle)
            return tuple(allds), tuple(d in extra2 for d in allds)
        extra = [a for a in _AXES3 if a not in self.vectors]
        return (*self.vectors, *extra), (False,) * len(self.vectors) + (True,) * len(extra)


class ArrangementGraph:
    """What the two arrangements of :class:`PlaneArrangement` count and place alike: their
    vertices (``X``, the first coordinates times ``D``) and edges (``edge_src`` to
    ``edge_dst``), and the edge midpoints from ``vertex_positions``."""

    X: NDArray[np.int64]
    edge_src: NDArray[np.int64]
    edge_dst: NDArray[np.int64]

    @property
    def n_vertices(self) -> int:
        return int(self.X.size)

    @property
    def n_edges(self) -> int:
        return int(self.edge_src.size)

    def vertex_positions(self) -> NDArray[np.float64]:
        """Vertex coordinates ``(n_vertices, d)`` in lattice units."""
        raise NotImplementedError

    def edge_positions(self) -> NDArray[np.float64]:
        """Edge midpoints in lattice units."""
        v = self.vertex_positions()
        out: NDArray[np.float64] = 0.5 * (v[self.edge_src] + v[self.edge_dst])
        return out


class PlaneArrangement(Protocol):
    """The arrangement protocol: what the 2D arrangement of lines
    (:class:`~csplab.continuous.arrangement.Arrangement`) and the 3D arrangement of planes
    (:class:`~csplab.continuous.space.Arrangement3`) both give, in lattice units: the
    region ``size``, ``F`` families (``family_vectors``; ``boundary_only`` the axis ones
    added for the region's sides), vertices at integer coordinates divided by ``D``, edges
    between consecutive vertices of one line (``edge_src`` to ``edge_dst``), and which
    region sides each vertex lies on (``on_side``: bits ``2 * axis`` low, ``2 * axis + 1``
    high)."""

    lattice: Lattice
    F: int
    D: int
    boundary_only: NDArray[np.bool_]
    edge_src: NDArray[np.int64]
    edge_dst: NDArray[np.int64]

    @property
    def size(self) -> tuple[int, ...]: ...

    @property
    def family_vectors(self) -> NDArray[np.int64]: ...

    @property
    def n_vertices(self) -> int: ...

    @property
    def n_edges(self) -> int: ...

    def vertex_positions(self) -> NDArray[np.float64]:
        """Vertex coordinates ``(n_vertices, d)`` in lattice units."""
        ...

    def edge_positions(self) -> NDArray[np.float64]:
        """Edge midpoints ``(n_edges, d)`` in lattice units."""
        ...

    def on_side(self) -> NDArray[np.int64]:
        """Per vertex, the region sides it lies on (bit mask)."""
        ...
