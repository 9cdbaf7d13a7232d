"""The solver contract: a solver declares itself once, here is what it declares.

A solver is a subclass of :class:`Solver` that sets the class attributes below and
implements :meth:`Solver.run`. Everything else is derived from the declaration: option
validation (types, allowed values, defaults, unknown names), the ``order``/``choice``
vocabulary, ``time_limit``, the registry's ``available_solvers()`` and ``csplab info``,
the CLI's choices, the experiments' solver capabilities, the solver benchmark and the
README solver table (:func:`csplab.solvers.markdown_table`).

============  ==================================================================
attribute     meaning
============  ==================================================================
name          registry name (``csplab synthesize --solver NAME``)
complete      can prove unsatisfiability (and never gives up on a satisfiable one)
description   one line: the algorithm
notes         a few sentences for the README table (defaults, measured facts)
requires      importable modules it needs (the pip extra that installs them is derived
              from :data:`csplab.deps.EXTRAS`: :func:`csplab.solvers.extra_of`)
options       :class:`Option` declarations (use :func:`order_option`,
              :data:`CHOICE`, :data:`TIME_LIMIT` for the shared vocabulary)
backends      a callable listing the ``name:backend`` values, or ``None``
alg31         runs Alg. 3.1 and takes its ``order``/``choice`` vocabulary (the
              experiments pass their ``--order``/``--choice`` to these solvers)
constraints   what it does with global constraints (:mod:`csplab.constraints`):
              ``exact`` (encoded: a solution honours them, unsat is a proof),
              ``propagated`` (pruned during the search, checked at the end) or
              ``checked`` (a finished grid that breaks one becomes ``failed``, which
              restarts retry); no solver returns ``solved`` with one broken
bench         option variants ``benchmarks/bench_solvers.py`` times
============  ==================================================================

Every exit of :meth:`Solver.run` is :meth:`Solver.result` (the time since ``call.t0``, the
proof of an ``unsat``), and the time limit is ``call.deadline``. Stats: ``Result.stats``
uses only the names of :data:`STATS` (one name per concept), whichever path made them (a
solver, :func:`csplab.solvers.solve`, continuous synthesis); the conformance suite checks
it. ``csplab/solvers/_template.py`` is a minimal solver to copy.

Examples
--------
>>> from csplab.solvers import solver_class
>>> cls = solver_class("catalog")
>>> [o.name for o in cls.options]
['order', 'choice', 'window', 'time_limit']
>>> cls.validate({"order": "scan:yx"})["choice"]
'uniform'
>>> cls.validate({"order": "zigzag"})
Traceback (most recent call last):
...
csplab.errors.InputError: solver 'catalog': order must be one of auto, scanline, ...
"""

from __future__ import annotations

import math
import sys
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.engine.alg31 import CHOICES, ORDERS, check_order
from csplab.errors import CsplabError, InputError
from csplab.problem import Problem
from csplab.result import Result, Status

__all__ = [
    "CHOICE",
    "STATS",
    "TIME_LIMIT",
    "WINDOW",
    "Call",
    "Option",
    "Solver",
    "order_option",
    "positive_seconds",
    "unknown_stats",
]

_MISSING = object()


