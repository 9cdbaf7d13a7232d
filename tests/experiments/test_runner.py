import importlib.util
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from csplab.errors import InputError
from csplab.examples import load_example
from csplab.experiments import ResultsStore, get_experiment
from csplab.experiments.runner import config_hash, run_trials
from csplab.experiments.trial import Trial, execute

ROOT = Path(__file__).resolve().parents[2]


def _trials(n=6, example="castle", size=(6, 6, 4)):
    E = load_example(example)
    ts = [
        Trial("t", example, E.hash(), size, "catalog", {"options": {}}, s, "auto") for s in range(n)
    ]
    return ts, {E.hash(): E}


def _outcomes(store, exp="t"):
    return {r["trial_key"]: (r["status"], r["stats"]["grid"]) for r in store.rows(exp)}


def test_serial_and_pool_give_the_same_outcomes(tmp_path):
    ts, ex = _trials()
    with ResultsStore(tmp_path / "a.sqlite") as a, ResultsStore(tmp_path / "b.sqlite") as b:
        s1 = run_trials(ts, ex, a, experiment="t", jobs=1, progress=False)
        s2 = run_trials(ts, ex, b, experiment="t", jobs=2, progress=False)
        assert (s1.ran, s2.ran) == (6, 6) and s2.executor == "2 local processes"
        assert _outcomes(a) == _outcomes(b)
        # the outcome is a pure function of the trial
        t = ts[3]
        out = execute(t, ex[t.example_hash])
        assert (out["status"], out["stats"]["grid"]) == _outcomes(a)[t.key]


def test_duplicates_and_errors(tmp_path):
    ts, ex = _trials(3)
    bad = Trial("t", "castle", ts[0].example_hash, (6, 6, 4), "nosuchsolver", {}, 0, "auto")
    with ResultsStore(tmp_path / "r.sqlite") as st:
        s = run_trials([*ts, ts[0], bad], ex, st, experiment="t", jobs=1, progress=False)
        assert s.total == 4 and s.ran == 3 and len(s.errors) == 1
        assert "unknown solver" in s.errors[0][1]
        assert st.count("t") == 3  # errors are not stored: the next run retries them
        with pytest.raises(InputError, match="no example model"):
            run_trials(ts, {}, st, experiment="t", jobs=1, progress=False)
    assert config_hash({"a": 1, "b": [1, 2]}) == config_hash({"b": [1, 2], "a": 1})


def _count(db):
    if not db.exists():
        return 0
    try:
        with ResultsStore(db) as st:
            return st.count("fig3_8")
    except Exception:  # the file is being created
        return 0


def test_kill_with_sigkill_then_resume_stores_every_trial_exactly_once(tmp_path):
    db = tmp_path / "r.sqlite"
    args = ["fig3_8", "--quick", "--example", "castle", "--sizes", "10,12", "--nz", "4",
            "--seeds", "150", "--store", str(db), "--out", str(tmp_path / "out"),
            "--no-progress"]  # fmt: skip
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "csplab", "experiment", *args, "--jobs", "2"],
        cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        start_new_session=True,
    )  # fmt: skip
    deadline = time.monotonic() + 120
    try:
        while _count(db) < 20 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)  # the sweep and its worker processes
        proc.wait(timeout=60)
    killed_at = _count(db)
    total = 2 * 150
    assert proc.returncode == -signal.SIGKILL, proc.stderr.read().decode()[-2000:]
    assert 20 <= killed_at < total
    exp = get_experiment("fig3_8")
    cfg = exp.make_config(quick=True, examples=["castle"], sizes=[10, 12], nz=4, seeds=150)
    trials, examples = exp.build(cfg)
    with ResultsStore(db) as st:
        s = run_trials(trials, examples, st, experiment="fig3_8", jobs=1, progress=False)
        assert s.skipped == killed_at and s.ran == total - killed_at
        rows = st.rows("fig3_8")
    keys = [r["trial_key"] for r in rows]
    assert len(rows) == total and len(set(keys)) == total
    assert set(keys) == {t.key for t in trials}


@pytest.mark.skipif(importlib.util.find_spec("distributed") is None, reason="needs distributed")
def test_dask_local_cluster_gives_the_same_results_as_the_local_pool(tmp_path):
    from distributed import Client, LocalCluster

    ts, ex = _trials(8)
    with ResultsStore(tmp_path / "a.sqlite") as a:
        run_trials(ts, ex, a, experiment="t", jobs=2, progress=False)
        pool = _outcomes(a)
    with (
        LocalCluster(
            n_workers=1, threads_per_worker=2, processes=True, dashboard_address=None
        ) as c,
        Client(c) as client,
        ResultsStore(tmp_path / "b.sqlite") as b,
    ):
        s = run_trials(ts[:4], ex, b, experiment="t", scheduler=client, progress=False)
        assert s.executor == "dask" and s.ran == 4 and not s.errors
        # by address too: the rest runs, the first four are skipped
        s2 = run_trials(ts, ex, b, experiment="t", scheduler=c.scheduler_address, progress=False)
        assert (s2.skipped, s2.ran, s2.executor) == (4, 4, "dask")
        assert _outcomes(b) == pool


def test_bad_scheduler_address_is_one_clear_error(tmp_path):
    pytest.importorskip("distributed")
    ts, ex = _trials(1)
    with ResultsStore(tmp_path / "r.sqlite") as st, pytest.raises(InputError, match="scheduler"):
        run_trials(ts, ex, st, experiment="t", scheduler=12, progress=False)
