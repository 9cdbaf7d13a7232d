"""Merrell's Alg. 3.1 (with the catalog of Alg. 3.2/3.3) as one compiled run: the engine
behind the ``catalog``, ``blocks`` and ``hybrid`` solvers, the catalog gap, the witness
search and the reduction checks.

:func:`run_alg31` assigns every cell a label drawn from the arc-consistent catalog C and
updates C after each assignment (the loop is :func:`csplab._kernels.alg31`); it returns a
:class:`~csplab.result.Result` whose ``trace`` lists the ``(cell, label)`` choices, 0-based
in step order. :func:`scan_order` is the one parser of the order vocabulary.

Orders (:data:`ORDERS`): ``scanline`` is the thesis' loop order (x outermost, z innermost);
``scan:AXES`` scans with the named axes from outermost to innermost, e.g. ``scan:yx``, the
order of the thesis' 2D figures; ``random`` a random permutation; ``min-entropy`` the
unassigned cell of least Shannon entropy (weighted when ``choice="weighted"``) with tiny
random tie-breaking, as WaveFunctionCollapse does; ``min-domain`` the unassigned cell with
the fewest labels left (WaveFunctionCollapse's ``MRV`` heuristic; same tie-breaking), whatever
the choice. Choices (:data:`CHOICES`): ``uniform``
over the catalog (thesis), ``weighted`` by the problem's label weights, or ``resemblance``
(2007 paper Eq. 2–6: by how many example windows the partial model still matches,
:mod:`csplab.engine.resemblance`).

Examples
--------
>>> import numpy as np
>>> from csplab import ExampleModel, from_example
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (4, 3))
>>> r = run_alg31(P, np.random.default_rng(1))
>>> r.status, r.trace.shape
('solved', (12, 2))
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab import _kernels as kern
from csplab.catalog import (
    HEAP_ORDERS,
    Propagator,
    alg31_flags,
    pack,
    reference_adjacency,
    reference_fixpoint,
)
from csplab.constraints import Connected, grid_csr
from csplab.errors import InputError
from csplab.problem import AXIS_NAMES, Problem
from csplab.result import Result, Status

__all__ = [
    "CHOICES",
    "ORDERS",
    "alg31_reference",
    "auto_order",
    "check_order",
    "jit_warmup",
    "run_alg31",
    "scan_order",
    "solution_hint",
]

ORDERS = ("scanline", "random", "min-entropy", "min-domain", "scan:AXES")
CHOICES = ("uniform", "weighted", "resemblance")
_CHUNK = 4096


def run_alg31(
    problem: Problem,
    rng: np.random.Generator,
    *,
    order: str = "scanline",
    choice: str = "uniform",
    time_limit: float | None = None,
    engine: Propagator | None = None,
    window: int = 1,
    context: tuple[Any, Any, tuple[int, ...]] | None = None,
) -> Result:
    """Run Alg. 3.1 once on ``problem`` with randomness from ``rng``.

    ``choice="resemblance"`` draws labels by resemblance to the example model the problem
    was built from (2007 paper Eq. 2–6, :mod:`csplab.engine.resemblance`; windows of
    ``2 * window + 1`` cells; ``context`` gives the labels around a block).

    ``engine`` may supply an already propagated :class:`~csplab.catalog.Propagator` for the
    problem (it is consumed).

    Global constraints (``problem.constraints``) prune the catalog after every assignment
    (:meth:`~csplab.catalog.Propagator.constrain`). A choice that arc consistency or a
    constraint then refutes is withdrawn (:func:`_withdraw`: the label leaves the cell's
    catalog, a sound pruning, and the cell chooses again; stat ``constraint_probes``); the
    run fails only when the catalog without it is refuted too. Under a connectivity
    constraint a cell that cannot touch the set's component yet draws from the labels
    outside the set (:class:`_Grow`). Without global constraints the run is the thesis'
    Alg. 3.1, unchanged. Random numbers are drawn in this order: the cell permutation
    (``random`` order only), one uniform per step for the label choice, one tie-breaking
    number per cell (``min-entropy`` and ``min-domain`` only). ``order="auto"`` is the
    order :func:`auto_order` gives the problem; the stats record the order used.
    """
    if order == "auto":
        order = auto_order(problem)
    scan = scan_order(problem.shape, order)
    if choice not in CHOICES:
        raise InputError(f"choice must be one of {', '.join(CHOICES)}, not {choice!r}")
    if choice == "resemblance":
        return _resemblance(problem, rng, order, scan, window, context, time_limit)
    t0 = time.perf_counter()
    n = problem.n
    perm = rng.permutation(n).astype(np.int64) if order == "random" else scan
    ustream = rng.random(n)
    noise = rng.random(n) if order in HEAP_ORDERS else np.zeros(n)
    eng = engine if engine is not None else Propagator(problem)
    grid = np.full(n, -1, dtype=np.int32)
    stats: dict[str, Any] = {"order": order, "choice": choice}
    if not eng.ok:
        stats.update(assigned=0, revisions=int(eng.stats[0]), removals=int(eng.stats[1]))
        stats["fail_cell"] = list(problem.coords(eng.wiped)) if eng.wiped >= 0 else None
        stats["proof"] = "arc-consistency wipe-out before any choice (Theorem 3.3.2)"
        return Result(
            "unsat", grid.reshape(problem.shape), "catalog", time_s=time.perf_counter() - t0,
            stats=stats, trace=np.zeros((0, 2), dtype=np.int64),
        )  # fmt: skip
    cons = bool(problem.constraints)
    if cons:  # global constraints: prune the root catalog (sound: no solution is lost)
        stats.update(constraint_prunings=0, constraint_conflicts=0)
        got = eng.constrain()
        if got != -1:
            stats.update(assigned=0, revisions=int(eng.stats[0]), removals=int(eng.stats[1]))
            stats["fail_cell"] = list(problem.coords(got)) if got >= 0 else None
            stats["proof"] = "global-constraint propagation before any choice"
            return Result(
                "unsat", grid.reshape(problem.shape), "catalog",
                time_s=time.perf_counter() - t0, stats=stats,
                trace=np.zeros((0, 2), dtype=np.int64),
            )  # fmt: skip
    use_heap, weighted, key_weighted = alg31_flags(order, choice)
    heap: kern.Heap | None = None
    if use_heap:
        pristine = engine is None and eng.c.initial is not None and not cons
        cached = eng.c.entropies.get(key_weighted) if pristine else None
        if cached is None:
            cached = _entropies(eng, key_weighted)
            if pristine:
                eng.c.entropies[key_weighted] = cached
        ent, sw, swl = cached[0], cached[1].copy(), cached[2].copy()
        # the cells and their keys; Propagator.alg31 orders them into a heap when the run starts
        heap = kern.Heap(
            heap=np.arange(n, dtype=np.int64), pos=np.zeros(n, dtype=np.int64),
            key=ent + 1e-6 * noise, noise=noise, sw=sw, swl=swl,
        )  # fmt: skip
    run = kern.Run(
        order=perm if perm is not None else np.arange(n, dtype=np.int64), ustream=ustream,
        grid=grid, trace_cell=np.full(n, -1, dtype=np.int64),
        trace_label=np.full(n, -1, dtype=np.int64),
        state=np.array([0, n if heap is not None else 0, -1], dtype=np.int64),
    )  # fmt: skip
    deadline = None if time_limit is None else t0 + float(time_limit)
    status: Status
    broken: str | None = None
    grow = _Grow(problem) if cons else None
    if cons:  # a refuted choice is withdrawn: the catalog is rebuilt from this one
        stats["constraint_probes"] = 0
        root = eng.bits.copy()
        withdrawn: list[tuple[int, int]] = []
    while True:
        steps = 1 if cons else _CHUNK if deadline is not None else None
        at = run.steps
        if grow is not None and grow.sets and at < n:  # the next cell: order or heap top
            grow.steer(eng.bits, int(run.order[at] if heap is None else heap.heap[0]))
        code = eng.alg31(run, heap, weighted=weighted, key_weighted=key_weighted,
                         max_steps=steps)  # fmt: skip
        if cons and code in (kern.Code.PAUSED, kern.Code.SOLVED):
            # after each assignment the constraints prune (Alg. 3.1 never undoes a choice)
            before = eng.prunings
            got = eng.constrain(incremental=True)
            if got == -1 and eng.prunings != before:
                stats["constraint_prunings"] += 1  # the propagators removed labels
            if got != -1:
                stats["constraint_conflicts"] += 1
                broken = (
                    f"{eng.refuted_by}: no completion is left"
                    if got == -2 and eng.refuted_by
                    else "arc consistency after a global constraint's pruning emptied a domain"
                )
                if got >= 0:
                    run.state[2] = got
                code = kern.Code.FAILED
        if cons and code is kern.Code.FAILED and run.steps > at:
            if _withdraw(eng, run, heap, root, withdrawn):
                stats["constraint_probes"] += 1
                broken = None
                continue  # the same cell again, from its catalog without the refuted label
        if code is kern.Code.SOLVED:
            status = "solved"
            break
        if code is kern.Code.FAILED:
            status = "failed"
            break
        if deadline is not None and time.perf_counter() > deadline:
            status = "timeout"
            break
    steps = run.steps
    stats.update(assigned=steps, revisions=int(eng.stats[0]), removals=int(eng.stats[1]))
    if status == "failed":
        fc = run.fail_cell
        stats["fail_cell"] = list(problem.coords(fc)) if fc >= 0 else None
        if broken is not None:
            stats["broken"] = [broken]
    trace = np.stack([run.trace_cell[:steps], run.trace_label[:steps]], axis=1)
    return Result(
        status, grid.reshape(problem.shape), "catalog", time_s=time.perf_counter() - t0,
        stats=stats, trace=trace,
    )  # fmt: skip


class _Grow:
    """The choice of Alg. 3.1 under connectivity constraints (every order; a heap order's
    next cell is the heap's top): once a cell must be in a constraint's set, a cell that
    touches no cell which must be in
    the set draws from the labels outside the set when it has any, so the set grows as one
    component from where it started instead of starting components that must meet later
    (on city 40×40×10 with connectivity and a count, uniform choices started one object
    per street and failed 4 runs out of 4 where the objects had to meet). A choice, not a
    pruning: when every label outside the set is refuted (withdrawn), the set's labels are
    drawn."""

    def __init__(self, problem: Problem) -> None:
        self.sets: list[NDArray[np.uint64]] = []
        for c in problem.constraints:
            S = c.set_labels(problem) if isinstance(c, Connected) else None
            if S is not None:
                self.sets.append(pack(S[None, :])[0])
        self.ptr, self.nbr = grid_csr(problem)
        self.started: set[bytes] = set()

    def steer(self, bits: NDArray[np.uint64], p: int) -> None:
        """Restrict cell ``p``'s catalog to the labels outside a set it cannot join yet."""
        ptr, nbr = self.ptr, self.nbr
        row = bits[p]
        for sp in self.sets:
            out = row & ~sp
            if not (row & sp).any() or not out.any():
                continue
            if kern.set_status(bits[nbr[ptr[p] : ptr[p + 1]]], sp)[1].any():
                continue  # p touches the component
            if not self._started(bits, sp):
                continue
            bits[p] = out
            row = out

    def _started(self, bits: NDArray[np.uint64], sp: NDArray[np.uint64]) -> bool:
        """Whether some cell must be in the set (remembered once true)."""
        key = sp.tobytes()
        if key in self.started:
            return True
        if kern.set_status(bits, sp)[1].any():
            self.started.add(key)
            return True
        return False


def _withdraw(
    eng: Propagator,
    run: kern.Run,
    heap: kern.Heap | None,
    root: NDArray[np.uint64],
    withdrawn: list[tuple[int, int]],
) -> bool:
    """Undo the last step of a run with global constraints whose label was refuted (by arc
    consistency or a constraint's propagator) and remove that label from its cell.

    The catalog is rebuilt from the run's ``root`` catalog: the assignments so far, the
    labels withdrawn so far (``withdrawn``, which gains this one) and propagation to the
    fixpoint of arc consistency and the constraints. A label is withdrawn only when the
    catalog before its step, with the label, is refuted, so every removal is sound (no
    solution extending the assignments is lost); rebuilding costs one propagation per
    withdrawal instead of a copy of the catalog per step. A heap order gets the cell back
    (keys of cells the refuted step narrowed stay low: they come earlier, which is only an
    order). ``True`` when the rebuilt catalog survives (the run chooses again at the same
    cell), ``False`` when it is refuted too."""
    t = run.steps - 1
    p, b = int(run.trace_cell[t]), int(run.trace_label[t])
    run.grid[p] = -1
    run.trace_cell[t] = run.trace_label[t] = -1
    run.state[0] = t
    run.state[2] = -1
    if heap is not None:
        size = int(run.state[1])
        heap.heap[size], heap.pos[p] = p, size
        run.state[1] = size + 1
        kern._heap_up(heap.heap, heap.pos, heap.key, size)
    withdrawn.append((p, b))
    bits = root.copy()
    cells = np.flatnonzero(run.grid >= 0)
    lab = run.grid[cells].astype(np.int64)
    bits[cells] = 0
    bits[cells, lab // 64] = np.left_shift(np.uint64(1), (lab % 64).astype(np.uint64))
    for c, a in withdrawn:
        bits[c, a // 64] &= ~np.uint64(1 << (a % 64))
    changed = np.flatnonzero((bits != root).any(axis=1))
    # previous domains unknown (the next revisions are full ones); load also forgets the
    # constraints' remembered fixpoints, which belong to the withdrawn step
    eng.load((bits, np.zeros_like(bits), True, -1))
    if not eng.propagate(changed) or eng.constrain() != -1:
        run.state[2] = p if eng.wiped < 0 else eng.wiped
        return False
    return True


def _resemblance(
    problem: Problem, rng: np.random.Generator, order: str, scan: Any, window: int,
    context: Any, time_limit: float | None,
) -> Result:  # fmt: skip
    from csplab.engine.resemblance import run_resemblance
    from csplab.example import ExampleModel

    example = problem.meta.get("model")
    if not isinstance(example, ExampleModel):
        raise InputError(
            "choice='resemblance' needs a problem built from an example model "
            "(csplab.from_example); tilesets have no example to resemble"
        )
    if order in HEAP_ORDERS:
        raise InputError("choice='resemblance' takes the scan orders and random, not " + order)
    perm = rng.permutation(problem.n).astype(np.int64) if order == "random" else scan
    r = run_resemblance(problem, example, rng, order=perm, window=window, context=context,
                        time_limit=time_limit)  # fmt: skip
    r.stats["order"] = order
    return r


def scan_order(shape: tuple[int, ...], order: str) -> np.ndarray | None:
    """Cell sequence of a scan order (``None`` for ``random``, ``min-entropy`` and
    ``min-domain``).

    Examples
    --------
    >>> scan_order((2, 3), "scanline").tolist()
    [0, 1, 2, 3, 4, 5]
    >>> scan_order((2, 3), "scan:yx").tolist()       # x fastest: the 2D figures' order
    [0, 3, 1, 4, 2, 5]
    """
    n = int(np.prod(shape))
    if order == "scanline":
        return np.arange(n, dtype=np.int64)
    if order in ("random", *HEAP_ORDERS):
        return None
    if order.startswith("scan:"):
        names = order[5:]
        axes = [AXIS_NAMES.find(a) for a in names]
        if sorted(axes) != list(range(len(shape))):
            raise InputError(
                f"order {order!r}: name each of the {len(shape)} axes "
                f"({AXIS_NAMES[: len(shape)]}) once, outermost first"
            )
        return np.arange(n, dtype=np.int64).reshape(shape).transpose(axes).ravel()
    raise InputError(f"order must be one of {', '.join(ORDERS)}, not {order!r}")


def _entropies(eng: Propagator, weighted: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Entropy of every cell's catalog, and (weighted) the sums of weights and of
    ``w log w`` the propagation keeps up to date (empty arrays when not weighted)."""
    C = eng.catalog()
    if not weighted:
        cnt = C.sum(axis=1)
        none = np.zeros(0, dtype=np.float64)
        return np.asarray(np.log(np.maximum(cnt, 1)), dtype=np.float64), none, none
    w, wl, wc = eng.c.weights, eng.c.wlogw, eng.c.wclass
    if len(w) == 1:
        s, sl = C @ w[0], C @ wl[0]
    else:  # per weight class
        s, sl = np.zeros(len(C)), np.zeros(len(C))
        for t in np.unique(wc).tolist():
            rows = wc == t
            s[rows], sl[rows] = C[rows] @ w[t], C[rows] @ wl[t]
    cnt = C.sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = np.where(s > 0, np.log(np.where(s > 0, s, 1.0)) - sl / np.where(s > 0, s, 1.0),
                     np.log(np.maximum(cnt, 1)))  # fmt: skip
    return (np.asarray(h, dtype=np.float64), np.ascontiguousarray(s, dtype=np.float64),
            np.ascontiguousarray(sl, dtype=np.float64))  # fmt: skip


def check_order(
    order: str, allowed: tuple[str, ...] = ORDERS, shape: tuple[int, ...] | None = None
) -> str:
    """Validate ``order`` against the kinds in ``allowed`` (``"scan:AXES"`` admits every
    ``scan:...`` order); with ``shape``, also check that a scan names each axis once.

    Examples
    --------
    >>> check_order("scan:yx", shape=(3, 4))
    'scan:yx'
    >>> check_order("min-entropy", ("scanline", "random"))
    Traceback (most recent call last):
    ...
    csplab.errors.InputError: order must be one of scanline, random, not 'min-entropy'
    """
    if not isinstance(order, str):
        raise InputError(f"order must be a string such as 'scanline', not {order!r}")
    kind = "scan:AXES" if order.startswith("scan:") else order
    if kind not in allowed:
        raise InputError(f"order must be one of {', '.join(allowed)}, not {order!r}")
    if shape is not None and kind == "scan:AXES":
        scan_order(shape, order)
    return order


def auto_order(problem: Problem) -> str:
    """The cell order ``order="auto"`` stands for (the ``catalog`` solver's default): the
    thesis' ``scanline`` for a problem without global constraints (its runs unchanged),
    ``min-entropy`` under global constraints.

    Under global constraints Alg. 3.1 withdraws refuted choices and grows one connected
    set (:func:`run_alg31`). A large connected object (a City building under a count of
    at least 5 % of the cells) grows from where it started in min-entropy order, and not
    in scanline order, which leaves cells far apart to start pieces that the count and the
    connectivity refute later (City 40×40×10 with connectivity and a count: scanline runs
    fail for seeds 1-3, min-entropy runs solve them in about 0.8 CPU s); the knot
    tileset's network grows in either (128×128: 2.2-2.4 CPU s in both).

    Parameters
    ----------
    problem : Problem
        The problem.

    Returns
    -------
    str
        ``"scanline"`` or ``"min-entropy"``.

    Examples
    --------
    >>> from csplab import from_example, load_example
    >>> from csplab.constraints import Count
    >>> P = from_example(load_example("line"), (8, 6))
    >>> auto_order(P), auto_order(P.with_constraints([Count([1], 0, 10)]))
    ('scanline', 'min-entropy')
    """
    return "min-entropy" if problem.constraints else "scanline"


#: Alg. 3.1 runs per order tried for a solution hint (:func:`solution_hint`)
HINT_TRIES = 3


def solution_hint(
    problem: Problem, rng: np.random.Generator, left: float | None = None
) -> NDArray[np.int64] | None:
    """A solution of Alg. 3.1 as one label per cell, for an exact solver to start from
    (``cpsat``'s default hint, ``sat``'s ``choice="catalog"`` phases), or None.

    Up to :data:`HINT_TRIES` runs in the order :func:`auto_order` gives the problem, then,
    when that is not scanline (global constraints), as many in scanline order; uniform
    choice.

    Parameters
    ----------
    problem : Problem
        The problem.
    rng : numpy.random.Generator
        The solver's random numbers (the runs draw from it in turn).
    left : float, optional
        Seconds the solver has left: the runs take at most a quarter of them.

    Returns
    -------
    numpy.ndarray of int64 or None
        The labels in cell order, or None when every run fails, arc consistency wipes a
        cell out, or the time is spent.

    Examples
    --------
    >>> import csplab.examples
    >>> from csplab.grids import from_example
    >>> P = from_example(csplab.examples.load_example("fig3_1b"), (6, 5))
    >>> h = solution_hint(P, np.random.default_rng(1))
    >>> h.shape, len(P.violations(h.reshape(P.shape).astype(np.int32)))
    ((30,), 0)
    """
    t0 = time.perf_counter()
    first = auto_order(problem)
    orders = [first] * HINT_TRIES + (["scanline"] * HINT_TRIES if first != "scanline" else [])
    for order in orders:
        budget = None if left is None else left / 4 - (time.perf_counter() - t0)
        if budget is not None and budget <= 0:
            return None
        r = run_alg31(problem, rng, order=order, time_limit=budget)
        if r.status == "solved":
            return np.asarray(r.grid, dtype=np.int64).reshape(-1)
        if r.status == "unsat":  # an arc-consistency wipe-out: the solver reports it
            return None
    return None


def alg31_reference(
    problem: Problem, rng: np.random.Generator, *, order: str = "scanline",
    choice: str = "uniform",
) -> tuple[str, NDArray[np.int32]]:  # fmt: skip
    """Slow, literal Alg. 3.1 on top of :func:`propagate_reference`.

    Draws random numbers exactly as :func:`run_alg31` does for the
    scan orders and ``random``, so both return the same grid for the same seed.
    Returns ``(status, grid)`` with status ``solved``, ``failed`` or ``unsat``. Arcs only:
    a problem with global constraints is refused (:class:`~csplab.errors.InputError`)
    rather than "solved" by a grid that may break them.
    """
    problem.require_no_constraints("the reference Alg. 3.1")
    if order in HEAP_ORDERS:
        raise InputError("the reference Alg. 3.1 supports the scan and random orders")
    n, K = problem.n, problem.K
    scan = scan_order(problem.shape, order)
    perm = rng.permutation(n) if scan is None else scan
    ustream = rng.random(n)
    adj = reference_adjacency(problem)
    C = problem.domains.copy()
    grid = np.full(n, -1, dtype=np.int32)
    if not C.any(axis=1).all() or not reference_fixpoint(C, adj, range(n)):
        return "unsat", grid.reshape(problem.shape)
    w = problem.weights
    for t in range(n):
        p = int(perm[t])
        labels = np.flatnonzero(C[p])
        if labels.size == 0:  # Alg. 3.1 line 9
            return "failed", grid.reshape(problem.shape)
        u = ustream[t]
        if choice == "weighted" and w[labels].sum() > 0:
            pos = labels[w[labels] > 0]
            cum = np.cumsum(w[pos])
            b = int(pos[min(int(np.searchsorted(cum, u * cum[-1], side="right")), pos.size - 1)])
        else:
            b = int(labels[min(int(u * labels.size), labels.size - 1)])
        grid[p] = b
        C[p] = False  # statement 3.7
        C[p, b] = True
        if not reference_fixpoint(C, adj, [p]):
            return "failed", grid.reshape(problem.shape)
    assert K == C.shape[1]
    return "solved", grid.reshape(problem.shape)


def jit_warmup() -> float:
    """Compile (or load from numba's on-disk cache) every kernel of Alg. 3.1; returns seconds
    spent. (Small problems would otherwise run interpreted, :mod:`csplab._interp`: the
    warm-up forces the kernels.)"""
    t0 = time.perf_counter()
    from csplab import _interp
    from csplab.example import ExampleModel
    from csplab.grids import from_example

    P = from_example(ExampleModel([[0, 1], [1, 0]]), (2, 2))
    rng = np.random.default_rng(0)
    saved, _interp.ENGINE = _interp.ENGINE, "kernels"
    try:
        for order in ("scanline", "min-entropy"):
            for choice in ("uniform", "weighted"):
                run_alg31(P, rng, order=order, choice=choice)
    finally:
        _interp.ENGINE = saved
    return time.perf_counter() - t0
