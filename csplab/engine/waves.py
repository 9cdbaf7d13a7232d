"""Wave schedule of modify-in-blocks: independent blocks solved in parallel.

Blocks that neither overlap nor are joined by an arc are independent: solving one does not
change what another sees, so they may run at the same time against the same grid. The
blocks of Alg. 3.4 (thesis Sec. 3.3.6) are laid out on a lattice of block indices (one per
axis, shifted by half a block); :func:`colour_classes` colours each block by its index
modulo 3 on each axis (``3 ** d`` colours). Two blocks of one colour are at least three
half-block steps apart on some axis, so a gap of ``3 * (m // 2) - m`` cells separates them
(half a block for an even ``m``) and no nearest-neighbour arc joins them. :func:`waves`
checks this on the arcs themselves: a block that shares an arc or a cell with an earlier
block of its wave is deferred to a following wave. That happens only where the lattice is
not regular or the gap is too small -- a last block flush with the end of its axis, a
periodic axis (wrap-around arcs), blocks of 3 cells (no gap), boxes of positions joined by
arcs longer than the gap -- so every wave it yields is independent whatever the problem.
:func:`independent` is the brute-force check the tests use.

Each block draws its random numbers from its own generator, :func:`block_rng`, seeded with
``numpy.random.SeedSequence([root, sweep, block])``; the outcome of a wave therefore does
not depend on which process solves which block, nor in which order. Executors:

* in-process (``workers=1``): :func:`solve_block` on each block in turn;
* with the compiled kernels loaded and a plain setting (grid blocks, scan or entropy
  orders, uniform or weighted choice; :class:`BlockContext` ``compiled``), a block is its
  arrays (:class:`CompiledTask`: its catalog and internal arcs, built by a kernel in the
  parent) and one kernel call solves it (:func:`solve_compiled`), with the same generator,
  draws and outcome as :func:`solve_block` on its subproblem;
* :class:`BlockRunner`: worker processes (:class:`csplab.engine.pool.Workers`: a local
  process pool, or a Dask ``distributed`` cluster, ``"local"`` for a
  ``distributed.LocalCluster``; the optional extra ``csplab[dask]``); each task carries a
  few blocks (:class:`BlockTask`: packed domains and the block's arcs; the relations and
  weights, the same for every block, reach each worker once).

Examples
--------
>>> colour_classes((4, 2))
[[0, 6], [1, 7], [2], [3], [4], [5]]
>>> int(block_rng(7, 0, 3).integers(100)) == int(block_rng(7, 0, 3).integers(100))
True
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from csplab import _interp
from csplab.catalog import BlockArrays, SupportTables, solve_block_arrays, support_tables
from csplab.engine.alg31 import run_alg31
from csplab.engine.pool import Workers
from csplab.problem import Problem

__all__ = [
    "BlockContext",
    "BlockOutcome",
    "BlockRunner",
    "BlockTask",
    "CompiledTask",
    "block_rng",
    "colour_classes",
    "independent",
    "pack_block",
    "run_tasks",
    "solve_block",
    "solve_compiled",
    "waves",
]

#: seconds the parent waits past the time limit for a wave before it stops the workers
GRACE_S = 2.0


def colour_classes(counts: Sequence[int]) -> list[list[int]]:
    """Flat block indices grouped by colour (block index modulo 3 on each axis).

    Parameters
    ----------
    counts : sequence of int
        Blocks per axis; blocks are numbered in C order (x outermost, the thesis' sweep).

    Returns
    -------
    list of list of int
        One list per non-empty colour, colours in C order, blocks in sweep order.
    """
    counts = tuple(int(c) for c in counts)
    classes: dict[tuple[int, ...], list[int]] = {}
    for flat, q in enumerate(itertools.product(*(range(c) for c in counts))):
        classes.setdefault(tuple(i % 3 for i in q), []).append(flat)
    return [classes[k] for k in sorted(classes)]


class WaveBlock(NamedTuple):
    """A block of a wave: its flat index, its cells and the sorted ids of its arcs."""

    block: int
    cells: NDArray[np.int64]
    arc_ids: NDArray[np.int64] | None


def waves(
    classes: Sequence[Sequence[int]],
    cells: Sequence[NDArray[np.int64]],
    n_cells: int,
    n_arcs: int,
    touching: Callable[[NDArray[np.int64]], NDArray[np.int64]] | None,
    near: Callable[[NDArray[np.int64]], NDArray[np.int64]] | None = None,
) -> Iterator[list[WaveBlock]]:
    """The waves of one sweep: colour classes split so that every wave is independent.

    Within a colour class, a block joins the current wave unless it shares a cell or an arc
    (``touching(cells)``: the sorted ids of the arcs with an end in ``cells``) with a block
    already in it; such a block waits for the next wave of the class (first fit, in sweep
    order, so the schedule depends on the problem only). Empty blocks are skipped. The
    generator is lazy: the caller may change the grid between waves. Instead of
    ``touching``, ``near(cells)`` may give the cells and their neighbours across the arcs:
    a block that shares an arc or a cell with another has a cell of it in that
    neighbourhood, so the waves are the same (and no arc ids are built:
    :attr:`WaveBlock.arc_ids` is ``None``).
    """
    arc_mark = np.zeros(n_arcs if near is None else 0, dtype=bool)
    cell_mark = np.zeros(n_cells, dtype=bool)
    for cls in classes:
        pending = [b for b in cls if cells[b].size]
        while pending:
            wave: list[WaveBlock] = []
            deferred: list[int] = []
            for b in pending:
                c = cells[b]
                if near is not None:
                    if cell_mark[near(c)].any():
                        deferred.append(b)
                        continue
                    cell_mark[c] = True
                    wave.append(WaveBlock(b, c, None))
                    continue
                assert touching is not None
                ids = touching(c)
                if arc_mark[ids].any() or cell_mark[c].any():
                    deferred.append(b)
                    continue
                arc_mark[ids] = True
                cell_mark[c] = True
                wave.append(WaveBlock(b, c, ids))
            for w in wave:  # unmark for the next wave
                if w.arc_ids is not None:
                    arc_mark[w.arc_ids] = False
                cell_mark[w.cells] = False
            yield wave
            pending = deferred


def independent(arcs: NDArray[np.int64], n_cells: int, blocks: Sequence[NDArray[np.int64]]) -> bool:
    """Brute force: no two of ``blocks`` share a cell and no arc joins two of them."""
    owner = np.full(n_cells, -1, dtype=np.int64)
    for i, c in enumerate(blocks):
        if (owner[c] >= 0).any():
            return False
        owner[c] = i
    a, b = owner[arcs[:, 0]], owner[arcs[:, 1]]
    return not bool(((a >= 0) & (b >= 0) & (a != b)).any())


def block_rng(root: int, sweep: int, index: int) -> np.random.Generator:
    """The generator of block ``index`` in sweep ``sweep`` of a run with seed ``root``."""
    return np.random.default_rng(np.random.SeedSequence([int(root), int(sweep), int(index)]))


class BlockOutcome(NamedTuple):
    """What solving one block gives: ``labels`` (``None`` unless ``status == "solved"``),
    the status of the last Alg. 3.1 run, the retries and the AC revisions spent."""

    block: int
    labels: NDArray[np.int32] | None
    status: str
    retries: int
    revisions: int


def solve_block(
    sub: Problem,
    rng: np.random.Generator,
    block: int,
    *,
    retries: int,
    order: str,
    choice: str,
    deadline: float | None,
    window: int = 1,
    context: tuple[Any, Any, tuple[int, ...]] | None = None,
) -> BlockOutcome:
    """Alg. 3.1 on a block's subproblem, retried up to ``retries`` times on failure (the
    inner loop of Alg. 3.4); ``deadline`` is a ``time.perf_counter()`` value; ``window``
    and ``context`` go to :func:`~csplab.engine.alg31.run_alg31` (resemblance choice)."""
    revisions = retry_count = 0
    status = "failed"
    for attempt in range(retries + 1):
        left = None if deadline is None else max(0.0, deadline - time.perf_counter())
        r = run_alg31(sub, rng, order=order, choice=choice, time_limit=left, window=window,
                      context=context)  # fmt: skip
        revisions += int(r.stats.get("revisions", 0))
        status = r.status
        if r.status == "solved":
            return BlockOutcome(block, r.grid.reshape(-1), status, retry_count, revisions)
        if r.status == "timeout":
            break
        if attempt < retries:
            retry_count += 1
    return BlockOutcome(block, None, status, retry_count, revisions)


@dataclass(frozen=True)
class BlockContext:
    """What every block task shares: relations, label weights and Alg. 3.1's settings."""

    relations: NDArray[np.bool_]
    weights: NDArray[np.float64]
    retries: int
    order: str
    choice: str
    root: int
    #: cells times labels of the whole problem (large: the workers load the kernels)
    size: int = 0
    #: the blocks travel as :class:`CompiledTask` and are solved by one kernel each
    #: (grid blocks, scan or entropy orders, uniform or weighted choice); ``scan`` is the
    #: cell order inside a block (``arange`` for the entropy orders)
    compiled: bool = False
    scan: NDArray[np.int64] | None = None
    #: the problem's per-class weight table (:attr:`csplab.problem.Problem.value_weights`),
    #: each block's classes travel with it
    value_table: NDArray[np.float64] | None = None


