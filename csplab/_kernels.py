"""Compiled kernels (numba) for the catalog: bitset arc consistency and Alg. 3.1.

Domains are bitsets ``uint64 (n, W)`` with ``W = ceil(K / 64)``. Each arc ``(u, v, r)`` is
stored twice in a CSR adjacency: at ``u`` as ``(v, 2r)`` and at ``v`` as ``(u, 2r + 1)``.
``sup[s, a]`` is the bitset of labels a neighbour may take when this cell has label ``a``
(``s = 2r``: the forward relation, ``s = 2r + 1``: its transpose).

Revising ``v`` from ``u`` (statement 3.6): ``D(v) &= OR_{a in D(u)} sup[s, a]``, stopping the
OR early once it covers ``D(v)``. A FIFO queue of changed cells runs this to the fixpoint
(Alg. 3.2/3.3 with a queue instead of a stack; the fixpoint is the same).

All randomness is drawn by the caller from a numpy Generator and passed in as arrays, so
the kernels are deterministic.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# ----------------------------------------------------------------------------- bit helpers

_DEBRUIJN = np.uint64(0x03F79D71B4CB0A89)
_DEBRUIJN_TABLE = np.array(
    [
        0, 1, 48, 2, 57, 49, 28, 3, 61, 58, 50, 42, 38, 29, 17, 4,
        62, 55, 59, 36, 53, 51, 43, 22, 45, 39, 33, 30, 24, 18, 12, 5,
        63, 47, 56, 27, 60, 41, 37, 16, 54, 35, 52, 21, 44, 32, 23, 11,
        46, 26, 40, 15, 34, 20, 31, 10, 25, 14, 19, 9, 13, 8, 7, 6,
    ],
    dtype=np.int64,
)  # fmt: skip


@njit(cache=True, inline="always")
def ctz64(x: np.uint64) -> int:
    """Index of the lowest set bit of a non-zero uint64."""
    low = x & (~x + np.uint64(1))
    return int(_DEBRUIJN_TABLE[(low * _DEBRUIJN) >> np.uint64(58)])


@njit(cache=True, inline="always")
def popcount64(x: np.uint64) -> int:
    x = x - ((x >> np.uint64(1)) & np.uint64(0x5555555555555555))
    x = (x & np.uint64(0x3333333333333333)) + ((x >> np.uint64(2)) & np.uint64(0x3333333333333333))
    x = (x + (x >> np.uint64(4))) & np.uint64(0x0F0F0F0F0F0F0F0F)
    return int((x * np.uint64(0x0101010101010101)) >> np.uint64(56))


@njit(cache=True)
def domain_size(dom: np.ndarray, v: int) -> int:
    c = 0
    for w in range(dom.shape[1]):
        c += popcount64(dom[v, w])
    return c


@njit(cache=True)
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


@njit(cache=True)
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


@njit(cache=True)
def _heap_swap(heap: np.ndarray, pos: np.ndarray, i: int, j: int) -> None:
    a = heap[i]
    b = heap[j]
    heap[i] = b
    heap[j] = a
    pos[b] = i
    pos[a] = j


@njit(cache=True)
def _heap_up(heap: np.ndarray, pos: np.ndarray, key: np.ndarray, i: int) -> None:
    while i > 0:
        p = (i - 1) >> 1
        if key[heap[i]] < key[heap[p]]:
            _heap_swap(heap, pos, i, p)
            i = p
        else:
            break


@njit(cache=True)
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


@njit(cache=True)
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


@njit(cache=True)
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
    weighted: bool,
) -> int:
    """Arc consistency from the cells ``start[:nstart]``; returns the wiped-out cell or -1.

    ``prev[u]`` is ``D(u)`` when ``u`` was last processed (all zero: unknown). When ``u``
    lost only a few of many labels since then, only the neighbour labels those supported
    are re-checked (``D(u) & sup[s ^ 1, c]``); otherwise ``D(v)`` is intersected with the
    union of the supports of ``D(u)``. ``stats[0]`` counts queue pops (propagation steps),
    ``stats[1]`` label removals. When ``hsize > 0`` the min-entropy heap keys of changed cells
    are updated. The queue is left empty on return (also after a wipe-out).
    """
    n = dom.shape[0]
    W = dom.shape[1]
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
    acc = np.empty(W, dtype=np.uint64)
    rem = np.empty(W, dtype=np.uint64)
    wiped = -1
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
        nd = 0
        nr = 0
        for w in range(W):
            if dom[u, w] != full[w]:
                isfull = False
            if prev[u, w]:
                known = True
            nd += popcount64(dom[u, w])
            rem[w] = prev[u, w] & ~dom[u, w]
            nr += popcount64(rem[w])
        if known and nr == 0:
            continue  # nothing changed since u was last processed
        use_delta = known and nr < nd
        for w in range(W):
            prev[u, w] = dom[u, w]
        for e in range(ptr[u], ptr[u + 1]):
            v = nbr[e]
            s = sidx[e]
            if use_delta:
                # labels of v that some removed label of u supported
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
            else:
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
            empty = True
            for w in range(W):
                old = dom[v, w]
                new = old & acc[w]
                if new != old:
                    stats[1] += popcount64(old ^ new)
                    dom[v, w] = new
                    changed = True
                if new:
                    empty = False
            if changed:
                if empty:
                    wiped = v
                    break
                if hsize > 0 and hpos[v] >= 0 and hpos[v] < hsize:
                    k = entropy_of(dom, v, weights, wlogw, weighted) + 1e-6 * noise[v]
                    heap_update(heap, hpos, hkey, hsize, v, k)
                if not inq[v]:
                    inq[v] = True
                    queue[tail] = v
                    tail += 1
                    if tail == n:
                        tail = 0
                    count += 1
        if wiped >= 0:
            break
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


@njit(cache=True)
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
    order: np.ndarray,
    use_heap: bool,
    ustream: np.ndarray,
    noise: np.ndarray,
    weights: np.ndarray,
    wlogw: np.ndarray,
    weighted: bool,
    grid: np.ndarray,
    trace_cell: np.ndarray,
    trace_label: np.ndarray,
    state: np.ndarray,
    max_steps: int,
    stats: np.ndarray,
    heap: np.ndarray,
    hpos: np.ndarray,
    hkey: np.ndarray,
) -> int:
    """Run Alg. 3.1 from step ``state[0]`` for at most ``max_steps`` assignments.

    ``state = [step, heap_size, fail_cell]``. Returns 0 when every cell is assigned,
    1 on failure (a domain emptied: ``state[2]`` is that cell), 2 when paused.
    The catalog must already be arc consistent when the run starts.
    """
    n = dom.shape[0]
    start = np.empty(1, dtype=np.int64)
    steps_here = 0
    while state[0] < n:
        if steps_here >= max_steps:
            return 2
        t = state[0]
        if use_heap:
            hsize = state[1]
            p = heap_pop(heap, hpos, hkey, hsize)
            state[1] = hsize - 1
        else:
            p = order[t]
        b = choose_label(dom, p, ustream[t], weights, weighted)
        if b < 0:
            state[2] = p
            return 1
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
            wiped = propagate(
                dom, prev, full, ptr, nbr, sidx, sup, supall, queue, inq, start, 1, stats,
                heap, hpos, hkey, state[1] if use_heap else 0, noise, weights, wlogw, weighted,
            )  # fmt: skip
            if wiped >= 0:
                state[2] = wiped
                return 1
    return 0
