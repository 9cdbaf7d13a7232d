"""Completability: can a partial model still be completed to a solution?

The exact catalog C* (thesis Eq. 3.4) is "the partial model plus ``cell = label`` can be
completed"; deciding it is NP-hard (Theorem 3.3.5). Everything in csplab that asks the
question goes through one protocol, :class:`Completability`, with two implementations:

* :class:`SatCompletability`: the incremental SAT oracle (:class:`~csplab.engine.sat.SatOracle`),
  one solver for many queries under assumptions; needs python-sat.
* :class:`SearchCompletability`: depth-first search with arc consistency (the compiled
  :class:`~csplab.catalog.Propagator`), exact, no dependency, for small problems; an optional
  node budget makes it answer ``None`` (undecided).

:func:`first_inconsistent_prefix` is the one binary search for "the first choice of a run
that left C*" (used by the ``hybrid`` solver, the catalog-gap experiment, the witness search
and :func:`csplab.exact.catalog_gap`). **Index base**: it returns the 0-based index ``k``
into the list of choices such that ``choices[:k]`` is completable and ``choices[:k + 1]`` is
not -- i.e. the step of the bad choice, counting from 0.

:func:`choose_from_exact` draws a label uniformly (or by weight) from C*(cell) with few SAT
calls, for the ``perfect`` and ``hybrid`` solvers.

Examples
--------
>>> import numpy as np
>>> from csplab import ExampleModel, Problem
>>> P = Problem.from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
>>> o = SearchCompletability(P)
>>> o.completable([0], [1]), o.completable([0, 1], [1, 1])
(True, False)
>>> first_inconsistent_prefix(o, np.array([[0, 1], [4, 1], [1, 1], [2, 0]]))
2
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.catalog import Propagator
from csplab.errors import InputError
from csplab.problem import Problem

__all__ = [
    "Completability",
    "PrefixTimeout",
    "SatCompletability",
    "SearchCompletability",
    "WitnessPool",
    "choose_from_exact",
    "first_inconsistent_prefix",
    "label_order",
    "make_completability",
]


class PrefixTimeout(Exception):
    """A completability query hit its deadline or node budget (undecided)."""


@runtime_checkable
class Completability(Protocol):
    """Answers "can the problem be solved with these cells fixed to these labels?"."""

    name: str
    calls: int

    def completable(
        self, cells: Sequence[int] | ArrayLike, labels: Sequence[int] | ArrayLike
    ) -> bool | None:
        """``True``/``False``, or ``None`` when undecided (time or node budget)."""
        ...


def _pairs(cells: Any, labels: Any) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    c = np.asarray(cells, dtype=np.int64).reshape(-1)
    b = np.asarray(labels, dtype=np.int64).reshape(-1)
    if c.shape != b.shape:
        raise InputError(f"cells and labels differ in length ({c.size} vs {b.size})")
    return c, b


class SearchCompletability:
    """Exact completability by depth-first search with arc consistency (small problems).

    Parameters
    ----------
    problem : Problem
    max_nodes : int, optional
        Search nodes per query before answering ``None`` (undecided); no limit by default.
    """

    name = "search"

    def __init__(self, problem: Problem, max_nodes: int | None = None) -> None:
        self.problem = problem
        self.max_nodes = max_nodes
        self.calls = 0

    def completable(self, cells: Any, labels: Any) -> bool | None:
        self.calls += 1
        c, b = _pairs(cells, labels)
        P = self.problem
        if c.size and np.any((b < 0) | (b >= P.K)):
            return False
        dom = P.domains.copy()
        if c.size:
            keep = dom[c, b]
            dom[c] = False
            dom[c, b] = keep
        eng = Propagator(P, domains=dom)
        return search_solution(eng, self.max_nodes) is not None if eng.ok else False


def search_solution(eng: Propagator, max_nodes: int | None = None) -> NDArray[np.int32] | None:
    """A solution below the propagated state ``eng`` by DFS with arc consistency
    (smallest domain first, labels in increasing order), or ``None`` if there is none.

    Raises :class:`PrefixTimeout` when ``max_nodes`` search nodes were not enough.
    """
    nodes = 0

    def rec(e: Propagator) -> NDArray[np.int32] | None:
        nonlocal nodes
        nodes += 1
        if max_nodes is not None and nodes > max_nodes:
            raise PrefixTimeout(f"more than {max_nodes} search nodes")
        sizes = e.sizes()
        open_ = np.flatnonzero(sizes > 1)
        if open_.size == 0:
            return np.asarray(np.argmax(e.catalog(), axis=1), dtype=np.int32)
        v = int(open_[np.argmin(sizes[open_])])
        for b in e.domain(v).tolist():
            e2 = e.copy()
            if e2.assign(v, int(b)):
                got = rec(e2)
                if got is not None:
                    return got
        return None

    return rec(eng)


class SatCompletability:
    """Exact completability by incremental SAT (one :class:`SatOracle`, assumptions).

    Parameters
    ----------
    problem : Problem
    backend : str, optional
        pysat backend, default ``cadical195``.
    deadline : float, optional
        ``time.perf_counter()`` value after which queries answer ``None``.
    """

    name = "sat"

    def __init__(
        self, problem: Problem, backend: str | None = None, deadline: float | None = None
    ) -> None:
        from csplab.engine.sat import SatOracle

        self.problem = problem
        self.deadline = deadline
        self.oracle = SatOracle(problem, backend=backend, deadline=deadline)
        self.calls = 0

    def completable(self, cells: Any, labels: Any) -> bool | None:
        self.calls += 1
        c, b = _pairs(cells, labels)
        o = self.oracle
        lits = [o.literal(int(x), int(y)) for x, y in zip(c.tolist(), b.tolist(), strict=True)]
        st = o.solve(lits, deadline=self.deadline)
        return None if st == "timeout" else st == "sat"

    def close(self) -> None:
        self.oracle.close()

    def __enter__(self) -> SatCompletability:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def make_completability(
    problem: Problem, method: str = "auto", **options: Any
) -> SatCompletability | SearchCompletability:
    """A :class:`Completability` for ``problem``: ``"sat"``, ``"search"`` or ``"auto"``
    (``sat`` when python-sat is installed)."""
    from csplab.deps import available

    if method == "auto":
        method = "sat" if available("pysat") else "search"
    if method == "sat":
        return SatCompletability(problem, **options)
    if method == "search":
        return SearchCompletability(problem, **options)
    raise InputError(f"completability method must be auto, sat or search, not {method!r}")


def first_inconsistent_prefix(
    oracle: Completability,
    choices: ArrayLike,
    *,
    full_inconsistent: bool = False,
) -> int | None:
    """The 0-based index ``k`` of the first choice that left C*: ``choices[:k]`` is
    completable and ``choices[:k + 1]`` is not; ``None`` if all of ``choices`` is
    completable.

    Consistency of a prefix is monotone (an inconsistent partial model stays
    inconsistent), so a binary search needs about ``log2(len(choices))`` queries. The empty
    prefix is assumed completable (check the problem first); ``full_inconsistent=True``
    says the whole sequence is known to be uncompletable (an Alg. 3.1 run that failed), which
    saves one query.

    Parameters
    ----------
    oracle : Completability
    choices : int array ``(steps, 2)``
        ``(cell, label)`` per step, e.g. :attr:`Result.trace` of Alg. 3.1.

    Raises
    ------
    PrefixTimeout
        When the oracle answers ``None`` (undecided).
    """
    ch = np.asarray(choices, dtype=np.int64).reshape(-1, 2)
    steps = ch.shape[0]

    def ok(t: int) -> bool:
        r = oracle.completable(ch[:t, 0], ch[:t, 1])
        if r is None:
            raise PrefixTimeout(f"completability of a {t}-step prefix undecided")
        return bool(r)

    if not full_inconsistent and (steps == 0 or ok(steps)):
        return None
    lo, hi = 0, steps  # prefix lo is completable, prefix hi is not
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if ok(mid):
            lo = mid
        else:
            hi = mid
    return hi - 1


# ----------------------------------------------------------------------------- drawing from C*


def label_order(
    labels: NDArray[np.int64], weights: NDArray[np.float64] | None, rng: np.random.Generator
) -> NDArray[np.int64]:
    """A random order of ``labels``: uniform, or weighted sampling without replacement
    (the first element of the order that lies in a subset S is then a uniform, or
    weight-proportional, draw from S)."""
    if weights is None:
        return labels[rng.permutation(labels.size)]
    w = np.asarray(weights, dtype=np.float64)[labels]
    keys = np.where(w > 0, rng.exponential(size=labels.size) / np.where(w > 0, w, 1.0), np.inf)
    return labels[np.argsort(keys, kind="stable")]


class WitnessPool:
    """Solutions consistent with the partial model so far (labels known to be in C*)."""

    def __init__(self, n: int, size: int) -> None:
        self.rows = np.zeros((0, n), dtype=np.int32)
        self.size = max(1, size)

    def has(self, cell: int, label: int) -> bool:
        return bool(np.any(self.rows[:, cell] == label))

    def add(self, grid: NDArray[np.int32]) -> None:
        self.rows = np.concatenate([grid.reshape(1, -1), self.rows])[: self.size]

    def fix(self, cell: int, label: int) -> None:
        self.rows = self.rows[self.rows[:, cell] == label]


def choose_from_exact(
    oracle: Any, pool: WitnessPool, cell: int, labels: NDArray[np.int64],
    weights: NDArray[np.float64] | None, rng: np.random.Generator, stats: dict[str, Any],
    deadline: float | None,
) -> int | None:  # fmt: skip
    """A label of C*(cell) drawn uniformly (by weight) from ``labels`` ⊇ C*(cell).

    Draw the labels in a random order (:func:`label_order`); the first one in C* is the
    draw. A label is known to be in C* without a SAT call if a witness of ``pool`` has it;
    otherwise one incremental call to ``oracle`` (a :class:`~csplab.engine.sat.SatOracle`)
    under one assumption decides it. Rejected labels are added as negative unit clauses
    (C* only shrinks as the model grows). Counts ``stats["sat_calls"]`` and
    ``stats["rejected"]``. Returns ``None`` on timeout (or, which cannot happen when the
    partial model is consistent, if no label is in C*).
    """
    for b in label_order(labels, weights, rng).tolist():
        if pool.has(cell, b):
            return int(b)
        lit = oracle.literal(cell, b)
        st = oracle.solve([lit], deadline=deadline)
        stats["sat_calls"] += 1
        if st == "timeout":
            return None
        if st == "sat":
            assert oracle.grid is not None
            pool.add(oracle.grid.reshape(-1))
            return int(b)
        stats["rejected"] += 1
        oracle.add_clause([-lit])
    return None
