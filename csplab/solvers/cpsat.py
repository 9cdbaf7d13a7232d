"""Solver ``cpsat``: OR-Tools CP-SAT on a one-hot Boolean model or a table model.

``model="onehot"`` (default): one Boolean per ``(cell, label)`` of the arc-consistent
catalog, ``ExactlyOne`` per cell and the support clauses of :mod:`csplab.cnf` as
``BoolOr`` constraints. ``model="table"``: one integer variable per cell with its catalog
as domain and ``AddAllowedAssignments`` per arc (the natural CSP model). Both are
complete: ``INFEASIBLE`` is a proof and gives ``unsat``.

Loading the one-hot model: OR-Tools' Python ``CpModelProto`` is a C++ message, and adding
its constraints one by one costs 1.5–2 µs each in Python (3.7–5.5 s for the 2.6M
constraints of city or castle at 40×40×10). Instead the whole message is serialized in
the protobuf wire format (a compiled loop for the clauses, numpy for the variables and the
hint; field numbers from the installed ``cp_model_pb2`` descriptor) and parsed into the
model's proto with one ``ParseFromArray`` call (:func:`_proto_parser`; the C++ pointer
comes from pybind11's type-checked conduit). Same model, field for field (a test compares
it with the element-by-element build, which stays as the fallback: ``stats["loader"]`` is
``"proto-bytes"`` or ``"proto-api"``); at 40×40×10 (60 MB) it takes 0.3–0.45 s.
The table model is still built through the API (0.8–1.0 s at 40×40×10, small next to
its search).

Measured on this class of machine (2 cores, shared; see ``benchmarks/bench_solvers.py``
and the README): CP-SAT's presolve expands binary tables into clauses and probes them,
which costs seconds to minutes on grids of a few thousand cells, so the defaults switch
presolve, probing, symmetry detection and linearization off (``presolve=True`` turns them
back on; table model with hints at 16×16×8: 27 s with them, 1.9 s without). At
40×40×10 (``boundary="auto"``, one-hot with random hints on both directions, the
former default, medians of 3 runs) end to end: city 2.6 s
(was 5.9 s), castle 2.7 s (was 6.5 s), against 0.7 and 0.8 s for ``sat`` (3.3–3.8×);
what remains is CP-SAT's own work in ``Solve``: its log on castle (2.67M ``bool_or``,
459k Booleans) shows validation to 0.36 s and the search starting at 1.9–2.5 s, the
search itself about 0.2 s. That set-up did not move with ``use_sat_inprocessing``,
``cp_model_use_sat_presolve``, ``max_presolve_iterations=0``,
``disable_constraint_expansion``, ``remove_fixed_variables_early`` or LNS off (all
3.7–4.0 s, one run each); the forward-only clauses (``supports="forward"``, half the
model) halve it to 1.0 s but the hint is then repaired in 5 s instead of 0.5 s. Why
one-hot is the default: the table model solved only 1 of 6 40×40×10 settings within 60 s
(11 s; it searches slowly); at 12×12×6 both take 3–5 s.

Diversity and the hint: CP-SAT returns the same solution for every ``random_seed`` by
default. ``diversity="catalog"`` (default) runs Alg. 3.1 (scanline, uniform choice; up to
three runs; with global constraints three runs in min-entropy order first, where a large
connected object grows from where it started) with the rng and gives its solution as a
complete hint; CP-SAT confirms a
complete feasible hint without search (0 branches), so the output is that solution, and the
model then needs only the forward support clauses (``supports="auto"``: with ``ExactlyOne``
per cell they are exact, and half the model is half CP-SAT's set-up). When Alg. 3.1 fails
the hint is random labels and the model has both directions. ``diversity="hint"`` gives a
solution hint with one random label per cell drawn from the catalog with the rng (CP-SAT
then repairs the hint, which is also fast: at 16×16×8, 0.3 s instead of 9 s without a hint);
``"polarity"`` sets ``random_polarity_ratio`` and ``random_branches_ratio`` to 0.5 (diverse,
as slow as no hint); ``"none"`` keeps CP-SAT's defaults. The seed is passed as
``random_seed``; with ``num_workers=1`` (default) runs are reproducible. Measured at
40×40×10 castle in one process (``benchmarks/bench_exact.py``, CPU time, loaded machine):
``sat`` 1.9–2.5 s; the catalog hint on the forward model 1.1–1.4× that; the random hint on
both directions (the former default) 3.0×; the catalog hint on both directions 2.0×; the
random hint on the forward model 6.8× (the repair is slow without arc consistency).

Time limit: the model is built in chunks that check the deadline (the one-hot model is
checked again after its single parse, about half a second at 40×40×10), and CP-SAT gets
the time that is left. CP-SAT's own set-up in ``Solve`` (validating and loading the
model, before its search) does not look at the limit (nor at ``StopSearch``): on a
30×30×8 box town (4 labels) it takes 0.95 s for the 37.5 MB one-hot model and 1.8 s for
the 1.86M allowed pairs of the table model, whatever the limit. So csplab estimates it
(model size over a rate learned from this machine's runs, :data:`_SETUP_RATE`) and
returns ``timeout`` at once when the time left cannot hold it (``stats["setup_estimate_s"]``)
instead of overrunning the limit by seconds.

Examples
--------
>>> from csplab import ExampleModel, from_example, solve
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (4, 5))
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
from numpy.typing import NDArray

from csplab._jit import njit
from csplab.cnf import DeadlineExceeded, encode
from csplab.constraints import ClauseContext
from csplab.deps import require
from csplab.engine.alg31 import solution_hint
from csplab.engine.sat import preferred_labels
from csplab.errors import InputError
from csplab.problem import Problem
from csplab.result import Result
from csplab.solvers.base import TIME_LIMIT, Call, Option, Solver

__all__ = ["CpsatSolver"]

_CHUNK = 20_000
_BULK_CHUNK = 1 << 20  # clauses serialized per kernel call (then the deadline is checked)
#: bytes per second of the one-call model parse (a cautious start, then measured)
_PARSE_RATE = [50e6]


#: CP-SAT's set-up before its search (model units per second; units: serialized bytes for
#: the one-hot model, allowed pairs for the table model). Starts from the rates measured on
#: 30x30x8 (39 MB/s and 1.0M pairs/s) made 1.5x cautious, then follows this machine's runs.
_SETUP_RATE = {"onehot": 26e6, "table": 0.67e6}
_SETUP_MIN_UNITS = {"onehot": 1 << 20, "table": 50_000}  # smaller runs teach nothing


def _learn_setup(model: str, units: int, solve_s: float, searched: bool, solved: bool) -> None:
    """Update :data:`_SETUP_RATE` from a finished ``Solve``.

    A call stopped before any search measured the set-up itself; a solved call bounds it
    from above (set-up took at most the whole call), so the rate can only rise from it.
    """
    if units < _SETUP_MIN_UNITS[model] or solve_s <= 0:
        return
    rate = units / solve_s
    if not searched and not solved:
        _SETUP_RATE[model] = rate
    elif solved and rate > _SETUP_RATE[model]:
        _SETUP_RATE[model] = rate


class _SetupOverrun(Exception):
    """CP-SAT's set-up (estimated) would end after the deadline."""

    def __init__(self, estimate: float) -> None:
        super().__init__(estimate)
        self.estimate = estimate


