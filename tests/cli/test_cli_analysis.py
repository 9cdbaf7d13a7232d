"""``csplab prove``, ``witness`` and ``refine``: verdicts and exit codes."""

from __future__ import annotations

import json

import pytest

from csplab.cli import main
from csplab.examples import load_example
from csplab.io.gridtext import read_grid


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_prove_exit_codes(capsys):
    code, out, _ = run(capsys, "prove", "line", "--order", "scan:yx")
    assert code == 0 and out.startswith("infallible") and "re-check" in out
    code, out, _ = run(capsys, "prove", "fig3_4a", "--region", "2", "--order", "scan:yx")
    assert code == 3 and "Alg. 3.6" in out and "empty catalog" in out
    code, out, _ = run(capsys, "prove", "fig3_4a", "--region", "3x2", "--order", "scan:yx")
    assert code == 0
    # the default decides: the smallest region that proves it (the thesis' 3x2)
    code, out, _ = run(capsys, "prove", "fig3_4a", "--order", "scan:yx", "--time-limit", "60")
    assert code == 0 and "method: region 3x2 history 0 (Alg. 3.6)" in out
    code, out, _ = run(capsys, "prove", "fig3_5a", "--order", "scan:yx")
    assert code == 1 and "fallible" in out and "inconsistent at choice" in out


def test_prove_recheck_hash(capsys):
    code, out, _ = run(capsys, "prove", "fig3_15", "--order", "scan:yx", "--json")
    d = json.loads(out)
    assert code == 0 and d["holds"] is True
    h = d["witness"]["sha256"]
    args = ["prove", "fig3_15", "--order", "scan:yx", "--expect-hash"]
    assert run(capsys, *args, h)[0] == 0
    assert run(capsys, *args, "0" * 64)[0] == 3


def test_prove_budget_and_corner(capsys):
    code, out, _ = run(capsys, "prove", "fig3_16", "--region", "4x2", "--order", "scan:yx",
                       "--max-states", "20")  # fmt: skip
    assert code == 3 and "budget" in out and "states enumerated" in out
    assert run(capsys, "prove", "fig3_15", "--corner")[0] == 0
    assert run(capsys, "prove", "fig3_5a", "--corner")[0] == 3


@pytest.mark.parametrize(
    ("args", "msg"),
    [
        (["prove", "line", "--region", "1x2"], "at least 2"),
        (["prove", "line", "--order", "random"], "region proof"),
        (["prove", "nosuchmodel"], "neither a model file"),
        (["witness", "line", "--order", "sideways"], "order"),
        (["witness", "line", "--time-limit", "0"], "--time-limit"),
        (["witness", "line", "--time-limit", "nan"], "--time-limit"),
        (["witness", "castle", "--boundary", "q"], "--boundary"),
    ],
)
def test_bad_input_is_one_line(capsys, args, msg):
    code, _, err = run(capsys, *args)
    assert code == 2 and msg in err and "Traceback" not in err


def test_witness_outputs(tmp_path, capsys):
    png = tmp_path / "w.png"
    code, out, _ = run(capsys, "witness", "fig3_5a", "--order", "scan:yx", "--max-size", "3x3",
                       "--out", str(png))  # fmt: skip
    assert code == 1 and png.read_bytes()[:4] == b"\x89PNG"
    js = tmp_path / "w.json"
    run(capsys, "witness", "fig3_5a", "--order", "scan:yx", "--max-size", "3x3", "--out", str(js))
    w = json.loads(js.read_text())
    assert w["shape"] == [3, 3] and w["choices"]
    code, out, _ = run(capsys, "witness", "line", "--max-size", "3x3")
    assert code == 0 and "no failure" in out
    code, out, _ = run(capsys, "witness", "line", "--max-size", "5x5", "--exhaustive-cells",
                       "4", "--runs", "2")  # fmt: skip
    assert code == 3 and "not a proof" in out


def test_witness_3d_defaults_escalate_and_shrink(tmp_path, capsys):
    # the search finds and shrinks castle's failure in about 1.3 s on an idle machine and
    # stops there; the limit leaves room for a loaded one (5 s failed under load 8+)
    js = tmp_path / "w.json"
    code, out, _ = run(capsys, "witness", "castle", "--boundary", "auto", "--time-limit", "20",
                       "--out", str(js))  # fmt: skip
    assert code == 1 and "fails on" in out
    line = next(x for x in out.splitlines() if x.startswith("  searched: "))
    assert "sizes exhaustive" in line and "random runs (" in line and "shrunk with" in line
    w = json.loads(js.read_text())
    assert w["boundary"] == "auto" and w["choices"]
    from csplab.analysis import replay

    assert replay(load_example("castle"), w).holds
    code, out, _ = run(capsys, "witness", "castle", "--boundary", "auto", "--time-limit", "20",
                       "--json")  # fmt: skip
    d = json.loads(out)
    assert code == 1 and d["stats"]["random_runs"] > 0 and d["stats"]["runs_per_size"]


def test_refine_writes_an_infallible_example(tmp_path, capsys):
    out = tmp_path / "ei.grid"
    code, stdout, _ = run(capsys, "refine", "fig3_5a", "--order", "scan:yx", "--out", str(out))
    assert code == 0 and "label 9" in stdout
    EI = read_grid(out)
    assert (EI.labels == 9).sum() == 3
    assert run(capsys, "prove", str(out), "--order", "scan:yx")[0] == 0
    assert load_example("fig3_5a").K == 9


@pytest.mark.parametrize("command", ["prove", "witness"])
def test_bad_out_is_refused_before_the_search(capsys, tmp_path, command):
    # one --out rule for both commands, checked before any work (witness used to search
    # for up to --time-limit seconds and only then refuse the suffix)
    code, out, err = run(capsys, command, "fig3_5a", "--out", str(tmp_path / "run.txt"))
    assert code == 2 and out == "" and "use a .png picture or a .json file" in err
    code, _, err = run(capsys, command, "fig3_5a", "--out", str(tmp_path / "no" / "run.json"))
    assert code == 2 and "does not exist" in err

