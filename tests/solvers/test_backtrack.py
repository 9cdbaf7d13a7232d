import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from csplab import ExampleModel, grids, solve
from csplab.errors import InputError
from csplab.grids import from_example
from csplab.solvers.backtrack import luby
from csplab.testing.brute import count
from csplab.testing.strategies import csp_problems
from csplab.testing.synthetic import box_town


def test_luby_sequence():
    assert [luby(i) for i in range(1, 16)] == [1, 1, 2, 1, 1, 2, 4, 1, 1, 2, 1, 1, 2, 4, 8]


@given(csp_problems(), st.sampled_from(["min-domain", "scanline"]), st.sampled_from([0, 1, 3, 100]),
       st.sampled_from(["uniform", "weighted"]), st.integers(0, 2**31))  # fmt: skip
def test_complete_and_correct(P, order, restart, choice, seed):
    r = solve(P, "backtrack", rng=seed, order=order, restart=restart, choice=choice)
    assert r.status in ("solved", "unsat")
    assert (r.status == "solved") == (count(P) > 0)


def test_refutes_what_arc_consistency_misses():
    P = grids.grid((7,), [[[False, True], [True, False]]], periodic=True)  # odd cycle
    r = solve(P, "backtrack", rng=0, restart=1)
    assert r.status == "unsat" and "exhausted" in r.stats["proof"] and r.stats["nodes"] > 0


def test_scanline_without_restarts_is_alg31_with_backtracking():
    # a fallible example: Alg. 3.1 fails, backtracking on the same order recovers
    E = ExampleModel([[0, 0, 0, 2], [2, 0, 0, 1], [0, 1, 2, 1]])
    P = from_example(E, (8, 8))
    assert all(solve(P, "catalog", rng=s).status == "failed" for s in range(5))
    for s in range(5):
        r = solve(P, "backtrack", rng=s, order="scanline", restart=0)
        assert r.status == "solved" and r.stats["conflicts"] > 0


def test_large_model_trail_growth_and_limits():
    P = from_example(box_town(1, rng=0), (24, 24, 8), boundary="auto")
    r = solve(P, "backtrack", rng=1)
    assert r.status == "solved"
    r = solve(P, "backtrack", rng=1, node_limit=5)
    assert r.status == "timeout" and r.stats["limit"] == "nodes" and r.stats["nodes"] == 5
    big = from_example(box_town(2, rng=0), (40, 40, 10))
    r = solve(big, "backtrack", rng=0, time_limit=0.2)
    assert r.status in ("timeout", "solved") and r.time_s < 1.2
    with pytest.raises(InputError):
        solve(P, "backtrack", rng=0, order="diagonal")
    with pytest.raises(InputError):
        solve(P, "backtrack:x", rng=0)
    assert np.all(r.grid >= -1)
