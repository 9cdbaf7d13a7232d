"""The exact solvers behind ``csplab synthesize --solver`` (``sat:glucose4`` style names)."""

import json

import pytest

from csplab.cli import main

pytest.importorskip("pysat")


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize(
    "solver", ["sat", "sat:glucose4", "sat:cd19", "cpsat", "backtrack", "perfect", "hybrid"]
)
def test_synthesize_with_exact_solvers(tmp_path, capsys, solver):
    if solver == "cpsat":
        pytest.importorskip("ortools")
    out = tmp_path / "o.npy"
    code, stdout, _ = run(capsys, "synthesize", "line", "--size", "9x7", "--seed", "3",
                          "--solver", solver, "--out", str(out), "--json")  # fmt: skip
    d = json.loads(stdout)
    assert code == 0 and d["status"] == "solved" and d["solver"] == solver
    assert run(capsys, "check", "line", str(out))[0] == 0


def test_unsat_exit_code_and_solver_options(capsys):
    code, stdout, _ = run(capsys, "synthesize", "fig3_1d", "--size", "5x5", "--solver", "sat")
    assert code == 1 and stdout.startswith("unsat")
    opts = ["--option", "amo=ladder", "--option", "choice=weighted", "--json"]
    code, stdout, _ = run(capsys, "synthesize", "line", "--size", "6x6", "--solver", "sat", *opts)
    assert code == 0 and json.loads(stdout)["stats"]["amo"] == "ladder"
    code, _, err = run(capsys, "synthesize", "line", "--size", "6x6", "--solver", "sat:kissat")
    assert code == 2 and "not supported" in err
    code, stdout, _ = run(capsys, "synthesize", "line", "--size", "6x6", "--solver", "backtrack",
                          "--order", "scanline", "--seed", "1")  # fmt: skip
    assert code == 0
