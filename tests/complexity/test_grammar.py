"""Theorems 5.2.1 (rows a^i b^i c^i forced) and 5.2.3 (regular grammar of a 1D example)."""

import numpy as np
import pytest
from hypothesis import given, settings

from csplab import ExampleModel
from csplab.complexity.grammar import RegularGrammar, abc_example, abc_figure, abc_rows_ok
from csplab.count import count_solutions
from csplab.engine.sat import enumerate_solutions
from csplab.grids import from_example
from csplab.testing.strategies import example_models

FACES = {f: 0 for f in ("x-", "x+", "y-", "y+")}


@pytest.mark.parametrize("shape", [(5, 5), (8, 7), (9, 9), (11, 9), (8, 12)])
def test_every_consistent_model_has_only_abc_rows(shape):
    P = from_example(abc_example(), shape, boundary=FACES)
    n, sizes = 0, set()
    for g in enumerate_solutions(P):
        sizes.update(abc_rows_ok(g))
        n += 1
    assert n == int(count_solutions(P))
    nx, ny = shape  # every figure that fits occurs
    assert sizes == {i for i in range(1, nx) if 3 * i <= nx - 2 and 2 * i + 1 <= ny - 2}


def test_figures_are_consistent_and_other_rows_are_not():
    E = abc_example()
    for i in (1, 2, 3, 5):
        g = abc_figure(i)
        assert from_example(E, g.shape, boundary=FACES).is_solution(g)
    g = abc_figure(3)
    g[7, 4] = 0  # drop the last c: the row is a^3 b^3 c^2
    with pytest.raises(ValueError, match="not a\\^i"):
        abc_rows_ok(g)
    assert not from_example(E, g.shape, boundary=FACES).is_solution(g)


@settings(max_examples=30)
@given(example_models(ndim=1, max_side=6, max_labels=4))
def test_regular_grammar_generates_exactly_the_consistent_models(E):
    G = RegularGrammar.from_example(E)
    counts = G.count(12)
    for n in range(1, 13):
        P = from_example(E, (n,))
        c = int(count_solutions(P))
        assert counts[n] == c
        if c <= 3000:
            gen = G.generate(n)[n]
            sols = {tuple(int(v) for v in g) for g in enumerate_solutions(P)}
            assert gen == sols
            for s in list(sols)[:20]:
                assert G.accepts(s)


def test_grammar_rejects_inconsistent_strings():
    E = ExampleModel(np.array([0, 1, 2, 0]))
    G = RegularGrammar.from_example(E)
    assert G.accepts([0, 1, 2, 0, 1]) and not G.accepts([0, 1, 2, 0, 0])
    assert not G.accepts([0, 2]) and not G.accepts([])
    with pytest.raises(ValueError, match="1D"):
        RegularGrammar.from_example(abc_example())
