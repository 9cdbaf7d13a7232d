import json

import pytest

from csplab.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_list_and_help(capsys):
    code, out, _ = run(capsys, "experiment", "list")
    assert code == 0
    for name in ("fig3_8", "blocksize", "table3_1", "catalog_gap", "sampling_bias"):
        assert name in out
    with pytest.raises(SystemExit) as e:
        main(["experiment", "fig3_8", "--help"])
    assert e.value.code == 0
    assert "--nz" in capsys.readouterr().out


def test_quick_run_json_then_report_only(capsys, tmp_path):
    args = ["experiment", "fig3_8", "--quick", "--example", "line", "--seeds", "2",
            "--store", str(tmp_path / "r.sqlite"), "--out", str(tmp_path / "o"),
            "--jobs", "1", "--no-progress", "--no-figures"]  # fmt: skip
    code, out, _ = run(capsys, *args, "--json")
    d = json.loads(out)
    assert code == 0 and d["ran"] == 4 and d["missing"] == 0 and not d["errors"]
    assert d["tables"]["success rate"][0]["trials"] == 2
    code, out, _ = run(capsys, *args)
    assert code == 0 and "4 already stored" in out and "| nx |" in out
    code, out, _ = run(capsys, *args, "--rerun")
    assert code == 0 and "0 already stored, 4 run" in out
    # more seeds, report only: the new trials are missing -> exit 1
    code, out, err = run(capsys, *args[:6], "4", *args[7:], "--report-only")
    assert code == 1 and "4 of 8 trials are missing" in err


@pytest.mark.parametrize(
    "extra, msg",
    [
        (["--sizes", "9:3"], "sizes"),
        (["--example", "nosuchmodel"], "neither a model file"),
        (["--option", "novalue"], "KEY=VALUE"),
        (["--solver", "nosuchsolver", "--seeds", "1"], "unknown solver 'nosuchsolver'"),
        (["--solver", "catalog@order=zigzag"], "order must be one of"),
        (["--option", "catalog.choice=heavy"], "choice must be one of"),
        (["--jobs", "0"], "--jobs"),
    ],
)
def test_bad_input_exits_2_with_one_line(capsys, tmp_path, extra, msg):
    code, _out, err = run(capsys, "experiment", "fig3_8", "--quick", "--store",
                          str(tmp_path / "r.sqlite"), "--out", str(tmp_path), "--no-progress",
                          "--no-figures", "--jobs", "1", *extra)  # fmt: skip
    assert code == 2 and msg in err and "Traceback" not in err


def test_options_that_do_not_apply_are_rejected(capsys):
    with pytest.raises(SystemExit) as e:
        main(["experiment", "table3_1", "--nz", "4"])
    assert e.value.code == 2
    code, _, err = run(capsys, "experiment", "fig9_9")
    assert code == 2 and "unknown experiment" in err


def test_original_model_in_merrells_format(capsys, tmp_path):
    """Users have the thesis' models as Merrell-format .txt files: --example takes them."""
    from csplab.examples import load_example
    from csplab.io import write_example

    path = tmp_path / "castle.txt"
    write_example(load_example("castle"), path)
    code, out, _ = run(capsys, "experiment", "fig3_8", "--example", str(path), "--sizes", "6",
                       "--nz", "4", "--seeds", "3", "--store", str(tmp_path / "r.sqlite"),
                       "--out", str(tmp_path / "o"), "--jobs", "1", "--no-progress",
                       "--no-figures", "--json")  # fmt: skip
    d = json.loads(out)
    assert code == 0 and d["ran"] == 3
    (row,) = d["tables"]["success rate"]
    assert row["example"] == path.stem and row["size"] == "6x6x4"  # the path: in the config
    # trials are identified by the example's content hash, not by its name or path
    grid = tmp_path / "castle.grid"
    write_example(load_example("castle"), grid)
    args = ["--sizes", "6", "--nz", "4", "--seeds", "3", "--store", str(tmp_path / "s.sqlite"),
            "--out", str(tmp_path / "o"), "--jobs", "1", "--no-progress", "--no-figures",
            "--json"]  # fmt: skip
    run(capsys, "experiment", "fig3_8", "--example", "castle", *args)
    code, out, _ = run(capsys, "experiment", "fig3_8", "--example", str(grid), *args)
    assert code == 0 and json.loads(out)["skipped"] == 3
