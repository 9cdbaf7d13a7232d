"""Solver ``hybrid``: Alg. 3.1 at full speed, repaired with SAT only when it fails.

csplab's design for a cheap complete variant of Merrell's algorithm. Alg. 3.1 runs as usual
(compiled catalog, no SAT). If it fails, the partial models M_0 ⊆ M_1 ⊆ ... of the run are
consistent up to some step and inconsistent after it (consistency is monotone), so a binary
search with incremental SAT calls (assumptions = the run's prefix) finds the first choice
that left C* -- the step where the catalog's imperfection (Fig. 3.5) bit. The consistent
prefix is fixed, that cell gets a label drawn from C*(p) (as in ``perfect``), and Alg. 3.1
resumes from there with fresh random choices. Each repair fixes at least one more cell, so
the loop ends; it never fails on a satisfiable problem and proves unsatisfiability with its
first SAT call. When Alg. 3.1 succeeds no SAT solver is even created.

Its outputs follow the same distribution as ``perfect`` (for the scanline order): steps
before the doomed one drew a label of C(p) that happened to lie in C*(p), i.e. a uniform
label of C*(p); the doomed draw is exactly the one ``perfect`` would reject, and it is
redrawn uniformly from C*(p); later steps use fresh randomness. (A chi-square test against
the exact distribution checks this: ``tests/solvers/test_perfect_hybrid.py``.) So
``hybrid`` is a cheap sampler of the thesis' ideal algorithm.

Examples
--------
>>> from csplab import ExampleModel, from_example, solve
>>> E = ExampleModel([[0, 0, 0, 2], [2, 0, 0, 1], [0, 1, 2, 1]])   # Alg. 3.1 fails on it
>>> P = from_example(E, (8, 8))
>>> solve(P, "catalog", rng=3).status
'failed'
>>> r = solve(P, "hybrid", rng=3)             # the same run, repaired where it failed
>>> r.status, r.stats["repairs"] > 0
('solved', True)
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.catalog import Propagator
from csplab.engine.alg31 import run_alg31
from csplab.engine.completability import (
    PrefixTimeout,
    SatCompletability,
    WitnessPool,
    choose_from_exact,
    first_inconsistent_prefix,
)
from csplab.engine.sat import SAT_STAT_KEYS, SatOracle
from csplab.engine.sat import backends as sat_backends
from csplab.errors import CsplabError
from csplab.problem import Problem
from csplab.result import Result, Status
from csplab.solvers.base import CHOICE, TIME_LIMIT, Call, Solver, order_option

__all__ = ["HybridSolver"]


class HybridSolver(Solver):
    """Complete: Alg. 3.1, with SAT-guided repair of the first bad choice after a failure."""

    name = "hybrid"
    constraints = "propagated"
    alg31 = True
    complete = True
    requires = ("pysat",)
    description = (
        "Alg. 3.1; after a failure, binary search (SAT) for the first choice outside C*, "
        "redraw it from C*, resume"
    )
    notes = (
        "as fast as Alg. 3.1 when it succeeds (no SAT solver is created), never fails; samples "
        "the same distribution as `perfect` (chi-square-tested)"
    )
    options = (order_option(), CHOICE, TIME_LIMIT)
    backends = staticmethod(sat_backends)

    def run(self, problem: Problem, call: Call) -> Result:
        rng, backend = call.rng, call.backend
        order, choice = call.get("order", "choice")
        deadline = call.deadline
        n = problem.n
        fixed = np.full(n, -1, dtype=np.int64)
        stats: dict[str, Any] = {"order": order, "choice": choice, "alg31_runs": 0,
                                 "repairs": 0, "sat_calls": 0, "rejected": 0}  # fmt: skip
        oracle: SatOracle | None = None
        w = problem.weights if choice == "weighted" else None
        try:
            while True:
                left = call.remaining()
                if left is not None and left <= 0:
                    return self.result("timeout", fixed, problem, stats, call)
                dom = problem.domains.copy()
                idx = np.flatnonzero(fixed >= 0)
                dom[idx] = False
                dom[idx, fixed[idx]] = True
                eng = Propagator(problem, domains=dom)
                stats["alg31_runs"] += 1
                r = run_alg31(problem, rng, order=order, choice=choice, time_limit=left,
                              engine=eng)  # fmt: skip
                if r.status == "solved":
                    stats["fixed_by_repair"] = int(idx.size)
                    return self.result("solved", r.grid, problem, stats, call)
                if r.status == "timeout":
                    return self.result("timeout", fixed, problem, stats, call)
                if r.status == "unsat" and idx.size == 0:  # Alg. 3.1's proof (Theorem 3.3.2)
                    proof = str(r.stats["proof"])
                    return self.result("unsat", fixed, problem, stats, call, proof=proof)
                if oracle is None:
                    oracle = SatOracle(problem, backend=backend, deadline=deadline,
                                       seed=int(rng.integers(2**31 - 1)))  # fmt: skip
                    st = oracle.solve(deadline=deadline)
                    stats["sat_calls"] += 1
                    if st != "sat":
                        if st == "unsat":
                            stats["proof"] = f"refutation by {oracle.backend}"
                        end: Status = "timeout" if st == "timeout" else "unsat"
                        return self.result(end, fixed, problem, stats, call)
                trace = r.trace if r.trace is not None else np.zeros((0, 2), dtype=np.int64)
                if r.status != "failed" or trace.shape[0] == 0:
                    raise CsplabError("hybrid: Alg. 3.1 failed on a consistent prefix (a bug)")
                k = self._first_bad(oracle, trace, stats, deadline)
                if k is None:
                    return self.result("timeout", fixed, problem, stats, call)
                # fix the consistent prefix, then redraw step k from C*
                for p, b in trace[:k].tolist():
                    if fixed[p] < 0:
                        fixed[p] = b
                        oracle.add_clause([oracle.literal(p, b)])
                p, bad = (int(x) for x in trace[k])
                oracle.add_clause([-oracle.literal(p, bad)])
                dom = problem.domains.copy()
                idx = np.flatnonzero(fixed >= 0)
                dom[idx] = False
                dom[idx, fixed[idx]] = True
                dom[p, bad] = False
                eng = Propagator(problem, domains=dom)
                labels = eng.domain(p) if eng.ok else np.zeros(0, dtype=np.int64)
                pool = WitnessPool(n, 1)
                b2 = choose_from_exact(oracle, pool, p, labels, w, rng, stats, deadline)
                if b2 is None:
                    if call.expired():
                        return self.result("timeout", fixed, problem, stats, call)
                    raise CsplabError("hybrid: no label of C* at a consistent step (a bug)")
                fixed[p] = b2
                oracle.add_clause([oracle.literal(p, b2)])
                stats["repairs"] += 1
        finally:
            if oracle is not None:
                stats["sat"] = {k: oracle.stats[k] for k in SAT_STAT_KEYS if k in oracle.stats}
                oracle.close()

    @staticmethod
    def _first_bad(oracle: SatOracle, trace: NDArray[np.int64], stats: dict[str, Any],
                   deadline: float | None) -> int | None:  # fmt: skip
        """0-based index of the first step of the failed run whose prefix (with it) is
        inconsistent, on top of the oracle's clauses (the fixed cells); ``None`` on
        timeout."""
        comp = SatCompletability(oracle.problem, deadline=deadline, oracle=oracle)
        try:
            return first_inconsistent_prefix(comp, trace, full_inconsistent=True)
        except PrefixTimeout:
            return None
        finally:
            stats["sat_calls"] += comp.calls
