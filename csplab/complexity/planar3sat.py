"""Random planar 3-SAT formulas drawn in Knuth–Raghunathan form.

The variables ``x_0 .. x_{n-1}`` sit on a horizontal line. Each clause uses three distinct
variables ``l < m < r`` and is drawn as a three-legged comb on one side of the line
(``side = +1`` above, ``-1`` below): a horizontal bar at some depth with vertical legs down
(or up) to its three variables. Two clauses on the same side never cross when one of them
lies in a *gap* of the other (between two consecutive legs, touching allowed) or when they
are disjoint (touching at an end variable allowed); the generator only accepts clauses that
satisfy this with every clause already placed on their side, so every instance comes with a
crossing-free drawing. The bar of a clause is drawn at depth ``1 + max`` depth of the
clauses nested inside it.

Within a variable's stretch of the line the legs are ordered per side: legs of clauses that
end at the variable (inner first), the middle leg, legs of clauses that start there (outer
first). :meth:`Planar3SAT.leg_order` returns this order; the grid layout in
:mod:`csplab.complexity.reduction` uses it.

Examples
--------
>>> f = random_planar3sat(5, 6, rng=3)
>>> f.nvars, len(f.clauses)
(5, 6)
>>> f.is_planar()
True
>>> f.satisfiable() == (len(f.models()) > 0)
True
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from csplab.errors import InputError
from csplab.rng import RngLike, make_rng

__all__ = ["Clause", "Planar3SAT", "random_planar3sat"]


@dataclass(frozen=True)
class Clause:
    """One clause: variables ``l < m < r``, literal signs, drawing side and depth.

    ``positive[i]`` is ``True`` for the literal ``x`` and ``False`` for ``NOT x``;
    ``side`` is ``+1`` (comb above the variable line) or ``-1`` (below); ``depth >= 1`` is
    the bar's level counted from the line.
    """

    vars: tuple[int, int, int]
    positive: tuple[bool, bool, bool]
    side: int
    depth: int = 1

    @property
    def l(self) -> int:  # noqa: E743 - the thesis' name for the left variable
        return self.vars[0]

    @property
    def m(self) -> int:
        return self.vars[1]

    @property
    def r(self) -> int:
        return self.vars[2]

    def literals(self) -> list[int]:
        """DIMACS literals (variable ``i`` is ``i + 1``)."""
        return [(v + 1) if p else -(v + 1) for v, p in zip(self.vars, self.positive, strict=True)]

    def satisfied(self, assignment: NDArray[np.bool_] | list[bool]) -> bool:
        return any(bool(assignment[v]) == p for v, p in zip(self.vars, self.positive, strict=True))

    def __str__(self) -> str:
        return (
            "("
            + " ∨ ".join(
                f"{'' if p else '¬'}x{v + 1}" for v, p in zip(self.vars, self.positive, strict=True)
            )
            + ")"
        )


def _compatible(a: tuple[int, int, int], b: tuple[int, int, int]) -> bool:
    """Two combs on the same side do not cross (touching allowed)."""
    al, am, ar = a
    bl, bm, br = b
    if ar <= bl or br <= al:
        return True  # disjoint
    if (al <= bl and br <= am) or (am <= bl and br <= ar):
        return True  # b in a gap of a
    return (bl <= al and ar <= bm) or (bm <= al and ar <= br)  # a in a gap of b


def _nested_in(inner: tuple[int, int, int], outer: tuple[int, int, int]) -> bool:
    il, _, ir = inner
    ol, om, orr = outer
    if inner == outer:
        return False
    return (ol <= il and ir <= om) or (om <= il and ir <= orr)


@dataclass(frozen=True)
class Planar3SAT:
    """A 3-CNF formula with a planar comb drawing.

    Attributes
    ----------
    nvars : int
    clauses : tuple of Clause
    seed : int or None
        The seed that reproduces :func:`random_planar3sat`.
    """

    nvars: int
    clauses: tuple[Clause, ...]
    seed: int | None = None
    meta: dict[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        for c in self.clauses:
            if not (0 <= c.l < c.m < c.r < self.nvars):
                raise InputError(f"clause {c} needs variables l < m < r in 0..{self.nvars - 1}")
            if c.side not in (1, -1):
                raise InputError(f"clause {c}: side must be +1 or -1")
        for s in (1, -1):
            same = [c.vars for c in self.clauses if c.side == s]
            for a, b in itertools.combinations(same, 2):
                if not _compatible(a, b):
                    raise InputError(f"clauses {a} and {b} cross on side {s:+d}")

    # ------------------------------------------------------------------ the formula
    def cnf(self) -> list[list[int]]:
        """DIMACS clauses."""
        return [c.literals() for c in self.clauses]

    def __str__(self) -> str:
        return " ∧ ".join(str(c) for c in self.clauses) or "TRUE"

    def evaluate(self, assignment: NDArray[np.bool_] | list[bool]) -> bool:
        """Does ``assignment`` (one bool per variable) satisfy every clause?"""
        return all(c.satisfied(assignment) for c in self.clauses)

    def satisfiable(self) -> bool:
        """Decided by a SAT solver (python-sat, CaDiCaL) on :meth:`cnf`."""
        from pysat.solvers import Solver

        with Solver(name="cadical195", bootstrap_with=self.cnf()) as s:
            s.add_clause([1, -1]) if self.nvars else None
            return bool(s.solve())

    def models(self) -> NDArray[np.bool_]:
        """Every satisfying assignment, by brute force over ``2**nvars`` (rows, bool)."""
        if self.nvars > 22:
            raise InputError("models() enumerates 2**nvars assignments; use at most 22")
        n = self.nvars
        allx = ((np.arange(2**n)[:, None] >> np.arange(n)) & 1).astype(bool)
        ok = np.ones(2**n, dtype=bool)
        for c in self.clauses:
            sat = np.zeros(2**n, dtype=bool)
            for v, p in zip(c.vars, c.positive, strict=True):
                sat |= allx[:, v] == p
            ok &= sat
        return allx[ok]

    # ------------------------------------------------------------------ the drawing
    def graph(self, with_line: bool = True) -> Any:
        """The variable–clause graph (networkx), with the path through the variables in
        line order when ``with_line`` (the stronger, Lichtenstein-style planarity)."""
        import networkx as nx

        G = nx.Graph()
        G.add_nodes_from(("x", i) for i in range(self.nvars))
        for j, c in enumerate(self.clauses):
            for v in c.vars:
                G.add_edge(("c", j), ("x", v))
        if with_line:
            for i in range(self.nvars - 1):
                G.add_edge(("x", i), ("x", i + 1))
        return G

    def is_planar(self) -> bool:
        """networkx's planarity test on :meth:`graph` (with the variable path)."""
        import networkx as nx

        planar, _ = nx.check_planarity(self.graph(with_line=True))
        return bool(planar)

    def leg_order(self) -> dict[int, list[tuple[int, int]]]:
        """Per variable, its legs from left to right as ``(clause index, position 0/1/2)``:
        first the legs above the line, then those below, each in the order ends (inner
        first), middle, starts (outer first)."""
        out: dict[int, list[tuple[int, int]]] = {v: [] for v in range(self.nvars)}
        for v in range(self.nvars):
            for side in (1, -1):
                mine = [(j, c) for j, c in enumerate(self.clauses) if c.side == side]
                ends = [(j, c) for j, c in mine if c.r == v]
                mids = [(j, c) for j, c in mine if c.m == v]
                starts = [(j, c) for j, c in mine if c.l == v]
                ends.sort(key=lambda jc: (jc[1].depth, jc[1].l), reverse=False)
                ends.sort(key=lambda jc: jc[1].depth)
                starts.sort(key=lambda jc: -jc[1].depth)
                out[v] += [(j, 2) for j, _ in ends]
                out[v] += [(j, 1) for j, _ in mids]
                out[v] += [(j, 0) for j, _ in starts]
        return out

    def max_depth(self, side: int) -> int:
        return max((c.depth for c in self.clauses if c.side == side), default=0)


