"""Properties of the built-in thesis examples whose grids the thesis text does not pin.

Each example file says which figure it stands for and which property it was designed to
have; these tests check those properties exactly on small outputs (exhaustive search over
every choice of Alg. 3.1, exact catalogs C* by backtracking, solution-set enumeration).
Orders: ``"scan:yx"`` is left to right, then bottom to top (the thesis' 2D figures);
``"scanline"`` is csplab's Alg. 3.1 loop (x outermost).
"""

from __future__ import annotations

import numpy as np
import pytest

from csplab import Problem, solve
from csplab.analysis import alg31_exhaustive, alg36_failure, corner_condition, prove_infallible
from csplab.catalog import Propagator
from csplab.examples import load_example
from csplab.grids import from_example
from tests._brute import assign_all, catalogs, satisfiable, solutions

FIG = "scan:yx"  # the thesis' 2D figures: left to right, then bottom to top
ORDERS = [FIG, "scanline"]


def alg31_failure(P: Problem, order: str) -> tuple[list | None, int]:
    v = alg31_exhaustive(P, order)
    assert v.holds is not None
    return (None if v.holds else v.witness), v.stats["states"]


def corner_holds(name: str) -> bool:
    return bool(corner_condition(load_example(name)).holds)


def window_proof(name: str, region: tuple[int, int]) -> bool | None:
    return prove_infallible(load_example(name), region, order=FIG, refute=False).holds


def problem(name: str, shape: tuple[int, ...], **kw: object) -> Problem:
    return from_example(load_example(name), shape, **kw)  # type: ignore[arg-type]


def successors(T: np.ndarray, axis: int, b: int) -> set[int]:
    return {int(c) for c in np.flatnonzero(T[axis, b])}


def longest_continuation(P: Problem, eng: Propagator, cells: list[int]) -> int:
    """Most further assignments Alg. 3.1 can make (cells in this order) before failing."""
    if not cells:
        return 0
    best = 0
    for b in eng.domain(cells[0]):
        e2 = eng.copy()
        if e2.assign(cells[0], int(b)):
            best = max(best, 1 + longest_continuation(P, e2, cells[1:]))
    return best


# ----------------------------------------------------------------------------- Fig. 3.4(a)


def test_fig3_4a_pieces():
    E = load_example("fig3_4a")
    T = E.transitions()
    assert E.K == 4
    assert successors(T, 1, 1) == {2}  # a 1 needs a 2 above it
    assert successors(T, 0, 1) == {0}  # ... and a 0 to its right
    assert problem("fig3_4a", (5, 5)).is_solution(np.zeros((5, 5), dtype=int))  # Fig. 3.9(a)


@pytest.mark.parametrize("order", ORDERS)
def test_fig3_4a_alg31_never_fails(order):
    for shape in [(3, 3), (4, 4), (4, 5)]:
        fail, states = alg31_failure(problem("fig3_4a", shape), order)
        assert fail is None, fail
        assert states > 100


def test_fig3_4a_region_proof_fails_with_2x2():
    v = corner_condition(load_example("fig3_4a"))
    assert not v.holds and v.witness["labels"] == {"a": 0, "b": 1, "c": 1}
    fail = alg36_failure(load_example("fig3_4a"), (3, 3), (2, 2), order=FIG)
    assert fail.holds is False
    (px, py), label = fail.witness[-1]
    assert label is None  # C_R is empty at p'
    known = {tuple(c): b for c, b in fail.witness[:-1]}
    # Sec. 3.3.7: the bottom 1 needs a 2 above it, the other 1 needs a 0 to its right
    assert known[(px, py - 1)] == 1 and known[(px - 1, py)] == 1
    assert window_proof("fig3_4a", (2, 2)) is None


def test_fig3_4a_region_proof_succeeds_with_3x2():
    assert window_proof("fig3_4a", (3, 2)) is True
    for shape in [(3, 3), (4, 4), (5, 3)]:
        assert alg36_failure(load_example("fig3_4a"), shape, (3, 2), order=FIG).holds


# ----------------------------------------------------------------------------- Fig. 3.5(a)

WITNESS_35 = {(0, 0): 2, (1, 0): 0}  # a scan-order prefix (figure order) on a 3x3 output


def test_fig3_5a_structure():
    T = load_example("fig3_5a").transitions()
    assert successors(T, 1, 2) == {3, 7}  # two paths from the 2
    assert not T[0, 2, 6]  # the 6 is not next to the 2
    assert not T[1, :, 2].any()  # 2s stand in the bottom row


def test_fig3_5a_every_2_has_a_6_two_cells_right():
    n2 = 0
    for shape in [(3, 3), (4, 3), (5, 3), (4, 4)]:
        for s in solutions(problem("fig3_5a", shape)):
            for x, y in zip(*np.nonzero(s == 2), strict=True):
                assert y == 0
                if x + 2 < shape[0]:
                    assert s[x + 2, y] == 6
                    n2 += 1
    assert n2 > 20


