"""The interpreted twin of :func:`csplab._kernels.propagate` and :func:`csplab._kernels.alg31`
for small problems: no numba, so a small synthesis starts in a fraction of the time.

Loading numba and one cached kernel costs 0.3–0.45 s on a 2-core machine, while Alg. 3.1 on
a 20×20 model takes a few milliseconds in plain Python. :class:`~csplab.catalog.Propagator`
therefore runs the propagation and Alg. 3.1 here while numba has not been loaded in the
process (:func:`csplab._jit.compiled`) and the problem is small (:func:`use_interp`); once a
kernel has been loaded, everything runs compiled.

This is not a second algorithm: it is the same computation in another language, checked
against the kernels by ``tests/test_interp.py`` (the same grid, trace, fail cell and counts
of queue pops and label removals for every order and choice, on random problems). Domains
are Python integers used as bitsets (bit ``b``: label ``b``); the support of a domain in an
arc direction is memoised per direction. The queue is the kernels' FIFO, cells are revised in
the same order, so the statistics agree pop for pop. The union of the supports of ``D(u)``
equals what each of the kernel's four revision branches keeps. ``min-entropy`` and
``min-domain`` pick the unassigned cell of least key from a binary heap of ``(key, cell)``
entries with stale entries skipped; as in the kernels, the key of a changed cell is computed
once, when the queue is empty (its weight sums are updated at each change, in the kernels'
order); the keys are computed with the kernels' formulas in the
same order of operations (``math.log`` is the C library's ``log``, as numba's ``np.log``
on a scalar), so the pick is the same unless two cells have bit-identical keys, which the
random tie-breaking term makes practically impossible.

The rule loads the kernels once :data:`BUDGET` seconds of interpreted work have been spent
in the process (many small solves, as experiments and witness searches make, run faster
compiled after that). ``CSPLAB_ENGINE`` (environment) or :data:`ENGINE` selects ``"auto"``
(the rule above),
``"kernels"`` or ``"interp"`` (every problem whose run fits one call; for tests and
benchmarks).

Examples
--------
>>> import numpy as np
>>> from csplab import ExampleModel, from_example
>>> from csplab.engine.alg31 import run_alg31
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (4, 3))
>>> run_alg31(P, np.random.default_rng(1)).status
'solved'
"""

from __future__ import annotations

import heapq
import math
import os
import time
from collections import deque
from collections.abc import Iterator
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab import _jit

__all__ = [
    "ENGINE",
    "LIMIT",
    "Tables",
    "alg31",
    "compiled_engine",
    "kernels_for",
    "propagate",
    "set_bits",
    "use_interp",
]

#: ``"auto"``, ``"kernels"`` or ``"interp"`` (see the module docstring)
ENGINE = os.environ.get("CSPLAB_ENGINE", "auto")
#: largest ``cells * labels`` the ``auto`` rule interprets (about 0.1 s of Python at most)
LIMIT = 50_000
#: seconds of interpreted work after which the ``auto`` rule loads the kernels (many small
#: solves in one process, as an experiment runs them, are faster compiled after that)
BUDGET = 0.5
_SPENT = [0.0]

_SOLVED, _FAILED = 0, 1  # csplab._kernels.Code values (that module defines the enum)


def use_interp(n: int, K: int) -> bool:
    """Whether a problem of ``n`` cells and ``K`` labels runs interpreted now."""
    if ENGINE == "interp":
        return True
    if ENGINE == "kernels":
        return False
    if n * K > LIMIT or _jit.compiled("csplab._kernels"):
        return False
    if _SPENT[0] > BUDGET:  # enough interpreted work in this process: load the kernels
        from csplab import _kernels

        _jit.load(_kernels.__name__)
        return False
    return True


def compiled_engine() -> bool:
    """Whether csplab's compiled kernels are the engine now (loaded, or forced)."""
    return ENGINE == "kernels" or (ENGINE == "auto" and _jit.compiled("csplab._kernels"))


def kernels_for(n: int, K: int) -> None:
    """A job of ``n`` cells and ``K`` labels that runs many small problems (modify in blocks,
    block workers): load the kernels now if the whole job is beyond :data:`LIMIT`, so its
    small problems run compiled too."""
    if ENGINE != "interp" and n * K > LIMIT:
        from csplab import _kernels

        _jit.load(_kernels.__name__)


def _ints(bits: NDArray[np.uint64]) -> list[int]:
    """Rows of ``uint64`` words as Python integers (word 0 lowest)."""
    n, W = bits.shape
    raw = np.ascontiguousarray(bits, dtype="<u8").tobytes()
    step = 8 * W
    return [int.from_bytes(raw[i * step : (i + 1) * step], "little") for i in range(n)]


def _store(values: list[int], out: NDArray[np.uint64]) -> None:
    """Write Python-integer bitsets back into ``out`` (``uint64 (n, W)``)."""
    n, W = out.shape
    step = 8 * W
    raw = b"".join(v.to_bytes(step, "little") for v in values)
    out[...] = np.frombuffer(raw, dtype="<u8").reshape(n, W)