def _depths(triples: list[tuple[int, int, int]]) -> list[int]:
    order = sorted(range(len(triples)), key=lambda i: triples[i][2] - triples[i][0])
    depth = [1] * len(triples)
    for i in order:
        inner = [depth[j] for j in order if _nested_in(triples[j], triples[i])]
        depth[i] = 1 + max(inner, default=0)
    return depth


def with_depths(nvars: int, clauses: list[Clause], seed: int | None = None) -> Planar3SAT:
    """A :class:`Planar3SAT` with every clause's depth recomputed from the nesting."""
    out = list(clauses)
    for s in (1, -1):
        idx = [i for i, c in enumerate(out) if c.side == s]
        dep = _depths([out[i].vars for i in idx])
        for i, d in zip(idx, dep, strict=True):
            c = out[i]
            out[i] = Clause(c.vars, c.positive, c.side, d)
    return Planar3SAT(nvars, tuple(out), seed)


def unsat_signs(
    nvars: int,
    triples: list[tuple[int, int, int]],
    rng: RngLike = None,
    *,
    conflicts: int | None = None,
) -> list[tuple[bool, bool, bool]] | None:
    """Literal signs that make the clauses on ``triples`` unsatisfiable, or ``None``.

    Clause ``j`` with signs ``s_j`` is falsified exactly by the assignments whose values on
    its three variables are ``NOT s_j``, so the formula is unsatisfiable iff these patterns
    cover all ``2**nvars`` assignments. A small SAT problem (one variable per clause and
    pattern) finds such patterns; random phases make the choice random. With a
    ``conflicts`` budget, ``None`` may also mean "not found within the budget".
    """
    from pysat.card import CardEnc, EncType
    from pysat.solvers import Solver

    gen, _ = make_rng(rng)
    m = len(triples)
    if m == 0 or nvars > 16:
        return None
    y = np.arange(1, 8 * m + 1).reshape(m, 8)  # y[j, p]: clause j falsified by pattern p
    clauses: list[list[int]] = []
    top = 8 * m
    for j in range(m):
        enc = CardEnc.equals(y[j].tolist(), 1, top_id=top, encoding=EncType.pairwise)
        clauses += enc.clauses
    allx = (np.arange(2**nvars)[:, None] >> np.arange(nvars)) & 1
    for x in allx:
        clauses.append(
            [int(y[j, x[t[0]] | (x[t[1]] << 1) | (x[t[2]] << 2)]) for j, t in enumerate(triples)]
        )
    with Solver(name="minisat22", bootstrap_with=clauses) as s:
        lits = np.arange(1, 8 * m + 1)
        s.set_phases((lits * np.where(gen.random(8 * m) < 0.5, 1, -1)).tolist())
        if conflicts is not None:
            s.conf_budget(conflicts)
            if not s.solve_limited():
                return None
        elif not s.solve():
            return None
        model = np.array(s.get_model()[: 8 * m]) > 0
    pat = model.reshape(m, 8).argmax(axis=1)
    # falsifying pattern p -> literal signs: variable k positive iff bit k of p is 0
    return [tuple(not bool((int(p) >> k) & 1) for k in range(3)) for p in pat]  # type: ignore[misc]


