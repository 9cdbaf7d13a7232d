"""Complexity tools for the thesis' negative and structural results.

* :mod:`csplab.complexity.planar3sat`: random planar 3-SAT formulas with a
  Knuth–Raghunathan drawing (variables on a line, clauses as combs).
* :mod:`csplab.complexity.gadgets`: the labels and transition matrices of the
  Theorem 3.3.4 / Fig. 3.7 reduction (enclosure, TRUE/FALSE fill, NOT and OR gates).
* :mod:`csplab.complexity.reduction`: the layout of a formula as an incomplete model
  ``M_t``, decoding and encoding of solutions, pictures and the verification.
* :mod:`csplab.complexity.lba`: linear-bounded automata and Theorem 5.2.4's construction.
* :mod:`csplab.complexity.grammar`: Theorem 5.2.1's example and Theorem 5.2.3's regular
  grammar.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from csplab.problem import Problem
    from csplab.result import Result
    from csplab.rng import RngLike

__all__ = ["complete_model"]


def complete_model(problem: Problem, rng: RngLike = None) -> Result:
    """Decide whether an incomplete model can be completed, with a completion.

    The reductions use this one function (the complete ``sat`` solver,
    ``csplab.solve(problem, "sat")``: status ``solved`` with a checked grid, or ``unsat``
    with a proof); it is the single place to switch to another complete solver.
    """
    from csplab.solvers import solve

    return solve(problem, "sat", rng=rng)
