"""Exact solvers started from a seeded Alg. 3.1 solution (:func:`solution_hint`): cpsat's
default hint, sat's ``choice="catalog"`` phases, asp's ``diversity="catalog"`` labels."""

from __future__ import annotations

import numpy as np
import pytest

import csplab
from csplab.engine.alg31 import run_alg31, solution_hint
from csplab.testing.synthetic import connected_city

CASES = [("cpsat", {}, "ortools"), ("sat", {"choice": "catalog"}, "pysat"),
         ("asp", {"diversity": "catalog"}, "clingo")]  # fmt: skip


@pytest.fixture(scope="module")
def city():
    return connected_city((12, 12, 6))[1]


def test_the_hint_goes_on_in_min_entropy_order_under_global_constraints(city):
    """On a small connected city scanline Alg. 3.1 solves about 1 run in 6 and min-entropy
    every run: every seed gets a hint, each one a solution of the constrained problem."""
    fails = sum(run_alg31(city, np.random.default_rng(s)).status != "solved" for s in range(6))
    assert fails >= 3  # scanline alone would leave seeds without a hint
    for seed in range(5):
        h = solution_hint(city, np.random.default_rng(seed))
        assert h is not None
        assert len(city.violations(h.reshape(city.shape).astype(np.int32))) == 0


@pytest.mark.parametrize("solver,opts,dep", CASES, ids=[c[0] for c in CASES])
def test_exact_solvers_start_from_the_hint(city, solver, opts, dep):
    pytest.importorskip(dep)
    for seed in range(3):
        r = csplab.solve(city, solver, rng=seed, time_limit=20, **opts)
        assert r.status == "solved" and len(city.violations(r.grid)) == 0
        assert r.stats["hint"] == "catalog solution"


def test_sat_default_starts_from_the_hint_under_global_constraints():
    """``choice="auto"`` (the default): a short attempt from uniform phases, then the hint,
    which the oracle confirms without a conflict. At 20×20×6 uniform phases need thousands
    of conflicts (2,554 for a seed that solved; two seeds timed out after 5,698 and 5,876)
    where the attempt gives up after ``PROBE_CONFLICTS``."""
    pytest.importorskip("pysat")
    from csplab.solvers.sat import PROBE_CONFLICTS

    Q = connected_city((20, 20, 6))[1]
    r = csplab.solve(Q, "sat", rng=0, time_limit=60)
    assert r.status == "solved" and len(Q.violations(r.grid)) == 0
    assert r.stats["choice"] == "catalog" and r.stats["hint"] == "catalog solution"
    assert r.stats["probe_conflicts"] >= PROBE_CONFLICTS
    assert r.stats["conflicts"] == r.stats["probe_conflicts"]  # the hint: no search
    again = csplab.solve(Q, "sat", rng=0, time_limit=60)
    assert np.array_equal(again.grid, r.grid)


def test_sat_default_keeps_what_the_uniform_attempt_finds(city):
    """When the uniform attempt solves the problem (a 12×12×6 connected city: 80-89
    conflicts) the default's output is ``choice="uniform"``'s, and no hint is computed."""
    pytest.importorskip("pysat")
    for seed in range(2):
        r = csplab.solve(city, "sat", rng=seed)
        u = csplab.solve(city, "sat", rng=seed, choice="uniform")
        assert r.status == "solved" and len(city.violations(r.grid)) == 0
        assert r.stats["choice"] == "uniform" and "hint" not in r.stats
        assert 0 < r.stats["probe_conflicts"] <= 300
        assert np.array_equal(r.grid, u.grid)


def test_sat_default_without_global_constraints_is_uniform():
    """No global constraints: the default is ``choice="uniform"``, byte for byte."""
    pytest.importorskip("pysat")
    from csplab import from_example, load_example

    for name, size, boundary in (("city", (10, 10, 6), "auto"), ("fig3_1b", (10, 8), None)):
        P = from_example(load_example(name), size, boundary=boundary)
        for seed in range(2):
            r = csplab.solve(P, "sat", rng=seed)
            u = csplab.solve(P, "sat", rng=seed, choice="uniform")
            assert r.status == "solved" and len(P.violations(r.grid)) == 0
            assert r.stats["choice"] == "uniform" and "probe_conflicts" not in r.stats
            assert np.array_equal(r.grid, u.grid)


def _broken(hint_of):
    """A hint that breaks the problem: the true hint with one inner cell (not fixed by the
    boundary) relabelled so that the grid has violations."""

    def hint(problem, rng, remaining=None):
        h = np.array(hint_of(problem, rng, remaining), dtype=np.int32).reshape(problem.shape)
        mid = tuple(n // 2 for n in problem.shape)
        for k in range(problem.K):
            h2 = h.copy()
            h2[mid] = k
            if len(problem.violations(h2)):
                return h2.reshape(-1)
        raise AssertionError("no label breaks the hint")

    return hint


def test_sat_goes_on_searching_when_the_hint_is_refuted(city, monkeypatch):
    """A hint refuted under its assumptions is no proof: the search goes on from its phases
    and solves (removing that second call would answer ``unsat`` on a solvable problem)."""
    pytest.importorskip("pysat")
    import csplab.solvers.sat as sat

    monkeypatch.setattr(sat, "PROBE_CONFLICTS", 1)  # the attempt gives up (it needs ~80)
    monkeypatch.setattr(sat, "solution_hint", _broken(solution_hint))
    r = csplab.solve(city, "sat", rng=0, time_limit=30)
    assert r.status == "solved" and len(city.violations(r.grid)) == 0
    assert r.stats["hint"] == "catalog solution (refuted)" and "proof" not in r.stats


def test_sat_default_without_a_hint_goes_on_from_the_attempt(city, monkeypatch):
    pytest.importorskip("pysat")
    import csplab.solvers.sat as sat

    monkeypatch.setattr(sat, "PROBE_CONFLICTS", 1)
    monkeypatch.setattr(sat, "solution_hint", lambda *a, **k: None)
    r = csplab.solve(city, "sat", rng=0, time_limit=30)
    assert r.status == "solved" and len(city.violations(r.grid)) == 0
    assert r.stats["hint"] == "uniform labels" and r.stats["choice"] == "uniform"


@pytest.mark.parametrize("backend", ["minisat22", "glucose4"])
def test_the_attempts_budget_does_not_outlive_it(city, monkeypatch, backend):
    """MiniSat's family keeps a conflict budget for later calls: after the attempt's, the
    confirmation of the hint under a time limit stopped at once (a timeout after 1 s of
    20)."""
    pytest.importorskip("pysat")
    import csplab.solvers.sat as sat

    monkeypatch.setattr(sat, "PROBE_CONFLICTS", 3)
    r = csplab.solve(city, f"sat:{backend}", rng=0, time_limit=20)
    assert r.status == "solved" and len(city.violations(r.grid)) == 0
    assert r.stats["hint"] == "catalog solution"
