"""Global constraints beside the binary arcs: count, connected, symmetric, separation, max-run.

A :class:`~csplab.problem.Problem` carries them in ``problem.constraints``;
:meth:`Problem.violations <csplab.problem.Problem.violations>` checks them (it stays the one
checker), and every solver says what it does with each kind (the ``constraints`` entry of
its declaration, :mod:`csplab.solvers.base`): ``exact`` solvers encode them (CNF clauses and
counters or adders for counts, a lazy cut loop for connectivity), ``propagated`` ones prune domains
with :meth:`Constraint.propagate` during search, ``checked`` ones test the finished grid and
report ``failed`` (so ``--restarts`` retries) instead of a broken ``solved``.

=============  ==========================================================================
kind           meaning
=============  ==========================================================================
``count``      the number of cells (of a box ``region``, default all) whose label is in
               ``labels`` lies in ``[min, max]``
``connected``  the cells whose label is in ``labels`` form one connected component of the
               grid's axis neighbourhood (4 in 2D, 6 in 3D; periodic axes wrap), and
               contain ``cells``; with ``ports`` two such cells connect only through faces
               both labels open (DeBroglie's ``edgedPath``)
``mirror``     the output equals its mirror image along ``axis`` under a label map
``rotate``     the output equals its rotation by ``turns`` quarter turns under a label map
``separation`` two cells with labels in ``labels`` are at least ``distance`` apart
               (Manhattan distance; DeBroglie's ``separation``)
``max-run``    at most ``n`` consecutive cells with labels in ``labels`` along each axis
               of ``axes`` (DeBroglie's ``maxConsecutive``)
=============  ==========================================================================

The constraints file (``csplab synthesize ... --constraints FILE``; read by
:func:`csplab.io.constraints.read_constraints`)::

    {"constraints": [
      {"type": "count", "labels": ["cross 0", "cross 1"], "min": 0, "max": 2,
       "region": {"from": [0, 0], "to": [9, 9]}},
      {"type": "connected", "labels": ["road", 3], "cells": [[0, 0], [-1, -1]]},
      {"type": "mirror", "axis": "x"},
      {"type": "rotate", "turns": 2},
      {"type": "separation", "labels": ["tower"], "distance": 4},
      {"type": "max-run", "labels": ["wall"], "n": 5, "axes": ["x"]}
    ]}

Labels are names or ids (a tile's name without orientation, ``"corner"``, names all its
orientations ``"corner 0"`` ... ``"corner 3"``); coordinates are grid coordinates
(``x, y[, z]``), negative ones count from the end as in Python (``-1`` is the last);
``region`` corners are inclusive. A
mirror or rotation without ``map`` uses the tileset's own symmetry (the label each tile
becomes when the tileset's symmetry group turns it) and the identity for example models.

Examples
--------
>>> import numpy as np
>>> from csplab import ExampleModel, from_example
>>> P = from_example(ExampleModel([[0, 0, 1], [1, 0, 0], [0, 1, 0]]), (4, 4))
>>> P = P.with_constraints([Count([1], min=2, max=2)])
>>> g = np.zeros((4, 4), dtype=int)
>>> g[0, 0] = 1
>>> P.violations(g).constraints
('count of {1} is 1, outside [2, 2]',)
"""

from __future__ import annotations

import itertools
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from csplab import _kernels as kern
from csplab.errors import FormatError, InputError

if TYPE_CHECKING:
    from csplab.problem import Problem

__all__ = [
    "KINDS",
    "ClauseContext",
    "Connected",
    "Constraint",
    "Count",
    "MaxRun",
    "Separation",
    "Symmetric",
    "adder_card",
    "arc_pairs",
    "constraints_json",
    "grid_coords",
    "grid_csr",
    "grid_edges",
    "label_mask",
    "mirror",
    "parse_constraints",
    "propagate_all",
    "rotate",
    "seqcounter",
]

#: the kinds of the constraints file, in the order of the module docstring
KINDS = ("count", "connected", "mirror", "rotate", "separation", "max-run")
_AXES = "xyzw"

Lit = int | bool
#: registers (cells x bound) up to which a count is a sequential counter, else an adder
#: (a counter of 2 million registers took 8 s to build and load at 16x16x6, one of 20
#: million over 60 s at 24x24x8)
_COUNTER_MAX = 1_000_000


# ----------------------------------------------------------------------------- helpers


def label_mask(labels: Sequence[int], K: int) -> NDArray[np.bool_]:
    """Bool ``(K,)``: ``True`` at ``labels``."""
    m = np.zeros(K, dtype=bool)
    m[list(labels)] = True
    return m


def _set_name(problem: Problem, labels: Sequence[int]) -> str:
    """``{a, b, c}``; long sets shortened to their first labels and their size."""
    names = [problem.label_name(int(b)) for b in labels]
    if len(names) > 6:
        return "{" + ", ".join(names[:3]) + f", ... ({len(names)} labels)}}"
    return "{" + ", ".join(names) + "}"


def _need_grid(problem: Problem, what: str, square: bool = False) -> None:
    """One line when ``what`` cannot live on ``problem``: cells at positions, or (for the
    kinds that use axis geometry: offsets, runs, mirror images, faces) a hexagonal or
    triangular grid."""
    if problem.positions is not None:
        raise InputError(f"{what} needs a grid problem (this one has cells at positions)")
    topo = str(problem.meta.get("topology", "square"))
    if square and topo.startswith(("hex", "tri")):
        raise InputError(f"{what} needs a square grid (this one is {topo})")


def grid_edges(problem: Problem) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """The axis neighbours of a grid problem as ``(lo, hi, axis)``: ``hi`` is ``lo``'s ``+1``
    neighbour along ``axis`` (periodic axes wrap), taken from the problem's arcs (so only
    neighbours the problem relates are neighbours); each pair once. On a hexagonal or
    triangular grid (:mod:`csplab.topology`) every arc joins neighbours: ``axis`` is then
    its relation."""
    cached = problem.__dict__.get("_grid_edges")
    if cached is not None:
        return cached  # type: ignore[no-any-return]
    a = problem.arcs
    a = a[a[:, 0] != a[:, 1]]
    if str(problem.meta.get("topology", "square")).startswith(("hex", "tri")):
        trip = np.unique(a, axis=0) if a.size else np.zeros((0, 3), np.int64)
        out = tuple(np.ascontiguousarray(trip[:, i], dtype=np.int64) for i in range(3))
        problem.__dict__["_grid_edges"] = out
        return out  # type: ignore[return-value]
    shp = np.array(problem.shape, dtype=np.int64)
    cs = np.stack(np.unravel_index(a[:, 0], problem.shape), axis=1)
    cd = np.stack(np.unravel_index(a[:, 1], problem.shape), axis=1)
    diff = (cd - cs) % shp
    nz = (diff != 0).sum(axis=1) == 1
    axis = np.argmax(diff != 0, axis=1)
    step = diff[np.arange(len(a)), axis]
    fwd = nz & (step == 1)
    bwd = nz & (step == shp[axis] - 1) & ~fwd
    lo = np.concatenate([a[fwd, 0], a[bwd, 1]])
    hi = np.concatenate([a[fwd, 1], a[bwd, 0]])
    ax = np.concatenate([axis[fwd], axis[bwd]])
    trip = np.unique(np.stack([lo, hi, ax], axis=1), axis=0) if lo.size else np.zeros((0, 3), int)
    out = (
        np.ascontiguousarray(trip[:, 0], dtype=np.int64),
        np.ascontiguousarray(trip[:, 1], dtype=np.int64),
        np.ascontiguousarray(trip[:, 2], dtype=np.int64),
    )
    problem.__dict__["_grid_edges"] = out
    return out


