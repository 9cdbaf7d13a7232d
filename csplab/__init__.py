"""csplab: constraint programming for example-based model synthesis (Merrell 2007/2009).

Quickstart
----------
>>> import csplab
>>> E = csplab.load_example("line")                      # thesis Fig. 3.1(c)
>>> P = csplab.from_example(E, (20, 10))
>>> r = csplab.solve(P, solver="catalog", rng=1)
>>> r.status, P.is_solution(r.grid)
('solved', True)
"""

from __future__ import annotations

from csplab.catalog import propagate, propagate_reference
from csplab.errors import CsplabError
from csplab.example import ExampleModel
from csplab.examples import example_names, load_example
from csplab.grids import from_example
from csplab.problem import Problem, Violations
from csplab.result import Result, Verdict
from csplab.solvers import Solver, available_solvers, solve
from csplab.world import World

__version__ = "0.1.0"

__all__ = [
    "CsplabError",
    "ExampleModel",
    "Problem",
    "Result",
    "Solver",
    "Verdict",
    "Violations",
    "World",
    "__version__",
    "available_solvers",
    "example_names",
    "from_example",
    "load_example",
    "propagate",
    "propagate_reference",
    "solve",
]
