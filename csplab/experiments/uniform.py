"""Exact uniform sampling and exact pattern frequencies on strips (transfer matrices).

For a problem whose arcs only join cells of the same slice ``x = i`` or of neighbouring
slices ``i, i + 1`` (grid problems from an example, not periodic along x), every solution is
a sequence of *slice states* (consistent labellings of one slice) with compatible
neighbours. :class:`StripSampler` enumerates the states of every slice, builds the
compatibility (transfer) matrices, and runs the forward/backward recursions. That gives:

* :meth:`~StripSampler.sample`: an exactly uniform random solution;
* :meth:`~StripSampler.label_frequencies`, :meth:`~StripSampler.pattern_frequencies`: the
  exact expected counts of every label and of every 2×2 (or other) window pattern over the
  uniform distribution on solutions;
* :attr:`~StripSampler.log_count`: the natural log of the number of solutions (the exact
  integer is :meth:`~StripSampler.count`, by :func:`csplab.count.count_solutions`).

Slice states are enumerated by the engine's exact search
(:func:`csplab.engine.completability.search_solutions`).

It is practical when slices are narrow (a few cells across and a few labels): the number of
states grows exponentially with the slice size. Probabilities use scaled floating point.

Examples
--------
>>> from csplab import ExampleModel, from_example
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (6, 3))           # checkerboard
>>> S = StripSampler(P)
>>> S.count()                                           # exactly two solutions
2
>>> g = S.sample(rng=4)
>>> P.is_solution(g)
True
>>> S.label_frequencies().tolist()                      # 9 of each label on average
[9.0, 9.0]
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.engine.completability import search_solutions
from csplab.errors import InputError
from csplab.problem import Problem
from csplab.rng import RngLike, make_rng

__all__ = ["StripSampler"]


class StripSampler:
    """Transfer-matrix model of a problem along axis 0 (see the module docstring).

    Parameters
    ----------
    problem : Problem
    max_states : int
        Refuse (with :class:`~csplab.errors.InputError`) when a slice has more states.
    """

    def __init__(self, problem: Problem, *, max_states: int = 20_000) -> None:
        self.problem = problem
        shp = problem.shape
        self.L = shp[0]
        self.slice_shape: tuple[int, ...] = shp[1:] if len(shp) > 1 else (1,)
        m = int(np.prod(self.slice_shape))
        self.m = m
        a = problem.arcs
        xs, xd = a[:, 0] // m, a[:, 1] // m
        if np.any(np.abs(xs - xd) > 1) or (self.L > 2 and np.any(np.abs(xs - xd) == self.L - 1)):
            raise InputError("StripSampler needs arcs only within a slice or between neighbours")
        # arcs inside one slice (the same for every slice of a grid problem, checked below)
        self.states: list[NDArray[np.int32]] = []
        cache: dict[bytes, NDArray[np.int32]] = {}
        for i in range(self.L):
            cells = np.arange(i * m, (i + 1) * m)
            inside = a[(xs == i) & (xd == i)]
            local = np.stack([inside[:, 0] - i * m, inside[:, 1] - i * m, inside[:, 2]], axis=1)
            dom = problem.domains[cells]
            key = dom.tobytes() + local.tobytes()
            st = cache.get(key)
            if st is None:
                sub = Problem(self.slice_shape, dom, problem.relations, local)
                found = []
                for g in search_solutions(sub, limit=max_states + 1):
                    found.append(g.reshape(-1))
                if len(found) > max_states:
                    raise InputError(
                        f"slice {i} has more than {max_states} states; StripSampler is for "
                        "narrow strips (make the problem narrower along the other axes)"
                    )
                st = (np.array(found, dtype=np.int32).reshape(len(found), m)
                      if found else np.zeros((0, m), dtype=np.int32))  # fmt: skip
                cache[key] = st
            self.states.append(st)
        # transfer matrices between slice i and i + 1
        self.T: list[NDArray[np.bool_]] = []
        rel = problem.relations
        for i in range(self.L - 1):
            A, B = self.states[i], self.states[i + 1]
            M = np.ones((A.shape[0], B.shape[0]), dtype=bool)
            fwd = a[(xs == i) & (xd == i + 1)]
            bwd = a[(xs == i + 1) & (xd == i)]
            for s, d, r in fwd:
                M &= rel[r][A[:, s - i * m]][:, B[:, d - (i + 1) * m]]
            for s, d, r in bwd:
                M &= rel[r].T[A[:, d - i * m]][:, B[:, s - (i + 1) * m]]
            self.T.append(M)
        # scaled forward / backward recursions
        self._fwd: list[NDArray[np.float64]] = []
        self._bwd: list[NDArray[np.float64]] = [np.zeros(0)] * self.L
        logz = 0.0
        f = np.ones(self.states[0].shape[0])
        self._fwd.append(f)
        for i in range(self.L - 1):
            f = f @ self.T[i].astype(np.float64)
            s = f.sum()
            if s > 0:
                f = f / s
                logz += math.log(s)
            self._fwd.append(f)
        last = self._fwd[-1].sum()
        self.log_count = logz + math.log(last) if last > 0 else -math.inf
        b = np.ones(self.states[-1].shape[0])
        self._bwd[-1] = b
        for i in range(self.L - 2, -1, -1):
            b = self.T[i].astype(np.float64) @ b
            s = b.sum()
            b = b / s if s > 0 else b
            self._bwd[i] = b

    @property
    def satisfiable(self) -> bool:
        return self.log_count > -math.inf

    def state_counts(self) -> list[int]:
        """Number of states per slice."""
        return [int(s.shape[0]) for s in self.states]

    def count(self) -> int:
        """The exact number of solutions: :func:`csplab.count.count_solutions` (its
        transfer method, the frontier form of these matrices)."""
        from csplab.count import count_solutions

        return int(count_solutions(self.problem, "transfer"))

    def _marginal(self, i: int) -> NDArray[np.float64]:
        p = self._fwd[i] * self._bwd[i]
        s = p.sum()
        return p / s if s > 0 else p

    def sample(self, rng: RngLike = None) -> NDArray[np.int32]:
        """One solution drawn exactly uniformly (up to floating-point rounding)."""
        if not self.satisfiable:
            raise InputError("the problem has no solution")
        gen, _ = make_rng(rng)
        out = np.empty((self.L, self.m), dtype=np.int32)
        p = self._marginal(0)
        s = int(gen.choice(p.size, p=p))
        out[0] = self.states[0][s]
        for i in range(self.L - 1):
            w = self.T[i][s] * self._bwd[i + 1]
            s = int(gen.choice(w.size, p=w / w.sum()))
            out[i + 1] = self.states[i + 1][s]
        return out.reshape(self.problem.shape)

    def sample_many(self, count: int, rng: RngLike = None) -> NDArray[np.int32]:
        """``count`` independent uniform solutions, shape ``(count, *problem.shape)``
        (vectorised over samples)."""
        if not self.satisfiable:
            raise InputError("the problem has no solution")
        gen, _ = make_rng(rng)
        out = np.empty((count, self.L, self.m), dtype=np.int32)
        p = self._marginal(0)
        s = np.minimum(np.searchsorted(np.cumsum(p), gen.random(count) * p.sum(), "right"),
                       p.size - 1)  # fmt: skip
        out[:, 0] = self.states[0][s]
        for i in range(self.L - 1):
            w = self.T[i][s] * self._bwd[i + 1][None, :]
            cum = np.cumsum(w, axis=1)
            u = gen.random(count) * cum[:, -1]
            s = np.minimum((cum <= u[:, None]).sum(axis=1), w.shape[1] - 1)
            out[:, i + 1] = self.states[i + 1][s]
        return out.reshape((count, *self.problem.shape))

    def label_frequencies(self) -> NDArray[np.float64]:
        """Expected count of each label in a uniform random solution, shape ``(K,)``."""
        K = self.problem.K
        tot = np.zeros(K)
        for i in range(self.L):
            p = self._marginal(i)
            for j in range(self.m):
                tot += np.bincount(self.states[i][:, j], weights=p, minlength=K)
        return tot

    def pattern_frequencies(self, window: int = 2) -> dict[int, float]:
        """Expected count of each ``window``-wide sub-block (base-``K`` code, as
        :func:`csplab.experiments.measures.pattern_counts`) in a uniform random solution.

        Only ``window = 2`` is supported along axis 0 (pairs of neighbouring slices).
        """
        if window != 2:
            raise InputError("pattern_frequencies supports window=2")
        K = self.problem.K
        out: dict[int, float] = {}
        if self.L < 2:
            return out
        for i in range(self.L - 1):
            A, B = self.states[i], self.states[i + 1]
            J = self._fwd[i][:, None] * self.T[i] * self._bwd[i + 1][None, :]
            J = J / J.sum()
            ia, ib = np.nonzero(J)
            for a_, b_ in zip(ia.tolist(), ib.tolist(), strict=True):
                pair = np.stack([A[a_], B[b_]]).reshape((2, *self.slice_shape))
                codes = _codes(pair, K)
                w = float(J[a_, b_])
                for c in codes:
                    out[c] = out.get(c, 0.0) + w
        return out


def _codes(grid: NDArray[Any], K: int) -> list[int]:
    from numpy.lib.stride_tricks import sliding_window_view

    g = np.asarray(grid, dtype=np.int64)
    w = tuple(min(2, s) for s in g.shape)
    size = int(np.prod(w))
    win = sliding_window_view(g, w).reshape(-1, size)
    return [int(c) for c in win @ (K ** np.arange(size - 1, -1, -1, dtype=np.int64))]