def _random_triangulation(gen: np.random.Generator, lo: int, hi: int) -> list[tuple[int, int, int]]:
    """A random triangulation of the polygon ``lo, lo+1, ..., hi`` (vertices on a line):
    the triangle on edge ``(lo, hi)`` with a uniform apex, then both sides recursively."""
    out: list[tuple[int, int, int]] = []
    stack = [(lo, hi)]
    while stack:
        a, b = stack.pop()
        if b - a < 2:
            continue
        k = int(gen.integers(a + 1, b))
        out.append((a, k, b))
        stack += [(a, k), (k, b)]
    return out


def _random_structure(
    gen: np.random.Generator, nvars: int, nclauses: int
) -> list[tuple[tuple[int, int, int], int]]:
    """``nclauses`` distinct combs drawn from a random triangulation on each side.

    Pairwise non-crossing combs are exactly subsets of triangulations of the polygon on the
    variables (in line order), so this draws a random crossing-free structure directly.
    """
    cap = 2 * (nvars - 2)
    if nclauses > cap:
        raise InputError(
            f"at most {cap} non-crossing clauses fit on {nvars} variables (a triangulation "
            f"on each side), asked for {nclauses}"
        )
    pool = [(t, 1) for t in _random_triangulation(gen, 0, nvars - 1)]
    pool += [(t, -1) for t in _random_triangulation(gen, 0, nvars - 1)]
    pick = gen.choice(len(pool), nclauses, replace=False)
    return [pool[int(i)] for i in sorted(pick, key=lambda i: gen.random())]


