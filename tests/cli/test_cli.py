import json

import numpy as np
import pytest

from csplab.cli import COMMANDS, main
from csplab.examples import example_names, load_example


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def _size_for(name):
    E = load_example(name)
    if E.ndim == 3 and E.shape[2] > 1:
        return "12x12x" + str(min(E.shape[2], 8))
    return "10x8"


@pytest.mark.parametrize("name", example_names())
@pytest.mark.parametrize("solver", ["catalog", "blocks"])
def test_synthesize_every_builtin(tmp_path, capsys, name, solver):
    out = tmp_path / "o.npy"
    size = _size_for(name)
    if name == "fig3_1d":
        size = "3x3"
    args = ["synthesize", name, "--size", size, "--seed", "1", "--out", str(out), "--json"]
    if solver == "blocks":
        args += ["--solver", "blocks", "--block", "4"]
    code, stdout, _ = run(capsys, *args)
    d = json.loads(stdout)
    if code == 0:
        assert d["status"] == "solved"
        code2, o2, _ = run(capsys, "check", name, str(out))
        assert code2 == 0 and o2.startswith("0 violations")
    else:
        assert code == 1 and d["status"] in ("failed", "unsat")


def test_outputs_png_txt_grid(tmp_path, capsys):
    for ext in ("png", "txt", "grid"):
        p = tmp_path / f"o.{ext}"
        code, out, _ = run(capsys, "synthesize", "line", "--size", "12x6", "--seed", "2",
                           "--out", str(p))  # fmt: skip
        assert code == 0 and p.exists() and "wrote" in out
        if ext != "png":
            assert run(capsys, "check", "line", str(p))[0] == 0


def test_exit_codes_and_one_line_errors(tmp_path, capsys):
    code, _, err = run(capsys, "synthesize", "fig3_1d", "--size", "5x5", "--seed", "0")
    assert code == 1
    for argv in (
        ["synthesize", "nonesuch", "--size", "5x5"],
        ["synthesize", "line", "--size", "5xq"],
        ["synthesize", "line", "--size", "5x5x5"],
        ["synthesize", "line", "--size", "5x5", "--solver", "zzz"],
        ["synthesize", "line", "--size", "5x5", "--out", "x.jpg"],
        ["synthesize", "E1", "--size", "5x5", "--boundary", "auto"],
        ["synthesize", str(tmp_path / "missing.txt"), "--size", "5x5"],
    ):
        code, _, err = run(capsys, *argv)
        lines = [ln for ln in err.splitlines() if ln.strip()]
        assert code == 2, argv
        assert lines and lines[0].startswith("csplab: error:") and "Traceback" not in err
    bad = tmp_path / "bad.txt"
    bad.write_text("a\nb\nc\n2 2 1\n0 1\n1 z\n")
    code, _, err = run(capsys, "synthesize", str(bad), "--size", "4x4x1")
    assert code == 2 and "line 6" in err and str(bad) in err


def test_check_reports_violations(tmp_path, capsys):
    g = np.zeros((5, 4), dtype=np.int32)
    g[0, 0] = g[0, 1] = 1  # two 1s on top of each other: never in the line example
    p = tmp_path / "g.npy"
    np.save(p, g)
    code, out, _ = run(capsys, "check", "line", str(p))
    assert code == 1 and out.startswith("1 violations")


def test_merrell_file_model(tmp_path, capsys):
    m = tmp_path / "house.txt"
    m.write_text("house\n\n\n3 3 2\n1 1 1\n1 1 1\n1 1 1\n0 0 0\n0 2 0\n0 0 0\n0 air\n")
    out = tmp_path / "o.txt"
    code, _, _ = run(capsys, "synthesize", str(m), "--size", "8x8x2", "--seed", "0",
                     "--boundary", "auto", "--out", str(out))  # fmt: skip
    assert code == 0
    assert run(capsys, "check", str(m), str(out), "--boundary", "auto")[0] == 0


def test_info(capsys):
    code, out, _ = run(capsys, "info", "--json")
    d = json.loads(out)
    assert code == 0 and {s["name"] for s in d["solvers"]} >= {"catalog", "blocks"}
    assert "line" in d["examples"]


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_command_help(capsys, name):
    # --help exits 0 with the command's description: its module docstring (or DESCRIPTION /
    # description()); a stray '%' in an option's help used to crash argparse here
    with pytest.raises(SystemExit) as e:
        main([name, "--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith(f"usage: csplab {name}")
    assert "``" not in out and ":mod:" not in out


def test_console_script_exit_at_once_keeps_codes_and_output(tmp_path, capsys):
    """`python -m csplab synthesize` ends without the interpreter's teardown
    (``EXIT_AT_ONCE``): the exit codes, the flushed stdout and the written file stay."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    env = dict(os.environ)
    env["PYTHONPATH"] = str(Path(__file__).resolve().parents[2])
    out = tmp_path / "o.npy"

    def cli(*argv):
        return subprocess.run([sys.executable, "-m", "csplab", *argv], env=env,
                              capture_output=True, text=True, timeout=120)  # fmt: skip

    p = cli("synthesize", "castle", "--size", "6x6x3", "--solver", "sat", "--seed", "1",
            "--out", str(out), "--json")  # fmt: skip
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)  # the whole line arrived: stdout was flushed before the exit
    assert d["status"] == "solved" and d["out"] == str(out)
    assert cli("check", "castle", str(out)).returncode == 0
    same = tmp_path / "same.npy"  # in-process (main(argv) returns): the same bytes
    assert main(["synthesize", "castle", "--size", "6x6x3", "--solver", "sat", "--seed", "1",
                 "--out", str(same)]) == 0  # fmt: skip
    assert same.read_bytes() == out.read_bytes()
    assert cli("synthesize", "fig3_1d", "--size", "5x5", "--seed", "0").returncode == 1
    bad = cli("synthesize", "line", "--size", "5xq")
    assert bad.returncode == 2 and bad.stderr.startswith("csplab: error:")
