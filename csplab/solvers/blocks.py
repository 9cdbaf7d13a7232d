"""Solver ``blocks``: modify an existing solution in overlapping blocks (Alg. 3.4, Sec. 3.3.6).

Start from a consistent grid (given as ``init``, or the trivial solution built by
:func:`trivial_solution`), then sweep blocks of ``m`` cells per axis shifted by half a block
(x outermost, as the thesis' loops). Labels outside the block stay fixed and constrain it
through the arcs (:meth:`Problem.subproblem`); Alg. 3.1 runs inside the block; on failure it
is retried with fresh random choices up to ``retries`` times, then the block is restored.
The grid is consistent after every block, so the result is always a solution. With ``m``
equal to the model size and ``retries=0`` this is exactly Alg. 3.1 for the same seed.

Compiled sweep. With numba's kernels loaded (a large job loads them first) and a plain
setting -- grid blocks, a scan or entropy order, uniform or weighted choice, no energy --
the whole sweep runs in one kernel (:func:`csplab._kernels.blocks_sweep`, 64 blocks per
call so that ``time_limit`` is checked between calls): each block's domains are cut from the
problem's by the fixed labels around it, in arrays of the block's size only (thesis Sec.
3.3.6: the catalog of the block, ``m ** d * K`` bits, not of the model), then arc
consistency and Alg. 3.1 with retries, with no Python per block. It draws the same random
numbers in the same order as the Python sweep and gives the same grid and counts (tested);
the ``random`` order, ``choice="resemblance"`` and ``energy=`` keep the Python sweep. The
wave schedule below does the same per block (one kernel call each, in the workers too).

Streamed (thesis Sec. 3.3.6: a block needs its neighbourhood, not the model).
:func:`stream_blocks` runs the same compiled sweep on a problem built window by window
(:class:`csplab.grids.GridWindows`): the blocks of one ``x`` origin in one kernel call on
the slab of the grid they touch, its domains and arcs those of a slab problem (a handful
serve the whole sweep), so the same grid and counts for a seed with the output as the only
array of the model's size; ``csplab synthesize --solver blocks`` takes it when the whole
problem would need more than :data:`STREAM_BYTES` and the settings allow it
(:func:`streams`).

Parallel blocks (``workers >= 1``). Blocks that neither overlap nor share an arc are
independent; :mod:`csplab.engine.waves` colours the blocks by their block index modulo 3 on
each axis and runs the ``3 ** d`` colour classes as waves, in order, the blocks of a wave in
parallel against the grid left by the previous wave (which the wave then updates). A block
that would share an arc with another of its wave (a flush last block, a periodic axis, boxes
of positions joined by long arcs) moves to a following wave, so every wave is independent.
Each block draws from its own generator, seeded with ``numpy.random.SeedSequence([root,
sweep, block])`` where ``root`` is one number drawn from the run's generator; the output is
therefore the same for any number of workers, in-process (``workers=1``), on a local process
pool (``workers=N``) or on Dask (``scheduler="local"`` or an address). **The wave schedule
is not the thesis' sweep**: blocks are visited in another order and with another random
stream, so for a given seed its output differs from ``workers=0`` (the default, the thesis'
order and random stream, unchanged). ``time_limit`` holds across waves: a wave still running
at the limit is stopped (its finished blocks are kept) and the status is ``timeout``.

Examples
--------
>>> from csplab import from_example, solve
>>> from csplab.examples import load_example
>>> P = from_example(load_example("fig3_4a"), (12, 12))
>>> r = solve(P, "blocks", rng=0, block=4)
>>> r.status, r.stats["blocks_tried"], r.stats["final_violations"]
('solved', 25, 0)
>>> a = solve(P, "blocks", rng=0, block=4, workers=1)      # the wave schedule, in-process
>>> b = solve(P, "blocks", rng=0, block=4, workers=2)      # two worker processes
>>> bool((a.grid == b.grid).all()), a.status
(True, 'solved')
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab import _interp
from csplab.catalog import block_arrays, neighbourhood, sweep_blocks
from csplab.engine import waves as wv
from csplab.engine.alg31 import run_alg31, scan_order
from csplab.errors import CsplabError, InputError, NoTrivialSolutionError
from csplab.grids import GridWindows
from csplab.problem import Problem
from csplab.progress import progress_bar
from csplab.result import Result, Status
from csplab.soft import Breaches, Energy
from csplab.solvers.base import (
    CHOICE,
    TIME_LIMIT,
    WINDOW,
    Call,
    Option,
    Solver,
    order_option,
)

__all__ = [
    "BlocksSolver",
    "ExactCompletion",
    "block_starts",
    "stream_blocks",
    "streams",
    "trivial_solution",
]


def block_starts(n: int, m: int) -> list[int]:
    """Block origins along one axis: every ``m // 2`` cells, the last block flush with the end.

    Examples
    --------
    >>> block_starts(40, 10)
    [0, 5, 10, 15, 20, 25, 30]
    >>> block_starts(12, 5)
    [0, 2, 4, 6, 7]
    >>> block_starts(10, 10)
    [0]
    """
    m = min(m, n)
    step = max(1, m // 2)
    starts = list(range(0, n - m + 1, step))
    if starts[-1] != n - m:
        starts.append(n - m)
    return starts


def trivial_solution(problem: Problem, attempts: int = 5) -> NDArray[np.int32]:
    """A simple consistent grid to start Alg. 3.4 from.

    Tries, in order: one label everywhere (empty space: a label that tiles every axis and is
    allowed in every cell), then a stack of uniform layers along each axis, last axis first
    (for grounded examples: ground at the bottom, empty space above), chosen by dynamic
    programming to respect domains and arcs between consecutive layers, and finally (for
    examples without empty space, such as the checkerboard) up to ``attempts`` runs of
    Alg. 3.1 with a private generator seeded 0, 1, ... (the caller's random stream is not
    touched). Each candidate is checked with :meth:`Problem.violations`. Raises
    :class:`~csplab.errors.NoTrivialSolutionError` when none works.

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> E = ExampleModel([[1, 0, 0], [1, 0, 0]])        # ground 1 under empty space 0
    >>> P = from_example(E, (3, 3), boundary="auto")
    >>> trivial_solution(P).tolist()
    [[1, 0, 0], [1, 0, 0], [1, 0, 0]]
    """
    plan = _trivial_plan(lambda axis: problem)
    if plan is not None:
        g = np.empty(problem.shape, dtype=np.int32)
        _paint(plan, g)
        return g
    # 3. a few runs of Alg. 3.1 on a private generator
    for seed in range(attempts):
        r = run_alg31(problem, np.random.default_rng(seed))
        if r.status == "solved" and problem.is_solution(r.grid):
            return np.asarray(r.grid, dtype=np.int32)
        if r.status == "unsat":
            raise NoTrivialSolutionError(
                "modify-in-blocks needs a consistent starting model, but the problem is "
                "unsatisfiable (arc consistency empties a domain before any choice)"
            )
    raise NoTrivialSolutionError(
        "modify-in-blocks needs a consistent starting model and none was found: no label "
        f"tiles every axis within the domains, no stack of uniform layers (e.g. ground under "
        f"empty space) fits, and Alg. 3.1 failed {attempts} times; pass init=<a consistent "
        "grid> or use another solver"
    )


#: a trivial solution that is a function of one coordinate: ``(axis, labels)``, the label
#: of every cell ``labels[its coordinate on axis]`` (one label everywhere: ``(-1, [label])``)
_TrivialPlan = tuple[int, NDArray[np.int32]]


def _trivial_plan(problem_for: Callable[[int | None], Problem]) -> _TrivialPlan | None:
    """Steps 1 and 2 of :func:`trivial_solution`: one label everywhere, else uniform layers
    along an axis, each tried on ``problem_for(None)`` / ``problem_for(axis)`` (the whole
    problem, or a miniature with every kind of cell and, along ``axis``, every layer:
    :meth:`csplab.grids.GridWindows.miniature`; the checks are translation invariant)."""
    P = problem_for(None)
    K = P.K
    w = np.asarray(P.weights, dtype=np.float64)
    pref = np.argsort(-w, kind="stable")
    # 1. a single label everywhere
    allowed_everywhere = np.asarray(P.domains.all(axis=0), dtype=bool)
    used_rel = np.unique(P.arcs[:, 2]) if P.arcs.size else np.zeros(0, dtype=np.int64)
    for a in pref:
        if allowed_everywhere[a] and all(P.relations[r, a, a] for r in used_rel):
            if P.is_solution(np.full(P.shape, a, dtype=np.int32)):
                return -1, np.full(1, a, dtype=np.int32)
    # 2. uniform layers along one axis (last axis first)
    score = np.log(np.maximum(w, 1e-12))
    for axis in reversed(range(P.ndim)):
        problem = problem_for(axis)
        rel, arcs = problem.relations, problem.arcs
        stride = math.prod(problem.shape[axis + 1 :])  # C order: the axis's index per cell
        layer = (np.arange(problem.n) // stride) % problem.shape[axis]
        L = problem.shape[axis]
        ls, ld = layer[arcs[:, 0]], layer[arcs[:, 1]]
        ok_label = np.ones((L, K), dtype=bool)
        for i in range(L):
            ok_label[i] = problem.domains[layer == i].all(axis=0)
            intra = arcs[(ls == i) & (ld == i)]
            for r in np.unique(intra[:, 2]):
                ok_label[i] &= np.diagonal(rel[r])
        # compatibility between consecutive layers i -> i + 1 (both arc directions)
        best = np.where(ok_label[0], score, -np.inf)
        back = np.zeros((L, K), dtype=np.int64)
        for i in range(1, L):
            compat = np.ones((K, K), dtype=bool)  # [label of layer i-1, label of layer i]
            fwd = arcs[(ls == i - 1) & (ld == i)]
            bwd = arcs[(ls == i) & (ld == i - 1)]
            for r in np.unique(fwd[:, 2]):
                compat &= rel[r]
            for r in np.unique(bwd[:, 2]):
                compat &= rel[r].T
            cand = np.where(compat, best[:, None], -np.inf)
            back[i] = cand.argmax(axis=0)
            best = cand.max(axis=0) + np.where(ok_label[i], score, -np.inf)
        if not np.isfinite(best.max()):
            continue
        labels = np.zeros(L, dtype=np.int32)
        labels[-1] = int(best.argmax())
        for i in range(L - 1, 0, -1):
            labels[i - 1] = back[i, labels[i]]
        if problem.is_solution(labels[layer].astype(np.int32).reshape(problem.shape)):
            return axis, labels
    return None


def _paint(plan: _TrivialPlan, out: NDArray[np.int32], start: int = 0) -> None:
    """Write a trivial solution into ``out`` (the whole grid, or the slab of it from
    ``x = start`` on), without a temporary of its size."""
    axis, labels = plan
    if axis < 0:
        out[...] = labels[0]
        return
    if axis == 0:
        labels = labels[start : start + out.shape[0]]
    shape = [1] * out.ndim
    shape[axis] = out.shape[axis]
    out[...] = labels.reshape(shape)


def _block_shape(block: int | Sequence[int], shape: tuple[int, ...]) -> tuple[int, ...]:
    if isinstance(block, int | np.integer):
        m = (int(block),) * len(shape)
    else:
        m = tuple(int(b) for b in block)
        if len(m) == 1:
            m = m * len(shape)
    if len(m) != len(shape) or any(b < 1 for b in m):
        raise InputError(f"block size {block!r} must be positive, one per axis of {shape}")
    return tuple(min(b, s) for b, s in zip(m, shape, strict=True))


def run_blocks(
    problem: Problem,
    rng: np.random.Generator,
    *,
    block: int | Sequence[int] = 10,
    retries: int = 20,
    init: ArrayLike | None = None,
    sweeps: int = 1,
    order: str = "scanline",
    choice: str = "uniform",
    deadline: float | None = None,
    workers: int = 0,
    scheduler: str | None = None,
    window: int = 1,
    energy: Energy | None = None,
    temperature: float = 1.0,
    cooling: float = 1.0,
    exact: str = "none",
    progress: bool = False,
) -> tuple[Status, NDArray[np.int32], dict[str, Any]]:
    """Alg. 3.4 (see the module docstring): the engine of :class:`BlocksSolver`.

    Parameters
    ----------
    problem : Problem
        The problem (a grid, or cells with :attr:`Problem.positions`: boxes of positions).
    rng : numpy.random.Generator
        The randomness (``workers >= 1``: one number drawn from it seeds every block).
    block, retries, init, sweeps, order, choice
        As declared by :class:`BlocksSolver`.
    deadline : float, optional
        ``time.perf_counter()`` value at which the sweeps stop (the call's deadline).
    workers : int
        0: the thesis' sweep in this process; ``N >= 1``: the wave schedule on ``N``
        workers (1: in this process).
    scheduler : str, optional
        ``"local"`` (a Dask ``LocalCluster`` of ``workers`` processes) or the address of a
        Dask scheduler; ``None``: a local process pool.
    window : int
        ``choice="resemblance"``: windows of ``2 * window + 1`` cells (2007 paper Eq. 2).
    energy, temperature, cooling
        Soft constraints (2007 paper Sec. 4.2, :mod:`csplab.soft`): a consistent new block
        is kept with probability ``min(1, exp(-(E(M') - E(M)) / T))``; ``T`` starts at
        ``temperature`` and is multiplied by ``cooling`` after each sweep.
    exact : {"none", "sat", "backtrack"}
        Exact block completion: a block whose Alg. 3.1 runs all fail is solved by this
        exact solver on the block's subproblem (its border fixed); when that proves the
        block has no labels fitting its border, it keeps its labels as before. Runs the
        thesis' sweep in Python (``workers=0``).

    Returns
    -------
    status : {"solved", "timeout"}
        ``solved`` (the grid is always consistent; :func:`csplab.solvers.solve` turns a
        broken global constraint into ``failed``) or ``timeout``.
    grid : int32 array of the problem's shape
    stats : dict
    """
    # global constraints: the blocks see only the arcs (as their subproblems do); a block
    # that breaks the constraints more than the model did is rejected (their excess is an
    # energy at zero temperature), so the sweeps repair the model; solve() checks the end
    repair = None
    if problem.constraints:
        repair = Breaches(problem, weight=1e6 if energy is not None else 1.0)
        energy = Energy([*(energy.terms if energy is not None else ()), repair])
        if repair.weight == 1.0:
            temperature, cooling = 1e-9, 1.0
        problem = problem.without_constraints()
    if retries < 0 or sweeps < 1:
        raise InputError("retries must be >= 0 and sweeps >= 1")
    _interp.kernels_for(problem.n, problem.K)  # a large job: its blocks run compiled
    if workers < 0:
        raise InputError(f"workers must be >= 0, not {workers}")
    if scheduler is not None and workers < 1:
        raise InputError(
            "scheduler needs workers >= 1 (the wave schedule); workers=0 is the sequential sweep"
        )
    counts: tuple[int, ...] = ()
    if problem.positions is not None:
        boxes, counts = _position_grid(problem, block)
    else:
        boxes = None
    m = _block_shape(block, problem.shape) if boxes is None else (0,)
    if init is None:
        grid = trivial_solution(problem).reshape(-1).copy()
        init_kind = "trivial"
    else:
        g0 = np.asarray(init)
        if g0.shape != problem.shape:
            raise InputError(f"init grid has shape {g0.shape}, the problem {problem.shape}")
        v = problem.violations(g0)
        if len(v):
            raise InputError(f"init grid is not consistent:\n{v.describe(5)}")
        grid = g0.reshape(-1).astype(np.int32).copy()
        init_kind = "given"
    idx = np.arange(problem.n, dtype=np.int64).reshape(problem.shape)
    if boxes is None:
        starts = [block_starts(s, b) for s, b in zip(problem.shape, m, strict=True)]
        counts = tuple(len(st) for st in starts)
        boxes = [
            idx[tuple(slice(a, a + b) for a, b in zip(q, m, strict=True))].reshape(-1)
            for q in itertools.product(*starts)
        ]
    soft = _Soft(energy, float(temperature), float(cooling)) if energy is not None else None
    plan = _Plan(retries, sweeps, order, choice, deadline)
    if workers >= 1:
        if choice == "resemblance" or soft is not None or exact != "none":
            raise InputError(
                "choice='resemblance', energy= and exact= run in the thesis' sweep (workers=0)"
            )
        status, tried, accepted, retry_count, revisions = _run_waves(
            problem, grid, boxes, counts, None if m == (0,) else m, rng, plan,
            workers=workers, scheduler=scheduler,
        )  # fmt: skip
    else:
        completion = ExactCompletion(exact) if exact != "none" else None
        status, tried, accepted, retry_count, revisions = _run_sweep(
            problem, grid, boxes, None if m == (0,) else m, rng, plan, window=window, soft=soft,
            completion=completion, progress=progress,
        )  # fmt: skip
    out = grid.reshape(problem.shape)
    final = len(problem.violations(out))
    stats: dict[str, Any] = {
        "block": list(m) if m != (0,) else _block_list(block, problem),
        "blocks_tried": tried,
        "blocks_accepted": accepted,
        "retries": retry_count,
        "acceptance_rate": accepted / tried if tried else 1.0,
        "final_violations": final,
        "init": init_kind,
        "revisions": revisions,
        "order": order,
        "choice": choice,
        "workers": workers,
    }
    if scheduler is not None:
        stats["scheduler"] = scheduler
    if soft is not None:
        stats.update(energy=soft.E, energies=soft.trace, metropolis_rejected=soft.rejected,
                     temperature=soft.T0, cooling=soft.cooling)  # fmt: skip
    if repair is not None:
        stats["breaches"] = repair(out)
    if exact != "none":
        stats["exact"] = exact
        if workers == 0 and completion is not None:
            stats["exact_blocks"] = completion.solved
            stats["exact_refuted"] = completion.refuted
    if final and status == "solved":  # cannot happen: every accepted block is consistent
        status = "failed"
    return status, out, stats


#: the whole problem's estimated peak memory from which ``csplab synthesize --solver
#: blocks`` streams it (:func:`stream_blocks`) when it can
STREAM_BYTES = 1 << 30


def streams(
    windows: GridWindows, *, workers: int = 0, init: Any = None, order: str = "scanline",
    choice: str = "uniform", exact: str = "none", energy: Any = None, **_: Any,
) -> str | None:  # fmt: skip
    """Why the thesis' sweep on ``windows`` cannot be streamed (:func:`stream_blocks`),
    or ``None`` when it can: the compiled sweep's settings, no starting grid, and a
    trivial solution that is one label or uniform layers."""
    if workers != 0:
        return "the wave schedule (workers >= 1) visits blocks across the whole model"
    if init is not None or exact != "none" or energy is not None:
        return "init=, exact= and energy= need the whole model"
    if choice not in ("uniform", "weighted") or order == "random":
        return "the random order and resemblance choice run in the Python sweep"
    _interp.kernels_for(windows.n, windows.K)  # a large job: its blocks run compiled
    if not _interp.compiled_engine():
        return "the compiled kernels are not loaded (CSPLAB_ENGINE=interp, or a small job)"
    if windows.miniature().value_weights is not None:
        return "per-class weights run in the Python sweep"
    if _trivial_plan(windows.miniature) is None:
        return "no trivial solution of one label or uniform layers"
    return None


def stream_blocks(
    windows: GridWindows,
    rng: np.random.Generator,
    *,
    block: int | Sequence[int] = 10,
    retries: int = 20,
    sweeps: int = 1,
    order: str = "scanline",
    choice: str = "uniform",
    deadline: float | None = None,
    out: NDArray[np.int32] | None = None,
    progress: bool = False,
) -> tuple[Status, NDArray[np.int32], dict[str, Any]]:
    """The thesis' sweep (Alg. 3.4, ``workers=0``) on a problem built window by window.

    The same blocks in the same order with the same random stream as :func:`run_blocks`,
    so the same grid and counts for a seed (tested), without the whole problem: the blocks
    at one ``x`` origin (all their ``y``, ``z``) are swept by one compiled kernel call
    (:func:`csplab.catalog.sweep_blocks`) on the slab of the grid they touch, whose
    domains and arcs are those of :meth:`GridWindows.window` (a handful of slab problems
    serve the whole sweep, thesis Sec. 3.3.6: what a block needs is its neighbourhood).
    The trivial solution is found on :meth:`GridWindows.miniature` problems and painted
    slab by slab. The output (``out``, e.g. a memory map, or a new array) is the only
    array of the model's size; the final check is :meth:`GridWindows.violations`.

    Parameters
    ----------
    windows : GridWindows
        The problem (square grid, no periodic axis, no global constraints).
    rng : numpy.random.Generator
        The randomness (one stream, as the thesis' sweep).
    block, retries, sweeps, order, choice
        As declared by :class:`BlocksSolver`.
    deadline : float, optional
        ``time.perf_counter()`` value at which the sweeps stop.
    out : int32 array of the output's shape, optional
        Where to write the labels.
    progress : bool
        A progress bar on stderr (after 2 s).

    Returns
    -------
    status : {"solved", "timeout", "failed"}
        ``failed`` only if the final check found a violation (never expected).
    grid : int32 array of the output's shape
    stats : dict
        As :func:`run_blocks`'s, with ``slab_problems`` (the slab problems built).

    Raises
    ------
    InputError
        When :func:`streams` gives a reason, or ``out`` does not fit.
    """
    why = streams(windows, order=order, choice=choice)
    if why is not None:
        raise InputError(f"modify in blocks cannot be streamed: {why}")
    if retries < 0 or sweeps < 1:
        raise InputError("retries must be >= 0 and sweeps >= 1")
    shape = windows.shape
    plan = _trivial_plan(windows.miniature)
    assert plan is not None
    grid = np.empty(shape, dtype=np.int32) if out is None else out
    if grid.shape != shape or grid.dtype != np.int32 or not grid.flags.c_contiguous:
        raise InputError(f"out must be a C-ordered int32 array of shape {shape}")
    m = _block_shape(block, shape)
    starts = [block_starts(s, b) for s, b in zip(shape, m, strict=True)]
    r, nx = windows.reach, shape[0]
    scan = _block_scan(m, order)
    counters = np.zeros(4, dtype=np.int64)  # tried, accepted, retries, revisions
    painted = 0  # the trivial solution is painted ahead of the sweep, slab by slab
    slabs: dict[tuple[tuple[int, ...], int], tuple[NDArray[np.int64], NDArray[np.int64]]] = {}
    status: Status = "solved"
    units = [a for _ in range(sweeps) for a in starts[0]]  # the x origins, sweep by sweep
    for a in progress_bar(units, total=len(units), desc="blocks", enabled=progress,
                          unit="slab"):  # fmt: skip
        lo, hi = max(0, a - r), min(nx, a + m[0] + r)
        if hi > painted:
            _paint(plan, grid[painted:hi], painted)
            painted = hi
        P = windows.window((lo, *(0,) * (len(shape) - 1)), (hi, *shape[1:]))
        key = (P.shape, a - lo)
        if key not in slabs:  # the blocks of this x origin, in the slab's cell numbers
            idx = np.arange(P.n, dtype=np.int64).reshape(P.shape)
            cells = [
                idx[(slice(a - lo, a - lo + m[0]),
                     *(slice(q, q + b) for q, b in zip(rest, m[1:], strict=True)))].reshape(-1)
                for rest in itertools.product(*starts[1:])
            ]  # fmt: skip
            bptr = np.arange(len(cells) + 1, dtype=np.int64) * int(np.prod(m))
            slabs[key] = (bptr, np.concatenate(cells))
        bptr, bcells = slabs[key]
        view = grid.reshape(nx, -1)[lo:hi].reshape(-1)  # the slab's cells, in place
        for b0 in range(0, len(bptr) - 1, _SWEEP_CHUNK):
            if deadline is not None and time.perf_counter() > deadline:
                status = "timeout"
                break
            sweep_blocks(P, view, bptr, bcells, (b0, min(b0 + _SWEEP_CHUNK, len(bptr) - 1)),
                         scan, retries, order, choice, rng, counters)  # fmt: skip
        if status == "timeout":
            break
    if painted < nx:
        _paint(plan, grid[painted:], painted)
    final = windows.violations(grid)
    tried, accepted, retry_count, revisions = (int(x) for x in counters)
    stats: dict[str, Any] = {
        "block": list(m),
        "blocks_tried": tried,
        "blocks_accepted": accepted,
        "retries": retry_count,
        "acceptance_rate": accepted / tried if tried else 1.0,
        "final_violations": final,
        "init": "trivial",
        "revisions": revisions,
        "order": order,
        "choice": choice,
        "workers": 0,
        "slab_problems": len(windows.built),
    }
    if final and status == "solved":  # cannot happen: every accepted block is consistent
        status = "failed"
    return status, grid, stats


_Counts = tuple[Status, int, int, int, int]  # status, tried, accepted, retries, revisions


class _Plan(NamedTuple):
    """The settings of Alg. 3.4 that the sweep and the waves share: retries per block,
    sweeps, Alg. 3.1's order and choice, and the deadline (a ``time.perf_counter()``
    value)."""

    retries: int
    sweeps: int
    order: str
    choice: str
    deadline: float | None


class ExactCompletion:
    """Exact block completion: an exact solver on a block's subproblem (its border fixed),
    seeded by one number drawn from the sweep's generator (deterministic for a seed)."""

    def __init__(self, solver: str) -> None:
        self.solver = solver
        self.solved = 0  # blocks completed exactly
        self.refuted = 0  # blocks proved to have no labels fitting their border

    def __call__(
        self, sub: Problem, rng: np.random.Generator, left: float | None
    ) -> tuple[NDArray[np.int32] | None, bool]:
        """The block's new labels (flat) or ``None``, and whether the time ran out."""
        from csplab.solvers import solver_class

        if left is not None and left <= 0:
            return None, True
        seed = int(rng.integers(2**62))
        opts: dict[str, Any] = {} if left is None else {"time_limit": left}
        r = solver_class(self.solver)().solve(
            sub, rng=np.random.default_rng(seed), seed=seed, **opts
        )
        if r.status == "solved" and sub.is_solution(r.grid):
            self.solved += 1
            return np.asarray(r.grid, dtype=np.int32).reshape(-1), False
        if r.status == "unsat":
            self.refuted += 1
        return None, r.status == "timeout"


class _Soft:
    """Metropolis acceptance of consistent blocks under an energy (2007 paper Sec. 4.2)."""

    def __init__(self, energy: Energy, temperature: float, cooling: float) -> None:
        if not temperature > 0 or not 0 < cooling <= 1:
            raise InputError("temperature must be > 0 and cooling in (0, 1]")
        self.energy, self.T0, self.T, self.cooling = energy, temperature, temperature, cooling
        self.shape: tuple[int, ...] = ()
        self.E = float("nan")
        self.trace: list[float] = []
        self.rejected = 0

    def start(self, grid: Any, shape: tuple[int, ...]) -> None:
        """The energy of the starting model (``grid`` flat)."""
        self.shape = shape
        self.E = self.energy(grid.reshape(shape))
        self.trace = [self.E]

    def accept(self, grid: Any, cells: Any, labels: Any, rng: np.random.Generator) -> bool:
        new = grid.copy()
        new[cells] = labels
        E2 = self.energy(new.reshape(self.shape))
        dE = E2 - self.E
        if dE <= 0 or rng.random() < math.exp(-dE / self.T):
            self.E = E2
            return True
        self.rejected += 1
        return False

    def end_sweep(self) -> None:
        self.trace.append(self.E)
        self.T *= self.cooling


def _run_sweep(
    problem: Problem,
    grid: NDArray[np.int32],
    boxes: Sequence[NDArray[np.int64]],
    m: tuple[int, ...] | None,
    rng: np.random.Generator,
    plan: _Plan,
    *,
    window: int = 1,
    soft: _Soft | None = None,
    completion: ExactCompletion | None = None,
    progress: bool = False,
) -> _Counts:
    """The thesis' sweep (``workers=0``): every block in turn, one random stream; updates
    ``grid`` (flat) in place. A step solves one block (``block_step``: Alg. 3.1 on its
    subproblem, retried by :func:`csplab.engine.waves.solve_block`, its labels kept if
    consistent and accepted by ``soft``) or, with the compiled kernels loaded and a plain
    setting (grid blocks, scan or entropy orders, uniform or weighted choice, no energy),
    the :data:`_SWEEP_CHUNK` blocks from the given one on in one kernel call
    (:func:`_chunk_step`: the same blocks, draws and results); the deadline is checked
    between steps; ``progress``: a bar on stderr (after 2 s) counting the steps."""
    retries, sweeps, order, choice, deadline = plan
    counters = np.zeros(4, dtype=np.int64)  # tried, accepted, retries, revisions
    touching = _arc_index(problem) if len(boxes) > 1 else None

    def block_step(b: int) -> bool:  # False when the time ran out
        cells = boxes[b]
        if not cells.size:
            return True
        arc_ids = None if touching is None else _arcs_touching(cells, *touching)
        sub = problem.subproblem(cells, grid, shape=m, arc_ids=arc_ids)
        ctx = (grid, cells, problem.shape) if choice == "resemblance" else None
        o = wv.solve_block(sub, rng, 0, retries=retries, order=order, choice=choice,
                           deadline=deadline, window=window, context=ctx)  # fmt: skip
        counters[:] += (1, 0, o.retries, o.revisions)
        labels = o.labels
        if labels is None and o.status != "timeout" and completion is not None:
            # every Alg. 3.1 run failed: complete the block exactly
            left = None if deadline is None else deadline - time.perf_counter()
            labels, timed_out = completion(sub, rng, left)
            if timed_out:
                return False
        if labels is not None and (soft is None or soft.accept(grid, cells, labels, rng)):
            grid[cells] = labels
            counters[1] += 1
        return o.status != "timeout"

    step: Callable[[int], bool] = block_step
    units = range(len(boxes))
    if (completion is None and problem.value_weights is None
            and _compiled_sweep_applies(boxes, m, order, choice, soft)):  # fmt: skip
        assert m is not None
        step = _chunk_step(problem, grid, boxes, m, rng, retries, order, choice, counters)
        units = range(0, len(boxes), _SWEEP_CHUNK)
    status: Status = "solved"
    if soft is not None:
        soft.start(grid, problem.shape)
    unit_name = "block" if step is block_step else f"x{_SWEEP_CHUNK} blocks"
    for sweep in range(sweeps):
        for unit in progress_bar(units, total=len(units), desc=_desc(sweep, sweeps),
                                 enabled=progress, unit=unit_name):  # fmt: skip
            if (deadline is not None and time.perf_counter() > deadline) or not step(unit):
                status = "timeout"
                break
        if soft is not None:
            soft.end_sweep()
        if status == "timeout":
            break
    tried, accepted, retry_count, revisions = (int(x) for x in counters)
    return status, tried, accepted, retry_count, revisions


_SWEEP_CHUNK = 64  # blocks per kernel call (the deadline is checked between calls)


def _desc(sweep: int, sweeps: int) -> str:
    return "blocks" if sweeps == 1 else f"blocks, sweep {sweep + 1}/{sweeps}"


def _compiled_sweep_applies(
    boxes: Sequence[NDArray[np.int64]], m: tuple[int, ...] | None, order: str, choice: str,
    soft: _Soft | None,
) -> bool:  # fmt: skip
    # grid blocks (m given) are C-order slices of the cell numbers: sorted, as the kernels
    # need; boxes of positions are not
    return (
        m is not None
        and soft is None
        and choice in ("uniform", "weighted")
        and order != "random"
        and _interp.compiled_engine()
    )


def _block_scan(m: tuple[int, ...], order: str) -> NDArray[np.int64]:
    """The cell order inside a block (``arange`` for the entropy orders, unused there)."""
    scan = scan_order(m, order)
    n = int(np.prod(m))
    return np.arange(n, dtype=np.int64) if scan is None else scan.astype(np.int64)


def _chunk_step(
    problem: Problem,
    grid: NDArray[np.int32],
    boxes: Sequence[NDArray[np.int64]],
    m: tuple[int, ...],
    rng: np.random.Generator,
    retries: int,
    order: str,
    choice: str,
    counters: NDArray[np.int64],
) -> Callable[[int], bool]:
    """The sweep's step on the :data:`_SWEEP_CHUNK` blocks from block ``a`` on in one
    compiled kernel call (:func:`csplab.catalog.sweep_blocks`, which adds to
    ``counters``)."""
    nb = int(np.prod(m))
    scan = _block_scan(m, order)
    sizes = np.array([b.size for b in boxes], dtype=np.int64)
    bptr = np.zeros(len(boxes) + 1, dtype=np.int64)
    np.cumsum(sizes, out=bptr[1:])
    bcells = np.concatenate(list(boxes)).astype(np.int64) if boxes else np.zeros(0, np.int64)
    if np.any((sizes != nb) & (sizes > 0)):
        raise AssertionError("grid blocks all have the block's shape")

    def step(a: int) -> bool:
        span = (a, min(a + _SWEEP_CHUNK, len(boxes)))
        sweep_blocks(problem, grid, bptr, bcells, span, scan, retries, order, choice, rng,
                     counters)  # fmt: skip
        return True

    return step


def _run_waves(
    problem: Problem,
    grid: NDArray[np.int32],
    boxes: Sequence[NDArray[np.int64]],
    counts: tuple[int, ...],
    m: tuple[int, ...] | None,
    rng: np.random.Generator,
    plan: _Plan,
    *,
    workers: int,
    scheduler: str | None,
) -> _Counts:
    """The wave schedule (``workers >= 1``, see the module docstring); updates ``grid``
    (flat) in place after each wave."""
    retries, sweeps, order, choice, deadline = plan
    root = int(rng.integers(2**63))
    compiled = problem.value_weights is None and _compiled_sweep_applies(
        boxes, m, order, choice, None)  # per-class weights: the subproblems carry them
    touching: Callable[[NDArray[np.int64]], NDArray[np.int64]] | None = None
    if not compiled:  # arc ids for the subproblems (the compiled blocks read the CSR rows)
        indptr, ids = _arc_index(problem)

        def touching(cells: NDArray[np.int64]) -> NDArray[np.int64]:
            return _arcs_touching(cells, indptr, ids)

    def near(cells: NDArray[np.int64]) -> NDArray[np.int64]:
        return neighbourhood(problem, cells)

    classes = wv.colour_classes(counts)
    assert sum(len(c) for c in classes) == len(boxes), "one block per lattice index"
    scan = _block_scan(m, order) if compiled and m is not None else None
    vt = None if problem.value_weights is None else problem.value_weights[0]
    ctx = wv.BlockContext(problem.relations, problem.weights, retries, order, choice, root,
                          size=problem.n * problem.K, compiled=compiled, scan=scan,
                          value_table=vt)  # fmt: skip
    runner: wv.BlockRunner | None = None
    if scheduler is not None or workers > 1:
        runner = wv.BlockRunner(workers, ctx, scheduler)
    tried = accepted = retry_count = revisions = 0
    status: Status = "solved"
    stopped = False  # a wave did not finish in time: its workers are stopped
    try:
        for sweep in range(sweeps):
            for wave in wv.waves(classes, boxes, problem.n, len(problem.arcs), touching,
                                 near if compiled else None):  # fmt: skip
                if deadline is not None and time.perf_counter() > deadline:
                    status = "timeout"
                    break
                outcomes: list[wv.BlockOutcome] = []
                if runner is None:
                    for b in wave:
                        if deadline is not None and time.perf_counter() > deadline:
                            stopped = True
                            break
                        if compiled:
                            arrays = block_arrays(problem, grid, b.cells)
                            task = wv.CompiledTask(b.block, sweep, arrays)
                            outcomes.append(wv.solve_compiled(task, ctx))
                            continue
                        sub = problem.subproblem(b.cells, grid, shape=m, arc_ids=b.arc_ids)
                        outcomes.append(
                            wv.solve_block(
                                sub,
                                wv.block_rng(root, sweep, b.block),
                                b.block,
                                retries=retries,
                                order=order,
                                choice=choice,
                                deadline=deadline,
                            )
                        )
                else:
                    size = wv.chunk_size(len(wave), runner.size)
                    wall = (
                        None if deadline is None else time.time() + deadline - time.perf_counter()
                    )
                    futures: list[Any] = []
                    chunk: list[wv.BlockTask | wv.CompiledTask] = []
                    for b in wave:
                        if compiled:
                            arrays = block_arrays(problem, grid, b.cells).compact()
                            chunk.append(wv.CompiledTask(b.block, sweep, arrays))
                        else:
                            sub = problem.subproblem(b.cells, grid, shape=m, arc_ids=b.arc_ids)
                            chunk.append(wv.pack_block(sub, b.block, sweep))
                        if len(chunk) == size:
                            futures.append(runner.submit(chunk, wall))
                            chunk = []
                    if chunk:
                        futures.append(runner.submit(chunk, wall))
                    wait_s = (
                        None
                        if deadline is None
                        else max(0.0, deadline - time.perf_counter()) + wv.GRACE_S
                    )
                    outcomes, complete = runner.gather(futures, wait_s)
                    stopped = not complete
                # the blocks of a wave are independent: any of their results may be kept
                cells_of = {b.block: b.cells for b in wave}
                for o in sorted(outcomes, key=lambda o: o.block):
                    tried += 1
                    retry_count += o.retries
                    revisions += o.revisions
                    if o.labels is not None:
                        grid[cells_of[o.block]] = o.labels
                        accepted += 1
                    elif o.status == "timeout":
                        status = "timeout"
                if stopped:
                    status = "timeout"
                if status == "timeout":
                    break
            if status == "timeout":
                break
    except BaseException:
        if runner is not None:
            runner.close(kill=True)
        raise
    if runner is not None:
        runner.close(kill=stopped or status == "timeout")
    return status, tried, accepted, retry_count, revisions


def _arc_index(problem: Problem) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """Arcs by cell (CSR ``indptr, arc ids``): each arc listed under both its ends."""
    a = problem.arcs
    ends = np.concatenate([a[:, 0], a[:, 1]])
    ids = np.concatenate([np.arange(len(a)), np.arange(len(a))]).astype(np.int64)
    order = np.argsort(ends, kind="stable")
    indptr = np.searchsorted(ends[order], np.arange(problem.n + 1)).astype(np.int64)
    return indptr, ids[order]


def _arcs_touching(
    cells: NDArray[np.int64], indptr: NDArray[np.int64], ids: NDArray[np.int64]
) -> NDArray[np.int64]:
    """The sorted ids of the arcs with an end in ``cells``."""
    start, lens = indptr[cells], indptr[cells + 1] - indptr[cells]
    first = np.cumsum(lens) - lens
    pos = np.repeat(start - first, lens) + np.arange(int(lens.sum()))
    out = np.sort(ids[pos])
    if out.size > 1:  # np.unique, without its hashing (4x faster on a block's few thousand ids)
        keep = np.empty(out.size, dtype=bool)
        keep[0] = True
        np.not_equal(out[1:], out[:-1], out=keep[1:])
        out = out[keep]
    return out


def _block_list(block: int | Sequence[int], problem: Problem) -> list[int]:
    d = 1 if problem.positions is None else problem.positions.shape[1]
    return [int(block)] * d if isinstance(block, int | np.integer) else [int(b) for b in block]


def _position_boxes(problem: Problem, block: int | Sequence[int]) -> list[NDArray[np.int64]]:
    """Cells in overlapping boxes of ``block`` position units per axis (problems with
    :attr:`Problem.positions`, such as continuous models: boxes in line spacings), shifted
    by half a box, x outermost; a cell on a box's border belongs to it."""
    return _position_grid(problem, block)[0]


def _position_grid(
    problem: Problem, block: int | Sequence[int]
) -> tuple[list[NDArray[np.int64]], tuple[int, ...]]:
    """:func:`_position_boxes` and the number of boxes per axis (their lattice)."""
    pos = problem.positions
    assert pos is not None
    d = pos.shape[1]
    m = _block_list(block, problem)
    if len(m) == 1:
        m = m * d
    if len(m) != d or any(b < 1 for b in m):
        raise InputError(f"block size {block!r} must be positive, one per axis of {d}")
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    starts = [
        [lo[a] + s for s in block_starts(max(1, int(np.ceil(hi[a] - lo[a]))), m[a])]
        for a in range(d)
    ]
    out = []
    for q in itertools.product(*starts):
        inside = np.ones(problem.n, dtype=bool)
        for a in range(d):
            inside &= (pos[:, a] >= q[a] - 1e-9) & (pos[:, a] <= q[a] + m[a] + 1e-9)
        out.append(np.flatnonzero(inside).astype(np.int64))
    return out, tuple(len(st) for st in starts)


def _block_arg(value: Any) -> int | tuple[int, ...]:
    if isinstance(value, str):
        from csplab.grids import parse_shape

        shp = parse_shape(value, what="block")
        return shp[0] if len(shp) == 1 else shp
    if isinstance(value, int | np.integer) and not isinstance(value, bool):
        if value < 1:
            raise InputError(f"must be positive, not {value!r}")
        return int(value)
    if isinstance(value, Sequence) and all(isinstance(v, int | np.integer) for v in value):
        return tuple(int(v) for v in value)
    raise InputError(f"must be a positive int or one per axis, e.g. 10 or 10x10x4, not {value!r}")


def _scheduler_arg(value: Any) -> str:
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"must be 'local' or a Dask scheduler address, not {value!r}")
    v = value.strip()
    if v != "local" and ":" not in v:
        raise InputError(f"must be 'local' or an address such as tcp://host:8786, not {v!r}")
    return v


def _energy_arg(value: Any) -> Energy:
    if not isinstance(value, Energy):
        raise InputError(f"must be a csplab.soft.Energy, not {type(value).__name__}")
    return value


def _positive(value: Any) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if isinstance(value, bool) or not v > 0 or not math.isfinite(v):
        raise InputError(f"must be a positive number, not {value!r}")
    return v


class BlocksSolver(Solver):
    """Alg. 3.4: modify a consistent model in overlapping blocks (never inconsistent)."""

    name = "blocks"
    alg31 = True
    complete = False
    description = "Merrell Alg. 3.4, modify in overlapping blocks"
    notes = (
        "starts from a trivial solution (empty space, or ground under empty space) or `init=`; "
        "`block=10`, `retries=20`; the output is always consistent; global constraints: a "
        "block that breaks them more is rejected, so `sweeps` repair the model (`failed` "
        "if one is still broken); soft constraints by Metropolis (`energy=`); "
        '`exact="sat"` completes a block whose retries all fail exactly, its border fixed '
        "(how the default chain finishes a model too large for SAT)"
    )
    options = (
        Option("block", object, 10, "block size per axis (an int or one per axis, e.g. 10x10x4)",
               convert=_block_arg),
        Option("retries", int, 20, "extra Alg. 3.1 attempts per block after a failure",
               minimum=0),
        Option("init", object, None, "a consistent starting grid (default: a trivial solution)",
               nullable=True),
        Option("sweeps", int, 1, "passes over all blocks", minimum=1),
        order_option(doc="cell order of Alg. 3.1 inside each block"),
        CHOICE,
        TIME_LIMIT,
        Option("workers", int, 0,
               "the thesis' sweep (0) or waves of independent blocks on N processes "
               "(1: in-process; another order and random stream, the same for every N)",
               minimum=0),
        Option("scheduler", str, None,
               "with workers: local (a Dask LocalCluster of N processes) or a Dask scheduler "
               "address; default a local process pool", nullable=True, convert=_scheduler_arg),
        WINDOW,
        Option("energy", object, None, "soft constraints: a csplab.soft.Energy; consistent "
               "blocks are kept with Metropolis probability (2007 paper Sec. 4.2)",
               nullable=True, convert=_energy_arg),
        Option("temperature", float, 1.0, "Metropolis temperature T at the first sweep",
               convert=_positive),
        Option("cooling", float, 1.0, "T is multiplied by this after each sweep (0 < c <= 1)",
               convert=_positive),
        Option("exact", str, "none", "exact block completion: a block whose retries all fail "
               "is solved by sat or backtrack with its border fixed (none: Alg. 3.4's restore)",
               values=("none", "sat", "backtrack")),
        Option("progress", bool, False, "a progress bar on stderr (after 2 s; the CLI's default)"),
    )  # fmt: skip

    def run(self, problem: Problem, call: Call) -> Result:
        options = {k: v for k, v in call.options.items() if k != "time_limit"}
        status, grid, stats = run_blocks(problem, call.rng, deadline=call.deadline, **options)
        return self.result(status, grid, problem, stats, call)

    def stream(
        self, windows: GridWindows, *, rng: np.random.Generator, seed: int | None,
        **options: Any,
    ) -> Result:  # fmt: skip
        """:func:`stream_blocks` with this solver's options: the thesis' sweep on a problem
        built window by window, the same grid as :meth:`solve` on the whole problem.

        Parameters
        ----------
        windows : GridWindows
            The problem.
        rng : numpy.random.Generator
            The randomness.
        seed : int or None
            The seed ``rng`` was made from, recorded in the result.
        **options
            The solver's options (validated as :meth:`solve` does).

        Returns
        -------
        Result
            ``solved`` or ``timeout``; its ``problem`` is ``None`` (there is no whole one).

        Raises
        ------
        InputError
            When an option is invalid or :func:`streams` gives a reason.
        CsplabError
            When the windowed check finds a violation (a bug).
        """
        call = Call(rng, seed, None, self.validate(options))
        o = call.options
        why = streams(windows, **o)
        if why is not None:
            raise InputError(f"modify in blocks cannot be streamed: {why}")
        status, grid, stats = stream_blocks(
            windows, call.rng, block=o["block"], retries=o["retries"], sweeps=o["sweeps"],
            order=o["order"], choice=o["choice"], deadline=call.deadline,
            progress=o["progress"],
        )  # fmt: skip
        if stats["final_violations"]:  # every accepted block is consistent: a bug
            raise CsplabError(f"the streamed sweep returned a grid with "
                              f"{stats['final_violations']} violations (a bug in csplab)")
        stats["violations"] = 0
        return Result(status, grid, self.name, seed=seed, time_s=time.perf_counter() - call.t0,
                      stats=stats)  # fmt: skip
