"""Infinite, chunked, seed-deterministic worlds: modify in blocks on an unbounded lattice.

A :class:`World` is a model that extends without end along ``x`` and ``y`` (a 3D world has
the fixed height of its chunk, the ground and sky of the model's boundary rule on the
``z`` faces). ``world.chunk(i, j)`` gives the labels of chunk ``(i, j)`` and
``world.region(...)`` any rectangle; the content is a pure function of the model, the seed,
the settings and the coordinates.

Construction: modify in blocks (Merrell 2009, Alg. 3.4/3.5, Sec. 3.3.6) on the whole plane.

* **State 0** is a consistent *periodic* model ``M0`` tiled over the plane: the trivial
  solution (:func:`csplab.solvers.blocks.trivial_solution`: one label, or uniform layers
  such as ground under empty space) of a small periodic problem, else a SAT solution of a
  small torus; a model with no periodic solution up to :data:`MAX_PERIOD` is refused.
* **Sub-pass 1** solves isolated blocks: block ``(bx, by)`` is the cells
  ``[bx * B, (bx + 1) * B - r)`` (per axis; ``B`` the blocks' size, by default
  ``min(chunk, BLOCK)``, chunks being only windows; ``r`` the arcs' reach),
  so a line of ``r`` cells of ``M0`` separates neighbours and every block sees only ``M0``:
  no block of sub-pass 1 depends on another.
* **Sub-passes** ``s = 2 .. S`` (``S = 1 + 4 * passes``). Pass ``q = 1 .. passes`` lays a
  lattice of blocks of size ``B`` shifted by ``q * B // (passes + 1)`` per axis (so the
  lines and block edges of the passes before lie inside its blocks); block ``(bx, by)``
  has colour ``(bx mod 2, by mod 2)`` and each colour is one sub-pass. Blocks of one colour
  are ``B`` cells apart, more than ``r`` (checked), so neither sees the other's cells:
  they are independent.
* **A block** of sub-pass ``s`` is the block's cells with the labels of state ``s - 1``
  around it fixed (a ring of width ``r``; :meth:`Problem.subproblem`). Alg. 3.1 completes
  it (:func:`csplab.engine.waves.solve_block`, with ``retries``) from the generator
  ``default_rng(SeedSequence([seed, s, zig(bx), zig(by)]))``; when every run fails, exact
  completion (SAT with the border fixed); when the border admits no completion, the block
  keeps its labels of state ``s - 1``. State ``s`` is state ``s - 1`` with the blocks of
  sub-pass ``s`` replaced.

Why the content does not depend on the visit order (proof sketch). By induction on ``s``:
state 0 is a fixed function of the coordinates. A block of sub-pass ``s`` is a function of
(seed, ``s``, its coordinates, the labels of state ``s - 1`` on the block and its ring); its
generator is keyed by those coordinates only, never by a stream shared with other blocks,
and the blocks of one sub-pass do not see each other's cells. So state ``s`` at any cell is
a function of state ``s - 1`` on a bounded window, hence (induction) of the coordinates
alone. Which chunks were generated before, by which worker, in which order, or whether a
block was evicted and solved again changes nothing: each is recomputed from the same
inputs. Consistency: state 0 is consistent, and a block only ever takes labels that satisfy
every arc inside it and to its fixed ring (or keeps its old ones), so every state is
consistent on the whole plane, and every stitched rectangle has 0 violations.

Dependency neighbourhood. The final label of a cell depends on state ``s - 1`` within the
block of sub-pass ``s`` that holds it widened by ``r``; unrolled over the ``S`` sub-passes,
a chunk depends only on the cells within ``S * (B + r)`` of it: with ``passes=1`` and
blocks of the chunk's size, 49 blocks (1, 2, 6 and 8 of the colour sub-passes, 32 isolated
ones); a 32x32 chunk of 12x12 blocks (the default), 97 blocks of 144 cells
(:attr:`World.pyramid`, the most over the chunk's positions on the lattice).

Constraints in world coordinates. ``fixed={(x, y[, z]): label}`` and ``mask=callable``
restrict the domains of the blocks that hold those cells; a block whose border leaves no
completion keeps its previous labels, so a fixed cell may stay unmet where every pass puts
a seam too close to it (:meth:`World.unmet` lists them; more ``passes`` help).

Per-chunk constraints (``chunk_constraints=``, :data:`PER_CHUNK`: a count, and a set that
is one component reaching the chunk's four sides) add a last pass: sub-passes ``S + 1 ..
S + 4`` whose blocks are the chunks (colour ``(i mod 2, j mod 2)``), each solved with the
constraints on its cells and its ring fixed (Alg. 3.1 checked by
:meth:`Problem.is_solution`, else SAT, else it keeps its labels). No later block writes a
chunk's cells, so every chunk meets them unless its ring admits no labels that do
(:meth:`World.unmet_chunks` lists those); the pass is four more sub-passes of independent
blocks keyed by their coordinates, so the induction above still holds.

Seams and infallibility (:attr:`World.seams`). ``csplab prove`` proves that Alg. 3.1
cannot fail on an *open* grid filled from nothing; a block here has its ring fixed, on its
forward sides too, which no open-grid run has (a block of the last sub-pass always does),
and open-grid infallibility does not reach it (pipes is proved, yet a ring with one pipe
end pointing at a cell leaves it no label). What does: every cell has a label whatever its
neighbours hold (:func:`csplab.analysis.rings.ring_completion`, checked on the template's
centre column, cached per rule set); then no block of any shape with any consistent ring
fails in any order. When it holds and no fixed cell, mask or per-chunk constraint restricts
the blocks, ``seams`` is ``"proved-infallible"``: sub-passes 2, 3, 4 redraw only the lines
between isolated blocks, as thin strips across ``x`` (``[k B - r - m, k B + m)`` by ``[b B
+ m, (b + 1) B - r - m)``), across ``y``, then their crossings (``m`` = :data:`THIN_MARGIN`
times ``r``), with one Alg. 3.1 run each: no retry, no exact completion. Blocks of one
sub-pass are at least ``r`` apart, so the induction above holds; the store key names this
lattice. Otherwise ``seams`` is ``"general"`` (:attr:`World.seams_why` says why).

Not honoured in an infinite world: global constraints over the whole world (counts,
connectivity, symmetry; the reasons are :data:`UNHONOURED`; for one network,
:func:`network_per_chunk` matches the chunks' sides instead): given as ``constraints=``
they are refused in one line, in a model file they are dropped with a warning
(:attr:`World.dropped`); boundary faces on the infinite ``x``/``y`` axes (there is no
outside: refused).

Examples
--------
>>> w = World("fig3_4a", seed=3, chunk=(8, 8))
>>> a = w.chunk(0, 1)
>>> a.shape, bool((World("fig3_4a", seed=3, chunk=(8, 8)).chunk(0, 1) == a).all())
((8, 8), True)
>>> len(w.problem((16, 16)).violations(w.region((-4, 12), (0, 16))))
0
"""

from __future__ import annotations

import hashlib
import json
import math
import sqlite3
import warnings
from collections import OrderedDict
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab import _interp
from csplab.catalog import (
    block_arrays,
    pack,
    solve_block_arrays,
    support_tables,
    sweep_blocks,
)
from csplab.constraints import Connected, Constraint, Count
from csplab.engine import waves as wv
from csplab.engine.alg31 import scan_order
from csplab.errors import InputError, NoTrivialSolutionError
from csplab.example import ExampleModel
from csplab.grids import arc_reach, from_example
from csplab.problem import Problem
from csplab.solvers.blocks import ExactCompletion, trivial_solution

