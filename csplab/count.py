"""Exact and approximate solution counting: ``D_E(n_x, n_y, n_z)`` of thesis Sec. 3.2.

:func:`count_solutions` counts the solutions of any :class:`~csplab.problem.Problem` (the
number of models consistent with an example at a given size, with fixed cells, boundary
labels, periodic axes ...). Exact counts are Python integers, never floats.

Methods
-------
``"transfer"``
    A transfer-matrix method over slice states, done cell by cell (a frontier dynamic
    program): cells are processed in an order that keeps the *frontier* (processed cells
    with an arc to an unprocessed one) small; a state is the labels on the frontier and
    carries the number of partial solutions that lead to it. On a grid scanned with its
    longest axis outermost the frontier is one slice (plus one cell), so models narrow in
    one axis (2D strips) or two (3D rods) are counted in time linear in the length.
    Domains are first made arc consistent (Theorem 3.3.2: no solution is lost).
``"enumerate"``
    SAT with blocking clauses (:func:`csplab.engine.sat.enumerate_solutions`): tiny problems.
``"ganak"``
    The exact #SAT solver Ganak (``pip install pyganak``, extra ``count``) on the support
    encoding (:func:`csplab.cnf.encode` with an exact at-most-one), projected on the label
    variables.
``"approxmc"``
    ApproxMC (``pip install pyapproxmc``, extra ``count``): an (ε, δ) approximation — with
    probability at least ``1 - delta`` the estimate lies within a factor ``1 + epsilon`` of
    the true count (Chakraborty, Meel, Vardi 2016). Not exact; ``Count.exact`` is False.
    Pinned to pyapproxmc 4.1.24: 4.4.0 returned 1 for ``x1 XOR x2`` (measured).
``"auto"``
    ``transfer`` when its state space stays below ``max_states``, else ``ganak`` when
    installed, else ``enumerate``.

Examples
--------
>>> from csplab import from_example, load_example
>>> int(count_solutions(from_example(load_example("fig3_1b"), (7, 9))))
2
>>> c = count_solutions(from_example(load_example("line"), (4, 4)))
>>> int(c), c.method, c.exact
(4096, 'transfer', True)
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from csplab.catalog import Propagator
from csplab.deps import available, require
from csplab.errors import CsplabError, InputError
from csplab.grids import from_example
from csplab.io.ruleset import RuleSet
from csplab.problem import Problem
from csplab.progress import progress_bar
from csplab.rng import RngLike, make_rng

if TYPE_CHECKING:
    from csplab.cnf import Encoding

_PAIRWISE_MAX = 8  # domain size up to which the counting CNF uses pairwise at-most-one

__all__ = [
    "METHODS",
    "Count",
    "CountTimeoutError",
    "count_solutions",
    "enclosed_sets",
    "entropy_per_cell",
    "frontier_order",
    "lower_bound_3_2_1",
]

METHODS = ("auto", "transfer", "enumerate", "ganak", "approxmc")


class Count(int):
    """An ``int`` (the count) with ``method``, ``exact``, ``time_s`` and ``stats``."""

    method: str
    exact: bool
    time_s: float
    stats: dict[str, Any]

    def __new__(
        cls,
        value: int,
        method: str,
        exact: bool = True,
        time_s: float = 0.0,
        stats: dict[str, Any] | None = None,
    ) -> Count:
        obj = super().__new__(cls, value)
        obj.method = method
        obj.exact = exact
        obj.time_s = time_s
        obj.stats = dict(stats or {})
        return obj

    def log2(self) -> float:
        """``log2`` of the count (``-inf`` for zero), exact for huge integers."""
        v = int(self)
        return math.log2(v) if v > 0 else float("-inf")

    def to_dict(self) -> dict[str, Any]:
        return {
            "count": str(int(self)),
            "log2": self.log2(),
            "method": self.method,
            "exact": self.exact,
            "time_s": round(self.time_s, 6),
            "stats": self.stats,
        }


# ----------------------------------------------------------------------------- orders


def _neighbours(problem: Problem) -> list[set[int]]:
    nb: list[set[int]] = [set() for _ in range(problem.n)]
    for s, d in problem.arcs[:, :2].tolist():
        if s != d:
            nb[s].add(d)
            nb[d].add(s)
    return nb


def _frontier_cost(order: Sequence[int], nb: list[set[int]], bits: NDArray[np.float64]) -> float:
    """max over steps of sum of log2|D| over the frontier (the log of a state-count bound)."""
    pos = np.empty(len(order), dtype=np.int64)
    pos[np.asarray(order, dtype=np.int64)] = np.arange(len(order))
    last = np.array([max((pos[u] for u in nb[c]), default=-1) for c in range(len(order))])
    # cell c is on the frontier for steps pos[c] .. last[c]-1
    delta = np.zeros(len(order) + 1)
    live = last > pos
    np.add.at(delta, pos[live], bits[live])
    np.add.at(delta, last[live], -bits[live])
    return float(np.cumsum(delta).max(initial=0.0))


def frontier_order(problem: Problem, domains: NDArray[np.bool_] | None = None) -> list[int]:
    """A cell order with a small frontier: the best of the grid's scan orders (one per
    choice of the outermost axis) and networkx's reverse Cuthill–McKee order."""
    dom = problem.domains if domains is None else domains
    bits = np.log2(np.maximum(dom.sum(axis=1), 1)).astype(np.float64)
    nb = _neighbours(problem)
    idx = np.arange(problem.n).reshape(problem.shape)
    cands: list[list[int]] = []
    nd = problem.ndim
    for outer in range(nd):
        rest = [d for d in range(nd) if d != outer]
        rest.sort(key=lambda d: -problem.shape[d])
        cands.append(np.transpose(idx, [outer, *rest]).ravel().tolist())
    if problem.n <= 20000:
        import networkx as nx

        Gr = nx.Graph()
        Gr.add_nodes_from(range(problem.n))
        Gr.add_edges_from((int(s), int(d)) for s, d in problem.arcs[:, :2] if s != d)
        cands.append([int(c) for c in nx.utils.reverse_cuthill_mckee_ordering(Gr)])
    costs = [_frontier_cost(o, nb, bits) for o in cands]
    return cands[int(np.argmin(costs))]


