"""Solver ``backtrack``: complete depth-first search maintaining arc consistency (MAC).

Each decision assigns a label to a cell and runs the catalog's arc consistency (the
revision of Alg. 3.2/3.3, compiled, with a trail for undo: :meth:`Propagator.mac_search
<csplab.catalog.Propagator.mac_search>`); a wipe-out undoes the decision and tries the
cell's next label; when a cell has no label left the search backtracks chronologically to
the previous decision. Restarts follow the Luby sequence (``restart`` failures times 1, 1,
2, 1, 1, 2, 4, ...), each run with fresh random choices; since the cutoffs grow without
bound the search stays complete. Exhausting the tree (or an arc-consistency wipe-out before
any decision) proves unsatisfiability.

With ``order="scanline"`` and no restarts this is exactly Alg. 3.1 plus chronological
backtracking: the same cell order and uniform label choice from the catalog.

Examples
--------
>>> from csplab import ExampleModel, from_example, solve
>>> E = ExampleModel([[0, 1, 0, 1], [1, 0, 1, 0]])
>>> P = from_example(E, (5, 5), fixed={(4, 4): 1})
>>> r = solve(P, "backtrack", rng=0)
>>> r.status, int(r.grid[4, 4])
('solved', 1)
>>> Q = from_example(E, (3, 3), fixed={(0, 0): 0, (2, 0): 1})           # parity clash
>>> solve(Q, "backtrack", rng=0).status
'unsat'
"""

from __future__ import annotations

from typing import Any

from csplab import _kernels as kern
from csplab.catalog import Code, Propagator, Search
from csplab.problem import Problem
from csplab.result import Result, Status
from csplab.solvers.base import CHOICE, TIME_LIMIT, Call, Option, Solver, order_option

__all__ = ["BacktrackSolver", "luby"]

_CHUNK_NODES = 2000


def _constrain(eng: Propagator, search: Search, code: Code, stats: dict[str, Any]) -> Code:
    """After a decision (``PAUSED``) or at a full assignment (``SOLVED``): prune with the
    problem's global constraints; a refutation rejects the decision (the search tries the
    cell's next label on resumption) or, at the root, proves unsatisfiability."""
    before = int(search.state[kern.TLEN])
    got = eng.constrain(search)
    if got == -1:
        if int(search.state[kern.TLEN]) != before:
            stats["constraint_prunings"] += 1
        if code is Code.SOLVED and eng.catalog().sum(axis=1).max() > 1:
            return Code.PAUSED  # the pruning left choices: search on
        return code
    stats["constraint_conflicts"] += 1
    if int(search.state[kern.LEVEL]) == 0:
        return Code.EXHAUSTED
    search.state[kern.NEED] = 0  # reject the current label of the last decision
    search.state[kern.FAILS] += 1
    search.state[kern.FAILS_RUN] += 1
    return Code.PAUSED


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


class BacktrackSolver(Solver):
    """Complete: MAC depth-first search with restarts (compiled)."""

    name = "backtrack"
    complete = True
    constraints = "propagated"
    description = "depth-first search maintaining arc consistency (MAC), compiled, with a trail"
    notes = (
        '`order="min-domain"` or `"scanline"` (= Alg. 3.1 + chronological backtracking); '
        "Luby restarts (`restart=100` failures); `node_limit`, `time_limit`"
    )
    options = (
        order_option(("min-domain", "scanline"), "min-domain",
                     "variable order: smallest domain first, or the scanline (Alg. 3.1 order)"),
        CHOICE,
        Option("restart", int, 100, "failures before the first Luby restart (0: never)",
               minimum=0),
        Option("node_limit", int, None, "search nodes before giving up (status timeout)",
               minimum=0, nullable=True),
        TIME_LIMIT,
    )  # fmt: skip

    def run(self, problem: Problem, call: Call) -> Result:
        rng = call.rng
        order, choice, restart, node_limit = call.get("order", "choice", "restart", "node_limit")
        n = problem.n
        eng = Propagator(problem)
        stats: dict[str, Any] = {"order": order, "choice": choice, "restart": int(restart)}
        if not eng.ok:
            stats.update(nodes=0, conflicts=0, restarts=0)
            stats["fail_cell"] = list(problem.coords(eng.wiped))
            proof = "arc-consistency wipe-out before any decision (Theorem 3.3.2)"
            return self.result("unsat", None, problem, stats, call, proof=proof)
        cons = bool(problem.constraints)
        if cons:  # global constraints: prune the root, then after every decision
            stats.update(constraint_prunings=0, constraint_conflicts=0)
            if eng.constrain() != -1:
                stats.update(nodes=0, conflicts=0, restarts=0)
                proof = "global-constraint propagation before any decision"
                return self.result("unsat", None, problem, stats, call, proof=proof)
        search = Search.new(n, eng.c.W, seed=int(rng.integers(0, 2**63 - 1)))
        restarts = 0
        cutoff = int(restart) * luby(1) if restart else 0
        status: Status
        while True:
            budget = _CHUNK_NODES
            if node_limit is not None:
                budget = min(budget, int(node_limit) - search.nodes)
                if budget <= 0:
                    status, stats["limit"] = "timeout", "nodes"
                    break
            code = eng.mac_search(search, scan=order == "scanline", weighted=choice == "weighted",
                                  max_nodes=1 if cons else budget,
                                  restart_fails=cutoff)  # fmt: skip
            if cons and code in (Code.PAUSED, Code.SOLVED):
                code = _constrain(eng, search, code, stats)
                # refutations by a constraint count towards the Luby restarts too
                if code is Code.PAUSED and cutoff and int(search.state[kern.FAILS_RUN]) >= cutoff:
                    code = Code.RESTART
            if code is Code.SOLVED:
                status = "solved"
                break
            if code is Code.EXHAUSTED:
                status = "unsat"
                stats["proof"] = (
                    f"search tree exhausted ({search.nodes} decisions, restart run {restarts + 1})"
                )
                break
            if code is Code.RESTART:
                restarts += 1
                eng.mac_restart(search)
                cutoff = int(restart) * luby(restarts + 1)
            elif code is Code.GROW:
                search = search.grown()
            if call.expired():
                status, stats["limit"] = "timeout", "time"
                break
        grid = eng.catalog().argmax(axis=1) if status == "solved" else None
        stats.update(
            nodes=search.nodes, conflicts=search.fails, restarts=restarts,
            propagations=int(search.counters[0]), removals=int(search.counters[1]),
        )  # fmt: skip
        return self.result(status, grid, problem, stats, call)
