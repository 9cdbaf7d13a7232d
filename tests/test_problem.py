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
