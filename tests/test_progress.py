"""Progress bars on long runs: shown on stderr after a delay, never by default in the library."""

import csplab.progress as progress
from csplab import load_example, solve
from csplab.count import count_solutions
from csplab.grids import from_example


def test_bars_appear_on_stderr_when_enabled(monkeypatch, capsys):
    monkeypatch.setattr(progress, "DELAY_S", 0.0)
    P = from_example(load_example("line"), (3, 12))
    assert int(count_solutions(P, "transfer", progress=True)) > 0
    assert "transfer matrix" in capsys.readouterr().err
    Q = from_example(load_example("line"), (5, 4))
    assert solve(Q, "perfect", rng=1, progress=True).status == "solved"
    assert "perfect" in capsys.readouterr().err


def test_library_calls_are_silent_by_default(monkeypatch, capsys):
    monkeypatch.setattr(progress, "DELAY_S", 0.0)
    P = from_example(load_example("line"), (3, 12))
    count_solutions(P, "transfer")
    solve(from_example(load_example("line"), (5, 4)), "perfect", rng=1)
    assert capsys.readouterr().err == ""