def grid_csr(problem: Problem) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """:func:`grid_edges` as a symmetric CSR adjacency ``(ptr, nbr)``: the neighbours of
    cell ``c`` are ``nbr[ptr[c]:ptr[c + 1]]``; computed once per problem.

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> ptr, nbr = grid_csr(from_example(ExampleModel([[0, 1], [1, 0]]), (2, 3)))
    >>> sorted(nbr[ptr[0]:ptr[1]].tolist())
    [1, 3]
    """
    cached = problem.__dict__.get("grid_csr")
    if cached is not None:
        return cached  # type: ignore[no-any-return]
    lo, hi, _ = grid_edges(problem)
    src = np.concatenate([lo, hi])
    dst = np.concatenate([hi, lo])
    o = np.argsort(src, kind="stable")
    ptr = np.zeros(problem.n + 1, dtype=np.int64)
    np.cumsum(np.bincount(src, minlength=problem.n), out=ptr[1:])
    out = (ptr, np.ascontiguousarray(dst[o], dtype=np.int64))
    problem.__dict__["grid_csr"] = out
    return out


def grid_coords(problem: Problem) -> NDArray[np.int64]:
    """The coordinates of every cell, ``(n, ndim)``, computed once per problem.

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> grid_coords(from_example(ExampleModel([[0, 1], [1, 0]]), (2, 3)))[4].tolist()
    [1, 1]
    """
    xyz = problem.__dict__.get("grid_coords")
    if xyz is None:
        xyz = np.ascontiguousarray(
            np.stack(np.unravel_index(np.arange(problem.n), problem.shape), axis=1),
            dtype=np.int64,
        )
        problem.__dict__["grid_coords"] = xyz
    return xyz


def arc_pairs(problem: Problem) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """The pairs of cells the problem's arcs join, as ``(lo, hi, relation)`` with
    ``lo < hi``, each pair once (the neighbours of a problem whose cells sit at positions)."""
    cached = problem.__dict__.get("_arc_pairs")
    if cached is not None:
        return cached  # type: ignore[no-any-return]
    a = problem.arcs
    a = a[a[:, 0] != a[:, 1]]
    trip = np.stack([np.minimum(a[:, 0], a[:, 1]), np.maximum(a[:, 0], a[:, 1]), a[:, 2]], axis=1)
    if len(trip):
        trip = trip[np.sort(np.unique(trip[:, :2], axis=0, return_index=True)[1])]
    out = tuple(np.ascontiguousarray(trip[:, i], dtype=np.int64) for i in range(3))
    problem.__dict__["_arc_pairs"] = out
    return out  # type: ignore[return-value]


class ClauseContext:
    """Clauses of the constraints of a problem over the literals of a CNF (the ``sat``,
    ``cpsat`` and ``asp`` solvers share it).

    ``lit(cell, label)`` gives a solver literal (``int``) or a constant (``True``/
    ``False``); :meth:`in_set` adds one auxiliary variable per cell and label set ("the
    label is in the set"); cardinalities are sequential counters or adders (:meth:`card`)
    unless a subclass overrides it. ``clauses`` collects the output; ``top`` is the largest
    variable used.
    """

    def __init__(self, problem: Problem, lit: Callable[[int, int], Lit], top: int) -> None:
        self.problem = problem
        self.lit = lit
        self.top = top
        self.clauses: list[list[int]] = []
        self._sets: dict[tuple[int, bytes], Lit] = {}
        self._links: dict[tuple[int, int, int], Lit] = {}
        #: literals a solver should prefer after the last :meth:`cuts` (the labels of the
        #: set negated on the cells of stray components: "try without them")
        self.hints: list[int] = []

    def new_var(self) -> int:
        self.top += 1
        return self.top

    def add(self, clause: Sequence[Lit]) -> None:
        """Add a clause whose literals may be constants (a true one drops the clause)."""
        out = []
        for x in clause:
            if x is True:
                return
            if x is False:
                continue
            out.append(int(x))
        self.clauses.append(out)  # an empty clause: unsatisfiable

    def in_set(self, cell: int, mask: NDArray[np.bool_]) -> Lit:
        """A literal true iff ``cell``'s label is in ``mask``."""
        key = (int(cell), np.packbits(mask).tobytes())
        got = self._sets.get(key)
        if got is not None:
            return got
        lits: list[int] = []
        out: Lit = False
        enc = getattr(self.lit, "__self__", None)  # an Encoding: read its arrays at once
        var, const = getattr(enc, "var", None), getattr(enc, "const", None)
        if isinstance(var, np.ndarray) and isinstance(const, np.ndarray):
            if const[cell] >= 0:
                out = bool(mask[int(const[cell])])
            else:
                row = var[cell][mask]
                lits = row[row > 0].tolist()
        else:
            for b in np.flatnonzero(mask):
                x = self.lit(int(cell), int(b))
                if x is True:
                    out = True
                    break
                if x is not False:
                    lits.append(int(x))
        if out is not True:
            if len(lits) == 1:
                out = lits[0]
            elif lits:
                out = self.define_set(int(cell), mask, lits)
        self._sets[key] = out
        return out

    def define_set(self, cell: int, mask: NDArray[np.bool_], lits: list[int]) -> Lit:
        """A new variable ``y`` for :meth:`in_set` with ``y <-> OR lits`` (the cell's
        literals of labels in ``mask``, at least two): a clause per literal and one more."""
        y = self.new_var()
        self.clauses.append([-y, *lits])
        self.clauses.extend([y, -x] for x in lits)
        return y

    def link(
        self, lo: int, hi: int, axis: int, ports: NDArray[np.bool_], S: NDArray[np.bool_]
    ) -> Lit:
        """A literal that can be true only if ``lo`` and ``hi`` (neighbours along ``axis``)
        both have labels of ``S`` that open the faces between them."""
        key = (lo, hi, axis)
        got = self._links.get(key)
        if got is not None:
            return got
        p = self.in_set(lo, S & ports[:, 2 * axis + 1])
        q = self.in_set(hi, S & ports[:, 2 * axis])
        if p is False or q is False:
            out: Lit = False
        elif p is True and q is True:
            out = True
        else:
            v = self.new_var()
            for x in (p, q):
                if x is not True:
                    self.clauses.append([-v, int(x)])
            out = v
        self._links[key] = out
        return out

    def card_bounds(
        self, lits: Sequence[Lit], lo: int, hi: int | None
    ) -> tuple[list[int], int, int | None] | None:
        """A count's free literals and its bounds on them (the true constants taken off),
        or None after adding the empty clause when no number of them meets the bounds."""
        fixed = sum(1 for x in lits if x is True)
        free = [int(x) for x in lits if x is not True and x is not False]
        lo, up = lo - fixed, None if hi is None else hi - fixed
        if (up is not None and up < 0) or lo > len(free):
            self.add([])
            return None
        return free, lo, up

    def card(self, lits: Sequence[Lit], lo: int, hi: int | None) -> None:
        """``lo <= (number of true lits) <= hi`` (``hi=None``: no upper bound)."""
        got = self.card_bounds(lits, lo, hi)
        if got is None:
            return
        free, lo, up = got
        n = len(free)
        big_lo = big_hi = None  # the bounds too large for a counter: one adder for both
        for bound, atmost in ((up, True), (lo, False)):
            if bound is None or (atmost and bound >= n) or (not atmost and bound <= 0):
                continue
            # the counter's registers: n * k for "at most k" (k = n - lo for "at least lo");
            # above _COUNTER_MAX the adder's O(n) clauses load faster than the counter helps
            if (bound if atmost else n - bound) * n <= _COUNTER_MAX:
                # at most `bound` of the lits, or at most n - lo of their negations
                xs = np.array(free if atmost else [-x for x in free], dtype=np.int64)
                cl, self.top = seqcounter(xs, bound if atmost else n - bound, self.top)
                self.clauses.extend(cl)
            elif atmost:
                big_hi = bound
            else:
                big_lo = bound
        if big_lo is not None or big_hi is not None:
            cl, self.top = adder_card(free, big_lo or 0, big_hi, self.top)
            self.clauses.extend(cl)

    def cuts(self, grid: NDArray[np.integer[Any]]) -> int:
        """Add clauses that exclude ``grid`` (a model of the clauses so far) where it breaks a
        constraint that is encoded lazily (connectivity); the number added."""
        lab = np.asarray(grid, dtype=np.int64).reshape(-1)
        before = len(self.clauses)
        self.hints = []
        for c in self.problem.constraints:
            c.cut(self, lab)
        return len(self.clauses) - before


