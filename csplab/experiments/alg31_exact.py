"""The exact output distribution of Alg. 3.1 (scan-line order) on tiny problems.

Alg. 3.1 in scan-line order is a random walk down a tree: at step ``t`` it picks a label of
the catalog ``C(x_t)`` with probability ``1/|C(x_t)|`` (or proportional to the label
weights), propagates, and either continues, fails (a domain empties) or finishes.
:func:`alg31_distribution` walks the whole tree with exact rational arithmetic and returns
the probability of every output model and of failure. It is exponential in the number of
cells and meant for problems of a dozen or so cells: it gives exact values for what the
experiments estimate (the success rate of Fig. 3.8, the output distribution compared with
uniform sampling) and checks a claim of Sec. 3.3.6: every consistent model has a positive
probability of being produced by Alg. 3.1.

Examples
--------
>>> from csplab import ExampleModel, from_example
>>> P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))           # checkerboard
>>> d = alg31_distribution(P)
>>> d.failure, sorted(d.outputs.values())
(Fraction(0, 1), [Fraction(1, 2), Fraction(1, 2)])
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from csplab.catalog import Propagator
from csplab.errors import InputError
from csplab.problem import Problem

__all__ = ["Alg31Distribution", "alg31_distribution"]


@dataclass
class Alg31Distribution:
    """``outputs``: model (``bytes`` of its int32 labels) -> probability; ``failure``: the
    probability that Alg. 3.1 fails; ``leaves``: number of tree leaves walked."""

    outputs: dict[bytes, Fraction] = field(default_factory=dict)
    failure: Fraction = Fraction(0)
    leaves: int = 0

    @property
    def success(self) -> Fraction:
        return 1 - self.failure

    def grid(self, key: bytes, shape: tuple[int, ...]) -> np.ndarray:
        return np.frombuffer(key, dtype=np.int32).reshape(shape)


def alg31_distribution(
    problem: Problem, *, choice: str = "uniform", max_leaves: int = 200_000
) -> Alg31Distribution:
    """Exact probabilities of Alg. 3.1's outcomes in scan-line order (see the module
    docstring). Raises :class:`InputError` when the tree has more than ``max_leaves``
    leaves."""
    if choice not in ("uniform", "weighted"):
        raise InputError(f"choice must be uniform or weighted, not {choice!r}")
    n = problem.n
    w = np.asarray(problem.weights, dtype=np.float64)
    out = Alg31Distribution()
    root = Propagator(problem)
    if not root.ok:
        out.failure = Fraction(1)
        out.leaves = 1
        return out
    grid = np.full(n, -1, dtype=np.int32)

    def walk(eng: Propagator, t: int, p: Fraction) -> None:
        if t == n:
            key = grid.copy().tobytes()
            out.outputs[key] = out.outputs.get(key, Fraction(0)) + p
            out.leaves += 1
            return
        labels = eng.domain(t)
        if choice == "weighted" and w[labels].sum() > 0:
            pos = [int(b) for b in labels if w[b] > 0]
            total = Fraction(sum(Fraction(float(w[b])) for b in pos))
            probs = [(b, Fraction(float(w[b])) / total) for b in pos]
        else:
            probs = [(int(b), Fraction(1, labels.size)) for b in labels]
        for b, q in probs:
            e2 = eng.copy()
            grid[t] = b
            if e2.assign(t, b):
                walk(e2, t + 1, p * q)
            else:
                out.failure += p * q
                out.leaves += 1
            if out.leaves > max_leaves:
                raise InputError(f"Alg. 3.1's tree has more than {max_leaves} leaves")
        grid[t] = -1

    walk(root, 0, Fraction(1))
    return out
