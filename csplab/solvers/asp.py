"""Solver ``asp``: answer-set programming with clingo (Karth & Smith, FDG 2017).

The program (first-order; the default grounding writes its ground instances itself)::

    1 { a(C,L) : d(C,L) } 1 :- cell(C).                       % one label per cell
    :- a(U,A), arc(U,V,R), not a(V,B) : ok(R,A,B), d(V,B).   % A has a successor
    :- a(V,B), arc(U,V,R), not a(U,A) : ok(R,A,B), d(U,A).   % B has a predecessor

``d(C,L)`` is the arc-consistent catalog of the :class:`~csplab.problem.Problem` (its
domains -- fixed cells, masks, boundary labels -- pruned by arc consistency, Alg. 3.2, as
:func:`csplab.cnf.encode` does for ``sat`` and ``cpsat``; a cell left with one label is a
constant), ``arc(U,V,R)`` its arcs and ``ok(R,A,B)`` its relations, so every grid variant
(periodic axes, extra arcs from ``add_arcs``, fixed cells, masks, boundaries) is covered.
The integrity constraints are *supports*: one per (arc direction, label), "this label has
a compatible label next to it". Answer sets and solutions correspond one to one (tested
against brute-force counts). ``supports="forward"`` keeps only the first (exact with
exactly-one, weaker propagation); ``encoding="direct"`` states one integrity constraint
per forbidden pair instead, ``:- a(U,A), a(V,B), arc(U,V,R), not ok(R,A,B).``

Grounding
---------
The ground program has one atom per (cell, label) of the catalog, a choice rule and an
at-most-one cardinality constraint per cell and one integrity constraint per support:
at 40×40×10 on the built-in examples 0.2--1.1 million atoms and 1.3--6.1 million rules
(3.6--17 million literals). ``grounding="csplab"`` (default) takes the rules from
:func:`csplab.cnf.encode` (the clauses of solver ``sat``) and streams them to clingo in
its intermediate format aspif (:func:`ground_program`); ``grounding="gringo"`` passes the
catalog, arcs and relations as facts with the program above (:func:`facts`) and lets
gringo ground it. Measured on castle 12×12×6 (864 cells, 281,000 support rules; a shared
2-core machine, ±30%):

=======================================================  =========  ====================
program                                                  grounding  clingo's solve call
=======================================================  =========  ====================
aspif written by csplab (writing + clingo parsing it)    0.3 s      0.3 s
clingo's Python backend, one ``add_rule`` per rule       0.85 s     0.5 s
gringo, support atoms ``s(V,R,A) :- a(V,B), ok(R,A,B)``  1.9 s      1.3 s (2× the rules)
gringo, conditional literals (the program above)         4.9 s      0.9 s
gringo, one constraint per forbidden pair                23 s       21 s (8.3M rules)
=======================================================  =========  ====================

At 40×40×10 forbidden pairs are out of reach (each relation allows about 200 of
K² = 4,000--14,000 pairs: 100--200 million rules; :func:`~csplab.cnf.encode` refuses them
with an :class:`~csplab.errors.InputError`), and gringo's grounding of the support program
costs 16 s for canal (auto; whole call 22 s) and 88 s for castle (none; 116 s). Time to a
40×40×10 model with the default (``benchmarks/bench_solvers.py --solvers asp --seeds 3
--time-limit 60 [--boundary auto]``, median of 3 seeds, all solved; total = encode + load +
solve seconds, where load is csplab writing the aspif and clingo parsing it, overlapped,
and solve is clasp preparing the program plus the search): none -- city 17.6 = 0.57 +
8.9 + 7.2, castle 15.4 = 0.50 + 7.3 + 6.8, canal 8.1 = 0.08 + 4.2 + 3.4; auto -- city
6.4 = 0.06 + 3.2 + 2.7, castle 7.1 = 0.07 + 3.3 + 3.4, canal 3.0 = 0.03 + 1.4 + 1.3. The
search itself takes under 1.5 s (at most a few dozen conflicts): clingo's per-rule cost of
parsing and preparing dominates, and none of clasp's preprocessing options changed it
(``--eq=0``, ``--no-init-moms``, ``--trans-ext=no``: within noise). With
``supports="forward"`` castle (none) ran 12 minutes without an answer (weak propagation;
solver ``sat`` saw the same).

Time limit and process
----------------------
clingo reads an aspif program in one piece (a second ``load`` fails: "incremental aspif
programs are not supported") and prepares it inside ``solve`` without looking at
interrupts: 4 s for the 1.7 million rules of a 30×30×8 box town. So clingo runs in a child
process (the same Python, importing only clingo, about 0.1 s to start): the program is
streamed into its standard input while csplab writes it, the child solves with clingo's
asynchronous ``solve``, ``wait(timeout)`` and ``cancel``, and reports the true atoms.
``time_limit`` covers the whole call: the child stops its search at the deadline, and is
killed 0.3 s after it if it is still parsing or preparing.

Diversity
---------
The seed comes from ``rng`` (clingo's ``--seed``); the same seed gives the same grid (one
thread). Mean fraction of cells that differ between two seeds' outputs, with the fraction
of non-empty cells in brackets, at 16×16×8 (city, canal none; castle auto):
``diversity="sign"`` (``--sign-def=rnd``: random default signs; the default,
``"auto"``, without global constraints) 0.28--0.34 (0.24--0.38); ``"label"`` (one random
catalog label per cell preferred through clasp's domain heuristic, like the decision phases
of ``sat``) 0.40--0.74 (0.45--0.92: a uniform label prefers the many non-empty labels);
``"catalog"`` (``"auto"`` under global constraints; see below) prefers the labels of a
seeded Alg. 3.1 solution (:func:`~csplab.engine.alg31.solution_hint`, as ``cpsat``'s
hint): clasp decides them without a conflict, so the output is that solution, as diverse
as Alg. 3.1's, and ``supports="auto"`` (default) then loads the forward supports only (exact
with exactly-one per cell; their weaker propagation is never used; random labels when
Alg. 3.1 fails, on both directions); ``"none"`` 0: the seed alone does not change clingo's
first answer set. ``--rand-freq=0.05`` on top of random signs added nothing
(0.27--0.38), so it is not offered. For comparison, Alg. 3.1 0.19--0.21 (0.12), ``sat``
0.49--0.51 (0.44). At 40×40×10 ``"sign"`` gives 0.23--0.50 (0.19--0.37).

Global constraints
------------------
:class:`AspContext` adds the problem's global constraints to the ground program: label
sets and other clauses as integrity constraints ("the label is in the set" defined by one
rule, :meth:`AspContext.define_set`), a count as clasp's cardinality rules
(``:- hi+1 {y}.``, ``:- not lo {y}.``), a connected set as reachability from a fixed root
(:meth:`AspContext.reach`), so answer sets and constrained solutions still correspond one
to one (tested against brute force). The label atoms are decided first (domain heuristic
level 1, ``--heuristic=Domain``): with random signs on every atom clasp also guessed
reachability atoms and rule bodies, cutting networks apart. Measured on the pipes
(knot) tileset at 128×128 (16,384 cells, 12 labels; one network through open ports, at
most 2 crossings; clingo on the written program, ``--sign-def=rnd``, a shared 2-core
machine at load 6--7, wall seconds with clasp's CPU seconds in brackets):

============================================  ======================================
program                                       clingo
============================================  ======================================
connectivity, a chosen root                   no answer in 40 s (2,265 conflicts)
count, sequential counter of clauses          solved, 7 conflicts (8.6 s with csplab)
connectivity, fixed root, random signs        no answer in 40 s (2,061 conflicts)
connectivity, fixed root, label atoms first   8.2 s (2.8 s), 0 conflicts
count, cardinality rule                       6.8 s (2.2 s), 0 conflicts
both, fixed root, label atoms first           7.4 s (2.8 s), 0 conflicts
============================================  ======================================

City 40×40×10 (boundary auto) with its non-background labels connected and 5--30 % of the
cells is not solved in 60 s: with the label atoms first clasp made 1,994 conflicts in 40 s
of search (each one closes a loop of reachability atoms over thousands of cells, against
a count over 16,000 cells); ordering the decisions outward from a random seed cell, with
the root first in that order and the cells next to the set preferred into it (domain
heuristics), gave 339--559 conflicts in 30 s and no answer either. Connectivity alone
is solved there (1,572 conflicts; a set of about 0.1 % of the cells). Hence
``diversity="auto"``: under global constraints the search starts from a seeded Alg. 3.1
solution (``"catalog"``), found by min-entropy runs that grow the one large object.

Where the time goes on City 40×40×10 with the constraints (clingo on the written program,
CPU seconds, a shared 2-core machine at load 2.5; parsing is clingo's ``load`` of the aspif,
preparing its clause set-up in ``solve``): with both directions of supports and a clause
per label defining "in the set" (3.65 M rules) parsing 3.9--4.1 s, preparing 3.2--3.5 s,
search 0.2 s (0 conflicts); the reference without constraints (2.64 M rules) 2.7 s and
2.3 s; in Python encoding 0.13 s, Alg. 3.1 0.85 s, the constraints' rules 0.46--0.57 s,
writing 0.35 s (overlapped with parsing). ``perf`` puts 70 % of parsing in clingo's hash
tables (about 1 µs a rule, whatever the order of the rules). None of ``--eq=0``,
``--sat-prepro=no``, ``--no-init-moms``, ``--configuration=frumpy`` changed the total by
more than noise (7.4--7.9 s); ``trendy`` and ``jumpy`` doubled preparing. What cut it:
forward supports only (parsing 1.8 s, preparing 1.8 s; 2.37 M rules) and "in the set" as
one rule over the cell's labels outside the set (:meth:`AspContext.define_set`; 1.92 M
rules): parent and child CPU together 5.5 s against 6.9--7.1 s for the reference. The
pipes at 128×128 pay for the start instead: an Alg. 3.1 run there takes about 2 s and the
min-entropy runs fail about half of the time (random signs alone solve it with 0 conflicts).
Finding the Alg. 3.1 solution in a thread while the program streams was tried and left
out: at load 3.4--4.6 it won on City in one series (9.2 and 7.6 s against 9.8 and 10.0 s)
and not in the next (6.7 and 10.6 s against 7.8 and 10.3 s), and Alg. 3.1, sharing the
interpreter lock with the writer, twice overran its quarter of the 35 s limit on the pipes
(14.3 and 16.0 s in all).

Status ``unsat`` comes with a proof: clingo's exhaustive search (no answer set), or an
arc-consistency wipe-out before encoding (Theorem 3.3.2). When arc consistency leaves one
label per cell, that is the solution and clingo is not started.

Examples
--------
>>> import numpy as np
>>> from csplab import ExampleModel, from_example
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (4, 5))
>>> r = AspSolver().solve(P, rng=np.random.default_rng(0), seed=0)
>>> r.status, P.is_solution(r.grid), r.stats["solver_status"]
('solved', True, 'SAT')
>>> Q = from_example(ExampleModel([[0, 1], [1, 0]]), (5, 4), periodic=True)
>>> AspSolver().solve(Q, rng=np.random.default_rng(0), seed=0).stats["proof"]
'clingo ...: no answer set (exhaustive search)'
>>> from csplab.grids import with_fixed
>>> R = with_fixed(P, {(0, 0): 0, (0, 1): 0})
>>> AspSolver().solve(R, rng=np.random.default_rng(0), seed=0).stats["proof"]
'arc-consistency wipe-out before encoding (Theorem 3.3.2)'
"""

