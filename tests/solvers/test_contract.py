"""The declared solver contract: declarations drive validation, `csplab info`, the CLI, the
conformance suite and the experiments; a toy solver registered once appears everywhere."""

import json
import os
import textwrap

import numpy as np
import pytest

from csplab import ExampleModel, solve
from csplab.cli import main
from csplab.errors import CsplabError, InputError
from csplab.grids import from_example
from csplab.solvers import (
    REGISTRY,
    available_solvers,
    markdown_table,
    register,
    solver_class,
    solver_names,
    unknown_stats,
)
from csplab.solvers.base import Call, Solver

TOY = textwrap.dedent(
    """
    from csplab.catalog import Propagator
    from csplab.engine.completability import search_solution
    from csplab.solvers.base import TIME_LIMIT, Option, Solver

    class ToySolver(Solver):
        name = "toy"
        complete = True
        description = "toy: depth-first search with arc consistency"
        options = (Option("flavour", str, "plain", "a toy option", values=("plain", "salty")),
                   TIME_LIMIT)

        def run(self, problem, call):
            eng = Propagator(problem)
            g = search_solution(eng) if eng.ok else None
            if g is None:
                return self.result("unsat", None, problem, {}, call, proof="exhaustive search")
            return self.result("solved", g, problem, {"assigned": int(problem.n)}, call)
    """
)


@pytest.fixture
def toy(tmp_path, monkeypatch):
    mod = tmp_path / "csplab_toy_solver.py"
    mod.write_text(TOY)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv(
        "PYTHONPATH", os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")])
    )
    monkeypatch.setenv("CSPLAB_SOLVERS", "")
    monkeypatch.setitem(REGISTRY, "toy", "csplab_toy_solver:ToySolver")
    register("toy", "csplab_toy_solver:ToySolver")  # one registry entry
    yield "toy"
    REGISTRY.pop("toy", None)


def test_every_solver_subclasses_the_contract():
    for name in solver_names():
        cls = solver_class(name)
        assert issubclass(cls, Solver) and cls.name == name
        assert cls.description and all(o.doc for o in cls.options)
        assert cls.option("time_limit") is not None, name  # every solver honours a time limit


def test_validation_comes_from_the_declaration():
    cls = solver_class("catalog")
    with pytest.raises(InputError, match=r"unknown option.*block"):
        cls.validate({"block": 3})
    with pytest.raises(InputError, match="choice must be one of uniform, weighted"):
        cls.validate({"choice": "heavy"})
    with pytest.raises(InputError, match="time_limit must be a positive number of seconds"):
        cls.validate({"time_limit": -1})
    assert solver_class("blocks").validate({"block": "4x3"})["block"] == (4, 3)
    P = from_example(ExampleModel([[0, 1], [1, 0]]), (4, 4))
    with pytest.raises(InputError, match="has no backends"):
        solve(P, "catalog:fast")


def test_hybrid_and_perfect_accept_scan_orders():
    # the bug that motivated the contract: hybrid rejected order="scan:yx"
    P = from_example(ExampleModel([[0, 1, 0, 1], [1, 0, 1, 0]]), (5, 4))
    for s in ("hybrid", "perfect", "catalog", "blocks"):
        assert solve(P, s, rng=1, order="scan:yx").status == "solved", s


def test_stats_use_the_glossary():
    P = from_example(ExampleModel([[0, 1], [1, 0]]), (6, 5))
    for info in available_solvers():
        if not info.get("installed"):
            continue
        r = solve(P, info["name"], rng=2)
        assert not unknown_stats(r.stats), (info["name"], unknown_stats(r.stats))


def test_result_is_the_one_way_out():
    P = from_example(ExampleModel([[0, 1], [1, 0]]), (3, 2))
    cls = solver_class("catalog")
    call = Call(np.random.default_rng(0), 7, None, cls.validate({}))
    r = cls().result("timeout", None, P, {"assigned": 0}, call)
    assert r.grid.shape == (3, 2) and r.grid.dtype == np.int32 and (r.grid == -1).all()
    assert r.solver == "catalog" and r.seed == 7 and r.time_s > 0
    with pytest.raises(CsplabError, match="unsat without a proof"):
        cls().result("unsat", None, P, {}, call)
    r = cls().result("unsat", None, P, {}, call, proof="a wipe-out")
    assert r.stats["proof"] == "a wipe-out"


def test_readme_solver_table_is_generated():
    from csplab.readme import stale_sections

    with open(os.path.join(os.path.dirname(__file__), "..", "..", "README.md")) as f:
        text = f.read()
    assert stale_sections(text) == [], "run: python -m csplab.readme --write"
    assert markdown_table().count("\n| `") == len(solver_names())


def test_a_toy_solver_registered_once_appears_everywhere(toy, capsys):
    # csplab info (text and JSON)
    assert main(["info"]) == 0
    assert "toy: depth-first search" in capsys.readouterr().out
    assert main(["info", "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    toy_info = next(s for s in info["solvers"] if s["name"] == "toy")
    assert toy_info["complete"] and toy_info["options"][0]["values"] == ["plain", "salty"]
    # the CLI's --solver and its options
    assert main(["synthesize", "line", "--size", "6x4", "--solver", "toy", "--seed", "1",
                 "--option", "flavour=salty"]) == 0  # fmt: skip
    assert "solved" in capsys.readouterr().out
    assert main(["synthesize", "line", "--size", "6x4", "--solver", "toy",
                 "--option", "flavour=sweet"]) == 2  # fmt: skip
    assert "flavour must be one of plain, salty" in capsys.readouterr().err
    # the conformance suite's checks
    from tests.solvers.test_conformance import check_solver_on

    rng = np.random.default_rng(0)
    for _ in range(20):
        E = ExampleModel(rng.integers(0, 3, size=(3, 3)))
        P = from_example(E, (4, 3), fixed={(0, 0): int(rng.integers(0, 3))})
        check_solver_on("toy", {}, P, int(rng.integers(1000)))
    # the experiments (worker processes see the registration)
    tmp = os.environ["PYTHONPATH"].split(os.pathsep)[0]
    assert main(["experiment", "fig3_8", "--quick", "--solver", "toy", "--jobs", "2",
                 "--store", tmp + "/s.sqlite", "--out", tmp + "/out"]) == 0  # fmt: skip
    assert "12 run (solved 12) on 2 local processes" in capsys.readouterr().out
