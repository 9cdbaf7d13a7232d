"""DeBroglie JSON configs (the ``adjacent`` model with explicit adjacencies).

The parts csplab reads (``//`` and ``/* */`` comments are allowed, as DeBroglie allows)::

    {
      "model": {"type": "adjacent"},            or {"type": "overlapping", "n": 3} with a PNG src
      "src": "tiles.tsx",                        a Tiled tileset: the tile pictures and
                                                 per-tile properties (a number is a tile's
                                                 gid, id + 1; a name its "name" property);
                                                 a PNG sample for "overlapping" (or "adjacent"
                                                 without adjacencies: learnt from the sample)
      "width": 10, "height": 10, "depth": 1, "periodic": false,
      "symmetry": 8,                             or rotationalSymmetry (1, 2, 4) and
                                                 reflectionalSymmetry (bool)
      "rotationTreatment": "unchanged",          or "missing"
      "tiles": [{"value": 6, "rotateCw": 17, "reflectX": 8, "changeFrequency": -0.9}, ...],
      "adjacencies": [{"left": [1, 8], "right": [1, 6]},   every left tile may be left of
                      {"up": [1, 6], "down": [1, 7]},      every right tile; up above down;
                      {"above": [..], "below": [..]}],     above on top of below (3D)
      "constraints": [{"type": "border", "tile": 1}, {"type": "fixedTile", ...}]
    }

Adjacencies hold in every frame of the symmetry group: a tile turned by a group element is
the tile its ``rotateCw``/``rotateCcw``/``reflectX``/``reflectY`` entries name (tiles
without entries are symmetric, ``rotationTreatment: "unchanged"``; with ``"missing"``
their turned forms do not exist and those adjacencies are not expanded). Weights are 1 plus
``changeFrequency``, times ``multiplyFrequency``. DeBroglie's ``y`` points down (image
rows); csplab's points up, so ``up`` is ``+y`` and pictures look the same.

Supported constraints: ``border`` (``tile``/``tiles``, ``sides``, ``excludeSides``,
``ban``) and ``fixedTile`` (``tile``/``tiles`` at ``point``) become domain restrictions;
``path`` (``tiles``, ``endPoints``), ``edgedPath`` (``exits``, ``endPoints``), ``count``
(``tiles``, ``comparison``, ``count``), ``mirrorX``/``mirrorY``, ``maxConsecutive``
(``tiles``, ``maxCount``, ``axes``) and ``separation`` (``tiles``, ``minDistance``) become
global constraints (:mod:`csplab.constraints`), which csplab's exact solvers enforce
exactly (DeBroglie enforces them heuristically while backtracking). Every other
constraint is reported as a warning and is NOT enforced; ``strict=True`` makes it an
error.

Examples
--------
>>> text = '''{"tiles": [{"value": "a", "rotateCw": "b"}, {"value": "b", "rotateCw": "a"}],
...   "symmetry": 8, "width": 3, "height": 2, // a and b swap under a quarter turn
...   "adjacencies": [{"left": ["a"], "right": ["b"]}]}'''
>>> rs = parse_debroglie(text, path="toy.json")
>>> rs.names, rs.relations[0].astype(int).tolist(), rs.relations[1].astype(int).tolist()
(('a', 'b'), [[0, 1], [1, 0]], [[0, 1], [1, 0]])
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from csplab.errors import FormatError
from csplab.io._json import load_json
from csplab.io.common import KIND, NO, LoaderWarnings, json_like, read_bytes
from csplab.io.ruleset import DomainOp, RuleSet
from csplab.io.symmetry import Group, square_group
from csplab.problem import AXIS_NAMES

__all__ = ["parse_debroglie", "read_debroglie", "sniff"]

_SIDES = {  # DeBroglie side name -> csplab face (DeBroglie y points down)
    "xmin": "x-", "xmax": "x+", "ymin": "y+", "ymax": "y-", "zmin": "z-", "zmax": "z+",
}  # fmt: skip


def sniff(head: bytes) -> int:
    """:data:`~csplab.io.common.KIND` for JSON (a POMS ``"rule"`` list scores higher)."""
    return KIND if json_like(head) else NO


def read_debroglie(path: str | Path, *, strict: bool = False) -> RuleSet:
    """Read a DeBroglie JSON config (see the module docstring).

    Parameters
    ----------
    path : str or Path
        The JSON file to read; a ``src`` sample is looked up next to it.
    strict : bool, optional
        Make unsupported constraints errors instead of warnings.

    Returns
    -------
    RuleSet
        The tiles with their adjacencies expanded over the symmetry group, weights, the
        output size and periodicity, ``border``/``fixedTile`` constraints as domain
        operations and the supported global constraints; unsupported parts are listed in
        ``meta["warnings"]`` (each also a :class:`UserWarning` naming the file).

    Raises
    ------
    FormatError
        Naming the file (and the line, where there is one) when it cannot be read, is larger than
        :data:`~csplab.io.common.MAX_FILE_BYTES` or is not a valid config (JSON errors, an
        unsupported model type, unknown tiles, a malformed adjacency or constraint, and with
        ``strict`` an unsupported constraint).
    """
    p = Path(path)
    return parse_debroglie(read_bytes(p), path=p, strict=strict)


def _key(v: Any, what: str, path: object) -> Any:
    if isinstance(v, bool) or not isinstance(v, int | str | float):
        raise FormatError(f"{what}: tile value must be a number or string, got {v!r}", path=path)
    return v


def _tile_list(v: Any, what: str, path: object) -> list[Any]:
    if not isinstance(v, list):
        v = [v]
    return [_key(t, what, path) for t in v]


def parse_debroglie(
    text: str | bytes, *, path: object = "<string>", strict: bool = False
) -> RuleSet:
    """Parse a DeBroglie JSON config into a :class:`RuleSet`."""
    d = load_json(text, path=path, comments=True)
    if not isinstance(d, dict):
        raise FormatError("a DeBroglie config is a JSON object", path=path)
    if set(d) == {"constraints"}:
        raise FormatError(
            "this is a constraints file (csplab.constraints), not a model: give it with "
            "--constraints",
            path=path,
        )
    warn = LoaderWarnings(path)

    def unsupported(msg: str) -> None:
        if strict:
            raise FormatError(msg, path=path)
        warn.add(msg)

    model = d.get("model", {}) or {}
    if not isinstance(model, dict):
        raise FormatError("'model' must be an object", path=path)
    mtype = str(model.get("type", "adjacent")).lower()
    src = d.get("src")
    if mtype == "overlapping" or (mtype == "adjacent" and not d.get("adjacencies")):
        return _from_sample(d, mtype, src, path, strict)
    if mtype != "adjacent":
        raise FormatError(
            f"model type {mtype!r} is not supported (adjacent, overlapping)", path=path
        )
    adj = d.get("adjacencies")
    if not isinstance(adj, list):
        raise FormatError("'adjacencies' must be a list", path=path)
    tiles = d.get("tiles", []) or []
    if not isinstance(tiles, list):
        raise FormatError("'tiles' must be a list", path=path)
    order: dict[Any, int] = {}

    def tid(v: Any) -> int:
        if v not in order:
            order[v] = len(order)
        return order[v]

    for i, t in enumerate(tiles):
        if not isinstance(t, dict) or "value" not in t:
            raise FormatError(f"tiles[{i}] must be an object with a 'value'", path=path)
        tid(_key(t["value"], f"tiles[{i}].value", path))
    stated: list[tuple[list[int], list[int], tuple[int, int]]] = []
    for i, a in enumerate(adj):
        if not isinstance(a, dict):
            raise FormatError(f"adjacencies[{i}] must be an object", path=path)
        pairs = [("left", "right", (0, 1)), ("down", "up", (1, 1)), ("below", "above", (2, 1))]
        hit = [(lo, hi, dr) for lo, hi, dr in pairs if lo in a or hi in a]
        if len(hit) != 1 or not all(k in a for k in hit[0][:2]):
            raise FormatError(
                f"adjacencies[{i}] needs exactly one of left/right, up/down, above/below",
                path=path,
            )
        lo, hi, dr = hit[0]
        A = [tid(v) for v in _tile_list(a[lo], f"adjacencies[{i}].{lo}", path)]
        B = [tid(v) for v in _tile_list(a[hi], f"adjacencies[{i}].{hi}", path)]
        stated.append((A, B, dr))
    K = len(order)
    if K == 0:
        raise FormatError("no tiles", path=path)
    ndim = 3 if any(dr[0] == 2 for _, _, dr in stated) or int(d.get("depth", 1) or 1) > 1 else 2
    G, perm = _tile_action(d, tiles, order, path, ndim)
    T = np.zeros((ndim, K, K), dtype=bool)
    for A, B, (axis, _) in stated:
        for g in range(len(G)):
            new_axis, sign = G.apply(g, (axis, 1))
            pa, pb = perm[g, A], perm[g, B]
            pa, pb = pa[pa >= 0], pb[pb >= 0]
            if sign > 0:
                T[new_axis][np.ix_(pa, pb)] = True
            else:
                T[new_axis][np.ix_(pb, pa)] = True
    weights = np.ones(K)
    for i, t in enumerate(tiles):
        k = order[t["value"]]
        for key in ("changeFrequency", "multiplyFrequency"):
            v = t.get(key)
            if v is not None and (isinstance(v, bool) or not isinstance(v, int | float)):
                raise FormatError(f"tiles[{i}].{key} must be a number", path=path)
        if t.get("changeFrequency") is not None:
            weights[k] += float(t["changeFrequency"])
        if t.get("multiplyFrequency") is not None:
            weights[k] *= float(t["multiplyFrequency"])
        if not np.isfinite(weights[k]) or weights[k] < 0:
            raise FormatError(f"tiles[{i}]: the frequency becomes {weights[k]:g} < 0", path=path)
        for key in ("tileSymmetry", "src"):
            if key in t:
                unsupported(f"tiles[{i}].{key} is not supported by csplab and is ignored")
    names = [str(v) for v in order]
    shape = _shape(d, ndim, path)
    boundary_ops, constraint_ops, global_ops = _constraints(d, order, K, ndim, path, unsupported)
    meta: dict[str, Any] = {
        "format": "debroglie",
        "source": str(path),
        "warnings": warn.items,
        "values": list(order),
        "group_order": len(G),
    }
    images = None
    tsx = Path(str(path)).parent / src if isinstance(src, str) else None
    if tsx is not None and tsx.suffix.lower() == ".tsx" and tsx.is_file():
        images = _tsx_pictures(tsx, list(order), meta, warn)
    rs = RuleSet(
        T,
        names=names,
        weights=weights,
        name=Path(str(path)).stem,
        shape=shape,
        periodic=bool(d.get("periodic", False)),
        boundary_ops=boundary_ops,
        constraint_ops=constraint_ops,
        constraints=global_ops,
        symmetry=(G, perm),
        meta=meta,
        images=images,
    )
    bad = rs.closure_violations(limit=20)
    meta["closure_violations"] = bad
    for msg in bad[:5]:
        warn.add(f"rule set not closed under the symmetry group: {msg}")
    # without a readable .tsx there are no tile pictures: say so, or a picture in one
    # colour per tile looks like a bug
    if images is None:
        where = ""
        if isinstance(src, str) and src:
            tsx_named = src.lower().endswith(".tsx")
            where = f" ({src!r} is not next to the config)" if tsx_named else (
                f" (csplab reads tile pictures from a Tiled .tsx, not {src!r})")  # fmt: skip
        if where or Path(str(path)).is_file():
            warn.add(f"no tile pictures{where}: pictures show one colour per tile")
    return rs


def _tsx_pictures(
    tsx: Path, values: list[Any], meta: dict[str, Any], warn: LoaderWarnings
) -> np.ndarray | None:
    """The tile pictures of ``values`` from a Tiled tileset, as DeBroglie finds them: a
    number is the tile's gid (its id + 1), a name the tile whose ``name`` (or ``value``)
    property it is; the tiles' properties go to ``meta["tile_properties"]``."""
    from csplab.io.tiled import read_tsx

    tiles = read_tsx(tsx)
    by_gid = {t.gid: t for t in tiles}
    by_name = {t.properties.get(k): t for t in tiles for k in ("name", "value")
               if t.properties.get(k) is not None}  # fmt: skip
    found = []
    for v in values:
        t = by_gid.get(v) if isinstance(v, int) else by_name.get(str(v))
        if t is None and isinstance(v, str) and v.isdigit():
            t = by_gid.get(int(v))
        found.append(t)
    missing = [str(v) for v, t in zip(values, found, strict=True) if t is None]
    if missing:
        warn.add(f"{tsx.name} has no tile {missing[0]}: pictures show one colour per tile")
        return None
    shapes = {t.image.shape for t in found if t is not None}
    if len(shapes) != 1:
        warn.add(f"{tsx.name}: tiles of different sizes; pictures show one colour per tile")
        return None
    meta["tile_properties"] = {
        str(v): dict(t.properties) for v, t in zip(values, found, strict=True) if t is not None
    }
    meta["tileset"] = str(tsx)
    return np.stack([t.image for t in found if t is not None])


