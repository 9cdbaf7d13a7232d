import math
from collections import Counter

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from csplab import ExampleModel, grids
from csplab.errors import InputError
from csplab.experiments.measures import label_counts, pattern_counts
from csplab.experiments.uniform import StripSampler
from csplab.grids import from_example
from csplab.testing import brute
from csplab.testing.strategies import example_models


@settings(max_examples=40)
@given(example_models(ndim=2, max_side=3, max_labels=3), st.integers(1, 5), st.integers(1, 3),
       st.sampled_from(["none", "faces"]))  # fmt: skip
def test_counts_and_frequencies_match_brute_force(E, L, w, bnd):
    boundary = {"x-": 0, "y+": 0} if bnd == "faces" else None
    P = from_example(E, (L, w), boundary=boundary)
    S = StripSampler(P)
    sols = list(brute.solutions(P))
    assert S.count() == len(sols)
    if not sols:
        assert not S.satisfiable
        return
    assert math.exp(S.log_count) == pytest.approx(len(sols))
    lab = np.mean([label_counts(g, P.K) for g in sols], axis=0)
    assert np.allclose(S.label_frequencies(), lab)
    if L >= 2 and w >= 2:
        pc = np.mean([pattern_counts(g, 2, P.K) for g in sols], axis=0)
        pf = S.pattern_frequencies(2)
        dense = np.zeros_like(pc)
        for c, v in pf.items():
            dense[c] = v
        assert np.allclose(dense, pc)
    g = S.sample(rng=1)
    assert P.is_solution(g)
    many = S.sample_many(5, rng=2)
    assert all(P.is_solution(x) for x in many)


def test_samples_are_uniform():
    E = ExampleModel([[0, 0, 0], [1, 2, 2], [0, 1, 2]])
    P = from_example(E, (4, 3))
    S = StripSampler(P)
    n = S.count()
    assert 5 < n < 100
    for draw in (lambda i: S.sample(rng=i), None):
        if draw is None:
            grids = list(S.sample_many(200 * n, rng=7))
        else:
            grids = [draw(i) for i in range(200 * n)]
        cnt = Counter(g.tobytes() for g in grids)
        assert len(cnt) == n
        chi2 = sum((c - 200) ** 2 / 200 for c in cnt.values())
        assert chi2 < n - 1 + 5 * math.sqrt(2 * (n - 1))  # far from any bias


def test_refuses_wide_or_wrapped_problems():
    E = ExampleModel([[0, 1], [1, 0]])
    with pytest.raises(InputError, match="neighbours"):
        StripSampler(from_example(E, (4, 4), periodic=True))
    anything = grids.grid((3, 9), np.ones((2, 2, 2), dtype=bool))  # 512 states per slice
    with pytest.raises(InputError, match="states"):
        StripSampler(anything, max_states=10)
    assert StripSampler(grids.grid((3, 4), np.ones((2, 2, 2), dtype=bool))).count() == 2**12
