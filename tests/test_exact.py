import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from csplab import ExampleModel, example_names, grids, load_example
from csplab.errors import InputError
from csplab.grids import from_example
from csplab.testing import brute
from csplab.testing.strategies import csp_problems

pytest.importorskip("pysat")
from csplab.exact import catalog_gap, exact_catalog, explain_unsat, is_consistent

FALLIBLE = ExampleModel([[0, 0, 0, 2], [2, 0, 0, 1], [0, 1, 2, 1]])


@given(csp_problems(max_cells=10), st.integers(0, 2**31))
def test_exact_catalog_equals_brute_force(P, seed):
    rng = np.random.default_rng(seed)
    partial = np.full(P.n, -1)
    for c in rng.choice(P.n, size=min(2, P.n), replace=False):
        if rng.random() < 0.6:
            partial[c] = rng.integers(P.K)
    X = exact_catalog(P, partial)
    B = brute.exact_catalog(P, partial)
    assert np.array_equal(X.exact, B)
    assert X.consistent == bool(B.any()) == is_consistent(P, partial)
    assert not (X.exact & ~X.catalog).any()  # Theorem 3.3.2: C* <= C
    assert np.array_equal(X.gap, X.catalog & ~X.exact)


def _first_gap(P, seeds=range(40), order="scanline"):
    """A run of Alg. 3.1 that chose a label of C outside C*, checked by brute force."""
    for s in seeds:
        v = catalog_gap(P, rng=s, order=order)
        if v.holds is False and v.witness is not None:
            t = v.witness["step"]
            partial = np.full(P.n, -1)
            for cell, lab, _inside in v.stats["per_step"][:t]:
                partial[P.cell(cell)] = lab
            X = exact_catalog(P, partial)
            c, b = P.cell(v.witness["cell"]), v.witness["label"]
            return s, v, X, c, b
    return None


def test_fallible_example_shows_c_differs_from_cstar():
    small = from_example(FALLIBLE, (4, 4))  # 5445 solutions: brute force is quick
    X = exact_catalog(small)
    assert X.consistent and X.gap.sum() == 9
    assert np.array_equal(X.exact, brute.exact_catalog(small))
    P = from_example(FALLIBLE, (5, 5))
    found = _first_gap(P)
    assert found is not None
    _s, v, X, c, b = found
    assert X.catalog[c, b] and not X.exact[c, b]  # in C, not in C* (Fig. 3.5)
    assert v.stats["alg31_status"] == "failed" and v.witness["steps_until_failure"] >= 1


@pytest.mark.skipif("fig3_5a" not in example_names(), reason="fig3_5a not built in yet")
def test_fig3_5_reproduction():
    """Thesis Fig. 3.5: with a 2 in M_t, two cells to its right C* holds only the 6, while
    the catalog C still holds other labels such as the 1; choosing the 1 empties the
    catalog (Fig. 3.5(e-g)); Alg. 3.1 runs into this gap."""
    from csplab.catalog import propagate

    E = load_example("fig3_5a")
    P = from_example(E, (6, 4))
    partial = np.full(P.shape, -1)
    partial[0, 0] = 2
    X = exact_catalog(P, partial)
    right = P.cell((2, 0))
    assert np.flatnonzero(X.exact[right]).tolist() == [6]
    assert X.catalog[right, 1] and X.gap[right].sum() >= 2
    assert np.array_equal(X.exact, brute.exact_catalog(P, partial))
    dom = P.domains.copy()
    dom[P.cell((0, 0))] = np.eye(P.K, dtype=bool)[2]
    dom[right] = np.eye(P.K, dtype=bool)[1]
    assert propagate(P, dom)[1] is False  # the catalog becomes empty
    # scanline runs never fail on it; in random order about 4% of 8x6 runs do
    found = _first_gap(from_example(E, (8, 6)), range(200), order="random")
    assert found is not None
    _s, _v, X2, c, b = found
    assert X2.catalog[c, b] and not X2.exact[c, b]


def test_catalog_gap_on_infallible_and_unsat_problems():
    P = from_example(load_example("line"), (6, 6))
    v = catalog_gap(P, rng=3, sizes=True)
    assert v.holds is True and len(v.stats["per_step"]) == P.n
    assert all(row[3] == row[4] for row in v.stats["per_step"])  # C = C* (infallible)
    odd = grids.grid((5,), [[[False, True], [True, False]]], periodic=True)
    w = catalog_gap(odd, rng=0)
    assert w.holds is False and "unsatisfiable" in w.message
    ac = catalog_gap(from_example(load_example("fig3_1d"), (5, 5)), rng=0)
    assert ac.holds is True and "arc consistency" in ac.message


@given(csp_problems(max_cells=9))
def test_explanations_are_minimal_unsatisfiable_subsets(P):
    v = explain_unsat(P)
    sat = brute.count(P) > 0
    if sat:
        assert v.holds is False and P.is_solution(v.witness)
        return
    assert v.holds is True and v.witness["minimal"]
    core = v.witness["core"]
    assert brute.count(P.without_unary(core)) == 0
    for i in range(len(core)):
        assert brute.count(P.without_unary(core[:i] + core[i + 1 :])) > 0


def test_explanation_names_the_conflicting_boundary_and_cells():
    E = ExampleModel([[1, 0, 0], [1, 0, 0], [1, 0, 0]])  # ground under empty space
    fixed = {(1, 1): 0, (2, 2): 0, (3, 3): 0}
    P = from_example(E, (4, 4), boundary={"y-": 1, "y+": 1}, fixed=fixed)
    v = explain_unsat(P)
    assert v.witness["unary"] == ["boundary face y+ = 1 (4 cells)"]
    Q = from_example(E, (4, 4), fixed={(0, 0): 0, (0, 1): 1, (3, 3): 0})
    w = explain_unsat(Q)
    assert sorted(w.witness["unary"]) == ["fixed cell (0, 1) = 1"]
    assert explain_unsat(from_example(load_example("fig3_1d"), (5, 5))).witness["core"] == []


def test_time_limits_and_bad_partials():
    P = from_example(FALLIBLE, (30, 30))
    X = exact_catalog(P, time_limit=0.05)
    assert not X.complete and X.undecided is not None
    assert not (X.exact & X.undecided).any()
    with pytest.raises(InputError):
        exact_catalog(P, np.zeros((3, 3), dtype=int))
    with pytest.raises(InputError):
        exact_catalog(P, np.full((30, 30), 7))