class CompiledTask(NamedTuple):
    """A block for :func:`csplab.catalog.solve_block_arrays`: flat index, sweep, and the
    block's catalog and internal arcs (:class:`csplab.catalog.BlockArrays`)."""

    block: int
    sweep: int
    arrays: BlockArrays


_TABLES: list[tuple[BlockContext, SupportTables]] = []


def solve_compiled(
    task: CompiledTask, ctx: BlockContext, deadline: float | None = None
) -> BlockOutcome:
    """One block in one kernel call, with its own generator (:func:`block_rng`): the same
    outcome as :func:`solve_block` on the block's subproblem (``deadline``, a
    ``time.perf_counter()`` value, is checked before the block starts)."""
    if deadline is not None and time.perf_counter() > deadline:
        return BlockOutcome(task.block, None, "timeout", 0, 0)
    if not _TABLES or _TABLES[0][0] is not ctx:  # once per context and process
        _TABLES[:] = [(ctx, support_tables(ctx.relations, ctx.weights))]
    assert ctx.scan is not None
    labels, retries, pops = solve_block_arrays(
        _TABLES[0][1], task.arrays, ctx.scan, ctx.retries, ctx.order, ctx.choice,
        block_rng(ctx.root, task.sweep, task.block),
    )  # fmt: skip
    status = "solved" if labels is not None else "failed"
    return BlockOutcome(task.block, labels, status, retries, pops)


