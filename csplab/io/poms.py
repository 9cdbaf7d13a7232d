"""PunchOutModelSynthesis (POMS) JSON configs.

The parts csplab reads::

    {
      "rule":   [[src, dst, dir, val], ...],   dst may be the neighbour of src in direction
                                               dir (0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z) if val > 0
      "name":   ["empty", "ground", ...],      one per tile (default "0", "1", ...)
      "weight": [1, 2, ...],                   one per tile (default 1)
      "size":   [X, Y, Z],                     the default output size
      "boundaryCondition": {"x+": {"type": "tile", "value": 0}, ...},
      "constraint": [{"type": "remove", "range": {"tile": [0, 1], "x": [], "y": [], "z": []}}],
      "objMap": ["tiles/e.obj", ...],          optional mesh per tile (for .obj export)
      "tileset": {"image": "...png", "tilewidth": 8, "tileheight": 8, ...}   optional pictures
    }

Meaning, as in POMS: a boundary condition ``{"type": "tile", "value": v}`` on face ``x+``
puts a virtual tile ``v`` just outside the grid, so the cells on that face keep only the
tiles that ``v`` may follow. Constraints are applied after the boundary conditions, in file
order; ranges are half-open ``[start, stop)``, ``[start]`` runs to the end, ``[]`` is
everything, negative numbers count from the end. ``remove``/``quiltRemove`` remove the
tiles, ``add``/``quiltAdd`` put them back, ``force``/``pin`` and their ``quilt`` forms set
the domain to the tiles (csplab solves the whole grid at once, so quilt and block ranges
are the same). Other constraint or boundary types are reported as warnings, never dropped
silently.

Axes: a config whose size has ``Z = 1`` is a 2D tile map in image coordinates (``y``
down); csplab flips it so that ``y`` points up and pictures look the same. A 3D config
with an ``objMap`` uses the OBJ convention (``y`` up); csplab (``z`` up) reads POMS
``(x, y, z)`` as ``(x, -z, y)``, a rotation, so the ``.obj`` export puts every piece back
where POMS would (``up="z"`` keeps the axes as they are).

Examples
--------
>>> text = '''{"rule": [[0,0,0,1],[0,0,2,1],[0,1,2,1],[1,0,2,1],[1,1,0,1]],
...            "name": ["sky", "land"], "size": [4, 3, 1],
...            "boundaryCondition": {"y+": {"type": "tile", "value": 1}}}'''
>>> rs = parse_poms(text, path="toy.json")
>>> rs.ndim, rs.shape, rs.names
(2, (4, 3), ('sky', 'land'))
>>> [(u.key, rs.problem().label_name(int(u.allowed[0].argmax()))) for u in rs.problem().unary]
[('y-', 'sky')]
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from csplab.errors import FormatError
from csplab.io._json import load_json
from csplab.io.common import NO, SURE, LoaderWarnings, json_like, load_image, read_bytes
from csplab.io.ruleset import DomainOp, RuleSet
from csplab.problem import AXIS_NAMES

__all__ = ["parse_poms", "read_poms", "sniff"]

MAX_TILES = 100_000
_DIRS = [(0, 1), (0, -1), (1, 1), (1, -1), (2, 1), (2, -1)]  # POMS dir -> (axis, sign)
_OPS = {
    "remove": "remove",
    "quiltremove": "remove",
    "add": "add",
    "quiltadd": "add",
    "force": "force",
    "quiltforce": "force",
    "pin": "force",
    "quiltpin": "force",
}


def sniff(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for JSON with a ``"rule"`` key."""
    return SURE if json_like(head) and re.search(rb'"rule"\s*:', head) else NO


