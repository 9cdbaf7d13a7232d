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

Options
-------
order : {"scanline", "random"}
choice : {"uniform", "weighted"}
backend : pysat backend (``perfect:glucose4``), default ``cadical195``
pool : int
    Witness solutions kept (default 16).
time_limit : float, optional

Examples
--------
>>> from csplab import ExampleModel, Problem, solve
>>> E = ExampleModel([[0, 1, 0, 1], [1, 0, 1, 0]])
>>> P = Problem.from_example(E, (5, 5), fixed={(4, 4): 1})
>>> r = solve(P, "perfect", rng=3)
>>> r.status, r.stats["rejected"] >= 0
('solved', True)
"""

from __future__ import annotations

import time
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from csplab.catalog import Propagator
from csplab.engine.completability import WitnessPool, choose_from_exact
from csplab.engine.sat import SAT_STAT_KEYS, SatOracle
from csplab.engine.sat import backends as sat_backends
from csplab.errors import CsplabError, InputError
from csplab.problem import Problem
from csplab.result import Result

__all__ = ["PerfectSolver"]


class PerfectSolver:
    """Complete: Alg. 3.1 drawing every label from C* (SAT-checked)."""

    name: ClassVar[str] = "perfect"
    complete: ClassVar[bool] = True
    requires: ClassVar[tuple[str, ...]] = ("pysat",)
    extra: ClassVar[str] = "sat"
    description: ClassVar[str] = (
        "Alg. 3.1 choosing only from the exact catalog C* (incremental SAT); never fails"
    )

    backends = staticmethod(sat_backends)  # the sat solver's backends

    def solve(
        self,
        problem: Problem,
        *,
        rng: np.random.Generator,
        seed: int | None,
        backend: str | None = None,
        order: str = "scanline",
        choice: str = "uniform",
        pool: int = 16,
        time_limit: float | None = None,
        **options: Any,
    ) -> Result:
        if options:
            raise InputError(f"unknown option(s) for solver 'perfect': {', '.join(options)}")
        if order not in ("scanline", "random"):
            raise InputError(f"order must be 'scanline' or 'random', not {order!r}")
        if choice not in ("uniform", "weighted"):
            raise InputError(f"choice must be 'uniform' or 'weighted', not {choice!r}")
        t0 = time.perf_counter()
        deadline = None if time_limit is None else t0 + float(time_limit)
        n = problem.n
        grid = np.full(n, -1, dtype=np.int32)
        stats: dict[str, Any] = {"order": order, "choice": choice, "sat_calls": 0,
                                 "rejected": 0, "assigned": 0}  # fmt: skip
        eng = Propagator(problem)
        if not eng.ok:
            stats["proof"] = "arc-consistency wipe-out before any choice (Theorem 3.3.2)"
            return _result("unsat", grid, problem, stats, t0)
        perm = rng.permutation(n) if order == "random" else np.arange(n)
        w = problem.weights if choice == "weighted" else None
        with SatOracle(problem, backend=backend, deadline=deadline,
                       seed=int(rng.integers(2**31 - 1))) as o:  # fmt: skip
            st = o.solve(deadline=deadline)
            stats["sat_calls"] += 1
            if st == "unsat":
                stats["proof"] = f"refutation by {o.backend}"
                return _result("unsat", grid, problem, stats, t0)
            if st == "timeout":
                return _result("timeout", grid, problem, stats, t0)
            wit = WitnessPool(n, pool)
            assert o.grid is not None
            wit.add(o.grid.reshape(-1))
            for p in perm.tolist():
                if deadline is not None and time.perf_counter() > deadline:
                    return _result("timeout", grid, problem, stats, t0)
                labels = eng.domain(p)
                if labels.size == 1:
                    b = int(labels[0])
                else:
                    pick = choose_from_exact(o, wit, p, labels, w, rng, stats, deadline)
                    if pick is None:
                        return _result("timeout", grid, problem, stats, t0)
                    b = pick
                    o.add_clause([o.literal(p, b)])
                grid[p] = b
                wit.fix(p, b)
                stats["assigned"] += 1
                if not eng.assign(p, b):  # impossible: M_t stays completable
                    raise CsplabError("perfect: arc consistency failed after a C* choice (a bug)")
            stats["sat"] = {k: o.stats[k] for k in SAT_STAT_KEYS if k in o.stats}
        return _result("solved", grid, problem, stats, t0)


def _result(status: Any, grid: NDArray[np.int32], problem: Problem, stats: dict[str, Any],
            t0: float) -> Result:  # fmt: skip
    return Result(status, grid.reshape(problem.shape), "perfect",
                  time_s=time.perf_counter() - t0, stats=stats)  # fmt: skip
