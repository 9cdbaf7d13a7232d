"""The CLI on polygon models: synthesize (every built-in, every output format), check, show,
and the one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from PIL import Image

from csplab.cli import main
from csplab.continuous import violations
from csplab.examples.continuous import continuous_example_names, load_polygon_example
from csplab.io.polygons import read_polygons_json, read_svg


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("name", continuous_example_names())
@pytest.mark.parametrize("solver", ["catalog", "blocks", "sat"])
def test_every_builtin_with_catalog_blocks_sat(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, solver: str
) -> None:
    out = tmp_path / "o.json"
    args = ["synthesize", name, "--size", "16x12", "--seed", "3", "--solver", solver,
            "--out", str(out), "--json"]  # fmt: skip
    if solver == "blocks":
        args += ["--block", "6"]
    code, stdout, _ = run(capsys, *args)
    d = json.loads(stdout)
    assert code == 0, d  # restarts=10 by default for catalog; blocks and sat never fail
    assert d["status"] == "solved" and d["violations"] == 0 and d["out"] == str(out)
    assert d["vertices"] > 0 and d["edges"] > d["vertices"]
    M = read_polygons_json(out)
    assert len(violations(load_polygon_example(name), M)) == 0
    code, stdout, _ = run(capsys, "check", name, str(out))
    assert code == 0 and stdout.startswith("0 violations")


def test_svg_and_png_outputs_and_show(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    svg, png = tmp_path / "t.svg", tmp_path / "t.png"
    code, stdout, _ = run(capsys, "synthesize", "two_objects", "--size", "20x14", "--seed", "1",
                          "--out", str(svg))  # fmt: skip
    assert code == 0 and "Eq. 4.1 violations=0" in stdout and f"wrote {svg}" in stdout
    M = read_svg(svg)
    assert M.labels == (1, 2)
    assert len(violations(load_polygon_example("two_objects"), M)) == 0
    code, _, _ = run(capsys, "synthesize", "two_objects", "--size", "20x14", "--seed", "1",
                     "--out", str(png))  # fmt: skip
    assert code == 0 and Image.open(png).size[0] > 0
    shown = tmp_path / "shown.png"
    code, stdout, _ = run(capsys, "show", str(svg), "--out", str(shown))
    assert code == 0 and shown.exists() and "polygons" in stdout
    code, _, err = run(capsys, "show", str(svg), "--out", str(shown))
    assert code == 2 and "--force" in err  # no silent overwrite


def test_check_finds_a_planted_defect(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"polygons": [{"label": 1, "points": [[0, 3], [4, 3], [2, 0]]}]}))
    code, stdout, _ = run(capsys, "check", "triangle", str(bad))
    assert code == 1 and stdout.startswith("6 violations") and "edge at (0, 3)" in stdout
    code, stdout, _ = run(capsys, "check", "triangle", str(bad), "--json")
    assert code == 1 and json.loads(stdout)["vertex"] == 3


def test_file_example_spacing_and_boundary(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ex = tmp_path / "ex.json"
    ex.write_text(json.dumps({"polygons": [{"label": 1, "points": [[0, 0], [10, 0], [5, 7.5]]}]}))
    code, stdout, _ = run(capsys, "synthesize", str(ex), "--size", "12x10", "--seed", "2")
    assert code == 0 and "spacings of 2.5" in stdout
    args = ["--spacing", "5", "--snap", "--boundary", "1", "--solver", "sat"]
    code, stdout, _ = run(capsys, "synthesize", str(ex), "--size", "12x10", "--seed", "2", *args)
    assert code == 0 and "spacings of 5" in stdout


def test_a_failed_run_hints_at_blocks(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "synthesize", "fallible", "--size", "40x40", "--seed", "1",
                         "--restarts", "0", "--fallback", "none")  # fmt: skip
    assert code == 1 and "--solver blocks" in err
    assert out.startswith("not solved:") and "says nothing about satisfiability" in out


def test_the_default_chain_finishes_a_failed_continuous_run(
    capsys: pytest.CaptureFixture[str],
) -> None:
    code, out, _ = run(capsys, "synthesize", "fallible", "--size", "40x40", "--seed", "1",
                       "--restarts", "0", "--json")  # fmt: skip
    d = json.loads(out)
    assert code == 0 and d["outcome"] == "solved" and d["violations"] == 0
    assert d["solver"] == "sat" and d["stats"]["fallback_from"] == "catalog"


@pytest.mark.parametrize(
    "argv, message",
    [
        (["synthesize", "triangle"], "--size is required"),
        (["synthesize", "triangle", "--size", "4x4x4"], "needs WxH"),
        (["synthesize", "triangle", "--size", "4x4", "--periodic"], "not periodic"),
        (["synthesize", "triangle", "--size", "4x4", "--boundary", "z-=1"], "one label"),
        (["synthesize", "triangle", "--size", "4x4", "--boundary", "5"], "does not occur"),
        (["synthesize", "triangle", "--size", "4x4", "--spacing", "-1"], "positive"),
        (["synthesize", "triangle", "--size", "4x4", "--out", "x.vox"], "unknown output format"),
        (["synthesize", "triangle", "--size", "4x4", "--out-partial"], "no partial"),
        (["synthesize", "line", "--size", "4x4", "--spacing", "2"], "continuous"),
        (["count", "triangle", "--size", "4x4"], "polygon model"),
        (["check", "triangle", "line"], "not a polygon model"),
    ],
)
def test_bad_input_is_one_line(
    capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    code, _, err = run(capsys, *argv)
    assert code == 2 and message in err and err.count("\n") == 1, err


def test_bad_polygon_file_names_file_and_polygon(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    f = tmp_path / "bow.json"
    f.write_text(json.dumps({"polygons": [
        {"label": 1, "points": [[0, 0], [1, 0], [0, 1]]},
        {"label": 1, "points": [[5, 5], [6, 6], [6, 5], [5, 6]]}]}))  # fmt: skip
    code, _, err = run(capsys, "synthesize", str(f), "--size", "4x4")
    assert code == 2 and "bow.json" in err and "polygon 1" in err and "crosses itself" in err


def test_ground_of_a_polygon_model(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    ex = tmp_path / "towers.json"
    ex.write_text(json.dumps({"name": "towers", "ground": "y-", "polygons": [
        {"label": 1, "points": [[0, 0], [2, 0], [2, 3], [1, 4], [0, 3]]},
        {"label": 2, "points": [[4, 0], [7, 0], [7, 1], [4, 1]]}]}))  # fmt: skip
    out = tmp_path / "o.json"
    code, stdout, _ = run(capsys, "synthesize", str(ex), "--size", "24x16", "--seed", "1",
                          "--out", str(out))  # fmt: skip
    assert code == 0 and "ground=y- (the example's)" in stdout
    M = read_polygons_json(out)
    assert len(M) and all(min(y for _, y in p.points) == 0 for p in M.polygons)
    code, stdout, _ = run(capsys, "check", str(ex), str(out))
    assert code == 0 and stdout.startswith("0 violations")
    free = tmp_path / "free.json"  # without the ground: polygons float, which it forbids
    code, _, _ = run(capsys, "synthesize", str(ex), "--size", "24x16", "--seed", "1",
                     "--ground", "none", "--out", str(free))  # fmt: skip
    assert code == 0
    code, stdout, _ = run(capsys, "check", str(ex), str(free), "--ground", "none")
    assert code == 0 and stdout.startswith("0 violations")
    code, stdout, _ = run(capsys, "check", str(ex), str(free))
    assert code == 1 and not stdout.startswith("0 violations")
    code, _, err = run(capsys, "synthesize", str(ex), "--size", "8x6", "--ground", "z-")
    assert code == 2 and "z-" in err and len(err.strip().splitlines()) == 1
