"""Solver registry and :func:`solve`.

Solvers are looked up by name in one lazy table (modules are imported on first use);
``"name:backend"`` passes ``backend`` to the solver (``"sat:cadical195"``). A solver is a
subclass of :class:`~csplab.solvers.base.Solver` that declares its name, completeness,
dependencies, options and backends once (:mod:`csplab.solvers.base`); the CLI's choices,
``csplab info``, the experiments, the solver benchmark, the conformance suite and the README
solver table (:func:`markdown_table`) are derived from the declarations.

Adding a solver touches its module and one line of :data:`REGISTRY` (plus an extra in
``pyproject.toml`` if it needs a package); :func:`register` adds one at run time, and
installed packages can add their own through the ``csplab.solvers`` entry-point group, and
the environment variable ``CSPLAB_SOLVERS="name=module:Class,..."`` adds solvers to a
process and its workers.

Examples
--------
>>> from csplab import ExampleModel, from_example, solve
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (4, 4))
>>> r = solve(P, "catalog", rng=3)
>>> r.status, P.is_solution(r.grid)
('solved', True)
>>> "backtrack" in solver_names()
True
"""

from __future__ import annotations

import importlib
import os
import time
from importlib.metadata import entry_points
from typing import Any

import numpy as np

from csplab.deps import EXTRAS, available
from csplab.errors import (
    CsplabError,
    DependencyError,
    InputError,
    NoTrivialSolutionError,
    UnknownSolverError,
)
from csplab.problem import Problem
from csplab.result import STATUSES, Result
from csplab.rng import RngLike, make_rng
from csplab.solvers.base import STATS, Option, Solver, unknown_stats

__all__ = [
    "REGISTRY",
    "STATS",
    "Option",
    "Solver",
    "available_solvers",
    "extra_of",
    "get_solver",
    "markdown_table",
    "option_values",
    "register",
    "solve",
    "solver_class",
    "solver_names",
    "solvers_taking",
    "unknown_stats",
]

# name -> "module:Class": the one place a solver is registered
REGISTRY: dict[str, str] = {
    "catalog": "csplab.solvers.catalog:CatalogSolver",
    "blocks": "csplab.solvers.blocks:BlocksSolver",
    "sat": "csplab.solvers.sat:SatSolver",
    "cpsat": "csplab.solvers.cpsat:CpsatSolver",
    "backtrack": "csplab.solvers.backtrack:BacktrackSolver",
    "perfect": "csplab.solvers.perfect:PerfectSolver",
    "hybrid": "csplab.solvers.hybrid:HybridSolver",
    "asp": "csplab.solvers.asp:AspSolver",
}
_PLUGINS_LOADED = False


_ENV = "CSPLAB_SOLVERS"  # "name=module:Class,..." registered in this process and its children


def _load_plugins() -> None:
    global _PLUGINS_LOADED
    for item in filter(None, os.environ.get(_ENV, "").split(",")):
        name, sep, target = item.partition("=")
        if sep and ":" in target:
            REGISTRY.setdefault(name.strip(), target.strip())
    if _PLUGINS_LOADED:
        return
    _PLUGINS_LOADED = True
    for ep in entry_points(group="csplab.solvers"):
        REGISTRY.setdefault(ep.name, ep.value)


def register(name: str, target: str) -> None:
    """Register a solver class ``"module:Class"`` under ``name`` at run time.

    The registration is also put into the environment variable ``CSPLAB_SOLVERS``, so the
    worker processes of an experiment (started later, from this process) see it too.
    """
    if not name or any(c in name for c in ":@=,"):
        raise InputError(f"solver name {name!r} may not be empty or contain : @ = ,")
    if target.count(":") != 1:
        raise InputError(f"solver target {target!r} must be 'module:Class'")
    REGISTRY[name] = target
    items = [i for i in os.environ.get(_ENV, "").split(",") if i and not i.startswith(name + "=")]
    os.environ[_ENV] = ",".join([*items, f"{name}={target}"])


