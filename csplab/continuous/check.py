"""The checker of continuous model synthesis: Eq. 4.1 on the polygons themselves.

:func:`violations` asks whether every point of an output model ``M`` is *locally
identical* to some point of the example ``E`` (thesis Eq. 4.1, 2008 paper Eq. 1). It works on
the two polygon sets only, independently of the arrangement and the CSP that produced ``M``
(it is the truth for tests, like :meth:`csplab.problem.Problem.violations` for grids):

1. ``E``'s edge directions, up to sign, are its *families* (equal within ``angle_tol``
   radians); an edge of ``M`` in any other direction is a violation.
2. For each model, every point where a ring has a vertex, or where a vertex of one ring lies
   on an edge of another, is a *node*; its neighbourhood is the rays of the ring edges
   through it and, between consecutive rays, the label on that side (the interior of a
   polygon is left of its rings, every other side is label 0). Points on an edge between
   nodes look like the two rays of that edge; points off the boundaries like their label.
3. Neighbourhoods are compared in reduced form (rays whose sides differ, each with the label
   after it, :func:`reduced`; the checker's own, written apart from the CSP's states); a
   node or node-side of an edge of ``M`` whose neighbourhood never occurs in ``E`` is a
   violation.

Coordinates are floats; two points are one node if they agree to ``1e-9`` of the models'
extent. Polygons with the same label are merged first (touching same-label pieces are one
object).

Examples
--------
>>> from csplab.continuous.model import Polygon, PolygonModel
>>> E = PolygonModel.from_json({"polygons": [{"label": 1, "points": [[0, 0], [4, 0], [2, 3]]}]})
>>> len(violations(E, E)), len(violations(E, PolygonModel.from_json(
...     {"polygons": [{"label": 1, "points": [[0, 0], [8, 0], [4, 6]]}]})))
(0, 0)
>>> bad = PolygonModel.from_json(                       # upside down
...     {"polygons": [{"label": 1, "points": [[0, 3], [4, 3], [2, 0]]}]})
>>> v = violations(E, bad)
>>> v.counts()
{'edge': 3, 'vertex': 3}
>>> print(v.describe(1))
6 violations of Eq. 4.1 (3 edge, 3 vertex)
  edge at (0, 3): an edge of direction 0 degrees with label 0 on its left, 1 on its right
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import shapely
from shapely.geometry.polygon import orient

from csplab.continuous.check3d import violations3
from csplab.continuous.defects import Defect, Violations
from csplab.continuous.model import Polygon, PolygonModel
from csplab.continuous.polyhedra import PolyhedralModel
from csplab.errors import InputError

__all__ = ["Defect", "Violations", "neighbourhoods", "reduced", "violations", "violations2"]

_FACES = ("z-", "z+", "x-", "x+", "y-", "y+")
#: a polygon model's sides, as ``(axis, sign)``
_SIDES = {"x-": (0, -1), "x+": (0, 1), "y-": (1, -1), "y+": (1, 1)}

#: a reduced neighbourhood: ``(ray, label after it)`` pairs, or ``((-1, label),)``
Signature = tuple[tuple[int, int], ...]

ANGLE_TOL = 1e-7
_FOREIGN = 1 << 20  # ray ids of directions the example does not have start here


def reduced(rays: list[int], sectors: list[int]) -> Signature:
    """The reduced form of a neighbourhood: the rays (in angular order) whose sector label
    ``sectors[i]`` (counter-clockwise after ``rays[i]``) differs from the one before, each
    with that label; a neighbourhood of one label everywhere is ``((-1, label),)``.

    >>> reduced([0, 1, 2, 3], [1, 1, 0, 0])
    ((0, 1), (2, 0))
    >>> reduced([0, 2], [5, 5])
    ((-1, 5),)
    """
    pairs = list(zip(rays, sectors, strict=True))
    changes = tuple(
        (int(r), int(b))
        for (r, b), (_, prev) in zip(pairs, pairs[-1:] + pairs[:-1], strict=True)
        if b != prev
    )
    return changes or ((-1, int(sectors[0]) if sectors else 0),)


class _Families:
    """The example's edge directions (angles in ``[0, pi)``), for naming rays."""

    def __init__(self, angles: list[float], tol: float) -> None:
        self.tol = tol
        angles = sorted(angles)
        fam: list[float] = []
        for a in angles:
            if not fam or a - fam[-1] > tol:
                fam.append(a)
        if len(fam) > 1 and fam[0] + math.pi - fam[-1] <= tol:
            fam.pop()
        self.angles = fam
        self.F = len(fam)
        self._foreign: dict[int, float] = {}

    def ray(self, dx: float, dy: float) -> int:
        """Ray id: ``f`` along family ``f``'s direction, ``F + f`` against it, or a foreign
        id (>= ``_FOREIGN``) for other directions (equal directions share an id)."""
        a = math.atan2(dy, dx) % (2 * math.pi)
        for f, t in enumerate(self.angles):
            for base, off in ((t, 0), (t + math.pi, self.F)):
                d = abs(a - base)
                if min(d, 2 * math.pi - d) <= self.tol:
                    return f + off
        key = round(a / self.tol)
        for k, v in self._foreign.items():
            d = abs(v - a)
            if min(d, 2 * math.pi - d) <= self.tol:
                return k
        k = _FOREIGN + int(key) % (1 << 30)
        self._foreign[k] = a
        return k

    def angle_of(self, ray: int) -> float:
        if ray >= _FOREIGN:
            return self._foreign[ray]
        return self.angles[ray % self.F] + (math.pi if ray >= self.F else 0.0)


