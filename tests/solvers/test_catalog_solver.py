import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from csplab import ExampleModel, load_example, solve
from csplab.errors import InputError, UnknownSolverError
from csplab.grids import from_example
from csplab.testing.brute import count
from csplab.testing.strategies import problems


@given(problems(max_side=4), st.sampled_from(["scanline", "random", "min-entropy"]),
       st.sampled_from(["uniform", "weighted"]), st.integers(0, 2**31))  # fmt: skip
def test_solved_grids_have_zero_violations(P, order, choice, seed):
    r = solve(P, "catalog", rng=seed, order=order, choice=choice)
    assert r.status in ("solved", "failed", "unsat")
    if r.status == "solved":
        assert len(P.violations(r.grid)) == 0
        assert r.stats["assigned"] == P.n
    if r.status == "unsat":
        assert count(P) == 0 if P.n <= 12 else True


@pytest.mark.parametrize("name", ["fig3_1a", "fig3_1b", "line"])
@pytest.mark.parametrize("order", ["scanline", "random", "min-entropy"])
def test_never_fails_on_infallible_examples_200_seeds(name, order):
    E = load_example(name)
    P = from_example(E, (9, 7))
    for seed in range(200):
        r = solve(P, "catalog", rng=seed, order=order)
        assert r.status == "solved", (name, seed)


def test_same_seed_same_grid_and_seed_recorded():
    P = from_example(load_example("line"), (15, 9))
    a = solve(P, "catalog", rng=5)
    b = solve(P, "catalog", rng=np.random.default_rng(5))
    assert np.array_equal(a.grid, b.grid) and a.seed == b.seed == 5
    c = solve(P, "catalog", rng=6)
    assert not np.array_equal(a.grid, c.grid)
    d = solve(P, "catalog")
    assert isinstance(d.seed, int)
    e = solve(P, "catalog", rng=d.seed)
    assert np.array_equal(d.grid, e.grid)


def test_trace_replays_to_the_grid():
    P = from_example(load_example("line"), (6, 5))
    r = solve(P, "catalog", rng=2, order="random")
    g = np.full(P.n, -1)
    g[r.trace[:, 0]] = r.trace[:, 1]
    assert np.array_equal(g.reshape(P.shape), r.grid)
    assert sorted(r.trace[:, 0].tolist()) == list(range(P.n))


def test_scanline_trace_is_thesis_loop_order():
    E = ExampleModel(np.zeros((2, 2, 2), dtype=int))
    P = from_example(E, (2, 3, 4))
    r = solve(P, "catalog", rng=0)
    coords = [P.coords(c) for c in r.trace[:, 0]]
    assert coords == sorted(coords)  # x outermost, z innermost


def test_checkerboard_two_solutions_both_reached():
    P = from_example(load_example("E1"), (5, 4))
    grids = {solve(P, "catalog", rng=s).grid.tobytes() for s in range(30)}
    assert len(grids) == 2


def test_unsat_and_failure_statuses():
    P = from_example(load_example("fig3_1d"), (5, 5))
    r = solve(P, "catalog", rng=0)
    assert r.status == "unsat" and "Theorem 3.3.2" in r.stats["proof"]
    # a satisfiable problem where scanline Alg. 3.1 can fail: parity constraint
    E = ExampleModel([[0, 1, 0, 1], [1, 0, 1, 0]])
    P2 = from_example(E, (3, 3), fixed={(2, 2): 1})
    r2 = solve(P2, "catalog", rng=0)
    assert r2.status in ("solved", "failed")


# chi-square with 2 degrees of freedom: P(X > x) = exp(-x / 2), so 1e-6 at 2 ln(1e6) = 27.6
CHI2_2DOF_P1E6 = 2 * math.log(1e6)


def _chi2(counts, probs):
    expected = counts.sum() * np.asarray(probs, dtype=float)
    return float(((counts - expected) ** 2 / expected).sum())


def _label_counts(P, choice, seeds=40):
    counts = np.zeros(P.K)
    for s in range(seeds):
        r = solve(P, "catalog", rng=s, choice=choice)
        assert r.ok
        counts += np.bincount(r.grid.ravel(), minlength=P.K)
    return counts


