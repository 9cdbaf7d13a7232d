"""Test meshes made the way users make them: CSG in a modelling package (manifold3d), then
exported as a CAD tool writes them (triangulated, float coordinates, coplanar faces split
into many triangles; optionally with zero-area slivers, duplicate vertices and flipped
triangles).

Every builder is deterministic (no randomness; the export's defects are drawn from a seeded
generator) and returns a ``trimesh.Trimesh`` (watertight, outward, float coordinates):

* ``engraved``: a 10 x 7 x 3 block with the letter A (slanted strokes, a triangular
  counter) engraved 1 deep into its top;
* ``chamfered``: a block with every edge chamfered (a convex hull of three boxes);
* ``bevelled``: a block whose top edges are bevelled (a frustum on a box);
* ``holes``: a plate with three cylindrical through holes (24 segments);
* ``dome``: a cube with a half sphere on its top;
* ``lathe``: a revolved profile (a vase-like solid of revolution, 32 segments);
* ``tetra``: the tetrahedron (0,0,0), (4,0,0), (2,3.5,0), (2,1.2,3);
* ``slanted``: an L-bracket with a slanted face, rotated 17 degrees about z and 6 about x,
  moved by float offsets.

:func:`export` writes one as STL (binary), OFF or OBJ; :func:`write_all` writes every
builder's mesh.

Examples
--------
>>> m = build("tetra")
>>> bool(m.is_watertight), round(float(m.volume), 6), len(m.faces)
(True, 7.0, 4)
>>> sorted(BUILDERS)[:3]
['bevelled', 'chamfered', 'dome']
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["BUILDERS", "build", "export", "pushed_through", "sliver", "write_all"]


def _man() -> Any:
    import manifold3d

    return manifold3d


def _mesh(m: Any) -> Any:
    """A manifold3d solid as a trimesh mesh (float64 vertices, outward triangles)."""
    import trimesh

    g = m.to_mesh64()
    v = np.asarray(g.vert_properties, dtype=np.float64)[:, :3]
    f = np.asarray(g.tri_verts, dtype=np.int64).reshape(-1, 3)
    return trimesh.Trimesh(vertices=v, faces=f, process=False)


def _section(shape: Any) -> Any:
    """A shapely polygon (holes allowed) as a manifold3d CrossSection."""
    from shapely.geometry.polygon import orient

    man = _man()
    shape = orient(shape, 1.0)  # exterior counter-clockwise, holes clockwise
    rings = [np.asarray(shape.exterior.coords)[:-1]]
    rings += [np.asarray(r.coords)[:-1] for r in shape.interiors]
    return man.CrossSection([r.tolist() for r in rings])


def letter_a() -> Any:
    """The outline of a letter A (shapely polygon with a triangular counter), about 6 wide
    and 5.4 tall, slanted strokes 1.1 wide, bar at 1.6."""
    from shapely.geometry import Polygon

    w, h, s = 6.0, 5.4, 1.1
    outer = Polygon([(0, 0), (s, 0), (s + 0.55, 1.6), (w - s - 0.55, 1.6), (w - s, 0), (w, 0),
                     (w / 2 + 0.6, h), (w / 2 - 0.6, h)])  # fmt: skip
    counter = Polygon([(s + 0.95, 2.55), (w - s - 0.95, 2.55), (w / 2, 4.2)])
    return outer.difference(counter)


def engraved() -> Any:
    man = _man()
    block = man.Manifold.cube((10.0, 7.0, 3.0))
    glyph = man.Manifold.extrude(_section(letter_a()), 1.5).translate((2.0, 0.8, 2.0))
    return _mesh(block - glyph)


def chamfered() -> Any:
    man = _man()
    a, b, c, k = 6.0, 4.0, 2.5, 0.6
    boxes = [
        man.Manifold.cube((a, b - 2 * k, c - 2 * k)).translate((0, k, k)),
        man.Manifold.cube((a - 2 * k, b, c - 2 * k)).translate((k, 0, k)),
        man.Manifold.cube((a - 2 * k, b - 2 * k, c)).translate((k, k, 0)),
    ]
    return _mesh(man.Manifold.batch_hull(boxes))


def bevelled() -> Any:
    man = _man()
    base = man.Manifold.cube((8.0, 5.0, 2.0))
    pts = [(x, y, 2.0) for x in (0.0, 8.0) for y in (0.0, 5.0)]
    pts += [(x, y, 3.25) for x in (1.25, 6.75) for y in (1.25, 3.75)]
    return _mesh(base + man.Manifold.hull_points(pts))


def holes() -> Any:
    man = _man()
    plate = man.Manifold.cube((12.0, 6.0, 2.0))
    cut = man.Manifold()
    for x, r in ((2.5, 1.0), (6.0, 1.4), (9.5, 0.75)):
        cut = cut + man.Manifold.cylinder(4.0, r, r, 24).translate((x, 3.0, -1.0))
    return _mesh(plate - cut)


def dome() -> Any:
    man = _man()
    cube = man.Manifold.cube((4.0, 4.0, 4.0))
    cap = man.Manifold.sphere(1.8, 24).trim_by_plane((0.0, 0.0, 1.0), 0.0)
    return _mesh(cube + cap.translate((2.0, 2.0, 4.0)))


def lathe() -> Any:
    man = _man()
    profile = [(0.0, 0.0), (2.2, 0.0), (2.4, 0.4), (1.4, 1.6), (1.1, 3.4), (1.7, 4.6),
               (1.8, 5.0), (0.0, 5.0)]  # fmt: skip
    return _mesh(man.Manifold.revolve(man.CrossSection([profile]), 32))


def tetra() -> Any:
    import trimesh

    v = np.array([[0, 0, 0], [4, 0, 0], [2, 3.5, 0], [2, 1.2, 3]], dtype=np.float64)
    f = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    return trimesh.Trimesh(vertices=v, faces=f, process=False)


def slanted() -> Any:
    man = _man()
    # an L profile with a slanted outer face, extruded 3.5 along y
    prof = [(0.0, 0.0), (6.0, 0.0), (6.0, 1.2), (2.4, 1.2), (1.5, 4.0), (0.0, 4.0)]
    part = man.Manifold.extrude(man.CrossSection([prof]), 3.5)
    part = part.rotate((90.0, 0.0, 0.0)).translate((0.0, 3.5, 0.0))  # the profile in x-z
    part = part.rotate((6.0, 0.0, 17.0)).translate((1.0 / 3.0, -2.718281828, 0.41421356))
    return _mesh(part)


BUILDERS: dict[str, Callable[[], Any]] = {
    "engraved": engraved,
    "chamfered": chamfered,
    "bevelled": bevelled,
    "holes": holes,
    "dome": dome,
    "lathe": lathe,
    "tetra": tetra,
    "slanted": slanted,
}


def build(name: str) -> Any:
    """The mesh of builder ``name`` (a ``trimesh.Trimesh``)."""
    return BUILDERS[name]()


def sliver(v: np.ndarray, f: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """The mesh with edge ``k`` (of the unique edges) split at its midpoint on one side and
    closed by a zero-area triangle on the other, as CAD exports do at T-junctions: the
    triangle ``(a, b, x)`` becomes ``(a, c, x), (c, b, x)`` and the sliver ``(a, b, c)``
    keeps the surface closed."""
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    owner = np.tile(np.arange(len(f)), 3)
    j = int(owner[k % len(edges)])
    a, b = (int(x) for x in edges[k % len(edges)])
    x = next(int(i) for i in f[j] if i not in (a, b))
    c = len(v)
    v = np.vstack([v, (v[a] + v[b]) / 2])
    keep = np.delete(f, j, axis=0)
    f = np.vstack([keep, [[a, c, x], [c, b, x], [a, b, c]]])
    return v, f


def pushed_through(mesh: Any, depth: float = 1.0) -> Any:
    """``mesh`` with its highest vertex (the one of largest ``x`` among ties) dragged to
    ``depth`` below the bottom: the faces around it cross the bottom face (a closed,
    consistently wound surface that intersects itself)."""
    import trimesh

    v = np.asarray(mesh.vertices, dtype=np.float64).copy()
    k = int(np.argmax(v[:, 2] + 1e-3 * v[:, 0]))
    v[k, 2] = float(v[:, 2].min()) - depth
    return trimesh.Trimesh(vertices=v, faces=np.asarray(mesh.faces), process=False)


def export(
    mesh: Any,
    path: str | Path,
    *,
    slivers: int = 0,
    duplicate_vertices: bool = False,
    flip: int = 0,
    seed: int = 0,
) -> Path:
    """Write ``mesh`` as a CAD tool would (format by extension: ``.stl`` binary, ``.off``,
    ``.obj``), with ``slivers`` zero-area triangles (:func:`sliver`), every triangle's
    own copy of its vertices (``duplicate_vertices``; STL always has them) and ``flip``
    triangles reversed (inconsistent winding); defects drawn from ``seed``."""
    import trimesh

    rng = np.random.default_rng(seed)
    v = np.asarray(mesh.vertices, dtype=np.float64)
    f = np.asarray(mesh.faces, dtype=np.int64)
    for _ in range(slivers):
        v, f = sliver(v, f, int(rng.integers(3 * len(f))))
    if flip:
        pick = rng.choice(len(f), size=min(flip, len(f)), replace=False)
        f = f.copy()
        f[pick] = f[pick][:, ::-1]
    if duplicate_vertices:
        v, f = v[f].reshape(-1, 3), np.arange(3 * len(f)).reshape(-1, 3)
    p = Path(path)
    out = trimesh.Trimesh(vertices=v, faces=f, process=False)
    ext = p.suffix.lower()
    if ext == ".stl":
        data: bytes | str = trimesh.exchange.stl.export_stl(out)
    elif ext == ".off":
        data = trimesh.exchange.off.export_off(out, digits=9)
    elif ext == ".obj":
        obj: Any = trimesh.exchange.obj
        data = obj.export_obj(out, include_normals=False, digits=9)
    else:
        raise ValueError(f"{p}: export writes .stl, .off or .obj")
    p.write_bytes(data if isinstance(data, bytes) else data.encode())
    return p


def write_all(folder: str | Path, ext: str = ".stl", **defects: Any) -> dict[str, Path]:
    """Every builder's mesh exported to ``folder/NAME.ext`` (with ``defects`` as for
    :func:`export`)."""
    d = Path(folder)
    d.mkdir(parents=True, exist_ok=True)
    return {n: export(build(n), d / f"{n}{ext}", **defects) for n in BUILDERS}


if __name__ == "__main__":  # pragma: no cover - a development aid
    import sys

    out = write_all(sys.argv[1] if len(sys.argv) > 1 else ".", *sys.argv[2:3])
    for n, p in out.items():
        m = build(n)
        print(f"{n}: {p} {len(m.faces)} triangles, volume {float(m.volume):.6g}")
