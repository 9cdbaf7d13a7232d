"""Solver ``asp`` (clingo): brute-force agreement, the ground program's answer sets, every
grid variant, unsat proofs, time limits and seeds."""

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("clingo")

from csplab import ExampleModel, Problem, solve
from csplab.cnf import encode
from csplab.errors import CsplabError, DependencyError, InputError
from csplab.grids import from_example, with_fixed
from csplab.solvers import REGISTRY, unknown_stats
from csplab.solvers.asp import AspContext, AspSolver, _grid_of, _run_child, facts, ground_program
from csplab.testing.brute import count, solutions
from csplab.testing.strategies import csp_problems
from csplab.testing.synthetic import box_town

CHECKER = ExampleModel([[0, 1], [1, 0]])


@pytest.fixture(autouse=True, scope="module")
def _asp_registered():
    """Register the solver for this module (a no-op once it is in the registry)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setitem(REGISTRY, "asp", "csplab.solvers.asp:AspSolver")
        yield


def _searched(P: Problem) -> bool:
    """Arc consistency neither wipes out nor decides every cell: clingo has to search."""
    enc = encode(P)
    return enc.ok and enc.nx > 0


SEARCHED = csp_problems().filter(_searched)


def _check(P, seed, **opts):
    """The conformance rules for one run; returns the result."""
    r = solve(P, "asp", rng=seed, **opts)
    satisfiable = next(solutions(P, limit=1), None) is not None
    assert r.status == ("solved" if satisfiable else "unsat"), (r.status, r.stats)
    assert r.grid.dtype == np.int32 and r.grid.shape == P.shape
    if r.ok:
        assert len(P.violations(r.grid)) == 0
    else:
        assert r.stats["proof"]
        assert (r.grid == -1).all()
    assert not unknown_stats(r.stats), unknown_stats(r.stats)
    return r


# ----------------------------------------------------------------------------- brute force


@given(P=csp_problems(), seed=st.integers(0, 2**31))
def test_agrees_with_brute_force(P, seed):
    _check(P, seed)


@given(P=SEARCHED, seed=st.integers(0, 2**31))
def test_agrees_with_brute_force_where_clingo_searches(P, seed):
    r = _check(P, seed)
    assert r.stats["solver_status"] in ("SAT", "UNSAT")


VARIANTS = [
    {"grounding": "gringo"},
    {"encoding": "direct"},
    {"supports": "forward"},
    {"diversity": "label"},
    {"grounding": "gringo", "encoding": "direct", "diversity": "label"},
]


@pytest.mark.parametrize("opts", VARIANTS, ids=lambda o: ",".join(f"{k}={v}" for k, v in o.items()))
@settings(max_examples=20)
@given(P=SEARCHED, seed=st.integers(0, 2**31))
def test_variants_agree_with_brute_force(opts, P, seed):
    _check(P, seed, **opts)


def test_passes_the_conformance_suite_checks():
    from tests.solvers.test_conformance import check_solver_on

    rng = np.random.default_rng(1)
    for _ in range(8):
        E = ExampleModel(rng.integers(0, 3, size=(3, 3)))
        P = from_example(E, (4, 3), fixed={(0, 0): int(rng.integers(0, 3))})
        check_solver_on("asp", {}, P, int(rng.integers(1000)))


def _answer_sets(program: bytes | str) -> int:
    import clingo

    ctl = clingo.Control(["--models=0"], logger=lambda *_: None)
    if isinstance(program, str):
        ctl.add("base", [], program)
    else:
        with tempfile.NamedTemporaryFile(suffix=".aspif", delete=False) as f:
            f.write(program)
        try:
            ctl.load(f.name)
        finally:
            os.unlink(f.name)
    ctl.ground([("base", [])])
    n = 0

    def on_model(m):
        nonlocal n
        n += 1

    ctl.solve(on_model=on_model)
    return n


@pytest.mark.parametrize("grounding", ["csplab", "gringo"])
@pytest.mark.parametrize(("encoding", "supports"), [("support", "both"), ("support", "forward"),
                                                    ("direct", "both")])  # fmt: skip
@settings(max_examples=25)
@given(P=csp_problems(max_cells=9).filter(_searched))
def test_answer_sets_are_exactly_the_solutions(grounding, encoding, supports, P):
    """One answer set per solution: the ground program (csplab's aspif, or gringo's
    grounding of the first-order program) is exact, not just satisfiable together."""
    enc = encode(P, encoding=encoding, supports=supports)
    if grounding == "csplab":
        n = _answer_sets(b"".join(ground_program(enc)))
    else:
        n = _answer_sets(facts(P, enc.catalog, supports, encoding))
    assert n == count(P)


def _answer_grids(P: Problem, supports: str = "both") -> list[bytes]:
    """The grids of every answer set of the solver's ground program for ``P`` (with its
    global constraints), one entry per answer set."""
    import clingo

    enc = encode(P, supports=supports)
    ctl = clingo.Control(["--models=0"], logger=lambda *_: None)
    with tempfile.NamedTemporaryFile(suffix=".aspif", delete=False) as f:
        f.write(b"".join(ground_program(enc, None, AspContext.of(P, enc))))
    try:
        ctl.load(f.name)
    finally:
        os.unlink(f.name)
    ctl.ground([("base", [])])
    out: list[bytes] = []

    def on_model(m):
        atoms = [i for i in range(1, enc.nx + 1) if m.is_true(i)]
        out.append(_grid_of(enc, {"atoms": atoms}).astype(np.int32).tobytes())

    ctl.solve(on_model=on_model)
    return out


def _constrained():
    from csplab.constraints import Connected, Count, parse_constraints

    E = ExampleModel([[0, 0, 1], [1, 0, 0], [0, 1, 0]])
    base = from_example(E, (3, 4))
    yield "connected", base.with_constraints([Connected([0])])
    yield "connected, single cells", base.with_constraints([Connected([1])])
    yield "connected through a cell", base.with_constraints([Connected([1], cells=(5,))])
    yield "connected, nonempty", base.with_constraints([Connected([0], nonempty=True)])
    yield "count", base.with_constraints([Count([1], min=2, max=3)])
    yield "count at least", base.with_constraints([Count([0], min=7)])
    yield "connected + count", base.with_constraints([Connected([0]), Count([0], min=9, max=10)])
    # two of four labels: "in the set" is defined by the two labels outside it
    G = from_example(ExampleModel([[0, 1, 2, 3], [1, 3, 0, 2], [3, 2, 1, 0], [0, 0, 3, 1]]),
                     (3, 4))  # fmt: skip
    yield "two of four labels", G.with_constraints([Connected([0, 1]), Count([0, 1], min=4, max=6)])
    # ports: 1 opens its x faces, 2 its y faces; most grids put two of them side by side
    # with a closed face between them (486 of 512), 2 are one network
    F = ExampleModel([[0, 1, 2, 0], [1, 2, 0, 1], [2, 0, 1, 2], [0, 2, 1, 0], [1, 1, 2, 2],
                      [0, 0, 2, 1]])  # fmt: skip
    ports = np.array([[0, 0, 0, 0], [1, 1, 0, 0], [0, 0, 1, 1]], dtype=bool)
    yield (
        "connected through open ports",
        from_example(F, (2, 3)).with_constraints([Connected([1, 2], ports=ports)]),
    )
    import csplab.examples

    data = Path(__file__).resolve().parents[1] / "io" / "data" / "pipes.xml"
    P = csplab.examples.load_model(data).problem((2, 2))
    cons = [{"type": "connected", "labels": ["line", "corner", "tee", "cross"]},
            {"type": "count", "labels": ["cross"], "min": 0, "max": 1}]  # fmt: skip
    yield (
        "pipes: one network through open ports + count",
        P.with_constraints(parse_constraints(cons, P)),
    )


@pytest.mark.parametrize("supports", ["both", "forward"])
@pytest.mark.parametrize(("what", "P"), list(_constrained()), ids=[w for w, _ in _constrained()])
def test_answer_sets_with_global_constraints_are_exactly_the_solutions(what, P, supports):
    """One answer set per solution of the constrained problem, and no other: reachability
    from a fixed root admits no grid of two components (nor one grid twice, as a chosen
    root would), the cardinality rules no wrong count. With forward supports too (the
    default program under global constraints, where the search starts from a solution)."""
    from csplab.engine.sat import enumerate_solutions

    sols = {g.astype(np.int32).tobytes() for g in enumerate_solutions(P.without_constraints())
            if not P.violations(g)}  # fmt: skip
    got = _answer_grids(P, supports)
    assert len(got) == len(set(got)), what
    assert set(got) == sols, what
    assert 0 < len(sols) < sum(1 for _ in enumerate_solutions(P.without_constraints()))


# ----------------------------------------------------------------------------- grid variants


def _variants():
    E = ExampleModel([[0, 0, 1, 2], [0, 1, 2, 2], [1, 2, 2, 0], [0, 0, 0, 0]])
    yield "plain", from_example(E, (9, 7))
    yield "periodic", from_example(E, (8, 8), periodic=True)
    yield "periodic x only", from_example(E, (8, 6), periodic=(True, False))
    yield "fixed", from_example(E, (9, 7), fixed={(0, 0): 1, (4, 3): 2, (8, 6): 0})
    mask = np.ones((9, 7, E.K), dtype=bool)
    mask[3:6, 2:5, 0] = False
    yield "mask", from_example(E, (9, 7), mask=mask)
    P = from_example(E, (7, 7))
    idx = np.arange(49).reshape(7, 7)
    differ = ~np.eye(E.K, dtype=bool)
    yield "diagonal arcs", P.add_arcs(differ, idx[:-1, :-1].ravel(), idx[1:, 1:].ravel(), "diag")
    T = box_town(2, rng=0)
    yield "3D boundary auto", from_example(T, (8, 8, 5), boundary="auto")
    yield "3D periodic fixed", from_example(T, (6, 6, 4), periodic=(True, True, False),
                                                    fixed={(2, 2, 0): 1})  # fmt: skip


@pytest.mark.parametrize(("what", "P"), list(_variants()), ids=[w for w, _ in _variants()])
def test_grid_variants_agree_with_backtracking(what, P):
    ref = solve(P, "backtrack", rng=0)
    for opts in ({}, {"grounding": "gringo"}):
        r = solve(P, "asp", rng=3, **opts)
        assert r.status == ref.status, (what, opts)
        if r.ok:
            assert len(P.violations(r.grid)) == 0
            fixed = P.fixed_grid >= 0
            assert (r.grid[fixed] == P.fixed_grid[fixed]).all()


# ----------------------------------------------------------------------------- unsat


def test_fixed_cell_conflict_wiped_out_by_arc_consistency():
    P = from_example(CHECKER, (3, 3), fixed={(0, 0): 0, (0, 1): 0})
    r = solve(P, "asp", rng=0)
    assert r.status == "unsat"
    assert "arc-consistency wipe-out" in r.stats["proof"]
    assert len(r.stats["fail_cell"]) == 2
    assert "solver_stats" not in r.stats  # decided before clingo


def _clique_colouring(n, colours, fixed=None):
    """Colouring of the complete graph K_n (unsatisfiable for fewer than n colours; arc
    consistency prunes nothing while two or more colours are left per cell)."""
    arcs = [(u, v, 0) for u in range(n) for v in range(u + 1, n)]
    eq = np.eye(colours, dtype=bool)
    P = Problem((n,), np.ones((n, colours), dtype=bool), [~eq], arcs)
    return P if fixed is None else with_fixed(P, fixed)


@pytest.mark.parametrize(
    "P",
    [
        _clique_colouring(4, 3, {(0,): 0}),
        _clique_colouring(5, 4, {(2,): 3}),
        from_example(CHECKER, (5, 4), periodic=True),  # odd cycle
    ],
    ids=["K4 3 colours fixed", "K5 4 colours fixed", "odd periodic checkerboard"],
)
def test_unsat_proven_by_clingos_search(P):
    assert encode(P).ok  # arc consistency does not see it
    for opts in ({}, {"grounding": "gringo"}, {"encoding": "direct"}):
        r = solve(P, "asp", rng=0, **opts)
        assert r.status == "unsat"
        assert r.stats["proof"].startswith("clingo")
        assert r.stats["solver_status"] == "UNSAT"


def test_satisfiable_clique_with_enough_colours():
    r = solve(_clique_colouring(5, 5, {(2,): 3}), "asp", rng=0, time_limit=30)
    assert r.ok and sorted(r.grid.tolist()) == [0, 1, 2, 3, 4] and r.grid[2] == 3


# ----------------------------------------------------------------------------- time limits


def test_time_limit_cancels_the_search():
    P = _clique_colouring(14, 13)  # the pigeonhole principle: exponential for clause learning
    t0 = time.perf_counter()
    r = solve(P, "asp", rng=0, time_limit=1.5)
    wall = time.perf_counter() - t0
    assert r.status == "timeout"
    assert wall < 1.5 + 1.0
    assert r.stats["solver_status"] == "UNKNOWN"  # the child stopped its own search
    assert r.stats["conflicts"] > 0 and "search_s" in r.stats["solver_stats"]


@pytest.mark.parametrize("limit", [0.3, 1.5])
def test_time_limit_while_grounding_a_large_problem(limit):
    big = from_example(box_town(2, rng=0), (30, 30, 8))  # 1.7 million rules
    solve(from_example(box_town(1, rng=0), (3, 3, 3)), "asp", rng=0)  # load kernels
    t0 = time.perf_counter()
    r = solve(big, "asp", rng=0, time_limit=limit)
    wall = time.perf_counter() - t0
    assert r.status == "timeout"
    assert wall < limit + 1.0
    assert (r.grid == -1).all()


# ----------------------------------------------------------------------------- seeds


def test_same_seed_same_grid_different_seeds_differ():
    P = from_example(box_town(2, rng=0), (12, 12, 6), boundary="auto")
    a, b, c = (solve(P, "asp", rng=s) for s in (7, 7, 8))
    assert a.ok and b.ok and c.ok
    assert np.array_equal(a.grid, b.grid)
    assert np.mean(a.grid != c.grid) > 0.05
    # the seed alone does not vary clingo's answer (hence the random signs)
    d, e = (solve(P, "asp", rng=s, diversity="none") for s in (7, 8))
    assert np.array_equal(d.grid, e.grid)
    f, g = (solve(P, "asp", rng=s, diversity="label") for s in (7, 8))
    assert np.mean(f.grid != g.grid) > 0.05


def test_global_constraints_start_from_a_catalog_solution_by_default():
    """``diversity="auto"``: under global constraints the search starts from a seeded
    Alg. 3.1 solution (City 40x40x10 with its constraints times out without it) and loads
    the forward supports only; clasp confirms that solution, so it is the output. Without
    global constraints the default stays random signs on both directions."""
    from csplab.engine.alg31 import solution_hint
    from csplab.testing.synthetic import connected_city

    _, P = connected_city((8, 8, 4))
    r = solve(P, "asp", rng=4)
    assert r.ok and not P.violations(r.grid)
    s = r.stats
    assert (s["diversity"], s["hint"], s["supports"]) == ("catalog", "catalog solution", "forward")
    assert s["conflicts"] == 0 and "--sign-def=rnd" not in s["solver_stats"]["args"]
    rng = np.random.default_rng(4)
    rng.integers(2**31 - 1)  # clingo's seed comes first
    assert np.array_equal(r.grid.reshape(-1), solution_hint(P, rng))
    q = solve(P.without_constraints(), "asp", rng=4).stats
    assert (q["diversity"], q["supports"]) == ("sign", "both") and "hint" not in q
    assert "--sign-def=rnd" in q["solver_stats"]["args"]
    # the defaults stay overridable
    o = solve(P, "asp", rng=4, diversity="label", supports="both").stats
    assert (o["diversity"], o["supports"]) == ("label", "both") and "hint" not in o


def test_a_failed_hint_loads_both_directions(monkeypatch):
    """When Alg. 3.1 finds no solution, the search starts from random preferred labels on
    both directions of supports (forward only propagates too weakly to search); an error
    in it is raised."""
    import csplab.solvers.asp as asp
    from csplab.testing.synthetic import connected_city

    _, P = connected_city((6, 6, 4))
    monkeypatch.setattr(asp, "solution_hint", lambda *a: None)
    r = solve(P, "asp", rng=2)
    assert r.ok and not P.violations(r.grid)
    assert (r.stats["hint"], r.stats["supports"]) == ("random labels", "both")
    assert solve(P, "asp", rng=2, supports="forward").stats["supports"] == "forward"

    def broken(*a):
        raise CsplabError("no hint today")

    monkeypatch.setattr(asp, "solution_hint", broken)
    with pytest.raises(CsplabError, match="no hint today"):
        solve(P, "asp", rng=2)


def test_seed_is_drawn_from_rng_only():
    P = from_example(CHECKER, (4, 4))
    np.random.seed(1)  # noqa: NPY002 - the global RNG must not matter
    a = solve(P, "asp", rng=5).stats["solver_stats"]["seed"]
    np.random.seed(2)  # noqa: NPY002
    b = solve(P, "asp", rng=5).stats["solver_stats"]["seed"]
    assert a == b == int(np.random.default_rng(5).integers(2**31 - 1))


# ----------------------------------------------------------------------------- the rest


def test_arc_consistency_alone_solves_it_without_clingo():
    P = from_example(ExampleModel([0, 1, 2]), (3,))
    r = solve(P, "asp", rng=0)
    assert r.ok and r.grid.tolist() == [0, 1, 2]
    assert r.stats["solve_s"] == 0.0 and "solver_stats" not in r.stats


def test_stats():
    P = from_example(box_town(2, rng=0), (6, 6, 4))
    s = solve(P, "asp", rng=0).stats
    assert s["rules"] > s["x_vars"] > 0 and s["atoms"] == s["x_vars"]
    assert s["ground_s"] >= s["encode_s"] and s["solve_s"] > 0
    assert s["solver_stats"]["clingo"].count(".") == 2
    assert {"choices", "conflicts"} <= set(s)


def test_options_are_checked():
    P = from_example(CHECKER, (3, 3))
    with pytest.raises(InputError, match="unknown option"):
        solve(P, "asp", rng=0, order="scanline")
    with pytest.raises(InputError, match="no backends"):
        solve(P, "asp:gringo", rng=0)
    with pytest.raises(InputError, match="grounding must be one of"):
        solve(P, "asp", rng=0, grounding="lparse")


def test_missing_clingo_is_one_dependency_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "clingo", None)
    P = from_example(CHECKER, (3, 3))
    with pytest.raises(DependencyError, match=r"csplab\[asp\]"):
        AspSolver().solve(P, rng=np.random.default_rng(0), seed=0)


def test_a_failing_child_is_reported():
    report, _ = _run_child(["--no-such-option"], iter([b"asp 1 0 0\n0\n"]), read="atoms", nx=0,
                           deadline=None)  # fmt: skip
    assert report is not None and report["status"] == "ERROR"
    report, _ = _run_child([], iter([b"asp 1 0 0\nnonsense\n"]), read="atoms", nx=0,
                           deadline=None)  # fmt: skip
    assert report is not None and report["status"] == "ERROR"


def test_a_child_crash_is_an_error(monkeypatch):
    import csplab.solvers.asp as asp

    monkeypatch.setattr(asp, "_child_source", lambda: "import sys; sys.exit(3)")
    P = from_example(box_town(2, rng=0), (5, 5, 3))
    with pytest.raises(CsplabError, match="exited with code 3"):
        solve(P, "asp", rng=0)


def test_global_constraints_with_gringo_are_refused_before_any_work(monkeypatch):
    """The refusal comes before the Alg. 3.1 start (which could run long), in one line."""
    import csplab.solvers.asp as asp
    from csplab.testing.synthetic import connected_city

    def no_hint(*a, **k):
        raise AssertionError("the hint ran before the refusal")

    monkeypatch.setattr(asp, "solution_hint", no_hint)
    _, P = connected_city((8, 8, 4))
    with pytest.raises(InputError, match="global constraints need grounding='csplab'"):
        solve(P, "asp", rng=0, grounding="gringo")
