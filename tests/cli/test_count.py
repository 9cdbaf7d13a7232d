"""csplab count."""

import json

from csplab.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_count_json_and_bounds(capsys):
    code, out, _ = run(capsys, "count", "line", "--size", "3x12", "--bounds", "--json")
    d = json.loads(out)
    assert code == 0 and d["exact"] and d["bounds_hold"] is True
    assert int(d["count"]) >= int(d["lower_bound_3_2_1"])


def test_count_checkerboard_and_unique(capsys):
    code, out, _ = run(capsys, "count", "fig3_1b", "--size", "6x9")
    assert code == 0 and "= 2 " in out
    code, out, _ = run(capsys, "count", "fig3_1d", "--size", "4x3")
    assert code == 1 and "= 0 " in out


def test_count_entropy_and_errors(capsys):
    code, out, _ = run(capsys, "count", "line", "--size", "4x6", "--entropy", "6,12")
    assert code == 0 and "bits per cell" in out
    code, _, err = run(capsys, "count", "line", "--size", "4x6", "--entropy", "6")
    assert code == 2 and "--entropy" in err
    code, _, err = run(capsys, "count", "nosuch", "--size", "4x6")
    assert code == 2
