"""Continuous model synthesis in 2D (thesis Ch. 4; Merrell & Manocha, SIGGRAPH Asia 2008).

The example is a set of labelled polygons (:class:`PolygonModel`); lines parallel to its
edges cut the plane (:class:`Arrangement`, exact on an integer lattice); the states of the
arrangement's vertices and edges form an ordinary binary :class:`~csplab.problem.Problem`
(:class:`ContinuousCSP`) that every csplab solver solves; the solution becomes polygons again
(:meth:`ContinuousCSP.model`), and :func:`violations` checks Eq. 4.1 on those polygons.
:func:`synthesize` does all of it.

Examples
--------
>>> from csplab.continuous import PolygonModel, synthesize, violations
>>> E = PolygonModel.from_json({"polygons": [
...     {"label": 1, "points": [[0, 0], [2, 0], [2, 1], [0, 1]]},
...     {"label": 2, "points": [[0, 1], [2, 1], [1, 2]]}]})
>>> s = synthesize(E, (10, 8), rng=3)
>>> s.result.status, len(violations(E, s.model))
('solved', 0)

``synthesize`` lives in :mod:`csplab.continuous.synthesis` (it uses the solvers, a layer
above the rest of this package) and is imported on first use.
"""

from __future__ import annotations

from typing import Any

from csplab.continuous.arrangement import Arrangement, Lattice
from csplab.continuous.check import Violations, violations
from csplab.continuous.csp import ContinuousCSP
from csplab.continuous.model import Polygon, PolygonModel

__all__ = [
    "Arrangement",
    "ContinuousCSP",
    "Lattice",
    "Polygon",
    "PolygonModel",
    "Synthesis",
    "Violations",
    "synthesize",
    "violations",
]


def __getattr__(name: str) -> Any:
    if name in ("synthesize", "Synthesis"):
        from csplab.continuous import synthesis

        return getattr(synthesis, name)
    raise AttributeError(f"module 'csplab.continuous' has no attribute {name!r}")
