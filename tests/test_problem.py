import math

import numpy as np
import pytest
from hypothesis import given

from csplab import ExampleModel, Problem
from csplab.errors import InputError
from csplab.grids import auto_boundary, from_example, parse_shape
from csplab.testing.strategies import problems


def test_grid_arcs_count_and_order():
    E = ExampleModel(np.zeros((2, 2, 2), dtype=int))
    P = from_example(E, (3, 4, 5))
    nx, ny, nz = 3, 4, 5
    assert len(P.arcs) == (nx - 1) * ny * nz + nx * (ny - 1) * nz + nx * ny * (nz - 1)
    # cell numbering is the thesis scan order: x outermost, z innermost
    assert P.cell((0, 0, 1)) == 1 and P.cell((0, 1, 0)) == nz and P.cell((1, 0, 0)) == ny * nz
    Pp = from_example(E, (3, 4, 5), periodic=True)
    assert len(Pp.arcs) == 3 * nx * ny * nz


def test_periodic_axis_of_length_one_is_a_unary_constraint():
    E = ExampleModel([[0, 1], [1, 1]])  # T_x(0,0) never happens
    P = from_example(E, (1, 3), periodic=(True, False))
    assert not P.domains[:, 0].any()


def test_example_is_a_solution_of_its_own_problem():
    rng = np.random.default_rng(1)
    for _ in range(30):
        lab = rng.integers(0, 5, size=tuple(rng.integers(1, 5, size=rng.integers(1, 4))))
        E = ExampleModel(lab)
        P = from_example(E, E.shape)
        assert P.is_solution(E.labels)


def test_violations_reports_arcs_and_cells():
    E = ExampleModel([[0, 1], [1, 0]])
    P = from_example(E, (2, 2), fixed={(0, 0): 1})
    g = np.array([[0, 1], [1, 0]])
    v = P.violations(g)
    assert v.cells.tolist() == [0] and v.arcs.size == 0
    g2 = np.array([[1, 1], [0, 1]])
    v2 = P.violations(g2)
    assert v2.cells.size == 0 and v2.arcs.size == 2
    assert "never occurs" in v2.describe()
    g3 = np.array([[1, -1], [0, 7]])
    v3 = P.violations(g3)
    assert set(v3.cells.tolist()) == {1, 3}
    with pytest.raises(InputError):
        P.violations(np.zeros((3, 3), dtype=int))


def test_fixed_boundary_mask():
    E = ExampleModel([[1, 0, 0], [1, 0, 0], [1, 0, 0]])
    P = from_example(E, (4, 3), boundary="auto")
    kinds = [u.kind for u in P.unary]
    assert kinds.count("boundary") == 4
    fg = P.fixed_grid
    assert fg[:, 0].tolist() == [1, 1, 1, 1]  # bottom face wins at corners
    assert fg[0, 1] == 0 and fg[3, 2] == 0 and fg[1, 2] == 0
    P2 = from_example(E, (4, 3), fixed=np.array([[-1] * 3] * 3 + [[1, 0, -1]]))
    assert [u.key for u in P2.unary] == [(3, 0), (3, 1)]
    mask = np.ones((4, 3, 2), dtype=bool)
    mask[2, 2, 1] = False
    P3 = from_example(E, (4, 3), mask=mask)
    assert not P3.domains[P3.cell((2, 2)), 1] and len(P3.unary) == 1
    with pytest.raises(InputError):
        from_example(E, (4, 3), fixed={(9, 9): 0})
    with pytest.raises(InputError):
        from_example(E, (4, 3), fixed={(0, 0): 5})
    with pytest.raises(InputError):
        from_example(E, (4, 3), boundary={"q+": 0})
    # without_unary restores the base domains
    assert P.without_unary().domains.all()


def test_auto_boundary_errors_clearly():
    with pytest.raises(InputError, match="empty-space"):
        auto_boundary(ExampleModel([[0, 1], [1, 0]]))


def test_shape_matching_and_parse_shape():
    E = ExampleModel(np.zeros((2, 2, 1), dtype=int))
    assert from_example(E, "5x6").shape == (5, 6, 1)
    with pytest.raises(InputError):
        from_example(ExampleModel(np.zeros((2, 2), dtype=int)), (3, 3, 3))
    for bad in ["", "3x", "0x3", "axb", "1x2x3x4x5"]:
        with pytest.raises(InputError):
            parse_shape(bad)


