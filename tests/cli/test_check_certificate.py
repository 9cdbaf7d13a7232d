"""``csplab prove --certificate`` and ``csplab check-certificate``: exit codes 0/1/2 (issue 26)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from csplab.cli import main

DATA = Path(__file__).resolve().parents[1] / "io" / "data"


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("model", ["pillar", str(DATA / "pipes.xml")])
def test_prove_and_check_a_3d_builtin_and_a_tileset(tmp_path, capsys, model):
    cert = tmp_path / "c.json"
    code, out, _ = run(capsys, "prove", model, "--certificate", str(cert))
    assert code == 0 and f"wrote certificate {cert} (infallible)" in out
    code, out, _ = run(capsys, "check-certificate", str(cert), "--model", model)
    assert code == 0, out
    assert "valid:" in out and "Theorem 3.3.6" in out and "the prover took" in out
    print(out)
    d = json.loads(cert.read_text())  # a planted defect: one state removed
    conf = max(d["configs"], key=lambda c: len(c["states"]))
    conf["states"].pop()
    cert.write_text(json.dumps(d))
    code, out, _ = run(capsys, "check-certificate", str(cert))
    assert code == 1 and "invalid:" in out


def test_refuted_certificate_and_undecided(tmp_path, capsys):
    cert = tmp_path / "c.json"
    code, out, _ = run(capsys, "prove", "fig3_5a", "--order", "scan:yx", "--certificate",
                       str(cert))  # fmt: skip
    assert code == 1 and "(fallible)" in out
    code, out, _ = run(capsys, "check-certificate", str(cert), "--model", "fig3_5a")
    assert code == 0 and "wipes out a catalog" in out
    other = tmp_path / "u.json"
    code, out, _ = run(capsys, "prove", "fig3_4a", "--region", "2", "--order", "scan:yx",
                       "--certificate", str(other))  # fmt: skip
    assert code == 3 and "no certificate written" in out and not other.exists()


def test_check_certificate_bad_files(tmp_path, capsys):
    code, _, err = run(capsys, "check-certificate", str(tmp_path / "none.json"))
    assert code == 2 and "no such file" in err and len(err.strip().splitlines()) == 1
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    code, _, err = run(capsys, "check-certificate", str(bad))
    assert code == 2 and "bad.json" in err
    cert = tmp_path / "c.json"
    assert run(capsys, "prove", "fig3_15", "--certificate", str(cert))[0] == 0
    code, _, err = run(capsys, "check-certificate", str(cert), "--model", "line")
    assert code == 2 and "not those of line" in err


def test_tileset_outside_the_proof_is_one_line(capsys):
    code, _, err = run(capsys, "prove", str(DATA / "tiny_debroglie.json"))
    assert code == 2 and "global constraints" in err
    assert len([ln for ln in err.splitlines() if ln.startswith("csplab: error")]) == 1


def test_witness_count_refine_on_tilesets(capsys):
    pipes = str(DATA / "pipes.xml")
    code, out, _ = run(capsys, "witness", pipes, "--max-size", "3x3", "--time-limit", "20")
    assert code != 1 and "no failure" in out  # prove says infallible
    code, out, _ = run(capsys, "count", pipes, "--size", "2x2", "--entropy", "2,3")
    assert code == 0 and "entropy estimate" in out
    code, _, err = run(capsys, "count", pipes, "--size", "2x2", "--bounds")
    assert code == 2 and "Theorem 3.2.1" in err and "tileset" in err
    code, _, err = run(capsys, "refine", pipes)
    assert code == 2 and "example grid" in err and len(err.strip().splitlines()) == 1


def test_witness_replays_on_a_tileset_with_its_own_boundary():
    # isle on both x faces and no two isles side by side along x: the file's boundary
    # makes every output of width 2 unsatisfiable, so Alg. 3.1 fails there; without the
    # boundary the rules are infallible (proved, and witness finds nothing)
    import numpy as np

    from csplab.analysis import find_failure, prove_infallible, replay
    from csplab.io.ruleset import DomainOp, RuleSet

    T = np.ones((2, 2, 2), dtype=bool)
    T[0, 1, 1] = False
    isle = np.array([False, True])
    faces = [DomainOp("force", isle, face="x-"), DomainOp("force", isle, face="x+")]
    rs = RuleSet(T, names=["sea", "isle"], boundary_ops=faces)
    own = find_failure(rs, max_size=(3, 3), random_runs=0, time_limit=20)
    assert own.holds is False and own.witness["boundary"] == "auto"
    assert own.witness["shape"][0] == 2 and replay(rs, own.witness).holds
    free = RuleSet(T, names=["sea", "isle"])
    assert find_failure(free, max_size=(3, 3), random_runs=0, time_limit=20).holds is True
    assert prove_infallible(free).holds is True


def test_catalog_gap_and_corner_on_a_tileset(capsys):
    pipes = str(DATA / "pipes.xml")
    code, out, _ = run(capsys, "catalog-gap", pipes, "--size", "3x3", "--seed", "1", "--steps",
                       "summary")  # fmt: skip
    assert code == 0 and out.startswith("pipes 3x3 (K=12)") and "ok: all 9" in out
    code, out, _ = run(capsys, "prove", pipes, "--corner")
    assert code == 0 and out.startswith("corner condition holds")
    code, out, _ = run(capsys, "prove", pipes)
    assert "scope: grids of every size, not periodic, no boundary conditions" in out


def test_corner_refuses_face_rules_in_one_line(capsys):
    code, _, err = run(capsys, "prove", str(DATA / "tiny_poms.json"), "--corner")
    assert code == 2 and "face rules" in err
    assert len([ln for ln in err.splitlines() if ln.startswith("csplab: error")]) == 1
