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

#: csplab's subpackages and modules, imported on first use as attributes: ``import csplab``
#: then ``csplab.io.read_model(...)`` works as the README writes it (without importing
#: every optional dependency up front)
_SUBMODULES = frozenset(
    {
        "analysis", "baselines", "catalog", "cli", "cnf", "complexity", "constraints",
        "continuous", "count", "deps", "engine", "errors", "exact", "example", "examples",
        "experiments", "grids", "io", "limits", "problem", "progress", "readme", "render",
        "result", "rng", "soft", "solvers", "testing", "topology",
    }
)  # fmt: skip


def __getattr__(name: str) -> object:
    """``csplab.io``, ``csplab.grids``, ...: the submodule, imported on first use."""
    if name in _SUBMODULES:
        import importlib

        return importlib.import_module(f"csplab.{name}")
    raise AttributeError(f"module 'csplab' has no attribute {name!r}")


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
