"""With default options, ``csplab synthesize`` solves every satisfiable built-in example and
shipped model file (tests/io/data, ../shared/anchors-data when present) and says ``unsat``
with the exact solver's proof line for the unsatisfiable ones: never 'not solved'.

The cases are those of ``benchmarks/default_failures.py`` (one list, loaded from there):
the default suite runs seed 1 (two or three seeds for the cases the incomplete solvers
fail on), the slow suite seeds 1-20, as the issue asks.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path
from types import ModuleType

import pytest

from csplab.cli import main

ROOT = Path(__file__).resolve().parents[2]


def _bench() -> ModuleType:
    spec = importlib.util.spec_from_file_location(
        "default_failures", ROOT / "benchmarks" / "default_failures.py"
    )
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


BENCH = _bench()
CASES = [*BENCH.cases(), *((g, []) for g in BENCH.GADGETS)]

#: the cases without a solution (everything else is satisfiable)
UNSAT = {
    "fig3_1d 20x20",  # no repeated label: no model larger than the example
    "fig3_1b periodic 21x21",  # a checkerboard cannot wrap around an odd size
    "fig3_1b periodic 5x5",
    "gadgets planar3sat unsat",  # the formulas have no satisfying assignment
}

#: measured on main (10 restarts, no fallback): the incomplete solver fails these seeds
FAST_SEEDS = {
    "fallible 20x20": (11,),
    "fallible 40x40": (1,),
    "gadgets planar3sat near": (1, 2),
    "gadgets planar3sat unsat": (1, 2),
}


def _outcome(label: str, args: list[str], seed: int) -> str:
    if label in BENCH.GADGETS:
        outcome: str = BENCH.run_gadgets(BENCH.GADGETS[label], seed)[0]
        return outcome
    outcome = BENCH.run_one(args, seed, BENCH.is_grid(args))[0]
    return outcome


def _check(label: str, args: list[str], seeds: tuple[int, ...] | range) -> None:
    want = "unsat" if label in UNSAT else "solved"
    got = {s: _outcome(label, args, s) for s in seeds}
    assert all(v == want for v in got.values()), f"{label}: {got}"


@pytest.mark.parametrize("label, args", CASES, ids=[c[0] for c in CASES])
def test_defaults_solve_or_prove_unsat(label: str, args: list[str]) -> None:
    _check(label, args, FAST_SEEDS.get(label, (1,)))


@pytest.mark.slow
@pytest.mark.parametrize("label, args", CASES, ids=[c[0] for c in CASES])
def test_defaults_solve_or_prove_unsat_seeds_1_to_20(label: str, args: list[str]) -> None:
    _check(label, args, range(1, 21))


def test_unsat_prints_the_proof_line(capsys: pytest.CaptureFixture[str]) -> None:
    for args in (["fig3_1b", "--size", "21x21", "--periodic"], ["fig3_1d", "--size", "20x20"]):
        code = main(["synthesize", *args, "--seed", "1"])
        out = capsys.readouterr().out
        assert code == 1 and out.startswith("unsat:"), out
        assert "\n  proof: " in out, out


def test_the_cases_cover_every_built_in_and_shipped_model() -> None:
    from csplab.examples import example_info

    labels = {c[0].split()[0] for c in CASES}
    assert {name for name, _ in example_info()} <= labels
    shipped = {
        p.name
        for p in (ROOT / "tests" / "io" / "data").rglob("*")
        if p.suffix in (".xml", ".json", ".png", ".tmx", ".svg", ".obj", ".off", ".stl")
    }
    # not models: the WFC tiles' pictures and two OBJ pieces that are not closed solids
    # (test inputs of the readers' errors)
    not_models = {"corner.png", "cross.png", "empty.png", "line.png", "tee.png",
                  "pillar.obj", "slab.obj"}  # fmt: skip
    covered = {Path(a[0]).name for _, a in CASES if a and Path(a[0]).suffix}
    assert shipped - not_models <= covered, shipped - not_models - covered
