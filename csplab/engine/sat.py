"""The incremental SAT oracle: one :class:`SatOracle` per :class:`~csplab.problem.Problem`.

:class:`SatOracle` is the engine behind the ``sat``, ``perfect`` and ``hybrid`` solvers, the
exact catalog C* (:mod:`csplab.exact`), UNSAT explanations, counting by enumeration and
every completability question (:mod:`csplab.engine.completability`): it loads an
:class:`~csplab.cnf.Encoding` once, then answers queries under assumptions, refines the lazy
at-most-one constraints, honours deadlines and reports cores. Backends are pysat solvers
(:func:`backends`; pysat's aliases such as ``g4`` work too); python-sat is imported through
:func:`csplab.deps.require`, so its absence is one line naming the ``sat`` extra.

Loading millions of clauses through pysat's Python API costs several microseconds per
clause (Python lists, one call per clause). For the CaDiCaL backends the oracle instead
feeds the flat clause array to ``CaDiCaL::Solver::add`` from a compiled loop (ctypes symbol
of pysat's own extension module, called from numba), after ``reserve``-ing the variables;
measured at 40×40×10 (castle, 5.5M clauses, loaded 2-core machine): 3.7 s instead of 17 s.
What remains is CaDiCaL's own per-clause work (allocation, watches). Any failure to find
the symbols falls back to the API, and ``loader="api"`` forces it; both paths give the
solver the same clauses in the same order (a property test compares their models).

Examples
--------
>>> from csplab import ExampleModel, from_example
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 4))
>>> len(list(enumerate_solutions(P)))
2
"""

from __future__ import annotations

import ctypes
import itertools
import threading
import time
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab._closing import Closing
from csplab._jit import njit
from csplab.cnf import DeadlineExceeded, Encoding, amo_clauses, encode
from csplab.constraints import ClauseContext, constraint_clauses
from csplab.deps import require
from csplab.errors import InputError
from csplab.problem import Problem

__all__ = [
    "DEFAULT_BACKEND",
    "SAT_STAT_KEYS",
    "SatOracle",
    "backends",
    "enumerate_solutions",
    "free_at_exit",
    "preferred_labels",
]

DEFAULT_BACKEND = "cadical195"
# the oracle figures the sat-based solvers report under stats["sat"]
SAT_STAT_KEYS = ("backend", "vars", "clauses", "encode_s", "load_s", "solve_s", "sat_calls")

# canonical pysat names csplab supports (each tested by the conformance suite)
_SUPPORTED = (
    "cadical195",
    "cadical153",
    "cadical300",
    "glucose3",
    "glucose4",
    "glucose42",
    "gluecard3",
    "gluecard4",
    "maplechrono",
    "maplecm",
    "maplesat",
    "mergesat3",
    "minicard",
    "minisat22",
    "minisatgh",
    "minisatep",
    "lingeling",
)
_PYSAT_NAME = {"minisatgh": "mgh"}  # only reachable through an alias
_NOT_SUPPORTED = {
    "kissat404": "kissat404 is non-incremental in pysat (no assumptions, no phases, no "
    "time limit) and aborts the process when reused",
    "cadical103": "cadical103 cannot set decision phases, so its outputs would not vary "
    "with the seed; use cadical153, cadical195 or cadical300",
    "cryptosat": "cryptosat needs the pycryptosat package and has no phases or budgets in pysat",
}
_NO_LIMIT = ("lingeling",)  # no conflict budget and no interrupt in pysat

# Freeing a native solver of millions of clauses takes about as long as loading them
# (CaDiCaL frees each clause; 0.5 s at 40x40x10 castle). A command that exits right after
# its one solve leaves large solvers to the operating system instead (free_at_exit).
_EXIT_MIN_LITERALS = 1_000_000  # smaller solvers are freed as usual
_EXIT_MAX_LITERALS = 20_000_000  # at most this many literals per process are left unfreed
_EXIT = {"on": 0, "left": 0}


