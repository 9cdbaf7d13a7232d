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
from collections.abc import Collection, Iterable, Sequence
from dataclasses import dataclass, field
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
    "FIT_DEG",
    "FIT_DEGS",
    "MAX_DENOMINATOR",
    "MAX_FAMILIES",
    "MAX_FAMILIES3",
    "MAX_SNAP_CHANGE",
    "MERGE_DEG",
    "PLANES",
    "Lattice",
    "PlaneArrangement",
    "check_snap",
    "denominator",
    "derived_spacing",
    "equal_steps",
    "face_planes",
    "family_vectors",
    "gcd_fractions",
    "integer_normal",
    "plane_snap",
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
#: degrees: face normals of an example in real coordinates closer than this are one plane
#: family (near-parallel normals merged; CAD exports differ in the 4th-6th decimal)
MERGE_DEG = 1.0
#: degrees: a family's normal is snapped to the smallest integer vector this close
FIT_DEG = 2.0
#: the tolerances tried in turn (:func:`plane_snap`) until the families' planes meet at
#: points of denominator at most :data:`MAX_DENOMINATOR`
FIT_DEGS = (FIT_DEG, 3.0, 4.0, 6.0, 8.0, 12.0)
#: the largest common denominator of the points where three planes meet that snapping by
#: planes accepts (exact coordinates stay small; fine denominators make dense arrangements)
MAX_DENOMINATOR = 1000
#: how the planes of a 3D family are spaced: ``lattice`` (``n . x = k`` for every integer
#: ``k``: a family of normal ``n`` has ``|n|`` planes per spacing), ``equal`` (every
#: family's planes about one spacing apart, the 2008 paper's Sec. 3.2 "we choose to space
#: all the lines identically", through the example's own faces: :func:`equal_steps`), or
#: ``auto`` (``equal`` for an example from real coordinates, whose spacing is derived;
#: ``lattice`` for exact ones, the built-in examples)
PLANES = ("auto", "lattice", "equal")


#: the largest relative change of an example's area (2D) or of a solid's volume (3D) that
#: snapping may make; beyond it the example is not the one given (an icosphere of radius 1
#: snapped onto spacing 1 becomes a cube of twice its volume)
MAX_SNAP_CHANGE = 0.5


def open_sides(
    ground: str | Sequence[str] | None,
    order: Collection[str],
    window: tuple[str, ...],
    what: str,
) -> tuple[str, ...]:
    """The open sides of a region from a ``ground`` declaration, in ``order``: ``None``,
    ``""`` or ``"none"``: none; ``"window"``: ``window``; otherwise sides of ``order``, as a
    comma-separated string or a sequence. ``what`` names the sides in the error.

    Raises
    ------
    InputError
        For a side not in ``order``.

    Examples
    --------
    >>> open_sides("y-,x+", ("x-", "x+", "y-", "y+"), ("y-",), "sides")
    ('x+', 'y-')
    >>> open_sides("floor", ("x-", "x+"), (), "sides")
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: ground: sides are x-, x+ (or window, none), not floor
    """
    if ground is None or (isinstance(ground, str) and ground.strip() in ("", "none")):
        return ()
    if isinstance(ground, str):
        if ground.strip() == "window":
            return window
        items = [g.strip() for g in ground.split(",") if g.strip()]
    else:
        items = [str(g) for g in ground]
    bad = [g for g in items if g not in order]
    if bad:
        raise InputError(f"ground: {what} are {', '.join(order)} (or window, none), not "
                         f"{', '.join(bad)}")  # fmt: skip
    return tuple(f for f in order if f in items)


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


