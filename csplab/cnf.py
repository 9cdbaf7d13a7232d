"""CNF for a :class:`~csplab.problem.Problem`: the support encoding, completion and enumeration.

This is the small pysat layer the analysis tools (issue 5: the reductions and exact
counting) need: decide whether an incomplete model can be completed, return a completion,
enumerate completions, and hand the clauses to a model counter.

Encoding. Domains are first made arc consistent with the catalog engine
(:class:`~csplab.catalog.Propagator`); by Theorem 3.3.2 this removes no label of any
solution, so completability and solution counts are unchanged. Cells left with one label
are constants and get no variable; an arc with a constant end is already satisfied (arc
consistency), so only arcs between two open cells get clauses. Each open cell ``c`` and
label ``b`` in its domain gets a variable ``x[c, b]``; clauses are

* at least one label per open cell and at most one (pairwise below 8 labels, else a
  sequential counter with auxiliary variables),
* the *support encoding* of every arc ``(s, d, r)``: ``x[s, b] -> OR_{c: R[b, c]} x[d, c]``
  and the same from ``d``'s side, so unit propagation is exactly arc consistency.

Solutions of the problem are in one-to-one correspondence with models of the CNF projected
on the ``x`` variables (:attr:`SupportCNF.primary`).

Examples
--------
>>> from csplab import ExampleModel, Problem
>>> P = Problem.from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
>>> enc = SupportCNF(P)
>>> enc.open_cells.size, enc.unsat                 # nothing fixed: every cell is open
(9, False)
>>> r = complete(P, rng=1)
>>> r.status, P.is_solution(r.grid)
('solved', True)
>>> sum(1 for _ in enumerate_solutions(P))         # the checkerboard: two solutions
2
>>> complete(P.with_fixed({(0, 0): 0, (0, 1): 0})).status
'unsat'
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.catalog import Propagator
from csplab.errors import DependencyError, InputError
from csplab.problem import Problem
from csplab.result import Result, Status
from csplab.rng import RngLike, make_rng

__all__ = ["DEFAULT_BACKEND", "SupportCNF", "complete", "enumerate_solutions"]

DEFAULT_BACKEND = "cadical195"
_PAIRWISE_MAX = 8


def _require_pysat() -> None:
    try:
        import pysat  # noqa: F401
    except ImportError:  # pragma: no cover - depends on the environment
        raise DependencyError(
            "this needs python-sat; install with pip install 'csplab[sat]'"
        ) from None


class SupportCNF:
    """The support encoding of a problem after arc-consistency pruning.

    Attributes
    ----------
    problem : Problem
    domains : bool array ``(n, K)``
        Arc-consistent domains (all ``False`` rows when ``unsat``).
    unsat : bool
        Arc consistency wiped a domain out: the problem has no solution.
    base : int32 array ``(n,)``
        Label of every cell with a single label, ``-1`` for open cells.
    open_cells : int array
        Cells with two or more labels.
    var : int64 array ``(n, K)``
        The variable of ``x[cell, label]`` (``0``: none).
    clauses : list of list of int
    nvars : int
        Number of variables including auxiliary ones.
    primary : list of int
        The ``x`` variables (the projection set for counting).
    """

    def __init__(self, problem: Problem, *, prune: bool = True) -> None:
        self.problem = problem
        n, K = problem.n, problem.K
        if prune:
            eng = Propagator(problem)
            dom = eng.catalog() if eng.ok else np.zeros((n, K), dtype=bool)
            self.unsat = not eng.ok
        else:
            dom = np.array(problem.domains, dtype=bool)
            self.unsat = bool((~dom.any(axis=1)).any())
        self.domains: NDArray[np.bool_] = dom
        size = dom.sum(axis=1)
        self.base: NDArray[np.int32] = np.where(size == 1, dom.argmax(axis=1), -1).astype(np.int32)
        self.open_cells: NDArray[np.int64] = np.flatnonzero(size > 1).astype(np.int64)
        var = np.zeros((n, K), dtype=np.int64)
        od = dom[self.open_cells]
        var[self.open_cells] = np.where(od, np.cumsum(od.ravel()).reshape(od.shape), 0)
        self.var = var
        self.nvars = int(od.sum())
        self.primary: list[int] = list(range(1, self.nvars + 1))
        self.clauses: list[list[int]] = []
        if not self.unsat:
            self._cells()
            self._arcs()

    # ------------------------------------------------------------------ building
    def _cells(self) -> None:
        rows = self.var[self.open_cells]
        alo = [[v for v in row if v] for row in rows.tolist()]
        self.clauses.extend(alo)
        for lits in alo:
            if len(lits) <= _PAIRWISE_MAX:
                self.clauses.extend(
                    [-lits[i], -lits[j]] for i in range(len(lits)) for j in range(i + 1, len(lits))
                )
            else:
                from pysat.card import CardEnc, EncType

                enc = CardEnc.atmost(lits, 1, top_id=self.nvars, encoding=EncType.seqcounter)
                self.nvars = max(self.nvars, enc.nv)
                self.clauses.extend(enc.clauses)

    def _arcs(self) -> None:
        P = self.problem
        a = P.arcs
        isopen = self.base < 0
        a = a[isopen[a[:, 0]] & isopen[a[:, 1]] & (a[:, 0] != a[:, 1])]
        if not a.size:
            return
        rel = P.relations
        for src, dst, fwd in ((a[:, 0], a[:, 1], True), (a[:, 1], a[:, 0], False)):
            for b in range(P.K):
                sel = np.flatnonzero(self.var[src, b] > 0)
                if not sel.size:
                    continue
                r = a[sel, 2]
                sup = rel[r, b, :] if fwd else rel[r, :, b]
                mat = np.where(sup, self.var[dst[sel]], 0)
                head = -self.var[src[sel], b]
                full = np.concatenate([head[:, None], mat], axis=1)
                self.clauses.extend([v for v in row if v] for row in full.tolist())

    # ------------------------------------------------------------------ models
    def decode(self, model: list[int] | NDArray[np.int64]) -> NDArray[np.int32]:
        """The grid (problem shape) of a SAT model."""
        m = np.asarray(model, dtype=np.int64)
        truth = np.zeros(self.nvars + 1, dtype=bool)
        pos = m[(m > 0) & (m <= self.nvars)]
        truth[pos] = True
        g = self.base.copy()
        if self.open_cells.size:
            v = self.var[self.open_cells]
            hit = truth[v] & (v > 0)
            g[self.open_cells] = np.where(hit.any(axis=1), hit.argmax(axis=1), -1)
        return g.reshape(self.problem.shape)

    def blocking_clause(self, grid: NDArray[np.integer[Any]]) -> list[int]:
        """The clause that excludes exactly this assignment of the open cells."""
        g = np.asarray(grid).reshape(-1)
        oc = self.open_cells
        return [-int(v) for v in self.var[oc, g[oc]]]

    def solver(self, backend: str = DEFAULT_BACKEND, rng: np.random.Generator | None = None) -> Any:
        """A pysat solver loaded with the clauses (random phases when ``rng`` is given)."""
        _require_pysat()
        from pysat.solvers import Solver

        try:
            s = Solver(name=backend, bootstrap_with=self.clauses)
        except Exception as e:  # pysat raises plain exceptions for unknown names
            raise InputError(f"unknown SAT backend {backend!r}: {e}") from None
        if rng is not None and self.nvars:
            lits = np.arange(1, self.nvars + 1)
            signs = np.where(rng.random(self.nvars) < 0.5, 1, -1)
            s.set_phases((lits * signs).tolist())
        return s


def complete(
    problem: Problem,
    rng: RngLike = None,
    *,
    backend: str = DEFAULT_BACKEND,
    time_limit: float | None = None,
) -> Result:
    """Decide whether ``problem`` (an incomplete model: fixed cells = assigned labels) can be
    completed; return a completion.

    Returns a :class:`~csplab.result.Result` with status ``solved`` (a grid checked with
    :meth:`Problem.violations`), ``unsat`` (proven: arc consistency or the SAT solver) or
    ``timeout``. ``stats`` holds the CNF size and where the answer came from.
    """
    gen, seed = make_rng(rng)
    t0 = time.perf_counter()
    enc = SupportCNF(problem)
    stats: dict[str, Any] = {
        "open_cells": int(enc.open_cells.size),
        "vars": enc.nvars,
        "clauses": len(enc.clauses),
    }
    empty = np.full(problem.shape, -1, dtype=np.int32)
    if enc.unsat:
        stats["decided_by"] = "arc consistency"
        return Result("unsat", empty, "cnf", seed, time.perf_counter() - t0, stats)
    if enc.open_cells.size == 0:
        stats["decided_by"] = "arc consistency"
        g = enc.base.reshape(problem.shape)
        st: Status = "solved" if problem.is_solution(g) else "unsat"
        return Result(st, g if st == "solved" else empty, "cnf", seed,
                      time.perf_counter() - t0, stats)  # fmt: skip
    stats["decided_by"] = f"sat:{backend}"
    with enc.solver(backend, gen) as s:
        if time_limit is not None:
            import threading

            timer = threading.Timer(time_limit, s.interrupt)
            timer.start()
            try:
                ok = s.solve_limited(expect_interrupt=True)
            finally:
                timer.cancel()
        else:
            ok = s.solve()
        if ok is None:
            return Result("timeout", empty, "cnf", seed, time.perf_counter() - t0, stats)
        if not ok:
            return Result("unsat", empty, "cnf", seed, time.perf_counter() - t0, stats)
        g = enc.decode(s.get_model())
    if not problem.is_solution(g):  # pragma: no cover - would be a bug in the encoding
        raise AssertionError(problem.violations(g).describe())
    return Result("solved", g, "cnf", seed, time.perf_counter() - t0, stats)


def enumerate_solutions(
    problem: Problem, *, limit: int | None = None, backend: str = DEFAULT_BACKEND
) -> Iterator[NDArray[np.int32]]:
    """Every solution of ``problem`` (each once), by SAT with blocking clauses.

    Meant for problems with up to some ten thousand solutions; ``limit`` stops early.
    """
    enc = SupportCNF(problem)
    if enc.unsat:
        return
    if enc.open_cells.size == 0:
        g = enc.base.reshape(problem.shape)
        if problem.is_solution(g):
            yield g
        return
    found = 0
    with enc.solver(backend) as s:
        while s.solve():
            g = enc.decode(s.get_model())
            yield g
            found += 1
            if limit is not None and found >= limit:
                return
            s.add_clause(enc.blocking_clause(g))
