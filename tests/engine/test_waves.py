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
