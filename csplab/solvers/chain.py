"""The default chain: an incomplete solver that gives up is followed by an exact one.

:func:`csplab.solvers.solve` takes ``fallback=``: when an incomplete solver (``catalog``,
``blocks``, the continuous pipeline's solvers ...) has used up its restarts and still
reports ``failed``, the same problem, with the same global constraints, goes to an exact
solver for the time that is left. Its answer is the answer: ``solved`` (checked with
:meth:`Problem.violations`), ``unsat`` with the exact solver's proof, or ``timeout``.

=================  ==================================================================
fallback           what runs after the incomplete solver gave up
=================  ==================================================================
``None``           nothing (also ``"none"``): the run is the incomplete solver's alone,
                   as the thesis' experiments measure it (the default of :func:`solve`)
``"auto"``         ``sat`` where python-sat is installed, else ``backtrack``; a problem
                   too large for the SAT encoding (more than :data:`SAT_CELL_LABELS`
                   cell labels) goes to ``blocks`` with exact block completion instead
                   (the command line's default)
``"sat"``          the SAT solver (:mod:`csplab.solvers.sat`)
``"backtrack"``    MAC search (:mod:`csplab.solvers.backtrack`)
=================  ==================================================================

The fallback draws its randomness from the seed of the attempt after the last restart
(``csplab.solvers._derived_seed`` of the user's seed), so the whole call repeats for a
seed, and the result's ``attempt_seed`` reruns the fallback alone. The result names the solver that
produced it (``Result.solver``) and says in its stats which solver gave up
(``fallback_from``), after how many ``attempts`` and seconds (``gave_up_s``).

Examples
--------
>>> from csplab import from_example, load_example, solve
>>> P = from_example(load_example("fig3_5a"), (8, 8))
>>> r = solve(P, "catalog", rng=3, order="scan:yx", fallback="sat")   # catalog fails here
>>> r.status, r.solver, r.stats["fallback_from"], r.stats["attempts"]
('solved', 'sat', 'catalog', 1)
>>> Q = from_example(load_example("fig3_1b"), (5, 5), periodic=True)  # no solution
>>> q = solve(Q, "catalog", rng=1, restarts=2, fallback="auto")
>>> q.status, q.stats["proof"]
('unsat', 'refutation by cadical195')
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from csplab.deps import available
from csplab.errors import InputError, NoTrivialSolutionError
from csplab.problem import Problem
from csplab.result import Result
from csplab.solvers.base import Solver

__all__ = ["FALLBACKS", "SAT_CELL_LABELS", "check_fallback", "exact_solver", "finish"]

#: the values of ``fallback=`` (and of ``csplab synthesize --fallback``)
FALLBACKS: tuple[str, ...] = ("auto", "sat", "backtrack", "none")

#: ``fallback="auto"``: above this many cell labels (cells x labels allowed by the domains)
#: the SAT encoding is too large for a default run, and modify in blocks with exact block
#: completion finishes instead. Measured on this class of machine: city 40x40x10 (K=119,
#: 1.9 million) encodes and solves in 10 s and 630 MB; castle 40x40x10 (K=63, 1.0 million)
#: in 34 s and 680 MB (its arc consistency is slow); the memory grows linearly beyond.
SAT_CELL_LABELS = 2_500_000


def check_fallback(fallback: str | None) -> str | None:
    """``fallback`` validated: ``None`` for no fallback, else one of :data:`FALLBACKS`
    (``"sat"`` when python-sat is missing is one :class:`InputError` line)."""
    if fallback is None or fallback == "none":
        return None
    if fallback not in FALLBACKS:
        raise InputError(f"fallback must be one of {', '.join(FALLBACKS)}, not {fallback!r}")
    if fallback == "sat" and not available("pysat"):
        raise InputError(
            "fallback 'sat' needs python-sat (pip install 'csplab[sat]'); use fallback 'backtrack'"
        )
    return fallback


def exact_solver(problem: Problem, fallback: str, gave_up: str) -> str:
    """The solver that finishes after ``gave_up`` (a solver name) failed: ``fallback``
    itself, or for ``"auto"`` ``sat``/``backtrack``, or ``blocks`` (with exact block
    completion) for a problem too large for SAT."""
    if fallback != "auto":
        return fallback
    exact = "sat" if available("pysat") else "backtrack"
    if exact == "sat" and gave_up != "blocks" and cell_labels(problem) > SAT_CELL_LABELS:
        return "blocks"
    return exact


def cell_labels(problem: Problem) -> int:
    """The number of (cell, label) pairs the domains allow (the SAT encoding's size)."""
    return int(np.count_nonzero(problem.domains))


def finish(
    problem: Problem,
    fallback: str,
    gave_up: Result,
    *,
    solver: str,
    seed: int,
    attempts: int,
    t0: float,
    time_limit: float | None,
    options: dict[str, Any],
    lookup: Callable[[str], type[Solver]],
) -> Result:
    """Run the fallback solver on ``problem`` after ``gave_up`` (the incomplete solver
    ``solver``'s last result, ``failed``), with what is left of ``time_limit`` (the
    whole call's, measured from ``t0``), seeded with ``seed``; ``options`` are the
    incomplete solver's (their ``choice`` carries over where the exact solver has it);
    ``lookup`` finds a solver class by name (the registry's
    :func:`csplab.solvers.solver_class`, passed in so this module never imports the package
    that imports it). The result says which solver produced it. With no time left,
    ``gave_up`` is returned as a ``timeout``."""
    from csplab.rng import make_rng

    name = solver.partition(":")[0]
    target = exact_solver(problem, fallback, name)
    cls = lookup(target)
    opts: dict[str, Any] = {}
    spent = time.perf_counter() - t0
    if time_limit is not None:
        left = float(time_limit) - spent
        if left <= 0:
            gave_up.status = "timeout"
            gave_up.stats["fallback"] = f"{target} (no time left)"
            return gave_up
        opts["time_limit"] = left
    choice = options.get("choice")
    o = cls.option("choice")
    if choice is not None and o is not None and (o.values is None or choice in o.values):
        opts["choice"] = choice  # the user's label choice, where the exact solver has it
    if target == "blocks":
        opts["exact"] = "sat"  # a block that fails every retry is completed exactly
    try:
        res = cls().solve(problem, rng=make_rng(seed)[0], seed=seed, backend=None, **opts)
    except NoTrivialSolutionError as e:  # modify in blocks found no starting model
        res = Result("failed", np.full(problem.shape, -1, dtype=np.int32), target,
                     stats={"reason": str(e).splitlines()[0]})  # fmt: skip
    if res.status == "solved" and problem.constraints and cls.constraints == "checked":
        broken = problem.violations(res.grid).constraints
        if broken:
            res.status = "failed"
            res.stats["broken"] = list(broken)
    res.solver = target
    if "reason" in gave_up.stats:  # why the incomplete solver gave up without a run
        res.stats["reason"] = gave_up.stats["reason"]
    res.stats.update(
        fallback=target, fallback_from=name, attempts=attempts, gave_up_s=spent,
        attempt_seed=seed,
    )  # fmt: skip
    return res
