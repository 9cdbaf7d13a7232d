"""Builder of csplab's own 3D example models: ``city``, ``castle`` and ``canal``.

Each example starts as a small voxel scene of materials (air, ground, brick, roof, water,
...) placed by hand with boxes (no randomness). The scene is then cut into model pieces the
way a polygon model is cut on a grid: the cutting planes run through the voxel *centres*
along ``x`` and ``y`` and between voxel layers along ``z``. So model cell ``(x, y, z)``
holds the four voxels ``(x..x+1, y..y+1)`` of layer ``z``, and its label is the pattern of
their materials (a dual grid, as in marching squares, one layer thick). Two neighbouring
pieces share two voxels, so the adjacency constraint makes pieces fit: a wall corner piece
must be followed by a wall side piece, a roof edge sits on a wall edge, and so on.

Label names describe the pattern (quarters ``sw, se, nw, ne`` with ``n`` = ``+y``,
``e`` = ``+x``):

* ``brick`` -- all four quarters of one material (``air`` is label 0, the ground label 1);
* ``roof_edge_n`` -- roof on the north half, air on the rest; ``roof_cnr_ne`` -- roof in
  the north-east quarter only (an outer corner); ``roof_in_sw`` -- roof everywhere but the
  south-west quarter (an inner corner); ``..._diag_swne`` -- two opposite quarters;
* ``deck_edge_n_glass`` -- as above, with glass instead of air on the rest;
* ``mix_SBAA`` -- three or more materials, one letter per quarter in the order sw, se, nw,
  ne (letters: :data:`ABBREV` of the scene).

Every scene keeps distinct objects (houses, trees, boats ...) at least two voxels apart,
so no piece holds parts of two objects and the output can place objects independently;
the outermost ring of the example is empty space above the ground, so each example is a
solution of its own problem with ``boundary="auto"``.

Run ``python -m csplab.examples.build3d`` to rewrite the ``.grid`` files next to this
module, ``--check`` to compare them with the builder, and ``--measure [names]`` to measure
the success rate of Alg. 3.1 at 40x40x10 (the numbers written into the file headers).

Examples
--------
>>> E = build("castle")
>>> E.K, E.shape, E.label_name(0), E.label_name(1)
(63, (30, 30, 8), 'air', 'grass')
>>> material_grid("castle", E.labels).shape
(30, 30, 8)
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.example import ExampleModel

__all__ = [
    "EXAMPLES3D",
    "Scene",
    "build",
    "build_scene",
    "dual_labels",
    "file_text",
    "main",
    "material_grid",
    "materials",
    "measure",
    "pieces",
    "write_all",
]

QUARTERS = ("sw", "se", "nw", "ne")
_QBIT = {q: i for i, q in enumerate(QUARTERS)}


# --------------------------------------------------------------------------- the scene


class Scene:
    """A voxel scene: materials ``V[x, y, z]`` (0 = air) and object ids of the footprint.

    ``shape`` is the voxel shape; the example built from it has one cell less along ``x``
    and ``y``. Layer 0 is filled with the ground material.
    """

    def __init__(self, materials: Sequence[str], abbrev: str, shape: tuple[int, int, int],
                 ground: str) -> None:  # fmt: skip
        if len(abbrev) != len(materials) or len(set(abbrev)) != len(abbrev):
            raise ValueError("need one distinct letter per material")
        self.materials = tuple(materials)
        self.abbrev = abbrev
        self.mat = {m: i for i, m in enumerate(materials)}
        self.V = np.zeros(shape, dtype=np.int64)
        self.V[:, :, 0] = self.mat[ground]
        self.ground = self.mat[ground]
        self.obj = np.zeros(shape[:2], dtype=np.int64)
        self.nobj = 0

    def new(self) -> None:
        """Start a new object (the following boxes belong to it)."""
        self.nobj += 1

    def box(self, m: str, x0: int, x1: int, y0: int, y1: int, z0: int, z1: int,
            attach: bool = False) -> None:  # fmt: skip
        """Fill ``[x0, x1) x [y0, y1) x [z0, z1)`` with material ``m`` (part of the current
        object, or of whatever object is below when ``attach``)."""
        self.V[x0:x1, y0:y1, z0:z1] = self.mat[m]
        if not attach:
            self.obj[x0:x1, y0:y1] = self.nobj

    def too_close(self, gap: int = 2) -> list[tuple[int, int]]:
        """Pairs of objects whose footprints are fewer than ``gap`` voxels apart."""
        ids = [int(i) for i in np.unique(self.obj) if i]
        bad = []
        for i in ids:
            m = self.obj == i
            grown = np.zeros_like(m)
            xs, ys = np.nonzero(m)
            for x, y in zip(xs, ys, strict=True):
                grown[max(0, x - gap) : x + gap + 1, max(0, y - gap) : y + gap + 1] = True
            others = np.unique(self.obj[grown])
            bad += [(i, int(j)) for j in others if j > i]
        return bad


def dual_labels(
    V: NDArray[np.int64], materials: Sequence[str], abbrev: str, first: Sequence[int] = (0,)
) -> tuple[NDArray[np.int32], list[str], NDArray[np.int64]]:
    """Cut voxel materials ``V`` (shape ``(nx+1, ny+1, nz)``) into labelled pieces.

    Returns the labels ``(nx, ny, nz)``, the label names and the pieces ``(K, 4)`` (material
    of the sw, se, nw, ne quarter of each label). Labels are numbered by their pattern,
    except that the uniform patterns of the materials in ``first`` come first.

    Examples
    --------
    >>> V = np.zeros((4, 2, 1), dtype=np.int64); V[1, :, 0] = 1       # a wall along y
    >>> lab, names, pieces = dual_labels(V, ["air", "wall"], "AW")
    >>> names, lab[:, 0, 0].tolist()
    (['air', 'wall_edge_e', 'wall_edge_w'], [1, 2, 0])
    >>> pieces[1].tolist()                                # sw, se, nw, ne
    [0, 1, 0, 1]
    """
    M = len(materials)
    v = np.asarray(V, dtype=np.int64)
    quarters = np.stack([v[:-1, :-1], v[1:, :-1], v[:-1, 1:], v[1:, 1:]], axis=-1)
    codes = ((quarters[..., 0] * M + quarters[..., 1]) * M + quarters[..., 2]) * M + quarters[
        ..., 3
    ]
    uniq = np.unique(codes)
    lead = [c * (M**3 + M**2 + M + 1) for c in first]
    order = [int(c) for c in lead if c in uniq] + [int(c) for c in uniq if int(c) not in lead]
    index = {c: i for i, c in enumerate(order)}
    labels = np.vectorize(index.__getitem__, otypes=[np.int32])(codes)
    pieces = np.array([[(c // M ** (3 - i)) % M for i in range(4)] for c in order], dtype=np.int64)
    names = [_piece_name(p, materials, abbrev) for p in pieces]
    if len(set(names)) != len(names):  # pragma: no cover - the naming is injective
        raise AssertionError("label names repeat")
    return labels.astype(np.int32), names, pieces


def _shape_name(quarters: frozenset[str]) -> str:
    k = len(quarters)
    if k == 1:
        return "cnr_" + next(iter(quarters))
    if k == 3:
        return "in_" + next(iter(set(QUARTERS) - quarters))
    sides = {
        frozenset(("nw", "ne")): "edge_n",
        frozenset(("sw", "se")): "edge_s",
        frozenset(("se", "ne")): "edge_e",
        frozenset(("sw", "nw")): "edge_w",
        frozenset(("sw", "ne")): "diag_swne",
        frozenset(("se", "nw")): "diag_senw",
    }
    return sides[quarters]


def _piece_name(p: Sequence[int] | NDArray[np.int64], materials: Sequence[str], abbrev: str) -> str:
    present = sorted({int(m) for m in p})
    if len(present) == 1:
        return materials[present[0]]
    if len(present) == 2:
        bg, fg = present
        where = frozenset(q for q, m in zip(QUARTERS, p, strict=True) if m == fg)
        name = f"{materials[fg]}_{_shape_name(where)}"
        return name if bg == 0 else f"{name}_{materials[bg]}"
    return "mix_" + "".join(abbrev[int(m)] for m in p)


# --------------------------------------------------------------------------- city

CITY_MATERIALS = (
    "air ground shop brick roof lobby glass deck lawn trunk leaves hedge pole lamp tank basin water"
).split()
CITY_ABBREV = "AGSBRYQDLKVHPMTNW"


def _city() -> Scene:
    s = Scene(CITY_MATERIALS, CITY_ABBREV, (41, 41, 8), "ground")

    def house(x0: int, x1: int, y0: int, y1: int, h: int, new: bool = True) -> None:
        if new:
            s.new()
        s.box("shop", x0, x1, y0, y1, 1, 2)
        s.box("brick", x0, x1, y0, y1, 2, h)
        s.box("roof", x0, x1, y0, y1, h, h + 1)

    def tower(x0: int, x1: int, y0: int, y1: int, h: int) -> None:
        s.new()
        s.box("lobby", x0, x1, y0, y1, 1, 2)
        s.box("glass", x0, x1, y0, y1, 2, h)
        s.box("deck", x0, x1, y0, y1, h, h + 1)

    def park(x0: int, x1: int, y0: int, y1: int, trees: Sequence[tuple[int, int]]) -> None:
        s.new()
        s.box("lawn", x0, x1, y0, y1, 1, 2)
        for x, y in trees:
            s.box("trunk", x, x + 1, y, y + 1, 2, 3, attach=True)
            s.box("leaves", x, x + 1, y, y + 1, 3, 4, attach=True)

    def lamp(x: int, y: int) -> None:
        s.new()
        s.box("pole", x, x + 1, y, y + 1, 1, 2)
        s.box("lamp", x, x + 1, y, y + 1, 2, 3)

    house(2, 6, 2, 7, 4)
    s.box("tank", 3, 4, 4, 5, 5, 6, attach=True)  # water tank on the roof
    house(2, 5, 10, 13, 3)
    house(9, 12, 2, 5, 5)  # an L-shaped house
    house(9, 15, 5, 8, 5, new=False)
    s.box("tank", 10, 11, 6, 7, 6, 7, attach=True)
    tower(18, 22, 2, 6, 6)
    tower(25, 31, 2, 8, 3)  # a tower with a terrace: the upper part is set back
    s.box("glass", 26, 29, 3, 6, 3, 6, attach=True)
    s.box("deck", 26, 29, 3, 6, 6, 7, attach=True)
    tower(14, 17, 13, 16, 5)
    park(2, 9, 17, 23, [(4, 19), (6, 20), (7, 18)])
    s.box("hedge", 2, 9, 22, 23, 2, 3, attach=True)
    s.box("hedge", 2, 3, 17, 22, 2, 3, attach=True)
    park(20, 23, 11, 15, [(21, 13)])
    for x, y in [(10, 11), (35, 12), (11, 36), (36, 30)]:
        lamp(x, y)
    house(14, 19, 20, 24, 4)
    house(26, 31, 18, 21, 6)
    tower(3, 7, 27, 31, 6)
    house(15, 20, 29, 34, 3)
    house(25, 30, 25, 30, 5)
    s.box("tank", 26, 27, 27, 28, 6, 7, attach=True)
    s.new()  # a fountain: a basin with water inside
    s.box("basin", 26, 31, 11, 14, 1, 2)
    s.box("water", 27, 30, 12, 13, 1, 2)
    return s


# --------------------------------------------------------------------------- castle

CASTLE_MATERIALS = "air grass stone merlon tower slate pillar".split()
CASTLE_ABBREV = "AGSMTLP"


def _castle() -> Scene:
    s = Scene(CASTLE_MATERIALS, CASTLE_ABBREV, (31, 31, 8), "grass")

    def wall(x0: int, x1: int, y0: int, y1: int, phase: int = 0, h: int = 3) -> None:
        s.box("stone", x0, x1, y0, y1, 1, h)
        for x in range(x0, x1):
            for y in range(y0, y1):
                if (x + y + phase) % 2 == 0:  # crenellation: merlon, gap, merlon ...
                    s.box("merlon", x, x + 1, y, y + 1, h, h + 1)

    def tower(x0: int, y0: int, w: int = 3, h: int = 5) -> None:
        s.box("tower", x0, x0 + w, y0, y0 + w, 1, h)
        s.box("slate", x0, x0 + w, y0, y0 + w, h, h + 1)  # a pointed roof
        c, d = x0 + w // 2, y0 + w // 2
        s.box("slate", c, c + 1, d, d + 1, h + 1, h + 2)

    s.new()
    a, b = 3, 23
    wall(a + 3, b, a + 1, a + 2)  # curtain walls between corner towers
    wall(a + 3, b, b + 1, b + 2)
    wall(a + 1, a + 2, a + 3, b)
    wall(b + 1, b + 2, a + 3, 14)  # the east wall turns inwards (no tower at the turn)
    wall(b - 2, b + 2, 13, 14)
    wall(b - 2, b - 1, 13, b)
    for x0, y0 in [(a, a), (a, b), (b, a), (b - 3, b)]:
        tower(x0, y0)
    s.box("air", 14, 15, a + 1, a + 2, 1, 2)  # the gate
    s.new()  # a free-standing wall ending in two pillars
    wall(9, 18, 15, 16, phase=1)
    s.box("pillar", 9, 10, 15, 16, 1, 4)
    s.box("pillar", 17, 18, 15, 16, 1, 4)
    return s


# --------------------------------------------------------------------------- canal town

CANAL_MATERIALS = "air sea quay bridge rail wall roof hull sail trunk crown post light".split()
CANAL_ABBREV = "ASQBLWRHNTCPG"


def _canal() -> Scene:
    s = Scene(CANAL_MATERIALS, CANAL_ABBREV, (39, 39, 8), "sea")

    def house(x0: int, x1: int, y0: int, y1: int, h: int) -> None:
        s.box("wall", x0, x1, y0, y1, 2, h, attach=True)
        s.box("roof", x0, x1, y0, y1, h, h + 1, attach=True)

    s.new()
    cy0, cy1 = 15, 21  # a wide canal along x
    cx0, cx1 = 17, 20  # a narrow canal along y
    s.box("quay", 2, cx0, 2, cy0, 1, 2)
    s.box("quay", cx1, 37, 2, cy0, 1, 2)
    s.box("quay", 2, cx0, cy1, 37, 1, 2)
    s.box("quay", cx1, 37, cy1, 37, 1, 2)
    for y0 in (6, 28):  # bridges with railings over the narrow canal
        s.box("bridge", cx0, cx1, y0, y0 + 3, 1, 2)
        s.box("rail", cx0, cx1, y0, y0 + 1, 2, 3)
        s.box("rail", cx0, cx1, y0 + 2, y0 + 3, 2, 3)
    x0 = 6  # and one over the wide canal
    s.box("bridge", x0, x0 + 3, cy0, cy1, 1, 2)
    s.box("rail", x0, x0 + 1, cy0, cy1, 2, 3)
    s.box("rail", x0 + 2, x0 + 3, cy0, cy1, 2, 3)
    house(2, 6, 2, 6, 4)  # houses: some along the water, some set back
    house(11, 17, 10, 15, 5)
    house(10, 14, 3, 7, 3)
    house(20, 24, 10, 15, 4)
    house(27, 33, 3, 8, 6)
    house(31, 37, 10, 15, 3)
    house(3, 8, 30, 35, 5)
    house(12, 17, 21, 26, 3)
    house(21, 26, 21, 25, 5)
    house(29, 34, 28, 34, 4)
    for x, y in [(5, 10), (24, 31), (13, 31)]:
        s.box("trunk", x, x + 1, y, y + 1, 2, 3)
        s.box("crown", x, x + 1, y, y + 1, 3, 4)
    for x, y in [(3, 12), (35, 23), (25, 3)]:
        s.box("post", x, x + 1, y, y + 1, 2, 3)
        s.box("light", x, x + 1, y, y + 1, 3, 4)
    s.new()  # a sailing boat in the wide canal
    s.box("hull", 11, 15, 18, 19, 1, 2)
    s.box("sail", 13, 14, 18, 19, 2, 3)
    return s


# --------------------------------------------------------------------------- registry


@dataclass(frozen=True)
class Spec:
    """One 3D example: its file, scene builder and what it shows."""

    file: str
    scene: Callable[[], Scene]
    title: str
    description: str


EXAMPLES3D: dict[str, Spec] = {
    "city": Spec(
        "city3d.grid",
        _city,
        "a city block",
        "Brick houses (shop floor, brick storeys, flat roof, some with a water tank), glass\n"
        "towers (lobby, glass storeys, roof deck; one with a set-back upper part), an\n"
        "L-shaped house, two parks (lawn, trees, a hedge), street lamps and a fountain on a\n"
        "paved ground. Built from boxes of the same footprint on each storey and objects\n"
        "kept apart, it behaves like the thesis' 'city at night': Alg. 3.1 has not been\n"
        "seen to fail on it.",
    ),
    "castle": Spec(
        "castle3d.grid",
        _castle,
        "a castle wall with towers",
        "A curtain wall with crenellations (merlon, gap, merlon ...) running between four\n"
        "square towers with pointed slate roofs, a gate, a corner where the wall turns without\n"
        "a tower, and a free-standing wall piece ending in two pillars. Walls must end in\n"
        "towers or pillars, towers are exactly 3x3 (their roof fixes the size) and the\n"
        "merlons must keep their rhythm, so Alg. 3.1 fails often (Alg. 3.4 is needed).",
    ),
    "canal": Spec(
        "canal3d.grid",
        _canal,
        "a canal town with bridges",
        "Four stone quays at the sea with houses (some right at the water, some set back),\n"
        "trees and lamps; a wide and a narrow canal between them, three bridges with\n"
        "railings across the canals and a sailing boat. A bridge must reach a quay at\n"
        "both ends; Alg. 3.1 fails now and then.",
    ),
}

# Measured with `python -m csplab.examples.build3d --measure --seeds 200` (see measure()):
# name -> {boundary: (solved, seeds)} for Alg. 3.1 (catalog solver, scanline order,
# uniform choice, seeds 0..seeds-1) at 40x40x10.
MEASURED: dict[str, dict[str, tuple[int, int]]] = {
    "city": {"auto": (200, 200), "none": (200, 200)},
    "castle": {"auto": (3, 200), "none": (140, 200)},
    "canal": {"auto": (198, 200), "none": (187, 200)},
}

_CACHE: dict[str, tuple[ExampleModel, NDArray[np.int64], Scene]] = {}


def build_scene(name: str) -> Scene:
    """The voxel scene of a 3D example (checked: objects apart, empty outer ring and top)."""
    spec = EXAMPLES3D[name]
    s = spec.scene()
    close = s.too_close()
    if close:  # pragma: no cover - guards edits of the scenes
        raise AssertionError(f"{name}: objects too close: {close}")
    V = s.V
    ring = np.ones(V.shape[:2], dtype=bool)
    ring[2:-2, 2:-2] = False
    if V[ring][:, 1:].any() or V[:, :, -1].any() or (V[:, :, 0] != s.ground).any():
        raise AssertionError(f"{name}: outer ring or top layer not empty")  # pragma: no cover
    return s


def _built(name: str) -> tuple[ExampleModel, NDArray[np.int64], Scene]:
    if name not in _CACHE:
        s = build_scene(name)
        labels, names, pcs = dual_labels(s.V, s.materials, s.abbrev, first=(0, s.ground))
        E = ExampleModel(labels, names=names, name=name)
        _CACHE[name] = (E, pcs, s)
    return _CACHE[name]


def build(name: str) -> ExampleModel:
    """The example model ``name`` (``"city"``, ``"castle"`` or ``"canal"``)."""
    return _built(name)[0]


def pieces(name: str) -> NDArray[np.int64]:
    """``(K, 4)``: the material of the sw, se, nw, ne quarter of each label of ``name``."""
    return _built(name)[1].copy()


def materials(name: str) -> tuple[str, ...]:
    """The material names of the scene of ``name`` (material 0 is air)."""
    return _built(name)[2].materials


def material_grid(name: str, grid: ArrayLike) -> NDArray[np.int64]:
    """Voxel materials of a labelled grid of example ``name``, for pictures.

    Voxel ``(x, y, z)`` is the north-east quarter of cell ``(x, y, z)`` (unassigned cells
    give ``-1``); ``csplab.render.save_png(material_grid(name, grid), path, empty=0)``
    draws the scene with one colour per material.
    """
    g = np.asarray(grid, dtype=np.int64)
    pcs = _built(name)[1]
    return np.where(g >= 0, pcs[np.clip(g, 0, len(pcs) - 1), 3], -1)


def _rate_line(name: str) -> list[str]:
    m = MEASURED.get(name)
    if not m:
        return ["Alg. 3.1 success rate at 40x40x10: not measured yet."]
    a, n = m["auto"]
    b, n2 = m["none"]
    return [
        "Alg. 3.1 (solver 'catalog', scanline order) at 40x40x10, seeds 0-" + str(n - 1) + ":",
        f"  boundary='auto': solved {a}/{n} ({100 * a / n:g}%); "
        f"no boundary: solved {b}/{n2} ({100 * b / n2:g}%).",
        f"  Measured with: python -m csplab.examples.build3d --measure {name} --seeds {n}",
    ]


def header(name: str) -> str:
    """The comment block written at the top of the example's file."""
    spec = EXAMPLES3D[name]
    E = build(name)
    nx, ny, nz = E.shape
    lines = [
        f'The "{name}" example: {spec.title} ({nx}x{ny}x{nz} cells, K = {E.K} labels).',
        "csplab's own example, generated by csplab/examples/build3d.py (do not edit; run",
        "python -m csplab.examples.build3d to regenerate). z is up; label 0 is air, label 1",
        "the ground; boundary='auto' puts the ground under the model and air around it.",
        "",
        *spec.description.splitlines(),
        "",
        "Each cell is a model piece cut from a voxel scene through the voxel centres along x",
        "and y: its label is the pattern of materials of the four voxels it holds (label",
        "names: see build3d.py).",
        "",
        *_rate_line(name),
    ]
    return "\n".join(lines)


