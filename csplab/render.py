"""Pictures of label grids: 2D as coloured cells, 3D as an isometric voxel preview.

2D grids are drawn as in the thesis figures: x to the right, y up. 3D grids are drawn from
above the ``+x, +y`` corner; cells holding the empty-space label (and unassigned cells) are
left out. Faces are shaded by orientation, as in a lit isometric view: the top face at the
label's full colour, the ``+x`` face darker, the ``+y`` face darker still.

Each label gets a fixed colour (label 0 a light grey). Labels of one object share the
colour (:func:`label_objects`, :func:`object_colors`): the labels that Merrell's object
table (the trailer of his ``.txt`` files, lines ``LABEL FILE.obj``) maps to the same file,
the orientations of one tile (names ``"corner 1"``, ``"corner 2"``) and, for names such as
``"shop_cnr_ne"``, the labels of one material (``shop``). ``legend=True`` adds a small
legend of object name -> colour.

Examples
--------
>>> import numpy as np
>>> img = render(np.array([[0, 1], [1, 0]]), scale=4)
>>> img.size
(8, 8)
"""

from __future__ import annotations

import colorsys
import io
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from PIL import Image, ImageDraw

__all__ = [
    "empty_label_guess",
    "label_objects",
    "model_objects",
    "object_colors",
    "palette",
    "render",
    "render_png_bytes",
    "render_tiles",
    "save_png",
]


def palette(K: int) -> NDArray[np.uint8]:
    """``K`` distinct RGB colours; label 0 light grey, others spread over hue."""
    cols = np.zeros((max(K, 1), 3), dtype=np.uint8)
    cols[0] = (225, 225, 225)
    for b in range(1, K):
        h = (b * 0.618033988749895) % 1.0
        s = 0.55 + 0.35 * ((b * 7) % 3) / 2
        v = 0.95 - 0.3 * ((b * 5) % 4) / 3
        r, g, bl = colorsys.hsv_to_rgb(h, s, v)
        cols[b] = (int(r * 255), int(g * 255), int(bl * 255))
    return cols


def _object_of_name(name: str) -> str:
    n = name.strip()
    head, sep, tail = n.rpartition(" ")
    if sep and tail.isdigit() and head.strip():  # a tile's orientation: "corner 1"
        n = head.strip()
    core = n.strip("_")
    if "_" in core:  # material_piece_orientation: "shop_cnr_ne"
        n = core.split("_", 1)[0]
    return n


def _trailer_objects(trailer: str, K: int) -> dict[int, str]:
    """Label -> object file stem from Merrell's object table (``LABEL FILE [...]`` lines)."""
    out: dict[int, str] = {}
    for line in trailer.splitlines():
        toks = line.split()
        if len(toks) < 2:
            continue
        try:
            b = int(toks[0])
        except ValueError:
            continue
        if 0 <= b < K:
            obj = toks[1].replace("\\", "/").rsplit("/", 1)[-1]
            out[b] = obj.rsplit(".", 1)[0] if "." in obj.strip(".") else obj
    return out


def label_objects(
    K: int, *, names: Sequence[str] | None = None, trailer: str | None = None
) -> list[str]:
    """The object each of ``K`` labels belongs to.

    From Merrell's object table ``trailer`` (lines ``LABEL FILE.obj``: the file's stem), else
    from the label's name (a trailing orientation number and, for ``a_b_c`` names,
    everything after the first ``_`` dropped), else the label id.

    Examples
    --------
    >>> label_objects(4, names=["empty 0", "corner 0", "corner 1", "line 0"])
    ['empty', 'corner', 'corner', 'line']
    >>> label_objects(3, trailer="<Objects>\\n0 empty\\n1 models/wall.obj 90\\n2 wall.obj\\n")
    ['empty', 'wall', 'wall']
    >>> label_objects(3, names=["air", "shop_cnr_ne", "shop_edge_n"])
    ['air', 'shop', 'shop']
    """
    table = _trailer_objects(trailer, K) if trailer else {}
    out = []
    for b in range(K):
        if b in table:
            out.append(table[b])
        elif names is not None and b < len(names) and str(names[b]).strip():
            out.append(_object_of_name(str(names[b])))
        else:
            out.append(str(b))
    return out


def model_objects(model: Any) -> list[str] | None:
    """:func:`label_objects` of an ``ExampleModel`` or ``RuleSet`` (its ``names`` and
    Merrell's object table ``meta["merrell_trailer"]``), or ``None`` when the model names
    no label."""
    K = int(getattr(model, "K", 0))
    names = getattr(model, "names", None)
    meta = getattr(model, "meta", None)
    trailer = meta.get("merrell_trailer") if isinstance(meta, Mapping) else None
    if K < 1 or (names is None and not trailer):
        return None
    return label_objects(K, names=names, trailer=str(trailer) if trailer else None)


