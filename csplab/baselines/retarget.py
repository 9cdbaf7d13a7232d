"""3D model retargeting with offset statistics (Wu et al.), on voxels.

Analysis: the example's closed solids are voxelized (``resolution`` voxels along the longest
side; exact point location). Surface voxels are the features; a feature's descriptor is the
occupancy of the ``5^3`` box around it (csplab's stand-in for the paper's SHOT descriptors,
with the reference frame fixed to the world axes as in the paper). Each feature is matched to
its most similar feature at least ``tau`` voxels away; the offsets are binned (one voxel per
bin) and the peaks of the histogram (non-maximum suppression within ``tau``) are the dominant
offsets. Along each axis the shortest of the frequent dominant offsets (at least half as
frequent as the most frequent one) is that axis' principal offset
(csplab keeps axis-aligned generators: the paper's models are mapped to such a canonical
frame, Sec. V).

Retargeting: the output volume of ``size`` voxels is labelled with translations of the input,
each voxel copying the input voxel its label shifts it back to (outside the input: empty).
The labels are the integer combinations of the principal offsets (*sparse*), or, for the
comparison of the paper's Fig. 1, every translation on a regular grid of ``regular`` voxels
(*all offsets*). The labelling is optimized by expansion moves over PyMaxflow: for each label
in turn, a minimum cut decides which voxels switch to it, a cut between neighbours ``x, y``
costing ``[cur(x) != new(x)] + [cur(y) != new(y)]`` (graph-cut texture seams); sweeps repeat
while the energy falls. The surface of the result is a closed mesh (marching cubes).

Examples
--------
>>> from csplab.examples.continuous3d import load_polyhedral_example
>>> v = voxelize(load_polyhedral_example("skyscrapers"), 12)
>>> v.shape, v.dtype.name, bool(v.any())
((12, 12, 12), 'bool', True)
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.deps import require
from csplab.errors import InputError
from csplab.rng import RngLike, make_rng

__all__ = ["OUTSIDE", "dominant_offsets", "retarget", "retarget_labels", "voxelize"]


def voxelize(model: Any, resolution: int = 24) -> NDArray[np.bool_]:
    """Occupancy of the voxels (centres inside a solid), ``resolution`` along the longest
    side of the model's bounds."""
    if resolution < 4:
        raise InputError(f"resolution must be >= 4, not {resolution}")
    b = np.array(model.bounds, dtype=np.float64)
    lo, hi = b[:3], b[3:]
    h = float((hi - lo).max()) / resolution
    shape = tuple(max(1, round((hi[a] - lo[a]) / h)) for a in range(3))
    from csplab.baselines.geometry import occupancy

    return occupancy(model, [lo[a] + h * (np.arange(shape[a]) + 0.5) + 1e-7 for a in range(3)])


def dominant_offsets(
    occ: NDArray[np.bool_], tau: int = 2
) -> tuple[list[tuple[tuple[int, int, int], int]], tuple[int, int, int]]:
    """The dominant offsets (with their counts, most frequent first) of the surface
    features, and the principal offset along each axis (0: none found)."""
    pad = np.pad(occ, 3)
    surf = occ & ~(
        np.roll(pad, 1, 0) & np.roll(pad, -1, 0) & np.roll(pad, 1, 1) & np.roll(pad, -1, 1)
        & np.roll(pad, 1, 2) & np.roll(pad, -1, 2)
    )[3:-3, 3:-3, 3:-3]  # fmt: skip
    feats = np.argwhere(surf)
    if len(feats) < 2:
        return [], (0, 0, 0)
    w = np.lib.stride_tricks.sliding_window_view(np.pad(occ, 2), (5, 5, 5))
    desc = w[feats[:, 0], feats[:, 1], feats[:, 2]].reshape(len(feats), -1).astype(np.int16)
    offsets = []
    for i in range(len(feats)):
        d = (desc != desc[i]).sum(axis=1).astype(np.float64)
        far = np.abs(feats - feats[i]).max(axis=1) >= tau
        if not far.any():
            continue
        d[~far] = np.inf
        j = int(np.argmin(d))
        offsets.append(tuple((feats[j] - feats[i]).tolist()))
    keys, counts = np.unique(np.array(offsets), axis=0, return_counts=True)
    order = np.argsort(-counts, kind="stable")
    keys, counts = keys[order], counts[order]
    peaks: list[tuple[tuple[int, int, int], int]] = []
    for k, c in zip(keys.tolist(), counts.tolist(), strict=True):
        if all(np.abs(np.array(k) - np.array(p)).max() > tau for p, _ in peaks):
            peaks.append(((int(k[0]), int(k[1]), int(k[2])), int(c)))
    principal = [0, 0, 0]
    for a in range(3):  # the shortest frequent offset along each axis: the generator
        along = [(abs(p[a]), c) for p, c in peaks
                 if p[a] != 0 and all(p[b] == 0 for b in range(3) if b != a)]  # fmt: skip
        if along:
            top = max(c for _, c in along)
            principal[a] = min(m for m, c in along if 2 * c >= top)
    return peaks, (principal[0], principal[1], principal[2])