def free_at_exit(on: bool = True) -> None:
    """Leave large native solvers to the process exit instead of freeing them on ``close``.

    For commands that end right after their solve (``csplab synthesize``): the operating
    system reclaims the memory at once, where CaDiCaL's destructor frees clause by clause
    (0.5 s at 40×40×10 castle). Only solvers of at least 10**6 literals are left, and at most
    2·10**7 literals per process (then they are freed as usual), so a command that builds many
    oracles cannot grow without bound. Off by default: library callers get every solver freed
    by :meth:`SatOracle.close`. Results are unaffected: the solver is left only after its
    answer has been read.

    Parameters
    ----------
    on : bool
        Switch the behaviour on (default) or off.

    Examples
    --------
    >>> free_at_exit(False)      # the default: close() frees the native solver
    """
    _EXIT["on"] = int(bool(on))


def backends() -> list[str]:
    """The pysat backends the ``sat`` solver accepts (``sat:NAME``)."""
    return list(_SUPPORTED)


def _canonical(backend: str | None) -> str:
    if backend is None:
        return DEFAULT_BACKEND
    SolverNames = require("pysat.solvers", "sat", "the SAT oracle").SolverNames
    key = backend.lower()
    for canon, aliases in vars(SolverNames).items():
        if canon.startswith("_") or not isinstance(aliases, tuple):
            continue
        if key == canon or key in aliases:
            if canon in _NOT_SUPPORTED:
                raise InputError(f"sat backend {canon!r} is not supported: {_NOT_SUPPORTED[canon]}")
            if canon in _SUPPORTED:
                return str(canon)
    raise InputError(f"unknown sat backend {backend!r}; available: {', '.join(_SUPPORTED)}")


# ----------------------------------------------------------------------------- fast loader


def _is_interrupt(e: BaseException) -> bool:
    """Whether ``e`` is pysat's report of a Ctrl-C inside the native solver
    (``pysolvers.error: Caught keyboard interrupt``).

    Examples
    --------
    >>> _is_interrupt(RuntimeError("Caught keyboard interrupt")), _is_interrupt(ValueError("x"))
    (True, False)
    """
    return "keyboard interrupt" in str(e).lower()


@njit(cache=True)
def _feed_clauses(fn: Any, ptr: int, lits: np.ndarray, starts: np.ndarray, a: int, b: int) -> None:
    """``add(lit) ... add(0)`` for clauses ``a..b-1`` (CaDiCaL's IPASIR-style API)."""
    for i in range(a, b):
        for j in range(starts[i], starts[i + 1]):
            fn(ptr, lits[j])
        fn(ptr, 0)


@njit(cache=True)
def _feed_literals(fn: Any, ptr: int, lits: np.ndarray) -> None:
    for i in range(lits.size):
        fn(ptr, lits[i])


@njit(cache=True)
def _read_values(fn: Any, ptr: int, nvars: int, out: np.ndarray) -> None:
    for v in range(1, nvars + 1):
        out[v] = fn(ptr, v) > 0


_VOID_INT = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_int)
_INT_INT = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_int)
_FAST_CACHE: dict[str, tuple[Any, Any, Any, Any] | None] = {}


def _cadical_functions(backend: str) -> tuple[Any, Any, Any, Any] | None:
    """ctypes ``add``, ``phase``, ``val`` and ``reserve`` of CaDiCaL in pysat's extension
    module (``val``/``reserve`` may be None), or None when the symbols are not there."""
    if backend in _FAST_CACHE:
        return _FAST_CACHE[backend]
    tag = {"cadical153": "1536", "cadical195": "1956", "cadical300": "3006"}.get(backend)
    found = None
    if tag is not None:
        try:
            import pysolvers  # type: ignore[import-not-found]

            lib = ctypes.CDLL(pysolvers.__file__)

            def address(method: str) -> int:
                a = ctypes.cast(getattr(lib, f"_ZN10CaDiCaL{tag}Solver{method}"), ctypes.c_void_p)
                if not a.value:
                    raise AttributeError(method)
                return int(a.value)

            add = _VOID_INT(address("3addEi"))
            phase = _VOID_INT(address("5phaseEi"))
            val = None
            if hasattr(lib, f"_ZN10CaDiCaL{tag}Solver3valEi"):
                val = _INT_INT(address("3valEi"))
            reserve = getattr(lib, f"_ZN10CaDiCaL{tag}Solver7reserveEi", None)
            if reserve is not None:
                reserve.argtypes = [ctypes.c_void_p, ctypes.c_int]
                reserve.restype = None
            found = (add, phase, val, reserve)
        except (OSError, AttributeError, ImportError):
            found = None
    _FAST_CACHE[backend] = found
    return found