def object_colors(objects: Sequence[str]) -> NDArray[np.uint8]:
    """One RGB colour per label: the ``i``-th object (in the order of their first labels)
    gets colour ``i`` of :func:`palette`, so labels that are all different objects keep
    :func:`palette`.

    Examples
    --------
    >>> c = object_colors(["air", "shop", "shop", "brick"])
    >>> (c[1] == c[2]).all(), (c[1] == c[3]).all(), (c == palette(4)[[0, 1, 1, 2]]).all()
    (np.True_, np.False_, np.True_)
    """
    K = len(objects)
    rank: dict[str, int] = {}
    idx = np.array([rank.setdefault(o, len(rank)) for o in objects], dtype=np.int64)
    return palette(K)[idx] if K else palette(1)[:0]


def _legend(
    img: Image.Image,
    g: NDArray[np.int64],
    objects: Sequence[str],
    cols: NDArray[np.uint8],
    skip: int | None,
    limit: int = 24,
) -> Image.Image:
    """``img`` with a legend (object name -> colour) of the labels drawn, on the right."""
    present = [int(b) for b in np.unique(g) if 0 <= b < len(objects) and b != skip]
    entries: dict[str, tuple[int, int, int]] = {}
    for b in present:
        c = cols[b]
        entries.setdefault(objects[b], (int(c[0]), int(c[1]), int(c[2])))
    items = list(entries.items())
    more = len(items) - limit
    if more > 0:
        items = items[:limit]
    row, sw = 14, 10
    lines = len(items) + (1 if more > 0 else 0)
    width = 24 + sw + 7 * max([len(t) for t, _ in items] + [12])
    out = Image.new("RGB", (img.width + width, max(img.height, lines * row + 8)), (250, 250, 250))
    out.paste(img, (0, 0))
    draw = ImageDraw.Draw(out)
    x0 = img.width + 8
    for i, (text, c) in enumerate(items):
        y = 4 + i * row
        draw.rectangle([x0, y + 1, x0 + sw, y + 1 + sw], fill=c, outline=(90, 90, 90))
        draw.text((x0 + sw + 5, y), text, fill=(20, 20, 20))
    if more > 0:
        draw.text((x0, 4 + len(items) * row), f"... and {more} more", fill=(20, 20, 20))
    return out


def empty_label_guess(grid: NDArray[np.integer[Any]]) -> int:
    """Most frequent label on the top layer of a 3D grid (the sky), else -1."""
    g = np.asarray(grid)
    top = g[..., -1].ravel()
    top = top[top >= 0]
    if top.size == 0:
        return -1
    return int(np.bincount(top).argmax())


def _render_2d(
    g: NDArray[np.int64], K: int, scale: int, colors: NDArray[np.uint8] | None = None
) -> Image.Image:
    cols = palette(K) if colors is None else colors
    rgb = np.where(g[..., None] >= 0, cols[np.clip(g, 0, K - 1)], np.uint8(40))
    img = np.transpose(rgb, (1, 0, 2))[::-1]  # rows = y descending, columns = x
    img = np.repeat(np.repeat(img, scale, axis=0), scale, axis=1)
    return Image.fromarray(np.ascontiguousarray(img, dtype=np.uint8), "RGB")


