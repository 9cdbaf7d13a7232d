"""Interrupts of a sweep: Ctrl-C inside the SAT oracle, SIGTERM and SIGKILL of the main
process (issue 12, item 8)."""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import textwrap
import time
from pathlib import Path
from typing import Any

import pytest

from csplab.engine import sat
from csplab.examples import load_example
from csplab.experiments.runner import run_trials
from csplab.experiments.store import ResultsStore
from csplab.experiments.trial import Trial

pytest.importorskip("pysat")


class _PysolversError(Exception):
    """Stands in for ``pysolvers.error``."""


def _trials(n: int, solver: str = "sat", size: tuple[int, int] = (6, 6)) -> tuple[list[Trial], Any]:
    E = load_example("line")
    return [Trial("demo", "line", E.hash(), size, solver, {}, seed=s) for s in range(n)], E


def test_pysat_keyboard_interrupt_becomes_keyboard_interrupt(monkeypatch: Any) -> None:
    from csplab.grids import from_example
    from csplab.solvers import solve

    def raw(self: Any, *a: Any) -> bool:
        raise _PysolversError("Caught keyboard interrupt")

    monkeypatch.setattr(sat.SatOracle, "_raw", raw)
    with pytest.raises(KeyboardInterrupt):
        solve(from_example(load_example("line"), (5, 5)), "sat", rng=0)


def test_other_solver_errors_are_not_interrupts(monkeypatch: Any) -> None:
    from csplab.grids import from_example
    from csplab.solvers import solve

    def raw(self: Any, *a: Any) -> bool:
        raise _PysolversError("something else")

    monkeypatch.setattr(sat.SatOracle, "_raw", raw)
    with pytest.raises(_PysolversError):
        solve(from_example(load_example("line"), (5, 5)), "sat", rng=0)


def test_ctrl_c_stops_a_one_process_sweep(monkeypatch: Any, tmp_path: Path) -> None:
    trials, E = _trials(6)
    calls = {"n": 0}
    real = sat.SatOracle._raw

    def raw(self: Any, *a: Any) -> Any:
        calls["n"] += 1
        if calls["n"] > 2:  # the first trials finish, then Ctrl-C
            raise _PysolversError("Caught keyboard interrupt")
        return real(self, *a)

    monkeypatch.setattr(sat.SatOracle, "_raw", raw)
    path = tmp_path / "r.sqlite"
    with ResultsStore(path) as st, pytest.raises(KeyboardInterrupt):
        run_trials(trials, {E.hash(): E}, st, experiment="demo", jobs=1, progress=False)
    with ResultsStore(path) as st:
        stored = st.done_keys("demo")
    assert 0 < len(stored) < len(trials)  # stopped, and what was stored stays
    db = sqlite3.connect(path)
    assert db.execute("SELECT status, finished_at IS NOT NULL FROM runs").fetchall() == [
        ("interrupted", 1)
    ]
    db.close()
    monkeypatch.setattr(sat.SatOracle, "_raw", real)
    with ResultsStore(path) as st:
        s = run_trials(trials, {E.hash(): E}, st, experiment="demo", jobs=1, progress=False)
        assert (s.skipped, s.ran) == (len(stored), len(trials) - len(stored))
        assert len(st.rows("demo")) == len(trials)


@pytest.mark.parametrize("solver", ["sat", "perfect"])
def test_cli_ctrl_c_in_sat_exits_130(monkeypatch: Any, capsys: Any, solver: str) -> None:
    from csplab.cli import main

    def raw(self: Any, *a: Any) -> bool:
        raise _PysolversError("Caught keyboard interrupt")

    monkeypatch.setattr(sat.SatOracle, "_raw", raw)
    code = main(["synthesize", "line", "--size", "5x5", "--solver", solver, "--seed", "0"])
    assert code == 130
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["csplab: interrupted"]


def test_cli_one_process_sweep_stops_on_ctrl_c(
    monkeypatch: Any, capsys: Any, tmp_path: Path
) -> None:
    from csplab.cli import main
    from csplab.experiments.trial import execute as real

    calls = {"n": 0}

    def execute(t: Trial, example: Any) -> Any:
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        return real(t, example)

    monkeypatch.setattr("csplab.experiments.runner.execute", execute)
    store = tmp_path / "r.sqlite"
    argv = ["experiment", "fig3_8", "--quick", "--jobs", "1", "--store", str(store)]
    code = main([*argv, "--out", str(tmp_path / "out")])
    assert code == 130
    assert capsys.readouterr().err.strip().splitlines()[-1] == "csplab: interrupted"
    assert calls["n"] == 3  # the sweep stopped
    with ResultsStore(store) as st:
        assert len(st.done_keys("fig3_8")) == 2  # the rows stored before stay
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


_SLOW = textwrap.dedent(
    """
    import time
    from csplab.experiments import trial


    def execute(t, example):
        if t.seed >= 2:  # a trial that runs long: its worker is busy when the main dies
            time.sleep(120)
        return trial.execute(t, example)
    """
)

