"""Solver ``catalog``: Merrell's discrete model synthesis, Alg. 3.1 (with Alg. 3.2/3.3).

Every cell is assigned a label drawn from the catalog C (arc consistency), and C is updated
after each assignment. When a domain empties the run stops with status ``failed``: the
algorithm gave up, which says nothing about satisfiability. A wipe-out before any choice is
a proof of unsatisfiability (Theorem 3.3.2) and gives ``unsat``.

Options
-------
order : {"scanline", "random", "min-entropy", "scan:AXES"}
    ``scanline`` is the thesis' loop order (x outermost, z innermost; default);
    ``scan:AXES`` scans with the named axes from outermost to innermost, e.g. ``scan:yx``,
    the order of the thesis' 2D figures (left to right, then bottom to top);
    ``random`` a random permutation; ``min-entropy`` picks the unassigned cell of least
    Shannon entropy (weighted when ``choice="weighted"``) with tiny random tie-breaking, as
    WaveFunctionCollapse does.
choice : {"uniform", "weighted"}
    ``uniform`` over the catalog (thesis, default) or ``weighted`` by the problem's label
    weights (example frequencies).
time_limit : float, optional
    Seconds; status ``timeout`` when exceeded.

Examples
--------
>>> from csplab import ExampleModel, Problem, solve
>>> from csplab.examples import load_example
>>> P = Problem.from_example(load_example("line"), (8, 6))
>>> r = solve(P, "catalog", rng=1, order="min-entropy")
>>> r.status, r.stats["assigned"]
('solved', 48)
"""

from __future__ import annotations

import time
from typing import Any, ClassVar

import numpy as np

from csplab import _kernels as kern
from csplab.catalog import Propagator
from csplab.errors import InputError
from csplab.problem import AXIS_NAMES, Problem
from csplab.result import Result, Status

__all__ = ["ORDERS", "CatalogSolver", "run_alg31", "scan_order"]

ORDERS = ("scanline", "random", "min-entropy", "scan:AXES")
CHOICES = ("uniform", "weighted")
_CHUNK = 4096


