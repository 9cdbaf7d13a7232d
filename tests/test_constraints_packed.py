"""The packed set propagators of count and connectivity (Propagator.constrain on bitsets,
csplab._kernels.connected_prune / connected_unchanged) against the unpacked ones
(propagate_all on the bool catalog), and Alg. 3.1's outputs with them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import csplab
from csplab import ExampleModel
from csplab.catalog import Propagator
from csplab.constraints import Connected, Count, parse_constraints
from csplab.grids import from_example

DATA = Path(__file__).parent / "io" / "data"
E3 = ExampleModel([[0, 1, 2, 0], [2, 0, 1, 1], [1, 2, 0, 2]])
E3D = ExampleModel(np.array([[[0, 1], [1, 2]], [[2, 0], [1, 1]], [[1, 2], [0, 0]]]))


def _constraint_sets(P, rng):
    cells = tuple(int(c) for c in rng.choice(P.n, size=int(rng.integers(0, 3)), replace=False))
    lab = sorted(int(b) for b in rng.choice(P.K, size=int(rng.integers(1, 3)), replace=False))
    lo = int(rng.integers(0, P.n // 2))
    region = None
    if rng.random() < 0.5:
        region = tuple((0, int(rng.integers(0, s))) for s in P.shape)
    return [
        [Connected(lab, cells=cells)],
        [Count(lab, min=lo, max=lo + int(rng.integers(0, 4)), region=region)],
        [Connected(lab), Count(lab, min=lo, max=None)],
        [Connected(lab, cells=cells), Count(lab[:1], max=int(rng.integers(0, 3)))],
    ][int(rng.integers(0, 4))]


@pytest.mark.parametrize("ex,shape", [(E3, (5, 6)), (E3, (7, 4)), (E3D, (4, 3, 3))])
def test_packed_constrain_equals_the_unpacked_one(ex, shape):
    """Same verdict and, when the catalog survives, the same catalog."""
    rng = np.random.default_rng(7)
    base = from_example(ex, shape)
    agree = pruned = refuted = 0
    for _ in range(120):
        P = base.with_constraints(_constraint_sets(base, rng))
        a = Propagator(P)
        for c in rng.choice(P.n, size=int(rng.integers(0, P.n // 2)), replace=False):
            if not a.restrict(int(c), rng.random(P.K) < 0.8):
                break
        if not a.ok:
            continue
        b = a.copy()
        before = a.catalog()
        ga, gb = a.constrain(), b.constrain_unpacked()
        assert (ga == -1) == (gb == -1), [c.describe(P) for c in P.constraints]
        if ga == -1:
            assert np.array_equal(a.catalog(), b.catalog())
            pruned += int(not np.array_equal(a.catalog(), before))
        else:
            refuted += 1
        agree += 1
    assert agree > 40 and pruned > 5 and refuted > 5  # the comparison saw both outcomes


def test_connected_prune_removes_strays_and_forces_separating_cells():
    # a 1x7 strip, must at both ends: every middle cell separates them; a cut between
    # them refutes; an open end cut off leaves the set
    P = from_example(E3, (1, 7)).with_constraints([Connected([1])])
    can = np.ones(7, dtype=bool)
    must = np.zeros(7, dtype=bool)
    must[[0, 6]] = True
    leave, join = P.constraints[0].prune_sets(P, can.copy(), must.copy())
    assert leave.tolist() == [] and join.tolist() == [1, 2, 3, 4, 5]
    can[5] = False
    assert P.constraints[0].prune_sets(P, can.copy(), must.copy()) is None
    must[6] = False
    can[6] = True
    leave, join = P.constraints[0].prune_sets(P, can.copy(), must.copy())
    assert leave.tolist() == [6] and join.tolist() == []


def test_unchanged_judgement_never_hides_a_stray():
    """When connected_unchanged says a shrunken state prunes nothing new, the full
    propagator removes no cell from the set there either."""
    rng = np.random.default_rng(3)
    for shape in [(6, 6), (4, 4, 3)]:
        P = from_example(E3 if len(shape) == 2 else E3D, shape)
        con = Connected([1])
        Q = P.with_constraints([con])
        judged = 0
        for _ in range(400):
            can = rng.random(P.n) < 0.75
            must = can & (rng.random(P.n) < 0.2)
            got = con.prune_sets(Q, can.copy(), must.copy())
            if got is None:
                continue
            can[got[0]] = False  # the fixpoint of this constraint
            must[got[1]] = True
            if con.prune_sets(Q, can.copy(), must.copy()) is None:
                continue
            c2, m2 = can.copy(), must.copy()
            for x in rng.choice(P.n, size=2, replace=False):
                if c2[x] and not m2[x]:
                    c2[x] = rng.random() < 0.5
                    m2[x] = c2[x] and rng.random() < 0.5
            if con.prunes_nothing_new(Q, c2, m2, (can, must)):
                judged += 1
                again = con.prune_sets(Q, c2.copy(), m2.copy())
                assert again is not None and again[0].size == 0
        assert judged > 20


def test_alg31_outputs_honour_connectivity_and_count():
    P = csplab.examples.load_model(DATA / "pipes.xml").problem((16, 16))
    Q = P.with_constraints(parse_constraints(
        [{"type": "connected", "labels": ["line", "corner", "tee", "cross"]},
         {"type": "count", "labels": ["cross"], "max": 1}], P))  # fmt: skip
    solved = 0
    for seed in range(4):
        r = csplab.solve(Q, "catalog", rng=seed, restarts=5)
        assert r.status in ("solved", "failed")
        if r.status == "solved":
            solved += 1
            assert not Q.violations(r.grid)
    assert solved >= 2


def test_seqcounter_allows_exactly_the_assignments_within_the_bound():
    pytest.importorskip("pysat")
    import itertools

    from pysat.solvers import Solver

    from csplab.constraints import seqcounter

    for n in range(1, 6):
        for k in range(n + 1):
            cl, top = seqcounter(np.arange(1, n + 1), k, n)
            assert top >= n
            with Solver("cadical195", bootstrap_with=cl) as S:
                for bits in itertools.product([0, 1], repeat=n):
                    got = S.solve(
                        assumptions=[i + 1 if b else -(i + 1) for i, b in enumerate(bits)]
                    )
                    assert got == (sum(bits) <= k), (n, k, bits)


def test_adder_card_allows_exactly_the_counts_within_the_bounds():
    pytest.importorskip("pysat")
    import itertools

    from pysat.solvers import Solver

    from csplab.constraints import adder_card

    for n in range(1, 6):
        for lo in range(n + 2):
            for hi in [None, *range(n + 1)]:
                cl, _ = adder_card(list(range(1, n + 1)), lo, hi, n)
                with Solver("cadical195", bootstrap_with=cl) as S:
                    for bits in itertools.product([0, 1], repeat=n):
                        lits = [i + 1 if b else -(i + 1) for i, b in enumerate(bits)]
                        k = sum(bits)
                        assert S.solve(assumptions=lits) == (lo <= k and (hi is None or k <= hi))
