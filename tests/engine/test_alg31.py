"""Alg. 3.1 orders."""


def test_min_domain_is_mrv_whatever_the_choice():
    """``min-domain`` (WFC's MRV) keys cells by their label count: with a uniform choice it
    is exactly ``min-entropy``; with a weighted choice it still ignores the weights."""
    import numpy as np

    from csplab import solve
    from csplab.examples import load_example
    from csplab.grids import from_example

    P = from_example(load_example("castle"), (10, 10, 6), boundary="auto")
    for seed in range(3):
        a = solve(P, "catalog", rng=seed, order="min-domain")
        b = solve(P, "catalog", rng=seed, order="min-entropy")
        assert a.status == b.status and np.array_equal(a.grid, b.grid)
    W = P._replace(weights=np.linspace(1, 50, P.K))
    r = solve(W, "catalog", rng=0, order="min-domain", choice="weighted")
    assert r.stats["order"] == "min-domain" and (r.status != "solved" or W.is_solution(r.grid))


def _problems():
    """Fixed problems where Alg. 3.1 solves, fails (loops in random order, seed 0) and is
    unsat."""
    import numpy as np

    from csplab import ExampleModel
    from csplab.examples import load_example
    from csplab.grids import from_example, with_fixed

    yield "fig3_10", from_example(load_example("fig3_10"), (7, 6))
    yield "castle", from_example(load_example("castle"), (6, 6, 5), boundary="auto")
    yield "loops", from_example(load_example("loops"), (8, 8))
    # 0 1 2 0 1 2 ... along x with both ends fixed to 0: unsat for length 5 (4 steps)
    P = from_example(ExampleModel(np.arange(9) % 3), (5,))
    yield "cycle-unsat", with_fixed(P, {(0,): 0, (4,): 0})


def test_run_alg31_is_the_literal_algorithm():
    """run_alg31 against alg31_reference (the literal Alg. 3.1 on the reference fixpoint):
    same status and grid for the same seed, orders scanline/random/scan:AXES, uniform and
    weighted choice; its trace is the cells in the order's sequence, each given the label
    the grid has, and a solved grid has no violation."""
    import numpy as np

    from csplab.catalog import Propagator
    from csplab.engine.alg31 import alg31_reference, run_alg31, scan_order

    statuses = set()
    for name, P in _problems():
        orders = ["scanline", "random", "scan:" + "xyz"[: P.ndim][::-1]]
        for order in orders:
            for choice in ("uniform", "weighted"):
                for seed in range(3):
                    want, grid = alg31_reference(P, np.random.default_rng(seed), order=order,
                                                 choice=choice)  # fmt: skip
                    r = run_alg31(P, np.random.default_rng(seed), order=order, choice=choice)
                    key = (name, order, choice, seed)
                    assert r.status == want, key
                    statuses.add(r.status)
                    flat = r.grid.reshape(-1)
                    if want == "unsat":
                        assert len(r.trace) == 0 and r.stats.get("proof"), key
                        # nothing assigned; the work is the root propagation's
                        root = Propagator(P)
                        assert r.stats["assigned"] == 0, key
                        assert r.stats["revisions"] == root.stats[0] > 0, key
                        assert r.stats["removals"] == root.stats[1] > 0, key
                        continue
                    assert np.array_equal(r.grid, grid) or want == "failed", key
                    cells, labels = r.trace[:, 0], r.trace[:, 1]
                    assert np.array_equal(flat[cells], labels), key
                    assert (flat >= 0).sum() >= len(cells)
                    scan = scan_order(P.shape, order)
                    if scan is not None:
                        assert np.array_equal(cells, scan[: len(cells)]), key
                    if want == "solved":
                        assert len(cells) == P.n and len(P.violations(r.grid)) == 0, key
                    else:
                        assert r.stats["fail_cell"] is not None, key
    assert {"solved", "failed", "unsat"} <= statuses  # the premise: every outcome seen


def test_heap_orders_visit_each_cell_once_and_solve_consistently():
    import numpy as np

    from csplab.engine.alg31 import run_alg31

    for _, P in _problems():
        for order in ("min-entropy", "min-domain"):
            for seed in range(3):
                r = run_alg31(P, np.random.default_rng(seed), order=order)
                cells = r.trace[:, 0]
                assert len(set(cells.tolist())) == len(cells)
                if r.status == "solved":
                    assert sorted(cells.tolist()) == list(range(P.n))
                    assert len(P.violations(r.grid)) == 0


