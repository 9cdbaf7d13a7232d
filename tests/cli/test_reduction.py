"""csplab reduction planar3sat | lba."""

import json

from csplab.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_planar3sat_check_and_pictures(tmp_path, capsys):
    png, sol, lab = tmp_path / "m.png", tmp_path / "s.png", tmp_path / "l.png"
    code, out, _ = run(capsys, "reduction", "planar3sat", "--vars", "6", "--clauses", "8",
                       "--seed", "1", "--png", str(png), "--solution-png", str(sol),
                       "--labels-png", str(lab), "--check")  # fmt: skip
    assert code == 0 and "reduction verified" in out
    assert png.stat().st_size and sol.stat().st_size and lab.stat().st_size


def test_planar3sat_unsat_json(capsys, tmp_path):
    code, out, err = run(capsys, "reduction", "planar3sat", "--vars", "7", "--clauses", "10",
                         "--seed", "3", "--signs", "unsat", "--check", "--json",
                         "--solution-png", str(tmp_path / "s.png"))  # fmt: skip
    d = json.loads(out)
    assert code == 0 and d["check"]["sat"] is False and d["check"]["completable"] is False
    assert d["solution_png"] is None and "unsatisfiable" in err


def test_planar3sat_bad_input(capsys):
    code, _, err = run(capsys, "reduction", "planar3sat", "--vars", "4", "--clauses", "9")
    assert code == 2 and "at most 4" in err and "Traceback" not in err


def test_lba(capsys):
    code, out, _ = run(capsys, "reduction", "lba", "anbncn", "--input", "aabbcc", "--show")
    assert code == 0 and "consistent" in out and "(>,acc)" in out
    code, out, _ = run(capsys, "reduction", "lba", "ww", "--input", "abba", "--json")
    d = json.loads(out)
    assert code == 1 and d["consistent"] is False and d["accepted"] is False and d["agree"]
    code, _, err = run(capsys, "reduction", "lba", "anbncn", "--input", "abx")
    assert code == 2 and "alphabet" in err
