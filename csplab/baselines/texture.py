"""Non-parametric texture synthesis of label grids (Efros & Leung 1999), 2D and 3D.

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

__all__ = ["efros_leung"]


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
