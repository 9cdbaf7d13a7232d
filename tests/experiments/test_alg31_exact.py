from fractions import Fraction

import numpy as np
from hypothesis import given, settings

from csplab import ExampleModel
from csplab.errors import InputError
from csplab.experiments import run
from csplab.experiments.alg31_exact import alg31_distribution
from csplab.experiments.stats import wilson
from csplab.grids import from_example
from csplab.testing import brute
from csplab.testing.strategies import example_models


@settings(max_examples=40)
@given(example_models(ndim=2, max_side=3, max_labels=3))
def test_every_consistent_model_has_positive_probability(E):
    """Sec. 3.3.6: 'there is always a tiny chance that a given model M consistent with E
    could be produced' by Alg. 3.1 -- exactly: its outputs are the solutions."""
    P = from_example(E, (3, 3))
    try:
        d = alg31_distribution(P, max_leaves=20_000)
    except InputError:
        return
    sols = {g.astype(np.int32).tobytes() for g in brute.solutions(P)}
    assert set(d.outputs) == sols
    assert all(p > 0 for p in d.outputs.values())
    assert sum(d.outputs.values()) + d.failure == 1
    dw = alg31_distribution(P, choice="weighted", max_leaves=20_000)
    assert set(dw.outputs) == sols


def test_harness_success_rate_agrees_with_the_exact_probability(tmp_path, fallible_npy):
    E = ExampleModel(np.load(fallible_npy))
    exact = alg31_distribution(from_example(E, (4, 4))).success
    assert exact == Fraction(1, 3)
    _, rep = run("fig3_8", examples=[str(fallible_npy)], sizes=[4], seeds=600, boundary="none",
                 store=tmp_path / "r.sqlite", out=tmp_path, jobs=1, progress=False,
                 figures=False)  # fmt: skip
    (row,) = rep.tables["success rate"]
    lo, hi = wilson(row["solved"], row["trials"], z=3.29)  # 99.9%
    assert lo <= float(exact) <= hi
