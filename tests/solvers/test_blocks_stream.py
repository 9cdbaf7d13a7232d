"""Modify in blocks streamed slab by slab (:func:`csplab.solvers.blocks.stream_blocks`):
the same grid and counts as the sweep on the whole problem, for the same seed."""

import json

import numpy as np
import pytest

from csplab import from_example
from csplab.errors import InputError
from csplab.examples import load_example
from csplab.grids import GridWindows
from csplab.solvers import solve, unknown_stats
from csplab.solvers.blocks import BlocksSolver, stream_blocks, streams


@pytest.fixture
def kernels(monkeypatch):
    from csplab import _interp

    monkeypatch.setattr(_interp, "ENGINE", "kernels")


@pytest.mark.parametrize(
    "name,shape,block,kw",
    [
        ("fig3_10", (40, 30), 8, {"boundary": "auto"}),
        ("fig3_4a", (25, 17), 5, {}),
        ("castle", (21, 23, 10), (6, 5, 4), {"boundary": "auto"}),
        ("city", (26, 14, 8), (6, 6, 8), {"boundary": "auto"}),  # K = 119: two words
    ],
)
@pytest.mark.parametrize("order,choice", [("scanline", "uniform"), ("min-entropy", "weighted")])
def test_streamed_sweep_is_the_whole_sweep(kernels, name, shape, block, kw, order, choice):
    E = load_example(name)
    P = from_example(E, shape, **kw)
    W = GridWindows(E, shape, **kw)
    a = solve(P, "blocks", rng=5, block=block, order=order, choice=choice, sweeps=2, retries=3)
    b = BlocksSolver().stream(W, rng=np.random.default_rng(5), seed=5, block=block,
                              order=order, choice=choice, sweeps=2, retries=3)  # fmt: skip
    assert a.status == b.status == "solved"
    assert np.array_equal(a.grid, b.grid) and b.grid.dtype == np.int32
    for k in ("blocks_tried", "blocks_accepted", "retries", "revisions", "final_violations"):
        assert a.stats[k] == b.stats[k], k
    assert P.is_solution(b.grid) and b.stats["blocks_accepted"] > 0
    assert 1 <= b.stats["slab_problems"] <= 8  # a handful of slab problems, not one per slab
    assert not unknown_stats(b.stats)


def test_streamed_sweep_writes_into_out_and_stops_at_the_deadline(kernels):
    E = load_example("castle")
    W = GridWindows(E, (30, 12, 10), boundary="auto")
    out = np.full(W.shape, -7, dtype=np.int32)
    status, g, stats = stream_blocks(W, np.random.default_rng(1), block=6, out=out)
    assert g is out and status == "solved" and stats["final_violations"] == 0
    P = from_example(E, W.shape, boundary="auto")
    assert P.is_solution(out)
    status, g, stats = stream_blocks(W, np.random.default_rng(1), block=6, deadline=0.0)
    assert status == "timeout" and stats["blocks_tried"] == 0
    assert P.is_solution(g)  # the trivial solution, painted whole
    with pytest.raises(InputError, match="out must be"):
        stream_blocks(W, np.random.default_rng(1), out=np.zeros((3, 3), dtype=np.int32))


def test_what_cannot_be_streamed_says_why(kernels, monkeypatch):
    W = GridWindows(load_example("castle"), (20, 20, 10), boundary="auto")
    assert streams(W) is None
    assert "wave schedule" in streams(W, workers=2)
    assert "whole model" in streams(W, init=np.zeros(3))
    assert "Python sweep" in streams(W, order="random")
    # the checkerboard has no trivial solution of one label or layers (Alg. 3.1 finds one)
    board = GridWindows(load_example("checkerboard"), (12, 12))
    assert "trivial" in streams(board)
    with pytest.raises(InputError, match="cannot be streamed"):
        BlocksSolver().stream(W, rng=np.random.default_rng(0), seed=0, workers=1)
    from csplab import _interp

    monkeypatch.setattr(_interp, "ENGINE", "interp")
    assert "compiled kernels" in streams(W)


def test_cli_streams_a_large_blocks_run_with_the_same_bytes(kernels, monkeypatch, tmp_path,
                                                            capsys):  # fmt: skip
    from csplab.cli import main
    from csplab.solvers import blocks

    argv = ["synthesize", "castle", "--size", "24x18x10", "--boundary", "auto", "--solver",
            "blocks", "--block", "8", "--seed", "4", "--json"]  # fmt: skip
    outs = []
    for limit in (blocks.STREAM_BYTES, 0):  # whole, then streamed
        monkeypatch.setattr(blocks, "STREAM_BYTES", limit)
        path = tmp_path / f"m{limit}.npy"
        assert main([*argv, "--out", str(path)]) == 0
        d = json.loads(capsys.readouterr().out)
        outs.append((d, np.load(path)))
    (a, ga), (b, gb) = outs
    assert "streamed" not in a["settings"] and "streamed" in b["settings"]
    assert a["status"] == b["status"] == "solved" and np.array_equal(ga, gb)
    assert a["stats"]["revisions"] == b["stats"]["revisions"]


def test_cli_refuses_a_streamed_run_over_the_memory_limit(kernels, monkeypatch, capsys):
    from csplab.cli import main
    from csplab.solvers import blocks

    monkeypatch.setattr(blocks, "STREAM_BYTES", 0)
    monkeypatch.setattr(blocks, "stream_blocks", None)  # refused before the work
    code = main(["synthesize", "castle", "--size", "400x400x10", "--boundary", "auto",
                 "--solver", "blocks", "--memory-limit", "0.5"])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and "streamed" in err and "would need about" in err, err
