"""The exact catalog C* (Eq. 3.4), the gap C \\ C*, and UNSAT explanations — by SAT.

``C*(x, b) = 1`` iff the partial model plus ``x = b`` can be completed to a consistent model.
Computing it is NP-hard (Theorems 3.3.4/3.3.5); the catalog C of Alg. 3.2 (arc
consistency) is a polynomial over-approximation: ``C* <= C`` (Theorem 3.3.2), and where
``C > C*`` Alg. 3.1 may pick a label that dooms the run (Fig. 3.5).

* :func:`exact_catalog` computes C* with one incremental SAT solver: the partial model is
  fixed by unit clauses, each model found marks all of its ``(cell, label)`` pairs as
  supported (solution sweeping, with decision phases steered towards unmarked pairs), and
  only unmarked pairs of C need their own call under an assumption.
* :func:`catalog_gap` replays a run of Alg. 3.1 and tells, at each step, whether the
  chosen label was in C* (one SAT call only when the label differs from the last witness
  solution), where the model first became inconsistent, and how many steps later the
  catalog emptied.
* :func:`is_consistent` asks the same completability oracle
  (:class:`~csplab.engine.completability.SatCompletability`) once.
* :func:`explain_unsat` finds a minimal set of the problem's unary restrictions (fixed
  cells, boundary faces, masks; :attr:`Problem.unary`) that is already unsatisfiable, from
  assumption cores and deletion-based minimisation.

Examples
--------
>>> import numpy as np
>>> from csplab import ExampleModel, from_example
>>> E = ExampleModel([[0, 1, 0, 1], [1, 0, 1, 0]])           # parity
>>> P = from_example(E, (3, 3))
>>> X = exact_catalog(P)
>>> bool(X.consistent), int(X.gap.sum())                     # 2x2 checkerboards only
(True, 0)
>>> Q = from_example(E, (3, 3), fixed={(0, 0): 0, (2, 0): 1})
>>> v = explain_unsat(Q)
>>> v.holds, v.witness["unary"]
(True, ['fixed cell (0, 0) = 0', 'fixed cell (2, 0) = 1'])
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.catalog import propagate
from csplab.engine.completability import PrefixTimeout, SatCompletability, catalog_at
from csplab.engine.sat import SatOracle, preferred_labels
from csplab.errors import InputError
from csplab.problem import Problem
from csplab.result import Verdict
from csplab.rng import RngLike, make_rng

__all__ = ["ExactCatalog", "catalog_gap", "exact_catalog", "explain_unsat", "is_consistent"]


@dataclass
class ExactCatalog:
    """C*, the arc-consistent catalog C and their difference, as ``bool (n, K)`` arrays.

    Attributes
    ----------
    exact : C* (Eq. 3.4); all ``False`` when the partial model cannot be completed.
    catalog : C, the catalog Alg. 3.1 would see (arc consistency after the partial model).
    gap : ``catalog & ~exact``: labels Alg. 3.1 may choose although they lead to failure.
    consistent : whether the partial model can be completed at all.
    complete : ``False`` if the time limit stopped the computation (then ``undecided``
        marks the pairs of C that were not settled and ``exact``/``gap`` are partial).
    stats : SAT calls, models found, time.
    """

    exact: NDArray[np.bool_]
    catalog: NDArray[np.bool_]
    gap: NDArray[np.bool_]
    consistent: bool
    complete: bool = True
    undecided: NDArray[np.bool_] | None = None
    stats: dict[str, Any] = field(default_factory=dict)


def _partial_array(problem: Problem, partial: ArrayLike | None) -> NDArray[np.int64]:
    if partial is None:
        return np.full(problem.n, -1, dtype=np.int64)
    g = np.asarray(partial)
    if g.shape != problem.shape and g.shape != (problem.n,):
        raise InputError(f"partial model has shape {g.shape}, the problem {problem.shape}")
    if not np.issubdtype(g.dtype, np.integer):
        raise InputError(f"partial model must hold integer labels (-1 = free), got {g.dtype}")
    flat = g.reshape(-1).astype(np.int64)
    if np.any(flat < -1) or np.any(flat >= problem.K):
        raise InputError(f"partial model labels must be -1 (free) or 0..{problem.K - 1}")
    return flat


def _fix(oracle: SatOracle, flat: NDArray[np.int64]) -> None:
    for c in np.flatnonzero(flat >= 0):
        oracle.add_clause([oracle.literal(int(c), int(flat[c]))])


def is_consistent(problem: Problem, partial: ArrayLike | None = None,
                  backend: str | None = None) -> bool:  # fmt: skip
    """Can ``partial`` (-1 = free) be completed to a solution? (Thesis Sec. 3.3.1.)

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
    >>> is_consistent(P, [[0, -1, -1], [-1, -1, -1], [-1, -1, 1]])
    False
    """
    flat = _partial_array(problem, partial)
    idx = np.flatnonzero(flat >= 0)
    with SatCompletability(problem, backend=backend) as o:
        return o.completable(idx, flat[idx]) is True


def exact_catalog(
    problem: Problem,
    partial: ArrayLike | None = None,
    *,
    backend: str | None = None,
    time_limit: float | None = None,
    rng: RngLike = 0,
) -> ExactCatalog:
    """C* for ``problem`` after the partial model ``partial`` (-1 = free; default: empty).

    Parameters
    ----------
    problem : Problem
    partial : int array of the problem's shape, optional
    backend : str, optional
        pysat backend (default ``cadical195``).
    time_limit : float, optional
        Seconds; on expiry the result has ``complete=False``.
    rng : int or Generator
        Steers the decision phases used for solution sweeping (the result does not depend
        on it, only the number of SAT calls).
    """
    t0 = time.perf_counter()
    deadline = None if time_limit is None else t0 + float(time_limit)
    gen, _ = make_rng(rng)
    flat = _partial_array(problem, partial)
    n, K = problem.n, problem.K
    dom = problem.domains.copy()
    assigned = flat >= 0
    ok_pre = bool(np.all(dom[np.flatnonzero(assigned), flat[assigned]]))
    dom[assigned] = False
    dom[np.flatnonzero(assigned), flat[assigned]] = True
    C, ok = propagate(problem, dom)
    if not (ok and ok_pre):
        C = np.zeros((n, K), dtype=bool) if not ok_pre else C
    stats: dict[str, Any] = {"sat_calls": 0, "models": 0}
    exact = np.zeros((n, K), dtype=bool)
    if not (ok and ok_pre):
        stats["time_s"] = time.perf_counter() - t0
        stats["proof"] = "arc-consistency wipe-out"
        return ExactCatalog(exact, C, C & ~exact, False, True, None, stats)
    with SatOracle(problem, backend=backend, deadline=deadline) as o:
        _fix(o, flat)
        todo = C.copy()
        idx = np.arange(n)

        def sweep(status: str) -> bool:
            stats["sat_calls"] += 1
            if status == "timeout":
                return False
            if status == "sat":
                assert o.grid is not None
                g = o.grid.reshape(-1)
                exact[idx, g] = True
                todo[idx, g] = False
                stats["models"] += 1
            return True

        o.set_phases(preferred_labels(todo, None, gen))
        first = o.solve(deadline=deadline)
        if not sweep(first):
            return _partial_result(exact, C, todo, stats, t0)
        if first == "unsat":
            stats["time_s"] = time.perf_counter() - t0
            stats["proof"] = f"refutation by {o.backend}"
            return ExactCatalog(exact, C, C.copy(), False, True, None, stats)
        pairs = np.argwhere(todo)
        for v, b in pairs:
            if not todo[v, b]:
                continue
            todo[v, b] = False
            if stats["sat_calls"] % 8 == 0:
                o.set_phases(preferred_labels(todo, None, gen))
            st = o.solve([o.literal(int(v), int(b))], deadline=deadline)
            if not sweep(st):
                todo[v, b] = True
                return _partial_result(exact, C, todo, stats, t0)
        stats["sat_stats"] = o.stats
    stats["time_s"] = time.perf_counter() - t0
    return ExactCatalog(exact, C, C & ~exact, True, True, None, stats)


def _partial_result(exact: NDArray[np.bool_], C: NDArray[np.bool_], todo: NDArray[np.bool_],
                    stats: dict[str, Any], t0: float) -> ExactCatalog:  # fmt: skip
    stats["time_s"] = time.perf_counter() - t0
    return ExactCatalog(exact, C, C & ~exact & ~todo, True, False, todo.copy(), stats)


# ----------------------------------------------------------------------------- Alg. 3.1 gap


def catalog_gap(
    problem: Problem,
    rng: RngLike = None,
    *,
    order: str = "scanline",
    choice: str = "uniform",
    backend: str | None = None,
    sizes: bool = False,
    time_limit: float | None = None,
) -> Verdict:
    """Run Alg. 3.1 and check each chosen label against C* (Eq. 3.4).

    ``holds`` is ``True`` when every chosen label was in C* (the run stayed completable),
    ``False`` when some label was in C but not in C* (the phenomenon of Fig. 3.5; the
    witness describes the first such step), ``None`` if the time limit stopped the check.
    ``stats["per_step"]`` lists, per step, ``[cell coords, label, in C*]`` (and with
    ``sizes=True`` also ``|C(p)|`` and ``|C*(p)|``, one SAT call per label of C(p)).

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (4, 4))
    >>> catalog_gap(P, rng=1).holds                # the checkerboard never goes wrong
    True
    """
    from csplab.engine.alg31 import run_alg31

    t0 = time.perf_counter()
    deadline = None if time_limit is None else t0 + float(time_limit)
    gen, seed = make_rng(rng)
    run = run_alg31(problem, gen, order=order, choice=choice)
    trace = run.trace if run.trace is not None else np.zeros((0, 2), dtype=np.int64)
    steps: list[list[Any]] = []
    stats: dict[str, Any] = {"seed": seed, "order": order, "choice": choice,
                             "alg31_status": run.status, "steps_taken": len(trace)}  # fmt: skip
    if run.status == "unsat":
        stats["time_s"] = time.perf_counter() - t0
        return Verdict(True, None, stats, "arc consistency proves the problem unsatisfiable; "
                       "Alg. 3.1 makes no choice")  # fmt: skip
    first_bad: dict[str, Any] | None = None
    consistent = True
    calls = 0
    # one oracle for the whole replay: each good step is fixed in it for good, so a query
    # only assumes the one label asked about
    with SatCompletability(problem, backend=backend, deadline=deadline) as o:
        status = o.completable([], [])
        calls += 1
        if status is None:
            return Verdict(None, None, {**stats, "sat_calls": calls}, "time limit")
        if not status:
            consistent = False
            stats["unsat"] = True
        witness = o.solution
        for t, (p, b) in enumerate(trace.tolist()):
            entry: list[Any] = [list(problem.coords(p)), int(b)]
            if not consistent:
                # M_t is inconsistent: C* is empty (Eq. 3.4)
                steps.append([*entry, False, *([None, 0] if sizes else [])])
                continue
            assert witness is not None
            inside: bool | None = bool(witness[p] == b)
            if not inside:
                inside = o.completable([p], [b])
                calls += 1
                if inside is None:
                    stats.update(sat_calls=calls, per_step=steps)
                    return Verdict(None, None, stats, "time limit")
                if inside:
                    witness = o.solution
            extra: list[Any] = []
            if sizes:
                assert witness is not None
                try:
                    C, star = catalog_at(o, problem, trace[:t, 0], trace[:t, 1], p, witness[p])
                except PrefixTimeout:
                    stats.update(sat_calls=calls, per_step=steps)
                    return Verdict(None, None, stats, "time limit")
                calls += len(C)  # one query per label of C(p) (the witness's label is free)
                extra = [len(C), len(star)]
            steps.append([*entry, inside, *extra])
            if inside:
                o.fix([p], [b])  # M_{t+1} is consistent: fix the step for good
            else:
                consistent = False
                first_bad = {"step": t, "cell": list(problem.coords(p)), "label": int(b),
                             "label_name": problem.label_name(int(b))}  # fmt: skip
    stats.update(sat_calls=calls, per_step=steps, time_s=time.perf_counter() - t0)
    if run.status == "failed":
        stats["fail_step"] = len(trace)
        stats["fail_cell"] = run.stats.get("fail_cell")
    if first_bad is None:
        if stats.get("unsat"):
            return Verdict(False, None, stats, "the problem is unsatisfiable (no label is in C*)")
        return Verdict(True, None, stats, f"all {len(trace)} chosen labels were in C*")
    if run.status == "failed":
        first_bad["steps_until_failure"] = len(trace) - first_bad["step"]
    msg = (
        f"step {first_bad['step']}: label {first_bad['label_name']} at {tuple(first_bad['cell'])}"
        f" was in C but not in C*; Alg. 3.1 {run.status}"
        + (f" {first_bad['steps_until_failure']} steps later" if run.status == "failed" else "")
    )
    return Verdict(False, first_bad, stats, msg)


# ----------------------------------------------------------------------------- explanations


def explain_unsat(
    problem: Problem,
    *,
    backend: str | None = None,
    minimize: bool = True,
    time_limit: float | None = None,
) -> Verdict:
    """A small (minimal when ``minimize``) unsatisfiable subset of ``problem.unary``.

    Each unary restriction (fixed cell, boundary face, mask, domain restriction) gets a
    selector variable; the SAT solver's assumption core is shrunk by deletion until every
    remaining restriction is needed. Returns a :class:`~csplab.result.Verdict`:
    ``holds=True`` with ``witness = {"core": indices into problem.unary, "unary":
    descriptions, "minimal": bool}`` when the problem is unsatisfiable (an empty core means
    the grid itself admits no solution, whatever is fixed); ``holds=False`` with a
    solution grid as witness when it is satisfiable; ``None`` on timeout.

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> E = ExampleModel([[1, 0, 0], [1, 0, 0], [1, 0, 0]])   # ground under empty space
    >>> P = from_example(E, (4, 4), boundary={"y-": 1, "y+": 1},
    ...                          fixed={(2, 2): 0})
    >>> v = explain_unsat(P)
    >>> v.holds, v.witness["unary"]
    (True, ['boundary face y+ = 1 (4 cells)'])
    """
    t0 = time.perf_counter()
    deadline = None if time_limit is None else t0 + float(time_limit)
    U = problem.unary
    stats: dict[str, Any] = {"unary": len(U), "sat_calls": 0}
    with SatOracle(problem, backend=backend, domains=problem.base_domains,
                   deadline=deadline) as o:  # fmt: skip
        sel: list[int] = []
        for u in U:
            s = o.new_var()
            sel.append(s)
            cells = np.asarray(u.cells, dtype=np.int64)
            forbid = ~np.asarray(u.allowed, dtype=bool)
            for j, c in enumerate(cells.tolist()):
                for b in np.flatnonzero(forbid[j]).tolist():
                    lit = o.enc.literal(c, b)
                    if lit is False:
                        continue
                    if lit is True:
                        o.add_clause([-s])  # this restriction contradicts a forced label
                    else:
                        o.add_clause([-s, -int(lit)])
        pos = {s: i for i, s in enumerate(sel)}

        def run(active: list[int]) -> str:
            stats["sat_calls"] += 1
            return o.solve([sel[i] for i in active], deadline=deadline)

        st = run(list(range(len(U))))
        if st == "timeout":
            stats["time_s"] = time.perf_counter() - t0
            return Verdict(None, None, stats, "time limit reached before the first answer")
        if st == "sat":
            assert o.grid is not None
            stats["time_s"] = time.perf_counter() - t0
            return Verdict(False, o.grid.copy(), stats, "the problem is satisfiable")
        core = sorted(pos[a] for a in o.core() if a in pos)
        stats["first_core"] = len(core)
        minimal = False
        if minimize:
            i = 0
            minimal = True
            while i < len(core):
                trial = core[:i] + core[i + 1 :]
                r = run(trial)
                if r == "timeout":
                    minimal = False
                    break
                if r == "unsat":
                    # keep only what the solver used (clause-set refinement)
                    used = {pos[a] for a in o.core() if a in pos}
                    core = [c for c in trial if c in used]
                else:
                    i += 1
    stats["time_s"] = time.perf_counter() - t0
    descr = [U[i].describe(problem) for i in core]
    witness = {"core": core, "unary": descr, "minimal": minimal}
    if not core:
        msg = "no solution even without the fixed cells, boundary or masks"
    else:
        msg = f"{len(core)} of {len(U)} restrictions conflict" + (" (minimal)" if minimal else "")
    return Verdict(True, witness, stats, msg)
