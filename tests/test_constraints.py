"""Global constraints (csplab.constraints): the checker, every solver against brute force,
the propagators, the file, the CLI and the DeBroglie importer."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import csplab
from csplab import ExampleModel, Problem
from csplab.constraints import (
    Connected,
    Count,
    MaxRun,
    Separation,
    constraints_json,
    mirror,
    parse_constraints,
    propagate_all,
    rotate,
)
from csplab.engine.sat import enumerate_solutions
from csplab.errors import FormatError
from csplab.grids import from_example
from csplab.io.constraints import read_constraints

from .io._helpers import installed_solvers

DATA = Path(__file__).parent / "io" / "data"
SHARED = Path(__file__).resolve().parents[2] / "shared" / "anchors-data"
EXACT = [s for s in ("sat", "cpsat", "asp", "perfect", "backtrack") if s in installed_solvers()]

E2 = ExampleModel([[0, 0, 1], [1, 0, 0], [0, 1, 0]])  # two labels, many grids
E3 = ExampleModel([[0, 1, 2, 0], [2, 0, 1, 1], [1, 2, 0, 2]])  # three labels


def brute(P: Problem) -> list[np.ndarray]:
    """Every solution of ``P``: the grids of the arcs alone, filtered by violations()."""
    return [g for g in enumerate_solutions(P.without_constraints()) if not P.violations(g)]


def kinds(P: Problem) -> list:
    return [
        Count([1], min=2, max=3),
        Count([0], max=4, region=((0, 1), (0, 1))),
        Connected([1]),
        Connected([1], cells=(0,)),
        mirror(P, "x"),
        rotate(P, 2),
        Separation([1], 2),
        MaxRun([0], 2),
        MaxRun([1], 1, axes=[1]),
    ]


@pytest.mark.parametrize("i", range(9))
def test_every_exact_solver_agrees_with_brute_force(i):
    base = from_example(E2, (3, 4))
    con = kinds(base)[i]
    P = base.with_constraints([con])
    sols = brute(P)
    keys = {g.tobytes() for g in sols}
    # enumeration with the constraints (SAT + cuts) finds exactly the same grids
    assert {g.tobytes() for g in enumerate_solutions(P)} == keys
    for solver in EXACT:
        for seed in range(2):
            r = csplab.solve(P, solver, rng=seed)
            if not sols:
                assert r.status == "unsat", (solver, con.describe(P))
            else:
                assert r.status == "solved", (solver, con.describe(P), r.stats)
                assert r.grid.astype(np.int32).tobytes() in keys


def test_violations_catch_each_planted_breach():
    P = from_example(E2, (4, 4))
    g = np.zeros((4, 4), dtype=np.int32)
    g[0, 0] = g[3, 3] = 1
    g[1, 0] = 1
    cases = {
        "count": Count([1], max=2),
        "connected": Connected([1]),
        "mirror": mirror(P, "y"),
        "rotate": rotate(P, 1),
        "separation": Separation([1], 3),
        "max-run": MaxRun([0], 3),
    }
    for name, con in cases.items():
        v = P.with_constraints([con]).violations(g)
        assert len(v) == len(v.arcs) + len(v.cells) + 1 and v.constraints, name
        assert name.split("-")[0] in v.constraints[0].replace("rotation", "rotate")
        assert "broken constraints" in v.describe()
    ok = P.with_constraints([Count([1], min=3, max=3), MaxRun([1], 2), Separation([1], 1)])
    assert not ok.violations(g).constraints


def test_propagators_are_sound_and_complete_on_assignments():
    """No solution loses a label to propagate_all; a breaking assignment is refuted."""
    base = from_example(E3, (3, 3))
    rng = np.random.default_rng(0)
    for con in kinds(base)[:8]:
        if isinstance(con, MaxRun | Separation | Count | Connected):
            con = type(con)(**{**con.__dict__, "labels": [1]})
        P = base.with_constraints([con])
        sols = brute(P)
        for _ in range(20):
            dom = P.domains.copy()
            dom &= rng.random(dom.shape) < 0.8
            d = propagate_all(P, dom)
            for g in sols:
                inside = dom[np.arange(P.n), g.reshape(-1)].all()
                if inside:  # a solution inside the domains survives the pruning
                    assert d is not None and d[np.arange(P.n), g.reshape(-1)].all()
        for g in enumerate_solutions(base.without_constraints(), limit=50):
            one = np.zeros((P.n, P.K), dtype=bool)
            one[np.arange(P.n), g.reshape(-1)] = True
            assert (propagate_all(P, one) is None) == bool(P.violations(g).constraints)


@st.composite
def random_constraints(draw, P):
    out = []
    for _ in range(draw(st.integers(1, 2))):
        kind = draw(st.sampled_from(["count", "connected", "separation", "max-run", "mirror"]))
        labels = draw(st.lists(st.integers(0, P.K - 1), min_size=1, max_size=2, unique=True))
        if kind == "count":
            lo = draw(st.integers(0, 6))
            out.append({"type": "count", "labels": labels, "min": lo,
                        "max": lo + draw(st.integers(0, 4))})  # fmt: skip
        elif kind == "connected":
            out.append({"type": "connected", "labels": labels})
        elif kind == "separation":
            out.append(
                {"type": "separation", "labels": labels, "distance": draw(st.integers(2, 3))}
            )
        elif kind == "max-run":
            out.append({"type": "max-run", "labels": labels, "n": draw(st.integers(1, 2))})
        else:
            out.append({"type": "mirror", "axis": draw(st.sampled_from(["x", "y"]))})
    return out


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_random_constraints_sat_and_backtrack_against_brute_force(data):
    base = from_example(E3, (3, 3))
    entries = data.draw(random_constraints(base))
    P = base.with_constraints(parse_constraints(entries, base))
    sols = brute(P)
    keys = {g.tobytes() for g in sols}
    for solver in ("sat", "backtrack"):
        r = csplab.solve(P, solver, rng=data.draw(st.integers(0, 99)))
        assert r.status == ("solved" if sols else "unsat"), (solver, entries)
        if sols:
            assert r.grid.astype(np.int32).tobytes() in keys
    # incomplete solvers never return a broken grid as solved
    for solver in ("catalog", "blocks", "hybrid"):
        r = csplab.solve(P, solver, rng=1, restarts=2)
        assert r.status != "solved" or not P.violations(r.grid), (solver, entries)


def test_file_round_trip_and_errors(tmp_path):
    P = csplab.examples.load_model(DATA / "pipes.xml").problem((6, 6))
    doc = {"constraints": [
        {"type": "count", "labels": ["cross"], "min": 0, "max": 2,
         "region": {"from": [0, 0], "to": [-1, 2]}},
        {"type": "connected", "labels": ["line", "corner 0"], "cells": [[0, 0], [-1, -1]]},
        {"type": "mirror", "axis": "x"},
        {"type": "rotate", "turns": 2},
        {"type": "separation", "labels": ["tee 0"], "distance": 3},
        {"type": "max-run", "labels": [0], "n": 4, "axes": ["y"]},
    ]}  # fmt: skip
    f = tmp_path / "c.json"
    f.write_text(json.dumps(doc))
    cons = read_constraints(f, P)
    Q = P.with_constraints(cons)
    assert [c.describe(Q).split()[0] for c in cons] == [
        "count", "connected", "mirror", "rotation", "separation", "max-run"]  # fmt: skip
    assert cons[0].region == ((0, 5), (0, 2)) and cons[1].cells == (0, 35)
    again = parse_constraints(constraints_json(Q), P)
    assert [c.describe(Q) for c in again] == [c.describe(Q) for c in cons]
    # the tileset's own mirror: "corner 0" becomes another corner under the x-mirror
    m = cons[2].label_map
    assert P.names[m[P.names.index("corner 0")]].startswith("corner ")
    assert m[P.names.index("corner 0")] != P.names.index("corner 0")
    for bad, what in [
        ({"constraints": [{"type": "count", "labels": ["crossing"]}]}, "unknown label 'crossing'"),
        ({"constraints": [{"type": "blob"}]}, "type 'blob' is not one of"),
        ({"constraints": [{"type": "count", "labels": [0], "max": "2"}]}, "'max' must be an int"),
        ({"constraints": [{"type": "connected", "labels": [0], "cells": [[9, 9]]}]}, "outside"),
        ({"constraints": [{"type": "mirror", "axis": "z"}]}, "axis 'z' is not one of x, y"),
        ({"constraints": [{"type": "count", "labels": [0], "mni": 1}]}, "takes no 'mni'"),
        ({"constraints": {"type": "count"}}, "a constraints file is"),
    ]:
        f.write_text(json.dumps(bad))
        with pytest.raises(FormatError, match=what) as e:
            read_constraints(f, P)
        assert str(f) in str(e.value) and "\n" not in str(e.value)
    f.write_text("{")
    with pytest.raises(FormatError, match="line 1"):
        read_constraints(f, P)


def test_incomplete_solvers_retry_or_report(tmp_path):
    P = csplab.examples.load_model(DATA / "pipes.xml").problem(
        (10, 10), boundary={f: 0 for f in ("x-", "x+", "y-", "y+")}
    )
    Q = P.with_constraints(parse_constraints(
        [{"type": "connected", "labels": ["line", "corner", "tee", "cross"]},
         {"type": "count", "labels": ["cross"], "max": 0}], P))  # fmt: skip
    for solver in ("catalog", "hybrid", "blocks"):
        for seed in range(3):
            r = csplab.solve(Q, solver, rng=seed, restarts=3)
            assert r.status in ("solved", "failed")
            if r.status == "solved":
                assert not Q.violations(r.grid)
            elif solver == "blocks":
                assert r.stats["broken"] and r.stats["breaches"] > 0  # the breach is named


def _run(capsys, *args):
    from csplab.cli import main

    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("solver", ["sat", "backtrack", "catalog"])
def test_cli_synthesize_and_check_honour_the_file(tmp_path, capsys, solver):
    cfile = tmp_path / "c.json"
    cfile.write_text(json.dumps({"constraints": [
        {"type": "connected", "labels": ["line", "corner", "tee", "cross"]},
        {"type": "count", "labels": ["cross"], "min": 0, "max": 2},
        {"type": "count", "labels": ["tee"], "min": 4}]}))  # fmt: skip
    out = tmp_path / "o.npy"
    code, o, err = _run(capsys, "synthesize", DATA / "pipes.xml", "--size", "24x24",
                        "--solver", solver, "--constraints", cfile, "--seed", "1",
                        "--restarts", "20", "--out", out)  # fmt: skip
    assert code == 0, err
    g = np.load(out)
    P = csplab.examples.load_model(DATA / "pipes.xml").problem((24, 24))
    Q = P.with_constraints(read_constraints(cfile, P))
    assert not Q.violations(g)
    assert int(np.isin(g, [P.names.index("cross 0")]).sum()) <= 2
    code, o, _ = _run(capsys, "check", DATA / "pipes.xml", out, "--constraints", cfile)
    assert code == 0 and o.startswith("0 violations")
    strict = tmp_path / "s.json"
    k = int((g == 11).sum())
    strict.write_text(json.dumps({"constraints": [{"type": "count", "labels": ["cross"],
                                                    "max": k - 1}]}))  # fmt: skip
    code, o, _ = _run(capsys, "check", DATA / "pipes.xml", out, "--constraints", strict)
    if k:
        assert code == 1 and "count of {cross 0}" in o


def test_cli_bad_constraints_file_is_one_line(tmp_path, capsys):
    cfile = tmp_path / "c.json"
    cfile.write_text('{"constraints": [{"type": "count", "labels": ["nope"]}]}')
    code, _, err = _run(capsys, "synthesize", DATA / "pipes.xml", "--size", "5x5",
                        "--constraints", cfile)  # fmt: skip
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "constraints[0] (count): unknown label 'nope'" in lines[0]


def test_debroglie_constraints_are_imported():
    text = json.dumps({
        "tiles": [{"value": "g"}, {"value": "r"}, {"value": "t"}],
        "adjacencies": [{"left": ["g", "r", "t"], "right": ["g", "r", "t"]},
                        {"up": ["g", "r", "t"], "down": ["g", "r", "t"]}],
        "width": 6, "height": 5,
        "constraints": [
            {"type": "path", "tiles": ["r"], "endPoints": [{"x": 0, "y": 0}, {"x": 5, "y": 4}]},
            {"type": "count", "tiles": ["t"], "comparison": "exactly", "count": 2},
            {"type": "maxConsecutive", "tiles": ["g"], "maxCount": 3, "axes": ["x"]},
            {"type": "separation", "tiles": ["t"], "minDistance": 3},
            {"type": "mirrorX"},
        ]})  # fmt: skip
    from csplab.io.debroglie import parse_debroglie

    rs = parse_debroglie(text, path="d.json", strict=True)
    P = rs.problem()
    assert [c.kind for c in P.constraints] == [
        "connected", "count", "max-run", "separation", "symmetric"]  # fmt: skip
    # DeBroglie's y points down: its (0, 0) is csplab's top-left cell (0, 4)
    assert P.constraints[0].cells == (P.cell((0, 4)), P.cell((5, 0)))
    for solver in EXACT:
        r = csplab.solve(P, solver, rng=3)
        assert r.status == "solved" and not P.violations(r.grid), solver
        assert (r.grid == rs.names.index("t")).sum() == 2


@pytest.mark.skipif(not (SHARED / "DeBroglie").is_dir(), reason="no ../shared/anchors-data")
@pytest.mark.parametrize("solver", installed_solvers())
def test_shared_edged_path_is_honoured(solver):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rs = csplab.examples.load_model(SHARED / "DeBroglie" / "edged_path_constraint.json")
    P = rs.problem()
    assert [c.kind for c in P.constraints] == ["connected"]
    r = csplab.solve(P, solver, rng=1, restarts=20, time_limit=60)
    if solver == "blocks":  # checks only: a run with a broken path is failed, never solved
        assert r.status in ("solved", "failed")
    else:
        assert r.status == "solved", r.stats
    if r.status == "solved":
        assert not P.violations(r.grid)
    # without the constraint, Alg. 3.1 breaks the path (DeBroglie's reason to have it)
    free = P.without_constraints()
    broken = sum(
        bool(P.violations(csplab.solve(free, "catalog", rng=s, restarts=20).grid).constraints)
        for s in range(5)
    )
    assert broken >= 3


def test_blocks_repairs_a_model_that_breaks_the_constraints():
    E = csplab.load_example("loops")
    P = from_example(E, (16, 16))
    paths = [b for b in range(E.K) if E.names[b] != "empty"]
    Q = P.with_constraints([Connected(paths), Count(paths, min=20, max=60)])
    r = csplab.solve(Q, "blocks", rng=1, block=6, sweeps=3)
    assert r.status == "solved" and not Q.violations(r.grid)
    assert r.stats["energies"][0] > 0 and r.stats["breaches"] == 0  # started broken
    for con, grid in [(Count([1], min=3), np.zeros((4, 4), dtype=np.int64))]:
        R = from_example(E, (4, 4)).with_constraints([con])
        assert con.excess(R, grid.reshape(-1)) == 3


def test_constraints_file_given_as_a_model_says_so(capsys):
    f = Path(__file__).parent / "constraints" / "pipes_network.json"
    code, _, err = _run(capsys, "synthesize", f, "--size", "5x5")
    assert code == 2 and "this is a constraints file" in err and "--constraints" in err
    code, _, err = _run(capsys, "synthesize", DATA / "pipes.xml", "--size", "12x12",
                        "--solver", "sat", "--constraints", f, "--seed", "2")  # fmt: skip
    assert code == 0, err


def test_alg31_counts_the_steps_where_a_constraint_pruned():
    """``constraint_prunings`` counts the Alg. 3.1 steps after which a global constraint
    removed labels: with at most 2 cells of label 1, once two are placed the others lose it
    (a pruning, not a conflict), and the run still ends solved with exactly that count."""
    from csplab.engine.alg31 import run_alg31

    P = from_example(E2, (5, 5)).with_constraints([Count([1], max=2)])
    seen = 0
    for seed in range(6):
        r = run_alg31(P, np.random.default_rng(seed))
        assert r.stats["constraint_prunings"] <= r.stats["assigned"]
        if r.status == "solved":
            assert not P.violations(r.grid)
            seen += r.stats["constraint_prunings"]
    assert seen > 0