@dataclass(frozen=True)
class Option:
    """One solver option: name, type, default, allowed values and one line of documentation.

    ``kind`` is ``int``, ``float``, ``str``, ``bool`` or ``object`` (anything, checked by
    ``convert``); ``values`` lists the allowed values of a ``str`` option (``"scan:AXES"``
    admits every ``scan:...`` order); ``minimum`` bounds numbers; ``nullable`` admits
    ``None``; ``convert`` turns a value into the solver's form (and raises
    :class:`InputError` for bad ones).
    """

    name: str
    kind: type
    default: Any
    doc: str
    values: tuple[str, ...] | None = None
    minimum: float | None = None
    nullable: bool = False
    convert: Callable[[Any], Any] | None = None

    def check(self, value: Any, solver: str) -> Any:
        """``value`` converted and validated, or an :class:`InputError` naming the solver."""
        where = f"solver {solver!r}: {self.name}"
        if value is None:
            if self.nullable or self.default is None:
                return None
            raise InputError(f"{where} may not be None")
        if self.convert is not None:
            try:
                return self.convert(value)
            except InputError as e:  # converters say "must be ...": the name goes first
                raise InputError(f"{where} {e}") from None
        if self.kind is bool:
            if isinstance(value, bool | np.bool_):
                return bool(value)
            if isinstance(value, str) and value.lower() in ("true", "false", "1", "0"):
                return value.lower() in ("true", "1")
            raise InputError(f"{where} must be true or false, not {value!r}")
        if self.kind in (int, float):
            if isinstance(value, bool) or not isinstance(value, int | float | np.number | str):
                raise InputError(f"{where} must be a number, not {value!r}")
            try:
                num = self.kind(value)
            except (TypeError, ValueError):
                raise InputError(f"{where} must be a number, not {value!r}") from None
            if self.kind is int and float(value) != num:
                raise InputError(f"{where} must be a whole number, not {value!r}")
            if self.minimum is not None and num < self.minimum:
                raise InputError(f"{where} must be at least {self.minimum:g}, not {value!r}")
            return num
        if self.kind is str:
            if not isinstance(value, str):
                raise InputError(f"{where} must be a string, not {value!r}")
            if self.values is not None:
                kind = "scan:AXES" if value.startswith("scan:") else value
                if kind not in self.values:
                    raise InputError(
                        f"{where} must be one of {', '.join(self.values)}, not {value!r}"
                    )
            return value
        return value

    def describe(self) -> str:
        """``name=default (a|b|c): doc`` for help texts and the README."""
        vals = f" ({'|'.join(self.values)})" if self.values else ""
        return f"{self.name}={self.default!r}{vals}: {self.doc}"


def _check_order_value(allowed: tuple[str, ...]) -> Callable[[Any], str]:
    def conv(value: Any) -> str:
        if not isinstance(value, str):
            raise InputError(f"must be a string such as 'scanline', not {value!r}")
        try:
            return check_order(value, allowed)
        except InputError as e:
            raise InputError(str(e).removeprefix("order ")) from None

    return conv


def order_option(
    orders: tuple[str, ...] = ORDERS, default: str = "scanline", doc: str | None = None
) -> Option:
    """The shared ``order`` option restricted to the order kinds a solver supports
    (:data:`csplab.engine.alg31.ORDERS`, plus solver-specific ones such as ``min-domain``)."""
    return Option(
        "order", str, default,
        doc or "cell order: scanline (thesis), random, min-entropy (WFC), min-domain (WFC's "
        "MRV), scan:AXES (scan:yx)",
        values=orders, convert=_check_order_value(orders),
    )  # fmt: skip


CHOICE = Option(
    "choice", str, "uniform",
    "label choice: uniform over the candidates (thesis), weighted by label frequencies, or "
    "resemblance to the example (2007 paper Eq. 2-6)",
    values=CHOICES,
)  # fmt: skip

WINDOW = Option(
    "window", int, 1, "choice=resemblance: windows of 2w+1 cells per axis (2007 paper Eq. 2)",
    minimum=0,
)  # fmt: skip


def positive_seconds(value: Any) -> float:
    """``value`` as a time limit: a positive finite number of seconds (0, negative numbers
    and ``nan`` are an :class:`InputError`)."""
    try:
        num = float(value)
    except (TypeError, ValueError):
        num = math.nan
    # a subnormal float (below ~2.2e-308) is no time a clock can measure: refused as 0 is
    if isinstance(value, bool) or not math.isfinite(num) or num < sys.float_info.min:
        raise InputError(f"must be a positive number of seconds, not {value!r}")
    return num


TIME_LIMIT = Option(
    "time_limit", float, None, "seconds for the whole call; status timeout when exceeded",
    nullable=True, convert=positive_seconds,
)  # fmt: skip

