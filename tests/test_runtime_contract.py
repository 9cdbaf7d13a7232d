"""Runtime cases of the error contract (issue 12, item 8): memory estimated before
allocating, a late MemoryError as one line."""

from __future__ import annotations

import time
from typing import Any

import numpy as np
import pytest

from csplab import limits
from csplab.catalog import Propagator
from csplab.errors import CsplabError, MemoryLimitError
from csplab.example import ExampleModel
from csplab.grids import from_example
from csplab.limits import check_memory
from csplab.problem import memory_estimate


def test_estimate_grows_with_cells_and_labels() -> None:
    small = memory_estimate(100, 2, 200)
    assert memory_estimate(1000, 2, 2000) > small
    assert memory_estimate(100, 200, 200) > small
    assert memory_estimate(100, 2, 200, propagator=False) < small
    assert memory_estimate(100, 2, 200, problem=False) < small


def test_too_large_output_is_one_line_before_allocating(monkeypatch: Any) -> None:
    monkeypatch.setattr(limits, "available_memory", lambda: int(6.1e9))
    E = ExampleModel(np.arange(119 * 2).reshape(119, 2, 1) % 119)
    t = time.perf_counter()
    with pytest.raises(MemoryLimitError) as exc:
        from_example(E, (2000, 2000, 10))
    assert time.perf_counter() - t < 2.0
    msg = str(exc.value)
    assert msg == (  # the one memory refusal (csplab.limits.check_memory); no
        # --memory-limit hint: the library's guard is the memory there is
        "2000x2000x10 with K=119 would need about 38.6 GB, over the memory available of "
        "6.1 GB: a smaller --size, or fewer labels"
    )
    assert isinstance(exc.value, MemoryError) and isinstance(exc.value, CsplabError)


def test_small_problems_do_not_read_meminfo(monkeypatch: Any) -> None:
    def boom() -> int:
        raise AssertionError("read /proc/meminfo for a tiny problem")

    monkeypatch.setattr(limits, "available_memory", boom)
    check_memory(memory_estimate(100, 3, 200), "10x10", "a smaller --size", available=True)
    from_example(ExampleModel([[0, 1], [1, 0]]), (40, 40))


def test_propagator_checks_what_it_adds(monkeypatch: Any) -> None:
    E = ExampleModel([[0, 1], [1, 0]])
    P = from_example(E, (3000, 3000))  # 9e6 cells: above the small threshold
    monkeypatch.setattr(limits, "available_memory", lambda: 2**20)
    with pytest.raises(MemoryLimitError, match=r"^3000x3000 with K=2 would need about"):
        Propagator(P)


def test_available_memory_reads_meminfo_or_falls_back(monkeypatch: Any) -> None:
    assert limits.available_memory() > 0
    import builtins

    real_open = builtins.open

    def no_proc(path: Any, *a: Any, **k: Any) -> Any:
        if str(path) == "/proc/meminfo":
            raise OSError("no /proc")
        return real_open(path, *a, **k)

    monkeypatch.setattr(builtins, "open", no_proc)
    assert limits.available_memory() == limits.FALLBACK_MEMORY


def test_cli_memory_estimate_exit_2(monkeypatch: Any, capsys: Any) -> None:
    from csplab.cli import main

    monkeypatch.setattr(limits, "available_memory", lambda: 2**30)
    assert main(["synthesize", "city", "--size", "2000x2000x10"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    # the CLI's estimate (csplab.limits: the budget is at most the memory available) comes
    # first, before the problem is built
    assert err[0].startswith("csplab: error: city --size 2000x2000x10 (K=119) would need about ")
    assert err[0].endswith("budget of 1.1 GB: use a smaller --size, or raise --memory-limit")


def test_cli_late_memory_error_is_one_line(monkeypatch: Any, capsys: Any) -> None:
    from csplab import cli

    def run(args: Any) -> int:
        raise MemoryError

    parser = cli.build_parser()
    real_parse = parser.parse_args

    def parse(argv: Any = None) -> Any:
        ns = real_parse(argv)
        ns._run = run
        return ns

    monkeypatch.setattr(parser, "parse_args", parse)
    monkeypatch.setattr(cli, "build_parser", lambda only=None: parser)
    assert cli.main(["synthesize", "line", "--size", "4x4"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["csplab: error: out of memory (try a smaller --size)"]
