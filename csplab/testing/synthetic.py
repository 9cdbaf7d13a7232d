"""Synthetic 3D example models for benchmarks and tests ("box towns").

:func:`box_town` builds a Merrell-style tiled 3D example: a ground layer, empty space, and
boxes ("buildings") standing on the ground, each cell of a box labelled by its material
and its position inside the box along each axis (low face, interior, high face), as a
tiled model's pieces would be. With ``m`` materials there are ``2 + 27 m`` labels (fewer
if some position never occurs), and a label's supports are small (about 1.5 labels per
direction), like real examples. These are csplab's stand-ins where the built-in 3D examples
are not needed (benchmarks take the built-ins from the registry when they exist).

Examples
--------
>>> E = box_town(materials=2, rng=0)
>>> E.ndim, E.K
(3, 56)
>>> E2 = box_town(materials=2, rng=0)
>>> bool((E.labels == E2.labels).all())
True
"""

from __future__ import annotations

import numpy as np

from csplab.example import ExampleModel
from csplab.problem import Problem
from csplab.rng import RngLike, make_rng

__all__ = ["box_town", "connected_city"]


def box_town(
    materials: int = 2,
    *,
    size: tuple[int, int, int] | None = None,
    boxes_per_material: int = 2,
    rng: RngLike = None,
) -> ExampleModel:
    """A 3D example: ground (label 1), empty space (label 0) and boxes of ``materials`` kinds.

    Each material gets ``boxes_per_material`` boxes of 3 to 5 cells per axis, standing on
    the ground and separated from each other by empty space. Label of a box cell:
    ``2 + 27 * material + 9 * px + 3 * py + pz`` with ``p = 0`` (low face), 1 (inside),
    2 (high face) along each axis. Every label occurs (the example's ``K`` is
    ``2 + 27 * materials``). The default ``size`` is ``(6m + 8, 6m + 8, 8)``.
    """
    gen, _seed = make_rng(rng)
    if size is None:
        size = (6 * materials + 8, 6 * materials + 8, 8)
    nx, ny, nz = size
    lab = np.zeros(size, dtype=np.int32)
    lab[:, :, 0] = 1
    occupied = np.zeros((nx, ny), dtype=bool)
    for m in range(materials):
        placed = 0
        for _attempt in range(500):
            if placed == boxes_per_material:
                break
            bx, by = int(gen.integers(3, 6)), int(gen.integers(3, 6))
            bz = int(gen.integers(3, min(6, nz - 1) + 1))
            x0 = int(gen.integers(1, nx - bx))
            y0 = int(gen.integers(1, ny - by))
            # keep one cell of empty space around every box
            if occupied[x0 - 1 : x0 + bx + 1, y0 - 1 : y0 + by + 1].any():
                continue
            occupied[x0 : x0 + bx, y0 : y0 + by] = True
            for i in range(bx):
                for j in range(by):
                    for k in range(bz):
                        p = [_pos(i, bx), _pos(j, by), _pos(k, bz)]
                        lab[x0 + i, y0 + j, 1 + k] = 2 + 27 * m + 9 * p[0] + 3 * p[1] + p[2]
            placed += 1
    return ExampleModel(lab, name=f"box_town_{materials}", num_labels=2 + 27 * materials)


def _pos(i: int, extent: int) -> int:
    return 0 if i == 0 else (2 if i == extent - 1 else 1)


def connected_city(
    size: tuple[int, ...] = (40, 40, 10), lo_frac: float = 0.05
) -> tuple[Problem, Problem]:
    """Merrell's City at Night of ``size`` with its boundary (``auto``), and the same with the
    global constraints of the performance issue: every non-background cell in one connected
    set, and between ``lo_frac`` and 30 % of the cells of it.

    Parameters
    ----------
    size : tuple of int
        The output size.
    lo_frac : float
        The count's lower bound as a share of the cells.

    Returns
    -------
    tuple of Problem
        The problem without and with the constraints.

    Examples
    --------
    >>> P, Q = connected_city((6, 6, 4))
    >>> len(P.constraints), [c.kind for c in Q.constraints]
    (0, ['connected', 'count'])
    """
    import csplab
    from csplab.constraints import parse_constraints
    from csplab.experiments.base import background_labels

    ex = csplab.load_example("city")
    P = csplab.from_example(ex, size, boundary="auto")
    bg = set(background_labels(ex))
    fg = [b for b in range(ex.K) if b not in bg]
    cons = [
        {"type": "connected", "labels": fg},
        {"type": "count", "labels": fg, "min": int(np.ceil(lo_frac * P.n)), "max": int(0.3 * P.n)},
    ]
    return P, P.with_constraints(parse_constraints(cons, P))
