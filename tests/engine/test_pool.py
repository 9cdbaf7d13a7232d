"""csplab.engine.pool.Workers: the one process pool / Dask runner of csplab."""

from __future__ import annotations

import importlib.util
import time

import pytest

from csplab.engine.pool import Workers
from csplab.errors import InputError


def test_local_workers_give_results_in_submission_order_and_close_twice():
    w = Workers.local(2)
    try:
        futures = [w.submit(pow, 2, k) for k in range(6)]
        done = w.wait(futures)
        assert done == futures and [f.result() for f in done] == [2**k for k in range(6)]
        first = w.wait([w.submit(pow, 3, 2)], first=True)
        assert [f.result() for f in first] == [9]
    finally:
        w.close()
    w.close()  # closing again does nothing


def test_a_task_error_comes_back_with_its_future():
    w = Workers.local(1)
    try:
        (f,) = w.wait([w.submit(int, "x")])
        assert isinstance(f.exception(), ValueError)
    finally:
        w.close()


def test_kill_stops_running_tasks_now():
    w = Workers.local(1)
    f = w.submit(time.sleep, 60)
    assert w.wait([f], timeout=0.5) == []
    procs = list(w.pool._processes.values())  # type: ignore[union-attr]
    t0 = time.perf_counter()
    w.cancel([f])
    w.close(kill=True)
    assert time.perf_counter() - t0 < 10
    assert all(not p.is_alive() for p in procs)


@pytest.mark.skipif(importlib.util.find_spec("distributed") is None, reason="needs distributed")
def test_a_bad_scheduler_is_one_line():
    with pytest.raises(InputError, match="scheduler must be an address"):
        Workers.dask(12, purpose="a test")