from __future__ import annotations

import inspect
import itertools
import json
import subprocess
import sys
import tempfile
import textwrap
import threading
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab._jit import njit
from csplab.cnf import DeadlineExceeded, Encoding, encode
from csplab.constraints import ClauseContext
from csplab.deps import require
from csplab.engine.alg31 import solution_hint
from csplab.engine.sat import preferred_labels
from csplab.errors import CsplabError, InputError
from csplab.problem import Problem
from csplab.result import Result, Status
from csplab.solvers.base import TIME_LIMIT, Call, Option, Solver

__all__ = ["PROGRAM", "AspContext", "AspSolver", "facts", "ground_program"]

PROGRAM = {
    "choice": "1 { a(C,L) : d(C,L) } 1 :- cell(C).",
    "forward": ":- a(U,A), arc(U,V,R), not a(V,B) : ok(R,A,B), d(V,B).",
    "backward": ":- a(V,B), arc(U,V,R), not a(U,A) : ok(R,A,B), d(U,A).",
    "direct": ":- a(U,A), a(V,B), arc(U,V,R), not ok(R,A,B).",
    "show": "#show a/2.",
}
"""The first-order program of ``grounding="gringo"`` (see the module docstring)."""

_GRACE = 0.3  # seconds the child may run past the deadline before it is killed
_CLAUSE_CHUNK = 100_000  # integrity constraints per streamed piece
_CELL_CHUNK = 4_096  # cells per streamed piece of choice rules


