import csv
import gzip

import pytest

from csplab import solve
from csplab.errors import InputError
from csplab.examples import load_example
from csplab.experiments import get_experiment, run
from csplab.experiments.trial import grid_digest
from csplab.grids import from_example


def test_quick_run_rates_intervals_files_and_resume(tmp_path):
    kw = {"store": tmp_path / "r.sqlite", "out": tmp_path / "out", "jobs": 1, "progress": False}
    s, rep = run("fig3_8", quick=True, seeds=4, **kw)
    assert s.ran == s.total == 2 * 2 * 4 and not s.errors
    table = rep.tables["success rate"]
    for t in table:
        assert t["rate"] == t["solved"] / t["trials"]
        assert t["lo95"] <= t["rate"] <= t["hi95"]
    assert {t["example"] for t in table} == {"castle", "line"}
    for f in ("fig3_8.png", "fig3_8.svg", "fig3_8.md", "fig3_8_trials.csv.gz",
              "fig3_8_success_rate.csv"):  # fmt: skip
        assert (tmp_path / "out" / f).stat().st_size > 100
    raw = list(csv.DictReader(gzip.open(tmp_path / "out" / "fig3_8_trials.csv.gz", "rt")))
    assert len(raw) == 16 and {r["solver"] for r in raw} == {"catalog"}
    # a stored trial is reproduced by its seed
    r = next(r for r in raw if r["example"] == "castle" and r["size"] == "8x8x4")
    P = from_example(load_example("castle"), (8, 8, 4), boundary="auto")
    again = solve(P, "catalog", rng=int(r["seed"]), order="scanline", choice="uniform")
    assert again.status == r["status"] and grid_digest(again.grid) == r["stats.grid"]
    # the same sweep again runs nothing; more seeds run only the new ones
    assert run("fig3_8", quick=True, seeds=4, **kw)[0].skipped == 16
    s3, _ = run("fig3_8", quick=True, seeds=5, **kw)
    assert (s3.skipped, s3.ran) == (16, 4)


def test_solver_variants_are_separate_curves(tmp_path):
    _, rep = run(
        "fig3_8", quick=True, examples=["line"], seeds=2, store=tmp_path / "r.sqlite",
        out=tmp_path, jobs=1, progress=False,
        solvers=["catalog", "catalog@order=random", "blocks@block=3"],
    )  # fmt: skip
    settings = {t["solver"] for t in rep.tables["success rate"]}
    assert settings == {"catalog", "catalog@order=random", "blocks@block=3"}
    wide = rep.tables["figure as table"][0]
    assert {"line/catalog", "line/catalog@order=random", "line/blocks@block=3"} <= set(wide)


def test_bad_configurations_are_one_line_errors():
    exp = get_experiment("fig3_8")
    with pytest.raises(InputError, match="no option"):
        exp.make_config(quick=True, colour="red")
    with pytest.raises(InputError, match="boundary none"):
        exp.build(exp.make_config(quick=True, examples=["fig3_1d"]))
    with pytest.raises(InputError, match="sizes"):
        exp.make_config(sizes="10:5")
    with pytest.raises(InputError, match="unknown experiment"):
        get_experiment("fig9_9")