def seqcounter(xs: NDArray[np.int64], k: int, top: int) -> tuple[list[list[int]], int]:
    """Sinz's sequential counter for "at most ``k`` of the literals ``xs`` are true"
    (Sinz 2005, LT_SEQ; what ``pysat.card``'s seqcounter builds, there in time quadratic in
    ``len(xs)``), built with array operations: the clauses and the new largest variable
    (register ``s[i, j]``, "at least j + 1 of ``xs[:i + 1]``", is ``top + 1 + i * k + j``).

    Examples
    --------
    >>> cl, top = seqcounter(np.array([1, 2, 3]), 1, 3)
    >>> top, len(cl)
    (5, 5)
    """
    n = len(xs)
    if k <= 0:
        return [[-int(x)] for x in xs], top
    if k >= n:
        return [], top
    s = top + 1 + np.arange((n - 1) * k, dtype=np.int64).reshape(n - 1, k)
    out: list[list[int]] = [[-int(xs[0]), int(s[0, 0])]]
    out += [[-int(v)] for v in s[0, 1:]]
    x = xs[1 : n - 1]
    prev, cur = s[:-1], s[1:]
    parts: list[NDArray[np.int64]] = [
        np.stack([-x, cur[:, 0]], axis=1),
        np.stack([-prev[:, 0], cur[:, 0]], axis=1),
        np.stack([-prev[:, 1:], cur[:, 1:]], axis=2).reshape(-1, 2),
        np.stack([-x, -prev[:, k - 1]], axis=1),
    ]
    for p in parts:
        out += p.tolist()
    if k > 1:
        three = np.stack([np.repeat(-x, k - 1), -prev[:, :-1].reshape(-1), cur[:, 1:].reshape(-1)],
                         axis=1)  # fmt: skip
        out += three.tolist()
    out.append([-int(xs[n - 1]), -int(s[n - 2, k - 1])])
    return out, top + (n - 1) * k


def adder_card(xs: Sequence[int], lo: int, hi: int | None, top: int) -> tuple[list[list[int]], int]:
    """``lo <= (number of true xs) <= hi`` as a tree of binary adders (Warners 1998: the
    count as a binary number, O(n) clauses and variables, where counters and sorting
    networks need O(n k) or O(n log² k) for a bound k in the thousands) and a comparison of
    the number with the bounds; the clauses and the new largest variable.

    Examples
    --------
    >>> cl, top = adder_card([1, 2, 3], 1, 2, 3)
    >>> top > 3 and len(cl) > 0
    True
    """
    out: list[list[int]] = []
    nxt = top

    def new() -> int:
        nonlocal nxt
        nxt += 1
        return nxt

    def add(a: list[int], b: list[int]) -> list[int]:
        res: list[int] = []
        carry = 0
        for i in range(max(len(a), len(b))):
            ins = [v for v in (a[i] if i < len(a) else 0, b[i] if i < len(b) else 0, carry) if v]
            if len(ins) == 1:
                res.append(ins[0])
                carry = 0
                continue
            sm, c = new(), new()
            if len(ins) == 2:
                x, y = ins
                out.extend([[-x, -y, -sm], [x, y, -sm], [x, -y, sm], [-x, y, sm],
                            [-c, x], [-c, y], [c, -x, -y]])  # fmt: skip
            else:
                x, y, z = ins
                for sx in (1, -1):
                    for sy in (1, -1):
                        for sz in (1, -1):
                            odd = (sx < 0) + (sy < 0) + (sz < 0)  # literals negated
                            # the clause (sx·x ∨ sy·y ∨ sz·z ∨ ±sm) fixes sm's parity
                            out.append([sx * x, sy * y, sz * z, sm if odd % 2 else -sm])
                out.extend([[-x, -y, c], [-x, -z, c], [-y, -z, c],
                            [x, y, -c], [x, z, -c], [y, z, -c]])  # fmt: skip
            res.append(sm)
            carry = c
        if carry:
            res.append(carry)
        return res

    nums: list[list[int]] = [[int(x)] for x in xs]
    if not nums:
        return ([[]] if lo > 0 else []), top
    while len(nums) > 1:
        nums = [add(nums[i], nums[i + 1]) if i + 1 < len(nums) else nums[i]
                for i in range(0, len(nums), 2)]  # fmt: skip
    bits = nums[0]
    w = len(bits)
    if hi is not None:
        if hi < 0:
            return [[]], nxt
        B = [(hi >> i) & 1 for i in range(w)]
        if hi < (1 << w):
            for i in range(w):
                if not B[i]:
                    out.append([-bits[i]] + [-bits[j] for j in range(i + 1, w) if B[j]])
    if lo > 0:
        if lo >= (1 << w):
            return [[]], nxt
        L = [(lo >> i) & 1 for i in range(w)]
        for i in range(w):
            if L[i]:
                out.append([bits[i]] + [bits[j] for j in range(i + 1, w) if not L[j]])
    return out, nxt


def constraint_clauses(problem: Problem, lit: Callable[[int, int], Lit], top: int) -> ClauseContext:
    """A :class:`ClauseContext` holding the clauses of every constraint of ``problem``."""
    ctx = ClauseContext(problem, lit, top)
    for c in problem.constraints:
        c.clauses(ctx)
    return ctx


def propagate_all(
    problem: Problem, dom: NDArray[np.bool_], why: list[str] | None = None
) -> NDArray[np.bool_] | None:
    """The domains ``dom`` (bool ``(n, K)``, not changed) pruned by every constraint's
    propagator until none prunes more; ``None`` when one proves that no completion exists
    (then ``why``, if given, receives that constraint's description)."""
    d = np.array(dom, dtype=bool)
    for _ in range(100):
        before = d.copy()
        for c in problem.constraints:
            if not c.propagate(problem, d) or not d.any(axis=1).all():
                if why is not None:
                    why.append(c.describe(problem))
                return None
        if np.array_equal(d, before):
            break
    return d


# ----------------------------------------------------------------------------- constraints


class Constraint(ABC):
    """One global constraint (see the module docstring for the kinds)."""

    kind: ClassVar[str]

    @abstractmethod
    def validate(self, problem: Problem) -> None:
        """Raise :class:`InputError` when the constraint does not fit ``problem``."""

    @abstractmethod
    def check(self, problem: Problem, lab: NDArray[np.int64]) -> str | None:
        """What a complete grid (flat labels, all in range) breaks, or ``None``."""

    def excess(self, problem: Problem, lab: NDArray[np.int64]) -> float:
        """How far a complete grid is from satisfying the constraint (0 when it does): a
        count of cells or pairs, the energy modify in blocks repairs with."""
        return 0.0 if self.check(problem, lab) is None else 1.0

    @abstractmethod
    def propagate(self, problem: Problem, dom: NDArray[np.bool_]) -> bool:
        """Remove from ``dom`` (in place) labels no solution can have; ``False`` when none
        exists. Complete on assigned domains: a grid the check rejects gives ``False``."""

    @abstractmethod
    def clauses(self, ctx: ClauseContext) -> None:
        """Add the constraint's clauses to ``ctx`` (lazy parts in :meth:`cut`)."""

    def cut(self, ctx: ClauseContext, lab: NDArray[np.int64]) -> None:  # noqa: B027
        """Add clauses excluding ``lab`` where the eager clauses let a breach through."""

    def set_labels(self, problem: Problem) -> NDArray[np.bool_] | None:
        """The label set ``S`` (bool ``(K,)``) when this constraint's propagator reads only
        which cells may and which must take a label of ``S`` (:meth:`prune_sets`), so a
        packed catalog needs no unpacking; ``None`` otherwise (then :meth:`propagate`)."""
        return None

    def prune_sets(
        self, problem: Problem, can: NDArray[np.bool_], must: NDArray[np.bool_]
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]] | None:
        """:meth:`propagate` for a constraint with :meth:`set_labels`: from ``can`` and
        ``must`` (bool ``(n,)``: may / must the cell take a label of ``S``; ``must`` may be
        changed) the cells that leave ``S`` and the cells restricted to ``S``; ``None`` when
        no completion exists."""
        raise NotImplementedError(f"{self.kind} has no set propagator")

    def prunes_nothing_new(
        self,
        problem: Problem,
        can: NDArray[np.bool_],
        must: NDArray[np.bool_],
        last: tuple[NDArray[np.bool_], NDArray[np.bool_]],
    ) -> bool:
        """Whether :meth:`prune_sets` needs no new run on ``can``/``must`` after one on
        ``last`` found nothing to prune, judged from the cells that changed (a catalog
        that only shrinks); ``False`` (run it) unless a kind knows better."""
        return bool(np.array_equal(can, last[0]) and np.array_equal(must, last[1]))

    @abstractmethod
    def describe(self, problem: Problem) -> str:
        """One line for reports."""

    @abstractmethod
    def to_json(self, problem: Problem) -> dict[str, Any]:
        """The constraints-file entry (labels by name where the problem has names)."""


