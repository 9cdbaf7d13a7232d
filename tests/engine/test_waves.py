"""A block task of modify in blocks (csplab.engine.waves) on a subproblem that Alg. 3.1
always fails: three cells that must all differ, with two labels (arc consistency prunes
nothing until the first choice, after which a domain empties). Its outcome counts every
retry and hands back no labels."""

from __future__ import annotations

import numpy as np

from csplab import Problem
from csplab.engine import waves as wv

NE = np.array([[[False, True], [True, False]]])  # one relation: the labels differ
TRIANGLE = Problem((3,), np.ones((3, 2), dtype=bool), NE, [[0, 1, 0], [1, 2, 0], [0, 2, 0]])


def _block(retries: int) -> wv.BlockOutcome:
    return wv.solve_block(TRIANGLE, np.random.default_rng(0), 7, retries=retries,
                          order="scanline", choice="uniform", deadline=None)  # fmt: skip


def test_a_block_that_always_fails_counts_each_retry() -> None:
    one = _block(0)
    assert one.block == 7 and one.labels is None and one.status == "failed"
    assert one.retries == 0 and one.revisions > 0
    for k in (1, 3):
        o = _block(k)
        assert o.labels is None and o.status == "failed"
        assert o.retries == k  # every retry spent, none more
        assert o.revisions == (k + 1) * one.revisions  # each attempt did the same work


def test_a_block_started_after_its_deadline_times_out_without_labels() -> None:
    """The time left for an attempt is the deadline minus now, never less than 0: a block
    whose deadline has passed stops after its first chunk of steps ("timeout", no labels,
    no retry), although the whole block would take milliseconds. (Mutants that give each
    attempt a second of its own, or no limit, solve it.)"""
    from csplab import ExampleModel, from_example
    from csplab.engine.alg31 import _CHUNK

    # a forced checkerboard, large enough to run compiled (milliseconds, once loaded)
    sub = from_example(ExampleModel([[0, 1], [1, 0]]), (160, 160))
    assert sub.n > _CHUNK  # more than one chunk: the deadline is looked at once at least
    done = wv.solve_block(sub, np.random.default_rng(0), 3, retries=2, order="scanline",
                          choice="uniform", deadline=None)  # fmt: skip
    assert done.status == "solved" and done.labels is not None  # the block itself is easy
    past = wv.time.perf_counter() - 1.0
    o = wv.solve_block(sub, np.random.default_rng(0), 3, retries=2, order="scanline",
                       choice="uniform", deadline=past)  # fmt: skip
    assert (o.status, o.labels, o.retries) == ("timeout", None, 0)
