"""Write the small test fixtures in tests/io/data (run from the repository root:
``python tests/io/make_fixtures.py``). Everything is drawn or written here, by us.

* ``pipes.xml`` + ``pipes/*.png``: a WaveFunctionCollapse simple-tiled tileset of pipes
  (tiles empty X, line I, corner L, tee T, cross X; 5x5 pixel pictures). The rules are the
  fewest statements whose symmetric closure is exactly "pipe ends meet pipe ends", computed
  from the same socket sets the pictures are drawn from.
* ``pipes3d.xml`` + ``pipes3d/*.vox``: the same idea as a MarkovJunior 3D tileset with
  3x3x3 voxel tiles (Empty, Line along z, Turn joining +x and +y).
* ``sample.png``: a 12x8 picture (sky, flowers, ground row) for the overlapping model.
* ``tiny_poms.json`` + ``pieces/*.obj``: a 3D POMS config with an objMap.
* ``tiny_debroglie.json``: a DeBroglie config with comments, rotations and constraints.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from csplab.io.symmetry import Orientations, cube_group, expand_rules, square_group  # noqa: E402
from csplab.io.vox import vox_bytes  # noqa: E402

DATA = Path(__file__).resolve().parent / "data"

# 2D pipes: sockets as directions (axis, sign) with y up
R, U, L, D = (0, 1), (1, 1), (0, -1), (1, -1)
TILES_2D = [
    ("empty", "X", 1.0, []),
    ("line", "I", 2.0, [U, D]),
    ("corner", "L", 1.0, [U, R]),
    ("tee", "T", 0.5, [L, R, D]),
    ("cross", "X", 0.25, [U, R, L, D]),
]
STAB = {"X": ["a", "b"], "I": ["aa", "b"], "L": ["aaab"], "T": ["b"]}
ORDER = ["", "a", "aa", "aaa", "b", "ba", "baa", "baaa"]
CARD = {"X": 1, "L": 4, "T": 4, "I": 2}


def socket_relation(G, orient, sockets, ndim):  # type: ignore[no-untyped-def]
    """T[d, a, b] = pipe on a's +d face iff pipe on b's -d face."""
    K = orient.K
    has = np.zeros((K, ndim, 2), dtype=bool)  # has[label, axis, side(+ = 0)]
    for lab in range(K):
        t, g = orient.tile_of[lab], orient.rep[lab]
        for s in sockets[t]:
            ax, sg = G.apply(g, s)
            has[lab, ax, 0 if sg > 0 else 1] = True
    T = np.zeros((ndim, K, K), dtype=bool)
    for d in range(ndim):
        T[d] = has[:, d, 0][:, None] == has[:, d, 1][None, :]
    return T


def minimal_rules(orient, T, label_name):  # type: ignore[no-untyped-def]
    """Greedy: stated +x rules until their closure is T."""
    stated = []
    cur = np.zeros_like(T)
    for a in range(orient.K):
        for b in range(orient.K):
            if T[0, a, b] and not cur[0, a, b]:
                stated.append((a, b))
                cur = expand_rules(orient, [(x, y, (0, 1)) for x, y in stated], ndim=T.shape[0])
    assert np.array_equal(cur, T), "the socket relation is not closed under the group"
    return [(label_name(a), label_name(b)) for a, b in stated]


def pipes_2d() -> None:
    G = square_group()
    stabs = [G.subgroup(STAB[s]) for _, s, _, _ in TILES_2D]
    order = [[G.index(w) for w in ORDER[: CARD[s]]] for _, s, _, _ in TILES_2D]
    orient = Orientations(G, stabs, order)
    T = socket_relation(G, orient, [t[3] for t in TILES_2D], 2)
    names = [f"{n} {k}" if CARD[s] > 1 else n for n, s, _, _ in TILES_2D for k in range(CARD[s])]
    rules = minimal_rules(orient, T, lambda i: names[i])
    lines = ['<set size="5">', "  <tiles>"]
    for n, s, w, _ in TILES_2D:
        lines.append(f'    <tile name="{n}" symmetry="{s}" weight="{w}"/>')
    lines += ["  </tiles>", "  <neighbors>"]
    lines += [f'    <neighbor left="{a}" right="{b}"/>' for a, b in rules]
    lines += ["  </neighbors>", "  <subsets>", '    <subset name="straight">']
    lines += [f'      <tile name="{n}"/>' for n in ("empty", "line", "cross")]
    lines += ["    </subset>", "  </subsets>", "</set>", ""]
    (DATA / "pipes.xml").write_text("\n".join(lines))
    (DATA / "pipes").mkdir(exist_ok=True)
    for n, _, _, socks in TILES_2D:
        img = np.full((5, 5, 3), 255, dtype=np.uint8)  # rows top to bottom
        if socks:
            img[2, 2] = (20, 20, 20)
        for s in socks:
            if s == U:
                img[0:2, 2] = (20, 20, 20)
            if s == D:
                img[3:5, 2] = (20, 20, 20)
            if s == L:
                img[2, 0:2] = (20, 20, 20)
            if s == R:
                img[2, 3:5] = (20, 20, 20)
        Image.fromarray(img, "RGB").save(DATA / "pipes" / f"{n}.png")


def pipes_3d() -> None:
    G = cube_group()
    X, Y, Z = (0, 1), (1, 1), (2, 1)
    tiles = [("Empty", []), ("Line", [Z, (2, -1)]), ("Turn", [X, Y])]
    vox = []
    for _, socks in tiles:
        v = np.zeros((3, 3, 3), dtype=np.int64)
        if socks:
            v[1, 1, 1] = 1
        for ax, sg in socks:
            idx = [1, 1, 1]
            idx[ax] = 2 if sg > 0 else 0
            v[tuple(idx)] = 2
        vox.append(v)
    # stabilizers from the voxels (what the loader must find too)
    from csplab.io.markovjunior import _label_name, transform_voxels

    stabs = [
        frozenset(g for g in range(len(G)) if np.array_equal(transform_voxels(v, G.elements[g]), v))
        for v in vox
    ]
    orient = Orientations(G, stabs)
    T = socket_relation(G, orient, [t[1] for t in tiles], 3)
    names = [
        _label_name(G, stabs[t], g, tiles[t][0])
        for t, g in zip(orient.tile_of, orient.rep, strict=True)
    ]
    rules = minimal_rules(orient, T, lambda i: names[i])
    lines = ['<tileset fullSymmetry="True">', "  <tiles>"]
    lines += [f'    <tile name="{n}"/>' for n, _ in tiles]
    lines += ["  </tiles>", "  <neighbors>"]
    lines += [f'    <neighbor left="{a}" right="{b}"/>' for a, b in rules]
    lines += ["  </neighbors>", "</tileset>", ""]
    (DATA / "pipes3d.xml").write_text("\n".join(lines))
    (DATA / "pipes3d").mkdir(exist_ok=True)
    for (n, _), v in zip(tiles, vox, strict=True):
        # colour index = value; empty voxels are 0
        (DATA / "pipes3d" / f"{n}.vox").write_bytes(vox_bytes(v - 1, empty=-1))


def sample_png() -> None:
    sky, ground, stem, petal = (120, 180, 250), (120, 80, 40), (40, 150, 40), (230, 40, 60)
    img = np.zeros((8, 12, 3), dtype=np.uint8)
    img[:] = sky
    img[7, :] = ground
    for x, h in ((2, 3), (7, 2), (10, 4)):
        img[7 - h : 7, x] = stem
        img[7 - h - 1, x] = petal
    Image.fromarray(img, "RGB").save(DATA / "sample.png")


def tiny_poms() -> None:
    # tiles: 0 air, 1 ground, 2 pillar; y is up (objMap => OBJ convention)
    rules = []
    for a in range(3):
        for b in range(3):
            for d in (0, 1, 4, 5):  # sideways: anything next to anything of the same layer kind
                if (a == 1) == (b == 1):
                    rules.append([a, b, d, 1])
    rules += [[1, 0, 2, 1], [0, 1, 3, 1], [1, 2, 2, 1], [2, 1, 3, 1]]  # air/pillar on ground
    rules += [[2, 2, 2, 1], [2, 2, 3, 1], [2, 0, 2, 1], [0, 2, 3, 1], [0, 0, 2, 1], [0, 0, 3, 1]]
    rules += [[1, 1, 0, 1]]
    cfg = {
        "rule": rules,
        "name": ["air", "ground", "pillar"],
        "weight": [4, 1, 1],
        "size": [5, 3, 4],
        "boundaryCondition": {
            f: {"type": "tile", "value": 0} for f in ("x+", "x-", "z+", "z-", "y+")
        },
        "constraint": [
            {"type": "quiltForce", "range": {"x": [], "y": [0, 1], "z": [], "tile": [1, 2]}},
            {"type": "remove", "range": {"x": [], "y": [1], "z": [], "tile": [1, 2]}},
            {"type": "count", "range": {"tile": [2, 3]}},
        ],
        "objMap": ["", "pieces/slab.obj", "pieces/pillar.obj"],
    }
    (DATA / "tiny_poms.json").write_text(json.dumps(cfg, indent=1))
    (DATA / "pieces").mkdir(exist_ok=True)
    (DATA / "pieces" / "slab.obj").write_text(
        "# a flat slab\nv 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nusemtl stone\nf 1 2 3 4\n"
    )
    (DATA / "pieces" / "pillar.obj").write_text(
        "# a thin post\nv 0.4 0 0.4\nv 0.6 0 0.4\nv 0.5 1 0.5\nusemtl wood\nf 1 2 3\n"
    )


def tiny_debroglie() -> None:
    text = """{
    // a road network: grass (g), straight road (ns / ew), corner (ne, nw, sw, se)
    "model": {"type": "adjacent"},
    "src": "roads.tsx",
    "symmetry": 8,
    "width": 8, "height": 6, "periodic": false,
    "tiles": [
        {"value": "g", "changeFrequency": 1.0},
        {"value": "ns", "rotateCw": "ew", "reflectX": "ns"},
        {"value": "ew", "rotateCw": "ns", "reflectX": "ew"},
        {"value": "ne", "rotateCw": "se", "reflectX": "nw"},
        {"value": "se", "rotateCw": "sw", "reflectX": "sw"},
        {"value": "sw", "rotateCw": "nw", "reflectX": "se"},
        {"value": "nw", "rotateCw": "ne", "reflectX": "ne", "multiplyFrequency": 2}
    ],
    "adjacencies": [
        /* no road crosses a vertical border here */
        {"left": ["g", "ns", "nw", "sw"], "right": ["g", "ns", "ne", "se"]},
        {"left": ["ew", "ne", "se"], "right": ["ew", "nw", "sw"]}
    ],
    "constraints": [
        {"type": "border", "tile": "g", "sides": "xmin,xmax"},
        {"type": "fixedTile", "tile": "ew", "point": {"x": 3, "y": 0}},
        {"type": "path", "tiles": ["ns", "ew", "ne", "se", "sw", "nw"]}
    ]
}
"""
    (DATA / "tiny_debroglie.json").write_text(text)


if __name__ == "__main__":
    DATA.mkdir(exist_ok=True)
    pipes_2d()
    pipes_3d()
    sample_png()
    tiny_poms()
    tiny_debroglie()
    print("wrote", sorted(p.name for p in DATA.iterdir()))
