"""Compiled point location and edge splitting for the 3D checker and output geometry.

:func:`point_labels` answers "which solid contains this point" for many points at once by
casting a ray from each point in a fixed generic direction and looking at the first face
it meets: a face crossed from inside (the face's outward normal along the ray) means the
point is in that face's solid, a face crossed from outside means empty space (solids do not
overlap; two solids touching along a face give two coincident faces, and the one left
through wins). Triangles are bucketed on a grid perpendicular to the ray, so each query
looks at the triangles of one column only. The ray direction is irrational with respect to
every lattice direction, so it meets an edge exactly with probability zero; to be safe the
query is made with two directions and every point where they disagree (or that is too
close to a face) is decided by the generalised winding number instead
(:func:`labels_at`).

:func:`points_on_segments` finds the vertices lying inside each segment (T-junctions),
with the same sorted-by-x candidate search as before, compiled.

Examples
--------
>>> import numpy as np
>>> cube = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
...                  [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)
>>> quads = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
>>> tri = np.array([[cube[q[0]], cube[q[i]], cube[q[i + 1]]] for q in quads for i in (1, 2)])
>>> point_labels(np.array([[0.5, 0.5, 0.5], [2.0, 0.5, 0.5]]), [(7, tri)]).tolist()
[7, 0]
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from csplab._jit import njit, prange

__all__ = ["labels_at", "point_labels", "points_on_segments", "triangulate_rings"]

# two ray directions, irrational w.r.t. lattice directions (components of sqrt(2), sqrt(3),
# sqrt(5), sqrt(7) fractional parts), mostly upwards
_RAYS = (
    np.array([0.41421356237309515, 0.7320508075688772 * 0.5, 1.0]),
    np.array([-0.2360679774997898, 0.6457513110645907 * 0.5, -1.0]),
)


def _frame(r: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rows ``e1, e2, r/|r|``: an orthonormal frame with the ray as the third axis."""
    z = r / np.linalg.norm(r)
    a = np.eye(3)[int(np.argmin(np.abs(z)))]
    e1 = np.cross(z, a)
    e1 /= np.linalg.norm(e1)
    return np.stack([e1, np.cross(z, e1), z])


