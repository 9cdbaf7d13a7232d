"""Tiled maps (``.tmx``): orthogonal and hexagonal tile maps as example models.

`Tiled <https://www.mapeditor.org>`_ stores a map as XML: ``<map orientation=...
width= height= staggeraxis= staggerindex=>`` with ``<layer><data encoding="csv">`` (or
``base64``, uncompressed or ``zlib``/``gzip``). DeBroglie reads such maps as samples,
including hexagonal ones; csplab reads the first tile layer as an example model:

* labels are the layer's tile ids (``gid``, flip bits removed; 0 = no tile, named
  ``empty``), compacted to 0, 1, ... and named ``gid N``;
* rows are flipped so that csplab's ``y`` points up (row 0, the top, becomes
  ``y = height - 1``), as for every picture-like format;
* ``orientation="hexagonal"`` gives an example on a hexagonal grid
  (:mod:`csplab.topology`): ``staggeraxis="y"`` (rows offset, pointy-top) is ``hex:odd-r``
  or ``hex:even-r`` -- which rows are shifted after the flip depends on the height's
  parity --, ``staggeraxis="x"`` (columns offset, flat-top; Tiled shifts the
  ``staggerindex`` columns down) is ``hex:even-q`` for ``odd`` and ``hex:odd-q`` for
  ``even``.

Examples
--------
>>> text = '''<map orientation="hexagonal" staggeraxis="y" staggerindex="odd"
...   width="3" height="2"><layer width="3" height="2"><data encoding="csv">
... 1,2,1,
... 2,2,1</data></layer></map>'''
>>> E = parse_tmx(text, path="m.tmx")
>>> E.topology, E.names, E.labels.tolist()        # row 0 of the file is y = 1
('hex:even-r', ('gid 1', 'gid 2'), [[1, 0], [1, 1], [0, 0]])
"""

from __future__ import annotations

import base64
import gzip
import zlib
from pathlib import Path

import numpy as np

from csplab.errors import FormatError
from csplab.example import ExampleModel
from csplab.io._xml import parse_xml
from csplab.io.common import KIND, NO, SURE, read_bytes, xml_root

__all__ = ["TsxTile", "parse_tmx", "read_tmx", "read_tsx", "sniff"]

_FLAGS = 0x0FFFFFFF  # the low 28 bits are the tile id; the high ones flip/rotate


