"""The check of an output whose curved parts went back into bounding volumes (thesis
Sec. 4.6.4; :mod:`~csplab.continuous.bounding`).

An output of synthesis through bounding volumes holds the example's curved geometry, which
has far more face orientations than the planes the synthesis used; Eq. 4.1 is stated, and
checked, on the *proxy*: :func:`bounded_violations` verifies, from the output's geometry
alone (not from the synthesis, its CSP or its reinsertion code),

0. that every label of the output is one of the example's (no box is left with its
   proxy label);
1. **that every curved part of the output is a transformed original**: the output's curved
   regions (found by the same definition as the example's,
   :func:`~csplab.continuous.bounding.curved_regions`) each match one curved region of the
   example moved and scaled per axis (same label and number of triangles, every vertex
   within ``1e-6`` of the output's extent of the mapped original: the rounding of a file
   format, e.g. STL's float32, passes); a part's regions
   placed by one map give one placed box ``Q`` (the map applied to the part's lattice box,
   as the synthesis maps the lattice box onto each placed copy), and each of
   the part's regions must be there; where parts alike up to scale (holes of other radii)
   match the same region, the part whose content the box holds (point 2) and whose box
   lies on the lattice of the synthesis is the one;
2. **that the geometry inside each placed box is exactly the mapped original**: for every
   label, the output's solids inside ``Q`` and the part's content mapped onto ``Q`` have
   a symmetric difference of volume at most the point tolerance times the surface of
   ``Q`` (manifold3d Booleans);
3. **Eq. 4.1 for the proxy**: the output with each ``Q`` emptied and filled with the two
   pieces of the part's lattice box (mapped onto ``Q``) has no violation of
   :func:`~csplab.continuous.check3d.violations3` against the proxy example. A box that
   was not scaled as its part allows (uniformly, or equally across a cylinder's axis)
   gives pieces whose cut face has an orientation the proxy lacks, so the scaling rule is
   part of this check.

The proxy example itself is built from the original by
:func:`~csplab.continuous.bounding.bounding_volumes` (the definition of the bounding
volumes, shared with the synthesis; the verdict of Eq. 4.1 is the independent checker's).

Examples
--------
>>> import trimesh
>>> from csplab.continuous.bounding import bounding_volumes
>>> from csplab.continuous.polyhedra import PolyhedralModel, Solid
>>> m = trimesh.creation.cylinder(radius=1.0, height=2.0, sections=16)
>>> rod = PolyhedralModel([{"label": 1, "vertices": m.vertices.tolist(),
...                         "faces": m.faces.tolist()}])
>>> b = bounding_volumes(rod, spacing=0.5)
>>> len(bounded_violations(b, rod))
0
>>> _ = m.apply_scale([2.0, 1.0, 1.0])  # not a scaling the cylinder allows (x=y)
>>> stretched = PolyhedralModel([{"label": 1, "vertices": m.vertices.tolist(),
...                               "faces": m.faces.tolist()}])
>>> len(bounded_violations(b, stretched)) > 0
True
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.continuous.bounding import (
    Bounded,
    Feature,
    axis_map,
    curved_regions,
    from_manifold,
)
from csplab.continuous.check3d import violations3
from csplab.continuous.defects import Defect, Violations
from csplab.continuous.polyhedra import PolyhedralModel, Solid
from csplab.deps import require

__all__ = ["bounded_violations"]

#: of the output's extent: a file's rounding (STL stores float32, ~6e-8 relative) passes, a
#: moved vertex does not
_POINT_TOL = 1e-6


def _box(lo: NDArray[np.float64], hi: NDArray[np.float64]) -> Any:
    man = require("manifold3d", "mesh", "checking bounding volumes")
    return man.Manifold.cube(tuple(float(x) for x in hi - lo)).translate(
        tuple(float(x) for x in lo))  # fmt: skip


def _defect(kind: str, p: NDArray[np.float64], detail: str) -> Defect:
    return Defect(kind, (float(p[0]), float(p[1])), detail)  # as check3d: (x, y)


def bounded_violations(
    bounded: Bounded,
    output: PolyhedralModel,
    *,
    region: tuple[float, float, float, float, float, float] | None = None,
    outside: Mapping[str, int] | None = None,
    ground: Sequence[str] = (),
    float32: bool = False,
) -> Violations:
    """The defects of an output synthesized through bounding volumes (see the module
    docstring): labels the example lacks (``"label"``: a box left unfilled), curved parts
    that are no transformed original (``"curved"``), boxes whose content is not the
    original (``"content"``), and Eq. 4.1 on the proxy.

    Parameters
    ----------
    bounded : Bounded
        The example's bounding volumes (:func:`~csplab.continuous.bounding.
        bounding_volumes` of the original example).
    output : PolyhedralModel
        The output, with the curved geometry substituted back.
    region, outside, ground
        As for :func:`~csplab.continuous.check3d.violations3` (Eq. 4.1 on the proxy).
    float32 : bool, default False
        The output was read from a format that stores float32 coordinates (binary STL,
        glTF): a box corner found from its curved vertices within ``1e-4`` spacings of a
        lattice point is that point (the one synthesis placed), not the rounding beside it.

    Returns
    -------
    Violations
        Empty when the output passes all three checks.
    """
    from scipy.spatial import cKDTree

    man = require("manifold3d", "mesh", "checking bounding volumes")
    defects: list[Defect] = []
    for b in output.labels:  # a box left with its proxy label, say
        if b not in bounded.example.labels:
            defects.append(Defect("label", (math.nan, math.nan), (
                f"label {b} does not occur in the example (its labels: "
                f"{list(bounded.example.labels)})")))  # fmt: skip
    if output.solids:
        pts = np.concatenate([np.asarray(s.vertices) for s in output.solids])
        tol = _POINT_TOL * max(1.0, float(np.ptp(pts, axis=0).max()))
    else:
        tol = _POINT_TOL
    # the output's solids by bounding box, as manifold3d solids when a box needs them
    slo = np.array([np.asarray(x.vertices).min(axis=0) for x in output.solids]).reshape(-1, 3)
    shi = np.array([np.asarray(x.vertices).max(axis=0) for x in output.solids]).reshape(-1, 3)
    cache: dict[int, Any] = {}

    def meets(qlo: NDArray[np.float64], qhi: NDArray[np.float64]) -> NDArray[np.int64]:
        return np.flatnonzero(np.all(slo < qhi + tol, axis=1) & np.all(qlo < shi + tol, axis=1))

    def content_gap(f: Feature, qlo: NDArray[np.float64], qhi: NDArray[np.float64]) -> str:
        """Why the output inside ``Q`` is not the part's content mapped onto it, or ""."""
        move = axis_map(f.box_lo, f.box_hi, qlo, qhi)
        want = {int(b): c.warp_batch(move) for b, c in f.contents}
        here: dict[int, list[Any]] = {}
        for i in meets(qlo, qhi).tolist():
            if i not in cache:
                cache[i] = output.solids[i].to_manifold()
            here.setdefault(int(output.solids[i].label), []).append(cache[i])
        box = _box(qlo, qhi)
        ext = qhi - qlo
        area = 2 * float(ext[0] * ext[1] + ext[1] * ext[2] + ext[0] * ext[2])
        for b in sorted(set(want) | set(here)):
            have = (man.Manifold.batch_boolean(here[b], man.OpType.Add) ^ box
                    if b in here else None)  # fmt: skip
            w = want.get(b)
            va = float(have.volume()) if have is not None else 0.0
            vb = float(w.volume()) if w is not None else 0.0
            both = float((have ^ w).volume()) if have is not None and w is not None else 0.0
            diff = va + vb - 2 * both
            if diff > tol * area:  # the surface moved by at most the point tolerance
                return (f"label {b} inside the box {_show(qlo)}..{_show(qhi)} differs from "
                        f"the mapped original by volume {diff:.3g}")  # fmt: skip
        return ""

    def near_lattice(q: NDArray[np.float64]) -> NDArray[np.float64]:
        """A box corner found from a file's curved vertices, put on the lattice where it
        is within a file's rounding of it (float32 STL/glTF: the corner is then the
        lattice point synthesis placed, not one ~1e-6 beside it)."""
        u = (q - bounded.origin) / bounded.spacing
        r = np.rint(u)
        if not float32:
            return q
        return np.where(np.abs(u - r) <= 1e-4, bounded.origin + r * bounded.spacing, q)

    def on_lattice(qlo: NDArray[np.float64], qhi: NDArray[np.float64]) -> bool:
        u = (np.concatenate([qlo, qhi]).reshape(2, 3) - bounded.origin) / bounded.spacing
        return bool(np.abs(u - np.rint(u)).max() <= 1e-6)

    # 1. every curved region of the output: a part's region, mapped per axis, whose box
    # holds the part's content (parts alike up to scale, e.g. holes of other radii, match
    # the same region: the content decides)
    found: dict[tuple[int, tuple[float, ...]], tuple[Feature, Any, Any, set[int]]] = {}
    verdict: dict[tuple[int, tuple[float, ...]], str] = {}
    own = [[g.points for g in f.regions] for f in bounded.features]  # computed once
    for r in curved_regions(output):
        rp = r.points
        tree = cKDTree(rp)
        hits = []
        for k, f in enumerate(bounded.features):
            for j, g in enumerate(f.regions):
                if g.label != r.label or len(g.triangles) != len(r.triangles):
                    continue
                move = axis_map(g.lo, g.hi, r.lo, r.hi)
                gp = move(own[k][j])
                if len(gp) != len(rp):
                    continue
                d, near = tree.query(gp)  # one to one: as many points, each its own
                if float(d.max()) <= tol and len(np.unique(near)) == len(rp):
                    qlo, qhi = near_lattice(move(f.box_lo)), near_lattice(move(f.box_hi))
                    key = (k, tuple(np.round(np.concatenate([qlo, qhi]) / tol).tolist()))
                    hits.append((key, f, qlo, qhi, j))
        if not hits:
            defects.append(_defect("curved", r.lo, (
                f"a curved part of label {r.label} ({len(r.triangles)} triangles, "
                f"{r.orientations} orientations) is no moved and scaled curved part of the "
                "example")))  # fmt: skip
            continue
        for key, f, qlo, qhi, _ in hits:
            if key not in verdict:
                verdict[key] = content_gap(f, qlo, qhi)
        good = [h for h in hits if not verdict[h[0]]]
        # of those, a box on the output's lattice (parts alike up to scale whose contents
        # both fit: a smaller part's box lies off the lattice)
        good.sort(key=lambda h: not on_lattice(h[2], h[3]))
        if not good:
            key, f, qlo, qhi, _ = hits[0]
            defects.append(_defect("content", qlo, verdict[key]))
        key, f, qlo, qhi, j = (good or hits)[0]
        found.setdefault(key, (f, qlo, qhi, set()))[3].add(j)
    placed = []
    for f, qlo, qhi, regions in found.values():
        if len(regions) != len(f.regions):
            defects.append(_defect("curved", qlo, (
                f"a box holds {len(regions)} of the {len(f.regions)} curved regions of its "
                "part")))  # fmt: skip
        placed.append((f, qlo, qhi))
    # 2. the output with the boxes emptied, and the boxes' pieces
    boxes = [_box(qlo, qhi) for _, qlo, qhi in placed]
    los = np.array([q for _, q, _ in placed]).reshape(-1, 3)
    his = np.array([q for _, _, q in placed]).reshape(-1, 3)
    kept: list[Any] = []  # solids no box touches: as they are
    touched: list[tuple[int, Any, NDArray[np.bool_]]] = []  # (label, manifold, boxes met)
    for i, s in enumerate(output.solids):
        meet = np.all(los < shi[i] + tol, axis=1) & np.all(slo[i] < his + tol, axis=1)
        if meet.any():
            touched.append((int(s.label), cache.get(i) or s.to_manifold(), meet))
        else:
            kept.append(s)
    new: list[dict[str, Any]] = []  # the touched solids without the boxes, and the pieces
    for b, m, meet in touched:
        cut = man.Manifold.batch_boolean([boxes[k] for k in np.flatnonzero(meet)],
                                         man.OpType.Add)  # fmt: skip
        new += from_manifold(m - cut, b)
    rebuilt = PolyhedralModel(new, source=output.source).solids  # validated: closed, outward
    # the pieces: the proxy example's (validated) solids of the box's labels, moved and
    # scaled onto Q (a positive scaling per axis keeps them closed and outward)
    pieces: list[Solid] = []
    for f, qlo, qhi in placed:
        move = axis_map(f.box_lo, f.box_hi, qlo, qhi)  # Q is the placed lattice box
        for p in bounded.proxy.solids:
            if int(p.label) in f.labels:
                pieces.append(Solid(p.label, move(p.vertices), p.faces, p.polygons,
                                    p.face_polygon))  # fmt: skip
    proxy_out = PolyhedralModel.trusted([*kept, *rebuilt, *pieces], name=output.name,
                                        source=output.source)  # fmt: skip
    defects += list(violations3(bounded.proxy, proxy_out, region=region, outside=outside,
                                ground=ground))
    return Violations(defects)


def _show(p: NDArray[np.float64]) -> str:
    return "(" + ", ".join(f"{float(x):.6g}" for x in p) + ")"

