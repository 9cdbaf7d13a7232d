"""`PolygonModel`: the example (and output) of continuous model synthesis (thesis Sec. 4.2).

A model is a set of closed simple polygons, holes allowed, each carrying an object label
``>= 1``; every other point of the plane is label 0 (empty space). Rings are normalised on
construction (exterior counter-clockwise, holes clockwise, no repeated closing point), and
the model is validated: at least three distinct finite points per ring, simple rings, no
zero-area part, holes inside their polygon, and no two polygons of *different* labels
overlapping (same-label polygons may overlap or touch: they are one object). Extra keys of
the JSON form are kept, per polygon and at the top level.

Examples
--------
>>> M = PolygonModel.from_json({"polygons": [
...     {"label": 1, "points": [[0, 0], [0, 2], [2, 0]]}]})       # clockwise: normalised
>>> M.polygons[0].points
((0.0, 0.0), (2.0, 0.0), (0.0, 2.0))
>>> M.labels, M.area(1)
((1,), 2.0)
>>> PolygonModel.from_json({"polygons": [
...     {"label": 1, "points": [[0, 0], [1, 1], [1, 0], [0, 1]]}]}, source="bow.json")
Traceback (most recent call last):
...
csplab.errors.InputError: bow.json: polygon 0: its boundary crosses itself (Self-intersection...
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely.geometry import Polygon as ShapelyPolygon

from csplab.continuous._parts import PartsModel
from csplab.errors import InputError

__all__ = ["Point", "Polygon", "PolygonModel", "Ring"]

Point = tuple[float, float]
Ring = tuple[Point, ...]


def _ring(raw: Any, where: str) -> Ring:
    """A ring from ``[[x, y], ...]``: finite floats, consecutive duplicates and the closing
    point dropped."""
    if not isinstance(raw, Sequence) or isinstance(raw, str | bytes):
        raise InputError(f"{where}: points must be a list of [x, y] pairs")
    pts: list[Point] = []
    for i, p in enumerate(raw):
        if not isinstance(p, Sequence) or isinstance(p, str | bytes) or len(p) != 2:
            raise InputError(f"{where}: point {i} must be [x, y], not {p!r}")
        try:
            x, y = float(p[0]), float(p[1])
        except OverflowError:
            raise InputError(f"{where}: point {i} has coordinates too large {p!r}") from None
        except (TypeError, ValueError):
            raise InputError(f"{where}: point {i} has non-numeric coordinates {p!r}") from None
        if not (math.isfinite(x) and math.isfinite(y)):
            raise InputError(f"{where}: point {i} has non-finite coordinates {p!r}")
        if not pts or pts[-1] != (x, y):
            pts.append((x, y))
    if len(pts) > 1 and pts[0] == pts[-1]:
        pts.pop()
    if len(set(pts)) < 3:
        raise InputError(f"{where}: a ring needs at least 3 distinct points, got {len(set(pts))}")
    return tuple(pts)


def _signed_area(ring: Ring) -> float:
    a = np.asarray(ring, dtype=np.float64)
    x, y = a[:, 0], a[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _oriented(ring: Ring, ccw: bool) -> Ring:
    return ring if (_signed_area(ring) > 0) == ccw else (ring[0], *ring[:0:-1])


@dataclass(frozen=True)
class Polygon:
    """One object of a polygon model: a labelled polygon, holes allowed.

    A polygon is normalised and validated when a :class:`PolygonModel` is built of it, not
    on its own.

    Parameters
    ----------
    label : int
        The object label, ``>= 1`` (0 is empty space).
    points : tuple of (float, float)
        The exterior ring, counter-clockwise, without a repeated closing point.
    holes : tuple of rings, default ()
        The hole rings, clockwise (the interior is on the left of every ring).
    extra : mapping of str to Any, default {}
        Any other keys of the JSON object, kept when written (not compared).
    """

    label: int
    points: Ring
    holes: tuple[Ring, ...] = ()
    extra: Mapping[str, Any] = field(default_factory=dict, compare=False)

    @property
    def shape(self) -> ShapelyPolygon:
        """The polygon as a shapely geometry."""
        return ShapelyPolygon(self.points, self.holes)

    def rings(self) -> Iterator[Ring]:
        """Exterior then holes; the interior is on the left of every ring."""
        yield self.points
        yield from self.holes

    def to_json(self) -> dict[str, Any]:
        """The JSON form of the polygon, its extra keys kept.

        Returns
        -------
        dict of str to Any
            ``extra``'s keys, then ``label``, ``points`` (a list of ``[x, y]``) and, if
            there are holes, ``holes`` (a list of such lists).
        """
        d: dict[str, Any] = dict(self.extra)
        d["label"] = self.label
        d["points"] = [list(p) for p in self.points]
        if self.holes:
            d["holes"] = [[list(p) for p in h] for h in self.holes]
        return d


class PolygonModel(PartsModel):
    """A labelled polygon set (see the module docstring); immutable.

    Parameters
    ----------
    polygons : sequence of Polygon or of JSON-like mappings
        May be empty (an output that is all empty space; an example needs one).
    name : str
        A short name for reports.
    meta : mapping
        Top-level extra keys (kept when written) and provenance.
    source : str
        The file (or ``"<model>"``) named in error messages.

    Raises
    ------
    InputError
        When a polygon is malformed (no points, a label not an integer ``>= 1``, a ring of
        fewer than 3 distinct finite points), a ring is flat or crosses itself, a polygon is
        invalid, or polygons of different labels overlap.
    """

    def __init__(
        self,
        polygons: Sequence[Polygon | Mapping[str, Any]],
        *,
        name: str = "",
        meta: Mapping[str, Any] | None = None,
        source: str = "<model>",
    ) -> None:
        out: list[Polygon] = []
        for i, p in enumerate(polygons):
            out.append(_polygon(p, f"{source}: polygon {i}"))
        self.polygons: tuple[Polygon, ...] = tuple(out)
        self.name = name
        self.meta: dict[str, Any] = dict(meta or {})
        self.source = source
        self._validate()

    # ------------------------------------------------------------------ construction
    @classmethod
    def _trusted(
        cls, polygons: list[Polygon], *, name: str = "", meta: Mapping[str, Any] | None = None
    ) -> PolygonModel:
        """A model from already normalised polygons, without validation (csplab's own
        outputs, which the checker verifies instead)."""
        m = cls.__new__(cls)
        m.polygons, m.name, m.meta, m.source = tuple(polygons), name, dict(meta or {}), "<model>"
        return m

    @classmethod
    def from_json(cls, data: Any, *, name: str = "", source: str = "<model>") -> PolygonModel:
        """A model from its JSON form.

        The schema is ``{"polygons": [{"label", "points", "holes"?}, ...]}``; other keys, of
        each polygon and at the top level, are kept.

        Parameters
        ----------
        data : Any
            The parsed JSON (a mapping with a ``"polygons"`` list).
        name : str, default ""
            A short name for reports; default: the data's ``"name"``, if any.
        source : str, default "<model>"
            The file named in error messages.

        Returns
        -------
        PolygonModel
            The model, normalised and validated.

        Raises
        ------
        InputError
            When ``data`` is not a mapping with a ``"polygons"`` list, or the polygons are
            not a valid model (see :class:`PolygonModel`).
        """
        if not isinstance(data, Mapping) or "polygons" not in data:
            raise InputError(f'{source}: expected an object with a "polygons" list')
        polys = data["polygons"]
        if not isinstance(polys, list):
            raise InputError(f'{source}: "polygons" must be a list')
        meta = {k: v for k, v in data.items() if k != "polygons"}
        return cls(polys, name=name or str(meta.get("name", "")), meta=meta, source=source)

    def to_json(self) -> dict[str, Any]:
        """The JSON form of the model (extra keys kept).

        Returns
        -------
        dict of str to Any
            The JSON-compatible ``meta`` keys and ``"polygons"``, a list of
            :meth:`Polygon.to_json`.
        """
        d: dict[str, Any] = {k: v for k, v in self.meta.items() if _jsonable(v)}
        d["polygons"] = [p.to_json() for p in self.polygons]
        return d

    @classmethod
    def from_shapes(
        cls, shapes: Mapping[int, Any], *, name: str = "", meta: Mapping[str, Any] | None = None
    ) -> PolygonModel:
        """A model from shapely geometries per label; empty geometries are skipped.

        Parameters
        ----------
        shapes : mapping of int to shapely geometry
            ``{label: Polygon or MultiPolygon}``, labels ``>= 1``.
        name : str, default ""
            A short name for reports.
        meta : mapping of str to Any, optional
            Top-level extra keys and provenance.

        Returns
        -------
        PolygonModel
            One polygon per (part of a) geometry, by increasing label.

        Raises
        ------
        InputError
            When the geometries are not a valid model (see :class:`PolygonModel`).
        """
        polys: list[Polygon] = []
        for label in sorted(shapes):
            for g in getattr(shapes[label], "geoms", [shapes[label]]):
                if g.is_empty:
                    continue
                polys.append(
                    Polygon(
                        int(label),
                        tuple(map(tuple, np.asarray(g.exterior.coords)[:-1].tolist())),
                        tuple(
                            tuple(map(tuple, np.asarray(h.coords)[:-1].tolist()))
                            for h in g.interiors
                        ),
                    )
                )
        return cls(polys, name=name, meta=meta)

    # ------------------------------------------------------------------ queries
    #: continuous models are planar
    ndim = 2
    #: what the model is made of, and its adjective (shared names with PolyhedralModel)
    parts = "polygons"
    kind = "polygon"

    def shape(self, label: int) -> Any:
        """The union of the polygons of one label.

        Parameters
        ----------
        label : int
            The object label.

        Returns
        -------
        shapely geometry
            The union of the polygons with ``label`` (empty if there are none).
        """
        return shapely.union_all([p.shape for p in self.polygons if p.label == label])

    def area(self, label: int | None = None) -> float:
        """The area of one label, or of all objects.

        Parameters
        ----------
        label : int, optional
            The object label; ``None`` (the default): all labels.

        Returns
        -------
        float
            The area (overlapping polygons of one label counted once).
        """
        labs = self.labels if label is None else (label,)
        return float(sum(self.shape(b).area for b in labs))

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """``(xmin, ymin, xmax, ymax)`` over all points."""
        a = np.concatenate([np.asarray(r) for p in self.polygons for r in p.rings()])
        return (float(a[:, 0].min()), float(a[:, 1].min()), float(a[:, 0].max()),
                float(a[:, 1].max()))  # fmt: skip

    def points(self) -> NDArray[np.float64]:
        """Every ring vertex of the model.

        Returns
        -------
        float array ``(n, 2)``
            The vertices of every ring (exterior then holes), polygon by polygon.
        """
        return np.concatenate([np.asarray(r, dtype=np.float64)
                               for p in self.polygons for r in p.rings()])  # fmt: skip

    def indexed_faces(self) -> tuple[NDArray[np.float64], list[list[int]]]:
        """Every ring vertex and the rings as lists of indices into them.

        This is what :meth:`Lattice.of_model <csplab.continuous.lattice.Lattice.of_model>`
        reads, as from a polyhedral model's vertices and faces.

        Returns
        -------
        points : float array ``(n, 2)``
            Every ring vertex, as :meth:`points`.
        rings : list of list of int
            Each ring (exterior then holes, polygon by polygon) as indices into ``points``.
        """
        rings = [np.asarray(r, dtype=np.float64).reshape(-1, 2) for p in self.polygons
                 for r in p.rings()]  # fmt: skip
        starts = np.cumsum([0, *(len(r) for r in rings)]).tolist()
        return np.concatenate(rings), [list(range(a, b)) for a, b in itertools.pairwise(starts)]

    @property
    def n_polygons(self) -> int:
        """The number of polygons (as :attr:`PolyhedralModel.n_polygons` counts faces)."""
        return len(self.polygons)

    # ------------------------------------------------------------------ validation
    def _validate(self) -> None:
        src = self.source
        shapes = []
        for i, p in enumerate(self.polygons):
            where = f"{src}: polygon {i}"
            for j, r in enumerate(p.rings()):
                what = "its boundary" if j == 0 else f"hole {j - 1}"
                a = np.asarray(r, dtype=np.float64)
                flat = np.linalg.matrix_rank(a - a.mean(axis=0), tol=1e-12 * _scale(r)) < 2
                if flat:
                    raise InputError(f"{where}: {what} has zero area (its points are collinear)")
                ring = shapely.LinearRing(r)
                if not ring.is_simple:
                    why = shapely.is_valid_reason(ShapelyPolygon(r))
                    raise InputError(f"{where}: {what} crosses itself ({why})")
                if abs(_signed_area(r)) <= 1e-12 * max(1.0, _scale(r)) ** 2:
                    raise InputError(f"{where}: {what} has zero area")
            g = p.shape
            if not g.is_valid:
                raise InputError(f"{where}: invalid polygon ({shapely.is_valid_reason(g)})")
            shapes.append(g)
        if len(shapes) < 2:
            return
        tree = shapely.STRtree(shapes)
        a, b = tree.query(shapes, predicate="intersects")
        for i, j in zip(a.tolist(), b.tolist(), strict=True):
            if i < j and self.polygons[i].label != self.polygons[j].label:
                inter = shapes[i].intersection(shapes[j])
                if inter.area > 1e-12 * max(1.0, shapes[i].area, shapes[j].area):
                    raise InputError(
                        f"{src}: polygons {i} (label {self.polygons[i].label}) and {j} "
                        f"(label {self.polygons[j].label}) overlap (area {inter.area:.6g})"
                    )


def _scale(r: Ring) -> float:
    a = np.asarray(r)
    return float(np.ptp(a, axis=0).max())


def _jsonable(v: Any) -> bool:
    return isinstance(v, str | int | float | bool | list | dict) or v is None


def _polygon(p: Polygon | Mapping[str, Any], where: str) -> Polygon:
    if isinstance(p, Polygon):
        raw_label: Any = p.label
        ext: Any = p.points
        holes: Any = p.holes
        extra: Mapping[str, Any] = p.extra
    elif isinstance(p, Mapping):
        if "points" not in p:
            raise InputError(f'{where}: missing "points"')
        raw_label, ext, holes = p.get("label"), p["points"], p.get("holes", [])
        extra = {k: v for k, v in p.items() if k not in ("label", "points", "holes")}
    else:
        raise InputError(f"{where}: expected an object, not {type(p).__name__}")
    if isinstance(raw_label, bool) or not isinstance(raw_label, int | np.integer):
        if isinstance(raw_label, float) and raw_label.is_integer():
            raw_label = int(raw_label)
        else:
            raise InputError(f"{where}: label must be an integer >= 1, not {raw_label!r}")
    label = int(raw_label)
    if label < 1:
        raise InputError(f"{where}: label must be >= 1 (0 is empty space), not {label}")
    from csplab.limits import check_label

    check_label(label, where)  # a picture or a file must be able to hold it
    if not isinstance(holes, Sequence) or isinstance(holes, str | bytes):
        raise InputError(f"{where}: holes must be a list of rings")
    outer = _oriented(_ring(ext, where), ccw=True)
    hs = tuple(_oriented(_ring(h, f"{where}: hole {j}"), ccw=False) for j, h in enumerate(holes))
    return Polygon(label, outer, hs, dict(extra))