def sniff(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for XML whose root is ``<map>``."""
    root = xml_root(head)
    return SURE if root == "map" else (KIND if root == "" else NO)


def read_tmx(path: str | Path) -> ExampleModel:
    """Read a Tiled map (see the module docstring).

    Parameters
    ----------
    path : str or Path
        The ``.tmx`` file to read.

    Returns
    -------
    ExampleModel
        The first tile layer's compacted tile ids (``y`` up), named ``gid N`` (``empty`` for
        0); a hexagonal map is on a hexagonal grid (``meta["topology"]``).

    Raises
    ------
    FormatError
        Naming the file (and the line, where there is one) when it cannot be read, is larger than
        :data:`~csplab.io.common.MAX_FILE_BYTES` or is not a supported map (root ``<map>``,
        orthogonal or hexagonal, finite, a tile layer with csv or base64 data of ``width * height``
        ids).
    """
    p = Path(path)
    return parse_tmx(read_bytes(p), path=p)


def parse_tmx(text: str | bytes, *, path: object = "<string>") -> ExampleModel:
    """Parse Tiled map XML into an example model."""
    root = parse_xml(text, path=path)
    if root.tag.lower() != "map":
        raise FormatError(f"a Tiled map has root <map>, not <{root.tag}>", path=path)
    orient = (root.get("orientation") or "orthogonal").lower()
    if orient not in ("orthogonal", "hexagonal"):
        raise FormatError(
            f"orientation {orient!r} is not supported (orthogonal, hexagonal)", path=path
        )
    if (root.get("infinite") or "0") != "0":
        raise FormatError("infinite maps are not supported", path=path)
    layer = root.find("layer")
    if layer is None:
        raise FormatError("no <layer> in the map", path=path, line=root.line)
    try:
        w = int(layer.get("width") or root.get("width") or "")
        h = int(layer.get("height") or root.get("height") or "")
    except ValueError:
        raise FormatError("width and height must be integers", path=path) from None
    if w < 1 or h < 1 or w * h > 10_000_000:
        raise FormatError(f"map size {w}x{h} is out of range", path=path)
    data = layer.find("data")
    if data is None:
        raise FormatError("the layer has no <data>", path=path, line=layer.line)
    enc = (data.get("encoding") or "").lower()
    comp = (data.get("compression") or "").lower()
    if enc == "csv":
        try:
            gids = [int(v) for v in data.text.replace("\n", "").split(",") if v.strip()]
        except ValueError:
            raise FormatError("csv tile data must be integers", path=path, line=data.line) from None
    elif enc == "base64":
        try:
            raw = base64.b64decode(data.text.strip(), validate=False)
            if comp == "zlib":
                raw = zlib.decompress(raw)
            elif comp == "gzip":
                raw = gzip.decompress(raw)
            elif comp:
                raise FormatError(f"compression {comp!r} is not supported", path=path)
        except (ValueError, zlib.error, OSError) as e:
            raise FormatError(f"bad base64 tile data: {e}", path=path, line=data.line) from None
        if len(raw) % 4:
            raise FormatError("base64 tile data is not a whole number of ids", path=path)
        gids = np.frombuffer(raw, dtype="<u4").astype(np.int64).tolist()
    else:
        raise FormatError(
            f"tile data encoding {enc or 'XML <tile>'!r} is not supported (csv, base64)",
            path=path,
            line=data.line,
        )
    if len(gids) != w * h:
        raise FormatError(f"{len(gids)} tiles for a {w}x{h} layer", path=path, line=data.line)
    g = np.asarray(gids, dtype=np.int64) & _FLAGS
    rows = g.reshape(h, w)  # row 0 is the top of the map
    ids = np.unique(rows)
    lab = np.searchsorted(ids, rows)[::-1].T  # [x, y] with y up
    names = [("empty" if v == 0 else f"gid {v}") for v in ids.tolist()]
    meta: dict[str, object] = {"format": "tiled", "source": str(path), "gids": ids.tolist()}
    if orient == "hexagonal":
        axis = (root.get("staggeraxis") or "y").lower()
        index = (root.get("staggerindex") or "odd").lower()
        if axis not in ("x", "y") or index not in ("odd", "even"):
            raise FormatError("staggeraxis must be x or y, staggerindex odd or even", path=path)
        if axis == "y":  # the flip maps file row r to y = h - 1 - r
            odd_rows = (index == "odd") == (h % 2 == 1)
            meta["topology"] = "hex:odd-r" if odd_rows else "hex:even-r"
        else:  # columns shifted down by Tiled = the other columns shifted up
            meta["topology"] = "hex:even-q" if index == "odd" else "hex:odd-q"
    name = Path(str(path)).stem
    return ExampleModel(lab, names=names, name=name, meta=meta)


# ------------------------------------------------------------------- tilesets (.tsx)
class TsxTile:
    """One tile of a Tiled tileset: its local ``id``, ``gid`` (``id + 1``: the first gid
    of a tileset loaded on its own, as DeBroglie loads one), RGBA ``image`` and
    ``properties`` (``<property name= value=>``)."""

    def __init__(self, tid: int, image: np.ndarray, properties: dict[str, str]) -> None:
        self.id = tid
        self.gid = tid + 1
        self.image = image
        self.properties = properties


def read_tsx(path: str | Path) -> list[TsxTile]:
    """A Tiled tileset (``.tsx``): every tile's picture, cut from the tileset image
    (``tilewidth``, ``tileheight``, ``columns``, ``margin``, ``spacing``) or its own
    ``<image>`` (an image-collection tileset), and its properties; a
    :class:`~csplab.errors.FormatError` naming the file and line otherwise.

    Examples
    --------
    >>> import tempfile
    >>> from PIL import Image
    >>> with tempfile.TemporaryDirectory() as d:
    ...     Image.new("RGBA", (4, 2), (255, 0, 0, 255)).save(f"{d}/t.png")
    ...     _ = Path(f"{d}/t.tsx").write_text(
    ...         '<tileset tilewidth="2" tileheight="2" tilecount="2" columns="2">'
    ...         '<image source="t.png" width="4" height="2"/><tile id="1"><properties>'
    ...         '<property name="name" value="wall"/></properties></tile></tileset>')
    ...     tiles = read_tsx(f"{d}/t.tsx")
    >>> [(t.gid, t.image.shape, t.properties) for t in tiles]
    [(1, (2, 2, 4), {}), (2, (2, 2, 4), {'name': 'wall'})]
    """
    from csplab.io.common import load_image

    p = Path(path)
    root = parse_xml(read_bytes(p), path=p)
    if root.tag.lower() != "tileset":
        raise FormatError(f"root element <{root.tag}>, not <tileset>", path=p, line=root.line)

    def num(node: object, key: str, default: int | None = None) -> int:
        raw = getattr(node, "attrib", {}).get(key)
        if raw is None:
            if default is None:
                raise FormatError(f"<tileset> has no {key}", path=p, line=root.line)
            return default
        try:
            v = int(raw)
        except ValueError:
            raise FormatError(f"{key}={raw!r} is not an integer", path=p, line=root.line) from None
        if v < 0 or v > 1_000_000:
            raise FormatError(f"{key}={v} is out of range", path=p, line=root.line)
        return v

    tw, th = num(root, "tilewidth"), num(root, "tileheight")
    margin, spacing = num(root, "margin", 0), num(root, "spacing", 0)
    sheet = root.find("image")
    props: dict[int, dict[str, str]] = {}
    own: dict[int, np.ndarray] = {}
    for t in root.children:
        if t.tag.lower() != "tile":
            continue
        tid = num(t, "id")
        pr = t.find("properties")
        props[tid] = {
            q.attrib.get("name", ""): q.attrib.get("value", q.text)
            for q in (pr.children if pr is not None else [])
            if q.tag.lower() == "property"
        }
        im = t.find("image")
        if im is not None and im.attrib.get("source"):
            own[tid] = load_image(p.parent / im.attrib["source"], where=p)
    tiles: list[TsxTile] = []
    if sheet is not None and sheet.attrib.get("source"):
        img = load_image(p.parent / sheet.attrib["source"], where=p)
        h, w = img.shape[:2]
        cols = num(root, "columns", max(1, (w - 2 * margin + spacing) // (tw + spacing)))
        count = num(root, "tilecount", cols * max(1, (h - 2 * margin + spacing) // (th + spacing)))
        for i in range(count):
            x = margin + (i % cols) * (tw + spacing)
            y = margin + (i // cols) * (th + spacing)
            if x + tw > w or y + th > h:
                raise FormatError(f"tile {i} lies outside the {w}x{h} image", path=p)
            tiles.append(TsxTile(i, img[y : y + th, x : x + tw].copy(), props.get(i, {})))
    else:
        for tid in sorted(own):
            tiles.append(TsxTile(tid, own[tid], props.get(tid, {})))
    if not tiles:
        raise FormatError("the tileset has no tiles (no <image>)", path=p, line=root.line)
    return tiles
