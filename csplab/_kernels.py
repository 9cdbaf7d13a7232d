"""Compiled kernels (numba): bitset arc consistency, Alg. 3.1, MAC search and the CNF encoders.

Domains are bitsets ``uint64 (n, W)`` with ``W = ceil(K / 64)``. Each arc ``(u, v, r)`` is
stored twice in a CSR adjacency: at ``u`` as ``(v, 2r)`` and at ``v`` as ``(u, 2r + 1)``.
``sup[s, a]`` is the bitset of labels a neighbour may take when this cell has label ``a``
(``s = 2r``: the forward relation, ``s = 2r + 1``: its transpose).

Revising ``v`` from ``u`` (statement 3.6): ``D(v) &= OR_{a in D(u)} sup[s, a]``, stopping the
OR early once it covers ``D(v)``, or (``K <= 256``) the same OR read from the slice table
``Arcs.nib``: one row per 8 (or 4) labels of ``D(u)``, for every direction at once. A FIFO
queue of changed cells runs this to the fixpoint (Alg. 3.2/3.3 with a queue instead of a
stack; the fixpoint is the same).

All randomness is drawn by the caller from a numpy Generator and passed in as arrays (or, for
the MAC search, as a splitmix64 seed in its state), so the kernels are deterministic.

Arguments travel in bundles (:class:`typing.NamedTuple` s of arrays, which numba compiles as
structs): :class:`Arcs`, the static arrays
of a compiled problem; :class:`AcState`, the mutable arc-consistency state of one
:class:`csplab.catalog.Propagator`; :class:`Heap`, the min-entropy heap; :class:`Run`, one
Alg. 3.1 run; :class:`Search`, one MAC search. Kernels return a :class:`Code` (as an int:
numba returns ints; callers wrap it with ``Code(...)`` and compare by name). Only
:mod:`csplab.catalog` calls the propagation kernels: :class:`~csplab.catalog.Propagator` has
one method per kernel (``propagate``, ``alg31``, ``mac_search``, ``mac_restart``).

Kernel cache rule
-----------------
**Every ``@njit`` function that calls another csplab ``@njit`` function lives in this file.**
numba's on-disk cache (``cache=True``) checks a compiled function against its own source
file only (modification time and size): a caller in another file that inlined or linked a
helper from this one would keep its stale machine code after the helper changed. With every
caller and every helper in one file, editing any of them invalidates all of them together.
``tests/test_kernels.py::test_njit_callers_of_csplab_kernels_live_in_kernels`` enforces the
rule (``@njit`` functions elsewhere, such as the ctypes feeders of
:mod:`csplab.engine.sat`, may call only non-csplab functions).

Bundles are unpacked once per kernel call: the loops behind the entry points
(:func:`_propagate`, called per step by :func:`alg31`; :func:`_mac_search` and its
per-decision :func:`_propagate_trail`) keep flat array arguments and are the code of the
earlier flat-argument kernels, unchanged (with the loops reading bundle fields, the MAC
search measured 4-5% slower). The two arc revisions are copies on purpose: moving the loop
into a shared ``@njit`` helper (inlined or not) made Alg. 3.1 30-40% slower at 40x40x10
(castle, city; A/B of both kernels in one process, 16 shuffled rounds, identical copies
within 5-9%). Measured again with only the full revision (the covering loop that
:func:`_propagate` and :func:`_propagate_trail` share) moved into one
``inline="always"`` helper: Alg. 3.1 at 40x40x10, three runs, median of shuffled A/B
rounds in one process on a busy 2-core machine, helper / copies = 1.21 (castle) and 1.15
(city) over 8 rounds, 1.00 and 1.21 over 16: still slower, so the copies stay.
Domains of one word (``K <= 64``: castle) go to :func:`_propagate_w` compiled with
``W = 1`` (:func:`_propagate_w1`), two words to the same loop compiled with ``W = 2``
(:func:`_propagate_w2`, 65-128 labels: the overlapping model's patterns, city), and any
other number of words to it with ``W`` read from the array (:func:`_propagate_wn`): with
``W`` a constant its word loops unroll. A hand-written copy for one word held in registers
(``_propagate1``) was once 25% faster than the loop over ``W`` words; against the loop
compiled with ``W = 1`` it measured the same (castle 300x300x10 via blocks, 5 alternating
runs each: medians 2.05 s and 2.03 s of CPU; castle and pillar by catalog the same within
noise; the same bytes), so it went. The step loop of Alg. 3.1 (:func:`_alg31_loop`) and those two
are compiled without numba's reference counting (``_nrt=False``: they allocate nothing).
"""

from __future__ import annotations

from enum import IntEnum
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from csplab._jit import njit, trailing_zeros

# ----------------------------------------------------------------------------- return codes


class Code(IntEnum):
    """What a kernel run ended with (:func:`alg31`, :func:`mac_search`)."""

    SOLVED = 0  #: every cell has a label
    FAILED = 1  #: Alg. 3.1: a domain emptied (``Run.state[2]`` is that cell)
    PAUSED = 2  #: the step or node budget of this call is used up: call again to resume
    EXHAUSTED = 3  #: MAC: the search tree is exhausted, the problem is unsatisfiable
    RESTART = 4  #: MAC: the failure cutoff of this run is reached (restart, then resume)
    GROW = 5  #: MAC: the trail is nearly full (``Search.grown()``, then resume)


# numba compiles module-level ints as constants; the enum stays on the Python side
_SOLVED = int(Code.SOLVED)
_FAILED = int(Code.FAILED)
_PAUSED = int(Code.PAUSED)
_EXHAUSTED = int(Code.EXHAUSTED)
_RESTART = int(Code.RESTART)
_GROW = int(Code.GROW)

# ----------------------------------------------------------------------------- bundles


class Arcs(NamedTuple):
    """The static arrays of a compiled problem (built once per problem, never written)."""

    full: NDArray[np.uint64]  #: ``(W,)`` bitset of every label
    ptr: NDArray[np.int64]  #: ``(n + 1,)`` CSR row starts of the arcs of each cell
    nbr: NDArray[np.int64]  #: neighbour of each arc end
    sidx: NDArray[np.int64]  #: support index of each arc end (``2r`` or ``2r + 1``)
    sup: NDArray[np.uint64]  #: ``(2R, K, W)`` supports of each label
    supall: NDArray[np.uint64]  #: ``(2R, W)`` union of the supports of all labels
    weights: NDArray[np.float64]  #: ``(T, K)`` label weights per weight class
    wlogw: NDArray[np.float64]  #: ``(T, K)`` ``w log w`` (0 where ``w = 0``)
    #: ``(n,)`` the weight class (row of ``weights``) of each cell; ``(1,)``: class 0 for all
    wclass: NDArray[np.int64]
    #: ``(ceil(K / b), 2**b, 2R * W)`` the supports of every ``b``-label slice of a domain
    #: (``b`` = 4 or 8) in every direction (:func:`csplab.catalog.nibble_supports`);
    #: ``(0, 16, 0)``: none (large K)
    nib: NDArray[np.uint64]


class AcState(NamedTuple):
    """The mutable arc-consistency state of one propagator."""

    dom: NDArray[np.uint64]  #: ``(n, W)`` the catalog as bitsets
    prev: NDArray[np.uint64]  #: ``(n, W)`` ``D(u)`` when ``u`` was last processed (0: unknown)
    queue: NDArray[np.int64]  #: ``(n,)`` FIFO ring of cells (empty between calls)
    inq: NDArray[np.bool_]  #: ``(n,)`` queue membership (all False between calls)
    stats: NDArray[np.int64]  #: ``[queue pops, label removals]``


class Heap(NamedTuple):
    """Indexed min-heap of cells by entropy key (``min-entropy`` order; empty arrays: none)."""

    heap: NDArray[np.int64]  #: cells in heap order
    pos: NDArray[np.int64]  #: position of each cell in ``heap`` (-1: popped)
    key: NDArray[np.float64]  #: entropy + tie-breaking noise of each cell
    noise: NDArray[np.float64]  #: ``(n,)`` tie-breaking numbers in [0, 1)
    #: ``(n,)`` sum of the weights and of ``w log w`` over ``D(v)``, kept up to date by
    #: the propagation for weighted entropy keys (fast-wfc's memoised entropy: each removed
    #: label is subtracted once); empty arrays: recomputed from the domain
    sw: NDArray[np.float64] = np.zeros(0, dtype=np.float64)
    swl: NDArray[np.float64] = np.zeros(0, dtype=np.float64)

    @staticmethod
    def empty() -> Heap:
        z = np.zeros(0, dtype=np.int64)
        f = np.zeros(0, dtype=np.float64)
        return Heap(z, z, f, f, f, f)


class Run(NamedTuple):
    """One Alg. 3.1 run: ``state = [step, heap_size, fail_cell]``."""

    order: NDArray[np.int64]  #: cell of each step (scan orders, ``random``)
    ustream: NDArray[np.float64]  #: one uniform per step for the label choice
    grid: NDArray[np.int32]  #: ``(n,)`` the labels assigned so far (-1: none)
    trace_cell: NDArray[np.int64]  #: cell of each step
    trace_label: NDArray[np.int64]  #: label of each step
    state: NDArray[np.int64]  #: ``[step, heap_size, fail_cell]``

    @property
    def steps(self) -> int:
        return int(self.state[0])

    @property
    def fail_cell(self) -> int:
        return int(self.state[2])


# MAC search state slots (Search.state)
LEVEL, NEED, EPOCH, TLEN, NODES, FAILS, FAILS_RUN, RNG, SCAN = range(9)