# One name per concept for Result.stats, whichever path emits it: a solver, solve() itself or
# continuous synthesis (the conformance suite checks every key, see unknown_stats).
STATS: dict[str, str] = {
    "order": "the cell order used",
    "choice": "the label choice used",
    "assigned": "cells assigned by the algorithm's own choices",
    "revisions": "arc-consistency revisions (queue pops of the AC engine)",
    "removals": "labels removed by arc consistency",
    "fail_cell": "coordinates of the cell whose domain emptied",
    "proof": "why the status is unsat (a wipe-out before any choice, a refutation by ...)",
    "violations": "violated constraints of the returned grid (0 when solved)",
    "broken": "global constraints the grid of a failed run breaks (csplab.constraints)",
    "constraint_clauses": "clauses of the global constraints (csplab.constraints)",
    "constraint_rules": "rules of the global constraints in the answer-set program "
    "(asp: reachability, cardinality)",
    "cuts": "connectivity cuts added lazily (csplab.constraints.Connected)",
    "connectivity_propagations": "cells excluded by the SAT search's connectivity propagator",
    "constraint_prunings": "search steps where a global-constraint propagator removed labels",
    "constraint_conflicts": "decisions refuted by a global-constraint propagator",
    "constraint_probes": "Alg. 3.1 choices refuted by arc consistency or a global-constraint "
    "propagator and withdrawn (the label leaves the cell's catalog, the cell chooses again)",
    "final_violations": "violations of the final grid (modify in blocks)",
    "energy": "soft-constraint energy E(M) of the returned grid (csplab.soft)",
    "breaches": "excess of the global constraints in the returned grid (0: all hold; blocks)",
    "energies": "energy after each sweep, the first entry before any (modify in blocks)",
    "metropolis_rejected": "consistent blocks rejected by the Metropolis test",
    "temperature": "Metropolis temperature at the first sweep",
    "cooling": "factor applied to the temperature after each sweep",
    "window": "resemblance window half-width (2007 paper Eq. 2)",
    "blocks_tried": "blocks attempted (Alg. 3.4)",
    "slab_problems": "slab problems the streamed sweep built (blocks.stream_blocks)",
    "blocks_accepted": "blocks whose new labels were kept (Alg. 3.4)",
    "acceptance_rate": "blocks_accepted / blocks_tried",
    "retries": "extra Alg. 3.1 runs after a failure",
    "attempts": "runs of the solver with restarts (solve(..., restarts=N))",
    "attempt_seed": "the seed that reproduces the returned attempt alone",
    "fallback": "the exact solver run after the incomplete one gave up (solve(fallback=...))",
    "fallback_from": "the incomplete solver that gave up before the fallback produced the result",
    "gave_up_s": "seconds the incomplete solver ran (all its attempts) before the fallback",
    "reason": "why an incomplete solver gave up without running (e.g. no starting model)",
    "exact": "the exact solver completing blocks whose retries all fail (modify in blocks)",
    "exact_blocks": "blocks completed by the exact solver after all their retries failed",
    "exact_refuted": "blocks the exact solver proved to have no labels fitting their border",
    "sweeps": "passes over the blocks",
    "init": "how the starting model of modify-in-blocks was built",
    "block": "block size used",
    "nodes": "search nodes",
    "conflicts": "conflicts (search dead ends)",
    "restarts": "search restarts",
    "decisions": "search decisions",
    "propagations": "propagated literals or domain changes",
    "sat_calls": "calls of a SAT or ASP solver",
    "rejected": "labels found outside C* by a SAT call",
    "repairs": "failed Alg. 3.1 runs repaired from C* (hybrid)",
    "alg31_runs": "runs of Alg. 3.1 (hybrid)",
    "fixed_by_repair": "cells fixed by repairs before the final run (hybrid)",
    "backend": "the backend solver",
    "encoding": "the CNF encoding",
    "supports": "support clauses in both directions or forward only",
    "amo": "the at-most-one encoding",
    "loader": "how clauses reached the SAT solver",
    "vars": "variables of the encoding",
    "clauses": "clauses of the encoding",
    "literals": "literals of the encoding",
    "x_vars": "cell-label variables of the encoding",
    "aux_vars": "auxiliary variables of the encoding (at-most-one)",
    "support_clauses": "support clauses of the encoding",
    "alo_clauses": "at-least-one clauses of the encoding",
    "amo_clauses": "at-most-one clauses of the encoding",
    "conflict_clauses": "conflict clauses of the direct encoding",
    "empty_clause": "arc consistency wiped out before encoding (the CNF is the empty clause)",
    "ac_s": "seconds spent on arc consistency before encoding",
    "refinements": "lazy at-most-one refinements",
    "encode_s": "seconds spent encoding",
    "load_s": "seconds spent loading clauses into the solver",
    "ground_s": "seconds spent grounding (ASP)",
    "build_s": "seconds spent building the model (CP-SAT)",
    "solve_s": "seconds spent searching",
    "free_s": "seconds spent freeing the solver",
    "model": "the model flavour (CP-SAT)",
    "diversity": "how outputs are diversified across seeds",
    "hint": "where the solver started: a seeded Alg. 3.1 solution (catalog solution; cpsat's "
    "hint, sat's choice=catalog phases, asp's diversity=catalog labels) or, when it fails, "
    "random or uniform labels; sat's \"catalog solution (refuted)\": the solution broke a "
    "constraint and the search went on from its phases",
    "hint_s": "seconds spent finding the hint, a seeded Alg. 3.1 solution",
    "probe_conflicts": "conflicts of sat's short attempt from uniform phases before the "
    "hint (choice=auto under global constraints)",
    "sat": "figures of the SAT oracle used (a dict with these names)",
    "atoms": "ground atoms (ASP)",
    "rules": "ground rules (ASP)",
    "choices": "choices (ASP)",
    "solver_status": "the backend's own status name",
    "solver_stats": "the backend's own statistics (a dict, backend names)",
    "limit": "the limit that ended a timeout: time or nodes (backtrack)",
    "restart": "failures before the first Luby restart, 0: never (backtrack)",
    "num_workers": "search workers (CP-SAT)",
    "presolve": "whether CP-SAT's presolve was on",
    "setup_estimate_s": "estimated seconds of CP-SAT's set-up that did not fit in the time left",
    "grounding": "who grounded the program: csplab (aspif) or gringo (ASP)",
    "workers": "0: the thesis' sweep; N: the wave schedule on N workers (blocks)",
    "scheduler": "where the waves ran: local or a Dask scheduler address (blocks)",
    "rounds": "solve rounds of the exact connectivity cut loop (continuous synthesis in 3D)",
    "constraint_attempts": "synthesis runs made while the output broke a user constraint "
    "(continuous synthesis in 3D with restarts)",
}