def _edge_angles(model: PolygonModel) -> list[float]:
    out = []
    for p in model.polygons:
        for r in p.rings():
            a = np.asarray(r, dtype=np.float64)
            d = np.roll(a, -1, axis=0) - a
            out.extend((np.arctan2(d[:, 1], d[:, 0]) % np.pi).tolist())
    return [a if a < math.pi - 1e-12 else 0.0 for a in out]


def _segments(model: PolygonModel) -> tuple[np.ndarray[Any, Any], list[int]]:
    """Directed ring segments ``(m, 2, 2)`` of the per-label unions (interior on the left)
    and their labels."""
    segs, labs = [], []
    for b in model.labels:
        g = model.shape(b)
        for poly in getattr(g, "geoms", [g]):
            if poly.is_empty or poly.geom_type != "Polygon":
                continue
            poly = orient(poly, 1.0)
            for ring in (poly.exterior, *poly.interiors):
                c = np.asarray(ring.coords)[:-1]
                segs.append(np.stack([c, np.roll(c, -1, axis=0)], axis=1))
                labs.extend([b] * len(c))
    if not segs:
        return np.zeros((0, 2, 2)), []
    return np.concatenate(segs), labs


@dataclass
class _Node:
    point: tuple[float, float]
    after: dict[int, set[int]]
    before: dict[int, set[int]]