def _shape(d: dict[str, Any], ndim: int, path: object) -> tuple[int, ...] | None:
    dims = []
    for key in ("width", "height", "depth")[:ndim]:
        v = d.get(key)
        if v is None:
            return None
        if isinstance(v, bool) or not isinstance(v, int) or v < 1:
            raise FormatError(f"'{key}' must be a positive integer, got {v!r}", path=path)
        dims.append(v)
    return tuple(dims)


def _group(d: dict[str, Any], path: object) -> Group:
    sym = d.get("symmetry")
    rot = d.get("rotationalSymmetry")
    refl = d.get("reflectionalSymmetry")
    if sym is not None:
        if isinstance(sym, bool) or not isinstance(sym, int) or sym not in (1, 2, 4, 8):
            raise FormatError(f"'symmetry' must be 1, 2, 4 or 8, got {sym!r}", path=path)
        rot = rot if rot is not None else (sym // 2 if sym % 2 == 0 else sym)
        refl = refl if refl is not None else sym % 2 == 0
    rot = 1 if rot is None else rot
    if rot not in (1, 2, 4):
        raise FormatError(f"'rotationalSymmetry' must be 1, 2 or 4, got {rot!r}", path=path)
    S = square_group()
    gens: dict[str, Any] = {}
    if rot == 4:
        gens["r"] = S.elements[S.index("aaa")]  # clockwise quarter turn: +x -> -y
    elif rot == 2:
        gens["h"] = S.elements[S.index("aa")]
    if refl:
        gens["m"] = S.elements[S.index("b")]
    return Group(gens, 2)


def _tile_action(
    d: dict[str, Any], tiles: list[Any], order: dict[Any, int], path: object, ndim: int
) -> tuple[Group, np.ndarray]:
    """The group and ``perm[g, tile]`` (``-1`` = that turned tile does not exist)."""
    G2 = _group(d, path)
    if ndim == 3:  # the same turns about the z axis
        gens = {}
        for nm, m in G2._gen_mats.items():
            m3 = np.eye(3, dtype=np.int64)
            m3[:2, :2] = m
            gens[nm] = m3
        G = Group(gens, 3)
    else:
        G = G2
    S = square_group()
    treat = str(d.get("rotationTreatment", "unchanged")).lower()
    if treat not in ("unchanged", "missing"):
        raise FormatError(
            f"rotationTreatment {treat!r} is not supported (unchanged, missing)", path=path
        )
    K = len(order)
    # facts over the full square group: img[s][t] = tile
    img: list[dict[int, int]] = [dict() for _ in range(len(S))]
    for t in range(K):
        img[0][t] = t
    words = {"rotateCw": "aaa", "rotateCcw": "a", "reflectX": "b", "reflectY": "baa"}
    for i, t in enumerate(tiles):
        a = order[t["value"]]
        for key, w in words.items():
            if key in t:
                b = order.get(_key(t[key], f"tiles[{i}].{key}", path))
                if b is None:
                    raise FormatError(f"tiles[{i}].{key}: unknown tile {t[key]!r}", path=path)
                _fact(img, S, S.index(w), a, b, path)
    _close(img, S, path)
    if treat == "unchanged":
        for t in range(K):
            for gen in ("a", "b"):
                g = S.index(gen)
                if t not in img[g]:
                    _fact(img, S, g, t, t, path)
                    _close(img, S, path)
    perm = np.full((len(G), K), -1, dtype=np.int64)
    for gi, m in enumerate(G.elements):
        s = S._index[np.ascontiguousarray(m[:2, :2], dtype=np.int8).tobytes()]
        for t in range(K):
            perm[gi, t] = img[s].get(t, -1)
    return G, perm


def _fact(img: list[dict[int, int]], S: Group, g: int, a: int, b: int, path: object) -> None:
    for gg, x, y in ((g, a, b), (int(S.inv[g]), b, a)):
        old = img[gg].get(x)
        if old is not None and old != y:
            raise FormatError(
                f"tile rotations are inconsistent: the transform {S.name(gg)} of one tile "
                "gives two different tiles",
                path=path,
            )
        img[gg][x] = y


def _close(img: list[dict[int, int]], S: Group, path: object) -> None:
    changed = True
    while changed:
        changed = False
        for g in range(len(S)):
            for x, y in list(img[g].items()):
                for h in range(len(S)):
                    z = img[h].get(y)
                    if z is None:
                        continue
                    hg = int(S.mul[h, g])
                    old = img[hg].get(x)
                    if old is None:
                        _fact(img, S, hg, x, z, path)
                        changed = True
                    elif old != z:
                        raise FormatError(
                            "tile rotations are inconsistent (they do not form a group action)",
                            path=path,
                        )


def _constraints(
    d: dict[str, Any], order: dict[Any, int], K: int, ndim: int, path: object, unsupported: Any
) -> tuple[list[DomainOp], list[DomainOp], list[dict[str, Any]]]:
    bops: list[DomainOp] = []
    cops: list[DomainOp] = []
    gops: list[dict[str, Any]] = []
    cons = d.get("constraints", []) or []
    if not isinstance(cons, list):
        raise FormatError("'constraints' must be a list", path=path)

    def labels(c: dict[str, Any], i: int) -> np.ndarray:
        vals = c.get("tiles", c.get("tile"))
        if vals is None:
            raise FormatError(f"constraints[{i}] needs 'tile' or 'tiles'", path=path)
        out = np.zeros(K, dtype=bool)
        for v in _tile_list(vals, f"constraints[{i}]", path):
            if v not in order:
                raise FormatError(f"constraints[{i}]: unknown tile {v!r}", path=path)
            out[order[v]] = True
        return out

    faces_all = [f"{a}{s}" for a in "xyz"[:ndim] for s in "-+"]

    def sides(v: Any, i: int) -> list[str]:
        if v is None:
            return []
        items = v if isinstance(v, list) else str(v).replace("|", ",").split(",")
        out = []
        for s in items:
            s = str(s).strip().lower()
            if s == "all":
                out += faces_all
            elif s in ("", "none"):
                continue
            elif s in _SIDES and _SIDES[s] in faces_all:
                out.append(_SIDES[s])
            else:
                raise FormatError(f"constraints[{i}]: unknown side {s!r}", path=path)
        return out

    for i, c in enumerate(cons):
        if not isinstance(c, dict):
            raise FormatError(f"constraints[{i}] must be an object", path=path)
        typ = str(c.get("type", ""))
        if typ == "border":
            lab = labels(c, i)
            chosen = sides(c.get("sides", "all"), i)
            excl = set(sides(c.get("excludeSides"), i))
            if c.get("invertArea"):
                unsupported(f"constraints[{i}] border invertArea is not supported and NOT applied")
                continue
            for f in chosen:
                if f in excl:
                    continue
                op = "remove" if c.get("ban") else "force"
                bops.append(DomainOp(op, lab, face=f, kind="boundary", key=f"{f} border"))  # type: ignore[arg-type]
        elif typ == "fixedTile":
            lab = labels(c, i)
            pt = c.get("point")
            if not isinstance(pt, dict):
                unsupported(f"constraints[{i}] fixedTile without a point is not supported")
                continue
            region = []
            for ax in "xyz"[:ndim]:
                v = pt.get(ax, 0)
                if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                    raise FormatError(
                        f"constraints[{i}].point.{ax} must be an integer ≥ 0", path=path
                    )
                region.append((v, v + 1))
            flip = [False, True, False][:ndim]
            cops.append(
                DomainOp(
                    "force", lab, region=region, flip=flip, kind="fixed", key=f"fixedTile {pt}"
                )
            )
        elif typ in _GLOBAL:
            spec = _global(c, typ, i, ndim, path, unsupported)
            if spec is not None:
                gops.append(spec)
        else:
            unsupported(
                f"constraints[{i}] type {typ!r} is not supported by csplab and is NOT "
                "enforced: outputs may violate it"
            )
    return bops, cops, gops


_GLOBAL = ("path", "edgedPath", "count", "mirrorX", "mirrorY", "maxConsecutive", "separation")
_EXIT = {  # DeBroglie exit direction -> csplab face (DeBroglie's y points down)
    "x-": "x-", "x+": "x+", "y-": "y+", "y+": "y-", "z-": "z-", "z+": "z+",
    "xmin": "x-", "xmax": "x+", "ymin": "y+", "ymax": "y-", "zmin": "z-", "zmax": "z+",
    "left": "x-", "right": "x+", "up": "y+", "down": "y-", "above": "z+", "below": "z-",
}  # fmt: skip


def _global(
    c: dict[str, Any], typ: str, i: int, ndim: int, path: object, unsupported: Any
) -> dict[str, Any] | None:
    """A DeBroglie constraint as an entry of csplab's constraints file
    (:mod:`csplab.constraints`; labels by name, ``y`` counted from the top as DeBroglie
    counts it: csplab's ``-1 - y``)."""
    where = f"constraints[{i}] ({typ})"

    def tiles(key: str = "tiles") -> list[str]:
        v = c.get(key, c.get("tile"))
        if v is None:
            raise FormatError(f"{where} needs {key!r}", path=path)
        return [str(t) for t in _tile_list(v, where, path)]

    def integer(key: str) -> int:
        v = c.get(key)
        if isinstance(v, bool) or not isinstance(v, int) or v < 0:
            raise FormatError(f"{where}.{key} must be an integer >= 0, got {v!r}", path=path)
        return v

    if typ in ("path", "edgedPath"):
        spec: dict[str, Any] = {"type": "connected"}
        if typ == "edgedPath":
            exits = c.get("exits")
            if not isinstance(exits, dict) or not exits:
                raise FormatError(f"{where} needs 'exits': {{tile: [directions]}}", path=path)
            ports: dict[str, list[str]] = {}
            for t, dirs in exits.items():
                out = []
                for dname in dirs if isinstance(dirs, list) else [dirs]:
                    f = _EXIT.get(str(dname).strip().lower())
                    if f is None or AXIS_NAMES.index(f[0]) >= ndim:
                        raise FormatError(
                            f"{where}: unknown exit {dname!r} of tile {t!r}", path=path
                        )
                    out.append(f)
                ports[str(t)] = out
            spec["labels"] = list(ports)
            spec["ports"] = ports
        else:
            spec["labels"] = tiles()
        pts = c.get("endPoints") or []
        cells = []
        for p in pts if isinstance(pts, list) else []:
            if not isinstance(p, dict):
                raise FormatError(f"{where}.endPoints must hold {{x, y[, z]}} objects", path=path)
            xyz = [p.get(a, 0) for a in "xyz"[:ndim]]
            if any(isinstance(v, bool) or not isinstance(v, int) or v < 0 for v in xyz):
                raise FormatError(
                    f"{where}.endPoints: coordinates must be integers >= 0", path=path
                )
            xyz[1] = -1 - xyz[1]  # DeBroglie's y points down
            cells.append(xyz)
        if cells:
            spec["cells"] = cells
        if c.get("endPointTiles"):
            unsupported(f"{where}: endPointTiles is not supported and NOT applied")
        return spec
    if typ == "count":
        cmp = str(c.get("comparison", "atMost")).lower()
        n = integer("count")
        bounds = {"atmost": (0, n), "atleast": (n, None), "exactly": (n, n)}.get(cmp)
        if bounds is None:
            raise FormatError(f"{where}.comparison must be atMost, atLeast or exactly", path=path)
        return {"type": "count", "labels": tiles(), "min": bounds[0], "max": bounds[1]}
    if typ in ("mirrorX", "mirrorY"):
        return {"type": "mirror", "axis": typ[-1].lower()}
    if typ == "maxConsecutive":
        spec = {"type": "max-run", "labels": tiles(), "n": integer("maxCount")}
        if c.get("axes") is not None:
            axes = c["axes"] if isinstance(c["axes"], list) else [c["axes"]]
            spec["axes"] = [str(a).lower()[:1] for a in axes]
        return spec
    return {"type": "separation", "labels": tiles(), "distance": integer("minDistance")}


def _from_tiled(d: dict[str, Any], mtype: str, f: Path, path: object) -> RuleSet:
    """An adjacent model learnt from a Tiled map sample (orthogonal or hexagonal, as
    DeBroglie reads them): the pairs of tiles the map shows along each relation of its
    grid (:mod:`csplab.io.tiled`, :mod:`csplab.topology`)."""
    from csplab.io.tiled import read_tmx
    from csplab.topology import Topology

    if mtype != "adjacent":
        raise FormatError(
            f"a {mtype} model of a Tiled map is not supported (adjacent is)", path=path
        )
    E = read_tmx(f)
    topo = Topology.parse(E.topology)
    T = topo.learn(E.labels, E.K) if not topo.square else E.transitions()
    shape = None
    w, h = d.get("width"), d.get("height")
    if isinstance(w, int) and isinstance(h, int) and w > 0 and h > 0:
        shape = (w, h)
    rs = RuleSet(
        T, names=E.names, weights=E.counts().astype(float), name=Path(str(path)).stem,
        shape=shape, periodic=bool(d.get("periodic", False)), topology=topo.name,
        meta={"format": "debroglie", "source": str(path), "sample": str(f)},
    )  # fmt: skip
    for i, c in enumerate(d.get("constraints", []) or []):
        typ = c.get("type") if isinstance(c, dict) else c
        rs.warnings.append(f"constraints[{i}] type {typ!r} is not supported for sample models "
                           "and NOT enforced")  # fmt: skip
    return rs


def _from_sample(d: dict[str, Any], mtype: str, src: Any, path: object, strict: bool) -> RuleSet:
    if not isinstance(src, str) or not src.lower().endswith((".png", ".bmp", ".gif", ".tmx")):
        raise FormatError(
            f"{'an' if mtype[:1].lower() in 'aeiou' else 'a'} {mtype} model without "
            "adjacencies needs a PNG or Tiled (.tmx) sample in "
            f"'src', got {src!r}",
            path=path,
        )
    f = Path(str(path)).parent / src
    if not f.is_file():
        raise FormatError(f"sample {src!r} not found next to the config", path=path)
    if src.lower().endswith(".tmx"):
        return _from_tiled(d, mtype, f, path)
    from csplab.io.overlap import OverlapModel

    model = d.get("model", {}) or {}
    n = int(model.get("n", 3)) if mtype == "overlapping" else 1
    sym = d.get("symmetry", 1)
    rs = OverlapModel.from_png(
        f,
        N=n,
        symmetry=int(sym) if isinstance(sym, int) and not isinstance(sym, bool) else 1,
        periodic_input=bool(d.get("periodicInput", True)),
    )
    for i, c in enumerate(d.get("constraints", []) or []):
        typ = c.get("type") if isinstance(c, dict) else c
        msg = f"constraints[{i}] type {typ!r} is not supported for sample models and NOT enforced"
        if strict:
            raise FormatError(msg, path=path)
        rs.warnings.append(msg)
    w, h = d.get("width"), d.get("height")
    if isinstance(w, int) and isinstance(h, int) and w > 0 and h > 0:
        rs.shape = (w, h)
    rs.periodic = bool(d.get("periodic", False))
    return rs
