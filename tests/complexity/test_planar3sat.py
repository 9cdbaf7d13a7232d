"""csplab.complexity.planar3sat: planar comb drawings, sign modes, reproducibility."""

import pytest

from csplab.complexity.planar3sat import Clause, Planar3SAT, random_planar3sat, unsat_signs
from csplab.errors import InputError


@pytest.mark.parametrize("seed", range(12))
def test_random_instances_are_planar_and_reproducible(seed):
    n = 3 + seed % 6
    m = min(2 * (n - 2), 1 + seed)
    f = random_planar3sat(n, m, rng=seed)
    assert f.is_planar() and len(f.clauses) == m and f.seed == seed
    assert f == random_planar3sat(n, m, rng=seed)
    assert f.satisfiable() == (len(f.models()) > 0)
    for row in f.models():
        assert f.evaluate(row)


@pytest.mark.parametrize("n,m", [(6, 8), (7, 10), (8, 12)])
def test_unsat_and_near_modes(n, m):
    assert not random_planar3sat(n, m, rng=1, signs="unsat").satisfiable()
    near = random_planar3sat(n, m, rng=1, signs="near")
    assert near.satisfiable() and len(near.models()) > 0


def test_unsat_signs_cover_every_assignment():
    trips = [(0, 1, 2), (0, 2, 3)]
    assert unsat_signs(4, trips, rng=0) is None  # 2 clauses falsify at most 4 of 16
    f = random_planar3sat(6, 8, rng=3, signs="unsat")
    assert f.models().shape[0] == 0


def test_crossing_clauses_are_rejected_and_errors_are_clear():
    with pytest.raises(InputError, match="cross"):
        Planar3SAT(5, (Clause((0, 2, 4), (True,) * 3, 1), Clause((1, 3, 4), (True,) * 3, 1)))
    with pytest.raises(InputError, match="at most 2"):
        random_planar3sat(3, 3, rng=0)
    with pytest.raises(InputError, match="at least 3"):
        random_planar3sat(2, 1, rng=0)
    with pytest.raises(InputError, match="signs"):
        random_planar3sat(5, 3, rng=0, signs="bogus")


def test_leg_order_puts_nested_legs_inside():
    f = random_planar3sat(8, 12, rng=5)
    order = f.leg_order()
    assert sum(len(v) for v in order.values()) == 3 * len(f.clauses)
