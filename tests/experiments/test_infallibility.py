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