def _render_3d(
    g: NDArray[np.int64],
    K: int,
    scale: int,
    empty: int | None,
    colors: NDArray[np.uint8] | None = None,
) -> Image.Image:
    nx, ny, nz = g.shape
    if empty is None:
        empty = empty_label_guess(g)
    filled = (g >= 0) & (g != empty)
    cols = (palette(K) if colors is None else colors).astype(np.float64)
    a = scale * 0.866
    b = scale * 0.5
    c = scale * 1.0
    W = int((nx + ny) * a) + 4
    H = int((nx + ny) * b + nz * c) + 4
    ox = ny * a + 2
    oy = nz * c + 2

    def pt(x: float, y: float, z: float) -> tuple[float, float]:
        return (ox + (x - y) * a, oy + (x + y) * b - z * c)

    img = Image.new("RGB", (W, H), (250, 250, 250))
    draw = ImageDraw.Draw(img)
    # only cells with a visible face
    pad = np.zeros((nx + 1, ny + 1, nz + 1), dtype=bool)
    pad[:nx, :ny, :nz] = filled
    vis_x = filled & ~pad[1:, :ny, :nz]
    vis_y = filled & ~pad[:nx, 1:, :nz]
    vis_z = filled & ~pad[:nx, :ny, 1:]
    xs, ys, zs = np.nonzero(vis_x | vis_y | vis_z)
    order = np.lexsort((zs, xs + ys + zs))
    edge = (90, 90, 90)
    for i in order:
        x, y, z = int(xs[i]), int(ys[i]), int(zs[i])
        col = cols[int(g[x, y, z]) % K]
        if vis_z[x, y, z]:
            q = [pt(x, y, z + 1), pt(x + 1, y, z + 1), pt(x + 1, y + 1, z + 1), pt(x, y + 1, z + 1)]
            draw.polygon(q, fill=tuple(int(v) for v in col), outline=edge if scale >= 6 else None)
        if vis_x[x, y, z]:
            q = [pt(x + 1, y, z), pt(x + 1, y + 1, z), pt(x + 1, y + 1, z + 1), pt(x + 1, y, z + 1)]
            draw.polygon(
                q, fill=tuple(int(v * 0.75) for v in col), outline=edge if scale >= 6 else None
            )
        if vis_y[x, y, z]:
            q = [pt(x, y + 1, z), pt(x + 1, y + 1, z), pt(x + 1, y + 1, z + 1), pt(x, y + 1, z + 1)]
            draw.polygon(
                q, fill=tuple(int(v * 0.55) for v in col), outline=edge if scale >= 6 else None
            )
    return img


def render_tiles(grid: ArrayLike, tiles: ArrayLike, *, scale: int = 1) -> Image.Image:
    """Composite one picture per label: ``tiles`` is ``(K, h, w, 3 or 4)`` uint8 (rows top to
    bottom, as in an image file); cell ``[x, y]`` of a 2D grid is drawn with ``y`` up.
    Unassigned cells (``-1``) are drawn dark grey.

    Examples
    --------
    >>> import numpy as np
    >>> tiles = np.zeros((2, 3, 3, 3), dtype=np.uint8); tiles[1] = 255
    >>> img = render_tiles(np.array([[0, 1]]), tiles)        # x = 0: y = 0 black, y = 1 white
    >>> img.size, img.getpixel((0, 0)), img.getpixel((0, 5))
    ((3, 6), (255, 255, 255), (0, 0, 0))
    """
    g = np.asarray(grid, dtype=np.int64)
    t = np.asarray(tiles, dtype=np.uint8)
    if g.ndim != 2:
        raise ValueError(f"tile pictures need a 2D grid, got shape {g.shape}")
    if t.shape[-1] == 4:  # composite on white
        a = t[..., 3:4].astype(np.float64) / 255.0
        t = (t[..., :3] * a + 255.0 * (1 - a)).astype(np.uint8)
    K, h, w = t.shape[:3]
    ext = np.concatenate([t[..., :3], np.full((1, h, w, 3), 40, np.uint8)])
    idx = np.where((g >= 0) & (g < K), g, K)
    rows = idx.T[::-1]  # image rows: y descending
    img = ext[rows]  # (ny, nx, h, w, 3)
    ny, nx = rows.shape
    img = img.transpose(0, 2, 1, 3, 4).reshape(ny * h, nx * w, 3)
    if scale > 1:
        img = np.repeat(np.repeat(img, scale, axis=0), scale, axis=1)
    return Image.fromarray(np.ascontiguousarray(img), "RGB")


def _render_polygons(
    g: NDArray[np.int64], K: int, colors: NDArray[np.uint8] | None, topology: str,
    scale: int | None,
) -> Image.Image:  # fmt: skip
    """One filled polygon per cell of a 2D grid on a :mod:`csplab.topology` grid."""
    from PIL import ImageDraw

    from csplab.topology import Topology

    polys = Topology.parse(topology).polygons((int(g.shape[0]), int(g.shape[1])))
    allp = np.concatenate(polys)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    s = float(scale or max(3, min(24, 640 / max(float((hi - lo).max()), 1.0))))
    W, H = (int(np.ceil(v)) + 3 for v in (hi - lo) * s)
    img = Image.new("RGB", (W, H), (255, 255, 255))
    draw = ImageDraw.Draw(img)
    cols = palette(K) if colors is None else colors
    for lab, pts in zip(g.reshape(-1).tolist(), polys, strict=True):
        c = (40, 40, 40) if lab < 0 else tuple(int(v) for v in cols[min(lab, K - 1)])
        xy = [(1 + (px - lo[0]) * s, H - 2 - (py - lo[1]) * s) for px, py in pts]
        draw.polygon(xy, fill=c, outline=(90, 90, 90))
    return img