def solver_names() -> list[str]:
    """Registered solver names."""
    _load_plugins()
    return list(REGISTRY)


def _split(spec: str) -> tuple[str, str | None]:
    if not isinstance(spec, str) or not spec:
        raise UnknownSolverError(f"solver must be a name such as 'catalog', got {spec!r}")
    name, _, backend = spec.partition(":")
    return name, (backend or None)


def solver_class(name: str) -> type[Solver]:
    """The class registered as ``name`` (imported, dependencies not checked)."""
    _load_plugins()
    target = REGISTRY.get(name)
    if target is None:
        raise UnknownSolverError(
            f"unknown solver {name!r}; available: {', '.join(sorted(REGISTRY))}"
        )
    modname, clsname = target.split(":")
    cls = getattr(importlib.import_module(modname), clsname)
    if not (isinstance(cls, type) and all(hasattr(cls, a) for a in ("validate", "run", "options"))):
        raise CsplabError(f"{target} is not a csplab.solvers.base.Solver subclass")
    return cls


def _missing(cls: type[Solver]) -> list[str]:
    return [m for m in cls.requires if not available(m)]


def extra_of(cls: type[Solver]) -> str | None:
    """The pip extra that installs what a solver ``requires``: the one table
    :data:`csplab.deps.EXTRAS` (module -> extra) says it, not the solver.

    Parameters
    ----------
    cls : type of Solver
        A solver class.

    Returns
    -------
    str or None
        The extra of its first required module that has one; ``None`` when it requires
        nothing.

    Examples
    --------
    >>> [extra_of(solver_class(name)) for name in ("cpsat", "perfect", "catalog")]
    ['cpsat', 'sat', None]
    """
    return next((EXTRAS[t] for m in cls.requires if (t := m.partition(".")[0]) in EXTRAS), None)


def get_solver(spec: str) -> tuple[type[Solver], str | None]:
    """The solver class and backend for a spec such as ``"sat:glucose4"``; a missing
    dependency is one :class:`~csplab.errors.DependencyError` line naming the extra."""
    name, backend = _split(spec)
    cls = solver_class(name)
    missing = _missing(cls)
    if missing:
        raise DependencyError(
            f"solver {name!r} needs {', '.join(missing)}; install it with "
            f"pip install 'csplab[{extra_of(cls) or name}]'"
        )
    return cls, backend


def _option_info(o: Option) -> dict[str, Any]:
    d: dict[str, Any] = {"name": o.name, "type": o.kind.__name__, "default": o.default,
                         "doc": o.doc}  # fmt: skip
    if o.values is not None:
        d["values"] = list(o.values)
    if o.minimum is not None:
        d["minimum"] = o.minimum
    return d


def available_solvers() -> list[dict[str, Any]]:
    """What every registered solver declares, and whether it can run here.

    Returns
    -------
    list of dict
        One dict per registered solver, in registry order: ``name``, ``description``,
        ``complete``, ``constraints``, ``requires``, ``extra``, ``installed`` and
        ``options`` (name, type, default, doc, and values or minimum where declared),
        plus ``backends`` when the solver has backends and is installed. A solver whose
        module cannot be imported is ``{"name", "installed": False, "error"}``.
    """
    out = []
    for name in solver_names():
        try:
            cls = solver_class(name)
        except (ImportError, CsplabError) as e:  # the module itself needs something missing
            out.append({"name": name, "installed": False, "error": str(e)})
            continue
        missing = _missing(cls)
        info: dict[str, Any] = {
            "name": name,
            "description": cls.description,
            "complete": cls.complete,
            "constraints": cls.constraints,
            "requires": list(cls.requires),
            "extra": extra_of(cls),
            "installed": not missing,
            "options": [_option_info(o) for o in cls.options],
        }
        if cls.backends is not None and not missing:
            info["backends"] = cls.backends()
        out.append(info)
    return out


