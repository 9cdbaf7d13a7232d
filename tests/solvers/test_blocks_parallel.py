"""Parallel blocks: the wave schedule of ``blocks`` (``workers >= 1``, csplab.engine.waves)."""

import hashlib
import time

import numpy as np
import pytest

from csplab import load_example, solve
from csplab.deps import available
from csplab.engine import waves as wv
from csplab.errors import InputError
from csplab.grids import from_example
from csplab.solvers.blocks import (
    _arc_index,
    _arcs_touching,
    _position_grid,
    block_starts,
)


def _grid_blocks(P, m):
    idx = np.arange(P.n, dtype=np.int64).reshape(P.shape)
    starts = [block_starts(s, b) for s, b in zip(P.shape, m, strict=True)]
    import itertools

    boxes = [
        idx[tuple(slice(a, a + b) for a, b in zip(q, m, strict=True))].reshape(-1)
        for q in itertools.product(*starts)
    ]
    return boxes, tuple(len(s) for s in starts)


def _schedule(P, boxes, counts):
    indptr, ids = _arc_index(P)
    classes = wv.colour_classes(counts)
    return list(
        wv.waves(classes, boxes, P.n, len(P.arcs), lambda c: _arcs_touching(c, indptr, ids))
    )


def _continuous(side=12):
    from csplab.continuous import ContinuousCSP
    from csplab.examples.continuous import load_polygon_example

    return ContinuousCSP(load_polygon_example("triangle"), (side, side)).problem


@pytest.fixture(scope="module")
def castle():
    return from_example(load_example("castle"), (30, 30, 10), boundary="auto")


def test_same_output_for_one_and_two_workers_and_consistent(castle):
    a = solve(castle, "blocks", rng=3, block=10, workers=1)
    b = solve(castle, "blocks", rng=3, block=10, workers=2)
    assert a.status == b.status == "solved"
    assert np.array_equal(a.grid, b.grid)
    assert len(castle.violations(a.grid)) == 0
    assert a.stats["blocks_tried"] == b.stats["blocks_tried"] == 25
    assert a.stats["retries"] == b.stats["retries"]
    assert a.stats["workers"] == 1 and b.stats["workers"] == 2
    # a different seed gives another output; the same seed repeats
    c = solve(castle, "blocks", rng=4, block=10, workers=1)
    assert not np.array_equal(a.grid, c.grid)
    assert np.array_equal(a.grid, solve(castle, "blocks", rng=3, block=10, workers=1).grid)


def test_sweeps_and_odd_blocks_same_for_any_workers():
    P = from_example(load_example("fig3_10"), (23, 19), boundary="auto")
    a = solve(P, "blocks", rng=5, block=(5, 3), sweeps=2, order="random", workers=1)
    b = solve(P, "blocks", rng=5, block=(5, 3), sweeps=2, order="random", workers=2)
    assert a.status == "solved" and np.array_equal(a.grid, b.grid)
    assert len(P.violations(a.grid)) == 0


def test_workers_0_is_the_thesis_sweep_unchanged():
    # hashes of the sequential sweep before the wave schedule was added
    P = from_example(load_example("fig3_10"), (60, 60), boundary="auto")
    r = solve(P, "blocks", rng=3, block=10)
    assert hashlib.sha256(r.grid.tobytes()).hexdigest()[:16] == "b48226d91d3db9bc"
    assert np.array_equal(r.grid, solve(P, "blocks", rng=3, block=10, workers=0).grid)
    P = from_example(load_example("castle"), (40, 40, 10), boundary="auto")
    r = solve(P, "blocks", rng=2, block=10)
    assert hashlib.sha256(r.grid.tobytes()).hexdigest()[:16] == "f75bcf136c49c03a"
    assert r.stats["retries"] == 29