class Search(NamedTuple):
    """One MAC search (:func:`mac_search`), resumable.

    ``state = [level, need_choose, epoch, trail_len, nodes, fails, fails_since_restart, rng,
    scan_pos]``. Level ``L >= 1`` is a decision on cell ``lv_cell[L]`` whose untried labels are
    ``lv_cand[L]``; ``lv_trail[L]`` is the trail length before its first attempt. The trail
    ``(tcell, tbits)`` holds the old domains of the cells changed since each decision.
    """

    stamp: NDArray[np.int64]  #: ``(n,)`` epoch in which a cell was last saved on the trail
    state: NDArray[np.int64]  #: the 9 slots above
    tcell: NDArray[np.int64]  #: trail: cell
    tbits: NDArray[np.uint64]  #: trail: its domain before the change
    lv_cell: NDArray[np.int64]
    lv_cand: NDArray[np.uint64]
    lv_trail: NDArray[np.int64]
    lv_scan: NDArray[np.int64]
    order: NDArray[np.int64]  #: cell sequence of the ``scanline`` order
    counters: NDArray[np.int64]  #: ``[queue pops, label removals]`` of the search

    @staticmethod
    def new(n: int, W: int, seed: int) -> Search:
        """A search at the root of ``n`` cells of ``W`` words, random numbers from ``seed``."""
        cap = max(4 * n, 1024)
        state = np.zeros(9, dtype=np.int64)
        state[NEED] = 1
        state[RNG] = seed
        return Search(
            stamp=np.full(n, -1, dtype=np.int64), state=state,
            tcell=np.zeros(cap, dtype=np.int64), tbits=np.zeros((cap, W), dtype=np.uint64),
            lv_cell=np.zeros(n + 2, dtype=np.int64),
            lv_cand=np.zeros((n + 2, W), dtype=np.uint64),
            lv_trail=np.zeros(n + 2, dtype=np.int64), lv_scan=np.zeros(n + 2, dtype=np.int64),
            order=np.arange(n, dtype=np.int64), counters=np.zeros(2, dtype=np.int64),
        )  # fmt: skip

    def grown(self) -> Search:
        """The same search with a trail twice as long (after :attr:`Code.GROW`)."""
        cap = 2 * self.tcell.size
        tcell = np.concatenate([self.tcell, np.zeros(cap - self.tcell.size, dtype=np.int64)])
        W = self.tbits.shape[1]
        tbits = np.concatenate([self.tbits, np.zeros((cap - self.tbits.shape[0], W), np.uint64)])
        return self._replace(tcell=tcell, tbits=tbits)

    @property
    def nodes(self) -> int:
        """Decisions so far (all runs)."""
        return int(self.state[NODES])

    @property
    def fails(self) -> int:
        """Wiped-out decisions so far (all runs)."""
        return int(self.state[FAILS])


# ----------------------------------------------------------------------------- bit helpers


@njit(cache=True, inline="always")
def ctz64(x: np.uint64) -> int:
    """Index of the lowest set bit of a non-zero uint64 (LLVM's ``cttz``, see
    :func:`csplab._jit.trailing_zeros`)."""
    return int(trailing_zeros(x))


@njit(cache=True, inline="always")
def popcount64(x: np.uint64) -> int:
    x = x - ((x >> np.uint64(1)) & np.uint64(0x5555555555555555))
    x = (x & np.uint64(0x3333333333333333)) + ((x >> np.uint64(2)) & np.uint64(0x3333333333333333))
    x = (x + (x >> np.uint64(4))) & np.uint64(0x0F0F0F0F0F0F0F0F)
    return int((x * np.uint64(0x0101010101010101)) >> np.uint64(56))


@njit(cache=True, inline="always")
def domain_size(dom: np.ndarray, v: int) -> int:
    c = 0
    for w in range(dom.shape[1]):
        c += popcount64(dom[v, w])
    return c


@njit(cache=True, inline="always")
def nth_label(dom: np.ndarray, v: int, j: int) -> int:
    """The ``j``-th (0-based) label in ``D(v)``, or -1."""
    for w in range(dom.shape[1]):
        x = dom[v, w]
        c = popcount64(x)
        if j < c:
            for _ in range(j):
                x &= x - np.uint64(1)
            return w * 64 + ctz64(x)
        j -= c
    return -1


@njit(cache=True, inline="always")
def wrow(wclass: np.ndarray, v: int) -> int:
    """The weight class of cell ``v`` (``wclass`` of length 1: class 0 for every cell)."""
    return wclass[v] if wclass.shape[0] > 1 else 0


@njit(cache=True, inline="always")
def entropy_of(
    dom: np.ndarray, v: int, weights: np.ndarray, wlogw: np.ndarray, weighted: bool
) -> float:
    """Shannon entropy of ``D(v)``: weighted by ``weights`` or uniform."""
    if not weighted:
        c = domain_size(dom, v)
        return np.log(c) if c > 0 else 0.0
    s = 0.0
    sl = 0.0
    cnt = 0
    for w in range(dom.shape[1]):
        x = dom[v, w]
        while x:
            a = w * 64 + ctz64(x)
            x &= x - np.uint64(1)
            s += weights[a]
            sl += wlogw[a]
            cnt += 1
    if s <= 0.0:
        return float(np.log(cnt)) if cnt > 0 else 0.0
    return float(np.log(s) - sl / s)


# ----------------------------------------------------------------------------- indexed heap


@njit(cache=True, inline="always")
def _heap_swap(heap: np.ndarray, pos: np.ndarray, i: int, j: int) -> None:
    a = heap[i]
    b = heap[j]
    heap[i] = b
    heap[j] = a
    pos[b] = i
    pos[a] = j


@njit(cache=True, inline="always")
def _heap_up(heap: np.ndarray, pos: np.ndarray, key: np.ndarray, i: int) -> None:
    while i > 0:
        p = (i - 1) >> 1
        if key[heap[i]] < key[heap[p]]:
            _heap_swap(heap, pos, i, p)
            i = p
        else:
            break


@njit(cache=True, inline="always")
def _heap_down(heap: np.ndarray, pos: np.ndarray, key: np.ndarray, i: int, size: int) -> None:
    while True:
        l = 2 * i + 1
        if l >= size:
            break
        m = l
        r = l + 1
        if r < size and key[heap[r]] < key[heap[l]]:
            m = r
        if key[heap[m]] < key[heap[i]]:
            _heap_swap(heap, pos, i, m)
            i = m
        else:
            break


@njit(cache=True, inline="always")
def heap_update(
    heap: np.ndarray, pos: np.ndarray, key: np.ndarray, size: int, v: int, k: float
) -> None:
    i = pos[v]
    if i < 0 or i >= size:
        return
    old = key[v]
    key[v] = k
    if k < old:
        _heap_up(heap, pos, key, i)
    else:
        _heap_down(heap, pos, key, i, size)