def _capsule_pointer(capsule: Any) -> int | None:
    try:
        get = ctypes.pythonapi.PyCapsule_GetPointer
        get.restype = ctypes.c_void_p
        get.argtypes = [ctypes.py_object, ctypes.c_char_p]
        p = get(capsule, None)
        return int(p) if p else None
    except (ValueError, TypeError, AttributeError):
        return None


# ----------------------------------------------------------------------------- oracle


class _Timeout(Exception):
    """Raised inside the oracle when its deadline passes."""


class SatOracle(Closing):
    """An incremental SAT engine for one :class:`Problem` (see the module docstring).

    Parameters
    ----------
    problem : Problem
    backend : str, optional
        pysat solver name (default ``cadical195``).
    encoding, supports, amo : str
        Passed to :func:`csplab.cnf.encode`.
    domains : bool array, optional
        Encode these domains instead of the problem's (then add the rest as clauses).
    loader : {"auto", "api"}
    deadline : float, optional
        ``time.perf_counter()`` value after which loading stops (``timed_out`` is set).
    seed : int, optional
        Seeds the backend where it has a seed option (CaDiCaL).

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> P = from_example(ExampleModel([0, 1, 2, 0]), (7,))
    >>> o = SatOracle(P)
    >>> o.solve([o.literal(0, 1)]), o.grid.tolist()     # cell 0 = 1 under an assumption
    ('sat', [1, 2, 0, 1, 2, 0, 1])
    >>> o.solve([o.literal(0, 1), o.literal(3, 0)])     # then cell 3 can only be 1
    'unsat'
    >>> len(o.core()) >= 1
    True
    """

    def __init__(
        self,
        problem: Problem,
        *,
        backend: str | None = None,
        encoding: str = "support",
        supports: str = "both",
        amo: str = "lazy",
        domains: Any = None,
        loader: str = "auto",
        deadline: float | None = None,
        seed: int | None = None,
    ) -> None:
        Solver = require("pysat.solvers", "sat", "the SAT oracle").Solver
        if loader not in ("auto", "api"):
            raise InputError(f"loader must be 'auto' or 'api', not {loader!r}")
        self.backend = _canonical(backend)
        if deadline is not None and self.backend in _NO_LIMIT:
            raise InputError(f"sat backend {self.backend!r} cannot honour a time limit")
        self.problem = problem
        self.timed_out = False
        try:
            self.enc: Encoding = encode(problem, encoding=encoding,  # type: ignore[arg-type]
                                        supports=supports, amo=amo, domains=domains,  # type: ignore[arg-type]
                                        deadline=deadline)  # fmt: skip
        except DeadlineExceeded:
            self.timed_out = True
            self.enc = encode(Problem((1,), [[True]], [[[True]]], []))  # a trivial stand-in
        self.top = self.enc.nvars
        self.cons: ClauseContext | None = None
        self._prop: Any = None
        self.stats: dict[str, Any] = dict(self.enc.stats)
        self.stats.update(backend=self.backend, refinements=0, sat_calls=0, solve_s=0.0)
        self.grid: NDArray[np.int32] | None = None
        self._amo_done = np.zeros(problem.n, dtype=bool)
        self._fast: tuple[Any, Any, Any, Any] | None = None
        self._ptr: int = 0
        self._last_core: list[int] | None = None
        self.solver = Solver(name=_PYSAT_NAME.get(self.backend, self.backend))
        if self.backend.startswith("cadical") and seed is not None:
            self.solver.solver.configure({"seed": int(seed) % (2**31 - 1)})
        if loader == "auto" and self.backend.startswith("cadical"):
            fns = _cadical_functions(self.backend)
            ptr = _capsule_pointer(self.solver.solver.cadical) if fns is not None else None
            if fns is not None and ptr is not None:
                self._fast, self._ptr = fns, ptr
                if fns[3] is not None and self.enc.nvars > 0:
                    fns[3](ptr, int(self.enc.nvars))  # allocate the variables at once
        self.stats["loader"] = "cadical-direct" if self._fast else "pysat-api"
        t0 = time.perf_counter()
        if not self.enc.ok:
            self.solver.add_clause([])  # the empty clause: arc consistency wiped out
        elif not self.timed_out:
            self._load(self.enc.lits, self.enc.starts, deadline)
        # global constraints (csplab.constraints): their clauses, and cuts in solve()
        if problem.constraints and self.enc.ok and not self.timed_out:
            self.cons = constraint_clauses(problem, self.enc.literal, self.top)
            self.stats["constraint_clauses"] = len(self.cons.clauses)
            self.stats["cuts"] = 0
            if self.backend == "cadical195":  # connectivity inside the search (IPASIR-UP)
                from csplab.engine.connectivity import attach

                self._prop = attach(self.solver, problem, self.cons)
            self._flush()
        self.stats["load_s"] = time.perf_counter() - t0
        self.stats["vars"] = self.top
        self.stats["clauses"] = self.enc.nclauses + len(self.cons.clauses if self.cons else ())

    # ------------------------------------------------------------------ building
    def _load(
        self, lits: NDArray[np.int32], starts: NDArray[np.int64], deadline: float | None = None
    ) -> None:
        nc = starts.size - 1
        chunk = max(nc, 1)
        if deadline is not None:
            chunk = 100_000 if self._fast is not None else 20_000
        for a in range(0, nc, chunk):
            if deadline is not None and time.perf_counter() > deadline:
                self.timed_out = True
                return
            b = min(nc, a + chunk)
            if self._fast is not None:
                _feed_clauses(self._fast[0], self._ptr, lits, starts, a, b)
            else:
                lo, hi = int(starts[a]), int(starts[b])
                sub = lits[lo:hi].tolist()
                st = (starts[a : b + 1] - lo).tolist()
                self.solver.append_formula([sub[i:j] for i, j in itertools.pairwise(st)])

    def _flush(self) -> None:
        """Load the constraint clauses not loaded yet."""
        ctx = self.cons
        if ctx is None:
            return
        done = getattr(self, "_cons_done", 0)
        new = ctx.clauses[done:]
        self._cons_done = len(ctx.clauses)
        self.top = max(self.top, ctx.top)
        if not new:
            return
        lengths = np.array([len(c) for c in new], dtype=np.int64)
        if (lengths == 0).any():
            self.solver.add_clause([])
            return
        self.add_clauses(np.fromiter(itertools.chain.from_iterable(new), np.int32), lengths)

    def add_clause(self, clause: Sequence[int]) -> None:
        """Add one clause (Python ints)."""
        if not self.timed_out:
            self.solver.add_clause([int(x) for x in clause])

    def add_clauses(self, lits: NDArray[np.int32], lengths: NDArray[np.int64]) -> None:
        """Add clauses given flat (``lits`` and per-clause lengths)."""
        starts = np.zeros(lengths.size + 1, dtype=np.int64)
        np.cumsum(lengths, out=starts[1:])
        self._load(np.ascontiguousarray(lits, dtype=np.int32), starts)

    def new_var(self) -> int:
        """A fresh variable (e.g. a selector for assumptions)."""
        self.top += 1
        if self.cons is not None:
            self.cons.top = self.top
        return self.top

    def add_amo(self, cells: NDArray[np.int64]) -> None:
        """At-most-one for ``cells`` (lazy refinement; each cell at most once)."""
        cells = np.asarray(cells, dtype=np.int64)
        cells = cells[~self._amo_done[cells]]
        if cells.size == 0:
            return
        self._amo_done[cells] = True
        has = self.enc.var > 0
        enc = "seqcounter"
        lits, lens, self.top = amo_clauses(self.enc.var, has, enc, self.top, cells=cells)
        if self.cons is not None:
            self.cons.top = self.top
        if lens.size:
            self.add_clauses(lits, lens)

    # ------------------------------------------------------------------ queries
    def literal(self, cell: int, label: int) -> int:
        """The literal of ``cell = label``; constants map to a fresh true/false variable."""
        if self.timed_out:  # nothing is loaded; any variable will do
            return self.new_var()
        lit = self.enc.literal(cell, label)
        if isinstance(lit, bool):
            key = ("const", lit)
            cached = getattr(self, "_const_vars", {})
            if key not in cached:
                v = self.new_var()
                self.add_clause([v if lit else -v])
                cached[key] = v
                self._const_vars = cached
            return int(cached[key])
        return lit

    def set_phases(self, preferred: NDArray[np.integer[Any]]) -> None:
        """Prefer label ``preferred[v]`` at each cell (``-1``: no preference)."""
        if self.timed_out:
            return
        var = self.enc.var
        n = var.shape[0]
        pref = np.asarray(preferred, dtype=np.int64).reshape(-1)
        neg = -var[var > 0]
        ok = pref >= 0
        pv = np.zeros(n, dtype=np.int64)
        pv[ok] = var[np.flatnonzero(ok), pref[ok]]
        pos = pv[pv > 0]
        lits = np.concatenate([neg, pos]).astype(np.int32)
        if self._fast is not None:
            self.solver.solver.configure({"lucky": 0})
            # later phase() calls override earlier ones: preferred labels win
            _feed_literals(self._fast[1], self._ptr, lits)
        else:
            # pysat takes one literal per variable
            val = np.zeros(self.enc.nvars + 1, dtype=np.int8)
            val[var[var > 0]] = -1
            val[pos] = 1
            ids = np.flatnonzero(val[1 : self.enc.nx + 1]) + 1
            self.solver.set_phases((ids * val[ids]).tolist())

    def assignment(self, labels: NDArray[np.integer[Any]]) -> list[int]:
        """Assumptions that give each cell ``v`` the label ``labels[v]`` and no other: every
        label variable set, so :meth:`solve` under them confirms a whole solution found
        elsewhere by unit propagation alone, auxiliary variables included (a count's adder:
        given the labels only, the cells' other labels stay open under the lazy at-most-one
        and CaDiCaL, deciding the auxiliary variables first, ran 2,000 conflicts without an
        answer on City 40×40×10 with connectivity and a count; so set, 0)."""
        var = self.enc.var
        lab = np.asarray(labels, dtype=np.int64).reshape(-1)
        rows = np.arange(var.shape[0])
        pos = var[rows, lab]
        other = var > 0
        other[rows, lab] = False
        lits: list[int] = np.concatenate([pos[pos > 0], -var[other]]).tolist()
        return lits

    def _prefer(self, lits: Sequence[int]) -> None:
        """Decision phases for some literals (later calls override earlier ones)."""
        if not lits or self.timed_out:
            return
        arr = np.asarray(lits, dtype=np.int32)
        if self._fast is not None:
            _feed_literals(self._fast[1], self._ptr, arr)
        else:
            try:
                self.solver.set_phases(arr.tolist())
            except (NotImplementedError, AttributeError):
                pass

    def _raw(
        self, assumptions: list[int], deadline: float | None, conflicts: int | None = None
    ) -> bool | None:
        S = self.solver
        if conflicts is not None:
            # one call of at most that many conflicts: its answer does not depend on the
            # clock, except that the deadline interrupts it where the backend can be
            # interrupted (not CaDiCaL through pysat: it may overrun by the budget), and the
            # run's answer is then a timeout whatever the call would have found
            left = None if deadline is None else deadline - time.perf_counter()
            if (left is not None and left <= 0) or self.backend in _NO_LIMIT:
                return None
            timer = None
            if left is not None and not self.backend.startswith("cadical"):
                timer = threading.Timer(left, S.interrupt)
            S.conf_budget(int(conflicts))
            if timer is not None:
                timer.start()
            try:
                r = S.solve_limited(assumptions=assumptions, expect_interrupt=timer is not None)
            finally:
                if timer is not None:
                    timer.cancel()
                    S.clear_interrupt()
                # MiniSat's family keeps a budget for later calls (CaDiCaL forgets it): a
                # later call under the deadline would stop at once
                S.conf_budget(-1)
            return None if r is None else bool(r)
        if deadline is None:
            return bool(S.solve(assumptions=assumptions))
        if self.backend.startswith("cadical"):
            # with global constraints a conflict can cost milliseconds (CaDiCaL's inprocessing
            # rounds over millions of clauses, or its explanation of a propagator's whole
            # implication cone): a first budget of 2000 overran a 20 s limit by 47 s at city
            # 40x40x10; the budget grows from 100 towards 0.2 s per call instead
            budget = 2000 if self.cons is None else 100
            while True:
                left = deadline - time.perf_counter()
                if left <= 0:
                    return None
                S.conf_budget(budget)
                t = time.perf_counter()
                r = S.solve_limited(assumptions=assumptions)
                if r is not None:
                    return bool(r)
                took = max(time.perf_counter() - t, 1e-4)
                target = min(0.2, max(left / 4, 0.01))
                budget = int(min(max(budget * target / took, 50), 10**7))
        left = deadline - time.perf_counter()
        if left <= 0:
            return None
        timer = threading.Timer(left, S.interrupt)
        timer.start()
        try:
            r = S.solve_limited(assumptions=assumptions, expect_interrupt=True)
        finally:
            timer.cancel()
            S.clear_interrupt()
        return None if r is None else bool(r)

    def _model_truth(self) -> NDArray[np.bool_]:
        truth = np.zeros(self.top + 1, dtype=bool)
        if self._fast is not None and self._fast[2] is not None:
            _read_values(self._fast[2], self._ptr, self.enc.nx, truth)
            return truth
        m = np.asarray(self.solver.get_model() or [], dtype=np.int64)
        m = m[(m > 0) & (m <= self.top)]
        truth[m] = True
        return truth

    def solve(
        self,
        assumptions: Sequence[int] = (),
        deadline: float | None = None,
        conflicts: int | None = None,
    ) -> str:
        """``"sat"`` (``grid`` holds a solution), ``"unsat"`` (``core()`` explains it under
        the assumptions) or ``"timeout"``: the deadline passed or, with ``conflicts``, a
        backend call (one per refinement or cut) reached that many conflicts. Such a call's
        answer does not depend on the clock: the deadline interrupts it where the backend
        can be interrupted (CaDiCaL cannot: it may overrun the deadline by the budget), and
        the budget is cleared after it (MiniSat's family would keep it); backends without
        conflict budgets (lingeling) answer ``"timeout"`` at once."""
        if self.timed_out:
            return "timeout"
        assume = [int(a) for a in assumptions]
        t0 = time.perf_counter()
        try:
            while True:
                self.stats["sat_calls"] += 1
                try:
                    r = self._raw(assume, deadline, conflicts)
                except Exception as e:  # pysat turns Ctrl-C into pysolvers.error
                    if _is_interrupt(e):
                        raise KeyboardInterrupt from None
                    raise
                if r is None:
                    return "timeout"
                if not r:
                    self._last_core = [int(x) for x in (self.solver.get_core() or [])]
                    self.grid = None
                    return "unsat"
                grid, multi = self.enc.decode(self._model_truth())
                if multi.size == 0:
                    if self.cons is not None:
                        self.cons.top = max(self.cons.top, self.top)
                        k = self.cons.cuts(grid)
                        if k:  # a connectivity breach: cut it off and solve again
                            self.stats["cuts"] += k
                            self._flush()
                            self._prefer(self.cons.hints)
                            continue
                    self.grid = grid
                    return "sat"
                self.stats["refinements"] += 1
                self.add_amo(multi)
        finally:
            self.stats["solve_s"] += time.perf_counter() - t0

    def core(self) -> list[int]:
        """The failed assumptions of the last ``unsat`` answer (a subset, maybe all)."""
        return list(self._last_core or [])

    def block(self, grid: NDArray[np.integer[Any]]) -> bool:
        """Exclude ``grid`` from future models; ``False`` if nothing is left to vary."""
        if self.timed_out:
            return False
        var = self.enc.var
        g = np.asarray(grid).reshape(-1)
        free = np.flatnonzero(self.enc.const < 0)
        if free.size == 0:
            return False
        self.add_clause((-var[free, g[free]]).tolist())
        return True

    def constraint_stats(self) -> dict[str, Any]:
        """Figures of the global constraints' connectivity propagator (if attached)."""
        if self._prop is None:
            return {}
        return {"connectivity_propagations": int(self._prop.propagated)}

    def solver_stats(self) -> dict[str, Any]:
        try:
            st = self.solver.accum_stats() or {}
        except (NotImplementedError, AttributeError):
            st = {}
        return {k: int(v) for k, v in st.items()}

    def close(self) -> None:
        """Free the native solver (or leave it to the process exit: :func:`free_at_exit`)."""
        inner = getattr(self.solver, "solver", None)
        size = int(self.enc.lits.size)
        if (
            _EXIT["on"]
            and inner is not None
            and size >= _EXIT_MIN_LITERALS
            and _EXIT["left"] + size <= _EXIT_MAX_LITERALS
        ):
            # pysat's capsule has no destructor: with the backend's delete() a no-op the
            # native object is never freed in-process, the operating system reclaims it
            _EXIT["left"] += size
            inner.delete = _keep
            self.solver.solver = None
            return
        self.solver.delete()