def test_fig3_5a_catalog_is_not_exact():
    P = problem("fig3_5a", (3, 3))
    eng = Propagator(P)
    for c, b in WITNESS_35.items():  # each label is in the catalog when it is chosen
        assert b in eng.domain(P.cell(c))
        assert eng.assign(P.cell(c), b)
    C, Cs = catalogs(P, WITNESS_35)
    R = P.cell((2, 0))
    assert set(np.flatnonzero(Cs[R])) == {6}
    assert set(np.flatnonzero(C[R])) == {0, 1, 2, 3, 6, 7}
    above = P.cell((0, 1))
    assert set(np.flatnonzero(C[above])) == {3, 7}
    for bad in (0, 1, 2, 3, 7):  # choosing any of them empties the catalog at once
        e2 = eng.copy()
        assert not e2.assign(R, bad)


def test_fig3_5a_is_fallible():
    fail, _ = alg31_failure(problem("fig3_5a", (3, 3)), FIG)
    assert fail is not None
    eng = assign_all(problem("fig3_5a", (3, 3)), {tuple(c): b for c, b in fail})
    assert not eng.ok
    # csplab's scanline order decides 3 or 7 before it reaches the cell two to the right
    assert alg31_failure(problem("fig3_5a", (4, 4)), "scanline")[0] is None


# ----------------------------------------------------------------------------- Fig. 3.15


def test_fig3_15_is_fig3_5a_with_9_for_enclosed_0():
    EI, EF = load_example("fig3_15"), load_example("fig3_5a")
    assert np.array_equal(np.where(EI.labels == 9, 0, EI.labels), EF.labels)  # Eq. 3.12
    assert (EI.labels == 9).sum() == 3
    assert 9 not in EF.labels


def test_fig3_15_corner_condition():
    assert corner_holds("fig3_15")
    assert not corner_holds("fig3_5a")  # the twin violates it


@pytest.mark.parametrize("order", ORDERS)
def test_fig3_15_alg31_never_fails(order):
    for shape in [(3, 3), (4, 3), (5, 3), (4, 4)]:
        fail, states = alg31_failure(problem("fig3_15", shape), order)
        assert fail is None, fail
        assert states > 100


def test_fig3_15_region_proof_2x2_and_exact_catalog():
    assert window_proof("fig3_15", (2, 2)) is True
    P = problem("fig3_15", (3, 3))
    C, Cs = catalogs(P, {(0, 0): 2, (1, 0): 9})
    assert np.array_equal(C, Cs)
    assert set(np.flatnonzero(C[P.cell((2, 0))])) == {6}


# ----------------------------------------------------------------------------- Fig. 3.6(a)

THREE_2S = [0, 0, 2, 0, 2, 0, 2, 0, 0]  # bottom row of a 9x3 output


def test_fig3_6a_2s_come_in_pairs():
    T = load_example("fig3_6a").transitions()
    assert successors(T, 1, 2) == {3, 5, 6, 7}
    paired = 0
    for shape in [(5, 4), (7, 4), (8, 4)]:
        # structures standing on the bottom row, empty space on the other sides, so that
        # no structure is cut off by an edge of the output
        mask = np.ones((*shape, 9), dtype=bool)
        mask[:, 0, :] = False
        mask[:, 0, [0, 2]] = True
        P = problem("fig3_6a", shape, boundary={"x-": 0, "x+": 0, "y+": 0}, mask=mask)
        for s in solutions(P):
            xs = [int(x) for x in np.flatnonzero(s[:, 0] == 2)]
            left = [x for x in xs if s[x, 1] in (3, 7)]  # a left post
            right = [x for x in xs if s[x, 1] in (5, 6)]  # a right post
            assert sorted(left + right) == xs
            assert [x + 2 for x in left] == right
            paired += len(left)
    assert paired > 10


def test_fig3_6a_inconsistent_while_catalog_not_empty():
    P = problem("fig3_6a", (9, 3))
    eng = Propagator(P)
    for x, b in enumerate(THREE_2S):  # scan order, every label from the catalog
        cell = P.cell((x, 0))
        assert b in eng.domain(cell)
        assert eng.assign(cell, b)
        assert satisfiable(P, eng) == (x < 8)
    assert eng.ok and eng.catalog().any(axis=1).all()  # C is not empty ...
    rest = [P.cell((x, y)) for y in (1, 2) for x in range(9)]
    assert longest_continuation(P, eng, rest) == 2  # ... Alg. 3.1 fails two cells later
    # the thesis' form: three 2s and two 0s, assigned in any order
    C, Cs = catalogs(P, {(2, 0): 2, (4, 0): 2, (6, 0): 2, (0, 0): 0, (8, 0): 0})
    assert C.any(axis=1).all() and not Cs.any()


def test_fig3_6a_is_fallible():
    fail, _ = alg31_failure(problem("fig3_6a", (5, 3)), FIG)
    assert fail is not None


