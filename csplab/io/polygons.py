"""Polygon models (continuous model synthesis, thesis Ch. 4) as JSON, SVG and PNG files.

* JSON (format ``polygons``): ``{"polygons": [{"label": 1, "points": [[x, y], ...],
  "holes": [[[x, y], ...], ...]}, ...]}``; extra keys are kept, per polygon and at the top
  level (:class:`~csplab.continuous.model.PolygonModel`).
* SVG (format ``svg``): ``<polygon>``, ``<polyline>``, ``<rect>`` and ``<path>`` elements
  with straight segments only (``M L H V Z``, absolute or relative), in nested ``<g>`` too,
  with ``transform`` (``translate``, ``scale``, ``rotate``, ``skewX``, ``skewY``,
  ``matrix``). The label is the ``data-label`` attribute of the element or of the nearest
  enclosing element that has one, else the fill colour: distinct colours get labels 1, 2,
  ... in order of first appearance (skipping labels given explicitly); a white, ``none`` or
  transparent fill (and ``data-label="0"``) is not an object. A path's subpaths are read
  by nesting: a subpath inside an earlier polygon is a hole of it, one inside a hole of it
  is a new polygon (an island), any other a new polygon -- the even-odd rule for these
  shapes, as the writer draws them. SVG's ``y`` axis points down: ``y`` is negated on
  reading and on writing, so that the model is upright and SVG -> model -> SVG gives the
  same coordinates.
* PNG (written only): the polygons drawn in the label colours, equal aspect, ``y`` up.

Every problem with a file is one :class:`~csplab.errors.InputError` line naming the file
(a :class:`~csplab.errors.FormatError` for syntax, with the line) and the polygon or SVG
element; files are read only when regular and within
:data:`~csplab.io.common.MAX_FILE_BYTES`; files are written atomically (a temporary file in
the same folder, then renamed).

Examples
--------
>>> import tempfile, pathlib
>>> from csplab.continuous.model import PolygonModel
>>> M = PolygonModel.from_json({"polygons": [
...     {"label": 1, "points": [[0, 0], [4, 0], [4, 4], [0, 4]],
...      "holes": [[[1, 1], [1, 2], [2, 2], [2, 1]]]},
...     {"label": 2, "points": [[5, 0], [6, 0], [6, 1]]}]})
>>> with tempfile.TemporaryDirectory() as d:
...     write_svg(M, pathlib.Path(d) / "m.svg")
...     write_polygons_json(M, pathlib.Path(d) / "m.json")
...     S, J = read_svg(pathlib.Path(d) / "m.svg"), read_polygons_json(pathlib.Path(d) / "m.json")
>>> S.polygons == M.polygons == J.polygons, J.name
(True, 'm')
"""

from __future__ import annotations

import io
import json
import math
import re
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from csplab.continuous.model import Polygon, PolygonModel
from csplab.errors import FormatError, InputError
from csplab.io._json import load_json
from csplab.io._xml import Node, parse_xml
from csplab.io.common import (
    NO,
    SURE,
    exact_text,
    json_like,
    png_target,
    read_bytes,
    write_atomic,
    xml_root,
)

__all__ = [
    "read_polygons_json",
    "read_svg",
    "sniff_json",
    "sniff_svg",
    "write_png",
    "write_polygons_json",
    "write_svg",
]

Matrix = tuple[float, float, float, float, float, float]  # SVG's (a, b, c, d, e, f)
_IDENTITY: Matrix = (1.0, 0.0, 0.0, 1.0, 0.0, 0.0)


