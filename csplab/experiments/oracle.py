"""Completability oracles: can a partial model still be completed to a solution?

The exact catalog C* (Eq. 3.4) is "the partial model plus (x, b) can be completed". The
catalog-gap experiment asks this question for growing prefixes of an Alg. 3.1 run. With
python-sat installed it uses the incremental SAT engine through
:func:`csplab.exact.catalog_gap` (oracle ``"sat"``); this module supplies the fallback
``"brute"``: depth-first search with arc consistency (:mod:`csplab.testing.brute`), exact but
only for tiny problems. :func:`oracle_methods` lists what is usable here, best first.

Examples
--------
>>> from csplab import ExampleModel, Problem
>>> P = Problem.from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
>>> o = make_oracle(P, "brute")
>>> o.completable([0], [1]), o.completable([0, 1], [1, 1])
(True, False)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from csplab.deps import available
from csplab.errors import InputError
from csplab.problem import Problem

__all__ = ["BruteOracle", "make_oracle", "oracle_methods"]


class BruteOracle:
    """Exact completability by DFS with arc consistency (tiny problems only)."""

    name = "brute"

    def __init__(self, problem: Problem) -> None:
        self.problem = problem
        self.calls = 0

    def completable(self, cells: Sequence[int], labels: Sequence[int]) -> bool:
        from csplab.testing.brute import solutions

        self.calls += 1
        part = np.full(self.problem.n, -1, dtype=np.int64)
        part[np.asarray(cells, dtype=np.int64)] = np.asarray(labels, dtype=np.int64)
        if np.any(~self.problem.domains[np.asarray(cells, dtype=np.int64),
                                        np.asarray(labels, dtype=np.int64)]):  # fmt: skip
            return False
        return next(iter(solutions(self.problem, part.reshape(self.problem.shape), limit=1)),
                    None) is not None  # fmt: skip


def oracle_methods() -> list[str]:
    """The oracles usable here, best first (``"sat"`` needs python-sat)."""
    return ["sat", "brute"] if available("pysat") else ["brute"]


def make_oracle(problem: Problem, method: str = "brute") -> BruteOracle:
    """A completability oracle for ``problem``: ``"brute"`` (the ``"sat"`` oracle is
    :func:`csplab.exact.catalog_gap`, which runs the whole replay itself)."""
    if method != "brute":
        raise InputError(f"make_oracle builds the brute oracle only, not {method!r}")
    return BruteOracle(problem)