def read_poms(path: str | Path, *, up: Literal["auto", "y", "z"] = "auto") -> RuleSet:
    """Read a POMS JSON config (see the module docstring).

    Parameters
    ----------
    path : str or Path
        The JSON file to read; a ``tileset`` image is looked up next to it.
    up : {"auto", "y", "z"}, optional
        For 3D configs: ``"y"`` reads them ``y``-up (POMS ``(x, y, z)`` becomes csplab's
        ``(x, -z, y)``), ``"z"`` keeps the axes, ``"auto"`` is ``"y"`` when the config has
        an ``objMap``.

    Returns
    -------
    RuleSet
        The tiles with their rules, weights and names, the default output size, the
        boundary conditions and constraints as domain operations, and the pieces or tile
        pictures; unsupported parts are listed in ``meta["warnings"]`` (each also a
        :class:`UserWarning` naming the file).

    Raises
    ------
    FormatError
        Naming the file (and the line, where there is one) when it cannot be read, is larger than
        :data:`~csplab.io.common.MAX_FILE_BYTES` or is not a valid POMS config (not a JSON object,
        no rules, a rule, size, boundary condition or constraint of the wrong form ...).
    """
    p = Path(path)
    return parse_poms(read_bytes(p), path=p, up=up)


def _int(v: Any, what: str, path: object) -> int:
    if isinstance(v, bool) or not isinstance(v, int | float) or v != int(v):
        raise FormatError(f"{what} must be an integer, got {v!r}", path=path)
    return int(v)


def _range(v: Any, what: str, path: object) -> tuple[int | None, int | None]:
    if v is None or v == []:
        return (None, None)
    if not isinstance(v, list) or len(v) > 2:
        raise FormatError(f"{what} must be [], [start] or [start, stop], got {v!r}", path=path)
    a = _int(v[0], what, path)
    b = _int(v[1], what, path) if len(v) == 2 else None
    return (a, b)