# ---------------------------------------------------------------------------- sniffing
def sniff_json(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for JSON with a ``"polygons"`` key.

    Examples
    --------
    >>> sniff_json(b'{"polygons": []}'), sniff_json(b'{"rule": []}')
    (3, 0)
    """
    return SURE if json_like(head) and b'"polygons"' in head else NO


def sniff_svg(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for XML with root ``<svg>``.

    Examples
    --------
    >>> sniff_svg(b'<?xml version="1.0"?>\\n<svg xmlns="http://www.w3.org/2000/svg"/>')
    3
    """
    root = xml_root(head)
    return SURE if root is not None and root.split(":")[-1] == "svg" else NO


# ---------------------------------------------------------------------------- files
def _model(
    polys: Sequence[Polygon | dict[str, Any]],
    *,
    data: Any = None,
    name: str,
    source: str,
    meta: dict[str, Any] | None = None,
) -> PolygonModel:
    """A validated model; number overflows and geometry-engine failures become one line."""
    try:
        if data is not None:
            return PolygonModel.from_json(data, name=name, source=source)
        return PolygonModel(polys, name=name, meta=meta, source=source)
    except InputError:
        raise
    except (OverflowError, ValueError, TypeError, shapely.errors.GEOSException) as e:
        # numbers too large for the geometry (e.g. squares of 1e300), engine failures
        raise InputError(f"{source}: cannot build the polygon model ({e})") from None


# ---------------------------------------------------------------------------- JSON
def read_polygons_json(path: str | Path) -> PolygonModel:
    """A polygon model from a JSON file (the schema of the module docstring).

    Parameters
    ----------
    path : str or Path
        The JSON file to read.

    Returns
    -------
    PolygonModel
        The polygons with their labels and holes (extra keys kept); its name is the file's
        stem unless the file has a ``"name"``.

    Raises
    ------
    FormatError
        Naming the file (and the line) when it cannot be read, is larger than
        :data:`~csplab.io.common.MAX_FILE_BYTES` or is not valid JSON.
    InputError
        One line naming the file and the polygon when the data do not make a polygon model
        (a missing key, a bad label, a ring of fewer than 3 distinct points, an invalid
        polygon ...).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = pathlib.Path(d) / "bad.json"
    ...     _ = p.write_text('{"polygons": [{"label": 1, "points": [[0, 0], [1, 0]]}]}')
    ...     read_polygons_json(p)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: .../bad.json: polygon 0: a ring needs at least 3 distinct \
points, got 2
    """
    p = Path(path)
    data = load_json(read_bytes(p), path=p)
    m = _model((), data=data, name="", source=str(p))
    if not m.name:
        m.name = p.stem
    return m


def _pts(ring: Sequence[tuple[float, float]]) -> str:
    return "[" + ", ".join(f"[{exact_text(x)}, {exact_text(y)}]" for x, y in ring) + "]"


def write_polygons_json(model: PolygonModel, path: str | Path) -> None:
    """Write ``model`` as JSON (atomically).

    Top-level keys one per line, one polygon per line, numbers exact (so the file reads
    back as the same model).

    Parameters
    ----------
    model : PolygonModel
        The polygons (may be empty).
    path : str or Path
        The ``.json`` file (written to a temporary file in the same folder, then renamed).

    Raises
    ------
    InputError
        Naming the file when it cannot be written.
    """
    p = Path(path)
    d = model.to_json()
    lines = [f"  {json.dumps(k)}: {json.dumps(v)}," for k, v in d.items() if k != "polygons"]
    polys: list[str] = []
    for poly, raw in zip(model.polygons, d["polygons"], strict=True):
        items = [f'"label": {poly.label}', f'"points": {_pts(poly.points)}']
        if poly.holes:
            items.append(f'"holes": [{", ".join(_pts(h) for h in poly.holes)}]')
        items += [f"{json.dumps(k)}: {json.dumps(v)}" for k, v in raw.items()
                  if k not in ("label", "points", "holes")]  # fmt: skip
        polys.append("    {" + ", ".join(items) + "}")
    body = "[]" if not polys else "[\n" + ",\n".join(polys) + "\n  ]"
    text = "{\n" + "\n".join(lines) + ("\n" if lines else "") + f'  "polygons": {body}\n}}\n'
    write_atomic(p, text.encode("utf-8"))


# ---------------------------------------------------------------------------- SVG in
_SKIP = {"defs", "clippath", "mask", "symbol", "pattern", "marker", "style", "title", "desc",
         "metadata", "lineargradient", "radialgradient", "filter", "text"}  # fmt: skip
_SHAPES = {"polygon", "polyline", "rect", "path", "circle", "ellipse", "line", "use", "image"}
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_PATH_TOKEN = re.compile(rf"\s*,?\s*([A-Za-z]|{_NUMBER})")
_TRANSFORM = re.compile(r"\s*,?\s*([A-Za-z]+)\s*\(([^)]*)\)")
_NOT_OBJECT = {"none", "transparent", "#ffffff", "#fff", "white"}


class _Element:
    """Where an SVG shape came from, for messages."""

    def __init__(self, path: Path, index: int | None, node: Node) -> None:
        at = f"element {index} (<{_tag(node)}>, line {node.line})"
        self.where = f"{path}: " + (
            at if index is not None else f"<{_tag(node)}>, line {node.line}"
        )

    def error(self, what: str) -> InputError:
        return InputError(f"{self.where}: {what}")


def _tag(node: Node) -> str:
    return node.tag.rsplit(":", 1)[-1].lower()


def _numbers(text: str, el: _Element, what: str) -> list[float]:
    parts = [t for t in re.split(r"[\s,]+", text.strip()) if t]
    try:
        out = [float(t) for t in parts]
    except ValueError:
        raise el.error(f"{what} must be numbers, not {text[:40]!r}") from None
    if not all(math.isfinite(v) for v in out):
        raise el.error(f"{what} has non-finite numbers")
    return out


def _length(node: Node, key: str, el: _Element, default: float | None = None) -> float:
    v = node.get(key)
    if v is None:
        if default is None:
            raise el.error(f"missing attribute {key}")
        return default
    text = v.strip()
    if text.endswith("px"):
        text = text[:-2]
    try:
        f = float(text)
    except ValueError:
        raise el.error(f"{key}={v!r} must be a number (user units or px)") from None
    if not math.isfinite(f):
        raise el.error(f"{key}={v!r} is not finite")
    return f


def _mul(m: Matrix, n: Matrix) -> Matrix:
    a, b, c, d, e, f = m
    a2, b2, c2, d2, e2, f2 = n
    return (a * a2 + c * b2, b * a2 + d * b2, a * c2 + c * d2, b * c2 + d * d2,
            a * e2 + c * f2 + e, b * e2 + d * f2 + f)  # fmt: skip


def _matches(
    pattern: re.Pattern[str], text: str, el: _Element, error: Callable[[int], str]
) -> Iterator[re.Match[str]]:
    """The matches of ``pattern`` one after another through ``text``, up to where only
    separators (white space, commas) are left; ``el.error(error(pos))`` at anything else."""
    pos = 0
    while pos < len(text):
        hit = pattern.match(text, pos)
        if hit is None:
            if text[pos:].strip(" ,\t\r\n") == "":
                return
            raise el.error(error(pos))
        yield hit
        pos = hit.end()


def _transform(text: str, el: _Element) -> Matrix:
    """The matrix of an SVG ``transform`` list."""
    m = _IDENTITY
    text = text.strip()
    for hit in _matches(_TRANSFORM, text, el, lambda pos: f"cannot read transform {text!r}"):
        kind, args = hit.group(1), _numbers(hit.group(2), el, f"transform {hit.group(1)}")
        n = len(args)
        t: Matrix
        if kind == "matrix" and n == 6:
            t = (args[0], args[1], args[2], args[3], args[4], args[5])
        elif kind == "translate" and n in (1, 2):
            t = (1.0, 0.0, 0.0, 1.0, args[0], args[1] if n == 2 else 0.0)
        elif kind == "scale" and n in (1, 2):
            t = (args[0], 0.0, 0.0, args[1] if n == 2 else args[0], 0.0, 0.0)
        elif kind == "rotate" and n in (1, 3):
            r = math.radians(args[0])
            cs, sn = math.cos(r), math.sin(r)
            t = (cs, sn, -sn, cs, 0.0, 0.0)
            if n == 3:
                cx, cy = args[1], args[2]
                t = _mul(_mul((1.0, 0.0, 0.0, 1.0, cx, cy), t), (1.0, 0.0, 0.0, 1.0, -cx, -cy))
        elif kind == "skewX" and n == 1:
            t = (1.0, 0.0, math.tan(math.radians(args[0])), 1.0, 0.0, 0.0)
        elif kind == "skewY" and n == 1:
            t = (1.0, math.tan(math.radians(args[0])), 0.0, 1.0, 0.0, 0.0)
        else:
            raise el.error(
                f"unsupported transform {kind}({hit.group(2).strip()}); use translate, scale, "
                "rotate, skewX, skewY or matrix"
            )
        m = _mul(m, t)
    return m


def _path_rings(d: str, el: _Element) -> list[list[tuple[float, float]]]:
    """The subpaths of path data with straight segments only."""
    tokens = [
        hit.group(1)
        for hit in _matches(
            _PATH_TOKEN, d, el, lambda p: f"cannot read path data near {d[p : p + 20]!r}"
        )
    ]
    rings: list[list[tuple[float, float]]] = []
    cur: list[tuple[float, float]] = []
    x = y = 0.0
    start = (0.0, 0.0)
    cmd = ""
    i = 0

    def num() -> float:
        nonlocal i
        if i >= len(tokens) or tokens[i].isalpha():
            raise el.error(f"path command {cmd} is missing numbers")
        v = float(tokens[i])
        if not math.isfinite(v):
            raise el.error("path data has non-finite numbers")
        i += 1
        return v

    while i < len(tokens):
        tok = tokens[i]
        if tok.isalpha():
            i += 1
            if tok in "CcSsQqTtAa":
                raise el.error(
                    f"path command {tok} draws a curve; only straight segments are supported "
                    "(M, L, H, V, Z)"
                )
            if tok not in "MmLlHhVvZz":
                raise el.error(f"unknown path command {tok!r}")
            if not cmd and tok not in "Mm":
                raise el.error("path data must start with a move-to command (M or m)")
            cmd = tok
            if cmd in "Zz":
                if cur:
                    rings.append(cur)
                cur = []
                x, y = start
                continue
        elif not cmd:
            raise el.error("path data must start with a move-to command (M or m)")
        elif cmd in "Zz":
            raise el.error(f"numbers after the close-path command {cmd}")
        if cmd in "Mm":
            nx, ny = num(), num()
            if cmd == "m" and (cur or rings):
                nx, ny = x + nx, y + ny
            if cur:
                rings.append(cur)
            x, y = nx, ny
            start = (x, y)
            cur = [(x, y)]
            cmd = "l" if cmd == "m" else "L"  # later pairs are line-tos
            continue
        if not cur:
            cur = [(x, y)]
            start = (x, y)
        if cmd == "L":
            x, y = num(), num()
        elif cmd == "l":
            dx, dy = num(), num()
            x, y = x + dx, y + dy
        elif cmd == "H":
            x = num()
        elif cmd == "h":
            x += num()
        elif cmd == "V":
            y = num()
        elif cmd == "v":
            y += num()
        cur.append((x, y))
    if cur:
        rings.append(cur)
    return rings


def _contains(outer: Sequence[tuple[float, float]], ring: Sequence[tuple[float, float]]) -> bool:
    """Whether every point of ``ring`` is in the polygon bounded by ``outer``."""
    try:
        poly = shapely.Polygon(outer)
        return bool(np.all(shapely.covers(poly, shapely.points(np.asarray(ring)))))
    except (ValueError, shapely.errors.GEOSException):
        return False


def _nest(
    rings: list[list[tuple[float, float]]],
) -> list[tuple[list[tuple[float, float]], list[list[tuple[float, float]]]]]:
    """Subpaths as (exterior, holes): see the module docstring."""
    out: list[tuple[list[tuple[float, float]], list[list[tuple[float, float]]]]] = []
    for r in rings:
        for ext, holes in out:
            if _contains(ext, r):
                if not any(_contains(h, r) for h in holes):
                    holes.append(r)
                    break
        else:
            out.append((r, []))
    return out


def _colour(text: str) -> str | None:
    """A fill as ``#rrggbb`` (``None``: not an object)."""
    from PIL import ImageColor

    t = text.strip().lower()
    if t in _NOT_OBJECT or t.startswith("url("):
        return None if t in _NOT_OBJECT else t
    try:
        rgb = ImageColor.getrgb(t)
    except ValueError:
        return t  # an unknown colour is still a colour: it gets a label
    if len(rgb) == 4 and rgb[3] == 0:
        return None
    hexa = "#{:02x}{:02x}{:02x}".format(*rgb[:3])
    return None if hexa == "#ffffff" else hexa


def _style(node: Node, key: str) -> str | None:
    style = node.get("style") or ""
    for item in style.split(";"):
        k, _, v = item.partition(":")
        if k.strip().lower() == key:
            return v.strip()
    return node.get(key)


def _walk(root: Node, path: Path) -> Iterator[tuple[Node, Matrix, str | None, str | None]]:
    """Elements in document order with their matrix (``transform`` applied), the inherited
    ``data-label`` and fill (iterative: deep nesting cannot overflow the stack); a bad
    transform of a non-shape element names its tag and line."""
    stack: list[tuple[Node, Matrix, str | None, str | None]] = [(root, _IDENTITY, None, None)]
    shapes = 0  # the index of the next shape element (as read_svg counts them)
    while stack:
        node, m, label, fill = stack.pop()
        tag = _tag(node)
        if tag in _SKIP:
            continue
        label = node.get("data-label", label)
        fill = _style(node, "fill") or fill
        t = node.get("transform")
        if t is not None:
            idx = shapes if tag in _SHAPES else None
            m = _mul(m, _transform(t, _Element(path, idx, node)))
        shapes += tag in _SHAPES
        yield node, m, label, fill
        stack.extend((c, m, label, fill) for c in reversed(node.children))


def read_svg(path: str | Path) -> PolygonModel:
    """A polygon model from the shapes of an SVG file (see the module docstring).

    Parameters
    ----------
    path : str or Path
        The ``.svg`` file to read.

    Returns
    -------
    PolygonModel
        One polygon per closed shape (holes by nesting), labelled by ``data-label`` or by
        fill colour (the colours kept in ``meta["colors"]``), ``y`` pointing up.

    Raises
    ------
    FormatError
        Naming the file (and the line) when it cannot be read, is larger than
        :data:`~csplab.io.common.MAX_FILE_BYTES`, is not XML or its root is not ``<svg>``.
    InputError
        One line naming the file and the element when a shape cannot be read (curves,
        arcs, circles, a bad ``transform``, an invalid polygon ...).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = pathlib.Path(d) / "c.svg"
    ...     _ = p.write_text('<svg><rect width="2" height="1" fill="red"/>'
    ...                      '<path d="M 3 0 C 4 0 4 1 3 1 Z"/></svg>')
    ...     read_svg(p)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: .../c.svg: element 1 (<path>, line 1): path command C draws \
a curve; only straight segments are supported (M, L, H, V, Z)
    """
    p = Path(path)
    root = parse_xml(read_bytes(p), path=p)
    if _tag(root) != "svg":
        raise FormatError(f"the root element is <{root.tag}>, not <svg>", path=p, line=root.line)
    found: list[tuple[_Element, int | None, str | None, list[list[tuple[float, float]]]]] = []
    index = 0
    for node, m, label, fill in _walk(root, p):
        tag = _tag(node)
        el = _Element(p, index, node)
        if tag not in _SHAPES:
            continue
        index += 1
        if tag in ("circle", "ellipse"):
            raise el.error(f"<{tag}> is a curve; only straight segments are supported")
        if tag in ("line", "use", "image"):
            continue  # no area (a line), or not a shape of this file
        lab: int | None = None
        if label is not None:
            try:
                lab = int(label.strip())
            except ValueError:
                raise el.error(f"data-label={label!r} must be an integer >= 0") from None
            if lab < 0:
                raise el.error(f"data-label={label!r} must be an integer >= 0")
            if lab == 0:
                continue
        colour = _colour(fill) if fill is not None else "#000000"  # SVG's default fill
        if lab is None and colour is None:
            continue
        if tag in ("polygon", "polyline"):
            v = _numbers(node.get("points") or "", el, "points")
            if len(v) % 2:
                raise el.error("points must be x,y pairs (an odd count of numbers)")
            rings = [list(zip(v[0::2], v[1::2], strict=True))]
        elif tag == "rect":
            x, y = _length(node, "x", el, 0.0), _length(node, "y", el, 0.0)
            w, h = _length(node, "width", el), _length(node, "height", el)
            if w <= 0 or h <= 0:
                raise el.error(f"width {w:g} and height {h:g} must be > 0")
            if _length(node, "rx", el, 0.0) > 0 or _length(node, "ry", el, 0.0) > 0:
                raise el.error("rounded corners (rx, ry) are curves; only straight segments "
                               "are supported")  # fmt: skip
            rings = [[(x, y), (x + w, y), (x + w, y + h), (x, y + h)]]
        else:
            rings = _path_rings(node.get("d") or "", el)
        a, b, c, d, e, f = m
        moved = [
            [(a * px + c * py + e + 0.0, 0.0 - (b * px + d * py + f)) for px, py in r]
            for r in rings
        ]
        if not all(math.isfinite(v) for r in moved for pt in r for v in pt):
            raise el.error("the transform makes coordinates non-finite")
        found.append((el, lab, colour, moved))
    explicit = {lab for _, lab, _, _ in found if lab is not None}
    by_colour: dict[str, int] = {}
    nxt = 1
    polys: list[Polygon | dict[str, Any]] = []
    origin: list[str] = []
    colours: dict[str, str] = {}
    for el, lab, colour, rings in found:
        if lab is None:
            assert colour is not None
            if colour not in by_colour:
                while nxt in explicit:
                    nxt += 1
                by_colour[colour] = nxt
                nxt += 1
            lab = by_colour[colour]
        if colour is not None and colour.startswith("#"):
            colours.setdefault(str(lab), colour)
        for ext, holes in _nest(rings):
            polys.append({"label": lab, "points": ext, "holes": holes})
            origin.append(el.where.split(": ", 1)[1])
    meta = {"colors": colours} if colours else {}
    try:
        return _model(polys, name=p.stem, source=str(p), meta=meta)
    except InputError as err:
        raise InputError(_with_elements(str(err), origin)) from None


def _with_elements(msg: str, origin: list[str]) -> str:
    """``msg`` with each polygon index followed by the SVG element it came from."""

    def sub(hit: re.Match[str]) -> str:
        i = int(hit.group(2))
        return f"{hit.group(0)} [{origin[i]}]" if i < len(origin) else hit.group(0)

    return re.sub(r"(polygons?|and) (\d+)\b", sub, msg, count=2)


# ---------------------------------------------------------------------------- SVG out
def _colours(model: PolygonModel) -> dict[int, tuple[int, int, int]]:
    """A colour per label: the model's own (``meta["colors"]``, from an SVG), else
    :func:`csplab.render.palette`."""
    from csplab.render import palette

    K = max(model.labels, default=0) + 1
    pal = palette(K)
    own = model.meta.get("colors") if isinstance(model.meta.get("colors"), dict) else {}
    out: dict[int, tuple[int, int, int]] = {}
    for b in model.labels:
        c = own.get(str(b)) if own else None
        if isinstance(c, str) and re.fullmatch(r"#[0-9a-fA-F]{6}", c):
            out[b] = (int(c[1:3], 16), int(c[3:5], 16), int(c[5:7], 16))
        else:
            out[b] = (int(pal[b][0]), int(pal[b][1]), int(pal[b][2]))
    return out


def _bounds(model: PolygonModel) -> tuple[float, float, float, float]:
    return model.bounds if model.polygons else (0.0, 0.0, 1.0, 1.0)


def write_svg(
    model: PolygonModel, path: str | Path, *, example: PolygonModel | None = None
) -> None:
    """Write ``model`` as SVG (atomically): one ``<path>`` per polygon (exterior and holes,
    ``fill-rule="evenodd"``) with its ``data-label`` and label colour, ``y`` negated (see
    the module docstring), a ``viewBox`` around the bounds and a thin stroke.

    Parameters
    ----------
    model : PolygonModel
        The polygons (may be empty).
    path : str or Path
        The ``.svg`` file.
    example : PolygonModel, optional
        The example the model was synthesised from: its colours (``meta["colors"]``) are
        used when ``model`` has none, so outputs look like their example.
    """
    p = Path(path)
    cols = _colours(model)
    if example is not None and not model.meta.get("colors"):
        ex = _colours(example)
        cols = {b: ex.get(b, c) for b, c in cols.items()}
    x0, y0, x1, y1 = _bounds(model)
    span = max(x1 - x0, y1 - y0, 1e-9)
    pad = 0.02 * span
    vb = [x0 - pad, -y1 - pad, x1 - x0 + 2 * pad, y1 - y0 + 2 * pad]
    stroke = 0.002 * span
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        '<svg xmlns="http://www.w3.org/2000/svg" '
        f'viewBox="{" ".join(exact_text(float(v)) for v in vb)}">',
    ]
    if model.name:
        lines.append(f"  <title>{_escape(model.name)}</title>")
    for poly in model.polygons:
        d = " ".join(
            "M " + " L ".join(f"{exact_text(x)} {exact_text(-y)}" for x, y in ring) + " Z"
            for ring in poly.rings()
        )
        r, g, b = cols[poly.label]
        lines.append(
            f'  <path data-label="{poly.label}" d="{d}" fill="#{r:02x}{g:02x}{b:02x}" '
            f'fill-rule="evenodd" stroke="#000000" stroke-width="{exact_text(stroke)}"/>'
        )
    lines.append("</svg>")
    write_atomic(p, ("\n".join(lines) + "\n").encode("utf-8"))


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