@pytest.mark.parametrize(
    "name, shape, m, boundary",
    [
        ("castle", (40, 40, 10), (10, 10, 10), "auto"),
        ("fig3_10", (40, 40), (10, 10), "auto"),
        ("fig3_10", (12, 17), (5, 3), "auto"),  # odd sizes, flush last blocks
        ("fig3_10", (12, 12), (3, 3), "periodic"),  # blocks of 3; wrap-around arcs
        ("fig3_10", (16, 16), (4, 4), "periodic"),  # block 0 and the last touch by the wrap
    ],
)
def test_every_wave_is_independent(name, shape, m, boundary):
    if boundary == "periodic":
        P = from_example(load_example(name), shape, periodic=True)
    else:
        P = from_example(load_example(name), shape, boundary=boundary)
    boxes, counts = _grid_blocks(P, m)
    schedule = _schedule(P, boxes, counts)
    # by neighbourhoods (the compiled blocks' test): the same waves
    from csplab.catalog import neighbourhood

    near = list(wv.waves(wv.colour_classes(counts), boxes, P.n, len(P.arcs), None,
                         lambda c: neighbourhood(P, c)))  # fmt: skip
    assert [[b.block for b in w] for w in near] == [[b.block for b in w] for w in schedule]
    seen = [b.block for w in schedule for b in w]
    assert sorted(seen) == list(range(len(boxes)))  # every block exactly once per sweep
    for w in schedule:
        assert wv.independent(P.arcs, P.n, [b.cells for b in w])
    if (
        m[0] % 2 == 0
        and boundary != "periodic"
        and all(s % (b // 2) == 0 for s, b in zip(shape, m, strict=True))
    ):
        # regular lattice: the colours modulo 3 alone are independent (3 ** d waves at most)
        assert len(schedule) == len(wv.colour_classes(counts))
        for cls in wv.colour_classes(counts):
            assert wv.independent(P.arcs, P.n, [boxes[i] for i in cls])


def test_colours_modulo_3_need_splitting_when_blocks_touch():
    # blocks of 3 cells step 1: blocks 0 and 3 are adjacent, so the class must split
    P = from_example(load_example("fig3_10"), (9, 9), boundary="auto")
    boxes, counts = _grid_blocks(P, (3, 3))
    cls0 = [boxes[i] for i in wv.colour_classes(counts)[0]]
    assert not wv.independent(P.arcs, P.n, cls0)
    schedule = _schedule(P, boxes, counts)
    assert len(schedule) > len(wv.colour_classes(counts))
    assert all(wv.independent(P.arcs, P.n, [b.cells for b in w]) for w in schedule)


def test_position_boxes_waves_are_independent_and_solve():
    P = _continuous()
    for block in (2, 3, 4):
        boxes, counts = _position_grid(P, block)
        assert len(boxes) == int(np.prod(counts))
        schedule = _schedule(P, boxes, counts)
        assert sorted(b.block for w in schedule for b in w) == [
            i for i, c in enumerate(boxes) if c.size
        ]
        for w in schedule:
            assert wv.independent(P.arcs, P.n, [b.cells for b in w])
    a = solve(P, "blocks", rng=0, block=3, workers=1)
    b = solve(P, "blocks", rng=0, block=3, workers=2)
    assert a.status == "solved" and np.array_equal(a.grid, b.grid)
    assert len(P.violations(a.grid)) == 0


def test_option_errors_are_one_line(castle):
    bad = [
        ({"workers": -1}, "workers must be at least 0"),
        ({"workers": "two"}, "workers must be a number"),
        ({"workers": 1.5}, "workers must be a whole number"),
        ({"scheduler": ""}, "scheduler must be 'local' or a Dask scheduler address"),
        ({"scheduler": "nowhere"}, "scheduler must be 'local' or an address"),
        ({"scheduler": 3}, "scheduler must be 'local'"),
        ({"scheduler": "local"}, "scheduler needs workers >= 1"),
    ]
    for opts, msg in bad:
        with pytest.raises(InputError, match=msg) as e:
            solve(castle, "blocks", rng=0, **opts)
        assert "\n" not in str(e.value)


def test_time_limit_holds_across_waves():
    P = from_example(load_example("castle"), (60, 60, 10), boundary="auto")
    for workers in (1, 2):
        t = time.perf_counter()
        r = solve(P, "blocks", rng=0, block=10, workers=workers, time_limit=0.05)
        assert time.perf_counter() - t < 5
        assert r.status in ("timeout", "solved")
        assert len(P.violations(r.grid)) == 0  # the grid stays consistent


def test_worker_exception_reaches_the_caller(monkeypatch):
    def boom(*a, **k):
        raise RuntimeError("boom in a worker")

    monkeypatch.setattr(wv, "solve_block", boom)  # the Python path
    monkeypatch.setattr(wv, "solve_compiled", boom)  # the compiled one
    P = from_example(load_example("fig3_10"), (20, 20), boundary="auto")
    with pytest.raises(RuntimeError, match="boom"):
        solve(P, "blocks", rng=0, block=10, workers=2)


@pytest.mark.parametrize("order", ["scanline", "min-entropy"])
def test_compiled_blocks_same_as_python_blocks_in_waves(monkeypatch, order):
    """The wave schedule with one kernel call per block (:func:`wv.solve_compiled`, the
    block's arrays built by a kernel) gives the grids and counts of the Python path."""
    from csplab import _interp

    for name, shape, kw in [("castle", (24, 24, 10), {}), ("loops", (24, 24), {"periodic": True})]:
        for workers in (1, 2):
            out = []
            for engine in ("interp", "kernels"):
                monkeypatch.setattr(_interp, "ENGINE", engine)
                P = from_example(load_example(name), shape, **kw)
                out.append(solve(P, "blocks", rng=4, block=8, order=order, choice="weighted",
                                 workers=workers, sweeps=2))  # fmt: skip
            a, b = out
            assert a.status == b.status == "solved" and np.array_equal(a.grid, b.grid)
            for k in ("blocks_tried", "blocks_accepted", "retries", "revisions"):
                assert a.stats[k] == b.stats[k], (name, workers, k)


@pytest.mark.slow
@pytest.mark.skipif(not available("distributed"), reason="distributed not installed")
def test_dask_local_cluster_same_output(castle):
    a = solve(castle, "blocks", rng=3, block=10, workers=1)
    b = solve(castle, "blocks", rng=3, block=10, workers=2, scheduler="local")
    assert b.status == "solved" and np.array_equal(a.grid, b.grid)
    assert b.stats["scheduler"] == "local"


def test_dask_missing_is_one_line(monkeypatch, castle):
    import sys

    monkeypatch.setitem(sys.modules, "distributed", None)
    from csplab.errors import DependencyError

    with pytest.raises(DependencyError, match=r"csplab\[dask\]"):
        solve(castle, "blocks", rng=0, workers=2, scheduler="local")