#: stats whose value is a dict that uses the names of :data:`STATS` too
_NESTED_STATS = ("sat",)


def unknown_stats(stats: Mapping[str, Any]) -> list[str]:
    """The keys of ``stats`` that :data:`STATS` does not name (a nested dict of
    :data:`STATS` names such as ``stats["sat"]`` is checked too, as ``"sat.KEY"``).

    Examples
    --------
    >>> unknown_stats({"assigned": 3, "sat": {"vars": 9, "speed": 1}, "mood": "good"})
    ['mood', 'sat.speed']
    """
    out = [k for k in stats if k not in STATS]
    for k in _NESTED_STATS:
        sub = stats.get(k)
        if isinstance(sub, Mapping):
            out += [f"{k}.{kk}" for kk in sub if kk not in STATS]
    return sorted(out)


@dataclass(frozen=True)
class Call:
    """What :meth:`Solver.run` gets: the randomness (``rng``, and the ``seed`` it was made
    from, recorded in the result), the backend, every declared option validated, and the
    start time ``t0``. The time limit is the call's: a solver watches :attr:`deadline`
    (or :meth:`remaining`, :meth:`expired`), never a clock of its own, and
    :meth:`Solver.result` measures the time from ``t0``."""

    rng: np.random.Generator
    seed: int | None
    backend: str | None
    options: Mapping[str, Any]
    t0: float = field(default_factory=time.perf_counter)

    def __getitem__(self, name: str) -> Any:
        return self.options[name]

    def get(self, *names: str) -> tuple[Any, ...]:
        """The values of several options, in the order named."""
        return tuple(self.options[n] for n in names)

    @property
    def deadline(self) -> float | None:
        """``time.perf_counter()`` value of the time limit (``None``: no limit)."""
        limit = self.options.get("time_limit")
        return None if limit is None else self.t0 + float(limit)

    def remaining(self) -> float | None:
        """Seconds left before :attr:`deadline` (at most 0 once it has passed; ``None``: no
        limit). Hand it to an engine that takes a ``time_limit``."""
        deadline = self.deadline
        return None if deadline is None else deadline - time.perf_counter()

    def expired(self) -> bool:
        """Whether :attr:`deadline` has passed."""
        deadline = self.deadline
        return deadline is not None and time.perf_counter() > deadline


