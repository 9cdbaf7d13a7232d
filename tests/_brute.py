"""Brute-force helpers for tests of small examples (exact, exhaustive, slow on big grids).

Orders: ``"figure"`` is the order of the thesis' 2D figures (left to right, then bottom to
top: x fastest); ``"scanline"`` is csplab's / Alg. 3.1's loop order (C order, x outermost).

Examples
--------
>>> import numpy as np
>>> from csplab import ExampleModel, Problem
>>> P = Problem.from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
>>> len(solutions(P))
2
>>> alg31_failure(P, "figure")[0] is None
True
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.catalog import Propagator
from csplab.problem import Problem
from csplab.testing import brute

__all__ = [
    "alg31_failure",
    "alg36_failure",
    "alg36_window_prover",
    "assign_all",
    "catalogs",
    "corner_violations",
    "flat_order",
    "satisfiable",
    "solutions",
    "successor_violations",
]


# ----------------------------------------------------------------------------- orders


def flat_order(shape: Sequence[int], order: str) -> list[int]:
    """Flat cell indices of a 2D grid in ``"figure"`` or ``"scanline"`` order."""
    nx, ny = shape
    if order == "figure":
        return [x * ny + y for y in range(ny) for x in range(nx)]
    if order == "scanline":
        return list(range(nx * ny))
    raise ValueError(order)


# ----------------------------------------------------------------------------- exact search


def assign_all(problem: Problem, assignments: dict[tuple[int, ...], int]) -> Propagator:
    """A propagated engine with ``{coords: label}`` assigned (check ``.ok``)."""
    eng = Propagator(problem)
    for c, b in assignments.items():
        if not eng.assign(problem.cell(c), int(b)):
            break
    return eng


def satisfiable(problem: Problem, eng: Propagator) -> bool:
    """Does the engine's catalog contain a complete consistent model? (MAC backtracking)"""
    if not eng.ok:
        return False
    C = eng.catalog()
    size = C.sum(axis=1)
    if (size == 1).all():
        return bool(problem.is_solution(C.argmax(axis=1).reshape(problem.shape)))
    c = int(np.where(size == 1, np.iinfo(np.int64).max, size).argmin())
    for b in np.flatnonzero(C[c]):
        e2 = eng.copy()
        if e2.assign(c, int(b)) and satisfiable(problem, e2):
            return True
    return False


def solutions(problem: Problem, limit: int | None = None) -> list[NDArray[np.int32]]:
    """Every consistent model of a small problem (MAC backtracking)."""
    return list(brute.solutions(problem, limit=limit))


def catalogs(
    problem: Problem, assignments: dict[tuple[int, ...], int]
) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """``(C, C*)`` as ``bool (n, K)`` for an incomplete model: the arc-consistent catalog and
    the exact one (label kept iff some consistent completion uses it)."""
    eng = assign_all(problem, assignments)
    C = eng.catalog()
    Cs = np.zeros_like(C)
    if not eng.ok or not satisfiable(problem, eng):
        return C, Cs
    for c in range(problem.n):
        for b in np.flatnonzero(C[c]):
            e2 = eng.copy()
            Cs[c, b] = e2.assign(c, int(b)) and satisfiable(problem, e2)
    return C, Cs


def alg31_failure(
    problem: Problem, order: str = "figure", max_states: int = 2_000_000
) -> tuple[list[tuple[tuple[int, ...], int]] | None, int]:
    """Exhaustive Alg. 3.1: try every label of the catalog at every step (cells in ``order``).

    Returns ``(choices, states)``: a choice sequence whose last assignment wipes the catalog
    out (Alg. 3.1 fails), or ``None`` if no sequence fails; ``states`` is the number of
    distinct catalogs visited (identical catalogs have identical futures).
    """
    cells = flat_order(problem.shape, order)
    seen: set[tuple[int, bytes]] = set()

    def rec(eng: Propagator, i: int, path: list[Any]) -> list[Any] | None:
        if i == len(cells):
            return None
        key = (i, eng.bits.tobytes())
        if key in seen:
            return None
        seen.add(key)
        if len(seen) > max_states:
            raise RuntimeError("too many states")
        c = cells[i]
        for b in eng.domain(c):
            e2 = eng.copy()
            p2 = [*path, (problem.coords(c), int(b))]
            if not e2.assign(c, int(b)):
                return p2
            r = rec(e2, i + 1, p2)
            if r is not None:
                return r
        return None

    eng = Propagator(problem)
    if not eng.ok:
        raise ValueError("problem is unsatisfiable")
    return rec(eng, 0, []), len(seen)


# ----------------------------------------------------------------------------- conditions


def used_labels(T: NDArray[np.bool_]) -> NDArray[np.int64]:
    return np.flatnonzero(T.any(axis=(0, 2)) | T.any(axis=(0, 1)))


def corner_violations(T: NDArray[np.bool_]) -> list[tuple[int, int, int]]:
    """Triples ``(a, b, c)`` with ``T_y(a, b)`` and ``T_x(a, c)`` but no ``d`` with
    ``T_x(b, d)`` and ``T_y(c, d)`` (the corner condition, Eq. 3.11 corrected)."""
    Tx, Ty = T[0], T[1]
    bad = []
    for a in range(Tx.shape[0]):
        for b in np.flatnonzero(Ty[a]):
            for c in np.flatnonzero(Tx[a]):
                if not np.any(Tx[b] & Ty[c]):
                    bad.append((a, int(b), int(c)))
    return bad


