"""Completability: can a partial model still be completed to a solution?

The exact catalog C* (thesis Eq. 3.4) is "the partial model plus ``cell = label`` can be
completed"; deciding it is NP-hard (Theorem 3.3.5). Everything in csplab that asks the
question goes through one protocol, :class:`Completability`, with two implementations:

* :class:`SatCompletability`: the incremental SAT oracle (:class:`~csplab.engine.sat.SatOracle`),
  one solver for many queries under assumptions; needs python-sat.
* :class:`SearchCompletability`: depth-first search with arc consistency (the compiled
  :class:`~csplab.catalog.Propagator`), exact, no dependency, for small problems; an optional
  node budget makes it answer ``None`` (undecided).

Both keep the completion found by the last ``True`` answer (``solution``) and can fix a
partial model for all later queries (``fix``). :func:`make_completability` picks one.

:func:`first_inconsistent_prefix` is the one binary search for "the first choice of a run
that left C*" (used by the ``hybrid`` solver, the catalog-gap experiment, the witness search
and :func:`csplab.exact.catalog_gap`). **Index base**: it returns the 0-based index ``k``
into the list of choices such that ``choices[:k]`` is completable and ``choices[:k + 1]`` is
not -- i.e. the step of the bad choice, counting from 0. (Reports that count choices from 1
convert at their edge with an explicit ``+ 1``.) :func:`catalog_at` gives C(p) and C*(p)
before one step of such a run.

:func:`search_solutions` enumerates every solution (depth-first, arc consistency, smallest
domain first, labels in increasing order) for the library's exact tools on tiny problems.

:func:`choose_from_exact` draws a label uniformly (or by weight) from C*(cell) with few SAT
calls, for the ``perfect`` and ``hybrid`` solvers.

Examples
--------
>>> import numpy as np
>>> from csplab import ExampleModel, from_example
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
>>> o = SearchCompletability(P)
>>> o.completable([0, 1], [1, 1])
False
>>> o.completable([0], [1]), o.solution.reshape(P.shape).tolist()   # and a completion
(True, [[1, 0, 1], [0, 1, 0], [1, 0, 1]])
>>> first_inconsistent_prefix(o, np.array([[0, 1], [4, 1], [1, 1], [2, 0]]))
2
>>> len(list(search_solutions(P)))              # the two checkerboards
2
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab._closing import Closing
from csplab.catalog import Propagator, propagate
from csplab.errors import InputError
from csplab.problem import Problem
from csplab.rng import RngLike

if TYPE_CHECKING:
    from csplab.engine.sat import SatOracle

__all__ = [
    "Completability",
    "PrefixTimeout",
    "SatCompletability",
    "SearchCompletability",
    "WitnessPool",
    "catalog_at",
    "choose_from_exact",
    "first_inconsistent_prefix",
    "label_order",
    "make_completability",
    "search_solution",
    "search_solutions",
]


class PrefixTimeout(Exception):
    """A completability query hit its deadline or node budget (undecided)."""


@runtime_checkable
class Completability(Protocol):
    """Answers "can the problem be solved with these cells fixed to these labels?".

    Attributes
    ----------
    name : str
        ``"sat"`` or ``"search"``.
    calls : int
        Queries answered so far (:meth:`completable` calls).
    solution : int32 array ``(n,)`` or None
        A completion found by the last query if it answered ``True``, else ``None``.
    """

    name: str
    calls: int
    solution: NDArray[np.int32] | None

    def completable(
        self, cells: Sequence[int] | ArrayLike, labels: Sequence[int] | ArrayLike
    ) -> bool | None:
        """``True``/``False``, or ``None`` when undecided (time or node budget)."""
        ...

    def fix(self, cells: Sequence[int] | ArrayLike, labels: Sequence[int] | ArrayLike) -> None:
        """Add ``cells = labels`` to every later query (e.g. a prefix known to be good)."""
        ...


def _pairs(
    cells: Any, labels: Any, problem: Problem
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    c = np.asarray(cells, dtype=np.int64).reshape(-1)
    b = np.asarray(labels, dtype=np.int64).reshape(-1)
    if c.shape != b.shape:
        raise InputError(f"cells and labels differ in length ({c.size} vs {b.size})")
    if np.any((c < 0) | (c >= problem.n)):
        raise InputError(f"cells must be 0..{problem.n - 1}")
    return c, b


def _restrict(dom: NDArray[np.bool_], c: NDArray[np.int64], b: NDArray[np.int64]) -> None:
    """Narrow ``dom`` in place to ``cells = labels`` (a label outside a domain, or two
    labels for one cell, leaves that cell's domain empty)."""
    if not c.size:
        return
    K = dom.shape[1]
    bad = (b < 0) | (b >= K)
    bb = np.where(bad, 0, b)
    keep = dom[c, bb] & ~bad
    dom[c] = False
    dom[c, bb] = keep
    if np.unique(c).size < c.size:  # a cell given twice: with two labels it cannot be done
        pairs = np.unique(np.stack([c, b], axis=1), axis=0)
        cells, n = np.unique(pairs[:, 0], return_counts=True)
        dom[cells[n > 1]] = False


class SearchCompletability:
    """Exact completability by depth-first search with arc consistency (small problems).

    Parameters
    ----------
    problem : Problem
    max_nodes : int, optional
        Search nodes per query before answering ``None`` (undecided); no limit by default.

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
    >>> o = SearchCompletability(P)
    >>> o.fix([0], [1])
    >>> o.completable([1], [0]), o.completable([1], [1]), o.completable([0, 0], [1, 0]), o.calls
    (True, False, False, 3)
    """

    name = "search"

    def __init__(self, problem: Problem, max_nodes: int | None = None) -> None:
        self.problem = problem
        self.max_nodes = max_nodes
        self.calls = 0
        self.solution: NDArray[np.int32] | None = None
        self._dom = problem.domains.copy()

    def completable(self, cells: Any, labels: Any) -> bool | None:
        self.calls += 1
        self.solution = None
        dom = self._dom.copy()
        _restrict(dom, *_pairs(cells, labels, self.problem))
        eng = Propagator(self.problem, domains=dom)
        if not eng.ok:
            return False
        try:
            self.solution = search_solution(eng, self.max_nodes)
        except PrefixTimeout:
            return None
        return self.solution is not None

    def fix(self, cells: Any, labels: Any) -> None:
        _restrict(self._dom, *_pairs(cells, labels, self.problem))


def _dfs(problem: Problem, eng: Propagator, max_nodes: int | None) -> Iterator[NDArray[np.int32]]:
    """Every solution below the propagated state ``eng`` (flat grids), depth first: the
    open cell with the smallest domain (the first of them), its labels in increasing
    order. Raises :class:`PrefixTimeout` after ``max_nodes`` search nodes."""
    nodes = 0

    def rec(e: Propagator) -> Iterator[NDArray[np.int32]]:
        nonlocal nodes
        nodes += 1
        if max_nodes is not None and nodes > max_nodes:
            raise PrefixTimeout(f"more than {max_nodes} search nodes")
        sizes = e.sizes()
        open_ = np.flatnonzero(sizes > 1)
        if open_.size == 0:
            g = np.asarray(np.argmax(e.catalog(), axis=1), dtype=np.int32)
            if problem.is_solution(g):  # arc consistency on singletons checks every arc
                yield g
            return
        v = int(open_[np.argmin(sizes[open_])])
        for b in e.domain(v).tolist():
            e2 = e.copy()
            if e2.assign(v, int(b)):
                yield from rec(e2)

    if eng.ok:
        yield from rec(eng)


def search_solution(eng: Propagator, max_nodes: int | None = None) -> NDArray[np.int32] | None:
    """A solution below the propagated state ``eng`` by DFS with arc consistency
    (smallest domain first, labels in increasing order), or ``None`` if there is none.

    Raises :class:`PrefixTimeout` when ``max_nodes`` search nodes were not enough.
    """
    return next(_dfs(eng.problem, eng, max_nodes), None)


def search_solutions(
    problem: Problem, partial: ArrayLike | None = None, limit: int | None = None
) -> Iterator[NDArray[np.int32]]:
    """Every solution (a grid of the problem's shape) extending ``partial`` (-1 = free),
    each once, in depth-first order (see :func:`search_solution`); at most ``limit``.

    Exact and complete; for problems with a few thousand solutions at most.

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (2, 2))
    >>> [g.tolist() for g in search_solutions(P, [[1, -1], [-1, -1]])]
    [[[1, 0], [0, 1]]]
    """
    dom = problem.domains.copy()
    if partial is not None:
        flat = np.asarray(partial, dtype=np.int64).reshape(-1)
        idx = np.flatnonzero(flat >= 0)
        _restrict(dom, idx, flat[idx])
    found = 0
    for g in _dfs(problem, Propagator(problem, domains=dom), None):
        if limit is not None and found >= limit:
            return
        found += 1
        yield g.reshape(problem.shape)


class SatCompletability(Closing):
    """Exact completability by incremental SAT (one :class:`SatOracle`, assumptions).

    Parameters
    ----------
    problem : Problem
    backend : str, optional
        pysat backend, default ``cadical195``.
    deadline : float, optional
        ``time.perf_counter()`` value after which queries answer ``None``.
    oracle : SatOracle, optional
        Ask this oracle (with the clauses it already has) instead of building one; it is
        then not closed by :meth:`close`.
    rng : int or Generator, optional
        Diversify the completions as the ``sat`` solver does: seed CaDiCaL and set the
        decision phases to a random label of the catalog per cell. Default: the solver's
        own phases.

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
    >>> with SatCompletability(P) as o:
    ...     o.fix([0], [1])
    ...     o.completable([1], [0]), o.completable([1], [1]), o.solution is None
    (True, False, True)
    """

    name = "sat"

    def __init__(
        self,
        problem: Problem,
        backend: str | None = None,
        deadline: float | None = None,
        *,
        oracle: SatOracle | None = None,
        rng: RngLike = None,
    ) -> None:
        from csplab.engine.sat import SatOracle, preferred_labels
        from csplab.rng import make_rng

        self.problem = problem
        self.deadline = deadline
        self.calls = 0
        self.solution: NDArray[np.int32] | None = None
        self._own = oracle is None
        if oracle is None:
            gen = None if rng is None else make_rng(rng)[0]
            seed = None if gen is None else int(gen.integers(2**31 - 1))
            oracle = SatOracle(problem, backend=backend, deadline=deadline, seed=seed)
            if gen is not None and oracle.enc.ok and not oracle.timed_out:
                oracle.set_phases(preferred_labels(oracle.enc.catalog, None, gen))
        self.oracle = oracle

    def completable(self, cells: Any, labels: Any) -> bool | None:
        self.calls += 1
        self.solution = None
        c, b = _pairs(cells, labels, self.problem)
        if np.any((b < 0) | (b >= self.problem.K)):
            return False
        o = self.oracle
        lits = [o.literal(int(x), int(y)) for x, y in zip(c.tolist(), b.tolist(), strict=True)]
        st = o.solve(lits, deadline=self.deadline)
        self.solution = o.grid.reshape(-1).copy() if st == "sat" and o.grid is not None else None
        return None if st == "timeout" else st == "sat"

    def fix(self, cells: Any, labels: Any) -> None:
        o = self.oracle
        for x, y in zip(*(a.tolist() for a in _pairs(cells, labels, self.problem)), strict=True):
            o.add_clause([o.literal(int(x), int(y))] if 0 <= y < self.problem.K else [])

    def close(self) -> None:
        if self._own:
            self.oracle.close()


def make_completability(
    problem: Problem, method: str = "auto", **options: Any
) -> SatCompletability | SearchCompletability:
    """A :class:`Completability` for ``problem``: ``"sat"``, ``"search"`` or ``"auto"``
    (``sat`` when python-sat is installed). ``options`` go to the class (``backend``,
    ``deadline``, ``rng`` for ``sat``; ``max_nodes`` for ``search``).

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
    >>> make_completability(P, "search", max_nodes=10).name
    'search'
    """
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

    Examples
    --------
    Fig. 3.5 on a 3x3 output, scanned row by row: Alg. 3.1 chose labels 2, 0, 0 along
    the bottom row and failed at the third choice; the third label (index 2) was the first
    outside C*.

    >>> from csplab import from_example
    >>> from csplab.examples import load_example
    >>> P = from_example(load_example("fig3_5a"), (3, 3))
    >>> run = [[P.cell((0, 0)), 2], [P.cell((1, 0)), 0], [P.cell((2, 0)), 0]]
    >>> first_inconsistent_prefix(SearchCompletability(P), run, full_inconsistent=True)
    2
    >>> first_inconsistent_prefix(SearchCompletability(P), run[:2]) is None
    True
    """
    ch = np.asarray(choices, dtype=np.int64).reshape(-1, 2)
    steps = ch.shape[0]

    def ok(t: int) -> bool:
        r = oracle.completable(ch[:t, 0], ch[:t, 1])
        if r is None:
            raise PrefixTimeout(f"completability of a {t}-step prefix undecided")
        return bool(r)

    if steps == 0 or (not full_inconsistent and ok(steps)):
        return None
    lo, hi = 0, steps  # prefix lo is completable, prefix hi is not
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if ok(mid):
            lo = mid
        else:
            hi = mid
    return hi - 1


def catalog_at(
    oracle: Completability,
    problem: Problem,
    cells: ArrayLike,
    labels: ArrayLike,
    cell: int,
    known: int | None = None,
) -> tuple[NDArray[np.int64], list[int]]:
    """C(cell) and C*(cell) after the partial model ``cells = labels`` (one step of a run).

    C is the arc-consistent catalog (Alg. 3.2) of the partial model; C* the labels of C
    that the ``oracle`` can complete, one query each. The oracle must already hold the
    partial model (:meth:`Completability.fix`); ``known`` is a label known to be in C*
    (the cell's label in a completion found before) and costs no query. Returns C(cell)
    as an array and C*(cell) as a list, both in increasing order; a query left undecided
    (``None``) raises :class:`PrefixTimeout`.

    Examples
    --------
    Fig. 3.5 on a 3x3 output: after labels 2 and 0 at the first two cells of the bottom
    row, the catalog of the third cell still holds six labels, but only one can be
    completed.

    >>> from csplab import from_example
    >>> from csplab.examples import load_example
    >>> P = from_example(load_example("fig3_5a"), (3, 3))
    >>> cells = [P.cell((0, 0)), P.cell((1, 0))]
    >>> o = SearchCompletability(P)
    >>> o.fix(cells, [2, 0])
    >>> C, star = catalog_at(o, P, cells, [2, 0], P.cell((2, 0)))
    >>> C.tolist(), star
    ([0, 1, 2, 3, 6, 7], [6])
    """
    c, b = _pairs(cells, labels, problem)
    dom = problem.domains.copy()
    _restrict(dom, c, b)
    C, ok = propagate(problem, dom)
    cand = np.flatnonzero(C[cell]) if ok else np.zeros(0, dtype=np.int64)
    star: list[int] = []
    for lab in cand.tolist():
        if known is not None and lab == known:
            star.append(lab)
            continue
        r = oracle.completable([cell], [lab])
        if r is None:
            raise PrefixTimeout(f"completability of label {lab} at cell {cell} undecided")
        if r:
            star.append(lab)
    return cand.astype(np.int64), star


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