# ----------------------------------------------------------------------------- aspif


@njit(cache=True, nogil=True)
def _format_lines(
    tokens: NDArray[np.int64], line_len: NDArray[np.int64], out: NDArray[np.uint8]
) -> int:
    """Write ``tokens`` as decimal text, ``line_len[i]`` tokens per line, into ``out``.

    Returns the number of bytes written (``out`` must be large enough).
    """
    pos = 0
    t = 0
    for i in range(line_len.size):
        for j in range(line_len[i]):
            x = tokens[t]
            t += 1
            if j > 0:
                out[pos] = 32
                pos += 1
            if x < 0:
                out[pos] = 45
                pos += 1
                x = -x
            nd = 1
            y = x // 10
            while y > 0:
                nd += 1
                y //= 10
            for d in range(nd - 1, -1, -1):
                out[pos + d] = 48 + x % 10
                x //= 10
            pos += nd
        out[pos] = 10
        pos += 1
    return pos


def _text(tokens: NDArray[np.int64], line_len: NDArray[np.int64]) -> bytes:
    if tokens.size == 0:
        return b""
    width = len(str(int(np.abs(tokens).max()))) + 2
    out = np.empty(tokens.size * width + line_len.size, dtype=np.uint8)
    n = _format_lines(tokens, line_len, out)
    return out[:n].tobytes()


def _cell_rules(first: NDArray[np.int64], k: NDArray[np.int64]) -> bytes:
    """Per cell with atoms ``first .. first+k-1``: the choice rule ``{a; ...}.`` and the
    at-most-one constraint ``:- 2 {a; ...}.`` (aspif lines ``1 1 k a.. 0 0`` and
    ``1 0 0 1 2 k a 1 ..``)."""
    m = k.size
    line = np.empty(2 * m, dtype=np.int64)
    line[0::2] = k + 5
    line[1::2] = 2 * k + 6
    off = np.zeros(2 * m, dtype=np.int64)
    np.cumsum(line[:-1], out=off[1:])
    tok = np.empty(int(line.sum()), dtype=np.int64)
    o1, o2 = off[0::2], off[1::2]
    cid = np.repeat(np.arange(m), k)
    j = np.arange(int(k.sum())) - np.repeat(np.cumsum(k) - k, k)
    atoms = first[cid] + j
    tok[o1], tok[o1 + 1], tok[o1 + 2] = 1, 1, k
    tok[o1[cid] + 3 + j] = atoms
    tok[o1 + 3 + k] = 0
    tok[o1 + 4 + k] = 0
    tok[o2], tok[o2 + 1], tok[o2 + 2], tok[o2 + 3], tok[o2 + 4], tok[o2 + 5] = 1, 0, 0, 1, 2, k
    tok[o2[cid] + 6 + 2 * j] = atoms
    tok[o2[cid] + 7 + 2 * j] = 1
    return _text(tok, line)