def solvers_taking(option: str) -> list[str]:
    """The solvers that declare ``option`` (importable ones only)."""
    out = []
    for name in solver_names():
        try:
            if solver_class(name).option(option) is not None:
                out.append(name)
        except (ImportError, CsplabError):
            continue
    return out


def option_values(option: str) -> list[str]:
    """Every value any solver allows for the ``str`` option ``option`` (first seen first)."""
    vals: dict[str, None] = {}
    for name in solvers_taking(option):
        o = solver_class(name).option(option)
        for v in o.values if o is not None and o.values else ():
            vals.setdefault(v)
    return list(vals)


def markdown_table() -> str:
    """The README solver table, from the declarations (``python -m csplab.solvers``)."""
    rows = [
        "| name | algorithm | complete | global constraints | options | notes |",
        "|---|---|---|---|---|---|",
    ]
    for name in solver_names():
        cls = solver_class(name)
        spec = f"`{name}[:backend]`" if cls.backends is not None else f"`{name}`"
        opts = ", ".join(
            f"`{o.name}`" + (f" ({'/'.join(o.values)})" if o.values else "") for o in cls.options
        )
        rows.append(
            f"| {spec} | {cls.description} | {'yes' if cls.complete else 'no'} | "
            f"{cls.constraints} | {opts} | {cls.notes} |"
        )
    return "\n".join(rows)