# ----------------------------------------------------------------------------- Fig. 3.16


def f314(labels: np.ndarray) -> np.ndarray:
    return np.where(labels >= 10, labels - 10, labels)  # Eq. 3.14


def test_fig3_16_maps_onto_fig3_6a():
    EI, EF = load_example("fig3_16"), load_example("fig3_6a")
    assert (EI.labels >= 10).any()
    assert np.array_equal(f314(EI.labels), EF.labels)


@pytest.mark.parametrize("shape", [(3, 3), (4, 3), (5, 3), (3, 4), (4, 4)])
def test_fig3_16_solution_sets_correspond(shape):
    lifted = {f314(s).tobytes() for s in solutions(problem("fig3_16", shape))}
    models = {s.tobytes() for s in solutions(problem("fig3_6a", shape))}
    assert lifted == models  # Eq. 3.13
    assert len(models) >= 50


def test_fig3_16_short_outputs_differ():
    # two rows leave no room for a roof: fig3_6a then has models fig3_16 cannot map onto
    lifted = {f314(s).tobytes() for s in solutions(problem("fig3_16", (4, 2)))}
    models = {s.tobytes() for s in solutions(problem("fig3_6a", (4, 2)))}
    assert lifted < models


@pytest.mark.parametrize("order", ORDERS)
def test_fig3_16_alg31_never_fails(order):
    for shape in [(5, 3), (7, 3), (6, 4)]:
        fail, states = alg31_failure(problem("fig3_16", shape), order)
        assert fail is None, fail
        assert states > 100


def test_fig3_16_region_proof_needs_4x2():
    assert not corner_holds("fig3_16")
    assert window_proof("fig3_16", (3, 2)) is None
    assert window_proof("fig3_16", (4, 2)) is True


@pytest.mark.slow
@pytest.mark.parametrize("order", ORDERS)
@pytest.mark.parametrize(
    ("name", "shape"),
    [("fig3_4a", (5, 5)), ("fig3_15", (6, 4)), ("fig3_15", (5, 5)), ("fig3_16", (9, 3))],
)
def test_infallible_examples_larger_outputs(name, shape, order):
    fail, _ = alg31_failure(problem(name, shape), order)
    assert fail is None, fail


# ----------------------------------------------------------------------------- Fig. 3.10

CLOSED = {"x-": 0, "x+": 0, "y-": 0, "y+": 0}


def rectangles(g: np.ndarray) -> list[tuple[int, int]]:
    """(width, height) of every rectangle, found from its bottom-left corner piece 1."""
    out = []
    for x, y in zip(*np.nonzero(g == 1), strict=True):
        x2, y2 = x, y
        while g[x2, y] != 3:
            x2 += 1
        while g[x, y2] != 7:
            y2 += 1
        assert g[x2, y2] == 9
        out.append((int(x2 - x + 1), int(y2 - y + 1)))
    return out


def test_fig3_10_small_blocks_grow_only_thin_rectangles():
    P = problem("fig3_10", (16, 16), boundary=CLOSED)
    m = 4
    dims = []
    for seed in range(5):
        r = solve(P, "blocks", rng=seed, block=m, sweeps=3)
        assert r.status == "solved"
        dims += rectangles(r.grid)
        assert (r.grid == 1).sum() == (r.grid == 9).sum()  # closed rectangles only
    assert all(min(d) <= m for d in dims)  # never wider and taller than a block
    assert any(max(d) > m for d in dims)  # but longer than a block


def test_fig3_10_large_square_is_consistent():
    g = np.zeros((12, 12), dtype=int)
    g[2:10, 2:10] = 5
    g[2:10, 2], g[2:10, 9], g[2, 2:10], g[9, 2:10] = 2, 8, 4, 6
    g[2, 2], g[9, 2], g[2, 9], g[9, 9] = 1, 3, 7, 9
    assert problem("fig3_10", (12, 12), boundary=CLOSED).is_solution(g)
    assert rectangles(g) == [(8, 8)]


# ----------------------------------------------------------------------------- pillar


def test_pillar_columns_cannot_levitate():
    E = load_example("pillar")
    T = E.transitions()
    assert E.ndim == 3 and E.K == 4
    assert not T[2, 0, 1:].any()  # empty space is never below a piece
    assert not T[2, :, 1].any()  # nothing is ever below a base
    P = from_example(E, (8, 8, 6))
    pillars = 0
    for seed in range(5):
        r = solve(P, "catalog", rng=seed)
        assert r.status == "solved"
        g = r.grid
        assert not (g[:, :, 1:] == 1).any()  # bases only on the bottom layer
        upper, below = g[:, :, 1:], g[:, :, :-1]
        assert np.isin(below[upper > 0], (1, 2)).all()  # every piece rests on base or shaft
        pillars += int((g[:, :, 0] == 1).sum())
    assert pillars > 0