__all__ = [
    "BLOCK",
    "LATTICE",
    "MAX_PERIOD",
    "PER_CHUNK",
    "THIN_MARGIN",
    "UNHONOURED",
    "World",
    "chunk_shape",
    "network_per_chunk",
    "world_problem",
    "world_zfaces",
]

#: largest period of the start model ``M0`` tried before a model is refused
MAX_PERIOD = 8
#: why each global-constraint kind (:data:`csplab.constraints.KINDS`; ``symmetric`` is
#: mirror and rotate) is not honoured by a world: ``World(constraints=...)`` refuses it
#: with this line
UNHONOURED = {
    "count": "an endless plane has no total to count (a count per chunk is honoured: "
    'chunk_constraints=, or "per": "chunk" in a constraints file)',
    "connected": "whether two cells are joined is not local: it can depend on cells "
    "arbitrarily far away (one road made to join two far cities must pass somewhere between "
    "them), while a chunk may depend only on a bounded neighbourhood, or it would not be a "
    "function of its coordinates in any visit order; per chunk it is honoured "
    '(chunk_constraints=, or "per": "chunk" in a constraints file: one component reaching '
    "the chunk's four sides), and network_per_chunk() matches the sides so that any "
    "4-connected set of chunks holds one network",
    "symmetric": "a mirror or rotation maps cells to cells arbitrarily far away (an endless "
    "plane has no centre)",
    "separation": "local, so it could hold as arcs of the blocks, but a block's subproblem "
    "carries no global constraints: not supported yet",
    "max-run": "local, so it could hold as arcs of the blocks, but a block's subproblem "
    "carries no global constraints: not supported yet",
}
#: the kinds a world honours per chunk (``World(chunk_constraints=...)``), and what each
#: means in every chunk
PER_CHUNK = {
    "count": "the count of the chunk's cells (of its region, in chunk coordinates) with a "
    "label of the set lies in [min, max]",
    "connected": "the chunk's cells with a label of the set form one component (inside the "
    "chunk) that holds the given cells and touches each of the chunk's four x/y sides",
}
#: the largest default block side: blocks are ``min(chunk, BLOCK)`` cells wide unless given
BLOCK = 12
#: thin seams (:attr:`World.seams` ``"proved-infallible"``): a seam block reaches this many
#: times the arcs' reach into the isolated blocks on each side of a line
THIN_MARGIN = 2
#: the version of the blocks' lattice, part of the store's key (chunks stored under another
#: lattice are not read back)
LATTICE = 2

Rect = tuple[tuple[int, int], ...]  # ((x0, x1), (y0, y1)) half-open


def _zig(v: int) -> int:
    """A non-negative key for a signed coordinate (SeedSequence takes non-negative ints)."""
    return 2 * v if v >= 0 else -2 * v - 1


class _BlockSolver:
    """Solve one block: a pure function of (settings, sub-pass, block, window).

    Built once per world: the template's CSR arcs and support tables serve every block.
    When the compiled kernels are the engine and run the order and choice, a block is one
    kernel call on its window (:func:`csplab.catalog.sweep_blocks`: its catalog, then Alg.
    3.1 with its retries), or, with fixed cells or a mask, :func:`csplab.catalog.block_arrays`
    cut by them then :func:`csplab.catalog.solve_block_arrays`; otherwise (and for exact
    completion) :meth:`Problem.subproblem` and :func:`csplab.engine.waves.solve_block`, the
    twins that give the same labels from the same draws.
    """

    def __init__(
        self,
        template: Problem,
        inner: NDArray[np.int64],
        arc_ids: NDArray[np.int64],
        block_shape: tuple[int, ...],
        seed: int,
        retries: int,
        order: str,
        choice: str,
        exact: str,
        constraints: Sequence[Constraint] = (),
        proved: bool = False,
    ) -> None:
        self.template, self.inner, self.arc_ids = template, inner, arc_ids
        self.block_shape, self.seed, self.retries = block_shape, seed, retries
        self.order, self.choice, self.exact = order, choice, exact
        #: the blocks cannot fail (:attr:`World.seams`): one run, no exact completion
        self.proved = proved
        if proved:
            self.retries, self.exact = 0, "none"
        #: global constraints on the block's cells (a chunk's, in the chunk pass)
        self.constraints = tuple(constraints)
        self.kernel = choice in ("uniform", "weighted") and order != "random"
        self.kernel = self.kernel and not self.constraints
        scan = scan_order(block_shape, order) if self.kernel else None
        self.scan = np.arange(inner.size, dtype=np.int64) if scan is None else scan.astype(np.int64)
        self.tables = support_tables(template.relations, template.weights)
        self.bptr = np.array([0, inner.size], dtype=np.int64)
        self.job = 0  #: cells of the job this solver is part of (whether to load kernels)

    def __call__(
        self,
        s: int,
        b: tuple[int, ...],
        window: NDArray[np.int32],
        allowed: NDArray[np.bool_] | None,
    ) -> tuple[NDArray[np.int32], str]:
        """The block's labels (block shape) and how they came: ``alg31``, ``exact``,
        ``kept``."""
        rng = np.random.default_rng(
            np.random.SeedSequence([self.seed, s, *(_zig(int(c)) for c in b)])
        )
        flat = np.ascontiguousarray(window, dtype=np.int32).reshape(-1)
        labels: NDArray[np.int32] | None
        sub: Problem | None = None
        if self.kernel and _interp.compiled_engine() and allowed is None:
            # one kernel call: the block's catalog, then Alg. 3.1 with its retries
            counters = np.zeros(4, dtype=np.int64)
            grid = flat.copy()
            sweep_blocks(self.template, grid, self.bptr, self.inner, (0, 1), self.scan,
                         self.retries, self.order, self.choice, rng, counters)  # fmt: skip
            labels = grid[self.inner] if counters[1] else None
        elif self.kernel and _interp.compiled_engine():
            arrays = block_arrays(self.template, flat, self.inner)
            if allowed is not None:
                cut = pack(allowed.reshape(self.inner.size, -1))
                arrays = arrays._replace(dom0=arrays.dom0 & cut)
            labels, _, _ = solve_block_arrays(self.tables, arrays, self.scan, self.retries,
                                              self.order, self.choice, rng)  # fmt: skip
        else:
            sub = self._sub(flat, allowed)
            labels = wv.solve_block(sub, rng, 0, retries=self.retries, order=self.order,
                                    choice=self.choice, deadline=None).labels  # fmt: skip
            if labels is not None and self.constraints and not sub.is_solution(labels):
                labels = None  # Alg. 3.1 keeps the arcs only: exact completion next
        how = "alg31"
        if labels is None and self.exact != "none":
            sub = sub if sub is not None else self._sub(flat, allowed)
            if not (~sub.domains.any(axis=1)).any():
                labels, _ = ExactCompletion(self.exact)(sub, rng, None)
                how = "exact"
        if labels is None:
            if self.proved:
                raise AssertionError(
                    f"block {b} of sub-pass {s} failed although its ring cannot make it fail "
                    "(World.seams): the ring-completion check is wrong"
                )
            old = flat[self.inner]
            return old.reshape(self.block_shape).astype(np.int32), "kept"
        return np.asarray(labels, dtype=np.int32).reshape(self.block_shape), how

    def _sub(self, flat: NDArray[np.int32], allowed: NDArray[np.bool_] | None) -> Problem:
        sub = self.template.subproblem(self.inner, flat, shape=self.block_shape,
                                       arc_ids=self.arc_ids)  # fmt: skip
        if self.constraints:
            sub = sub.with_constraints(self.constraints)
        return sub if allowed is None else sub.restrict(allowed)