def test_weighted_choice_follows_weights():
    """The example is a de Bruijn sequence (every ordered pair of the 3 labels occurs), so
    every label may follow every label: the catalog of each cell is always all 3 labels and
    Alg. 3.1 draws the cells independently, with probability w / sum(w) under weighted
    choice and 1/3 under uniform choice. 40 seeds x 60 cells = 2400 draws per setting."""
    seq = [0, 0, 1, 0, 2, 1, 1, 2, 2, 0]
    uniform = [1 / 3] * 3
    for w in ([1.0, 2.0, 5.0], [6.0, 1.0, 1.0]):
        P = from_example(ExampleModel(seq, weights=w), (60,))
        assert P.domains.all() and P.K == 3
        p = np.array(w) / sum(w)
        weighted = _label_counts(P, "weighted")
        assert _chi2(weighted, p) < CHI2_2DOF_P1E6, (w, weighted)
        assert _chi2(weighted, uniform) > CHI2_2DOF_P1E6, (w, weighted)
        flat = _label_counts(P, "uniform")  # the weights only matter to weighted choice
        assert _chi2(flat, uniform) < CHI2_2DOF_P1E6, (w, flat)
        assert _chi2(flat, p) > CHI2_2DOF_P1E6, (w, flat)
    # a label of weight 0 is never chosen while another label is possible
    P0 = from_example(ExampleModel(seq, weights=[1.0, 1.0, 0.0]), (60,))
    zero = _label_counts(P0, "weighted", seeds=10)
    assert zero[2] == 0 and zero[0] > 0 and zero[1] > 0


def test_time_limit_and_bad_options():
    P = from_example(load_example("line"), (40, 40))
    r = solve(P, "catalog", rng=0, time_limit=1e-9)
    assert r.status in ("timeout", "solved")
    with pytest.raises(InputError):
        solve(P, "catalog", rng=0, order="sideways")
    with pytest.raises(InputError):
        solve(P, "catalog", rng=0, colour="blue")
    with pytest.raises(UnknownSolverError):
        solve(P, "nonesuch")


@given(problems(max_side=4, max_labels=5), st.sampled_from(["scanline", "random", "scan:rev"]),
       st.sampled_from(["uniform", "weighted"]), st.integers(0, 2**31))  # fmt: skip
def test_compiled_alg31_equals_reference_run(P, order, choice, seed):
    from csplab.engine.alg31 import alg31_reference

    if order == "scan:rev":  # innermost axis outermost
        order = "scan:" + "xyzw"[: P.ndim][::-1]
    status, grid = alg31_reference(P, np.random.default_rng(seed), order=order, choice=choice)
    r = solve(P, "catalog", rng=seed, order=order, choice=choice)
    assert r.status == status
    if status == "solved":
        assert np.array_equal(r.grid, grid)


def test_scan_axis_orders():
    from csplab.engine.alg31 import scan_order

    P = from_example(load_example("line"), (4, 3))
    r = solve(P, "catalog", rng=0, order="scan:yx")
    assert [P.coords(c) for c in r.trace[:, 0]] == [(x, y) for y in range(3) for x in range(4)]
    with pytest.raises(InputError):
        scan_order((2, 2), "scan:xx")
    with pytest.raises(InputError):
        scan_order((2, 2, 2), "scan:yx")


def test_default_order_auto_is_scanline_without_global_constraints():
    """``order="auto"`` (the default) runs the thesis' scanline order on a problem without
    global constraints: the same grid and trace as ``order="scanline"``, recorded so."""
    P = from_example(load_example("city"), (10, 10, 6), boundary="auto")
    for seed in range(4):
        a, b = solve(P, "catalog", rng=seed), solve(P, "catalog", rng=seed, order="scanline")
        assert a.status == b.status and a.stats["order"] == "scanline"
        assert np.array_equal(a.grid, b.grid) and np.array_equal(a.trace, b.trace)


def test_default_order_auto_is_min_entropy_under_global_constraints():
    """On a small connected City (one object of at least 5 % of the cells) scanline
    Alg. 3.1 fails for seeds 1-5 and min-entropy solves them: the default resolves ``auto``
    to min-entropy (recorded in the stats), and each output is a solution."""
    from csplab.testing.synthetic import connected_city

    Q = connected_city((12, 12, 6))[1]
    for seed in range(1, 6):
        assert solve(Q, "catalog", rng=seed, order="scanline").status == "failed"
        r = solve(Q, "catalog", rng=seed)
        assert r.status == "solved" and r.stats["order"] == "min-entropy"
        assert len(Q.violations(r.grid)) == 0
        assert np.array_equal(r.grid, solve(Q, "catalog", rng=seed, order="min-entropy").grid)