class BlockTask(NamedTuple):
    """A block's subproblem as sent to a worker: flat index, sweep, shape, domains packed
    8 labels a byte, and the arcs inside the block (int32, local cell numbers)."""

    block: int
    sweep: int
    shape: tuple[int, ...]
    domains: NDArray[np.uint8]
    arcs: NDArray[np.int32]
    #: each cell's weight class (problems with ``value_weights``), else None
    classes: NDArray[np.int32] | None = None


def pack_block(sub: Problem, block: int, sweep: int) -> BlockTask:
    """The :class:`BlockTask` of subproblem ``sub`` (built by :meth:`Problem.subproblem`)."""
    cls = None if sub.value_weights is None else sub.value_weights[1].astype(np.int32)
    return BlockTask(
        block, sweep, sub.shape, np.packbits(sub.domains, axis=1), sub.arcs.astype(np.int32),
        cls,
    )


def _unpack(task: BlockTask, ctx: BlockContext) -> Problem:
    K = int(ctx.relations.shape[1])
    dom = np.unpackbits(task.domains, axis=1, count=K).astype(bool)
    vw = None
    if ctx.value_table is not None and task.classes is not None:
        vw = (ctx.value_table, task.classes)
    return Problem(task.shape, dom, ctx.relations, task.arcs, weights=ctx.weights,
                   value_weights=vw)  # fmt: skip


_CONTEXT: BlockContext | None = None


def run_tasks(
    tasks: Sequence[BlockTask | CompiledTask],
    wall_deadline: float | None,
    ctx: BlockContext | None = None,
) -> list[BlockOutcome]:
    """Worker side: solve ``tasks`` by ``wall_deadline`` (a ``time.time()`` value, or
    ``None``); ``ctx`` defaults to the one the pool initializer installed."""
    c = _CONTEXT if ctx is None else ctx
    if c is None:
        raise RuntimeError("run_tasks needs a BlockContext (none installed in this process)")
    _interp.kernels_for(c.size, 1)
    deadline = (
        None if wall_deadline is None else time.perf_counter() + (wall_deadline - time.time())
    )
    return [
        solve_compiled(t, c, deadline)
        if isinstance(t, CompiledTask)
        else solve_block(
            _unpack(t, c),
            block_rng(c.root, t.sweep, t.block),
            t.block,
            retries=c.retries,
            order=c.order,
            choice=c.choice,
            deadline=deadline,
        )
        for t in tasks
    ]


def _install(ctx: BlockContext) -> None:
    """Pool initializer: the context :func:`run_tasks` uses in this worker."""
    global _CONTEXT
    _CONTEXT = ctx


class BlockRunner:
    """Blocks on :class:`~csplab.engine.pool.Workers`: a local pool of ``workers``
    processes (fork on Linux; each receives the context once, at start) or, with
    ``scheduler``, a Dask cluster (the context is scattered to every worker once).

    :meth:`submit` sends a few blocks as one task; :meth:`gather` waits for tasks until a
    ``timeout`` and returns the outcomes that arrived and whether all did; :meth:`close`
    shuts the workers down (``kill=True``: now, killing running workers).
    """

    def __init__(self, workers: int, ctx: BlockContext, scheduler: str | None = None) -> None:
        self.ctx: Any = None  # a local pool's workers hold the context already
        if scheduler is None:
            self.workers = Workers.local(workers, initializer=_install, initargs=(ctx,))
            return
        self.workers = Workers.dask(
            scheduler, purpose="solver 'blocks' with scheduler=", local_workers=workers
        )
        try:
            self.ctx = self.workers.share(ctx)
        except BaseException:
            self.close()
            raise

    @property
    def size(self) -> int:
        """Tasks that run at once."""
        return self.workers.size

    def submit(self, tasks: Sequence[BlockTask | CompiledTask], wall_deadline: float | None) -> Any:
        return self.workers.submit(run_tasks, list(tasks), wall_deadline, self.ctx)

    def gather(
        self, futures: Sequence[Any], timeout: float | None
    ) -> tuple[list[BlockOutcome], bool]:
        done = self.workers.wait(futures, timeout)
        out: list[BlockOutcome] = []
        for f in done:
            out.extend(f.result())  # re-raises a worker's exception
        return out, len(done) == len(futures)

    def close(self, kill: bool = False) -> None:
        self.workers.close(kill)


def chunk_size(blocks: int, workers: int) -> int:
    """Blocks per task: about eight tasks per worker and wave, at most 32 blocks each."""
    return max(1, min(32, math.ceil(blocks / (8 * max(1, workers)))))
