import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from csplab import ExampleModel, Problem, load_example, solve
from csplab.errors import InputError, NoTrivialSolutionError
from csplab.solvers.blocks import block_starts, trivial_solution
from csplab.testing.strategies import problems


@given(problems(max_side=5, fixed=False, masks=False), st.integers(0, 2**31))
def test_blocks_with_full_size_block_equals_alg_3_1(P, seed):
    try:
        trivial_solution(P)
    except NoTrivialSolutionError:
        return
    a = solve(P, "catalog", rng=seed)
    b = solve(P, "blocks", rng=seed, block=max(P.shape), retries=0)
    assert b.stats["blocks_tried"] == 1
    if a.status == "solved":
        assert b.stats["blocks_accepted"] == 1
        assert np.array_equal(a.grid, b.grid)
    else:
        assert b.stats["blocks_accepted"] == 0


@given(problems(max_side=6, fixed=False, masks=False), st.integers(1, 4), st.integers(0, 99))
def test_blocks_output_always_consistent(P, m, seed):
    try:
        trivial_solution(P)
    except NoTrivialSolutionError:
        return
    r = solve(P, "blocks", rng=seed, block=m, retries=2)
    assert r.status == "solved" and r.stats["final_violations"] == 0


def test_block_starts_cover_everything():
    for n in range(1, 30):
        for m in range(1, 12):
            s = block_starts(n, m)
            mm = min(m, n)
            covered = np.zeros(n, bool)
            for a in s:
                covered[a : a + mm] = True
                assert a + mm <= n
            assert covered.all()


def test_trivial_solution_layers_and_errors():
    E = ExampleModel(np.array([[[1, 0, 0]] * 2] * 2))  # ground below empty space
    P = Problem.from_example(E, (4, 4, 3), boundary="auto")
    g = trivial_solution(P)
    assert (g[:, :, 0] == 1).all() and (g[:, :, 1:] == 0).all()
    # no empty space: the checkerboard starts from an Alg. 3.1 run
    g = trivial_solution(Problem.from_example(load_example("E1"), (4, 4)))
    assert Problem.from_example(load_example("E1"), (4, 4)).is_solution(g)
    with pytest.raises(NoTrivialSolutionError, match="unsatisfiable"):
        trivial_solution(Problem.from_example(load_example("E3"), (5, 5)))
    # a parity constraint arc consistency cannot see: a checkerboard on an odd torus
    P = Problem.from_example(load_example("E1"), (3, 3), periodic=True)
    with pytest.raises(NoTrivialSolutionError, match="failed 5 times"):
        trivial_solution(P)


def test_blocks_from_given_init_and_bad_init():
    P = Problem.from_example(load_example("line"), (10, 8))
    init = solve(P, "catalog", rng=1).grid
    r = solve(P, "blocks", rng=2, init=init, block=4)
    assert r.ok and r.stats["init"] == "given"
    bad = init.copy()
    bad[0, 0] = 1
    bad[0, 1] = 1
    with pytest.raises(InputError):
        solve(P, "blocks", rng=2, init=bad)
    with pytest.raises(InputError):
        solve(P, "blocks", rng=2, block=0)


def test_block_stats_and_timeout():
    P = Problem.from_example(load_example("line"), (20, 20))
    r = solve(P, "blocks", rng=0, block=(6, 6))
    assert r.stats["blocks_tried"] == len(block_starts(20, 6)) ** 2
    assert r.stats["blocks_accepted"] + 0 <= r.stats["blocks_tried"]
    t = solve(P, "blocks", rng=0, block=4, time_limit=0.0)
    assert t.status == "timeout" and P.is_solution(t.grid)
