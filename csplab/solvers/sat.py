"""Solver ``sat``: a CNF encoding (:mod:`csplab.cnf`) solved with python-sat.

Backends are pysat solvers named after the colon, ``sat:cadical195`` (default),
``sat:glucose4``, ... (:func:`csplab.engine.sat.backends`; pysat's aliases such as ``g4``
work too). The work is done by the incremental oracle :class:`csplab.engine.sat.SatOracle`
(encoding, the fast CaDiCaL loader, deadlines); this module is the adapter.

Diversity: before solving, every cell gets a preferred label drawn from the catalog with
the rng (``choice="uniform"``, the default, like Alg. 3.1's uniform choice, or
``"weighted"`` by the example's label frequencies) and the solver's decision phases are set
to it; CaDiCaL is also seeded. Two seeds' outputs differ in 30-46% of the cells at
40×40×10 (``benchmarks/bench_solvers.py``; Alg. 3.1: 16-30%); ``"weighted"`` phases give
mostly empty space and much less variety; ``choice="none"`` keeps the solver's own phases.
``choice="catalog"`` sets the phases to a seeded Alg. 3.1 solution
(:func:`~csplab.engine.alg31.solution_hint`, as ``cpsat``'s default hint; uniform labels when
every run fails): with global constraints CDCL on its own does not find one connected object
of hundreds of cells (City 40×40×10 with connectivity and a count: timeout at 60 s), and from
that solution it does (7 s, ``benchmarks/bench_global.py``).

Status ``unsat`` comes only with a proof: the SAT solver's refutation, or an arc-consistency
wipe-out before any choice (what unit propagation on the support encoding also derives).

Examples
--------
>>> from csplab import ExampleModel, from_example, solve
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (5, 4))
>>> r = solve(P, "sat", rng=1)
>>> r.status, r.stats["backend"]
('solved', 'cadical195')
>>> solve(P, "sat:glucose4", rng=1).status
'solved'
>>> Q = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3), fixed={(0, 0): 0, (0, 1): 0})
>>> solve(Q, "sat", rng=1).stats["proof"]
'arc-consistency wipe-out (unit propagation on the support encoding)'
"""

from __future__ import annotations

import time

from numpy.typing import ArrayLike

from csplab.cnf import AMO_ENCODINGS
from csplab.engine.alg31 import solution_hint
from csplab.engine.sat import SatOracle, backends, preferred_labels
from csplab.problem import Problem
from csplab.result import Result, Status
from csplab.solvers.base import TIME_LIMIT, Call, Option, Solver

__all__ = ["SatSolver"]


# ----------------------------------------------------------------------------- solver


class SatSolver(Solver):
    """Complete: CNF encoding + a pysat backend."""

    name = "sat"
    constraints = "exact"
    complete = True
    requires = ("pysat",)
    description = (
        "CNF on the arc-consistent catalog, solved by python-sat (`sat:cadical195` default, "
        "`sat:glucose4`, … `csplab info` lists the backends)"
    )
    notes = (
        'support encoding (unit propagation = arc consistency) or `encoding="direct"`; '
        '`supports="forward"` halves the clauses; at-most-one `amo="lazy"` (added only '
        "for cells a model labels twice) or any `pysat.card` encoding; diverse outputs from "
        'random decision phases (`choice="uniform"`/`"weighted"`, `"catalog"`: a seeded '
        'Alg. 3.1 solution, `"none"` keeps the solver\'s); clauses go to CaDiCaL through a '
        'compiled loader (`loader="api"` for pysat\'s); `unsat` = the solver\'s refutation'
    )
    options = (
        Option("encoding", str, "support", "support clauses (= arc consistency) or direct "
               "(conflict clauses: forward checking)", values=("support", "direct")),
        Option("supports", str, "both", "support clauses in both directions of each arc or "
               "forward only (half the clauses, weaker)", values=("both", "forward")),
        Option("amo", str, "lazy", "at-most-one per cell: lazy (added for cells a model "
               "labels twice) or a pysat.card encoding", values=AMO_ENCODINGS),
        Option("choice", str, "uniform", "decision phases: a label per cell drawn uniformly "
               "or by weight from the catalog, a seeded Alg. 3.1 solution (catalog; "
               "uniform when it fails), or none (the solver's own)",
               values=("uniform", "weighted", "catalog", "none")),
        Option("loader", str, "auto", "clause loading: auto (compiled CaDiCaL loader when "
               "available) or api (pysat's Python API)", values=("auto", "api")),
        TIME_LIMIT,
    )  # fmt: skip
    backends = staticmethod(backends)
    bench = ({}, {"supports": "forward"}, {"loader": "api"}, {"backend": "glucose4"})

    def run(self, problem: Problem, call: Call) -> Result:
        rng, backend = call.rng, call.backend
        encoding, supports, amo, choice, loader = call.get(
            "encoding", "supports", "amo", "choice", "loader"
        )
        deadline = call.deadline
        cseed = int(rng.integers(2**31 - 1))
        grid: ArrayLike | None = None
        with SatOracle(
            problem, backend=backend, encoding=encoding, supports=supports, amo=amo,
            loader=loader, deadline=deadline, seed=cseed,
        ) as o:  # fmt: skip
            stats = o.stats
            stats.update(encoding=encoding, supports=supports, amo=amo, choice=choice)
            status = "timeout"
            if o.timed_out:
                pass
            elif not o.enc.ok:
                status = "unsat"
                stats["proof"] = (
                    "arc-consistency wipe-out (unit propagation on the support encoding)"
                )
                stats["fail_cell"] = list(problem.coords(o.enc.wiped))
            else:
                hint = None
                if choice == "catalog":  # a seeded Alg. 3.1 solution, as cpsat's hint
                    hint = solution_hint(problem, rng, call.remaining())
                    stats["hint"] = "catalog solution" if hint is not None else "uniform labels"
                if hint is not None:
                    o.set_phases(hint)
                elif choice != "none":
                    w = None
                    if choice == "weighted":  # per cell when the weights are per class
                        tab, cls = problem.weight_classes()
                        w = tab[0] if cls is None else tab[cls]
                    o.set_phases(preferred_labels(o.enc.catalog, w, rng))
                status = o.solve(deadline=deadline)
                stats.update(o.solver_stats())
                stats.update(o.constraint_stats())
                if status == "sat" and o.grid is not None:
                    grid = o.grid
                if status == "unsat":
                    stats["proof"] = f"refutation by {o.backend}"
            t1 = time.perf_counter()
        # freeing a solver with millions of clauses takes a while: it counts (`csplab
        # synthesize` leaves a large one to the process exit: engine.sat.free_at_exit)
        stats["free_s"] = time.perf_counter() - t1
        final: Status = "solved" if status == "sat" else "unsat" if status == "unsat" else "timeout"
        return self.result(final, grid, problem, stats, call)