def _check_setup(model: str, units: int, deadline: float | None, before: float = 0.0) -> None:
    """Raise :class:`_SetupOverrun` when ``before`` seconds of work and then CP-SAT's set-up
    for ``units`` cannot end by ``deadline``."""
    if deadline is None:
        return
    est = units / _SETUP_RATE[model]
    if time.perf_counter() + before + est > deadline:
        raise _SetupOverrun(est)


class _Deadline(Exception):
    pass


def _check(deadline: float | None) -> None:
    if deadline is not None and time.perf_counter() > deadline:
        raise _Deadline


class CpsatSolver(Solver):
    """Complete: OR-Tools CP-SAT (one-hot Boolean or table model)."""

    name = "cpsat"
    constraints = "exact"
    complete = True
    requires = ("ortools",)
    description = "OR-Tools CP-SAT"
    notes = (
        '`model="onehot"` (Booleans + the support clauses, default) or `"table"` '
        "(`AddAllowedAssignments` per arc); presolve off by default (it expands the tables); "
        "diverse outputs from solution hints: a seeded Alg. 3.1 solution (then forward "
        "support clauses only) or random labels; `num_workers`, `time_limit` (CP-SAT's "
        "set-up ignores it, so csplab estimates the set-up and stops before a run that "
        "cannot fit)"
    )
    options = (
        Option("model", str, "onehot", "one Boolean per label and the support clauses, or "
               "one integer per cell with a table per arc", values=("onehot", "table")),
        Option("diversity", str, "catalog", "how seeds vary the output: random solution hints, "
               "a seeded Alg. 3.1 solution as the hint (catalog; random labels when it fails), "
               "random polarity, or none", values=("hint", "catalog", "polarity", "none")),
        Option("supports", str, "auto", "one-hot support clauses: both directions of each "
               "arc, forward only (half; exact with exactly-one), or auto (forward when the "
               "hint is a whole solution, else both)", values=("auto", "both", "forward")),
        Option("num_workers", int, 1, "CP-SAT search workers (1 is deterministic)", minimum=1),
        Option("presolve", bool, False, "CP-SAT presolve (expands the tables: slow here)"),
        TIME_LIMIT,
    )  # fmt: skip
    bench = ({}, {"model": "table"})

    def run(self, problem: Problem, call: Call) -> Result:
        rng = call.rng
        model, diversity, num_workers, presolve, supports = call.get(
            "model", "diversity", "num_workers", "presolve", "supports"
        )
        cp_model = require("ortools.sat.python.cp_model", "cpsat", "solver 'cpsat'")
        t0, deadline = call.t0, call.deadline
        rseed = int(rng.integers(2**31 - 1))
        stats: dict[str, Any] = {
            "model": model,
            "diversity": diversity,
            "num_workers": int(num_workers),
            "presolve": bool(presolve),
        }

        def timeout() -> Result:
            return self.result("timeout", None, problem, stats, call)

        whole = None  # a solution to hint (diversity="catalog")
        if diversity == "catalog":
            whole = solution_hint(problem, rng, call.remaining())
            stats["hint"] = "catalog solution" if whole is not None else "random labels"
        if supports == "auto":
            supports = "forward" if whole is not None else "both"
        if model == "onehot":  # the table model uses the encoding's catalog, not its clauses
            stats["supports"] = supports
        try:
            enc = encode(problem, supports=supports, deadline=deadline)
        except DeadlineExceeded:
            return timeout()
        stats["encode_s"] = enc.stats.get("encode_s", 0.0)
        if call.expired():
            return timeout()
        if not enc.ok:
            stats["fail_cell"] = list(problem.coords(enc.wiped))
            proof = "arc-consistency wipe-out before search (Theorem 3.3.2)"
            return self.result("unsat", None, problem, stats, call, proof=proof)
        pref = whole
        if pref is None and diversity in ("hint", "catalog"):
            pref = preferred_labels(enc.catalog, None, rng)
        if problem.constraints and model != "onehot":
            raise InputError("solver 'cpsat': global constraints need model='onehot'")
        m = cp_model.CpModel()
        t_load = time.perf_counter()
        try:
            if model == "onehot":
                read, stats["loader"], units = self._onehot(m, enc, pref, deadline)
            else:
                read, stats["loader"], units = self._table(m, enc, pref, deadline)
            _check_setup(model, units, deadline)
        except _SetupOverrun as e:
            stats["setup_estimate_s"] = e.estimate
            stats["build_s"] = time.perf_counter() - t0
            return timeout()
        except _Deadline:
            stats["load_s"] = time.perf_counter() - t_load
            stats["build_s"] = time.perf_counter() - t0
            return timeout()
        ctx = None
        if problem.constraints:  # global constraints: clauses and linear counts, cuts below
            ctx = _LinearContext(problem, enc.literal, enc.nvars)
            for c in problem.constraints:
                c.clauses(ctx)
            ctx.emit(m)
            stats["constraint_clauses"] = len(ctx.clauses)
            stats["cuts"] = 0
        t1 = time.perf_counter()
        stats["load_s"] = t1 - t_load
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
        left = call.remaining()
        if left is not None:
            if left <= 0:
                return timeout()
            prm.max_time_in_seconds = left
        code = s.Solve(m)
        while ctx is not None and code in (cp_model.OPTIMAL, cp_model.FEASIBLE):
            values = np.asarray(list(s.response_proto.solution), dtype=np.int64)
            k = ctx.cuts(read(values))  # connectivity: cut the solution off, solve again
            if not k:
                break
            stats["cuts"] += k
            ctx.emit(m)
            left = call.remaining()
            if left is not None:
                if left <= 0:
                    code = cp_model.UNKNOWN
                    break
                prm.max_time_in_seconds = left
            code = s.Solve(m)
        stats["solve_s"] = time.perf_counter() - t1
        stats["solver_status"] = s.StatusName(code)
        stats["conflicts"] = int(s.NumConflicts())
        stats["decisions"] = int(s.NumBranches())
        solved = code in (cp_model.OPTIMAL, cp_model.FEASIBLE)
        searched = stats["conflicts"] > 0 or stats["decisions"] > 0
        if num_workers == 1:  # several workers set up several copies
            _learn_setup(model, units, stats["solve_s"], searched, solved)
        if code in (cp_model.OPTIMAL, cp_model.FEASIBLE):
            values = np.asarray(list(s.response_proto.solution), dtype=np.int64)
            return self.result("solved", read(values), problem, stats, call)
        if code == cp_model.INFEASIBLE:
            return self.result("unsat", None, problem, stats, call, proof="CP-SAT: infeasible")
        return timeout()

    @staticmethod
    def _onehot(m: Any, enc: Any, pref: Any, deadline: float | None) -> tuple[Any, str, int]:
        """Booleans x[v, b] (proto index = SAT variable - 1) and the support clauses.

        The model is serialized in bulk (:func:`_onehot_bytes`) and parsed into
        ``m``'s proto in one call; without the parser (:func:`_proto_parser`), or for a
        model over 2 GB, it is built element by element (:func:`_onehot_elementwise`).
        Returns the function from solution values to the grid, the loader's name
        (``"proto-bytes"`` or ``"proto-api"``) and the model's size in bytes (0 when built
        element by element) for :func:`_check_setup`.
        """
        parse = _proto_parser()
        buf = _onehot_bytes(enc, pref, deadline) if parse is not None else None
        if parse is not None and buf is not None:
            _check(deadline)
            # neither the parse nor CP-SAT's set-up can be interrupted: do not start a parse
            # the time left cannot hold with the set-up after it
            _check_setup("onehot", buf.size, deadline, before=buf.size / _PARSE_RATE[0])
            t = time.perf_counter()
            if not parse(m.proto, buf):
                raise RuntimeError("CP-SAT could not parse the model csplab serialized")
            if buf.size > 1 << 20:  # learn this machine's rate from real models
                _PARSE_RATE[0] = max(1e6, buf.size / max(time.perf_counter() - t, 1e-6))
            _check(deadline)
            return _onehot_reader(enc), "proto-bytes", int(buf.size)
        _onehot_elementwise(m, enc, pref, deadline)
        return _onehot_reader(enc), "proto-api", 0

    @staticmethod
    def _table(m: Any, enc: Any, pref: Any, deadline: float | None) -> tuple[Any, str, int]:
        """One integer variable per cell and ``AddAllowedAssignments`` per arc (returns the
        reader, the loader's name and the number of allowed pairs)."""
        cp_model = require("ortools.sat.python.cp_model", "cpsat", "solver 'cpsat'")

        P = enc.problem
        C = enc.catalog
        real = P.arcs[:, 0] != P.arcs[:, 1]
        pairs = P.relations.reshape(P.R, -1).sum(axis=1)
        units = int(pairs[P.arcs[real, 2]].sum())
        _check_setup("table", units, deadline)  # before spending the build on it
        X = []
        for v in range(P.n):
            labels = np.flatnonzero(C[v]).tolist()
            X.append(m.NewIntVarFromDomain(cp_model.Domain.FromValues(labels), ""))
            if v % _CHUNK == 0:
                _check(deadline)
        tuples = [np.argwhere(P.relations[r]).tolist() for r in range(P.R)]
        arcs = P.arcs[real].tolist()
        for i, (a, b, r) in enumerate(arcs):
            m.AddAllowedAssignments([X[a], X[b]], tuples[r])
            if i % _CHUNK == 0:
                _check(deadline)
        if pref is not None:
            m.proto.solution_hint.vars.extend(range(P.n))
            m.proto.solution_hint.values.extend(np.maximum(pref, 0).tolist())

        def read(values: np.ndarray) -> np.ndarray:
            return np.asarray(values[: P.n], dtype=np.int32)

        return read, "proto-api", units