def run_alg31(
    problem: Problem,
    rng: np.random.Generator,
    *,
    order: str = "scanline",
    choice: str = "uniform",
    time_limit: float | None = None,
    engine: Propagator | None = None,
) -> Result:
    """Run Alg. 3.1 once on ``problem`` with randomness from ``rng``.

    ``engine`` may supply an already propagated :class:`~csplab.catalog.Propagator` for the
    problem (it is consumed). Random numbers are drawn in this order: the cell permutation
    (``random`` order only), one uniform per step for the label choice, one tie-breaking
    number per cell (``min-entropy`` only).
    """
    scan = scan_order(problem.shape, order)
    if choice not in CHOICES:
        raise InputError(f"choice must be one of {', '.join(CHOICES)}, not {choice!r}")
    t0 = time.perf_counter()
    n = problem.n
    perm = rng.permutation(n).astype(np.int64) if order == "random" else scan
    ustream = rng.random(n)
    noise = rng.random(n) if order == "min-entropy" else np.zeros(n)
    eng = engine if engine is not None else Propagator(problem)
    grid = np.full(n, -1, dtype=np.int32)
    stats: dict[str, Any] = {"order": order, "choice": choice}
    if not eng.ok:
        stats.update(assigned=0, steps=int(eng.stats[0]), removals=int(eng.stats[1]))
        stats["fail_cell"] = list(problem.coords(eng.wiped)) if eng.wiped >= 0 else None
        stats["proof"] = "arc-consistency wipe-out before any choice (Theorem 3.3.2)"
        return Result(
            "unsat", grid.reshape(problem.shape), "catalog", time_s=time.perf_counter() - t0,
            stats=stats, trace=np.zeros((0, 2), dtype=np.int64),
        )  # fmt: skip
    c = eng.c
    weighted = choice == "weighted"
    use_heap = order == "min-entropy"
    if use_heap:
        heap = np.arange(n, dtype=np.int64)
        hpos = np.zeros(n, dtype=np.int64)
        hkey = _entropies(eng, weighted) + 1e-6 * noise
        kern.heap_build(heap, hpos, hkey, n)
    else:
        heap = np.zeros(0, dtype=np.int64)
        hpos = np.zeros(0, dtype=np.int64)
        hkey = np.zeros(0, dtype=np.float64)
    order_arr = perm if perm is not None else np.arange(n, dtype=np.int64)
    trace_cell = np.full(n, -1, dtype=np.int64)
    trace_label = np.full(n, -1, dtype=np.int64)
    state = np.array([0, n if use_heap else 0, -1], dtype=np.int64)
    deadline = None if time_limit is None else t0 + float(time_limit)
    status: Status
    while True:
        code = kern.alg31(
            eng.bits, eng.prev, c.full, c.ptr, c.nbr, c.sidx, c.sup, c.supall, eng._queue, eng._inq,
            order_arr, use_heap, ustream, noise, c.weights, c.wlogw, weighted, grid,
            trace_cell, trace_label, state, _CHUNK if deadline is not None else n + 1,
            eng.stats, heap, hpos, hkey,
        )  # fmt: skip
        if code == 0:
            status = "solved"
            break
        if code == 1:
            status = "failed"
            eng.ok = False
            eng.wiped = int(state[2])
            break
        if deadline is not None and time.perf_counter() > deadline:
            status = "timeout"
            break
    steps = int(state[0])
    stats.update(assigned=steps, steps=int(eng.stats[0]), removals=int(eng.stats[1]))
    if status == "failed":
        stats["fail_cell"] = list(problem.coords(int(state[2])))
    trace = np.stack([trace_cell[:steps], trace_label[:steps]], axis=1)
    return Result(
        status, grid.reshape(problem.shape), "catalog", time_s=time.perf_counter() - t0,
        stats=stats, trace=trace,
    )  # fmt: skip


def scan_order(shape: tuple[int, ...], order: str) -> np.ndarray | None:
    """Cell sequence of a scan order (``None`` for ``random`` and ``min-entropy``).

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
    if order in ("random", "min-entropy"):
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


def _entropies(eng: Propagator, weighted: bool) -> np.ndarray:
    C = eng.catalog()
    if not weighted:
        cnt = C.sum(axis=1)
        return np.asarray(np.log(np.maximum(cnt, 1)), dtype=np.float64)
    w = eng.c.weights
    s = C @ w
    sl = C @ eng.c.wlogw
    cnt = C.sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = np.where(s > 0, np.log(np.where(s > 0, s, 1.0)) - sl / np.where(s > 0, s, 1.0),
                     np.log(np.maximum(cnt, 1)))  # fmt: skip
    return np.asarray(h, dtype=np.float64)


class CatalogSolver:
    """Alg. 3.1: assign every cell from the arc-consistent catalog (incomplete)."""

    name: ClassVar[str] = "catalog"
    complete: ClassVar[bool] = False
    requires: ClassVar[tuple[str, ...]] = ()
    description: ClassVar[str] = (
        "Merrell Alg. 3.1: assign cells from the arc-consistent catalog; "
        "orders scanline/random/min-entropy"
    )

    def solve(
        self,
        problem: Problem,
        *,
        rng: np.random.Generator,
        seed: int | None,
        backend: str | None = None,
        order: str = "scanline",
        choice: str = "uniform",
        time_limit: float | None = None,
        **options: Any,
    ) -> Result:
        if backend is not None:
            raise InputError(f"solver 'catalog' has no backends (got {backend!r})")
        if options:
            raise InputError(f"unknown option(s) for solver 'catalog': {', '.join(options)}")
        return run_alg31(problem, rng, order=order, choice=choice, time_limit=time_limit)
