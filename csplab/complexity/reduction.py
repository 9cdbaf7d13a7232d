"""Theorem 3.3.4: planar 3-SAT reduces to deciding whether an incomplete model is consistent.

:func:`reduce_planar3sat` lays a :class:`~csplab.complexity.planar3sat.Planar3SAT` out as an
incomplete 2D model ``M_t`` over the labels of :mod:`csplab.complexity.gadgets` (thesis
Fig. 3.7(c)): every gadget cell is fixed, every wire cell is free.

Layout (all wires one cell wide, enclosed by ``enc[..]`` pieces):

* each variable is a horizontal wire on the *variable line* ``y = y0``; its legs leave it
  upwards (clauses above) and downwards (clauses below) at distinct columns, three columns
  apart, in the order of :meth:`Planar3SAT.leg_order`; variables are two wall columns apart;
* a clause of depth ``d`` has its bar on row ``y0 ± (3d + 1)``: the left and right legs bend
  into the bar and run towards the middle leg, which ends below (above) the *junction*
  cell; ``OR-top`` (``OR-bot``) is fixed on the other side of the junction, so the junction
  must hold an OR arrow that demands TRUE from one of the three wires;
* a negative literal gets a NOT gate on its leg two rows from the line: ``NOT`` is fixed in
  the leg's left wall and the leg cell to its right must hold a NOT arrow, which swaps the
  values below and above it.

So the region of a variable (its stretch of the line and its legs up to a NOT gate or a
junction) is all TRUE or all FALSE, a leg past a NOT gate holds the negated value, and the
model can be completed iff some assignment makes a TRUE wire reach every junction: iff the
formula is satisfiable. The grid has width ``3 (#legs + #unused variables) + 2`` and height
``3 (depth above + depth below) + 7``, at most ``O((n + m) m)`` cells for ``n`` variables
and ``m`` clauses.

Examples
--------
>>> from csplab.complexity.planar3sat import random_planar3sat
>>> f = random_planar3sat(5, 4, rng=2)
>>> red = reduce_planar3sat(f)
>>> P = red.problem()
>>> x = f.models()[0]                       # a satisfying assignment
>>> g = red.encode(x)
>>> P.is_solution(g), bool((red.decode(g) == x).all())
(True, True)
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab import grids
from csplab.complexity import complete_model
from csplab.complexity import gadgets as G
from csplab.complexity.planar3sat import Planar3SAT
from csplab.errors import InputError
from csplab.problem import Problem
from csplab.rng import RngLike, make_rng

__all__ = ["Reduction", "reduce_planar3sat", "verify_instance"]

_SPACING = 3
_MARGIN = 2


@dataclass
class Reduction:
    """An incomplete model ``M_t`` for a planar 3-SAT formula, with its bookkeeping.

    Attributes
    ----------
    formula : Planar3SAT
    fixed : int32 array ``(nx, ny)``
        The incomplete model: gadget labels, ``-1`` on free (wire) cells.
    region : int32 array ``(nx, ny)``
        Region id of each wire cell (``-1`` elsewhere and on arrow cells).
    region_var, region_negated : int arrays
        The literal each region carries.
    var_cell : list of (x, y)
        A cell on each variable's stretch of the line (decoding reads it).
    not_gates : list of (x, y, variable, side)
        Cells of NOT arrows (the fixed ``NOT`` is at ``(x - 1, y)``).
    junctions : list of (x, y, clause index)
        Cells of OR arrows.
    """

    formula: Planar3SAT
    fixed: NDArray[np.int32]
    region: NDArray[np.int32]
    region_var: NDArray[np.int64]
    region_negated: NDArray[np.bool_]
    var_cell: list[tuple[int, int]]
    not_gates: list[tuple[int, int, int, int]]
    junctions: list[tuple[int, int, int]]
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def shape(self) -> tuple[int, int]:
        return (int(self.fixed.shape[0]), int(self.fixed.shape[1]))

    @property
    def area(self) -> int:
        return int(self.fixed.size)

    @property
    def free_cells(self) -> int:
        return int((self.fixed < 0).sum())

    @cached_property
    def _problem(self) -> Problem:
        return grids.grid(
            self.shape,
            G.transitions(),
            fixed=self.fixed,
            names=G.NAMES,
            name="planar3sat",
            meta={"formula": str(self.formula), "seed": self.formula.seed},
        )

    def problem(self) -> Problem:
        """The model-consistency problem: the gadget transition matrices, the gadget cells
        fixed (:class:`~csplab.problem.Problem` is immutable, so this is cached)."""
        return self._problem

    def decode(self, grid: ArrayLike) -> NDArray[np.bool_]:
        """The assignment a completed grid encodes: TRUE on each variable's line cell."""
        g = np.asarray(grid)
        return np.array([g[x, y] == G.TRUE for x, y in self.var_cell], dtype=bool)

    def encode(self, assignment: ArrayLike) -> NDArray[np.int32] | None:
        """The completion of ``M_t`` for an assignment, or ``None`` when it falsifies a
        clause (no OR arrow has a TRUE wire to point at)."""
        a = np.asarray(assignment, dtype=bool).reshape(-1)
        if a.size != self.formula.nvars:
            raise InputError(f"assignment needs {self.formula.nvars} values, got {a.size}")
        g = self.fixed.copy()
        val = a[self.region_var] ^ self.region_negated
        m = self.region >= 0
        g[m] = np.where(val[self.region[m]], G.TRUE, G.FALSE)
        for x, y, v, side in self.not_gates:
            near_is_true = bool(a[v])  # the value on the line side of the gate
            if side > 0:
                g[x, y] = G.NOT_DN if near_is_true else G.NOT_UP
            else:
                g[x, y] = G.NOT_UP if near_is_true else G.NOT_DN
        for x, y, j in self.junctions:
            c = self.formula.clauses[j]
            lit = [bool(a[v]) == p for v, p in zip(c.vars, c.positive, strict=True)]
            if not any(lit):
                return None
            arrows = G.ARROW_TOP if c.side > 0 else G.ARROW_BOT
            g[x, y] = arrows[lit.index(True)]
        return g

    def stats(self) -> dict[str, Any]:
        nx, ny = self.shape
        return {
            "nvars": self.formula.nvars,
            "nclauses": len(self.formula.clauses),
            "nx": nx,
            "ny": ny,
            "area": self.area,
            "free_cells": self.free_cells,
            "not_gates": len(self.not_gates),
            "labels": G.K,
        }