SIGN_MODES = ("random", "unsat", "near")


def random_planar3sat(
    nvars: int,
    nclauses: int,
    rng: RngLike = None,
    *,
    signs: str = "random",
    p_negative: float = 0.5,
    max_structures: int = 200,
) -> Planar3SAT:
    """A random planar 3-CNF formula with ``nclauses`` clauses over ``nvars`` variables.

    The structure is ``nclauses`` combs drawn from a random triangulation of the variables
    (in line order) on each side: pairwise non-crossing comb sets are exactly subsets of such
    triangulations, so at most ``2 (nvars - 2)`` clauses fit. Literal signs:

    ``signs="random"``
        each literal negated with probability ``p_negative`` (such sparse planar formulas
        are almost always satisfiable);
    ``signs="unsat"``
        chosen by :func:`unsat_signs` so the formula is unsatisfiable (structures that
        cannot be made unsatisfiable are redrawn, up to ``max_structures`` times);
    ``signs="near"``
        an unsatisfiable choice with one clause's signs redrawn until the formula is
        satisfiable: formulas with few satisfying assignments.

    Raises :class:`~csplab.errors.InputError` when the clauses do not fit or no structure
    admits the requested signs.
    """
    gen, seed = make_rng(rng)
    if nvars < 3:
        raise InputError(f"a 3-SAT formula needs at least 3 variables, got {nvars}")
    if nclauses < 0:
        raise InputError("nclauses must be non-negative")
    if signs not in SIGN_MODES:
        raise InputError(f"signs must be one of {', '.join(SIGN_MODES)}, not {signs!r}")
    for _ in range(max_structures):
        placed = _random_structure(gen, nvars, nclauses)
        trips = [t for t, _ in placed]
        if signs == "random":
            pos = [tuple(bool(b) for b in gen.random(3) >= p_negative) for _ in placed]
        else:
            cover = unsat_signs(nvars, trips, gen, conflicts=2000)
            if cover is None:
                continue
            pos = list(cover)
            if signs == "near":
                j = int(gen.integers(len(pos)))
                choices = [p for p in itertools.product([True, False], repeat=3) if p != pos[j]]
                for k in gen.permutation(len(choices)):
                    pos[j] = choices[int(k)]
                    f = with_depths(nvars, _clauses(placed, pos), seed)
                    if len(f.models()):
                        break
                else:
                    continue
        f = with_depths(nvars, _clauses(placed, pos), seed)
        f.meta["signs"] = signs
        return f
    raise InputError(
        f"no planar structure with {nclauses} clauses on {nvars} variables admits "
        f"signs={signs!r} (tried {max_structures}); unsatisfiable ones need at least 6 "
        "variables and 8 clauses"
    )


def _clauses(placed: list[tuple[tuple[int, int, int], int]], pos: list[Any]) -> list[Clause]:
    return [Clause(t, (bool(p[0]), bool(p[1]), bool(p[2])), s)
            for (t, s), p in zip(placed, pos, strict=True)]  # fmt: skip