# ----------------------------------------------------------------------------- transfer


def _count_transfer(
    problem: Problem, max_states: int, deadline: float | None = None, progress: bool = False
) -> tuple[int, dict[str, Any]]:
    eng = Propagator(problem)
    if not eng.ok:
        return 0, {"decided_by": "arc consistency", "max_states": 0}
    dom = eng.catalog()
    n = problem.n
    order = frontier_order(problem, dom)
    pos = np.empty(n, dtype=np.int64)
    pos[np.asarray(order, dtype=np.int64)] = np.arange(n)
    # arcs by the later endpoint: (earlier cell, relation, earlier-is-source)
    back: list[list[tuple[int, int, bool]]] = [[] for _ in range(n)]
    last = np.full(n, -1, dtype=np.int64)
    for s, d, r in problem.arcs.tolist():
        if s == d:
            continue
        if pos[s] < pos[d]:
            back[d].append((s, r, True))
        else:
            back[s].append((d, r, False))
        last[s] = max(last[s], pos[d])
        last[d] = max(last[d], pos[s])
    rel = problem.relations
    frontier: list[int] = []
    labels = np.zeros((1, 0), dtype=np.int32)  # states x frontier cells
    counts: NDArray[Any] = np.ones(1, dtype=np.int64)
    big = False
    peak = 1
    steps = progress_bar(enumerate(order), total=n, desc="transfer matrix", enabled=progress)
    for step, v in steps:
        if deadline is not None and time.perf_counter() > deadline:
            raise CountTimeoutError("transfer", f"after {step} of {n} cells")
        D = np.flatnonzero(dom[v]).astype(np.int32)
        col = {c: i for i, c in enumerate(frontier)}
        S = labels.shape[0]
        ok = np.ones((S, D.size), dtype=bool)
        for u, r, u_is_src in back[v]:
            lu = labels[:, col[u]]
            ok &= rel[r][lu][:, D] if u_is_src else rel[r][D][:, lu].T
        si, bi = np.nonzero(ok)
        if si.size == 0:
            return 0, {"max_states": peak, "order_cost_bits": None}
        new_labels = np.concatenate([labels[si], D[bi][:, None]], axis=1)
        new_counts = counts[si]
        cells = [*frontier, v]
        keep = [i for i, c in enumerate(cells) if last[c] > step]
        new_labels = new_labels[:, keep]
        frontier = [cells[i] for i in keep]
        if len(keep) < len(cells):
            new_labels, new_counts = _merge(new_labels, new_counts, problem.K)
        labels, counts = new_labels, new_counts
        peak = max(peak, labels.shape[0])
        if labels.shape[0] > max_states:
            raise _TooBig(labels.shape[0])
        if (
            not big
            and counts.dtype != object
            and counts.max(initial=0) > 2**62 // max(problem.K, 2)
        ):
            counts = counts.astype(object)
            big = True
    total = int(counts.sum()) if counts.size else 0
    return total, {"max_states": int(peak), "exact_arithmetic": "object" if big else "int64"}