def _constraints(lits: NDArray[np.int32], starts: NDArray[np.int64], a: int, b: int) -> bytes:
    """Clauses ``a..b-1`` as integrity constraints ``:- not c1, ...`` (aspif
    ``1 0 0 0 n -c1 ...``): a clause is violated exactly when its negation holds."""
    lens = np.diff(starts[a : b + 1]).astype(np.int64)
    m = b - a
    line = lens + 5
    off = np.zeros(m, dtype=np.int64)
    np.cumsum(line[:-1], out=off[1:])
    tok = np.empty(int(line.sum()), dtype=np.int64)
    head = off[:, None] + np.arange(5)
    tok[head[:, 0]] = 1
    tok[head[:, 1:4]] = 0
    tok[head[:, 4]] = lens
    body = np.ones(tok.size, dtype=bool)
    body[head.ravel()] = False
    tok[body] = -lits[starts[a] : starts[b]].astype(np.int64)
    return _text(tok, line)


def _heuristics(atoms: NDArray[np.int64], sign: int = 1, modifier: int = 1) -> bytes:
    """``#heuristic a. [sign, sign]`` for each atom (aspif ``7 1 a sign 0 0``); with
    ``modifier=0`` ``#heuristic a. [sign, level]``."""
    m = atoms.size
    tok = np.zeros((m, 6), dtype=np.int64)
    tok[:, 0], tok[:, 1], tok[:, 2], tok[:, 3] = 7, modifier, atoms, sign
    return _text(tok.ravel(), np.full(m, 6, dtype=np.int64))


def ground_program(
    enc: Encoding,
    prefer: NDArray[np.int64] | None = None,
    ctx: AspContext | None = None,
) -> Iterator[bytes]:
    """The ground ASP program of an encoding, in aspif, as a stream of pieces.

    Atom ``i`` is CNF variable ``i`` of ``enc`` (``(cell, label)`` of the catalog, numbered
    cell by cell); constant cells have no atoms. ``prefer`` (one label per cell, -1 for
    none) adds domain-heuristic sign preferences. ``ctx`` adds the clauses of the
    problem's global constraints (:class:`AspContext`): its rules (counts, reachability),
    its auxiliary variables not defined by them as free choice atoms and every clause an
    integrity constraint, so answer sets are exactly the models of the clauses and rules.

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> from csplab.cnf import encode
    >>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (1, 2))
    >>> print(b"".join(ground_program(encode(P))).decode(), end="")
    asp 1 0 0
    1 1 2 1 2 0 0
    1 0 0 1 2 2 1 1 2 1
    1 1 2 3 4 0 0
    1 0 0 1 2 2 3 1 4 1
    1 0 0 0 2 1 -4
    1 0 0 0 2 2 -3
    1 0 0 0 2 3 -2
    1 0 0 0 2 4 -1
    1 0 0 0 2 -1 -2
    1 0 0 0 2 -3 -4
    0
    """
    yield b"asp 1 0 0\n"
    has = enc.var > 0
    k_all = has.sum(axis=1).astype(np.int64)
    cells = np.flatnonzero(k_all > 0)
    k = k_all[cells]
    first = np.cumsum(k) - k + 1
    for a in range(0, cells.size, _CELL_CHUNK):
        yield _cell_rules(first[a : a + _CELL_CHUNK], k[a : a + _CELL_CHUNK])
    for a in range(0, enc.nclauses, _CLAUSE_CHUNK):
        yield _constraints(enc.lits, enc.starts, a, min(a + _CLAUSE_CHUNK, enc.nclauses))
    if ctx is not None:
        if ctx.rules:
            yield ("\n".join(ctx.rules) + "\n").encode()
        aux = np.arange(enc.nvars + 1, ctx.top + 1, dtype=np.int64)
        aux = aux[~np.isin(aux, np.asarray(ctx.defined, dtype=np.int64))]
        if aux.size:  # {a1; ...; am}.
            yield f"1 1 {aux.size} {' '.join(map(str, aux.tolist()))} 0 0\n".encode()
        lits = np.fromiter(itertools.chain.from_iterable(ctx.clauses), np.int32)
        lens = np.array([len(c) for c in ctx.clauses], dtype=np.int64)
        starts = np.zeros(lens.size + 1, dtype=np.int64)
        np.cumsum(lens, out=starts[1:])
        for a in range(0, lens.size, _CLAUSE_CHUNK):
            yield _constraints(lits, starts, a, min(a + _CLAUSE_CHUNK, lens.size))
    if prefer is not None:
        c = cells[prefer[cells] >= 0]
        atoms = enc.var[c, prefer[c]].astype(np.int64)
        yield _heuristics(atoms[atoms > 0])
    if ctx is not None:  # label atoms first: auxiliary atoms and bodies follow from them
        yield _heuristics(np.arange(1, enc.nvars + 1, dtype=np.int64), 1, modifier=0)
    if ctx is not None and ctx.hints:  # after a cut: try the stray cells without the set
        yield _heuristics(-np.asarray(ctx.hints, dtype=np.int64), sign=-1)
    yield b"0\n"


