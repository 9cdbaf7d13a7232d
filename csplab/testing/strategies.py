"""Hypothesis strategies for csplab objects: example models and problems.

The module imports without hypothesis (a test dependency, ``pip install 'csplab[test]'``):
hypothesis is imported when a strategy is first built, and a missing one is one
:class:`~csplab.errors.DependencyError` line.

Examples
--------
>>> from hypothesis import given, settings
>>> @settings(max_examples=5, deadline=None)
... @given(example_models(max_labels=3))
... def check(E):
...     assert E.transitions().shape == (E.ndim, E.K, E.K)
>>> check()
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from csplab import grids
from csplab.example import ExampleModel
from csplab.grids import from_example, with_fixed
from csplab.problem import Problem

if TYPE_CHECKING:
    from hypothesis.strategies import SearchStrategy

T = TypeVar("T")


def _hypothesis_strategies() -> Any:
    from csplab.deps import require

    return require("hypothesis.strategies", "test", "csplab.testing.strategies")


class _LazyStrategies:
    """``hypothesis.strategies``, imported on first use."""

    def __getattr__(self, name: str) -> Any:
        return getattr(_hypothesis_strategies(), name)


st: Any = _LazyStrategies()


def _composite(f: Callable[..., T]) -> Callable[..., SearchStrategy[T]]:
    """``hypothesis.strategies.composite``, applied when the strategy is first built."""
    built: Callable[..., SearchStrategy[T]] | None = None

    @functools.wraps(f)
    def make(*args: Any, **kwargs: Any) -> SearchStrategy[T]:
        nonlocal built
        if built is None:
            built = _hypothesis_strategies().composite(f)
        assert built is not None
        return built(*args, **kwargs)

    sig = inspect.signature(f)  # the signature without ``draw``, as composite gives it
    make.__signature__ = sig.replace(parameters=list(sig.parameters.values())[1:])  # type: ignore[attr-defined]
    return make


__all__ = [
    "analysis_examples",
    "corrupted",
    "csp_problems",
    "example_models",
    "label_grids",
    "polygon_models",
    "problems",
    "random_problems",
    "shapes",
    "tile_rule_sets",
]


@_composite
def shapes(draw: Any, ndim: int | None = None, min_side: int = 1, max_side: int = 4,
           max_ndim: int = 3) -> tuple[int, ...]:  # fmt: skip
    """Grid shapes with 1 to ``max_ndim`` axes."""
    d = ndim if ndim is not None else draw(st.integers(1, max_ndim))
    return tuple(draw(st.integers(min_side, max_side)) for _ in range(d))


@_composite
def label_grids(draw: Any, ndim: int | None = None, max_side: int = 5, max_labels: int = 5,
                max_ndim: int = 3) -> np.ndarray:  # fmt: skip
    """Integer label grids; labels ``0..max_labels-1``, label 0 more frequent (empty space)."""
    shp = draw(shapes(ndim=ndim, max_side=max_side, max_ndim=max_ndim))
    k = draw(st.integers(1, max_labels))
    n = int(np.prod(shp))
    p_empty = draw(st.sampled_from([0.0, 0.3, 0.6]))
    vals = draw(
        st.lists(
            st.one_of(st.just(0), st.integers(0, k - 1)) if p_empty else st.integers(0, k - 1),
            min_size=n,
            max_size=n,
        )
    )
    return np.array(vals, dtype=np.int32).reshape(shp)


@_composite
def example_models(draw: Any, ndim: int | None = None, max_side: int = 5, max_labels: int = 5,
                   max_ndim: int = 3) -> ExampleModel:  # fmt: skip
    """Random example models (1D to ``max_ndim``-D)."""
    g = draw(label_grids(ndim=ndim, max_side=max_side, max_labels=max_labels, max_ndim=max_ndim))
    return ExampleModel(g)


@_composite
def problems(
    draw: Any,
    ndim: int | None = None,
    max_side: int = 4,
    max_labels: int = 4,
    max_example_side: int = 4,
    periodic: bool | None = None,
    fixed: bool = True,
    masks: bool = True,
    max_ndim: int = 3,
) -> Problem:
    """Model-synthesis problems: a random example, an output shape, optional periodic axes,
    fixed cells and masks (so some are unsatisfiable)."""
    E = draw(example_models(ndim=ndim, max_side=max_example_side, max_labels=max_labels,
                            max_ndim=max_ndim))  # fmt: skip
    shp = draw(shapes(ndim=E.ndim, max_side=max_side))
    per = draw(st.booleans()) if periodic is None else periodic
    n = int(np.prod(shp))
    fx = None
    if fixed and draw(st.booleans()):
        cells = draw(st.lists(st.integers(0, n - 1), max_size=min(3, n), unique=True))
        fx = np.full(n, -1, dtype=np.int64)
        for c in cells:
            fx[c] = draw(st.integers(0, E.K - 1))
        fx = fx.reshape(shp)
    mk = None
    if masks and draw(st.booleans()):
        bits = draw(st.lists(st.booleans(), min_size=n * E.K, max_size=n * E.K))
        mk = (
            np.array(bits, dtype=bool).reshape(*shp, E.K)
            | draw(st.sampled_from([False, True])) * np.eye(E.K, dtype=bool)[0]
        )
    return from_example(E, shp, periodic=per, fixed=fx, mask=mk)


@_composite
def random_problems(draw: Any, max_side: int = 4, max_labels: int = 4, max_ndim: int = 3,
                    density: tuple[float, float] = (0.2, 0.9)) -> Problem:  # fmt: skip
    """Grid problems with random transition matrices (not from an example)."""
    shp = draw(shapes(max_side=max_side, max_ndim=max_ndim))
    k = draw(st.integers(1, max_labels))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    p = rng.uniform(*density)
    T = rng.random((len(shp), k, k)) < p
    per = draw(st.booleans())
    return grids.grid(shp, T, periodic=per)


@_composite
def corrupted(draw: Any, data: bytes, max_edits: int = 3) -> bytes:
    """``data`` damaged by 1 to ``max_edits`` edits: truncation, byte flips, deleted or
    duplicated lines, deleted or duplicated ``key="value"`` attributes (for fuzzing file
    loaders: only :class:`~csplab.errors.CsplabError` may escape)."""
    import re

    out = bytearray(data)
    for _ in range(draw(st.integers(1, max_edits))):
        kind = draw(
            st.sampled_from(["truncate", "flip", "del_line", "dup_line", "del_attr", "dup_attr"])
        )
        if not out:
            break
        if kind == "truncate":
            out = out[: draw(st.integers(0, len(out) - 1))]
        elif kind == "flip":
            i = draw(st.integers(0, len(out) - 1))
            out[i] = draw(st.integers(0, 255))
        elif kind in ("del_line", "dup_line"):
            lines = bytes(out).split(b"\n")
            i = draw(st.integers(0, len(lines) - 1))
            if kind == "del_line":
                del lines[i]
            else:
                lines.insert(i, lines[i])
            out = bytearray(b"\n".join(lines))
        else:
            attrs = list(re.finditer(rb'[\w"]+\s*[=:]\s*("[^"]*"|[-\w.]+)', bytes(out)))
            if not attrs:
                continue
            m = attrs[draw(st.integers(0, len(attrs) - 1))]
            piece = b"" if kind == "del_attr" else m.group(0) + b" "
            end = m.start() if kind == "dup_attr" else m.end()
            out = out[: m.start()] + piece + out[end:]
    return bytes(out)


@_composite
def tile_rule_sets(draw: Any, max_tiles: int = 4, max_rules: int = 8) -> str:
    """Random valid WaveFunctionCollapse simple-tiled XML (no images)."""
    syms = ["X", "L", "T", "I", "\\", "F"]
    card = {"X": 1, "L": 4, "T": 4, "I": 2, "\\": 2, "F": 8}
    n = draw(st.integers(1, max_tiles))
    tiles = [(f"t{i}", draw(st.sampled_from(syms))) for i in range(n)]
    lines = ["<set>", "  <tiles>"]
    for nm, sym in tiles:
        w = draw(st.sampled_from([0.5, 1, 2]))
        lines.append(f'    <tile name="{nm}" symmetry="{sym}" weight="{w}"/>')
    lines += ["  </tiles>", "  <neighbors>"]
    for _ in range(draw(st.integers(1, max_rules))):
        a, sa = draw(st.sampled_from(tiles))
        b, sb = draw(st.sampled_from(tiles))
        ka = draw(st.integers(0, card[sa] - 1))
        kb = draw(st.integers(0, card[sb] - 1))
        lines.append(f'    <neighbor left="{a} {ka}" right="{b} {kb}"/>')
    lines += ["  </neighbors>", "</set>"]
    return "\n".join(lines) + "\n"


@_composite
def analysis_examples(draw: Any, ndim: int = 2, max_side: int = 4, max_labels: int = 4,
                      frame: bool | None = None) -> ExampleModel:  # fmt: skip
    """Small examples for infallibility analysis; with ``frame`` (drawn when ``None``) the
    grid is surrounded by a layer of empty space 0, as the thesis' examples are (so every
    output size has the all-empty model)."""
    g = draw(label_grids(ndim=ndim, max_side=max_side, max_labels=max_labels))
    if frame if frame is not None else draw(st.booleans()):
        g = np.pad(g, 1, constant_values=0)
    return ExampleModel(g)


@_composite
def csp_problems(draw: Any, max_side: int = 3, max_labels: int = 4, max_ndim: int = 3,
                 max_cells: int = 12) -> Problem:  # fmt: skip
    """Small problems of every kind for solver conformance: from example models (periodic
    or not, fixed cells, masks) or random relations (periodic or not, sometimes with a
    fixed cell), at most ``max_cells`` cells; some are unsatisfiable."""
    P: Problem = draw(
        st.one_of(
            problems(max_side=max_side, max_labels=max_labels, max_ndim=max_ndim),
            random_problems(max_side=max_side, max_labels=max_labels, max_ndim=max_ndim),
        )
    )
    if P.n > max_cells:
        P = P.subproblem(np.arange(max_cells), np.full(P.n, -1))
    if not P.unary and draw(st.booleans()):
        c = draw(st.integers(0, P.n - 1))
        P = with_fixed(P, {P.coords(c): draw(st.integers(0, P.K - 1))})
    return P


@_composite
def polygon_models(draw: Any, max_extent: int = 6, max_pieces: int = 3, max_labels: int = 3,
                   kinds: tuple[str, ...] = ("convex", "cells", "cut")) -> Any:  # fmt: skip
    """Random continuous examples (:class:`~csplab.continuous.model.PolygonModel`) with every
    vertex on the integer lattice ``[0, max_extent]^2``: non-overlapping convex hulls of
    random points (``convex``: arbitrary directions), unions of unit cells with several
    labels, touching and with holes (``cells``), or cells with a diamond cut away (``cut``:
    45-degree edges, reflex vertices)."""
    import shapely

    from csplab.continuous.model import PolygonModel

    kind = draw(st.sampled_from(kinds))
    k = draw(st.integers(1, max_labels))
    pieces: dict[int, Any] = {}

    def hull() -> Any:
        n = draw(st.integers(3, 5))
        pts = [(draw(st.integers(0, max_extent)), draw(st.integers(0, max_extent)))
               for _ in range(n)]  # fmt: skip
        return shapely.MultiPoint(pts).convex_hull

    def free(g: Any) -> bool:  # touching is fine, overlapping would add off-lattice vertices
        return all(g.intersection(h).area == 0 for h in pieces.values())

    if kind == "convex":
        for _ in range(draw(st.integers(1, max_pieces))):
            g, b = hull(), draw(st.integers(1, k))
            if g.area > 0 and free(g):
                pieces[b] = g.union(pieces[b]) if b in pieces else g
    else:
        side = draw(st.integers(2, min(max_extent, 4)))
        cells = draw(st.lists(st.integers(0, k), min_size=side * side, max_size=side * side))
        for i, b in enumerate(cells):
            if b:
                x, y = divmod(i, side)
                box = shapely.box(x, y, x + 1, y + 1)
                pieces[b] = box.union(pieces[b]) if b in pieces else box
        if kind == "cut" and pieces:
            cx, cy = draw(st.integers(0, side)), draw(st.integers(0, side))
            r = draw(st.integers(1, 2))
            g = shapely.Polygon([(cx - r, cy), (cx, cy - r), (cx + r, cy), (cx, cy + r)])
            if g.area > 0:
                pieces = {b: h.difference(g) for b, h in pieces.items()}
                pieces = {b: h for b, h in pieces.items() if h.area > 0}
    if not pieces:
        pieces = {1: shapely.box(0, 0, 1, 1)}
    # keep polygonal parts only (differences may leave slivers of lower dimension)
    clean = {}
    for b, g in pieces.items():
        polys = [p for p in getattr(g, "geoms", [g]) if p.geom_type == "Polygon" and p.area > 0]
        if polys:
            clean[b] = shapely.MultiPolygon(polys)
    return PolygonModel.from_shapes(clean or {1: shapely.box(0, 0, 1, 1)}, name=f"random-{kind}")