class Tables:
    """A problem's compiled arrays (:class:`csplab.catalog._Compiled`) as Python lists."""

    def __init__(self, c: Any) -> None:
        self.n, self.K = int(c.n), int(c.K)
        self.ptr: list[int] = c.ptr.tolist()
        self.nbr: list[int] = c.nbr.tolist()
        self.sidx: list[int] = c.sidx.tolist()
        S = c.sup.shape[0]
        flat = _ints(c.sup.reshape(S * self.K, -1))
        self.sup = [flat[s * self.K : (s + 1) * self.K] for s in range(S)]
        self.memo: list[dict[int, int]] = [{} for _ in range(S)]
        #: per weight class, the label weights and ``w log w``; the class of each cell
        self.weights: list[list[float]] = c.weights.tolist()
        self.wlogw: list[list[float]] = c.wlogw.tolist()
        self.wclass: list[int] = c.wclass.tolist()

    def row(self, v: int) -> int:
        """:func:`csplab._kernels.wrow`: the weight class of cell ``v``."""
        return self.wclass[v] if len(self.wclass) > 1 else 0

    def support(self, s: int, d: int) -> int:
        """The labels supported across direction ``s`` by the domain ``d``."""
        acc = 0
        sup = self.sup[s]
        x = d
        while x:
            low = x & -x
            acc |= sup[low.bit_length() - 1]
            x ^= low
        self.memo[s][d] = acc
        return acc


class _Keys:
    """The entropy heap of a ``min-entropy`` / ``min-domain`` run."""

    def __init__(self, T: Tables, hp: Any, hsize: int, weighted: bool) -> None:
        cells: list[int] = hp.heap[:hsize].tolist()
        self.key: list[float] = hp.key.tolist()
        self.noise: list[float] = hp.noise.tolist()
        self.memo = weighted and hp.sw.shape[0] > 0
        self.sw: list[float] = hp.sw.tolist()
        self.swl: list[float] = hp.swl.tolist()
        self.weighted = weighted
        self.inheap = bytearray(T.n)
        for c in cells:
            self.inheap[c] = 1
        self.entries: list[tuple[float, int]] = [(self.key[c], c) for c in cells]
        heapq.heapify(self.entries)
        self.T = T

    def removed(self, v: int, gone: int) -> None:
        if self.memo:
            r = self.T.row(v)
            w, wl = self.T.weights[r], self.T.wlogw[r]
            for a in set_bits(gone):
                self.sw[v] -= w[a]
                self.swl[v] -= wl[a]

    def update(self, v: int, d: int) -> None:
        if self.memo and self.sw[v] > 1e-12:
            k = math.log(self.sw[v]) - self.swl[v] / self.sw[v] + 1e-6 * self.noise[v]
        else:
            k = _entropy(self.T, d, self.weighted, v) + 1e-6 * self.noise[v]
        self.key[v] = k
        heapq.heappush(self.entries, (k, v))

    def pop(self) -> int:
        while True:
            k, c = heapq.heappop(self.entries)
            if self.inheap[c] and k == self.key[c]:
                self.inheap[c] = 0
                return c


def set_bits(d: int) -> Iterator[int]:
    """The set bits of the Python-int bitset ``d`` (the labels of a domain), lowest first."""
    while d:
        low = d & -d
        yield low.bit_length() - 1
        d ^= low


def _entropy(T: Tables, d: int, weighted: bool, v: int) -> float:
    """:func:`csplab._kernels.entropy_of` of the domain ``d`` of cell ``v``."""
    if not weighted:
        c = d.bit_count()
        return math.log(c) if c > 0 else 0.0
    s = sl = 0.0
    w, wl = T.weights[T.row(v)], T.wlogw[T.row(v)]
    for a in set_bits(d):
        s += w[a]
        sl += wl[a]
    if s <= 0.0:
        cnt = d.bit_count()
        return math.log(cnt) if cnt > 0 else 0.0
    return math.log(s) - sl / s