@njit(cache=True)
def _bucket(
    tri: NDArray[np.float64], x0: float, y0: float, h: float, nx: int, ny: int
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:  # pragma: no cover - compiled
    """CSR lists of the triangles whose xy bounding box meets each grid cell."""
    T = tri.shape[0]
    counts = np.zeros(nx * ny + 1, dtype=np.int64)
    lo = np.empty((T, 2), dtype=np.int64)
    hi = np.empty((T, 2), dtype=np.int64)
    for t in range(T):
        ax = min(tri[t, 0, 0], tri[t, 1, 0], tri[t, 2, 0])
        bx = max(tri[t, 0, 0], tri[t, 1, 0], tri[t, 2, 0])
        ay = min(tri[t, 0, 1], tri[t, 1, 1], tri[t, 2, 1])
        by = max(tri[t, 0, 1], tri[t, 1, 1], tri[t, 2, 1])
        lo[t, 0] = max(0, min(nx - 1, int((ax - x0) / h)))
        hi[t, 0] = max(0, min(nx - 1, int((bx - x0) / h)))
        lo[t, 1] = max(0, min(ny - 1, int((ay - y0) / h)))
        hi[t, 1] = max(0, min(ny - 1, int((by - y0) / h)))
        for i in range(lo[t, 0], hi[t, 0] + 1):
            for j in range(lo[t, 1], hi[t, 1] + 1):
                counts[i * ny + j + 1] += 1
    for c in range(nx * ny):
        counts[c + 1] += counts[c]
    fill = counts[:-1].copy()
    items = np.empty(counts[-1], dtype=np.int64)
    for t in range(T):
        for i in range(lo[t, 0], hi[t, 0] + 1):
            for j in range(lo[t, 1], hi[t, 1] + 1):
                c = i * ny + j
                items[fill[c]] = t
                fill[c] += 1
    return counts, items


@njit(cache=True, parallel=True)
def _first_hits(
    q: NDArray[np.float64],
    tri: NDArray[np.float64],
    lab: NDArray[np.int64],
    start: NDArray[np.int64],
    items: NDArray[np.int64],
    x0: float,
    y0: float,
    h: float,
    nx: int,
    ny: int,
    tol: float,
) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:  # pragma: no cover - compiled
    """Label of the first face above each point (rotated frame: the ray is +z), and
    whether the answer is doubtful (a face within ``tol`` of the point, or a hit within
    ``tol`` of a triangle's edge of another solid)."""
    P = q.shape[0]
    out = np.zeros(P, dtype=np.int64)
    doubt = np.zeros(P, dtype=np.bool_)
    for p in prange(P):
        px, py, pz = q[p, 0], q[p, 1], q[p, 2]
        i = int((px - x0) / h)
        j = int((py - y0) / h)
        if i < 0 or j < 0 or i >= nx or j >= ny:
            continue
        c = i * ny + j
        best = np.inf
        best_lab = 0
        best_up = False
        for k in range(start[c], start[c + 1]):
            t = items[k]
            ax, ay, az = tri[t, 0, 0], tri[t, 0, 1], tri[t, 0, 2]
            bx, by, bz = tri[t, 1, 0], tri[t, 1, 1], tri[t, 1, 2]
            cx, cy, cz = tri[t, 2, 0], tri[t, 2, 1], tri[t, 2, 2]
            area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
            if area == 0.0:
                continue
            w0 = (bx - px) * (cy - py) - (by - py) * (cx - px)
            w1 = (cx - px) * (ay - py) - (cy - py) * (ax - px)
            w2 = (ax - px) * (by - py) - (ay - py) * (bx - px)
            if area > 0:
                if w0 < 0 or w1 < 0 or w2 < 0:
                    continue
            elif w0 > 0 or w1 > 0 or w2 > 0:
                continue
            z = (w0 * az + w1 * bz + w2 * cz) / area
            if z <= pz + tol:
                if z > pz - tol:
                    doubt[p] = True
                continue
            up = area > 0
            if z < best - tol:
                best, best_lab, best_up = z, lab[t], up
            elif z <= best + tol:
                if up and not best_up:
                    best_lab, best_up = lab[t], True
                elif up and best_up and lab[t] != best_lab:
                    doubt[p] = True  # two solids left through at one point: overlap
                if z < best:
                    best = z
        out[p] = best_lab if best_up else 0
    return out, doubt


def _one_ray(
    points: NDArray[np.float64],
    tri: NDArray[np.float64],
    lab: NDArray[np.int64],
    r: NDArray[np.float64],
    tol: float,
) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    R = _frame(r)
    t = np.ascontiguousarray(tri @ R.T)
    q = np.ascontiguousarray(points @ R.T)
    xy = t[:, :, :2].reshape(-1, 2)
    lo = np.minimum(xy.min(axis=0), q[:, :2].min(axis=0)) - 1e-9
    hi = np.maximum(xy.max(axis=0), q[:, :2].max(axis=0)) + 1e-9
    ext = np.maximum(hi - lo, 1e-12)
    # cells of about the typical triangle's footprint, at most ~4 per triangle
    typical = float(np.median(np.ptp(t[:, :, :2], axis=1).max(axis=1))) if len(t) else 1.0
    h = max(0.5 * typical, float(np.sqrt(ext[0] * ext[1] / (8.0 * max(len(t), 1)))), 1e-12)
    nx, ny = int(ext[0] / h) + 1, int(ext[1] / h) + 1
    start, items = _bucket(t, float(lo[0]), float(lo[1]), h, nx, ny)
    return _first_hits(q, t, lab, start, items, float(lo[0]), float(lo[1]), h, nx, ny, tol)


@njit(cache=True, parallel=True)
def _solid_angles(
    p: NDArray[np.float64], tri: NDArray[np.float64]
) -> NDArray[np.float64]:  # pragma: no cover - compiled
    """Signed solid angles ``(len(p),)`` of the triangles ``tri`` ``(m, 3, 3)`` summed, seen
    from the points ``p`` (Van Oosterom & Strackee), one point per thread."""
    n, m = p.shape[0], tri.shape[0]
    out = np.zeros(n)
    for i in prange(n):
        acc = 0.0
        for j in range(m):
            ax, ay, az = tri[j, 0, 0] - p[i, 0], tri[j, 0, 1] - p[i, 1], tri[j, 0, 2] - p[i, 2]
            bx, by, bz = tri[j, 1, 0] - p[i, 0], tri[j, 1, 1] - p[i, 1], tri[j, 1, 2] - p[i, 2]
            cx, cy, cz = tri[j, 2, 0] - p[i, 0], tri[j, 2, 1] - p[i, 1], tri[j, 2, 2] - p[i, 2]
            la = np.sqrt(ax * ax + ay * ay + az * az)
            lb = np.sqrt(bx * bx + by * by + bz * bz)
            lc = np.sqrt(cx * cx + cy * cy + cz * cz)
            num = ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx)
            ab = ax * bx + ay * by + az * bz
            ac = ax * cx + ay * cy + az * cz
            bc = bx * cx + by * cy + bz * cz
            den = la * lb * lc + ab * lc + ac * lb + bc * la
            acc += 2.0 * np.arctan2(num, den)
        out[i] = acc
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
        w = _solid_angles(np.ascontiguousarray(points[inside], dtype=np.float64),
                          np.ascontiguousarray(tri, dtype=np.float64)) / (4 * np.pi)  # fmt: skip
        lab[inside[w > 0.5]] = b
    return lab


