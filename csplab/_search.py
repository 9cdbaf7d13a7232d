"""Compiled depth-first search maintaining arc consistency (MAC) with a trail (numba).

Used by the ``backtrack`` solver (:mod:`csplab.solvers.backtrack`). Domains are the bitsets
of :mod:`csplab._kernels`; the arc revision is the one of :func:`csplab._kernels.propagate`
(``D(v) &= OR_{a in D(u)} sup[s, a]``), here with a trail: before a cell's domain first
changes after a decision, its old bitset is pushed, so undoing a decision restores exactly
the cells it touched instead of copying the whole catalog. The revision loop is a copy of
the one in :func:`csplab._kernels.propagate` on purpose: moving it into a shared ``@njit``
helper (inlined or not) made Alg. 3.1 30–40% slower at 40x40x10 (castle, city; A/B of
both kernels in one process, 16 shuffled rounds, identical copies within 5–9%).

Search state lives in arrays so the kernel can pause (node budget, trail full) and resume:
``state = [level, need_choose, epoch, trail_len, nodes, fails, fails_since_restart,
rng, scan_pos]``. Level ``L >= 1`` is a decision on cell ``lv_cell[L]`` whose untried labels
are ``lv_cand[L]``; ``lv_trail[L]`` is the trail length before its first attempt.
Return codes: 0 solved, 1 unsatisfiable (tree exhausted), 2 restart requested,
3 paused (node budget), 4 trail nearly full (grow and resume).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from csplab._kernels import ctz64, domain_size, popcount64

# state slots
LEVEL, NEED, EPOCH, TLEN, NODES, FAILS, FAILS_RUN, RNG, SCAN = range(9)


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
def propagate_trail(
    dom: np.ndarray, full: np.ndarray, ptr: np.ndarray, nbr: np.ndarray, sidx: np.ndarray,
    sup: np.ndarray, supall: np.ndarray, queue: np.ndarray, inq: np.ndarray, start: int,
    stamp: np.ndarray, state: np.ndarray, tcell: np.ndarray, tbits: np.ndarray,
    counters: np.ndarray,
) -> int:  # fmt: skip
    """Arc consistency from cell ``start`` saving old domains on the trail; wiped cell or -1."""
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
    dom: np.ndarray, full: np.ndarray, ptr: np.ndarray, nbr: np.ndarray, sidx: np.ndarray,
    sup: np.ndarray, supall: np.ndarray, queue: np.ndarray, inq: np.ndarray,
    stamp: np.ndarray, state: np.ndarray, tcell: np.ndarray, tbits: np.ndarray,
    lv_cell: np.ndarray, lv_cand: np.ndarray, lv_trail: np.ndarray, lv_scan: np.ndarray,
    scan: bool, order: np.ndarray, weights: np.ndarray, weighted: bool,
    max_nodes: int, restart_fails: int, counters: np.ndarray,
) -> int:  # fmt: skip
    """Run (or resume) the search; see the module docstring for codes and state."""
    n, W = dom.shape
    nodes_here = 0
    while True:
        L = state[LEVEL]
        if state[NEED] == 1:
            if nodes_here >= max_nodes:
                return 3
            if tcell.shape[0] - state[TLEN] < n + 1:
                return 4
            v = _choose_cell(dom, scan, order, state)
            if v < 0:
                return 0
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
                return 1
            continue
        if tcell.shape[0] - state[TLEN] < n + 1:
            return 4
        v = lv_cell[L]
        b = _pick_label(lv_cand[L], weights, weighted, _rand(state))
        wb = b // 64
        bit = np.uint64(1) << np.uint64(b - wb * 64)
        lv_cand[L, wb] &= ~bit
        state[EPOCH] += 1
        _save(dom, v, stamp, state, tcell, tbits)
        for w in range(W):
            dom[v, w] = bit if w == wb else np.uint64(0)
        wiped = propagate_trail(dom, full, ptr, nbr, sidx, sup, supall, queue, inq, v, stamp,
                                state, tcell, tbits, counters)  # fmt: skip
        if wiped >= 0:
            state[FAILS] += 1
            state[FAILS_RUN] += 1
            if restart_fails > 0 and state[FAILS_RUN] >= restart_fails:
                return 2
            continue
        state[NEED] = 1