class AspContext(ClauseContext):
    """The global constraints of a problem as ASP rules over the atoms of an encoding.

    Clauses (label sets, links, cuts) become integrity constraints over free choice atoms
    as in :class:`~csplab.constraints.ClauseContext`; a count becomes clasp's native
    cardinality rules, ``:- hi+1 {y}.`` and ``:- not lo {y}.`` (:meth:`card`), and every
    :class:`~csplab.constraints.Connected` reachability rules (:meth:`reach`). ``rules``
    holds their aspif lines, ``defined`` the atoms they define (not free choices).

    Parameters
    ----------
    problem : Problem
        The problem whose constraints are encoded.
    lit : callable
        ``lit(cell, label)``: the atom of a label (or a constant ``True``/``False``).
    top : int
        The largest atom used so far.

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> from csplab.cnf import encode
    >>> from csplab.constraints import Count
    >>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (1, 3))
    >>> enc = encode(P)
    >>> ctx = AspContext(P, enc.literal, enc.nvars)
    >>> ctx.card([1, 3, 5], 1, 2)
    >>> ctx.rules
    ['1 0 0 1 3 3 1 1 3 1 5 1', '1 0 1 7 1 1 3 1 1 3 1 5 1', '1 0 0 0 1 -7']
    """

    def __init__(self, problem: Problem, lit: Any, top: int) -> None:
        super().__init__(problem, lit, top)
        self.rules: list[str] = []
        self.defined: list[int] = []

    @classmethod
    def of(cls, problem: Problem, enc: Encoding) -> AspContext:
        """The clauses and rules of every global constraint of ``problem`` over the atoms
        of its encoding ``enc``."""
        ctx = cls(problem, enc.literal, enc.nvars)
        for con in problem.constraints:
            con.clauses(ctx)
        ctx.reach()
        return ctx

    def _atom(self) -> int:
        x = self.new_var()
        self.defined.append(x)
        return x

    def define_set(self, cell: int, mask: NDArray[np.bool_], lits: list[int]) -> Any:
        """The literal "the label of ``cell`` is in ``mask``" as ``y :- not c1, ..., not cm``
        over the cell's atoms outside ``mask``: the choice rule gives the cell exactly one label, so
        none of those is one of ``lits``. One rule where a clause per label defines it
        otherwise (City 40x40x10: 2 atoms outside the set of non-background labels, about
        26 in it); the literal ``not c1`` itself when ``m = 1``."""
        enc = getattr(self.lit, "__self__", None)
        var = getattr(enc, "var", None)
        if not isinstance(var, np.ndarray):
            return super().define_set(cell, mask, lits)
        out = var[cell][~mask]
        out = out[out > 0]
        if out.size <= 1:  # every label of the cell is in mask, or all but one
            return True if out.size == 0 else -int(out[0])
        y = self._atom()
        self.rules.append(f"1 0 1 {y} 0 {out.size} " + " ".join(map(str, (-out).tolist())))
        return y

    def card(self, lits: Any, lo: int, hi: int | None) -> None:
        """``lo <= (number of true lits) <= hi`` as cardinality rules (clasp propagates
        them as one constraint each, where a counter or adder of clauses propagates weakly
        and loads O(n) or O(n k) rules)."""
        got = self.card_bounds(lits, lo, hi)
        if got is None:
            return
        free, lo, up = got
        body = f"{len(free)} " + " ".join(f"{x} 1" for x in free)
        if up is not None and up < len(free):
            self.rules.append(f"1 0 0 1 {up + 1} {body}")  # :- up+1 {free}.
        if lo > 0:
            g = self._atom()
            self.rules.append(f"1 0 1 {g} 1 {lo} {body}")  # g :- lo {free}.
            self.rules.append(f"1 0 0 0 1 -{g}")  # :- not g.

    def reach(self) -> None:
        """Connectivity the ASP way, for every :class:`~csplab.constraints.Connected` of
        the problem: a root ``h(r)``, reachability ``h(v) :- h(u), link(u, v)`` along the
        axis neighbours (through open ports for ``edgedPath``) and ``:- y(c), not h(c)``.
        Stable models make ``h`` the least fixpoint, so the answer sets are exactly the
        connected grids: no cut loop. The root is fixed, not chosen (no symmetric answer
        sets): a cell that must be in the set, else the first cell of the set in scan order,
        ``h(c) :- y(c), not b(c)`` with ``b(c)`` "a cell before ``c`` is in the set"."""
        from csplab.constraints import Connected

        P = self.problem
        for con in P.constraints:
            if not isinstance(con, Connected):
                continue
            S = con.mask(P)
            y = [con.in_set(self, c) for c in range(P.n)]
            h = np.zeros(P.n, dtype=np.int64)
            cand = [c for c in range(P.n) if y[c] is not False]
            for c in cand:
                h[c] = self._atom()
            must = [c for c in cand if y[c] is True]
            if must:
                self.rules.append(f"1 0 1 {h[must[0]]} 0 0")  # h(root).
            before = 0
            for i, c in enumerate(cand if not must else ()):
                yc = int(y[c])
                if before:
                    self.rules.append(f"1 0 1 {h[c]} 0 2 {yc} -{before}")  # h(c) :- y(c), not b(c).
                else:
                    self.rules.append(f"1 0 1 {h[c]} 0 1 {yc}")
                if i + 1 < len(cand):  # b(next) :- y(c).  b(next) :- b(c).
                    b = self._atom()
                    self.rules.append(f"1 0 1 {b} 0 1 {yc}")
                    if before:
                        self.rules.append(f"1 0 1 {b} 0 1 {before}")
                    before = b
            for c in cand:
                if y[c] is True:
                    self.rules.append(f"1 0 0 0 1 -{h[c]}")  # :- not h(c).
                else:
                    self.rules.append(f"1 0 0 0 2 {int(y[c])} -{h[c]}")  # :- y(c), not h(c).
            lo, hi, ax = con.edges(P)
            ports = None if con.ports is None else np.asarray(con.ports, dtype=bool)
            for u, v, a in zip(lo.tolist(), hi.tolist(), ax.tolist(), strict=True):
                if not (h[u] and h[v]):
                    continue
                if ports is None:  # h(u) holds only on cells of the set
                    for src, dst in ((u, v), (v, u)):
                        body = [int(h[src])] + ([] if y[dst] is True else [int(y[dst])])
                        self.rules.append(f"1 0 1 {h[dst]} 0 {len(body)} "
                                          + " ".join(map(str, body)))  # fmt: skip
                    continue
                p = self.in_set(u, S & ports[:, 2 * a + 1])
                q = self.in_set(v, S & ports[:, 2 * a])
                if p is False or q is False:
                    continue
                ends = [int(x) for x in (p, q) if x is not True]
                for src, dst in ((u, v), (v, u)):
                    lits = [int(h[src]), *ends]
                    self.rules.append(f"1 0 1 {h[dst]} 0 {len(lits)} " + " ".join(map(str, lits)))