def solve(
    problem: Problem,
    solver: str = "catalog",
    rng: RngLike = None,
    *,
    restarts: int = 0,
    fallback: str | None = None,
    **options: Any,
) -> Result:
    """Solve ``problem`` with the named solver.

    Parameters
    ----------
    problem : Problem
        The problem to solve (:func:`csplab.from_example`, :mod:`csplab.grids`).
    solver : str
        ``"catalog"``, ``"blocks"``, ... or ``"name:backend"``.
    rng : int, numpy.random.Generator or None
        Randomness; the seed is recorded in the result.
    restarts : int
        For an incomplete solver, run again up to this many times while it reports
        ``failed`` (each attempt with a fresh seed derived from ``rng``; the first attempt is
        the run without restarts). WaveFunctionCollapse retries a contradiction up to 10
        times per output, Merrell's code up to 20 times per block; the thesis' experiments
        measure single runs (0, the default here). The result's stats say ``attempts`` and,
        after a restart, the ``attempt_seed`` that reproduces the returned run alone.
        ``time_limit`` covers all attempts.
    fallback : {None, "auto", "sat", "backtrack", "none"}
        What finishes the problem when an incomplete solver still reports ``failed`` after
        its restarts (:mod:`csplab.solvers.chain`): ``None`` (the default, as the thesis'
        experiments: the incomplete solver's run is the result) or an exact solver, run on
        the same problem for the time that is left, seeded from ``rng``; ``"auto"`` is
        ``sat`` where installed, else ``backtrack``, and modify in blocks with exact block
        completion for a problem too large for SAT. The result's ``solver`` is the one that
        produced it; its stats say ``fallback_from``.
    **options
        Solver options (``order=``, ``time_limit=``, ``block=`` ...).

    Returns
    -------
    Result
        A ``solved`` grid is always checked with :meth:`Problem.violations`.

    Raises
    ------
    InputError
        When ``problem`` is not a :class:`Problem`, ``restarts`` is not a non-negative
        integer, ``fallback`` is unknown, or an option is unknown or invalid for the solver.
    UnknownSolverError
        When ``solver`` names no registered solver.
    DependencyError
        When the solver needs an optional package that is not installed (the message names
        the pip extra).
    NoTrivialSolutionError
        When modify in blocks finds no consistent starting model and there is no
        ``fallback``.
    CsplabError
        When a solver returns an unknown status or a grid that is not a solution (a bug).

    Examples
    --------
    >>> from csplab import from_example, load_example
    >>> P = from_example(load_example("fig3_5a"), (8, 8))           # Fig. 3.5: fallible
    >>> solve(P, "catalog", rng=3, order="scan:yx").status          # fails on this seed
    'failed'
    >>> r = solve(P, "catalog", rng=3, order="scan:yx", restarts=10)
    >>> r.status, r.stats["attempts"] > 1, r.seed
    ('solved', True, 3)
    >>> solve(P, "catalog", rng=r.stats["attempt_seed"], order="scan:yx").status  # alone
    'solved'
    """
    if not isinstance(problem, Problem):
        raise InputError(f"solve() needs a Problem, got {type(problem).__name__}")
    if isinstance(restarts, bool) or not isinstance(restarts, int) or restarts < 0:
        raise InputError(f"restarts must be a non-negative integer, not {restarts!r}")
    from csplab.solvers import chain

    fallback = chain.check_fallback(fallback)
    cls, backend = get_solver(solver)
    gen, seed = make_rng(rng)
    t0 = time.perf_counter()
    limit = options.get("time_limit")
    attempt_seed: int | None = None
    attempt = 0
    while True:
        try:
            res = cls().solve(problem, rng=gen, seed=seed, backend=backend, **options)
        except NoTrivialSolutionError as e:
            if fallback is None or cls.complete:
                raise
            # modify in blocks found no starting model (the same on every attempt): it gave up
            res = Result("failed", np.full(problem.shape, -1, dtype=np.int32), cls.name,
                         stats={"reason": str(e).splitlines()[0]})  # fmt: skip
            attempt += 1
            break
        attempt += 1
        if res.status not in STATUSES:
            raise CsplabError(f"solver {solver!r} returned unknown status {res.status!r}")
        if res.status == "solved" and problem.constraints and cls.constraints == "checked":
            # a solver that only checks global constraints: a breach is a failed run
            broken = problem.violations(res.grid).constraints
            if broken:
                res.status = "failed"
                res.stats["broken"] = list(broken)
        if res.status != "failed" or cls.complete or attempt > restarts:
            break
        if limit is not None:
            left = float(limit) - (time.perf_counter() - t0)
            if left <= 0:
                break
            options = {**options, "time_limit": left}
        attempt_seed = _derived_seed(seed, attempt, gen)
        gen = make_rng(attempt_seed)[0]
    chained = fallback is not None and res.status == "failed" and not cls.complete
    if chained:
        assert fallback is not None
        res = chain.finish(
            problem, fallback, res, solver=solver, seed=_derived_seed(seed, attempt, gen),
            attempts=attempt, t0=t0, time_limit=limit, options=options, lookup=solver_class,
        )  # fmt: skip
    elapsed = time.perf_counter() - t0
    if "fallback_from" not in res.stats:
        res.solver = solver
    res.seed = seed
    res.time_s = elapsed if attempt > 1 or chained else (res.time_s or elapsed)
    res.problem = problem
    if restarts and "fallback_from" not in res.stats:
        res.stats["attempts"] = attempt
        if attempt_seed is not None:
            res.stats["attempt_seed"] = attempt_seed
    if res.status == "solved":
        v = problem.violations(res.grid)
        if len(v):
            raise CsplabError(
                f"solver {res.solver!r} returned a grid that is not a solution "
                f"(a bug in csplab, please report):\n{v.describe()}"
            )
        res.stats.setdefault("violations", 0)
    return res


def _derived_seed(seed: int | None, attempt: int, gen: Any) -> int:
    """The seed of restart ``attempt``: a function of the user's seed (so the whole call
    repeats), or drawn from the generator when it has no recorded seed."""
    if seed is None:
        return int(gen.integers(2**62))
    state = np.random.SeedSequence([seed, attempt]).generate_state(1, np.uint64)[0]
    return int(state >> np.uint64(2))