def reduce_planar3sat(formula: Planar3SAT) -> Reduction:
    """Lay ``formula`` out as an incomplete model (see the module docstring)."""
    f = formula
    order = f.leg_order()
    leg_x: dict[tuple[int, int], int] = {}
    seg: list[tuple[int, int]] = []
    x = _MARGIN
    for v in range(f.nvars):
        start = x
        for key in order[v]:
            leg_x[key] = x
            x += _SPACING
        if not order[v]:
            x += _SPACING
        seg.append((start, x - _SPACING))
    nx = x - _SPACING + 1 + _MARGIN
    d_dn, d_up = f.max_depth(-1), f.max_depth(1)
    y0 = 3 * d_dn + 3
    ny = y0 + 3 * d_up + 4

    region = np.full((nx, ny), -1, dtype=np.int32)
    free = np.zeros((nx, ny), dtype=bool)
    gate = np.full((nx, ny), -1, dtype=np.int32)
    rvar: list[int] = []
    rneg: list[bool] = []

    def claim(cx: int, cy: int, r: int) -> None:
        if free[cx, cy] or gate[cx, cy] >= 0:
            raise AssertionError(f"layout overlap at {(cx, cy)}")  # a bug in the drawing
        free[cx, cy] = True
        region[cx, cy] = r

    for v in range(f.nvars):
        rvar.append(v)
        rneg.append(False)
        a, b = seg[v]
        for cx in range(a, b + 1):
            claim(cx, y0, v)
    not_gates: list[tuple[int, int, int, int]] = []
    junctions: list[tuple[int, int, int]] = []
    for j, c in enumerate(f.clauses):
        s = c.side
        yb = y0 + s * (3 * c.depth + 1)
        xs = [leg_x[(j, p)] for p in range(3)]
        for p in range(3):
            v, pos = c.vars[p], c.positive[p]
            lx = xs[p]
            r = v
            yend = yb if p != 1 else yb - s
            ys = list(range(y0 + s, yend + s, s))
            ynot = y0 + 2 * s
            for cy in ys:
                if not pos and cy == ynot:
                    free[lx, cy] = True  # the NOT arrow: free, no region
                    not_gates.append((lx, cy, v, s))
                    if gate[lx - 1, cy] >= 0 or free[lx - 1, cy]:
                        raise AssertionError(f"NOT gate overlap at {(lx - 1, cy)}")
                    gate[lx - 1, cy] = G.NOT
                    rvar.append(v)
                    rneg.append(True)
                    r = len(rvar) - 1
                    continue
                claim(lx, cy, r)
            if p == 0:
                for cx in range(xs[0] + 1, xs[1]):
                    claim(cx, yb, r)
            elif p == 2:
                for cx in range(xs[1] + 1, xs[2]):
                    claim(cx, yb, r)
        free[xs[1], yb] = True  # the junction: an OR arrow
        junctions.append((xs[1], yb, j))
        if gate[xs[1], yb + s] >= 0 or free[xs[1], yb + s]:
            raise AssertionError(f"OR gate overlap at {(xs[1], yb + s)}")
        gate[xs[1], yb + s] = G.OR_TOP if s > 0 else G.OR_BOT

    fixed = np.full((nx, ny), -1, dtype=np.int32)
    pad = np.zeros((nx + 2, ny + 2), dtype=bool)
    pad[1:-1, 1:-1] = free
    nb = {"L": pad[:-2, 1:-1], "R": pad[2:, 1:-1], "D": pad[1:-1, :-2], "U": pad[1:-1, 2:]}
    for cx in range(nx):
        for cy in range(ny):
            if free[cx, cy]:
                continue
            if gate[cx, cy] >= 0:
                fixed[cx, cy] = gate[cx, cy]
            else:
                fixed[cx, cy] = G.enclosure("".join(d for d in G.SIDES if nb[d][cx, cy]))
    red = Reduction(
        formula=f,
        fixed=fixed,
        region=region,
        region_var=np.array(rvar, dtype=np.int64),
        region_negated=np.array(rneg, dtype=bool),
        var_cell=[(seg[v][0], y0) for v in range(f.nvars)],
        not_gates=not_gates,
        junctions=junctions,
        meta={"y0": y0},
    )
    _check_layout(red)
    return red


