"""Wavefront ``.obj`` export of 3D label grids (voxel meshes or placed pieces), and a small
OBJ reader used to check the output and to load pieces.

:func:`write_obj` writes, for a grid ``[x, y, z]`` (``z`` up):

* a **voxel mesh**: one unit cube per non-empty cell, but only the faces between a filled
  cell and an empty (or outside) cell, shared vertices, one material per label in a
  ``.mtl`` file next to the ``.obj``;
* or, with ``pieces={label: "piece.obj"}``, a copy of each label's mesh translated to every
  cell holding that label (labels without a piece fall back to cubes).

OBJ files are ``y``-up: csplab's ``(x, y, z)`` is written as ``(x, z, -y)`` (a rotation,
so shapes keep their handedness) and Blender's default import shows the model upright.
Pieces are taken to be in OBJ coordinates already and are only translated.

Examples
--------
>>> import numpy as np, tempfile, os
>>> g = np.zeros((2, 1, 1), dtype=np.int32); g[0, 0, 0] = 1; g[1, 0, 0] = 2
>>> d = tempfile.mkdtemp()
>>> stats = write_obj(g, os.path.join(d, "m.obj"), empty=0)
>>> stats["faces"], stats["vertices"]           # two cubes touching: 10 outer faces
(10, 12)
>>> mesh = read_obj(os.path.join(d, "m.obj"))
>>> len(mesh.faces), sorted(mesh.materials)
(10, ['label_1', 'label_2'])
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.errors import FormatError, InputError
from csplab.io.common import Output, read_text

__all__ = ["Mesh", "parse_obj", "read_obj", "write_obj", "write_output"]

# cube faces: (axis, side) -> 4 corners (dx, dy, dz), counter-clockwise seen from outside
_FACES: dict[tuple[int, int], list[tuple[int, int, int]]] = {
    (0, 1): [(1, 0, 0), (1, 1, 0), (1, 1, 1), (1, 0, 1)],
    (0, -1): [(0, 0, 0), (0, 0, 1), (0, 1, 1), (0, 1, 0)],
    (1, 1): [(0, 1, 0), (0, 1, 1), (1, 1, 1), (1, 1, 0)],
    (1, -1): [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)],
    (2, 1): [(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)],
    (2, -1): [(0, 0, 0), (0, 1, 0), (1, 1, 0), (1, 0, 0)],
}


def _to_obj(x: float, y: float, z: float) -> tuple[float, float, float]:
    """csplab (z up) -> OBJ (y up)."""
    return (x, z, -y)


@dataclass
class Mesh:
    """What :func:`read_obj` found: vertices ``(V, 3)``, polygon faces (0-based vertex
    indices), the material of each face, normals and the material colours of the ``.mtl``."""

    vertices: NDArray[np.float64]
    faces: list[list[int]]
    face_material: list[str | None] = field(default_factory=list)
    normals: NDArray[np.float64] = field(default_factory=lambda: np.zeros((0, 3)))
    materials: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    mtllibs: list[str] = field(default_factory=list)


def write_obj(
    grid: ArrayLike,
    path: str | Path,
    *,
    empty: int | None = None,
    colors: ArrayLike | None = None,
    names: Any = None,
    pieces: Mapping[int, str | Path] | None = None,
    cell: float = 1.0,
) -> dict[str, int]:
    """Write a 3D (or 2D, as one layer) label grid as an OBJ mesh with an MTL file.

    Parameters
    ----------
    grid : int array ``[x, y, z]``
    path : str or Path
        The ``.obj`` file; the materials go to the same name with ``.mtl``.
    empty : int, optional
        The empty-space label, not drawn (default: the most frequent top-layer label).
    colors : uint8 array ``(K, 3)``, optional
        Material colours (default: csplab's palette).
    names : sequence of str, optional
        Label names, written as comments in the material file.
    pieces : mapping label -> OBJ file, optional
        Place these meshes instead of cubes (translated by ``cell`` per grid step).
    cell : float
        Edge length of a cell.

    Returns
    -------
    dict
        ``vertices``, ``faces``, ``cells`` (non-empty cells written), ``pieces`` placed.
    """
    from csplab.render import empty_label_guess, palette

    g = np.asarray(grid)
    if g.ndim == 2:
        g = g[:, :, None]
    if g.ndim != 3:
        raise InputError(f".obj export needs a 2D or 3D grid, got shape {g.shape}")
    g = g.astype(np.int64)
    if empty is None:
        empty = empty_label_guess(g)
    K = int(g.max()) + 1 if g.size and g.max() >= 0 else 1
    cols = palette(K) if colors is None else np.asarray(colors, dtype=np.uint8).reshape(-1, 3)
    if len(cols) < K:
        cols = np.concatenate([cols, palette(K)[len(cols) :]])
    filled = (g >= 0) & (g != empty)
    p = Path(path)
    mtl = p.with_suffix(".mtl")
    loaded: dict[int, Mesh] = {}
    for lab, f in (pieces or {}).items():
        loaded[int(lab)] = read_obj(f)
    lines = [
        f"# csplab voxel mesh of a {'x'.join(map(str, g.shape))} grid (y up: csplab (x,y,z) "
        "-> (x,z,-y))",
        f"mtllib {mtl.name}",
    ]
    for m in {lib for mesh in loaded.values() for lib in mesh.mtllibs}:
        lines.append(f"mtllib {m}")
    normals = {k: _to_obj(*(float(k[1]) if i == k[0] else 0.0 for i in range(3))) for k in _FACES}
    nidx = {k: i + 1 for i, k in enumerate(_FACES)}
    for k in _FACES:
        lines.append("vn {:g} {:g} {:g}".format(*normals[k]))
    vindex: dict[tuple[int, int, int], int] = {}
    vlines: list[str] = []
    flines: dict[int, list[str]] = {}
    pad = np.zeros(tuple(s + 2 for s in g.shape), dtype=bool)
    pad[1:-1, 1:-1, 1:-1] = filled
    faces = 0
    cells = list(zip(*np.nonzero(filled), strict=True))
    for x, y, z in cells:  # cubes: only faces towards empty cells
        lab = int(g[x, y, z])
        if lab in loaded:
            continue
        for (axis, side), corners in _FACES.items():
            nb = [x + 1, y + 1, z + 1]
            nb[axis] += side
            if pad[tuple(nb)]:
                continue
            ids = []
            for dx, dy, dz in corners:
                key = (int(x) + dx, int(y) + dy, int(z) + dz)
                if key not in vindex:
                    vindex[key] = len(vindex) + 1
                    vlines.append("v {:g} {:g} {:g}".format(*_to_obj(*(c * cell for c in key))))
                ids.append(vindex[key])
            flines.setdefault(lab, []).append(
                "f " + " ".join(f"{i}//{nidx[(axis, side)]}" for i in ids)
            )
            faces += 1
    lines += vlines
    for lab in sorted(flines):
        lines += [f"g label_{lab}", f"usemtl label_{lab}", *flines[lab]]
    nverts = len(vindex)
    placed = 0
    for x, y, z in cells:  # pieces: translated copies
        lab = int(g[x, y, z])
        if lab not in loaded:
            continue
        mesh = loaded[lab]
        off = np.array(_to_obj(x * cell, y * cell, z * cell))
        lines.append(f"g cell_{x}_{y}_{z}")
        lines += ["v {:g} {:g} {:g}".format(*(v + off)) for v in mesh.vertices]
        cur = None
        mats = mesh.face_material or [None] * len(mesh.faces)
        for face, mat in zip(mesh.faces, mats, strict=True):
            if mat is not None and mat != cur:
                lines.append(f"usemtl {mat}")
                cur = mat
            lines.append("f " + " ".join(str(nverts + i + 1) for i in face))
            faces += 1
        nverts += len(mesh.vertices)
        placed += 1
    text = "\n".join(lines) + "\n"
    mlines = ["# csplab materials: one per label"]
    for lab in sorted({int(v) for v in np.unique(g[filled])}):
        r, gg, b = (int(c) / 255.0 for c in cols[lab])
        nm = f" ({names[lab]})" if names is not None and lab < len(names) else ""
        mlines += [f"newmtl label_{lab}", f"# label {lab}{nm}", f"Kd {r:.4f} {gg:.4f} {b:.4f}",
                   "Ka 0 0 0", "d 1", ""]  # fmt: skip
    from csplab.io.common import write_atomic

    write_atomic(mtl, "\n".join(mlines))  # the materials first: the mesh names them
    write_atomic(p, text)
    return {
        "vertices": nverts,
        "faces": faces,
        "cells": int(filled.sum()),
        "pieces": placed,
    }


def write_output(out: Output, path: Path) -> None:
    """The grid as a Wavefront mesh (a rule set's voxel tiles composited, or its pieces placed).

    A ``.mtl`` file with one material per label is written next to ``path``.

    Parameters
    ----------
    out : Output
        The grid to write, with its model (voxel tiles), names, colours, empty-space label and
        pieces.
    path : Path
        The file to write (overwritten).

    Raises
    ------
    InputError
        When the grid is not 2D or 3D.
    """
    out = out.tile_voxels()
    write_obj(
        out.grid, path, empty=out.empty, colors=out.colors, names=out.names, pieces=out.pieces
    )


def read_obj(path: str | Path) -> Mesh:
    """Read an OBJ file (``v``, ``vn``, ``f``, ``usemtl``, ``mtllib``; other statements are
    skipped) and the colours of its material libraries when present."""
    p = Path(path)
    mesh = parse_obj(read_text(p), path=p)
    for lib in mesh.mtllibs:
        f = p.parent / lib
        if f.is_file():
            mesh.materials.update(_parse_mtl(f.read_text(encoding="utf-8", errors="replace"), f))
    return mesh


def parse_obj(text: str, *, path: object = "<string>") -> Mesh:
    """Parse OBJ text; face indices may be negative (relative) and carry ``/vt/vn`` parts."""
    verts: list[tuple[float, float, float]] = []
    normals: list[tuple[float, float, float]] = []
    faces: list[list[int]] = []
    fmat: list[str | None] = []
    libs: list[str] = []
    cur: str | None = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        t = raw.split("#", 1)[0].split()
        if not t:
            continue
        kw = t[0]
        try:
            if kw in ("v", "vn"):
                vals = [float(v) for v in t[1:4]]
                if len(vals) != 3 or not all(math.isfinite(c) for c in vals):
                    raise ValueError
                (verts if kw == "v" else normals).append((vals[0], vals[1], vals[2]))
            elif kw == "f":
                idx = []
                for tok in t[1:]:
                    i = int(tok.split("/")[0])
                    i = i - 1 if i > 0 else len(verts) + i
                    if not 0 <= i < len(verts):
                        raise FormatError(
                            f"face refers to vertex {tok.split('/')[0]} of {len(verts)}",
                            path=path,
                            line=lineno,
                        )
                    idx.append(i)
                if len(idx) < 3:
                    raise FormatError("a face needs at least 3 vertices", path=path, line=lineno)
                faces.append(idx)
                fmat.append(cur)
            elif kw == "usemtl":
                cur = " ".join(t[1:]) or None
            elif kw == "mtllib":
                libs.extend(t[1:])
        except ValueError:
            raise FormatError(
                f"bad {kw!r} statement: {raw.strip()!r}", path=path, line=lineno
            ) from None
    return Mesh(
        np.array(verts, dtype=np.float64).reshape(-1, 3),
        faces,
        fmat,
        np.array(normals, dtype=np.float64).reshape(-1, 3),
        {},
        libs,
    )


def _parse_mtl(text: str, path: object) -> dict[str, tuple[float, float, float]]:
    out: dict[str, tuple[float, float, float]] = {}
    cur = None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        t = raw.split("#", 1)[0].split()
        if not t:
            continue
        if t[0] == "newmtl":
            cur = " ".join(t[1:])
            out[cur] = (0.8, 0.8, 0.8)
        elif t[0] == "Kd" and cur is not None:
            try:
                r, g, b = (float(v) for v in t[1:4])
            except ValueError:
                raise FormatError(f"bad Kd: {raw.strip()!r}", path=path, line=lineno) from None
            out[cur] = (r, g, b)
    return out
