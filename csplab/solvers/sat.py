"""Solver ``sat``: a CNF encoding (:mod:`csplab.cnf`) solved with python-sat.

Backends are pysat solvers named after the colon, ``sat:cadical195`` (default),
``sat:glucose4``, ... (:func:`csplab.engine.sat.backends`; pysat's aliases such as ``g4``
work too). The work is done by the incremental oracle :class:`csplab.engine.sat.SatOracle`
(encoding, the fast CaDiCaL loader, deadlines); this module is the adapter.

Diversity: before solving, every cell gets a preferred label drawn from the catalog with
the rng (``phase="uniform"``, the default, like Alg. 3.1's uniform choice, or
``"weighted"`` by the example's label frequencies) and the solver's decision phases are set
to it; CaDiCaL is also seeded. Two seeds' outputs differ in 30-46% of the cells at
40×40×10 (``benchmarks/bench_solvers.py``; Alg. 3.1: 16-30%); ``"weighted"`` phases give
mostly empty space and much less variety; ``phase="none"`` keeps the solver's own phases.

Status ``unsat`` comes only with a proof: the SAT solver's refutation, or an arc-consistency
wipe-out before any choice (what unit propagation on the support encoding also derives).

Options
-------
encoding : {"support", "direct"}
supports : {"both", "forward"}
amo : str
    ``"lazy"`` (default) or a :mod:`pysat.card` encoding (see :mod:`csplab.cnf`).
phase : {"uniform", "weighted", "none"}
time_limit : float, optional
    Seconds for the whole call (encoding, loading and search); status ``timeout``.
loader : {"auto", "api"}

Examples
--------
>>> from csplab import ExampleModel, Problem, solve
>>> P = Problem.from_example(ExampleModel([[0, 1], [1, 0]]), (5, 4))
>>> r = solve(P, "sat", rng=1)
>>> r.status, r.stats["backend"]
('solved', 'cadical195')
>>> solve(P, "sat:glucose4", rng=1).status
'solved'
>>> Q = Problem.from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3), fixed={(0, 0): 0, (0, 1): 0})
>>> solve(Q, "sat", rng=1).stats["proof"]
'arc-consistency wipe-out (unit propagation on the support encoding)'
"""

from __future__ import annotations

import time
from typing import Any, ClassVar

import numpy as np

from csplab.cnf import AMO_ENCODINGS
from csplab.engine.sat import SatOracle, backends, preferred_labels
from csplab.errors import InputError
from csplab.problem import Problem
from csplab.result import Result, Status

__all__ = ["SatSolver"]


# ----------------------------------------------------------------------------- solver


class SatSolver:
    """Complete: CNF encoding + a pysat backend."""

    name: ClassVar[str] = "sat"
    complete: ClassVar[bool] = True
    requires: ClassVar[tuple[str, ...]] = ("pysat",)
    extra: ClassVar[str] = "sat"
    description: ClassVar[str] = (
        "CNF (support encoding, lazy at-most-one) solved by python-sat; sat:BACKEND"
    )

    @staticmethod
    def backends() -> list[str]:
        return backends()

    def solve(
        self,
        problem: Problem,
        *,
        rng: np.random.Generator,
        seed: int | None,
        backend: str | None = None,
        encoding: str = "support",
        supports: str = "both",
        amo: str = "lazy",
        phase: str = "uniform",
        time_limit: float | None = None,
        loader: str = "auto",
        **options: Any,
    ) -> Result:
        if options:
            raise InputError(f"unknown option(s) for solver 'sat': {', '.join(options)}")
        if phase not in ("weighted", "uniform", "none"):
            raise InputError(f"phase must be 'weighted', 'uniform' or 'none', not {phase!r}")
        if amo not in AMO_ENCODINGS:
            raise InputError(f"amo must be one of {', '.join(AMO_ENCODINGS)}")
        t0 = time.perf_counter()
        deadline = None if time_limit is None else t0 + float(time_limit)
        cseed = int(rng.integers(2**31 - 1))
        grid = np.full(problem.shape, -1, dtype=np.int32)
        with SatOracle(
            problem, backend=backend, encoding=encoding, supports=supports, amo=amo,
            loader=loader, deadline=deadline, seed=cseed,
        ) as o:  # fmt: skip
            stats = o.stats
            stats.update(encoding=encoding, supports=supports, amo=amo, phase=phase)
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
                if phase != "none":
                    w = problem.weights if phase == "weighted" else None
                    o.set_phases(preferred_labels(o.enc.catalog, w, rng))
                status = o.solve(deadline=deadline)
                stats.update(o.solver_stats())
                if status == "sat" and o.grid is not None:
                    grid = o.grid
                if status == "unsat":
                    stats["proof"] = f"refutation by {o.backend}"
            t1 = time.perf_counter()
        # freeing a solver with millions of clauses takes a while: it counts
        stats["free_s"] = time.perf_counter() - t1
        final: Status = "solved" if status == "sat" else "unsat" if status == "unsat" else "timeout"
        return Result(final, grid, "sat", time_s=time.perf_counter() - t0, stats=stats)
