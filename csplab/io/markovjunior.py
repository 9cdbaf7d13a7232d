"""MarkovJunior tileset XML (3D tiles, the cube's symmetry group).

Layout::

    <tileset fullSymmetry="True">
      <tiles><tile name="Empty"/><tile name="Line" weight="2"/>...</tiles>
      <neighbors>
        <neighbor left="Line" right="x Line"/>     right may be the +x neighbour of left
        <neighbor top="Turn" bottom="Empty"/>      without fullSymmetry: top on top of bottom
      </neighbors>
    </tileset>

``"zzx Turn"`` is tile ``Turn`` turned by ``x``, then ``z``, then ``z`` (quarter turns: ``x``
takes ``+y`` to ``+z``, ``y`` takes ``+x`` to ``+z``, ``z`` takes ``+x`` to ``+y``). With
``fullSymmetry`` every rule holds in all 48 frames of the cube's symmetry group (turns and
mirrors), so ``left/right`` rules also give the ``y`` and ``z`` rules; without it the group
is the square's 8 symmetries about the vertical ``z`` axis and vertical rules are stated
with ``top``/``bottom``.

Labels are the distinct orientations of each tile. MarkovJunior tells them apart by the
tiles' voxel data (``<name>.vox`` in a folder named after the XML file next to it); csplab
reads those files when they are there and then matches MarkovJunior exactly. Without them,
each tile's own symmetry is inferred from the rules: every stated rule glues a face of one
tile to a face of another, glued faces get the same *socket*, faces no rule mentions get
the most common socket, and a tile's symmetries are the transformations that keep its six
sockets in place. A warning says so and lists the inferred orientation counts.

Examples
--------
>>> xml = '''<tileset fullSymmetry="True"><tiles><tile name="Empty"/><tile name="Line"/>
... </tiles><neighbors><neighbor left="Empty" right="Empty"/>
... <neighbor left="Empty" right="Line"/><neighbor left="Line" right="Line"/>
... <neighbor left="y Line" right="y Line"/></neighbors></tileset>'''
>>> import warnings
>>> with warnings.catch_warnings():
...     warnings.simplefilter("ignore")
...     rs = parse_markovjunior(xml, path="pipes.xml")
>>> rs.K, rs.names                    # an empty tile and a straight pipe in 3 directions
(4, ('Empty', 'Line', 'x Line', 'y Line'))
>>> rs.closure_violations()
[]
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.errors import FormatError, InputError
from csplab.io._xml import Node, parse_xml
from csplab.io.common import (
    NO,
    SURE,
    LoaderWarnings,
    neighbor_side,
    read_bytes,
    xml_bool,
    xml_float,
    xml_neighbors,
    xml_root,
)
from csplab.io.ruleset import RuleSet
from csplab.io.symmetry import Group, Orientations, cube_group, expand_rules, square_group

__all__ = ["parse_markovjunior", "read_markovjunior", "sniff", "transform_voxels"]

_DIRS = [(a, s) for a in range(3) for s in (1, -1)]


def sniff(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for XML whose root element is ``<tileset>``."""
    return SURE if xml_root(head) == "tileset" else NO


def read_markovjunior(path: str | Path) -> RuleSet:
    """Read a MarkovJunior tileset XML file (see the module docstring).

    Parameters
    ----------
    path : str or Path
        The XML file to read; the tiles' ``.vox`` files are looked up in a folder named
        after it.

    Returns
    -------
    RuleSet
        One label per distinct tile orientation, the rules expanded over the cube's (or,
        without ``fullSymmetry``, the square's) symmetry group, the weights and, when the
        ``.vox`` files are there, the tiles' voxels; inferred symmetries are reported in
        ``meta["warnings"]`` (each also a :class:`UserWarning` naming the file).

    Raises
    ------
    FormatError
        Naming the file (and the line, where there is one) when it cannot be read, is larger than
        :data:`~csplab.io.common.MAX_FILE_BYTES` or is not a valid tileset (no ``<tiles>``, a
        neighbour naming an unknown tile or turn, a bad attribute or ``.vox`` file ...).
    """
    p = Path(path)
    return parse_markovjunior(read_bytes(p), path=p)


def transform_voxels(vox: NDArray[Any], m: NDArray[np.int64]) -> NDArray[Any]:
    """Apply a signed axis permutation ``m`` to a voxel block ``[x, y, z]`` about its centre."""
    shape = np.array(vox.shape)
    idx = np.indices(vox.shape).reshape(3, -1) * 2 - (shape - 1)[:, None]
    new = m @ idx
    new_shape = np.abs(m) @ shape
    tgt = (new + (new_shape - 1)[:, None]) // 2
    out = np.zeros(tuple(int(s) for s in new_shape), dtype=vox.dtype)
    out[tuple(tgt)] = vox.reshape(-1)
    return out