def file_text(name: str) -> str:
    """The exact text of the example's ``.grid`` file."""
    from csplab.io.gridtext import format_grid

    return format_grid(build(name), header(name))


def write_all(
    directory: str | Path | None = None, names: Sequence[str] | None = None
) -> list[Path]:
    """Write the ``.grid`` files (default: next to this module)."""
    d = Path(directory) if directory is not None else Path(__file__).parent
    out = []
    for name in names or EXAMPLES3D:
        p = d / EXAMPLES3D[name].file
        p.write_text(file_text(name), encoding="utf-8")
        out.append(p)
    return out


def measure(
    name: str,
    seeds: int = 200,
    shape: tuple[int, ...] = (40, 40, 10),
    boundary: Literal["auto", "none"] | None = "auto",
    progress: bool = False,
) -> dict[str, Any]:
    """Run Alg. 3.1 (``catalog``, scanline order) for seeds ``0..seeds-1``.

    Returns ``{"solved", "seeds", "failed_seeds", "median_s", "median_solved_s"}`` (median
    run times over all runs and over the solved ones).
    """
    from csplab.grids import from_example
    from csplab.solvers import solve

    P = from_example(build(name), shape, boundary=boundary)
    solved, failed, times, times_ok = 0, [], [], []
    for seed in range(seeds):
        r = solve(P, "catalog", rng=seed)
        times.append(r.time_s)
        if r.status == "solved":
            solved += 1
            times_ok.append(r.time_s)
        else:
            failed.append(seed)
        if progress and seed % 50 == 49:
            print(f"  {name} {boundary}: {seed + 1} seeds, {solved} solved", file=sys.stderr)
    return {
        "solved": solved,
        "seeds": seeds,
        "failed_seeds": failed,
        "median_s": float(np.median(times)),
        "median_solved_s": float(np.median(times_ok)) if times_ok else float("nan"),
    }


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: write (default), ``--check`` or ``--measure`` the 3D examples."""
    ap = argparse.ArgumentParser(prog="python -m csplab.examples.build3d", description=__doc__)
    ap.add_argument("names", nargs="*", help="examples (default: all)")
    ap.add_argument("--check", action="store_true", help="compare the files with the builder")
    ap.add_argument("--measure", action="store_true", help="measure Alg. 3.1 at 40x40x10")
    ap.add_argument("--seeds", type=int, default=200)
    ap.add_argument("--dir", default=None, help="output directory (default: the package)")
    a = ap.parse_args(argv)
    names = a.names or list(EXAMPLES3D)
    unknown = [n for n in names if n not in EXAMPLES3D]
    if unknown:
        ap.error(f"unknown example(s) {unknown}; 3D examples: {', '.join(EXAMPLES3D)}")
    if a.measure:
        for name in names:
            E = build(name)
            for bnd in ("auto", None):
                t0 = time.perf_counter()
                m = measure(name, a.seeds, boundary=bnd, progress=True)
                print(
                    f"{name}: K={E.K} boundary={bnd or 'none'}: solved {m['solved']}/{m['seeds']}"
                    f", median {m['median_s']:.3f} s (solved runs {m['median_solved_s']:.3f} s)"
                    f", total {time.perf_counter() - t0:.1f} s"
                    f", failed seeds {m['failed_seeds'][:10]}"
                )
        return 0
    if a.check:
        d = Path(a.dir) if a.dir else Path(__file__).parent
        bad = [n for n in names if (d / EXAMPLES3D[n].file).read_text("utf-8") != file_text(n)]
        for n in bad:
            print(f"{EXAMPLES3D[n].file} differs from the builder output")
        return 1 if bad else 0
    for name, p in zip(names, write_all(a.dir, names), strict=True):
        E = build(name)
        print(f"wrote {p} ({'x'.join(map(str, E.shape))}, K={E.K})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
