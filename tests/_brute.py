"""Exact helpers for tests of small examples (brute force; slow on big grids).

The exhaustive searches themselves live in the package (``csplab.analysis``,
``csplab.testing.brute``); these are thin conveniences for the thesis-example tests.

Examples
--------
>>> from csplab import ExampleModel, from_example
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
>>> len(solutions(P))
2
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from csplab.catalog import Propagator
from csplab.problem import Problem
from csplab.testing import brute

__all__ = ["assign_all", "catalogs", "satisfiable", "solutions"]


def assign_all(problem: Problem, assignments: dict[tuple[int, ...], int]) -> Propagator:
    """A propagated engine with ``{coords: label}`` assigned (check ``.ok``)."""
    eng = Propagator(problem)
    for c, b in assignments.items():
        if not eng.assign(problem.cell(c), int(b)):
            break
    return eng


def _partial(problem: Problem, eng: Propagator) -> NDArray[np.int64]:
    C = eng.catalog()
    return np.where(C.sum(axis=1) == 1, C.argmax(axis=1), -1).reshape(problem.shape)


def satisfiable(problem: Problem, eng: Propagator) -> bool:
    """Does the engine's catalog contain a complete consistent model?"""
    if not eng.ok:
        return False
    return (
        brute.satisfiable(problem.restrict(eng.catalog().reshape(*problem.shape, problem.K)))
        is True
    )


def solutions(problem: Problem, limit: int | None = None) -> list[NDArray[np.int32]]:
    """Every consistent model of a small problem (MAC backtracking)."""
    return list(brute.solutions(problem, limit=limit))


def catalogs(
    problem: Problem, assignments: dict[tuple[int, ...], int]
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """``(C, C*)`` as ``bool (n, K)`` for an incomplete model: the arc-consistent catalog and
    the exact one (label kept iff some consistent completion uses it)."""
    eng = assign_all(problem, assignments)
    C = eng.catalog()
    if not eng.ok:
        return C, np.zeros_like(C)
    return C, brute.exact_catalog(problem.restrict(C.reshape(*problem.shape, problem.K)))