_WORKER: tuple[_BlockSolver, ...] | None = None
#: the ring-completion verdicts (:mod:`csplab.analysis.rings`) per block template (its
#: relations, domains and arcs): a model's is computed once per process
_RING_VERDICTS: dict[str, Any] = {}

#: a block task: the solver's index (isolated, shifted, chunk pass), the sub-pass, the
#: block, its window of the state before and the labels allowed in it
_Task = tuple[int, int, tuple[int, ...], NDArray[np.int32], NDArray[np.bool_] | None]


def _init_worker(solvers: tuple[_BlockSolver, ...]) -> None:
    global _WORKER
    _WORKER = solvers


def _solve_task(
    tasks: list[_Task], solvers: tuple[_BlockSolver, ...] | None = None
) -> list[tuple[NDArray[np.int32], str]]:
    """Blocks on a worker: the solvers are the pool's (``_WORKER``) or sent along (Dask)."""
    sv = solvers or _WORKER
    assert sv is not None
    # a worker started without the kernels loads them (the parent's reason holds here)
    _interp.kernels_for(sv[1].job, sv[1].template.K)
    return [sv[t[0]](*t[1:]) for t in tasks]


class _LRU(OrderedDict[Any, Any]):
    """A bounded mapping that forgets the least recently used entry."""

    def __init__(self, size: int) -> None:
        super().__init__()
        self.size = size

    def get_(self, key: Any) -> Any:
        v = self.get(key)
        if v is not None:
            self.move_to_end(key)
        return v

    def put(self, key: Any, value: Any) -> None:
        self[key] = value
        self.move_to_end(key)
        while len(self) > self.size:
            self.popitem(last=False)


def chunk_shape(chunk: Sequence[int]) -> tuple[int, ...]:
    """A world's chunk shape checked: 2 or 3 positive sizes.

    Parameters
    ----------
    chunk : sequence of int
        ``(X, Y)`` or ``(X, Y, height)``.

    Returns
    -------
    tuple of int

    Raises
    ------
    InputError
        For another number of sizes or a size below 1.

    Examples
    --------
    >>> chunk_shape([16, 16, 10])
    (16, 16, 10)
    """
    shape = tuple(int(c) for c in chunk)
    if len(shape) not in (2, 3) or min(shape) < 1:
        raise InputError(f"chunk must be 2 or 3 positive sizes, not {tuple(chunk)!r}")
    return shape


def world_zfaces(
    model: Any, chunk: Sequence[int], boundary: Any
) -> dict[str, int] | None:
    """The ``z`` faces of a world of ``chunk``-sized chunks (``None``: no faces).

    Parameters
    ----------
    model : ExampleModel or rule set
        The world's model.
    chunk : sequence of int
        The chunk's shape; a 3D world's third number is its height.
    boundary : {"auto", "none"}, mapping or None
        As :class:`World` takes it: only ``z-`` and ``z+`` exist in an infinite world.

    Returns
    -------
    dict of str to int or None
        The label of each bounded ``z`` face.

    Raises
    ------
    InputError
        For a chunk that is not 2 or 3 positive sizes, faces other than ``z-``/``z+`` or a
        boundary that is not ``auto``, ``none`` or a mapping.

    Examples
    --------
    >>> import csplab.examples
    >>> world_zfaces(csplab.examples.load_example("city"), (16, 16, 10), "auto")
    {'z+': 0, 'z-': 1}
    >>> world_zfaces(csplab.examples.load_example("line"), (16, 16), "auto") is None
    True
    """
    chunk = chunk_shape(chunk)
    ndim = len(chunk)
    if boundary in (None, "none"):
        return None
    if isinstance(boundary, Mapping):
        bad = [f for f in boundary if f not in ("z-", "z+")]
        if bad or ndim == 2:
            raise InputError(
                f"boundary faces {bad or list(boundary)} do not exist in an infinite "
                "world (only z- and z+ of a 3D world)"
            )
        return {str(f): int(v) for f, v in boundary.items()}
    if boundary != "auto":
        raise InputError(f"boundary must be 'auto', 'none' or a mapping, not {boundary!r}")
    if ndim == 2:
        return None
    if isinstance(model, ExampleModel):
        P = from_example(model, (6, 6, int(chunk[2])), boundary="auto")
        faces = P.meta.get("boundary") or {}
    else:
        faces = dict(getattr(model, "boundary", None) or {})
    z = {f: int(v) for f, v in faces.items() if f in ("z-", "z+")}
    return z or None


def world_problem(
    model: Any,
    shape: Sequence[int],
    height: int | None,
    zfaces: Mapping[str, int] | None,
    *,
    periodic: bool = False,
) -> tuple[Problem, list[str]]:
    """The grid problem of a world's rectangle, and the global constraints it drops.

    No faces on ``x``/``y``; ``zfaces`` (:func:`world_zfaces`) on ``z``. What
    :meth:`World.problem` gives, without building a world (``csplab world`` reads its
    ``--constraints`` against it).

    Parameters
    ----------
    model : ExampleModel or rule set
        The world's model.
    shape : sequence of int
        ``(X, Y)``.
    height : int or None
        A 3D world's height (``None``: 2D).
    zfaces : mapping of str to int or None
        The ``z`` faces' labels.
    periodic : bool
        Wrap ``x`` and ``y``.

    Returns
    -------
    Problem
        The problem, without the model's global constraints.
    list of str
        The names of the global constraints dropped (a world cannot honour them).

    Raises
    ------
    InputError
        When the model is not a grid model (an example or a rule set).

    Examples
    --------
    >>> import csplab.examples
    >>> P, dropped = world_problem(csplab.examples.load_example("line"), (8, 6), None, None)
    >>> P.shape, dropped
    ((8, 6), [])
    """
    shp = tuple(int(s) for s in shape[:2])
    per: bool | tuple[bool, ...] = periodic
    if height is not None:
        shp = (*shp, int(height))
        per = (periodic, periodic, False)
    bound: Any = dict(zfaces) if zfaces else "none"
    if isinstance(model, ExampleModel):
        P = from_example(model, shp, periodic=per, boundary=bound)
    elif hasattr(model, "problem"):
        P = model.problem(shp, periodic=per, boundary=bound)
    else:
        raise InputError(
            f"{getattr(model, 'name', None) or type(model).__name__} is not a grid model: a "
            "world takes grid examples, tilesets and overlapping samples"
        )
    if not P.constraints:
        return P, []
    return P.without_constraints(), [type(c).__name__ for c in P.constraints]