def point_labels(
    points: NDArray[np.float64], solids: Sequence[tuple[int, NDArray[np.float64]]]
) -> NDArray[np.int64]:
    """The label of the solid containing each point (0: none).

    Parameters
    ----------
    points : ndarray, shape (P, 3)
        Query points, not on any face.
    solids : sequence of (label, triangles)
        Each closed solid's outward triangles ``(m, 3, 3)``.

    Returns
    -------
    ndarray of int64, shape (P,)
    """
    pts = np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 3)
    items = [(int(b), np.asarray(t, dtype=np.float64).reshape(-1, 3, 3)) for b, t in solids]
    items = [(b, t) for b, t in items if len(t)]
    if not len(pts) or not items:
        return np.zeros(len(pts), dtype=np.int64)
    tri = np.concatenate([t for _, t in items])
    lab = np.concatenate([np.full(len(t), b, dtype=np.int64) for b, t in items])
    scale = max(1.0, float(np.abs(tri).max()), float(np.abs(pts).max()))
    tol = 1e-10 * scale
    a, da = _one_ray(pts, tri, lab, _RAYS[0], tol)
    b, db = _one_ray(pts, tri, lab, _RAYS[1], tol)
    bad = np.flatnonzero((a != b) | da | db)
    if bad.size:
        a[bad] = labels_at(pts[bad], items)
    return a


@njit(cache=True)
def _on_segments(
    a: NDArray[np.float64],
    b: NDArray[np.float64],
    vs: NDArray[np.float64],
    tol: float,
    fill: bool,
    seg: NDArray[np.int64],
    ts: NDArray[np.float64],
) -> int:  # pragma: no cover - compiled
    """Count (and with ``fill``, record) the vertices ``vs`` (sorted by x) strictly inside
    each segment ``a[k] -> b[k]``: the segment index and the parameter ``t``."""
    n = 0
    V = vs.shape[0]
    for k in range(a.shape[0]):
        px, py, pz = a[k, 0], a[k, 1], a[k, 2]
        dx, dy, dz = b[k, 0] - px, b[k, 1] - py, b[k, 2] - pz
        L2 = dx * dx + dy * dy + dz * dz
        lox, hix = min(px, b[k, 0]) - tol, max(px, b[k, 0]) + tol
        loy, hiy = min(py, b[k, 1]) - tol, max(py, b[k, 1]) + tol
        loz, hiz = min(pz, b[k, 2]) - tol, max(pz, b[k, 2]) + tol
        # binary search for the first vertex with x >= lox
        lo, hi = 0, V
        while lo < hi:
            mid = (lo + hi) // 2
            if vs[mid, 0] < lox:
                lo = mid + 1
            else:
                hi = mid
        for i in range(lo, V):
            x = vs[i, 0]
            if x > hix:
                break
            y, z = vs[i, 1], vs[i, 2]
            if y < loy or y > hiy or z < loz or z > hiz:
                continue
            t = ((x - px) * dx + (y - py) * dy + (z - pz) * dz) / L2
            if t <= 0.0 or t >= 1.0:
                continue
            ex, ey, ez = x - (px + t * dx), y - (py + t * dy), z - (pz + t * dz)
            if ex * ex + ey * ey + ez * ez > tol * tol:
                continue
            if fill:
                seg[n] = k
                ts[n] = t
            n += 1
    return n


def points_on_segments(
    a: NDArray[np.float64], b: NDArray[np.float64], verts: NDArray[np.float64], tol: float
) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """The vertices of ``verts`` strictly inside the segments ``a[k] -> b[k]`` (within
    ``tol``): parallel arrays of segment index and segment parameter ``t`` in (0, 1).

    Examples
    --------
    >>> a, b = np.array([[0.0, 0, 0]]), np.array([[2.0, 0, 0]])
    >>> k, t = points_on_segments(a, b, np.array([[1.0, 0, 0], [1, 1, 0]]), 1e-9)
    >>> k.tolist(), t.tolist()
    ([0], [0.5])
    """
    A = np.ascontiguousarray(a, dtype=np.float64).reshape(-1, 3)
    B = np.ascontiguousarray(b, dtype=np.float64).reshape(-1, 3)
    V = np.asarray(verts, dtype=np.float64).reshape(-1, 3)
    vs = np.ascontiguousarray(V[np.argsort(V[:, 0], kind="stable")])
    empty_i, empty_f = np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.float64)
    n = _on_segments(A, B, vs, float(tol), False, empty_i, empty_f)
    seg, ts = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.float64)
    if n:
        _on_segments(A, B, vs, float(tol), True, seg, ts)
    return seg, ts


