"""The catalog C (thesis Sec. 3.3.2, Alg. 3.2/3.3): arc consistency on a :class:`Problem`.

A catalog is a boolean array ``(n, K)`` (reshape to ``(*shape, K)`` to view it on the grid):
``C[x, b]`` says label ``b`` is still possible at cell ``x``. :func:`propagate` computes the
largest catalog inside the given one that satisfies statements 3.6 (every label keeps a
support across every arc) and 3.7 (assigned cells hold one label) -- arc consistency -- and
reports whether a domain was wiped out. By Theorem 3.3.2 it never removes a label that
occurs in some solution.

:func:`propagate` runs the compiled bitset kernel of :mod:`csplab._kernels`;
:func:`propagate_reference` is a slow, literal transcription of Alg. 3.2/3.3 kept for tests.
:class:`Propagator` is the stateful engine solvers use (assign, propagate, save/restore,
and one method per compiled kernel: Alg. 3.1, MAC search); :class:`Run`, :class:`Heap` and
:class:`Search` are the argument bundles of those kernels and :class:`Code` their return
codes (defined in :mod:`csplab._kernels`).

Examples
--------
>>> import numpy as np
>>> from csplab import ExampleModel, from_example
>>> E = ExampleModel([[0, 1], [1, 0]])                  # checkerboard
>>> P = from_example(E, (3, 3))
>>> C = initial_catalog(P)
>>> C, ok = assign(P, C, P.cell((0, 0)), 1)
>>> ok
True
>>> C.reshape(3, 3, 2).argmax(axis=2).tolist()          # the whole board is forced
[[1, 0, 1], [0, 1, 0], [1, 0, 1]]
"""

from __future__ import annotations

import weakref
from collections import deque
from collections.abc import Callable
from typing import Any, NamedTuple, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab import _interp
from csplab import _kernels as kern
from csplab._kernels import Code, Heap, Run, Search
from csplab.constraints import Constraint, propagate_all
from csplab.errors import InputError
from csplab.limits import check_memory
from csplab.problem import Problem, memory_estimate

__all__ = [
    "HEAP_ORDERS",
    "BlockArrays",
    "Code",
    "Heap",
    "Propagator",
    "Run",
    "Search",
    "SupportTables",
    "alg31_flags",
    "assign",
    "block_arrays",
    "initial_catalog",
    "neighbourhood",
    "pack",
    "propagate",
    "propagate_reference",
    "reference_adjacency",
    "reference_fixpoint",
    "solve_block_arrays",
    "support_tables",
    "sweep_blocks",
    "unpack",
]


#: the orders of Alg. 3.1 that take the next cell from a heap of keys (entropies, or
#: domain sizes for min-domain)
HEAP_ORDERS = ("min-entropy", "min-domain")


def alg31_flags(order: str, choice: str) -> tuple[bool, bool, bool]:
    """Alg. 3.1's ``order`` and ``choice`` as the kernels' flags ``(heap, weighted,
    key_weighted)``: the next cell is popped from a heap, labels are drawn by weight, the
    heap's keys are weighted entropies (min-entropy with weighted choice; min-domain (MRV)
    keys count labels)."""
    weighted = choice == "weighted"
    return order in HEAP_ORDERS, weighted, weighted and order == "min-entropy"


# ----------------------------------------------------------------------------- bitsets