def _labels_json(problem: Problem, labels: Sequence[int]) -> list[Any]:
    return [problem.names[b] if problem.names else int(b) for b in labels]


@dataclass(frozen=True, eq=False)
class Count(Constraint):
    """The number of cells (of ``region``, inclusive ``(lo, hi)`` per axis; default all)
    whose label is in ``labels`` lies in ``[min, max]`` (``max=None``: no upper bound)."""

    labels: Sequence[int]
    min: int = 0
    max: int | None = None
    region: Sequence[tuple[int, int]] | None = None
    kind: ClassVar[str] = "count"

    def cells(self, problem: Problem) -> NDArray[np.int64]:
        idx = np.arange(problem.n, dtype=np.int64).reshape(problem.shape)
        if self.region is None:
            return idx.ravel()
        return idx[tuple(slice(a, b + 1) for a, b in self.region)].ravel()

    def validate(self, problem: Problem) -> None:
        _check_labels(self.labels, problem)
        if self.min < 0 or (self.max is not None and self.max < self.min):
            raise InputError(f"count bounds [{self.min}, {self.max}] are not 0 <= min <= max")
        if self.region is not None:
            if len(self.region) != problem.ndim or any(
                not 0 <= a <= b < s for (a, b), s in zip(self.region, problem.shape, strict=True)
            ):
                raise InputError(f"count region {list(self.region)} is outside {problem.shape}")

    def check(self, problem: Problem, lab: NDArray[np.int64]) -> str | None:
        k = int(np.isin(lab[self.cells(problem)], list(self.labels)).sum())
        if k < self.min or (self.max is not None and k > self.max):
            where = "" if self.region is None else f" in {list(self.region)}"
            return (
                f"count of {_set_name(problem, self.labels)}{where} is {k}, "
                f"outside [{self.min}, {'n' if self.max is None else self.max}]"
            )
        return None

    def excess(self, problem: Problem, lab: NDArray[np.int64]) -> float:
        k = int(np.isin(lab[self.cells(problem)], list(self.labels)).sum())
        return float(max(0, self.min - k) + (0 if self.max is None else max(0, k - self.max)))

    def propagate(self, problem: Problem, dom: NDArray[np.bool_]) -> bool:
        S = label_mask(self.labels, problem.K)
        cells = self.cells(problem)
        sub = dom[cells]
        can = (sub & S).any(axis=1)
        must = can & ~(sub & ~S).any(axis=1)
        nm, nc = int(must.sum()), int(can.sum())
        if nc < self.min or (self.max is not None and nm > self.max):
            return False
        open_ = cells[can & ~must]
        if self.max is not None and nm == self.max and open_.size:
            dom[open_] &= ~S
        elif nc == self.min and open_.size:
            dom[open_] &= S
        return True

    def set_labels(self, problem: Problem) -> NDArray[np.bool_] | None:
        return label_mask(self.labels, problem.K)

    def prune_sets(
        self, problem: Problem, can: NDArray[np.bool_], must: NDArray[np.bool_]
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]] | None:
        cells = None if self.region is None else self.cells(problem)
        c = can if cells is None else can[cells]
        m = must if cells is None else must[cells]
        nm, nc = int(np.count_nonzero(m)), int(np.count_nonzero(c))
        if nc < self.min or (self.max is not None and nm > self.max):
            return None
        none = np.zeros(0, dtype=np.int64)
        if nm == nc or not (nc == self.min or nm == self.max):
            return none, none
        open_ = np.flatnonzero(c & ~m)
        if cells is not None:
            open_ = cells[open_]
        if self.max is not None and nm == self.max:
            return open_.astype(np.int64), none
        return none, open_.astype(np.int64)

    def clauses(self, ctx: ClauseContext) -> None:
        S = label_mask(self.labels, ctx.problem.K)
        ctx.card([ctx.in_set(int(c), S) for c in self.cells(ctx.problem)], self.min, self.max)

    def describe(self, problem: Problem) -> str:
        where = "" if self.region is None else f" in {list(self.region)}"
        hi = "∞" if self.max is None else self.max
        return f"count {_set_name(problem, self.labels)}{where} in [{self.min}, {hi}]"

    def to_json(self, problem: Problem) -> dict[str, Any]:
        d: dict[str, Any] = {"type": "count", "labels": _labels_json(problem, self.labels),
                             "min": self.min, "max": self.max}  # fmt: skip
        if self.region is not None:
            d["region"] = {"from": [a for a, _ in self.region], "to": [b for _, b in self.region]}
        return d


