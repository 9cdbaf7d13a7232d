"""Failure witnesses of Alg. 3.1 (csplab.analysis.witness): thesis rows I4, I7 and soundness."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from csplab import solve
from csplab.analysis import alg31_exhaustive, find_failure, replay
from csplab.catalog import Propagator
from csplab.engine.completability import SearchCompletability, first_inconsistent_prefix
from csplab.errors import InputError
from csplab.examples import load_example
from csplab.grids import from_example, with_fixed
from csplab.testing.brute import exact_catalog, satisfiable
from csplab.testing.strategies import analysis_examples

FIG = "scan:yx"


def prefix_grid(shape, choices, t):
    g = np.full(shape, -1)
    for c, b in choices[:t]:
        g[tuple(c)] = b
    return g


def test_fig3_5a_witness_like_fig3_5efg():  # I4
    E = load_example("fig3_5a")
    v = find_failure(E, order=FIG, max_size=(3, 3))
    assert v.holds is False
    w = v.witness
    assert replay(E, w).holds
    # the last label was outside C* but inside C, and C emptied at once (Fig. 3.5(e-g))
    assert w["first_outside_cstar"] == w["fail_step"] and w["detection_delay"] == 0
    P = from_example(E, tuple(w["shape"]))
    t = w["fail_step"] - 1
    partial = prefix_grid(P.shape, w["choices"], t)
    eng = Propagator(with_fixed(P, partial))
    cell = P.cell(tuple(w["choices"][t][0]))
    C = set(eng.domain(cell).tolist())
    Cs = set(np.flatnonzero(exact_catalog(P, partial)[cell]).tolist())
    assert Cs < C and w["choices"][t][1] in C - Cs


def test_fig3_5a_scanline_has_no_small_failure():
    # csplab's scanline order decides the 3 or 7 above a 2 first: no failure up to 4x4
    v = find_failure(load_example("fig3_5a"), order="scanline", max_size=(4, 4), random_runs=0)
    assert v.holds is True and v.stats["states"] > 1000


def test_fig3_5a_random_order_witness_has_a_seed():
    E = load_example("fig3_5a")
    v = find_failure(E, order="random", max_size=(6, 3), random_runs=100, rng=3)
    assert v.holds is False
    assert "seed" in v.witness and replay(E, v.witness).holds
    r = solve(from_example(E, tuple(v.witness["shape"])), "catalog",
              rng=v.witness["seed"], order="random")  # fmt: skip
    assert r.status == "failed"


def test_fig3_6a_late_detection():  # I7
    E = load_example("fig3_6a")
    P = from_example(E, (9, 3))
    v = alg31_exhaustive(P, FIG, late=True)
    assert v.holds is False
    w = {"shape": [9, 3], "order": FIG, "choices": v.witness}
    assert replay(E, w).holds
    t = v.stats["first_outside_cstar"]
    assert t < len(v.witness)  # C not yet empty when the model became inconsistent
    assert satisfiable(P, prefix_grid(P.shape, v.witness, t - 1)) is True
    assert satisfiable(P, prefix_grid(P.shape, v.witness, t)) is False
    eng = Propagator(with_fixed(P, prefix_grid(P.shape, v.witness, t)))
    assert eng.ok
    choices = [[P.cell(tuple(c)), b] for c, b in v.witness]
    # 0-based index of the bad choice; the witness counts choices from 1
    assert first_inconsistent_prefix(SearchCompletability(P), choices) == t - 1
    # the bottom row holds three 2s that cannot be paired (Fig. 3.6(b))
    row = [b for c, b in v.witness if c[1] == 0]
    assert row.count(2) % 2 == 1


def test_fig3_6a_is_fallible_in_figure_order():
    v = find_failure(load_example("fig3_6a"), order=FIG, max_size=(5, 3), random_runs=0)
    assert v.holds is False and replay(load_example("fig3_6a"), v.witness).holds


def test_bad_orders():
    with pytest.raises(InputError):
        alg31_exhaustive(from_example(load_example("line"), (2, 2)), "random")
    with pytest.raises(InputError):
        find_failure(load_example("line"), order="diagonal")


def test_replay_rejects_a_non_failing_run():
    E = load_example("line")
    w = {"shape": [2, 2], "order": FIG, "choices": [[[0, 0], 0], [[1, 0], 0]]}
    assert replay(E, w).holds is False
    w2 = {"shape": [2, 2], "order": FIG, "choices": [[[1, 0], 0]]}
    assert "out of order" in replay(E, w2).message


# ----------------------------------------------------------------------------- soundness


@settings(max_examples=40)
@given(analysis_examples(max_side=3, max_labels=4), st.sampled_from([FIG, "scanline"]))
def test_find_failure_witnesses_replay_and_bounds_hold(E, order):
    v = find_failure(E, order=order, max_size=(3, 3), random_runs=0, max_states=20_000)
    if v.holds is False:
        assert replay(E, v.witness).holds
        t = v.witness.get("first_outside_cstar")
        if t is not None:
            P = from_example(E, tuple(v.witness["shape"]))
            ch = v.witness["choices"]
            assert satisfiable(P, prefix_grid(P.shape, ch, t - 1)) is True
            assert satisfiable(P, prefix_grid(P.shape, ch, t)) is False
    elif v.holds is True:
        for shape in [(2, 2), (3, 2), (2, 3), (3, 3)]:
            P = from_example(E, shape)
            for seed in range(5):
                assert solve(P, "catalog", rng=seed, order=order).status == "solved"


# ------------------------------------------------------- 3D: escalate, shrink, time budget


def test_3d_witness_with_defaults_in_a_few_seconds():
    E = load_example("castle")  # fails often with boundary auto at 12x12x8
    v = find_failure(E, boundary="auto", time_limit=5, rng=1)
    assert v.holds is False and v.stats["time_s"] < 5 + 2
    w = v.witness
    assert replay(E, w).holds and w["boundary"] == "auto" and w["kind"] == "failed"
    st = v.stats
    assert st["random_runs"] > 0 and sum(st["runs_per_size"].values()) == st["random_runs"]
    assert int(np.prod(w["shape"])) <= int(np.prod(st["found_on"]))  # shrunk (or kept)
    t = w["first_outside_cstar"]
    assert t is not None and w["detection_delay"] == w["fail_step"] - t
    P = from_example(E, tuple(w["shape"]), boundary="auto")
    ch = w["choices"]
    assert satisfiable(P, prefix_grid(P.shape, ch, t - 1)) is True
    assert satisfiable(P, prefix_grid(P.shape, ch, t)) is False


def test_3d_shrinks_a_large_failure():
    E = load_example("castle")
    # no exhaustive phase (no catalogs allowed): the failure comes from a random run
    v = find_failure(E, boundary="auto", time_limit=10, rng=0, max_states=0)
    assert v.holds is False and v.stats["exhaustive_sizes"] == 0
    assert int(np.prod(v.witness["shape"])) < int(np.prod(v.stats["found_on"]))
    assert v.stats["shrink_runs"] > 0 and "shrunk" in v.witness["search"]
    assert replay(E, v.witness).holds
    # the boundary matters: without it the witness does not replay as a failure
    assert not replay(E, {**v.witness, "boundary": None}).holds


def test_time_limit_is_kept_on_an_infallible_3d_model():
    E = load_example("pillar")
    v = find_failure(E, time_limit=2)
    assert v.holds is None and "not a proof" in v.message
    assert v.stats["time_s"] < 2 + 1.5 and v.stats["random_runs"] > 0


def test_random_order_3d_witness_replays_by_seed():
    E = load_example("castle")
    for order in ("random", "min-entropy"):
        v = find_failure(E, boundary="auto", order=order, time_limit=5, rng=2)
        assert v.holds is False and v.stats["exhaustive_sizes"] == 0  # no exhaustive phase
        assert "seed" in v.witness and replay(E, v.witness).holds
        bad = {**v.witness, "seed": v.witness["seed"] + 1}
        assert not replay(E, bad).holds


@pytest.mark.parametrize("bad", [0, -1.0, float("nan"), float("inf")])
def test_bad_time_limit(bad):
    with pytest.raises(InputError, match="time_limit"):
        find_failure(load_example("line"), time_limit=bad)


def _merrell_3d_models():
    from pathlib import Path

    root = Path(__file__).resolve().parents[3] / "shared" / "anchors-data"
    return sorted(p for p in root.glob("**/*.txt") if "errell" in str(p)) if root.is_dir() else []


@pytest.mark.parametrize("path", _merrell_3d_models() or [None])
def test_merrell_3d_model_witness(path):
    if path is None:
        pytest.skip("no Merrell 3D model in ../shared/anchors-data")
    from csplab.io import read_model

    E = read_model(path)
    if E.ndim < 3:
        pytest.skip(f"{path.name} is not 3D")
    v = find_failure(E, time_limit=10)
    if v.holds is False:
        assert replay(E, v.witness).holds


@pytest.mark.parametrize("seed", [0, 1])
def test_3d_window_shrink_finds_failures_seeds_miss(seed):
    # castle without a boundary fails in ~2% of runs at 10x10x8 and above; windows of the
    # failing run, anchored at its failing cell, shrink it to a few dozen cells
    E = load_example("castle")
    v = find_failure(E, time_limit=10, rng=seed, max_states=0)
    assert v.holds is False and replay(E, v.witness).holds
    assert int(np.prod(v.stats["found_on"])) >= 800 and int(np.prod(v.witness["shape"])) <= 60
    P = from_example(E, tuple(v.witness["shape"]))
    fails = sum(solve(P, "catalog", rng=s).status != "solved" for s in range(200))
    assert fails < 20  # a window, not a size where random runs fail anyway
