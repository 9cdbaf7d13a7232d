"""`csplab synthesize`: restarts, settings that follow the input, partial outputs."""

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from csplab.cli import main
from csplab.io.registry import synthesis_defaults

DATA = Path(__file__).resolve().parents[1] / "io" / "data"
# Fig. 3.5's example fails on seed 3 in the figures' scan order (first attempt only)
FALLIBLE = ["synthesize", "fig3_5a", "--size", "8x8", "--seed", "3", "--order", "scan:yx"]


def _run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_restarts_turn_a_failed_first_run_into_a_result(capsys):
    code, out, _ = _run(capsys, *FALLIBLE, "--restarts", "0", "--fallback", "none", "--json")
    d = json.loads(out)
    assert code == 1 and d["status"] == "failed" and d["settings"]["restarts"] == 0
    assert d["outcome"] == "not solved" and d["proof"] is None
    code, out, _ = _run(capsys, *FALLIBLE, "--json")  # default: 10 restarts
    d = json.loads(out)
    assert code == 0 and d["status"] == "solved" and d["settings"]["restarts"] == 10
    assert d["stats"]["attempts"] >= 2 and d["seed"] == 3
    seed = d["stats"]["attempt_seed"]  # reproduces the successful attempt alone
    code, out, _ = _run(capsys, "synthesize", "fig3_5a", "--size", "8x8", "--seed", seed,
                        "--order", "scan:yx", "--restarts", "0", "--json")  # fmt: skip
    assert code == 0 and json.loads(out)["status"] == "solved"


def test_complete_solvers_do_not_restart(capsys):
    code, out, _ = _run(capsys, "synthesize", "line", "--size", "6x4", "--solver", "backtrack",
                        "--seed", "1", "--json")  # fmt: skip
    assert code == 0 and json.loads(out)["settings"]["restarts"] == 0


def test_settings_follow_the_input(capsys):
    code, out, _ = _run(capsys, "synthesize", DATA / "pipes.xml", "--size", "10x10", "--seed",
                        "1", "--json")  # fmt: skip
    s = json.loads(out)["settings"]
    assert code == 0 and s["order"] == "min-entropy (wfc defaults)"
    assert s["choice"] == "weighted (wfc defaults)"
    code, out, _ = _run(capsys, "synthesize", DATA / "pipes.xml", "--size", "10x10", "--seed",
                        "1", "--order", "scanline", "--json")  # fmt: skip
    assert json.loads(out)["settings"]["order"] == "scanline (given)"
    code, out, _ = _run(capsys, "synthesize", "line", "--size", "6x4", "--seed", "1")
    assert "order=scanline (auto: no global constraints; solver default)" in out
    assert "choice=uniform (the thesis defaults)" in out
    # backtrack's order vocabulary has no min-entropy: its own default stays
    code, out, _ = _run(capsys, "synthesize", DATA / "pipes.xml", "--size", "8x8", "--seed",
                        "1", "--solver", "backtrack", "--json")  # fmt: skip
    s = json.loads(out)["settings"]
    assert s["order"] == "min-domain (solver default)" and s["choice"] == "weighted (wfc defaults)"


def test_catalog_default_order_under_global_constraints(capsys, tmp_path):
    """``catalog``'s ``order=auto`` under a constraints file: the settings and the stats
    name the order it stands for (min-entropy), and one run without restarts solves a
    connected City for a seed on which scanline order fails (the order decided it)."""
    from csplab.constraints import constraints_json
    from csplab.testing.synthetic import connected_city

    c = tmp_path / "c.json"
    c.write_text(json.dumps(constraints_json(connected_city((12, 12, 6))[1])))
    argv = ["synthesize", "city", "--size", "12x12x6", "--boundary", "auto", "--seed", "1",
            "--constraints", c, "--restarts", "0", "--fallback", "none", "--json"]  # fmt: skip
    code, out, _ = _run(capsys, *argv)
    d = json.loads(out)
    assert code == 0 and d["status"] == "solved" and d["stats"]["order"] == "min-entropy"
    assert d["settings"]["order"] == "min-entropy (auto: global constraints; solver default)"
    code, out, _ = _run(capsys, *argv, "--order", "scanline")
    d = json.loads(out)
    assert code == 1 and d["status"] == "failed" and d["settings"]["order"] == "scanline (given)"
    code, out, _ = _run(capsys, *argv, "--order", "auto")
    d = json.loads(out)
    assert d["settings"]["order"] == "min-entropy (auto: global constraints; given)"


def test_a_files_own_heuristic_wins():
    d, src = synthesis_defaults(SimpleNamespace(meta={"format": "wfc", "heuristic": "Scanline"}))
    assert d == {"order": "scanline", "choice": "weighted"}
    assert "Scanline" in src["order"] and src["choice"] == "wfc defaults"
    d, src = synthesis_defaults(SimpleNamespace(meta={"format": "wfc", "heuristic": "MRV"}))
    assert d["order"] == "min-domain"
    assert synthesis_defaults(SimpleNamespace(meta={"format": "merrell"})) == (
        {},
        {"*": "the thesis defaults"},
    )