def _nodes(
    segs: np.ndarray[Any, Any], labs: list[int], fams: _Families, scale: float
) -> list[_Node]:
    if not len(segs):
        return []
    q = 1e-9 * scale
    pts = segs[:, 0]
    keys = np.rint(pts / q).astype(np.int64)
    _, first, inv = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inv = inv.reshape(-1)
    nodes = [_Node((float(pts[i, 0]), float(pts[i, 1])), {}, {}) for i in first]

    def add(n: _Node, dx: float, dy: float, label: int, side: str) -> None:
        r = fams.ray(dx, dy)
        (n.after if side == "after" else n.before).setdefault(r, set()).add(label)

    m = len(segs)
    end_node = inv[(np.arange(m) + 1) % m]
    # segments of one ring are consecutive; the end of segment i is the start of the next
    # segment of the same ring, which the key lookup below finds exactly
    end_keys = np.rint(segs[:, 1] / q).astype(np.int64)
    lookup = {
        tuple(k): int(inv[i]) for i, k in zip(first.tolist(), keys[first].tolist(), strict=True)
    }
    for i in range(m):
        (ax, ay), (bx, by) = segs[i]
        a = int(inv[i])
        b = lookup.get(tuple(end_keys[i].tolist()), int(end_node[i]))
        add(nodes[a], bx - ax, by - ay, labs[i], "after")
        add(nodes[b], ax - bx, ay - by, labs[i], "before")
    # vertices lying inside another ring's edge (T-junctions)
    lines = shapely.linestrings(segs)
    tree = shapely.STRtree(lines)
    node_pts = shapely.points(np.array([n.point for n in nodes]))
    ni, si = tree.query(node_pts, predicate="dwithin", distance=q)
    for k, s in zip(ni.tolist(), si.tolist(), strict=True):
        (ax, ay), (bx, by) = segs[s]
        px, py = nodes[k].point
        dx, dy = bx - ax, by - ay
        L2 = dx * dx + dy * dy
        t = ((px - ax) * dx + (py - ay) * dy) / L2
        length = math.sqrt(L2)
        if t * length <= q or (1 - t) * length <= q:
            continue  # an endpoint: already counted
        add(nodes[k], dx, dy, labs[s], "after")
        add(nodes[k], -dx, -dy, labs[s], "before")
    return nodes


def neighbourhoods(
    model: PolygonModel,
    fams: _Families,
    scale: float,
    segments: tuple[np.ndarray[Any, Any], list[int]] | None = None,
    within: tuple[float, float, float, float] | None = None,
) -> tuple[dict[Signature, tuple[float, float]], dict[Signature, tuple[float, float]],
           list[Defect]]:  # fmt: skip
    """Reduced neighbourhoods of ``model``'s nodes and of its edges (beside each node), each
    with one point where it occurs, and defects that are not about matching (foreign
    directions, overlapping labels); ``within`` ``(x0, y0, x1, y1)``: only nodes in that
    closed box."""
    F = fams.F
    vsig: dict[Signature, tuple[float, float]] = {}
    esig: dict[Signature, tuple[float, float]] = {}
    defects: list[Defect] = []
    segs, labs = segments if segments is not None else _segments(model)
    t = 1e-9 * scale
    for n in _nodes(segs, labs, fams, scale):
        if within is not None and not (
            within[0] - t <= n.point[0] <= within[2] + t
            and within[1] - t <= n.point[1] <= within[3] + t
        ):
            continue  # fmt: skip
        rays = sorted(set(n.after) | set(n.before))
        m = len(rays)
        sect = []
        for i in range(m):
            cand = n.after.get(rays[i], set()) | n.before.get(rays[(i + 1) % m], set())
            if len(cand) > 1:
                defects.append(Defect("label", n.point, f"labels {sorted(cand)} overlap here"))
            sect.append(min(cand) if cand else 0)
        vsig.setdefault(reduced(rays, sect), n.point)
        for i, r in enumerate(rays):
            after, before = sect[i], sect[i - 1]
            if r >= _FOREIGN:
                continue  # reported once per edge by violations()
            f = r % F
            L, R = (after, before) if r < F else (before, after)
            esig.setdefault(reduced([f, F + f], [L, R]), n.point)
    return vsig, esig, defects


