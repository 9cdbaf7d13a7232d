"""Sec. 3.5: other grids, symmetry, shapes and 4D models are only more arcs or domain
restrictions of the same binary CSP — synthesized here with an incomplete (``catalog``) and
a complete (``sat``) solver and checked against pair sets recomputed from the arrays, not
only with ``Problem.violations``."""

import numpy as np
import pytest

from csplab import ExampleModel, load_example, solve
from csplab.grids import from_example

pytest.importorskip("pysat")


def pairs(grid, axis, offset=None):
    """Set of label pairs (a, b) with b at ``+offset`` (default: +1 along ``axis``)."""
    g = np.asarray(grid)
    off = [0] * g.ndim
    if offset is None:
        off[axis] = 1
    else:
        off = list(offset)
    src = tuple(slice(0, g.shape[d] - off[d]) if off[d] >= 0 else slice(-off[d], None)
                for d in range(g.ndim))  # fmt: skip
    dst = tuple(slice(off[d], None) if off[d] >= 0 else slice(0, g.shape[d] + off[d])
                for d in range(g.ndim))  # fmt: skip
    return set(zip(g[src].ravel().tolist(), g[dst].ravel().tolist(), strict=True))


def solved(P, solver, seeds=range(30)):
    for s in seeds:
        r = solve(P, solver, rng=s)
        if r.status == "solved":
            return r.grid
        assert r.status == "failed"
    raise AssertionError(f"{solver} never solved")


@pytest.mark.parametrize("solver", ["catalog", "sat"])
def test_diagonal_neighbours_are_one_more_relation(solver):
    """Sec. 3.5.1: diagonal neighbours = a transition matrix between more pairs of points."""
    E = load_example("fig3_4a")
    P = from_example(E, (9, 8))
    T = np.zeros((E.K, E.K), dtype=bool)
    for a, b in pairs(E.labels, 0, (1, 1)):
        T[a, b] = True
    idx = np.arange(P.n).reshape(P.shape)
    P2 = P.add_arcs(T, idx[:-1, :-1], idx[1:, 1:], name="diagonal")
    g = solved(P2, solver)
    assert pairs(g, 0, (1, 1)) <= pairs(E.labels, 0, (1, 1))
    for d in range(2):
        assert pairs(g, d) <= pairs(E.labels, d)


@pytest.mark.parametrize("solver", ["catalog", "sat"])
def test_cylinder_wraps_around(solver):
    """Sec. 3.5.1: a cylinder is the grid plus arcs from the last column to the first."""
    E = load_example("line")
    P = from_example(E, (7, 6), periodic=(True, False))
    g = solved(P, solver)
    wrapped = np.concatenate([g, g[:1]], axis=0)  # column 0 again after the last one
    assert pairs(wrapped, 0) <= pairs(E.labels, 0) and pairs(g, 1) <= pairs(E.labels, 1)


@pytest.mark.parametrize("solver", ["catalog", "sat"])
def test_mirror_symmetry_pairs(solver):
    """Sec. 3.5.2, Fig. 3.25: a transition matrix T_s between mirrored points gives
    symmetric models (fig3_4a's T_x is symmetric, so T_s is the identity)."""
    E = load_example("fig3_4a")
    T = E.transitions()
    assert (T[0] == T[0].T).all()
    P = from_example(E, (10, 9))
    idx = np.arange(P.n).reshape(P.shape)
    half = P.shape[0] // 2
    P2 = P.add_arcs(np.eye(E.K, dtype=bool), idx[:half], idx[::-1][:half], name="mirror")
    g = solved(P2, solver)
    assert (g == g[::-1]).all()
    assert len(np.unique(g)) > 1  # not just empty space
    assert pairs(g, 0) <= pairs(E.labels, 0) and pairs(g, 1) <= pairs(E.labels, 1)


@pytest.mark.parametrize("solver", ["catalog", "sat"])
def test_shape_mask(solver):
    """Sec. 3.5.3, Fig. 3.26: labels with zero probability are removed from C — here every
    label but empty space outside a disk, and empty space on the disk's centre line."""
    E = load_example("line")
    shape = (16, 16)
    x, y = np.indices(shape)
    disk = (x - 7.5) ** 2 + (y - 7.5) ** 2 <= 36
    mask = np.ones((*shape, E.K), dtype=bool)
    mask[~disk, 1:] = False  # outside: only empty space (label 0)
    mask[disk & (y == 8) & (abs(x - 7.5) < 4), 0] = False  # inside: a line is forced
    P = from_example(E, shape, mask=mask)
    g = solved(P, solver)
    assert (g[~disk] == 0).all() and (g[disk & (y == 8) & (abs(x - 7.5) < 4)] != 0).all()
    assert pairs(g, 0) <= pairs(E.labels, 0) and pairs(g, 1) <= pairs(E.labels, 1)


def rolling_ball() -> ExampleModel:
    """A 4D example E[x, y, z, t]: a ball (1) in empty space (0) on a floor (2) moving one
    cell along x per time step (Sec. 3.5.4, Fig. 3.27, reduced to its bones)."""
    nx, T = 5, 4
    E = np.zeros((nx, 2, 2, T), dtype=np.int32)  # two equal rows along y
    E[:, :, 0, :] = 2
    for t in range(T):
        E[t + 1, :, 1, t] = 1
    return ExampleModel(E)


@pytest.mark.parametrize("solver", ["catalog", "sat"])
def test_4d_time_varying_model(solver):
    E = rolling_ball()
    P = from_example(E, (8, 3, 2, 7), fixed={(2, 1, 1, 0): 1})
    g = solved(P, solver)
    for d in range(4):
        assert pairs(g, d) <= pairs(E.labels, d)
    assert (g[2, :, 1, 0] == 1).all()  # the ball fills its row along y, as in E
    assert (g[2, :, 1, 1] == 0).all() and (1, 1) not in pairs(g, 3)  # and never stays put
    assert (g[..., 0, :] == 2).all()  # the floor is everywhere