def test_failed_runs_write_nothing_unless_asked(capsys, tmp_path):
    out = tmp_path / "g.npy"
    alone = ("--restarts", "0", "--fallback", "none")  # the incomplete solver's run alone
    code, stdout, err = _run(capsys, *FALLIBLE, *alone, "--out", out)
    assert code == 1 and not out.exists() and "--out-partial" in err
    assert stdout.startswith("not solved:") and "not solved" in err and "unsat" not in err
    code, stdout, _ = _run(capsys, *FALLIBLE, *alone, "--out", out, "--out-partial")
    g = np.load(out)
    assert code == 1 and (g < 0).any() and "partial" in stdout
    code, _, err = _run(capsys, *FALLIBLE, "--out", tmp_path / "g.txt", "--out-partial")
    assert code == 2 and "cannot hold unassigned cells" in err and not (tmp_path / "g.txt").exists()


def test_the_default_chain_solves_what_the_incomplete_solver_gave_up_on(capsys, tmp_path):
    out = tmp_path / "g.npy"
    code, stdout, _ = _run(capsys, *FALLIBLE, "--restarts", "0", "--out", out)
    assert code == 0 and out.exists() and stdout.startswith("solved:")
    assert "catalog gave up after 1 attempt" in stdout and "fallback=sat (auto)" in stdout
    code, stdout, _ = _run(capsys, *FALLIBLE, "--restarts", "0", "--json")
    d = json.loads(stdout)
    assert d["solver"] == "sat" and d["stats"]["fallback_from"] == "catalog"
    # the fallback alone, from the recorded seed: the same grid
    seed = d["stats"]["attempt_seed"]
    code2, _, _ = _run(capsys, "synthesize", "fig3_5a", "--size", "8x8", "--solver", "sat",
                       "--seed", seed, "--out", tmp_path / "h.npy")  # fmt: skip
    assert code2 == 0 and (np.load(out) == np.load(tmp_path / "h.npy")).all()


def test_unsat_says_so_with_the_proof_and_not_solved_says_it_decides_nothing(capsys, tmp_path):
    odd = ["synthesize", "fig3_1b", "--size", "5x5", "--periodic", "--seed", "1"]
    code, stdout, err = _run(capsys, *odd, "--out", tmp_path / "g.npy")
    assert code == 1 and stdout.startswith("unsat:") and "  proof: refutation by" in stdout
    assert "no solution exists" in err and not (tmp_path / "g.npy").exists()
    code, stdout, _ = _run(capsys, *odd, "--json")
    d = json.loads(stdout)
    assert (d["status"], d["outcome"], d["solver"]) == ("unsat", "unsat", "sat")
    assert d["proof"].startswith("refutation by")
    code, stdout, _ = _run(capsys, *odd, "--fallback", "backtrack", "--json")
    d = json.loads(stdout)
    assert code == 1 and d["outcome"] == "unsat" and d["proof"].startswith("search tree exhausted")
    code, stdout, _ = _run(capsys, *odd, "--fallback", "none")
    assert code == 1 and stdout.startswith("not solved:") and "proof" not in stdout
    code, stdout, _ = _run(capsys, *odd, "--fallback", "none", "--json")
    d = json.loads(stdout)
    assert (d["status"], d["outcome"], d["proof"]) == ("failed", "not solved", None)


def test_an_unwritable_output_is_refused_before_the_work(capsys, tmp_path):
    code, out, err = _run(capsys, "synthesize", "line", "--size", "6x4", "--out",
                          tmp_path / "missing" / "x.npy")  # fmt: skip
    assert code == 2 and out == "" and "does not exist" in err and len(err.splitlines()) == 1


def test_sat_under_global_constraints_keeps_its_auto_phases(capsys, tmp_path):
    """A WFC tileset suggests weighted label choices; for ``sat`` under a constraints file
    its ``choice=auto`` (the Alg. 3.1 start after a short uniform attempt) wins over that
    suggestion, and the settings say so; without constraints the suggestion stands."""
    pytest.importorskip("pysat")
    model = str(Path(__file__).resolve().parents[1] / "io" / "data" / "pipes.xml")
    c = tmp_path / "c.json"
    c.write_text(json.dumps([{"type": "connected", "labels": ["line", "corner", "tee", "cross"]}]))
    argv = ["synthesize", model, "--size", "12x12", "--seed", "1", "--solver", "sat", "--json"]
    code, out, _ = _run(capsys, *argv, "--constraints", c)
    d = json.loads(out)
    assert code == 0 and d["status"] == "solved"
    assert d["settings"]["choice"].startswith("auto (solver default: global constraints")
    assert d["stats"]["choice"] in ("uniform", "catalog") and "probe_conflicts" in d["stats"]
    code, out, _ = _run(capsys, *argv)
    d = json.loads(out)
    assert code == 0 and d["settings"]["choice"] == "weighted (wfc defaults)"
    assert d["stats"]["choice"] == "weighted"
