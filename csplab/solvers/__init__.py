"""Solver registry and :func:`solve`.

Solvers are looked up by name in one lazy table (modules are imported on first use);
``"name:backend"`` passes ``backend`` to the solver (``"sat:cadical195"``). Adding a solver
touches two files: its module here and the table below.

Every solver class has ``name``, ``complete`` (can prove unsatisfiability), ``requires``
(importable modules it needs), ``description`` and ``solve(problem, *, rng, seed, backend,
**options) -> Result``.

Examples
--------
>>> from csplab import ExampleModel, Problem, solve
>>> P = Problem.from_example(ExampleModel([[0, 1], [1, 0]]), (4, 4))
>>> r = solve(P, "catalog", rng=3)
>>> r.status, P.is_solution(r.grid)
('solved', True)
"""

from __future__ import annotations

import importlib
import importlib.util
import time
from typing import Any, ClassVar, Protocol

from csplab.errors import CsplabError, InputError, UnknownSolverError
from csplab.problem import Problem
from csplab.result import STATUSES, Result
from csplab.rng import RngLike, make_rng

__all__ = ["Solver", "available_solvers", "get_solver", "solve", "solver_names"]

# name -> "module:Class"
_REGISTRY: dict[str, str] = {
    "catalog": "csplab.solvers.catalog:CatalogSolver",
    "blocks": "csplab.solvers.blocks:BlocksSolver",
    "sat": "csplab.solvers.sat:SatSolver",
    "cpsat": "csplab.solvers.cpsat:CpsatSolver",
    "backtrack": "csplab.solvers.backtrack:BacktrackSolver",
    "perfect": "csplab.solvers.perfect:PerfectSolver",
    "hybrid": "csplab.solvers.hybrid:HybridSolver",
}


class Solver(Protocol):
    """What a solver class provides."""

    name: ClassVar[str]
    complete: ClassVar[bool]
    requires: ClassVar[tuple[str, ...]]
    description: ClassVar[str]

    def solve(
        self,
        problem: Problem,
        *,
        rng: Any,
        seed: int | None,
        backend: str | None = None,
        **options: Any,
    ) -> Result: ...


def solver_names() -> list[str]:
    """Registered solver names."""
    return list(_REGISTRY)


def _split(spec: str) -> tuple[str, str | None]:
    if not isinstance(spec, str) or not spec:
        raise UnknownSolverError(f"solver must be a name such as 'catalog', got {spec!r}")
    name, _, backend = spec.partition(":")
    return name, (backend or None)


def get_solver(spec: str) -> tuple[type[Solver], str | None]:
    """The solver class and backend for a spec such as ``"sat:glucose4"``."""
    name, backend = _split(spec)
    target = _REGISTRY.get(name)
    if target is None:
        raise UnknownSolverError(
            f"unknown solver {name!r}; available: {', '.join(sorted(_REGISTRY))}"
        )
    modname, clsname = target.split(":")
    cls: type[Solver] = getattr(importlib.import_module(modname), clsname)
    missing = [m for m in cls.requires if importlib.util.find_spec(m) is None]
    if missing:
        from csplab.errors import DependencyError

        raise DependencyError(
            f"solver {name!r} needs {', '.join(missing)}; install with "
            f"pip install 'csplab[{getattr(cls, 'extra', name)}]'"
        )
    return cls, backend


def available_solvers() -> list[dict[str, Any]]:
    """Name, description, completeness and whether dependencies are installed, per solver."""
    out = []
    for name, target in _REGISTRY.items():
        modname, clsname = target.split(":")
        try:
            cls = getattr(importlib.import_module(modname), clsname)
        except ImportError as e:  # the module itself needs something missing
            out.append({"name": name, "installed": False, "error": str(e)})
            continue
        missing = [m for m in cls.requires if importlib.util.find_spec(m) is None]
        info = {
            "name": name,
            "description": cls.description,
            "complete": cls.complete,
            "requires": list(cls.requires),
            "installed": not missing,
        }
        backends = getattr(cls, "backends", None)
        if callable(backends) and not missing:
            info["backends"] = backends()
        out.append(info)
    return out


def solve(problem: Problem, solver: str = "catalog", rng: RngLike = None, **options: Any) -> Result:
    """Solve ``problem`` with the named solver.

    Parameters
    ----------
    problem : Problem
    solver : str
        ``"catalog"``, ``"blocks"``, ... or ``"name:backend"``.
    rng : int, numpy.random.Generator or None
        Randomness; the seed is recorded in the result.
    **options
        Solver options (``order=``, ``time_limit=``, ``block=`` ...).

    Returns
    -------
    Result
        A ``solved`` grid is always checked with :meth:`Problem.violations`.
    """
    if not isinstance(problem, Problem):
        raise InputError(f"solve() needs a Problem, got {type(problem).__name__}")
    cls, backend = get_solver(solver)
    gen, seed = make_rng(rng)
    t0 = time.perf_counter()
    res = cls().solve(problem, rng=gen, seed=seed, backend=backend, **options)
    elapsed = time.perf_counter() - t0
    if res.status not in STATUSES:
        raise CsplabError(f"solver {solver!r} returned unknown status {res.status!r}")
    res.solver = solver
    res.seed = seed
    res.time_s = res.time_s or elapsed
    res.problem = problem
    if res.status == "solved":
        v = problem.violations(res.grid)
        if len(v):
            raise CsplabError(
                f"solver {solver!r} returned a grid that is not a solution "
                f"(a bug in csplab, please report):\n{v.describe()}"
            )
        res.stats.setdefault("violations", 0)
    return res
