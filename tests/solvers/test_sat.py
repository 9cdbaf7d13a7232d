import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from csplab import ExampleModel, grids, solve
from csplab.errors import InputError
from csplab.grids import from_example
from csplab.testing.brute import count
from csplab.testing.strategies import csp_problems
from csplab.testing.synthetic import box_town

pytest.importorskip("pysat")
from csplab.engine.sat import SatOracle, backends, enumerate_solutions

CHECKER = ExampleModel([[0, 1], [1, 0]])
ODD_CYCLE = grids.grid((5,), [[[False, True], [True, False]]], periodic=True)


@pytest.mark.parametrize("backend", backends())
def test_every_listed_backend_solves_and_refutes(backend):
    P = from_example(CHECKER, (4, 3))
    r = solve(P, f"sat:{backend}", rng=0)
    assert r.status == "solved" and r.stats["backend"] == backend
    # 2-colouring an odd cycle: arc consistent, yet unsatisfiable (proof from the solver)
    r2 = solve(ODD_CYCLE, f"sat:{backend}", rng=0)
    assert r2.status == "unsat" and r2.stats["proof"] == f"refutation by {backend}"


def test_aliases_and_unsupported_backends():
    P = from_example(CHECKER, (2, 2))
    assert solve(P, "sat:g4", rng=0).stats["backend"] == "glucose4"
    for bad in ("kissat404", "cd103", "nonesuch"):
        with pytest.raises(InputError):
            solve(P, f"sat:{bad}", rng=0)
    with pytest.raises(InputError):
        solve(P, "sat:lingeling", rng=0, time_limit=1.0)
    with pytest.raises(InputError):
        solve(P, "sat", rng=0, colour="red")


@given(
    csp_problems(max_cells=9),
    st.sampled_from(["lazy", "seqcounter", "ladder", "pairwise"]),
    st.sampled_from(["support", "direct"]),
    st.sampled_from(["cadical195", "glucose4"]),
)
def test_enumeration_matches_brute_force_counts(P, amo, encoding, backend):
    n = sum(1 for _ in enumerate_solutions(P, amo=amo, encoding=encoding, backend=backend))
    assert n == count(P)


@given(csp_problems(), st.sampled_from([{}, {"supports": "forward"}, {"encoding": "direct"},
                                        {"amo": "bitwise"}, {"choice": "none"},
                                        {"choice": "weighted"}]),
       st.integers(0, 2**31))  # fmt: skip
def test_options_solve_correctly(P, opts, seed):
    r = solve(P, "sat", rng=seed, **opts)
    assert r.status in ("solved", "unsat")
    assert (r.status == "solved") == (count(P) > 0)


@given(csp_problems(), st.integers(0, 2**31))
def test_direct_loader_gives_the_solver_the_same_formula(P, seed):
    """The ctypes/numba loader and pysat's API load identical clauses: same model."""
    a = solve(P, "sat", rng=seed, loader="auto")
    b = solve(P, "sat", rng=seed, loader="api")
    assert a.status == b.status
    assert np.array_equal(a.grid, b.grid)
    if a.stats.get("loader"):
        assert a.stats["loader"] == "cadical-direct" and b.stats["loader"] == "pysat-api"


def test_outputs_differ_across_seeds_and_repeat_for_a_seed():
    P = from_example(box_town(1, rng=0), (12, 12, 6), boundary="auto")
    g = [solve(P, "sat", rng=s).grid for s in range(4)]
    assert np.array_equal(g[0], solve(P, "sat", rng=0).grid)
    ham = [np.mean(g[i] != g[j]) for i in range(4) for j in range(i + 1, 4)]
    assert min(ham) > 0.02
    same = [solve(P, "sat", rng=s, choice="none").grid for s in range(2)]
    assert all(P.is_solution(x) for x in same)


def test_oracle_assumptions_cores_and_blocking():
    E = ExampleModel([0, 1, 2, 0])
    P = from_example(E, (6,))
    with SatOracle(P) as o:
        a, b = o.literal(0, 1), o.literal(3, 0)
        assert o.solve([a]) == "sat" and o.grid[0] == 1
        assert o.solve([a, b]) == "unsat" and set(o.core()) <= {a, b}
        seen = set()
        while o.solve() == "sat":
            seen.add(tuple(o.grid.tolist()))
            o.block(o.grid)
        assert len(seen) == 3 == count(P)


def test_lazy_at_most_one_refinement_is_used_when_needed():
    # forward supports leave multi-labelled cells possible: refinement must repair them
    P = from_example(box_town(1, rng=1), (10, 10, 6))
    for s in range(3):
        r = solve(P, "sat", rng=s, supports="forward", choice="none")
        assert r.status == "solved" and r.stats["refinements"] >= 0


def test_time_limit_on_a_large_problem():
    P = from_example(box_town(2, rng=0), (40, 40, 10))
    solve(from_example(CHECKER, (2, 2)), "sat", rng=0)  # load the JIT first
    r = solve(P, "sat", rng=0, time_limit=0.2)
    assert r.status in ("timeout", "solved")
    assert r.time_s < 1.2


def test_free_at_exit_leaves_large_solvers_and_changes_no_output(monkeypatch, tmp_path):
    """With free_at_exit on, close() leaves the native solver unfreed (its delete() is a
    no-op) and only while the per-process cap holds; the outputs are those of the freeing
    path. The CLI switches it on for its one solve and off again after."""
    from csplab import load_example
    from csplab.cli import main
    from csplab.engine import sat as engine_sat

    P = from_example(load_example("castle"), (6, 6, 4))
    freed = solve(P, "sat", rng=3).grid
    monkeypatch.setattr(engine_sat, "_EXIT_MIN_LITERALS", 1)
    monkeypatch.setattr(engine_sat, "_EXIT", {"on": 0, "left": 0})
    engine_sat.free_at_exit()
    try:
        with SatOracle(P, seed=1) as o:
            assert o.solve() == "sat"
            inner = o.solver.solver
        assert o.solver.solver is None and inner.delete is engine_sat._keep
        left = engine_sat._EXIT["left"]
        assert left == o.enc.lits.size > 0
        assert np.array_equal(solve(P, "sat", rng=3).grid, freed)
        monkeypatch.setattr(engine_sat, "_EXIT_MAX_LITERALS", engine_sat._EXIT["left"])
        with SatOracle(P, seed=1) as o:  # over the cap: freed as usual
            inner = o.solver.solver
        assert inner.delete is not engine_sat._keep
    finally:
        engine_sat.free_at_exit(False)
    # off (the default): close() frees, nothing is counted
    monkeypatch.setattr(engine_sat, "_EXIT", {"on": 0, "left": 0})
    with SatOracle(P, seed=1) as o:
        inner = o.solver.solver
    assert inner.delete is not engine_sat._keep and engine_sat._EXIT["left"] == 0
    out = tmp_path / "o.npy"
    assert main(["synthesize", "castle", "--size", "6x6x4", "--solver", "sat", "--seed", "1",
                 "--out", str(out)]) == 0  # fmt: skip
    assert engine_sat._EXIT["on"] == 0 and engine_sat._EXIT["left"] > 0
    assert np.array_equal(np.load(out), solve(P, "sat", rng=1).grid)
