"""The sweep's summary line reads as a sentence."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from csplab.experiments import run
from csplab.experiments.runner import RunSummary


def test_summary_line_is_a_sentence(tmp_path: Path) -> None:
    kw: dict[str, Any] = {"store": tmp_path / "r.sqlite", "out": tmp_path / "out", "jobs": 1,
                          "progress": False, "figures": False}  # fmt: skip
    s, _ = run("fig3_8", quick=True, examples=["line"], seeds=3, **kw)
    assert s.line().startswith(f"fig3_8: {s.total} trials, 0 already stored, {s.total} run (")
    assert "(none)" not in s.line()
    again, _ = run("fig3_8", quick=True, examples=["line"], seeds=3, **kw)
    assert again.line() == f"fig3_8: {s.total} trials, all {s.total} already stored; nothing to run"
    assert RunSummary("x", 0, 0).line() == "x: no trials; nothing to run"
    assert RunSummary("x", 1, 1).line() == "x: 1 trial, 1 already stored; nothing to run"
    only = RunSummary("x", 4, 3, executor="nothing (report only)")
    assert only.line() == "x: 4 trials, 3 already stored; report only, nothing run"