def violations(
    example: PolygonModel | PolyhedralModel,
    model: PolygonModel | PolyhedralModel,
    *,
    region: Sequence[float] | None = None,
    outside: int | Mapping[str, int] = 0,
    ground: Sequence[str] = (),
) -> Violations:
    """Every place where an output of either dimension breaks Eq. 4.1 w.r.t. its example.

    :func:`violations2` checks polygon models, :func:`~csplab.continuous.check3d.violations3`
    polyhedral ones; both models must have the same dimension.

    Parameters
    ----------
    example : PolygonModel or PolyhedralModel
        The example model.
    model : PolygonModel or PolyhedralModel
        The output to check, of the example's dimension.
    region : sequence of float, optional
        The output region, ``x0, y0, x1, y1`` (2D) or ``x0, y0, z0, x1, y1, z1`` (3D); only
        points in the closed region are checked. ``None`` (the default): the whole model.
    outside : int or mapping of str to int, default 0
        The label around the region; in 3D also one per face (``{"z-": 1}``, faces not
        named being empty space, label 0).
    ground : sequence of str, default ()
        The sides (2D: ``"x-", "x+", "y-", "y+"``) or faces (3D: ``"z-"`` ...) past which
        the example (its bounding box) and the output (``region``) continue, as a synthesis
        with a ground has them.

    Returns
    -------
    Violations
        The defects found; empty means the model is a valid output.

    Raises
    ------
    InputError
        When ``outside`` is a mapping for polygon models, the two models differ in
        dimension, or a 2D ``ground`` names another side or comes without a ``region``.

    Examples
    --------
    >>> from csplab.continuous.model import PolygonModel
    >>> E = PolygonModel.from_json({"polygons": [{"label": 1, "points": [[0, 0], [1, 0],
    ...     [0, 1]]}]})
    >>> len(violations(E, E))
    0
    """
    if isinstance(example, PolygonModel) and isinstance(model, PolygonModel):
        if isinstance(outside, Mapping):
            raise InputError("a polygon model has one label outside its region, not one per face")
        r2 = None if region is None else (region[0], region[1], region[2], region[3])
        return violations2(example, model, region=r2, outside=outside, ground=ground)
    if isinstance(example, PolyhedralModel) and isinstance(model, PolyhedralModel):
        faces = outside if isinstance(outside, Mapping) else dict.fromkeys(_FACES, outside)
        r3 = None if region is None else (region[0], region[1], region[2], region[3], region[4],
                                          region[5])  # fmt: skip
        return violations3(example, model, region=r3, outside=faces, ground=ground)
    raise InputError(
        f"{model.source} is a {model.ndim}D model and the example {example.source} a "
        f"{example.ndim}D one"
    )


