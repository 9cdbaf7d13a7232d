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

pytest.importorskip("ortools")


@given(csp_problems(max_cells=9), st.sampled_from(["onehot", "table"]),
       st.sampled_from(["hint", "catalog", "none", "polarity"]), st.integers(0, 2**31))  # fmt: skip
def test_both_models_agree_with_brute_force(P, model, diversity, seed):
    r = solve(P, "cpsat", rng=seed, model=model, diversity=diversity)
    assert r.status in ("solved", "unsat")
    assert (r.status == "solved") == (count(P) > 0)
    if r.status == "unsat":
        assert r.stats["proof"]


def test_infeasible_is_a_proof():
    P = grids.grid((5,), [[[False, True], [True, False]]], periodic=True)  # odd cycle
    for model in ("onehot", "table"):
        r = solve(P, "cpsat", rng=0, model=model)
        assert r.status == "unsat" and r.stats["proof"] == "CP-SAT: infeasible"


def test_hints_make_outputs_differ_and_seeds_repeat():
    P = from_example(box_town(1, rng=0), (8, 8, 6), boundary="auto")
    a, b = (solve(P, "cpsat", rng=s) for s in (1, 2))
    assert np.mean(a.grid != b.grid) > 0.02
    assert np.array_equal(a.grid, solve(P, "cpsat", rng=1).grid)
    # without diversity CP-SAT gives the same solution for every seed (documented)
    c, d = (solve(P, "cpsat", rng=s, diversity="none") for s in (1, 2))
    assert np.array_equal(c.grid, d.grid)


def test_catalog_hint_is_confirmed_on_the_forward_model():
    from csplab.engine.alg31 import run_alg31

    P = from_example(box_town(1, rng=0), (8, 8, 6), boundary="auto")
    r = solve(P, "cpsat", rng=5)  # default: diversity="catalog", supports="auto"
    assert r.stats["hint"] == "catalog solution" and r.stats["supports"] == "forward"
    rng = np.random.default_rng(5)
    rng.integers(2**31 - 1)  # the solver draws CP-SAT's seed first
    hint = run_alg31(P, rng)
    assert hint.status == "solved"
    assert np.array_equal(r.grid, hint.grid)  # a complete feasible hint is kept as it is
    assert len(P.violations(r.grid)) == 0
    both = solve(P, "cpsat", rng=5, supports="both")
    assert both.stats["supports"] == "both" and np.array_equal(both.grid, r.grid)
    # random labels as the hint (the former default): both directions, CP-SAT repairs
    h = solve(P, "cpsat", rng=5, diversity="hint")
    assert "hint" not in h.stats and h.stats["supports"] == "both"
    assert len(P.violations(h.grid)) == 0


def test_options_and_time_limit():
    P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 3))
    assert solve(P, "cpsat", rng=0, num_workers=2, presolve=True).status == "solved"
    for bad in ({"model": "mip"}, {"diversity": "lots"}, {"num_workers": 0}, {"x": 1}):
        with pytest.raises(InputError):
            solve(P, "cpsat", rng=0, **bad)
    big = from_example(box_town(2, rng=0), (40, 40, 10))
    r = solve(big, "cpsat", rng=0, time_limit=0.3)
    assert r.status == "timeout" and r.time_s < 1.3