def successor_violations(T: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """``(axis, label)`` for used labels without any successor along that axis (such a label
    could be chosen in the first row or column and leave the next cell without a label)."""
    return [(d, int(b)) for d in range(T.shape[0]) for b in used_labels(T) if not T[d, b].any()]


# ----------------------------------------------------------------------------- Alg. 3.6


class _Regions:
    """Catalogs ``C_R`` of Alg. 3.7 for a 2D transition set, cached by window content."""

    def __init__(self, T: NDArray[np.bool_], r: tuple[int, int]) -> None:
        self.T = np.asarray(T, dtype=bool)
        self.r = r
        self.used = np.zeros(self.T.shape[1], dtype=bool)
        self.used[used_labels(self.T)] = True
        self.cat = functools.lru_cache(maxsize=None)(self._cat)

    def _cat(
        self, wshape: tuple[int, int], p: tuple[int, int], known: tuple[Any, ...]
    ) -> tuple[int, ...]:
        fixed = np.full(wshape, -1, dtype=np.int64)
        for (x, y), b in known:
            fixed[x, y] = b
        mask = np.broadcast_to(self.used, (*wshape, self.used.size))
        P = Problem.grid(wshape, self.T, fixed=fixed, mask=mask)
        eng = Propagator(P)
        return tuple(int(b) for b in eng.domain(P.cell(p))) if eng.ok else ()

    def choices(
        self, shape: tuple[int, int], p: tuple[int, int], known: dict[tuple[int, int], int]
    ) -> tuple[int, ...]:
        """``C_R`` at ``p``: the region spans ``p - 1 .. p + r - 2`` on each axis (clipped),
        and only the labels already assigned inside it are used."""
        (nx, ny), (px, py), (rx, ry) = shape, p, self.r
        x0, x1 = max(0, px - 1), min(nx - 1, px + rx - 2)
        y0, y1 = max(0, py - 1), min(ny - 1, py + ry - 2)
        inside = tuple(
            sorted(
                ((x - x0, y - y0), b)
                for (x, y), b in known.items()
                if x0 <= x <= x1 and y0 <= y <= y1
            )
        )
        return self.cat((x1 - x0 + 1, y1 - y0 + 1), (px - x0, py - y0), inside)


def _before(p: tuple[int, int], q: tuple[int, int]) -> bool:
    return (p[1], p[0]) < (q[1], q[0])  # figure order


def alg36_failure(
    T: NDArray[np.bool_], shape: tuple[int, int], r: tuple[int, int]
) -> list[tuple[tuple[int, int], int | None]] | None:
    """Exhaustive Alg. 3.6 with ``r``-regions on one output size (figure order): a choice
    sequence ending in an empty ``C_R`` (label ``None``), or ``None`` if it never fails."""
    R = _Regions(T, r)
    nx, ny = shape
    cells = [(x, y) for y in range(ny) for x in range(nx)]

    def rec(i: int, known: dict[tuple[int, int], int], path: list[Any]) -> list[Any] | None:
        if i == len(cells):
            return None
        p = cells[i]
        ch = R.choices(shape, p, known)
        if not ch:
            return [*path, (p, None)]
        for b in ch:
            known[p] = b
            res = rec(i + 1, known, [*path, (p, b)])
            del known[p]
            if res is not None:
                return res
        return None

    return rec(0, {}, [])


def alg36_window_prover(
    T: NDArray[np.bool_], r: tuple[int, int], history: tuple[int, int] = (2, 1)
) -> list[tuple[tuple[int, int], tuple[int, int], dict[tuple[int, int], int]]]:
    """Over-approximate "Alg. 3.6 with ``r``-regions never fails" for every output size.

    For a point ``q`` only its region matters. Every position of ``q`` relative to the
    left, right and bottom edges of an output is represented by a small frame: ``q``'s
    region plus ``history = (columns, rows)`` more columns to its left and rows below it.
    The frame's cells are filled in figure order with every label their own regions allow,
    labels outside the frame being unknown (treated as unassigned, so regions allow more).
    Every real run restricted to a frame is one of these runs, so if ``C_R(q)`` is never
    empty here, Alg. 3.6 never fails (with ``r_y = 2``). Returns the failures found
    (``(output shape, q, frame labels)``); spurious failures are possible.
    """
    R = _Regions(T, r)
    rx, ry = r
    if ry != 2:
        raise ValueError("only regions two rows tall are supported")
    hx, hy = history
    fails: list[tuple[tuple[int, int], tuple[int, int], dict[tuple[int, int], int]]] = []

    def rec(shape: tuple[int, int], frame: list[tuple[int, int]], i: int, known: dict) -> bool:
        p, q = frame[i], frame[-1]
        ch = R.choices(shape, p, known)
        if p == q:
            if not ch:
                fails.append((shape, q, dict(known)))
                return True
            return False
        for b in ch:
            known[p] = b
            stop = rec(shape, frame, i + 1, known)
            del known[p]
            if stop:
                return True
        return False

    for nx in range(1, hx + rx + 3):
        for qy in range(0, hy + 3):
            for qx in range(nx):
                q = (qx, qy)
                fx0, fy0, fx1 = max(0, qx - 1 - hx), max(0, qy - 1 - hy), min(nx - 1, qx + rx - 2)
                frame = [
                    (x, y)
                    for y in range(fy0, qy + 1)
                    for x in range(fx0, fx1 + 1)
                    if _before((x, y), q) or (x, y) == q
                ]
                rec((nx, qy + 1), frame, 0, {})
    return fails
