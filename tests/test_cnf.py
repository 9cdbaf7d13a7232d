"""csplab.cnf: the support encoding decides completability and enumerates solutions exactly."""

import numpy as np
from hypothesis import assume, given, settings

from csplab.cnf import SupportCNF, complete, enumerate_solutions
from csplab.testing import brute
from csplab.testing.strategies import problems, random_problems


@settings(max_examples=40)
@given(problems(max_side=3, max_labels=3))
def test_complete_agrees_with_brute_force(P):
    sols = list(brute.solutions(P, limit=1))
    r = complete(P, rng=0)
    assert (r.status == "solved") == bool(sols)
    if r.status == "solved":
        assert P.is_solution(r.grid)


@settings(max_examples=40)
@given(random_problems(max_side=3, max_labels=3, max_ndim=2))
def test_enumeration_is_exact(P):
    from csplab.count import count_solutions

    assume(int(count_solutions(P)) <= 3000)  # both sides enumerate every solution
    got = {g.tobytes() for g in enumerate_solutions(P)}
    want = {np.asarray(g, dtype=np.int32).tobytes() for g in brute.solutions(P)}
    assert got == want


def test_fixed_cells_are_constants():
    from csplab import ExampleModel, Problem

    P = Problem.from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3), fixed={(0, 0): 1})
    enc = SupportCNF(P)
    assert enc.open_cells.size == 0 and not enc.clauses  # one label forces the whole board
    assert complete(P).status == "solved"