class _LinearContext(ClauseContext):
    """Constraint clauses for CP-SAT: literals are the one-hot Booleans (SAT variable ``v``
    is proto variable ``v - 1``), counts become linear constraints."""

    def __init__(self, problem: Problem, lit: Any, top: int) -> None:
        super().__init__(problem, lit, top)
        self.linear: list[tuple[list[int], int, int]] = []
        self._done = (0, 0)

    def card(self, lits: Any, lo: int, hi: int | None) -> None:
        fixed = sum(1 for x in lits if x is True)
        free = [int(x) for x in lits if x is not True and x is not False]
        if any(x < 0 for x in free):  # not produced by csplab's constraints; stay general
            super().card(lits, lo, hi)
            return
        up = len(free) if hi is None else hi - fixed
        low = max(lo - fixed, 0)
        if low > min(up, len(free)):
            self.add([])  # infeasible: an empty clause
            return
        self.linear.append((free, low, up))

    def emit(self, m: Any) -> None:
        """Add what is new since the last call to the model ``m``."""
        proto = m.proto
        while len(proto.variables) < self.top:
            proto.variables.add().domain.extend([0, 1])
        nc, nl = self._done
        for c in self.clauses[nc:]:  # SAT literal l: proto literal l - 1 (l > 0) or l
            proto.constraints.add().bool_or.literals.extend([x - 1 if x > 0 else x for x in c])
        for free, lo, up in self.linear[nl:]:
            lin = proto.constraints.add().linear
            lin.vars.extend([x - 1 for x in free])
            lin.coeffs.extend([1] * len(free))
            lin.domain.extend([lo, up])
        self._done = (len(self.clauses), len(self.linear))