@dataclass(frozen=True, eq=False)
class Connected(Constraint):
    """The cells whose label is in ``labels`` form one connected component (axis
    neighbours of the grid) containing every cell of ``cells`` (flat indices). With
    ``ports`` (bool ``(K, 2 * ndim)``, faces ``x-, x+, y-, ...``) two neighbours connect
    only when both labels open the faces between them (DeBroglie's ``edgedPath``).

    On a problem whose cells sit at positions (the CSP of continuous model synthesis,
    :mod:`csplab.continuous`) the neighbours are the cells its arcs join, and ``members``
    (bool ``(n, K)``) says which values put each cell in the set (there a value is a state,
    and the states that touch an object differ from cell to cell); ``labels`` then only
    name the set, and ``what`` describes it. ``nonempty``: at least one cell is in the set
    (one component, not none: thesis Sec. 4.6.2).

    Solvers: the CNF adds one cut per stray component and model (two cells of different
    components, and none of the first component's neighbours, cannot all hold); the
    propagator removes the labels from cells no longer reachable from a cell that must
    hold them, and forces them on cells that separate two such cells (articulation points,
    as DeBroglie's path constraint does).
    """

    labels: Sequence[int]
    cells: Sequence[int] = ()
    ports: NDArray[np.bool_] | None = field(default=None, repr=False)
    members: NDArray[np.bool_] | None = field(default=None, repr=False)
    nonempty: bool = False
    what: str = ""
    kind: ClassVar[str] = "connected"

    def validate(self, problem: Problem) -> None:
        _check_labels(self.labels, problem)
        if self.members is None:
            _need_grid(problem, "a connected constraint", square=self.ports is not None)
        elif self.ports is not None:
            raise InputError("connected: ports need a grid, not per-cell members")
        elif np.shape(self.members) != (problem.n, problem.K):
            raise InputError(f"connected: members must have shape ({problem.n}, {problem.K})")
        if any(not 0 <= c < problem.n for c in self.cells):
            raise InputError("connected: cells must be inside the grid")
        if self.ports is not None and np.shape(self.ports) != (problem.K, 2 * problem.ndim):
            raise InputError(f"connected: ports must have shape ({problem.K}, {2 * problem.ndim})")

    def mask(self, problem: Problem) -> NDArray[np.bool_]:
        """The values that put a cell in the set: ``(K,)`` for every cell alike, or the
        per-cell ``members`` ``(n, K)``."""
        if self.members is not None:
            return np.asarray(self.members, dtype=bool)
        return label_mask(self.labels, problem.K)

    def edges(self, problem: Problem) -> tuple[NDArray[np.int64], ...]:
        """The neighbour pairs ``(lo, hi, axis)``: :func:`grid_edges` on a grid, the pairs
        of cells an arc joins (``axis``: its relation) when the cells sit at positions."""
        if self.members is None:
            return grid_edges(problem)
        return arc_pairs(problem)

    def active(self, problem: Problem, lab: NDArray[np.int64]) -> NDArray[np.bool_]:
        """The cells whose label puts them in the set."""
        if self.members is None:
            return np.isin(lab, list(self.labels))
        M = np.asarray(self.members, dtype=bool)
        out: NDArray[np.bool_] = (lab >= 0) & M[np.arange(problem.n), np.clip(lab, 0, None)]
        return out

    def components(self, problem: Problem, lab: NDArray[np.int64]) -> NDArray[np.int64]:
        """Component id (smallest cell) of each cell with a label in the set, -1 elsewhere."""
        lo, hi, ax = self.edges(problem)
        act = self.active(problem, lab)
        on = act[lo] & act[hi]
        if self.ports is not None:
            P = np.asarray(self.ports, dtype=bool)
            safe = np.clip(lab, 0, problem.K - 1)
            on &= P[safe[lo], 2 * ax + 1] & P[safe[hi], 2 * ax]
        return kern.components(problem.n, lo[on], hi[on], act)

    def excess(self, problem: Problem, lab: NDArray[np.int64]) -> float:
        """Cells of the set outside its largest component, plus ``n`` per missing given cell
        (and for an empty set that must not be)."""
        comp = self.components(problem, lab)
        miss = sum(1 for c in self.cells if comp[c] < 0)
        ids, sizes = np.unique(comp[comp >= 0], return_counts=True)
        miss += int(self.nonempty and not ids.size)
        return float(problem.n * miss + (sizes.sum() - sizes.max() if ids.size else 0))

    def check(self, problem: Problem, lab: NDArray[np.int64]) -> str | None:
        comp = self.components(problem, lab)
        miss = [c for c in self.cells if comp[c] < 0]
        if miss:
            return (
                f"connected {self._name(problem)}: cell {problem.coords(miss[0])} "
                f"has label {problem.label_name(int(lab[miss[0]]))}, not one of the set"
            )
        k = np.unique(comp[comp >= 0]).size
        if k > 1:
            return f"connected {self._name(problem)}: {k} components, not one"
        if k == 0 and self.nonempty:
            return f"connected {self._name(problem)}: no cell in the set, not one component"
        return None

    def propagate(self, problem: Problem, dom: NDArray[np.bool_]) -> bool:
        S = self.mask(problem)
        if len(self.cells):
            cs = list(self.cells)
            dom[cs] &= S if S.ndim == 1 else S[cs]
        can: NDArray[np.bool_] = np.asarray((dom & S).any(axis=1))
        must: NDArray[np.bool_] = np.asarray(can & ~(dom & ~S).any(axis=1))
        if self.nonempty and not can.any():
            return False
        if not must.any():
            return True
        lo, hi, ax = self.edges(problem)
        pe = can[lo] & can[hi]
        if self.ports is not None:
            P = np.asarray(self.ports, dtype=bool)
            sp = dom[lo] & S & P[:, 1::2].T[ax]
            sm = dom[hi] & S & P[:, 0::2].T[ax]
            pe &= sp.any(axis=1) & sm.any(axis=1)
        lo, hi = lo[pe], hi[pe]
        comp = kern.components(problem.n, lo, hi, can)
        roots = np.unique(comp[must])
        if roots.size > 1:
            return False
        stray = can & (comp != roots[0])
        if stray.any():
            dom[stray] &= ~S if S.ndim == 1 else ~S[stray]
            can &= ~stray
        keep = can[lo] & can[hi]
        lo, hi = lo[keep], hi[keep]
        if int(must.sum()) < 2:
            return True
        src = np.concatenate([lo, hi])
        dst = np.concatenate([hi, lo])
        o = np.argsort(src, kind="stable")
        nbr = np.ascontiguousarray(dst[o])
        ptr = np.zeros(problem.n + 1, dtype=np.int64)
        np.cumsum(np.bincount(src, minlength=problem.n), out=ptr[1:])
        res = kern.separating_cells(ptr, nbr, must, int(np.flatnonzero(must)[0]))
        force = res[:, 0] & ~must
        if force.any():
            dom[force] &= S if S.ndim == 1 else S[force]
        return True

    def set_labels(self, problem: Problem) -> NDArray[np.bool_] | None:
        if self.ports is not None or self.members is not None:
            return None
        return label_mask(self.labels, problem.K)

    def prune_sets(
        self, problem: Problem, can: NDArray[np.bool_], must: NDArray[np.bool_]
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]] | None:
        given = np.asarray(self.cells, dtype=np.int64)
        if given.size:
            if not can[given].all():
                return None
            given = given[~must[given]]
            must[given] = True
        if self.nonempty and not can.any():
            return None
        ptr, nbr = grid_csr(problem)
        ok, out, force = kern.connected_prune(ptr, nbr, can, must)
        if not ok:
            return None
        if given.size:
            force[given] = True
        return np.flatnonzero(out).astype(np.int64), np.flatnonzero(force).astype(np.int64)

    def prunes_nothing_new(
        self,
        problem: Problem,
        can: NDArray[np.bool_],
        must: NDArray[np.bool_],
        last: tuple[NDArray[np.bool_], NDArray[np.bool_]],
    ) -> bool:
        """No cell joined ``can``, the cells that left it were bypassed inside their box,
        new must cells touch old ones (:func:`csplab._kernels.connected_unchanged`): no
        cell became unreachable. Cells that now separate two must cells along a rerouted
        path are found by the next full run (the caller bounds the steps in between)."""
        ptr, nbr = grid_csr(problem)
        xyz = grid_coords(problem)
        return bool(kern.connected_unchanged(ptr, nbr, xyz, can, must, last[0], last[1]))

    def in_set(self, ctx: ClauseContext, cell: int) -> Lit:
        """The literal "``cell`` is in the set"."""
        S = self.mask(ctx.problem)
        return ctx.in_set(int(cell), S if S.ndim == 1 else S[int(cell)])

    def clauses(self, ctx: ClauseContext) -> None:
        for c in self.cells:
            ctx.add([self.in_set(ctx, int(c))])
        if self.nonempty:
            ctx.add([self.in_set(ctx, c) for c in range(ctx.problem.n)])

    def cut(self, ctx: ClauseContext, lab: NDArray[np.int64]) -> None:
        P = ctx.problem
        comp = self.components(P, lab)
        ids, sizes = np.unique(comp[comp >= 0], return_counts=True)
        if ids.size <= 1:
            return
        S = self.mask(P)
        lo, hi, ax = self.edges(P)
        big = int(ids[np.argmax(sizes)])
        t = self.in_set(ctx, big)
        for cell in np.flatnonzero((comp >= 0) & (comp != big)):
            for b in self.labels if S.ndim == 1 else np.flatnonzero(S[cell]).tolist():
                x = ctx.lit(int(cell), int(b))
                if not isinstance(x, bool):
                    ctx.hints.append(-x)
        for cid in ids:
            if cid == big:
                continue
            inside = comp == cid
            clause: list[Lit] = [_neg(self.in_set(ctx, int(cid))), _neg(t)]
            cross = inside[lo] != inside[hi]
            if self.ports is None:
                out = np.unique(np.where(inside[lo[cross]], hi[cross], lo[cross]))
                clause += [self.in_set(ctx, int(w)) for w in out]
            else:
                Pt = np.asarray(self.ports, dtype=bool)
                clause += [
                    ctx.link(int(a), int(b), int(x), Pt, S)
                    for a, b, x in zip(lo[cross], hi[cross], ax[cross], strict=True)
                ]
            ctx.add(clause)

    def _name(self, problem: Problem) -> str:
        return self.what or _set_name(problem, self.labels)

    def describe(self, problem: Problem) -> str:
        at = f" through {len(self.cells)} given cells" if len(self.cells) else ""
        how = " (through open tile edges)" if self.ports is not None else ""
        some = ", at least one cell" if self.nonempty else ""
        return f"connected {self._name(problem)}{at}{how}{some}"

    def to_json(self, problem: Problem) -> dict[str, Any]:
        if self.members is not None:
            raise InputError(f"connected {self._name(problem)}: per-cell members have no file form")
        d: dict[str, Any] = {"type": "connected", "labels": _labels_json(problem, self.labels)}
        if len(self.cells):
            d["cells"] = [list(problem.coords(c)) for c in self.cells]
        if self.ports is not None:
            faces = [f"{a}{s}" for a in _AXES[: problem.ndim] for s in "-+"]
            d["ports"] = {
                (problem.names[b] if problem.names else str(b)): [
                    f for f, o in zip(faces, np.asarray(self.ports)[b], strict=True) if o
                ]
                for b in self.labels
            }
        if self.nonempty:
            d["nonempty"] = True
        return d