class Solver(ABC):
    """Base class of every solver (see the module docstring)."""

    name: ClassVar[str]
    complete: ClassVar[bool]
    description: ClassVar[str]
    notes: ClassVar[str] = ""
    requires: ClassVar[tuple[str, ...]] = ()
    options: ClassVar[tuple[Option, ...]] = (TIME_LIMIT,)
    backends: ClassVar[Callable[[], list[str]] | None] = None
    bench: ClassVar[tuple[dict[str, Any], ...]] = ({},)
    alg31: ClassVar[bool] = False
    constraints: ClassVar[Literal["exact", "propagated", "checked"]] = "checked"

    @classmethod
    def option(cls, name: str) -> Option | None:
        """The declaration of option ``name``.

        Parameters
        ----------
        name : str
            An option name such as ``"order"`` or ``"time_limit"``.

        Returns
        -------
        Option or None
            The declaration, or ``None`` if the solver has no such option (so
            ``option(name) is not None`` asks whether the solver takes it).
        """
        return next((o for o in cls.options if o.name == name), None)

    @classmethod
    def validate(cls, options: Mapping[str, Any], backend: str | None = None) -> dict[str, Any]:
        """Every declared option, converted and checked, defaults filled in.

        Parameters
        ----------
        options : mapping
            Option values by name (strings from the command line are converted).
        backend : str, optional
            The backend of a ``name:backend`` solver spec, if any.

        Returns
        -------
        dict
            One entry per declared option, in declaration order.

        Raises
        ------
        InputError
            When a backend is given to a solver without backends, an option is unknown
            (the message lists the known ones) or a value is invalid (the message names
            the solver and the option).
        """
        if backend is not None and cls.backends is None:
            raise InputError(f"solver {cls.name!r} has no backends (got {backend!r})")
        known = {o.name for o in cls.options}
        unknown = [k for k in options if k not in known]
        if unknown:
            raise InputError(
                f"unknown option(s) for solver {cls.name!r}: {', '.join(unknown)}; "
                f"it takes {', '.join(sorted(known)) or 'none'}"
            )
        return {
            o.name: o.check(options[o.name], cls.name) if o.name in options else o.default
            for o in cls.options
        }

    def solve(
        self,
        problem: Problem,
        *,
        rng: np.random.Generator,
        seed: int | None,
        backend: str | None = None,
        **options: Any,
    ) -> Result:
        """Validate ``options`` against the declaration, then :meth:`run`.

        Parameters
        ----------
        problem : Problem
            The problem to solve.
        rng : numpy.random.Generator
            The randomness of the run.
        seed : int or None
            The seed ``rng`` was made from, recorded in the result.
        backend : str, optional
            The backend of a ``name:backend`` solver spec, if any.
        **options
            The solver's declared options (:attr:`options`).

        Returns
        -------
        Result
            The solver's result (``solved``, ``failed``, ``unsat`` or ``timeout``).

        Raises
        ------
        InputError
            When an option or the backend is invalid (see :meth:`validate`).
        """
        call = Call(rng, seed, backend, self.validate(options, backend))
        return self.run(problem, call)

    @abstractmethod
    def run(self, problem: Problem, call: Call) -> Result:
        """Solve ``problem``; every exit returns :meth:`result`.

        Parameters
        ----------
        problem : Problem
            The problem to solve.
        call : Call
            The randomness, the backend, every declared option (validated) and the
            deadline.

        Returns
        -------
        Result
            The outcome, made by :meth:`result`.
        """

    def result(
        self,
        status: Status,
        grid: ArrayLike | None,
        problem: Problem,
        stats: dict[str, Any],
        call: Call,
        *,
        proof: str | None = None,
        trace: NDArray[np.int64] | None = None,
    ) -> Result:
        """The one way out of :meth:`run`: a :class:`Result` of this solver.

        Parameters
        ----------
        status : {"solved", "failed", "unsat", "timeout"}
            The outcome.
        grid : array_like or None
            The labels (reshaped to the problem's shape, as int32); ``None``: no cell
            assigned (every label ``-1``).
        problem : Problem
            The problem solved.
        stats : dict
            The figures of the run, named as in :data:`STATS` (kept by reference, so a
            ``finally`` clause may still add to them).
        call : Call
            The call being answered: the time is measured from ``call.t0`` and the seed
            recorded.
        proof : str, optional
            Why the status is ``unsat``; stored as ``stats["proof"]``. An ``unsat`` result
            without a proof is a bug (:class:`~csplab.errors.CsplabError`).
        trace : int array ``(steps, 2)``, optional
            The ``(cell, label)`` choices of an Alg. 3.1 run.

        Returns
        -------
        Result
            The result of this solver, its time measured from ``call.t0``.

        Raises
        ------
        CsplabError
            When ``status`` is ``"unsat"`` without a proof (a bug of the solver).
        """
        if proof is not None:
            stats["proof"] = proof
        if status == "unsat" and not stats.get("proof"):
            raise CsplabError(f"solver {self.name!r} returned unsat without a proof (a bug)")
        if grid is None:
            g = np.full(problem.shape, -1, dtype=np.int32)
        else:
            g = np.asarray(grid, dtype=np.int32).reshape(problem.shape)
        return Result(status, g, self.name, seed=call.seed,
                      time_s=time.perf_counter() - call.t0, stats=stats, trace=trace)  # fmt: skip