class CountTimeoutError(CsplabError, TimeoutError):
    """:func:`count_solutions` ran out of its ``time_limit`` (the count is undecided).

    Attributes
    ----------
    method : str
        The counting method that was running.
    progress : str
        How far it got (cells of the transfer matrix, solutions enumerated).
    """

    def __init__(self, method: str, progress: str) -> None:
        super().__init__(f"the time limit ran out while counting by {method} ({progress})")
        self.method = method
        self.progress = progress


class _TooBig(Exception):
    def __init__(self, states: int) -> None:
        super().__init__(states)
        self.states = states


def _merge(labels: NDArray[np.int32], counts: NDArray[Any], K: int) -> tuple[Any, Any]:
    if labels.shape[1] == 0:
        return labels[:1], np.array([counts.sum()], dtype=counts.dtype)
    if labels.shape[1] * math.log2(max(K, 2)) < 62:
        radix = (K ** np.arange(labels.shape[1], dtype=np.int64)).astype(np.int64)
        codes = labels.astype(np.int64) @ radix
        order = np.argsort(codes, kind="stable")
        sc = codes[order]
        starts = np.flatnonzero(np.r_[True, sc[1:] != sc[:-1]])
    else:
        _uniq, inv = np.unique(labels, axis=0, return_inverse=True)
        order = np.argsort(inv.ravel(), kind="stable")
        si = inv.ravel()[order]
        starts = np.flatnonzero(np.r_[True, si[1:] != si[:-1]])
    return labels[order[starts]], np.add.reduceat(counts[order], starts)


# ----------------------------------------------------------------------------- SAT based


def _counting_cnf(problem: Problem) -> Encoding:
    """The support encoding with an exact at-most-one (pairwise for small domains, a
    sequential counter otherwise): its models projected on the ``x`` variables
    (``1..nx``) are exactly the solutions. The solver's lazy at-most-one would not do:
    a model with two true labels in a cell is not a solution."""
    from csplab.cnf import encode

    K = int(problem.domains.sum(axis=1).max()) if problem.n else 0
    return encode(problem, amo="pairwise" if K <= _PAIRWISE_MAX else "seqcounter")


def _open_cells(enc: Encoding) -> int:
    return int(((enc.var > 0).sum(axis=1) > 0).sum())


def _count_enumerate(
    problem: Problem, limit: int, deadline: float | None = None
) -> tuple[int, dict[str, Any]]:
    from csplab.engine.sat import enumerate_solutions

    n = 0
    for _ in enumerate_solutions(problem, limit=limit + 1):
        n += 1
        if deadline is not None and time.perf_counter() > deadline:
            raise CountTimeoutError("enumerate", f"{n} solutions so far")
    if n > limit:
        raise InputError(
            f"more than {limit} solutions: enumeration is for tiny problems; use "
            "method='transfer' or 'ganak'"
        )
    return n, {"enumerated": n}


def _count_ganak(
    problem: Problem, seed: int, deadline: float | None = None
) -> tuple[int, dict[str, Any]]:
    require("pyganak", "count", "count method 'ganak'")

    enc = _counting_cnf(problem)
    stats = {"vars": enc.nvars, "clauses": enc.nclauses, "open_cells": _open_cells(enc)}
    if not enc.ok:
        return 0, stats
    if enc.nx == 0:
        return int(problem.is_solution(enc.const.reshape(problem.shape))), stats
    job = (enc.nvars, [list(map(int, c)) for c in enc.clauses()], enc.nx, seed % (2**31))
    if deadline is None:
        return _ganak_count(*job), stats
    # pyganak has no time limit: count in a child process, stopped when the time is up
    import multiprocessing as mp

    ctx: Any = mp.get_context("fork" if "fork" in mp.get_all_start_methods() else "spawn")
    recv, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_ganak_child, args=(send, job), daemon=True)
    proc.start()
    send.close()
    try:
        if not recv.poll(max(deadline - time.perf_counter(), 0.0)):
            raise CountTimeoutError("ganak", "the #SAT count did not finish")
        try:
            kind, value = recv.recv()
        except EOFError:
            raise InputError("the ganak process ended without a count") from None
    finally:
        if proc.is_alive():
            proc.kill()
        proc.join()
        recv.close()
    if kind != "ok":
        raise InputError(f"ganak failed: {value}")
    return int(value), stats


