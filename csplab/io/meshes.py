"""Polyhedral models (3D continuous model synthesis) as OBJ, OFF and STL files, and a PNG
preview.

* OBJ in (format ``mesh-obj``): ``v``, ``f`` (polygons; ``i``, ``i/t``, ``i//n``,
  ``i/t/n``, negative indices relative), ``o``/``g``, ``usemtl`` and ``# csplab label N``;
  other statements are ignored. The ``labels`` option says what makes a label:

  - ``auto`` (default): the materials when any face has one, else the ``o``/``g`` groups
    when there are any, else one label for the file;
  - ``materials`` / ``groups``: a material (group) named ``label_N`` (or ``labelN``,
    ``label N``, any case) has label ``N``; other names get labels 1, 2, ... in order of
    first appearance, skipping the labels named explicitly (faces before any name count
    as one more name);
  - ``components``: every connected component its own label, 1, 2, ... in file order;
  - ``one``: label 1 for everything.

  A ``# csplab label N`` comment gives the faces after it in the same ``o``/``g`` group
  label ``N``, whatever the option (a new ``o``/``g`` statement ends it). A solid is one
  edge-connected shell of faces with one label and one ``o``/``g`` group. Coordinates are
  kept as they are (no axis change).
* OFF and STL (ASCII or binary) in (formats ``off``, ``stl``): one label for the file
  (``labels=one``) or one per connected component (``labels=components``); every connected
  shell is a solid.
* OBJ out (``mesh-obj``): one ``o solid_I`` per solid, ``usemtl label_N``, the solid's
  polygons; the ``.mtl`` next to it (``newmtl label_N`` with the label's colour, ``Kd``),
  both written atomically (a temporary file, then renamed) -- so a written model reads back
  with the same labels, solids, vertices and polygons.
* PNG out (``mesh-png``): a shaded view of the solids in their label colours (matplotlib).

Meshes as CAD tools write them are repaired first (:mod:`csplab.io.mesh_repair`): duplicate
vertices merged, faces with repeated vertices dropped, zero-area sliver triangles removed by
edge flips, inconsistent winding made consistent (and outward); one ``UserWarning`` line
says what was repaired (the CLI prints it as ``csplab: warning: FILE: repaired ...``) and
``meta["repaired"]`` has the counts. A file whose faces would need more memory than the
budget (:data:`~csplab.io.mesh_repair.BYTES_PER_FACE` each) is refused from its counts,
before the faces are read.

Every problem is one line: a :class:`~csplab.errors.FormatError` naming the file and line
for syntax, an :class:`~csplab.errors.InputError` naming the file and the line, triangle or
solid/face for geometry (non-finite or too large coordinates, a surface that crosses
itself: :func:`~csplab.io.mesh_repair.self_intersection`, and the checks of
:class:`~csplab.continuous.polyhedra.PolyhedralModel`).

Examples
--------
>>> import tempfile, pathlib
>>> with tempfile.TemporaryDirectory() as d:
...     p = pathlib.Path(d) / "t.off"
...     _ = p.write_text("OFF\\n4 4 0\\n0 0 0\\n1 0 0\\n0 1 0\\n0 0 1\\n"
...                      "3 0 2 1\\n3 0 1 3\\n3 1 2 3\\n3 0 3 2\\n")
...     M = read_off(p)
...     write_obj_model(M, pathlib.Path(d) / "t.obj")
...     B = read_obj_model(pathlib.Path(d) / "t.obj")
>>> B.labels, round(B.volume(1), 6), B.n_polygons, B.meta["format"]
((1,), 0.166667, 4, 'mesh-obj')
"""

from __future__ import annotations

import io
import json
import re
import struct
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.continuous.polyhedra import PolyhedralModel
from csplab.deps import require
from csplab.errors import CsplabError, FormatError, InputError
from csplab.io.common import (
    KIND,
    NO,
    PLAUSIBLE,
    SURE,
    exact_text,
    png_target,
    read_bytes,
    write_atomic,
)
from csplab.io.mesh_repair import (
    Repairs,
    check_coordinates,
    check_face_count,
    flip_slivers,
    merge_duplicates,
    orient_shell,
    self_intersection,
)

__all__ = [
    "read_glb",
    "read_obj_model",
    "read_off",
    "read_stl",
    "sniff_glb",
    "sniff_obj",
    "sniff_off",
    "sniff_stl",
    "write_glb",
    "write_obj_model",
    "write_png",
]

_LABEL_NAME = re.compile(r"label[_\s-]?(\d+)", re.IGNORECASE)
_LABEL_COMMENT = re.compile(r"#\s*csplab\s+label\s+(\S+)", re.IGNORECASE)
_SYNTHESIS_COMMENT = re.compile(r"#\s*csplab\s+synthesis\s+(.*\S)")


def _synthesis(model: PolyhedralModel) -> dict[str, Any] | None:
    """The settings ``csplab synthesize`` made the model with (``meta["synthesis"]``: the
    spacing, snap and lines that differ from the defaults), which ``.obj`` and ``.glb``
    outputs keep so that ``csplab check`` compares the example as it was synthesized."""
    d = model.meta.get("synthesis")
    return dict(d) if isinstance(d, dict) else None


_EMPTY_GLB_GENERATOR = "csplab (empty scene)"


def _read_synthesis(text: str | Any, p: Path, where: str) -> dict[str, Any]:
    """``{"synthesis": settings}`` from the JSON text (or the decoded object) a writer
    stored; one line naming the file on error."""
    try:
        d = json.loads(text) if isinstance(text, str) else text
    except ValueError:
        raise FormatError(f"{where}: the csplab synthesis settings are not JSON", path=p) from None
    if not isinstance(d, dict):
        raise FormatError(f"{where}: the csplab synthesis settings are not an object", path=p)
    return {"synthesis": d}