def violations2(
    example: PolygonModel,
    model: PolygonModel,
    *,
    angle_tol: float = ANGLE_TOL,
    region: tuple[float, float, float, float] | None = None,
    outside: int = 0,
    ground: Sequence[str] = (),
) -> Violations:
    """Every place where the polygon model ``model`` breaks Eq. 4.1 w.r.t. ``example``
    (see the module docstring); ``len() == 0`` means the model is a valid output.

    ``region`` ``(x0, y0, x1, y1)`` and ``outside``: the model fills that rectangle and
    the plane around it has label ``outside`` (a synthesis with a boundary label other than
    0); only points in the closed region are checked. ``ground``: the sides (``"x-"``,
    ``"x+"``, ``"y-"``, ``"y+"``) past which the world goes on, for the example past its
    bounding box and for the model past ``region``: each polygon touching such a side
    along an edge is extended straight across it (the label just inside continues), and
    only the example's neighbourhoods inside its box count.
    """
    bad = [g for g in ground if g not in _SIDES]
    if bad:
        raise InputError(f"ground: a polygon model has the sides {', '.join(_SIDES)}, not "
                         f"{', '.join(bad)}")  # fmt: skip
    if ground and region is None:
        raise InputError("a ground needs the output's region")
    if region is not None and outside != 0:
        x0, y0, x1, y1 = region
        m = max(x1 - x0, y1 - y0)
        ring = shapely.box(x0 - m, y0 - m, x1 + m, y1 + m).difference(
            _open_slabs(region, ground, m)
        )
        frame = [Polygon(outside, tuple(g.exterior.coords)[:-1],
                         tuple(tuple(h.coords)[:-1] for h in g.interiors))
                 for g in getattr(ring, "geoms", [ring]) if g.area > 0]  # fmt: skip
        model = PolygonModel._trusted([*model.polygons, *frame], name=model.name)
    ebox = None
    if ground:
        assert region is not None
        ebox = example.bounds
        ext = max(ebox[2] - ebox[0], ebox[3] - ebox[1], region[2] - region[0],
                  region[3] - region[1])  # fmt: skip
        example = _continued(example, (ebox[0], ebox[1], ebox[2], ebox[3]), ground, ext)
        model = _continued(model, region, ground, ext)
    lo = np.minimum(
        np.array(example.bounds[:2]), np.array(model.bounds[:2]) if len(model) else np.inf
    )
    hi = np.maximum(
        np.array(example.bounds[2:]), np.array(model.bounds[2:]) if len(model) else -np.inf
    )
    scale = float(max(1.0, np.abs(lo).max(), np.abs(hi).max(), (hi - lo).max()))
    fams = _Families(_edge_angles(example), angle_tol)
    ev, ee, _ = neighbourhoods(example, fams, scale, within=ebox)
    # on an open side, the output has what the example has on that side of its box (or
    # bare ground): its nodes there and the edges beside them
    on_side: dict[str, set[Signature]] = {}
    for g in ground:
        assert ebox is not None
        sv, se, _ = neighbourhoods(example, fams, scale, within=_side_of(ebox, g))
        on_side[g] = {((-1, 0),)} | set(sv) | set(se)
    allowed = set(ev) | set(ee) | {((-1, 0),)} | {((-1, b),) for b in example.labels}
    defects: list[Defect] = []
    for b in model.labels:
        if b not in example.labels:
            c = model.shape(b).representative_point()
            defects.append(Defect("label", (c.x, c.y), f"label {b} does not occur in the example"))
    # two labels claiming one area: found by their shapes, not by the nodes (rings that cross
    # inside edges, or a polygon inside another, have no node in the overlap)
    used = model.labels
    shapes = {b: model.shape(b) for b in used} if len(used) > 1 else {}
    for i, a in enumerate(used):
        for b in used[i + 1 :]:
            both = shapes[a].intersection(shapes[b])
            if both.area > 1e-12 * scale * scale:
                c = both.representative_point()
                defects.append(Defect("label", (c.x, c.y), f"labels [{a}, {b}] overlap here"))
    segs, labs = _segments(model)
    # only nodes in the region: a neighbourhood seen first outside it (on the frame or past
    # an open side) would otherwise hide the same one inside
    mv, me, extra = neighbourhoods(model, fams, scale, (segs, labs), within=region)
    for (ax, ay), (bx, by) in segs.tolist():
        r = fams.ray(bx - ax, by - ay)
        if r >= _FOREIGN:
            deg = math.degrees(fams.angle_of(r)) % 180
            defects.append(Defect(
                "direction", ((ax + bx) / 2, (ay + by) / 2),
                f"an edge of direction {deg:.6g} degrees, which the example does not have",
            ))  # fmt: skip
    defects.extend(extra)
    for g in ground:
        assert region is not None
        sv, se, _ = neighbourhoods(model, fams, scale, (segs, labs),
                                   within=_side_of(region, g))  # fmt: skip
        for sig, pt in {**se, **sv}.items():
            if sig not in on_side[g]:
                defects.append(Defect("ground", pt, f"a neighbourhood {_show(sig, fams)} on "
                                      f"the open side {g} that the example does not have on "
                                      "that side of its box"))  # fmt: skip
    F = fams.F
    for sig, pt in me.items():
        if sig not in allowed:
            deg = math.degrees(fams.angle_of(sig[0][0] % F)) % 180
            sides = _edge_sides(sig, F)
            defects.append(Defect(
                "edge", pt,
                f"an edge of direction {deg:.6g} degrees with label {sides[0]} on its left, "
                f"{sides[1]} on its right",
            ))  # fmt: skip
    for sig, pt in mv.items():
        if sig not in allowed and sig not in me:
            defects.append(
                Defect(
                    "vertex",
                    pt,
                    f"a vertex neighbourhood {_show(sig, fams)} that the example does not have",
                )
            )
    if region is not None:
        x0, y0, x1, y1 = region
        t = 1e-9 * scale
        defects = [d for d in defects if x0 - t <= d.point[0] <= x1 + t
                   and y0 - t <= d.point[1] <= y1 + t]  # fmt: skip
    return Violations(defects)


