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

    The reductions use this one function: one query of the completability oracle
    (:class:`~csplab.engine.completability.SatCompletability`, complete), diversified as
    the ``sat`` solver (a seeded CaDiCaL, random decision phases from ``rng``; the same
    seed gives the same completion as ``csplab.solve(problem, "sat", rng=seed)``).
    Returns a :class:`~csplab.result.Result` of solver ``"sat"``: status ``solved`` with a
    checked grid, or ``unsat`` with a proof (``stats["proof"]``). It is the single place to
    switch to another complete method.

    Examples
    --------
    >>> from csplab import ExampleModel, from_example
    >>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3), fixed={(0, 0): 1})
    >>> r = complete_model(P, rng=1)
    >>> r.status, r.grid[0].tolist()
    ('solved', [1, 0, 1])
    >>> from csplab.grids import with_fixed
    >>> r = complete_model(with_fixed(P, {(1, 1): 0}), rng=1)
    >>> r.status, r.stats["proof"]
    ('unsat', 'arc-consistency wipe-out (unit propagation on the support encoding)')
    """
    import time

    import numpy as np

    from csplab.engine.completability import SatCompletability
    from csplab.errors import CsplabError
    from csplab.result import Result, Status
    from csplab.rng import make_rng

    t0 = time.perf_counter()
    gen, seed = make_rng(rng)
    stats: dict[str, object] = {}
    with SatCompletability(problem, rng=gen) as c:
        done = c.completable([], [])
        o = c.oracle
        if done is False:
            stats["proof"] = (
                f"refutation by {o.backend}" if o.enc.ok
                else "arc-consistency wipe-out (unit propagation on the support encoding)"
            )  # fmt: skip
    grid = np.full(problem.shape, -1, dtype=np.int32)
    if done and c.solution is not None:
        grid = c.solution.reshape(problem.shape)
        if len(problem.violations(grid)):
            raise CsplabError("complete_model: the SAT completion is not a solution (a bug)")
    status: Status = "solved" if done else "unsat" if done is False else "timeout"
    return Result(status, grid, "sat", seed=seed, time_s=time.perf_counter() - t0,
                  stats=dict(stats), problem=problem)  # fmt: skip
