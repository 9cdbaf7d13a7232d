"""Soft constraints: an energy over models, minimised by Metropolis acceptance in Alg. 3.4.

The 2007 paper's Sec. 4.2: with ``f(M)`` a function the model should maximise, modify in
blocks accepts a consistent new block (Step 5) with probability ``min(1, f(M') / f(M))``.
Here ``f(M) = exp(-E(M) / T)`` for an energy ``E`` that is a weighted sum of user terms and a
temperature ``T`` (``blocks`` options ``energy``, ``temperature``, ``cooling``: ``T`` is
multiplied by ``cooling`` after each sweep, a simulated-annealing schedule), so the
acceptance is ``min(1, exp(-(E(M') - E(M)) / T))``. The hard constraints are untouched:
every accepted model is consistent.

Terms (each ``weight`` times a count of cells, so energies of different terms add up):

* :class:`Histogram`: how far the label histogram is from target fractions (half the L1
  distance of the counts: the number of cells that would have to change label);
* :class:`Region`: cells inside a region (a bool mask, e.g. a symbol's shape, the paper's
  Fig. 13) whose label is not in a set, plus, with ``outside=True``, cells outside it whose
  label is in the set;
* :class:`HeightField`: for 3D models, the sum over columns of ``|height - target|`` where
  the height of a column is one above its topmost cell not in ``empty``.

Examples
--------
>>> import numpy as np
>>> E = Energy([Histogram({1: 0.5}), Region(np.eye(3, dtype=bool), [1])])
>>> E(np.array([[1, 0, 0], [0, 0, 0], [0, 0, 0]]))      # (8 + 3.5) / 2 + 2 cells
7.75
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from csplab.errors import InputError

__all__ = ["Breaches", "Energy", "HeightField", "Histogram", "Region", "Term"]


class Term:
    """One energy term; subclasses implement :meth:`__call__` on a complete grid."""

    weight: float = 1.0

    def __call__(self, grid: NDArray[np.integer[Any]]) -> float:  # pragma: no cover
        raise NotImplementedError


@dataclass(frozen=True, eq=False)
class Histogram(Term):
    """Half the L1 distance between the label counts and ``target`` fractions times the
    number of cells, labels not named having target 0 (the cells that would have to change
    label); with ``others=False`` only the named labels count: ``sum |count - target|``
    over them."""

    target: Mapping[int, float]
    weight: float = 1.0
    others: bool = True

    def __call__(self, grid: NDArray[np.integer[Any]]) -> float:
        g = np.asarray(grid).reshape(-1)
        K = max(int(g.max(initial=0)), *self.target.keys()) + 1
        counts = np.bincount(g, minlength=K).astype(np.float64)
        want = np.zeros(K)
        for b, f in self.target.items():
            want[b] = f * g.size
        if not self.others:
            keys = list(self.target)
            return float(self.weight * np.abs(counts[keys] - want[keys]).sum())
        return float(self.weight * 0.5 * np.abs(counts - want).sum())


@dataclass(frozen=True, eq=False)
class Region(Term):
    """Cells of ``mask`` (bool, the grid's shape or its first axes) whose label is not in
    ``labels``; with ``outside``, also cells outside the mask whose label is in it."""

    mask: NDArray[np.bool_]
    labels: Sequence[int]
    weight: float = 1.0
    outside: bool = False

    def __call__(self, grid: NDArray[np.integer[Any]]) -> float:
        g = np.asarray(grid)
        m = np.asarray(self.mask, dtype=bool)
        if m.shape != g.shape[: m.ndim]:
            raise InputError(f"region mask {m.shape} does not fit the grid {g.shape}")
        m = m.reshape(m.shape + (1,) * (g.ndim - m.ndim))
        m = np.broadcast_to(m, g.shape)
        inside = np.isin(g, list(self.labels))
        cost = int((m & ~inside).sum())
        if self.outside:
            cost += int((~m & inside).sum())
        return float(self.weight * cost)


@dataclass(frozen=True, eq=False)
class HeightField(Term):
    """3D: ``sum |height(x, y) - heights[x, y]|`` with the height of a column one above its
    topmost label not in ``empty`` (0 for an empty column)."""

    heights: NDArray[np.float64]
    empty: Sequence[int] = (0,)
    weight: float = 1.0

    def __call__(self, grid: NDArray[np.integer[Any]]) -> float:
        g = np.asarray(grid)
        if g.ndim != 3 or np.shape(self.heights) != g.shape[:2]:
            raise InputError(f"a height field {np.shape(self.heights)} needs a 3D grid over it")
        solid = ~np.isin(g, list(self.empty))
        z = np.arange(1, g.shape[2] + 1)
        h = np.where(solid, z, 0).max(axis=2)
        return float(self.weight * np.abs(h - np.asarray(self.heights)).sum())


@dataclass(frozen=True, eq=False)
class Breaches(Term):
    """The global constraints of a problem as an energy: the sum of their
    :meth:`~csplab.constraints.Constraint.excess` (0 when every one holds); modify in
    blocks minimises it to repair a model that breaks them."""

    problem: Any
    weight: float = 1.0

    def __call__(self, grid: NDArray[np.integer[Any]]) -> float:
        lab = np.asarray(grid, dtype=np.int64).reshape(-1)
        return float(
            self.weight * sum(c.excess(self.problem, lab) for c in self.problem.constraints)
        )


@dataclass(frozen=True, eq=False)
class Energy:
    """A sum of :class:`Term` s; ``Energy(grid)`` is ``E(M)``."""

    terms: Sequence[Term] = field(default_factory=tuple)

    def __call__(self, grid: ArrayLike) -> float:
        g = np.asarray(grid)
        if (g < 0).any():
            raise InputError("the energy is defined on complete models")
        return float(sum(t(g) for t in self.terms))
