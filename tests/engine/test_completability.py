"""csplab.engine.completability: both oracles, the prefix search, C(p)/C*(p) and the
enumerator, each checked against the independent brute-force reference
(csplab.testing.brute) or a plain linear scan."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from csplab import ExampleModel, solve
from csplab.deps import available
from csplab.engine.completability import (
    Completability,
    PrefixTimeout,
    SatCompletability,
    SearchCompletability,
    catalog_at,
    first_inconsistent_prefix,
    make_completability,
    search_solutions,
)
from csplab.errors import InputError
from csplab.examples import load_example
from csplab.grids import from_example
from csplab.testing import brute
from csplab.testing.strategies import csp_problems

FALLIBLE = ExampleModel([[0, 0, 0, 2], [2, 0, 0, 1], [0, 1, 2, 1]])


def _oracles(P):
    """Both implementations (the search oracle alone without python-sat)."""
    return [SearchCompletability(P), *([SatCompletability(P)] if available("pysat") else [])]


def _partial(P, cells, labels):
    g = np.full(P.n, -1, dtype=np.int64)
    g[np.asarray(cells, dtype=np.int64)] = labels
    return g.reshape(P.shape)


@given(csp_problems(max_cells=9), st.integers(0, 2**31))
def test_completable_equals_brute_force(P, seed):
    rng = np.random.default_rng(seed)
    for o in _oracles(P):
        assert isinstance(o, Completability)
        for _ in range(3):
            k = int(rng.integers(0, min(3, P.n) + 1))
            cells = rng.choice(P.n, size=k, replace=False)
            labels = rng.integers(0, P.K, size=k)
            want = brute.satisfiable(P, _partial(P, cells, labels))
            got = o.completable(cells, labels)
            assert got is want
            if got:  # the completion extends the partial model and is a solution
                assert o.solution is not None and P.is_solution(o.solution)
                assert (o.solution[cells] == labels).all()
            else:
                assert o.solution is None


def test_contradictions_and_labels_outside_the_domain():
    P = from_example(FALLIBLE, (3, 3))
    for o in _oracles(P):
        assert o.completable([0, 0], [0, 2]) is False  # one cell, two labels
        assert o.completable([0, 0], [0, 0]) is brute.satisfiable(P, _partial(P, [0], [0]))
        assert o.completable([1], [P.K + 3]) is False
        with pytest.raises(InputError):
            o.completable([0, 1], [0])


def test_fix_adds_the_partial_model_to_every_query():
    P = from_example(FALLIBLE, (4, 4))
    sols = list(brute.solutions(P))
    g = sols[len(sols) // 2].reshape(-1)
    for o in _oracles(P):
        o.fix([0, 5], [int(g[0]), int(g[5])])
        for b in range(P.K):
            want = brute.satisfiable(P, _partial(P, [0, 5, 10], [g[0], g[5], b]))
            assert o.completable([10], [b]) is want


def _linear_first_bad(P, ch):
    """The reference: the first t whose prefix of t + 1 choices has no solution."""
    for t in range(len(ch)):
        if not brute.satisfiable(P, _partial(P, ch[: t + 1, 0], ch[: t + 1, 1])):
            return t
    return None


@pytest.mark.parametrize("seed", range(12))
def test_first_inconsistent_prefix_is_the_linear_scan(seed):
    from csplab.engine.alg31 import run_alg31

    P = from_example(FALLIBLE, (4, 4))
    r = run_alg31(P, np.random.default_rng(seed), order="scanline")
    ch = np.asarray(r.trace, dtype=np.int64)
    want = _linear_first_bad(P, ch)
    assert (want is None) == (r.status == "solved")
    for o in _oracles(P):
        assert first_inconsistent_prefix(o, ch) == want
        if r.status == "failed":
            assert first_inconsistent_prefix(o, ch, full_inconsistent=True) == want
            assert first_inconsistent_prefix(o, ch[:want]) is None  # 0-based: k choices are fine


def test_first_inconsistent_prefix_edges():
    P = from_example(FALLIBLE, (3, 3))
    o = SearchCompletability(P)
    assert first_inconsistent_prefix(o, np.zeros((0, 2), dtype=np.int64)) is None
    assert first_inconsistent_prefix(o, [], full_inconsistent=True) is None
    assert first_inconsistent_prefix(o, [[0, 0], [0, 2]]) == 1
    assert first_inconsistent_prefix(o, [[0, 0], [0, 2]], full_inconsistent=True) == 1
    with pytest.raises(PrefixTimeout):  # a node budget of 0 decides nothing
        first_inconsistent_prefix(SearchCompletability(P, max_nodes=0), [[0, 0], [1, 0]])
    assert SearchCompletability(P, max_nodes=0).completable([], []) is None


@given(csp_problems(max_cells=9), st.integers(0, 2**31))
def test_catalog_at_equals_brute_force(P, seed):
    rng = np.random.default_rng(seed)
    k = int(rng.integers(0, min(2, P.n - 1) + 1))
    cells = rng.choice(P.n, size=k + 1, replace=False)
    prefix, cell = cells[:k], int(cells[k])
    part = _partial(P, prefix, rng.integers(0, P.K, size=k))
    labels = part.reshape(-1)[prefix]
    if not brute.satisfiable(P, part):
        return
    C = brute.exact_catalog(P, part)[cell]
    for o in _oracles(P):
        o.fix(prefix, labels)
        cand, star = catalog_at(o, P, prefix, labels, cell)
        assert set(star) == set(np.flatnonzero(C).tolist())
        assert set(star) <= set(cand.tolist())  # Theorem 3.3.2: C* <= C
        known = star[0] if star else None
        calls = o.calls
        assert catalog_at(o, P, prefix, labels, cell, known=known)[1] == star
        assert o.calls - calls == cand.size - (known is not None)


def test_catalog_at_shows_fig3_5():
    P = from_example(load_example("fig3_5a"), (3, 3))
    cells = [P.cell((0, 0)), P.cell((1, 0))]
    o = SearchCompletability(P)
    o.fix(cells, [2, 0])
    cand, star = catalog_at(o, P, cells, [2, 0], P.cell((2, 0)))
    assert 0 in cand and star == [6]  # label 0 is in C but not in C*


@given(csp_problems(max_cells=8))
def test_search_solutions_is_the_reference_enumeration(P):
    want = [g.tolist() for g in brute.solutions(P)]
    assert [g.tolist() for g in search_solutions(P)] == want  # same order too
    assert [g.tolist() for g in search_solutions(P, limit=2)] == want[:2]
    if want:
        part = np.full(P.n, -1)
        part[0] = np.asarray(want[-1]).reshape(-1)[0]
        part = part.reshape(P.shape)
        sub = [g.tolist() for g in search_solutions(P, part)]
        assert sub and sub == [g.tolist() for g in brute.solutions(P, part)]


def test_make_completability():
    P = from_example(FALLIBLE, (3, 3))
    assert make_completability(P, "search", max_nodes=5).max_nodes == 5
    assert make_completability(P).name in ("sat", "search")
    with pytest.raises(InputError):
        make_completability(P, "brute")


def test_sat_completability_wraps_an_oracle_and_matches_the_sat_solver():
    pytest.importorskip("pysat")
    from csplab.complexity import complete_model
    from csplab.engine.sat import SatOracle

    P = from_example(load_example("fig3_6a"), (9, 5))
    with SatOracle(P) as raw:
        c = SatCompletability(P, oracle=raw)
        assert c.completable([0], [0]) is True
        c.close()  # does not close the oracle it was given
        assert raw.solve() == "sat"
    for seed in range(3):  # complete_model's completion is the sat solver's, seed for seed
        assert np.array_equal(complete_model(P, seed).grid, solve(P, "sat", rng=seed).grid)
