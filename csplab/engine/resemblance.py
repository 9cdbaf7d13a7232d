"""Resemblance-weighted label choice: the 2007 paper's Sec. 3.3, Eq. 2–6.

When Alg. 3.1 (Step 4 of the paper's Table 2) assigns cell ``v``, each candidate label
``k`` of the catalog gets the weight

    L(k) = |{v' in E : d(w(v', E), w(v, M' + (v, k))) <= d0}|           (Eq. 4, 5)

where ``w(v, M)`` is the ``(2w+1)^d`` window of *assigned* labels around ``v`` (Eq. 2),
``d(P, Q) = |P| - |P ∩ Q|`` counts the model's window pieces the example's window at
``v'`` does not share (Eq. 3; a piece outside the example is never shared) and ``d0`` is
the minimum perceptual distance over all candidates and example locations. The label is
drawn with probability ``L(k) / sum L`` (Eq. 6): labels that continue a piece of the
example that the partial model already matches are preferred.

:class:`Resemblance` precomputes the example's windows once (``E[v' + q]`` for every
location and offset) so that a step costs one vectorised pass over the example's
locations. :func:`run_resemblance` is Alg. 3.1 with this choice (solver option
``choice="resemblance"`` of ``catalog``, ``blocks`` and ``hybrid``; ``blocks`` passes the
labels around the block, which the windows see as the paper's ``M'`` does).

Examples
--------
>>> import numpy as np
>>> from csplab import ExampleModel, from_example
>>> E = ExampleModel([[0, 0, 1, 1], [0, 0, 1, 1], [2, 2, 2, 2]])
>>> P = from_example(E, (6, 6))
>>> r = run_resemblance(P, E, np.random.default_rng(0))
>>> r.status, P.is_solution(r.grid)
('solved', True)
"""

from __future__ import annotations

import itertools
import time
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from csplab.catalog import Propagator
from csplab.errors import InputError
from csplab.problem import Problem
from csplab.result import Result, Status

if TYPE_CHECKING:
    from csplab.example import ExampleModel

__all__ = ["Resemblance", "run_resemblance"]

_OUTSIDE = -2  # an example window piece outside the example: never shared


class Resemblance:
    """The example's windows and the label weights of Eq. 4–6.

    Parameters
    ----------
    example : ExampleModel
    ndim : int
        Axes of the output grid (an example with fewer axes is extended by size-1 axes).
    window : int
        ``w``: windows of ``2w + 1`` cells per axis (default 1: 3×3 or 3×3×3).
    """

    def __init__(self, example: ExampleModel, ndim: int, window: int = 1) -> None:
        if window < 0:
            raise InputError(f"the resemblance window must be >= 0, not {window}")
        E = np.asarray(example.labels, dtype=np.int64)
        if E.ndim > ndim:
            raise InputError(f"a {E.ndim}-D example cannot guide a {ndim}-D output")
        E = E.reshape(E.shape + (1,) * (ndim - E.ndim))
        self.w = int(window)
        self.offsets = np.array(
            list(itertools.product(range(-window, window + 1), repeat=ndim)), dtype=np.int64
        )
        self.center = int(np.flatnonzero((self.offsets == 0).all(axis=1))[0])
        pos = np.stack(np.unravel_index(np.arange(E.size), E.shape), axis=1)
        q = pos[:, None, :] + self.offsets[None, :, :]
        inside: NDArray[np.bool_] = np.asarray(((q >= 0) & (q < np.array(E.shape))).all(axis=2))
        qc = np.where(inside[..., None], q, 0)
        self.windows = np.where(inside, E[tuple(np.moveaxis(qc, 2, 0))], _OUTSIDE)  # (m, |Q|)
        self.K = int(example.K)

    def weights(
        self, around: NDArray[np.int64], candidates: NDArray[np.int64]
    ) -> NDArray[np.float64]:
        """``L(k)`` for each candidate label, given the model's window ``around``
        (labels at the offsets, -1 where unassigned or outside the grid; the centre is
        ignored)."""
        known = around >= 0
        known[self.center] = False
        if known.any():
            base = (self.windows[:, known] != around[known]).sum(axis=1)
        else:
            base = np.zeros(self.windows.shape[0], dtype=np.int64)
        centre = self.windows[:, self.center]  # always inside the example
        K = max(self.K, int(candidates.max(initial=0)) + 1)
        in_cand = np.isin(centre, candidates)
        # d_k(v') = base(v') + [centre(v') != k]; d0 = its minimum over candidates k and v'
        # (a location whose centre is not k reaches base + 1: some candidate differs)
        d0 = min(int(base[in_cand].min(initial=1 << 30)), int(base.min()) + 1)
        hit = np.bincount(centre[base <= d0], minlength=K)[candidates]
        near = base + 1 <= d0
        L = hit + int(near.sum()) - np.bincount(centre[near], minlength=K)[candidates]
        return np.asarray(L, dtype=np.float64)