def retarget_labels(
    occ: NDArray[np.bool_],
    size: Sequence[int],
    steps: Sequence[int],
    *,
    cell: Sequence[int] = (1, 1, 1),
    sweeps: int = 3,
    rng: RngLike = None,
) -> tuple[NDArray[np.bool_], dict[str, Any]]:
    """Label the ``size`` output with translations of ``occ`` by multiples of ``steps``
    (per axis; 0: that axis is not resized) by expansion moves; the output occupancy and
    the graph figures (nodes, labels, time, energy). The graph's nodes are blocks of
    ``cell`` voxels that take one label (the paper discretizes the retargeting space by the
    principal offsets: one node per offset step).

    Energy: a voxel whose label shifts it outside the input costs ``OUTSIDE`` (the copies
    must cover the output, as the paper's retargeting space); neighbours with different
    labels cost the seam ``[c_a(x) != c_b(x)] + [c_a(y) != c_b(y)]``."""
    maxflow = require("maxflow", "baselines", "the retarget baseline")
    shape = tuple(int(s) for s in size)
    if len(shape) != 3 or any(s < 1 for s in shape):
        raise InputError(f"size {shape} must be three positive sides")
    gen, _ = make_rng(rng)
    n_in = np.array(occ.shape)
    ranges = []
    for a in range(3):
        extra = max(0, shape[a] - int(n_in[a]))
        st = int(steps[a])
        r = [0] if st <= 0 else list(range(0, extra + st, st))
        ranges.append(r)
    labels = np.array(list(itertools.product(*ranges)), dtype=np.int64).reshape(-1, 3)
    idx = np.stack(np.meshgrid(*[np.arange(s) for s in shape], indexing="ij"), axis=-1)
    L = len(labels)
    copies = np.zeros((L, *shape), dtype=bool)
    valid = np.zeros((L, *shape), dtype=bool)
    for i, t in enumerate(labels):
        src = idx - t
        ok: NDArray[np.bool_] = np.asarray(((src >= 0) & (src < n_in)).all(axis=-1))
        srcc = np.where(ok[..., None], src, 0)
        valid[i] = ok
        copies[i] = ok & occ[srcc[..., 0], srcc[..., 1], srcc[..., 2]]
    # start: the shift that brings each voxel back into the input, per axis
    start = np.zeros((*shape, 3), dtype=np.int64)
    for a in range(3):
        st = int(steps[a])
        if st > 0:
            need = np.maximum(0, idx[..., a] - (int(n_in[a]) - 1))
            start[..., a] = np.minimum(-(-need // st) * st, ranges[a][-1])
    # the label of those shifts: its position in the product of the ranges (C order)
    step_no = [start[..., a] // max(int(steps[a]), 1) for a in range(3)]
    cur = np.ravel_multi_index(step_no, [len(r) for r in ranges]).astype(np.int64)
    ii, jj, kk = idx[..., 0], idx[..., 1], idx[..., 2]
    c = np.array([max(1, int(x)) for x in cell])
    coarse = tuple(int(-(-shape[a] // c[a])) for a in range(3))
    cidx = np.stack(np.meshgrid(*[np.arange(s) for s in coarse], indexing="ij"), axis=-1)

    def up(lab_c: NDArray[np.int64]) -> NDArray[np.int64]:
        """Cell labels -> voxel labels."""
        out: NDArray[np.int64] = lab_c[ii // c[0], jj // c[1], kk // c[2]]
        return out

    def cellsum(v: NDArray[np.float64]) -> NDArray[np.float64]:
        """Voxel values summed per cell."""
        out = np.zeros(coarse)
        np.add.at(out, (ii // c[0], jj // c[1], kk // c[2]), v)
        return out

    # the cells start with the label of their first voxel
    cur_c = cur[tuple(np.minimum(cidx[..., a] * c[a], shape[a] - 1) for a in range(3))]

    def energy(lab: NDArray[np.int64]) -> float:
        e = OUTSIDE * float((~valid[lab, ii, jj, kk]).sum())
        for a in range(3):
            x = [slice(None)] * 3
            y = [slice(None)] * 3
            x[a], y[a] = slice(0, -1), slice(1, None)
            la, lb = lab[tuple(x)], lab[tuple(y)]
            px = tuple(v[tuple(x)] for v in (ii, jj, kk))
            py = tuple(v[tuple(y)] for v in (ii, jj, kk))
            e += float((copies[(la, *px)] != copies[(lb, *px)]).sum())
            e += float((copies[(la, *py)] != copies[(lb, *py)]).sum())
        return e

    t0 = time.perf_counter()
    best = energy(up(cur_c))
    for _ in range(sweeps):
        improved = False
        for alpha in gen.permutation(L).tolist():
            cur = up(cur_c)
            old = copies[cur, ii, jj, kk]
            diff = (old != copies[alpha]).astype(np.float64)
            g = maxflow.Graph[float]()
            nodes = g.add_grid_nodes(coarse)
            for a in range(3):
                # seam weight between neighbouring cells: the voxel pairs across their face
                x = [slice(None)] * 3
                y = [slice(None)] * 3
                x[a], y[a] = slice(0, -1), slice(1, None)
                across = np.zeros(shape, dtype=bool)
                across[tuple(x)] = (idx[tuple(x)][..., a] // c[a]) != (
                    idx[tuple(y)][..., a] // c[a]
                )
                vw = np.zeros(shape)
                vw[tuple(x)] = (diff[tuple(x)] + diff[tuple(y)]) * across[tuple(x)]
                wgt = cellsum(vw)
                struct = np.zeros((3, 3, 3))
                pos = [1, 1, 1]
                pos[a] = 2
                struct[tuple(pos)] = 1
                g.add_grid_edges(nodes, weights=wgt, structure=struct, symmetric=True)
            cur_bad = cellsum((~valid[cur, ii, jj, kk]).astype(np.float64)) * OUTSIDE
            new_bad = cellsum((~valid[alpha]).astype(np.float64)) * OUTSIDE
            # keeping costs the cell's uncovered voxels now, switching those under alpha
            g.add_grid_tedges(nodes, new_bad, cur_bad)
            g.maxflow()
            cand_c = np.where(g.get_grid_segments(nodes), alpha, cur_c)
            e = energy(up(cand_c))
            if e < best:
                cur_c, best, improved = cand_c, e, True
        if not improved:
            break
    cur = up(cur_c)
    dt = time.perf_counter() - t0
    out = copies[cur, ii, jj, kk]
    info = {"nodes": int(np.prod(coarse)), "labels": L, "time_s": dt, "energy": best,
            "labels_used": len(np.unique(cur))}  # fmt: skip
    return np.asarray(out, dtype=bool), info


#: the data cost of a voxel whose label copies from outside the input
OUTSIDE = 1000.0


def retarget(
    model: Any,
    size: Sequence[int],
    *,
    resolution: int = 24,
    offsets: str = "sparse",
    regular: int = 2,
    tau: int = 2,
    rng: RngLike = None,
) -> Any:
    """Retarget a closed polyhedral model to ``size`` voxels (the example is
    ``resolution`` voxels along its longest side): ``offsets="sparse"`` uses the principal
    offsets of :func:`dominant_offsets`, ``"all"`` every translation ``regular`` voxels
    apart (the paper's conventional MRF). Returns a closed ``trimesh.Trimesh`` (in voxel
    units scaled to the example's) with the figures in ``mesh.metadata["retarget"]``."""
    from csplab.baselines.geometry import surface
    from csplab.continuous.polyhedra import PolyhedralModel

    if not isinstance(model, PolyhedralModel):
        raise InputError("the retarget baseline takes a polyhedral model (a closed mesh)")
    if offsets not in ("sparse", "all"):
        raise InputError(f"offsets must be sparse or all, not {offsets!r}")
    occ = voxelize(model, resolution)
    peaks, principal = dominant_offsets(occ, tau)
    if offsets == "sparse":
        steps, cell = principal, tuple(max(1, p) for p in principal)
    else:
        steps, cell = (regular, regular, regular), (1, 1, 1)
    grid, info = retarget_labels(occ, size, steps, cell=cell, rng=rng)
    info.update(dominant=len(peaks), principal=list(principal), offsets=offsets)
    sdf = np.where(grid, -1.0, 1.0)
    mesh = surface(sdf)
    b = np.array(model.bounds, dtype=np.float64)
    mesh.apply_scale(float((b[3:] - b[:3]).max()) / resolution)
    mesh.metadata["retarget"] = info
    return mesh