def face_planes(
    points: NDArray[np.float64],
    faces: Sequence[Sequence[int]],
    vectors: Sequence[Sequence[int]],
) -> dict[tuple[int, ...], list[int]]:
    """The planes of the polygons ``faces`` of an example in lattice units ``points`` (3D)
    whose faces lie on planes of the families ``vectors``: per family normal ``n``, the
    sorted distinct integers ``k`` of their planes ``n . x = k`` (each polygon's family is
    the one nearest its Newell normal).

    >>> face_planes(np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0], [0, 0, 2]]),
    ...             [[0, 2, 1], [1, 2, 3]], [(0, 0, 1), (1, 1, 1)])
    {(0, 0, 1): [0], (1, 1, 1): [2]}
    """
    V = np.array(vectors, dtype=np.float64).reshape(-1, 3)
    unit = V / np.linalg.norm(V, axis=1, keepdims=True)
    ks: dict[tuple[int, ...], set[int]] = {tuple(int(x) for x in v): set() for v in vectors}
    pts = np.asarray(points, dtype=np.float64)
    for poly in faces:
        q = pts[list(poly)]
        n = _newell(q)
        if not np.linalg.norm(n) > 0 or not len(V):
            continue
        f = int(np.argmax(np.abs(unit @ n)))
        ks[tuple(int(x) for x in vectors[f])].add(round(float(V[f] @ q.mean(axis=0))))
    return {p: sorted(k) for p, k in sorted(ks.items()) if k}


