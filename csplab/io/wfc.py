"""WaveFunctionCollapse simple-tiled tilesets (mxgmn's XML format).

Layout::

    <set unique="False">                       unique: one image per orientation
      <tiles>
        <tile name="corner" symmetry="L" weight="0.5"/>
        ...
      </tiles>
      <neighbors>
        <neighbor left="corner 1" right="line"/>   "name k": k = 0..7 (default 0), see
        ...                                        below; right may be the +x neighbour
      </neighbors>
      <subsets>
        <subset name="small"><tile name="corner"/>...</subset>
      </subsets>
    </set>

A tile of symmetry class X, L, T, I, \\ or F has 1, 4, 4, 2, 2 or 8 orientations (labels
``"corner 0"`` ... ``"corner 3"``): orientation ``k < 4`` is the tile turned ``k`` quarter
turns counter-clockwise, ``k >= 4`` that turned ``k - 4`` times and mirrored left-right,
as WaveFunctionCollapse numbers them. A neighbour ``"name k"`` is resolved as
WaveFunctionCollapse resolves it, through the tile's 8-element action table
(:func:`wfc_action`): ``k`` may be 0..7 for every tile, and for ``k`` beyond the tile's
orientations it names the orientation the table gives (``"line 3"`` of a symmetry-``I``
tile is ``"line 1"``). Rules are stated for ``+x`` and hold in every frame of
the square's symmetry group (:mod:`csplab.io.symmetry`); vertical rules follow from the
rotations. Tile images are read from a folder named after the XML file next to it (or
from the XML file's own folder): ``corner.png``, or ``corner 0.png``, ``corner 1.png``
... for ``unique`` tilesets. Image rows run top to bottom and csplab's ``y`` points up,
so pictures look as in WaveFunctionCollapse.

Examples
--------
>>> xml = '''<set><tiles><tile name="sea"/><tile name="coast" symmetry="T"/></tiles>
... <neighbors><neighbor left="sea" right="sea"/><neighbor left="coast 1" right="sea"/>
... <neighbor left="coast" right="coast"/></neighbors></set>'''
>>> rs = parse_wfc(xml, path="toy.xml")
>>> rs.K, rs.names
(5, ('sea 0', 'coast 0', 'coast 1', 'coast 2', 'coast 3'))
>>> rs.closure_violations()
[]
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.errors import FormatError
from csplab.io._xml import Node, parse_xml
from csplab.io.common import (
    KIND,
    NO,
    LoaderWarnings,
    load_image,
    neighbor_side,
    read_bytes,
    xml_bool,
    xml_float,
    xml_neighbors,
    xml_root,
)
from csplab.io.ruleset import RuleSet
from csplab.io.symmetry import Group, Orientations, expand_rules, square_group

__all__ = ["CARDINALITY", "parse_wfc", "read_wfc", "sniff", "stabilizer_words", "wfc_action"]

CARDINALITY = {"X": 1, "L": 4, "T": 4, "I": 2, "\\": 2, "F": 8}
# words generating the symmetry group of orientation 0 (a: quarter turn +x -> +y, b: x-mirror)
_STAB: dict[str, list[str]] = {
    "X": ["a", "b"],
    "I": ["aa", "b"],
    "\\": ["aa", "aaab"],
    "T": ["b"],
    "L": ["aaab"],
    "F": [],
}
_ORDER = ["", "a", "aa", "aaa", "b", "ba", "baa", "baaa"]  # orientation k = this element


# WaveFunctionCollapse's maps a (quarter turn) and b (mirror) on a tile's orientation indices
_A: dict[str, Callable[[int], int]] = {
    "L": lambda i: (i + 1) % 4,
    "T": lambda i: (i + 1) % 4,
    "I": lambda i: 1 - i,
    "\\": lambda i: 1 - i,
    "F": lambda i: (i + 1) % 4 if i < 4 else 4 + (i - 1) % 4,
    "X": lambda i: i,
}
_B: dict[str, Callable[[int], int]] = {
    "L": lambda i: i + 1 if i % 2 == 0 else i - 1,
    "T": lambda i: i if i % 2 == 0 else 4 - i,
    "I": lambda i: i,
    "\\": lambda i: 1 - i,
    "F": lambda i: i + 4 if i < 4 else i - 4,
    "X": lambda i: i,
}


def wfc_action(symmetry: str) -> list[list[int]]:
    """WaveFunctionCollapse's action table of a symmetry class: row ``t`` (one per
    orientation) lists the orientations ``t, a(t), a(a(t)), a(a(a(t)))`` and their images
    under ``b``; a neighbour ``"name k"`` is orientation ``wfc_action(sym)[0][k]``.

    Examples
    --------
    >>> wfc_action("I")[0], wfc_action("L")[0]
    ([0, 1, 0, 1, 0, 1, 0, 1], [0, 1, 2, 3, 1, 0, 3, 2])
    """
    a, b = _A[symmetry], _B[symmetry]
    rows = []
    for t in range(CARDINALITY[symmetry]):
        r = [t, a(t), a(a(t)), a(a(a(t)))]
        rows.append(r + [b(i) for i in r])
    return rows


def stabilizer_words(symmetry: str) -> list[str]:
    """Generators (words in ``a``, ``b``) of the symmetry group of a WFC symmetry class."""
    return list(_STAB[symmetry])


def _transform(img: NDArray[np.uint8], word: str) -> NDArray[np.uint8]:
    """Apply a word in ``a`` (counter-clockwise quarter turn) and ``b`` (left-right mirror) to
    an image array (rows top to bottom), right to left."""
    out = img
    for ch in reversed(word):
        out = np.rot90(out, 1) if ch == "a" else out[:, ::-1]
    return np.ascontiguousarray(out)


def sniff(head: bytes) -> int:
    """:data:`~csplab.io.common.KIND` for XML (a MarkovJunior ``<tileset>`` scores higher)."""
    return NO if xml_root(head) is None else KIND


def read_wfc(path: str | Path, *, subset: str | None = None, images: bool = True) -> RuleSet:
    """Read a WaveFunctionCollapse simple-tiled XML tileset (see the module docstring).

    Parameters
    ----------
    path : str or Path
        The XML file to read; tile images are looked up next to it.
    subset : str, optional
        Use only the tiles of this ``<subset>`` (default: every tile).
    images : bool, optional
        Read the tile pictures (for PNG output); ``False`` reads the rules alone.

    Returns
    -------
    RuleSet
        One label per tile orientation (``"name k"``), the ``+x`` rules expanded over the
        square's symmetry group, the tiles' weights and pictures; ``meta["warnings"]``
        lists what was skipped (each also a :class:`UserWarning` naming the file).

    Raises
    ------
    FormatError
        Naming the file (and the line, where there is one) when it cannot be read, is larger than
        :data:`~csplab.io.common.MAX_FILE_BYTES` or is not a valid tileset (no ``<tiles>``, an
        unknown symmetry, tile or subset, a neighbour naming an unknown tile, a bad attribute ...).
    """
    p = Path(path)
    return parse_wfc(read_bytes(p), path=p, subset=subset, images=images)


def parse_wfc(
    text: str | bytes,
    *,
    path: object = "<string>",
    subset: str | None = None,
    images: bool = True,
) -> RuleSet:
    """Parse WaveFunctionCollapse simple-tiled XML (images looked up next to ``path``)."""
    root = parse_xml(text, path=path)
    return _build(root, path=path, subset=subset, images=images)


def _build(root: Node, *, path: object, subset: str | None, images: bool) -> RuleSet:
    warn = LoaderWarnings(path)
    xtiles = root.find("tiles")
    if xtiles is None:
        raise FormatError(f"<{root.tag}> has no <tiles> element", path=path, line=root.line)
    unique = xml_bool(root, "unique", False, path)
    wanted: set[str] | None = None
    if subset is not None:
        xsubsets = root.find("subsets")
        names_ = [s.get("name") for s in xsubsets.iter("subset")] if xsubsets else []
        xs = (
            next((s for s in xsubsets.iter("subset") if s.get("name") == subset), None)
            if xsubsets
            else None
        )
        if xs is None:
            raise FormatError(
                f"no subset {subset!r}; subsets: {', '.join(n for n in names_ if n) or 'none'}",
                path=path,
            )
        wanted = set()
        for t in xs.iter("tile"):
            nm = t.get("name")
            if nm is None:
                raise FormatError("<tile> in <subset> has no name", path=path, line=t.line)
            wanted.add(nm)
    G = square_group()
    tiles: list[tuple[str, str, float, int]] = []  # name, symmetry, weight, line
    seen: dict[str, int] = {}
    all_names: set[str] = set()
    for xt in xtiles.iter("tile"):
        nm = xt.get("name")
        if not nm or not nm.strip():
            raise FormatError("<tile> has no name", path=path, line=xt.line)
        if nm in all_names:
            raise FormatError(f"tile {nm!r} is defined twice", path=path, line=xt.line)
        all_names.add(nm)
        sym = xt.get("symmetry", "X") or "X"
        if sym not in CARDINALITY:
            raise FormatError(
                f"tile {nm!r}: unknown symmetry {sym!r} (use X, L, T, I, \\ or F)",
                path=path,
                line=xt.line,
            )
        w = xml_float(xt, "weight", 1.0, path)
        if wanted is not None and nm not in wanted:
            continue
        seen[nm] = len(tiles)
        tiles.append((nm, sym, w, xt.line))
    if wanted is not None and wanted - all_names:
        raise FormatError(
            f"subset {subset!r} names unknown tiles {sorted(wanted - all_names)}", path=path
        )
    if not tiles:
        raise FormatError("the tileset has no tiles", path=path, line=xtiles.line)
    stabs = [G.subgroup(_STAB[sym]) for _, sym, _, _ in tiles]
    order = [[G.index(w) for w in _ORDER[: CARDINALITY[sym]]] for _, sym, _, _ in tiles]
    orient = Orientations(G, stabs, order)
    names = [f"{nm} {k}" for nm, sym, _, _ in tiles for k in range(CARDINALITY[sym])]
    weights = [w for _, sym, w, _ in tiles for _ in range(CARDINALITY[sym])]

    def ref(node: Node, side: str) -> int | None:
        nm, turn = neighbor_side(node, side, path, all_names, name_first=True,
                                 forms=("name", "name k"))  # fmt: skip
        if nm not in seen:  # outside the chosen subset
            return None
        t = seen[nm]
        text = node.get(side)
        try:
            k = int(turn) if turn is not None else 0
        except ValueError:
            raise FormatError(
                f"<neighbor> {side}={text!r}: orientation {turn!r} is not an integer",
                path=path,
                line=node.line,
            ) from None
        if not 0 <= k < 8:  # WFC indexes its 8-element action table with k
            raise FormatError(
                f"<neighbor> {side}={text!r}: orientation {k} is not 0..7",
                path=path,
                line=node.line,
            )
        return orient.label(t, order[t][wfc_action(tiles[t][1])[0][k]])

    rules = []
    for node in xml_neighbors(root, path):
        a = ref(node, "left")
        b = ref(node, "right")
        if a is not None and b is not None:
            rules.append((a, b, (0, 1)))
    if not rules:
        warn.add("no <neighbor> rules: no tile may touch another")
    T = expand_rules(orient, rules)
    imgs = _images(path, tiles, unique, G, warn) if images else None
    meta: dict[str, Any] = {
        "format": "wfc",
        "source": str(path),
        "unique": unique,
        "subset": subset,
        "tiles": [{"name": nm, "symmetry": sym, "weight": w} for nm, sym, w, _ in tiles],
        "rules_stated": len(rules),
        "warnings": warn.items,
    }
    stem = Path(str(path)).stem
    rs = RuleSet(
        T,
        names=names,
        weights=weights,
        name=stem + (f"[{subset}]" if subset else ""),
        images=imgs,
        symmetry=(G, orient.perm),
        meta=meta,
    )
    bad = rs.closure_violations(limit=20)
    meta["closure_violations"] = bad
    for msg in bad[:5]:
        warn.add(f"rule set not closed under the square's symmetries: {msg}")
    return rs


def _images(
    path: object,
    tiles: list[tuple[str, str, float, int]],
    unique: bool,
    G: Group,
    warn: LoaderWarnings,
) -> NDArray[np.uint8] | None:
    p = Path(str(path))
    if not p.parent.exists():
        return None
    folders = [p.parent / p.stem, p.parent]
    folder = next(
        (
            f
            for f in folders
            if f.is_dir()
            and any(
                (f / (f"{nm}.png" if not unique else f"{nm} 0.png")).is_file() for nm, *_ in tiles
            )
        ),
        None,
    )
    if folder is None:
        if p.is_file():  # a tileset read from a file whose pictures are not there
            first = tiles[0][0] + (" 0" if unique else "")
            warn.add(
                f"no tile pictures found (looked for {folders[0].name}/{first}.png and "
                f"{first}.png next to the file): pictures show one colour per tile"
            )
        return None
    out: list[NDArray[np.uint8] | None] = []
    missing = []
    for nm, sym, _, _ in tiles:
        card = CARDINALITY[sym]
        if unique:
            for k in range(card):
                f = folder / f"{nm} {k}.png"
                out.append(load_image(f) if f.is_file() else None)
                if out[-1] is None:
                    missing.append(f.name)
        else:
            f = folder / f"{nm}.png"
            if not f.is_file():
                missing.append(f.name)
                out.extend([None] * card)
                continue
            base = load_image(f)
            if base.shape[0] != base.shape[1]:
                raise FormatError(
                    f"tile image is {base.shape[1]}x{base.shape[0]}, not square", path=f
                )
            for w in _STAB[sym]:
                if not np.array_equal(_transform(base, w), base):
                    warn.add(
                        f"tile {nm!r} is declared symmetry {sym} but its image changes under "
                        f"{'the mirror' if w.endswith('b') else 'a turn'} ({w})"
                    )
                    break
            out.extend(_transform(base, w) for w in _ORDER[:card])
    shapes = {o.shape for o in out if o is not None}
    if len(shapes) > 1:
        raise FormatError(f"tile images have different sizes {sorted(shapes)}", path=folder)
    if missing:
        warn.add(f"missing tile images in {folder}: {', '.join(missing[:6])}; drawn as colours")
    if not shapes:
        return None
    h, w, _ = shapes.pop()
    from csplab.render import palette

    cols = palette(len(out))
    arr = np.zeros((len(out), h, w, 4), dtype=np.uint8)
    for i, o in enumerate(out):
        if o is None:
            arr[i, :, :, :3] = cols[i]
            arr[i, :, :, 3] = 255
        else:
            arr[i] = o
    return arr