def _grid_of(enc: Encoding, report: dict[str, Any]) -> NDArray[np.int32]:
    """The grid of an answer set read as ``atoms`` (atom i+1 is ``(cells[i], labels[i])``)."""
    grid = enc.const.copy()
    cells, labels = np.nonzero(enc.var > 0)
    idx = np.asarray(report["atoms"], dtype=np.int64) - 1
    if idx.size != np.count_nonzero(enc.const < 0):
        raise CsplabError(f"clingo's model has {idx.size} labels for the "
                          f"{np.count_nonzero(enc.const < 0)} open cells")  # fmt: skip
    grid[cells[idx]] = labels[idx]
    return grid


def facts(problem: Problem, catalog: NDArray[np.bool_], supports: str, encoding: str) -> str:
    """The facts and first-order program of ``grounding="gringo"``.

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (1, 2))
    >>> print(facts(P, P.domains, "forward", "support"))
    cell(0..1).
    d(0,(0;1)).
    d(1,(0;1)).
    arc(0,1,1).
    ok(0,0,1). ok(0,1,0). ok(1,0,1). ok(1,1,0).
    1 { a(C,L) : d(C,L) } 1 :- cell(C).
    :- a(U,A), arc(U,V,R), not a(V,B) : ok(R,A,B), d(V,B).
    #show a/2.
    """
    lines = [f"cell(0..{problem.n - 1})."]
    for c, row in enumerate(catalog):
        lab = np.flatnonzero(row)
        if lab.size:
            lines.append(f"d({c},({';'.join(map(str, lab.tolist()))})).")
    arcs = problem.arcs[problem.arcs[:, 0] != problem.arcs[:, 1]]
    lines += [f"arc({u},{v},{r})." for u, v, r in arcs.tolist()]
    lines.append(
        " ".join(f"ok({r},{x},{y})." for r, x, y in np.argwhere(problem.relations).tolist())
    )
    lines.append(PROGRAM["choice"])
    if encoding == "direct":
        lines.append(PROGRAM["direct"])
    else:
        lines.append(PROGRAM["forward"])
        if supports == "both":
            lines.append(PROGRAM["backward"])
    lines.append(PROGRAM["show"])
    return "\n".join(lines)


# ----------------------------------------------------------------------------- the child


def _clingo_child() -> None:  # pragma: no cover - runs in the child process
    """Entry point of the child: load the program from stdin, solve, print JSON.

    ``sys.argv[1]`` is the configuration: clingo ``args``, the wall-clock ``deadline``
    (or null), how to ``read`` the model (``atoms`` 1..``nx`` or the ``shown`` symbols).
    Self-contained (its source is what the child runs): stdlib and clingo only.
    """
    import json
    import sys
    import time

    out: dict[str, Any] = {"status": "UNKNOWN", "messages": []}
    try:
        import clingo

        cfg = json.loads(sys.argv[1])

        def log(code: Any, msg: str) -> None:
            if len(out["messages"]) < 10:
                out["messages"].append(msg.strip()[:500])

        ctl = clingo.Control(cfg["args"], logger=log, message_limit=10)
        ctl.load("-")
        ctl.ground([("base", [])])
        out["loaded"] = time.time()
        deadline = cfg["deadline"]
        model: dict[str, Any] = {}

        def on_model(m: Any) -> None:
            t = time.time()
            if cfg["read"] == "atoms":
                model["atoms"] = [i for i in range(1, cfg["nx"] + 1) if m.is_true(i)]
            else:
                model["pairs"] = [
                    [s.arguments[0].number, s.arguments[1].number] for s in m.symbols(shown=True)
                ]
            out["read_s"] = time.time() - t

        if deadline is None or time.time() < deadline:
            t = time.time()
            with ctl.solve(on_model=on_model, async_=True) as h:
                out["prepare_s"] = time.time() - t
                left = None if deadline is None else max(0.0, deadline - time.time())
                if not h.wait(left):
                    h.cancel()
                res = h.get()
            out["search_s"] = time.time() - t - out["prepare_s"]
            if res.satisfiable and model:
                out["status"] = "SAT"
                out.update(model)
            elif res.unsatisfiable:
                out["status"] = "UNSAT"
        st = ctl.statistics
        lp = st.get("problem", {}).get("lp", {})
        sv = st.get("solving", {}).get("solvers", {})
        out["stats"] = {
            "atoms": int(lp.get("atoms", 0)),
            "rules": int(lp.get("rules", 0)),
            "choices": int(sv.get("choices", 0)),
            "conflicts": int(sv.get("conflicts", 0)),
            "restarts": int(sv.get("restarts", 0)),
        }
    except Exception as e:
        out["status"] = "ERROR"
        out["error"] = f"{type(e).__name__}: {e}"
    sys.stdout.write(json.dumps(out))
    sys.stdout.flush()