_SCRIPT = textwrap.dedent(
    """
    import sys
    import slowtrial
    from csplab.examples import load_example
    from csplab.experiments import runner
    from csplab.experiments.store import ResultsStore
    from csplab.experiments.trial import Trial

    if __name__ == "__main__":
        runner.execute = slowtrial.execute
        E = load_example("line")
        trials = [Trial("demo", "line", E.hash(), (8, 8), "catalog", {}, seed=s)
                  for s in range(N)]
        with ResultsStore(sys.argv[1]) as st:
            try:
                runner.run_trials(trials, {E.hash(): E}, st, experiment="demo", jobs=2,
                                  progress=False)
            except KeyboardInterrupt:
                print("csplab: interrupted", file=sys.stderr)
                sys.exit(130)
    """
)


def _children(pid: int) -> set[int]:
    out: set[int] = set()
    for task in Path(f"/proc/{pid}/task").iterdir():
        try:
            out |= {int(c) for c in (task / "children").read_text().split()}
        except OSError:
            pass
    return out


def _stored(store: Path) -> int:
    try:
        db = sqlite3.connect(store, timeout=0.1)
        try:
            return int(db.execute("SELECT count(*) FROM trials").fetchone()[0])
        finally:
            db.close()
    except sqlite3.Error:
        return 0


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"  # a zombie has exited


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs /proc")
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL])
def test_killed_sweep_leaves_no_workers_and_resumes(tmp_path: Path, sig: int) -> None:
    n = 8
    store = tmp_path / "r.sqlite"
    script = tmp_path / "sweep.py"
    script.write_text(_SCRIPT.replace("range(N)", f"range({n})"))
    (tmp_path / "slowtrial.py").write_text(_SLOW)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), *sys.path])}
    log = tmp_path / "stderr.txt"
    with log.open("w") as fh:
        proc = subprocess.Popen([sys.executable, str(script), str(store)], stderr=fh, env=env)
    try:
        workers: set[int] = set()
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and proc.poll() is None:
            workers = {c for c in _children(proc.pid) if _alive(c)}
            if len(workers) >= 2 and _stored(store) >= 2:
                break
            time.sleep(0.05)
        assert proc.poll() is None and workers, "the sweep ended before the workers started"
        time.sleep(0.5)
        workers |= _children(proc.pid)
        os.kill(proc.pid, sig)
        code = proc.wait(timeout=30)
        err = log.read_text()
        if sig == signal.SIGTERM:
            assert code == 130, err
            assert err.strip().splitlines()[-1:] == ["csplab: interrupted"], err
        else:
            assert code == -signal.SIGKILL
        end = time.monotonic() + 10
        while time.monotonic() < end and any(_alive(w) for w in workers):
            time.sleep(0.1)
        assert not [w for w in workers if _alive(w)], "orphaned workers survive"
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    db = sqlite3.connect(store)
    runs = db.execute("SELECT status, finished_at FROM runs").fetchall()
    db.close()
    if sig == signal.SIGTERM:
        assert [r[0] for r in runs] == ["interrupted"] and runs[0][1] is not None
    else:  # nobody could record the end: the next sweep marks it
        assert runs == [(None, None)]
    E = load_example("line")
    trials = [Trial("demo", "line", E.hash(), (8, 8), "catalog", {}, seed=s) for s in range(n)]
    with ResultsStore(store) as st:
        before = len(st.done_keys("demo"))
        assert before == 2  # the trials finished before the kill stay
        s = run_trials(trials, {E.hash(): E}, st, experiment="demo", jobs=1, progress=False)
        assert (s.skipped, s.ran, s.errors) == (before, n - before, [])
        keys = [r["trial_key"] for r in st.rows("demo")]
    assert sorted(keys) == sorted(t.key for t in trials)  # every trial exactly once
    db = sqlite3.connect(store)
    runs = db.execute("SELECT status FROM runs ORDER BY id").fetchall()
    db.close()
    assert runs == [("interrupted",), ("finished",)]


def test_mark_abandoned_only_marks_dead_runs(tmp_path: Path) -> None:
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    with ResultsStore(tmp_path / "r.sqlite") as st:
        live = st.start_run("demo", {}, "c", trials=1, skipped=0)
        gone = st.start_run("demo", {}, "c", trials=1, skipped=0)
        other = st.start_run("other", {}, "c", trials=1, skipped=0)
        db = sqlite3.connect(tmp_path / "r.sqlite")
        db.execute("UPDATE runs SET pid = ? WHERE id IN (?, ?)", (dead.pid, gone, other))
        db.commit()
        db.close()
        assert st.mark_abandoned("demo") == 1
        assert st.mark_abandoned("demo") == 0
    db = sqlite3.connect(tmp_path / "r.sqlite")
    got = dict(db.execute("SELECT id, status FROM runs").fetchall())
    db.close()
    assert got == {live: None, gone: "interrupted", other: None}
