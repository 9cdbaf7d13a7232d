"""Solver ``backtrack``: complete depth-first search maintaining arc consistency (MAC).

Each decision assigns a label to a cell and runs the catalog's arc consistency (the
revision of Alg. 3.2/3.3, compiled, with a trail for undo: :mod:`csplab._search`); a
wipe-out undoes the decision and tries the cell's next label; when a cell has no label
left the search backtracks chronologically to the previous decision. Restarts follow the
Luby sequence (``restart`` failures times 1, 1, 2, 1, 1, 2, 4, ...), each run with fresh
random choices; since the cutoffs grow without bound the search stays complete. Exhausting
the tree (or an arc-consistency wipe-out before any decision) proves unsatisfiability.

With ``order="scanline"`` and no restarts this is exactly Alg. 3.1 plus chronological
backtracking: the same cell order and uniform label choice from the catalog.

Options
-------
order : {"min-domain", "scanline"}
    ``min-domain`` (default): a cell with the fewest labels left, random tie-breaking.
    ``scanline``: the first unassigned cell in the thesis' scan order.
choice : {"uniform", "weighted"}
    Label order: uniformly random, or random by label weight.
restart : int
    Failures before the first restart (0: never restart). Default 100.
node_limit : int, optional
    Status ``timeout`` (``stats["limit"] = "nodes"``) after this many decisions.
time_limit : float, optional
    Seconds; status ``timeout``.

Examples
--------
>>> from csplab import ExampleModel, Problem, solve
>>> E = ExampleModel([[0, 1, 0, 1], [1, 0, 1, 0]])
>>> P = Problem.from_example(E, (5, 5), fixed={(4, 4): 1})
>>> r = solve(P, "backtrack", rng=0)
>>> r.status, int(r.grid[4, 4])
('solved', 1)
>>> Q = Problem.from_example(E, (3, 3), fixed={(0, 0): 0, (2, 0): 1})   # parity clash
>>> solve(Q, "backtrack", rng=0).status
'unsat'
"""

from __future__ import annotations

import time
from typing import Any, ClassVar

import numpy as np

from csplab import _search as ks
from csplab.catalog import Propagator, unpack
from csplab.errors import InputError
from csplab.problem import Problem
from csplab.result import Result, Status

__all__ = ["BacktrackSolver", "luby"]

_CHUNK_NODES = 2000


def luby(i: int) -> int:
    """The ``i``-th term (1-based) of the Luby sequence 1, 1, 2, 1, 1, 2, 4, 1, ...

    Examples
    --------
    >>> [luby(i) for i in range(1, 16)]
    [1, 1, 2, 1, 1, 2, 4, 1, 1, 2, 1, 1, 2, 4, 8]
    """
    k = 1
    while (1 << k) - 1 < i:
        k += 1
    while True:
        if i == (1 << k) - 1:
            return 1 << (k - 1)
        i -= (1 << (k - 1)) - 1
        k = 1
        while (1 << k) - 1 < i:
            k += 1


