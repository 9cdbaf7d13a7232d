"""Solver ``catalog``: Merrell's discrete model synthesis, Alg. 3.1 (with Alg. 3.2/3.3).

Every cell is assigned a label drawn from the catalog C (arc consistency), and C is updated
after each assignment. When a domain empties the run stops with status ``failed``: the
algorithm gave up, which says nothing about satisfiability. A wipe-out before any choice is
a proof of unsatisfiability (Theorem 3.3.2) and gives ``unsat``.

Options
-------
order : {"scanline", "random", "min-entropy", "scan:AXES"}
    ``scanline`` is the thesis' loop order (x outermost, z innermost; default);
    ``scan:AXES`` scans with the named axes from outermost to innermost, e.g. ``scan:yx``,
    the order of the thesis' 2D figures (left to right, then bottom to top);
    ``random`` a random permutation; ``min-entropy`` picks the unassigned cell of least
    Shannon entropy (weighted when ``choice="weighted"``) with tiny random tie-breaking, as
    WaveFunctionCollapse does.
choice : {"uniform", "weighted"}
    ``uniform`` over the catalog (thesis, default) or ``weighted`` by the problem's label
    weights (example frequencies).
time_limit : float, optional
    Seconds; status ``timeout`` when exceeded.

Examples
--------
>>> from csplab import ExampleModel, Problem, solve
>>> from csplab.examples import load_example
>>> P = Problem.from_example(load_example("line"), (8, 6))
>>> r = solve(P, "catalog", rng=1, order="min-entropy")
>>> r.status, r.stats["assigned"]
('solved', 48)
"""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from csplab.engine.alg31 import run_alg31
from csplab.errors import InputError
from csplab.problem import Problem
from csplab.result import Result

__all__ = ["CatalogSolver"]


class CatalogSolver:
    """Alg. 3.1: assign every cell from the arc-consistent catalog (incomplete)."""

    name: ClassVar[str] = "catalog"
    complete: ClassVar[bool] = False
    requires: ClassVar[tuple[str, ...]] = ()
    description: ClassVar[str] = (
        "Merrell Alg. 3.1: assign cells from the arc-consistent catalog; "
        "orders scanline/random/min-entropy"
    )

    def solve(
        self,
        problem: Problem,
        *,
        rng: np.random.Generator,
        seed: int | None,
        backend: str | None = None,
        order: str = "scanline",
        choice: str = "uniform",
        time_limit: float | None = None,
        **options: Any,
    ) -> Result:
        if backend is not None:
            raise InputError(f"solver 'catalog' has no backends (got {backend!r})")
        if options:
            raise InputError(f"unknown option(s) for solver 'catalog': {', '.join(options)}")
        return run_alg31(problem, rng, order=order, choice=choice, time_limit=time_limit)
