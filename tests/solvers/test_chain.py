"""solve(fallback=...): an exact solver finishes what an incomplete one gave up on, and
modify in blocks' exact block completion."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from csplab import from_example, load_example, solve
from csplab.errors import InputError
from csplab.solvers import chain
from csplab.solvers.blocks import ExactCompletion

# Fig. 3.5's example: Alg. 3.1 fails on seed 3 in the figures' scan order
FALLIBLE = from_example(load_example("fig3_5a"), (8, 8))
# a checkerboard cannot wrap around an odd size: no solution, and Alg. 3.1 only gives up
ODD = from_example(load_example("fig3_1b"), (5, 5), periodic=True)


def test_without_a_fallback_the_incomplete_run_is_the_result() -> None:
    r = solve(FALLIBLE, "catalog", rng=3, order="scan:yx")
    assert (r.status, r.solver) == ("failed", "catalog") and "fallback" not in r.stats
    assert solve(FALLIBLE, "catalog", rng=3, order="scan:yx", fallback="none").status == "failed"


@pytest.mark.parametrize("fallback", ["auto", "sat", "backtrack"])
def test_the_fallback_solves_and_says_who_did(fallback: str) -> None:
    r = solve(FALLIBLE, "catalog", rng=3, order="scan:yx", fallback=fallback)
    exact = "sat" if fallback == "auto" else fallback
    assert r.status == "solved" and FALLIBLE.is_solution(r.grid)
    assert (r.solver, r.stats["fallback"], r.stats["fallback_from"]) == (exact, exact, "catalog")
    assert r.stats["attempts"] == 1 and r.seed == 3 and r.stats["gave_up_s"] >= 0
    again = solve(FALLIBLE, "catalog", rng=3, order="scan:yx", fallback=fallback)
    assert (again.grid == r.grid).all()  # the same seed, the same bytes
    alone = solve(FALLIBLE, exact, rng=r.stats["attempt_seed"], choice="uniform")
    assert (alone.grid == r.grid).all()  # the recorded seed reruns the fallback alone


def test_a_solution_found_by_a_restart_needs_no_fallback() -> None:
    r = solve(FALLIBLE, "catalog", rng=3, order="scan:yx", restarts=10, fallback="auto")
    assert (r.status, r.solver) == ("solved", "catalog") and "fallback_from" not in r.stats


@pytest.mark.parametrize("fallback, proof", [("sat", "refutation by"),
                                             ("backtrack", "search tree exhausted")])  # fmt: skip
def test_unsat_comes_from_the_exact_solver_with_its_proof(fallback: str, proof: str) -> None:
    r = solve(ODD, "catalog", rng=1, restarts=3, fallback=fallback)
    assert r.status == "unsat" and r.stats["proof"].startswith(proof)
    assert r.stats["fallback_from"] == "catalog" and r.stats["attempts"] == 4


def test_blocks_without_a_starting_model_falls_back_or_raises() -> None:
    from csplab.errors import NoTrivialSolutionError

    with pytest.raises(NoTrivialSolutionError):
        solve(ODD, "blocks", rng=1)
    r = solve(ODD, "blocks", rng=1, fallback="auto")
    assert r.status == "unsat" and r.stats["fallback_from"] == "blocks"
    assert r.stats["reason"].startswith("modify-in-blocks needs a consistent starting model")


def test_no_time_left_is_a_timeout_not_a_verdict() -> None:
    big = from_example(load_example("fig3_1b"), (41, 41), periodic=True)
    r = solve(big, "catalog", rng=1, restarts=10**6, time_limit=0.05, fallback="sat")
    assert r.status == "timeout" and "proof" not in r.stats and r.time_s < 1.0
    assert r.solver == "catalog" and r.stats["attempts"] > 1
    # with time left, the fallback runs within what remains of the same budget
    r = solve(ODD, "catalog", rng=1, restarts=3, time_limit=30.0, fallback="sat")
    assert r.status == "unsat" and r.time_s < 30.0


def test_auto_uses_backtrack_without_python_sat(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "pysat", None)
    assert chain.exact_solver(FALLIBLE, "auto", "catalog") == "backtrack"
    with pytest.raises(InputError, match="python-sat"):
        chain.check_fallback("sat")


def test_auto_finishes_a_model_too_large_for_sat_in_blocks(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    P = from_example(load_example("castle"), (16, 16, 8), boundary="auto")
    monkeypatch.setattr(chain, "SAT_CELL_LABELS", 1000)  # "too large" for the test
    assert chain.exact_solver(P, "auto", "catalog") == "blocks"
    assert chain.exact_solver(P, "auto", "blocks") == "sat"  # blocks gave up: not again
    assert solve(P, "catalog", rng=1).status == "failed"  # measured: half the seeds fail
    r = solve(P, "catalog", rng=1, fallback="auto")
    assert r.status == "solved" and r.solver == "blocks" and r.stats["exact"] == "sat"
    assert P.is_solution(r.grid) and r.stats["fallback_from"] == "catalog"


def test_bad_fallback_is_one_line() -> None:
    with pytest.raises(InputError, match="fallback must be one of"):
        solve(FALLIBLE, "catalog", rng=1, fallback="maybe")


# ---------------------------------------------------------------- exact block completion


@pytest.mark.parametrize("exact", ["sat", "backtrack"])
def test_exact_block_completion_keeps_blocks_that_alg31_gave_up_on(exact: str) -> None:
    P = from_example(load_example("castle"), (24, 24, 8), boundary="auto")
    plain = solve(P, "blocks", rng=1, retries=0, block=6)
    r = solve(P, "blocks", rng=1, retries=0, block=6, exact=exact)
    assert plain.status == r.status == "solved" and P.is_solution(r.grid)
    # measured: 11 of 98 blocks fail their only Alg. 3.1 run at this seed; completed exactly,
    # every block gets new labels
    assert plain.stats["blocks_accepted"] < plain.stats["blocks_tried"]
    assert r.stats["exact_blocks"] > 0 and r.stats["exact_refuted"] == 0
    assert r.stats["blocks_accepted"] == r.stats["blocks_tried"]
    again = solve(P, "blocks", rng=1, retries=0, block=6, exact=exact)
    assert (again.grid == r.grid).all()


def test_exact_block_completion_is_off_by_default_and_leaves_the_thesis_sweep() -> None:
    P = from_example(load_example("loops"), (20, 20))
    a = solve(P, "blocks", rng=2, block=6, retries=1)
    b = solve(P, "blocks", rng=2, block=6, retries=1, exact="none")
    assert (a.grid == b.grid).all() and "exact_blocks" not in a.stats
    with pytest.raises(InputError, match="exact"):
        solve(P, "blocks", rng=2, block=6, exact="sat", workers=1)


def test_a_block_refuted_with_its_border_keeps_its_labels() -> None:
    # one block whose border leaves no labels: the exact solver proves it, the block stays
    E = load_example("fig3_1b")  # checkerboard: a block's border fixes its parity
    P = from_example(E, (8, 8))
    start = solve(P, "sat", rng=1).grid
    sub_cells = np.arange(64).reshape(8, 8)[2:5, 2:5].ravel()
    grid = start.copy().reshape(-1)
    sub = P.subproblem(sub_cells, grid, shape=(3, 3))
    assert solve(sub, "sat", rng=1).status == "solved"  # a consistent border: solvable
    completion = ExactCompletion("sat")
    labels, timed_out = completion(sub, np.random.default_rng(1), None)
    assert labels is not None and not timed_out and completion.solved == 1
    grid[sub_cells[0] - 1] = 1 - grid[sub_cells[0] - 1]  # break the border's parity
    bad = P.subproblem(sub_cells, grid, shape=(3, 3))
    labels, timed_out = completion(bad, np.random.default_rng(1), None)
    assert labels is None and not timed_out and completion.refuted == 1