def parse_markovjunior(text: str | bytes, *, path: object = "<string>") -> RuleSet:
    """Parse MarkovJunior tileset XML into a :class:`RuleSet` (tile ``.vox`` files are
    looked up next to ``path``)."""
    root = parse_xml(text, path=path)
    warn = LoaderWarnings(path)
    full = xml_bool(root, "fullSymmetry", False, path)
    G: Group = cube_group() if full else square_group(3)
    xtiles = root.find("tiles")
    if xtiles is None:
        raise FormatError(f"<{root.tag}> has no <tiles> element", path=path, line=root.line)
    tiles: list[tuple[str, float, int]] = []
    seen: dict[str, int] = {}
    for xt in xtiles.iter("tile"):
        nm = xt.get("name")
        if not nm or not nm.strip() or " " in nm.strip():
            raise FormatError("<tile> needs a name without spaces", path=path, line=xt.line)
        if nm in seen:
            raise FormatError(f"tile {nm!r} is defined twice", path=path, line=xt.line)
        seen[nm] = len(tiles)
        tiles.append((nm, xml_float(xt, "weight", 1.0, path), xt.line))
    if not tiles:
        raise FormatError("the tileset has no tiles", path=path, line=xtiles.line)

    def ref(node: Node, side: str) -> tuple[int, int]:
        nm, turn = neighbor_side(node, side, path, seen, name_first=False,
                                 forms=("tile", "xyz tile"))  # fmt: skip
        word = turn or ""
        text = node.get(side)
        if not full:
            if set(word) - {"z"}:
                raise FormatError(
                    f"<neighbor> {side}={text!r}: only z turns exist without fullSymmetry",
                    path=path,
                    line=node.line,
                )
            word = word.replace("z", "a")
        try:
            g = G.index(word)
        except InputError as e:
            raise FormatError(
                f"<neighbor> {side}={text!r}: {e}", path=path, line=node.line
            ) from None
        return seen[nm], g

    stated: list[tuple[tuple[int, int], tuple[int, int], tuple[int, int]]] = []
    for node in xml_neighbors(root, path):
        if node.get("left") is not None or node.get("right") is not None:
            a = ref(node, "left")
            b = ref(node, "right")
            stated.append((a, b, (0, 1)))
        elif node.get("top") is not None or node.get("bottom") is not None:
            if full:
                raise FormatError(
                    "top/bottom rules are only for tilesets without fullSymmetry",
                    path=path,
                    line=node.line,
                )
            a = ref(node, "bottom")
            b = ref(node, "top")
            stated.append((a, b, (2, 1)))
        else:
            raise FormatError(
                "<neighbor> needs left/right or top/bottom", path=path, line=node.line
            )
    vox = _voxels(path, [t[0] for t in tiles], warn)
    if vox is not None:
        stabs = [
            frozenset(g for g in range(len(G)) if _same(transform_voxels(v, G.elements[g]), v))
            for v in vox
        ]
        how = "voxel data"
        vox_src = vox
    else:
        stabs, arms = _infer_stabilizers(G, len(tiles), stated)
        vox_src = [_socket_voxels(arms[t], t + 1) for t in range(len(tiles))]
        how = "inferred from the rules"
    orient = Orientations(G, stabs)
    rules = [(orient.label(ta, ga), orient.label(tb, gb), d) for (ta, ga), (tb, gb), d in stated]
    T = expand_rules(orient, rules, ndim=3)
    names = [
        _label_name(G, stabs[t], g, tiles[t][0])
        for t, g in zip(orient.tile_of, orient.rep, strict=True)
    ]
    weights = [tiles[t][1] for t in orient.tile_of]
    counts = {tiles[t][0]: len(G) // len(stabs[t]) for t in range(len(tiles))}
    if vox is None:
        warn.add(
            "tile voxel files not found: tile symmetries inferred from the rules "
            f"(orientations: {', '.join(f'{k} {v}' for k, v in counts.items())}); put the "
            "tiles' .vox files in a folder named after the XML file for MarkovJunior's exact "
            "semantics"
        )
    empty = None
    if vox is not None:
        empties = [t for t, v in enumerate(vox) if not v.any()]
        if empties:
            empty = orient.label(empties[0], 0)
    else:
        em = [t for t, (nm, _, _) in enumerate(tiles) if nm.lower() in ("empty", "air", "space")]
        if em and counts[tiles[em[0]][0]] == 1:
            empty = orient.label(em[0], 0)
    meta: dict[str, Any] = {
        "format": "markovjunior",
        "source": str(path),
        "full_symmetry": full,
        "symmetry_source": how,
        "orientations": counts,
        "rules_stated": len(stated),
        "warnings": warn.items,
    }
    label_vox = np.stack(
        [
            transform_voxels(vox_src[t], G.elements[g])
            for t, g in zip(orient.tile_of, orient.rep, strict=True)
        ]
    ).astype(np.uint8)
    if vox is None:
        from csplab.render import palette

        pal = np.zeros((256, 3), dtype=np.uint8)
        pal[1 : len(tiles) + 1] = palette(len(tiles) + 1)[1:]
    else:
        pal = _palette(path, [t[0] for t in tiles])
    rs = RuleSet(
        T,
        names=names,
        weights=weights,
        name=Path(str(path)).stem,
        empty=empty,
        voxels=label_vox,
        voxel_palette=pal,
        symmetry=(G, orient.perm),
        meta=meta,
    )
    meta["closure_violations"] = rs.closure_violations(limit=20)
    return rs


def _same(a: NDArray[Any], b: NDArray[Any]) -> bool:
    return a.shape == b.shape and bool(np.array_equal(a, b))


def _label_name(G: Group, H: frozenset[int], g: int, tile: str) -> str:
    words = [G.words[int(G.mul[g, h])] for h in H]
    best = min(words, key=lambda w: ("m" in w, len(w), w))
    if G.gen_names == ["a", "b"]:
        best = best.replace("a", "z")
    return f"{best} {tile}" if best else tile


def _socket_voxels(arms: list[bool], colour: int) -> NDArray[np.uint8]:
    """A 3x3x3 picture of a tile from its sockets: an arm towards every face whose socket is
    not the common one (pipes, for a tileset like Knots3D)."""
    v = np.zeros((3, 3, 3), dtype=np.uint8)
    if any(arms):
        v[1, 1, 1] = colour
    for (ax, sg), on in zip(_DIRS, arms, strict=True):
        if on:
            idx = [1, 1, 1]
            idx[ax] = 2 if sg > 0 else 0
            v[tuple(idx)] = colour
    return v


def _palette(path: object, names: list[str]) -> NDArray[np.uint8]:
    from csplab.io.vox import read_vox

    p = Path(str(path))
    models = [read_vox(p.parent / p.stem / f"{nm}.vox") for nm in names]
    best = max(models, key=lambda m: len(np.unique(m.grid)))  # the tile using most colours
    return np.ascontiguousarray(best.palette[:, :3])


def _infer_stabilizers(
    G: Group, ntiles: int, stated: list[tuple[tuple[int, int], tuple[int, int], tuple[int, int]]]
) -> tuple[list[frozenset[int]], list[list[bool]]]:
    """Tile symmetries from face sockets glued together by the stated rules, and which faces
    of each tile have a socket other than the most common one."""
    parent = list(range(ntiles * 6))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    def face(t: int, g: int, d: tuple[int, int]) -> int:
        f = G.apply(int(G.inv[g]), d)  # the base tile's face that ends up facing d
        return t * 6 + _DIRS.index(f)

    mentioned = set()
    for (ta, ga), (tb, gb), (axis, _) in stated:
        fa, fb = face(ta, ga, (axis, 1)), face(tb, gb, (axis, -1))
        mentioned |= {fa, fb}
        parent[find(fa)] = find(fb)
    roots = [find(i) for i in range(ntiles * 6)]
    sizes: dict[int, int] = {}
    for i in mentioned:
        sizes[roots[i]] = sizes.get(roots[i], 0) + 1
    default = max(sizes, key=lambda r: (sizes[r], -r)) if sizes else -1
    sock = [roots[i] if i in mentioned else default for i in range(ntiles * 6)]
    stabs = []
    for t in range(ntiles):
        H = []
        for g in range(len(G)):
            if all(
                sock[t * 6 + _DIRS.index(G.apply(g, d))] == sock[t * 6 + k]
                for k, d in enumerate(_DIRS)
            ):
                H.append(g)
        stabs.append(frozenset(H))
    arms = [[sock[t * 6 + k] != default for k in range(6)] for t in range(ntiles)]
    return stabs, arms


def _voxels(path: object, names: list[str], warn: LoaderWarnings) -> list[NDArray[np.uint8]] | None:
    p = Path(str(path))
    folder = p.parent / p.stem
    if not folder.is_dir():
        return None
    files = [folder / f"{nm}.vox" for nm in names]
    if not any(f.is_file() for f in files):
        return None
    missing = [f.name for f in files if not f.is_file()]
    if missing:
        warn.add(f"missing tile voxel files in {folder}: {', '.join(missing[:6])}")
        return None
    from csplab.io.vox import read_vox

    out = [read_vox(f).grid for f in files]
    if len({v.shape for v in out}) != 1:
        raise FormatError(f"tile voxel files in {folder} have different sizes", path=path)
    return out