def parse_poms(
    text: str | bytes, *, path: object = "<string>", up: Literal["auto", "y", "z"] = "auto"
) -> RuleSet:
    """Parse a POMS JSON config into a :class:`RuleSet`."""
    d = load_json(text, path=path)
    if not isinstance(d, dict):
        raise FormatError("a POMS config is a JSON object", path=path)
    warn = LoaderWarnings(path)
    rules = d.get("rule")
    if not isinstance(rules, list) or not rules:
        raise FormatError("'rule' must be a non-empty list of [src, dst, dir, val]", path=path)
    arr = np.zeros((len(rules), 4), dtype=np.float64)
    for i, r in enumerate(rules):
        if not isinstance(r, list) or len(r) not in (3, 4):
            raise FormatError(f"rule[{i}] must be [src, dst, dir, val], got {r!r}", path=path)
        for j, v in enumerate(r):
            if isinstance(v, bool) or not isinstance(v, int | float) or not np.isfinite(v):
                raise FormatError(f"rule[{i}][{j}] is not a number: {v!r}", path=path)
            arr[i, j] = v
        if len(r) == 3:
            arr[i, 3] = 1.0
    src, dst, dr = arr[:, 0], arr[:, 1], arr[:, 2]
    for what, col in (("tile", src), ("tile", dst), ("direction", dr)):
        if np.any(col != np.round(col)) or np.any(col < 0):
            i = int(np.flatnonzero((col != np.round(col)) | (col < 0))[0])
            raise FormatError(f"rule[{i}]: {what} must be a non-negative integer", path=path)
    if np.any(dr > 5):
        i = int(np.flatnonzero(dr > 5)[0])
        raise FormatError(f"rule[{i}]: direction {int(dr[i])} is not 0..5", path=path)
    names = d.get("name")
    Kmax = int(max(src.max(), dst.max())) + 1
    if names is not None:
        if not isinstance(names, list) or not all(isinstance(s, str | int) for s in names):
            raise FormatError("'name' must be a list of strings", path=path)
        K = len(names)
    else:
        K = Kmax
    if K > MAX_TILES:
        raise FormatError(f"{K} tiles is too many", path=path)
    if Kmax > K:
        i = int(np.flatnonzero(np.maximum(src, dst) >= K)[0])
        raise FormatError(f"rule[{i}] names tile {int(max(src[i], dst[i]))} of {K}", path=path)
    weights = d.get("weight")
    if weights is not None:
        if not isinstance(weights, list) or len(weights) != K:
            raise FormatError(f"'weight' must be a list of {K} numbers", path=path)
        for i, w in enumerate(weights):
            if (
                isinstance(w, bool)
                or not isinstance(w, int | float)
                or not w >= 0
                or w == float("inf")
            ):
                raise FormatError(
                    f"weight[{i}] must be a non-negative number, got {w!r}", path=path
                )
    F = np.zeros((6, K, K), dtype=bool)  # F[dir, a, b]: b may be in direction dir of a
    ok = arr[:, 3] > 0
    F[dr[ok].astype(int), src[ok].astype(int), dst[ok].astype(int)] = True
    opp = [1, 0, 3, 2, 5, 4]
    one_way = int((F & ~F[opp].transpose(0, 2, 1)).sum())
    if one_way:
        warn.add(
            f"{one_way} rules are stated in one direction only; csplab uses every rule both ways"
        )
    size = d.get("size")
    shape3: tuple[int, int, int] | None = None
    if size is not None:
        if not isinstance(size, list) or len(size) != 3:
            raise FormatError(f"'size' must be [X, Y, Z], got {size!r}", path=path)
        sx, sy, sz = (_int(v, "size", path) for v in size)
        if min(sx, sy, sz) < 1:
            raise FormatError(f"'size' must be positive, got {size!r}", path=path)
        shape3 = (sx, sy, sz)
    two_d = (shape3[2] == 1) if shape3 is not None else not bool(F[4:].any())
    if up not in ("auto", "y", "z"):
        raise FormatError(f"up must be 'auto', 'y' or 'z', not {up!r}", path=path)
    y_up = not two_d and (up == "y" or (up == "auto" and d.get("objMap") is not None))
    # axis map: csplab axis -> (POMS axis, flipped)
    if two_d:
        amap = [(0, False), (1, True)]
    elif y_up:
        amap = [(0, False), (2, True), (1, False)]
    else:
        amap = [(0, False), (1, False), (2, False)]
    ndim = len(amap)
    T = np.zeros((ndim, K, K), dtype=bool)
    for c, (pa, flip) in enumerate(amap):
        fwd, back = F[2 * pa], F[2 * pa + 1]
        both = fwd | back.T  # b at +pa of a
        T[c] = both.T if flip else both
    csp_face: dict[str, str] = {}
    for c, (pa, flip) in enumerate(amap):
        for s in "+-":
            t = {"+": "-", "-": "+"}[s] if flip else s
            csp_face[f"{'xyz'[pa]}{s}"] = f"{AXIS_NAMES[c]}{t}"

    boundary_ops: list[DomainOp] = []
    base_keep = np.ones(K, dtype=bool)
    bc = d.get("boundaryCondition", {}) or {}
    if not isinstance(bc, dict):
        raise FormatError("'boundaryCondition' must be an object", path=path)
    for face, spec in bc.items():
        if face not in ("x+", "x-", "y+", "y-", "z+", "z-"):
            raise FormatError(f"boundaryCondition: unknown face {face!r}", path=path)
        if not isinstance(spec, dict):
            raise FormatError(f"boundaryCondition[{face!r}] must be an object", path=path)
        typ = spec.get("type")
        if typ != "tile":
            warn.add(f"boundaryCondition[{face!r}] type {typ!r} is not supported and NOT applied")
            continue
        v = _int(spec.get("value"), f"boundaryCondition[{face!r}].value", path)
        if not 0 <= v < K:
            raise FormatError(f"boundaryCondition[{face!r}]: tile {v} of {K}", path=path)
        pdir = "xyz".index(face[0]) * 2 + (0 if face[1] == "+" else 1)
        allowed = F[pdir, :, v] | F[opp[pdir], v, :]
        if face not in csp_face:  # the z faces of a 2D map: every cell touches them
            base_keep &= allowed
            continue
        boundary_ops.append(DomainOp("keep", allowed, face=csp_face[face], kind="boundary"))
    constraint_ops: list[DomainOp] = []
    if not base_keep.all():
        constraint_ops.append(DomainOp("keep", base_keep, key="z boundary (2D map)"))
    cons = d.get("constraint", []) or []
    if not isinstance(cons, list):
        raise FormatError("'constraint' must be a list", path=path)
    for i, c in enumerate(cons):
        if not isinstance(c, dict):
            raise FormatError(f"constraint[{i}] must be an object", path=path)
        typ = str(c.get("type", ""))
        op = _OPS.get(typ.lower())
        if op is None:
            warn.add(f"constraint[{i}] type {typ!r} is not supported by csplab and is NOT applied")
            continue
        rng = c.get("range", {}) or {}
        if not isinstance(rng, dict):
            raise FormatError(f"constraint[{i}].range must be an object", path=path)
        ta, tb = _range(rng.get("tile"), f"constraint[{i}].range.tile", path)
        labels = np.zeros(K, dtype=bool)
        labels[slice(ta, tb)] = True
        box = {ax: _range(rng.get(ax), f"constraint[{i}].range.{ax}", path) for ax in "xyz"}
        if two_d:
            za, zb = box["z"]
            if not np.arange(1)[slice(za, zb)].size:
                continue  # the range misses the map's only layer
        region = [box["xyz"[pa]] for pa, _ in amap]
        constraint_ops.append(
            DomainOp(
                op,  # type: ignore[arg-type]
                labels,
                region=region,
                flip=[f for _, f in amap],
                kind="domain",
                key=f"constraint[{i}] {typ}",
            )
        )
    shape = None
    if shape3 is not None:
        shape = tuple(shape3[pa] for pa, _ in amap)
    empty = None
    vals = {s.get("value") for s in bc.values() if isinstance(s, dict) and s.get("type") == "tile"}
    if len(vals) == 1:
        v0 = vals.pop()
        empty = v0 if isinstance(v0, int) and 0 <= v0 < K else None
    meta: dict[str, Any] = {
        "format": "poms",
        "source": str(path),
        "warnings": warn.items,
        "axes": "csplab (x, y) = POMS (x, -y)"
        if two_d
        else (
            "csplab (x, y, z) = POMS (x, -z, y)" if y_up else "csplab (x, y, z) = POMS (x, y, z)"
        ),
    }
    pieces = _pieces(d.get("objMap"), path, K, warn)
    if pieces:
        meta["pieces"] = pieces
    images = _tile_images(d.get("tileset"), path, K, warn) if two_d else None
    nm = [str(s) for s in names] if names is not None else None
    return RuleSet(
        T,
        names=nm,
        weights=weights,
        name=Path(str(path)).stem,
        shape=shape,
        boundary_ops=boundary_ops,
        constraint_ops=constraint_ops,
        images=images,
        empty=empty,
        meta=meta,
    )


