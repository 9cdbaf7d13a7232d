import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from csplab.experiments.stats import (
    bootstrap_ci,
    jensen_shannon,
    median_iqr,
    total_variation,
    wilson,
)


@given(st.integers(1, 500), st.data())
def test_wilson_interval_contains_the_estimate_and_shrinks(n, data):
    k = data.draw(st.integers(0, n))
    lo, hi = wilson(k, n)
    assert 0 <= lo <= k / n <= hi <= 1
    lo4, hi4 = wilson(4 * k, 4 * n)
    assert hi4 - lo4 < hi - lo + 1e-12


def test_wilson_known_values():
    # Newcombe (1998) Table I, method 3: 81/263 -> 0.2553 .. 0.3662
    lo, hi = wilson(81, 263)
    assert (round(lo, 4), round(hi, 4)) == (0.2553, 0.3662)
    assert wilson(0, 10)[0] == 0 and wilson(10, 10)[1] == 1
    with pytest.raises(ValueError):
        wilson(3, 2)


def test_wilson_coverage_is_close_to_95_percent():
    rng = np.random.default_rng(0)
    p, n = 0.3, 40
    ks = rng.binomial(n, p, size=4000)
    cover = np.mean([wilson(int(k), n)[0] <= p <= wilson(int(k), n)[1] for k in ks])
    assert 0.93 < cover < 0.97


@given(st.lists(st.floats(0, 10), min_size=3, max_size=8), st.data())
def test_divergences_are_metrics_like(p, data):
    q = data.draw(st.lists(st.floats(0, 10), min_size=len(p), max_size=len(p)))
    if sum(p) == 0 or sum(q) == 0:
        return
    assert total_variation(p, p) == pytest.approx(0, abs=1e-12)
    assert 0 <= total_variation(p, q) <= 1 + 1e-12
    assert total_variation(p, q) == pytest.approx(total_variation(q, p))
    assert -1e-12 <= jensen_shannon(p, q) <= 1 + 1e-12
    assert jensen_shannon(p, q) == pytest.approx(jensen_shannon(q, p), abs=1e-12)


def test_bootstrap_and_median():
    est, lo, hi = bootstrap_ci(np.arange(1000.0), np.mean, rng=3, n_boot=300)
    assert est == 499.5
    assert lo < 499.5 < hi and hi - lo < 60
    assert median_iqr([3.0, 1.0, 2.0]) == (2.0, 1.5, 2.5)
    assert all(math.isnan(v) for v in median_iqr([]))