_CHILD_SOURCE: str | None = None


def _child_source() -> str:
    global _CHILD_SOURCE
    if _CHILD_SOURCE is None:
        src = textwrap.dedent(inspect.getsource(_clingo_child))
        _CHILD_SOURCE = (
            f"# csplab solver asp: clingo child\nfrom typing import Any\n{src}\n_clingo_child()\n"
        )
    return _CHILD_SOURCE


def _run_child(
    args: list[str],
    pieces: Iterator[bytes],
    *,
    read: str,
    nx: int,
    deadline: float | None,
) -> tuple[dict[str, Any] | None, float]:
    """Run clingo in a child process on the streamed program.

    Returns the child's report (``None`` when it was killed at the deadline) and the
    wall-clock time at which csplab finished writing the program.
    """
    wall_deadline = None if deadline is None else time.time() + (deadline - time.perf_counter())
    cfg = json.dumps({"args": args, "deadline": wall_deadline, "read": read, "nx": nx})
    with tempfile.TemporaryFile() as err:
        proc = subprocess.Popen(
            [sys.executable, "-c", _child_source(), cfg],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=err,
        )
        written = [0.0]
        failure: list[BaseException] = []
        output: list[bytes] = []

        def writer() -> None:
            stdin = proc.stdin
            assert stdin is not None
            try:
                for piece in pieces:
                    try:
                        stdin.write(piece)
                    except (OSError, ValueError):  # the child died or was killed
                        return
                stdin.close()
                written[0] = time.time()
            except (OSError, ValueError):
                return
            except BaseException as e:  # building the program failed: re-raised below
                failure.append(e)
                proc.kill()

        def reader() -> None:
            assert proc.stdout is not None
            output.append(proc.stdout.read())

        threads = [threading.Thread(target=f, daemon=True) for f in (writer, reader)]
        for th in threads:
            th.start()
        killed = False
        try:
            try:
                left = None if deadline is None else deadline - time.perf_counter()
                proc.wait(None if left is None else max(0.0, left) + _GRACE)
            except subprocess.TimeoutExpired:
                proc.kill()
                killed = True
                proc.wait()
            for th in threads:
                th.join()
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        if failure:
            raise failure[0]
        if killed:
            return None, written[0]
        try:
            report: dict[str, Any] = json.loads((output[0] if output else b"").decode())
        except ValueError:
            err.seek(0)
            tail = err.read().decode(errors="replace").strip().splitlines()[-3:]
            raise CsplabError(
                f"the clingo child process exited with code {proc.returncode} without a "
                "result" + (": " + " | ".join(tail) if tail else "")
            ) from None
    return report, written[0]


# ----------------------------------------------------------------------------- solver


