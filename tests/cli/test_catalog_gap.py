import json

import numpy as np
import pytest

from csplab.cli import main

pytest.importorskip("pysat")

FALLIBLE = np.array([[0, 0, 0, 2], [2, 0, 0, 1], [0, 1, 2, 1]], dtype=np.int32)


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_gap_found_on_a_fallible_example(tmp_path, capsys):
    m = tmp_path / "fallible.npy"
    np.save(m, FALLIBLE)
    code, out, _ = run(capsys, "catalog-gap", str(m), "--size", "5x5", "--seed", "0")
    assert code == 1
    assert "NOT in C*" in out and out.count("step ") >= 2 and "gap: step 0" in out
    code, out, _ = run(capsys, "catalog-gap", str(m), "--size", "5x5", "--seed", "0", "--json")
    d = json.loads(out)
    assert d["holds"] is False and d["witness"]["step"] == 0


def test_no_gap_on_an_infallible_example(capsys):
    code, out, _ = run(capsys, "catalog-gap", "line", "--size", "5x4", "--seed", "2", "--sizes")
    assert code == 0 and "|C*|" in out and "NOT" not in out and out.rstrip().endswith("s)")
    code, out, _ = run(capsys, "catalog-gap", "line", "--size", "5x4", "--steps", "summary")
    assert code == 0 and "step " not in out.split("\n", 1)[1].split("ok:")[0]


def test_bad_input(capsys):
    code, _, err = run(capsys, "catalog-gap", "line", "--size", "5x4", "--seed", "-1")
    assert code == 2 and err.startswith("csplab: error:")


def test_scan_axes_orders_on_the_command_line(tmp_path, capsys):
    """The thesis' 2D figures scan x fastest (``scan:yx``); Fig. 3.5 replays in that order."""
    code, out, _ = run(capsys, "catalog-gap", "fig3_5a", "--size", "4x4", "--seed", "8",
                       "--order", "scan:yx", "--steps", "summary")  # fmt: skip
    assert code == 1 and "gap: step 2: label 1 at (2, 0)" in out
    code, out, _ = run(capsys, "synthesize", "line", "--size", "6x4", "--order", "scan:yx",
                       "--seed", "0", "--out", str(tmp_path / "o.npy"))  # fmt: skip
    assert code == 0
    code, _, err = run(capsys, "synthesize", "line", "--size", "6x4", "--order", "scan:xx")
    assert code == 2 and "name each of the 2 axes" in err
