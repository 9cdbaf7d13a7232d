"""csplab.count: exact counts D_E(n) (Sec. 3.2) cross-checked against brute force and #SAT."""

import importlib.util
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings

from csplab import ExampleModel, load_example
from csplab.count import (
    count_solutions,
    enclosed_sets,
    entropy_per_cell,
    frontier_order,
    lower_bound_3_2_1,
)
from csplab.errors import InputError
from csplab.grids import from_example, with_fixed
from csplab.testing import brute
from csplab.testing.strategies import problems, random_problems

HAS_GANAK = importlib.util.find_spec("pyganak") is not None
HAS_AMC = importlib.util.find_spec("pyapproxmc") is not None


def _reference_count(P, c):
    """Brute force when there are few solutions, else the SAT enumeration of the first
    2001 (both must then agree that there are more than 2000) and Ganak when installed."""
    if int(c) <= 2000:
        return brute.count(P)
    from csplab.engine.sat import enumerate_solutions

    assert sum(1 for _ in enumerate_solutions(P, limit=2001)) == 2001
    return int(count_solutions(P, "ganak")) if HAS_GANAK else int(c)


@settings(max_examples=60)
@given(problems(max_side=4, max_labels=3))
def test_transfer_equals_brute_force(P):
    try:  # a rare 3D draw (e.g. 3x4x3, K=3) has a frontier beyond max_states: refused
        c = count_solutions(P, "transfer")
    except InputError:
        assume(False)
    assert c.exact and isinstance(int(c), int)
    assert int(c) == _reference_count(P, c)


@settings(max_examples=40)
@given(random_problems(max_side=3, max_labels=3, max_ndim=3))
def test_transfer_equals_brute_force_random_relations_periodic(P):
    try:  # periodic 3D grids can have huge frontiers: skip those
        c = count_solutions(P, "transfer", max_states=50_000)
    except InputError:
        assume(False)
    assert int(c) == _reference_count(P, c)


@pytest.mark.skipif(not HAS_GANAK, reason="pyganak not installed")
@settings(max_examples=25)
@given(problems(max_side=4, max_labels=4, max_ndim=2))
def test_ganak_equals_transfer(P):
    assert int(count_solutions(P, "ganak")) == int(count_solutions(P, "transfer"))


@pytest.mark.parametrize("shape", [(1, 1), (2, 7), (5, 5), (9, 4), (13, 6)])
def test_d_e0_is_1_and_d_e1_is_2_at_every_size(shape):
    assert int(count_solutions(from_example(load_example("fig3_1a"), shape))) == 1
    assert int(count_solutions(from_example(load_example("fig3_1b"), shape))) == 2


def test_d_e3_is_zero_above_its_own_size():
    E3 = load_example("fig3_1d")
    assert int(count_solutions(from_example(E3, (3, 3)))) >= 1
    for shape in [(4, 3), (3, 4), (4, 4), (5, 5), (4, 1), (1, 4), (8, 2)]:
        assert int(count_solutions(from_example(E3, shape))) == 0


@pytest.mark.parametrize("shape", [(3, 2), (6, 4), (7, 7), (9, 6), (12, 5), (20, 3)])
def test_theorem_3_2_1_and_3_2_2_bounds_on_line(shape):
    E = load_example("line")  # H = the line, 2x1, enclosed by empty space
    assert [h.extent for h in enclosed_sets(E)] == [(2, 1)]
    lo = lower_bound_3_2_1(E, shape)
    assert lo == 2 ** ((shape[0] // 3) * (shape[1] // 2))
    c = count_solutions(from_example(E, shape))
    assert lo <= int(c) <= E.K ** math.prod(shape)


def test_no_enclosed_set_without_self_tiling_empty_space():
    assert enclosed_sets(load_example("fig3_1b")) == []
    assert lower_bound_3_2_1(load_example("fig3_1b"), (5, 5)) == 1


def test_counts_are_python_ints_beyond_64_bits():
    c = count_solutions(from_example(load_example("line"), (8, 30)))
    assert int(c) > 2**64 and c.stats["exact_arithmetic"] == "object"
    # additivity check: fixing the first cell to each label partitions the solutions
    P = from_example(load_example("line"), (8, 30))
    parts = [int(count_solutions(with_fixed(P, {(0, 0): b}))) for b in range(P.K)]
    assert sum(parts) == int(c)


def test_enumerate_and_limits():
    P = from_example(load_example("line"), (3, 3))
    assert int(count_solutions(P, "enumerate")) == brute.count(P)
    with pytest.raises(InputError, match="more than 10"):
        count_solutions(P, "enumerate", limit=10)
    with pytest.raises(InputError, match="too wide"):
        count_solutions(from_example(load_example("line"), (12, 12)), "transfer",
                        max_states=10)  # fmt: skip
    with pytest.raises(InputError):
        count_solutions(P, "magic")


def test_auto_falls_back_beyond_max_states():
    P = from_example(load_example("line"), (6, 6))
    c = count_solutions(P, "auto", max_states=4)
    assert c.method in ("ganak", "enumerate") or c.method == "transfer"
    if HAS_GANAK:
        assert c.method == "ganak" and int(c) == int(count_solutions(P, "transfer"))


@pytest.mark.skipif(not HAS_AMC, reason="pyapproxmc not installed")
def test_approxmc_within_its_tolerance_on_small_models():
    for name, shape in [("fig3_1b", (5, 5)), ("line", (4, 4)), ("line", (5, 4))]:
        P = from_example(load_example(name), shape)
        exact = int(count_solutions(P))
        est = count_solutions(P, "approxmc", rng=1, epsilon=0.8, delta=0.2)
        assert not est.exact
        assert exact / 1.8 <= int(est) <= exact * 1.8


def test_frontier_order_picks_the_narrow_axis():
    P = from_example(load_example("line"), (40, 3))
    order = frontier_order(P)
    assert P.coords(order[1]) == (0, 1)  # x outermost, the 3-cell axis scanned inside


def test_entropy_per_cell_of_builtins():
    for name in ["fig3_1a", "fig3_1b", "line"]:
        E = load_example(name)
        e = entropy_per_cell(E, (4,), (6, 12))
        assert 0.0 <= e["bits_per_cell"] <= math.log2(E.K) + 1e-9
    assert entropy_per_cell(load_example("fig3_1b"), (4,), (6, 12))["bits_per_cell"] == 0.0
    assert entropy_per_cell(load_example("line"), (3,), (4, 8))["bits_per_cell"] > 0.5
    corner = ExampleModel(np.array([[0, 1], [1, 1]]))  # 0 only in a corner: one model
    assert entropy_per_cell(corner, (3,), (4, 8))["bits_per_cell"] == 0.0