def _neg(x: Lit) -> Lit:
    return (not x) if isinstance(x, bool) else -x


@dataclass(frozen=True, eq=False)
class Symmetric(Constraint):
    """The output equals its image under a grid symmetry ``matrix`` (a signed permutation
    of the axes about the grid's centre) with labels mapped by ``label_map``:
    ``M[g(p)] = label_map[M[p]]`` for every cell ``p`` (thesis Sec. 3.5.2).
    Build one with :func:`mirror` or :func:`rotate`."""

    matrix: NDArray[np.int64]
    label_map: NDArray[np.int64]
    name: str = "symmetric"
    spec: Mapping[str, Any] = field(default_factory=dict)
    kind: ClassVar[str] = "symmetric"

    def perm(self, problem: Problem) -> NDArray[np.int64]:
        """The image cell of every cell."""
        M = np.asarray(self.matrix, dtype=np.int64)
        s = np.array(problem.shape, dtype=np.int64)
        p = np.stack(np.unravel_index(np.arange(problem.n), problem.shape), axis=1)
        q = ((2 * p - (s - 1)) @ M.T + (s - 1)) // 2
        return np.asarray(np.ravel_multi_index(tuple(q.T), problem.shape), dtype=np.int64)

    def validate(self, problem: Problem) -> None:
        _need_grid(problem, f"a {self.name} constraint", square=True)
        M = np.asarray(self.matrix)
        if M.shape != (problem.ndim, problem.ndim):
            raise InputError(f"{self.name}: the grid has {problem.ndim} axes")
        s = np.array(problem.shape)
        if not np.array_equal(np.abs(M) @ s, s):
            raise InputError(f"{self.name}: the grid {problem.shape} is not square where it turns")
        m = np.asarray(self.label_map)
        if m.shape != (problem.K,) or sorted(m.tolist()) != list(range(problem.K)):
            raise InputError(
                f"{self.name}: the label map must be a permutation of the {problem.K} labels"
            )

    def check(self, problem: Problem, lab: NDArray[np.int64]) -> str | None:
        perm = self.perm(problem)
        m = np.asarray(self.label_map)
        bad = np.flatnonzero(lab[perm] != m[np.clip(lab, 0, problem.K - 1)])
        if bad.size:
            c = int(bad[0])
            return (
                f"{self.describe(problem)}: {bad.size} cells differ from their image, first "
                f"{problem.coords(c)} ({problem.label_name(int(lab[c]))}) and "
                f"{problem.coords(int(perm[c]))} ({problem.label_name(int(lab[perm[c]]))})"
            )
        return None

    def excess(self, problem: Problem, lab: NDArray[np.int64]) -> float:
        m = np.asarray(self.label_map)
        return float((lab[self.perm(problem)] != m[np.clip(lab, 0, problem.K - 1)]).sum())

    def propagate(self, problem: Problem, dom: NDArray[np.bool_]) -> bool:
        perm = self.perm(problem)
        m = np.asarray(self.label_map)
        inv = np.argsort(m)
        dom &= dom[perm][:, m]  # a at p needs m[a] at g(p)
        tmp = np.empty_like(dom)
        tmp[perm] = dom[:, inv]  # b at g(p) needs inv[b] at p
        dom &= tmp
        return True

    def clauses(self, ctx: ClauseContext) -> None:
        perm = self.perm(ctx.problem)
        m = np.asarray(self.label_map)
        for p in range(ctx.problem.n):
            for a in range(ctx.problem.K):
                x = ctx.lit(p, a)
                if x is not False:
                    ctx.add([_neg(x), ctx.lit(int(perm[p]), int(m[a]))])

    def describe(self, problem: Problem) -> str:
        return str(self.spec.get("text", self.name))

    def to_json(self, problem: Problem) -> dict[str, Any]:
        d = {k: v for k, v in self.spec.items() if k != "text"}
        d["map"] = {
            problem.label_name(a): problem.label_name(int(b))
            for a, b in enumerate(np.asarray(self.label_map))
            if a != b
        }
        return d


def _group_map(problem: Problem, M: NDArray[np.int64]) -> NDArray[np.int64] | None:
    """The label map of a tileset's own symmetry ``M`` (``None`` if it has none)."""
    model = problem.meta.get("model")
    sym = getattr(model, "symmetry", None)
    if sym is None:
        return None
    G, perm = sym
    for g, e in enumerate(G.elements):
        if e.shape == M.shape and np.array_equal(e, M):
            return np.asarray(perm[g], dtype=np.int64)
    return None


def _resolve_map(problem: Problem, M: NDArray[np.int64], label_map: Any) -> NDArray[np.int64]:
    if label_map is None:
        got = _group_map(problem, M)
        return np.arange(problem.K, dtype=np.int64) if got is None else got
    if isinstance(label_map, Mapping):
        m = np.arange(problem.K, dtype=np.int64)
        for a, b in label_map.items():
            ia, ib = _label_id(a, problem), _label_id(b, problem)
            m[ia], m[ib] = ib, ia
        return m
    return np.asarray(label_map, dtype=np.int64)


def mirror(problem: Problem, axis: int | str, label_map: Any = None) -> Symmetric:
    """The output equals its mirror image along ``axis``; ``label_map`` (array of ``K``
    labels, or a mapping of label pairs to swap) defaults to the tileset's own mirror
    (the identity for example models)."""
    ax = _axis(axis, problem.ndim)
    M = np.eye(problem.ndim, dtype=np.int64)
    M[ax, ax] = -1
    spec = {"type": "mirror", "axis": _AXES[ax], "text": f"mirror along {_AXES[ax]}"}
    return Symmetric(M, _resolve_map(problem, M, label_map), "mirror", spec)


def rotate(problem: Problem, turns: int = 1, axes: str = "xy", label_map: Any = None) -> Symmetric:
    """The output equals itself turned by ``turns`` quarter turns in the plane ``axes``
    (``+x`` towards ``+y`` for ``"xy"``); labels map as in :func:`mirror`."""
    if turns not in (1, 2, 3):
        raise InputError(f"rotate: turns must be 1, 2 or 3, not {turns!r}")
    if len(axes) != 2 or axes[0] == axes[1]:
        raise InputError(f"rotate: axes must name two axes such as 'xy', not {axes!r}")
    i, j = (_axis(a, problem.ndim) for a in axes)
    q = np.eye(problem.ndim, dtype=np.int64)
    q[i, i] = q[j, j] = 0
    q[j, i], q[i, j] = 1, -1
    M = np.linalg.matrix_power(q, turns).astype(np.int64)
    return Symmetric(M, _resolve_map(problem, M, label_map), "rotate",
                     {"type": "rotate", "turns": turns, "axes": axes,
                      "text": f"rotation by {90 * turns}° in {axes}"})  # fmt: skip


