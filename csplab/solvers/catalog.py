"""Solver ``catalog``: Merrell's discrete model synthesis, Alg. 3.1 (with Alg. 3.2/3.3).

Every cell is assigned a label drawn from the catalog C (arc consistency), and C is updated
after each assignment. When a domain empties the run stops with status ``failed``: the
algorithm gave up, which says nothing about satisfiability. A wipe-out before any choice is
a proof of unsatisfiability (Theorem 3.3.2) and gives ``unsat``.

Examples
--------
>>> from csplab import ExampleModel, from_example, solve
>>> from csplab.examples import load_example
>>> P = from_example(load_example("line"), (8, 6))
>>> r = solve(P, "catalog", rng=1, order="min-entropy")
>>> r.status, r.stats["assigned"]
('solved', 48)
>>> solve(P, "catalog", rng=1).stats["order"]     # auto: no global constraints
'scanline'
"""

from __future__ import annotations

from csplab.engine.alg31 import ORDERS, run_alg31
from csplab.problem import Problem
from csplab.result import Result
from csplab.solvers.base import CHOICE, TIME_LIMIT, WINDOW, Call, Solver, order_option

__all__ = ["CatalogSolver"]


class CatalogSolver(Solver):
    """Alg. 3.1: assign every cell from the arc-consistent catalog (incomplete)."""

    name = "catalog"
    constraints = "propagated"
    alg31 = True
    complete = False
    description = "Merrell Alg. 3.1 with the catalog of Alg. 3.2/3.3 (arc consistency)"
    notes = (
        "orders `auto` (default: `scanline`, the thesis loop order, without global constraints, "
        "`min-entropy` under them; the stats record the order used), `scanline`, `random`, "
        "`min-entropy` (WFC-style), `min-domain`, `scan:AXES`; label choice `uniform` "
        "(thesis) or `weighted`; `failed` = gave up, "
        "`unsat` only when arc consistency wipes out before any choice; with global "
        "constraints a refuted choice is withdrawn and the cell chooses again"
    )
    options = (
        order_option(
            ("auto", *ORDERS), "auto",
            "cell order: auto (scanline without global constraints, min-entropy under them), "
            "scanline (thesis), random, min-entropy (WFC), min-domain (WFC's MRV), scan:AXES "
            "(scan:yx)",
        ),
        CHOICE, WINDOW, TIME_LIMIT,
    )  # fmt: skip

    def run(self, problem: Problem, call: Call) -> Result:
        order, choice, window = call.get("order", "choice", "window")
        r = run_alg31(problem, call.rng, order=order, choice=choice, window=window,
                      time_limit=call.remaining())  # fmt: skip
        return self.result(r.status, r.grid, problem, r.stats, call, trace=r.trace)
