import csv
import sqlite3

from csplab.experiments.store import ResultsStore, git_revision
from csplab.experiments.trial import Trial


def _t(seed, **kw):
    return Trial(
        "exp", "line", "hash0", (6, 4), "catalog", {"options": {"order": "random"}}, seed, **kw
    )


def test_each_trial_is_stored_once_with_provenance(tmp_path):
    st = ResultsStore(tmp_path / "sub" / "r.sqlite")
    assert st.add(_t(1), {"status": "solved", "time_s": 0.5, "stats": {"a": 1}}, config_hash="c")
    assert not st.add(_t(1), {"status": "failed", "time_s": 9.0, "stats": {}}, config_hash="d")
    assert st.add(_t(2), {"status": "failed", "time_s": 0.1, "stats": {"a": 2}}, config_hash="c")
    rows = st.rows("exp")
    assert [(r["seed"], r["status"]) for r in rows] == [(1, "solved"), (2, "failed")]
    r = rows[0]
    assert r["params"] == {"options": {"order": "random"}} and r["stats"] == {"a": 1}
    assert r["example_hash"] == "hash0" and r["size"] == "6x4" and r["config_hash"] == "c"
    assert r["csplab_version"] and r["git_rev"] == git_revision() and r["host"]
    assert st.done_keys("exp") == {_t(1).key, _t(2).key}
    assert st.count() == 2 and st.count("other") == 0
    st.close()
    # the unique index is in the file itself, not only in the Python layer
    db = sqlite3.connect(tmp_path / "sub" / "r.sqlite")
    idx = db.execute("SELECT sql FROM sqlite_master WHERE type='index'").fetchall()
    assert (
        any("trial_key" in (s or "") for (s,) in idx)
        or db.execute(
            "SELECT COUNT(*) FROM sqlite_master WHERE sql LIKE '%UNIQUE (experiment, trial_key)%'"
        ).fetchone()[0]
    )


def test_rows_filtered_by_keys_and_csv_export(tmp_path):
    with ResultsStore(tmp_path / "r.sqlite") as st:
        for s in range(4):
            st.add(_t(s), {"status": "solved", "time_s": s, "stats": {"x": s, "_hidden": "z"}},
                   config_hash="c")  # fmt: skip
        keys = {_t(1).key, _t(3).key}
        assert sorted(r["seed"] for r in st.rows("exp", keys)) == [1, 3]
        n = st.export_csv(tmp_path / "o.csv", "exp", keys)
    assert n == 2
    rows = list(csv.DictReader(open(tmp_path / "o.csv")))
    assert [r["stats.x"] for r in rows] == ["1", "3"]
    assert "stats._hidden" not in rows[0] and rows[0]["solver"] == "catalog"


def test_delete_and_gzip_export(tmp_path):
    import gzip

    with ResultsStore(tmp_path / "r.sqlite") as st:
        for s in range(3):
            st.add(_t(s), {"status": "solved", "time_s": 0, "stats": {}}, config_hash="c")
        assert st.delete("exp", [_t(0).key, "nokey"]) == 1
        assert st.count("exp") == 2
        assert st.export_csv(tmp_path / "o.csv.gz", "exp") == 2
        assert st.delete("exp") == 2 and st.count() == 0
    with gzip.open(tmp_path / "o.csv.gz", "rt") as f:
        assert len(list(csv.DictReader(f))) == 2


def test_runs_table_records_sweeps(tmp_path):
    with ResultsStore(tmp_path / "r.sqlite") as st:
        rid = st.start_run("exp", {"a": 1}, "h", trials=5, skipped=2, command="csplab x")
        st.finish_run(rid, ran=3, errors=0)
        (run,) = st.runs("exp")
    assert run["trials"] == 5 and run["skipped"] == 2 and run["ran"] == 3 and run["finished_at"]


def test_trial_key_depends_on_everything_but_the_name():
    base = _t(1)
    assert base.key == Trial.from_dict(base.to_dict()).key
    renamed = Trial("exp", "path/to/line.grid", "hash0", (6, 4), "catalog",
                    {"options": {"order": "random"}}, 1)  # fmt: skip
    assert renamed.key == base.key
    for other in (
        _t(2),
        _t(1, boundary="auto"),
        _t(1, periodic=True),
        Trial("exp", "line", "hash1", (6, 4), "catalog", base.params, 1),
        Trial("exp", "line", "hash0", (6, 5), "catalog", base.params, 1),
        Trial("exp", "line", "hash0", (6, 4), "blocks", base.params, 1),
        Trial("exp", "line", "hash0", (6, 4), "catalog", {"options": {}}, 1),
        Trial("exp2", "line", "hash0", (6, 4), "catalog", base.params, 1),
    ):
        assert other.key != base.key