def _check_layout(red: Reduction) -> None:
    """Invariants the correctness argument needs (raise AssertionError: a drawing bug)."""
    fx, reg = red.fixed, red.region
    nx, ny = fx.shape
    free = fx < 0
    for cx, cy in zip(*np.nonzero(free), strict=True):
        guarded = False
        for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            ox, oy = cx + dx, cy + dy
            if not (0 <= ox < nx and 0 <= oy < ny):
                continue
            if fx[ox, oy] >= 0:
                guarded = True
            elif reg[cx, cy] >= 0 and reg[ox, oy] >= 0 and reg[cx, cy] != reg[ox, oy]:
                raise AssertionError(f"regions touch at {(int(cx), int(cy))}")
        if not guarded:
            raise AssertionError(f"free cell {(int(cx), int(cy))} has no fixed neighbour")
    P = grids.grid(red.shape, G.transitions(), fixed=red.fixed)
    # fixed–fixed neighbours must be allowed by T
    g = np.where(free, 0, fx)
    v = P.violations(g)
    bad = [i for i in v.arcs if not free.ravel()[P.arcs[i, 0]] and not free.ravel()[P.arcs[i, 1]]]
    if bad:
        raise AssertionError(f"fixed cells violate T: {v.describe()}")


# ----------------------------------------------------------------------------- verification


def verify_instance(
    formula: Planar3SAT, rng: RngLike = None, *, alg31: bool = True
) -> dict[str, Any]:
    """Check Theorem 3.3.4's reduction on one formula; every figure is measured.

    Returns a dict with the formula's satisfiability (pysat on the CNF) and its number of
    satisfying assignments (brute force), whether ``M_t`` is completable (SAT on the grid),
    whether the decoded assignment satisfies the formula, how many satisfying assignments
    encode to a grid with zero violations, whether the catalog C (arc consistency) stays
    non-empty, the outcome of one Alg. 3.1 run (scanline order), sizes and times.
    """
    gen, _seed = make_rng(rng)
    out: dict[str, Any] = {"seed": formula.seed, "formula": str(formula)}
    t0 = time.perf_counter()
    sat = formula.satisfiable()
    models = formula.models()
    out["sat"] = sat
    out["models"] = len(models)
    out["t_cnf"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    red = reduce_planar3sat(formula)
    P = red.problem()
    out.update(red.stats())
    out["t_build"] = time.perf_counter() - t0
    out["planar"] = formula.is_planar()
    t0 = time.perf_counter()
    r = complete_model(P, gen)
    out["t_grid_sat"] = time.perf_counter() - t0
    out["completable"] = r.status == "solved"
    out["grid_status"] = r.status
    out["decoded_ok"] = None
    if r.status == "solved":
        out["decoded_ok"] = bool(formula.evaluate(red.decode(r.grid)))
    t0 = time.perf_counter()
    enc_ok = 0
    for a in models:
        g = red.encode(a)
        if g is not None and P.is_solution(g) and (red.decode(g) == a).all():
            enc_ok += 1
    out["encoded_ok"] = enc_ok
    out["t_encode"] = time.perf_counter() - t0
    from csplab.catalog import Propagator

    out["catalog_nonempty"] = bool(Propagator(P).ok)
    if alg31:
        from csplab.engine.alg31 import run_alg31

        t0 = time.perf_counter()
        res = run_alg31(P, gen, order="scanline")
        out["alg31"] = res.status
        out["t_alg31"] = time.perf_counter() - t0
    out["agree"] = (
        out["completable"] == sat
        and out["decoded_ok"] is not False
        and enc_ok == len(models)
        and out["planar"]
    )
    return out