@njit(cache=True)
def heap_build(heap: np.ndarray, pos: np.ndarray, key: np.ndarray, size: int) -> None:
    for i in range(size):
        pos[heap[i]] = i
    for i in range(size // 2 - 1, -1, -1):
        _heap_down(heap, pos, key, i, size)


@njit(cache=True, inline="always")
def heap_pop(heap: np.ndarray, pos: np.ndarray, key: np.ndarray, size: int) -> int:
    v = heap[0]
    last = size - 1
    _heap_swap(heap, pos, 0, last)
    pos[v] = -1
    _heap_down(heap, pos, key, 0, last)
    return int(v)


# ----------------------------------------------------------------------------- propagation


@njit(cache=True)
def propagate(
    arcs: Arcs,
    ac: AcState,
    start: np.ndarray,
    nstart: int,
    hp: Heap,
    hsize: int,
    weighted: bool,
) -> int:
    """Arc consistency from the cells ``start[:nstart]``; returns the wiped-out cell or -1.

    ``ac.prev[u]`` is ``D(u)`` when ``u`` was last processed (all zero: unknown). When ``u``
    lost only a few of many labels since then, only the neighbour labels those supported
    are re-checked (``D(u) & sup[s ^ 1, c]``); otherwise ``D(v)`` is intersected with the
    union of the supports of ``D(u)``. ``ac.stats[0]`` counts queue pops (propagation steps),
    ``ac.stats[1]`` label removals. When ``hsize > 0`` the keys of changed cells in the
    min-entropy heap ``hp`` are updated (weighted entropy with ``weighted``). The queue is
    left empty on return (also after a wipe-out).
    """
    m = ac.dom.shape[0] if hsize > 0 else 0
    return _propagate(
        ac.dom, ac.prev, arcs.full, arcs.ptr, arcs.nbr, arcs.sidx, arcs.sup, arcs.supall,
        ac.queue, ac.inq, start, nstart, ac.stats, hp.heap, hp.pos, hp.key, hsize, hp.noise,
        arcs.weights, arcs.wlogw, arcs.wclass, weighted, hp.sw, hp.swl, arcs.nib,
        np.empty(m, dtype=np.int64), np.zeros(m, dtype=np.bool_),
        np.empty(ac.dom.shape[1], dtype=np.uint64), np.empty(ac.dom.shape[1], dtype=np.uint64),
        np.empty(arcs.nib.shape[2], dtype=np.uint64),
    )  # fmt: skip


@njit(cache=True, inline="always")
def _propagate(
    dom: np.ndarray,
    prev: np.ndarray,
    full: np.ndarray,
    ptr: np.ndarray,
    nbr: np.ndarray,
    sidx: np.ndarray,
    sup: np.ndarray,
    supall: np.ndarray,
    queue: np.ndarray,
    inq: np.ndarray,
    start: np.ndarray,
    nstart: int,
    stats: np.ndarray,
    heap: np.ndarray,
    hpos: np.ndarray,
    hkey: np.ndarray,
    hsize: int,
    noise: np.ndarray,
    weights: np.ndarray,
    wlogw: np.ndarray,
    wclass: np.ndarray,
    weighted: bool,
    sw: np.ndarray,
    swl: np.ndarray,
    nib: np.ndarray,
    dirty: np.ndarray,
    isdirty: np.ndarray,
    acc: np.ndarray,
    rem: np.ndarray,
    accs: np.ndarray,
) -> int:
    """:func:`propagate` with flat arguments (Alg. 3.1 calls it per step with its own arrays).

    ``prev[u]`` is ``D(u)`` when ``u`` was last processed (all zero: unknown). When ``u``
    lost only a few of many labels since then, only the neighbour labels those supported
    are re-checked (``D(u) & sup[s ^ 1, c]``; the union of their supports read from the
    table's single-label rows once per pop); otherwise ``D(v)`` is intersected with the
    union of the supports of ``D(u)``: with the slice table ``nib``
    (:func:`csplab.catalog.nibble_supports`, 4- or 8-label slices: its rows for the slices
    of ``D(u)``, every direction at once, once per pop), else label by label until the
    union covers ``D(v)``. ``stats[0]`` counts queue pops (propagation steps), ``stats[1]``
    label removals. When ``hsize > 0`` the min-entropy heap keys of the changed cells
    (listed in ``dirty``, flagged in ``isdirty``: arrays of ``n``) are updated once each
    when the queue is empty (a wiped-out run leaves them); their weight sums ``sw``, ``swl``
    lose each removed label's terms in label order. ``acc``, ``rem`` (``W``) and ``accs``
    (``nib.shape[2]``) are scratch buffers of the caller. The queue is left empty on return
    (also after a wipe-out). Inlined into its callers (:func:`alg31` calls it per step, and a call
    counted references to its 30 arrays and allocated its buffers: inlined with the
    caller's buffers, a 48x48 overlapping run took 5% less time).

    Domains of one or two words (up to 128 labels) run :func:`_propagate_w` with ``W``
    the constant 1 or 2, so its word loops unroll: the kernel of a
    48x48 overlapping run of the sample (K=69) took 0.89 of the time with ``W`` read from
    the array (A/B in one process, 600 runs each, the same outputs).
    """
    W = dom.shape[1]
    if W == 1:
        return _propagate_w1(
            dom, prev, full, ptr, nbr, sidx, sup, supall, queue, inq, start, nstart, stats,
            heap, hpos, hkey, hsize, noise, weights, wlogw, wclass, weighted, sw, swl, nib,
            dirty, isdirty, (acc, rem, accs),
        )  # fmt: skip
    # the buffers travel as one tuple: CPython compiles a call of more than 30 arguments
    # to f(*args), which numba cannot compile
    if W == 2:
        return _propagate_w2(
            dom, prev, full, ptr, nbr, sidx, sup, supall, queue, inq, start, nstart, stats,
            heap, hpos, hkey, hsize, noise, weights, wlogw, wclass, weighted, sw, swl, nib,
            dirty, isdirty, (acc, rem, accs),
        )  # fmt: skip
    return _propagate_wn(
        dom, prev, full, ptr, nbr, sidx, sup, supall, queue, inq, start, nstart, stats,
        heap, hpos, hkey, hsize, noise, weights, wlogw, wclass, weighted, sw, swl, nib,
        dirty, isdirty, (acc, rem, accs),
    )  # fmt: skip


# The loops of one word, two words and any number of words are compiled once each, called
# (not inlined) by every caller of _propagate: inlined, each caller compiled three copies
# of the loop and the first run after a change of this file took 2.4 times the CPU time
# to compile. Compiled without numba's reference counting (``_nrt=False``; they allocate
# nothing): a call then costs no atomic count per array argument.
@njit(cache=True, _nrt=False)
def _propagate_w1(
    dom: np.ndarray, prev: np.ndarray, full: np.ndarray, ptr: np.ndarray, nbr: np.ndarray,
    sidx: np.ndarray, sup: np.ndarray, supall: np.ndarray, queue: np.ndarray,
    inq: np.ndarray, start: np.ndarray, nstart: int, stats: np.ndarray, heap: np.ndarray,
    hpos: np.ndarray, hkey: np.ndarray, hsize: int, noise: np.ndarray, weights: np.ndarray,
    wlogw: np.ndarray, wclass: np.ndarray, weighted: bool, sw: np.ndarray, swl: np.ndarray,
    nib: np.ndarray, dirty: np.ndarray, isdirty: np.ndarray,
    bufs: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> int:  # fmt: skip
    """:func:`_propagate_w` for domains of one word."""
    return _propagate_w(
        dom, prev, full, ptr, nbr, sidx, sup, supall, queue, inq, start, nstart, stats,
        heap, hpos, hkey, hsize, noise, weights, wlogw, wclass, weighted, sw, swl, nib,
        dirty, isdirty, bufs, 1,
    )  # fmt: skip


@njit(cache=True, _nrt=False)
def _propagate_w2(
    dom: np.ndarray, prev: np.ndarray, full: np.ndarray, ptr: np.ndarray, nbr: np.ndarray,
    sidx: np.ndarray, sup: np.ndarray, supall: np.ndarray, queue: np.ndarray,
    inq: np.ndarray, start: np.ndarray, nstart: int, stats: np.ndarray, heap: np.ndarray,
    hpos: np.ndarray, hkey: np.ndarray, hsize: int, noise: np.ndarray, weights: np.ndarray,
    wlogw: np.ndarray, wclass: np.ndarray, weighted: bool, sw: np.ndarray, swl: np.ndarray,
    nib: np.ndarray, dirty: np.ndarray, isdirty: np.ndarray,
    bufs: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> int:  # fmt: skip
    """:func:`_propagate_w` for domains of two words."""
    return _propagate_w(
        dom, prev, full, ptr, nbr, sidx, sup, supall, queue, inq, start, nstart, stats,
        heap, hpos, hkey, hsize, noise, weights, wlogw, wclass, weighted, sw, swl, nib,
        dirty, isdirty, bufs, 2,
    )  # fmt: skip


@njit(cache=True, _nrt=False)
def _propagate_wn(
    dom: np.ndarray, prev: np.ndarray, full: np.ndarray, ptr: np.ndarray, nbr: np.ndarray,
    sidx: np.ndarray, sup: np.ndarray, supall: np.ndarray, queue: np.ndarray,
    inq: np.ndarray, start: np.ndarray, nstart: int, stats: np.ndarray, heap: np.ndarray,
    hpos: np.ndarray, hkey: np.ndarray, hsize: int, noise: np.ndarray, weights: np.ndarray,
    wlogw: np.ndarray, wclass: np.ndarray, weighted: bool, sw: np.ndarray, swl: np.ndarray,
    nib: np.ndarray, dirty: np.ndarray, isdirty: np.ndarray,
    bufs: tuple[np.ndarray, np.ndarray, np.ndarray],
) -> int:  # fmt: skip
    """:func:`_propagate_w` for domains of any number of words."""
    return _propagate_w(
        dom, prev, full, ptr, nbr, sidx, sup, supall, queue, inq, start, nstart, stats,
        heap, hpos, hkey, hsize, noise, weights, wlogw, wclass, weighted, sw, swl, nib,
        dirty, isdirty, bufs, dom.shape[1],
    )  # fmt: skip


@njit(cache=True, inline="always")
def _propagate_w(
    dom: np.ndarray,
    prev: np.ndarray,
    full: np.ndarray,
    ptr: np.ndarray,
    nbr: np.ndarray,
    sidx: np.ndarray,
    sup: np.ndarray,
    supall: np.ndarray,
    queue: np.ndarray,
    inq: np.ndarray,
    start: np.ndarray,
    nstart: int,
    stats: np.ndarray,
    heap: np.ndarray,
    hpos: np.ndarray,
    hkey: np.ndarray,
    hsize: int,
    noise: np.ndarray,
    weights: np.ndarray,
    wlogw: np.ndarray,
    wclass: np.ndarray,
    weighted: bool,
    sw: np.ndarray,
    swl: np.ndarray,
    nib: np.ndarray,
    dirty: np.ndarray,
    isdirty: np.ndarray,
    bufs: tuple[np.ndarray, np.ndarray, np.ndarray],
    W: int,
) -> int:
    """The loop of :func:`_propagate` for domains of ``W`` words (``W == dom.shape[1]``,
    passed by the caller so that a constant unrolls), its buffers ``(acc, rem, accs)``."""
    acc, rem, accs = bufs
    n = dom.shape[0]
    head = 0
    tail = 0
    count = 0
    for i in range(nstart):
        c = start[i]
        if not inq[c]:
            inq[c] = True
            queue[tail] = c
            tail += 1
            if tail == n:
                tail = 0
            count += 1
    J = nib.shape[0]  # slices of a domain in the table (0: no table)
    B = nib.shape[1]  # rows per slice: 16 (4-label slices) or 256 (8-label slices)
    lb = 4 if B == 16 else 8
    sh = 2 if B == 16 else 3
    SW = nib.shape[2]
    wiped = -1
    ndirty = 0
    while count > 0:
        u = queue[head]
        head += 1
        if head == n:
            head = 0
        count -= 1
        inq[u] = False
        stats[0] += 1
        isfull = True
        known = False
        some = False
        for w in range(W):
            if dom[u, w] != full[w]:
                isfull = False
            if prev[u, w]:
                known = True
            rem[w] = prev[u, w] & ~dom[u, w]
            if rem[w]:
                some = True
        if known and not some:
            continue  # nothing changed since u was last processed
        # the delta re-checks the labels the removed ones supported, the table ORs one row
        # per slice (K=69 with 8-label slices: Alg. 3.1 3% faster without the delta); the
        # labels are counted only where the delta can be chosen (0.97 of the time on the
        # sample: with a table of fewer than 16 slices, 16 * nr > J once u lost a label)
        use_delta = False
        if known and (J == 0 or J >= 16):
            nd = 0
            nr = 0
            for w in range(W):
                nd += popcount64(dom[u, w])
                nr += popcount64(rem[w])
            use_delta = nr < nd and (J == 0 or 16 * nr <= J)
        for w in range(W):
            prev[u, w] = dom[u, w]
        tabled = J > 0 and not use_delta and not isfull
        if use_delta and J > 0:
            # the supports of the removed labels in every direction: their rows of the table
            for q in range(SW):
                accs[q] = 0
            for w in range(W):
                x = rem[w]
                while x:
                    a = w * 64 + ctz64(x)
                    x &= x - np.uint64(1)
                    for q in range(SW):
                        accs[q] |= nib[a >> sh, 1 << (a & (lb - 1)), q]
        if tabled and SW <= 8:
            # the row in registers (unused ones stay 0): Alg. 3.1 3% faster on the sample's
            # overlapping model (SW = 8), 12% on castle 24x24x8 (SW = 6) than the loop below
            a0 = np.uint64(0)
            a1 = np.uint64(0)
            a2 = np.uint64(0)
            a3 = np.uint64(0)
            a4 = np.uint64(0)
            a5 = np.uint64(0)
            a6 = np.uint64(0)
            a7 = np.uint64(0)
            # the non-empty slices only (no slice straddles two words): one ctz each
            # instead of a test of every slice, 0.95 of the kernel's time on the sample
            for w in range(W):
                y = dom[u, w]
                while y:
                    t = ctz64(y) >> sh
                    j = w * (64 >> sh) + t
                    x = (y >> np.uint64(t * lb)) & np.uint64(B - 1)
                    y &= ~(np.uint64(B - 1) << np.uint64(t * lb))
                    a0 |= nib[j, x, 0]
                    if SW > 1:
                        a1 |= nib[j, x, 1]
                    if SW > 2:
                        a2 |= nib[j, x, 2]
                    if SW > 3:
                        a3 |= nib[j, x, 3]
                    if SW > 4:
                        a4 |= nib[j, x, 4]
                    if SW > 5:
                        a5 |= nib[j, x, 5]
                    if SW > 6:
                        a6 |= nib[j, x, 6]
                    if SW > 7:
                        a7 |= nib[j, x, 7]
            accs[0] = a0
            if SW > 1:
                accs[1] = a1
            if SW > 2:
                accs[2] = a2
            if SW > 3:
                accs[3] = a3
            if SW > 4:
                accs[4] = a4
            if SW > 5:
                accs[5] = a5
            if SW > 6:
                accs[6] = a6
            if SW > 7:
                accs[7] = a7
        elif tabled:
            for q in range(SW):
                accs[q] = 0
            for w in range(W):
                y = dom[u, w]
                while y:
                    t = ctz64(y) >> sh
                    j = w * (64 >> sh) + t
                    x = (y >> np.uint64(t * lb)) & np.uint64(B - 1)
                    y &= ~(np.uint64(B - 1) << np.uint64(t * lb))
                    for q in range(SW):
                        accs[q] |= nib[j, x, q]
        for e in range(ptr[u], ptr[u + 1]):
            v = nbr[e]
            s = sidx[e]
            if use_delta:
                # labels of v that some removed label of u supported
                if J > 0:
                    for w in range(W):
                        acc[w] = accs[s * W + w]
                else:
                    for w in range(W):
                        acc[w] = 0
                    for w in range(W):
                        x = rem[w]
                        while x:
                            a = w * 64 + ctz64(x)
                            x &= x - np.uint64(1)
                            for w2 in range(W):
                                acc[w2] |= sup[s, a, w2]
                # keep those that still have a support in D(u)
                for w in range(W):
                    x = dom[v, w] & acc[w]
                    keep = ~x
                    while x:
                        cbit = x & (~x + np.uint64(1))
                        c = w * 64 + ctz64(x)
                        x ^= cbit
                        for w2 in range(W):
                            if dom[u, w2] & sup[s ^ 1, c, w2]:
                                keep |= cbit
                                break
                    acc[w] = keep
            elif isfull:
                for w in range(W):
                    acc[w] = supall[s, w]
            elif tabled:
                for w in range(W):
                    acc[w] = accs[s * W + w]
            else:  # the full revision, a copy on purpose (see the module docstring)
                for w in range(W):
                    acc[w] = 0
                covered = False
                for w in range(W):
                    x = dom[u, w]
                    while x:
                        a = w * 64 + ctz64(x)
                        x &= x - np.uint64(1)
                        cov = True
                        for w2 in range(W):
                            acc[w2] |= sup[s, a, w2]
                            if dom[v, w2] & ~acc[w2]:
                                cov = False
                        if cov:
                            covered = True
                            break
                    if covered:
                        break
                if covered:
                    continue
            changed = False  # most revisions remove nothing: 0.93 of the time tested first
            for w in range(W):
                if dom[v, w] & ~acc[w]:
                    changed = True
            if not changed:
                continue
            empty = True
            inheap = hsize > 0 and hpos[v] >= 0 and hpos[v] < hsize
            memo = inheap and weighted and sw.shape[0] > 0
            for w in range(W):
                old = dom[v, w]
                new = old & acc[w]
                if new != old:
                    stats[1] += popcount64(old ^ new)
                    dom[v, w] = new
                    changed = True
                    if memo:
                        x = old & ~new
                        r = wrow(wclass, v)
                        s1 = sw[v]
                        s2 = swl[v]
                        while x:
                            a = w * 64 + ctz64(x)
                            x &= x - np.uint64(1)
                            s1 -= weights[r, a]
                            s2 -= wlogw[r, a]
                        sw[v] = s1
                        swl[v] = s2
                if new:
                    empty = False
            if changed:
                if empty:
                    wiped = v
                    break
                if inheap and not isdirty[v]:  # its key is updated when the queue is empty
                    isdirty[v] = True
                    dirty[ndirty] = v
                    ndirty += 1
                if not inq[v]:
                    inq[v] = True
                    queue[tail] = v
                    tail += 1
                    if tail == n:
                        tail = 0
                    count += 1
        if wiped >= 0:
            break
    for i in range(ndirty):
        v = dirty[i]
        isdirty[v] = False
        if wiped < 0:
            if weighted and sw.shape[0] > 0 and sw[v] > 1e-12:
                k = np.log(sw[v]) - swl[v] / sw[v] + 1e-6 * noise[v]
            else:
                r = wrow(wclass, v)
                k = entropy_of(dom, v, weights[r], wlogw[r], weighted) + 1e-6 * noise[v]
            heap_update(heap, hpos, hkey, hsize, v, k)
    # drain the queue flags; cells left in the queue are not at their fixpoint
    while count > 0:
        q = queue[head]
        inq[q] = False
        for w in range(W):
            prev[q, w] = 0
        head += 1
        if head == n:
            head = 0
        count -= 1
    return wiped


@njit(cache=True, inline="always")
def choose_label(dom: np.ndarray, v: int, u: float, weights: np.ndarray, weighted: bool) -> int:
    """Pick a label of ``D(v)`` with the uniform number ``u``: uniformly or by weight."""
    W = dom.shape[1]
    if weighted:
        tot = 0.0
        for w in range(W):
            x = dom[v, w]
            while x:
                a = w * 64 + ctz64(x)
                x &= x - np.uint64(1)
                tot += weights[a]
        if tot > 0.0:
            target = u * tot
            last = -1
            cum = 0.0
            for w in range(W):
                x = dom[v, w]
                while x:
                    a = w * 64 + ctz64(x)
                    x &= x - np.uint64(1)
                    if weights[a] > 0.0:
                        cum += weights[a]
                        last = a
                        if cum > target:
                            return a
            return last
    c = domain_size(dom, v)
    if c == 0:
        return -1
    j = int(u * c)
    if j >= c:
        j = c - 1
    return nth_label(dom, v, j)


@njit(cache=True)
def alg31(
    arcs: Arcs,
    ac: AcState,
    run: Run,
    hp: Heap,
    use_heap: bool,
    weighted: bool,
    key_weighted: bool,
    max_steps: int,
) -> int:
    """Run Alg. 3.1 from step ``run.state[0]`` for at most ``max_steps`` assignments.

    Labels are drawn by weight with ``weighted``; the heap's entropy keys are weighted with
    ``key_weighted`` (min-entropy) or plain domain-size logarithms (min-domain, MRV).

    ``state = [step, heap_size, fail_cell]``. Returns :attr:`Code.SOLVED` when every cell is
    assigned, :attr:`Code.FAILED` when a domain emptied (``state[2]`` is that cell),
    :attr:`Code.PAUSED` when ``max_steps`` were made. The cells come from ``run.order`` or,
    with ``use_heap``, from the entropy heap ``hp``. The catalog must already be arc
    consistent when the run starts.
    """
    n = ac.dom.shape[0]
    m = n if use_heap else 0
    bufs = (
        np.empty(1, dtype=np.int64), np.empty(m, dtype=np.int64), np.zeros(m, dtype=np.bool_),
        np.empty(ac.dom.shape[1], dtype=np.uint64), np.empty(ac.dom.shape[1], dtype=np.uint64),
        np.empty(arcs.nib.shape[2], dtype=np.uint64),
    )  # fmt: skip
    return _alg31_loop(arcs, ac, run, hp, use_heap, weighted, key_weighted, max_steps, bufs)


# Compiled without numba's reference counting (``_nrt=False``; it allocates nothing, its
# buffers come from :func:`alg31`): the arrays bound at each step's inlined call of
# :func:`_propagate` were counted up and down with atomic instructions, 8% of the time of a
# 48x48 overlapping run of the sample (A/B in one process, 400 runs each, the same outputs).
@njit(cache=True, _nrt=False)
def _alg31_loop(
    arcs: Arcs, ac: AcState, run: Run, hp: Heap, use_heap: bool, weighted: bool,
    key_weighted: bool, max_steps: int,
    bufs: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
) -> int:  # fmt: skip
    """The step loop of :func:`alg31` with its buffers ``bufs = (start, dirty, isdirty,
    acc, rem, accs)``."""
    # unpacked once: the per-step call of the arc-consistency loop takes flat arrays
    dom, prev, queue, inq, stats = ac.dom, ac.prev, ac.queue, ac.inq, ac.stats
    full, ptr, nbr, sidx = arcs.full, arcs.ptr, arcs.nbr, arcs.sidx
    sup, supall, weights, wlogw = arcs.sup, arcs.supall, arcs.weights, arcs.wlogw
    wclass, nib = arcs.wclass, arcs.nib
    order, ustream, grid, state = run.order, run.ustream, run.grid, run.state
    trace_cell, trace_label = run.trace_cell, run.trace_label
    heap, hpos, hkey, noise, sw, swl = hp.heap, hp.pos, hp.key, hp.noise, hp.sw, hp.swl
    n = dom.shape[0]
    start, dirty, isdirty, acc, rem, accs = bufs
    steps_here = 0
    while state[0] < n:
        if steps_here >= max_steps:
            return _PAUSED
        t = state[0]
        if use_heap:
            hsize = state[1]
            p = heap_pop(heap, hpos, hkey, hsize)
            state[1] = hsize - 1
        else:
            p = order[t]
        b = choose_label(dom, p, ustream[t], weights[wrow(wclass, p)], weighted)
        if b < 0:
            state[2] = p
            return _FAILED
        grid[p] = b
        trace_cell[t] = p
        trace_label[t] = b
        state[0] = t + 1
        steps_here += 1
        # statement 3.7: only b remains at p
        changed = False
        for w in range(dom.shape[1]):
            bit = np.uint64(1) << np.uint64(b - w * 64) if b // 64 == w else np.uint64(0)
            if dom[p, w] != bit:
                stats[1] += popcount64(dom[p, w] ^ bit)
                dom[p, w] = bit
                changed = True
        if changed:
            start[0] = p
            # start.shape[0] (1) rather than the literal 1: _propagate_w2 and _propagate_wn
            # then have the signature of their call by propagate, compiled once for both
            wiped = _propagate(
                dom, prev, full, ptr, nbr, sidx, sup, supall, queue, inq, start,
                start.shape[0], stats,
                heap, hpos, hkey, state[1] if use_heap else 0, noise, weights, wlogw,
                wclass, key_weighted, sw, swl, nib, dirty, isdirty, acc, rem, accs,
            )  # fmt: skip
            if wiped >= 0:
                state[2] = wiped
                return _FAILED
    return _SOLVED


@njit(cache=True)
def alg31_flat(
    full: np.ndarray, ptr: np.ndarray, nbr: np.ndarray, sidx: np.ndarray, sup: np.ndarray,
    supall: np.ndarray, weights: np.ndarray, wlogw: np.ndarray, wclass: np.ndarray,
    nib: np.ndarray, dom: np.ndarray, prev: np.ndarray, queue: np.ndarray, inq: np.ndarray,
    stats: np.ndarray, order: np.ndarray, ustream: np.ndarray, grid: np.ndarray,
    trace_cell: np.ndarray, trace_label: np.ndarray, state: np.ndarray, heap: np.ndarray,
    pos: np.ndarray, key: np.ndarray, noise: np.ndarray, sw: np.ndarray, swl: np.ndarray,
    use_heap: bool, weighted: bool, key_weighted: bool, max_steps: int,
) -> int:  # fmt: skip
    """:func:`alg31` with the fields of its bundles as arguments (``*arcs, *ac, *run, *hp``),
    for calls from Python: numba types a plain array argument in C but a bundle in Python
    (about 50 us each, 0.2 ms per call: 4% of a 48x48 overlapping output)."""
    return alg31(
        Arcs(full, ptr, nbr, sidx, sup, supall, weights, wlogw, wclass, nib),
        AcState(dom, prev, queue, inq, stats),
        Run(order, ustream, grid, trace_cell, trace_label, state),
        Heap(heap, pos, key, noise, sw, swl), use_heap, weighted, key_weighted, max_steps,
    )  # fmt: skip


# ----------------------------------------------------------------------------- MAC search


@njit(cache=True)
def _rand(state: np.ndarray) -> float:
    """splitmix64 uniform in [0, 1) from ``state[RNG]``."""
    z = np.uint64(state[RNG]) + np.uint64(0x9E3779B97F4A7C15)
    state[RNG] = np.int64(z)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z = z ^ (z >> np.uint64(31))
    return float(z >> np.uint64(11)) / 9007199254740992.0


@njit(cache=True)
def _save(dom: np.ndarray, v: int, stamp: np.ndarray, state: np.ndarray,
          tcell: np.ndarray, tbits: np.ndarray) -> None:  # fmt: skip
    if stamp[v] != state[EPOCH]:
        stamp[v] = state[EPOCH]
        t = state[TLEN]
        tcell[t] = v
        for w in range(dom.shape[1]):
            tbits[t, w] = dom[v, w]
        state[TLEN] = t + 1


@njit(cache=True)
def _undo(dom: np.ndarray, to: int, state: np.ndarray, tcell: np.ndarray,
          tbits: np.ndarray) -> None:  # fmt: skip
    t = state[TLEN]
    while t > to:
        t -= 1
        v = tcell[t]
        for w in range(dom.shape[1]):
            dom[v, w] = tbits[t, w]
    state[TLEN] = to


@njit(cache=True)
def _propagate_trail(
    dom: np.ndarray, full: np.ndarray, ptr: np.ndarray, nbr: np.ndarray, sidx: np.ndarray,
    sup: np.ndarray, supall: np.ndarray, queue: np.ndarray, inq: np.ndarray, start: int,
    stamp: np.ndarray, state: np.ndarray, tcell: np.ndarray, tbits: np.ndarray,
    counters: np.ndarray,
) -> int:  # fmt: skip
    """Arc consistency from cell ``start`` saving old domains on the trail; wiped cell or -1.

    The revision of :func:`_propagate` without its delta step (``prev`` is not kept);
    ``counters`` counts queue pops and label removals.
    """
    n = dom.shape[0]
    W = dom.shape[1]
    head = 0
    tail = 1
    count = 1
    queue[0] = start
    inq[start] = True
    acc = np.empty(W, dtype=np.uint64)
    wiped = -1
    while count > 0:
        u = queue[head]
        head += 1
        if head == n:
            head = 0
        count -= 1
        inq[u] = False
        counters[0] += 1
        isfull = True
        for w in range(W):
            if dom[u, w] != full[w]:
                isfull = False
                break
        for e in range(ptr[u], ptr[u + 1]):
            v = nbr[e]
            s = sidx[e]
            if isfull:
                for w in range(W):
                    acc[w] = supall[s, w]
            else:  # the full revision, a copy on purpose (see the module docstring)
                for w in range(W):
                    acc[w] = 0
                covered = False
                for w in range(W):
                    x = dom[u, w]
                    while x:
                        a = w * 64 + ctz64(x)
                        x &= x - np.uint64(1)
                        cov = True
                        for w2 in range(W):
                            acc[w2] |= sup[s, a, w2]
                            if dom[v, w2] & ~acc[w2]:
                                cov = False
                        if cov:
                            covered = True
                            break
                    if covered:
                        break
                if covered:
                    continue
            changed = False
            for w in range(W):
                if dom[v, w] & ~acc[w]:
                    changed = True
                    break
            if not changed:
                continue
            _save(dom, v, stamp, state, tcell, tbits)
            empty = True
            for w in range(W):
                old = dom[v, w]
                new = old & acc[w]
                counters[1] += popcount64(old ^ new)
                dom[v, w] = new
                if new:
                    empty = False
            if empty:
                wiped = v
                break
            if not inq[v]:
                inq[v] = True
                queue[tail] = v
                tail += 1
                if tail == n:
                    tail = 0
                count += 1
        if wiped >= 0:
            break
    while count > 0:
        inq[queue[head]] = False
        head += 1
        if head == n:
            head = 0
        count -= 1
    return wiped


@njit(cache=True)
def _pick_label(cand: np.ndarray, weights: np.ndarray, weighted: bool, u: float) -> int:
    W = cand.shape[0]
    if weighted:
        tot = 0.0
        for w in range(W):
            x = cand[w]
            while x:
                a = w * 64 + ctz64(x)
                x &= x - np.uint64(1)
                tot += weights[a]
        if tot > 0.0:
            target = u * tot
            cum = 0.0
            last = -1
            for w in range(W):
                x = cand[w]
                while x:
                    a = w * 64 + ctz64(x)
                    x &= x - np.uint64(1)
                    if weights[a] > 0.0:
                        cum += weights[a]
                        last = a
                        if cum > target:
                            return a
            if last >= 0:
                return last
    c = 0
    for w in range(W):
        c += popcount64(cand[w])
    j = int(u * c)
    if j >= c:
        j = c - 1
    for w in range(W):
        x = cand[w]
        k = popcount64(x)
        if j < k:
            for _ in range(j):
                x &= x - np.uint64(1)
            return w * 64 + ctz64(x)
        j -= k
    return -1


@njit(cache=True)
def _choose_cell(dom: np.ndarray, scan: bool, order: np.ndarray, state: np.ndarray) -> int:
    n = dom.shape[0]
    if scan:
        p = state[SCAN]
        while p < n:
            v = order[p]
            if domain_size(dom, v) > 1:
                state[SCAN] = p
                return int(v)
            p += 1
        state[SCAN] = n
        return -1
    best = -1
    bsize = 1 << 30
    ties = 0
    for v in range(n):
        s = domain_size(dom, v)
        if s <= 1:
            continue
        if s < bsize:
            bsize = s
            best = v
            ties = 1
        elif s == bsize:
            ties += 1
            if _rand(state) * ties < 1.0:
                best = v
    return best


@njit(cache=True)
def mac_search(
    arcs: Arcs, ac: AcState, se: Search, scan: bool, weighted: bool, max_nodes: int,
    restart_fails: int,
) -> int:  # fmt: skip
    """Run (or resume) a MAC search on the domains ``ac.dom`` (see :class:`Search`).

    Each decision assigns a label (uniform, or by weight) to a cell (the first unassigned one
    of ``se.order`` with ``scan``, else one of fewest labels) and runs
    :func:`_propagate_trail`; a wipe-out tries the cell's next label; a cell without labels
    left backtracks chronologically. Returns :attr:`Code.SOLVED` (``ac.dom`` holds one label
    per cell), :attr:`Code.EXHAUSTED` (no solution; the domains are back at the root),
    :attr:`Code.RESTART` after ``restart_fails`` failures in this run (0: never; call
    :func:`mac_restart`), :attr:`Code.PAUSED` after ``max_nodes`` decisions in this call,
    :attr:`Code.GROW` when the trail is nearly full (resume with ``se.grown()``).
    """
    return _mac_search(
        ac.dom, arcs.full, arcs.ptr, arcs.nbr, arcs.sidx, arcs.sup, arcs.supall, ac.queue,
        ac.inq, se.stamp, se.state, se.tcell, se.tbits, se.lv_cell, se.lv_cand, se.lv_trail,
        se.lv_scan, scan, se.order, arcs.weights, arcs.wclass, weighted, max_nodes,
        restart_fails,
        se.counters,
    )  # fmt: skip


@njit(cache=True)
def _mac_search(
    dom: np.ndarray, full: np.ndarray, ptr: np.ndarray, nbr: np.ndarray, sidx: np.ndarray,
    sup: np.ndarray, supall: np.ndarray, queue: np.ndarray, inq: np.ndarray,
    stamp: np.ndarray, state: np.ndarray, tcell: np.ndarray, tbits: np.ndarray,
    lv_cell: np.ndarray, lv_cand: np.ndarray, lv_trail: np.ndarray, lv_scan: np.ndarray,
    scan: bool, order: np.ndarray, weights: np.ndarray, wclass: np.ndarray, weighted: bool,
    max_nodes: int, restart_fails: int, counters: np.ndarray,
) -> int:  # fmt: skip
    """:func:`mac_search` with flat arguments."""
    n, W = dom.shape
    nodes_here = 0
    while True:
        L = state[LEVEL]
        if state[NEED] == 1:
            if nodes_here >= max_nodes:
                return _PAUSED
            if tcell.shape[0] - state[TLEN] < n + 1:
                return _GROW
            v = _choose_cell(dom, scan, order, state)
            if v < 0:
                return _SOLVED
            L += 1
            state[LEVEL] = L
            lv_cell[L] = v
            lv_trail[L] = state[TLEN]
            lv_scan[L] = state[SCAN]
            for w in range(W):
                lv_cand[L, w] = dom[v, w]
            state[NEED] = 0
            nodes_here += 1
            state[NODES] += 1
        # try the next untried label at level L
        _undo(dom, lv_trail[L], state, tcell, tbits)
        state[SCAN] = lv_scan[L]
        empty = True
        for w in range(W):
            if lv_cand[L, w]:
                empty = False
                break
        if empty:
            # every label failed: backtrack to the parent decision
            state[LEVEL] = L - 1
            if L - 1 == 0:
                _undo(dom, lv_trail[L], state, tcell, tbits)
                return _EXHAUSTED
            continue
        if tcell.shape[0] - state[TLEN] < n + 1:
            return _GROW
        v = lv_cell[L]
        b = _pick_label(lv_cand[L], weights[wrow(wclass, v)], weighted, _rand(state))
        wb = b // 64
        bit = np.uint64(1) << np.uint64(b - wb * 64)
        lv_cand[L, wb] &= ~bit
        state[EPOCH] += 1
        _save(dom, v, stamp, state, tcell, tbits)
        for w in range(W):
            dom[v, w] = bit if w == wb else np.uint64(0)
        wiped = _propagate_trail(dom, full, ptr, nbr, sidx, sup, supall, queue, inq, v, stamp,
                                 state, tcell, tbits, counters)  # fmt: skip
        if wiped >= 0:
            state[FAILS] += 1
            state[FAILS_RUN] += 1
            if restart_fails > 0 and state[FAILS_RUN] >= restart_fails:
                return _RESTART
            continue
        state[NEED] = 1


@njit(cache=True)
def mac_restart(ac: AcState, se: Search) -> None:
    """Undo every decision of ``se`` (the domains go back to the root) for a new run."""
    state = se.state
    _undo(ac.dom, se.lv_trail[1], state, se.tcell, se.tbits)
    state[LEVEL] = 0
    state[NEED] = 1
    state[SCAN] = 0
    state[FAILS_RUN] = 0


# ----------------------------------------------------------------------------- CNF encoders


@njit(cache=True)
def support_clauses(
    bits: np.ndarray,
    arcs: Arcs,
    isconst: np.ndarray,
    vid: np.ndarray,
    forward_only: bool,
    fill: bool,
    lits: np.ndarray,
    starts: np.ndarray,
) -> tuple[int, int]:
    """Support clauses of every non-constant cell; returns ``(clauses, literals)``.

    With ``fill=False`` only counts (``lits``/``starts`` are not touched). Used by
    :func:`csplab.cnf.encode`.
    """
    ptr, nbr, sidx, sup = arcs.ptr, arcs.nbr, arcs.sidx, arcs.sup
    n, W = bits.shape
    nl = 0
    nc = 0
    for v in range(n):
        if isconst[v]:
            continue
        for e in range(ptr[v], ptr[v + 1]):
            s = sidx[e]
            if forward_only and (s & 1) == 1:
                continue
            u = nbr[e]
            for w in range(W):
                x = bits[v, w]
                while x:
                    b = w * 64 + ctz64(x)
                    x &= x - np.uint64(1)
                    covered = True
                    for w2 in range(W):
                        if bits[u, w2] & ~sup[s, b, w2]:
                            covered = False
                            break
                    if covered:
                        continue
                    if fill:
                        starts[nc] = nl
                        lits[nl] = -vid[v, b]
                    nl += 1
                    for w2 in range(W):
                        y = bits[u, w2] & sup[s, b, w2]
                        while y:
                            c = w2 * 64 + ctz64(y)
                            y &= y - np.uint64(1)
                            if fill:
                                lits[nl] = vid[u, c]
                            nl += 1
                    nc += 1
    if fill:
        starts[nc] = nl
    return nc, nl


@njit(cache=True)
def direct_clauses(
    bits: np.ndarray,
    arcs: Arcs,
    isconst: np.ndarray,
    vid: np.ndarray,
    fill: bool,
    lits: np.ndarray,
) -> int:
    """Binary conflict clauses (each arc once, from its source); returns the count.

    A constant cell (arc consistent, so compatible with all of its neighbours' labels) needs
    none. Used by :func:`csplab.cnf.encode`.
    """
    ptr, nbr, sidx, sup = arcs.ptr, arcs.nbr, arcs.sidx, arcs.sup
    n, W = bits.shape
    nc = 0
    for v in range(n):
        if isconst[v]:
            continue
        for e in range(ptr[v], ptr[v + 1]):
            s = sidx[e]
            if (s & 1) == 1:
                continue
            u = nbr[e]
            for w in range(W):
                x = bits[v, w]
                while x:
                    b = w * 64 + ctz64(x)
                    x &= x - np.uint64(1)
                    if isconst[u]:
                        continue
                    for w2 in range(W):
                        y = bits[u, w2] & ~sup[s, b, w2]
                        while y:
                            c = w2 * 64 + ctz64(y)
                            y &= y - np.uint64(1)
                            if fill:
                                lits[2 * nc] = -vid[v, b]
                                lits[2 * nc + 1] = -vid[u, c]
                            nc += 1
    return nc


# ----------------------------------------------------------------------------- global constraints


@njit(cache=True)
def mac_restrict(arcs: Arcs, ac: AcState, se: Search, cells: np.ndarray, masks: np.ndarray) -> int:
    """Intersect the domains of ``cells`` with ``masks`` (packed, ``(len(cells), W)``) inside a
    MAC search, saving the old domains on the trail, and propagate; the wiped cell or -1.

    What a global-constraint propagator (:mod:`csplab.constraints`) removes between two
    decisions: undone with the current decision when it is rejected (state slot ``NEED``
    set to 0) or backtracked.
    """
    dom = ac.dom
    W = dom.shape[1]
    state = se.state
    changed = np.zeros(cells.shape[0], dtype=np.bool_)
    for i in range(cells.shape[0]):
        v = cells[i]
        diff = False
        for w in range(W):
            if dom[v, w] & ~masks[i, w]:
                diff = True
                break
        if not diff:
            continue
        _save(dom, v, se.stamp, state, se.tcell, se.tbits)
        empty = True
        for w in range(W):
            dom[v, w] &= masks[i, w]
            if dom[v, w]:
                empty = False
        if empty:
            return int(v)
        changed[i] = True
    for i in range(cells.shape[0]):
        if changed[i]:
            wiped = _propagate_trail(
                dom, arcs.full, arcs.ptr, arcs.nbr, arcs.sidx, arcs.sup, arcs.supall,
                ac.queue, ac.inq, cells[i], se.stamp, state, se.tcell, se.tbits, se.counters,
            )  # fmt: skip
            if wiped >= 0:
                return wiped
    return -1


@njit(cache=True)
def components(n: int, eu: np.ndarray, ev: np.ndarray, active: np.ndarray) -> np.ndarray:
    """Connected components of the ``active`` vertices over edges ``(eu[i], ev[i])`` (union
    find); component ids are the smallest vertex of each component, -1 for inactive ones."""
    parent = np.arange(n)
    for i in range(eu.shape[0]):
        a = eu[i]
        b = ev[i]
        if not (active[a] and active[b]):
            continue
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        while parent[b] != b:
            parent[b] = parent[parent[b]]
            b = parent[b]
        if a != b:
            if a < b:
                parent[b] = a
            else:
                parent[a] = b
    out = np.full(n, -1, dtype=np.int64)
    for v in range(n):
        if active[v]:
            r = v
            while parent[r] != r:
                r = parent[r]
            out[v] = r
    return out


@njit(cache=True)
def _cut_search(
    ptr: np.ndarray, nbr: np.ndarray, can: np.ndarray, must: np.ndarray, root: int
) -> tuple[np.ndarray, np.ndarray]:
    """Tarjan's low points over an iterative depth-first search from the must vertex
    ``root`` through the vertices ``can`` allows (the graph ``ptr``/``nbr``, CSR): the
    discovery times (-1: not reached) and the vertices whose removal cuts a must vertex off
    the root (a vertex ``u`` other than the root with a child ``c``, ``low[c] >= disc[u]``,
    whose subtree holds a must vertex)."""
    n = ptr.shape[0] - 1
    disc = np.full(n, -1, dtype=np.int64)
    low = np.zeros(n, dtype=np.int64)
    below = np.zeros(n, dtype=np.int64)  # must vertices in the DFS subtree
    parent = np.full(n, -1, dtype=np.int64)
    it = np.zeros(n, dtype=np.int64)
    stack = np.empty(n, dtype=np.int64)
    sep = np.zeros(n, dtype=np.bool_)
    stack[0] = root
    sp = 1
    disc[root] = 0
    it[root] = ptr[root]
    below[root] = 1
    t = 1
    while sp > 0:
        u = stack[sp - 1]
        if it[u] < ptr[u + 1]:
            w = nbr[it[u]]
            it[u] += 1
            if not can[w]:
                continue
            if disc[w] < 0:
                disc[w] = t
                low[w] = t
                t += 1
                parent[w] = u
                it[w] = ptr[w]
                below[w] = 1 if must[w] else 0
                stack[sp] = w
                sp += 1
            elif w != parent[u] and disc[w] < low[u]:
                low[u] = disc[w]
        else:
            sp -= 1
            p = parent[u]
            if p >= 0:
                if low[u] < low[p]:
                    low[p] = low[u]
                below[p] += below[u]
                if p != root and low[u] >= disc[p] and below[u] > 0:
                    sep[p] = True
    return disc, sep


@njit(cache=True)
def separating_cells(ptr: np.ndarray, nbr: np.ndarray, must: np.ndarray, root: int) -> np.ndarray:
    """The vertices whose removal separates two ``must`` vertices (the graph ``ptr``/``nbr``,
    CSR, holds only the vertices that may take part; ``root`` is a must vertex), by
    :func:`_cut_search`: ``out[:, 0]`` is "separating", ``out[:, 1]`` is "reached" from the
    root.
    """
    n = ptr.shape[0] - 1
    disc, sep = _cut_search(ptr, nbr, np.ones(n, dtype=np.bool_), must, root)
    out = np.zeros((n, 2), dtype=np.bool_)
    for v in range(n):
        out[v, 0] = sep[v]
        out[v, 1] = disc[v] >= 0
    return out


@njit(cache=True)
def set_status(bits: np.ndarray, sp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per cell of the packed catalog ``bits``: may it take a label of the set ``sp``
    (packed ``(W,)``), and must it (every label left is in the set)? Read from the bitsets,
    without unpacking them."""
    n, W = bits.shape
    can = np.zeros(n, dtype=np.bool_)
    must = np.zeros(n, dtype=np.bool_)
    for v in range(n):
        c = False
        o = False
        for w in range(W):
            x = bits[v, w]
            if x & sp[w]:
                c = True
            if x & ~sp[w]:
                o = True
        can[v] = c
        must[v] = c and not o
    return can, must


@njit(cache=True)
def connected_prune(
    ptr: np.ndarray, nbr: np.ndarray, can: np.ndarray, must: np.ndarray
) -> tuple[bool, np.ndarray, np.ndarray]:
    """The connectivity propagator on the set's cells (:class:`csplab.constraints.Connected`):
    ``can``/``must`` say which cells may / must be in the set, ``ptr``/``nbr`` (CSR) the
    grid's neighbours. A search from the first must cell through may-cells reaches the
    region every member has to lie in: ``(False, ...)`` when a must cell is outside it;
    else ``(True, out, force)`` with ``out`` the may-cells outside it (they leave the
    set) and ``force`` the may-not-must cells that separate two must cells (Tarjan's low
    points, :func:`separating_cells`), which join it."""
    n = can.shape[0]
    out = np.zeros(n, dtype=np.bool_)
    root = -1
    for v in range(n):
        if must[v]:
            root = v
            break
    if root < 0:
        return True, out, np.zeros(n, dtype=np.bool_)
    # the region reachable through may-cells, and its cut cells (Tarjan's low points)
    disc, force = _cut_search(ptr, nbr, can, must, root)
    for v in range(n):
        if can[v] and disc[v] < 0:
            if must[v]:
                return False, out, force
            out[v] = True
        elif must[v]:
            force[v] = False
    return True, out, force


@njit(cache=True)
def connected_unchanged(
    ptr: np.ndarray,
    nbr: np.ndarray,
    xyz: np.ndarray,
    can: np.ndarray,
    must: np.ndarray,
    pcan: np.ndarray,
    pmust: np.ndarray,
) -> bool:
    """Whether :func:`connected_prune` on ``can``/``must`` can prune nothing more than it
    did on ``pcan``/``pmust`` (the state it last ran on, its prunings applied), judged
    from the cells that changed only, for a catalog that only shrinks.

    ``True`` when no cell joined ``can``; every cell that left it had its may-neighbours
    joined around it through may-cells of its box (the cells within one step along every
    axis, diagonals included; ``xyz`` holds the cells' coordinates), so no path between
    two cells was cut; and every new must cell is joined to an old one through must cells
    (a vertex separating it from a must cell, not being a must cell, would separate that
    old one too). A cut
    path that is only rerouted can still create separating cells on the detour: the
    caller runs the full propagator again after a bounded number of such steps.
    """
    n = can.shape[0]
    had = False
    for v in range(n):
        if pmust[v]:
            had = True
            break
    seen = np.zeros(n, dtype=np.bool_)
    queue = np.empty(n, dtype=np.int64)
    fresh = 0  # new must cells
    head = tail = 0  # those joined to an old must cell through must cells, to visit
    for v in range(n):
        if can[v] and not pcan[v]:
            return False
        if must[v] and not pmust[v]:
            if not had:
                return False
            fresh += 1
            for e in range(ptr[v], ptr[v + 1]):
                if pmust[nbr[e]]:
                    seen[v] = True
                    queue[tail] = v
                    tail += 1
                    break
    while head < tail:  # new must cells next to joined ones are joined too
        v = queue[head]
        head += 1
        for e in range(ptr[v], ptr[v + 1]):
            w = nbr[e]
            if must[w] and not pmust[w] and not seen[w]:
                seen[w] = True
                queue[tail] = w
                tail += 1
    if tail < fresh:
        return False
    for i in range(tail):
        seen[queue[i]] = False
    for x in range(n):
        if pcan[x] and not can[x] and not _bypassed(ptr, nbr, xyz, can, x, seen, queue):
            return False
    return True


@njit(cache=True)
def _bypassed(
    ptr: np.ndarray,
    nbr: np.ndarray,
    xyz: np.ndarray,
    can: np.ndarray,
    x: int,
    seen: np.ndarray,
    queue: np.ndarray,
) -> bool:
    """Whether the ``can`` neighbours of cell ``x`` are joined through ``can`` cells of
    x's box (one step along every axis, diagonals included; ``xyz``: the coordinates).
    ``seen`` (all ``False``) and ``queue`` are work arrays of length ``n``."""
    start = -1
    for e in range(ptr[x], ptr[x + 1]):
        if can[nbr[e]]:
            start = nbr[e]
            break
    if start < 0:
        return True
    qh = 0
    qt = 1
    queue[0] = start
    seen[start] = True
    while qh < qt:
        u = queue[qh]
        qh += 1
        for e in range(ptr[u], ptr[u + 1]):
            w = nbr[e]
            if not can[w] or seen[w] or w == x:
                continue
            near = True
            for a in range(xyz.shape[1]):
                d = xyz[w, a] - xyz[x, a]
                if d > 1 or d < -1:
                    near = False
            if near:
                seen[w] = True
                queue[qt] = w
                qt += 1
    ok = True
    for e in range(ptr[x], ptr[x + 1]):
        if can[nbr[e]] and not seen[nbr[e]]:
            ok = False
    for i in range(qt):
        seen[queue[i]] = False
    return ok


@njit(cache=True)
def all_bypassed(
    ptr: np.ndarray, nbr: np.ndarray, xyz: np.ndarray, can: np.ndarray, cells: np.ndarray
) -> bool:
    """Whether removing ``cells`` (not in ``can``) from the graph of ``can`` cells cut no
    path between two of them: each one's ``can`` neighbours are joined around it inside
    its box (:func:`_bypassed`)."""
    n = can.shape[0]
    seen = np.zeros(n, dtype=np.bool_)
    queue = np.empty(n, dtype=np.int64)
    for i in range(cells.shape[0]):
        if not _bypassed(ptr, nbr, xyz, can, cells[i], seen, queue):
            return False
    return True


# ----------------------------------------------------------------------------- modify in blocks


@njit(cache=True)
def _find(cells: np.ndarray, nb: int, u: int) -> int:
    """The index of ``u`` in the sorted ``cells[:nb]``, else -1 (a bisection: numba's
    ``np.searchsorted`` on a scalar costs ten times more per call)."""
    lo = 0
    hi = nb
    while lo < hi:
        mid = (lo + hi) >> 1
        if cells[mid] < u:
            lo = mid + 1
        else:
            hi = mid
    return lo if lo < nb and cells[lo] == u else -1


@njit(cache=True)
def block_catalog(
    arcs: Arcs,
    doms: np.ndarray,
    grid: np.ndarray,
    cells: np.ndarray,
    dom0: np.ndarray,
    lptr: np.ndarray,
    lnbr: np.ndarray,
    lsidx: np.ndarray,
    table: np.ndarray,
) -> int:
    """The catalog of one block of Alg. 3.4 before propagation, and its internal arcs.

    ``cells`` (sorted) is the block; every other cell keeps its label in ``grid``. Fills
    ``dom0`` (``(nb, W)``: ``doms``, the problem's packed domains, cut by the supports of
    the fixed labels around the block, as :meth:`csplab.problem.Problem.subproblem` cuts
    them) and the block's arcs as CSR rows in local cell numbers (``lptr``, ``nb + 1``;
    ``lnbr``/``lsidx``, as long as the block's arc ends in the problem), in the order of the
    problem's arcs, as in the subproblem. Returns the number of internal arc ends.

    ``table`` (``int64``, the problem's cells, all -1) looks the block's cells up (it is
    left all -1); an empty one: a table of the problem's cells is made when the block is
    most of the problem (a world's template), else ``cells`` is bisected per arc (ten
    times slower per block of 1000 cells than a table).
    """
    ptr, nbr, sidx, sup = arcs.ptr, arcs.nbr, arcs.sidx, arcs.sup
    W = doms.shape[1]
    nb = cells.shape[0]
    n = grid.shape[0]
    given = table.shape[0] == n
    dense = given or n <= 4 * nb
    pos = table if given else np.full(n if dense else 0, -1, dtype=np.int64)
    if dense:
        for i in range(nb):
            pos[cells[i]] = i
    k = 0
    for i in range(nb):
        v = cells[i]
        lptr[i] = k
        for w in range(W):
            dom0[i, w] = doms[v, w]
        for e in range(ptr[v], ptr[v + 1]):
            u = nbr[e]
            j = pos[u] if dense else _find(cells, nb, u)
            if j >= 0:
                lnbr[k] = j
                lsidx[k] = sidx[e]
                k += 1
            else:
                a = grid[u]
                if a >= 0:  # labels of v that the fixed label a of u supports
                    s1 = sidx[e] ^ 1
                    for w in range(W):
                        dom0[i, w] &= sup[s1, a, w]
    lptr[nb] = k
    if given:
        for i in range(nb):
            pos[cells[i]] = -1
    return k


@njit(cache=True)
def block_alg31(
    local: Arcs,
    dom0: np.ndarray,
    scan: np.ndarray,
    retries: int,
    use_heap: bool,
    weighted: bool,
    key_weighted: bool,
    rng: Any,  # a numpy.random.Generator
    lgrid: np.ndarray,
    counters: np.ndarray,
) -> bool:
    """Alg. 3.1 on one block (catalog ``dom0``, arcs ``local``), retried up to ``retries``
    times: the inner loop of Alg. 3.4, as :func:`csplab.engine.alg31.run_alg31` runs it on
    the block's subproblem, with the same draws from ``rng`` (per attempt one uniform per
    cell, then, for ``use_heap``, one tie-breaking number per cell), the same queue and the
    same result. On success ``lgrid`` holds the labels and ``True`` is returned.
    ``counters[2] += retries``, ``counters[3] += queue pops``. The block's arc-consistent
    catalog, which no draw enters, is computed once and restored for each retry (its pops
    counted per attempt, as a fresh propagation would).
    """
    nb = dom0.shape[0]
    W = dom0.shape[1]
    full, sup, supall, weights, wlogw, wclass = (
        local.full,
        local.sup,
        local.supall,
        local.weights,
        local.wlogw,
        local.wclass,
    )
    zi = np.zeros(0, dtype=np.int64)
    zf = np.zeros(0, dtype=np.float64)
    dom = np.empty((nb, W), dtype=np.uint64)
    prev = np.zeros((nb, W), dtype=np.uint64)
    queue = np.zeros(nb, dtype=np.int64)
    inq = np.zeros(nb, dtype=np.bool_)
    stats = np.zeros(2, dtype=np.int64)
    start = np.arange(nb, dtype=np.int64)
    tcell = np.empty(nb, dtype=np.int64)
    tlab = np.empty(nb, dtype=np.int64)
    # the block's arc-consistent catalog is the same for every attempt (no draw enters it):
    # computed once, restored per attempt with its pops counted each time
    ok = True
    for i in range(nb):
        some = False
        for w in range(W):
            dom[i, w] = dom0[i, w]
            prev[i, w] = 0
            if dom0[i, w]:
                some = True
        if not some:
            ok = False
    stats[0] = 0
    stats[1] = 0
    wiped = 0
    if ok:
        wiped = _propagate(
            dom, prev, full, local.ptr, local.nbr, local.sidx, sup, supall, queue, inq,
            start, nb, stats, zi, zi, zf, 0, zf, weights, wlogw, wclass, False, zf, zf,
            local.nib, zi, np.zeros(0, dtype=np.bool_), np.empty(W, dtype=np.uint64),
            np.empty(W, dtype=np.uint64), np.empty(local.nib.shape[2], dtype=np.uint64),
        )  # fmt: skip
    dom_ac = dom.copy()
    prev_ac = prev.copy()
    pops0 = stats[0]
    removed0 = stats[1]
    for attempt in range(retries + 1):
        us = rng.random(nb)
        noise = rng.random(nb) if use_heap else zf
        stats[0] = pops0
        stats[1] = removed0
        code = _FAILED
        if ok:
            if attempt > 0:
                for i in range(nb):
                    for w in range(W):
                        dom[i, w] = dom_ac[i, w]
                        prev[i, w] = prev_ac[i, w]
            if wiped < 0:
                if use_heap:
                    hheap = np.arange(nb, dtype=np.int64)
                    hpos = np.zeros(nb, dtype=np.int64)
                    hkey = np.empty(nb, dtype=np.float64)
                    sw = np.empty(nb if key_weighted else 0, dtype=np.float64)
                    swl = np.empty(nb if key_weighted else 0, dtype=np.float64)
                    for i in range(nb):
                        r = wrow(wclass, i)
                        if key_weighted:  # the sums the propagation keeps up to date
                            s = 0.0
                            sl = 0.0
                            for w in range(W):
                                x = dom[i, w]
                                while x:
                                    a = w * 64 + ctz64(x)
                                    x &= x - np.uint64(1)
                                    s += weights[r, a]
                                    sl += wlogw[r, a]
                            sw[i] = s
                            swl[i] = sl
                        ent = entropy_of(dom, i, weights[r], wlogw[r], key_weighted)
                        hkey[i] = ent + 1e-6 * noise[i]
                    heap_build(hheap, hpos, hkey, nb)
                    hp = Heap(hheap, hpos, hkey, noise, sw, swl)
                else:
                    hp = Heap(zi, zi, zf, zf, zf, zf)
                for i in range(nb):
                    lgrid[i] = -1
                state = np.zeros(3, dtype=np.int64)
                state[1] = nb if use_heap else 0
                state[2] = -1
                run = Run(scan, us, lgrid, tcell, tlab, state)
                ac = AcState(dom, prev, queue, inq, stats)
                code = alg31(local, ac, run, hp, use_heap, weighted, key_weighted, nb + 1)
        counters[3] += stats[0]
        if code == _SOLVED:
            return True
        if attempt < retries:
            counters[2] += 1
    return False


@njit(cache=True)
def blocks_sweep(
    arcs: Arcs,
    doms: np.ndarray,
    grid: np.ndarray,
    bptr: np.ndarray,
    bcells: np.ndarray,
    first: int,
    last: int,
    scan: np.ndarray,
    retries: int,
    use_heap: bool,
    weighted: bool,
    key_weighted: bool,
    rng: Any,  # a numpy.random.Generator
    counters: np.ndarray,
) -> None:
    """Alg. 3.4's sweep over blocks ``first .. last - 1`` (thesis Sec. 3.3.6), in place.

    Block ``b`` is the sorted cells ``bcells[bptr[b]:bptr[b + 1]]``; every other cell keeps
    its label in ``grid`` (``int32 (n,)``, a consistent model). Per block, in arrays of the
    block's size only: :func:`block_catalog` (what :meth:`csplab.problem.Problem.subproblem`
    builds) and :func:`block_alg31` (what :func:`csplab.engine.alg31.run_alg31` does, with
    its draws from ``rng``); a solved block is written into ``grid``, a failed one is left
    as it was. ``counters += [blocks tried, accepted, retries, queue pops]``.
    """
    W = doms.shape[1]
    table = np.full(grid.shape[0], -1, dtype=np.int64)  # the block's cells, looked up
    for b in range(first, last):
        lo = bptr[b]
        nb = bptr[b + 1] - lo
        if nb == 0:
            continue
        counters[0] += 1
        cells = bcells[lo : lo + nb]
        deg = 0
        for i in range(nb):
            deg += arcs.ptr[cells[i] + 1] - arcs.ptr[cells[i]]
        dom0 = np.empty((nb, W), dtype=np.uint64)
        lptr = np.zeros(nb + 1, dtype=np.int64)
        lnbr = np.empty(max(deg, 1), dtype=np.int64)
        lsidx = np.empty(max(deg, 1), dtype=np.int64)
        k = block_catalog(arcs, doms, grid, cells, dom0, lptr, lnbr, lsidx, table)
        lclass = arcs.wclass[cells].copy() if arcs.wclass.shape[0] > 1 else arcs.wclass
        local = Arcs(arcs.full, lptr, lnbr[:k].copy(), lsidx[:k].copy(), arcs.sup,
                     arcs.supall, arcs.weights, arcs.wlogw, lclass, arcs.nib)  # fmt: skip
        lgrid = np.empty(nb, dtype=np.int32)
        if block_alg31(local, dom0, scan, retries, use_heap, weighted, key_weighted, rng,
                       lgrid, counters):  # fmt: skip
            for i in range(nb):
                grid[cells[i]] = lgrid[i]
            counters[1] += 1


# ----------------------------------------------------------------------------- problem arrays


@njit(cache=True)
def arc_csr(arcs: np.ndarray, ptr: np.ndarray, nbr: np.ndarray, sidx: np.ndarray) -> None:
    """The arcs of each cell as CSR rows, by counting sort (the arrays of
    :class:`csplab.catalog._Compiled`; ``arcs`` is ``Problem.arcs``, ``(m, 3)``).

    Row ``v`` lists the arcs with ``src = v`` in arc order (support index ``2r``), then
    those with ``dst = v`` (``2r + 1``); self-arcs are left out. ``ptr`` (``n + 1``, zeros)
    and ``nbr``, ``sidx`` (two entries per other arc) are filled in place: the same rows as
    a stable sort of both arc ends by cell, in O(m) and without temporaries of that size.
    """
    m = arcs.shape[0]
    n = ptr.shape[0] - 1
    for i in range(m):
        s = arcs[i, 0]
        d = arcs[i, 1]
        if s != d:
            ptr[s + 1] += 1
            ptr[d + 1] += 1
    for v in range(n):
        ptr[v + 1] += ptr[v]
    fill = ptr[:n].copy()
    for i in range(m):
        s = arcs[i, 0]
        d = arcs[i, 1]
        if s != d:
            k = fill[s]
            nbr[k] = d
            sidx[k] = 2 * arcs[i, 2]
            fill[s] = k + 1
    for i in range(m):
        s = arcs[i, 0]
        d = arcs[i, 1]
        if s != d:
            k = fill[d]
            nbr[k] = s
            sidx[k] = 2 * arcs[i, 2] + 1
            fill[d] = k + 1