def _pieces(objmap: Any, path: object, K: int, warn: LoaderWarnings) -> dict[int, str]:
    if objmap is None:
        return {}
    if not isinstance(objmap, list) or len(objmap) != K:
        raise FormatError(f"'objMap' must be a list of {K} file names", path=path)
    base = Path(str(path)).parent
    out: dict[int, str] = {}
    for t, f in enumerate(objmap):
        if not isinstance(f, str):
            raise FormatError(f"objMap[{t}] must be a file name", path=path)
        for root in (base, base.parent):
            cand = root / f.replace("//", "/")
            if f and cand.is_file():
                out[t] = str(cand)
                break
    if objmap and not out:
        warn.add("objMap meshes not found next to the config; .obj export draws cubes")
    return out


def _tile_images(ts: Any, path: object, K: int, warn: LoaderWarnings) -> NDArray[np.uint8] | None:
    """Tiled-style tileset image: tile ``t >= 1`` is image tile ``t - 1`` (row major)."""
    if not isinstance(ts, dict) or not isinstance(ts.get("image"), str):
        return None
    base = Path(str(path)).parent
    f = next((r / ts["image"] for r in (base, base.parent) if (r / ts["image"]).is_file()), None)
    if f is None:
        return None
    img = load_image(f)
    try:
        tw, th = int(ts["tilewidth"]), int(ts["tileheight"])
    except (KeyError, TypeError, ValueError):
        raise FormatError("'tileset' needs integer tilewidth and tileheight", path=path) from None
    if tw < 1 or th < 1 or tw > img.shape[1] or th > img.shape[0]:
        raise FormatError(f"tileset tile size {tw}x{th} does not fit the image", path=path)
    cols = img.shape[1] // tw
    rows = img.shape[0] // th
    out = np.zeros((K, th, tw, 4), dtype=np.uint8)
    for t in range(1, K):
        i = t - 1
        if i >= cols * rows:
            warn.add(f"tileset image {f.name} has {cols * rows} tiles; tile {t} has none")
            break
        r, c = divmod(i, cols)
        out[t] = img[r * th : (r + 1) * th, c * tw : (c + 1) * tw]
    return out