@dataclass(frozen=True, eq=False)
class Separation(Constraint):
    """Two different cells with labels in ``labels`` are at least ``distance`` apart
    (Manhattan distance in grid steps; periodic axes do not wrap here)."""

    labels: Sequence[int]
    distance: int
    kind: ClassVar[str] = "separation"

    def offsets(self, ndim: int) -> NDArray[np.int64]:
        """Offsets ``o`` with ``0 < |o|_1 < distance``, lexicographically positive."""
        r = range(-self.distance + 1, self.distance)
        out = [o for o in itertools.product(r, repeat=ndim)
               if 0 < sum(map(abs, o)) < self.distance and o > (0,) * ndim]  # fmt: skip
        return np.array(out, dtype=np.int64).reshape(-1, ndim)

    def validate(self, problem: Problem) -> None:
        _check_labels(self.labels, problem)
        _need_grid(problem, "a separation constraint", square=True)
        if self.distance < 1:
            raise InputError(f"separation distance must be at least 1, not {self.distance}")

    def _pairs(
        self, problem: Problem, cells: NDArray[np.int64]
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """``(c, d)`` with ``c`` in ``cells``, ``d`` at an offset (both signs) in the grid."""
        offs = self.offsets(problem.ndim)
        offs = np.concatenate([offs, -offs])
        if not offs.size or not cells.size:
            return np.zeros(0, np.int64), np.zeros(0, np.int64)
        s = np.array(problem.shape)
        p = np.stack(np.unravel_index(cells, problem.shape), axis=1)
        q = p[:, None, :] + offs[None, :, :]
        ok = ((q >= 0) & (q < s)).all(axis=2)
        src = np.broadcast_to(cells[:, None], ok.shape)[ok]
        dst = np.ravel_multi_index(tuple(q[ok].T), problem.shape).astype(np.int64)
        return src.astype(np.int64), dst

    def check(self, problem: Problem, lab: NDArray[np.int64]) -> str | None:
        act = np.flatnonzero(np.isin(lab, list(self.labels)))
        src, dst = self._pairs(problem, act)
        bad = np.isin(lab[dst], list(self.labels))
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            return (
                f"separation {_set_name(problem, self.labels)} >= {self.distance}: cells "
                f"{problem.coords(int(src[i]))} and {problem.coords(int(dst[i]))} are closer"
            )
        return None

    def excess(self, problem: Problem, lab: NDArray[np.int64]) -> float:
        act = np.flatnonzero(np.isin(lab, list(self.labels)))
        _, dst = self._pairs(problem, act)
        return float(np.isin(lab[dst], list(self.labels)).sum() / 2)

    def propagate(self, problem: Problem, dom: NDArray[np.bool_]) -> bool:
        S = label_mask(self.labels, problem.K)
        must = np.flatnonzero((dom & S).any(axis=1) & ~(dom & ~S).any(axis=1))
        _, dst = self._pairs(problem, must)
        if dst.size:
            dom[np.unique(dst)] &= ~S
        return True

    def clauses(self, ctx: ClauseContext) -> None:
        P = ctx.problem
        S = label_mask(self.labels, P.K)
        can = np.flatnonzero((P.domains & S).any(axis=1))
        s = np.array(P.shape)
        p = np.stack(np.unravel_index(can, P.shape), axis=1)
        for o in self.offsets(P.ndim):
            q = p + o
            ok = ((q >= 0) & (q < s)).all(axis=1)
            dst = np.ravel_multi_index(tuple(q[ok].T), P.shape)
            for a, b in zip(can[ok], dst, strict=True):
                ctx.add([_neg(ctx.in_set(int(a), S)), _neg(ctx.in_set(int(b), S))])

    def describe(self, problem: Problem) -> str:
        return f"separation {_set_name(problem, self.labels)} at least {self.distance} apart"

    def to_json(self, problem: Problem) -> dict[str, Any]:
        return {"type": "separation", "labels": _labels_json(problem, self.labels),
                "distance": self.distance}  # fmt: skip


@dataclass(frozen=True, eq=False)
class MaxRun(Constraint):
    """At most ``n`` consecutive cells with labels in ``labels`` along each axis of
    ``axes`` (default all; periodic axes do not wrap here)."""

    labels: Sequence[int]
    n: int
    axes: Sequence[int] | None = None
    kind: ClassVar[str] = "max-run"

    def _axes(self, problem: Problem) -> list[int]:
        return list(range(problem.ndim)) if self.axes is None else list(self.axes)

    def validate(self, problem: Problem) -> None:
        _check_labels(self.labels, problem)
        _need_grid(problem, "a max-run constraint", square=True)
        if self.n < 0:
            raise InputError(f"max-run n must be at least 0, not {self.n}")
        if any(not 0 <= a < problem.ndim for a in self._axes(problem)):
            raise InputError(f"max-run axes must be among the grid's {problem.ndim} axes")

    @staticmethod
    def _runs(act: NDArray[np.bool_], axis: int) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Per cell: the run of ``act`` ending just before it and starting just after it."""
        a = np.moveaxis(act, axis, 0)
        L = a.shape[0]
        left = np.zeros(a.shape, dtype=np.int64)
        right = np.zeros(a.shape, dtype=np.int64)
        for i in range(1, L):
            left[i] = np.where(a[i - 1], left[i - 1] + 1, 0)
        for i in range(L - 2, -1, -1):
            right[i] = np.where(a[i + 1], right[i + 1] + 1, 0)
        return np.moveaxis(left, 0, axis), np.moveaxis(right, 0, axis)

    def excess(self, problem: Problem, lab: NDArray[np.int64]) -> float:
        act = np.isin(lab, list(self.labels)).reshape(problem.shape)
        total = 0.0
        for ax in self._axes(problem):
            left, right = self._runs(act, ax)
            run = np.where(act, left + 1 + right, 0)
            total += float(np.maximum(run - self.n, 0).sum())  # each cell of a long run
        return total

    def check(self, problem: Problem, lab: NDArray[np.int64]) -> str | None:
        act = np.isin(lab, list(self.labels)).reshape(problem.shape)
        for ax in self._axes(problem):
            left, right = self._runs(act, ax)
            run = np.where(act, left + 1 + right, 0)
            if run.max(initial=0) > self.n:
                c = int(np.argmax(run.reshape(-1)))
                return (
                    f"max-run {_set_name(problem, self.labels)} <= {self.n} along "
                    f"{_AXES[ax]}: a run of {int(run.max())} through {problem.coords(c)}"
                )
        return None

    def propagate(self, problem: Problem, dom: NDArray[np.bool_]) -> bool:
        S = label_mask(self.labels, problem.K)
        can = (dom & S).any(axis=1)
        must: NDArray[np.bool_] = np.asarray(can & ~(dom & ~S).any(axis=1)).reshape(problem.shape)
        for ax in self._axes(problem):
            left, right = self._runs(must, ax)
            total = (left + 1 + right).reshape(-1)
            m = must.reshape(-1)
            if (total[m] > self.n).any():
                return False
            cut = can & ~m & (total > self.n)
            if cut.any():
                dom[cut] &= ~S
        return True

    def clauses(self, ctx: ClauseContext) -> None:
        P = ctx.problem
        S = label_mask(self.labels, P.K)
        idx = np.arange(P.n).reshape(P.shape)
        for ax in self._axes(P):
            a = np.moveaxis(idx, ax, -1).reshape(-1, P.shape[ax])
            for row in a:
                for i in range(row.size - self.n):
                    ctx.add([_neg(ctx.in_set(int(c), S)) for c in row[i : i + self.n + 1]])

    def describe(self, problem: Problem) -> str:
        along = "".join(_AXES[a] for a in self._axes(problem))
        return f"max-run {_set_name(problem, self.labels)} at most {self.n} along {along}"

    def to_json(self, problem: Problem) -> dict[str, Any]:
        d: dict[str, Any] = {"type": "max-run", "labels": _labels_json(problem, self.labels),
                             "n": self.n}  # fmt: skip
        if self.axes is not None:
            d["axes"] = [_AXES[a] for a in self.axes]
        return d


# ----------------------------------------------------------------------------- the file


def _check_labels(labels: Sequence[int], problem: Problem) -> None:
    if not len(labels):
        raise InputError("a constraint needs at least one label")
    if any(not 0 <= int(b) < problem.K for b in labels):
        raise InputError(f"constraint labels must be 0..{problem.K - 1}")


def _label_id(v: Any, problem: Problem) -> int:
    if isinstance(v, bool):
        raise InputError(f"label {v!r} is neither a name nor an id")
    if isinstance(v, int):
        if not 0 <= v < problem.K:
            raise InputError(f"label id {v} is outside 0..{problem.K - 1}")
        return v
    if isinstance(v, str):
        if problem.names is not None and v in problem.names:
            return problem.names.index(v)
        if v.lstrip("-").isdigit():
            return _label_id(int(v), problem)
        close = [nm for nm in (problem.names or ()) if nm.split(" ")[0] == v.split(" ")[0]]
        hint = f" (did you mean {', '.join(repr(c) for c in close[:4])}?)" if close else ""
        raise InputError(f"unknown label {v!r}{hint}")
    raise InputError(f"label {v!r} is neither a name nor an id")


def _label_ids(v: Any, problem: Problem) -> list[int]:
    """A label, or every orientation of a tile: ``"corner"`` names ``"corner 0"`` ...
    ``"corner 3"`` when the problem has no label called ``"corner"``."""
    if isinstance(v, str) and problem.names is not None and v not in problem.names:
        group = [i for i, nm in enumerate(problem.names) if nm.rsplit(" ", 1)[0] == v]
        if group and all(problem.names[i].rsplit(" ", 1)[-1].isdigit() for i in group):
            return group
    return [_label_id(v, problem)]


def _axis(v: Any, ndim: int) -> int:
    if isinstance(v, str) and len(v) == 1 and v in _AXES[:ndim]:
        return _AXES.index(v)
    if isinstance(v, int) and not isinstance(v, bool) and 0 <= v < ndim:
        return v
    raise InputError(f"axis {v!r} is not one of {', '.join(_AXES[:ndim])}")


def _coords(v: Any, problem: Problem) -> tuple[int, ...]:
    if (
        not isinstance(v, list | tuple)
        or len(v) != problem.ndim
        or any(isinstance(c, bool) or not isinstance(c, int) for c in v)
    ):
        raise InputError(f"cell {v!r} must be a list of {problem.ndim} integers")
    out = []
    for c, s in zip(v, problem.shape, strict=True):
        c2 = c + s if c < 0 else c
        if not 0 <= c2 < s:
            raise InputError(f"cell {list(v)} is outside the grid {problem.shape}")
        out.append(c2)
    return tuple(out)


def _int(d: Mapping[str, Any], key: str, default: Any = ...) -> Any:
    v = d.get(key, default)
    if v is ...:
        raise InputError(f"needs {key!r}")
    if v is None and default is None:
        return None
    if isinstance(v, bool) or not isinstance(v, int):
        raise InputError(f"{key!r} must be an integer, not {v!r}")
    return v


_FIELDS = {
    "count": {"labels", "min", "max", "region"},
    "connected": {"labels", "cells", "ports"},
    "mirror": {"axis", "map"},
    "rotate": {"turns", "axes", "map"},
    "separation": {"labels", "distance"},
    "max-run": {"labels", "n", "axes"},
}


def _one(c: Mapping[str, Any], problem: Problem) -> Constraint:
    typ = c.get("type")
    if typ not in _FIELDS:
        raise InputError(f"type {typ!r} is not one of {', '.join(KINDS)}")
    extra = set(c) - _FIELDS[typ] - {"type", "comment"}
    if extra:
        raise InputError(f"{typ} takes no {', '.join(sorted(map(repr, extra)))}")

    def labels() -> list[int]:
        v = c.get("labels")
        if v is None:
            raise InputError(f"{typ} needs 'labels'")
        items = v if isinstance(v, list) else [v]
        out = sorted({i for x in items for i in _label_ids(x, problem)})
        if not out:
            raise InputError(f"{typ} needs at least one label")
        return out

    con: Constraint
    if typ == "count":
        region = None
        if c.get("region") is not None:
            r = c["region"]
            if not isinstance(r, Mapping) or set(r) != {"from", "to"}:
                raise InputError('count region must be {"from": [x, y...], "to": [x, y...]}')
            a, b = _coords(r["from"], problem), _coords(r["to"], problem)
            region = tuple((min(p, q), max(p, q)) for p, q in zip(a, b, strict=True))
        con = Count(labels(), _int(c, "min", 0), _int(c, "max", None), region)
    elif typ == "connected":
        cells = tuple(problem.cell(_coords(x, problem)) for x in c.get("cells", []) or [])
        ports = None
        if c.get("ports") is not None:
            if not isinstance(c["ports"], Mapping):
                raise InputError('connected ports must be {"label": ["x-", "y+", ...]}')
            faces = [f"{a}{s}" for a in _AXES[: problem.ndim] for s in "-+"]
            ports = np.zeros((problem.K, 2 * problem.ndim), dtype=bool)
            for lab, fs in c["ports"].items():
                bid = _label_id(lab, problem)
                for f in fs if isinstance(fs, list) else [fs]:
                    if f not in faces:
                        raise InputError(f"port {f!r} is not one of {', '.join(faces)}")
                    ports[bid, faces.index(f)] = True
        con = Connected(labels(), cells, ports)
    elif typ == "mirror":
        con = mirror(problem, c.get("axis", "x"), c.get("map"))
    elif typ == "rotate":
        con = rotate(problem, _int(c, "turns", 1), str(c.get("axes", "xy")), c.get("map"))
    elif typ == "separation":
        con = Separation(labels(), _int(c, "distance"))
    else:
        axes = c.get("axes")
        ax = None if axes is None else sorted({_axis(a, problem.ndim) for a in axes})
        con = MaxRun(labels(), _int(c, "n"), ax)
    con.validate(problem)
    return con


def parse_constraints(data: Any, problem: Problem, source: object = None) -> list[Constraint]:
    """The constraints of a constraints-file document (``{"constraints": [...]}``, or the
    list itself) for ``problem``; a bad entry is one :class:`FormatError` naming
    ``source`` and the entry."""
    items = data.get("constraints") if isinstance(data, Mapping) else data
    if not isinstance(items, list):
        raise FormatError('a constraints file is {"constraints": [ ... ]}', path=source)
    out = []
    for i, c in enumerate(items):
        if not isinstance(c, Mapping):
            raise FormatError(f"constraints[{i}] must be an object", path=source)
        try:
            out.append(_one(c, problem))
        except InputError as e:
            typ = c.get("type", "?")
            shown = typ if isinstance(typ, str) and typ.isprintable() else repr(typ)
            what = f"constraints[{i}] ({shown})"
            raise FormatError(f"{what}: {e}", path=source) from None
    return out


def constraints_json(problem: Problem) -> dict[str, Any]:
    """The constraints file of ``problem``'s constraints (round trip of
    :func:`parse_constraints`)."""
    return {"constraints": [c.to_json(problem) for c in problem.constraints]}


def solver_note(kind: str) -> str:
    """What a solver's ``constraints`` declaration means, for tables."""
    return {
        "exact": "encoded: every output honours them, unsat is a proof",
        "propagated": "pruned during the search and checked at the end",
        "checked": "checked at the end; a breach is a failed run, retried by --restarts",
    }[kind]