class World:
    """An endless chunked world of ``model`` (see the module docstring for the construction).

    Parameters
    ----------
    model : str, ExampleModel or RuleSet
        A built-in example name or model file (:func:`csplab.examples.load_model`), an
        example or a rule set (tilesets and overlapping samples).
    seed : int
        The world's seed (any non-negative integer).
    chunk : tuple of int
        ``(X, Y)`` for a 2D world, ``(X, Y, Z)`` for a 3D one (``Z``: its fixed height).
        Chunks are windows on the world: the blocks of modify in blocks have their own size.
    boundary : "auto", "none" or mapping
        Labels of the ``z`` faces of a 3D world (``"auto"``: the rule of
        :func:`csplab.grids.from_example`, ground below and sky above; only its ``z`` faces
        are kept). Faces on ``x``/``y`` do not exist in an infinite world: refused.
    passes : int
        Shifted colour passes of modify in blocks after the isolated blocks' sub-pass (pass
        ``q`` shifted by ``q * B // (passes + 1)``).
    retries : int
        Alg. 3.1 runs per block after the first, before exact completion.
    exact : {"sat", "backtrack", "none"}
        Exact completion of a block that Alg. 3.1 cannot complete.
    order, choice : str
        Alg. 3.1's cell order and label choice inside a block (the thesis': ``scanline``,
        ``uniform``).
    fixed : mapping ``{(x, y[, z]): label}``, optional
        Cells fixed in world coordinates.
    mask : callable, optional
        ``mask(xs, ys) -> bool array (..., K)``: the labels allowed at world cells
        ``xs, ys`` (integer arrays of the block's ``(X, Y)`` shape); 3D: ``(X, Y, Z, K)``.
    cache_blocks, cache_chunks : int
        Sizes of the block and chunk caches (least recently used entries are forgotten:
        memory stays flat however far one walks). The block cache holds at least the
        blocks one chunk needs from scratch (``sum((k + 2) ** 2 for k < S)``).
    store : str or Path, optional
        A SQLite file keeping generated chunks (keyed by the model's rules, the seed and the
        settings; a ``mask`` by its module and name): a restart reads them instead of
        solving again.
    workers : int
        Processes solving independent blocks of a sub-pass at once (0 or 1: this process);
        the output is the same for any number.
    block : tuple of int, optional
        ``(bx, by)``, the blocks' size in ``x`` and ``y`` (default ``min(chunk, BLOCK)``
        per axis; more than the arcs' reach). Smaller blocks make a chunk depend on fewer
        cells (a 32x32 chunk from scratch: 13.6 times its cells with 12x12 blocks, 49 times
        with 32x32 ones), larger ones leave room for larger structures.
    constraints : sequence of Constraint
        Global constraints (:mod:`csplab.constraints`) on the whole world: every kind is
        refused, with the reason of :data:`UNHONOURED` (fixed cells, masks and
        ``chunk_constraints`` are the constraints a world honours).
    chunk_constraints : sequence of Count or Connected
        Constraints that hold in every chunk (:data:`PER_CHUNK`), built on the chunk's
        grid (:meth:`problem` of the chunk's shape: regions and cells in chunk
        coordinates). A last pass solves each chunk as one block with them, its ring
        fixed (module doc); a chunk whose ring admits no such labels keeps its labels
        and is listed by :meth:`unmet_chunks`.
    seams : {"auto", "general"}
        ``"auto"``: when every cell has a label whatever its neighbours hold
        (:func:`csplab.analysis.rings.ring_completion` of the blocks' template, cached per
        rule set), no block with any ring can fail, and the seams between the isolated
        blocks are redrawn by thin strips (:data:`THIN_MARGIN`) instead of a shifted pass
        of whole blocks: :attr:`seams` is ``"proved-infallible"`` (other bytes, another
        store key). Otherwise, or with ``"general"``, the lattice above.
    scheduler : str, optional
        Solve them on Dask instead: ``"local"`` (a ``LocalCluster`` of ``max(workers, 1)``
        processes) or a scheduler address (as the ``blocks`` solver takes it); the same
        output again.

    Raises
    ------
    InputError
        For bad settings (a chunk shape, faces on ``x``/``y``, unknown options, a global
        constraint) or a model with no periodic solution to start from.
    """

    def __init__(
        self,
        model: Any,
        *,
        seed: int = 0,
        chunk: Sequence[int] = (32, 32),
        boundary: Any = "auto",
        passes: int = 1,
        retries: int = 20,
        exact: str = "sat",
        order: str = "scanline",
        choice: str = "uniform",
        fixed: Mapping[Sequence[int], int] | None = None,
        mask: Callable[..., Any] | None = None,
        cache_blocks: int = 4096,
        cache_chunks: int = 1024,
        store: str | Path | None = None,
        workers: int = 0,
        scheduler: str | None = None,
        constraints: Sequence[Constraint] = (),
        block: Sequence[int] | None = None,
        chunk_constraints: Sequence[Constraint] = (),
        seams: str = "auto",
    ) -> None:
        from csplab.examples import load_model

        for c in constraints:  # refused, one line each (module doc, UNHONOURED)
            kind = getattr(c, "kind", type(c).__name__)
            why = UNHONOURED.get(kind, "not a grid constraint of csplab.constraints")
            raise InputError(f"a world cannot honour a {kind} constraint: {why}")
        if isinstance(model, str | Path):
            model = load_model(model)
        self.model = model
        self.seed = int(seed)
        if self.seed < 0:
            raise InputError(f"seed must be >= 0, not {seed}")
        self.chunk_shape = chunk_shape(chunk)
        if passes < 1 or retries < 0 or workers < 0:
            raise InputError("passes must be >= 1, retries >= 0 and workers >= 0")
        if exact not in ("sat", "backtrack", "none"):
            raise InputError(f"exact must be sat, backtrack or none, not {exact!r}")
        if seams not in ("auto", "general"):
            raise InputError(f"seams must be auto or general, not {seams!r}")
        self.ndim = len(self.chunk_shape)
        self.passes, self.retries, self.exact = int(passes), int(retries), exact
        self.order, self.choice, self.workers = order, choice, int(workers)
        self.scheduler = scheduler
        #: blocks are solved a sub-pass at a time on workers (a local pool or Dask)
        self.parallel = self.workers >= 2 or scheduler is not None
        self.B = self.chunk_shape[:2]
        if block is None:  # small blocks: a chunk depends on fewer cells (module doc)
            block = tuple(min(c, BLOCK) for c in self.B)
        self.block = tuple(int(b) for b in block)
        if len(self.block) != 2 or min(self.block) < 2:
            raise InputError(f"block must be 2 sizes >= 2 (x and y), not {block!r}")
        self.height = self.chunk_shape[2] if self.ndim == 3 else None
        self.zfaces = self._zfaces(boundary)
        self.dropped: list[str] = []  # the model's global constraints (cannot hold)
        # the template: a block with its ring; the arcs' reach from it
        probe = self.problem(tuple(max(4, 2 * b) for b in self.block))
        self.reach = arc_reach(probe, axes=(0, 1))  # along x and y: z is the chunk's own
        if self.reach >= min(self.block):
            raise InputError(
                f"the model's arcs reach {self.reach} cells, as far as the blocks "
                f"{self.block}: use larger blocks"
            )
        r = self.reach
        self.template = self.problem(tuple(b + 2 * r for b in self.block))
        self.K = self.template.K
        # blocks are cached in the smallest integer type that holds the labels
        self._small = np.int16 if self.K <= np.iinfo(np.int16).max else np.int32
        self.fixed = {tuple(int(c) for c in k): int(v) for k, v in (fixed or {}).items()}
        for k, v in self.fixed.items():
            if len(k) != self.ndim or not 0 <= v < self.K:
                raise InputError(f"fixed cell {k}: {v} is not a cell and label of this world")
            if self.ndim == 3 and not 0 <= k[2] < self.chunk_shape[2]:
                raise InputError(f"fixed cell {k} is outside the world's height")
        self.mask = mask
        self.M0 = self._start()
        # sub-pass 1 (the isolated blocks, a line of r cells of M0 between them) and the
        # colour sub-passes: one template and one solver each
        iso = tuple(b - r for b in self.block)
        self.chunk_constraints = tuple(chunk_constraints)
        #: the chunk's grid with the per-chunk constraints (their checker:
        #: :meth:`unmet_chunks`)
        self.chunk_problem = self.problem(self.B).with_constraints(
            self._per_chunk(self.chunk_constraints)
        )
        #: how blocks and seams are solved: ``"proved-infallible"`` (every cell has a label
        #: whatever its neighbours hold, so no block with any ring can fail: one Alg. 3.1
        #: run per block, no retry, no exact completion, same bytes) or ``"general"``;
        #: :attr:`seams_why` says why (module doc, "Seams and infallibility")
        self.seams, self.seams_why = self._seams(seams)
        #: thin seams (proved-infallible only): how far a seam block reaches into the
        #: isolated blocks on each side of a line (0: the general lattice)
        self.margin = THIN_MARGIN * r if self.seams == "proved-infallible" else 0
        if self.margin:
            w = r + 2 * self.margin  # a seam's width; a strip's length below
            strip = [b - w for b in self.block]
            solvers = [self._solver(iso), self._solver((w, strip[1])),
                       self._solver((strip[0], w)), self._solver((w, w))]  # fmt: skip
            self.S_blocks = 4
        else:
            solvers = [self._solver(iso), self._solver(self.block)]
            #: the sub-passes of the blocks' lattice; a last pass of chunks (4 colours)
            #: after them when there are per-chunk constraints
            self.S_blocks = 1 + 4 * self.passes
        self.S = self.S_blocks
        if self.chunk_constraints:
            if min(self.B) <= r:
                raise InputError(
                    f"per-chunk constraints need chunks wider than the arcs' reach {r}"
                )
            solvers.append(self._solver(self.B, self.chunk_problem.constraints))
            self.S += 4
        self.solvers = tuple(solvers)
        # the blocks one chunk needs from scratch; a smaller cache would solve blocks again
        # and again within one chunk
        # (the most over the chunk's positions relative to the blocks' lattice)
        phases = [b // math.gcd(b, c) for b, c in zip(self.block, self.B, strict=True)]
        self.pyramid = max(
            sum(len(n) for n in self._needed(self._chunk_rect(i, j), set()))
            for i in range(phases[0]) for j in range(phases[1])
        )  # fmt: skip
        # a chunk from scratch is a job of ``pyramid`` blocks: large ones run compiled
        for sv in self.solvers:
            sv.job = self.pyramid * int(np.prod(self._full(self.block)))
        _interp.kernels_for(self.solvers[1].job, self.K)
        self.blocks: _LRU = _LRU(max(int(cache_blocks), self.pyramid))
        self.chunks: _LRU = _LRU(int(cache_chunks))
        self.stats: dict[str, int] = {"alg31": 0, "exact": 0, "kept": 0, "stored": 0}
        self.key = self._key()
        self._db: sqlite3.Connection | None = None
        if store is not None:
            self._db = sqlite3.connect(str(store))
            self._db.execute(
                "CREATE TABLE IF NOT EXISTS chunks (world TEXT, i INTEGER, j INTEGER, "
                "data BLOB, PRIMARY KEY (world, i, j))"
            )
            self._db.commit()
        self._pool: Any = None
        self._shared: Any = None  # the solvers, sent to each Dask worker once

    # -- problems -------------------------------------------------------------------------
    @property
    def _bshape(self) -> tuple[int, ...]:
        """A chunk's shape."""
        return self._full(self.B)

    def _full(self, xy: Sequence[int]) -> tuple[int, ...]:
        """A block's shape from its ``x``/``y`` sizes (3D: the world's height)."""
        return tuple(xy) if self.height is None else (*xy, self.height)

    def _per_chunk(self, cons: Sequence[Constraint]) -> list[Constraint]:
        """The chunk grid's constraints of the per-chunk ones (:data:`PER_CHUNK`): a count
        as given; a connectivity as one non-empty component with a cell on each side."""
        P = self.problem(self.B)
        out: list[Constraint] = []
        for c in cons:
            kind = getattr(c, "kind", type(c).__name__)
            if not isinstance(c, Count | Connected) or (
                isinstance(c, Connected) and c.members is not None
            ):
                raise InputError(
                    f"a world cannot honour a {kind} constraint per chunk: only "
                    f"{' and '.join(PER_CHUNK)} hold per chunk"
                )
            c.validate(P)
            if isinstance(c, Count):
                out.append(c)
                continue
            out.append(Connected(c.labels, c.cells, c.ports, nonempty=True))
            full = [(0, n - 1) for n in P.shape]
            for a in range(2):
                for end in (0, P.shape[a] - 1):
                    side = list(full)
                    side[a] = (end, end)
                    out.append(Count(c.labels, 1, None, tuple(side)))
        return out

    def _solver(self, xy: Sequence[int], constraints: Sequence[Constraint] = ()) -> _BlockSolver:
        """The solver of blocks ``xy`` wide: their template (the block and a ring of ``r``)."""
        r = self.reach
        same = tuple(xy) == self.block
        t = self.template if same else self.problem(tuple(b + 2 * r for b in xy))
        idx = np.arange(t.n, dtype=np.int64).reshape(t.shape)
        inner = idx[r : r + xy[0], r : r + xy[1]].reshape(-1)
        touch = np.isin(t.arcs[:, 0], inner) | np.isin(t.arcs[:, 1], inner)
        arc_ids = np.flatnonzero(touch).astype(np.int64)
        proved = self.seams == "proved-infallible" and not constraints
        return _BlockSolver(t, inner, arc_ids, self._full(xy), self.seed, self.retries,
                            self.order, self.choice, self.exact, constraints,
                            proved=proved)  # fmt: skip

    def _seams(self, mode: str) -> tuple[str, str]:
        """The seams' path and why (:attr:`seams`): the ring-completion check of the
        template's centre column (cached per rule set, :data:`_RING_VERDICTS`)."""
        if mode == "general":
            return "general", "asked for (seams='general')"
        if self.fixed or self.mask is not None or self.chunk_constraints:
            return "general", (
                "fixed cells, a mask or per-chunk constraints restrict blocks beyond the "
                "model's rules: those blocks may fail"
            )
        t = self.template
        h = hashlib.sha256()
        for arr in (t.relations, t.domains, t.arcs):
            h.update(np.ascontiguousarray(arr).tobytes())
        key = h.hexdigest()
        v = _RING_VERDICTS.get(key)
        if v is None:
            from csplab.analysis.rings import ring_completion

            idx = np.arange(t.n).reshape(t.shape)
            centre = idx[t.shape[0] // 2, t.shape[1] // 2].reshape(-1)
            v = _RING_VERDICTS[key] = ring_completion(t, centre.tolist())
        if v.holds:
            r = self.reach
            w = r + 2 * THIN_MARGIN * r
            if min(self.block) < w + r:
                return "general", (
                    f"{v.message}, but blocks {self.block} are too small for thin seams "
                    f"(at least {w + r} per axis)"
                )
            return "proved-infallible", v.message
        return "general", "ring completion " + (
            f"fails: {v.message}" if v.holds is False else v.message
        )

    def _zfaces(self, boundary: Any) -> dict[str, int] | None:
        return world_zfaces(self.model, self.chunk_shape, boundary)

    def problem(self, shape: Sequence[int], *, periodic: bool = False) -> Problem:
        """The model's problem on a rectangle of ``shape``.

        No faces on ``x``/``y``, the world's ``z`` faces. Check a stitched region with its
        :meth:`Problem.violations`.

        Parameters
        ----------
        shape : sequence of int
            ``(X, Y)``; a 3D world adds its height.
        periodic : bool
            Wrap ``x`` and ``y``.

        Returns
        -------
        Problem
            The grid problem of the rectangle.

        Raises
        ------
        InputError
            When the model is not a grid model (an example or a rule set).
        """
        P, dropped = world_problem(self.model, shape, self.height, self.zfaces, periodic=periodic)
        if dropped and not self.dropped:  # global constraints of the file cannot hold
            self.dropped = dropped
            warnings.warn(
                f"a world cannot honour the model's global constraints "
                f"({', '.join(self.dropped)}): dropped",
                stacklevel=3,
            )
        return P

    def _start(self) -> NDArray[np.int32]:
        """``M0``: a consistent periodic tile (checked on the template's window)."""
        from csplab.solvers import solve

        r = self.reach
        for p in range(1, MAX_PERIOD + 1):
            if p < r:
                continue
            P = self.problem((p, p), periodic=True)
            tile: NDArray[np.int32] | None = None
            try:
                tile = trivial_solution(P, attempts=0)
            except NoTrivialSolutionError:
                res = solve(P, "sat", rng=self.seed)
                if res.status == "solved":
                    tile = np.asarray(res.grid, dtype=np.int32)
            if tile is None:
                continue
            win = self._tile(tile, self._rect_of(self.template.shape, r))
            if self.template.is_solution(win):
                return tile
        raise InputError(
            f"{getattr(self.model, 'name', '') or 'this model'} has no periodic solution "
            f"with a period up to {MAX_PERIOD}: a world needs one to start from"
        )

    def _rect_of(self, shape: Sequence[int], r: int) -> Rect:
        return ((-r, shape[0] - r), (-r, shape[1] - r))

    def _tile(self, tile: NDArray[np.int32], rect: Rect) -> NDArray[np.int32]:
        (x0, x1), (y0, y1) = rect
        p, q = tile.shape[0], tile.shape[1]
        xs = np.arange(x0, x1) % p
        ys = np.arange(y0, y1) % q
        return np.ascontiguousarray(tile[xs[:, None], ys[None, :]], dtype=np.int32)

    # -- lattice --------------------------------------------------------------------------
    def _kind(self, s: int) -> int:
        """The solver of sub-pass ``s``: 0 isolated blocks, 1 shifted blocks, 2 chunks;
        thin seams: 0 isolated blocks, 1 strips across ``x``, 2 along ``x``, 3 crossings."""
        if self.margin:
            return s - 1
        return 0 if s == 1 else 1 if s <= self.S_blocks else 2

    def _thin_axes(self, s: int) -> tuple[bool, bool]:
        """Thin seams, sub-pass ``s >= 2``: per axis, whether its blocks are seams across
        that axis (``[k * B - r - m, k * B + m)``) or spans between them."""
        return (s in (2, 4), s in (3, 4))

    def _pass_colour(self, s: int) -> tuple[int, tuple[int, int]]:
        """Sub-pass ``s >= 2``: its pass ``q >= 1`` (``passes + 1``: the chunks) and colour."""
        q, c = divmod(s - 2, 4)
        return q + 1, (c >> 1, c & 1)

    def _lattice(self, s: int) -> tuple[tuple[int, int], Sequence[int]]:
        """Offset and size of the blocks of sub-pass ``s >= 2`` (chunks in the last pass)."""
        if self._kind(s) == 2:
            return (0, 0), self.B
        return self._offset(self._pass_colour(s)[0]), self.block

    def _offset(self, q: int) -> tuple[int, int]:
        return (q * self.block[0] // (self.passes + 1),
                q * self.block[1] // (self.passes + 1))  # fmt: skip

    def _blocks_in(self, s: int, rect: Rect) -> list[tuple[int, int]]:
        """Blocks of sub-pass ``s`` (its colour only) that meet ``rect``."""
        ranges = []
        if s == 1:  # block b: [b * B, (b + 1) * B - r) per axis
            for a in range(2):
                lo, hi = rect[a]
                B = self.block[a]
                ranges.append(range((lo - B + self.reach) // B + 1, (hi - 1) // B + 1))
            return [(bx, by) for bx in ranges[0] for by in ranges[1]]
        if self.margin:  # a seam [k B - r - m, k B + m), a span [b B + m, (b + 1) B - r - m)
            r, m = self.reach, self.margin
            for a, seam in enumerate(self._thin_axes(s)):
                lo, hi = rect[a]
                B = self.block[a]
                if seam:
                    ranges.append(range((lo - m) // B + 1, (hi + r + m - 1) // B + 1))
                else:
                    ranges.append(range((lo + r + m) // B, (hi - m - 1) // B + 1))
            return [(bx, by) for bx in ranges[0] for by in ranges[1]]
        _, col = self._pass_colour(s)
        off, size = self._lattice(s)
        for a in range(2):
            lo, hi = rect[a]
            b0 = (lo - off[a]) // size[a]
            b1 = (hi - 1 - off[a]) // size[a]
            first = b0 + ((col[a] - b0) % 2)
            ranges.append(range(first, b1 + 1, 2))
        return [(bx, by) for bx in ranges[0] for by in ranges[1]]

    def _block_rect(self, s: int, b: tuple[int, int]) -> Rect:
        if s == 1:
            return tuple((b[a] * self.block[a], (b[a] + 1) * self.block[a] - self.reach)
                         for a in range(2))  # fmt: skip
        if self.margin:
            r, m = self.reach, self.margin
            return tuple(
                (b[a] * self.block[a] - r - m, b[a] * self.block[a] + m) if seam
                else (b[a] * self.block[a] + m, (b[a] + 1) * self.block[a] - r - m)
                for a, seam in enumerate(self._thin_axes(s))
            )  # fmt: skip
        off, B = self._lattice(s)
        return tuple((off[a] + b[a] * B[a], off[a] + (b[a] + 1) * B[a]) for a in range(2))

    def _chunk_rect(self, i: int, j: int) -> Rect:
        return ((i * self.B[0], (i + 1) * self.B[0]), (j * self.B[1], (j + 1) * self.B[1]))

    def _needed(self, rect: Rect, have: Any) -> list[set[tuple[int, int]]]:
        """Per sub-pass ``s`` (index ``s - 1``), the blocks state ``S`` on ``rect`` depends
        on that are not in ``have`` (a container of ``(s, b)``)."""
        need: list[set[tuple[int, int]]] = [set() for _ in range(self.S)]
        rects: list[Rect] = [rect]
        for s in range(self.S, 0, -1):
            new: list[Rect] = []
            for rc in rects:
                for b in self._blocks_in(s, rc):
                    if b not in need[s - 1] and (s, b) not in have:
                        need[s - 1].add(b)
                        new.append(self._window(s, b))
            rects = rects + new
            if len(rects) > 64:  # merge into the bounding box (a superset: correct)
                rects = [tuple((min(r[a][0] for r in rects), max(r[a][1] for r in rects))
                               for a in range(2))]  # fmt: skip
        return need

    # -- state ----------------------------------------------------------------------------
    def _state(self, s: int, rect: Rect) -> NDArray[np.int32]:
        """Labels of state ``s`` on ``rect`` (blocks solved on demand)."""
        out = self._tile(self.M0, rect)
        for t in range(1, s + 1):
            for b in self._blocks_in(t, rect):
                lab = self._block(t, b)
                br = self._block_rect(t, b)
                lo = [max(br[a][0], rect[a][0]) for a in range(2)]
                hi = [min(br[a][1], rect[a][1]) for a in range(2)]
                out[
                    lo[0] - rect[0][0] : hi[0] - rect[0][0], lo[1] - rect[1][0] : hi[1] - rect[1][0]
                ] = lab[lo[0] - br[0][0] : hi[0] - br[0][0], lo[1] - br[1][0] : hi[1] - br[1][0]]
        return out

    def _window(self, s: int, b: tuple[int, int]) -> Rect:
        br, r = self._block_rect(s, b), self.reach
        return ((br[0][0] - r, br[0][1] + r), (br[1][0] - r, br[1][1] + r))

    def _allowed(self, s: int, b: tuple[int, int]) -> NDArray[np.bool_] | None:
        if not self.fixed and self.mask is None:
            return None
        (x0, x1), (y0, y1) = self._block_rect(s, b)
        al = np.ones((*self._full((x1 - x0, y1 - y0)), self.K), dtype=bool)
        if self.mask is not None:
            xs, ys = np.meshgrid(np.arange(x0, x1), np.arange(y0, y1), indexing="ij")
            al &= np.broadcast_to(np.asarray(self.mask(xs, ys), dtype=bool), al.shape)
        hit = False
        for k, v in self.fixed.items():
            if x0 <= k[0] < x1 and y0 <= k[1] < y1:
                cell = (k[0] - x0, k[1] - y0, *k[2:])
                al[cell] = False
                al[(*cell, v)] = True
                hit = True
        return al if (hit or self.mask is not None) else None

    def _block(self, s: int, b: tuple[int, int]) -> NDArray[np.int32]:
        key = (s, b)
        lab = self.blocks.get_(key)
        if lab is None:
            win = self._state(s - 1, self._window(s, b))
            lab, how = self.solvers[self._kind(s)](s, b, win, self._allowed(s, b))
            self.stats[how] += 1
            self.blocks.put(key, lab.astype(self._small, copy=False))
        return lab  # type: ignore[no-any-return]

    def _prefetch(self, rect: Rect) -> None:
        """Solve the blocks ``rect`` needs, sub-pass by sub-pass, independent blocks of a
        sub-pass on the workers (``workers >= 2``)."""
        need = self._needed(rect, self.blocks)
        pool = self._workers()
        for s in range(1, self.S + 1):
            todo = sorted(b for b in need[s - 1] if (s, b) not in self.blocks)
            if not todo:
                continue
            tasks: list[_Task] = [
                (self._kind(s), s, b, self._state(s - 1, self._window(s, b)),
                 self._allowed(s, b)) for b in todo
            ]  # fmt: skip
            size = max(1, len(tasks) // (2 * pool.size))
            futures = [pool.submit(_solve_task, tasks[i : i + size], self._shared)
                       for i in range(0, len(tasks), size)]  # fmt: skip
            results = [x for f in futures for x in f.result()]
            for b, (lab, how) in zip(todo, results, strict=True):
                self.stats[how] += 1
                self.blocks.put((s, b), lab.astype(self._small, copy=False))

    def _workers(self) -> Any:
        if self._pool is None:
            from csplab.engine.pool import Workers

            if self.scheduler is None:
                self._pool = Workers.local(self.workers, initializer=_init_worker,
                                           initargs=(self.solvers,))  # fmt: skip
            else:
                self._pool = Workers.dask(self.scheduler, purpose="csplab.World with scheduler=",
                                          local_workers=max(1, self.workers))  # fmt: skip
                self._shared = self._pool.share(self.solvers)
        return self._pool

    def close(self) -> None:
        """Stop the workers and close the store."""
        if self._pool is not None:
            self._pool.close()
            self._pool = None
        if self._db is not None:
            self._db.close()
            self._db = None

    def __enter__(self) -> World:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- public ---------------------------------------------------------------------------
    def _key(self) -> str:
        t = self.template
        h = hashlib.sha256()
        for arr in (t.relations, t.domains, np.asarray(t.weights), t.arcs, self.M0):
            h.update(np.ascontiguousarray(arr).tobytes())
        thin = ["thin seams", self.margin] if self.margin else []  # another lattice
        h.update(json.dumps([LATTICE, *thin, self.seed, self.chunk_shape, self.block, self.passes,
                             self.retries, self.exact, self.order, self.choice, self.zfaces,
                             sorted(self.fixed.items()), _name_of(self.mask),
                             [c.to_json(self.chunk_problem) for c in self.chunk_constraints],
                             ]).encode())  # fmt: skip
        return h.hexdigest()[:32]

    def chunk(self, i: int, j: int, k: int = 0) -> NDArray[np.int32]:
        """The labels of chunk ``(i, j)``: cells ``[i * X, (i + 1) * X) x [j * Y, ...)``.

        Parameters
        ----------
        i, j : int
            The chunk's coordinates (any integers).
        k : int
            Must be 0: a 3D world's height is one chunk.

        Returns
        -------
        ndarray of int32
            The chunk's labels, shape ``chunk`` (a copy: the caller may change it).

        Raises
        ------
        InputError
            When ``k`` is not 0.
        """
        if k != 0:
            raise InputError("a world is one chunk high: k must be 0")
        key = (int(i), int(j))
        got = self.chunks.get_(key)
        if got is not None:
            return got.astype(np.int32)  # type: ignore[no-any-return]
        if self._db is not None:
            row = self._db.execute(
                "SELECT data FROM chunks WHERE world=? AND i=? AND j=?", (self.key, *key)
            ).fetchone()
            if row is not None:
                arr = np.frombuffer(row[0], dtype=np.int32).reshape(self._bshape).copy()
                self.chunks.put(key, arr.astype(self._small))
                self.stats["stored"] += 1
                return arr.copy()
        rect = self._chunk_rect(*key)
        if self.parallel:
            self._prefetch(rect)
        arr = self._state(self.S, rect)
        self.chunks.put(key, arr.astype(self._small))
        if self._db is not None:
            self._db.execute("INSERT OR REPLACE INTO chunks VALUES (?, ?, ?, ?)",
                             (self.key, *key, arr.tobytes()))  # fmt: skip
            self._db.commit()
        return arr.copy()

    def region(
        self, xs: tuple[int, int], ys: tuple[int, int], *, progress: bool = False
    ) -> NDArray[np.int32]:
        """The labels of cells ``[x0, x1) x [y0, y1)`` (3D: the whole height).

        Parameters
        ----------
        xs, ys : tuple of int
            ``(x0, x1)`` and ``(y0, y1)``, half-open, any integers.
        progress : bool
            A bar on stderr (after 2 s) counting chunks.

        Returns
        -------
        ndarray of int32
            The region stitched from chunks.

        Raises
        ------
        InputError
            When the region is empty.
        """
        from csplab.progress import progress_bar

        (x0, x1), (y0, y1) = (int(xs[0]), int(xs[1])), (int(ys[0]), int(ys[1]))
        if x1 <= x0 or y1 <= y0:
            raise InputError(f"empty region {xs}, {ys}")
        X, Y = self.B
        out = np.empty((x1 - x0, y1 - y0, *self._bshape[2:]), dtype=np.int32)
        rows = range(x0 // X, (x1 - 1) // X + 1)
        cols = range(y0 // Y, (y1 - 1) // Y + 1)

        def band(i: int, k: int) -> Rect:
            return ((i * X, (i + k) * X), (cols[0] * Y, (cols[-1] + 1) * Y))

        def chunks() -> Iterable[tuple[int, int]]:
            i = rows[0]
            while i <= rows[-1]:
                k = rows[-1] + 1 - i
                if self.parallel:  # bands of rows on the workers: as many as half the cache
                    while k > 1 and sum(map(len, self._needed(band(i, k), self.blocks))) > (
                        self.blocks.size // 2
                    ):
                        k = (k + 1) // 2
                    self._prefetch(band(i, k))
                for r in range(i, i + k):
                    for j in cols:
                        yield r, j
                i += k

        for i, j in progress_bar(chunks(), total=len(rows) * len(cols), desc="chunks",
                                 enabled=progress, unit="chunk"):  # fmt: skip
            c = self.chunk(i, j)
            lo = (max(x0, i * X), max(y0, j * Y))
            hi = (min(x1, (i + 1) * X), min(y1, (j + 1) * Y))
            out[lo[0] - x0 : hi[0] - x0, lo[1] - y0 : hi[1] - y0] = c[
                lo[0] - i * X : hi[0] - i * X, lo[1] - j * Y : hi[1] - j * Y
            ]
        return out

    def chunks_in(self, xs: tuple[int, int], ys: tuple[int, int]) -> Iterable[tuple[int, int]]:
        """The chunk coordinates a region covers, in order.

        Parameters
        ----------
        xs, ys : tuple of int
            ``(x0, x1)`` and ``(y0, y1)``, half-open.

        Yields
        ------
        tuple of int
            ``(i, j)`` of each chunk, row by row.
        """
        X, Y = self.B
        for i in range(xs[0] // X, (xs[1] - 1) // X + 1):
            for j in range(ys[0] // Y, (ys[1] - 1) // Y + 1):
                yield i, j

    def unmet(self, xs: tuple[int, int], ys: tuple[int, int]) -> list[tuple[int, ...]]:
        """The fixed cells in the region whose label differs from the requested one.

        Parameters
        ----------
        xs, ys : tuple of int
            ``(x0, x1)`` and ``(y0, y1)``, half-open.

        Returns
        -------
        list of tuple of int
            The world coordinates of those cells, sorted.
        """
        g = self.region(xs, ys)
        out = []
        for k, v in sorted(self.fixed.items()):
            if xs[0] <= k[0] < xs[1] and ys[0] <= k[1] < ys[1]:
                if int(g[(k[0] - xs[0], k[1] - ys[0], *k[2:])]) != v:
                    out.append(k)
        return out


    def unmet_chunks(self, xs: tuple[int, int], ys: tuple[int, int]) -> list[tuple[int, int]]:
        """The chunks of a region whose labels break a per-chunk constraint.

        The check is the chunk grid's :meth:`Problem.violations` (:attr:`chunk_problem`).

        Parameters
        ----------
        xs, ys : tuple of int
            ``(x0, x1)`` and ``(y0, y1)``, half-open.

        Returns
        -------
        list of tuple of int
            ``(i, j)`` of those chunks, row by row (none without per-chunk constraints).
        """
        if not self.chunk_constraints:
            return []
        return [(i, j) for i, j in self.chunks_in(xs, ys)
                if len(self.chunk_problem.violations(self.chunk(i, j)))]  # fmt: skip


def network_per_chunk(
    chunk: Sequence[int], labels: Sequence[int], ports: NDArray[np.bool_] | None = None
) -> tuple[list[Constraint], Callable[..., Any] | None]:
    """Per-chunk constraints (and a mask) under which every 4-connected set of chunks is
    one network.

    ``Connected(labels)`` per chunk (:data:`PER_CHUNK`) makes each chunk's set one
    component touching its four sides, but two neighbouring chunks may touch their shared
    side at different cells: their components need not meet. Matched sides: each chunk's
    component holds the middle cell of each side (``(0, Y // 2)``, ``(X - 1, Y // 2)``,
    ``(X // 2, 0)``, ``(X // 2, Y - 1)``), so across a shared side two cells of the set
    face each other and join the two components. With ``ports`` (connections through open
    tile edges) the mask also opens each middle cell's edge across its side, in world
    coordinates (every pass sees it, so the chunk solved first does not fix a closed edge
    its neighbour cannot open); the model's rules must join an open edge to an open edge
    only (pipes, roads).

    Parameters
    ----------
    chunk : sequence of int
        The world's chunk ``(X, Y)`` (2D).
    labels : sequence of int
        The set (the roads).
    ports : bool array ``(K, 4)``, optional
        Open edges per label (``x-, x+, y-, y+``), as :class:`csplab.constraints.Connected`.

    Returns
    -------
    list of Constraint
        For ``World(chunk_constraints=...)``.
    callable or None
        For ``World(mask=...)`` (with ``ports``).

    Raises
    ------
    InputError
        For a 3D chunk, or one too small to have four middle cells.

    Examples
    --------
    >>> cons, mask = network_per_chunk((8, 8), [1])
    >>> [c.kind for c in cons], mask
    (['connected'], None)
    """
    if len(chunk) != 2 or min(chunk) < 2:
        raise InputError(f"a matched network needs a 2D chunk of at least 2x2, not {chunk!r}")
    X, Y = (int(c) for c in chunk)
    mids = [(0, Y // 2), (X - 1, Y // 2), (X // 2, 0), (X // 2, Y - 1)]
    cons: list[Constraint] = [Connected(list(labels), [x * Y + y for x, y in mids], ports)]
    if ports is None:
        return cons, None
    P = np.asarray(ports, dtype=bool)
    inset = np.zeros(P.shape[0], dtype=bool)
    inset[list(labels)] = True
    return cons, _SideMask(X, Y, mids, P & inset[:, None])


class _SideMask:
    """The labels allowed at world cells: at each chunk's side middles, those of the set
    whose edge across that side is open (:func:`network_per_chunk`); a plain object, so
    workers can take it, named by its settings in the store's key."""

    def __init__(
        self, X: int, Y: int, mids: Sequence[tuple[int, int]], open_: NDArray[np.bool_]
    ) -> None:
        self.X, self.Y, self.mids, self.open = X, Y, list(mids), open_
        digest = hashlib.sha256(np.ascontiguousarray(open_).tobytes()).hexdigest()[:12]
        self.__qualname__ = f"_SideMask({X}x{Y}, {digest})"

    def __call__(self, xs: NDArray[np.int64], ys: NDArray[np.int64]) -> NDArray[np.bool_]:
        al = np.ones((*np.shape(xs), self.open.shape[0]), dtype=bool)
        for face, (x, y) in enumerate(self.mids):
            al[(xs % self.X == x) & (ys % self.Y == y)] = self.open[:, face]
        return al


def _name_of(f: Callable[..., Any] | None) -> str | None:
    """A mask's identity in the store key: its module and qualified name."""
    if f is None:
        return None
    return f"{getattr(f, '__module__', '')}.{getattr(f, '__qualname__', type(f).__name__)}"