class BacktrackSolver:
    """Complete: MAC depth-first search with restarts (compiled)."""

    name: ClassVar[str] = "backtrack"
    complete: ClassVar[bool] = True
    requires: ClassVar[tuple[str, ...]] = ()
    description: ClassVar[str] = (
        "MAC: depth-first search maintaining arc consistency, chronological "
        "backtracking, Luby restarts; orders min-domain/scanline"
    )

    def solve(
        self,
        problem: Problem,
        *,
        rng: np.random.Generator,
        seed: int | None,
        backend: str | None = None,
        order: str = "min-domain",
        choice: str = "uniform",
        restart: int = 100,
        node_limit: int | None = None,
        time_limit: float | None = None,
        **options: Any,
    ) -> Result:
        if backend is not None:
            raise InputError(f"solver 'backtrack' has no backends (got {backend!r})")
        if options:
            raise InputError(f"unknown option(s) for solver 'backtrack': {', '.join(options)}")
        if order not in ("min-domain", "scanline"):
            raise InputError(f"order must be 'min-domain' or 'scanline', not {order!r}")
        if choice not in ("uniform", "weighted"):
            raise InputError(f"choice must be 'uniform' or 'weighted', not {choice!r}")
        if int(restart) < 0 or (node_limit is not None and int(node_limit) < 0):
            raise InputError("restart and node_limit must be >= 0")
        t0 = time.perf_counter()
        deadline = None if time_limit is None else t0 + float(time_limit)
        n = problem.n
        eng = Propagator(problem)
        grid = np.full(problem.shape, -1, dtype=np.int32)
        stats: dict[str, Any] = {"order": order, "choice": choice, "restart": int(restart)}
        if not eng.ok:
            stats.update(nodes=0, fails=0, restarts=0)
            stats["proof"] = "arc-consistency wipe-out before any decision (Theorem 3.3.2)"
            stats["fail_cell"] = list(problem.coords(eng.wiped))
            return Result("unsat", grid, "backtrack", time_s=time.perf_counter() - t0,
                          stats=stats)  # fmt: skip
        c = eng.c
        dom = eng.bits
        W = dom.shape[1]
        cap = max(4 * n, 1024)
        tcell = np.zeros(cap, dtype=np.int64)
        tbits = np.zeros((cap, W), dtype=np.uint64)
        stamp = np.full(n, -1, dtype=np.int64)
        lv_cell = np.zeros(n + 2, dtype=np.int64)
        lv_cand = np.zeros((n + 2, W), dtype=np.uint64)
        lv_trail = np.zeros(n + 2, dtype=np.int64)
        lv_scan = np.zeros(n + 2, dtype=np.int64)
        state = np.zeros(9, dtype=np.int64)
        state[ks.NEED] = 1
        state[ks.RNG] = int(rng.integers(0, 2**63 - 1))
        scan_order = np.arange(n, dtype=np.int64)
        counters = np.zeros(2, dtype=np.int64)
        restarts = 0
        cutoff = int(restart) * luby(1) if restart else 0
        status: Status
        while True:
            budget = _CHUNK_NODES
            if node_limit is not None:
                budget = min(budget, int(node_limit) - int(state[ks.NODES]))
                if budget <= 0:
                    status, stats["limit"] = "timeout", "nodes"
                    break
            code = ks.mac_search(
                dom, c.full, c.ptr, c.nbr, c.sidx, c.sup, c.supall, eng._queue, eng._inq,
                stamp, state, tcell, tbits, lv_cell, lv_cand, lv_trail, lv_scan,
                order == "scanline", scan_order, c.weights, choice == "weighted",
                budget, cutoff, counters,
            )  # fmt: skip
            if code == 0:
                status = "solved"
                break
            if code == 1:
                status = "unsat"
                stats["proof"] = (
                    f"search tree exhausted ({int(state[ks.NODES])} decisions, "
                    f"restart run {restarts + 1})"
                )
                break
            if code == 2:
                restarts += 1
                ks._undo(dom, int(lv_trail[1]), state, tcell, tbits)
                state[ks.LEVEL] = 0
                state[ks.NEED] = 1
                state[ks.SCAN] = 0
                state[ks.FAILS_RUN] = 0
                cutoff = int(restart) * luby(restarts + 1)
            elif code == 4:
                cap *= 2
                tcell = np.concatenate([tcell, np.zeros(cap - tcell.size, dtype=np.int64)])
                tbits = np.concatenate([tbits, np.zeros((cap - tbits.shape[0], W), np.uint64)])
            if deadline is not None and time.perf_counter() > deadline:
                status, stats["limit"] = "timeout", "time"
                break
        if status == "solved":
            grid = unpack(dom, problem.K).argmax(axis=1).astype(np.int32).reshape(problem.shape)
        stats.update(
            nodes=int(state[ks.NODES]), fails=int(state[ks.FAILS]), restarts=restarts,
            propagations=int(counters[0]), removals=int(counters[1]),
        )  # fmt: skip
        return Result(status, grid, "backtrack", time_s=time.perf_counter() - t0, stats=stats)
