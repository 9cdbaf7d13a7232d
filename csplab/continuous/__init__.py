"""Continuous model synthesis in 2D and 3D (thesis Ch. 4; Merrell & Manocha, SIGGRAPH Asia
2008).

The example is a set of labelled polygons (:class:`PolygonModel`) or solids
(:class:`PolyhedralModel`); lines parallel to its edges (planes parallel to its faces) cut
the space (:class:`Arrangement`, :class:`~csplab.continuous.space.Arrangement3`, exact on
one integer :class:`Lattice`); the states of the arrangement's vertices and edges form an
ordinary binary :class:`~csplab.problem.Problem` (:func:`continuous_csp`:
:class:`ContinuousCSP` or :class:`~csplab.continuous.csp3d.ContinuousCSP3`) that every
csplab solver solves; the solution becomes polygons or solids again (``csp.model``), and
:func:`violations` checks Eq. 4.1 on them. :func:`synthesize` does all of it, in either
dimension (Alg. 4.1 is one algorithm).

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

from csplab.continuous.arrangement import Arrangement
from csplab.continuous.check import Violations, violations
from csplab.continuous.csp import ContinuousCSP, continuous_csp
from csplab.continuous.lattice import Lattice
from csplab.continuous.model import Polygon, PolygonModel
from csplab.continuous.polyhedra import PolyhedralModel

__all__ = [
    "Arrangement",
    "ContinuousCSP",
    "Lattice",
    "Polygon",
    "PolygonModel",
    "PolyhedralModel",
    "Synthesis",
    "Violations",
    "continuous_csp",
    "synthesize",
    "violations",
]


def __getattr__(name: str) -> Any:
    if name in ("synthesize", "Synthesis"):
        from csplab.continuous import synthesis

        return getattr(synthesis, name)
    raise AttributeError(f"module 'csplab.continuous' has no attribute {name!r}")