def run_resemblance(
    problem: Problem,
    example: ExampleModel,
    rng: np.random.Generator,
    *,
    order: NDArray[np.int64] | None = None,
    window: int = 1,
    context: tuple[NDArray[np.int64], NDArray[np.int64], tuple[int, ...]] | None = None,
    time_limit: float | None = None,
) -> Result:
    """Alg. 3.1 with the resemblance-weighted choice (see the module docstring).

    ``order`` is the cell sequence (default scanline). ``context`` = ``(grid, cells,
    shape)``: the labels of a larger model (flat, -1 unassigned), where this problem's
    cells sit in it and its shape -- the windows then see the labels around a block.
    """
    t0 = time.perf_counter()
    deadline = None if time_limit is None else t0 + float(time_limit)
    n = problem.n
    eng = Propagator(problem)
    grid = np.full(n, -1, dtype=np.int32)
    stats: dict[str, Any] = {"order": "given", "choice": "resemblance", "window": window}
    trace: list[tuple[int, int]] = []

    def done(status: Status) -> Result:
        stats.update(assigned=len(trace), revisions=int(eng.stats[0]),
                     removals=int(eng.stats[1]))  # fmt: skip
        return Result(status, grid.reshape(problem.shape), "catalog",
                      time_s=time.perf_counter() - t0, stats=stats,
                      trace=np.asarray(trace, dtype=np.int64).reshape(-1, 2))  # fmt: skip

    if not eng.ok or (problem.constraints and eng.constrain() != -1):
        stats["proof"] = "arc consistency (or a global constraint) empties a domain first"
        return done("unsat")
    if context is None:
        work = np.full(n, -1, dtype=np.int64)
        where = np.arange(n, dtype=np.int64)
        shape = problem.shape
    else:
        work = np.asarray(context[0], dtype=np.int64).reshape(-1).copy()
        where = np.asarray(context[1], dtype=np.int64)
        shape = tuple(context[2])
        work[where] = -1
    res = Resemblance(example, len(shape), window)
    s = np.array(shape, dtype=np.int64)
    seq = np.arange(n, dtype=np.int64) if order is None else np.asarray(order, dtype=np.int64)
    for step, v in enumerate(seq.tolist()):
        if deadline is not None and step % 64 == 0 and time.perf_counter() > deadline:
            return done("timeout")
        cand = eng.domain(v)
        if cand.size == 0:
            stats["fail_cell"] = list(problem.coords(v))
            return done("failed")
        p = np.array(np.unravel_index(int(where[v]), shape), dtype=np.int64)
        q = p + res.offsets
        inside = ((q >= 0) & (q < s)).all(axis=1)
        around = np.full(len(q), -1, dtype=np.int64)
        around[inside] = work[np.ravel_multi_index(tuple(q[inside].T), shape)]
        L = res.weights(around, cand) if cand.size > 1 else np.ones(1)
        tot = float(L.sum())
        if tot <= 0:
            k = int(cand[min(int(rng.random() * cand.size), cand.size - 1)])
        else:
            k = int(cand[min(int(np.searchsorted(np.cumsum(L), rng.random() * tot, "right")),
                             cand.size - 1)])  # fmt: skip
        grid[v] = k
        work[where[v]] = k
        trace.append((v, k))
        if not eng.assign(v, k) or (problem.constraints and eng.constrain() != -1):
            stats["fail_cell"] = list(problem.coords(eng.wiped)) if eng.wiped >= 0 else None
            return done("failed")
    return done("solved")