def _ganak_count(nvars: int, clauses: list[list[int]], nx: int, seed: int) -> int:
    Counter = require("pyganak", "count", "count method 'ganak'").Counter
    c = Counter(seed=seed)
    c.new_vars(nvars)
    c.add_clauses(clauses)
    if nvars > nx:
        c.set_sampling_set(list(range(1, nx + 1)))
    return int(c.count())


def _ganak_child(send: Any, job: tuple[int, list[list[int]], int, int]) -> None:
    try:
        send.send(("ok", str(_ganak_count(*job))))
    except Exception as e:  # reported to the parent as one line
        send.send(("error", f"{type(e).__name__}: {e}"))
    finally:
        send.close()


def _count_approxmc(
    problem: Problem, seed: int, epsilon: float, delta: float
) -> tuple[int, dict[str, Any]]:
    Counter = require("pyapproxmc", "count", "count method 'approxmc'").Counter

    enc = _counting_cnf(problem)
    stats: dict[str, Any] = {"epsilon": epsilon, "delta": delta, "vars": enc.nvars}
    if not enc.ok:
        return 0, stats
    if enc.nx == 0:
        return int(problem.is_solution(enc.const.reshape(problem.shape))), stats
    c = Counter(seed=seed % (2**31), epsilon=epsilon, delta=delta)
    c.add_clauses(enc.clauses())
    cells, hashes = c.count(list(range(1, enc.nx + 1)))
    stats.update(cells=int(cells), hashes=int(hashes))
    return int(cells) * 2 ** int(hashes), stats


# ----------------------------------------------------------------------------- API


def count_solutions(
    problem: Problem,
    method: str = "auto",
    *,
    rng: RngLike = 0,
    max_states: int = 2_000_000,
    limit: int = 100_000,
    epsilon: float = 0.8,
    delta: float = 0.2,
    time_limit: float | None = None,
    progress: bool = False,
) -> Count:
    """The number of solutions of ``problem`` (see the module docstring for methods).

    ``progress=True`` shows a bar on stderr (after 2 s) while the transfer matrix sweeps the
    cells (the CLI turns it on).

    Parameters
    ----------
    problem : Problem
    method : {"auto", "transfer", "enumerate", "ganak", "approxmc"}
    rng : int or Generator
        Seed for the (randomised) counters ganak and approxmc.
    max_states : int
        ``transfer`` gives up (``auto`` moves on) above this many frontier states.
    limit : int
        ``enumerate`` refuses problems with more solutions than this.
    epsilon, delta : float
        ApproxMC's tolerance and confidence.
    time_limit : float, optional
        Seconds for the whole count: ``transfer`` checks the clock before each cell of its
        order, ``enumerate`` after each solution, ``ganak`` counts in a child process that
        is stopped at the limit (``approxmc`` has no limit).

    Returns
    -------
    Count
        An ``int`` with ``method``, ``exact``, ``time_s`` and ``stats``.

    Raises
    ------
    CountTimeoutError
        The time limit ran out before the count was known.
    """
    if not isinstance(problem, Problem):
        raise InputError(f"count_solutions() needs a Problem, got {type(problem).__name__}")
    if method not in METHODS:
        raise InputError(f"method must be one of {', '.join(METHODS)}, not {method!r}")
    if not (epsilon > 0 and 0 < delta < 1):
        raise InputError("epsilon must be > 0 and delta in (0, 1)")
    if time_limit is not None and not (math.isfinite(time_limit) and time_limit > 0):
        raise InputError(f"time_limit must be a positive number of seconds, not {time_limit!r}")
    _, seed = make_rng(rng)
    seed = seed or 0
    problem.require_no_constraints("counting")
    t0 = time.perf_counter()
    deadline = None if time_limit is None else t0 + time_limit
    if method in ("auto", "transfer"):
        try:
            val, st = _count_transfer(problem, max_states, deadline, progress)
            return Count(val, "transfer", True, time.perf_counter() - t0, st)
        except _TooBig as e:
            if method == "transfer":
                raise InputError(
                    f"transfer-matrix counting needs more than {max_states} states "
                    f"(reached {e.states}); the model is too wide: raise max_states or use "
                    "method='ganak'"
                ) from None
        method = "ganak" if available("pyganak") else "enumerate"
    if method == "enumerate":
        val, st = _count_enumerate(problem, limit, deadline)
    elif method == "ganak":
        val, st = _count_ganak(problem, seed, deadline)
    else:
        val, st = _count_approxmc(problem, seed, epsilon, delta)
        return Count(val, "approxmc", False, time.perf_counter() - t0, st)
    return Count(val, method, True, time.perf_counter() - t0, st)


