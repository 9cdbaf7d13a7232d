"""Brute-force references for tiny problems: every solution, the exact catalog C*.

These enumerate solutions by depth-first search with arc consistency (so they are exact
and complete) and are meant for problems with at most a few thousand solutions.

They are the tests' independent reference: the library's own exact search is
:mod:`csplab.engine.completability` (``SearchCompletability``, ``search_solutions``), which
the tests check against this module; nothing in the library imports it.

Examples
--------
>>> from csplab import ExampleModel, from_example
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 4))
>>> len(list(solutions(P)))          # the checkerboard has two solutions at every size
2
>>> bool(exact_catalog(P).all())
True
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.catalog import Propagator
from csplab.problem import Problem

__all__ = ["count", "exact_catalog", "satisfiable", "solutions"]


def solutions(
    problem: Problem, partial: ArrayLike | None = None, limit: int | None = None
) -> Iterator[NDArray[np.int32]]:
    """Every solution (as a grid of the problem's shape) extending ``partial`` (-1 = free)."""
    eng = Propagator(problem)
    if partial is not None:
        flat = np.asarray(partial).reshape(-1)
        for c in np.flatnonzero(flat >= 0):
            if not eng.assign(int(c), int(flat[c])):
                return
    if not eng.ok:
        return
    found = 0

    def rec(e: Propagator) -> Iterator[NDArray[np.int32]]:
        nonlocal found
        sizes = e.sizes()
        open_cells = np.flatnonzero(sizes > 1)
        if open_cells.size == 0:
            g = e.catalog().argmax(axis=1).astype(np.int32)
            if problem.is_solution(g):  # AC on singletons is a full check, but be safe
                found += 1
                yield g.reshape(problem.shape)
            return
        c = int(open_cells[np.argmin(sizes[open_cells])])
        for b in e.domain(c):
            e2 = e.copy()
            if e2.assign(c, int(b)):
                yield from rec(e2)
                if limit is not None and found >= limit:
                    return

    yield from rec(eng)


def count(problem: Problem, partial: ArrayLike | None = None) -> int:
    """Number of solutions (brute force)."""
    return sum(1 for _ in solutions(problem, partial))


def exact_catalog(problem: Problem, partial: ArrayLike | None = None) -> NDArray[np.bool_]:
    """C*: ``[cell, label]`` true iff some solution extending ``partial`` has it (Eq. 3.4)."""
    C = np.zeros((problem.n, problem.K), dtype=bool)
    idx = np.arange(problem.n)
    for g in solutions(problem, partial):
        C[idx, g.reshape(-1)] = True
    return C


def satisfiable(
    problem: Problem, partial: ArrayLike | None = None, max_nodes: int | None = None
) -> bool | None:
    """Does a solution extend ``partial`` (-1 = free)? MAC backtracking (smallest domain
    first); ``None`` when ``max_nodes`` search nodes did not decide it.

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
    >>> satisfiable(P, [[0, -1, -1], [-1, 0, -1], [-1, -1, -1]]), satisfiable(P, [[0, 0, -1],
    ...     [-1, -1, -1], [-1, -1, -1]])
    (True, False)
    """
    eng = Propagator(problem)
    if partial is not None:
        flat = np.asarray(partial).reshape(-1)
        for c in np.flatnonzero(flat >= 0):
            if not eng.assign(int(c), int(flat[c])):
                return False
    if not eng.ok:
        return False
    nodes = 0

    def rec(e: Propagator) -> bool | None:
        nonlocal nodes
        nodes += 1
        if max_nodes is not None and nodes > max_nodes:
            return None
        sizes = e.sizes()
        open_cells = np.flatnonzero(sizes > 1)
        if open_cells.size == 0:
            return True
        c = int(open_cells[np.argmin(sizes[open_cells])])
        undecided = False
        for b in e.domain(c):
            e2 = e.copy()
            if e2.assign(c, int(b)):
                r = rec(e2)
                if r:
                    return True
                if r is None:
                    undecided = True
                    break
        return None if undecided else False

    return rec(eng)
