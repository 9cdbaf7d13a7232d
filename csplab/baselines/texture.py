"""Texture synthesis of label grids, 2D and 3D: non-parametric sampling (Efros & Leung 1999)
and graph-cut patches (Kwatra et al. 2003).

The baseline the thesis compares model synthesis with (Sec. 2.3, 5.1, Fig. 5.1): the output
grows cell by cell in scanline order; each new cell looks at its *causal* neighbourhood (the
cells of a ``window``-wide box around it that are already synthesized), finds the example
positions whose neighbourhood differs least from it (Hamming distance over the known cells;
cells outside the example count as different), and copies the label of one of the positions
within ``(1 + eps)`` of the best distance, drawn uniformly. Nothing enforces the adjacency
constraint: ``Problem.violations`` counts what it breaks (``csplab check``).

Examples
--------
>>> from csplab.examples import load_example
>>> E = load_example("fig3_10")
>>> g = efros_leung(E, (12, 12), window=3, rng=1)
>>> g.shape, g.dtype.name, set(g.ravel().tolist()) <= set(range(E.K))
((12, 12), 'int32', True)
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from csplab.errors import InputError
from csplab.example import ExampleModel
from csplab.rng import RngLike, make_rng

__all__ = ["METHODS", "efros_leung", "graphcut", "texture"]


def _offsets(ndim: int, window: int) -> NDArray[np.int64]:
    """The causal offsets of a ``window``-wide box: cells before the centre in C order."""
    h = window // 2
    box = [o for o in itertools.product(range(-h, h + 1), repeat=ndim) if any(o)]
    causal = [o for o in box if o < (0,) * ndim]  # lexicographically before: synthesized
    return np.array(causal, dtype=np.int64).reshape(-1, ndim)


def efros_leung(
    example: ExampleModel,
    size: Sequence[int],
    *,
    window: int = 5,
    eps: float = 0.1,
    rng: RngLike = None,
) -> NDArray[np.int32]:
    """A label grid of ``size`` grown from ``example`` by Efros-Leung sampling.

    Parameters
    ----------
    example : ExampleModel
    size : sequence of int
        The output shape (as many axes as the example).
    window : int
        Odd width of the neighbourhood box (in cells, every axis).
    eps : float
        Candidates within ``(1 + eps)`` times the best distance are drawn uniformly.
    rng : int or numpy Generator, optional

    Returns
    -------
    int32 array of shape ``size``
    """
    shape = tuple(int(s) for s in size)
    E = np.asarray(example.labels, dtype=np.int64)
    if len(shape) != E.ndim:
        raise InputError(f"size {shape} has {len(shape)} axes, the example has {E.ndim}")
    if any(s < 1 for s in shape):
        raise InputError(f"size {shape} must be positive")
    if window < 1 or window % 2 == 0:
        raise InputError(f"window must be a positive odd number, not {window}")
    if not eps >= 0:
        raise InputError(f"eps must be >= 0, not {eps}")
    gen, _ = make_rng(rng)
    off = _offsets(E.ndim, window)
    # the example's neighbourhood of every position (-1: outside the example)
    pos = np.array(list(np.ndindex(*E.shape)), dtype=np.int64).reshape(-1, E.ndim)
    nb = pos[:, None, :] + off[None, :, :]
    inside: NDArray[np.bool_] = np.asarray(((nb >= 0) & (nb < np.array(E.shape))).all(axis=2))
    nbc = np.where(inside[..., None], nb, 0)
    ex_nb = np.where(inside, E[tuple(nbc[..., a] for a in range(E.ndim))], -1)
    ex_lab = E.reshape(-1)
    out = np.full(shape, -1, dtype=np.int64)
    lim = np.array(shape)
    for cell in np.ndindex(*shape):
        q = np.array(cell) + off
        ok: NDArray[np.bool_] = np.asarray(((q >= 0) & (q < lim)).all(axis=1))
        qc = np.where(ok[:, None], q, 0)
        known = np.where(ok, out[tuple(qc[:, a] for a in range(E.ndim))], -1)
        use = known >= 0
        if not use.any():
            out[cell] = ex_lab[int(gen.integers(len(ex_lab)))]
            continue
        dist = (ex_nb[:, use] != known[use][None, :]).sum(axis=1)
        best = int(dist.min())
        cand = np.flatnonzero(dist <= best * (1.0 + eps))
        out[cell] = ex_lab[int(cand[gen.integers(len(cand))])]
    return out.astype(np.int32)


def graphcut(
    example: ExampleModel,
    size: Sequence[int],
    *,
    patch: int = 8,
    overlap: int = 3,
    eps: float = 0.1,
    rng: RngLike = None,
) -> NDArray[np.int32]:
    """Graph-cut patch synthesis of a label grid (Kwatra et al. 2003, 2D and 3D).

    Patches of the example (``patch`` cells per axis, clipped to the example) are placed in
    scan order, ``patch - overlap`` apart; each copies the example block whose labels
    disagree least with the cells already written under it (one of those within
    ``(1 + eps)`` of the best, uniformly), and the seam between old and new cells is a
    minimum cut (PyMaxflow) where cutting between neighbours ``s, t`` costs
    ``[old(s) != new(s)] + [old(t) != new(t)]``: written cells on the footprint's border keep
    their label, unwritten ones take the patch's.

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> g = graphcut(load_example("fig3_10"), (14, 14), patch=4, overlap=2, rng=0)
    >>> g.shape, int(g.min()) >= 0
    ((14, 14), True)
    """
    from csplab.deps import require

    maxflow = require("maxflow", "baselines", "the graph-cut texture baseline")
    shape = tuple(int(s) for s in size)
    E = np.asarray(example.labels, dtype=np.int64)
    d = E.ndim
    if len(shape) != d or any(s < 1 for s in shape):
        raise InputError(f"size {shape} must have {d} positive axes like the example")
    if patch < 2 or not 0 <= overlap < patch:
        raise InputError(f"need patch >= 2 and 0 <= overlap < patch, not {patch}, {overlap}")
    if not eps >= 0:
        raise InputError(f"eps must be >= 0, not {eps}")
    gen, _ = make_rng(rng)
    P = np.minimum(patch, np.array(E.shape))
    step = np.maximum(P - overlap, 1)
    out = np.full(shape, -1, dtype=np.int64)
    # every example block of size P (its corner)
    corners = np.array(list(np.ndindex(*(np.array(E.shape) - P + 1))), dtype=np.int64)
    starts = [np.arange(0, s, st) for s, st in zip(shape, step, strict=True)]
    for corner in itertools.product(*starts):
        lo = np.array(corner)
        hi = np.minimum(lo + P, shape)
        ext = hi - lo
        win = tuple(slice(a, b) for a, b in zip(lo, hi, strict=True))
        old = out[win]
        filled = old >= 0
        # candidate blocks: mismatches over the written cells
        costs = np.empty(len(corners))
        for i, c in enumerate(corners):
            blk = E[tuple(slice(a, a + e) for a, e in zip(c, ext, strict=True))]
            costs[i] = np.count_nonzero((blk != old) & filled)
        best = costs.min()
        cand = np.flatnonzero(costs <= best * (1.0 + eps))
        c = corners[int(cand[gen.integers(len(cand))])]
        new = E[tuple(slice(a, a + e) for a, e in zip(c, ext, strict=True))]
        if not filled.any():
            out[win] = new
            continue
        # the seam: a minimum cut between keeping the old labels and taking the new ones
        g = maxflow.Graph[float]()
        nodes = g.add_grid_nodes(old.shape)
        diff = (old != new).astype(np.float64)
        for axis in range(d):
            w = np.zeros(old.shape)
            a = [slice(None)] * d
            b = [slice(None)] * d
            a[axis], b[axis] = slice(0, -1), slice(1, None)
            w[tuple(a)] = diff[tuple(a)] + diff[tuple(b)] + 1e-6
            struct = np.zeros((3,) * d)
            idx = [1] * d
            idx[axis] = 2
            struct[tuple(idx)] = 1
            g.add_grid_edges(nodes, weights=w, structure=struct, symmetric=True)
        big = 1e9
        border = np.zeros(old.shape, dtype=bool)  # written cells next to written outside
        for axis in range(d):
            for side, at in ((0, lo[axis] - 1), (-1, hi[axis])):
                if 0 <= at < shape[axis]:
                    sl = [slice(a, b) for a, b in zip(lo, hi, strict=True)]
                    sl[axis] = slice(at, at + 1)
                    outside = (out[tuple(sl)] >= 0).reshape(
                        [1 if k == axis else ext[k] for k in range(d)])  # fmt: skip
                    face = [slice(None)] * d
                    face[axis] = slice(side, side + 1) if side == 0 else slice(-1, None)
                    border[tuple(face)] |= outside & filled[tuple(face)]
        g.add_grid_tedges(nodes, np.where(border, big, 0.0), np.where(~filled, big, 0.0))
        g.maxflow()
        take_new = g.get_grid_segments(nodes)  # sink side: the new patch
        out[win] = np.where(take_new, new, old)
    return out.astype(np.int32)


#: the texture synthesis methods of :func:`texture`
METHODS = ("efros-leung", "graphcut")


def texture_memory(
    example: ExampleModel,
    size: Sequence[int],
    *,
    method: str = "efros-leung",
    window: int = 5,
    patch: int = 8,
    overlap: int = 3,
    **_: object,
) -> float:
    """The peak bytes :func:`texture` would allocate, from the sizes alone (nothing is
    built). Efros-Leung keeps, per example cell, its causal neighbourhood of
    ``(window**d - 1) / 2`` offsets: coordinates twice (8 bytes per axis each), an inside
    mask and the labels (``17 d + 16`` bytes per pair), after listing the ``window**d``
    offsets of the box (about 100 bytes each). Graph-cut keeps the output, the example's
    patch corners and one patch's flow graph.

    Examples
    --------
    >>> from csplab.examples import load_example
    >>> texture_memory(load_example("castle"), (10, 10, 8), window=999) > 1e12
    True
    >>> texture_memory(load_example("castle"), (10, 10, 8)) < 1e8
    True
    """
    E = np.asarray(example.labels)
    d = E.ndim
    cells = float(np.prod([float(s) for s in size]))
    ex = float(E.size)
    if method == "graphcut":
        p = float(min(patch, *E.shape)) ** d
        return 24 * cells + 8 * d * ex + 400 * p
    box = float(window) ** d
    return (box - 1) / 2 * ex * (17 * d + 16) + 100 * box + 24 * cells


def texture(
    example: ExampleModel,
    size: Sequence[int],
    *,
    method: str = "efros-leung",
    window: int = 5,
    patch: int = 8,
    overlap: int = 3,
    eps: float = 0.1,
    rng: RngLike = None,
) -> NDArray[np.int32]:
    """Texture synthesis of a label grid: :func:`efros_leung` (``window``) or
    :func:`graphcut` (``patch``, ``overlap``); ``eps`` for both."""
    if method == "efros-leung":
        return efros_leung(example, size, window=window, eps=eps, rng=rng)
    if method == "graphcut":
        return graphcut(example, size, patch=patch, overlap=overlap, eps=eps, rng=rng)
    raise InputError(f"texture method must be one of {', '.join(METHODS)}, not {method!r}")
