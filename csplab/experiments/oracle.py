"""Completability oracles: can a partial model still be completed to a solution?

The exact catalog C* (Eq. 3.4) is "the partial model plus (x, b) can be completed". The
catalog-gap experiment asks this question many times for growing prefixes of an Alg. 3.1
run. Two oracles answer it:

* ``"sat"``: the incremental SAT engine of :mod:`csplab.solvers.sat` (``SatOracle``, with
  the partial model as assumptions), when that module is installed;
* ``"brute"``: depth-first search with arc consistency (:mod:`csplab.testing.brute`), exact
  but only for tiny problems.

``"auto"`` picks ``sat`` when available, else ``brute``.

Examples
--------
>>> from csplab import ExampleModel, Problem
>>> P = Problem.from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
>>> o = make_oracle(P, "brute")
>>> o.completable([0], [1]), o.completable([0, 1], [1, 1])
(True, False)
"""

from __future__ import annotations

import importlib.util
from collections.abc import Sequence
from typing import Any, Protocol

import numpy as np

from csplab.errors import DependencyError, InputError
from csplab.problem import Problem

__all__ = ["Oracle", "make_oracle", "oracle_methods"]


class Oracle(Protocol):
    name: str
    calls: int

    def completable(self, cells: Sequence[int], labels: Sequence[int]) -> bool: ...

    def close(self) -> None: ...


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

    def close(self) -> None:
        pass


class SatCompletion:
    """Completability with the incremental SAT engine (partial model as assumptions)."""

    name = "sat"

    def __init__(self, problem: Problem) -> None:
        mod: Any = __import__("csplab.solvers.sat", fromlist=["SatOracle"])
        self.problem = problem
        self.oracle = mod.SatOracle(problem)
        self.calls = 0

    def completable(self, cells: Sequence[int], labels: Sequence[int]) -> bool:
        self.calls += 1
        c = np.asarray(cells, dtype=np.int64)
        b = np.asarray(labels, dtype=np.int64)
        if c.size and np.any(~self.problem.domains[c, b]):
            return False
        lits = [int(self.oracle.literal(int(x), int(y))) for x, y in zip(c, b, strict=True)]
        r = self.oracle.solve(lits)
        if r == "timeout":
            raise InputError("the SAT oracle timed out")
        return bool(r == "sat")

    def close(self) -> None:
        self.oracle.close()


def oracle_methods() -> list[str]:
    """The oracles usable here."""
    out = ["brute"]
    if importlib.util.find_spec("csplab.solvers.sat") is not None and importlib.util.find_spec(
        "pysat"
    ):
        out.insert(0, "sat")
    return out


def make_oracle(problem: Problem, method: str = "auto") -> Oracle:
    """A completability oracle for ``problem`` (``"auto"``, ``"sat"`` or ``"brute"``)."""
    methods = oracle_methods()
    if method == "auto":
        method = methods[0]
    if method == "brute":
        return BruteOracle(problem)
    if method == "sat":
        if "sat" not in methods:
            raise DependencyError(
                "the sat oracle needs csplab's sat solver and python-sat "
                "(pip install 'csplab[sat]')"
            )
        return SatCompletion(problem)
    raise InputError(f"oracle must be auto, sat or brute, not {method!r}")