class AspSolver(Solver):
    """Complete: answer-set programming with clingo (choice rule + support constraints)."""

    name = "asp"
    constraints = "exact"
    complete = True
    requires = ("clingo",)
    description = "answer-set programming with clingo (Karth & Smith 2017)"
    notes = (
        "one label per cell by a choice rule, one integrity constraint per (arc, label) "
        'support (`encoding="direct"`: per forbidden pair) on the arc-consistent catalog; '
        'ground by csplab and streamed as aspif (`grounding="gringo"` grounds the '
        "first-order program); clingo runs in a child process, so `time_limit` also stops "
        "parsing; diverse outputs from `--seed` and random signs, or under global "
        "constraints from a seeded Alg. 3.1 solution (then forward supports only)"
    )
    options = (
        Option("encoding", str, "support", "integrity constraints per (arc, label) support "
               "or per forbidden pair", values=("support", "direct")),
        Option("supports", str, "auto", "support constraints in both arc directions, "
               "forward only (half; exact with exactly-one), or auto (forward when the "
               "search starts from a whole catalog solution, else both)",
               values=("auto", "both", "forward")),
        Option("grounding", str, "csplab", "ground program written by csplab (aspif) or "
               "grounded by gringo from facts", values=("csplab", "gringo")),
        Option("diversity", str, "auto", "how seeds vary the output: random default signs, "
               "a random preferred label per cell, a seeded Alg. 3.1 solution as the "
               "preferred labels (catalog; random labels when it fails), the seed alone, or "
               "auto (catalog when the problem has global constraints, else sign)",
               values=("auto", "sign", "label", "catalog", "none")),
        TIME_LIMIT,
    )  # fmt: skip

    def run(self, problem: Problem, call: Call) -> Result:
        encoding, supports, grounding, diversity = call.get(
            "encoding", "supports", "grounding", "diversity"
        )
        clingo = require("clingo", "asp", "solver 'asp'")
        if problem.constraints and grounding != "csplab":  # before any work
            raise InputError("solver 'asp': global constraints need grounding='csplab'")
        t0, deadline, rng = call.t0, call.deadline, call.rng
        cseed = int(rng.integers(2**31 - 1))
        if diversity == "auto":  # City 40x40x10 with its constraints needs the catalog start
            diversity = "catalog" if problem.constraints else "sign"
        whole, hint_s = None, 0.0  # a seeded Alg. 3.1 solution, as cpsat's hint
        if diversity == "catalog":
            t_hint = time.perf_counter()
            whole = solution_hint(problem, rng, call.remaining())
            hint_s = time.perf_counter() - t_hint
        if supports == "auto":  # from a whole solution clasp does not search: forward suffices
            supports = "forward" if whole is not None else "both"
        empty = np.full(problem.shape, -1, dtype=np.int32)
        stats: dict[str, Any] = {
            "encoding": encoding,
            "supports": supports,
            "grounding": grounding,
            "diversity": diversity,
        }

        def done(status: Status, grid: NDArray[np.int32] = empty) -> Result:
            return self.result(status, grid, problem, stats, call)

        try:
            enc = encode(problem, encoding=encoding, supports=supports, deadline=deadline)
        except DeadlineExceeded:
            return done("timeout")
        t_enc = time.perf_counter()
        stats["encode_s"] = t_enc - t0 - hint_s
        if not enc.ok:
            stats["proof"] = "arc-consistency wipe-out before encoding (Theorem 3.3.2)"
            stats["fail_cell"] = list(problem.coords(enc.wiped))
            return done("unsat")
        stats["x_vars"] = enc.nx
        if enc.nx == 0:  # arc consistency left one label per cell: that is the solution
            stats["ground_s"] = stats["encode_s"]
            stats["solve_s"] = 0.0
            broken = problem.violations(enc.const).constraints
            if broken:
                stats["proof"] = f"the only labelling arc consistency leaves breaks {broken[0]}"
                return done("unsat")
            return done("solved", enc.const.reshape(problem.shape))
        if call.expired():
            return done("timeout")

        args = ["--models=1", f"--seed={cseed}"]
        if diversity == "sign":
            args.append("--sign-def=rnd")
        prefer = whole
        if diversity == "catalog":
            stats["hint"] = "catalog solution" if prefer is not None else "random labels"
            stats["hint_s"] = hint_s
        if diversity == "label" or (diversity == "catalog" and prefer is None):
            prefer = preferred_labels(enc.catalog, None, rng)
        if prefer is not None or problem.constraints:  # preferred labels, label atoms first
            args.append("--heuristic=Domain")
        pieces: Iterator[bytes]
        ctx = None
        if problem.constraints:  # global constraints: choice atoms and integrity constraints
            ctx = AspContext.of(problem, enc)
            stats["constraint_clauses"] = len(ctx.clauses)
            stats["constraint_rules"] = len(ctx.rules)
            stats["cuts"] = 0
        if grounding == "csplab":
            pieces = ground_program(enc, prefer, ctx)
            read = "atoms"
        else:
            text = facts(problem, enc.catalog, supports, encoding)
            if prefer is not None:
                text += "\n" + " ".join(
                    f"#heuristic a({c},{b}). [1,sign]"
                    for c, b in enumerate(prefer.tolist())
                    if b >= 0 and enc.var[c, b] > 0
                )
            pieces = iter([text.encode()])
            read = "shown"
        t_write = time.time()
        report, written = _run_child(args, pieces, read=read, nx=enc.nx, deadline=deadline)
        while ctx is not None and report is not None and report.get("status") == "SAT":
            k = ctx.cuts(_grid_of(enc, report))  # connectivity: cut the answer off, run again
            if not k:
                break
            stats["cuts"] += k
            stats["sat_calls"] = stats.get("sat_calls", 1) + 1
            report, written = _run_child(args, ground_program(enc, prefer, ctx), read=read,
                                         nx=enc.nx, deadline=deadline)  # fmt: skip
        stats["solver_stats"] = sub = {
            "clingo": str(clingo.__version__),
            "seed": cseed,
            "args": args,
            "write_s": round(max(0.0, written - t_write), 6) if written else None,
        }
        if report is None:
            sub["killed"] = "at the deadline, while clingo parsed or prepared the program"
            return done("timeout")
        if report.get("status") == "ERROR":
            raise CsplabError(f"clingo failed: {report.get('error')}")
        stats["solver_status"] = report["status"]
        stats.update(report.get("stats", {}))
        if "loaded" in report:
            stats["load_s"] = max(0.0, report["loaded"] - t_write)
            stats["ground_s"] = stats["encode_s"] + stats["load_s"]
        for key in ("prepare_s", "search_s", "read_s"):
            if key in report:
                sub[key] = report[key]
        if "prepare_s" in report:
            stats["solve_s"] = report["prepare_s"] + report["search_s"]
        if report.get("messages"):
            sub["messages"] = report["messages"]
        if report["status"] == "SAT":
            if read == "atoms":
                grid = _grid_of(enc, report)
            else:
                grid = enc.const.copy()
                pairs = np.asarray(report["pairs"], dtype=np.int64).reshape(-1, 2)
                grid[pairs[:, 0]] = pairs[:, 1]
            return done("solved", grid.reshape(problem.shape))
        if report["status"] == "UNSAT":
            stats["proof"] = f"clingo {clingo.__version__}: no answer set (exhaustive search)"
            return done("unsat")
        return done("timeout")
