"""A resumed sweep says when stored trials were computed by other code, and can rerun them."""

import itertools
import re
import sqlite3
import subprocess
from pathlib import Path

import pytest

from csplab import __version__
from csplab.cli import main
from csplab.experiments import ResultsStore
from csplab.experiments.store import code_revision, git_revision, is_current, same_code

OTHER = "0123456789ab"  # a revision this checkout does not have


def _cli(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def _age(db, n, *, skip=0, rev=OTHER, version=None):
    """Pretend ``n`` stored trials (after the first ``skip``) came from revision ``rev``."""
    con = sqlite3.connect(db)
    q = "SELECT id FROM trials ORDER BY id LIMIT ? OFFSET ?"
    ids = [i for (i,) in con.execute(q, (n, skip))]
    for i in ids:
        con.execute(
            "UPDATE trials SET git_rev = ?, csplab_version = ? WHERE id = ?",
            (rev, version or __version__, i),
        )
    con.commit()
    con.close()


def _revs(db):
    with ResultsStore(db) as st:
        return sorted((r["git_rev"], r["csplab_version"]) for r in st.rows("fig3_8"))


@pytest.fixture
def sweep(tmp_path):
    args = ["experiment", "fig3_8", "--quick", "--example", "line", "--seeds", "2",
            "--store", str(tmp_path / "r.sqlite"), "--out", str(tmp_path / "o"),
            "--jobs", "1", "--no-progress", "--no-figures"]  # fmt: skip
    return args, tmp_path / "r.sqlite", tmp_path / "o" / "fig3_8.md"


def test_resume_reports_rows_from_other_code_and_rerun_stale_recomputes_them(capsys, sweep):
    args, db, md = sweep
    code, out, err = _cli(capsys, *args)
    assert code == 0 and "4 run" in out and "warning" not in err
    current = _revs(db)
    assert current == [code_revision()] * 4
    _age(db, 2)
    _age(db, 1, skip=2, rev=code_revision()[0], version="0.0.1")  # same sources, older version
    # resuming reuses them but says so: one line on stderr, exit 0
    code, out, err = _cli(capsys, *args)
    assert code == 0 and "all 4 already stored (3 by other code); nothing to run" in out
    (line,) = [ln for ln in err.splitlines() if ln.strip()]
    assert line.startswith("csplab: warning: fig3_8: 3 of the 4 stored trials")
    assert f"2 by git {OTHER} (csplab {__version__})" in line
    assert f"1 by git {code_revision()[0]} (csplab 0.0.1)" in line
    assert "--rerun-stale" in line and "--rerun " in line
    note = md.read_text()
    assert "computed by 3 revisions of csplab" in note and f"git {OTHER}" in note
    # the report only: the same line
    code, out, err = _cli(capsys, *args, "--report-only")
    assert code == 0 and "3 of the 4 stored trials" in err
    # --rerun-stale runs those three again and nothing else
    code, out, err = _cli(capsys, *args, "--rerun-stale")
    assert code == 0 and "1 already stored, 3 run" in out and "warning" not in err
    assert _revs(db) == current
    assert "revisions of csplab" not in md.read_text()
    # --json carries the counts too
    _age(db, 4)
    code, out, _ = _cli(capsys, *args, "--json")
    assert '"stale": {"git ' + OTHER in out
    # --rerun recomputes the whole sweep
    code, out, err = _cli(capsys, *args, "--rerun")
    assert code == 0 and "0 already stored, 4 run" in out and "warning" not in err
    assert _revs(db) == current


def test_identical_rows_are_recomputed_identically_after_rerun(capsys, sweep):
    args, db, _ = sweep
    _cli(capsys, *args)
    with ResultsStore(db) as st:
        before = {r["trial_key"]: (r["status"], r["stats"]["grid"]) for r in st.rows("fig3_8")}
    _age(db, 4)
    _cli(capsys, *args, "--rerun-stale")
    with ResultsStore(db) as st:
        after = {r["trial_key"]: (r["status"], r["stats"]["grid"]) for r in st.rows("fig3_8")}
        assert not st.stale("fig3_8")
    assert after == before


def test_revision_format_and_comparison():
    rev = git_revision()
    assert rev == "-" or re.fullmatch(r"[0-9a-f]{12}(\+dirty\.[0-9a-f]{8})?", rev)
    assert same_code(rev, rev) and is_current(*code_revision())
    assert not is_current(rev, "0.0.1")
    assert not same_code(OTHER, "fedcba987654")  # unknown commits: cannot tell, so stale
    assert not same_code("-", OTHER) and not same_code(f"{OTHER}+dirty.00000000", OTHER)


def _git(*args):
    pkg = Path(__file__).resolve().parents[2] / "csplab"
    r = subprocess.run(["git", *args], cwd=pkg, capture_output=True, text=True)
    if r.returncode:
        pytest.skip("needs a git checkout with history")
    return r.stdout.strip()


def test_commits_with_the_same_package_sources_are_the_same_code():
    """Derived independently: the git tree object of csplab/ at each commit."""
    commits = _git("rev-list", "--max-count=40", "HEAD").split()
    trees = {c: _git("rev-parse", f"{c}:csplab") for c in commits}
    pairs = list(itertools.pairwise(commits))
    same = [(a, b) for a, b in pairs if trees[a] == trees[b]]
    other = [(a, b) for a, b in pairs if trees[a] != trees[b]]
    if not same or not other:
        pytest.skip("history too short for both cases")
    for a, b in same[:3] + other[:3]:
        assert same_code(a[:12], b[:12]) == (trees[a] == trees[b]), (a, b)
