"""The solver to copy: the smallest complete example of the solver contract.

To add a solver, copy this file to ``csplab/solvers/NAME.py`` and follow "Add a solver" in
``ARCHITECTURE.md``. This module is not in :data:`csplab.solvers.REGISTRY` (the README,
the CLI and ``csplab info`` do not show it); the conformance suite registers it for its own
run (``tests/solvers/test_conformance.py``), so it is checked like every real solver and
cannot rot.

What it shows, in the order a solver does it:

1. The declaration (class attributes, :mod:`csplab.solvers.base`): ``name``,
   ``complete``, ``constraints``, ``description``, ``notes``, ``options`` built from the
   shared vocabulary (:func:`~csplab.solvers.base.order_option`,
   :data:`~csplab.solvers.base.TIME_LIMIT`), ``bench`` variants. A solver that needs a
   package also sets ``requires`` (the extra that installs it comes from
   ``csplab.deps.EXTRAS``); one with backends sets ``backends``.
2. :meth:`TemplateSolver.run`: the options come validated in ``call``; every random number
   is drawn from ``call.rng``; the algorithm lives in the engine (:mod:`csplab.catalog`,
   :mod:`csplab.engine`), the solver only adapts it; the time limit is ``call.deadline``
   (an engine that takes a ``time_limit`` gets ``call.remaining()``), never a clock of
   the solver's own.
3. Every exit is :meth:`~csplab.solvers.base.Solver.result`: ``unsat`` with its
   ``proof=``, stats named in :data:`~csplab.solvers.base.STATS` only.

The algorithm: Merrell's Alg. 3.1 (:func:`csplab.engine.alg31.run_alg31`) in scanline or
random cell order with the uniform label choice. It is incomplete: ``failed`` says nothing
about satisfiability, and ``unsat`` comes only from an arc-consistency wipe-out before any
choice (Theorem 3.3.2) or from a global constraint's propagation at the root.

Examples
--------
>>> import numpy as np
>>> from csplab import ExampleModel, from_example
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (4, 3))
>>> r = TemplateSolver().solve(P, rng=np.random.default_rng(1), seed=1, order="random")
>>> r.status, r.solver, r.stats["assigned"]
('solved', 'template', 12)
>>> Q = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3), fixed={(0, 0): 0, (0, 1): 0})
>>> r = TemplateSolver().solve(Q, rng=np.random.default_rng(1), seed=1)
>>> r.status, r.stats["proof"]
('unsat', 'arc-consistency wipe-out before any choice (Theorem 3.3.2)')
"""

from __future__ import annotations

from typing import Any

from csplab.catalog import Propagator
from csplab.engine.alg31 import run_alg31
from csplab.problem import Problem
from csplab.result import Result
from csplab.solvers.base import TIME_LIMIT, Call, Solver, order_option

__all__ = ["TemplateSolver"]


class TemplateSolver(Solver):
    """Alg. 3.1 in scanline or random order: the solver to copy (incomplete)."""

    name = "template"
    complete = False
    # run_alg31 prunes with the global constraints after every choice (Propagator.constrain)
    constraints = "propagated"
    description = "the solver template: Alg. 3.1 in scanline or random order"
    notes = "copy `csplab/solvers/_template.py` to add a solver; not registered"
    options = (order_option(("scanline", "random")), TIME_LIMIT)
    bench = ({}, {"order": "random"})

    def run(self, problem: Problem, call: Call) -> Result:
        """Arc consistency at the root, then one run of Alg. 3.1 within the time left."""
        (order,) = call.get("order")
        stats: dict[str, Any] = {"order": order, "choice": "uniform"}
        eng = Propagator(problem)  # the catalog C of Alg. 3.2/3.3, propagated
        if not eng.ok:
            stats["fail_cell"] = list(problem.coords(eng.wiped)) if eng.wiped >= 0 else None
            proof = "arc-consistency wipe-out before any choice (Theorem 3.3.2)"
            return self.result("unsat", None, problem, stats, call, proof=proof)
        if call.expired():
            return self.result("timeout", None, problem, stats, call)
        r = run_alg31(problem, call.rng, order=order, engine=eng, time_limit=call.remaining())
        stats.update(r.stats)  # assigned, revisions, removals, fail_cell, proof, ...
        return self.result(r.status, r.grid, problem, stats, call, trace=r.trace)