# ---------------------------------------------------------------------------- PNG out
def write_png(model: PolygonModel, path: str | Path, *, size_px: int = 512) -> None:
    """Draw ``model`` as a PNG (atomically).

    The longer side is ``size_px`` pixels, equal aspect, ``y`` up, the label colours of
    :func:`write_svg` on white, label 0 not drawn.

    Parameters
    ----------
    model : PolygonModel
        The polygons to draw.
    path : str or Path
        The ``.png`` file (written to a temporary file in the same folder, then renamed).
    size_px : int, optional
        Pixels of the longer side, 8 to 16384.

    Raises
    ------
    InputError
        When ``size_px`` is not an integer from 8 to 16384, or naming the file when it
        cannot be written.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from PIL import Image
    >>> from csplab.continuous.model import PolygonModel
    >>> M = PolygonModel.from_json({"polygons": [{"label": 1, "points": [[0, 0], [2, 0], [2, 1]]}]})
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_png(M, pathlib.Path(d) / "m.png", size_px=64)
    ...     Image.open(pathlib.Path(d) / "m.png").size
    (64, 33)
    """
    from PIL import Image, ImageDraw

    p = png_target(path, size_px, 8, 16384)
    x0, y0, x1, y1 = _bounds(model)
    span = max(x1 - x0, y1 - y0, 1e-12)
    margin = 1
    s = (size_px - 2 * margin) / span
    w = max(1, round((x1 - x0) * s) + 2 * margin)
    h = max(1, round((y1 - y0) * s) + 2 * margin)
    img = Image.new("RGB", (w, h), (255, 255, 255))
    cols = _colours(model)

    def px(ring: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
        a: NDArray[np.float64] = np.asarray(ring, dtype=np.float64)
        xs = margin + (a[:, 0] - x0) * s
        ys = margin + (y1 - a[:, 1]) * s
        return list(zip(xs.tolist(), ys.tolist(), strict=True))

    for poly in model.polygons:
        mask = Image.new("L", (w, h), 0)
        draw = ImageDraw.Draw(mask)
        draw.polygon(px(poly.points), fill=255)
        for hole in poly.holes:
            draw.polygon(px(hole), fill=0)
        img.paste(cols[poly.label], (0, 0, w, h), mask)
    buf = io.BytesIO()
    img.save(buf, format="PNG")
    write_atomic(p, buf.getvalue())
