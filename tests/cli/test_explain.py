import json

import numpy as np
import pytest

from csplab.cli import main
from csplab.cli.explain import load_fixed
from csplab.errors import FormatError

pytest.importorskip("pysat")


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_explain_prints_a_minimal_core(tmp_path, capsys):
    f = tmp_path / "fixed.txt"
    f.write_text("# x y label\n0 0 0\n1, 1 = 0\n2 0 1\n")
    code, out, _ = run(capsys, "explain", "E1", "--size", "3x3", "--fixed", str(f))
    assert code == 1
    assert out.startswith("unsat:") and "2 of 3 restrictions conflict (minimal)" in out
    assert "fixed cell (2, 0) = 1" in out and "fixed cell (1, 1) = 0" not in out
    code, out, _ = run(capsys, "explain", "E1", "--size", "3x3", "--fixed", str(f), "--json")
    d = json.loads(out)
    assert code == 1 and d["holds"] is True and d["witness"]["minimal"] is True


def test_explain_satisfiable_unsat_without_restrictions_and_npy(tmp_path, capsys):
    code, out, _ = run(capsys, "explain", "line", "--size", "6x6", "--boundary", "auto")
    assert code == 0 and out.startswith("satisfiable")
    code, out, _ = run(capsys, "explain", "fig3_1d", "--size", "5x5")
    assert code == 1 and "even without" in out
    g = np.full((3, 3), -1)
    g[0, 0], g[0, 1] = 0, 0
    np.save(tmp_path / "f.npy", g)
    code, out, _ = run(capsys, "explain", "E1", "--size", "3x3", "--fixed", str(tmp_path / "f.npy"))
    assert code == 1 and "(0, 1) = 0" in out


def test_explain_bad_input_is_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.txt"
    bad.write_text("0 0 1\n0 q 1\n")
    for argv in (
        ["explain", "E1", "--size", "3x3", "--fixed", str(bad)],
        ["explain", "E1", "--size", "3x3", "--fixed", str(tmp_path / "none.txt")],
        ["explain", "E1", "--size", "3x3", "--backend", "nonesuch"],
    ):
        code, _, err = run(capsys, *argv)
        assert code == 2 and err.startswith("csplab: error:") and "Traceback" not in err
    with pytest.raises(FormatError, match="line 2"):
        load_fixed(str(bad), (3, 3))
    far = tmp_path / "far.txt"
    far.write_text("5 5 0\n")
    with pytest.raises(FormatError, match="outside"):
        load_fixed(str(far), (3, 3))