def _keep() -> None:
    """Stands in for a backend's ``delete`` when its solver is left to the process exit."""


def preferred_labels(
    catalog: NDArray[np.bool_], weights: NDArray[np.float64] | None, rng: np.random.Generator
) -> NDArray[np.int64]:
    """One random label per cell from ``catalog`` (weighted if ``weights``: ``(K,)``, or
    ``(n, K)`` per cell; -1 if empty)."""
    n, K = catalog.shape
    w = np.ones(K) if weights is None else np.asarray(weights, dtype=np.float64)
    ww = catalog * (np.where(w > 0, w, 0.0)[None, :] if w.ndim == 1 else np.where(w > 0, w, 0.0))
    zero = ww.sum(axis=1) <= 0
    ww[zero] = catalog[zero]  # fall back to uniform when weights vanish
    cum = np.cumsum(ww, axis=1)
    u = rng.random(n) * cum[:, -1]
    pick = (cum <= u[:, None]).sum(axis=1)
    pick = np.minimum(pick, K - 1)
    pick[~catalog.any(axis=1)] = -1
    return np.asarray(pick, dtype=np.int64)


def enumerate_solutions(
    problem: Problem,
    *,
    limit: int | None = None,
    backend: str | None = None,
    amo: str = "lazy",
    encoding: str = "support",
) -> Iterator[NDArray[np.int32]]:
    """Every solution grid, each once, by SAT with blocking clauses.

    The blocking clause of a solution mentions only its ``x`` variables (not pysat's
    ``enum_models``, which blocks whole models: auxiliary variables of an at-most-one
    encoding could then repeat a grid).

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 4))
    >>> len(list(enumerate_solutions(P)))
    2
    """
    with SatOracle(problem, backend=backend, amo=amo, encoding=encoding) as o:
        found = 0
        while limit is None or found < limit:
            if o.solve() != "sat":
                return
            assert o.grid is not None
            g = o.grid.copy()
            found += 1
            yield g
            if not o.block(g):
                return