# ----------------------------------------------------------------------------- Sec. 3.2


@dataclass(frozen=True)
class EnclosedSet:
    """A set H of non-empty cells of an example enclosed by empty space (Theorem 3.2.1)."""

    cells: tuple[tuple[int, ...], ...]
    extent: tuple[int, ...]


def enclosed_sets(example: Any, empty: int = 0) -> list[EnclosedSet]:
    """The connected (face-adjacent) groups of non-``empty`` cells of ``example`` all of
    whose neighbours lie inside the example and hold ``empty`` (sets H of Theorem 3.2.1),
    smallest extent first. Empty when ``empty`` is not adjacent to itself along every axis.
    """
    import networkx as nx

    lab = np.asarray(example.labels)
    T = example.transitions()
    if not all(T[d, empty, empty] for d in range(lab.ndim)):
        return []
    filled = lab != empty
    Gr = nx.Graph()
    coords = [tuple(int(i) for i in c) for c in np.argwhere(filled)]
    Gr.add_nodes_from(coords)
    for c in coords:
        for d in range(lab.ndim):
            o = list(c)
            o[d] += 1
            if tuple(o) in Gr:
                Gr.add_edge(c, tuple(o))
    out = []
    for comp in nx.connected_components(Gr):
        cells = sorted(comp)
        arr = np.array(cells)
        lo, hi = arr.min(axis=0), arr.max(axis=0)
        if (lo == 0).any() or (hi == np.array(lab.shape) - 1).any():
            continue  # touches the example's border: its outside is unknown
        out.append(EnclosedSet(tuple(cells), tuple(int(v) for v in hi - lo + 1)))
    out.sort(key=lambda h: math.prod(h.extent))
    return out


def lower_bound_3_2_1(example: Any, shape: Sequence[int], empty: int = 0) -> int:
    """Theorem 3.2.1's bound ``2^(prod floor(n_d / (h_d + 1)))`` for the best enclosed set
    H of ``example`` (1 when there is none: the all-empty model)."""
    best = 0
    for h in enclosed_sets(example, empty):
        ext = list(h.extent) + [1] * (len(shape) - len(h.extent))
        copies = math.prod(int(n) // (e + 1) for n, e in zip(shape, ext, strict=False))
        best = max(best, int(copies))
    return int(2**best)


def entropy_per_cell(
    example: Any,
    width: Sequence[int],
    lengths: tuple[int, int] = (8, 16),
    *,
    method: str = "transfer",
    periodic: bool = False,
    **kw: Any,
) -> dict[str, Any]:
    """Growth rate of ``D_E`` on strips: ``(log2 D(w, L2) - log2 D(w, L1)) / (|w| (L2 - L1))``
    bits per cell, for models of cross-section ``width`` (all axes but the last) and
    lengths ``L1 < L2`` along the last axis. As ``L`` grows this tends to the strip's
    entropy per cell (``log2`` of the largest transfer-matrix eigenvalue over ``|w|``), and
    as the width grows to the example's entropy per cell.
    """
    L1, L2 = lengths
    if not 1 <= L1 < L2:
        raise InputError("lengths must be two increasing positive integers")
    w = tuple(int(v) for v in width)

    def strip(length: int) -> Problem:
        if isinstance(example, RuleSet):  # a tileset's rules (its domain rules, no boundary)
            return example.problem((*w, length), periodic=periodic, boundary="none")
        return from_example(example, (*w, length), periodic=periodic)

    c1 = count_solutions(strip(L1), method, **kw)
    c2 = count_solutions(strip(L2), method, **kw)
    cells = math.prod(w)
    if int(c1) == 0 or int(c2) == 0:
        rate = float("-inf")
    else:
        rate = (c2.log2() - c1.log2()) / (cells * (L2 - L1))
    return {"width": w, "lengths": (L1, L2), "counts": (int(c1), int(c2)), "bits_per_cell": rate}