_OBJ_FACE = re.compile(r"^[ \t]*f[ \t]", re.MULTILINE)


# ---------------------------------------------------------------------------- sniffing
def sniff_obj(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for text with ``v`` and ``f`` lines.

    Examples
    --------
    >>> sniff_obj(b"# x\\nv 0 0 0\\nf 1 2 3\\n"), sniff_obj(b"v 0 0 0\\n"), sniff_obj(b"0 1")
    (3, 1, 0)
    """
    if b"\0" in head[:4096]:
        return NO
    has_v = re.search(rb"^[ \t]*v[ \t]", head, re.MULTILINE) is not None
    has_f = re.search(rb"^[ \t]*f[ \t]", head, re.MULTILINE) is not None
    return SURE if has_v and has_f else PLAUSIBLE if has_v else NO


def sniff_off(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for text starting with ``OFF`` (after comments).

    Examples
    --------
    >>> sniff_off(b"# c\\nOFF\\n4 4 0\\n"), sniff_off(b"OFFSET 1")
    (3, 0)
    """
    for line in head[:4096].splitlines():
        text = line.split(b"#", 1)[0].strip()
        if text:
            word = text.split()[0]
            return SURE if word in (b"OFF", b"COFF", b"NOFF", b"CNOFF") else NO
    return NO


def sniff_stl(head: bytes) -> int:
    """:data:`~csplab.io.common.SURE` for ASCII STL (``solid`` ... ``facet``),
    :data:`~csplab.io.common.KIND` for a binary STL whose triangle count fits the size.

    Examples
    --------
    >>> sniff_stl(b"solid t\\n facet normal 0 0 1\\n"), sniff_stl(b"\\0" * 80 + bytes(4))
    (3, 2)
    """
    if head.lstrip().lower().startswith(b"solid") and b"facet" in head[:4096].lower():
        return SURE
    if len(head) >= 84:
        (n,) = struct.unpack_from("<I", head, 80)
        if len(head) == 84 + 50 * n:
            return KIND
    return NO


# ---------------------------------------------------------------------------- helpers
def _text(path: Path) -> str:
    data = read_bytes(path)
    if b"\0" in data:
        raise FormatError("a binary file, not text", path=path)
    return data.decode("utf-8", errors="replace")


def _components(polys: Sequence[Sequence[int]], n_vertices: int) -> list[list[int]]:
    """The faces grouped into edge-connected components (indices, in file order)."""
    if not polys:
        return []
    graph = require("scipy.sparse", "mesh", "the face graph of polyhedral models")
    csgraph = require("scipy.sparse.csgraph", "mesh", "the face graph of polyhedral models")
    edges: dict[tuple[int, int], int] = {}
    rows: list[int] = []
    cols: list[int] = []
    for j, p in enumerate(polys):
        for k in range(len(p)):
            a, b = p[k], p[(k + 1) % len(p)]
            if a == b:
                continue
            key = (a, b) if a < b else (b, a)
            if key in edges:
                rows.append(edges[key])
                cols.append(j)
            else:
                edges[key] = j
    n = len(polys)
    adj = graph.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    _, comp = csgraph.connected_components(adj, directed=False)
    order: dict[int, list[int]] = {}
    for j, c in enumerate(comp.tolist()):
        order.setdefault(int(c), []).append(j)
    return list(order.values())


def _edge_uses(polys: Sequence[Sequence[int]]) -> NDArray[np.int64]:
    """The distinct numbers of faces that share an (undirected) edge."""
    pairs = [(a, p[(k + 1) % len(p)]) for p in polys for k, a in enumerate(p)]
    if not pairs:
        return np.zeros(0, dtype=np.int64)
    e = np.sort(np.asarray(pairs, dtype=np.int64), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    return np.unique(counts)


def _solids(
    v: NDArray[np.float64],
    polys: list[list[int]],
    labels: list[int],
    groups: list[str],
    names: dict[int, str],
    path: Path,
    fmt: str,
    by_component: bool,
    vertex_name: Callable[[int], str] | None = None,
    extra: dict[str, Any] | None = None,
) -> PolyhedralModel:
    """Solids (edge-connected shells of one label and group) and the model, after the
    repairs of :mod:`csplab.io.mesh_repair` (one warning line says what was repaired;
    ``meta["repaired"]`` has the counts)."""
    check_coordinates(v, path, vertex_name or (lambda k: f"vertex {k}"))
    repairs = Repairs()
    orig = polys
    v, polys, _ = merge_duplicates(v, polys)
    keep = [j for j, p in enumerate(polys) if len(set(p)) >= 3]
    if len(keep) < len(polys):
        repairs.degenerate = len(polys) - len(keep)
        orig = [orig[j] for j in keep]
        polys = [polys[j] for j in keep]
        labels = [labels[j] for j in keep]
        groups = [groups[j] for j in keep]
    scale = float(np.ptp(v, axis=0).max()) if len(v) else 1.0
    keys = list(dict.fromkeys(zip(groups, labels, strict=True)))
    solids: list[dict[str, Any]] = []
    for g, b in keys:
        idx = [j for j in range(len(polys)) if groups[j] == g and labels[j] == b]
        mine = [polys[j] for j in idx]
        comps = _components(mine, len(v))
        if _edge_uses(mine).max(initial=0) > 2:
            # solids that touch along an edge (or a point) share merged vertices: the
            # file's own vertex numbers keep them apart when every shell is closed so
            alone = _components([orig[j] for j in idx], len(v))
            if all(_edge_uses([mine[c] for c in comp]).tolist() in ([], [2]) for comp in alone):
                comps = alone
        for comp in comps:
            if fmt != "stl":  # every STL triangle has its own vertices: not a defect
                # coincident vertices of one shell (other shells may share positions)
                ids = {i for c in comp for i in orig[idx[c]]}
                repairs.duplicates += len(ids) - len({i for c in comp for i in mine[c]})
            faces = orient_shell(v, [mine[c] for c in comp], repairs)
            faces = flip_slivers(v, faces, repairs, scale)
            used = sorted({i for f in faces for i in f})
            where = {old: new for new, old in enumerate(used)}
            s: dict[str, Any] = {
                "label": b,
                "vertices": v[used],
                "faces": [[where[i] for i in f] for f in faces],
            }
            if g:
                s["group"] = g
            solids.append(s)
    if by_component:
        for k, s in enumerate(solids, 1):
            s["label"] = k
    if not solids:
        raise InputError(f"{path}: no faces: a polyhedral example needs closed solids")
    meta: dict[str, Any] = {"format": fmt, **(extra or {})}
    if names and not by_component:
        meta["label_names"] = {str(b): n for b, n in sorted(names.items())}
    if repairs:
        meta["repaired"] = repairs.as_dict()
    try:
        model = PolyhedralModel(solids, name=path.stem, meta=meta, source=str(path))
    except CsplabError:
        raise
    except (ValueError, TypeError, OverflowError, IndexError, MemoryError) as e:
        raise InputError(f"{path}: cannot build the polyhedral model ({e})") from None
    for i, solid in enumerate(model.solids):
        hit = self_intersection(solid.vertices, solid.faces)
        if hit is not None:
            f1, f2 = (int(solid.face_polygon[k]) for k in hit)
            raise InputError(
                f"{path}: solid {i}: the surface crosses itself (faces {f1} and {f2} intersect)"
            )
    if repairs:
        warnings.warn(repairs.note(path), UserWarning, stacklevel=3)
    return model


def _number_labels(
    keys: list[str | None], explicit_taken: set[int], path: Path
) -> tuple[list[int], dict[int, str]]:
    """Labels for names: ``label_N`` -> N, others 1, 2, ... in order of first appearance."""
    out: dict[str | None, int] = {}
    named: dict[int, str] = {}
    taken = set(explicit_taken)
    for k in keys:
        m = _LABEL_NAME.fullmatch(k or "")
        if m is not None:
            b = int(m.group(1))
            if b < 1:
                raise InputError(f"{path}: {k!r}: label must be >= 1 (0 is empty space)")
            out[k] = b
            taken.add(b)
    nxt = 1
    for k in dict.fromkeys(keys):
        if k in out:
            continue
        while nxt in taken:
            nxt += 1
        out[k] = nxt
        taken.add(nxt)
        if k:
            named[nxt] = k
    return [out[k] for k in keys], named


# ---------------------------------------------------------------------------- OBJ in
def read_obj_model(path: str | Path, labels: str = "auto") -> PolyhedralModel:
    """A polyhedral model from a Wavefront OBJ file (rules in the module docstring).

    Parameters
    ----------
    path : str or Path
        The ``.obj`` file (its ``.mtl`` is not needed).
    labels : {"auto", "materials", "groups", "components", "one"}
        What makes a label.

    Returns
    -------
    PolyhedralModel
        The solids (edge-connected shells with one label and group), named after the file.

    Raises
    ------
    FormatError
        Naming the file and line for syntax (a bad vertex, face or label comment, a
        binary file, one larger than :data:`~csplab.io.common.MAX_FILE_BYTES`).
    InputError
        Naming the file for a bad ``labels`` value, and the file and the solid or face for
        geometry (no faces; a zero-area face, an open, non-manifold or inconsistently wound
        solid ...).
    """
    p = Path(path)
    if labels not in ("auto", "materials", "groups", "components", "one"):
        raise InputError(f"{p}: labels must be auto, materials, groups, components or one")
    verts: list[tuple[float, float, float]] = []
    polys: list[list[int]] = []
    lines: list[int] = []
    groups: list[str] = []
    mats: list[str | None] = []
    explicit: list[int | None] = []
    group, mat, label = "", None, None
    any_group = False
    extra: dict[str, Any] = {}
    text = _text(p)
    check_face_count(sum(1 for _ in _OBJ_FACE.finditer(text)), p)
    vlines: list[int] = []
    for n, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("#"):
            sm = _SYNTHESIS_COMMENT.match(line)
            if sm is not None:
                extra = _read_synthesis(sm.group(1), p, f"line {n}")
                continue
            m = _LABEL_COMMENT.match(line)
            if m is not None:
                try:
                    label = int(m.group(1))
                except ValueError:
                    raise FormatError(f"bad label {m.group(1)!r}", path=p, line=n) from None
                if label < 1:
                    raise FormatError("label must be >= 1 (0 is empty space)", path=p, line=n)
            continue
        tok = line.split("#", 1)[0].split()
        if not tok:
            continue
        key = tok[0]
        if key == "v":
            try:
                x, y, z = (float(t) for t in tok[1:4])
            except ValueError:
                raise FormatError("a vertex needs 3 numbers", path=p, line=n) from None
            verts.append((x, y, z))
            vlines.append(n)
        elif key == "f":
            face: list[int] = []
            for t in tok[1:]:
                try:
                    i = int(t.split("/", 1)[0])
                except ValueError:
                    raise FormatError(f"bad vertex reference {t!r}", path=p, line=n) from None
                k = i - 1 if i > 0 else len(verts) + i
                if i == 0 or not 0 <= k < len(verts):
                    raise FormatError(
                        f"vertex {i} does not exist ({len(verts)} so far)", path=p, line=n
                    )
                face.append(k)
            if len(face) < 3:
                raise FormatError("a face needs at least 3 vertices", path=p, line=n)
            polys.append(face)
            lines.append(n)
            groups.append(group)
            mats.append(mat)
            explicit.append(label)
        elif key in ("o", "g"):
            group = " ".join(tok[1:])
            any_group = True
            label = None
        elif key == "usemtl":
            mat = " ".join(tok[1:])
    if not polys:
        raise FormatError(
            "no faces (`f` lines): csplab writes .obj files of label grids too, but reads .obj "
            "files only as polyhedral examples (closed solids)",
            path=p,
        )
    v = np.asarray(verts, dtype=np.float64).reshape(-1, 3)
    mode = labels
    if mode == "auto":
        mode = "materials" if any(mats) else "groups" if any_group else "one"
    taken = {b for b in explicit if b is not None}
    free = [j for j, b in enumerate(explicit) if b is None]  # faces a name labels
    names: dict[int, str] = {}
    labs = [1 if b is None else b for b in explicit]
    if mode in ("materials", "groups"):
        keys = mats if mode == "materials" else [g or None for g in groups]
        got, names = _number_labels([keys[j] for j in free], taken, p)
        for j, b in zip(free, got, strict=True):
            labs[j] = b
    return _solids(v, polys, labs, groups, names, p, "mesh-obj", mode == "components",
                   lambda k: f"line {vlines[k]}", extra)  # fmt: skip


# ---------------------------------------------------------------------------- OFF in
def read_off(path: str | Path, labels: str = "one") -> PolyhedralModel:
    """A polyhedral model from an OFF file.

    ``OFF``, the counts, the vertices, then ``k i1 ... ik`` faces; colours and comments
    are ignored. Every connected shell is a solid.

    Parameters
    ----------
    path : str or Path
        The ``.off`` file.
    labels : {"one", "components"}
        One label for the file, or one per connected component (1, 2, ... in file order).

    Returns
    -------
    PolyhedralModel
        The solids, named after the file.

    Raises
    ------
    FormatError
        Naming the file and line for syntax (no ``OFF``, bad counts, vertices or faces).
    InputError
        Naming the file for a bad ``labels`` value, and the file and the solid or face for
        geometry.
    """
    p = Path(path)
    by = _labels_option(p, labels)
    rows: list[tuple[int, list[str]]] = []
    checked = False
    for n, raw in enumerate(_text(p).splitlines(), 1):
        tok = raw.split("#", 1)[0].split()
        if tok:
            rows.append((n, tok))
            if not checked and len(rows) <= 2:  # the counts, before the body is read
                counts = rows[-1][1][1:] if len(rows) == 1 else rows[-1][1]
                if len(counts) >= 2 and counts[1].isdigit():
                    check_face_count(int(counts[1]), p)
                    checked = True
    if not rows or not rows[0][1][0].endswith("OFF"):
        raise FormatError("an OFF file starts with OFF", path=p, line=rows[0][0] if rows else 1)
    first = rows[0][1][1:]
    rest = rows[1:]
    if not first:
        if not rest:
            raise FormatError("missing the counts line", path=p)
        n0, first = rest[0]
        rest = rest[1:]
    else:
        n0 = rows[0][0]
    try:
        nv, nf = int(first[0]), int(first[1])
    except (ValueError, IndexError):
        raise FormatError("the counts line is `vertices faces edges`", path=p, line=n0) from None
    if nv < 0 or nf < 0 or nv + nf > len(rest):
        raise FormatError(
            f"{nv} vertices and {nf} faces announced, {len(rest)} lines follow", path=p, line=n0
        )
    verts: list[list[float]] = []
    for n, tok in rest[:nv]:
        try:
            verts.append([float(t) for t in tok[:3]])
        except ValueError:
            raise FormatError("a vertex needs 3 numbers", path=p, line=n) from None
        if len(verts[-1]) != 3:
            raise FormatError("a vertex needs 3 numbers", path=p, line=n)
    polys: list[list[int]] = []
    for n, tok in rest[nv : nv + nf]:
        try:
            k = int(tok[0])
            face = [int(t) for t in tok[1 : 1 + k]]
        except ValueError:
            raise FormatError("a face is `k i1 ... ik`", path=p, line=n) from None
        if k < 3 or len(face) != k:
            raise FormatError("a face is `k i1 ... ik` with k >= 3", path=p, line=n)
        if any(not 0 <= i < nv for i in face):
            raise FormatError(f"a face refers to a vertex outside 0..{nv - 1}", path=p, line=n)
        polys.append(face)
    v = np.asarray(verts, dtype=np.float64).reshape(-1, 3)
    vline = [n for n, _ in rest[:nv]]
    return _solids(v, polys, [1] * len(polys), [""] * len(polys), {}, p, "off", by,
                   lambda k: f"line {vline[k]}")  # fmt: skip


def _labels_option(p: Path, labels: str) -> bool:
    if labels not in ("one", "components"):
        raise InputError(f"{p}: labels must be one or components, not {labels!r}")
    return labels == "components"


# ---------------------------------------------------------------------------- STL in
_STL_DTYPE = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
_STL_VERTEX = re.compile(rb"vertex\s+(\S+)\s+(\S+)\s+(\S+)", re.IGNORECASE)


def read_stl(path: str | Path, labels: str = "one") -> PolyhedralModel:
    """A polyhedral model from an STL file, ASCII or binary.

    Coincident vertices are merged and adjacent coplanar triangles make one polygon; every
    connected shell is a solid.

    Parameters
    ----------
    path : str or Path
        The ``.stl`` file.
    labels : {"one", "components"}
        One label for the file, or one per connected component (1, 2, ... in file order).

    Returns
    -------
    PolyhedralModel
        The solids, named after the file.

    Raises
    ------
    FormatError
        Naming the file for syntax (a bad vertex, not 3 vertices per facet, a truncated
        binary file).
    InputError
        Naming the file for a bad ``labels`` value, no triangles, and the solid or face
        for geometry.
    """
    p = Path(path)
    by = _labels_option(p, labels)
    data = read_bytes(p)
    ascii_ = data.lstrip().lower().startswith(b"solid") and b"facet" in data[:4096].lower()
    if ascii_:
        check_face_count(len(re.findall(rb"(?i)endfacet", data)), p)
        try:
            tri = np.asarray(
                [[float(x) for x in m.groups()] for m in _STL_VERTEX.finditer(data)],
                dtype=np.float64,
            ).reshape(-1, 3)
        except ValueError:
            raise FormatError("a vertex needs 3 numbers", path=p) from None
        if len(tri) % 3:
            raise FormatError(f"{len(tri)} vertices: not 3 per facet", path=p)
    else:
        if len(data) < 84:
            raise FormatError("too short for a binary STL (no triangle count)", path=p)
        (n,) = struct.unpack_from("<I", data, 80)
        if len(data) < 84 + 50 * n:
            raise FormatError(
                f"{n} triangles announced, the file holds {(len(data) - 84) // 50}", path=p
            )
        check_face_count(n, p)
        rec = np.frombuffer(data, dtype=_STL_DTYPE, count=n, offset=84)
        tri = rec["v"].astype(np.float64).reshape(-1, 3)
    if not len(tri):
        raise InputError(f"{p}: no triangles: a polyhedral example needs closed solids")
    polys = np.arange(len(tri)).reshape(-1, 3).tolist()
    return _solids(tri, polys, [1] * len(polys), [""] * len(polys), {}, p, "stl", by,
                   lambda k: f"triangle {k // 3}")  # fmt: skip


# ---------------------------------------------------------------------------- glTF in
def sniff_glb(head: bytes) -> int:
    """Binary glTF starts with the magic ``glTF``."""
    return SURE if head[:4] == b"glTF" else NO


def _glb_json(data: bytes, p: Path) -> dict[str, Any]:
    """The JSON chunk of a ``.glb`` (header and chunk checked; one line naming the file)."""
    import json

    if len(data) < 20 or data[:4] != b"glTF":
        raise FormatError("not a binary glTF file (no `glTF` header)", path=p)
    version, total = struct.unpack_from("<II", data, 4)
    n, kind = struct.unpack_from("<I4s", data, 12)
    if version != 2 or kind != b"JSON" or 20 + n > len(data):
        raise FormatError(
            f"a glTF 2.0 binary starts with its JSON chunk (version {version}, "
            f"{total} bytes announced, {len(data)} in the file)",
            path=p,
        )
    try:
        doc = json.loads(data[20 : 20 + n])
    except (ValueError, UnicodeDecodeError) as e:
        raise FormatError(f"the JSON chunk does not parse ({e})", path=p) from None
    if not isinstance(doc, dict):
        raise FormatError("the JSON chunk is not an object", path=p)
    return doc


def _glb_face_count(doc: dict[str, Any], p: Path) -> int:
    """The triangles the file's meshes announce (index or position accessor counts / 3)."""
    acc = doc.get("accessors", [])
    total = 0
    try:
        for mesh in doc.get("meshes", []):
            for prim in mesh.get("primitives", []):
                k = prim.get("indices", prim.get("attributes", {}).get("POSITION"))
                if k is not None:
                    total += int(acc[k]["count"]) // 3
    except (TypeError, KeyError, IndexError, ValueError, AttributeError):
        raise FormatError("a mesh primitive refers to a missing accessor", path=p) from None
    return total


def read_glb(path: str | Path, labels: str = "auto") -> PolyhedralModel:
    """A polyhedral model from a binary glTF file (``.glb``; trimesh).

    What :func:`write_glb` writes reads back as the same solids and labels: a mesh whose
    material (or, failing that, node or mesh) is named ``label_N`` has label ``N``; other
    names get the free labels 1, 2, ... in order of appearance. Node transforms are applied
    and glTF's ``y`` up is turned back into csplab's ``z`` up (``(x, y, z)`` ->
    ``(x, -z, y)``). Every connected closed shell is a solid, repaired and validated as
    for the other mesh readers (:mod:`csplab.io.mesh_repair`).

    Parameters
    ----------
    path : str or Path
        The ``.glb`` file.
    labels : {"auto", "components", "one"}
        Labels from the names, one per connected component, or one for the file.

    Returns
    -------
    PolyhedralModel
        The solids, named after the file.

    Raises
    ------
    FormatError
        Naming the file for a file that is not binary glTF or that trimesh cannot read.
    InputError
        Naming the file for a bad ``labels`` value, no triangles, and the solid or face
        for geometry.
    MemoryLimitError
        When reading the faces the file announces would exceed the memory budget.
    DependencyError
        When trimesh (the ``mesh`` extra) is not installed.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from csplab.continuous.polyhedra import PolyhedralModel
    >>> box = lambda x, b: {"label": b, "vertices": [[x, 0, 0], [x + 1, 0, 0], [x + 1, 1, 0],
    ...     [x, 1, 0], [x, 0, 1], [x + 1, 0, 1], [x + 1, 1, 1], [x, 1, 1]],
    ...     "faces": [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6],
    ...               [3, 0, 4, 7]]}
    >>> M = PolyhedralModel([box(0, 2), box(3, 5)])
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_glb(M, pathlib.Path(d) / "m.glb")
    ...     B = read_glb(pathlib.Path(d) / "m.glb")
    >>> B.labels, round(B.volume(5), 6), len(B), B.meta["format"]
    ((2, 5), 1.0, 2, 'glb')
    """
    p = Path(path)
    if labels not in ("auto", "components", "one"):
        raise InputError(f"{p}: labels must be auto, components or one, not {labels!r}")
    data = read_bytes(p)
    doc = _glb_json(data, p)
    check_face_count(_glb_face_count(doc, p), p)
    extra: dict[str, Any] = {}
    scenes, k = doc.get("scenes"), doc.get("scene", 0)
    if isinstance(scenes, list) and isinstance(k, int) and 0 <= k < len(scenes):
        mine = scenes[k].get("extras") if isinstance(scenes[k], dict) else None
        ours = mine.get("csplab") if isinstance(mine, dict) else None
        if isinstance(ours, dict) and "synthesis" in ours:
            extra = _read_synthesis(ours["synthesis"], p, "the scene's extras")
    asset = doc.get("asset")
    if not doc.get("meshes") and isinstance(asset, dict) and (
        asset.get("generator") == _EMPTY_GLB_GENERATOR
    ):  # what write_glb writes for an output that is all empty space
        return PolyhedralModel([], name=p.stem, meta={"format": "glb", **extra}, source=str(p))
    nodes = doc.get("nodes", [])
    rank = {n.get("name"): i for i, n in enumerate(nodes) if isinstance(n, dict)}
    tm = require("trimesh", "mesh", "reading glTF")
    try:
        scene = tm.load(io.BytesIO(data), file_type="glb", force="scene", process=False)
    except CsplabError:
        raise
    except Exception as e:  # trimesh raises many kinds on a damaged file
        raise FormatError(f"trimesh cannot read it ({type(e).__name__}: {e})", path=p) from None
    vs: list[NDArray[np.float64]] = []
    polys: list[list[int]] = []
    keys: list[str | None] = []
    base = 0
    for node in sorted(scene.graph.nodes_geometry, key=lambda n: rank.get(n, len(rank))):
        transform, gname = scene.graph[node]
        g = scene.geometry[gname]
        faces = np.asarray(getattr(g, "faces", np.zeros((0, 3))), dtype=np.int64)
        if not len(faces):
            continue  # points and lines are no solids
        v = np.asarray(g.vertices, dtype=np.float64)
        v = v @ np.asarray(transform, dtype=np.float64)[:3, :3].T + transform[:3, 3]
        vs.append(v[:, [0, 2, 1]] * np.array([1.0, -1.0, 1.0]))
        mat = getattr(getattr(g, "visual", None), "material", None)
        names = [getattr(mat, "name", None), node, gname]
        key = next((n for n in names if n and _LABEL_NAME.fullmatch(n)), None)
        key = key or next((n for n in names if n), None)
        polys += (faces + base).tolist()
        keys += [key] * len(faces)
        base += len(v)
    if not polys:
        raise InputError(f"{p}: no triangles: a polyhedral example needs closed solids")
    v = np.concatenate(vs)
    names_: dict[int, str] = {}
    if labels == "auto":
        labs, names_ = _number_labels(keys, set(), p)
    else:
        labs = [1] * len(polys)
    return _solids(v, polys, labs, [""] * len(polys), names_, p, "glb",
                   labels == "components", lambda k: f"vertex {k}", extra)  # fmt: skip


# ---------------------------------------------------------------------------- OBJ out
def _colours(model: PolyhedralModel) -> dict[int, tuple[int, int, int]]:
    from csplab.render import palette

    pal = palette(max(model.labels, default=0) + 1)
    return {b: (int(pal[b][0]), int(pal[b][1]), int(pal[b][2])) for b in model.labels}


def write_obj_model(model: PolyhedralModel, path: str | Path) -> None:
    """Write ``model`` as OBJ + MTL (the ``.mtl`` next to it, same stem; both atomic).

    One ``o solid_I`` per solid with ``usemtl label_N`` and its polygons, exact numbers, so
    the file reads back as the same model.

    Parameters
    ----------
    model : PolyhedralModel
        The solids to write.
    path : str or Path
        The ``.obj`` file; the ``.mtl`` with one material per label goes next to it.

    Raises
    ------
    InputError
        Naming the file when it cannot be written.
    """
    p = Path(path)
    mtl = p.with_suffix(".mtl")
    cols = _colours(model)
    m_lines = ["# csplab polyhedral model: one material per label"]
    for b, c in cols.items():
        r, g, bl = (x / 255 for x in c)
        m_lines += [f"newmtl label_{b}", f"Kd {r:.6g} {g:.6g} {bl:.6g}", "Ka 0 0 0", ""]
    lines = [
        f"# csplab polyhedral model {model.name}".rstrip()
        + f": {len(model)} solids, labels {list(model.labels)}",
        f"mtllib {mtl.name}",
    ]
    settings = _synthesis(model)
    if settings is not None:
        lines.insert(1, "# csplab synthesis " + json.dumps(settings, sort_keys=True))
    base = 1
    for i, s in enumerate(model.solids):
        lines += [f"o solid_{i}", f"usemtl label_{s.label}"]
        lines += [
            f"v {exact_text(x)} {exact_text(y)} {exact_text(z)}" for x, y, z in s.vertices.tolist()
        ]
        lines += ["f " + " ".join(str(base + k) for k in poly) for poly in s.polygons]
        base += len(s.vertices)
    write_atomic(mtl, ("\n".join(m_lines) + "\n").encode("utf-8"))
    write_atomic(p, ("\n".join(lines) + "\n").encode("utf-8"))


# ---------------------------------------------------------------------------- PNG out
def write_png(model: PolyhedralModel, path: str | Path, *, size_px: int = 512) -> None:
    """A shaded view of ``model`` as a PNG (atomically; matplotlib, no display needed).

    The solids in their label colours (those of :func:`write_obj_model`), lit from the
    viewer's upper left, equal aspect, ``size_px`` pixels square.

    Parameters
    ----------
    model : PolyhedralModel
        The solids to draw.
    path : str or Path
        The ``.png`` file (written to a temporary file in the same folder, then renamed).
    size_px : int, optional
        The picture's side in pixels, 16 to 8192.

    Raises
    ------
    InputError
        When ``size_px`` is not an integer from 16 to 8192, or naming the file when it
        cannot be written.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from PIL import Image
    >>> from csplab.continuous.polyhedra import PolyhedralModel
    >>> T = PolyhedralModel([{"label": 1, "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0],
    ...     [0, 0, 1]], "faces": [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]}])
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_png(T, pathlib.Path(d) / "t.png", size_px=96)
    ...     Image.open(pathlib.Path(d) / "t.png").size
    (96, 96)
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    p = png_target(path, size_px, 16, 8192)
    dpi = 100
    fig = Figure(figsize=(size_px / dpi, size_px / dpi), dpi=dpi)
    FigureCanvasAgg(fig)
    ax: Any = fig.add_axes((0.0, 0.0, 1.0, 1.0), projection="3d")
    ax.set_axis_off()
    ax.view_init(elev=25, azim=-60)
    cols = _colours(model)
    light = np.asarray([-0.4, -0.6, 0.7])
    light /= np.linalg.norm(light)
    tris: list[NDArray[np.float64]] = []
    shades: list[NDArray[np.float64]] = []
    for s in model.solids:
        t = s.vertices[s.faces]
        nrm = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
        nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-300)
        lam = 0.35 + 0.65 * np.clip(nrm @ light, 0.0, 1.0)
        base = np.asarray(cols[s.label], dtype=np.float64) / 255
        tris.append(t)
        shades.append(np.clip(lam[:, None] * base[None, :], 0, 1))
    if tris:
        allt = np.concatenate(tris)
        ax.add_collection3d(
            Poly3DCollection(list(allt), facecolors=np.concatenate(shades), linewidths=0)
        )
        lo, hi = allt.reshape(-1, 3).min(axis=0), allt.reshape(-1, 3).max(axis=0)
        mid, half = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 1e-12)
        ax.set_xlim(mid[0] - half, mid[0] + half)
        ax.set_ylim(mid[1] - half, mid[1] + half)
        ax.set_zlim(mid[2] - half, mid[2] + half)
        ax.set_box_aspect((1, 1, 1), zoom=1.3)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, facecolor="white")
    write_atomic(p, buf.getvalue())


# ---------------------------------------------------------------------------- triangles out
def _ear_clip(pts: NDArray[np.float64]) -> list[tuple[int, int, int]] | None:
    """Triangles of a simple polygon (2D points, either orientation) by ear clipping that
    keeps every vertex, flat ones included, and makes no zero-area triangle (``None`` when
    it finds no ear)."""
    n = len(pts)
    x, y = pts[:, 0], pts[:, 1]
    signed = float((x * np.roll(y, -1) - np.roll(x, -1) * y).sum())
    ring = list(range(n)) if signed > 0 else list(range(n))[::-1]
    scale = float(np.ptp(pts, axis=0).max()) or 1.0
    eps = 1e-12 * scale**2

    def cross(a: int, b: int, c: int) -> float:
        return float(
            (pts[b, 0] - pts[a, 0]) * (pts[c, 1] - pts[a, 1])
            - (pts[b, 1] - pts[a, 1]) * (pts[c, 0] - pts[a, 0])
        )

    out: list[tuple[int, int, int]] = []
    while len(ring) > 3:
        m = len(ring)
        for k in range(m):
            a, b, c = ring[k - 1], ring[k], ring[(k + 1) % m]
            if cross(a, b, c) <= eps:
                continue  # reflex or flat: not an ear
            if any(
                cross(a, b, q) >= -eps and cross(b, c, q) >= -eps and cross(c, a, q) >= -eps
                for q in ring
                if q not in (a, b, c) and not np.array_equal(pts[q], pts[b])
            ):
                continue  # another vertex in (or on) the ear
            out.append((a, b, c))
            del ring[k]
            break
        else:
            return None
    if cross(*ring) <= eps:
        return None
    out.append((ring[0], ring[1], ring[2]))
    return out if signed > 0 else [(a, c, b) for a, b, c in out]


def solid_triangles(solid: Any, where: str = "solid") -> NDArray[np.int64]:
    """The solid's triangles, outward, with no zero-area triangle and every polygon vertex
    kept (no T-junctions between neighbouring faces): the solid's own triangulation where
    it has no zero-area triangle, else the polygon ear-clipped again in its plane (an
    :class:`~csplab.errors.InputError` naming ``where`` and the polygon if that fails).

    Examples
    --------
    >>> from csplab.continuous.polyhedra import PolyhedralModel
    >>> cube = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
    ...         [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1], [0.5, 0, 0], [0.5, 0, 1]]
    >>> quads = [[0, 3, 2, 1, 8], [4, 9, 5, 6, 7], [0, 8, 1, 5, 9, 4], [1, 2, 6, 5],
    ...          [2, 3, 7, 6], [3, 0, 4, 7]]
    >>> M = PolyhedralModel([{"label": 1, "vertices": cube, "faces": quads}])
    >>> len(solid_triangles(M.solids[0]))  # 3 + 3 + 4 + 2 + 2 + 2
    16
    """
    v, T = solid.vertices, np.asarray(solid.faces, dtype=np.int64)
    tri = v[T]
    area2 = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    scale = float(np.ptp(v, axis=0).max()) or 1.0
    bad = np.unique(np.asarray(solid.face_polygon)[area2 <= 1e-12 * scale**2])
    if not bad.size:
        return T
    keep = ~np.isin(solid.face_polygon, bad)
    parts = [T[keep]]
    for j in bad.tolist():
        ids = np.asarray(solid.polygons[j], dtype=np.int64)
        pts = v[ids]
        normal = np.cross(pts - pts[0], np.roll(pts, -1, axis=0) - pts[0]).sum(axis=0)
        axis = int(np.argmax(np.abs(normal)))
        flat2 = np.delete(pts, axis, axis=1)
        if normal[axis] < 0:  # keep the face's orientation in the projection
            flat2 = flat2[:, ::-1]
        got = _ear_clip(flat2)
        if got is None:
            raise InputError(
                f"{where}: polygon {j} cannot be triangulated without zero-area triangles"
            )
        loc = np.asarray(got, dtype=np.int64)
        parts.append(ids[loc])
    return np.concatenate(parts)


def _triangle_soup(
    model: PolyhedralModel, path: str | Path
) -> tuple[list[NDArray[np.float64]], list[NDArray[np.int64]]]:
    """Per solid: its vertices and its triangles (:func:`solid_triangles`)."""
    tris = [solid_triangles(s, f"{path}: solid {i}") for i, s in enumerate(model.solids)]
    return [s.vertices for s in model.solids], tris


def write_stl_model(model: PolyhedralModel, path: str | Path) -> None:
    """Write ``model`` as a binary STL (atomically).

    Every solid's triangles (:func:`solid_triangles`: no zero-area triangle, no
    T-junction), outward normals, float32 coordinates; STL has no labels (the ``.obj`` and
    ``.glb`` writers keep them).

    Parameters
    ----------
    model : PolyhedralModel
        The solids to write.
    path : str or Path
        The ``.stl`` file.

    Raises
    ------
    InputError
        Naming the file when it cannot be written, or the solid and polygon when a polygon
        cannot be triangulated without zero-area triangles.
    """
    verts, tris = _triangle_soup(model, path)
    n = sum(len(t) for t in tris)
    rec = np.zeros(n, dtype=_STL_DTYPE)
    k = 0
    for v, t in zip(verts, tris, strict=True):
        tri = v[t]
        nrm = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
        nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-300)
        rec["normal"][k : k + len(t)] = nrm
        rec["v"][k : k + len(t)] = tri
        k += len(t)
    head = f"csplab polyhedral model {model.name}: {len(model)} solids".encode()[:80]
    write_atomic(Path(path), head.ljust(80, b" ") + struct.pack("<I", n) + rec.tobytes())


def write_off_model(model: PolyhedralModel, path: str | Path) -> None:
    """Write ``model`` as OFF (atomically).

    Every solid's vertices and polygons, exact numbers; the solids are its connected shells
    (read back with ``labels=components`` for one label per solid: OFF has no labels).

    Parameters
    ----------
    model : PolyhedralModel
        The solids to write.
    path : str or Path
        The ``.off`` file.

    Raises
    ------
    InputError
        Naming the file when it cannot be written.
    """
    lines: list[str] = []
    polys: list[str] = []
    base = 0
    for s in model.solids:
        lines += [
            f"{exact_text(x)} {exact_text(y)} {exact_text(z)}" for x, y, z in s.vertices.tolist()
        ]
        polys += [f"{len(p)} " + " ".join(str(base + i) for i in p) for p in s.polygons]
        base += len(s.vertices)
    head = ["OFF", f"# csplab polyhedral model {model.name}: {len(model)} solids, labels "
            f"{list(model.labels)}", f"{base} {len(polys)} 0"]  # fmt: skip
    write_atomic(Path(path), ("\n".join([*head, *lines, *polys]) + "\n").encode("utf-8"))


def write_glb(model: PolyhedralModel, path: str | Path) -> None:
    """Write ``model`` as binary glTF (``.glb``, atomically; trimesh).

    One mesh and one PBR material per label (the label colours of :func:`write_obj_model`),
    node names ``label_N``, the solids' triangles (:func:`solid_triangles`), ``y`` up as
    glTF wants (csplab ``(x, y, z)`` -> ``(x, z, -y)``).

    Parameters
    ----------
    model : PolyhedralModel
        The solids to write.
    path : str or Path
        The ``.glb`` file.

    Raises
    ------
    InputError
        Naming the file when it cannot be written, or the solid and polygon when a polygon
        cannot be triangulated without zero-area triangles.
    DependencyError
        When trimesh (the ``mesh`` extra) is not installed.
    """
    tm = require("trimesh", "mesh", "writing glTF")
    cols = _colours(model)
    scene = tm.Scene()
    verts, tris = _triangle_soup(model, path)
    for b in model.labels:
        vs: list[NDArray[np.float64]] = []
        fs: list[NDArray[np.int64]] = []
        base = 0
        for s, v, t in zip(model.solids, verts, tris, strict=True):
            if s.label == b:
                vs.append(v[:, [0, 2, 1]] * np.array([1.0, 1.0, -1.0]))
                fs.append(t + base)
                base += len(v)
        mat = tm.visual.material.PBRMaterial(
            name=f"label_{b}", baseColorFactor=[*cols[b], 255], metallicFactor=0.0,
            roughnessFactor=0.8, doubleSided=False,
        )  # fmt: skip
        mesh = tm.Trimesh(vertices=np.concatenate(vs), faces=np.concatenate(fs), process=False)
        mesh.visual = tm.visual.TextureVisuals(material=mat)
        scene.add_geometry(mesh, node_name=f"label_{b}", geom_name=f"label_{b}")
    settings = _synthesis(model)
    if settings is not None:  # the scene's extras (glTF's place for application data)
        scene.metadata["csplab"] = {"synthesis": settings}
    data = scene.export(file_type="glb") if model.solids else _empty_glb(settings)
    write_atomic(Path(path), bytes(data))


def _empty_glb(settings: dict[str, Any] | None = None) -> bytes:
    """A valid ``.glb`` with an empty scene (an output that is all empty space), which
    :func:`read_glb` reads back as a model of no solids."""
    scene: dict[str, Any] = {} if settings is None else {
        "extras": {"csplab": {"synthesis": settings}}}
    doc = json.dumps({"asset": {"version": "2.0", "generator": _EMPTY_GLB_GENERATOR},
                      "scenes": [scene], "scene": 0}).encode()  # fmt: skip
    doc += b" " * (-len(doc) % 4)
    return (
        b"glTF"
        + struct.pack("<II", 2, 12 + 8 + len(doc))
        + struct.pack("<I4s", len(doc), b"JSON")
        + doc
    )