def render(
    grid: ArrayLike,
    *,
    K: int | None = None,
    scale: int | None = None,
    empty: int | None = None,
    colors: ArrayLike | None = None,
    tiles: ArrayLike | None = None,
    objects: Sequence[str] | None = None,
    legend: bool = False,
    topology: str | None = None,
) -> Image.Image:
    """A PIL image of a label grid (1D/2D: cells; 3D: isometric voxels; 4D: the ``w = 0`` slice).

    ``topology`` (:mod:`csplab.topology`) draws 2D hexagonal and triangular grids as
    hexagons and triangles, a cylinder as an annulus and an affine grid as parallelograms.

    Parameters
    ----------
    grid : int array
        Labels (``-1`` = unassigned, drawn dark in 2D and left out in 3D).
    K : int, optional
        Number of labels (for the palette); default ``max + 1``.
    scale : int, optional
        Pixels per cell (default chosen from the grid size).
    empty : int, optional
        3D only: the label left out (default: the most frequent label of the top layer).
    colors : uint8 array ``(K, 3)``, optional
        One colour per label (default :func:`palette`).
    tiles : uint8 array ``(K, h, w, 3 or 4)``, optional
        2D only: one picture per label, composited by :func:`render_tiles`.
    objects : sequence of str, optional
        The object of each label (:func:`label_objects`, :func:`model_objects`): labels of
        one object share a colour (:func:`object_colors`) unless ``colors`` is given.
    legend : bool
        Add a legend (object name, or label id, -> colour) of the labels drawn.

    Examples
    --------
    >>> g = np.zeros((2, 2, 2), dtype=int); g[0, 0, 0] = 1; g[1, 1, 0] = 2
    >>> a = render(g, objects=["air", "wall", "wall"], scale=8, legend=True)
    >>> b = render(g, objects=["air", "wall", "wall"], scale=8)
    >>> a.width > b.width
    True
    """
    g = np.asarray(grid, dtype=np.int64)
    if g.ndim == 4:
        g = g[..., 0]
    if g.ndim == 1:
        g = g[:, None]
    if K is None:
        K = int(g.max()) + 1 if g.size and g.max() >= 0 else 1
    if g.ndim == 3 and g.shape[2] == 1:
        g = g[:, :, 0]
    cols = None
    if colors is not None:
        cols = np.asarray(colors, dtype=np.uint8).reshape(-1, 3)
        K = max(K, len(cols))
        if len(cols) < K:
            cols = np.concatenate([cols, palette(K)[len(cols) :]])
    objs = None
    if objects is not None:
        objs = [str(o) for o in objects]
        K = max(K, len(objs))
        objs += [str(b) for b in range(len(objs), K)]
        if cols is None:
            cols = object_colors(objs)
    if g.ndim == 2 and tiles is not None:
        t = np.asarray(tiles)
        s = scale or max(1, min(8, 640 // max(max(g.shape) * max(t.shape[1:3]), 1)))
        return render_tiles(g, t, scale=s)
    skip = None
    if g.ndim == 2 and topology not in (None, "square"):
        img = _render_polygons(g, K, cols, topology, scale)
    elif g.ndim == 2:
        s = scale or max(2, min(24, 640 // max(g.shape)))
        img = _render_2d(g, K, s, cols)
    else:
        s = scale or max(3, min(20, 900 // max(g.shape[0] + g.shape[1], 1)))
        skip = empty_label_guess(g) if empty is None else empty
        img = _render_3d(g, K, s, skip, cols)
    if legend:
        img = _legend(
            img, g, objs or [str(b) for b in range(K)], palette(K) if cols is None else cols, skip
        )
    return img


def save_png(grid: ArrayLike, path: str | Path, *, names: Sequence[str] | None = None,
             **kwargs: Any) -> None:  # fmt: skip
    """Write :func:`render` of ``grid`` to a PNG file."""
    K = len(names) if names is not None else None
    render(grid, K=K, **kwargs).save(Path(path), format="PNG")


def render_png_bytes(
    grid: ArrayLike,
    *,
    names: Sequence[str] | None = None,
    model: Any = None,
    periodic: bool | None = None,
    topology: str | None = None,
) -> bytes:
    """PNG bytes of :func:`render` (or of ``model.render(grid)`` when the model, e.g. a
    :class:`~csplab.io.ruleset.RuleSet`, draws its own tiles)."""
    buf = io.BytesIO()
    if model is not None and hasattr(model, "render"):
        img = model.render(grid, periodic=periodic)
    else:
        K = len(names) if names is not None else None
        objects = model_objects(model) if model is not None else None
        if objects is None and names is not None:
            objects = label_objects(len(names), names=names)
        img = render(grid, K=K, objects=objects, topology=topology)
    img.save(buf, format="PNG")
    return buf.getvalue()