def words(K: int) -> int:
    return max(1, (K + 63) // 64)


def pack(catalog: ArrayLike) -> NDArray[np.uint64]:
    """Boolean ``(n, K)`` -> bitsets ``uint64 (n, ceil(K/64))`` (bit ``b`` = label ``b``)."""
    C = np.asarray(catalog, dtype=bool)
    n, K = C.shape
    W = words(K)
    padded = np.zeros((n, W * 64), dtype=bool)
    padded[:, :K] = C
    by = np.packbits(padded, axis=1, bitorder="little")
    return np.ascontiguousarray(by).view("<u8").astype(np.uint64).reshape(n, W)


def unpack(bits: NDArray[np.uint64], K: int) -> NDArray[np.bool_]:
    """Inverse of :func:`pack`."""
    n = bits.shape[0]
    by = np.ascontiguousarray(bits.astype("<u8")).view(np.uint8).reshape(n, -1)
    return np.unpackbits(by, axis=1, bitorder="little")[:, :K].astype(bool)


# ----------------------------------------------------------------------------- engine


class SupportTables(NamedTuple):
    """What the kernels read of a rule set: the support bitsets of every label in both
    directions of every relation, and the label weights."""

    full: NDArray[np.uint64]  #: ``(W,)`` bitset of every label
    sup: NDArray[np.uint64]  #: ``(2R, K, W)`` supports of each label
    supall: NDArray[np.uint64]  #: ``(2R, W)`` union of the supports of all labels
    weights: NDArray[np.float64]  #: ``(T, K)`` per weight class
    wlogw: NDArray[np.float64]  #: ``(T, K)`` ``w log w`` (0 where ``w = 0``)
    #: ``(n,)`` each cell's weight class, or ``(1,)``: class 0 for every cell
    wclass: NDArray[np.int64]
    #: ``(ceil(K / b), 2**b, 2R * W)`` :func:`nibble_supports` for slices of ``b = 8`` or
    #: ``4`` labels (``(0, 16, 0)``: none)
    nib: NDArray[np.uint64]


#: the most labels for which :func:`support_tables` builds a table of slice supports (its
#: size grows as ``K**2``; beyond it a revision ORs the supports of the labels one by one)
NIBBLE_MAX_K = 256
#: the largest table of 8-label slices :func:`support_tables` builds, in bytes (else 4-label
#: slices: 16 times fewer rows, twice as many per revision). The overlapping model of
#: ``tests/io/data/sample.png`` (K=69, 2D) takes 147 KiB; its 48x48 Alg. 3.1 runs were 10%
#: faster than with the nibble table
BYTE_TABLE_MAX = 1 << 19


def nibble_supports(sup: NDArray[np.uint64], bits: int = 4) -> NDArray[np.uint64]:
    """The union of the supports of every ``bits``-label slice of a domain (4: nibbles, 8:
    bytes), in every direction.

    ``nib[j, x, s * W + w]`` is word ``w`` of the union of ``sup[s, a]`` over the labels
    ``a = bits * j + b`` with bit ``b`` set in ``x``, so the support of a whole domain ``D``
    in every direction at once is the OR of ``nib[j, (D >> bits * j) & (2**bits - 1)]``
    over the slices of ``D``: ``ceil(K / bits)`` contiguous rows, whatever the domain size
    (the kernels' revision of the neighbours of a cell that lost many labels,
    :func:`csplab._kernels.propagate`). Row ``1 << b`` of slice ``j`` is the support of
    label ``bits * j + b`` alone.

    Parameters
    ----------
    sup : uint64 array ``(S, K, W)``
        The support bitsets of each label in each direction (:class:`SupportTables`).
    bits : int
        Labels per slice: 4 or 8 (a divisor of 64, so no slice straddles two words).

    Returns
    -------
    uint64 array ``(ceil(K / bits), 2**bits, S * W)``

    Raises
    ------
    InputError
        When ``bits`` is not 4 or 8.

    Examples
    --------
    >>> sup = pack(np.eye(3, dtype=bool)[[1, 2, 0]]).reshape(1, 3, 1)  # a -> a + 1 mod 3
    >>> bool(nibble_supports(sup)[0, 0b011, 0] == pack(np.array([[0, 1, 1]], dtype=bool))[0, 0])
    True
    >>> nibble_supports(sup, bits=8).shape
    (1, 256, 1)
    """
    if bits not in (4, 8):
        raise InputError(f"bits must be 4 or 8, not {bits}")
    S, K, W = sup.shape
    J = -(-K // bits)
    padded = np.zeros((S, bits * J, W), dtype=np.uint64)
    padded[:, :K] = sup
    quads = padded.reshape(S, J, bits, W)
    out = np.zeros((J, 1 << bits, S, W), dtype=np.uint64)
    for x in range(1, 1 << bits):
        low = (x & -x).bit_length() - 1  # the row of x without its lowest bit, plus that bit
        out[:, x] = out[:, x & (x - 1)] | quads[:, :, low].transpose(1, 0, 2)
    return np.ascontiguousarray(out.reshape(J, 1 << bits, S * W))


def support_tables(
    relations: NDArray[np.bool_], weights: ArrayLike, wclass: ArrayLike | None = None
) -> SupportTables:
    """The :class:`SupportTables` of ``relations`` (``(R, K, K)``) and label ``weights``
    (``(K,)``, or ``(T, K)`` per weight class with each cell's class ``wclass``)."""
    R, K = relations.shape[0], relations.shape[1]
    W = words(K)
    both = np.empty((2 * R, K, K), dtype=bool)
    both[0::2] = relations
    both[1::2] = relations.transpose(0, 2, 1)
    sup = pack(both.reshape(2 * R * K, K)).reshape(2 * R, K, W)
    supall = pack(both.any(axis=1))  # (2R, W): union of supports of all labels
    full = pack(np.ones((1, K), dtype=bool))[0]
    w = np.ascontiguousarray(np.asarray(weights, dtype=np.float64).reshape(-1, K))
    with np.errstate(divide="ignore", invalid="ignore"):
        wlogw = np.ascontiguousarray(np.where(w > 0, w * np.log(np.where(w > 0, w, 1.0)), 0.0))
    wc = np.zeros(1, dtype=np.int64) if wclass is None else np.ascontiguousarray(
        np.asarray(wclass, dtype=np.int64).reshape(-1))  # fmt: skip
    if K > NIBBLE_MAX_K:
        nib = np.zeros((0, 16, 0), dtype=np.uint64)
    else:  # bytes when their table is small enough, else nibbles
        byte_table = -(-K // 8) * 256 * sup.shape[0] * W * 8
        nib = nibble_supports(sup, 8 if byte_table <= BYTE_TABLE_MAX else 4)
    return SupportTables(full, sup, supall, w, wlogw, wc, nib)


class _Compiled:
    """CSR adjacency and support bitsets of a problem (shared by engines of one problem)."""

    def __init__(self, problem: Problem) -> None:
        n, K = problem.n, problem.K
        # the problem exists already: only what the engine adds must still fit
        size = "x".join(map(str, problem.shape))
        check_memory(memory_estimate(n, K, len(problem.arcs), problem=False),
                     f"{size} with K={K}", "a smaller --size, or fewer labels",
                     available=True)  # fmt: skip
        W = words(K)
        a = problem.arcs
        keep = a[:, 0] != a[:, 1]  # self-arcs are folded into the domains
        self.ptr = np.zeros(n + 1, dtype=np.int64)
        if _interp.use_interp(n, K):  # small: numpy (numba stays unloaded)
            a = a[keep]
            src = np.concatenate([a[:, 0], a[:, 1]])
            dst = np.concatenate([a[:, 1], a[:, 0]])
            sid = np.concatenate([2 * a[:, 2], 2 * a[:, 2] + 1])
            o = np.argsort(src, kind="stable")
            self.nbr = np.ascontiguousarray(dst[o], dtype=np.int64)
            self.sidx = np.ascontiguousarray(sid[o], dtype=np.int64)
            np.cumsum(np.bincount(src, minlength=n), out=self.ptr[1:])
        else:  # the same rows by counting sort, in O(arcs) (5x faster at 10^7 cells)
            ends = 2 * int(np.count_nonzero(keep))
            self.nbr = np.empty(ends, dtype=np.int64)
            self.sidx = np.empty(ends, dtype=np.int64)
            kern.arc_csr(np.ascontiguousarray(a, dtype=np.int64), self.ptr, self.nbr, self.sidx)
        t = support_tables(problem.relations, *problem.weight_classes())
        self.sup, self.supall, self.full, self.nib = t.sup, t.supall, t.full, t.nib
        self.n, self.K, self.W = n, K, W
        #: the arc-consistent catalog of the problem's own domains (bits, prev, stats, ok,
        #: wiped): every solve of the problem starts from it, so it is computed once
        self.initial: tuple[Any, Any, Any, bool, int] | None = None
        self._doms: NDArray[np.uint64] | None = None  # packed_domains(), built on demand
        #: per weighting, the entropies (and weight sums) of that catalog
        self.entropies: dict[bool, tuple[Any, Any, Any]] = {}
        self.weights, self.wlogw, self.wclass = t.weights, t.wlogw, t.wclass
        # the same arrays as one kernel argument
        self.arcs = kern.Arcs(
            self.full, self.ptr, self.nbr, self.sidx, self.sup, self.supall, self.weights,
            self.wlogw, self.wclass, self.nib,
        )  # fmt: skip

    def packed_domains(self, problem: Problem) -> NDArray[np.uint64]:
        """The problem's domains packed, once (modify in blocks cuts each block's from them)."""
        if self._doms is None:
            self._doms = pack(problem.domains)
        return self._doms


#: the most calls in a row :meth:`Propagator.constrain` skips a constraint judged unchanged
_FULL_EVERY = 16


class Propagator:
    """Stateful bitset arc-consistency engine for one :class:`Problem`.

    The state is the packed catalog ``bits`` (``uint64 (n, W)``). :meth:`assign` and
    :meth:`restrict` shrink it and propagate; :meth:`save`/:meth:`load` copy it for
    backtracking. The compiled kernels of :mod:`csplab._kernels` that work on this state are
    called only through the methods here, one per kernel: :meth:`propagate` (arc
    consistency), :meth:`alg31` (Alg. 3.1), :meth:`mac_search` and :meth:`mac_restart`
    (the ``backtrack`` solver).

    Parameters
    ----------
    problem : Problem
    domains : bool array ``(n, K)``, optional
        Start from this catalog instead of the problem's domains.
    propagate_initial : bool
        Make the initial domains arc consistent right away (default).

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> P = from_example(ExampleModel([0, 1, 2]), (3,))
    >>> eng = Propagator(P)
    >>> eng.catalog().astype(int).tolist()              # 1D: only the example itself
    [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    """

    def __init__(
        self,
        problem: Problem,
        *,
        domains: ArrayLike | None = None,
        propagate_initial: bool = True,
    ) -> None:
        self.problem = problem
        self.c = _compiled_for(problem)
        n = problem.n
        self._queue = np.zeros(max(n, 1), dtype=np.int64)
        self._inq = np.zeros(max(n, 1), dtype=np.bool_)
        self.refuted_by: str | None = None  # the global constraint :meth:`constrain` broke
        self.prunings = 0  # calls of :meth:`constrain` whose propagators removed labels
        # per constraint: its last fixpoint (can, must) and the calls skipped since
        self._last: list[tuple[NDArray[np.bool_], NDArray[np.bool_]] | None] = []
        self._skips: list[int] = []
        self.bits: NDArray[np.uint64]
        self.prev: NDArray[np.uint64]  # D(u) when u was last processed by the kernel (0: unknown)
        self.stats: NDArray[np.int64]  # pops, removals
        self.ok: bool
        self.wiped: int
        init = self.c.initial if propagate_initial and domains is None else None
        if init is not None:  # the problem's own fixpoint, computed once per problem
            self.bits, self.prev = init[0].copy(), init[1].copy()
            self.stats = init[2].copy()
            self.ok, self.wiped = init[3], init[4]
            return
        self.bits = pack(problem.domains if domains is None else _check_catalog(problem, domains))
        self.prev = np.zeros_like(self.bits)
        self.stats = np.zeros(2, dtype=np.int64)
        self.ok = bool(np.all(self.bits.any(axis=1))) if n else True
        self.wiped = -1 if self.ok else int(np.flatnonzero(~self.bits.any(axis=1))[0])
        if propagate_initial and self.ok:
            self.propagate(None)
            if domains is None:
                self.c.initial = (self.bits.copy(), self.prev.copy(), self.stats.copy(),
                                  self.ok, self.wiped)  # fmt: skip

    # --------------------------------------------------------------- core
    def propagate(self, changed: ArrayLike | None = None) -> bool:
        """Propagate from ``changed`` cells (default: all); returns ``False`` on wipe-out."""
        if not self.ok:
            return False
        start = (
            np.arange(self.c.n, dtype=np.int64)
            if changed is None
            else np.ascontiguousarray(np.asarray(changed, dtype=np.int64).ravel())
        )
        if _interp.use_interp(self.c.n, self.c.K):
            wiped = _interp.propagate(self.c, self.bits, self.prev, self.stats, start)
        else:
            wiped = kern.propagate(self.c.arcs, self._ac(), start, start.size, _NO_HEAP, 0, False)
        if wiped >= 0:
            self.ok = False
            self.wiped = int(wiped)
        return self.ok

    def assign(self, cell: int, label: int) -> bool:
        """Set ``cell`` to ``label`` (statement 3.7) and propagate; ``False`` on wipe-out."""
        if not 0 <= label < self.c.K:
            raise InputError(f"label {label} outside 0..{self.c.K - 1}")
        if not self.ok:
            return False
        w, bit = divmod(int(label), 64)
        if not (int(self.bits[cell, w]) >> bit) & 1:
            self.bits[cell] = 0
            self.ok = False
            self.wiped = int(cell)
            return False
        self.bits[cell] = 0
        self.bits[cell, w] = np.uint64(1) << np.uint64(bit)
        return self.propagate([cell])

    def restrict(self, cell: int, allowed: ArrayLike) -> bool:
        """Intersect ``D(cell)`` with a boolean label mask and propagate."""
        if not self.ok:
            return False
        m = pack(np.asarray(allowed, dtype=bool).reshape(1, -1))[0]
        new = self.bits[cell] & m
        if np.array_equal(new, self.bits[cell]):
            return True
        self.bits[cell] = new
        if not new.any():
            self.ok = False
            self.wiped = int(cell)
            return False
        return self.propagate([cell])

    def narrow(self, allowed: ArrayLike) -> bool:
        """Intersect every domain with ``allowed`` (bool ``(n, K)``) and propagate from the
        cells that changed; ``False`` on wipe-out."""
        if not self.ok:
            return False
        new = self.bits & pack(np.asarray(allowed, dtype=bool))
        changed = np.flatnonzero((new != self.bits).any(axis=1))
        if not changed.size:
            return True
        self.bits[changed] = new[changed]
        empty = changed[~new[changed].any(axis=1)]
        if empty.size:
            self.ok = False
            self.wiped = int(empty[0])
            return False
        return self.propagate(changed)

    def constrain(self, search: Search | None = None, *, incremental: bool = False) -> int:
        """Prune the catalog with the problem's global constraints
        (:func:`csplab.constraints.propagate_all`) and arc consistency until neither removes
        more. Inside a MAC ``search`` the removals go on its trail (undone with the current
        decision). Returns -2 when a constraint propagator refutes the catalog (its
        description in ``refuted_by``), the wiped cell when arc consistency does, -1 when
        the catalog survives.

        When every constraint has a set propagator
        (:meth:`~csplab.constraints.Constraint.set_labels`: count, unported connectivity)
        the catalog stays packed: each reads which cells may and must take its labels
        straight from the bitsets (:func:`csplab._kernels.set_status`), and a constraint
        runs again only when that changed. Its fixpoint is the unpacked loop's
        (:meth:`constrain_unpacked`; the propagators are monotone, tests check equality).

        ``incremental`` (Alg. 3.1, whose catalog only shrinks between calls): remember
        each constraint's last fixpoint across calls and skip a constraint whose changes
        since cannot prune (:meth:`~csplab.constraints.Constraint.prunes_nothing_new`),
        at most ``_FULL_EVERY`` times in a row; the full run then catches up."""
        sets = self._set_masks()
        if sets is None:
            return self.constrain_unpacked(search)
        if not incremental or len(self._last) != len(sets):
            self._last = [None] * len(sets)
            self._skips = [0] * len(sets)
        seen = self._last
        for _ in range(100_000):
            quiet = True
            status: dict[bytes, tuple[NDArray[np.bool_], NDArray[np.bool_]]] = {}
            for i, (con, sp) in enumerate(sets):
                key = sp.tobytes()  # constraints over one label set read one status
                if key not in status:
                    status[key] = kern.set_status(self.bits, sp)
                can, must = status[key][0], status[key][1].copy()
                last = seen[i]
                if last is not None and (
                    (np.array_equal(last[0], can) and np.array_equal(last[1], must))
                    or (self._skips[i] < _FULL_EVERY
                        and con.prunes_nothing_new(self.problem, can, must, last))
                ):  # fmt: skip
                    self._skips[i] += 1
                    continue
                self._skips[i] = 0
                mine = must.copy()
                got = con.prune_sets(self.problem, can, must)
                if got is None:
                    self.refuted_by = con.describe(self.problem)
                    return -2
                leave, join = got
                if not leave.size and not join.size:
                    seen[i] = (can, mine)  # a fixpoint of this constraint
                    continue
                cells = np.concatenate([leave, join])
                rows = self.bits[cells].copy()
                rows[: leave.size] &= ~sp
                rows[leave.size :] &= sp
                if np.array_equal(rows, self.bits[cells]):
                    seen[i] = (can, mine)
                    continue
                seen[i] = None
                if quiet:
                    self.prunings += 1
                quiet = False
                status.clear()  # the catalog changes below
                if search is None:
                    self.bits[cells] = rows
                    if not self.propagate(cells):
                        return self.wiped
                else:
                    wiped = kern.mac_restrict(self.c.arcs, self._ac(), search, cells, rows)
                    if wiped >= 0:
                        return int(wiped)
            if quiet:
                return -1
        return -1

    def _set_masks(self) -> list[tuple[Constraint, NDArray[np.uint64]]] | None:
        """Each constraint with its packed label set, or ``None`` when one has no set
        propagator."""
        cached = self.__dict__.get("_sets")
        if cached is not None:
            return cached if cached else None
        out: list[tuple[Constraint, NDArray[np.uint64]]] = []
        for con in self.problem.constraints:
            S = con.set_labels(self.problem)
            if S is None:
                out = []
                break
            out.append((con, pack(S.reshape(1, -1))[0]))
        self.__dict__["_sets"] = out
        return out if out else None

    def constrain_unpacked(self, search: Search | None = None) -> int:
        """:meth:`constrain` on the unpacked catalog with
        :func:`csplab.constraints.propagate_all` (every kind of constraint)."""
        for _ in range(1000):
            cur = self.catalog()
            why: list[str] = []
            d = propagate_all(self.problem, cur, why)
            if d is None:
                self.refuted_by = why[0] if why else None
                return -2
            changed = np.flatnonzero((d != cur).any(axis=1))
            if not changed.size:
                return -1
            if search is None:
                if not self.narrow(d):
                    return self.wiped
                continue
            cells = np.ascontiguousarray(changed, dtype=np.int64)
            wiped = kern.mac_restrict(self.c.arcs, self._ac(), search, cells, pack(d[changed]))
            if wiped >= 0:
                return int(wiped)
        return -1

    # --------------------------------------------------------------- kernels
    def _ac(self) -> kern.AcState:
        """The mutable state as one kernel argument (built per call: arrays may be replaced)."""
        return kern.AcState(self.bits, self.prev, self._queue, self._inq, self.stats)

    def alg31(
        self, run: Run, heap: Heap | None = None, *, weighted: bool = False,
        max_steps: int | None = None, key_weighted: bool | None = None,
    ) -> Code:  # fmt: skip
        """Run (or resume) Alg. 3.1 on this catalog: :func:`csplab._kernels.alg31`.

        The cells come from ``run.order``, or from the entropy ``heap`` when one is given
        (the cells ``heap.heap[:run.state[1]]`` with their ``heap.key``; ordered into a heap
        when the run starts);
        labels are drawn uniformly or, with ``weighted``, by the problem's weights (the heap's
        entropy keys too, unless ``key_weighted`` says otherwise). Stops
        after ``max_steps`` assignments (default: none) with :attr:`~csplab._kernels.Code.PAUSED`.
        On :attr:`~csplab._kernels.Code.FAILED` the engine is marked wiped out (``ok``,
        ``wiped``). The catalog must be arc consistent (``ok``) when the run starts. Small
        problems run in :mod:`csplab._interp` until numba is loaded (same results).
        """
        n = self.c.n
        if (max_steps is None or max_steps >= n - run.steps) and _interp.use_interp(n, self.c.K):
            code = _interp.alg31(
                self.c, self.bits, self.prev, self.stats, run, heap, heap is not None, weighted,
                weighted if key_weighted is None else key_weighted,
            )  # fmt: skip
        else:
            if heap is not None and run.steps == 0:  # a new run: its cells, by key
                kern.heap_build(heap.heap, heap.pos, heap.key, int(run.state[1]))
            code = kern.alg31_flat(  # the bundles' fields: numba types them faster
                *self.c.arcs, *self._ac(), *run, *(_NO_HEAP if heap is None else heap),
                heap is not None, weighted, weighted if key_weighted is None else key_weighted,
                n + 1 if max_steps is None else int(max_steps),
            )  # fmt: skip
        result = Code(code)
        if result is Code.FAILED:
            self.ok = False
            self.wiped = run.fail_cell
        return result

    def mac_search(
        self, search: Search, *, scan: bool = False, weighted: bool = False,
        max_nodes: int, restart_fails: int = 0,
    ) -> Code:  # fmt: skip
        """Run (or resume) a MAC search on this catalog: :func:`csplab._kernels.mac_search`.

        ``search`` (:meth:`csplab._kernels.Search.new`) holds the decisions and the trail;
        the catalog is changed in place and stays inside the catalog at the first call (the
        trail only restores), so :meth:`propagate` remains valid afterwards. Codes:
        ``SOLVED`` (the catalog holds one label per cell), ``EXHAUSTED`` (unsatisfiable; the
        catalog is back at the root), ``RESTART`` (call :meth:`mac_restart`), ``PAUSED``
        (``max_nodes`` decisions made), ``GROW`` (continue with ``search.grown()``).
        """
        code = kern.mac_search(
            self.c.arcs, self._ac(), search, scan, weighted, int(max_nodes), int(restart_fails)
        )
        return Code(code)

    def mac_restart(self, search: Search) -> None:
        """Undo every decision of ``search`` (:func:`csplab._kernels.mac_restart`)."""
        kern.mac_restart(self._ac(), search)

    # --------------------------------------------------------------- state
    def save(self) -> tuple[NDArray[np.uint64], NDArray[np.uint64], bool, int]:
        """A snapshot of the catalog for :meth:`load` (backtracking)."""
        return self.bits.copy(), self.prev.copy(), self.ok, self.wiped

    def load(self, state: tuple[NDArray[np.uint64], NDArray[np.uint64], bool, int]) -> None:
        self.bits[...] = state[0]
        self.prev[...] = state[1]
        self.ok, self.wiped = state[2], state[3]
        self._last = []  # the catalog may have grown: no fixpoint to compare with

    def copy(self) -> Propagator:
        new = object.__new__(Propagator)
        new.__dict__.update(self.__dict__)
        new.bits = self.bits.copy()
        new.prev = self.prev.copy()
        new._queue = self._queue.copy()
        new._inq = self._inq.copy()
        new.stats = self.stats.copy()
        new._last, new._skips = list(self._last), list(self._skips)
        return new

    # --------------------------------------------------------------- views
    def catalog(self) -> NDArray[np.bool_]:
        """The current catalog as ``bool (n, K)``."""
        return unpack(self.bits, self.c.K)

    def domain(self, cell: int) -> NDArray[np.int64]:
        """Labels still possible at ``cell``."""
        return np.flatnonzero(unpack(self.bits[cell : cell + 1], self.c.K)[0])

    def sizes(self) -> NDArray[np.int64]:
        return np.asarray(self.catalog().sum(axis=1), dtype=np.int64)


class BlockArrays(NamedTuple):
    """One block of Alg. 3.4 as the kernels take it: its catalog before propagation
    (``dom0``, packed, with the fixed labels around it applied) and its internal arcs as CSR
    rows in local cell numbers (the arrays a worker process receives)."""

    dom0: NDArray[np.uint64]
    lptr: NDArray[np.int64]  #: (``int32`` after :meth:`compact`)
    lnbr: NDArray[np.int64]
    lsidx: NDArray[np.int64]

    def compact(self) -> BlockArrays:
        """The same block with ``int32`` arcs (to send to a worker: 40 % fewer bytes)."""
        i32 = np.int32
        return BlockArrays(self.dom0, self.lptr.astype(i32), self.lnbr.astype(i32),
                           self.lsidx.astype(i32))  # fmt: skip


def block_arrays(
    problem: Problem, grid: NDArray[np.int32], cells: NDArray[np.int64]
) -> BlockArrays:
    """The :class:`BlockArrays` of the block ``cells`` (sorted) of ``grid`` (flat,
    labelled): :func:`csplab._kernels.block_catalog`, what :meth:`Problem.subproblem`
    builds."""
    c = _compiled_for(problem)
    cells = np.ascontiguousarray(cells, dtype=np.int64)
    nb = cells.size
    deg = int((c.ptr[cells + 1] - c.ptr[cells]).sum())
    dom0 = np.empty((nb, c.W), dtype=np.uint64)
    lptr = np.zeros(nb + 1, dtype=np.int64)
    lnbr = np.empty(max(deg, 1), dtype=np.int64)
    lsidx = np.empty(max(deg, 1), dtype=np.int64)
    k = kern.block_catalog(c.arcs, c.packed_domains(problem), grid, cells, dom0, lptr, lnbr,
                           lsidx, np.zeros(0, dtype=np.int64))  # fmt: skip
    return BlockArrays(dom0, lptr, lnbr[:k].copy(), lsidx[:k].copy())


def solve_block_arrays(
    tables: SupportTables,
    block: BlockArrays,
    scan: NDArray[np.int64],
    retries: int,
    order: str,
    choice: str,
    rng: np.random.Generator,
) -> tuple[NDArray[np.int32] | None, int, int]:
    """Alg. 3.1 with retries on one block (:func:`csplab._kernels.block_alg31`): the labels
    (``None`` if every attempt failed), the retries and the queue pops spent; ``scan`` is
    the cell order inside the block (unused by the heap orders)."""
    heap, weighted, key_weighted = alg31_flags(order, choice)

    def i64(x: NDArray[Any]) -> NDArray[np.int64]:
        return np.ascontiguousarray(x, dtype=np.int64)

    local = kern.Arcs(tables.full, i64(block.lptr), i64(block.lnbr), i64(block.lsidx),
                      tables.sup, tables.supall, tables.weights, tables.wlogw,
                      tables.wclass, tables.nib)  # fmt: skip
    nb = block.dom0.shape[0]
    lgrid = np.empty(nb, dtype=np.int32)
    counters = np.zeros(4, dtype=np.int64)
    ok = kern.block_alg31(local, block.dom0, scan, int(retries), heap, weighted, key_weighted,
                          rng, lgrid, counters)  # fmt: skip
    return (lgrid if ok else None), int(counters[2]), int(counters[3])


def neighbourhood(problem: Problem, cells: NDArray[np.int64]) -> NDArray[np.int64]:
    """``cells`` and every cell joined to one of them by an arc (with repeats)."""
    c = _compiled_for(problem)
    start = c.ptr[cells]
    lens = c.ptr[cells + 1] - start
    total = int(lens.sum())
    offs = np.repeat(start - np.cumsum(lens) + lens, lens) + np.arange(total, dtype=np.int64)
    return np.concatenate([cells, c.nbr[offs]])


def sweep_blocks(
    problem: Problem,
    grid: NDArray[np.int32],
    bptr: NDArray[np.int64],
    bcells: NDArray[np.int64],
    span: tuple[int, int],
    scan: NDArray[np.int64],
    retries: int,
    order: str,
    choice: str,
    rng: np.random.Generator,
    counters: NDArray[np.int64],
) -> None:
    """Modify in blocks ``span[0] .. span[1] - 1`` of the blocks ``bcells[bptr[b]:bptr[b +
    1]]`` (sorted cells) of ``grid`` (flat, consistent, changed in place), one compiled
    kernel for the whole span: :func:`csplab._kernels.blocks_sweep`."""
    c = _compiled_for(problem)
    heap, weighted, key_weighted = alg31_flags(order, choice)
    kern.blocks_sweep(
        c.arcs, c.packed_domains(problem), grid, bptr, bcells, int(span[0]), int(span[1]),
        scan, int(retries), heap, weighted, key_weighted, rng, counters,
    )  # fmt: skip


# ----------------------------------------------------------------------------- pure API


def initial_catalog(problem: Problem) -> NDArray[np.bool_]:
    """The catalog before any assignment: a copy of the problem's domains (not propagated)."""
    return np.array(problem.domains, dtype=bool)


def _check_catalog(problem: Problem, catalog: ArrayLike) -> NDArray[np.bool_]:
    C = np.asarray(catalog, dtype=bool)
    if C.shape == (*problem.shape, problem.K):
        C = C.reshape(problem.n, problem.K)
    if C.shape != (problem.n, problem.K):
        raise InputError(f"catalog must have shape ({problem.n}, {problem.K}), got {C.shape}")
    return C


_F = TypeVar("_F", bound=Callable[..., Any])


def _contract_of(twin: Callable[..., Any]) -> Callable[[_F], _F]:
    """Decorator: append ``twin``'s sections from ``Parameters`` on to the decorated
    function's docstring, for a second implementation of the same contract (its text is
    written once; nothing when docstrings are stripped, ``python -OO``)."""

    def give(f: _F) -> _F:
        doc, contract = f.__doc__, twin.__doc__
        if doc and contract and "    Parameters\n" in contract:
            head = contract[contract.index("    Parameters\n") :]
            f.__doc__ = doc.rstrip() + "\n\n" + head.rstrip() + "\n    "
        return f

    return give


def propagate(
    problem: Problem, catalog: ArrayLike, changed: ArrayLike | None = None
) -> tuple[NDArray[np.bool_], bool]:
    """Arc-consistency fixpoint of statements 3.6/3.7 (compiled kernel).

    Parameters
    ----------
    problem : Problem
        The problem whose arcs are propagated.
    catalog : bool array ``(n, K)`` or ``(*shape, K)``
        Not modified.
    changed : array of cell indices, optional
        Cells whose entries were removed since the catalog was last consistent (default:
        all cells). Propagation starts from these.

    Returns
    -------
    catalog : bool array ``(n, K)``
        The largest arc-consistent catalog inside the given one.
    ok : bool
        ``False`` if some cell lost every label (a wipe-out); the catalog is then partial.

    Raises
    ------
    InputError
        When ``catalog`` has neither shape ``(n, K)`` nor ``(*shape, K)``.
    """
    eng = Propagator(problem, domains=catalog, propagate_initial=False)
    eng.propagate(changed)
    return eng.catalog(), eng.ok


def assign(
    problem: Problem, catalog: ArrayLike, cell: int, label: int
) -> tuple[NDArray[np.bool_], bool]:
    """Assign ``label`` to ``cell`` (statement 3.7) and propagate; returns a new catalog."""
    C = _check_catalog(problem, catalog).copy()
    if not C[cell, label]:
        C[cell] = False
        return C, False
    C[cell] = False
    C[cell, label] = True
    return propagate(problem, C, [cell])


@_contract_of(propagate)
def propagate_reference(
    problem: Problem, catalog: ArrayLike, changed: ArrayLike | None = None
) -> tuple[NDArray[np.bool_], bool]:
    """Slow, literal Alg. 3.2/3.3 (a stack of cells, statement 3.6 per neighbour).

    Same contract as :func:`propagate`, whose Parameters, Returns and Raises are appended
    here (one text for the twins); used to test the compiled kernel.
    """
    C = _check_catalog(problem, catalog).copy()
    adj = reference_adjacency(problem)
    if not C.any(axis=1).all():
        return C, False
    ok = reference_fixpoint(C, adj, range(problem.n) if changed is None else np.ravel(changed))
    return C, ok


def reference_adjacency(problem: Problem) -> list[list[tuple[int, NDArray[np.bool_]]]]:
    rel = problem.relations
    adj: list[list[tuple[int, NDArray[np.bool_]]]] = [[] for _ in range(problem.n)]
    for s, d, r in problem.arcs.tolist():
        if s == d:
            continue
        adj[s].append((d, rel[r]))  # T: C[d, c] needs some b in C[s] with T[b, c]
        adj[d].append((s, rel[r].T))
    return adj


def reference_fixpoint(
    C: NDArray[np.bool_], adj: list[list[tuple[int, NDArray[np.bool_]]]], changed: Any
) -> bool:
    """Alg. 3.2 lines 7-16 with Alg. 3.3 (statement 3.6), a stack of cells; in place."""
    stack = deque(int(c) for c in changed)
    onstack = np.zeros(C.shape[0], dtype=bool)
    onstack[list(stack)] = True
    while stack:
        v = stack.pop()
        onstack[v] = False
        for w, T in adj[v]:
            for c in np.flatnonzero(C[w]):
                # Alg. 3.3 line 2: is there a b with C[v, b] = 1 and T[b, c] = 1?
                if not np.any(C[v] & T[:, c]):
                    C[w, c] = False
                    if not onstack[w]:
                        stack.append(w)
                        onstack[w] = True
            if not C[w].any():
                return False
    return True


_NO_HEAP = Heap.empty()  # read-only: kernels touch the heap only when its size is > 0

# the compiled arrays of a problem live as long as the problem (keyed weakly by the object)
_COMPILED: weakref.WeakKeyDictionary[Problem, _Compiled] = weakref.WeakKeyDictionary()


def _compiled_for(problem: Problem) -> _Compiled:
    comp = _COMPILED.get(problem)
    if comp is None:
        comp = _COMPILED[problem] = _Compiled(problem)
    return comp
