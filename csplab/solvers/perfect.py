"""Solver ``perfect``: Alg. 3.1 choosing only from the exact catalog C* (Eq. 3.4).

The thesis' ideal algorithm: at each step the label is drawn uniformly (or by weight) from
C*(p) -- the labels that keep the partial model completable -- instead of from the
arc-consistent catalog C. It never fails on a satisfiable problem (and proves
unsatisfiability with its first SAT call), so it is the upper reference for Alg. 3.1's
success rate; it is costly because C* is NP-hard (Theorem 3.3.5).

How: draw the labels of C(p) in a random order (uniform, or weighted sampling without
replacement); the first one that is in C* is exactly a uniform (weighted) draw from C*(p).
A label is known to be in C* without a SAT call if one of the solutions found so far agrees
with the partial model and has it (a pool of witnesses); otherwise one incremental SAT call
under an assumption decides it. Accepted labels become unit clauses, rejected ones
negative units (C* only shrinks as the model grows), so every call has one assumption.

Examples
--------
>>> from csplab import ExampleModel, from_example, solve
>>> E = ExampleModel([[0, 0, 0, 2], [2, 0, 0, 1], [0, 1, 2, 1]])   # Alg. 3.1 fails on it
>>> r = solve(from_example(E, (8, 8)), "perfect", rng=3)
>>> r.status, r.stats["rejected"] > 0            # it met labels of C outside C*
('solved', True)
"""

from __future__ import annotations

from typing import Any

import numpy as np

from csplab.catalog import Propagator
from csplab.engine.alg31 import scan_order
from csplab.engine.completability import WitnessPool, choose_from_exact
from csplab.engine.sat import SAT_STAT_KEYS, SatOracle
from csplab.engine.sat import backends as sat_backends
from csplab.errors import CsplabError
from csplab.problem import Problem
from csplab.progress import progress_bar
from csplab.result import Result
from csplab.solvers.base import CHOICE, TIME_LIMIT, Call, Option, Solver, order_option

__all__ = ["PerfectSolver"]


class PerfectSolver(Solver):
    """Complete: Alg. 3.1 drawing every label from C* (SAT-checked)."""

    name = "perfect"
    constraints = "exact"
    alg31 = True
    complete = True
    requires = ("pysat",)
    description = "Alg. 3.1 choosing every label from the exact catalog C* (SAT-checked)"
    notes = "never fails on a satisfiable problem; the upper reference for success rates; costly"
    options = (
        order_option(("scanline", "random", "scan:AXES")),
        CHOICE,
        Option("pool", int, 16, "witness solutions kept (labels known to be in C*)", minimum=1),
        Option("progress", bool, False, "a progress bar on stderr (after 2 s; the CLI's default)"),
        TIME_LIMIT,
    )  # fmt: skip
    backends = staticmethod(sat_backends)

    def run(self, problem: Problem, call: Call) -> Result:
        rng, backend = call.rng, call.backend
        order, choice, pool, progress = call.get("order", "choice", "pool", "progress")
        deadline = call.deadline
        n = problem.n
        grid = np.full(n, -1, dtype=np.int32)
        stats: dict[str, Any] = {"order": order, "choice": choice, "sat_calls": 0,
                                 "rejected": 0, "assigned": 0}  # fmt: skip
        eng = Propagator(problem)
        if not eng.ok:
            proof = "arc-consistency wipe-out before any choice (Theorem 3.3.2)"
            return self.result("unsat", grid, problem, stats, call, proof=proof)
        scan = scan_order(problem.shape, order)
        perm = rng.permutation(n) if scan is None else scan
        w = problem.weights if choice == "weighted" else None
        with SatOracle(problem, backend=backend, deadline=deadline,
                       seed=int(rng.integers(2**31 - 1))) as o:  # fmt: skip
            st = o.solve(deadline=deadline)
            stats["sat_calls"] += 1
            if st == "unsat":
                proof = f"refutation by {o.backend}"
                return self.result("unsat", grid, problem, stats, call, proof=proof)
            if st == "timeout":
                return self.result("timeout", grid, problem, stats, call)
            wit = WitnessPool(n, pool)
            assert o.grid is not None
            wit.add(o.grid.reshape(-1))
            cells = progress_bar(perm.tolist(), total=n, desc="perfect", enabled=progress)
            for p in cells:
                if call.expired():
                    return self.result("timeout", grid, problem, stats, call)
                labels = eng.domain(p)
                if labels.size == 1:
                    b = int(labels[0])
                else:
                    pick = choose_from_exact(o, wit, p, labels, w, rng, stats, deadline)
                    if pick is None:
                        return self.result("timeout", grid, problem, stats, call)
                    b = pick
                    o.add_clause([o.literal(p, b)])
                grid[p] = b
                wit.fix(p, b)
                stats["assigned"] += 1
                if not eng.assign(p, b):  # impossible: M_t stays completable
                    raise CsplabError("perfect: arc consistency failed after a C* choice (a bug)")
            stats["sat"] = {k: o.stats[k] for k in SAT_STAT_KEYS if k in o.stats}
        return self.result("solved", grid, problem, stats, call)