@njit(cache=True)
def _earclip(
    xy: NDArray[np.int64],
    start: NDArray[np.int64],
    tris: NDArray[np.int64],
    ok: NDArray[np.bool_],
) -> None:  # pragma: no cover - compiled
    """Ear clipping of counter-clockwise integer rings (every vertex kept: collinear
    vertices are never ears, and block an ear whose triangle they touch)."""
    out = 0
    for r in range(start.shape[0] - 1):
        s, e = start[r], start[r + 1]
        n = e - s
        base = out
        ok[r] = False
        if n < 3:
            continue
        prv = np.empty(n, dtype=np.int64)
        nxt = np.empty(n, dtype=np.int64)
        for i in range(n):
            prv[i] = (i - 1) % n
            nxt[i] = (i + 1) % n
        left = n
        i = 0
        stall = 0
        good = True
        while left > 3:
            a, c = prv[i], nxt[i]
            ax, ay = xy[s + a, 0], xy[s + a, 1]
            bx, by = xy[s + i, 0], xy[s + i, 1]
            cx, cy = xy[s + c, 0], xy[s + c, 1]
            cr = (bx - ax) * (cy - by) - (by - ay) * (cx - bx)
            ear = cr > 0
            if ear:
                j = nxt[c]
                while j != a:
                    px, py = xy[s + j, 0], xy[s + j, 1]
                    same = (
                        (px == ax and py == ay)
                        or (px == bx and py == by)
                        or (px == cx and py == cy)
                    )
                    if not same:
                        # inside or on the closed triangle a, b, c (counter-clockwise)
                        d1 = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
                        d2 = (cx - bx) * (py - by) - (cy - by) * (px - bx)
                        d3 = (ax - cx) * (py - cy) - (ay - cy) * (px - cx)
                        if d1 >= 0 and d2 >= 0 and d3 >= 0:
                            ear = False
                            break
                    j = nxt[j]
            if ear:
                tris[out, 0], tris[out, 1], tris[out, 2] = s + a, s + i, s + c
                out += 1
                nxt[a], prv[c] = c, a
                left -= 1
                i = a
                stall = 0
            else:
                i = nxt[i]
                stall += 1
                if stall > left:
                    good = False
                    break
        if good:
            a, c = prv[i], nxt[i]
            ax, ay = xy[s + a, 0], xy[s + a, 1]
            bx, by = xy[s + i, 0], xy[s + i, 1]
            cx, cy = xy[s + c, 0], xy[s + c, 1]
            if (bx - ax) * (cy - by) - (by - ay) * (cx - bx) > 0:
                tris[out, 0], tris[out, 1], tris[out, 2] = s + a, s + i, s + c
                out += 1
                ok[r] = True
        if not ok[r]:
            out = base
            for k in range(n - 2):  # keep the slots of this ring aligned
                tris[base + k, 0] = -1
        out = base + n - 2


def triangulate_rings(
    xy: NDArray[np.int64], start: NDArray[np.int64]
) -> tuple[NDArray[np.int64], NDArray[np.bool_]]:
    """Triangles of simple counter-clockwise rings with integer coordinates.

    Parameters
    ----------
    xy : int64 array ``(N, 2)``
        The rings' vertices one after another.
    start : int64 array ``(R + 1,)``
        Ring ``r`` is ``xy[start[r]:start[r + 1]]``.

    Returns
    -------
    tris : int64 array ``(N - 2R, 3)``
        Positions in ``xy``, counter-clockwise; ring ``r``'s ``n - 2`` triangles follow
        ring ``r - 1``'s (rows of ``-1`` where it failed).
    ok : bool array ``(R,)``
        Rings that are not simple (or not counter-clockwise) fail.

    Examples
    --------
    >>> sq = np.array([[0, 0], [1, 0], [2, 0], [2, 1], [0, 1]])
    >>> t, ok = triangulate_rings(sq, np.array([0, 5]))
    >>> ok.tolist(), len(t), sorted({int(i) for i in t.ravel()}) == list(range(5))
    ([True], 3, True)
    """
    XY = np.ascontiguousarray(xy, dtype=np.int64).reshape(-1, 2)
    S = np.ascontiguousarray(start, dtype=np.int64)
    R = len(S) - 1
    tris = np.full((max(0, len(XY) - 2 * R), 3), -1, dtype=np.int64)
    ok = np.zeros(max(R, 0), dtype=np.bool_)
    if R > 0:
        _earclip(XY, S, tris, ok)
    return tris, ok