def _onehot_elementwise(m: Any, enc: Any, pref: Any, deadline: float | None) -> None:
    """Build the one-hot model element by element through the proto API (about 10 µs per
    constraint: the fallback of :meth:`CpsatSolver._onehot` and the reference for tests).
    """
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


def _onehot_reader(enc: Any) -> Any:
    """A function from CP-SAT's solution values to the grid (cell-major, flat)."""

    def read(values: np.ndarray) -> np.ndarray:
        truth = np.zeros(enc.nx + 1, dtype=bool)
        truth[1:] = values[: enc.nx] > 0
        grid, _multi = enc.decode(truth)
        return np.asarray(grid, dtype=np.int32)

    return read


# ----------------------------------------------------------------------------- bulk proto

_MAX_PROTO_BYTES = 2**31 - 1  # protobuf's ParseFromArray takes an int size


def _varint_sizes(values: NDArray[np.int64]) -> NDArray[np.int64]:
    """Bytes of each value as a protobuf varint: 10 for a negative value (two's
    complement), else one per started 7 bits (values must be below ``2**53``).

    Examples
    --------
    >>> _varint_sizes(np.array([0, 127, 128, 2**21, -1], dtype=np.int64)).tolist()
    [1, 1, 2, 4, 10]
    """
    bits = np.frexp(values.astype(np.float64))[1].astype(np.int64)  # bit length of |x|
    n = np.maximum((bits + 6) // 7, 1)
    n[values < 0] = 10
    return n


def _varints(values: NDArray[np.int64]) -> NDArray[np.uint8]:
    """The protobuf varint encoding of ``values`` (below ``2**53``), back to back.

    Examples
    --------
    >>> _varints(np.array([1, 300, -1], dtype=np.int64)).tolist()
    [1, 172, 2, 255, 255, 255, 255, 255, 255, 255, 255, 255, 1]
    """
    values = np.ascontiguousarray(values, dtype=np.int64)
    u = values.view(np.uint64)
    n = _varint_sizes(values)
    ends = np.cumsum(n)
    out = np.empty(int(ends[-1]) if n.size else 0, dtype=np.uint8)
    off = ends - n
    counts = np.bincount(n, minlength=11)
    for size in np.flatnonzero(counts).tolist():  # one 2D pass per varint length
        whole = counts[size] == n.size
        idx = None if whole else np.flatnonzero(n == size)
        w = u if idx is None else u[idx]
        at = off if idx is None else off[idx]
        shifts = np.arange(size, dtype=np.uint64) * np.uint64(7)
        block = (w[:, None] >> shifts).astype(np.uint8)  # the low byte of each group
        block &= 0x7F
        block[:, :-1] |= 0x80
        if whole:
            out[:] = block.reshape(-1)
        else:
            out[at[:, None] + np.arange(size)] = block
    return out


def _tag(number: int) -> int:
    """The key of a length-delimited field (wire type 2) as a varint value."""
    return (number << 3) | 2


def _field(message: str, name: str) -> int:
    """Key of field ``name`` of ``message`` in ``cp_model.proto`` (from the installed
    descriptor, so that a renumbering in OR-Tools cannot go unnoticed)."""
    pb = require("ortools.sat.cp_model_pb2", "cpsat", "solver 'cpsat'")
    return _tag(int(getattr(pb, message).DESCRIPTOR.fields_by_name[name].number))


@njit(cache=True)
def _clause_records(
    lits: np.ndarray, starts: np.ndarray, a: int, b: int, nsup: int,
    keys: np.ndarray, out: np.ndarray, write: bool,
) -> int:  # fmt: skip
    """Serialize clauses ``a..b-1`` as ``constraints`` entries of a ``CpModelProto``.

    ``keys`` holds the field keys ``(constraints, bool_or, exactly_one, literals)``; clause
    ``i`` is a ``bool_or`` if ``i < nsup``, else an ``exactly_one``; SAT literal ``v > 0``
    becomes index ``v - 1`` and ``-v`` stays ``-v`` (CP-SAT's negation of ``v - 1``).
    Returns the number of bytes; they are written to ``out`` only if ``write``. Self-
    contained (no other csplab kernel is called: see :mod:`csplab._kernels`' cache rule).
    """
    head = np.empty(6, dtype=np.int64)
    pos = 0
    for i in range(a, b):
        n0 = 0  # bytes of the packed literals
        for j in range(starts[i], starts[i + 1]):
            y = int(lits[j])
            if y < 0:
                n0 += 10
                continue
            y -= 1
            n0 += 1
            while y >= 128:
                y >>= 7
                n0 += 1
        kind = keys[1] if i < nsup else keys[2]
        n1 = n0 + 2  # BoolArgumentProto: key of literals, length, literals
        for y in (keys[3], n0):  # the bytes of key and length beyond their first
            while y >= 128:
                y >>= 7
                n1 += 1
        n2 = n1 + 2  # ConstraintProto: key of bool_or / exactly_one, length, argument
        for y in (kind, n1):
            while y >= 128:
                y >>= 7
                n2 += 1
        head[0] = keys[0]
        head[1] = n2
        head[2] = kind
        head[3] = n1
        head[4] = keys[3]
        head[5] = n0
        lo = starts[i]
        for t in range(6 + starts[i + 1] - lo):
            if t < 6:
                y = head[t]
            else:
                y = int(lits[lo + t - 6])
                if y > 0:
                    y -= 1
            u = np.uint64(y)  # two's complement: a negative value takes 10 bytes
            while u >= np.uint64(128):
                if write:
                    out[pos] = np.uint8((u & np.uint64(127)) | np.uint64(128))
                pos += 1
                u >>= np.uint64(7)
            if write:
                out[pos] = np.uint8(u)
            pos += 1
    return pos


def _packed(key: int, values: NDArray[np.int64]) -> NDArray[np.uint8]:
    """A packed repeated varint field (nothing when ``values`` is empty, as protobuf writes)."""
    if values.size == 0:
        return np.zeros(0, dtype=np.uint8)
    data = _varints(values)
    return np.concatenate([_varints(np.array([key, data.size], dtype=np.int64)), data])


def _onehot_bytes(enc: Any, pref: Any, deadline: float | None) -> NDArray[np.uint8] | None:
    """The serialized ``CpModelProto`` of the one-hot model (compiled loop + numpy).

    Field for field what :func:`_onehot_elementwise` builds: ``enc.nx`` Boolean variables
    (domain ``[0, 1]``), one ``bool_or`` per support clause and one ``exactly_one`` per
    at-least-one clause (SAT literal ``v`` is index ``v - 1``, ``-v`` is CP-SAT's negation
    ``-(v - 1) - 1 = -v``), and the solution hint when ``pref`` is given.

    Parameters
    ----------
    enc : Encoding
        The support encoding with lazy at-most-one (:func:`csplab.cnf.encode`).
    pref : int array ``(n,)`` or None
        The hinted label per cell.
    deadline : float, optional
        Checked between chunks of clauses (raises ``_Deadline``).

    Returns
    -------
    uint8 array or None
        The message bytes, or None when they would exceed protobuf's 2 GB limit.
    """
    k_var = _field("CpModelProto", "variables")
    k_con = _field("CpModelProto", "constraints")
    k_hint = _field("CpModelProto", "solution_hint")
    k_dom = _field("IntegerVariableProto", "domain")
    k_or = _field("ConstraintProto", "bool_or")
    k_one = _field("ConstraintProto", "exactly_one")
    k_lits = _field("BoolArgumentProto", "literals")
    k_hvars = _field("PartialVariableAssignment", "vars")
    k_hvals = _field("PartialVariableAssignment", "values")
    parts: list[NDArray[np.uint8]] = []
    one_var = np.concatenate([_varints(np.array([k_var, 4], dtype=np.int64)),
                              _packed(k_dom, np.array([0, 1], dtype=np.int64))])  # fmt: skip
    parts.append(np.tile(one_var, enc.nx))
    nsup = enc.nclauses - int(enc.stats["alo_clauses"])
    keys = np.array([k_con, k_or, k_one, k_lits], dtype=np.int64)
    size = 0
    # compile (or load) the kernel even when there is no clause, so that the first small
    # model pays for it and not a later one under a time limit
    _clause_records(enc.lits, enc.starts, 0, 0, nsup, keys, parts[0], False)
    for a in range(0, enc.nclauses, _BULK_CHUNK):
        _check(deadline)
        b = min(a + _BULK_CHUNK, enc.nclauses)
        nbytes = _clause_records(enc.lits, enc.starts, a, b, nsup, keys, parts[0], False)
        size += nbytes
        if size > _MAX_PROTO_BYTES:
            return None
        chunk = np.empty(nbytes, dtype=np.uint8)
        _clause_records(enc.lits, enc.starts, a, b, nsup, keys, chunk, True)
        parts.append(chunk)
    if pref is not None:
        cells, labels = np.nonzero(enc.var > 0)
        hvars = enc.var[cells, labels].astype(np.int64) - 1
        hvals = (labels == pref[cells]).astype(np.int64)
        body = np.concatenate([_packed(k_hvars, hvars), _packed(k_hvals, hvals)])
        parts.append(_varints(np.array([k_hint, body.size], dtype=np.int64)))
        parts.append(body)
    _check(deadline)
    out = np.concatenate(parts)
    return out if out.size <= _MAX_PROTO_BYTES else None


_PARSER: list[Any] = []  # [parse function or None], filled on first use
_TYPE_INFO_NAME = b"St9type_info"  # typeid(std::type_info).name() (Itanium C++ ABI)


def _proto_parser() -> Any:
    """A function ``parse(proto, buf) -> bool`` that replaces the contents of a CP-SAT
    ``CpModelProto`` (OR-Tools' pybind11 wrapper) by the serialized message in ``buf``, or
    None when this OR-Tools build does not offer the pieces.

    OR-Tools' Python ``CpModelProto`` is a C++ message without ``ParseFromString``. The
    C++ pointer comes from pybind11's cross-module conduit (``_pybind11_conduit_v1_``,
    which checks the C++ type), and ``google::protobuf::MessageLite::ParseFromArray`` is
    called through ctypes from the protobuf library the extension module links (found
    through the module's own symbol lookup, so it is the same copy). Any missing piece
    gives None and the caller builds the model element by element.
    """
    if _PARSER:
        return _PARSER[0]
    parse_fn: Any = None
    try:
        import builtins
        import ctypes
        import re

        from ortools.sat.python import cp_model_helper as cmh

        lib = ctypes.CDLL(cmh.__file__)
        raw = lib["_ZN6google8protobuf11MessageLite14ParseFromArrayEPKvi"]
        raw.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int]
        raw.restype = ctypes.c_bool
        tinfo = ctypes.addressof(
            ctypes.c_char.in_dll(lib, "_ZTIN19operations_research3sat12CpModelProtoE")
        )
        # private prototypes: the shared ctypes.pythonapi attributes may be retyped elsewhere
        api = ctypes.pythonapi
        new_capsule = ctypes.PYFUNCTYPE(
            ctypes.py_object, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_void_p
        )(("PyCapsule_New", api))
        get_name = ctypes.PYFUNCTYPE(ctypes.c_void_p, ctypes.py_object)(("PyCapsule_GetName", api))
        get_pointer = ctypes.PYFUNCTYPE(ctypes.c_void_p, ctypes.py_object, ctypes.c_void_p)(
            ("PyCapsule_GetPointer", api)
        )
        capsule = new_capsule(tinfo, _TYPE_INFO_NAME, None)
        abis = [mt.group(1).encode() for k in vars(builtins)
                if (mt := re.fullmatch(r"__pybind11_internals_v\d+(_.*)__", k))]  # fmt: skip

        def pointer(proto: Any) -> int | None:
            for abi in abis:
                c = proto._pybind11_conduit_v1_(abi, capsule, b"raw_pointer_ephemeral")
                if c is not None:
                    p = get_pointer(c, get_name(c))
                    return int(p) if p else None
            return None

        def parse(proto: Any, buf: NDArray[np.uint8]) -> bool:
            p = pointer(proto)
            if p is None:
                raise RuntimeError("no C++ pointer for CP-SAT's model proto")
            data = np.ascontiguousarray(buf, dtype=np.uint8)
            return bool(raw(p, data.ctypes.data, int(data.size)))

        probe = cmh.CpModelProto()
        k_var, k_dom = _field("CpModelProto", "variables"), _field("IntegerVariableProto", "domain")
        one = np.array([k_var, 4, k_dom, 2, 0, 1], dtype=np.uint8)  # one variable in [0, 1]
        if pointer(probe) is not None and parse(probe, one) and len(probe.variables) == 1:
            parse_fn = parse
    except (ImportError, OSError, AttributeError, ValueError, TypeError, RuntimeError):
        parse_fn = None
    _PARSER.append(parse_fn)
    return parse_fn
