"""Solver ``cpsat``: OR-Tools CP-SAT on a one-hot Boolean model or a table model.

``model="onehot"`` (default): one Boolean per ``(cell, label)`` of the arc-consistent
catalog, ``ExactlyOne`` per cell and the support clauses of :mod:`csplab.cnf` as
``BoolOr`` constraints (written straight into the model proto). ``model="table"``: one
integer variable per cell with its catalog as domain and ``AddAllowedAssignments`` per arc
(the natural CSP model). Both are complete: ``INFEASIBLE`` is a proof and gives ``unsat``.

Measured on this class of machine (see ``benchmarks/bench_solvers.py`` and the README):
CP-SAT's presolve expands binary tables into clauses and probes them, which costs seconds
to minutes on grids of a few thousand cells, so the defaults switch presolve, probing,
symmetry detection and linearization off (``presolve=True`` turns them back on; table
model with hints at 16×16×8: 27 s with them, 1.9 s without); building the model costs about
10 µs per constraint in Python, which dominates at 40×40×10. Why one-hot is the default:
at 40×40×10 on the built-in examples it solved 5 of 6 settings within 60 s (7–50 s, most
of it building the model), the table model only 1 (11 s; it builds in 2–3 s but searches
slowly); at 12×12×6 both take 3–5 s.

Diversity: CP-SAT returns the same solution for every ``random_seed`` by default.
``diversity="hint"`` (default) gives a solution hint with one random label per cell drawn
from the catalog with the rng (CP-SAT then repairs the hint, which is also fast: at
16×16×8, 0.3 s instead of 9 s without a hint); ``"polarity"`` sets
``random_polarity_ratio`` and ``random_branches_ratio`` to 0.5 (diverse, as slow as no
hint); ``"none"`` keeps CP-SAT's defaults. The seed is passed as ``random_seed``; with
``num_workers=1`` (default) runs are reproducible.

Time limit: the model is built in chunks that check the deadline, and CP-SAT gets the time
that is left; but CP-SAT loads a table model without looking at its limit (nor at
``StopSearch``): on a 30×30×8 box town (4 labels) the call ended 1.7–2.1 s after a 0.3 s
limit. The one-hot model stays within the limit.

Examples
--------
>>> from csplab import ExampleModel, Problem, solve
>>> P = Problem.from_example(ExampleModel([[0, 1], [1, 0]]), (4, 5))
>>> r = solve(P, "cpsat", rng=0)
>>> r.status, r.stats["model"]
('solved', 'onehot')
>>> solve(P, "cpsat", rng=0, model="table").status
'solved'
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from csplab.cnf import DeadlineExceeded, encode
from csplab.deps import require
from csplab.engine.sat import preferred_labels
from csplab.problem import Problem
from csplab.result import Result
from csplab.solvers.base import TIME_LIMIT, Call, Option, Solver

__all__ = ["CpsatSolver"]

_CHUNK = 20_000


class _Deadline(Exception):
    pass


def _check(deadline: float | None) -> None:
    if deadline is not None and time.perf_counter() > deadline:
        raise _Deadline


class CpsatSolver(Solver):
    """Complete: OR-Tools CP-SAT (one-hot Boolean or table model)."""

    name = "cpsat"
    complete = True
    requires = ("ortools",)
    extra = "cpsat"
    description = "OR-Tools CP-SAT"
    notes = (
        '`model="onehot"` (Booleans + the support clauses, default) or `"table"` '
        "(`AddAllowedAssignments` per arc); presolve off by default (it expands the tables); "
        "diverse outputs from random solution hints; `num_workers`, `time_limit` (CP-SAT "
        "loads a table model without looking at the limit: 1.7-2.1 s over it on 30x30x8)"
    )
    options = (
        Option("model", str, "onehot", "one Boolean per label and the support clauses, or "
               "one integer per cell with a table per arc", values=("onehot", "table")),
        Option("diversity", str, "hint", "how seeds vary the output: random solution hints, "
               "random polarity, or none", values=("hint", "polarity", "none")),
        Option("num_workers", int, 1, "CP-SAT search workers (1 is deterministic)", minimum=1),
        Option("presolve", bool, False, "CP-SAT presolve (expands the tables: slow here)"),
        TIME_LIMIT,
    )  # fmt: skip
    bench = ({}, {"model": "table"})

    def run(self, problem: Problem, call: Call) -> Result:
        rng = call.rng
        model, diversity, num_workers, presolve, time_limit = call.get(
            "model", "diversity", "num_workers", "presolve", "time_limit"
        )
        cp_model = require("ortools.sat.python.cp_model", "cpsat", "solver 'cpsat'")
        t0 = time.perf_counter()
        deadline = None if time_limit is None else t0 + float(time_limit)
        rseed = int(rng.integers(2**31 - 1))
        grid = np.full(problem.shape, -1, dtype=np.int32)
        stats: dict[str, Any] = {
            "model": model,
            "diversity": diversity,
            "num_workers": int(num_workers),
            "presolve": bool(presolve),
        }
        try:
            enc = encode(problem, deadline=deadline)
        except DeadlineExceeded:
            return Result("timeout", grid, "cpsat", time_s=time.perf_counter() - t0, stats=stats)
        stats["encode_s"] = enc.stats.get("encode_s", 0.0)
        if deadline is not None and time.perf_counter() > deadline:
            return Result("timeout", grid, "cpsat", time_s=time.perf_counter() - t0, stats=stats)
        if not enc.ok:
            stats["proof"] = "arc-consistency wipe-out before search (Theorem 3.3.2)"
            stats["fail_cell"] = list(problem.coords(enc.wiped))
            return Result("unsat", grid, "cpsat", time_s=time.perf_counter() - t0, stats=stats)
        pref = preferred_labels(enc.catalog, None, rng) if diversity == "hint" else None
        m = cp_model.CpModel()
        try:
            if model == "onehot":
                read = self._onehot(m, enc, pref, deadline)
            else:
                read = self._table(m, enc, pref, deadline)
        except _Deadline:
            stats["build_s"] = time.perf_counter() - t0
            return Result("timeout", grid, "cpsat", time_s=time.perf_counter() - t0, stats=stats)
        t1 = time.perf_counter()
        stats["build_s"] = t1 - t0
        s = cp_model.CpSolver()
        prm = s.parameters
        prm.random_seed = rseed
        prm.num_workers = int(num_workers)
        if not presolve:
            prm.cp_model_presolve = False
            prm.cp_model_probing_level = 0
            prm.symmetry_level = 0
            prm.linearization_level = 0
        if diversity == "polarity":
            prm.random_polarity_ratio = 0.5
            prm.random_branches_ratio = 0.5
        if num_workers > 1:
            prm.interleave_search = True  # deterministic with several workers
        if deadline is not None:
            left = deadline - time.perf_counter()
            if left <= 0:
                return Result("timeout", grid, "cpsat", time_s=time.perf_counter() - t0,
                              stats=stats)  # fmt: skip
            prm.max_time_in_seconds = left
        code = s.Solve(m)
        stats["solve_s"] = time.perf_counter() - t1
        stats["solver_status"] = s.StatusName(code)
        stats["conflicts"] = int(s.NumConflicts())
        stats["decisions"] = int(s.NumBranches())
        if code in (cp_model.OPTIMAL, cp_model.FEASIBLE):
            values = np.asarray(list(s.response_proto.solution), dtype=np.int64)
            out = read(values).reshape(problem.shape)
            return Result("solved", out, "cpsat", time_s=time.perf_counter() - t0, stats=stats)
        if code == cp_model.INFEASIBLE:
            stats["proof"] = "CP-SAT: infeasible"
            return Result("unsat", grid, "cpsat", time_s=time.perf_counter() - t0, stats=stats)
        return Result("timeout", grid, "cpsat", time_s=time.perf_counter() - t0, stats=stats)

    @staticmethod
    def _onehot(m: Any, enc: Any, pref: Any, deadline: float | None) -> Any:
        """Booleans x[v, b] (proto index = SAT variable - 1) and the support clauses."""
        p = m.proto
        variables = p.variables
        for a in range(0, enc.nx, _CHUNK):
            _check(deadline)
            for _ in range(a, min(a + _CHUNK, enc.nx)):
                variables.add().domain.extend((0, 1))
        nalo = int(enc.stats["alo_clauses"])
        nsup = enc.nclauses - nalo
        cons = p.constraints
        for a in range(0, enc.nclauses, _CHUNK):
            _check(deadline)
            b = min(a + _CHUNK, enc.nclauses)
            lo, hi = int(enc.starts[a]), int(enc.starts[b])
            chunk = enc.lits[lo:hi]
            lits = np.where(chunk > 0, chunk - 1, chunk).astype(np.int64).tolist()
            st = (enc.starts[a : b + 1] - lo).tolist()
            for i in range(b - a):
                if a + i < nsup:
                    cons.add().bool_or.literals.extend(lits[st[i] : st[i + 1]])
                else:
                    cons.add().exactly_one.literals.extend(lits[st[i] : st[i + 1]])
        if pref is not None:
            var = enc.var
            has = var > 0
            cells, labels = np.nonzero(has)
            vals = (labels == pref[cells]).astype(np.int64)
            p.solution_hint.vars.extend((var[has].astype(np.int64) - 1).tolist())
            p.solution_hint.values.extend(vals.tolist())

        def read(values: np.ndarray) -> np.ndarray:
            truth = np.zeros(enc.nx + 1, dtype=bool)
            truth[1:] = values[: enc.nx] > 0
            grid, _multi = enc.decode(truth)
            return np.asarray(grid, dtype=np.int32)

        return read

    @staticmethod
    def _table(m: Any, enc: Any, pref: Any, deadline: float | None) -> Any:
        """One integer variable per cell and ``AddAllowedAssignments`` per arc."""
        cp_model = require("ortools.sat.python.cp_model", "cpsat", "solver 'cpsat'")

        P = enc.problem
        C = enc.catalog
        X = []
        for v in range(P.n):
            labels = np.flatnonzero(C[v]).tolist()
            X.append(m.NewIntVarFromDomain(cp_model.Domain.FromValues(labels), ""))
            if v % _CHUNK == 0:
                _check(deadline)
        tuples = [np.argwhere(P.relations[r]).tolist() for r in range(P.R)]
        arcs = P.arcs[P.arcs[:, 0] != P.arcs[:, 1]].tolist()
        for i, (a, b, r) in enumerate(arcs):
            m.AddAllowedAssignments([X[a], X[b]], tuples[r])
            if i % _CHUNK == 0:
                _check(deadline)
        if pref is not None:
            m.proto.solution_hint.vars.extend(range(P.n))
            m.proto.solution_hint.values.extend(np.maximum(pref, 0).tolist())

        def read(values: np.ndarray) -> np.ndarray:
            return np.asarray(values[: P.n], dtype=np.int32)

        return read
