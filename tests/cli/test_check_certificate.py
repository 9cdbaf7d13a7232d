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
    code, out, _ = run(capsys, "prove", "fig3_4a", "--order", "scan:yx", "--certificate",
                       str(other))  # fmt: skip
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
