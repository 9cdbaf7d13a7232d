"""Solver ``sat``: a CNF encoding (:mod:`csplab.cnf`) solved with python-sat.

Backends are pysat solvers named after the colon, ``sat:cadical195`` (default),
``sat:glucose4``, ... (:func:`csplab.engine.sat.backends`; pysat's aliases such as ``g4``
work too). The work is done by the incremental oracle :class:`csplab.engine.sat.SatOracle`
(encoding, the fast CaDiCaL loader, deadlines); this module is the adapter.

Diversity: before solving, every cell gets a preferred label drawn from the catalog with
the rng (``choice="uniform"``, like Alg. 3.1's uniform choice, or ``"weighted"`` by the
example's label frequencies) and the solver's decision phases are set to it; CaDiCaL is
also seeded. Two seeds' outputs differ in 30-46% of the cells at 40×40×10
(``benchmarks/bench_solvers.py``; Alg. 3.1: 16-30%); ``"weighted"`` phases give mostly empty
space and much less variety; ``choice="none"`` keeps the solver's own phases.
``choice="catalog"`` starts from a seeded Alg. 3.1 solution
(:func:`~csplab.engine.alg31.solution_hint`, as ``cpsat``'s default hint; uniform labels when
every run fails): its phases, and the solution itself as assumptions (every label variable
of every cell, :meth:`~csplab.engine.sat.SatOracle.assignment`), which the solver confirms
by propagation, so the output is that solution; were it refuted, the search would go on
from its phases. With the labels alone as phases CaDiCaL decided the auxiliary variables of
the count first and searched (City 40×40×10 with connectivity and a count: 1,102 to 8,266
conflicts, solved in 5.7 s or timed out at 35 s by the run); so confirmed, 0 conflicts.

The default ``choice="auto"`` is ``"uniform"`` without global constraints (the same outputs
as before it existed) and with them a short attempt from uniform phases
(:data:`PROBE_CONFLICTS` conflicts per backend call, counted in conflicts and not in
seconds so that its answer is reproducible; the deadline stops it where the backend can be
interrupted, not CaDiCaL), then
``"catalog"``: CDCL alone does not find one connected object of
hundreds of cells (City 40×40×10: timeout at 35 s after 8,365 conflicts; at 20×20×6 one of
three seeds solved, after 2,554 conflicts, two timed out at 30 s after 5,698 and 5,876),
Alg. 3.1 grows it (0.8-1.6 s), while the knot tileset's network at 128×128 takes uniform
phases 37-53 conflicts over six seeds (1.3-2.3 s in all) against 2-3.5 s for the hint alone
(``benchmarks/bench_global.py``). ``stats["choice"]`` says which phases
gave the output, ``probe_conflicts`` the attempt's conflicts.

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

__all__ = ["PROBE_CONFLICTS", "SatSolver"]

#: conflicts per backend call of the uniform-phase attempt of ``choice="auto"`` under global
#: constraints, before the Alg. 3.1 hint (the knot network at 128×128 takes 37-53 in all; the
#: first 300 of City 40×40×10's cost 0.1 s and find nothing)
PROBE_CONFLICTS = 300


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
        'Alg. 3.1 solution the solver confirms, `"none"` keeps the solver\'s; the default '
        '`"auto"`: `"uniform"`, under global constraints a short uniform attempt, then '
        '`"catalog"`); clauses go to CaDiCaL through a compiled loader (`loader="api"` for '
        "pysat's); `unsat` = the solver's refutation"
    )
    options = (
        Option("encoding", str, "support", "support clauses (= arc consistency) or direct "
               "(conflict clauses: forward checking)", values=("support", "direct")),
        Option("supports", str, "both", "support clauses in both directions of each arc or "
               "forward only (half the clauses, weaker)", values=("both", "forward")),
        Option("amo", str, "lazy", "at-most-one per cell: lazy (added for cells a model "
               "labels twice) or a pysat.card encoding", values=AMO_ENCODINGS),
        Option("choice", str, "auto", "decision phases: auto (uniform; under global "
               "constraints a short uniform attempt, then catalog), a label per cell drawn "
               "uniformly or by weight "
               "from the catalog, a seeded Alg. 3.1 solution the solver confirms (catalog; "
               "uniform when it fails), or none (the solver's own)",
               values=("auto", "uniform", "weighted", "catalog", "none")),
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
        # auto: under global constraints a short attempt from uniform phases, then the hint
        probe = choice == "auto" and bool(problem.constraints)
        if choice == "auto":
            choice = "catalog" if problem.constraints else "uniform"
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
                if probe:
                    o.set_phases(preferred_labels(o.enc.catalog, None, rng))
                    status = o.solve(deadline=deadline, conflicts=PROBE_CONFLICTS)
                    stats["probe_conflicts"] = o.solver_stats().get("conflicts", 0)
                    if status != "timeout":
                        stats["choice"] = "uniform"
                if status == "timeout":
                    hint = None
                    if choice == "catalog":  # a seeded Alg. 3.1 solution, as cpsat's hint
                        t = time.perf_counter()
                        hint = solution_hint(problem, rng, call.remaining())
                        stats["hint"] = "catalog solution" if hint is not None else "uniform labels"
                        stats["hint_s"] = time.perf_counter() - t
                    if hint is not None:
                        o.set_phases(hint)
                        # the oracle confirms it by propagation (no conflict) and it is the
                        # output; were it refuted, the search goes on from its phases
                        status = o.solve(o.assignment(hint), deadline=deadline)
                        if status == "unsat":  # under the hint's assumptions: no proof
                            stats["hint"] = "catalog solution (refuted)"
                            status = o.solve(deadline=deadline)
                    else:
                        if probe:  # no hint: the search goes on from the attempt's phases
                            stats["choice"] = "uniform"
                        if choice != "none" and not probe:
                            w = None
                            if choice == "weighted":  # per cell when weights are per class
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