@given(problems(max_side=3))
def test_subproblem_with_full_grid_context(P):
    """A block's subproblem accepts exactly the block labelings that complete the grid."""
    rng = np.random.default_rng(P.n)
    g = rng.integers(0, P.K, size=P.n)
    block = np.flatnonzero(rng.random(P.n) < 0.5)
    if block.size == 0:
        return
    sub = P.subproblem(block, g)
    for _ in range(5):
        inner = rng.integers(0, P.K, size=block.size)
        full = g.copy()
        full[block] = inner
        outside_ok = True
        v = P.violations(full)
        bad_arcs = P.arcs[v.arcs]
        inb = np.zeros(P.n, dtype=bool)
        inb[block] = True
        # violations touching the block must be exactly the subproblem's
        touching = np.any(inb[bad_arcs[:, :2]], axis=1) if len(bad_arcs) else np.zeros(0, bool)
        bad_cells_in_block = inb[v.cells]
        sub_bad = len(sub.violations(inner)) > 0
        assert sub_bad == (bool(touching.any()) or bool(bad_cells_in_block.any())), outside_ok


def test_add_arcs_symmetry_pairs():
    E = ExampleModel([[0, 1], [2, 3]])
    P = from_example(E, (4, 1), boundary=None)
    mirror = np.zeros((4, 4), dtype=bool)
    mirror[[0, 1, 2, 3], [2, 3, 0, 1]] = True  # a toy mirror map
    P2 = P.add_arcs(mirror, [P.cell((0, 0))], [P.cell((3, 0))], name="mirror")
    assert P2.R == P.R + 1 and len(P2.arcs) == len(P.arcs) + 1
    assert P2.relation_names[-1] == "mirror"


def test_problem_constructor_validates():
    with pytest.raises(InputError):
        Problem((2,), np.ones((2, 2), bool), np.ones((1, 2, 2), bool), [[0, 5, 0]])
    with pytest.raises(InputError):
        Problem((2,), np.ones((2, 3), bool), np.ones((1, 2, 2), bool), [])
    P = Problem((3,), np.ones((3, 2), bool), np.ones((1, 2, 2), bool), [[0, 1, 0]])
    assert P.n == 3 and math.prod(P.shape) == 3


def test_labels_absent_from_the_example_are_excluded():
    E = ExampleModel([[0, 3], [3, 0]])  # K = 4, labels 1 and 2 never occur
    P = from_example(E, (1, 1))
    assert P.domains[0].tolist() == [True, False, False, True]
    assert not P.is_solution([[1]])


def _violations_by_hand(P, g):
    """Brute force from the definition: a cell is bad when its label is negative, >= K or
    outside its domain; an arc is broken when an end is bad-ranged or the relation forbids
    the pair."""
    lab = np.asarray(g).reshape(-1)
    cells = [c for c in range(P.n)
             if not 0 <= lab[c] < P.K or not P.domains[c, lab[c]]]  # fmt: skip
    arcs = []
    for i, (s, d, r) in enumerate(P.arcs.tolist()):
        a, b = int(lab[s]), int(lab[d])
        if not (0 <= a < P.K and 0 <= b < P.K and P.relations[r, a, b]):
            arcs.append(i)
    return cells, arcs


def test_violations_match_the_definition_on_random_grids():
    """Random relations, domains and grids with labels from -1 to K (one past the last
    label) on problems of 1 to 3 labels: the same cells and arcs as the definition."""
    rng = np.random.default_rng(32)
    for K in (1, 2, 3):
        for _ in range(15):
            shape = (3, 4)
            n = 12
            idx = np.arange(n).reshape(shape)
            arcs = [[int(idx[i, j]), int(idx[i, j + 1]), 0] for i in range(3) for j in range(3)]
            arcs += [[int(idx[i, j]), int(idx[i + 1, j]), 1] for i in range(2) for j in range(4)]
            rel = rng.random((2, K, K)) < 0.6
            dom = rng.random((n, K)) < 0.8
            dom[np.arange(n), rng.integers(0, K, n)] = True
            P = Problem(shape, dom, rel, arcs)
            g = rng.integers(-1, K + 1, shape)
            v = P.violations(g)
            cells, broken = _violations_by_hand(P, g)
            assert v.cells.tolist() == cells and v.arcs.tolist() == broken
            assert len(v) == len(cells) + len(broken) and v.constraints == ()
            assert P.is_solution(g) == (not cells and not broken)


def test_constraints_are_checked_on_complete_grids_and_counted():
    from csplab.constraints import Count

    E = ExampleModel([[0, 1], [1, 0]])
    P = from_example(E, (2, 2)).with_constraints([Count([1], min=3)])
    good_arcs = np.array([[0, 1], [1, 0]])  # a solution of the arcs with two 1s
    v = P.violations(good_arcs)
    assert v.arcs.size == 0 and v.cells.size == 0 and len(v.constraints) == 1
    assert "count" in v.constraints[0] and len(v) == 1 and not P.is_solution(good_arcs)
    ok = P.with_constraints([]).without_constraints().with_constraints([Count([1], min=2)])
    assert len(ok.violations(good_arcs)) == 0 and ok.violations(good_arcs).constraints == ()
    # an incomplete grid: its cells are reported, the constraints are not checked yet
    part = np.array([[0, 1], [1, -1]])
    vp = P.violations(part)
    assert vp.cells.tolist() == [3] and vp.constraints == ()