def _side_of(box: Sequence[float], g: str) -> tuple[float, float, float, float]:
    """The side ``g`` of ``box`` ``(x0, y0, x1, y1)``, as a box of zero width."""
    x0, y0, x1, y1 = box
    a, sgn = _SIDES[g]
    at = box[a] if sgn < 0 else box[a + 2]
    return (at, y0, at, y1) if a == 0 else (x0, at, x1, at)


def _open_slabs(box: Sequence[float], ground: Sequence[str], far: float) -> shapely.Geometry:
    """The strips past the open sides of ``box`` (across each side, as wide as the box
    and the other open sides' strips)."""
    x0, y0, x1, y1 = box
    lo = [x0 - (far if "x-" in ground else 0), y0 - (far if "y-" in ground else 0)]
    hi = [x1 + (far if "x+" in ground else 0), y1 + (far if "y+" in ground else 0)]
    out = shapely.Polygon()
    for g in ground:
        a, sgn = _SIDES[g]
        b0, b1 = list(lo), list(hi)
        if sgn < 0:
            b0[a], b1[a] = box[a] - far, box[a]
        else:
            b0[a], b1[a] = box[a + 2], box[a + 2] + far
        out = out.union(shapely.box(b0[0], b0[1], b1[0], b1[1]))
    return out


def _continued(
    model: PolygonModel, box: Sequence[float], ground: Sequence[str], far: float
) -> PolygonModel:
    """``model`` seen through the window ``box``: past each open side, every label
    touching that side along a segment goes on straight across it for ``far`` (sides in
    the order given, so a corner between two open sides takes the label at the box's
    corner)."""
    x0, y0, x1, y1 = box
    shapes = {b: model.shape(b) for b in model.labels}
    for g in ground:
        a, sgn = _SIDES[g]
        at = box[a] if sgn < 0 else box[a + 2]
        span = (y0 - far, y1 + far) if a == 0 else (x0 - far, x1 + far)
        line = (shapely.LineString([(at, span[0]), (at, span[1])]) if a == 0
                else shapely.LineString([(span[0], at), (span[1], at)]))  # fmt: skip
        for b, shp in shapes.items():
            cut = shp.intersection(line)
            rects = []
            for part in getattr(cut, "geoms", [cut]):
                if part.geom_type != "LineString" or part.length <= 0:
                    continue  # touching at a point: nothing continues
                c = np.asarray(part.coords)
                u0, u1 = float(c[:, 1 - a].min()), float(c[:, 1 - a].max())
                v0, v1 = (at - far, at) if sgn < 0 else (at, at + far)
                rects.append(shapely.box(v0, u0, v1, u1) if a == 0
                             else shapely.box(u0, v0, u1, v1))  # fmt: skip
            if rects:
                shapes[b] = shapely.union_all([shp, *rects])
    polys = []
    for b, shp in shapes.items():
        for g in getattr(shp, "geoms", [shp]):
            if g.geom_type == "Polygon" and g.area > 0:
                polys.append(Polygon(b, tuple(g.exterior.coords)[:-1],
                                     tuple(tuple(h.coords)[:-1] for h in g.interiors)))  # fmt: skip
    return PolygonModel._trusted(polys, name=model.name)


def _edge_sides(sig: Signature, F: int) -> tuple[int, int]:
    """(left, right) labels of a reduced two-ray edge neighbourhood ``((f, L), (F+f, R))``."""
    d = dict(sig)
    f = min(r for r in d) % F
    return d.get(f, 0), d.get(F + f, 0)


def _show(sig: Signature, fams: _Families) -> str:
    if sig[0][0] == -1:
        return f"[label {sig[0][1]}]"
    rays = sorted(sig, key=lambda rb: fams.angle_of(rb[0]))
    parts = [f"{math.degrees(fams.angle_of(r)):.4g}deg->{b}" for r, b in rays]
    return "[" + ", ".join(parts) + "]"