def _revise(
    T: Tables, dom: list[int], prev: list[int], start: Any, stats: list[int],
    keys: _Keys | None,
) -> int:  # fmt: skip
    """:func:`csplab._kernels._propagate` on Python bitsets; returns the wiped cell or -1."""
    ptr, nbr, sidx, memo = T.ptr, T.nbr, T.sidx, T.memo
    inq = bytearray(T.n)
    queue: deque[int] = deque()
    for c in start:
        if not inq[c]:
            inq[c] = 1
            queue.append(c)
    pops = removals = 0
    wiped = -1
    dirty: dict[int, None] = {}  # cells whose key changed, updated once the queue is empty
    while queue:
        u = queue.popleft()
        inq[u] = 0
        pops += 1
        du = dom[u]
        pu = prev[u]
        if pu and not (pu & ~du):
            continue  # nothing changed since u was last processed
        prev[u] = du
        for e in range(ptr[u], ptr[u + 1]):
            v = nbr[e]
            s = sidx[e]
            acc = memo[s].get(du)
            if acc is None:
                acc = T.support(s, du)
            old = dom[v]
            new = old & acc
            if new != old:
                removals += (old ^ new).bit_count()
                dom[v] = new
                inheap = keys is not None and keys.inheap[v]
                if inheap:
                    keys.removed(v, old & ~new)  # type: ignore[union-attr]
                if not new:
                    wiped = v
                    break
                if inheap:
                    dirty[v] = None
                if not inq[v]:
                    inq[v] = 1
                    queue.append(v)
        if wiped >= 0:
            break
    if keys is not None and wiped < 0:
        for v in dirty:
            keys.update(v, dom[v])
    for q in queue:  # cells left in the queue are not at their fixpoint
        prev[q] = 0
    stats[0] += pops
    stats[1] += removals
    return wiped


def _write_back(
    dom: list[int], pv: list[int], st: list[int], bits: NDArray[np.uint64],
    prev: NDArray[np.uint64], stats: NDArray[np.int64], since: float,
) -> None:  # fmt: skip
    """The end of an entry point: the domains and their last-processed copies back into the
    kernel's arrays, the pops and removals added to ``stats``, the time since ``since``
    counted as interpreted work."""
    _store(dom, bits)
    _store(pv, prev)
    stats[0] += st[0]
    stats[1] += st[1]
    _SPENT[0] += time.perf_counter() - since


def _tables(c: Any) -> Tables:
    T = getattr(c, "interp", None)
    if T is None:
        T = c.interp = Tables(c)
    return T


def propagate(c: Any, bits: NDArray[np.uint64], prev: NDArray[np.uint64],
              stats: NDArray[np.int64], start: Any) -> int:  # fmt: skip
    """Arc consistency from the cells ``start`` on the packed catalog ``bits`` (in place, as
    :func:`csplab._kernels.propagate` without a heap); returns the wiped cell or -1."""
    t0 = time.perf_counter()
    T = _tables(c)
    dom, pv = _ints(bits), _ints(prev)
    st = [0, 0]
    wiped = _revise(T, dom, pv, np.asarray(start).tolist(), st, None)
    _write_back(dom, pv, st, bits, prev, stats, t0)
    return wiped


def _choose(T: Tables, d: int, u: float, weighted: bool, v: int) -> int:
    """:func:`csplab._kernels.choose_label` on the domain ``d`` of cell ``v``."""
    if weighted:
        w = T.weights[T.row(v)]
        tot = 0.0  # added in label order, as the kernel does (not sum(): 3.12 compensates)
        for a in set_bits(d):
            tot += w[a]
        if tot > 0.0:
            target = u * tot
            last = -1
            cum = 0.0
            for a in set_bits(d):
                if w[a] > 0.0:
                    cum += w[a]
                    last = a
                    if cum > target:
                        return a
            return last
    cnt = d.bit_count()
    if cnt == 0:
        return -1
    j = min(int(u * cnt), cnt - 1)
    x = d
    for _ in range(j):
        x &= x - 1
    return (x & -x).bit_length() - 1


def alg31(
    c: Any, bits: NDArray[np.uint64], prev: NDArray[np.uint64], stats: NDArray[np.int64],
    run: Any, hp: Any, use_heap: bool, weighted: bool, key_weighted: bool,
) -> int:  # fmt: skip
    """:func:`csplab._kernels.alg31` to the end of the run (solved or failed); updates
    ``bits``, ``prev``, ``stats`` and the :class:`~csplab._kernels.Run` as the kernel does.
    Returns the kernel's code (0 solved, 1 failed)."""
    t_start = time.perf_counter()
    T = _tables(c)
    n = T.n
    dom, pv = _ints(bits), _ints(prev)
    st = [0, 0]
    state = run.state
    t0 = t = int(state[0])
    hsize = int(state[1])
    keys = _Keys(T, hp, hsize, key_weighted) if use_heap else None
    order = run.order.tolist()
    us = run.ustream.tolist()
    grid, tcell, tlabel = run.grid, run.trace_cell, run.trace_label
    code = _SOLVED
    while t < n:
        p = keys.pop() if keys is not None else order[t]
        b = _choose(T, dom[p], us[t], weighted, p)
        if b < 0:
            state[2] = p
            code = _FAILED
            break
        grid[p] = b
        tcell[t] = p
        tlabel[t] = b
        t += 1
        bit = 1 << b
        if dom[p] != bit:
            st[1] += (dom[p] ^ bit).bit_count()
            dom[p] = bit
            wiped = _revise(T, dom, pv, (p,), st, keys)
            if wiped >= 0:
                state[2] = wiped
                code = _FAILED
                break
    state[0] = t
    if keys is not None:
        state[1] = hsize - (t - t0)
    _write_back(dom, pv, st, bits, prev, stats, t_start)
    return code