def _newell(q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The Newell normal of a polygon (twice its area vector), in floats."""
    q = q - q.mean(axis=0)
    nxt = np.roll(q, -1, axis=0)
    return np.array([((q[:, 1] - nxt[:, 1]) * (q[:, 2] + nxt[:, 2])).sum(),
                     ((q[:, 2] - nxt[:, 2]) * (q[:, 0] + nxt[:, 0])).sum(),
                     ((q[:, 0] - nxt[:, 0]) * (q[:, 1] + nxt[:, 1])).sum()])  # fmt: skip


def _angle(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    """The angle (degrees) between two lines of directions ``a`` and ``b``."""
    c = abs(float(a @ b)) / (float(np.linalg.norm(a)) * float(np.linalg.norm(b)))
    return math.degrees(math.acos(min(1.0, c)))


def denominator(vectors: Sequence[Sequence[int]]) -> int:
    """The least common multiple of ``|det|`` over every three independent integer
    normals: the points where three planes ``n . x = k`` (integer ``k``) meet have
    coordinates that are integers divided by it.

    >>> denominator([(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1), (0, 1, 2)])
    2
    """
    V = [tuple(int(x) for x in v) for v in vectors]
    out = 1
    for a, b, c in itertools.combinations(V, 3):
        det = (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
               + a[2] * (b[0] * c[1] - b[1] * c[0]))  # fmt: skip
        if det:
            out = out * abs(det) // math.gcd(out, abs(det))
    return out


def integer_normal(u: Sequence[float], tol: float = FIT_DEG) -> tuple[int, int, int]:
    """The primitive integer vector of smallest entries within ``tol`` degrees of the
    direction ``u`` (the family normal that a face of normal ``u`` is snapped to).

    >>> integer_normal([0.956, 0.292, 0.0])      # 17 degrees: (3, 1, 0) is 1.4 off
    (3, 1, 0)
    >>> integer_normal([0.0, -0.928, 0.371])
    (0, 5, -2)
    """
    v = np.asarray(u, dtype=np.float64)
    m = float(np.abs(v).max())
    best = v
    for c in range(1, 257):
        w = np.rint(c * v / m)
        if w.any() and _angle(w, v) <= tol:
            best = w
            break
        best = w
    return primitive3([int(x) for x in best])


def plane_snap(
    u: NDArray[np.float64], faces: Sequence[Sequence[int]], equal: bool
) -> tuple[NDArray[np.float64], tuple[tuple[int, int, int], ...], tuple[int, ...],
           tuple[int, ...], float] | None:  # fmt: skip
    """Snap an example given in lattice units ``u`` (floats) by its planes, not its
    vertices: face normals within :data:`MERGE_DEG` are one family (near-parallel normals
    merged), each family's normal becomes a small integer vector within :data:`FIT_DEG`
    (:func:`integer_normal`; a larger tolerance of :data:`FIT_DEGS` when the planes of
    those would meet at points of denominator over :data:`MAX_DENOMINATOR`), each face's
    plane ``n . x = k`` moves to the nearest plane of its family (every integer ``k``, or
    with ``equal`` the planes ``step`` apart, ``step`` the integer nearest ``|n|``, offset
    to fit the faces best), and each vertex to the nearest point on the planes of its
    faces.

    A vertex of more than three families (the apex of a pyramid, thesis Sec. 4.5.8) is
    pinned to its nearest lattice point and its faces' planes pass through it: planes of
    integer ``k`` meet at every lattice point, so such vertices exist in the arrangement
    (with ``equal`` planes, each family's step divides the differences of its pinned
    planes, so the periodic planes keep them).

    Returns ``(moved vertices, family normals, steps, residues, largest normal change in
    degrees)``, or ``None`` when some vertex's planes still do not meet at one point (a
    face between two pinned vertices that put it on different planes): the caller then
    rounds the vertices onto the lattice instead.
    """
    polys = [list(p) for p in faces]
    normals, areas = [], []
    for p in polys:
        n = _newell(u[p])
        normals.append(n)
        areas.append(float(np.linalg.norm(n)))
    generic = np.array([0.5773, 0.5774, 0.5775])
    reps: list[NDArray[np.float64]] = []
    cluster = [-1] * len(polys)
    for i in sorted(range(len(polys)), key=lambda i: -areas[i]):
        if areas[i] <= 0:
            continue
        n = normals[i] / areas[i]
        if n @ generic < 0:
            n = -n
        for c, r in enumerate(reps):
            if _angle(r, n) <= MERGE_DEG:
                cluster[i] = c
                reps[c] = reps[c] + n * areas[i]
                break
        else:
            cluster[i] = len(reps)
            reps.append(n * areas[i])
    # the smallest tolerance whose integer normals meet at points of a small common
    # denominator (thesis Sec. 4.5.8's second option: "modify the normals just enough so
    # that the shapes better fit on a lattice"); the change is reported
    for tol in FIT_DEGS:
        fam_of = [integer_normal((r / np.linalg.norm(r)).tolist(), tol) for r in reps]
        vectors = tuple(sorted(set(fam_of)))
        if denominator([*vectors, *(a for a in _AXES3 if a not in vectors)]) <= MAX_DENOMINATOR:
            break
    if not reps:
        return None
    N = {v: np.array(v, dtype=np.float64) for v in vectors}
    # each face's plane, and the grid of its family
    kreal: dict[tuple[int, int, int], list[tuple[int, float]]] = {v: [] for v in vectors}
    turned = 0.0
    for i, p in enumerate(polys):
        if cluster[i] < 0:
            continue
        v = fam_of[cluster[i]]
        kreal[v].append((i, float(N[v] @ u[p].mean(axis=0))))
        turned = max(turned, _angle(N[v], normals[i]))
    # Sec. 4.5.8: a vertex of more than three families is pinned to its nearest lattice
    # point, where planes of every family with integer k meet; its faces' planes go
    # through it (a face between two pinned vertices that disagree: None)
    fam_i = {i: fam_of[c] for i, c in enumerate(cluster) if c >= 0}
    vfams: list[set[tuple[int, int, int]]] = [set() for _ in range(len(u))]
    for i, p in enumerate(polys):
        if i in fam_i:
            for j in p:
                vfams[j].add(fam_i[i])
    pinned = {j: np.rint(u[j]) for j, fs in enumerate(vfams) if len(fs) > 3}
    fixed: dict[int, int] = {}
    for i, p in enumerate(polys):
        if i not in fam_i:
            continue
        for j in p:
            if j in pinned:
                k = round(float(N[fam_i[i]] @ pinned[j]))
                if fixed.setdefault(i, k) != k:
                    return None
    steps: list[int] = []
    residues: list[int] = []
    face_k: dict[int, tuple[tuple[int, int, int], int]] = {}
    for v in vectors:
        kv = np.array([kr for _, kr in kreal[v]], dtype=np.float64)
        pins = sorted({fixed[i] for i, _ in kreal[v] if i in fixed})
        if equal:
            period = 0
            for x in pins:
                period = math.gcd(period, x - pins[0])
            st = _step_near(float(np.linalg.norm(N[v])), period)
        else:
            st = 1

        def err(res: int, kv: NDArray[np.float64] = kv, st: int = st) -> float:
            return float(np.abs(kv - (np.rint((kv - res) / st) * st + res)).max())

        res = pins[0] % st if pins else min(range(st), key=err)
        steps.append(st)
        residues.append(res)
        for i, kr in kreal[v]:
            face_k[i] = (v, fixed[i] if i in fixed else round((kr - res) / st) * st + res)
    # each vertex: the nearest point on its faces' planes
    rows: list[list[tuple[tuple[int, int, int], int]]] = [[] for _ in range(len(u))]
    for i, p in enumerate(polys):
        if i in face_k:
            for j in p:
                if face_k[i] not in rows[j]:
                    rows[j].append(face_k[i])
    moved = u.astype(np.float64).copy()
    for j, row in enumerate(rows):
        if not row:
            continue
        A = np.array([N[v] for v, _ in row])
        kk = np.array([float(x) for _, x in row])
        x = u[j] + np.linalg.pinv(A) @ (kk - A @ u[j])
        if np.abs(A @ x - kk).max() > 1e-7 * max(1.0, float(np.abs(kk).max())):
            return None  # Sec. 4.5.8: these planes do not meet at one point
        moved[j] = x
    return moved, vectors, tuple(steps), tuple(residues), turned


def _step_near(target: float, period: int) -> int:
    """The divisor of ``period`` (any positive integer when ``period`` is 0) nearest to
    ``target`` in ratio, at least 1."""
    if period == 0:
        return max(1, round(target))
    divs = [d for d in range(1, math.isqrt(period) + 1) if period % d == 0]
    divs += [period // d for d in divs]
    return min(divs, key=lambda d: (abs(math.log(d / target)), d))


def equal_steps(
    ip: NDArray[np.int64], faces: Sequence[Sequence[int]], vectors: Sequence[Sequence[int]]
) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """Equal plane spacing per family (3D): the planes of family ``n`` are ``n . x = k``
    for the ``k`` with ``k % step == residue``, so ``step / |n|`` spacings apart.

    ``step`` is the integer nearest to ``|n|`` (planes one spacing apart, as the 2008 paper
    spaces its lines) among those that put every face of the example of that family on a
    plane: the divisors of the gcd of the differences of their ``k`` (any step for a
    family of one plane); ``residue`` is their ``k`` modulo ``step``. Since every example
    vertex is a lattice point on the planes of all its faces, the example's vertices where
    four or more planes meet (the pyramid apex, thesis Sec. 4.5.8) are vertices of the
    arrangement, and so is every point of the region congruent to one (the families'
    planes are periodic): Eq. 4.25 holds by construction, without solving for spacings.

    Parameters
    ----------
    ip : int array ``(n, 3)``
        The example's vertices as lattice points.
    faces : sequence of sequence of int
        Its polygons (vertex indices).
    vectors : sequence of (int, int, int)
        The families (:func:`family_vectors`).

    Returns
    -------
    steps, residues : tuple of int
        Per family of ``vectors``.

    Examples
    --------
    >>> ip = np.array([[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4]])
    >>> faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    >>> equal_steps(ip, faces, family_vectors(ip, faces))   # (1, 1, 1): 4 = 2 * 2
    ((1, 1, 1, 2), (0, 0, 0, 0))
    """
    ks: dict[tuple[int, ...], list[int]] = {tuple(v): [] for v in vectors}
    ks |= face_planes(ip.astype(np.float64), faces, vectors)
    steps, residues = [], []
    for v in vectors:
        k = ks[tuple(v)]
        period = 0
        for x in k:
            period = math.gcd(period, x - k[0])
        st = _step_near(float(np.linalg.norm(v)), period)
        steps.append(st)
        residues.append(k[0] % st if k else 0)
    return tuple(steps), tuple(residues)


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
    steps, residues : tuple of int, default ()
        3D: per family of ``vectors``, its planes are ``n . x = k`` for the ``k`` with
        ``k % step == residue`` (:func:`equal_steps`); empty: every integer ``k``
        (``lattice`` planes).
    moved : float array ``(n, 3)``, optional
        3D, snapped by planes (:func:`plane_snap`): the example's vertices (in the order
        of :meth:`~csplab.continuous.polyhedra.PolyhedralModel.indexed_faces`) moved onto
        their faces' planes, in lattice units; ``None``: snapping rounds them onto lattice
        points.
    """

    origin: tuple[Fraction, ...]
    spacing: Fraction
    vectors: tuple[tuple[int, ...], ...]
    snapped: float = 0.0
    normal_change: float = 0.0
    derived: bool = False
    steps: tuple[int, ...] = ()
    residues: tuple[int, ...] = ()
    moved: NDArray[np.float64] | None = field(default=None, compare=False, repr=False)

    @property
    def planes(self) -> str:
        """How the planes of a family are spaced: ``equal`` or ``lattice`` (:data:`PLANES`)."""
        return "equal" if self.steps else "lattice"

    def plane_steps(self) -> tuple[tuple[int, ...], tuple[int, ...]]:
        """Step and residue of every family of :meth:`families`.

        Returns
        -------
        steps, residues : tuple of int
            Per family, its planes are ``n . x = k`` with ``k % step == residue`` (1 and 0
            for the lattice planes and for the added axis families).
        """
        fams, _ = self.families()
        st = dict(zip(self.vectors, self.steps, strict=True)) if self.steps else {}
        rs = dict(zip(self.vectors, self.residues, strict=True)) if self.steps else {}
        return (tuple(st.get(v, 1) for v in fams), tuple(rs.get(v, 0) for v in fams))

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
        planes: str = "auto",
        by_planes: bool = True,
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
        planes : {"auto", "lattice", "equal"}, default "auto"
            3D: how each family's planes are spaced (:data:`PLANES`; ``auto`` is ``equal``
            when the spacing is derived, the example being in real coordinates).
        by_planes : bool, default True
            3D: snap vertices that are off the lattice by their faces' planes
            (:func:`plane_snap`: near-parallel normals merged, small integer normals) when
            those meet at every vertex; otherwise (or ``False``) round them onto lattice
            points.

        Returns
        -------
        Lattice
            The example's lattice.

        Raises
        ------
        InputError
            When ``spacing`` is not a positive number, a vertex has no exact rational form
            (without ``spacing``), the example has no extent, a vertex is off the lattice
            without ``snap``, the example spans more than ``max_extent`` spacings, it has
            more families than are supported (:data:`MAX_FAMILIES`,
            :data:`MAX_FAMILIES3`), or ``planes`` is not one of :data:`PLANES`.
        """
        if planes not in PLANES:
            raise InputError(f"planes must be one of {', '.join(PLANES)}, not {planes!r}")
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
        equal = d == 3 and (planes == "equal" or (planes == "auto" and derived))
        if d == 3 and snap and by_planes and off > _SNAP_TOL:
            ps = plane_snap(u, faces, equal)
            if ps is not None:
                moved, pvec, st, rs, pturn = ps
                if len(set(pvec) | set(_AXES3)) <= MAX_FAMILIES3:
                    move = float(np.linalg.norm(moved - u, axis=1).max())
                    return cls(origin, s, pvec, move, pturn, derived,
                               st if equal else (), rs if equal else (), moved)  # fmt: skip
        vectors = family_vectors(iu.astype(np.int64), faces, where)
        turned = _normal_change(pts, iu.astype(np.int64), faces) if snap and d == 3 else 0.0
        steps: tuple[int, ...] = ()
        residues: tuple[int, ...] = ()
        if equal:
            steps, residues = equal_steps(iu.astype(np.int64), faces, vectors)
        return cls(origin, s, vectors, off if snap else 0.0, turned, derived, steps, residues)

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
        planes: str = "auto",
        by_planes: bool = True,
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
        planes : {"auto", "lattice", "equal"}, default "auto"
            3D plane spacing per family (:data:`PLANES`).
        by_planes : bool, default True
            3D: snap by the faces' planes where they meet (:meth:`of_points`).

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
        return cls.of_points(pts, faces, spacing, snap=snap, where=example.source, planes=planes,
                             by_planes=by_planes)

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
