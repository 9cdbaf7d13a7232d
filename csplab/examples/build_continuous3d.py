"""Build the built-in polyhedral examples of continuous model synthesis in 3D.

``python -m csplab.examples.build_continuous3d`` writes one Wavefront OBJ file per example
into ``csplab/examples/continuous3d/`` (loaded by
:func:`csplab.examples.continuous3d.load_polyhedral_example`). The examples stand for the
inputs of the 2008 paper (Merrell & Manocha, "Continuous Model Synthesis", SIGGRAPH Asia
2008: Table 1, Fig. 1, 8-13); the paper shows pictures only, so every file's header comment
says which figure it stands for, what the text pins down (Table 1's input polygon count, the
caption) and what was chosen here.

The choices keep the examples cheap: integer vertex coordinates with extents of at most
7 lattice units and at most 7 face orientations (plane families) including the three axes,
slopes of 45 degrees only (normals like ``(1, 0, 1)``). Each solid is written as its own
``o`` group with ``usemtl label_N`` (so :func:`csplab.io.meshes.read_obj_model` gives it
label ``N``), faces counter-clockwise seen from outside.

Examples
--------
>>> s = box(0, 0, 0, 1, 2, 3)
>>> len(s.vertices), len(s.faces)
(8, 6)
>>> print(obj_text(EXAMPLES[0]).splitlines()[0])
# csplab built-in polyhedral example 'tetrahedron'
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["EXAMPLES", "Example", "Shape", "box", "main", "obj_text", "prism", "write_all"]

Point3 = tuple[int, int, int]


@dataclass
class Shape:
    """One closed solid: ``label``, integer ``vertices`` and polygon ``faces`` (0-based
    vertex indices, counter-clockwise seen from outside)."""

    label: int
    vertices: list[Point3]
    faces: list[list[int]]
    name: str = "solid"


@dataclass
class Example:
    """A built-in example: file ``name``, the ``figure`` it stands for, what the paper
    ``pins`` down, what was ``chosen`` here, and its ``shapes``."""

    name: str
    figure: str
    pins: str
    chosen: str
    shapes: list[Shape] = field(default_factory=list)


def box(x0: int, y0: int, z0: int, x1: int, y1: int, z1: int, label: int = 1,
        name: str = "box") -> Shape:  # fmt: skip
    """The axis-aligned box ``[x0, x1] x [y0, y1] x [z0, z1]`` (6 quads, outward).

    Parameters
    ----------
    x0, y0, z0, x1, y1, z1 : int
        Opposite corners (``x0 < x1`` and so on).
    label : int
        Its object label.
    name : str
        The OBJ group name.

    Returns
    -------
    Shape
    """
    return prism([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], z0, z1, label, name)


def prism(outline: Sequence[tuple[int, int]], z0: int, z1: int, label: int = 1,
          name: str = "prism", axis: int = 2) -> Shape:  # fmt: skip
    """A right prism: the simple polygon ``outline`` (counter-clockwise in its plane)
    extruded from ``z0`` to ``z1`` along ``axis``.

    Parameters
    ----------
    outline : sequence of (int, int)
        The cross-section, counter-clockwise seen from the positive ``axis`` direction, in
        the coordinates that follow ``axis`` cyclically (``axis=2``: ``(x, y)``; ``axis=0``:
        ``(y, z)``; ``axis=1``: ``(z, x)``).
    z0, z1 : int
        The extent along ``axis`` (``z0 < z1``).
    label : int
        Its object label.
    name : str
        The OBJ group name.
    axis : int
        The extrusion axis (0, 1 or 2).

    Returns
    -------
    Shape
        ``2 + len(outline)`` faces: the bottom, the top and one quad per outline edge.
    """
    n = len(outline)

    def at(u: int, v: int, w: int) -> Point3:
        p = [0, 0, 0]
        p[(axis + 1) % 3], p[(axis + 2) % 3], p[axis] = u, v, w
        return (p[0], p[1], p[2])

    verts = [at(u, v, z0) for u, v in outline] + [at(u, v, z1) for u, v in outline]
    faces = [list(range(n - 1, -1, -1)), list(range(n, 2 * n))]
    faces += [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    return Shape(label, verts, faces, name)


def _tetrahedron() -> Example:
    return Example(
        "tetrahedron",
        "2008 paper Fig. 8/9 (the 3D case; thesis Sec. 4.5.3)",
        "a tetrahedron with four face normals, so four plane families; the vertex where the "
        "planes of its top vertex's three faces meet has nine states (Fig. 9: exterior, "
        "interior, three face, three edge states and the vertex itself)",
        "the corner tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1) with normals (1,0,0), "
        "(0,1,0), (0,0,1) and (1,1,1); its 'top vertex' is (0,0,1), where the faces x=0, "
        "y=0 and x+y+z=1 meet; 4 input polygons, label 1",
        [
            Shape(
                1,
                [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)],
                [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
                "tetrahedron",
            )
        ],
    )


def _houses() -> Example:
    roof = prism([(0, 2), (2, 2), (1, 3)], 0, 3, 2, "roof", axis=0)
    return Example(
        "houses",
        "2008 paper Fig. 12 (houses; Table 1 row 'Houses': 39 input polygons)",
        "houses with walls and roofs of another material; 'each house has a complex and "
        "unique roof structure' in the output",
        "one house: walls a 3x2x2 box (label 1) under a 45-degree gable roof, a triangular "
        "prism along x with ridge at y=1, z=3 (label 2); 11 input polygons, 5 orientations "
        "(the axes and (0,1,1), (0,1,-1)); a second house with the ridge along y would add "
        "two more orientations and was left out to keep the arrangement small",
        [box(0, 0, 0, 3, 2, 2, 1, "walls"), roof],
    )


def _skyscrapers() -> Example:
    return Example(
        "skyscrapers",
        "2008 paper Fig. 1 (office buildings; Table 1 row 'Skyscrapers': 27 input polygons)",
        "office buildings whose shapes resemble the input, axis-aligned setbacks",
        "three stacked boxes of decreasing size (a setback tower): 6x6x2 (label 1), "
        "4x4x2 (label 2), 2x2x2 (label 3); 18 input polygons, the 3 axis orientations only",
        [
            box(0, 0, 0, 6, 6, 2, 1, "base"),
            box(1, 1, 2, 5, 5, 4, 2, "middle"),
            box(2, 2, 4, 4, 4, 6, 3, "top"),
        ],
    )


def _arches() -> Example:
    # the arch's outline in the (x, z) plane, counter-clockwise there; the prism along y
    # takes (z, x) coordinates (counter-clockwise seen from +y), hence swapped and reversed
    xz = [(0, 0), (1, 0), (1, 2), (2, 3), (3, 2), (3, 0), (4, 0), (4, 4), (0, 4)]
    outline = [(z, x) for x, z in reversed(xz)]
    return Example(
        "arches",
        "2008 paper Fig. 11 (arches; Table 1 row 'Arches': 20 input polygons)",
        "an arch; the output has 'structures with multiple arches and arches passing over arches'",
        "one pointed arch, a single solid (label 1): two 1-wide pillars 2 high, 45-degree "
        "haunches meeting at height 3, a lintel up to height 4, 4 wide in x and 1 deep in y "
        "(the outline (x,z) = (0,0) (1,0) (1,2) (2,3) (3,2) (3,0) (4,0) (4,4) (0,4) extruded "
        "along y); 11 input polygons, 5 orientations (the axes and (1,0,1), (1,0,-1))",
        [prism(outline, 0, 1, 1, "arch", axis=1)],
    )


def _terrain() -> Example:
    hill = Shape(
        2,
        [(1, 1, 1), (5, 1, 1), (5, 5, 1), (1, 5, 1), (2, 2, 2), (4, 2, 2), (4, 4, 2), (2, 4, 2)],
        [
            [3, 2, 1, 0],
            [4, 5, 6, 7],
            [0, 1, 5, 4],
            [1, 2, 6, 5],
            [2, 3, 7, 6],
            [3, 0, 4, 7],
        ],
        "hill",
    )
    return Example(
        "terrain",
        "2008 paper Fig. 10(a, b) (rocky terrain; Table 1 row 'Terrain': 22 input polygons)",
        "a landscape: terrain generated from a small piece of it; the thesis' landscapes "
        "stand on a ground layer (synthesize with a ground below the region, boundary "
        "z- = 1)",
        "a ground slab 6x6x1 (label 1) carrying a 45-degree frustum of rock (label 2): base "
        "4x4 at z=1, top 2x2 at z=2; 12 input polygons, 7 orientations (the axes and "
        "(1,0,1), (1,0,-1), (0,1,1), (0,1,-1))",
        [box(0, 0, 0, 6, 6, 1, 1, "ground"), hill],
    )


def _fractals() -> Example:
    return Example(
        "fractals",
        "2008 paper Fig. 10(c, d) (fractal structures; Table 1 row 'Fractals': 8 input polygons)",
        "a self-similar input generates fractal structures (the paper uses a Sierpinski "
        "tetrahedron)",
        "a self-similar stack of cubes halving in size, each standing on a corner of the one "
        "below: 4x4x4, 2x2x2 and 1x1x1 (one label, three solids of label 1); 18 input "
        "polygons, the 3 axis orientations only",
        [
            box(0, 0, 0, 4, 4, 4, 1, "cube4"),
            box(0, 0, 4, 2, 2, 6, 1, "cube2"),
            box(0, 0, 6, 1, 1, 7, 1, "cube1"),
        ],
    )


def _pentagons() -> Example:
    outline = [(0, 0), (2, 0), (3, 2), (1, 3), (-1, 2)]
    return Example(
        "pentagons",
        "2008 paper Fig. 13 (pentagonal buildings; Table 1 row 'Pentagons': 33 input polygons)",
        "pentagonal buildings; 'most of the faces are not aligned with the axes'",
        "a pentagonal prism: the lattice pentagon (0,0) (2,0) (3,2) (1,3) (-1,2) (edge "
        "directions (1,0), (1,2), (-2,1), (-2,-1), (1,-2)) from z=0 to z=2 (label 1) with a "
        "roof slab of the same section from z=2 to z=3 (label 2); 14 input polygons, "
        "7 orientations (z, five vertical ones and the x sides of the region)",
        [prism(outline, 0, 2, 1, "building"), prism(outline, 2, 3, 2, "roof")],
    )


#: the built-in examples, in the order of ``POLYHEDRAL_EXAMPLES``
EXAMPLES: list[Example] = [
    _tetrahedron(),
    _houses(),
    _skyscrapers(),
    _arches(),
    _terrain(),
    _fractals(),
    _pentagons(),
]


def _wrap(text: str, width: int = 86) -> list[str]:
    out, line = [], ""
    for word in text.split():
        if line and len(line) + 1 + len(word) > width:
            out.append(line)
            line = word
        else:
            line = f"{line} {word}" if line else word
    return [*out, line] if line else out


def obj_text(example: Example) -> str:
    """The OBJ file of ``example``: the header comment, then per solid ``o``, ``usemtl
    label_N``, its vertices and faces.

    Parameters
    ----------
    example : Example

    Returns
    -------
    str
    """
    n_polys = sum(len(s.faces) for s in example.shapes)
    head = [f"csplab built-in polyhedral example {example.name!r}"]
    head += _wrap(f"Stands for: {example.figure}.")
    head += _wrap(f"The paper pins down: {example.pins}.")
    head += _wrap(f"Chosen here: {example.chosen}.")
    head += [
        f"{len(example.shapes)} solids, {n_polys} polygons; written by "
        "`python -m csplab.examples.build_continuous3d`"
    ]
    lines = [f"# {h}" for h in head]
    base = 1
    for i, s in enumerate(example.shapes):
        lines += [f"o {s.name}_{i}", f"usemtl label_{s.label}"]
        lines += [f"v {x} {y} {z}" for x, y, z in s.vertices]
        lines += ["f " + " ".join(str(base + k) for k in f) for f in s.faces]
        base += len(s.vertices)
    return "\n".join(lines) + "\n"


def write_all(directory: Path) -> list[Path]:
    """Write every example's OBJ file into ``directory`` (created if missing).

    Parameters
    ----------
    directory : Path

    Returns
    -------
    list of Path
        The files written.
    """
    directory.mkdir(parents=True, exist_ok=True)
    out = []
    for ex in EXAMPLES:
        p = directory / f"{ex.name}.obj"
        p.write_text(obj_text(ex), encoding="utf-8")
        out.append(p)
    return out


def main(argv: Sequence[str] | None = None) -> None:
    """Command line: write the OBJ files (``--out`` defaults to the package directory).

    Parameters
    ----------
    argv : sequence of str, optional
    """
    ap = argparse.ArgumentParser(description=(__doc__ or "").split("\n")[0])
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "continuous3d")
    args = ap.parse_args(argv)
    for p in write_all(args.out):
        print(p)


if __name__ == "__main__":
    main()
