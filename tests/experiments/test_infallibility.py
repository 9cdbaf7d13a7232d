"""``csplab experiment infallibility`` (issue 26): the table, its targets, and a planted
wrong verdict that the cross-checks catch."""

from __future__ import annotations

from csplab.experiments import ResultsStore, run
from csplab.result import Verdict


def test_quick_table_and_targets(tmp_path):
    s, rep = run("infallibility", quick=True, store=tmp_path / "r.sqlite", out=tmp_path,
                 jobs=1, progress=False)  # fmt: skip
    assert not s.errors
    rows = rep.tables["verdicts"]
    assert {r["verdict"] for r in rows} == {"proved"}
    assert all("0 failed" in r["cross-check"] for r in rows)
    text = (tmp_path / "infallibility.md").read_text()
    assert "Target 0 contradictions between verdicts and runs: 0: meets" in text
    assert "| fig3_4a |" in text and "region 3x2 history 0 (Alg. 3.6)" in text


def test_a_wrong_proof_is_reported_as_a_contradiction(tmp_path, monkeypatch):
    import csplab.analysis.decide as decide

    def planted(example, **kw):  # claims every model infallible
        return Verdict(True, {}, {"method": "planted", "attempts": []}, "planted")

    monkeypatch.setattr(decide, "decide_infallibility", planted)
    run("infallibility", quick=True, store=tmp_path / "r.sqlite", out=tmp_path,
        jobs=1, progress=False, examples=["fig3_5a"], boundary="none", runs=400,
        runs_limit=30.0)  # fmt: skip
    with ResultsStore(tmp_path / "r.sqlite") as st:
        rows = st.rows("infallibility")
    yx = [r for r in rows if r["params"]["order"] == "scan:yx"]
    assert yx and "although proved infallible" in yx[0]["stats"]["contradiction"]
    assert "SHORTFALL (bugs)" in (tmp_path / "infallibility.md").read_text()


def test_random_runs_find_replay_and_count_by_the_documented_mix():
    """The cross-check of a proved model, forced on a fallible one (Fig. 3.5, scan:yx,
    no boundary): it finds failures, each replays alone through the catalog solver with
    its recorded seed and size, and the runs per size are the documented mix."""
    from csplab.analysis.witness import model_problem, replay
    from csplab.examples import load_example
    from csplab.experiments.infallibility import RUN_MIX, random_runs
    from csplab.solvers import solve

    E = load_example("fig3_5a")
    out = random_runs(E, "scan:yx", None, runs=200, seed=5, time_limit=60)
    assert out["runs_done"] == 200 and not out["cut"] and out["invalid"] == 0
    assert out["runs_per_size"] == {"x".join(map(str, s)): 2 * w for s, w in RUN_MIX[2]}
    assert 0 < out["failed"] < 200 and len(out["failures"]) == 3
    for f in out["failures"]:
        assert f["replays"] and replay(E, f).holds
        P = model_problem(E, f["shape"], None)
        assert 5 <= f["seed"] < 205
        assert solve(P, "catalog", rng=f["seed"], order="scan:yx").status == "failed"
    # same seed, same runs (the runs depend on the seed only, not on the process)
    again = random_runs(E, "scan:yx", None, runs=200, seed=5, time_limit=60)
    assert [f["seed"] for f in again["failures"]] == [f["seed"] for f in out["failures"]]
    assert again["failed"] == out["failed"]


def test_random_runs_check_every_solved_output(monkeypatch):
    """A planted defect the engine cannot see: a 'solved' grid with an unassigned cell on
    every 10th run is counted invalid by the independent check (Problem.violations)."""
    import csplab.engine.alg31 as alg31
    from csplab.examples import load_example
    from csplab.experiments.infallibility import random_runs

    real, calls = alg31.run_alg31, [0]

    def planted(P, rng, **kw):
        r = real(P, rng, **kw)
        calls[0] += 1
        if calls[0] % 10 == 0 and r.status == "solved":
            r.grid.flat[-1] = -1
        return r

    monkeypatch.setattr(alg31, "run_alg31", planted)
    out = random_runs(load_example("line"), "scanline", None, runs=100, seed=0, time_limit=60)
    assert out["failed"] == 0 and out["invalid"] == 10
    assert [f["kind"] for f in out["failures"]] == ["invalid"] * 3
    cut = random_runs(load_example("line"), "scanline", None, runs=100, seed=0, time_limit=0)
    assert cut["runs_done"] == 0 and cut["cut"]