def test_resemblance_windows_are_3_cells_wide_by_default():
    """``run_alg31(choice="resemblance")`` uses windows of 3 cells (``window=1``, the 2007
    paper's) unless told otherwise: the default run is the ``window=1`` run, draw for draw,
    and a wider window changes some run."""
    import numpy as np

    from csplab.engine.alg31 import run_alg31
    from csplab.examples import load_example
    from csplab.grids import from_example

    P = from_example(load_example("fig3_10"), (8, 8))
    differs = False
    for seed in range(4):
        a = run_alg31(P, np.random.default_rng(seed), choice="resemblance")
        b = run_alg31(P, np.random.default_rng(seed), choice="resemblance", window=1)
        c = run_alg31(P, np.random.default_rng(seed), choice="resemblance", window=2)
        assert a.status == b.status and np.array_equal(a.grid, b.grid)
        differs |= not np.array_equal(a.grid, c.grid)
    assert differs


def test_global_constraints_refuted_before_any_choice():
    """A fixed cell whose label a count constraint forbids: the constraint refutes the root
    catalog, so Alg. 3.1 stops "unsat" before any choice, with the work of the root
    propagation (revisions and removals told apart) and nothing assigned."""
    import numpy as np

    from csplab.catalog import Propagator
    from csplab.constraints import Count
    from csplab.engine.alg31 import run_alg31
    from csplab.examples import load_example
    from csplab.grids import from_example, with_fixed

    P = with_fixed(from_example(load_example("fig3_10"), (6, 5)), {(2, 3): 1})
    P = P.with_constraints([Count(labels=[1], max=0)])
    r = run_alg31(P, np.random.default_rng(0))
    assert r.status == "unsat" and len(r.trace) == 0
    assert r.stats["proof"] == "global-constraint propagation before any choice"
    assert r.stats["assigned"] == 0
    root = Propagator(P)
    assert root.constrain() == -2  # the same refutation, replayed: by the count, no cell
    assert (r.stats["revisions"], r.stats["removals"]) == (root.stats[0], root.stats[1])
    assert root.stats[0] != root.stats[1]  # the premise: the two counts differ here


def test_a_global_constraint_pruning_left_to_arc_consistency_names_the_wiped_cell(monkeypatch):
    """The root pruning by a global constraint may leave the wipe-out to arc consistency:
    the constraint removes labels without seeing a contradiction, and the arcs then empty a
    cell. Alg. 3.1 stops "unsat" with the global-constraint proof and names that cell.

    A chain 0 - 1 - 2 of labels A, C, X, Y: cells 0 and 2 may be A or C, cell 1 X or Y;
    after C only X may follow, before C only Y may come, A goes with both. The catalog is
    arc consistent and no cell must be A, so "no A" (a count with max 0) prunes A from
    cells 0 and 2 without refuting; cell 1 must then be X (after C) and Y (before C): arc
    consistency empties cell 1 while it revises it against the two changed cells, before
    cell 1 itself is looked at. The literal reference (arcs only) refuses the problem
    rather than "solve" it."""
    import itertools

    import numpy as np
    import pytest

    from csplab import Problem, _interp
    from csplab.catalog import Propagator
    from csplab.constraints import Count
    from csplab.engine.alg31 import alg31_reference, run_alg31
    from csplab.errors import InputError

    A, C, X, Y = range(4)
    dom = np.zeros((3, 4), dtype=bool)
    dom[0, [A, C]] = dom[1, [X, Y]] = dom[2, [A, C]] = True
    rel = np.zeros((1, 4, 4), dtype=bool)
    for a, b in [(A, X), (A, Y), (C, X), (X, A), (Y, A), (Y, C)]:
        rel[0, a, b] = True
    free = Problem((3,), dom, rel, [[0, 1, 0], [1, 2, 0]], names="ACXY")
    P = free.with_constraints([Count([A], max=0)])
    grids = [np.array(g) for g in itertools.product([A, C], [X, Y], [A, C])]
    assert any(free.is_solution(g) for g in grids)  # the arcs alone are satisfiable
    assert not any(P.is_solution(g) for g in grids)  # with "no A" nothing is
    root = Propagator(P)
    assert root.ok and root.catalog().sum() == 6  # arc consistent, nothing removed
    assert root.constrain() == 1 and root.refuted_by is None  # the count did not refute
    assert Propagator(P).constrain_unpacked() == 1  # the unpacked path agrees
    for name in ("kernels", "interp"):
        monkeypatch.setattr(_interp, "ENGINE", name)
        r = run_alg31(P, np.random.default_rng(0))
        assert r.status == "unsat" and len(r.trace) == 0, name
        assert r.stats["proof"] == "global-constraint propagation before any choice", name
        assert r.stats["fail_cell"] == [1], name
        assert r.stats["assigned"] == 0, name
    with pytest.raises(InputError, match="global constraints"):  # it would "solve" P
        alg31_reference(P, np.random.default_rng(0))
    assert alg31_reference(free, np.random.default_rng(0))[0] == "solved"
